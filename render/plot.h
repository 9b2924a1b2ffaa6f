/* SPDX-License-Identifier: MIT */
/* Line plots for people to read: a curve over x in [0, 1] with a limit line and marked x
 * positions (the in-between error plots of `morphkit bake --plot`). */
#ifndef MKR_PLOT_H
#define MKR_PLOT_H

#include <stdint.h>
#include "image.h"

typedef struct mkr_plot {
    const char *title;
    const double *values;        /* y at x = k / (count - 1), k = 0..count-1; may be NULL */
    uint32_t count;
    double limit;                /* a horizontal line at this y (e.g. a tolerance); 0 = none */
    const float *marks;          /* x positions marked by vertical lines (in [0, 1]) */
    uint32_t mark_count;
    double label_scale;          /* y tick labels show y * label_scale ... */
    const char *unit;            /* ... followed by this unit (e.g. "%") */
    const char *note;            /* shown instead of a curve when values is NULL */
} mkr_plot;

/* A straight line of rgba pixels from (x0, y0) to (x1, y1), clipped; every `dash` pixels on
 * and off when dash > 0. */
void mkr_draw_line(mkr_image *img, int x0, int y0, int x1, int y1, const uint8_t rgba[4], int dash);

/* Draws the plot in the rectangle (x, y, width, height): a title, axes with tick labels (x at
 * 0, 0.5, 1; y at 0, the limit and the top), the limit dashed, the marks dotted and the curve.
 * The y range is [0, max(largest value, limit) x 1.1]. */
void mkr_plot_draw(mkr_image *img, int x, int y, int width, int height, const mkr_plot *plot);

/* One curve of a line chart: values[k] at x = k (e.g. a frame), its label in the legend and
 * indices k marked with a dot on the curve. */
typedef struct mkr_series {
    const double *values;
    uint32_t count;
    const char *label;
    const uint32_t *marks;
    uint32_t mark_count;
} mkr_series;

/* Several curves on shared axes (the volume ratios of `morphkit bake --plot`). */
typedef struct mkr_lines {
    const char *title, *x_label, *y_label;
    double x_scale;              /* x tick labels show k * x_scale (e.g. seconds per frame); 0: k */
    double y_max;                /* the y axis is [0, y_max]; 0: the largest value x 1.1 */
    const mkr_series *series;
    uint32_t series_count;
} mkr_lines;

/* The color of curve i (a fixed palette, repeating). */
const uint8_t *mkr_series_color(uint32_t i);

/* Draws the chart in the rectangle (x, y, width, height): a title, axes with tick labels (x at
 * 0, half and the longest curve's end; y at 0, half and the top; values above the top are drawn
 * at the top), the x label under the axis and the y label inside the top-left corner, every
 * curve in its color with its marks as dots, and a legend of the labels in their colors at the
 * top right. */
void mkr_lines_draw(mkr_image *img, int x, int y, int width, int height, const mkr_lines *lines);

#endif

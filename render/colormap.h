/* SPDX-License-Identifier: MIT */
/* A perceptually ordered color map and a legend bar to read it.
 *
 * The ramp is defined in the Oklab color space (B. Ottosson's perceptual Lab, 2020): the
 * lightness L rises linearly from 0.27 (dark violet) to 0.93 (yellow) while the hue turns
 * from 300 to 105 degrees through blue, teal and green, the way viridis-style maps do;
 * chroma grows toward the end and is reduced where sRGB cannot show it, keeping L and hue.
 * Lightness therefore increases monotonically: the map reads correctly in grayscale and
 * for color-blind viewers, and "hot" (yellow) always means larger. */
#ifndef MKR_COLORMAP_H
#define MKR_COLORMAP_H

#include <stdint.h>
#include "image.h"

#define MKR_COLORMAP_SIZE 256

/* The ramp color (sRGB, 8 bits) at t in [0, 1] (clamped; NaN gives the hot end). */
void mkr_colormap(float t, uint8_t rgb[3]);
/* MKR_COLORMAP_SIZE entries of 3 bytes: entry i is mkr_colormap(i / 255). */
void mkr_colormap_table(uint8_t table[3 * MKR_COLORMAP_SIZE]);

/* A horizontal legend: optional caption line, the ramp bar from lo (left) to hi (right),
 * tick marks, a row of value labels and optionally a second row of the same values in
 * another unit (value * second_scale, e.g. a percentage). */
typedef struct mkr_legend {
    float lo, hi;
    int ticks;                  /* labelled ticks including both ends; below 2 counts as 2 */
    const char *caption;        /* line above the bar, or NULL */
    const char *suffix;         /* appended to the value labels (e.g. " m"), or NULL */
    float second_scale;         /* > 0: draw the second row */
    const char *second_suffix;  /* appended to the second-row labels (e.g. "%"), or NULL */
    int text_scale;             /* font scale; below 1 counts as 1 */
    int bar_height;             /* pixels; below 1: 12 font pixels */
} mkr_legend;

/* Height in pixels that mkr_legend_draw uses. */
int mkr_legend_height(const mkr_legend *legend);
/* Draws the legend with its top-left corner at (x, y), width pixels wide; text in color. */
void mkr_legend_draw(mkr_image *img, int x, int y, int width, const mkr_legend *legend, const uint8_t color[4]);

#endif

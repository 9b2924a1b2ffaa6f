/* SPDX-License-Identifier: MIT */
/* Contact sheets: one picture of many frames, each frame a cell of a grid, all drawn through
 * one fixed camera framed on the union of every frame's bounds, so motion shows as change
 * between cells.
 *
 * Layout, top to bottom: an optional title strip; the grid (cells left to right, then down,
 * separated by 2-pixel gutters); for diff sheets a legend strip. Each cell has a label band
 * at its top (as tall as the longest label) and draws its meshes below it.
 *
 * Cell labels: "t=0.50 s" (decimals added until distinct times read distinctly) when the
 * cell has a time; for diff sheets "max 0.0012 (0.07%)", the cell's largest scalar in mesh
 * units and as a percentage of the bounding-box diagonal (or "max 12.5 deg" with a scalar
 * suffix); then the cell's own text lines. */
#ifndef MKR_SHEET_H
#define MKR_SHEET_H

#include <stdint.h>
#include "camera.h"
#include "image.h"
#include "morphkit.h"
#include "raster.h"

#define MKR_SHEET_GUTTER 2

typedef struct mkr_cell {
    const mkr_mesh_view *meshes;   /* the frame: every mesh of the asset at one time */
    uint32_t mesh_count;
    double time;                   /* seconds, labelled "t=0.50 s"; NAN: no time line */
    const char *text;              /* more label lines ('\n'-separated, e.g. weights), or NULL */
} mkr_cell;

typedef struct mkr_sheet_desc {
    const mkr_cell *cells;
    uint32_t cell_count;
    int cell_width, cell_height;   /* pixels per cell, label band included; 0: 320 */
    int columns;                   /* 0: ceil(sqrt(cell_count)) */
    mkr_view view;
    const char *title;             /* title strip text ('\n'-separated lines), or NULL: no strip */
    int text_scale;                /* font scale; 0: 2 for cells at least 384 pixels wide, else 1 */
    float diff_max;                /* diff sheets: scalar drawn hottest; <= 0: largest in any cell */
    const char *scalar_caption;    /* diff sheets whose scalars are not distances: the legend's
                                    * caption (e.g. "angle to the surface normal, degrees"), with
                                    * scalar_suffix (up to 8 characters, e.g. " deg") after every
                                    * value and no percent of the diagonal; NULL: distances in
                                    * mesh units */
    const char *scalar_suffix;
} mkr_sheet_desc;

/* Where things land on the sheet, in pixels. */
typedef struct mkr_sheet_layout {
    int width, height;             /* the whole sheet */
    int columns, rows;
    int cell_width, cell_height;
    int text_scale;
    int title_height;              /* strip at the top (0: none) */
    int label_height;              /* band at the top of every cell (0: no labels) */
    int legend_height;             /* strip at the bottom (diff sheets; 0: none) */
} mkr_sheet_layout;

/* Contact sheet: meshes lit in a flat color per mesh of the cell (first mesh clay gray).
 * Creates *out (free it with mkr_image_destroy); on error *out is zeroed.
 * Errors: MK_ERROR_INVALID_ARGUMENT (NULL desc/out, no cells, cell_count meshes NULL, negative
 * sizes), MK_ERROR_LIMIT (sheet above MKR_IMAGE_MAX_SIDE a side), those of mkr_draw_mesh. */
mk_result mkr_sheet_render(const mkr_sheet_desc *desc, mkr_image *out, mk_error *err);

/* Diff sheet: every mesh colored by its per-vertex scalars (e.g. the distance between two
 * evaluations) on one scale shared by all cells, 0 coldest, diff_max (or the largest
 * scalar) hottest, lit only lightly so the colors match the legend. Every mesh needs
 * scalars (MK_ERROR_INVALID_ARGUMENT otherwise). The legend gives the scale in mesh units
 * and as a percentage of the diagonal of the frames' union bounding box. */
mk_result mkr_diff_sheet_render(const mkr_sheet_desc *desc, mkr_image *out, mk_error *err);

/* The layout a sheet (diff: nonzero for a diff sheet) of desc would have. Returns 0 (and a
 * zeroed layout) for a desc the render functions reject for its shape. */
int mkr_sheet_layout_get(const mkr_sheet_desc *desc, int diff, mkr_sheet_layout *layout);
/* Top-left corner and size of cell index in a layout: rect = { x, y, width, height }. */
void mkr_sheet_cell_rect(const mkr_sheet_layout *layout, uint32_t index, int rect[4]);

#endif

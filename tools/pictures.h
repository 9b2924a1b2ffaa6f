/* SPDX-License-Identifier: MIT */
/* What the picture verbs (render, conform --report, bake --plot) share: played frames as the
 * render library's mesh views, per-vertex distances, --size values, PNG bytes. */
#ifndef MK_PICTURES_H
#define MK_PICTURES_H

#include "cli.h"
#include "frame_write.h"
#include "render.h"

/* Cells at most this many pixels a side (and at least CLI_CELL_MIN): a sheet of them still
 * fits the render library's image limit. */
#define CLI_CELL_MIN 32
#define CLI_CELL_MAX 4096

/* Parses "WIDTHxHEIGHT" (each CLI_CELL_MIN..CLI_CELL_MAX) for option. Returns -1 when fine,
 * else the exit status after printing the error. */
int cli_parse_size(const cli_verb *verb, const char *option, const char *text, int *width, int *height);

/* A view of mesh `mesh` of a played frame: its positions and normals (NULL where the mesh has
 * none: face normals are drawn), the asset's triangles, no scalars or colors. */
mkr_mesh_view cli_mesh_view(const pb_frame *frame, uint32_t mesh);

/* out[v] = |a[v] - b[v]| for 3-float points (NaN where a coordinate is not finite). */
void cli_distances(const float *a, const float *b, uint32_t count, float *out);

/* Encodes img as PNG into out's data (out owns png's bytes until mkr_png_free). Returns -1
 * when fine, else the exit status after printing the error. */
int cli_png_encode(const cli_verb *verb, const mkr_image *img, mkr_png *png, cli_output *out);

#endif

/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "pictures.h"

/* One side of a --size value: digits only, in range; returns -1 when not. */
static long size_side(const char *p, const char **end)
{
    const char *q = p;
    while (*q >= '0' && *q <= '9' && q - p < 9) q++;
    if (q == p || (*q >= '0' && *q <= '9')) return -1;
    *end = q;
    return strtol(p, NULL, 10);
}

int cli_parse_size(const cli_verb *verb, const char *option, const char *text, int *width, int *height)
{
    const char *end = text;
    long w = size_side(text, &end), h = -1;
    if (w >= 0 && *end == 'x') h = size_side(end + 1, &end);
    if (w < 0 || h < 0 || *end)
        return cli_usage_error(verb, "%s %s: write WIDTHxHEIGHT in pixels, e.g. 512x512", option, text);
    if (w < CLI_CELL_MIN || h < CLI_CELL_MIN || w > CLI_CELL_MAX || h > CLI_CELL_MAX)
        return cli_usage_error(verb, "%s %s: a cell must be %d to %d pixels a side", option, text, CLI_CELL_MIN,
                               CLI_CELL_MAX);
    *width = (int)w;
    *height = (int)h;
    return -1;
}

mkr_mesh_view cli_mesh_view(const pb_frame *frame, uint32_t mesh)
{
    mk_mesh_info m;
    mk_mesh_get(frame->asset, mesh, &m);
    mkr_mesh_view v = { .vertex_count = m.vertex_count, .positions = frame->positions[mesh],
                        .normals = frame->normals[mesh], .triangle_count = m.triangle_count,
                        .triangles = m.triangles };
    return v;
}

void cli_distances(const float *a, const float *b, uint32_t count, float *out)
{
    for (uint32_t v = 0; v < count; v++) {
        double d = 0;
        for (int k = 0; k < 3; k++) {
            double e = (double)a[3 * v + (uint32_t)k] - b[3 * v + (uint32_t)k];
            d += e * e;
        }
        out[v] = (float)sqrt(d);   /* NaN stays NaN: the color map shows it hot */
    }
}

int cli_png_encode(const cli_verb *verb, const mkr_image *img, mkr_png *png, cli_output *out)
{
    mk_error err;
    if (mkr_png_encode(img, png, &err) != MK_OK) return cli_fail(verb->name, &err);
    out->file.data = png->data;
    out->file.size = png->size;
    return -1;
}

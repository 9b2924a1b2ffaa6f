/* SPDX-License-Identifier: MIT */
/* Writes samples/recipes/tube_source.gltf, the source asset of the transfer sample
 * (samples/recipes/transfer.json; docs/baking.md, "transfer"): a coarser tube of the example's
 * size (radius 0.5, height 2; 16 segments x 8 rings) with two one-target channels, "pinch" (the
 * radius narrowed to half at mid-height) and "lean" (the tube bent over, its top 0.4 along +x
 * and 0.1 lower), target normals computed from the targets, written by the glTF writer behind
 * `morphkit export`. A test regenerates the file and compares it byte for byte.
 * usage: make_tube_source OUT.gltf */
#include <math.h>
#include <stdio.h>
#include "gltf_export.h"
#include "primitives.h"

#define SEGMENTS 16
#define RINGS 8
#define PI 3.14159265358979

typedef void (*shape_fn)(const double p[3], double q[3]);

static void pinch(const double p[3], double q[3])
{
    double k = 1 - 0.5 * sin(PI * p[1] / 2);
    q[0] = p[0] * k;
    q[1] = p[1];
    q[2] = p[2] * k;
}

static void lean(const double p[3], double q[3])
{
    q[0] = p[0] + 0.1 * p[1] * p[1];
    q[1] = p[1] - 0.025 * p[1] * p[1];
    q[2] = p[2];
}

/* A channel of one dense target, shape(p) - p per vertex (computed in double). */
static int add_channel(mk_raw_asset *raw, const char *name, shape_fn shape)
{
    const mk_raw_mesh *m = &raw->meshes[0];
    mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
    if (!ch || !(ch->name = mk_arena_strdup(&raw->arena, name))) return 0;
    mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
    if (!t) return 0;
    t->name = ch->name;
    t->full_weight = 1;
    t->count = m->vertex_count;
    t->indices = mk_arena_array(&raw->arena, m->vertex_count, sizeof(uint32_t));
    t->positions = mk_arena_array(&raw->arena, 3 * (size_t)m->vertex_count, sizeof(float));
    if (!t->indices || !t->positions) return 0;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        const float *pf = m->positions + 3 * (size_t)v;
        double p[3] = { pf[0], pf[1], pf[2] }, q[3];
        shape(p, q);
        t->indices[v] = v;
        for (int c = 0; c < 3; c++) t->positions[3 * (size_t)v + c] = (float)(q[c] - p[c]);
    }
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 2 || argv[1][0] == '-') {
        fprintf(stderr, "usage: make_tube_source OUT.gltf\n");
        return 2;
    }
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *m = mk_raw_add_tube(&raw, "coarse_tube", SEGMENTS, RINGS);
    int ok = m != NULL;
    /* The committed file's rings were computed in double (mk_raw_add_tube works in float, with
     * another pi): its triangles are kept, its vertices and normals written again that way. */
    for (uint32_t r = 0; ok && r <= RINGS; r++)
        for (uint32_t s = 0; s < SEGMENTS; s++) {
            float *p = m->positions + 3 * (size_t)(r * SEGMENTS + s), *n = m->normals + 3 * (size_t)(r * SEGMENTS + s);
            double a = 2 * PI * s / SEGMENTS;
            p[0] = (float)(0.5 * cos(a));
            p[1] = (float)(2.0 * r / RINGS);
            p[2] = (float)(0.5 * sin(a));
            n[0] = (float)cos(a);
            n[1] = 0;
            n[2] = (float)sin(a);
        }
    ok = ok && add_channel(&raw, "pinch", pinch) && add_channel(&raw, "lean", lean);
    mk_error err;
    mk_gltf_export_report report;
    int status = 0;
    if (!ok) {
        fprintf(stderr, "make_tube_source: out of memory\n");
        status = 1;
    } else if (mk_raw_compute_target_normals(&raw, 0, 0, 0, &err) != MK_OK ||
               mk_export_gltf(&raw, argv[1], NULL, &report, &err) != MK_OK) {
        fprintf(stderr, "make_tube_source: %s\n", err.message);
        status = 1;
    } else {
        printf("wrote %s: tube of %u vertices, channels 'pinch' and 'lean'\n", argv[1], m->vertex_count);
    }
    mk_raw_free(&raw);
    return status;
}

/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "demo_mesh.h"

/* Midpoint vertex of edge (a, b), shared through an open-addressing table keyed by the pair. */
typedef struct edge_table {
    uint64_t *keys;     /* (min << 32 | max) + 1; 0 is empty */
    uint32_t *values;
    size_t mask;
} edge_table;

static uint32_t midpoint(edge_table *t, demo_mesh *m, uint32_t a, uint32_t b)
{
    uint64_t key = ((uint64_t)(a < b ? a : b) << 32 | (a < b ? b : a)) + 1;
    size_t slot = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & t->mask;
    while (t->keys[slot] && t->keys[slot] != key) slot = (slot + 1) & t->mask;
    if (t->keys[slot]) return t->values[slot];
    uint32_t v = m->vertex_count++;
    float *p = m->positions + 3 * (size_t)v, *pa = m->positions + 3 * (size_t)a, *pb = m->positions + 3 * (size_t)b;
    float len = 0;
    for (int i = 0; i < 3; i++) p[i] = pa[i] + pb[i], len += p[i] * p[i];
    len = sqrtf(len);
    for (int i = 0; i < 3; i++) p[i] /= len;
    t->keys[slot] = key;
    t->values[slot] = v;
    return v;
}

int demo_icosphere(int level, demo_mesh *out)
{
    memset(out, 0, sizeof *out);
    size_t faces = 20, verts = 12;
    for (int l = 0; l < level; l++) verts += faces * 3 / 2, faces *= 4;
    out->positions = malloc(verts * 3 * sizeof(float));
    out->normals = malloc(verts * 3 * sizeof(float));
    out->triangles = malloc(faces * 3 * sizeof(uint32_t));
    uint32_t *scratch = malloc(faces * 3 * sizeof(uint32_t));
    size_t table_size = 1;
    while (table_size < verts * 4) table_size *= 2;
    edge_table table = { calloc(table_size, sizeof(uint64_t)), malloc(table_size * sizeof(uint32_t)), table_size - 1 };
    int ok = out->positions && out->normals && out->triangles && scratch && table.keys && table.values;
    if (ok) {
        const float g = 1.6180339887f;
        const float seed[12][3] = { { -1, g, 0 }, { 1, g, 0 }, { -1, -g, 0 }, { 1, -g, 0 }, { 0, -1, g }, { 0, 1, g },
                                    { 0, -1, -g }, { 0, 1, -g }, { g, 0, -1 }, { g, 0, 1 }, { -g, 0, -1 }, { -g, 0, 1 } };
        static const uint32_t seed_faces[20][3] = {
            { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 }, { 1, 5, 9 }, { 5, 11, 4 },
            { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 }, { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 },
            { 3, 8, 9 }, { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
        float len = sqrtf(1 + g * g);
        for (int v = 0; v < 12; v++)
            for (int i = 0; i < 3; i++) out->positions[3 * v + i] = seed[v][i] / len;
        memcpy(out->triangles, seed_faces, sizeof seed_faces);
        out->vertex_count = 12;
        out->triangle_count = 20;
        for (int l = 0; l < level; l++) {
            memset(table.keys, 0, table_size * sizeof(uint64_t));
            uint32_t *src = out->triangles, *dst = scratch;
            for (uint32_t f = 0; f < out->triangle_count; f++) {
                uint32_t a = src[3 * f], b = src[3 * f + 1], c = src[3 * f + 2];
                uint32_t ab = midpoint(&table, out, a, b), bc = midpoint(&table, out, b, c), ca = midpoint(&table, out, c, a);
                uint32_t quad[12] = { a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca };
                memcpy(dst + 12 * (size_t)f, quad, sizeof quad);
            }
            out->triangle_count *= 4;
            out->triangles = dst;
            scratch = src;
        }
        memcpy(out->normals, out->positions, (size_t)out->vertex_count * 3 * sizeof(float));
    }
    free(scratch);
    free(table.keys);
    free(table.values);
    if (!ok) demo_mesh_free(out);
    return ok;
}

void demo_mesh_free(demo_mesh *mesh)
{
    free(mesh->positions);
    free(mesh->normals);
    free(mesh->triangles);
    memset(mesh, 0, sizeof *mesh);
}

void demo_vertex_normals(const float *positions, uint32_t vertex_count, const uint32_t *triangles,
                         uint32_t triangle_count, float *normals)
{
    memset(normals, 0, (size_t)vertex_count * 3 * sizeof(float));
    for (uint32_t t = 0; t < triangle_count; t++) {
        const uint32_t *f = triangles + 3 * (size_t)t;
        const float *a = positions + 3 * (size_t)f[0], *b = positions + 3 * (size_t)f[1], *c = positions + 3 * (size_t)f[2];
        float e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        float n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++) normals[3 * (size_t)f[k] + i] += n[i];
    }
    for (uint32_t v = 0; v < vertex_count; v++) {
        float *n = normals + 3 * (size_t)v, len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 0)
            for (int i = 0; i < 3; i++) n[i] /= len;
    }
}

void demo_bulge(const float *base, uint32_t vertex_count, const float dir[3], float amount, float width, float *out)
{
    for (uint32_t v = 0; v < vertex_count; v++) {
        const float *p = base + 3 * (size_t)v;
        float len = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        float c = len > 0 ? (p[0] * dir[0] + p[1] * dir[1] + p[2] * dir[2]) / len : 1;
        float angle = acosf(c < -1 ? -1 : c > 1 ? 1 : c) / width;
        float scale = 1 + amount * expf(-angle * angle);
        for (int i = 0; i < 3; i++) out[3 * (size_t)v + i] = p[i] * scale;
    }
}

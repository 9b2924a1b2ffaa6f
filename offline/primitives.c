/* SPDX-License-Identifier: MIT */
#include "primitives.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

mk_raw_mesh *mk_raw_add_tube(mk_raw_asset *raw, const char *name, uint32_t segments, uint32_t rings)
{
    const uint32_t n = segments * (rings + 1);
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    if (!m) return NULL;
    m->name = mk_arena_strdup(&raw->arena, name);
    m->vertex_count = n;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    m->triangles = mk_arena_array(&raw->arena, 6 * (size_t)segments * rings, sizeof(uint32_t));
    if (!m->name || !m->positions || !m->normals || !m->triangles) return NULL;
    for (uint32_t r = 0; r <= rings; r++)
        for (uint32_t s = 0; s < segments; s++) {
            uint32_t v = r * segments + s;
            float a = 6.28318531f * (float)s / (float)segments;
            m->positions[3 * v] = 0.5f * cosf(a);
            m->positions[3 * v + 1] = 2.0f * (float)r / (float)rings;
            m->positions[3 * v + 2] = 0.5f * sinf(a);
            m->normals[3 * v] = cosf(a);
            m->normals[3 * v + 1] = 0;
            m->normals[3 * v + 2] = sinf(a);
        }
    for (uint32_t r = 0, t = 0; r < rings; r++)
        for (uint32_t s = 0; s < segments; s++, t++) {
            uint32_t a = r * segments + s, b = r * segments + (s + 1) % segments, c = a + segments, d = b + segments;
            uint32_t *tri = &m->triangles[6 * t];
            tri[0] = a; tri[1] = c; tri[2] = b; tri[3] = b; tri[4] = c; tri[5] = d;
        }
    m->triangle_count = 2 * segments * rings;
    return m;
}

/* Midpoint of edge (a, b) on the unit sphere, created once per edge (open-addressing table
 * keyed by the sorted pair). */
static uint32_t midpoint(double *pos, uint32_t *count, uint64_t *keys, uint32_t *values, size_t slots,
                         uint32_t a, uint32_t b)
{
    uint64_t key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
    size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & (slots - 1);
    while (keys[h] != UINT64_MAX && keys[h] != key) h = (h + 1) & (slots - 1);
    if (keys[h] == key) return values[h];
    uint32_t v = (*count)++;
    double p[3], l = 0;
    for (int c = 0; c < 3; c++) { p[c] = pos[3 * a + c] + pos[3 * b + c]; l += p[c] * p[c]; }
    for (int c = 0; c < 3; c++) pos[3 * (size_t)v + c] = p[c] / sqrt(l);
    keys[h] = key;
    values[h] = v;
    return v;
}

mk_raw_mesh *mk_raw_add_icosphere(mk_raw_asset *raw, const char *name, float radius, uint32_t levels)
{
    uint32_t nv = 12, nt = 20;
    for (uint32_t l = 0; l < levels; l++) { nv += 3 * nt / 2; nt *= 4; }
    double *pos = calloc(3 * (size_t)nv, sizeof(double));
    uint32_t *tris = calloc(3 * (size_t)nt, sizeof(uint32_t)), *next = calloc(3 * (size_t)nt, sizeof(uint32_t));
    size_t slots = 1;
    while (slots < 4 * (size_t)nv) slots *= 2;
    uint64_t *keys = malloc(slots * sizeof *keys);
    uint32_t *values = malloc(slots * sizeof *values);
    mk_raw_mesh *m = NULL;
    if (!pos || !tris || !next || !keys || !values) goto done;
    const double g = (1 + sqrt(5.0)) / 2;
    const double ico[12][3] = { { -1, g, 0 }, { 1, g, 0 }, { -1, -g, 0 }, { 1, -g, 0 },
                                { 0, -1, g }, { 0, 1, g }, { 0, -1, -g }, { 0, 1, -g },
                                { g, 0, -1 }, { g, 0, 1 }, { -g, 0, -1 }, { -g, 0, 1 } };
    const uint32_t faces[20][3] = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 },
                                    { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
                                    { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 },
                                    { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
    for (int v = 0; v < 12; v++) {
        double l = sqrt(ico[v][0] * ico[v][0] + ico[v][1] * ico[v][1] + ico[v][2] * ico[v][2]);
        for (int c = 0; c < 3; c++) pos[3 * v + c] = ico[v][c] / l;
    }
    memcpy(tris, faces, sizeof faces);
    uint32_t count = 12, tri_count = 20;
    for (uint32_t l = 0; l < levels; l++) {
        memset(keys, 0xff, slots * sizeof *keys);
        for (uint32_t t = 0; t < tri_count; t++) {
            uint32_t a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
            uint32_t ab = midpoint(pos, &count, keys, values, slots, a, b);
            uint32_t bc = midpoint(pos, &count, keys, values, slots, b, c);
            uint32_t ca = midpoint(pos, &count, keys, values, slots, c, a);
            uint32_t quad[12] = { a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca };
            memcpy(next + 12 * (size_t)t, quad, sizeof quad);
        }
        tri_count *= 4;
        uint32_t *swap = tris; tris = next; next = swap;
    }
    m = mk_raw_add_meshes(raw, 1);
    if (!m) goto done;
    m->name = mk_arena_strdup(&raw->arena, name);
    m->vertex_count = nv;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)nv, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)nv, sizeof(float));
    m->triangle_count = nt;
    m->triangles = mk_arena_array(&raw->arena, 3 * (size_t)nt, sizeof(uint32_t));
    m->control_point_count = nv;
    m->control_points = mk_arena_array(&raw->arena, nv, sizeof(uint32_t));
    if (!m->name || !m->positions || !m->normals || !m->triangles || !m->control_points) { m = NULL; goto done; }
    for (uint32_t v = 0; v < nv; v++) m->control_points[v] = v;
    for (size_t i = 0; i < 3 * (size_t)nv; i++) {
        m->positions[i] = radius * (float)pos[i];
        m->normals[i] = (float)pos[i];
    }
    memcpy(m->triangles, tris, 3 * (size_t)nt * sizeof(uint32_t));
done:
    free(pos); free(tris); free(next); free(keys); free(values);
    return m;
}

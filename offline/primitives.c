/* SPDX-License-Identifier: MIT */
#include "primitives.h"
#include <math.h>

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

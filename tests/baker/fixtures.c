/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "mat4.h"
#include "fixtures.h"
#include "primitives.h"

#define PI 3.14159265358979323846

static mk_raw_mesh *new_mesh(mk_raw_asset *raw, const char *name, uint32_t nv, uint32_t nt, int tangents)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = mk_arena_strdup(&raw->arena, name);
    m->vertex_count = nv;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)nv, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)nv, sizeof(float));
    if (tangents) m->tangents = mk_arena_array(&raw->arena, 4 * (size_t)nv, sizeof(float));
    m->triangle_count = nt;
    m->triangles = mk_arena_array(&raw->arena, 3 * (size_t)nt, sizeof(uint32_t));
    m->control_point_count = nv;
    m->control_points = mk_arena_array(&raw->arena, nv, sizeof(uint32_t));
    for (uint32_t v = 0; v < nv; v++) m->control_points[v] = v;
    mk_mat4_identity(m->world);
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = -1;
    m->stacking = MK_STACKING_ADDITIVE;
    return m;
}

mk_raw_mesh *fixture_cylinder(mk_raw_asset *raw, const char *name, float radius, float height,
                              uint32_t segments, uint32_t rings)
{
    uint32_t cols = segments + 1;
    mk_raw_mesh *m = new_mesh(raw, name, cols * (rings + 1), 2 * segments * rings, 1);
    for (uint32_t r = 0; r <= rings; r++)
        for (uint32_t s = 0; s < cols; s++) {
            uint32_t v = r * cols + s;
            double a = 2 * PI * (double)(s % segments) / segments;
            m->positions[3 * v] = radius * (float)cos(a);
            m->positions[3 * v + 1] = radius * (float)sin(a);
            m->positions[3 * v + 2] = height * (float)r / (float)rings;
            m->normals[3 * v] = (float)cos(a);
            m->normals[3 * v + 1] = (float)sin(a);
            m->tangents[4 * v + 2] = 1;
            m->tangents[4 * v + 3] = 1;
        }
    uint32_t t = 0;
    for (uint32_t r = 0; r < rings; r++)
        for (uint32_t s = 0; s < segments; s++) {
            uint32_t a = r * cols + s, b = a + 1, c = a + cols, d = c + 1;
            uint32_t *tri = m->triangles + 6 * (size_t)t++;
            /* counter-clockwise seen from outside */
            tri[0] = a; tri[1] = b; tri[2] = d; tri[3] = a; tri[4] = d; tri[5] = c;
        }
    return m;
}

mk_raw_mesh *fixture_grid(mk_raw_asset *raw, const char *name, float size_x, float size_y,
                          uint32_t nx, uint32_t ny)
{
    mk_raw_mesh *m = new_mesh(raw, name, (nx + 1) * (ny + 1), 2 * nx * ny, 1);
    for (uint32_t j = 0; j <= ny; j++)
        for (uint32_t i = 0; i <= nx; i++) {
            uint32_t v = j * (nx + 1) + i;
            m->positions[3 * v] = size_x * (float)i / (float)nx;
            m->positions[3 * v + 1] = size_y * (float)j / (float)ny;
            m->normals[3 * v + 2] = 1;
            m->tangents[4 * v] = 1;
            m->tangents[4 * v + 3] = 1;
        }
    uint32_t t = 0;
    for (uint32_t j = 0; j < ny; j++)
        for (uint32_t i = 0; i < nx; i++) {
            uint32_t a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
            uint32_t *tri = m->triangles + 6 * (size_t)t++;
            tri[0] = a; tri[1] = b; tri[2] = d; tri[3] = a; tri[4] = d; tri[5] = c;
        }
    return m;
}

mk_raw_mesh *fixture_sphere(mk_raw_asset *raw, const char *name, float radius, uint32_t segments,
                            uint32_t rings)
{
    /* vertex 0: south pole, then (rings - 1) latitude rings of `segments`, then north pole */
    uint32_t nv = 2 + segments * (rings - 1);
    uint32_t nt = 2 * segments * (rings - 1);
    mk_raw_mesh *m = new_mesh(raw, name, nv, nt, 0);
    uint32_t north = nv - 1;
    m->positions[2] = -radius; m->normals[2] = -1;
    m->positions[3 * north + 2] = radius; m->normals[3 * north + 2] = 1;
    for (uint32_t r = 1; r < rings; r++)
        for (uint32_t s = 0; s < segments; s++) {
            uint32_t v = 1 + (r - 1) * segments + s;
            double th = PI * (double)r / rings - PI / 2, ph = 2 * PI * (double)s / segments;
            double n[3] = { cos(th) * cos(ph), cos(th) * sin(ph), sin(th) };
            for (int c = 0; c < 3; c++) {
                m->positions[3 * v + (uint32_t)c] = radius * (float)n[c];
                m->normals[3 * v + (uint32_t)c] = (float)n[c];
            }
        }
    uint32_t t = 0;
    for (uint32_t s = 0; s < segments; s++) {
        uint32_t a = 1 + s, b = 1 + (s + 1) % segments;
        uint32_t *tri = m->triangles + 3 * (size_t)t++;
        tri[0] = 0; tri[1] = b; tri[2] = a;
        uint32_t base = 1 + (rings - 2) * segments;
        tri = m->triangles + 3 * (size_t)t++;
        tri[0] = north; tri[1] = base + s; tri[2] = base + (s + 1) % segments;
    }
    for (uint32_t r = 1; r + 1 < rings; r++)
        for (uint32_t s = 0; s < segments; s++) {
            uint32_t a = 1 + (r - 1) * segments + s, b = 1 + (r - 1) * segments + (s + 1) % segments;
            uint32_t c = a + segments, d = b + segments;
            uint32_t *tri = m->triangles + 3 * (size_t)t++;
            tri[0] = a; tri[1] = b; tri[2] = d;
            tri = m->triangles + 3 * (size_t)t++;
            tri[0] = a; tri[1] = d; tri[2] = c;
        }
    return m;
}

mk_raw_mesh *fixture_icosphere(mk_raw_asset *raw, const char *name, float radius, uint32_t levels)
{
    return mk_raw_add_icosphere(raw, name, radius, levels);
}

uint32_t fixture_select_z(const mk_raw_mesh *mesh, float lo, float hi, uint32_t *out)
{
    uint32_t count = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        float z = mesh->positions[3 * (size_t)v + 2];
        if (z > lo && z < hi) out[count++] = v;
    }
    return count;
}

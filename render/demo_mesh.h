/* SPDX-License-Identifier: MIT */
/* Generated meshes for the render benchmark and demo (not part of the library). */
#ifndef MKR_DEMO_MESH_H
#define MKR_DEMO_MESH_H

#include <stdint.h>

typedef struct demo_mesh {
    uint32_t vertex_count, triangle_count;
    float *positions, *normals;   /* 3 per vertex */
    uint32_t *triangles;          /* 3 per triangle, counter-clockwise seen from outside */
} demo_mesh;

/* Unit sphere: an icosahedron split `level` times (10 * 4^level + 2 vertices, 20 * 4^level
 * triangles), normals = positions. Returns 0 when out of memory. */
int demo_icosphere(int level, demo_mesh *out);
void demo_mesh_free(demo_mesh *mesh);

/* Area-weighted vertex normals (unit length) of a triangle mesh. */
void demo_vertex_normals(const float *positions, uint32_t vertex_count, const uint32_t *triangles,
                         uint32_t triangle_count, float *normals);

/* out = base pushed outward along its normal by amount * exp(-(angle to dir / width)^2):
 * a smooth bump on a unit sphere around direction dir (unit). */
void demo_bulge(const float *base, uint32_t vertex_count, const float dir[3], float amount, float width, float *out);

#endif

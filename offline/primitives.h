/* SPDX-License-Identifier: MIT */
/* Meshes made by code for examples, seeds and tests. */
#ifndef MK_PRIMITIVES_H
#define MK_PRIMITIVES_H

#include "raw.h"

/* Adds an open tube along +y to raw: radius 0.5, y from 0 to 2, `segments` vertices around
 * (≥ 3) and `rings` + 1 rows of them (`rings` ≥ 1), outward normals, two triangles a quad,
 * named `name` (copied). Returns the mesh, or NULL when memory runs out (the arena records it). */
mk_raw_mesh *mk_raw_add_tube(mk_raw_asset *raw, const char *name, uint32_t segments, uint32_t rings);

/* Adds a closed icosphere: the icosahedron with every triangle split in four `levels` times
 * (10 * 4^levels + 2 vertices), new vertices pushed onto the sphere of radius `radius`,
 * outward normals and winding, one control point per vertex. NULL when memory runs out. */
mk_raw_mesh *mk_raw_add_icosphere(mk_raw_asset *raw, const char *name, float radius, uint32_t levels);

#endif

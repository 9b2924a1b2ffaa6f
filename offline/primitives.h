/* SPDX-License-Identifier: MIT */
/* Meshes made by code for examples, seeds and tests. */
#ifndef MK_PRIMITIVES_H
#define MK_PRIMITIVES_H

#include "raw.h"

/* Adds an open tube along +y to raw: radius 0.5, y from 0 to 2, `segments` vertices around
 * (≥ 3) and `rings` + 1 rows of them (`rings` ≥ 1), outward normals, two triangles a quad,
 * named `name` (copied). Returns the mesh, or NULL when memory runs out (the arena records it). */
mk_raw_mesh *mk_raw_add_tube(mk_raw_asset *raw, const char *name, uint32_t segments, uint32_t rings);

#endif

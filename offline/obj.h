/* SPDX-License-Identifier: MIT */
/* Reading Wavefront OBJ: vertices ("v"), normals ("vn", kept when there is one per vertex)
 * and faces ("f", polygons fan-triangulated, negative indices relative). */
#ifndef MK_OBJ_H
#define MK_OBJ_H

#include "alloc.h"

typedef struct mk_obj {
    uint32_t vertex_count;
    double *positions;       /* 3 per vertex */
    double *normals;         /* 3 per vertex, or NULL */
    uint32_t triangle_count;
    uint32_t *triangles;     /* 3 per triangle, 0-based */
} mk_obj;

/* Reads path into arena memory; errors name the file and line. */
mk_result mk_obj_read(const char *path, mk_arena *arena, mk_obj *out, mk_error *err);

#endif

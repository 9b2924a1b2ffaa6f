/* SPDX-License-Identifier: MIT */
/* FBX 7 objects and connections for a raw asset's channels and clips (fbx_objects.c): the
 * write-back adds them to the file a bake came from, the export to a file made from nothing. */
#ifndef MK_FBX_OBJECTS_H
#define MK_FBX_OBJECTS_H

#include "fbx_node_write.h"
#include "fbx_write.h"

typedef struct fbx_objects {
    mk_arena *a;                 /* the nodes' arena */
    mk_error *err;
    int binary;                  /* names spelled for a binary file, else for ASCII */
    int ascii_float_bits;        /* ASCII 7.2+: KeyAttrDataFloat as int32 bit patterns */
    double ticks;                /* KTime ticks per second of the file (fbx_doc_ticks) */
    int blender;                 /* the file's Creator is Blender's exporter (fbx_objects.c) */
    int64_t next_id;             /* the next new object's id */
    fbx_wnode **objects, **connections;   /* new Objects and Connections children, in order */
    uint32_t object_count, object_cap, connection_count, connection_cap;
    mk_fbx_write_report *report;
} fbx_objects;

mk_result fbx_objects_oom(fbx_objects *o);
/* A new object "type: id, "class::name", subclass" appended to o->objects; *id is its id. */
fbx_wnode *fbx_object_new(fbx_objects *o, const char *type, const char *cls, const char *name, const char *sub,
                          int64_t *id);
/* C: kind ("OO" or "OP"), child, parent[, property]. 0 when out of memory. */
int fbx_object_connect(fbx_objects *o, const char *kind, int64_t child, int64_t parent, const char *property);
/* MK_OK when the file can hold `name` (ASCII names cannot hold a quote or a line break). */
mk_result fbx_object_check_name(fbx_objects *o, const char *what, const char *name);

/* Per control point of m, the number of its render vertices (checks the map), and the delta
 * tolerance between render vertices of one control point (1e-6 of the diagonal). */
mk_result fbx_objects_mesh(fbx_objects *o, const mk_raw_mesh *m, uint32_t **render_count, double *tolerance);
/* Channel ch of mesh m as a BlendShapeChannel with its Shapes, connected to blend_shape. */
mk_result fbx_objects_add_channel(fbx_objects *o, const mk_raw_mesh *m, const uint32_t *render_count, double tolerance,
                                  const mk_raw_channel *ch, int64_t blend_shape, int64_t *channel_id);
/* A clip as an animation stack; channel_ids: the FBX object each raw channel's weight is a
 * property of, channel_props: that property's name per channel (NULL: "DeformPercent"). */
mk_result fbx_objects_add_clip(fbx_objects *o, const mk_raw_clip *clip, const int64_t *channel_ids,
                               const char *const *channel_props);
/* The deltas of target t of channel ch on control points (fbx_objects.c's rule): *count entries,
 * indexes increasing, 3 doubles each; a target that moves nothing gives one zero entry. */
mk_result fbx_objects_target(fbx_objects *o, const mk_raw_mesh *m, const uint32_t *render_count, const mk_raw_channel *ch,
                             uint32_t t, double tolerance, int32_t **indexes, double **deltas, uint32_t *count);

#endif

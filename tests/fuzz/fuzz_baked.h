/* SPDX-License-Identifier: MIT */
/* The made-up bake of the importer fuzz targets' write-back step (fuzz_fbx.c, fuzz_gltf.c):
 * one baked channel (origin "{}") per raw mesh that moves the render vertices of control point
 * 0 (FBX) / glTF vertex 0 by 0.25 along x, so every instance of a mesh is baked alike. The
 * channels and their targets are named "fuzz_written". */
#ifndef MK_FUZZ_BAKED_H
#define MK_FUZZ_BAKED_H

#include <string.h>
#include "raw.h"

/* Returns the number of channels added (they are the asset's last). */
static uint32_t fuzz_add_baked_channels(mk_raw_asset *raw)
{
    uint32_t added = 0;
    for (uint32_t m = 0; m < raw->mesh_count; m++) {
        const mk_raw_mesh *mesh = &raw->meshes[m];
        uint32_t count = 0;
        for (uint32_t v = 0; mesh->control_points && v < mesh->vertex_count; v++) count += mesh->control_points[v] == 0;
        if (!count) continue;
        mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
        if (!ch) break;
        ch->name = "fuzz_written";
        ch->origin = "{}";
        ch->mesh = m;
        mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
        if (!t) { raw->channel_count--; break; }
        t->name = "fuzz_written";
        t->full_weight = 1;
        t->count = count;
        t->indices = mk_arena_array(&raw->arena, count, sizeof *t->indices);
        t->positions = mk_arena_array(&raw->arena, count, 3 * sizeof *t->positions);
        if (!t->indices || !t->positions) { raw->channel_count--; break; }
        memset(t->positions, 0, (size_t)count * 3 * sizeof *t->positions);
        count = 0;
        for (uint32_t v = 0; v < mesh->vertex_count; v++) {
            if (mesh->control_points[v] != 0) continue;
            t->indices[count] = v;
            t->positions[3 * count] = 0.25f;
            count++;
        }
        added++;
    }
    return added;
}

#endif

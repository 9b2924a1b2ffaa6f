/* SPDX-License-Identifier: MIT */
/* mk_read_blob: an opened .morph asset back into a raw model (deltas dequantized, each
 * entry by its own precision). An entry's mask may cover vertices a target does not move (the
 * writer may fill short gaps), stored as zeros; all-zero vertices are dropped again (a vertex the author stored with a zero delta is indistinguishable from that
 * padding, and moves nothing). */
#include <stdio.h>
#include <string.h>
#include "blob_io.h"
#include "format.h"

static void *copy(mk_arena *arena, const void *src, size_t n)
{
    void *p = mk_arena_alloc(arena, n ? n : 1);
    if (p && n) memcpy(p, src, n);
    return p;
}

/* Component c (0-2) of attribute `attribute` of the j-th vertex of an entry (docs/format.md):
 * the packed value (offset + u) times the step from the entry's layout, or (layout NULL) the
 * float32 triple from p, the entry's data. */
static float decode(const mk_blob_entry *en, const mk_packed_layout *layout, const uint8_t *p, uint32_t mesh_flags,
                    uint32_t target_flags, uint32_t attribute, uint32_t c, uint32_t j, float step)
{
    if (layout) {
        const uint32_t k = mk_attribute_component(mesh_flags, attribute) + c;
        return (float)(layout->offset[k] + (int32_t)mk_unpack(layout->at[k], layout->width[k], j)) * step;
    }
    const uint32_t before = attribute == 0 ? 0u : attribute == 1 ? 1u : 1u + ((target_flags & MK_TARGET_HAS_NORMALS) ? 1u : 0u);
    float f;
    memcpy(&f, p + 12u * ((size_t)before * mk_popcount64(en->mask) + j) + 4u * c, 4);
    return f;
}

static mk_result read_target(const mk_asset *a, const mk_blob_mesh *bm, uint32_t local, mk_raw_target *t,
                             mk_arena *arena, mk_error *err)
{
    const mk_blob_target *bt = &a->targets[bm->first_target + local];
    const uint32_t *block_first = (const uint32_t *)(a->data + bm->block_entries);
    const uint8_t *entries = a->data + bm->entries;
    const uint32_t stride = mk_entry_stride(bm->flags);
    const int hn = (bt->flags & MK_TARGET_HAS_NORMALS) != 0, ht = (bt->flags & MK_TARGET_HAS_TANGENTS) != 0;
    uint64_t capacity = 0;
    for (uint64_t e = 0; e < bm->entry_count; e++)
        if (mk_entry_target(mk_entry_at(entries, stride, e)) == local)
            capacity += (uint64_t)mk_popcount64(mk_entry_at(entries, stride, e)->mask);
    t->indices = mk_arena_array(arena, capacity + 1, sizeof(uint32_t));
    t->positions = mk_arena_array(arena, 3 * capacity + 3, sizeof(float));
    t->normals = hn ? mk_arena_array(arena, 3 * capacity + 3, sizeof(float)) : NULL;
    t->tangents = ht ? mk_arena_array(arena, 3 * capacity + 3, sizeof(float)) : NULL;
    if (!t->indices || !t->positions || (hn && !t->normals) || (ht && !t->tangents))
        return mk_error_oom(err, "reading target deltas");
    uint32_t n = 0;
    for (uint32_t b = 0; b < bm->block_count; b++) {
        for (uint32_t e = block_first[b]; e < block_first[b + 1]; e++) {
            const mk_blob_entry *en = mk_entry_at(entries, stride, e);
            if (mk_entry_target(en) != local) continue;
            const int q = mk_entry_packed(en);   /* per entry: a quantized target's outliers are float */
            const uint8_t *p = a->data + bm->target_data + (size_t)en->data * MK_DATA_UNIT;
            mk_packed_layout layout;
            if (q) mk_packed_layout_of(&layout, en, mk_mesh_components(bm->flags), p);
            const mk_packed_layout *pl = q ? &layout : NULL;
            uint32_t j = 0;
            for (uint64_t bits = en->mask; bits; bits &= bits - 1, j++) {
                float pv[3], nv[3] = { 0, 0, 0 }, tv[3] = { 0, 0, 0 };
                int nonzero = 0;
                for (uint32_t c = 0; c < 3; c++) {
                    pv[c] = decode(en, pl, p, bm->flags, bt->flags, 0, c, j, q ? bt->position_scale : 1.0f);
                    if (hn) nv[c] = decode(en, pl, p, bm->flags, bt->flags, 1, c, j, q ? bt->normal_scale : 1.0f);
                    if (ht) tv[c] = decode(en, pl, p, bm->flags, bt->flags, 2, c, j, q ? bt->tangent_scale : 1.0f);
                    nonzero |= pv[c] != 0 || nv[c] != 0 || tv[c] != 0;
                }
                if (!nonzero) continue;   /* a vertex the mask covers but the target does not move */
                t->indices[n] = b * MK_BLOCK_SIZE + mk_ctz64(bits);
                memcpy(&t->positions[3u * n], pv, sizeof pv);
                if (hn) memcpy(&t->normals[3u * n], nv, sizeof nv);
                if (ht) memcpy(&t->tangents[3u * n], tv, sizeof tv);
                n++;
            }
        }
    }
    t->count = n;
    return MK_OK;
}

mk_result mk_read_blob(const mk_asset *a, mk_raw_asset *out, mk_error *err)
{
    mk_arena *arena = &out->arena;
    if (a->mesh_count && !mk_raw_add_meshes(out, a->mesh_count)) return mk_error_oom(err, "reading meshes");
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const mk_blob_mesh *bm = &a->meshes[i];
        mk_raw_mesh *m = &out->meshes[i];
        m->name = mk_arena_strdup(arena, a->strings + bm->name);
        m->vertex_count = bm->vertex_count;
        m->positions = copy(arena, a->data + bm->positions, 12u * (size_t)bm->vertex_count);
        if (bm->flags & MK_MESH_HAS_NORMALS) m->normals = copy(arena, a->data + bm->normals, 12u * (size_t)bm->vertex_count);
        if (bm->flags & MK_MESH_HAS_TANGENTS) m->tangents = copy(arena, a->data + bm->tangents, 16u * (size_t)bm->vertex_count);
        m->triangle_count = bm->triangle_count;
        m->triangles = copy(arena, a->data + bm->triangles, 12u * (size_t)bm->triangle_count);
        m->control_point_count = bm->control_point_count;
        m->control_points = copy(arena, a->data + bm->control_points, 4u * (size_t)bm->vertex_count);
        memcpy(m->world, bm->world, sizeof m->world);
        m->gltf_node = bm->gltf_node;
        m->gltf_mesh = bm->gltf_mesh;
        m->gltf_primitive = bm->gltf_primitive;
        m->stacking = (mk_stacking)bm->stacking;
        if (!m->name || !m->positions || !m->triangles || !m->control_points
            || ((bm->flags & MK_MESH_HAS_NORMALS) && !m->normals) || ((bm->flags & MK_MESH_HAS_TANGENTS) && !m->tangents))
            return mk_error_oom(err, "reading mesh arrays");
    }
    if (a->channel_count && !mk_raw_add_channels(out, a->channel_count)) return mk_error_oom(err, "reading channels");
    for (uint32_t c = 0; c < a->channel_count; c++) {
        const mk_blob_channel *bc = &a->channels[c];
        const mk_blob_mesh *bm = &a->meshes[bc->mesh];
        mk_raw_channel *ch = &out->channels[c];
        ch->name = mk_arena_strdup(arena, a->strings + bc->name);
        ch->origin = mk_arena_strdup(arena, a->strings + bc->origin);
        ch->mesh = bc->mesh;
        ch->default_weight = bc->default_weight;
        if (!ch->name || !ch->origin || !mk_raw_add_targets(out, ch, bc->target_count))
            return mk_error_oom(err, "reading channels");
        for (uint32_t k = 0; k < bc->target_count; k++) {
            const mk_blob_target *bt = &a->targets[bc->first_target + k];
            mk_raw_target *t = &ch->targets[k];
            t->name = mk_arena_strdup(arena, a->strings + bt->name);
            t->full_weight = bt->full_weight;
            if (!t->name) return mk_error_oom(err, "reading target names");
            mk_result r = read_target(a, bm, bc->first_target + k - bm->first_target, t, arena, err);
            if (r) return r;
        }
    }
    if (a->clip_count && !mk_raw_add_clips(out, a->clip_count)) return mk_error_oom(err, "reading clips");
    for (uint32_t i = 0; i < a->clip_count; i++) {
        const mk_blob_clip *bc = &a->clips[i];
        mk_raw_clip *clip = &out->clips[i];
        clip->name = mk_arena_strdup(arena, a->strings + bc->name);
        clip->start = bc->start;
        clip->duration = bc->duration;
        clip->track_count = bc->track_count;
        clip->tracks = mk_arena_array(arena, bc->track_count + 1u, sizeof(mk_raw_track));
        if (!clip->name || !clip->tracks) return mk_error_oom(err, "reading clips");
        for (uint32_t t = 0; t < bc->track_count; t++) {
            const mk_blob_track *bt = &a->tracks[bc->first_track + t];
            clip->tracks[t].channel = bt->channel;
            clip->tracks[t].key_count = bt->key_count;
            clip->tracks[t].keys = copy(arena, &a->keys[bt->first_key], (size_t)bt->key_count * sizeof(mk_key));
            if (!clip->tracks[t].keys) return mk_error_oom(err, "reading keys");
        }
    }
    snprintf(out->source_format, sizeof out->source_format, "morph v%u", MK_FORMAT_VERSION);
    return MK_OK;
}

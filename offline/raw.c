/* SPDX-License-Identifier: MIT */
/* The raw model: growth helpers, warnings, ordering and validation. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "mat4.h"
#include "raw.h"

void mk_raw_init(mk_raw_asset *raw, const mk_allocator *allocator)
{
    memset(raw, 0, sizeof *raw);
    mk_arena_init(&raw->arena, allocator);
    raw->up_axis = -1;
}

void mk_raw_free(mk_raw_asset *raw)
{
    mk_arena_free_all(&raw->arena);
    mk_arena saved = raw->arena;
    memset(raw, 0, sizeof *raw);
    raw->arena = saved;
    raw->up_axis = -1;
}

/* Grows *array of *count elements by add, zeroing the new ones. */
static void *grow(mk_raw_asset *raw, void **array, uint32_t *count, uint32_t add, size_t elem)
{
    if (add > UINT32_MAX - *count) return NULL;
    void *p = mk_arena_realloc(&raw->arena, *array, (size_t)*count * elem, ((size_t)*count + add) * elem);
    if (!p) return NULL;
    *array = p;
    void *first = (char *)p + (size_t)*count * elem;
    *count += add;
    return first;
}

mk_raw_mesh *mk_raw_add_meshes(mk_raw_asset *raw, uint32_t count)
{
    mk_raw_mesh *m = grow(raw, (void **)&raw->meshes, &raw->mesh_count, count, sizeof *m);
    for (uint32_t i = 0; m && i < count; i++) {
        mk_mat4_identity(m[i].world);
        m[i].gltf_node = m[i].gltf_mesh = m[i].gltf_primitive = -1;
        m[i].stacking = MK_STACKING_ADDITIVE;
    }
    return m;
}

mk_raw_channel *mk_raw_add_channels(mk_raw_asset *raw, uint32_t count)
{
    return grow(raw, (void **)&raw->channels, &raw->channel_count, count, sizeof(mk_raw_channel));
}

mk_raw_clip *mk_raw_add_clips(mk_raw_asset *raw, uint32_t count)
{
    return grow(raw, (void **)&raw->clips, &raw->clip_count, count, sizeof(mk_raw_clip));
}

mk_raw_target *mk_raw_add_targets(mk_raw_asset *raw, mk_raw_channel *channel, uint32_t count)
{
    mk_raw_target *t = grow(raw, (void **)&channel->targets, &channel->target_count, count, sizeof *t);
    for (uint32_t i = 0; t && i < count; i++) t[i].full_weight = 1.0f;
    return t;
}

void mk_raw_warn(mk_raw_asset *raw, const char *fmt, ...)
{
    uint32_t index = raw->warning_count++;
    if (index >= MK_RAW_MAX_WARNINGS) return;
    if (!raw->warnings) {
        raw->warnings = mk_arena_array(&raw->arena, MK_RAW_MAX_WARNINGS, sizeof(mk_raw_warning));
        if (!raw->warnings) return;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(raw->warnings[index].message, sizeof raw->warnings[index].message, fmt, ap);
    va_end(ap);
}

void mk_raw_sort_targets(mk_raw_asset *raw)
{
    for (uint32_t c = 0; c < raw->channel_count; c++) {
        mk_raw_channel *ch = &raw->channels[c];
        /* Insertion sort: stable, and channels have few targets. */
        for (uint32_t i = 1; i < ch->target_count; i++) {
            mk_raw_target t = ch->targets[i];
            uint32_t j = i;
            while (j > 0 && ch->targets[j - 1].full_weight > t.full_weight) {
                ch->targets[j] = ch->targets[j - 1];
                j--;
            }
            ch->targets[j] = t;
        }
    }
}

mk_result mk_raw_group_channels(mk_raw_asset *raw, mk_error *err)
{
    uint32_t n = raw->channel_count;
    if (n == 0) return MK_OK;
    uint32_t *order = mk_arena_array(&raw->arena, n, sizeof *order);   /* new -> old */
    uint32_t *remap = mk_arena_array(&raw->arena, n, sizeof *remap);   /* old -> new */
    mk_raw_channel *sorted = mk_arena_array(&raw->arena, n, sizeof *sorted);
    if (!order || !remap || !sorted) {
        mk_arena_release(&raw->arena, order);
        mk_arena_release(&raw->arena, remap);
        mk_arena_release(&raw->arena, sorted);
        return mk_error_oom(err, "grouping channels by mesh");
    }
    uint32_t k = 0;
    for (uint32_t m = 0; m < raw->mesh_count; m++)
        for (uint32_t c = 0; c < n; c++)
            if (raw->channels[c].mesh == m) order[k++] = c;
    if (k != n) {
        mk_arena_release(&raw->arena, order);
        mk_arena_release(&raw->arena, remap);
        mk_arena_release(&raw->arena, sorted);
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "a channel names a mesh index past the %u meshes",
                            raw->mesh_count);
    }
    for (uint32_t i = 0; i < n; i++) { sorted[i] = raw->channels[order[i]]; remap[order[i]] = i; }
    memcpy(raw->channels, sorted, n * sizeof *sorted);
    for (uint32_t c = 0; c < raw->clip_count; c++)
        for (uint32_t t = 0; t < raw->clips[c].track_count; t++)
            if (raw->clips[c].tracks[t].channel < n)
                raw->clips[c].tracks[t].channel = remap[raw->clips[c].tracks[t].channel];
    mk_arena_release(&raw->arena, order);
    mk_arena_release(&raw->arena, remap);
    mk_arena_release(&raw->arena, sorted);
    return MK_OK;
}

void mk_raw_drop_plain_meshes(mk_raw_asset *raw, const char *what)
{
    uint32_t kept = 0;
    for (uint32_t m = 0; m < raw->mesh_count; m++) {
        int has_channels = 0;
        for (uint32_t c = 0; c < raw->channel_count && !has_channels; c++) has_channels = raw->channels[c].mesh == m;
        if (!has_channels) {
            mk_raw_warn(raw, "mesh '%s' has no morph targets; %s", raw->meshes[m].name ? raw->meshes[m].name : "",
                        what ? what : "skipped");
            continue;
        }
        for (uint32_t c = 0; c < raw->channel_count; c++)
            if (raw->channels[c].mesh == m) raw->channels[c].mesh = kept;
        raw->meshes[kept++] = raw->meshes[m];
    }
    raw->mesh_count = kept;
}

void mk_raw_drop_target_normals(mk_raw_asset *raw)
{
    for (uint32_t c = 0; c < raw->channel_count; c++)
        for (uint32_t k = 0; k < raw->channels[c].target_count; k++) {
            mk_raw_target *t = &raw->channels[c].targets[k];
            mk_arena_release(&raw->arena, t->normals);
            t->normals = NULL;
        }
}

static int finite_array(const float *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(p[i])) return 0;
    return 1;
}

static mk_result validate_mesh(const mk_raw_mesh *m, uint32_t i, mk_error *err)
{
    const char *name = m->name ? m->name : "";
    if (m->vertex_count == 0 || !m->positions)
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "mesh %u '%s': no vertices", i, name);
    if (!finite_array(m->positions, 3 * (size_t)m->vertex_count))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "mesh %u '%s': a base position is NaN or infinite", i, name);
    if (m->normals && !finite_array(m->normals, 3 * (size_t)m->vertex_count))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "mesh %u '%s': a base normal is NaN or infinite", i, name);
    if (m->tangents && !finite_array(m->tangents, 4 * (size_t)m->vertex_count))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "mesh %u '%s': a base tangent is NaN or infinite", i, name);
    if (m->triangle_count && !m->triangles)
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "mesh %u '%s': triangle count without triangles", i, name);
    for (size_t k = 0; k < 3 * (size_t)m->triangle_count; k++)
        if (m->triangles[k] >= m->vertex_count)
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "mesh %u '%s': triangle %zu uses vertex %u of %u",
                                i, name, k / 3, m->triangles[k], m->vertex_count);
    if (m->control_points) {
        for (uint32_t k = 0; k < m->vertex_count; k++)
            if (m->control_points[k] >= m->control_point_count)
                return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                                    "mesh %u '%s': vertex %u maps to control point %u of %u", i, name, k,
                                    m->control_points[k], m->control_point_count);
    }
    if (!finite_array(m->world, 16))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "mesh %u '%s': world transform is not finite", i, name);
    if (m->stacking != MK_STACKING_ADDITIVE && m->stacking != MK_STACKING_SEQUENTIAL)
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "mesh %u '%s': stacking must be additive or sequential", i, name);
    return MK_OK;
}

static mk_result validate_target(const mk_raw_asset *raw, const mk_raw_channel *ch, uint32_t c, uint32_t k,
                                 mk_error *err)
{
    const mk_raw_target *t = &ch->targets[k];
    const mk_raw_mesh *m = &raw->meshes[ch->mesh];
    const char *cn = ch->name ? ch->name : "";
    if (!isfinite(t->full_weight) || fabsf(t->full_weight) < MK_MIN_FULL_WEIGHT_GAP)
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                            "channel %u '%s' target %u: full weight %g must be finite and at least 1e-6 away from 0",
                            c, cn, k, (double)t->full_weight);
    if (k > 0 && !(t->full_weight - ch->targets[k - 1].full_weight >= MK_MIN_FULL_WEIGHT_GAP))
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                            "channel %u '%s' target %u: full weight %g does not increase (previous %g)", c, cn, k,
                            (double)t->full_weight, (double)ch->targets[k - 1].full_weight);
    if (t->count && (!t->indices || !t->positions))
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "channel %u '%s' target %u: missing indices or deltas", c, cn, k);
    for (uint32_t j = 0; j < t->count; j++) {
        if (t->indices[j] >= m->vertex_count)
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "channel %u '%s' target %u: index %u past %u vertices",
                                c, cn, k, t->indices[j], m->vertex_count);
        if (j > 0 && t->indices[j] <= t->indices[j - 1])
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                                "channel %u '%s' target %u: indices not strictly increasing at entry %u", c, cn, k, j);
    }
    if (!finite_array(t->positions, 3 * (size_t)t->count)
        || (t->normals && !finite_array(t->normals, 3 * (size_t)t->count))
        || (t->tangents && !finite_array(t->tangents, 3 * (size_t)t->count)))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "channel %u '%s' target %u: a delta is NaN or infinite", c, cn, k);
    if ((t->normals && !m->normals) || (t->tangents && !m->tangents))
        return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                            "channel %u '%s' target %u: normal/tangent deltas on a mesh without base normals/tangents", c, cn, k);
    return MK_OK;
}

mk_result mk_raw_validate(const mk_raw_asset *raw, mk_error *err)
{
    mk_result r;
    for (uint32_t i = 0; i < raw->mesh_count; i++)
        if ((r = validate_mesh(&raw->meshes[i], i, err))) return r;
    for (uint32_t c = 0; c < raw->channel_count; c++) {
        const mk_raw_channel *ch = &raw->channels[c];
        if (ch->mesh >= raw->mesh_count)
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "channel %u '%s': mesh %u does not exist", c,
                                ch->name ? ch->name : "", ch->mesh);
        if (c > 0 && ch->mesh < raw->channels[c - 1].mesh)
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                                "channel %u: channels are not grouped by mesh (call mk_raw_group_channels)", c);
        if (ch->target_count == 0)
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "channel %u '%s': has no targets", c, ch->name ? ch->name : "");
        if (!isfinite(ch->default_weight))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "channel %u '%s': default weight is not finite", c,
                                ch->name ? ch->name : "");
        for (uint32_t k = 0; k < ch->target_count; k++)
            if ((r = validate_target(raw, ch, c, k, err))) return r;
    }
    for (uint32_t i = 0; i < raw->clip_count; i++) {
        const mk_raw_clip *clip = &raw->clips[i];
        if (!isfinite(clip->start) || !isfinite(clip->duration))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "clip %u: start/duration not finite", i);
        if (clip->duration < 0)  /* as mk_asset_open judges the blob it would become */
            return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "clip %u: negative duration %g", i, (double)clip->duration);
        for (uint32_t t = 0; t < clip->track_count; t++) {
            const mk_raw_track *tr = &clip->tracks[t];
            if (tr->channel >= raw->channel_count)
                return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "clip %u track %u: channel %u does not exist", i, t, tr->channel);
            if (tr->key_count == 0 || !tr->keys)
                return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "clip %u track %u: no keys", i, t);
            for (uint32_t k = 0; k < tr->key_count; k++) {
                const mk_key *key = &tr->keys[k];
                if (!isfinite(key->time) || !isfinite(key->value) || !isfinite(key->left_slope)
                    || !isfinite(key->right_slope))
                    return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "clip %u track %u key %u: not finite", i, t, k);
                if (key->interp >= MK_INTERP_COUNT)
                    return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "clip %u track %u key %u: unknown interpolation", i, t, k);
                if (!(key->left_weight > 0 && key->left_weight <= 1 && key->right_weight > 0 && key->right_weight <= 1))
                    return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                                        "clip %u track %u key %u: tangent weights must be in (0, 1] (1/3 = Hermite)", i, t, k);
                if (k > 0 && !(key->time > key[-1].time))
                    return mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX,
                                        "clip %u track %u key %u: time %g does not increase", i, t, k, (double)key->time);
            }
        }
    }
    return MK_OK;
}

float mk_raw_mesh_diagonal(const mk_raw_mesh *m)
{
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int d = 0; d < 3; d++) {
            float x = m->positions[3u * v + (uint32_t)d];
            lo[d] = x < lo[d] ? x : lo[d];
            hi[d] = x > hi[d] ? x : hi[d];
        }
    float s = 0;
    for (int d = 0; d < 3; d++) s += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    return sqrtf(s);
}

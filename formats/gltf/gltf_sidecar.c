/* SPDX-License-Identifier: MIT */
/* The glTF channel sidecar (format: docs/importing-gltf.md). glTF has no in-between
 * concept, so `morphkit export` writes each progressive channel as several glTF targets and this
 * JSON file says which targets form which channel, with their full weights; re-import restores
 * the channels. Every field is checked; errors name the JSON path. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cjson/cJSON.h>
#include "gltf_internal.h"

typedef struct parser {
    mk_arena *arena;
    const char *where;
    mk_error *err;
} parser;

static mk_result fail(parser *p, const char *path, const char *what)
{
    return mk_error_set(p->err, MK_ERROR_PARSE, UINT64_MAX, "%s: %s: %s", p->where, path, what);
}

static mk_result get_uint(parser *p, const cJSON *o, const char *key, const char *path, int required, uint32_t *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) return required ? fail(p, path, key) : MK_OK;
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0 && v->valuedouble <= 4294967295.0) || v->valuedouble != floor(v->valuedouble))
        return fail(p, path, "expected a non-negative integer");
    *out = (uint32_t)v->valuedouble;
    return MK_OK;
}

static mk_result uint_array(parser *p, const cJSON *a, const char *path, uint32_t **out, uint32_t *count)
{
    if (!cJSON_IsArray(a)) return fail(p, path, "expected an array");
    int n = cJSON_GetArraySize(a);
    *out = mk_arena_array(p->arena, (size_t)n + 1, sizeof **out);
    if (!*out) return mk_error_oom(p->err, "sidecar");
    int i = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, a) {
        if (!cJSON_IsNumber(e) || !(e->valuedouble >= 0 && e->valuedouble <= 4294967295.0) || e->valuedouble != floor(e->valuedouble))
            return fail(p, path, "expected non-negative integers");
        (*out)[i++] = (uint32_t)e->valuedouble;
    }
    *count = (uint32_t)n;
    return MK_OK;
}

static const char *dup_string(parser *p, const cJSON *v)
{
    return cJSON_IsString(v) && v->valuestring ? mk_arena_strdup(p->arena, v->valuestring) : NULL;
}

static mk_result parse_channel(parser *p, const cJSON *o, const char *path, mk_gltf_sidecar_channel *ch)
{
    if (!cJSON_IsObject(o)) return fail(p, path, "channel must be an object");
    ch->name = dup_string(p, cJSON_GetObjectItemCaseSensitive(o, "name"));
    if (!ch->name) return fail(p, path, "channel needs a string \"name\"");
    ch->origin = dup_string(p, cJSON_GetObjectItemCaseSensitive(o, "origin"));
    mk_result r = uint_array(p, cJSON_GetObjectItemCaseSensitive(o, "targets"), path, &ch->targets, &ch->target_count);
    if (r != MK_OK) return r;
    if (ch->target_count == 0) return fail(p, path, "channel has no targets");
    const cJSON *fw = cJSON_GetObjectItemCaseSensitive(o, "full_weights");
    ch->full_weights = mk_arena_array(p->arena, ch->target_count, sizeof(float));
    if (!ch->full_weights) return mk_error_oom(p->err, "sidecar");
    if (!fw) {
        if (ch->target_count != 1) return fail(p, path, "\"full_weights\" required for several targets");
        ch->full_weights[0] = 1.0f;
    } else {
        if (!cJSON_IsArray(fw) || (uint32_t)cJSON_GetArraySize(fw) != ch->target_count)
            return fail(p, path, "\"full_weights\" must have one number per target");
        uint32_t i = 0;
        const cJSON *e;
        cJSON_ArrayForEach(e, fw) {
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || e->valuedouble == 0.0 || fabs(e->valuedouble) > 1e6)
                return fail(p, path, "full weights must be finite and nonzero");
            ch->full_weights[i++] = (float)e->valuedouble;
        }
    }
    const cJSON *tn = cJSON_GetObjectItemCaseSensitive(o, "target_names");
    if (tn) {
        if (!cJSON_IsArray(tn) || (uint32_t)cJSON_GetArraySize(tn) != ch->target_count)
            return fail(p, path, "\"target_names\" must have one string per target");
        ch->target_names = mk_arena_array(p->arena, ch->target_count, sizeof(char *));
        if (!ch->target_names) return mk_error_oom(p->err, "sidecar");
        uint32_t i = 0;
        const cJSON *e;
        cJSON_ArrayForEach(e, tn) ch->target_names[i++] = dup_string(p, e);
    }
    return MK_OK;
}

static mk_result parse_mesh(parser *p, const cJSON *o, uint32_t index, mk_gltf_sidecar_mesh *m)
{
    char path[64];
    snprintf(path, sizeof path, "meshes[%u]", index);
    if (!cJSON_IsObject(o)) return fail(p, path, "must be an object");
    uint32_t node = 0, prim = 0;
    mk_result r;
    if ((r = get_uint(p, o, "node", path, 1, &node)) != MK_OK) return r;
    if ((r = get_uint(p, o, "primitive", path, 0, &prim)) != MK_OK) return r;
    if (node > INT32_MAX || prim > INT32_MAX) return fail(p, path, "index too large");
    m->node = (int32_t)node;
    m->primitive = (int32_t)prim;
    m->name = dup_string(p, cJSON_GetObjectItemCaseSensitive(o, "name"));
    const cJSON *st = cJSON_GetObjectItemCaseSensitive(o, "stacking");
    if (st) {
        if (cJSON_IsString(st) && strcmp(st->valuestring, "additive") == 0) m->stacking = MK_STACKING_ADDITIVE;
        else if (cJSON_IsString(st) && strcmp(st->valuestring, "sequential") == 0) m->stacking = MK_STACKING_SEQUENTIAL;
        else return fail(p, path, "\"stacking\" must be \"additive\" or \"sequential\"");
    }
    const cJSON *un = cJSON_GetObjectItemCaseSensitive(o, "unused_targets");
    if (un && (r = uint_array(p, un, path, &m->unused, &m->unused_count)) != MK_OK) return r;
    const cJSON *cp = cJSON_GetObjectItemCaseSensitive(o, "control_points");
    if (cp) {
        if (!cJSON_IsObject(cp)) return fail(p, path, "\"control_points\" must be an object");
        if ((r = get_uint(p, cp, "count", path, 1, &m->control_point_count)) != MK_OK) return r;
        if ((r = uint_array(p, cJSON_GetObjectItemCaseSensitive(cp, "map"), path, &m->control_points, &m->control_point_map_count)) != MK_OK)
            return r;
    }
    const cJSON *chs = cJSON_GetObjectItemCaseSensitive(o, "channels");
    if (!cJSON_IsArray(chs)) return fail(p, path, "needs a \"channels\" array");
    int n = cJSON_GetArraySize(chs);
    m->channels = mk_arena_array(p->arena, (size_t)n + 1, sizeof *m->channels);
    if (!m->channels) return mk_error_oom(p->err, "sidecar");
    const cJSON *e;
    cJSON_ArrayForEach(e, chs) {
        char cpath[96];
        snprintf(cpath, sizeof cpath, "%s.channels[%u]", path, m->channel_count);
        if ((r = parse_channel(p, e, cpath, &m->channels[m->channel_count])) != MK_OK) return r;
        m->channel_count++;
    }
    return MK_OK;
}

mk_result mk_gltf_sidecar_parse(mk_arena *arena, const char *text, size_t size, const char *where,
                                mk_gltf_sidecar *out, mk_error *err)
{
    parser p = {arena, where, err};
    memset(out, 0, sizeof *out);
    cJSON *root = cJSON_ParseWithLength(text, size);
    if (!root) return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: not valid JSON", where);
    mk_result r = MK_OK;
    const cJSON *fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    if (!cJSON_IsObject(root) || !cJSON_IsString(fmt) || strcmp(fmt->valuestring, "morphkit-gltf-channels") != 0)
        r = fail(&p, "format", "expected \"morphkit-gltf-channels\"");
    else if (!cJSON_IsArray(meshes))
        r = fail(&p, "meshes", "expected an array");
    if (r == MK_OK) {
        uint32_t version = 0;
        r = get_uint(&p, root, "version", "version", 1, &version);
        if (r == MK_OK && version != 1) r = fail(&p, "version", "only version 1 is known");
    }
    if (r == MK_OK) {
        int n = cJSON_GetArraySize(meshes);
        out->meshes = mk_arena_array(arena, (size_t)n + 1, sizeof *out->meshes);
        if (!out->meshes) r = mk_error_oom(err, "sidecar");
        const cJSON *e;
        if (r == MK_OK) cJSON_ArrayForEach(e, meshes) {
            if ((r = parse_mesh(&p, e, out->mesh_count, &out->meshes[out->mesh_count])) != MK_OK) break;
            out->mesh_count++;
        }
    }
    const cJSON *clips = cJSON_GetObjectItemCaseSensitive(root, "clips");
    if (r == MK_OK && clips) {
        if (!cJSON_IsArray(clips)) r = fail(&p, "clips", "expected an array");
        int n = r == MK_OK ? cJSON_GetArraySize(clips) : 0;
        if (r == MK_OK && !(out->clips = mk_arena_array(arena, (size_t)n + 1, sizeof *out->clips))) r = mk_error_oom(err, "sidecar");
        const cJSON *e;
        if (r == MK_OK) cJSON_ArrayForEach(e, clips) {
            const cJSON *st = cJSON_GetObjectItemCaseSensitive(e, "start"), *du = cJSON_GetObjectItemCaseSensitive(e, "duration");
            char path[48];
            snprintf(path, sizeof path, "clips[%u]", out->clip_count);
            /* The raw model's rule (mk_raw_validate): finite as float, duration not negative. A
             * clip imported from glTF keys far in time has such a range, and the write-back's and
             * the exporter's sidecars carry it. */
            if (!cJSON_IsNumber(st) || !cJSON_IsNumber(du) || !(fabs(st->valuedouble) <= FLT_MAX) ||
                !(du->valuedouble >= 0 && du->valuedouble <= FLT_MAX)) {
                r = fail(&p, path, "needs finite \"start\" and non-negative \"duration\" seconds");
                break;
            }
            out->clips[out->clip_count].start = (float)st->valuedouble;
            out->clips[out->clip_count].duration = (float)du->valuedouble;
            out->clip_count++;
        }
    }
    cJSON_Delete(root);
    return r;
}

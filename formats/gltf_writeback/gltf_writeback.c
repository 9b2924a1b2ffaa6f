/* SPDX-License-Identifier: MIT */
/* Write-back: the baked channels of a raw asset appended to the glTF it was imported from
 * (docs/baking.md, "Baking into your own file", glTF).
 *
 * The document is edited as a cJSON tree: every member, extension, extras and unknown property
 * stays, in its order; only members are added (new accessors, bufferViews, targets, weights,
 * target names, animations) or, where glTF needs it, replaced (a weight sampler's `output`
 * grows with the new targets, `buffers[0].byteLength` of a .glb grows with its BIN chunk,
 * relative URIs point back to the input's folder when the output is elsewhere). Original
 * binary bytes are copied unchanged; the data of the mk_gltf_doc (tinygltf) load is only read,
 * for the values of existing weight animations.
 *
 * Raw meshes map to glTF as the importer made them (formats/gltf/gltf_import.c): one raw mesh
 * per (node, primitive) of a node's mesh, its imported channels first, one per glTF target, then
 * the baked ones (origin non-empty). glTF targets belong to the mesh, so every node instancing a
 * mesh must carry the same baked channels, and every primitive gets a target per new slot (zeros
 * where the channel deforms another primitive). */
#define _GNU_SOURCE
#include "gltf_writeback.h"
#include <limits.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cjson/cJSON.h>
#include "blob_io.h"
#include "gltf_accessor.h"
#include "gltf_weights.h"

enum { GLB_JSON = 0x4E4F534A, GLB_BIN = 0x004E4942, ARRAY_BUFFER = 34962 };

typedef struct slot {
    uint32_t prim;                 /* the primitive the channel deforms */
    uint32_t ord;                  /* baked channel ordinal on that primitive */
    uint32_t target;               /* target of that channel */
    uint32_t channel;              /* the reference node's raw channel */
} slot;

typedef struct mesh_plan {
    int32_t mesh;
    uint32_t prim_count, old_targets, slot_count;
    slot *slots;
    float *defaults;               /* per slot: glTF weight at the channel's default weight */
    uint32_t node_count;
    int32_t *nodes;                /* nodes instancing the mesh */
} mesh_plan;

typedef struct wb {
    mk_arena tmp;
    const mk_raw_asset *raw;
    mk_gltf_write_back_report *rep;
    mk_error *err;
    int oom;
    cJSON *root, *accessors, *views, *buffers, *meshes, *nodes, *animations;
    mk_gltf_doc doc;
    int doc_loaded;
    mk_gltf_reader reader;
    int glb;
    const uint8_t *json_text;
    size_t json_size;
    const uint8_t *bin;            /* GLB BIN chunk data */
    uint64_t bin_size;
    const uint8_t *after_bin;      /* further GLB chunks, kept as they are */
    size_t after_bin_size;
    int in_bin;                    /* new bytes go to the end of buffer 0 (the BIN chunk) */
    int32_t data_buffer;
    uint64_t data_base;
    uint8_t *data;                 /* new bytes (malloc) */
    size_t size, cap;
    mesh_plan *plans;
    uint32_t plan_count;
    uint32_t animation_count;      /* the input's */
} wb;

static void note(wb *w, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void note(wb *w, const char *fmt, ...)
{
    if (w->rep->note_count < 8) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(w->rep->notes[w->rep->note_count], sizeof w->rep->notes[0], fmt, ap);
        va_end(ap);
    }
    w->rep->note_count++;
}

static mk_result bad(wb *w, const char *path, const char *what)
{
    return mk_error_set(w->err, MK_ERROR_PARSE, UINT64_MAX, "glTF write-back: %s: %s", path, what);
}

/* ---- JSON helpers (every creation failure sets w->oom, checked at the end) ---- */

static cJSON *track(wb *w, cJSON *item)
{
    if (!item) w->oom = 1;
    return item;
}

static void add_item(wb *w, cJSON *obj, const char *key, cJSON *item)
{
    if (!item || !(key ? cJSON_AddItemToObject(obj, key, item) : cJSON_AddItemToArray(obj, item))) {
        cJSON_Delete(item);
        w->oom = 1;
    }
}

static void add_num(wb *w, cJSON *obj, const char *key, double v) { add_item(w, obj, key, cJSON_CreateNumber(v)); }
static void add_str(wb *w, cJSON *obj, const char *key, const char *s) { add_item(w, obj, key, cJSON_CreateString(s)); }

static void set_num(wb *w, cJSON *obj, const char *key, double v)
{
    cJSON *n = track(w, cJSON_CreateNumber(v));
    if (n && !cJSON_ReplaceItemInObjectCaseSensitive(obj, key, n)) { cJSON_Delete(n); w->oom = 1; }
}

/* The array member `key` of the root, created when absent; an error when it is not an array. */
static mk_result root_array(wb *w, const char *key, int create, cJSON **out)
{
    cJSON *a = cJSON_GetObjectItemCaseSensitive(w->root, key);
    if (a && !cJSON_IsArray(a)) return bad(w, key, "expected an array");
    if (!a && create) {
        a = track(w, cJSON_CreateArray());
        add_item(w, w->root, key, a);
        if (w->oom) return mk_error_oom(w->err, "glTF write-back");
    }
    *out = a;
    return MK_OK;
}

static int is_uint(const cJSON *v, double limit)
{
    return cJSON_IsNumber(v) && v->valuedouble >= 0 && v->valuedouble < limit && v->valuedouble == floor(v->valuedouble);
}

/* obj[key] as an index below limit; *out = -1 when absent and not required. */
static mk_result get_index(wb *w, const cJSON *obj, const char *key, uint32_t limit, const char *path, int required,
                           int32_t *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = -1;
    if (!v) {
        if (!required) return MK_OK;
        char m[96];
        snprintf(m, sizeof m, "missing \"%s\"", key);
        return bad(w, path, m);
    }
    if (!is_uint(v, limit)) {
        char m[128];
        snprintf(m, sizeof m, "\"%s\" must be an index below %u", key, limit);
        return bad(w, path, m);
    }
    *out = (int32_t)v->valuedouble;
    return MK_OK;
}

/* NaN/Inf cannot come from JSON text, but a number out of double range parses as infinite and
 * cJSON would print it as null: refuse it rather than change the document. */
static mk_result check_numbers(wb *w, const cJSON *v, int depth)
{
    if (depth > 200) return bad(w, "(document)", "nested too deeply");
    for (; v; v = v->next) {
        if (cJSON_IsNumber(v) && !isfinite(v->valuedouble)) {
            char m[160];
            snprintf(m, sizeof m, "a number out of range%s%s", v->string ? " in member " : "", v->string ? v->string : "");
            return bad(w, "(document)", m);
        }
        if (v->child) {
            mk_result r = check_numbers(w, v->child, depth + 1);
            if (r != MK_OK) return r;
        }
    }
    return MK_OK;
}

/* ---- new binary data ---- */

static mk_result put_bytes(wb *w, const void *p, size_t n, size_t *offset)
{
    size_t at = (w->size + 3) & ~(size_t)3;
    if (at + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < at + n) cap *= 2;
        uint8_t *d = realloc(w->data, cap);
        if (!d) return mk_error_oom(w->err, "glTF write-back data");
        w->data = d;
        w->cap = cap;
    }
    memset(w->data + w->size, 0, at - w->size);
    if (n) memcpy(w->data + at, p, n);
    w->size = at + n;
    *offset = at;
    return MK_OK;
}

static int32_t add_view(wb *w, size_t offset, size_t length, uint32_t stride, int target)
{
    cJSON *v = track(w, cJSON_CreateObject());
    if (!v) return -1;
    add_num(w, v, "buffer", w->data_buffer);
    add_num(w, v, "byteOffset", (double)(w->data_base + offset));
    add_num(w, v, "byteLength", (double)length);
    if (stride) add_num(w, v, "byteStride", stride);
    if (target) add_num(w, v, "target", target);
    int32_t index = cJSON_GetArraySize(w->views);
    add_item(w, w->views, NULL, v);
    return index;
}

static int32_t add_accessor(wb *w, cJSON *a)
{
    int32_t index = cJSON_GetArraySize(w->accessors);
    add_item(w, w->accessors, NULL, a);
    return index;
}

/* ---- encoding one target attribute ---- */

typedef struct encoding {
    int ctype;                     /* MK_GLTF_FLOAT, MK_GLTF_BYTE or MK_GLTF_SHORT */
    int normalized;
} encoding;

static int component_size(int ctype) { return ctype == MK_GLTF_FLOAT ? 4 : ctype == MK_GLTF_SHORT ? 2 : 1; }

/* v as the integer component, or 0 when out of range (KHR_mesh_quantization decoding, spec
 * §3.11: normalized c / 127 or c / 32767). */
static int quantize(float v, encoding e, int32_t *c)
{
    double scale = e.normalized ? (e.ctype == MK_GLTF_SHORT ? 32767.0 : 127.0) : 1.0;
    double lo = e.normalized ? -scale : e.ctype == MK_GLTF_SHORT ? -32768.0 : -128.0;
    double hi = e.ctype == MK_GLTF_SHORT ? 32767.0 : 127.0;
    double q = floor((double)v * scale + 0.5);
    if (!(q >= lo && q <= hi)) return 0;
    *c = (int32_t)q;
    return 1;
}

/* One VEC3 accessor of a new target: dense holds 3 floats per vertex (NULL: all zero), moved
 * the n vertices with a nonzero delta of the whole target (increasing). Sparse when fewer than
 * half the vertices move; no bufferView at all when none moves. */
static mk_result write_attribute(wb *w, const float *dense, uint32_t V, const uint32_t *moved, uint32_t n, encoding e,
                                 int minmax, int32_t *out)
{
    if (!dense) n = 0;
    if (e.ctype != MK_GLTF_FLOAT) {
        int32_t c;
        for (uint32_t i = 0; i < n; i++)
            for (int k = 0; k < 3; k++)
                if (!quantize(dense[3 * (size_t)moved[i] + k], e, &c)) {
                    w->rep->float_fallbacks++;
                    e.ctype = MK_GLTF_FLOAT;
                    e.normalized = 0;
                    i = n;
                    break;
                }
    }
    int sparse = n > 0 && (uint64_t)n * 2 < V;
    size_t csize = (size_t)component_size(e.ctype), elem = 3 * csize;
    size_t stride = sparse ? elem : (elem + 3) & ~(size_t)3;
    uint32_t count = sparse ? n : n ? V : 0;
    double lo[3] = { 0, 0, 0 }, hi[3] = { 0, 0, 0 };
    int first = !(sparse && n < V);   /* zeros of untouched vertices count for min/max */
    mk_result r = MK_OK;
    uint8_t *bytes = count ? calloc((size_t)count, stride) : NULL;
    if (count && !bytes) return mk_error_oom(w->err, "glTF write-back target");
    for (uint32_t i = 0, j = 0; i < count; i++) {
        uint32_t v = sparse ? moved[i] : i;
        int has = 0;
        if (!sparse) { while (j < n && moved[j] < v) j++; has = j < n && moved[j] == v; }
        else has = 1;
        for (int k = 0; k < 3; k++) {
            float f = has ? dense[3 * (size_t)v + k] : 0.0f;
            double stored;
            uint8_t *dst = bytes + (size_t)i * stride + (size_t)k * csize;
            if (e.ctype == MK_GLTF_FLOAT) {
                memcpy(dst, &f, 4);
                stored = f;
            } else {
                int32_t c = 0;
                quantize(f, e, &c);
                if (e.ctype == MK_GLTF_SHORT) { int16_t s = (int16_t)c; memcpy(dst, &s, 2); }
                else { int8_t b = (int8_t)c; memcpy(dst, &b, 1); }
                stored = c;
            }
            if (first || stored < lo[k]) lo[k] = stored;
            if (first || stored > hi[k]) hi[k] = stored;
        }
        first = 0;
    }
    cJSON *a = track(w, cJSON_CreateObject());
    if (a) {
        add_num(w, a, "componentType", e.ctype);
        if (e.normalized) add_item(w, a, "normalized", cJSON_CreateTrue());
        add_num(w, a, "count", V);
        add_str(w, a, "type", "VEC3");
    }
    if (count && sparse) {
        int wide = V > 65536;
        size_t isz = wide ? 4 : 2, off_i, off_v;
        uint8_t *idx = malloc((size_t)n * isz);
        if (!idx) r = mk_error_oom(w->err, "glTF write-back target");
        for (uint32_t i = 0; r == MK_OK && i < n; i++) {
            if (wide) memcpy(idx + 4 * (size_t)i, &moved[i], 4);
            else { uint16_t s = (uint16_t)moved[i]; memcpy(idx + 2 * (size_t)i, &s, 2); }
        }
        if (r == MK_OK) r = put_bytes(w, idx, (size_t)n * isz, &off_i);
        if (r == MK_OK) r = put_bytes(w, bytes, (size_t)n * elem, &off_v);
        free(idx);
        if (r == MK_OK && a) {
            cJSON *sp = track(w, cJSON_CreateObject()), *ji = track(w, cJSON_CreateObject()), *jv = track(w, cJSON_CreateObject());
            if (sp && ji && jv) {
                add_num(w, ji, "bufferView", add_view(w, off_i, (size_t)n * isz, 0, 0));
                add_num(w, ji, "componentType", wide ? MK_GLTF_UNSIGNED_INT : MK_GLTF_UNSIGNED_SHORT);
                add_num(w, jv, "bufferView", add_view(w, off_v, (size_t)n * elem, 0, 0));
                add_num(w, sp, "count", n);
                add_item(w, sp, "indices", ji);
                add_item(w, sp, "values", jv);
                add_item(w, a, "sparse", sp);
            } else { cJSON_Delete(sp); cJSON_Delete(ji); cJSON_Delete(jv); }
        }
        w->rep->sparse_accessors++;
    } else if (count) {
        size_t off;
        r = put_bytes(w, bytes, (size_t)V * stride, &off);
        if (r == MK_OK && a) {
            /* A view of its own (byteOffset 0 in the accessor): vertex attributes need 4-byte
             * aligned elements, so 3-byte and 6-byte elements get a stride. */
            cJSON *bv = track(w, cJSON_CreateNumber(add_view(w, off, (size_t)V * stride, stride != elem ? (uint32_t)stride : 0,
                                                             ARRAY_BUFFER)));
            if (bv && !cJSON_AddItemToObject(a, "bufferView", bv)) { cJSON_Delete(bv); w->oom = 1; }
        }
        w->rep->dense_accessors++;
    }
    free(bytes);
    if (e.ctype != MK_GLTF_FLOAT && count) w->rep->quantized_accessors++;
    if (r == MK_OK && a && minmax) {
        cJSON *jmin = track(w, cJSON_CreateDoubleArray(lo, 3)), *jmax = track(w, cJSON_CreateDoubleArray(hi, 3));
        add_item(w, a, "min", jmin);
        add_item(w, a, "max", jmax);
    }
    if (r != MK_OK) { cJSON_Delete(a); return r; }
    *out = a ? add_accessor(w, a) : -1;
    return MK_OK;
}

/* ---- the plan: which raw meshes and channels go where ---- */

static int baked(const mk_raw_channel *c) { return c->origin && c->origin[0]; }

static int32_t raw_mesh_of(const mk_raw_asset *raw, int32_t node, int32_t mesh, uint32_t prim)
{
    for (uint32_t m = 0; m < raw->mesh_count; m++)
        if (raw->meshes[m].gltf_node == node && raw->meshes[m].gltf_mesh == mesh && raw->meshes[m].gltf_primitive == (int32_t)prim)
            return (int32_t)m;
    return -1;
}

/* Channels of raw mesh m, imported then baked, in raw order. */
static mk_result channels_of(wb *w, uint32_t m, uint32_t old_targets, uint32_t **baked_out, uint32_t *baked_count,
                             uint32_t **orig_out)
{
    const mk_raw_asset *raw = w->raw;
    uint32_t nb = 0, no = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (raw->channels[c].mesh == m) { if (baked(&raw->channels[c])) nb++; else no++; }
    uint32_t *b = mk_arena_array(&w->tmp, nb + 1u, sizeof *b), *o = mk_arena_array(&w->tmp, no + 1u, sizeof *o);
    if (!b || !o) return mk_error_oom(w->err, "glTF write-back");
    const mk_raw_mesh *rm = &raw->meshes[m];
    if (no != old_targets)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "glTF write-back: mesh '%s' (node %d primitive %d) has %u imported channels for %u glTF targets; "
                            "write-back needs the asset imported from this file without a channel sidecar",
                            rm->name ? rm->name : "", rm->gltf_node, rm->gltf_primitive, no, old_targets);
    uint32_t ib = 0, io = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++) {
        const mk_raw_channel *ch = &raw->channels[c];
        if (ch->mesh != m) continue;
        if (baked(ch)) { b[ib++] = c; continue; }
        if (ib || ch->target_count != 1 || ch->targets[0].full_weight != 1.0f)
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "glTF write-back: mesh '%s' channel '%s' is not one glTF target as imported (or follows a baked "
                                "channel); write-back needs the asset imported from this file without a channel sidecar",
                                rm->name ? rm->name : "", ch->name ? ch->name : "");
        o[io++] = c;
    }
    *baked_out = b;
    *baked_count = nb;
    if (orig_out) *orig_out = o;
    return MK_OK;
}

static int same_floats(const float *a, const float *b, uint32_t n)
{
    if (!a || !b) return a == b;
    return memcmp(a, b, (size_t)n * 3 * sizeof(float)) == 0;
}

static int same_channel(const mk_raw_channel *a, const mk_raw_channel *b)
{
    if (a->target_count != b->target_count || a->default_weight != b->default_weight) return 0;
    if (strcmp(a->name ? a->name : "", b->name ? b->name : "")) return 0;
    for (uint32_t k = 0; k < a->target_count; k++) {
        const mk_raw_target *x = &a->targets[k], *y = &b->targets[k];
        if (x->full_weight != y->full_weight || x->count != y->count) return 0;
        if (memcmp(x->indices, y->indices, (size_t)x->count * sizeof(uint32_t))) return 0;
        if (!same_floats(x->positions, y->positions, x->count) || !same_floats(x->normals, y->normals, x->count) ||
            !same_floats(x->tangents, y->tangents, x->count))
            return 0;
    }
    return 1;
}

static mk_result plan_mesh(wb *w, int32_t mi, mesh_plan *p)
{
    const mk_raw_asset *raw = w->raw;
    char path[96];
    snprintf(path, sizeof path, "meshes[%d]", mi);
    cJSON *mesh = cJSON_GetArrayItem(w->meshes, mi);
    cJSON *prims = cJSON_GetObjectItemCaseSensitive(mesh, "primitives");
    if (!cJSON_IsObject(mesh) || !cJSON_IsArray(prims) || cJSON_GetArraySize(prims) == 0)
        return bad(w, path, "expected an object with a non-empty \"primitives\" array");
    memset(p, 0, sizeof *p);
    p->mesh = mi;
    p->prim_count = (uint32_t)cJSON_GetArraySize(prims);
    for (uint32_t q = 0; q < p->prim_count; q++) {
        cJSON *pr = cJSON_GetArrayItem(prims, (int)q), *tg = cJSON_GetObjectItemCaseSensitive(pr, "targets");
        char pp[128];
        snprintf(pp, sizeof pp, "%s.primitives[%u]", path, q);
        if (!cJSON_IsObject(pr) || (tg && !cJSON_IsArray(tg))) return bad(w, pp, "expected an object with a \"targets\" array");
        uint32_t n = tg ? (uint32_t)cJSON_GetArraySize(tg) : 0;
        if (q == 0) p->old_targets = n;
        else if (n != p->old_targets) return bad(w, pp, "the primitives of the mesh have different target counts");
    }
    /* Nodes instancing the mesh, each of whose primitives must have been imported. */
    int node_total = cJSON_GetArraySize(w->nodes);
    p->nodes = mk_arena_array(&w->tmp, (size_t)node_total + 1, sizeof *p->nodes);
    if (!p->nodes) return mk_error_oom(w->err, "glTF write-back");
    for (int n = 0; n < node_total; n++) {
        cJSON *node = cJSON_GetArrayItem(w->nodes, n);
        char np[48];
        snprintf(np, sizeof np, "nodes[%d]", n);
        if (!cJSON_IsObject(node)) return bad(w, np, "expected an object");
        int32_t m;
        mk_result r = get_index(w, node, "mesh", (uint32_t)cJSON_GetArraySize(w->meshes), np, 0, &m);
        if (r != MK_OK) return r;
        if (m == mi) p->nodes[p->node_count++] = n;
    }
    /* The reference node: the first that carries baked channels. */
    int32_t ref = -1;
    for (uint32_t i = 0; i < p->node_count && ref < 0; i++)
        for (uint32_t q = 0; q < p->prim_count; q++) {
            int32_t rm = raw_mesh_of(raw, p->nodes[i], mi, q);
            for (uint32_t c = 0; rm >= 0 && c < raw->channel_count; c++)
                if (raw->channels[c].mesh == (uint32_t)rm && baked(&raw->channels[c])) ref = p->nodes[i];
        }
    if (ref < 0) return MK_OK;
    const char *mname = cJSON_IsString(cJSON_GetObjectItemCaseSensitive(mesh, "name"))
                            ? cJSON_GetObjectItemCaseSensitive(mesh, "name")->valuestring : "";
    uint32_t total = 0;
    uint32_t **ref_baked = mk_arena_array(&w->tmp, p->prim_count, sizeof *ref_baked);
    uint32_t *ref_count = mk_arena_array(&w->tmp, p->prim_count, sizeof *ref_count);
    if (!ref_baked || !ref_count) return mk_error_oom(w->err, "glTF write-back");
    for (uint32_t i = 0; i < p->node_count; i++)
        for (uint32_t q = 0; q < p->prim_count; q++) {
            int32_t rm = raw_mesh_of(raw, p->nodes[i], mi, q);
            if (rm < 0)
                return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "glTF write-back: mesh %d '%s': node %d primitive %u is not in the baked asset (imported "
                                    "without keep_plain_meshes, or without POSITION)", mi, mname, p->nodes[i], q);
            uint32_t *b, nb;
            mk_result r = channels_of(w, (uint32_t)rm, p->old_targets, &b, &nb, NULL);
            if (r != MK_OK) return r;
            if (p->nodes[i] == ref) { ref_baked[q] = b; ref_count[q] = nb; continue; }
            int32_t rr = raw_mesh_of(raw, ref, mi, q);
            uint32_t *rb, rn;
            if ((r = channels_of(w, (uint32_t)rr, p->old_targets, &rb, &rn, NULL)) != MK_OK) return r;
            int same = rn == nb;
            for (uint32_t k = 0; same && k < nb; k++) same = same_channel(&raw->channels[rb[k]], &raw->channels[b[k]]);
            if (!same)
                return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "glTF write-back: mesh %d '%s' is instanced by nodes %d and %d, and the bake gave them "
                                    "different channels (primitive %u); glTF morph targets belong to the mesh, so this cannot "
                                    "be written: bake every instance alike, give each node its own mesh, or write a .morph",
                                    mi, mname, ref, p->nodes[i], q);
        }
    for (uint32_t q = 0; q < p->prim_count; q++)
        for (uint32_t k = 0; k < ref_count[q]; k++) total += raw->channels[ref_baked[q][k]].target_count;
    p->slots = mk_arena_array(&w->tmp, total + 1u, sizeof *p->slots);
    p->defaults = mk_arena_array(&w->tmp, total + 1u, sizeof *p->defaults);
    if (!p->slots || !p->defaults) return mk_error_oom(w->err, "glTF write-back");
    for (uint32_t q = 0; q < p->prim_count; q++)
        for (uint32_t k = 0; k < ref_count[q]; k++) {
            const mk_raw_channel *ch = &raw->channels[ref_baked[q][k]];
            if (ch->target_count > 256)
                return mk_error_set(w->err, MK_ERROR_LIMIT, UINT64_MAX, "glTF write-back: channel '%s' has %u targets (256 at most)",
                                    ch->name ? ch->name : "", ch->target_count);
            mk_gltf_slot_weights(ch, ch->default_weight, &p->defaults[p->slot_count]);
            for (uint32_t t = 0; t < ch->target_count; t++)
                p->slots[p->slot_count++] = (slot){ q, k, t, ref_baked[q][k] };
            w->rep->channels++;
            if (ch->target_count > 1) w->rep->sidecar_needed = 1;
        }
    /* Later passes look channels up per node: keep the reference first. */
    for (uint32_t i = 0; i < p->node_count; i++)
        if (p->nodes[i] == ref) { p->nodes[i] = p->nodes[0]; p->nodes[0] = ref; break; }
    return MK_OK;
}

static const mesh_plan *plan_of(const wb *w, int32_t mesh)
{
    for (uint32_t i = 0; i < w->plan_count; i++)
        if (w->plans[i].mesh == mesh) return &w->plans[i];
    return NULL;
}

/* The raw channel of a slot on node `node` (the same ordinal on that node's primitive). */
static const mk_raw_channel *slot_channel(wb *w, const mesh_plan *p, int32_t node, const slot *s)
{
    int32_t rm = raw_mesh_of(w->raw, node, p->mesh, s->prim);
    uint32_t k = 0;
    for (uint32_t c = 0; rm >= 0 && c < w->raw->channel_count; c++)
        if (w->raw->channels[c].mesh == (uint32_t)rm && baked(&w->raw->channels[c]) && k++ == s->ord) return &w->raw->channels[c];
    return &w->raw->channels[s->channel];
}

/* ---- writing the targets of one mesh ---- */

/* The encoding of the primitive's existing targets for a semantic: quantized ones are kept
 * (signed byte/short, KHR_mesh_quantization), anything else is float. *present: some target has it. */
static encoding target_encoding(wb *w, cJSON *targets, const char *semantic, int *present)
{
    encoding e = { MK_GLTF_FLOAT, 0 };
    *present = 0;
    cJSON *t;
    cJSON_ArrayForEach(t, targets) {
        cJSON *a = cJSON_GetObjectItemCaseSensitive(t, semantic);
        if (!a) continue;
        *present = 1;
        cJSON *acc = is_uint(a, (double)cJSON_GetArraySize(w->accessors)) ? cJSON_GetArrayItem(w->accessors, (int)a->valuedouble) : NULL;
        cJSON *ct = cJSON_GetObjectItemCaseSensitive(acc, "componentType");
        if (!cJSON_IsNumber(ct)) return e;
        int c = (int)ct->valuedouble;
        if (c == MK_GLTF_BYTE || c == MK_GLTF_SHORT) {
            e.ctype = c;
            e.normalized = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(acc, "normalized"));
        }
        return e;
    }
    return e;
}

static mk_result write_mesh_targets(wb *w, const mesh_plan *p)
{
    const mk_raw_asset *raw = w->raw;
    cJSON *mesh = cJSON_GetArrayItem(w->meshes, p->mesh), *prims = cJSON_GetObjectItemCaseSensitive(mesh, "primitives");
    int32_t ref = p->nodes[0];
    mk_result r = MK_OK;
    for (uint32_t q = 0; q < p->prim_count && r == MK_OK; q++) {
        char pp[128];
        snprintf(pp, sizeof pp, "meshes[%d].primitives[%u]", p->mesh, q);
        cJSON *pr = cJSON_GetArrayItem(prims, (int)q);
        cJSON *attrs = cJSON_GetObjectItemCaseSensitive(pr, "attributes");
        if (!cJSON_IsObject(attrs)) return bad(w, pp, "expected an \"attributes\" object");
        int32_t pos;
        if ((r = get_index(w, attrs, "POSITION", (uint32_t)cJSON_GetArraySize(w->accessors), pp, 1, &pos)) != MK_OK) return r;
        const cJSON *cnt = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(w->accessors, pos), "count");
        if (!is_uint(cnt, (double)(1u << 28))) return bad(w, pp, "the POSITION accessor has no valid \"count\"");
        uint32_t V = (uint32_t)cnt->valuedouble;
        int32_t rm = raw_mesh_of(raw, ref, p->mesh, q);
        const mk_raw_mesh *m = &raw->meshes[rm];
        if (m->vertex_count != V || !m->control_points)
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "glTF write-back: %s: the raw mesh '%s' has %u vertices, the glTF primitive %u", pp,
                                m->name ? m->name : "", m->vertex_count, V);
        cJSON *ext = cJSON_GetObjectItemCaseSensitive(pr, "extensions");
        if (cJSON_GetObjectItemCaseSensitive(ext, "KHR_draco_mesh_compression")) {
            w->rep->draco_primitives++;
            note(w, "%s is Draco-compressed: its new targets are plain accessors in Draco's decoded vertex order "
                    "(the extension does not compress targets)", pp);
        }
        cJSON *targets = cJSON_GetObjectItemCaseSensitive(pr, "targets");
        if (!targets) {
            targets = track(w, cJSON_CreateArray());
            add_item(w, pr, "targets", targets);
            if (w->oom) return mk_error_oom(w->err, "glTF write-back");
        }
        int has_p_old, has_n_old, has_t_old, baked_n = 0, baked_t = 0;
        encoding ep = target_encoding(w, targets, "POSITION", &has_p_old);
        encoding en = target_encoding(w, targets, "NORMAL", &has_n_old);
        encoding et = target_encoding(w, targets, "TANGENT", &has_t_old);
        for (uint32_t s = 0; s < p->slot_count; s++) {
            if (p->slots[s].prim != q) continue;
            const mk_raw_target *t = &raw->channels[p->slots[s].channel].targets[p->slots[s].target];
            baked_n |= t->normals != NULL;
            baked_t |= t->tangents != NULL;
        }
        int base_n = cJSON_GetObjectItemCaseSensitive(attrs, "NORMAL") != NULL;
        int base_t = base_n && cJSON_GetObjectItemCaseSensitive(attrs, "TANGENT") != NULL;
        int with_n = base_n && (has_n_old || baked_n), with_t = base_t && (has_t_old || baked_t);
        float *dense = malloc((size_t)V * 9 * sizeof(float) + 1);
        uint32_t *moved = malloc((size_t)V * sizeof(uint32_t) + 4);
        uint8_t *hit = malloc((size_t)V + 1);
        if (!dense || !moved || !hit) r = mk_error_oom(w->err, "glTF write-back");
        for (uint32_t s = 0; s < p->slot_count && r == MK_OK; s++) {
            float *dp = dense, *dn = dense + 3 * (size_t)V, *dt = dense + 6 * (size_t)V;
            uint32_t n = 0;
            if (p->slots[s].prim == q) {
                const mk_raw_target *t = &raw->channels[p->slots[s].channel].targets[p->slots[s].target];
                memset(dense, 0, (size_t)V * 9 * sizeof(float));
                memset(hit, 0, V);
                for (uint32_t i = 0; i < t->count; i++) {
                    uint32_t rv = t->indices[i];
                    uint32_t g = rv < m->vertex_count ? m->control_points[rv] : UINT32_MAX;
                    if (g >= V || hit[g]) {
                        r = mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                         "glTF write-back: %s: channel '%s' vertex %u maps to glTF vertex %u, out of range or "
                                         "used twice", pp, raw->channels[p->slots[s].channel].name, rv, g);
                        break;
                    }
                    hit[g] = 1;
                    memcpy(dp + 3 * (size_t)g, t->positions + 3 * (size_t)i, 3 * sizeof(float));
                    if (t->normals) memcpy(dn + 3 * (size_t)g, t->normals + 3 * (size_t)i, 3 * sizeof(float));
                    if (t->tangents) memcpy(dt + 3 * (size_t)g, t->tangents + 3 * (size_t)i, 3 * sizeof(float));
                }
                for (uint32_t g = 0; g < V && r == MK_OK; g++) {
                    int nz = 0;
                    for (int k = 0; k < 3; k++)
                        nz |= (dp[3 * (size_t)g + k] != 0) | (with_n && dn[3 * (size_t)g + k] != 0) |
                              (with_t && dt[3 * (size_t)g + k] != 0);
                    if (nz) moved[n++] = g;
                }
            } else {
                w->rep->padding_targets++;
            }
            if (r != MK_OK) break;
            cJSON *tj = track(w, cJSON_CreateObject());
            int32_t acc;
            if ((r = write_attribute(w, n ? dp : NULL, V, moved, n, ep, 1, &acc)) != MK_OK) { cJSON_Delete(tj); break; }
            add_num(w, tj, "POSITION", acc);
            if (with_n) {
                if ((r = write_attribute(w, n ? dn : NULL, V, moved, n, en, 0, &acc)) != MK_OK) { cJSON_Delete(tj); break; }
                add_num(w, tj, "NORMAL", acc);
            }
            if (with_t) {
                if ((r = write_attribute(w, n ? dt : NULL, V, moved, n, et, 0, &acc)) != MK_OK) { cJSON_Delete(tj); break; }
                add_num(w, tj, "TANGENT", acc);
            }
            add_item(w, targets, NULL, tj);
        }
        free(dense);
        free(moved);
        free(hit);
    }
    return r;
}

/* weights arrays (mesh.weights, node.weights): the old length must be the old target count
 * (shorter ones are padded with 0, as the importer reads them); the new defaults follow. */
static mk_result extend_weights(wb *w, cJSON *owner, const char *path, const mesh_plan *p, int create)
{
    cJSON *wts = cJSON_GetObjectItemCaseSensitive(owner, "weights");
    if (!wts) {
        int any = 0;
        for (uint32_t s = 0; s < p->slot_count; s++) any |= p->defaults[s] != 0;
        if (!create || !any) return MK_OK;
        wts = track(w, cJSON_CreateArray());
        add_item(w, owner, "weights", wts);
        if (w->oom) return mk_error_oom(w->err, "glTF write-back");
    }
    char wp[128];
    snprintf(wp, sizeof wp, "%s.weights", path);
    if (!cJSON_IsArray(wts)) return bad(w, wp, "expected an array");
    cJSON *v;
    cJSON_ArrayForEach(v, wts) if (!cJSON_IsNumber(v)) return bad(w, wp, "expected numbers");
    int n = cJSON_GetArraySize(wts);
    if ((uint32_t)n > p->old_targets) return bad(w, wp, "more weights than the mesh has targets");
    for (uint32_t k = (uint32_t)n; k < p->old_targets; k++) add_item(w, wts, NULL, cJSON_CreateNumber(0));
    for (uint32_t s = 0; s < p->slot_count; s++) add_item(w, wts, NULL, cJSON_CreateNumber(p->defaults[s]));
    return MK_OK;
}

/* mesh.extras.targetNames, and primitive.extras.targetNames where a primitive has them: the
 * new targets' names appended. Created on the mesh when absent (with the names the importer
 * gives the old targets), so a re-import without sidecar names the new channels. */
static mk_result extend_names(wb *w, const mesh_plan *p)
{
    const mk_raw_asset *raw = w->raw;
    cJSON *mesh = cJSON_GetArrayItem(w->meshes, p->mesh);
    char path[96];
    snprintf(path, sizeof path, "meshes[%d].extras", p->mesh);
    cJSON *extras = cJSON_GetObjectItemCaseSensitive(mesh, "extras");
    if (extras && !cJSON_IsObject(extras)) {
        note(w, "%s is not an object: the new targets are not named there", path);
        return MK_OK;
    }
    cJSON *prims = cJSON_GetObjectItemCaseSensitive(mesh, "primitives"), *pr;
    int32_t rm0 = raw_mesh_of(raw, p->nodes[0], p->mesh, 0);
    uint32_t *orig = NULL, *b, nb;
    mk_result r = channels_of(w, (uint32_t)rm0, p->old_targets, &b, &nb, &orig);
    if (r != MK_OK) return r;
    if (!extras) {
        extras = track(w, cJSON_CreateObject());
        add_item(w, mesh, "extras", extras);
    }
    cJSON *names = cJSON_GetObjectItemCaseSensitive(extras, "targetNames");
    if (!names && extras) {
        names = track(w, cJSON_CreateArray());
        add_item(w, extras, "targetNames", names);
        for (uint32_t k = 0; names && k < p->old_targets; k++) add_str(w, names, NULL, raw->channels[orig[k]].name);
    }
    if (w->oom) return mk_error_oom(w->err, "glTF write-back");
    uint32_t q = 0;
    cJSON_ArrayForEach(pr, prims) {
        cJSON *list[2] = { names, cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(pr, "extras"), "targetNames") };
        for (int i = q == 0 ? 0 : 1; i < 2; i++) {
            cJSON *l = list[i];
            if (!l) continue;
            if (!cJSON_IsArray(l) || (uint32_t)cJSON_GetArraySize(l) != p->old_targets) {
                note(w, "meshes[%d]%s.extras.targetNames does not list %u names: left as it is", p->mesh,
                     i ? "[primitive]" : "", p->old_targets);
                continue;
            }
            for (uint32_t s = 0; s < p->slot_count; s++) {
                const mk_raw_target *t = &raw->channels[p->slots[s].channel].targets[p->slots[s].target];
                add_str(w, l, NULL, t->name ? t->name : raw->channels[p->slots[s].channel].name);
            }
        }
        q++;
    }
    return w->oom ? mk_error_oom(w->err, "glTF write-back") : MK_OK;
}

/* ---- animations ---- */

static int32_t add_floats(wb *w, const float *v, size_t n, int minmax, mk_result *r)
{
    size_t off;
    if ((*r = put_bytes(w, v, n * sizeof(float), &off)) != MK_OK) return -1;
    cJSON *a = track(w, cJSON_CreateObject());
    if (!a) return -1;
    add_num(w, a, "bufferView", add_view(w, off, n * sizeof(float), 0, 0));
    add_num(w, a, "componentType", MK_GLTF_FLOAT);
    add_num(w, a, "count", (double)n);
    add_str(w, a, "type", "SCALAR");
    if (minmax && n) {
        double lo = v[0], hi = v[0];
        for (size_t i = 1; i < n; i++) { if (v[i] < lo) lo = v[i]; if (v[i] > hi) hi = v[i]; }
        add_item(w, a, "min", cJSON_CreateDoubleArray(&lo, 1));
        add_item(w, a, "max", cJSON_CreateDoubleArray(&hi, 1));
    }
    return add_accessor(w, a);
}

/* Existing weight animations of nodes whose mesh grew: the sampler's output gets the new
 * targets, held at their default weights (tangents 0), in a new accessor. */
static mk_result extend_animations(wb *w)
{
    if (!w->animations) return MK_OK;
    mk_result r = MK_OK;
    int na = cJSON_GetArraySize(w->animations);
    for (int a = 0; a < na && r == MK_OK; a++) {
        char ap[64];
        snprintf(ap, sizeof ap, "animations[%d]", a);
        cJSON *anim = cJSON_GetArrayItem(w->animations, a);
        cJSON *chans = cJSON_GetObjectItemCaseSensitive(anim, "channels"), *samplers = cJSON_GetObjectItemCaseSensitive(anim, "samplers");
        if (!cJSON_IsObject(anim) || !cJSON_IsArray(chans) || !cJSON_IsArray(samplers))
            return bad(w, ap, "expected an object with \"channels\" and \"samplers\" arrays");
        int ns = cJSON_GetArraySize(samplers);
        const mesh_plan **done = mk_arena_array(&w->tmp, (size_t)ns + 1, sizeof *done);
        if (!done) return mk_error_oom(w->err, "glTF write-back");
        int ci = 0;
        cJSON *ch;
        cJSON_ArrayForEach(ch, chans) {
            char cp[96];
            snprintf(cp, sizeof cp, "%s.channels[%d]", ap, ci++);
            cJSON *tgt = cJSON_GetObjectItemCaseSensitive(ch, "target");
            cJSON *path = cJSON_GetObjectItemCaseSensitive(tgt, "path");
            if (!cJSON_IsString(path) || strcmp(path->valuestring, "weights")) continue;
            int32_t node, si, mesh;
            if ((r = get_index(w, tgt, "node", (uint32_t)cJSON_GetArraySize(w->nodes), cp, 0, &node)) != MK_OK) return r;
            if (node < 0) continue;
            if ((r = get_index(w, ch, "sampler", (uint32_t)ns, cp, 1, &si)) != MK_OK) return r;
            if ((r = get_index(w, cJSON_GetArrayItem(w->nodes, node), "mesh", UINT32_MAX, cp, 0, &mesh)) != MK_OK) return r;
            const mesh_plan *p = mesh >= 0 ? plan_of(w, mesh) : NULL;
            if (!p || !p->slot_count) continue;
            if (done[si]) {
                if (done[si] != p) return bad(w, cp, "a weights sampler shared by nodes of different meshes");
                continue;
            }
            done[si] = p;
            char sp[96];
            snprintf(sp, sizeof sp, "%s.samplers[%d]", ap, si);
            cJSON *smp = cJSON_GetArrayItem(samplers, si);
            int32_t in, out;
            if ((r = get_index(w, smp, "input", w->doc.accessor_count, sp, 1, &in)) != MK_OK) return r;
            if ((r = get_index(w, smp, "output", w->doc.accessor_count, sp, 1, &out)) != MK_OK) return r;
            cJSON *ip = cJSON_GetObjectItemCaseSensitive(smp, "interpolation");
            int cubic = cJSON_IsString(ip) && !strcmp(ip->valuestring, "CUBICSPLINE");
            uint64_t keys = w->doc.accessors[in].count, n;
            float *vals;
            if ((r = mk_gltf_read_floats(&w->reader, out, 1, sp, &vals, &n, w->err)) != MK_OK) return r;
            uint32_t T = p->old_targets, S = p->slot_count, parts = cubic ? 3 : 1;
            if (n != keys * T * parts) return bad(w, sp, "output count is not keys x targets");
            size_t total = (size_t)keys * parts * (T + S);
            float *nv = malloc(total * sizeof(float) + 4);
            if (!nv) return mk_error_oom(w->err, "glTF write-back");
            size_t o = 0;
            for (uint64_t k = 0; k < keys * parts; k++) {
                int value_part = !cubic || k % 3 == 1;
                memcpy(nv + o, vals + k * T, (size_t)T * sizeof(float));
                o += T;
                for (uint32_t s = 0; s < S; s++) nv[o++] = value_part ? p->defaults[s] : 0.0f;
            }
            int32_t acc = add_floats(w, nv, total, 0, &r);
            free(nv);
            if (r != MK_OK) return r;
            set_num(w, smp, "output", acc);
            w->rep->rewritten_samplers++;
        }
    }
    return r;
}

static const mk_raw_track *track_of(const mk_raw_clip *clip, uint32_t channel)
{
    for (uint32_t t = 0; t < clip->track_count; t++)
        if (clip->tracks[t].channel == channel) return &clip->tracks[t];
    return NULL;
}

/* Appends the key-sampling times of one track: its keys and what gltf_weights.h samples
 * between them (as `morphkit export` does). */
static mk_result track_times(wb *w, const mk_raw_track *t, const mk_raw_channel *ch, float **times, size_t *n, size_t *cap)
{
    float *add = mk_arena_array(&w->tmp, MK_GLTF_SEGMENT_TIMES + 1, sizeof(float));
    if (!add) return mk_error_oom(w->err, "glTF write-back");
    for (uint32_t k = 0; k < t->key_count; k++) {
        add[0] = t->keys[k].time;
        size_t na = 1 + (k + 1 < t->key_count ? mk_gltf_segment_times(&t->keys[k], &t->keys[k + 1], ch, add + 1) : 0);
        if (*n + na > *cap) {
            size_t c = (*cap ? *cap * 2 : 256) + na;
            float *g = mk_arena_realloc(&w->tmp, *times, *cap * sizeof(float), c * sizeof(float));
            if (!g) return mk_error_oom(w->err, "glTF write-back");
            *times = g;
            *cap = c;
        }
        memcpy(*times + *n, add, na * sizeof(float));
        *n += na;
    }
    mk_arena_release(&w->tmp, add);
    return MK_OK;
}

/* Clips the bake added (past the file's animations): one new animation each, every node with a
 * track sampled to LINEAR keys over all its targets; channels without a track hold their
 * default weight, as morphkit plays them. */
static mk_result add_clips(wb *w)
{
    const mk_raw_asset *raw = w->raw;
    mk_result r = MK_OK;
    for (uint32_t c = w->animation_count; c < raw->clip_count && r == MK_OK; c++) {
        const mk_raw_clip *clip = &raw->clips[c];
        if ((r = root_array(w, "animations", 1, &w->animations)) != MK_OK) return r;
        cJSON *anim = track(w, cJSON_CreateObject()), *chans = track(w, cJSON_CreateArray()), *smps = track(w, cJSON_CreateArray());
        if (w->oom) { cJSON_Delete(anim); cJSON_Delete(chans); cJSON_Delete(smps); return mk_error_oom(w->err, "glTF write-back"); }
        if (clip->name) add_str(w, anim, "name", clip->name);
        add_item(w, anim, "channels", chans);
        add_item(w, anim, "samplers", smps);
        add_item(w, w->animations, NULL, anim);
        int node_total = cJSON_GetArraySize(w->nodes);
        for (int node = 0; node < node_total && r == MK_OK; node++) {
            int32_t mesh;
            if ((r = get_index(w, cJSON_GetArrayItem(w->nodes, node), "mesh", UINT32_MAX, "nodes", 0, &mesh)) != MK_OK) return r;
            if (mesh < 0) continue;
            /* The node's channels per glTF target: the primitive-0 import for old targets, the
             * slots' channels for new ones. */
            const mesh_plan *p = plan_of(w, mesh);
            int32_t rm0 = raw_mesh_of(raw, node, mesh, 0);
            if (rm0 < 0) continue;
            uint32_t *b, nb, *orig, T;
            const cJSON *tg = cJSON_GetObjectItemCaseSensitive(
                cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(w->meshes, mesh), "primitives"), 0), "targets");
            T = p ? p->old_targets : (uint32_t)cJSON_GetArraySize(tg);
            uint32_t S = p ? p->slot_count : 0;
            if ((r = channels_of(w, (uint32_t)rm0, T, &b, &nb, &orig)) != MK_OK) return r;
            const mk_raw_channel **drv = mk_arena_array(&w->tmp, (size_t)T + S + 1, sizeof *drv);
            if (!drv) return mk_error_oom(w->err, "glTF write-back");
            int any = 0;
            for (uint32_t k = 0; k < T; k++) drv[k] = &raw->channels[orig[k]];
            for (uint32_t s = 0; s < S; s++) drv[T + s] = slot_channel(w, p, node, &p->slots[s]);
            float *times = NULL;
            size_t n = 0, cap = 0;
            for (uint32_t k = 0; k < T + S && r == MK_OK; k++) {
                if (k >= T && p->slots[k - T].target) continue;   /* one pass per channel */
                const mk_raw_track *t = track_of(clip, (uint32_t)(drv[k] - raw->channels));
                if (t) { any = 1; r = track_times(w, t, drv[k], &times, &n, &cap); }
            }
            if (r != MK_OK || !any) continue;
            size_t u = mk_gltf_unique_times(times, n);
            float *vals = mk_arena_array(&w->tmp, u * (T + S) + 1, sizeof(float)), wts[256];
            if (!vals) return mk_error_oom(w->err, "glTF write-back");
            for (size_t i = 0; i < u; i++)
                for (uint32_t k = 0; k < T + S; k++) {
                    const mk_raw_channel *ch = drv[k];
                    const mk_raw_track *t = track_of(clip, (uint32_t)(ch - raw->channels));
                    float wv = t ? mk_curve_eval(t->keys, t->key_count, times[i], NULL) : ch->default_weight;
                    if (k < T) { vals[i * (T + S) + k] = wv; continue; }
                    mk_gltf_slot_weights(ch, wv, wts);
                    vals[i * (T + S) + k] = wts[p->slots[k - T].target];
                }
            int32_t in = add_floats(w, times, u, 1, &r);
            int32_t out = r == MK_OK ? add_floats(w, vals, u * (T + S), 0, &r) : -1;
            if (r != MK_OK) return r;
            cJSON *smp = track(w, cJSON_CreateObject()), *ch = track(w, cJSON_CreateObject()), *tgt = track(w, cJSON_CreateObject());
            if (w->oom) { cJSON_Delete(smp); cJSON_Delete(ch); cJSON_Delete(tgt); return mk_error_oom(w->err, "glTF write-back"); }
            add_num(w, smp, "input", in);
            add_str(w, smp, "interpolation", "LINEAR");
            add_num(w, smp, "output", out);
            add_num(w, ch, "sampler", cJSON_GetArraySize(smps));
            add_item(w, smps, NULL, smp);
            add_num(w, tgt, "node", node);
            add_str(w, tgt, "path", "weights");
            add_item(w, ch, "target", tgt);
            add_item(w, chans, NULL, ch);
        }
        w->rep->animations_added++;
    }
    return r;
}

/* ---- the channel sidecar (docs/importing-gltf.md) ---- */

static mk_result make_sidecar(wb *w, mk_arena *arena, char **text, size_t *size)
{
    const mk_raw_asset *raw = w->raw;
    cJSON *root = cJSON_CreateObject(), *meshes = cJSON_CreateArray();
    wb *x = w;
    if (!root || !meshes) { cJSON_Delete(root); cJSON_Delete(meshes); return mk_error_oom(w->err, "sidecar"); }
    add_str(x, root, "format", "morphkit-gltf-channels");
    add_num(x, root, "version", 1);
    add_item(x, root, "meshes", meshes);
    mk_result r = MK_OK;
    for (uint32_t i = 0; i < w->plan_count && r == MK_OK; i++) {
        const mesh_plan *p = &w->plans[i];
        if (!p->slot_count) continue;
        for (uint32_t ni = 0; ni < p->node_count && r == MK_OK; ni++)
            for (uint32_t q = 0; q < p->prim_count && r == MK_OK; q++) {
                int32_t rm = raw_mesh_of(raw, p->nodes[ni], p->mesh, q);
                uint32_t *b, nb, *orig;
                if ((r = channels_of(w, (uint32_t)rm, p->old_targets, &b, &nb, &orig)) != MK_OK) break;
                cJSON *e = cJSON_CreateObject(), *chans = cJSON_CreateArray(), *unused = cJSON_CreateArray();
                add_item(x, meshes, NULL, e);
                if (!e || !chans || !unused) { cJSON_Delete(chans); cJSON_Delete(unused); x->oom = 1; break; }
                add_num(x, e, "node", p->nodes[ni]);
                add_num(x, e, "primitive", q);
                add_str(x, e, "name", raw->meshes[rm].name ? raw->meshes[rm].name : "");
                if (raw->meshes[rm].stacking == MK_STACKING_SEQUENTIAL) add_str(x, e, "stacking", "sequential");
                for (uint32_t k = 0; k < p->old_targets; k++) {
                    cJSON *c = cJSON_CreateObject();
                    add_item(x, chans, NULL, c);
                    if (!c) break;
                    add_str(x, c, "name", raw->channels[orig[k]].name ? raw->channels[orig[k]].name : "");
                    add_item(x, c, "targets", cJSON_CreateIntArray((const int[]){ (int)k }, 1));
                }
                for (uint32_t s = 0; s < p->slot_count; s++) {
                    if (p->slots[s].prim != q) { add_item(x, unused, NULL, cJSON_CreateNumber(p->old_targets + s)); continue; }
                    if (p->slots[s].target) continue;
                    const mk_raw_channel *ch = slot_channel(w, p, p->nodes[ni], &p->slots[s]);
                    cJSON *c = cJSON_CreateObject(), *tg = cJSON_CreateArray(), *fw = cJSON_CreateArray(), *tn = cJSON_CreateArray();
                    add_item(x, chans, NULL, c);
                    if (!c || !tg || !fw || !tn) { cJSON_Delete(tg); cJSON_Delete(fw); cJSON_Delete(tn); x->oom = 1; break; }
                    add_str(x, c, "name", ch->name ? ch->name : "");
                    for (uint32_t t = 0; t < ch->target_count; t++) {
                        add_item(x, tg, NULL, cJSON_CreateNumber(p->old_targets + s + t));
                        add_item(x, fw, NULL, cJSON_CreateNumber(ch->targets[t].full_weight));
                        add_str(x, tn, NULL, ch->targets[t].name ? ch->targets[t].name : "");
                    }
                    add_item(x, c, "targets", tg);
                    add_item(x, c, "full_weights", fw);
                    add_item(x, c, "target_names", tn);
                    add_str(x, c, "origin", ch->origin);
                }
                add_item(x, e, "channels", chans);
                if (cJSON_GetArraySize(unused)) add_item(x, e, "unused_targets", unused);
                else cJSON_Delete(unused);
            }
    }
    if (raw->clip_count && r == MK_OK) {
        cJSON *clips = cJSON_CreateArray();
        add_item(x, root, "clips", clips);
        for (uint32_t c = 0; clips && c < raw->clip_count; c++) {
            cJSON *o = cJSON_CreateObject();
            add_item(x, clips, NULL, o);
            if (!o) break;
            add_str(x, o, "name", raw->clips[c].name ? raw->clips[c].name : "");
            add_num(x, o, "start", raw->clips[c].start);
            add_num(x, o, "duration", raw->clips[c].duration);
        }
    }
    char *s = r == MK_OK && !x->oom ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (r != MK_OK) return r;
    if (!s) return mk_error_oom(w->err, "sidecar");
    *size = strlen(s);
    *text = mk_arena_strndup(arena, s, *size);
    free(s);
    return *text ? MK_OK : mk_error_oom(w->err, "sidecar");
}

/* ---- URIs ---- */

static int relative_uri(const char *u)
{
    if (!u[0] || u[0] == '/' || u[0] == '\\' || !strncmp(u, "data:", 5)) return 0;
    for (const char *c = u; *c && *c != '/'; c++)
        if (*c == ':') return 0;   /* a scheme (or C:\) */
    return 1;
}

/* Relative URIs of buffers and images point at the input's folder from the output's. */
static mk_result rewrite_uris(wb *w, const char *input_path, const char *output_path)
{
    if (!input_path || !output_path) return MK_OK;
    char a[4096], b[4096], in_dir[PATH_MAX], out_dir[PATH_MAX];
    mk_path_dir(input_path, a, sizeof a);
    mk_path_dir(output_path, b, sizeof b);
    if (!realpath(a, in_dir) || !realpath(b, out_dir)) return MK_OK;   /* the output check reports a missing folder */
    if (!strcmp(in_dir, out_dir)) return MK_OK;
    /* prefix = out_dir -> in_dir, percent-encoded */
    size_t common = 0, i = 0;
    for (; in_dir[i] && in_dir[i] == out_dir[i]; i++)
        if (in_dir[i] == '/') common = i;
    if ((!in_dir[i] || in_dir[i] == '/') && (!out_dir[i] || out_dir[i] == '/')) common = i;
    char prefix[8192];
    size_t n = 0;
    for (const char *c = out_dir + common; *c && n + 4 < sizeof prefix; c++)
        if (*c == '/' && c[1]) { memcpy(prefix + n, "../", 3); n += 3; }
    if (common == 1 && out_dir[1] == 0) { /* out_dir is "/" */ }
    for (const char *c = in_dir + common + (in_dir[common] == '/'); *c && n + 4 < sizeof prefix; c++) {
        unsigned char ch = (unsigned char)*c;
        if ((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || strchr("-._~/!$&'()*+,;=@", ch))
            prefix[n++] = (char)ch;
        else n += (size_t)snprintf(prefix + n, sizeof prefix - n, "%%%02X", ch);
    }
    if (n && prefix[n - 1] != '/') prefix[n++] = '/';
    prefix[n] = 0;
    static const char *const lists[] = { "buffers", "images" };
    for (int l = 0; l < 2; l++) {
        cJSON *arr = cJSON_GetObjectItemCaseSensitive(w->root, lists[l]), *e;
        if (!cJSON_IsArray(arr)) continue;
        cJSON_ArrayForEach(e, arr) {
            cJSON *u = cJSON_GetObjectItemCaseSensitive(e, "uri");
            if (!cJSON_IsString(u) || !relative_uri(u->valuestring)) continue;
            size_t len = n + strlen(u->valuestring) + 1;
            char *s = malloc(len);
            if (!s) return mk_error_oom(w->err, "glTF write-back");
            snprintf(s, len, "%s%s", prefix, u->valuestring);
            cJSON *ns = track(w, cJSON_CreateString(s));
            free(s);
            if (ns && !cJSON_ReplaceItemInObjectCaseSensitive(e, "uri", ns)) { cJSON_Delete(ns); w->oom = 1; }
            w->rep->rewritten_uris++;
        }
    }
    if (w->rep->rewritten_uris)
        note(w, "%u relative URIs now point at the input's folder (%s) from the output's", w->rep->rewritten_uris, prefix);
    return w->oom ? mk_error_oom(w->err, "glTF write-back") : MK_OK;
}

/* ---- container ---- */

static uint32_t rd32(const uint8_t *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static void wr32(uint8_t *p, uint32_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24); }

static mk_result split_container(wb *w, const uint8_t *in, size_t size)
{
    if (size >= 4 && !memcmp(in, "glTF", 4)) {
        w->glb = 1;
        if (size < 20) return mk_error_set(w->err, MK_ERROR_PARSE, 0, "glTF write-back: GLB shorter than its header");
        uint32_t length = rd32(in + 8);
        if (rd32(in + 4) != 2) return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, 4, "glTF write-back: GLB version %u", rd32(in + 4));
        if (length > size || length < 20) return mk_error_set(w->err, MK_ERROR_PARSE, 8, "glTF write-back: GLB length %u, file %zu bytes", length, size);
        uint32_t jl = rd32(in + 12);
        if (rd32(in + 16) != GLB_JSON || jl > length - 20)
            return mk_error_set(w->err, MK_ERROR_PARSE, 12, "glTF write-back: GLB first chunk is not a JSON chunk that fits");
        w->json_text = in + 20;
        w->json_size = jl;
        size_t at = 20 + (size_t)jl;
        if (at + 8 <= length && rd32(in + at + 4) == GLB_BIN) {
            uint32_t bl = rd32(in + at);
            if (bl > length - at - 8) return mk_error_set(w->err, MK_ERROR_PARSE, at, "glTF write-back: GLB BIN chunk past the file");
            w->bin = in + at + 8;
            w->bin_size = bl;
            at += 8 + (size_t)bl;
        }
        w->after_bin = in + at;
        w->after_bin_size = length - at;
        return MK_OK;
    }
    w->json_text = in;
    w->json_size = size;
    return MK_OK;
}

static mk_result assemble(wb *w, mk_arena *arena, void **out, size_t *out_size)
{
    if (w->size && w->in_bin) {
        cJSON *b0 = cJSON_GetArrayItem(w->buffers, 0);
        set_num(w, b0, "byteLength", (double)(w->data_base + w->size));
    } else if (w->size) {
        /* A buffer of its own, embedded as base64 */
        static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        static const char head[] = "data:application/octet-stream;base64,";
        size_t hl = sizeof head - 1, n = hl + (w->size + 2) / 3 * 4 + 1;
        char *s = malloc(n);
        if (!s) return mk_error_oom(w->err, "glTF write-back");
        memcpy(s, head, hl);
        size_t o = hl;
        for (size_t i = 0; i < w->size; i += 3) {
            uint32_t v = (uint32_t)w->data[i] << 16 | (i + 1 < w->size ? (uint32_t)w->data[i + 1] << 8 : 0) |
                         (i + 2 < w->size ? w->data[i + 2] : 0);
            s[o++] = tab[v >> 18 & 63];
            s[o++] = tab[v >> 12 & 63];
            s[o++] = i + 1 < w->size ? tab[v >> 6 & 63] : '=';
            s[o++] = i + 2 < w->size ? tab[v & 63] : '=';
        }
        s[o] = 0;
        cJSON *b = track(w, cJSON_CreateObject());
        if (b) {
            add_num(w, b, "byteLength", (double)w->size);
            add_str(w, b, "uri", s);
            add_item(w, w->buffers, NULL, b);
        }
        free(s);
    }
    if (w->oom) return mk_error_oom(w->err, "glTF write-back");
    char *json = w->glb ? cJSON_PrintUnformatted(w->root) : cJSON_Print(w->root);
    if (!json) return mk_error_oom(w->err, "glTF write-back");
    size_t jl = strlen(json);
    if (!w->glb) {
        *out = mk_arena_alloc(arena, jl + 1);
        if (*out) { memcpy(*out, json, jl); ((char *)*out)[jl] = '\n'; *out_size = jl + 1; }
        free(json);
        return *out ? MK_OK : mk_error_oom(w->err, "glTF write-back");
    }
    size_t jp = (jl + 3) & ~(size_t)3;
    uint64_t bin = w->in_bin ? w->data_base + w->size : w->bin ? w->bin_size : 0;
    int has_bin = w->bin || (w->in_bin && w->size);
    bin = (bin + 3) & ~(uint64_t)3;
    uint64_t total = 12 + 8 + jp + (has_bin ? 8 + bin : 0) + w->after_bin_size;
    if (total > UINT32_MAX) { free(json); return mk_error_set(w->err, MK_ERROR_LIMIT, UINT64_MAX, "glTF write-back: the GLB would pass 4 GiB"); }
    uint8_t *o = mk_arena_alloc(arena, (size_t)total);
    if (!o) { free(json); return mk_error_oom(w->err, "glTF write-back"); }
    memset(o, 0, (size_t)total);
    memcpy(o, "glTF", 4);
    wr32(o + 4, 2);
    wr32(o + 8, (uint32_t)total);
    wr32(o + 12, (uint32_t)jp);
    wr32(o + 16, GLB_JSON);
    memcpy(o + 20, json, jl);
    memset(o + 20 + jl, ' ', jp - jl);
    free(json);
    size_t at = 20 + jp;
    if (has_bin) {
        wr32(o + at, (uint32_t)bin);
        wr32(o + at + 4, GLB_BIN);
        if (w->bin_size) memcpy(o + at + 8, w->bin, (size_t)w->bin_size);
        if (w->in_bin && w->size) memcpy(o + at + 8 + w->data_base, w->data, w->size);
        at += 8 + (size_t)bin;
    }
    if (w->after_bin_size) memcpy(o + at, w->after_bin, w->after_bin_size);
    *out = o;
    *out_size = (size_t)total;
    return MK_OK;
}

/* ---- entry ---- */

static mk_result run(wb *w, const uint8_t *in, size_t size, const char *input_path, const char *output_path,
                     mk_arena *arena, void **out, size_t *out_size, char **sidecar, size_t *sidecar_size)
{
    mk_result r = split_container(w, in, size);
    if (r != MK_OK) return r;
    if (output_path && !mk_path_has_extension(output_path, w->glb ? ".glb" : ".gltf"))
        return mk_error_set(w->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "glTF write-back: the input is %s, so the output must end in %s (%.200s)",
                            w->glb ? "a .glb" : "glTF JSON", w->glb ? ".glb" : ".gltf", output_path);
    char base[4096];
    if (input_path) mk_path_dir(input_path, base, sizeof base);
    if ((r = mk_gltf_doc_load(&w->tmp, in, size, w->glb, input_path ? base : NULL, 0, NULL, NULL, &w->doc, w->err)) != MK_OK)
        return r;
    w->doc_loaded = 1;
    if ((r = mk_gltf_reader_init(&w->reader, &w->doc, &w->tmp, w->err)) != MK_OK) return r;
    w->root = cJSON_ParseWithLength((const char *)w->json_text, w->json_size);
    if (!w->root) return mk_error_set(w->err, MK_ERROR_PARSE, UINT64_MAX, "glTF write-back: the JSON does not parse (cJSON)");
    if (!cJSON_IsObject(w->root)) return bad(w, "(document)", "expected an object");
    if ((r = check_numbers(w, w->root->child, 0)) != MK_OK) return r;
    if ((r = root_array(w, "meshes", 0, &w->meshes)) != MK_OK || (r = root_array(w, "nodes", 0, &w->nodes)) != MK_OK ||
        (r = root_array(w, "animations", 0, &w->animations)) != MK_OK)
        return r;
    w->animation_count = (uint32_t)cJSON_GetArraySize(w->animations);
    const mk_raw_asset *raw = w->raw;
    if (raw->clip_count < w->animation_count)
        return mk_error_set(w->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "glTF write-back: the asset has %u clips, the file %u animations: it was not imported from this file",
                            raw->clip_count, w->animation_count);
    for (uint32_t m = 0; m < raw->mesh_count; m++)
        if (raw->meshes[m].gltf_mesh >= cJSON_GetArraySize(w->meshes) || raw->meshes[m].gltf_node >= cJSON_GetArraySize(w->nodes))
            return mk_error_set(w->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "glTF write-back: raw mesh '%s' names glTF node %d mesh %d, which this file does not have",
                                raw->meshes[m].name ? raw->meshes[m].name : "", raw->meshes[m].gltf_node, raw->meshes[m].gltf_mesh);
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (baked(&raw->channels[c]) && raw->meshes[raw->channels[c].mesh].gltf_mesh < 0)
            return mk_error_set(w->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "glTF write-back: baked channel '%s' is on mesh '%s', which did not come from glTF",
                                raw->channels[c].name, raw->meshes[raw->channels[c].mesh].name);
    int nmesh = cJSON_GetArraySize(w->meshes);
    w->plans = mk_arena_array(&w->tmp, (size_t)nmesh + 1, sizeof *w->plans);
    if (!w->plans) return mk_error_oom(w->err, "glTF write-back");
    for (int mi = 0; mi < nmesh; mi++) {
        int used = 0;
        for (uint32_t m = 0; m < raw->mesh_count; m++) used |= raw->meshes[m].gltf_mesh == mi;
        if (!used) continue;
        if ((r = plan_mesh(w, mi, &w->plans[w->plan_count])) != MK_OK) return r;
        if (w->plans[w->plan_count].slot_count) {
            w->rep->meshes++;
            w->rep->targets += w->plans[w->plan_count].slot_count;
        }
        w->plan_count++;
    }
    int nothing = w->rep->targets == 0 && raw->clip_count == w->animation_count;
    if (nothing) note(w, "no baked channel or clip: the file is written unchanged");
    if (!nothing) {
        if ((r = root_array(w, "accessors", 1, &w->accessors)) != MK_OK || (r = root_array(w, "bufferViews", 1, &w->views)) != MK_OK ||
            (r = root_array(w, "buffers", 1, &w->buffers)) != MK_OK)
            return r;
        cJSON *b0 = cJSON_GetArrayItem(w->buffers, 0);
        if (w->glb && w->bin && cJSON_IsObject(b0) && !cJSON_GetObjectItemCaseSensitive(b0, "uri")) {
            const cJSON *bl = cJSON_GetObjectItemCaseSensitive(b0, "byteLength");
            if (!is_uint(bl, 9007199254740992.0) || bl->valuedouble > (double)w->bin_size)
                return bad(w, "buffers[0]", "\"byteLength\" is not a length within the GLB BIN chunk");
            w->in_bin = 1;
            w->data_buffer = 0;
            w->data_base = (w->bin_size + 3) & ~(uint64_t)3;
        } else {
            w->data_buffer = cJSON_GetArraySize(w->buffers);
            w->data_base = 0;
        }
        for (uint32_t i = 0; i < w->plan_count && r == MK_OK; i++) {
            const mesh_plan *p = &w->plans[i];
            if (!p->slot_count) continue;
            char path[48];
            snprintf(path, sizeof path, "meshes[%d]", p->mesh);
            if ((r = write_mesh_targets(w, p)) != MK_OK) return r;
            if ((r = extend_weights(w, cJSON_GetArrayItem(w->meshes, p->mesh), path, p, 1)) != MK_OK) return r;
            for (uint32_t n = 0; n < p->node_count; n++) {
                snprintf(path, sizeof path, "nodes[%d]", p->nodes[n]);
                if ((r = extend_weights(w, cJSON_GetArrayItem(w->nodes, p->nodes[n]), path, p, 0)) != MK_OK) return r;
            }
            if ((r = extend_names(w, p)) != MK_OK) return r;
        }
        if ((r = extend_animations(w)) != MK_OK) return r;
        if ((r = add_clips(w)) != MK_OK) return r;
        if (w->rep->float_fallbacks)
            note(w, "%u accessors of quantized primitives written as float (a delta outside the quantized range)",
                 w->rep->float_fallbacks);
    }
    if ((r = rewrite_uris(w, input_path, output_path)) != MK_OK) return r;
    w->rep->added_bytes = w->size;
    if (nothing && !w->rep->rewritten_uris) {
        *out = mk_arena_alloc(arena, size ? size : 1);
        if (!*out) return mk_error_oom(w->err, "glTF write-back");
        memcpy(*out, in, size);
        *out_size = size;
    } else if ((r = assemble(w, arena, out, out_size)) != MK_OK) {
        return r;
    }
    if (sidecar) {
        *sidecar = NULL;
        *sidecar_size = 0;
        if (w->rep->channels || raw->clip_count > w->animation_count) r = make_sidecar(w, arena, sidecar, sidecar_size);
    }
    return r;
}

mk_result mk_gltf_write_back(const void *input, size_t input_size, const char *input_path, const char *output_path,
                             const mk_raw_asset *raw, mk_arena *arena, void **out, size_t *out_size, char **sidecar,
                             size_t *sidecar_size, mk_gltf_write_back_report *report, mk_error *err)
{
    if (!input || !raw || !arena || !out || !out_size || (sidecar && !sidecar_size))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "glTF write-back: invalid argument");
    mk_gltf_write_back_report local;
    wb w;
    memset(&w, 0, sizeof w);
    w.rep = report ? report : &local;
    memset(w.rep, 0, sizeof *w.rep);
    w.raw = raw;
    w.err = err;
    mk_arena_init(&w.tmp, NULL);
    *out = NULL;
    *out_size = 0;
    mk_result r = run(&w, input, input_size, input_path, output_path, arena, out, out_size, sidecar, sidecar_size);
    if (r != MK_OK) {
        *out = NULL;
        *out_size = 0;
        if (sidecar) { *sidecar = NULL; *sidecar_size = 0; }
    }
    cJSON_Delete(w.root);
    if (w.doc_loaded) mk_gltf_doc_free(&w.doc);
    mk_arena_free_all(&w.tmp);
    free(w.data);
    return r;
}

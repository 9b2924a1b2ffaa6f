/* SPDX-License-Identifier: MIT */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "blob_io.h"
#include "obj.h"
#include "reference.h"

#define REFERENCE_MAX_BYTES ((size_t)1 << 30)

/* A JSON array of finite numbers into arena memory; count 0 and NULL when absent. */
static mk_result number_array(pb_reference *r, const cJSON *array, const char *path, const char *what, double **out,
                              uint32_t *count, mk_error *err)
{
    *out = NULL;
    *count = 0;
    if (!array || cJSON_IsNull(array)) return MK_OK;
    int n = cJSON_GetArraySize(array);
    if (!cJSON_IsArray(array))
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: %s must be an array", path, what);
    double *p = mk_arena_array(&r->arena, (size_t)n + 1, sizeof(double));
    if (!p) return mk_error_oom(err, "reference frame");
    uint32_t i = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, array)
    {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: %s[%u] is not a finite number", path, what,
                                i);
        p[i++] = e->valuedouble;
    }
    *out = p;
    *count = i;
    return MK_OK;
}

static int32_t int_or(const cJSON *item, int32_t fallback)
{
    return cJSON_IsNumber(item) ? (int32_t)item->valuedouble : fallback;
}

static mk_result read_json_mesh(pb_reference *r, const char *path, pb_reference_kind kind, uint32_t index,
                                const cJSON *j, pb_ref_mesh *m, mk_error *err)
{
    char what[96];
    const char *node = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "node"));
    const char *label = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "label"));
    const char *name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "name"));
    m->node = node ? mk_arena_strdup(&r->arena, node) : name ? mk_arena_strdup(&r->arena, name) : NULL;
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = m->mesh_index = -1;
    if (kind == PB_REF_THREE_JSON) {
        m->gltf_node = int_or(cJSON_GetObjectItemCaseSensitive(j, "node"), -1);
        m->gltf_mesh = int_or(cJSON_GetObjectItemCaseSensitive(j, "mesh"), -1);
        m->gltf_primitive = int_or(cJSON_GetObjectItemCaseSensitive(j, "primitive"), -1);
        m->node = NULL;
    } else if (kind == PB_REF_MORPHKIT_JSON) {
        m->gltf_node = int_or(cJSON_GetObjectItemCaseSensitive(j, "gltf_node"), -1);
        m->gltf_mesh = int_or(cJSON_GetObjectItemCaseSensitive(j, "gltf_mesh"), -1);
        m->gltf_primitive = int_or(cJSON_GetObjectItemCaseSensitive(j, "gltf_primitive"), -1);
        m->mesh_index = int_or(cJSON_GetObjectItemCaseSensitive(j, "mesh_index"), -1);
    }
    char fallback[64];
    snprintf(fallback, sizeof fallback, "mesh %u", index);
    m->label = mk_arena_strdup(&r->arena, label ? label : m->node ? m->node : fallback);
    if (!m->label) return mk_error_oom(err, "reference frame");
    /* Channel weights: three.js "weights": [w...]; ufbx and morphkit "channels": [{name, weight}]. */
    const cJSON *weights = cJSON_GetObjectItemCaseSensitive(j, "weights");
    const cJSON *channels = cJSON_GetObjectItemCaseSensitive(j, "channels");
    mk_result res = MK_OK;
    if (cJSON_IsArray(weights)) {
        snprintf(what, sizeof what, "meshes[%u].weights", index);
        res = number_array(r, weights, path, what, &m->weights, &m->weight_count, err);
        m->has_channels = m->weight_count > 0;
    } else if (cJSON_IsArray(channels)) {
        int n = cJSON_GetArraySize(channels);
        m->weights = mk_arena_array(&r->arena, (size_t)n + 1, sizeof(double));
        if (!m->weights) return mk_error_oom(err, "reference frame");
        const cJSON *c;
        cJSON_ArrayForEach(c, channels)
        {
            const cJSON *w = cJSON_GetObjectItemCaseSensitive(c, "weight");
            m->weights[m->weight_count++] = cJSON_IsNumber(w) ? w->valuedouble : NAN;
        }
        m->has_channels = n > 0;
    }
    if (res != MK_OK) return res;
    uint32_t count, ncount;
    snprintf(what, sizeof what, "meshes[%u].positions", index);
    if ((res = number_array(r, cJSON_GetObjectItemCaseSensitive(j, "positions"), path, what, &m->positions, &count,
                            err)) != MK_OK)
        return res;
    if (!m->positions || count % 3)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: %s must hold 3 numbers per point", path, what);
    m->point_count = count / 3;
    snprintf(what, sizeof what, "meshes[%u].normals", index);
    if ((res = number_array(r, cJSON_GetObjectItemCaseSensitive(j, "normals"), path, what, &m->normals, &ncount,
                            err)) != MK_OK)
        return res;
    if (m->normals && ncount != count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: %s has %u numbers, positions %u", path, what,
                            ncount, count);
    return MK_OK;
}

/* OBJ: its vertices in order are the points; its normals, when one per vertex, theirs. */
static mk_result read_obj(pb_reference *r, const char *path, mk_error *err)
{
    mk_obj obj;
    mk_result res = mk_obj_read(path, &r->arena, &obj, err);
    if (res != MK_OK) return res;
    pb_ref_mesh *m = r->meshes = mk_arena_array(&r->arena, 1, sizeof(pb_ref_mesh));
    if (!m) return mk_error_oom(err, "reference frame");
    r->mesh_count = 1;
    m->label = "obj";
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = m->mesh_index = -1;
    m->has_channels = 1; /* an OBJ frame is of the mesh with channels */
    m->positions = obj.positions;
    m->normals = obj.normals;
    m->point_count = obj.vertex_count;
    return MK_OK;
}

/* Little-endian u32 at p. */
static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* n little-endian floats at *at into doubles (out may be NULL); 0 when they pass the end. */
static int read_floats(const unsigned char *data, size_t size, size_t *at, size_t n, double *out)
{
    if (n > (size - *at) / 4) return 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t u = le32(data + *at + 4 * i);
        float f;
        memcpy(&f, &u, 4);
        if (out) out[i] = f;
    }
    *at += 4 * n;
    return 1;
}

/* The binary frame format (docs/conformance.md): a 48-byte header, the weights of every
 * channel, then per mesh a 16-byte header and its positions, normals and tangents. */
static mk_result read_mkf(pb_reference *r, const char *path, const unsigned char *data, size_t size, mk_error *err)
{
    if (size < 48 || memcmp(data, "MKFRAME1", 8) != 0 || le32(data + 8) != 1)
        return mk_error_set(err, MK_ERROR_PARSE, 0, "%.200s: not a morphkit frame (.mkf version 1)", path);
    uint32_t meshes = le32(data + 12), channels = le32(data + 16);
    size_t at = 48;
    double *weights = mk_arena_array(&r->arena, (size_t)channels + 1, sizeof(double));
    if (!weights) return mk_error_oom(err, "reference frame");
    if (meshes > size / 16 || !read_floats(data, size, &at, channels, weights))
        return mk_error_set(err, MK_ERROR_TRUNCATED, at, "%.200s: the frame is shorter than its counts", path);
    r->meshes = mk_arena_array(&r->arena, (size_t)meshes + 1, sizeof(pb_ref_mesh));
    if (!r->meshes) return mk_error_oom(err, "reference frame");
    for (uint32_t i = 0; i < meshes; i++) {
        if (size - at < 16) return mk_error_set(err, MK_ERROR_TRUNCATED, at, "%.200s: mesh %u is cut off", path, i);
        uint32_t n = le32(data + at), first = le32(data + at + 4), count = le32(data + at + 8), flags = le32(data + at + 12);
        at += 16;
        if (first > channels || count > channels - first)
            return mk_error_set(err, MK_ERROR_PARSE, at - 16, "%.200s: mesh %u's channels pass the %u weights", path, i, channels);
        pb_ref_mesh *m = &r->meshes[r->mesh_count++];
        char label[32];
        snprintf(label, sizeof label, "mesh %u", i);
        m->label = mk_arena_strdup(&r->arena, label);
        m->gltf_node = m->gltf_mesh = m->gltf_primitive = -1;
        m->mesh_index = (int32_t)i;
        m->has_channels = count > 0;
        m->weights = weights + first;
        m->weight_count = count;
        m->point_count = n;
        m->positions = mk_arena_array(&r->arena, 3 * (size_t)n + 3, sizeof(double));
        m->normals = (flags & 1u) ? mk_arena_array(&r->arena, 3 * (size_t)n + 3, sizeof(double)) : NULL;
        if (!m->label || !m->positions || ((flags & 1u) && !m->normals)) return mk_error_oom(err, "reference frame");
        if (!read_floats(data, size, &at, 3 * (size_t)n, m->positions)
            || ((flags & 1u) && !read_floats(data, size, &at, 3 * (size_t)n, m->normals))
            || ((flags & 2u) && !read_floats(data, size, &at, 4 * (size_t)n, NULL)))
            return mk_error_set(err, MK_ERROR_TRUNCATED, at, "%.200s: mesh %u is cut off", path, i);
    }
    return MK_OK;
}

mk_result pb_reference_read(const char *path, pb_reference_kind kind, pb_reference *out, mk_error *err)
{
    memset(out, 0, sizeof *out);
    mk_arena_init(&out->arena, NULL);
    if (kind == PB_REF_OBJ) return read_obj(out, path, err);
    void *data;
    size_t size;
    mk_result r = mk_read_file(&out->arena, path, REFERENCE_MAX_BYTES, &data, &size, err);
    if (r != MK_OK) return r;
    if (kind == PB_REF_MORPHKIT_FRAME) return read_mkf(out, path, data, size, err);
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(data, size, &end, 0);
    if (!root)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: JSON parse error at byte %zu", path,
                            end ? (size_t)(end - (const char *)data) : (size_t)0);
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    if (!cJSON_IsArray(meshes)) {
        cJSON_Delete(root);
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: not a reference frame (no \"meshes\" array)",
                            path);
    }
    out->meshes = mk_arena_array(&out->arena, (size_t)cJSON_GetArraySize(meshes) + 1, sizeof(pb_ref_mesh));
    if (!out->meshes) r = mk_error_oom(err, "reference frame");
    const cJSON *m;
    cJSON_ArrayForEach(m, meshes)
    {
        if (r != MK_OK) break;
        r = read_json_mesh(out, path, kind, out->mesh_count, m, &out->meshes[out->mesh_count], err);
        out->mesh_count++;
    }
    cJSON_Delete(root);
    return r;
}

void pb_reference_free(pb_reference *r)
{
    mk_arena_free_all(&r->arena);
}

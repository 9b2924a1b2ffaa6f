/* SPDX-License-Identifier: MIT */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "blob_io.h"
#include "morphkit.h"
#include "manifest.h"

#define MANIFEST_MAX_BYTES ((size_t)256 << 20)

static mk_result field_error(mk_error *err, const char *path, const char *where, const char *what)
{
    return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%.200s: %.200s: %s", path, where, what);
}

static const char *dup_string(pb_manifest *m, const cJSON *item)
{
    return cJSON_IsString(item) ? mk_arena_strdup(&m->arena, item->valuestring) : NULL;
}

/* One of the words of `choices` ("a|b|c") as its index, or -1. */
static int choice(const cJSON *item, const char *const *choices, int count)
{
    if (!cJSON_IsString(item)) return -1;
    for (int i = 0; i < count; i++)
        if (!strcmp(item->valuestring, choices[i])) return i;
    return -1;
}

static mk_result read_frame(pb_manifest *m, const char *path, const char *where, const cJSON *j, pb_frame_spec *f,
                            mk_error *err)
{
    if (!cJSON_IsObject(j)) return field_error(err, path, where, "a frame must be an object");
    const cJSON *time = cJSON_GetObjectItemCaseSensitive(j, "time"),
                *clip = cJSON_GetObjectItemCaseSensitive(j, "clip"),
                *weights = cJSON_GetObjectItemCaseSensitive(j, "weights"),
                *file = cJSON_GetObjectItemCaseSensitive(j, "file");
    char w[320];
    if (!cJSON_IsString(file) || !file->valuestring[0])
        return field_error(err, path, where, "\"file\" must name the reference frame");
    f->file = dup_string(m, file);
    f->weights_from_reference = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(j, "weights_from_reference"));
    f->clip = -1;
    if (time && !cJSON_IsNull(time)) {
        if (!cJSON_IsNumber(time) || !isfinite(time->valuedouble)) {
            snprintf(w, sizeof w, "%.280s.time", where);
            return field_error(err, path, w, "must be a number of seconds, or null for the static state");
        }
        f->has_time = 1;
        f->time = time->valuedouble;
    }
    if (clip) {
        if (!cJSON_IsNumber(clip) || clip->valuedouble < 0 || clip->valuedouble != floor(clip->valuedouble) ||
            clip->valuedouble > 1e6) {
            snprintf(w, sizeof w, "%.280s.clip", where);
            return field_error(err, path, w, "must be an animation index (0, 1, ...)");
        }
        f->clip = (int32_t)clip->valuedouble;
    }
    if (weights) {
        int n = cJSON_GetArraySize(weights);
        snprintf(w, sizeof w, "%.280s.weights", where);
        if (!cJSON_IsArray(weights)) return field_error(err, path, w, "must be an array of numbers");
        f->forced = mk_arena_array(&m->arena, (size_t)n + 1, sizeof(double));
        if (!f->forced) return mk_error_oom(err, "manifest");
        const cJSON *e;
        cJSON_ArrayForEach(e, weights)
        {
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
                return field_error(err, path, w, "must hold finite numbers");
            f->forced[f->forced_count++] = e->valuedouble;
        }
    }
    return f->file ? MK_OK : mk_error_oom(err, "manifest");
}

static mk_result read_case(pb_manifest *m, const char *path, uint32_t index, const cJSON *j, pb_case *c, mk_error *err)
{
    char where[256], w[300];
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(j, "name");
    snprintf(where, sizeof where, "cases[%u]%s%.100s%s", index, cJSON_IsString(name) ? " '" : "",
             cJSON_IsString(name) ? name->valuestring : "", cJSON_IsString(name) ? "'" : "");
    if (!cJSON_IsObject(j)) return field_error(err, path, where, "a case must be an object");
    if (!cJSON_IsString(name) || !name->valuestring[0]) return field_error(err, path, where, "needs a \"name\"");
    const cJSON *source = cJSON_GetObjectItemCaseSensitive(j, "source");
    if (!cJSON_IsString(source) || !source->valuestring[0])
        return field_error(err, path, where, "needs a \"source\" file");
    static const char *const formats[] = { "fbx", "gltf", "morph" };
    int format = choice(cJSON_GetObjectItemCaseSensitive(j, "format"), formats, 3);
    if (format < 0) return field_error(err, path, where, "\"format\" must be fbx, gltf or morph");
    static const char *const stackings[] = { "additive", "sequential" }, *const normal_modes[] = { "nlerp", "slerp" };
    const cJSON *stacking_item = cJSON_GetObjectItemCaseSensitive(j, "stacking");
    const cJSON *normals_item = cJSON_GetObjectItemCaseSensitive(j, "normals");
    int stacking = stacking_item ? choice(stacking_item, stackings, 2) : -1;
    int normal_mode = normals_item ? choice(normals_item, normal_modes, 2) : 0;
    if (stacking_item && stacking < 0) return field_error(err, path, where, "\"stacking\" must be additive or sequential");
    if (normal_mode < 0) return field_error(err, path, where, "\"normals\" must be nlerp or slerp");
    c->stacking = stacking < 0 ? MK_STACKING_ASSET : stacking ? MK_STACKING_SEQUENTIAL : MK_STACKING_ADDITIVE;
    c->normal_mode = normal_mode ? MK_NORMALS_SLERP : MK_NORMALS_NLERP;
    const cJSON *ref = cJSON_GetObjectItemCaseSensitive(j, "reference");
    snprintf(w, sizeof w, "%.250s.reference", where);
    if (!cJSON_IsObject(ref)) return field_error(err, path, w, "must be an object (kind, space, match, tolerance)");
    static const char *const kinds[] = { "ufbx-json", "three-json", "morphkit-json", "morphkit-frame", "obj" };
    static const char *const spaces[] = { "mesh-local", "world" };
    static const char *const matches[] = { "vertices", "control_points" };
    static const char *const sizes[] = { "diagonal", "largest_coordinate" };
    int kind = choice(cJSON_GetObjectItemCaseSensitive(ref, "kind"), kinds, 5);
    int space = choice(cJSON_GetObjectItemCaseSensitive(ref, "space"), spaces, 2);
    int match = choice(cJSON_GetObjectItemCaseSensitive(ref, "match"), matches, 2);
    if (kind < 0)
        return field_error(err, path, w, "\"kind\" must be ufbx-json, three-json, morphkit-json, morphkit-frame or obj");
    if (space < 0) return field_error(err, path, w, "\"space\" must be world or mesh-local");
    if (match < 0) return field_error(err, path, w, "\"match\" must be control_points or vertices");
    const cJSON *tol = cJSON_GetObjectItemCaseSensitive(ref, "tolerance");
    const cJSON *rel = cJSON_GetObjectItemCaseSensitive(ref, "relative_tolerance");
    const cJSON *rel_to = cJSON_GetObjectItemCaseSensitive(ref, "relative_to");
    if (tol && (!cJSON_IsNumber(tol) || !(tol->valuedouble >= 0) || !isfinite(tol->valuedouble)))
        return field_error(err, path, w, "\"tolerance\" must be a number >= 0");
    if (rel && (!cJSON_IsNumber(rel) || !(rel->valuedouble >= 0) || !isfinite(rel->valuedouble)))
        return field_error(err, path, w, "\"relative_tolerance\" must be a number >= 0");
    if (!tol && !rel) return field_error(err, path, w, "needs \"tolerance\" and/or \"relative_tolerance\"");
    int size = rel_to ? choice(rel_to, sizes, 2) : 0;
    if (size < 0) return field_error(err, path, w, "\"relative_to\" must be diagonal or largest_coordinate");
    c->name = dup_string(m, name);
    c->source = dup_string(m, source);
    c->gltf = format == 1;   /* "morph" sources name clips like FBX: the first unless a frame names one */
    static const pb_reference_kind kind_values[] = { PB_REF_UFBX_JSON, PB_REF_THREE_JSON, PB_REF_MORPHKIT_JSON,
                                                     PB_REF_MORPHKIT_FRAME, PB_REF_OBJ };
    c->kind = kind_values[kind];
    c->world = space == 1;
    c->by_control_point = match == 1;
    c->tolerance = tol ? tol->valuedouble : 0;
    c->relative_tolerance = rel ? rel->valuedouble : 0;
    c->relative_to_largest = size == 1;
    if (!c->name || !c->source) return mk_error_oom(err, "manifest");
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(j, "frames");
    snprintf(w, sizeof w, "%.250s.frames", where);
    if (!cJSON_IsArray(frames) || cJSON_GetArraySize(frames) == 0)
        return field_error(err, path, w, "must be a non-empty array");
    c->frames = mk_arena_array(&m->arena, (size_t)cJSON_GetArraySize(frames), sizeof(pb_frame_spec));
    if (!c->frames) return mk_error_oom(err, "manifest");
    const cJSON *f;
    cJSON_ArrayForEach(f, frames)
    {
        snprintf(w, sizeof w, "%.250s.frames[%u]", where, c->frame_count);
        mk_result r = read_frame(m, path, w, f, &c->frames[c->frame_count], err);
        if (r != MK_OK) return r;
        c->frame_count++;
    }
    return MK_OK;
}

mk_result pb_manifest_read(const char *path, pb_manifest *out, mk_error *err)
{
    memset(out, 0, sizeof *out);
    mk_arena_init(&out->arena, NULL);
    snprintf(out->base_dir, sizeof out->base_dir, "%s", path);
    char *slash = strrchr(out->base_dir, '/');
    if (slash)
        *slash = 0;
    else
        strcpy(out->base_dir, ".");
    void *text;
    size_t size;
    mk_result r = mk_read_file(&out->arena, path, MANIFEST_MAX_BYTES, &text, &size, err);
    if (r != MK_OK) return r;
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    if (!root)
        return mk_error_set(err, MK_ERROR_PARSE, end ? (uint64_t)(end - (const char *)text) : 0,
                            "%.200s: not JSON (parse error at byte %zu)", path,
                            end ? (size_t)(end - (const char *)text) : (size_t)0);
    const cJSON *cases = cJSON_GetObjectItemCaseSensitive(root, "cases");
    if (!cJSON_IsObject(root) || !cJSON_IsArray(cases)) {
        cJSON_Delete(root);
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX,
                            "%.200s: not a conformance manifest (expected an object with a \"cases\" array)", path);
    }
    out->cases = mk_arena_array(&out->arena, (size_t)cJSON_GetArraySize(cases) + 1, sizeof(pb_case));
    if (!out->cases) r = mk_error_oom(err, "manifest");
    const cJSON *c;
    cJSON_ArrayForEach(c, cases)
    {
        if (r != MK_OK) break;
        r = read_case(out, path, out->case_count, c, &out->cases[out->case_count], err);
        if (r == MK_OK) out->case_count++;
    }
    cJSON_Delete(root);
    mk_arena_release(&out->arena, text);
    return r;
}

void pb_manifest_free(pb_manifest *m)
{
    mk_arena_free_all(&m->arena);
}

void pb_manifest_path(const pb_manifest *m, const char *path, char *out, size_t size)
{
    if (path[0] == '/')
        snprintf(out, size, "%s", path);
    else
        snprintf(out, size, "%s/%s", m->base_dir, path);
}

const char *pb_frame_label(const pb_frame_spec *f)
{
    const char *slash = strrchr(f->file, '/');
    return slash ? slash + 1 : f->file;
}

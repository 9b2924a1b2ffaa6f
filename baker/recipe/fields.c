/* SPDX-License-Identifier: MIT */
/* Readers of recipe fields: each checks one JSON value and names the field by its path on error,
 * e.g. "channels[1].handles[0].radius: must be > 0" (docs/baking.md). Shared by the recipe
 * document and its ops. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fields.h"

#define PI 3.14159265358979323846

int recipe_untrusted(const recipe_ctx *ctx)
{
    return ctx->options && ctx->options->untrusted;
}

mk_result recipe_field_error(recipe_ctx *ctx, const char *path, const char *field, const char *fmt,
                             const char *detail)
{
    char what[200];
    snprintf(what, sizeof what, fmt, detail ? detail : "");
    return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s%s%s: %s", path,
                        field && *field ? "." : "", field ? field : "", what);
}

mk_result recipe_get_number(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                            double *out, int required)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!item) return required ? recipe_field_error(ctx, path, field, "missing%s", NULL) : MK_OK;
    if (!cJSON_IsNumber(item)) return recipe_field_error(ctx, path, field, "must be a number%s", NULL);
    if (!isfinite(item->valuedouble)) return recipe_field_error(ctx, path, field, "is not a finite number%s", NULL);
    *out = item->valuedouble;
    return MK_OK;
}

mk_result recipe_get_uint(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                          uint32_t *out, uint32_t min, uint32_t max)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!item) return MK_OK;
    double v = item->valuedouble;
    if (!cJSON_IsNumber(item) || !isfinite(v) || v != floor(v) || v < min || v > max) {
        char range[64];
        snprintf(range, sizeof range, "%u..%u", min, max);
        return recipe_field_error(ctx, path, field, "must be an integer in %s", range);
    }
    *out = (uint32_t)v;
    return MK_OK;
}

mk_result recipe_vec3_item(recipe_ctx *ctx, const cJSON *item, const char *path,
                           const char *field, double out[3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return recipe_field_error(ctx, path, field, "must be an array of 3 numbers%s", NULL);
    for (int c = 0; c < 3; c++) {
        const cJSON *e = cJSON_GetArrayItem(item, c);
        if (!cJSON_IsNumber(e)) return recipe_field_error(ctx, path, field, "must be an array of 3 numbers%s", NULL);
        if (!isfinite(e->valuedouble)) return recipe_field_error(ctx, path, field, "holds a value that is not finite%s", NULL);
        out[c] = e->valuedouble;
    }
    return MK_OK;
}

int recipe_get_vec3(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field, double out[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!item) return 0;
    return recipe_vec3_item(ctx, item, path, field, out) == MK_OK ? 1 : -1;
}

mk_result recipe_check_fields(recipe_ctx *ctx, const cJSON *obj, const char *path,
                              const char *const *a, const char *const *b)
{
    for (const cJSON *it = obj->child; it; it = it->next) {
        int known = 0;
        for (int i = 0; a && a[i] && !known; i++) known = strcmp(a[i], it->string) == 0;
        for (int i = 0; b && b[i] && !known; i++) known = strcmp(b[i], it->string) == 0;
        if (!known) return recipe_field_error(ctx, path, it->string, "unknown field%s (see docs/baking.md)", NULL);
    }
    return MK_OK;
}

mk_result recipe_get_object(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                            const char *const *fields, const char *usage, char *subpath, size_t subpath_size,
                            const cJSON **out)
{
    *out = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!*out) return MK_OK;
    snprintf(subpath, subpath_size, "%s.%s", path, field);
    if (!cJSON_IsObject(*out)) return recipe_field_error(ctx, subpath, "", "must be an object %s", usage);
    return recipe_check_fields(ctx, *out, subpath, fields, NULL);
}

mk_result recipe_selection(recipe_ctx *ctx, const mk_raw_mesh *mesh, const cJSON *sel,
                           const char *path, unsigned char *mark, uint32_t **list,
                           uint32_t *count, uint32_t *capacity, int allow_extra)
{
    static const char *const sel_fields[] = { "indices", "center", "radius", "min", "max", NULL };
    static const char *const handle_fields[] = { "translate", "rotate", NULL };
    if (!cJSON_IsObject(sel)) return recipe_field_error(ctx, path, "", "must be an object (indices, center+radius or min+max)%s", NULL);
    mk_result r = recipe_check_fields(ctx, sel, path, sel_fields, allow_extra ? handle_fields : NULL);
    if (r != MK_OK) return r;
    const cJSON *indices = cJSON_GetObjectItemCaseSensitive(sel, "indices");
    int has_sphere = cJSON_HasObjectItem(sel, "center") || cJSON_HasObjectItem(sel, "radius");
    int has_box = cJSON_HasObjectItem(sel, "min") || cJSON_HasObjectItem(sel, "max");
    if ((indices != NULL) + has_sphere + has_box != 1)
        return recipe_field_error(ctx, path, "", "give exactly one of indices, center+radius or min+max%s", NULL);
    uint32_t before = *count;
    size_t n = mesh->vertex_count;
#define PUSH(v) do { if (!mark[v]) { \
        if (*count == *capacity) { \
            uint32_t ncap = *capacity ? 2 * *capacity : 64; \
            uint32_t *nl = mk_arena_realloc(ctx->scratch, *list, (size_t)*capacity * 4, (size_t)ncap * 4); \
            if (!nl) return mk_error_oom(ctx->err, "selection"); \
            *list = nl; *capacity = ncap; } \
        mark[v] = 1; (*list)[(*count)++] = (uint32_t)(v); } } while (0)
    if (indices) {
        if (!cJSON_IsArray(indices)) return recipe_field_error(ctx, path, "indices", "must be an array of vertex indices%s", NULL);
        int k = 0;
        for (const cJSON *e = indices->child; e; e = e->next, k++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < 0 || v >= (double)n) {
                char msg[96];
                snprintf(msg, sizeof msg, "entry %d is not a vertex index in 0..%zu", k, n ? n - 1 : 0);
                return recipe_field_error(ctx, path, "indices", "%s", msg);
            }
            PUSH((size_t)v);
        }
    } else if (has_sphere) {
        double c[3], radius = 0;
        int got = recipe_get_vec3(ctx, sel, path, "center", c);
        if (got < 0) return ctx->err->code;
        if (got == 0) return recipe_field_error(ctx, path, "center", "missing (a sphere needs center and radius)%s", NULL);
        if ((r = recipe_get_number(ctx, sel, path, "radius", &radius, 1)) != MK_OK) return r;
        if (!(radius > 0)) return recipe_field_error(ctx, path, "radius", "must be > 0%s", NULL);
        for (size_t v = 0; v < n; v++) {
            const float *p = mesh->positions + 3 * v;
            double d[3] = { p[0] - c[0], p[1] - c[1], p[2] - c[2] };
            if (vec3_dot(d, d) <= radius * radius) PUSH(v);
        }
    } else {
        double lo[3], hi[3];
        int g1 = recipe_get_vec3(ctx, sel, path, "min", lo), g2 = recipe_get_vec3(ctx, sel, path, "max", hi);
        if (g1 < 0 || g2 < 0) return ctx->err->code;
        if (!g1 || !g2) return recipe_field_error(ctx, path, g1 ? "max" : "min", "missing (a box needs min and max)%s", NULL);
        for (size_t v = 0; v < n; v++) {
            const float *p = mesh->positions + 3 * v;
            if (p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] &&
                p[2] >= lo[2] && p[2] <= hi[2]) PUSH(v);
        }
    }
#undef PUSH
    if (*count == before)
        return recipe_field_error(ctx, path, "", "selection is empty (no vertex matches, or all were taken by anchors/earlier handles)%s", NULL);
    return MK_OK;
}

mk_result recipe_rotate(recipe_ctx *ctx, const cJSON *obj, const char *path, double axis[3],
                        double *angle, double pivot[3], const double def_pivot[3])
{
    static const char *const rot_fields[] = { "axis", "degrees", "pivot", NULL };
    const cJSON *rot;
    char rpath[256];
    *angle = 0;
    axis[0] = 0; axis[1] = 0; axis[2] = 1;
    for (int c = 0; c < 3; c++) pivot[c] = def_pivot[c];
    mk_result r = recipe_get_object(ctx, obj, path, "rotate", rot_fields, "{axis, degrees, pivot}", rpath, sizeof rpath, &rot);
    if (r != MK_OK || !rot) return r;
    int got = recipe_get_vec3(ctx, rot, rpath, "axis", axis);
    if (got < 0) return ctx->err->code;
    if (got == 0) return recipe_field_error(ctx, rpath, "axis", "missing%s", NULL);
    if (!(vec3_normalize(axis) > 0)) return recipe_field_error(ctx, rpath, "axis", "is a zero vector%s", NULL);
    double deg = 0;
    if ((r = recipe_get_number(ctx, rot, rpath, "degrees", &deg, 1)) != MK_OK) return r;
    *angle = deg * PI / 180;
    if (recipe_get_vec3(ctx, rot, rpath, "pivot", pivot) < 0) return ctx->err->code;
    return MK_OK;
}

mk_result recipe_axis(recipe_ctx *ctx, const cJSON *obj, const char *path, double axis[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, "axis");
    axis[0] = 0; axis[1] = 1; axis[2] = 0;
    if (!item) return MK_OK;
    if (cJSON_IsString(item)) {
        const char *s = item->valuestring;
        double sign = 1;
        if (*s == '-') { sign = -1; s++; } else if (*s == '+') s++;
        int k = !strcmp(s, "x") ? 0 : !strcmp(s, "y") ? 1 : !strcmp(s, "z") ? 2 : -1;
        if (k < 0) return recipe_field_error(ctx, path, "axis", "\"%s\" is not x, y, z, -x, -y, -z or [x, y, z]", item->valuestring);
        axis[0] = axis[1] = axis[2] = 0;
        axis[k] = sign;
        return MK_OK;
    }
    if (recipe_vec3_item(ctx, item, path, "axis", axis) != MK_OK) return ctx->err->code;
    if (!(vec3_length(axis) > 0)) return recipe_field_error(ctx, path, "axis", "is a zero vector%s", NULL);
    return MK_OK;
}
void recipe_path(const recipe_ctx *ctx, const char *name, char *full, size_t size)
{
    const char *dir = ctx->options && ctx->options->base_dir ? ctx->options->base_dir : "";
    if (name[0] == '/' || !*dir) snprintf(full, size, "%s", name);
    else snprintf(full, size, "%s/%s", dir, name);
}
mk_result recipe_get_bounded(recipe_ctx *ctx, const cJSON *ch, const char *path, const char *field, double *out,
                             double lo, int lo_open, double hi, const char *range)
{
    mk_result r = recipe_get_number(ctx, ch, path, field, out, 0);
    if (r != MK_OK) return r;
    if ((lo_open ? !(*out > lo) : !(*out >= lo)) || !(*out < hi)) return recipe_field_error(ctx, path, field, "must be %s", range);
    return MK_OK;
}
mk_result recipe_resolve_mesh(recipe_ctx *ctx, const mk_raw_asset *raw, const cJSON *item, const char *path,
                              const char *field, uint32_t *mesh)
{
    if (!item) return recipe_field_error(ctx, path, field, "missing (a mesh name or index)%s", NULL);
    if (cJSON_IsNumber(item)) {
        double v = item->valuedouble;
        if (!isfinite(v) || v != floor(v) || v < 0 || v >= raw->mesh_count) {
            char msg[96];
            snprintf(msg, sizeof msg, "index %g is not a mesh (the asset has %u)", v, raw->mesh_count);
            return recipe_field_error(ctx, path, field, "%s", msg);
        }
        *mesh = (uint32_t)v;
        return MK_OK;
    }
    if (!cJSON_IsString(item)) return recipe_field_error(ctx, path, field, "must be a mesh name or index%s", NULL);
    for (uint32_t m = 0; m < raw->mesh_count; m++)
        if (raw->meshes[m].name && !strcmp(raw->meshes[m].name, item->valuestring)) {
            *mesh = m;
            return MK_OK;
        }
    char names[120] = "";
    for (uint32_t m = 0; m < raw->mesh_count && recipe_list_name(names, sizeof names, raw->meshes[m].name); m++) {}
    char msg[200];
    snprintf(msg, sizeof msg, "no mesh named \"%.40s\"; the meshes are %s", item->valuestring,
             raw->mesh_count ? names : "(none)");
    return recipe_field_error(ctx, path, field, "%s", msg);
}

int recipe_list_name(char *list, size_t size, const char *name)
{
    size_t n = strlen(list);
    if (!name) name = "";
    if (n + strlen(name) + 8 >= size) {
        snprintf(list + n, size - n, ", ...");
        return 0;
    }
    snprintf(list + n, size - n, "%s\"%s\"", n ? ", " : "", name);
    return 1;
}

void *recipe_state_new(recipe_ctx *ctx, recipe_channel *ch, size_t size)
{
    void *s = mk_arena_alloc(ctx->scratch, size);
    if (s) memset(s, 0, size);
    ch->state = s;
    return s;
}

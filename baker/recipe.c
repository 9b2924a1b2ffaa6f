/* SPDX-License-Identifier: MIT */
/* JSON bake recipes (docs/baking.md): parse, validate every field, then bake channel by channel.
 *
 * All or nothing: the whole recipe is parsed and checked before any baking starts, and if a
 * channel fails while baking, the channels added so far are dropped again (raw->channel_count
 * is restored), so `morphkit bake` writes nothing on any error. Errors name the field by its
 * JSON path, e.g. "channels[1].handles[0].radius: must be > 0".
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cjson/cJSON.h>
#include "bake.h"
#include "bake_util.h"
#include "barr.h"
#include "cage_mvc.h"
#include "ffd.h"
#include "ffd_travel.h"
#include "ffd_cylinder.h"
#include "ffd_prism.h"
#include "inbetween.h"
#include "surface_edit.h"
#include "transfer.h"
#include "shell/shell_channel.h"
#include "obj.h"

#define PI 3.14159265358979323846

typedef enum op_kind { OP_FFD, OP_TAPER, OP_TWIST, OP_BEND, OP_CAGE, OP_LAPLACIAN, OP_ARAP, OP_FFD_TRAVEL, OP_FFD_KEYS, OP_FFD_CYLINDER, OP_FFD_PRISM, OP_TRANSFER, OP_SHELL } op_kind;

static const char *const op_names[] = { "ffd", "taper", "twist", "bend", "cage", "laplacian", "arap", "ffd_travel", "ffd_keys", "ffd_cylinder", "ffd_prism", "transfer", "shell" };

/* Fields accepted by every op, and per op. */
static const char *const common_fields[] = { "name", "op", "mesh", "inbetweens", "tolerance",
                                             "samples", "max_targets", "default_weight", NULL };
static const char *const op_fields[][20] = {
    [OP_FFD] = { "dims", "basis", "origin", "axes", "padding", "moves", NULL },
    [OP_TAPER] = { "axis", "center", "range", "scale", NULL },
    [OP_TWIST] = { "axis", "center", "range", "angle", NULL },
    [OP_BEND] = { "axis", "center", "range", "angle", "direction", NULL },
    [OP_CAGE] = { "cage", "deformed_cage", NULL },
    [OP_LAPLACIAN] = { "weights", "constraints", "soft_weight", "anchors", "handles", NULL },
    [OP_ARAP] = { "weights", "constraints", "soft_weight", "anchors", "handles", "iterations",
                  "convergence", "acceleration", NULL },
    [OP_FFD_TRAVEL] = { "dims", "basis", "origin", "axes", "padding", "moves", "travel", "duration", NULL },
    [OP_FFD_KEYS] = { "dims", "basis", "origin", "axes", "padding", "keys", NULL },
    [OP_FFD_CYLINDER] = { "dims", "axis", "center", "range", "radius", "inner_radius", "reference", "padding",
                          "moves", NULL },
    [OP_FFD_PRISM] = { "sides", "section", "degree", "layers", "axis", "center", "range", "radius", "reference",
                       "padding", "rest_moves", "moves", NULL },
    [OP_TRANSFER] = { "source", "source_mesh", "channels", "markers", "prefix", NULL },
    [OP_SHELL] = { "pressure", "ramp", "dt", "frames", "iterations", "substeps", "density", "damping", "material", "mu",
                   "lambda", "kB", "anisotropic", "thickness", "epsilon", "at_frames", "at_volume_ratios", "log", "clip", NULL },
};

/* Everything parsed for one channel before baking. */
typedef struct channel_plan {
    op_kind op;
    char name[128];
    uint32_t mesh;
    char *origin;                 /* recipe JSON of the channel (scratch arena) */
    mk_inbetween_options inbetween;
    float default_weight;
    mk_barr barr;
    mk_ffd_lattice ffd;
    double *ffd_displacements;
    mk_cage cage;
    mk_edit_params edit;
    mk_edit_handle *handles;
    mk_ffd_travel travel;
    double clip_duration;         /* ffd_travel: seconds of the clip playing 0 -> 1; 0 = no clip */
    uint32_t key_count;           /* ffd_keys: lattice keys, their times and displacements */
    double *key_times;
    double **key_displacements;
    double *lattice_rest;         /* ffd, ffd_keys, ffd_cylinder, ffd_prism: rest control points */
    mk_cylinder_lattice cylinder;
    mk_prism_lattice prism;
    double *lattice_coordinates;  /* per vertex: ffd_cylinder (s, t, u), ffd_prism (wedge, l1, l2, u) */
    mk_raw_asset *source;         /* transfer: the loaded source asset (freed after the bake) */
    uint32_t source_mesh;
    uint32_t source_channel_count;/* transfer: channels of the source asset to carry over */
    uint32_t *source_channels;
    uint32_t marker_count;        /* transfer: (source vertex, target vertex) pairs */
    uint32_t (*markers)[2];
    char prefix[64];              /* transfer: prepended to the source channel names */
    int has_default_weight;
    shell_params shell;           /* shell: the simulation */
    unsigned char *shell_region;  /* shell: anisotropic region per render vertex, or NULL */
    double *shell_at;             /* shell: at_frames or at_volume_ratios (0 entries: default) */
    uint32_t shell_at_count;
    int shell_at_ratios;
    const char *shell_log;        /* shell: CSV log path, or NULL */
} channel_plan;

typedef struct recipe_ctx {
    mk_raw_asset *raw;
    mk_arena *scratch;
    const mk_bake_options *options;
    mk_error *err;
} recipe_ctx;

static int untrusted(const recipe_ctx *ctx)
{
    return ctx->options && ctx->options->untrusted;
}

/* ---- small JSON helpers that name the field on error ---- */

static mk_result field_error(recipe_ctx *ctx, const char *path, const char *field, const char *fmt,
                             const char *detail)
{
    char what[200];
    snprintf(what, sizeof what, fmt, detail ? detail : "");
    return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s%s%s: %s", path,
                        field && *field ? "." : "", field ? field : "", what);
}

static mk_result get_number(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                            double *out, int required)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!item) return required ? field_error(ctx, path, field, "missing%s", NULL) : MK_OK;
    if (!cJSON_IsNumber(item)) return field_error(ctx, path, field, "must be a number%s", NULL);
    if (!isfinite(item->valuedouble)) return field_error(ctx, path, field, "is not a finite number%s", NULL);
    *out = item->valuedouble;
    return MK_OK;
}

static mk_result get_uint(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                          uint32_t *out, uint32_t min, uint32_t max)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!item) return MK_OK;
    double v = item->valuedouble;
    if (!cJSON_IsNumber(item) || !isfinite(v) || v != floor(v) || v < min || v > max) {
        char range[64];
        snprintf(range, sizeof range, "%u..%u", min, max);
        return field_error(ctx, path, field, "must be an integer in %s", range);
    }
    *out = (uint32_t)v;
    return MK_OK;
}

static mk_result parse_vec3_item(recipe_ctx *ctx, const cJSON *item, const char *path,
                                 const char *field, double out[3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return field_error(ctx, path, field, "must be an array of 3 numbers%s", NULL);
    for (int c = 0; c < 3; c++) {
        const cJSON *e = cJSON_GetArrayItem(item, c);
        if (!cJSON_IsNumber(e)) return field_error(ctx, path, field, "must be an array of 3 numbers%s", NULL);
        if (!isfinite(e->valuedouble)) return field_error(ctx, path, field, "holds a value that is not finite%s", NULL);
        out[c] = e->valuedouble;
    }
    return MK_OK;
}

/* Returns 1 when present (and parsed), 0 when absent, -1 on error. */
static int get_vec3(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field, double out[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!item) return 0;
    return parse_vec3_item(ctx, item, path, field, out) == MK_OK ? 1 : -1;
}

static mk_result check_fields(recipe_ctx *ctx, const cJSON *obj, const char *path,
                              const char *const *a, const char *const *b)
{
    for (const cJSON *it = obj->child; it; it = it->next) {
        int known = 0;
        for (int i = 0; a && a[i] && !known; i++) known = strcmp(a[i], it->string) == 0;
        for (int i = 0; b && b[i] && !known; i++) known = strcmp(b[i], it->string) == 0;
        if (!known) return field_error(ctx, path, it->string, "unknown field%s (see docs/baking.md)", NULL);
    }
    return MK_OK;
}

/* The object field `field` of obj (NULL in *out when absent): checked to be an object with only
 * the given fields; subpath receives "path.field" for its own errors. */
static mk_result get_object(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                            const char *const *fields, const char *usage, char *subpath, size_t subpath_size,
                            const cJSON **out)
{
    *out = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (!*out) return MK_OK;
    snprintf(subpath, subpath_size, "%s.%s", path, field);
    if (!cJSON_IsObject(*out)) return field_error(ctx, subpath, "", "must be an object %s", usage);
    return check_fields(ctx, *out, subpath, fields, NULL);
}

/* ---- vertex selections ---- */

/* Selection object: {"indices": [...]} | {"center": [x,y,z], "radius": r} |
 * {"min": [..], "max": [..]}. Appends matching vertices to *list (deduplicated by a mark). */
static mk_result parse_selection(recipe_ctx *ctx, const mk_raw_mesh *mesh, const cJSON *sel,
                                 const char *path, unsigned char *mark, uint32_t **list,
                                 uint32_t *count, uint32_t *capacity, int allow_extra)
{
    static const char *const sel_fields[] = { "indices", "center", "radius", "min", "max", NULL };
    static const char *const handle_fields[] = { "translate", "rotate", NULL };
    if (!cJSON_IsObject(sel)) return field_error(ctx, path, "", "must be an object (indices, center+radius or min+max)%s", NULL);
    mk_result r = check_fields(ctx, sel, path, sel_fields, allow_extra ? handle_fields : NULL);
    if (r != MK_OK) return r;
    const cJSON *indices = cJSON_GetObjectItemCaseSensitive(sel, "indices");
    int has_sphere = cJSON_HasObjectItem(sel, "center") || cJSON_HasObjectItem(sel, "radius");
    int has_box = cJSON_HasObjectItem(sel, "min") || cJSON_HasObjectItem(sel, "max");
    if ((indices != NULL) + has_sphere + has_box != 1)
        return field_error(ctx, path, "", "give exactly one of indices, center+radius or min+max%s", NULL);
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
        if (!cJSON_IsArray(indices)) return field_error(ctx, path, "indices", "must be an array of vertex indices%s", NULL);
        int k = 0;
        for (const cJSON *e = indices->child; e; e = e->next, k++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < 0 || v >= (double)n) {
                char msg[96];
                snprintf(msg, sizeof msg, "entry %d is not a vertex index in 0..%zu", k, n ? n - 1 : 0);
                return field_error(ctx, path, "indices", "%s", msg);
            }
            PUSH((size_t)v);
        }
    } else if (has_sphere) {
        double c[3], radius = 0;
        int got = get_vec3(ctx, sel, path, "center", c);
        if (got < 0) return ctx->err->code;
        if (got == 0) return field_error(ctx, path, "center", "missing (a sphere needs center and radius)%s", NULL);
        if ((r = get_number(ctx, sel, path, "radius", &radius, 1)) != MK_OK) return r;
        if (!(radius > 0)) return field_error(ctx, path, "radius", "must be > 0%s", NULL);
        for (size_t v = 0; v < n; v++) {
            const float *p = mesh->positions + 3 * v;
            double d[3] = { p[0] - c[0], p[1] - c[1], p[2] - c[2] };
            if (vec3_dot(d, d) <= radius * radius) PUSH(v);
        }
    } else {
        double lo[3], hi[3];
        int g1 = get_vec3(ctx, sel, path, "min", lo), g2 = get_vec3(ctx, sel, path, "max", hi);
        if (g1 < 0 || g2 < 0) return ctx->err->code;
        if (!g1 || !g2) return field_error(ctx, path, g1 ? "max" : "min", "missing (a box needs min and max)%s", NULL);
        for (size_t v = 0; v < n; v++) {
            const float *p = mesh->positions + 3 * v;
            if (p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] &&
                p[2] >= lo[2] && p[2] <= hi[2]) PUSH(v);
        }
    }
#undef PUSH
    if (*count == before)
        return field_error(ctx, path, "", "selection is empty (no vertex matches, or all were taken by anchors/earlier handles)%s", NULL);
    return MK_OK;
}

/* Rotation object {"axis": [..], "degrees": d, "pivot": [..]}; pivot defaults to def_pivot. */
static mk_result parse_rotate(recipe_ctx *ctx, const cJSON *obj, const char *path, double axis[3],
                              double *angle, double pivot[3], const double def_pivot[3])
{
    static const char *const rot_fields[] = { "axis", "degrees", "pivot", NULL };
    const cJSON *rot;
    char rpath[256];
    *angle = 0;
    axis[0] = 0; axis[1] = 0; axis[2] = 1;
    for (int c = 0; c < 3; c++) pivot[c] = def_pivot[c];
    mk_result r = get_object(ctx, obj, path, "rotate", rot_fields, "{axis, degrees, pivot}", rpath, sizeof rpath, &rot);
    if (r != MK_OK || !rot) return r;
    int got = get_vec3(ctx, rot, rpath, "axis", axis);
    if (got < 0) return ctx->err->code;
    if (got == 0) return field_error(ctx, rpath, "axis", "missing%s", NULL);
    if (!(vec3_normalize(axis) > 0)) return field_error(ctx, rpath, "axis", "is a zero vector%s", NULL);
    double deg = 0;
    if ((r = get_number(ctx, rot, rpath, "degrees", &deg, 1)) != MK_OK) return r;
    *angle = deg * PI / 180;
    if (get_vec3(ctx, rot, rpath, "pivot", pivot) < 0) return ctx->err->code;
    return MK_OK;
}

static mk_result parse_axis(recipe_ctx *ctx, const cJSON *obj, const char *path, double axis[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, "axis");
    axis[0] = 0; axis[1] = 1; axis[2] = 0;
    if (!item) return MK_OK;
    if (cJSON_IsString(item)) {
        const char *s = item->valuestring;
        double sign = 1;
        if (*s == '-') { sign = -1; s++; } else if (*s == '+') s++;
        int k = !strcmp(s, "x") ? 0 : !strcmp(s, "y") ? 1 : !strcmp(s, "z") ? 2 : -1;
        if (k < 0) return field_error(ctx, path, "axis", "\"%s\" is not x, y, z, -x, -y, -z or [x, y, z]", item->valuestring);
        axis[0] = axis[1] = axis[2] = 0;
        axis[k] = sign;
        return MK_OK;
    }
    if (parse_vec3_item(ctx, item, path, "axis", axis) != MK_OK) return ctx->err->code;
    if (!(vec3_length(axis) > 0)) return field_error(ctx, path, "axis", "is a zero vector%s", NULL);
    return MK_OK;
}

/* ---- per-op parsing ---- */

static mk_result parse_barr(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_barr *b = &plan->barr;
    memset(b, 0, sizeof *b);
    b->op = plan->op == OP_TAPER ? MK_BARR_TAPER : plan->op == OP_TWIST ? MK_BARR_TWIST : MK_BARR_BEND;
    mk_result r = parse_axis(ctx, ch, path, b->axis);
    if (r != MK_OK) return r;
    double bmin[3], bmax[3], diag;
    bake_bounds(mesh, bmin, bmax, &diag);
    for (int c = 0; c < 3; c++) b->center[c] = 0.5 * (bmin[c] + bmax[c]);
    if (get_vec3(ctx, ch, path, "center", b->center) < 0) return ctx->err->code;
    double axis_unit[3] = { b->axis[0], b->axis[1], b->axis[2] };
    vec3_normalize(axis_unit);
    const cJSON *range = cJSON_GetObjectItemCaseSensitive(ch, "range");
    if (range) {
        if (!cJSON_IsArray(range) || cJSON_GetArraySize(range) != 2 ||
            !cJSON_IsNumber(range->child) || !cJSON_IsNumber(range->child->next))
            return field_error(ctx, path, "range", "must be [min, max] along the axis%s", NULL);
        b->range[0] = range->child->valuedouble;
        b->range[1] = range->child->next->valuedouble;
        if (!isfinite(b->range[0]) || !isfinite(b->range[1]))
            return field_error(ctx, path, "range", "holds a value that is not finite%s", NULL);
        if (!(b->range[1] > b->range[0]))
            return field_error(ctx, path, "range", "must have min < max%s", NULL);
    } else {
        for (uint32_t v = 0; v < mesh->vertex_count; v++) {
            const float *p = mesh->positions + 3 * (size_t)v;
            double pd[3] = { p[0], p[1], p[2] }, a = vec3_dot(pd, axis_unit);
            if (v == 0 || a < b->range[0]) b->range[0] = a;
            if (v == 0 || a > b->range[1]) b->range[1] = a;
        }
        if (!(b->range[1] > b->range[0]))
            return field_error(ctx, path, "range", "the mesh has no extent along the axis: give range%s", NULL);
    }
    if (plan->op == OP_TAPER) {
        if ((r = get_number(ctx, ch, path, "scale", &b->scale, 1)) != MK_OK) return r;
    } else {
        double deg = 0;
        if ((r = get_number(ctx, ch, path, "angle", &deg, 1)) != MK_OK) return r;
        b->angle = deg * PI / 180;
    }
    if (plan->op == OP_BEND) {
        /* Default bend direction: the coordinate axis after the axis' dominant one. */
        int k = 0;
        for (int c = 1; c < 3; c++) if (fabs(axis_unit[c]) > fabs(axis_unit[k])) k = c;
        b->direction[(k + 1) % 3] = 1;
        if (get_vec3(ctx, ch, path, "direction", b->direction) < 0) return ctx->err->code;
    }
    mk_error inner;
    if (mk_barr_prepare(b, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    return MK_OK;
}

static mk_result parse_index_range(recipe_ctx *ctx, const cJSON *mv, const char *path, const char *field,
                                   uint32_t dim, uint32_t *lo, uint32_t *hi)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(mv, field);
    *lo = 0; *hi = dim - 1;
    if (!item) return MK_OK;
    double a, b;
    if (cJSON_IsNumber(item)) a = b = item->valuedouble;
    else if (cJSON_IsArray(item) && cJSON_GetArraySize(item) == 2 && cJSON_IsNumber(item->child) &&
             cJSON_IsNumber(item->child->next)) {
        a = item->child->valuedouble; b = item->child->next->valuedouble;
    } else return field_error(ctx, path, field, "must be an index or [first, last]%s", NULL);
    if (!isfinite(a) || !isfinite(b) || a != floor(a) || b != floor(b) || a < 0 || b < a || b >= dim) {
        char msg[64];
        snprintf(msg, sizeof msg, "must lie in 0..%u with first <= last", dim - 1);
        return field_error(ctx, path, field, "%s", msg);
    }
    *lo = (uint32_t)a; *hi = (uint32_t)b;
    return MK_OK;
}

static mk_result parse_ffd_moves(recipe_ctx *ctx, const uint32_t dims[3], const mk_prism_lattice *prism,
                                 const cJSON *obj, const char *path, const char *field, const double *rest,
                                 double *current, double *displacements);

/* bounds: the box the default lattice encloses (min, max), NULL = the mesh's bounding box. */
static mk_result parse_ffd(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path,
                           const double (*bounds)[3])
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_ffd_lattice *f = &plan->ffd;
    memset(f, 0, sizeof *f);
    f->dims[0] = f->dims[1] = f->dims[2] = 4;
    const cJSON *dims = cJSON_GetObjectItemCaseSensitive(ch, "dims");
    if (dims) {
        if (!cJSON_IsArray(dims) || cJSON_GetArraySize(dims) != 3)
            return field_error(ctx, path, "dims", "must be [l, m, n] control points per axis%s", NULL);
        int a = 0;
        for (const cJSON *e = dims->child; e; e = e->next, a++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < 2 || v > (untrusted(ctx) ? 8 : 64))
                return field_error(ctx, path, "dims", "each entry must be an integer in 2..64 (8 when untrusted)%s", NULL);
            f->dims[a] = (uint32_t)v;
        }
    }
    const cJSON *basis = cJSON_GetObjectItemCaseSensitive(ch, "basis");
    if (basis) {
        if (cJSON_IsString(basis) && !strcmp(basis->valuestring, "bernstein")) f->basis = MK_FFD_BERNSTEIN;
        else if (cJSON_IsString(basis) && !strcmp(basis->valuestring, "bspline")) f->basis = MK_FFD_BSPLINE;
        else return field_error(ctx, path, "basis", "must be \"bernstein\" or \"bspline\"%s", NULL);
    }
    const cJSON *axes = cJSON_GetObjectItemCaseSensitive(ch, "axes");
    int has_origin = cJSON_HasObjectItem(ch, "origin");
    if ((axes != NULL) != has_origin)
        return field_error(ctx, path, axes ? "origin" : "axes", "missing (origin and axes go together)%s", NULL);
    if (axes) {
        if (get_vec3(ctx, ch, path, "origin", f->origin) < 0) return ctx->err->code;
        if (!cJSON_IsArray(axes) || cJSON_GetArraySize(axes) != 3)
            return field_error(ctx, path, "axes", "must be [S, T, U], three vectors%s", NULL);
        int a = 0;
        for (const cJSON *e = axes->child; e; e = e->next, a++)
            if (parse_vec3_item(ctx, e, path, "axes", f->axes[a]) != MK_OK) return ctx->err->code;
    } else {
        double padding = 0.01, bmin[3], bmax[3], diag;
        mk_result r = get_number(ctx, ch, path, "padding", &padding, 0);
        if (r != MK_OK) return r;
        if (padding < 0) return field_error(ctx, path, "padding", "must be >= 0%s", NULL);
        bake_bounds(mesh, bmin, bmax, &diag);
        if (bounds) {
            double d[3];
            for (int c = 0; c < 3; c++) { bmin[c] = bounds[0][c]; bmax[c] = bounds[1][c]; }
            vec3_sub(d, bmax, bmin);
            diag = vec3_length(d);
        }
        double pad = padding * diag;
        for (int a = 0; a < 3; a++) {
            f->origin[a] = bmin[a] - pad;
            for (int c = 0; c < 3; c++) f->axes[a][c] = 0;
            f->axes[a][a] = bmax[a] - bmin[a] + 2 * pad;
        }
    }
    size_t count = (size_t)f->dims[0] * f->dims[1] * f->dims[2];
    plan->ffd_displacements = mk_arena_array(ctx->scratch, 3 * count, sizeof(double));
    double *current = mk_arena_array(ctx->scratch, 3 * count, sizeof(double));
    plan->lattice_rest = mk_arena_array(ctx->scratch, 3 * count, sizeof(double));
    if (!plan->ffd_displacements || !current || !plan->lattice_rest) return mk_error_oom(ctx->err, "lattice");
    for (uint32_t k = 0; k < f->dims[2]; k++)
        for (uint32_t j = 0; j < f->dims[1]; j++)
            for (uint32_t i = 0; i < f->dims[0]; i++)
                mk_ffd_control_point(f, i, j, k, plan->lattice_rest + 3 * (i + f->dims[0] * ((size_t)j + f->dims[1] * k)));
    mk_error inner;
    if (mk_ffd_prepare(f, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    mk_result r = parse_ffd_moves(ctx, f->dims, NULL, ch, path, "moves", plan->lattice_rest, current, plan->ffd_displacements);
    if (r != MK_OK) return r;
    f->displacements = plan->ffd_displacements;
    if (mk_ffd_prepare(f, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    return MK_OK;
}

/* Positions j of row i of a lattice: dims[1] for a box, the sides * i points of ring i (1 for
 * the centre) for a prism. */
static uint32_t grid_positions(const uint32_t dims[3], const mk_prism_lattice *prism, uint32_t i)
{
    return prism ? (i ? prism->sides * i : 1) : dims[1];
}

static size_t grid_index(const uint32_t dims[3], const mk_prism_lattice *prism, uint32_t i, uint32_t j, uint32_t k)
{
    return prism ? mk_prism_index(prism, i, j, k) : i + dims[0] * ((size_t)j + dims[1] * k);
}

/* The moves in obj's field (at path; "moves" but for ffd_prism's "rest_moves") applied to a lattice of dims control points (point (i, j, k) at
 * index i + dims[0] (j + dims[1] k)), or with prism set to its rings (i = ring 0..dims[0]-1,
 * j = position around ring i, k = layer 0..dims[2]-1; without "j" a move takes whole rings):
 * current starts as a copy of rest and ends moved; displacements gets moved - rest. */
static mk_result parse_ffd_moves(recipe_ctx *ctx, const uint32_t dims[3], const mk_prism_lattice *prism,
                                 const cJSON *obj, const char *path, const char *field, const double *rest,
                                 double *current, double *displacements)
{
    size_t points = prism ? mk_prism_point_count(prism) : (size_t)dims[0] * dims[1] * dims[2];
    memcpy(current, rest, 3 * points * sizeof(double));
    const cJSON *moves = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (moves && !cJSON_IsArray(moves))
        return field_error(ctx, path, field, "must be an array of moves%s", NULL);
    int m = 0;
    for (const cJSON *mv = moves ? moves->child : NULL; mv; mv = mv->next, m++) {
        static const char *const move_fields[] = { "i", "j", "k", "translate", "rotate", "scale", "pivot", NULL };
        char mpath[256];
        snprintf(mpath, sizeof mpath, "%s.%s[%d]", path, field, m);
        if (!cJSON_IsObject(mv)) return field_error(ctx, mpath, "", "must be an object%s", NULL);
        mk_result r = check_fields(ctx, mv, mpath, move_fields, NULL);
        if (r != MK_OK) return r;
        uint32_t lo[3], hi[3];
        static const char *const ijk[3] = { "i", "j", "k" };
        for (int a = 0; a < 3; a++)
            if ((r = parse_index_range(ctx, mv, mpath, ijk[a], a == 1 ? grid_positions(dims, prism, lo[0]) : dims[a],
                                       &lo[a], &hi[a])) != MK_OK) return r;
        int all_j = !cJSON_HasObjectItem(mv, "j");
#define LAST_J(i) (all_j ? grid_positions(dims, prism, i) - 1 : hi[1])
        /* Default pivot: centroid of the selected control points (current positions). */
        double centroid[3] = { 0, 0, 0 };
        size_t sel = 0;
        for (uint32_t k = lo[2]; k <= hi[2]; k++)
            for (uint32_t i = lo[0]; i <= hi[0]; i++)
                for (uint32_t j = lo[1]; j <= LAST_J(i); j++, sel++)
                    for (int c = 0; c < 3; c++)
                        centroid[c] += current[3 * grid_index(dims, prism, i, j, k) + c];
        for (int c = 0; c < 3; c++) centroid[c] /= (double)sel;
        double pivot[3] = { centroid[0], centroid[1], centroid[2] };
        if (get_vec3(ctx, mv, mpath, "pivot", pivot) < 0) return ctx->err->code;
        double scale[3] = { 1, 1, 1 }, translate[3] = { 0, 0, 0 }, axis[3], angle, rpivot[3];
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(mv, "scale");
        if (sc && cJSON_IsNumber(sc)) {
            if (!isfinite(sc->valuedouble)) return field_error(ctx, mpath, "scale", "is not finite%s", NULL);
            scale[0] = scale[1] = scale[2] = sc->valuedouble;
        } else if (sc && get_vec3(ctx, mv, mpath, "scale", scale) < 0) return ctx->err->code;
        if (get_vec3(ctx, mv, mpath, "translate", translate) < 0) return ctx->err->code;
        if ((r = parse_rotate(ctx, mv, mpath, axis, &angle, rpivot, pivot)) != MK_OK) return r;
        double R[9];
        mat3_rotation(R, axis, angle);
        /* P <- rotate(scale(P about pivot)) about rotate.pivot, then translate. */
        for (uint32_t k = lo[2]; k <= hi[2]; k++)
            for (uint32_t i = lo[0]; i <= hi[0]; i++)
                for (uint32_t j = lo[1]; j <= LAST_J(i); j++) {
                    double *p = current + 3 * grid_index(dims, prism, i, j, k);
                    double q[3], o[3];
                    for (int c = 0; c < 3; c++) q[c] = pivot[c] + scale[c] * (p[c] - pivot[c]) - rpivot[c];
                    mat3_mul_vec(o, R, q);
                    for (int c = 0; c < 3; c++) p[c] = rpivot[c] + o[c] + translate[c];
                }
    }
#undef LAST_J
    for (size_t q = 0; q < 3 * points; q++) displacements[q] = current[q] - rest[q];
    return MK_OK;
}

/* A recipe's file path resolved against options.base_dir (absolute paths are kept). */
static void recipe_path(const recipe_ctx *ctx, const char *name, char *full, size_t size)
{
    const char *dir = ctx->options && ctx->options->base_dir ? ctx->options->base_dir : "";
    if (name[0] == '/' || !*dir) snprintf(full, size, "%s", name);
    else snprintf(full, size, "%s/%s", dir, name);
}

static mk_result load_cage_file(recipe_ctx *ctx, const cJSON *ch, const char *path, const char *field,
                                double **verts, uint32_t *nv, uint32_t **tris, uint32_t *nt)
{
    if (untrusted(ctx)) return field_error(ctx, path, field, "files are not read for untrusted recipes%s", NULL);
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(ch, field);
    if (!item) return field_error(ctx, path, field, "missing (path of an OBJ file)%s", NULL);
    if (!cJSON_IsString(item) || !*item->valuestring)
        return field_error(ctx, path, field, "must be the path of an OBJ file%s", NULL);
    char full[4096];
    recipe_path(ctx, item->valuestring, full, sizeof full);
    mk_error inner;
    mk_obj obj;
    if (mk_obj_read(full, ctx->scratch, &obj, &inner) != MK_OK)
        return mk_error_set(ctx->err, inner.code, inner.offset, "%s.%s: %s", path, field, inner.message);
    if (ctx->options && ctx->options->file_read) ctx->options->file_read(ctx->options->user, full);
    *verts = obj.positions;
    *nv = obj.vertex_count;
    *tris = obj.triangles;
    *nt = obj.triangle_count;
    return MK_OK;
}

static mk_result parse_cage(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    double *rest, *def;
    uint32_t nv, nt, nv2, nt2, *tris, *tris2;
    mk_result r = load_cage_file(ctx, ch, path, "cage", &rest, &nv, &tris, &nt);
    if (r == MK_OK) r = load_cage_file(ctx, ch, path, "deformed_cage", &def, &nv2, &tris2, &nt2);
    if (r != MK_OK) return r;
    if (nv2 != nv)
        return field_error(ctx, path, "deformed_cage", "has a different vertex count than cage%s", NULL);
    plan->cage.vertex_count = nv;
    plan->cage.rest = rest;
    plan->cage.deformed = def;
    plan->cage.triangle_count = nt;
    plan->cage.triangles = tris;
    mk_error inner;
    if (mk_cage_validate(&plan->cage, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.cage: %s", path, inner.message);
    return MK_OK;
}

static mk_result parse_edit(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_edit_params *e = &plan->edit;
    memset(e, 0, sizeof *e);
    e->method = plan->op == OP_ARAP ? MK_EDIT_ARAP : MK_EDIT_LAPLACIAN;
    const cJSON *w = cJSON_GetObjectItemCaseSensitive(ch, "weights");
    if (w) {
        if (cJSON_IsString(w) && !strcmp(w->valuestring, "cotangent")) e->weights = MK_WEIGHTS_COTANGENT;
        else if (cJSON_IsString(w) && !strcmp(w->valuestring, "uniform")) e->weights = MK_WEIGHTS_UNIFORM;
        else return field_error(ctx, path, "weights", "must be \"cotangent\" or \"uniform\"%s", NULL);
    }
    const cJSON *cons = cJSON_GetObjectItemCaseSensitive(ch, "constraints");
    if (cons) {
        if (cJSON_IsString(cons) && !strcmp(cons->valuestring, "hard")) e->soft = 0;
        else if (cJSON_IsString(cons) && !strcmp(cons->valuestring, "soft")) e->soft = 1;
        else return field_error(ctx, path, "constraints", "must be \"hard\" or \"soft\"%s", NULL);
    }
    e->soft_weight = 100;
    mk_result r = get_number(ctx, ch, path, "soft_weight", &e->soft_weight, 0);
    if (r != MK_OK) return r;
    if (!(e->soft_weight > 0)) return field_error(ctx, path, "soft_weight", "must be > 0%s", NULL);
    e->iterations = untrusted(ctx) ? 50 : 1000;
    if ((r = get_uint(ctx, ch, path, "iterations", &e->iterations, 1, untrusted(ctx) ? 50 : 10000)) != MK_OK) return r;
    e->convergence = 1e-6;
    if ((r = get_number(ctx, ch, path, "convergence", &e->convergence, 0)) != MK_OK) return r;
    if (!(e->convergence >= 0 && e->convergence < 1))
        return field_error(ctx, path, "convergence", "must be in [0, 1) (0: run all iterations)%s", NULL);
    if (e->convergence == 0) e->convergence = -1;  /* the C API's "all iterations" */
    const cJSON *acc = cJSON_GetObjectItemCaseSensitive(ch, "acceleration");
    if (acc) {
        if (cJSON_IsString(acc) && !strcmp(acc->valuestring, "lbfgs")) e->acceleration = MK_ARAP_LBFGS;
        else if (cJSON_IsString(acc) && !strcmp(acc->valuestring, "anderson")) e->acceleration = MK_ARAP_ANDERSON;
        else if (cJSON_IsString(acc) && !strcmp(acc->valuestring, "none")) e->acceleration = MK_ARAP_PLAIN;
        else return field_error(ctx, path, "acceleration", "must be \"lbfgs\", \"anderson\" or \"none\"%s", NULL);
    }

    unsigned char *mark = mk_arena_array(ctx->scratch, mesh->vertex_count ? mesh->vertex_count : 1, 1);
    if (!mark) return mk_error_oom(ctx->err, "selection");
    /* Anchors: one selection or an array of them. */
    const cJSON *anchors = cJSON_GetObjectItemCaseSensitive(ch, "anchors");
    uint32_t *alist = NULL, acount = 0, acap = 0;
    char spath[256];
    if (anchors && cJSON_IsArray(anchors)) {
        int k = 0;
        for (const cJSON *s = anchors->child; s; s = s->next, k++) {
            snprintf(spath, sizeof spath, "%s.anchors[%d]", path, k);
            if ((r = parse_selection(ctx, mesh, s, spath, mark, &alist, &acount, &acap, 0)) != MK_OK) return r;
        }
    } else if (anchors) {
        snprintf(spath, sizeof spath, "%s.anchors", path);
        if ((r = parse_selection(ctx, mesh, anchors, spath, mark, &alist, &acount, &acap, 0)) != MK_OK) return r;
    }
    e->anchor_count = acount;
    e->anchors = alist;
    /* Handles: array of selection + translate/rotate. A vertex belongs to the first handle
     * (or anchor) that selects it. */
    const cJSON *handles = cJSON_GetObjectItemCaseSensitive(ch, "handles");
    if (!handles) return field_error(ctx, path, "handles", "missing (at least one handle moves the mesh)%s", NULL);
    if (cJSON_IsObject(handles)) {
        /* allow a single handle object */
    } else if (!cJSON_IsArray(handles) || cJSON_GetArraySize(handles) == 0)
        return field_error(ctx, path, "handles", "must be a non-empty array of handles%s", NULL);
    int hcount = cJSON_IsObject(handles) ? 1 : cJSON_GetArraySize(handles);
    plan->handles = mk_arena_array(ctx->scratch, (size_t)hcount, sizeof *plan->handles);
    if (!plan->handles) return mk_error_oom(ctx->err, "handles");
    for (int h = 0; h < hcount; h++) {
        const cJSON *hd = cJSON_IsObject(handles) ? handles : cJSON_GetArrayItem(handles, h);
        if (cJSON_IsObject(handles)) snprintf(spath, sizeof spath, "%s.handles", path);
        else snprintf(spath, sizeof spath, "%s.handles[%d]", path, h);
        uint32_t *list = NULL, count = 0, cap = 0;
        if ((r = parse_selection(ctx, mesh, hd, spath, mark, &list, &count, &cap, 1)) != MK_OK) return r;
        mk_edit_handle *eh = &plan->handles[h];
        eh->count = count;
        eh->vertices = list;
        double centroid[3] = { 0, 0, 0 };
        for (uint32_t i = 0; i < count; i++)
            for (int c = 0; c < 3; c++) centroid[c] += mesh->positions[3 * (size_t)list[i] + c];
        for (int c = 0; c < 3; c++) centroid[c] /= count;
        if (get_vec3(ctx, hd, spath, "translate", eh->translate) < 0) return ctx->err->code;
        if ((r = parse_rotate(ctx, hd, spath, eh->axis, &eh->angle, eh->pivot, centroid)) != MK_OK) return r;
    }
    e->handles = plan->handles;
    e->handle_count = (uint32_t)hcount;
    return MK_OK;
}

/* ffd_travel: the travel (a rigid motion), a lattice around the swept mesh, the clip. */
static mk_result parse_ffd_travel(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    static const char *const travel_fields[] = { "translate", "rotate", NULL };
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_ffd_travel *t = &plan->travel;
    memset(t, 0, sizeof *t);
    char tpath[96];
    snprintf(tpath, sizeof tpath, "%s.travel", path);
    const cJSON *travel = cJSON_GetObjectItemCaseSensitive(ch, "travel");
    if (!travel) return field_error(ctx, path, "travel", "missing (translate and/or rotate: the mesh's path through the lattice)%s", NULL);
    if (!cJSON_IsObject(travel)) return field_error(ctx, path, "travel", "must be an object {translate, rotate}%s", NULL);
    mk_result r = check_fields(ctx, travel, tpath, travel_fields, NULL);
    if (r != MK_OK) return r;
    double bmin[3], bmax[3], diag, centre[3];
    bake_bounds(mesh, bmin, bmax, &diag);
    for (int c = 0; c < 3; c++) centre[c] = 0.5 * (bmin[c] + bmax[c]);
    if (get_vec3(ctx, travel, tpath, "translate", t->translate) < 0) return ctx->err->code;
    if ((r = parse_rotate(ctx, travel, tpath, t->axis, &t->angle, t->pivot, centre)) != MK_OK) return r;
    if (vec3_length(t->translate) == 0 && t->angle == 0)
        return field_error(ctx, tpath, "", "moves nothing: give a nonzero translate or rotate%s", NULL);
    plan->clip_duration = 0;
    if ((r = get_number(ctx, ch, path, "duration", &plan->clip_duration, 0)) != MK_OK) return r;
    if (cJSON_HasObjectItem(ch, "duration") && !(plan->clip_duration > 0))
        return field_error(ctx, path, "duration", "must be > 0 seconds%s", NULL);
    /* Default lattice: around the mesh at 17 points of its travel. */
    double bounds[2][3];
    for (int c = 0; c < 3; c++) { bounds[0][c] = bmin[c]; bounds[1][c] = bmax[c]; }
    for (int k = 1; k <= 16; k++) {
        double R[9];
        mat3_rotation(R, t->axis, k / 16.0 * t->angle);
        for (uint32_t v = 0; v < mesh->vertex_count; v++) {
            const float *p = mesh->positions + 3 * (size_t)v;
            double d[3] = { p[0] - t->pivot[0], p[1] - t->pivot[1], p[2] - t->pivot[2] }, q[3];
            mat3_mul_vec(q, R, d);
            for (int c = 0; c < 3; c++) {
                q[c] += t->pivot[c] + k / 16.0 * t->translate[c];
                if (q[c] < bounds[0][c]) bounds[0][c] = q[c];
                if (q[c] > bounds[1][c]) bounds[1][c] = q[c];
            }
        }
    }
    if ((r = parse_ffd(ctx, plan, ch, path, (const double (*)[3])bounds)) != MK_OK) return r;
    t->lattice = &plan->ffd;
    /* The channel's weight 0 is the rest mesh: the lattice may not move the start pose. */
    double worst = 0;
    uint32_t worst_v = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const float *p = mesh->positions + 3 * (size_t)v;
        double pd[3] = { p[0], p[1], p[2] }, q[3], J[9], d[3];
        mk_ffd_travel_map(t, 0, pd, q, J);
        vec3_sub(d, q, pd);
        if (vec3_length(d) > worst) { worst = vec3_length(d); worst_v = v; }
    }
    if (worst > 1e-6 * diag) {
        char msg[200];
        snprintf(msg, sizeof msg, "the deformed lattice moves the mesh before it travels (vertex %u by %.3g x diagonal): "
                 "keep the control points around the start pose at rest", worst_v, worst / diag);
        return field_error(ctx, path, "moves", "%s", msg);
    }
    return MK_OK;
}

/* ffd_keys: the lattice, then per key its time and its own moves from the rest lattice. */
static mk_result parse_ffd_keys(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    static const char *const key_fields[] = { "time", "moves", NULL };
    mk_result r = parse_ffd(ctx, plan, ch, path, NULL);
    if (r != MK_OK) return r;
    if (strlen(plan->name) + 8 >= sizeof plan->name)
        return field_error(ctx, path, "name", "must be under 120 bytes for ffd_keys (channels are named NAME.keyK)%s", NULL);
    const cJSON *keys = cJSON_GetObjectItemCaseSensitive(ch, "keys");
    if (!keys) return field_error(ctx, path, "keys", "missing (an array of {time, moves})%s", NULL);
    int count = cJSON_IsArray(keys) ? cJSON_GetArraySize(keys) : 0;
    if (count < 1 || count > (untrusted(ctx) ? 32 : 256))
        return field_error(ctx, path, "keys", "must be an array of 1..256 keys {time, moves} (32 when untrusted)%s", NULL);
    const mk_ffd_lattice *f = &plan->ffd;
    size_t points = (size_t)f->dims[0] * f->dims[1] * f->dims[2];
    plan->key_count = (uint32_t)count;
    plan->key_times = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double));
    plan->key_displacements = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double *));
    double *current = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    if (!plan->key_times || !plan->key_displacements || !current) return mk_error_oom(ctx->err, "lattice keys");
    int k = 0;
    for (const cJSON *key = keys->child; key; key = key->next, k++) {
        char kpath[96];
        snprintf(kpath, sizeof kpath, "%s.keys[%d]", path, k);
        if (!cJSON_IsObject(key)) return field_error(ctx, kpath, "", "must be an object {time, moves}%s", NULL);
        if ((r = check_fields(ctx, key, kpath, key_fields, NULL)) != MK_OK) return r;
        if ((r = get_number(ctx, key, kpath, "time", &plan->key_times[k], 1)) != MK_OK) return r;
        if (plan->key_times[k] < 0) return field_error(ctx, kpath, "time", "must be >= 0 seconds%s", NULL);
        if (k > 0 && !(plan->key_times[k] > plan->key_times[k - 1]))
            return field_error(ctx, kpath, "time", "must be later than the previous key's%s", NULL);
        plan->key_displacements[k] = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
        if (!plan->key_displacements[k]) return mk_error_oom(ctx->err, "lattice keys");
        if ((r = parse_ffd_moves(ctx, f->dims, NULL, key, kpath, "moves", plan->lattice_rest, current, plan->key_displacements[k])) != MK_OK)
            return r;
    }
    return MK_OK;
}

/* The placement shared by the lattices around an axis (ffd_cylinder, ffd_prism): fields axis,
 * center, padding (default 0.05), range and reference. base gets the axis point of the first
 * layer, axis_out the axis scaled to the range's length, reference the direction of sector or
 * corner 0 (default: the coordinate axis least aligned with the axis); far gets the mesh's
 * largest distance from the axis and pad the padding in mesh units. */
static mk_result parse_axial_lattice(recipe_ctx *ctx, const cJSON *ch, const char *path, const mk_raw_mesh *mesh,
                                     double base[3], double axis_out[3], double reference[3], double *far,
                                     double *pad)
{
    double axis[3], bmin[3], bmax[3], diag, padding = 0.05;
    mk_result r = parse_axis(ctx, ch, path, axis);
    if (r != MK_OK) return r;
    vec3_normalize(axis);
    bake_bounds(mesh, bmin, bmax, &diag);
    double center[3];
    for (int k = 0; k < 3; k++) center[k] = 0.5 * (bmin[k] + bmax[k]);
    if (get_vec3(ctx, ch, path, "center", center) < 0) return ctx->err->code;
    if ((r = get_number(ctx, ch, path, "padding", &padding, 0)) != MK_OK) return r;
    if (padding < 0) return field_error(ctx, path, "padding", "must be >= 0%s", NULL);
    /* Extent along the axis and largest distance from it. */
    double lo = INFINITY, hi = -INFINITY;
    *far = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const float *pf = mesh->positions + 3 * (size_t)v;
        double d[3] = { pf[0] - center[0], pf[1] - center[1], pf[2] - center[2] }, a = vec3_dot(d, axis);
        lo = fmin(lo, a + vec3_dot(center, axis)); hi = fmax(hi, a + vec3_dot(center, axis));
        for (int k = 0; k < 3; k++) d[k] -= a * axis[k];
        *far = fmax(*far, vec3_length(d));
    }
    *pad = padding * diag;
    double range[2] = { lo - *pad, hi + *pad };
    const cJSON *ritem = cJSON_GetObjectItemCaseSensitive(ch, "range");
    if (ritem) {
        if (!cJSON_IsArray(ritem) || cJSON_GetArraySize(ritem) != 2 || !cJSON_IsNumber(ritem->child) ||
            !cJSON_IsNumber(ritem->child->next) || !isfinite(ritem->child->valuedouble) ||
            !isfinite(ritem->child->next->valuedouble))
            return field_error(ctx, path, "range", "must be [min, max] along the axis (p . axis, mesh units)%s", NULL);
        range[0] = ritem->child->valuedouble;
        range[1] = ritem->child->next->valuedouble;
    }
    if (!(range[1] > range[0])) return field_error(ctx, path, "range", "must have min < max%s", NULL);
    int least = 0;
    for (int k = 1; k < 3; k++) if (fabs(axis[k]) < fabs(axis[least])) least = k;
    for (int k = 0; k < 3; k++) reference[k] = k == least;
    if (get_vec3(ctx, ch, path, "reference", reference) < 0) return ctx->err->code;
    for (int k = 0; k < 3; k++) {
        base[k] = center[k] + (range[0] - vec3_dot(center, axis)) * axis[k];
        axis_out[k] = (range[1] - range[0]) * axis[k];
    }
    return MK_OK;
}

/* ffd_cylinder: the cylindrical lattice around the axis, its moves, every vertex's coordinates. */
static mk_result parse_ffd_cylinder(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_cylinder_lattice *c = &plan->cylinder;
    memset(c, 0, sizeof *c);
    c->dims[0] = 3; c->dims[1] = 8; c->dims[2] = 4;
    const cJSON *dims = cJSON_GetObjectItemCaseSensitive(ch, "dims");
    if (dims) {
        static const double least[3] = { 2, 3, 2 };
        if (!cJSON_IsArray(dims) || cJSON_GetArraySize(dims) != 3)
            return field_error(ctx, path, "dims", "must be [rings, sectors, layers]%s", NULL);
        int a = 0;
        for (const cJSON *e = dims->child; e; e = e->next, a++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < least[a] || v > (untrusted(ctx) ? 8 : 64))
                return field_error(ctx, path, "dims", "rings 2..64, sectors 3..64, layers 2..64 (8 when untrusted)%s", NULL);
            c->dims[a] = (uint32_t)v;
        }
    }
    double far, pad;
    mk_result r = parse_axial_lattice(ctx, ch, path, mesh, c->center, c->axis, c->reference, &far, &pad);
    if (r != MK_OK) return r;
    c->outer_radius = (far + pad) / mk_cylinder_ring_ratio(c->dims[1]);
    if ((r = get_number(ctx, ch, path, "radius", &c->outer_radius, 0)) != MK_OK) return r;
    if ((r = get_number(ctx, ch, path, "inner_radius", &c->inner_radius, 0)) != MK_OK) return r;
    mk_error inner;
    if (mk_cylinder_prepare(c, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    size_t points = (size_t)c->dims[0] * c->dims[1] * c->dims[2];
    plan->lattice_rest = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *current = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *displacements = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    plan->lattice_coordinates = mk_arena_array(ctx->scratch, 3 * (size_t)mesh->vertex_count, sizeof(double));
    if (!plan->lattice_rest || !current || !displacements || !plan->lattice_coordinates)
        return mk_error_oom(ctx->err, "cylinder lattice");
    for (uint32_t k = 0; k < c->dims[2]; k++)
        for (uint32_t j = 0; j < c->dims[1]; j++)
            for (uint32_t i = 0; i < c->dims[0]; i++)
                mk_cylinder_control_point(c, i, j, k, plan->lattice_rest + 3 * (i + c->dims[0] * ((size_t)j + c->dims[1] * k)));
    if ((r = parse_ffd_moves(ctx, c->dims, NULL, ch, path, "moves", plan->lattice_rest, current, displacements)) != MK_OK) return r;
    if (c->inner_radius == 0)
        /* Ring 0 is on the axis: its points of one layer are one point; they move by their mean. */
        for (uint32_t k = 0; k < c->dims[2]; k++) {
            double mean[3] = { 0, 0, 0 };
            for (uint32_t j = 0; j < c->dims[1]; j++)
                for (int q = 0; q < 3; q++) mean[q] += displacements[3 * (c->dims[0] * ((size_t)j + c->dims[1] * k)) + q] / c->dims[1];
            for (uint32_t j = 0; j < c->dims[1]; j++)
                for (int q = 0; q < 3; q++) displacements[3 * (c->dims[0] * ((size_t)j + c->dims[1] * k)) + q] = mean[q];
        }
    c->displacements = displacements;
    if (mk_cylinder_bind(c, mesh, plan->lattice_coordinates, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s: %s (enlarge radius or range)", path, inner.message);
    return MK_OK;
}

/* ffd_prism: the prism lattice around the axis, its moves, every vertex's wedge and coordinates. */
static mk_result parse_ffd_prism(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_prism_lattice *c = &plan->prism;
    memset(c, 0, sizeof *c);
    c->sides = 6; c->degree = 2; c->layers = 4;
    uint32_t most = untrusted(ctx) ? 8 : 64;
    mk_result r;
    if ((r = get_uint(ctx, ch, path, "sides", &c->sides, 3, most)) != MK_OK ||
        (r = get_uint(ctx, ch, path, "degree", &c->degree, 1, untrusted(ctx) ? 4 : 16)) != MK_OK ||
        (r = get_uint(ctx, ch, path, "layers", &c->layers, 2, most)) != MK_OK)
        return r;
    const cJSON *section = cJSON_GetObjectItemCaseSensitive(ch, "section");
    if (section) {
        /* An explicit polygon: [[x, y], ...] in the frame of reference and axis x reference. */
        if (cJSON_HasObjectItem(ch, "sides") || cJSON_HasObjectItem(ch, "radius"))
            return field_error(ctx, path, cJSON_HasObjectItem(ch, "sides") ? "sides" : "radius",
                               "give either section or sides and radius, not both%s", NULL);
        int count = cJSON_IsArray(section) ? cJSON_GetArraySize(section) : 0;
        if (count < 3 || count > (int)most)
            return field_error(ctx, path, "section", "must be an array of 3..64 corners [x, y] (8 when untrusted)%s", NULL);
        double *corners = mk_arena_array(ctx->scratch, 2 * (size_t)count, sizeof(double));
        if (!corners) return mk_error_oom(ctx->err, "prism section");
        int w = 0;
        for (const cJSON *e = section->child; e; e = e->next, w++) {
            char field[32];
            snprintf(field, sizeof field, "section[%d]", w);
            if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 2 || !cJSON_IsNumber(e->child) || !cJSON_IsNumber(e->child->next))
                return field_error(ctx, path, field, "must be a corner [x, y] (mesh units along reference and axis x reference)%s", NULL);
            corners[2 * w] = e->child->valuedouble;
            corners[2 * w + 1] = e->child->next->valuedouble;
            if (!isfinite(corners[2 * w]) || !isfinite(corners[2 * w + 1]))
                return field_error(ctx, path, field, "holds a value that is not finite%s", NULL);
        }
        c->sides = (uint32_t)count;
        c->section = corners;
    }
    double far, pad;
    if ((r = parse_axial_lattice(ctx, ch, path, mesh, c->center, c->axis, c->reference, &far, &pad)) != MK_OK) return r;
    /* The polygon's sides are cos(pi / sides) of the corner radius from the centre. */
    c->radius = (far + pad) / cos(PI / c->sides);
    if ((r = get_number(ctx, ch, path, "radius", &c->radius, 0)) != MK_OK) return r;
    mk_error inner;
    if (mk_prism_prepare(c, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    size_t points = mk_prism_point_count(c);
    plan->lattice_rest = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *current = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *displacements = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    plan->lattice_coordinates = mk_arena_array(ctx->scratch, 4 * (size_t)mesh->vertex_count, sizeof(double));
    if (!plan->lattice_rest || !current || !displacements || !plan->lattice_coordinates)
        return mk_error_oom(ctx->err, "prism lattice");
    for (uint32_t k = 0; k < c->layers; k++)
        for (uint32_t i = 0; i <= c->degree; i++)
            for (uint32_t j = 0; j < (i ? c->sides * i : 1); j++)
                mk_prism_control_point(c, i, j, k, plan->lattice_rest + 3 * (size_t)mk_prism_index(c, i, j, k));
    uint32_t dims[3] = { c->degree + 1, 0, c->layers };
    if (cJSON_HasObjectItem(ch, "rest_moves")) {
        /* The rest lattice shaped to the mesh before binding: the regular one moved. */
        if ((r = parse_ffd_moves(ctx, dims, c, ch, path, "rest_moves", plan->lattice_rest, current, displacements)) != MK_OK)
            return r;
        memcpy(plan->lattice_rest, current, 3 * points * sizeof(double));
        c->rest = plan->lattice_rest;
    }
    if ((r = parse_ffd_moves(ctx, dims, c, ch, path, "moves", plan->lattice_rest, current, displacements)) != MK_OK)
        return r;
    c->displacements = displacements;
    if (mk_prism_prepare(c, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.moves/rest_moves: %s", path, inner.message);
    if (mk_prism_bind(c, mesh, plan->lattice_coordinates, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s: %s (enlarge radius or range)", path, inner.message);
    return MK_OK;
}

/* mk_deformer for ffd_cylinder and ffd_prism: p + a sum w d per vertex, from the coordinates
 * found once at parse time. */
static mk_result extended_ffd_eval(void *user, double amplitude, double *positions, double *normals, double *tangents,
                                   uint32_t *inverted, mk_error *err)
{
    (void)normals; (void)tangents; (void)err;
    const channel_plan *plan = ((const bake_pointwise *)user)->user;
    const mk_raw_mesh *mesh = ((const bake_pointwise *)user)->mesh;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const float *pf = mesh->positions + 3 * (size_t)v;
        double p[3] = { pf[0], pf[1], pf[2] };
        if (plan->op == OP_FFD_PRISM)
            mk_prism_eval(&plan->prism, amplitude, plan->lattice_coordinates + 4 * (size_t)v, p, positions + 3 * (size_t)v);
        else
            mk_cylinder_eval(&plan->cylinder, amplitude, plan->lattice_coordinates + 3 * (size_t)v, p,
                             positions + 3 * (size_t)v);
    }
    if (inverted) *inverted = 0;
    return MK_OK;
}

/* shell: the simulation parameters, the anisotropic region and where the targets go. */
static mk_result get_positive(recipe_ctx *ctx, const cJSON *ch, const char *path, const char *field, double *out,
                              double lo, int lo_open, double hi, const char *range)
{
    mk_result r = get_number(ctx, ch, path, field, out, 0);
    if (r != MK_OK) return r;
    if ((lo_open ? !(*out > lo) : !(*out >= lo)) || !(*out < hi)) return field_error(ctx, path, field, "must be %s", range);
    return MK_OK;
}

static mk_result parse_shell_at(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(ch, "at_frames");
    const cJSON *ratios = cJSON_GetObjectItemCaseSensitive(ch, "at_volume_ratios");
    if (frames && ratios) return field_error(ctx, path, "at_volume_ratios", "give at_frames or at_volume_ratios, not both%s", NULL);
    const cJSON *list = frames ? frames : ratios;
    const char *field = frames ? "at_frames" : "at_volume_ratios";
    if (!list) return MK_OK;
    int count = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : 0;
    if (count < 1 || count > (untrusted(ctx) ? 32 : SHELL_MAX_KEYS))
        return field_error(ctx, path, field, "must be an array of 1..256 numbers (32 when untrusted)%s", NULL);
    plan->shell_at = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double));
    if (!plan->shell_at) return mk_error_oom(ctx->err, field);
    plan->shell_at_ratios = ratios != NULL;
    int k = 0;
    for (const cJSON *e = list->child; e; e = e->next, k++) {
        double v = e->valuedouble;
        char msg[160];
        int ok = cJSON_IsNumber(e) && isfinite(v);
        if (frames) {
            ok = ok && v == floor(v) && v >= 1 && v <= plan->shell.frames && (k == 0 || v > plan->shell_at[k - 1]);
            snprintf(msg, sizeof msg, "entry %d must be a frame in 1..%u (frames), later than the previous entry", k, plan->shell.frames);
        } else {
            ok = ok && v > 0 && v < 1 && (k == 0 || v < plan->shell_at[k - 1]);
            snprintf(msg, sizeof msg, "entry %d must be a volume ratio in (0, 1), smaller than the previous entry", k);
        }
        if (!ok) return field_error(ctx, path, field, "%s", msg);
        plan->shell_at[k] = v;
    }
    plan->shell_at_count = (uint32_t)count;
    return MK_OK;
}

static mk_result parse_shell_region(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    static const char *const aniso_fields[] = { "region", "direction", "energy", "stiffness", "k_A", NULL };
    shell_params *p = &plan->shell;
    const cJSON *an;
    char apath[96];
    mk_result r = get_object(ctx, ch, path, "anisotropic", aniso_fields, "{region, direction, energy, stiffness, k_A}",
                             apath, sizeof apath, &an);
    if (r != MK_OK || !an) return r;
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    const cJSON *region = cJSON_GetObjectItemCaseSensitive(an, "region");
    if (!region) return field_error(ctx, apath, "region", "missing (a vertex selection)%s", NULL);
    plan->shell_region = mk_arena_array(ctx->scratch, mesh->vertex_count, 1);
    if (!plan->shell_region) return mk_error_oom(ctx->err, "shell region");
    uint32_t *list = NULL, count = 0, cap = 0;
    char rpath[128];
    snprintf(rpath, sizeof rpath, "%s.region", apath);
    if ((r = parse_selection(ctx, mesh, region, rpath, plan->shell_region, &list, &count, &cap, 0)) != MK_OK) return r;
    p->aniso_direction[1] = 1;
    int got = get_vec3(ctx, an, apath, "direction", p->aniso_direction);
    if (got < 0) return ctx->err->code;
    if (!(vec3_normalize(p->aniso_direction) > 0)) return field_error(ctx, apath, "direction", "is a zero vector%s", NULL);
    const cJSON *energy = cJSON_GetObjectItemCaseSensitive(an, "energy");
    p->aniso_energy = SHELL_ANISO_ARAP;
    if (energy) {
        const char *e = cJSON_IsString(energy) ? energy->valuestring : "";
        if (!strcmp(e, "arap")) p->aniso_energy = SHELL_ANISO_ARAP;
        else if (!strcmp(e, "sqrt")) p->aniso_energy = SHELL_ANISO_SQRT;
        else if (!strcmp(e, "stvk")) p->aniso_energy = SHELL_ANISO_STVK;
        else return field_error(ctx, apath, "energy", "must be \"arap\", \"sqrt\" or \"stvk\"%s", NULL);
    }
    p->aniso_mu = p->mu;
    if ((r = get_positive(ctx, an, apath, "stiffness", &p->aniso_mu, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = get_number(ctx, an, apath, "k_A", &p->aniso_kA, 0)) != MK_OK) return r;
    return MK_OK;
}

static mk_result parse_shell(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    shell_params *p = &plan->shell;
    memset(p, 0, sizeof *p);
    p->threads = ctx->options ? ctx->options->threads : 0;
    p->pressure = 20;
    p->dt = 0.01;
    p->frames = 100;
    p->iterations = 5;
    p->density = 1;
    p->damping = 0.02;
    p->material = SHELL_STVK;
    p->mu = 100;
    p->lambda = 100;
    p->kB = 1e-2;
    p->epsilon = 0.05;
    mk_result r;
    if ((r = get_positive(ctx, ch, path, "pressure", &p->pressure, 0, 1, INFINITY, "> 0")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "dt", &p->dt, 0, 1, INFINITY, "> 0 seconds")) != MK_OK) return r;
    if ((r = get_uint(ctx, ch, path, "frames", &p->frames, 1, untrusted(ctx) ? 200 : 100000)) != MK_OK) return r;
    if ((r = get_uint(ctx, ch, path, "iterations", &p->iterations, 1, untrusted(ctx) ? 20 : 1000)) != MK_OK) return r;
    if ((r = get_uint(ctx, ch, path, "substeps", &p->substeps, 0, untrusted(ctx) ? SHELL_MAX_SUBSTEPS : 1000)) != MK_OK) return r;
    p->ramp = p->frames * p->dt;
    if ((r = get_positive(ctx, ch, path, "ramp", &p->ramp, 0, 0, INFINITY, ">= 0 seconds")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "density", &p->density, 0, 1, INFINITY, "> 0")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "damping", &p->damping, 0, 0, 1, "in [0, 1)")) != MK_OK) return r;
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(ch, "material");
    if (mat) {
        static const char *const names[] = { "stvk", "corotated", "linear", "mooney_rivlin" };
        int k = -1;
        for (int i = 0; i < 4 && cJSON_IsString(mat); i++)
            if (!strcmp(mat->valuestring, names[i])) k = i;
        if (k < 0) return field_error(ctx, path, "material", "must be \"stvk\", \"corotated\", \"linear\" or \"mooney_rivlin\"%s", NULL);
        p->material = (shell_material)k;
    }
    if ((r = get_positive(ctx, ch, path, "mu", &p->mu, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "lambda", &p->lambda, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "kB", &p->kB, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "epsilon", &p->epsilon, 0, 0, 1, "in [0, 1)")) != MK_OK) return r;
    if ((r = get_positive(ctx, ch, path, "thickness", &p->thickness, 0, 0, INFINITY, ">= 0 (mesh units)")) != MK_OK) return r;
    if ((r = parse_shell_region(ctx, plan, ch, path)) != MK_OK) return r;
    if ((r = parse_shell_at(ctx, plan, ch, path)) != MK_OK) return r;
    const cJSON *log = cJSON_GetObjectItemCaseSensitive(ch, "log");
    if (log) {
        if (untrusted(ctx)) return field_error(ctx, path, "log", "files are not written for untrusted recipes%s", NULL);
        if (!cJSON_IsString(log) || !*log->valuestring) return field_error(ctx, path, "log", "must be the path of a CSV file%s", NULL);
        plan->shell_log = log->valuestring;
    }
    const cJSON *clip = cJSON_GetObjectItemCaseSensitive(ch, "clip");
    if (clip && !cJSON_IsBool(clip)) return field_error(ctx, path, "clip", "must be true or false%s", NULL);
    plan->clip_duration = cJSON_IsTrue(clip) ? -1 : 0;  /* the simulated duration, known after the run */
    return MK_OK;
}

/* ---- recipe ---- */

/* A mesh of `raw` by name or index (field `field` of the object at path). */
static mk_result resolve_mesh_of(recipe_ctx *ctx, const mk_raw_asset *raw, const cJSON *item, const char *path,
                                 const char *field, uint32_t *mesh)
{
    if (!item) return field_error(ctx, path, field, "missing (a mesh name or index)%s", NULL);
    if (cJSON_IsNumber(item)) {
        double v = item->valuedouble;
        if (!isfinite(v) || v != floor(v) || v < 0 || v >= raw->mesh_count) {
            char msg[96];
            snprintf(msg, sizeof msg, "index %g is not a mesh (the asset has %u)", v, raw->mesh_count);
            return field_error(ctx, path, field, "%s", msg);
        }
        *mesh = (uint32_t)v;
        return MK_OK;
    }
    if (!cJSON_IsString(item)) return field_error(ctx, path, field, "must be a mesh name or index%s", NULL);
    for (uint32_t m = 0; m < raw->mesh_count; m++)
        if (raw->meshes[m].name && !strcmp(raw->meshes[m].name, item->valuestring)) {
            *mesh = m;
            return MK_OK;
        }
    char names[120] = "";
    for (uint32_t m = 0; m < raw->mesh_count; m++) {
        size_t n = strlen(names);
        const char *name = raw->meshes[m].name ? raw->meshes[m].name : "";
        if (n + strlen(name) + 8 >= sizeof names) { snprintf(names + n, sizeof names - n, ", ..."); break; }
        snprintf(names + n, sizeof names - n, "%s\"%s\"", n ? ", " : "", name);
    }
    char msg[200];
    snprintf(msg, sizeof msg, "no mesh named \"%.40s\"; the meshes are %s", item->valuestring,
             raw->mesh_count ? names : "(none)");
    return field_error(ctx, path, field, "%s", msg);
}

static mk_result resolve_mesh(recipe_ctx *ctx, const cJSON *item, const char *path, uint32_t *mesh)
{
    return resolve_mesh_of(ctx, ctx->raw, item, path, "mesh", mesh);
}

static mk_result check_mesh(recipe_ctx *ctx, uint32_t m, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[m];
    if (mesh->vertex_count == 0)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.mesh: mesh %u has no vertices", path, m);
    for (size_t i = 0; i < 3 * (size_t)mesh->vertex_count; i++)
        if (!isfinite(mesh->positions[i]))
            return mk_error_set(ctx->err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                "mesh %u vertex %zu: position is not finite", m, i / 3);
    for (size_t i = 0; i < 3 * (size_t)mesh->triangle_count; i++)
        if (mesh->triangles[i] >= mesh->vertex_count)
            return mk_error_set(ctx->err, MK_ERROR_CORRUPT, UINT64_MAX,
                                "mesh %u triangle %zu: vertex index out of range", m, i / 3);
    return MK_OK;
}

/* transfer: load the source asset through options.load_asset, pick its mesh and channels, read
 * the markers. The source stays loaded until the bake ends (free_plan). */
static mk_result parse_transfer(recipe_ctx *ctx, channel_plan *plan, const cJSON *ch, const char *path)
{
    static const char *const not_for_transfer[] = { "name", "inbetweens", "tolerance", "samples", "max_targets", NULL };
    for (int i = 0; not_for_transfer[i]; i++)
        if (cJSON_HasObjectItem(ch, not_for_transfer[i]))
            return field_error(ctx, path, not_for_transfer[i],
                               "does not apply to transfer%s (channels are named after the source's, with prefix; "
                               "in-betweens are carried over one to one)", NULL);
    plan->has_default_weight = cJSON_HasObjectItem(ch, "default_weight");
    const cJSON *prefix = cJSON_GetObjectItemCaseSensitive(ch, "prefix");
    if (prefix && (!cJSON_IsString(prefix) || strlen(prefix->valuestring) >= sizeof plan->prefix))
        return field_error(ctx, path, "prefix", "must be a string under 64 bytes%s", NULL);
    if (prefix) snprintf(plan->prefix, sizeof plan->prefix, "%s", prefix->valuestring);

    if (untrusted(ctx)) return field_error(ctx, path, "source", "files are not read for untrusted recipes%s", NULL);
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(ch, "source");
    if (!item) return field_error(ctx, path, "source", "missing (path of the asset whose channels are transferred)%s", NULL);
    if (!cJSON_IsString(item) || !*item->valuestring)
        return field_error(ctx, path, "source", "must be the path of an asset file (.fbx, .gltf, .glb, .morph)%s", NULL);
    if (!ctx->options || !ctx->options->load_asset)
        return field_error(ctx, path, "source", "this bake has no asset loader (mk_bake_options.load_asset)%s", NULL);
    char full[4096];
    recipe_path(ctx, item->valuestring, full, sizeof full);
    plan->source = mk_arena_alloc(ctx->scratch, sizeof *plan->source);
    if (!plan->source) return mk_error_oom(ctx->err, "transfer source");
    mk_raw_init(plan->source, &ctx->raw->arena.allocator);
    mk_error inner;
    memset(&inner, 0, sizeof inner);
    if (ctx->options->load_asset(ctx->options->user, full, plan->source, &inner) != MK_OK)
        return mk_error_set(ctx->err, inner.code ? inner.code : MK_ERROR_IO, inner.offset, "%s.source: %s", path,
                            inner.message);  /* the loader names the file */
    if (ctx->options->file_read) ctx->options->file_read(ctx->options->user, full);
    const mk_raw_asset *src = plan->source;
    plan->source_mesh = 0;
    const cJSON *sm = cJSON_GetObjectItemCaseSensitive(ch, "source_mesh");
    mk_result r;
    if (sm && (r = resolve_mesh_of(ctx, src, sm, path, "source_mesh", &plan->source_mesh)) != MK_OK) return r;
    if (plan->source_mesh >= src->mesh_count)
        return field_error(ctx, path, "source", "the asset has no mesh%s", NULL);
    const mk_raw_mesh *smesh = &src->meshes[plan->source_mesh];
    if (smesh->vertex_count == 0 || smesh->triangle_count == 0)
        return field_error(ctx, path, sm ? "source_mesh" : "source", "the source mesh has no triangles%s", NULL);

    /* the source mesh's channels, all by default */
    plan->source_channels = mk_arena_array(ctx->scratch, (size_t)src->channel_count + 1, sizeof(uint32_t));
    if (!plan->source_channels) return mk_error_oom(ctx->err, "transfer channels");
    const cJSON *names = cJSON_GetObjectItemCaseSensitive(ch, "channels");
    char cpath[128];
    if (!names) {
        for (uint32_t c = 0; c < src->channel_count; c++)
            if (src->channels[c].mesh == plan->source_mesh) plan->source_channels[plan->source_channel_count++] = c;
        if (plan->source_channel_count == 0) {
            char msg[160];
            snprintf(msg, sizeof msg, "the source mesh %u (\"%.60s\") has no channels to transfer", plan->source_mesh,
                     smesh->name ? smesh->name : "");
            return field_error(ctx, path, "source", "%s", msg);
        }
    } else {
        if (!cJSON_IsArray(names) || cJSON_GetArraySize(names) == 0)
            return field_error(ctx, path, "channels", "must be a non-empty array of source channel names%s", NULL);
        int i = 0;
        for (const cJSON *n = names->child; n; n = n->next, i++) {
            snprintf(cpath, sizeof cpath, "%s.channels[%d]", path, i);
            if (!cJSON_IsString(n)) return field_error(ctx, cpath, "", "must be a channel name (a string)%s", NULL);
            uint32_t found = UINT32_MAX;
            for (uint32_t c = 0; c < src->channel_count && found == UINT32_MAX; c++)
                if (src->channels[c].mesh == plan->source_mesh && src->channels[c].name &&
                    !strcmp(src->channels[c].name, n->valuestring)) found = c;
            if (found == UINT32_MAX) {
                char list[120] = "";
                for (uint32_t c = 0; c < src->channel_count; c++) {
                    if (src->channels[c].mesh != plan->source_mesh) continue;
                    size_t len = strlen(list);
                    const char *cn = src->channels[c].name ? src->channels[c].name : "";
                    if (len + strlen(cn) + 8 >= sizeof list) { snprintf(list + len, sizeof list - len, ", ..."); break; }
                    snprintf(list + len, sizeof list - len, "%s\"%s\"", len ? ", " : "", cn);
                }
                char msg[240];
                snprintf(msg, sizeof msg, "no channel \"%.40s\" on the source mesh; its channels are %s", n->valuestring,
                         *list ? list : "(none)");
                return field_error(ctx, cpath, "", "%s", msg);
            }
            plan->source_channels[plan->source_channel_count++] = found;
        }
    }
    for (uint32_t k = 0; k < plan->source_channel_count; k++) {
        const mk_raw_channel *sc = &src->channels[plan->source_channels[k]];
        if (sc->target_count == 0)
            return field_error(ctx, path, "source", "channel \"%s\" of the source has no targets", sc->name ? sc->name : "");
        if (strlen(plan->prefix) + strlen(sc->name ? sc->name : "") >= sizeof plan->name)
            return field_error(ctx, path, "prefix", "with the source channel \"%.60s\" makes a name of 128 bytes or more", sc->name);
    }

    /* markers: [[source vertex, target vertex], ...] */
    const cJSON *markers = cJSON_GetObjectItemCaseSensitive(ch, "markers");
    if (markers) {
        if (!cJSON_IsArray(markers))
            return field_error(ctx, path, "markers", "must be an array of [source_vertex, target_vertex] pairs%s", NULL);
        int count = cJSON_GetArraySize(markers);
        plan->markers = mk_arena_array(ctx->scratch, (size_t)count + 1, sizeof *plan->markers);
        if (!plan->markers) return mk_error_oom(ctx->err, "markers");
        uint32_t limit[2] = { smesh->vertex_count, ctx->raw->meshes[plan->mesh].vertex_count };
        static const char *const side[2] = { "source", "target" };
        int i = 0;
        for (const cJSON *m = markers->child; m; m = m->next, i++) {
            snprintf(cpath, sizeof cpath, "%s.markers[%d]", path, i);
            if (!cJSON_IsArray(m) || cJSON_GetArraySize(m) != 2)
                return field_error(ctx, cpath, "", "must be a pair [source_vertex, target_vertex]%s", NULL);
            int k = 0;
            for (const cJSON *e = m->child; e; e = e->next, k++) {
                double v = e->valuedouble;
                if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < 0 || v >= limit[k]) {
                    char msg[120];
                    snprintf(msg, sizeof msg, "the %s vertex must be an integer in 0..%u", side[k], limit[k] ? limit[k] - 1 : 0);
                    return field_error(ctx, cpath, "", "%s", msg);
                }
                plan->markers[i][k] = (uint32_t)v;
            }
        }
        plan->marker_count = (uint32_t)count;
    }
    return MK_OK;
}

static mk_result parse_channel(recipe_ctx *ctx, const cJSON *ch, int index, int has_top_mesh,
                               uint32_t top_mesh, channel_plan *plan)
{
    char path[64];
    snprintf(path, sizeof path, "channels[%d]", index);
    if (!cJSON_IsObject(ch)) return field_error(ctx, path, "", "must be an object%s", NULL);
    const cJSON *op = cJSON_GetObjectItemCaseSensitive(ch, "op");
    if (!op) return field_error(ctx, path, "op", "missing (ffd, ffd_travel, ffd_keys, ffd_cylinder, ffd_prism, taper, twist, bend, cage, laplacian, arap, transfer or shell)%s", NULL);
    if (!cJSON_IsString(op)) return field_error(ctx, path, "op", "must be a string%s", NULL);
    int k = -1;
    for (int i = 0; i < (int)(sizeof op_names / sizeof op_names[0]); i++)
        if (!strcmp(op_names[i], op->valuestring)) k = i;
    if (k < 0) return field_error(ctx, path, "op", "unknown op \"%s\" (expected ffd, ffd_travel, ffd_keys, ffd_cylinder, ffd_prism, taper, twist, bend, cage, laplacian, arap, transfer or shell)", op->valuestring);
    plan->op = (op_kind)k;
    mk_result r = check_fields(ctx, ch, path, common_fields, op_fields[k]);
    if (r != MK_OK) return r;

    const cJSON *mesh_item = cJSON_GetObjectItemCaseSensitive(ch, "mesh");
    if (mesh_item) {
        if ((r = resolve_mesh(ctx, mesh_item, path, &plan->mesh)) != MK_OK) return r;
    } else if (has_top_mesh) plan->mesh = top_mesh;
    else return field_error(ctx, "mesh", "", "missing (a mesh name or index, at the top or per channel)%s", NULL);
    if ((r = check_mesh(ctx, plan->mesh, path)) != MK_OK) return r;

    const cJSON *name = cJSON_GetObjectItemCaseSensitive(ch, "name");
    if (name && (!cJSON_IsString(name) || !*name->valuestring || strlen(name->valuestring) >= sizeof plan->name))
        return field_error(ctx, path, "name", "must be a non-empty string under 128 bytes%s", NULL);
    if (name) snprintf(plan->name, sizeof plan->name, "%s", name->valuestring);
    else snprintf(plan->name, sizeof plan->name, "%s%d", op_names[k], index);

    /* Twist, bend, Laplacian (with rotations), ARAP and FFD travel are nonlinear in the amplitude: they
     * default to adaptive in-betweens; FFD, taper and cage are linear: one target is exact. */
    int nonlinear = plan->op == OP_TWIST || plan->op == OP_BEND || plan->op == OP_LAPLACIAN || plan->op == OP_ARAP ||
                    plan->op == OP_FFD_TRAVEL;
    plan->inbetween.count = nonlinear ? 0 : 1;
    const cJSON *ib = cJSON_GetObjectItemCaseSensitive(ch, "inbetweens");
    if (ib && plan->op == OP_SHELL)
        return field_error(ctx, path, "inbetweens", "is not used by shell: give at_frames or at_volume_ratios%s", NULL);
    if (ib) {
        if (cJSON_IsString(ib) && !strcmp(ib->valuestring, "auto")) plan->inbetween.count = 0;
        else if (cJSON_IsNumber(ib) && isfinite(ib->valuedouble) && ib->valuedouble == floor(ib->valuedouble) &&
                 ib->valuedouble >= 1 && ib->valuedouble <= (untrusted(ctx) ? 32 : 256))
            plan->inbetween.count = (uint32_t)ib->valuedouble;
        else return field_error(ctx, path, "inbetweens", "must be \"auto\" or an integer in 1..256%s", NULL);
    }
    plan->inbetween.tolerance = 0.001;
    if ((r = get_number(ctx, ch, path, "tolerance", &plan->inbetween.tolerance, 0)) != MK_OK) return r;
    if (!(plan->inbetween.tolerance > 0)) return field_error(ctx, path, "tolerance", "must be > 0%s", NULL);
    plan->inbetween.samples = 100;
    if ((r = get_uint(ctx, ch, path, "samples", &plan->inbetween.samples, 2, untrusted(ctx) ? 200 : 100000)) != MK_OK) return r;
    plan->inbetween.max_targets = untrusted(ctx) ? 32 : 64;
    if ((r = get_uint(ctx, ch, path, "max_targets", &plan->inbetween.max_targets, 1, untrusted(ctx) ? 32 : 256)) != MK_OK) return r;
    double dw = 0;
    if ((r = get_number(ctx, ch, path, "default_weight", &dw, 0)) != MK_OK) return r;
    plan->default_weight = (float)dw;

    switch (plan->op) {
    case OP_TAPER: case OP_TWIST: case OP_BEND: r = parse_barr(ctx, plan, ch, path); break;
    case OP_FFD: r = parse_ffd(ctx, plan, ch, path, NULL); break;
    case OP_FFD_TRAVEL: r = parse_ffd_travel(ctx, plan, ch, path); break;
    case OP_FFD_KEYS: r = parse_ffd_keys(ctx, plan, ch, path); break;
    case OP_FFD_CYLINDER: r = parse_ffd_cylinder(ctx, plan, ch, path); break;
    case OP_FFD_PRISM: r = parse_ffd_prism(ctx, plan, ch, path); break;
    case OP_CAGE: r = parse_cage(ctx, plan, ch, path); break;
    case OP_LAPLACIAN: case OP_ARAP: r = parse_edit(ctx, plan, ch, path); break;
    case OP_TRANSFER: r = parse_transfer(ctx, plan, ch, path); break;
    case OP_SHELL: r = parse_shell(ctx, plan, ch, path); break;
    }
    if (r != MK_OK) return r;
    char *json = cJSON_PrintUnformatted(ch);
    if (!json) return mk_error_oom(ctx->err, "recipe origin");
    plan->origin = mk_arena_strdup(ctx->scratch, json);
    cJSON_free(json);
    if (!plan->origin) return mk_error_oom(ctx->err, "recipe origin");
    return MK_OK;
}

/* A clip named like the channel that plays its weight linearly from 0 to 1 over the duration. */
static mk_result add_travel_clip(recipe_ctx *ctx, const channel_plan *plan, uint32_t channel)
{
    mk_raw_asset *raw = ctx->raw;
    mk_raw_track *track = mk_arena_array(&raw->arena, 1, sizeof *track);
    mk_key *keys = mk_arena_array(&raw->arena, 2, sizeof *keys);
    char *name = mk_arena_strdup(&raw->arena, plan->name);
    mk_raw_clip *clip = track && keys && name ? mk_raw_add_clips(raw, 1) : NULL;
    if (!clip) return mk_error_oom(ctx->err, "travel clip");
    keys[0].time = 0;
    keys[0].value = 0;
    keys[1].time = (float)plan->clip_duration;
    keys[1].value = 1;
    for (int k = 0; k < 2; k++) {
        keys[k].interp = MK_INTERP_LINEAR;
        keys[k].left_weight = keys[k].right_weight = 1.0f / 3;
        keys[k].left_slope = keys[k].right_slope = (float)(1 / plan->clip_duration);
    }
    track->channel = channel;
    track->key_count = 2;
    track->keys = keys;
    clip->name = name;
    clip->start = 0;
    clip->duration = (float)plan->clip_duration;
    clip->track_count = 1;
    clip->tracks = track;
    return MK_OK;
}

/* shell: simulate, pick the target frames, write the log; the channel's weights are frame / last. */
static mk_result bake_shell_run(recipe_ctx *ctx, channel_plan *plan, shell_bake **out, mk_error *err)
{
    const mk_bake_options *o = ctx->options;
    shell_bake *b = mk_arena_alloc(ctx->scratch, sizeof *b);
    if (!b) return mk_error_oom(err, "shell");
    char stage[200];
    snprintf(stage, sizeof stage, "%s: simulating", plan->name);
    mk_result r = shell_bake_prepare(&ctx->raw->meshes[plan->mesh], &plan->shell, plan->shell_region, plan->shell_at,
                                     plan->shell_at_count, plan->shell_at_ratios, ctx->scratch, o ? o->progress : NULL,
                                     o ? o->user : NULL, stage, b, err);
    if (r != MK_OK) return r;
    *out = b;
    plan->inbetween.count = b->keys;
    plan->inbetween.weights = b->weights;
    if (plan->clip_duration < 0) plan->clip_duration = b->last * plan->shell.dt;
    if (plan->shell_log) {
        char full[4096];
        recipe_path(ctx, plan->shell_log, full, sizeof full);
        FILE *f = fopen(full, "w");
        int bad = !f || shell_write_log(f, &b->run) != 0;
        if (f && fclose(f) != 0) bad = 1;
        if (bad) return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "log: cannot write %s", full);
    }
    return MK_OK;
}

static mk_result bake_plan(recipe_ctx *ctx, channel_plan *plan, int index, mk_bake_report *report)
{
    mk_raw_asset *raw = ctx->raw;
    const mk_raw_mesh *mesh = &raw->meshes[plan->mesh];
    const mk_bake_options *o = ctx->options;
    double t0 = bake_now();
    mk_deformer deformer;
    memset(&deformer, 0, sizeof deformer);
    bake_pointwise pw = { mesh, NULL, NULL, ctx->scratch };
    mk_cage_binding *binding = NULL;
    mk_surface_edit *edit = NULL;
    shell_bake *shell = NULL;
    mk_result r = MK_OK;
    mk_error inner;
    char path[64];
    snprintf(path, sizeof path, "channels[%d]", index);
    switch (plan->op) {
    case OP_TAPER: case OP_TWIST: case OP_BEND:
        pw.map = mk_barr_map; pw.user = &plan->barr;
        deformer.eval = bake_pointwise_eval; deformer.user = &pw; deformer.analytic_normals = 1;
        break;
    case OP_FFD: case OP_FFD_KEYS:
        pw.map = mk_ffd_map; pw.user = &plan->ffd;
        deformer.eval = bake_pointwise_eval; deformer.user = &pw; deformer.analytic_normals = 1;
        break;
    case OP_FFD_CYLINDER: case OP_FFD_PRISM:
        pw.user = plan;
        deformer.eval = extended_ffd_eval; deformer.user = &pw;
        break;
    case OP_FFD_TRAVEL:
        pw.map = mk_ffd_travel_map; pw.user = &plan->travel;
        deformer.eval = bake_pointwise_eval; deformer.user = &pw; deformer.analytic_normals = 1;
        break;
    case OP_CAGE:
        if (o && o->progress) o->progress(o->user, "binding cage", 0);
        r = mk_cage_bind(mesh, &plan->cage, &raw->arena.allocator, &binding, &inner);
        deformer.eval = mk_cage_eval; deformer.user = binding;
        break;
    case OP_LAPLACIAN: case OP_ARAP:
        if (o && o->progress) o->progress(o->user, "factoring", 0);
        r = mk_surface_edit_create(mesh, &plan->edit, &raw->arena.allocator, &edit, &inner);
        deformer.eval = mk_surface_edit_eval; deformer.user = edit; deformer.expensive = 1;
        break;
    case OP_TRANSFER:  /* bake_transfer */
        return mk_error_set(ctx->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%s: transfer is not a deformer", path);
    case OP_SHELL:
        r = bake_shell_run(ctx, plan, &shell, &inner);
        deformer.eval = shell_bake_eval; deformer.user = shell;
        break;
    }
    if (r != MK_OK) return mk_error_set(ctx->err, inner.code, inner.offset, "%s (%s): %s", path, op_names[plan->op], inner.message);
    mk_inbetween_result res;
    memset(&res, 0, sizeof res);
    r = mk_bake_channel(raw, plan->mesh, plan->name, plan->origin, &deformer, &plan->inbetween,
                        o ? o->progress : NULL, o ? o->user : NULL, &res, &inner);
    mk_bake_channel_report cr;
    memset(&cr, 0, sizeof cr);
    if (edit) {
        mk_solver_stats st;
        mk_surface_edit_stats(edit, &st);
        cr.factorizations = st.factorizations;
        cr.factor_seconds = st.factor_seconds;
        cr.solve_seconds = st.solve_seconds;
        cr.solves = st.solves;
        cr.iterations = st.iterations;
        cr.max_iterations = st.max_iterations;
        cr.unconverged = st.unconverged;
        cr.energy = st.energy;
        cr.start_energy = st.start_energy;
        mk_surface_edit_destroy(edit);
    }
    if (binding) mk_cage_unbind(binding);
    if (r != MK_OK) return mk_error_set(ctx->err, inner.code, inner.offset, "%s (%s): %s", path, op_names[plan->op], inner.message);
    raw->channels[raw->channel_count - 1].default_weight = plan->default_weight;
    if (plan->clip_duration > 0 && (r = add_travel_clip(ctx, plan, raw->channel_count - 1)) != MK_OK) return r;
    if (res.inverted_vertices)
        mk_raw_warn(raw, "channel \"%s\": %u vertices where the deformation folds (det J <= 0); "
                    "their normals come from the deformed surface", plan->name, res.inverted_vertices);
    cr.name = plan->name;
    cr.op = op_names[plan->op];
    cr.mesh = plan->mesh;
    cr.targets = res.targets;
    cr.evaluations = res.evaluations;
    cr.max_error = res.max_error;
    cr.error_measured_on_grid = res.error_on_grid;
    cr.moved_vertices = res.moved_vertices;
    cr.inverted_vertices = res.inverted_vertices;
    cr.error_curve = res.error_curve;
    cr.curve_samples = res.curve_samples;
    cr.key_weights = res.key_weights;
    cr.tolerance = res.tolerance;
    if (shell) {  /* the volume curve outlives the scratch the run lives in */
        double *ratios = mk_arena_array(&raw->arena, (size_t)shell->run.frames + 1, sizeof(double));
        uint32_t *keys = mk_arena_array(&raw->arena, shell->keys ? shell->keys : 1, sizeof(uint32_t));
        if (!ratios || !keys) return mk_error_oom(ctx->err, "shell volume curve");
        for (uint32_t f = 0; f <= shell->run.frames; f++) ratios[f] = shell->run.stats[f].volume_ratio;
        memcpy(keys, shell->frames, shell->keys * sizeof(uint32_t));
        cr.volume_ratios = ratios;
        cr.volume_frames = shell->run.frames + 1;
        cr.frame_seconds = plan->shell.dt;
        cr.key_frames = keys;
    }
    cr.seconds = bake_now() - t0;
    if (o && o->channel_done) o->channel_done(o->user, &cr);
    report->channels_added++;
    report->targets_added += res.targets;
    if (res.max_error > report->max_error) report->max_error = res.max_error;
    return MK_OK;
}

/* ffd_keys: one channel per key (the lattice at that key, one exact target each: FFD is linear
 * in the control points) and a clip that cross-fades consecutive keys linearly, so the clip
 * plays the lattice with its control points interpolated linearly between keys. */
static mk_result bake_ffd_keys(recipe_ctx *ctx, channel_plan *plan, int index, mk_bake_report *report)
{
    mk_raw_asset *raw = ctx->raw;
    uint32_t n = plan->key_count;
    char base[sizeof plan->name];
    memcpy(base, plan->name, sizeof base);
    uint32_t *channel = mk_arena_array(ctx->scratch, n, sizeof(uint32_t));
    if (!channel) return mk_error_oom(ctx->err, "lattice keys");
    size_t values = 3 * (size_t)plan->ffd.dims[0] * plan->ffd.dims[1] * plan->ffd.dims[2];
    uint32_t track_count = 0;
    for (uint32_t k = 0; k < n; k++) {
        /* A key with the lattice at rest contributes zero displacement: no channel, no track. */
        uint32_t q = 0;
        while (q < values && plan->key_displacements[k][q] == 0) q++;
        channel[k] = UINT32_MAX;
        if (q == values) continue;
        snprintf(plan->name, sizeof plan->name, "%.119s.key%u", base, k % 1000);
        plan->ffd.displacements = plan->key_displacements[k];
        mk_result r = bake_plan(ctx, plan, index, report);
        if (r != MK_OK) return r;
        channel[k] = raw->channel_count - 1;
        track_count++;
    }
    memcpy(plan->name, base, sizeof base);
    if (track_count == 0)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "channels[%d].keys: no key moves the lattice", index);
    mk_raw_track *tracks = mk_arena_array(&raw->arena, n, sizeof *tracks);
    mk_key *keys = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof *keys);
    char *name = mk_arena_strdup(&raw->arena, base);
    mk_raw_clip *clip = tracks && keys && name ? mk_raw_add_clips(raw, 1) : NULL;
    if (!clip) return mk_error_oom(ctx->err, "lattice key clip");
    const double *t = plan->key_times;
    for (uint32_t k = 0, track = 0; k < n; k++) {
        if (channel[k] == UINT32_MAX) continue;
        /* Hat function: 0 at the previous key, 1 at this one, 0 at the next (held outside). */
        mk_key *kk = keys + 3 * (size_t)k;
        uint32_t m = 0;
        if (k > 0) kk[m++] = (mk_key){ .time = (float)t[k - 1], .value = 0 };
        kk[m++] = (mk_key){ .time = (float)t[k], .value = 1 };
        if (k + 1 < n) kk[m++] = (mk_key){ .time = (float)t[k + 1], .value = 0 };
        for (uint32_t i = 0; i < m; i++) {
            kk[i].interp = MK_INTERP_LINEAR;
            kk[i].left_weight = kk[i].right_weight = 1.0f / 3;
        }
        tracks[track++] = (mk_raw_track){ .channel = channel[k], .key_count = m, .keys = kk };
    }
    clip->name = name;
    clip->start = 0;
    clip->duration = (float)t[n - 1];
    clip->track_count = track_count;
    clip->tracks = tracks;
    return MK_OK;
}

/* transfer: one channel per source channel, all from one factorization. */
static mk_result bake_transfer(recipe_ctx *ctx, channel_plan *plan, int index, mk_bake_report *report)
{
    mk_raw_asset *raw = ctx->raw;
    const mk_bake_options *o = ctx->options;
    const mk_raw_mesh *smesh = &plan->source->meshes[plan->source_mesh];
    double t0 = bake_now();
    if (o && o->progress) o->progress(o->user, "transfer: matching triangles", 0);
    mk_transfer_params tp = { smesh, &raw->meshes[plan->mesh], plan->marker_count,
                              (const uint32_t (*)[2])plan->markers };
    mk_transfer *x = NULL;
    mk_error inner;
    mk_result r = mk_transfer_create(&tp, &raw->arena.allocator, &x, &inner);
    uint32_t solves_before = 0;
    double solve_seconds_before = 0;
    for (uint32_t k = 0; r == MK_OK && k < plan->source_channel_count; k++) {
        const mk_raw_channel *sc = &plan->source->channels[plan->source_channels[k]];
        snprintf(plan->name, sizeof plan->name, "%s%s", plan->prefix, sc->name ? sc->name : "");
        if (o && o->progress) o->progress(o->user, plan->name, (double)k / plan->source_channel_count);
        uint32_t moved = 0;
        r = mk_transfer_channel(raw, plan->mesh, plan->name, plan->origin, x, smesh, sc, &moved, &inner);
        if (r != MK_OK) break;
        if (plan->has_default_weight) raw->channels[raw->channel_count - 1].default_weight = plan->default_weight;
        mk_transfer_stats st;
        mk_transfer_stats_get(x, &st);
        mk_bake_channel_report cr;
        memset(&cr, 0, sizeof cr);
        cr.name = plan->name;
        cr.op = op_names[plan->op];
        cr.mesh = plan->mesh;
        cr.targets = sc->target_count;
        cr.evaluations = sc->target_count;
        cr.moved_vertices = moved;
        /* the one factorization is reported with the first channel, each channel its own solves */
        cr.factorizations = k == 0;
        cr.factor_seconds = k == 0 ? st.factor_seconds : 0;
        cr.solves = st.solves - solves_before;
        cr.solve_seconds = st.solve_seconds - solve_seconds_before;
        solves_before = st.solves;
        solve_seconds_before = st.solve_seconds;
        cr.seconds = bake_now() - t0;
        t0 = bake_now();
        if (o && o->channel_done) o->channel_done(o->user, &cr);
        report->channels_added++;
        report->targets_added += sc->target_count;
    }
    if (r == MK_OK) {
        mk_transfer_stats st;
        mk_transfer_stats_get(x, &st);
        if (st.flipped || st.unmatched)
            mk_raw_warn(raw, "transfer channels[%d]: %u target triangles matched a farther source triangle facing "
                        "their way, %u matched none (they follow their neighbors)", index, st.flipped, st.unmatched);
    }
    mk_transfer_destroy(x);
    if (r != MK_OK)
        return mk_error_set(ctx->err, inner.code, inner.offset, "channels[%d] (transfer): %s", index, inner.message);
    return MK_OK;
}

static mk_result run_recipe(recipe_ctx *ctx, const char *json, size_t size, mk_bake_report *report)
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(json, size, &end, 0);
    if (!root) {
        uint64_t off = end && end >= json ? (uint64_t)(end - json) : UINT64_MAX;
        return mk_error_set(ctx->err, MK_ERROR_PARSE, off, "recipe: JSON syntax error at byte %llu",
                            (unsigned long long)off);
    }
    mk_result r = MK_OK;
    channel_plan *plans = NULL;
    int count = 0;
    static const char *const top_fields[] = { "mesh", "channels", NULL };
    if (!cJSON_IsObject(root)) { r = field_error(ctx, "recipe", "", "must be a JSON object%s", NULL); goto done; }
    if ((r = check_fields(ctx, root, "recipe", top_fields, NULL)) != MK_OK) goto done;
    const cJSON *mesh_item = cJSON_GetObjectItemCaseSensitive(root, "mesh");
    uint32_t top_mesh = 0;
    if (mesh_item && (r = resolve_mesh(ctx, mesh_item, "recipe", &top_mesh)) != MK_OK) goto done;
    const cJSON *channels = cJSON_GetObjectItemCaseSensitive(root, "channels");
    if (!channels) { r = field_error(ctx, "channels", "", "missing (an array of channel recipes)%s", NULL); goto done; }
    if (!cJSON_IsArray(channels) || cJSON_GetArraySize(channels) == 0) {
        r = field_error(ctx, "channels", "", "must be a non-empty array%s", NULL);
        goto done;
    }
    count = cJSON_GetArraySize(channels);
    plans = mk_arena_array(ctx->scratch, (size_t)count, sizeof *plans);
    if (!plans) { r = mk_error_oom(ctx->err, "recipe"); goto done; }
    int i = 0;
    for (const cJSON *ch = channels->child; ch; ch = ch->next, i++)
        if ((r = parse_channel(ctx, ch, i, mesh_item != NULL, top_mesh, &plans[i])) != MK_OK) goto done;
    for (i = 0; i < count; i++)
        if ((r = plans[i].op == OP_FFD_KEYS ? bake_ffd_keys(ctx, &plans[i], i, report)
                 : plans[i].op == OP_TRANSFER ? bake_transfer(ctx, &plans[i], i, report)
                                              : bake_plan(ctx, &plans[i], i, report)) != MK_OK) goto done;
done:
    for (i = 0; plans && i < count; i++)
        if (plans[i].source) mk_raw_free(plans[i].source);
    cJSON_Delete(root);
    return r;
}

mk_result mk_bake_recipe(mk_raw_asset *raw, const char *recipe_json, size_t recipe_size,
                         const mk_bake_options *options, mk_bake_report *report, mk_error *err)
{
    mk_bake_report local;
    if (!report) report = &local;
    memset(report, 0, sizeof *report);
    if (!raw || !recipe_json)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_bake_recipe: raw and recipe are required");
    mk_arena scratch;
    mk_arena_init(&scratch, &raw->arena.allocator);
    recipe_ctx ctx = { raw, &scratch, options, err };
    mk_error local_err;
    if (!err) ctx.err = &local_err;
    uint32_t old_channels = raw->channel_count;
    uint32_t old_warnings = raw->warning_count;
    uint32_t old_clips = raw->clip_count;
    mk_result r = run_recipe(&ctx, recipe_json, recipe_size, report);
    if (r == MK_OK) r = mk_raw_group_channels(raw, ctx.err);
    if (r != MK_OK) {
        raw->channel_count = old_channels;
        raw->warning_count = old_warnings;  /* drop warnings of the abandoned bake */
        raw->clip_count = old_clips;        /* and travel clips */
        memset(report, 0, sizeof *report);
    }
    mk_arena_free_all(&scratch);
    return r;
}

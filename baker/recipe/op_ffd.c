/* SPDX-License-Identifier: MIT */
/* Recipe ops on a box lattice (ffd.h, ffd_travel.h): ffd (Sederberg & Parry's free-form
 * deformation), ffd_travel (the mesh carried through a deformed lattice, with its clip) and
 * ffd_keys (the lattice keyed over time: one channel per key and a clip cross-fading them). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "ffd.h"
#include "ffd_travel.h"
#include "fields.h"
#include "lattice_moves.h"

typedef struct ffd_state {
    mk_ffd_lattice ffd;
    double *rest;                 /* rest control points */
    mk_ffd_travel travel;         /* ffd_travel */
    uint32_t key_count;           /* ffd_keys: the keys' times and displacements */
    double *key_times;
    double **key_displacements;
} ffd_state;

/* The box lattice of every ffd op: dims, basis, origin and axes or padding, moves. bounds: the
 * box the default lattice encloses (min, max), NULL = the mesh's bounding box. */
static mk_result parse_lattice(recipe_ctx *ctx, const recipe_channel *plan, ffd_state *s, const cJSON *ch,
                               const char *path, const double (*bounds)[3])
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_ffd_lattice *f = &s->ffd;
    memset(f, 0, sizeof *f);
    f->dims[0] = f->dims[1] = f->dims[2] = 4;
    const cJSON *dims = cJSON_GetObjectItemCaseSensitive(ch, "dims");
    if (dims) {
        if (!cJSON_IsArray(dims) || cJSON_GetArraySize(dims) != 3)
            return recipe_field_error(ctx, path, "dims", "must be [l, m, n] control points per axis%s", NULL);
        int a = 0;
        for (const cJSON *e = dims->child; e; e = e->next, a++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < 2 || v > (recipe_untrusted(ctx) ? 8 : 64))
                return recipe_field_error(ctx, path, "dims", "each entry must be an integer in 2..64 (8 when untrusted)%s", NULL);
            f->dims[a] = (uint32_t)v;
        }
    }
    const cJSON *basis = cJSON_GetObjectItemCaseSensitive(ch, "basis");
    if (basis) {
        if (cJSON_IsString(basis) && !strcmp(basis->valuestring, "bernstein")) f->basis = MK_FFD_BERNSTEIN;
        else if (cJSON_IsString(basis) && !strcmp(basis->valuestring, "bspline")) f->basis = MK_FFD_BSPLINE;
        else return recipe_field_error(ctx, path, "basis", "must be \"bernstein\" or \"bspline\"%s", NULL);
    }
    const cJSON *axes = cJSON_GetObjectItemCaseSensitive(ch, "axes");
    int has_origin = cJSON_HasObjectItem(ch, "origin");
    if ((axes != NULL) != has_origin)
        return recipe_field_error(ctx, path, axes ? "origin" : "axes", "missing (origin and axes go together)%s", NULL);
    if (axes) {
        if (recipe_get_vec3(ctx, ch, path, "origin", f->origin) < 0) return ctx->err->code;
        if (!cJSON_IsArray(axes) || cJSON_GetArraySize(axes) != 3)
            return recipe_field_error(ctx, path, "axes", "must be [S, T, U], three vectors%s", NULL);
        int a = 0;
        for (const cJSON *e = axes->child; e; e = e->next, a++)
            if (recipe_vec3_item(ctx, e, path, "axes", f->axes[a]) != MK_OK) return ctx->err->code;
    } else {
        double padding = 0.01, bmin[3], bmax[3], diag;
        mk_result r = recipe_get_number(ctx, ch, path, "padding", &padding, 0);
        if (r != MK_OK) return r;
        if (padding < 0) return recipe_field_error(ctx, path, "padding", "must be >= 0%s", NULL);
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
    double *displacements = mk_arena_array(ctx->scratch, 3 * count, sizeof(double));
    double *current = mk_arena_array(ctx->scratch, 3 * count, sizeof(double));
    s->rest = mk_arena_array(ctx->scratch, 3 * count, sizeof(double));
    if (!displacements || !current || !s->rest) return mk_error_oom(ctx->err, "lattice");
    for (uint32_t k = 0; k < f->dims[2]; k++)
        for (uint32_t j = 0; j < f->dims[1]; j++)
            for (uint32_t i = 0; i < f->dims[0]; i++)
                mk_ffd_control_point(f, i, j, k, s->rest + 3 * (i + f->dims[0] * ((size_t)j + f->dims[1] * k)));
    mk_error inner;
    if (mk_ffd_prepare(f, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    mk_result r = recipe_lattice_moves(ctx, f->dims, NULL, ch, path, "moves", s->rest, current, displacements);
    if (r != MK_OK) return r;
    f->displacements = displacements;
    if (mk_ffd_prepare(f, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    return MK_OK;
}
static mk_result parse_ffd(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    ffd_state *s = recipe_state_new(ctx, plan, sizeof *s);
    if (!s) return mk_error_oom(ctx->err, "lattice");
    return parse_lattice(ctx, plan, s, ch, path, NULL);
}

/* ffd_travel: the travel (a rigid motion), a lattice around the swept mesh, the clip. */
static mk_result parse_ffd_travel(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    static const char *const travel_fields[] = { "translate", "rotate", NULL };
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    ffd_state *s = recipe_state_new(ctx, plan, sizeof *s);
    if (!s) return mk_error_oom(ctx->err, "lattice");
    mk_ffd_travel *t = &s->travel;
    char tpath[96];
    snprintf(tpath, sizeof tpath, "%s.travel", path);
    const cJSON *travel = cJSON_GetObjectItemCaseSensitive(ch, "travel");
    if (!travel) return recipe_field_error(ctx, path, "travel", "missing (translate and/or rotate: the mesh's path through the lattice)%s", NULL);
    if (!cJSON_IsObject(travel)) return recipe_field_error(ctx, path, "travel", "must be an object {translate, rotate}%s", NULL);
    mk_result r = recipe_check_fields(ctx, travel, tpath, travel_fields, NULL);
    if (r != MK_OK) return r;
    double bmin[3], bmax[3], diag, centre[3];
    bake_bounds(mesh, bmin, bmax, &diag);
    for (int c = 0; c < 3; c++) centre[c] = 0.5 * (bmin[c] + bmax[c]);
    if (recipe_get_vec3(ctx, travel, tpath, "translate", t->translate) < 0) return ctx->err->code;
    if ((r = recipe_rotate(ctx, travel, tpath, t->axis, &t->angle, t->pivot, centre)) != MK_OK) return r;
    if (vec3_length(t->translate) == 0 && t->angle == 0)
        return recipe_field_error(ctx, tpath, "", "moves nothing: give a nonzero translate or rotate%s", NULL);
    plan->clip_duration = 0;
    if ((r = recipe_get_number(ctx, ch, path, "duration", &plan->clip_duration, 0)) != MK_OK) return r;
    if (cJSON_HasObjectItem(ch, "duration") && !(plan->clip_duration > 0))
        return recipe_field_error(ctx, path, "duration", "must be > 0 seconds%s", NULL);
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
    if ((r = parse_lattice(ctx, plan, s, ch, path, (const double (*)[3])bounds)) != MK_OK) return r;
    t->lattice = &s->ffd;
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
        return recipe_field_error(ctx, path, "moves", "%s", msg);
    }
    return MK_OK;
}

/* ffd_keys: the lattice, then per key its time and its own moves from the rest lattice. */
static mk_result parse_ffd_keys(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    static const char *const key_fields[] = { "time", "moves", NULL };
    ffd_state *s = recipe_state_new(ctx, plan, sizeof *s);
    if (!s) return mk_error_oom(ctx->err, "lattice");
    mk_result r = parse_lattice(ctx, plan, s, ch, path, NULL);
    if (r != MK_OK) return r;
    if (strlen(plan->name) + 8 >= sizeof plan->name)
        return recipe_field_error(ctx, path, "name", "must be under 120 bytes for ffd_keys (channels are named NAME.keyK)%s", NULL);
    const cJSON *keys = cJSON_GetObjectItemCaseSensitive(ch, "keys");
    if (!keys) return recipe_field_error(ctx, path, "keys", "missing (an array of {time, moves})%s", NULL);
    int count = cJSON_IsArray(keys) ? cJSON_GetArraySize(keys) : 0;
    if (count < 1 || count > (recipe_untrusted(ctx) ? 32 : 256))
        return recipe_field_error(ctx, path, "keys", "must be an array of 1..256 keys {time, moves} (32 when untrusted)%s", NULL);
    const mk_ffd_lattice *f = &s->ffd;
    size_t points = (size_t)f->dims[0] * f->dims[1] * f->dims[2];
    s->key_count = (uint32_t)count;
    s->key_times = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double));
    s->key_displacements = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double *));
    double *current = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    if (!s->key_times || !s->key_displacements || !current) return mk_error_oom(ctx->err, "lattice keys");
    int k = 0;
    for (const cJSON *key = keys->child; key; key = key->next, k++) {
        char kpath[96];
        snprintf(kpath, sizeof kpath, "%s.keys[%d]", path, k);
        if (!cJSON_IsObject(key)) return recipe_field_error(ctx, kpath, "", "must be an object {time, moves}%s", NULL);
        if ((r = recipe_check_fields(ctx, key, kpath, key_fields, NULL)) != MK_OK) return r;
        if ((r = recipe_get_number(ctx, key, kpath, "time", &s->key_times[k], 1)) != MK_OK) return r;
        if (s->key_times[k] < 0) return recipe_field_error(ctx, kpath, "time", "must be >= 0 seconds%s", NULL);
        if (k > 0 && !(s->key_times[k] > s->key_times[k - 1]))
            return recipe_field_error(ctx, kpath, "time", "must be later than the previous key's%s", NULL);
        s->key_displacements[k] = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
        if (!s->key_displacements[k]) return mk_error_oom(ctx->err, "lattice keys");
        if ((r = recipe_lattice_moves(ctx, f->dims, NULL, key, kpath, "moves", s->rest, current, s->key_displacements[k])) != MK_OK)
            return r;
    }
    return MK_OK;
}
/* ffd_keys: one channel per key (the lattice at that key, one exact target each: FFD is linear
 * in the control points) and a clip that cross-fades consecutive keys linearly, so the clip
 * plays the lattice with its control points interpolated linearly between keys. */
static mk_result bake_ffd_keys(recipe_ctx *ctx, recipe_channel *plan, int index, mk_bake_report *report)
{
    mk_raw_asset *raw = ctx->raw;
    ffd_state *s = plan->state;
    uint32_t n = s->key_count;
    char base[sizeof plan->name];
    memcpy(base, plan->name, sizeof base);
    uint32_t *channel = mk_arena_array(ctx->scratch, n, sizeof(uint32_t));
    if (!channel) return mk_error_oom(ctx->err, "lattice keys");
    size_t values = 3 * (size_t)s->ffd.dims[0] * s->ffd.dims[1] * s->ffd.dims[2];
    uint32_t track_count = 0;
    for (uint32_t k = 0; k < n; k++) {
        /* A key with the lattice at rest contributes zero displacement: no channel, no track. */
        uint32_t q = 0;
        while (q < values && s->key_displacements[k][q] == 0) q++;
        channel[k] = UINT32_MAX;
        if (q == values) continue;
        snprintf(plan->name, sizeof plan->name, "%.119s.key%u", base, k % 1000);
        s->ffd.displacements = s->key_displacements[k];
        mk_result r = recipe_bake_deformer(ctx, plan, index, report);
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
    const double *t = s->key_times;
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

static mk_result ffd_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    (void)ctx; (void)err;
    ffd_state *s = plan->state;
    out->pointwise.map = mk_ffd_map;
    out->pointwise.user = &s->ffd;
    out->deformer.analytic_normals = 1;
    return MK_OK;
}

static mk_result travel_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    (void)ctx; (void)err;
    ffd_state *s = plan->state;
    out->pointwise.map = mk_ffd_travel_map;
    out->pointwise.user = &s->travel;
    out->deformer.analytic_normals = 1;
    return MK_OK;
}

static const char *const ffd_fields[] = { "dims", "basis", "origin", "axes", "padding", "moves", NULL };
static const char *const ffd_travel_fields[] = { "dims", "basis", "origin", "axes", "padding", "moves", "travel",
                                                 "duration", NULL };
static const char *const ffd_keys_fields[] = { "dims", "basis", "origin", "axes", "padding", "keys", NULL };

/* FFD is linear in the amplitude: one target is exact; the travel's rigid motion is not. */
const recipe_op recipe_op_ffd = { .name = "ffd", .fields = ffd_fields, .parse = parse_ffd, .deformer = ffd_deformer };
const recipe_op recipe_op_ffd_travel = { .name = "ffd_travel", .fields = ffd_travel_fields, .nonlinear = 1,
                                         .parse = parse_ffd_travel, .deformer = travel_deformer };
const recipe_op recipe_op_ffd_keys = { .name = "ffd_keys", .fields = ffd_keys_fields, .parse = parse_ffd_keys,
                                       .deformer = ffd_deformer, .bake = bake_ffd_keys };

/* SPDX-License-Identifier: MIT */
/* Recipe ops on lattices around an axis: ffd_cylinder (a cylindrical lattice, ffd_cylinder.h)
 * and ffd_prism (a prism of polygonal rings, ffd_prism.h). Every vertex's lattice coordinates
 * are found once, at parse time. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "ffd_cylinder.h"
#include "ffd_prism.h"
#include "fields.h"
#include "lattice_moves.h"

#define PI 3.14159265358979323846

typedef struct axial_state {
    int prism_shaped;             /* 1: ffd_prism, 0: ffd_cylinder */
    mk_cylinder_lattice cylinder;
    mk_prism_lattice prism;
    double *rest;                 /* rest control points */
    double *coordinates;          /* per vertex: cylinder (s, t, u), prism (wedge, l1, l2, u) */
} axial_state;

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
    mk_result r = recipe_axis(ctx, ch, path, axis);
    if (r != MK_OK) return r;
    vec3_normalize(axis);
    bake_bounds(mesh, bmin, bmax, &diag);
    double center[3];
    for (int k = 0; k < 3; k++) center[k] = 0.5 * (bmin[k] + bmax[k]);
    if (recipe_get_vec3(ctx, ch, path, "center", center) < 0) return ctx->err->code;
    if ((r = recipe_get_number(ctx, ch, path, "padding", &padding, 0)) != MK_OK) return r;
    if (padding < 0) return recipe_field_error(ctx, path, "padding", "must be >= 0%s", NULL);
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
            return recipe_field_error(ctx, path, "range", "must be [min, max] along the axis (p . axis, mesh units)%s", NULL);
        range[0] = ritem->child->valuedouble;
        range[1] = ritem->child->next->valuedouble;
    }
    if (!(range[1] > range[0])) return recipe_field_error(ctx, path, "range", "must have min < max%s", NULL);
    int least = 0;
    for (int k = 1; k < 3; k++) if (fabs(axis[k]) < fabs(axis[least])) least = k;
    for (int k = 0; k < 3; k++) reference[k] = k == least;
    if (recipe_get_vec3(ctx, ch, path, "reference", reference) < 0) return ctx->err->code;
    for (int k = 0; k < 3; k++) {
        base[k] = center[k] + (range[0] - vec3_dot(center, axis)) * axis[k];
        axis_out[k] = (range[1] - range[0]) * axis[k];
    }
    return MK_OK;
}

/* ffd_cylinder: the cylindrical lattice around the axis, its moves, every vertex's coordinates. */
static mk_result parse_ffd_cylinder(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    axial_state *s = recipe_state_new(ctx, plan, sizeof *s);
    if (!s) return mk_error_oom(ctx->err, "cylinder lattice");
    mk_cylinder_lattice *c = &s->cylinder;
    c->dims[0] = 3; c->dims[1] = 8; c->dims[2] = 4;
    const cJSON *dims = cJSON_GetObjectItemCaseSensitive(ch, "dims");
    if (dims) {
        static const double least[3] = { 2, 3, 2 };
        if (!cJSON_IsArray(dims) || cJSON_GetArraySize(dims) != 3)
            return recipe_field_error(ctx, path, "dims", "must be [rings, sectors, layers]%s", NULL);
        int a = 0;
        for (const cJSON *e = dims->child; e; e = e->next, a++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < least[a] || v > (recipe_untrusted(ctx) ? 8 : 64))
                return recipe_field_error(ctx, path, "dims", "rings 2..64, sectors 3..64, layers 2..64 (8 when untrusted)%s", NULL);
            c->dims[a] = (uint32_t)v;
        }
    }
    double far, pad;
    mk_result r = parse_axial_lattice(ctx, ch, path, mesh, c->center, c->axis, c->reference, &far, &pad);
    if (r != MK_OK) return r;
    c->outer_radius = (far + pad) / mk_cylinder_ring_ratio(c->dims[1]);
    if ((r = recipe_get_number(ctx, ch, path, "radius", &c->outer_radius, 0)) != MK_OK) return r;
    if ((r = recipe_get_number(ctx, ch, path, "inner_radius", &c->inner_radius, 0)) != MK_OK) return r;
    mk_error inner;
    if (mk_cylinder_prepare(c, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    size_t points = (size_t)c->dims[0] * c->dims[1] * c->dims[2];
    s->rest = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *current = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *displacements = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    s->coordinates = mk_arena_array(ctx->scratch, 3 * (size_t)mesh->vertex_count, sizeof(double));
    if (!s->rest || !current || !displacements || !s->coordinates)
        return mk_error_oom(ctx->err, "cylinder lattice");
    for (uint32_t k = 0; k < c->dims[2]; k++)
        for (uint32_t j = 0; j < c->dims[1]; j++)
            for (uint32_t i = 0; i < c->dims[0]; i++)
                mk_cylinder_control_point(c, i, j, k, s->rest + 3 * (i + c->dims[0] * ((size_t)j + c->dims[1] * k)));
    if ((r = recipe_lattice_moves(ctx, c->dims, NULL, ch, path, "moves", s->rest, current, displacements)) != MK_OK) return r;
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
    if (mk_cylinder_bind(c, mesh, s->coordinates, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s: %s (enlarge radius or range)", path, inner.message);
    return MK_OK;
}

/* ffd_prism: the prism lattice around the axis, its moves, every vertex's wedge and coordinates. */
static mk_result parse_ffd_prism(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    axial_state *s = recipe_state_new(ctx, plan, sizeof *s);
    if (!s) return mk_error_oom(ctx->err, "prism lattice");
    s->prism_shaped = 1;
    mk_prism_lattice *c = &s->prism;
    c->sides = 6; c->degree = 2; c->layers = 4;
    uint32_t most = recipe_untrusted(ctx) ? 8 : 64;
    mk_result r;
    if ((r = recipe_get_uint(ctx, ch, path, "sides", &c->sides, 3, most)) != MK_OK ||
        (r = recipe_get_uint(ctx, ch, path, "degree", &c->degree, 1, recipe_untrusted(ctx) ? 4 : 16)) != MK_OK ||
        (r = recipe_get_uint(ctx, ch, path, "layers", &c->layers, 2, most)) != MK_OK)
        return r;
    const cJSON *section = cJSON_GetObjectItemCaseSensitive(ch, "section");
    if (section) {
        /* An explicit polygon: [[x, y], ...] in the frame of reference and axis x reference. */
        if (cJSON_HasObjectItem(ch, "sides") || cJSON_HasObjectItem(ch, "radius"))
            return recipe_field_error(ctx, path, cJSON_HasObjectItem(ch, "sides") ? "sides" : "radius",
                                      "give either section or sides and radius, not both%s", NULL);
        int count = cJSON_IsArray(section) ? cJSON_GetArraySize(section) : 0;
        if (count < 3 || count > (int)most)
            return recipe_field_error(ctx, path, "section", "must be an array of 3..64 corners [x, y] (8 when untrusted)%s", NULL);
        double *corners = mk_arena_array(ctx->scratch, 2 * (size_t)count, sizeof(double));
        if (!corners) return mk_error_oom(ctx->err, "prism section");
        int w = 0;
        for (const cJSON *e = section->child; e; e = e->next, w++) {
            char field[32];
            snprintf(field, sizeof field, "section[%d]", w);
            if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 2 || !cJSON_IsNumber(e->child) || !cJSON_IsNumber(e->child->next))
                return recipe_field_error(ctx, path, field, "must be a corner [x, y] (mesh units along reference and axis x reference)%s", NULL);
            corners[2 * w] = e->child->valuedouble;
            corners[2 * w + 1] = e->child->next->valuedouble;
            if (!isfinite(corners[2 * w]) || !isfinite(corners[2 * w + 1]))
                return recipe_field_error(ctx, path, field, "holds a value that is not finite%s", NULL);
        }
        c->sides = (uint32_t)count;
        c->section = corners;
    }
    double far, pad;
    if ((r = parse_axial_lattice(ctx, ch, path, mesh, c->center, c->axis, c->reference, &far, &pad)) != MK_OK) return r;
    /* The polygon's sides are cos(pi / sides) of the corner radius from the centre. */
    c->radius = (far + pad) / cos(PI / c->sides);
    if ((r = recipe_get_number(ctx, ch, path, "radius", &c->radius, 0)) != MK_OK) return r;
    mk_error inner;
    if (mk_prism_prepare(c, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    size_t points = mk_prism_point_count(c);
    s->rest = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *current = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    double *displacements = mk_arena_array(ctx->scratch, 3 * points, sizeof(double));
    s->coordinates = mk_arena_array(ctx->scratch, 4 * (size_t)mesh->vertex_count, sizeof(double));
    if (!s->rest || !current || !displacements || !s->coordinates)
        return mk_error_oom(ctx->err, "prism lattice");
    for (uint32_t k = 0; k < c->layers; k++)
        for (uint32_t i = 0; i <= c->degree; i++)
            for (uint32_t j = 0; j < (i ? c->sides * i : 1); j++)
                mk_prism_control_point(c, i, j, k, s->rest + 3 * (size_t)mk_prism_index(c, i, j, k));
    uint32_t dims[3] = { c->degree + 1, 0, c->layers };
    if (cJSON_HasObjectItem(ch, "rest_moves")) {
        /* The rest lattice shaped to the mesh before binding: the regular one moved. */
        if ((r = recipe_lattice_moves(ctx, dims, c, ch, path, "rest_moves", s->rest, current, displacements)) != MK_OK)
            return r;
        memcpy(s->rest, current, 3 * points * sizeof(double));
        c->rest = s->rest;
    }
    if ((r = recipe_lattice_moves(ctx, dims, c, ch, path, "moves", s->rest, current, displacements)) != MK_OK)
        return r;
    c->displacements = displacements;
    if (mk_prism_prepare(c, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.moves/rest_moves: %s", path, inner.message);
    if (mk_prism_bind(c, mesh, s->coordinates, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s: %s (enlarge radius or range)", path, inner.message);
    return MK_OK;
}

/* mk_deformer for ffd_cylinder and ffd_prism: p + a sum w d per vertex, from the coordinates
 * found once at parse time. */
static mk_result extended_ffd_eval(void *user, double amplitude, double *positions, double *normals, double *tangents,
                                   uint32_t *inverted, mk_error *err)
{
    (void)normals; (void)tangents; (void)err;
    const axial_state *s = ((const bake_pointwise *)user)->user;
    const mk_raw_mesh *mesh = ((const bake_pointwise *)user)->mesh;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const float *pf = mesh->positions + 3 * (size_t)v;
        double p[3] = { pf[0], pf[1], pf[2] };
        if (s->prism_shaped)
            mk_prism_eval(&s->prism, amplitude, s->coordinates + 4 * (size_t)v, p, positions + 3 * (size_t)v);
        else
            mk_cylinder_eval(&s->cylinder, amplitude, s->coordinates + 3 * (size_t)v, p,
                             positions + 3 * (size_t)v);
    }
    if (inverted) *inverted = 0;
    return MK_OK;
}

static mk_result axial_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    (void)ctx; (void)err;
    out->pointwise.user = plan->state;
    out->deformer.eval = extended_ffd_eval;
    out->deformer.user = &out->pointwise;
    return MK_OK;
}

static const char *const cylinder_fields[] = { "dims", "axis", "center", "range", "radius", "inner_radius",
                                               "reference", "padding", "moves", NULL };
static const char *const prism_fields[] = { "sides", "section", "degree", "layers", "axis", "center", "range",
                                            "radius", "reference", "padding", "rest_moves", "moves", NULL };

const recipe_op recipe_op_ffd_cylinder = { .name = "ffd_cylinder", .fields = cylinder_fields,
                                           .parse = parse_ffd_cylinder, .deformer = axial_deformer };
const recipe_op recipe_op_ffd_prism = { .name = "ffd_prism", .fields = prism_fields, .parse = parse_ffd_prism,
                                        .deformer = axial_deformer };

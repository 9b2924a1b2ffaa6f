/* SPDX-License-Identifier: MIT */
/* Recipe ops taper, twist and bend: Barr's deformations (barr.h) along an axis. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "barr.h"
#include "fields.h"

#define PI 3.14159265358979323846

static mk_result parse_barr(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_barr *b = recipe_state_new(ctx, plan, sizeof *b);
    if (!b) return mk_error_oom(ctx->err, "barr");
    b->op = (mk_barr_op)plan->op->variant;
    mk_result r = recipe_axis(ctx, ch, path, b->axis);
    if (r != MK_OK) return r;
    double bmin[3], bmax[3], diag;
    bake_bounds(mesh, bmin, bmax, &diag);
    for (int c = 0; c < 3; c++) b->center[c] = 0.5 * (bmin[c] + bmax[c]);
    if (recipe_get_vec3(ctx, ch, path, "center", b->center) < 0) return ctx->err->code;
    double axis_unit[3] = { b->axis[0], b->axis[1], b->axis[2] };
    vec3_normalize(axis_unit);
    const cJSON *range = cJSON_GetObjectItemCaseSensitive(ch, "range");
    if (range) {
        if (!cJSON_IsArray(range) || cJSON_GetArraySize(range) != 2 ||
            !cJSON_IsNumber(range->child) || !cJSON_IsNumber(range->child->next))
            return recipe_field_error(ctx, path, "range", "must be [min, max] along the axis%s", NULL);
        b->range[0] = range->child->valuedouble;
        b->range[1] = range->child->next->valuedouble;
        if (!isfinite(b->range[0]) || !isfinite(b->range[1]))
            return recipe_field_error(ctx, path, "range", "holds a value that is not finite%s", NULL);
        if (!(b->range[1] > b->range[0]))
            return recipe_field_error(ctx, path, "range", "must have min < max%s", NULL);
    } else {
        for (uint32_t v = 0; v < mesh->vertex_count; v++) {
            const float *p = mesh->positions + 3 * (size_t)v;
            double pd[3] = { p[0], p[1], p[2] }, a = vec3_dot(pd, axis_unit);
            if (v == 0 || a < b->range[0]) b->range[0] = a;
            if (v == 0 || a > b->range[1]) b->range[1] = a;
        }
        if (!(b->range[1] > b->range[0]))
            return recipe_field_error(ctx, path, "range", "the mesh has no extent along the axis: give range%s", NULL);
    }
    if (b->op == MK_BARR_TAPER) {
        if ((r = recipe_get_number(ctx, ch, path, "scale", &b->scale, 1)) != MK_OK) return r;
    } else {
        double deg = 0;
        if ((r = recipe_get_number(ctx, ch, path, "angle", &deg, 1)) != MK_OK) return r;
        b->angle = deg * PI / 180;
    }
    if (b->op == MK_BARR_BEND) {
        /* Default bend direction: the coordinate axis after the axis' dominant one. */
        int k = 0;
        for (int c = 1; c < 3; c++) if (fabs(axis_unit[c]) > fabs(axis_unit[k])) k = c;
        b->direction[(k + 1) % 3] = 1;
        if (recipe_get_vec3(ctx, ch, path, "direction", b->direction) < 0) return ctx->err->code;
    }
    mk_error inner;
    if (mk_barr_prepare(b, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.%s", path, inner.message);
    return MK_OK;
}

static mk_result barr_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    (void)ctx; (void)err;
    out->pointwise.map = mk_barr_map;
    out->pointwise.user = plan->state;
    out->deformer.analytic_normals = 1;
    return MK_OK;
}

static const char *const taper_fields[] = { "axis", "center", "range", "scale", NULL };
static const char *const twist_fields[] = { "axis", "center", "range", "angle", NULL };
static const char *const bend_fields[] = { "axis", "center", "range", "angle", "direction", NULL };

/* Twist and bend are nonlinear in the amplitude: adaptive in-betweens by default; taper's
 * scale is linear: one target is exact. */
const recipe_op recipe_op_taper = { .name = "taper", .fields = taper_fields, .variant = MK_BARR_TAPER,
                                    .parse = parse_barr, .deformer = barr_deformer };
const recipe_op recipe_op_twist = { .name = "twist", .fields = twist_fields, .variant = MK_BARR_TWIST,
                                    .nonlinear = 1, .parse = parse_barr, .deformer = barr_deformer };
const recipe_op recipe_op_bend = { .name = "bend", .fields = bend_fields, .variant = MK_BARR_BEND,
                                   .nonlinear = 1, .parse = parse_barr, .deformer = barr_deformer };

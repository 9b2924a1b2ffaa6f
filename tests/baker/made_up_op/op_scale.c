/* SPDX-License-Identifier: MIT */
/* A made-up recipe op, "scale": the mesh scaled about its bounding box centre, by `factor` at
 * amplitude 1 (p' = c + (1 + a (factor - 1)) (p - c)). It exists to show that an op is one file
 * and one line of the table (test_recipe_op.c); it is not part of the product. */
#include <string.h>
#include "recipe/fields.h"

typedef struct scale_state {
    double centre[3];
    double factor;
} scale_state;

static void scale_map(const void *user, double amplitude, const double p[3], double out[3], double J[9])
{
    const scale_state *s = user;
    double k = 1 + amplitude * (s->factor - 1);
    for (int c = 0; c < 3; c++) out[c] = s->centre[c] + k * (p[c] - s->centre[c]);
    for (int i = 0; i < 9; i++) J[i] = i % 4 == 0 ? k : 0;
}

static mk_result parse_scale(recipe_ctx *ctx, recipe_channel *ch, const cJSON *json, const char *path)
{
    scale_state *s = recipe_state_new(ctx, ch, sizeof *s);
    if (!s) return mk_error_oom(ctx->err, "scale");
    double bmin[3], bmax[3], diag;
    bake_bounds(&ctx->raw->meshes[ch->mesh], bmin, bmax, &diag);
    for (int c = 0; c < 3; c++) s->centre[c] = 0.5 * (bmin[c] + bmax[c]);
    mk_result r = recipe_get_number(ctx, json, path, "factor", &s->factor, 1);
    if (r != MK_OK) return r;
    if (!(s->factor > 0)) return recipe_field_error(ctx, path, "factor", "must be > 0%s", NULL);
    return MK_OK;
}

static mk_result scale_deformer(recipe_ctx *ctx, recipe_channel *ch, recipe_deformer *out, mk_error *err)
{
    (void)ctx; (void)err;
    out->pointwise.map = scale_map;
    out->pointwise.user = ch->state;
    out->deformer.analytic_normals = 1;
    return MK_OK;
}

static const char *const scale_fields[] = { "factor", NULL };

const recipe_op recipe_op_scale = { .name = "scale", .fields = scale_fields, .parse = parse_scale,
                                    .deformer = scale_deformer };

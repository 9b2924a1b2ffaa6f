/* SPDX-License-Identifier: MIT */
/* Recipe op cage: the mesh bound to a rest cage by mean value coordinates and moved by a
 * deformed one (cage_mvc.h), both read from OBJ files. */
#include <stdio.h>
#include <string.h>
#include "cage_mvc.h"
#include "fields.h"
#include "obj.h"

static mk_result load_cage_file(recipe_ctx *ctx, const cJSON *ch, const char *path, const char *field,
                                double **verts, uint32_t *nv, uint32_t **tris, uint32_t *nt)
{
    if (recipe_untrusted(ctx)) return recipe_field_error(ctx, path, field, "files are not read for untrusted recipes%s", NULL);
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(ch, field);
    if (!item) return recipe_field_error(ctx, path, field, "missing (path of an OBJ file)%s", NULL);
    if (!cJSON_IsString(item) || !*item->valuestring)
        return recipe_field_error(ctx, path, field, "must be the path of an OBJ file%s", NULL);
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

static mk_result parse_cage(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    double *rest, *def;
    uint32_t nv, nt, nv2, nt2, *tris, *tris2;
    mk_result r = load_cage_file(ctx, ch, path, "cage", &rest, &nv, &tris, &nt);
    if (r == MK_OK) r = load_cage_file(ctx, ch, path, "deformed_cage", &def, &nv2, &tris2, &nt2);
    if (r != MK_OK) return r;
    if (nv2 != nv)
        return recipe_field_error(ctx, path, "deformed_cage", "has a different vertex count than cage%s", NULL);
    mk_cage *cage = recipe_state_new(ctx, plan, sizeof *cage);
    if (!cage) return mk_error_oom(ctx->err, "cage");
    cage->vertex_count = nv;
    cage->rest = rest;
    cage->deformed = def;
    cage->triangle_count = nt;
    cage->triangles = tris;
    mk_error inner;
    if (mk_cage_validate(cage, &inner) != MK_OK)
        return mk_error_set(ctx->err, MK_ERROR_PARSE, UINT64_MAX, "%s.cage: %s", path, inner.message);
    return MK_OK;
}

static mk_result cage_finish(recipe_ctx *ctx, const recipe_channel *ch, recipe_deformer *d, int baked,
                             mk_bake_channel_report *report)
{
    (void)ctx; (void)ch; (void)baked; (void)report;
    mk_cage_unbind(d->owner);
    return MK_OK;
}

static mk_result cage_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    const mk_bake_options *o = ctx->options;
    if (o && o->progress) o->progress(o->user, "binding cage", 0);
    mk_cage_binding *binding = NULL;
    mk_result r = mk_cage_bind(&ctx->raw->meshes[plan->mesh], plan->state, &ctx->raw->arena.allocator, &binding, err);
    if (r != MK_OK) return r;
    out->deformer.eval = mk_cage_eval;
    out->deformer.user = binding;
    out->owner = binding;
    out->finish = cage_finish;
    return MK_OK;
}

static const char *const cage_fields[] = { "cage", "deformed_cage", NULL };

/* Mean value coordinates are linear in the cage: one target is exact. */
const recipe_op recipe_op_cage = { .name = "cage", .fields = cage_fields, .parse = parse_cage,
                                   .deformer = cage_deformer };

/* SPDX-License-Identifier: MIT */
/* JSON bake recipes (docs/baking.md): the document. Reads the top level and what every channel
 * has (op, name, mesh, in-betweens, tolerance, samples, max_targets, default_weight), hands the
 * rest of each channel to its op (recipe_op.h, the table in recipe_ops.c), then bakes channel by
 * channel.
 *
 * All or nothing: the whole recipe is parsed and checked before any baking starts, and if a
 * channel fails while baking, the channels added so far are dropped again (raw->channel_count
 * is restored), so `morphkit bake` writes nothing on any error. Errors name the field by its
 * JSON path, e.g. "channels[1].handles[0].radius: must be > 0".
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fields.h"

/* Fields accepted by every op. */
static const char *const common_fields[] = { "name", "op", "mesh", "inbetweens", "tolerance",
                                             "samples", "max_targets", "default_weight", NULL };

/* "a, b, ... or z": the ops' names in table order. */
static void op_list(char *out, size_t size)
{
    size_t n = 0;
    out[0] = 0;
    for (unsigned i = 0; i < recipe_op_count && n < size; i++) {
        const char *sep = i == 0 ? "" : i + 1 == recipe_op_count ? " or " : ", ";
        int w = snprintf(out + n, size - n, "%s%s", sep, recipe_ops[i]->name);
        n += w > 0 ? (size_t)w : 0;
    }
}

static mk_result resolve_mesh(recipe_ctx *ctx, const cJSON *item, const char *path, uint32_t *mesh)
{
    return recipe_resolve_mesh(ctx, ctx->raw, item, path, "mesh", mesh);
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
static mk_result parse_channel(recipe_ctx *ctx, const cJSON *ch, int index, int has_top_mesh,
                               uint32_t top_mesh, recipe_channel *plan)
{
    char path[64];
    snprintf(path, sizeof path, "channels[%d]", index);
    if (!cJSON_IsObject(ch)) return recipe_field_error(ctx, path, "", "must be an object%s", NULL);
    char names[400];
    op_list(names, sizeof names);
    const cJSON *op = cJSON_GetObjectItemCaseSensitive(ch, "op");
    if (!op) {
        char usage[420];
        snprintf(usage, sizeof usage, "missing (%s)", names);
        return recipe_field_error(ctx, path, "op", "%s", usage);
    }
    if (!cJSON_IsString(op)) return recipe_field_error(ctx, path, "op", "must be a string%s", NULL);
    plan->op = NULL;
    for (unsigned i = 0; i < recipe_op_count; i++)
        if (!strcmp(recipe_ops[i]->name, op->valuestring)) plan->op = recipe_ops[i];
    if (!plan->op) {
        char usage[700];
        snprintf(usage, sizeof usage, "unknown op \"%s\" (expected %s)", op->valuestring, names);
        return recipe_field_error(ctx, path, "op", "%s", usage);
    }
    mk_result r = recipe_check_fields(ctx, ch, path, common_fields, plan->op->fields);
    if (r != MK_OK) return r;

    const cJSON *mesh_item = cJSON_GetObjectItemCaseSensitive(ch, "mesh");
    if (mesh_item) {
        if ((r = resolve_mesh(ctx, mesh_item, path, &plan->mesh)) != MK_OK) return r;
    } else if (has_top_mesh) plan->mesh = top_mesh;
    else return recipe_field_error(ctx, "mesh", "", "missing (a mesh name or index, at the top or per channel)%s", NULL);
    if ((r = check_mesh(ctx, plan->mesh, path)) != MK_OK) return r;

    const cJSON *name = cJSON_GetObjectItemCaseSensitive(ch, "name");
    if (name && (!cJSON_IsString(name) || !*name->valuestring || strlen(name->valuestring) >= sizeof plan->name))
        return recipe_field_error(ctx, path, "name", "must be a non-empty string under 128 bytes%s", NULL);
    if (name) snprintf(plan->name, sizeof plan->name, "%s", name->valuestring);
    else snprintf(plan->name, sizeof plan->name, "%s%d", plan->op->name, index);

    plan->inbetween.count = plan->op->nonlinear ? 0 : 1;
    const cJSON *ib = cJSON_GetObjectItemCaseSensitive(ch, "inbetweens");
    if (ib && plan->op->refuse_inbetweens) {
        char usage[200];
        snprintf(usage, sizeof usage, "is not used by %s: %s", plan->op->name, plan->op->refuse_inbetweens);
        return recipe_field_error(ctx, path, "inbetweens", "%s", usage);
    }
    if (ib) {
        if (cJSON_IsString(ib) && !strcmp(ib->valuestring, "auto")) plan->inbetween.count = 0;
        else if (cJSON_IsNumber(ib) && isfinite(ib->valuedouble) && ib->valuedouble == floor(ib->valuedouble) &&
                 ib->valuedouble >= 1 && ib->valuedouble <= (recipe_untrusted(ctx) ? 32 : 256))
            plan->inbetween.count = (uint32_t)ib->valuedouble;
        else return recipe_field_error(ctx, path, "inbetweens", "must be \"auto\" or an integer in 1..256%s", NULL);
    }
    plan->inbetween.tolerance = 0.001;
    if ((r = recipe_get_number(ctx, ch, path, "tolerance", &plan->inbetween.tolerance, 0)) != MK_OK) return r;
    if (!(plan->inbetween.tolerance > 0)) return recipe_field_error(ctx, path, "tolerance", "must be > 0%s", NULL);
    plan->inbetween.samples = 100;
    if ((r = recipe_get_uint(ctx, ch, path, "samples", &plan->inbetween.samples, 2, recipe_untrusted(ctx) ? 200 : 100000)) != MK_OK) return r;
    plan->inbetween.max_targets = recipe_untrusted(ctx) ? 32 : 64;
    if ((r = recipe_get_uint(ctx, ch, path, "max_targets", &plan->inbetween.max_targets, 1, recipe_untrusted(ctx) ? 32 : 256)) != MK_OK) return r;
    double dw = 0;
    if ((r = recipe_get_number(ctx, ch, path, "default_weight", &dw, 0)) != MK_OK) return r;
    plan->default_weight = (float)dw;

    r = plan->op->parse(ctx, plan, ch, path);
    if (r != MK_OK) return r;
    char *json = cJSON_PrintUnformatted(ch);
    if (!json) return mk_error_oom(ctx->err, "recipe origin");
    plan->origin = mk_arena_strdup(ctx->scratch, json);
    cJSON_free(json);
    if (!plan->origin) return mk_error_oom(ctx->err, "recipe origin");
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
    recipe_channel *plans = NULL;
    int count = 0;
    static const char *const top_fields[] = { "mesh", "channels", NULL };
    if (!cJSON_IsObject(root)) { r = recipe_field_error(ctx, "recipe", "", "must be a JSON object%s", NULL); goto done; }
    if ((r = recipe_check_fields(ctx, root, "recipe", top_fields, NULL)) != MK_OK) goto done;
    const cJSON *mesh_item = cJSON_GetObjectItemCaseSensitive(root, "mesh");
    uint32_t top_mesh = 0;
    if (mesh_item && (r = resolve_mesh(ctx, mesh_item, "recipe", &top_mesh)) != MK_OK) goto done;
    const cJSON *channels = cJSON_GetObjectItemCaseSensitive(root, "channels");
    if (!channels) { r = recipe_field_error(ctx, "channels", "", "missing (an array of channel recipes)%s", NULL); goto done; }
    if (!cJSON_IsArray(channels)) {
        r = recipe_field_error(ctx, "channels", "", "must be an array%s", NULL);
        goto done;
    }
    count = cJSON_GetArraySize(channels);  /* none: the bake adds nothing (a write-back gives the input back) */
    plans = mk_arena_array(ctx->scratch, count ? (size_t)count : 1, sizeof *plans);
    if (!plans) { r = mk_error_oom(ctx->err, "recipe"); goto done; }
    int i = 0;
    for (const cJSON *ch = channels->child; ch; ch = ch->next, i++)
        if ((r = parse_channel(ctx, ch, i, mesh_item != NULL, top_mesh, &plans[i])) != MK_OK) goto done;
    for (i = 0; i < count; i++)
        if ((r = plans[i].op->bake ? plans[i].op->bake(ctx, &plans[i], i, report)
                                   : recipe_bake_deformer(ctx, &plans[i], i, report)) != MK_OK) goto done;
done:
    for (i = 0; plans && i < count; i++)
        if (plans[i].op && plans[i].op->release) plans[i].op->release(&plans[i]);
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

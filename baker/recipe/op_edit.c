/* SPDX-License-Identifier: MIT */
/* Recipe ops laplacian and arap: surface editing (surface_edit.h) with anchors and handles,
 * each a vertex selection that handles move. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fields.h"
#include "surface_edit.h"

static mk_result parse_edit(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    mk_edit_params *e = recipe_state_new(ctx, plan, sizeof *e);
    if (!e) return mk_error_oom(ctx->err, "edit");
    e->method = (mk_edit_method)plan->op->variant;
    const cJSON *w = cJSON_GetObjectItemCaseSensitive(ch, "weights");
    if (w) {
        if (cJSON_IsString(w) && !strcmp(w->valuestring, "cotangent")) e->weights = MK_WEIGHTS_COTANGENT;
        else if (cJSON_IsString(w) && !strcmp(w->valuestring, "uniform")) e->weights = MK_WEIGHTS_UNIFORM;
        else return recipe_field_error(ctx, path, "weights", "must be \"cotangent\" or \"uniform\"%s", NULL);
    }
    const cJSON *cons = cJSON_GetObjectItemCaseSensitive(ch, "constraints");
    if (cons) {
        if (cJSON_IsString(cons) && !strcmp(cons->valuestring, "hard")) e->soft = 0;
        else if (cJSON_IsString(cons) && !strcmp(cons->valuestring, "soft")) e->soft = 1;
        else return recipe_field_error(ctx, path, "constraints", "must be \"hard\" or \"soft\"%s", NULL);
    }
    e->soft_weight = 100;
    mk_result r = recipe_get_number(ctx, ch, path, "soft_weight", &e->soft_weight, 0);
    if (r != MK_OK) return r;
    if (!(e->soft_weight > 0)) return recipe_field_error(ctx, path, "soft_weight", "must be > 0%s", NULL);
    e->iterations = recipe_untrusted(ctx) ? 50 : 1000;
    if ((r = recipe_get_uint(ctx, ch, path, "iterations", &e->iterations, 1, recipe_untrusted(ctx) ? 50 : 10000)) != MK_OK) return r;
    e->convergence = 1e-6;
    if ((r = recipe_get_number(ctx, ch, path, "convergence", &e->convergence, 0)) != MK_OK) return r;
    if (!(e->convergence >= 0 && e->convergence < 1))
        return recipe_field_error(ctx, path, "convergence", "must be in [0, 1) (0: run all iterations)%s", NULL);
    if (e->convergence == 0) e->convergence = -1;  /* the C API's "all iterations" */
    const cJSON *acc = cJSON_GetObjectItemCaseSensitive(ch, "acceleration");
    if (acc) {
        if (cJSON_IsString(acc) && !strcmp(acc->valuestring, "lbfgs")) e->acceleration = MK_ARAP_LBFGS;
        else if (cJSON_IsString(acc) && !strcmp(acc->valuestring, "anderson")) e->acceleration = MK_ARAP_ANDERSON;
        else if (cJSON_IsString(acc) && !strcmp(acc->valuestring, "none")) e->acceleration = MK_ARAP_PLAIN;
        else return recipe_field_error(ctx, path, "acceleration", "must be \"lbfgs\", \"anderson\" or \"none\"%s", NULL);
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
            if ((r = recipe_selection(ctx, mesh, s, spath, mark, &alist, &acount, &acap, 0)) != MK_OK) return r;
        }
    } else if (anchors) {
        snprintf(spath, sizeof spath, "%s.anchors", path);
        if ((r = recipe_selection(ctx, mesh, anchors, spath, mark, &alist, &acount, &acap, 0)) != MK_OK) return r;
    }
    e->anchor_count = acount;
    e->anchors = alist;
    /* Handles: array of selection + translate/rotate. A vertex belongs to the first handle
     * (or anchor) that selects it. */
    const cJSON *handles = cJSON_GetObjectItemCaseSensitive(ch, "handles");
    if (!handles) return recipe_field_error(ctx, path, "handles", "missing (at least one handle moves the mesh)%s", NULL);
    if (cJSON_IsObject(handles)) {
        /* allow a single handle object */
    } else if (!cJSON_IsArray(handles) || cJSON_GetArraySize(handles) == 0)
        return recipe_field_error(ctx, path, "handles", "must be a non-empty array of handles%s", NULL);
    int hcount = cJSON_IsObject(handles) ? 1 : cJSON_GetArraySize(handles);
    mk_edit_handle *handle_list = mk_arena_array(ctx->scratch, (size_t)hcount, sizeof *handle_list);
    if (!handle_list) return mk_error_oom(ctx->err, "handles");
    for (int h = 0; h < hcount; h++) {
        const cJSON *hd = cJSON_IsObject(handles) ? handles : cJSON_GetArrayItem(handles, h);
        if (cJSON_IsObject(handles)) snprintf(spath, sizeof spath, "%s.handles", path);
        else snprintf(spath, sizeof spath, "%s.handles[%d]", path, h);
        uint32_t *list = NULL, count = 0, cap = 0;
        if ((r = recipe_selection(ctx, mesh, hd, spath, mark, &list, &count, &cap, 1)) != MK_OK) return r;
        mk_edit_handle *eh = &handle_list[h];
        eh->count = count;
        eh->vertices = list;
        double centroid[3] = { 0, 0, 0 };
        for (uint32_t i = 0; i < count; i++)
            for (int c = 0; c < 3; c++) centroid[c] += mesh->positions[3 * (size_t)list[i] + c];
        for (int c = 0; c < 3; c++) centroid[c] /= count;
        if (recipe_get_vec3(ctx, hd, spath, "translate", eh->translate) < 0) return ctx->err->code;
        if ((r = recipe_rotate(ctx, hd, spath, eh->axis, &eh->angle, eh->pivot, centroid)) != MK_OK) return r;
    }
    e->handles = handle_list;
    e->handle_count = (uint32_t)hcount;
    return MK_OK;
}

static mk_result edit_finish(recipe_ctx *ctx, const recipe_channel *ch, recipe_deformer *d, int baked,
                             mk_bake_channel_report *report)
{
    (void)ctx; (void)ch; (void)baked;
    mk_solver_stats st;
    mk_surface_edit_stats(d->owner, &st);
    report->factorizations = st.factorizations;
    report->factor_seconds = st.factor_seconds;
    report->solve_seconds = st.solve_seconds;
    report->solves = st.solves;
    report->iterations = st.iterations;
    report->max_iterations = st.max_iterations;
    report->unconverged = st.unconverged;
    report->energy = st.energy;
    report->start_energy = st.start_energy;
    mk_surface_edit_destroy(d->owner);
    return MK_OK;
}

static mk_result edit_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    const mk_bake_options *o = ctx->options;
    if (o && o->progress) o->progress(o->user, "factoring", 0);
    mk_surface_edit *edit = NULL;
    mk_result r = mk_surface_edit_create(&ctx->raw->meshes[plan->mesh], plan->state, &ctx->raw->arena.allocator,
                                         &edit, err);
    if (r != MK_OK) return r;
    out->deformer.eval = mk_surface_edit_eval;
    out->deformer.user = edit;
    out->deformer.expensive = 1;
    out->owner = edit;
    out->finish = edit_finish;
    return MK_OK;
}

static const char *const laplacian_fields[] = { "weights", "constraints", "soft_weight", "anchors", "handles", NULL };
static const char *const arap_fields[] = { "weights", "constraints", "soft_weight", "anchors", "handles", "iterations",
                                           "convergence", "acceleration", NULL };

/* Rotated handles make the Laplacian nonlinear in the amplitude, ARAP always is: adaptive
 * in-betweens by default. */
const recipe_op recipe_op_laplacian = { .name = "laplacian", .fields = laplacian_fields, .variant = MK_EDIT_LAPLACIAN,
                                        .nonlinear = 1, .parse = parse_edit, .deformer = edit_deformer };
const recipe_op recipe_op_arap = { .name = "arap", .fields = arap_fields, .variant = MK_EDIT_ARAP, .nonlinear = 1,
                                   .parse = parse_edit, .deformer = edit_deformer };

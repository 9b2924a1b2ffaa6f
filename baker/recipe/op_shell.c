/* SPDX-License-Identifier: MIT */
/* Recipe op shell: the thin-shell contraction simulation (shell/shell_channel.h). Its targets
 * are frames of one simulated run, picked by frame or volume ratio; the run's per-frame log can
 * be written as CSV, and its volume curve goes into the channel's report. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "blob_io.h"
#include "fields.h"
#include "shell/shell_channel.h"

typedef struct shell_state {
    shell_params params;
    unsigned char *region;        /* anisotropic region per render vertex, or NULL */
    double *at;                   /* at_frames or at_volume_ratios (0 entries: default) */
    uint32_t at_count;
    int at_ratios;
    const char *log;              /* CSV log path, or NULL */
} shell_state;

static mk_result parse_shell_at(recipe_ctx *ctx, shell_state *st, const cJSON *ch, const char *path)
{
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(ch, "at_frames");
    const cJSON *ratios = cJSON_GetObjectItemCaseSensitive(ch, "at_volume_ratios");
    if (frames && ratios) return recipe_field_error(ctx, path, "at_volume_ratios", "give at_frames or at_volume_ratios, not both%s", NULL);
    const cJSON *list = frames ? frames : ratios;
    const char *field = frames ? "at_frames" : "at_volume_ratios";
    if (!list) return MK_OK;
    int count = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : 0;
    if (count < 1 || count > (recipe_untrusted(ctx) ? 32 : SHELL_MAX_KEYS))
        return recipe_field_error(ctx, path, field, "must be an array of 1..256 numbers (32 when untrusted)%s", NULL);
    st->at = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double));
    if (!st->at) return mk_error_oom(ctx->err, field);
    st->at_ratios = ratios != NULL;
    int k = 0;
    for (const cJSON *e = list->child; e; e = e->next, k++) {
        double v = e->valuedouble;
        char msg[160];
        int ok = cJSON_IsNumber(e) && isfinite(v);
        if (frames) {
            ok = ok && v == floor(v) && v >= 1 && v <= st->params.frames && (k == 0 || v > st->at[k - 1]);
            snprintf(msg, sizeof msg, "entry %d must be a frame in 1..%u (frames), later than the previous entry", k, st->params.frames);
        } else {
            ok = ok && v > 0 && v < 1 && (k == 0 || v < st->at[k - 1]);
            snprintf(msg, sizeof msg, "entry %d must be a volume ratio in (0, 1), smaller than the previous entry", k);
        }
        if (!ok) return recipe_field_error(ctx, path, field, "%s", msg);
        st->at[k] = v;
    }
    st->at_count = (uint32_t)count;
    return MK_OK;
}

static mk_result parse_shell_region(recipe_ctx *ctx, const recipe_channel *plan, shell_state *st, const cJSON *ch, const char *path)
{
    static const char *const aniso_fields[] = { "region", "direction", "energy", "stiffness", "k_A", NULL };
    shell_params *p = &st->params;
    const cJSON *an;
    char apath[96];
    mk_result r = recipe_get_object(ctx, ch, path, "anisotropic", aniso_fields, "{region, direction, energy, stiffness, k_A}",
                             apath, sizeof apath, &an);
    if (r != MK_OK || !an) return r;
    const mk_raw_mesh *mesh = &ctx->raw->meshes[plan->mesh];
    const cJSON *region = cJSON_GetObjectItemCaseSensitive(an, "region");
    if (!region) return recipe_field_error(ctx, apath, "region", "missing (a vertex selection)%s", NULL);
    st->region = mk_arena_array(ctx->scratch, mesh->vertex_count, 1);
    if (!st->region) return mk_error_oom(ctx->err, "shell region");
    uint32_t *list = NULL, count = 0, cap = 0;
    char rpath[128];
    snprintf(rpath, sizeof rpath, "%s.region", apath);
    if ((r = recipe_selection(ctx, mesh, region, rpath, st->region, &list, &count, &cap, 0)) != MK_OK) return r;
    p->aniso_direction[1] = 1;
    int got = recipe_get_vec3(ctx, an, apath, "direction", p->aniso_direction);
    if (got < 0) return ctx->err->code;
    if (!(vec3_normalize(p->aniso_direction) > 0)) return recipe_field_error(ctx, apath, "direction", "is a zero vector%s", NULL);
    const cJSON *energy = cJSON_GetObjectItemCaseSensitive(an, "energy");
    p->aniso_energy = SHELL_ANISO_ARAP;
    if (energy) {
        const char *e = cJSON_IsString(energy) ? energy->valuestring : "";
        if (!strcmp(e, "arap")) p->aniso_energy = SHELL_ANISO_ARAP;
        else if (!strcmp(e, "sqrt")) p->aniso_energy = SHELL_ANISO_SQRT;
        else if (!strcmp(e, "stvk")) p->aniso_energy = SHELL_ANISO_STVK;
        else return recipe_field_error(ctx, apath, "energy", "must be \"arap\", \"sqrt\" or \"stvk\"%s", NULL);
    }
    p->aniso_mu = p->mu;
    if ((r = recipe_get_bounded(ctx, an, apath, "stiffness", &p->aniso_mu, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = recipe_get_number(ctx, an, apath, "k_A", &p->aniso_kA, 0)) != MK_OK) return r;
    return MK_OK;
}

static mk_result parse_shell(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    shell_state *st = recipe_state_new(ctx, plan, sizeof *st);
    if (!st) return mk_error_oom(ctx->err, "shell");
    shell_params *p = &st->params;
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
    if ((r = recipe_get_bounded(ctx, ch, path, "pressure", &p->pressure, 0, 1, INFINITY, "> 0")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "dt", &p->dt, 0, 1, INFINITY, "> 0 seconds")) != MK_OK) return r;
    if ((r = recipe_get_uint(ctx, ch, path, "frames", &p->frames, 1, recipe_untrusted(ctx) ? 200 : 100000)) != MK_OK) return r;
    if ((r = recipe_get_uint(ctx, ch, path, "iterations", &p->iterations, 1, recipe_untrusted(ctx) ? 20 : 1000)) != MK_OK) return r;
    if ((r = recipe_get_uint(ctx, ch, path, "substeps", &p->substeps, 0, recipe_untrusted(ctx) ? SHELL_MAX_SUBSTEPS : 1000)) != MK_OK) return r;
    p->ramp = p->frames * p->dt;
    if ((r = recipe_get_bounded(ctx, ch, path, "ramp", &p->ramp, 0, 0, INFINITY, ">= 0 seconds")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "density", &p->density, 0, 1, INFINITY, "> 0")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "damping", &p->damping, 0, 0, 1, "in [0, 1)")) != MK_OK) return r;
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(ch, "material");
    if (mat) {
        static const char *const names[] = { "stvk", "corotated", "linear", "mooney_rivlin" };
        int k = -1;
        for (int i = 0; i < 4 && cJSON_IsString(mat); i++)
            if (!strcmp(mat->valuestring, names[i])) k = i;
        if (k < 0) return recipe_field_error(ctx, path, "material", "must be \"stvk\", \"corotated\", \"linear\" or \"mooney_rivlin\"%s", NULL);
        p->material = (shell_material)k;
    }
    if ((r = recipe_get_bounded(ctx, ch, path, "mu", &p->mu, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "lambda", &p->lambda, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "kB", &p->kB, 0, 0, INFINITY, ">= 0")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "epsilon", &p->epsilon, 0, 0, 1, "in [0, 1)")) != MK_OK) return r;
    if ((r = recipe_get_bounded(ctx, ch, path, "thickness", &p->thickness, 0, 0, INFINITY, ">= 0 (mesh units)")) != MK_OK) return r;
    if ((r = parse_shell_region(ctx, plan, st, ch, path)) != MK_OK) return r;
    if ((r = parse_shell_at(ctx, st, ch, path)) != MK_OK) return r;
    const cJSON *log = cJSON_GetObjectItemCaseSensitive(ch, "log");
    if (log) {
        if (recipe_untrusted(ctx)) return recipe_field_error(ctx, path, "log", "files are not written for untrusted recipes%s", NULL);
        if (!cJSON_IsString(log) || !*log->valuestring) return recipe_field_error(ctx, path, "log", "must be the path of a CSV file%s", NULL);
        st->log = log->valuestring;
    }
    const cJSON *clip = cJSON_GetObjectItemCaseSensitive(ch, "clip");
    if (clip && !cJSON_IsBool(clip)) return recipe_field_error(ctx, path, "clip", "must be true or false%s", NULL);
    plan->clip_duration = cJSON_IsTrue(clip) ? -1 : 0;  /* the simulated duration, known after the run */
    return MK_OK;
}

/* The run's figures outlive the scratch it lives in: the volume curve and the frames baked. */
static mk_result shell_finish(recipe_ctx *ctx, const recipe_channel *ch, recipe_deformer *d, int baked,
                              mk_bake_channel_report *report)
{
    const shell_bake *shell = d->owner;
    if (!baked) return MK_OK;
    mk_raw_asset *raw = ctx->raw;
    double *ratios = mk_arena_array(&raw->arena, (size_t)shell->run.frames + 1, sizeof(double));
    uint32_t *keys = mk_arena_array(&raw->arena, shell->keys ? shell->keys : 1, sizeof(uint32_t));
    if (!ratios || !keys) return mk_error_oom(ctx->err, "shell volume curve");
    for (uint32_t f = 0; f <= shell->run.frames; f++) ratios[f] = shell->run.stats[f].volume_ratio;
    memcpy(keys, shell->frames, shell->keys * sizeof(uint32_t));
    report->volume_ratios = ratios;
    report->volume_frames = shell->run.frames + 1;
    report->frame_seconds = ((const shell_state *)ch->state)->params.dt;
    report->key_frames = keys;
    return MK_OK;
}

/* Simulates, picks the target frames and writes the log; the channel's weights are frame / last. */
static mk_result shell_deformer(recipe_ctx *ctx, recipe_channel *plan, recipe_deformer *out, mk_error *err)
{
    const mk_bake_options *o = ctx->options;
    shell_state *st = plan->state;
    shell_bake *b = mk_arena_alloc(ctx->scratch, sizeof *b);
    if (!b) return mk_error_oom(err, "shell");
    char stage[200];
    snprintf(stage, sizeof stage, "%s: simulating", plan->name);
    mk_result r = shell_bake_prepare(&ctx->raw->meshes[plan->mesh], &st->params, st->region, st->at, st->at_count,
                                     st->at_ratios, ctx->scratch, o ? o->progress : NULL, o ? o->user : NULL, stage,
                                     b, err);
    if (r != MK_OK) return r;
    plan->inbetween.count = b->keys;
    plan->inbetween.weights = b->weights;
    if (plan->clip_duration < 0) plan->clip_duration = b->last * st->params.dt;
    if (st->log) {
        char full[4096];
        recipe_path(ctx, st->log, full, sizeof full);
        size_t size = 0;
        char *csv = shell_log_csv(&b->run, ctx->scratch, &size);
        if (!csv) return mk_error_oom(err, "shell log");
        mk_error inner;
        if (mk_write_file(full, csv, size, &inner) != MK_OK)
            return mk_error_set(err, inner.code, inner.offset, "log: %s", inner.message);
    }
    out->deformer.eval = shell_bake_eval;
    out->deformer.user = b;
    out->owner = b;
    out->finish = shell_finish;
    return MK_OK;
}

static const char *const shell_fields[] = { "pressure", "ramp", "dt", "frames", "iterations", "substeps", "density",
                                            "damping", "material", "mu", "lambda", "kB", "anisotropic", "thickness",
                                            "epsilon", "at_frames", "at_volume_ratios", "log", "clip", NULL };

const recipe_op recipe_op_shell = { .name = "shell", .fields = shell_fields,
                                    .refuse_inbetweens = "give at_frames or at_volume_ratios",
                                    .parse = parse_shell, .deformer = shell_deformer };

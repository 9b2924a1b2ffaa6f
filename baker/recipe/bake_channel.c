/* SPDX-License-Identifier: MIT */
/* One recipe channel baked from its op's deformer: the in-betweens (inbetween.h), the channel's
 * default weight and clip, and its report. */
#include <string.h>
#include "recipe_op.h"

/* A clip named like the channel that plays its weight linearly from 0 to 1 over the duration. */
static mk_result add_clip(recipe_ctx *ctx, const recipe_channel *plan, uint32_t channel)
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

mk_result recipe_bake_deformer(recipe_ctx *ctx, recipe_channel *plan, int index, mk_bake_report *report)
{
    mk_raw_asset *raw = ctx->raw;
    const mk_bake_options *o = ctx->options;
    double t0 = bake_now();
    recipe_deformer d;
    memset(&d, 0, sizeof d);
    d.pointwise.mesh = &raw->meshes[plan->mesh];
    d.pointwise.scratch = ctx->scratch;
    mk_error inner;
    mk_result r = plan->op->deformer ? plan->op->deformer(ctx, plan, &d, &inner)
                                     : mk_error_set(&inner, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "not a deformer");
    if (r != MK_OK)
        return mk_error_set(ctx->err, inner.code, inner.offset, "channels[%d] (%s): %s", index, plan->op->name, inner.message);
    if (!d.deformer.eval) {  /* a point map */
        d.deformer.eval = bake_pointwise_eval;
        d.deformer.user = &d.pointwise;
    }
    mk_inbetween_result res;
    memset(&res, 0, sizeof res);
    r = mk_bake_channel(raw, plan->mesh, plan->name, plan->origin, &d.deformer, &plan->inbetween,
                        o ? o->progress : NULL, o ? o->user : NULL, &res, &inner);
    mk_bake_channel_report cr;
    memset(&cr, 0, sizeof cr);
    mk_result finished = d.finish ? d.finish(ctx, plan, &d, r == MK_OK, &cr) : MK_OK;
    if (r != MK_OK)
        return mk_error_set(ctx->err, inner.code, inner.offset, "channels[%d] (%s): %s", index, plan->op->name, inner.message);
    if (finished != MK_OK) return finished;
    raw->channels[raw->channel_count - 1].default_weight = plan->default_weight;
    if (plan->clip_duration > 0 && (r = add_clip(ctx, plan, raw->channel_count - 1)) != MK_OK) return r;
    if (res.inverted_vertices)
        mk_raw_warn(raw, "channel \"%s\": %u vertices where the deformation folds (det J <= 0); "
                    "their normals come from the deformed surface", plan->name, res.inverted_vertices);
    cr.name = plan->name;
    cr.op = plan->op->name;
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
    cr.seconds = bake_now() - t0;
    if (o && o->channel_done) o->channel_done(o->user, &cr);
    report->channels_added++;
    report->targets_added += res.targets;
    if (res.max_error > report->max_error) report->max_error = res.max_error;
    return MK_OK;
}

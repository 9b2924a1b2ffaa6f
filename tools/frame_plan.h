/* SPDX-License-Identifier: MIT */
/* Which frames a verb plays, from its --clip, --frames, --times and --weights: times evenly
 * spaced over a clip, listed times, forced weight sets, or the static state of an asset
 * without clips. `frames` and `render` read them the same way. */
#ifndef MK_FRAME_PLAN_H
#define MK_FRAME_PLAN_H

#include "cli_args.h"
#include "frame_write.h"
#include "morphkit.h"

/* One frame: a clip time, or a forced weight set. */
typedef struct cli_frame {
    double time;          /* seconds on the clip's time line (0 without a clip) */
    const char *weights;  /* NAME=V,... (weights_arg.h) or NULL */
} cli_frame;

typedef struct cli_frame_plan {
    int32_t clip;         /* the clip sampled, or -1 (forced weights, or no clip) */
    uint32_t count;
    cli_frame *frames;
    char *storage;        /* the split copy of --times or --weights */
} cli_frame_plan;

/* The clip named or numbered by arg, or -1 after printing a usage error that lists the clips. */
int32_t cli_find_clip(const cli_verb *verb, const mk_asset *asset, const char *arg);

/* Fills plan for asset (read from input, named in errors): with weights, one frame per
 * ';'-separated set; else with a clip, the listed times or `frames` evenly spaced times over
 * the clip (both ends included); else the static state. Returns -1 when fine, else the exit
 * status after printing the error. Free with cli_frame_plan_free, also on error. */
int cli_frame_plan_make(const cli_verb *verb, const mk_asset *asset, const char *input, const char *clip,
                        const char *times, const char *weights, uint32_t frames, cli_frame_plan *plan);
void cli_frame_plan_free(cli_frame_plan *plan);

/* Plays frame `index` of plan into frame, whose asset, stacking, normal_mode, world and
 * skip_tangents the caller sets: the weights (allocated here) from the plan's clip at the
 * frame's time, or the defaults, then the frame's forced set; then every mesh. Returns -1,
 * else the exit status after printing the error (a forced set naming no channel of `input`
 * is a usage error). Free with cli_frame_clear, also on error. */
int cli_frame_play(const cli_verb *verb, const char *input, const cli_frame_plan *plan, uint32_t index,
                   pb_frame *frame);
/* Frees what cli_frame_play allocated (weights, positions, normals, tangents). */
void cli_frame_clear(pb_frame *frame);

#endif

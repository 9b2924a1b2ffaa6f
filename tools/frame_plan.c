/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "frame.h"
#include "frame_plan.h"
#include "weights_arg.h"

/* Largest frame count of a plan: far more than any sheet or golden set needs. */
#define MAX_FRAMES 10000u

int32_t cli_find_clip(const cli_verb *verb, const mk_asset *a, const char *arg)
{
    int32_t clip = mk_find_clip(a, arg);
    if (clip >= 0) return clip;
    char *end;
    long idx = strtol(arg, &end, 10);
    if (!*end && end != arg && idx >= 0 && idx < (long)a->clip_count) return (int32_t)idx;
    char names[600] = "";
    for (uint32_t c = 0; c < a->clip_count; c++) {
        mk_clip_info ci;
        mk_clip_get(a, c, &ci);
        size_t n = strlen(names);
        if (n + strlen(ci.name) + 8 < sizeof names)
            snprintf(names + n, sizeof names - n, "%s'%s'", n ? ", " : "", ci.name);
    }
    cli_usage_error(verb, "--clip: no clip '%s'; the clips are %s", arg, a->clip_count ? names : "(none: no animation)");
    return -1;
}

/* Splits list at sep in place; returns the item count, 0 when an item is empty, or
 * MAX_FRAMES + 1 when there are more. */
static uint32_t split(char *list, char sep, char **items)
{
    uint32_t n = 0;
    for (char *p = list, *next; p; p = next) {
        next = strchr(p, sep);
        if (next) *next++ = 0;
        if (!*p) return 0;
        if (n == MAX_FRAMES) return MAX_FRAMES + 1;
        items[n++] = p;
    }
    return n;
}

int cli_frame_plan_make(const cli_verb *verb, const mk_asset *a, const char *input, const char *clip_arg,
                        const char *times, const char *weights, uint32_t frames, cli_frame_plan *plan)
{
    memset(plan, 0, sizeof *plan);
    plan->clip = -1;
    if (times && weights) return cli_usage_error(verb, "--times and --weights contradict each other");
    const char *list = weights ? weights : times;
    char **items = NULL;
    if (list) {
        plan->storage = strdup(list);
        items = malloc((MAX_FRAMES + 1) * sizeof *items);
        if (!plan->storage || !items) {
            free(items);
            fprintf(stderr, "morphkit %s: out of memory\n", verb->name);
            return CLI_EXIT_FAILURE;
        }
        plan->count = split(plan->storage, weights ? ';' : ',', items);
        const char *option = weights ? "--weights" : "--times";
        int status = -1;
        if (plan->count == 0)
            status = cli_usage_error(verb, weights ? "%s: a set is empty (write NAME=V,...;NAME=V,...)" : "%s: an item is empty",
                                     option);
        else if (plan->count > MAX_FRAMES)
            status = cli_usage_error(verb, "%s: more than %u frames", option, MAX_FRAMES);
        if (status >= 0) {
            free(items);
            return status;
        }
    } else {
        plan->count = frames;
    }
    if (!weights && a->clip_count) {
        plan->clip = clip_arg ? cli_find_clip(verb, a, clip_arg) : 0;
        if (plan->clip < 0) {
            free(items);
            return CLI_EXIT_USAGE;
        }
    } else if (!weights) {
        free(items);
        if (clip_arg || times) return cli_usage_error(verb, "%s has no clip; give --weights", input);
        plan->count = 1;   /* the static state */
    }
    plan->frames = calloc(plan->count, sizeof *plan->frames);
    if (!plan->frames) {
        free(items);
        fprintf(stderr, "morphkit %s: out of memory\n", verb->name);
        return CLI_EXIT_FAILURE;
    }
    if (plan->clip < 0 && !weights) return -1;
    mk_clip_info ci = { 0 };
    if (plan->clip >= 0) mk_clip_get(a, (uint32_t)plan->clip, &ci);
    for (uint32_t i = 0; i < plan->count; i++) {
        cli_frame *f = &plan->frames[i];
        if (weights) {
            f->weights = items[i];
        } else if (times) {
            char *end;
            f->time = strtod(items[i], &end);
            if (*end || !isfinite(f->time)) {
                int status = cli_usage_error(verb, "--times: \"%s\" is not a number of seconds", items[i]);
                free(items);
                return status;
            }
        } else {
            f->time = ci.start + ci.duration * (plan->count > 1 ? (double)i / (plan->count - 1) : 0.0);
        }
    }
    free(items);
    return -1;
}

void cli_frame_plan_free(cli_frame_plan *plan)
{
    free(plan->frames);
    free(plan->storage);
    memset(plan, 0, sizeof *plan);
}

int cli_frame_play(const cli_verb *verb, const char *input, const cli_frame_plan *plan, uint32_t index, pb_frame *frame)
{
    const cli_frame *f = &plan->frames[index];
    const mk_asset *a = frame->asset;
    frame->clip = plan->clip;
    frame->time = f->time;
    frame->weights = calloc(a->channel_count + 1u, sizeof(float));
    mk_error err;
    if (!frame->weights) {
        fprintf(stderr, "morphkit %s: out of memory\n", verb->name);
        return CLI_EXIT_FAILURE;
    }
    if (pb_frame_weights(a, plan->clip, f->time, frame->weights, &err) != MK_OK) return cli_fail(verb->name, &err);
    char why[1024];
    if (f->weights && weights_arg_apply(a, f->weights, frame->weights, why, sizeof why) != 0)
        return cli_usage_error(verb, "--weights: %s: %s", input, why);
    if (pb_frame_evaluate(frame, &err) != MK_OK) return cli_fail(verb->name, &err);
    return -1;
}

void cli_frame_clear(pb_frame *frame)
{
    pb_frame_free(frame);
    free(frame->weights);
    frame->weights = NULL;
}

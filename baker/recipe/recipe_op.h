/* SPDX-License-Identifier: MIT */
/* What a recipe op is: the interface between the recipe document (recipe.c) and one op
 * (op_*.c), and the table of ops (recipe_ops.c).
 *
 * recipe.c reads what every channel has (op, name, mesh, in-betweens, tolerance, samples,
 * max_targets, default_weight), looks the op up by name in the table, checks the channel's fields
 * against the common ones and the op's own, and calls the op's parse. Once every channel is
 * parsed it bakes them in order: through the op's `bake` when it has one (ops that make several
 * channels), else through recipe_bake_deformer (bake_channel.c) with the op's `deformer`.
 *
 * Adding an op: a file op_NAME.c defining `const recipe_op recipe_op_NAME`, and its line in the
 * table. Nothing else changes (tests/baker/test_recipe_op.c adds one that way).
 */
#ifndef MORPHKIT_RECIPE_OP_H
#define MORPHKIT_RECIPE_OP_H

#include <cjson/cJSON.h>
#include "bake.h"
#include "bake_util.h"
#include "inbetween.h"

typedef struct recipe_op recipe_op;

/* The bake in progress: what every op may read, and where errors go. */
typedef struct recipe_ctx {
    mk_raw_asset *raw;
    mk_arena *scratch;            /* freed when the bake ends: parsed state lives here */
    const mk_bake_options *options;
    mk_error *err;
} recipe_ctx;

/* One channel entry of the recipe, parsed. */
typedef struct recipe_channel {
    const recipe_op *op;
    char name[128];
    uint32_t mesh;
    char *origin;                 /* recipe JSON of the channel (scratch) */
    mk_inbetween_options inbetween;
    float default_weight;
    double clip_duration;         /* > 0: a clip of this many seconds plays the weight 0 -> 1 */
    void *state;                  /* what the op's parse made (scratch, or freed by release) */
} recipe_channel;

/* What an op's deformer hook gives recipe_bake_deformer. */
typedef struct recipe_deformer {
    mk_deformer deformer;
    bake_pointwise pointwise;     /* for point maps: deformer.user = &pointwise (mesh and scratch set) */
    /* NULL, or called once right after the channel is baked, whether it was or not (baked 0/1):
     * puts the op's own figures into the report and frees what the deformer holds. An error
     * (only when baked) ends the bake. */
    mk_result (*finish)(recipe_ctx *ctx, const struct recipe_channel *ch, struct recipe_deformer *d, int baked,
                        mk_bake_channel_report *report);
    void *owner;
} recipe_deformer;

struct recipe_op {
    const char *name;
    const char *const *fields;    /* the op's fields beyond the common ones, NULL-terminated */
    int variant;                  /* for ops that share code: which of them (e.g. mk_barr_op) */
    int nonlinear;                /* in-betweens default to adaptive (else one exact target) */
    const char *refuse_inbetweens;/* non-NULL: "inbetweens" is refused, with this advice */
    /* Reads the op's fields of `json` (the channel object at `path`) into ch->state; may set
     * ch->clip_duration. Errors name the field by path (recipe_field_error). */
    mk_result (*parse)(recipe_ctx *ctx, recipe_channel *ch, const cJSON *json, const char *path);
    /* The deformation of one channel (times as part of the channel's bake); progress may be
     * reported. Errors go to *err, which the caller prefixes with the channel. */
    mk_result (*deformer)(recipe_ctx *ctx, recipe_channel *ch, recipe_deformer *out, mk_error *err);
    /* NULL, or the whole bake of an op that makes its own channels (index: the entry). */
    mk_result (*bake)(recipe_ctx *ctx, recipe_channel *ch, int index, mk_bake_report *report);
    /* NULL, or frees what parse holds outside the scratch; called for every parsed entry. */
    void (*release)(recipe_channel *ch);
};

/* The table, in the order the error messages list the ops. */
extern const recipe_op *const recipe_ops[];
extern const unsigned recipe_op_count;

/* Bakes one channel (ch->name) of ch->op's deformer and reports it: adds the channel, its default
 * weight and clip (clip_duration > 0), warns about folds. */
mk_result recipe_bake_deformer(recipe_ctx *ctx, recipe_channel *ch, int index, mk_bake_report *report);

#endif

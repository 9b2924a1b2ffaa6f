/* SPDX-License-Identifier: MIT */
/* An op added the way docs/baking.md says: op_scale.c and its line in a copy of the op table
 * (add_op.py), nothing else. The recipe front end finds it by name, lists it in its errors,
 * checks its fields and bakes it like the ops of the product. And the field readers' name lists. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "bake.h"
#include "fixtures.h"
#include "recipe/fields.h"

static mk_result bake(mk_raw_asset *raw, const char *recipe, mk_error *err)
{
    mk_bake_report rep;
    return mk_bake_recipe(raw, recipe, strlen(recipe), NULL, &rep, err);
}

static void made_up_op_bakes_its_channel(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *m = fixture_cylinder(&raw, "tube", 1, 4, 24, 16);
    mk_error err;
    const char *recipe = "{\"mesh\": \"tube\", \"channels\": [{\"name\": \"grow\", \"op\": \"scale\", \"factor\": 1.5},"
                         " {\"name\": \"grow3\", \"op\": \"scale\", \"factor\": 0.5, \"inbetweens\": 3}]}";
    mk_result r = bake(&raw, recipe, &err);
    CHECK_MSG(r == MK_OK, "bake: %s", err.message);
    if (r != MK_OK) { mk_raw_free(&raw); return; }
    CHECK_EQ_INT(raw.channel_count, 2);
    CHECK(!strcmp(raw.channels[0].name, "grow"));
    CHECK_EQ_INT(raw.channels[0].target_count, 1);  /* linear: one exact target by default */
    CHECK_EQ_INT(raw.channels[1].target_count, 3);  /* the common field inbetweens applies */
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], m->positions[3 * (size_t)v + c]);
            hi[c] = fmax(hi[c], m->positions[3 * (size_t)v + c]);
        }
    const mk_raw_target *t = &raw.channels[0].targets[0];
    CHECK_NEAR(t->full_weight, 1, 0);
    double worst = 0;
    for (uint32_t k = 0; k < t->count; k++)
        for (int c = 0; c < 3; c++) {
            double p = m->positions[3 * (size_t)t->indices[k] + c], centre = 0.5 * (lo[c] + hi[c]);
            worst = fmax(worst, fabs(t->positions[3 * (size_t)k + c] - 0.5 * (p - centre)));
        }
    CHECK_MSG(worst < 1e-5, "largest delta error %g", worst);
    CHECK(t->count > m->vertex_count / 2);  /* every vertex off the centre moves */
    mk_raw_free(&raw);
}

static void expect_error(const char *channel, const char *message)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_cylinder(&raw, "tube", 1, 4, 24, 16);
    char recipe[512];
    snprintf(recipe, sizeof recipe, "{\"mesh\": \"tube\", \"channels\": [%s]}", channel);
    mk_error err;
    memset(&err, 0, sizeof err);
    mk_result r = bake(&raw, recipe, &err);
    CHECK_MSG(r != MK_OK && !strcmp(err.message, message), "%s:\n  got      %s\n  expected %s", channel, err.message,
              message);
    CHECK_EQ_INT(raw.channel_count, 0);
    mk_raw_free(&raw);
}

static void made_up_op_is_listed_and_its_fields_checked(void)
{
    expect_error("{\"op\": \"grow\"}",
                 "channels[0].op: unknown op \"grow\" (expected ffd, ffd_travel, ffd_keys, ffd_cylinder, ffd_prism, "
                 "taper, twist, bend, cage, laplacian, arap, transfer, shell or scale)");
    expect_error("{\"name\": \"x\"}",
                 "channels[0].op: missing (ffd, ffd_travel, ffd_keys, ffd_cylinder, ffd_prism, taper, twist, bend, "
                 "cage, laplacian, arap, transfer, shell or scale)");
    expect_error("{\"op\": \"scale\", \"factor\": 2, \"dims\": [2, 2, 2]}",
                 "channels[0].dims: unknown field (see docs/baking.md)");
    expect_error("{\"op\": \"scale\"}", "channels[0].factor: missing");
    expect_error("{\"op\": \"scale\", \"factor\": -1}", "channels[0].factor: must be > 0");
    expect_error("{\"op\": \"scale\", \"factor\": 2, \"samples\": 1}", "channels[0].samples: must be an integer in 2..100000");
}

/* What ops add to a channel's report through their finish: the solver's figures (laplacian) and
 * the simulated volume curve (shell). */
typedef struct seen_reports {
    int count;
    mk_bake_channel_report r[4];
} seen_reports;

static void on_channel(void *user, const mk_bake_channel_report *r)
{
    seen_reports *seen = user;
    if (seen->count < 4) seen->r[seen->count++] = *r;
}

static void ops_report_their_own_figures(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_grid(&raw, "sheet", 2, 1, 20, 10);
    fixture_sphere(&raw, "ball", 1, 12, 8);
    const char *recipe =
        "{\"channels\": ["
        " {\"mesh\": \"sheet\", \"op\": \"laplacian\", \"inbetweens\": 1,"
        "  \"anchors\": {\"min\": [-1, -1, -1], \"max\": [0.01, 2, 1]},"
        "  \"handles\": [{\"min\": [1.99, -1, -1], \"max\": [3, 2, 1], \"translate\": [0, 0, 0.5]}]},"
        " {\"mesh\": \"ball\", \"op\": \"shell\", \"frames\": 4, \"dt\": 0.02}]}";
    seen_reports seen = { 0 };
    mk_bake_options o = { .channel_done = on_channel, .user = &seen };
    mk_bake_report rep;
    mk_error err;
    mk_result r = mk_bake_recipe(&raw, recipe, strlen(recipe), &o, &rep, &err);
    CHECK_MSG(r == MK_OK, "bake: %s", err.message);
    CHECK_EQ_INT(seen.count, 2);
    if (seen.count == 2) {
        CHECK_EQ_INT(seen.r[0].factorizations, 1);
        CHECK(seen.r[0].solves >= 1);
        CHECK_EQ_INT(seen.r[1].volume_frames, 5);
        CHECK(seen.r[1].volume_ratios && seen.r[1].volume_ratios[0] == 1);
        CHECK_NEAR(seen.r[1].frame_seconds, 0.02, 0);
    }
    mk_raw_free(&raw);
}

/* The lists of names errors give (meshes, a source's channels) end with ", ..." while it fits. */
static void name_lists_stop_before_they_are_cut(void)
{
    char list[24] = "";
    CHECK(recipe_list_name(list, sizeof list, "alpha"));
    CHECK(recipe_list_name(list, sizeof list, NULL));
    CHECK(!recipe_list_name(list, sizeof list, "gamma"));
    CHECK_MSG(!strcmp(list, "\"alpha\", \"\", ..."), "list: %s", list);
}

CHECK_MAIN(CASE(made_up_op_bakes_its_channel),
           CASE(name_lists_stop_before_they_are_cut),
           CASE(ops_report_their_own_figures),
           CASE(made_up_op_is_listed_and_its_fields_checked))

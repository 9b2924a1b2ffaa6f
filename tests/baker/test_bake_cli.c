/* SPDX-License-Identifier: MIT */
/* `morphkit bake` end to end: bake a sample recipe onto samples/make_example's tube, open the
 * result with the runtime, and check that a bad recipe fails without writing anything.
 * usage (from meson): test_bake_cli MORPHKIT MAKE_EXAMPLE RECIPES_DIR WORK_DIR */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "blob_io.h"
#include "check.h"

static const char *morphkit, *make_example, *recipes, *work;

static int run(const char *fmt, const char *a, const char *b, const char *c, const char *d)
{
    char cmd[8192];  /* 4 paths of < 1024 bytes + the format */
    snprintf(cmd, sizeof cmd, fmt, a, b, c, d);
    return system(cmd);
}

static int exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f) fclose(f);
    return f != NULL;
}

/* Writes the example tube to work/IN_NAME, bakes samples/recipes/RECIPE_NAME onto it into
 * work/OUT_NAME through the CLI and opens the result (data in arena). 1 when it opened. */
static int bake_example(const char *in_name, const char *recipe_name, const char *out_name, mk_arena *arena,
                        mk_asset *asset)
{
    char in[1024], out[1024], recipe[1024];
    snprintf(in, sizeof in, "%s/%s", work, in_name);
    snprintf(out, sizeof out, "%s/%s", work, out_name);
    snprintf(recipe, sizeof recipe, "%s/%s", recipes, recipe_name);
    remove(out);
    CHECK(run("\"%s\" \"%s\" > /dev/null%s%s", make_example, in, "", "") == 0);
    CHECK(run("\"%s\" bake \"%s\" --recipe \"%s\" -o \"%s\" --quiet > /dev/null", morphkit, in, recipe, out) == 0);
    void *data = NULL;
    size_t size = 0;
    mk_error err;
    mk_result r = mk_read_file(arena, out, 1 << 28, &data, &size, &err);
    if (r == MK_OK) r = mk_asset_open(data, size, asset, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    return r == MK_OK;
}

static void bake_sample_and_open_it(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset asset;
    if (bake_example("cli_tube.morph", "barr.json", "cli_tube_baked.morph", &arena, &asset)) {
        /* the example's 2 channels untouched + 3 baked ones, baked ones carry their recipe */
        CHECK_EQ_INT(asset.channel_count, 5);
        int32_t c = mk_find_channel(&asset, "bend_forward");
        mk_channel_info ci;
        CHECK(c >= 0 && mk_channel_get(&asset, (uint32_t)c, &ci));
        CHECK(c >= 0 && strstr(ci.origin, "\"op\":\"bend\"") != NULL);
        CHECK(c >= 0 && ci.target_count > 1);
        int32_t b = mk_find_channel(&asset, "bulge");
        CHECK(b >= 0 && mk_channel_get(&asset, (uint32_t)b, &ci) && ci.origin[0] == 0);
    }
    mk_arena_free_all(&arena);
}

/* The transfer sample reads its source asset (a glTF next to the recipe) through the CLI's loader. */
static void transfer_sample_reads_its_source(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset asset;
    if (bake_example("cli_tube3.morph", "transfer.json", "cli_tube_transfer.morph", &arena, &asset)) {
        /* the example's 2 channels + the source's "pinch" and "lean" with the prefix */
        CHECK_EQ_INT(asset.channel_count, 4);
        mk_channel_info ci;
        int32_t c = mk_find_channel(&asset, "coarse_pinch");
        CHECK(c >= 0 && mk_channel_get(&asset, (uint32_t)c, &ci) && strstr(ci.origin, "\"op\":\"transfer\"") != NULL);
        CHECK(mk_find_channel(&asset, "coarse_lean") >= 0);
    }
    mk_arena_free_all(&arena);
}

/* The transfer sample between two characters (make_example --heads): the template's six expressions
 * carried onto the character through the iterative correspondence, which the report names. */
static void heads_sample_carries_the_expressions(void)
{
    char dir[1024], in[1100], out[1100], recipe[1100], report[1100];
    snprintf(dir, sizeof dir, "%s/heads", work);
    snprintf(in, sizeof in, "%s/head_character.morph", dir);
    snprintf(out, sizeof out, "%s/character_expressions.morph", dir);
    snprintf(recipe, sizeof recipe, "%s/transfer_heads.json", dir);
    snprintf(report, sizeof report, "%s/report.txt", dir);
    CHECK(run("mkdir -p \"%s\" && \"%s\" --heads \"%s\" > /dev/null", dir, make_example, dir, "") == 0);
    char cmd[6000];
    snprintf(cmd, sizeof cmd, "\"%s\" bake \"%s\" --recipe \"%s\" -o \"%s\" > \"%s\"", morphkit, in, recipe, out, report);
    CHECK(system(cmd) == 0);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    void *data = NULL, *text = NULL;
    size_t size = 0, text_size = 0;
    mk_error err;
    mk_asset asset;
    mk_result r = mk_read_file(&arena, out, 1 << 28, &data, &size, &err);
    if (r == MK_OK) r = mk_asset_open(data, size, &asset, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r == MK_OK) {
        CHECK_EQ_INT(asset.channel_count, 6);
        CHECK(mk_find_channel(&asset, "character_jaw_open") >= 0 && mk_find_channel(&asset, "character_nose_wrinkle") >= 0);
    }
    CHECK(mk_read_file(&arena, report, 1 << 20, &text, &text_size, &err) == MK_OK &&
          strstr(text, "correspondence: iterative") != NULL);
    /* the same in --json: the correspondence and the fit's residual of the entry's first channel */
    snprintf(cmd, sizeof cmd, "\"%s\" bake \"%s\" --recipe \"%s\" -o \"%s\" --json > \"%s\"", morphkit, in, recipe, out,
             report);
    CHECK(system(cmd) == 0);
    CHECK(mk_read_file(&arena, report, 1 << 20, &text, &text_size, &err) == MK_OK &&
          strstr(text, "\"correspondence\": \"iterative\"") != NULL && strstr(text, "\"fit_mean\": ") != NULL &&
          strstr(text, "\"channels_added\": 6") != NULL);
    mk_arena_free_all(&arena);
}

/* The solver bakes (Laplacian, ARAP: CHOLMOD on the BLAS) give the same bytes on every run. */
static void solver_bakes_repeat_to_the_byte(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset first, second;
    if (bake_example("cli_tube4.morph", "laplacian.json", "cli_tube_laplacian1.morph", &arena, &first)
        && bake_example("cli_tube4.morph", "laplacian.json", "cli_tube_laplacian2.morph", &arena, &second)) {
        CHECK_EQ_INT(first.channel_count, 4);
        CHECK(first.size == second.size && memcmp(first.data, second.data, first.size) == 0);
    }
    mk_arena_free_all(&arena);
}

static void bad_recipe_writes_nothing(void)
{
    char in[1024], out[1024], recipe[1024];
    snprintf(in, sizeof in, "%s/cli_tube2.morph", work);
    snprintf(out, sizeof out, "%s/cli_tube_bad.morph", work);
    snprintf(recipe, sizeof recipe, "%s/cli_bad_recipe.json", work);
    remove(out);
    FILE *f = fopen(recipe, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs("{\"mesh\": \"tube\", \"channels\": [{\"op\": \"twist\", \"angle\": 90},"
          " {\"op\": \"arap\", \"handles\": [{\"center\": [9, 9, 9], \"radius\": 0.1}]}]}", f);
    fclose(f);
    CHECK(run("\"%s\" \"%s\" > /dev/null%s%s", make_example, in, "", "") == 0);
    CHECK(run("\"%s\" bake \"%s\" --recipe \"%s\" -o \"%s\" 2> /dev/null > /dev/null", morphkit, in, recipe, out) != 0);
    CHECK(!exists(out));
}

int main(int argc, char **argv)
{
    if (argc < 5) { fprintf(stderr, "usage: test_bake_cli MORPHKIT MAKE_EXAMPLE RECIPES_DIR WORK_DIR\n"); return 2; }
    morphkit = argv[1]; make_example = argv[2]; recipes = argv[3]; work = argv[4];
    static const check_case cases[] = { CASE(bake_sample_and_open_it), CASE(transfer_sample_reads_its_source),
                                        CASE(heads_sample_carries_the_expressions),
                                        CASE(solver_bakes_repeat_to_the_byte), CASE(bad_recipe_writes_nothing) };
    return check_run(cases, (int)(sizeof cases / sizeof cases[0]), 1, argv);
}

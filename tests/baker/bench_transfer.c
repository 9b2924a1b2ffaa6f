/* SPDX-License-Identifier: MIT */
/* Deformation transfer benchmark: KEYS keys (default 52) of a template head (offline/head.h, a UV
 * sphere of RINGS rings: 72 gives 20 448 triangles) carried onto the warped head as an icosphere
 * (LEVELS 5: 20 480 triangles) through `mk_bake_recipe`, as `morphkit bake` runs a transfer entry.
 * Runs the iterative correspondence and the one pass (closest) in the same process, alternating
 * ROUNDS times (default 3), and prints, per run, the whole bake, the correspondence (alignment, fit
 * and matching) and the time per key after the first; then the ranges and the iterative run's
 * cost over the one pass's. The keys are the head's six expressions at weights spread over
 * (0, 1], one channel each. usage: bench_transfer [KEYS [RINGS [LEVELS [ROUNDS]]]] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bake.h"
#include "bake_util.h"
#include "head.h"
#include "transfer.h"

static uint32_t keys = 52, rings = 72, levels = 5;

/* The source asset: the template head, its expressions copied until there are `keys` channels,
 * key j being expression j % 6 at weight (j / 6 + 1) / (keys / 6 + 1). */
static mk_result load_template(void *user, const char *path, mk_raw_asset *out, mk_error *err)
{
    (void)user; (void)path;
    mk_raw_mesh *m = mk_raw_add_head(out, "template", rings, 1, 0, 0, 0, NULL);
    if (!m) return mk_error_oom(err, "template");
    double *surface = malloc(3 * (size_t)m->vertex_count * sizeof(double));
    if (!surface) return mk_error_oom(err, "template");
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int c = 0; c < 3; c++) surface[3 * (size_t)v + c] = m->positions[3 * (size_t)v + c];
    uint32_t per = keys / MK_HEAD_EXPRESSIONS + 1;
    for (uint32_t j = 0; j < keys; j++) {
        mk_raw_channel *ch = mk_raw_add_channels(out, 1);
        char name[64];
        snprintf(name, sizeof name, "%s_%u", mk_head_expression_name(j % MK_HEAD_EXPRESSIONS), j);
        ch->name = mk_arena_strdup(&out->arena, name);
        ch->mesh = 0;
        mk_raw_target *t = mk_raw_add_targets(out, ch, 1);
        t->name = ch->name;
        t->indices = mk_arena_array(&out->arena, m->vertex_count, sizeof(uint32_t));
        t->positions = mk_arena_array(&out->arena, 3 * (size_t)m->vertex_count, sizeof(float));
        if (!ch->name || !t->indices || !t->positions) { free(surface); return mk_error_oom(err, "template"); }
        double w = (double)(j / MK_HEAD_EXPRESSIONS + 1) / per;
        for (uint32_t v = 0; v < m->vertex_count; v++) {
            double q[3];
            mk_head_expression(j % MK_HEAD_EXPRESSIONS, w, surface + 3 * (size_t)v, q);
            t->indices[v] = v;
            for (int c = 0; c < 3; c++) t->positions[3 * (size_t)v + c] = (float)(q[c] - surface[3 * (size_t)v + c]);
        }
        t->count = m->vertex_count;
    }
    free(surface);
    return MK_OK;
}

typedef struct timing { double first_done, last_done; uint32_t channels; mk_bake_channel_report first; } timing;

static void on_channel(void *user, const mk_bake_channel_report *c)
{
    timing *t = user;
    if (t->channels++ == 0) { t->first = *c; t->first_done = bake_now(); }
    t->last_done = bake_now();
}

/* One bake; total seconds, the first channel's (correspondence, factorization, its solve) and
 * seconds per further key. */
static int run(const char *mode, double *total, double *first, double *per_key, double *fit)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    if (!mk_raw_add_head(&raw, "character", levels, 0, 0.3, 1, 0, NULL)) return 0;
    char recipe[512];
    snprintf(recipe, sizeof recipe, "{\"mesh\": 0, \"channels\": [{\"op\": \"transfer\", \"source\": \"template\", "
             "\"correspondence\": \"%s\", \"markers\": []}]}", mode);
    timing t;
    memset(&t, 0, sizeof t);
    mk_bake_options o = { .channel_done = on_channel, .user = &t, .load_asset = load_template };
    mk_error err;
    double t0 = bake_now();
    mk_result r = mk_bake_recipe(&raw, recipe, strlen(recipe), &o, NULL, &err);
    *total = bake_now() - t0;
    if (r != MK_OK) { fprintf(stderr, "bench_transfer: %s\n", err.message); mk_raw_free(&raw); return 0; }
    *first = t.first_done - t0;
    *per_key = t.channels > 1 ? (t.last_done - t.first_done) / (t.channels - 1) : 0;
    *fit = t.first.fit_mean;
    mk_raw_free(&raw);
    return 1;
}

int main(int argc, char **argv)
{
    uint32_t rounds = 3;
    if (argc > 1) keys = (uint32_t)atoi(argv[1]);
    if (argc > 2) rings = (uint32_t)atoi(argv[2]);
    if (argc > 3) levels = (uint32_t)atoi(argv[3]);
    if (argc > 4) rounds = (uint32_t)atoi(argv[4]);
    if (keys < 1 || keys > 1000 || rings < 4 || rings > 1000 || levels > 7 || rounds < 1) {
        fprintf(stderr, "usage: bench_transfer [KEYS [RINGS [LEVELS [ROUNDS]]]]\n");
        return 2;
    }
    printf("%u keys; source: UV head of %u rings (%u triangles); target: icosphere head of level %u (%u triangles)\n",
           keys, rings, 4 * rings * (rings - 1), levels, 20u << (2 * levels));
    double lo[2][3], hi[2][3];
    for (int m = 0; m < 2; m++)
        for (int k = 0; k < 3; k++) { lo[m][k] = INFINITY; hi[m][k] = 0; }
    static const char *const modes[2] = { "iterative", "closest" };
    for (uint32_t round = 0; round < rounds; round++)
        for (int m = 0; m < 2; m++) {
            double v[3], fit;
            if (!run(modes[m], &v[0], &v[1], &v[2], &fit)) return 1;
            printf("  %-9s total %.2f s, first key (correspondence and factorization included) %.2f s, %.1f ms per "
                   "further key%s", modes[m], v[0], v[1], 1e3 * v[2], m == 0 ? "" : "\n");
            if (m == 0) printf(", fit %.2g x diagonal\n", fit);
            for (int k = 0; k < 3; k++) { lo[m][k] = fmin(lo[m][k], v[k]); hi[m][k] = fmax(hi[m][k], v[k]); }
        }
    for (int m = 0; m < 2; m++)
        printf("%-9s total %.2f-%.2f s, first key %.2f-%.2f s, %.1f-%.1f ms per further key\n", modes[m], lo[m][0],
               hi[m][0], lo[m][1], hi[m][1], 1e3 * lo[m][2], 1e3 * hi[m][2]);
    printf("iterative over closest: total %.2f-%.2fx\n", lo[0][0] / hi[1][0], hi[0][0] / lo[1][0]);
    return 0;
}

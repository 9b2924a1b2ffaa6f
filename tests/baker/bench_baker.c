/* SPDX-License-Identifier: MIT */
/* Baker benchmark: Laplacian (cotangent) and ARAP (10 iterations) bakes of a ~100 000-vertex
 * sphere, one factorization each; prints factor time, per-solve time and total wall time.
 * usage: bench_baker [rings segments]   (default 250 x 400 = 99 602 vertices) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bake.h"
#include "bake_util.h"
#include "fixtures.h"

typedef struct bench_user { mk_bake_channel_report last; } bench_user;

static void on_channel(void *user, const mk_bake_channel_report *c)
{
    ((bench_user *)user)->last = *c;
}

static int run(const char *label, const char *recipe, uint32_t rings, uint32_t segments)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *m = fixture_sphere(&raw, "ball", 1, segments, rings);
    bench_user u;
    memset(&u, 0, sizeof u);
    mk_bake_options o = { .channel_done = on_channel, .user = &u };
    mk_error err;
    mk_bake_report rep;
    double t0 = bake_now();
    mk_result r = mk_bake_recipe(&raw, recipe, strlen(recipe), &o, &rep, &err);
    double total = bake_now() - t0;
    if (r != MK_OK) { fprintf(stderr, "%s: %s\n", label, err.message); mk_raw_free(&raw); return 1; }
    const mk_bake_channel_report *c = &u.last;
    printf("%-22s %6u vertices %7u triangles: factorizations %u, factor %.3f s, %u solves x 3 rhs "
           "%.4f s each, total %.3f s (moved %u vertices, %u target%s)\n",
           label, m->vertex_count, m->triangle_count, c->factorizations, c->factor_seconds, c->solves,
           c->solves ? c->solve_seconds / c->solves : 0.0, total, c->moved_vertices, c->targets,
           c->targets == 1 ? "" : "s");
    mk_raw_free(&raw);
    return 0;
}

int main(int argc, char **argv)
{
    uint32_t rings = 250, segments = 400;
    if (argc == 3) { rings = (uint32_t)atoi(argv[1]); segments = (uint32_t)atoi(argv[2]); }
    if (rings < 4 || segments < 4) { fprintf(stderr, "usage: bench_baker [rings segments]\n"); return 2; }
    /* South cap anchored, north cap pulled up and turned 30 degrees. */
    const char *edit =
        "{\"mesh\": \"ball\", \"channels\": [{\"name\": \"%s\", \"op\": \"%s\", \"inbetweens\": 1,"
        " \"weights\": \"cotangent\"%s,"
        " \"anchors\": {\"min\": [-2, -2, -2], \"max\": [2, 2, -0.8]},"
        " \"handles\": [{\"min\": [-2, -2, 0.8], \"max\": [2, 2, 2], \"translate\": [0, 0, 0.3],"
        "   \"rotate\": {\"axis\": [1, 0, 0], \"degrees\": 30}}]}]}";
    char recipe[1024];
    int fails = 0;
    snprintf(recipe, sizeof recipe, edit, "lap", "laplacian", "");
    fails += run("laplacian (cotangent)", recipe, rings, segments);
    snprintf(recipe, sizeof recipe, edit, "arap", "arap", ", \"iterations\": 10");
    fails += run("arap (10 iterations)", recipe, rings, segments);
    return fails ? 1 : 0;
}

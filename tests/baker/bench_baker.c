/* SPDX-License-Identifier: MIT */
/* Baker benchmark: Laplacian (cotangent) and ARAP (10 iterations) bakes of a ~100 000-vertex
 * sphere, one factorization each; prints factor time, per-solve time and total wall time.
 * usage: bench_baker [rings segments]   (default 250 x 400 = 99 602 vertices)
 *
 * ARAP convergence: bench_baker arap LEVELS (icosphere, 6: 40 962 vertices, 7: 163 842):
 * anchors z < -0.5, handle z > 0.8 moved by (0.3, 0, 0.2). Prints energy, time and distance
 * to a tightly converged reference (Anderson, relative energy change 1e-9) for 10 plain
 * iterations, plain to convergence and Anderson to convergence, and the time each run took to
 * come within 1 % of the reference energy.
 *
 * Shell: bench_baker shell SEGMENTS RINGS [THICKNESS [FRAMES [KB [PRESSURE]]]] (UV sphere of 2 x SEGMENTS x
 * (RINGS - 1) triangles; 100 51: 10 000, 250 101: 50 000): FRAMES (100) frames of the default shell recipe
 * (pressure 20 ramped over 1 s), ms per frame and the collision part (THICKNESS > 0 turns collisions on). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bake.h"
#include "bake_util.h"
#include "fixtures.h"
#include "shell/shell.h"
#include "surface_edit.h"

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

typedef struct arap_trace {
    double t0, target_energy, reached_seconds;  /* reached: first time within 1 % (or -1) */
    uint32_t reached_iteration;
} arap_trace;

static void on_iteration(void *user, uint32_t iteration, double energy)
{
    arap_trace *t = user;
    if (getenv("BENCH_ARAP_TRACE")) printf("    %u %.6f\n", iteration, energy);
    if (t->reached_seconds < 0 && energy <= 1.01 * t->target_energy) {
        t->reached_seconds = bake_now() - t->t0;
        t->reached_iteration = iteration;
    }
}

static int arap_convergence(uint32_t levels)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *m = fixture_icosphere(&raw, "ico", 1, levels);
    uint32_t *anchors = malloc(m->vertex_count * sizeof(uint32_t)), *handle = malloc(m->vertex_count * sizeof(uint32_t));
    uint32_t na = fixture_select_z(m, -2, -0.5f, anchors), nh = fixture_select_z(m, 0.8f, 2, handle);
    mk_edit_handle h = { nh, handle, { 0.3, 0, 0.2 }, { 0, 0, 1 }, 0, { 0, 0, 0 } };
    const double move = sqrt(0.3 * 0.3 + 0.2 * 0.2);
    /* BENCH_ARAP_RUNS=n: only the first n runs (the reference always). */
    struct { const char *label; mk_arap_acceleration acc; uint32_t cap; double convergence; } runs[] = {
        { "reference (lbfgs, 1e-10)", MK_ARAP_LBFGS, 5000, 1e-10 },
        { "lbfgs, default", MK_ARAP_LBFGS, 1000, 0 },
        { "lbfgs, 1e-7", MK_ARAP_LBFGS, 1000, 1e-7 },
        { "plain, 10 iterations", MK_ARAP_PLAIN, 10, -1 },
        { "anderson, default", MK_ARAP_ANDERSON, 1000, 0 },
        { "plain, default", MK_ARAP_PLAIN, 1000, 0 },
        { "anderson, 1e-4", MK_ARAP_ANDERSON, 1000, 1e-4 },
        { "anderson, 1e-5", MK_ARAP_ANDERSON, 1000, 1e-5 },
        { "plain, 1000 iterations", MK_ARAP_PLAIN, 1000, -1 },
    };
    size_t n3 = 3 * (size_t)m->vertex_count;
    double *reference = malloc(n3 * sizeof(double)), *pos = malloc(n3 * sizeof(double));
    double reference_energy = 0;
    int fails = 0;
    printf("ARAP on an icosphere of %u vertices, %u anchors, %u handle vertices moved by %.4f\n",
           m->vertex_count, na, nh, move);
    size_t run_count = sizeof runs / sizeof runs[0];
    if (getenv("BENCH_ARAP_RUNS")) {
        size_t n = (size_t)atoi(getenv("BENCH_ARAP_RUNS"));
        if (n >= 1 && n < run_count) run_count = n;
    }
    for (size_t k = 0; k < run_count; k++) {
        fflush(stdout);
        arap_trace trace = { 0, reference_energy, -1, 0 };
        mk_edit_params p = { .method = MK_EDIT_ARAP, .anchor_count = na, .anchors = anchors,
                             .handle_count = 1, .handles = &h, .iterations = runs[k].cap,
                             .convergence = runs[k].convergence, .acceleration = runs[k].acc,
                             .iteration_done = k ? on_iteration : NULL, .user = &trace };
        mk_surface_edit *e = NULL;
        mk_error err;
        if (mk_surface_edit_create(m, &p, NULL, &e, &err) != MK_OK) {
            fprintf(stderr, "%s: %s\n", runs[k].label, err.message);
            fails++;
            continue;
        }
        trace.t0 = bake_now();
        mk_result r = mk_surface_edit_eval(e, 1, k ? pos : reference, NULL, NULL, NULL, &err);
        double seconds = bake_now() - trace.t0;
        mk_solver_stats st;
        mk_surface_edit_stats(e, &st);
        mk_surface_edit_destroy(e);
        if (r != MK_OK) { fprintf(stderr, "%s: %s\n", runs[k].label, err.message); fails++; continue; }
        if (k == 0) reference_energy = st.energy;
        double far = 0;
        for (size_t i = 0; k && i < n3; i += 3) {
            double d[3] = { pos[i] - reference[i], pos[i + 1] - reference[i + 1], pos[i + 2] - reference[i + 2] };
            far = fmax(far, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
        }
        printf("  %-28s %4u iterations %7.3f s (local %.3f s, %u rejected), energy %.6f (initial %.4f, "
               "%.4f x reference), max distance to reference %.4f x handle move",
               runs[k].label, st.iterations, seconds, st.local_seconds, st.rejected_steps, st.energy,
               st.start_energy, reference_energy > 0 ? st.energy / reference_energy : 1.0, far / move);
        if (k && trace.reached_seconds >= 0)
            printf(", within 1 %% of the reference energy after %u iterations, %.3f s\n",
                   trace.reached_iteration, trace.reached_seconds);
        else printf("\n");
    }
    free(reference); free(pos); free(anchors); free(handle);
    mk_raw_free(&raw);
    return fails;
}

/* The shell simulation on a UV sphere: ms per frame with and without collision handling, the
 * collision part separately (docs/performance.md). */
static int shell_bench(uint32_t segments, uint32_t rings, double thickness, uint32_t frames, double kB, double pressure)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *mesh = fixture_sphere(&raw, "ball", 1, segments, rings);
    shell_params p;
    memset(&p, 0, sizeof p);
    p.pressure = pressure; p.dt = 0.01; p.frames = frames; p.ramp = 1; p.iterations = 5; p.density = 1; p.damping = 0.02;
    p.material = SHELL_STVK; p.mu = 100; p.lambda = 100; p.kB = kB; p.epsilon = 0.05; p.thickness = thickness;
    if (getenv("BENCH_SHELL_THREADS")) p.threads = (uint32_t)atoi(getenv("BENCH_SHELL_THREADS"));  /* 0: one per core */
    shell_mesh m;
    shell_run run;
    mk_error err;
    double t0 = bake_now();
    mk_result r = shell_mesh_build(mesh, p.density, &raw.arena, &m, &err);
    double t1 = bake_now();
    if (r == MK_OK) r = shell_simulate(&m, &p, &raw.arena, NULL, NULL, &run, &err);
    if (r != MK_OK) { fprintf(stderr, "shell: %s\n", err.message); mk_raw_free(&raw); return 1; }
    double frame_ms = 0, collision_ms = 0;
    uint32_t hits = 0, rounds = 0, most = 0, rises = 0;
    for (uint32_t f = 1; f <= run.frames; f++) {
        rises += !(run.stats[f].volume_ratio < run.stats[f - 1].volume_ratio);
        rounds += run.stats[f].collision_rounds;
        if (run.stats[f].collision_rounds > most) most = run.stats[f].collision_rounds;
        frame_ms += run.stats[f].ms_step;
        collision_ms += run.stats[f].ms_collision;
        hits += run.stats[f].vt_hits + run.stats[f].ee_hits;
    }
    printf("shell: %u triangles, %u vertices, kB %g, P %g, thickness %g: setup %.1f ms; %u frames (%u substeps each), %.2f ms "
           "per frame of which collisions %.2f ms (%u hits, %.1f rounds per frame, at most %u); V/V0 after the run %.4f\n",
           m.tri_count, m.n, kB, pressure, thickness, 1000 * (t1 - t0), run.frames, run.substeps, frame_ms / run.frames,
           collision_ms / run.frames, hits, (double)rounds / run.frames, most, run.stats[run.frames].volume_ratio);
    printf("  V/V0 at frames 0, 10, ...:");
    for (uint32_t f = 0; f <= run.frames; f += 10) printf(" %.4f", run.stats[f].volume_ratio);
    printf("; %u frames did not lower the volume\n", rises);
    mk_raw_free(&raw);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 4 && !strcmp(argv[1], "shell"))
        return shell_bench((uint32_t)atoi(argv[2]), (uint32_t)atoi(argv[3]), argc > 4 ? atof(argv[4]) : 0,
                           argc > 5 ? (uint32_t)atoi(argv[5]) : 100, argc > 6 ? atof(argv[6]) : 0.01,
                           argc > 7 ? atof(argv[7]) : 20);
    if (argc == 3 && !strcmp(argv[1], "arap")) return arap_convergence((uint32_t)atoi(argv[2])) ? 1 : 0;
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
    snprintf(recipe, sizeof recipe, edit, "arap", "arap",
             ", \"iterations\": 10, \"convergence\": 0, \"acceleration\": \"none\"");
    fails += run("arap (10 iterations)", recipe, rings, segments);
    return fails ? 1 : 0;
}

/* SPDX-License-Identifier: MIT */
/* morphkit bench [FILE] [--vertices N] [--channels C] [--active A] [--density D] [--threads T]
 *                [--frames F] [--json] [--profile N]
 *
 * Measures evaluation speed against baselines run in the same process:
 *   bound_ns   the bytes one frame must touch, at the memory-copy bandwidth measured now
 *   naive_ns   a straightforward dense float loop over all vertices and the active targets
 * With FILE, plays its first clip at F evenly spaced times (--frames, default 100); without,
 * builds a synthetic mesh (default 1 000 000 vertices, 100 channels of which 20 % progressive,
 * each target moving `density` of the vertices in a few spatially coherent regions, `active`
 * channels nonzero).
 * The timed configurations (additive, positions only, sequential, and with --threads T > 1 in
 * the text report also one thread, for thread_scaling) run round-robin, best pass of each, with
 * copy-bandwidth samples between the rounds. --json prints exactly the keys above.
 */
#define _GNU_SOURCE
#include <math.h>
#include <stddef.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "asset.h"
#include "bench_gpu.h"
#include "cli.h"
#include "clock.h"
#include "frame.h"
#include "naive.h"
#include "normal_quality.h"
#include "surface.h"
#include "synthetic.h"
#include "timing.h"

static void progress_update(void *user, const char *stage, double fraction)
{
    cli_progress_update(user, stage, fraction);
}

typedef struct bench_args {
    const char *file;
    uint64_t vertices, channels, active, threads, frames, profile;
    double density;
    int json, quiet, gpu;
} bench_args;

static int run_bench(void *p);

static const cli_option options[] = {
    { "--vertices", "N", CLI_UINT, offsetof(bench_args, vertices), "Synthetic mesh size, in vertices.", "1000000", NULL,
      64, 100000000, 0, 0 },
    { "--channels", "C", CLI_UINT, offsetof(bench_args, channels),
      "Synthetic channels (one in five progressive, with an in-between at 0.5).", "100", NULL, 1, 100000, 0, 0 },
    { "--active", "A", CLI_UINT, offsetof(bench_args, active),
      "Synthetic channels with a nonzero weight in each frame (<= C).", "30", NULL, 0, 100000, 0, 0 },
    { "--density", "D", CLI_NUMBER, offsetof(bench_args, density),
      "Fraction of the vertices each synthetic target moves (in a few coherent regions).", "0.1", NULL, 1e-6, 0.3, 0,
      0 },
    { "--threads", "T", CLI_UINT, offsetof(bench_args, threads),
      "Evaluation threads (ranges of 256 blocks taken from a shared counter).", "1", NULL, 1, 64, 0, 0 },
    { "--frames", "F", CLI_UINT, offsetof(bench_args, frames),
      "Weight sets per pass (with FILE: its first clip at F evenly spaced times).", "100", NULL, 1, 100000, 0, 0 },
    { "--json", NULL, CLI_FLAG, offsetof(bench_args, json), "Print one JSON object with the measured keys only.", NULL,
      NULL, 0, 0, 0, 0 },
    { "--profile", "N", CLI_UINT, offsetof(bench_args, profile),
      "Profiling mode: only N rounds of evaluation (for perf or callgrind), no baselines.", NULL, NULL, 1, 1000000, 0,
      0 },
    { "--quiet", NULL, CLI_FLAG, offsetof(bench_args, quiet), "No progress lines.", NULL, NULL, 0, 0, 0, 0 },
    { "--gpu", NULL, CLI_FLAG, offsetof(bench_args, gpu),
      "Also time the GPU path (docs/gpu.md): GPU ns per frame from timestamp queries, the CPU time of planning and "
      "recording a frame, and the ratio to the device's own buffer-copy bandwidth, beside the CPU figures of the "
      "same run (no surface, naive or normal-quality measurements then).",
      NULL, NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_bench = {
    .name = "bench",
    .usage = "[FILE] [options]",
    .summary = "measure evaluation speed against baselines run in the same process",
    .description = "Times the runtime's evaluation (positions + normals, positions only, sequential stacking) and "
                   "prints it with ratios "
                   "against baselines measured in the same run: the memory-copy bound for the bytes a frame touches, "
                   "and a naive dense "
                   "loop. With FILE it also measures how far the evaluated normals are from the evaluated surface, per "
                   "normal mode (docs/semantics.md, Normal quality), and times positions + surface normals against positions + "
                   "nlerp, on the asset itself and on a copy without target normals (what `import --target-normals none` "
                   "writes for surface normals). Without FILE a synthetic asset is built (--vertices, "
                   "--channels, --active, --density).",
    .positional = "FILE",
    .positional_help = "An asset to play instead of the synthetic one (its first clip).",
    .positional_offset = offsetof(bench_args, file),
    .positional_required = 0,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(bench_args),
    .run = run_bench,
};


/* Normal quality (playback/normal_quality.h) over up to 20 of the frames, evenly spread. */
static mk_result measure_normals(const pb_asset *l, const float *weights, uint32_t frames,
                                 pb_normal_stats out[PB_QUALITY_MODES], mk_error *err)
{
    const mk_asset *a = &l->asset;
    mk_result r = MK_OK;
    pb_normal_quality q;
    memset(&q, 0, sizeof q);
    uint32_t measured = frames < 20 ? frames : 20;
    for (uint32_t k = 0; k < measured && r == MK_OK; k++) {
        uint32_t f = measured > 1 ? (uint32_t)((uint64_t)k * (frames - 1) / (measured - 1)) : 0;
        r = pb_normal_quality_add(&q, a, &l->raw, weights + (size_t)f * a->channel_count, MK_STACKING_ASSET, err);
    }
    for (int m = 0; m < PB_QUALITY_MODES; m++) out[m] = pb_normal_quality_stats(&q, m);
    pb_normal_quality_free(&q);
    return r;
}

/* bench --gpu: the GPU path timed (tools/bench_gpu.c) beside the CPU frame of the same run. */
static int report_gpu(const bench_args *args, const mk_asset *a, const float *weights, uint32_t frames, double bytes,
                      double cpu_ns, double cpu_ns_positions, double cpu_bound_ns)
{
    cli_gpu_bench g;
    mk_error err;
    if (cli_bench_gpu(a, weights, frames, &g, &err) != MK_OK) return cli_fail("bench", &err);
    const double gpu_bound_ns = g.copy_bytes_per_ns > 0 ? bytes / g.copy_bytes_per_ns : 0;
    if (args->json) {
        printf("{\"device\": \"");
        for (const char *c = g.device; *c; c++)
            if (*c != '"' && *c != '\\' && (unsigned char)*c >= 32) putchar(*c);
        printf("\", \"gpu_ns_per_frame\": %.0f, \"gpu_ns_per_frame_min\": %.0f, \"gpu_ns_per_frame_positions\": %.0f, "
               "\"cpu_record_ns_per_frame\": %.0f, \"upload_ms\": %.3f, \"bytes_per_frame\": %.0f, "
               "\"gpu_copy_gb_per_s\": %.3f, \"gpu_bound_ns\": %.0f, \"gpu_ratio_to_bound\": %.3f, "
               "\"cpu_ns_per_frame\": %.0f, \"cpu_ns_per_frame_positions\": %.0f, \"cpu_bound_ns\": %.0f, "
               "\"gpu_speedup_vs_cpu\": %.3f}\n",
               g.gpu_ns, g.gpu_ns_min, g.gpu_ns_positions, g.record_ns, g.upload_ms, bytes, g.copy_bytes_per_ns,
               gpu_bound_ns, gpu_bound_ns / g.gpu_ns, cpu_ns, cpu_ns_positions, cpu_bound_ns, cpu_ns / g.gpu_ns);
        return 0;
    }
    printf("device: %s, frames: %u (median of %u passes after one warm-up)\n", g.device, frames, 3u);
    printf("gpu_ns_per_frame           %12.0f  (positions + normals; best %.0f)\n", g.gpu_ns, g.gpu_ns_min);
    printf("gpu_ns_per_frame_positions %12.0f\n", g.gpu_ns_positions);
    printf("cpu_record_ns_per_frame    %12.0f  (plans written, dispatches recorded)\n", g.record_ns);
    printf("upload_ms                  %12.3f  (the blob, once)\n", g.upload_ms);
    printf("bytes_per_frame            %12.0f\n", bytes);
    printf("gpu_bound_ns               %12.0f  (device copy bandwidth %.2f GB/s)\n", gpu_bound_ns, g.copy_bytes_per_ns);
    printf("gpu_ratio_to_bound         %12.3f\n", gpu_bound_ns / g.gpu_ns);
    printf("cpu_ns_per_frame           %12.0f  (%u thread%s, same run; positions only %.0f)\n", cpu_ns,
           (unsigned)args->threads, args->threads == 1 ? "" : "s", cpu_ns_positions);
    printf("gpu_speedup_vs_cpu         %12.2f\n", cpu_ns / g.gpu_ns);
    return 0;
}

static int run_bench(void *p)
{
    bench_args *args = p;
    const cli_verb *verb = &cli_verb_bench;
    bench_synthetic o = { (uint32_t)args->vertices, (uint32_t)args->channels, (uint32_t)args->active, args->density };
    const uint32_t thread_count = (uint32_t)args->threads, frames = (uint32_t)args->frames,
                   profile = (uint32_t)args->profile;
    const char *file = args->file;
    if (o.active > o.channels)
        return cli_usage_error(verb, "--active %u is more than --channels %u", o.active, o.channels);
    if (!file) {
        double need = bench_synthetic_bytes(&o), have = bench_machine_memory();
        if (have > 0 && need > 0.8 * have)
            return cli_usage_error(verb,
                                   "the synthetic asset needs about %.1f GB, more than this machine's %.1f GB allows; "
                                   "lower --vertices, --channels, --active or --density",
                                   need / 1e9, have / 1e9);
    }
    cli_progress progress;
    cli_progress_init(&progress, args->quiet || args->json);
    pb_asset l;
    mk_error err;
    memset(&l, 0, sizeof l);
    mk_result r;
    double t_build = bench_now_ns();
    cli_progress_update(&progress, file ? "loading the asset" : "building the synthetic asset", -1);
    if (file) {
        r = pb_asset_load(file, NULL, NULL, &l, &err);
    } else {
        mk_raw_init(&l.raw, NULL);
        r = bench_build_synthetic(&o, &l.raw, &err);
        if (!r) r = mk_write_blob(&l.raw, NULL, &l.raw.arena, &l.blob, &l.blob_size, &l.report, &err);
        if (!r) r = mk_asset_open(l.blob, l.blob_size, &l.asset, &err);
    }
    if (r) {
        pb_asset_free(&l);
        return cli_fail(verb->name, &err);
    }
    t_build = bench_now_ns() - t_build;
    const mk_asset *a = &l.asset;

    /* Weight sets: a clip sampled at evenly spaced times, or `active` fixed channels with
     * weights that change every frame (progressive channels cross their in-between). */
    float *weights = calloc((size_t)frames * a->channel_count + 1, sizeof(float));
    if (!weights) return 1;
    for (uint32_t f = 0; f < frames; f++) {
        float *w = weights + (size_t)f * a->channel_count;
        if (file) {
            mk_clip_info clip;
            double t = 0;
            if (mk_clip_get(a, 0, &clip))
                t = clip.start + clip.duration * (float)f / (float)(frames > 1 ? frames - 1 : 1);
            pb_frame_weights(a, a->clip_count ? 0 : -1, t, w, &err);
        } else {
            for (uint32_t k = 0; k < o.active; k++) {
                uint32_t c = (k * 97u) % a->channel_count;
                w[c] = 0.05f + 0.9f * (float)((f * 7u + k * 13u) % 100u) / 100.0f;
            }
        }
    }

    bench_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.asset = a;
    ctx.threads = thread_count;
    ctx.progress = progress_update;
    ctx.user = &progress;
    size_t max_vertices = 0, max_scratch = 0;
    for (uint32_t mi = 0; mi < a->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(a, mi, &m);
        if (m.vertex_count > max_vertices) max_vertices = m.vertex_count;
        if (mk_eval_scratch_size(a, mi) > max_scratch) max_scratch = mk_eval_scratch_size(a, mi);
    }
    ctx.positions = malloc(12 * max_vertices);
    ctx.out_normals = malloc(12 * max_vertices);
    ctx.scratch = calloc(thread_count, sizeof(void *));
    for (uint32_t t = 0; t < thread_count; t++) ctx.scratch[t] = aligned_alloc(16, (max_scratch + 15) & ~(size_t)15);
    pthread_t *threads = calloc(thread_count, sizeof(pthread_t));
    worker *workers = calloc(thread_count, sizeof(worker));
    if (thread_count > 1) {
        pthread_barrier_init(&ctx.start, NULL, thread_count);
        pthread_barrier_init(&ctx.done, NULL, thread_count);
        for (uint32_t t = 1; t < thread_count; t++) {
            workers[t].ctx = &ctx;
            workers[t].index = t;
            pthread_create(&threads[t], NULL, bench_worker_main, &workers[t]);
        }
    }
    if (profile) {
        /* Profiling mode: nothing but evaluation (positions + normals), for perf/callgrind. */
        timed_config config = { thread_count, MK_STACKING_ADDITIVE, 1, 0 };
        for (uint32_t k = 0; k < profile; k++) bench_time_configs(&ctx, weights, frames, &config, 1);
        printf("profiled %u x %u frames\n", profile, frames);
        return 0;
    }
    /* Warm up once, then measure. With more than one thread the text report also times one
     * thread in the same rounds, for the scaling (--json keeps its fixed keys). */
    timed_config warm = { thread_count, MK_STACKING_ADDITIVE, 1, 0 };
    bench_time_configs(&ctx, weights, frames < 5 ? frames : 5, &warm, 1);
    copy_probe probe;
    if (copy_probe_init(&probe)) ctx.probe = &probe;
    timed_config configs[4] = {
        { thread_count, MK_STACKING_ADDITIVE, 1, 0 },
        { thread_count, MK_STACKING_ADDITIVE, 0, 0 },
        { thread_count, MK_STACKING_SEQUENTIAL, 1, 0 },
        { 1, MK_STACKING_ADDITIVE, 1, 0 },
    };
    const int scaling = thread_count > 1 && !args->json;
    bench_time_configs(&ctx, weights, frames, configs, scaling ? 4 : 3);
    double ns = configs[0].best, ns_positions = configs[1].best, ns_sequential = configs[2].best;
    double ns_one = scaling ? configs[3].best : 0, least_share = bench_least_thread_share(&ctx);
    if (thread_count > 1) {
        ctx.quit = 1;
        pthread_barrier_wait(&ctx.start);
        for (uint32_t t = 1; t < thread_count; t++) pthread_join(threads[t], NULL);
    }
    double bytes = 0;
    for (uint32_t f = 0; f < frames; f++)
        bytes += bench_frame_bytes(a, weights + (size_t)f * a->channel_count, 1, ctx.scratch[0]);
    bytes /= frames;
    for (int i = 0; i < 5; i++) copy_probe_sample(ctx.probe);
    double bandwidth = copy_probe_bandwidth(&probe);
    copy_probe_free(&probe);
    ctx.probe = NULL;
    double bound_ns = bandwidth > 0 ? bytes / bandwidth : 0;
    int status = 0;
    if (args->gpu) {
        status = report_gpu(args, a, weights, frames, bytes, ns, ns_positions, bound_ns);
        goto done;
    }
    double diff = 0;
    cli_progress_update(&progress, "naive baseline", -1);
    double naive_ns = bench_naive_frames(&l, weights, frames < 20 ? frames : 20, &diff);
    /* Normal quality (a file's normals are meant to match its surface; the synthetic asset's
     * normal deltas are made up): up to 20 of the frames, evenly spread. */
    pb_normal_stats quality[PB_QUALITY_MODES];
    memset(quality, 0, sizeof quality);
    double ns_surface_nlerp = 0, ns_surface = 0, ns_bare_nlerp = 0, ns_bare = 0;
    if (file && !profile) {
        cli_progress_update(&progress, "surface normals", -1);
        bench_surface_frames(&l, &l, weights, frames < 20 ? frames : 20, &ns_surface_nlerp, &ns_surface);
        /* The same asset without target normals, as `import --target-normals none` writes it for
         * a program that only uses surface normals. */
        pb_asset bare;
        memset(&bare, 0, sizeof bare);
        mk_raw_init(&bare.raw, NULL);
        mk_error bare_err;
        uint32_t quantized, floats;
        double step_error;
        cli_precision_of(a, &quantized, &floats, &step_error);
        const mk_write_options bare_write = { .precision = quantized ? MK_PRECISION_Q16 : MK_PRECISION_FLOAT };
        mk_result br = mk_read_blob(a, &bare.raw, &bare_err);
        if (br == MK_OK) {
            mk_raw_drop_target_normals(&bare.raw);
            br = pb_asset_open_raw(&bare, &bare_write, &bare_err);
        }
        if (br == MK_OK) bench_surface_frames(&l, &bare, weights, frames < 20 ? frames : 20, &ns_bare_nlerp, &ns_bare);
        else fprintf(stderr, "morphkit bench: surface normals without target normals not measured: %s\n", bare_err.message);
        pb_asset_free(&bare);
        cli_progress_update(&progress, "normal quality", -1);
        if (measure_normals(&l, weights, frames, quality, &err) != MK_OK) {
            fprintf(stderr, "morphkit bench: normal quality not measured: %s\n", err.message);
            memset(quality, 0, sizeof quality);
        }
    }

    if (args->json) {
        printf("{\"ns_per_frame\": %.0f, \"ns_per_frame_positions\": %.0f, \"bytes_per_frame\": %.0f, "
               "\"bound_ns\": %.0f, \"ratio_to_bound\": %.3f, \"naive_ns\": %.0f, \"speedup_vs_naive\": %.2f, "
               "\"sequential_over_additive\": %.3f",
               ns, ns_positions, bytes, bound_ns, bound_ns / ns, naive_ns, naive_ns / ns, ns_sequential / ns);
        if (quality[0].count) {
            printf(", \"normals_measured\": %zu", quality[0].count);
            for (int k = 0; k < PB_QUALITY_MODES; k++)
                printf(", \"normals_%s_mean_deg\": %.4f, \"normals_%s_p99_deg\": %.4f, \"normals_%s_max_deg\": %.4f",
                       pb_quality_name(k), quality[k].mean, pb_quality_name(k), quality[k].p99, pb_quality_name(k), quality[k].max);
        }
        if (ns_surface > 0)
            printf(", \"ns_per_frame_surface\": %.0f, \"surface_over_nlerp\": %.3f", ns_surface,
                   ns_surface / ns_surface_nlerp);
        if (ns_bare > 0)
            printf(", \"ns_per_frame_surface_without_target_normals\": %.0f, "
                   "\"surface_without_target_normals_over_nlerp\": %.3f",
                   ns_bare, ns_bare / ns_bare_nlerp);
        printf("}\n");
    } else {
        uint32_t vertices = 0;
        for (uint32_t mi = 0; mi < a->mesh_count; mi++) {
            mk_mesh_info m;
            mk_mesh_get(a, mi, &m);
            vertices += m.vertex_count;
        }
        printf("asset: %s, %u meshes, %u vertices, %u channels, %u targets, blob %.1f MB (built in %.1f s)\n",
               file ? file : "synthetic", a->mesh_count, vertices, a->channel_count, a->target_count,
               (double)l.blob_size / 1e6, t_build / 1e9);
        printf("threads: %u, frames: %u\n", thread_count, frames);
        printf("ns_per_frame             %12.0f  (positions + normals)\n", ns);
        printf("ns_per_frame_positions   %12.0f\n", ns_positions);
        printf("bytes_per_frame          %12.0f\n", bytes);
        printf("bound_ns                 %12.0f  (copy bandwidth %.2f GB/s)\n", bound_ns, bandwidth);
        printf("ratio_to_bound           %12.3f\n", bound_ns / ns);
        printf("naive_ns                 %12.0f  (dense float loop; max |difference| %.3g)\n", naive_ns, diff);
        printf("speedup_vs_naive         %12.2f\n", naive_ns / ns);
        printf("sequential_over_additive %12.3f\n", ns_sequential / ns);
        if (ns_surface > 0)
            printf("surface_over_nlerp       %12.3f  (positions + surface normals %.0f ns, positions + nlerp %.0f ns; "
                   "one thread, alternating per frame)\n",
                   ns_surface / ns_surface_nlerp, ns_surface, ns_surface_nlerp);
        if (ns_bare > 0)
            printf("surface_without_target_normals_over_nlerp %.3f  (positions + surface normals on a copy without "
                   "target normals %.0f ns, positions + nlerp %.0f ns; alternating per frame)\n",
                   ns_bare / ns_bare_nlerp, ns_bare, ns_bare_nlerp);
        if (quality[0].count) {
            printf("normal error vs the evaluated surface (degrees over %zu moved vertex-frames: mean / p99 / max):\n",
                   quality[0].count);
            for (int k = 0; k < PB_QUALITY_MODES; k++)
                printf("  %-22s %9.4f / %9.4f / %9.4f\n", pb_quality_label(k), quality[k].mean, quality[k].p99, quality[k].max);
        }
        if (ns_one > 0) {
            printf("thread_scaling           %12.2f  (1 thread %.0f ns, %u threads %.0f ns; passes alternating)\n",
                   ns_one / ns, ns_one, thread_count, ns);
            printf("least_thread_share       %12.2f  (of the %u-thread passes' chunks; %.2f is even)\n", least_share,
                   thread_count, 1.0 / thread_count);
        }
    }
done:
    for (uint32_t t = 0; t < thread_count; t++) free(ctx.scratch[t]);
    free(ctx.scratch);
    free(ctx.positions);
    free(ctx.out_normals);
    free(threads);
    free(workers);
    free(weights);
    pb_asset_free(&l);
    return status;
}

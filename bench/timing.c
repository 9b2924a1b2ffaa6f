/* SPDX-License-Identifier: MIT */
/* The benchmark's timing harness: a pool of threads that split a mesh as a job system would,
 * configurations timed round-robin, and the bytes a frame must move. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "clock.h"
#include "timing.h"

/* Threads split a mesh the way a job system would: into ranges of BENCH_CHUNK_BLOCKS
 * 64-vertex blocks (so no two jobs share a block), each one mk_eval_run job, taken from a
 * shared counter until none is left. Dynamic assignment keeps both threads busy when the
 * active targets are unevenly spread over the mesh. One thread runs the whole mesh as one job. */
#define BENCH_CHUNK_BLOCKS 256u

static void run_range(bench_ctx *c, uint32_t index, const mk_mesh_info *m, uint32_t first, uint32_t last)
{
    mk_eval_job job = {
        .asset = c->asset,
        .mesh = c->mesh,
        .first_vertex = first,
        .vertex_count = last - first,
        .weights = c->weights + m->first_channel,
        .weight_count = m->channel_count,
        .stacking = c->stacking,
        .scratch = c->scratch[index],
        .scratch_size = mk_eval_scratch_size(c->asset, c->mesh),
        .positions = c->positions + 3 * (size_t)first,
        .positions_size = 12 * (size_t)(last - first),
        .normals = c->normals && m->has_normals ? c->out_normals + 3 * (size_t)first : NULL,
        .normals_size = 12 * (size_t)(last - first),
    };
    mk_error err;
    if (mk_eval_run(&job, &err) != MK_OK) {
        fprintf(stderr, "bench: eval failed: %s\n", err.message);
        exit(1);
    }
}

static void run_slice(bench_ctx *c, uint32_t index)
{
    mk_mesh_info m;
    mk_mesh_get(c->asset, c->mesh, &m);
    if (c->running == 1) {
        run_range(c, index, &m, 0, m.vertex_count);
        return;
    }
    const uint32_t chunk = BENCH_CHUNK_BLOCKS * 64;
    for (;;) {
        uint32_t k = atomic_fetch_add(&c->next_chunk, 1);
        if ((uint64_t)k * chunk >= m.vertex_count) return;
        uint32_t first = k * chunk, last = m.vertex_count - first < chunk ? m.vertex_count : first + chunk;
        run_range(c, index, &m, first, last);
        c->chunks[index][0]++;
    }
}

void *bench_worker_main(void *arg)
{
    worker *w = arg;
    for (;;) {
        pthread_barrier_wait(&w->ctx->start);
        if (w->ctx->quit) return NULL;
        run_slice(w->ctx, w->index);
        pthread_barrier_wait(&w->ctx->done);
    }
}

/* Rounds over the configurations; each result is its best pass. The machines this runs on are
 * shared, and interference comes in bursts of a second or more, so more passes give steadier
 * numbers. */
#define BENCH_PASSES 5

/* One pass over the frames with `running` threads (1 or the pool); ns per frame. */
static double time_pass(bench_ctx *c, const float *weight_sets, uint32_t frames, uint32_t running)
{
    c->running = running;
    double t0 = bench_now_ns();
    for (uint32_t f = 0; f < frames; f++) {
        c->weights = weight_sets + (size_t)f * c->asset->channel_count;
        for (uint32_t mi = 0; mi < c->asset->mesh_count; mi++) {
            c->mesh = mi;
            atomic_store(&c->next_chunk, 0);
            if (running > 1) pthread_barrier_wait(&c->start);
            run_slice(c, 0);
            if (running > 1) pthread_barrier_wait(&c->done);
        }
    }
    return (bench_now_ns() - t0) / frames;
}

/* Times the configurations round-robin, BENCH_PASSES rounds, one pass of each per round, and
 * keeps each one's best pass; a memory-copy sample follows each round. Interleaving means a
 * burst of interference on the shared host (seconds long) costs each configuration one pass
 * rather than all of one configuration's passes, and the ratios between them (thread scaling,
 * sequential over additive, ratio to the copy bound) compare passes from the same stretch of
 * time. The chunks each thread takes in pool passes are counted in c->chunks. */
void bench_time_configs(bench_ctx *c, const float *weight_sets, uint32_t frames, timed_config *configs, int count)
{
    memset(c->chunks, 0, sizeof c->chunks);
    for (int i = 0; i < count; i++) configs[i].best = INFINITY;
    for (int pass = 0; pass < BENCH_PASSES; pass++) {
        for (int i = 0; i < count; i++) {
            c->stacking = configs[i].stacking;
            c->normals = configs[i].normals;
            double t = time_pass(c, weight_sets, frames, configs[i].running);
            if (t < configs[i].best) configs[i].best = t;
        }
        copy_probe_sample(c->probe);
        if (c->progress) c->progress(c->user, "timing passes", (double)(pass + 1) / BENCH_PASSES);
    }
}

/* The smallest fraction of the pool passes' chunks one thread took: 1/T when the threads
 * kept pace; near 0 when a core was taken from this process, which explains poor scaling. */
double bench_least_thread_share(const bench_ctx *c)
{
    uint64_t total = 0, least = UINT64_MAX;
    for (uint32_t t = 0; t < c->threads; t++) {
        total += c->chunks[t][0];
        if (c->chunks[t][0] < least) least = c->chunks[t][0];
    }
    return total ? (double)least / (double)total : 0;
}

/* Bytes a frame must touch (mk_eval_traffic, summed over the meshes). */
double bench_frame_bytes(const mk_asset *a, const float *weights, int normals, void *scratch)
{
    double bytes = 0;
    for (uint32_t mi = 0; mi < a->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(a, mi, &m);
        static float sink[3];
        mk_eval_job job = {
            .asset = a,
            .mesh = mi,
            .vertex_count = MK_VERTICES_TO_END,
            .weights = weights + m.first_channel,
            .weight_count = m.channel_count,
            .scratch = scratch,
            .scratch_size = mk_eval_scratch_size(a, mi),
            /* Output spans are only validated, never written. */
            .positions = sink,
            .positions_stride = 12,
            .positions_size = SIZE_MAX,
            .normals = normals && m.has_normals ? sink : NULL,
            .normals_stride = 12,
            .normals_size = SIZE_MAX,
        };
        bytes += (double)mk_eval_traffic(&job);
    }
    return bytes;
}

/* SPDX-License-Identifier: MIT */
/* Timing evaluation the way an engine runs it: a pool of threads taking ranges of a mesh. */
#ifndef MK_BENCH_TIMING_H
#define MK_BENCH_TIMING_H

#include <pthread.h>
#include <stdatomic.h>
#include "copy_probe.h"
#include "morphkit.h"

typedef struct bench_ctx {
    const mk_asset *asset;
    uint32_t mesh;
    const float *weights; /* asset-wide weights of the current frame */
    mk_stacking stacking;
    int normals;
    float *positions, *out_normals;
    void **scratch;   /* one per thread */
    uint32_t threads; /* threads in the pool */
    uint32_t running; /* threads evaluating this pass: 1 or `threads` */
    pthread_barrier_t start, done;
    atomic_uint next_chunk; /* next range of the current mesh to evaluate */
    int quit;
    copy_probe *probe; /* sampled after each round of timed passes, or NULL */
    void (*progress)(void *user, const char *stage, double fraction); /* may be NULL */
    void *user;
    uint64_t chunks[64][8]; /* chunks each thread evaluated (one cache line per thread) */
} bench_ctx;

typedef struct worker {
    bench_ctx *ctx;
    uint32_t index;
} worker;

/* One measured configuration: threads running, stacking, normals; best ns per frame. */
typedef struct timed_config {
    uint32_t running;
    mk_stacking stacking;
    int normals;
    double best;
} timed_config;

/* Rounds over the configurations; each result is its best pass. */
#define BENCH_PASSES 5

/* A pool thread's loop (index >= 1); the caller's thread is index 0. */
void *bench_worker_main(void *worker);
/* Times the configurations round-robin and keeps each one's best pass (ns per frame). */
void bench_time_configs(bench_ctx *c, const float *weight_sets, uint32_t frames, timed_config *configs, int count);
/* The smallest fraction of the pool passes' chunks one thread took. */
double bench_least_thread_share(const bench_ctx *c);
/* Bytes a frame must touch (mk_eval_traffic over the meshes); scratch of the largest mesh. */
double bench_frame_bytes(const mk_asset *a, const float *weights, int normals, void *scratch);

#endif

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
#include "cli.h"
#include "frame.h"

typedef struct bench_options {
    uint32_t vertices, channels, active, threads, frames;
    uint32_t profile;          /* --profile N: only N evaluation frames (for perf/callgrind) */
    double density;
    int json;
} bench_options;

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* ---- synthetic asset ---- */

/* A w x h grid (wavy height) with normals; targets move the vertices inside 3 disks. */
static mk_result build_synthetic(const bench_options *o, mk_raw_asset *raw, mk_error *err)
{
    uint32_t w = (uint32_t)ceil(sqrt((double)o->vertices));
    uint32_t h = (o->vertices + w - 1) / w;
    uint32_t n = o->vertices;
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    if (!m) return mk_error_oom(err, "building the synthetic mesh");
    m->name = mk_arena_strdup(&raw->arena, "synthetic");
    m->vertex_count = n;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    uint32_t quads = (w - 1) * (h - 1);
    m->triangles = mk_arena_array(&raw->arena, 6 * (size_t)quads, sizeof(uint32_t));
    if (!m->name || !m->positions || !m->normals || !m->triangles) return mk_error_oom(err, "building the synthetic mesh");
    for (uint32_t v = 0; v < n; v++) {
        float x = (float)(v % w) / (float)w, y = (float)(v / w) / (float)h;
        m->positions[3 * v] = x;
        m->positions[3 * v + 1] = y;
        m->positions[3 * v + 2] = 0.02f * sinf(20 * x) * cosf(17 * y);
        m->normals[3 * v + 2] = 1;
    }
    uint32_t t = 0;
    for (uint32_t y = 0; y + 1 < h; y++)
        for (uint32_t x = 0; x + 1 < w; x++) {
            uint32_t a = y * w + x, b = a + 1, c = a + w, d = c + 1;
            if (d >= n) continue;
            uint32_t *tri = &m->triangles[6 * (size_t)t++];
            tri[0] = a; tri[1] = b; tri[2] = d; tri[3] = a; tri[4] = d; tri[5] = c;
        }
    m->triangle_count = 2 * t;
    uint32_t progressive = o->channels / 5;
    mk_raw_channel *channels = mk_raw_add_channels(raw, o->channels);
    if (!channels) return mk_error_oom(err, "building channels");
    uint32_t *scratch = mk_arena_array(&raw->arena, n, sizeof(uint32_t));
    if (!scratch) return mk_error_oom(err, "building channels");
    double radius = sqrt(o->density * (double)n / (3.0 * 3.14159265)) ;
    uint64_t seed = 12345;
    for (uint32_t c = 0; c < o->channels; c++) {
        mk_raw_channel *ch = &channels[c];
        char name[32];
        snprintf(name, sizeof name, "channel%03u", c);
        ch->name = mk_arena_strdup(&raw->arena, name);
        uint32_t targets = c < progressive ? 2 : 1;
        if (!mk_raw_add_targets(raw, ch, targets)) return mk_error_oom(err, "building targets");
        /* Three disk centres per channel (an LCG keeps it deterministic). */
        double cx[3], cy[3];
        for (int k = 0; k < 3; k++) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            cx[k] = radius + (double)(seed >> 33) / 2147483648.0 * (w - 2 * radius);
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            cy[k] = radius + (double)(seed >> 33) / 2147483648.0 * (h - 2 * radius);
        }
        uint32_t count = 0;
        for (uint32_t v = 0; v < n; v++) {
            double x = v % w, y = v / w;
            for (int k = 0; k < 3; k++)
                if ((x - cx[k]) * (x - cx[k]) + (y - cy[k]) * (y - cy[k]) < radius * radius) { scratch[count++] = v; break; }
        }
        for (uint32_t k = 0; k < targets; k++) {
            mk_raw_target *tg = &ch->targets[k];
            tg->full_weight = targets == 2 ? (k == 0 ? 0.5f : 1.0f) : 1.0f;
            tg->name = ch->name;
            tg->count = count;
            tg->indices = mk_arena_array(&raw->arena, count + 1u, sizeof(uint32_t));
            tg->positions = mk_arena_array(&raw->arena, 3 * (size_t)count + 3, sizeof(float));
            tg->normals = mk_arena_array(&raw->arena, 3 * (size_t)count + 3, sizeof(float));
            if (!tg->indices || !tg->positions || !tg->normals) return mk_error_oom(err, "building targets");
            memcpy(tg->indices, scratch, count * sizeof(uint32_t));
            for (uint32_t j = 0; j < count; j++) {
                float s = (float)(k + 1) * 0.01f * (float)((j * 2654435761u) % 1000) / 1000.0f;
                tg->positions[3 * j + 2] = s;
                tg->positions[3 * j] = 0.3f * s;
                tg->normals[3 * j] = 0.2f * s;
                tg->normals[3 * j + 1] = -0.1f * s;
            }
        }
    }
    return MK_OK;
}

/* ---- timing harness ---- */

/* Memory-copy bandwidth: copies of 256 MiB (read + write counted), best of all samples.
 * Samples are taken between the evaluation passes as well as at the end, so the bound and
 * the frame time come from the same stretch of time on a shared host. */
typedef struct copy_probe {
    char *a, *b;
    size_t size;
    double best_ns;
    int flip;
} copy_probe;

static int copy_probe_init(copy_probe *p)
{
    p->size = (size_t)256 << 20;
    p->a = malloc(p->size);
    p->b = malloc(p->size);
    p->best_ns = INFINITY;
    p->flip = 0;
    if (!p->a || !p->b) return 0;
    memset(p->a, 1, p->size);
    memset(p->b, 2, p->size);
    return 1;
}

/* p is NULL when copy_probe_init failed (then nothing is sampled). */
static void copy_probe_sample(copy_probe *p)
{
    if (!p) return;
    double t0 = now_ns();
    memcpy(p->flip ? p->a : p->b, p->flip ? p->b : p->a, p->size);
    double t = now_ns() - t0;
    p->flip = !p->flip;
    volatile char sink = p->a[p->size / 2] + p->b[p->size / 3];
    (void)sink;
    if (t < p->best_ns) p->best_ns = t;
}

/* Bytes per ns, or 0 when the buffers could not be allocated. */
static double copy_probe_bandwidth(const copy_probe *p)
{
    return isfinite(p->best_ns) ? 2.0 * (double)p->size / p->best_ns : 0;
}

static void copy_probe_free(copy_probe *p)
{
    free(p->a);
    free(p->b);
}

typedef struct bench_ctx {
    const mk_asset *asset;
    uint32_t mesh;
    const float *weights;      /* asset-wide weights of the current frame */
    mk_stacking stacking;
    int normals;
    float *positions, *out_normals;
    void **scratch;            /* one per thread */
    uint32_t threads;          /* threads in the pool */
    uint32_t running;          /* threads evaluating this pass: 1 or `threads` */
    pthread_barrier_t start, done;
    atomic_uint next_chunk;    /* next range of the current mesh to evaluate */
    int quit;
    copy_probe *probe;         /* sampled after each round of timed passes, or NULL */
    cli_progress *progress;
    uint64_t chunks[64][8];    /* chunks each thread evaluated (one cache line per thread) */
} bench_ctx;

typedef struct worker { bench_ctx *ctx; uint32_t index; } worker;

/* Threads split a mesh the way a job system would: into ranges of BENCH_CHUNK_BLOCKS
 * 64-vertex blocks (so no two jobs share a block), each one mk_eval_run job, taken from a
 * shared counter until none is left. Dynamic assignment keeps both threads busy when the
 * active targets are unevenly spread over the mesh. One thread runs the whole mesh as one job. */
#define BENCH_CHUNK_BLOCKS 256u

static void run_range(bench_ctx *c, uint32_t index, const mk_mesh_info *m, uint32_t first, uint32_t last)
{
    mk_eval_job job = {
        .asset = c->asset, .mesh = c->mesh, .first_vertex = first, .vertex_count = last - first,
        .weights = c->weights + m->first_channel, .weight_count = m->channel_count, .stacking = c->stacking,
        .scratch = c->scratch[index], .scratch_size = mk_eval_scratch_size(c->asset, c->mesh),
        .positions = c->positions + 3 * (size_t)first, .positions_size = 12 * (size_t)(last - first),
        .normals = c->normals && m->has_normals ? c->out_normals + 3 * (size_t)first : NULL,
        .normals_size = 12 * (size_t)(last - first),
    };
    mk_error err;
    if (mk_eval_run(&job, &err) != MK_OK) { fprintf(stderr, "bench: eval failed: %s\n", err.message); exit(1); }
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

static void *worker_main(void *arg)
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
    double t0 = now_ns();
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
    return (now_ns() - t0) / frames;
}

/* One measured configuration: threads running, stacking, normals; best ns per frame. */
typedef struct timed_config {
    uint32_t running;
    mk_stacking stacking;
    int normals;
    double best;
} timed_config;

/* Times the configurations round-robin, BENCH_PASSES rounds, one pass of each per round, and
 * keeps each one's best pass; a memory-copy sample follows each round. Interleaving means a
 * burst of interference on the shared host (seconds long) costs each configuration one pass
 * rather than all of one configuration's passes, and the ratios between them (thread scaling,
 * sequential over additive, ratio to the copy bound) compare passes from the same stretch of
 * time. The chunks each thread takes in pool passes are counted in c->chunks. */
static void time_configs(bench_ctx *c, const float *weight_sets, uint32_t frames, timed_config *configs, int count)
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
        if (c->progress) cli_progress_update(c->progress, "timing passes", (double)(pass + 1) / BENCH_PASSES);
    }
}

/* The smallest fraction of the pool passes' chunks one thread took: 1/T when the threads
 * kept pace; near 0 when a core was taken from this process, which explains poor scaling. */
static double least_thread_share(const bench_ctx *c)
{
    uint64_t total = 0, least = UINT64_MAX;
    for (uint32_t t = 0; t < c->threads; t++) {
        total += c->chunks[t][0];
        if (c->chunks[t][0] < least) least = c->chunks[t][0];
    }
    return total ? (double)least / (double)total : 0;
}

/* Bytes a frame must touch (mk_eval_traffic, summed over the meshes). */
static double frame_bytes(const mk_asset *a, const float *weights, int normals, void *scratch)
{
    double bytes = 0;
    for (uint32_t mi = 0; mi < a->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(a, mi, &m);
        static float sink[3];
        mk_eval_job job = {
            .asset = a, .mesh = mi, .vertex_count = MK_VERTICES_TO_END, .weights = weights + m.first_channel,
            .weight_count = m.channel_count, .scratch = scratch, .scratch_size = mk_eval_scratch_size(a, mi),
            /* Output spans are only validated, never written. */
            .positions = sink, .positions_stride = 12, .positions_size = SIZE_MAX,
            .normals = normals && m.has_normals ? sink : NULL, .normals_stride = 12, .normals_size = SIZE_MAX,
        };
        bytes += (double)mk_eval_traffic(&job);
    }
    return bytes;
}

/* The naive baseline: dense float deltas for every target, a loop over all vertices for
 * each active target, then normals normalized. Returns ns per frame; checks its output
 * against the runtime's (max abs difference into *diff). */
static double naive_frames(const pb_asset *l, const float *weight_sets, uint32_t frames, double *diff)
{
    const mk_asset *a = &l->asset;
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    if (mk_read_blob(a, &raw, &err)) { fprintf(stderr, "bench: %s\n", err.message); exit(1); }
    /* Which targets are ever active: only those get dense arrays (memory). Targets are
     * numbered across the asset, channel by channel, as in the blob. */
    uint32_t *first_target = calloc(raw.channel_count + 1u, sizeof *first_target);
    if (!first_target) { fprintf(stderr, "bench: out of memory\n"); exit(1); }
    for (uint32_t c = 0; c < raw.channel_count; c++) first_target[c + 1] = first_target[c] + raw.channels[c].target_count;
    double total = 0;
    *diff = 0;
    for (uint32_t mi = 0; mi < raw.mesh_count; mi++) {
        const mk_raw_mesh *m = &raw.meshes[mi];
        size_t n = m->vertex_count;
        /* Dense arrays per asset target (indexed like the blob's target table). */
        float **dense_p = calloc(a->target_count + 1u, sizeof(float *));
        float **dense_n = calloc(a->target_count + 1u, sizeof(float *));
        float *out_p = malloc(12 * n), *out_n = malloc(12 * n);
        mk_mesh_info info;
        mk_mesh_get(a, mi, &info);
        for (uint32_t c = info.first_channel; c < info.first_channel + info.channel_count; c++) {
            int ever = 0;
            for (uint32_t f = 0; f < frames; f++) ever |= weight_sets[(size_t)f * a->channel_count + c] != 0;
            if (!ever) continue;
            const mk_raw_channel *ch = &raw.channels[c];
            for (uint32_t k = 0; k < ch->target_count; k++) {
                const mk_raw_target *t = &ch->targets[k];
                float *dp = calloc(3 * n, sizeof(float)), *dn = calloc(3 * n, sizeof(float));
                for (uint32_t j = 0; j < t->count; j++)
                    for (int d = 0; d < 3; d++) {
                        dp[3 * (size_t)t->indices[j] + (size_t)d] = t->positions[3 * (size_t)j + (size_t)d];
                        if (t->normals) dn[3 * (size_t)t->indices[j] + (size_t)d] = t->normals[3 * (size_t)j + (size_t)d];
                    }
                dense_p[first_target[c] + k] = dp;
                dense_n[first_target[c] + k] = dn;
            }
        }
        double best = INFINITY;
        for (int pass = 0; pass < BENCH_PASSES; pass++) {
            double t0 = now_ns();
            for (uint32_t f = 0; f < frames; f++) {
                const float *w = weight_sets + (size_t)f * a->channel_count;
                memcpy(out_p, m->positions, 12 * n);
                if (m->normals) memcpy(out_n, m->normals, 12 * n);
                for (uint32_t c = info.first_channel; c < info.first_channel + info.channel_count; c++) {
                    if (w[c] == 0) continue;
                    int32_t ia, ib;
                    float ca, cb;
                    pb_channel_span(a, c, w[c], &ia, &ca, &ib, &cb);
                    for (int side = 0; side < 2; side++) {
                        int32_t k = side ? ib : ia;
                        float coef = side ? cb : ca;
                        if (k < 0 || !dense_p[first_target[c] + (uint32_t)k]) continue;
                        const float *dp = dense_p[first_target[c] + (uint32_t)k], *dn = dense_n[first_target[c] + (uint32_t)k];
                        for (size_t i = 0; i < 3 * n; i++) out_p[i] += coef * dp[i];
                        if (m->normals) for (size_t i = 0; i < 3 * n; i++) out_n[i] += coef * dn[i];
                    }
                }
                if (m->normals)
                    for (size_t v = 0; v < n; v++) {
                        float *q = &out_n[3 * v];
                        float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                        if (len > 1e-8f) { q[0] /= len; q[1] /= len; q[2] /= len; }
                    }
            }
            double t = (now_ns() - t0) / frames;
            if (t < best) best = t;
        }
        total += best;
        /* Check: the last frame against the runtime. */
        float *rp = malloc(12 * n), *rn = malloc(12 * n);
        if (pb_eval_mesh(a, mi, weight_sets + (size_t)(frames - 1) * a->channel_count, MK_STACKING_ADDITIVE,
                            MK_NORMALS_NLERP, rp, m->normals ? rn : NULL, &err) == MK_OK)
            for (size_t i = 0; i < 3 * n; i++) {
                double d = fabs((double)rp[i] - out_p[i]);
                if (d > *diff) *diff = d;
            }
        free(rp);
        free(rn);
        for (uint32_t k = 0; k < a->target_count; k++) { free(dense_p[k]); free(dense_n[k]); }
        free(dense_p);
        free(dense_n);
        free(out_p);
        free(out_n);
    }
    free(first_target);
    mk_raw_free(&raw);
    return total;
}

typedef struct bench_args {
    const char *file;
    uint64_t vertices, channels, active, threads, frames, profile;
    double density;
    int json, quiet;
} bench_args;

static int run_bench(void *p);

static const cli_option options[] = {
    { "--vertices", "N", CLI_UINT, offsetof(bench_args, vertices), "Synthetic mesh size, in vertices.", "1000000", NULL, 64,
      100000000, 0, 0 },
    { "--channels", "C", CLI_UINT, offsetof(bench_args, channels),
      "Synthetic channels (one in five progressive, with an in-between at 0.5).", "100", NULL, 1, 100000, 0, 0 },
    { "--active", "A", CLI_UINT, offsetof(bench_args, active), "Synthetic channels with a nonzero weight in each frame (<= C).",
      "30", NULL, 0, 100000, 0, 0 },
    { "--density", "D", CLI_NUMBER, offsetof(bench_args, density),
      "Fraction of the vertices each synthetic target moves (in a few coherent regions).", "0.1", NULL, 1e-6, 0.3, 0, 0 },
    { "--threads", "T", CLI_UINT, offsetof(bench_args, threads),
      "Evaluation threads (ranges of 256 blocks taken from a shared counter).", "1", NULL, 1, 64, 0, 0 },
    { "--frames", "F", CLI_UINT, offsetof(bench_args, frames),
      "Weight sets per pass (with FILE: its first clip at F evenly spaced times).", "100", NULL, 1, 100000, 0, 0 },
    { "--json", NULL, CLI_FLAG, offsetof(bench_args, json), "Print one JSON object with the measured keys only.", NULL, NULL,
      0, 0, 0, 0 },
    { "--profile", "N", CLI_UINT, offsetof(bench_args, profile),
      "Profiling mode: only N rounds of evaluation (for perf or callgrind), no baselines.", NULL, NULL, 1, 1000000, 0, 0 },
    { "--quiet", NULL, CLI_FLAG, offsetof(bench_args, quiet), "No progress lines.", NULL, NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_bench = {
    "bench", "[FILE] [options]", "measure evaluation speed against baselines run in the same process",
    "Times the runtime's evaluation (positions + normals, positions only, sequential stacking) and prints it with ratios "
    "against baselines measured in the same run: the memory-copy bound for the bytes a frame touches, and a naive dense "
    "loop. Without FILE a synthetic asset is built (--vertices, --channels, --active, --density).",
    "FILE", "An asset to play instead of the synthetic one (its first clip).", offsetof(bench_args, file), 0,
    options, sizeof options / sizeof options[0], sizeof(bench_args), run_bench,
};

/* Bytes of memory the machine has, or 0 when unknown. */
static double machine_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (double)pages * (double)page : 0;
}

/* What the synthetic benchmark will allocate, roughly: the raw model and its blob (base
 * arrays, triangles, target deltas), the naive baseline's copy and dense arrays of the active
 * targets, the outputs and the copy probe. */
static double synthetic_bytes(const bench_options *o)
{
    double n = (double)o->vertices, targets = 1.2 * (double)o->channels;
    double base = n * (24 + 24 + 24 + 24 + 24);
    double deltas = targets * o->density * n * 28.0 * 3;
    double dense = 1.2 * (double)o->active * n * 24.0;
    return base + deltas + dense + (double)(512u << 20);
}

static int run_bench(void *p)
{
    bench_args *args = p;
    const cli_verb *verb = &cli_verb_bench;
    bench_options o = { (uint32_t)args->vertices, (uint32_t)args->channels, (uint32_t)args->active, (uint32_t)args->threads,
                        (uint32_t)args->frames, (uint32_t)args->profile, args->density, args->json };
    const char *file = args->file;
    if (o.active > o.channels) return cli_usage_error(verb, "--active %u is more than --channels %u", o.active, o.channels);
    if (!file) {
        double need = synthetic_bytes(&o), have = machine_memory();
        if (have > 0 && need > 0.8 * have)
            return cli_usage_error(verb, "the synthetic asset needs about %.1f GB, more than this machine's %.1f GB allows; "
                                   "lower --vertices, --channels, --active or --density", need / 1e9, have / 1e9);
    }
    cli_progress progress;
    cli_progress_init(&progress, args->quiet || args->json);
    pb_asset l;
    mk_error err;
    memset(&l, 0, sizeof l);
    mk_result r;
    double t_build = now_ns();
    cli_progress_update(&progress, file ? "loading the asset" : "building the synthetic asset", -1);
    if (file) {
        r = pb_asset_load(file, NULL, NULL, &l, &err);
    } else {
        mk_raw_init(&l.raw, NULL);
        r = build_synthetic(&o, &l.raw, &err);
        if (!r) r = mk_write_blob(&l.raw, NULL, &l.raw.arena, &l.blob, &l.blob_size, &l.report, &err);
        if (!r) r = mk_asset_open(l.blob, l.blob_size, &l.asset, &err);
    }
    if (r) { pb_asset_free(&l); return cli_fail(verb->name, &err); }
    t_build = now_ns() - t_build;
    const mk_asset *a = &l.asset;

    /* Weight sets: a clip sampled at evenly spaced times, or `active` fixed channels with
     * weights that change every frame (progressive channels cross their in-between). */
    uint32_t frames = o.frames;
    float *weights = calloc((size_t)frames * a->channel_count + 1, sizeof(float));
    if (!weights) return 1;
    for (uint32_t f = 0; f < frames; f++) {
        float *w = weights + (size_t)f * a->channel_count;
        if (file) {
            mk_clip_info clip;
            double t = 0;
            if (mk_clip_get(a, 0, &clip)) t = clip.start + clip.duration * (float)f / (float)(frames > 1 ? frames - 1 : 1);
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
    ctx.threads = o.threads;
    ctx.progress = &progress;
    size_t max_vertices = 0, max_scratch = 0;
    for (uint32_t mi = 0; mi < a->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(a, mi, &m);
        if (m.vertex_count > max_vertices) max_vertices = m.vertex_count;
        if (mk_eval_scratch_size(a, mi) > max_scratch) max_scratch = mk_eval_scratch_size(a, mi);
    }
    ctx.positions = malloc(12 * max_vertices);
    ctx.out_normals = malloc(12 * max_vertices);
    ctx.scratch = calloc(o.threads, sizeof(void *));
    for (uint32_t t = 0; t < o.threads; t++) ctx.scratch[t] = aligned_alloc(16, (max_scratch + 15) & ~(size_t)15);
    pthread_t *threads = calloc(o.threads, sizeof(pthread_t));
    worker *workers = calloc(o.threads, sizeof(worker));
    if (o.threads > 1) {
        pthread_barrier_init(&ctx.start, NULL, o.threads);
        pthread_barrier_init(&ctx.done, NULL, o.threads);
        for (uint32_t t = 1; t < o.threads; t++) {
            workers[t].ctx = &ctx;
            workers[t].index = t;
            pthread_create(&threads[t], NULL, worker_main, &workers[t]);
        }
    }
    if (o.profile) {
        /* Profiling mode: nothing but evaluation (positions + normals), for perf/callgrind. */
        timed_config profile = { o.threads, MK_STACKING_ADDITIVE, 1, 0 };
        for (uint32_t k = 0; k < o.profile; k++) time_configs(&ctx, weights, frames, &profile, 1);
        printf("profiled %u x %u frames\n", o.profile, frames);
        return 0;
    }
    /* Warm up once, then measure. With more than one thread the text report also times one
     * thread in the same rounds, for the scaling (--json keeps its fixed keys). */
    timed_config warm = { o.threads, MK_STACKING_ADDITIVE, 1, 0 };
    time_configs(&ctx, weights, frames < 5 ? frames : 5, &warm, 1);
    copy_probe probe;
    if (copy_probe_init(&probe)) ctx.probe = &probe;
    timed_config configs[4] = {
        { o.threads, MK_STACKING_ADDITIVE, 1, 0 },
        { o.threads, MK_STACKING_ADDITIVE, 0, 0 },
        { o.threads, MK_STACKING_SEQUENTIAL, 1, 0 },
        { 1, MK_STACKING_ADDITIVE, 1, 0 },
    };
    const int scaling = o.threads > 1 && !o.json;
    time_configs(&ctx, weights, frames, configs, scaling ? 4 : 3);
    double ns = configs[0].best, ns_positions = configs[1].best, ns_sequential = configs[2].best;
    double ns_one = scaling ? configs[3].best : 0, least_share = least_thread_share(&ctx);
    if (o.threads > 1) {
        ctx.quit = 1;
        pthread_barrier_wait(&ctx.start);
        for (uint32_t t = 1; t < o.threads; t++) pthread_join(threads[t], NULL);
    }
    double bytes = 0;
    for (uint32_t f = 0; f < frames; f++) bytes += frame_bytes(a, weights + (size_t)f * a->channel_count, 1, ctx.scratch[0]);
    bytes /= frames;
    for (int i = 0; i < 5; i++) copy_probe_sample(ctx.probe);
    double bandwidth = copy_probe_bandwidth(&probe);
    copy_probe_free(&probe);
    ctx.probe = NULL;
    double bound_ns = bandwidth > 0 ? bytes / bandwidth : 0;
    double diff = 0;
    cli_progress_update(&progress, "naive baseline", -1);
    double naive_ns = naive_frames(&l, weights, frames < 20 ? frames : 20, &diff);

    if (o.json) {
        printf("{\"ns_per_frame\": %.0f, \"ns_per_frame_positions\": %.0f, \"bytes_per_frame\": %.0f, "
               "\"bound_ns\": %.0f, \"ratio_to_bound\": %.3f, \"naive_ns\": %.0f, \"speedup_vs_naive\": %.2f, "
               "\"sequential_over_additive\": %.3f}\n",
               ns, ns_positions, bytes, bound_ns, bound_ns / ns, naive_ns, naive_ns / ns, ns_sequential / ns);
    } else {
        uint32_t vertices = 0;
        for (uint32_t mi = 0; mi < a->mesh_count; mi++) { mk_mesh_info m; mk_mesh_get(a, mi, &m); vertices += m.vertex_count; }
        printf("asset: %s, %u meshes, %u vertices, %u channels, %u targets, blob %.1f MB (built in %.1f s)\n",
               file ? file : "synthetic", a->mesh_count, vertices, a->channel_count, a->target_count,
               (double)l.blob_size / 1e6, t_build / 1e9);
        printf("threads: %u, frames: %u\n", o.threads, frames);
        printf("ns_per_frame             %12.0f  (positions + normals)\n", ns);
        printf("ns_per_frame_positions   %12.0f\n", ns_positions);
        printf("bytes_per_frame          %12.0f\n", bytes);
        printf("bound_ns                 %12.0f  (copy bandwidth %.2f GB/s)\n", bound_ns, bandwidth);
        printf("ratio_to_bound           %12.3f\n", bound_ns / ns);
        printf("naive_ns                 %12.0f  (dense float loop; max |difference| %.3g)\n", naive_ns, diff);
        printf("speedup_vs_naive         %12.2f\n", naive_ns / ns);
        printf("sequential_over_additive %12.3f\n", ns_sequential / ns);
        if (ns_one > 0) {
            printf("thread_scaling           %12.2f  (1 thread %.0f ns, %u threads %.0f ns; passes alternating)\n",
                   ns_one / ns, ns_one, o.threads, ns);
            printf("least_thread_share       %12.2f  (of the %u-thread passes' chunks; %.2f is even)\n", least_share,
                   o.threads, 1.0 / o.threads);
        }
    }
    for (uint32_t t = 0; t < o.threads; t++) free(ctx.scratch[t]);
    free(ctx.scratch);
    free(ctx.positions);
    free(ctx.out_normals);
    free(threads);
    free(workers);
    free(weights);
    pb_asset_free(&l);
    return 0;
}

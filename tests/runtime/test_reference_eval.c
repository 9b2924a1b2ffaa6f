/* SPDX-License-Identifier: MIT */
/* The runtime against the reference evaluator (reference_eval.c, docs/semantics.md in double
 * precision from the raw model), not against itself.
 *
 * test_random_assets: random assets (1-6 channels of 1-4 in-betweens with negative and
 * positive full weights; targets moving none, a few, most or all vertices, in runs or
 * scattered; meshes mostly of 65-300 vertices, not multiples of 64, so blocks are crossed and
 * the last one is partial; base normals unit or not, normals and tangents present or not) and
 * random weights in [-2, 3] (also exactly 0, exactly at full weights, beyond the first and
 * last key). Each asset is written as a float32 and as a quantized blob (mk_write_blob), opened,
 * and evaluated (mk_eval_run) for both normal modes and every job stacking (the blob's own,
 * which is random, and both overrides), over the whole mesh and a random vertex range.
 * Tolerances are derived, not tuned (reference_eval.c): a few float ulps of the magnitudes
 * involved, plus for quantized blobs the writer's reported quantization error times the sum of the
 * |coefficients|; normals and tangents as angles.
 *
 *   MK_REF_SEED=N    runs only asset N, printing details (every failure prints its seed)
 *   MK_REF_ASSETS=N  number of random assets, each with 2 weight vectors (default 1500)
 *
 * The other cases pin what random assets rarely hit, against hand-computed values: sequential
 * stacking's beta (negative full weights, the first in-between, no positive full weight, both
 * clamps), slerp between two in-betweens, extrapolated, under sequential stacking, with
 * identical, opposite and nearly opposite ends (the lerp fallback and its threshold), and
 * normal deltas that cancel the base normal. */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "mat4.h"
#include "check.h"
#include "fixtures.h"
#include "reference_eval.h"
#include "random_asset.h"

#define PI 3.14159265358979323846

/* ---- one case ---- */

enum { WEIGHT_SETS = 2 };

typedef struct totals {
    uint64_t cases, jobs, failed_cases;
    ref_stats stats[2];   /* float, q16 blobs */
} totals;

static const char *stacking_name(mk_stacking s)
{
    return s == MK_STACKING_ASSET ? "asset" : s == MK_STACKING_ADDITIVE ? "additive" : "sequential";
}

static void describe_asset(const mk_raw_asset *raw, const float *weights)
{
    const mk_raw_mesh *m = &raw->meshes[0];
    fprintf(stderr, "  mesh: %u vertices, normals %s, tangents %s, blob stacking %s\n", m->vertex_count,
            m->normals ? "yes" : "no", m->tangents ? "yes" : "no", stacking_name(m->stacking));
    for (uint32_t c = 0; c < raw->channel_count; c++) {
        const mk_raw_channel *ch = &raw->channels[c];
        fprintf(stderr, "  channel %u: w = %.9g, full weights", c, (double)weights[c]);
        for (uint32_t k = 0; k < ch->target_count; k++)
            fprintf(stderr, " %.9g (%u moved%s%s)", (double)ch->targets[k].full_weight, ch->targets[k].count,
                    ch->targets[k].normals ? ", normals" : "", ch->targets[k].tangents ? ", tangents" : "");
        fputc('\n', stderr);
    }
}

/* Runs one runtime job over [first, first + count) and compares it with the reference.
 * n and t may be NULL: those outputs are not requested. */
static uint32_t run_job(const mk_asset *asset, const mk_raw_asset *raw, const float *weights, mk_stacking stacking,
                        mk_normal_mode mode, uint32_t first, uint32_t count, const ref_job *rj, const ref_vertex *expected,
                        void *scratch, size_t scratch_size, float *p, float *n, float *t, ref_mismatch *mismatch,
                        ref_stats *stats)
{
    const mk_raw_mesh *m = &raw->meshes[0];
    mk_eval_job job = { .asset = asset, .mesh = 0, .first_vertex = first, .vertex_count = count, .weights = weights,
                        .weight_count = raw->channel_count, .stacking = stacking, .normal_mode = mode,
                        .scratch = scratch, .scratch_size = scratch_size, .positions = p,
                        .positions_size = 12u * (size_t)count, .normals = m->normals ? n : NULL,
                        .normals_size = 12u * (size_t)count, .tangents = m->tangents ? t : NULL,
                        .tangents_size = 16u * (size_t)count };
    if (count == m->vertex_count - first && (first & 1)) job.vertex_count = MK_VERTICES_TO_END;
    mk_error err;
    if (mk_eval_run(&job, &err) != MK_OK) {
        *mismatch = (ref_mismatch){ first, err.message, 0, 0, 0, 0 };
        return 1;
    }
    return ref_compare(rj, expected, first, count, p, job.normals, job.tangents, mismatch, stats);
}

/* Builds, writes and evaluates case `seed`; returns the number of failed jobs. */
static int run_case(uint64_t seed, int verbose, totals *tot)
{
    rng r = { seed * 0x2545f4914f6cdd1dull + 1 };
    mk_raw_asset raw;
    random_asset(&r, &raw);
    const mk_raw_mesh *m = &raw.meshes[0];
    const uint32_t n = m->vertex_count;
    /* The writer's mask rule: the default (0), exact masks (1), whole blocks (65), or any. */
    static const uint32_t limits[] = { 0, 1, 2, 5, 9, 65 };
    const uint32_t pick = below(&r, 7), gap_limit = pick < 6 ? limits[pick] : below(&r, 66);

    /* The two blobs. q16 sometimes with the default tolerance (entries that would err too
     * much are float), else one that quantizes every target. */
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset assets[2];
    ref_stored_error stored[2] = { { 0, 0, 0 }, { 0, 0, 0 } };
    const char *precision_name[2] = { "float", "q16" };
    int failed = 0;
    for (int q = 0; q < 2; q++) {
        mk_write_options o = { .precision = q ? MK_PRECISION_Q16 : MK_PRECISION_FLOAT,
                               .tolerance = q && chance(&r, 0.7) ? 1e3f : 0.0f, .gap_limit = gap_limit };
        void *blob;
        size_t size;
        mk_write_report report;
        mk_error err;
        if (mk_write_blob(&raw, &o, &arena, &blob, &size, &report, &err) != MK_OK
            || mk_asset_open(blob, size, &assets[q], &err) != MK_OK) {
            fprintf(stderr, "case %llu (MK_REF_SEED=%llu): %s blob: %s\n", (unsigned long long)seed,
                    (unsigned long long)seed, precision_name[q], err.message);
            mk_arena_free_all(&arena);
            mk_raw_free(&raw);
            return 1;
        }
        if (q) stored[q] = (ref_stored_error){ report.max_position_error, report.max_normal_error, report.max_tangent_error };
    }

    size_t scratch_size = mk_eval_scratch_size(&assets[0], 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    float *p = malloc(12u * n), *nr = malloc(12u * n), *tg = malloc(16u * n), *weights = malloc(4u * raw.channel_count);
    ref_vertex *expected = malloc(sizeof(ref_vertex) * n);
    for (int set = 0; set < WEIGHT_SETS; set++) {
        for (uint32_t c = 0; c < raw.channel_count; c++) weights[c] = random_weight(&r, &raw.channels[c]);
        tot->cases++;
        int case_failed = 0;
        for (int q = 0; q < 2; q++)
            for (int mode = MK_NORMALS_NLERP; mode <= MK_NORMALS_SLERP; mode++)
                for (int effective = MK_STACKING_ADDITIVE; effective <= MK_STACKING_SEQUENTIAL; effective++) {
                    ref_job rj;
                    ref_job_init(&rj, &raw, 0, weights, (mk_stacking)effective, (mk_normal_mode)mode, stored[q]);
                    ref_eval_mesh(&rj, expected);
                    /* The explicit override, and the blob's own setting where it is this one. */
                    mk_stacking job_stackings[2] = { (mk_stacking)effective, MK_STACKING_ASSET };
                    int job_count = m->stacking == (mk_stacking)effective ? 2 : 1;
                    for (int js = 0; js < job_count; js++) {
                        uint32_t first = below(&r, n), count = 1 + below(&r, n - first);
                        const uint32_t ranges[2][2] = { { 0, n }, { first, count } };
                        for (int range = 0; range < 2; range++) {
                            ref_mismatch mm;
                            tot->jobs++;
                            /* Normals and tangents are optional outputs: mostly requested. */
                            float *want_n = chance(&r, 0.8) ? nr : NULL, *want_t = chance(&r, 0.8) ? tg : NULL;
                            uint32_t bad = run_job(&assets[q], &raw, weights, job_stackings[js], (mk_normal_mode)mode,
                                                   ranges[range][0], ranges[range][1], &rj, expected, scratch,
                                                   scratch_size, p, want_n, want_t, &mm, &tot->stats[q]);
                            if (!bad) continue;
                            failed++;
                            if (!case_failed++ || verbose) {
                                fprintf(stderr,
                                        "case %llu (rerun: MK_REF_SEED=%llu) weights %d: %s blob, job stacking %s "
                                        "(evaluates %s), normals %s, vertices [%u, %u): %u mismatches; first: vertex %u %s",
                                        (unsigned long long)seed, (unsigned long long)seed, set, precision_name[q],
                                        stacking_name(job_stackings[js]), stacking_name((mk_stacking)effective),
                                        mode ? "slerp" : "nlerp", ranges[range][0], ranges[range][0] + ranges[range][1],
                                        bad, mm.vertex, mm.what);
                                if (mm.component >= 0) fprintf(stderr, "[%d] = %.9g, expected %.9g", mm.component, mm.got, mm.expected);
                                else fprintf(stderr, " off by %.3g rad", mm.got);
                                fprintf(stderr, " (tolerance %.3g)\n", mm.tolerance);
                                if (case_failed == 1) describe_asset(&raw, weights);
                            }
                        }
                    }
                }
        if (case_failed) tot->failed_cases++;
        if (verbose && !case_failed) {
            fprintf(stderr, "case %llu weights %d: ok\n", (unsigned long long)seed, set);
            describe_asset(&raw, weights);
        }
    }
    free(expected);
    free(weights);
    free(tg);
    free(nr);
    free(p);
    free(scratch);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
    return failed;
}

static void test_random_assets(void)
{
    const char *one = getenv("MK_REF_SEED"), *assets = getenv("MK_REF_ASSETS");
    totals tot;
    memset(&tot, 0, sizeof tot);
    clock_t start = clock();
    if (one && *one) {
        uint64_t seed = strtoull(one, NULL, 10);
        CHECK_MSG(run_case(seed, 1, &tot) == 0, "case %llu failed", (unsigned long long)seed);
    } else {
        uint64_t count = assets && *assets ? strtoull(assets, NULL, 10) : 1500;
        for (uint64_t seed = 1; seed <= count; seed++) run_case(seed, 0, &tot);
        CHECK_MSG(tot.failed_cases == 0, "%llu of %llu cases failed (seeds above)", (unsigned long long)tot.failed_cases,
                  (unsigned long long)tot.cases);
    }
    printf("random assets: %llu cases (asset + weights), %llu jobs, %llu + %llu vertices compared (float, q16), "
           "%llu + %llu unstable normals skipped, %.2f s\n",
           (unsigned long long)tot.cases, (unsigned long long)tot.jobs, (unsigned long long)tot.stats[0].vertices,
           (unsigned long long)tot.stats[1].vertices, (unsigned long long)tot.stats[0].normals_skipped,
           (unsigned long long)tot.stats[1].normals_skipped, (double)(clock() - start) / CLOCKS_PER_SEC);
    for (int q = 0; q < 2; q++)
        printf("  %s blobs: worst error / tolerance: positions %.3g, normal angles %.3g, tangent angles %.3g\n",
               q ? "q16" : "float", tot.stats[q].worst_ratio[0], tot.stats[q].worst_ratio[1], tot.stats[q].worst_ratio[2]);
}


/* ---- hand-computed cases ---- */

typedef struct hand_target {
    float full_weight;
    uint32_t count;
    const uint32_t *indices;
    const float *positions, *normals, *tangents;   /* 3 per index; normals/tangents may be NULL */
} hand_target;

static void *copy_into(mk_raw_asset *raw, const void *src, size_t bytes)
{
    if (!src) return NULL;
    void *p = mk_arena_alloc(&raw->arena, bytes);
    memcpy(p, src, bytes);
    return p;
}

static void hand_mesh(mk_raw_asset *raw, uint32_t n, const float *positions, const float *normals, const float *tangents)
{
    mk_raw_init(raw, NULL);
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = mk_arena_strdup(&raw->arena, "hand");
    mk_mat4_identity(m->world);
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = -1;
    m->vertex_count = m->control_point_count = n;
    m->stacking = MK_STACKING_ADDITIVE;
    m->positions = copy_into(raw, positions, 12u * n);
    m->normals = copy_into(raw, normals, 12u * n);
    m->tangents = copy_into(raw, tangents, 16u * n);
}

static void hand_channel(mk_raw_asset *raw, const char *name, uint32_t count, const hand_target *targets)
{
    mk_raw_add_channels(raw, 1);
    mk_raw_channel *ch = &raw->channels[raw->channel_count - 1];
    ch->name = mk_arena_strdup(&raw->arena, name);
    mk_raw_add_targets(raw, ch, count);
    for (uint32_t k = 0; k < count; k++) {
        mk_raw_target *t = &ch->targets[k];
        const hand_target *h = &targets[k];
        t->name = ch->name;
        t->full_weight = h->full_weight;
        t->count = h->count;
        t->indices = copy_into(raw, h->indices, 4u * h->count);
        t->positions = copy_into(raw, h->positions, 12u * h->count);
        t->normals = copy_into(raw, h->normals, 12u * h->count);
        t->tangents = copy_into(raw, h->tangents, 12u * h->count);
    }
}

/* A float32 blob of raw with the mesh's stacking set to `stacking`, opened. */
static void hand_open(mk_raw_asset *raw, mk_stacking stacking, mk_arena *arena, mk_asset *asset)
{
    raw->meshes[0].stacking = stacking;
    size_t size;
    void *blob = fixture_blob(raw, MK_PRECISION_FLOAT, arena, &size);
    mk_error err;
    if (mk_asset_open(blob, size, asset, &err) != MK_OK) {
        fprintf(stderr, "open: %s\n", err.message);
        exit(2);
    }
}

/* A frame of a hand-made asset: the runtime's and the reference's. */
typedef struct hand_frame {
    float positions[3 * 256], normals[3 * 256], tangents[4 * 256];
    ref_vertex ref[256];
    int ok;
} hand_frame;

static void hand_eval(const mk_raw_asset *raw, const mk_asset *asset, const float *weights, mk_stacking job_stacking,
                      mk_normal_mode mode, hand_frame *f)
{
    const mk_raw_mesh *m = &raw->meshes[0];
    _Alignas(16) unsigned char scratch[4096];
    mk_eval_job job = { .asset = asset, .vertex_count = MK_VERTICES_TO_END, .weights = weights, .weight_count = raw->channel_count, .stacking = job_stacking,
                        .normal_mode = mode, .scratch = scratch, .scratch_size = sizeof scratch,
                        .positions = f->positions, .positions_size = sizeof f->positions,
                        .normals = m->normals ? f->normals : NULL, .normals_size = sizeof f->normals,
                        .tangents = m->tangents ? f->tangents : NULL, .tangents_size = sizeof f->tangents };
    mk_error err;
    f->ok = m->vertex_count <= 256 && mk_eval_run(&job, &err) == MK_OK;
    CHECK_MSG(f->ok, "eval: %s", err.message);
    ref_job rj;
    mk_mesh_info info;
    mk_mesh_get(asset, 0, &info);
    mk_stacking effective = job_stacking == MK_STACKING_ASSET ? info.stacking : job_stacking;
    ref_job_init(&rj, raw, 0, weights, effective, mode, (ref_stored_error){ 0, 0, 0 });
    ref_eval_mesh(&rj, f->ref);
}

/* Runtime within 2e-6 (float32 rounding of values of order 1), reference within 1e-12. */
static void expect_position(const hand_frame *f, uint32_t v, double x, double y, double z, const char *label)
{
    const double e[3] = { x, y, z };
    for (int k = 0; k < 3; k++) {
        CHECK_MSG(fabs(f->positions[3 * v + (uint32_t)k] - e[k]) <= 2e-6, "%s: runtime position v%u[%d] = %.9g, expected %.9g",
                  label, v, k, (double)f->positions[3 * v + (uint32_t)k], e[k]);
        CHECK_MSG(fabs(f->ref[v].position[k] - e[k]) <= 1e-12, "%s: reference position v%u[%d] = %.17g, expected %.17g",
                  label, v, k, f->ref[v].position[k], e[k]);
    }
}

static double angle_to(const double *a, const double *b)
{
    double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

/* The runtime's unit normal within `tolerance` rad of direction (x, y, z) (no NaN), the
 * reference's within 1e-9. */
static void expect_normal(const hand_frame *f, uint32_t v, double x, double y, double z, double tolerance, const char *label)
{
    const double e[3] = { x, y, z };
    const double got[3] = { f->normals[3 * v], f->normals[3 * v + 1], f->normals[3 * v + 2] };
    double len = sqrt(got[0] * got[0] + got[1] * got[1] + got[2] * got[2]);
    double angle = angle_to(got, e), ref_angle = angle_to(f->ref[v].normal, e);
    CHECK_MSG(isfinite(len) && fabs(len - 1) <= 1e-6 && angle <= tolerance,
              "%s: runtime normal v%u = (%.9g, %.9g, %.9g), %.3g rad from (%.9g, %.9g, %.9g) (tolerance %.3g)", label, v,
              got[0], got[1], got[2], angle, x, y, z, tolerance);
    CHECK_MSG(ref_angle <= 1e-9, "%s: reference normal v%u = (%.17g, %.17g, %.17g), %.3g rad from expected", label, v,
              f->ref[v].normal[0], f->ref[v].normal[1], f->ref[v].normal[2], ref_angle);
}

/* Where B_n + d_n vanishes the base normal is kept as stored: exactly. */
static void expect_kept_normal(const hand_frame *f, const mk_raw_asset *raw, uint32_t v, const char *label)
{
    const float *b = raw->meshes[0].normals + 3 * v;
    for (int k = 0; k < 3; k++) {
        CHECK_MSG(f->normals[3 * v + (uint32_t)k] == b[k], "%s: runtime normal v%u[%d] = %.9g, expected the base %.9g",
                  label, v, k, (double)f->normals[3 * v + (uint32_t)k], (double)b[k]);
        CHECK_MSG(f->ref[v].normal[k] == b[k], "%s: reference normal v%u[%d] = %.17g, expected the base %.9g", label, v, k,
                  f->ref[v].normal[k], (double)b[k]);
    }
}

/* Sequential stacking, d_c = (1 - beta_c) d_{c-1} + D_c(w_c), beta_c = clamp(w_c / f_first, 0, 1),
 * on one vertex at the origin, with the blob's setting and with the job's override. */
static void test_sequential_beta(void)
{
    static const uint32_t v0[] = { 0 };
    static const float origin[3] = { 0, 0, 0 };
    mk_raw_asset raw;
    hand_mesh(&raw, 1, origin, NULL, NULL);
    /* f_first 0.5, a negative in-between; D(0.75) = (1, 0, 2), D(-0.5) = (0, 0.5, 0). */
    hand_target inbetweens[3] = { { -1.0f, 1, v0, (const float[]){ 0, 1, 0 }, NULL, NULL },
                                  { 0.5f, 1, v0, (const float[]){ 2, 0, 0 }, NULL, NULL },
                                  { 1.0f, 1, v0, (const float[]){ 0, 0, 4 }, NULL, NULL } };
    /* f_first 2 behind a negative key: beta = w / 2 (not w / -0.5, not w / 1). */
    hand_target first_positive_2[2] = { { -0.5f, 1, v0, (const float[]){ 1, 1, 1 }, NULL, NULL },
                                        { 2.0f, 1, v0, (const float[]){ 0, 0, 2 }, NULL, NULL } };
    /* No positive full weight: beta = 0 for every w. */
    hand_target no_positive[2] = { { -2.0f, 1, v0, (const float[]){ 5, 0, 0 }, NULL, NULL },
                                   { -1.0f, 1, v0, (const float[]){ 0, 3, 0 }, NULL, NULL } };
    /* f_first 0.25 (the first in-between, not the last): beta reaches 1 at w = 0.25. */
    hand_target quarter[2] = { { 0.25f, 1, v0, (const float[]){ 1, 0, 0 }, NULL, NULL },
                               { 1.0f, 1, v0, (const float[]){ 0, 1, 0 }, NULL, NULL } };
    hand_channel(&raw, "inbetweens", 3, inbetweens);
    hand_channel(&raw, "first_positive_2", 2, first_positive_2);
    hand_channel(&raw, "no_positive", 2, no_positive);
    hand_channel(&raw, "quarter", 2, quarter);

    static const struct { float w[4]; double sequential[3], additive[3]; const char *what; } cases[] = {
        { { 0.75f, 0, 0, 0 }, { 1, 0, 2 }, { 1, 0, 2 }, "first channel alone (its beta scales nothing)" },
        { { 0.75f, 1, 0, 0 }, { 0.5, 0, 2 }, { 1, 0, 3 }, "beta 1/2 from f_first 2: 0.5 (1,0,2) + (0,0,1)" },
        { { 0.75f, -0.25f, 0, 0 }, { 1.5, 0.5, 2.5 }, { 1.5, 0.5, 2.5 }, "negative w on a later channel: beta clamps to 0" },
        { { 0.75f, 3, 0, 0 }, { 0, 0, 3 }, { 1, 0, 5 }, "w beyond f_first: beta clamps to 1, D extrapolated" },
        { { 0.75f, 0, 0.5f, 0 }, { 1, -1.5, 2 }, { 1, -1.5, 2 }, "no positive full weight, w > 0: beta 0" },
        { { 0.75f, 0, -1.5f, 0 }, { 3.5, 1.5, 2 }, { 3.5, 1.5, 2 }, "no positive full weight, w < 0: beta 0" },
        { { 0.75f, 0, 0, 0.5f }, { 2.0 / 3, 1.0 / 3, 0 }, { 1 + 2.0 / 3, 1.0 / 3, 2 }, "w above the first in-between: beta 1" },
        { { 0.75f, 0, 0, 0.25f }, { 1, 0, 0 }, { 2, 0, 2 }, "w at the first in-between: beta exactly 1" },
        { { 0.75f, 0, 0, 0.125f }, { 1, 0, 1 }, { 1.5, 0, 2 }, "beta 1/2 from f_first 0.25" },
        { { 0.75f, 0, 0, -0.25f }, { 0, 0, 2 }, { 0, 0, 2 }, "negative w with a positive f_first: beta 0, D extrapolated" },
        { { -0.5f, 0, 0, 0.125f }, { 0.5, 0.25, 0 }, { 0.5, 0.5, 0 }, "negative in-between scaled by a later beta" },
        { { 0.75f, 1, -1.5f, 0.125f }, { 2, 0.75, 1 }, { 4, 1.5, 3 }, "the whole chain" },
    };
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset sequential_blob, additive_blob;
    hand_open(&raw, MK_STACKING_SEQUENTIAL, &arena, &sequential_blob);
    hand_open(&raw, MK_STACKING_ADDITIVE, &arena, &additive_blob);
    static hand_frame f;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const double *s = cases[i].sequential, *a = cases[i].additive;
        char label[160];
        snprintf(label, sizeof label, "%s (sequential blob)", cases[i].what);
        hand_eval(&raw, &sequential_blob, cases[i].w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
        expect_position(&f, 0, s[0], s[1], s[2], label);
        snprintf(label, sizeof label, "%s (sequential override)", cases[i].what);
        hand_eval(&raw, &additive_blob, cases[i].w, MK_STACKING_SEQUENTIAL, MK_NORMALS_NLERP, &f);
        expect_position(&f, 0, s[0], s[1], s[2], label);
        snprintf(label, sizeof label, "%s (additive blob)", cases[i].what);
        hand_eval(&raw, &additive_blob, cases[i].w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
        expect_position(&f, 0, a[0], a[1], a[2], label);
        snprintf(label, sizeof label, "%s (additive override)", cases[i].what);
        hand_eval(&raw, &sequential_blob, cases[i].w, MK_STACKING_ADDITIVE, MK_NORMALS_NLERP, &f);
        expect_position(&f, 0, a[0], a[1], a[2], label);
    }
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Slerp between the implicit key and an in-between, between two in-betweens, extrapolated on
 * both sides, against nlerp, and scaled by later channels' (1 - beta) under sequential
 * stacking. v0's normal turns from +z to +x at f = 0.5 and to +y at f = 1. */
static void test_slerp_spans(void)
{
    static const uint32_t v0[] = { 0 };
    static const float position[3] = { 0, 0, 0 }, normal[3] = { 0, 0, 1 };
    mk_raw_asset raw;
    hand_mesh(&raw, 1, position, normal, NULL);
    hand_target turn[2] = { { 0.5f, 1, v0, (const float[]){ 0, 0, 0.1f }, (const float[]){ 1, 0, -1 }, NULL },
                            { 1.0f, 1, v0, (const float[]){ 0, 0, 0.2f }, (const float[]){ 0, 1, -1 }, NULL } };
    hand_target later[1] = { { 1.0f, 1, v0, (const float[]){ 1, 0, 0 }, NULL, NULL } };   /* no normal data */
    hand_channel(&raw, "turn", 2, turn);
    hand_channel(&raw, "later", 1, later);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset additive_blob, sequential_blob;
    hand_open(&raw, MK_STACKING_ADDITIVE, &arena, &additive_blob);
    hand_open(&raw, MK_STACKING_SEQUENTIAL, &arena, &sequential_blob);
    static hand_frame f;
    const double c8 = cos(PI / 8), s8 = sin(PI / 8), tol = 2e-6;
    static const struct { float w; double n[3]; const char *what; } spans[] = {
        { 0.25f, { 1, 0, 1 }, "implicit key to the first in-between, t = 1/2" },
        { 0.5f, { 1, 0, 0 }, "at the first in-between" },
        { 0.75f, { 1, 1, 0 }, "between two in-betweens, t = 1/2" },
        { 1.0f, { 0, 1, 0 }, "at the last in-between" },
        { 1.25f, { -1, 1, 0 }, "extrapolated past the last key, t = 3/2: 135 degrees from +x" },
        { -0.25f, { -1, 0, 1 }, "extrapolated below the implicit key, t = -1/2" },
    };
    for (size_t i = 0; i < sizeof spans / sizeof spans[0]; i++) {
        float w[2] = { spans[i].w, 0 };
        hand_eval(&raw, &additive_blob, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
        expect_normal(&f, 0, spans[i].n[0], spans[i].n[1], spans[i].n[2], tol, spans[i].what);
    }
    float w[2] = { 0.625f, 0 };   /* between the in-betweens, t = 1/4 */
    hand_eval(&raw, &additive_blob, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
    expect_normal(&f, 0, c8, s8, 0, tol, "slerp at t = 1/4: 22.5 degrees from +x");
    hand_eval(&raw, &additive_blob, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
    expect_normal(&f, 0, 0.75, 0.25, 0, tol, "nlerp at t = 1/4");
    /* Sequential: "later" at w has beta = w, scaling turn's displacement slerp - n0 by 1 - w;
     * it has no normal data of its own. */
    static const struct { float w; double scale; const char *what; } later_w[] = {
        { 0.5f, 0.5, "slerp under sequential stacking, scaled by 1 - beta = 1/2" },
        { 0.25f, 0.75, "slerp under sequential stacking, scaled by 1 - beta = 3/4" },
        { 1.0f, 0.0, "slerp under sequential stacking, scaled by 1 - beta = 0" },
        { -0.5f, 1.0, "slerp under sequential stacking, negative later w: unscaled" },
        { 2.0f, 0.0, "slerp under sequential stacking, later beta clamped to 1" },
    };
    for (size_t i = 0; i < sizeof later_w / sizeof later_w[0]; i++) {
        float ws[2] = { 0.625f, later_w[i].w };
        double k = later_w[i].scale;   /* B + k (s - B), s = (c8, s8, 0) */
        hand_eval(&raw, &sequential_blob, ws, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
        expect_normal(&f, 0, k * c8, k * s8, 1 - k, tol, later_w[i].what);
        hand_eval(&raw, &additive_blob, ws, MK_STACKING_SEQUENTIAL, MK_NORMALS_SLERP, &f);
        expect_normal(&f, 0, k * c8, k * s8, 1 - k, tol, later_w[i].what);
        hand_eval(&raw, &sequential_blob, ws, MK_STACKING_ADDITIVE, MK_NORMALS_SLERP, &f);
        expect_normal(&f, 0, c8, s8, 0, tol, "the same weights, additive: unscaled");
    }
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Slerp ends that are identical, opposite and nearly opposite, alone and beside a second
 * channel. Base normals +z; channel "ends" has in-betweens at 0.5 and 1 and is evaluated at
 * w = 0.625, 0.75 and 2.5 (t = 1/4, 1/2, 4), giving the single-channel slerp S; channel "tilt"
 * turns every normal to +y at w1 = 1 (displacement y - z), so n = normalize(S + w1 (0, 1, -1))
 * for w1 = 0 and 1.
 *   v 0..63    identical ends n_a = n_b = normalize(d) for random d (a float dot product of a
 *              vector with itself may exceed 1): S = n_a for any t.
 *   v 64..127  opposite ends in the xy plane, n_b = -n_a exactly: sin theta = 0, the lerp
 *              S = (1 - 2t) n_a: at t = 1/2 with w1 = 0 the sum vanishes and the base normal is
 *              kept, at t = 4 S = -7 n_a (its length matters beside "tilt").
 *   v 128..    nearly opposite ends, n_a = +x and n_b at pi - eps from it towards +z (eps down
 *              to 2e-6, just above the 1e-6 threshold): S turns +x towards +z by t (pi - eps),
 *              where the lerp would stay near +x. The slerp weights are ~1/eps, so the float
 *              rounding of the ends and of theta near pi (~1e-7) moves S by ~1e-7 / eps:
 *              1e-6 / eps rad is allowed. At eps = 5e-7, below the threshold, S is the lerp. */
static void test_slerp_identical_and_opposite_ends(void)
{
    enum { SAME = 64, OPPOSITE = 64 };
    static const double eps[] = { 0.1, 0.01, 1e-3, 1e-4, 1e-5, 2e-6, 5e-7 };
    const uint32_t near_count = sizeof eps / sizeof eps[0], n = SAME + OPPOSITE + near_count;
    float positions[3 * 256] = { 0 }, normals[3 * 256], da[3 * 256], db[3 * 256], pa[3 * 256] = { 0 }, tilt[3 * 256];
    uint32_t indices[256];
    rng r = { 7 };
    for (uint32_t v = 0; v < n; v++) {
        indices[v] = v;
        normals[3 * v] = normals[3 * v + 1] = 0;
        normals[3 * v + 2] = 1;
        tilt[3 * v] = 0;
        tilt[3 * v + 1] = 1;
        tilt[3 * v + 2] = -1;
        float *a = da + 3 * v, *b = db + 3 * v;
        if (v < SAME) {
            for (int k = 0; k < 3; k++) a[k] = (float)uniform(&r, -1, 1);
            a[2] -= 1;   /* delta = d - B */
            memcpy(b, a, 12);
        } else if (v < SAME + OPPOSITE) {
            double phi = uniform(&r, 0, 2 * PI), len = uniform(&r, 0.2, 3);
            a[0] = (float)(len * cos(phi));
            a[1] = (float)(len * sin(phi));
            a[2] = -1;   /* B + delta_a = (x, y, 0) exactly */
            b[0] = -a[0];
            b[1] = -a[1];
            b[2] = -1;   /* B + delta_b = -(x, y, 0) exactly */
        } else {
            double e = eps[v - SAME - OPPOSITE];
            a[0] = 1, a[1] = 0, a[2] = -1;   /* n_a = +x */
            b[0] = (float)-cos(e), b[1] = 0, b[2] = (float)(sin(e) - 1);   /* n_b = (-cos e, 0, sin e) */
        }
    }
    mk_raw_asset raw;
    hand_mesh(&raw, n, positions, normals, NULL);
    hand_target ends[2] = { { 0.5f, n, indices, pa, da, NULL }, { 1.0f, n, indices, pa, db, NULL } };
    hand_target tilts[1] = { { 1.0f, n, indices, pa, tilt, NULL } };
    hand_channel(&raw, "ends", 2, ends);
    hand_channel(&raw, "tilt", 1, tilts);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset asset;
    hand_open(&raw, MK_STACKING_ADDITIVE, &arena, &asset);
    static hand_frame f;
    static const float ws[] = { 0.625f, 0.75f, 2.5f };
    for (int i = 0; i < 3; i++)
        for (int w1 = 0; w1 <= 1; w1++) {
            const double t = (ws[i] - 0.5) / 0.5;
            const float w[2] = { ws[i], (float)w1 };
            hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
            for (uint32_t v = 0; v < n; v++) {
                char label[128];
                const float *a = da + 3 * v;
                if (v < SAME) {
                    double len = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (a[2] + 1.0) * (a[2] + 1.0));
                    snprintf(label, sizeof label, "identical ends, t = %g, tilt %d", t, w1);
                    expect_normal(&f, v, a[0] / len, a[1] / len + w1, (a[2] + 1.0) / len - w1, 1e-5, label);
                } else if (v < SAME + OPPOSITE) {
                    double len = sqrt((double)a[0] * a[0] + (double)a[1] * a[1]), k = (1 - 2 * t) / len;
                    snprintf(label, sizeof label, "opposite ends, t = %g, tilt %d", t, w1);
                    if (t == 0.5 && !w1) expect_kept_normal(&f, &raw, v, label);
                    else expect_normal(&f, v, k * a[0], k * a[1] + w1, -w1, 1e-6, label);
                } else if (t < 1) {
                    /* the stored ends: (1, 0, 0) and B + delta_b, at pi - e from it */
                    double bx = db[3 * v], bz = 1.0 + (double)db[3 * v + 2], len = sqrt(bx * bx + bz * bz);
                    double e = atan2(bz, -bx), angle = t * (PI - e);
                    snprintf(label, sizeof label, "nearly opposite ends, eps %g, t = %g, tilt %d", eps[v - SAME - OPPOSITE], t,
                             w1);
                    if (sin(e) >= 1e-6) expect_normal(&f, v, cos(angle), w1, sin(angle) - w1, 1e-6 / e + 1e-6, label);
                    else   /* below the threshold: the lerp */
                        expect_normal(&f, v, (1 - t) + t * bx / len, w1, t * bz / len - w1, 1e-6, label);
                }
            }
        }
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Normal deltas that cancel the base normal: nlerp keeps the base normal (as stored, even
 * when not unit) where B_n + d_n is shorter than 1e-8, and normalizes short sums above that;
 * slerp replaces a span end shorter than 1e-8 by normalize(B_n) (not B_n). Tangent deltas
 * likewise. Base normals +z except v3's (0, 0, 2); tangents (1, 0, 0, -1).
 *   "cancel" (f = 1): -B_n at v0, v2, v3; -B_n + (1e-5, 0, 0) at v1 (above 1e-8);
 *                     -B_n + (5e-9, 0, 0) at v4 (below 1e-8); tangent -(1, 0, 0) at v0 and v2.
 *   "turn" (f = 1): to +x at v2 and v4, to 45 degrees between +z and +x at v3.
 *   "cancel_below" (f = -1): -B_n at v3, so at w < 0 the vanishing end is span end a. */
static void test_degenerate_normals(void)
{
    static const uint32_t idx[] = { 0, 1, 2, 3, 4 }, idx_turn[] = { 2, 3, 4 }, idx3[] = { 3 };
    static const float positions[15] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0 };
    static const float normals[15] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 2, 0, 0, 1 };
    static const float tangents[20] = { 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1 };
    static const float zero[15] = { 0 };
    mk_raw_asset raw;
    hand_mesh(&raw, 5, positions, normals, tangents);
    hand_target cancel[1] = { { 1.0f, 5, idx, zero, (const float[]){ 0, 0, -1, 1e-5f, 0, -1, 0, 0, -1, 0, 0, -2, 5e-9f, 0, -1 },
                                (const float[]){ -1, 0, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 0, 0, 0 } } };
    hand_target turn[1] = { { 1.0f, 3, idx_turn, zero, (const float[]){ 1, 0, -1, 1, 0, -1, 1, 0, -1 }, NULL } };
    hand_target cancel_below[1] = { { -1.0f, 1, idx3, zero, (const float[]){ 0, 0, -2 }, NULL } };
    hand_channel(&raw, "cancel", 1, cancel);
    hand_channel(&raw, "turn", 1, turn);
    hand_channel(&raw, "cancel_below", 1, cancel_below);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset asset;
    hand_open(&raw, MK_STACKING_ADDITIVE, &arena, &asset);
    static hand_frame f;
    const double r = sqrt(0.5), c8 = cos(PI / 8), s8 = sin(PI / 8), tol = 2e-6;

    float w[3] = { 1, 0, 0 };
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
    expect_kept_normal(&f, &raw, 0, "nlerp, sum exactly zero");
    expect_normal(&f, 1, 1, 0, 0, tol, "nlerp, sum of length 1e-5 (above 1e-8) is normalized");
    expect_kept_normal(&f, &raw, 2, "nlerp, sum exactly zero");
    expect_kept_normal(&f, &raw, 3, "nlerp, sum zero: the non-unit base normal is kept as stored");
    expect_kept_normal(&f, &raw, 4, "nlerp, sum of length 5e-9 (below 1e-8): base kept");
    for (int k = 0; k < 3; k++) {
        CHECK(f.tangents[k] == tangents[k]);                 /* tangent sum zero: base kept */
        CHECK(f.ref[0].tangent[k] == tangents[k]);
    }
    CHECK(f.tangents[3] == -1 && f.ref[0].tangent[3] == -1);   /* w is the base's */
    for (int k = 0; k < 4; k++)   /* v2 too: its own base tangent (4 floats a vertex), not another's */
        CHECK_MSG(f.tangents[8 + k] == tangents[8 + k], "tangent sum zero at v2: [%d] = %.9g, expected the base %.9g", k,
                  (double)f.tangents[8 + k], (double)tangents[8 + k]);
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
    expect_normal(&f, 0, 0, 0, 1, tol, "slerp, vanishing end replaced by normalize(B_n)");
    expect_normal(&f, 1, 1, 0, 0, tol, "slerp, end of length 1e-5 is normalized");
    expect_normal(&f, 3, 0, 0, 1, tol, "slerp, vanishing end, non-unit base");
    expect_normal(&f, 4, 0, 0, 1, tol, "slerp, end of length 5e-9 replaced by normalize(B_n)");

    w[0] = 2;   /* extrapolated: nlerp sum -B; slerp of n0 with itself stays n0, of +z to +x turns 180 degrees */
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
    expect_normal(&f, 0, 0, 0, -1, tol, "nlerp at w = 2");
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
    expect_normal(&f, 0, 0, 0, 1, tol, "slerp at w = 2, vanishing end");
    expect_normal(&f, 1, 0, 0, -1, tol, "slerp at w = 2: +z through +x to -z");

    w[0] = 0.5f;   /* cancel's end vanishes (slerp: contributes nothing); turn at t = 1/2 */
    w[1] = 0.5f;
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
    expect_normal(&f, 2, r, 0, r, tol, "slerp, a vanishing end beside another channel");
    expect_normal(&f, 4, r, 0, r, tol, "slerp, an end below 1e-8 beside another channel");
    /* v3: the vanishing end is normalize(B_n) = +z, not B_n = (0, 0, 2); turn slerps +z to 22.5
     * degrees: B_n + (sin, 0, cos - 1) of 22.5 degrees */
    expect_normal(&f, 3, s8, 0, 1 + c8, tol, "slerp, vanishing end b of a non-unit base beside another channel");
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
    expect_normal(&f, 2, 1, 0, 0, tol, "nlerp, half cancelled beside another channel: (0.5, 0, 0)");
    const float below[3] = { 0, 0.5f, -0.5f };   /* v3: cancel_below's end a vanishes, t = 1/2 */
    hand_eval(&raw, &asset, below, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
    expect_normal(&f, 3, s8, 0, 1 + c8, tol, "slerp, vanishing end a of a non-unit base beside another channel");
    hand_eval(&raw, &asset, below, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
    expect_normal(&f, 3, 0.5, 0, 0.5, tol, "nlerp, half cancelled from below beside another channel");
    w[0] = 1;
    w[1] = 1;
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &f);
    expect_normal(&f, 2, r, 0, -r, tol, "nlerp, cancelled base plus a turn: (1, 0, -1)");
    hand_eval(&raw, &asset, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, &f);
    expect_normal(&f, 2, 1, 0, 0, tol, "slerp, vanishing end plus a turn");
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

CHECK_MAIN(CASE(test_random_assets), CASE(test_sequential_beta), CASE(test_slerp_spans),
           CASE(test_slerp_identical_and_opposite_ends), CASE(test_degenerate_normals))

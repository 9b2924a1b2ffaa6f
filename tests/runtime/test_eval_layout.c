/* SPDX-License-Identifier: MIT */
/* Block storage against a reference computed straight from the raw model: masks with one or
 * many runs of moved vertices (bit 0, bit 63, single bits, whole blocks, blocks stored dense
 * with zeros), partial last blocks, normals and tangents, float and packed data; the store
 * modes (cached and streaming stores write the same values for every range, stride and
 * alignment); and jobs over part of the mesh (the same bytes as the whole-mesh job). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fixtures.h"
#include "format.h"

enum { VERTICES = 300, TARGETS = 24 };

static uint64_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 33;
}

/* Uniform in [-amplitude, amplitude] in steps of amplitude / 1000. */
static float symmetric(uint64_t *s, float amplitude)
{
    return (float)((int)(lcg(s) % 2001) - 1000) * (amplitude / 1000.0f);
}

/* Whether target t moves vertex v: hand-picked masks first, then random densities. */
static int moves(uint32_t t, uint32_t v, uint64_t *seed)
{
    uint32_t b = v / 64, i = v % 64;
    switch (t) {
    case 0: return b == 0;                                      /* a whole block */
    case 1: return b == 1 && ((i >= 5 && i <= 20) || i == 30 || i >= 60);   /* runs, the last ending at bit 63 */
    case 2: return b == 2 && (i == 0 || i == 63);               /* single bits at both ends */
    case 3: return v % 2 == 0;                                  /* every other vertex: 32 one-vertex runs */
    case 4: return v >= 250;                                    /* into the partial last block */
    default: {
        uint32_t density = 1 + (t * 7) % 60;                    /* 1..60 of 64: sparse and dense blocks */
        return (uint32_t)(lcg(seed) % 64) < density;
    }
    }
}

static void build(mk_raw_asset *raw)
{
    mk_raw_init(raw, NULL);
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = mk_arena_strdup(&raw->arena, "layout");
    m->vertex_count = VERTICES;
    m->positions = mk_arena_array(&raw->arena, 3 * VERTICES, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * VERTICES, sizeof(float));
    m->tangents = mk_arena_array(&raw->arena, 4 * VERTICES, sizeof(float));
    for (uint32_t v = 0; v < VERTICES; v++) {
        m->positions[3 * v] = (float)v * 0.01f;
        m->positions[3 * v + 1] = (float)(v % 7) * 0.1f;
        m->positions[3 * v + 2] = 0.5f;
        m->normals[3 * v + 2] = 1.0f;
        m->tangents[4 * v] = 1.0f;
        m->tangents[4 * v + 3] = v % 3 ? 1.0f : -1.0f;
    }
    mk_raw_channel *channels = mk_raw_add_channels(raw, TARGETS);
    uint64_t seed = 99;
    for (uint32_t t = 0; t < TARGETS; t++) {
        mk_raw_channel *ch = &channels[t];
        char name[16];
        snprintf(name, sizeof name, "t%u", t);
        ch->name = mk_arena_strdup(&raw->arena, name);
        mk_raw_add_targets(raw, ch, 1);
        mk_raw_target *tg = &ch->targets[0];
        tg->name = ch->name;
        tg->full_weight = 1.0f;
        tg->indices = mk_arena_array(&raw->arena, VERTICES, sizeof(uint32_t));
        tg->positions = mk_arena_array(&raw->arena, 3 * VERTICES, sizeof(float));
        tg->normals = mk_arena_array(&raw->arena, 3 * VERTICES, sizeof(float));
        tg->tangents = mk_arena_array(&raw->arena, 3 * VERTICES, sizeof(float));
        uint32_t n = 0;
        for (uint32_t v = 0; v < VERTICES; v++) {
            if (!moves(t, v, &seed)) continue;
            tg->indices[n] = v;
            for (int k = 0; k < 3; k++) {
                tg->positions[3 * n + k] = symmetric(&seed, 0.1f);
                tg->normals[3 * n + k] = symmetric(&seed, 0.2f);
                tg->tangents[3 * n + k] = k == 2 ? 0.3f : 0.0f;
            }
            n++;
        }
        tg->count = n;
    }
}

static void normalized(float *v)
{
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++) v[k] /= len;
}

/* base + sum of w_t * delta_t, normals and tangents renormalized (nlerp). */
static void reference(const mk_raw_asset *raw, const float *w, float *p, float *n, float *t)
{
    const mk_raw_mesh *m = &raw->meshes[0];
    for (uint32_t v = 0; v < VERTICES; v++) {
        memcpy(p + 3 * v, m->positions + 3 * v, 12);
        memcpy(n + 3 * v, m->normals + 3 * v, 12);
        memcpy(t + 4 * v, m->tangents + 4 * v, 16);
    }
    for (uint32_t c = 0; c < TARGETS; c++) {
        const mk_raw_target *tg = &raw->channels[c].targets[0];
        for (uint32_t j = 0; j < tg->count; j++) {
            uint32_t v = tg->indices[j];
            for (int k = 0; k < 3; k++) {
                p[3 * v + k] += w[c] * tg->positions[3 * j + k];
                n[3 * v + k] += w[c] * tg->normals[3 * j + k];
                t[4 * v + k] += w[c] * tg->tangents[3 * j + k];
            }
        }
    }
    for (uint32_t v = 0; v < VERTICES; v++) {
        normalized(n + 3 * v);
        normalized(t + 4 * v);
    }
}

typedef struct loaded {
    mk_raw_asset raw;
    mk_arena arena;
    mk_asset asset;
    void *scratch;
    size_t scratch_size;
    mk_write_report report;        /* the writer's largest errors per attribute */
} loaded;

/* gap_limit: the writer's mask rule (0 = default; 1 stores exactly the moved vertices, so
 * target 3's every other vertex is 32 one-vertex runs). tolerance: the writer's position
 * tolerance, twice that for normals and tangents (0: the defaults). */
static void load_with(loaded *l, mk_precision precision, uint32_t gap_limit, float tolerance)
{
    build(&l->raw);
    mk_arena_init(&l->arena, NULL);
    size_t size;
    void *blob;
    mk_error err;
    mk_write_options o = { .precision = precision, .gap_limit = gap_limit, .tolerance = tolerance,
                           .normal_tolerance = 2 * tolerance };
    CHECK_MSG(mk_write_blob(&l->raw, &o, &l->arena, &blob, &size, &l->report, &err) == MK_OK, "write: %s", err.message);
    CHECK_MSG(mk_asset_open(blob, size, &l->asset, &err) == MK_OK, "open: %s", err.message);
    l->scratch_size = mk_eval_scratch_size(&l->asset, 0);
    l->scratch = aligned_alloc(16, (l->scratch_size + 15) & ~(size_t)15);
}

static void load(loaded *l, mk_precision precision) { load_with(l, precision, 0, 0); }

static void unload(loaded *l)
{
    free(l->scratch);
    mk_arena_free_all(&l->arena);
    mk_raw_free(&l->raw);
}

/* write_tolerance: the writer's (0: its default). Each output may err by float rounding
 * (1e-5) plus, per target, |w| times the writer's reported largest error of that attribute
 * (0 for float storage), before renormalization. */
static void masks_match_reference(mk_precision precision, float write_tolerance, uint32_t gap_limit)
{
    loaded l;
    load_with(&l, precision, gap_limit, write_tolerance);
    /* The hand-picked masks really are stored as intended: block 1 of target 1 masked, with 21
     * moved vertices in three runs; block 0 of target 0 full. */
    const mk_blob_mesh *bm = &l.asset.meshes[0];
    const uint32_t *first = (const uint32_t *)(l.asset.data + bm->block_entries);
    const uint8_t *entries = l.asset.data + bm->entries;
    const uint32_t stride = mk_entry_stride(bm->flags);
    int seen_runs = 0, seen_full = 0;
    for (uint32_t e = first[1]; e < first[2]; e++) {
        const mk_blob_entry *en = mk_entry_at(entries, stride, e);
        if (mk_entry_target(en) == 1) seen_runs = mk_popcount64(en->mask) == 21;
    }
    for (uint32_t e = first[0]; e < first[1]; e++) {
        const mk_blob_entry *en = mk_entry_at(entries, stride, e);
        if (mk_entry_target(en) == 0) seen_full = en->mask == ~0ull;
    }
    CHECK(seen_runs && seen_full);

    float w[TARGETS], p[3 * VERTICES], n[3 * VERTICES], t[4 * VERTICES];
    float rp[3 * VERTICES], rn[3 * VERTICES], rt[4 * VERTICES];
    uint64_t seed = 5;
    for (int trial = 0; trial < 20; trial++) {
        for (int c = 0; c < TARGETS; c++)
            w[c] = trial == 0 ? 1.0f : (lcg(&seed) % 3 == 0) ? 0.0f : symmetric(&seed, 1.0f);
        reference(&l.raw, w, rp, rn, rt);
        mk_eval_job job = { .asset = &l.asset, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = TARGETS, .scratch = l.scratch,
                            .scratch_size = l.scratch_size, .positions = p, .positions_size = sizeof p,
                            .normals = n, .normals_size = sizeof n, .tangents = t, .tangents_size = sizeof t };
        mk_error err;
        CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
        double sum_w = 0, worst_p = 0, worst_n = 0, worst_t = 0;
        for (int c = 0; c < TARGETS; c++) sum_w += fabs(w[c]);
        const double bound_p = 1e-5 + sum_w * l.report.max_position_error, bound_n = 1e-5 + sum_w * l.report.max_normal_error,
                     bound_t = 1e-5 + sum_w * l.report.max_tangent_error;
        for (int i = 0; i < 3 * VERTICES; i++) {
            worst_p = fmax(worst_p, fabs(p[i] - rp[i]));
            worst_n = fmax(worst_n, fabs(n[i] - rn[i]));
        }
        for (int i = 0; i < 4 * VERTICES; i++) worst_t = fmax(worst_t, fabs(t[i] - rt[i]));
        CHECK_MSG(worst_p < bound_p && worst_n < bound_n && worst_t < bound_t, "trial %d: errors %g %g %g over %g %g %g", trial,
                  worst_p, worst_n, worst_t, bound_p, bound_n, bound_t);
    }
    unload(&l);
}

static void test_masks_match_reference_float(void)
{
    masks_match_reference(MK_PRECISION_FLOAT, 0, 0);
    masks_match_reference(MK_PRECISION_FLOAT, 0, 1);
}
static void test_masks_match_reference_q16(void)
{
    masks_match_reference(MK_PRECISION_Q16, 0, 0);
    masks_match_reference(MK_PRECISION_Q16, 0, 1);
    /* A tight tolerance: components spanning 15 and 16 bits (width code 15 is 16 bits). */
    masks_match_reference(MK_PRECISION_Q16, 2e-6f, 0);
}

/* Evaluates [first, first + count) into out (+ offset bytes) with the given store mode. */
static void eval_range(loaded *l, const float *w, mk_store_mode mode, uint32_t first, uint32_t count, size_t stride,
                       unsigned char *pos, unsigned char *nrm)
{
    mk_eval_job job = { .asset = &l->asset, .weights = w, .weight_count = TARGETS, .scratch = l->scratch,
                        .scratch_size = l->scratch_size, .first_vertex = first, .vertex_count = count,
                        .positions = (float *)(void *)pos, .positions_stride = stride,
                        .positions_size = stride * (count - 1) + 12, .normals = (float *)(void *)nrm,
                        .normals_stride = stride, .normals_size = stride * (count - 1) + 12, .store_mode = mode };
    mk_error err;
    CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
}

static void test_store_modes_write_the_same(void)
{
    loaded l;
    load(&l, MK_PRECISION_Q16);
    float w[TARGETS];
    for (int c = 0; c < TARGETS; c++) w[c] = 0.1f * (float)(c % 9) - 0.35f;
    const size_t size = 32 * VERTICES + 64;
    unsigned char *expect_p = aligned_alloc(64, size), *expect_n = aligned_alloc(64, size);
    unsigned char *got_p = aligned_alloc(64, size), *got_n = aligned_alloc(64, size);
    const struct { uint32_t first, count; } ranges[] = { { 0, VERTICES }, { 0, 64 }, { 64, 192 }, { 1, 250 }, { 63, 2 },
                                                        { 256, 44 } };
    const size_t strides[] = { 12, 16, 32 };
    const size_t offsets[] = { 0, 4, 16 };
    int cases = 0;
    for (size_t r = 0; r < sizeof ranges / sizeof ranges[0]; r++)
        for (size_t s = 0; s < 3; s++)
            for (size_t o = 0; o < 3; o++) {
                memset(expect_p, 0xAB, size); memset(expect_n, 0xAB, size);
                memset(got_p, 0xAB, size); memset(got_n, 0xAB, size);
                eval_range(&l, w, MK_STORE_CACHED, ranges[r].first, ranges[r].count, strides[s],
                           expect_p + offsets[o], expect_n + offsets[o]);
                for (int mode = MK_STORE_AUTO; mode <= MK_STORE_STREAMING; mode++) {
                    if (mode == MK_STORE_CACHED) continue;
                    memset(got_p, 0xAB, size); memset(got_n, 0xAB, size);
                    eval_range(&l, w, (mk_store_mode)mode, ranges[r].first, ranges[r].count, strides[s],
                               got_p + offsets[o], got_n + offsets[o]);
                    /* Bytes between strided vertices stay untouched, too. */
                    CHECK_MSG(!memcmp(expect_p, got_p, size) && !memcmp(expect_n, got_n, size),
                              "range %u+%u stride %zu offset %zu mode %d differs", ranges[r].first, ranges[r].count,
                              strides[s], offsets[o], mode);
                    cases++;
                }
            }
    CHECK_EQ_INT(cases, 6 * 3 * 3 * 2);
    free(expect_p); free(expect_n); free(got_p); free(got_n);
    unload(&l);
}

/* A job over part of the mesh writes exactly the bytes the whole-mesh job writes for those
 * vertices: ranges starting and ending inside blocks, every combination of optional outputs,
 * both normal modes, every store mode; packed data with normals and tangents, so entries of
 * the 40-byte stride, and components of odd widths starting at odd byte offsets. */
static void test_subranges_match_whole_mesh(void)
{
    loaded l;
    load(&l, MK_PRECISION_Q16);
    float w[TARGETS];
    for (int c = 0; c < TARGETS; c++) w[c] = 0.1f * (float)(c % 9) - 0.35f;
    static float whole_p[3 * VERTICES], whole_n[3 * VERTICES], whole_t[4 * VERTICES];
    static float p[3 * VERTICES], n[3 * VERTICES], t[4 * VERTICES];
    const struct { uint32_t first, count; } ranges[] = { { 1, 1 }, { 63, 1 }, { 63, 2 }, { 5, 59 }, { 70, 200 },
                                                        { 127, 130 }, { 250, 50 }, { 299, 1 }, { 0, VERTICES } };
    mk_error err;
    int cases = 0;
    for (int normal_mode = MK_NORMALS_NLERP; normal_mode <= MK_NORMALS_SLERP; normal_mode++) {
        mk_eval_job whole = { .asset = &l.asset, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = TARGETS, .scratch = l.scratch,
                              .scratch_size = l.scratch_size, .normal_mode = (mk_normal_mode)normal_mode,
                              .positions = whole_p, .positions_size = sizeof whole_p, .normals = whole_n,
                              .normals_size = sizeof whole_n, .tangents = whole_t, .tangents_size = sizeof whole_t };
        CHECK_MSG(mk_eval_run(&whole, &err) == MK_OK, "%s", err.message);
        for (int mode = MK_STORE_AUTO; mode <= MK_STORE_STREAMING; mode++)
            for (int outputs = 0; outputs < 4; outputs++)   /* bit 0 normals, bit 1 tangents */
                for (size_t r = 0; r < sizeof ranges / sizeof ranges[0]; r++) {
                    const uint32_t first = ranges[r].first, count = ranges[r].count;
                    mk_eval_job job = whole;
                    job.first_vertex = first;
                    job.vertex_count = count;
                    job.store_mode = (mk_store_mode)mode;
                    job.positions_size = 12 * (size_t)count;
                    job.positions = p;
                    job.normals = outputs & 1 ? n : NULL;
                    job.normals_size = 12 * (size_t)count;
                    job.tangents = outputs & 2 ? t : NULL;
                    job.tangents_size = 16 * (size_t)count;
                    CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
                    int same = !memcmp(p, whole_p + 3 * first, 12 * (size_t)count)
                            && (!(outputs & 1) || !memcmp(n, whole_n + 3 * first, 12 * (size_t)count))
                            && (!(outputs & 2) || !memcmp(t, whole_t + 4 * first, 16 * (size_t)count));
                    CHECK_MSG(same, "range %u+%u normals %d store %d outputs %d differs", first, count, normal_mode,
                              mode, outputs);
                    cases++;
                }
    }
    CHECK_EQ_INT(cases, 2 * 3 * 4 * 9);
    unload(&l);
}

CHECK_MAIN(CASE(test_masks_match_reference_float), CASE(test_masks_match_reference_q16),
           CASE(test_store_modes_write_the_same), CASE(test_subranges_match_whole_mesh))

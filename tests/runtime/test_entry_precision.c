/* SPDX-License-Identifier: MIT */
/* The writer's per-entry choices and what the runtime makes of them: a quantized target with
 * one outlier block stores that block's entry as float32 and the others as int16, its scales
 * taken from the int16 entries; evaluation and read-back stay within the tolerance. And the
 * mask rule (mk_block_mask): which vertices an entry stores. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "block_mask.h"
#include "check.h"
#include "fixtures.h"
#include "format.h"

#define VERTICES 300u
#define OUTLIER 70u                /* vertex in block 1 */
#define TOLERANCE 0.001f

static void write_open(const mk_raw_asset *raw, const mk_write_options *o, mk_arena *arena, mk_asset *a,
                       mk_write_report *rep)
{
    void *blob;
    size_t size;
    mk_error err;
    CHECK_MSG(mk_write_blob(raw, o, arena, &blob, &size, rep, &err) == MK_OK, "write: %s", err.message);
    CHECK_MSG(mk_asset_open(blob, size, a, &err) == MK_OK, "open: %s", err.message);
}

/* mk_eval_traffic of a whole-mesh positions-only job at these weights. */
static uint64_t traffic(const mk_asset *a, const float *weights, float *positions)
{
    size_t scratch_size = mk_eval_scratch_size(a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    mk_eval_job job = { .asset = a, .vertex_count = MK_VERTICES_TO_END, .weights = weights, .weight_count = 4,
                        .scratch = scratch, .scratch_size = scratch_size, .positions = positions,
                        .positions_size = 12u * VERTICES };
    uint64_t bytes = mk_eval_traffic(&job);
    free(scratch);
    return bytes;
}

static void test_outlier_block_is_float(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, VERTICES, 4, 1);   /* every target moves all 300 vertices: 5 blocks */
    mk_raw_target *t3 = &raw.channels[3].targets[0];
    t3->positions[3 * OUTLIER + 1] = 1000.0f;   /* needs a step of 1000 / 32767: far over the tolerance */
    /* The scale the int16 entries should get: from every block but the outlier's. */
    float others = 0;
    for (uint32_t j = 0; j < t3->count; j++)
        if (t3->indices[j] / 64 != OUTLIER / 64)
            for (int k = 0; k < 3; k++) others = fmaxf(others, fabsf(t3->positions[3 * j + (uint32_t)k]));
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_write_options o = { .precision = MK_PRECISION_Q16, .tolerance = TOLERANCE };
    mk_asset a;
    mk_write_report rep;
    write_open(&raw, &o, &arena, &a, &rep);
    CHECK_EQ_INT(rep.quantized_targets, 4);
    CHECK_EQ_INT(rep.float_targets, 0);
    CHECK_EQ_INT(rep.float_entries, 1);
    CHECK_MSG(rep.max_position_error <= TOLERANCE, "error %g over the tolerance", rep.max_position_error);
    const mk_blob_target *bt = &a.targets[3];
    CHECK(bt->flags & MK_TARGET_QUANTIZED);
    CHECK_MSG(bt->position_scale == others / 32767.0f, "scale %g, expected %g (the other blocks')",
              (double)bt->position_scale, (double)(others / 32767.0f));
    const mk_blob_mesh *bm = &a.meshes[0];
    const uint32_t *first = (const uint32_t *)(a.data + bm->block_entries);
    const mk_blob_entry *entries = (const mk_blob_entry *)(a.data + bm->entries);
    int float_seen = 0, int16_seen = 0;
    for (uint32_t b = 0; b < bm->block_count; b++)
        for (uint32_t e = first[b]; e < first[b + 1]; e++) {
            if (mk_entry_target(&entries[e]) != 3) { CHECK(mk_entry_quantized(&entries[e])); continue; }
            if (b == OUTLIER / 64) float_seen += !mk_entry_quantized(&entries[e]);
            else int16_seen += mk_entry_quantized(&entries[e]);
        }
    CHECK_EQ_INT(float_seen, 1);
    CHECK_EQ_INT(int16_seen, 4);
    mk_mesh_info mi;
    CHECK(mk_mesh_get(&a, 0, &mi) && mk_mesh_float_entries(&a, 0) == 1);

    /* Evaluation against the float model: every position within sum |w| x tolerance. */
    static const float weights[][4] = { { 0, 0, 0, 1 }, { 0.5f, -1, 0.25f, 0.75f }, { 1, 1, 1, -0.5f } };
    size_t scratch_size = mk_eval_scratch_size(&a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    float *p = malloc(12u * VERTICES), *n = malloc(12u * VERTICES);
    for (size_t w = 0; w < sizeof weights / sizeof weights[0]; w++) {
        mk_eval_job job = { .asset = &a, .vertex_count = MK_VERTICES_TO_END, .weights = weights[w], .weight_count = 4,
                            .scratch = scratch, .scratch_size = scratch_size, .positions = p,
                            .positions_size = 12u * VERTICES, .normals = n, .normals_size = 12u * VERTICES };
        mk_error err;
        CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
        double worst = 0, bound = 0;
        for (int c = 0; c < 4; c++) bound += fabs(weights[w][c]) * TOLERANCE;
        for (uint32_t v = 0; v < VERTICES; v++)
            for (uint32_t k = 0; k < 3; k++) {
                double expect = raw.meshes[0].positions[3 * v + k];
                for (uint32_t c = 0; c < 4; c++) {
                    const mk_raw_target *t = &raw.channels[c].targets[0];
                    expect += (double)weights[w][c] * t->positions[3 * v + k];   /* stride 1: index j = v */
                }
                worst = fmax(worst, fabs(p[3 * v + k] - expect));
            }
        CHECK_MSG(worst <= bound + 1e-4 * 1e-3, "weights %zu: worst position error %g over %g", w, worst, bound);
        CHECK_NEAR(p[3 * OUTLIER + 1], (double)weights[w][3] * 1000.0 + (double)weights[w][0] * raw.channels[0].targets[0].positions[3 * OUTLIER + 1]
                   + (double)weights[w][1] * raw.channels[1].targets[0].positions[3 * OUTLIER + 1]
                   + (double)weights[w][2] * raw.channels[2].targets[0].positions[3 * OUTLIER + 1], 1e-3);
    }
    /* mk_eval_traffic counts the float entry's bytes as float: target 3 alone, positions only:
     * the block table (6 values), 20 entry headers, 236 vertices of int16 positions and the
     * outlier block's 64 of float, the base read and the output written. */
    CHECK_EQ_INT(traffic(&a, weights[0], p), 4 * 6 + 16 * 20 + 6 * (VERTICES - 64) + 12 * 64 + 24 * VERTICES);
    free(scratch);
    free(p);
    free(n);

    /* Read back: the outlier exact, the rest within the reported error. */
    mk_raw_asset back;
    mk_raw_init(&back, NULL);
    mk_error err;
    CHECK(mk_read_blob(&a, &back, &err) == MK_OK);
    const mk_raw_target *u = &back.channels[3].targets[0];
    int found = 0;
    for (uint32_t j = 0; j < u->count; j++)
        if (u->indices[j] == OUTLIER) found = u->positions[3 * j + 1] == 1000.0f;
    CHECK(found);
    mk_raw_free(&back);

    /* Every block an outlier: those whose deltas spread narrowly are int16 around an offset,
     * the one with the 1000 stays float32. */
    for (uint32_t j = 0; j < t3->count; j++) t3->positions[3 * j] = 500.0f;
    write_open(&raw, &o, &arena, &a, &rep);
    CHECK_EQ_INT(rep.float_targets, 0);
    CHECK_EQ_INT(rep.float_entries, 1);
    CHECK_EQ_INT(rep.offset_entries, 4);
    CHECK(a.targets[3].flags & MK_TARGET_QUANTIZED);
    /* With a spread too wide everywhere, the target stays float. */
    for (uint32_t j = 0; j < t3->count; j++) t3->positions[3 * j] = j % 2 ? 500.0f : -500.0f;
    write_open(&raw, &o, &arena, &a, &rep);
    CHECK_EQ_INT(rep.float_targets, 1);
    CHECK_EQ_INT(rep.float_entries, 0);
    CHECK_EQ_INT(rep.offset_entries, 0);
    CHECK(!(a.targets[3].flags & MK_TARGET_QUANTIZED));
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

static uint64_t bits(const unsigned *list, size_t n)
{
    uint64_t m = 0;
    for (size_t i = 0; i < n; i++) m |= 1ull << list[i];
    return m;
}

static uint64_t range(unsigned lo, unsigned hi) { return (hi >= 63 ? ~0ull : (1ull << (hi + 1)) - 1) & ~((1ull << lo) - 1); }

/* One job's outputs: positions, normals and tangents of [first, first + count). */
static void eval_range(const mk_asset *a, const float *w, mk_normal_mode mode, uint32_t first, uint32_t count, float *p,
                       float *n, float *t)
{
    size_t scratch_size = mk_eval_scratch_size(a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    mk_eval_job job = { .asset = a, .first_vertex = first, .vertex_count = count, .weights = w, .weight_count = 4,
                        .normal_mode = mode, .scratch = scratch, .scratch_size = scratch_size,
                        .positions = p + 3 * first, .positions_size = 12u * count,
                        .normals = n + 3 * first, .normals_size = 12u * count,
                        .tangents = t + 4 * first, .tangents_size = 16u * count };
    mk_error err;
    CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
    free(scratch);
}

/* The outlier block's float entry in normals and tangents too, with nlerp and slerp, and in
 * range jobs: the mixed blob plays like the all-float one within the quantization error, and
 * any split of the vertices gives the whole-mesh bytes. */
static void test_outlier_block_every_path(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, VERTICES, 4, 1);
    mk_raw_mesh *m = &raw.meshes[0];
    m->tangents = mk_arena_array(&raw.arena, 4u * VERTICES, sizeof(float));
    for (uint32_t v = 0; v < VERTICES; v++) { m->tangents[4 * v] = 1; m->tangents[4 * v + 3] = v % 2 ? 1.0f : -1.0f; }
    for (uint32_t c = 0; c < 4; c++) {
        mk_raw_target *t = &raw.channels[c].targets[0];
        t->tangents = mk_arena_array(&raw.arena, 3u * t->count, sizeof(float));
        for (uint32_t j = 0; j < t->count; j++) t->tangents[3 * j + 2] = 0.02f * (float)((t->indices[j] + c) % 4);
    }
    mk_raw_target *t3 = &raw.channels[3].targets[0];
    t3->positions[3 * OUTLIER + 1] = 1000.0f;
    t3->normals[3 * OUTLIER + 2] = 0.5f;      /* the outlier block's normal and tangent deltas are float too */
    t3->tangents[3 * OUTLIER + 1] = 0.25f;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset mixed, exact;
    mk_write_report rep;
    mk_write_options q = { .precision = MK_PRECISION_Q16, .tolerance = TOLERANCE }, f = { .precision = MK_PRECISION_FLOAT };
    write_open(&raw, &q, &arena, &mixed, &rep);
    CHECK_EQ_INT(rep.float_entries, 1);
    /* The float block's normal deltas set no scale: the int16 blocks' do. */
    float others_n = 0;
    for (uint32_t j = 0; j < t3->count; j++)
        if (t3->indices[j] / 64 != OUTLIER / 64)
            for (int k = 0; k < 3; k++) others_n = fmaxf(others_n, fabsf(t3->normals[3 * j + (uint32_t)k]));
    CHECK_MSG(mixed.targets[3].normal_scale == others_n / 32767.0f, "normal scale %g, expected %g (the int16 blocks')",
              (double)mixed.targets[3].normal_scale, (double)(others_n / 32767.0f));
    write_open(&raw, &f, &arena, &exact, &rep);
    static const float w[4] = { 0.5f, -1, 0.25f, 0.75f };
    float *p = malloc(12u * VERTICES), *n = malloc(12u * VERTICES), *t = malloc(16u * VERTICES);
    float *pe = malloc(12u * VERTICES), *ne = malloc(12u * VERTICES), *te = malloc(16u * VERTICES);
    float *ps = malloc(12u * VERTICES), *ns = malloc(12u * VERTICES), *ts = malloc(16u * VERTICES);
    for (int mode = 0; mode < 2; mode++) {
        mk_normal_mode nm = mode ? MK_NORMALS_SLERP : MK_NORMALS_NLERP;
        eval_range(&mixed, w, nm, 0, VERTICES, p, n, t);
        eval_range(&exact, w, nm, 0, VERTICES, pe, ne, te);
        double dp = 0, dn = 0, dt = 0;
        for (uint32_t k = 0; k < 3 * VERTICES; k++) { dp = fmax(dp, fabs(p[k] - pe[k])); dn = fmax(dn, fabs(n[k] - ne[k])); }
        for (uint32_t k = 0; k < 4 * VERTICES; k++) dt = fmax(dt, fabs(t[k] - te[k]));
        CHECK_MSG(dp <= 2.5 * TOLERANCE && dn <= 1e-3 && dt <= 1e-3, "mode %d: positions %g, normals %g, tangents %g from the float blob",
                  mode, dp, dn, dt);
        /* With only the outlier's target playing, its block plays exactly as in the float blob
         * (the whole entry, normals and tangents too, is float). */
        static const float only3[4] = { 0, 0, 0, 0.75f };
        eval_range(&mixed, only3, nm, 0, VERTICES, ps, ns, ts);
        eval_range(&exact, only3, nm, 0, VERTICES, pe, ne, te);
        const size_t b0 = OUTLIER / 64 * 64;
        CHECK_MSG(memcmp(&ps[3 * b0], &pe[3 * b0], 12 * 64) == 0 && memcmp(&ns[3 * b0], &ne[3 * b0], 12 * 64) == 0
                  && memcmp(&ts[4 * b0], &te[4 * b0], 16 * 64) == 0,
                  "mode %d: the outlier block differs from the float blob's", mode);
        static const uint32_t cuts[] = { 0, 70, 128, 129, VERTICES };
        for (size_t r = 0; r + 1 < sizeof cuts / sizeof cuts[0]; r++)
            eval_range(&mixed, w, nm, cuts[r], cuts[r + 1] - cuts[r], ps, ns, ts);
        CHECK_MSG(memcmp(p, ps, 12u * VERTICES) == 0 && memcmp(n, ns, 12u * VERTICES) == 0 && memcmp(t, ts, 16u * VERTICES) == 0,
                  "mode %d: range jobs differ from the whole-mesh job", mode);
    }
    free(p); free(n); free(t); free(pe); free(ne); free(te); free(ps); free(ns); free(ts);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* A block whose deltas are large but close together (block 1 of target 3 moved 200 units along
 * x, beyond what int16 holds within the tolerance) is stored int16 around an offset: its entry
 * has MK_ENTRY_OFFSET and an exact mask, the target's scale covers the spread, and evaluation,
 * range jobs, read-back and mk_eval_traffic agree with the float model. */
static void test_offset_entry(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, VERTICES, 4, 1);
    mk_raw_mesh *m = &raw.meshes[0];   /* tangents, for eval_range */
    m->tangents = mk_arena_array(&raw.arena, 4u * VERTICES, sizeof(float));
    for (uint32_t v = 0; v < VERTICES; v++) { m->tangents[4 * v] = 1; m->tangents[4 * v + 3] = 1; }
    mk_raw_target *t3 = &raw.channels[3].targets[0];
    /* Block 1 of target 3: every third vertex left out (gaps the mask must not fill: a covered
     * vertex would read as the offset), the others moved 200 units along x. */
    uint32_t kept = 0;
    for (uint32_t j = 0; j < t3->count; j++) {
        const uint32_t v = t3->indices[j];
        if (v / 64 == 1 && v % 3 == 0) continue;
        t3->indices[kept] = v;
        memmove(&t3->positions[3 * kept], &t3->positions[3 * j], 12);
        memmove(&t3->normals[3 * kept], &t3->normals[3 * j], 12);
        if (v / 64 == 1) t3->positions[3 * kept] += 200.0f + 0.01f * (float)(j % 7);
        kept++;
    }
    t3->count = kept;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_write_options o = { .precision = MK_PRECISION_Q16, .tolerance = TOLERANCE };
    mk_write_options fo = { .precision = MK_PRECISION_FLOAT };
    mk_asset a, exact;
    mk_write_report rep;
    write_open(&raw, &fo, &arena, &exact, &rep);
    write_open(&raw, &o, &arena, &a, &rep);
    CHECK_EQ_INT(rep.float_entries, 0);
    CHECK_EQ_INT(rep.offset_entries, 1);
    CHECK_MSG(rep.max_position_error <= TOLERANCE, "error %g over the tolerance", rep.max_position_error);
    const mk_blob_mesh *bm = &a.meshes[0];
    const uint32_t *first = (const uint32_t *)(a.data + bm->block_entries);
    const mk_blob_entry *entries = (const mk_blob_entry *)(a.data + bm->entries);
    int offsets = 0;
    for (uint32_t b = 0; b < bm->block_count; b++)
        for (uint32_t e = first[b]; e < first[b + 1]; e++) {
            if (!mk_entry_has_offset(&entries[e])) continue;
            offsets++;
            CHECK(b == 1 && mk_entry_target(&entries[e]) == 3 && mk_entry_quantized(&entries[e]));
            uint64_t moved = 0;
            for (uint32_t i = 0; i < 64; i++) moved |= (uint64_t)((64 + i) % 3 != 0) << i;
            CHECK_MSG(entries[e].mask == moved, "offset entry mask %llx, moved %llx", (unsigned long long)entries[e].mask,
                      (unsigned long long)moved);
            const float *off = (const float *)(const void *)(a.data + bm->target_data + 16u * entries[e].data);
            CHECK_MSG(off[0] > 199 && off[0] < 202, "offset x %g", (double)off[0]);
        }
    CHECK_EQ_INT(offsets, 1);
    CHECK_EQ_INT(mk_mesh_offset_entries(&a, 0), 1);   /* what morphkit info counts */
    CHECK_EQ_INT(mk_mesh_float_entries(&a, 0), 0);
    CHECK_EQ_INT(mk_mesh_offset_entries(&exact, 0), 0);
    CHECK_EQ_INT(mk_mesh_offset_entries(&a, 1), 0);   /* no such mesh */
    static const float w[4] = { 0.5f, -1, 0.25f, 0.75f };
    float *p = malloc(12u * VERTICES), *n = malloc(12u * VERTICES), *t = malloc(16u * VERTICES);
    float *pe = malloc(12u * VERTICES), *ne = malloc(12u * VERTICES), *te = malloc(16u * VERTICES);
    float *ps = malloc(12u * VERTICES), *ns = malloc(12u * VERTICES), *ts = malloc(16u * VERTICES);
    eval_range(&a, w, MK_NORMALS_NLERP, 0, VERTICES, p, n, t);
    eval_range(&exact, w, MK_NORMALS_NLERP, 0, VERTICES, pe, ne, te);
    double dp = 0;
    for (uint32_t k = 0; k < 3 * VERTICES; k++) dp = fmax(dp, fabs(p[k] - pe[k]));
    CHECK_MSG(dp <= 2.5 * TOLERANCE, "positions %g from the float blob", dp);
    CHECK_NEAR(p[3 * 100], pe[3 * 100], 0.75 * TOLERANCE + 1e-4);
    static const uint32_t cuts[] = { 0, 70, 128, 129, VERTICES };
    for (size_t r = 0; r + 1 < sizeof cuts / sizeof cuts[0]; r++)
        eval_range(&a, w, MK_NORMALS_NLERP, cuts[r], cuts[r + 1] - cuts[r], ps, ns, ts);
    CHECK(memcmp(p, ps, 12u * VERTICES) == 0 && memcmp(n, ns, 12u * VERTICES) == 0);
    /* Traffic: target 3 alone, positions only: the block table, 20 headers, 300 - 21 vertices
     * of int16 positions, the offset's 16 bytes, the base read and the output written. */
    static const float only3[4] = { 0, 0, 0, 1 };
    CHECK_EQ_INT(traffic(&a, only3, p), 4 * 6 + 16 * 20 + 6 * (VERTICES - 21) + 16 + 24 * VERTICES);
    /* Read back: every delta within the reported error of the source. */
    mk_raw_asset back;
    mk_raw_init(&back, NULL);
    mk_error err;
    CHECK(mk_read_blob(&a, &back, &err) == MK_OK);
    const mk_raw_target *u = &back.channels[3].targets[0];
    CHECK_EQ_INT(u->count, t3->count);
    double worst = 0;
    for (uint32_t j = 0; j < u->count && j < t3->count; j++)
        for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(u->positions[3 * j + (uint32_t)k] - t3->positions[3 * j + (uint32_t)k]));
    CHECK_MSG(worst <= rep.max_position_error * 1.0001 + 1e-9, "read back %g, reported %g", worst, rep.max_position_error);
    mk_raw_free(&back);
    free(p); free(n); free(t); free(pe); free(ne); free(te); free(ps); free(ns); free(ts);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

static void test_gap_rule(void)
{
    static const unsigned moved[] = { 0, 1, 2, 5, 20 };
    const uint64_t m = bits(moved, 5);
    CHECK_EQ_INT(mk_block_mask(m, 64, 2), range(0, 5) | 1ull << 20);   /* gap 3-4 filled, 6-19 not */
    CHECK_EQ_INT(mk_block_mask(m, 64, 1), m);                           /* a gap of 2 stays */
    CHECK_EQ_INT(mk_block_mask(m, 64, 0), m);
    CHECK_EQ_INT(mk_block_mask(m, 64, 14), range(0, 20));   /* 6-19 is 14; 43 left (tail 21-63) > 3 x 14 */
    CHECK_EQ_INT(mk_block_mask(m, 64, 15), ~0ull);          /* 43 left <= 3 x 15: the whole block */
    /* Only the head and tail missing, each short: the whole block (the runtime's fast path). */
    CHECK_EQ_INT(mk_block_mask(range(2, 62), 64, 1), ~0ull);       /* 3 left <= 3 x 1 */
    CHECK_EQ_INT(mk_block_mask(range(2, 62), 64, 0), range(2, 62));
    CHECK_EQ_INT(mk_block_mask(range(0, 61), 64, 2), ~0ull);
    static const unsigned ends[] = { 0, 1, 2, 3, 60, 61, 62 };    /* 57 left: 4-59 and the tail 63 */
    CHECK_EQ_INT(mk_block_mask(bits(ends, 7), 64, 18), bits(ends, 7));
    CHECK_EQ_INT(mk_block_mask(bits(ends, 7), 64, 19), ~0ull);
    /* Interior gaps filled, head 1 + tail 1 <= 2. */
    static const unsigned sparse[] = { 1, 3, 5, 60, 62 };
    CHECK_EQ_INT(mk_block_mask(bits(sparse, 5) | range(5, 60), 64, 2), ~0ull);
    /* A partial last block (40 vertices): full means its 40 bits. */
    CHECK_EQ_INT(mk_block_mask(range(1, 38), 40, 2), range(0, 39));
    CHECK_EQ_INT(mk_block_mask(range(1, 38), 40, 0), range(1, 38));
    /* Every bit, the last bit, one bit. */
    CHECK_EQ_INT(mk_block_mask(~0ull, 64, 0), ~0ull);
    CHECK_EQ_INT(mk_block_mask(1ull << 63, 64, 4), 1ull << 63);
    /* Nothing moved: nothing stored; a gap so large that 3 x gap would wrap in 32 bits still
     * stores the whole block. */
    CHECK_EQ_INT(mk_block_mask(0, 64, 8), 0);
    CHECK_EQ_INT(mk_block_mask(1, 64, 0x55555556u), ~0ull);
    CHECK_EQ_INT(mk_block_mask(1ull << 63, 64, 64), ~0ull);
    CHECK_EQ_INT(mk_block_mask(1, 1, 0), 1);
    static const unsigned pair[] = { 62, 63 };
    CHECK_EQ_INT(mk_block_mask(bits(pair, 2) | 1, 64, 20), bits(pair, 2) | 1);   /* the gap 1-61: 61 > 3 x 20 */
    CHECK_EQ_INT(mk_block_mask(bits(pair, 2) | 1, 64, 21), ~0ull);
}

/* The writer uses the rule: a target moving {0, 1, 2, 5, 20} of block 0 stores bits 0-5 and 20
 * with gap_limit 3 (G = 2); with gap_limit 1 exactly the moved vertices. */
static void test_writer_masks(void)
{
    static const unsigned moved[] = { 0, 1, 2, 5, 20 };
    for (int g = 0; g < 2; g++) {
        mk_raw_asset raw;
        mk_raw_init(&raw, NULL);
        fixture_line(&raw, 64, 1, 1);
        mk_raw_target *t = &raw.channels[0].targets[0];
        for (uint32_t j = 0; j < 5; j++) {
            t->indices[j] = moved[j];
            for (int k = 0; k < 3; k++) t->positions[3 * j + (uint32_t)k] = 0.01f * (float)(j + 1);
        }
        t->count = 5;
        mk_write_options o = { .gap_limit = g ? 3 : 1 };
        mk_asset a;
        mk_write_report rep;
        write_open(&raw, &o, &raw.arena, &a, &rep);
        const mk_blob_entry *e = (const mk_blob_entry *)(a.data + a.meshes[0].entries);
        CHECK_EQ_INT(a.meshes[0].entry_count, 1);
        CHECK_EQ_INT(e->mask, g ? range(0, 5) | 1ull << 20 : bits(moved, 5));
        mk_raw_free(&raw);
    }
}

CHECK_MAIN(CASE(test_outlier_block_is_float), CASE(test_outlier_block_every_path), CASE(test_offset_entry), CASE(test_gap_rule),
           CASE(test_writer_masks))

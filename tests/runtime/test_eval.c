/* SPDX-License-Identifier: MIT */
/* Evaluation semantics (docs/semantics.md) against hand-computed values: in-betweens, negative full
 * weights, extrapolation, sequential stacking, nlerp/slerp normals, vertex ranges, strides. */
#include <stdlib.h>
#include "check.h"
#include "fixtures.h"

typedef struct setup {
    mk_raw_asset raw;
    mk_asset asset;
    void *blob;
    size_t size;
} setup;

static void open_basic(setup *s, mk_precision precision)
{
    mk_raw_init(&s->raw, NULL);
    fixture_basic(&s->raw);
    s->blob = fixture_blob(&s->raw, precision, &s->raw.arena, &s->size);
    mk_error err;
    mk_result r = mk_asset_open(s->blob, s->size, &s->asset, &err);
    CHECK_MSG(r == MK_OK, "open: %s", err.message);
}

/* Evaluates mesh 0 with mesh-local weights; positions/normals/tangents out (4 vertices). */
static mk_result eval_quad(setup *s, const float w[4], mk_stacking stacking, mk_normal_mode mode, float *p, float *n,
                           float *t)
{
    _Alignas(16) unsigned char scratch[1024];
    mk_eval_job job = { .asset = &s->asset, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = 4, .stacking = stacking,
                        .normal_mode = mode, .scratch = scratch, .scratch_size = sizeof scratch,
                        .positions = p, .positions_size = 48, .normals = n, .normals_size = 48,
                        .tangents = t, .tangents_size = 64 };
    mk_error err;
    mk_result r = mk_eval_run(&job, &err);
    CHECK_MSG(r == MK_OK, "eval: %s", err.message);
    return r;
}

static void check_vec(const float *got, float x, float y, float z, double tol)
{
    CHECK_NEAR(got[0], x, tol);
    CHECK_NEAR(got[1], y, tol);
    CHECK_NEAR(got[2], z, tol);
}

static void test_channel_span_rule(void)
{
    /* FBX SDK notes example: in-betweens at 50 and 100. */
    const float f[2] = { 0.5f, 1.0f };
    int32_t ia, ib;
    float ca, cb, t;
    mk_channel_span(f, 2, 0.25f, &ia, &ca, &ib, &cb, &t);
    CHECK(ia == -1 && ib == 0);
    CHECK_NEAR(cb, 0.5, 1e-7);
    mk_channel_span(f, 2, 0.75f, &ia, &ca, &ib, &cb, &t);
    CHECK(ia == 0 && ib == 1);
    CHECK_NEAR(ca, 0.5, 1e-7);
    CHECK_NEAR(cb, 0.5, 1e-7);
    mk_channel_span(f, 2, 0.0f, &ia, &ca, &ib, &cb, &t);
    CHECK(ib != -1 ? cb == 0 : 1);
    const float g[3] = { -0.499f, -0.249f, 1.0f };  /* Maya MoveToSide */
    mk_channel_span(g, 3, -0.3f, &ia, &ca, &ib, &cb, &t);
    CHECK(ia == 0 && ib == 1);
    CHECK_NEAR(ca * -0.499f + cb * -0.249f, -0.3, 1e-6);
    mk_channel_span(g, 3, -0.1f, &ia, &ca, &ib, &cb, &t);
    CHECK(ia == 1 && ib == -1);
    CHECK_NEAR(ca, 0.1 / 0.249, 1e-6);
}

static void test_inbetweens(void)
{
    setup s;
    open_basic(&s, MK_PRECISION_FLOAT);
    float p[12], w[4] = { 0.25f, 0, 0, 0 };
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, 0.5f, 1e-6);             /* 0.5 * delta1 */
    w[0] = 0.75f;
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, 2.0f, 1e-6);             /* delta1 + 0.5 (delta2 - delta1) */
    w[0] = 0.5f;
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, 1.0f, 1e-6);
    w[0] = 1.0f;
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, 3.0f, 1e-6);
    check_vec(p + 3, 1, 0, 0, 0);               /* other vertices untouched */
    mk_raw_free(&s.raw);
}

static void test_extrapolation(void)
{
    setup s;
    open_basic(&s, MK_PRECISION_FLOAT);
    float p[12], w[4] = { 1.5f, 0, 0, 0 };
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, 5.0f, 1e-5);             /* last span, t = 2: -1*d1 + 2*d2 */
    w[0] = -0.5f;
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, -1.0f, 1e-6);            /* first span (0 .. 0.5) extrapolated */
    mk_raw_free(&s.raw);
}

static void test_negative_full_weights(void)
{
    setup s;
    open_basic(&s, MK_PRECISION_FLOAT);
    float p[12], w[4] = { 0, -0.5f, 0, 0 };
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p + 3, 1, 0.5f, 0, 1e-6);         /* halfway from 0 to the f=-1 target */
    w[1] = -2.0f;
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p + 3, 1, 2.0f, 0, 1e-6);         /* extrapolated below the most negative key */
    w[1] = 0.5f;
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p + 3, 1.5f, 0, 0, 1e-6);
    mk_raw_free(&s.raw);
}

static void test_additive_and_sequential(void)
{
    setup s;
    open_basic(&s, MK_PRECISION_FLOAT);
    float p[12];
    const float w1 = 0.6f, w2 = 0.3f;
    float w[4] = { 0, 0, w1, w2 };
    eval_quad(&s, w, MK_STACKING_ADDITIVE, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p + 6, 0 + w1 * 1, 1 + w2 * 2, 0, 1e-6);
    eval_quad(&s, w, MK_STACKING_SEQUENTIAL, MK_NORMALS_NLERP, p, NULL, NULL);
    /* FBX SDK notes: P' = P + (P1 - P) w1, then P'' = P' + (P2 - P') w2, with P1 = P + d1 and
     * P2 = P + d2 (targets as absolute shapes). */
    float P[3] = { 0, 1, 0 }, P1[3] = { 1, 1, 0 }, P2[3] = { 0, 3, 0 }, Pp[3], Ppp[3];
    for (int k = 0; k < 3; k++) {
        Pp[k] = P[k] + (P1[k] - P[k]) * w1;
        Ppp[k] = Pp[k] + (P2[k] - Pp[k]) * w2;
    }
    check_vec(p + 6, Ppp[0], Ppp[1], Ppp[2], 1e-6);
    /* w2 = 1: the later channel overrides the earlier one completely. */
    w[3] = 1.0f;
    eval_quad(&s, w, MK_STACKING_SEQUENTIAL, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p + 6, 0, 3, 0, 1e-6);
    /* A progressive channel in sequential mode is scaled by every later channel's
     * (1 - beta): channel 3 at 0.5 has beta 0.5, channels 1 and 2 at 0 have beta 0. */
    float v[4] = { 0.75f, 0, 0, 0.5f };
    eval_quad(&s, v, MK_STACKING_SEQUENTIAL, MK_NORMALS_NLERP, p, NULL, NULL);
    check_vec(p, 0, 0, 2.0f * 0.5f, 1e-6);      /* D0 = 2 scaled by (1 - beta_3) = 0.5 */
    mk_raw_free(&s.raw);
}

static void test_normals_nlerp_slerp(void)
{
    setup s;
    open_basic(&s, MK_PRECISION_FLOAT);
    float p[12], n[12], t[16];
    /* Target f=0.5 turns v0's normal from +z to +x (delta (1,0,-1)); at w = 0.25 the span
     * parameter is 0.5. */
    float w[4] = { 0.25f, 0, 0, 0 };
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, n, t);
    check_vec(n, 0.70710678f, 0, 0.70710678f, 1e-6);
    check_vec(n + 3, 0, 0, 1, 0);
    w[0] = 0.125f;                              /* span parameter 0.25 */
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, n, t);
    double len = sqrt(0.25 * 0.25 + 0.75 * 0.75);
    check_vec(n, (float)(0.25 / len), 0, (float)(0.75 / len), 1e-6);
    eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_SLERP, p, n, t);
    double angle = 0.25 * 3.14159265358979 / 2;  /* a quarter of the 90 degree turn */
    check_vec(n, (float)sin(angle), 0, (float)cos(angle), 1e-6);
    /* Tangents keep the base w. */
    CHECK_NEAR(t[3], 1.0, 0);
    mk_raw_free(&s.raw);
}

static void test_weights_zero_give_base(void)
{
    for (int q = 0; q < 2; q++) {
        setup s;
        open_basic(&s, q ? MK_PRECISION_Q16 : MK_PRECISION_FLOAT);
        float p[12], n[12], t[16], w[4] = { 0, 0, 0, 0 };
        eval_quad(&s, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, p, n, t);
        for (int i = 0; i < 12; i++) CHECK(p[i] == s.raw.meshes[0].positions[i]);
        for (int i = 0; i < 12; i++) CHECK(n[i] == s.raw.meshes[0].normals[i]);
        mk_raw_free(&s.raw);
    }
}

/* A large sparse/dense mesh: splitting into vertex ranges with strides gives the same result
 * as one job, for both precisions and stacking modes. */
static void test_ranges_and_strides(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 1000, 12, 3);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    size_t size;
    void *blob = fixture_blob(&raw, MK_PRECISION_Q16, &arena, &size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    float w[12];
    for (int c = 0; c < 12; c++) w[c] = 0.1f * (float)(c + 1) - 0.3f;
    size_t scratch_size = mk_eval_scratch_size(&a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    float *whole = malloc(1000 * 12), *whole_n = malloc(1000 * 12);
    float *inter = malloc(1000 * 32);          /* interleaved: pos(12) pad(4) normal(12) pad(4) */
    for (int stacking = 1; stacking <= 2; stacking++) {
        mk_eval_job job = { .asset = &a, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = 12, .stacking = (mk_stacking)stacking,
                            .scratch = scratch, .scratch_size = scratch_size, .positions = whole,
                            .positions_size = 12000, .normals = whole_n, .normals_size = 12000 };
        CHECK(mk_eval_run(&job, &err) == MK_OK);
        const uint32_t cuts[] = { 0, 1, 63, 64, 65, 500, 937, 1000 };
        for (int k = 0; k + 1 < 8; k++) {
            mk_eval_job part = job;
            part.first_vertex = cuts[k];
            part.vertex_count = cuts[k + 1] - cuts[k];
            part.positions = inter + 8 * (size_t)cuts[k];
            part.positions_stride = 32;
            part.positions_size = 32 * (size_t)(part.vertex_count - 1) + 12;
            part.normals = inter + 8 * (size_t)cuts[k] + 4;
            part.normals_stride = 32;
            part.normals_size = 32 * (size_t)(part.vertex_count - 1) + 12;
            CHECK_MSG(mk_eval_run(&part, &err) == MK_OK, "%s", err.message);
        }
        int same = 1;
        for (int v = 0; v < 1000; v++)
            for (int d = 0; d < 3; d++)
                same &= inter[8 * v + d] == whole[3 * v + d] && inter[8 * v + 4 + d] == whole_n[3 * v + d];
        CHECK(same);
    }
    /* q16 stays within the reported error of the float evaluation. */
    size_t fsize;
    void *fblob = fixture_blob(&raw, MK_PRECISION_FLOAT, &arena, &fsize);
    mk_asset fa;
    CHECK(mk_asset_open(fblob, fsize, &fa, &err) == MK_OK);
    float *exact = malloc(1000 * 12);
    mk_eval_job job = { .asset = &fa, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = 12, .scratch = scratch,
                        .scratch_size = scratch_size, .positions = exact, .positions_size = 12000 };
    CHECK(mk_eval_run(&job, &err) == MK_OK);
    job.asset = &a;
    job.positions = whole;
    CHECK(mk_eval_run(&job, &err) == MK_OK);
    mk_write_report report;
    void *b2;
    size_t s2;
    CHECK(mk_write_blob(&raw, NULL, &arena, &b2, &s2, &report, &err) == MK_OK);
    double coef_sum = 0;
    for (int c = 0; c < 12; c++) coef_sum += fabs(w[c]);
    double worst = 0;
    for (int i = 0; i < 3000; i++) worst = fabs(exact[i] - whole[i]) > worst ? fabs(exact[i] - whole[i]) : worst;
    CHECK_MSG(worst <= report.max_position_error * coef_sum + 1e-6, "q16 error %g > bound %g", worst,
              report.max_position_error * coef_sum);
    CHECK(report.max_position_error > 0 && report.max_position_error <= report.tolerance_used);
    free(exact);
    free(scratch);
    free(whole);
    free(whole_n);
    free(inter);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

CHECK_MAIN(CASE(test_channel_span_rule), CASE(test_inbetweens), CASE(test_extrapolation),
           CASE(test_negative_full_weights), CASE(test_additive_and_sequential), CASE(test_normals_nlerp_slerp),
           CASE(test_weights_zero_give_base), CASE(test_ranges_and_strides))

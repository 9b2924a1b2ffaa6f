/* SPDX-License-Identifier: MIT */
/* Every interpolation mode of weight curves against hand-computed values, and the sampling job. */
#include <float.h>
#include <math.h>
#include "check.h"
#include "fixtures.h"

static mk_key key(float t, float v, mk_interp interp)
{
    mk_key k = { t, v, 0, 1.0f / 3, 0, 1.0f / 3, (uint32_t)interp, 0 };
    return k;
}

static void test_constant_linear(void)
{
    mk_key k[2] = { key(0, 1, MK_INTERP_CONSTANT), key(1, 3, MK_INTERP_CONSTANT) };
    CHECK_NEAR(mk_curve_eval(k, 2, 0.5f, NULL), 1, 0);
    CHECK_NEAR(mk_curve_eval(k, 2, 0.999f, NULL), 1, 0);
    CHECK_NEAR(mk_curve_eval(k, 2, 1.0f, NULL), 3, 0);
    k[0].interp = MK_INTERP_CONSTANT_NEXT;
    CHECK_NEAR(mk_curve_eval(k, 2, 0.0f, NULL), 1, 0);
    CHECK_NEAR(mk_curve_eval(k, 2, 0.001f, NULL), 3, 0);
    k[0].interp = MK_INTERP_LINEAR;
    CHECK_NEAR(mk_curve_eval(k, 2, 0.5f, NULL), 2, 1e-7);
    CHECK_NEAR(mk_curve_eval(k, 2, 0.25f, NULL), 1.5, 1e-7);
}

static void test_clamp_outside(void)
{
    mk_key k[2] = { key(1, 5, MK_INTERP_LINEAR), key(2, 7, MK_INTERP_LINEAR) };
    CHECK_NEAR(mk_curve_eval(k, 2, -10.0f, NULL), 5, 0);
    CHECK_NEAR(mk_curve_eval(k, 2, 99.0f, NULL), 7, 0);
    CHECK_NEAR(mk_curve_eval(k, 1, 99.0f, NULL), 5, 0);   /* one key: constant */
}

static void test_hermite(void)
{
    /* Zero slopes, weights 1/3: smoothstep h(s) = 3s^2 - 2s^3. */
    mk_key k[2] = { key(0, 1, MK_INTERP_CUBIC), key(1, 3, MK_INTERP_CUBIC) };
    CHECK_NEAR(mk_curve_eval(k, 2, 0.5f, NULL), 2.0, 1e-6);
    CHECK_NEAR(mk_curve_eval(k, 2, 0.25f, NULL), 1 + 2 * 0.15625, 1e-6);
    /* Slopes: values 0 -> 0 over dt = 2, right slope 1 at key 0: p = h10(s) dt m0,
     * h10(0.5) = 0.125 -> 0.25. */
    mk_key h[2] = { key(0, 0, MK_INTERP_CUBIC), key(2, 0, MK_INTERP_CUBIC) };
    h[0].right_slope = 1;
    CHECK_NEAR(mk_curve_eval(h, 2, 1.0f, NULL), 0.25, 1e-6);
    /* Left slope of the next key: h11(s) = s^3 - s^2, value dt m1 h11(0.5) = 2 * 1 * -0.125. */
    h[0].right_slope = 0;
    h[1].left_slope = 1;
    CHECK_NEAR(mk_curve_eval(h, 2, 1.0f, NULL), -0.25, 1e-6);
}

static void test_weighted_bezier(void)
{
    /* wr = 0.5, wl = 1/3, values 0 -> 1, slopes 0. At parameter u = 0.3:
     * x = 3u(1-u)^2 * 0.5 + 3u^2(1-u) * (2/3) + u^3 = 0.2205 + 0.126 + 0.027 = 0.3735
     * y = 3u^2(1-u) * 1 + u^3 = 0.189 + 0.027 = 0.216 */
    mk_key k[2] = { key(0, 0, MK_INTERP_CUBIC), key(1, 1, MK_INTERP_CUBIC) };
    k[0].right_weight = 0.5f;
    CHECK_NEAR(mk_curve_eval(k, 2, 0.3735f, NULL), 0.216, 1e-5);
    /* Scaled in time and value: keys at 2 s and 4 s, values 1 -> 3. */
    mk_key s[2] = { key(2, 1, MK_INTERP_CUBIC), key(4, 3, MK_INTERP_CUBIC) };
    s[0].right_weight = 0.5f;
    CHECK_NEAR(mk_curve_eval(s, 2, 2 + 2 * 0.3735f, NULL), 1 + 2 * 0.216, 1e-5);
    /* Both weights 1 (x control points 0,1,0,1: non-monotonic slope in the middle) stays
     * finite and inside the value range. */
    k[0].right_weight = 1;
    k[1].left_weight = 1;
    for (int i = 0; i <= 100; i++) {
        float v = mk_curve_eval(k, 2, (float)i / 100, NULL);
        CHECK(v >= -1e-6f && v <= 1 + 1e-6f);
    }
}

static void test_cursor_matches_search(void)
{
    mk_key k[50];
    for (int i = 0; i < 50; i++) k[i] = key((float)i * 0.1f, (float)((i * 37) % 11), (mk_interp)(i % 4));
    uint32_t cursor = 0;
    int same = 1;
    for (int i = -5; i < 520; i++) {
        float t = (float)i * 0.01f;
        same &= mk_curve_eval(k, 50, t, &cursor) == mk_curve_eval(k, 50, t, NULL);
    }
    for (int i = 520; i > -5; i -= 7) {           /* backwards jumps too */
        float t = (float)i * 0.01f;
        same &= mk_curve_eval(k, 50, t, &cursor) == mk_curve_eval(k, 50, t, NULL);
    }
    cursor = UINT32_MAX;                          /* must not wrap into keys[UINT32_MAX] */
    same &= mk_curve_eval(k, 50, 2.05, &cursor) == mk_curve_eval(k, 50, 2.05, NULL);
    cursor = 12345;                               /* a garbage cursor is ignored */
    /* Time is double: an instant just before a step key still gets the previous value. */
    mk_key st[2] = { key(0, 1, MK_INTERP_CONSTANT), key(3.9f, 2, MK_INTERP_CONSTANT) };
    CHECK_NEAR(mk_curve_eval(st, 2, (double)3.9f - 1e-7, NULL), 1, 0);
    CHECK_NEAR(mk_curve_eval(st, 2, (double)3.9f, NULL), 2, 0);
    same &= mk_curve_eval(k, 50, 2.05f, &cursor) == mk_curve_eval(k, 50, 2.05f, NULL);
    CHECK(same);
}

/* docs/semantics.md: a cubic segment's value saturates at +-FLT_MAX. Slope 3e38 over 100 s puts
 * the first handle at 1e40: the midpoint is 3.75e39, past float range. */
static void test_steep_slopes_stay_finite(void)
{
    mk_key k[2] = { key(0, 0, MK_INTERP_CUBIC), key(100, 0, MK_INTERP_CUBIC) };
    k[0].right_slope = 3e38f;
    CHECK(mk_curve_eval(k, 2, 50.0, NULL) == FLT_MAX);
    k[0].right_slope = -3e38f;
    CHECK(mk_curve_eval(k, 2, 50.0, NULL) == -FLT_MAX);
    /* Near the start the curve is still within range and keeps its value. */
    k[0].right_slope = 1e30f;
    float v = mk_curve_eval(k, 2, 1e-6, NULL);
    CHECK(isfinite(v) && v > 0 && v < FLT_MAX);
}

static void test_span_without_targets(void)
{
    int32_t ia = 7, ib = 7;
    float ca = 1, cb = 1, t = 1;
    mk_channel_span(NULL, 0, 0.5f, &ia, &ca, &ib, &cb, &t);
    CHECK(ia == -1 && ib == -1 && ca == 0 && cb == 0);
}

static void test_sample_job(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_basic(&raw);
    raw.channels[1].default_weight = 0.7f;
    size_t size;
    void *blob = fixture_blob(&raw, MK_PRECISION_FLOAT, &raw.arena, &size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    float w[5];
    uint32_t cursors[2] = { 0, 0 };
    mk_sample_job job = { .asset = &a, .clip = 0, .time = 0.25f, .weights = w, .weight_count = 5, .cursors = cursors,
                          .cursor_count = 2 };
    CHECK(mk_sample_run(&job, &err) == MK_OK);
    CHECK_NEAR(w[0], 0.25, 1e-7);
    CHECK_NEAR(w[1], 0.7, 1e-7);                 /* not animated: default */
    CHECK_NEAR(w[4], 0.5, 0);
    job.time = 1.25f;                             /* past the end: holds */
    CHECK(mk_sample_run(&job, &err) == MK_OK);
    CHECK_NEAR(w[0], 1.0, 0);
    job.loop = 1;                                 /* wraps to 0.25 */
    CHECK(mk_sample_run(&job, &err) == MK_OK);
    CHECK_NEAR(w[0], 0.25, 1e-6);
    job.time = -0.75f;                            /* negative wraps too */
    CHECK(mk_sample_run(&job, &err) == MK_OK);
    CHECK_NEAR(w[0], 0.25, 1e-6);
    mk_raw_free(&raw);
}

/* A looping clip wraps time into [start, start + duration) (docs/semantics.md): relative to its
 * start, not to time 0. fixture_rich's clip "blink" starts at 0.5 and lasts 1; its track on
 * channel 2 is linear from 0 at 0.5 to 1 at 1.5, so the weight at clip time t is t - 0.5. */
static void test_loop_relative_to_start(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_rich(&raw);
    size_t size;
    void *blob = fixture_blob(&raw, MK_PRECISION_FLOAT, &raw.arena, &size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    float w[16];
    CHECK(a.channel_count <= 16);
    static const struct { double time, expected; } cases[] = {
        { 0.75, 0.25 },    /* inside the clip: no wrap */
        { 2.75, 0.25 },    /* 2 durations on: 0.75 */
        { 1.75, 0.25 },    /* one duration on (wrapped from 0, it would be 0.75) */
        { 0.25, 0.75 },    /* before the start: wraps up to 1.25 */
        { -3.0, 0.5 },     /* far before: 1.0 */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        mk_sample_job job = { .asset = &a, .clip = 2, .time = cases[i].time, .weights = w,
                              .weight_count = a.channel_count, .loop = 1 };
        CHECK(mk_sample_run(&job, &err) == MK_OK);
        CHECK_MSG(fabs(w[2] - cases[i].expected) <= 1e-6, "looping clip at time %g: weight %.9g, expected %g",
                  cases[i].time, (double)w[2], cases[i].expected);
    }
    mk_raw_free(&raw);
}

CHECK_MAIN(CASE(test_constant_linear), CASE(test_clamp_outside), CASE(test_hermite), CASE(test_weighted_bezier),
           CASE(test_cursor_matches_search), CASE(test_steep_slopes_stay_finite),
           CASE(test_span_without_targets), CASE(test_sample_job), CASE(test_loop_relative_to_start))

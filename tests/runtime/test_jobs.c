/* SPDX-License-Identifier: MIT */
/* Every invalid evaluation and sampling job is rejected with the right code (JobValidity
 * style): start from a valid job, break one field at a time. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fixtures.h"

static mk_raw_asset raw;
static mk_asset asset;
static _Alignas(16) unsigned char scratch[1024];
static float weights[5], pos[64], nrm[64], tan4[64];

static void setup(void)
{
    static int done = 0;
    if (done) return;
    done = 1;
    mk_raw_init(&raw, NULL);
    fixture_basic(&raw);
    size_t size;
    void *blob = fixture_blob(&raw, MK_PRECISION_Q16, &raw.arena, &size);
    mk_error err;
    if (mk_asset_open(blob, size, &asset, &err) != MK_OK) abort();
}

static mk_eval_job valid_eval(void)
{
    setup();
    mk_eval_job j = { .asset = &asset, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = weights,
                      .weight_count = 4, .scratch = scratch, .scratch_size = sizeof scratch, .positions = pos, .positions_size = 48, .normals = nrm,
                      .normals_size = 48, .tangents = tan4, .tangents_size = 64 };
    return j;
}

/* mk_eval_validate and mk_eval_run agree on every job: validate says what run would. */
static void expect(mk_eval_job j, mk_result code, const char *what)
{
    mk_error err = { 0 }, verr = { 0 };
    mk_result v = mk_eval_validate(&j, &verr);
    CHECK_MSG(v == code, "%s: validate gave %s (%s), expected %s", what, mk_result_name(v), verr.message, mk_result_name(code));
    mk_result r = mk_eval_run(&j, &err);
    CHECK_MSG(r == code, "%s: got %s (%s), expected %s", what, mk_result_name(r), err.message, mk_result_name(code));
    if (code != MK_OK) CHECK_MSG(err.message[0] != 0 && !strcmp(err.message, verr.message), "%s: no message, or run and validate differ", what);
}

static void test_valid_job_runs(void) { expect(valid_eval(), MK_OK, "valid"); }

static void test_invalid_eval_jobs(void)
{
    mk_eval_job j;
    CHECK(mk_eval_run(NULL, NULL) == MK_ERROR_INVALID_ARGUMENT);
    j = valid_eval(); j.asset = NULL; expect(j, MK_ERROR_INVALID_ARGUMENT, "asset NULL");
    j = valid_eval(); j.mesh = 2; expect(j, MK_ERROR_OUT_OF_RANGE, "mesh out of range");
    j = valid_eval(); j.first_vertex = 5; expect(j, MK_ERROR_OUT_OF_RANGE, "first vertex past end");
    j = valid_eval(); j.first_vertex = 1; j.vertex_count = 4; expect(j, MK_ERROR_OUT_OF_RANGE, "count past end");
    j = valid_eval(); j.first_vertex = 2; j.vertex_count = 3; expect(j, MK_ERROR_OUT_OF_RANGE, "range past end");
    j = valid_eval(); j.weight_count = 3; expect(j, MK_ERROR_OUT_OF_RANGE, "weight count");
    j = valid_eval(); j.weights = NULL; expect(j, MK_ERROR_INVALID_ARGUMENT, "weights NULL");
    j = valid_eval(); weights[2] = NAN; expect(j, MK_ERROR_NOT_FINITE, "NaN weight"); weights[2] = 0;
    j = valid_eval(); weights[1] = INFINITY; expect(j, MK_ERROR_NOT_FINITE, "inf weight"); weights[1] = 0;
    j = valid_eval(); j.stacking = (mk_stacking)7; expect(j, MK_ERROR_INVALID_ARGUMENT, "stacking");
    j = valid_eval(); j.normal_mode = (mk_normal_mode)5; expect(j, MK_ERROR_INVALID_ARGUMENT, "normal mode");
    j = valid_eval(); j.store_mode = (mk_store_mode)3; expect(j, MK_ERROR_INVALID_ARGUMENT, "store mode");
    j = valid_eval(); j.scratch = NULL; expect(j, MK_ERROR_INVALID_ARGUMENT, "scratch NULL");
    j = valid_eval(); j.scratch = scratch + 4; expect(j, MK_ERROR_INVALID_ARGUMENT, "scratch misaligned");
    j = valid_eval(); j.scratch_size = 8; expect(j, MK_ERROR_BUFFER_TOO_SMALL, "scratch small");
    j = valid_eval(); j.positions = NULL; expect(j, MK_ERROR_INVALID_ARGUMENT, "positions NULL");
    j = valid_eval(); j.positions_size = 47; expect(j, MK_ERROR_BUFFER_TOO_SMALL, "positions small");
    j = valid_eval(); j.positions_stride = 8; expect(j, MK_ERROR_BUFFER_TOO_SMALL, "stride < element");
    j = valid_eval(); j.positions_stride = 14; j.positions_size = 1000; expect(j, MK_ERROR_BUFFER_TOO_SMALL, "stride misaligned");
    j = valid_eval(); j.positions = (float *)((char *)pos + 2); expect(j, MK_ERROR_BUFFER_TOO_SMALL, "positions misaligned");
    j = valid_eval(); j.normals_size = 12; expect(j, MK_ERROR_BUFFER_TOO_SMALL, "normals small");
    j = valid_eval(); j.tangents_size = 60; expect(j, MK_ERROR_BUFFER_TOO_SMALL, "tangents small");
    j = valid_eval(); j.mesh = 1; j.weight_count = 1; j.tangents = NULL; expect(j, MK_ERROR_UNSUPPORTED, "normals on mesh without");
    j = valid_eval(); j.mesh = 1; j.weight_count = 1; j.normals = NULL; expect(j, MK_ERROR_UNSUPPORTED, "tangents on mesh without");
    /* The exact size is enough: stride * (n - 1) + element. */
    j = valid_eval(); j.positions_stride = 16; j.positions_size = 16 * 3 + 12; expect(j, MK_OK, "exact strided size");
    j = valid_eval(); j.scratch_size = mk_eval_scratch_size(&asset, 0); expect(j, MK_OK, "queried scratch size");
}

/* The runtime never writes past scratch_size bytes of the scratch: every size from 0 to
 * mk_eval_scratch_size() is either refused with MK_ERROR_BUFFER_TOO_SMALL or enough, and then
 * gives the frame the queried size gives. Canary bytes after the given size catch a write past
 * it (a size check that lets a scratch a few bytes short through). */
static void test_scratch_never_overrun(void)
{
    enum { CANARY = 64 };
    mk_eval_job j = valid_eval();
    const size_t needed = mk_eval_scratch_size(&asset, 0);
    CHECK(needed > 0 && needed + CANARY <= sizeof scratch);
    const float w[4] = { 0.75f, -0.5f, 0.5f, 1.0f };   /* every channel active */
    memcpy(weights, w, sizeof w);
    float expected[12];
    j.normals = NULL;
    j.tangents = NULL;
    j.scratch_size = needed;
    j.stacking = MK_STACKING_SEQUENTIAL;
    mk_error err;
    CHECK_MSG(mk_eval_run(&j, &err) == MK_OK, "queried size: %s", err.message);
    memcpy(expected, pos, sizeof expected);
    for (size_t n = 0; n <= needed; n++) {
        memset(scratch, 0xa5, sizeof scratch);
        memset(pos, 0, sizeof pos);
        j.scratch_size = n;
        mk_result r = mk_eval_run(&j, &err);
        CHECK_MSG(r == MK_OK || r == MK_ERROR_BUFFER_TOO_SMALL, "scratch of %zu bytes: %s", n, mk_result_name(r));
        int intact = 1;
        for (size_t i = n; i < n + CANARY; i++) intact &= scratch[i] == 0xa5;
        CHECK_MSG(intact, "scratch of %zu bytes (%s): written past its end", n, mk_result_name(r));
        if (r == MK_OK) CHECK_MSG(!memcmp(pos, expected, sizeof expected), "scratch of %zu bytes: another frame", n);
    }
    memset(weights, 0, sizeof w);
}

/* vertex_count 0 is an empty range: it writes nothing, wherever it starts (a job splitter
 * that produces an empty slice must not evaluate the whole mesh); MK_VERTICES_TO_END from
 * the last vertex is empty too. */
static void test_empty_ranges_write_nothing(void)
{
    static const uint32_t firsts[] = { 0, 2, 4 };
    for (int k = 0; k < 3; k++)
        for (int to_end = 0; to_end < 2; to_end++) {
            if (to_end && firsts[k] != 4) continue;
            mk_eval_job j = valid_eval();
            j.first_vertex = firsts[k];
            j.vertex_count = to_end ? MK_VERTICES_TO_END : 0;
            for (int i = 0; i < 64; i++) pos[i] = nrm[i] = tan4[i] = -7.0f;
            j.positions_size = j.normals_size = j.tangents_size = 0;
            mk_error err;
            CHECK_MSG(mk_eval_run(&j, &err) == MK_OK, "empty range at %u: %s", firsts[k], err.message);
            int untouched = 1;
            for (int i = 0; i < 64; i++) untouched &= pos[i] == -7.0f && nrm[i] == -7.0f && tan4[i] == -7.0f;
            CHECK_MSG(untouched, "empty range at %u wrote output", firsts[k]);
        }
}

static mk_sample_job valid_sample(void)
{
    setup();
    static uint32_t cursors[2];
    mk_sample_job j = { .asset = &asset, .clip = 0, .time = 0.5f, .weights = weights, .weight_count = 5,
                        .cursors = cursors, .cursor_count = 2 };
    return j;
}

static void expect_sample(mk_sample_job j, mk_result code, const char *what)
{
    mk_error err = { 0 }, verr = { 0 };
    mk_result v = mk_sample_validate(&j, &verr);
    CHECK_MSG(v == code, "%s: validate gave %s, expected %s", what, mk_result_name(v), mk_result_name(code));
    mk_result r = mk_sample_run(&j, &err);
    CHECK_MSG(r == code, "%s: got %s, expected %s", what, mk_result_name(r), mk_result_name(code));
    if (code != MK_OK) CHECK_MSG(err.message[0] != 0 && !strcmp(err.message, verr.message), "%s: no message, or run and validate differ", what);
}

static void test_invalid_sample_jobs(void)
{
    mk_sample_job j;
    expect_sample(valid_sample(), MK_OK, "valid");
    CHECK(mk_sample_run(NULL, NULL) == MK_ERROR_INVALID_ARGUMENT);
    j = valid_sample(); j.asset = NULL; expect_sample(j, MK_ERROR_INVALID_ARGUMENT, "asset NULL");
    j = valid_sample(); j.clip = 1; expect_sample(j, MK_ERROR_OUT_OF_RANGE, "clip");
    j = valid_sample(); j.time = NAN; expect_sample(j, MK_ERROR_NOT_FINITE, "NaN time");
    j = valid_sample(); j.weights = NULL; expect_sample(j, MK_ERROR_INVALID_ARGUMENT, "weights NULL");
    j = valid_sample(); j.weight_count = 4; expect_sample(j, MK_ERROR_BUFFER_TOO_SMALL, "weight count");
    j = valid_sample(); j.cursor_count = 1; expect_sample(j, MK_ERROR_BUFFER_TOO_SMALL, "cursor count");
    j = valid_sample(); j.cursors = NULL; j.cursor_count = 0; expect_sample(j, MK_OK, "no cursors");
}

static void test_queries_reject_bad_indices(void)
{
    setup();
    mk_mesh_info m;
    mk_channel_info c;
    mk_target_info t;
    mk_clip_info k;
    CHECK(!mk_mesh_get(&asset, 2, &m));
    CHECK(!mk_channel_get(&asset, 5, &c));
    CHECK(!mk_target_get(&asset, 0, 2, &t));
    CHECK(!mk_clip_get(&asset, 1, &k));
    CHECK(!mk_track_get(&asset, 0, 2, NULL, NULL, NULL));
    CHECK(mk_find_channel(&asset, "negative") == 1);
    CHECK(mk_find_mesh(&asset, "plain") == 1);
    CHECK(mk_find_clip(&asset, "nope") == -1);
    CHECK(mk_eval_scratch_size(&asset, 9) == 0);
}

CHECK_MAIN(CASE(test_valid_job_runs), CASE(test_invalid_eval_jobs), CASE(test_empty_ranges_write_nothing), CASE(test_scratch_never_overrun),
           CASE(test_invalid_sample_jobs),
           CASE(test_queries_reject_bad_indices))

/* SPDX-License-Identifier: MIT */
/* The GPU path (gpu/, docs/gpu.md) against the CPU runtime, on whatever Vulkan device the
 * harness finds (lavapipe in the test suite: meson sets VK_ICD_FILENAMES to it), with the
 * validation layer and robust buffer access on; any validation message fails the test.
 *
 * The tolerance is docs/gpu.md's: positions within 1e-6 of the evaluated mesh's bounding-box
 * diagonal, normals and tangents within 1e-4 rad. Cases: random assets (in-betweens with
 * negative and positive full weights, additive and sequential, weights beyond the keys, both
 * normal modes, float and quantized blobs, partial and whole blocks), the rich fixture's four meshes
 * over its clips, entries stored around a position offset and as float32 outliers, outputs
 * interleaved at an engine's stride and offsets, refused frames (NaN weights, a bad slot) and
 * refused outputs. Without any Vulkan device every case reports itself skipped. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fixtures.h"
#include "format.h"
#include "harness.h"
#include "random_asset.h"

static mkg_harness harness;
static int harness_state;   /* 0 not tried, 1 open, -1 no device */
static char harness_why[256];

static mkg_harness *device(void)
{
    if (!harness_state) {
        mk_error err;
        /* Robust buffer access drops out-of-bounds writes, so test_gpu_bounds (MK_GPU_NO_ROBUST)
         * runs without it and lets GPU-assisted validation report them. */
        const unsigned flags = MKG_HARNESS_VALIDATION | (getenv("MK_GPU_NO_ROBUST") ? 0u : (unsigned)MKG_HARNESS_ROBUST);
        harness_state = mkg_harness_open(&harness, flags, &err) == MK_OK ? 1 : -1;
        if (harness_state < 0) snprintf(harness_why, sizeof harness_why, "%s", err.message);
        else fprintf(stderr, "device: %s (validation layer %s, robust buffer access %s)\n", harness.props.deviceName,
                     harness.validation ? "on" : "missing", harness.robust ? "on" : "off");
    }
    return harness_state > 0 ? &harness : NULL;
}

/* Validation messages before the current case: each case answers for its own. */
static unsigned messages_before;

#define NEED_DEVICE(h) mkg_harness *h = device(); if (!h) SKIP("no Vulkan device: %s", harness_why); \
    messages_before = h->validation_messages

/* Largest differences of one mesh's frame, GPU against CPU. */
typedef struct diff {
    double position;       /* absolute */
    double diagonal;       /* of the CPU positions' bounding box */
    double normal, tangent;   /* angles (rad) */
    int tangent_w_differs;
} diff;

static double angle(const float *a, const float *b)
{
    double d = 0, c[3] = { (double)a[1] * b[2] - (double)a[2] * b[1], (double)a[2] * b[0] - (double)a[0] * b[2],
                           (double)a[0] * b[1] - (double)a[1] * b[0] };
    for (int k = 0; k < 3; k++) d += (double)a[k] * b[k];
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), d);
}

/* Evaluates mesh on both paths and compares; returns 0 when the GPU path failed to run. */
static int compare_mesh(mkg_harness *h, mkg_asset *ga, const mk_asset *a, uint32_t mesh, const float *weights,
                        mk_stacking stacking, mk_normal_mode mode, diff *d)
{
    mk_mesh_info mi;
    mk_mesh_get(a, mesh, &mi);
    const size_t v = mi.vertex_count;
    float *cp = malloc(12 * v), *cn = malloc(12 * v), *ct = malloc(16 * v);
    float *gp = malloc(12 * v), *gn = malloc(12 * v), *gt = malloc(16 * v);
    size_t scratch_size = mk_eval_scratch_size(a, mesh);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    mk_eval_job job = { .asset = a, .mesh = mesh, .vertex_count = MK_VERTICES_TO_END, .weights = weights,
                        .weight_count = mi.channel_count, .stacking = stacking, .normal_mode = mode,
                        .scratch = scratch, .scratch_size = scratch_size, .positions = cp, .positions_size = 12 * v,
                        .normals = mi.has_normals ? cn : NULL, .normals_size = 12 * v,
                        .tangents = mi.has_tangents ? ct : NULL, .tangents_size = 16 * v };
    mk_error err;
    CHECK(mk_eval_run(&job, &err) == MK_OK);
    mk_result r = mkg_harness_eval(h, ga, mesh, weights, mi.channel_count, stacking, mode, gp,
                                   mi.has_normals ? gn : NULL, mi.has_tangents ? gt : NULL, &err);
    CHECK_MSG(r == MK_OK, "GPU evaluation failed: %s", err.message);
    memset(d, 0, sizeof *d);
    if (r == MK_OK) {
        float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
        for (size_t i = 0; i < v; i++)
            for (int k = 0; k < 3; k++) {
                float x = cp[3 * i + (size_t)k];
                lo[k] = fminf(lo[k], x);
                hi[k] = fmaxf(hi[k], x);
                d->position = fmax(d->position, fabs((double)gp[3 * i + (size_t)k] - x));
            }
        d->diagonal = sqrt(pow(hi[0] - lo[0], 2) + pow(hi[1] - lo[1], 2) + pow(hi[2] - lo[2], 2));
        for (size_t i = 0; mi.has_normals && i < v; i++) d->normal = fmax(d->normal, angle(gn + 3 * i, cn + 3 * i));
        for (size_t i = 0; mi.has_tangents && i < v; i++) {
            d->tangent = fmax(d->tangent, angle(gt + 4 * i, ct + 4 * i));
            d->tangent_w_differs |= gt[4 * i + 3] != ct[4 * i + 3];
        }
    }
    free(cp); free(cn); free(ct); free(gp); free(gn); free(gt); free(scratch);
    return r == MK_OK;
}

/* docs/gpu.md's tolerance; the diagonal has a floor so a mesh collapsed to a point still has
 * a scale. */
static int within(const diff *d)
{
    const double diag = d->diagonal > 1e-3 ? d->diagonal : 1e-3;
    return d->position <= 1e-6 * diag && d->normal <= 1e-4 && d->tangent <= 1e-4 && !d->tangent_w_differs;
}

static void check_within(const diff *d, const char *what)
{
    CHECK_MSG(within(d), "%s: positions %.3g (%.3g of the diagonal %.3g), normals %.3g rad, tangents %.3g rad%s", what,
              d->position, d->position / d->diagonal, d->diagonal, d->normal, d->tangent,
              d->tangent_w_differs ? ", tangent w differs" : "");
}

static void check_no_validation_messages(const mkg_harness *h)
{
    CHECK_MSG(h->validation_messages == messages_before, "the Vulkan validation layer reported %u messages",
              h->validation_messages - messages_before);
}

/* A raw asset written as a blob, opened and uploaded. */
typedef struct opened {
    mk_arena arena;
    mk_asset asset;
    mkg_asset *gpu;   /* NULL when the upload failed (a CHECK says so) */
} opened;

static void open_raw(mkg_harness *h, const mk_raw_asset *raw, mk_precision precision, opened *o)
{
    mk_arena_init(&o->arena, NULL);
    size_t size;
    void *blob = fixture_blob(raw, precision, &o->arena, &size);
    mk_error err;
    o->gpu = NULL;
    CHECK(mk_asset_open(blob, size, &o->asset, &err) == MK_OK);
    CHECK(mkg_asset_upload(h->ctx, &o->asset, h->queue, h->family, &o->gpu, &err) == MK_OK);
}

static void close_raw(opened *o)
{
    mkg_asset_destroy(o->gpu);
    mk_arena_free_all(&o->arena);
}

/* The rich fixture (raw, initialized here) as a quantized blob, opened and uploaded; 0 (everything
 * freed, a CHECK failed) when that did not work. */
static int open_rich(mkg_harness *h, mk_raw_asset *raw, opened *o)
{
    mk_raw_init(raw, NULL);
    fixture_rich(raw);
    open_raw(h, raw, MK_PRECISION_Q16, o);
    if (o->gpu) return 1;
    close_raw(o);
    mk_raw_free(raw);
    return 0;
}

/* ---- cases ---- */

static void test_random_assets(void)
{
    NEED_DEVICE(h);
    const char *env = getenv("MK_GPU_ASSETS");
    const int assets = env ? atoi(env) : 300;
    int failed = 0;
    double worst_pos = 0, worst_n = 0;
    for (int seed = 0; seed < assets; seed++) {
        rng r = { 0x5eed0000u + (uint64_t)seed };
        mk_raw_asset raw;
        random_asset(&r, &raw);
        for (int precision = 0; precision < 2; precision++) {
            opened o;
            open_raw(h, &raw, precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16, &o);
            for (int set = 0; o.gpu && set < 2; set++) {
                float w[8];
                for (uint32_t c = 0; c < raw.channel_count; c++) w[c] = random_weight(&r, &raw.channels[c]);
                for (int s = 0; s < 3; s++)
                    for (int mode = 0; mode < 2; mode++) {
                        diff d;
                        if (!compare_mesh(h, o.gpu, &o.asset, 0, w, (mk_stacking)s, (mk_normal_mode)mode, &d)) {
                            failed++;
                            continue;
                        }
                        worst_pos = fmax(worst_pos, d.position / fmax(d.diagonal, 1e-3));
                        worst_n = fmax(worst_n, fmax(d.normal, d.tangent));
                        if (!within(&d)) {
                            char what[96];
                            snprintf(what, sizeof what, "asset %d (%s), weights %d, stacking %d, %s", seed,
                                     precision ? "float" : "q16", set, s, mode ? "slerp" : "nlerp");
                            check_within(&d, what);
                            failed++;
                        }
                    }
            }
            close_raw(&o);
        }
        mk_raw_free(&raw);
    }
    fprintf(stderr, "random assets: %d, worst positions %.3g of the diagonal, worst normal/tangent %.3g rad\n", assets,
            worst_pos, worst_n);
    CHECK_EQ_INT(failed, 0);
    check_no_validation_messages(h);
}

/* Every mesh of the rich fixture (normals and tangents, in-betweens with a negative one, a
 * sequential mesh with sparse and dense blocks, a mesh without normals, one without channels)
 * over its clips' frames. */
static void test_rich_clips(void)
{
    NEED_DEVICE(h);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_rich(&raw);
    for (int precision = 0; precision < 2; precision++) {
        opened o;
        open_raw(h, &raw, precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16, &o);
        const mk_asset *a = &o.asset;
        mkg_asset *ga = o.gpu;
        mk_error err;
        float weights[16];
        for (uint32_t clip = 0; ga && clip < a->clip_count; clip++)
            for (int k = 0; k <= 8; k++) {
                mk_clip_info ci;
                mk_clip_get(a, clip, &ci);
                for (uint32_t c = 0; c < a->channel_count; c++) weights[c] = 0.0f;
                mk_sample_job s = { .asset = a, .clip = clip, .time = ci.start + ci.duration * k / 8.0,
                                    .weights = weights, .weight_count = a->channel_count };
                CHECK(mk_sample_run(&s, &err) == MK_OK);
                weights[0] *= 1.7f;   /* beyond the last in-between too */
                for (uint32_t m = 0; m < a->mesh_count; m++) {
                    mk_mesh_info mi;
                    mk_mesh_get(a, m, &mi);
                    for (int mode = 0; mode < 2; mode++) {
                        diff d;
                        if (compare_mesh(h, ga, a, m, weights + mi.first_channel, MK_STACKING_ASSET, (mk_normal_mode)mode, &d)) {
                            char what[64];
                            snprintf(what, sizeof what, "clip %u frame %d mesh %u mode %d", clip, k, m, mode);
                            check_within(&d, what);
                        }
                    }
                }
            }
        close_raw(&o);
    }
    mk_raw_free(&raw);
    check_no_validation_messages(h);
}

/* A mesh whose quantized blob has a WIDE entry (block 0: deltas of about 30 spread by 0.06, at a
 * 1e-5 tolerance beyond int16 offsets) and a float32 outlier (block 1: deltas from -40 to 40,
 * more than 16 bits of range), beside plain packed blocks. */
static void test_offset_and_float_entries(void)
{
    NEED_DEVICE(h);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 200, 2, 1);
    mk_raw_target *t = &raw.channels[0].targets[0];
    for (uint32_t i = 0; i < t->count; i++) {
        uint32_t v = t->indices[i];
        for (int k = 0; k < 3; k++) {
            float *p = &t->positions[3 * i + (uint32_t)k];
            if (v < 64) *p = 30.0f + 0.0003f * (float)v + 0.01f * (float)k;
            else if (v < 128) *p = -40.0f + 80.0f * (float)((v * 37 + (uint32_t)k * 11) % 64) / 63.0f;
            else *p = 0.001f * (float)(v % 13);
        }
    }
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_write_options o = { .precision = MK_PRECISION_Q16, .tolerance = 1e-5f };
    mk_write_report rep;
    void *blob = NULL;
    size_t size = 0;
    mk_error err;
    CHECK(mk_write_blob(&raw, &o, &arena, &blob, &size, &rep, &err) == MK_OK);
    mk_asset a;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    CHECK(mk_mesh_wide_entries(&a, 0) > 0);
    CHECK(mk_mesh_float_entries(&a, 0) > 0);
    mkg_asset *ga = NULL;
    CHECK(mkg_asset_upload(h->ctx, &a, h->queue, h->family, &ga, &err) == MK_OK);
    const float sets[3][2] = { { 1.0f, 0.0f }, { 0.35f, -1.2f }, { 2.5f, 0.7f } };
    for (int s = 0; ga && s < 3; s++) {
        diff d;
        if (compare_mesh(h, ga, &a, 0, sets[s], MK_STACKING_ASSET, MK_NORMALS_NLERP, &d)) check_within(&d, "offset/float");
        CHECK(d.position < 1e-3);   /* a wrong offset or outlier would be off by tens of units */
    }
    mkg_asset_destroy(ga);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
    check_no_validation_messages(h);
}

/* Outputs where an engine puts them: one interleaved buffer (stride 48: position at 4, normal
 * at 16, tangent at 28, 4 bytes the engine keeps at 0 and 44) at an offset; the values equal the
 * planar readback bit for bit, and the bytes between them are untouched. */
static void test_interleaved_outputs(void)
{
    NEED_DEVICE(h);
    mk_raw_asset raw;
    opened o;
    if (!open_rich(h, &raw, &o)) return;
    const mk_asset a = o.asset;
    mkg_asset *ga = o.gpu;
    mk_error err;
    const uint32_t mesh = 0;
    mk_mesh_info mi;
    mk_mesh_get(&a, mesh, &mi);
    const VkDeviceSize base = 256, stride = 48, bytes = base + stride * mi.vertex_count + 64;
    mkg_host_buffer out;
    CHECK(mkg_host_buffer_create(h, bytes, &out, &err) == MK_OK);
    memset(out.mapped, 0xAB, (size_t)bytes);
    mkg_mesh_desc d = { .mesh = mesh, .frames_in_flight = 3,
                        .positions = { out.buffer, base + 4, stride, bytes - base - 4 },
                        .normals = { out.buffer, base + 16, stride, bytes - base - 16 },
                        .tangents = { out.buffer, base + 28, stride, bytes - base - 28 } };
    mkg_mesh *gm = NULL;
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_OK);
    const float w[2] = { 0.8f, -0.4f };
    CHECK(gm && mkg_harness_begin(h, &err) == MK_OK);
    mkg_frame f = { .weights = w, .weight_count = mi.channel_count, .slot = 2, .normal_mode = MK_NORMALS_SLERP };
    CHECK(gm && mkg_mesh_record(gm, h->cmd, &f, &err) == MK_OK);
    mkg_cmd_output_barrier(h->cmd, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    CHECK(mkg_harness_submit(h, &err) == MK_OK);
    float p[3 * 8], n[3 * 8], t[4 * 8];
    CHECK(mi.vertex_count <= 8);
    CHECK(mkg_harness_eval(h, ga, mesh, w, mi.channel_count, MK_STACKING_ASSET, MK_NORMALS_SLERP, p, n, t, &err) == MK_OK);
    const uint8_t *bytes_out = out.mapped;
    for (uint32_t v = 0; v < mi.vertex_count; v++) {
        const uint8_t *vx = bytes_out + base + stride * v;
        CHECK(memcmp(vx + 4, p + 3 * v, 12) == 0);
        CHECK(memcmp(vx + 16, n + 3 * v, 12) == 0);
        CHECK(memcmp(vx + 28, t + 4 * v, 16) == 0);
        CHECK(vx[0] == 0xAB && vx[3] == 0xAB && vx[44] == 0xAB && vx[47] == 0xAB);
    }
    CHECK(bytes_out[base - 1] == 0xAB && bytes_out[base + stride * mi.vertex_count] == 0xAB);
    mkg_mesh_destroy(gm);
    mkg_host_buffer_destroy(h, &out);
    close_raw(&o);
    mk_raw_free(&raw);
    check_no_validation_messages(h);
}

/* Frames and outputs the library refuses, with a message and nothing recorded or made. */
static void test_refusals(void)
{
    NEED_DEVICE(h);
    mk_raw_asset raw;
    opened o;
    if (!open_rich(h, &raw, &o)) return;
    const mk_asset a = o.asset;
    mkg_asset *ga = o.gpu;
    mk_error err;
    mkg_host_buffer out;
    CHECK(mkg_host_buffer_create(h, 4096, &out, &err) == MK_OK);
    mkg_mesh *gm = NULL;
    /* Outputs: too small, misaligned, an attribute the mesh lacks, a mesh that does not exist. */
    mkg_mesh_desc d = { .mesh = 0, .positions = { out.buffer, 0, 12, 4 * 12 - 1 } };
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_ERROR_BUFFER_TOO_SMALL && !gm);
    CHECK(strstr(err.message, "positions output needs 48 bytes") != NULL);
    d.positions = (mkg_output){ out.buffer, 2, 12, 1024 };
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_ERROR_INVALID_ARGUMENT && !gm);
    d.positions = (mkg_output){ out.buffer, 0, 8, 1024 };
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_ERROR_INVALID_ARGUMENT && !gm);
    d = (mkg_mesh_desc){ .mesh = 1, .positions = { out.buffer, 0, 0, 1024 }, .normals = { out.buffer, 1024, 0, 1024 } };
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_ERROR_UNSUPPORTED && !gm);
    d = (mkg_mesh_desc){ .mesh = 9, .positions = { out.buffer, 0, 0, 1024 } };
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_ERROR_OUT_OF_RANGE && !gm);
    /* Frames: NaN and infinite weights (as the CPU job refuses them), a wrong count, a slot
     * past frames_in_flight. */
    d = (mkg_mesh_desc){ .mesh = 0, .frames_in_flight = 2, .positions = { out.buffer, 0, 0, 1024 } };
    CHECK(mkg_mesh_create(ga, &d, &gm, &err) == MK_OK);
    CHECK(gm && mkg_harness_begin(h, &err) == MK_OK);
    float w[2] = { NAN, 0.0f };
    mkg_frame f = { .weights = w, .weight_count = 2 };
    CHECK(gm && mkg_mesh_record(gm, h->cmd, &f, &err) == MK_ERROR_NOT_FINITE);
    w[0] = INFINITY;
    CHECK(gm && mkg_mesh_record(gm, h->cmd, &f, &err) == MK_ERROR_NOT_FINITE);
    w[0] = 0.5f;
    f.weight_count = 1;
    CHECK(gm && mkg_mesh_record(gm, h->cmd, &f, &err) == MK_ERROR_OUT_OF_RANGE);
    f.weight_count = 2;
    f.slot = 2;
    CHECK(gm && mkg_mesh_record(gm, h->cmd, &f, &err) == MK_ERROR_OUT_OF_RANGE);
    CHECK(strstr(err.message, "slot 2") != NULL);
    CHECK(mkg_harness_submit(h, &err) == MK_OK);
    /* The CPU plan refuses the same way. */
    _Alignas(16) uint8_t plan[256];
    w[0] = NAN;
    mk_gpu_plan_job pj = { .asset = &a, .mesh = 0, .weights = w, .weight_count = 2, .plan = plan, .plan_size = sizeof plan };
    CHECK(mk_gpu_plan_run(&pj, &err) == MK_ERROR_NOT_FINITE);
    w[0] = 0.5f;
    pj.plan_size = mk_gpu_plan_size(&a, 0) - 1;
    CHECK(mk_gpu_plan_run(&pj, &err) == MK_ERROR_BUFFER_TOO_SMALL);
    pj.plan = plan + 4;
    pj.plan_size = sizeof plan - 4;
    CHECK(mk_gpu_plan_run(&pj, &err) == MK_ERROR_INVALID_ARGUMENT);
    mkg_mesh_destroy(gm);
    mkg_host_buffer_destroy(h, &out);
    close_raw(&o);
    mk_raw_free(&raw);
    check_no_validation_messages(h);
}

/* Rewrites a changed blob's checksum (docs/format.md), so mk_asset_open reaches its structural
 * checks. */
static void reseal(uint8_t *blob, size_t size)
{
    const uint64_t sum = mk_checksum(blob + 32, size - 32);
    memcpy(blob + 24, &sum, sizeof sum);
}

/* Hostile blobs: bytes of the rich fixture's quantized blob changed at random (checksum rewritten so
 * the structural checks are reached); every one mk_asset_open accepts is evaluated on every mesh.
 * Under GPU-assisted validation (the gpu_bounds test sets VK_LAYER_ENABLES) a read or write
 * outside a binding is a validation message, which fails the case. */
static void test_hostile_blobs(void)
{
    NEED_DEVICE(h);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_rich(&raw);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    size_t size;
    const uint8_t *blob = fixture_blob(&raw, MK_PRECISION_Q16, &arena, &size);
    uint8_t *copy = aligned_alloc(16, size);
    const char *env = getenv("MK_GPU_HOSTILE");
    const int tries = env ? atoi(env) : 400;
    rng r = { 0x4057113u };
    int accepted = 0;
    float p[3 * 160], n[3 * 160], t[4 * 160], w[8] = { 0.7f, -0.3f, 1.4f, 0.5f, 2.0f, 0.9f, 0, 0 };
    for (int k = 0; copy && k < tries; k++) {
        memcpy(copy, blob, size);
        for (uint32_t c = 1 + below(&r, 4); c-- > 0;) {
            const size_t at = 64 + below(&r, (uint32_t)(size - 64));
            copy[at] = below(&r, 3) ? (uint8_t)next_u64(&r) : (uint8_t)(copy[at] ^ (1u << below(&r, 8)));
        }
        reseal(copy, size);
        mk_asset a;
        mk_error err;
        if (mk_asset_open(copy, size, &a, &err) != MK_OK) continue;
        accepted++;
        mkg_asset *ga = NULL;
        if (mkg_asset_upload(h->ctx, &a, h->queue, h->family, &ga, &err) != MK_OK) {
            CHECK_MSG(0, "upload of an accepted blob failed: %s", err.message);
            continue;
        }
        for (uint32_t m = 0; m < a.mesh_count; m++) {
            mk_mesh_info mi;
            mk_mesh_get(&a, m, &mi);
            if (mi.vertex_count > 160 || mi.channel_count > 8) continue;   /* a changed count: nothing to read back into */
            mk_result res = mkg_harness_eval(h, ga, m, w, mi.channel_count, MK_STACKING_ASSET, (mk_normal_mode)(k & 1), p,
                                             mi.has_normals ? n : NULL, mi.has_tangents ? t : NULL, &err);
            CHECK_MSG(res == MK_OK, "blob %d mesh %u: %s", k, m, err.message);
        }
        mkg_asset_destroy(ga);
    }
    fprintf(stderr, "hostile blobs: %d of %d changed blobs opened and were evaluated\n", accepted, tries);
    CHECK(accepted > tries / 10);   /* most changes land in delta data, which any value may hold */
    free(copy);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
    check_no_validation_messages(h);
}

/* A blob whose mesh's target data is cut to the least mk_asset_open accepts: its last entry's
 * data, then exactly the MK_TARGET_DATA_TAIL bytes a decoder may read past it, the size not a
 * multiple of 4 (the window's end is rounded up to a whole word). The GPU must still match the
 * CPU. A window cut short of the tail goes unseen here: the bits read past a value are masked
 * off, and test_gpu_bounds's GPU-assisted validation reported nothing when it was tried. One
 * target moving 3 vertices, positions only, packed. */
static void test_data_cut_to_tail(void)
{
    NEED_DEVICE(h);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 3, 1, 1);
    raw.channels[0].targets[0].normals = NULL;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    size_t size;
    uint8_t *blob = fixture_blob(&raw, MK_PRECISION_Q16, &arena, &size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    const mk_blob_mesh *m = &a.meshes[0];
    uint64_t end = 0;
    for (uint64_t e = 0; e < m->entry_count; e++) {
        const mk_blob_entry *en = mk_entry_at(a.data + m->entries, mk_entry_stride(m->flags), e);
        const uint64_t at = (uint64_t)en->data * MK_DATA_UNIT
                          + mk_entry_bytes(en, m->flags, a.targets[m->first_target + mk_entry_target(en)].flags);
        if (at > end) end = at;
    }
    uint64_t data_size = end + MK_TARGET_DATA_TAIL;
    CHECK(m->target_data_size >= data_size);
    CHECK_MSG(data_size % 4 != 0, "the entry's data ends on a word (%llu bytes): the case tests less than it says",
              (unsigned long long)end);
    const size_t at = (size_t)((const uint8_t *)&m->target_data_size - blob);
    memcpy(blob + at, &data_size, sizeof data_size);
    reseal(blob, size);
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    CHECK(a.meshes[0].target_data_size == data_size);
    mkg_asset *ga = NULL;
    CHECK(mkg_asset_upload(h->ctx, &a, h->queue, h->family, &ga, &err) == MK_OK);
    const float w[1] = { 1.0f };
    diff d;
    if (ga && compare_mesh(h, ga, &a, 0, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, &d)) check_within(&d, "data cut to the tail");
    mkg_asset_destroy(ga);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
    check_no_validation_messages(h);
}

static void test_close(void)
{
    NEED_DEVICE(h);
    mkg_harness_close(h);
    harness_state = 0;
    CHECK_MSG(h->validation || !getenv("MK_GPU_REQUIRE_VALIDATION"), "the validation layer is required but missing");
    CHECK_MSG(h->validation_messages == 0, "the Vulkan validation layer reported %u messages in all", h->validation_messages);
}

CHECK_MAIN(CASE(test_random_assets), CASE(test_rich_clips), CASE(test_offset_and_float_entries),
           CASE(test_interleaved_outputs), CASE(test_refusals), CASE(test_hostile_blobs),
           CASE(test_data_cut_to_tail), CASE(test_close))

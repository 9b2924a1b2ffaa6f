/* SPDX-License-Identifier: MIT */
/* FBX import of writer-made fixtures: every format the writer produces (binary 7100..7700,
 * 13/25-byte records, raw and zlib arrays, ASCII 7100..7700) imports to the same raw model and
 * evaluates to the positions computed here by hand from the fixture's definition (shape
 * deltas, in-between interpolation, curve shapes, the FBX transform stack). Also: quirks
 * (Blender per-vertex FullWeights, duplicate full weights), warnings, and clear errors for
 * hostile constructs.
 *
 * `test_fbx_writer --write-seeds DIR` writes the fixtures as fuzzer seeds instead. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <libdeflate.h>
#include "check.h"
#include "fbx_fixtures.h"
#include "fbx_internal.h"
#include "fbx_test_util.h"

/* Hand-computed world position of the Box fixture's control point `cp` with Squash weight ws
 * and Grow weight wg: deltas first (mesh-local), then geometric translation (0,0,.25), the
 * pivot-wrapped 90 degree Z rotation, translation (1,2,3), and the parent's scale 2. */
static void expected_box(int cp, double ws, double wg, double out[3])
{
    static const double points[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 0, 1 }, { 0, 0, 1 },
                                         { 0, 1, 0 }, { 1, 1, 0 }, { 1, 1, 1 }, { 0, 1, 1 } };
    double p[3] = { points[cp][0], points[cp][1], points[cp][2] };
    if (cp >= 4) p[1] += -0.5 * ws;
    if (cp == 0) {
        /* Grow: keys (0.5, -0.25) and (1, -1) plus the implicit (0, 0); linear extrapolation. */
        double dx = wg <= 0.5 ? wg / 0.5 * -0.25 : -0.25 + (wg - 0.5) / 0.5 * (-1.0 + 0.25);
        p[0] += dx;
    }
    p[2] += 0.25;
    p[0] -= 0.5;
    double x = -p[1], y = p[0];
    p[0] = x + 0.5 + 1;
    p[1] = y + 2;
    p[2] = p[2] + 3;
    for (int k = 0; k < 3; k++) out[k] = 2 * p[k];
}

static double smoothstep(double s) { return s * s * (3 - 2 * s); }

static const uint32_t versions[] = { 7100, 7200, 7400, 7500, 7700 };

static unsigned char *make_fixture(uint32_t version, int binary, int compress, size_t *size)
{
    fbxw_scene scene;
    fixture_cube(&scene, version, binary, compress);
    unsigned char *data = NULL;
    if (fbxw_write(&scene, &data, size) != 0) return NULL;
    return data;
}

static void check_box_import(const mk_raw_asset *raw, const char *label)
{
    CHECK_MSG(raw->mesh_count == 2, "%s: %u meshes", label, raw->mesh_count);
    int32_t box = ft_find_mesh(raw, "Box");
    CHECK_MSG(box >= 0, "%s: no Box mesh (names must drop the Model:: prefix)", label);
    CHECK(ft_find_mesh(raw, "Root") >= 0);
    if (box < 0) return;
    const mk_raw_mesh *m = &raw->meshes[box];
    CHECK_EQ_INT(m->control_point_count, 8);
    CHECK_EQ_INT(m->vertex_count, 24);       /* split at every hard edge */
    CHECK_EQ_INT(m->triangle_count, 12);
    CHECK(m->normals != NULL);
    /* Every render vertex maps to a control point and keeps its position. */
    for (uint32_t v = 0; v < m->vertex_count; v++) CHECK(m->control_points[v] < 8);
    CHECK_EQ_INT(raw->channel_count, 2);
    if (raw->channel_count != 2) return;
    const mk_raw_channel *squash = &raw->channels[0], *grow = &raw->channels[1];
    CHECK(strcmp(squash->name, "Squash") == 0);
    CHECK(strcmp(grow->name, "Grow") == 0);
    CHECK_NEAR(squash->default_weight, 0.25, 1e-7);
    CHECK_NEAR(grow->default_weight, 0.0, 1e-7);
    CHECK_EQ_INT(squash->target_count, 1);
    CHECK_EQ_INT(grow->target_count, 2);
    if (grow->target_count == 2) {
        /* FullWeights pair with shapes in connection order: Grow100 <- 100, Grow50 <- 50. */
        CHECK(strcmp(grow->targets[0].name, "Grow50") == 0);
        CHECK_NEAR(grow->targets[0].full_weight, 0.5, 1e-7);
        CHECK(strcmp(grow->targets[1].name, "Grow100") == 0);
        CHECK_NEAR(grow->targets[1].full_weight, 1.0, 1e-7);
        /* Grow50: out-of-range entry skipped, zero delta dropped: only control point 0's
         * three render vertices move, in increasing order (other entries are neighbours whose
         * normals change: computed normal deltas with zero position delta). */
        const mk_raw_target *t = &grow->targets[0];
        uint32_t moved = 0;
        for (uint32_t i = 0; i < t->count; i++) {
            if (i) CHECK(t->indices[i] > t->indices[i - 1]);
            int zero = t->positions[3 * i] == 0 && t->positions[3 * i + 1] == 0 && t->positions[3 * i + 2] == 0;
            if (zero) continue;
            moved++;
            CHECK(m->control_points[t->indices[i]] == 0);
            CHECK_NEAR(t->positions[3 * i], -0.25, 1e-7);
        }
        CHECK_EQ_INT(moved, 3);
    }
    if (squash->target_count == 1) {
        const mk_raw_target *t = &squash->targets[0];
        uint32_t moved = 0;
        for (uint32_t i = 0; i < t->count; i++) {
            if (t->positions[3 * i + 1] == 0) continue;
            moved++;
            CHECK(m->control_points[t->indices[i]] >= 4);
            CHECK_NEAR(t->positions[3 * i + 1], -0.5, 1e-7);
        }
        CHECK_EQ_INT(moved, 12);     /* 4 top points x 3 render vertices each */
        CHECK(t->normals != NULL);   /* computed from positions (no shape normals in the file) */
    }
    /* One warning at least: the out-of-range index. */
    int warned = 0;
    for (uint32_t i = 0; i < raw->warning_count && i < MK_RAW_MAX_WARNINGS; i++)
        if (strstr(raw->warnings[i].message, "outside")) warned = 1;
    CHECK_MSG(warned, "%s: no warning for the out-of-range shape index", label);
    CHECK_EQ_INT(raw->clip_count, 1);
    if (raw->clip_count == 1) {
        CHECK_NEAR(raw->clips[0].start, 0.0, 1e-7);
        CHECK_NEAR(raw->clips[0].duration, 2.0, 1e-6);
        CHECK_EQ_INT(raw->clips[0].track_count, 2);
    }
}

static void check_box_frames(const mk_raw_asset *raw, const char *label)
{
    int32_t box = ft_find_mesh(raw, "Box");
    if (box < 0 || raw->clip_count != 1) return;
    static const double times[] = { 0.0, 0.25, 0.5, 1.0, 1.3, 1.75, 2.0, 3.0 };
    for (size_t i = 0; i < sizeof times / sizeof times[0]; i++) {
        double t = times[i] > 2 ? 2 : times[i];
        double ws = t <= 1 ? smoothstep(t) : smoothstep(2 - t);
        double wg = t / 2;
        float *p = NULL;
        uint32_t n = 0;
        CHECK(ft_eval_control_points(raw, (uint32_t)box, 0, (float)times[i], NULL, 1, &p, &n) == 0);
        if (!p) continue;
        CHECK_EQ_INT(n, 8);
        for (int cp = 0; cp < 8 && n == 8; cp++) {
            double e[3];
            expected_box(cp, ws, wg, e);
            for (int k = 0; k < 3; k++)
                CHECK_MSG(fabs(p[3 * cp + k] - e[k]) < 2e-5, "%s t=%g cp %d[%d]: %g, expected %g", label, times[i], cp, k,
                          (double)p[3 * cp + k], e[k]);
        }
        free(p);
    }
    /* Rest pose (no clip): default weights 0.25 / 0. */
    float *p = NULL;
    uint32_t n = 0;
    CHECK(ft_eval_control_points(raw, (uint32_t)box, -1, 0, NULL, 1, &p, &n) == 0);
    for (int cp = 0; p && cp < 8; cp++) {
        double e[3];
        expected_box(cp, 0.25, 0.0, e);
        for (int k = 0; k < 3; k++) CHECK_NEAR(p[3 * cp + k], e[k], 2e-5);
    }
    free(p);
    /* Extrapolated in-between weights (1.5 and -0.5) follow the first/last span. */
    float weights[2] = { 0.0f, 1.5f };
    CHECK(ft_eval_control_points(raw, (uint32_t)box, -1, 0, weights, 1, &p, &n) == 0);
    if (p) {
        double e[3];
        expected_box(0, 0, 1.5, e);
        for (int k = 0; k < 3; k++) CHECK_NEAR(p[k], e[k], 2e-5);
        free(p);
    }
}

static void test_formats_roundtrip(void)
{
    for (size_t v = 0; v < sizeof versions / sizeof versions[0]; v++)
        for (int mode = 0; mode < 3; mode++) {  /* 0 ASCII, 1 binary raw arrays, 2 binary zlib arrays */
            char label[64];
            snprintf(label, sizeof label, "%u %s", versions[v], mode == 0 ? "ascii" : mode == 1 ? "binary" : "binary+zlib");
            size_t size;
            unsigned char *data = make_fixture(versions[v], mode > 0, mode == 2, &size);
            CHECK(data != NULL);
            if (!data) continue;
            mk_raw_asset raw;
            mk_error err;
            mk_result r = ft_import(data, size, NULL, &raw, &err);
            CHECK_MSG(r == MK_OK, "%s: %s", label, err.message);
            if (r == MK_OK) {
                CHECK_MSG(mk_raw_validate(&raw, &err) == MK_OK, "%s: %s", label, err.message);
                char expect[32];
                snprintf(expect, sizeof expect, "fbx %u %s", versions[v], mode ? "binary" : "ascii");
                CHECK_MSG(strcmp(raw.source_format, expect) == 0, "%s: source_format '%s'", label, raw.source_format);
                CHECK(strcmp(raw.source_creator, "morphkit test writer") == 0);
                CHECK_EQ_INT(raw.up_axis, 1);
                CHECK_NEAR(raw.unit_scale, 1.0, 0);
                check_box_import(&raw, label);
                check_box_frames(&raw, label);
            }
            mk_raw_free(&raw);
            free(data);
        }
}

static void test_stacking_option(void)
{
    size_t size;
    unsigned char *data = make_fixture(7400, 1, 0, &size);
    CHECK(data != NULL);
    if (!data) return;
    mk_import_options options;
    memset(&options, 0, sizeof options);
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, &options, &raw, &err) == MK_OK);
    for (uint32_t m = 0; m < raw.mesh_count; m++) CHECK_EQ_INT(raw.meshes[m].stacking, MK_STACKING_ADDITIVE);
    mk_raw_free(&raw);
    options.stacking = MK_STACKING_SEQUENTIAL;
    CHECK(ft_import(data, size, &options, &raw, &err) == MK_OK);
    for (uint32_t m = 0; m < raw.mesh_count; m++) CHECK_EQ_INT(raw.meshes[m].stacking, MK_STACKING_SEQUENTIAL);
    mk_raw_free(&raw);
    options.stacking = (mk_stacking)7;
    CHECK(ft_import(data, size, &options, &raw, &err) == MK_ERROR_INVALID_ARGUMENT);
    mk_raw_free(&raw);
    options.stacking = MK_STACKING_ADDITIVE;
    options.max_input_size = size - 1;
    CHECK(ft_import(data, size, &options, &raw, &err) == MK_ERROR_LIMIT);
    mk_raw_free(&raw);
    free(data);
}

/* ---- curves: one channel, keys chosen per case ---- */

static const double one_point[3] = { 0, 0, 0 };
static const int32_t one_triangle[3] = { 0, 0, ~0 };
static const double tri_points[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
static const int32_t tri_polygon[3] = { 0, 1, ~2 };

/* A mesh of one triangle (control points 0, 1, 2 of `points`) without a parent. */
static fbxw_mesh triangle_mesh(const char *name, const double *points, const fbxw_channel *channels, uint32_t channel_count)
{
    fbxw_mesh mesh = { .name = name, .control_point_count = 3, .control_points = points, .polygon_vertex_count = 3,
                       .polygon_vertex_index = tri_polygon, .channel_count = channel_count, .channels = channels,
                       .parent = -1 };
    return mesh;
}

/* Writes `scene` and imports it (raw is initialized either way); the write failing is
 * reported as MK_ERROR_CORRUPT. */
static mk_result write_import(const fbxw_scene *scene, mk_raw_asset *raw, mk_error *err)
{
    unsigned char *data;
    size_t size;
    memset(err, 0, sizeof *err);
    if (fbxw_write(scene, &data, &size) != 0) {
        mk_raw_init(raw, NULL);
        snprintf(err->message, sizeof err->message, "the test FBX writer failed");
        return MK_ERROR_CORRUPT;
    }
    mk_result r = ft_import(data, size, NULL, raw, err);
    free(data);
    return r;
}

static int import_curve(const int64_t *times, const float *values, const int32_t *flags, const float *attr, uint32_t count,
                        int binary, mk_raw_asset *raw)
{
    static const int32_t idx[1] = { 0 };
    static const double delta[3] = { 1, 0, 0 };
    static const double fw[1] = { 100 };
    fbxw_shape shape = { "S", 1, idx, delta, NULL, 0 };
    fbxw_curve curve = { count, times, values, flags, attr };
    fbxw_channel channel = { .name = "C", .shape_count = 1, .shapes = &shape, .full_weight_count = 1, .full_weights = fw,
                             .curve = &curve };
    fbxw_mesh mesh = triangle_mesh("M", one_point, &channel, 1);
    mesh.control_point_count = 1;
    mesh.polygon_vertex_index = one_triangle;
    fbxw_scene scene = { .version = 7500, .binary = binary, .stack_stop = FIXTURE_KTIME(4), .mesh_count = 1, .meshes = &mesh };
    mk_error err;
    mk_result r = write_import(&scene, raw, &err);
    if (r != MK_OK) fprintf(stderr, "curve import: %s\n", err.message);
    return r == MK_OK && raw->clip_count == 1 && raw->clips[0].track_count == 1 ? 0 : -1;
}

static float sample(const mk_raw_asset *raw, double t)
{
    const mk_raw_track *tr = &raw->clips[0].tracks[0];
    return mk_curve_eval(tr->keys, tr->key_count, (float)t, NULL);
}

static float packed(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, 4);
    return f;
}

static void test_curves(void)
{
    for (int binary = 0; binary < 2; binary++) {
        mk_raw_asset raw;
        int64_t t3[3] = { FIXTURE_KTIME(0), FIXTURE_KTIME(1), FIXTURE_KTIME(3) };
        /* Constant, then constant-next, then linear (last key's flags unused). */
        {
            float v[3] = { 10, 50, 90 };
            int32_t f[3] = { 0x2, 0x102, 0x4 };
            float a[12] = { 0 };
            CHECK(import_curve(t3, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) {
                CHECK_NEAR(sample(&raw, 0.5), 0.10, 1e-6);   /* hold */
                CHECK_NEAR(sample(&raw, 2.0), 0.90, 1e-6);   /* constant-next: next key's value */
                CHECK_NEAR(sample(&raw, 1.0), 0.50, 1e-6);
                CHECK_NEAR(sample(&raw, -1.0), 0.10, 1e-6);  /* before the first key: first value */
                CHECK_NEAR(sample(&raw, 9.0), 0.90, 1e-6);   /* after the last key: last value */
            }
            mk_raw_free(&raw);
        }
        /* User tangents (Hermite with 1/3 weights): slopes in percent per second. */
        {
            float v[3] = { 0, 100, 0 };
            int32_t f[3] = { 0x408, 0x408, 0x408 };
            float a[12] = { 200, -100, packed(0x0D050D05u), 0, 0, 0, packed(0x0D050D05u), 0, 0, 0, packed(0x0D050D05u), 0 };
            CHECK(import_curve(t3, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) {
                /* Segment 0..1: p0=0, p1=1 (normalized), m0 = 2/s, m1 = -1/s; Hermite at s=.5. */
                double s = 0.5, h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
                double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
                double expect = h00 * 0 + h10 * 2.0 + h01 * 1 + h11 * -1.0;
                CHECK_NEAR(sample(&raw, 0.5), expect, 2e-4);
            }
            mk_raw_free(&raw);
        }
        /* Auto tangents recomputed: interior key on a monotonic run gets the neighbour slope
         * (clamped so handles stay within the neighbours); extremum and ends get 0. */
        {
            float v[3] = { 0, 50, 100 };
            int32_t f[3] = { 0x6108, 0x6108, 0x6108 };
            float a[12] = { 0, 0, packed(0x0D050D05u), 0, 0, 0, packed(0x0D050D05u), 0, 0, 0, packed(0x0D050D05u), 0 };
            CHECK(import_curve(t3, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) {
                const mk_key *k = raw.clips[0].tracks[0].keys;
                /* (100 - 0) / (3 - 0) % per s = 1/3 per s; clamp limits: left 0.5/(1/3*1) = 1.5, right 0.5/(1/3*2) = .75. */
                CHECK_NEAR(k[1].left_slope, 1.0 / 3.0, 1e-6);
                CHECK_NEAR(k[1].right_slope, 1.0 / 3.0, 1e-6);
                CHECK_NEAR(k[0].right_slope, 0.0, 0);
                CHECK_NEAR(k[2].left_slope, 0.0, 0);
            }
            mk_raw_free(&raw);
        }
        /* Weighted tangents: packed weights (right 0.2 of key 0, next-left 0.6). */
        {
            float v[3] = { 0, 100, 0 };
            int32_t f[3] = { 0x408 | 0x1000000 | 0x2000000, 0x408, 0x408 };
            uint32_t bits = 2000u | (6000u << 16);
            float a[12] = { 0, 0, packed(bits), 0, 0, 0, packed(0x0D050D05u), 0, 0, 0, packed(0x0D050D05u), 0 };
            CHECK(import_curve(t3, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) {
                const mk_key *k = raw.clips[0].tracks[0].keys;
                CHECK_NEAR(k[0].right_weight, 0.2, 1e-6);
                CHECK_NEAR(k[1].left_weight, 0.6, 1e-6);
                CHECK_NEAR(k[1].right_weight, 1.0 / 3.0, 1e-6);
                CHECK_EQ_INT(k[0].interp, MK_INTERP_CUBIC);
            }
            mk_raw_free(&raw);
        }
        /* TCB with tension = continuity = bias = 0: Catmull-Rom-like slopes from the one-sided
         * secants, halved in the interior (ufbxi_solve_tcb): key 1 = .5 (100/1 - 100/2) = 25 %/s,
         * key 0 (an end, factor 1) = its right secant 100 %/s. */
        {
            float v[3] = { 0, 100, 0 };
            int32_t f[3] = { 0x208, 0x208, 0x208 };
            float a[12] = { 0 };
            CHECK(import_curve(t3, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) {
                const mk_key *k = raw.clips[0].tracks[0].keys;
                CHECK_NEAR(k[1].left_slope, 0.25, 1e-6);
                CHECK_NEAR(k[1].right_slope, 0.25, 1e-6);
                CHECK_NEAR(k[0].right_slope, 1.0, 1e-6);
            }
            mk_raw_free(&raw);
        }
        /* Auto tangents without the time-independent flag average the neighbour secant with the
         * time-weighted one-sided secants (ufbxi_solve_auto_tangent):
         * slope = total/2 + (left (1 - d) + right d)/2, d = (t1 - t0)/(t2 - t0). */
        {
            float v[3] = { 0, 100, 150 };
            int32_t f[3] = { 0x108, 0x108, 0x108 };  /* cubic auto, no clamp, not time-independent */
            float a[12] = { 0 };
            CHECK(import_curve(t3, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) {
                const mk_key *k = raw.clips[0].tracks[0].keys;
                double total = 150.0 / 3.0, left = 100.0, right = 25.0, delta = 1.0 / 3.0;
                double expect = total * 0.5 + (left * (1 - delta) + right * delta) * 0.5;
                CHECK_NEAR(k[1].right_slope, expect / 100.0, 1e-6);
                /* Unclamped end keys take their one-sided secant. */
                CHECK_NEAR(k[0].right_slope, 1.0, 1e-6);
                CHECK_NEAR(k[2].left_slope, 0.25, 1e-6);
            }
            mk_raw_free(&raw);
        }
        /* Duplicate key times collapse to the first key (warning), never an invalid track. */
        {
            int64_t td[3] = { FIXTURE_KTIME(0), FIXTURE_KTIME(1), FIXTURE_KTIME(1) };
            float v[3] = { 0, 100, 50 };
            int32_t f[3] = { 0x4, 0x4, 0x4 };
            float a[12] = { 0 };
            CHECK(import_curve(td, v, f, a, 3, binary, &raw) == 0);
            if (raw.clip_count) CHECK_EQ_INT(raw.clips[0].tracks[0].key_count, 2);
            mk_error err;
            CHECK(mk_raw_validate(&raw, &err) == MK_OK);
            CHECK(raw.warning_count > 0);
            mk_raw_free(&raw);
        }
    }
}

/* ---- quirks ---- */

static void test_blender_full_weights(void)
{
    static const int32_t idx[2] = { 0, 1 };
    static const double delta[6] = { 0, 0, 2, 0, 0, 2 };
    static const double fw[2] = { 25, 100 };  /* per Indexes entry: Blender vertex-group weights */
    for (int blender = 0; blender < 2; blender++) {
        fbxw_shape shape = { "Key", 2, idx, delta, NULL, 0 };
        fbxw_channel channel = { .name = "Key", .deform_percent = 100, .deform_as_field_only = 1, .shape_count = 1,
                                 .shapes = &shape, .full_weight_count = 2, .full_weights = fw };
        fbxw_mesh mesh = triangle_mesh("Tri", tri_points, &channel, 1);
        fbxw_scene scene = { .version = 7400, .binary = 1, .mesh_count = 1, .meshes = &mesh,
                             .creator = blender ? "Blender (stable FBX IO) - 4.4.1 - 5.12.7"
                                                : "FBX SDK/FBX Plugins version 2020.1" };
        mk_raw_asset raw;
        mk_error err;
        CHECK(write_import(&scene, &raw, &err) == MK_OK);
        CHECK_EQ_INT(raw.channel_count, 1);
        if (raw.channel_count == 1) {
            const mk_raw_channel *ch = &raw.channels[0];
            CHECK_NEAR(ch->default_weight, 1.0, 1e-7);  /* DeformPercent read from the plain field */
            CHECK_EQ_INT(ch->target_count, 1);
            const mk_raw_target *t = &ch->targets[0];
            /* Blender: weights scale the deltas, full weight 1. Others: FullWeights[0] = 25 %. */
            CHECK_NEAR(t->full_weight, blender ? 1.0 : 0.25, 1e-7);
            for (uint32_t i = 0; i < t->count; i++) {
                uint32_t cp = raw.meshes[0].control_points[t->indices[i]];
                double expect = cp > 1 ? 0.0 : blender ? (cp == 0 ? 0.5 : 2.0) : 2.0;
                CHECK_NEAR(t->positions[3 * i + 2], expect, 1e-7);
            }
        }
        mk_raw_free(&raw);
    }
}

/* Blender's vertex-group reading of FullWeights is for a channel of one shape (Blender exports
 * no in-betweens): a Blender file whose channel has two shapes and one FullWeights entry per
 * shape gets in-betweens at those weights, with the deltas unscaled. */
static void test_blender_inbetweens_keep_full_weights(void)
{
    static const int32_t idx[2] = { 0, 1 };
    static const double half[6] = { 0, 0, 1, 0, 0, 1 }, full[6] = { 0, 0, 3, 0, 0, 3 };
    static const double fw[2] = { 50, 100 };
    static const double points[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    static const int32_t tri[3] = { 0, 1, ~2 };
    fbxw_shape shapes[2] = { { "Half", 2, idx, half, NULL, 0 }, { "Full", 2, idx, full, NULL, 0 } };
    fbxw_channel channel;
    memset(&channel, 0, sizeof channel);
    channel.name = "Key";
    channel.deform_percent = 0;
    channel.deform_as_field_only = 1;
    channel.shape_count = 2;
    channel.shapes = shapes;
    channel.full_weight_count = 2;
    channel.full_weights = fw;
    fbxw_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    mesh.name = "Tri";
    mesh.control_point_count = 3;
    mesh.control_points = points;
    mesh.polygon_vertex_count = 3;
    mesh.polygon_vertex_index = tri;
    mesh.channel_count = 1;
    mesh.channels = &channel;
    mesh.parent = -1;
    fbxw_scene scene;
    memset(&scene, 0, sizeof scene);
    scene.version = 7400;
    scene.binary = 1;
    scene.creator = "Blender (stable FBX IO) - 4.4.1 - 5.12.7";
    scene.mesh_count = 1;
    scene.meshes = &mesh;
    unsigned char *data;
    size_t size;
    CHECK(fbxw_write(&scene, &data, &size) == 0);
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    free(data);
    CHECK_EQ_INT(raw.channel_count, 1);
    if (raw.channel_count == 1 && raw.channels[0].target_count == 2) {
        const mk_raw_channel *ch = &raw.channels[0];
        for (uint32_t k = 0; k < 2; k++) {
            const mk_raw_target *t = &ch->targets[k];
            CHECK_NEAR(t->full_weight, k ? 1.0 : 0.5, 1e-7);
            for (uint32_t i = 0; i < t->count; i++) {
                uint32_t cp = raw.meshes[0].control_points[t->indices[i]];
                CHECK_NEAR(t->positions[3 * i + 2], cp > 1 ? 0.0 : k ? 3.0 : 1.0, 1e-7);
            }
        }
    } else {
        CHECK_MSG(0, "expected one channel of two in-betweens");
    }
    mk_raw_free(&raw);
}

static void test_duplicate_full_weights(void)
{
    static const int32_t idx[1] = { 0 };
    static const double d1[3] = { 1, 0, 0 }, d2[3] = { 2, 0, 0 }, d3[3] = { 3, 0, 0 };
    static const double fw[3] = { 50, 50, 0 };  /* duplicate, then a zero full weight */
    fbxw_shape shapes[3] = { { "A", 1, idx, d1, NULL, 0 }, { "B", 1, idx, d2, NULL, 0 }, { "C", 1, idx, d3, NULL, 0 } };
    fbxw_channel channel = { .name = "Dup", .shape_count = 3, .shapes = shapes, .full_weight_count = 3, .full_weights = fw };
    fbxw_mesh mesh = triangle_mesh("Tri", tri_points, &channel, 1);
    fbxw_scene scene = { .version = 7500, .binary = 0, .mesh_count = 1, .meshes = &mesh };
    mk_raw_asset raw;
    mk_error err;
    CHECK(write_import(&scene, &raw, &err) == MK_OK);
    CHECK_EQ_INT(raw.channel_count, 1);
    if (raw.channel_count == 1) {
        CHECK_EQ_INT(raw.channels[0].target_count, 1);
        if (raw.channels[0].target_count) CHECK(strcmp(raw.channels[0].targets[0].name, "A") == 0);
    }
    CHECK(raw.warning_count >= 2);
    CHECK(mk_raw_validate(&raw, &err) == MK_OK);
    mk_raw_free(&raw);
}

/* Full weights the runtime cannot place (closer than 1e-6 to 0, or to the previous
 * in-between) are skipped with a warning at import, not passed on to fail validation. */
static void test_tiny_full_weights(void)
{
    static const int32_t idx[1] = { 0 };
    static const double d1[3] = { 1, 0, 0 }, d2[3] = { 2, 0, 0 }, d3[3] = { 3, 0, 0 }, d4[3] = { 4, 0, 0 };
    /* percent: 1e-5 % = 1e-7 (too close to 0), 50, 50 + 1e-5 % (too close to 50), 100 */
    static const double fw[4] = { 1e-5, 50, 50.00001, 100 };
    fbxw_shape shapes[4] = { { "A", 1, idx, d1, NULL, 0 }, { "B", 1, idx, d2, NULL, 0 }, { "C", 1, idx, d3, NULL, 0 },
                             { "D", 1, idx, d4, NULL, 0 } };
    fbxw_channel channel = { .name = "Tiny", .shape_count = 4, .shapes = shapes, .full_weight_count = 4, .full_weights = fw };
    fbxw_mesh mesh = triangle_mesh("Tri", tri_points, &channel, 1);
    fbxw_scene scene = { .version = 7500, .binary = 1, .mesh_count = 1, .meshes = &mesh };
    mk_raw_asset raw;
    mk_error err;
    CHECK(write_import(&scene, &raw, &err) == MK_OK);
    CHECK_MSG(mk_raw_validate(&raw, &err) == MK_OK, "%s", err.message);
    CHECK_EQ_INT(raw.channel_count, 1);
    if (raw.channel_count == 1) {
        CHECK_EQ_INT(raw.channels[0].target_count, 2);
        if (raw.channels[0].target_count == 2) {
            CHECK(strcmp(raw.channels[0].targets[0].name, "B") == 0);
            CHECK(strcmp(raw.channels[0].targets[1].name, "D") == 0);
        }
    }
    CHECK(raw.warning_count >= 2);
    mk_raw_free(&raw);
}

/* Rotation order and pre-rotation: a point at (1,0,0) under T(1,0,0) and R(90,0,90).
 * XYZ applies X first: (1,0,0) -> (1,0,0) -> (0,1,0), + T = (1,1,0).
 * ZYX applies Z first: (1,0,0) -> (0,1,0) -> (0,0,1), + T = (1,0,1).
 * R(90,0,0) XYZ with PreRotation(0,0,90): Rpre after R: (1,0,0) -> (1,0,0) -> (0,1,0) + T.
 * A smoke test on evaluated positions: with a zero Y angle several orders agree, so the six
 * orders, every transform property and parent chains are checked against the full formula in
 * test_fbx_transform.c. */
static void test_rotation_order(void)
{
    static const double points[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    struct { double r[3], pre[3]; int order; double expect[3]; } cases[] = {
        { { 90, 0, 90 }, { 0, 0, 0 }, 0, { 1, 1, 0 } },
        { { 90, 0, 90 }, { 0, 0, 0 }, 5, { 1, 0, 1 } },
        { { 90, 0, 0 }, { 0, 0, 90 }, 0, { 1, 1, 0 } },
        { { 90, 0, 0 }, { 0, 0, 0 }, 0, { 2, 0, 0 } },
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        for (int binary = 0; binary < 2; binary++) {
            fbxw_mesh mesh = triangle_mesh("Tri", points, NULL, 0);
            mesh.translation[0] = 1;
            memcpy(mesh.rotation, cases[c].r, sizeof mesh.rotation);
            memcpy(mesh.pre_rotation, cases[c].pre, sizeof mesh.pre_rotation);
            mesh.rotation_order = cases[c].order;
            fbxw_scene scene = { .version = 7400, .binary = binary, .mesh_count = 1, .meshes = &mesh };
            mk_raw_asset raw;
            mk_error err;
            CHECK(write_import(&scene, &raw, &err) == MK_OK);
            float *p = NULL;
            uint32_t n = 0;
            CHECK(raw.mesh_count == 1 && ft_eval_control_points(&raw, 0, -1, 0, NULL, 1, &p, &n) == 0);
            for (int k = 0; p && k < 3; k++)
                CHECK_MSG(fabs(p[k] - cases[c].expect[k]) < 1e-6, "case %zu axis %d: %g expected %g", c, k, (double)p[k],
                          cases[c].expect[k]);
            free(p);
            mk_raw_free(&raw);
        }
    }
}

/* FBX 6.1 ASCII written by hand (always runs, unlike the corpus): geometry and a `Shape:`
 * inside the Model, the weight as a Properties60 property named after the shape, name-based
 * connections, and a Take whose `Key:` list mixes linear, constant-next and cubic keys. */
static void test_legacy_61_ascii(void)
{
    const char *text = fixture_legacy61;
    mk_raw_asset raw;
    mk_error err;
    mk_result r = ft_import(text, strlen(text), NULL, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r != MK_OK) { mk_raw_free(&raw); return; }
    CHECK(strcmp(raw.source_format, "fbx 6100 ascii") == 0);
    CHECK_EQ_INT(raw.mesh_count, 1);
    CHECK_EQ_INT(raw.channel_count, 1);
    if (raw.mesh_count == 1 && raw.channel_count == 1) {
        CHECK(strcmp(raw.meshes[0].name, "Tri") == 0);
        CHECK_EQ_INT(raw.meshes[0].control_point_count, 3);
        CHECK(strcmp(raw.channels[0].name, "Up") == 0);
        CHECK_NEAR(raw.channels[0].default_weight, 0.4, 1e-7);
        CHECK_EQ_INT(raw.clip_count, 1);
        if (raw.clip_count == 1) {
            CHECK_NEAR(raw.clips[0].duration, 2.0, 1e-6);
            CHECK_EQ_INT(raw.clips[0].track_count, 1);
            /* 0 -> 1 linear over 1 s, then constant-next: 0.5 right after t = 1. */
            CHECK_NEAR(sample(&raw, 0.5), 0.5, 1e-6);
            CHECK_NEAR(sample(&raw, 1.2), 0.5, 1e-6);
            CHECK_NEAR(sample(&raw, 1.0), 1.0, 1e-6);
        }
        /* World: scale 2 then translate 10: point 2 at (0,1,0) + weight 0.4 * (0,0,1). */
        float *p = NULL;
        uint32_t n = 0;
        CHECK(ft_eval_control_points(&raw, 0, -1, 0, NULL, 1, &p, &n) == 0);
        if (p && n == 3) {
            CHECK_NEAR(p[6], 10.0, 1e-6);
            CHECK_NEAR(p[7], 2.0, 1e-6);
            CHECK_NEAR(p[8], 0.8, 1e-6);
        }
        free(p);
    }
    mk_raw_free(&raw);
}

/* InheritType: a child at T(1,0,0) under a parent scaled by 2 has its origin at x = 2 either
 * way (the parent scales the child's translation); its own unit x is 4 with RSrs (the default)
 * and 3 with Rrs (Maya segment scale compensate: the parent's scale does not scale the child). */
static void test_inherit_type(void)
{
    for (int ignore = 0; ignore < 2; ignore++) {
        fbxw_mesh meshes[2] = { triangle_mesh("Parent", tri_points, NULL, 0), triangle_mesh("Child", tri_points, NULL, 0) };
        meshes[1].parent = 0;
        meshes[0].scaling[0] = meshes[0].scaling[1] = meshes[0].scaling[2] = 2;
        meshes[1].translation[0] = 1;
        meshes[1].ignore_parent_scale = ignore;
        fbxw_scene scene = { .version = 7500, .binary = 1, .mesh_count = 2, .meshes = meshes };
        mk_raw_asset raw;
        mk_error err;
        CHECK(write_import(&scene, &raw, &err) == MK_OK);
        int32_t child = ft_find_mesh(&raw, "Child");
        float *p = NULL;
        uint32_t n = 0;
        CHECK(child >= 0 && ft_eval_control_points(&raw, (uint32_t)child, -1, 0, NULL, 1, &p, &n) == 0);
        if (p) {
            CHECK_NEAR(p[0], 2.0, 1e-6);                     /* control point 0 = the child's origin */
            CHECK_NEAR(p[3], ignore ? 3.0 : 4.0, 1e-6);      /* (1,0,0): the child's own unit, scaled or not */
        }
        free(p);
        mk_raw_free(&raw);
    }
}

/* ---- meshes that cannot be imported are skipped with a warning ---- */

/* 1 when some warning contains both `a` and `b`. */
static int has_warning(const mk_raw_asset *raw, const char *a, const char *b)
{
    for (uint32_t i = 0; i < raw->warning_count && i < MK_RAW_MAX_WARNINGS; i++)
        if (strstr(raw->warnings[i].message, a) && strstr(raw->warnings[i].message, b)) return 1;
    return 0;
}

/* A scene whose "Prop" mesh has an empty Vertices array (and, in one variant, a blend shape
 * channel of its own) next to "Tri" (one triangle, one channel) and "Plain" (a triangle
 * without blend shapes): Prop is skipped with a warning naming it, Tri and Plain import. */
static void test_empty_mesh_skipped(void)
{
    static const int32_t idx[1] = { 2 };
    static const double delta[3] = { 0, 0, 1 };
    static const double fw[1] = { 100 };
    fbxw_shape shape = { "Up", 1, idx, delta, NULL, 0 };
    fbxw_channel channels[2] = { { .name = "Up", .deform_percent = 50, .shape_count = 1, .shapes = &shape,
                                   .full_weight_count = 1, .full_weights = fw } };
    channels[1] = channels[0];
    channels[1].name = "PropUp";
    for (int variant = 0; variant < 4; variant++) {
        int binary = variant & 1, prop_has_channel = variant >> 1;
        fbxw_mesh meshes[3] = { { .name = "Prop", .parent = -1 },   /* no control points, no polygons */
                                triangle_mesh("Tri", tri_points, &channels[0], 1),
                                triangle_mesh("Plain", tri_points, NULL, 0) };
        meshes[0].channel_count = prop_has_channel ? 1 : 0;
        meshes[0].channels = &channels[1];
        fbxw_scene scene = { .version = binary ? 7500 : 7400, .binary = binary, .mesh_count = 3, .meshes = meshes };
        mk_raw_asset raw;
        mk_error err;
        mk_result r = write_import(&scene, &raw, &err);
        CHECK_MSG(r == MK_OK, "variant %d: %s", variant, err.message);
        if (r == MK_OK) {
            CHECK_EQ_INT(raw.mesh_count, 2);
            CHECK(ft_find_mesh(&raw, "Prop") < 0);
            CHECK(ft_find_mesh(&raw, "Tri") >= 0);
            CHECK(ft_find_mesh(&raw, "Plain") >= 0);   /* meshes without blend shapes are kept */
            CHECK_EQ_INT(raw.channel_count, 1);
            if (raw.channel_count == 1) CHECK(strcmp(raw.channels[0].name, "Up") == 0);
            CHECK_MSG(has_warning(&raw, "'Prop'", "no vertices"), "variant %d: no warning names the skipped mesh", variant);
            if (prop_has_channel) CHECK(has_warning(&raw, "'Prop'", "1 blend shape channel"));
            CHECK(mk_raw_validate(&raw, &err) == MK_OK);
        }
        mk_raw_free(&raw);
    }
}

/* Other reasons a mesh is not imported, each named in a warning: a mesh geometry no model uses,
 * a second mesh geometry on one model, and (6.x) a mesh model without Vertices. */
static void test_skipped_mesh_warnings(void)
{
    const char *orphan =
        "; FBX 7.4.0 project file\nObjects: {\n"
        " Geometry: 1, \"Geometry::Used\", \"Mesh\" {\n  Vertices: *9 { a: 0,0,0,1,0,0,0,1,0 }\n"
        "  PolygonVertexIndex: *3 { a: 0,1,-3 }\n }\n"
        " Geometry: 3, \"Geometry::Spare\", \"Mesh\" {\n  Vertices: *9 { a: 0,0,0,1,0,0,0,1,0 }\n"
        "  PolygonVertexIndex: *3 { a: 0,1,-3 }\n }\n"
        " Geometry: 4, \"Geometry::Lost\", \"Mesh\" {\n  Vertices: *9 { a: 0,0,0,1,0,0,0,1,0 }\n"
        "  PolygonVertexIndex: *3 { a: 0,1,-3 }\n }\n"
        " Model: 2, \"Model::M\", \"Mesh\" {\n }\n"
        " Model: 5, \"Model::Hollow\", \"Mesh\" {\n }\n"
        "}\nConnections: {\n C: \"OO\",1,2\n C: \"OO\",3,2\n}\n";
    mk_raw_asset raw;
    mk_error err;
    mk_result r = ft_import(orphan, strlen(orphan), NULL, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    CHECK_EQ_INT(raw.mesh_count, 1);
    CHECK(has_warning(&raw, "'Lost'", "no model"));
    CHECK(has_warning(&raw, "'M'", "'Spare'"));
    CHECK(has_warning(&raw, "'Hollow'", "no mesh geometry"));
    mk_raw_free(&raw);
    const char *legacy =
        "; FBX 6.1.0 project file\nObjects:  {\n"
        "\tModel: \"Model::Tri\", \"Mesh\" {\n\t\tVertices: 0,0,0,1,0,0,0,1,0\n\t\tPolygonVertexIndex: 0,1,-3\n\t}\n"
        "\tModel: \"Model::Prop\", \"Mesh\" {\n\t\tVersion: 232\n\t}\n"
        "\tModel: \"Model::Empty\", \"Mesh\" {\n\t\tVertices: \n\t\tPolygonVertexIndex: \n\t}\n"
        "\tModel: \"Model::Null\", \"Null\" {\n\t}\n"
        "}\n";
    r = ft_import(legacy, strlen(legacy), NULL, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    CHECK_EQ_INT(raw.mesh_count, 1);
    CHECK(has_warning(&raw, "'Prop'", "no vertices"));
    CHECK(has_warning(&raw, "'Empty'", "no vertices"));
    CHECK(!has_warning(&raw, "'Null'", ""));
    CHECK_EQ_INT(raw.warning_count, 2);
    mk_raw_free(&raw);
}

/* ---- ASCII comments and not-finite numbers ---- */

/* `;` comments inside `a:` arrays and between the items of a value list that spans lines
 * import exactly like the same file without comments. */
static void test_ascii_array_comments(void)
{
    static const char *const texts[2] = {
        "; FBX 7.4.0 project file\nObjects: {\n Geometry: 1, \"Geometry::\", \"Mesh\" {\n"
        "  Vertices: *9 {\n   a: 0,0,0,1,0,0,0,2,0\n  }\n"
        "  PolygonVertexIndex: *3 { a: 0,1,-3 }\n }\n Model: 2, \"Model::M\", \"Mesh\" {\n }\n}\n"
        "Connections: {\n C: \"OO\",1,2\n}\n",
        "; FBX 7.4.0 project file\nObjects: {\n Geometry: 1, \"Geometry::\", \"Mesh\" {\n"
        "  Vertices: *9 ; nine values\n  {\n   a: ; x, y, z per point\n"
        "      0,0,0, ; point 0 } (a brace in a comment)\n"
        "; a whole comment line between items, with commas , , and 1.#INF\n"
        "      1,0,0 ; point 1, no trailing comma\n"
        "      ,0,2,0 ; point 2\n  }\n"
        "  PolygonVertexIndex: *3 { a: 0,1, ; closes\n -3 }\n }\n Model: 2, \"Model::M\", \"Mesh\" {\n }\n}\n"
        "Connections: {\n C: \"OO\",1,2\n}\n",
    };
    float positions[2][9];
    for (int t = 0; t < 2; t++) {
        mk_raw_asset raw;
        mk_error err;
        mk_result r = ft_import(texts[t], strlen(texts[t]), NULL, &raw, &err);
        CHECK_MSG(r == MK_OK, "text %d: %s", t, err.message);
        CHECK_EQ_INT(raw.mesh_count, 1);
        if (r == MK_OK && raw.mesh_count == 1 && raw.meshes[0].vertex_count == 3)
            memcpy(positions[t], raw.meshes[0].positions, sizeof positions[t]);
        else
            memset(positions[t], 0xff, sizeof positions[t]);
        mk_raw_free(&raw);
    }
    CHECK(memcmp(positions[0], positions[1], sizeof positions[0]) == 0);
    CHECK_NEAR(positions[1][7], 2.0, 0);
    /* 6.x value lists: a comment line between continuation lines. */
    const char *legacy =
        "; FBX 6.1.0 project file\nObjects:  {\n\tModel: \"Model::Tri\", \"Mesh\" {\n"
        "\t\tVertices: 0,0,0,1,0,0 ; two points\n\t\t; the third follows\n\t\t,0,2,0\n"
        "\t\tPolygonVertexIndex: 0,1,\n\t\t; the closing index\n\t\t-3\n\t}\n}\n";
    mk_raw_asset raw;
    mk_error err;
    mk_result r = ft_import(legacy, strlen(legacy), NULL, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    CHECK(r == MK_OK && raw.mesh_count == 1 && raw.meshes[0].control_point_count == 3 && raw.meshes[0].triangle_count == 1);
    mk_raw_free(&raw);
}

/* A 7.4 ASCII scene with one value of each kind the importer checks: a control point
 * coordinate (@V), a Lcl Translation component (@T), a shape delta (@D), a curve key value
 * (@K). fill() substitutes them and records where each token starts. */
static const char not_finite_template[] =
    "; FBX 7.4.0 project file\nObjects: {\n"
    " Geometry: 1, \"Geometry::\", \"Mesh\" {\n  Vertices: *9 { a: 0,0,0,1,@V,0,0,1,0 }\n"
    "  PolygonVertexIndex: *3 { a: 0,1,-3 }\n }\n"
    " Model: 2, \"Model::M\", \"Mesh\" {\n  Properties70: {\n"
    "   P: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",@T,0,0\n  }\n }\n"
    " Deformer: 3, \"Deformer::B\", \"BlendShape\" {\n }\n"
    " Deformer: 4, \"SubDeformer::C\", \"BlendShapeChannel\" {\n  DeformPercent: 0\n  FullWeights: *1 { a: 100 }\n }\n"
    " Geometry: 5, \"Geometry::S\", \"Shape\" {\n  Indexes: *1 { a: 2 }\n  Vertices: *3 { a: 0,@D,0 }\n }\n"
    " AnimationStack: 6, \"AnimStack::Take\", \"\" {\n }\n AnimationLayer: 7, \"AnimLayer::Base\", \"\" {\n }\n"
    " AnimationCurveNode: 8, \"AnimCurveNode::DeformPercent\", \"\" {\n }\n"
    " AnimationCurve: 9, \"AnimCurve::\", \"\" {\n  KeyTime: *2 { a: 0,46186158000 }\n  KeyValueFloat: *2 { a: 0,@K }\n"
    "  KeyAttrFlags: *1 { a: 4 }\n  KeyAttrDataFloat: *4 { a: 0,0,218434821,0 }\n  KeyAttrRefCount: *1 { a: 2 }\n }\n"
    "}\nConnections: {\n C: \"OO\",1,2\n C: \"OO\",3,1\n C: \"OO\",4,3\n C: \"OO\",5,4\n C: \"OO\",7,6\n C: \"OO\",8,7\n"
    " C: \"OP\",8,4, \"DeformPercent\"\n C: \"OP\",9,8, \"d|DeformPercent\"\n}\n";

static char *fill(const char *bad, int slot, size_t *bad_offset)
{
    static const char slots[] = "VTDK";
    char *out = malloc(sizeof not_finite_template + 64);
    size_t n = 0;
    for (const char *p = not_finite_template; *p; p++) {
        if (p[0] == '@' && p[1]) {
            int which = (int)(strchr(slots, p[1]) - slots);
            const char *token = which == slot ? bad : "1";
            if (which == slot) *bad_offset = n;
            memcpy(out + n, token, strlen(token));
            n += strlen(token);
            p++;
            continue;
        }
        out[n++] = *p;
    }
    out[n] = 0;
    return out;
}

/* NaN and infinity in every spelling exporters write (C99, Windows CRT, glibc) are numbers,
 * never "malformed" and never bare-word characters: each gives MK_ERROR_NOT_FINITE naming the
 * array (or property), the element and the byte offset of the token. */
static void test_ascii_not_finite(void)
{
    static const char *const spellings[] = { "nan", "-nan", "NaN", "NAN", "inf", "-inf", "INF", "Inf", "Infinity",
                                              "-Infinity", "1.#INF", "-1.#INF", "1.#IND", "-1.#IND", "1.#QNAN",
                                              "1.#SNAN", "1.#INF00", "-1.#IND00", "nan(ind)", "-nan(ind)", "1e999" };
    static const char *const names[4][2] = { { "Objects/Geometry/Vertices", "control point 1" },
                                             { "Lcl Translation", "'M'" },
                                             { "Objects/Geometry/Vertices", "shape 'S' entry 0" },
                                             { "Objects/AnimationCurve/KeyValueFloat", "key 1" } };
    size_t offset = 0;
    char *text = fill("1", -1, &offset);
    mk_raw_asset raw;
    mk_error err;
    mk_result r = ft_import(text, strlen(text), NULL, &raw, &err);
    CHECK_MSG(r == MK_OK, "finite template: %s", err.message);
    CHECK_EQ_INT(raw.channel_count, 1);
    CHECK_EQ_INT(raw.clip_count, 1);
    mk_raw_free(&raw);
    free(text);
    for (size_t i = 0; i < sizeof spellings / sizeof spellings[0]; i++) {
        for (int slot = 0; slot < 4; slot++) {
            text = fill(spellings[i], slot, &offset);
            memset(&err, 0, sizeof err);
            r = ft_import(text, strlen(text), NULL, &raw, &err);
            char at[48];
            snprintf(at, sizeof at, "byte %zu", offset);
            CHECK_MSG(r == MK_ERROR_NOT_FINITE, "'%s' in slot %d: %s (%s)", spellings[i], slot, mk_result_name(r), err.message);
            CHECK_MSG(strstr(err.message, "not finite") && strstr(err.message, names[slot][0]) &&
                          strstr(err.message, names[slot][1]) && strstr(err.message, at),
                      "'%s' in slot %d: message '%s' should say not finite, name %s, %s and %s", spellings[i], slot,
                      err.message, names[slot][0], names[slot][1], at);
            CHECK_MSG(err.offset == offset, "'%s' in slot %d: offset %llu, token at %zu", spellings[i], slot,
                      (unsigned long long)err.offset, offset);
            mk_raw_free(&raw);
            free(text);
        }
    }
}

/* The binary path reports the same error: a NaN control point in a raw array points at the
 * element's eight bytes, in a zlib array at the array (its elements have no file offset). */
static void test_binary_not_finite(void)
{
    double points[3 * 30];
    for (int i = 0; i < 90; i++) points[i] = (double)(i % 7);
    points[4] = NAN;   /* control point 1, y */
    for (int compress = 0; compress < 2; compress++) {
        fbxw_mesh mesh = triangle_mesh("M", points, NULL, 0);
        mesh.control_point_count = 30;   /* 90 doubles: compressed when asked */
        fbxw_scene scene = { .version = 7500, .binary = 1, .compress = compress, .mesh_count = 1, .meshes = &mesh };
        unsigned char *data;
        size_t size;
        CHECK(fbxw_write(&scene, &data, &size) == 0);
        mk_raw_asset raw;
        mk_error err;
        memset(&err, 0, sizeof err);
        mk_result r = ft_import(data, size, NULL, &raw, &err);
        CHECK_EQ_INT(r, MK_ERROR_NOT_FINITE);
        char at[48];
        snprintf(at, sizeof at, "byte %llu", (unsigned long long)err.offset);
        CHECK_MSG(strstr(err.message, "Objects/Geometry/Vertices") && strstr(err.message, "control point 1") &&
                      strstr(err.message, "not finite") && strstr(err.message, at),
                  "message: %s", err.message);
        CHECK(err.offset < size);
        if (err.offset + 8 <= size) {
            if (compress) CHECK(data[err.offset] == 'd');
            else CHECK(memcmp(data + err.offset, &points[4], 8) == 0);
        }
        mk_raw_free(&raw);
        free(data);
    }
}

/* ---- big-endian binary files ---- */

#define SAME(cond, ...) CHECK_MSG(cond, __VA_ARGS__)

static int same_floats(const float *a, const float *b, size_t n)
{
    return (!a && !b) || (a && b && memcmp(a, b, n * sizeof(float)) == 0);
}

static int same_u32(const uint32_t *a, const uint32_t *b, size_t n)
{
    return (!a && !b) || (a && b && memcmp(a, b, n * sizeof(uint32_t)) == 0);
}

static int same_str(const char *a, const char *b)
{
    return (!a && !b) || (a && b && strcmp(a, b) == 0);
}

/* Every field of two raw models, bit for bit. */
static void check_same_raw(const mk_raw_asset *a, const mk_raw_asset *b, const char *label)
{
    SAME(strcmp(a->source_format, b->source_format) == 0 && strcmp(a->source_creator, b->source_creator) == 0 &&
             memcmp(&a->unit_scale, &b->unit_scale, sizeof a->unit_scale) == 0 && a->up_axis == b->up_axis,
         "%s: import facts differ", label);
    SAME(a->warning_count == b->warning_count, "%s: %u vs %u warnings", label, a->warning_count, b->warning_count);
    for (uint32_t i = 0; i < a->warning_count && i < b->warning_count && i < MK_RAW_MAX_WARNINGS; i++)
        SAME(strcmp(a->warnings[i].message, b->warnings[i].message) == 0, "%s: warning %u differs", label, i);
    SAME(a->mesh_count == b->mesh_count && a->channel_count == b->channel_count && a->clip_count == b->clip_count,
         "%s: counts differ", label);
    for (uint32_t m = 0; m < a->mesh_count && m < b->mesh_count; m++) {
        const mk_raw_mesh *x = &a->meshes[m], *y = &b->meshes[m];
        SAME(same_str(x->name, y->name) && x->vertex_count == y->vertex_count && x->triangle_count == y->triangle_count &&
                 x->control_point_count == y->control_point_count && x->gltf_node == y->gltf_node &&
                 x->gltf_mesh == y->gltf_mesh && x->gltf_primitive == y->gltf_primitive && x->stacking == y->stacking,
             "%s: mesh %u header differs", label, m);
        if (x->vertex_count != y->vertex_count || x->triangle_count != y->triangle_count) continue;
        SAME(same_floats(x->positions, y->positions, 3 * (size_t)x->vertex_count) &&
                 same_floats(x->normals, y->normals, 3 * (size_t)x->vertex_count) &&
                 same_floats(x->tangents, y->tangents, 4 * (size_t)x->vertex_count) &&
                 same_u32(x->triangles, y->triangles, 3 * (size_t)x->triangle_count) &&
                 same_u32(x->control_points, y->control_points, x->vertex_count) &&
                 memcmp(x->world, y->world, sizeof x->world) == 0,
             "%s: mesh %u data differs", label, m);
    }
    for (uint32_t c = 0; c < a->channel_count && c < b->channel_count; c++) {
        const mk_raw_channel *x = &a->channels[c], *y = &b->channels[c];
        SAME(same_str(x->name, y->name) && same_str(x->origin, y->origin) && x->mesh == y->mesh &&
                 memcmp(&x->default_weight, &y->default_weight, sizeof(float)) == 0 && x->target_count == y->target_count,
             "%s: channel %u header differs", label, c);
        for (uint32_t k = 0; k < x->target_count && k < y->target_count; k++) {
            const mk_raw_target *t = &x->targets[k], *u = &y->targets[k];
            SAME(same_str(t->name, u->name) && memcmp(&t->full_weight, &u->full_weight, sizeof(float)) == 0 &&
                     t->count == u->count, "%s: channel %u target %u header differs", label, c, k);
            if (t->count != u->count) continue;
            SAME(same_u32(t->indices, u->indices, t->count) && same_floats(t->positions, u->positions, 3 * (size_t)t->count) &&
                     same_floats(t->normals, u->normals, 3 * (size_t)t->count) &&
                     same_floats(t->tangents, u->tangents, 3 * (size_t)t->count),
                 "%s: channel %u target %u data differs", label, c, k);
        }
    }
    for (uint32_t c = 0; c < a->clip_count && c < b->clip_count; c++) {
        const mk_raw_clip *x = &a->clips[c], *y = &b->clips[c];
        SAME(same_str(x->name, y->name) && memcmp(&x->start, &y->start, sizeof(float)) == 0 &&
                 memcmp(&x->duration, &y->duration, sizeof(float)) == 0 && x->track_count == y->track_count,
             "%s: clip %u header differs", label, c);
        for (uint32_t t = 0; t < x->track_count && t < y->track_count; t++)
            SAME(x->tracks[t].channel == y->tracks[t].channel && x->tracks[t].key_count == y->tracks[t].key_count &&
                     memcmp(x->tracks[t].keys, y->tracks[t].keys, x->tracks[t].key_count * sizeof(mk_key)) == 0,
                 "%s: clip %u track %u differs", label, c, t);
    }
}

typedef struct parsed { mk_arena arena; mk_error err; fbx_doc doc; mk_result result; } parsed;

static void parse_binary(parsed *p, const unsigned char *data, size_t size)
{
    mk_arena_init(&p->arena, NULL);
    memset(&p->err, 0, sizeof p->err);
    memset(&p->doc, 0, sizeof p->doc);
    p->doc.arena = &p->arena;
    p->doc.data = data;
    p->doc.size = size;
    p->doc.err = &p->err;
    p->doc.binary = 1;
    p->result = fbx_parse_binary(&p->doc);
    if (p->result == MK_OK) fbx_link_parents(&p->doc.root);
}

static void parsed_free(parsed *p)
{
    fbx_doc_free(&p->doc);
    mk_arena_free_all(&p->arena);
}

/* Two parse trees value by value; arrays decoded as every element type (same values, or the
 * same error). Offsets are compared when the files have the same layout (no zlib arrays: the
 * compressed twins differ in length). Returns the number of values compared. */
static int check_same_tree(parsed *pa, const fbx_node *a, parsed *pb, const fbx_node *b, int same_layout, const char *label)
{
    int compared = 0;
    char path[160];
    fbx_node_path(a, path, sizeof path);
    if (!(a->name_length == b->name_length && memcmp(a->name, b->name, a->name_length) == 0 &&
          a->value_count == b->value_count && a->child_count == b->child_count && (!same_layout || a->offset == b->offset))) {
        CHECK_MSG(0, "%s: node %s differs", label, path);
        return compared;
    }
    for (uint32_t i = 0; i < a->value_count; i++) {
        const fbx_value *x = &a->values[i], *y = &b->values[i];
        int same = x->kind == y->kind && x->type == y->type && x->encoding == y->encoding && x->count == y->count &&
                   (!same_layout || x->offset == y->offset);
        if (same && (x->kind == FBX_INT || x->kind == FBX_CHAR)) same = x->u.i == y->u.i;
        if (same && x->kind == FBX_FLOAT) same = memcmp(&x->u.f, &y->u.f, sizeof x->u.f) == 0;
        if (same && x->kind == FBX_STRING)
            same = x->u.s.length == y->u.s.length && memcmp(x->u.s.data, y->u.s.data, x->u.s.length) == 0;
        if (same && x->kind == FBX_ARRAY && a->value_count == 1) {
            static const fbx_elem elems[5] = { FBX_ELEM_F64, FBX_ELEM_F32, FBX_ELEM_I32, FBX_ELEM_I64, FBX_ELEM_F32_BITS };
            for (int e = 0; e < 5 && same; e++) {
                void *da = NULL, *db = NULL;
                size_t na = 0, nb = 0;
                mk_result ra = fbx_node_array(&pa->doc, a, elems[e], &da, &na);
                mk_result rb = fbx_node_array(&pb->doc, b, elems[e], &db, &nb);
                size_t esize = (elems[e] == FBX_ELEM_F64 || elems[e] == FBX_ELEM_I64) ? 8 : 4;
                same = ra == rb && na == nb && (ra != MK_OK || na == 0 || memcmp(da, db, na * esize) == 0);
                if (ra == MK_OK) mk_arena_release(&pa->arena, da);
                if (rb == MK_OK) mk_arena_release(&pb->arena, db);
            }
        }
        CHECK_MSG(same, "%s: %s value %u (type '%c') differs", label, path, i, x->type);
        compared++;
    }
    for (uint32_t c = 0; c < a->child_count; c++)
        compared += check_same_tree(pa, &a->children[c], pb, &b->children[c], same_layout, label);
    return compared;
}

/* The type zoo as a big-endian reader must see it (the writer's values, not just equal ones). */
static void check_type_zoo(parsed *p, const char *label)
{
    const fbx_node *zoo = fbx_child(&p->doc.root, "MorphkitTypes");
    CHECK_MSG(zoo && zoo->value_count == 10 && zoo->child_count == 12, "%s: type zoo missing", label);
    if (!zoo || zoo->value_count != 10 || zoo->child_count != 12) return;
    const fbx_value *v = zoo->values;
    CHECK(v[0].type == 'Y' && v[0].u.i == -12345);
    CHECK(v[1].type == 'C' && v[1].u.i == 'x');
    CHECK(v[2].type == 'B' && v[2].u.i == 200);
    CHECK(v[3].type == 'Z' && v[3].u.i == 1);
    CHECK(v[4].type == 'I' && v[4].u.i == -123456789);
    CHECK(v[5].type == 'L' && v[5].u.i == -1234567890123456789LL);
    CHECK(v[6].type == 'F' && v[6].u.f == (double)-3.25e-3f);
    CHECK(v[7].type == 'D' && v[7].u.f == 0.1);
    CHECK(v[8].type == 'S' && v[8].u.s.length == 11 && memcmp(v[8].u.s.data, "name\0\1Class", 11) == 0);
    CHECK(v[9].type == 'R' && v[9].u.s.length == 5 && memcmp(v[9].u.s.data, "\x00\x01\x02\xff\x80", 5) == 0);
    static const double expect[6][5] = {
        { 0.1, -2.5e10, 1e-300, 3.0, -0.0 },
        { (double)1e-3f, -7.5, (double)3.0e38f, 0.0, (double)(1.0f / 3.0f) },
        { (double)0x0102030405060708LL, -2, (double)INT64_MIN, 46186158000.0, 0 },
        { (double)0x01020304, -2, (double)INT32_MIN, 7, 0 },
        { 0, 1, 255, 128, 2 },
        { 'a', 'Y', 0, 'T', 'N' } };
    static const int64_t expect_l[5] = { 0x0102030405060708LL, -2, INT64_MIN, 46186158000LL, 0 };
    for (uint32_t c = 0; c < 12; c++) {
        const fbx_node *n = &zoo->children[c];
        int a = (int)c / 2;
        double *d = NULL;
        size_t count = 0;
        mk_result r = fbx_node_array(&p->doc, n, FBX_ELEM_F64, (void **)&d, &count);
        CHECK_MSG(r == MK_OK && count == 5, "%s: zoo array %u: %s", label, c, p->err.message);
        for (size_t k = 0; r == MK_OK && k < count; k++)
            CHECK_MSG(d[k] == expect[a][k], "%s: zoo array %u[%zu] = %g, expected %g", label, c, k, d[k], expect[a][k]);
        if (r == MK_OK) mk_arena_release(&p->arena, d);
        if (a == 2) {  /* int64 exactly */
            int64_t *l = NULL;
            r = fbx_node_array(&p->doc, n, FBX_ELEM_I64, (void **)&l, &count);
            CHECK(r == MK_OK && count == 5 && memcmp(l, expect_l, sizeof expect_l) == 0);
            if (r == MK_OK) mk_arena_release(&p->arena, l);
        }
    }
}

/* A big-endian file imports to exactly the raw model of its little-endian twin: 13- and 25-byte
 * records, raw and zlib arrays (some, all), and with the type mix every property type where
 * the importer reads it; the parse trees agree value by value (arrays decoded as every element
 * type), and the type zoo reads back the values the writer put in. */
static void test_big_endian_twins(void)
{
    static const uint32_t be_versions[] = { 7100, 7400, 7500, 7700 };
    int compared = 0;
    for (size_t v = 0; v < sizeof be_versions / sizeof be_versions[0]; v++)
        for (int compress = 0; compress < 3; compress++)
            for (int mix = 0; mix < 2; mix++) {
                char label[64];
                snprintf(label, sizeof label, "%u compress %d%s", be_versions[v], compress, mix ? " type mix" : "");
                unsigned char *data[2] = { NULL, NULL };
                size_t size[2] = { 0, 0 };
                for (int big = 0; big < 2; big++) {
                    fbxw_scene scene;
                    fixture_cube(&scene, be_versions[v], 1, compress);
                    scene.big_endian = big;
                    scene.type_mix = mix;
                    CHECK(fbxw_write(&scene, &data[big], &size[big]) == 0);
                }
                if (!data[0] || !data[1]) { free(data[0]); free(data[1]); continue; }
                int same_layout = compress == 0 && !mix;
                CHECK(data[1][22] == 1 && data[0][22] == 0 && (!same_layout || size[0] == size[1]));
                mk_raw_asset raw[2];
                mk_error err[2];
                mk_result r[2];
                for (int big = 0; big < 2; big++) r[big] = ft_import(data[big], size[big], NULL, &raw[big], &err[big]);
                CHECK_MSG(r[0] == MK_OK, "%s little-endian: %s", label, err[0].message);
                CHECK_MSG(r[1] == MK_OK, "%s big-endian: %s", label, err[1].message);
                if (r[0] == MK_OK && r[1] == MK_OK) {
                    check_box_import(&raw[1], label);
                    check_same_raw(&raw[0], &raw[1], label);
                    CHECK(strstr(raw[1].source_format, "binary") != NULL);
                }
                mk_raw_free(&raw[0]);
                mk_raw_free(&raw[1]);
                parsed pa, pb;
                parse_binary(&pa, data[0], size[0]);
                parse_binary(&pb, data[1], size[1]);
                CHECK_MSG(pa.result == MK_OK && pb.result == MK_OK, "%s: parse %s / %s", label, pa.err.message, pb.err.message);
                if (pa.result == MK_OK && pb.result == MK_OK) {
                    CHECK(pb.doc.header_version == be_versions[v]);
                    CHECK_EQ_INT(pa.doc.root.child_count, pb.doc.root.child_count);
                    for (uint32_t c = 0; c < pa.doc.root.child_count && c < pb.doc.root.child_count; c++)
                        compared += check_same_tree(&pa, &pa.doc.root.children[c], &pb, &pb.doc.root.children[c],
                                                    same_layout, label);
                    if (mix) {
                        check_type_zoo(&pa, label);
                        check_type_zoo(&pb, label);
                    }
                }
                parsed_free(&pa);
                parsed_free(&pb);
                free(data[0]);
                free(data[1]);
            }
    fprintf(stderr, "big-endian twins: %d values compared\n", compared);
    CHECK(compared > 1000);
}

/* ---- hostile constructs: clear errors ---- */

typedef struct buf { unsigned char data[4096]; size_t size; } buf;
static void b_bytes(buf *b, const void *p, size_t n) { memcpy(b->data + b->size, p, n); b->size += n; }
static void b_u32(buf *b, uint32_t v) { unsigned char x[4] = { (unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)(v >> 24) }; b_bytes(b, x, 4); }
static void b_header(buf *b, uint32_t version)
{
    b->size = 0;
    b_bytes(b, "Kaydara FBX Binary  \0\x1a\0", 23);
    b_u32(b, version);
}

static mk_result import_buf(const buf *b, mk_error *err)
{
    mk_raw_asset raw;
    mk_result r = ft_import(b->data, b->size, NULL, &raw, err);
    mk_raw_free(&raw);
    return r;
}

static void test_hostile_constructs(void)
{
    buf b;
    mk_error err;
    /* A zlib array whose stream inflates to more than its declared element count. */
    {
        double values[3] = { 1, 2, 3 };
        unsigned char z[256];
        struct libdeflate_compressor *c = libdeflate_alloc_compressor(6);
        size_t zn = libdeflate_zlib_compress(c, values, sizeof values, z, sizeof z);
        libdeflate_free_compressor(c);
        b_header(&b, 7400);
        size_t start = b.size;
        b_u32(&b, 0); b_u32(&b, 1); b_u32(&b, (uint32_t)(13 + zn)); b_bytes(&b, "\x08Vertices", 9);
        b_bytes(&b, "d", 1); b_u32(&b, 2); b_u32(&b, 1); b_u32(&b, (uint32_t)zn); b_bytes(&b, z, zn);
        uint32_t end = (uint32_t)b.size;
        memcpy(b.data + start, &end, 4);
        unsigned char zero[13] = { 0 };
        b_bytes(&b, zero, 13);
        /* The parser is lazy about arrays: wrap it so the scene reads it (Objects/Geometry). */
        CHECK(import_buf(&b, &err) == MK_OK);  /* a stray top-level array is never decoded */
    }
    /* Node end offset past the end of the file. */
    {
        b_header(&b, 7400);
        b_u32(&b, 100000); b_u32(&b, 0); b_u32(&b, 0); b_bytes(&b, "\x03" "Foo", 4);
        CHECK(import_buf(&b, &err) == MK_ERROR_PARSE);
        CHECK(err.offset == 27);
        CHECK(strstr(err.message, "end offset") != NULL);
    }
    /* 25-byte records from 7500: a 13-byte record is misread and rejected, not overread. */
    {
        b_header(&b, 7500);
        b_u32(&b, 40); b_u32(&b, 0); b_u32(&b, 0); b_bytes(&b, "\x03" "Foo", 4);
        CHECK(import_buf(&b, &err) != MK_OK);
    }
    /* Nesting beyond the limit. */
    {
        b_header(&b, 7400);
        size_t starts[80];
        for (int d = 0; d < 80; d++) {
            starts[d] = b.size;
            b_u32(&b, 0); b_u32(&b, 0); b_u32(&b, 0); b_bytes(&b, "\x01N", 2);
        }
        unsigned char zero[13] = { 0 };
        for (int d = 79; d >= 0; d--) {
            b_bytes(&b, zero, 13);
            uint32_t end = (uint32_t)b.size;
            memcpy(b.data + starts[d], &end, 4);
        }
        b_bytes(&b, zero, 13);
        CHECK(import_buf(&b, &err) == MK_ERROR_LIMIT);
    }
    /* ASCII: array shorter than its count; unterminated node; compressed array lies. */
    {
        const char *text = "; FBX 7.5.0 project file\nObjects: {\n Geometry: 1, \"Geometry::\", \"Mesh\" {\n"
                           "  Vertices: *6 { a: 0,0,0 }\n  PolygonVertexIndex: *3 { a: 0,0,-1 }\n }\n"
                           " Model: 2, \"Model::M\", \"Mesh\" {\n }\n}\nConnections: {\n C: \"OO\",1,2\n}\n";
        mk_raw_asset raw;
        CHECK(ft_import(text, strlen(text), NULL, &raw, &err) == MK_ERROR_PARSE);
        CHECK(strstr(err.message, "Objects/Geometry/Vertices") != NULL);
        CHECK(strstr(err.message, "fewer values") != NULL);
        mk_raw_free(&raw);
        const char *open = "; FBX 7.5.0 project file\nObjects: {\n Geometry: 1, \"x\", \"Mesh\" {\n";
        CHECK(ft_import(open, strlen(open), NULL, &raw, &err) == MK_ERROR_PARSE);
        mk_raw_free(&raw);
        const char *bad_index = "; FBX 7.5.0 project file\nObjects: {\n Geometry: 1, \"Geometry::\", \"Mesh\" {\n"
                                "  Vertices: *3 { a: 0,0,0 }\n  PolygonVertexIndex: *3 { a: 0,5,-1 }\n }\n"
                                " Model: 2, \"Model::M\", \"Mesh\" {\n }\n}\nConnections: {\n C: \"OO\",1,2\n}\n";
        CHECK(ft_import(bad_index, strlen(bad_index), NULL, &raw, &err) == MK_ERROR_PARSE);
        CHECK(strstr(err.message, "PolygonVertexIndex") != NULL);
        mk_raw_free(&raw);
    }
    /* A zlib array inside a mesh that inflates beyond its declared size. */
    {
        fbxw_scene scene;
        fixture_cube(&scene, 7400, 1, 1);
        unsigned char *data;
        size_t size;
        CHECK(fbxw_write(&scene, &data, &size) == 0);
        /* Find the Box's compressed normals (72 doubles, 'd' + count 72 + encoding 1) and
         * declare 71 elements: the stream then inflates past the buffer. */
        int patched = 0;
        for (size_t i = 0; i + 9 < size && !patched; i++) {
            if (data[i] == 'd' && data[i + 1] == 72 && data[i + 2] == 0 && data[i + 5] == 1 && data[i + 6] == 0) {
                data[i + 1] = 71;
                patched = 1;
            }
        }
        CHECK(patched);
        mk_raw_asset raw;
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_ERROR_PARSE);
        CHECK(strstr(err.message, "inflates beyond") != NULL);
        CHECK(err.offset != UINT64_MAX && err.offset < size);
        mk_raw_free(&raw);
        free(data);
    }
}

/* Failing allocation K for every K gives MK_ERROR_OUT_OF_MEMORY (never a crash, another
 * error or a leak: ASan's leak check covers the arenas), until K is past the last allocation. */
static void test_allocation_failures(void)
{
    static const struct { uint32_t version; int binary, compress; } forms[] = { { 7500, 1, 1 }, { 7400, 0, 0 } };
    for (size_t f = 0; f < sizeof forms / sizeof forms[0]; f++) {
        size_t size;
        unsigned char *data = make_fixture(forms[f].version, forms[f].binary, forms[f].compress, &size);
        CHECK(data != NULL);
        if (!data) continue;
        int succeeded = 0;
        uint64_t k;
        for (k = 1; k < 100000 && !succeeded; k++) {
            mk_allocator allocator;
            memset(&allocator, 0, sizeof allocator);
            allocator.fail_after = k;
            mk_raw_asset raw;
            mk_raw_init(&raw, &allocator);
            mk_error err;
            mk_result r = mk_import_fbx(data, size, NULL, &raw, &err);
            if (r == MK_OK) succeeded = 1;
            else CHECK_MSG(r == MK_ERROR_OUT_OF_MEMORY, "fail_after %llu: %s (%s)", (unsigned long long)k,
                           mk_result_name(r), err.message);
            mk_raw_free(&raw);
        }
        CHECK(succeeded);
        CHECK(k > 10);
        free(data);
    }
}

static int write_seeds(const char *dir)
{
    int failures = 0;
    for (size_t v = 0; v < sizeof versions / sizeof versions[0]; v++)
        for (int mode = 0; mode < 3; mode++) {
            size_t size;
            unsigned char *data = make_fixture(versions[v], mode > 0, mode == 2, &size);
            char path[1024];
            snprintf(path, sizeof path, "%s/fixture_%u_%d.fbx", dir, versions[v], mode);
            FILE *f = data ? fopen(path, "wb") : NULL;
            if (!f || fwrite(data, 1, size, f) != size) failures++;
            if (f) fclose(f);
            free(data);
        }
    /* Big-endian, every property type, all arrays compressed. */
    for (size_t v = 0; v < sizeof versions / sizeof versions[0]; v++) {
        fbxw_scene scene;
        fixture_cube(&scene, versions[v], 1, 2);
        scene.big_endian = 1;
        scene.type_mix = 1;
        unsigned char *data = NULL;
        size_t size = 0;
        char path[1024];
        snprintf(path, sizeof path, "%s/fixture_%u_big_endian.fbx", dir, versions[v]);
        FILE *f = fbxw_write(&scene, &data, &size) == 0 ? fopen(path, "wb") : NULL;
        if (!f || fwrite(data, 1, size, f) != size) failures++;
        if (f) fclose(f);
        free(data);
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/fixture_legacy61.fbx", dir);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(fixture_legacy61, 1, strlen(fixture_legacy61), f) != strlen(fixture_legacy61)) failures++;
    if (f) fclose(f);
    return failures ? 1 : 0;
}

static const check_case cases[] = {
    CASE(test_formats_roundtrip), CASE(test_stacking_option), CASE(test_curves), CASE(test_blender_full_weights), CASE(test_blender_inbetweens_keep_full_weights),
    CASE(test_duplicate_full_weights), CASE(test_tiny_full_weights), CASE(test_hostile_constructs),
    CASE(test_allocation_failures), CASE(test_rotation_order), CASE(test_legacy_61_ascii), CASE(test_inherit_type),
    CASE(test_empty_mesh_skipped), CASE(test_skipped_mesh_warnings),
    CASE(test_ascii_array_comments), CASE(test_ascii_not_finite), CASE(test_binary_not_finite),
    CASE(test_big_endian_twins),
};

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--write-seeds") == 0) return write_seeds(argv[2]);
    return check_run(cases, (int)(sizeof cases / sizeof cases[0]), argc, argv);
}

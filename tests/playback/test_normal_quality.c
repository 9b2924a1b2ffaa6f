/* SPDX-License-Identifier: MIT */
/* The normal-quality measure (playback/normal_quality.h): its reference equals a brute-force
 * recomputation, a single target at full weight has no error under nlerp (the rule target
 * normals are made with), unmorphed base normals do, and combined shapes are measured. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fixtures.h"
#include "normal_quality.h"


static void test_reference_is_the_recomputed_surface(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_wavy_grid(&raw, 16, 3);
    const mk_raw_mesh *m = &raw.meshes[0];
    const mk_raw_target *t = &raw.channels[2].targets[0];   /* a disc of radius 4 inside the grid */
    const uint32_t n = m->vertex_count;
    float *p = malloc(3 * sizeof(float) * n);
    double *rest = malloc(3 * sizeof(double) * n), *ref = malloc(3 * sizeof(double) * n);
    unsigned char *moved = malloc(n), *expect_moved = calloc(n, 1);
    memcpy(p, m->positions, 3 * sizeof(float) * n);
    for (uint32_t j = 0; j < t->count; j++)
        for (int d = 0; d < 3; d++) p[3 * t->indices[j] + (uint32_t)d] += 0.7f * t->positions[3 * j + (uint32_t)d];
    for (uint32_t tri = 0; tri < m->triangle_count; tri++) {
        const uint32_t *c = &m->triangles[3 * tri];
        int any = 0;
        for (int k = 0; k < 3; k++) any |= memcmp(&p[3 * c[k]], &m->positions[3 * c[k]], 3 * sizeof(float)) != 0;
        if (any) expect_moved[c[0]] = expect_moved[c[1]] = expect_moved[c[2]] = 1;
    }
    mk_normal_groups g;
    mk_error err;
    CHECK(mk_normal_groups_build(m, MK_GROUP_BY_CONTROL_POINT, &raw.arena, &g, &err) == MK_OK);
    for (uint32_t v = 0; v < n; v++) fixture_brute_normal(m, m->positions, v, 0, &rest[3 * v]);
    long count = pb_reference_normals(m, &g, rest, p, ref, moved, &raw.arena);
    long expected = 0;
    uint32_t wrong_flag = 0;
    double worst = 0;
    for (uint32_t v = 0; v < n; v++) {
        expected += expect_moved[v];
        wrong_flag += moved[v] != expect_moved[v];
        if (!moved[v]) continue;
        double np[3], r[3], len = 0, dot = 0;
        fixture_brute_normal(m, p, v, 0, np);
        for (int d = 0; d < 3; d++) { r[d] = m->normals[3 * v + (uint32_t)d] + np[d] - rest[3 * v + (uint32_t)d]; len += r[d] * r[d]; }
        for (int d = 0; d < 3; d++) dot += r[d] / sqrt(len) * ref[3 * v + (uint32_t)d];
        double angle = acos(fmin(1.0, dot)) * 180 / 3.14159265358979;
        if (angle > worst) worst = angle;
    }
    CHECK_EQ_INT(count, expected);
    CHECK_MSG(expected > 10 && expected < (long)n, "%ld of %u vertices moved", expected, n);
    CHECK_MSG(wrong_flag == 0, "%u vertices flagged wrongly", wrong_flag);
    CHECK_MSG(worst < 1e-4, "reference differs from the brute-force normal by %g degrees", worst);
    free(p); free(rest); free(ref); free(moved); free(expect_moved);
    mk_raw_free(&raw);
}

/* Measures the wavy grid with `targets` targets (normals computed like an import's) at
 * weights w (one per channel). */
static void measure(uint32_t targets, const float *w, pb_normal_stats out[PB_QUALITY_MODES])
{
    pb_asset a;
    memset(&a, 0, sizeof a);
    mk_raw_init(&a.raw, NULL);
    fixture_wavy_grid(&a.raw, 24, targets);
    mk_error err;
    mk_write_options wo = { .precision = MK_PRECISION_FLOAT };
    CHECK(mk_raw_compute_target_normals(&a.raw, 0, 0, 1, &err) == MK_OK);
    CHECK_MSG(pb_asset_open_raw(&a, &wo, &err) == MK_OK, "%s", err.message);
    pb_normal_quality q;
    memset(&q, 0, sizeof q);
    CHECK_MSG(pb_normal_quality_add(&q, &a.asset, &a.raw, w, MK_STACKING_ASSET, &err) == MK_OK, "%s", err.message);
    CHECK_EQ_INT(q.frames, 1);
    for (int k = 0; k < PB_QUALITY_MODES; k++) out[k] = pb_normal_quality_stats(&q, k);
    pb_normal_quality_free(&q);
    pb_asset_free(&a);
}

static void test_single_target_is_exact(void)
{
    const float w[3] = { 0, 0, 1 };
    pb_normal_stats s[PB_QUALITY_MODES];
    measure(3, w, s);
    CHECK(s[PB_QUALITY_NLERP].count > 10);
    CHECK_MSG(s[PB_QUALITY_NLERP].max < 1e-3, "nlerp max %g degrees", s[PB_QUALITY_NLERP].max);
    CHECK_MSG(s[PB_QUALITY_SLERP].max < 1e-3, "slerp max %g degrees", s[PB_QUALITY_SLERP].max);
    CHECK_MSG(s[PB_QUALITY_BASE].max > 5, "base normals kept: max %g degrees", s[PB_QUALITY_BASE].max);
    CHECK(s[PB_QUALITY_BASE].mean <= s[PB_QUALITY_BASE].p99 && s[PB_QUALITY_BASE].p99 <= s[PB_QUALITY_BASE].max);
}

/* Overlapping discs at full weight: the sum of the normal changes is not the change of the
 * summed shape, and the measure says so. */
static void test_combination_is_measured(void)
{
    float w[12];
    for (int k = 0; k < 12; k++) w[k] = 1;
    pb_normal_stats s[PB_QUALITY_MODES];
    measure(12, w, s);
    CHECK(s[PB_QUALITY_NLERP].count > 100);
    CHECK_MSG(s[PB_QUALITY_NLERP].max > 0.1, "nlerp max %g degrees", s[PB_QUALITY_NLERP].max);
    CHECK(s[PB_QUALITY_NLERP].max < s[PB_QUALITY_BASE].max);
}

CHECK_MAIN(CASE(test_reference_is_the_recomputed_surface), CASE(test_single_target_is_exact),
           CASE(test_combination_is_measured))

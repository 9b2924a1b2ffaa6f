/* SPDX-License-Identifier: MIT */
/* Target normals computed from target positions: they equal normals computed from scratch
 * on the deformed mesh (property), UV-seam duplicates smooth together, hard edges stay hard,
 * tangents stay orthogonal to the new normals, and any thread count gives the same bytes. The
 * face normal they and the bakers build on faces the counterclockwise side, twice the area long. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fixtures.h"
#include "mesh_groups.h"

/* mk_triangle_normal: (b - a) x (c - a); mk_face_normal: the same of a mesh's triangle, from
 * its floats or from given doubles. */
static void test_face_normal_faces_the_counterclockwise_side(void)
{
    const double a[3] = { 1, 1, 1 }, b[3] = { 3, 1, 1 }, c[3] = { 1, 4, 1 };
    double n[3];
    mk_triangle_normal(a, b, c, n);
    CHECK(n[0] == 0 && n[1] == 0 && n[2] == 6);   /* +z, twice the area 3 */
    mk_triangle_normal(a, c, b, n);
    CHECK(n[0] == 0 && n[1] == 0 && n[2] == -6);
    const double p[3] = { 0.1, -0.2, 0.3 }, q[3] = { 0.7, 0.4, -0.5 }, r[3] = { -0.3, 0.9, 0.2 };
    mk_triangle_normal(p, q, r, n);
    const double e1[3] = { q[0] - p[0], q[1] - p[1], q[2] - p[2] }, e2[3] = { r[0] - p[0], r[1] - p[1], r[2] - p[2] };
    CHECK(n[0] == e1[1] * e2[2] - e1[2] * e2[1] && n[1] == e1[2] * e2[0] - e1[0] * e2[2] &&
          n[2] == e1[0] * e2[1] - e1[1] * e2[0]);
    static float positions[] = { 0, 0, 0, 0, 1, 0, 1, 0, 0 };
    static uint32_t triangles[] = { 0, 1, 2 };
    mk_raw_mesh m = { 0 };
    m.vertex_count = 3;
    m.positions = positions;
    m.triangle_count = 1;
    m.triangles = triangles;
    mk_face_normal(&m, NULL, 0, n);
    CHECK(n[0] == 0 && n[1] == 0 && n[2] == -1);   /* clockwise seen from +z */
    const double moved[9] = { 0, 0, 0, 0, 2, 0, 0, 0, 2 };
    mk_face_normal(&m, moved, 0, n);
    CHECK(n[0] == 4 && n[1] == 0 && n[2] == 0);
}


/* A flat 5x5 grid (normals +z, tangents +x) whose centre control point is duplicated for a
 * UV seam: vertex 25 is control point 12 and the triangles right of the centre use it. */
static void grid_with_seam(mk_raw_asset *raw)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = "grid";
    m->vertex_count = 26;
    m->control_point_count = 25;
    m->positions = mk_arena_array(&raw->arena, 78, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 78, sizeof(float));
    m->tangents = mk_arena_array(&raw->arena, 104, sizeof(float));
    m->control_points = mk_arena_array(&raw->arena, 26, sizeof(uint32_t));
    m->triangles = mk_arena_array(&raw->arena, 32 * 3, sizeof(uint32_t));
    for (uint32_t v = 0; v < 26; v++) {
        uint32_t cp = v < 25 ? v : 12;
        m->control_points[v] = cp;
        m->positions[3 * v] = (float)(cp % 5);
        m->positions[3 * v + 1] = (float)(cp / 5);
        m->normals[3 * v + 2] = 1;
        m->tangents[4 * v] = 1;
        m->tangents[4 * v + 3] = 1;
    }
    uint32_t t = 0;
    for (uint32_t y = 0; y < 4; y++)
        for (uint32_t x = 0; x < 4; x++) {
            uint32_t q[4] = { y * 5 + x, y * 5 + x + 1, (y + 1) * 5 + x, (y + 1) * 5 + x + 1 };
            if (x >= 2) for (int k = 0; k < 4; k++) if (q[k] == 12) q[k] = 25;
            uint32_t *tri = &m->triangles[6 * t++];
            tri[0] = q[0]; tri[1] = q[1]; tri[2] = q[3]; tri[3] = q[0]; tri[4] = q[3]; tri[5] = q[2];
        }
    m->triangle_count = 32;
    mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
    ch->name = "bump";
    mk_raw_target *tg = mk_raw_add_targets(raw, ch, 1);
    tg->name = "bump";
    tg->count = 3;
    tg->indices = mk_arena_array(&raw->arena, 3, sizeof(uint32_t));
    tg->positions = mk_arena_array(&raw->arena, 9, sizeof(float));
    tg->indices[0] = 7; tg->indices[1] = 12; tg->indices[2] = 25;  /* both seam copies move together */
    tg->positions[2] = 0.3f; tg->positions[5] = 0.8f; tg->positions[8] = 0.8f;
}

static void test_matches_recomputed_normals(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    grid_with_seam(&raw);
    mk_error err;
    CHECK(mk_raw_compute_target_normals(&raw, 0, 0, 0, &err) == MK_OK);
    const mk_raw_mesh *m = &raw.meshes[0];
    const mk_raw_target *t = &raw.channels[0].targets[0];
    CHECK(t->normals != NULL && t->tangents != NULL);
    CHECK(t->count > 3);                         /* neighbours joined the index set */
    float deformed[78];
    memcpy(deformed, m->positions, sizeof deformed);
    for (uint32_t j = 0; j < t->count; j++)
        for (int d = 0; d < 3; d++) deformed[3 * t->indices[j] + (uint32_t)d] += t->positions[3 * j + (uint32_t)d];
    double worst = 0, ortho = 0;
    for (uint32_t j = 0; j < t->count; j++) {
        uint32_t v = t->indices[j];
        float n[3], ref[3];
        for (int d = 0; d < 3; d++) n[d] = m->normals[3 * v + (uint32_t)d] + t->normals[3 * j + (uint32_t)d];
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double r[3];
        fixture_brute_normal(m, deformed, v, 0, r);
        for (int d = 0; d < 3; d++) ref[d] = (float)r[d];
        for (int d = 0; d < 3; d++) worst = fmax(worst, fabs(n[d] / l - ref[d]));
        float tn[3];
        for (int d = 0; d < 3; d++) tn[d] = m->tangents[4 * v + (uint32_t)d] + t->tangents[3 * j + (uint32_t)d];
        ortho = fmax(ortho, fabs(tn[0] * ref[0] + tn[1] * ref[1] + tn[2] * ref[2]));
    }
    CHECK_MSG(worst < 1e-6, "normal differs from the recomputed one by %g", worst);
    CHECK_MSG(ortho < 1e-6, "tangent not orthogonal to the new normal (%g)", ortho);
    /* The seam copies (vertices 12 and 25) got the same normal delta. */
    const float *d12 = NULL, *d25 = NULL;
    for (uint32_t j = 0; j < t->count; j++) {
        if (t->indices[j] == 12) d12 = &t->normals[3 * j];
        if (t->indices[j] == 25) d25 = &t->normals[3 * j];
    }
    CHECK(d12 && d25 && !memcmp(d12, d25, 12));
    mk_raw_free(&raw);
}

/* Authored tangent deltas are kept when normals are computed: each moved vertex keeps its
 * own delta in the grown index set, and the neighbours that joined it get none. */
static void authored_tangents_case(int replacing)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    grid_with_seam(&raw);
    mk_raw_target *t = &raw.channels[0].targets[0];
    static const float authored[9] = { 0.1f, 0, 0, 0, 0.2f, 0, 0, 0, 0.3f };   /* v7, v12, v25 */
    t->tangents = mk_arena_array(&raw.arena, 9, sizeof(float));
    memcpy(t->tangents, authored, sizeof authored);
    mk_error err;
    CHECK(replacing ? mk_raw_compute_target_normals_replacing(&raw, 0, 0, 0, &err) == MK_OK
                    : mk_raw_compute_target_normals(&raw, 0, 0, 0, &err) == MK_OK);
    t = &raw.channels[0].targets[0];
    CHECK(t->count > 3 && t->tangents != NULL);
    uint32_t found = 0;
    for (uint32_t j = 0; j < t->count; j++) {
        const uint32_t v = t->indices[j];
        const int k = v == 7 ? 0 : v == 12 ? 1 : v == 25 ? 2 : -1;
        found += k >= 0;
        for (int d = 0; d < 3; d++) {
            const float want = k >= 0 ? authored[3 * k + d] : 0.0f;
            CHECK_MSG(t->tangents[3 * j + (uint32_t)d] == want, "vertex %u tangent delta[%d] = %g, expected %g", v, d,
                      (double)t->tangents[3 * j + (uint32_t)d], (double)want);
        }
    }
    CHECK_EQ_INT(found, 3);
    mk_raw_free(&raw);
}

/* Both variants: the plain one, and the replacing one whose indices and positions grow in
 * place (merged from the end). */
static void test_authored_tangents_follow_their_vertex(void)
{
    authored_tangents_case(0);
    authored_tangents_case(1);
}

/* Two targets moving the same vertices on one worker thread: the second gets the same grown
 * index set and normals as the first (the per-worker work arrays start clean for each target). */
static void test_targets_in_turn_on_one_thread(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    grid_with_seam(&raw);
    mk_raw_channel *ch = mk_raw_add_channels(&raw, 1);   /* may move the channels */
    ch->name = "bump_again";
    mk_raw_target *t = mk_raw_add_targets(&raw, ch, 1);
    const mk_raw_target *first = &raw.channels[0].targets[0];
    t->name = "bump_again";
    t->count = first->count;
    t->indices = first->indices;
    t->positions = first->positions;
    mk_error err;
    CHECK(mk_raw_compute_target_normals(&raw, 0, 0, 1, &err) == MK_OK);
    const mk_raw_target *a = &raw.channels[0].targets[0], *b = &raw.channels[1].targets[0];
    CHECK_MSG(a->count > 3 && b->count == a->count, "index sets of %u and %u vertices", a->count, b->count);
    if (b->count == a->count) {
        CHECK(!memcmp(a->indices, b->indices, 4u * a->count));
        CHECK(!memcmp(a->normals, b->normals, 12u * a->count));
    }
    mk_raw_free(&raw);
}

/* An L of two quads meeting at a right angle with a hard edge: the shared edge's control
 * points have one vertex per face (different normals). Moving a far vertex of the floor
 * must not change the wall's normals. */
static void test_hard_edge_stays_hard(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *m = mk_raw_add_meshes(&raw, 1);
    static float pos[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,    /* floor (z = 0), v2 v3 on the edge */
                           0, 1, 0, 1, 1, 0, 0, 1, 1, 1, 1, 1 };  /* wall (y = 1), v4 v5 on the edge */
    static float nrm[] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0 };
    static uint32_t cps[] = { 0, 1, 2, 3, 2, 3, 4, 5 };
    static uint32_t tris[] = { 0, 1, 3, 0, 3, 2, 4, 5, 7, 4, 7, 6 };
    m->name = "L";
    m->vertex_count = 8;
    m->control_point_count = 6;
    m->positions = pos;
    m->normals = nrm;
    m->control_points = cps;
    m->triangles = tris;
    m->triangle_count = 4;
    mk_raw_channel *ch = mk_raw_add_channels(&raw, 1);
    ch->name = "lift";
    mk_raw_target *t = mk_raw_add_targets(&raw, ch, 1);
    static uint32_t idx[] = { 0 };
    static float d[] = { 0, 0, 0.5f };
    t->name = "lift"; t->count = 1; t->indices = idx; t->positions = d;
    mk_error err;
    CHECK(mk_raw_compute_target_normals(&raw, 0, 0, 0, &err) == MK_OK);
    t = &raw.channels[0].targets[0];
    for (uint32_t j = 0; j < t->count; j++) {
        double len = fabs(t->normals[3 * j]) + fabs(t->normals[3 * j + 1]) + fabs(t->normals[3 * j + 2]);
        if (t->indices[j] >= 4) CHECK_MSG(len == 0, "wall vertex %u changed normal", t->indices[j]);
        if (t->indices[j] == 2 || t->indices[j] == 3) CHECK_MSG(len > 0.01, "floor edge vertex %u did not change", t->indices[j]);
    }
    mk_raw_free(&raw);
}


/* Targets are computed on worker threads: the result must not depend on how many, nor on
 * whether the replaced arrays go back to the arena at once (the importer's variant). */
static void test_same_result_for_any_thread_count(void)
{
    mk_raw_asset one, many, replacing;
    mk_raw_init(&one, NULL);
    mk_raw_init(&many, NULL);
    mk_raw_init(&replacing, NULL);
    fixture_wavy_grid(&one, 48, 23);
    fixture_wavy_grid(&many, 48, 23);
    fixture_wavy_grid(&replacing, 48, 23);
    mk_error err;
    CHECK(mk_raw_compute_target_normals(&one, 0, 0, 1, &err) == MK_OK);
    CHECK(mk_raw_compute_target_normals(&many, 0, 0, 5, &err) == MK_OK);
    CHECK(mk_raw_compute_target_normals_replacing(&replacing, 0, 0, 5, &err) == MK_OK);
    uint32_t differ = 0, grew = 0;
    for (uint32_t c = 0; c < one.channel_count; c++) {
        const mk_raw_target *a = &one.channels[c].targets[0];
        for (int k = 0; k < 2; k++) {
            const mk_raw_target *b = k ? &replacing.channels[c].targets[0] : &many.channels[c].targets[0];
            CHECK(a->normals != NULL && b->normals != NULL);
            if (a->count != b->count) { differ++; continue; }
            differ += memcmp(a->indices, b->indices, a->count * sizeof *a->indices) != 0;
            differ += memcmp(a->positions, b->positions, 3 * a->count * sizeof(float)) != 0;
            differ += memcmp(a->normals, b->normals, 3 * a->count * sizeof(float)) != 0;
        }
        grew += a->count > 0;
    }
    CHECK_MSG(differ == 0, "%u targets differ between 1 and 5 threads or the replacing variant", differ);
    CHECK(grew == one.channel_count);
    /* The replacing variant keeps only the new arrays: the old ones (the fixture's) are gone. */
    CHECK_MSG(replacing.arena.bytes_live < many.arena.bytes_live,
              "live bytes %zu (replacing) vs %zu", replacing.arena.bytes_live, many.arena.bytes_live);
    mk_raw_free(&one);
    mk_raw_free(&many);
    mk_raw_free(&replacing);
}

CHECK_MAIN(CASE(test_face_normal_faces_the_counterclockwise_side), CASE(test_matches_recomputed_normals), CASE(test_authored_tangents_follow_their_vertex),
           CASE(test_targets_in_turn_on_one_thread),
           CASE(test_hard_edge_stays_hard),
           CASE(test_same_result_for_any_thread_count))

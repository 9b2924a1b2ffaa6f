/* SPDX-License-Identifier: MIT */
/* Surface normals (mk_surface_run) against a brute-force recomputation written from
 * docs/semantics.md, on random grids with UV seams and hard edges and random shape weights;
 * any split into ranges gives the same bytes; unmoved vertices keep their base normal; a triangle
 * with two corners in one group counts once; the topology is refused for another mesh or asset. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fixtures.h"

static uint32_t rng = 12345;
static float frand(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (float)(rng >> 8) / 16777216.0f;
}

/* The wavy grid with a UV seam (the column x = n/2 split: its vertices duplicated, same
 * control point, same normal) and a hard edge (the row y = n/3 split, the copies with another
 * base normal), random base normals near +z elsewhere, and `targets` random discs. */
static void seamed_grid(mk_raw_asset *raw, uint32_t n, uint32_t targets, int tangents)
{
    fixture_wavy_grid(raw, n, targets);
    mk_raw_mesh *m = &raw->meshes[0];
    uint32_t base = n * n, extra = 2 * n, total = base + extra;
    float *p = mk_arena_array(&raw->arena, 3 * (size_t)total, sizeof(float));
    float *nr = mk_arena_array(&raw->arena, 3 * (size_t)total, sizeof(float));
    float *tg = mk_arena_array(&raw->arena, 4 * (size_t)total, sizeof(float));
    uint32_t *cp = mk_arena_array(&raw->arena, total, sizeof(uint32_t));
    memcpy(p, m->positions, 12 * (size_t)base);
    for (uint32_t v = 0; v < base; v++) {
        float a = 0.3f * (frand() - 0.5f), b = 0.3f * (frand() - 0.5f), l = sqrtf(a * a + b * b + 1);
        nr[3 * v] = a / l; nr[3 * v + 1] = b / l; nr[3 * v + 2] = 1 / l;
        cp[v] = v;
        tg[4 * v] = 1; tg[4 * v + 3] = v % 2 ? 1.0f : -1.0f;
    }
    for (uint32_t k = 0; k < extra; k++) {
        uint32_t src = k < n ? k * n + n / 2 : (n / 3) * n + (k - n), v = base + k;
        memcpy(&p[3 * v], &p[3 * src], 12);
        memcpy(&nr[3 * v], &nr[3 * src], 12);
        if (k >= n) { nr[3 * v] = 0.6f; nr[3 * v + 1] = 0; nr[3 * v + 2] = 0.8f; }   /* hard edge */
        memcpy(&tg[4 * v], &tg[4 * src], 16);
        cp[v] = src;
    }
    /* Triangles right of the seam use the column's copies; those above the edge the row's. */
    for (uint32_t t = 0; t < m->triangle_count; t++)
        for (int c = 0; c < 3; c++) {
            uint32_t *w = &m->triangles[3 * t + (uint32_t)c];
            const uint32_t *tri = &m->triangles[3 * t];
            uint32_t minx = n, miny = n;
            for (int q = 0; q < 3; q++) {
                uint32_t o = cp[tri[q]] < base ? cp[tri[q]] : tri[q];
                if (o % n < minx) minx = o % n;
                if (o / n < miny) miny = o / n;
            }
            if (*w % n == n / 2 && minx >= n / 2 && *w < base) *w = base + *w / n;
            else if (*w < base && *w / n == n / 3 && miny >= n / 3) *w = base + n + *w % n;
        }
    m->positions = p;
    m->normals = nr;
    m->tangents = tangents ? tg : NULL;
    m->control_points = cp;
    m->vertex_count = total;
}

static int same_normal(const float *a, const float *b)
{
    return fabsf(a[0] - b[0]) <= 1e-5f && fabsf(a[1] - b[1]) <= 1e-5f && fabsf(a[2] - b[2]) <= 1e-5f;
}

/* Whether a triangle with a corner in v's group (same control point, same base normal) has a
 * corner that moved (a value differs: -0 and +0 do not). */
static int group_moved(const mk_raw_mesh *m, const float *q, uint32_t v)
{
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = &m->triangles[3 * t];
        int in = 0, moved = 0;
        for (int c = 0; c < 3; c++) {
            in |= m->control_points[tri[c]] == m->control_points[v] && same_normal(&m->normals[3 * tri[c]], &m->normals[3 * v]);
            for (int d = 0; d < 3; d++) moved |= q[3 * tri[c] + (uint32_t)d] != m->positions[3 * tri[c] + (uint32_t)d];
        }
        if (in && moved) return 1;
    }
    return 0;
}

typedef struct opened {
    mk_raw_asset raw;
    mk_arena arena;
    mk_asset asset;
    void *topology, *scratch;
    size_t topology_size, scratch_size;
} opened;

static void open_grid(opened *o, uint32_t n, uint32_t targets, int tangents)
{
    mk_raw_init(&o->raw, NULL);
    mk_arena_init(&o->arena, NULL);
    seamed_grid(&o->raw, n, targets, tangents);
    mk_error err;
    CHECK_MSG(mk_raw_compute_target_normals(&o->raw, 0, 0, 1, &err) == MK_OK, "%s", err.message);
    size_t size;
    void *blob = fixture_blob(&o->raw, MK_PRECISION_FLOAT, &o->arena, &size);
    CHECK(mk_asset_open(blob, size, &o->asset, &err) == MK_OK);
    o->topology_size = mk_surface_topology_size(&o->asset, 0);
    o->topology = mk_arena_alloc(&o->arena, o->topology_size);
    o->scratch_size = mk_surface_scratch_size(&o->asset, 0);
    o->scratch = mk_arena_alloc(&o->arena, o->scratch_size);
    CHECK_MSG(mk_surface_topology_build(&o->asset, 0, o->topology, o->topology_size, &err) == MK_OK, "%s", err.message);
}

static void close_grid(opened *o)
{
    mk_arena_free_all(&o->arena);
    mk_raw_free(&o->raw);
}

static void eval_positions(const opened *o, const float *w, float *p)
{
    mk_mesh_info m;
    mk_mesh_get(&o->asset, 0, &m);
    size_t ss = mk_eval_scratch_size(&o->asset, 0);
    void *scratch = aligned_alloc(16, (ss + 31) & ~(size_t)15);
    mk_eval_job job = { .asset = &o->asset, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = m.channel_count,
                        .scratch = scratch, .scratch_size = ss, .positions = p, .positions_size = 12 * (size_t)m.vertex_count };
    mk_error err;
    CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
    free(scratch);
}

static mk_result surface(const opened *o, const float *p, uint32_t first, uint32_t count, float *normals, float *tangents,
                         mk_error *err)
{
    mk_mesh_info m;
    mk_mesh_get(&o->asset, 0, &m);
    mk_surface_job job = { .asset = &o->asset, .topology = o->topology, .topology_size = o->topology_size,
                           .positions = p, .positions_size = 12 * (size_t)m.vertex_count, .first_vertex = first,
                           .vertex_count = count, .normals = normals, .normals_size = 12 * (size_t)m.vertex_count,
                           .tangents = tangents, .tangents_size = 16 * (size_t)m.vertex_count,
                           .scratch = o->scratch, .scratch_size = o->scratch_size };
    return mk_surface_run(&job, err);
}

static void test_matches_brute_force(void)
{
    for (int round = 0; round < 6; round++) {
        opened o;
        open_grid(&o, 14 + (uint32_t)round, 9, round % 2);
        const mk_raw_mesh *m = &o.raw.meshes[0];
        const uint32_t nv = m->vertex_count;
        float w[9], *p = malloc(12 * (size_t)nv), *nrm = malloc(12 * (size_t)nv), *tan = malloc(16 * (size_t)nv);
        for (int c = 0; c < 9; c++) w[c] = frand() < 0.4f ? 0 : 2 * frand() - 0.5f;
        eval_positions(&o, w, p);
        mk_error err;
        CHECK_MSG(surface(&o, p, 0, MK_VERTICES_TO_END, nrm, round % 2 ? tan : NULL, &err) == MK_OK, "%s", err.message);
        double worst = 0;
        uint32_t moved = 0, kept = 0, bad_kept = 0, bad_tangent = 0;
        for (uint32_t v = 0; v < nv; v++) {
            double now[3], rest[3], r[3], len = 0;
            int is_moved = group_moved(m, p, v);
            fixture_brute_normal(m, p, v, 1, now);
            fixture_brute_normal(m, m->positions, v, 1, rest);
            if (!is_moved) {
                kept++;
                bad_kept += memcmp(&nrm[3 * v], &m->normals[3 * v], 12) != 0;
                continue;
            }
            moved++;
            for (int d = 0; d < 3; d++) { r[d] = m->normals[3 * v + (uint32_t)d] + now[d] - rest[d]; len += r[d] * r[d]; }
            double dot = 0, nn = 0;
            for (int d = 0; d < 3; d++) { dot += nrm[3 * v + (uint32_t)d] * r[d] / sqrt(len); nn += (double)nrm[3 * v + (uint32_t)d] * nrm[3 * v + (uint32_t)d]; }
            double angle = atan2(sqrt(fmax(0, nn - dot * dot)), dot) * 180 / 3.14159265358979;
            if (angle > worst) worst = angle;
            if (round % 2) {
                const float *t = &tan[4 * v];
                float td = t[0] * nrm[3 * v] + t[1] * nrm[3 * v + 1] + t[2] * nrm[3 * v + 2];
                bad_tangent += fabsf(td) > 1e-5f || t[3] != m->tangents[4 * v + 3];
            }
        }
        CHECK_MSG(moved > 10 && kept > 10, "round %d: %u moved, %u kept", round, moved, kept);
        CHECK_MSG(worst < 1e-3, "round %d: %g degrees from the brute-force normal", round, worst);
        CHECK_MSG(bad_kept == 0, "round %d: %u unmoved vertices changed normal", round, bad_kept);
        CHECK_MSG(bad_tangent == 0, "round %d: %u tangents not orthogonal or lost their handedness", round, bad_tangent);
        /* The hard edge stays hard: the row's copies keep a different normal from their originals. */
        uint32_t n = 14 + (uint32_t)round, base = n * n, same = 0;
        for (uint32_t k = 0; k < n; k++) same += same_normal(&nrm[3 * (base + n + k)], &nrm[3 * ((n / 3) * n + k)]);
        CHECK_MSG(same == 0, "round %d: %u hard-edge copies got their original's normal", round, same);
        free(p); free(nrm); free(tan);
        close_grid(&o);
    }
}

/* Random ranges give the bytes of the whole-mesh job. */
static void test_ranges_same_bytes(void)
{
    opened o;
    open_grid(&o, 20, 7, 1);
    const uint32_t nv = o.raw.meshes[0].vertex_count;
    float w[7] = { 1, 0.5f, 0, 0.8f, 1.3f, 0, 0.2f };
    float *p = malloc(12 * (size_t)nv), *whole = malloc(12 * (size_t)nv), *split = malloc(12 * (size_t)nv);
    float *tw = malloc(16 * (size_t)nv), *ts = malloc(16 * (size_t)nv);
    eval_positions(&o, w, p);
    mk_error err;
    CHECK(surface(&o, p, 0, MK_VERTICES_TO_END, whole, tw, &err) == MK_OK);
    memset(split, 0xff, 12 * (size_t)nv);
    for (uint32_t first = 0; first < nv;) {
        uint32_t count = 1 + (uint32_t)(frand() * 37);
        if (count > nv - first) count = nv - first;
        memset(o.scratch, 0x7f, o.scratch_size);   /* a job must not read what an earlier one left */
        CHECK(surface(&o, p, first, count, split + 3 * first, ts + 4 * first, &err) == MK_OK);
        first += count;
    }
    CHECK(memcmp(whole, split, 12 * (size_t)nv) == 0);
    CHECK(memcmp(tw, ts, 16 * (size_t)nv) == 0);
    CHECK(surface(&o, p, 5, 0, split, NULL, &err) == MK_OK);   /* an empty range writes nothing */
    free(p); free(whole); free(split); free(tw); free(ts);
    close_grid(&o);
}

/* A small mesh with one channel of one target, opened with its topology (o->raw owns the
 * arrays, o->arena the blob, topology and scratch). cps NULL: every vertex its own control
 * point. */
typedef struct small_mesh {
    const float *positions, *normals, *deltas;
    const uint32_t *control_points, *triangles, *moved;
    uint32_t vertex_count, control_point_count, triangle_count, moved_count;
} small_mesh;

static int open_small(opened *o, const small_mesh *s)
{
    mk_raw_init(&o->raw, NULL);
    mk_arena_init(&o->arena, NULL);
    mk_raw_mesh *m = mk_raw_add_meshes(&o->raw, 1);
    m->name = "small";
    m->vertex_count = s->vertex_count;
    m->control_point_count = s->control_point_count;
    m->triangle_count = s->triangle_count;
    m->positions = mk_arena_array(&o->raw.arena, 3 * (size_t)s->vertex_count, sizeof(float));
    m->normals = mk_arena_array(&o->raw.arena, 3 * (size_t)s->vertex_count, sizeof(float));
    m->control_points = mk_arena_array(&o->raw.arena, s->vertex_count, sizeof(uint32_t));
    m->triangles = mk_arena_array(&o->raw.arena, 3 * (size_t)s->triangle_count, sizeof(uint32_t));
    memcpy(m->positions, s->positions, 12 * (size_t)s->vertex_count);
    memcpy(m->normals, s->normals, 12 * (size_t)s->vertex_count);
    for (uint32_t v = 0; v < s->vertex_count; v++) m->control_points[v] = s->control_points ? s->control_points[v] : v;
    memcpy(m->triangles, s->triangles, 12 * (size_t)s->triangle_count);
    mk_raw_channel *ch = mk_raw_add_channels(&o->raw, 1);
    ch->name = "move";
    mk_raw_target *tg = mk_raw_add_targets(&o->raw, ch, 1);
    tg->name = "move";
    tg->count = s->moved_count;
    tg->indices = mk_arena_array(&o->raw.arena, s->moved_count, sizeof(uint32_t));
    tg->positions = mk_arena_array(&o->raw.arena, 3 * (size_t)s->moved_count, sizeof(float));
    memcpy(tg->indices, s->moved, 4 * (size_t)s->moved_count);
    memcpy(tg->positions, s->deltas, 12 * (size_t)s->moved_count);
    size_t size;
    mk_error err;
    void *blob = fixture_blob(&o->raw, MK_PRECISION_FLOAT, &o->arena, &size);
    CHECK(blob && mk_asset_open(blob, size, &o->asset, &err) == MK_OK);
    if (!blob) return 0;
    o->topology_size = mk_surface_topology_size(&o->asset, 0);
    o->scratch_size = mk_surface_scratch_size(&o->asset, 0);
    o->topology = mk_arena_alloc(&o->arena, o->topology_size);
    o->scratch = mk_arena_alloc(&o->arena, o->scratch_size);
    CHECK_MSG(mk_surface_topology_build(&o->asset, 0, o->topology, o->topology_size, &err) == MK_OK, "%s", err.message);
    return 1;
}

/* A triangle with two corners in one group (split copies of a control point that a target pulls
 * apart) adds its face normal to that group's sum once, as every triangle does. */
static void test_welded_corners(void)
{
    static const float p0[15] = { 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 };
    static const float n0[15] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
    static const uint32_t cps[5] = { 0, 1, 1, 2, 3 }, tris[6] = { 0, 1, 2, 1, 4, 3 }, moved[2] = { 2, 4 };
    static const float deltas[6] = { 0, 0.5f, 0.4f, 0, 0, 0.3f };
    const small_mesh sm = { p0, n0, deltas, cps, tris, moved, 5, 4, 2, 2 };
    opened o;
    if (open_small(&o, &sm)) {
        float p[15], nrm[15];
        memcpy(p, p0, sizeof p);
        for (int k = 0; k < 2; k++)
            for (int d = 0; d < 3; d++) p[3 * moved[k] + (uint32_t)d] += deltas[3 * k + d];
        mk_error err;
        CHECK_MSG(surface(&o, p, 0, MK_VERTICES_TO_END, nrm, NULL, &err) == MK_OK, "%s", err.message);
        /* The group's base and rest normals are both +z (the pulled triangle has no area at
         * rest), so its vertices take the normalized sum of both faces at P. */
        double worst = 0;
        for (uint32_t v = 1; v <= 2; v++) {
            double want[3];
            fixture_brute_normal(&o.raw.meshes[0], p, v, 1, want);
            for (int d = 0; d < 3; d++) worst = fmax(worst, fabs(nrm[3 * v + (uint32_t)d] - want[d]));
        }
        CHECK_MSG(worst < 1e-6, "the welded corners' normals are %g from the sum of their group's faces", worst);
    }
    close_grid(&o);
}

/* Each vertex's range job gives the whole-mesh job's bytes, whatever the scratch held, also for a
 * vertex that is never a triangle's first corner (the apex of a fan whose triangles all list it
 * last). */
static void test_range_of_a_fan_apex(void)
{
    static const float p0[15] = { 0, 0, 0.2f, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0 };
    static const float n0[15] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
    static const uint32_t tris[12] = { 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 0 }, moved[2] = { 0, 1 };
    static const float deltas[6] = { 0.1f, 0, 0.3f, 0, 0, -0.2f };
    const small_mesh sm = { p0, n0, deltas, NULL, tris, moved, 5, 5, 4, 2 };
    opened o;
    if (open_small(&o, &sm)) {
        float p[15], whole[15], range[15];
        memcpy(p, p0, sizeof p);
        for (int k = 0; k < 2; k++)
            for (int d = 0; d < 3; d++) p[3 * moved[k] + (uint32_t)d] += deltas[3 * k + d];
        mk_error err;
        CHECK_MSG(surface(&o, p, 0, MK_VERTICES_TO_END, whole, NULL, &err) == MK_OK, "%s", err.message);
        for (uint32_t v = 0; v < 5; v++) {
            memset(o.scratch, 0x3f, o.scratch_size);   /* finite sums a job must not add to */
            CHECK_MSG(surface(&o, p, v, 1, range + 3 * v, NULL, &err) == MK_OK, "%s", err.message);
        }
        CHECK(memcmp(whole, range, sizeof whole) == 0);
    }
    close_grid(&o);
}

/* A vertex in no triangle keeps its base normal in a range job as in the whole-mesh one, whatever
 * the scratch held (a finite pattern here: an infinite one would fall back to the base normal by
 * itself); outputs with their own strides get the packed outputs' bytes. */
static void test_isolated_vertex_and_strides(void)
{
    static const float p0[15] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 3, 3, 3, 1, 1, 0.5f };
    static const float n0[15] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1 };
    static const uint32_t tris[6] = { 0, 1, 2, 1, 4, 2 }, moved[2] = { 1, 4 };
    static const float deltas[6] = { 0, 0, 0.5f, 0.2f, 0, -0.3f };
    const small_mesh sm = { p0, n0, deltas, NULL, tris, moved, 5, 5, 2, 2 };
    opened o;
    if (open_small(&o, &sm)) {
        float p[15], whole[15], range[15], wide[30];
        memcpy(p, p0, sizeof p);
        for (int k = 0; k < 2; k++)
            for (int d = 0; d < 3; d++) p[3 * moved[k] + (uint32_t)d] += deltas[3 * k + d];
        mk_error err;
        CHECK_MSG(surface(&o, p, 0, MK_VERTICES_TO_END, whole, NULL, &err) == MK_OK, "%s", err.message);
        CHECK(memcmp(&whole[9], &n0[9], 12) == 0);   /* the isolated vertex */
        for (uint32_t v = 0; v < 5; v++) {
            memset(o.scratch, 0x3f, o.scratch_size);
            CHECK_MSG(surface(&o, p, v, 1, &range[3 * v], NULL, &err) == MK_OK, "%s", err.message);
        }
        CHECK_MSG(memcmp(whole, range, sizeof whole) == 0, "one-vertex jobs differ from the whole-mesh job");
        mk_surface_job job = { .asset = &o.asset, .topology = o.topology, .topology_size = o.topology_size,
                               .positions = p, .positions_size = sizeof p, .vertex_count = MK_VERTICES_TO_END,
                               .normals = wide, .normals_stride = 24, .normals_size = sizeof wide,
                               .scratch = o.scratch, .scratch_size = o.scratch_size };
        memset(wide, 0, sizeof wide);
        CHECK_MSG(mk_surface_run(&job, &err) == MK_OK, "%s", err.message);
        int same = 1;
        for (uint32_t v = 0; v < 5; v++) same &= memcmp(&wide[6 * v], &whole[3 * v], 12) == 0 && wide[6 * v + 3] == 0;
        CHECK_MSG(same, "normals written with a stride of 24 bytes differ from the packed ones");
    }
    close_grid(&o);
}

static void test_refuses_wrong_topology(void)
{
    opened a, b;
    open_grid(&a, 12, 3, 0);
    open_grid(&b, 12, 4, 0);
    const uint32_t nv = a.raw.meshes[0].vertex_count;
    float *p = calloc(3 * (size_t)nv, sizeof(float)), *nrm = malloc(12 * (size_t)nv);
    memcpy(p, a.raw.meshes[0].positions, 12 * (size_t)nv);
    mk_error err;
    opened mixed = a;
    mixed.topology = b.topology;  /* same mesh shape, another asset */
    CHECK_EQ_INT(surface(&mixed, p, 0, MK_VERTICES_TO_END, nrm, NULL, &err), MK_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "topology") != NULL);
    mixed = a;
    mixed.topology_size = a.topology_size - 16;
    CHECK_EQ_INT(surface(&mixed, p, 0, MK_VERTICES_TO_END, nrm, NULL, &err), MK_ERROR_INVALID_ARGUMENT);
    CHECK_EQ_INT(mk_surface_topology_build(&a.asset, 0, a.topology, a.topology_size - 16, &err), MK_ERROR_BUFFER_TOO_SMALL);
    CHECK_EQ_INT(mk_surface_topology_build(&a.asset, 0, (char *)a.topology + 4, a.topology_size, &err),
                 MK_ERROR_INVALID_ARGUMENT);
    CHECK_EQ_INT(mk_surface_topology_build(&a.asset, 1, a.topology, a.topology_size, &err), MK_ERROR_OUT_OF_RANGE);
    /* A topology claiming more groups than vertices (its header's fifth u32, after magic, mesh,
     * vertex and triangle counts) would make a job zero sums past its scratch: refused. */
    void *forged = mk_arena_alloc(&a.arena, a.topology_size);
    memcpy(forged, a.topology, a.topology_size);
    uint32_t groups = nv + 1;
    memcpy((char *)forged + 16, &groups, 4);
    mixed = a;
    mixed.topology = forged;
    CHECK_EQ_INT(surface(&mixed, p, 0, MK_VERTICES_TO_END, nrm, NULL, &err), MK_ERROR_INVALID_ARGUMENT);
    mk_surface_job job = { .asset = &a.asset, .topology = a.topology, .topology_size = a.topology_size, .positions = p,
                           .positions_size = 12 * (size_t)nv - 4, .vertex_count = MK_VERTICES_TO_END, .normals = nrm,
                           .normals_size = 12 * (size_t)nv, .scratch = a.scratch, .scratch_size = a.scratch_size - 16 };
    CHECK_EQ_INT(mk_surface_run(&job, &err), MK_ERROR_BUFFER_TOO_SMALL);   /* scratch too small */
    job.scratch_size += 16;
    CHECK_EQ_INT(mk_surface_run(&job, &err), MK_ERROR_BUFFER_TOO_SMALL);   /* positions must cover the mesh */
    job.positions_size += 4;
    job.first_vertex = 3;
    job.normals_size = 12 * (size_t)(nv - 3) - 4;
    CHECK_EQ_INT(mk_surface_run(&job, &err), MK_ERROR_BUFFER_TOO_SMALL);
    job.normals_size += 4;
    CHECK_EQ_INT(mk_surface_run(&job, &err), MK_OK);
    job.tangents = nrm;
    job.tangents_size = 16 * (size_t)nv;
    CHECK_EQ_INT(mk_surface_run(&job, &err), MK_ERROR_UNSUPPORTED);  /* no tangents in this mesh */
    free(p); free(nrm);
    close_grid(&a);
    close_grid(&b);
    /* A mesh without normals has no topology. */
    mk_raw_asset raw;
    mk_arena arena;
    mk_raw_init(&raw, NULL);
    mk_arena_init(&arena, NULL);
    fixture_basic(&raw);
    size_t size;
    void *blob = fixture_blob(&raw, MK_PRECISION_FLOAT, &arena, &size);
    mk_asset asset;
    CHECK(mk_asset_open(blob, size, &asset, &err) == MK_OK);
    CHECK_EQ_INT(mk_surface_topology_size(&asset, 1), 0);     /* "plain": no normals */
    CHECK_EQ_INT(mk_surface_topology_build(&asset, 1, blob, 1024, &err), MK_ERROR_UNSUPPORTED);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Non-finite positions (a caller's own, or weights far past a target's range) give finite
 * normals and tangents: a group whose sum is not finite takes its base normal as N(P). */
static void test_non_finite_positions(void)
{
    opened o;
    open_grid(&o, 16, 5, 1);
    const uint32_t nv = o.raw.meshes[0].vertex_count;
    float w[5] = { 1, 0.5f, 0, 0.8f, 1 }, *p = malloc(12 * (size_t)nv), *nrm = malloc(12 * (size_t)nv),
          *tan = malloc(16 * (size_t)nv), *split = malloc(12 * (size_t)nv);
    eval_positions(&o, w, p);
    p[3 * 40] = NAN;
    p[3 * 90 + 1] = INFINITY;
    p[3 * 91 + 2] = 3e38f;   /* finite, but its face normals overflow */
    mk_error err;
    CHECK_MSG(surface(&o, p, 0, MK_VERTICES_TO_END, nrm, tan, &err) == MK_OK, "%s", err.message);
    uint32_t bad = 0;
    for (uint32_t i = 0; i < 3 * nv; i++) bad += !isfinite(nrm[i]);
    for (uint32_t i = 0; i < 4 * nv; i++) bad += !isfinite(tan[i]);
    CHECK_MSG(bad == 0, "%u non-finite normal or tangent components", bad);
    for (uint32_t first = 0; first < nv; first += 29) {
        uint32_t count = nv - first < 29 ? nv - first : 29;
        CHECK(surface(&o, p, first, count, split + 3 * first, NULL, &err) == MK_OK);
    }
    CHECK(memcmp(nrm, split, 12 * (size_t)nv) == 0);
    free(p); free(nrm); free(tan); free(split);
    close_grid(&o);
}

/* Degenerate pieces: a triangle whose corners coincide at rest (each corner a group without
 * area at rest, N(P0) = B_n) that a target opens, a vertex in no triangle, and an ordinary
 * triangle the target leaves alone. Opened: the coinciding corners take the opened face's own
 * normal (d = N(P)); the lone vertex and the untouched triangle keep their base bytes; at
 * weight 0 every vertex keeps them. */
static void test_degenerate_pieces(void)
{
    static const float p0[21] = { 0, 0, 0, 1, 0, 0, 0, 1, 0,  5, 5, 1, 5, 5, 1, 5, 5, 1,  9, 9, 9 };
    static const float n0[21] = { 0, 0, 1, 0, 0, 1, 0, 0, 1,  0.6f, 0, 0.8f, 0, 0.6f, 0.8f, 0, 0, 1,  1, 0, 0 };
    static const uint32_t tris[6] = { 0, 1, 2, 3, 4, 5 }, moved[3] = { 4, 5, 6 };
    static const float deltas[9] = { 1, 0, 0.5f, 0, 1, 0.25f, 0.5f, 0.5f, 0.5f };
    const small_mesh sm = { p0, n0, deltas, NULL, tris, moved, 7, 7, 2, 3 };
    opened o;
    if (!open_small(&o, &sm)) goto done;
    for (int opened_up = 0; opened_up < 2; opened_up++) {
        float p[21], nrm[21];
        memcpy(p, p0, sizeof p);
        if (opened_up)
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 3; d++) p[3 * moved[k] + (uint32_t)d] += deltas[3 * k + d];
        mk_error err;
        CHECK_MSG(surface(&o, p, 0, MK_VERTICES_TO_END, nrm, NULL, &err) == MK_OK, "%s", err.message);
        CHECK_MSG(memcmp(nrm, n0, 9 * sizeof(float)) == 0, "opened %d: the untouched triangle changed", opened_up);
        CHECK_MSG(memcmp(nrm + 18, n0 + 18, 3 * sizeof(float)) == 0, "opened %d: the lone vertex changed", opened_up);
        if (!opened_up) {
            CHECK(memcmp(nrm + 9, n0 + 9, 9 * sizeof(float)) == 0);
            continue;
        }
        /* The opened face's normal: (b - a) x (c - a) normalized. */
        const float *A = &p[9], *B = &p[12], *C = &p[15];
        double e1[3] = { B[0] - A[0], B[1] - A[1], B[2] - A[2] }, e2[3] = { C[0] - A[0], C[1] - A[1], C[2] - A[2] };
        double f[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
        double l = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), worst = 0;
        for (uint32_t v = 3; v < 6; v++)
            for (int d = 0; d < 3; d++) worst = fmax(worst, fabs(nrm[3 * v + (uint32_t)d] - f[d] / l));
        CHECK_MSG(worst < 1e-6, "the opened corners are %g from their face's normal", worst);
    }
done:
    close_grid(&o);
}

CHECK_MAIN(CASE(test_matches_brute_force), CASE(test_ranges_same_bytes), CASE(test_range_of_a_fan_apex), CASE(test_non_finite_positions),
           CASE(test_degenerate_pieces), CASE(test_welded_corners), CASE(test_isolated_vertex_and_strides),
           CASE(test_refuses_wrong_topology))

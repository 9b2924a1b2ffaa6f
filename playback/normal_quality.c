/* SPDX-License-Identifier: MIT */
#include "normal_quality.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "frame.h"

long pb_reference_normals(const mk_raw_mesh *m, const mk_normal_groups *groups, const double *rest_normals,
                          const float *positions, double *reference, unsigned char *moved, mk_arena *arena)
{
    const size_t n = m->vertex_count;
    double *p = mk_arena_array(arena, 3 * n + 3, sizeof(double));
    unsigned char *group_moved = mk_arena_array(arena, (size_t)groups->group_count + 1, 1);
    if (!p || !group_moved) return -1;
    for (size_t i = 0; i < 3 * n; i++) p[i] = positions[i];
    /* A group's normal changes when one of its triangles has a corner that moved. */
    memset(moved, 0, n);
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = &m->triangles[3u * t];
        int any = 0;
        for (int c = 0; c < 3; c++)
            for (int d = 0; d < 3; d++) any |= positions[3u * tri[c] + (uint32_t)d] != m->positions[3u * tri[c] + (uint32_t)d];
        if (any)
            for (int c = 0; c < 3; c++) group_moved[groups->group_of[tri[c]]] = 1;
    }
    long count = 0;
    for (size_t v = 0; v < n; v++) count += moved[v] = group_moved[groups->group_of[v]];
    mk_error err;
    if (mk_normal_groups_smooth(groups, m, p, moved, reference, arena, &err) != MK_OK) count = -1;
    for (size_t v = 0; count >= 0 && v < n; v++) {
        if (!moved[v]) { reference[3 * v] = reference[3 * v + 1] = reference[3 * v + 2] = 0; continue; }
        double r[3], len = 0;
        for (int d = 0; d < 3; d++) {
            r[d] = m->normals[3 * v + (size_t)d] + reference[3 * v + (size_t)d] - rest_normals[3 * v + (size_t)d];
            len += r[d] * r[d];
        }
        len = sqrt(len);
        for (int d = 0; d < 3; d++) reference[3 * v + (size_t)d] = len > 0 ? r[d] / len : 0;
    }
    mk_arena_release(arena, p);
    mk_arena_release(arena, group_moved);
    return count;
}

/* Angle in degrees between a (any length) and the unit vector b. */
static double angle_deg(const float *a, const double *b)
{
    double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
    double s = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return atan2(s, d) * (180.0 / 3.14159265358979323846);
}

void pb_normal_angles(const float *a, const float *b, uint32_t count, float *degrees)
{
    for (uint32_t v = 0; v < count; v++) {
        const double r[3] = { b[3 * v], b[3 * v + 1], b[3 * v + 2] };
        degrees[v] = (float)angle_deg(&a[3 * v], r);
    }
}

static int reserve(pb_normal_quality *q, size_t more)
{
    if (q->count + more <= q->capacity) return 1;
    size_t cap = q->capacity ? q->capacity : 1024;
    while (cap < q->count + more) cap *= 2;
    for (int k = 0; k < PB_QUALITY_MODES; k++) {
        double *grown = realloc(q->angles[k], cap * sizeof(double));
        if (!grown) return 0;
        q->angles[k] = grown;
    }
    q->capacity = cap;
    return 1;
}

/* What a mesh's frames share: its smoothing groups and rest normals, its surface topology. */
typedef struct pb_quality_mesh {
    int ready, measured;               /* built; has normals and triangles */
    mk_arena arena;
    mk_normal_groups groups;
    double *rest;                      /* N(P0), 3 per vertex */
    pb_surface surface;
} pb_quality_mesh;

static mk_result prepare_mesh(pb_quality_mesh *qm, const mk_asset *asset, const mk_raw_mesh *m, uint32_t mi,
                              mk_error *err)
{
    mk_mesh_info info;
    mk_mesh_get(asset, mi, &info);
    qm->ready = 1;
    mk_arena_init(&qm->arena, NULL);
    if (!m->normals || !m->triangle_count || !info.has_normals) return MK_OK;
    if (info.vertex_count != m->vertex_count)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "normal quality: mesh %u has %u vertices in the raw model, %u in the asset", mi,
                            m->vertex_count, info.vertex_count);
    const size_t n = m->vertex_count;
    double *rest_p = mk_arena_array(&qm->arena, 3 * n + 3, sizeof(double));
    qm->rest = mk_arena_array(&qm->arena, 3 * n + 3, sizeof(double));
    if (!rest_p || !qm->rest) return mk_error_oom(err, "normal quality");
    mk_result r = mk_normal_groups_build(m, MK_GROUP_BY_CONTROL_POINT, &qm->arena, &qm->groups, err);
    for (size_t i = 0; r == MK_OK && i < 3 * n; i++) rest_p[i] = m->positions[i];
    if (r == MK_OK) r = mk_normal_groups_smooth(&qm->groups, m, rest_p, NULL, qm->rest, &qm->arena, err);
    mk_arena_release(&qm->arena, rest_p);
    if (r == MK_OK) r = pb_surface_prepare(&qm->surface, asset, mi, err);
    qm->measured = r == MK_OK;
    return r;
}

mk_result pb_normal_quality_add(pb_normal_quality *q, const mk_asset *asset, const mk_raw_asset *raw,
                                const float *weights, mk_stacking stacking, mk_error *err)
{
    if ((!raw || raw->mesh_count == 0) && asset->mesh_count > 0) {
        if (!q->read_back) {
            if (!(q->read_back = malloc(sizeof *q->read_back))) return mk_error_oom(err, "normal quality");
            mk_raw_init(q->read_back, NULL);
            mk_result r = mk_read_blob(asset, q->read_back, err);
            if (r != MK_OK) return r;
        }
        raw = q->read_back;
    }
    if (raw->mesh_count != asset->mesh_count || (q->meshes && q->mesh_count != asset->mesh_count))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "normal quality: the raw model has %u meshes, the asset %u", raw->mesh_count,
                            asset->mesh_count);
    if (!q->meshes) {
        q->meshes = calloc(asset->mesh_count + 1u, sizeof *q->meshes);
        if (!q->meshes) return mk_error_oom(err, "normal quality");
        q->mesh_count = asset->mesh_count;
    }
    mk_result r = MK_OK;
    for (uint32_t mi = 0; mi < asset->mesh_count && r == MK_OK; mi++) {
        const mk_raw_mesh *m = &raw->meshes[mi];
        pb_quality_mesh *qm = &q->meshes[mi];
        if (!qm->ready && (r = prepare_mesh(qm, asset, m, mi, err)) != MK_OK) break;
        if (!qm->measured) continue;
        const size_t n = m->vertex_count;
        mk_arena arena;
        mk_arena_init(&arena, NULL);
        double *reference = mk_arena_array(&arena, 3 * n + 3, sizeof(double));
        float *positions = mk_arena_array(&arena, 3 * n + 3, sizeof(float));
        float *normals = mk_arena_array(&arena, 3 * n + 3, sizeof(float));
        unsigned char *moved = mk_arena_array(&arena, n + 1, 1);
        if (!reference || !positions || !normals || !moved) r = mk_error_oom(err, "normal quality");
        if (r == MK_OK) r = pb_eval_mesh(asset, mi, weights, stacking, MK_NORMALS_NLERP, positions, normals, err);
        long count = r == MK_OK ? pb_reference_normals(m, &qm->groups, qm->rest, positions, reference, moved, &arena) : 0;
        if (count < 0 || (r == MK_OK && !reserve(q, (size_t)count))) r = mk_error_oom(err, "normal quality");
        for (int mode = 0; r == MK_OK && mode < PB_QUALITY_MODES; mode++) {
            if (mode == PB_QUALITY_SLERP)
                r = pb_eval_mesh(asset, mi, weights, stacking, MK_NORMALS_SLERP, positions, normals, err);
            if (mode == PB_QUALITY_SURFACE) r = pb_surface_run(&qm->surface, positions, normals, NULL, err);
            if (r != MK_OK) break;
            size_t at = q->count;
            for (size_t v = 0; v < n; v++) {
                if (!moved[v]) continue;
                const float *e = mode == PB_QUALITY_BASE ? &m->normals[3 * v] : &normals[3 * v];
                q->angles[mode][at++] = angle_deg(e, &reference[3 * v]);
            }
        }
        if (r == MK_OK) q->count += (size_t)count;
        mk_arena_free_all(&arena);
    }
    if (r == MK_OK) q->frames++;
    return r;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

const char *pb_quality_name(int mode)
{
    static const char *const names[PB_QUALITY_MODES] = { "nlerp", "slerp", "surface", "base" };
    return mode >= 0 && mode < PB_QUALITY_MODES ? names[mode] : "";
}

const char *pb_quality_label(int mode)
{
    static const char *const labels[PB_QUALITY_MODES] = { "nlerp", "slerp", "surface", "base normals kept" };
    return mode >= 0 && mode < PB_QUALITY_MODES ? labels[mode] : "";
}

pb_normal_stats pb_normal_quality_stats(const pb_normal_quality *q, int mode)
{
    pb_normal_stats s = { q->count, 0, 0, 0 };
    if (!q->count || mode < 0 || mode >= PB_QUALITY_MODES) return s;
    double *sorted = malloc(q->count * sizeof(double));
    if (!sorted) return s;
    memcpy(sorted, q->angles[mode], q->count * sizeof(double));
    qsort(sorted, q->count, sizeof(double), compare_double);
    double sum = 0;
    for (size_t i = 0; i < q->count; i++) sum += sorted[i];
    s.mean = sum / (double)q->count;
    s.p99 = sorted[(size_t)ceil(0.99 * (double)q->count) - 1];
    s.max = sorted[q->count - 1];
    free(sorted);
    return s;
}

void pb_normal_quality_free(pb_normal_quality *q)
{
    for (int k = 0; k < PB_QUALITY_MODES; k++) free(q->angles[k]);
    for (uint32_t mi = 0; q->meshes && mi < q->mesh_count; mi++) {
        pb_surface_free(&q->meshes[mi].surface);
        if (q->meshes[mi].ready) mk_arena_free_all(&q->meshes[mi].arena);
    }
    free(q->meshes);
    if (q->read_back) mk_raw_free(q->read_back);
    free(q->read_back);
    memset(q, 0, sizeof *q);
}

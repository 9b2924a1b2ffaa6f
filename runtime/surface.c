/* SPDX-License-Identifier: MIT */
/* Surface normals: normals recomputed from evaluated positions (docs/semantics.md, "Surface
 * normals"; the API in morphkit.h).
 *
 * The topology, built once per mesh into caller memory, holds the smoothing groups (vertices
 * with the same control point and the same base normal within 1e-5 per component, numbered in
 * control-point order, then vertex order), each group's triangles (a triangle once per
 * distinct corner group, in triangle order) and each group's rest normal. The rules and the
 * order of every sum are those of the offline importer's target normals, so a single target at
 * its full weight reproduces the normal deltas the importer computed for it. A vertex's normal
 * depends only on the positions and the topology, never on the job's range. */
#include <math.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"
#include "error.h"
#include "span.h"
#include "determinism.h"

#define TOPOLOGY_MAGIC 0x54534b4du /* "MKST" */

typedef struct topology_header {
    uint32_t magic, mesh;
    uint32_t vertex_count, triangle_count, group_count, reserved;
    uint64_t size;                 /* bytes the topology was built for */
    uint64_t checksum;             /* the blob's, to refuse another asset's topology */
    uint64_t group_of, group_tri_first, group_tris, rest; /* array offsets in the topology */
} topology_header;                 /* 64 bytes */

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

typedef struct layout {
    size_t group_of, group_tri_first, group_tris, rest, size;
} layout;

/* Offsets of the arrays; size 0 when the mesh cannot have a topology. The rest-normal region
 * (3 doubles per possible group) first serves as the build's scratch (control point lists). */
static layout topology_layout(const mk_blob_mesh *m)
{
    layout l = { 0, 0, 0, 0, 0 };
    if (!(m->flags & MK_MESH_HAS_NORMALS) || m->triangle_count == 0 || m->vertex_count == 0) return l;
    size_t v = m->vertex_count, t = m->triangle_count, c = m->control_point_count;
    if (v > SIZE_MAX / 64 || t > SIZE_MAX / 64 || c > SIZE_MAX / 64) return l;
    size_t scratch = 4 * (2 * c + v + 1);
    size_t rest = 24 * v > scratch ? 24 * v : scratch;
    l.group_of = align16(sizeof(topology_header));
    l.group_tri_first = l.group_of + align16(4 * v);
    l.group_tris = l.group_tri_first + align16(4 * (v + 1));
    l.rest = l.group_tris + align16(12 * t);
    l.size = l.rest + align16(rest);
    return l;
}

size_t mk_surface_topology_size(const mk_asset *asset, uint32_t mesh)
{
    if (!asset || mesh >= asset->mesh_count) return 0;
    return topology_layout(&asset->meshes[mesh]).size;
}

static int same_normal(const float *a, const float *b)
{
    return fabsf(a[0] - b[0]) <= 1e-5f && fabsf(a[1] - b[1]) <= 1e-5f && fabsf(a[2] - b[2]) <= 1e-5f;
}

/* Area-weighted face normal (cross product) of triangle tri at positions p (stride bytes). */
static void face_normal(const uint32_t *tri, const uint8_t *p, size_t stride, double out[3])
{
    const float *a = (const float *)(const void *)(p + stride * tri[0]);
    const float *b = (const float *)(const void *)(p + stride * tri[1]);
    const float *c = (const float *)(const void *)(p + stride * tri[2]);
    double e1[3] = { (double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2] };
    double e2[3] = { (double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2] };
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* The normalized sum of a group's face normals at positions p; fallback where it has no area. */
static void group_normal(const uint32_t *tris, uint32_t first, uint32_t end, const uint32_t *triangles,
                         const uint8_t *p, size_t stride, const float *fallback, double out[3])
{
    double sum[3] = { 0, 0, 0 }, f[3];
    for (uint32_t k = first; k < end; k++) {
        face_normal(&triangles[3u * tris[k]], p, stride, f);
        sum[0] += f[0]; sum[1] += f[1]; sum[2] += f[2];
    }
    double len = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    for (int d = 0; d < 3; d++) out[d] = len > 0 ? sum[d] / len : (double)fallback[d];
}

mk_result mk_surface_topology_build(const mk_asset *asset, uint32_t mesh, void *topology, size_t size, mk_error *err)
{
    if (!asset || mesh >= asset->mesh_count)
        return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "surface topology: mesh index out of range");
    const mk_blob_mesh *m = &asset->meshes[mesh];
    layout l = topology_layout(m);
    if (!l.size)
        return mk_error_fail(err, MK_ERROR_UNSUPPORTED, MK_NO_OFFSET, "surface topology: the mesh has no normals or no triangles");
    if (!topology || (uintptr_t)topology % 16)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "surface topology: memory is NULL or not 16-byte aligned");
    if (size < l.size)
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "surface topology: memory is smaller than mk_surface_topology_size()");
    uint8_t *base = topology;
    const uint32_t n = m->vertex_count, cps = m->control_point_count, tri_count = m->triangle_count;
    const uint32_t *cp = (const uint32_t *)(const void *)(asset->data + m->control_points);
    const uint32_t *triangles = (const uint32_t *)(const void *)(asset->data + m->triangles);
    const float *normals = (const float *)(const void *)(asset->data + m->normals);
    uint32_t *group_of = (uint32_t *)(void *)(base + l.group_of);
    uint32_t *tri_first = (uint32_t *)(void *)(base + l.group_tri_first);
    uint32_t *group_tris = (uint32_t *)(void *)(base + l.group_tris);
    /* Scratch in the rest-normal region: control point -> its vertices (CSR), a fill cursor. */
    uint32_t *cp_first = (uint32_t *)(void *)(base + l.rest), *cp_verts = cp_first + cps + 1, *fill = cp_verts + n;
    memset(cp_first, 0, 4 * ((size_t)cps + 1));
    for (uint32_t v = 0; v < n; v++) cp_first[cp[v] + 1]++;
    for (uint32_t k = 0; k < cps; k++) cp_first[k + 1] += cp_first[k];
    memcpy(fill, cp_first, 4 * (size_t)cps);
    for (uint32_t v = 0; v < n; v++) cp_verts[fill[cp[v]]++] = v;
    /* Groups: per control point, a vertex joins the first earlier vertex with its normal. */
    uint32_t groups = 0;
    for (uint32_t k = 0; k < cps; k++)
        for (uint32_t i = cp_first[k]; i < cp_first[k + 1]; i++) {
            uint32_t v = cp_verts[i], found = UINT32_MAX;
            for (uint32_t j = cp_first[k]; j < i && found == UINT32_MAX; j++)
                if (same_normal(&normals[3u * cp_verts[j]], &normals[3u * v])) found = group_of[cp_verts[j]];
            group_of[v] = found != UINT32_MAX ? found : groups++;
        }
    /* Group -> triangles: each triangle once per distinct corner group, in triangle order. */
    memset(tri_first, 0, 4 * ((size_t)groups + 1));
    for (uint32_t t = 0; t < tri_count; t++) {
        uint32_t g0 = group_of[triangles[3u * t]], g1 = group_of[triangles[3u * t + 1]], g2 = group_of[triangles[3u * t + 2]];
        tri_first[g0 + 1]++;
        if (g1 != g0) tri_first[g1 + 1]++;
        if (g2 != g0 && g2 != g1) tri_first[g2 + 1]++;
    }
    for (uint32_t g = 0; g < groups; g++) tri_first[g + 1] += tri_first[g];
    memcpy(fill, tri_first, 4 * (size_t)groups);
    for (uint32_t t = 0; t < tri_count; t++) {
        uint32_t g0 = group_of[triangles[3u * t]], g1 = group_of[triangles[3u * t + 1]], g2 = group_of[triangles[3u * t + 2]];
        group_tris[fill[g0]++] = t;
        if (g1 != g0) group_tris[fill[g1]++] = t;
        if (g2 != g0 && g2 != g1) group_tris[fill[g2]++] = t;
    }
    /* Rest normals (the scratch is no longer needed); (0,0,0) for a group without area, whose
     * vertices then take their own base normal as the rest normal. */
    double *rest = (double *)(void *)(base + l.rest);
    static const float none[3] = { 0, 0, 0 };
    for (uint32_t g = 0; g < groups; g++)
        group_normal(group_tris, tri_first[g], tri_first[g + 1], triangles, asset->data + m->positions, 12, none,
                     &rest[3u * g]);
    topology_header h = { .magic = TOPOLOGY_MAGIC, .mesh = mesh, .vertex_count = n, .triangle_count = tri_count,
                          .group_count = groups, .size = l.size, .checksum = asset->header->checksum,
                          .group_of = l.group_of, .group_tri_first = l.group_tri_first, .group_tris = l.group_tris,
                          .rest = l.rest };
    memcpy(base, &h, sizeof h);
    return MK_OK;
}

mk_result mk_surface_validate(const mk_surface_job *job, mk_error *err)
{
    if (!job || !job->asset)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "surface job or its asset is NULL");
    const mk_asset *a = job->asset;
    if (job->mesh >= a->mesh_count)
        return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "surface job: mesh index out of range");
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    if (!(m->flags & MK_MESH_HAS_NORMALS) || m->triangle_count == 0)
        return mk_error_fail(err, MK_ERROR_UNSUPPORTED, MK_NO_OFFSET, "surface job: the mesh has no normals or no triangles");
    if (job->first_vertex > m->vertex_count
        || (job->vertex_count != MK_VERTICES_TO_END && job->vertex_count > m->vertex_count - job->first_vertex))
        return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "surface job: vertex range exceeds the mesh");
    topology_header h;
    if (!job->topology || (uintptr_t)job->topology % 16 || job->topology_size < sizeof h)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "surface job: topology is NULL, misaligned or too small");
    memcpy(&h, job->topology, sizeof h);
    layout l = topology_layout(m);
    if (h.magic != TOPOLOGY_MAGIC || h.mesh != job->mesh || h.vertex_count != m->vertex_count
        || h.triangle_count != m->triangle_count || h.checksum != a->header->checksum || h.size != l.size
        || job->topology_size < l.size)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET,
                             "surface job: the topology was not built by mk_surface_topology_build for this mesh of this asset");
    if (!job->scratch || (uintptr_t)job->scratch % 16 || job->scratch_size < mk_surface_scratch_size(a, job->mesh))
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET,
                             "surface job: scratch is NULL, not 16-byte aligned or smaller than mk_surface_scratch_size()");
    if (!job->positions || !mk_span_ok(job->positions, mk_stride_or(job->positions_stride, 12), job->positions_size, m->vertex_count, 12))
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET,
                             "surface job: positions (the whole mesh) are NULL, too small or misaligned");
    uint32_t n = job->vertex_count == MK_VERTICES_TO_END ? m->vertex_count - job->first_vertex : job->vertex_count;
    if (!job->normals || !mk_span_ok(job->normals, mk_stride_or(job->normals_stride, 12), job->normals_size, n, 12))
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "surface job: normals output is NULL, too small or misaligned");
    if (job->tangents) {
        if (!(m->flags & MK_MESH_HAS_TANGENTS))
            return mk_error_fail(err, MK_ERROR_UNSUPPORTED, MK_NO_OFFSET, "surface job: tangents requested but the mesh has no tangents");
        if (!mk_span_ok(job->tangents, mk_stride_or(job->tangents_stride, 16), job->tangents_size, n, 16))
            return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "surface job: tangents span is too small or misaligned");
    }
    return MK_OK;
}

/* Per triangle, in the job's scratch: whether a corner moved and, once a moved group needs
 * it, its face normal at the evaluated positions; each computed at most once per job however
 * many groups use the triangle. A job first clears the states of the triangles its range
 * reaches, so the scratch needs no initialization and any job may use any scratch. */
enum { FACE_UNKNOWN, FACE_CHECKED, FACE_NORMAL };

typedef struct face_cache {
    double normal[3];
    uint32_t state, moved;
} face_cache;

/* Whether a corner of tri is not where it rests (-0 and +0 are the same place), checked once. */
static uint32_t face_moved(face_cache *f, const uint32_t *tri, const uint8_t *p, size_t stride, const float *p0)
{
    if (f->state == FACE_UNKNOWN) {
        uint32_t any = 0;
        for (int c = 0; c < 3; c++) {
            const float *q = (const float *)(const void *)(p + stride * tri[c]);
            const float *o = &p0[3u * tri[c]];
            any |= (uint32_t)(q[0] != o[0]) | (uint32_t)(q[1] != o[1]) | (uint32_t)(q[2] != o[2]);
        }
        f->moved = any;
        f->state = FACE_CHECKED;
    }
    return f->moved;
}

size_t mk_surface_scratch_size(const mk_asset *asset, uint32_t mesh)
{
    if (!mk_surface_topology_size(asset, mesh)) return 0;
    return sizeof(face_cache) * (size_t)asset->meshes[mesh].triangle_count;
}

mk_result mk_surface_run(const mk_surface_job *job, mk_error *err)
{
    mk_result r = mk_surface_validate(job, err);
    if (r != MK_OK) return r;
    const mk_asset *a = job->asset;
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    topology_header h;
    memcpy(&h, job->topology, sizeof h);
    const uint8_t *base = job->topology;
    const uint32_t *group_of = (const uint32_t *)(const void *)(base + h.group_of);
    const uint32_t *tri_first = (const uint32_t *)(const void *)(base + h.group_tri_first);
    const uint32_t *group_tris = (const uint32_t *)(const void *)(base + h.group_tris);
    const double *rest = (const double *)(const void *)(base + h.rest);
    const uint32_t *triangles = (const uint32_t *)(const void *)(a->data + m->triangles);
    const float *p0 = (const float *)(const void *)(a->data + m->positions);
    const float *normals = (const float *)(const void *)(a->data + m->normals);
    const float *tangents = m->tangents ? (const float *)(const void *)(a->data + m->tangents) : NULL;
    const uint8_t *p = (const uint8_t *)job->positions;
    const size_t ps = mk_stride_or(job->positions_stride, 12), ns = mk_stride_or(job->normals_stride, 12),
                 ts = mk_stride_or(job->tangents_stride, 16);
    face_cache *faces = job->scratch;
    uint32_t n = job->vertex_count == MK_VERTICES_TO_END ? m->vertex_count - job->first_vertex : job->vertex_count;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t g = group_of[job->first_vertex + i];
        for (uint32_t k = tri_first[g]; k < tri_first[g + 1]; k++) faces[group_tris[k]].state = FACE_UNKNOWN;
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t v = job->first_vertex + i, g = group_of[v];
        const float *b = &normals[3u * v];
        /* Moved: a corner of one of the group's triangles is not where it rests. Unmoved groups
         * keep their base normal without any face normal. */
        uint32_t moved = 0;
        for (uint32_t k = tri_first[g]; k < tri_first[g + 1] && !moved; k++)
            moved = face_moved(&faces[group_tris[k]], &triangles[3u * group_tris[k]], p, ps, p0);
        double sum[3] = { 0, 0, 0 };
        for (uint32_t k = tri_first[g]; moved && k < tri_first[g + 1]; k++) {
            face_cache *f = &faces[group_tris[k]];
            if (f->state != FACE_NORMAL) {
                face_moved(f, &triangles[3u * group_tris[k]], p, ps, p0);   /* a later group may ask */
                face_normal(&triangles[3u * group_tris[k]], p, ps, f->normal);
                f->state = FACE_NORMAL;
            }
            sum[0] += f->normal[0]; sum[1] += f->normal[1]; sum[2] += f->normal[2];
        }
        float out[3] = { b[0], b[1], b[2] };
        if (moved) {
            double now[3], s[3], area = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
            double inv = area > 0 ? 1.0 / area : 0.0;
            for (int d = 0; d < 3; d++) now[d] = area > 0 ? sum[d] * inv : (double)b[d];
            const double *r0 = &rest[3u * g];
            int flat = r0[0] == 0 && r0[1] == 0 && r0[2] == 0;
            for (int d = 0; d < 3; d++) s[d] = (double)b[d] + now[d] - (flat ? (double)b[d] : r0[d]);
            double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            if (len > 1e-8) {
                double inv_len = 1.0 / len;
                for (int d = 0; d < 3; d++) out[d] = (float)(s[d] * inv_len);
            }
        }
        memcpy((uint8_t *)job->normals + ns * i, out, sizeof out);
        if (job->tangents) {
            float t[4];
            memcpy(t, &tangents[4u * v], sizeof t);
            if (moved) {
                float dot = t[0] * out[0] + t[1] * out[1] + t[2] * out[2];
                float o[3] = { t[0] - out[0] * dot, t[1] - out[1] * dot, t[2] - out[2] * dot };
                float len = sqrtf(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
                if (len >= 1e-12f)
                    for (int d = 0; d < 3; d++) t[d] = o[d] / len;
            }
            memcpy((uint8_t *)job->tangents + ts * i, t, sizeof t);
        }
    }
    return MK_OK;
}

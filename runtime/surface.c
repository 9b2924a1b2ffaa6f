/* SPDX-License-Identifier: MIT */
/* Surface normals: normals recomputed from evaluated positions (docs/semantics.md, "Surface
 * normals"; the API in morphkit.h).
 *
 * The topology, built once per mesh into caller memory, holds the smoothing groups (vertices
 * with the same control point and the same base normal within 1e-5 per component, numbered in
 * control-point order, then vertex order), each group's triangles (a triangle once per
 * distinct corner group, in triangle order), each triangle's distinct corner groups and each
 * group's rest normal. The rules and the order of every sum are those of the offline
 * importer's target normals (which sums in double precision; here single precision keeps the
 * per-frame pass small), so a single target at its full weight reproduces the normal deltas
 * the importer computed for it up to float rounding. A job sums each needed triangle's face
 * normal into its corner groups in one pass in triangle order, then finishes its vertices. A
 * vertex's normal depends only on the positions and the topology, never on the job's range. */
#include <math.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"
#include "error.h"
#include "span.h"
#include "determinism.h"

#define TOPOLOGY_MAGIC 0x54534b4du /* "MKST" */
#define NO_GROUP UINT32_MAX

typedef struct topology_header {
    uint32_t magic, mesh;
    uint32_t vertex_count, triangle_count, group_count, reserved;
    uint64_t size;                 /* bytes the topology was built for */
    uint64_t checksum;             /* the blob's, to refuse another asset's topology */
    uint64_t group_of, group_tri_first, group_tris, rest, tri_groups; /* array offsets */
} topology_header;

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

typedef struct layout {
    size_t group_of, group_tri_first, group_tris, tri_groups, rest, size;
} layout;

/* Per smoothing group: the sum of its face normals and whether a corner of its triangles moved
 * (a job's sums in its scratch; the rest normals in the topology, normalized, moved unused). */
typedef struct group_sum {
    float normal[3];
    uint32_t moved;
} group_sum;

/* Offsets of the arrays; size 0 when the mesh cannot have a topology. The rest-normal region
 * (a group_sum per possible group) first serves as the build's scratch (control point lists). */
static layout topology_layout(const mk_blob_mesh *m)
{
    layout l = { 0, 0, 0, 0, 0, 0 };
    if (!(m->flags & MK_MESH_HAS_NORMALS) || m->triangle_count == 0 || m->vertex_count == 0) return l;
    size_t v = m->vertex_count, t = m->triangle_count, c = m->control_point_count;
    if (v > SIZE_MAX / 64 || t > SIZE_MAX / 64 || c > SIZE_MAX / 64) return l;
    size_t scratch = mk_smoothing_groups_scratch_size((uint32_t)c, (uint32_t)v);
    size_t rest = sizeof(group_sum) * v > scratch ? sizeof(group_sum) * v : scratch;
    l.group_of = align16(sizeof(topology_header));
    l.group_tri_first = l.group_of + align16(4 * v);
    l.group_tris = l.group_tri_first + align16(4 * (v + 1));
    l.tri_groups = l.group_tris + align16(12 * t);
    l.rest = l.tri_groups + align16(12 * t);
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

size_t mk_smoothing_groups_scratch_size(uint32_t key_count, uint32_t vertex_count)
{
    return 4 * (2 * (size_t)key_count + vertex_count + 1);
}

uint32_t mk_smoothing_groups(const uint32_t *keys, uint32_t key_count, const float *normals, uint32_t vertex_count,
                             uint32_t *group_of, void *scratch)
{
    /* Key -> its vertices (CSR, vertex order), then per key: a vertex joins the first earlier
     * vertex with its normal (without normals, the key's first vertex). */
    uint32_t *key_first = scratch, *key_verts = key_first + key_count + 1, *fill = key_verts + vertex_count;
    memset(key_first, 0, 4 * ((size_t)key_count + 1));
    for (uint32_t v = 0; v < vertex_count; v++) key_first[keys[v] + 1]++;
    for (uint32_t k = 0; k < key_count; k++) key_first[k + 1] += key_first[k];
    memcpy(fill, key_first, 4 * (size_t)key_count);
    for (uint32_t v = 0; v < vertex_count; v++) key_verts[fill[keys[v]]++] = v;
    uint32_t groups = 0;
    for (uint32_t k = 0; k < key_count; k++)
        for (uint32_t i = key_first[k]; i < key_first[k + 1]; i++) {
            uint32_t v = key_verts[i], found = UINT32_MAX;
            for (uint32_t j = key_first[k]; j < i && found == UINT32_MAX; j++)
                if (!normals || same_normal(&normals[3u * key_verts[j]], &normals[3u * v])) found = group_of[key_verts[j]];
            group_of[v] = found != UINT32_MAX ? found : groups++;
        }
    return groups;
}

/* Area-weighted face normal (cross product) of triangle tri at positions p (stride bytes). */
static void face_normal(const uint32_t *tri, const uint8_t *p, size_t stride, float out[3])
{
    const float *a = (const float *)(const void *)(p + stride * tri[0]);
    const float *b = (const float *)(const void *)(p + stride * tri[1]);
    const float *c = (const float *)(const void *)(p + stride * tri[2]);
    float e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    float e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* Adds the face normal of every triangle in [t_lo, t_hi) (those with mark[t], mark NULL: all) at
 * positions p to each of its distinct corner groups, in triangle order (docs/semantics.md), and
 * with vmoved (per vertex, may be NULL) marks a group moved when a corner of one of its
 * triangles moved. The one sum behind both N(P0) (the build) and N(P) (every job). */
static void add_face_normals(const uint32_t *triangles, const uint32_t *tri_groups, const uint8_t *mark, uint32_t t_lo,
                             uint32_t t_hi, const uint8_t *p, size_t stride, const uint8_t *vmoved, group_sum *sums)
{
    for (uint32_t t = t_lo; t < t_hi; t++) {
        if (mark && !mark[t]) continue;
        const uint32_t *tri = &triangles[3u * t], *g = &tri_groups[3u * t];
        float f[3];
        face_normal(tri, p, stride, f);
        uint32_t moved_corners = vmoved ? (uint32_t)vmoved[tri[0]] + vmoved[tri[1]] + vmoved[tri[2]] : 0;
        for (int c = 0; c < 3; c++)
            if (g[c] != NO_GROUP) {
                group_sum *gs = &sums[g[c]];
                gs->normal[0] += f[0]; gs->normal[1] += f[1]; gs->normal[2] += f[2]; gs->moved |= moved_corners != 0;
            }
    }
}

/* N: a group's summed face normals, normalized; the fallback where the sum is zero. */
static void normalize_sum(const float sum[3], const float fallback[3], float out[3])
{
    float len = sqrtf(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    if (len > 0) {
        float inv = 1.0f / len;
        for (int d = 0; d < 3; d++) out[d] = sum[d] * inv;
    } else {
        for (int d = 0; d < 3; d++) out[d] = fallback[d];
    }
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
    uint32_t *tri_groups = (uint32_t *)(void *)(base + l.tri_groups);
    /* The groups, with the rest-normal region as scratch; then a fill cursor there. */
    uint32_t *fill = (uint32_t *)(void *)(base + l.rest);
    uint32_t groups = mk_smoothing_groups(cp, cps, normals, n, group_of, fill);
    /* Triangle -> its distinct corner groups (NO_GROUP for a repeated one), and the inverse:
     * group -> its triangles in triangle order (CSR, counted first). */
    memset(tri_first, 0, 4 * ((size_t)groups + 1));
    for (uint32_t t = 0; t < tri_count; t++) {
        uint32_t g0 = group_of[triangles[3u * t]], g1 = group_of[triangles[3u * t + 1]], g2 = group_of[triangles[3u * t + 2]];
        uint32_t *g = &tri_groups[3u * t];
        g[0] = g0;
        g[1] = g1 != g0 ? g1 : NO_GROUP;
        g[2] = g2 != g0 && g2 != g1 ? g2 : NO_GROUP;
        for (int c = 0; c < 3; c++)
            if (g[c] != NO_GROUP) tri_first[g[c] + 1]++;
    }
    for (uint32_t g = 0; g < groups; g++) tri_first[g + 1] += tri_first[g];
    memcpy(fill, tri_first, 4 * (size_t)groups);
    for (uint32_t t = 0; t < tri_count; t++)
        for (int c = 0; c < 3; c++)
            if (tri_groups[3u * t + c] != NO_GROUP) group_tris[fill[tri_groups[3u * t + c]]++] = t;
    /* Rest normals N(P0) by the jobs' own sum (the scratch is no longer needed); (0,0,0) for a
     * group without area, whose vertices then take their own base normal as the rest normal. */
    group_sum *rest = (group_sum *)(void *)(base + l.rest);
    static const float none[3] = { 0, 0, 0 };
    memset(rest, 0, sizeof(group_sum) * (size_t)groups);
    add_face_normals(triangles, tri_groups, NULL, 0, tri_count, asset->data + m->positions, 12, NULL, rest);
    for (uint32_t g = 0; g < groups; g++) normalize_sum(rest[g].normal, none, rest[g].normal);
    topology_header h = { .magic = TOPOLOGY_MAGIC, .mesh = mesh, .vertex_count = n, .triangle_count = tri_count,
                          .group_count = groups, .size = l.size, .checksum = asset->header->checksum,
                          .group_of = l.group_of, .group_tri_first = l.group_tri_first, .group_tris = l.group_tris,
                          .tri_groups = l.tri_groups, .rest = l.rest };
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

/* A job's scratch: one mark byte per triangle (whether the job needs it), one per vertex
 * (whether it moved), then one
 * accumulator per possible group (the sum of its face normals at the evaluated positions and
 * whether a corner of its triangles moved). A job fills what it reads, so the scratch needs no
 * initialization and any job may use any scratch. */

static size_t marks_size(const mk_blob_mesh *m) { return align16(m->triangle_count) + align16(m->vertex_count); }

size_t mk_surface_scratch_size(const mk_asset *asset, uint32_t mesh)
{
    if (!mk_surface_topology_size(asset, mesh)) return 0;
    const mk_blob_mesh *m = &asset->meshes[mesh];
    return marks_size(m) + sizeof(group_sum) * (size_t)m->vertex_count;
}

/* Whether vertices [lo, hi) are not where they rest (-0 and +0 are the same place). */
static void vertices_moved(uint8_t *moved, uint32_t lo, uint32_t hi, const uint8_t *p, size_t stride, const float *p0)
{
    for (uint32_t v = lo; v < hi; v++) {
        const float *q = (const float *)(const void *)(p + stride * v);
        const float *o = &p0[3u * v];
        moved[v] = (uint8_t)((q[0] != o[0]) | (q[1] != o[1]) | (q[2] != o[2]));
    }
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
    const uint32_t *tri_groups = (const uint32_t *)(const void *)(base + h.tri_groups);
    const group_sum *rest = (const group_sum *)(const void *)(base + h.rest);
    const uint32_t *triangles = (const uint32_t *)(const void *)(a->data + m->triangles);
    const float *p0 = (const float *)(const void *)(a->data + m->positions);
    const float *normals = (const float *)(const void *)(a->data + m->normals);
    const float *tangents = m->tangents ? (const float *)(const void *)(a->data + m->tangents) : NULL;
    const uint8_t *p = (const uint8_t *)job->positions;
    const size_t ps = mk_stride_or(job->positions_stride, 12), ns = mk_stride_or(job->normals_stride, 12),
                 ts = mk_stride_or(job->tangents_stride, 16);
    uint8_t *mark = job->scratch, *vmoved = mark + align16(m->triangle_count);
    group_sum *sums = (group_sum *)(void *)((uint8_t *)job->scratch + marks_size(m));
    const uint32_t n = job->vertex_count == MK_VERTICES_TO_END ? m->vertex_count - job->first_vertex : job->vertex_count;
    const uint32_t tri_count = m->triangle_count;
    /* The triangles the range needs: those with a corner in a group of one of its vertices
     * (all of them for the whole mesh), in [t_lo, t_hi). */
    uint32_t t_lo = 0, t_hi = tri_count, v_lo = 0, v_hi = m->vertex_count;
    const int whole = n == m->vertex_count;   /* every triangle: no marks needed */
    if (whole) {
        memset(sums, 0, sizeof(group_sum) * (size_t)h.group_count);
    } else {
        memset(mark, 0, tri_count);
        t_lo = tri_count; t_hi = 0;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t g = group_of[job->first_vertex + i];
            memset(&sums[g], 0, sizeof(group_sum));   /* a group without triangles stays unmoved */
            for (uint32_t k = tri_first[g]; k < tri_first[g + 1]; k++) {
                uint32_t t = group_tris[k];
                mark[t] = 1;
                if (t < t_lo) t_lo = t;
                if (t + 1 > t_hi) t_hi = t + 1;
            }
        }
        v_lo = m->vertex_count; v_hi = 0;
        for (uint32_t t = t_lo; t < t_hi; t++)
            if (mark[t])
                for (int c = 0; c < 3; c++) {
                    uint32_t v = triangles[3u * t + c];
                    if (tri_groups[3u * t + c] != NO_GROUP) memset(&sums[tri_groups[3u * t + c]], 0, sizeof(group_sum));
                    if (v < v_lo) v_lo = v;
                    if (v + 1 > v_hi) v_hi = v + 1;
                }
    }
    vertices_moved(vmoved, v_lo, v_hi, p, ps, p0);
    add_face_normals(triangles, tri_groups, whole ? NULL : mark, t_lo, t_hi, p, ps, vmoved, sums);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t v = job->first_vertex + i, g = group_of[v];
        const float *b = &normals[3u * v];
        /* Moved: a corner of one of the group's triangles is not where it rests. Unmoved groups
         * keep their base normal. */
        uint32_t moved = sums[g].moved;
        float out[3] = { b[0], b[1], b[2] };
        if (moved) {
            float now[3], d[3];
            normalize_sum(sums[g].normal, b, now);
            const float *r0 = rest[g].normal;
            int flat = r0[0] == 0 && r0[1] == 0 && r0[2] == 0;
            for (int c = 0; c < 3; c++) d[c] = flat ? now[c] : b[c] + (now[c] - r0[c]);
            float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (len > 1e-8f) {
                float inv = 1.0f / len;
                for (int c = 0; c < 3; c++) out[c] = d[c] * inv;
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

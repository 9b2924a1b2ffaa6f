/* SPDX-License-Identifier: MIT */
/* Surface normals: normals recomputed from evaluated positions (docs/semantics.md, "Surface
 * normals"; the API in morphkit.h).
 *
 * The topology, built once per mesh into caller memory, holds the smoothing groups (vertices
 * with the same control point and the same base normal within 1e-5 per component), each
 * group's triangles (a triangle once per distinct corner group, in triangle order), each
 * triangle's distinct corner groups and each group's rest normal. The rules and the order of
 * every sum are those of the offline importer's target normals (which sums in double
 * precision; here single precision keeps the per-frame pass small), so a single target at its
 * full weight reproduces the normal deltas the importer computed for it up to float rounding.
 * A job walks the triangles it needs in order, adds each one's face normal to the sums of its
 * distinct corner groups (so every group's sum is formed in its triangle order, the order the
 * importer sums in), then finishes sixteen vertices at a time in lanes without branches,
 * compiled per ISA level (clones.h). A vertex's normal depends only on the positions and the
 * topology, never on the job's range. */
#include <float.h>
#include <math.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"
#include "error.h"
#include "span.h"
#include "clones.h"
#include "determinism.h"

#define TOPOLOGY_MAGIC 0x33534b4du /* "MKS3" */
#define NO_GROUP UINT32_MAX

typedef struct topology_header {
    uint32_t magic, mesh;
    uint32_t vertex_count, triangle_count, group_count, reserved;
    uint64_t size;                 /* bytes the topology was built for */
    uint64_t checksum;             /* the blob's, to refuse another asset's topology */
    uint64_t group_of, group_tri_first, group_tris, corners, rest; /* array offsets */
} topology_header;

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

typedef struct layout {
    size_t group_of, group_tri_first, group_tris, corners, rest, size;
} layout;

/* Offsets of the arrays; size 0 when the mesh cannot have a topology (no normals, no
 * triangles, or too large for 32-bit indices into its per-corner and per-vertex arrays: more
 * than 1,431,655,765 triangles or 1,073,741,823 vertices). The rest normals are three floats per
 * group; their region first serves as the build's scratch. */
static layout topology_layout(const mk_blob_mesh *m)
{
    layout l = { 0, 0, 0, 0, 0, 0 };
    if (!(m->flags & MK_MESH_HAS_NORMALS) || m->triangle_count == 0 || m->vertex_count == 0) return l;
    size_t v = m->vertex_count, t = m->triangle_count, c = m->control_point_count;
    if (3 * (uint64_t)t > UINT32_MAX || 4 * (uint64_t)v > UINT32_MAX || v > SIZE_MAX / 64 || t > SIZE_MAX / 64
        || c > SIZE_MAX / 64)
        return l;
    size_t scratch = mk_smoothing_groups_scratch_size((uint32_t)c, (uint32_t)v);
    size_t rest = 12 * v > scratch ? 12 * v : scratch;
    l.group_of = align16(sizeof(topology_header));
    l.group_tri_first = l.group_of + align16(4 * v);
    l.group_tris = l.group_tri_first + align16(4 * (v + 1));
    l.corners = l.group_tris + align16(12 * t);
    l.rest = l.corners + align16(12 * t);
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

/* The distinct corner groups of triangle t, NO_GROUP for a repeated one. */
static void corner_groups(const uint32_t *triangles, const uint32_t *group_of, uint32_t t, uint32_t g[3])
{
    g[0] = group_of[triangles[3u * t]];
    g[1] = group_of[triangles[3u * t + 1]];
    g[2] = group_of[triangles[3u * t + 2]];
    if (g[1] == g[0]) g[1] = NO_GROUP;
    if (g[2] == g[0] || g[2] == g[1]) g[2] = NO_GROUP;
}

/* Each group's sum of the face normals of its triangles, in triangle order, into sums[group]:
 * the triangles [t_lo, t_hi) (only those marked, when mark is not NULL) add their face normal at
 * positions p to the sums of their distinct corner groups (corners: three per triangle,
 * NO_GROUP for a repeated one), in order. The sums the triangles touch start at zero (all
 * group_count of them without marks), so sums needs no initialization; a group gets its whole
 * sum when all its triangles are in the walk (a range job marks every triangle of its
 * vertices' groups). The build's rest normals and a job's normals are the same sums, at P0 and
 * at P. */
static void group_sums(const uint32_t *triangles, const uint32_t *corners, uint32_t group_count, uint32_t t_lo,
                       uint32_t t_hi, const uint8_t *mark, const uint8_t *p, size_t stride, float (*sums)[3])
{
    if (!mark) memset(sums, 0, 12 * (size_t)group_count);
    else
        for (uint32_t t = t_lo; t < t_hi; t++)
            if (mark[t]) {
                const uint32_t *g = &corners[3u * t];
                for (int c = 0; c < 3; c++)
                    if (g[c] != NO_GROUP) sums[g[c]][0] = sums[g[c]][1] = sums[g[c]][2] = 0;
            }
    for (uint32_t t = t_lo; t < t_hi; t++)
        if (!mark || mark[t]) {
            float f[3];
            const uint32_t *g = &corners[3u * t];
            face_normal(&triangles[3u * t], p, stride, f);
            for (int c = 0; c < 3; c++)
                if (g[c] != NO_GROUP)
                    for (int d = 0; d < 3; d++) sums[g[c]][d] += f[d];
        }
}

mk_result mk_surface_topology_build(const mk_asset *asset, uint32_t mesh, void *topology, size_t size, mk_error *err)
{
    if (!asset || mesh >= asset->mesh_count)
        return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "surface topology: mesh index out of range");
    const mk_blob_mesh *m = &asset->meshes[mesh];
    layout l = topology_layout(m);
    if (!l.size)
        return mk_error_fail(err, MK_ERROR_UNSUPPORTED, MK_NO_OFFSET, "surface topology: the mesh has no normals or no triangles, or more than 1,431,655,765 triangles or 1,073,741,823 vertices");
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
    /* The groups, with the rest-normal region as scratch; then a cursor there. */
    uint32_t *fill = (uint32_t *)(void *)(base + l.rest);
    uint32_t groups = mk_smoothing_groups(cp, cps, normals, n, group_of, fill);
    /* Renumbered in the order of their first vertex, so that a job, which walks vertices in
     * order, reads the groups' arrays nearly in order too (a private numbering: a group's sum
     * is in triangle order whatever its number). */
    for (uint32_t g = 0; g < groups; g++) fill[g] = NO_GROUP;
    for (uint32_t v = 0, next = 0; v < n; v++) {
        if (fill[group_of[v]] == NO_GROUP) fill[group_of[v]] = next++;
        group_of[v] = fill[group_of[v]];
    }
    /* Group -> its triangles in triangle order (CSR, counted first). */
    memset(tri_first, 0, 4 * ((size_t)groups + 1));
    for (uint32_t t = 0; t < tri_count; t++) {
        uint32_t g[3];
        corner_groups(triangles, group_of, t, g);
        for (int c = 0; c < 3; c++)
            if (g[c] != NO_GROUP) tri_first[g[c] + 1]++;
    }
    for (uint32_t g = 0; g < groups; g++) tri_first[g + 1] += tri_first[g];
    memcpy(fill, tri_first, 4 * (size_t)groups);
    for (uint32_t t = 0; t < tri_count; t++) {
        uint32_t g[3];
        corner_groups(triangles, group_of, t, g);
        for (int c = 0; c < 3; c++)
            if (g[c] != NO_GROUP) group_tris[fill[g[c]]++] = t;
    }
    /* Rest normals N(P0) by the jobs' own sum (the scratch is no longer needed); (0,0,0) for a
     * group without area, whose vertices then take their own base normal as the rest normal. */
    uint32_t *corners = (uint32_t *)(void *)(base + l.corners);
    for (uint32_t t = 0; t < tri_count; t++) corner_groups(triangles, group_of, t, &corners[3u * t]);
    float (*rest)[3] = (float (*)[3])(void *)(base + l.rest);
    group_sums(triangles, corners, groups, 0, tri_count, NULL, asset->data + m->positions, 12, rest);
    for (uint32_t g = 0; g < groups; g++) {
        float *sum = rest[g];
        float len = sqrtf(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
        for (int c = 0; c < 3; c++) sum[c] = len > 0 && len <= FLT_MAX ? sum[c] * (1.0f / len) : 0;
    }
    topology_header h = { .magic = TOPOLOGY_MAGIC, .mesh = mesh, .vertex_count = n, .triangle_count = tri_count,
                          .group_count = groups, .size = l.size, .checksum = asset->header->checksum,
                          .group_of = l.group_of, .group_tri_first = l.group_tri_first, .group_tris = l.group_tris, .corners = l.corners,
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
        || h.group_count > m->vertex_count || job->topology_size < l.size)
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

/* A job's scratch: one mark byte per triangle (whether a range job needs it), then the sums of
 * the groups (at most one per vertex). A job fills what it reads, so the scratch needs no
 * initialization and any job may use any scratch. */

static size_t marks_size(const mk_blob_mesh *m) { return align16(m->triangle_count); }

size_t mk_surface_scratch_size(const mk_asset *asset, uint32_t mesh)
{
    if (!mk_surface_topology_size(asset, mesh)) return 0;
    const mk_blob_mesh *m = &asset->meshes[mesh];
    return marks_size(m) + 12 * (size_t)m->vertex_count;
}

/* Vertices are finished FINISH_BLOCK at a time in lanes (component-major): every operation is
 * done in every lane and only the choices between computed values depend on the data, so the
 * compiler can use vector instructions (with -fno-math-errno, which the build adds: otherwise a
 * square root may set errno, a branch that keeps the loop scalar); the same IEEE operations per
 * lane, so the same bytes as one vertex at a time. */
#define FINISH_BLOCK 16
typedef struct finish_block {
    float sum[3][FINISH_BLOCK], base[3][FINISH_BLOCK], rest[3][FINISH_BLOCK], out[3][FINISH_BLOCK];
    float changed[FINISH_BLOCK];
} finish_block;

/* Per lane, with sum the group's face normals at P, base B_n and rest N(P0) (zero for a group
 * without area at rest): N(P) is the normalized sum (B_n where its length is zero or not
 * finite), and for a group without area at rest N(P0) is B_n. Where N(P) differs from N(P0)
 * the normal is d / |d| with d = B_n + (N(P) - N(P0)) (d = N(P) for a group without area at
 * rest), B_n unless |d| > 1e-8; where they are equal it is B_n and changed is 0. A divisor is
 * offset by exactly 1 where its quotient is not used, so nothing divides by zero and no
 * non-finite value is chosen.
 *
 * GCC by default moves a floating-point operation whose only use is one side of a choice into
 * that side (it could trap), which keeps the loop from vector instructions; for this function
 * only, that is turned off. The result is the same (clang does this by default). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize("no-trapping-math")
#endif
MK_INLINE void finish_normals(finish_block *k)
{
    for (int j = 0; j < FINISH_BLOCK; j++) {
        float sx = k->sum[0][j], sy = k->sum[1][j], sz = k->sum[2][j];
        float bx = k->base[0][j], by = k->base[1][j], bz = k->base[2][j];
        float rx = k->rest[0][j], ry = k->rest[1][j], rz = k->rest[2][j];
        float len = sqrtf(sx * sx + sy * sy + sz * sz);
        float none = !(len > 0) | !(len <= FLT_MAX);
        float inv = 1.0f / (len + none);
        float ax = sx * inv, ay = sy * inv, az = sz * inv;
        float nx = none != 0 ? bx : ax, ny = none != 0 ? by : ay, nz = none != 0 ? bz : az;
        float flat = (rx == 0) & (ry == 0) & (rz == 0);
        float wx = flat != 0 ? bx : rx, wy = flat != 0 ? by : ry, wz = flat != 0 ? bz : rz;
        float changed = (nx != wx) | (ny != wy) | (nz != wz);
        float ex = bx + (nx - rx), ey = by + (ny - ry), ez = bz + (nz - rz);
        float dx = flat != 0 ? nx : ex, dy = flat != 0 ? ny : ey, dz = flat != 0 ? nz : ez;
        float dlen = sqrtf(dx * dx + dy * dy + dz * dz);
        float keep = (changed == 0) | !(dlen > 1e-8f);
        float dinv = 1.0f / (dlen + keep);
        float ox = dx * dinv, oy = dy * dinv, oz = dz * dinv;
        k->out[0][j] = keep != 0 ? bx : ox;
        k->out[1][j] = keep != 0 ? by : oy;
        k->out[2][j] = keep != 0 ? bz : oz;
        k->changed[j] = changed;
    }
}
/* The job's vertices [0, n): each one's normal (and tangent) from its group's sum, FINISH_BLOCK
 * at a time. */
static MK_CLONES void finish_range(const mk_surface_job *job, uint32_t n, const uint32_t *group_of,
                                   const float (*sums)[3], const float (*rest)[3], const float *normals,
                                   const float *tangents, size_t ns, size_t ts)
{
    for (uint32_t i0 = 0; i0 < n; i0 += FINISH_BLOCK) {
        const uint32_t count = n - i0 < FINISH_BLOCK ? n - i0 : FINISH_BLOCK;
        finish_block block;
        for (uint32_t j = 0; j < FINISH_BLOCK; j++) {   /* lanes past the range repeat the block's first vertex */
            uint32_t v = job->first_vertex + i0 + (j < count ? j : 0), g = group_of[v];
            for (int c = 0; c < 3; c++) {
                block.sum[c][j] = sums[g][c];
                block.base[c][j] = normals[3u * v + (uint32_t)c];
                block.rest[c][j] = rest[g][c];
            }
        }
        finish_normals(&block);
        for (uint32_t j = 0; j < count; j++) {
            const uint32_t i = i0 + j, v = job->first_vertex + i;
            const float out[3] = { block.out[0][j], block.out[1][j], block.out[2][j] };
            memcpy((uint8_t *)job->normals + ns * i, out, sizeof out);
            if (job->tangents) {
                float t[4];
                memcpy(t, &tangents[4u * v], sizeof t);
                if (block.changed[j] != 0) {
                    float dot = t[0] * out[0] + t[1] * out[1] + t[2] * out[2];
                    float o[3] = { t[0] - out[0] * dot, t[1] - out[1] * dot, t[2] - out[2] * dot };
                    float len = sqrtf(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
                    if (len >= 1e-12f)
                        for (int d = 0; d < 3; d++) t[d] = o[d] / len;
                }
                memcpy((uint8_t *)job->tangents + ts * i, t, sizeof t);
            }
        }
    }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif

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
    const float (*rest)[3] = (const float (*)[3])(const void *)(base + h.rest);
    const uint32_t *corners = (const uint32_t *)(const void *)(base + h.corners);
    const uint32_t *triangles = (const uint32_t *)(const void *)(a->data + m->triangles);
    const float *normals = (const float *)(const void *)(a->data + m->normals);
    const float *tangents = m->tangents ? (const float *)(const void *)(a->data + m->tangents) : NULL;
    const uint8_t *p = (const uint8_t *)job->positions;
    const size_t ps = mk_stride_or(job->positions_stride, 12), ns = mk_stride_or(job->normals_stride, 12),
                 ts = mk_stride_or(job->tangents_stride, 16);
    uint8_t *mark = job->scratch;
    float (*sums)[3] = (float (*)[3])(void *)((uint8_t *)job->scratch + marks_size(m));
    const uint32_t n = job->vertex_count == MK_VERTICES_TO_END ? m->vertex_count - job->first_vertex : job->vertex_count;
    /* The sums the range needs: those of its vertices' groups, from the triangles of those groups
     * (every triangle for the whole mesh, which needs no marks). */
    if (n == m->vertex_count) {
        group_sums(triangles, corners, h.group_count, 0, m->triangle_count, NULL, p, ps, sums);
    } else {
        uint32_t t_lo = m->triangle_count, t_hi = 0;
        memset(mark, 0, m->triangle_count);
        for (uint32_t i = 0; i < n; i++) {
            uint32_t g = group_of[job->first_vertex + i];
            sums[g][0] = sums[g][1] = sums[g][2] = 0;   /* a group without triangles sums to zero too */
            for (uint32_t k = tri_first[g]; k < tri_first[g + 1]; k++) {
                uint32_t t = group_tris[k];
                mark[t] = 1;
                if (t < t_lo) t_lo = t;
                if (t + 1 > t_hi) t_hi = t + 1;
            }
        }
        group_sums(triangles, corners, h.group_count, t_lo, t_hi, mark, p, ps, sums);
    }
    finish_range(job, n, group_of, (const float (*)[3])sums, rest, normals, tangents, ns, ts);
    return MK_OK;
}

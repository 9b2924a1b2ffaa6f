/* SPDX-License-Identifier: MIT */
/* The shell's rest state: the position-welded mesh (which must be closed and enclose a positive
 * volume), each triangle's 2D rest frame, Dm^-1 and area, the bending hinges of the interior
 * edges with their cotangent stencil, lumped masses; and the enclosed volume with its gradient. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "shell.h"
#include "bake_util.h"
#include "mesh_groups.h"

typedef struct half_edge {
    uint32_t lo, hi;      /* vertices, lo < hi */
    uint32_t tri;
    uint32_t opposite;    /* the triangle's third vertex */
    uint32_t forward;     /* 1: the triangle runs lo -> hi */
} half_edge;

static int compare_half_edges(const void *pa, const void *pb)
{
    const half_edge *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    if (a->tri != b->tri) return a->tri < b->tri ? -1 : 1;
    return 0;
}

static double cot_angle(const double v[3], const double w[3])
{
    double c[3];
    vec3_cross(c, v, w);
    return vec3_dot(v, w) / vec3_length(c);
}

double shell_volume(const shell_mesh *m, const double *x, double *grad)
{
    double v = 0;
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *tri = m->tris + 3 * (size_t)t;
        const double *a = x + 3 * (size_t)tri[0], *b = x + 3 * (size_t)tri[1], *c = x + 3 * (size_t)tri[2];
        double bc[3];
        vec3_cross(bc, b, c);
        v += vec3_dot(a, bc);
    }
    if (grad) shell_volume_gradient(m, x, grad, 0, m->n);
    return v / 6;
}

void shell_volume_gradient(const shell_mesh *m, const double *x, double *grad, uint32_t first, uint32_t last)
{
    /* d(a . (b x c))/da = b x c, and cyclically: corner k's term is the cross product of the
     * next corner and the one after. */
    for (uint32_t v = first; v < last; v++) {
        double g[3] = { 0, 0, 0 };
        for (uint32_t i = m->corner_start[v]; i < m->corner_start[v + 1]; i++) {
            const uint32_t t = m->corners[i] / 3, k = m->corners[i] % 3, *tri = m->tris + 3 * (size_t)t;
            double term[3];
            vec3_cross(term, x + 3 * (size_t)tri[(k + 1) % 3], x + 3 * (size_t)tri[(k + 2) % 3]);
            for (int c = 0; c < 3; c++) g[c] += term[c] / 6;
        }
        for (int c = 0; c < 3; c++) grad[3 * (size_t)v + c] = g[c];
    }
}

void shell_vertex_normals(const shell_mesh *m, const double *x, double *normals)
{
    memset(normals, 0, 3 * (size_t)m->n * sizeof(double));
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *tri = m->tris + 3 * (size_t)t;
        double n[3];
        mk_triangle_normal(x + 3 * (size_t)tri[0], x + 3 * (size_t)tri[1], x + 3 * (size_t)tri[2], n);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) normals[3 * (size_t)tri[k] + c] += n[c];
    }
    for (uint32_t v = 0; v < m->n; v++) vec3_normalize(normals + 3 * (size_t)v);
}

mk_result shell_mesh_build(const mk_raw_mesh *mesh, double density, mk_arena *arena, shell_mesh *m, mk_error *err)
{
    memset(m, 0, sizeof *m);
    if (mesh->triangle_count < 4)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "the mesh is not closed (%u triangles)",
                            mesh->triangle_count);
    if (mesh->triangle_count > UINT32_MAX / 3)   /* corners are numbered 3 t + k in 32 bits */
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "the mesh has too many triangles for a shell (%u)",
                            mesh->triangle_count);
    m->weld = mk_mesh_weld(mesh, arena, &m->n);
    if (!m->weld) return mk_error_oom(err, "shell mesh");
    uint32_t nt = mesh->triangle_count;
    m->tri_count = nt;
    m->tris = mk_arena_array(arena, 3 * (size_t)nt, sizeof(uint32_t));
    m->rest = mk_arena_array(arena, 3 * (size_t)m->n, sizeof(double));
    m->Dm_inv = mk_arena_array(arena, 4 * (size_t)nt, sizeof(double));
    m->basis = mk_arena_array(arena, 6 * (size_t)nt, sizeof(double));
    m->area = mk_arena_array(arena, nt, sizeof(double));
    m->inv_mass = mk_arena_array(arena, m->n, sizeof(double));
    half_edge *he = mk_arena_array(arena, 3 * (size_t)nt, sizeof(half_edge));
    if (!m->tris || !m->rest || !m->Dm_inv || !m->basis || !m->area || !m->inv_mass || !he)
        return mk_error_oom(err, "shell mesh");
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        for (int c = 0; c < 3; c++) m->rest[3 * (size_t)m->weld[v] + c] = mesh->positions[3 * (size_t)v + c];
    for (uint32_t t = 0; t < nt; t++) {
        uint32_t *tri = m->tris + 3 * (size_t)t;
        for (int k = 0; k < 3; k++) tri[k] = m->weld[mesh->triangles[3 * (size_t)t + k]];
        const double *x0 = m->rest + 3 * (size_t)tri[0], *x1 = m->rest + 3 * (size_t)tri[1], *x2 = m->rest + 3 * (size_t)tri[2];
        double d1[3], d2[3], n[3];
        vec3_sub(d1, x1, x0);
        vec3_sub(d2, x2, x0);
        mk_triangle_normal(x0, x1, x2, n);
        double twice = vec3_normalize(n), l1 = vec3_length(d1);
        if (!(twice > 1e-12 * l1 * l1) || tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "triangle %u is degenerate (zero area)", t);
        double *e1 = m->basis + 6 * (size_t)t, *e2 = e1 + 3;
        for (int c = 0; c < 3; c++) e1[c] = d1[c] / l1;
        vec3_cross(e2, n, e1);
        double Dm[4] = { vec3_dot(d1, e1), vec3_dot(d2, e1), vec3_dot(d1, e2), vec3_dot(d2, e2) };
        double det = Dm[0] * Dm[3] - Dm[1] * Dm[2];
        double *inv = m->Dm_inv + 4 * (size_t)t;
        inv[0] = Dm[3] / det; inv[1] = -Dm[1] / det; inv[2] = -Dm[2] / det; inv[3] = Dm[0] / det;
        m->area[t] = 0.5 * twice;
        for (int k = 0; k < 3; k++) {
            uint32_t a = tri[k], b = tri[(k + 1) % 3];
            he[3 * (size_t)t + k] = (half_edge){ a < b ? a : b, a < b ? b : a, t, tri[(k + 2) % 3], a < b };
            m->inv_mass[a] += density * m->area[t] / 3;
        }
    }
    for (uint32_t v = 0; v < m->n; v++) {
        if (!(m->inv_mass[v] > 0))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "vertex %u is used by no triangle (the shell must be one closed surface)", v);
        m->inv_mass[v] = 1 / m->inv_mass[v];
    }
    /* Every vertex's corners, in triangle order. */
    if (!mk_csr_build(arena, m->tris, 3 * nt, m->n, &m->corner_start, &m->corners)) return mk_error_oom(err, "shell mesh");
    /* Closed and consistently oriented: every edge twice, once in each direction. */
    qsort(he, 3 * (size_t)nt, sizeof *he, compare_half_edges);
    size_t edges = 3 * (size_t)nt / 2;
    m->hinges = mk_arena_array(arena, 4 * edges, sizeof(uint32_t));
    m->hinge_K = mk_arena_array(arena, 4 * edges, sizeof(double));
    m->hinge_scale = mk_arena_array(arena, edges, sizeof(double));
    m->hinge_rest = mk_arena_array(arena, edges, sizeof(double));
    m->hinge_tri = mk_arena_array(arena, edges, sizeof(uint32_t));
    if (!m->hinges || !m->hinge_K || !m->hinge_scale || !m->hinge_rest || !m->hinge_tri) return mk_error_oom(err, "shell hinges");
    for (size_t i = 0; i < 3 * (size_t)nt;) {
        size_t j = i;
        while (j < 3 * (size_t)nt && he[j].lo == he[i].lo && he[j].hi == he[i].hi) j++;
        if (j - i != 2 || he[i].forward == he[i + 1].forward)
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "the mesh is not a closed, consistently oriented surface: edge %u-%u is used by %zu triangle(s)%s "
                                "(welded vertices)", he[i].lo, he[i].hi, j - i,
                                j - i == 2 ? " in the same direction" : "");
        uint32_t h = m->hinge_count++;
        uint32_t *q = m->hinges + 4 * (size_t)h;
        q[0] = he[i].lo; q[1] = he[i].hi; q[2] = he[i].opposite; q[3] = he[i + 1].opposite;
        m->hinge_tri[h] = he[i].tri;
        const double *x0 = m->rest + 3 * (size_t)q[0], *x1 = m->rest + 3 * (size_t)q[1];
        const double *x2 = m->rest + 3 * (size_t)q[2], *x3 = m->rest + 3 * (size_t)q[3];
        double e0[3], e1[3], e2[3], e3[3], e4[3], me0[3];
        vec3_sub(e0, x1, x0); vec3_sub(e1, x2, x0); vec3_sub(e2, x3, x0);
        vec3_sub(e3, x2, x1); vec3_sub(e4, x3, x1);
        for (int c = 0; c < 3; c++) me0[c] = -e0[c];
        double c01 = cot_angle(e0, e1), c02 = cot_angle(e0, e2), c03 = cot_angle(me0, e3), c04 = cot_angle(me0, e4);
        double *K = m->hinge_K + 4 * (size_t)h;
        K[0] = c03 + c04; K[1] = c01 + c02; K[2] = -c01 - c03; K[3] = -c02 - c04;
        m->hinge_scale[h] = 3 / (m->area[he[i].tri] + m->area[he[i + 1].tri]);
        double v[3] = { 0, 0, 0 };
        const double *x[4] = { x0, x1, x2, x3 };
        for (int k = 0; k < 4; k++)
            for (int c = 0; c < 3; c++) v[c] += K[k] * x[k][c];
        m->hinge_rest[h] = vec3_length(v);
        i = j;
    }
    m->volume0 = shell_volume(m, m->rest, NULL);
    if (!(m->volume0 > 0))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "the mesh encloses no positive volume (%g): its triangles must face outwards", m->volume0);
    return MK_OK;
}

/* SPDX-License-Identifier: MIT */
/* Cage deformation by mean value coordinates of a closed triangle cage.
 *
 * Paper: T. Ju, S. Schaefer, J. Warren, "Mean Value Coordinates for Closed Triangular Meshes",
 * SIGGRAPH 2005 -- the robust evaluation (their Figure 4 pseudo-code), including
 * - x on a cage vertex: lambda = e_j (within eps_d);
 * - x on a cage triangle (pi - h < eps): 2D barycentric coordinates on that triangle, with
 *   w_i = sin(theta_i) d_{i-1} d_{i+1} -- distances d, not chord lengths (the QMVC reference
 *   code uses chord lengths there, which is wrong);
 * - x coplanar with a triangle but outside it (|s_i| <= eps): that triangle is skipped.
 * Angles use theta = 2 asin(|u_a - u_b| / 2), which stays accurate for small and near-pi
 * angles where acos(dot) does not.
 *
 * Conventions fixed here:
 * - The cage must be closed and consistently oriented (either way: reversing every triangle
 *   flips every raw weight and leaves the normalized coordinates unchanged).
 * - Deformed points: x' = x + a * sum_j lambda_j (p'_j - p_j). By linear precision this equals
 *   sum_j lambda_j p'_j at a = 1, and it is exactly x at a = 0 and wherever the cage does not
 *   move. Linear in a: one target is exact.
 * - Normals are recomputed from the deformed surface (mk_raw_compute_target_normals).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cage_mvc.h"
#include "bake_util.h"
#include "blob_io.h"

#define PI 3.14159265358979323846

void mk_mvc_coordinates(const mk_cage *cage, const double x[3], double eps_d, double *w)
{
    uint32_t nv = cage->vertex_count;
    const double eps = 1e-10;
    double total = 0;
    for (uint32_t j = 0; j < nv; j++) w[j] = 0;
    /* d_j and u_j are computed per triangle corner (cheap, and avoids a scratch array). */
    for (uint32_t j = 0; j < nv; j++) {
        const double *p = cage->rest + 3 * (size_t)j;
        double d[3] = { p[0] - x[0], p[1] - x[1], p[2] - x[2] };
        if (vec3_length(d) < eps_d) { w[j] = 1; return; }
    }
    for (uint32_t t = 0; t < cage->triangle_count; t++) {
        const uint32_t *tri = cage->triangles + 3 * (size_t)t;
        double u[3][3], d[3], l[3], th[3], c[3], s[3];
        for (int i = 0; i < 3; i++) {
            const double *p = cage->rest + 3 * (size_t)tri[i];
            for (int k = 0; k < 3; k++) u[i][k] = p[k] - x[k];
            d[i] = vec3_normalize(u[i]);
        }
        for (int i = 0; i < 3; i++) {
            int a = (i + 1) % 3, b = (i + 2) % 3;
            double e[3] = { u[a][0] - u[b][0], u[a][1] - u[b][1], u[a][2] - u[b][2] };
            l[i] = vec3_length(e);
            th[i] = 2 * asin(fmin(1.0, l[i] / 2));
        }
        double h = (th[0] + th[1] + th[2]) / 2;
        if (PI - h < eps) {
            /* x lies on this triangle: barycentric coordinates (2 x sub-triangle areas). */
            double bw[3], sum = 0;
            for (int i = 0; i < 3; i++) {
                bw[i] = sin(th[i]) * d[(i + 2) % 3] * d[(i + 1) % 3];
                sum += bw[i];
            }
            for (uint32_t j = 0; j < nv; j++) w[j] = 0;
            for (int i = 0; i < 3; i++) w[tri[i]] += bw[i] / sum;
            return;
        }
        double det = u[0][0] * (u[1][1] * u[2][2] - u[1][2] * u[2][1]) -
                     u[0][1] * (u[1][0] * u[2][2] - u[1][2] * u[2][0]) +
                     u[0][2] * (u[1][0] * u[2][1] - u[1][1] * u[2][0]);
        double sign = det < 0 ? -1 : 1;
        int skip = 0;
        for (int i = 0; i < 3; i++) {
            int a = (i + 1) % 3, b = (i + 2) % 3;
            c[i] = 2 * sin(h) * sin(h - th[i]) / (sin(th[a]) * sin(th[b])) - 1;
            s[i] = sign * sqrt(fmax(0.0, 1 - c[i] * c[i]));
            if (fabs(s[i]) <= eps) skip = 1;
        }
        if (skip) continue;  /* x is in the triangle's plane but outside it: no contribution */
        for (int i = 0; i < 3; i++) {
            int a = (i + 1) % 3, b = (i + 2) % 3;
            double wi = (th[i] - c[a] * th[b] - c[b] * th[a]) / (d[i] * sin(th[a]) * s[b]);
            w[tri[i]] += wi;
            total += wi;
        }
    }
    if (fabs(total) > 1e-300)
        for (uint32_t j = 0; j < nv; j++) w[j] /= total;
}

typedef struct edge_rec { uint32_t a, b; } edge_rec;

static int edge_cmp(const void *pa, const void *pb)
{
    const edge_rec *x = pa, *y = pb;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    return x->b < y->b ? -1 : x->b > y->b;
}

mk_result mk_cage_validate(const mk_cage *cage, mk_error *err)
{
    if (cage->vertex_count < 4 || cage->triangle_count < 4)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "a closed cage needs at least 4 vertices and 4 triangles (has %u, %u)",
                            cage->vertex_count, cage->triangle_count);
    for (size_t i = 0; i < 3 * (size_t)cage->vertex_count; i++)
        if (!isfinite(cage->rest[i]) || !isfinite(cage->deformed[i]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "cage vertex %zu is not finite", i / 3);
    size_t ne = 3 * (size_t)cage->triangle_count;
    edge_rec *edges = malloc(ne * sizeof *edges);
    if (!edges) return mk_error_oom(err, "cage edges");
    double volume = 0;
    for (uint32_t t = 0; t < cage->triangle_count; t++) {
        const uint32_t *tri = cage->triangles + 3 * (size_t)t;
        for (int i = 0; i < 3; i++)
            if (tri[i] >= cage->vertex_count) {
                free(edges);
                return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                    "cage triangle %u: vertex index %u out of range", t, tri[i]);
            }
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
            free(edges);
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "cage triangle %u is degenerate", t);
        }
        for (int i = 0; i < 3; i++) {
            edges[3 * (size_t)t + i].a = tri[i];
            edges[3 * (size_t)t + i].b = tri[(i + 1) % 3];
        }
        const double *a = cage->rest + 3 * (size_t)tri[0], *b = cage->rest + 3 * (size_t)tri[1],
                     *c = cage->rest + 3 * (size_t)tri[2];
        double bc[3];
        vec3_cross(bc, b, c);
        volume += vec3_dot(a, bc) / 6;
    }
    qsort(edges, ne, sizeof *edges, edge_cmp);
    for (size_t i = 0; i < ne; i++) {
        if (i + 1 < ne && edges[i].a == edges[i + 1].a && edges[i].b == edges[i + 1].b) {
            mk_result r = mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                       "edge %u-%u is used twice in the same direction: the cage is "
                                       "not consistently oriented (or not manifold)", edges[i].a, edges[i].b);
            free(edges);
            return r;
        }
        edge_rec rev = { edges[i].b, edges[i].a };
        if (!bsearch(&rev, edges, ne, sizeof *edges, edge_cmp)) {
            mk_result r = mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                       "edge %u-%u has no opposite half-edge: the cage is not closed "
                                       "or not consistently oriented", edges[i].a, edges[i].b);
            free(edges);
            return r;
        }
    }
    free(edges);
    if (!(fabs(volume) > 0))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "the cage encloses no volume");
    return MK_OK;
}

struct mk_cage_binding {
    mk_arena arena;
    const mk_raw_mesh *mesh;
    uint32_t cage_vertices;
    double *weights;       /* vertex_count x cage_vertices */
    double *moves;         /* deformed - rest, 3 per cage vertex */
};

mk_result mk_cage_bind(const mk_raw_mesh *mesh, const mk_cage *cage, const mk_allocator *allocator,
                       mk_cage_binding **out, mk_error *err)
{
    *out = NULL;
    mk_arena arena;
    mk_arena_init(&arena, allocator);
    mk_cage_binding *b = mk_arena_alloc(&arena, sizeof *b);
    size_t n = mesh->vertex_count, m = cage->vertex_count;
    if (!b || (m && n > SIZE_MAX / 8 / m)) { mk_arena_free_all(&arena); return mk_error_oom(err, "cage binding"); }
    b->weights = mk_arena_array(&arena, (n && m) ? n * m : 1, sizeof(double));
    b->moves = mk_arena_array(&arena, 3 * m, sizeof(double));
    if (!b->weights || !b->moves) { mk_arena_free_all(&arena); return mk_error_oom(err, "cage binding"); }
    b->mesh = mesh;
    b->cage_vertices = cage->vertex_count;
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t j = 0; j < m; j++)
        for (int c = 0; c < 3; c++) {
            double v = cage->rest[3 * j + (size_t)c];
            if (v < lo[c]) lo[c] = v;
            if (v > hi[c]) hi[c] = v;
            b->moves[3 * j + (size_t)c] = cage->deformed[3 * j + (size_t)c] - v;
        }
    double diag[3] = { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] };
    double eps_d = 1e-8 * vec3_length(diag);
    for (size_t v = 0; v < n; v++) {
        const float *p = mesh->positions + 3 * v;
        double x[3] = { p[0], p[1], p[2] };
        mk_mvc_coordinates(cage, x, eps_d, b->weights + v * m);
    }
    b->arena = arena;
    *out = b;
    return MK_OK;
}

mk_result mk_cage_eval(void *binding, double amplitude, double *positions, double *normals,
                       double *tangents, uint32_t *inverted, mk_error *err)
{
    (void)normals; (void)tangents; (void)err;
    const mk_cage_binding *b = binding;
    size_t n = b->mesh->vertex_count, m = b->cage_vertices;
    for (size_t v = 0; v < n; v++) {
        const double *w = b->weights + v * m;
        double d[3] = { 0, 0, 0 };
        for (size_t j = 0; j < m; j++)
            for (int c = 0; c < 3; c++) d[c] += w[j] * b->moves[3 * j + (size_t)c];
        for (int c = 0; c < 3; c++)
            positions[3 * v + (size_t)c] = b->mesh->positions[3 * v + (size_t)c] + amplitude * d[c];
    }
    if (inverted) *inverted = 0;
    return MK_OK;
}

void mk_cage_unbind(mk_cage_binding *b)
{
    if (!b) return;
    mk_arena arena = b->arena;
    mk_arena_free_all(&arena);
}

/* SPDX-License-Identifier: MIT */
/* Deformation transfer, first step: align the source to the target from marker pairs, then match
 * every target triangle with a source triangle (transfer_internal.h, docs/baking.md).
 *
 * Conventions fixed here:
 * - The alignment is a similarity p' = s R p + t fitted to the markers by least squares: the
 *   rotation maximizes sum (q_i - mean q) . R (p_i - mean p) (Horn), the scale is Umeyama's
 *   s = sum (q_i - mean q) . R (p_i - mean p) / sum |p_i - mean p|^2. Collinear markers leave the
 *   rotation about their line undetermined (the fit returns one of them).
 * - The match (of the one pass, and of the iterative correspondence at the fitted positions,
 *   transfer_register.c): for the centroid c of each target triangle, the source triangle with
 *   the nearest closest point to c, among the source triangles whose normal makes an angle below
 *   90 degrees with the target triangle's; ties go to the lower source triangle index.
 * - The search visits a uniform grid over the source triangles' bounding boxes (cells about
 *   twice a triangle's extent, at most about 8 cells per triangle) ring by ring around the
 *   centroid's cell, and stops when the cells not visited yet are all farther than the best
 *   compatible candidate: the same answer as trying every source triangle.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "transfer_internal.h"
#include "bake_util.h"
#include "mesh_groups.h"
#include "rotation_fit.h"

static void load(double out[3], const float *p)
{
    out[0] = p[0]; out[1] = p[1]; out[2] = p[2];
}

mk_result bake_transfer_align(const mk_raw_mesh *source, const mk_raw_mesh *target, uint32_t count,
                              const uint32_t (*markers)[2], double A[9], double t[3], double *residual,
                              mk_error *err)
{
    memset(A, 0, 9 * sizeof(double));
    A[0] = A[4] = A[8] = 1;
    t[0] = t[1] = t[2] = 0;
    *residual = 0;
    if (count == 0) return MK_OK;
    double mp[3] = { 0, 0, 0 }, mq[3] = { 0, 0, 0 };
    for (uint32_t i = 0; i < count; i++) {
        double p[3], q[3];
        load(p, source->positions + 3 * (size_t)markers[i][0]);
        load(q, target->positions + 3 * (size_t)markers[i][1]);
        for (int c = 0; c < 3; c++) { mp[c] += p[c] / count; mq[c] += q[c] / count; }
    }
    double spread = 0, S[9] = { 0 };
    for (uint32_t i = 0; i < count; i++) {
        double p[3], q[3];
        load(p, source->positions + 3 * (size_t)markers[i][0]);
        load(q, target->positions + 3 * (size_t)markers[i][1]);
        vec3_sub(p, p, mp);
        vec3_sub(q, q, mq);
        spread += vec3_dot(p, p);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) S[3 * r + c] += p[r] * q[c];
    }
    if (count >= 2) {
        if (!(spread > 0))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "markers: the source markers all sit at one point; no scale or rotation can be fitted");
        double R[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
        if (count >= 3) bake_fit_rotation(S, R);
        double num = 0;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) num += R[3 * r + c] * S[3 * c + r];  /* tr(R S) */
        double s = num / spread;
        if (!(s > 0))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "markers: the fitted alignment scale is %g (markers in opposite order?)", s);
        for (int i = 0; i < 9; i++) A[i] = s * R[i];
    }
    double Amp[3];
    mat3_mul_vec(Amp, A, mp);
    vec3_sub(t, mq, Amp);
    double sum = 0;
    for (uint32_t i = 0; i < count; i++) {
        double p[3], q[3], ap[3];
        load(p, source->positions + 3 * (size_t)markers[i][0]);
        load(q, target->positions + 3 * (size_t)markers[i][1]);
        mat3_mul_vec(ap, A, p);
        for (int c = 0; c < 3; c++) ap[c] += t[c] - q[c];
        sum += vec3_dot(ap, ap);
    }
    *residual = sqrt(sum / count);
    return MK_OK;
}

/* Squared distance from p to triangle abc and the barycentric coordinates of the closest point
 * (the Voronoi regions of the vertices, the edges and the face, in that order). */
static double closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3],
                                  double bary[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    vec3_sub(ab, b, a); vec3_sub(ac, c, a); vec3_sub(ap, p, a);
    double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
    vec3_sub(bp, p, b);
    double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
    vec3_sub(cp, p, c);
    double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
    double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d1 <= 0 && d2 <= 0) { bary[0] = 1; bary[1] = 0; bary[2] = 0; }
    else if (d3 >= 0 && d4 <= d3) { bary[0] = 0; bary[1] = 1; bary[2] = 0; }
    else if (d6 >= 0 && d5 <= d6) { bary[0] = 0; bary[1] = 0; bary[2] = 1; }
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        bary[0] = 1 - v; bary[1] = v; bary[2] = 0;
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        bary[0] = 1 - w; bary[1] = 0; bary[2] = w;
    } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        bary[0] = 0; bary[1] = 1 - w; bary[2] = w;
    } else {
        double inv = 1 / (va + vb + vc), v = vb * inv, w = vc * inv;
        bary[0] = 1 - v - w; bary[1] = v; bary[2] = w;
    }
    double d2sum = 0;
    for (int k = 0; k < 3; k++) {
        double q = bary[0] * a[k] + bary[1] * b[k] + bary[2] * c[k] - p[k];
        d2sum += q * q;
    }
    return d2sum;
}

/* Corners of triangle t (positions: 3 doubles per vertex, or the mesh's floats when NULL), its
 * unnormalized normal (mk_face_normal's, from the corners already loaded), and whether it is
 * degenerate. */
static int triangle(const mk_raw_mesh *mesh, const double *positions, uint32_t t, double v[3][3], double n[3])
{
    double longest = 0;
    for (int k = 0; k < 3; k++) {
        uint32_t i = mesh->triangles[3 * (size_t)t + k];
        if (positions) memcpy(v[k], positions + 3 * (size_t)i, sizeof v[k]);
        else load(v[k], mesh->positions + 3 * (size_t)i);
    }
    double e1[3], e2[3], e3[3];
    vec3_sub(e1, v[1], v[0]); vec3_sub(e2, v[2], v[0]); vec3_sub(e3, v[2], v[1]);
    mk_triangle_normal(v[0], v[1], v[2], n);
    longest = fmax(vec3_dot(e1, e1), fmax(vec3_dot(e2, e2), vec3_dot(e3, e3)));
    return !(vec3_length(n) > TRANSFER_DEGENERATE * longest);
}

static void cell_range(const bake_tri_grid *g, const double lo[3], const double hi[3], int32_t a[3], int32_t b[3])
{
    for (int c = 0; c < 3; c++) {
        double fa = floor((lo[c] - g->lo[c]) / g->h), fb = floor((hi[c] - g->lo[c]) / g->h);
        a[c] = fa < 0 ? 0 : fa > g->dims[c] - 1 ? g->dims[c] - 1 : (int32_t)fa;
        b[c] = fb < 0 ? 0 : fb > g->dims[c] - 1 ? g->dims[c] - 1 : (int32_t)fb;
    }
}

static size_t cell_index(const bake_tri_grid *g, int32_t x, int32_t y, int32_t z)
{
    return ((size_t)z * (size_t)g->dims[1] + (size_t)y) * (size_t)g->dims[0] + (size_t)x;
}

static void triangle_box(const bake_tri_grid *g, uint32_t s, double lo[3], double hi[3])
{
    for (int c = 0; c < 3; c++) { lo[c] = INFINITY; hi[c] = -INFINITY; }
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++) {
            double v = g->positions[3 * (size_t)g->mesh->triangles[3 * (size_t)s + k] + c];
            lo[c] = fmin(lo[c], v);
            hi[c] = fmax(hi[c], v);
        }
}

int bake_triangle_degenerate(const mk_raw_mesh *mesh, const double *positions, uint32_t t)
{
    double v[3][3], n[3];
    return triangle(mesh, positions, t, v, n);
}

mk_result bake_tri_grid_build(bake_tri_grid *g, const mk_raw_mesh *mesh, const double *positions,
                              const unsigned char *exclude, mk_arena *arena, mk_error *err)
{
    uint32_t ns = mesh->triangle_count, live = 0;
    memset(g, 0, sizeof *g);
    g->mesh = mesh;
    g->positions = positions;
    g->normal = mk_arena_array(arena, 3 * (size_t)ns + 1, sizeof(double));
    g->bad = mk_arena_array(arena, (size_t)ns + 1, 1);
    g->seen = mk_arena_array(arena, (size_t)ns + 1, sizeof(uint32_t));
    if (!g->normal || !g->bad || !g->seen) return mk_error_oom(err, "triangle grid");
    for (uint32_t s = 0; s < ns; s++) {
        double v[3][3];
        g->bad[s] = (unsigned char)(triangle(mesh, positions, s, v, g->normal + 3 * (size_t)s) || (exclude && exclude[s]));
    }
    double hi[3], extent_sum = 0;
    for (int c = 0; c < 3; c++) { g->lo[c] = INFINITY; hi[c] = -INFINITY; }
    for (uint32_t s = 0; s < ns; s++) {
        if (g->bad[s]) continue;
        double tlo[3], thi[3], ext = 0;
        triangle_box(g, s, tlo, thi);
        for (int c = 0; c < 3; c++) {
            g->lo[c] = fmin(g->lo[c], tlo[c]);
            hi[c] = fmax(hi[c], thi[c]);
            ext = fmax(ext, thi[c] - tlo[c]);
        }
        extent_sum += ext;
        live++;
    }
    double size = 0;
    for (int c = 0; c < 3; c++) size = fmax(size, live ? hi[c] - g->lo[c] : 0);
    /* cells about twice a triangle's extent, at most ~8 cells per triangle */
    g->h = live ? 2 * extent_sum / live : 1;
    if (!(g->h > 1e-9 * size)) g->h = size > 0 ? size : 1;
    for (;;) {
        double cells = 1;
        for (int c = 0; c < 3; c++) {
            double d = live ? floor((hi[c] - g->lo[c]) / g->h) + 1 : 1;
            g->dims[c] = (int32_t)d;
            cells *= d;
        }
        if (cells <= 8.0 * live + 64) break;
        g->h *= 1.5;
    }
    size_t cells = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    g->first = mk_arena_array(arena, cells + 1, sizeof(uint32_t));
    if (!g->first) return mk_error_oom(err, "triangle grid");
    for (int pass = 0; pass < 2; pass++) {
        for (uint32_t s = 0; s < ns; s++) {
            if (g->bad[s]) continue;
            double tlo[3], thi[3];
            triangle_box(g, s, tlo, thi);
            int32_t a[3], b[3];
            cell_range(g, tlo, thi, a, b);
            for (int32_t z = a[2]; z <= b[2]; z++)
                for (int32_t y = a[1]; y <= b[1]; y++)
                    for (int32_t x = a[0]; x <= b[0]; x++) {
                        size_t cell = cell_index(g, x, y, z);
                        if (pass == 0) g->first[cell + 1]++;
                        else g->tris[g->first[cell]++] = s;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < cells; c++) g->first[c + 1] += g->first[c];
            g->tris = mk_arena_array(arena, (size_t)g->first[cells] + 1, sizeof(uint32_t));
            if (!g->tris) return mk_error_oom(err, "triangle grid");
        } else {
            /* the fill advanced first[c] to first[c + 1]: shift back */
            for (size_t c = cells; c > 0; c--) g->first[c] = g->first[c - 1];
            g->first[0] = 0;
        }
    }
    return MK_OK;
}

uint32_t bake_tri_grid_closest(bake_tri_grid *g, const double p[3], const double n[3], double bary[3], double *d2,
                               int *away_nearer)
{
    uint32_t match = UINT32_MAX, stamp = ++g->stamp;
    double best = INFINITY, best_away = INFINITY;
    bary[0] = bary[1] = bary[2] = 0;
    if (d2) *d2 = INFINITY;
    if (away_nearer) *away_nearer = 0;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) return UINT32_MAX;
    int32_t center[3];
    cell_range(g, p, p, center, center);
    /* rings of cells at Chebyshev distance k from p's cell, until no unvisited cell can hold
     * a point nearer than the best compatible one */
    for (int32_t k = 0;; k++) {
        for (int32_t z = center[2] - k; z <= center[2] + k; z++)
            for (int32_t y = center[1] - k; y <= center[1] + k; y++)
                for (int32_t x = center[0] - k; x <= center[0] + k; x++) {
                    if (x < 0 || y < 0 || z < 0 || x >= g->dims[0] || y >= g->dims[1] || z >= g->dims[2]) continue;
                    if (abs(x - center[0]) != k && abs(y - center[1]) != k && abs(z - center[2]) != k) continue;
                    size_t cell = cell_index(g, x, y, z);
                    for (uint32_t q = g->first[cell]; q < g->first[cell + 1]; q++) {
                        uint32_t s = g->tris[q];
                        if (g->seen[s] == stamp) continue;
                        g->seen[s] = stamp;
                        const uint32_t *tri = g->mesh->triangles + 3 * (size_t)s;
                        double b[3];
                        double e2 = closest_on_triangle(p, g->positions + 3 * (size_t)tri[0], g->positions + 3 * (size_t)tri[1],
                                                        g->positions + 3 * (size_t)tri[2], b);
                        if (vec3_dot(n, g->normal + 3 * (size_t)s) > 0) {
                            if (e2 < best || (e2 == best && s < match)) { best = e2; match = s; memcpy(bary, b, sizeof b); }
                        } else if (e2 < best_away) best_away = e2;
                    }
                }
        /* distance from p to the cells not visited yet (sides of the block with cells beyond) */
        double bound = INFINITY;
        int more = 0;
        for (int c = 0; c < 3; c++) {
            if (center[c] - k > 0) {
                more = 1;
                bound = fmin(bound, p[c] - (g->lo[c] + (center[c] - k) * g->h));
            }
            if (center[c] + k < g->dims[c] - 1) {
                more = 1;
                bound = fmin(bound, g->lo[c] + (center[c] + k + 1) * g->h - p[c]);
            }
        }
        if (!more || (bound > 0 && bound * bound > best)) break;
    }
    if (d2) *d2 = best;
    if (away_nearer) *away_nearer = best_away < best;
    return match;
}

mk_result bake_transfer_correspond(const mk_raw_mesh *source, const double *aligned, const unsigned char *exclude,
                                   const mk_raw_mesh *target, const double *target_positions, mk_arena *arena,
                                   uint32_t *match, double *barycentric, uint32_t *flipped, uint32_t *unmatched,
                                   mk_error *err)
{
    bake_tri_grid g;
    mk_result r = bake_tri_grid_build(&g, source, aligned, exclude, arena, err);
    if (r != MK_OK) return r;
    *flipped = 0;
    *unmatched = 0;
    for (uint32_t t = 0; t < target->triangle_count; t++) {
        double v[3][3], n[3], p[3];
        double *bary = barycentric + 3 * (size_t)t;
        match[t] = UINT32_MAX;
        bary[0] = bary[1] = bary[2] = 0;
        if (triangle(target, target_positions, t, v, n)) { (*unmatched)++; continue; }
        for (int c = 0; c < 3; c++) p[c] = (v[0][c] + v[1][c] + v[2][c]) / 3;
        int away_nearer = 0;
        match[t] = bake_tri_grid_closest(&g, p, n, bary, NULL, &away_nearer);
        if (match[t] == UINT32_MAX) { (*unmatched)++; continue; }
        if (away_nearer) (*flipped)++;
    }
    return MK_OK;
}

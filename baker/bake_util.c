/* SPDX-License-Identifier: MIT */
/* Shared baker helpers: bounds, welding, normals from a deformed surface, the point-map
 * evaluator used by FFD and Barr, the lattices' Bernstein basis, timing.
 *
 * Conventions fixed here:
 * - Normal transform N' = normalize(cof(J) N), cof(J) = det(J) J^-T, never dividing by det J;
 *   cof(J) N stays consistent with the winding of the deformed triangles even where the map
 *   folds, since (Ja) x (Jb) = cof(J)(a x b) (Barr 1984; docs/baking.md, "Normals").
 * - A vertex whose scale-free conditioning det J / (|J|_F / sqrt 3)^3 is <= 1e-6 is
 *   "inverted": counted, and its normal comes from the deformed surface (area-weighted face
 *   normals, smoothed over render vertices with equal base position and base normal).
 * - Tangents: T' = J T, Gram-Schmidt against N'; the runtime keeps the handedness w.
 * - Welding for the solvers: bit-identical float positions (-0 == +0) are one vertex.
 */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bake_util.h"
#include "mesh_groups.h"

double bake_jacobian_quality(const double J[9])
{
    double f2 = 0;
    for (int i = 0; i < 9; i++) f2 += J[i] * J[i];
    if (!(f2 > 0)) return 0;
    double s = sqrt(f2 / 3.0);
    return mat3_det(J) / (s * s * s);
}

void bake_bernstein(uint32_t points, double x, double *w, double *dw)
{
    /* B_i^deg by the triangle recursion B_i^d = (1 - x) B_i^(d-1) + x B_(i-1)^(d-1): no powers,
     * no binomials, stable for x in [0, 1]; the degree deg-1 values give the derivative. */
    const int deg = (int)points - 1;
    double low[BAKE_BERNSTEIN_MAX_POINTS];
    for (int i = 0; i <= deg; i++) w[i] = 0;
    w[0] = 1;
    for (int d = 1; d <= deg; d++) {
        if (d == deg)
            for (int i = 0; i < d; i++) low[i] = w[i];
        for (int i = d; i >= 0; i--)
            w[i] = (i < d ? (1 - x) * w[i] : 0) + (i > 0 ? x * w[i - 1] : 0);
    }
    if (deg == 0) { dw[0] = 0; return; }
    for (int i = 0; i <= deg; i++)
        dw[i] = deg * ((i > 0 ? low[i - 1] : 0) - (i < deg ? low[i] : 0));
}

void bake_bounds(const mk_raw_mesh *mesh, double min[3], double max[3], double *diagonal)
{
    for (int c = 0; c < 3; c++) { min[c] = 0; max[c] = 0; }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        for (int c = 0; c < 3; c++) {
            double x = mesh->positions[3 * (size_t)v + c];
            if (v == 0 || x < min[c]) min[c] = x;
            if (v == 0 || x > max[c]) max[c] = x;
        }
    double d[3] = { max[0] - min[0], max[1] - min[1], max[2] - min[2] };
    if (diagonal) *diagonal = vec3_length(d);
}

mk_result bake_surface_normals(const mk_raw_mesh *mesh, const double *positions,
                                  const unsigned char *flags, double *normals_out, mk_arena *arena,
                                  mk_error *err)
{
    mk_normal_groups groups;
    mk_result r = mk_normal_groups_build(mesh, MK_GROUP_BY_POSITION, arena, &groups, err);
    if (r == MK_OK) r = mk_normal_groups_smooth(&groups, mesh, positions, flags, normals_out, arena, err);
    void *scratch[] = { groups.group_of, groups.group_vert_first, groups.group_verts, groups.group_tri_first, groups.group_tris };
    for (size_t i = 0; r == MK_OK && i < sizeof scratch / sizeof scratch[0]; i++) mk_arena_release(arena, scratch[i]);
    return r;
}

double bake_now(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

mk_result bake_pointwise_eval(void *pointwise, double amplitude, double *positions, double *normals,
                            double *tangents, uint32_t *inverted, mk_error *err)
{
    const bake_pointwise *pw = pointwise;
    const mk_raw_mesh *mesh = pw->mesh;
    size_t n = mesh->vertex_count;
    unsigned char *flags = NULL;
    uint32_t bad = 0;
    for (size_t v = 0; v < n; v++) {
        double p[3] = { mesh->positions[3 * v], mesh->positions[3 * v + 1], mesh->positions[3 * v + 2] };
        double J[9];
        pw->map(pw->user, amplitude, p, positions + 3 * v, J);
        if (!normals) continue;
        double q = bake_jacobian_quality(J);
        double *nv = normals + 3 * v;
        const float *n0 = mesh->normals + 3 * v;
        if (!(q > BAKE_DEGENERATE_R)) {
            if (!flags) {
                flags = mk_arena_array(pw->scratch, n ? n : 1, 1);
                if (!flags) return mk_error_oom(err, "normal flags");
            }
            flags[v] = 1;
            bad++;
        } else {
            double cof[9], nb[3] = { n0[0], n0[1], n0[2] };
            mat3_cofactor(cof, J);
            mat3_mul_vec(nv, cof, nb);
            if (!(vec3_normalize(nv) > 0)) { nv[0] = n0[0]; nv[1] = n0[1]; nv[2] = n0[2]; }
        }
        if (tangents) {
            const float *t0 = mesh->tangents + 4 * v;
            double tb[3] = { t0[0], t0[1], t0[2] }, *tv = tangents + 3 * v;
            mat3_mul_vec(tv, J, tb);
            /* Gram-Schmidt against the new normal happens after flagged normals are known. */
        }
    }
    if (flags) {
        mk_result r = bake_surface_normals(mesh, positions, flags, normals, pw->scratch, err);
        mk_arena_release(pw->scratch, flags);
        if (r != MK_OK) return r;
    }
    if (tangents)
        for (size_t v = 0; v < n; v++) {
            double *tv = tangents + 3 * v, *nv = normals + 3 * v;
            double d = vec3_dot(tv, nv);
            for (int c = 0; c < 3; c++) tv[c] -= d * nv[c];
            if (!(vec3_normalize(tv) > 0))
                for (int c = 0; c < 3; c++) tv[c] = mesh->tangents[4 * v + (size_t)c];
        }
    if (inverted) *inverted = bad;
    return MK_OK;
}

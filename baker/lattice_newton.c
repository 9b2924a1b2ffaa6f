/* SPDX-License-Identifier: MIT */
/* 3x3 solve and damped Newton iteration for the extended FFD lattices.
 *
 * Newton on a rest map F (Coquillart's extended FFD: a block whose rest shape is not affine has
 * no closed-form local coordinates): q <- q - lambda J(q)^-1 (F(q) - p), lambda = 1, 1/2, 1/4 ...
 * until |F - p| falls (at most 30 halvings; the last trial is taken either way), each trial
 * clamped into the caller's box so a far start cannot run off the block. */
#include <math.h>
#include <string.h>
#include "lattice_newton.h"
#include "bake_util.h"

int bake_solve3(const double J[9], const double b[3], double x[3])
{
    double size = 0, inverse[9];
    for (int i = 0; i < 9; i++) size = fmax(size, fabs(J[i]));
    if (!mat3_inverse(inverse, J, 1e-14 * size * size * size)) return 0;
    mat3_mul_vec(x, inverse, b);
    return 1;
}

double bake_newton_solve(const bake_newton *n, const double p[3], double q[3], uint32_t *iterations)
{
    double f[3], J[9], res = INFINITY;
    uint32_t it = 0;
    for (;; it++) {
        n->map(n->user, q, f, J);
        vec3_sub(f, f, p);
        res = vec3_length(f);
        if (res <= n->target || it == n->max_iterations) break;
        double step[3];
        if (!bake_solve3(J, f, step)) {
            /* Singular (e.g. a coordinate that is free on an axis): solve for the other two. */
            if (n->held < 0) break;
            int a = (n->held + 1) % 3, b = (n->held + 2) % 3;
            double A[9] = { J[a], J[b], 0, J[3 + a], J[3 + b], 0, J[6 + a], J[6 + b], 1 }, sol[3];
            if (!bake_solve3(A, f, sol)) break;
            step[n->held] = 0; step[a] = sol[0]; step[b] = sol[1];
        }
        double lambda = 1, trial[3], g[3];
        for (int h = 0; h < 30; h++, lambda *= 0.5) {
            for (int k = 0; k < 3; k++) trial[k] = fmin(fmax(q[k] - lambda * step[k], n->lower[k]), n->upper[k]);
            n->map(n->user, trial, g, NULL);
            vec3_sub(g, g, p);
            if (vec3_length(g) < res) break;
        }
        memcpy(q, trial, sizeof trial);
    }
    if (iterations) *iterations = it;
    return res;
}

mk_result bake_lattice_bind(const void *lattice, bake_locate locate, uint32_t stride, const mk_raw_mesh *mesh,
                            double *coords, mk_error *err)
{
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const float *pf = mesh->positions + 3 * (size_t)v;
        double p[3] = { pf[0], pf[1], pf[2] };
        mk_error inner;
        if (locate(lattice, p, coords + stride * (size_t)v, &inner) != MK_OK)
            return mk_error_set(err, inner.code, UINT64_MAX, "vertex %u (%g, %g, %g): %s", v, p[0], p[1], p[2],
                                inner.message);
    }
    return MK_OK;
}

mk_result bake_axial_frame(const double axis[3], const double reference[3], double frame[3][3], double *height,
                           mk_error *err)
{
    double *e1 = frame[0], *e2 = frame[1], *e3 = frame[2];
    memcpy(e3, axis, 3 * sizeof(double));
    *height = vec3_normalize(e3);
    if (!(*height > 0)) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "axis: zero length (no height)");
    double d = vec3_dot(reference, e3);
    for (int k = 0; k < 3; k++) e1[k] = reference[k] - d * e3[k];
    if (!(vec3_normalize(e1) > 1e-9 * vec3_length(reference)))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "reference: parallel to the axis");
    vec3_cross(e2, e3, e1);
    return MK_OK;
}

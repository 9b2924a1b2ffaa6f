/* SPDX-License-Identifier: MIT */
/* Free-form deformation: a lattice of control points deforms the space it encloses.
 *
 * Papers and sources:
 * - T. W. Sederberg, S. R. Parry, "Free-Form Deformation of Solid Geometric Models",
 *   SIGGRAPH 1986: parallelepiped lattice X0 + sS + tT + uU, parameters from the cross-product
 *   formulas s = (T x U).(X - X0) / ((T x U).S) (and cyclic), trivariate Bernstein basis.
 * - Blender's Lattice modifier (lattice_deform.cc, key.cc key_curve_position_weights): uniform
 *   cubic B-spline weights over 4 taps per axis with indices clamped to the lattice, applied to
 *   control point displacements (so an undeformed lattice is the identity everywhere).
 *
 * Conventions fixed here:
 * - Both bases are written in displacement form: X' = X + a * sum_p w_p(s,t,u) d_p with
 *   d_p = P'_p - P_p and amplitude a. For Bernstein this equals sum B P' (linear precision of
 *   the Bernstein basis), so an affine map of all control points maps X affinely, exactly.
 *   Everything is linear in a: a single target reproduces an FFD exactly.
 * - Bernstein: points outside the lattice (s, t or u outside [0, 1]) stay where they are
 *   (J = I); keep the outer layer of control points at rest for a seamless boundary.
 * - B-spline: grid coordinate g = s (l - 1); taps floor(g) - 1 .. floor(g) + 2 clamped to
 *   [0, l-1]; the weights are not interpolating (5/6, 1/6 at the boundary, as Blender). Outside
 *   the lattice the taps clamp onto the boundary, so far points move with the boundary layer.
 * - Jacobian: J = I + a * G M^-1 with G = [dX/ds dX/dt dX/du] from the basis derivatives
 *   (d/ds B_i^l = l (B_{i-1}^{l-1} - B_i^{l-1})); normals use cof(J) (bake_util.h).
 */
#include <math.h>
#include <string.h>
#include "ffd.h"
#include "bake_util.h"

#define MAX_DIM 64
_Static_assert(MAX_DIM <= BAKE_BERNSTEIN_MAX_POINTS, "bake_bernstein takes every lattice axis");

void mk_ffd_control_point(const mk_ffd_lattice *f, uint32_t i, uint32_t j, uint32_t k, double out[3])
{
    double s = (double)i / (f->dims[0] - 1), t = (double)j / (f->dims[1] - 1),
           u = (double)k / (f->dims[2] - 1);
    for (int c = 0; c < 3; c++)
        out[c] = f->origin[c] + s * f->axes[0][c] + t * f->axes[1][c] + u * f->axes[2][c];
}

mk_result mk_ffd_prepare(mk_ffd_lattice *f, mk_error *err)
{
    for (int a = 0; a < 3; a++) {
        if (f->dims[a] < 2 || f->dims[a] > MAX_DIM)
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "dims[%d]: %u control points (need 2..%d)", a, f->dims[a], MAX_DIM);
        for (int c = 0; c < 3; c++)
            if (!isfinite(f->axes[a][c]) || !isfinite(f->origin[c]))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "origin/axes: not finite");
    }
    const double *S = f->axes[0], *T = f->axes[1], *U = f->axes[2];
    double TxU[3], SxU[3], SxT[3];
    vec3_cross(TxU, T, U);
    vec3_cross(SxU, S, U);
    vec3_cross(SxT, S, T);
    double det = vec3_dot(TxU, S);
    double scale = vec3_length(S) * vec3_length(T) * vec3_length(U);
    if (!(fabs(det) > 1e-9 * scale) || !(scale > 0))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "lattice: axes S, T, U are degenerate (they span no volume)");
    /* Each numerator and denominator uses the same cross product: the signs cancel. */
    double dt = vec3_dot(SxU, T), du = vec3_dot(SxT, U);
    for (int c = 0; c < 3; c++) {
        f->inverse[c] = TxU[c] / det;
        f->inverse[3 + c] = SxU[c] / dt;
        f->inverse[6 + c] = SxT[c] / du;
    }
    size_t count = (size_t)f->dims[0] * f->dims[1] * f->dims[2];
    if (f->displacements)
        for (size_t i = 0; i < 3 * count; i++)
            if (!isfinite(f->displacements[i]))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                    "lattice: control point %zu displacement is not finite", i / 3);
    return MK_OK;
}

void mk_ffd_parameters(const mk_ffd_lattice *f, const double p[3], double stu[3])
{
    double d[3] = { p[0] - f->origin[0], p[1] - f->origin[1], p[2] - f->origin[2] };
    mat3_mul_vec(stu, f->inverse, d);
}

/* Uniform cubic B-spline weights of the 4 taps floor(g)-1 .. floor(g)+2 and derivatives
 * (d/dg). */
static void bspline(double t, double w[4], double dw[4])
{
    double t2 = t * t, t3 = t2 * t, m = 1 - t;
    w[0] = m * m * m / 6;
    w[1] = (3 * t3 - 6 * t2 + 4) / 6;
    w[2] = (-3 * t3 + 3 * t2 + 3 * t + 1) / 6;
    w[3] = t3 / 6;
    dw[0] = -m * m / 2;
    dw[1] = (3 * t2 - 4 * t) / 2;
    dw[2] = (-3 * t2 + 2 * t + 1) / 2;
    dw[3] = t2 / 2;
}

void mk_ffd_map(const void *user, double amplitude, const double p[3], double out[3], double J[9])
{
    const mk_ffd_lattice *f = user;
    double stu[3];
    mk_ffd_parameters(f, p, stu);
    for (int c = 0; c < 3; c++) out[c] = p[c];
    for (int i = 0; i < 9; i++) J[i] = (i % 4 == 0) ? 1 : 0;
    if (!f->displacements || amplitude == 0) return;

    /* Per axis: the taps (control indices) with their weights and d/d(param) weights. */
    int first[3], taps[3];
    int idx[3][MAX_DIM];
    double w[3][MAX_DIM], dw[3][MAX_DIM];
    if (f->basis == MK_FFD_BERNSTEIN) {
        for (int a = 0; a < 3; a++)
            if (!(stu[a] >= 0 && stu[a] <= 1)) return;  /* outside: unchanged */
        for (int a = 0; a < 3; a++) {
            bake_bernstein(f->dims[a], stu[a], w[a], dw[a]);
            taps[a] = (int)f->dims[a];
            first[a] = 0;
            for (int i = 0; i < taps[a]; i++) idx[a][i] = i;
        }
    } else {
        for (int a = 0; a < 3; a++) {
            int n = (int)f->dims[a];
            double g = stu[a] * (n - 1);
            /* Far outside, every tap clamps to the boundary: avoid int overflow. */
            if (g < -4) g = -4;
            if (g > n + 3) g = n + 3;
            double fl = floor(g);
            double bw[4], bdw[4];
            bspline(g - fl, bw, bdw);
            taps[a] = 4;
            first[a] = (int)fl - 1;
            for (int i = 0; i < 4; i++) {
                int q = first[a] + i;
                idx[a][i] = q < 0 ? 0 : (q > n - 1 ? n - 1 : q);
                w[a][i] = bw[i];
                /* dw/ds = dw/dg * (n - 1); zero when g was clamped far outside */
                dw[a][i] = (stu[a] * (n - 1) < -4 || stu[a] * (n - 1) > n + 3) ? 0 : bdw[i] * (n - 1);
            }
        }
    }
    double disp[3] = { 0, 0, 0 }, G[9] = { 0 };  /* G columns: d/ds, d/dt, d/du */
    uint32_t sx = 1, sy = f->dims[0], sz = f->dims[0] * f->dims[1];
    for (int k = 0; k < taps[2]; k++)
        for (int j = 0; j < taps[1]; j++) {
            double wjk = w[1][j] * w[2][k], djk_t = dw[1][j] * w[2][k], djk_u = w[1][j] * dw[2][k];
            for (int i = 0; i < taps[0]; i++) {
                const double *d = f->displacements +
                    3 * ((size_t)idx[0][i] * sx + (size_t)idx[1][j] * sy + (size_t)idx[2][k] * sz);
                double ws = w[0][i] * wjk, gs = dw[0][i] * wjk, gt = w[0][i] * djk_t,
                       gu = w[0][i] * djk_u;
                for (int c = 0; c < 3; c++) {
                    disp[c] += ws * d[c];
                    G[3 * c] += gs * d[c];
                    G[3 * c + 1] += gt * d[c];
                    G[3 * c + 2] += gu * d[c];
                }
            }
        }
    double GM[9];
    mat3_mul(GM, G, f->inverse);
    for (int c = 0; c < 3; c++) out[c] = p[c] + amplitude * disp[c];
    for (int i = 0; i < 9; i++) J[i] += amplitude * GM[i];
}

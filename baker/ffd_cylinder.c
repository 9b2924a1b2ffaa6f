/* SPDX-License-Identifier: MIT */
/* Extended free-form deformation with a cylindrical lattice.
 *
 * Papers:
 * - S. Coquillart, "Extended Free-Form Deformation: A Sculpturing Tool for 3D Geometric
 *   Modeling", SIGGRAPH 1990: lattices that are not parallelepipeds (cylindrical ones among
 *   them), whose local coordinates are no longer a linear solve.
 * - T. W. Sederberg, S. R. Parry, SIGGRAPH 1986, for the Bernstein basis (see ffd.c).
 *
 * Conventions fixed here:
 * - Control point (i, j, k) rests at center + r_i (cos a_j e1 + sin a_j e2) + k/(l-1) axis.
 *   Basis: Bernstein of degree rings-1 in s (radial), the uniform periodic cubic B-spline in
 *   t over the sectors (angular: the seam at t = 0 = 1 is C2 like everywhere else, no special
 *   case), Bernstein of degree layers-1 in u (axial). The rest map is therefore
 *   F(s,t,u) = center + r(s) C(t) + u axis with r linear in s and C the B-spline "circle" of
 *   the sector directions (radius between 0.90 and 1 of a unit circle for 8 sectors), not an
 *   affine map: coordinates come from Newton's method.
 * - Displacement form, as ffd.c: X' = X + a sum w(s,t,u) d, so an unmoved lattice is the
 *   identity, and moving every control point by one affine map moves X by that map (the
 *   weights sum to 1 and reproduce F), provided Newton found the coordinates.
 * - Newton: start from the cylindrical coordinates of the point (exact in s and u up to the
 *   B-spline circle's radius), steps damped by halving until the residual falls, at most 50
 *   iterations, converged at |F(q) - X| <= 1e-10 of the lattice size. Points with s or u
 *   outside [-1e-9, 1 + 1e-9] are outside the lattice.
 */
#include <math.h>
#include <string.h>
#include "ffd_cylinder.h"
#include "bake_util.h"
#include "lattice_newton.h"

#define PI 3.14159265358979323846
#define MAX_DIM 64
_Static_assert(MAX_DIM <= BAKE_BERNSTEIN_MAX_POINTS, "bake_bernstein takes every lattice axis");

mk_result mk_cylinder_prepare(mk_cylinder_lattice *c, mk_error *err)
{
    static const uint32_t min_dims[3] = { 2, 3, 2 };
    for (int a = 0; a < 3; a++)
        if (c->dims[a] < min_dims[a] || c->dims[a] > MAX_DIM)
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "dims[%d]: %u control points (need %u..%d)",
                                a, c->dims[a], min_dims[a], MAX_DIM);
    for (int k = 0; k < 3; k++)
        if (!isfinite(c->center[k]) || !isfinite(c->axis[k]) || !isfinite(c->reference[k]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "center/axis/reference: not finite");
    if (!isfinite(c->inner_radius) || !isfinite(c->outer_radius) || !(c->inner_radius >= 0) ||
        !(c->outer_radius > c->inner_radius))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "radius: need 0 <= inner radius < outer radius (got %g, %g)", c->inner_radius, c->outer_radius);
    mk_result r = bake_axial_frame(c->axis, c->reference, c->frame, &c->height, err);
    if (r != MK_OK) return r;
    return MK_OK;
}

void mk_cylinder_control_point(const mk_cylinder_lattice *c, uint32_t i, uint32_t j, uint32_t k, double out[3])
{
    double r = c->inner_radius + (c->outer_radius - c->inner_radius) * i / (c->dims[0] - 1);
    double a = 2 * PI * j / c->dims[1], u = (double)k / (c->dims[2] - 1);
    for (int q = 0; q < 3; q++)
        out[q] = c->center[q] + r * (cos(a) * c->frame[0][q] + sin(a) * c->frame[1][q]) + u * c->height * c->frame[2][q];
}

/* Periodic uniform cubic B-spline over n control points at t in [0, 1): the 4 taps (indices
 * mod n), their weights and derivatives d/dt. */
static void periodic_bspline(uint32_t n, double t, uint32_t taps[4], double w[4], double dw[4])
{
    double g = t * n, f = floor(g), x = g - f;
    long base = (long)f;
    for (int q = 0; q < 4; q++) taps[q] = (uint32_t)((((base - 1 + q) % (long)n) + (long)n) % (long)n);
    double y = 1 - x;
    w[0] = y * y * y / 6;
    w[1] = (3 * x * x * x - 6 * x * x + 4) / 6;
    w[2] = (-3 * x * x * x + 3 * x * x + 3 * x + 1) / 6;
    w[3] = x * x * x / 6;
    dw[0] = -y * y / 2 * n;
    dw[1] = (9 * x * x - 12 * x) / 6 * n;
    dw[2] = (-9 * x * x + 6 * x + 3) / 6 * n;
    dw[3] = x * x / 2 * n;
}

/* sum w(q) P_ijk + amplitude * sum w(q) d_ijk and its derivatives (columns d/ds, d/dt, d/du,
 * row-major J[3*row + col]); P from the rest control points, d = NULL for the rest map. */
static void lattice_eval(const mk_cylinder_lattice *c, const double q[3], const double *disp, double amplitude,
                         double out[3], double J[9])
{
    double ws[MAX_DIM], dws[MAX_DIM], wu[MAX_DIM], dwu[MAX_DIM], wt[4], dwt[4];
    uint32_t taps[4];
    double t = q[1] - floor(q[1]);
    bake_bernstein(c->dims[0], q[0], ws, dws);
    periodic_bspline(c->dims[1], t, taps, wt, dwt);
    bake_bernstein(c->dims[2], q[2], wu, dwu);
    memset(out, 0, 3 * sizeof(double));
    if (J) memset(J, 0, 9 * sizeof(double));
    for (uint32_t k = 0; k < c->dims[2]; k++)
        for (int b = 0; b < 4; b++)
            for (uint32_t i = 0; i < c->dims[0]; i++) {
                uint32_t j = taps[b];
                double p[3];
                if (disp) {
                    const double *d = disp + 3 * (i + c->dims[0] * ((size_t)j + c->dims[1] * k));
                    for (int r = 0; r < 3; r++) p[r] = amplitude * d[r];
                } else mk_cylinder_control_point(c, i, j, k, p);
                double w = ws[i] * wt[b] * wu[k];
                for (int r = 0; r < 3; r++) out[r] += w * p[r];
                if (J)
                    for (int r = 0; r < 3; r++) {
                        J[3 * r + 0] += dws[i] * wt[b] * wu[k] * p[r];
                        J[3 * r + 1] += ws[i] * dwt[b] * wu[k] * p[r];
                        J[3 * r + 2] += ws[i] * wt[b] * dwu[k] * p[r];
                    }
            }
}

/* bake_rest_map of the cylinder's rest lattice. */
static void rest_map(const void *user, const double q[3], double F[3], double J[9])
{
    lattice_eval(user, q, NULL, 0, F, J);
}

mk_result mk_cylinder_coordinates(const mk_cylinder_lattice *c, const double p[3], double q[3], uint32_t *iterations,
                                  mk_error *err)
{
    double size = fmax(c->outer_radius, c->height), rel[3], target_error = 1e-10 * size;
    vec3_sub(rel, p, c->center);
    double x = vec3_dot(rel, c->frame[0]), y = vec3_dot(rel, c->frame[1]), z = vec3_dot(rel, c->frame[2]);
    double radius = sqrt(x * x + y * y), angle = atan2(y, x);
    q[0] = (radius - c->inner_radius) / (c->outer_radius - c->inner_radius);
    q[1] = angle / (2 * PI);
    q[2] = z / c->height;
    q[0] = fmin(fmax(q[0], 0), 1);
    /* On the axis (inner radius 0, s = 0) the angle is free: J is singular, t is held. */
    bake_newton newton = { rest_map, c, { -0.5, -INFINITY, -INFINITY }, { INFINITY, INFINITY, INFINITY }, 1,
                           target_error, 50 };
    uint32_t it = 0;
    double res = bake_newton_solve(&newton, p, q, &it);
    if (iterations) *iterations = it;
    q[1] -= floor(q[1]);
    if (!(res <= target_error))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "Newton did not converge (residual %.3g of the lattice size after %u iterations)",
                            res / size, it);
    if (q[0] < -1e-9 || q[0] > 1 + 1e-9 || q[2] < -1e-9 || q[2] > 1 + 1e-9)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "outside the lattice (s = %.4g, u = %.4g; both must be in [0, 1])", q[0], q[2]);
    return MK_OK;
}

void mk_cylinder_eval(const mk_cylinder_lattice *c, double amplitude, const double q[3], const double p[3],
                      double out[3])
{
    double moved[3];
    lattice_eval(c, q, c->displacements, amplitude, moved, NULL);
    for (int k = 0; k < 3; k++) out[k] = p[k] + moved[k];
}

double mk_cylinder_ring_ratio(uint32_t sectors)
{
    /* |C(t)| for control points on the unit circle, sampled 64 times per sector (the minimum
     * is between sectors, where the curve cuts the chord the most). */
    double least = 1;
    for (uint32_t q = 0; q < 64 * sectors; q++) {
        uint32_t taps[4];
        double w[4], dw[4], x = 0, y = 0;
        periodic_bspline(sectors, (double)q / (64 * sectors), taps, w, dw);
        for (int b = 0; b < 4; b++) {
            x += w[b] * cos(2 * PI * taps[b] / sectors);
            y += w[b] * sin(2 * PI * taps[b] / sectors);
        }
        least = fmin(least, sqrt(x * x + y * y));
    }
    return least;
}

static mk_result locate(const void *lattice, const double p[3], double *stu, mk_error *err)
{
    return mk_cylinder_coordinates(lattice, p, stu, NULL, err);
}

mk_result mk_cylinder_bind(const mk_cylinder_lattice *c, const mk_raw_mesh *mesh, double *stu, mk_error *err)
{
    return bake_lattice_bind(c, locate, 3, mesh, stu, err);
}

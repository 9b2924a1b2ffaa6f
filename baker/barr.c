/* SPDX-License-Identifier: MIT */
/* Barr's global deformations: taper, twist and bend, with exact Jacobians for the normals.
 *
 * Paper: A. H. Barr, "Global and Local Deformations of Solid Primitives", SIGGRAPH 1984.
 * Normal transform: n' = cof(J) n = det(J) J^-T n (Barr's form, no division), normalized.
 *
 * Conventions fixed here (docs/baking.md repeats them for recipe users):
 * - The axis line passes through `center`; a = p . axis_unit is the coordinate along it, in
 *   mesh units; [a_min, a_max] is the deformed range (recipe default: the mesh's extent).
 * - Twist: rotation about the axis by theta(a) = angle * s(a), s(a) = clamp((a - a_min) /
 *   (a_max - a_min), 0, 1); positive angles turn counter-clockwise looking down the axis
 *   (right-hand rule). Outside the range the rotation is rigid (theta' = 0).
 * - Taper: the distance from the axis scales by r(a) = 1 + (scale - 1) * s(a), so r = 1 at
 *   a_min and r = scale at a_max; rigid scaling outside the range.
 * - Bend: the range [a_min, a_max] turns through `angle` about a line perpendicular to the axis
 *   and to `direction`, at distance 1/k (k = angle / (a_max - a_min)) on the +direction side
 *   of the axis line; a <= a_min stays in place, a >= a_max continues straight (rigidly)
 *   (Barr's clamped bend with y0 = a_min). Where k * z >= 1 (z = distance along direction)
 *   the bend folds (det J = 1 - k z <= 0); such vertices are reported as inverted.
 * - Amplitude a in [0, 1] scales the angle (twist, bend) or moves the scale from 1 (taper):
 *   taper is linear in the amplitude (one target reproduces it exactly); twist and bend are
 *   not, since linear blending of a rotation shrinks the mesh, so they need in-betweens.
 * - Small bend angles use the sinc forms of the bend (never 1/k), so angle -> 0 is the identity.
 */
#include <math.h>
#include "barr.h"
#include "bake_util.h"

mk_result mk_barr_prepare(mk_barr *b, mk_error *err)
{
    for (int c = 0; c < 3; c++)
        if (!isfinite(b->axis[c]) || !isfinite(b->center[c]) || !isfinite(b->direction[c]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "axis/center/direction: not finite");
    if (!isfinite(b->range[0]) || !isfinite(b->range[1]))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "range: not finite");
    if (!isfinite(b->angle) || !isfinite(b->scale))
        return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "angle/scale: not finite");
    double axis[3] = { b->axis[0], b->axis[1], b->axis[2] };
    if (!(vec3_normalize(axis) > 1e-30))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "axis: zero vector");
    if (!(b->range[1] > b->range[0]))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "range: [%g, %g] is empty (need min < max; a flat mesh along the axis "
                            "needs an explicit range)", b->range[0], b->range[1]);
    for (int c = 0; c < 3; c++) b->axis[c] = axis[c];
    double e1[3], e2[3];
    if (b->op == MK_BARR_BEND) {
        /* z = direction minus its axis component. */
        double d = vec3_dot(b->direction, axis);
        for (int c = 0; c < 3; c++) e2[c] = b->direction[c] - d * axis[c];
        if (!(vec3_normalize(e2) > 1e-12 * (1 + vec3_length(b->direction))))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "direction: zero or parallel to the axis");
        vec3_cross(e1, axis, e2);  /* x = y x z: right-handed (x, y, z) */
        for (int c = 0; c < 3; c++) {
            b->frame[c] = e1[c]; b->frame[3 + c] = axis[c]; b->frame[6 + c] = e2[c];
            b->direction[c] = e2[c];
        }
    } else {
        /* Any e1 perpendicular to the axis; e2 = axis x e1 so (e1, e2, axis) is right-handed. */
        int k = fabs(axis[0]) < 0.9 ? 0 : 1;
        double t[3] = { 0, 0, 0 };
        t[k] = 1;
        double d = vec3_dot(t, axis);
        for (int c = 0; c < 3; c++) e1[c] = t[c] - d * axis[c];
        vec3_normalize(e1);
        vec3_cross(e2, axis, e1);
        for (int c = 0; c < 3; c++) {
            b->frame[c] = e1[c]; b->frame[3 + c] = e2[c]; b->frame[6 + c] = axis[c];
        }
    }
    double ca = vec3_dot(b->center, axis);
    b->local_min = b->range[0] - ca;
    b->local_max = b->range[1] - ca;
    return MK_OK;
}

/* sinc(x) = sin x / x with its series near 0. */
static double sinc(double x)
{
    if (fabs(x) < 1e-4) return 1 - x * x / 6;
    return sin(x) / x;
}

void mk_barr_map(const void *user, double amplitude, const double p[3], double out[3], double J[9])
{
    const mk_barr *b = user;
    const double *R = b->frame;
    double d[3] = { p[0] - b->center[0], p[1] - b->center[1], p[2] - b->center[2] };
    double l[3], o[3], Jl[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    mat3_mul_vec(l, R, d);
    double len = b->local_max - b->local_min;
    if (b->op == MK_BARR_TWIST || b->op == MK_BARR_TAPER) {
        double x = l[0], y = l[1], z = l[2];
        double s = (z - b->local_min) / len, ds = 1 / len;
        /* Strict: a vertex exactly at a_min / a_max (the default range is the mesh extent)
         * takes the derivative from inside the range, where its surface lies. */
        if (s < 0) { s = 0; ds = 0; }
        else if (s > 1) { s = 1; ds = 0; }
        if (b->op == MK_BARR_TWIST) {
            double phi = amplitude * b->angle, th = phi * s, dth = phi * ds;
            double C = cos(th), S = sin(th);
            o[0] = x * C - y * S;
            o[1] = x * S + y * C;
            o[2] = z;
            /* J = [[C, -S, -th'(xS + yC)], [S, C, th'(xC - yS)], [0, 0, 1]], det J = 1 */
            Jl[0] = C; Jl[1] = -S; Jl[2] = -dth * (x * S + y * C);
            Jl[3] = S; Jl[4] = C;  Jl[5] = dth * (x * C - y * S);
        } else {
            double k = amplitude * (b->scale - 1);
            double r = 1 + k * s, dr = k * ds;
            o[0] = r * x;
            o[1] = r * y;
            o[2] = z;
            /* J = [[r, 0, r'x], [0, r, r'y], [0, 0, 1]], det J = r^2 */
            Jl[0] = r; Jl[2] = dr * x;
            Jl[4] = r; Jl[5] = dr * y;
        }
    } else {
        /* Barr's bend in (x, y = axis, z = direction), y0 = local_min. */
        double x = l[0], y = l[1], z = l[2];
        double k = amplitude * b->angle / len;
        double y0 = b->local_min, yh = y, kh = k;
        if (yh < b->local_min) { yh = b->local_min; kh = 0; }
        else if (yh > b->local_max) { yh = b->local_max; kh = 0; }
        double th = k * (yh - y0), C = cos(th), S = sin(th);
        o[0] = x;
        o[1] = y0 - S * z + (yh - y0) * sinc(th) + C * (y - yh);
        double h = sinc(0.5 * th);
        o[2] = C * z + (yh - y0) * 0.5 * th * h * h + S * (y - yh);
        /* J = [[1, 0, 0], [0, C(1 - k^z), -S], [0, S(1 - k^z), C]], det J = 1 - k^z */
        Jl[4] = C * (1 - kh * z); Jl[5] = -S;
        Jl[7] = S * (1 - kh * z); Jl[8] = C;
    }
    /* Back to world: out = c + R^T o, J = R^T Jl R. */
    double Rt[9] = { R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8] };
    double w[3];
    mat3_mul_vec(w, Rt, o);
    for (int c = 0; c < 3; c++) out[c] = b->center[c] + w[c];
    double tmp[9];
    mat3_mul(tmp, Jl, R);
    mat3_mul(J, Rt, tmp);
}

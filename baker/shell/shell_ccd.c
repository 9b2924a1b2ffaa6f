/* SPDX-License-Identifier: MIT */
/* The shell's narrow phase (shell_ccd.h; Bridson, Fedkiw, Anderson 2002): a pair can only cross
 * when its four points are coplanar, f(t) = (x1 - x0) x (x2 - x0) . (x3 - x0) = 0 with every
 * point on its line, a cubic in t. f is split at its critical points into monotone pieces; a
 * piece whose ends have the same sign has no root, and the root of any other is checked for
 * contact (distance within the tolerance).
 *
 * Cheap tests first, each one only skipping work whose answer it already knows: the cubic's
 * Bernstein coefficients on [0, 1] all clearly of one sign (then f has no root there, and the
 * values the pieces' sign tests would see have that sign too), and for the end-of-step
 * proximity test the distance from the vertex to the triangle's plane (or between the two
 * edges' lines), which bounds the pair's distance from below. "Clearly" means by more than a
 * bound on the rounding of the values compared. */
#include <float.h>
#include <math.h>
#include <string.h>
#include "shell_ccd.h"
#include "bake_util.h"

static void lerp3(double out[3], const double *a, const double *b, double t)
{
    for (int c = 0; c < 3; c++) out[c] = a[c] + t * (b[c] - a[c]);
}

/* Squared distance from q to triangle abc (closest point by region, Ericson's method). */
static double point_triangle_distance2(const double q[3], const double a[3], const double b[3], const double c[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], r[3];
    vec3_sub(ab, b, a); vec3_sub(ac, c, a); vec3_sub(ap, q, a);
    double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) { vec3_sub(r, q, a); return vec3_dot(r, r); }
    vec3_sub(bp, q, b);
    double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) { vec3_sub(r, q, b); return vec3_dot(r, r); }
    double vc = d1 * d4 - d3 * d2, w[3];
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++) w[k] = a[k] + v * ab[k];
        vec3_sub(r, q, w); return vec3_dot(r, r);
    }
    vec3_sub(cp, q, c);
    double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) { vec3_sub(r, q, c); return vec3_dot(r, r); }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double v = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++) w[k] = a[k] + v * ac[k];
        vec3_sub(r, q, w); return vec3_dot(r, r);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++) w[k] = b[k] + v * (c[k] - b[k]);
        vec3_sub(r, q, w); return vec3_dot(r, r);
    }
    double den = 1 / (va + vb + vc), v = vb * den, u = vc * den;
    for (int k = 0; k < 3; k++) w[k] = a[k] + v * ab[k] + u * ac[k];
    vec3_sub(r, q, w);
    return vec3_dot(r, r);
}

static double clamp01(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

/* Squared distance between segments p0p1 and q0q1 (Ericson's closest points). */
static double segment_distance2(const double p0[3], const double p1[3], const double q0[3], const double q1[3])
{
    double d1[3], d2[3], r[3];
    vec3_sub(d1, p1, p0); vec3_sub(d2, q1, q0); vec3_sub(r, p0, q0);
    double a = vec3_dot(d1, d1), e = vec3_dot(d2, d2), f = vec3_dot(d2, r), s, t;
    if (a <= 1e-300 && e <= 1e-300) s = t = 0;
    else if (a <= 1e-300) { s = 0; t = clamp01(f / e); }
    else {
        double c = vec3_dot(d1, r);
        if (e <= 1e-300) { t = 0; s = clamp01(-c / a); }
        else {
            double b = vec3_dot(d1, d2), den = a * e - b * b;
            s = den > 1e-300 ? clamp01((b * f - c * e) / den) : 0;
            t = (b * s + f) / e;
            if (t < 0) { t = 0; s = clamp01(-c / a); }
            else if (t > 1) { t = 1; s = clamp01((b - c) / a); }
        }
    }
    double w[3];
    for (int k = 0; k < 3; k++) w[k] = (p0[k] + s * d1[k]) - (q0[k] + t * d2[k]);
    return vec3_dot(w, w);
}

/* Distance of the pair at time t: kind 0 = point 3 against triangle 0 1 2, 1 = edge 0 1 against
 * edge 2 3. */
static double pair_distance2(int kind, const double *const s[4], const double *const e[4], double t)
{
    double q[4][3];
    for (int i = 0; i < 4; i++) lerp3(q[i], s[i], e[i], t);
    return kind == 0 ? point_triangle_distance2(q[3], q[0], q[1], q[2]) : segment_distance2(q[0], q[1], q[2], q[3]);
}

/* Are the pair's two parts (points 0-2 and 3, or 0-1 and 2-3) at least d apart on some axis
 * over the positions p0 and p1 (and so over every position between, points moving on lines)?
 * Then their distance is at least d meanwhile. */
static int apart_on_an_axis(int kind, const double (*p0)[3], const double (*p1)[3], double d)
{
    int split = kind == 0 ? 3 : 2;
    for (int c = 0; c < 3; c++) {
        double alo = INFINITY, ahi = -INFINITY, blo = INFINITY, bhi = -INFINITY;
        for (int i = 0; i < 4; i++) {
            double u = p0[i][c], w = p1[i][c], lo = u < w ? u : w, hi = u < w ? w : u;
            double *plo = i < split ? &alo : &blo, *phi = i < split ? &ahi : &bhi;
            if (lo < *plo) *plo = lo;
            if (hi > *phi) *phi = hi;
        }
        if (blo - ahi >= d || alo - bhi >= d) return 1;
    }
    return 0;
}

double shell_ccd_cubic(const double k[4], double t) { return ((k[3] * t + k[2]) * t + k[1]) * t + k[0]; }

/* The coplanarity cubic's coefficients, f(t) = k[0] + k[1] t + k[2] t^2 + k[3] t^3. */
static void coplanarity_cubic(const double *const s[4], const double *const e[4], double k[4])
{
    double x21[3], x31[3], x41[3], v21[3], v31[3], v41[3], v[4][3], c[3];
    for (int i = 0; i < 4; i++) vec3_sub(v[i], e[i], s[i]);
    vec3_sub(x21, s[1], s[0]); vec3_sub(x31, s[2], s[0]); vec3_sub(x41, s[3], s[0]);
    vec3_sub(v21, v[1], v[0]); vec3_sub(v31, v[2], v[0]); vec3_sub(v41, v[3], v[0]);
    vec3_cross(c, x21, x31); k[0] = vec3_dot(c, x41);
    k[1] = vec3_dot(c, v41);
    vec3_cross(c, v21, x31); k[1] += vec3_dot(c, x41); k[2] = vec3_dot(c, v41);
    vec3_cross(c, x21, v31); k[1] += vec3_dot(c, x41); k[2] += vec3_dot(c, v41);
    vec3_cross(c, v21, v31); k[2] += vec3_dot(c, x41); k[3] = vec3_dot(c, v41);
}

/* Does f keep one sign on [0, 1] by more than its evaluation's rounding? Its Bernstein
 * coefficients k0, k0 + k1/3, k0 + 2 k1/3 + k2/3, f(1) bound it from both sides there. */
static int cubic_clearly_one_signed(const double k[4])
{
    double b1 = k[0] + k[1] / 3, b2 = k[0] + (2 * k[1] + k[2]) / 3, b3 = k[0] + k[1] + k[2] + k[3];
    double lo = k[0], hi = k[0];
    if (b1 < lo) lo = b1;
    if (b2 < lo) lo = b2;
    if (b3 < lo) lo = b3;
    if (b1 > hi) hi = b1;
    if (b2 > hi) hi = b2;
    if (b3 > hi) hi = b3;
    double slack = 16 * DBL_EPSILON * (fabs(k[0]) + fabs(k[1]) + fabs(k[2]) + fabs(k[3]));
    return lo > slack || hi < -slack;
}

int shell_ccd_monotone_pieces(const double k[4], double cuts[4])
{
    /* The roots of f' = 3 k3 t^2 + 2 k2 t + k1 inside (0, 1). */
    int nc = 0;
    cuts[nc++] = 0;
    double A = 3 * k[3], B = 2 * k[2], C = k[1];
    if (fabs(A) > 1e-300) {
        double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            double sq = sqrt(disc), r1 = (-B - sq) / (2 * A), r2 = (-B + sq) / (2 * A);
            if (r1 > r2) { double tmp = r1; r1 = r2; r2 = tmp; }
            if (r1 > 0 && r1 < 1) cuts[nc++] = r1;
            if (r2 > 0 && r2 < 1) cuts[nc++] = r2;
        }
    } else if (fabs(B) > 1e-300) {
        double r1 = -C / B;
        if (r1 > 0 && r1 < 1) cuts[nc++] = r1;
    }
    cuts[nc++] = 1;
    return nc;
}

double shell_ccd_cubic_root(const double k[4], double a, double fa, double b, double fb)
{
    double t = a - fa * (b - a) / (fb - fa);
    if (!(t > a && t < b)) t = 0.5 * (a + b);
    for (int it = 0; it < 200; it++) {
        double ft = shell_ccd_cubic(k, t);
        if (ft == 0) return t;
        if ((ft > 0) == (fa > 0)) { a = t; fa = ft; } else b = t;
        double d = (3 * k[3] * t + 2 * k[2]) * t + k[1], n = t - ft / d;
        if (!(n > a && n < b)) n = 0.5 * (a + b);
        int done = fabs(n - t) <= 0x1p-52 || b - a <= 0x1p-52;
        t = n;
        if (done) break;
    }
    return t;
}

/* Earliest time in [0, 1] at which the pair touches (within tol), or -1. */
static double time_of_impact(int kind, const double *const s[4], const double *const e[4], const double k[4], double tol)
{
    double cuts[4];
    int nc = shell_ccd_monotone_pieces(k, cuts);
    double tol2 = tol * tol;
    for (int i = 0; i + 1 < nc; i++) {
        double a = cuts[i], b = cuts[i + 1], fa = shell_ccd_cubic(k, a), fb = shell_ccd_cubic(k, b);
        if (fa != 0 && fb != 0 && (fa > 0) == (fb > 0)) continue;
        /* No contact possible in [a, b] when the parts stay apart by more than tol. */
        double qa[4][3], qb[4][3];
        for (int j = 0; j < 4; j++) { lerp3(qa[j], s[j], e[j], a); lerp3(qb[j], s[j], e[j], b); }
        if (apart_on_an_axis(kind, (const double (*)[3])qa, (const double (*)[3])qb, 1.0000001 * tol)) continue;
        double t = fa == 0 ? a : fb == 0 ? b : shell_ccd_cubic_root(k, a, fa, b, fb);
        if (pair_distance2(kind, s, e, t) <= tol2) return t;
    }
    return -1;
}

static double norm1(const double a[3]) { return fabs(a[0]) + fabs(a[1]) + fabs(a[2]); }

/* Is the pair's distance at the end of the step at least d? A lower bound first: the distance
 * from the vertex to the triangle's plane, or between the edges' lines, |n . z| / |n| with
 * n = u x w (u, w the triangle's sides or the two edges, z from point 0 to point 3 or 2), taken
 * only when it exceeds d by more than its rounding (bounded through the 1-norms). */
static int ends_at_least(int kind, const double *const s[4], const double *const e[4], double d)
{
    double u[3], w[3], z[3], n[3];
    vec3_sub(u, e[1], e[0]);
    if (kind == SHELL_PAIR_VT) { vec3_sub(w, e[2], e[0]); vec3_sub(z, e[3], e[0]); }
    else { vec3_sub(w, e[3], e[2]); vec3_sub(z, e[2], e[0]); }
    vec3_cross(n, u, w);
    double uw = norm1(u) * norm1(w), f = fabs(vec3_dot(n, z)) - 32 * DBL_EPSILON * uw * norm1(z);
    if (f > 0 && f > (1 + 1e-9) * d * (vec3_length(n) + 32 * DBL_EPSILON * uw)) return 1;
    double end[4][3];
    for (int i = 0; i < 4; i++) memcpy(end[i], e[i], sizeof end[i]);
    return apart_on_an_axis(kind, (const double (*)[3])end, (const double (*)[3])end, d) || !(pair_distance2(kind, s, e, 1) < d * d);
}

double shell_ccd_hit(int kind, const double *const s[4], const double *const e[4], double tol, double thickness)
{
    double k[4];
    coplanarity_cubic(s, e, k);
    if (!cubic_clearly_one_signed(k)) {
        double t = time_of_impact(kind, s, e, k, tol);
        if (t >= 0) return t;
    }
    if (thickness > 0) {
        if (!ends_at_least(kind, s, e, thickness) && pair_distance2(kind, s, e, 0) >= thickness * thickness)
            return 1;
    }
    return -1;
}

/* SPDX-License-Identifier: MIT */
/* The narrow phase of the shell's collision handling (shell_collide.c): one vertex-triangle or
 * edge-edge pair whose four points move on straight lines over a step. Internal to baker/. */
#ifndef SHELL_CCD_H
#define SHELL_CCD_H

/* Kinds of pair: points 0 1 2 a triangle and point 3 a vertex, or points 0 1 and 2 3 two edges. */
enum { SHELL_PAIR_VT = 0, SHELL_PAIR_EE = 1 };

/* The cubic k[0] + k[1] t + k[2] t^2 + k[3] t^3 (Horner). */
double shell_ccd_cubic(const double k[4], double t);

/* Splits [0, 1] at the cubic's critical points inside it: cuts[0] = 0 < ... < cuts[n - 1] = 1,
 * returns n (2 to 4); the cubic is monotone between consecutive cuts. */
int shell_ccd_monotone_pieces(const double k[4], double cuts[4]);

/* A root of the cubic k[0] + k[1] t + k[2] t^2 + k[3] t^3 in [a, b], where it is monotone and
 * fa = f(a), fb = f(b) are nonzero and of opposite signs: Newton steps from the secant's point,
 * kept inside the shrinking bracket (a bisection when a step would leave it), until a step or
 * the bracket is below 2^-52 (t is in [0, 1]). */
double shell_ccd_cubic_root(const double k[4], double a, double fa, double b, double fb);

/* When the pair counts as a hit over the step (points s[i] -> e[i]): the earliest time in
 * [0, 1] at which the four points are coplanar and the pair is within tol, else 1 when it ends
 * closer than thickness having started no closer, else -1. */
double shell_ccd_hit(int kind, const double *const s[4], const double *const e[4], double tol, double thickness);

#endif

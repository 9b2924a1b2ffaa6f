/* SPDX-License-Identifier: MIT */
/* The bakers' shared formulas (bake_util.h): the Bernstein basis every FFD lattice uses
 * against its closed form; the one 3x3 inverse under its two rules for "singular" (deformation
 * transfer's and the lattices' bake_solve3). */
#include <math.h>
#include "bake_util.h"
#include "check.h"
#include "lattice_newton.h"

/* C(n, i) x^i (1 - x)^(n - i), 0 outside 0..n, in long double. */
static long double bernstein_closed(int n, int i, long double x)
{
    if (i < 0 || i > n) return 0;
    long double binomial = 1;
    for (int k = 1; k <= i; k++) binomial = binomial * (n - i + k) / k;
    return binomial * powl(x, i) * powl(1 - x, n - i);
}

static void bernstein_is_the_closed_form_with_its_derivative(void)
{
    static const double xs[] = { 0, 1e-3, 0.1, 0.25, 1.0 / 3, 0.5, 0.7, 0.9, 1 - 1e-3, 1 };
    double w[BAKE_BERNSTEIN_MAX_POINTS], dw[BAKE_BERNSTEIN_MAX_POINTS];
    for (uint32_t points = 1; points <= BAKE_BERNSTEIN_MAX_POINTS; points++)
        for (size_t k = 0; k < sizeof xs / sizeof xs[0]; k++) {
            const double x = xs[k];
            const int deg = (int)points - 1;
            bake_bernstein(points, x, w, dw);
            double sum = 0, dsum = 0;
            for (int i = 0; i <= deg; i++) {
                double expect = (double)bernstein_closed(deg, i, x);
                double dexpect = deg ? (double)(deg * (bernstein_closed(deg - 1, i - 1, x) - bernstein_closed(deg - 1, i, x))) : 0;
                CHECK_MSG(fabs(w[i] - expect) <= 1e-14, "points %u, x %g: w[%d] = %.17g, closed form %.17g", points, x, i,
                          w[i], expect);
                CHECK_MSG(fabs(dw[i] - dexpect) <= 1e-12 * (1 + fabs(dexpect)),
                          "points %u, x %g: dw[%d] = %.17g, closed form %.17g", points, x, i, dw[i], dexpect);
                sum += w[i];
                dsum += dw[i];
            }
            CHECK_MSG(fabs(sum - 1) <= 1e-14, "points %u, x %g: weights sum to %.17g", points, x, sum);
            CHECK_MSG(fabs(dsum) <= 1e-11, "points %u, x %g: derivatives sum to %.17g", points, x, dsum);
        }
    /* the ends interpolate exactly: the first and the last control point */
    bake_bernstein(5, 0, w, dw);
    CHECK(w[0] == 1 && w[1] == 0 && w[4] == 0);
    bake_bernstein(5, 1, w, dw);
    CHECK(w[4] == 1 && w[0] == 0 && w[3] == 0);
}

/* One inverse, two rules: mat3_inverse with min_det 0 (deformation transfer's edge matrices)
 * inverts anything with a finite nonzero determinant; bake_solve3 (the lattices' Newton steps)
 * refuses a matrix singular relative to its size. */
static void inverse_and_solve_differ_only_in_what_they_call_singular(void)
{
    const double m[9] = { 2, 1, 0, -1, 3, 0.5, 0.25, 0, 4 }, b[3] = { 1, -2, 3 };
    double inv[9], product[9], x[3], back[3];
    CHECK(mat3_inverse(inv, m, 0));
    mat3_mul(product, inv, m);
    for (int i = 0; i < 9; i++) CHECK_NEAR(product[i], i % 4 == 0 ? 1 : 0, 1e-15);
    CHECK(bake_solve3(m, b, x));
    mat3_mul_vec(back, m, x);
    for (int i = 0; i < 3; i++) CHECK_NEAR(back[i], b[i], 1e-14);
    /* the same inverse: bake_solve3 is J^-1 b with mat3_inverse's J^-1, bit for bit */
    double expect[3];
    mat3_mul_vec(expect, inv, b);
    CHECK(x[0] == expect[0] && x[1] == expect[1] && x[2] == expect[2]);

    /* a sliver: det 1e-16 of a unit-sized matrix (an edge matrix of a triangle about 1e-10 of its
     * longest edge squared): transfer inverts it, the lattices' solve refuses it */
    const double sliver[9] = { 1, 0, 0, 0, 1e-8, 0, 0, 0, 1e-8 };
    double sentinel[9] = { 7, 7, 7, 7, 7, 7, 7, 7, 7 };
    x[0] = x[1] = x[2] = 7;
    CHECK(mat3_inverse(inv, sliver, 0));
    CHECK_NEAR(inv[4], 1e8, 1e-7);
    CHECK(!bake_solve3(sliver, b, x));
    CHECK(x[0] == 7 && x[1] == 7 && x[2] == 7);
    /* just above the relative cut, the solve takes it */
    const double thin[9] = { 1, 0, 0, 0, 2e-7, 0, 0, 0, 1e-7 };
    CHECK(bake_solve3(thin, b, x));
    CHECK_NEAR(x[1], -1e7, 1e-7);

    /* singular and not finite: neither, and the output stays untouched */
    const double flat[9] = { 1, 2, 3, 2, 4, 6, 0, 1, 1 }, inf[9] = { INFINITY, 0, 0, 0, 1, 0, 0, 0, 1 },
                 nan[9] = { NAN, 0, 0, 0, 1, 0, 0, 0, 1 };
    CHECK(!mat3_inverse(sentinel, flat, 0) && !mat3_inverse(sentinel, inf, 0) && !mat3_inverse(sentinel, nan, 0));
    for (int i = 0; i < 9; i++) CHECK(sentinel[i] == 7);
    CHECK(!bake_solve3(flat, b, x) && !bake_solve3(inf, b, x) && !bake_solve3(nan, b, x));
}

CHECK_MAIN(CASE(bernstein_is_the_closed_form_with_its_derivative),
           CASE(inverse_and_solve_differ_only_in_what_they_call_singular))

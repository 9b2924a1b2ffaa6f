/* SPDX-License-Identifier: MIT */
/* The bakers' shared formulas (bake_util.h): the Bernstein basis every FFD lattice uses
 * against its closed form, and where two versions of a formula are kept on purpose, both. */
#include <math.h>
#include "bake_util.h"
#include "check.h"

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

CHECK_MAIN(CASE(bernstein_is_the_closed_form_with_its_derivative))

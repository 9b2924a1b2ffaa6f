/* SPDX-License-Identifier: MIT */
/* Extended free-form deformation with a prism lattice.
 *
 * Papers:
 * - S. Coquillart, "Extended Free-Form Deformation: A Sculpturing Tool for 3D Geometric
 *   Modeling", SIGGRAPH 1990: lattices built from blocks that are not parallelepipeds (prisms
 *   among them), joined by sharing control points, with local coordinates found numerically.
 * - G. Farin, "Triangular Bernstein-Bezier patches", CAGD 3 (1986), for the Bernstein basis
 *   over a triangle, B^n_abc(l0, l1, l2) = n!/(a! b! c!) l0^a l1^b l2^c (a + b + c = n).
 *
 * Conventions fixed here:
 * - The cross-section is a regular polygon of `sides` corners around the centre (or the
 *   caller's polygon, star-shaped from the centre), split into
 *   `sides` triangles (centre, corner w, corner w + 1); extruded along the axis each is a wedge
 *   block. A block is the Bernstein triangle of degree n in (l1, l2) times the Bernstein
 *   polynomial of degree layers-1 in u. Its control point (a, b, c; k) is the lattice point on
 *   ring r = b + c at position w r + c (mod sides r) of layer k.
 * - Neighbouring wedges share the control points of their common face (ring positions that are
 *   multiples of r, and the centre): on that face both blocks reduce to the same univariate
 *   Bernstein form, so the deformation is C0 across every seam. C1 is not imposed.
 * - Displacement form, as ffd.c: X' = X + a sum w d. The weights sum to 1 and reproduce the
 *   rest map, so an unmoved lattice is the identity and moving every control point by one
 *   affine map moves X by that map. Linear in a: one target is exact.
 * - Point location: wedges are tried starting with the one whose spokes enclose the point's
 *   direction from the axis, then outwards by wedge index; the first wedge where Newton converges with all three
 *   barycentric coordinates and u in [-1e-9, 1 + 1e-9] owns the point (a point on a seam goes
 *   to the wedge on whose first spoke it lies). Newton starts from the inverse of the affine map through
 *   the wedge's four corner points (exact for the regular lattice), clamps iterates into
 *   [-0.5, 1.5] and stops at 1e-10 of the lattice size or after 50 iterations. A wedge whose
 *   corner map puts the point more than 1/2 outside it is not searched (the point is outside).
 */
#include <math.h>
#include <string.h>
#include "ffd_prism.h"
#include "bake_util.h"
#include "lattice_newton.h"

#define PI 3.14159265358979323846
#define MAX_SIDES 64
#define MAX_DEGREE 16
#define MAX_LAYERS 64
_Static_assert(MAX_LAYERS <= BAKE_BERNSTEIN_MAX_POINTS, "bake_bernstein takes every layer count");

mk_result mk_prism_prepare(mk_prism_lattice *c, mk_error *err)
{
    if (c->sides < 3 || c->sides > MAX_SIDES)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "sides: %u (need 3..%d)", c->sides, MAX_SIDES);
    if (c->degree < 1 || c->degree > MAX_DEGREE)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "degree: %u (need 1..%d)", c->degree, MAX_DEGREE);
    if (c->layers < 2 || c->layers > MAX_LAYERS)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "layers: %u (need 2..%d)", c->layers, MAX_LAYERS);
    for (int k = 0; k < 3; k++)
        if (!isfinite(c->center[k]) || !isfinite(c->axis[k]) || !isfinite(c->reference[k]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "center/axis/reference: not finite");
    if (!c->section && (!isfinite(c->radius) || !(c->radius > 0)))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "radius: must be > 0 (got %g)", c->radius);
    mk_result r = bake_axial_frame(c->axis, c->reference, c->frame, &c->height, err);
    if (r != MK_OK) return r;
    c->size = fmax(c->height, c->section ? 0 : c->radius);
    if (c->section) {
        /* Each triangle turns left and the angles add up to one turn. */
        double turn = 0;
        for (uint32_t w = 0; w < c->sides; w++) {
            const double *a = c->section + 2 * w, *b = c->section + 2 * ((w + 1) % c->sides);
            if (!isfinite(a[0]) || !isfinite(a[1]))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "section: corner %u is not finite", w);
            double cross = a[0] * b[1] - a[1] * b[0], dot = a[0] * b[0] + a[1] * b[1];
            if (!(cross > 1e-12 * (a[0] * a[0] + a[1] * a[1] + b[0] * b[0] + b[1] * b[1])))
                return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                    "section: corners %u and %u do not turn counter-clockwise about the centre", w,
                                    (w + 1) % c->sides);
            turn += atan2(cross, dot);
            c->size = fmax(c->size, sqrt(a[0] * a[0] + a[1] * a[1]));
        }
        if (!(fabs(turn - 2 * PI) < 1e-6))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "section: the corners go %.4g times round the centre (must be once)", turn / (2 * PI));
    }
    size_t values = 3 * (size_t)mk_prism_point_count(c);
    for (size_t i = 0; i < values; i++)
        if ((c->rest && !isfinite(c->rest[i])) || (c->displacements && !isfinite(c->displacements[i])))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "control point %zu: not finite", i / 3);
    return MK_OK;
}

uint32_t mk_prism_layer_points(const mk_prism_lattice *c)
{
    return 1 + c->sides * c->degree * (c->degree + 1) / 2;
}

uint32_t mk_prism_point_count(const mk_prism_lattice *c)
{
    return c->layers * mk_prism_layer_points(c);
}

uint32_t mk_prism_index(const mk_prism_lattice *c, uint32_t ring, uint32_t position, uint32_t layer)
{
    return layer * mk_prism_layer_points(c) + (ring ? 1 + c->sides * ring * (ring - 1) / 2 + position : 0);
}

/* Corner w of the polygon relative to the centre. */
static void corner(const mk_prism_lattice *c, uint32_t w, double out[3])
{
    double a = 2 * PI * (w % c->sides) / c->sides, x = c->radius * cos(a), y = c->radius * sin(a);
    if (c->section) { x = c->section[2 * (w % c->sides)]; y = c->section[2 * (w % c->sides) + 1]; }
    for (int q = 0; q < 3; q++) out[q] = x * c->frame[0][q] + y * c->frame[1][q];
}

void mk_prism_control_point(const mk_prism_lattice *c, uint32_t ring, uint32_t position, uint32_t layer, double out[3])
{
    double u = (double)layer / (c->layers - 1), A[3] = { 0, 0, 0 }, B[3] = { 0, 0, 0 }, lb = 0, lc = 0;
    if (ring) {
        uint32_t w = position / ring, cc = position % ring;
        corner(c, w, A);
        corner(c, w + 1, B);
        lb = (double)(ring - cc) / c->degree;
        lc = (double)cc / c->degree;
    }
    for (int q = 0; q < 3; q++) out[q] = c->center[q] + lb * A[q] + lc * B[q] + u * c->height * c->frame[2][q];
}

/* All Bernstein triangle values of degree n at (1 - s - t, s, t): tri[b (n + 1) + c] = B^n_abc. */
static void triangle_bernstein(int n, double s, double t, double *tri)
{
    double l0 = 1 - s - t;
    for (int b = 0; b <= n; b++)
        for (int cc = 0; b + cc <= n; cc++) {
            int a = n - b - cc;
            double coefficient = 1;  /* n! / (a! b! c!) = C(n, b + c) C(b + c, c) */
            for (int k = 1; k <= b + cc; k++) coefficient = coefficient * (a + k) / k;
            for (int k = 1; k <= cc; k++) coefficient = coefficient * (b + k) / k;
            tri[b * (n + 1) + cc] = coefficient * pow(l0, a) * pow(s, b) * pow(t, cc);
        }
}

/* sum over wedge w of the weights times either the rest points (disp NULL) or amplitude times
 * the displacements, with the derivatives d/d(l1, l2, u) in J (row-major; may be NULL). */
static void wedge_eval(const mk_prism_lattice *c, uint32_t w, const double q[3], const double *disp, double amplitude,
                       double out[3], double J[9])
{
    int n = (int)c->degree;
    double tri[(MAX_DEGREE + 1) * (MAX_DEGREE + 1)], low[(MAX_DEGREE + 1) * (MAX_DEGREE + 1)];
    double wu[MAX_LAYERS], dwu[MAX_LAYERS];
    triangle_bernstein(n, q[0], q[1], tri);
    triangle_bernstein(n - 1, q[0], q[1], low);
    bake_bernstein(c->layers, q[2], wu, dwu);
    memset(out, 0, 3 * sizeof(double));
    if (J) memset(J, 0, 9 * sizeof(double));
    for (uint32_t k = 0; k < c->layers; k++)
        for (int b = 0; b <= n; b++)
            for (int cc = 0; b + cc <= n; cc++) {
                uint32_t r = (uint32_t)(b + cc), m = r ? (w * r + (uint32_t)cc) % (c->sides * r) : 0;
                uint32_t index = mk_prism_index(c, r, m, k);
                double p[3];
                if (disp)
                    for (int x = 0; x < 3; x++) p[x] = amplitude * disp[3 * (size_t)index + x];
                else if (c->rest)
                    memcpy(p, c->rest + 3 * (size_t)index, sizeof p);
                else
                    mk_prism_control_point(c, r, m, k, p);
                double bt = tri[b * (n + 1) + cc], wgt = bt * wu[k];
                for (int x = 0; x < 3; x++) out[x] += wgt * p[x];
                if (!J) continue;
                /* d/ds B^n_abc = n (B^(n-1)_(a, b-1, c) - B^(n-1)_(a-1, b, c)), likewise d/dt with c. */
                int a = n - b - cc;
                double lb = b > 0 ? low[(b - 1) * n + cc] : 0, lc = cc > 0 ? low[b * n + cc - 1] : 0;
                double la = a > 0 ? low[b * n + cc] : 0;
                double ds = n * (lb - la) * wu[k], dt = n * (lc - la) * wu[k], du = bt * dwu[k];
                for (int x = 0; x < 3; x++) {
                    J[3 * x + 0] += ds * p[x];
                    J[3 * x + 1] += dt * p[x];
                    J[3 * x + 2] += du * p[x];
                }
            }
}

void mk_prism_rest_map(const mk_prism_lattice *c, uint32_t wedge, const double q[3], double out[3], double J[9])
{
    wedge_eval(c, wedge, q, NULL, 0, out, J);
}

typedef struct wedge_map { const mk_prism_lattice *lattice; uint32_t wedge; } wedge_map;

static void rest_map(const void *user, const double q[3], double F[3], double J[9])
{
    const wedge_map *m = user;
    wedge_eval(m->lattice, m->wedge, q, NULL, 0, F, J);
}

/* How far q lies outside the wedge: the most negative barycentric coordinate or u outside [0, 1]. */
static double outside_by(const double q[3])
{
    return fmax(fmax(-q[0], -q[1]), fmax(fmax(q[0] + q[1] - 1, -q[2]), q[2] - 1));
}

/* Newton in wedge w from the affine map through its corner points. Returns the residual |F(q) - p|,
 * or 0 with q from the corner map alone (*far set) when that puts p more than 1/2 outside. */
static double locate_in_wedge(const mk_prism_lattice *c, uint32_t w, const double p[3], double target, double q[3],
                              uint32_t *iterations, int *far)
{
    double o0[3], a[3], b[3], o1[3], J[9], rel[3];
    wedge_map map = { c, w };
    /* Corner points of the block: q = 0, (1, 0, 0), (0, 1, 0), (0, 0, 1). */
    double e[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    rest_map(&map, e[0], o0, NULL);
    rest_map(&map, e[1], a, NULL);
    rest_map(&map, e[2], b, NULL);
    rest_map(&map, e[3], o1, NULL);
    for (int x = 0; x < 3; x++) {
        J[3 * x + 0] = a[x] - o0[x];
        J[3 * x + 1] = b[x] - o0[x];
        J[3 * x + 2] = o1[x] - o0[x];
    }
    vec3_sub(rel, p, o0);
    if (!bake_solve3(J, rel, q)) { q[0] = q[1] = 1.0 / 3; q[2] = 0.5; }
    *iterations = 0;
    *far = outside_by(q) > 0.5;
    if (*far) return 0;
    bake_newton newton = { rest_map, &map, { -0.5, -0.5, -0.5 }, { 1.5, 1.5, 1.5 }, -1, target, 50 };
    return bake_newton_solve(&newton, p, q, iterations);
}

mk_result mk_prism_coordinates(const mk_prism_lattice *c, const double p[3], double coords[4], uint32_t *iterations,
                               mk_error *err)
{
    double size = c->size, target = 1e-10 * size, rel[3];
    vec3_sub(rel, p, c->center);
    /* The wedge whose spokes (centre to corner w, w + 1) enclose p's direction: corner w on
     * the right of it or along it, corner w + 1 on its left (0 for a point on the axis). */
    double x = vec3_dot(rel, c->frame[0]), y = vec3_dot(rel, c->frame[1]);
    uint32_t first = 0;
    for (uint32_t w = 0; w < c->sides; w++) {
        double a[3], b[3];
        corner(c, w, a);
        corner(c, w + 1, b);
        double ax = vec3_dot(a, c->frame[0]), ay = vec3_dot(a, c->frame[1]);
        double bx = vec3_dot(b, c->frame[0]), by = vec3_dot(b, c->frame[1]);
        if (ax * y - ay * x >= 0 && bx * y - by * x < 0) { first = w; break; }
    }
    /* The wedge that owns p, else the located wedge p is least outside of, and the wedge where
     * Newton failed with the smallest residual. */
    double best_q[3] = { 0, 0, 0 }, best_out = INFINITY, failed_res = INFINITY;
    uint32_t best_w = first, best_it = 0, failed_w = UINT32_MAX;
    for (uint32_t tried = 0; tried < c->sides; tried++) {
        /* first, first + 1, first - 1, first + 2, ... */
        uint32_t step = (tried + 1) / 2, w = tried % 2 ? (first + step) % c->sides : (first + c->sides - step) % c->sides;
        double q[3];
        uint32_t it = 0;
        int far = 0;
        double res = locate_in_wedge(c, w, p, target, q, &it, &far);
        if (!(res <= target)) {
            if (res < failed_res || failed_w == UINT32_MAX) { failed_res = res; failed_w = w; }
            continue;
        }
        double out = outside_by(q);
        if (out < best_out) {
            best_out = out; best_w = w; best_it = it;
            memcpy(best_q, q, sizeof q);
        }
        if (out <= 1e-9) break;
    }
    coords[0] = best_w;
    memcpy(coords + 1, best_q, sizeof best_q);
    if (iterations) *iterations = best_it;
    if (best_out <= 1e-9) return MK_OK;
    if (failed_w != UINT32_MAX)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "in no wedge: Newton did not converge in wedge %u (residual %.3g of the lattice size; "
                            "the rest lattice may fold there)", failed_w, failed_res / size);
    return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                        "outside the lattice (nearest wedge %u: barycentric (%.4g, %.4g, %.4g), u = %.4g; all must be in [0, 1])",
                        best_w, 1 - best_q[0] - best_q[1], best_q[0], best_q[1], best_q[2]);
}

void mk_prism_eval(const mk_prism_lattice *c, double amplitude, const double coords[4], const double p[3], double out[3])
{
    double moved[3];
    wedge_eval(c, (uint32_t)coords[0], coords + 1, c->displacements, amplitude, moved, NULL);
    for (int k = 0; k < 3; k++) out[k] = p[k] + moved[k];
}

static mk_result locate(const void *lattice, const double p[3], double *coords, mk_error *err)
{
    return mk_prism_coordinates(lattice, p, coords, NULL, err);
}

mk_result mk_prism_bind(const mk_prism_lattice *c, const mk_raw_mesh *mesh, double *coords, mk_error *err)
{
    return bake_lattice_bind(c, locate, 4, mesh, coords, err);
}

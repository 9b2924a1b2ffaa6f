/* SPDX-License-Identifier: MIT */
/* Small shared pieces of the bakers: 3-vector / 3x3 helpers (double precision, row-major
 * 3x3 as m[3*row + col]), the lattices' Bernstein basis, mesh bounding box, and normals
 * recomputed from a deformed surface.
 * Internal to baker/ (not installed). */
#ifndef BAKE_UTIL_H
#define BAKE_UTIL_H

#include <math.h>
#include "raw.h"

static inline double vec3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void vec3_cross(double out[3], const double a[3], const double b[3])
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
           z = a[0] * b[1] - a[1] * b[0];
    out[0] = x; out[1] = y; out[2] = z;
}
static inline void vec3_sub(double out[3], const double a[3], const double b[3])
{
    out[0] = a[0] - b[0]; out[1] = a[1] - b[1]; out[2] = a[2] - b[2];
}

static inline double vec3_length(const double a[3]) { return sqrt(vec3_dot(a, a)); }
/* Normalizes in place; returns the old length (0 leaves the vector unchanged). */
static inline double vec3_normalize(double a[3])
{
    double l = vec3_length(a);
    if (l > 0) { a[0] /= l; a[1] /= l; a[2] /= l; }
    return l;
}
static inline void mat3_mul_vec(double out[3], const double m[9], const double v[3])
{
    double x = m[0] * v[0] + m[1] * v[1] + m[2] * v[2];
    double y = m[3] * v[0] + m[4] * v[1] + m[5] * v[2];
    double z = m[6] * v[0] + m[7] * v[1] + m[8] * v[2];
    out[0] = x; out[1] = y; out[2] = z;
}
static inline void mat3_mul(double out[9], const double a[9], const double b[9])
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
    for (int i = 0; i < 9; i++) out[i] = r[i];
}
/* Union-find: the root of v's set, halving the path on the way (parent[root] == root). */
static inline uint32_t bake_find_root(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v) {
        parent[v] = parent[parent[v]];
        v = parent[v];
    }
    return v;
}

static inline double mat3_det(const double m[9])
{
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}
/* cof(J) = det(J) J^-T without a division: (Ja) x (Jb) = cof(J)(a x b), so cof(J) n is the
 * normal transform that stays consistent with the winding of deformed triangles. */
static inline void mat3_cofactor(double out[9], const double m[9])
{
    double c[9];
    c[0] = m[4] * m[8] - m[5] * m[7]; c[1] = m[5] * m[6] - m[3] * m[8]; c[2] = m[3] * m[7] - m[4] * m[6];
    c[3] = m[2] * m[7] - m[1] * m[8]; c[4] = m[0] * m[8] - m[2] * m[6]; c[5] = m[1] * m[6] - m[0] * m[7];
    c[6] = m[1] * m[5] - m[2] * m[4]; c[7] = m[2] * m[3] - m[0] * m[5]; c[8] = m[0] * m[4] - m[1] * m[3];
    for (int i = 0; i < 9; i++) out[i] = c[i];
}
/* The inverse cof(m)^T / det m, when |det m| > min_det and det m is finite; else 0 and out
 * untouched. */
static inline int mat3_inverse(double out[9], const double m[9], double min_det)
{
    double det = mat3_det(m), cof[9];
    if (!(fabs(det) > min_det) || !isfinite(det)) return 0;
    mat3_cofactor(cof, m);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) out[3 * r + c] = cof[3 * c + r] / det;
    return 1;
}
/* Rotation matrix about a unit axis by angle (radians), right-hand rule. */
static inline void mat3_rotation(double out[9], const double axis[3], double angle)
{
    double c = cos(angle), s = sin(angle), t = 1 - c;
    double x = axis[0], y = axis[1], z = axis[2];
    out[0] = t * x * x + c;     out[1] = t * x * y - s * z; out[2] = t * x * z + s * y;
    out[3] = t * x * y + s * z; out[4] = t * y * y + c;     out[5] = t * y * z - s * x;
    out[6] = t * x * z - s * y; out[7] = t * y * z + s * x; out[8] = t * z * z + c;
}

/* Scale-free conditioning of a Jacobian, r = det J / (|J|_F / sqrt 3)^3: 1 for a rotation,
 * <= 0 when the map folds. Vertices with r <= BAKE_DEGENERATE_R get their normal from the
 * deformed surface instead of cof(J) n (docs/baking.md, "Normals"). */
#define BAKE_DEGENERATE_R 1e-6
double bake_jacobian_quality(const double J[9]);

/* Bernstein weights B_i^deg(x), deg = points - 1, into w[0 .. points) and their derivatives
 * d/dx = deg (B_(i-1)^(deg-1) - B_i^(deg-1)) into dw: the basis of every FFD lattice axis that
 * is not a B-spline (ffd.c, ffd_cylinder.c, ffd_prism.c). 1 <= points <= BAKE_BERNSTEIN_MAX_POINTS. */
#define BAKE_BERNSTEIN_MAX_POINTS 64
void bake_bernstein(uint32_t points, double x, double *w, double *dw);

/* Axis-aligned bounds of the mesh's base positions and the diagonal length (> 0 is not
 * guaranteed: a single point has diagonal 0). */
void bake_bounds(const mk_raw_mesh *mesh, double min[3], double max[3], double *diagonal);

/* Normals recomputed from deformed positions (3 doubles per vertex) with the base triangles,
 * area-weighted, for the vertices where flags[v] != 0 (flags NULL: all). Render vertices with
 * the same base position and base normal are smoothed together, so UV seams do not show and
 * hard edges stay hard. Writes unit normals into normals_out (3 per vertex) for those vertices;
 * a vertex without any non-degenerate triangle keeps its base normal. Uses `arena` for scratch. */
mk_result bake_surface_normals(const mk_raw_mesh *mesh, const double *positions,
                                  const unsigned char *flags, double *normals_out, mk_arena *arena,
                                  mk_error *err);



/* A deformation given point by point with its Jacobian (FFD, Barr): out = f_a(p),
 * J = df_a/dp (row-major). bake_pointwise_eval turns it into mesh positions, normals
 * n' = normalize(cof(J) n) and tangents t' = J t orthogonalized against n' (w is kept by the
 * runtime), with the det J <= 0 policy: such vertices are counted in *inverted and take their
 * normal from the deformed surface (bake_surface_normals). */
typedef void (*bake_point_map)(const void *user, double amplitude, const double p[3], double out[3],
                             double J[9]);
typedef struct bake_pointwise {
    const mk_raw_mesh *mesh;
    bake_point_map map;
    const void *user;
    mk_arena *scratch;         /* for the per-evaluation flags */
} bake_pointwise;
/* Matches mk_deformer.eval (user = bake_pointwise *). */
mk_result bake_pointwise_eval(void *pointwise, double amplitude, double *positions, double *normals,
                            double *tangents, uint32_t *inverted, mk_error *err);

/* Seconds from a wall clock (timespec_get, C11). */
double bake_now(void);

#endif

/* Shared baker helpers: bounds, welding, normals from a deformed surface, the point-map
 * evaluator used by FFD and Barr, timing.
 *
 * Conventions fixed here:
 * - Normal transform N' = normalize(cof(J) N), cof(J) = det(J) J^-T, never dividing by det J;
 *   cof(J) N stays consistent with the winding of the deformed triangles even where the map
 *   folds, since (Ja) x (Jb) = cof(J)(a x b) (Barr 1984; notes A1.1 "Policy when det J <= 0").
 * - A vertex whose scale-free conditioning det J / (|J|_F / sqrt 3)^3 is <= 1e-6 is
 *   "inverted": counted, and its normal comes from the deformed surface (area-weighted face
 *   normals, smoothed over render vertices with equal base position and base normal).
 * - Tangents: T' = J T, Gram-Schmidt against N'; the runtime keeps the handedness w.
 * - Welding for the solvers: bit-identical float positions (-0 == +0) are one vertex.
 */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bake_util.h"

double mk_bake_jacobian_quality(const double J[9])
{
    double f2 = 0;
    for (int i = 0; i < 9; i++) f2 += J[i] * J[i];
    if (!(f2 > 0)) return 0;
    double s = sqrt(f2 / 3.0);
    return mk_mat3_det(J) / (s * s * s);
}

void mk_bake_bounds(const mk_raw_mesh *mesh, double min[3], double max[3], double *diagonal)
{
    for (int c = 0; c < 3; c++) { min[c] = 0; max[c] = 0; }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        for (int c = 0; c < 3; c++) {
            double x = mesh->positions[3 * (size_t)v + c];
            if (v == 0 || x < min[c]) min[c] = x;
            if (v == 0 || x > max[c]) max[c] = x;
        }
    double d[3] = { max[0] - min[0], max[1] - min[1], max[2] - min[2] };
    if (diagonal) *diagonal = mk_len3(d);
}

/* Sort records: 6 float bit patterns (position, normal) and the vertex. */
typedef struct weld_key {
    uint32_t bits[6];
    uint32_t vertex;
} weld_key;

static int weld_key_cmp(const void *pa, const void *pb)
{
    const weld_key *a = pa, *b = pb;
    for (int i = 0; i < 6; i++)
        if (a->bits[i] != b->bits[i]) return a->bits[i] < b->bits[i] ? -1 : 1;
    /* Tie-break on the vertex so the order (and hence the output) is deterministic. */
    return a->vertex < b->vertex ? -1 : a->vertex > b->vertex;
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    if (f == 0.0f) f = 0.0f;   /* -0 and +0 weld together */
    memcpy(&u, &f, 4);
    return u;
}

static weld_key *make_keys(const mk_raw_mesh *mesh, int with_normals, mk_arena *arena)
{
    weld_key *keys = mk_arena_array(arena, mesh->vertex_count ? mesh->vertex_count : 1, sizeof *keys);
    if (!keys) return NULL;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        for (int c = 0; c < 3; c++) {
            keys[v].bits[c] = float_bits(mesh->positions[3 * (size_t)v + c]);
            keys[v].bits[3 + c] = with_normals && mesh->normals
                ? float_bits(mesh->normals[3 * (size_t)v + c]) : 0;
        }
        keys[v].vertex = v;
    }
    qsort(keys, mesh->vertex_count, sizeof *keys, weld_key_cmp);
    return keys;
}

uint32_t *mk_bake_weld(const mk_raw_mesh *mesh, mk_arena *arena, uint32_t *welded_count)
{
    uint32_t *weld = mk_arena_array(arena, mesh->vertex_count ? mesh->vertex_count : 1, sizeof *weld);
    weld_key *keys = make_keys(mesh, 0, arena);
    if (!weld || !keys) return NULL;
    /* Welded indices are assigned in order of first render vertex so vertex order is kept
     * as much as possible (better locality for the solver's ordering). */
    uint32_t *first = mk_arena_array(arena, mesh->vertex_count ? mesh->vertex_count : 1, sizeof *first);
    if (!first) return NULL;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) first[v] = UINT32_MAX;
    for (uint32_t k = 0; k < mesh->vertex_count;) {
        uint32_t e = k + 1;
        while (e < mesh->vertex_count && memcmp(keys[e].bits, keys[k].bits, 12) == 0) e++;
        for (uint32_t q = k; q < e; q++) first[keys[q].vertex] = keys[k].vertex; /* smallest v */
        k = e;
    }
    uint32_t count = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        if (first[v] == v) weld[v] = count++;
        else weld[v] = weld[first[v]];
    }
    mk_arena_release(arena, keys);
    mk_arena_release(arena, first);
    *welded_count = count;
    return weld;
}

mk_result mk_bake_surface_normals(const mk_raw_mesh *mesh, const double *positions,
                                  const unsigned char *flags, double *normals_out, mk_arena *arena,
                                  mk_error *err)
{
    size_t n = mesh->vertex_count;
    double *acc = mk_arena_array(arena, n ? 3 * n : 1, sizeof *acc);
    if (!acc) return mk_error_oom(err, "surface normals");
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *tri = mesh->triangles + 3 * (size_t)t;
        if (tri[0] >= n || tri[1] >= n || tri[2] >= n) continue;
        const double *a = positions + 3 * (size_t)tri[0], *b = positions + 3 * (size_t)tri[1],
                     *c = positions + 3 * (size_t)tri[2];
        double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
        double e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        double fn[3];
        mk_cross3(fn, e1, e2);  /* length = 2 * area: area weighting for free */
        for (int k = 0; k < 3; k++)
            for (int c3 = 0; c3 < 3; c3++) acc[3 * (size_t)tri[k] + c3] += fn[c3];
    }
    /* Smooth over render vertices with the same base position and base normal. */
    weld_key *keys = make_keys(mesh, 1, arena);
    if (!keys) { mk_arena_release(arena, acc); return mk_error_oom(err, "surface normals"); }
    for (size_t k = 0; k < n;) {
        size_t e = k + 1;
        while (e < n && memcmp(keys[e].bits, keys[k].bits, sizeof keys[k].bits) == 0) e++;
        double sum[3] = { 0, 0, 0 };
        for (size_t q = k; q < e; q++)
            for (int c = 0; c < 3; c++) sum[c] += acc[3 * (size_t)keys[q].vertex + c];
        double len = mk_normalize3(sum);
        for (size_t q = k; q < e; q++) {
            uint32_t v = keys[q].vertex;
            if (flags && !flags[v]) continue;
            for (int c = 0; c < 3; c++)
                normals_out[3 * (size_t)v + c] = len > 0 ? sum[c]
                    : (mesh->normals ? mesh->normals[3 * (size_t)v + c] : 0);
        }
        k = e;
    }
    mk_arena_release(arena, keys);
    mk_arena_release(arena, acc);
    return MK_OK;
}

double mk_bake_now(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

mk_result mk_pointwise_eval(void *pointwise, double amplitude, double *positions, double *normals,
                            double *tangents, uint32_t *inverted, mk_error *err)
{
    const mk_pointwise *pw = pointwise;
    const mk_raw_mesh *mesh = pw->mesh;
    size_t n = mesh->vertex_count;
    unsigned char *flags = NULL;
    uint32_t bad = 0;
    for (size_t v = 0; v < n; v++) {
        double p[3] = { mesh->positions[3 * v], mesh->positions[3 * v + 1], mesh->positions[3 * v + 2] };
        double J[9];
        pw->map(pw->user, amplitude, p, positions + 3 * v, J);
        if (!normals) continue;
        double q = mk_bake_jacobian_quality(J);
        double *nv = normals + 3 * v;
        const float *n0 = mesh->normals + 3 * v;
        if (!(q > MK_BAKE_DEGENERATE_R)) {
            if (!flags) {
                flags = mk_arena_array(pw->scratch, n ? n : 1, 1);
                if (!flags) return mk_error_oom(err, "normal flags");
            }
            flags[v] = 1;
            bad++;
        } else {
            double cof[9], nb[3] = { n0[0], n0[1], n0[2] };
            mk_mat3_cofactor(cof, J);
            mk_mat3_mul_vec(nv, cof, nb);
            if (!(mk_normalize3(nv) > 0)) { nv[0] = n0[0]; nv[1] = n0[1]; nv[2] = n0[2]; }
        }
        if (tangents) {
            const float *t0 = mesh->tangents + 4 * v;
            double tb[3] = { t0[0], t0[1], t0[2] }, *tv = tangents + 3 * v;
            mk_mat3_mul_vec(tv, J, tb);
            /* Gram-Schmidt against the new normal happens after flagged normals are known. */
        }
    }
    if (flags) {
        mk_result r = mk_bake_surface_normals(mesh, positions, flags, normals, pw->scratch, err);
        mk_arena_release(pw->scratch, flags);
        if (r != MK_OK) return r;
    }
    if (tangents)
        for (size_t v = 0; v < n; v++) {
            double *tv = tangents + 3 * v, *nv = normals + 3 * v;
            double d = mk_dot3(tv, nv);
            for (int c = 0; c < 3; c++) tv[c] -= d * nv[c];
            if (!(mk_normalize3(tv) > 0))
                for (int c = 0; c < 3; c++) tv[c] = mesh->tangents[4 * v + (size_t)c];
        }
    if (inverted) *inverted = bad;
    return MK_OK;
}

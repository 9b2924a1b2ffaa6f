/* SPDX-License-Identifier: MIT */
/* Deformation transfer (transfer.h): the least-squares fit of the target's deformation
 * gradients to the matched source triangles', factored once and solved per source shape.
 *
 * Conventions fixed here (docs/baking.md, "transfer", writes the system out):
 * - Unknowns: the position-welded target vertices (render vertices with bit-identical positions
 *   are one vertex, so seams do not tear) and one fourth vertex per matched target triangle;
 *   the three coordinates share the matrix and are solved as three right-hand sides.
 * - Energy: sum over the (target triangle j, source triangle m) pairs of |T_j - S'_m|_F^2,
 *   unweighted as in the paper, with T_j = V~_j V_j^-1 (V_j: the target's rest edge matrix,
 *   fourth vertex included) and S'_m = A S_m A^-1 the source triangle's gradient conjugated by
 *   the alignment A. The pairs: every target triangle with its match, and with the iterative
 *   correspondence also every source triangle with the target triangle nearest its fitted
 *   centroid (transfer_register.c fits the source first).
 * - The energy only sees differences of positions: each connected component's translation is
 *   free. One vertex per component (its first welded vertex) is fixed at 0 to make the matrix
 *   definite; after the solve the component is translated so that its triangles' centroids move
 *   on average as the source moves at their matched points (mapped by the alignment A).
 * - Target vertices in no paired triangle (loose or only in degenerate triangles) stay at rest,
 *   and so does a component paired from the source's side only (its translation is unknown).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "transfer.h"
#include "transfer_internal.h"
#include "bake_util.h"
#include "inbetween.h"
#include "mesh_groups.h"
#include "sparse_spd.h"

struct mk_transfer {
    mk_arena arena;
    const mk_raw_mesh *source, *target;
    double A[9], A_inv[9], t[3];
    double *aligned;            /* source rest positions aligned to the target, 3 per vertex */
    double *fitted;             /* iterative: the aligned source fitted to the target, 3 per vertex */
    unsigned char *rest_degenerate; /* per source triangle: no area at rest (aligned), so no gradient */
    bake_tri_grid target_grid;  /* iterative: the target's triangles, for the fit and the pairing */
    double *source_inverse;     /* 9 per source triangle: V^-1 at rest (zeros when degenerate) */
    double *gradient;           /* 9 per source triangle: A S A^-1 of the current shape */
    uint32_t *match;            /* per target triangle: source triangle or UINT32_MAX */
    double *barycentric;        /* 3 per target triangle */
    uint32_t welded;
    uint32_t *weld;             /* render -> welded */
    uint32_t used_count;        /* target triangles in a pair */
    uint32_t *used;             /* their target triangle indices */
    uint32_t *slot;             /* per target triangle: its index in used, UINT32_MAX when in no pair */
    uint32_t pair_count;        /* (target triangle, source triangle) pairs: every match, both ways */
    uint32_t (*pairs)[2];       /* used index, source triangle */
    unsigned char *paired;      /* per source triangle: in a pair */
    uint32_t source_count, *sources; /* the source triangles in a pair, each once */
    double *coef;               /* 12 per used triangle: column c, corner q at [4 c + q] */
    uint32_t *unknown;          /* welded -> unknown row, UINT32_MAX when pinned or unused */
    uint32_t *component;        /* welded -> component, UINT32_MAX when in no matched triangle */
    uint32_t component_count;
    uint32_t unknown_count;     /* welded unknowns, then one fourth vertex per matched triangle */
    double *solution;           /* 3 per welded vertex */
    double *shift;              /* 4 per component: summed offset and count */
    bake_spd spd;
    mk_transfer_stats stats;
};

static void corner(double out[3], const mk_raw_mesh *mesh, uint32_t t, int k)
{
    const float *p = mesh->positions + 3 * (size_t)mesh->triangles[3 * (size_t)t + k];
    out[0] = p[0]; out[1] = p[1]; out[2] = p[2];
}

/* Unknown row of corner q (0..2: the welded vertices, 3: the fourth vertex) of used triangle u. */
static uint32_t variable(const mk_transfer *x, uint32_t u, int q)
{
    if (q == 3) return x->unknown_count - x->used_count + u;
    return x->unknown[x->weld[x->target->triangles[3 * (size_t)x->used[u] + q]]];
}

static mk_result build_system(mk_transfer *x, mk_error *err)
{
    const mk_raw_mesh *tg = x->target;
    uint32_t n = x->welded;
    uint32_t *parent = mk_arena_array(&x->arena, n + 1, sizeof(uint32_t));
    x->unknown = mk_arena_array(&x->arena, n + 1, sizeof(uint32_t));
    x->component = mk_arena_array(&x->arena, n + 1, sizeof(uint32_t));
    x->coef = mk_arena_array(&x->arena, 12 * (size_t)x->used_count + 1, sizeof(double));
    if (!parent || !x->unknown || !x->component || !x->coef) return mk_error_oom(err, "transfer system");
    for (uint32_t v = 0; v < n; v++) { parent[v] = v; x->component[v] = UINT32_MAX; }
    for (uint32_t u = 0; u < x->used_count; u++) {
        const uint32_t *tri = tg->triangles + 3 * (size_t)x->used[u];
        uint32_t a = x->weld[tri[0]];
        for (int k = 0; k < 3; k++) {
            uint32_t ra = bake_find_root(parent, a), rb = bake_find_root(parent, x->weld[tri[k]]);
            if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
            x->component[x->weld[tri[k]]] = 0;  /* used; numbered below */
        }
        /* coefficients of T = V~ V^-1 on (v1, v2, v3, v4) per column c */
        double a3[3], b3[3], c3[3];
        corner(a3, tg, x->used[u], 0); corner(b3, tg, x->used[u], 1); corner(c3, tg, x->used[u], 2);
        if (!bake_transfer_coefficients(x->coef + 12 * (size_t)u, a3, b3, c3))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "target triangle %u is degenerate", x->used[u]);
    }
    /* components (numbered by their smallest welded vertex) and the pinned vertex of each */
    x->component_count = 0;
    uint32_t welded_unknowns = 0;
    for (uint32_t v = 0; v < n; v++) {
        if (x->component[v] == UINT32_MAX) { x->unknown[v] = UINT32_MAX; continue; }
        uint32_t root = bake_find_root(parent, v);
        if (root == v) {
            x->component[v] = x->component_count++;
            x->unknown[v] = UINT32_MAX;  /* pinned */
        } else {
            x->component[v] = x->component[root];
            x->unknown[v] = welded_unknowns++;
        }
    }
    x->unknown_count = welded_unknowns + x->used_count;
    x->stats.components = x->component_count;
    x->stats.unknowns = x->unknown_count;
    x->shift = mk_arena_array(&x->arena, 4 * (size_t)x->component_count + 1, sizeof(double));
    if (!x->shift) return mk_error_oom(err, "transfer system");
    mk_arena_release(&x->arena, parent);

    /* normal equations: sum over pairs and columns of a_c a_c^T (upper triangle) */
    bake_spd_start(&x->spd, 0, 0);
    cholmod_triplet *T = cholmod_allocate_triplet(x->unknown_count, x->unknown_count, 30 * (size_t)x->pair_count,
                                                  1, CHOLMOD_REAL, &x->spd.cm);
    if (!T) return mk_error_oom(err, "transfer system");
    int *ti = T->i, *tj = T->j;
    double *tx = T->x;
    size_t k = 0;
    for (uint32_t pr = 0; pr < x->pair_count; pr++)
        for (int c = 0; c < 3; c++) {
            uint32_t u = x->pairs[pr][0];
            const double *a = x->coef + 12 * (size_t)u + 4 * c;
            for (int p = 0; p < 4; p++)
                for (int q = 0; q < 4; q++) {
                    uint32_t vp = variable(x, u, p), vq = variable(x, u, q);
                    if (vp == UINT32_MAX || vq == UINT32_MAX || vp > vq) continue;
                    ti[k] = (int)vp; tj[k] = (int)vq; tx[k++] = a[p] * a[q];
                }
        }
    T->nnz = k;
    mk_result r = bake_spd_factor(&x->spd, &T, 3, err);
    x->stats.factor_seconds = x->spd.factor_seconds;
    return r;
}

/* Whether the aligned source and the target coincide: every target triangle with an area matched,
 * its centroid within TRANSFER_COINCIDE of the diagonal from its match. */
static int coincide(const mk_transfer *x, const double *positions)
{
    const mk_raw_mesh *src = x->source, *tg = x->target;
    double lo[3], hi[3], diagonal;
    bake_bounds(tg, lo, hi, &diagonal);
    for (uint32_t t = 0; t < tg->triangle_count; t++) {
        if (x->match[t] == UINT32_MAX) {
            if (bake_triangle_degenerate(tg, NULL, t)) continue;  /* no equation either way */
            return 0;
        }
        const uint32_t *tt = tg->triangles + 3 * (size_t)t, *st = src->triangles + 3 * (size_t)x->match[t];
        const double *b = x->barycentric + 3 * (size_t)t;
        double d[3];
        for (int c = 0; c < 3; c++) {
            double centroid = 0, on = 0;
            for (int k = 0; k < 3; k++) {
                centroid += tg->positions[3 * (size_t)tt[k] + c] / 3.0;
                on += b[k] * positions[3 * (size_t)st[k] + c];
            }
            d[c] = centroid - on;
        }
        if (!(vec3_length(d) <= TRANSFER_COINCIDE * diagonal)) return 0;
    }
    return 1;
}

/* The correspondence phase: the aligned source fitted to the target (bake_transfer_register),
 * then every target triangle matched again at the fitted positions. */
static mk_result register_source(mk_transfer *x, const mk_transfer_params *params, mk_error *err)
{
    static const double default_steps[] = { TRANSFER_DEFAULT_STEPS };
    const mk_raw_mesh *src = x->source, *tg = x->target;
    x->fitted = mk_arena_array(&x->arena, 3 * (size_t)src->vertex_count + 1, sizeof(double));
    if (!x->fitted) return mk_error_oom(err, "transfer registration");
    memcpy(x->fitted, x->aligned, 3 * (size_t)src->vertex_count * sizeof(double));
    bake_register_params rp = { src, tg, &x->target_grid, params->marker_count, params->markers,
                                params->step_count ? params->step_count : sizeof default_steps / sizeof default_steps[0],
                                params->step_count ? params->steps : default_steps, 1.0, 0.001 };
    bake_register_stats rs;
    mk_result r = bake_transfer_register(&rp, x->fitted, &x->arena.allocator, &rs, err);
    if (r != MK_OK) return r;
    x->stats.fit_mean = rs.mean_distance;
    x->stats.fit_max = rs.max_distance;
    x->stats.marker_distance = rs.marker_distance;
    x->stats.register_seconds = rs.seconds;
    x->stats.register_solves = rs.solves;
    /* source triangles without an area at rest have no gradient: they match nothing */
    return bake_transfer_correspond(src, x->fitted, x->rest_degenerate, tg, NULL, &x->arena, x->match, x->barycentric,
                                    &x->stats.flipped, &x->stats.unmatched, err);
}

/* The other direction: every source triangle paired with the target triangle nearest its centroid
 * among those facing its way, at the fitted positions (unless that pair is a target's match). */
static void pair_source_triangles(mk_transfer *x)
{
    const mk_raw_mesh *src = x->source;
    for (uint32_t s = 0; s < src->triangle_count; s++) {
        double n[3], c[3] = { 0, 0, 0 }, b[3];
        const uint32_t *st = src->triangles + 3 * (size_t)s;
        if (x->rest_degenerate[s]) continue;
        mk_face_normal(src, x->fitted, s, n);
        if (!(vec3_length(n) > 0)) continue;
        for (int k = 0; k < 3; k++)
            for (int q = 0; q < 3; q++) c[q] += x->fitted[3 * (size_t)st[k] + q] / 3.0;
        uint32_t t = bake_tri_grid_closest(&x->target_grid, c, n, b, NULL, NULL);
        if (t == UINT32_MAX || x->match[t] == s) continue;
        if (x->slot[t] == UINT32_MAX) {
            x->slot[t] = x->used_count;
            x->used[x->used_count++] = t;
        }
        x->pairs[x->pair_count][0] = x->slot[t];
        x->pairs[x->pair_count++][1] = s;
    }
}

/* The grid over the target's triangles that the fit and the pairing search. */
static mk_result build_target_grid(mk_transfer *x, mk_error *err)
{
    const mk_raw_mesh *tg = x->target;
    double *target_pos = mk_arena_array(&x->arena, 3 * (size_t)tg->vertex_count + 1, sizeof(double));
    if (!target_pos) return mk_error_oom(err, "transfer target grid");
    for (size_t i = 0; i < 3 * (size_t)tg->vertex_count; i++) target_pos[i] = tg->positions[i];
    return bake_tri_grid_build(&x->target_grid, tg, target_pos, NULL, &x->arena, err);
}

/* Positions must be finite (the searches and the solves assume it). */
static mk_result check_finite(const mk_raw_mesh *mesh, const char *which, mk_error *err)
{
    for (size_t i = 0; i < 3 * (size_t)mesh->vertex_count; i++)
        if (!isfinite(mesh->positions[i]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "%s vertex %zu: position is not finite", which, i / 3);
    return MK_OK;
}

mk_result mk_transfer_create(const mk_transfer_params *params, const mk_allocator *allocator,
                             mk_transfer **out, mk_error *err)
{
    *out = NULL;
    const mk_raw_mesh *src = params->source, *tg = params->target;
    for (uint32_t i = 0; i < params->marker_count; i++)
        if (params->markers[i][0] >= src->vertex_count || params->markers[i][1] >= tg->vertex_count)
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "markers[%u]: vertex out of range (source has %u, target %u vertices)", i,
                                src->vertex_count, tg->vertex_count);
    mk_result r0 = check_finite(src, "source", err);
    if (r0 == MK_OK) r0 = check_finite(tg, "target", err);
    if (r0 != MK_OK) return r0;
    mk_arena arena;
    mk_arena_init(&arena, allocator);
    mk_transfer *x = mk_arena_alloc(&arena, sizeof *x);
    if (!x) { mk_arena_free_all(&arena); return mk_error_oom(err, "transfer"); }
    memset(x, 0, sizeof *x);
    x->arena = arena;
    x->source = src;
    x->target = tg;
    mk_result r = MK_OK;
    double t0 = bake_now();
#define FAIL(expr) do { r = (expr); goto fail; } while (0)
    if ((r = bake_transfer_align(src, tg, params->marker_count, params->markers, x->A, x->t,
                                 &x->stats.alignment_residual, err)) != MK_OK) goto fail;
    memcpy(x->stats.alignment, x->A, sizeof x->A);
    memcpy(x->stats.alignment + 9, x->t, sizeof x->t);
    if (!mat3_inverse(x->A_inv, x->A, 0)) FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "markers: singular alignment"));
    size_t ns = src->triangle_count, nt = tg->triangle_count;
    x->aligned = mk_arena_array(&x->arena, 3 * (size_t)src->vertex_count + 1, sizeof(double));
    x->source_inverse = mk_arena_array(&x->arena, 9 * ns + 1, sizeof(double));
    x->gradient = mk_arena_array(&x->arena, 9 * ns + 1, sizeof(double));
    x->match = mk_arena_array(&x->arena, nt + 1, sizeof(uint32_t));
    x->barycentric = mk_arena_array(&x->arena, 3 * nt + 1, sizeof(double));
    x->used = mk_arena_array(&x->arena, nt + 1, sizeof(uint32_t));
    x->slot = mk_arena_array(&x->arena, nt + 1, sizeof(uint32_t));
    x->pairs = mk_arena_array(&x->arena, nt + ns + 1, sizeof *x->pairs);
    x->rest_degenerate = mk_arena_array(&x->arena, ns + 1, 1);
    x->paired = mk_arena_array(&x->arena, ns + 1, 1);
    x->sources = mk_arena_array(&x->arena, ns + 1, sizeof(uint32_t));
    if (!x->aligned || !x->source_inverse || !x->gradient || !x->match || !x->barycentric || !x->used || !x->slot ||
        !x->pairs || !x->rest_degenerate || !x->paired || !x->sources)
        FAIL(mk_error_oom(err, "transfer"));
    for (uint32_t v = 0; v < src->vertex_count; v++) {
        double p[3] = { src->positions[3 * (size_t)v], src->positions[3 * (size_t)v + 1], src->positions[3 * (size_t)v + 2] };
        mat3_mul_vec(x->aligned + 3 * (size_t)v, x->A, p);
        for (int c = 0; c < 3; c++) x->aligned[3 * (size_t)v + c] += x->t[c];
    }
    for (uint32_t s = 0; s < src->triangle_count; s++) {
        double a[3], b[3], c[3], V[9];
        x->rest_degenerate[s] = (unsigned char)bake_triangle_degenerate(src, x->aligned, s);
        corner(a, src, s, 0); corner(b, src, s, 1); corner(c, src, s, 2);
        bake_transfer_edge_matrix(V, a, b, c);
        if (!mat3_inverse(x->source_inverse + 9 * (size_t)s, V, TRANSFER_EDGE_MIN_DET))
            memset(x->source_inverse + 9 * (size_t)s, 0, 9 * sizeof(double));
    }
    if ((r = bake_transfer_correspond(src, x->aligned, NULL, tg, NULL, &x->arena, x->match, x->barycentric,
                                      &x->stats.flipped, &x->stats.unmatched, err)) != MK_OK) goto fail;
    int iterative = params->correspondence == MK_TRANSFER_ITERATIVE ||
                    (params->correspondence == MK_TRANSFER_AUTO && !coincide(x, x->aligned));
    x->stats.iterative = iterative;
    if (iterative && ((r = build_target_grid(x, err)) != MK_OK || (r = register_source(x, params, err)) != MK_OK)) goto fail;
    /* pairs: every target triangle with its match, then (iterative) every source triangle with the
     * target triangle nearest its centroid at the fitted positions */
    for (uint32_t t = 0; t < tg->triangle_count; t++) {
        x->slot[t] = UINT32_MAX;
        if (x->match[t] == UINT32_MAX) continue;
        x->slot[t] = x->used_count;
        x->pairs[x->pair_count][0] = x->used_count;
        x->pairs[x->pair_count++][1] = x->match[t];
        x->used[x->used_count++] = t;
    }
    if (iterative) pair_source_triangles(x);
    /* the source triangles in a pair, each once: their gradients are computed per key */
    for (uint32_t pr = 0; pr < x->pair_count; pr++) {
        uint32_t s = x->pairs[pr][1];
        if (!x->paired[s]) x->sources[x->source_count++] = s;
        x->paired[s] = 1;
    }
    x->stats.pairs = x->pair_count;
    if (x->used_count == 0)
        FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                          "no target triangle has a source triangle facing its way (are the meshes aligned? give markers)"));
    x->stats.correspond_seconds = bake_now() - t0;
    x->weld = mk_mesh_weld(tg, &x->arena, &x->welded);
    x->solution = x->weld ? mk_arena_array(&x->arena, 3 * (size_t)x->welded + 1, sizeof(double)) : NULL;
    if (!x->solution) FAIL(mk_error_oom(err, "transfer"));
    if ((r = build_system(x, err)) != MK_OK) goto fail;
#undef FAIL
    *out = x;
    return MK_OK;
fail:
    mk_transfer_destroy(x);
    return r;
}

mk_result mk_transfer_apply(mk_transfer *x, const double *source_positions, double *target_positions, mk_error *err)
{
    const mk_raw_mesh *src = x->source, *tg = x->target;
    for (size_t i = 0; i < 3 * (size_t)src->vertex_count; i++)
        if (!isfinite(source_positions[i]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "source vertex %zu: position is not finite", i / 3);
    /* gradients of the paired source triangles, conjugated by the alignment */
    for (uint32_t i = 0; i < x->source_count; i++) {
        uint32_t s = x->sources[i];
        const uint32_t *tri = src->triangles + 3 * (size_t)s;
        double V[9], S[9];
        bake_transfer_edge_matrix(V, source_positions + 3 * (size_t)tri[0], source_positions + 3 * (size_t)tri[1],
                                  source_positions + 3 * (size_t)tri[2]);
        mat3_mul(S, V, x->source_inverse + 9 * (size_t)s);
        mat3_mul(S, x->A, S);
        mat3_mul(x->gradient + 9 * (size_t)s, S, x->A_inv);
    }
    uint32_t nu = x->unknown_count;
    double *b = x->spd.rhs->x;
    memset(b, 0, 3 * (size_t)nu * sizeof(double));
    for (uint32_t pr = 0; pr < x->pair_count; pr++) {
        uint32_t u = x->pairs[pr][0];
        const double *S = x->gradient + 9 * (size_t)x->pairs[pr][1];
        for (int q = 0; q < 4; q++) {
            uint32_t row = variable(x, u, q);
            if (row == UINT32_MAX) continue;
            for (int c = 0; c < 3; c++) {
                double a = x->coef[12 * (size_t)u + 4 * c + q];
                for (int r = 0; r < 3; r++) b[(size_t)r * nu + row] += a * S[3 * r + c];
            }
        }
    }
    mk_result res = bake_spd_solve(&x->spd, err);
    if (res != MK_OK) return res;
    const double *sol = x->spd.x->x;
    for (uint32_t v = 0; v < x->welded; v++)
        for (int r = 0; r < 3; r++)
            x->solution[3 * (size_t)v + r] = x->unknown[v] == UINT32_MAX ? 0 : sol[(size_t)r * nu + x->unknown[v]];
    /* the free translation of each component: match the mean centroid to the aligned source */
    memset(x->shift, 0, 4 * (size_t)x->component_count * sizeof(double));
    for (uint32_t u = 0; u < x->used_count; u++) {
        uint32_t t = x->used[u], s = x->match[t];
        if (s == UINT32_MAX) continue;  /* paired from the source's side only */
        const uint32_t *tt = tg->triangles + 3 * (size_t)t, *st = src->triangles + 3 * (size_t)s;
        const double *bary = x->barycentric + 3 * (size_t)t;
        /* the source's displacement at the matched point, in the target's frame */
        double d[3] = { 0, 0, 0 }, q[3];
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                d[c] += bary[k] * (source_positions[3 * (size_t)st[k] + c] - src->positions[3 * (size_t)st[k] + c]);
        mat3_mul_vec(q, x->A, d);
        double *sh = x->shift + 4 * (size_t)x->component[x->weld[tt[0]]];
        for (int c = 0; c < 3; c++) {
            double moved = 0, rest = 0;
            for (int k = 0; k < 3; k++) {
                moved += x->solution[3 * (size_t)x->weld[tt[k]] + c] / 3;
                rest += tg->positions[3 * (size_t)tt[k] + c] / 3.0;
            }
            sh[c] += rest + q[c] - moved;
        }
        sh[3] += 1;
    }
    for (uint32_t v = 0; v < tg->vertex_count; v++) {
        uint32_t w = x->weld[v], comp = x->component[w];
        const double *sh = comp == UINT32_MAX ? NULL : x->shift + 4 * (size_t)comp;
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * (size_t)v + (size_t)c;
            /* a component in no matched triangle, or paired from the source's side only, stays */
            target_positions[i] = sh && sh[3] > 0 ? x->solution[3 * (size_t)w + c] + sh[c] / sh[3] : tg->positions[i];
        }
    }
    x->stats.solves = x->spd.solves;
    x->stats.solve_seconds = x->spd.solve_seconds;
    return MK_OK;
}

uint32_t mk_transfer_match(const mk_transfer *x, uint32_t t, double barycentric[3])
{
    if (t >= x->target->triangle_count) return UINT32_MAX;
    memcpy(barycentric, x->barycentric + 3 * (size_t)t, 3 * sizeof(double));
    return x->match[t];
}

void mk_transfer_stats_get(const mk_transfer *x, mk_transfer_stats *stats)
{
    *stats = x->stats;
}

void mk_transfer_destroy(mk_transfer *x)
{
    if (!x) return;
    bake_spd_finish(&x->spd);
    mk_arena arena = x->arena;
    mk_arena_free_all(&arena);
}

mk_result mk_transfer_channel(mk_raw_asset *raw, uint32_t mesh, const char *name, const char *origin,
                              mk_transfer *x, const mk_raw_mesh *source_mesh, const mk_raw_channel *source_channel,
                              uint32_t *moved, mk_error *err)
{
    const mk_raw_mesh *tg = &raw->meshes[mesh];
    if (tg != x->target || source_mesh != x->source)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_transfer_channel: meshes differ from the transfer's");
    mk_arena scratch;
    mk_arena_init(&scratch, &raw->arena.allocator);
    size_t ns = source_mesh->vertex_count, nt = tg->vertex_count;
    double *src = mk_arena_array(&scratch, 3 * ns + 1, sizeof(double));
    double *pos = mk_arena_array(&scratch, 3 * nt + 1, sizeof(double));
    /* read before adding a channel: the source may be a channel of raw itself (the array moves) */
    const mk_raw_target *targets = source_channel->targets;
    uint32_t target_count = source_channel->target_count;
    float default_weight = source_channel->default_weight;
    uint32_t old_count = raw->channel_count;
    mk_raw_channel *channel = src && pos ? mk_raw_add_channels(raw, 1) : NULL;
    mk_result r = MK_OK;
    if (!channel) { r = mk_error_oom(err, "transferred channel"); goto done; }
    channel->name = mk_arena_strdup(&raw->arena, name);
    channel->origin = mk_arena_strdup(&raw->arena, origin ? origin : "");
    channel->mesh = mesh;
    channel->default_weight = default_weight;
    if (!channel->name || !channel->origin) { r = mk_error_oom(err, "transferred channel"); goto done; }
    double bmin[3], bmax[3], diagonal;
    bake_bounds(tg, bmin, bmax, &diagonal);
    if (!(diagonal > 0)) diagonal = 1;
    *moved = 0;
    for (uint32_t k = 0; k < target_count; k++) {
        const mk_raw_target *st = &targets[k];
        for (size_t i = 0; i < 3 * ns; i++) src[i] = source_mesh->positions[i];
        for (uint32_t i = 0; i < st->count; i++) {
            if (st->indices[i] >= ns) { r = mk_error_set(err, MK_ERROR_CORRUPT, UINT64_MAX, "source target %u: index out of range", k); goto done; }
            for (int c = 0; c < 3; c++) src[3 * (size_t)st->indices[i] + c] += st->positions[3 * (size_t)i + c];
        }
        if ((r = mk_transfer_apply(x, src, pos, err)) != MK_OK) goto done;
        char tname[300];
        if (k + 1 == target_count) snprintf(tname, sizeof tname, "%s", name);
        else snprintf(tname, sizeof tname, "%s@%.4g", name, (double)st->full_weight);
        /* the same full weight (a float) as the source's in-between */
        if ((r = bake_store_target(raw, channel, mesh, (double)st->full_weight, tname, diagonal, pos, NULL, NULL, moved,
                                   err)) != MK_OK) goto done;
    }
    if (tg->normals) r = mk_raw_compute_target_normals(raw, mesh, 0, 0, err);
done:
    if (r != MK_OK) raw->channel_count = old_count;
    mk_arena_free_all(&scratch);
    return r;
}

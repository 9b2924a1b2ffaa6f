/* SPDX-License-Identifier: MIT */
/* Deformation transfer (transfer.h): the least-squares fit of the target's deformation
 * gradients to the matched source triangles', factored once and solved per source shape.
 *
 * Conventions fixed here (docs/baking.md, "transfer", writes the system out):
 * - Unknowns: the position-welded target vertices (render vertices with bit-identical positions
 *   are one vertex, so seams do not tear) and one fourth vertex per matched target triangle;
 *   the three coordinates share the matrix and are solved as three right-hand sides.
 * - Energy: sum over matched target triangles of |T_j - S'_m(j)|_F^2, unweighted as in the
 *   paper, with T_j = V~_j V_j^-1 (V_j: the target's rest edge matrix, fourth vertex included)
 *   and S'_m = A S_m A^-1 the source triangle's gradient conjugated by the alignment A.
 * - The energy only sees differences of positions: each connected component's translation is
 *   free. One vertex per component (its first welded vertex) is fixed at 0 to make the matrix
 *   definite; after the solve the component is translated so that the mean of its triangles'
 *   centroids matches the mean of the aligned deformed source at their matched points.
 * - Target vertices in no matched triangle (loose or only in degenerate triangles) stay at rest.
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
    double *source_inverse;     /* 9 per source triangle: V^-1 at rest (zeros when degenerate) */
    double *gradient;           /* 9 per source triangle: A S A^-1 of the current shape */
    uint32_t *match;            /* per target triangle: source triangle or UINT32_MAX */
    double *barycentric;        /* 3 per target triangle */
    uint32_t welded;
    uint32_t *weld;             /* render -> welded */
    uint32_t used_count;        /* matched target triangles */
    uint32_t *used;             /* their target triangle indices */
    double *coef;               /* 12 per matched triangle: column c, corner q at [4 c + q] */
    uint32_t *unknown;          /* welded -> unknown row, UINT32_MAX when pinned or unused */
    uint32_t *component;        /* welded -> component, UINT32_MAX when in no matched triangle */
    uint32_t component_count;
    uint32_t unknown_count;     /* welded unknowns, then one fourth vertex per matched triangle */
    double *solution;           /* 3 per welded vertex */
    double *shift;              /* 4 per component: summed offset and count */
    bake_spd spd;
    mk_transfer_stats stats;
};

/* Edge matrices are inverted whenever their determinant is finite and nonzero (mat3_inverse's
 * min_det 0), not with the lattices' relative cut (bake_solve3): det V = |n|^(3/2), so a cut at
 * 1e-14 max|V_ij|^3 would call singular the triangles between TRANSFER_DEGENERATE (1e-12 of the
 * longest edge squared, where the correspondence stops) and about 4.6e-10, and such a source
 * triangle would hand a zero gradient to the target triangles matched to it. */
#define EDGE_MATRIX_MIN_DET 0

/* Edge matrix [v2 - v1, v3 - v1, v4 - v1] (columns, row-major storage) with the fourth vertex
 * v4 = v1 + n / sqrt(|n|), n = (v2 - v1) x (v3 - v1) (v4 = v1 for a collapsed triangle). */
static void edge_matrix(double V[9], const double a[3], const double b[3], const double c[3])
{
    double e1[3], e2[3], n[3];
    vec3_sub(e1, b, a);
    vec3_sub(e2, c, a);
    mk_triangle_normal(a, b, c, n);
    double l = vec3_length(n), s = l > 0 ? 1 / sqrt(l) : 0;
    for (int r = 0; r < 3; r++) {
        V[3 * r] = e1[r];
        V[3 * r + 1] = e2[r];
        V[3 * r + 2] = n[r] * s;
    }
}

static void corner(double out[3], const mk_raw_mesh *mesh, uint32_t t, int k)
{
    const float *p = mesh->positions + 3 * (size_t)mesh->triangles[3 * (size_t)t + k];
    out[0] = p[0]; out[1] = p[1]; out[2] = p[2];
}

/* Unknown row of corner q (0..2: the welded vertices, 3: the fourth vertex) of matched triangle u. */
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
        double a3[3], b3[3], c3[3], V[9], W[9];
        corner(a3, tg, x->used[u], 0); corner(b3, tg, x->used[u], 1); corner(c3, tg, x->used[u], 2);
        edge_matrix(V, a3, b3, c3);
        if (!mat3_inverse(W, V, EDGE_MATRIX_MIN_DET))
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "target triangle %u is degenerate", x->used[u]);
        for (int c = 0; c < 3; c++) {
            double *k = x->coef + 12 * (size_t)u + 4 * c;
            k[1] = W[c]; k[2] = W[3 + c]; k[3] = W[6 + c];
            k[0] = -(k[1] + k[2] + k[3]);
        }
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

    /* normal equations: sum over matched triangles and columns of a_c a_c^T (upper triangle) */
    bake_spd_start(&x->spd, 0, 0);
    cholmod_triplet *T = cholmod_allocate_triplet(x->unknown_count, x->unknown_count, 30 * (size_t)x->used_count,
                                                  1, CHOLMOD_REAL, &x->spd.cm);
    if (!T) return mk_error_oom(err, "transfer system");
    int *ti = T->i, *tj = T->j;
    double *tx = T->x;
    size_t k = 0;
    for (uint32_t u = 0; u < x->used_count; u++)
        for (int c = 0; c < 3; c++) {
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
    x->aligned = mk_arena_array(&x->arena, 3 * (size_t)src->vertex_count + 1, sizeof(double));
    x->source_inverse = mk_arena_array(&x->arena, 9 * (size_t)src->triangle_count + 1, sizeof(double));
    x->gradient = mk_arena_array(&x->arena, 9 * (size_t)src->triangle_count + 1, sizeof(double));
    x->match = mk_arena_array(&x->arena, (size_t)tg->triangle_count + 1, sizeof(uint32_t));
    x->barycentric = mk_arena_array(&x->arena, 3 * (size_t)tg->triangle_count + 1, sizeof(double));
    x->used = mk_arena_array(&x->arena, (size_t)tg->triangle_count + 1, sizeof(uint32_t));
    if (!x->aligned || !x->source_inverse || !x->gradient || !x->match || !x->barycentric || !x->used)
        FAIL(mk_error_oom(err, "transfer"));
    for (uint32_t v = 0; v < src->vertex_count; v++) {
        double p[3] = { src->positions[3 * (size_t)v], src->positions[3 * (size_t)v + 1], src->positions[3 * (size_t)v + 2] };
        mat3_mul_vec(x->aligned + 3 * (size_t)v, x->A, p);
        for (int c = 0; c < 3; c++) x->aligned[3 * (size_t)v + c] += x->t[c];
    }
    for (uint32_t s = 0; s < src->triangle_count; s++) {
        double a[3], b[3], c[3], V[9];
        corner(a, src, s, 0); corner(b, src, s, 1); corner(c, src, s, 2);
        edge_matrix(V, a, b, c);
        if (!mat3_inverse(x->source_inverse + 9 * (size_t)s, V, EDGE_MATRIX_MIN_DET)) memset(x->source_inverse + 9 * (size_t)s, 0, 9 * sizeof(double));
    }
    if ((r = bake_transfer_correspond(src, x->aligned, tg, &x->arena, x->match, x->barycentric, &x->stats.flipped,
                                      &x->stats.unmatched, err)) != MK_OK) goto fail;
    for (uint32_t t = 0; t < tg->triangle_count; t++)
        if (x->match[t] != UINT32_MAX) x->used[x->used_count++] = t;
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
    /* gradients of the matched source triangles, conjugated by the alignment */
    for (uint32_t u = 0; u < x->used_count; u++) {
        uint32_t s = x->match[x->used[u]];
        const uint32_t *tri = src->triangles + 3 * (size_t)s;
        double V[9], S[9];
        edge_matrix(V, source_positions + 3 * (size_t)tri[0], source_positions + 3 * (size_t)tri[1],
                    source_positions + 3 * (size_t)tri[2]);
        mat3_mul(S, V, x->source_inverse + 9 * (size_t)s);
        mat3_mul(S, x->A, S);
        mat3_mul(x->gradient + 9 * (size_t)s, S, x->A_inv);
    }
    uint32_t nu = x->unknown_count;
    double *b = x->spd.rhs->x;
    memset(b, 0, 3 * (size_t)nu * sizeof(double));
    for (uint32_t u = 0; u < x->used_count; u++) {
        const double *S = x->gradient + 9 * (size_t)x->match[x->used[u]];
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
        const uint32_t *tt = tg->triangles + 3 * (size_t)t, *st = src->triangles + 3 * (size_t)s;
        const double *bary = x->barycentric + 3 * (size_t)t;
        double p[3] = { 0, 0, 0 }, q[3];
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) p[c] += bary[k] * source_positions[3 * (size_t)st[k] + c];
        mat3_mul_vec(q, x->A, p);
        double *sh = x->shift + 4 * (size_t)x->component[x->weld[tt[0]]];
        for (int c = 0; c < 3; c++) {
            double centroid = 0;
            for (int k = 0; k < 3; k++) centroid += x->solution[3 * (size_t)x->weld[tt[k]] + c] / 3;
            sh[c] += q[c] + x->t[c] - centroid;
        }
        sh[3] += 1;
    }
    for (uint32_t v = 0; v < tg->vertex_count; v++) {
        uint32_t w = x->weld[v], comp = x->component[w];
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * (size_t)v + (size_t)c;
            if (comp == UINT32_MAX) target_positions[i] = tg->positions[i];
            else target_positions[i] = x->solution[3 * (size_t)w + c] + x->shift[4 * (size_t)comp + c] / x->shift[4 * (size_t)comp + 3];
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

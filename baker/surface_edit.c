/* SPDX-License-Identifier: MIT */
/* The core of surface editing (Laplacian and ARAP): the position-welded mesh, its adjacency
 * and edge weights, the constraints (anchors and handles), the system matrix factored once with
 * CHOLMOD, and the solve. The methods are leaves on it (laplacian.c, arap.c); edit.c picks one.
 *
 * Conventions fixed here:
 * - Cotangent weights w_ij = (cot a_ij + cot b_ij) / 2 (Pinkall-Polthier 1993, Meyer et al.
 *   2003), the angles opposite edge ij, clamped to |cot| <= 1e5 (degenerate triangles); or
 *   uniform weights 1 per edge.
 * - The Laplacian operator is L = I - D^-1 W (rows sum to 0, so constants are in its kernel):
 *   W is the adjacency (uniform) or the cotangent weights, D = diag(sum_j w_ij). A row whose
 *   cotangent weights sum to <= 0 (very obtuse fans) falls back to uniform weights.
 * - Solved on the position-welded mesh (render vertices with bit-identical positions are one
 *   vertex), then copied back to every render vertex, so UV/normal seams do not tear.
 * - With hard constraints (default) the known vertices are eliminated from the system; with
 *   soft constraints they stay unknowns with a penalty w^2 |x_c - c|^2. The matrix depends only
 *   on the mesh, the method and the constraint set, not on the amplitude: it is analyzed and
 *   factored once per bake, then each amplitude costs solves with 3 right-hand sides.
 * - A connected component without any constrained vertex would make the matrix singular, and
 *   CHOLMOD does not reliably report that: it is rejected before factoring. Vertices used by
 *   no triangle are kept at rest.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "surface_edit_internal.h"
#include "bake_util.h"
#include "mesh_groups.h"

#define COT_CLAMP 1e5

/* Edge list -> CSR adjacency with unique sorted neighbors. */
static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static mk_result build_adjacency(mk_surface_edit *s, const uint32_t *tris, uint32_t tri_count, mk_error *err)
{
    uint32_t n = s->welded;
    s->offsets = mk_arena_array(&s->arena, (size_t)n + 1, sizeof(uint32_t));
    uint32_t *fill = mk_arena_array(&s->arena, (size_t)n + 1, sizeof(uint32_t));
    if (!s->offsets || !fill) return mk_error_oom(err, "adjacency");
    for (uint32_t t = 0; t < tri_count; t++)
        for (int i = 0; i < 3; i++) s->offsets[tris[3 * (size_t)t + i] + 1] += 2;
    for (uint32_t v = 0; v < n; v++) s->offsets[v + 1] += s->offsets[v];
    size_t total = s->offsets[n];
    uint32_t *nb = mk_arena_array(&s->arena, total ? total : 1, sizeof(uint32_t));
    if (!nb) return mk_error_oom(err, "adjacency");
    for (uint32_t t = 0; t < tri_count; t++) {
        const uint32_t *tri = tris + 3 * (size_t)t;
        for (int i = 0; i < 3; i++) {
            uint32_t v = tri[i];
            nb[s->offsets[v] + fill[v]++] = tri[(i + 1) % 3];
            nb[s->offsets[v] + fill[v]++] = tri[(i + 2) % 3];
        }
    }
    /* sort + unique per row, compacting in place */
    uint32_t out = 0;
    for (uint32_t v = 0; v < n; v++) {
        uint32_t b = s->offsets[v], e = s->offsets[v + 1];
        qsort(nb + b, e - b, sizeof(uint32_t), cmp_u32);
        s->offsets[v] = out;
        for (uint32_t k = b; k < e; k++)
            if (k == b || nb[k] != nb[k - 1]) nb[out++] = nb[k];
    }
    s->offsets[n] = out;
    s->neighbors = nb;
    mk_arena_release(&s->arena, fill);
    s->edge_weights = mk_arena_array(&s->arena, out ? out : 1, sizeof(double));
    s->weight_sums = mk_arena_array(&s->arena, n ? n : 1, sizeof(double));
    if (!s->edge_weights || !s->weight_sums) return mk_error_oom(err, "adjacency");
    return MK_OK;
}

static uint32_t *edge_slot(mk_surface_edit *s, uint32_t i, uint32_t j, uint32_t *slot)
{
    for (uint32_t k = s->offsets[i]; k < s->offsets[i + 1]; k++)
        if (s->neighbors[k] == j) { *slot = k; return slot; }
    return NULL;
}

static void build_weights(mk_surface_edit *s, const uint32_t *tris, uint32_t tri_count)
{
    uint32_t n = s->welded;
    if (s->params.weights == MK_WEIGHTS_UNIFORM) {
        for (uint32_t k = 0; k < s->offsets[n]; k++) s->edge_weights[k] = 1;
    } else {
        for (uint32_t t = 0; t < tri_count; t++) {
            const uint32_t *tri = tris + 3 * (size_t)t;
            for (int i = 0; i < 3; i++) {
                uint32_t a = tri[i], b = tri[(i + 1) % 3], c = tri[(i + 2) % 3];
                const double *pa = s->rest + 3 * (size_t)a, *pb = s->rest + 3 * (size_t)b,
                             *pc = s->rest + 3 * (size_t)c;
                double e1[3] = { pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2] };
                double e2[3] = { pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2] };
                double cr[3];
                vec3_cross(cr, e1, e2);
                double len = vec3_length(cr);
                if (!(len > 0)) continue;  /* degenerate triangle: no contribution */
                double cot = vec3_dot(e1, e2) / len;
                if (cot > COT_CLAMP) cot = COT_CLAMP;
                if (cot < -COT_CLAMP) cot = -COT_CLAMP;
                uint32_t k;
                if (edge_slot(s, b, c, &k)) s->edge_weights[k] += 0.5 * cot;
                if (edge_slot(s, c, b, &k)) s->edge_weights[k] += 0.5 * cot;
            }
        }
    }
    for (uint32_t v = 0; v < n; v++) {
        double sum = 0;
        for (uint32_t k = s->offsets[v]; k < s->offsets[v + 1]; k++) sum += s->edge_weights[k];
        s->weight_sums[v] = sum;
    }
}

/* Row v of L = I - D^-1 W as (column, value) pairs: writes count entries, column v first. */
uint32_t edit_laplacian_row(const mk_surface_edit *s, uint32_t v, uint32_t *cols, double *vals)
{
    uint32_t b = s->offsets[v], e = s->offsets[v + 1], m = 0;
    cols[m] = v; vals[m++] = 1;
    if (e == b) return m;
    double sum = s->weight_sums[v];
    int uniform = !(sum > 1e-12);
    if (uniform) sum = (double)(e - b);
    for (uint32_t k = b; k < e; k++) {
        cols[m] = s->neighbors[k];
        vals[m++] = -(uniform ? 1.0 : s->edge_weights[k]) / sum;
    }
    return m;
}

void edit_targets(mk_surface_edit *s, double amplitude)
{
    const mk_edit_params *p = &s->params;
    for (uint32_t h = 0; h < p->handle_count; h++) {
        double axis[3] = { p->handles[h].axis[0], p->handles[h].axis[1], p->handles[h].axis[2] };
        if (!(vec3_normalize(axis) > 0)) { axis[0] = 0; axis[1] = 0; axis[2] = 1; }
        mat3_rotation(s->handle_rotation[h], axis, amplitude * p->handles[h].angle);
    }
    for (uint32_t v = 0; v < s->welded; v++) {
        int32_t c = s->constraint[v];
        double *t = s->target + 3 * (size_t)v;
        const double *x = s->rest + 3 * (size_t)v;
        if (c <= 0) { t[0] = x[0]; t[1] = x[1]; t[2] = x[2]; continue; }
        const mk_edit_handle *h = &p->handles[c - 1];
        double d[3] = { x[0] - h->pivot[0], x[1] - h->pivot[1], x[2] - h->pivot[2] }, r[3];
        mat3_mul_vec(r, s->handle_rotation[c - 1], d);
        for (int k = 0; k < 3; k++) t[k] = h->pivot[k] + r[k] + amplitude * h->translate[k];
    }
}

mk_result edit_solve(mk_surface_edit *s, mk_error *err)
{
    return bake_spd_solve(&s->spd, err);
}

mk_result edit_solve_positions(mk_surface_edit *s, const double *known, const double *base, mk_error *err)
{
    mk_result r = edit_solve(s, err);
    if (r != MK_OK) return r;
    const double *x = s->spd.x->x;
    const uint32_t nu = s->unknown_count;
    for (uint32_t v = 0; v < s->welded; v++)
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * (size_t)v + (size_t)c;
            double d = s->unknown[v] != UINT32_MAX ? x[(size_t)c * nu + s->unknown[v]] : known[i];
            s->solution[i] = base ? base[i] + d : d;
        }
    return MK_OK;
}

/* Triplets of the system matrix (upper triangle, stype 1; duplicates are summed). */
static mk_result assemble(mk_surface_edit *s, cholmod_triplet **out, mk_error *err)
{
    uint32_t n = s->welded, nu = s->unknown_count;
    int arap = s->params.method == MK_EDIT_ARAP;
    double w2 = s->params.soft ? s->params.soft_weight * s->params.soft_weight : 0;
    size_t nnz = 0;
    uint32_t max_row = 0;
    for (uint32_t v = 0; v < n; v++) {
        size_t d = s->offsets[v + 1] - s->offsets[v] + 1;
        if (d > max_row) max_row = (uint32_t)d;
        nnz += arap ? d : d * (d + 1) / 2;
    }
    nnz += n;  /* soft diagonal */
    cholmod_triplet *T = cholmod_allocate_triplet(nu, nu, nnz, 1, CHOLMOD_REAL, &s->spd.cm);
    uint32_t *cols = mk_arena_array(&s->arena, max_row, sizeof(uint32_t));
    double *vals = mk_arena_array(&s->arena, max_row, sizeof(double));
    if (!T || !cols || !vals) {
        if (T) cholmod_free_triplet(&T, &s->spd.cm);
        return mk_error_oom(err, "system matrix");
    }
    int *ti = T->i, *tj = T->j;
    double *tx = T->x;
    size_t k = 0;
#define PUT(a, b, val) do { uint32_t ua_ = s->unknown[a], ub_ = s->unknown[b]; \
        if (ua_ != UINT32_MAX && ub_ != UINT32_MAX) { \
            ti[k] = (int)(ua_ < ub_ ? ua_ : ub_); tj[k] = (int)(ua_ < ub_ ? ub_ : ua_); tx[k++] = (val); } } while (0)
    for (uint32_t v = 0; v < n; v++) {
        if (arap) {
            /* Cotangent Laplacian with a positive diagonal: L_ii = sum w_ij, L_ij = -w_ij. */
            PUT(v, v, s->weight_sums[v]);
            for (uint32_t q = s->offsets[v]; q < s->offsets[v + 1]; q++)
                if (s->neighbors[q] > v) PUT(v, s->neighbors[q], -s->edge_weights[q]);
        } else {
            /* L^T L = sum over rows r of l_r^T l_r. */
            uint32_t m = edit_laplacian_row(s, v, cols, vals);
            for (uint32_t a = 0; a < m; a++)
                for (uint32_t b = a; b < m; b++) PUT(cols[a], cols[b], vals[a] * vals[b]);
        }
        if (w2 > 0 && s->constraint[v] >= 0) PUT(v, v, w2);
    }
#undef PUT
    T->nnz = k;
    *out = T;
    mk_arena_release(&s->arena, cols);
    mk_arena_release(&s->arena, vals);
    return MK_OK;
}

mk_result mk_surface_edit_create(const mk_raw_mesh *mesh, const mk_edit_params *params,
                                 const mk_allocator *allocator, mk_surface_edit **out,
                                 mk_error *err)
{
    *out = NULL;
    double t_setup = bake_now();
    mk_arena arena;
    mk_arena_init(&arena, allocator);
    mk_surface_edit *s = mk_arena_alloc(&arena, sizeof *s);
    if (!s) { mk_arena_free_all(&arena); return mk_error_oom(err, "surface edit"); }
    s->arena = arena;
    s->mesh = mesh;
    s->params = *params;
    if (s->params.soft_weight <= 0) s->params.soft_weight = 100;
    if (s->params.iterations == 0) s->params.iterations = 1000;
    if (s->params.convergence == 0) s->params.convergence = 1e-6;
    mk_result r = MK_OK;
#define FAIL(expr) do { r = (expr); goto fail; } while (0)
    if ((unsigned)params->acceleration > MK_ARAP_PLAIN)
        FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "acceleration: %d is not an mk_arap_acceleration", (int)params->acceleration));
    if (params->handle_count == 0) FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "handles: none given"));
    s->weld = mk_mesh_weld(mesh, &s->arena, &s->welded);
    if (!s->weld) FAIL(mk_error_oom(err, "weld"));
    uint32_t n = s->welded;
    s->rest = mk_arena_array(&s->arena, 3 * (size_t)n, sizeof(double));
    s->target = mk_arena_array(&s->arena, 3 * (size_t)n, sizeof(double));
    s->solution = mk_arena_array(&s->arena, 3 * (size_t)n, sizeof(double));
    s->work = mk_arena_array(&s->arena, 3 * (size_t)n, sizeof(double));
    s->constraint = mk_arena_array(&s->arena, n, sizeof(int32_t));
    s->unknown = mk_arena_array(&s->arena, n, sizeof(uint32_t));
    s->handle_rotation = mk_arena_array(&s->arena, params->handle_count, sizeof *s->handle_rotation);
    uint32_t *tris = mk_arena_array(&s->arena, 3 * (size_t)mesh->triangle_count + 1, sizeof(uint32_t));
    if (!s->rest || !s->target || !s->solution || !s->work || !s->constraint || !s->unknown ||
        !s->handle_rotation || !tris)
        FAIL(mk_error_oom(err, "surface edit"));
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        for (int c = 0; c < 3; c++) s->rest[3 * (size_t)s->weld[v] + c] = mesh->positions[3 * (size_t)v + c];
    /* Welded triangles, dropping those that collapse (two corners welded together). */
    uint32_t tri_count = 0;
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        uint32_t a = s->weld[mesh->triangles[3 * (size_t)t]], b = s->weld[mesh->triangles[3 * (size_t)t + 1]],
                 c = s->weld[mesh->triangles[3 * (size_t)t + 2]];
        if (a == b || b == c || a == c) continue;
        tris[3 * (size_t)tri_count] = a; tris[3 * (size_t)tri_count + 1] = b; tris[3 * (size_t)tri_count + 2] = c;
        tri_count++;
    }
    if ((r = build_adjacency(s, tris, tri_count, err)) != MK_OK) goto fail;
    build_weights(s, tris, tri_count);
    mk_arena_release(&s->arena, tris);

    /* Constraints: anchors, then handles (a handle wins on a shared welded vertex). */
    for (uint32_t v = 0; v < n; v++) s->constraint[v] = -1;
    for (uint32_t i = 0; i < params->anchor_count; i++) {
        if (params->anchors[i] >= mesh->vertex_count)
            FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "anchors: vertex %u out of range", params->anchors[i]));
        s->constraint[s->weld[params->anchors[i]]] = 0;
    }
    for (uint32_t h = 0; h < params->handle_count; h++) {
        const mk_edit_handle *hd = &params->handles[h];
        if (hd->count == 0)
            FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "handles[%u]: selection is empty", h));
        for (int c = 0; c < 3; c++)
            if (!isfinite(hd->translate[c]) || !isfinite(hd->pivot[c]) || !isfinite(hd->axis[c]) || !isfinite(hd->angle))
                FAIL(mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "handles[%u]: motion is not finite", h));
        for (uint32_t i = 0; i < hd->count; i++) {
            if (hd->vertices[i] >= mesh->vertex_count)
                FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "handles[%u]: vertex %u out of range", h, hd->vertices[i]));
            s->constraint[s->weld[hd->vertices[i]]] = (int32_t)h + 1;
        }
    }
    /* Vertices without neighbors stay at rest; every component needs a constraint. */
    uint32_t *parent = mk_arena_array(&s->arena, n, sizeof(uint32_t));
    unsigned char *has = mk_arena_array(&s->arena, n, 1);
    if (!parent || !has) FAIL(mk_error_oom(err, "components"));
    for (uint32_t v = 0; v < n; v++) parent[v] = v;
    for (uint32_t v = 0; v < n; v++) {
        if (s->offsets[v] == s->offsets[v + 1] && s->constraint[v] < 0) s->constraint[v] = 0;
        for (uint32_t q = s->offsets[v]; q < s->offsets[v + 1]; q++) {
            uint32_t a = bake_find_root(parent, v), b = bake_find_root(parent, s->neighbors[q]);
            if (a != b) parent[a < b ? b : a] = a < b ? a : b;
        }
    }
    for (uint32_t v = 0; v < n; v++)
        if (s->constraint[v] >= 0) has[bake_find_root(parent, v)] = 1;
    for (uint32_t v = 0; v < n; v++) {
        uint32_t root = bake_find_root(parent, v);
        if (!has[root]) {
            uint32_t size = 0, render = 0;
            for (uint32_t u = 0; u < n; u++) size += bake_find_root(parent, u) == root;
            for (uint32_t u = 0; u < mesh->vertex_count; u++)
                if (s->weld[u] == v) { render = u; break; }
            FAIL(mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                              "the connected component containing vertex %u (%u welded vertices) has no "
                              "anchor or handle: the system would be singular; add an anchor there",
                              render, size));
        }
    }
    mk_arena_release(&s->arena, parent);
    mk_arena_release(&s->arena, has);
    s->unknown_count = 0;
    for (uint32_t v = 0; v < n; v++)
        s->unknown[v] = (s->params.soft || s->constraint[v] < 0) ? s->unknown_count++ : UINT32_MAX;
    if (s->params.method == MK_EDIT_ARAP) {
        s->rotations = mk_arena_array(&s->arena, 9 * (size_t)n, sizeof(double));
        if (!s->rotations) FAIL(mk_error_oom(err, "rotations"));
        if (s->params.acceleration != MK_ARAP_PLAIN) {
            size_t vectors = s->params.acceleration == MK_ARAP_ANDERSON ? 2 + 2 * (size_t)EDIT_ANDERSON_HISTORY
                                                                        : 4 + 2 * (size_t)EDIT_LBFGS_HISTORY;
            s->anderson = mk_arena_array(&s->arena, vectors * 3 * n, sizeof(double));
            if (!s->anderson) FAIL(mk_error_oom(err, "Anderson acceleration history"));
        }
    }
    s->stats.unknowns = s->unknown_count;

    /* ARAP's cotangent Laplacian has a 1-ring stencil and little fill: the simplicial factor
     * solved 2x faster than the supernodal one (bench_baker, 100k vertices: 0.015 vs 0.030 s
     * per 3-rhs solve) at the same factor time. L^T L (2-ring) fills in more and factors
     * faster supernodal (2.1 vs 3.8 s), so Laplacian editing keeps CHOLMOD's choice. */
    bake_spd_start(&s->spd, s->params.method == MK_EDIT_ARAP, s->params.method != MK_EDIT_ARAP);
    if (s->unknown_count > 0) {
        cholmod_triplet *T = NULL;
        if ((r = assemble(s, &T, err)) != MK_OK) goto fail;
        s->stats.setup_seconds = bake_now() - t_setup;
        if ((r = bake_spd_factor(&s->spd, &T, 3, err)) != MK_OK) goto fail;
    }
#undef FAIL
    *out = s;
    return MK_OK;
fail:
    mk_surface_edit_destroy(s);
    return r;
}

void mk_surface_edit_apply_operator(const mk_surface_edit *s, const double *x, double *out)
{
    const mk_raw_mesh *mesh = s->mesh;
    double *xw = s->work, *yw = s->target;  /* scratch: both are rewritten by every eval */
    for (uint32_t v = mesh->vertex_count; v-- > 0;)
        for (int c = 0; c < 3; c++) xw[3 * (size_t)s->weld[v] + c] = x[3 * (size_t)v + c];
    for (uint32_t v = 0; v < s->welded; v++) {
        double acc[3] = { 0, 0, 0 };
        if (s->params.method == MK_EDIT_ARAP) {
            for (uint32_t k = s->offsets[v]; k < s->offsets[v + 1]; k++)
                for (int c = 0; c < 3; c++)
                    acc[c] += s->edge_weights[k] * (xw[3 * (size_t)v + c] - xw[3 * (size_t)s->neighbors[k] + c]);
        } else {
            uint32_t cols[1024];
            double vals[1024];
            if (s->offsets[v + 1] - s->offsets[v] + 1 > 1024) continue;
            uint32_t m = edit_laplacian_row(s, v, cols, vals);
            for (uint32_t a = 0; a < m; a++)
                for (int c = 0; c < 3; c++) acc[c] += vals[a] * xw[3 * (size_t)cols[a] + c];
        }
        for (int c = 0; c < 3; c++) yw[3 * (size_t)v + c] = acc[c];
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        for (int c = 0; c < 3; c++) out[3 * (size_t)v + c] = yw[3 * (size_t)s->weld[v] + c];
}

void mk_surface_edit_stats(const mk_surface_edit *s, mk_solver_stats *stats)
{
    *stats = s->stats;
    stats->local_seconds = s->local_seconds;
    stats->factorizations = s->spd.factorizations;
    stats->solves = s->spd.solves;
    stats->factor_seconds = s->spd.factor_seconds;
    stats->solve_seconds = s->spd.solve_seconds;
    stats->factor_nonzeros = s->spd.factor_nonzeros;
}

void mk_surface_edit_destroy(mk_surface_edit *s)
{
    if (!s) return;
    bake_spd_finish(&s->spd);
    mk_arena arena = s->arena;
    mk_arena_free_all(&arena);
}

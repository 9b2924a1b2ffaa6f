/* SPDX-License-Identifier: MIT */
/* Deformation transfer, the correspondence phase (transfer_internal.h, docs/baking.md): the source
 * deformed towards the target by the iterated optimization of Sumner & Popovic (2004), section 5,
 * before triangles are matched.
 *
 * Conventions fixed here:
 * - Unknowns: the position-welded source vertices that are not markers, and one fourth vertex per
 *   non-degenerate source triangle; the three coordinates share the matrix (three right-hand
 *   sides). A marker's source vertex is held at its target vertex (its terms move to the
 *   right-hand side); two markers on one source vertex hold it at the later one's target vertex.
 * - T_i = V~_i V_i^-1 with V_i the edge matrix (fourth vertex included) of the source at the
 *   start (the aligned rest), so E_I measures the change from the aligned source.
 * - Smoothness pairs: triangles sharing an edge of welded vertices (at a non-manifold edge, each
 *   triangle with the next one in index order).
 * - The closest point of a vertex: on the target triangle nearest to it among those whose normal
 *   makes a positive dot product with the vertex normal (area-weighted over its triangles at the
 *   current positions). A vertex without one is held where it is for that solve (its closest
 *   point is its own position), so the matrix is the same for every vertex and stays definite.
 * - The closest term is divided by L^2, L the target's bounding-box diagonal, so the weights do
 *   not depend on the meshes' units.
 * - The matrix is analyzed once (CHOLMOD's symbolic factorization) and factored again for each
 *   weight: it changes only on the diagonal of the vertex unknowns. Without markers the first
 *   solve (w_C = 0) is skipped: nothing would hold the source in place.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "transfer_internal.h"
#include "bake_util.h"
#include "mesh_groups.h"
#include "sparse_spd.h"

typedef struct reg {
    const bake_register_params *p;
    uint32_t welded, *weld;        /* source render -> welded */
    uint32_t *var;                 /* welded -> unknown, UINT32_MAX for a marker vertex */
    double *fixed;                 /* 3 per welded vertex: a marker vertex's position */
    double *pos;                   /* 3 per welded vertex: the current positions */
    uint32_t live, *tri;           /* non-degenerate source triangles */
    double *coef;                  /* 12 per live triangle: column c, corner q at [4 c + q] */
    uint32_t free_count, unknowns;
} reg;

/* Unknown of corner q (0..2, 3: the fourth vertex) of live triangle u, UINT32_MAX when held. */
static uint32_t corner_var(const reg *g, uint32_t u, int q)
{
    if (q == 3) return g->free_count + u;
    return g->var[g->weld[g->p->source->triangles[3 * (size_t)g->tri[u] + q]]];
}

static uint32_t corner_welded(const reg *g, uint32_t u, int q)
{
    return g->weld[g->p->source->triangles[3 * (size_t)g->tri[u] + q]];
}

/* A sparse row: up to 8 (unknown or held welded vertex, coefficient) terms. */
typedef struct row {
    int n;
    uint32_t var[8], held[8];      /* held: welded vertex when var is UINT32_MAX */
    double a[8];
} row;

static void row_add(const reg *g, row *r, uint32_t u, int c, double sign)
{
    const double *k = g->coef + 12 * (size_t)u + 4 * c;
    for (int q = 0; q < 4; q++) {
        uint32_t v = corner_var(g, u, q), h = q == 3 ? UINT32_MAX : corner_welded(g, u, q);
        int i = 0;
        while (i < r->n && !(r->var[i] == v && (v != UINT32_MAX || r->held[i] == h))) i++;
        if (i == r->n) { r->var[i] = v; r->held[i] = h; r->a[i] = 0; r->n++; }
        r->a[i] += sign * k[q];
    }
}

/* Adds weight * row row^T to the triplets (upper triangle) and weight * row * (b - held part) to
 * the right-hand sides (nu rows per coordinate; b: 3 values, one per coordinate). */
static void row_emit(const reg *g, const row *r, double weight, const double b[3], cholmod_triplet *T, double *rhs)
{
    int *ti = T->i, *tj = T->j;
    double *tx = T->x, rest[3] = { b[0], b[1], b[2] };
    for (int i = 0; i < r->n; i++)
        if (r->var[i] == UINT32_MAX)
            for (int c = 0; c < 3; c++) rest[c] -= r->a[i] * g->fixed[3 * (size_t)r->held[i] + c];
    for (int i = 0; i < r->n; i++) {
        uint32_t vi = r->var[i];
        if (vi == UINT32_MAX) continue;
        for (int c = 0; c < 3; c++) rhs[(size_t)c * g->unknowns + vi] += weight * r->a[i] * rest[c];
        for (int j = 0; j < r->n; j++) {
            uint32_t vj = r->var[j];
            if (vj == UINT32_MAX || vi > vj) continue;
            size_t k = T->nnz++;
            ti[k] = (int)vi; tj[k] = (int)vj; tx[k] = weight * r->a[i] * r->a[j];
        }
    }
}

typedef struct edge_ref { uint32_t lo, hi, u; } edge_ref;

static int edge_cmp(const void *a, const void *b)
{
    const edge_ref *x = a, *y = b;
    if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
    return x->u < y->u ? -1 : x->u > y->u;
}

/* Area-weighted vertex normals (3 per welded vertex) of the source at `render` (its positions
 * per render vertex, copied from g->pos here). */
static void vertex_normals(const reg *g, double *render, double *normals)
{
    const mk_raw_mesh *src = g->p->source;
    for (uint32_t v = 0; v < src->vertex_count; v++)
        memcpy(render + 3 * (size_t)v, g->pos + 3 * (size_t)g->weld[v], 3 * sizeof(double));
    memset(normals, 0, 3 * (size_t)g->welded * sizeof(double));
    for (uint32_t u = 0; u < g->live; u++) {
        double n[3];
        mk_face_normal(src, render, g->tri[u], n);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) normals[3 * (size_t)corner_welded(g, u, k) + c] += n[c];
    }
}

mk_result bake_transfer_register(const bake_register_params *p, double *deformed, const mk_allocator *allocator,
                                 bake_register_stats *stats, mk_error *err)
{
    const mk_raw_mesh *src = p->source, *tg = p->target;
    double t0 = bake_now();
    memset(stats, 0, sizeof *stats);
    mk_arena scratch;
    mk_arena_init(&scratch, allocator);
    mk_arena *arena = &scratch;
    reg g;
    memset(&g, 0, sizeof g);
    g.p = p;
    g.weld = mk_mesh_weld(src, arena, &g.welded);
    if (!g.weld) { mk_arena_free_all(&scratch); return mk_error_oom(err, "registration"); }
    size_t nw = g.welded, ns = src->triangle_count;
    g.var = mk_arena_array(arena, nw + 1, sizeof(uint32_t));
    g.fixed = mk_arena_array(arena, 3 * nw + 1, sizeof(double));
    g.pos = mk_arena_array(arena, 3 * nw + 1, sizeof(double));
    g.tri = mk_arena_array(arena, ns + 1, sizeof(uint32_t));
    g.coef = mk_arena_array(arena, 12 * ns + 1, sizeof(double));
    double *normals = mk_arena_array(arena, 3 * nw + 1, sizeof(double));
    double *closest = mk_arena_array(arena, 3 * nw + 1, sizeof(double));
    uint32_t *parent = mk_arena_array(arena, nw + 1, sizeof(uint32_t));
    unsigned char *anchored = mk_arena_array(arena, nw + 1, 1);  /* per welded root: the component has a marker */
    const double *target_pos = p->target_grid->positions;
    if (!g.var || !g.fixed || !g.pos || !g.tri || !g.coef || !normals || !closest || !parent || !anchored) {
        mk_arena_free_all(&scratch);
        return mk_error_oom(err, "registration");
    }
    for (uint32_t v = 0; v < src->vertex_count; v++)
        memcpy(g.pos + 3 * (size_t)g.weld[v], deformed + 3 * (size_t)v, 3 * sizeof(double));
    /* live triangles and the coefficients of T = V~ V^-1 at the start */
    for (uint32_t s = 0; s < ns; s++) {
        const uint32_t *t = src->triangles + 3 * (size_t)s;
        if (g.weld[t[0]] == g.weld[t[1]] || g.weld[t[1]] == g.weld[t[2]] || g.weld[t[0]] == g.weld[t[2]] ||
            !bake_transfer_coefficients(g.coef + 12 * (size_t)g.live, deformed + 3 * (size_t)t[0],
                                        deformed + 3 * (size_t)t[1], deformed + 3 * (size_t)t[2])) continue;
        g.tri[g.live++] = s;
    }
    /* held: the markers' vertices (at their target vertices) and the vertices in no live triangle
     * (where they are); the components (over live triangles) that hold a marker */
    for (size_t w = 0; w < nw; w++) { g.var[w] = UINT32_MAX; parent[w] = (uint32_t)w; }
    memcpy(g.fixed, g.pos, 3 * nw * sizeof(double));
    for (uint32_t u = 0; u < g.live; u++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = bake_find_root(parent, corner_welded(&g, u, k)), b = bake_find_root(parent, corner_welded(&g, u, (k + 1) % 3));
            if (a != b) parent[a < b ? b : a] = a < b ? a : b;
            g.var[corner_welded(&g, u, k)] = 0;
        }
    memset(anchored, 0, nw);
    for (uint32_t m = 0; m < p->marker_count; m++) {
        uint32_t w = g.weld[p->markers[m][0]];
        g.var[w] = UINT32_MAX;
        memcpy(g.fixed + 3 * (size_t)w, target_pos + 3 * (size_t)p->markers[m][1], 3 * sizeof(double));
        anchored[bake_find_root(parent, w)] = 1;
    }
    for (size_t w = 0; w < nw; w++)
        if (g.var[w] != UINT32_MAX) g.var[w] = g.free_count++;
    if (g.live == 0) {
        mk_arena_free_all(&scratch);
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "source mesh has no triangle with an area");
    }
    g.unknowns = g.free_count + g.live;
    /* smoothness pairs: triangles sharing a welded edge, adjacent in (edge, triangle) order */
    edge_ref *edges = mk_arena_array(arena, 3 * (size_t)g.live + 1, sizeof *edges);
    if (!edges) { mk_arena_free_all(&scratch); return mk_error_oom(err, "registration"); }
    for (uint32_t u = 0; u < g.live; u++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = corner_welded(&g, u, k), b = corner_welded(&g, u, (k + 1) % 3);
            edges[3 * (size_t)u + k] = (edge_ref){ a < b ? a : b, a < b ? b : a, u };
        }
    qsort(edges, 3 * (size_t)g.live, sizeof *edges, edge_cmp);
    size_t pairs = 0;
    for (size_t e = 0; e + 1 < 3 * (size_t)g.live; e++)
        if (edges[e].lo == edges[e + 1].lo && edges[e].hi == edges[e + 1].hi) pairs++;

    /* the matrix without the closest term (its diagonal entries are there, at 0) and the
     * right-hand sides of the terms that do not change */
    bake_spd spd;
    memset(&spd, 0, sizeof spd);
    bake_spd_start(&spd, 0, 1);
    /* identity: 10 entries (upper triangle of 4 unknowns) per column; smoothness: 21 (6 unknowns) */
    size_t cap = 30 * (size_t)g.live + 3 * 21 * pairs + g.free_count + 1;
    cholmod_triplet *T = cholmod_allocate_triplet(g.unknowns, g.unknowns, cap, 1, CHOLMOD_REAL, &spd.cm);
    double *rhs_base = mk_arena_array(arena, 3 * (size_t)g.unknowns + 1, sizeof(double));
    mk_result r = MK_OK;
    cholmod_sparse *A0 = NULL, *A = NULL;
    if (!T || !rhs_base) { r = mk_error_oom(err, "registration system"); goto done; }
    for (uint32_t u = 0; u < g.live; u++)
        for (int c = 0; c < 3; c++) {
            row rw = { 0 };
            row_add(&g, &rw, u, c, 1);
            double b[3] = { c == 0, c == 1, c == 2 };  /* column c of I, per coordinate */
            row_emit(&g, &rw, p->identity, b, T, rhs_base);
        }
    for (size_t e = 0; e + 1 < 3 * (size_t)g.live; e++) {
        if (edges[e].lo != edges[e + 1].lo || edges[e].hi != edges[e + 1].hi) continue;
        for (int c = 0; c < 3; c++) {
            row rw = { 0 };
            row_add(&g, &rw, edges[e].u, c, 1);
            row_add(&g, &rw, edges[e + 1].u, c, -1);
            static const double zero[3] = { 0, 0, 0 };
            row_emit(&g, &rw, p->smoothness, zero, T, rhs_base);
        }
    }
    for (uint32_t v = 0; v < g.free_count; v++) {
        size_t k = T->nnz++;
        ((int *)T->i)[k] = (int)v; ((int *)T->j)[k] = (int)v; ((double *)T->x)[k] = 0;
    }
    A0 = cholmod_triplet_to_sparse(T, 0, &spd.cm);
    cholmod_free_triplet(&T, &spd.cm);
    if (!A0) { r = mk_error_oom(err, "registration system"); goto done; }
    /* where each vertex unknown's diagonal entry sits (upper triangle: last in its column) */
    size_t *diag = mk_arena_array(arena, (size_t)g.free_count + 1, sizeof(size_t));
    if (!diag) { r = mk_error_oom(err, "registration system"); goto done; }
    {
        const int *Ap = A0->p, *Ai = A0->i;
        for (uint32_t v = 0; v < g.free_count; v++) {
            int q = Ap[v];
            while (q < Ap[v + 1] && Ai[q] != (int)v) q++;
            diag[v] = (size_t)q;
        }
    }
    bake_tri_grid *grid = p->target_grid;
    double lo[3], hi[3], diagonal;
    bake_bounds(tg, lo, hi, &diagonal);
    if (!(diagonal > 0)) diagonal = 1;
    uint32_t first = p->marker_count ? 0 : 1;
    for (uint32_t level = first; level <= p->step_count; level++) {
        double w = level == 0 ? 0 : p->steps[level - 1] / (diagonal * diagonal), hold = 1 / (diagonal * diagonal);
        if (level > 0) {  /* closest valid points at the current positions */
            vertex_normals(&g, deformed, normals);
            for (size_t v = 0; v < nw; v++) {
                double b[3];
                uint32_t t = g.var[v] == UINT32_MAX ? UINT32_MAX
                                                    : bake_tri_grid_closest(grid, g.pos + 3 * v, normals + 3 * v, b, NULL, NULL);
                if (t == UINT32_MAX) { memcpy(closest + 3 * v, g.pos + 3 * v, 3 * sizeof(double)); continue; }
                const uint32_t *tt = tg->triangles + 3 * (size_t)t;
                for (int c = 0; c < 3; c++)
                    closest[3 * v + c] = b[0] * target_pos[3 * (size_t)tt[0] + c] + b[1] * target_pos[3 * (size_t)tt[1] + c] +
                                         b[2] * target_pos[3 * (size_t)tt[2] + c];
            }
        }
        /* the weight changed: factor again, with the first analysis (the same pattern) */
        if (!A && !(A = cholmod_copy_sparse(A0, &spd.cm))) { r = mk_error_oom(err, "registration system"); goto done; }
        memcpy(A->x, A0->x, (size_t)((const int *)A0->p)[A0->ncol] * sizeof(double));  /* packed: p[n] entries */
        /* at the first solve (w_C = 0) a component without a marker would be free to move: it is
         * held where it is with the weight 1 / L^2 */
        for (size_t v = 0; v < nw; v++)
            if (g.var[v] != UINT32_MAX)
                ((double *)A->x)[diag[g.var[v]]] += level == 0 && !anchored[bake_find_root(parent, (uint32_t)v)] ? hold : w;
        if ((r = level == first ? bake_spd_factor_matrix(&spd, A, 3, err) : bake_spd_refactor(&spd, A, err)) != MK_OK)
            goto done;
        double *b = spd.rhs->x;
        memcpy(b, rhs_base, 3 * (size_t)g.unknowns * sizeof(double));
        for (size_t v = 0; v < nw; v++) {
            if (g.var[v] == UINT32_MAX) continue;
            int held = level == 0 && !anchored[bake_find_root(parent, (uint32_t)v)];
            for (int c = 0; c < 3; c++)
                b[(size_t)c * g.unknowns + g.var[v]] += held ? hold * g.pos[3 * v + c] : w * closest[3 * v + c];
        }
        if ((r = bake_spd_solve(&spd, err)) != MK_OK) goto done;
        const double *x = spd.x->x;
        for (size_t v = 0; v < nw; v++)
            for (int c = 0; c < 3; c++)
                g.pos[3 * v + c] = g.var[v] == UINT32_MAX ? g.fixed[3 * v + c] : x[(size_t)c * g.unknowns + g.var[v]];
    }
    /* how close the fit came: every vertex to the nearest target point facing its way */
    vertex_normals(&g, deformed, normals);
    double sum = 0;
    uint32_t counted = 0;
    for (size_t v = 0; v < nw; v++) {
        double b[3], d2;
        if (bake_tri_grid_closest(grid, g.pos + 3 * v, normals + 3 * v, b, &d2, NULL) == UINT32_MAX) continue;
        double d = sqrt(d2) / diagonal;
        sum += d;
        counted++;
        if (d > stats->max_distance) stats->max_distance = d;
    }
    stats->mean_distance = counted ? sum / counted : 0;
    for (uint32_t m = 0; m < p->marker_count; m++) {
        double d[3];
        vec3_sub(d, g.pos + 3 * (size_t)g.weld[p->markers[m][0]], target_pos + 3 * (size_t)p->markers[m][1]);
        stats->marker_distance = fmax(stats->marker_distance, vec3_length(d) / diagonal);
    }
    for (uint32_t v = 0; v < src->vertex_count; v++)
        memcpy(deformed + 3 * (size_t)v, g.pos + 3 * (size_t)g.weld[v], 3 * sizeof(double));
    stats->solves = spd.solves;
    stats->factorizations = spd.factorizations;
done:
    if (A) cholmod_free_sparse(&A, &spd.cm);
    if (A0) cholmod_free_sparse(&A0, &spd.cm);
    if (T) cholmod_free_triplet(&T, &spd.cm);
    bake_spd_finish(&spd);
    mk_arena_free_all(&scratch);
    stats->seconds = bake_now() - t0;
    return r;
}

/* SPDX-License-Identifier: MIT */
/* Continuous collision handling for the shell (Bridson, Fedkiw, Anderson 2002, "Robust treatment
 * of collisions, contact and friction for cloth animation"): over a step every vertex moves on a
 * straight line x + t (p - x), t in [0, 1]. A vertex-triangle or edge-edge pair can only cross
 * when its four points are coplanar, which is a cubic in t; at each root in [0, 1] the pair is
 * checked for actual contact (distance within the tolerance). Broad phase: the swept boxes of
 * triangles and edges (inflated by the thickness) in a hashed uniform grid; pairs that share a
 * vertex are skipped. A pair that also ends closer than the thickness while it started farther
 * counts as a hit (a proximity test backing up the root finding).
 *
 * Response: the vertices of a hit are moved back to 0.8 of their time of impact; hits that
 * remain after that are moved back to the start of the step (which was free of intersections),
 * round after round, so the result never crosses itself within the tests' resolution. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "shell.h"
#include "bake_util.h"

#define MAX_ROUNDS 64

typedef struct cell_entry {
    uint64_t key;
    uint32_t item;
} cell_entry;

typedef struct grid {
    cell_entry *entries;
    size_t count, capacity;
    double cell;
    mk_arena *arena;
} grid;

static int compare_entries(const void *pa, const void *pb)
{
    const cell_entry *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return a->item < b->item ? -1 : a->item > b->item;
}

static uint64_t cell_key(int64_t i, int64_t j, int64_t k)
{
    return ((uint64_t)(i & 0x1fffff) << 42) | ((uint64_t)(j & 0x1fffff) << 21) | (uint64_t)(k & 0x1fffff);
}

/* Box of the points idx[0..k) over the step (start x, end p), inflated by pad. */
static void swept_box(const double *x, const double *p, const uint32_t *idx, int k, double pad, double lo[3], double hi[3])
{
    for (int c = 0; c < 3; c++) { lo[c] = INFINITY; hi[c] = -INFINITY; }
    for (int i = 0; i < k; i++)
        for (int c = 0; c < 3; c++) {
            double a = x[3 * (size_t)idx[i] + c], b = p[3 * (size_t)idx[i] + c];
            double l = a < b ? a : b, h = a < b ? b : a;
            if (l < lo[c]) lo[c] = l;
            if (h > hi[c]) hi[c] = h;
        }
    for (int c = 0; c < 3; c++) { lo[c] -= pad; hi[c] += pad; }
}

static int grid_add(grid *g, const double lo[3], const double hi[3], uint32_t item)
{
    int64_t a[3], b[3];
    for (int c = 0; c < 3; c++) { a[c] = (int64_t)floor(lo[c] / g->cell); b[c] = (int64_t)floor(hi[c] / g->cell); }
    for (int64_t i = a[0]; i <= b[0]; i++)
        for (int64_t j = a[1]; j <= b[1]; j++)
            for (int64_t k = a[2]; k <= b[2]; k++) {
                if (g->count == g->capacity) {
                    size_t nc = g->capacity ? 2 * g->capacity : 1024;
                    cell_entry *ne = mk_arena_realloc(g->arena, g->entries, g->capacity * sizeof *ne, nc * sizeof *ne);
                    if (!ne) return 0;
                    g->entries = ne;
                    g->capacity = nc;
                }
                g->entries[g->count++] = (cell_entry){ cell_key(i, j, k), item };
            }
    return 1;
}

static size_t lower_bound(const grid *g, uint64_t key)
{
    size_t lo = 0, hi = g->count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (g->entries[mid].key < key) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* ---- narrow phase ---- */

static void lerp3(double out[3], const double *a, const double *b, double t)
{
    for (int c = 0; c < 3; c++) out[c] = a[c] + t * (b[c] - a[c]);
}

/* Squared distance from q to triangle abc (closest point by region, Ericson's method). */
static double point_triangle_distance2(const double q[3], const double a[3], const double b[3], const double c[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], r[3];
    vec3_sub(ab, b, a); vec3_sub(ac, c, a); vec3_sub(ap, q, a);
    double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) { vec3_sub(r, q, a); return vec3_dot(r, r); }
    vec3_sub(bp, q, b);
    double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) { vec3_sub(r, q, b); return vec3_dot(r, r); }
    double vc = d1 * d4 - d3 * d2, w[3];
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++) w[k] = a[k] + v * ab[k];
        vec3_sub(r, q, w); return vec3_dot(r, r);
    }
    vec3_sub(cp, q, c);
    double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) { vec3_sub(r, q, c); return vec3_dot(r, r); }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double v = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++) w[k] = a[k] + v * ac[k];
        vec3_sub(r, q, w); return vec3_dot(r, r);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++) w[k] = b[k] + v * (c[k] - b[k]);
        vec3_sub(r, q, w); return vec3_dot(r, r);
    }
    double den = 1 / (va + vb + vc), v = vb * den, u = vc * den;
    for (int k = 0; k < 3; k++) w[k] = a[k] + v * ab[k] + u * ac[k];
    vec3_sub(r, q, w);
    return vec3_dot(r, r);
}

static double clamp01(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

/* Squared distance between segments p0p1 and q0q1 (Ericson's closest points). */
static double segment_distance2(const double p0[3], const double p1[3], const double q0[3], const double q1[3])
{
    double d1[3], d2[3], r[3];
    vec3_sub(d1, p1, p0); vec3_sub(d2, q1, q0); vec3_sub(r, p0, q0);
    double a = vec3_dot(d1, d1), e = vec3_dot(d2, d2), f = vec3_dot(d2, r), s, t;
    if (a <= 1e-300 && e <= 1e-300) s = t = 0;
    else if (a <= 1e-300) { s = 0; t = clamp01(f / e); }
    else {
        double c = vec3_dot(d1, r);
        if (e <= 1e-300) { t = 0; s = clamp01(-c / a); }
        else {
            double b = vec3_dot(d1, d2), den = a * e - b * b;
            s = den > 1e-300 ? clamp01((b * f - c * e) / den) : 0;
            t = (b * s + f) / e;
            if (t < 0) { t = 0; s = clamp01(-c / a); }
            else if (t > 1) { t = 1; s = clamp01((b - c) / a); }
        }
    }
    double w[3];
    for (int k = 0; k < 3; k++) w[k] = (p0[k] + s * d1[k]) - (q0[k] + t * d2[k]);
    return vec3_dot(w, w);
}

/* Distance of the pair at time t: kind 0 = point 3 against triangle 0 1 2, 1 = edge 0 1 against
 * edge 2 3. */
static double pair_distance2(int kind, const double *const s[4], const double *const e[4], double t)
{
    double q[4][3];
    for (int i = 0; i < 4; i++) lerp3(q[i], s[i], e[i], t);
    return kind == 0 ? point_triangle_distance2(q[3], q[0], q[1], q[2]) : segment_distance2(q[0], q[1], q[2], q[3]);
}

static double cubic(const double k[4], double t) { return ((k[3] * t + k[2]) * t + k[1]) * t + k[0]; }

/* Earliest time in [0, 1] at which the pair touches (within tol), or -1. */
static double time_of_impact(int kind, const double *const s[4], const double *const e[4], double tol)
{
    double x21[3], x31[3], x41[3], v21[3], v31[3], v41[3], v[4][3];
    for (int i = 0; i < 4; i++) vec3_sub(v[i], e[i], s[i]);
    vec3_sub(x21, s[1], s[0]); vec3_sub(x31, s[2], s[0]); vec3_sub(x41, s[3], s[0]);
    vec3_sub(v21, v[1], v[0]); vec3_sub(v31, v[2], v[0]); vec3_sub(v41, v[3], v[0]);
    double c[3], k[4];
    vec3_cross(c, x21, x31); k[0] = vec3_dot(c, x41);
    k[1] = vec3_dot(c, v41);
    vec3_cross(c, v21, x31); k[1] += vec3_dot(c, x41); k[2] = vec3_dot(c, v41);
    vec3_cross(c, x21, v31); k[1] += vec3_dot(c, x41); k[2] += vec3_dot(c, v41);
    vec3_cross(c, v21, v31); k[2] += vec3_dot(c, x41); k[3] = vec3_dot(c, v41);
    /* Monotone pieces of f on [0, 1]: split at the roots of f' = 3 k3 t^2 + 2 k2 t + k1. */
    double cuts[4] = { 0, 1, 1, 1 };
    int nc = 1;
    double A = 3 * k[3], B = 2 * k[2], C = k[1];
    if (fabs(A) > 1e-300) {
        double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            double sq = sqrt(disc), r1 = (-B - sq) / (2 * A), r2 = (-B + sq) / (2 * A);
            if (r1 > r2) { double tmp = r1; r1 = r2; r2 = tmp; }
            if (r1 > 0 && r1 < 1) cuts[nc++] = r1;
            if (r2 > 0 && r2 < 1) cuts[nc++] = r2;
        }
    } else if (fabs(B) > 1e-300) {
        double r1 = -C / B;
        if (r1 > 0 && r1 < 1) cuts[nc++] = r1;
    }
    cuts[nc++] = 1;
    double tol2 = tol * tol;
    for (int i = 0; i + 1 < nc; i++) {
        double a = cuts[i], b = cuts[i + 1], fa = cubic(k, a), fb = cubic(k, b);
        if (fa != 0 && fb != 0 && (fa > 0) == (fb > 0)) continue;
        double t = a;
        if (fa == 0) t = a;
        else if (fb == 0) t = b;
        else {
            for (int it = 0; it < 50; it++) {
                double m = 0.5 * (a + b), fm = cubic(k, m);
                if ((fm > 0) == (fa > 0)) { a = m; fa = fm; } else b = m;
            }
            t = 0.5 * (a + b);
        }
        if (pair_distance2(kind, s, e, t) <= tol2) return t;
    }
    return -1;
}

typedef struct collide_ctx {
    const shell_mesh *m;
    const double *x;
    double *p;
    double thickness, tol;
    double *scale;            /* per vertex: fraction of its step kept this round (1: untouched) */
    uint32_t *stamp;          /* per triangle or edge: query + 1 of the last visit */
    unsigned char *moved;     /* per vertex: pulled back in the previous round */
    double *boxes[2];         /* this round's swept boxes (lo, hi: 6 doubles) of triangles, edges */
    uint32_t vt, ee;
} collide_ctx;

/* One pair: on a hit, the four vertices keep at most 0.8 of the time of impact (round 0) or
 * nothing (later rounds). */
static void test_pair(collide_ctx *c, int kind, const uint32_t idx[4], int round)
{
    /* After the first round only pairs with a vertex pulled back in the previous round can
     * change: the others move as they did when they were tested. */
    if (round > 0 && !c->moved[idx[0]] && !c->moved[idx[1]] && !c->moved[idx[2]] && !c->moved[idx[3]]) return;
    const double *s[4], *e[4];
    for (int i = 0; i < 4; i++) { s[i] = c->x + 3 * (size_t)idx[i]; e[i] = c->p + 3 * (size_t)idx[i]; }
    double t = time_of_impact(kind, s, e, c->tol);
    if (t < 0 && c->thickness > 0) {
        double th2 = c->thickness * c->thickness;
        if (pair_distance2(kind, s, e, 1) < th2 && pair_distance2(kind, s, e, 0) >= th2) t = 1;
    }
    if (t < 0) return;
    if (kind == 0) c->vt++; else c->ee++;
    double keep = round == 0 ? 0.8 * t : 0;
    for (int i = 0; i < 4; i++)
        if (keep < c->scale[idx[i]]) c->scale[idx[i]] = keep;
}

/* The candidates of one query item (kind 0: vertex `query` against the triangles of g; 1: edge
 * `query` against the edges of g with a larger index) whose swept boxes overlap, each once
 * (c->stamp), without pairs that share a vertex; each goes to test_pair. */
static void visit_cells(collide_ctx *c, const grid *g, int kind, uint32_t query, int round)
{
    const shell_mesh *m = c->m;
    const uint32_t *qa = kind == 0 ? &query : m->hinges + 4 * (size_t)query;
    double lo[3], hi[3];
    swept_box(c->x, c->p, qa, kind == 0 ? 1 : 2, c->thickness, lo, hi);
    int64_t a[3], b[3];
    for (int k = 0; k < 3; k++) { a[k] = (int64_t)floor(lo[k] / g->cell); b[k] = (int64_t)floor(hi[k] / g->cell); }
    for (int64_t i = a[0]; i <= b[0]; i++)
        for (int64_t j = a[1]; j <= b[1]; j++)
            for (int64_t k = a[2]; k <= b[2]; k++) {
                uint64_t key = cell_key(i, j, k);
                for (size_t q = lower_bound(g, key); q < g->count && g->entries[q].key == key; q++) {
                    uint32_t item = g->entries[q].item;
                    if ((kind == 1 && item <= query) || c->stamp[item] == query + 1) continue;
                    c->stamp[item] = query + 1;
                    const uint32_t *ib = kind == 0 ? m->tris + 3 * (size_t)item : m->hinges + 4 * (size_t)item;
                    int nb = kind == 0 ? 3 : 2, shared = 0;
                    for (int u = 0; u < (kind == 0 ? 1 : 2); u++)
                        for (int w = 0; w < nb; w++) shared |= qa[u] == ib[w];
                    if (shared) continue;
                    const double *blo = c->boxes[kind] + 6 * (size_t)item, *bhi = blo + 3;
                    if (blo[0] > hi[0] || bhi[0] < lo[0] || blo[1] > hi[1] || bhi[1] < lo[1] || blo[2] > hi[2] || bhi[2] < lo[2])
                        continue;
                    uint32_t idx[4];
                    if (kind == 0) { idx[0] = ib[0]; idx[1] = ib[1]; idx[2] = ib[2]; idx[3] = query; }
                    else { idx[0] = qa[0]; idx[1] = qa[1]; idx[2] = ib[0]; idx[3] = ib[1]; }
                    test_pair(c, kind, idx, round);
                }
            }
}

mk_result shell_collide(const shell_mesh *m, const double *x, double *p, double thickness, mk_arena *arena,
                        uint32_t *vt, uint32_t *ee, uint32_t *rounds, mk_error *err)
{
    *vt = *ee = *rounds = 0;
    mk_arena local;
    mk_arena_init(&local, &arena->allocator);
    double *scale = mk_arena_array(&local, m->n, sizeof(double));
    uint32_t *stamp = mk_arena_array(&local, (size_t)m->tri_count + m->hinge_count, sizeof(uint32_t));
    unsigned char *moved = mk_arena_array(&local, m->n, 1);
    double *tri_boxes = mk_arena_array(&local, 6 * (size_t)m->tri_count, sizeof(double));
    double *edge_boxes = mk_arena_array(&local, 6 * (size_t)m->hinge_count, sizeof(double));
    mk_result r = MK_OK;
    if (!scale || !stamp || !moved || !tri_boxes || !edge_boxes) { mk_arena_free_all(&local); return mk_error_oom(err, "shell collisions"); }
    /* Cell size: the mean edge length at the step's start. */
    double mean = 0;
    for (uint32_t h = 0; h < m->hinge_count; h++) {
        double d[3];
        vec3_sub(d, x + 3 * (size_t)m->hinges[4 * (size_t)h], x + 3 * (size_t)m->hinges[4 * (size_t)h + 1]);
        mean += vec3_length(d) / m->hinge_count;
    }
    collide_ctx c = { m, x, p, thickness, fmax(thickness, 1e-9 * mean), scale, stamp, moved, { tri_boxes, edge_boxes }, 0, 0 };
    for (int round = 0; round < MAX_ROUNDS; round++) {
        grid tg = { NULL, 0, 0, fmax(2 * mean, 4 * thickness), &local }, eg = tg;
        int ok = 1;
        for (uint32_t t = 0; t < m->tri_count && ok; t++) {
            double *box = c.boxes[0] + 6 * (size_t)t;
            swept_box(x, p, m->tris + 3 * (size_t)t, 3, thickness, box, box + 3);
            ok = grid_add(&tg, box, box + 3, t);
        }
        for (uint32_t h = 0; h < m->hinge_count && ok; h++) {
            double *box = c.boxes[1] + 6 * (size_t)h;
            swept_box(x, p, m->hinges + 4 * (size_t)h, 2, thickness, box, box + 3);
            ok = grid_add(&eg, box, box + 3, h);
        }
        if (!ok) { r = mk_error_oom(err, "shell collisions"); break; }
        qsort(tg.entries, tg.count, sizeof *tg.entries, compare_entries);
        qsort(eg.entries, eg.count, sizeof *eg.entries, compare_entries);
        for (uint32_t v = 0; v < m->n; v++) scale[v] = 1;
        memset(stamp, 0, ((size_t)m->tri_count + m->hinge_count) * sizeof(uint32_t));
        uint32_t before = c.vt + c.ee;
        /* Vertex against triangle, then edge against edge (each unordered pair once). */
        for (uint32_t v = 0; v < m->n; v++) visit_cells(&c, &tg, 0, v, round);
        memset(stamp, 0, ((size_t)m->tri_count + m->hinge_count) * sizeof(uint32_t));
        for (uint32_t e = 0; e < m->hinge_count; e++) visit_cells(&c, &eg, 1, e, round);
        *rounds = (uint32_t)round + 1;
        mk_arena_release(&local, tg.entries);
        mk_arena_release(&local, eg.entries);
        if (c.vt + c.ee == before) break;
        /* Response: pull the hit vertices back along their step. */
        for (uint32_t v = 0; v < m->n; v++) {
            moved[v] = scale[v] < 1;
            if (scale[v] < 1)
                for (int k = 0; k < 3; k++) {
                    size_t i = 3 * (size_t)v + (size_t)k;
                    p[i] = x[i] + scale[v] * (p[i] - x[i]);
                }
        }
        if (round == MAX_ROUNDS - 1) memcpy(p, x, 3 * (size_t)m->n * sizeof(double));  /* fail-safe: no motion */
    }
    *vt = c.vt;
    *ee = c.ee;
    mk_arena_free_all(&local);
    return r;
}

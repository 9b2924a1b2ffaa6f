/* SPDX-License-Identifier: MIT */
/* Continuous collision handling for the shell (Bridson, Fedkiw, Anderson 2002, "Robust treatment
 * of collisions, contact and friction for cloth animation"): over a step every vertex moves on a
 * straight line x + t (p - x), t in [0, 1]. A vertex-triangle or edge-edge pair can only cross
 * when its four points are coplanar, which is a cubic in t; at each root in [0, 1] the pair is
 * checked for actual contact (distance within the tolerance). A pair that also ends closer than
 * the thickness while it started farther counts as a hit (a proximity test backing up the root
 * finding).
 *
 * Broad phase: the swept boxes of vertices, edges and triangles (inflated by the thickness). A
 * hierarchy over the triangles' boxes, built once on the rest mesh and refitted every step
 * (shell_bvh.c), yields the pairs of triangles whose boxes overlap in one traversal of the tree
 * against itself. Every vertex and every edge is owned by one of its triangles, whose box holds
 * its own, so the vertex-triangle and edge-edge pairs whose boxes overlap are among those of
 * owners that overlap, each met once. Pairs that share a vertex are skipped.
 *
 * Response: the vertices of a hit are moved back to 0.8 of their time of impact; hits that
 * remain after that are moved back to the start of the step (which was free of intersections),
 * round after round, so the result never crosses itself within the tests' resolution. A round
 * only shortens steps along their lines, so its swept boxes lie inside round 0's: the later
 * rounds retest round 0's candidates that have a vertex moved in the round before, without a
 * broad phase. */
#include <math.h>
#include <string.h>
#include "shell.h"
#include "bake_util.h"
#include "shell_bvh.h"

#define MAX_ROUNDS 64

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

/* Are the pair's two parts (points 0-2 and 3, or 0-1 and 2-3) at least d apart on some axis
 * over the positions p0 and p1 (and so over every position between, points moving on lines)?
 * Then their distance is at least d meanwhile. */
static int apart_on_an_axis(int kind, const double (*p0)[3], const double (*p1)[3], double d)
{
    int split = kind == 0 ? 3 : 2;
    for (int c = 0; c < 3; c++) {
        double alo = INFINITY, ahi = -INFINITY, blo = INFINITY, bhi = -INFINITY;
        for (int i = 0; i < 4; i++) {
            double u = p0[i][c], w = p1[i][c], lo = u < w ? u : w, hi = u < w ? w : u;
            double *plo = i < split ? &alo : &blo, *phi = i < split ? &ahi : &bhi;
            if (lo < *plo) *plo = lo;
            if (hi > *phi) *phi = hi;
        }
        if (blo - ahi >= d || alo - bhi >= d) return 1;
    }
    return 0;
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
        /* No contact possible in [a, b] when the parts stay apart by more than tol. */
        double qa[4][3], qb[4][3];
        for (int j = 0; j < 4; j++) { lerp3(qa[j], s[j], e[j], a); lerp3(qb[j], s[j], e[j], b); }
        if (apart_on_an_axis(kind, (const double (*)[3])qa, (const double (*)[3])qb, 1.0000001 * tol)) continue;
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

struct shell_collider {
    shell_bvh tree;           /* over the triangles' boxes */
    double *tri_boxes;        /* 6 per triangle: this step's swept boxes, inflated */
    double *vertex_boxes;     /* 6 per vertex */
    double *edge_boxes;       /* 6 per edge */
    /* Every vertex and edge belongs to one of its triangles, whose box holds its own: the
     * vertices of triangle t are owned_vertices[vertex_start[t] .. vertex_start[t + 1]), its
     * edges likewise. */
    uint32_t *vertex_start, *owned_vertices, *edge_start, *owned_edges;
};

/* Lists items[0..n) by owner (counting sort): start[owner .. owner + 1) in list. */
static void group_by_owner(const uint32_t *owner, uint32_t n, uint32_t owners, uint32_t *start, uint32_t *list)
{
    memset(start, 0, ((size_t)owners + 1) * sizeof(uint32_t));
    for (uint32_t i = 0; i < n; i++) start[owner[i] + 1]++;
    for (uint32_t t = 0; t < owners; t++) start[t + 1] += start[t];
    for (uint32_t i = 0; i < n; i++) list[start[owner[i]]++] = i;
    for (uint32_t t = owners; t > 0; t--) start[t] = start[t - 1];
    start[0] = 0;
}

shell_collider *shell_collider_create(const shell_mesh *m, mk_arena *arena)
{
    shell_collider *c = mk_arena_array(arena, 1, sizeof *c);
    if (!c) return NULL;
    c->tri_boxes = mk_arena_array(arena, 6 * (size_t)m->tri_count, sizeof(double));
    c->vertex_boxes = mk_arena_array(arena, 6 * (size_t)m->n, sizeof(double));
    c->edge_boxes = mk_arena_array(arena, 6 * (size_t)m->hinge_count + 6, sizeof(double));
    c->vertex_start = mk_arena_array(arena, (size_t)m->tri_count + 1, sizeof(uint32_t));
    c->edge_start = mk_arena_array(arena, (size_t)m->tri_count + 1, sizeof(uint32_t));
    c->owned_vertices = mk_arena_array(arena, m->n, sizeof(uint32_t));
    c->owned_edges = mk_arena_array(arena, (size_t)m->hinge_count + 1, sizeof(uint32_t));
    uint32_t *owner = mk_arena_array(arena, (size_t)m->n + 1, sizeof(uint32_t));
    if (!c->tri_boxes || !c->vertex_boxes || !c->edge_boxes || !c->vertex_start || !c->edge_start || !c->owned_vertices ||
        !c->owned_edges || !owner)
        return NULL;
    /* A vertex's owner: its first triangle. */
    for (uint32_t v = 0; v < m->n; v++) owner[v] = UINT32_MAX;
    for (uint32_t t = m->tri_count; t-- > 0;)
        for (int k = 0; k < 3; k++) owner[m->tris[3 * (size_t)t + k]] = t;
    group_by_owner(owner, m->n, m->tri_count, c->vertex_start, c->owned_vertices);
    group_by_owner(m->hinge_tri, m->hinge_count, m->tri_count, c->edge_start, c->owned_edges);
    mk_arena_release(arena, owner);
    /* The hierarchy's shape from the rest mesh (neighbours on the surface stay neighbours). */
    for (uint32_t t = 0; t < m->tri_count; t++)
        swept_box(m->rest, m->rest, m->tris + 3 * (size_t)t, 3, 0, c->tri_boxes + 6 * (size_t)t, c->tri_boxes + 6 * (size_t)t + 3);
    if (!shell_bvh_build(&c->tree, c->tri_boxes, m->tri_count, arena)) return NULL;
    return c;
}

typedef struct collide_ctx {
    const shell_mesh *m;
    const shell_collider *col;
    const double *x;
    double *p;
    double thickness, tol;
    double *scale;            /* per vertex: fraction of its step kept this round (1: untouched) */
    unsigned char *moved;     /* per vertex: pulled back in the previous round */
    uint32_t vt, ee;
    /* Round 0's candidates (pairs whose swept boxes overlap), 2 per pair: triangle and vertex,
     * or edge and edge. */
    uint32_t *pairs[2];
    size_t pair_count[2], pair_capacity[2];
    mk_arena *arena;
    int oom;
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
        double end[4][3];
        for (int i = 0; i < 4; i++) memcpy(end[i], e[i], sizeof end[i]);
        if (!apart_on_an_axis(kind, (const double (*)[3])end, (const double (*)[3])end, c->thickness) &&
            pair_distance2(kind, s, e, 1) < th2 && pair_distance2(kind, s, e, 0) >= th2)
            t = 1;
    }
    if (t < 0) return;
    if (kind == 0) c->vt++; else c->ee++;
    double keep = round == 0 ? 0.8 * t : 0;
    for (int i = 0; i < 4; i++)
        if (keep < c->scale[idx[i]]) c->scale[idx[i]] = keep;
}

/* The four vertices of a candidate: triangle then vertex (kind 0), or edge then edge (kind 1). */
static void pair_vertices(const shell_mesh *m, int kind, uint32_t a, uint32_t b, uint32_t idx[4])
{
    if (kind == 0) {
        const uint32_t *t = m->tris + 3 * (size_t)a;
        idx[0] = t[0]; idx[1] = t[1]; idx[2] = t[2]; idx[3] = b;
    } else {
        const uint32_t *e = m->hinges + 4 * (size_t)a, *f = m->hinges + 4 * (size_t)b;
        idx[0] = e[0]; idx[1] = e[1]; idx[2] = f[0]; idx[3] = f[1];
    }
}

static int boxes_overlap(const double *a, const double *b)
{
    return !(a[0] > b[3] || a[3] < b[0] || a[1] > b[4] || a[4] < b[1] || a[2] > b[5] || a[5] < b[2]);
}

/* Round 0 meets a pair whose boxes overlap: unless the two share a vertex, it is kept for the
 * later rounds and tested. */
static void add_candidate(collide_ctx *c, int kind, uint32_t a, uint32_t b)
{
    if (kind == 1 && b < a) { uint32_t t = a; a = b; b = t; }  /* the smaller edge first: the same rounding either way round */
    uint32_t idx[4];
    pair_vertices(c->m, kind, a, b, idx);
    if (kind == 0 ? (idx[3] == idx[0] || idx[3] == idx[1] || idx[3] == idx[2])
                  : (idx[0] == idx[2] || idx[0] == idx[3] || idx[1] == idx[2] || idx[1] == idx[3]))
        return;
    if (c->pair_count[kind] == c->pair_capacity[kind]) {
        size_t nc = c->pair_capacity[kind] ? 2 * c->pair_capacity[kind] : 4096;
        uint32_t *np = mk_arena_realloc(c->arena, c->pairs[kind], 2 * c->pair_capacity[kind] * sizeof *np, 2 * nc * sizeof *np);
        if (!np) { c->oom = 1; return; }
        c->pairs[kind] = np;
        c->pair_capacity[kind] = nc;
    }
    c->pairs[kind][2 * c->pair_count[kind]] = a;
    c->pairs[kind][2 * c->pair_count[kind] + 1] = b;
    c->pair_count[kind]++;
    test_pair(c, kind, idx, 0);
}

/* The vertices owned by triangle u against triangle t. */
static void owned_vertices_against(collide_ctx *c, uint32_t u, uint32_t t)
{
    const shell_collider *col = c->col;
    const double *tb = col->tri_boxes + 6 * (size_t)t;
    for (uint32_t i = col->vertex_start[u]; i < col->vertex_start[u + 1]; i++) {
        uint32_t v = col->owned_vertices[i];
        if (boxes_overlap(col->vertex_boxes + 6 * (size_t)v, tb)) add_candidate(c, 0, t, v);
    }
}

/* Two triangles whose boxes overlap (possibly the same one): every vertex-triangle and edge-edge
 * pair whose vertex or edges they own. Each candidate is met once: a vertex's box lies in its
 * owner's, an edge's in its owner's. */
static void visit_triangles(void *user, uint32_t t, uint32_t u)
{
    collide_ctx *c = user;
    const shell_collider *col = c->col;
    owned_vertices_against(c, u, t);
    if (t != u) owned_vertices_against(c, t, u);
    for (uint32_t i = col->edge_start[t]; i < col->edge_start[t + 1]; i++) {
        uint32_t e = col->owned_edges[i];
        const double *eb = col->edge_boxes + 6 * (size_t)e;
        for (uint32_t j = t == u ? i + 1 : col->edge_start[u]; j < col->edge_start[u + 1]; j++) {
            uint32_t f = col->owned_edges[j];
            if (boxes_overlap(eb, col->edge_boxes + 6 * (size_t)f)) add_candidate(c, 1, e, f);
        }
    }
}

mk_result shell_collide(shell_collider *col, const shell_mesh *m, const double *x, double *p, double thickness,
                        mk_arena *arena, uint32_t *vt, uint32_t *ee, uint32_t *rounds, mk_error *err)
{
    *vt = *ee = *rounds = 0;
    mk_arena local;
    mk_arena_init(&local, &arena->allocator);
    double *scale = mk_arena_array(&local, m->n, sizeof(double));
    unsigned char *moved = mk_arena_array(&local, m->n, 1);
    if (!scale || !moved) { mk_arena_free_all(&local); return mk_error_oom(err, "shell collisions"); }
    /* Contact tolerance: the thickness, at least 1e-9 of the mean edge length at the step's start. */
    double mean = 0;
    for (uint32_t h = 0; h < m->hinge_count; h++) {
        double d[3];
        vec3_sub(d, x + 3 * (size_t)m->hinges[4 * (size_t)h], x + 3 * (size_t)m->hinges[4 * (size_t)h + 1]);
        mean += vec3_length(d) / m->hinge_count;
    }
    collide_ctx c;
    memset(&c, 0, sizeof c);
    c.m = m; c.col = col; c.x = x; c.p = p; c.thickness = thickness; c.tol = fmax(thickness, 1e-9 * mean);
    c.scale = scale; c.moved = moved; c.arena = &local;
    /* Broad phase, once: later rounds only pull vertices back along their steps, so their swept
     * boxes lie inside round 0's and round 0's candidates are all the pairs that can meet. */
    for (uint32_t t = 0; t < m->tri_count; t++)
        swept_box(x, p, m->tris + 3 * (size_t)t, 3, thickness, col->tri_boxes + 6 * (size_t)t, col->tri_boxes + 6 * (size_t)t + 3);
    for (uint32_t v = 0; v < m->n; v++)
        swept_box(x, p, &v, 1, thickness, col->vertex_boxes + 6 * (size_t)v, col->vertex_boxes + 6 * (size_t)v + 3);
    for (uint32_t h = 0; h < m->hinge_count; h++)
        swept_box(x, p, m->hinges + 4 * (size_t)h, 2, thickness, col->edge_boxes + 6 * (size_t)h, col->edge_boxes + 6 * (size_t)h + 3);
    shell_bvh_refit(&col->tree);
    for (int round = 0; round < MAX_ROUNDS; round++) {
        for (uint32_t v = 0; v < m->n; v++) scale[v] = 1;
        uint32_t before = c.vt + c.ee;
        if (round == 0) {
            shell_bvh_self_pairs(&col->tree, visit_triangles, &c);
            if (c.oom) { mk_arena_free_all(&local); return mk_error_oom(err, "shell collisions (candidate pairs)"); }
        } else {
            for (int kind = 0; kind < 2; kind++)
                for (size_t i = 0; i < c.pair_count[kind]; i++) {
                    uint32_t idx[4];
                    pair_vertices(m, kind, c.pairs[kind][2 * i], c.pairs[kind][2 * i + 1], idx);
                    test_pair(&c, kind, idx, round);
                }
        }
        *rounds = (uint32_t)round + 1;
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
    return MK_OK;
}

/* SPDX-License-Identifier: MIT */
/* Continuous collision handling for the shell (Bridson, Fedkiw, Anderson 2002, "Robust treatment
 * of collisions, contact and friction for cloth animation"): over a step every vertex moves on a
 * straight line x + t (p - x), t in [0, 1]. A vertex-triangle or edge-edge pair can only cross
 * when its four points are coplanar, which is a cubic in t; at each root in [0, 1] the pair is
 * checked for actual contact (distance within the tolerance). A pair that also ends closer than
 * the thickness while it started farther counts as a hit (a proximity test backing up the root
 * finding). The tests of one pair are in shell_ccd.c.
 *
 * Broad phase: the swept boxes of vertices, edges and triangles (inflated by the thickness). A
 * hierarchy over the triangles' boxes, built once on the rest mesh and refitted before each use
 * (shell_bvh.c), yields the pairs of triangles whose boxes overlap in one traversal of the tree
 * against itself. Every vertex and every edge is owned by one of its triangles, whose box holds
 * its own, so the vertex-triangle and edge-edge pairs whose boxes overlap are among those of
 * owners that overlap, each met once. Pairs that share a vertex are skipped. Triangles that
 * share a vertex always overlap (most of the pairs the traversal meets): their owned pairs are
 * listed once when the collider is made and only their boxes are tested per step, and the
 * traversal passes such triangles by. The triangles are stored in the tree's leaf order, with
 * what they own next to them. The traversal itself runs only now and then: it lists the other
 * pairs of triangles whose boxes, grown from every vertex's range (its step continued a few
 * steps ahead, plus a margin), overlap; while each step stays inside its vertex's range a
 * triangle's box lies inside its grown box, so the steps in between test only the listed pairs'
 * boxes (and when a list serves only a step or two, the next steps traverse directly); the
 * neighbours' listed pairs are filtered with the same grown boxes. Which pairs are tested, and
 * so every result, is the same as with a traversal per step.
 *
 * Response: the vertices of a hit are moved back to 0.8 of their time of impact; hits that
 * remain after that are moved back to the start of the step (which was free of intersections),
 * round after round, so the result never crosses itself within the tests' resolution. A round
 * only shortens steps along their lines, so its swept boxes lie inside round 0's: the later
 * rounds retest round 0's candidates that have a vertex moved in the round before, without a
 * broad phase. */
#include <math.h>
#include <string.h>
#include <threads.h>
#include "shell.h"
#include "bake_util.h"
#include "mesh_groups.h"
#include "parallel.h"
#include "shell_bvh.h"
#include "shell_ccd.h"

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

/* The triangles are numbered in the hierarchy's leaf order ("slots", shell_bvh_renumber), and
 * what a traversal reads of a slot lies together: its box, its corners, the vertices and edges
 * it owns with their boxes. */
struct shell_collider {
    shell_bvh tree;           /* over the slots' boxes */
    uint32_t *slot_tri;       /* per slot: its triangle */
    uint32_t *slot_corners;   /* 3 per slot: the triangle's vertices */
    double *tri_boxes;        /* 6 per slot: this step's swept boxes, inflated */
    /* Every vertex and edge belongs to one of its triangles, whose box holds its own: slot s owns
     * owned_vertices[vertex_start[s] .. vertex_start[s + 1]), its edges likewise. */
    uint32_t *vertex_start, *owned_vertices, *edge_start, *owned_edges;
    double *vertex_boxes;     /* 6 per entry of owned_vertices */
    double *edge_boxes;       /* 6 per entry of owned_edges */
    uint32_t *edge_ends;      /* 2 per entry of owned_edges: its vertices */
    /* Triangles that share a vertex always have overlapping boxes: their pairs that share no
     * vertex are listed once here and the traversal skips such triangles. 2 per pair: an entry of
     * owned_vertices and a slot (kind 0), or two entries of owned_edges (kind 1). */
    uint32_t *near[2];
    size_t near_count[2];
    uint32_t *live[2];        /* those of near whose grown boxes (below) overlap */
    size_t live_count[2];
    /* The other pairs of slots whose boxes can overlap (2 per pair), from one traversal of the
     * hierarchy with every vertex's box grown to a range ahead of its step (far_range, 6 per
     * vertex); valid while every step stays inside its vertex's range. */
    uint32_t *far;
    size_t far_count, far_capacity;
    double *far_range;
    double *step_box;         /* 6 per vertex: this step's box (start and end), not inflated */
    int far_valid, far_oom;
    uint32_t far_frames;      /* steps the current list has served */
    uint32_t direct_left;     /* steps still to traverse directly (the ranges held too briefly) */
    mk_arena *arena;          /* the list of far pairs grows here */
};

/* Appends (a, b) to a growing list of pairs (2 per pair); 0 when out of memory. */
static int push_pair(mk_arena *arena, uint32_t **list, size_t *count, size_t *capacity, uint32_t a, uint32_t b)
{
    if (*count == *capacity) {
        size_t nc = *capacity ? 2 * *capacity : 4096;
        uint32_t *np = mk_arena_realloc(arena, *list, 2 * *capacity * sizeof *np, 2 * nc * sizeof *np);
        if (!np) return 0;
        *list = np;
        *capacity = nc;
    }
    (*list)[2 * *count] = a;
    (*list)[2 * *count + 1] = b;
    (*count)++;
    return 1;
}

static int edges_share_a_vertex(const uint32_t a[2], const uint32_t b[2])
{
    return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
}

/* Appends (a, b) to list (2 per pair) at *count, or only counts when list is NULL. */
static void put_pair(uint32_t *list, size_t *count, uint32_t a, uint32_t b)
{
    if (list) { list[2 * *count] = a; list[2 * *count + 1] = b; }
    (*count)++;
}

/* The pairs of slots s < u sharing a vertex (through the slots around each vertex: ring holds
 * their corners 3 u + k), each once: the vertices one owns that are not the other's corners against the other, and their
 * owned edges that share no vertex. With near[k] NULL only counts. mark: one per slot. */
static void list_near_pairs(shell_collider *c, uint32_t slots, const uint32_t *ring_start, const uint32_t *ring,
                            uint32_t *mark)
{
    for (uint32_t s = 0; s < slots; s++) mark[s] = UINT32_MAX;
    c->near_count[0] = c->near_count[1] = 0;
    for (uint32_t s = 0; s < slots; s++) {
        const uint32_t *ks = c->slot_corners + 3 * (size_t)s;
        for (int k = 0; k < 3; k++)
            for (uint32_t r = ring_start[ks[k]]; r < ring_start[ks[k] + 1]; r++) {
                uint32_t u = ring[r] / 3;
                if (u <= s || mark[u] == s) continue;
                mark[u] = s;
                const uint32_t *ku = c->slot_corners + 3 * (size_t)u;
                for (int side = 0; side < 2; side++) {
                    uint32_t owner = side ? s : u, tri = side ? u : s;
                    const uint32_t *kt = side ? ku : ks;
                    for (uint32_t i = c->vertex_start[owner]; i < c->vertex_start[owner + 1]; i++) {
                        uint32_t v = c->owned_vertices[i];
                        if (v != kt[0] && v != kt[1] && v != kt[2]) put_pair(c->near[0], &c->near_count[0], i, tri);
                    }
                }
                for (uint32_t i = c->edge_start[s]; i < c->edge_start[s + 1]; i++)
                    for (uint32_t j = c->edge_start[u]; j < c->edge_start[u + 1]; j++)
                        if (!edges_share_a_vertex(c->edge_ends + 2 * (size_t)i, c->edge_ends + 2 * (size_t)j))
                            put_pair(c->near[1], &c->near_count[1], i, j);
            }
    }
}

shell_collider *shell_collider_create(const shell_mesh *m, mk_arena *arena)
{
    shell_collider *c = mk_arena_array(arena, 1, sizeof *c);
    if (!c) return NULL;
    size_t nt = m->tri_count, nh = m->hinge_count;
    c->slot_tri = mk_arena_array(arena, nt + 1, sizeof(uint32_t));
    c->slot_corners = mk_arena_array(arena, 3 * nt + 3, sizeof(uint32_t));
    c->tri_boxes = mk_arena_array(arena, 6 * nt, sizeof(double));
    c->vertex_boxes = mk_arena_array(arena, 6 * (size_t)m->n, sizeof(double));
    c->edge_boxes = mk_arena_array(arena, 6 * nh + 6, sizeof(double));
    c->edge_ends = mk_arena_array(arena, 2 * nh + 2, sizeof(uint32_t));
    c->far_range = mk_arena_array(arena, 6 * (size_t)m->n + 6, sizeof(double));
    c->step_box = mk_arena_array(arena, 6 * (size_t)m->n + 6, sizeof(double));
    c->arena = arena;
    uint32_t *slot_of = mk_arena_array(arena, nt + 1, sizeof(uint32_t));
    uint32_t *owner = mk_arena_array(arena, (size_t)(m->n > nh ? m->n : nh) + 1, sizeof(uint32_t));
    if (!c->slot_tri || !c->slot_corners || !c->tri_boxes || !c->vertex_boxes || !c->edge_boxes || !c->edge_ends ||
        !c->far_range || !c->step_box || !slot_of || !owner)
        return NULL;
    /* The hierarchy's shape from the rest mesh (neighbours on the surface stay neighbours), then
     * the slots in its leaf order. */
    for (uint32_t t = 0; t < m->tri_count; t++)
        swept_box(m->rest, m->rest, m->tris + 3 * (size_t)t, 3, 0, c->tri_boxes + 6 * (size_t)t, c->tri_boxes + 6 * (size_t)t + 3);
    if (!shell_bvh_build(&c->tree, c->tri_boxes, m->tri_count, arena)) return NULL;
    shell_bvh_renumber(&c->tree, c->slot_tri, m->tri_count);
    for (uint32_t s = 0; s < m->tri_count; s++) {
        slot_of[c->slot_tri[s]] = s;
        memcpy(c->slot_corners + 3 * (size_t)s, m->tris + 3 * (size_t)c->slot_tri[s], 3 * sizeof(uint32_t));
    }
    /* A vertex's owner: its first triangle; an edge's: the hinge's triangle. */
    for (uint32_t v = 0; v < m->n; v++) owner[v] = UINT32_MAX;
    for (uint32_t t = m->tri_count; t-- > 0;)
        for (int k = 0; k < 3; k++) owner[m->tris[3 * (size_t)t + k]] = slot_of[t];
    if (!mk_csr_build(arena, owner, m->n, m->tri_count, &c->vertex_start, &c->owned_vertices)) return NULL;
    for (uint32_t h = 0; h < m->hinge_count; h++) owner[h] = slot_of[m->hinge_tri[h]];
    if (!mk_csr_build(arena, owner, m->hinge_count, m->tri_count, &c->edge_start, &c->owned_edges)) return NULL;
    for (uint32_t i = 0; i < m->hinge_count; i++)
        memcpy(c->edge_ends + 2 * (size_t)i, m->hinges + 4 * (size_t)c->owned_edges[i], 2 * sizeof(uint32_t));
    /* The slots around each vertex (as their corners 3 s + k, in slot order; shell_mesh_build
     * keeps 3 x triangles within 32 bits), then the pairs of slots that share a vertex. */
    uint32_t *ring_start, *ring;
    if (!mk_csr_build(arena, c->slot_corners, (uint32_t)(3 * nt), m->n, &ring_start, &ring)) return NULL;
    list_near_pairs(c, m->tri_count, ring_start, ring, slot_of);
    c->near[0] = mk_arena_array(arena, 2 * c->near_count[0] + 2, sizeof(uint32_t));
    c->near[1] = mk_arena_array(arena, 2 * c->near_count[1] + 2, sizeof(uint32_t));
    c->live[0] = mk_arena_array(arena, 2 * c->near_count[0] + 2, sizeof(uint32_t));
    c->live[1] = mk_arena_array(arena, 2 * c->near_count[1] + 2, sizeof(uint32_t));
    if (!c->near[0] || !c->near[1] || !c->live[0] || !c->live[1]) return NULL;
    list_near_pairs(c, m->tri_count, ring_start, ring, slot_of);
    mk_arena_release(arena, ring);
    mk_arena_release(arena, ring_start);
    mk_arena_release(arena, owner);
    mk_arena_release(arena, slot_of);
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
    double *hit_time[2];      /* per candidate: this round's time of impact, or -1 */
    int round;
    mk_arena *arena;
    mk_team *team;            /* for the parallel parts (NULL: the caller's thread only) */
    int oom;
} collide_ctx;

/* One pair's time of impact this round, or -1 (no hit, or not retested). */
static double pair_time(const collide_ctx *c, int kind, const uint32_t idx[4], int round)
{
    /* After the first round only pairs with a vertex pulled back in the previous round can
     * change: the others move as they did when they were tested. */
    if (round > 0 && !c->moved[idx[0]] && !c->moved[idx[1]] && !c->moved[idx[2]] && !c->moved[idx[3]]) return -1;
    const double *s[4], *e[4];
    for (int i = 0; i < 4; i++) { s[i] = c->x + 3 * (size_t)idx[i]; e[i] = c->p + 3 * (size_t)idx[i]; }
    double t = shell_ccd_hit(kind, s, e, c->tol, c->thickness);
    return t < 0 ? -1 : t;
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

/* Boxes stored as six values (lo, hi) overlap. */
static int boxes_overlap(const double *a, const double *b) { return shell_boxes_overlap(a, a + 3, b, b + 3); }

/* Round 0 meets a pair that shares no vertex and whose boxes overlap: a candidate, tested in
 * every round (narrow_phase). */
static void add_candidate(collide_ctx *c, int kind, uint32_t a, uint32_t b)
{
    if (kind == 1 && b < a) { uint32_t t = a; a = b; b = t; }  /* the smaller edge first: the same rounding either way round */
    if (!push_pair(c->arena, &c->pairs[kind], &c->pair_count[kind], &c->pair_capacity[kind], a, b)) c->oom = 1;
}

/* Work split for the team: items of CHUNK list entries. */
#define CHUNK 2048

static uint32_t chunks(size_t count)
{
    return (uint32_t)((count + CHUNK - 1) / CHUNK);
}

/* The items of a loop over `lists` lists of counts[] entries, one list after the other. */
static uint32_t chunks_of(const size_t *counts, int lists)
{
    uint32_t n = 0;
    for (int l = 0; l < lists; l++) n += chunks(counts[l]);
    return n;
}

/* Item `item` of such a loop: which list, and its entries [*first, *last). */
static int chunk_range(uint32_t item, const size_t *counts, size_t *first, size_t *last)
{
    int list = 0;
    while (item >= chunks(counts[list])) item -= chunks(counts[list++]);
    *first = (size_t)item * CHUNK;
    *last = *first + CHUNK < counts[list] ? *first + CHUNK : counts[list];
    return list;
}

/* The times of impact of candidates [CHUNK item, ...) of both kinds (items of kind 0 first). */
static void narrow_item(void *user, uint32_t item, uint32_t worker)
{
    (void)worker;
    collide_ctx *c = user;
    size_t first, last;
    int kind = chunk_range(item, c->pair_count, &first, &last);
    for (size_t i = first; i < last; i++) {
        uint32_t idx[4];
        pair_vertices(c->m, kind, c->pairs[kind][2 * i], c->pairs[kind][2 * i + 1], idx);
        c->hit_time[kind][i] = pair_time(c, kind, idx, c->round);
    }
}

/* Every candidate tested this round (on the team), then the hits applied in list order: the
 * four vertices of a hit keep at most 0.8 of the time of impact (round 0) or nothing (later
 * rounds). Times and the smallest keep per vertex do not depend on the order, so neither does
 * the result. */
static void narrow_phase(collide_ctx *c, int round)
{
    c->round = round;
    mk_team_for(c->team, chunks_of(c->pair_count, 2), narrow_item, c);
    for (int kind = 0; kind < 2; kind++)
        for (size_t i = 0; i < c->pair_count[kind]; i++) {
            double t = c->hit_time[kind][i];
            if (t < 0) continue;
            if (kind == 0) c->vt++; else c->ee++;
            uint32_t idx[4];
            pair_vertices(c->m, kind, c->pairs[kind][2 * i], c->pairs[kind][2 * i + 1], idx);
            double keep = round == 0 ? 0.8 * t : 0;
            for (int k = 0; k < 4; k++)
                if (keep < c->scale[idx[k]]) c->scale[idx[k]] = keep;
        }
}

/* The vertices owned by slot u against slot s's triangle (the two share no vertex). */
static void owned_vertices_against(collide_ctx *c, uint32_t u, uint32_t s)
{
    const shell_collider *col = c->col;
    const double *tb = col->tri_boxes + 6 * (size_t)s;
    for (uint32_t i = col->vertex_start[u]; i < col->vertex_start[u + 1]; i++)
        if (boxes_overlap(col->vertex_boxes + 6 * (size_t)i, tb)) add_candidate(c, 0, col->slot_tri[s], col->owned_vertices[i]);
}

/* Two slots that share no vertex and whose boxes overlap (a slot with itself has no pair that
 * shares no vertex; neighbours' pairs are listed, near): every vertex-triangle and edge-edge
 * pair whose vertex or edges they own. Each candidate is met once: a vertex's box lies in its
 * owner's, an edge's in its owner's. */
static void visit_triangles(collide_ctx *c, uint32_t s, uint32_t u)
{
    const shell_collider *col = c->col;
    owned_vertices_against(c, u, s);
    owned_vertices_against(c, s, u);
    for (uint32_t i = col->edge_start[s]; i < col->edge_start[s + 1]; i++) {
        const double *eb = col->edge_boxes + 6 * (size_t)i;
        for (uint32_t j = col->edge_start[u]; j < col->edge_start[u + 1]; j++)
            if (boxes_overlap(eb, col->edge_boxes + 6 * (size_t)j)) add_candidate(c, 1, col->owned_edges[i], col->owned_edges[j]);
    }
}

/* Box tests of listed pairs on the team: overlap[kind][k] for pair k of lists[kind] (kind 0:
 * an owned vertex and a slot, kind 1: two owned edges; kind 2: two slots, lists[2] far pairs). */
typedef struct box_job {
    const shell_collider *col;
    const uint32_t *lists[3];
    size_t counts[3];
    unsigned char *overlap[3];
} box_job;

static void box_item(void *user, uint32_t item, uint32_t worker)
{
    (void)worker;
    box_job *j = user;
    size_t first, last;
    int kind = chunk_range(item, j->counts, &first, &last);
    const shell_collider *col = j->col;
    const double *boxes_a = kind == 0 ? col->vertex_boxes : kind == 1 ? col->edge_boxes : col->tri_boxes;
    const double *boxes_b = kind == 0 ? col->tri_boxes : kind == 1 ? col->edge_boxes : col->tri_boxes;
    const uint32_t *list = j->lists[kind];
    for (size_t k = first; k < last; k++)
        j->overlap[kind][k] = (unsigned char)boxes_overlap(boxes_a + 6 * (size_t)list[2 * k], boxes_b + 6 * (size_t)list[2 * k + 1]);
}

/* The overlap flags of the near lists (and the far list when far is nonzero), tested on the
 * team; 0 when out of memory. */
static int box_tests(collide_ctx *c, uint32_t *const lists[2], const size_t counts[2], int far, box_job *j)
{
    const shell_collider *col = c->col;
    memset(j, 0, sizeof *j);
    j->col = col;
    for (int kind = 0; kind < 3; kind++) {
        j->lists[kind] = kind < 2 ? lists[kind] : far ? col->far : NULL;
        j->counts[kind] = kind < 2 ? counts[kind] : far ? col->far_count : 0;
        j->overlap[kind] = mk_arena_array(c->arena, j->counts[kind] + 1, 1);
        if (!j->overlap[kind]) return 0;
    }
    mk_team_for(c->team, chunks_of(j->counts, 3), box_item, j);
    return 1;
}

/* Listed pairs of neighbouring triangles (near, or live) whose boxes overlap (flags from
 * box_tests), in list order: as candidates (c), or copied to out (then c is NULL). */
static void near_pairs(collide_ctx *c, const shell_collider *col, const box_job *j, uint32_t *out[2], size_t out_count[2])
{
    for (int kind = 0; kind < 2; kind++) {
        const uint32_t *list = j->lists[kind];
        for (size_t k = 0; k < j->counts[kind]; k++) {
            if (!j->overlap[kind][k]) continue;
            uint32_t i = list[2 * k], jj = list[2 * k + 1];
            if (!c) put_pair(out[kind], &out_count[kind], i, jj);
            else if (kind == 0) add_candidate(c, 0, col->slot_tri[jj], col->owned_vertices[i]);
            else add_candidate(c, 1, col->owned_edges[i], col->owned_edges[jj]);
        }
    }
}

/* Each vertex's range: its step x -> p continued FAR_STEPS steps ahead, grown by FAR_SLACK of
 * the step's largest coordinate and FAR_MARGIN of the mean edge length. */
#define FAR_STEPS 3
#define FAR_SLACK 0.5
#define FAR_MARGIN 0.15
/* A list that served fewer than FAR_MIN_STEPS steps costs more than it saves: the next
 * FAR_PAUSE steps traverse the hierarchy directly (this step's boxes), then a list is tried
 * again. */
#define FAR_MIN_STEPS 3
#define FAR_PAUSE 8

static void far_ranges(shell_collider *col, uint32_t n, const double *x, const double *p, double margin)
{
    for (uint32_t v = 0; v < n; v++) {
        const double *a = x + 3 * (size_t)v, *b = p + 3 * (size_t)v;
        double *r = col->far_range + 6 * (size_t)v, d[3], big = 0;
        vec3_sub(d, b, a);
        for (int k = 0; k < 3; k++)
            if (fabs(d[k]) > big) big = fabs(d[k]);
        double grow = FAR_SLACK * big + margin;
        for (int k = 0; k < 3; k++) {
            double ahead = b[k] + FAR_STEPS * d[k], lo = d[k] < 0 ? ahead : a[k], hi = d[k] < 0 ? a[k] : ahead;
            r[k] = lo - grow;
            r[3 + k] = hi + grow;
        }
    }
}

/* Does every vertex's step lie inside its range? */
static int far_ranges_hold(const shell_collider *col, uint32_t n, const double *x, const double *p)
{
    for (uint32_t v = 0; v < n; v++) {
        const double *r = col->far_range + 6 * (size_t)v, *a = x + 3 * (size_t)v, *b = p + 3 * (size_t)v;
        for (int k = 0; k < 3; k++)
            if (!(a[k] >= r[k] && a[k] <= r[3 + k] && b[k] >= r[k] && b[k] <= r[3 + k])) return 0;
    }
    return 1;
}

/* The box of the vertices idx[0..k)'s boxes (6 per vertex), inflated by pad. */
static void union_box(const double *vertex_box, const uint32_t *idx, int k, double pad, double box[6])
{
    for (int c = 0; c < 3; c++) { box[c] = INFINITY; box[3 + c] = -INFINITY; }
    for (int j = 0; j < k; j++) {
        const double *r = vertex_box + 6 * (size_t)idx[j];
        for (int c = 0; c < 3; c++) {
            if (r[c] < box[c]) box[c] = r[c];
            if (r[3 + c] > box[3 + c]) box[3 + c] = r[3 + c];
        }
    }
    for (int c = 0; c < 3; c++) { box[c] -= pad; box[3 + c] += pad; }
}

/* Every slot's, owned vertex's and owned edge's box from their vertices' boxes, inflated by pad:
 * CHUNK of them per item (slots, then vertices, then edges), on the team. */
typedef struct boxes_job {
    shell_collider *col;
    const double *vertex_box;
    double pad;
    size_t counts[3];         /* slots, vertices, edges */
} boxes_job;

static void boxes_item(void *user, uint32_t item, uint32_t worker)
{
    (void)worker;
    boxes_job *j = user;
    shell_collider *col = j->col;
    size_t first, last;
    int kind = chunk_range(item, j->counts, &first, &last);
    for (size_t i = first; i < last; i++) {
        if (kind == 0) union_box(j->vertex_box, col->slot_corners + 3 * (size_t)i, 3, j->pad, col->tri_boxes + 6 * (size_t)i);
        else if (kind == 1) union_box(j->vertex_box, col->owned_vertices + i, 1, j->pad, col->vertex_boxes + 6 * (size_t)i);
        else union_box(j->vertex_box, col->edge_ends + 2 * (size_t)i, 2, j->pad, col->edge_boxes + 6 * (size_t)i);
    }
}

static void all_boxes(mk_team *team, shell_collider *col, const shell_mesh *m, const double *vertex_box, double pad)
{
    boxes_job j = { col, vertex_box, pad, { m->tri_count, m->n, m->hinge_count } };
    mk_team_for(team, chunks_of(j.counts, 3), boxes_item, &j);
}

/* The hierarchy's self-traversal on the team: split into tasks (shell_bvh_self_split), each
 * task's overlapping slot pairs into its own list (grown under a lock: the arena is not shared
 * otherwise), then taken by `take` one task after the other, which is the order of the traversal
 * on one thread: the result does not depend on the thread count. */
#define TRAVERSAL_TASKS 64

typedef struct traversal_job {
    const shell_collider *col;
    uint32_t tasks[2 * TRAVERSAL_TASKS];
    uint32_t *pairs[TRAVERSAL_TASKS];
    size_t count[TRAVERSAL_TASKS];
    mk_arena *arena;
    mtx_t lock;
    int oom;                  /* set under the lock */
} traversal_job;

/* One task's list while it runs, on its thread's stack (the job's per-task arrays share cache
 * lines between tasks on different threads): written back when the task ends. */
typedef struct task_sink {
    traversal_job *job;
    uint32_t *pairs;
    size_t count, capacity;
    int oom;
} task_sink;

static void sink_pair(void *user, uint32_t a, uint32_t b)
{
    task_sink *s = user;
    if (s->count < s->capacity) {
        put_pair(s->pairs, &s->count, a, b);
        return;
    }
    if (s->oom) return;
    traversal_job *j = s->job;
    mtx_lock(&j->lock);
    if (!push_pair(j->arena, &s->pairs, &s->count, &s->capacity, a, b)) s->oom = j->oom = 1;
    mtx_unlock(&j->lock);
}

static void traverse_task(void *user, uint32_t task, uint32_t worker)
{
    (void)worker;
    traversal_job *j = user;
    task_sink sink = { j, NULL, 0, 0, 0 };
    shell_bvh_task_pairs(&j->col->tree, j->col->slot_corners, j->tasks[2 * task], j->tasks[2 * task + 1], sink_pair, &sink);
    j->pairs[task] = sink.pairs;
    j->count[task] = sink.count;
}

/* 0 when out of memory. */
static int traverse(collide_ctx *c, void (*take)(void *user, uint32_t a, uint32_t b), void *user)
{
    traversal_job *j = mk_arena_array(c->arena, 1, sizeof *j);
    if (!j) return 0;
    if (mtx_init(&j->lock, mtx_plain) != thrd_success) {
        mk_arena_release(c->arena, j);
        return 0;
    }
    j->col = c->col;
    j->arena = c->arena;
    uint32_t tasks = shell_bvh_self_split(&c->col->tree, TRAVERSAL_TASKS, j->tasks);
    /* Under an arena limit the growths' order must not depend on timing: one thread. */
    mk_team_for(mk_arena_threads(c->arena, 2) > 1 ? c->team : NULL, tasks, traverse_task, j);
    mtx_destroy(&j->lock);
    for (uint32_t t = 0; t < tasks && !j->oom; t++)
        for (size_t k = 0; k < j->count[t]; k++) take(user, j->pairs[t][2 * k], j->pairs[t][2 * k + 1]);
    for (uint32_t t = 0; t < tasks; t++) mk_arena_release(c->arena, j->pairs[t]);
    int ok = !j->oom;
    mk_arena_release(c->arena, j);
    return ok;
}

static void collect_far(void *user, uint32_t s, uint32_t u)
{
    shell_collider *col = user;
    if (!push_pair(col->arena, &col->far, &col->far_count, &col->far_capacity, s, u)) col->far_oom = 1;
}

/* The far pairs again: the slots' boxes from their corners' ranges (inflated by the thickness),
 * one traversal. A slot's box this step (from x, p inside the ranges, inflated by the same
 * thickness) lies inside, the rounding of the inflation being monotonic. 0 when out of memory. */
static int far_rebuild(collide_ctx *c, shell_collider *col, const double *x, const double *p, double thickness,
                       double margin)
{
    const shell_mesh *m = c->m;
    far_ranges(col, m->n, x, p, margin);
    all_boxes(c->team, col, m, col->far_range, thickness);
    col->live_count[0] = col->live_count[1] = 0;
    box_job j;
    if (!box_tests(c, col->near, col->near_count, 0, &j)) return 0;
    near_pairs(NULL, col, &j, col->live, col->live_count);
    shell_bvh_refit(&col->tree);
    col->far_count = 0;
    col->far_oom = 0;
    if (!traverse(c, collect_far, col)) col->far_oom = 1;
    col->far_valid = !col->far_oom;
    return col->far_valid;
}

static void visit_direct(void *user, uint32_t s, uint32_t u)
{
    visit_triangles(user, s, u);
}

/* The far pairs whose boxes overlap this step (flags from box_tests), in list order. */
static void far_pairs(collide_ctx *c, const box_job *j)
{
    const shell_collider *col = c->col;
    for (size_t k = 0; k < col->far_count; k++)
        if (j->overlap[2][k]) visit_triangles(c, col->far[2 * k], col->far[2 * k + 1]);
}

mk_result shell_collide(shell_collider *col, const shell_mesh *m, const double *x, double *p, double thickness,
                        mk_team *team, mk_arena *arena, uint32_t *vt, uint32_t *ee, uint32_t *rounds, mk_error *err)
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
    c.scale = scale; c.moved = moved; c.arena = &local; c.team = team;
    /* Broad phase, once: later rounds only pull vertices back along their steps, so their swept
     * boxes lie inside round 0's and round 0's candidates are all the pairs that can meet. */
    int direct = 0;
    if (col->direct_left > 0) {
        col->direct_left--;
        direct = 1;
    } else if (col->far_valid && far_ranges_hold(col, m->n, x, p)) {
        col->far_frames++;
    } else if (col->far_valid && col->far_frames < FAR_MIN_STEPS) {
        col->far_valid = 0;
        col->direct_left = FAR_PAUSE - 1;
        direct = 1;
    } else {
        if (!far_rebuild(&c, col, x, p, thickness, FAR_MARGIN * mean)) {
            mk_arena_free_all(&local);
            return mk_error_oom(err, "shell collisions (candidate pairs)");
        }
        col->far_frames = 1;
    }
    for (uint32_t v = 0; v < m->n; v++) swept_box(x, p, &v, 1, 0, col->step_box + 6 * (size_t)v, col->step_box + 6 * (size_t)v + 3);
    all_boxes(team, col, m, col->step_box, thickness);
    for (int round = 0; round < MAX_ROUNDS; round++) {
        for (uint32_t v = 0; v < m->n; v++) scale[v] = 1;
        uint32_t before = c.vt + c.ee;
        if (round == 0) {
            box_job j;
            if (!box_tests(&c, direct ? col->near : col->live, direct ? col->near_count : col->live_count, !direct, &j))
                c.oom = 1;
            else {
                near_pairs(&c, col, &j, NULL, NULL);
                if (direct) {
                    shell_bvh_refit(&col->tree);
                    if (!traverse(&c, visit_direct, &c)) c.oom = 1;
                } else {
                    far_pairs(&c, &j);
                }
            }
            for (int kind = 0; kind < 2 && !c.oom; kind++)
                if (!(c.hit_time[kind] = mk_arena_array(&local, c.pair_count[kind] + 1, sizeof(double)))) c.oom = 1;
            if (c.oom) { mk_arena_free_all(&local); return mk_error_oom(err, "shell collisions (candidate pairs)"); }
        }
        narrow_phase(&c, round);
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

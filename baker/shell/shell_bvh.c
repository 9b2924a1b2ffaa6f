/* SPDX-License-Identifier: MIT */
/* The shell's box hierarchy (shell_bvh.h): top-down median splits, iterative traversal. */
#include <math.h>
#include <string.h>
#include "shell_bvh.h"
#include "alloc.h"

#define LEAF_SIZE 4
#define STACK_SIZE 96

/* Key of an item along an axis: its box centre (times 2), ties broken by the index. */
static int key_less(const double *boxes, int axis, uint32_t a, uint32_t b)
{
    double ka = boxes[6 * (size_t)a + axis] + boxes[6 * (size_t)a + 3 + axis];
    double kb = boxes[6 * (size_t)b + axis] + boxes[6 * (size_t)b + 3 + axis];
    return ka < kb || (ka == kb && a < b);
}

/* Reorders items[0..n) so that items[k] is the k-th smallest by key, smaller ones before it and
 * larger ones after (quickselect, median-of-three pivot). */
static void select_kth(const double *boxes, int axis, uint32_t *items, uint32_t n, uint32_t k)
{
    uint32_t lo = 0, hi = n - 1;
    while (hi > lo) {
        uint32_t mid = lo + (hi - lo) / 2, t;
        /* Median of three into items[mid]. */
        if (key_less(boxes, axis, items[mid], items[lo])) { t = items[mid]; items[mid] = items[lo]; items[lo] = t; }
        if (key_less(boxes, axis, items[hi], items[lo])) { t = items[hi]; items[hi] = items[lo]; items[lo] = t; }
        if (key_less(boxes, axis, items[hi], items[mid])) { t = items[hi]; items[hi] = items[mid]; items[mid] = t; }
        uint32_t pivot = items[mid];
        uint32_t i = lo, j = hi;
        while (i <= j) {
            while (key_less(boxes, axis, items[i], pivot)) i++;
            while (key_less(boxes, axis, pivot, items[j])) j--;
            if (i <= j) {
                t = items[i]; items[i] = items[j]; items[j] = t;
                i++;
                if (j == 0) break;
                j--;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else return;
    }
}

typedef struct build_task { uint32_t node, start, count; } build_task;

int shell_bvh_build(shell_bvh *bvh, const double *boxes, uint32_t count, mk_arena *arena)
{
    bvh->boxes = boxes;
    bvh->node_count = 0;
    bvh->items = mk_arena_array(arena, (size_t)count + 1, sizeof(uint32_t));
    bvh->nodes = mk_arena_array(arena, 2 * (size_t)count + 1, sizeof(shell_bvh_node));
    if (!bvh->items || !bvh->nodes) return 0;
    if (count == 0) return 1;
    for (uint32_t i = 0; i < count; i++) bvh->items[i] = i;
    build_task stack[STACK_SIZE];
    int top = 0;
    bvh->node_count = 1;
    stack[top++] = (build_task){ 0, 0, count };
    while (top > 0) {
        uint32_t node = stack[top - 1].node, start = stack[top - 1].start, n = stack[top - 1].count;
        top--;
        shell_bvh_node *b = &bvh->nodes[node];
        double clo[3], chi[3];
        for (int c = 0; c < 3; c++) { b->lo[c] = clo[c] = INFINITY; b->hi[c] = chi[c] = -INFINITY; }
        for (uint32_t i = start; i < start + n; i++) {
            const double *box = boxes + 6 * (size_t)bvh->items[i];
            for (int c = 0; c < 3; c++) {
                double centre = box[c] + box[3 + c];
                if (box[c] < b->lo[c]) b->lo[c] = box[c];
                if (box[3 + c] > b->hi[c]) b->hi[c] = box[3 + c];
                if (centre < clo[c]) clo[c] = centre;
                if (centre > chi[c]) chi[c] = centre;
            }
        }
        if (n <= LEAF_SIZE || top + 2 > STACK_SIZE) {
            b->start = start;
            b->count = n;
            continue;
        }
        int axis = 0;
        for (int c = 1; c < 3; c++)
            if (chi[c] - clo[c] > chi[axis] - clo[axis]) axis = c;
        uint32_t half = n / 2;
        select_kth(boxes, axis, bvh->items + start, n, half);
        uint32_t left = bvh->node_count;
        bvh->node_count += 2;
        b->start = left;
        b->count = 0;
        stack[top++] = (build_task){ left + 1, start + half, n - half };
        stack[top++] = (build_task){ left, start, half };
    }
    return 1;
}

void shell_bvh_renumber(shell_bvh *bvh, uint32_t *order, uint32_t count)
{
    for (uint32_t i = 0; i < count; i++) {
        order[i] = bvh->items[i];
        bvh->items[i] = i;
    }
}


void shell_bvh_refit(shell_bvh *bvh)
{
    /* Children come after their parent: refit from the last node back. */
    for (uint32_t k = bvh->node_count; k-- > 0;) {
        shell_bvh_node *b = &bvh->nodes[k];
        for (int c = 0; c < 3; c++) { b->lo[c] = INFINITY; b->hi[c] = -INFINITY; }
        if (b->count) {
            for (uint32_t i = b->start; i < b->start + b->count; i++) {
                const double *box = bvh->boxes + 6 * (size_t)bvh->items[i];
                for (int c = 0; c < 3; c++) {
                    if (box[c] < b->lo[c]) b->lo[c] = box[c];
                    if (box[3 + c] > b->hi[c]) b->hi[c] = box[3 + c];
                }
            }
            continue;
        }
        for (uint32_t child = b->start; child < b->start + 2; child++)
            for (int c = 0; c < 3; c++) {
                if (bvh->nodes[child].lo[c] < b->lo[c]) b->lo[c] = bvh->nodes[child].lo[c];
                if (bvh->nodes[child].hi[c] > b->hi[c]) b->hi[c] = bvh->nodes[child].hi[c];
            }
    }
}

typedef struct pair_walk {
    const shell_bvh *bvh;
    const uint32_t *corners;
    void (*visit)(void *user, uint32_t a, uint32_t b);
    void *user;
} pair_walk;

static int share_a_corner(const uint32_t *a, const uint32_t *b)
{
    return (a[0] == b[0]) | (a[0] == b[1]) | (a[0] == b[2]) | (a[1] == b[0]) | (a[1] == b[1]) | (a[1] == b[2]) |
           (a[2] == b[0]) | (a[2] == b[1]) | (a[2] == b[2]);
}

/* The overlapping item pairs of two leaves (the same leaf: each unordered pair once, with
 * itself too), but for items that share a corner. */
static void leaf_pairs(const pair_walk *w, const shell_bvh_node *a, const shell_bvh_node *b)
{
    const shell_bvh *bvh = w->bvh;
    for (uint32_t i = a->start; i < a->start + a->count; i++) {
        uint32_t ia = bvh->items[i];
        const double *ba = bvh->boxes + 6 * (size_t)ia;
        for (uint32_t j = a == b ? i : b->start; j < b->start + b->count; j++) {
            uint32_t ib = bvh->items[j];
            const double *bb = bvh->boxes + 6 * (size_t)ib;
            if (w->corners && share_a_corner(w->corners + 3 * (size_t)ia, w->corners + 3 * (size_t)ib)) continue;
            if (shell_boxes_overlap(ba, ba + 3, bb, bb + 3)) w->visit(w->user, ia, ib);
        }
    }
}

static void node_pairs(const pair_walk *w, uint32_t na, uint32_t nb)
{
    const shell_bvh_node *a = &w->bvh->nodes[na], *b = &w->bvh->nodes[nb];
    if (na == nb) {
        if (a->count) { leaf_pairs(w, a, a); return; }
        node_pairs(w, a->start, a->start);
        node_pairs(w, a->start + 1, a->start + 1);
        node_pairs(w, a->start, a->start + 1);
        return;
    }
    if (!shell_boxes_overlap(a->lo, a->hi, b->lo, b->hi)) return;
    if (a->count && b->count) { leaf_pairs(w, a, b); return; }
    /* Descend into the inner node with the larger box (or the only inner one). */
    double va = 0, vb = 0;
    for (int c = 0; c < 3; c++) { va += a->hi[c] - a->lo[c]; vb += b->hi[c] - b->lo[c]; }
    if (b->count || (!a->count && va >= vb)) {
        node_pairs(w, a->start, nb);
        node_pairs(w, a->start + 1, nb);
    } else {
        node_pairs(w, na, b->start);
        node_pairs(w, na, b->start + 1);
    }
}

void shell_bvh_task_pairs(const shell_bvh *bvh, const uint32_t *corners, uint32_t a, uint32_t b,
                          void (*visit)(void *user, uint32_t a, uint32_t b), void *user)
{
    if (bvh->node_count == 0) return;
    pair_walk w = { bvh, corners, visit, user };
    node_pairs(&w, a, b);
}

void shell_bvh_self_pairs(const shell_bvh *bvh, const uint32_t *corners, void (*visit)(void *user, uint32_t a, uint32_t b),
                          void *user)
{
    shell_bvh_task_pairs(bvh, corners, 0, 0, visit, user);
}

/* Task (a, b)'s sub-tasks as node_pairs would recurse into them, in its order, at out (at most
 * 3); returns their number, 0 for a pair of boxes that do not overlap, or UINT32_MAX for a task
 * that does not split (a leaf with itself or two leaves). */
static uint32_t split_task(const shell_bvh *bvh, uint32_t na, uint32_t nb, uint32_t *out)
{
    const shell_bvh_node *a = &bvh->nodes[na], *b = &bvh->nodes[nb];
    if (na == nb) {
        if (a->count) return UINT32_MAX;
        const uint32_t l = a->start, r = a->start + 1, t[6] = { l, l, r, r, l, r };
        memcpy(out, t, sizeof t);
        return 3;
    }
    if (!shell_boxes_overlap(a->lo, a->hi, b->lo, b->hi)) return 0;
    if (a->count && b->count) return UINT32_MAX;
    double va = 0, vb = 0;
    for (int c = 0; c < 3; c++) { va += a->hi[c] - a->lo[c]; vb += b->hi[c] - b->lo[c]; }
    if (b->count || (!a->count && va >= vb)) {
        const uint32_t t[4] = { a->start, nb, a->start + 1, nb };
        memcpy(out, t, sizeof t);
    } else {
        const uint32_t t[4] = { na, b->start, na, b->start + 1 };
        memcpy(out, t, sizeof t);
    }
    return 2;
}

uint32_t shell_bvh_self_split(const shell_bvh *bvh, uint32_t max, uint32_t *tasks)
{
    if (bvh->node_count == 0 || max == 0) return 0;
    if (max > SHELL_BVH_TASKS_MAX) max = SHELL_BVH_TASKS_MAX;
    uint32_t next[2 * SHELL_BVH_TASKS_MAX], n = 1;
    tasks[0] = tasks[1] = 0;
    for (int split = 1; split;) {   /* one level per pass, while the tasks fit */
        split = 0;
        uint32_t m = 0;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t sub[6], k = m + 3 + (n - i - 1) <= max ? split_task(bvh, tasks[2 * i], tasks[2 * i + 1], sub) : UINT32_MAX;
            if (k == UINT32_MAX) {   /* kept as it is */
                next[2 * m] = tasks[2 * i];
                next[2 * m + 1] = tasks[2 * i + 1];
                m++;
                continue;
            }
            memcpy(next + 2 * m, sub, 2 * k * sizeof *sub);
            m += k;
            split = 1;
        }
        memcpy(tasks, next, 2 * (size_t)m * sizeof *tasks);
        n = m;
    }
    return n;
}

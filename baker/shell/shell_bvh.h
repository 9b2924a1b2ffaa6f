/* SPDX-License-Identifier: MIT */
/* A bounding volume hierarchy over axis-aligned boxes (the shell's collision broad phase,
 * shell_collide.c). Internal to baker/. */
#ifndef SHELL_BVH_H
#define SHELL_BVH_H

#include <stdint.h>
#include "alloc.h"

/* Closed boxes [alo, ahi] and [blo, bhi] overlap: all six comparisons without branches, one
 * branch on the result (mostly no, while which comparison fails first is hard to predict). */
static inline int shell_boxes_overlap(const double *alo, const double *ahi, const double *blo, const double *bhi)
{
    return (alo[0] <= bhi[0]) & (blo[0] <= ahi[0]) & (alo[1] <= bhi[1]) & (blo[1] <= ahi[1]) & (alo[2] <= bhi[2]) &
           (blo[2] <= ahi[2]);
}

typedef struct shell_bvh_node {
    double lo[3], hi[3];
    uint32_t start;           /* leaf: first entry of items; inner node: index of the left child (right = start + 1) */
    uint32_t count;           /* leaf: number of items (> 0); inner node: 0 */
} shell_bvh_node;

typedef struct shell_bvh {
    shell_bvh_node *nodes;
    uint32_t node_count;
    uint32_t *items;          /* item indices, grouped by leaf */
    const double *boxes;      /* 6 doubles per item (lo, hi), as given to shell_bvh_build */
} shell_bvh;

/* Builds the hierarchy over count boxes (6 doubles each: lo[3], hi[3]; kept by reference) by
 * median splits along the longest axis of the box centres, at most 4 items per leaf. The tree
 * depends only on the boxes (ties broken by item index). Memory from arena; 0 when out of memory. */
int shell_bvh_build(shell_bvh *bvh, const double *boxes, uint32_t count, mk_arena *arena);

/* Renumbers the items in the order of the leaves: order[i] (count entries) receives the item
 * now numbered i, and from then on the boxes array must hold item order[i]'s box at i. Items
 * of a leaf, and of nearby leaves, then lie next to each other in memory. */
void shell_bvh_renumber(shell_bvh *bvh, uint32_t *order, uint32_t count);

/* Recomputes every node's box after the items' boxes (the same array) changed; the tree's
 * shape stays (it is only as tight as the items stay near their neighbours at build time). */
void shell_bvh_refit(shell_bvh *bvh);

/* Calls visit(user, a, b) for every unordered pair of items whose boxes overlap (closed boxes),
 * each item with itself too, in a fixed order. With corners (3 per item, e.g. a triangle's
 * vertices) pairs of items that share one are left out, and so is each item with itself. */
void shell_bvh_self_pairs(const shell_bvh *bvh, const uint32_t *corners, void (*visit)(void *user, uint32_t a, uint32_t b),
                          void *user);

/* The same traversal in parts: shell_bvh_self_split writes up to max (at most
 * SHELL_BVH_TASKS_MAX) tasks, pairs of nodes (2 per task), and returns their number;
 * shell_bvh_task_pairs(a, b) visits a task's pairs. The tasks' visits, one task after the other
 * in their order, are exactly shell_bvh_self_pairs' visits in its order, so the tasks can run on
 * several threads and their pairs be taken in task order afterwards. */
#define SHELL_BVH_TASKS_MAX 256
uint32_t shell_bvh_self_split(const shell_bvh *bvh, uint32_t max, uint32_t *tasks);
void shell_bvh_task_pairs(const shell_bvh *bvh, const uint32_t *corners, uint32_t a, uint32_t b,
                          void (*visit)(void *user, uint32_t a, uint32_t b), void *user);

#endif

/* SPDX-License-Identifier: MIT */
/* Which vertices of a 64-vertex block a target's entry stores (the writer's mask rule). */
#ifndef MK_BLOCK_MASK_H
#define MK_BLOCK_MASK_H

#include <stdint.h>

/* The default largest gap the writer fills (mk_write_options.gap_limit = it + 1), and how
 * many times that many unfilled vertices a block may lack and still be stored whole. Measured
 * on a 165k-vertex Blender export (docs/performance.md, "Blob size"): evaluation time follows
 * the runs the runtime adds one by one far more than the zeros it adds, so the whole-block
 * threshold (here 24) decides the speed, and the gap size changes the blob by little. */
#define MK_DEFAULT_FILL_GAP 8u
#define MK_WHOLE_BLOCK_FACTOR 3u

/* The entry mask for the moved vertices `moved` (nonzero) of a block holding `in_block` (1 to
 * 64) vertices: every interior gap of at most `gap` unmoved vertices between two moved ones is
 * filled (stored as zero deltas, so the runtime adds one run where it would add two), and
 * when what is still unfilled (the head before the first moved vertex, the tail after the
 * last, the larger gaps) is at most MK_WHOLE_BLOCK_FACTOR x `gap` vertices, the whole block
 * is stored: a whole block of 64 is the runtime's constant-trip loop. gap 0 stores exactly
 * the moved vertices (a block is whole only when all its vertices move); gap >= 64 stores
 * every touched block whole. */
uint64_t mk_block_mask(uint64_t moved, uint32_t in_block, uint32_t gap);

#endif

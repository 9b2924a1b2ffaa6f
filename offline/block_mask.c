/* SPDX-License-Identifier: MIT */
#include "block_mask.h"
#include "format.h"

uint64_t mk_block_mask(uint64_t moved, uint32_t in_block, uint32_t gap)
{
    const uint64_t all = in_block >= MK_BLOCK_SIZE ? ~0ull : (1ull << in_block) - 1;
    if (!moved) return 0;
    uint64_t mask = moved;
    /* From run to run of moved bits; the clear run between two of them is an interior gap. */
    for (unsigned i = mk_ctz64(moved);;) {
        const uint64_t rest = moved >> i;              /* bit 0 set: vertex i moves */
        if (rest == ~0ull >> i) break;                 /* moved up to bit 63: no gap above */
        i += mk_ctz64(~rest);                          /* past the run (i < 64: a clear bit above) */
        if ((moved >> i) == 0) break;                  /* the tail: nothing moved above */
        const unsigned hole = mk_ctz64(moved >> i);
        if (hole <= gap) mask |= ((1ull << hole) - 1) << i;
        i += hole;
    }
    if (in_block - mk_popcount64(mask) <= MK_WHOLE_BLOCK_FACTOR * (uint64_t)gap) mask = all;
    return mask;
}

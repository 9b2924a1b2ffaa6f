/* SPDX-License-Identifier: MIT */
/* Pages of freed large blocks kept for the next large blocks (the offline allocator's, alloc.c).
 *
 * On the virtual machines the tools run on, the first touch of a fresh page costs a fault in
 * the guest and often one in the host: an import of a 47 MB FBX touched ~310 MB of fresh pages
 * (79k faults, half a second of system time) to peak at 130 MB, because its big transient
 * arrays were unmapped when freed and the next arrays were mapped anew. With recycling enabled,
 * blocks of MK_RECYCLE_MIN bytes or more are mappings of their own; a freed one is kept (up to a
 * cap, the rest unmapped) and the next large block reuses its pages: moved and resized with
 * mremap, split when larger than asked, always handed out zeroed. Zeroing touches only the
 * resident pages (mincore); the others are dropped (MADV_DONTNEED) and stay untouched, so a
 * reused block sized for the worst case but used in part costs no more than a fresh one.
 * Fresh mappings are prepared for their first use: from MK_RECYCLE_HUGE on they ask for
 * transparent huge pages (one fault per 2 MB for the 2 MB-aligned stretches inside them, where
 * the system gives them on request; the hint stays with their pages when they are kept and
 * reused, and the kernel may later merge such pages into huge ones), below it they are
 * prefaulted whole in one call (about half the cost of faulting their pages in one by one,
 * measured; such a block is then resident whole, used or not).
 *
 * Off until mk_recycle_enable: a process that keeps running after an import (an editor) may not
 * want up to `cap` bytes of freed memory held. Kept pages count as resident until reused, and a
 * reused page stays resident even where its new block leaves it unused, so recycling can raise
 * a process's peak memory by the cap and more; measure it (docs/performance.md has blob8's
 * figures). Linux only; elsewhere mk_recycle_enable does nothing and the other functions
 * return NULL.
 */
#ifndef MK_PAGE_RECYCLE_H
#define MK_PAGE_RECYCLE_H

#include <stddef.h>

/* Blocks from this size on are recycled (glibc maps blocks of 128 KiB and more by default too). */
#define MK_RECYCLE_MIN ((size_t)128 << 10)
/* Fresh mappings from this size on may use transparent huge pages (MADV_HUGEPAGE); smaller
 * fresh ones are prefaulted in one call (MADV_POPULATE_WRITE). */
#define MK_RECYCLE_HUGE ((size_t)2 << 20)

/* Turns recycling on with at most `cap` bytes kept (0: off). Call once, before other threads
 * allocate through an arena; later calls are ignored. Returns whether recycling is on. */
int mk_recycle_enable(size_t cap);
int mk_recycle_enabled(void);

/* A zeroed, page-aligned mapping of at least `bytes` (its length in *mapped), from kept pages
 * where there are some; NULL when refused. */
void *mk_recycle_take(size_t bytes, size_t *mapped);
/* Gives a mapping from mk_recycle_take or mk_recycle_grow back: kept up to the cap, the rest
 * unmapped. */
void mk_recycle_give(void *p, size_t mapped);
/* Grows a mapping to at least `bytes`, keeping its contents and pages (mremap; the new tail is
 * zero); *mapped is updated. NULL (and the mapping unchanged) when refused. */
void *mk_recycle_grow(void *p, size_t *mapped, size_t bytes);

/* For tests: bytes kept now. */
size_t mk_recycle_kept(void);

#endif

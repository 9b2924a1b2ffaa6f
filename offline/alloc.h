/* SPDX-License-Identifier: MIT */
/* Offline allocation for morphkit (importer, baker, tools). The runtime never allocates.
 *
 * mk_allocator is the user hook (zero-initialized means libc malloc/free, no limit).
 * mk_arena hands out blocks from that allocator and frees them all at once; the raw model,
 * parsers and writers allocate through one, so nothing leaks on any error path and a test can
 * fail allocation K for every K (tests/offline/test_alloc_fail.c).
 */
#ifndef MK_ALLOC_H
#define MK_ALLOC_H

#include <stddef.h>
#include <stdint.h>
#include <threads.h>
#include "morphkit.h"

typedef struct mk_allocator {
    void *(*alloc)(void *user, size_t size); /* NULL: malloc */
    void (*free)(void *user, void *ptr);     /* NULL: free */
    void *user;
    size_t memory_limit;                     /* bytes live at once through one arena; 0: no limit */
    uint64_t fail_after;                     /* testing: fail the (fail_after)-th call; 0: never */
} mk_allocator;

typedef struct mk_arena_block mk_arena_block;

typedef struct mk_arena {
    mk_allocator allocator;
    mk_arena_block *blocks;    /* every allocation, newest first */
    size_t bytes_live;
    size_t bytes_peak;
    uint64_t calls;
    int failed;                /* set once an allocation was refused */
} mk_arena;

/* allocator may be NULL (defaults). */
void mk_arena_init(mk_arena *arena, const mk_allocator *allocator);
/* Zeroed memory, 16-byte aligned; NULL (and arena->failed set) when refused or size overflows.
 * size 0 returns a valid unique pointer. */
/* Threads a parallel step whose workers allocate through arenas made from this arena's
 * allocator may use: `threads`, or 1 where the allocator has a memory limit or a fault-injection
 * count. Those are counted per arena, so per worker they would let the workers together go past
 * the limit and make where an import fails depend on the thread count. */
uint32_t mk_arena_threads(const mk_arena *arena, uint32_t threads);
void *mk_arena_alloc(mk_arena *arena, size_t size);
/* count * size with overflow check. */
void *mk_arena_array(mk_arena *arena, size_t count, size_t size);
/* Grows an array allocated from this arena: returns new zeroed-tail copy (old is released).
 * ptr may be NULL (then a new block, as mk_arena_alloc). */
void *mk_arena_realloc(mk_arena *arena, void *ptr, size_t old_size, size_t new_size);
/* Grows a block of this arena to new_size bytes (never shrinks it: a smaller size returns ptr);
 * the bytes past its old size are zeroed. With the default allocator the block is moved by
 * realloc, which keeps a large block's pages (mremap) instead of copying them into fresh ones;
 * otherwise as mk_arena_realloc. NULL (and ptr left as it was) when refused. */
void *mk_arena_grow(mk_arena *arena, void *ptr, size_t new_size);
/* ptr may be NULL (nothing is released). */
void mk_arena_release(mk_arena *arena, void *ptr);
/* Releases ptrs[0 .. n) (NULLs skipped) while holding `lock`: for workers giving arrays back to
 * an arena they share. */
void mk_arena_release_locked(mk_arena *arena, mtx_t *lock, void *const *ptrs, size_t n);
char *mk_arena_strdup(mk_arena *arena, const char *s);
char *mk_arena_strndup(mk_arena *arena, const char *s, size_t n);
void mk_arena_free_all(mk_arena *arena);
/* Moves every block of `from` into `into` (both on the same allocator); `from` is left empty.
 * Lets worker threads allocate from arenas of their own and hand the results over. */
void mk_arena_adopt(mk_arena *into, mk_arena *from);

/* Fills err with code, offset (UINT64_MAX when none) and a printf-style message; returns code.
 * err may be NULL. */
mk_result mk_error_set(mk_error *err, mk_result code, uint64_t offset, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
mk_result mk_error_oom(mk_error *err, const char *what);

#endif

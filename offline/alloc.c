/* SPDX-License-Identifier: MIT */
/* mk_arena: every allocation is its own block from the user allocator, linked into a list so
 * mk_arena_free_all releases everything (no leak on any error path) and single blocks can
 * still be released or grown. A live-bytes limit and a fail-after-K hook make allocation
 * failure testable. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "page_recycle.h"

struct mk_arena_block {
    mk_arena_block *prev, *next;
    size_t size;
    size_t mapped;              /* bytes of the block's own mapping when recycled (page_recycle.h),
                                 * else 0; also keeps the payload 16-byte aligned */
};

void mk_arena_init(mk_arena *arena, const mk_allocator *allocator)
{
    memset(arena, 0, sizeof *arena);
    if (allocator) arena->allocator = *allocator;
}

/* Zeroed memory for a block of `size` bytes (header included). The default allocator uses
 * calloc: large blocks then come from fresh pages the kernel has zeroed, instead of being
 * written twice (a memset here and the real data after it), which profiled as a tenth of an
 * import; or, where page recycling is on, the kept pages of freed large blocks. */
static mk_arena_block *raw_alloc(mk_arena *arena, size_t size)
{
    arena->calls++;
    if (arena->allocator.fail_after && arena->calls >= arena->allocator.fail_after) return NULL;
    if (arena->allocator.alloc) {
        mk_arena_block *b = arena->allocator.alloc(arena->allocator.user, size);
        if (b) memset(b, 0, size);
        return b;
    }
    if (size >= MK_RECYCLE_MIN && mk_recycle_enabled()) {
        size_t mapped;
        mk_arena_block *b = mk_recycle_take(size, &mapped);
        if (b) b->mapped = mapped;
        return b;
    }
    return calloc(1, size);
}

static void raw_free(mk_arena *arena, mk_arena_block *b)
{
    if (b->mapped) mk_recycle_give(b, b->mapped);
    else if (arena->allocator.free) arena->allocator.free(arena->allocator.user, b);
    else free(b);
}

/* Whether `more` bytes would take the arena past its limit. An arena that adopted another's
 * blocks (mk_arena_adopt) may already be past it: then every further byte is refused. */
static int over_limit(const mk_arena *arena, size_t more)
{
    const size_t limit = arena->allocator.memory_limit;
    return limit && (arena->bytes_live > limit || more > limit - arena->bytes_live);
}

uint32_t mk_arena_threads(const mk_arena *arena, uint32_t threads)
{
    return arena->allocator.memory_limit || arena->allocator.fail_after ? 1u : threads;
}

void *mk_arena_alloc(mk_arena *arena, size_t size)
{
    if (size > SIZE_MAX - sizeof(mk_arena_block) - 16) { arena->failed = 1; return NULL; }
    if (over_limit(arena, size)) {
        arena->failed = 1;
        return NULL;
    }
    mk_arena_block *b = raw_alloc(arena, sizeof(mk_arena_block) + size);
    if (!b) { arena->failed = 1; return NULL; }
    b->prev = NULL;
    b->next = arena->blocks;
    b->size = size;
    if (arena->blocks) arena->blocks->prev = b;
    arena->blocks = b;
    arena->bytes_live += size;
    if (arena->bytes_live > arena->bytes_peak) arena->bytes_peak = arena->bytes_live;
    return b + 1;
}

void *mk_arena_array(mk_arena *arena, size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size) { arena->failed = 1; return NULL; }
    return mk_arena_alloc(arena, count * size);
}

void mk_arena_release(mk_arena *arena, void *ptr)
{
    if (!ptr) return;
    mk_arena_block *b = (mk_arena_block *)ptr - 1;
    if (b->prev) b->prev->next = b->next; else arena->blocks = b->next;
    if (b->next) b->next->prev = b->prev;
    arena->bytes_live -= b->size;
    raw_free(arena, b);
}

void mk_arena_release_locked(mk_arena *arena, mtx_t *lock, void *const *ptrs, size_t n)
{
    mtx_lock(lock);
    for (size_t i = 0; i < n; i++) mk_arena_release(arena, ptrs[i]);
    mtx_unlock(lock);
}

void *mk_arena_realloc(mk_arena *arena, void *ptr, size_t old_size, size_t new_size)
{
    void *p = mk_arena_alloc(arena, new_size);
    if (!p) return NULL;
    if (ptr) {
        memcpy(p, ptr, old_size < new_size ? old_size : new_size);
        mk_arena_release(arena, ptr);
    }
    return p;
}

void *mk_arena_grow(mk_arena *arena, void *ptr, size_t new_size)
{
    mk_arena_block *b = (mk_arena_block *)ptr - 1;
    size_t old_size = b->size;
    if (new_size <= old_size) return ptr;
    if (arena->allocator.alloc || arena->allocator.free) return mk_arena_realloc(arena, ptr, old_size, new_size);
    if (new_size > SIZE_MAX - sizeof(mk_arena_block) - 16 || over_limit(arena, new_size - old_size)) {
        arena->failed = 1;
        return NULL;
    }
    arena->calls++;
    if (arena->allocator.fail_after && arena->calls >= arena->allocator.fail_after) { arena->failed = 1; return NULL; }
    mk_arena_block *prev = b->prev, *next = b->next;
    mk_arena_block *g;
    if (b->mapped) {
        size_t mapped = b->mapped;
        g = mk_recycle_grow(b, &mapped, sizeof(mk_arena_block) + new_size);
        if (g) g->mapped = mapped;
    } else {
        g = realloc(b, sizeof(mk_arena_block) + new_size);
    }
    if (!g) { arena->failed = 1; return NULL; }
    if (prev) prev->next = g; else arena->blocks = g;
    if (next) next->prev = g;
    g->size = new_size;
    arena->bytes_live += new_size - old_size;
    if (arena->bytes_live > arena->bytes_peak) arena->bytes_peak = arena->bytes_live;
    /* A recycled block is zero past old_size already: its pages were zeroed when it was handed
     * out and only [0, size) is written, and mremap's new tail is fresh. */
    if (!g->mapped) memset((char *)(g + 1) + old_size, 0, new_size - old_size);
    return g + 1;
}

char *mk_arena_strndup(mk_arena *arena, const char *s, size_t n)
{
    char *p = mk_arena_alloc(arena, n + 1);
    if (p && n) memcpy(p, s, n);
    return p;
}

char *mk_arena_strdup(mk_arena *arena, const char *s)
{
    return mk_arena_strndup(arena, s ? s : "", s ? strlen(s) : 0);
}

void mk_arena_free_all(mk_arena *arena)
{
    mk_arena_block *b = arena->blocks;
    while (b) {
        mk_arena_block *next = b->next;
        raw_free(arena, b);
        b = next;
    }
    arena->blocks = NULL;
    arena->bytes_live = 0;
}

void mk_arena_adopt(mk_arena *into, mk_arena *from)
{
    mk_arena_block *b = from->blocks;
    if (b) {
        mk_arena_block *last = b;
        while (last->next) last = last->next;
        last->next = into->blocks;
        if (into->blocks) into->blocks->prev = last;
        into->blocks = b;
    }
    into->bytes_live += from->bytes_live;
    if (into->bytes_live > into->bytes_peak) into->bytes_peak = into->bytes_live;
    into->calls += from->calls;
    into->failed |= from->failed;
    from->blocks = NULL;
    from->bytes_live = 0;
}

mk_result mk_error_set(mk_error *err, mk_result code, uint64_t offset, const char *fmt, ...)
{
    if (!err) return code;
    err->code = code;
    err->offset = offset;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return code;
}

mk_result mk_error_oom(mk_error *err, const char *what)
{
    return mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "out of memory while %s", what);
}

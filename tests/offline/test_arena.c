/* SPDX-License-Identifier: MIT */
/* mk_arena_grow: a grown block keeps its bytes, its new tail is zero, it stays in the arena's
 * list wherever it sits (first, middle, last; mk_arena_free_all frees it, the sanitizer build
 * checks nothing leaks), live bytes follow, a smaller size changes nothing, and a refused
 * growth (fail_after, memory_limit, a user allocator's fallback) leaves the block as it was. */
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "check.h"

static void *counted_alloc(void *user, size_t size) { (*(int *)user)++; return malloc(size); }
static void counted_free(void *user, void *ptr) { (*(int *)user)--; free(ptr); }

static void fill(unsigned char *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i++) p[i] = (unsigned char)(seed + i * 7u);
}

static int intact(const unsigned char *p, size_t n, unsigned seed, size_t grown)
{
    for (size_t i = 0; i < n; i++)
        if (p[i] != (unsigned char)(seed + i * 7u)) return 0;
    for (size_t i = n; i < grown; i++)
        if (p[i] != 0) return 0;
    return 1;
}

static void grow_each_position(const mk_allocator *allocator)
{
    for (int which = 0; which < 3; which++) {  /* the newest block, a middle one, the oldest */
        mk_arena arena;
        mk_arena_init(&arena, allocator);
        unsigned char *b[3];
        const size_t small = 100, big = (size_t)3 << 20;  /* past the mmap threshold: moved by mremap */
        for (int k = 0; k < 3; k++) {
            b[k] = mk_arena_alloc(&arena, small);
            CHECK(b[k] != NULL);
            if (b[k]) fill(b[k], small, (unsigned)k);
        }
        size_t live = arena.bytes_live;
        int at = 2 - which;
        unsigned char *g = mk_arena_grow(&arena, b[at], big);
        CHECK(g != NULL);
        if (g) {
            CHECK(intact(g, small, (unsigned)at, big));
            b[at] = g;
            CHECK_EQ_INT(arena.bytes_live, live + big - small);
            unsigned char *again = mk_arena_grow(&arena, g, big + small);
            CHECK(again != NULL && intact(again, small, (unsigned)at, big + small));
            if (again) b[at] = again;
            CHECK(mk_arena_grow(&arena, b[at], 10) == b[at]);  /* never shrinks */
        }
        for (int k = 0; k < 3; k++) CHECK(k == at || intact(b[k], small, (unsigned)k, small));
        /* The list still links every block: release the grown block's neighbours (older and
         * newer), then everything. */
        if (at > 0) mk_arena_release(&arena, b[at - 1]);
        if (at < 2) mk_arena_release(&arena, b[at + 1]);
        mk_arena_free_all(&arena);
        CHECK_EQ_INT(arena.bytes_live, 0);
    }
}

static void test_grow_default_allocator(void) { grow_each_position(NULL); }

static void test_grow_user_allocator(void)
{
    int outstanding = 0;
    mk_allocator a;
    memset(&a, 0, sizeof a);
    a.alloc = counted_alloc;
    a.free = counted_free;
    a.user = &outstanding;
    grow_each_position(&a);
    CHECK_EQ_INT(outstanding, 0);
}

static void test_refused_growth_keeps_the_block(void)
{
    for (int how = 0; how < 2; how++) {
        mk_allocator a;
        memset(&a, 0, sizeof a);
        if (how == 0) a.fail_after = 2;         /* the grow is the second call */
        else a.memory_limit = 1000;
        mk_arena arena;
        mk_arena_init(&arena, &a);
        unsigned char *p = mk_arena_alloc(&arena, 100);
        CHECK(p != NULL);
        if (!p) continue;
        fill(p, 100, 9);
        CHECK(mk_arena_grow(&arena, p, 5000) == NULL);
        CHECK(arena.failed);
        CHECK(intact(p, 100, 9, 100));
        CHECK_EQ_INT(arena.bytes_live, 100);
        mk_arena_free_all(&arena);
    }
}

/* An arena that adopted a worker arena's blocks can be past its limit (each arena counts its
 * own): then it refuses everything, instead of the limit check wrapping around. A limited
 * arena also keeps parallel steps on one thread, so where an import runs out does not depend
 * on the thread count. */
static void test_adopted_past_the_limit_refuses(void)
{
    mk_allocator a;
    memset(&a, 0, sizeof a);
    a.memory_limit = 100;
    mk_arena into, from;
    mk_arena_init(&into, &a);
    mk_arena_init(&from, &a);
    unsigned char *p = mk_arena_alloc(&into, 80), *q = mk_arena_alloc(&from, 80);
    CHECK(p != NULL && q != NULL);
    mk_arena_adopt(&into, &from);
    CHECK_EQ_INT(into.bytes_live, 160);
    CHECK(mk_arena_alloc(&into, 1) == NULL);
    CHECK(mk_arena_alloc(&into, (size_t)1 << 20) == NULL);
    if (p) CHECK(mk_arena_grow(&into, p, (size_t)2 << 20) == NULL);
    CHECK(into.failed);
    CHECK_EQ_INT(mk_arena_threads(&into, 8), 1);
    a.memory_limit = 0;
    mk_arena free_arena;
    mk_arena_init(&free_arena, &a);
    CHECK_EQ_INT(mk_arena_threads(&free_arena, 8), 8);
    mk_arena_free_all(&into);
}

CHECK_MAIN(CASE(test_grow_default_allocator), CASE(test_grow_user_allocator), CASE(test_refused_growth_keeps_the_block),
           CASE(test_adopted_past_the_limit_refuses))

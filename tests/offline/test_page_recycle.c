/* SPDX-License-Identifier: MIT */
/* Page recycling (offline/page_recycle.h) through the arena: off until enabled; a freed large
 * block's pages serve the next large block (the same addresses), which is always zeroed, also
 * where its previous owner left pages untouched (those stay untouched: not resident after the
 * zeroing); the cap bounds what is kept; kept ranges smaller than a request are grown into it;
 * grown blocks keep their bytes and get a zero tail; fresh blocks are prepared for their first
 * use (small ones resident at once, large ones asking for huge pages); threads taking and giving
 * at once always get zeroed blocks. The cases run in order: the first sees recycling off. */
#define _DEFAULT_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <threads.h>
#include <unistd.h>
#include "alloc.h"
#include "check.h"
#include "page_recycle.h"

#define MB ((size_t)1 << 20)
#define CAP (16 * MB)

static int all_zero(const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i]) return 0;
    return 1;
}

/* Whole pages inside [p, p + n): the first one's address in *lo, their count returned. */
static size_t whole_pages(const void *p, size_t n, uintptr_t *lo)
{
    const size_t page = (size_t)sysconf(_SC_PAGESIZE);
    uintptr_t first = ((uintptr_t)p + page - 1) / page * page, hi = ((uintptr_t)p + n) / page * page;
    if (lo) *lo = first;
    return hi > first ? (hi - first) / page : 0;
}

/* Resident pages among the whole pages inside [p, p + n). */
static size_t resident_pages(const void *p, size_t n)
{
    const size_t page = (size_t)sysconf(_SC_PAGESIZE);
    uintptr_t lo;
    size_t pages = whole_pages(p, n, &lo), count = 0;
    if (!pages) return 0;
    const uintptr_t hi = lo + pages * page;
    unsigned char *vec = malloc(pages);
    if (!vec) return SIZE_MAX;
    if (mincore((void *)lo, hi - lo, vec) != 0) { free(vec); return SIZE_MAX; }
    for (size_t i = 0; i < pages; i++) count += vec[i] & 1;
    free(vec);
    return count;
}

/* Whether the kernel takes the madvise advice (MADV_POPULATE_WRITE: Linux 5.14 on;
 * MADV_HUGEPAGE: kernels built with transparent huge pages), tried on a mapping of its own. */
static int advice_supported(int advice)
{
    const size_t len = MK_RECYCLE_HUGE;
    void *q = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (q == MAP_FAILED) return 0;
    int ok = madvise(q, len, advice) == 0;
    munmap(q, len);
    return ok;
}

/* Whether the mapping holding p has the VmFlags token `flag` in /proc/self/smaps (-1: unknown). */
static int mapping_has_flag(const void *p, const char *flag)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f) return -1;
    char line[512];
    int inside = 0, found = -1;
    while (found < 0 && fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        const char *dash = strchr(line, '-'), *space = strchr(line, ' ');
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && dash && space && dash < space)
            inside = (uintptr_t)p >= lo && (uintptr_t)p < hi;
        else if (inside && strncmp(line, "VmFlags:", 8) == 0) {
            char token[8];
            snprintf(token, sizeof token, " %s", flag);
            found = 0;
            for (char *t = strstr(line, token); t && !found; t = strstr(t + 1, token))
                found = t[strlen(token)] == ' ' || t[strlen(token)] == '\n';
        }
    }
    fclose(f);
    return found;
}

/* Takes every kept page into blocks of `arena`. */
static void drain(mk_arena *arena)
{
    for (int i = 0; i < 10000 && mk_recycle_kept(); i++) CHECK(mk_arena_alloc(arena, MK_RECYCLE_MIN) != NULL);
    CHECK_EQ_INT(mk_recycle_kept(), 0);
}

static void test_off_until_enabled(void)
{
    CHECK(!mk_recycle_enabled());
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    unsigned char *p = mk_arena_alloc(&arena, 2 * MB);
    CHECK(p != NULL);
    if (p) memset(p, 0xAB, 2 * MB);
    mk_arena_release(&arena, p);
    CHECK_EQ_INT(mk_recycle_kept(), 0);
    CHECK(mk_recycle_enable(0) == 0);   /* a zero cap leaves it off */
    CHECK(!mk_recycle_enabled());
}

static void test_freed_pages_are_reused_zeroed(void)
{
    CHECK(mk_recycle_enable(CAP));
    CHECK(mk_recycle_enabled());
    CHECK(mk_recycle_enable(2 * CAP));   /* later calls change nothing */
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    unsigned char *p = mk_arena_alloc(&arena, 3 * MB);
    CHECK(p != NULL);
    if (!p) return;
    CHECK(all_zero(p, 3 * MB));
    memset(p, 0xCD, 3 * MB);
    mk_arena_release(&arena, p);
    CHECK(mk_recycle_kept() >= 3 * MB);
    size_t kept = mk_recycle_kept();
    /* A smaller block is split off the front of the kept range: the same pages, zeroed. */
    unsigned char *q = mk_arena_alloc(&arena, MB);
    CHECK(q == p);
    CHECK(q && all_zero(q, MB));
    CHECK(mk_recycle_kept() < kept);
    /* Below the threshold blocks come from malloc and leave the kept pages alone. */
    kept = mk_recycle_kept();
    unsigned char *s = mk_arena_alloc(&arena, MK_RECYCLE_MIN / 2);
    CHECK(s && all_zero(s, MK_RECYCLE_MIN / 2));
    CHECK_EQ_INT(mk_recycle_kept(), kept);
    mk_arena_free_all(&arena);
    CHECK_EQ_INT(arena.bytes_live, 0);
}

/* A block used only in its first half: reused, it reads zero throughout, and its second half's
 * pages are still not resident (zeroing did not touch them). */
static void test_untouched_pages_stay_untouched(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    drain(&arena);   /* what earlier cases kept: the block below is a fresh mapping */
    unsigned char *p = mk_arena_alloc(&arena, 4 * MB);
    CHECK(p != NULL);
    if (!p) { mk_arena_free_all(&arena); return; }
    /* Where transparent huge pages are always on, the memset below would fault in a whole
     * 2 MB page reaching past the first half. */
    const uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE);
    madvise((void *)((uintptr_t)p / page * page), 4 * MB + page, MADV_NOHUGEPAGE);
    memset(p, 0x5A, 2 * MB);
    /* Before any recycling this is the kernel's doing, not ours: twice in many hundred runs,
     * both on a loaded machine, some of the second half was resident here already (the fresh
     * mapping asked for huge pages first). Then what follows cannot be observed. */
    const size_t before = resident_pages(p + 2 * MB + 4096, 2 * MB - 8192);
    if (before != 0) {
        mk_arena_release(&arena, p);
        mk_arena_free_all(&arena);
        SKIP("%zu pages of the untouched half were resident before any reuse", before);
    }
    mk_arena_release(&arena, p);
    unsigned char *q = mk_arena_alloc(&arena, 4 * MB);
    CHECK(q == p);
    if (q) {
        CHECK(resident_pages(q + 2 * MB + 4096, 2 * MB - 8192) == 0);
        CHECK(all_zero(q, 4 * MB));
    }
    mk_arena_release(&arena, q);
    mk_arena_free_all(&arena);
}

/* A fresh block is prepared for its first use: below MK_RECYCLE_HUGE it is resident whole at
 * once (prefaulted in one call, where the kernel can), from it on its mapping asks for
 * transparent huge pages (the "hg" flag); either way it reads zero. */
static void test_fresh_blocks_prepared(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    drain(&arena);   /* nothing kept: both blocks are fresh mappings */
    unsigned char *small = mk_arena_alloc(&arena, MK_RECYCLE_HUGE / 2);
    unsigned char *big = mk_arena_alloc(&arena, 2 * MK_RECYCLE_HUGE);
    CHECK(small != NULL && big != NULL);
    if (!small || !big) { mk_arena_free_all(&arena); return; }
#ifdef MADV_POPULATE_WRITE
    if (advice_supported(MADV_POPULATE_WRITE))
        CHECK_EQ_INT(resident_pages(small, MK_RECYCLE_HUGE / 2), whole_pages(small, MK_RECYCLE_HUGE / 2, NULL));
    else
#endif
        fprintf(stderr, "note: this kernel cannot prefault on request; residency not checked\n");
    CHECK(all_zero(small, MK_RECYCLE_HUGE / 2));
    const int small_hg = mapping_has_flag(small, "hg"), big_hg = mapping_has_flag(big, "hg");
#ifdef MADV_HUGEPAGE
    if (big_hg >= 0 && advice_supported(MADV_HUGEPAGE)) {
        CHECK_EQ_INT(big_hg, 1);
        CHECK_EQ_INT(small_hg, 0);
    } else
#endif
        fprintf(stderr, "note: no huge pages on request here (or no VmFlags in smaps); not checked\n");
    CHECK(all_zero(big, 2 * MK_RECYCLE_HUGE));
    mk_arena_free_all(&arena);
}

/* What is given back beyond the cap is unmapped; a request larger than every kept range grows
 * the largest one (its pages reused, the tail fresh), zeroed. */
static void test_cap_and_growth(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    drain(&arena);
    unsigned char *big = mk_arena_alloc(&arena, 3 * CAP);
    CHECK(big != NULL);
    CHECK_EQ_INT(mk_recycle_kept(), 0);
    if (big) memset(big, 0x77, 3 * CAP);
    mk_arena_release(&arena, big);
    CHECK_EQ_INT(mk_recycle_kept(), CAP);
    unsigned char *p = mk_arena_alloc(&arena, 2 * CAP);
    CHECK(p != NULL);
    CHECK_EQ_INT(mk_recycle_kept(), 0);
    if (p) CHECK(all_zero(p, 2 * CAP));
    mk_arena_free_all(&arena);
}

/* mk_arena_grow of a recycled block keeps its bytes and zeroes the tail, in place or moved. */
static void test_grow_recycled_block(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    unsigned char *p = mk_arena_alloc(&arena, MB + 100);
    CHECK(p != NULL);
    if (!p) return;
    for (size_t i = 0; i < MB + 100; i++) p[i] = (unsigned char)(i * 13u + 1u);
    unsigned char *g = mk_arena_grow(&arena, p, MB + 200);   /* within its pages */
    CHECK(g == p);
    g = mk_arena_grow(&arena, g, 5 * MB);
    CHECK(g != NULL);
    if (g) {
        int same = 1;
        for (size_t i = 0; i < MB + 100; i++) same &= g[i] == (unsigned char)(i * 13u + 1u);
        CHECK(same);
        CHECK(all_zero(g + MB + 100, 4 * MB - 100));
        CHECK_EQ_INT(arena.bytes_live, 5 * MB);
    }
    mk_arena_free_all(&arena);
}

/* A split that would leave less than a recycled block's minimum hands the whole range out. */
static void test_no_unusable_remainders(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    drain(&arena);
    void *a = mk_arena_alloc(&arena, MB);
    CHECK(a != NULL);
    mk_arena_release(&arena, a);
    const size_t kept = mk_recycle_kept();
    CHECK(kept >= MB);
    void *b = mk_arena_alloc(&arena, kept - MK_RECYCLE_MIN / 2);
    CHECK(b == a);
    CHECK_EQ_INT(mk_recycle_kept(), 0);
    mk_arena_free_all(&arena);
}

/* With every slot taken, a larger range given back replaces the smallest kept one. */
static void test_full_table_keeps_the_larger(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    drain(&arena);
    void *small[64];
    for (int i = 0; i < 64; i++) small[i] = mk_arena_alloc(&arena, MK_RECYCLE_MIN);
    void *big = mk_arena_alloc(&arena, 2 * MB);
    CHECK(big != NULL);
    for (int i = 0; i < 64; i++) mk_arena_release(&arena, small[i]);
    const size_t kept = mk_recycle_kept(), one = kept / 64;
    CHECK(kept == 64 * one && one >= MK_RECYCLE_MIN);
    mk_arena_release(&arena, big);
    CHECK(mk_recycle_kept() >= kept - one + 2 * MB);
    mk_arena_free_all(&arena);
}

static int churn(void *arg)
{
    unsigned seed = (unsigned)(uintptr_t)arg;
    int bad = 0;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    for (int round = 0; round < 200; round++) {
        seed = seed * 1103515245u + 12345u;
        size_t n = MK_RECYCLE_MIN + (seed >> 8) % (3 * MB);
        unsigned char *p = mk_arena_alloc(&arena, n);
        if (!p) { bad++; continue; }
        bad += !all_zero(p, n);
        memset(p, (int)(seed & 0xFF) | 1, n);
        mk_arena_release(&arena, p);
    }
    mk_arena_free_all(&arena);
    return bad;
}

static void test_threads_get_zeroed_blocks(void)
{
    thrd_t t[4];
    int started[4];
    for (int i = 0; i < 4; i++) started[i] = thrd_create(&t[i], churn, (void *)(uintptr_t)(i + 1)) == thrd_success;
    int bad = 0;
    for (int i = 0; i < 4; i++) {
        int r = 1;
        if (started[i]) thrd_join(t[i], &r);
        bad += r;
    }
    CHECK_EQ_INT(bad, 0);
    CHECK(mk_recycle_kept() <= CAP);
}

CHECK_MAIN(CASE(test_off_until_enabled), CASE(test_freed_pages_are_reused_zeroed),
           CASE(test_untouched_pages_stay_untouched), CASE(test_fresh_blocks_prepared), CASE(test_cap_and_growth), CASE(test_grow_recycled_block),
           CASE(test_no_unusable_remainders), CASE(test_full_table_keeps_the_larger),
           CASE(test_threads_get_zeroed_blocks))

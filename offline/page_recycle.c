/* SPDX-License-Identifier: MIT */
/* Kept pages of freed large blocks (page_recycle.h). The kept ranges are a small unordered
 * table under one mutex: large blocks are few (hundreds per import), so a linear best-fit
 * search costs nothing next to the faults it saves. */
#define _GNU_SOURCE
#include <stdint.h>
#include <string.h>
#include "page_recycle.h"

#if defined(__linux__)
#include <sys/mman.h>
#include <threads.h>
#include <unistd.h>

#define RANGE_SLOTS 64

typedef struct kept_range {
    uint8_t *p;
    size_t len;
} kept_range;

static kept_range kept[RANGE_SLOTS];
static size_t kept_count, kept_bytes, cap_bytes, page_size;
static int enabled;
static mtx_t lock;

int mk_recycle_enable(size_t cap)
{
    if (enabled || cap == 0) return enabled;
    long ps = sysconf(_SC_PAGESIZE);
    if (ps <= 0 || mtx_init(&lock, mtx_plain) != thrd_success) return 0;
    page_size = (size_t)ps;
    cap_bytes = cap;
    enabled = 1;
    return 1;
}

int mk_recycle_enabled(void) { return enabled; }

size_t mk_recycle_kept(void)
{
    if (!enabled) return 0;
    mtx_lock(&lock);
    size_t n = kept_bytes;
    mtx_unlock(&lock);
    return n;
}

/* Bytes rounded up to whole pages; 0 when that overflows. */
static size_t page_round(size_t bytes)
{
    return bytes > SIZE_MAX - page_size ? 0 : (bytes + page_size - 1) / page_size * page_size;
}

static void remove_kept(size_t i)
{
    kept_bytes -= kept[i].len;
    kept[i] = kept[--kept_count];
}

/* Zeroes reused pages without touching the ones that are not resident: resident runs are
 * cleared with memset, the others dropped (MADV_DONTNEED makes them zero-filled on first touch,
 * also where they had been swapped out). */
static void zero_pages(uint8_t *p, size_t len)
{
    unsigned char resident[4096];
    for (size_t at = 0; at < len;) {
        size_t pages = (len - at) / page_size;
        if (pages > sizeof resident) pages = sizeof resident;
        const size_t span = pages * page_size;
        if (mincore(p + at, span, resident) != 0) {
            memset(p + at, 0, span);
            at += span;
            continue;
        }
        for (size_t i = 0; i < pages;) {
            const int in = resident[i] & 1;
            size_t j = i + 1;
            while (j < pages && (resident[j] & 1) == in) j++;
            uint8_t *q = p + at + i * page_size;
            const size_t n = (j - i) * page_size;
            if (in || madvise(q, n, MADV_DONTNEED) != 0) memset(q, 0, n);
            i = j;
        }
        at += span;
    }
}

/* A new mapping of len bytes (whole pages), prepared for its first use. From MK_RECYCLE_HUGE on
 * it asks for transparent huge pages: one fault per 2 MB for the 2 MB-aligned stretches inside
 * it where the system gives them on request, as Debian does by default (the hint stays with the
 * pages when they are kept and reused). Below it, it is prefaulted in one call (one system call
 * instead of a fault per page; the block is then resident whole, used or not). Both are hints:
 * where the kernel lacks them the pages fault in one by one. NULL when the system refuses the
 * mapping. */
static void *map_fresh(size_t len)
{
    void *q = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (q == MAP_FAILED) return NULL;
    if (len >= MK_RECYCLE_HUGE) {
#ifdef MADV_HUGEPAGE
        (void)madvise(q, len, MADV_HUGEPAGE);
#endif
    } else {
#ifdef MADV_POPULATE_WRITE
        (void)madvise(q, len, MADV_POPULATE_WRITE);
#endif
    }
    return q;
}

void *mk_recycle_take(size_t bytes, size_t *mapped)
{
    if (!enabled) return NULL;
    size_t len = page_round(bytes);
    if (len == 0) return NULL;
    /* The smallest kept range that holds the block (split off its front), else the largest,
     * grown: either way every kept page is reused before fresh ones are mapped. */
    mtx_lock(&lock);
    size_t best = SIZE_MAX, largest = SIZE_MAX;
    for (size_t i = 0; i < kept_count; i++) {
        if (kept[i].len >= len && (best == SIZE_MAX || kept[i].len < kept[best].len)) best = i;
        if (largest == SIZE_MAX || kept[i].len > kept[largest].len) largest = i;
    }
    kept_range r = { NULL, 0 };
    if (best != SIZE_MAX) {
        /* A remainder too small for any later block is handed out with the block (its length
         * is the mapping's), instead of taking a slot it could never leave. */
        if (kept[best].len - len < MK_RECYCLE_MIN) len = kept[best].len;
        r = (kept_range){ kept[best].p, len };
        if (kept[best].len > len) {
            kept[best].p += len;
            kept[best].len -= len;
            kept_bytes -= len;
        } else {
            remove_kept(best);
        }
    } else if (largest != SIZE_MAX) {
        r = kept[largest];
        remove_kept(largest);
    }
    mtx_unlock(&lock);
    if (r.p && r.len < len) {
        void *g = mremap(r.p, r.len, len, MREMAP_MAYMOVE);
        if (g == MAP_FAILED) {
            munmap(r.p, r.len);
            r.p = NULL;
        } else {
            zero_pages(g, r.len);   /* the grown tail is fresh and zero */
            *mapped = len;
            return g;
        }
    }
    if (r.p) {
        zero_pages(r.p, len);
        *mapped = len;
        return r.p;
    }
    void *q = map_fresh(len);
    if (!q) return NULL;
    *mapped = len;
    return q;
}

void mk_recycle_give(void *p, size_t len)
{
    if (!p || !enabled) return;
    len = len / page_size * page_size;   /* mappings from take and grow are whole pages */
    kept_range drop = { NULL, 0 };
    mtx_lock(&lock);
    if (kept_count == RANGE_SLOTS) {   /* full: the smallest range makes room for a larger one */
        size_t smallest = 0;
        for (size_t i = 1; i < kept_count; i++)
            if (kept[i].len < kept[smallest].len) smallest = i;
        if (kept[smallest].len < len) {
            drop = kept[smallest];
            remove_kept(smallest);
        }
    }
    size_t keep = kept_bytes < cap_bytes ? (cap_bytes - kept_bytes) / page_size * page_size : 0;
    if (keep > len) keep = len;
    if (kept_count == RANGE_SLOTS) keep = 0;
    if (keep) {
        kept[kept_count++] = (kept_range){ p, keep };
        kept_bytes += keep;
    }
    mtx_unlock(&lock);
    if (drop.p) munmap(drop.p, drop.len);
    if (keep < len) munmap((uint8_t *)p + keep, len - keep);
}

void *mk_recycle_grow(void *p, size_t *mapped, size_t bytes)
{
    if (!enabled) return NULL;
    const size_t len = page_round(bytes);
    if (len == 0) return NULL;
    if (len <= *mapped) return p;
    void *g = mremap(p, *mapped, len, MREMAP_MAYMOVE);
    if (g == MAP_FAILED) return NULL;
    *mapped = len;
    return g;
}

#else

int mk_recycle_enable(size_t cap) { (void)cap; return 0; }
int mk_recycle_enabled(void) { return 0; }
size_t mk_recycle_kept(void) { return 0; }
void *mk_recycle_take(size_t bytes, size_t *mapped) { (void)bytes; (void)mapped; return NULL; }
void mk_recycle_give(void *p, size_t mapped) { (void)p; (void)mapped; }
void *mk_recycle_grow(void *p, size_t *mapped, size_t bytes) { (void)p; (void)mapped; (void)bytes; return NULL; }

#endif

/* SPDX-License-Identifier: MIT */
#define _GNU_SOURCE
#include "parallel.h"
#include <stdatomic.h>
#include <threads.h>
#include <unistd.h>
#if defined(__linux__)
#include <sched.h>
#endif

static uint32_t available_cores(void)
{
#if defined(__linux__)
    cpu_set_t set;  /* the cores this process may run on (containers, taskset) */
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return (uint32_t)CPU_COUNT(&set);
#endif
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (uint32_t)n : 1;
}

uint32_t mk_parallel_threads(uint32_t requested, uint32_t items)
{
    uint32_t n = requested ? requested : available_cores();
    if (n > MK_PARALLEL_MAX_THREADS) n = MK_PARALLEL_MAX_THREADS;
    if (n > items) n = items;
    return n ? n : 1;
}

typedef struct loop {
    atomic_uint next;
    uint32_t items;
    mk_parallel_fn fn;
    void *user;
} loop;

typedef struct worker {
    loop *l;
    uint32_t index;
} worker;

static void drain(loop *l, uint32_t index)
{
    for (;;) {
        uint32_t item = atomic_fetch_add(&l->next, 1u);
        if (item >= l->items) return;
        l->fn(l->user, item, index);
    }
}

static int worker_main(void *p)
{
    worker *w = p;
    drain(w->l, w->index);
    return 0;
}

void mk_parallel_for(uint32_t items, uint32_t threads, mk_parallel_fn fn, void *user)
{
    uint32_t n = mk_parallel_threads(threads, items);
    loop l;
    atomic_init(&l.next, 0u);
    l.items = items;
    l.fn = fn;
    l.user = user;
    thrd_t ids[MK_PARALLEL_MAX_THREADS];
    worker workers[MK_PARALLEL_MAX_THREADS];
    uint32_t started = 0;
    for (uint32_t i = 1; i < n; i++) {
        workers[started] = (worker){ &l, started + 1 };
        if (thrd_create(&ids[started], worker_main, &workers[started]) != thrd_success) break;
        started++;
    }
    drain(&l, 0);
    for (uint32_t i = 0; i < started; i++) thrd_join(ids[i], NULL);
}

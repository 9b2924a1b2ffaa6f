/* SPDX-License-Identifier: MIT */
#define _GNU_SOURCE
#include "parallel.h"
#include <stdatomic.h>
#include <stdlib.h>
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
    mk_team *team;
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

/* One loop on a team made for it (one piece of code for both kinds of loop). */
void mk_parallel_for(uint32_t items, uint32_t threads, mk_parallel_fn fn, void *user)
{
    mk_team *team = mk_team_create(mk_parallel_threads(threads, items));
    mk_team_for(team, items, fn, user);
    mk_team_destroy(team);
}

/* The team: the caller opens a loop (a new generation), drains it with whoever joins, closes it
 * and waits for the workers that joined. A worker joins a loop only while it is open, so the
 * caller never waits for a worker that is not running (another process may hold its core: then
 * the caller does the whole loop itself). Waiting spins for a moment first (a sweep's loops
 * come every few hundred microseconds; a sleep and wake-up costs tens of them), then sleeps. The
 * loop's fields change only while no worker is in it. */
struct mk_team {
    mtx_t lock;
    cnd_t start, done;
    atomic_ulong generation;  /* loops opened; changed under lock */
    atomic_uint active;       /* workers in the current loop; changed under lock */
    int closed;               /* the current loop takes no more workers; under lock */
    atomic_int stop;
    loop l;
    uint32_t count;           /* threads, the caller included */
    uint32_t started;         /* worker threads running */
    thrd_t ids[MK_PARALLEL_MAX_THREADS];
    worker workers[MK_PARALLEL_MAX_THREADS];
};

#define TEAM_SPINS 20000

/* One turn of a spin: a pause, and every 64th turn the core to whoever waits for it (more
 * threads than free cores: a spinning thread must not keep out the one it waits for). */
static void spin_pause(int turn)
{
    if ((turn & 63) == 63) {
        thrd_yield();
        return;
    }
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

static int team_main(void *p)
{
    worker *w = p;
    mk_team *t = w->team;
    unsigned long seen = 0;
    for (;;) {
        for (int i = 0; i < TEAM_SPINS && atomic_load(&t->generation) == seen && !atomic_load(&t->stop); i++) spin_pause(i);
        mtx_lock(&t->lock);
        while (atomic_load(&t->generation) == seen && !atomic_load(&t->stop)) cnd_wait(&t->start, &t->lock);
        if (atomic_load(&t->stop)) {
            mtx_unlock(&t->lock);
            return 0;
        }
        seen = atomic_load(&t->generation);
        int join = !t->closed;
        if (join) atomic_fetch_add(&t->active, 1u);
        mtx_unlock(&t->lock);
        if (!join) continue;  /* the loop was done without this worker */
        drain(&t->l, w->index);
        mtx_lock(&t->lock);
        if (atomic_fetch_sub(&t->active, 1u) == 1u) cnd_signal(&t->done);
        mtx_unlock(&t->lock);
    }
}

mk_team *mk_team_create(uint32_t threads)
{
    uint32_t n = mk_parallel_threads(threads, UINT32_MAX);
    if (n < 2) return NULL;
    mk_team *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    atomic_init(&t->l.next, 0u);
    atomic_init(&t->generation, 0ul);
    atomic_init(&t->active, 0u);
    atomic_init(&t->stop, 0);
    if (mtx_init(&t->lock, mtx_plain) != thrd_success) {
        free(t);
        return NULL;
    }
    if (cnd_init(&t->start) != thrd_success) {
        mtx_destroy(&t->lock);
        free(t);
        return NULL;
    }
    if (cnd_init(&t->done) != thrd_success) {
        cnd_destroy(&t->start);
        mtx_destroy(&t->lock);
        free(t);
        return NULL;
    }
    for (uint32_t i = 1; i < n; i++) {
        t->workers[t->started] = (worker){ t, t->started + 1 };
        if (thrd_create(&t->ids[t->started], team_main, &t->workers[t->started]) != thrd_success) break;
        t->started++;
    }
    t->count = t->started + 1;
    if (t->started == 0) {
        mk_team_destroy(t);
        return NULL;
    }
    return t;
}

void mk_team_for(mk_team *t, uint32_t items, mk_parallel_fn fn, void *user)
{
    if (!t || items < 2) {
        for (uint32_t i = 0; i < items; i++) fn(user, i, 0);
        return;
    }
    mtx_lock(&t->lock);
    /* No worker is in a loop here: the last call waited for those that joined it. */
    atomic_store(&t->l.next, 0u);
    t->l.items = items;
    t->l.fn = fn;
    t->l.user = user;
    t->closed = 0;
    atomic_fetch_add(&t->generation, 1ul);
    cnd_broadcast(&t->start);
    mtx_unlock(&t->lock);
    drain(&t->l, 0);
    /* Every item is taken: close the loop, then wait for the workers still in it. */
    mtx_lock(&t->lock);
    t->closed = 1;
    mtx_unlock(&t->lock);
    for (int i = 0; i < TEAM_SPINS && atomic_load(&t->active) > 0; i++) spin_pause(i);
    mtx_lock(&t->lock);
    while (atomic_load(&t->active) > 0) cnd_wait(&t->done, &t->lock);
    mtx_unlock(&t->lock);
}

uint32_t mk_team_threads(const mk_team *t)
{
    return t ? t->count : 1;
}

void mk_team_destroy(mk_team *t)
{
    if (!t) return;
    mtx_lock(&t->lock);
    atomic_store(&t->stop, 1);
    cnd_broadcast(&t->start);
    mtx_unlock(&t->lock);
    for (uint32_t i = 0; i < t->started; i++) thrd_join(t->ids[i], NULL);
    cnd_destroy(&t->done);
    cnd_destroy(&t->start);
    mtx_destroy(&t->lock);
    free(t);
}

/* SPDX-License-Identifier: MIT */
/* A parallel loop for offline work (import, bake): items taken in increasing order from a
 * shared counter by a few threads. The result of a loop must not depend on which thread ran
 * which item: give each item its own output and each worker its own scratch (indexed by the
 * worker number), and merge in item order afterwards. */
#ifndef MK_PARALLEL_H
#define MK_PARALLEL_H

#include <stdint.h>

#define MK_PARALLEL_MAX_THREADS 64

/* fn(user, item, worker): worker is in [0, the thread count the loop resolved). */
typedef void (*mk_parallel_fn)(void *user, uint32_t item, uint32_t worker);

/* The threads a loop over `items` uses when `requested` threads are asked for: 0 asks for
 * one per available core; never more than the items or MK_PARALLEL_MAX_THREADS, at least 1. */
uint32_t mk_parallel_threads(uint32_t requested, uint32_t items);

/* Runs fn for every item in [0, items) on mk_parallel_threads(threads, items) threads, the
 * calling thread being worker 0; returns when all are done. If a thread cannot be started,
 * the others do its share. */
void mk_parallel_for(uint32_t items, uint32_t threads, mk_parallel_fn fn, void *user);

/* A team of threads kept between loops, for many short loops in a row (a simulation's sweeps),
 * where starting threads per loop (mk_parallel_for) would cost more than the loop. The same
 * rules for what a loop may depend on. */
typedef struct mk_team mk_team;

/* A team of mk_parallel_threads(threads, UINT32_MAX) threads, the caller of mk_team_for being
 * one of them. NULL when only one thread is asked for or available, or when a thread or the
 * memory for the team cannot be had; mk_team_for then runs the loop on the calling thread. */
mk_team *mk_team_create(uint32_t threads);
/* Runs fn for every item in [0, items) on the team (worker 0 is the caller); returns when all
 * are done. team may be NULL. */
void mk_team_for(mk_team *team, uint32_t items, mk_parallel_fn fn, void *user);
/* The team's thread count (1 for NULL). */
uint32_t mk_team_threads(const mk_team *team);
/* Stops and frees the team (NULL: nothing). */
void mk_team_destroy(mk_team *team);

#endif

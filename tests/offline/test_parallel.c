/* SPDX-License-Identifier: MIT */
/* mk_parallel_for and the team (mk_team_*): every item runs exactly once per loop, each worker
 * number within the thread count, for teams of 1 (NULL) to 4 threads and thousands of loops in
 * a row of 0, 1, a few and many items (short loops, where a worker may come too late to join);
 * a loop sees the memory the caller wrote before it, and the caller sees the items' writes after
 * it. */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "parallel.h"

typedef struct run {
    atomic_uint *hits;        /* per item */
    const uint32_t *input;    /* written by the caller before the loop */
    uint32_t *output;         /* per item, read by the caller after the loop */
    uint32_t threads;
    atomic_uint bad_worker;
    atomic_uint on_workers;   /* items run by workers, not the caller */
} run;

static _Thread_local volatile uint32_t sink;

/* A little work per item (so that workers join the longer loops), and more on a worker before
 * the output is written: a caller that returned before its workers were done would find
 * outputs missing. */
static void item_fn(void *user, uint32_t item, uint32_t worker)
{
    run *r = user;
    atomic_fetch_add(&r->hits[item], 1u);
    uint32_t x = item;
    for (int i = 0; i < (worker ? 4000 : 40); i++) x = x * 1664525u + 1013904223u;
    sink = x;
    r->output[item] = r->input[item] * 3u + 1u;
    if (worker) atomic_fetch_add(&r->on_workers, 1u);
    if (worker >= r->threads) atomic_fetch_add(&r->bad_worker, 1u);
}

static void team_runs_every_item_once(void)
{
    enum { MAX_ITEMS = 5000 };
    atomic_uint *hits = malloc(MAX_ITEMS * sizeof *hits);
    uint32_t *input = malloc(MAX_ITEMS * sizeof *input), *output = malloc(MAX_ITEMS * sizeof *output);
    CHECK(hits && input && output);
    if (!hits || !input || !output) return;
    for (uint32_t threads = 1; threads <= 4; threads++) {
        mk_team *team = mk_team_create(threads);
        uint32_t n = mk_team_threads(team), loops = 0, wrong = 0;
        CHECK(threads == 1 ? team == NULL && n == 1 : n >= 1 && n <= threads);
        run r = { .hits = hits, .input = input, .output = output, .threads = n };
        atomic_init(&r.bad_worker, 0u);
        atomic_init(&r.on_workers, 0u);
        static const uint32_t sizes[] = { 0, 1, 2, 3, 7, 64, 5000 };
        for (uint32_t rep = 0; rep < 300; rep++)
            for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
                uint32_t items = sizes[k];
                for (uint32_t i = 0; i < items; i++) {
                    atomic_init(&hits[i], 0u);
                    input[i] = rep * 7919u + i;
                    output[i] = 0;
                }
                mk_team_for(team, items, item_fn, &r);
                for (uint32_t i = 0; i < items; i++)
                    if (atomic_load(&hits[i]) != 1u || output[i] != input[i] * 3u + 1u) wrong++;
                loops++;
            }
        printf("team of %u thread%s (asked %u): %u loops, %u items on workers, %u items wrong, %u bad worker numbers\n", n,
               n == 1 ? "" : "s", threads, loops, atomic_load(&r.on_workers), wrong, atomic_load(&r.bad_worker));
        CHECK(wrong == 0 && atomic_load(&r.bad_worker) == 0);
        mk_team_destroy(team);
    }
    /* The one-shot loop follows the same rules. */
    run r = { .hits = hits, .input = input, .output = output, .threads = 3 };
    atomic_init(&r.bad_worker, 0u);
    atomic_init(&r.on_workers, 0u);
    uint32_t wrong = 0;
    for (uint32_t i = 0; i < MAX_ITEMS; i++) {
        atomic_init(&hits[i], 0u);
        input[i] = i;
    }
    mk_parallel_for(MAX_ITEMS, 3, item_fn, &r);
    for (uint32_t i = 0; i < MAX_ITEMS; i++)
        if (atomic_load(&hits[i]) != 1u || output[i] != input[i] * 3u + 1u) wrong++;
    CHECK(wrong == 0 && atomic_load(&r.bad_worker) == 0);
    free(hits);
    free(input);
    free(output);
}

CHECK_MAIN(CASE(team_runs_every_item_once))

/* SPDX-License-Identifier: MIT */
/* The order in which a Gauss-Seidel sweep visits the elements (shell.h, shell_sweep_order).
 *
 * Phases and parts: the elements, in mesh order, are cut into runs of equal length
 * (count / SHELL_PART_MIN of them, at least 1 and at most SHELL_PARTS_MAX); a vertex belongs to
 * the run of the first element that has it. An element all of whose vertices belong to its own
 * run is in that run's part of the first phase; the others (along the cuts) are left for the next
 * phase, which cuts them the same way, and so on; the last phase (SHELL_PHASES_MAX) takes what is
 * left as one part. The parts of a phase share no vertex, so they can be swept at the same time,
 * each by one thread: the same result as one after the other in this order, for any number of
 * threads. The order depends on the mesh only.
 *
 * Batches: within a part the elements are cut into short batches of elements that share no
 * vertex. An element's projection moves the vertices the next one reads, so in mesh order
 * (neighbours after neighbours) every projection waits for the one before it: a chain of square
 * roots and divisions that leaves the processor idle. Within a batch the elements are
 * independent, so the sweep evaluates all of them, then projects all of them. Each batch is filled
 * greedily from a short window of the part's elements not yet placed, in mesh order, so the sweep
 * still walks the mesh from one end to the other (its data stays in cache). */
#include <string.h>
#include "shell.h"

/* Places the listed elements (list[0 .. count), mesh order) in batches at out->order[*placed ..). */
static void place_batches(const uint32_t *idx, int k, uint32_t *list, uint32_t count, uint32_t *next, uint32_t *stamp,
                          shell_sweep_order *out, uint32_t *placed)
{
    /* The elements not placed yet, a linked list over positions in `list`; count ends it. */
    for (uint32_t i = 0; i < count; i++) next[i] = i + 1;
    uint32_t head = 0;
    while (head < count) {
        uint32_t b = out->batch_count++, mark = b + 1;  /* stamps: the batch that holds a vertex */
        out->start[b] = *placed;
        uint32_t *link = &head, taken = 0;
        for (uint32_t seen = 0; *link < count && taken < SHELL_BATCH && seen < SHELL_BATCH_WINDOW; seen++) {
            uint32_t i = *link;
            const uint32_t *v = idx + (size_t)k * list[i];
            int free = 1;
            for (int j = 0; j < k; j++) free &= stamp[v[j]] != mark;
            if (!free) {
                link = &next[i];
                continue;
            }
            for (int j = 0; j < k; j++) stamp[v[j]] = mark;
            out->order[(*placed)++] = list[i];
            taken++;
            *link = next[i];  /* unlink i */
        }
    }
    out->start[out->batch_count] = *placed;
}

uint32_t shell_sweep_parts(uint32_t count)
{
    uint32_t parts = count / SHELL_PART_MIN;
    return parts > SHELL_PARTS_MAX ? SHELL_PARTS_MAX : parts < 1 ? 1 : parts;
}

mk_result shell_sweep_order_build(const uint32_t *idx, int k, uint32_t count, uint32_t n, mk_arena *arena,
                                  shell_sweep_order *out, mk_error *err)
{
    memset(out, 0, sizeof *out);
    uint32_t parts = shell_sweep_parts(count);
    out->order = mk_arena_array(arena, (size_t)count + 1, sizeof(uint32_t));
    out->start = mk_arena_array(arena, (size_t)count + 2, sizeof(uint32_t));
    uint32_t *group = mk_arena_array(arena, (size_t)count + 1, sizeof(uint32_t));
    uint32_t *list = mk_arena_array(arena, (size_t)count + 1, sizeof(uint32_t));
    uint32_t *part = mk_arena_array(arena, (size_t)count + 1, sizeof(uint32_t));
    uint32_t *next = mk_arena_array(arena, (size_t)count + 1, sizeof(uint32_t));
    uint32_t *owner = mk_arena_array(arena, (size_t)n + 1, sizeof(uint32_t));
    uint32_t *stamp = mk_arena_array(arena, (size_t)n + 1, sizeof(uint32_t));
    if (!out->order || !out->start || !group || !list || !part || !next || !owner || !stamp)
        return mk_error_oom(err, "shell sweep order");
    /* list: the elements left for this phase, in mesh order (at first all of them). */
    uint32_t left = count, placed = 0;
    for (uint32_t e = 0; e < count; e++) list[e] = e;
    while (left > 0) {
        uint32_t f = out->phase_count++;
        uint32_t runs = f + 1 == SHELL_PHASES_MAX ? 1 : parts;  /* the last phase takes the rest as one part */
        for (uint32_t v = 0; v < n; v++) owner[v] = UINT32_MAX;
        for (uint32_t i = 0; i < left; i++) {
            uint32_t run = (uint32_t)((uint64_t)i * runs / left);
            const uint32_t *v = idx + (size_t)k * list[i];
            for (int j = 0; j < k; j++)
                if (owner[v[j]] == UINT32_MAX) owner[v[j]] = run;
            group[i] = run;
        }
        for (uint32_t i = 0; i < left; i++) {
            const uint32_t *v = idx + (size_t)k * list[i];
            for (int j = 0; j < k; j++)
                if (owner[v[j]] != group[i]) group[i] = runs;  /* along a cut: a later phase */
        }
        out->phase_part[f] = out->part_count;
        for (uint32_t g = 0; g < runs; g++) {
            uint32_t c = 0;
            for (uint32_t i = 0; i < left; i++)
                if (group[i] == g) part[c++] = list[i];
            if (c == 0) continue;
            out->part_batch[out->part_count++] = out->batch_count;
            place_batches(idx, k, part, c, next, stamp, out, &placed);
        }
        uint32_t rest = 0;
        for (uint32_t i = 0; i < left; i++)
            if (group[i] == runs) list[rest++] = list[i];
        left = rest;
    }
    out->phase_part[out->phase_count] = out->part_count;
    out->part_batch[out->part_count] = out->batch_count;
    mk_arena_release(arena, stamp);
    mk_arena_release(arena, owner);
    mk_arena_release(arena, next);
    mk_arena_release(arena, part);
    mk_arena_release(arena, list);
    mk_arena_release(arena, group);
    return MK_OK;
}

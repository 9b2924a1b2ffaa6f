/* SPDX-License-Identifier: MIT */
/* Where a long offline job's time and memory go, phase by phase (`morphkit import --timings`).
 * A log is optional everywhere: every function accepts NULL and then does nothing. Marks with
 * the same name add up (a phase that runs once per mesh is one line). */
#ifndef MK_PHASE_LOG_H
#define MK_PHASE_LOG_H

#include <stdint.h>
#include <stdio.h>

#define MK_PHASE_MAX 16

typedef struct mk_phase {
    const char *name;    /* a string literal */
    double seconds;      /* wall-clock time spent in the phase */
    double peak_bytes;   /* the process's peak resident memory when the phase last ended (0 unknown) */
} mk_phase;

typedef struct mk_phase_log {
    uint32_t count;
    mk_phase phases[MK_PHASE_MAX];
    double started, last_mark;
} mk_phase_log;

/* Starts the clock: the first phase begins now. */
void mk_phase_log_start(mk_phase_log *log);
/* Ends the phase that began at the previous mark (or the start) and names it. */
void mk_phase_log_mark(mk_phase_log *log, const char *name);
/* Prints one line per phase (seconds, share of the total, peak memory) and the total. */
void mk_phase_log_print(const mk_phase_log *log, FILE *out);

#endif

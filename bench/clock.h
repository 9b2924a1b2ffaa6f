/* SPDX-License-Identifier: MIT */
/* The benchmark's clock. A file of its own below the rest of bench/: the timing harness
 * (timing.c) and the baselines it times or samples (copy_probe.c, naive.c, surface.c) all read
 * it, and none of them has to call another for it. */
#ifndef MK_BENCH_CLOCK_H
#define MK_BENCH_CLOCK_H

/* Monotonic time in nanoseconds (CLOCK_MONOTONIC), for differences. */
double bench_now_ns(void);

#endif

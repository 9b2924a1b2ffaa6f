/* SPDX-License-Identifier: MIT */
/* The benchmark's clock (clock.h). */
#include <time.h>
#include "clock.h"

double bench_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

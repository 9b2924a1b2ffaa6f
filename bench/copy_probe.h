/* SPDX-License-Identifier: MIT */
/* The memory-bandwidth baseline of the benchmark. */
#ifndef MK_BENCH_COPY_PROBE_H
#define MK_BENCH_COPY_PROBE_H

#include <stddef.h>

/* Memory-copy bandwidth: copies of 256 MiB (read + write counted), best of all samples.
 * Samples are taken between the evaluation passes as well as at the end, so the bound and
 * the frame time come from the same stretch of time on a shared host. */
typedef struct copy_probe {
    char *a, *b;
    size_t size;
    double best_ns;
    int flip;
} copy_probe;

/* 0 when the buffers could not be allocated (then nothing is sampled). */
int copy_probe_init(copy_probe *p);
/* One timed copy; p may be NULL. */
void copy_probe_sample(copy_probe *p);
/* Bytes per ns (read + write), or 0 when the buffers could not be allocated. */
double copy_probe_bandwidth(const copy_probe *p);
void copy_probe_free(copy_probe *p);

#endif

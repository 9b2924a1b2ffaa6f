/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "clock.h"
#include "copy_probe.h"

int copy_probe_init(copy_probe *p)
{
    p->size = (size_t)256 << 20;
    p->a = malloc(p->size);
    p->b = malloc(p->size);
    p->best_ns = INFINITY;
    p->flip = 0;
    if (!p->a || !p->b) return 0;
    memset(p->a, 1, p->size);
    memset(p->b, 2, p->size);
    return 1;
}

/* p is NULL when copy_probe_init failed (then nothing is sampled). */
void copy_probe_sample(copy_probe *p)
{
    if (!p) return;
    double t0 = bench_now_ns();
    memcpy(p->flip ? p->a : p->b, p->flip ? p->b : p->a, p->size);
    double t = bench_now_ns() - t0;
    p->flip = !p->flip;
    volatile char sink = p->a[p->size / 2] + p->b[p->size / 3];
    (void)sink;
    if (t < p->best_ns) p->best_ns = t;
}

/* Bytes per ns, or 0 when the buffers could not be allocated. */
double copy_probe_bandwidth(const copy_probe *p)
{
    return isfinite(p->best_ns) ? 2.0 * (double)p->size / p->best_ns : 0;
}

void copy_probe_free(copy_probe *p)
{
    free(p->a);
    free(p->b);
}

/* SPDX-License-Identifier: MIT */
/* The synthetic asset `morphkit bench` builds without a file. */
#ifndef MK_BENCH_SYNTHETIC_H
#define MK_BENCH_SYNTHETIC_H

#include "raw.h"

typedef struct bench_synthetic {
    uint32_t vertices; /* a near-square grid of this many vertices (>= 64) */
    uint32_t channels; /* one in five progressive (an in-between at 0.5) */
    uint32_t active;   /* channels nonzero per frame (for the memory estimate) */
    double density;    /* fraction of the vertices each target moves */
} bench_synthetic;

/* One mesh with normals; each channel's targets move the vertices inside 3 disks (an LCG
 * places them, so the asset is the same every run). */
mk_result bench_build_synthetic(const bench_synthetic *params, mk_raw_asset *raw, mk_error *err);
/* What the benchmark allocates for it, roughly: raw model and blob, the naive baseline's dense
 * arrays, outputs and the copy probe. */
double bench_synthetic_bytes(const bench_synthetic *params);
/* Bytes of memory the machine has, or 0 when unknown. */
double bench_machine_memory(void);

#endif

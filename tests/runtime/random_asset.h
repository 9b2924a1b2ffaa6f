/* SPDX-License-Identifier: MIT */
/* Random assets for the tests that compare one evaluator with another (the runtime against the
 * reference evaluator, the GPU path against the runtime): one mesh of 1-300 vertices (crossing
 * blocks, partial blocks, whole blocks), base normals unit or not, tangents or not, additive or
 * sequential, 1-6 channels of 1-4 in-betweens with negative and positive full weights, targets
 * moving none, a few, most or all vertices, in runs or scattered. */
#ifndef MK_TEST_RANDOM_ASSET_H
#define MK_TEST_RANDOM_ASSET_H

#include <stdint.h>
#include "raw.h"

/* splitmix64: any seed is a good seed. */
typedef struct rng {
    uint64_t state;
} rng;

uint64_t next_u64(rng *r);
double uniform(rng *r, double lo, double hi);
uint32_t below(rng *r, uint32_t n);
int chance(rng *r, double p);
/* A random unit vector (3 floats). */
void random_unit(rng *r, float *out);
/* Fills raw (initialized here) with a random asset as described above. */
void random_asset(rng *r, mk_raw_asset *raw);
/* A weight for a channel: exactly 0, exactly a full weight, beyond the first or last key, or
 * uniform in [-2, 3]. */
float random_weight(rng *r, const mk_raw_channel *ch);

#endif

/* SPDX-License-Identifier: MIT */
/* Small raw assets built by code for tests, with hand-checkable deltas. */
#ifndef MK_FIXTURES_H
#define MK_FIXTURES_H

#include "blob_io.h"

/* Mesh 0 "quad": 4 vertices at (0,0,0) (1,0,0) (0,1,0) (1,1,0), normals +z, tangents +x (w=1),
 * 2 triangles. Channels (mesh 0):
 *   0 "progressive": f=0.5 delta v0 (0,0,1), normal v0 (1,0,-1);  f=1.0 delta v0 (0,0,3)
 *   1 "negative":    f=-1  delta v1 (0,1,0);                      f=1.0 delta v1 (1,0,0)
 *   2 "seq_a":       f=1   delta v2 (1,0,0)
 *   3 "seq_b":       f=1   delta v2 (0,2,0)
 * Mesh 1 "plain": 3 vertices, no normals, channel 4 "lift": f=1 delta v0..v2 (0,0,1).
 * Clip 0 "anim": channel 0 linear 0->1 over [0,1] s; channel 4 constant 0.5.
 * Channel default weights are 0. */
void fixture_basic(mk_raw_asset *raw);

/* A mesh of n vertices on a line with `channels` single-target channels touching every
 * `stride`-th vertex (sparse) or all (dense); deterministic values. */
void fixture_line(mk_raw_asset *raw, uint32_t n, uint32_t channels, uint32_t stride);

/* Writes raw to a blob in arena (aborts the test program on failure). */
void *fixture_blob(const mk_raw_asset *raw, mk_precision precision, mk_arena *arena, size_t *size);

#endif

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

/* Every structure the format has, small enough to patch by hand (the corruption tests of
 * mk_asset_open break each field of it):
 * Mesh 0 "face": 4 vertices (the quad of fixture_basic) with normals and tangents, control
 *   points {0, 1, 2, 2} (3 of them), additive. Channels:
 *     0 "brow" (progressive, a negative in-between): f = -0.5 (v0), 0.5 (v0 v1), 1 (v0 v1 v3),
 *       each with position, normal and tangent deltas;
 *     1 "jaw": f = 1, positions only (v2 v3).
 * Mesh 1 "prop": 3 vertices, no normals, no channels.
 * Mesh 2 "strip": 150 vertices (3 blocks, the last of 22), normals, sequential. Channels:
 *     2 "dense": f = 1 moves every vertex, with normal deltas (dense blocks 0 and 1);
 *     3 "sparse": f = 0.5 and 1 move every 7th vertex (sparse entries);
 *     4 "span": f = 1 moves vertices 60..70 (across the block 0/1 boundary), default 0.25.
 * Mesh 3 "rigid": 3 vertices, no normals, channel 5 "lift": f = 1 moves all three.
 * Clips: 0 "talk" (start 0, 2 s): channel 0 cubic (3 keys, weights 1/3), channel 1 weighted
 *   cubic (2 keys, weights 0.25/0.75), channel 3 constant-next (2 keys);
 *   1 "still" (0 s, no tracks);
 *   2 "blink" (start 0.5, 1 s): channel 4 constant (1 key), channel 2 linear (2 keys). */
void fixture_rich(mk_raw_asset *raw);

/* Mesh 0 "wavy": an n x n grid (spacing 1, height 0.3 sin(0.7 x) cos(0.4 y), base normals
 * +z, one control point per vertex, 2 (n-1)^2 triangles) and `targets` single-target
 * channels "lift", target k lifting a disc of radius 2 + k % 4 around (7k % n, 13k % n) by up
 * to 0.5 (and pushing it outwards by 0.1 x the distance). */
void fixture_wavy_grid(mk_raw_asset *raw, uint32_t n, uint32_t targets);

/* Brute force: the normalized sum of the area-weighted normals (cross products) of every
 * triangle with a corner in v's group, at positions pos (3 floats per render vertex). The
 * group: the vertices with v's control point (v alone without control points), and, with
 * split_by_normal, v's base normal within 1e-5 per component. */
void fixture_brute_normal(const mk_raw_mesh *m, const float *pos, uint32_t v, int split_by_normal, double out[3]);

/* Writes raw to a blob in arena (aborts the test program on failure). */
void *fixture_blob(const mk_raw_asset *raw, mk_precision precision, mk_arena *arena, size_t *size);

#endif

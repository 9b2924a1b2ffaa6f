/* SPDX-License-Identifier: MIT */
/* How a channel with in-betweens is written as glTF targets, shared by the glTF export and the
 * glTF write-back (gltf_weights.c; docs/importing-gltf.md). */
#ifndef MK_GLTF_WEIGHTS_H
#define MK_GLTF_WEIGHTS_H

#include "raw.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The glTF weights of channel ch's targets at channel weight w: the runtime's span
 * coefficients (mk_channel_span), so the two targets around w get their factors and the others
 * 0. u holds ch->target_count floats. */
void mk_gltf_slot_weights(const mk_raw_channel *ch, float w, float *u);

/* glTF LINEAR keys cannot hold what a track does between two keys in every case: the times to
 * sample inside the segment from key a to key b (not a's own time) are written to out, at most
 * MK_GLTF_SEGMENT_TIMES, and counted: 1 ms (at most a quarter of the gap) before a constant
 * segment's jump (after the key for constant-next), where a linear segment crosses 0 or a
 * full weight of an in-between channel (where its slot weights bend), and 60 per second (at
 * least 2 steps, at most 4096) inside a cubic segment. */
#define MK_GLTF_SEGMENT_TIMES 4096
uint32_t mk_gltf_segment_times(const mk_key *a, const mk_key *b, const mk_raw_channel *ch, float *out);

/* Sorts times and drops those within 1e-6 s of the one before; returns the count kept. */
size_t mk_gltf_unique_times(float *times, size_t count);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* In-between channels as glTF targets (gltf_weights.h). */
#include <math.h>
#include <stdlib.h>
#include "gltf_weights.h"

void mk_gltf_slot_weights(const mk_raw_channel *ch, float w, float *u)
{
    const uint32_t n = ch->target_count;
    for (uint32_t k = 0; k < n; k++) u[k] = ch->targets[k].full_weight;   /* the span's input first */
    int32_t ia, ib;
    float ca, cb, t;
    mk_channel_span(u, n, w, &ia, &ca, &ib, &cb, &t);
    for (uint32_t k = 0; k < n; k++) u[k] = 0.0f;
    if (ia >= 0 && (uint32_t)ia < n) u[ia] += ca;
    if (ib >= 0 && (uint32_t)ib < n) u[ib] += cb;
}

uint32_t mk_gltf_segment_times(const mk_key *a, const mk_key *b, const mk_raw_channel *ch, float *out)
{
    uint32_t n = 0;
    const float gap = b->time - a->time, delta = gap / 4 < 1e-3f ? gap / 4 : 1e-3f;
    switch (a->interp) {
    case MK_INTERP_CONSTANT: out[n++] = b->time - delta; break;
    case MK_INTERP_CONSTANT_NEXT: out[n++] = a->time + delta; break;
    case MK_INTERP_LINEAR:
        for (uint32_t j = 0; ch->target_count > 1 && j <= ch->target_count && n < MK_GLTF_SEGMENT_TIMES; j++) {
            const float f = j ? ch->targets[j - 1].full_weight : 0.0f;
            if ((a->value - f) * (b->value - f) < 0) out[n++] = a->time + gap * (f - a->value) / (b->value - a->value);
        }
        break;
    default: {
        int steps = (int)ceilf(gap * 60.0f);
        if (steps < 2) steps = 2;
        if (steps > MK_GLTF_SEGMENT_TIMES) steps = MK_GLTF_SEGMENT_TIMES;
        for (int q = 1; q < steps; q++) out[n++] = a->time + gap * (float)q / (float)steps;
    }
    }
    return n;
}

static int by_value(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

size_t mk_gltf_unique_times(float *times, size_t count)
{
    qsort(times, count, sizeof *times, by_value);
    size_t kept = 0;
    for (size_t i = 0; i < count; i++)
        if (!kept || times[i] - times[kept - 1] > 1e-6f) times[kept++] = times[i];
    return kept;
}

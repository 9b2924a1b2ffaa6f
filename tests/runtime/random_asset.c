/* SPDX-License-Identifier: MIT */
/* Random assets for the tests that compare evaluators (random_asset.h). */
#include <math.h>
#include <stdio.h>
#include "mat4.h"
#include "random_asset.h"

/* ---- random numbers (splitmix64: any seed is a good seed) ---- */

uint64_t next_u64(rng *r)
{
    uint64_t z = (r->state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

double uniform(rng *r, double lo, double hi) { return lo + (hi - lo) * (double)(next_u64(r) >> 11) * 0x1p-53; }
uint32_t below(rng *r, uint32_t n) { return (uint32_t)(next_u64(r) % n); }
int chance(rng *r, double p) { return uniform(r, 0, 1) < p; }

void random_unit(rng *r, float *out)
{
    double v[3], len;
    do {
        for (int k = 0; k < 3; k++) v[k] = uniform(r, -1, 1);
        len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (len < 0.1 || len > 1);
    for (int k = 0; k < 3; k++) out[k] = (float)(v[k] / len);
}

/* ---- random assets ---- */

/* Whether a target moves vertex v, by a per-target pattern. */
typedef enum pattern { NONE, ALL, SCATTERED, RUNS, PATTERN_COUNT } pattern;

static void random_target(rng *r, mk_raw_asset *raw, const mk_raw_mesh *m, mk_raw_target *t, float full_weight)
{
    const uint32_t n = m->vertex_count;
    t->name = mk_arena_strdup(&raw->arena, "t");
    t->full_weight = full_weight;
    t->indices = mk_arena_array(&raw->arena, n, sizeof(uint32_t));
    uint32_t count = 0;
    pattern p = (pattern)below(r, PATTERN_COUNT);
    double density = chance(r, 0.5) ? uniform(r, 0.01, 0.3) : uniform(r, 0.5, 0.97);
    uint32_t run_left = 0;
    int in_run = 0;
    for (uint32_t v = 0; v < n; v++) {
        int moves = 0;
        switch (p) {
        case NONE: moves = 0; break;
        case ALL: moves = 1; break;
        case SCATTERED: moves = chance(r, density); break;
        default:   /* runs of 1-40 moved, then of 1-40 still vertices */
            if (run_left == 0) { in_run = !in_run; run_left = 1 + below(r, 40); }
            run_left--;
            moves = in_run;
            break;
        }
        if (moves) t->indices[count++] = v;
    }
    t->count = count;
    const double amplitude = uniform(r, 0.01, 2.0), normal_amplitude = uniform(r, 0.1, 1.5);
    t->positions = mk_arena_array(&raw->arena, 3 * (size_t)count + 1, sizeof(float));
    for (size_t i = 0; i < 3 * (size_t)count; i++) t->positions[i] = (float)uniform(r, -amplitude, amplitude);
    if (m->normals && chance(r, 0.75)) {
        t->normals = mk_arena_array(&raw->arena, 3 * (size_t)count + 1, sizeof(float));
        for (size_t i = 0; i < 3 * (size_t)count; i++) t->normals[i] = (float)uniform(r, -normal_amplitude, normal_amplitude);
    }
    if (m->tangents && chance(r, 0.7)) {
        t->tangents = mk_arena_array(&raw->arena, 3 * (size_t)count + 1, sizeof(float));
        for (size_t i = 0; i < 3 * (size_t)count; i++) t->tangents[i] = (float)uniform(r, -0.8, 0.8);
    }
}

/* count distinct sorted full weights: quarter steps in [-2, 2] (or [-2, -0.25] for a channel
 * without a positive one) jittered by < 0.08, so keys stay >= 0.09 apart and |f| >= 0.17. */
static void random_full_weights(rng *r, uint32_t count, float *out)
{
    if (count == 1 && chance(r, 0.25)) { out[0] = 1.0f; return; }
    const int all_negative = chance(r, 0.15);
    int chosen[17] = { 0 };
    for (uint32_t k = 0; k < count;) {
        int step = all_negative ? -1 - (int)below(r, 8) : (int)below(r, 16) - 8;
        if (step >= 0) step++;   /* -8..-1, 1..8 */
        if (chosen[step + 8]) continue;
        chosen[step + 8] = 1;
        k++;
    }
    uint32_t k = 0;
    for (int step = -8; step <= 8; step++)
        if (chosen[step + 8]) out[k++] = (float)(0.25 * step + uniform(r, -0.08, 0.08));
}

void random_asset(rng *r, mk_raw_asset *raw)
{
    mk_raw_init(raw, NULL);
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = mk_arena_strdup(&raw->arena, "random");
    mk_mat4_identity(m->world);
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = -1;
    uint32_t n, shape = below(r, 100);
    if (shape < 75) {
        n = 65 + below(r, 236);              /* 65..300, crossing block boundaries */
        if (n % 64 == 0) n++;
    } else if (shape < 90) {
        n = 1 + below(r, 64);                /* one partial block */
    } else {
        n = 64 * (1 + below(r, 3));          /* whole blocks only */
    }
    m->vertex_count = n;
    m->control_point_count = n;
    m->stacking = chance(r, 0.5) ? MK_STACKING_ADDITIVE : MK_STACKING_SEQUENTIAL;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    for (size_t i = 0; i < 3 * (size_t)n; i++) m->positions[i] = (float)uniform(r, -1, 1);
    if (chance(r, 0.85)) {
        const int unit = chance(r, 0.75);
        m->normals = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
        for (uint32_t v = 0; v < n; v++) {
            random_unit(r, m->normals + 3 * (size_t)v);
            if (!unit) {
                float scale = (float)uniform(r, 0.5, 2.0);
                for (int k = 0; k < 3; k++) m->normals[3 * (size_t)v + (size_t)k] *= scale;
            }
        }
    }
    if (chance(r, 0.5)) {
        m->tangents = mk_arena_array(&raw->arena, 4 * (size_t)n, sizeof(float));
        for (uint32_t v = 0; v < n; v++) {
            random_unit(r, m->tangents + 4 * (size_t)v);
            m->tangents[4 * (size_t)v + 3] = chance(r, 0.5) ? 1.0f : -1.0f;
        }
    }
    const uint32_t channels = 1 + below(r, 6);
    mk_raw_add_channels(raw, channels);
    for (uint32_t c = 0; c < channels; c++) {
        mk_raw_channel *ch = &raw->channels[c];
        char name[16];
        snprintf(name, sizeof name, "c%u", c);
        ch->name = mk_arena_strdup(&raw->arena, name);
        ch->mesh = 0;
        uint32_t count = 1 + below(r, 4);
        float full[4];
        random_full_weights(r, count, full);
        mk_raw_add_targets(raw, ch, count);
        for (uint32_t k = 0; k < count; k++) random_target(r, raw, m, &ch->targets[k], full[k]);
    }
}

/* A weight for a channel: exactly 0, exactly a full weight, beyond the first or last key, or
 * uniform in [-2, 3]. */
float random_weight(rng *r, const mk_raw_channel *ch)
{
    const float first = ch->targets[0].full_weight, last = ch->targets[ch->target_count - 1].full_weight;
    double p = uniform(r, 0, 1);
    if (p < 0.12) return 0.0f;
    if (p < 0.35) return ch->targets[below(r, ch->target_count)].full_weight;
    if (p < 0.42) return (float)((last > 0 ? last : 0) + uniform(r, 0.01, 1.0));
    if (p < 0.47) return (float)((first < 0 ? first : 0) - uniform(r, 0.01, 1.0));
    return (float)uniform(r, -2, 3);
}


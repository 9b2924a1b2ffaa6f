/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "clock.h"
#include "frame.h"
#include "naive.h"
#include "timing.h"

/* The naive baseline: dense float deltas for every target, a loop over all vertices for
 * each active target, then normals normalized. Returns ns per frame; checks its output
 * against the runtime's (max abs difference into *diff). */
double bench_naive_frames(const pb_asset *l, const float *weight_sets, uint32_t frames, double *diff)
{
    const mk_asset *a = &l->asset;
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    if (mk_read_blob(a, &raw, &err)) {
        fprintf(stderr, "bench: %s\n", err.message);
        exit(1);
    }
    /* Which targets are ever active: only those get dense arrays (memory). Targets are
     * numbered across the asset, channel by channel, as in the blob. */
    uint32_t *first_target = calloc(raw.channel_count + 1u, sizeof *first_target);
    if (!first_target) {
        fprintf(stderr, "bench: out of memory\n");
        exit(1);
    }
    for (uint32_t c = 0; c < raw.channel_count; c++)
        first_target[c + 1] = first_target[c] + raw.channels[c].target_count;
    double total = 0;
    *diff = 0;
    for (uint32_t mi = 0; mi < raw.mesh_count; mi++) {
        const mk_raw_mesh *m = &raw.meshes[mi];
        size_t n = m->vertex_count;
        /* Dense arrays per asset target (indexed like the blob's target table). */
        float **dense_p = calloc(a->target_count + 1u, sizeof(float *));
        float **dense_n = calloc(a->target_count + 1u, sizeof(float *));
        float *out_p = malloc(12 * n), *out_n = malloc(12 * n);
        mk_mesh_info info;
        mk_mesh_get(a, mi, &info);
        for (uint32_t c = info.first_channel; c < info.first_channel + info.channel_count; c++) {
            int ever = 0;
            for (uint32_t f = 0; f < frames; f++) ever |= weight_sets[(size_t)f * a->channel_count + c] != 0;
            if (!ever) continue;
            const mk_raw_channel *ch = &raw.channels[c];
            for (uint32_t k = 0; k < ch->target_count; k++) {
                const mk_raw_target *t = &ch->targets[k];
                float *dp = calloc(3 * n, sizeof(float)), *dn = calloc(3 * n, sizeof(float));
                for (uint32_t j = 0; j < t->count; j++)
                    for (int d = 0; d < 3; d++) {
                        dp[3 * (size_t)t->indices[j] + (size_t)d] = t->positions[3 * (size_t)j + (size_t)d];
                        if (t->normals)
                            dn[3 * (size_t)t->indices[j] + (size_t)d] = t->normals[3 * (size_t)j + (size_t)d];
                    }
                dense_p[first_target[c] + k] = dp;
                dense_n[first_target[c] + k] = dn;
            }
        }
        double best = INFINITY;
        for (int pass = 0; pass < BENCH_PASSES; pass++) {
            double t0 = bench_now_ns();
            for (uint32_t f = 0; f < frames; f++) {
                const float *w = weight_sets + (size_t)f * a->channel_count;
                memcpy(out_p, m->positions, 12 * n);
                if (m->normals) memcpy(out_n, m->normals, 12 * n);
                for (uint32_t c = info.first_channel; c < info.first_channel + info.channel_count; c++) {
                    if (w[c] == 0) continue;
                    int32_t ia, ib;
                    float ca, cb;
                    pb_channel_span(a, c, w[c], &ia, &ca, &ib, &cb);
                    for (int side = 0; side < 2; side++) {
                        int32_t k = side ? ib : ia;
                        float coef = side ? cb : ca;
                        if (k < 0 || !dense_p[first_target[c] + (uint32_t)k]) continue;
                        const float *dp = dense_p[first_target[c] + (uint32_t)k],
                                    *dn = dense_n[first_target[c] + (uint32_t)k];
                        for (size_t i = 0; i < 3 * n; i++) out_p[i] += coef * dp[i];
                        if (m->normals)
                            for (size_t i = 0; i < 3 * n; i++) out_n[i] += coef * dn[i];
                    }
                }
                if (m->normals)
                    for (size_t v = 0; v < n; v++) {
                        float *q = &out_n[3 * v];
                        float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                        if (len > 1e-8f) {
                            q[0] /= len;
                            q[1] /= len;
                            q[2] /= len;
                        }
                    }
            }
            double t = (bench_now_ns() - t0) / frames;
            if (t < best) best = t;
        }
        total += best;
        /* Check: the last frame against the runtime. */
        float *rp = malloc(12 * n), *rn = malloc(12 * n);
        if (pb_eval_mesh(a, mi, weight_sets + (size_t)(frames - 1) * a->channel_count, MK_STACKING_ADDITIVE,
                         MK_NORMALS_NLERP, rp, m->normals ? rn : NULL, &err) == MK_OK)
            for (size_t i = 0; i < 3 * n; i++) {
                double d = fabs((double)rp[i] - out_p[i]);
                if (d > *diff) *diff = d;
            }
        free(rp);
        free(rn);
        for (uint32_t k = 0; k < a->target_count; k++) {
            free(dense_p[k]);
            free(dense_n[k]);
        }
        free(dense_p);
        free(dense_n);
        free(out_p);
        free(out_n);
    }
    free(first_target);
    mk_raw_free(&raw);
    return total;
}

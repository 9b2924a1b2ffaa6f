/* SPDX-License-Identifier: MIT */
/* Prints one hash of everything the runtime computes for the given blobs: every clip sampled at
 * 17 times, and 8 weight sets per mesh (weights in [-1.5, 2.5], crossing in-betweens) evaluated
 * with both stackings and both normal modes, positions, normals and tangents, over the whole
 * mesh and a range starting mid-block, and surface normals and tangents from those positions. The flag-matrix test builds this and the runtime with
 * many compilers and flags and expects the same hash from every build.
 * usage: determinism_driver BLOB...   (runtime only: libc and morphkit.h) */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "morphkit.h"

static uint64_t fnv(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

static void *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    void *p = aligned_alloc(16, ((size_t)n + 15) / 16 * 16);
    if (p && fread(p, 1, (size_t)n, f) != (size_t)n) { free(p); p = NULL; }
    fclose(f);
    *size = (size_t)n;
    return p;
}

int main(int argc, char **argv)
{
    uint64_t h = 14695981039346656037ull;
    for (int i = 1; i < argc; i++) {
        size_t size;
        void *blob = read_all(argv[i], &size);
        mk_asset a;
        mk_error err;
        if (!blob || mk_asset_open(blob, size, &a, &err) != MK_OK) {
            fprintf(stderr, "%s: cannot open\n", argv[i]);
            return 1;
        }
        float *w = calloc(a.channel_count + 1, sizeof(float));
        for (uint32_t c = 0; c < a.clip_count; c++) {
            mk_clip_info ci;
            mk_clip_get(&a, c, &ci);
            for (int k = 0; k < 17; k++) {
                mk_sample_job s = { .asset = &a, .clip = c, .time = ci.start + ci.duration * k / 16.0 - 0.01,
                                    .weights = w, .weight_count = a.channel_count };
                if (mk_sample_run(&s, &err) != MK_OK) return 1;
                h = fnv(h, w, a.channel_count * sizeof(float));
            }
        }
        uint64_t rng = 88172645463325252ull;
        for (uint32_t mi = 0; mi < a.mesh_count; mi++) {
            mk_mesh_info m;
            mk_mesh_get(&a, mi, &m);
            size_t n = m.vertex_count;
            float *out = calloc(n * 10 + 4, sizeof(float));
            size_t scratch_size = mk_eval_scratch_size(&a, mi);
            void *scratch = aligned_alloc(16, (scratch_size + 31) / 16 * 16);
            size_t topology_size = mk_surface_topology_size(&a, mi);
            void *topology = topology_size ? aligned_alloc(16, (topology_size + 15) / 16 * 16) : NULL;
            size_t surface_scratch_size = mk_surface_scratch_size(&a, mi);
            void *surface_scratch = topology_size ? aligned_alloc(16, (surface_scratch_size + 15) / 16 * 16) : NULL;
            if (topology && mk_surface_topology_build(&a, mi, topology, topology_size, &err) != MK_OK) {
                fprintf(stderr, "%s\n", err.message);
                return 1;
            }
            for (int set = 0; set < 8; set++) {
                for (uint32_t c = 0; c < m.channel_count; c++) {
                    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
                    w[m.first_channel + c] = -1.5f + 4.0f * (float)(rng >> 40) / (float)(1u << 24);
                }
                for (int mode = 0; mode < 4; mode++)
                    for (int range = 0; range < 2; range++) {
                        uint32_t first = range ? (uint32_t)(n / 3) | 1u : 0;
                        if (first >= n) continue;
                        mk_eval_job j = {
                            .asset = &a, .mesh = mi, .first_vertex = first, .vertex_count = MK_VERTICES_TO_END,
                            .weights = w + m.first_channel, .weight_count = m.channel_count,
                            .stacking = (mode & 1) ? MK_STACKING_SEQUENTIAL : MK_STACKING_ADDITIVE,
                            .normal_mode = (mode & 2) ? MK_NORMALS_SLERP : MK_NORMALS_NLERP,
                            .scratch = scratch, .scratch_size = scratch_size,
                            .positions = out, .positions_stride = 40, .positions_size = 40 * n,
                            .normals = m.has_normals ? out + 3 : NULL, .normals_stride = 40, .normals_size = 40 * n,
                            .tangents = m.has_tangents ? out + 6 : NULL, .tangents_stride = 40, .tangents_size = 40 * n,
                        };
                        memset(out, 0, 40 * n);
                        if (mk_eval_run(&j, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
                        h = fnv(h, out, 40 * (n - first));
                        /* Surface normals (and tangents) from the whole mesh's positions, two ranges. */
                        if (range == 0 && topology) {
                            float *sn = calloc(n * 7 + 4, sizeof(float));
                            for (int part = 0; part < 2; part++) {
                                uint32_t from = part ? (uint32_t)(n / 3) | 1u : 0;
                                if (from >= n) continue;
                                mk_surface_job sj = {
                                    .asset = &a, .mesh = mi, .topology = topology, .topology_size = topology_size,
                                    .positions = out, .positions_stride = 40, .positions_size = 40 * n,
                                    .first_vertex = from, .vertex_count = part ? MK_VERTICES_TO_END : (uint32_t)(n / 3) | 1u,
                                    .normals = sn + 3 * (size_t)from, .normals_size = 12 * (n - from),
                                    .tangents = m.has_tangents ? sn + 3 * n + 4 * (size_t)from : NULL,
                                    .tangents_size = 16 * (n - from),
                                    .scratch = surface_scratch, .scratch_size = surface_scratch_size,
                                };
                                if (sj.vertex_count != MK_VERTICES_TO_END && sj.vertex_count > n) sj.vertex_count = (uint32_t)n;
                                if (mk_surface_run(&sj, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
                            }
                            h = fnv(h, sn, 28 * n);
                            free(sn);
                        }
                    }
            }
            free(out);
            free(scratch);
            free(topology);
            free(surface_scratch);
        }
        free(w);
        free(blob);
    }
    printf("%016llx\n", (unsigned long long)h);
    return 0;
}

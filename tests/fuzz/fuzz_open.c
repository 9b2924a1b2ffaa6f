/* SPDX-License-Identifier: MIT */
/* libFuzzer target: mk_asset_open on a .morph blob, then, if it opens, every query, sampling of
 * every clip and evaluation of every mesh (normals, tangents, both normal modes, both stackings,
 * a vertex sub-range, strided outputs). Any crash, overread or UB is a bug.
 *
 * Inputs are plain blobs (make_seeds writes them from the fixtures, baked assets and the shared
 * corpus); a crashing input is itself a blob (`morphkit info` opens it). Nearly every mutation
 * of a blob fails its checksum, so the fuzzer would never get past it: this fuzzing-only
 * LLVMFuzzerCustomMutator lets libFuzzer mutate (any of its mutations, crossover included), then
 * rewrites the header's file size and checksum to match the mutated bytes -- except in one
 * mutation of 16 each, so the file-size and checksum checks stay exercised too. The runtime's
 * checks are the same as in every build. */
#include <stdlib.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
size_t LLVMFuzzerMutate(uint8_t *data, size_t size, size_t max_size);
size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed);

size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed)
{
    size = LLVMFuzzerMutate(data, size, max_size);
    if (size >= sizeof(mk_blob_header)) {
        if (seed % 16 != 0) {
            uint64_t file_size = size;
            memcpy(data + 16, &file_size, 8);
        }
        if (seed / 16 % 16 != 0) {
            uint64_t sum = mk_checksum(data + 32, size - 32);
            memcpy(data + 24, &sum, 8);
        }
    }
    return size;
}

enum { MAX_VERTICES = 1 << 16, MAX_CHANNELS = 1 << 16 };

static void use(const mk_asset *a)
{
    volatile size_t sink = 0;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        if (mk_mesh_get(a, i, &m)) sink += strlen(m.name);
    }
    for (uint32_t i = 0; i < a->channel_count; i++) {
        mk_channel_info ch;
        if (!mk_channel_get(a, i, &ch)) continue;
        sink += strlen(ch.name) + strlen(ch.origin);
        mk_target_info t;
        if (mk_target_get(a, i, ch.target_count - 1, &t)) sink += strlen(t.name);
    }
    for (uint32_t i = 0; i < a->clip_count; i++) {
        mk_clip_info c;
        if (mk_clip_get(a, i, &c)) sink += strlen(c.name);
        const mk_key *keys;
        uint32_t channel, key_count;
        if (c.track_count && mk_track_get(a, i, c.track_count - 1, &channel, &keys, &key_count))
            sink += (size_t)keys[key_count - 1].interp + channel;
    }
    if (a->mesh_count) sink += (size_t)mk_find_mesh(a, "a");
    if (a->channel_count) sink += (size_t)mk_find_channel(a, "a") + mk_find_channels(a, "a", NULL, 0);
    if (a->clip_count) sink += (size_t)mk_find_clip(a, "a");
    (void)sink;

    /* Buffers of exactly the sizes the asset asks for, so ASan sees a write past them too. */
    if (a->channel_count > MAX_CHANNELS) return;
    float *weights = malloc(a->channel_count ? a->channel_count * sizeof(float) : 1);
    if (!weights) return;
    for (uint32_t c = 0; c < a->clip_count; c++)
        for (int loop = 0; loop < 2; loop++) {
            uint32_t tracks = a->clips[c].track_count;
            uint32_t *cursors = tracks && tracks <= 4096 ? calloc(tracks, sizeof *cursors) : NULL;
            mk_sample_job s = { .asset = a, .clip = c, .time = loop ? 7.3f : 0.5f, .weights = weights,
                                .weight_count = a->channel_count, .loop = loop, .cursors = cursors,
                                .cursor_count = tracks };
            mk_sample_run(&s, NULL);
            free(cursors);
        }

    for (uint32_t c = 0; c < a->channel_count; c++) weights[c] = (float)(c % 5) * 0.6f - 1.1f;
    for (uint32_t m = 0; m < a->mesh_count; m++) {
        mk_mesh_info info;
        mk_mesh_get(a, m, &info);
        size_t scratch_size = mk_eval_scratch_size(a, m);
        if (info.vertex_count > MAX_VERTICES || scratch_size > (1u << 20)) continue;
        size_t packed = 12 * (size_t)info.vertex_count, wide = 16 * (size_t)info.vertex_count;
        float *out = malloc(wide), *out_n = malloc(wide), *out_t = malloc(wide);
        void *scratch = NULL;
        if (!out || !out_n || !out_t || posix_memalign(&scratch, 16, scratch_size) != 0) {
            free(out); free(out_n); free(out_t);
            continue;
        }
        for (int pass = 0; pass < 3; pass++) {
            /* pass 0: the whole mesh, packed, the asset's stacking; 1: slerp normals, sequential
             * stacking, 16-byte strided outputs; 2: a sub-range, additive. */
            uint32_t first = pass == 2 ? info.vertex_count / 3 : 0;
            size_t stride = pass == 1 ? 16 : 0, size = pass == 1 ? wide : packed;
            mk_eval_job j = { .asset = a, .mesh = m, .first_vertex = first,
                              .vertex_count = pass == 2 ? info.vertex_count / 2 : MK_VERTICES_TO_END,
                              .weights = weights + info.first_channel, .weight_count = info.channel_count,
                              .stacking = pass == 1 ? MK_STACKING_SEQUENTIAL : pass == 2 ? MK_STACKING_ADDITIVE : MK_STACKING_ASSET,
                              .normal_mode = pass == 1 ? MK_NORMALS_SLERP : MK_NORMALS_NLERP,
                              .scratch = scratch, .scratch_size = scratch_size,
                              .positions = out, .positions_size = size, .positions_stride = stride,
                              .normals = info.has_normals ? out_n : NULL, .normals_size = size, .normals_stride = stride,
                              .tangents = info.has_tangents ? out_t : NULL, .tangents_size = wide };
            mk_eval_run(&j, NULL);
        }
        free(out);
        free(out_n);
        free(out_t);
        free(scratch);
    }
    free(weights);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* An allocation of exactly the blob's size, 16-aligned: ASan sees any read past it. */
    uint8_t *blob = NULL;
    if (posix_memalign((void **)&blob, 16, size ? size : 1) != 0) return 0;
    if (size) memcpy(blob, data, size);
    mk_asset a;
    mk_error err;
    if (mk_asset_open(blob, size, &a, &err) == MK_OK) use(&a);
    else if (err.message[0] == 0) abort();   /* errors always say what went wrong */
    free(blob);
    return 0;
}

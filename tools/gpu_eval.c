/* SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "gpu_eval.h"
#if MK_HAVE_GPU
#include "harness.h"

struct cli_gpu {
    mkg_harness h;
    /* The asset uploaded last, known by the caller's mk_asset, its blob and the blob's checksum:
     * a caller that frees an asset and loads another at the same addresses (conform, case after
     * case) gets a fresh upload. */
    const mk_asset *asset;
    const uint8_t *data;
    size_t size;
    uint64_t checksum;
    mkg_asset *uploaded;
};

static uint64_t blob_checksum(const mk_asset *a)
{
    uint64_t c;
    memcpy(&c, a->data + 24, sizeof c);   /* the header's checksum field (docs/format.md) */
    return c;
}

static mk_result uploaded(cli_gpu *g, const mk_asset *a, mkg_asset **out, mk_error *err)
{
    if (g->uploaded && g->asset == a && g->data == a->data && g->size == a->size && g->checksum == blob_checksum(a)) {
        *out = g->uploaded;
        return MK_OK;
    }
    mkg_asset_destroy(g->uploaded);
    g->uploaded = NULL;
    mk_result r = mkg_asset_upload(g->h.ctx, a, g->h.queue, g->h.family, out, err);
    if (r != MK_OK) return r;
    g->asset = a;
    g->data = a->data;
    g->size = a->size;
    g->checksum = blob_checksum(a);
    g->uploaded = *out;
    return MK_OK;
}

static mk_result gpu_eval(void *user, const mk_asset *a, uint32_t mesh, const float *weights, mk_stacking stacking,
                          mk_normal_mode mode, float *positions, float *normals, float *tangents, mk_error *err)
{
    cli_gpu *g = user;
    mkg_asset *ga;
    mk_result r = uploaded(g, a, &ga, err);
    if (r != MK_OK) return r;
    mk_mesh_info m;
    mk_mesh_get(a, mesh, &m);
    return mkg_harness_eval(&g->h, ga, mesh, weights + m.first_channel, m.channel_count, stacking, mode, positions,
                            normals, tangents, err);
}

mk_result cli_gpu_open(cli_gpu **out, pb_evaluator *evaluator, int quiet, mk_error *err)
{
    cli_gpu *g = calloc(1, sizeof *g);
    if (!g) return mk_error_oom(err, "GPU device");
    const char *v = getenv("MORPHKIT_VK_VALIDATION");
    mk_result r = mkg_harness_open(&g->h, v && strcmp(v, "1") == 0 ? MKG_HARNESS_REQUIRE_VALIDATION : 0, err);
    if (r != MK_OK) {
        free(g);
        return r;
    }
    if (!quiet) fprintf(stderr, "morphkit: GPU path on %s\n", g->h.props.deviceName);
    *out = g;
    *evaluator = (pb_evaluator){ gpu_eval, g };
    return MK_OK;
}

struct mkg_harness *cli_gpu_harness(cli_gpu *g) { return &g->h; }

int cli_gpu_close(cli_gpu *g)
{
    if (!g) return 0;
    mkg_asset_destroy(g->uploaded);
    mkg_harness_close(&g->h);
    unsigned messages = g->h.validation_messages;
    if (messages) fprintf(stderr, "morphkit: the Vulkan validation layer reported %u messages\n", messages);
    free(g);
    return messages != 0;
}

#else

mk_result cli_gpu_open(cli_gpu **out, pb_evaluator *evaluator, int quiet, mk_error *err)
{
    (void)quiet;
    *out = NULL;
    memset(evaluator, 0, sizeof *evaluator);
    return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                        "this morphkit was built without the GPU path (it needs libvulkan, glslc and spirv-cross: "
                        "./scripts/install-deps, then meson setup -Dgpu=enabled)");
}

int cli_gpu_close(cli_gpu *g)
{
    (void)g;
    return 0;
}

struct mkg_harness *cli_gpu_harness(cli_gpu *g)
{
    (void)g;
    return NULL;
}

#endif

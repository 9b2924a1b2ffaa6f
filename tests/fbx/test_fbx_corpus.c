/* SPDX-License-Identifier: MIT */
/* FBX import against the shared corpus: every "fbx" case of cases.json is imported, written as
 * a float blob and checked frame by frame with the conformance check `morphkit conform` uses
 * (playback/conform.c: the static state for "time": null, the first stack otherwise; world
 * space; per control point; case tolerance plus float32 rounding), and facts the frames do not
 * show (names, in-between order), and the same blob on any thread count. SKIPs when the corpus is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "corpus_cases.h"
#include "conform.h"
#include "fbx_test_util.h"

static void test_corpus_frames(void)
{
    char path[4200];
    pb_manifest manifest;
    mk_error err;
    CHECK_CORPUS_MANIFEST(&manifest);
    double worst = 0, worst_weight = 0;
    int cases = 0, frames = 0;
    mk_write_options wo = { .precision = MK_PRECISION_FLOAT };
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        const pb_case *c = &manifest.cases[i];
        if (c->gltf) continue;
        cases++;
        pb_manifest_path(&manifest, c->source, path, sizeof path);
        pb_asset asset;
        mk_result r = pb_asset_load(path, NULL, &wo, &asset, &err);
        CHECK_MSG(r == MK_OK, "%s: import failed: %s", c->name, err.message);
        for (uint32_t k = 0; r == MK_OK && k < c->frame_count; k++) {
            pb_frame_result res;
            pb_conform_frame(&manifest, c, &c->frames[k], &asset, NULL, &res);
            CHECK_MSG(res.passed, "%s %s: position error %g (allowed %g), weight error %g%s%s", c->name, c->frames[k].file,
                      res.position_error, res.allowed, res.weight_error, res.failure[0] ? ": " : "", res.failure);
            if (res.position_error > worst) worst = res.position_error;
            if (res.weight_error > worst_weight) worst_weight = res.weight_error;
            frames++;
        }
        pb_asset_free(&asset);
    }
    CHECK(cases > 0);
    fprintf(stderr, "fbx corpus: %d cases, %d frames, worst position error %.3g, worst weight error %.3g\n", cases, frames,
            worst, worst_weight);
    pb_manifest_free(&manifest);
}

/* Facts the frames do not show: names, in-between order, quirks. */
static void test_corpus_structure(void)
{
    const char *corpus = check_corpus_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/fbx/maya_blend_inbetween_7500_ascii.fbx", corpus);
    size_t size;
    unsigned char *data = check_read_file(path, &size);
    if (!data) SKIP("corpus not found at %s", corpus);
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    free(data);
    CHECK_EQ_INT(raw.mesh_count, 1);
    CHECK(raw.mesh_count && strcmp(raw.meshes[0].name, "pCube1") == 0);
    CHECK_EQ_INT(raw.channel_count, 2);
    if (raw.channel_count == 2) {
        /* In-betweens sorted by full weight, negative ones first (FullWeights in connection order). */
        const mk_raw_channel *lift = &raw.channels[0], *side = &raw.channels[1];
        CHECK(strcmp(lift->name, "KeyBlend.LiftTop") == 0);
        CHECK(strcmp(side->name, "KeyBlend.MoveToSide") == 0);
        CHECK_EQ_INT(lift->target_count, 2);
        CHECK_EQ_INT(side->target_count, 3);
        if (lift->target_count == 2) {
            CHECK_NEAR(lift->targets[0].full_weight, 0.5, 1e-6);
            CHECK_NEAR(lift->targets[1].full_weight, 1.0, 1e-6);
        }
        if (side->target_count == 3) {
            CHECK_NEAR(side->targets[0].full_weight, -0.499, 1e-6);
            CHECK_NEAR(side->targets[1].full_weight, -0.249, 1e-6);
            CHECK_NEAR(side->targets[2].full_weight, 1.0, 1e-6);
        }
    }
    CHECK_EQ_INT(raw.clip_count, 1);
    if (raw.clip_count == 1) CHECK_EQ_INT(raw.clips[0].track_count, 2);
    CHECK(strncmp(raw.source_format, "fbx 7500 ascii", 14) == 0);
    CHECK(strstr(raw.source_creator, "FBX SDK") != NULL);
    CHECK_EQ_INT(raw.up_axis, 1);
    mk_raw_free(&raw);
}

/* Target normals, quantization and block layout run on worker threads: every FBX case gives
 * the same blob bytes on 1 and on 4 threads. */
static void test_corpus_thread_count(void)
{
    char path[4200];
    pb_manifest manifest;
    mk_error err;
    CHECK_CORPUS_MANIFEST(&manifest);
    int compared = 0;
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        const pb_case *c = &manifest.cases[i];
        if (c->gltf) continue;
        pb_manifest_path(&manifest, c->source, path, sizeof path);
        size_t size;
        unsigned char *data = check_read_file(path, &size);
        CHECK_MSG(data != NULL, "%s: cannot read %s", c->name, path);
        if (!data) continue;
        void *blob[2] = { NULL, NULL };
        size_t blob_size[2] = { 0, 0 };
        mk_raw_asset raw[2];
        for (int k = 0; k < 2; k++) {
            mk_import_options io = { .threads = k ? 4 : 1 };
            mk_write_options wo = { .precision = MK_PRECISION_Q16, .threads = k ? 4 : 1 };
            mk_result r = ft_import(data, size, &io, &raw[k], &err);
            if (r == MK_OK) r = mk_write_blob(&raw[k], &wo, &raw[k].arena, &blob[k], &blob_size[k], NULL, &err);
            CHECK_MSG(r == MK_OK, "%s: %s", c->name, err.message);
        }
        if (blob[0] && blob[1]) {
            CHECK_MSG(blob_size[0] == blob_size[1] && memcmp(blob[0], blob[1], blob_size[0]) == 0,
                      "%s: the blob differs between 1 and 4 threads", c->name);
            compared++;
        }
        for (int k = 0; k < 2; k++) mk_raw_free(&raw[k]);
        free(data);
    }
    CHECK(compared > 0);
    pb_manifest_free(&manifest);
}

CHECK_MAIN(CASE(test_corpus_frames), CASE(test_corpus_structure), CASE(test_corpus_thread_count))

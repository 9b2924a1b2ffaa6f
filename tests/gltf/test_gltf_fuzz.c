/* SPDX-License-Identifier: MIT */
/* Regression run of the glTF importer with the fuzz target's settings (tests/fuzz/fuzz_gltf.c)
 * over the corpus: every glTF/GLB file whole, truncated at a spread of lengths, and with random
 * byte flips. Each input either imports to a model that validates, or fails with a valid code
 * and a message; ASan/UBSan catch the rest. Each input also goes through the fuzz target's own
 * function (linked in), which writes an accepted import back with a made-up baked channel per
 * mesh and re-imports the output (it aborts on a failure). The whole files must import (their damaged copies
 * are measured against that). .gltf files with external buffers fail early from memory (no
 * base directory), so their JSON parsing is what gets exercised; GLB files exercise everything. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "gltf_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
extern unsigned long fuzz_gltf_written, fuzz_gltf_refused;

static const char *files[] = {
    "gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf",
    "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.draco.glb",
    "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.gltfpack-c.glb",
    "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.meshopt.glb",
    "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.quantized.glb",
    "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.sparse.glb",
    "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.draco.glb",
    "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.gltfpack-c.glb",
    "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.meshopt.glb",
    "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.quantized.glb",
    "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.sparse.glb",
    "gltf/MorphStressTest/variants/MorphStressTest.draco.glb",
    "gltf/MorphStressTest/variants/MorphStressTest.gltfpack-c.glb",
    "gltf/MorphStressTest/variants/MorphStressTest.meshopt.glb",
    "gltf/SimpleMorph/variants/SimpleMorph.draco.glb",
    "gltf/SimpleMorph/variants/SimpleMorph.gltfpack-c.glb",
    "gltf/SimpleMorph/variants/SimpleMorph.meshopt.glb",
    "gltf/SimpleMorph/variants/SimpleMorph.quantized.glb",
    "gltf/SimpleMorph/variants/SimpleMorph.sparse.glb",
    "gltf/tinygltf-SparseMorphTargets-issue280/singleBlendshapeCube_sparse.glb",
};

static uint64_t state = 0x2545f4914f6cdd1dull;
static uint32_t next(void)
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return (uint32_t)state;
}

/* One input with the fuzz target's limits: 1 when it imported. */
static int import_checked(const unsigned char *data, size_t size)
{
    mk_raw_asset raw;
    mk_allocator limit = { 0 };
    limit.memory_limit = (size_t)256 << 20;
    mk_raw_init(&raw, &limit);
    mk_import_options options = { .max_input_size = (size_t)64 << 20 };
    mk_error err;
    memset(&err, 0, sizeof err);
    mk_result r = mk_import_gltf(data, size, &options, &raw, &err);
    if (r == MK_OK) {
        mk_error verr;
        CHECK_MSG(mk_raw_validate(&raw, &verr) == MK_OK, "an imported model does not validate: %s", verr.message);
    } else {
        CHECK_MSG(r > MK_OK && r < MK_RESULT_COUNT && err.message[0] != 0 && err.code == r,
                  "a failure without a valid code and message (%d)", (int)r);
    }
    mk_raw_free(&raw);
    LLVMFuzzerTestOneInput(data, size);
    return r == MK_OK;
}

static void test_fuzz_seeds(void)
{
    const char *corpus = check_corpus_dir();
    int found = 0, runs = 0;
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", corpus, files[i]);
        size_t size;
        unsigned char *data = check_read_file(path, &size);
        if (!data) continue;
        found++;
        unsigned char *copy = malloc(size + 1);
        /* The whole GLB files import (.gltf files need their folder, absent from memory). */
        unsigned long written = fuzz_gltf_written;
        int whole = import_checked(data, size);
        if (strstr(files[i], ".glb")) {
            CHECK_MSG(whole, "%s does not import from memory", files[i]);
            CHECK_MSG(fuzz_gltf_written == written + 1, "%s is not written back by the fuzz target", files[i]);
        }
        size_t step = size / 200 + 1;
        for (size_t n = 0; n <= size; n += step) {
            memcpy(copy, data, n);
            import_checked(copy, n);
            runs++;
        }
        for (int k = 0; k < 200; k++) {
            memcpy(copy, data, size);
            int flips = 1 + (int)(next() % 8);
            for (int f = 0; f < flips; f++) copy[next() % size] ^= (unsigned char)(1u << (next() % 8));
            import_checked(copy, size);
            runs++;
        }
        free(copy);
        free(data);
    }
    if (!found) SKIP("corpus not found at %s", corpus);
    printf("  %d inputs from %d seed files; the fuzz target wrote %lu back and re-imported them, refused %lu\n", runs, found,
           fuzz_gltf_written, fuzz_gltf_refused);
}

CHECK_MAIN(CASE(test_fuzz_seeds))

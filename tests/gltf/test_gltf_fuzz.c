/* SPDX-License-Identifier: MIT */
/* Regression run of the glTF fuzz target (tests/fuzz/fuzz_gltf.c) over the corpus: every
 * glTF/GLB file whole, truncated at a spread of lengths, and with random byte flips. The
 * target aborts when a failure has no message; ASan/UBSan catch the rest. .gltf files with
 * external buffers fail early from memory (no base directory), so their JSON parsing is what
 * gets exercised; GLB files exercise everything. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "../fuzz/fuzz_gltf.c"

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
        size_t step = size / 200 + 1;
        for (size_t n = 0; n <= size; n += step) {
            memcpy(copy, data, n);
            CHECK(LLVMFuzzerTestOneInput(copy, n) == 0);
            runs++;
        }
        for (int k = 0; k < 200; k++) {
            memcpy(copy, data, size);
            int flips = 1 + (int)(next() % 8);
            for (int f = 0; f < flips; f++) copy[next() % size] ^= (unsigned char)(1u << (next() % 8));
            CHECK(LLVMFuzzerTestOneInput(copy, size) == 0);
            runs++;
        }
        free(copy);
        free(data);
    }
    if (!found) SKIP("corpus not found at %s", corpus);
    printf("  %d inputs from %d seed files\n", runs, found);
}

CHECK_MAIN(CASE(test_fuzz_seeds))

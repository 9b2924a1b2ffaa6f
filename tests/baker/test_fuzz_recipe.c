/* SPDX-License-Identifier: MIT */
/* The recipe fuzz target (tests/fuzz/fuzz_recipe.c) as a plain regression test: every sample
 * recipe, all its truncations and single-byte flips must give a result or a clean error. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const seeds[] = { "twist.json", "barr.json", "ffd.json", "cage.json", "laplacian.json",
                                     "ffd_travel.json", "ffd_keys.json", "ffd_cylinder.json", "ffd_prism.json",
                                     "shell.json" };

static void sample_recipes_truncated_and_flipped(void)
{
    const char *root = getenv("MORPHKIT_SOURCE_ROOT");
    if (!root) root = MK_SOURCE_ROOT;
    int inputs = 0;
    for (size_t s = 0; s < sizeof seeds / sizeof seeds[0]; s++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/samples/recipes/%s", root, seeds[s]);
        size_t size = 0;
        unsigned char *data = check_read_file(path, &size);
        CHECK_MSG(data != NULL, "missing seed %s", path);
        if (!data) continue;
        unsigned char *copy = malloc(size + 1);
        for (size_t n = 0; n <= size; n += (size > 400 ? 3 : 1), inputs++)
            LLVMFuzzerTestOneInput(data, n);
        srand(11);
        for (int k = 0; k < 300; k++, inputs++) {
            memcpy(copy, data, size);
            size_t at = (size_t)rand() % size;
            copy[at] = (unsigned char)(k % 3 == 0 ? (unsigned char)(copy[at] ^ (1u << (rand() % 8))) : (unsigned char)"{}[],:\"0-e9.aN "[rand() % 16]);
            LLVMFuzzerTestOneInput(copy, size);
        }
        free(copy);
        free(data);
    }
    fprintf(stderr, "%d recipe inputs ran without a crash\n", inputs);
    CHECK(inputs > 1000);
}

CHECK_MAIN(CASE(sample_recipes_truncated_and_flipped))

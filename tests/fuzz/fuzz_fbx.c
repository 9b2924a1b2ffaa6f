/* SPDX-License-Identifier: MIT */
/* libFuzzer target for the FBX importer (binary and ASCII): any input must give an error or
 * a raw model that passes mk_raw_validate, never a crash, hang or out-of-bounds access.
 * tests/fbx/test_fbx_hostile.c links this same function and runs it over every truncation and
 * random byte flips of the corpus files and of writer-made fixtures. Seeds: the corpus FBX
 * files and `test_fbx_writer --write-seeds DIR`. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fbx_import.h"
#include "import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* A memory limit keeps hostile size claims from exhausting the fuzzer's RSS budget. */
    mk_allocator allocator;
    memset(&allocator, 0, sizeof allocator);
    allocator.memory_limit = (size_t)256 << 20;
    mk_raw_asset raw;
    mk_raw_init(&raw, &allocator);
    mk_error err;
    mk_import_options options;
    memset(&options, 0, sizeof options);
    if (mk_import_fbx(data, size, &options, &raw, &err) == MK_OK) {
        if (mk_raw_validate(&raw, &err) != MK_OK) {  /* an accepted import must be valid */
            fprintf(stderr, "fuzz_fbx: import accepted an invalid model: %s\n", err.message);
            abort();
        }
    } else if (err.message[0] == 0) {
        abort();  /* errors always say what went wrong */
    }
    mk_raw_free(&raw);
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* libFuzzer target for the FBX importer (binary and ASCII): any input must give an error or
 * a raw model that passes mk_raw_validate, never a crash, hang or out-of-bounds access.
 * An accepted file is then written back (formats/fbx_write) with one made-up baked channel per
 * mesh (control point 0 moved), and a written file must import again, valid, with those
 * channels added; a refusal must say why.
 * tests/fbx/test_fbx_hostile.c links this same function and runs it over every truncation and
 * random byte flips of the corpus files and of writer-made fixtures. Seeds: the corpus FBX
 * files and `test_fbx_writer --write-seeds DIR`. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fbx_import.h"
#include "fbx_write.h"
#include "import.h"
#include "fuzz_baked.h"

static void write_back(const uint8_t *data, size_t size, mk_raw_asset *raw)
{
    const uint32_t before = raw->channel_count;
    const uint32_t added = fuzz_add_baked_channels(raw);
    mk_error err;
    if (mk_raw_group_channels(raw, &err) != MK_OK) return;
    void *out = NULL;
    size_t out_size = 0;
    if (mk_fbx_write_back(data, size, raw, &raw->arena, &out, &out_size, NULL, &err) != MK_OK) {
        if (err.message[0] == 0) abort();  /* refusals say why */
        return;
    }
    mk_raw_asset again;
    mk_raw_init(&again, &raw->arena.allocator);
    mk_import_options options;
    memset(&options, 0, sizeof options);
    options.keep_plain_meshes = 1;
    mk_result r = mk_import_fbx(out, out_size, &options, &again, &err);
    if (r == MK_OK) r = mk_raw_validate(&again, &err);
    if (r != MK_OK && r != MK_ERROR_OUT_OF_MEMORY) {
        fprintf(stderr, "fuzz_fbx: the written-back file does not import: %s\n", err.message);
        abort();
    }
    if (r == MK_OK && again.channel_count != before + added) {
        fprintf(stderr, "fuzz_fbx: written back with %u channels, imported %u\n", before + added, again.channel_count);
        abort();
    }
    mk_raw_free(&again);
}

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
    options.keep_plain_meshes = 1;  /* as `morphkit bake` imports */
    if (mk_import_fbx(data, size, &options, &raw, &err) == MK_OK) {
        if (mk_raw_validate(&raw, &err) != MK_OK) {  /* an accepted import must be valid */
            fprintf(stderr, "fuzz_fbx: import accepted an invalid model: %s\n", err.message);
            abort();
        }
        write_back(data, size, &raw);
    } else if (err.message[0] == 0) {
        abort();  /* errors always say what went wrong */
    }
    mk_raw_free(&raw);
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* libFuzzer target for the glTF importer: arbitrary bytes as .gltf/.glb (external files are
 * refused when loading from memory, so only embedded/data-URI buffers are exercised). Every
 * input must either import to a model that passes mk_raw_validate or fail with a message;
 * never crash, hang or read out of bounds. The import is `morphkit bake`'s (plain meshes kept).
 * An accepted file is then written back (formats/gltf_writeback) with one made-up baked channel
 * per raw mesh (glTF vertex 0 moved, the same on every instance of a mesh), and a written file
 * must import again with the sidecar the write-back returned, valid, with those channels added;
 * a refusal must say why.
 * Build: clang with -fsanitize=fuzzer,address,undefined, linked with the importer and
 * write-back libraries (C++: tinygltf + libdraco, libmeshoptimizer, libcjson).
 * tests/gltf/test_gltf_fuzz.c links this same function and runs it over truncated and
 * byte-flipped corpus files as a regression test. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gltf_import.h"
#include "gltf_writeback.h"
#include "fuzz_baked.h"

/* Inputs written back and re-imported, and write-backs refused (tests/gltf/test_gltf_fuzz.c
 * reads them). */
extern unsigned long fuzz_gltf_written, fuzz_gltf_refused;
unsigned long fuzz_gltf_written, fuzz_gltf_refused;

static void write_back(const uint8_t *data, size_t size, mk_raw_asset *raw)
{
    const uint32_t before = raw->channel_count;
    const uint32_t added = fuzz_add_baked_channels(raw);
    mk_error err;
    err.message[0] = 0;
    if (mk_raw_group_channels(raw, &err) != MK_OK) return;
    void *out = NULL;
    char *sidecar = NULL;
    size_t out_size = 0, sidecar_size = 0;
    err.message[0] = 0;
    if (mk_gltf_write_back(data, size, NULL, NULL, raw, &raw->arena, &out, &out_size, &sidecar, &sidecar_size, NULL, &err) !=
        MK_OK) {
        if (err.message[0] == 0) abort();  /* refusals say why */
        if (getenv("FUZZ_GLTF_VERBOSE")) fprintf(stderr, "fuzz_gltf: refused: %s\n", err.message);
        fuzz_gltf_refused++;
        return;
    }
    if (added && !sidecar) {
        fprintf(stderr, "fuzz_gltf: %u channels written back without a channel sidecar\n", added);
        abort();
    }
    mk_raw_asset again;
    mk_raw_init(&again, &raw->arena.allocator);
    mk_import_options options;
    memset(&options, 0, sizeof options);
    options.keep_plain_meshes = 1;
    options.max_input_size = (size_t)64 << 20;
    options.channels_sidecar_text = sidecar;
    options.channels_sidecar_size = sidecar_size;
    mk_result r = mk_import_gltf(out, out_size, &options, &again, &err);
    if (r == MK_OK) r = mk_raw_validate(&again, &err);
    if (r != MK_OK && r != MK_ERROR_OUT_OF_MEMORY) {
        fprintf(stderr, "fuzz_gltf: the written-back file does not import: %s\n", err.message);
        abort();
    }
    if (r == MK_OK && (again.channel_count != before + added || again.mesh_count != raw->mesh_count)) {
        fprintf(stderr, "fuzz_gltf: written back %u meshes with %u channels, imported %u with %u\n", raw->mesh_count,
                before + added, again.mesh_count, again.channel_count);
        abort();
    }
    uint32_t baked = 0;   /* the sidecar gives the new channels back their origin */
    for (uint32_t c = 0; r == MK_OK && c < again.channel_count; c++) baked += again.channels[c].origin && again.channels[c].origin[0];
    if (r == MK_OK && baked != added) {
        fprintf(stderr, "fuzz_gltf: %u baked channels written back, %u re-imported as baked\n", added, baked);
        abort();
    }
    if (r == MK_OK) fuzz_gltf_written++;
    mk_raw_free(&again);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mk_raw_asset raw;
    mk_allocator limit;
    memset(&limit, 0, sizeof limit);
    limit.memory_limit = (size_t)256 << 20;   /* hostile counts must fail, not exhaust memory */
    mk_raw_init(&raw, &limit);
    mk_import_options options;
    memset(&options, 0, sizeof options);
    options.max_input_size = (size_t)64 << 20;
    options.keep_plain_meshes = 1;            /* as `morphkit bake` imports */
    mk_error err;
    err.message[0] = 0;
    mk_result r = mk_import_gltf(data, size, &options, &raw, &err);
    if (r == MK_OK) {
        if (mk_raw_validate(&raw, &err) != MK_OK) {  /* an accepted import must be valid */
            fprintf(stderr, "fuzz_gltf: import accepted an invalid model: %s\n", err.message);
            abort();
        }
        write_back(data, size, &raw);
    } else if (err.message[0] == 0) {
        abort();   /* an error must say what went wrong */
    }
    mk_raw_free(&raw);
    return 0;
}

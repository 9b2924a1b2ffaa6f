/* SPDX-License-Identifier: MIT */
/* libFuzzer target for the glTF importer: arbitrary bytes as .gltf/.glb (external files are
 * refused when loading from memory, so only embedded/data-URI buffers are exercised). Every
 * input must either import or fail with a message; never crash, hang or read out of bounds.
 * Build: clang with -fsanitize=fuzzer,address,undefined, linked with the importer library
 * (C++: tinygltf + libdraco, libmeshoptimizer, libcjson). tests/gltf/test_gltf_fuzz.c runs
 * this same function over truncated and byte-flipped corpus files as a regression test. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include "gltf_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mk_raw_asset raw;
    mk_allocator limit = {0};
    limit.memory_limit = (size_t)256 << 20;   /* hostile counts must fail, not exhaust memory */
    mk_raw_init(&raw, &limit);
    mk_import_options options = {0};
    options.max_input_size = (size_t)64 << 20;
    mk_error err;
    err.message[0] = 0;
    mk_result r = mk_import_gltf(data, size, &options, &raw, &err);
    if (r != MK_OK && err.message[0] == 0) abort();   /* an error must say what went wrong */
    mk_raw_free(&raw);
    return 0;
}

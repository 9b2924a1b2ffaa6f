/* SPDX-License-Identifier: MIT */
/* Hostile input: the fuzz target's function (tests/fuzz/fuzz_fbx.c, LLVMFuzzerTestOneInput)
 * over every truncation length and seeded random byte changes of
 *   - writer-made fixtures (binary 7400/7500 raw and zlib, big-endian 7100 raw and 7500 zlib
 *     with every property type, ASCII 7500/7100) — always run;
 *   - every FBX file of the shared corpus — SKIP when the corpus is absent.
 * Each input must give an error or a valid import (the target aborts otherwise); under
 * ASan/UBSan this also proves there is no out-of-bounds access. A hang shows up as the test
 * timeout. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fbx_fixtures.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint32_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 11);
}

/* Every prefix, then `flips` mutated copies (1..4 bytes replaced, sometimes by bytes that
 * matter to the parsers: 0, 0xff, digits, separators). */
static int hammer(const unsigned char *data, size_t size, int flips, size_t truncation_step)
{
    unsigned char *copy = malloc(size + 1);
    if (!copy) return 0;
    int runs = 0;
    for (size_t n = 0; n <= size; n += truncation_step) {
        /* A fresh allocation of exactly n bytes, so ASan sees reads past the end. */
        unsigned char *prefix = malloc(n ? n : 1);
        memcpy(prefix, data, n);
        LLVMFuzzerTestOneInput(prefix, n);
        free(prefix);
        runs++;
    }
    static const unsigned char interesting[] = { 0, 0xff, 0x7f, 0x80, '0', '9', '-', ',', '{', '}', '"', '*', ';', '\n', 1, 'd', 'i' };
    for (int f = 0; f < flips; f++) {
        memcpy(copy, data, size);
        int changes = 1 + (int)(rng() % 4);
        for (int c = 0; c < changes && size; c++) {
            size_t at = rng() % size;
            copy[at] = (rng() & 1) ? (unsigned char)rng() : interesting[rng() % sizeof interesting];
        }
        LLVMFuzzerTestOneInput(copy, size);
        runs++;
    }
    free(copy);
    return runs;
}

static void test_fixtures(void)
{
    static const struct { uint32_t version; int binary, compress, big_endian; } forms[] = {
        { 7400, 1, 0, 0 }, { 7500, 1, 1, 0 }, { 7500, 0, 0, 0 }, { 7100, 0, 0, 0 }, { 7100, 1, 0, 1 }, { 7500, 1, 2, 1 },
    };
    int runs = 0;
    for (size_t i = 0; i < sizeof forms / sizeof forms[0]; i++) {
        fbxw_scene scene;
        fixture_cube(&scene, forms[i].version, forms[i].binary, forms[i].compress);
        scene.big_endian = forms[i].big_endian;
        scene.type_mix = forms[i].big_endian;
        unsigned char *data;
        size_t size;
        CHECK(fbxw_write(&scene, &data, &size) == 0);
        if (!data) continue;
        runs += hammer(data, size, 3000, 1);
        free(data);
    }
    runs += hammer((const unsigned char *)fixture_legacy61, strlen(fixture_legacy61), 3000, 1);
    fprintf(stderr, "fixtures: %d hostile inputs\n", runs);
    CHECK(runs > 0);
}

static void test_corpus_files(void)
{
    const char *corpus = check_corpus_dir();
    char dir_path[1024];
    snprintf(dir_path, sizeof dir_path, "%s/fbx", corpus);
    DIR *dir = opendir(dir_path);
    if (!dir) SKIP("corpus not found at %s", corpus);
    int files = 0, runs = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".fbx") != 0) continue;
        char path[1300];
        snprintf(path, sizeof path, "%s/%s", dir_path, e->d_name);
        size_t size;
        unsigned char *data = check_read_file(path, &size);
        CHECK_MSG(data != NULL, "cannot read %s", path);
        if (!data) continue;
        /* Every truncation length (the cost is quadratic in the file size: corpus files are
         * at most 64 KB), plus random changes. */
        runs += hammer(data, size, 2000, 1);
        files++;
        free(data);
    }
    closedir(dir);
    fprintf(stderr, "corpus: %d files, %d hostile inputs\n", files, runs);
    CHECK(files > 0);
}

CHECK_MAIN(CASE(test_fixtures), CASE(test_corpus_files))

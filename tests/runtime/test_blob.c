/* SPDX-License-Identifier: MIT */
/* Blob robustness: every truncation and random byte flips (with and without a recomputed
 * checksum, so validation beyond the checksum is exercised) each give an error or a valid
 * open -- never a crash or out-of-bounds read (run under ASan+UBSan in CI; blobs live in
 * exact-size allocations so ASan sees any overread). test_open_checks.c has a targeted
 * corruption for every check. */

#include <stdlib.h>
#include "check.h"
#include "fixtures.h"
#include "format.h"

static unsigned char *exact_copy(const void *src, size_t n)
{
    void *p = NULL;
    if (posix_memalign(&p, 16, n ? n : 1) != 0) abort();
    if (n) memcpy(p, src, n);
    return p;
}

static void rechecksum(unsigned char *blob, size_t size)
{
    uint64_t sum = mk_checksum(blob + 32, size - 32);
    memcpy(blob + 24, &sum, 8);
}

/* Opens; if valid, exercises every mesh and clip with awkward weights. */
static mk_result open_and_use(const unsigned char *blob, size_t size)
{
    mk_asset a;
    mk_error err;
    mk_result r = mk_asset_open(blob, size, &a, &err);
    if (r != MK_OK) {
        CHECK(err.message[0] != 0);
        return r;
    }
    static float weights[4096];
    static _Alignas(16) unsigned char scratch[1 << 16];
    static float out[3 * 4096], out_n[3 * 4096], out_t[4 * 4096];
    const float values[] = { 0.0f, 0.3f, -2.5f, 1e6f };
    if (a.channel_count > 4096) return r;
    for (uint32_t i = 0; i < a.clip_count; i++) {
        mk_sample_job s = { .asset = &a, .clip = i, .time = 0.37f, .weights = weights, .weight_count = a.channel_count };
        CHECK(mk_sample_run(&s, &err) == MK_OK);
    }
    for (uint32_t mi = 0; mi < a.mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(&a, mi, &m);
        if (m.vertex_count > 4096 || mk_eval_scratch_size(&a, mi) > sizeof scratch) continue;
        for (int v = 0; v < 4; v++) {
            for (uint32_t c = 0; c < a.channel_count; c++) weights[c] = values[(c + (uint32_t)v) % 4];
            mk_eval_job j = { .asset = &a, .mesh = mi, .vertex_count = MK_VERTICES_TO_END, .weights = weights + m.first_channel, .weight_count = m.channel_count,
                              .normal_mode = (mk_normal_mode)(v & 1), .scratch = scratch, .scratch_size = sizeof scratch,
                              .positions = out, .positions_size = sizeof out,
                              .normals = m.has_normals ? out_n : NULL, .normals_size = sizeof out_n,
                              .tangents = m.has_tangents ? out_t : NULL, .tangents_size = sizeof out_t };
            CHECK(mk_eval_run(&j, &err) == MK_OK);
        }
    }
    return r;
}

static void *basic_blob(mk_raw_asset *raw, mk_precision p, size_t *size)
{
    mk_raw_init(raw, NULL);
    fixture_basic(raw);
    return fixture_blob(raw, p, &raw->arena, size);
}

static void *rich_blob(mk_raw_asset *raw, mk_precision p, size_t *size)
{
    mk_raw_init(raw, NULL);
    fixture_rich(raw);
    return fixture_blob(raw, p, &raw->arena, size);
}

static void test_valid_blob_opens(void)
{
    mk_raw_asset raw;
    size_t size;
    unsigned char *blob = basic_blob(&raw, MK_PRECISION_Q16, &size);
    CHECK(open_and_use(blob, size) == MK_OK);
    mk_raw_free(&raw);
}

static void test_every_truncation(void)
{
    mk_raw_asset raw;
    size_t size;
    unsigned char *blob = basic_blob(&raw, MK_PRECISION_Q16, &size);
    int all_rejected = 1;
    for (size_t n = 0; n < size; n++) {
        unsigned char *copy = exact_copy(blob, n);
        all_rejected &= open_and_use(copy, n) != MK_OK;
        free(copy);
    }
    CHECK(all_rejected);
    mk_raw_free(&raw);
}

static uint64_t rng = 0x853c49e6748fea9bull;
static uint32_t next_random(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(rng >> 33);
}

static void flips(int fix_checksum, int iterations, int *opened, int *rejected)
{
    for (int p = 0; p < 4; p++) {
        mk_raw_asset raw;
        size_t size;
        mk_precision precision = p % 2 ? MK_PRECISION_FLOAT : MK_PRECISION_Q16;
        unsigned char *blob = p < 2 ? basic_blob(&raw, precision, &size) : rich_blob(&raw, precision, &size);
        for (int it = 0; it < iterations; it++) {
            unsigned char *copy = exact_copy(blob, size);
            int n = 1 + (int)(next_random() % 4);
            for (int k = 0; k < n; k++) {
                /* Bias towards the tables (where the structure is), but hit everything. */
                size_t at = next_random() % 2 ? next_random() % (size < 1024 ? size : 1024) : next_random() % size;
                copy[at] ^= (unsigned char)(1u << (next_random() % 8));
            }
            if (fix_checksum) rechecksum(copy, size);
            /* Two flips of the same bit leave the blob as it was: nothing to catch. */
            if (memcmp(copy, blob, size) == 0) { free(copy); continue; }
            if (open_and_use(copy, size) == MK_OK) (*opened)++; else (*rejected)++;
            free(copy);
        }
        mk_raw_free(&raw);
    }
}

static void test_random_flips_fail_checksum(void)
{
    int opened = 0, rejected = 0;
    flips(0, 2000, &opened, &rejected);
    CHECK_EQ_INT(opened, 0);   /* any change without a new checksum is caught */
    printf("  flips without checksum fix-up: %d rejected\n", rejected);
}

static void test_random_flips_with_checksum(void)
{
    int opened = 0, rejected = 0;
    flips(1, 4000, &opened, &rejected);
    printf("  flips with checksum fix-up: %d opened (harmless flips), %d rejected\n", opened, rejected);
    CHECK(rejected > 0);
}

static void test_alignment_and_arguments(void)
{
    mk_raw_asset raw;
    size_t size;
    unsigned char *blob = basic_blob(&raw, MK_PRECISION_Q16, &size);
    unsigned char *shifted = malloc(size + 16);
    unsigned char *odd = shifted + (((uintptr_t)shifted % 16) == 8 ? 0 : 8);
    if ((uintptr_t)odd % 16 == 0) odd += 8;
    memcpy(odd, blob, size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(odd, size, &a, &err) == MK_ERROR_BAD_ALIGNMENT);
    CHECK(mk_asset_open(NULL, size, &a, &err) == MK_ERROR_INVALID_ARGUMENT);
    CHECK(mk_asset_open(blob, size, NULL, &err) == MK_ERROR_INVALID_ARGUMENT);
    CHECK(mk_asset_open(blob, size, &a, NULL) == MK_OK);   /* err is optional */
    free(shifted);
    mk_raw_free(&raw);
}

CHECK_MAIN(CASE(test_valid_blob_opens), CASE(test_every_truncation), CASE(test_random_flips_fail_checksum),
           CASE(test_random_flips_with_checksum), CASE(test_alignment_and_arguments))

/* SPDX-License-Identifier: MIT */
/* Blob robustness: every truncation, random byte flips (with and without a recomputed
 * checksum, so validation beyond the checksum is exercised), and targeted corruptions each
 * give an error or a valid open -- never a crash or out-of-bounds read (run under ASan+UBSan
 * in CI; blobs live in exact-size allocations so ASan sees any overread). */

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
    for (int p = 0; p < 2; p++) {
        mk_raw_asset raw;
        size_t size;
        unsigned char *blob = basic_blob(&raw, p ? MK_PRECISION_FLOAT : MK_PRECISION_Q16, &size);
        for (int it = 0; it < iterations; it++) {
            unsigned char *copy = exact_copy(blob, size);
            int n = 1 + (int)(next_random() % 4);
            for (int k = 0; k < n; k++) {
                /* Bias towards the tables (where the structure is), but hit everything. */
                size_t at = next_random() % 2 ? next_random() % (size < 1024 ? size : 1024) : next_random() % size;
                copy[at] ^= (unsigned char)(1u << (next_random() % 8));
            }
            if (fix_checksum) rechecksum(copy, size);
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

/* Patches a field, fixes the checksum, and expects code (and, if given, a message naming the
 * check, so a neighbouring check cannot stand in for the one under test). */
static uint64_t expect_corrupt_message(void (*patch)(unsigned char *, mk_asset *), mk_result code, const char *what,
                                       const char *message)
{
    mk_raw_asset raw;
    size_t size;
    unsigned char *blob = basic_blob(&raw, MK_PRECISION_FLOAT, &size);
    unsigned char *copy = exact_copy(blob, size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(copy, size, &a, &err) == MK_OK);
    patch(copy, &a);
    rechecksum(copy, size);
    mk_result r = mk_asset_open(copy, size, &a, &err);
    CHECK_MSG(r == code, "%s: got %s (%s)", what, mk_result_name(r), err.message);
    if (message) CHECK_MSG(strstr(err.message, message) != NULL, "%s: message is '%s'", what, err.message);
    free(copy);
    mk_raw_free(&raw);
    return err.offset;             /* where the error says the problem is */
}

static void expect_corrupt(void (*patch)(unsigned char *, mk_asset *), mk_result code, const char *what)
{
    expect_corrupt_message(patch, code, what, NULL);
}

#define FIELD(a, ptr) ((unsigned char *)(uintptr_t)(ptr))
static void patch_magic(unsigned char *b, mk_asset *a) { (void)a; b[0] = 'X'; }
static void patch_version(unsigned char *b, mk_asset *a) { (void)a; b[8] = (unsigned char)(MK_FORMAT_VERSION + 1); }
static void patch_entry_target(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_blob_entry *e = (mk_blob_entry *)(uintptr_t)(a->data + a->meshes[0].entries);
    e->target = 99;
}
static void patch_full_weights(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_target *)(uintptr_t)&a->targets[1])->full_weight = 0.25f;   /* below its predecessor 0.5 */
}
static void patch_nan_position(unsigned char *b, mk_asset *a)
{
    (void)b;
    float *p = (float *)(uintptr_t)(a->data + a->meshes[0].positions);
    p[4] = NAN;
}
static void patch_triangle(unsigned char *b, mk_asset *a)
{
    (void)b;
    uint32_t *t = (uint32_t *)(uintptr_t)(a->data + a->meshes[0].triangles);
    t[5] = 4;
}
static void patch_section_offset(unsigned char *b, mk_asset *a)
{
    (void)a;
    mk_blob_section *s = (mk_blob_section *)(b + 64);
    s[2].offset = (uint64_t)1 << 40;
}
static void patch_key_order(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_key *k = (mk_key *)(uintptr_t)a->keys;
    k[1].time = 0;                 /* equal to the previous key */
}
static void patch_mask(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_blob_entry *e = (mk_blob_entry *)(uintptr_t)(a->data + a->meshes[0].entries);
    e->mask |= 1ull << 10;         /* vertex 10 of a 4-vertex mesh */
}
static void patch_data_offset(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_blob_entry *e = (mk_blob_entry *)(uintptr_t)(a->data + a->meshes[0].entries);
    e->data = 0xFFFFFFF0u;
}

static void patch_overlapping_tracks(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_blob_track *t = (mk_blob_track *)(uintptr_t)a->tracks;
    t[1].first_key = 0;            /* shares track 0's keys: validation must stay O(size) */
}
static void patch_tiny_full_weight(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_target *)(uintptr_t)&a->targets[4])->full_weight = 1e-42f;   /* spans would overflow */
}
/* Reserved fields and the string section's leading NUL must be zero (format.md). */
static void patch_header_reserved(unsigned char *b, mk_asset *a) { (void)a; b[60] = 1; }
static void patch_mesh_reserved(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_mesh *)(uintptr_t)a->meshes)->reserved[1] = 7;
}
static void patch_mesh_normals_without_flag(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_blob_mesh *m = (mk_blob_mesh *)(uintptr_t)a->meshes;
    m->flags &= ~(uint32_t)MK_MESH_HAS_NORMALS;    /* the normals offset stays set */
}
static void patch_channel_reserved(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_channel *)(uintptr_t)a->channels)->reserved[0] = 1;
}
static void patch_clip_reserved(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_clip *)(uintptr_t)a->clips)->reserved[2] = 1;
}
static void patch_track_reserved(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_track *)(uintptr_t)a->tracks)->reserved = 1;
}
static void patch_key_reserved(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_key *)(uintptr_t)a->keys)[2].reserved = 1;
}
static void patch_strings_start(unsigned char *b, mk_asset *a)
{
    (void)b;
    *(char *)(uintptr_t)a->strings = 'x';
}

/* Clips must own every track and tracks every key, so no table entry goes unvalidated. */
static void patch_unowned_track(unsigned char *b, mk_asset *a)
{
    (void)b;
    ((mk_blob_clip *)(uintptr_t)&a->clips[a->clip_count - 1])->track_count--;
}
static void patch_unowned_key(unsigned char *b, mk_asset *a)
{
    (void)b;
    mk_blob_track *t = (mk_blob_track *)(uintptr_t)a->tracks;   /* track 0 has 2 keys, track 1 one */
    t[0].key_count--;
    t[1].first_key--;              /* still tiled; the last key now has no track */
}

/* The version error says which version this runtime reads. */
static void test_version_message(void)
{
    char expected[64];
    snprintf(expected, sizeof expected, "this runtime reads version %u (byte offset 8)", (unsigned)MK_FORMAT_VERSION);
    CHECK(expect_corrupt_message(patch_version, MK_ERROR_BAD_VERSION, "version", expected) == 8);
}

/* A block table whose middle value points past the entries must be rejected before any
 * block's entries are read (ASan catches the read otherwise). */
static void test_block_table_checked_first(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 200, 3, 2);
    size_t size;
    unsigned char *blob = fixture_blob(&raw, MK_PRECISION_FLOAT, &raw.arena, &size);
    unsigned char *copy = exact_copy(blob, size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(copy, size, &a, &err) == MK_OK);
    uint32_t *first = (uint32_t *)(uintptr_t)(a.data + a.meshes[0].block_entries);
    first[1] = 1000000;
    rechecksum(copy, size);
    CHECK(mk_asset_open(copy, size, &a, &err) == MK_ERROR_CORRUPT);
    CHECK(strstr(err.message, "block table") != NULL);
    free(copy);
    mk_raw_free(&raw);
}

static void test_targeted_corruptions(void)
{
    expect_corrupt(patch_magic, MK_ERROR_BAD_MAGIC, "magic");
    expect_corrupt(patch_version, MK_ERROR_BAD_VERSION, "version");
    expect_corrupt(patch_entry_target, MK_ERROR_CORRUPT, "entry target");
    expect_corrupt(patch_full_weights, MK_ERROR_CORRUPT, "full weights order");
    expect_corrupt(patch_nan_position, MK_ERROR_NOT_FINITE, "NaN position");
    expect_corrupt(patch_triangle, MK_ERROR_CORRUPT, "triangle index");
    expect_corrupt(patch_section_offset, MK_ERROR_TRUNCATED, "section offset");
    expect_corrupt(patch_key_order, MK_ERROR_CORRUPT, "key order");
    expect_corrupt(patch_mask, MK_ERROR_CORRUPT, "mask past mesh end");
    expect_corrupt(patch_data_offset, MK_ERROR_CORRUPT, "entry data offset");
    expect_corrupt(patch_overlapping_tracks, MK_ERROR_CORRUPT, "overlapping key ranges");
    expect_corrupt(patch_tiny_full_weight, MK_ERROR_CORRUPT, "subnormal full weight");
    expect_corrupt_message(patch_header_reserved, MK_ERROR_CORRUPT, "header reserved", "reserved fields are not those");
    expect_corrupt_message(patch_mesh_reserved, MK_ERROR_CORRUPT, "mesh reserved", "mesh 0: reserved");
    expect_corrupt_message(patch_mesh_normals_without_flag, MK_ERROR_CORRUPT, "normals offset without flag", "normal or tangent offset is set");
    expect_corrupt_message(patch_channel_reserved, MK_ERROR_CORRUPT, "channel reserved", "channel 0: reserved");
    expect_corrupt_message(patch_clip_reserved, MK_ERROR_CORRUPT, "clip reserved", "clip 0: reserved");
    expect_corrupt_message(patch_track_reserved, MK_ERROR_CORRUPT, "track reserved", "track 0: reserved");
    expect_corrupt_message(patch_key_reserved, MK_ERROR_CORRUPT, "key reserved", "key 2: reserved");
    expect_corrupt_message(patch_unowned_track, MK_ERROR_CORRUPT, "track without clip", "tracks no clip owns");
    expect_corrupt_message(patch_unowned_key, MK_ERROR_CORRUPT, "key without track", "keys no track owns");
    expect_corrupt_message(patch_strings_start, MK_ERROR_CORRUPT, "string section start", "does not start and end");
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
           CASE(test_random_flips_with_checksum), CASE(test_targeted_corruptions), CASE(test_version_message), CASE(test_block_table_checked_first),
           CASE(test_alignment_and_arguments))

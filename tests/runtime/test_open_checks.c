/* SPDX-License-Identifier: MIT */
/* Every check mk_asset_open makes is proven by a corruption test.
 *
 * runtime/open.c names each check: a failure is written `if (FAILS("area.rule", condition))`
 * (and CHECK_ARRAY("area.array", ...) stands for "area.array.align" and "area.array.bounds").
 * This program compiles open.c with -DMK_OPEN_CHECK_IDS, which records the name of the check
 * that rejected a blob in mk_open_rejected_by. Each corruption below writes a valid blob of
 * fixture_rich, breaks one thing (a field; a few set up a state several fields make), fixes
 * the checksum so validation gets past it, and expects the check's name, its error code and a
 * distinctive part of its message. test_every_check_has_a_test reads open.c and fails when a
 * check has no corruption here, a name is used twice, an error is returned without FAILS, or
 * docs/format.md does not list a check.
 *
 * Proving the tests bite: with MK_OPEN_DISABLE=<check> in the environment the named check's
 * condition is forced false and only that check's corruptions run; each must then fail (the
 * blob opens, another check catches it, or -- in an ASan build -- the read it guarded is
 * reported). tests/runtime/prove_open_checks.sh runs that for every check.
 *
 * Blobs live in exact-size allocations, so under ASan any read past the end is reported; a
 * corrupted blob that opens anyway is used (queries, sampling, evaluation) so that a missing
 * check shows up as the out-of-bounds read it would allow. */

#include <stdint.h>
#include <stdlib.h>
#include "check.h"
#include "fixtures.h"
#include "format.h"

extern const char *mk_open_rejected_by;
extern const char *mk_open_disabled_check;

/* ---- the intact blobs ---- */

typedef struct fixture_blob_cache {
    unsigned char *data;
    size_t size;
} fixture_blob_cache;

static const fixture_blob_cache *rich_blob(mk_precision precision)
{
    static fixture_blob_cache cache[2];
    fixture_blob_cache *c = &cache[precision == MK_PRECISION_Q16];
    if (!c->data) {
        mk_raw_asset raw;
        mk_raw_init(&raw, NULL);
        fixture_rich(&raw);
        size_t size;
        void *blob = fixture_blob(&raw, precision, &raw.arena, &size);
        c->data = malloc(size);
        if (!c->data) abort();
        memcpy(c->data, blob, size);
        c->size = size;
        mk_raw_free(&raw);
    }
    return c;
}

static unsigned char *aligned_copy(const void *src, size_t n, size_t capacity)
{
    void *p = NULL;
    if (posix_memalign(&p, 16, capacity ? capacity : 1) != 0) abort();
    memset(p, 0, capacity ? capacity : 1);
    if (n) memcpy(p, src, n);
    return p;
}

/* ---- what a patch works on ---- */

enum { CALL_NORMAL, CALL_NULL_OUT, CALL_NULL_DATA, CALL_MISALIGNED };
#define SLACK 256                  /* a patch may grow the blob by this much (zeros) */

typedef struct blob_case {
    unsigned char *b;              /* the working copy, 16-aligned, size + SLACK bytes */
    size_t size;                   /* bytes passed to mk_asset_open (a patch may change it) */
    mk_asset a;                    /* the intact blob opened: pointers into b */
    int keep_checksum;             /* set by a patch that tests the checksum itself */
    int call;                      /* CALL_*: how mk_asset_open is called */
} blob_case;

#define WRITABLE(p) ((void *)(uintptr_t)(p))
static mk_blob_header *header(blob_case *c) { return (mk_blob_header *)(void *)c->b; }
static mk_blob_section *section_at(blob_case *c, uint32_t i) { return (mk_blob_section *)(void *)(c->b + 64) + i; }
static mk_blob_section *section(blob_case *c, uint32_t kind)
{
    for (uint32_t i = 0; i < header(c)->section_count; i++)
        if (section_at(c, i)->kind == kind) return section_at(c, i);
    abort();
}
/* The DATA section's end rounded down to 16 bytes: where an aligned array may start to run
 * over it (the section itself may end unaligned, its last target data in 4-byte units). */
static uint64_t data_end(blob_case *c) { return (section(c, MK_SECTION_DATA)->offset + section(c, MK_SECTION_DATA)->size) & ~(uint64_t)15; }
static mk_blob_mesh *mesh(blob_case *c, uint32_t i) { return WRITABLE(&c->a.meshes[i]); }
static mk_blob_channel *channel(blob_case *c, uint32_t i) { return WRITABLE(&c->a.channels[i]); }
static mk_blob_target *target(blob_case *c, uint32_t i) { return WRITABLE(&c->a.targets[i]); }
static mk_blob_clip *clip(blob_case *c, uint32_t i) { return WRITABLE(&c->a.clips[i]); }
static mk_blob_track *track(blob_case *c, uint32_t i) { return WRITABLE(&c->a.tracks[i]); }
static mk_key *key(blob_case *c, uint32_t i) { return WRITABLE(&c->a.keys[i]); }
static uint32_t *block_table(blob_case *c, uint32_t m) { return (uint32_t *)(void *)(c->b + mesh(c, m)->block_entries); }
static uint32_t stride(blob_case *c, uint32_t m) { return mk_entry_stride(mesh(c, m)->flags); }
static uint32_t components(blob_case *c, uint32_t m) { return mk_mesh_components(mesh(c, m)->flags); }
static mk_blob_entry *entry(blob_case *c, uint32_t m, uint32_t e)
{
    return (mk_blob_entry *)(void *)(c->b + mesh(c, m)->entries + (uint64_t)e * stride(c, m));
}
/* Where entry e of mesh m has its data (entry.data counts 4-byte units). */
static unsigned char *entry_data(blob_case *c, uint32_t m, uint32_t e)
{
    return c->b + mesh(c, m)->target_data + (uint64_t)MK_DATA_UNIT * entry(c, m, e)->data;
}
/* The width codes (4 bits per component, low nibble first) and the int16 offsets after them. */
static void set_code(blob_case *c, uint32_t m, uint32_t e, uint32_t k, uint32_t code)
{
    unsigned char *codes = (unsigned char *)entry(c, m, e) + MK_ENTRY_HEAD;
    const unsigned shift = 4u * (k & 1u);
    codes[k / 2] = (unsigned char)((codes[k / 2] & ~(15u << shift)) | code << shift);
}
static void set_offset(blob_case *c, uint32_t m, uint32_t e, uint32_t k, int16_t offset)
{
    unsigned char *p = (unsigned char *)entry(c, m, e) + MK_ENTRY_HEAD + mk_entry_code_bytes(components(c, m)) + 2 * k;
    memcpy(p, &offset, 2);
}
/* Clears an entry's codes and offsets (as a float entry has them). */
static void clear_packing(blob_case *c, uint32_t m, uint32_t e)
{
    memset((unsigned char *)entry(c, m, e) + MK_ENTRY_HEAD, 0, stride(c, m) - MK_ENTRY_HEAD);
}
static float *floats_at(blob_case *c, uint64_t offset) { return (float *)(void *)(c->b + offset); }
static uint32_t *u32_at(blob_case *c, uint64_t offset) { return (uint32_t *)(void *)(c->b + offset); }
static uint32_t last_mesh(blob_case *c) { return c->a.mesh_count - 1; }

/* The entry of mesh m whose data lies last in its target data (it ends within 16 bytes of
 * the target data's end, which is the end of DATA and of the blob for the last mesh). */
static uint32_t entry_with_last_data(blob_case *c, uint32_t m)
{
    uint32_t best = 0;
    for (uint32_t e = 1; e < mesh(c, m)->entry_count; e++)
        if (entry(c, m, e)->data > entry(c, m, best)->data) best = e;
    return best;
}

/* First entry of mesh m with all 64 mask bits set (a dense block). */
static uint32_t dense_entry(blob_case *c, uint32_t m)
{
    for (uint32_t e = 0; e < mesh(c, m)->entry_count; e++)
        if (entry(c, m, e)->mask == ~0ull) return e;
    abort();
}

/* First target whose flags include `flags`. */
static uint32_t target_with(blob_case *c, uint32_t flags)
{
    for (uint32_t t = 0; t < c->a.target_count; t++)
        if ((target(c, t)->flags & flags) == flags) return t;
    abort();
}

/* Appends n bytes (copied from src, or zeros) to the blob at a 16-aligned end; returns their
 * offset. The header's file size follows. */
static uint64_t append(blob_case *c, const void *src, size_t n)
{
    size_t at = (c->size + 15) & ~(size_t)15;
    if (at + n > c->size + SLACK) abort();
    memset(c->b + c->size, 0, at - c->size);
    if (src) memcpy(c->b + at, src, n); else memset(c->b + at, 0, n);
    c->size = at + n;
    header(c)->file_size = c->size;
    return at;
}

/* ---- the corruptions ---- */

#define PATCH(name) static void name(blob_case *c)

/* arguments and header */
PATCH(call_null_out) { c->call = CALL_NULL_OUT; }
PATCH(call_null_data) { c->call = CALL_NULL_DATA; }
PATCH(call_misaligned) { c->call = CALL_MISALIGNED; }
PATCH(size_63) { c->size = 63; }
PATCH(size_0) { c->size = 0; }
PATCH(magic) { c->b[0] = 'X'; }
PATCH(magic_last_byte) { c->b[7] = 'k'; }
PATCH(version_next) { header(c)->version = MK_FORMAT_VERSION + 1; }
PATCH(version_2) { header(c)->version = 2; }
PATCH(version_3) { header(c)->version = 3; }
PATCH(version_4) { header(c)->version = 4; }
PATCH(version_1) { header(c)->version = 1; }
PATCH(header_size) { header(c)->header_size = 72; }
PATCH(header_flags) { header(c)->flags = 1; }
PATCH(header_reserved_first) { header(c)->reserved[0] = 1; }
PATCH(header_reserved_last) { header(c)->reserved[5] = 0x80000000u; }
PATCH(blob_cut_short) { c->size -= 16; }
PATCH(blob_one_byte_short) { c->size -= 1; }
PATCH(blob_too_long) { c->size += 16; }
PATCH(checksum_data_byte) { c->keep_checksum = 1; c->b[c->size - 5] ^= 0x10; }
PATCH(checksum_field) { c->keep_checksum = 1; header(c)->checksum ^= 1; }

/* sections */
PATCH(section_count_huge) { header(c)->section_count = 0x10000000u; }
PATCH(section_table_straddles) { header(c)->section_count = (uint32_t)((c->size - 64) / 32 + 1); }
PATCH(section_kind_0) { section_at(c, 3)->kind = 0; }
PATCH(section_kind_9) { section_at(c, 3)->kind = MK_SECTION_KIND_COUNT; }
PATCH(section_duplicate) { section_at(c, 1)->kind = section_at(c, 0)->kind; }
PATCH(section_element_size) { section(c, MK_SECTION_MESHES)->element_size = 200; }
PATCH(section_element_size_zero) { section(c, MK_SECTION_DATA)->element_size = 0; }
PATCH(section_size) { section(c, MK_SECTION_KEYS)->size += 32; }
PATCH(section_count_overflow) { section(c, MK_SECTION_KEYS)->count = (uint64_t)1 << 60; }
PATCH(section_count_2_32)
{
    mk_blob_section *s = section(c, MK_SECTION_TRACKS);
    s->count = (uint64_t)1 << 32;
    s->size = s->count * s->element_size;
}
PATCH(section_misaligned) { section(c, MK_SECTION_CLIPS)->offset += 8; }
PATCH(section_past_end) { section(c, MK_SECTION_CHANNELS)->offset = (uint64_t)1 << 40; }
PATCH(section_straddles_end) { section(c, MK_SECTION_KEYS)->offset = c->size - 16; }
PATCH(section_missing) { header(c)->section_count--; }    /* DATA is the table's last */
PATCH(section_over_table) { section(c, MK_SECTION_STRINGS)->offset = 64; }
PATCH(section_over_header) { section(c, MK_SECTION_TARGETS)->offset = 0; }
PATCH(section_overlap_same) { section(c, MK_SECTION_CHANNELS)->offset = section(c, MK_SECTION_MESHES)->offset; }
PATCH(section_overlap_straddles) { section(c, MK_SECTION_KEYS)->offset = section(c, MK_SECTION_TRACKS)->offset + 16; }
PATCH(section_overlap_data) { section(c, MK_SECTION_CLIPS)->offset = data_end(c) - 16 * c->a.clip_count * 2; }
PATCH(strings_start) { *(char *)WRITABLE(c->a.strings) = 'x'; }
PATCH(strings_empty)
{
    mk_blob_section *s = section(c, MK_SECTION_STRINGS);
    s->count = s->size = 0;
}
PATCH(strings_end) { ((char *)WRITABLE(c->a.strings))[c->a.strings_size - 1] = 'x'; }
/* The string section moved to the end of the blob, its last string unterminated and named by
 * every record: a missing check lets strcmp/strlen read past the blob. */
PATCH(strings_unterminated_at_end)
{
    static const char text[16] = { 0, 'u', 'n', 't', 'e', 'r', 'm', 'i', 'n', 'a', 't', 'e', 'd', '!', '!', '!' };
    mk_blob_section *s = section(c, MK_SECTION_STRINGS);
    s->offset = append(c, text, sizeof text);
    s->count = s->size = sizeof text;
    for (uint32_t i = 0; i < c->a.mesh_count; i++) mesh(c, i)->name = 1;
    for (uint32_t i = 0; i < c->a.channel_count; i++) { channel(c, i)->name = 1; channel(c, i)->origin = 1; }
    for (uint32_t i = 0; i < c->a.target_count; i++) target(c, i)->name = 1;
    for (uint32_t i = 0; i < c->a.clip_count; i++) clip(c, i)->name = 1;
}

/* meshes */
PATCH(mesh_name) { mesh(c, 1)->name = (uint32_t)c->a.strings_size; }
PATCH(mesh_name_far) { mesh(c, 3)->name = 0x7FFFFFF0u; }
PATCH(mesh_no_vertices) { mesh(c, 1)->vertex_count = 0; }
PATCH(mesh_too_many_vertices) { mesh(c, 1)->vertex_count = MK_MAX_VERTICES + 1; }
PATCH(mesh_uint32_max_vertices) { mesh(c, 3)->vertex_count = UINT32_MAX; }
PATCH(mesh_block_count_low) { mesh(c, 2)->block_count = 2; }
PATCH(mesh_block_count_high) { mesh(c, 0)->block_count = 2; }
PATCH(mesh_first_channel) { mesh(c, 1)->first_channel = 1; }
PATCH(mesh_channel_count) { mesh(c, 2)->channel_count = 5; }
PATCH(mesh_channel_count_huge) { mesh(c, 3)->channel_count = UINT32_MAX; }
PATCH(mesh_first_target) { mesh(c, 2)->first_target = 3; }
PATCH(mesh_target_count) { mesh(c, 3)->target_count = 2; }
PATCH(mesh_target_count_max) { mesh(c, 3)->target_count = MK_MAX_MESH_TARGETS + 1; }
PATCH(mesh_stacking_0) { mesh(c, 0)->stacking = 0; }
PATCH(mesh_stacking_3) { mesh(c, 2)->stacking = 3; }
PATCH(mesh_flags) { mesh(c, 1)->flags |= 4; }
PATCH(mesh_reserved_0) { mesh(c, 0)->reserved[0] = 1; }
PATCH(mesh_reserved_1) { mesh(c, 3)->reserved[1] = 7; }
PATCH(mesh_normals_set) { mesh(c, 1)->normals = mesh(c, 0)->normals; }
PATCH(mesh_normals_flag_cleared) { mesh(c, 0)->flags &= ~(uint32_t)MK_MESH_HAS_NORMALS; }
PATCH(mesh_tangents_set) { mesh(c, 2)->tangents = mesh(c, 0)->tangents; }
PATCH(mesh_world_inf) { mesh(c, 1)->world[13] = INFINITY; }
PATCH(mesh_world_nan) { mesh(c, 2)->world[0] = NAN; }
PATCH(positions_misaligned) { mesh(c, 0)->positions += 4; }
PATCH(positions_past_data) { mesh(c, last_mesh(c))->positions = data_end(c) - 16; }
PATCH(positions_outside_data) { mesh(c, 1)->positions = section(c, MK_SECTION_KEYS)->offset; }
PATCH(positions_nan) { floats_at(c, mesh(c, 2)->positions)[3 * 149 + 2] = NAN; }
PATCH(positions_inf) { floats_at(c, mesh(c, 0)->positions)[0] = -INFINITY; }
PATCH(normals_misaligned) { mesh(c, 2)->normals += 12; }
PATCH(normals_past_data) { mesh(c, 2)->normals = data_end(c) - 32; }
PATCH(normals_nan) { floats_at(c, mesh(c, 0)->normals)[5] = NAN; }
PATCH(tangents_misaligned) { mesh(c, 0)->tangents += 8; }
PATCH(tangents_past_data) { mesh(c, 0)->tangents = data_end(c) - 48; }
PATCH(tangents_inf) { floats_at(c, mesh(c, 0)->tangents)[15] = -INFINITY; }
PATCH(triangles_misaligned) { mesh(c, 2)->triangles += 4; }
PATCH(triangles_past_data) { mesh(c, last_mesh(c))->triangles = data_end(c); }
PATCH(triangles_count) { mesh(c, 1)->triangle_count = 0x40000000u; }
PATCH(triangle_index) { u32_at(c, mesh(c, 2)->triangles)[3 * 147 + 2] = 150; }
PATCH(triangle_index_huge) { u32_at(c, mesh(c, 3)->triangles)[0] = 0xFFFFFFFFu; }
PATCH(control_points_misaligned) { mesh(c, 1)->control_points += 4; }
PATCH(control_points_past_data) { mesh(c, last_mesh(c))->control_points = data_end(c); }
PATCH(control_point_index) { u32_at(c, mesh(c, 0)->control_points)[3] = 3; }
PATCH(meshes_channel_left) { mesh(c, last_mesh(c))->channel_count--; }
PATCH(meshes_target_left) { mesh(c, last_mesh(c))->target_count--; }
/* Channel 3 ("sparse") keeps one target and channel 4 takes the other: mesh 2's last target
 * then has no channel (each other field stays consistent so only that check sees it). */
PATCH(mesh_target_without_channel)
{
    channel(c, 3)->target_count = 1;
    channel(c, 4)->first_target = 6;
    target(c, 6)->channel = 4;
}

/* channels and targets */
PATCH(channel_name) { channel(c, 3)->name = (uint32_t)c->a.strings_size + 5; }
PATCH(channel_origin) { channel(c, 0)->origin = 0xFFFFFFFFu; }
PATCH(channel_mesh) { channel(c, 5)->mesh = 4; }
PATCH(channel_mesh_huge) { channel(c, 2)->mesh = 0x10000000u; }
PATCH(channel_other_mesh) { channel(c, 1)->mesh = 2; }
PATCH(channel_no_targets) { channel(c, 1)->target_count = 0; }
PATCH(channel_targets_past_table) { channel(c, 5)->target_count = 2; }
PATCH(channel_first_target_past_table) { channel(c, 5)->first_target = 10; }
PATCH(channel_targets_wrap) { channel(c, 1)->target_count = UINT32_MAX - 1; }
PATCH(channel_targets_other_mesh) { channel(c, 2)->first_target = 3; }
PATCH(channel_targets_overlap) { channel(c, 1)->first_target = 2; }
PATCH(channel_targets_gap) { channel(c, 3)->first_target = 6; }
PATCH(channel_default_nan) { channel(c, 4)->default_weight = NAN; }
PATCH(channel_default_inf) { channel(c, 0)->default_weight = INFINITY; }
PATCH(channel_reserved) { channel(c, 2)->reserved[1] = 1; }
PATCH(target_channel) { target(c, 5)->channel = 2; }
PATCH(target_name) { target(c, 7)->name = (uint32_t)c->a.strings_size; }
PATCH(target_full_inf) { target(c, 1)->full_weight = INFINITY; }
PATCH(target_full_nan) { target(c, 8)->full_weight = NAN; }
PATCH(target_full_zero) { target(c, 4)->full_weight = 0; }
PATCH(target_full_subnormal) { target(c, 3)->full_weight = 1e-42f; }
PATCH(target_full_tiny_negative) { target(c, 0)->full_weight = -5e-7f; }
PATCH(target_full_below_previous) { target(c, 1)->full_weight = -0.75f; }
PATCH(target_full_equal) { target(c, 6)->full_weight = 0.5f; }
PATCH(target_full_gap_too_small) { target(c, 2)->full_weight = 0.5000005f; }
PATCH(target_flags) { target(c, 3)->flags |= 8; }
PATCH(target_normals_without_mesh_normals) { target(c, 8)->flags |= MK_TARGET_HAS_NORMALS; }
PATCH(target_tangents_without_mesh_tangents) { target(c, 4)->flags |= MK_TARGET_HAS_TANGENTS; }
PATCH(target_position_scale_nan) { target(c, target_with(c, MK_TARGET_QUANTIZED))->position_scale = NAN; }
PATCH(target_normal_scale_inf) { target(c, 2)->normal_scale = INFINITY; }
PATCH(target_tangent_scale_negative) { target(c, target_with(c, MK_TARGET_QUANTIZED | MK_TARGET_HAS_TANGENTS))->tangent_scale = -1; }
PATCH(target_position_scale_negative) { target(c, 7)->position_scale = -0.5f; }

/* block tables and entries */
PATCH(block_table_misaligned) { mesh(c, 2)->block_entries += 4; }
PATCH(block_table_past_data) { mesh(c, 2)->block_entries = data_end(c); }
PATCH(entries_misaligned) { mesh(c, 0)->entries += 8; }
PATCH(entries_past_data) { mesh(c, last_mesh(c))->entries = data_end(c) - 16; }   /* 1 entry of 24 bytes */
PATCH(entries_count_overflow) { mesh(c, 2)->entry_count = (uint64_t)1 << 60; }
PATCH(target_data_misaligned) { mesh(c, 2)->target_data += 4; }
PATCH(target_data_past_data) { mesh(c, last_mesh(c))->target_data_size += 16; }
PATCH(block_table_first) { block_table(c, 2)[0] = 1; }
PATCH(block_table_last) { block_table(c, 2)[3] = (uint32_t)mesh(c, 2)->entry_count - 1; }
PATCH(block_table_last_huge) { block_table(c, 0)[1] = 0xFFFFFFFFu; }
PATCH(entry_count_more) { mesh(c, 2)->entry_count++; }
PATCH(block_table_order) { block_table(c, 2)[1] = 1000000; }
PATCH(block_table_order_dip) { block_table(c, 2)[2] = block_table(c, 2)[1] - 1; }
PATCH(entry_target) { entry(c, 0, 3)->target_and_flags = 4 | MK_ENTRY_FLOAT; }
PATCH(entry_target_huge) { entry(c, 3, 0)->target_and_flags = MK_ENTRY_TARGET_MASK - 15; }
PATCH(entry_flags) { entry(c, 0, 1)->target_and_flags |= 1u << 24; }
PATCH(entry_flags_top) { entry(c, 2, 3)->target_and_flags |= 0x20000000u; }
PATCH(entry_packed_of_float_target) { entry(c, 2, 4)->target_and_flags &= ~MK_ENTRY_FLOAT; }
PATCH(entry_duplicate) { entry(c, 0, 1)->target_and_flags = entry(c, 0, 0)->target_and_flags; }
PATCH(entry_misordered) { entry(c, 2, 2)->target_and_flags = 0; }
PATCH(entry_mask_empty) { entry(c, 2, 5)->mask = 0; }
PATCH(entry_mask_past_end_small) { entry(c, 0, 2)->mask |= 1ull << 4; }
PATCH(entry_mask_past_end_block) { entry(c, 2, mesh(c, 2)->entry_count - 1)->mask |= 1ull << 22; }
PATCH(entry_data_straddles) { entry(c, last_mesh(c), entry_with_last_data(c, last_mesh(c)))->data += 1; }
PATCH(entry_data_far) { entry(c, 2, dense_entry(c, 2))->data = 0xFFFFFFF0u; }
/* The target data 4 bytes shorter: the last entry's data ends less than 16 bytes before it,
 * where a decoder's 16-byte loads would run past. */
PATCH(entry_data_no_tail) { mesh(c, last_mesh(c))->target_data_size -= 4; }
PATCH(entry_data_nan) { ((float *)(void *)entry_data(c, 2, dense_entry(c, 2)))[100] = NAN; }
/* A quantized blob's last entry flagged float (its packing cleared): 3 float triples where
 * the packed entry stored none, past the target data. */
PATCH(entry_float_last)
{
    const uint32_t m = last_mesh(c), e = entry_with_last_data(c, m);
    entry(c, m, e)->target_and_flags |= MK_ENTRY_FLOAT;
    clear_packing(c, m, e);
}
/* A quantized target's entry flagged float (packing cleared, data moved to the start of the
 * target data, where its 4 position triples fit), with a NaN among its now float deltas. */
PATCH(entry_float_nan)
{
    mk_blob_entry *e = entry(c, 0, 3);    /* target 3: positions only, 4 vertices */
    e->target_and_flags |= MK_ENTRY_FLOAT;
    e->data = 0;
    clear_packing(c, 0, 3);
    ((float *)(void *)entry_data(c, 0, 3))[7] = NAN;
}
PATCH(entry_normal_delta_inf)
{
    /* target 2: 4 vertices, 12 position floats, then normals */
    ((float *)(void *)entry_data(c, 0, 2))[12 + 4] = INFINITY;
}
PATCH(entry_wide_on_float) { entry(c, 2, 3)->target_and_flags |= MK_ENTRY_WIDE; }
PATCH(entry_float_code) { set_code(c, 0, 1, 4, 3); }
PATCH(entry_float_offset) { set_offset(c, 3, 0, 2, 1); }   /* the entry's last byte */
/* Mesh 3 has 3 components: code 3 is the high nibble of the second code byte. */
PATCH(entry_code_padding_nibble) { set_code(c, 3, 0, 3, 1); }
/* Mesh 0 has 9 components in 6 code bytes: codes 9-11 pad. */
PATCH(entry_code_padding_byte) { set_code(c, 0, 2, 11, 15); }
/* Target 3 of mesh 0 and target 3 of mesh 2 (asset 7) move positions only. */
PATCH(entry_absent_normal_code) { set_code(c, 2, 3, 3, 15); }
PATCH(entry_absent_tangent_offset) { set_offset(c, 0, 3, 8, -1); }
/* An entry with a position offset in its head flagged WIDE. */
PATCH(entry_wide_head) { entry(c, 0, 0)->target_and_flags |= MK_ENTRY_WIDE; }
/* Entry 0 of mesh 0 made WIDE (head offsets zero): its first 12 data bytes are the int32
 * position offsets, one of them out of range. */
static void make_wide(blob_case *c, int32_t x, int32_t y, int32_t z)
{
    entry(c, 0, 0)->target_and_flags |= MK_ENTRY_WIDE;
    for (uint32_t k = 0; k < 3; k++) set_offset(c, 0, 0, k, 0);
    const int32_t o[3] = { x, y, z };
    memcpy(entry_data(c, 0, 0), o, sizeof o);
}
PATCH(entry_wide_past_max) { make_wide(c, 5, MK_WIDE_OFFSET_MAX + 1, -MK_WIDE_OFFSET_MAX); }
PATCH(entry_wide_int32_min) { make_wide(c, 0, 0, INT32_MIN); }

/* clips, tracks, keys */
PATCH(clip_name) { clip(c, 1)->name = (uint32_t)c->a.strings_size; }
PATCH(clip_first_track) { clip(c, 2)->first_track = 2; }
PATCH(clip_track_count) { clip(c, 2)->track_count = 3; }
/* Clip 0 claims 2^32 - 1 tracks and clip 1 starts where that wraps to: a missing check lets
 * sampling clip 0 read past the track table. */
PATCH(clip_track_count_wraps)
{
    clip(c, 0)->track_count = UINT32_MAX;
    clip(c, 1)->first_track = UINT32_MAX;
    clip(c, 2)->first_track = UINT32_MAX;
    clip(c, 2)->track_count = 6;
}
PATCH(clip_start) { clip(c, 2)->start = -INFINITY; }
PATCH(clip_duration_nan) { clip(c, 0)->duration = NAN; }
PATCH(clip_duration_negative) { clip(c, 2)->duration = -1; }
PATCH(clip_duration_tiny_negative) { clip(c, 1)->duration = -1e-30f; }
PATCH(clip_reserved) { clip(c, 1)->reserved[2] = 1; }
PATCH(clips_track_left) { clip(c, 2)->track_count--; }
PATCH(track_channel) { track(c, 0)->channel = 6; }
PATCH(track_channel_huge) { track(c, 3)->channel = 0x10000000u; }
PATCH(track_reserved) { track(c, 3)->reserved = 1; }
PATCH(track_no_keys) { track(c, 2)->key_count = 0; }
PATCH(track_first_key) { track(c, 1)->first_key = 0; }
PATCH(track_key_range) { track(c, 4)->key_count = 3; }
PATCH(tracks_key_left) { track(c, 4)->key_count--; }
PATCH(key_time_nan) { key(c, 4)->time = NAN; }
PATCH(key_right_slope_inf) { key(c, 0)->right_slope = INFINITY; }
PATCH(key_left_weight_nan) { key(c, 9)->left_weight = NAN; }
PATCH(key_interp) { key(c, 1)->interp = MK_INTERP_COUNT; }
PATCH(key_reserved) { key(c, 7)->reserved = 1; }
PATCH(key_right_weight_zero) { key(c, 3)->right_weight = 0; }
PATCH(key_left_weight_zero) { key(c, 4)->left_weight = 0; }
PATCH(key_right_weight_negative) { key(c, 2)->right_weight = -0.25f; }
PATCH(key_left_weight_above_one) { key(c, 1)->left_weight = 1.5f; }
PATCH(key_time_equal) { key(c, 6)->time = key(c, 5)->time; }
PATCH(key_time_decreasing) { key(c, 2)->time = 0.5f; }

typedef struct corruption {
    const char *check;             /* the FAILS / CHECK_ARRAY name it must trip */
    void (*patch)(blob_case *);
    const char *what;
    mk_result code;
    const char *message;           /* a distinctive part of the message */
    int q16;                       /* 1: the blob is written quantized (MK_PRECISION_Q16), 0: float */
} corruption;

#define Q16 1
static const corruption corruptions[] = {
    { "args.output", call_null_out, "output asset NULL", MK_ERROR_INVALID_ARGUMENT, "output asset is NULL", 0 },
    { "args.data", call_null_data, "blob pointer NULL", MK_ERROR_INVALID_ARGUMENT, "blob pointer is NULL", 0 },
    { "blob.alignment", call_misaligned, "blob at an address = 8 mod 16", MK_ERROR_BAD_ALIGNMENT, "blob memory is not 16-byte aligned", 0 },
    { "header.truncated", size_63, "63 bytes", MK_ERROR_TRUNCATED, "blob of 63 bytes is shorter than the 64-byte header", 0 },
    { "header.truncated", size_0, "0 bytes", MK_ERROR_TRUNCATED, "blob of 0 bytes is shorter", 0 },
    { "header.magic", magic, "magic XORPHKIT", MK_ERROR_BAD_MAGIC, "magic is not MORPHKIT", 0 },
    { "header.magic", magic_last_byte, "magic MORPHKIt", MK_ERROR_BAD_MAGIC, "magic is not MORPHKIT", 0 },
    { "header.version", version_next, "next version", MK_ERROR_BAD_VERSION, "version 6 is not supported; this runtime reads version 5 (byte offset 8)", 0 },
    { "header.version", version_2, "version 2 (no entry flags)", MK_ERROR_BAD_VERSION, "version 2 is not supported; this runtime reads version 5: the format is older, re-import the source with this version's tools (byte offset 8)", 0 },
    { "header.version", version_3, "version 3 (no offset entries)", MK_ERROR_BAD_VERSION, "version 3 is not supported; this runtime reads version 5: the format is older, re-import the source", 0 },
    { "header.version", version_4, "version 4 (int16 entries)", MK_ERROR_BAD_VERSION, "version 4 is not supported; this runtime reads version 5: the format is older, re-import the source", 0 },
    { "header.version", version_1, "version 1 (never released)", MK_ERROR_BAD_VERSION, "blob format version 1 is not supported; this runtime reads version 5 (byte offset 8)", 0 },
    { "header.size", header_size, "header size 72", MK_ERROR_CORRUPT, "header size 72 is not 64", 0 },
    { "header.flags", header_flags, "header flags 1", MK_ERROR_CORRUPT, "header flags (1) are not zero", 0 },
    { "header.reserved", header_reserved_first, "reserved[0]", MK_ERROR_CORRUPT, "header reserved field 0 is not zero (byte offset 40)", 0 },
    { "header.reserved", header_reserved_last, "reserved[5]", MK_ERROR_CORRUPT, "header reserved field 5 is not zero (byte offset 60)", 0 },
    { "header.file_size_short", blob_cut_short, "16 bytes cut", MK_ERROR_TRUNCATED, "shorter than the header's file size", 0 },
    { "header.file_size_short", blob_one_byte_short, "1 byte cut", MK_ERROR_TRUNCATED, "shorter than the header's file size", 0 },
    { "header.file_size_long", blob_too_long, "16 bytes appended", MK_ERROR_CORRUPT, "longer than the header's file size", 0 },
    { "header.checksum", checksum_data_byte, "a data bit flipped", MK_ERROR_BAD_CHECKSUM, "checksum mismatch", 0 },
    { "header.checksum", checksum_field, "the checksum's bit flipped", MK_ERROR_BAD_CHECKSUM, "checksum mismatch", 0 },

    { "section.table", section_count_huge, "2^28 sections", MK_ERROR_TRUNCATED, "section table of 268435456 sections extends past the end", 0 },
    { "section.table", section_table_straddles, "table one entry past the end", MK_ERROR_TRUNCATED, "sections extends past the end of the blob", 0 },
    { "section.kind", section_kind_0, "kind 0", MK_ERROR_CORRUPT, "section 3: unknown kind 0", 0 },
    { "section.kind", section_kind_9, "kind 9", MK_ERROR_CORRUPT, "section 3: unknown kind 9", 0 },
    { "section.duplicate", section_duplicate, "two STRINGS", MK_ERROR_CORRUPT, "section 1 (STRINGS): kind appears twice (also section 0)", 0 },
    { "section.element_size", section_element_size, "MESHES element size 200", MK_ERROR_CORRUPT, "(MESHES): element size 200 is wrong", 0 },
    { "section.element_size", section_element_size_zero, "DATA element size 0", MK_ERROR_CORRUPT, "(DATA): element size 0 is wrong", 0 },
    { "section.size", section_size, "KEYS size + 32", MK_ERROR_CORRUPT, "(KEYS): size", 0 },
    { "section.size", section_count_overflow, "KEYS count 2^60 (size overflows)", MK_ERROR_CORRUPT, "is not count x element size", 0 },
    { "section.count", section_count_2_32, "2^32 tracks", MK_ERROR_CORRUPT, "(TRACKS): more than 2^32 elements", 0 },
    { "section.align", section_misaligned, "CLIPS at +8", MK_ERROR_BAD_ALIGNMENT, "(CLIPS): array is not 16-byte aligned", 0 },
    { "section.bounds", section_past_end, "CHANNELS at 2^40", MK_ERROR_TRUNCATED, "(CHANNELS): array of 6 x 32 bytes is not inside the blob", 0 },
    { "section.bounds", section_straddles_end, "KEYS over the blob's end", MK_ERROR_TRUNCATED, "(KEYS): array of 10 x 32 bytes is not inside the blob", 0 },
    { "section.missing", section_missing, "DATA left out of the table", MK_ERROR_CORRUPT, "required section kind 8 (DATA) is missing", 0 },
    { "section.overlaps_table", section_over_table, "STRINGS over the section table", MK_ERROR_CORRUPT, "(STRINGS): overlaps the header and section table, which end at byte 320", 0 },
    { "section.overlaps_table", section_over_header, "TARGETS over the header", MK_ERROR_CORRUPT, "(TARGETS): overlaps the header", 0 },
    { "section.overlap", section_overlap_same, "CHANNELS on MESHES", MK_ERROR_CORRUPT, "section 2 (CHANNELS) overlaps section 1 (MESHES)", 0 },
    { "section.overlap", section_overlap_straddles, "KEYS 16 bytes into TRACKS", MK_ERROR_CORRUPT, "section 6 (KEYS) overlaps section 5 (TRACKS)", 0 },
    { "section.overlap", section_overlap_data, "CLIPS inside DATA", MK_ERROR_CORRUPT, "(DATA) overlaps section 4 (CLIPS)", 0 },
    { "strings.leading_nul", strings_start, "first string byte 'x'", MK_ERROR_CORRUPT, "string section does not start with a NUL byte", 0 },
    { "strings.leading_nul", strings_empty, "empty string section", MK_ERROR_CORRUPT, "string section does not start with a NUL byte", 0 },
    { "strings.trailing_nul", strings_end, "last string byte 'x'", MK_ERROR_CORRUPT, "does not end with a NUL byte: its last string is unterminated", 0 },
    { "strings.trailing_nul", strings_unterminated_at_end, "every name unterminated at the blob's end", MK_ERROR_CORRUPT, "its last string is unterminated", 0 },

    { "mesh.name", mesh_name, "name = string section size", MK_ERROR_CORRUPT, "mesh 1: name string offset", 0 },
    { "mesh.name", mesh_name_far, "name far out", MK_ERROR_CORRUPT, "mesh 3: name string offset 2147483632 is out of range", 0 },
    { "mesh.vertex_count_zero", mesh_no_vertices, "0 vertices", MK_ERROR_CORRUPT, "mesh 1: has no vertices", 0 },
    { "mesh.vertex_count_max", mesh_too_many_vertices, "2^32 - 63 vertices", MK_ERROR_UNSUPPORTED, "mesh 1: has 4294967233 vertices, more than a mesh may have", 0 },
    { "mesh.vertex_count_max", mesh_uint32_max_vertices, "2^32 - 1 vertices", MK_ERROR_UNSUPPORTED, "mesh 3: has 4294967295 vertices", 0 },
    { "mesh.block_count", mesh_block_count_low, "2 blocks for 150 vertices", MK_ERROR_CORRUPT, "mesh 2: block count 2 does not match its 150 vertices", 0 },
    { "mesh.block_count", mesh_block_count_high, "2 blocks for 4 vertices", MK_ERROR_CORRUPT, "mesh 0: block count 2 does not match its 4 vertices", 0 },
    { "mesh.first_channel", mesh_first_channel, "mesh 1 starts at channel 1", MK_ERROR_CORRUPT, "mesh 1: first channel 1 does not follow the previous mesh's channels (expected 2)", 0 },
    { "mesh.channel_count", mesh_channel_count, "mesh 2 has 5 channels", MK_ERROR_CORRUPT, "mesh 2: its 5 channels run past the end of the channel table (6 channels)", 0 },
    { "mesh.channel_count", mesh_channel_count_huge, "mesh 3 has 2^32 - 1 channels", MK_ERROR_CORRUPT, "mesh 3: its 4294967295 channels run past", 0 },
    { "mesh.first_target", mesh_first_target, "mesh 2 starts at target 3", MK_ERROR_CORRUPT, "mesh 2: first target 3 does not follow the previous mesh's targets (expected 4)", 0 },
    { "mesh.target_count_max", mesh_target_count_max, "2^24 + 1 targets", MK_ERROR_UNSUPPORTED, "mesh 3: has 16777217 targets, more than a mesh may have (2^24)", 0 },
    { "mesh.target_count", mesh_target_count, "mesh 3 has 2 targets", MK_ERROR_CORRUPT, "mesh 3: its 2 targets run past the end of the target table (9 targets)", 0 },
    { "mesh.stacking", mesh_stacking_0, "stacking 0", MK_ERROR_CORRUPT, "mesh 0: unknown stacking mode 0", 0 },
    { "mesh.stacking", mesh_stacking_3, "stacking 3", MK_ERROR_CORRUPT, "mesh 2: unknown stacking mode 3", 0 },
    { "mesh.flags", mesh_flags, "mesh flag 4", MK_ERROR_CORRUPT, "mesh 1: unknown flags (4)", 0 },
    { "mesh.reserved", mesh_reserved_0, "mesh reserved[0]", MK_ERROR_CORRUPT, "mesh 0: reserved field 0 is not zero", 0 },
    { "mesh.reserved", mesh_reserved_1, "mesh reserved[1]", MK_ERROR_CORRUPT, "mesh 3: reserved field 1 is not zero", 0 },
    { "mesh.normals_offset", mesh_normals_set, "normals offset without the flag", MK_ERROR_CORRUPT, "mesh 1: normals offset is set but", 0 },
    { "mesh.normals_offset", mesh_normals_flag_cleared, "normals flag cleared", MK_ERROR_CORRUPT, "mesh 0: normals offset is set but the mesh's flags say it has no normals", 0 },
    { "mesh.tangents_offset", mesh_tangents_set, "tangents offset without the flag", MK_ERROR_CORRUPT, "mesh 2: tangents offset is set but the mesh's flags say it has no tangents", 0 },
    { "mesh.world", mesh_world_inf, "world[13] = inf", MK_ERROR_NOT_FINITE, "mesh 1: world transform element 13 is not finite", 0 },
    { "mesh.world", mesh_world_nan, "world[0] = NaN", MK_ERROR_NOT_FINITE, "mesh 2: world transform element 0 is not finite", 0 },
    { "mesh.positions.align", positions_misaligned, "positions at +4", MK_ERROR_BAD_ALIGNMENT, "mesh 0 positions: array is not 16-byte aligned", 0 },
    { "mesh.positions.bounds", positions_past_data, "positions over the end", MK_ERROR_CORRUPT, "mesh 3 positions: array of 3 x 12 bytes is not inside the DATA section", 0 },
    { "mesh.positions.bounds", positions_outside_data, "positions in KEYS", MK_ERROR_CORRUPT, "mesh 1 positions: array of 3 x 12 bytes is not inside the DATA section", 0 },
    { "mesh.positions_finite", positions_nan, "last vertex z = NaN", MK_ERROR_NOT_FINITE, "mesh 2: base position of vertex 149 is not finite", 0 },
    { "mesh.positions_finite", positions_inf, "first vertex x = -inf", MK_ERROR_NOT_FINITE, "mesh 0: base position of vertex 0 is not finite", 0 },
    { "mesh.normals.align", normals_misaligned, "normals at +12", MK_ERROR_BAD_ALIGNMENT, "mesh 2 normals: array is not 16-byte aligned", 0 },
    { "mesh.normals.bounds", normals_past_data, "normals over the end", MK_ERROR_CORRUPT, "mesh 2 normals: array of 150 x 12 bytes is not inside the DATA section", 0 },
    { "mesh.normals_finite", normals_nan, "normal NaN", MK_ERROR_NOT_FINITE, "mesh 0: base normal of vertex 1 is not finite", 0 },
    { "mesh.tangents.align", tangents_misaligned, "tangents at +8", MK_ERROR_BAD_ALIGNMENT, "mesh 0 tangents: array is not 16-byte aligned", 0 },
    { "mesh.tangents.bounds", tangents_past_data, "tangents over the end", MK_ERROR_CORRUPT, "mesh 0 tangents: array of 4 x 16 bytes is not inside the DATA section", 0 },
    { "mesh.tangents_finite", tangents_inf, "handedness -inf", MK_ERROR_NOT_FINITE, "mesh 0: base tangent of vertex 3 is not finite", 0 },
    { "mesh.triangles.align", triangles_misaligned, "triangles at +4", MK_ERROR_BAD_ALIGNMENT, "mesh 2 triangles: array is not 16-byte aligned", 0 },
    { "mesh.triangles.bounds", triangles_past_data, "triangles over the end", MK_ERROR_CORRUPT, "mesh 3 triangles: array of 1 x 12 bytes is not inside the DATA section", 0 },
    { "mesh.triangles.bounds", triangles_count, "2^30 triangles", MK_ERROR_CORRUPT, "mesh 1 triangles: array of 1073741824 x 12 bytes", 0 },
    { "mesh.triangle_index", triangle_index, "index = vertex count", MK_ERROR_CORRUPT, "mesh 2: triangle 147 has vertex index 150 out of range", 0 },
    { "mesh.triangle_index", triangle_index_huge, "index 2^32 - 1", MK_ERROR_CORRUPT, "mesh 3: triangle 0 has vertex index 4294967295 out of range", 0 },
    { "mesh.control_points.align", control_points_misaligned, "control points at +4", MK_ERROR_BAD_ALIGNMENT, "mesh 1 control points: array is not 16-byte aligned", 0 },
    { "mesh.control_points.bounds", control_points_past_data, "control points over the end", MK_ERROR_CORRUPT, "mesh 3 control points: array of 3 x 4 bytes is not inside the DATA section", 0 },
    { "mesh.control_point_index", control_point_index, "control point = count", MK_ERROR_CORRUPT, "mesh 0: vertex 3 has control point 3 out of range", 0 },
    { "meshes.channels_owned", meshes_channel_left, "last channel without mesh", MK_ERROR_CORRUPT, "meshes own 5 of the 6 channels", 0 },
    { "meshes.targets_owned", meshes_target_left, "last target without mesh", MK_ERROR_CORRUPT, "meshes own 8 of the 9 targets", 0 },
    { "mesh.targets_without_channel", mesh_target_without_channel, "mesh 2's last target without channel", MK_ERROR_CORRUPT, "mesh 2: its channels end at target 7, before its targets end at 8", 0 },

    { "channel.name", channel_name, "name past the strings", MK_ERROR_CORRUPT, "channel 3: name string offset", 0 },
    { "channel.origin", channel_origin, "origin 2^32 - 1", MK_ERROR_CORRUPT, "channel 0: origin string offset 4294967295 is out of range", 0 },
    { "channel.mesh", channel_mesh, "mesh 4 of 4", MK_ERROR_CORRUPT, "channel 5: mesh index 4 is out of range", 0 },
    { "channel.mesh", channel_mesh_huge, "mesh 2^28", MK_ERROR_CORRUPT, "channel 2: mesh index 268435456 is out of range", 0 },
    { "channel.outside_mesh", channel_other_mesh, "channel 1 claims mesh 2", MK_ERROR_CORRUPT, "channel 1: is not one of mesh 2's channels", 0 },
    { "channel.target_count", channel_no_targets, "no targets", MK_ERROR_CORRUPT, "channel 1: has no targets", 0 },
    { "channel.target_range", channel_targets_past_table, "2 targets from 8 of 9", MK_ERROR_CORRUPT, "channel 5: its 2 targets from 8 run past the end of the target table", 0 },
    { "channel.target_range", channel_first_target_past_table, "first target 10 of 9", MK_ERROR_CORRUPT, "channel 5: its 1 targets from 10 run past", 0 },
    { "channel.target_range", channel_targets_wrap, "2^32 - 2 targets (the end wraps)", MK_ERROR_CORRUPT, "channel 1: its 4294967294 targets from 3 run past", 0 },
    { "channel.targets_outside_mesh", channel_targets_other_mesh, "mesh 2's channel at mesh 0's target", MK_ERROR_CORRUPT, "channel 2: its targets are not inside mesh 2's targets", 0 },
    { "channel.targets_order", channel_targets_overlap, "targets overlap the previous channel's", MK_ERROR_CORRUPT, "channel 1: first target 2 does not follow the previous channel's targets (expected 3)", 0 },
    { "channel.targets_order", channel_targets_gap, "a gap before the channel's targets", MK_ERROR_CORRUPT, "channel 3: first target 6 does not follow the previous channel's targets (expected 5)", 0 },
    { "channel.default_weight", channel_default_nan, "NaN", MK_ERROR_NOT_FINITE, "channel 4: default weight is not finite", 0 },
    { "channel.default_weight", channel_default_inf, "inf", MK_ERROR_NOT_FINITE, "channel 0: default weight is not finite", 0 },
    { "channel.reserved", channel_reserved, "reserved[1]", MK_ERROR_CORRUPT, "channel 2: reserved field 1 is not zero", 0 },
    { "target.channel", target_channel, "target 5 says channel 2", MK_ERROR_CORRUPT, "target 5: channel index 2 does not match its channel 3", 0 },
    { "target.name", target_name, "name = string section size", MK_ERROR_CORRUPT, "target 7: name string offset", 0 },
    { "target.full_weight_finite", target_full_inf, "inf", MK_ERROR_NOT_FINITE, "target 1: full weight is not finite", 0 },
    { "target.full_weight_finite", target_full_nan, "NaN", MK_ERROR_NOT_FINITE, "target 8: full weight is not finite", 0 },
    { "target.full_weight_zero", target_full_zero, "0", MK_ERROR_CORRUPT, "target 4: full weight is zero or nearly", 0 },
    { "target.full_weight_zero", target_full_subnormal, "1e-42", MK_ERROR_CORRUPT, "target 3: full weight is zero or nearly", 0 },
    { "target.full_weight_zero", target_full_tiny_negative, "-5e-7", MK_ERROR_CORRUPT, "target 0: full weight is zero or nearly", 0 },
    { "target.full_weight_order", target_full_below_previous, "-0.75 after -0.5", MK_ERROR_CORRUPT, "target 1: full weight does not exceed target 0's by at least 1e-6", 0 },
    { "target.full_weight_order", target_full_equal, "0.5 after 0.5", MK_ERROR_CORRUPT, "target 6: full weight does not exceed target 5's", 0 },
    { "target.full_weight_order", target_full_gap_too_small, "0.5000005 after 0.5", MK_ERROR_CORRUPT, "target 2: full weight does not exceed target 1's", 0 },
    { "target.flags", target_flags, "flag 8", MK_ERROR_CORRUPT, "target 3: unknown flags (8)", 0 },
    { "target.normals", target_normals_without_mesh_normals, "normal deltas on mesh 3", MK_ERROR_CORRUPT, "target 8: has normal deltas but its mesh 3 has no base normals", 0 },
    { "target.tangents", target_tangents_without_mesh_tangents, "tangent deltas on mesh 2", MK_ERROR_CORRUPT, "target 4: has tangent deltas but its mesh 2 has no base tangents", 0 },
    { "target.scale_finite", target_position_scale_nan, "quantized position scale NaN", MK_ERROR_NOT_FINITE, ": position scale is not finite", Q16 },
    { "target.scale_finite", target_normal_scale_inf, "normal scale inf", MK_ERROR_NOT_FINITE, "target 2: normal scale is not finite", 0 },
    { "target.scale_negative", target_tangent_scale_negative, "quantized tangent scale -1", MK_ERROR_CORRUPT, ": tangent scale is negative", Q16 },
    { "target.scale_negative", target_position_scale_negative, "position scale -0.5", MK_ERROR_CORRUPT, "target 7: position scale is negative", 0 },

    { "mesh.block_table.align", block_table_misaligned, "block table at +4", MK_ERROR_BAD_ALIGNMENT, "mesh 2 block table: array is not 16-byte aligned", 0 },
    { "mesh.block_table.bounds", block_table_past_data, "block table at the end", MK_ERROR_CORRUPT, "mesh 2 block table: array of 4 x 4 bytes is not inside the DATA section", 0 },
    { "mesh.entries.align", entries_misaligned, "entries at +8", MK_ERROR_BAD_ALIGNMENT, "mesh 0 entries: array is not 16-byte aligned", 0 },
    { "mesh.entries.bounds", entries_past_data, "entries over the end", MK_ERROR_CORRUPT, "mesh 3 entries: array of 1 x 24 bytes is not inside the DATA section", 0 },
    { "mesh.entries.bounds", entries_count_overflow, "2^60 entries (the size overflows)", MK_ERROR_CORRUPT, "mesh 2 entries: array of 1152921504606846976 x 32 bytes", 0 },
    { "mesh.target_data.align", target_data_misaligned, "target data at +4", MK_ERROR_BAD_ALIGNMENT, "mesh 2 target data: array is not 16-byte aligned", 0 },
    { "mesh.target_data.bounds", target_data_past_data, "target data 16 bytes longer", MK_ERROR_CORRUPT, "mesh 3 target data: array of", 0 },
    { "block_table.first", block_table_first, "table starts at 1", MK_ERROR_CORRUPT, "mesh 2: block table starts at entry 1 instead of 0", 0 },
    { "block_table.last", block_table_last, "table ends one short", MK_ERROR_CORRUPT, "mesh 2: block table ends at entry 10 instead of the entry count 11", 0 },
    { "block_table.last", block_table_last_huge, "table ends at 2^32 - 1", MK_ERROR_CORRUPT, "mesh 0: block table ends at entry 4294967295", 0 },
    { "block_table.last", entry_count_more, "entry count one more", MK_ERROR_CORRUPT, "instead of the entry count 12", 0 },
    { "block_table.order", block_table_order, "block 1 starts at 10^6", MK_ERROR_CORRUPT, "mesh 2: block table decreases at block 2", 0 },
    { "block_table.order", block_table_order_dip, "block 2 starts before block 1", MK_ERROR_CORRUPT, "mesh 2: block table decreases at block 2", 0 },
    { "entry.target", entry_target, "target 4 of 4", MK_ERROR_CORRUPT, "mesh 0 entry 3: target index 4 is out of range", 0 },
    { "entry.target", entry_target_huge, "target 2^24 - 16", MK_ERROR_CORRUPT, "mesh 3 entry 0: target index 16777200 is out of range", 0 },
    { "entry.target", entry_target_huge, "quantized: target 2^24 - 16", MK_ERROR_CORRUPT, "mesh 3 entry 0: target index 16777200 is out of range", Q16 },
    { "entry.flags", entry_flags, "flag bit 24", MK_ERROR_CORRUPT, "mesh 0 entry 1: unknown flag bits 16777216", 0 },
    { "entry.flags", entry_flags_top, "quantized: flag bit 29", MK_ERROR_CORRUPT, "mesh 2 entry 3: unknown flag bits 536870912", Q16 },
    { "entry.precision", entry_packed_of_float_target, "a float target's entry without the float flag", MK_ERROR_CORRUPT, "mesh 2 entry 4: packed data for float target 0", 0 },
    { "entry.order", entry_duplicate, "two entries for target 0 in block 0", MK_ERROR_CORRUPT, "mesh 0 entry 1: target 0 repeats or precedes the previous entry's", 0 },
    { "entry.order", entry_misordered, "target 0 after target 1", MK_ERROR_CORRUPT, "mesh 2 entry 2: target 0 repeats or precedes", 0 },
    { "entry.mask_empty", entry_mask_empty, "mask 0", MK_ERROR_CORRUPT, "mesh 2 entry 5: vertex mask is empty", 0 },
    { "entry.mask_past_end", entry_mask_past_end_small, "vertex 4 of 4", MK_ERROR_CORRUPT, "mesh 0 entry 2: vertex mask has bits past the mesh's last vertex (block 0)", 0 },
    { "entry.mask_past_end", entry_mask_past_end_block, "vertex 150 of 150", MK_ERROR_CORRUPT, "mesh 2 entry 10: vertex mask has bits past the mesh's last vertex (block 2)", 0 },
    { "entry.data", entry_data_straddles, "the last data 4 bytes on, into the tail", MK_ERROR_CORRUPT, "mesh 3 entry 0: its 36 bytes of data and the 16-byte tail run past the mesh's target data", 0 },
    { "entry.data", entry_data_straddles, "quantized: the last data 4 bytes on", MK_ERROR_CORRUPT, "mesh 3 entry 0: its 0 bytes of data and the 16-byte tail run past", Q16 },
    { "entry.data", entry_data_far, "data at 16 GiB", MK_ERROR_CORRUPT, "mesh 2 entry 0: its 1536 bytes of data and the 16-byte tail run past", 0 },
    { "entry.data", entry_data_no_tail, "a 12-byte tail", MK_ERROR_CORRUPT, "mesh 3 entry 0: its 36 bytes of data and the 16-byte tail run past", 0 },
    { "entry.data", entry_data_no_tail, "quantized: a 12-byte tail", MK_ERROR_CORRUPT, "mesh 3 entry 0: its 0 bytes of data and the 16-byte tail run past", Q16 },
    { "entry.data", entry_float_last, "quantized: the last entry flagged float", MK_ERROR_CORRUPT, "mesh 3 entry 0: its 36 bytes of data and the 16-byte tail run past", Q16 },
    { "entry.data_finite", entry_data_nan, "a dense position delta NaN", MK_ERROR_NOT_FINITE, "mesh 2 entry 0: delta value 100 is not finite", 0 },
    { "entry.data_finite", entry_float_nan, "quantized: a float-flagged entry's delta NaN", MK_ERROR_NOT_FINITE, "mesh 0 entry 3: delta value 7 is not finite", Q16 },
    { "entry.data_finite", entry_normal_delta_inf, "a normal delta inf", MK_ERROR_NOT_FINITE, "mesh 0 entry 2: delta value 16 is not finite", 0 },
    { "entry.wide_precision", entry_wide_on_float, "WIDE on a float entry", MK_ERROR_CORRUPT, "mesh 2 entry 3: WIDE on float32 data", 0 },
    { "entry.float_packing", entry_float_code, "a float entry's width code", MK_ERROR_CORRUPT, "mesh 0 entry 1: float32 entry has a nonzero width code or offset", 0 },
    { "entry.float_packing", entry_float_offset, "a float entry's last offset", MK_ERROR_CORRUPT, "mesh 3 entry 0: float32 entry has a nonzero width code or offset", 0 },
    { "entry.code_padding", entry_code_padding_nibble, "quantized: the padding nibble of 3 codes", MK_ERROR_CORRUPT, "mesh 3 entry 0: width code 3 is not zero (it pads the codes", Q16 },
    { "entry.code_padding", entry_code_padding_byte, "quantized: the last padding nibble of 9 codes", MK_ERROR_CORRUPT, "mesh 0 entry 2: width code 11 is not zero", Q16 },
    { "entry.absent_attribute", entry_absent_normal_code, "quantized: a normal code of a positions-only target", MK_ERROR_CORRUPT, "mesh 2 entry 3: component 3 has a width code or offset but its target has no normal deltas", Q16 },
    { "entry.absent_attribute", entry_absent_tangent_offset, "quantized: a tangent offset of a positions-only target", MK_ERROR_CORRUPT, "mesh 0 entry 3: component 8 has a width code or offset but its target has no tangent deltas", Q16 },
    { "entry.wide_head", entry_wide_head, "quantized: WIDE with a head position offset", MK_ERROR_CORRUPT, "mesh 0 entry 0: WIDE entry's head position offset 2 is not zero", Q16 },
    { "entry.wide_range", entry_wide_past_max, "quantized: a WIDE offset of 2^23", MK_ERROR_CORRUPT, "mesh 0 entry 0: WIDE position offset 1 is beyond +-8388607", Q16 },
    { "entry.wide_range", entry_wide_int32_min, "quantized: a WIDE offset of -2^31", MK_ERROR_CORRUPT, "mesh 0 entry 0: WIDE position offset 2 is beyond", Q16 },

    { "clip.name", clip_name, "name = string section size", MK_ERROR_CORRUPT, "clip 1: name string offset", 0 },
    { "clip.first_track", clip_first_track, "clip 2 starts at track 2", MK_ERROR_CORRUPT, "clip 2: first track 2 does not follow the previous clip's tracks (expected 3)", 0 },
    { "clip.track_count", clip_track_count, "clip 2 has 3 tracks", MK_ERROR_CORRUPT, "clip 2: its 3 tracks run past the end of the track table (5 tracks)", 0 },
    { "clip.track_count", clip_track_count_wraps, "clip 0 has 2^32 - 1 tracks (the end wraps)", MK_ERROR_CORRUPT, "clip 0: its 4294967295 tracks run past", 0 },
    { "clip.start", clip_start, "start -inf", MK_ERROR_NOT_FINITE, "clip 2: start is not finite", 0 },
    { "clip.duration_finite", clip_duration_nan, "duration NaN", MK_ERROR_NOT_FINITE, "clip 0: duration is not finite", 0 },
    { "clip.duration_negative", clip_duration_negative, "duration -1", MK_ERROR_CORRUPT, "clip 2: duration is negative", 0 },
    { "clip.duration_negative", clip_duration_tiny_negative, "duration -1e-30", MK_ERROR_CORRUPT, "clip 1: duration is negative", 0 },
    { "clip.reserved", clip_reserved, "reserved[2]", MK_ERROR_CORRUPT, "clip 1: reserved field 2 is not zero", 0 },
    { "clips.tracks_owned", clips_track_left, "last track without clip", MK_ERROR_CORRUPT, "clips own 4 of the 5 tracks", 0 },
    { "track.channel", track_channel, "channel 6 of 6", MK_ERROR_CORRUPT, "track 0: channel index 6 is out of range", 0 },
    { "track.channel", track_channel_huge, "channel 2^28", MK_ERROR_CORRUPT, "track 3: channel index 268435456 is out of range", 0 },
    { "track.reserved", track_reserved, "reserved", MK_ERROR_CORRUPT, "track 3: reserved field is not zero", 0 },
    { "track.key_count", track_no_keys, "no keys", MK_ERROR_CORRUPT, "track 2: has no keys", 0 },
    { "track.first_key", track_first_key, "track 1 shares track 0's keys", MK_ERROR_CORRUPT, "track 1: first key 0 does not follow the previous track's keys (expected 3)", 0 },
    { "track.key_range", track_key_range, "last track has 3 keys", MK_ERROR_CORRUPT, "track 4: its 3 keys run past the end of the key table (10 keys)", 0 },
    { "tracks.keys_owned", tracks_key_left, "last key without track", MK_ERROR_CORRUPT, "tracks own 9 of the 10 keys", 0 },
    { "key.finite", key_time_nan, "time NaN", MK_ERROR_NOT_FINITE, "track 1 key 1: time is not finite", 0 },
    { "key.finite", key_right_slope_inf, "right slope inf", MK_ERROR_NOT_FINITE, "track 0 key 0: right slope is not finite", 0 },
    { "key.finite", key_left_weight_nan, "left weight NaN", MK_ERROR_NOT_FINITE, "track 4 key 1: left tangent weight is not finite", 0 },
    { "key.interp", key_interp, "interpolation 4", MK_ERROR_CORRUPT, "track 0 key 1: unknown interpolation 4", 0 },
    { "key.reserved", key_reserved, "reserved", MK_ERROR_CORRUPT, "track 3 key 0: reserved field is not zero", 0 },
    { "key.tangent_weight", key_right_weight_zero, "right weight 0", MK_ERROR_CORRUPT, "track 1 key 0: right tangent weight is outside (0, 1]", 0 },
    { "key.tangent_weight", key_left_weight_zero, "left weight 0", MK_ERROR_CORRUPT, "track 1 key 1: left tangent weight is outside (0, 1]", 0 },
    { "key.tangent_weight", key_right_weight_negative, "right weight -0.25", MK_ERROR_CORRUPT, "track 0 key 2: right tangent weight is outside", 0 },
    { "key.tangent_weight", key_left_weight_above_one, "left weight 1.5", MK_ERROR_CORRUPT, "track 0 key 1: left tangent weight is outside", 0 },
    { "key.time_order", key_time_equal, "equal times", MK_ERROR_CORRUPT, "track 2 key 1: time is not after the previous key's", 0 },
    { "key.time_order", key_time_decreasing, "time goes back", MK_ERROR_CORRUPT, "track 0 key 2: time is not after the previous key's", 0 },
};
#define CORRUPTION_COUNT (sizeof corruptions / sizeof corruptions[0])

/* ---- using an asset that opened ---- */

/* Everything the runtime promises after a successful open: names are strings, triangles index
 * vertices, every clip samples and every mesh evaluates (with normals, tangents, both normal
 * modes and both stackings). A missing check shows up here as an out-of-bounds read. */
static void use_asset(const mk_asset *a)
{
    volatile size_t sink = 0;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        if (!mk_mesh_get(a, i, &m)) continue;
        sink += strlen(m.name);
        for (uint64_t k = 0; k < 3ull * m.triangle_count; k++) sink += (size_t)m.positions[3 * (size_t)m.triangles[k]];
    }
    for (uint32_t i = 0; i < a->channel_count; i++) {
        mk_channel_info ch;
        if (!mk_channel_get(a, i, &ch)) continue;
        sink += strlen(ch.name) + strlen(ch.origin);
        for (uint32_t t = 0; t < ch.target_count && t < 64; t++) {
            mk_target_info ti;
            if (mk_target_get(a, i, t, &ti)) sink += strlen(ti.name);
        }
    }
    for (uint32_t i = 0; i < a->clip_count; i++) {
        mk_clip_info ci;
        if (mk_clip_get(a, i, &ci)) sink += strlen(ci.name);
    }
    sink += (size_t)(mk_find_mesh(a, "no such name") + mk_find_channel(a, "no such name") + mk_find_clip(a, "no such name"));
    (void)sink;

    /* Every buffer of exactly the size the asset asks for: ASan sees a write past it too. */
    if (a->channel_count > (1u << 20)) return;
    float *weights = malloc(a->channel_count ? a->channel_count * sizeof(float) : 1);
    if (!weights) abort();
    mk_error err;
    for (uint32_t i = 0; i < a->clip_count; i++)
        for (int loop = 0; loop < 2; loop++) {
            uint32_t tracks = a->clips[i].track_count;
            uint32_t *cursors = tracks && tracks <= 4096 ? calloc(tracks, sizeof *cursors) : NULL;
            mk_sample_job s = { .asset = a, .clip = i, .time = 0.37f + (float)loop, .weights = weights,
                                .weight_count = a->channel_count, .loop = loop, .cursors = cursors,
                                .cursor_count = tracks };
            mk_sample_run(&s, &err);
            free(cursors);
        }
    const float values[] = { 0.0f, 0.3f, -2.5f, 1.0f, 0.75f };
    for (uint32_t mi = 0; mi < a->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(a, mi, &m);
        size_t scratch_size = mk_eval_scratch_size(a, mi);
        if (m.vertex_count > (1u << 20) || scratch_size > ((size_t)1 << 24)) continue;
        float *out = malloc(12 * (size_t)m.vertex_count + !m.vertex_count);
        float *out_n = malloc(12 * (size_t)m.vertex_count + !m.vertex_count);
        float *out_t = malloc(16 * (size_t)m.vertex_count + !m.vertex_count);
        void *scratch = NULL;
        if (!out || !out_n || !out_t || posix_memalign(&scratch, 16, scratch_size) != 0) abort();
        for (int v = 0; v < 4; v++) {
            for (uint32_t c = 0; c < a->channel_count; c++) weights[c] = values[(c + (uint32_t)v) % 5];
            mk_eval_job j = { .asset = a, .mesh = mi, .vertex_count = MK_VERTICES_TO_END,
                              .weights = weights + m.first_channel, .weight_count = m.channel_count,
                              .stacking = (mk_stacking)(v % 3), .normal_mode = (mk_normal_mode)(v & 1),
                              .scratch = scratch, .scratch_size = scratch_size,
                              .positions = out, .positions_size = 12 * (size_t)m.vertex_count,
                              .normals = m.has_normals ? out_n : NULL, .normals_size = 12 * (size_t)m.vertex_count,
                              .tangents = m.has_tangents ? out_t : NULL, .tangents_size = 16 * (size_t)m.vertex_count };
            mk_eval_run(&j, &err);
        }
        free(out);
        free(out_n);
        free(out_t);
        free(scratch);
    }
    free(weights);
}

/* ---- running a corruption ---- */

/* Writes the blob, applies the patch, fixes the checksum and opens it. Returns 1 when it is
 * rejected with the expected code and message; *by_check is set when the expected check
 * rejected it. */
static int run_corruption(const corruption *k, int *by_check, const char **got)
{
    const fixture_blob_cache *intact = rich_blob(k->q16 ? MK_PRECISION_Q16 : MK_PRECISION_FLOAT);
    blob_case c;
    memset(&c, 0, sizeof c);
    c.size = intact->size;
    c.b = aligned_copy(intact->data, intact->size, intact->size + SLACK);
    mk_error err;
    const char *disabled = mk_open_disabled_check;
    mk_open_disabled_check = NULL;
    if (mk_asset_open(c.b, c.size, &c.a, &err) != MK_OK) {
        fprintf(stderr, "the intact blob does not open: %s\n", err.message);
        abort();
    }
    mk_open_disabled_check = disabled;
    k->patch(&c);
    if (!c.keep_checksum && c.size >= 64) {
        uint64_t sum = mk_checksum(c.b + 32, c.size - 32);
        memcpy(c.b + 24, &sum, 8);
    }
    /* The blob to open, in an allocation of exactly its size (ASan sees any overread). */
    unsigned char *holder = aligned_copy(c.b, c.size, c.call == CALL_MISALIGNED ? c.size + 8 : c.size);
    const unsigned char *blob = holder;
    if (c.call == CALL_MISALIGNED) {
        memmove(holder + 8, holder, c.size);
        blob = holder + 8;
    }
    mk_asset a;
    memset(&a, 0xA5, sizeof a);
    mk_open_rejected_by = NULL;
    mk_result r = mk_asset_open(c.call == CALL_NULL_DATA ? NULL : blob, c.size, c.call == CALL_NULL_OUT ? NULL : &a, &err);
    const char *by = mk_open_rejected_by ? mk_open_rejected_by : "(none)";
    int ok = r != MK_OK && r == k->code && strstr(err.message, k->message) != NULL;
    *by_check = strcmp(by, k->check) == 0;
    static char description[400];
    snprintf(description, sizeof description, "%s from %s: \"%s\"", mk_result_name(r), by, r ? err.message : "");
    *got = description;
    if (disabled) {                /* printed before the blob is used: that may crash */
        printf("  %s disabled, %s: %s -> %s\n", k->check, k->what, description, ok ? "STILL PASSES" : "fails");
        fflush(stdout);
    }
    if (r == MK_OK) {
        use_asset(&a);             /* what the check should have kept away */
    } else if (c.call != CALL_NULL_OUT) {
        static const mk_asset zero;
        CHECK_MSG(memcmp(&a, &zero, sizeof a) == 0, "%s (%s): *out is not zeroed on failure", k->check, k->what);
    }
    free(holder);
    free(c.b);
    return ok;
}

static const char *disabled_check(void)
{
    const char *d = getenv("MK_OPEN_DISABLE");
    return d && *d ? d : NULL;
}

/* Normally: every corruption is rejected by its check, with its code and message.
 * With MK_OPEN_DISABLE=<check>: only that check's corruptions run, with its condition forced
 * false; each must then fail by its code and message alone (so the test bites even without
 * the check names of test builds). The case passes when they all fail. */
static void test_every_corruption(void)
{
    const char *disabled = disabled_check();
    mk_open_disabled_check = disabled;
    int ran = 0, still_pass = 0;
    for (size_t i = 0; i < CORRUPTION_COUNT; i++) {
        const corruption *k = &corruptions[i];
        if (disabled && strcmp(k->check, disabled) != 0) continue;
        ran++;
        int by_check;
        const char *got;
        int ok = run_corruption(k, &by_check, &got);
        if (!disabled)
            CHECK_MSG(ok && by_check, "%s (%s): expected %s from %s with \"%s\"; got %s", k->check, k->what,
                      mk_result_name(k->code), k->check, k->message, got);
        still_pass += ok;
    }
    mk_open_disabled_check = NULL;
    if (disabled) {
        CHECK_MSG(ran > 0, "no corruption names check %s", disabled);
        CHECK_MSG(still_pass == 0, "%d of %d corruptions of %s still pass with the check disabled", still_pass, ran, disabled);
        printf("%s %s: %d of %d corruptions fail without it\n", ran && !still_pass ? "BITES" : "DOES NOT BITE", disabled,
               ran - still_pass, ran);
    }
}

/* ---- the checks listed from the source ---- */

typedef struct name_list {
    char names[256][64];
    int count;
} name_list;

static void add_name(name_list *l, const char *name)
{
    if (l->count == 256) { CHECK_MSG(0, "more than 256 checks"); return; }
    snprintf(l->names[l->count++], sizeof l->names[0], "%s", name);
}

static int has_name(const name_list *l, const char *name)
{
    for (int i = 0; i < l->count; i++)
        if (strcmp(l->names[i], name) == 0) return 1;
    return 0;
}

static char *read_source(const char *relative)
{
    const char *root = getenv("MORPHKIT_SOURCE_ROOT");
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", root && *root ? root : MK_SOURCE_ROOT, relative);
    char *text = (char *)check_read_file(path, NULL);
    CHECK_MSG(text != NULL, "cannot read %s", path);
    return text;
}

/* The source with its comments blanked out (string literals kept). */
static void blank_comments(char *s)
{
    for (char *p = s; *p; p++) {
        if (*p == '"') {
            for (p++; *p && *p != '"'; p++)
                if (*p == '\\' && p[1]) p++;
            if (!*p) return;
        } else if (p[0] == '/' && p[1] == '*') {
            for (; *p && !(p[0] == '*' && p[1] == '/'); p++)
                if (*p != '\n') *p = ' ';
            if (!*p) return;
            p[0] = p[1] = ' ';
            p++;
        } else if (p[0] == '/' && p[1] == '/') {
            for (; *p && *p != '\n'; p++) *p = ' ';
            if (!*p) return;
        }
    }
}

/* Every FAILS("name", ...) and CHECK_ARRAY("name", ...) (two checks: name.align,
 * name.bounds) in open.c. */
static void list_checks(const char *source, name_list *out)
{
    static const struct { const char *marker; const char *suffixes[2]; } kinds[] = {
        { "FAILS(\"", { "", NULL } },
        { "CHECK_ARRAY(\"", { ".align", ".bounds" } },
    };
    for (size_t k = 0; k < 2; k++)
        for (const char *p = strstr(source, kinds[k].marker); p; p = strstr(p + 1, kinds[k].marker)) {
            const char *begin = p + strlen(kinds[k].marker), *end = strchr(begin, '"');
            if (!end) break;
            for (int s = 0; s < 2 && kinds[k].suffixes[s]; s++) {
                char name[64];
                snprintf(name, sizeof name, "%.*s%s", (int)(end - begin), begin, kinds[k].suffixes[s]);
                CHECK_MSG(!has_name(out, name), "open.c names two checks %s", name);
                add_name(out, name);
            }
        }
}

/* Every error open.c returns comes from a check named with FAILS: each "return fail" and each
 * message started in check_array or by hand lies in a statement whose condition is FAILS. */
static void check_failures_are_named(const char *source)
{
    const char *body = strstr(source, "typedef struct region");   /* after the message helpers */
    CHECK(body != NULL);
    if (!body) return;
    static const char *const markers[] = { "return fail", "start_message(v->err" };
    for (size_t k = 0; k < 2; k++)
        for (const char *p = strstr(body, markers[k]); p; p = strstr(p + 1, markers[k])) {
            const char *cond = NULL;
            for (const char *q = p; q > body; q--)
                if (strncmp(q, "if (", 4) == 0) { cond = q; break; }
            int line = 1;
            for (const char *q = source; q < p; q++) line += *q == '\n';
            CHECK_MSG(cond && strncmp(cond, "if (FAILS(", 10) == 0, "runtime/open.c:%d: an error not named by FAILS", line);
        }
    CHECK_MSG(strstr(body, "return MK_ERROR") == NULL, "runtime/open.c returns an error code without a message");
}

static void test_every_check_has_a_test(void)
{
    char *source = read_source("runtime/open.c");
    char *doc = read_source("docs/format.md");
    if (!source || !doc) { free(source); free(doc); return; }
    blank_comments(source);
    static name_list checks;
    checks.count = 0;
    list_checks(source, &checks);
    CHECK_MSG(checks.count >= 90, "only %d checks found in open.c", checks.count);
    check_failures_are_named(source);
    for (int i = 0; i < checks.count; i++) {
        int tested = 0;
        for (size_t k = 0; k < CORRUPTION_COUNT; k++) tested |= strcmp(corruptions[k].check, checks.names[i]) == 0;
        CHECK_MSG(tested, "check %s has no corruption test", checks.names[i]);
        char quoted[80];
        snprintf(quoted, sizeof quoted, "`%s`", checks.names[i]);
        CHECK_MSG(strstr(doc, quoted) != NULL, "docs/format.md does not list check %s", checks.names[i]);
    }
    for (size_t k = 0; k < CORRUPTION_COUNT; k++)
        CHECK_MSG(has_name(&checks, corruptions[k].check), "a corruption names %s, which open.c does not have",
                  corruptions[k].check);
    /* docs/format.md lists no check that is gone: its table rows are "| `name` | ...". */
    for (const char *p = strstr(doc, "\n| `"); p; p = strstr(p + 1, "\n| `")) {
        const char *begin = p + 4, *end = strchr(begin, '`');
        if (!end) break;
        char name[64];
        snprintf(name, sizeof name, "%.*s", (int)(end - begin), begin);
        CHECK_MSG(has_name(&checks, name), "docs/format.md lists check %s, which open.c does not have", name);
    }
    printf("  %d checks in open.c, %zu corruptions\n", checks.count, CORRUPTION_COUNT);
    free(source);
    free(doc);
}

/* The fixture has what the corruptions rely on. */
static void test_fixture_has_every_structure(void)
{
    for (int p = 0; p < 2; p++) {
        const fixture_blob_cache *intact = rich_blob(p ? MK_PRECISION_Q16 : MK_PRECISION_FLOAT);
        unsigned char *b = aligned_copy(intact->data, intact->size, intact->size);
        mk_asset a;
        mk_error err;
        CHECK(mk_asset_open(b, intact->size, &a, &err) == MK_OK);
        CHECK_EQ_INT(a.mesh_count, 4);
        CHECK_EQ_INT(a.channel_count, 6);
        CHECK_EQ_INT(a.target_count, 9);
        CHECK_EQ_INT(a.clip_count, 3);
        CHECK_EQ_INT(a.track_count, 5);
        CHECK_EQ_INT(a.key_count, 10);
        CHECK_EQ_INT(a.meshes[1].channel_count, 0);
        CHECK_EQ_INT(a.meshes[0].flags, MK_MESH_HAS_NORMALS | MK_MESH_HAS_TANGENTS);
        CHECK_EQ_INT(a.meshes[2].stacking, MK_STACKING_SEQUENTIAL);
        CHECK_EQ_INT(a.meshes[0].entry_count, 4);
        CHECK_EQ_INT(a.meshes[2].entry_count, 11);
        CHECK_EQ_INT(a.targets[2].flags & ~(uint32_t)MK_TARGET_QUANTIZED, MK_TARGET_HAS_NORMALS | MK_TARGET_HAS_TANGENTS);
        CHECK(a.targets[0].full_weight < 0);
        /* Entries of every stride: positions (mesh 3), and normals (mesh 2), and tangents (mesh 0). */
        CHECK_EQ_INT(mk_entry_stride(a.meshes[0].flags), 40);
        CHECK_EQ_INT(mk_entry_stride(a.meshes[2].flags), 32);
        CHECK_EQ_INT(mk_entry_stride(a.meshes[3].flags), 24);
        int dense = 0, sparse = 0, quantized = 0, float_entries = 0, wide = 0, entries = 0;
        for (uint32_t m = 0; m < a.mesh_count; m++)
            for (uint64_t e = 0; e < a.meshes[m].entry_count; e++) {
                const mk_blob_entry *en = mk_entry_at(a.data + a.meshes[m].entries, mk_entry_stride(a.meshes[m].flags), e);
                dense += en->mask == ~0ull;
                sparse += mk_popcount64(en->mask) < 8;
                float_entries += !mk_entry_packed(en);
                wide += mk_entry_wide(en);
                entries++;
            }
        CHECK(p ? float_entries == 0 : float_entries == entries);   /* a float blob's entries all say so */
        CHECK_EQ_INT(wide, 0);                                       /* the WIDE patches make their own */
        for (uint32_t t = 0; t < a.target_count; t++) quantized += (a.targets[t].flags & MK_TARGET_QUANTIZED) != 0;
        CHECK(dense >= 2);
        CHECK(sparse >= 4);
        CHECK(p ? quantized == 9 : quantized == 0);
        CHECK_NEAR(a.keys[3].right_weight, 0.25f, 0);
        CHECK_EQ_INT(a.keys[0].interp, MK_INTERP_CUBIC);
        CHECK_EQ_INT(a.clips[1].track_count, 0);
        /* The data ends the blob (but for the padding of the blob to 16 bytes). */
        CHECK(intact->size - (a.meshes[3].target_data + a.meshes[3].target_data_size) < MK_ALIGN);
        use_asset(&a);
        free(b);
    }
}

/* The WIDE checks are not too strict: offsets of +-(2^23 - 1) open and evaluate to
 * (offset + value) x step exactly as the head's int16 offsets would. */
static void test_wide_entry_at_the_limits_opens(void)
{
    const fixture_blob_cache *intact = rich_blob(MK_PRECISION_Q16);
    blob_case c;
    memset(&c, 0, sizeof c);
    c.size = intact->size;
    c.b = aligned_copy(intact->data, intact->size, intact->size);
    mk_error err;
    CHECK(mk_asset_open(c.b, c.size, &c.a, &err) == MK_OK);
    const int16_t head_z = (int16_t)mk_entry_offset(entry(&c, 0, 0), components(&c, 0), 2);
    make_wide(&c, MK_WIDE_OFFSET_MAX, -MK_WIDE_OFFSET_MAX, head_z);
    uint64_t sum = mk_checksum(c.b + 32, c.size - 32);
    memcpy(c.b + 24, &sum, 8);
    mk_asset a;
    CHECK_MSG(mk_asset_open(c.b, c.size, &a, &err) == MK_OK, "%s", err.message);
    CHECK_EQ_INT(mk_mesh_wide_entries(&a, 0), 1);
    /* Only target 0 weighted: vertex v moves by (offset + value) x step; x and y store width
     * 0 (every vertex has the offset), z keeps its offset and values. */
    mk_mesh_info m;
    mk_mesh_get(&a, 0, &m);
    float weights[4] = { 0 }, out[12], base[12];
    weights[0] = a.targets[0].full_weight;   /* channel 0 at target 0's full weight: its coefficient 1 */
    size_t scratch_size = mk_eval_scratch_size(&a, 0);
    void *scratch = NULL;
    if (posix_memalign(&scratch, 16, scratch_size ? scratch_size : 16) != 0) abort();
    mk_eval_job j = { .asset = &a, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = weights, .weight_count = m.channel_count,
                      .scratch = scratch, .scratch_size = scratch_size, .positions = out, .positions_size = sizeof out };
    CHECK_MSG(mk_eval_run(&j, &err) == MK_OK, "%s", err.message);
    const mk_blob_entry *en = entry(&c, 0, 0);
    CHECK_EQ_INT(mk_entry_code(en, 0), 0);
    CHECK_EQ_INT(mk_entry_code(en, 1), 0);
    memcpy(base, m.positions, sizeof base);
    const float step = a.targets[0].position_scale;
    for (int v = 0; v < 4; v++) {
        CHECK_NEAR(out[3 * v], base[3 * v] + (float)MK_WIDE_OFFSET_MAX * step, 1e-3);
        CHECK_NEAR(out[3 * v + 1], base[3 * v + 1] - (float)MK_WIDE_OFFSET_MAX * step, 1e-3);
    }
    free(scratch);
    free(c.b);
}

CHECK_MAIN(CASE(test_fixture_has_every_structure), CASE(test_every_corruption), CASE(test_every_check_has_a_test),
           CASE(test_wide_entry_at_the_limits_opens))

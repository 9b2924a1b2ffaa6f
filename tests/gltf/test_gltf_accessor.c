/* SPDX-License-Identifier: MIT */
/* glTF accessor decoding with exact expectations: every component type, normalized and not, at
 * its endpoints and a few interior values; byteStride; sparse substitution (over a bufferView
 * and over zeros, every index component type, the bound at count - 1 / count, unsorted and
 * duplicate indices); index accessors; and one import that carries quantized and sparse data to
 * the raw model.
 *
 * The documents are built here (JSON with the buffer as a data: URI) and parsed with
 * mk_gltf_doc_load; the decoded floats must equal, bit for bit, the glTF 2.0 formulas written
 * out below in double and rounded once to float:
 *   BYTE            max(c / 127.0, -1.0)     UNSIGNED_BYTE   c / 255.0
 *   SHORT           max(c / 32767.0, -1.0)   UNSIGNED_SHORT  c / 65535.0
 * Non-normalized integers are their value; FLOAT is its bits. A wrong divisor, a missing clamp
 * or a sparse bound off by one changes at least one compared value. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "gltf_test_util.h"
#include "gltf_accessor.h"
#include "gltf_import.h"

/* ---- documents ---- */

/* A glTF document: one buffer holding bin[0..n) as a data: URI, then `rest` (more top-level
 * members, starting with a comma: bufferViews, accessors, meshes...). */
static char *gltf_text(const void *bin, size_t n, const char *rest)
{
    char *b64 = gt_base64(bin, n);
    size_t len = strlen(b64) + strlen(rest) + 256;
    char *json = malloc(len);
    snprintf(json, len,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
             "\"uri\":\"data:application/octet-stream;base64,%s\"}]%s}", n, b64, rest);
    free(b64);
    return json;
}

typedef struct doc {
    mk_arena arena;
    mk_gltf_doc doc;
    mk_gltf_reader reader;
    int ok;
} doc;

/* Parses a document of one buffer (bin), `views` (JSON array body) and `accessors`. */
static int doc_load(doc *d, const void *bin, size_t n, const char *views, const char *accessors)
{
    size_t len = strlen(views) + strlen(accessors) + 64;
    char *rest = malloc(len);
    snprintf(rest, len, ",\"bufferViews\":[%s],\"accessors\":[%s]", views, accessors);
    char *json = gltf_text(bin, n, rest);
    free(rest);
    memset(d, 0, sizeof *d);
    mk_arena_init(&d->arena, NULL);
    mk_error err;
    memset(&err, 0, sizeof err);
    mk_result r = mk_gltf_doc_load(&d->arena, json, strlen(json), 0, NULL, 0, NULL, NULL, &d->doc, &err);
    free(json);
    CHECK_MSG(r == MK_OK, "document does not load: %s", err.message);
    if (r == MK_OK) {
        r = mk_gltf_reader_init(&d->reader, &d->doc, &d->arena, &err);
        CHECK_MSG(r == MK_OK, "reader: %s", err.message);
    }
    d->ok = r == MK_OK;
    return d->ok;
}

static void doc_free(doc *d)
{
    if (d->ok) mk_gltf_doc_free(&d->doc);
    mk_arena_free_all(&d->arena);
}

/* Accessor `acc` as floats (components each); returns the result code, fills *values and *count. */
static mk_result read_floats(doc *d, int acc, int components, float **values, uint64_t *count, mk_error *err)
{
    memset(err, 0, sizeof *err);
    *values = NULL;
    *count = 0;
    return mk_gltf_read_floats(&d->reader, acc, components, "test", values, count, err);
}

/* Float bits equal (so -0 and +0 differ, and NaN never matches). */
static int same_float(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* Checks accessor `acc` decodes to exactly expect[0..n). */
static void expect_floats(doc *d, int acc, int components, const float *expect, uint64_t n, const char *label)
{
    float *v;
    uint64_t count;
    mk_error err;
    mk_result r = read_floats(d, acc, components, &v, &count, &err);
    CHECK_MSG(r == MK_OK, "%s: accessor %d: %s", label, acc, err.message);
    if (r != MK_OK) return;
    CHECK_MSG(count * (uint64_t)components == n, "%s: accessor %d: %llu elements", label, acc, (unsigned long long)count);
    for (uint64_t i = 0; i < n && i < count * (uint64_t)components; i++)
        CHECK_MSG(same_float(v[i], expect[i]), "%s: accessor %d value %llu = %.9g, expected %.9g", label, acc,
                  (unsigned long long)i, (double)v[i], (double)expect[i]);
}

/* Checks accessor `acc` fails with `code` and a message naming "accessor <acc>" and `needle`. */
static void expect_refused(doc *d, int acc, int components, mk_result code, const char *needle)
{
    float *v;
    uint64_t count;
    mk_error err;
    mk_result r = read_floats(d, acc, components, &v, &count, &err);
    char name[32];
    snprintf(name, sizeof name, "accessor %d", acc);
    CHECK_MSG(r == code, "accessor %d: expected %s, got %s (%s)", acc, mk_result_name(code), mk_result_name(r), err.message);
    CHECK_MSG(strstr(err.message, name) != NULL, "message '%s' does not name '%s'", err.message, name);
    CHECK_MSG(strstr(err.message, needle) != NULL, "message '%s' does not say '%s'", err.message, needle);
}

/* The spec's normalized conversions, in double, rounded once to float. */
static float snorm8(int c) { return (float)fmax(c / 127.0, -1.0); }
static float unorm8(int c) { return (float)(c / 255.0); }
static float snorm16(int c) { return (float)fmax(c / 32767.0, -1.0); }
static float unorm16(int c) { return (float)(c / 65535.0); }

/* ---- component types ---- */

static const int8_t i8[] = { -128, -127, -126, -64, -1, 0, 1, 2, 63, 64, 126, 127 };
static const uint8_t u8[] = { 0, 1, 2, 127, 128, 254, 255 };
static const int16_t i16[] = { -32768, -32767, -32766, -16384, -1, 0, 1, 16384, 32766, 32767 };
static const uint16_t u16[] = { 0, 1, 2, 32767, 32768, 65534, 65535 };
#define N8 (sizeof i8 / sizeof *i8)
#define NU8 (sizeof u8 / sizeof *u8)
#define N16 (sizeof i16 / sizeof *i16)
#define NU16 (sizeof u16 / sizeof *u16)

/* Layout: BYTE at 0 (12), UNSIGNED_BYTE at 12 (7), SHORT at 20 (20), UNSIGNED_SHORT at 40 (14),
 * FLOAT at 56 (7), UNSIGNED_INT at 84 (3). Accessors 0..3 normalized, 4..7 the same data not
 * normalized, 8 FLOAT, 9 FLOAT with "normalized": true, 10/11 UNSIGNED_INT (not / normalized). */
static const float floats[] = { 0.0f, -0.0f, 1.5f, -2.25f, 1e-30f, 3.0e38f, 1.4e-45f };
#define NF (sizeof floats / sizeof *floats)

static int component_doc(doc *d)
{
    unsigned char bin[96];
    memset(bin, 0xEE, sizeof bin);
    memcpy(bin, i8, sizeof i8);
    memcpy(bin + 12, u8, sizeof u8);
    memcpy(bin + 20, i16, sizeof i16);
    memcpy(bin + 40, u16, sizeof u16);
    memcpy(bin + 56, floats, sizeof floats);
    const uint32_t u32[3] = { 0, 1, 4294967295u };
    memcpy(bin + 84, u32, sizeof u32);
    char acc[2048];
    snprintf(acc, sizeof acc,
             "{\"bufferView\":0,\"byteOffset\":0,\"componentType\":5120,\"normalized\":true,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5121,\"normalized\":true,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":20,\"componentType\":5122,\"normalized\":true,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":40,\"componentType\":5123,\"normalized\":true,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":0,\"componentType\":5120,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5121,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":20,\"componentType\":5122,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":40,\"componentType\":5123,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":56,\"componentType\":5126,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":56,\"componentType\":5126,\"normalized\":true,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":84,\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"},"
             "{\"bufferView\":0,\"byteOffset\":84,\"componentType\":5125,\"normalized\":true,\"count\":3,\"type\":\"SCALAR\"}",
             N8, NU8, N16, NU16, N8, NU8, N16, NU16, NF, NF);
    return doc_load(d, bin, sizeof bin, "{\"buffer\":0,\"byteLength\":96}", acc);
}

static void test_normalized_endpoints(void)
{
    doc d;
    if (!component_doc(&d)) { doc_free(&d); return; }
    float e[16];
    /* BYTE: -128 and -127 both give -1 (the clamp), 127 gives 1. */
    for (size_t i = 0; i < N8; i++) e[i] = snorm8(i8[i]);
    CHECK(e[0] == -1.0f && e[1] == -1.0f && e[5] == 0.0f && e[11] == 1.0f);
    CHECK(e[9] == 0.503937007874015748f);        /* 64 / 127 */
    CHECK(e[2] == -0.992125984251968504f);       /* -126 / 127 */
    expect_floats(&d, 0, 1, e, N8, "BYTE normalized");
    for (size_t i = 0; i < NU8; i++) e[i] = unorm8(u8[i]);
    CHECK(e[0] == 0.0f && e[6] == 1.0f);
    CHECK(e[4] == 0.501960784313725490f);        /* 128 / 255 */
    expect_floats(&d, 1, 1, e, NU8, "UNSIGNED_BYTE normalized");
    for (size_t i = 0; i < N16; i++) e[i] = snorm16(i16[i]);
    CHECK(e[0] == -1.0f && e[1] == -1.0f && e[5] == 0.0f && e[9] == 1.0f);
    CHECK(e[7] == 0.500015259254738005f);        /* 16384 / 32767 */
    CHECK(e[3] == -0.500015259254738005f);
    expect_floats(&d, 2, 1, e, N16, "SHORT normalized");
    for (size_t i = 0; i < NU16; i++) e[i] = unorm16(u16[i]);
    CHECK(e[0] == 0.0f && e[6] == 1.0f);
    CHECK(e[4] == 0.500007629510948349f);        /* 32768 / 65535 */
    expect_floats(&d, 3, 1, e, NU16, "UNSIGNED_SHORT normalized");
    doc_free(&d);
}

static void test_integers_and_floats(void)
{
    doc d;
    if (!component_doc(&d)) { doc_free(&d); return; }
    float e[16];
    for (size_t i = 0; i < N8; i++) e[i] = (float)i8[i];
    expect_floats(&d, 4, 1, e, N8, "BYTE");
    for (size_t i = 0; i < NU8; i++) e[i] = (float)u8[i];
    expect_floats(&d, 5, 1, e, NU8, "UNSIGNED_BYTE");
    for (size_t i = 0; i < N16; i++) e[i] = (float)i16[i];
    expect_floats(&d, 6, 1, e, N16, "SHORT");
    for (size_t i = 0; i < NU16; i++) e[i] = (float)u16[i];
    expect_floats(&d, 7, 1, e, NU16, "UNSIGNED_SHORT");
    /* FLOAT: the bits as stored (-0 stays -0, a subnormal stays), "normalized" ignored. */
    expect_floats(&d, 8, 1, floats, NF, "FLOAT");
    expect_floats(&d, 9, 1, floats, NF, "FLOAT normalized:true");
    /* UNSIGNED_INT is for indices only: no float data, normalized or not. */
    expect_refused(&d, 10, 1, MK_ERROR_PARSE, "UNSIGNED_INT");
    expect_refused(&d, 11, 1, MK_ERROR_PARSE, "UNSIGNED_INT");
    /* The element type must match what the caller reads. */
    expect_refused(&d, 8, 3, MK_ERROR_PARSE, "components");
    doc_free(&d);
}

/* ---- byteStride ---- */

static void test_byte_stride(void)
{
    unsigned char bin[128];
    memset(bin, 0xEE, sizeof bin);           /* padding bytes must never be read */
    /* view 0 (stride 4): UNSIGNED_BYTE VEC3 normalized, 3 elements in 4-byte slots, the last
     * element ending at the view's end (11 bytes, not 12). */
    const uint8_t ub[9] = { 0, 128, 255, 1, 2, 3, 254, 127, 64 };
    for (int i = 0; i < 3; i++) memcpy(bin + 4 * i, ub + 3 * i, 3);
    /* view 1 (stride 8) at 12: SHORT VEC3 normalized, 2 elements, the first at byteOffset 2. */
    const int16_t sh[6] = { -32768, 0, 32767, -16384, 1, -1 };
    for (int i = 0; i < 2; i++) memcpy(bin + 12 + 2 + 8 * i, sh + 3 * i, 6);
    /* view 2 (stride 24) at 32: interleaved FLOAT VEC3 position + VEC3 normal, 2 elements. */
    const float pn[12] = { 1, 2, 3, 0, 0, 1, -4, -5, -6, 0, 1, 0 };
    memcpy(bin + 32, pn, sizeof pn);
    const char *views =
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":11,\"byteStride\":4},"
        "{\"buffer\":0,\"byteOffset\":12,\"byteLength\":16,\"byteStride\":8},"
        "{\"buffer\":0,\"byteOffset\":32,\"byteLength\":48,\"byteStride\":24},"
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":10,\"byteStride\":4},"      /* one byte short of view 0 */
        "{\"buffer\":0,\"byteOffset\":32,\"byteLength\":48,\"byteStride\":8}";     /* stride < 12-byte element */
    const char *acc =
        "{\"bufferView\":0,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"},"
        "{\"bufferView\":1,\"byteOffset\":2,\"componentType\":5122,\"normalized\":true,\"count\":2,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"byteOffset\":12,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
        "{\"bufferView\":3,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"},"
        "{\"bufferView\":4,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
        "{\"bufferView\":1,\"byteOffset\":4,\"componentType\":5122,\"normalized\":true,\"count\":2,\"type\":\"VEC3\"}";
    doc d;
    if (!doc_load(&d, bin, sizeof bin, views, acc)) { doc_free(&d); return; }
    float e[9];
    for (int i = 0; i < 9; i++) e[i] = unorm8(ub[i]);
    expect_floats(&d, 0, 3, e, 9, "UNSIGNED_BYTE VEC3 stride 4");
    for (int i = 0; i < 6; i++) e[i] = snorm16(sh[i]);
    expect_floats(&d, 1, 3, e, 6, "SHORT VEC3 stride 8");
    const float pos[6] = { 1, 2, 3, -4, -5, -6 }, nrm[6] = { 0, 0, 1, 0, 1, 0 };
    expect_floats(&d, 2, 3, pos, 6, "interleaved positions");
    expect_floats(&d, 3, 3, nrm, 6, "interleaved normals");
    expect_refused(&d, 4, 3, MK_ERROR_TRUNCATED, "bufferView 3");
    expect_refused(&d, 5, 3, MK_ERROR_PARSE, "byteStride 8 smaller");
    /* byteOffset 4 + 8 + 6 = 18 bytes > 16: the second element runs past view 1. */
    expect_refused(&d, 6, 3, MK_ERROR_TRUNCATED, "bufferView 1");
    doc_free(&d);
}

/* ---- sparse ---- */

/* Layout: base FLOAT[5] = 10..14 at 0; sparse indices {1, 4} as UNSIGNED_BYTE at 20,
 * UNSIGNED_SHORT at 24, UNSIGNED_INT at 28; FLOAT values {-1, -4} at 36; more index lists
 * at 44.. (see the accessors). One bufferView covers the buffer. */
static void test_sparse(void)
{
    unsigned char bin[128];
    memset(bin, 0, sizeof bin);
    const float base[5] = { 10, 11, 12, 13, 14 }, values[2] = { -1, -4 };
    memcpy(bin, base, sizeof base);
    const uint8_t i_u8[2] = { 1, 4 };
    const uint16_t i_u16[2] = { 1, 4 };
    const uint32_t i_u32[2] = { 1, 4 };
    memcpy(bin + 20, i_u8, 2);
    memcpy(bin + 24, i_u16, 4);
    memcpy(bin + 28, i_u32, 8);
    memcpy(bin + 36, values, 8);
    const uint16_t unsorted[2] = { 4, 1 }, dup[2] = { 1, 1 };
    memcpy(bin + 44, unsorted, 4);
    memcpy(bin + 48, dup, 4);
    /* The same list {1, 4} as BYTE / SHORT / FLOAT, which are not index types. */
    const int16_t i_i16[2] = { 1, 4 };
    const float i_f32[2] = { 1, 4 };
    memcpy(bin + 52, i_u8, 2);
    memcpy(bin + 56, i_i16, 4);
    memcpy(bin + 60, i_f32, 8);
#define SPARSE(count, itype, ioff, scount) \
    "{\"bufferView\":0,\"componentType\":5126,\"count\":" #count ",\"type\":\"SCALAR\",\"sparse\":{\"count\":" #scount "," \
    "\"indices\":{\"bufferView\":0,\"byteOffset\":" #ioff ",\"componentType\":" #itype "}," \
    "\"values\":{\"bufferView\":0,\"byteOffset\":36}}}"
#define SPARSE0(count, itype, ioff, scount) \
    "{\"componentType\":5126,\"count\":" #count ",\"type\":\"SCALAR\",\"sparse\":{\"count\":" #scount "," \
    "\"indices\":{\"bufferView\":0,\"byteOffset\":" #ioff ",\"componentType\":" #itype "}," \
    "\"values\":{\"bufferView\":0,\"byteOffset\":36}}}"
    const char *acc =
        SPARSE(5, 5121, 20, 2) "," SPARSE(5, 5123, 24, 2) "," SPARSE(5, 5125, 28, 2) ","       /* 0-2: over the view */
        SPARSE0(5, 5121, 20, 2) "," SPARSE0(5, 5123, 24, 2) "," SPARSE0(5, 5125, 28, 2) ","    /* 3-5: over zeros */
        SPARSE(4, 5121, 20, 2) "," SPARSE(4, 5123, 24, 2) "," SPARSE0(4, 5125, 28, 2) ","      /* 6-8: index 4 == count */
        SPARSE(3, 5121, 20, 2) "," SPARSE0(3, 5125, 28, 2) ","                                 /* 9-10: index 4 > count */
        SPARSE(5, 5123, 44, 2) "," SPARSE(5, 5123, 48, 2) ","                                  /* 11-12: 4,1 and 1,1 */
        SPARSE(5, 5120, 52, 2) "," SPARSE(5, 5122, 56, 2) "," SPARSE(5, 5126, 60, 2) ","       /* 13-15: bad index types */
        SPARSE(5, 5123, 24, 6) "," SPARSE(5, 5123, 24, 0) ","                                  /* 16-17: sparse count 6, 0 */
        SPARSE(5, 5123, 126, 2) "," SPARSE(2, 5121, 20, 1);                                    /* 18: indices past the view; 19: {1} of 2 */
#undef SPARSE
#undef SPARSE0
    doc d;
    if (!doc_load(&d, bin, sizeof bin, "{\"buffer\":0,\"byteLength\":128}", acc)) { doc_free(&d); return; }
    const float over[5] = { 10, -1, 12, 13, -4 }, zeros[5] = { 0, -1, 0, 0, -4 };
    const char *type_names[3] = { "UNSIGNED_BYTE", "UNSIGNED_SHORT", "UNSIGNED_INT" };
    for (int t = 0; t < 3; t++) {
        expect_floats(&d, t, 1, over, 5, type_names[t]);       /* index 4 = count - 1 is the last element */
        expect_floats(&d, 3 + t, 1, zeros, 5, type_names[t]);
    }
    for (int a = 6; a <= 10; a++) expect_refused(&d, a, 1, MK_ERROR_PARSE, "sparse index 4 (entry 1) is past");
    expect_refused(&d, 11, 1, MK_ERROR_PARSE, "sparse index 1 (entry 1) after 4: sparse indices must strictly increase");
    expect_refused(&d, 12, 1, MK_ERROR_PARSE, "sparse index 1 (entry 1) after 1: sparse indices must strictly increase");
    expect_refused(&d, 13, 1, MK_ERROR_PARSE, "componentType 5120 invalid");
    expect_refused(&d, 14, 1, MK_ERROR_PARSE, "componentType 5122 invalid");
    expect_refused(&d, 15, 1, MK_ERROR_PARSE, "componentType 5126 invalid");
    expect_refused(&d, 16, 1, MK_ERROR_PARSE, "sparse count 6");
    expect_refused(&d, 17, 1, MK_ERROR_PARSE, "sparse count 0");
    expect_refused(&d, 18, 1, MK_ERROR_TRUNCATED, "bufferView 0");
    const float one_of_two[2] = { 10, -1 };
    expect_floats(&d, 19, 1, one_of_two, 2, "sparse index 1 = count - 1 of 2");
    doc_free(&d);
}

/* The largest index of each index type at count - 1 (accepted) and at count (refused), so an
 * index is never truncated or compared through a narrower type. Bases are zeros. */
static void test_sparse_index_widths(void)
{
    unsigned char bin[16];
    memset(bin, 0, sizeof bin);
    const uint8_t a = 255;
    const uint16_t b = 65535;
    const uint32_t c = 16777215u, big = 4294967295u;   /* 2^24 - 1: the largest count allowed without a view is 2^24 */
    const float v = 0.75f;
    memcpy(bin, &a, 1);
    memcpy(bin + 2, &b, 2);
    memcpy(bin + 4, &c, 4);
    memcpy(bin + 8, &big, 4);
    memcpy(bin + 12, &v, 4);
#define S(count, itype, ioff) \
    "{\"componentType\":5126,\"count\":" #count ",\"type\":\"SCALAR\",\"sparse\":{\"count\":1," \
    "\"indices\":{\"bufferView\":0,\"byteOffset\":" #ioff ",\"componentType\":" #itype "}," \
    "\"values\":{\"bufferView\":0,\"byteOffset\":12}}}"
    const char *acc = S(256, 5121, 0) "," S(255, 5121, 0) "," S(65536, 5123, 2) "," S(65535, 5123, 2) ","
                      S(16777216, 5125, 4) "," S(16777215, 5125, 4) "," S(5, 5125, 8);
#undef S
    doc d;
    if (!doc_load(&d, bin, sizeof bin, "{\"buffer\":0,\"byteLength\":16}", acc)) { doc_free(&d); return; }
    const uint64_t counts[3] = { 256, 65536, 16777216 };
    const char *needles[3] = { "sparse index 255 (entry 0) is past the accessor's 255 elements",
                               "sparse index 65535 (entry 0) is past the accessor's 65535 elements",
                               "sparse index 16777215 (entry 0) is past the accessor's 16777215 elements" };
    for (int t = 0; t < 3; t++) {
        float *f;
        uint64_t n;
        mk_error err;
        mk_result r = read_floats(&d, 2 * t, 1, &f, &n, &err);
        CHECK_MSG(r == MK_OK, "accessor %d: %s", 2 * t, err.message);
        if (r == MK_OK) {
            CHECK_EQ_INT(n, counts[t]);
            uint64_t nonzero = 0;
            for (uint64_t i = 0; i < n; i++) nonzero += f[i] != 0.0f;
            CHECK_EQ_INT(nonzero, 1);
            CHECK(same_float(f[n - 1], 0.75f));
        }
        expect_refused(&d, 2 * t + 1, 1, MK_ERROR_PARSE, needles[t]);
    }
    expect_refused(&d, 6, 1, MK_ERROR_PARSE, "sparse index 4294967295 (entry 0) is past the accessor's 5 elements");
    doc_free(&d);
}

/* Sparse values are decoded like the base: the accessor's componentType and normalized flag. */
static void test_sparse_normalized_values(void)
{
    unsigned char bin[32];
    memset(bin, 0, sizeof bin);
    const int16_t base[4] = { 32767, -32767, 16384, 1 };
    const uint8_t idx[2] = { 0, 3 };
    const int16_t vals[2] = { -32768, 32766 };
    const int8_t base8[3] = { 127, 127, 127 }, vals8[1] = { -128 };
    memcpy(bin, base, 8);
    memcpy(bin + 8, idx, 2);
    memcpy(bin + 12, vals, 4);
    memcpy(bin + 16, base8, 3);
    memcpy(bin + 20, vals8, 1);
    const char *acc =
        "{\"bufferView\":0,\"componentType\":5122,\"normalized\":true,\"count\":4,\"type\":\"SCALAR\",\"sparse\":{\"count\":2,"
        "\"indices\":{\"bufferView\":0,\"byteOffset\":8,\"componentType\":5121},\"values\":{\"bufferView\":0,\"byteOffset\":12}}},"
        "{\"bufferView\":0,\"byteOffset\":16,\"componentType\":5120,\"normalized\":true,\"count\":3,\"type\":\"SCALAR\",\"sparse\":{\"count\":1,"
        "\"indices\":{\"bufferView\":0,\"byteOffset\":9,\"componentType\":5121},\"values\":{\"bufferView\":0,\"byteOffset\":20}}},"
        "{\"bufferView\":0,\"componentType\":5122,\"count\":4,\"type\":\"SCALAR\",\"sparse\":{\"count\":2,"
        "\"indices\":{\"bufferView\":0,\"byteOffset\":8,\"componentType\":5121},\"values\":{\"bufferView\":0,\"byteOffset\":12}}}";
    doc d;
    if (!doc_load(&d, bin, sizeof bin, "{\"buffer\":0,\"byteLength\":32}", acc)) { doc_free(&d); return; }
    const float e0[4] = { -1.0f, snorm16(-32767), snorm16(16384), snorm16(32766) };
    expect_floats(&d, 0, 1, e0, 4, "SHORT normalized + sparse");
    CHECK(e0[1] == -1.0f && e0[3] == 0.999969481490218817f);   /* 32766 / 32767 */
    /* Index 3 is past this 3-element accessor (the index list is shared). */
    expect_refused(&d, 1, 1, MK_ERROR_PARSE, "sparse index 3 (entry 0) is past");
    const float e2[4] = { -32768, -32767, 16384, 32766 };
    expect_floats(&d, 2, 1, e2, 4, "SHORT + sparse");
    doc_free(&d);
}

/* ---- index accessors ---- */

static void test_index_accessors(void)
{
    unsigned char bin[40];
    memset(bin, 0, sizeof bin);
    const uint8_t a[3] = { 0, 1, 255 };
    const uint16_t b[3] = { 0, 256, 65535 };
    const uint32_t c[3] = { 0, 65536, 4294967295u };
    memcpy(bin, a, 3);
    memcpy(bin + 4, b, 6);
    memcpy(bin + 12, c, 12);
    const char *acc =
        "{\"bufferView\":0,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5125,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"componentType\":5120,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5122,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5123,\"count\":3,\"type\":\"VEC3\"}";
    doc d;
    if (!doc_load(&d, bin, sizeof bin, "{\"buffer\":0,\"byteLength\":40}", acc)) { doc_free(&d); return; }
    const uint32_t expect[3][3] = { { 0, 1, 255 }, { 0, 256, 65535 }, { 0, 65536, 4294967295u } };
    for (int k = 0; k < 3; k++) {
        uint32_t *u;
        uint64_t n;
        mk_error err;
        memset(&err, 0, sizeof err);
        mk_result r = mk_gltf_read_indices(&d.reader, k, "test", &u, &n, &err);
        CHECK_MSG(r == MK_OK, "accessor %d: %s", k, err.message);
        if (r != MK_OK) continue;
        CHECK_EQ_INT(n, 3);
        for (int i = 0; i < 3; i++) CHECK_EQ_INT(u[i], expect[k][i]);
    }
    for (int k = 3; k < 7; k++) {
        uint32_t *u;
        uint64_t n;
        mk_error err;
        memset(&err, 0, sizeof err);
        mk_result r = mk_gltf_read_indices(&d.reader, k, "test", &u, &n, &err);
        char name[32];
        snprintf(name, sizeof name, "accessor %d", k);
        CHECK_MSG(r == MK_ERROR_PARSE, "accessor %d: %s", k, mk_result_name(r));
        CHECK_MSG(strstr(err.message, name) != NULL, "'%s' does not name %s", err.message, name);
    }
    doc_free(&d);
}

/* ---- through the importer ---- */

/* A triangle whose POSITION is normalized SHORT, with one target whose POSITION is a normalized
 * BYTE sparse accessor without bufferView touching only vertex 2 (= count - 1): the raw model
 * gets exactly the spec's values. */
static void test_import_quantized_sparse(void)
{
    unsigned char bin[32];
    memset(bin, 0, sizeof bin);
    const int16_t pos[12] = { 32767, 0, 0, 0, 0, 0, -32768, 0, -32767, 16384, -1, 0 };  /* 3 x VEC3 in 8-byte slots */
    memcpy(bin, pos, sizeof pos);
    const uint8_t idx[1] = { 2 };
    const int8_t delta[3] = { 127, -128, 64 };
    bin[24] = idx[0];
    memcpy(bin + 28, delta, 3);
    const char *rest =
        ",\"extensionsUsed\":[\"KHR_mesh_quantization\"],\"extensionsRequired\":[\"KHR_mesh_quantization\"],"
        "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"name\":\"q\",\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":1}]}]}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":24,\"byteStride\":8},{\"buffer\":0,\"byteOffset\":24,\"byteLength\":8}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5122,\"normalized\":true,\"count\":3,\"type\":\"VEC3\","
        "\"min\":[-1,0,-1],\"max\":[1,0.5,0]},"
        "{\"componentType\":5120,\"normalized\":true,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":1,"
        "\"indices\":{\"bufferView\":1,\"componentType\":5121},\"values\":{\"bufferView\":1,\"byteOffset\":4}}}]";
    char *json = gltf_text(bin, sizeof bin, rest);
    mk_raw_asset raw;
    mk_error err;
    mk_result r = gt_import_text(json, NULL, &raw, &err);
    free(json);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r == MK_OK && raw.mesh_count == 1 && raw.channel_count == 1) {
        const mk_raw_mesh *m = &raw.meshes[0];
        const float ep[9] = { 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, -1.0f, -1.0f, snorm16(16384), snorm16(-1) };
        CHECK_EQ_INT(m->vertex_count, 3);
        for (int i = 0; i < 9 && m->vertex_count == 3; i++)
            CHECK_MSG(same_float(m->positions[i], ep[i]), "position %d = %.9g, expected %.9g", i, (double)m->positions[i], (double)ep[i]);
        const mk_raw_target *t = &raw.channels[0].targets[0];
        CHECK_EQ_INT(t->count, 1);
        if (t->count == 1) {
            CHECK_EQ_INT(t->indices[0], 2);
            CHECK(same_float(t->positions[0], 1.0f));
            CHECK(same_float(t->positions[1], -1.0f));
            CHECK(same_float(t->positions[2], snorm8(64)));
        }
    } else {
        CHECK_MSG(0, "expected one mesh and one channel (%u, %u)", raw.mesh_count, raw.channel_count);
    }
    mk_raw_free(&raw);
}

CHECK_MAIN(CASE(test_normalized_endpoints), CASE(test_integers_and_floats), CASE(test_byte_stride), CASE(test_sparse),
           CASE(test_sparse_index_widths), CASE(test_sparse_normalized_values), CASE(test_index_accessors),
           CASE(test_import_quantized_sparse))

/* SPDX-License-Identifier: MIT */
/* EXT_meshopt_compression filters (importer/gltf/gltf_meshopt.c) against outputs computed by
 * hand from the extension README's formulas, at rounding boundaries, plus one import that
 * carries a filtered normal to the raw model, and a comparison with libmeshoptimizer's own
 * filters on the corpus meshopt variants (the library may differ by the README's one-unit
 * allowance, never more).
 *
 * OCTAHEDRAL by hand: with input (a, b, one) the README computes x = a/one, y = b/one,
 * z = 1 - |x| - |y|; for z < 0, x -= copysign(z, x) and y -= copysign(z, y), i.e. in integers
 * a' = sign(a)(|a| + c), b' = sign(b)(|b| + c) with c = one - |a| - |b|; then every component is
 * round(INTN_MAX * a' / sqrt(a'^2 + b'^2 + c^2)), half away from zero. The comments give those
 * integer steps and the value before rounding (to 9 decimals). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <meshoptimizer.h>
#include "check.h"
#include "gltf_test_util.h"
#include "gltf_accessor.h"
#include "gltf_import.h"
#include "gltf_meshopt.h"

typedef struct oct8 { int8_t in[4], out[4]; const char *why; } oct8;
typedef struct oct16 { int16_t in[4], out[4]; const char *why; } oct16;

static void test_octahedral_8bit(void)
{
    static const oct8 cases[] = {
        { { 0, 0, 127, 9 }, { 0, 0, 127, 9 }, "+z pole; the fourth byte passes through" },
        { { 127, 0, 127, -3 }, { 127, 0, 0, -3 }, "+x on the equator (c = 0)" },
        { { 0, -127, 127, 0 }, { 0, -127, 0, 0 }, "-y on the equator" },
        { { 127, 127, 127, 0 }, { 0, 0, -127, 0 }, "c = -127: a' = b' = 0, the -z pole" },
        /* c = 47, n = 50^2 + 30^2 + 47^2 = 5609: 84.787338977, -50.872403386, 79.700098638 */
        { { 50, -30, 127, 0 }, { 85, -51, 80, 0 }, "upper hemisphere" },
        /* c = -115: (-10, -2, -115), n = 13329: -11.000310324, -2.200062065, -126.503568723
         * (libmeshoptimizer 0.18 gives -126 for z) */
        { { -125, -117, 127, 0 }, { -11, -2, -127, 0 }, "z at -126.5036" },
        /* c = -70: (-54, -3, -70), n = 7825: -77.527415742, -4.307078652, -100.498501888
         * (0.18 gives -101 for z) */
        { { -124, -73, 127, 0 }, { -78, -4, -100, 0 }, "z at -100.4985" },
        /* c = -117: (-6, -4, -117), n = 13741: -6.500485614, -4.333657076, -126.759469481 */
        { { -123, -121, 127, 0 }, { -7, -4, -127, 0 }, "x at -6.50049" },
        /* c = -81: (-37, -9, -81), n = 8011: -52.500335549, -12.770351890, -114.933167014
         * (0.18 gives -52 for x) */
        { { -118, -90, 127, 0 }, { -53, -13, -115, 0 }, "x at -52.50034" },
        /* c = -80: (-47, 0, -80), n = 8609: -64.331729176, 0, -109.500815619 */
        { { -127, -80, 127, 0 }, { -64, 0, -110, 0 }, "z at -109.50082" },
        /* K = 6 (one = 31), c = 0: (20, -11, 0), n = 521: 111.279420402, -61.203681221, 0 */
        { { 20, -11, 31, 0 }, { 111, -61, 0, 0 }, "6-bit input" },
        /* K = 7 (one = 63), c = -57: (-5, -1, -57), n = 3275: -11.096041520, -2.219208304,
         * -126.494873323 (0.18 gives -127 for z) */
        { { -62, -58, 63, 0 }, { -11, -2, -126, 0 }, "7-bit input, z at -126.4949" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        int8_t v[4];
        memcpy(v, cases[i].in, 4);
        mk_meshopt_filter_octahedral(v, 1, 4);
        CHECK_MSG(memcmp(v, cases[i].out, 4) == 0, "(%d,%d,%d,%d) [%s] -> (%d,%d,%d,%d), expected (%d,%d,%d,%d)",
                  cases[i].in[0], cases[i].in[1], cases[i].in[2], cases[i].in[3], cases[i].why, v[0], v[1], v[2], v[3],
                  cases[i].out[0], cases[i].out[1], cases[i].out[2], cases[i].out[3]);
    }
    /* Several elements in one call, each decoded on its own. */
    int8_t many[12] = { 0, 0, 127, 9, -125, -117, 127, 1, 127, 127, 127, 2 };
    const int8_t expect[12] = { 0, 0, 127, 9, -11, -2, -127, 1, 0, 0, -127, 2 };
    mk_meshopt_filter_octahedral(many, 3, 4);
    CHECK(memcmp(many, expect, sizeof expect) == 0);
}

static void test_octahedral_16bit(void)
{
    static const oct16 cases[] = {
        { { 32767, 0, 32767, 1234 }, { 32767, 0, 0, 1234 }, "+x; the fourth component passes through" },
        { { 0, 0, -32767, 0 }, { 0, 0, 32767, 0 }, "one = -32767 (invalid K): +z, deterministic" },
        /* K = 12 (one = 2047), c = -1266: (-735, -46, -1266), n = 2145097:
         * -16443.738150574, -1029.131911464, -28323.499998132 (0.18 gives -28324 for z) */
        { { -2001, -1312, 2047, 0 }, { -16444, -1029, -28323, 0 }, "z 1.9e-6 above -28323.5" },
        /* K = 16, c = -31647: (-1120, 0, -31647), n = 1002787009: -1158.911718375, 0,
         * -32746.499242347 (a float32 evaluation of the README's steps gives exactly -32746.5
         * here and so -32747: the README allows that unit; we give the formula's value) */
        { { -32767, -31647, 32767, 0 }, { -1159, 0, -32746, 0 }, "z at -32746.49924" },
        /* K = 12, c = -1275: (-772, 0, -1275), n = 2221609: -16971.497653334, 0,
         * -28029.351694302 (float32 steps give exactly -16971.5 for x, so -16972) */
        { { -2047, -1275, 2047, -5 }, { -16971, 0, -28029, -5 }, "x at -16971.49765" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        int16_t v[4];
        memcpy(v, cases[i].in, 8);
        mk_meshopt_filter_octahedral(v, 1, 8);
        CHECK_MSG(memcmp(v, cases[i].out, 8) == 0, "(%d,%d,%d,%d) [%s] -> (%d,%d,%d,%d), expected (%d,%d,%d,%d)",
                  cases[i].in[0], cases[i].in[1], cases[i].in[2], cases[i].in[3], cases[i].why, v[0], v[1], v[2], v[3],
                  cases[i].out[0], cases[i].out[1], cases[i].out[2], cases[i].out[3]);
    }
}

/* QUATERNION by hand: one = input[3] | 3, s = 1/sqrt(2); x, y, z = input[0..2] / one * s;
 * w = sqrt(1 - x^2 - y^2 - z^2); maxcomp = input[3] & 3; output[(maxcomp + 1..3) % 4] = x, y,
 * z and output[maxcomp] = w, each round(v * 32767). */
static void test_quaternion(void)
{
    static const oct16 cases[] = {
        { { 0, 0, 0, 32767 }, { 0, 0, 0, 32767 }, "identity, maxcomp 3 (w last)" },
        { { 0, 0, 0, 32764 }, { 32767, 0, 0, 0 }, "maxcomp 0: the rotation puts w first" },
        /* 90 degrees about z: z = 32767/32767 * s = 0.7071.., 23169.767899140 for z and w */
        { { 0, 0, 32767, 32767 }, { 0, 0, 23170, 23170 }, "z = w = 1/sqrt(2)" },
        /* K = 12 (one = 2047), maxcomp 1: x = -11624.500064688, y = -16378.433878874,
         * z = 3633.363700842, w = 25633.822561975 -> out[2] = x, out[3] = y, out[0] = z,
         * out[1] = w (0.18 gives -11624 for x) */
        { { -1027, -1447, 321, 2045 }, { 3633, 25634, -11625, -16378 }, "x 6.5e-5 past -11624.5" },
        /* maxcomp 2, one = 32767: 70.710678119, -141.421356237, 212.132034356, w 32765.93.. */
        { { 100, -200, 300, 32766 }, { -141, 212, 32766, 71 }, "maxcomp 2" },
        /* Invalid K (one = 3): x = -253067928.25: clamped to the int16 range, not wrapped. */
        { { -32767, 0, 0, 3 }, { -32767, 0, 0, 0 }, "out of range input clamps" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        int16_t v[4];
        memcpy(v, cases[i].in, 8);
        mk_meshopt_filter_quaternion(v, 1, 8);
        CHECK_MSG(memcmp(v, cases[i].out, 8) == 0, "(%d,%d,%d,%d) [%s] -> (%d,%d,%d,%d), expected (%d,%d,%d,%d)",
                  cases[i].in[0], cases[i].in[1], cases[i].in[2], cases[i].in[3], cases[i].why, v[0], v[1], v[2], v[3],
                  cases[i].out[0], cases[i].out[1], cases[i].out[2], cases[i].out[3]);
    }
}

/* EXPONENTIAL: 2^e * m with e the top 8 bits and m the low 24 bits, both two's complement. */
static void test_exponential(void)
{
    struct { int e, m; float expect; } cases[] = {
        { 0, 1, 1.0f }, { -1, 3, 1.5f }, { -8, -1, -0.00390625f }, { 0, 0, 0.0f },
        { -100, 1, 7.88860905e-31f },                 /* 2^-100, exact */
        { 100, -8388608, -1.0633823966e37f },         /* -2^23 * 2^100 = -2^123 */
        { 100, 8388607, 1.0633822698e37f },           /* (2^23 - 1) * 2^100 */
        { -23, 8388607, 0.99999988079f },             /* 1 - 2^-23 */
        { 10, -1000, -1024000.0f },
    };
    uint32_t words[16] = { 0 };
    size_t n = sizeof cases / sizeof *cases;
    for (size_t i = 0; i < n; i++)
        words[i] = (uint32_t)(cases[i].e & 0xff) << 24 | ((uint32_t)cases[i].m & 0xffffffu);
    /* stride 8: two words per element, so the loop must cover count * stride / 4 words */
    mk_meshopt_filter_exponential(words, (n + 1) / 2, 8);
    for (size_t i = 0; i < n; i++) {
        float f;
        memcpy(&f, &words[i], 4);
        CHECK_MSG(f == cases[i].expect && signbit(f) == signbit(cases[i].expect), "e %d m %d -> %.10g, expected %.10g",
                  cases[i].e, cases[i].m, (double)f, (double)cases[i].expect);
    }
    CHECK(ldexpf(1.0f, -100) == 7.88860905e-31f && ldexpf(-1.0f, 123) == -1.0633823966e37f);
    /* Outside the README's [-100, 100]: e = 127 overflows to infinity (the accessor reader
     * then refuses the value), never wraps. */
    uint32_t big = (uint32_t)127 << 24 | 0x7fffffu;
    mk_meshopt_filter_exponential(&big, 1, 4);
    float f;
    memcpy(&f, &big, 4);
    CHECK(isinf(f) && f > 0);
}

/* ---- the importer uses the filter ---- */

/* A triangle whose base NORMAL is a meshopt ATTRIBUTES view with the OCTAHEDRAL filter (the
 * stream encoded here with libmeshoptimizer's encoder): the raw normals are the hand-computed
 * filter outputs / 127. */
static void test_import_filtered_normals(void)
{
    const int8_t oct[12] = { -125, -117, 127, 0, 50, -30, 127, 0, -118, -90, 127, 0 };
    const int8_t out[9] = { -11, -2, -127, 85, -51, 80, -53, -13, -115 };
    const float pos[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1 };   /* + one target delta */
    unsigned char bin[4096];
    memset(bin, 0, sizeof bin);
    memcpy(bin, pos, sizeof pos);
    size_t bound = meshopt_encodeVertexBufferBound(3, 4);
    CHECK(48 + bound <= sizeof bin);
    if (48 + bound > sizeof bin) return;
    size_t clen = meshopt_encodeVertexBuffer(bin + 48, bound, oct, 3, 4);
    CHECK(clen > 0);
    char *b64 = gt_base64(bin, 48 + clen);
    char *json = malloc(strlen(b64) + 4096);
    sprintf(json,
            "{\"asset\":{\"version\":\"2.0\"},"
            "\"extensionsUsed\":[\"EXT_meshopt_compression\",\"KHR_mesh_quantization\"],"
            "\"extensionsRequired\":[\"EXT_meshopt_compression\",\"KHR_mesh_quantization\"],"
            "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"},"
            "{\"byteLength\":12,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}],"
            "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},"
            "{\"buffer\":1,\"byteLength\":12,\"byteStride\":4,\"extensions\":{\"EXT_meshopt_compression\":"
            "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":%zu,\"byteStride\":4,\"count\":3,\"mode\":\"ATTRIBUTES\",\"filter\":\"OCTAHEDRAL\"}}}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
            "{\"bufferView\":1,\"componentType\":5120,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"},"
            "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"targets\":[{\"POSITION\":2}]}]}],"
            "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
            48 + clen, b64, clen);
    free(b64);
    mk_raw_asset raw;
    mk_error err;
    mk_result r = gt_import_text(json, NULL, &raw, &err);
    free(json);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r == MK_OK && raw.mesh_count == 1 && raw.meshes[0].normals && raw.meshes[0].vertex_count == 3) {
        for (int i = 0; i < 9; i++) {
            float expect = (float)fmax(out[i] / 127.0, -1.0);
            CHECK_MSG(raw.meshes[0].normals[i] == expect, "normal component %d = %.9g (%.4f / 127), expected %d / 127", i,
                      (double)raw.meshes[0].normals[i], raw.meshes[0].normals[i] * 127.0, out[i]);
        }
    } else {
        CHECK_MSG(0, "expected one mesh with 3 normals");
    }
    mk_raw_free(&raw);
}

/* ---- libmeshoptimizer on the corpus ---- */

typedef struct filter_stats { uint64_t elements, elements_differ, values, values_differ; int max_diff; } filter_stats;

/* Decodes view vi's stream and applies our filter and the library's; tallies differences. */
static void compare_view(const mk_gltf_doc *d, int vi, filter_stats *st, const char *file)
{
    const mk_gltf_view *v = &d->views[vi];
    const mk_gltf_buffer *b = &d->buffers[v->mo_buffer];
    size_t n = (size_t)v->mo_count, stride = v->mo_stride;
    unsigned char *ours = malloc(n * stride), *lib = malloc(n * stride);
    int rc = meshopt_decodeVertexBuffer(ours, n, stride, b->data + v->mo_offset, (size_t)v->mo_length);
    CHECK_MSG(rc == 0, "%s view %d: stream does not decode (%d)", file, vi, rc);
    memcpy(lib, ours, n * stride);
    const char *name = "?";
    int comps = 0;
    if (v->mo_filter == MK_MESHOPT_OCTAHEDRAL) {
        name = "OCTAHEDRAL";
        comps = 3;
        mk_meshopt_filter_octahedral(ours, n, stride);
        meshopt_decodeFilterOct(lib, n, stride);
    } else if (v->mo_filter == MK_MESHOPT_QUATERNION) {
        name = "QUATERNION";
        comps = 4;
        mk_meshopt_filter_quaternion(ours, n, stride);
        meshopt_decodeFilterQuat(lib, n, stride);
    } else if (v->mo_filter == MK_MESHOPT_EXPONENTIAL) {
        name = "EXPONENTIAL";
        mk_meshopt_filter_exponential(ours, n, stride);
        meshopt_decodeFilterExp(lib, n, stride);
    }
    filter_stats vs = { 0, 0, 0, 0, 0 };
    for (size_t i = 0; i < n; i++) {
        int differ = 0;
        if (v->mo_filter == MK_MESHOPT_EXPONENTIAL) {
            differ = memcmp(ours + i * stride, lib + i * stride, stride) != 0;
            vs.values += stride / 4;
            if (differ) { vs.values_differ++; vs.max_diff = vs.max_diff > 1 ? vs.max_diff : 1000; }
        } else {
            for (int c = 0; c < comps; c++) {
                int a, l;
                if (stride == 4) { a = (int8_t)ours[i * 4 + c]; l = (int8_t)lib[i * 4 + c]; }
                else { int16_t x, y; memcpy(&x, ours + i * stride + 2 * c, 2); memcpy(&y, lib + i * stride + 2 * c, 2); a = x; l = y; }
                int dd = abs(a - l);
                vs.values++;
                if (dd) { vs.values_differ++; differ = 1; }
                if (dd > vs.max_diff) vs.max_diff = dd;
            }
        }
        vs.elements++;
        vs.elements_differ += differ;
    }
    printf("  %s view %d %s stride %zu: %llu of %llu elements differ (%llu of %llu values), max %d unit(s)\n", file, vi, name,
           stride, (unsigned long long)vs.elements_differ, (unsigned long long)vs.elements,
           (unsigned long long)vs.values_differ, (unsigned long long)vs.values, vs.max_diff);
    CHECK_MSG(vs.max_diff <= (v->mo_filter == MK_MESHOPT_EXPONENTIAL ? 0 : 1), "%s view %d: differs from libmeshoptimizer by %d units",
              file, vi, vs.max_diff);
    st->elements += vs.elements;
    st->elements_differ += vs.elements_differ;
    st->values += vs.values;
    st->values_differ += vs.values_differ;
    if (vs.max_diff > st->max_diff) st->max_diff = vs.max_diff;
    free(ours);
    free(lib);
}

static void test_corpus_against_library(void)
{
    static const char *files[] = {
        "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.meshopt.glb",
        "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.meshopt.glb",
        "gltf/MorphStressTest/variants/MorphStressTest.meshopt.glb",
        "gltf/SimpleMorph/variants/SimpleMorph.meshopt.glb",
    };
    const char *corpus = check_corpus_dir();
    filter_stats total = { 0, 0, 0, 0, 0 };
    int found = 0, filtered = 0;
    for (size_t f = 0; f < sizeof files / sizeof *files; f++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", corpus, files[f]);
        size_t size;
        unsigned char *data = check_read_file(path, &size);
        if (!data) continue;
        found++;
        mk_arena arena;
        mk_arena_init(&arena, NULL);
        mk_gltf_doc doc;
        mk_error err;
        memset(&err, 0, sizeof err);
        mk_result r = mk_gltf_doc_load(&arena, data, size, -1, NULL, 0, NULL, NULL, &doc, &err);
        CHECK_MSG(r == MK_OK, "%s: %s", files[f], err.message);
        if (r == MK_OK) {
            for (uint32_t vi = 0; vi < doc.view_count; vi++) {
                const mk_gltf_view *v = &doc.views[vi];
                if (!v->meshopt || v->mo_mode != MK_MESHOPT_ATTRIBUTES || v->mo_filter <= MK_MESHOPT_NONE) continue;
                filtered++;
                compare_view(&doc, (int)vi, &total, strrchr(files[f], '/') + 1);
            }
            mk_gltf_doc_free(&doc);
        }
        mk_arena_free_all(&arena);
        free(data);
    }
    if (!found) SKIP("no corpus meshopt variants under %s", corpus);
    printf("  all: %d filtered views, %llu of %llu elements differ from libmeshoptimizer %d.%02d "
           "(%llu of %llu values), max %d unit(s)\n", filtered, (unsigned long long)total.elements_differ,
           (unsigned long long)total.elements, MESHOPTIMIZER_VERSION / 1000, MESHOPTIMIZER_VERSION % 1000 / 10,
           (unsigned long long)total.values_differ, (unsigned long long)total.values, total.max_diff);
}

CHECK_MAIN(CASE(test_octahedral_8bit), CASE(test_octahedral_16bit), CASE(test_quaternion), CASE(test_exponential),
           CASE(test_import_filtered_normals), CASE(test_corpus_against_library))

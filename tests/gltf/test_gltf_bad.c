/* SPDX-License-Identifier: MIT */
/* Bad glTF input gives a clear error, never a crash (run under ASan/UBSan in CI).
 *
 * Fixtures are generated here: one small valid .gltf (a triangle with one morph target and a
 * weight animation, buffer embedded as a base64 data URI), then each case edits the JSON text
 * or the binary data to break exactly one thing, and checks the error code and that the message
 * names the culprit. A last case truncates and byte-flips every corpus glTF/GLB. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "check.h"
#include "gltf_test_util.h"
#include "gltf_import.h"
#include "import.h"

/* ---- fixture ---- */

typedef struct fixture {
    float pos[9], tpos[9];
    uint16_t idx[3];
    float times[3];
    float values[9];             /* keys x targets (x3 for cubic) */
    int keys, values_count;
    const char *interp;
} fixture;

static void fixture_default(fixture *f)
{
    static const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const float tpos[9] = {0, 0, 0, 0, 0, 0, 0, 0.5f, 0};
    memset(f, 0, sizeof *f);
    memcpy(f->pos, pos, sizeof pos);
    memcpy(f->tpos, tpos, sizeof tpos);
    f->idx[0] = 0; f->idx[1] = 1; f->idx[2] = 2;
    f->times[0] = 0; f->times[1] = 1; f->times[2] = 2;
    f->values[0] = 0; f->values[1] = 1; f->values[2] = 0;
    f->keys = 3;
    f->values_count = 3;
    f->interp = "LINEAR";
}

/* Layout: positions 0..36, target 36..72, indices 72..78 (+2 pad), times 80..80+4K, values after. */
static char *fixture_json(const fixture *f)
{
    unsigned char bin[256];
    memset(bin, 0, sizeof bin);
    memcpy(bin, f->pos, 36);
    memcpy(bin + 36, f->tpos, 36);
    memcpy(bin + 72, f->idx, 6);
    memcpy(bin + 80, f->times, 4 * (size_t)f->keys);
    size_t vo = 80 + 4 * (size_t)f->keys;
    memcpy(bin + vo, f->values, 4 * (size_t)f->values_count);
    size_t total = vo + 4 * (size_t)f->values_count;
    char *b64 = gt_base64(bin, total);
    char *json = malloc(8192);
    snprintf(json, 8192,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"name\":\"tri\",\"mesh\":0,\"translation\":[1,2,3]}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":2,\"targets\":[{\"POSITION\":1}]}],"
        "\"weights\":[0.25],\"extras\":{\"targetNames\":[\"up\"]}}],"
        "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6},"
        "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":%zu}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
        "{\"bufferView\":0,\"byteOffset\":36,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[0,0.5,0]},"
        "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":%d,\"type\":\"SCALAR\",\"min\":[0],\"max\":[2]},"
        "{\"bufferView\":2,\"byteOffset\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"SCALAR\"}],"
        "\"animations\":[{\"name\":\"bounce\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}],"
        "\"samplers\":[{\"input\":3,\"output\":4,\"interpolation\":\"%s\"}]}]}",
        total, b64 ? b64 : "", total - 80, f->keys, 4 * f->keys, f->values_count, f->interp);
    free(b64);
    return json;
}

/* Replaces the first occurrence of `from` (which must exist) by `to`. */
static char *edit(char *json, const char *from, const char *to)
{
    char *at = strstr(json, from);
    CHECK_MSG(at != NULL, "fixture edit: '%s' not found", from);
    if (!at) return json;
    size_t n = strlen(json) - strlen(from) + strlen(to) + 1;
    char *out = malloc(n);
    memcpy(out, json, (size_t)(at - json));
    strcpy(out + (at - json), to);
    strcat(out, at + strlen(from));
    free(json);
    return out;
}

static mk_result import_text(const char *json, mk_raw_asset *raw, mk_error *err)
{
    return gt_import_text(json, NULL, raw, err);
}

/* Imports json, expects `code` and a message containing `needle`; frees json. */
static void expect_error(char *json, mk_result code, const char *needle)
{
    mk_raw_asset raw;
    mk_error err;
    mk_result r = import_text(json, &raw, &err);
    CHECK_MSG(r == code, "expected %s, got %s (%s)", mk_result_name(code), mk_result_name(r), err.message);
    CHECK_MSG(strstr(err.message, needle) != NULL, "message '%s' does not name '%s'", err.message, needle);
    if (r != MK_OK) printf("  %s: %s\n", check_global.current, err.message);
    mk_raw_free(&raw);
    free(json);
}

/* ---- cases ---- */

static void test_fixture_is_valid(void)
{
    fixture f;
    fixture_default(&f);
    char *json = fixture_json(&f);
    mk_raw_asset raw;
    mk_error err;
    mk_result r = import_text(json, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r == MK_OK) {
        CHECK_EQ_INT(raw.mesh_count, 1);
        CHECK_EQ_INT(raw.channel_count, 1);
        CHECK(strcmp(raw.channels[0].name, "up") == 0);
        CHECK_NEAR(raw.channels[0].default_weight, 0.25, 0);
        CHECK_EQ_INT(raw.channels[0].targets[0].count, 1);          /* only vertex 2 moves */
        CHECK_EQ_INT(raw.channels[0].targets[0].indices[0], 2);
        CHECK_NEAR(raw.channels[0].targets[0].positions[1], 0.5, 0);
        CHECK_NEAR(raw.meshes[0].world[12], 1, 0);                   /* translation, column-major */
        CHECK_NEAR(raw.meshes[0].world[14], 3, 0);
        CHECK_EQ_INT(raw.clip_count, 1);
        CHECK_EQ_INT(raw.clips[0].tracks[0].key_count, 3);
        CHECK_NEAR(raw.clips[0].duration, 2, 0);
    }
    mk_raw_free(&raw);
    free(json);
}

static void test_missing_buffer_file(void)
{
    /* A .gltf on disk whose buffer URI names a file that does not exist. */
    char path[128];
    snprintf(path, sizeof path, "/tmp/morphkit_gltf_missing_buffer_%ld.gltf", (long)getpid());
    fixture f;
    fixture_default(&f);
    char *json = fixture_json(&f);
    char *b = strstr(json, "data:application");
    char *e = b ? strchr(b, '"') : NULL;
    CHECK(b && e);
    if (!b || !e) { free(json); return; }
    FILE *out = fopen(path, "wb");
    CHECK(out != NULL);
    if (!out) { free(json); return; }
    fwrite(json, 1, (size_t)(b - json), out);
    fputs("no_such_buffer.bin", out);
    fputs(e, out);
    fclose(out);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err = {0};
    mk_result r = mk_import_file(path, NULL, &raw, &err);
    CHECK(r != MK_OK);
    CHECK_MSG(strstr(err.message, "no_such_buffer.bin") != NULL, "message: %s", err.message);
    printf("  %s\n", err.message);
    mk_raw_free(&raw);
    remove(path);
    free(json);
    /* From memory, external files are refused outright. */
    fixture_default(&f);
    json = edit(fixture_json(&f), "data:application/octet-stream;base64,", "x.bin#");
    expect_error(json, MK_ERROR_PARSE, "x.bin");
}

/* A node whose mesh has no morph targets is not imported (only morphing meshes are), but the
 * user is told which one and why. */
static void test_plain_mesh_warns(void)
{
    fixture f;
    fixture_default(&f);
    char *json = fixture_json(&f);
    json = edit(json, "\"translation\":[1,2,3]}]", "\"translation\":[1,2,3]},{\"name\":\"rock\",\"mesh\":1}]");
    json = edit(json, "\"extras\":{\"targetNames\":[\"up\"]}}]",
                "\"extras\":{\"targetNames\":[\"up\"]}},{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":2}]}]");
    mk_raw_asset raw;
    mk_error err;
    mk_result r = import_text(json, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    CHECK_EQ_INT(raw.mesh_count, 1);
    int warned = 0;
    for (uint32_t i = 0; i < raw.warning_count && i < MK_RAW_MAX_WARNINGS; i++)
        warned |= strstr(raw.warnings[i].message, "'rock'") && strstr(raw.warnings[i].message, "no morph targets");
    CHECK_MSG(warned, "no warning names the skipped node 'rock'");
    mk_raw_free(&raw);
    free(json);
}

/* ---- external URIs resolve against the glTF file's folder only ---- */

static int write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}

/* The corpus AnimatedMorphCube .gltf text with its buffer URI replaced by `uri` (malloc'ed),
 * and its .bin; NULL when the corpus is absent. */
static char *cube_gltf(const char *uri, unsigned char **bin, size_t *bin_size)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.bin", check_corpus_dir());
    *bin = check_read_file(path, bin_size);
    snprintf(path, sizeof path, "%s/gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", check_corpus_dir());
    size_t size;
    char *text = (char *)check_read_file(path, &size);
    if (!text || !*bin) { free(text); free(*bin); *bin = NULL; return NULL; }
    return edit(text, "\"uri\": \"AnimatedMorphCube.bin\"", uri);
}

/* Imports `path` and expects `code` with every needle in the message (code MK_OK: success). */
static void expect_import(const char *path, mk_result code, const char *n1, const char *n2)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err = {0};
    mk_result r = mk_import_file(path, NULL, &raw, &err);
    CHECK_MSG(r == code, "%s: expected %s, got %s (%s)", path, mk_result_name(code), mk_result_name(r), err.message);
    if (code != MK_OK) {
        CHECK_MSG(strstr(err.message, n1) && (!n2 || strstr(err.message, n2)), "%s: message '%s' should name '%s' and '%s'",
                  path, err.message, n1, n2 ? n2 : "");
        printf("  %s\n", err.message);
    } else {
        CHECK_EQ_INT(raw.channel_count, 2);
    }
    mk_raw_free(&raw);
}

/* A .gltf copied into a folder without its .bin must not pick up a same-named .bin from the
 * current directory: the error names the URI and the path tried. */
static void test_buffer_not_from_working_directory(void)
{
    unsigned char *bin;
    size_t bin_size;
    char *json = cube_gltf("\"uri\": \"AnimatedMorphCube.bin\"", &bin, &bin_size);
    if (!json) SKIP("corpus not found at %s", check_corpus_dir());
    char gltf_dir[] = "/tmp/morphkit_nobin_XXXXXX", cwd_dir[] = "/tmp/morphkit_cwd_XXXXXX";
    CHECK(mkdtemp(gltf_dir) && mkdtemp(cwd_dir));
    char saved[4096], gltf_path[256], cwd_bin[256], next_bin[256], relative[256], tried[300], tried_relative[300];
    CHECK(getcwd(saved, sizeof saved) != NULL);
    snprintf(gltf_path, sizeof gltf_path, "%s/AnimatedMorphCube.gltf", gltf_dir);
    snprintf(cwd_bin, sizeof cwd_bin, "%s/AnimatedMorphCube.bin", cwd_dir);
    snprintf(next_bin, sizeof next_bin, "%s/AnimatedMorphCube.bin", gltf_dir);
    snprintf(tried, sizeof tried, "'%s'", next_bin);
    /* The same file by a relative path from the working directory (both folders are in /tmp). */
    snprintf(relative, sizeof relative, "../%s/AnimatedMorphCube.gltf", gltf_dir + 5);
    snprintf(tried_relative, sizeof tried_relative, "'../%s/AnimatedMorphCube.bin'", gltf_dir + 5);
    CHECK(write_file(gltf_path, json, strlen(json)) && write_file(cwd_bin, bin, bin_size));
    CHECK(chdir(cwd_dir) == 0);
    expect_import(gltf_path, MK_ERROR_IO, "'AnimatedMorphCube.bin'", tried);
    expect_import(relative, MK_ERROR_IO, "'AnimatedMorphCube.bin'", tried_relative);
    /* With the .bin next to the .gltf it imports, from any working directory. */
    CHECK(write_file(next_bin, bin, bin_size));
    expect_import(gltf_path, MK_OK, NULL, NULL);
    expect_import(relative, MK_OK, NULL, NULL);
    CHECK(chdir(saved) == 0);
    remove(next_bin);
    remove(gltf_path);
    remove(cwd_bin);
    rmdir(gltf_dir);
    rmdir(cwd_dir);
    free(json);
    free(bin);
}

/* data: URIs work from disk; relative URIs (also with "..") resolve against the .gltf's folder;
 * absolute paths and other schemes are refused with an error naming the URI, even when the
 * file they name exists. */
static void test_external_uri_rules(void)
{
    unsigned char *bin;
    size_t bin_size;
    char *probe = cube_gltf("\"uri\": \"x\"", &bin, &bin_size);
    if (!probe) SKIP("corpus not found at %s", check_corpus_dir());
    free(probe);
    char parent[] = "/tmp/morphkit_uris_XXXXXX", cwd_dir[] = "/tmp/morphkit_cwd_XXXXXX";
    CHECK(mkdtemp(parent) && mkdtemp(cwd_dir));
    char sub[256], bin_path[256], gltf_path[300], saved[4096], uri[400];
    snprintf(sub, sizeof sub, "%s/sub", parent);
    snprintf(bin_path, sizeof bin_path, "%s/AnimatedMorphCube.bin", parent);
    snprintf(gltf_path, sizeof gltf_path, "%s/AnimatedMorphCube.gltf", sub);
    CHECK(mkdir(sub, 0700) == 0 && write_file(bin_path, bin, bin_size));
    free(bin);
    CHECK(getcwd(saved, sizeof saved) != NULL);
    CHECK(chdir(cwd_dir) == 0);
    /* The buffer one folder up. */
    char *json = cube_gltf("\"uri\": \"../AnimatedMorphCube.bin\"", &bin, &bin_size);
    CHECK(json && write_file(gltf_path, json, strlen(json)));
    expect_import(gltf_path, MK_OK, NULL, NULL);
    free(json);
    free(bin);
    /* Absolute path to that same existing file, plain and percent-encoded, and as file: URI. */
    static const char *const forms[3] = { "\"uri\": \"%s\"", "\"uri\": \"%%2F%s\"", "\"uri\": \"file://%s\"" };
    for (int k = 0; k < 3; k++) {
        snprintf(uri, sizeof uri, forms[k], k == 1 ? bin_path + 1 : bin_path);
        json = cube_gltf(uri, &bin, &bin_size);
        CHECK(json && write_file(gltf_path, json, strlen(json)));
        expect_import(gltf_path, MK_ERROR_UNSUPPORTED, "AnimatedMorphCube.bin", k == 2 ? "scheme" : "absolute");
        free(json);
        free(bin);
    }
    /* A data: URI from disk (the fixture's buffer), imported from another working directory. */
    fixture f;
    fixture_default(&f);
    json = fixture_json(&f);
    CHECK(write_file(gltf_path, json, strlen(json)));
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err = {0};
    CHECK_MSG(mk_import_file(gltf_path, NULL, &raw, &err) == MK_OK, "%s", err.message);
    mk_raw_free(&raw);
    free(json);
    CHECK(chdir(saved) == 0);
    remove(gltf_path);
    remove(bin_path);
    rmdir(sub);
    rmdir(parent);
    rmdir(cwd_dir);
}

static void test_index_out_of_range(void)
{
    fixture f;
    fixture_default(&f);
    f.idx[1] = 7;
    expect_error(fixture_json(&f), MK_ERROR_PARSE, "index 1 is vertex 7");
}

static void test_accessor_counts_disagree(void)
{
    fixture f;
    fixture_default(&f);
    /* The target accessor claims 2 vertices, the base 3. */
    expect_error(edit(fixture_json(&f), "\"byteOffset\":36,\"componentType\":5126,\"count\":3", "\"byteOffset\":36,\"componentType\":5126,\"count\":2"),
                 MK_ERROR_PARSE, "has 2 elements");
    /* The base accessor claims more elements than its bufferView holds. */
    expect_error(edit(fixture_json(&f), "{\"bufferView\":0,\"componentType\":5126,\"count\":3", "{\"bufferView\":0,\"componentType\":5126,\"count\":9"),
                 MK_ERROR_TRUNCATED, "accessor 0");
    /* Weight output with the wrong number of values for keys x targets. */
    fixture_default(&f);
    f.values_count = 2;
    expect_error(fixture_json(&f), MK_ERROR_PARSE, "output accessor 4 has 2 values");
    /* Two primitives with different target counts. */
    expect_error(edit(fixture_json(&f), "\"targets\":[{\"POSITION\":1}]}]", "\"targets\":[{\"POSITION\":1}]},{\"attributes\":{\"POSITION\":0}}]"),
                 MK_ERROR_PARSE, "must agree");
}

static void test_not_finite(void)
{
    fixture f;
    fixture_default(&f);
    f.pos[4] = NAN;
    expect_error(fixture_json(&f), MK_ERROR_NOT_FINITE, "POSITION: accessor 0 element 1");
    fixture_default(&f);
    f.tpos[8] = INFINITY;
    expect_error(fixture_json(&f), MK_ERROR_NOT_FINITE, "target 0 POSITION");
    fixture_default(&f);
    f.values[1] = NAN;
    expect_error(fixture_json(&f), MK_ERROR_NOT_FINITE, "animation 0 channel 0");
    fixture_default(&f);
    f.times[2] = INFINITY;
    expect_error(fixture_json(&f), MK_ERROR_NOT_FINITE, "accessor 3");
}

static void test_cubicspline_one_key(void)
{
    fixture f;
    fixture_default(&f);
    f.interp = "CUBICSPLINE";
    f.keys = 1;
    f.values_count = 3;   /* in-tangent, value, out-tangent of the single key */
    expect_error(fixture_json(&f), MK_ERROR_PARSE, "CUBICSPLINE needs at least 2 keys");
    /* Two keys but the output lacks the tangents. */
    fixture_default(&f);
    f.interp = "CUBICSPLINE";
    f.keys = 2;
    f.values_count = 2;
    expect_error(fixture_json(&f), MK_ERROR_PARSE, "x 3");
}

static void test_structure_errors(void)
{
    fixture f;
    fixture_default(&f);
    expect_error(edit(fixture_json(&f), "\"indices\":2", "\"indices\":42"), MK_ERROR_PARSE, "accessor");
    expect_error(edit(fixture_json(&f), "{\"POSITION\":1}", "{\"POSITION\":17}"), MK_ERROR_PARSE, "accessor 17 out of range");
    expect_error(edit(fixture_json(&f), "\"mesh\":0,", "\"mesh\":0,\"children\":[0],"), MK_ERROR_PARSE, "node 0");
    expect_error(edit(fixture_json(&f), "\"byteOffset\":72,\"byteLength\":6", "\"byteOffset\":72,\"byteLength\":600"), MK_ERROR_TRUNCATED, "bufferView 1");
    expect_error(edit(fixture_json(&f), "\"sampler\":0,", "\"sampler\":3,"), MK_ERROR_PARSE, "sampler 3 out of range");
    expect_error(edit(fixture_json(&f), "\"node\":0,\"path\"", "\"node\":9,\"path\""), MK_ERROR_PARSE, "node 9");
    /* Key times must increase. */
    f.times[2] = 0.5f;
    expect_error(fixture_json(&f), MK_ERROR_PARSE, "does not increase");
    /* Sparse target: indices not increasing. The sparse indices reuse the index bytes (0,1,2 → 2,1). */
    fixture_default(&f);
    f.idx[0] = 2; f.idx[1] = 1; f.idx[2] = 0;
    expect_error(edit(fixture_json(&f), "{\"bufferView\":0,\"byteOffset\":36,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"",
                      "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":1,\"componentType\":5123},"
                      "\"values\":{\"bufferView\":0,\"byteOffset\":0}}"),
                 MK_ERROR_PARSE, "must strictly increase");
    /* An unknown required extension is refused, not half-imported. */
    fixture_default(&f);
    expect_error(edit(fixture_json(&f), "\"scene\":0,", "\"scene\":0,\"extensionsRequired\":[\"EXT_future_geometry\"],"),
                 MK_ERROR_UNSUPPORTED, "EXT_future_geometry");
    /* Hostile nesting (would overflow recursive JSON code) and a huge view-less accessor. */
    size_t depth = 100000;
    char *deep = malloc(2 * depth + 64);
    strcpy(deep, "{\"asset\":{\"version\":\"2.0\"},\"extras\":");
    size_t at = strlen(deep);
    for (size_t i = 0; i < depth; i++) deep[at++] = '[';
    for (size_t i = 0; i < depth; i++) deep[at++] = ']';
    strcpy(deep + at, "}");
    expect_error(deep, MK_ERROR_LIMIT, "nests deeper");
    fixture_default(&f);
    expect_error(edit(fixture_json(&f), "{\"bufferView\":0,\"byteOffset\":36,\"componentType\":5126,\"count\":3",
                      "{\"componentType\":5126,\"count\":3000000000"), MK_ERROR_LIMIT, "accessor 1");
    /* Malformed JSON and a broken GLB header. */
    char *bad = malloc(32);
    strcpy(bad, "{\"asset\":{\"version\":\"2.0\"");
    expect_error(bad, MK_ERROR_PARSE, "JSON");
    bad = malloc(32);
    memcpy(bad, "glTF\x02\0\0\0\xff\xff\0\0", 13);
    mk_raw_asset raw;
    mk_error err;
    mk_raw_init(&raw, NULL);
    CHECK(mk_import_gltf(bad, 12, NULL, &raw, &err) == MK_ERROR_TRUNCATED);
    mk_raw_free(&raw);
    free(bad);
}

/* The channel sidecar: a valid one groups targets; broken ones fail naming the JSON path. */
static mk_result import_with_sidecar(const char *json, const char *sidecar, mk_raw_asset *raw, mk_error *err)
{
    mk_import_options o = { .channels_sidecar_text = sidecar, .channels_sidecar_size = strlen(sidecar) };
    return gt_import_text(json, &o, raw, err);
}

static void test_sidecar(void)
{
    fixture f;
    fixture_default(&f);
    mk_raw_asset raw;
    mk_error err;
    const char *good = "{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"primitive\":0,"
                       "\"stacking\":\"sequential\",\"channels\":[{\"name\":\"up\",\"targets\":[0,1],\"full_weights\":[0.5,1]}]}]}";
    /* Two targets (the same accessor twice) grouped as in-betweens at 0.5 and 1; the
     * animation drives both, so 2 values per key. */
    fixture_default(&f);
    f.values_count = 6;
    f.values[0] = 0; f.values[1] = 0; f.values[2] = 1; f.values[3] = 0.5f; f.values[4] = 0; f.values[5] = 1;
    char *json = edit(fixture_json(&f), "\"targets\":[{\"POSITION\":1}]", "\"targets\":[{\"POSITION\":1},{\"POSITION\":1}]");
    json = edit(json, "\"weights\":[0.25]", "\"weights\":[0.5,0.25]");
    mk_result r = import_with_sidecar(json, good, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r == MK_OK) {
        CHECK_EQ_INT(raw.channel_count, 1);
        CHECK_EQ_INT(raw.channels[0].target_count, 2);
        CHECK_NEAR(raw.channels[0].targets[0].full_weight, 0.5, 0);
        CHECK_NEAR(raw.channels[0].default_weight, 0.5 * 0.5 + 1.0 * 0.25, 1e-6);   /* w = sum f_k u_k */
        CHECK_EQ_INT(raw.meshes[0].stacking, MK_STACKING_SEQUENTIAL);
        CHECK_EQ_INT(raw.clips[0].track_count, 1);
        CHECK_NEAR(raw.clips[0].tracks[0].keys[1].value, 0.5 * 1 + 1.0 * 0.5, 1e-6);
    }
    mk_raw_free(&raw);
    static const struct { const char *sidecar, *needle; } bad[] = {
        {"{\"format\":\"something-else\",\"version\":1,\"meshes\":[]}", "format"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":2,\"meshes\":[]}", "version"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"channels\":[{\"name\":\"a\",\"targets\":[0,9],\"full_weights\":[0.5,1]}]}]}", "target 9"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"channels\":[{\"name\":\"a\",\"targets\":[0]},{\"name\":\"b\",\"targets\":[0]}]}]}", "used twice"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"channels\":[{\"name\":\"a\",\"targets\":[0,1],\"full_weights\":[0,1]}]}]}", "meshes[0].channels[0]"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"channels\":[{\"name\":\"a\",\"targets\":[0,1]}]}]}", "full_weights"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":-1,\"channels\":[]}]}", "meshes[0]"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"control_points\":{\"count\":1,\"map\":[0,0]},\"channels\":[]}]}", "control points"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"control_points\":{\"count\":1,\"map\":[0,0,5]},\"channels\":[]}]}", "control point 5"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[{\"node\":0,\"channels\":[{\"name\":\"a\",\"targets\":[1,0],\"full_weights\":[1,1]}]}]}", "full weight"},
        {"{\"format\":", "not valid JSON"},
        {"{\"format\":\"morphkit-gltf-channels\",\"version\":1,\"meshes\":[],\"clips\":[{\"start\":0,\"duration\":-1}]}", "clips[0]"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        r = import_with_sidecar(json, bad[i].sidecar, &raw, &err);
        CHECK_MSG(r != MK_OK, "sidecar %zu accepted", i);
        CHECK_MSG(strstr(err.message, bad[i].needle) != NULL, "sidecar %zu: message '%s' does not name '%s'", i, err.message, bad[i].needle);
        printf("  %s\n", err.message);
        mk_raw_free(&raw);
    }
    free(json);
}

/* Allocation failure at every point of an import (each arena fails its K-th call) gives
 * MK_ERROR_OUT_OF_MEMORY or success, never a crash or leak (ASan checks leaks). */
static void test_allocation_failures(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf/AnimatedMorphCube/variants/AnimatedMorphCube.draco.glb", check_corpus_dir());
    size_t size;
    unsigned char *data = check_read_file(path, &size);
    if (!data) SKIP("corpus not found");
    int oom = 0, ok = 0;
    for (uint64_t k = 1; k < 400; k++) {
        mk_allocator al = {0};
        al.fail_after = k;
        mk_raw_asset raw;
        mk_raw_init(&raw, &al);
        mk_error err = {0};
        mk_result r = mk_import_gltf(data, size, NULL, &raw, &err);
        CHECK_MSG(r == MK_OK || r == MK_ERROR_OUT_OF_MEMORY, "fail_after %llu: %s (%s)", (unsigned long long)k,
                  mk_result_name(r), err.message);
        if (r == MK_OK) ok++; else oom++;
        mk_raw_free(&raw);
    }
    CHECK(oom > 0 && ok > 0);
    printf("  %d imports failed cleanly with out-of-memory, %d succeeded\n", oom, ok);
    free(data);
}

/* ---- corpus truncations and byte flips ---- */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint32_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)rng_state;
}

static int mutate_one(const unsigned char *data, size_t size, const char *dir, size_t new_size, int flips)
{
    unsigned char *copy = malloc(size ? size : 1);
    memcpy(copy, data, size);
    for (int i = 0; i < flips && size; i++) copy[rng() % size] ^= (unsigned char)(1u << (rng() % 8));
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err = {0};
    mk_import_options o = { .base_dir = dir };
    mk_result r = mk_import_gltf(copy, new_size, &o, &raw, &err);
    int ok = r == MK_OK || err.message[0] != 0;   /* failure must say something */
    if (!ok) fprintf(stderr, "no message for %s (%zu bytes, %d flips)\n", dir, new_size, flips);
    mk_raw_free(&raw);
    free(copy);
    return ok;
}

static void test_corpus_mutations(void)
{
    static const char *files[] = {
        "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.draco.glb",
        "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.gltfpack-c.glb",
        "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.meshopt.glb",
        "gltf/MorphPrimitivesTest/variants/MorphPrimitivesTest.draco.glb",
        "gltf/SimpleMorph/variants/SimpleMorph.sparse.glb",
        "gltf/SimpleMorph/variants/SimpleMorph.quantized.glb",
        "gltf/SimpleMorph/glTF/SimpleMorph.gltf",
        "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.cubic.gltf",
        "gltf/tinygltf-SparseMorphTargets-issue280/singleBlendshapeCube_sparse.glb",
    };
    const char *corpus = check_corpus_dir();
    int runs = 0, found = 0;
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        char path[1024], dir[1024];
        snprintf(path, sizeof path, "%s/%s", corpus, files[i]);
        size_t size;
        unsigned char *data = check_read_file(path, &size);
        if (!data) continue;
        found++;
        snprintf(dir, sizeof dir, "%s", path);
        *strrchr(dir, '/') = 0;
        /* Every truncation length for small files, a spread of them for larger ones. */
        size_t step = size / 300 + 1;
        for (size_t n = 0; n < size; n += step) { CHECK(mutate_one(data, size, dir, n, 0)); runs++; }
        for (int k = 0; k < 300; k++) { CHECK(mutate_one(data, size, dir, size, 1 + (int)(rng() % 4))); runs++; }
        free(data);
    }
    if (!found) SKIP("corpus not found at %s", corpus);
    printf("  %d mutated imports without a crash\n", runs);
}

CHECK_MAIN(CASE(test_fixture_is_valid), CASE(test_missing_buffer_file), CASE(test_plain_mesh_warns),
           CASE(test_buffer_not_from_working_directory), CASE(test_external_uri_rules), CASE(test_index_out_of_range),
           CASE(test_accessor_counts_disagree), CASE(test_not_finite), CASE(test_cubicspline_one_key),
           CASE(test_structure_errors), CASE(test_sidecar), CASE(test_allocation_failures),
           CASE(test_corpus_mutations))

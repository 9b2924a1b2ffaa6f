/* SPDX-License-Identifier: MIT */
/* Writes fuzz seeds for fuzz_open: plain .morph blobs (fuzz_open's mutator keeps the file size
 * and checksum of mutated blobs right, so seeds are ordinary blobs):
 *   - the test fixtures (basic, line, rich) written q16 and float;
 *   - sequential assets: fixture_basic and fixture_rich with every mesh sequential;
 *   - baked assets: a tube with each sample recipe of samples/recipes applied;
 *   - every FBX and glTF file of the shared corpus, imported and written q16, float and
 *     sequential. The corpus is $MORPHKIT_CORPUS, else $MORPHKIT_SOURCE_ROOT/../shared/corpus,
 *     else the source tree's ../shared/corpus; it is skipped when absent.
 * Blobs over MAX_SEED bytes (the fuzzer's -max_len) and repeats of a blob are left out; blobs
 * over SMALL_SEED are written q16 only.
 * usage: make_seeds DIR */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "bake.h"
#include "check.h"
#include "fixtures.h"
#include "import.h"
#include "primitives.h"

#define MAX_SEED (1u << 20)
#define SMALL_SEED (64u << 10)     /* float and sequential variants only up to this size */

static int written, skipped, duplicates;
static size_t last_size;           /* of the blob put() last wrote, 0 if none */

/* Checksums and sizes of the blobs written (glTF variants of one model often write the same
 * blob: it is kept once). */
static struct { uint64_t checksum, size; } seen[1024];
static int seen_count;

static int seen_before(const void *blob, size_t size)
{
    uint64_t checksum;
    memcpy(&checksum, (const char *)blob + 24, 8);
    for (int i = 0; i < seen_count; i++)
        if (seen[i].checksum == checksum && seen[i].size == size) return 1;
    if (seen_count < 1024) { seen[seen_count].checksum = checksum; seen[seen_count++].size = size; }
    return 0;
}

static int put(const char *dir, const char *name, const mk_raw_asset *raw, mk_precision p)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_write_options o = { .precision = p };
    void *blob;
    size_t size;
    mk_error err;
    int r = 0;
    last_size = 0;
    if (mk_write_blob(raw, &o, &arena, &blob, &size, NULL, &err) != MK_OK) {
        fprintf(stderr, "make_seeds: %s: %s (left out)\n", name, err.message);
        skipped++;
    } else if (size > MAX_SEED) {
        fprintf(stderr, "make_seeds: %s: %zu bytes (left out)\n", name, size);
        skipped++;
    } else if (seen_before(blob, size)) {
        duplicates++;
    } else {
        last_size = size;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, name);
        FILE *f = fopen(path, "wb");
        if (!f || fwrite(blob, 1, size, f) != size) r = 1; else written++;
        if (f && fclose(f) != 0) r = 1;
    }
    mk_arena_free_all(&arena);
    return r;
}

static void make_sequential(mk_raw_asset *raw)
{
    for (uint32_t i = 0; i < raw->mesh_count; i++) raw->meshes[i].stacking = MK_STACKING_SEQUENTIAL;
}

/* Writes one raw asset as q16 and, when that is new and small, float and (when `sequential`)
 * q16 with sequential stacking. */
static int put_all(const char *dir, const char *name, mk_raw_asset *raw, int sequential)
{
    char n[1024];
    int r = 0;
    snprintf(n, sizeof n, "%s.q16.morph", name);
    r |= put(dir, n, raw, MK_PRECISION_Q16);
    if (last_size == 0 || last_size > SMALL_SEED) return r;
    snprintf(n, sizeof n, "%s.float.morph", name);
    r |= put(dir, n, raw, MK_PRECISION_FLOAT);
    if (sequential) {
        make_sequential(raw);
        snprintf(n, sizeof n, "%s.sequential.morph", name);
        r |= put(dir, n, raw, MK_PRECISION_Q16);
    }
    return r;
}

static int fixtures(const char *dir)
{
    int r = 0;
    for (int k = 0; k < 3; k++) {
        mk_raw_asset raw;
        mk_raw_init(&raw, NULL);
        if (k == 0) fixture_basic(&raw);
        else if (k == 1) fixture_line(&raw, 200, 5, 3);
        else fixture_rich(&raw);
        r |= put_all(dir, k == 0 ? "basic" : k == 1 ? "line" : "rich", &raw, k != 1);
        mk_raw_free(&raw);
    }
    return r;
}

/* The sample recipes' mesh: a tube of radius 0.5 along y in [0, 2] named "tube" (like
 * samples/make_example's, coarser). */
static void make_tube(mk_raw_asset *raw)
{
    if (!mk_raw_add_tube(raw, "tube", 12, 10)) { fprintf(stderr, "make_seeds: out of memory\n"); exit(1); }
}

static const char *source_root(void)
{
    const char *root = getenv("MORPHKIT_SOURCE_ROOT");
    return root && *root ? root : MK_SOURCE_ROOT;
}

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

/* Each sample recipe on its own tube. */
static int baked(const char *dir)
{
    char recipes[1024];
    snprintf(recipes, sizeof recipes, "%s/samples/recipes", source_root());
    DIR *d = opendir(recipes);
    if (!d) { fprintf(stderr, "make_seeds: no recipes at %s (baked seeds left out)\n", recipes); return 0; }
    int r = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (!has_suffix(e->d_name, ".json")) continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", recipes, e->d_name);
        size_t size;
        unsigned char *json = check_read_file(path, &size);
        if (!json) continue;
        mk_raw_asset raw;
        mk_raw_init(&raw, NULL);
        make_tube(&raw);
        mk_bake_options options;
        memset(&options, 0, sizeof options);
        options.base_dir = recipes;
        options.load_asset = mk_import_load_asset;  /* the transfer sample's source asset */
        mk_error err;
        if (mk_bake_recipe(&raw, (const char *)json, size, &options, NULL, &err) == MK_OK) {
            char name[512];
            snprintf(name, sizeof name, "baked_%.*s", (int)(strlen(e->d_name) - 5), e->d_name);
            r |= put_all(dir, name, &raw, 1);
        } else {
            fprintf(stderr, "make_seeds: recipe %s: %s (left out)\n", e->d_name, err.message);
            skipped++;
        }
        mk_raw_free(&raw);
        free(json);
    }
    closedir(d);
    return r;
}

/* Every .fbx, .gltf and .glb under path (recursively), imported. */
static int corpus_files(const char *dir, const char *path, const char *prefix)
{
    DIR *d = opendir(path);
    if (!d) return 0;
    int r = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        char child[2048], name[1024];
        snprintf(child, sizeof child, "%s/%s", path, e->d_name);
        snprintf(name, sizeof name, "%s%s%s", prefix, *prefix ? "_" : "", e->d_name);
        struct stat st;
        if (stat(child, &st) != 0) continue;
        if (S_ISDIR(st.st_mode)) {
            r |= corpus_files(dir, child, name);
            continue;
        }
        if (!has_suffix(e->d_name, ".fbx") && !has_suffix(e->d_name, ".gltf") && !has_suffix(e->d_name, ".glb")) continue;
        mk_raw_asset raw;
        mk_raw_init(&raw, NULL);
        mk_import_options options;
        memset(&options, 0, sizeof options);
        mk_error err;
        if (mk_import_file(child, &options, &raw, &err) == MK_OK) {
            r |= put_all(dir, name, &raw, 1);
        } else {
            fprintf(stderr, "make_seeds: %s: %s (left out)\n", child, err.message);
            skipped++;
        }
        mk_raw_free(&raw);
    }
    closedir(d);
    return r;
}

static int corpus(const char *dir)
{
    char path[1024];
    const char *env = getenv("MORPHKIT_CORPUS");
    if (env && *env) snprintf(path, sizeof path, "%s", env);
    else snprintf(path, sizeof path, "%s/../shared/corpus", source_root());
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "make_seeds: no corpus at %s (its seeds left out)\n", path);
        return 0;
    }
    char sub[1100];
    snprintf(sub, sizeof sub, "%s/fbx", path);
    int r = corpus_files(dir, sub, "fbx");
    snprintf(sub, sizeof sub, "%s/gltf", path);
    return r | corpus_files(dir, sub, "gltf");
}

int main(int argc, char **argv)
{
    if (argc < 2) { fprintf(stderr, "usage: make_seeds DIR\n"); return 2; }
    int r = fixtures(argv[1]) | baked(argv[1]) | corpus(argv[1]);
    fprintf(stderr, "make_seeds: %d seeds written, %d duplicates and %d others left out\n", written, duplicates, skipped);
    return r;
}

/* SPDX-License-Identifier: MIT */
/* An FBX import on worker threads: a mesh's large arrays are decoded together
 * (fbx_prefetch.c), its shapes decoded and expanded (fbx_shapes.c). The imported model, its
 * warnings (which and in what order), the blob and, for a broken file, the error are the same
 * on 1, 2, 3 and 8 threads, including channels whose in-betweens the skip rules drop (zero and
 * repeated full weights), Blender per-vertex FullWeights, entries outside the control points,
 * authored shape normals and a corrupt zlib stream in a mesh array. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fbx_test_util.h"
#include "fbx_writer.h"

#define GRID 120                 /* control points per side */
#define CHANNELS 14
#define ENTRIES 2500             /* sparse entries of a plain shape */

static const uint32_t thread_counts[] = { 1, 2, 3, 8 };

typedef struct grid_scene {
    double *points, *normals;
    int32_t *polygons;
    fbxw_shape shapes[CHANNELS][3];
    fbxw_channel channels[CHANNELS];
    int32_t *indexes[CHANNELS][3];
    double *deltas[CHANNELS][3], *shape_normals[CHANNELS][3], *full_weights[CHANNELS];
    fbxw_mesh mesh;
    fbxw_scene scene;
} grid_scene;

static uint32_t next_random(uint32_t *state)
{
    *state = *state * 1664525u + 1013904223u;
    return *state >> 8;
}

/* A GRID x GRID plane of quads; channel c has one shape, except channel 10 (in-betweens at 50,
 * 50 and 100 %: the second is a repeat and dropped), channel 11 (0 and 100 %: the first is
 * skipped) and channel 12 (50 and 50 %: the first has too few Vertices values and is skipped,
 * so the repeat is kept: the importer runs it only then). Channel 4 lists a control point past the mesh; channel 6 has normals; channel 9's
 * FullWeights (per-vertex weights for Blender) has one entry too few. Channels 3 and 8 get a
 * NaN delta when `nan`. */
static void build(grid_scene *g, int blender, int nan)
{
    memset(g, 0, sizeof *g);
    const uint32_t cps = GRID * GRID, quads = (GRID - 1) * (GRID - 1);
    g->points = calloc((size_t)cps * 3, sizeof(double));
    g->polygons = calloc((size_t)quads * 4, sizeof(int32_t));
    g->normals = calloc((size_t)quads * 4 * 3, sizeof(double));
    for (uint32_t y = 0; y < GRID; y++)
        for (uint32_t x = 0; x < GRID; x++) {
            g->points[3 * (y * GRID + x)] = x;
            g->points[3 * (y * GRID + x) + 1] = y;
        }
    uint32_t q = 0;
    for (uint32_t y = 0; y + 1 < GRID; y++)
        for (uint32_t x = 0; x + 1 < GRID; x++, q++) {
            int32_t a = (int32_t)(y * GRID + x);
            g->polygons[4 * q] = a;
            g->polygons[4 * q + 1] = a + 1;
            g->polygons[4 * q + 2] = a + 1 + GRID;
            g->polygons[4 * q + 3] = ~(a + GRID);
            for (int k = 0; k < 4; k++) g->normals[3 * (4 * q + (uint32_t)k) + 2] = 1.0;
        }
    uint32_t seed = 12345;
    for (uint32_t c = 0; c < CHANNELS; c++) {
        uint32_t shape_count = c == 10 ? 3 : c == 11 || c == 12 ? 2 : 1;
        uint32_t entries = ENTRIES + 300 * c;
        for (uint32_t s = 0; s < shape_count; s++) {
            int32_t *idx = calloc(entries, sizeof(int32_t));
            double *d = calloc((size_t)entries * 3, sizeof(double));
            double *n = c == 6 ? calloc((size_t)entries * 3, sizeof(double)) : NULL;
            for (uint32_t e = 0; e < entries; e++) {
                idx[e] = (int32_t)(next_random(&seed) % cps);  /* repeats sum, as the importer does */
                for (int k = 0; k < 3; k++) d[3 * e + (uint32_t)k] = (double)(next_random(&seed) % 2001) / 1000.0 - 1.0;
                if (n) n[3 * e + 2] = (double)(next_random(&seed) % 1000) / 2000.0;
            }
            if (c == 4) idx[entries / 2] = (int32_t)cps + 7;
            if (nan && (c == 3 || c == 8) && s == 0) d[3 * (entries - 5) + 1] = NAN;
            g->indexes[c][s] = idx;
            g->deltas[c][s] = d;
            g->shape_normals[c][s] = n;
            g->shapes[c][s] = (fbxw_shape){ NULL, entries, idx, d, n, c == 12 && s == 0 ? 1u : 0u };
        }
        uint32_t fw_count = shape_count;
        double *fw;
        if (blender && shape_count == 1) {
            fw_count = c == 9 ? entries - 1 : entries;
            fw = calloc(fw_count, sizeof(double));
            for (uint32_t e = 0; e < fw_count; e++) fw[e] = (double)(next_random(&seed) % 101);
        } else {
            fw = calloc(3, sizeof(double));
            fw[0] = c == 10 || c == 12 ? 50 : c == 11 ? 0 : 100;
            fw[1] = c == 10 || c == 12 ? 50 : 100;
            fw[2] = 100;
        }
        g->full_weights[c] = fw;
        g->channels[c] = (fbxw_channel){ .deform_percent = 10.0 * c, .shape_count = shape_count, .shapes = g->shapes[c],
                                         .full_weight_count = fw_count, .full_weights = fw };
    }
    static const char *const channel_names[CHANNELS] = { "c0", "c1", "c2", "c3", "c4", "c5", "c6",
                                                         "c7", "c8", "c9", "c10", "c11", "c12", "c13" };
    static const char *const shape_names[CHANNELS][3] = {
        { "s0" }, { "s1" }, { "s2" }, { "s3" }, { "s4" }, { "s5" }, { "s6" }, { "s7" }, { "s8" }, { "s9" },
        { "s10a", "s10b", "s10c" }, { "s11a", "s11b" }, { "s12a", "s12b" }, { "s13" } };
    for (uint32_t c = 0; c < CHANNELS; c++) {
        g->channels[c].name = channel_names[c];
        for (uint32_t s = 0; s < g->channels[c].shape_count; s++) g->shapes[c][s].name = shape_names[c][s];
    }
    g->mesh = (fbxw_mesh){ .name = "Grid", .control_point_count = cps, .control_points = g->points,
                           .polygon_vertex_count = quads * 4, .polygon_vertex_index = g->polygons,
                           .normals = g->normals, .channel_count = CHANNELS, .channels = g->channels, .parent = -1 };
    g->scene = (fbxw_scene){ .version = 7400, .binary = 1, .compress = 1, .mesh_count = 1, .meshes = &g->mesh,
                             .creator = blender ? "Blender (stable FBX IO) - 3.4.1 - 4.37.1" : NULL };
}

static void release(grid_scene *g)
{
    free(g->points);
    free(g->normals);
    free(g->polygons);
    for (uint32_t c = 0; c < CHANNELS; c++) {
        for (uint32_t s = 0; s < 3; s++) {
            free(g->indexes[c][s]);
            free(g->deltas[c][s]);
            free(g->shape_normals[c][s]);
        }
        free(g->full_weights[c]);
    }
}

typedef struct outcome {
    mk_result result;
    mk_error err;
    uint32_t warning_count;
    mk_raw_warning *warnings;
    void *blob;
    size_t blob_size;
} outcome;

static void import_with(const unsigned char *data, size_t size, uint32_t threads, outcome *o)
{
    memset(o, 0, sizeof *o);
    mk_raw_asset raw;
    mk_import_options io = { .threads = threads };
    o->result = ft_import(data, size, &io, &raw, &o->err);
    o->warning_count = raw.warning_count;
    uint32_t kept = raw.warning_count < MK_RAW_MAX_WARNINGS ? raw.warning_count : MK_RAW_MAX_WARNINGS;
    o->warnings = calloc(kept ? kept : 1, sizeof *o->warnings);
    if (raw.warnings && kept) memcpy(o->warnings, raw.warnings, kept * sizeof *o->warnings);
    if (o->result == MK_OK) {
        mk_arena arena;
        mk_arena_init(&arena, NULL);
        mk_write_options wo = { .precision = MK_PRECISION_FLOAT, .threads = 1 };
        void *blob = NULL;
        if (mk_write_blob(&raw, &wo, &arena, &blob, &o->blob_size, NULL, &o->err) == MK_OK) {
            o->blob = malloc(o->blob_size);
            memcpy(o->blob, blob, o->blob_size);
        }
        mk_arena_free_all(&arena);
    }
    mk_raw_free(&raw);
}

/* Flips a byte in the middle of the zlib stream of the first array named `name` after `after`
 * (binary 7400: name length byte, name, then the 'd'/'f'/'i' array header of 13 bytes). */
static int corrupt_array(unsigned char *data, size_t size, const char *after, const char *name)
{
    size_t n = strlen(name), from = 0, a = strlen(after);
    for (; from + a <= size && memcmp(data + from, after, a) != 0; from++) {}
    for (size_t i = from; i + n + 14 < size; i++) {
        if (data[i - 1] != n || memcmp(data + i, name, n) != 0) continue;
        const unsigned char *h = data + i + n;
        uint32_t encoding = (uint32_t)h[5] | (uint32_t)h[6] << 8, stored = (uint32_t)h[9] | (uint32_t)h[10] << 8 |
                                                                        (uint32_t)h[11] << 16 | (uint32_t)h[12] << 24;
        if (encoding != 1 || stored < 64 || i + n + 13 + stored > size) return 0;
        for (uint32_t k = stored / 2; k < stored / 2 + 16; k++) data[i + n + 13 + k] ^= 0x5a;
        return 1;
    }
    return 0;
}

/* corrupt: 0 none, 1 the mesh's Vertices, 2 its layer Normals (both decoded ahead). */
static void compare_threads(int blender, int nan, int corrupt, const char *what)
{
    grid_scene g;
    build(&g, blender, nan);
    unsigned char *data = NULL;
    size_t size = 0;
    CHECK(fbxw_write(&g.scene, &data, &size) == 0);
    if (corrupt)
        CHECK(corrupt_array(data, size, corrupt == 1 ? "Geometry" : "LayerElementNormal", corrupt == 1 ? "Vertices" : "Normals"));
    outcome first;
    import_with(data, size, 1, &first);
    if (corrupt) {
        CHECK_MSG(first.result == MK_ERROR_PARSE && strstr(first.err.message, corrupt == 1 ? "Vertices" : "Normals") &&
                      (strstr(first.err.message, "zlib") || strstr(first.err.message, "compressed array")),
                  "%s: %s", what, first.err.message);
    } else if (nan) {
        CHECK_MSG(first.result == MK_ERROR_NOT_FINITE, "%s: %s", what, first.err.message);
        CHECK_MSG(strstr(first.err.message, "'s3'") != NULL, "%s: the first broken shape in file order: %s", what,
                  first.err.message);
    } else {
        CHECK_MSG(first.result == MK_OK && first.blob != NULL, "%s: %s", what, first.err.message);
        /* repeat (c10), zero full weight (c11), index past the mesh (c4), the broken first shape of
         * c12 (its repeat is used, not dropped), and for Blender the FullWeights count of c9 */
        CHECK_MSG(first.warning_count == (blender ? 5u : 4u), "%s: %u warnings", what, first.warning_count);
        int broken_seen = 0, c12_dropped = 0;
        for (uint32_t w = 0; w < first.warning_count && w < MK_RAW_MAX_WARNINGS; w++) {
            broken_seen |= strstr(first.warnings[w].message, "shape needs Indexes and 3 Vertices values") != NULL;
            c12_dropped |= strstr(first.warnings[w].message, "'s12") != NULL && strstr(first.warnings[w].message, "duplicate") != NULL;
        }
        CHECK_MSG(broken_seen && !c12_dropped, "%s: c12's broken shape skipped and its repeat kept", what);
        mk_asset asset;
        uint32_t c12 = UINT32_MAX;
        mk_channel_info info;
        memset(&info, 0, sizeof info);
        if (first.blob && mk_asset_open(first.blob, first.blob_size, &asset, NULL) == MK_OK &&
            mk_find_channels(&asset, "c12", &c12, 1) == 1)
            mk_channel_get(&asset, c12, &info);
        CHECK_MSG(c12 != UINT32_MAX && info.target_count == 1, "%s: channel c12 holds its kept repeat", what);
    }
    for (size_t t = 1; t < sizeof thread_counts / sizeof thread_counts[0]; t++)
        for (int round = 0; round < 3; round++) {
            outcome o;
            import_with(data, size, thread_counts[t], &o);
            CHECK_MSG(o.result == first.result && strcmp(o.err.message, first.err.message) == 0,
                      "%s, %u threads: result %s '%s', one thread %s '%s'", what, thread_counts[t], mk_result_name(o.result),
                      o.err.message, mk_result_name(first.result), first.err.message);
            CHECK_MSG(o.warning_count == first.warning_count, "%s, %u threads: %u warnings, one thread %u", what,
                      thread_counts[t], o.warning_count, first.warning_count);
            for (uint32_t w = 0; w < o.warning_count && w < first.warning_count && w < MK_RAW_MAX_WARNINGS; w++)
                CHECK_MSG(strcmp(o.warnings[w].message, first.warnings[w].message) == 0,
                          "%s, %u threads: warning %u '%s', one thread '%s'", what, thread_counts[t], w,
                          o.warnings[w].message, first.warnings[w].message);
            CHECK_MSG(o.blob_size == first.blob_size && (!o.blob || memcmp(o.blob, first.blob, o.blob_size) == 0),
                      "%s, %u threads: the blob differs from one thread's", what, thread_counts[t]);
            free(o.warnings);
            free(o.blob);
        }
    free(first.warnings);
    free(first.blob);
    free(data);
    release(&g);
}

static void test_plain_shapes(void) { compare_threads(0, 0, 0, "plain"); }
static void test_blender_vertex_weights(void) { compare_threads(1, 0, 0, "Blender"); }
static void test_first_error_in_file_order(void)
{
    compare_threads(0, 1, 0, "NaN deltas");
    compare_threads(1, 1, 0, "NaN deltas, Blender");
}
static void test_corrupt_mesh_arrays(void)
{
    compare_threads(0, 0, 1, "corrupt Vertices");
    compare_threads(0, 0, 2, "corrupt Normals");
}

CHECK_MAIN(CASE(test_plain_shapes), CASE(test_blender_vertex_weights), CASE(test_first_error_in_file_order),
           CASE(test_corrupt_mesh_arrays))

/* SPDX-License-Identifier: MIT */
/* FBX import benchmark (built, not run as a test).
 *
 * Writes a large binary FBX 7500 with the test writer into a temporary directory: a grid mesh
 * of N x N control points (default 1024 x 1024 = 1 048 576) with quads, ByPolygonVertex
 * normals, and C channels (default 50) of two shapes each (an in-between at 50 % and the full
 * target), each shape moving `--moved` control points (default 10 000), every channel
 * animated by a 121-key cubic auto-tangent curve. Then, in a child process, reads the file and
 * imports it with mk_import_fbx, and reports:
 *   - file MB/s and control points/s for read + convert (and convert alone),
 *   - peak memory: bytes live through the importer's allocator plus the file buffer, and the
 *     child's maximum resident set size, both as a ratio to the file size,
 *   - a memcpy of the file measured in the same run, for scale.
 *
 * --shape-normals writes non-zero shape Normals, so the importer keeps them instead of computing
 * target normals with mk_raw_compute_target_normals (isolates the reader's own cost).
 *
 * usage: bench_fbx_import [--grid N] [--channels C] [--moved M] [--compress] [--shape-normals]
 *                         [--keep] [--dir D]
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "fbx_writer.h"
#include "fbx_import.h"
#include "import.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Counting allocator: live and peak bytes through mk_allocator (raw model + parse scratch). */
typedef struct counter { size_t live, peak; } counter;
static void *count_alloc(void *user, size_t size)
{
    counter *c = user;
    size_t *p = malloc(size + 16);
    if (!p) return NULL;
    p[0] = size;
    c->live += size;
    if (c->live > c->peak) c->peak = c->live;
    return (char *)p + 16;
}
static void count_free(void *user, void *ptr)
{
    counter *c = user;
    if (!ptr) return;
    size_t *p = (size_t *)((char *)ptr - 16);
    c->live -= p[0];
    free(p);
}

static int generate(const char *path, uint32_t grid, uint32_t channels, uint32_t moved, int compress, int shape_normals)
{
    size_t cps = (size_t)grid * grid, quads = (size_t)(grid - 1) * (grid - 1);
    double *points = malloc(cps * 3 * sizeof(double));
    int32_t *polys = malloc(quads * 4 * sizeof(int32_t));
    double *normals = malloc(quads * 4 * 3 * sizeof(double));
    fbxw_channel *chans = calloc(channels, sizeof *chans);
    fbxw_shape *shapes = calloc(2 * (size_t)channels, sizeof *shapes);
    fbxw_curve *curves = calloc(channels, sizeof *curves);
    int32_t *indexes = malloc((size_t)moved * sizeof(int32_t));
    double *deltas_half = malloc((size_t)moved * 3 * sizeof(double));
    double *deltas_full = malloc((size_t)moved * 3 * sizeof(double));
    double *shape_normal = malloc((size_t)moved * 3 * sizeof(double));
    enum { KEYS = 121 };
    int64_t *times = malloc(KEYS * sizeof(int64_t));
    float *values = malloc((size_t)channels * KEYS * sizeof(float));
    int32_t *flags = malloc(KEYS * sizeof(int32_t));
    float *data = calloc(KEYS * 4, sizeof(float));
    static const double full_weights[2] = { 50, 100 };
    if (!points || !polys || !normals || !chans || !shapes || !curves || !indexes || !deltas_half || !deltas_full || !shape_normal ||
        !times || !values || !flags || !data)
        return -1;
    for (uint32_t j = 0; j < grid; j++)
        for (uint32_t i = 0; i < grid; i++) {
            double *p = points + 3 * ((size_t)j * grid + i);
            p[0] = i * 0.01;
            p[1] = 0.05 * ((i * 7 + j * 13) % 17) / 17.0;
            p[2] = j * 0.01;
        }
    size_t q = 0;
    for (uint32_t j = 0; j + 1 < grid; j++)
        for (uint32_t i = 0; i + 1 < grid; i++, q++) {
            int32_t a = (int32_t)(j * grid + i);
            polys[4 * q + 0] = a;
            polys[4 * q + 1] = a + (int32_t)grid;
            polys[4 * q + 2] = a + (int32_t)grid + 1;
            polys[4 * q + 3] = ~(a + 1);
            for (int k = 0; k < 4; k++) {
                double *n = normals + 3 * (4 * q + (size_t)k);
                n[0] = 0; n[1] = 1; n[2] = 0;
            }
        }
    for (uint32_t e = 0; e < moved; e++) {
        indexes[e] = (int32_t)(((uint64_t)e * 97) % cps);  /* spread over the mesh, unsorted */
        deltas_half[3 * e] = 0.001; deltas_half[3 * e + 1] = 0.02; deltas_half[3 * e + 2] = 0;
        deltas_full[3 * e] = 0.002; deltas_full[3 * e + 1] = 0.05; deltas_full[3 * e + 2] = -0.001;
        shape_normal[3 * e] = 0.01; shape_normal[3 * e + 1] = -0.001; shape_normal[3 * e + 2] = 0.0;
    }
    for (int k = 0; k < KEYS; k++) {
        times[k] = (int64_t)k * (FBXW_KTIME_PER_SECOND / 24);
        flags[k] = 0x6108;
    }
    for (uint32_t c = 0; c < channels; c++) {
        for (int k = 0; k < KEYS; k++) values[(size_t)c * KEYS + (size_t)k] = (float)(50 + 50 * ((k + (int)c) % 24 < 12 ? 1 : -1));
        curves[c] = (fbxw_curve){ KEYS, times, values + (size_t)c * KEYS, flags, data };
        shapes[2 * c] = (fbxw_shape){ "half", moved, indexes, deltas_half, shape_normals ? shape_normal : NULL, 0 };
        shapes[2 * c + 1] = (fbxw_shape){ "full", moved, indexes, deltas_full, shape_normals ? shape_normal : NULL, 0 };
        chans[c].name = "channel";
        chans[c].shape_count = 2;
        chans[c].shapes = &shapes[2 * c];
        chans[c].full_weight_count = 2;
        chans[c].full_weights = full_weights;
        chans[c].curve = &curves[c];
    }
    fbxw_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    mesh.name = "Grid";
    mesh.control_point_count = (uint32_t)cps;
    mesh.control_points = points;
    mesh.polygon_vertex_count = (uint32_t)(4 * quads);
    mesh.polygon_vertex_index = polys;
    mesh.normals = normals;
    mesh.channel_count = channels;
    mesh.channels = chans;
    mesh.parent = -1;
    fbxw_scene scene;
    memset(&scene, 0, sizeof scene);
    scene.version = 7500;
    scene.binary = 1;
    scene.compress = compress;
    scene.stack_stop = (KEYS - 1) * (FBXW_KTIME_PER_SECOND / 24);
    scene.mesh_count = 1;
    scene.meshes = &mesh;
    int r = fbxw_write_file(&scene, path);
    free(points); free(polys); free(normals); free(chans); free(shapes); free(curves); free(indexes);
    free(deltas_half); free(deltas_full); free(shape_normal); free(times); free(values); free(flags); free(data);
    return r;
}

/* Child: read + import, print the numbers. */
static int measure(const char *path)
{
    double t0 = now();
    FILE *f = fopen(path, "rb");
    if (!f) { perror(path); return 1; }
    struct stat st;
    if (fstat(fileno(f), &st)) return 1;
    size_t size = (size_t)st.st_size;
    unsigned char *file = malloc(size);
    if (!file || fread(file, 1, size, f) != size) { fprintf(stderr, "read failed\n"); return 1; }
    fclose(f);
    double t1 = now();
    counter c = { 0, 0 };
    mk_allocator allocator;
    memset(&allocator, 0, sizeof allocator);
    allocator.alloc = count_alloc;
    allocator.free = count_free;
    allocator.user = &c;
    mk_raw_asset raw;
    mk_raw_init(&raw, &allocator);
    mk_error err;
    mk_result r = mk_import_fbx(file, size, NULL, &raw, &err);
    double t2 = now();
    if (r != MK_OK) { fprintf(stderr, "import failed: %s\n", err.message); return 1; }
    uint64_t vertices = 0, cps = 0, targets = 0, moved = 0;
    for (uint32_t m = 0; m < raw.mesh_count; m++) { vertices += raw.meshes[m].vertex_count; cps += raw.meshes[m].control_point_count; }
    for (uint32_t ch = 0; ch < raw.channel_count; ch++)
        for (uint32_t k = 0; k < raw.channels[ch].target_count; k++) { targets++; moved += raw.channels[ch].targets[k].count; }
    /* memcpy of the file for scale (same process, same buffer sizes). */
    unsigned char *copy = malloc(size);
    double t3 = now();
    if (copy) memcpy(copy, file, size);
    double t4 = now();
    volatile unsigned char sink = copy ? copy[size / 2] : 0;
    (void)sink;
    double mb = (double)size / 1e6;
    printf("file: %.1f MB, %llu control points, %llu render vertices, %u channels, %llu targets (%llu stored entries), %u clips\n",
           mb, (unsigned long long)cps, (unsigned long long)vertices, raw.channel_count, (unsigned long long)targets,
           (unsigned long long)moved, raw.clip_count);
    printf("read:            %.3f s\n", t1 - t0);
    printf("convert:         %.3f s  %.1f MB/s  %.2f M control points/s\n", t2 - t1, mb / (t2 - t1), cps / 1e6 / (t2 - t1));
    printf("read + convert:  %.3f s  %.1f MB/s  %.2f M control points/s\n", t2 - t0, mb / (t2 - t0), cps / 1e6 / (t2 - t0));
    printf("memcpy of file:  %.3f s  %.1f MB/s (for scale)\n", t4 - t3, mb / (t4 - t3));
    printf("importer peak (allocator, raw + scratch): %.1f MB; + file buffer = %.1f MB = %.2f x file\n", c.peak / 1e6,
           (c.peak + size) / 1e6, (double)(c.peak + size) / (double)size);
    printf("raw model kept: %.1f MB\n", c.live / 1e6);
    mk_raw_free(&raw);
    free(copy);
    free(file);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    uint32_t grid = 1024, channels = 50, moved = 10000;
    int compress = 0, keep = 0, shape_normals = 0;
    const char *dir = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--grid") && i + 1 < argc) grid = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--channels") && i + 1 < argc) channels = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--moved") && i + 1 < argc) moved = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--compress")) compress = 1;
        else if (!strcmp(argv[i], "--shape-normals")) shape_normals = 1;
        else if (!strcmp(argv[i], "--keep")) keep = 1;
        else if (!strcmp(argv[i], "--dir") && i + 1 < argc) dir = argv[++i];
        else { fprintf(stderr, "usage: %s [--grid N] [--channels C] [--moved M] [--compress] [--shape-normals] [--keep] [--dir D]\n", argv[0]); return 2; }
    }
    if (grid < 2 || moved == 0) return 2;
    char template_dir[512];
    snprintf(template_dir, sizeof template_dir, "%s/mk-fbx-bench-XXXXXX", dir ? dir : (getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp"));
    if (!mkdtemp(template_dir)) { perror("mkdtemp"); return 1; }
    char path[600];
    snprintf(path, sizeof path, "%s/grid.fbx", template_dir);
    double t0 = now();
    if (generate(path, grid, channels, moved, compress, shape_normals)) { fprintf(stderr, "writing %s failed\n", path); return 1; }
    printf("generated %s in %.2f s (%s arrays)\n", path, now() - t0, compress ? "zlib" : "raw");
    fflush(stdout);
    pid_t child = fork();
    if (child < 0) { perror("fork"); return 1; }
    if (child == 0) _exit(measure(path));
    int status = 0;
    struct rusage usage;
    if (waitpid(child, &status, 0) < 0 || getrusage(RUSAGE_CHILDREN, &usage)) { perror("waitpid"); return 1; }
    struct stat st;
    stat(path, &st);
    printf("child max RSS: %.1f MB = %.2f x file\n", usage.ru_maxrss / 1e3, usage.ru_maxrss * 1e3 / (double)st.st_size);
    if (!keep) {
        unlink(path);
        rmdir(template_dir);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

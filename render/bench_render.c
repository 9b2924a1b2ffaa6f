/* SPDX-License-Identifier: MIT */
/* render_bench [level] [rounds]: times mkr_draw_mesh on a subdivided sphere (level 7:
 * 163842 vertices, 327680 triangles) in a 512x512 cell, per view, then a 6-cell contact
 * sheet and its PNG encoding. Prints the best and median milliseconds. Not a test. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "demo_mesh.h"
#include "render.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void report(const char *what, double *ms, int rounds)
{
    qsort(ms, (size_t)rounds, sizeof *ms, by_value);
    printf("%-44s best %7.2f ms  median %7.2f ms\n", what, ms[0], ms[rounds / 2]);
}

int main(int argc, char **argv)
{
    int level = argc > 1 ? atoi(argv[1]) : 7, rounds = argc > 2 ? atoi(argv[2]) : 15;
    if (level < 0 || level > 9 || rounds < 1) {
        fprintf(stderr, "usage: render_bench [level 0-9] [rounds >= 1]\n");
        return 2;
    }
    demo_mesh sphere;
    if (!demo_icosphere(level, &sphere)) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    /* A bump so the normals vary like a deformed frame's. */
    static const float dir[3] = { 0.48f, 0.6f, 0.64f };
    demo_bulge(sphere.positions, sphere.vertex_count, dir, 0.35f, 0.5f, sphere.positions);
    demo_vertex_normals(sphere.positions, sphere.vertex_count, sphere.triangles, sphere.triangle_count, sphere.normals);
    printf("mesh: %u vertices, %u triangles; cell 512x512; %d rounds\n", sphere.vertex_count, sphere.triangle_count,
           rounds);

    mkr_image img;
    mk_error err;
    if (mkr_image_create(&img, 512, 512, &err) != MK_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    float lo[3], hi[3];
    mkr_bounds_reset(lo, hi);
    mkr_bounds_add(lo, hi, sphere.positions, sphere.vertex_count);
    double *ms = malloc((size_t)rounds * sizeof *ms);
    static const uint8_t background[4] = { 38, 40, 45, 255 };
    for (int with_normals = 1; with_normals >= 0; with_normals--)
        for (int v = 0; v < MKR_VIEW_COUNT; v++) {
            mkr_camera cam = { 0 };
            mkr_camera_set_view(&cam, (mkr_view)v);
            mkr_camera_frame(&cam, lo, hi, 0, 0, 512, 512, 0.06f);
            mkr_mesh_view mesh = { .vertex_count = sphere.vertex_count, .positions = sphere.positions,
                                   .normals = with_normals ? sphere.normals : NULL,
                                   .triangle_count = sphere.triangle_count, .triangles = sphere.triangles };
            for (int r = 0; r < rounds; r++) {
                double t0 = now_ms();
                mkr_image_clear(&img, background);
                if (mkr_draw_mesh(&img, &cam, &mesh, NULL, &err) != MK_OK) {
                    fprintf(stderr, "%s\n", err.message);
                    return 1;
                }
                ms[r] = now_ms() - t0;
            }
            char what[64];
            snprintf(what, sizeof what, "cell (clear + draw) %s%s", mkr_view_name((mkr_view)v),
                     with_normals ? "" : " face normals");
            report(what, ms, rounds);
        }
    mkr_image_destroy(&img);

    /* A 6-cell sheet of the same mesh (3x2 cells of 512), then its PNG. */
    mkr_mesh_view mesh = { .vertex_count = sphere.vertex_count, .positions = sphere.positions, .normals = sphere.normals,
                           .triangle_count = sphere.triangle_count, .triangles = sphere.triangles };
    mkr_cell cells[6];
    for (int i = 0; i < 6; i++) cells[i] = (mkr_cell){ .meshes = &mesh, .mesh_count = 1, .time = i * 0.2 };
    mkr_sheet_desc desc = { .cells = cells, .cell_count = 6, .cell_width = 512, .cell_height = 512,
                            .view = MKR_VIEW_ISO, .title = "bench" };
    double *png_ms = malloc((size_t)rounds * sizeof *png_ms);
    size_t png_size = 0;
    int sheet_w = 0, sheet_h = 0;
    for (int r = 0; r < rounds; r++) {
        double t0 = now_ms();
        if (mkr_sheet_render(&desc, &img, &err) != MK_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        double t1 = now_ms();
        mkr_png png;
        if (mkr_png_encode(&img, &png, &err) != MK_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        ms[r] = (t1 - t0) / 6;
        sheet_w = img.width, sheet_h = img.height;
        png_ms[r] = now_ms() - t1;
        png_size = png.size;
        mkr_png_free(&png);
        mkr_image_destroy(&img);
    }
    report("sheet of 6, per cell", ms, rounds);
    char what[96];
    snprintf(what, sizeof what, "png of the %dx%d sheet (%zu bytes)", sheet_w, sheet_h, png_size);
    report(what, png_ms, rounds);
    free(ms);
    free(png_ms);
    demo_mesh_free(&sphere);
    return 0;
}

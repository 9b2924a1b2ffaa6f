/* SPDX-License-Identifier: MIT */
/* render_demo DIR: writes sample pictures into DIR to look at (not a test):
 *   bulge_sheet.png   contact sheet, sphere with a bulge growing over 6 frames (iso view)
 *   bulge_diff.png    diff sheet of those frames against a slightly different bulge, one
 *                     frame with a single vertex moved
 *   views.png         the four standard views of a cube with axis markers (+x red, +y green,
 *                     +z blue)
 *   normals.png       a sphere with outward normals, inverted normals, and face normals
 *   font.png          every glyph at scales 1 to 3, and the color map legend */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "demo_mesh.h"
#include "render.h"

static int save(const mkr_image *img, const char *dir, const char *name)
{
    mkr_png png;
    mk_error err;
    if (mkr_png_encode(img, &png, &err) != MK_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        return 0;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(png.data, 1, png.size, f) == png.size;
    if (f && fclose(f) != 0) ok = 0;
    mkr_png_free(&png);
    if (!ok) fprintf(stderr, "cannot write %s\n", path);
    else printf("%s\n", path);
    return ok;
}

static int fail(const mk_error *err)
{
    fprintf(stderr, "%s\n", err->message);
    return 1;
}

/* Appends an axis-aligned box with one color to the arrays at the given counts. */
static void add_box(float *pos, uint8_t *col, uint32_t *tri, uint32_t *nv, uint32_t *nt, const float lo[3],
                    const float hi[3], const uint8_t rgb[3])
{
    /* Four vertices per face so every face has its own flat normal. */
    static const int faces[6][4][3] = {
        { { 1, 0, 0 }, { 1, 1, 0 }, { 1, 1, 1 }, { 1, 0, 1 } }, { { 0, 0, 1 }, { 0, 1, 1 }, { 0, 1, 0 }, { 0, 0, 0 } },
        { { 0, 1, 1 }, { 1, 1, 1 }, { 1, 1, 0 }, { 0, 1, 0 } }, { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 0, 1 }, { 0, 0, 1 } },
        { { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } }, { { 0, 1, 0 }, { 1, 1, 0 }, { 1, 0, 0 }, { 0, 0, 0 } },
    };
    for (int f = 0; f < 6; f++) {
        uint32_t base = *nv;
        for (int k = 0; k < 4; k++) {
            for (int i = 0; i < 3; i++) {
                pos[3 * (size_t)*nv + i] = faces[f][k][i] ? hi[i] : lo[i];
                col[3 * (size_t)*nv + i] = rgb[i];
            }
            (*nv)++;
        }
        uint32_t quad[6] = { base, base + 1, base + 2, base, base + 2, base + 3 };
        memcpy(tri + 3 * (size_t)*nt, quad, sizeof quad);
        *nt += 2;
    }
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: render_demo OUTPUT_DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    mk_error err;
    mkr_image img;

    /* Six frames of a sphere whose bulge grows, then shrinks a little. */
    demo_mesh sphere;
    if (!demo_icosphere(5, &sphere)) return 1;
    const uint32_t n = sphere.vertex_count;
    enum { FRAMES = 6 };
    static const float dir_bulge[3] = { 0.867f, 0.379f, -0.325f };
    static const float amounts[FRAMES] = { 0.0f, 0.15f, 0.3f, 0.45f, 0.6f, 0.5f };
    float *pos = malloc((size_t)FRAMES * n * 3 * sizeof(float)), *nrm = malloc((size_t)FRAMES * n * 3 * sizeof(float));
    float *ref = malloc((size_t)n * 3 * sizeof(float)), *dist = malloc((size_t)FRAMES * n * sizeof(float));
    if (!pos || !nrm || !ref || !dist) return 1;
    mkr_mesh_view meshes[FRAMES];
    mkr_cell cells[FRAMES];
    char texts[FRAMES][64];
    for (int f = 0; f < FRAMES; f++) {
        float *p = pos + (size_t)f * n * 3, *nr = nrm + (size_t)f * n * 3;
        demo_bulge(sphere.positions, n, dir_bulge, amounts[f], 0.45f, p);
        demo_vertex_normals(p, n, sphere.triangles, sphere.triangle_count, nr);
        meshes[f] = (mkr_mesh_view){ .vertex_count = n, .positions = p, .normals = nr,
                                     .triangle_count = sphere.triangle_count, .triangles = sphere.triangles };
        snprintf(texts[f], sizeof texts[f], "bulge %.2f", amounts[f]);
        cells[f] = (mkr_cell){ .meshes = &meshes[f], .mesh_count = 1, .time = f * 0.2, .text = texts[f] };
    }
    mkr_sheet_desc desc = { .cells = cells, .cell_count = FRAMES, .cell_width = 384, .cell_height = 384,
                            .view = MKR_VIEW_ISO, .title = "demo: sphere, bulge toward (0.87, 0.38, -0.33), iso view" };
    if (mkr_sheet_render(&desc, &img, &err) != MK_OK) return fail(&err);
    if (!save(&img, dir, "bulge_sheet.png")) return 1;
    mkr_image_destroy(&img);

    desc.view = MKR_VIEW_FRONT;
    desc.title = "demo: the same frames, front view";
    if (mkr_sheet_render(&desc, &img, &err) != MK_OK) return fail(&err);
    if (!save(&img, dir, "bulge_sheet_front.png")) return 1;
    mkr_image_destroy(&img);

    /* Diff: each frame against a reference whose bulge is 10% narrower; frame 3 also has one
     * vertex (the one nearest the +x axis) moved by 0.2. */
    uint32_t moved = 0;
    for (uint32_t v = 0; v < n; v++)
        if (sphere.positions[3 * v] > sphere.positions[3 * moved]) moved = v;
    for (int f = 0; f < FRAMES; f++) {
        float *p = pos + (size_t)f * n * 3, *d = dist + (size_t)f * n;
        demo_bulge(sphere.positions, n, dir_bulge, amounts[f], 0.405f, ref);
        if (f == 3) ref[3 * moved] += 0.2f;
        for (uint32_t v = 0; v < n; v++) {
            float dx = p[3 * v] - ref[3 * v], dy = p[3 * v + 1] - ref[3 * v + 1], dz = p[3 * v + 2] - ref[3 * v + 2];
            d[v] = sqrtf(dx * dx + dy * dy + dz * dz);
        }
        meshes[f].scalars = d;
    }
    desc.view = MKR_VIEW_ISO;
    desc.title = "demo: distance to a 10% narrower bulge; t=0.60 s has vertex +x moved by 0.2";
    if (mkr_diff_sheet_render(&desc, &img, &err) != MK_OK) return fail(&err);
    if (!save(&img, dir, "bulge_diff.png")) return 1;
    mkr_image_destroy(&img);

    /* The four views of a cube with axis markers. */
    {
        enum { BOXES = 4 };
        float bpos[BOXES * 24 * 3];
        uint8_t bcol[BOXES * 24 * 3];
        uint32_t btri[BOXES * 12 * 3], nv = 0, nt = 0;
        static const float box[BOXES][2][3] = {
            { { -0.5f, -0.5f, -0.5f }, { 0.5f, 0.5f, 0.5f } },
            { { 0.5f, -0.1f, -0.1f }, { 0.9f, 0.1f, 0.1f } },
            { { -0.1f, 0.5f, -0.1f }, { 0.1f, 0.9f, 0.1f } },
            { { -0.1f, -0.1f, 0.5f }, { 0.1f, 0.1f, 0.9f } },
        };
        static const uint8_t color[BOXES][3] = { { 200, 196, 188 }, { 220, 60, 50 }, { 60, 190, 70 }, { 60, 100, 230 } };
        for (int b = 0; b < BOXES; b++) add_box(bpos, bcol, btri, &nv, &nt, box[b][0], box[b][1], color[b]);
        mkr_mesh_view cube = { .vertex_count = nv, .positions = bpos, .triangle_count = nt, .triangles = btri,
                               .colors = bcol };
        const int cell = 320;
        if (mkr_image_create(&img, 2 * cell, 2 * cell, &err) != MK_OK) return fail(&err);
        static const uint8_t bg[4] = { 38, 40, 45, 255 }, fg[4] = { 236, 236, 236, 255 }, box_bg[4] = { 0, 0, 0, 150 };
        mkr_image_clear(&img, bg);
        float lo[3], hi[3];
        mkr_bounds_reset(lo, hi);
        mkr_bounds_add(lo, hi, bpos, nv);
        for (int v = 0; v < MKR_VIEW_COUNT; v++) {
            mkr_camera cam = { 0 };
            mkr_camera_set_view(&cam, (mkr_view)v);
            mkr_camera_frame(&cam, lo, hi, (v % 2) * cell, (v / 2) * cell, cell, cell, 0.08f);
            if (mkr_draw_mesh(&img, &cam, &cube, NULL, &err) != MK_OK) return fail(&err);
            char label[96];
            snprintf(label, sizeof label, "%s\n+x red, +y green, +z blue", mkr_view_name((mkr_view)v));
            mkr_draw_text(&img, (v % 2) * cell + 2, (v / 2) * cell + 2, label, 1, fg, box_bg);
        }
        if (!save(&img, dir, "views.png")) return 1;
        mkr_image_destroy(&img);
    }

    /* Normals: outward, inverted, none (face normals). */
    {
        demo_mesh s;
        if (!demo_icosphere(3, &s)) return 1;
        float *inverted = malloc((size_t)s.vertex_count * 3 * sizeof(float));
        if (!inverted) return 1;
        for (size_t i = 0; i < (size_t)s.vertex_count * 3; i++) inverted[i] = -s.normals[i];
        mkr_mesh_view a = { .vertex_count = s.vertex_count, .positions = s.positions, .normals = s.normals,
                            .triangle_count = s.triangle_count, .triangles = s.triangles };
        mkr_mesh_view b = a, c = a;
        b.normals = inverted;
        c.normals = NULL;
        mkr_cell nc[3] = { { .meshes = &a, .mesh_count = 1, .time = NAN, .text = "vertex normals" },
                           { .meshes = &b, .mesh_count = 1, .time = NAN, .text = "inverted normals" },
                           { .meshes = &c, .mesh_count = 1, .time = NAN, .text = "face normals" } };
        mkr_sheet_desc nd = { .cells = nc, .cell_count = 3, .cell_width = 256, .cell_height = 256,
                              .view = MKR_VIEW_FRONT, .title = "demo: lighting, front view" };
        if (mkr_sheet_render(&nd, &img, &err) != MK_OK) return fail(&err);
        if (!save(&img, dir, "normals.png")) return 1;
        mkr_image_destroy(&img);
        free(inverted);
        demo_mesh_free(&s);
    }

    /* Font and color map. */
    {
        if (mkr_image_create(&img, 620, 430, &err) != MK_OK) return fail(&err);
        static const uint8_t bg[4] = { 38, 40, 45, 255 }, fg[4] = { 236, 236, 236, 255 };
        static const uint8_t box_bg[4] = { 90, 30, 30, 255 };
        mkr_image_clear(&img, bg);
        char all[200];
        int k = 0;
        for (int ch = 32; ch < 127; ch++) {
            all[k++] = (char)ch;
            if ((ch - 31) % 32 == 0) all[k++] = '\n';
        }
        all[k] = 0;
        int y = 4;
        for (int s = 1; s <= 3; s++) {
            int h;
            mkr_draw_text(&img, 4, y, all, s, fg, s == 1 ? box_bg : NULL);
            mkr_text_box(all, s, NULL, &h);
            y += h + 4;
        }
        mkr_legend legend = { .lo = 0, .hi = 0.25f, .ticks = 5, .caption = "colormap 0 .. 0.25 (second row: x 400 %)",
                              .second_scale = 400, .second_suffix = "%", .text_scale = 1 };
        mkr_legend_draw(&img, 4, y, 600, &legend, fg);
        if (!save(&img, dir, "font.png")) return 1;
        mkr_image_destroy(&img);
    }

    free(pos);
    free(nrm);
    free(ref);
    free(dist);
    demo_mesh_free(&sphere);
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* morphkit_render: silhouettes of the standard views, light direction and normals, depth,
 * the fill rule, font, color map, sheets and PNG bytes. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "render.h"
#include "plot.h"

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#include <stb_image.h>

static const uint8_t black[4] = { 0, 0, 0, 255 };

/* ---- helpers ---- */

/* An axis-aligned box [lo, hi] with 4 vertices per face (so each face has its own flat
 * normal), counter-clockwise seen from outside; normals (if non-NULL) point out. */
typedef struct box_mesh {
    float positions[24 * 3], normals[24 * 3];
    uint32_t triangles[12 * 3];
} box_mesh;

static void make_box(box_mesh *b, const float lo[3], const float hi[3])
{
    static const int corners[6][4][3] = {
        { { 1, 0, 0 }, { 1, 1, 0 }, { 1, 1, 1 }, { 1, 0, 1 } }, { { 0, 0, 1 }, { 0, 1, 1 }, { 0, 1, 0 }, { 0, 0, 0 } },
        { { 0, 1, 1 }, { 1, 1, 1 }, { 1, 1, 0 }, { 0, 1, 0 } }, { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 0, 1 }, { 0, 0, 1 } },
        { { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } }, { { 0, 1, 0 }, { 1, 1, 0 }, { 1, 0, 0 }, { 0, 0, 0 } },
    };
    static const float face_normals[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
    for (int f = 0; f < 6; f++) {
        for (int k = 0; k < 4; k++)
            for (int i = 0; i < 3; i++) {
                b->positions[3 * (4 * f + k) + i] = corners[f][k][i] ? hi[i] : lo[i];
                b->normals[3 * (4 * f + k) + i] = face_normals[f][i];
            }
        uint32_t q[6] = { 4 * f, 4 * f + 1, 4 * f + 2, 4 * f, 4 * f + 2, 4 * f + 3 };
        memcpy(b->triangles + 6 * f, q, sizeof q);
    }
}

static mkr_mesh_view box_view(const box_mesh *b, int with_normals)
{
    mkr_mesh_view m = { .vertex_count = 24, .positions = b->positions, .normals = with_normals ? b->normals : NULL,
                        .triangle_count = 12, .triangles = b->triangles };
    return m;
}

static int covered(const mkr_image *img, int x, int y)
{
    return isfinite(img->depth[(size_t)y * (size_t)img->width + (size_t)x]);
}

static int count_covered(const mkr_image *img, int x, int y, int w, int h)
{
    int n = 0;
    for (int j = y; j < y + h; j++)
        for (int i = x; i < x + w; i++) n += covered(img, i, j);
    return n;
}

/* Bounding rectangle of the covered pixels: { x0, y0, x1, y1 } inclusive; x0 = -1 if none. */
static void covered_rect(const mkr_image *img, int rect[4])
{
    rect[0] = rect[1] = -1, rect[2] = rect[3] = -1;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            if (covered(img, x, y)) {
                if (rect[0] < 0 || x < rect[0]) rect[0] = x;
                if (rect[1] < 0 || y < rect[1]) rect[1] = y;
                if (x > rect[2]) rect[2] = x;
                if (y > rect[3]) rect[3] = y;
            }
}

static float luma(const mkr_image *img, int x, int y)
{
    const uint8_t *p = mkr_image_pixel(img, x, y);
    return p ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : -1;
}

/* A camera mapping world (x, y) to screen (w/2 + x, h/2 - y): pixel-exact placement. */
static mkr_camera screen_camera(int w, int h)
{
    mkr_camera cam = { 0 };
    mkr_camera_set_view(&cam, MKR_VIEW_FRONT);
    cam.pixels_per_unit = 1;
    cam.width = w, cam.height = h;
    return cam;
}

/* The 2 x 1 x 0.5 box used by the silhouette tests, framed in a 100x100 viewport with a 10%
 * margin: 40 pixels per unit whenever the long axis is on screen. */
static const float slab_lo[3] = { -1.0f, -0.5f, -0.25f }, slab_hi[3] = { 1.0f, 0.5f, 0.25f };

static void render_slab(mkr_image *img, mkr_view view, mkr_camera *cam_out)
{
    box_mesh b;
    make_box(&b, slab_lo, slab_hi);
    mkr_mesh_view m = box_view(&b, 0);
    mkr_camera cam = { 0 };
    mkr_camera_set_view(&cam, view);
    mkr_camera_frame(&cam, slab_lo, slab_hi, 0, 0, 100, 100, 0.1f);
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(img, 100, 100, &err), MK_OK);
    CHECK_EQ_INT(mkr_draw_mesh(img, &cam, &m, NULL, &err), MK_OK);
    if (cam_out) *cam_out = cam;
}

/* The silhouette is exactly the rectangle [x0, x1] x [y0, y1] (inclusive pixels). */
static void check_rectangle(const mkr_image *img, int x0, int y0, int x1, int y1)
{
    int rect[4];
    covered_rect(img, rect);
    CHECK_EQ_INT(rect[0], x0);
    CHECK_EQ_INT(rect[1], y0);
    CHECK_EQ_INT(rect[2], x1);
    CHECK_EQ_INT(rect[3], y1);
    CHECK_EQ_INT(count_covered(img, 0, 0, img->width, img->height), (x1 - x0 + 1) * (y1 - y0 + 1));
}

/* ---- views ---- */

/* Front: x (2 units) across, y (1 unit) up, at 40 px per unit around the center (50, 50). */
static void silhouette_front(void)
{
    mkr_image img;
    render_slab(&img, MKR_VIEW_FRONT, NULL);
    check_rectangle(&img, 10, 30, 89, 69);
    CHECK(covered(&img, 50, 50));
    CHECK(!covered(&img, 50, 29) && !covered(&img, 9, 50) && !covered(&img, 90, 50) && !covered(&img, 50, 70));
    mkr_image_destroy(&img);
}

/* Side: z (0.5) across, y (1) up: scale 80 px per unit. */
static void silhouette_side(void)
{
    mkr_image img;
    render_slab(&img, MKR_VIEW_SIDE, NULL);
    check_rectangle(&img, 30, 10, 69, 89);
    mkr_image_destroy(&img);
}

/* Top: x (2) across, z (0.5) up: 40 px per unit. */
static void silhouette_top(void)
{
    mkr_image img;
    render_slab(&img, MKR_VIEW_TOP, NULL);
    check_rectangle(&img, 10, 40, 89, 59);
    mkr_image_destroy(&img);
}

/* Iso: a hexagon. Each of the six outline corners has covered pixels 2 px inward and none
 * 2 px outward; the corners nearest and farthest from the eye project inside. */
static void silhouette_iso(void)
{
    mkr_image img;
    mkr_camera cam;
    render_slab(&img, MKR_VIEW_ISO, &cam);
    CHECK(covered(&img, 50, 50));
    CHECK(!covered(&img, 0, 0) && !covered(&img, 99, 0) && !covered(&img, 0, 99) && !covered(&img, 99, 99));
    for (int c = 0; c < 8; c++) {
        if (c == 0 || c == 7) continue;  /* (-,-,-) and (+,+,+): inside the outline */
        float p[3] = { (c & 1) ? slab_hi[0] : slab_lo[0], (c & 2) ? slab_hi[1] : slab_lo[1], (c & 4) ? slab_hi[2] : slab_lo[2] };
        float s[3];
        mkr_camera_project(&cam, p, s);
        float dx = s[0] - 50, dy = s[1] - 50, len = sqrtf(dx * dx + dy * dy);
        dx /= len, dy /= len;
        CHECK_MSG(covered(&img, (int)(s[0] - 2.5f * dx), (int)(s[1] - 2.5f * dy)), "corner %d: inside not covered", c);
        CHECK_MSG(!covered(&img, (int)(s[0] + 2.5f * dx), (int)(s[1] + 2.5f * dy)), "corner %d: outside covered", c);
    }
    /* Framing: the outline touches the margin (10 px) on the tighter axis. */
    int rect[4];
    covered_rect(&img, rect);
    CHECK(rect[1] <= 11 && rect[3] >= 88);
    mkr_image_destroy(&img);
}

/* The documented axes: a cube with a red marker box on +x, green on +y, blue on +z. */
static void view_axes(void)
{
    box_mesh parts[4];
    static const float lo[4][3] = { { -0.5f, -0.5f, -0.5f }, { 0.5f, -0.1f, -0.1f }, { -0.1f, 0.5f, -0.1f }, { -0.1f, -0.1f, 0.5f } };
    static const float hi[4][3] = { { 0.5f, 0.5f, 0.5f }, { 0.9f, 0.1f, 0.1f }, { 0.1f, 0.9f, 0.1f }, { 0.1f, 0.1f, 0.9f } };
    static const uint8_t colors[4][3] = { { 128, 128, 128 }, { 255, 0, 0 }, { 0, 255, 0 }, { 0, 0, 255 } };
    /* Where each marker's center must land, relative to the image center, per view:
     * 1 = right/up of center, -1 = left/down, 0 = on it (within 3 px). Columns x, y. */
    static const int expect[MKR_VIEW_COUNT][3][2] = {
        { { 1, 0 }, { 0, 1 }, { 0, 0 } },    /* front: +x right, +y up, +z toward the eye */
        { { 0, 0 }, { 0, 1 }, { -1, 0 } },   /* side: +z left */
        { { 1, 0 }, { 0, 0 }, { 0, -1 } },   /* top: +z down */
        { { 1, -1 }, { 0, 1 }, { -1, -1 } }, /* iso: +x lower right, +z lower left */
    };
    for (int v = 0; v < MKR_VIEW_COUNT; v++) {
        mkr_image img;
        mk_error err;
        CHECK_EQ_INT(mkr_image_create(&img, 120, 120, &err), MK_OK);
        mkr_camera cam = { 0 };
        mkr_camera_set_view(&cam, (mkr_view)v);
        float blo[3] = { -0.9f, -0.9f, -0.9f }, bhi[3] = { 0.9f, 0.9f, 0.9f };
        mkr_camera_frame(&cam, blo, bhi, 0, 0, 120, 120, 0.05f);
        for (int p = 0; p < 4; p++) {
            make_box(&parts[p], lo[p], hi[p]);
            uint8_t rgb[24 * 3];
            for (int k = 0; k < 24; k++) memcpy(rgb + 3 * k, colors[p], 3);
            mkr_mesh_view m = box_view(&parts[p], 0);
            m.colors = rgb;
            mkr_style unlit = mkr_style_default();
            unlit.unlit = 1;
            CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, &unlit, &err), MK_OK);
        }
        for (int axis = 0; axis < 3; axis++) {
            /* Centroid of the pixels of that marker's pure color. */
            double sx = 0, sy = 0;
            int n = 0;
            for (int y = 0; y < 120; y++)
                for (int x = 0; x < 120; x++) {
                    const uint8_t *px = mkr_image_pixel(&img, x, y);
                    if (px[axis] == 255 && px[(axis + 1) % 3] == 0 && px[(axis + 2) % 3] == 0) sx += x + 0.5, sy += y + 0.5, n++;
                }
            CHECK_MSG(n > 0, "%s: marker %d not visible", mkr_view_name((mkr_view)v), axis);
            if (!n) continue;
            double dx = sx / n - 60, dy = 60 - sy / n;
            int gx = dx > 3 ? 1 : dx < -3 ? -1 : 0, gy = dy > 3 ? 1 : dy < -3 ? -1 : 0;
            CHECK_MSG(gx == expect[v][axis][0] && gy == expect[v][axis][1], "%s: marker %d at (%+.1f, %+.1f)",
                      mkr_view_name((mkr_view)v), axis, dx, dy);
        }
        mkr_image_destroy(&img);
    }
    const char *names[] = { "front", "side", "top", "iso" };
    for (int v = 0; v < MKR_VIEW_COUNT; v++) {
        mkr_view parsed = MKR_VIEW_COUNT;
        CHECK(mkr_view_parse(names[v], &parsed) && parsed == (mkr_view)v);
        CHECK(strcmp(mkr_view_name((mkr_view)v), names[v]) == 0);
    }
    mkr_view unused;
    CHECK(!mkr_view_parse("back", &unused));
}

/* ---- light ---- */

/* In the iso view the top faces the light most, the front (+z) less, the +x side away. */
static void shading_iso_faces(void)
{
    mkr_image img;
    mkr_camera cam;
    render_slab(&img, MKR_VIEW_ISO, &cam);
    const float centers[3][3] = { { 0, 0.5f, 0 }, { 0, 0, 0.25f }, { 1.0f, 0, 0 } }; /* top, front, +x */
    float l[3];
    for (int f = 0; f < 3; f++) {
        float s[3];
        mkr_camera_project(&cam, centers[f], s);
        l[f] = luma(&img, (int)s[0], (int)s[1]);
    }
    CHECK_MSG(l[0] > l[1] && l[1] > l[2], "top %.0f, front %.0f, +x side %.0f", l[0], l[1], l[2]);
    mkr_image_destroy(&img);
}

/* A face whose normal points at the light gets ambient + key (full base color); one whose
 * normal points away gets ambient + fill: darker but not black. */
static void shading_toward_and_away(void)
{
    mkr_camera cam = screen_camera(40, 20);
    float light[3];
    mkr_light_direction(&cam, light);
    CHECK_NEAR(light[0] * light[0] + light[1] * light[1] + light[2] * light[2], 1, 1e-5);
    CHECK(light[0] < 0 && light[1] > 0 && light[2] > 0);  /* upper left, in front */
    /* Two squares at z = 0: left one with normals at the light, right one away. */
    float pos[8 * 3] = { -18, -8, 0, -2, -8, 0, -2, 8, 0, -18, 8, 0, 2, -8, 0, 18, -8, 0, 18, 8, 0, 2, 8, 0 };
    float nrm[8 * 3];
    for (int v = 0; v < 8; v++)
        for (int i = 0; i < 3; i++) nrm[3 * v + i] = v < 4 ? light[i] : -light[i];
    uint32_t tri[4 * 3] = { 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7 };
    mkr_mesh_view m = { .vertex_count = 8, .positions = pos, .normals = nrm, .triangle_count = 4, .triangles = tri };
    mkr_style style = { .color = { 200, 200, 200 } };
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, 40, 20, &err), MK_OK);
    CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, &style, &err), MK_OK);
    const uint8_t *toward = mkr_image_pixel(&img, 10, 10), *away = mkr_image_pixel(&img, 30, 10);
    CHECK_NEAR(toward[0], 200 * (MKR_LIGHT_AMBIENT + MKR_LIGHT_KEY), 1);
    CHECK_NEAR(away[0], 200 * (MKR_LIGHT_AMBIENT + MKR_LIGHT_FILL), 1);
    CHECK(toward[0] > away[0] + 50 && away[0] > 60);
    mkr_image_destroy(&img);
}

/* Inverted vertex normals, or a reversed winding without normals, change the shade of known
 * pixels: the front face of the slab goes from lit to fill. */
static void shading_flipped_normals(void)
{
    box_mesh b;
    make_box(&b, slab_lo, slab_hi);
    float light[3];
    mkr_camera cam = { 0 };
    mkr_camera_set_view(&cam, MKR_VIEW_FRONT);
    mkr_camera_frame(&cam, slab_lo, slab_hi, 0, 0, 100, 100, 0.1f);
    mkr_light_direction(&cam, light);
    float lit = mkr_light_intensity(light[2]), flipped = mkr_light_intensity(-light[2]); /* front normal is +z */
    uint8_t base = mkr_style_default().color[0];
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, 100, 100, &err), MK_OK);

    for (int variant = 0; variant < 4; variant++) {
        box_mesh c = b;
        int with_normals = variant < 2, flip = variant & 1;
        if (flip && with_normals)
            for (int i = 0; i < 24 * 3; i++) c.normals[i] = -c.normals[i];
        if (flip && !with_normals)
            for (int t = 0; t < 12; t++) {
                uint32_t tmp = c.triangles[3 * t + 1];
                c.triangles[3 * t + 1] = c.triangles[3 * t + 2], c.triangles[3 * t + 2] = tmp;
            }
        mkr_image_clear(&img, black);
        mkr_mesh_view m = box_view(&c, with_normals);
        CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, NULL, &err), MK_OK);
        static const int probes[3][2] = { { 50, 50 }, { 15, 35 }, { 85, 65 } };
        for (int p = 0; p < 3; p++) {
            const uint8_t *px = mkr_image_pixel(&img, probes[p][0], probes[p][1]);
            CHECK_MSG(fabsf(px[0] - base * (flip ? flipped : lit)) <= 1, "variant %d probe %d: %d, expected %.1f",
                      variant, p, px[0], base * (flip ? flipped : lit));
        }
    }
    CHECK(base * (lit - flipped) > 40);
    mkr_image_destroy(&img);
}

/* Normals are interpolated and normalized per pixel (not the vertices' shades averaged):
 * two vertex normals tilted 75 degrees from the light either way, one at it; at the
 * centroid the normalized mean normal lies close to the light. */
static void shading_per_pixel_normals(void)
{
    mkr_camera cam = screen_camera(64, 64);
    float L[3];
    mkr_light_direction(&cam, L);
    /* A unit vector perpendicular to L. */
    float u[3] = { L[1], -L[0], 0 }, ul = sqrtf(u[0] * u[0] + u[1] * u[1]);
    for (int i = 0; i < 3; i++) u[i] /= ul;
    const float a = 75.0f * 3.14159265f / 180;
    float nrm[9];
    for (int i = 0; i < 3; i++) {
        nrm[i] = L[i];
        nrm[3 + i] = cosf(a) * L[i] + sinf(a) * u[i];
        nrm[6 + i] = cosf(a) * L[i] - sinf(a) * u[i];
    }
    float pos[9] = { -30, -30, 0, 30, -30, 0, 0, 30, 0 };
    uint32_t tri[3] = { 0, 1, 2 };
    mkr_mesh_view m = { .vertex_count = 3, .positions = pos, .normals = nrm, .triangle_count = 1, .triangles = tri };
    mkr_style style = { .color = { 250, 250, 250 } };
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, 64, 64, &err), MK_OK);
    CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, &style, &err), MK_OK);
    /* Centroid (0, -10) is pixel (32, 42); the mean normal there is L (1 + 2 cos a) / 3. */
    float phong = mkr_light_intensity(1.0f);
    float gouraud = (mkr_light_intensity(1.0f) + 2 * mkr_light_intensity(cosf(a))) / 3;
    const uint8_t *px = mkr_image_pixel(&img, 31, 41);
    CHECK_MSG(fabsf(px[0] - 250 * phong) <= 3, "centroid %d, per-pixel normal %.0f, averaged shades %.0f", px[0],
              250 * phong, 250 * gouraud);
    /* Near a tilted vertex the shade is darker than at the centroid. */
    CHECK(mkr_image_pixel(&img, 60, 62)[0] + 20 < px[0]);
    mkr_image_destroy(&img);
}

/* ---- depth and coverage ---- */

/* A near triangle hides a far one in either drawing order; the far one shows elsewhere. */
static void depth_order(void)
{
    mkr_camera cam = screen_camera(40, 40);
    /* Far (z = -5) red triangle covering x + y <= 0, near (z = +5, toward the eye) blue one
     * covering y <= x, both within [-18, 18]^2. */
    float far_pos[9] = { -18, -18, -5, 18, -18, -5, -18, 18, -5 };
    float near_pos[9] = { -10, -10, 5, 18, -10, 5, 18, 18, 5 };
    uint32_t tri[3] = { 0, 1, 2 };
    mkr_mesh_view far_mesh = { .vertex_count = 3, .positions = far_pos, .triangle_count = 1, .triangles = tri };
    mkr_mesh_view near_mesh = far_mesh;
    near_mesh.positions = near_pos;
    mkr_style red = { .color = { 255, 0, 0 }, .unlit = 1 }, blue = { .color = { 0, 0, 255 }, .unlit = 1 };
    for (int order = 0; order < 2; order++) {
        mkr_image img;
        mk_error err;
        CHECK_EQ_INT(mkr_image_create(&img, 40, 40, &err), MK_OK);
        if (order == 0) {
            CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &far_mesh, &red, &err), MK_OK);
            CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &near_mesh, &blue, &err), MK_OK);
        } else {
            CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &near_mesh, &blue, &err), MK_OK);
            CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &far_mesh, &red, &err), MK_OK);
        }
        /* World (-2, -6), screen (18, 26), is in both; world (-15, 5), screen (5, 15), only
         * in the far one. */
        const uint8_t *both = mkr_image_pixel(&img, 18, 26), *far_only = mkr_image_pixel(&img, 5, 15);
        CHECK_MSG(both[2] == 255 && both[0] == 0, "order %d: overlap shows %d,%d,%d", order, both[0], both[1], both[2]);
        CHECK_MSG(far_only[0] == 255 && far_only[2] == 0, "order %d: far-only pixel %d,%d,%d", order, far_only[0],
                  far_only[1], far_only[2]);
        /* Depth runs along the view direction (-z in the front view): the near triangle's is -5. */
        CHECK_NEAR(img.depth[26 * 40 + 18], -5, 1e-4);
        CHECK_NEAR(img.depth[15 * 40 + 5], 5, 1e-4);
        mkr_image_destroy(&img);
    }
}

/* Draws each triangle alone and counts, per pixel, how many drew it. */
static void coverage_counts(const float *pos, uint32_t vertex_count, const uint32_t *tri, uint32_t triangle_count,
                            int w, int h, int *counts)
{
    mkr_camera cam = screen_camera(w, h);
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, w, h, &err), MK_OK);
    memset(counts, 0, (size_t)w * (size_t)h * sizeof *counts);
    for (uint32_t t = 0; t < triangle_count; t++) {
        mkr_image_clear(&img, black);
        mkr_mesh_view m = { .vertex_count = vertex_count, .positions = pos, .triangle_count = 1, .triangles = tri + 3 * t };
        CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, NULL, &err), MK_OK);
        for (int i = 0; i < w * h; i++) counts[i] += isfinite(img.depth[i]);
    }
    mkr_image_destroy(&img);
}

/* Is screen point (x, y) strictly inside the convex polygon (screen coordinates, any
 * winding)? Sets *on_edge when it is within 1e-9 of an edge line segment. */
static int inside_convex(const double *px, const double *py, int n, double x, double y, int *on_edge)
{
    int pos = 0, neg = 0;
    *on_edge = 0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double c = (px[j] - px[i]) * (y - py[i]) - (py[j] - py[i]) * (x - px[i]);
        if (fabs(c) < 1e-9) *on_edge = 1;
        pos += c > 0, neg += c < 0;
    }
    return pos == 0 || neg == 0;
}

/* Triangles sharing edges (a fan around a pixel center, spokes through pixel centers, both
 * windings; then random quads cut along a diagonal) draw every pixel inside exactly once. */
static void fill_rule(void)
{
    enum { W = 64, H = 64, SPOKES = 16 };
    static int counts[W * H];
    /* Fan: center at pixel center (32.5, 32.5); rim points at radius 27.3 on directions that
     * include the axes and diagonals (those spokes pass through many pixel centers). */
    float pos[(SPOKES + 1) * 3];
    double rim_x[SPOKES], rim_y[SPOKES];
    uint32_t tri[SPOKES * 3];
    for (int k = 0; k <= SPOKES; k++) {
        double sx = 32.5, sy = 32.5;
        if (k > 0) {
            double a = 2 * 3.14159265358979 * (k - 1) / SPOKES;
            /* Axis and diagonal spokes hit pixel centers exactly: radius in whole pixels there. */
            double r = (k - 1) % 2 == 0 ? 27.0 : 27.3;
            sx = 32.5 + round(r * cos(a) * 16) / 16, sy = 32.5 + round(r * sin(a) * 16) / 16;
            rim_x[k - 1] = sx, rim_y[k - 1] = sy;
        }
        pos[3 * k] = (float)(sx - W / 2), pos[3 * k + 1] = (float)(H / 2 - sy), pos[3 * k + 2] = 0;
    }
    for (int k = 0; k < SPOKES; k++) {
        uint32_t a = 1 + (uint32_t)k, b = 1 + (uint32_t)((k + 1) % SPOKES);
        tri[3 * k] = 0;
        tri[3 * k + 1] = k % 2 ? a : b;  /* alternate windings */
        tri[3 * k + 2] = k % 2 ? b : a;
    }
    coverage_counts(pos, SPOKES + 1, tri, SPOKES, W, H, counts);
    int twice = 0, gaps = 0, outside = 0, inside_total = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int on_edge, in = inside_convex(rim_x, rim_y, SPOKES, x + 0.5, y + 0.5, &on_edge);
            int c = counts[y * W + x];
            twice += c > 1;
            if (on_edge) continue;  /* the outline's own edges may go either way */
            inside_total += in;
            gaps += in && c == 0;
            outside += !in && c > 0;
        }
    CHECK_EQ_INT(twice, 0);
    CHECK_EQ_INT(gaps, 0);
    CHECK_EQ_INT(outside, 0);
    CHECK(inside_total > 2000);

    /* Random quads cut along one diagonal, vertices on the 1/16 grid. */
    uint32_t seed = 12345;
    int tested = 0;
    for (int q = 0; q < 200; q++) {
        double qx[4], qy[4];
        float qp[12];
        /* A convex quad: 4 points on an ellipse at increasing angles. */
        double cx = 20 + (seed = seed * 1664525u + 1013904223u) % 24, cy = 20 + (seed = seed * 1664525u + 1013904223u) % 24;
        double angle = (seed = seed * 1664525u + 1013904223u) % 1000 / 1000.0;
        for (int k = 0; k < 4; k++) {
            angle += 0.6 + (seed = seed * 1664525u + 1013904223u) % 1000 / 1000.0 * 0.9;
            double r = 4 + (seed = seed * 1664525u + 1013904223u) % 1400 / 100.0;
            qx[k] = round((cx + r * cos(angle)) * 16) / 16, qy[k] = round((cy + r * sin(angle)) * 16) / 16;
            qp[3 * k] = (float)(qx[k] - W / 2), qp[3 * k + 1] = (float)(H / 2 - qy[k]), qp[3 * k + 2] = 0;
        }
        int convex = 1, pos_turns = 0;
        for (int k = 0; k < 4; k++) {
            int j = (k + 1) % 4, l = (k + 2) % 4;
            double c = (qx[j] - qx[k]) * (qy[l] - qy[j]) - (qy[j] - qy[k]) * (qx[l] - qx[j]);
            if (c == 0) convex = 0;
            pos_turns += c > 0;
        }
        if (!convex || (pos_turns != 0 && pos_turns != 4)) continue;  /* only strictly convex quads */
        tested++;
        uint32_t qt[6] = { 0, 1, 2, 0, 2, 3 };
        coverage_counts(qp, 4, qt, 2, W, H, counts);
        int bad_twice = 0, bad_gap = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int on_edge, in = inside_convex(qx, qy, 4, x + 0.5, y + 0.5, &on_edge);
                bad_twice += counts[y * W + x] > 1;
                if (!on_edge) bad_gap += in && counts[y * W + x] == 0;
            }
        CHECK_MSG(bad_twice == 0 && bad_gap == 0, "quad %d: %d pixels drawn twice, %d gaps", q, bad_twice, bad_gap);
    }
    CHECK_MSG(tested >= 100, "only %d convex quads", tested);

    /* Top-left, not merely consistent: a square whose edges run through pixel centers, from
     * (10.5, 10.5) to (20.5, 20.5), owns its top row and left column, not its bottom row and
     * right column. */
    float sq[12] = { 10.5f - W / 2, H / 2 - 10.5f, 0, 20.5f - W / 2, H / 2 - 10.5f, 0,
                     20.5f - W / 2, H / 2 - 20.5f, 0, 10.5f - W / 2, H / 2 - 20.5f, 0 };
    uint32_t sq_tri[6] = { 0, 1, 2, 0, 2, 3 };
    coverage_counts(sq, 4, sq_tri, 2, W, H, counts);
    int total = 0, outside_square = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            total += counts[y * W + x];
            outside_square += counts[y * W + x] && !(x >= 10 && x <= 19 && y >= 10 && y <= 19);
        }
    CHECK_EQ_INT(total, 100);
    CHECK_EQ_INT(outside_square, 0);
}

/* ---- text and color ---- */

static void font_glyph(void)
{
    static const uint8_t A[MKR_FONT_HEIGHT] = { 0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11, 0, 0 };
    static const uint8_t g[MKR_FONT_HEIGHT] = { 0, 0, 0x0F, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E };
    CHECK(memcmp(mkr_font_glyph('A'), A, sizeof A) == 0);
    CHECK(memcmp(mkr_font_glyph('g'), g, sizeof g) == 0);
    CHECK(mkr_font_glyph(200) == mkr_font_glyph('?') && mkr_font_glyph(7) == mkr_font_glyph('?'));
    /* Every printable glyph but the space has ink; no two share a bitmap. */
    for (int c = 33; c < 127; c++) {
        int ink = 0;
        for (int r = 0; r < MKR_FONT_HEIGHT; r++) ink |= mkr_font_glyph(c)[r];
        CHECK_MSG(ink, "glyph '%c' is empty", c);
        for (int d = 32; d < c; d++)
            CHECK_MSG(memcmp(mkr_font_glyph(c), mkr_font_glyph(d), MKR_FONT_HEIGHT) != 0, "'%c' looks like '%c'", c, d);
    }

    /* Drawn at scale 2: each font pixel is a 2x2 block after the padding; the box is filled. */
    int w, h;
    mkr_text_box("A", 2, &w, &h);
    CHECK_EQ_INT(w, (5 + 2 * MKR_FONT_PADDING) * 2);
    CHECK_EQ_INT(h, (9 + 2 * MKR_FONT_PADDING) * 2);
    mkr_text_box("ab\nlonger\n", 1, &w, &h);
    CHECK_EQ_INT(w, 6 * 6 - 1 + 2 * MKR_FONT_PADDING);
    CHECK_EQ_INT(h, 3 * 10 - 1 + 2 * MKR_FONT_PADDING);
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, 40, 40, &err), MK_OK);
    static const uint8_t fg[4] = { 255, 255, 255, 255 }, bg[4] = { 0, 0, 255, 255 };
    mkr_draw_text(&img, 3, 4, "A", 2, fg, bg);
    int wrong = 0;
    for (int y = 0; y < 40; y++)
        for (int x = 0; x < 40; x++) {
            const uint8_t *p = mkr_image_pixel(&img, x, y);
            int in_box = x >= 3 && x < 3 + 18 && y >= 4 && y < 4 + 26;
            int fx = (x - 3 - 2 * MKR_FONT_PADDING) >> 1, fy = (y - 4 - 2 * MKR_FONT_PADDING) >> 1;
            int ink = in_box && fx >= 0 && fx < 5 && fy >= 0 && fy < 9 && (A[fy] & (0x10 >> fx));
            int expect_r = ink ? 255 : 0, expect_b = ink || in_box ? 255 : 0;
            wrong += p[0] != expect_r || p[2] != expect_b;
        }
    CHECK_EQ_INT(wrong, 0);
    mkr_image_destroy(&img);
}

static double srgb_to_linear(double u) { return u <= 0.04045 ? u / 12.92 : pow((u + 0.055) / 1.055, 2.4); }

/* CIE L* of an 8-bit sRGB color. */
static double lightness(const uint8_t rgb[3])
{
    double y = 0.2126 * srgb_to_linear(rgb[0] / 255.0) + 0.7152 * srgb_to_linear(rgb[1] / 255.0) +
               0.0722 * srgb_to_linear(rgb[2] / 255.0);
    return y > 216.0 / 24389 ? 116 * cbrt(y) - 16 : y * 24389.0 / 27;
}

static void colormap_lightness(void)
{
    uint8_t table[3 * MKR_COLORMAP_SIZE];
    mkr_colormap_table(table);
    double prev = -1;
    int not_rising = 0;
    for (int i = 0; i < MKR_COLORMAP_SIZE; i++) {
        double l = lightness(table + 3 * i);
        not_rising += !(l > prev);
        prev = l;
        uint8_t direct[3];
        mkr_colormap((float)i / 255, direct);
        CHECK(memcmp(direct, table + 3 * i, 3) == 0);
    }
    CHECK_EQ_INT(not_rising, 0);
    CHECK(lightness(table) < 20 && lightness(table + 3 * 255) > 85);
    /* Cold is bluish, hot is yellowish; out of range clamps; NaN is hot. */
    CHECK(table[2] > table[0] && table[3 * 255] > table[3 * 255 + 2]);
    uint8_t c[3];
    mkr_colormap(-1, c);
    CHECK(memcmp(c, table, 3) == 0);
    mkr_colormap(7, c);
    CHECK(memcmp(c, table + 3 * 255, 3) == 0);
    mkr_colormap(NAN, c);
    CHECK(memcmp(c, table + 3 * 255, 3) == 0);
}

/* ---- sheets ---- */

/* A flat 9x9 grid in the z = 0 plane, facing +z, spanning [-1, 1]^2. */
typedef struct grid_mesh {
    float positions[81 * 3];
    uint32_t triangles[128 * 3];
} grid_mesh;

static void make_grid(grid_mesh *g, float dx)
{
    for (int j = 0; j < 9; j++)
        for (int i = 0; i < 9; i++) {
            float *p = g->positions + 3 * (9 * j + i);
            p[0] = -1 + 0.25f * (float)i + dx, p[1] = -1 + 0.25f * (float)j, p[2] = 0;
        }
    int t = 0;
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++) {
            uint32_t a = (uint32_t)(9 * j + i), q[6] = { a, a + 1, a + 10, a, a + 10, a + 9 };
            memcpy(g->triangles + 6 * t++, q, sizeof q);
        }
}

static int hot_pixel(const uint8_t *p) { return p[0] > 150 && p[1] > 140 && p[2] < 120; }

/* One vertex of frame 2 moved: in the diff sheet cell 2 has hot (yellow) pixels, the others
 * none. */
static void diff_sheet_hot_cell(void)
{
    grid_mesh g;
    make_grid(&g, 0);
    float zero[81] = { 0 }, moved[81] = { 0 };
    moved[40] = 0.3f;  /* the center vertex moved by 0.3 */
    mkr_mesh_view views[4];
    mkr_cell cells[4];
    for (int i = 0; i < 4; i++) {
        views[i] = (mkr_mesh_view){ .vertex_count = 81, .positions = g.positions, .triangle_count = 128,
                                    .triangles = g.triangles, .scalars = i == 2 ? moved : zero };
        cells[i] = (mkr_cell){ .meshes = &views[i], .mesh_count = 1, .time = 0.25 * i };
    }
    mkr_sheet_desc desc = { .cells = cells, .cell_count = 4, .cell_width = 160, .cell_height = 160,
                            .view = MKR_VIEW_FRONT, .title = "diff" };
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_diff_sheet_render(&desc, &img, &err), MK_OK);
    mkr_sheet_layout layout;
    CHECK(mkr_sheet_layout_get(&desc, 1, &layout));
    CHECK_EQ_INT(img.width, layout.width);
    CHECK_EQ_INT(img.height, layout.height);
    CHECK_EQ_INT(layout.columns, 2);
    CHECK(layout.legend_height > 0 && layout.title_height > 0 && layout.label_height > 0);
    for (uint32_t i = 0; i < 4; i++) {
        int rect[4], hot = 0, cold_mesh = 0;
        mkr_sheet_cell_rect(&layout, i, rect);
        for (int y = rect[1]; y < rect[1] + rect[3]; y++)
            for (int x = rect[0]; x < rect[0] + rect[2]; x++) {
                const uint8_t *p = mkr_image_pixel(&img, x, y);
                hot += hot_pixel(p);
                cold_mesh += p[2] > p[0] && p[2] > p[1] && p[0] < 80;  /* dark violet: the cold end */
            }
        if (i == 2) CHECK_MSG(hot > 20, "cell 2 has %d hot pixels", hot);
        else CHECK_MSG(hot == 0, "cell %u has %d hot pixels", i, hot);
        CHECK_MSG(cold_mesh > 1000, "cell %u: mesh not drawn in the cold color (%d)", i, cold_mesh);
    }
    /* The hot spot sits at the moved vertex: the center of cell 2's drawing area. */
    int rect[4];
    mkr_sheet_cell_rect(&layout, 2, rect);
    int cx = rect[0] + rect[2] / 2, cy = rect[1] + layout.label_height + (rect[3] - layout.label_height) / 2;
    CHECK(hot_pixel(mkr_image_pixel(&img, cx, cy)));
    mkr_image_destroy(&img);

    /* diff_max fixes the scale: at 100x the moved distance nothing is hot. */
    desc.diff_max = 30;
    CHECK_EQ_INT(mkr_diff_sheet_render(&desc, &img, &err), MK_OK);
    int hot = 0;
    for (int y = 0; y < layout.height - layout.legend_height; y++)
        for (int x = 0; x < img.width; x++) hot += hot_pixel(mkr_image_pixel(&img, x, y));
    CHECK_EQ_INT(hot, 0);
    mkr_image_destroy(&img);
}

/* One camera for all cells: a grid moving right from cell to cell lands further right. */
static void sheet_fixed_camera(void)
{
    grid_mesh g[3];
    mkr_mesh_view views[3];
    mkr_cell cells[3];
    for (int i = 0; i < 3; i++) {
        make_grid(&g[i], 2.0f * (float)i);
        views[i] = (mkr_mesh_view){ .vertex_count = 81, .positions = g[i].positions, .triangle_count = 128,
                                    .triangles = g[i].triangles };
        cells[i] = (mkr_cell){ .meshes = &views[i], .mesh_count = 1, .time = NAN };
    }
    mkr_sheet_desc desc = { .cells = cells, .cell_count = 3, .columns = 3, .cell_width = 120, .cell_height = 60,
                            .view = MKR_VIEW_FRONT };
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_sheet_render(&desc, &img, &err), MK_OK);
    mkr_sheet_layout layout;
    CHECK(mkr_sheet_layout_get(&desc, 0, &layout));
    CHECK_EQ_INT(layout.label_height, 0);  /* no time, no text: no label band */
    CHECK_EQ_INT(layout.rows, 1);
    uint8_t background[4];
    int rect[4];
    mkr_sheet_cell_rect(&layout, 0, rect);
    memcpy(background, mkr_image_pixel(&img, rect[0] + 1, rect[1] + 1), 4);
    for (int i = 0; i < 3; i++) {
        mkr_sheet_cell_rect(&layout, (uint32_t)i, rect);
        /* Each frame covers one third of the union's width: columns [i/3, (i+1)/3) of the
         * framed area (margins aside). */
        int third = rect[2] / 3;
        for (int k = 0; k < 3; k++) {
            int x = rect[0] + k * third + third / 2, y = rect[1] + rect[3] / 2;
            int drawn = memcmp(mkr_image_pixel(&img, x, y), background, 3) != 0;
            CHECK_MSG(drawn == (k == i), "cell %d, third %d: drawn %d", i, k, drawn);
        }
    }
    mkr_image_destroy(&img);
}

static void labels(void)
{
    /* Labels: time, then the text lines; times 0.100 and 0.104 need 3 decimals to differ. */
    grid_mesh g;
    make_grid(&g, 0);
    mkr_mesh_view v = { .vertex_count = 81, .positions = g.positions, .triangle_count = 128, .triangles = g.triangles };
    mkr_cell cells[2] = { { .meshes = &v, .mesh_count = 1, .time = 0.1, .text = "smile 0.50\nblink 1.00" },
                          { .meshes = &v, .mesh_count = 1, .time = 0.104 } };
    mkr_sheet_desc desc = { .cells = cells, .cell_count = 2, .cell_width = 200, .cell_height = 120 };
    mkr_sheet_layout layout;
    CHECK(mkr_sheet_layout_get(&desc, 0, &layout));
    int three_lines;
    mkr_text_box("t\ns\nb", layout.text_scale, NULL, &three_lines);
    CHECK_EQ_INT(layout.label_height, three_lines + 4);
    CHECK(mkr_sheet_layout_get(&desc, 1, &layout));  /* diff adds the max line */
    int four_lines;
    mkr_text_box("t\nm\ns\nb", layout.text_scale, NULL, &four_lines);
    CHECK_EQ_INT(layout.label_height, four_lines + 4);
    /* The label's text pixels: "t=0.100 s" is 9 characters wide (3 decimals), so its
     * background box is that wide in cell 1. */
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_sheet_render(&desc, &img, &err), MK_OK);
    CHECK(mkr_sheet_layout_get(&desc, 0, &layout));
    int rect[4], box_w;
    mkr_sheet_cell_rect(&layout, 1, rect);
    mkr_text_box("t=0.104 s", layout.text_scale, &box_w, NULL);
    const uint8_t *inside = mkr_image_pixel(&img, rect[0] + 2 + box_w - 1, rect[1] + 3);
    const uint8_t *beyond = mkr_image_pixel(&img, rect[0] + 2 + box_w + 1, rect[1] + 3);
    CHECK(memcmp(inside, beyond, 3) != 0);
    mkr_image_destroy(&img);
}

/* ---- PNG ---- */

static void png_decodes(void)
{
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, 37, 23, &err), MK_OK);
    for (int y = 0; y < 23; y++)
        for (int x = 0; x < 37; x++) {
            uint8_t *p = mkr_image_pixel(&img, x, y);
            p[0] = (uint8_t)(x * 7), p[1] = (uint8_t)(y * 11), p[2] = (uint8_t)(x * y), p[3] = 255;
        }
    for (int alpha = 0; alpha < 2; alpha++) {
        if (alpha) mkr_image_pixel(&img, 5, 6)[3] = 10;
        mkr_png png;
        CHECK_EQ_INT(mkr_png_encode(&img, &png, &err), MK_OK);
        CHECK(png.size > 8 && memcmp(png.data, "\x89PNG\r\n\x1a\n", 8) == 0);
        int w = 0, h = 0, channels = 0;
        unsigned char *decoded = stbi_load_from_memory(png.data, (int)png.size, &w, &h, &channels, 4);
        CHECK(decoded != NULL);
        CHECK_EQ_INT(w, 37);
        CHECK_EQ_INT(h, 23);
        CHECK_EQ_INT(channels, alpha ? 4 : 3);  /* opaque pictures are written as RGB */
        if (decoded) CHECK(memcmp(decoded, img.pixels, 37 * 23 * 4) == 0);
        stbi_image_free(decoded);
        mkr_png_free(&png);
        CHECK(png.data == NULL && png.size == 0);
    }
    mkr_image_destroy(&img);
    mkr_png png;
    CHECK_EQ_INT(mkr_png_encode(&img, &png, &err), MK_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "png") != NULL);
}

/* ---- errors ---- */

/* A line chart: a straight series lands on the pixels its values give, clipped at y_max, with
 * its mark as a 5x5 dot; a second series gets the palette's second color. */
static void lines_chart(void)
{
    mkr_image img;
    mk_error err;
    CHECK(mkr_image_create(&img, 400, 200, &err) == MK_OK);
    double rising[11], flat[6];
    for (int k = 0; k <= 10; k++) rising[k] = k / 8.0;          /* passes y_max = 1 at k = 8 */
    for (int k = 0; k < 6; k++) flat[k] = 0.3;
    const uint32_t mark = 4;
    mkr_series series[2] = { { rising, 11, "rising", &mark, 1 }, { flat, 6, "flat", NULL, 0 } };
    mkr_lines lines = { .title = "t", .x_label = "x", .y_label = "y", .y_max = 1, .series = series, .series_count = 2 };
    mkr_lines_draw(&img, 0, 0, 400, 200, &lines);
    const int left = 64, right = 390, top = 22, bottom = 168;   /* the plot area of a 400x200 chart */
    const uint8_t *c0 = mkr_series_color(0), *c1 = mkr_series_color(1);
    int hits = 0, clipped = 0;
    for (int k = 0; k <= 10; k++) {
        int px = left + (int)lround((right - left) * k / 10.0);
        double v = rising[k] < 1 ? rising[k] : 1;
        int py = bottom - (int)lround((bottom - top) * v);
        const uint8_t *p = mkr_image_pixel(&img, px, py);
        hits += p && !memcmp(p, c0, 3);
        clipped += k >= 8 && py == top;
    }
    CHECK_MSG(hits == 11, "%d of 11 points of the rising series on their pixels", hits);
    CHECK(clipped == 3);
    int mx = left + (int)lround((right - left) * 0.4), my = bottom - (int)lround((bottom - top) * 0.5), dot = 0;
    for (int dy = -2; dy <= 2; dy++)
        for (int dx = -2; dx <= 2; dx++) dot += !memcmp(mkr_image_pixel(&img, mx + dx, my + dy), c0, 3);
    CHECK_MSG(dot == 25, "mark dot %d of 25 pixels", dot);
    int flat_y = bottom - (int)lround((bottom - top) * 0.3), flat_end = 0;
    for (int x = left; x <= right; x++)
        if (!memcmp(mkr_image_pixel(&img, x, flat_y), c1, 3)) flat_end = x;
    CHECK_MSG(abs(flat_end - (left + (int)lround((right - left) * 0.5))) <= 1, "flat series ends at %d", flat_end);
    mkr_image_destroy(&img);
}

static void errors(void)
{
    mkr_image img;
    mk_error err;
    CHECK_EQ_INT(mkr_image_create(&img, 0, 10, &err), MK_ERROR_INVALID_ARGUMENT);
    CHECK(img.pixels == NULL);
    CHECK_EQ_INT(mkr_image_create(&img, MKR_IMAGE_MAX_SIDE + 1, 10, &err), MK_ERROR_LIMIT);
    CHECK_EQ_INT(mkr_image_create(&img, 16, 16, &err), MK_OK);

    float pos[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    uint32_t bad[3] = { 0, 1, 3 };
    mkr_mesh_view m = { .vertex_count = 3, .positions = pos, .triangle_count = 1, .triangles = bad };
    mkr_camera cam = screen_camera(16, 16);
    CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, NULL, &err), MK_ERROR_OUT_OF_RANGE);
    CHECK_MSG(strstr(err.message, "triangle 0 uses vertex 3 of 3") != NULL, "message: %s", err.message);
    mkr_camera empty = { 0 };
    uint32_t good[3] = { 0, 1, 2 };
    m.triangles = good;
    CHECK_EQ_INT(mkr_draw_mesh(&img, &empty, &m, NULL, &err), MK_ERROR_INVALID_ARGUMENT);
    m.positions = NULL;
    CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, NULL, &err), MK_ERROR_INVALID_ARGUMENT);
    /* Non-finite and far-away vertices are skipped, not drawn as garbage. */
    float wild[9] = { NAN, 0, 0, 1e30f, 0, 0, 0, 1, 0 };
    m.positions = wild;
    CHECK_EQ_INT(mkr_draw_mesh(&img, &cam, &m, NULL, &err), MK_OK);
    CHECK_EQ_INT(count_covered(&img, 0, 0, 16, 16), 0);
    mkr_image_destroy(&img);

    mkr_sheet_desc desc = { 0 };
    CHECK_EQ_INT(mkr_sheet_render(&desc, &img, &err), MK_ERROR_INVALID_ARGUMENT);
    CHECK(img.pixels == NULL);
    m.positions = pos;
    mkr_cell cell = { .meshes = &m, .mesh_count = 1, .time = NAN };
    desc.cells = &cell;
    desc.cell_count = 1;
    CHECK_EQ_INT(mkr_diff_sheet_render(&desc, &img, &err), MK_ERROR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(err.message, "no scalars") != NULL, "message: %s", err.message);
    desc.cell_width = 20000;
    CHECK_EQ_INT(mkr_sheet_render(&desc, &img, &err), MK_ERROR_LIMIT);
    desc.cell_width = 64;
    desc.cell_height = 10;
    desc.title = "x";
    cell.text = "one\ntwo";
    CHECK_EQ_INT(mkr_sheet_render(&desc, &img, &err), MK_ERROR_INVALID_ARGUMENT);  /* no room under labels */
    CHECK(img.pixels == NULL);
}

CHECK_MAIN(CASE(silhouette_front), CASE(silhouette_side), CASE(silhouette_top), CASE(silhouette_iso), CASE(view_axes),
           CASE(shading_iso_faces), CASE(shading_toward_and_away), CASE(shading_flipped_normals),
           CASE(shading_per_pixel_normals), CASE(depth_order), CASE(fill_rule), CASE(font_glyph),
           CASE(colormap_lightness), CASE(diff_sheet_hot_cell), CASE(sheet_fixed_camera), CASE(labels),
           CASE(png_decodes), CASE(lines_chart), CASE(errors))

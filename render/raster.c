/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include "alloc.h"
#include "raster.h"

/* Screen positions are snapped to 1/16 pixel; pixel centers sit at 16 i + 8. */
#define SUBPIXEL_BITS 4
#define SUBPIXEL (1 << SUBPIXEL_BITS)
/* Vertices farther off-screen than this (pixels) are not drawn: keeps the edge products in
 * int64 (coordinates < 2^26 sixteenths, products < 2^54). */
#define MAX_SCREEN 4194304.0f

typedef struct screen_vertex {
    int32_t x, y;   /* 1/16 pixel; x == INT32_MIN marks a vertex that is not drawn */
    float z;
} screen_vertex;

mkr_style mkr_style_default(void)
{
    mkr_style s = { .color = { 200, 196, 188 } };
    return s;
}

void mkr_light_direction(const mkr_camera *cam, float out[3])
{
    const float x = MKR_LIGHT_SCREEN_X, y = MKR_LIGHT_SCREEN_Y, z = MKR_LIGHT_SCREEN_Z;
    float len = 0;
    for (int i = 0; i < 3; i++) {
        /* Toward the eye is -forward. */
        out[i] = x * cam->right[i] + y * cam->up[i] - z * cam->forward[i];
        len += out[i] * out[i];
    }
    len = sqrtf(len);
    for (int i = 0; i < 3; i++) out[i] /= len;
}

float mkr_light_intensity(float n_dot_l)
{
    return n_dot_l >= 0 ? MKR_LIGHT_AMBIENT + MKR_LIGHT_KEY * n_dot_l : MKR_LIGHT_AMBIENT - MKR_LIGHT_FILL * n_dot_l;
}

/* Pixel columns (or rows) whose centers 16 i + 8 lie at or after / at or before v (1/16
 * pixel, |v| < 2^27): ceil((v - 8) / 16) and floor((v - 8) / 16), shifted through an offset
 * that makes the shifted value non-negative. */
#define CENTER_OFFSET ((int64_t)1 << 30)
static int64_t first_center(int64_t v) { return ((v + 7 + CENTER_OFFSET) >> SUBPIXEL_BITS) - (CENTER_OFFSET >> SUBPIXEL_BITS); }
static int64_t last_center(int64_t v) { return ((v - 8 + CENTER_OFFSET) >> SUBPIXEL_BITS) - (CENTER_OFFSET >> SUBPIXEL_BITS); }

static int64_t min3(int64_t a, int64_t b, int64_t c) { return a < b ? (a < c ? a : c) : (b < c ? b : c); }
static int64_t max3(int64_t a, int64_t b, int64_t c) { return a > b ? (a > c ? a : c) : (b > c ? b : c); }

/* Edge a->b of a triangle whose edge functions are positive inside. Top-left edges own the
 * pixel centers exactly on them; the others get a bias of -1 so those centers fail. With y
 * down and this orientation, a left edge goes down (dy > 0) and a top edge goes left. */
typedef struct edge {
    int64_t value;        /* biased edge function at the first pixel center of the row */
    int64_t step_x, step_y;
    int64_t bias;
} edge;

static edge edge_setup(const screen_vertex *a, const screen_vertex *b, int64_t px, int64_t py)
{
    int64_t dx = (int64_t)b->x - a->x, dy = (int64_t)b->y - a->y;
    edge e;
    e.bias = (dy > 0 || (dy == 0 && dx < 0)) ? 0 : -1;
    e.value = (px - a->x) * dy - (py - a->y) * dx + e.bias;
    e.step_x = SUBPIXEL * dy;
    e.step_y = -SUBPIXEL * dx;
    return e;
}

static uint8_t to_byte(float v)
{
    return !(v > 0) ? 0 : v >= 255 ? 255 : (uint8_t)(v + 0.5f);
}

mk_result mkr_draw_mesh(mkr_image *img, const mkr_camera *cam, const mkr_mesh_view *mesh, const mkr_style *style,
                        mk_error *err)
{
    if (!img || !img->pixels || !cam || !mesh)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "draw: NULL image, camera or mesh");
    if ((mesh->vertex_count && !mesh->positions) || (mesh->triangle_count && !mesh->triangles))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "draw: mesh has %u vertices and %u triangles but no array",
                             mesh->vertex_count, mesh->triangle_count);
    if (cam->width <= 0 || cam->height <= 0)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "draw: camera viewport %dx%d is empty (frame the camera)",
                             cam->width, cam->height);
    for (uint64_t i = 0; i < 3 * (uint64_t)mesh->triangle_count; i++)
        if (mesh->triangles[i] >= mesh->vertex_count)
            return mk_error_set(err, MK_ERROR_OUT_OF_RANGE, UINT64_MAX, "draw: triangle %llu uses vertex %u of %u",
                                 (unsigned long long)(i / 3), mesh->triangles[i], mesh->vertex_count);
    mkr_style def = mkr_style_default();
    if (!style) style = &def;

    /* Clip rectangle in pixels: viewport within the image. */
    int64_t clip_x0 = cam->x > 0 ? cam->x : 0, clip_y0 = cam->y > 0 ? cam->y : 0;
    int64_t clip_x1 = (int64_t)cam->x + cam->width, clip_y1 = (int64_t)cam->y + cam->height;
    if (clip_x1 > img->width) clip_x1 = img->width;
    if (clip_y1 > img->height) clip_y1 = img->height;
    if (clip_x0 >= clip_x1 || clip_y0 >= clip_y1 || mesh->triangle_count == 0) return MK_OK;

    screen_vertex *sv = malloc((mesh->vertex_count ? mesh->vertex_count : 1) * sizeof *sv);
    if (!sv) return mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "draw: out of memory for %u vertices", mesh->vertex_count);
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        float s[3];
        mkr_camera_project(cam, mesh->positions + 3 * (size_t)v, s);
        if (!(fabsf(s[0]) < MAX_SCREEN && fabsf(s[1]) < MAX_SCREEN && isfinite(s[2]))) {
            sv[v].x = INT32_MIN;
            continue;
        }
        sv[v].x = (int32_t)lrintf(s[0] * SUBPIXEL);
        sv[v].y = (int32_t)lrintf(s[1] * SUBPIXEL);
        sv[v].z = s[2];
    }

    float light[3];
    mkr_light_direction(cam, light);
    const float unlit = style->unlit < 0 ? 0 : style->unlit > 1 ? 1 : style->unlit;
    const int use_ramp = style->ramp && mesh->scalars;
    const int use_colors = !use_ramp && mesh->colors;
    float ramp_scale = 0;
    if (use_ramp && style->scalar_hi > style->scalar_lo) ramp_scale = 255.0f / (style->scalar_hi - style->scalar_lo);
    const int width = img->width;

    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *tri = mesh->triangles + 3 * (size_t)t;
        uint32_t ia = tri[0], ib = tri[1], ic = tri[2];
        const screen_vertex *a = &sv[ia], *b = &sv[ib], *c = &sv[ic];
        if (a->x == INT32_MIN || b->x == INT32_MIN || c->x == INT32_MIN) continue;

        /* The pixel centers in the bounding box, clipped. Most triangles of a dense mesh
         * cover none or one, so everything else waits for the first covered pixel. */
        int64_t x0 = first_center(min3(a->x, b->x, c->x)), x1 = last_center(max3(a->x, b->x, c->x));
        int64_t y0 = first_center(min3(a->y, b->y, c->y)), y1 = last_center(max3(a->y, b->y, c->y));
        if (x0 < clip_x0) x0 = clip_x0;
        if (y0 < clip_y0) y0 = clip_y0;
        if (x1 >= clip_x1) x1 = clip_x1 - 1;
        if (y1 >= clip_y1) y1 = clip_y1 - 1;
        if (x0 > x1 || y0 > y1) continue;

        /* Twice the signed area, as the edge function of a->b at c; make it positive. */
        int64_t area = ((int64_t)c->x - a->x) * ((int64_t)b->y - a->y) - ((int64_t)c->y - a->y) * ((int64_t)b->x - a->x);
        if (area == 0) continue;
        if (area < 0) {
            const screen_vertex *tmp = b; b = c; c = tmp;
            uint32_t ti = ib; ib = ic; ic = ti;
            area = -area;
        }

        /* Edge functions: e_bc weighs a, e_ca weighs b, e_ab weighs c. */
        int64_t px = SUBPIXEL * x0 + SUBPIXEL / 2, py = SUBPIXEL * y0 + SUBPIXEL / 2;
        edge ea = edge_setup(b, c, px, py), eb = edge_setup(c, a, px, py), ec = edge_setup(a, b, px, py);

        /* Filled at the first covered pixel: vertex attributes in the (possibly swapped)
         * order a, b, c. */
        int ready = 0;
        float inv_area = 0, face_intensity = 0;
        const float *na = NULL, *nb = NULL, *nc = NULL;
        float ca[3] = { 0 }, cb[3] = { 0 }, cc[3] = { 0 }, sa = 0, sb = 0, sc = 0;

        for (int64_t y = y0; y <= y1; y++) {
            int64_t wa = ea.value, wb = eb.value, wc = ec.value;
            float *depth = img->depth + (size_t)y * (size_t)width;
            uint8_t *row = img->pixels + 4 * (size_t)y * (size_t)width;
            for (int64_t x = x0; x <= x1; x++, wa += ea.step_x, wb += eb.step_x, wc += ec.step_x) {
                if ((wa | wb | wc) < 0) continue;
                if (!ready) {
                    ready = 1;
                    inv_area = 1.0f / (float)area;
                    if (mesh->normals) {
                        na = mesh->normals + 3 * (size_t)ia, nb = mesh->normals + 3 * (size_t)ib;
                        nc = mesh->normals + 3 * (size_t)ic;
                    } else {
                        /* The face normal of the original winding. */
                        const float *p0 = mesh->positions + 3 * (size_t)tri[0];
                        const float *p1 = mesh->positions + 3 * (size_t)tri[1];
                        const float *p2 = mesh->positions + 3 * (size_t)tri[2];
                        float e1[3] = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
                        float e2[3] = { p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2] };
                        float n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                       e1[0] * e2[1] - e1[1] * e2[0] };
                        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                        float ndl = len > 0 ? (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len : 0;
                        face_intensity = mkr_light_intensity(ndl);
                    }
                    if (use_ramp) {
                        sa = (mesh->scalars[ia] - style->scalar_lo) * ramp_scale;
                        sb = (mesh->scalars[ib] - style->scalar_lo) * ramp_scale;
                        sc = (mesh->scalars[ic] - style->scalar_lo) * ramp_scale;
                    } else if (use_colors) {
                        for (int k = 0; k < 3; k++) {
                            ca[k] = mesh->colors[3 * (size_t)ia + k];
                            cb[k] = mesh->colors[3 * (size_t)ib + k];
                            cc[k] = mesh->colors[3 * (size_t)ic + k];
                        }
                    }
                }
                float la = (float)(wa - ea.bias) * inv_area, lb = (float)(wb - eb.bias) * inv_area;
                float lc = 1.0f - la - lb;
                float z = la * a->z + lb * b->z + lc * c->z;
                if (!(z < depth[x])) continue;
                depth[x] = z;

                float intensity = face_intensity;
                if (na) {
                    float n0 = la * na[0] + lb * nb[0] + lc * nc[0];
                    float n1 = la * na[1] + lb * nb[1] + lc * nc[1];
                    float n2 = la * na[2] + lb * nb[2] + lc * nc[2];
                    float len2 = n0 * n0 + n1 * n1 + n2 * n2;
                    float ndl = len2 > 1e-30f ? (n0 * light[0] + n1 * light[1] + n2 * light[2]) / sqrtf(len2) : 0;
                    intensity = mkr_light_intensity(ndl);
                }
                intensity += unlit * (1.0f - intensity);
                uint8_t *p = row + 4 * x;
                if (use_ramp) {
                    float v = la * sa + lb * sb + lc * sc;
                    /* NaN (a broken value) shows as the hot end. */
                    int i = !(v < 255) ? 255 : v <= 0 ? 0 : (int)(v + 0.5f);
                    const uint8_t *rgb = style->ramp + 3 * i;
                    p[0] = to_byte(rgb[0] * intensity);
                    p[1] = to_byte(rgb[1] * intensity);
                    p[2] = to_byte(rgb[2] * intensity);
                } else if (use_colors) {
                    p[0] = to_byte((la * ca[0] + lb * cb[0] + lc * cc[0]) * intensity);
                    p[1] = to_byte((la * ca[1] + lb * cb[1] + lc * cc[1]) * intensity);
                    p[2] = to_byte((la * ca[2] + lb * cb[2] + lc * cc[2]) * intensity);
                } else {
                    p[0] = to_byte(style->color[0] * intensity);
                    p[1] = to_byte(style->color[1] * intensity);
                    p[2] = to_byte(style->color[2] * intensity);
                }
                p[3] = 255;
            }
            ea.value += ea.step_y, eb.value += eb.step_y, ec.value += ec.step_y;
        }
    }
    free(sv);
    return MK_OK;
}

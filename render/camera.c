/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>
#include "camera.h"

static const char *const view_names[MKR_VIEW_COUNT] = { "front", "side", "top", "iso" };

const char *mkr_view_name(mkr_view view)
{
    return (unsigned)view < MKR_VIEW_COUNT ? view_names[view] : "?";
}

int mkr_view_parse(const char *name, mkr_view *view)
{
    for (int v = 0; v < MKR_VIEW_COUNT; v++)
        if (name && strcmp(name, view_names[v]) == 0) {
            *view = (mkr_view)v;
            return 1;
        }
    return 0;
}

static void cross(const float a[3], const float b[3], float out[3])
{
    float x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}

static int normalize(float v[3])
{
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(len > 1e-30f) || !isfinite(len)) return 0;
    for (int i = 0; i < 3; i++) v[i] /= len;
    return 1;
}

void mkr_camera_look_at(mkr_camera *cam, const float eye[3], const float target[3], const float up[3])
{
    float f[3] = { target[0] - eye[0], target[1] - eye[1], target[2] - eye[2] };
    if (!normalize(f)) f[0] = 0, f[1] = 0, f[2] = -1;
    float r[3];
    cross(f, up, r);
    if (!normalize(r)) {
        /* up is parallel to the view direction: looking straight down or up keeps -z up,
         * anything else keeps +y up. */
        static const float minus_z[3] = { 0, 0, -1 }, plus_y[3] = { 0, 1, 0 };
        cross(f, fabsf(f[1]) > 0.9f ? minus_z : plus_y, r);
        normalize(r);
    }
    memcpy(cam->forward, f, sizeof f);
    memcpy(cam->right, r, sizeof r);
    cross(r, f, cam->up);
    memcpy(cam->center, target, sizeof cam->center);
}

void mkr_camera_set_view(mkr_camera *cam, mkr_view view)
{
    static const float origin[3] = { 0, 0, 0 };
    static const float eyes[MKR_VIEW_COUNT][3] = { { 0, 0, 1 }, { 1, 0, 0 }, { 0, 1, 0 }, { 1, 1, 1 } };
    static const float ups[MKR_VIEW_COUNT][3] = { { 0, 1, 0 }, { 0, 1, 0 }, { 0, 0, -1 }, { 0, 1, 0 } };
    if ((unsigned)view >= MKR_VIEW_COUNT) view = MKR_VIEW_FRONT;
    float center[3];
    memcpy(center, cam->center, sizeof center);
    mkr_camera_look_at(cam, eyes[view], origin, ups[view]);
    memcpy(cam->center, center, sizeof center);
}

static float dot(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void mkr_camera_frame_extent(mkr_camera *cam, const float lo[3], const float hi[3], int x, int y, int width,
                             int height, float margin)
{
    float a[3] = { -0.5f, -0.5f, -0.5f }, b[3] = { 0.5f, 0.5f, 0.5f };
    if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]) {
        memcpy(a, lo, sizeof a);
        memcpy(b, hi, sizeof b);
    }
    float mid[3] = { 0.5f * (a[0] + b[0]), 0.5f * (a[1] + b[1]), 0.5f * (a[2] + b[2]) };
    for (int i = 0; i < 3; i++) cam->center[i] = mid[0] * cam->right[i] + mid[1] * cam->up[i] + mid[2] * cam->forward[i];
    float half_x = 0.5f * (b[0] - a[0]), half_y = 0.5f * (b[1] - a[1]);
    cam->x = x, cam->y = y, cam->width = width, cam->height = height;
    if (!(margin >= 0 && margin < 0.5f)) margin = 0;
    float room_x = 0.5f * (float)width * (1 - 2 * margin), room_y = 0.5f * (float)height * (1 - 2 * margin);
    float scale = INFINITY;
    if (half_x > 0) scale = room_x / half_x;
    if (half_y > 0 && room_y / half_y < scale) scale = room_y / half_y;
    cam->pixels_per_unit = isfinite(scale) && scale > 0 ? scale : 1.0f; /* a point: any scale */
}

void mkr_camera_frame(mkr_camera *cam, const float lo[3], const float hi[3], int x, int y, int width, int height,
                      float margin)
{
    float a[3] = { -0.5f, -0.5f, -0.5f }, b[3] = { 0.5f, 0.5f, 0.5f };
    if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]) {
        memcpy(a, lo, sizeof a);
        memcpy(b, hi, sizeof b);
    }
    /* The box's extent along an axis: its center's coordinate plus or minus the half sizes
     * weighted by the axis components. */
    float mid[3] = { 0.5f * (a[0] + b[0]), 0.5f * (a[1] + b[1]), 0.5f * (a[2] + b[2]) };
    float half[3] = { 0.5f * (b[0] - a[0]), 0.5f * (b[1] - a[1]), 0.5f * (b[2] - a[2]) };
    const float *axes[3] = { cam->right, cam->up, cam->forward };
    float ext_lo[3], ext_hi[3];
    for (int k = 0; k < 3; k++) {
        float c = dot(mid, axes[k]);
        float r = fabsf(axes[k][0]) * half[0] + fabsf(axes[k][1]) * half[1] + fabsf(axes[k][2]) * half[2];
        ext_lo[k] = c - r, ext_hi[k] = c + r;
    }
    mkr_camera_frame_extent(cam, ext_lo, ext_hi, x, y, width, height, margin);
}

void mkr_camera_extent_add(const mkr_camera *cam, float lo[3], float hi[3], const float *positions, uint32_t count)
{
    const float *axes[3] = { cam->right, cam->up, cam->forward };
    for (uint32_t v = 0; v < count; v++) {
        const float *p = positions + 3 * (size_t)v;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
        for (int k = 0; k < 3; k++) {
            float d = dot(p, axes[k]);
            if (d < lo[k]) lo[k] = d;
            if (d > hi[k]) hi[k] = d;
        }
    }
}

void mkr_camera_project(const mkr_camera *cam, const float p[3], float out[3])
{
    float d[3] = { p[0] - cam->center[0], p[1] - cam->center[1], p[2] - cam->center[2] };
    float s = cam->pixels_per_unit;
    out[0] = (float)cam->x + 0.5f * (float)cam->width + s * (d[0] * cam->right[0] + d[1] * cam->right[1] + d[2] * cam->right[2]);
    out[1] = (float)cam->y + 0.5f * (float)cam->height - s * (d[0] * cam->up[0] + d[1] * cam->up[1] + d[2] * cam->up[2]);
    out[2] = d[0] * cam->forward[0] + d[1] * cam->forward[1] + d[2] * cam->forward[2];
}

void mkr_bounds_reset(float lo[3], float hi[3])
{
    for (int i = 0; i < 3; i++) lo[i] = INFINITY, hi[i] = -INFINITY;
}

void mkr_bounds_add(float lo[3], float hi[3], const float *positions, uint32_t count)
{
    for (uint32_t v = 0; v < count; v++) {
        const float *p = positions + 3 * (size_t)v;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
        for (int i = 0; i < 3; i++) {
            if (p[i] < lo[i]) lo[i] = p[i];
            if (p[i] > hi[i]) hi[i] = p[i];
        }
    }
}

/* SPDX-License-Identifier: MIT */
/* Orthographic cameras: look-at orientation, the four standard views, and framing of a
 * bounding box into a viewport.
 *
 * World: right-handed, +y up; a model's front faces +z (the glTF convention).
 * Screen: x to the right, y down, pixel (i, j) covers [i, i+1) x [j, j+1) with its center at
 * (i + 0.5, j + 0.5); depth grows away from the eye (smaller is nearer).
 *
 *   front  eye on +z looking along -z   screen right = +x, up = +y
 *   side   eye on +x looking along -x   screen right = -z, up = +y (the front faces left)
 *   top    eye on +y looking along -y   screen right = +x, up = -z (the front faces down)
 *   iso    eye on (+1,+1,+1) looking at the center, +y kept up: sees front, +x side and top
 */
#ifndef MKR_CAMERA_H
#define MKR_CAMERA_H

#include <stdint.h>

typedef enum mkr_view {
    MKR_VIEW_FRONT = 0,
    MKR_VIEW_SIDE,
    MKR_VIEW_TOP,
    MKR_VIEW_ISO,
    MKR_VIEW_COUNT
} mkr_view;

typedef struct mkr_camera {
    float right[3], up[3], forward[3]; /* orthonormal world axes of the screen; forward into it */
    float center[3];                   /* world point drawn at the viewport center */
    float pixels_per_unit;             /* orthographic scale */
    int x, y, width, height;           /* viewport in image pixels; drawing is clipped to it */
} mkr_camera;

/* "front", "side", "top", "iso". */
const char *mkr_view_name(mkr_view view);
/* Parses a view name; returns 1 and sets *view, or 0 for an unknown name. */
int mkr_view_parse(const char *name, mkr_view *view);

/* Orients the camera from eye toward target with up as the screen-up hint (replaced by -z or
 * +y when parallel to the view direction); center = target. Scale and viewport unchanged. */
void mkr_camera_look_at(mkr_camera *cam, const float eye[3], const float target[3], const float up[3]);
/* Orients the camera for a standard view (see the table above). */
void mkr_camera_set_view(mkr_camera *cam, mkr_view view);
/* Keeps the orientation; sets the viewport and centers and scales the box [lo, hi] so its
 * projection fills the viewport less a margin (fraction of the viewport on every side).
 * An empty box (lo > hi) frames the unit cube around the origin. */
void mkr_camera_frame(mkr_camera *cam, const float lo[3], const float hi[3], int x, int y, int width, int height,
                      float margin);

/* Tighter framing of the points themselves: their extents along the camera axes (right,
 * up, forward), started with mkr_bounds_reset and grown with mkr_camera_extent_add (which
 * only reads the orientation), then framed like a box. A sphere framed this way fills the
 * viewport in every view, where its bounding box's corners would not. */
void mkr_camera_extent_add(const mkr_camera *cam, float lo[3], float hi[3], const float *positions, uint32_t count);
void mkr_camera_frame_extent(mkr_camera *cam, const float lo[3], const float hi[3], int x, int y, int width,
                             int height, float margin);
/* Screen position and depth of a world point: out = { x, y, depth }. */
void mkr_camera_project(const mkr_camera *cam, const float p[3], float out[3]);

/* Bounds helpers: start empty, then grow by count points (non-finite points ignored). */
void mkr_bounds_reset(float lo[3], float hi[3]);
void mkr_bounds_add(float lo[3], float hi[3], const float *positions, uint32_t count);

#endif

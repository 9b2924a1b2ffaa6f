/* SPDX-License-Identifier: MIT */
/* Software rasterizer: indexed triangle meshes into an mkr_image through an orthographic
 * mkr_camera, with a depth buffer and one fixed directional light.
 *
 * Coverage: a pixel is drawn when its center is inside the triangle; edge functions in 1/16
 * pixel fixed point with the top-left rule, so triangles sharing an edge draw each pixel on
 * it exactly once. Both windings are drawn (no culling). Depth: nearer (smaller) wins; an
 * equal depth keeps what was drawn first.
 *
 * Shading: the normal is interpolated per pixel from the vertex normals (or, without them,
 * the face normal of the winding: counter-clockwise seen from the front). With n.l the
 * cosine to the light, intensity = AMBIENT + KEY * max(n.l, 0) + FILL * max(-n.l, 0): a face
 * turned away from the light gets the weaker fill light instead of going black, so an
 * inverted normal shows as a darker, flatter shade. The light is fixed to the camera (from
 * the upper left, in front of the model), so every view is lit alike.
 */
#ifndef MKR_RASTER_H
#define MKR_RASTER_H

#include <stdint.h>
#include "camera.h"
#include "image.h"
#include "morphkit.h"

#define MKR_LIGHT_AMBIENT 0.25f
#define MKR_LIGHT_KEY 0.75f
#define MKR_LIGHT_FILL 0.30f
/* Direction toward the light in screen axes (right, up, toward the eye), before normalizing. */
#define MKR_LIGHT_SCREEN_X -0.40f
#define MKR_LIGHT_SCREEN_Y 0.60f
#define MKR_LIGHT_SCREEN_Z 0.70f

/* One mesh to draw: plain arrays, nothing owned. */
typedef struct mkr_mesh_view {
    uint32_t vertex_count;
    const float *positions;     /* 3 per vertex, world units */
    const float *normals;       /* 3 per vertex (need not be unit length), or NULL: face normals */
    uint32_t triangle_count;
    const uint32_t *triangles;  /* 3 vertex indices per triangle */
    const float *scalars;       /* 1 per vertex, colored through mkr_style.ramp, or NULL */
    const uint8_t *colors;      /* RGB, 3 per vertex, or NULL */
} mkr_mesh_view;

/* How to color a mesh: scalars through the ramp when both are given, else the vertex colors,
 * else the flat color; then lit. */
typedef struct mkr_style {
    uint8_t color[3];           /* flat base color */
    float unlit;                /* 0: full light model ... 1: colors as given, no shading */
    const uint8_t *ramp;        /* 256 RGB entries (768 bytes) for scalars, or NULL */
    float scalar_lo, scalar_hi; /* scalars mapped onto the ramp's first and last entry (clamped) */
} mkr_style;

/* The style used for a NULL style: clay gray, fully lit. */
mkr_style mkr_style_default(void);

/* Unit world direction toward the light for this camera. */
void mkr_light_direction(const mkr_camera *cam, float out[3]);
/* Light intensity (0..1) for the cosine between the unit normal and the light direction. */
float mkr_light_intensity(float n_dot_l);

/* Draws the mesh into img, clipped to the camera viewport. style may be NULL (defaults).
 * Errors: MK_ERROR_INVALID_ARGUMENT (NULL image, camera, mesh or a needed array; empty
 * viewport), MK_ERROR_OUT_OF_RANGE (a triangle index >= vertex_count; nothing is drawn),
 * MK_ERROR_OUT_OF_MEMORY. Triangles with a non-finite or far off-screen (2^22 pixels) vertex
 * are skipped. */
mk_result mkr_draw_mesh(mkr_image *img, const mkr_camera *cam, const mkr_mesh_view *mesh, const mkr_style *style,
                        mk_error *err);

#endif

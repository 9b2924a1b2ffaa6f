/* SPDX-License-Identifier: MIT */
/* An RGBA8 picture with a float depth buffer: the target every drawing function writes to. */
#ifndef MKR_IMAGE_H
#define MKR_IMAGE_H

#include <stdint.h>
#include "morphkit.h"

/* Largest accepted width or height (pixels). */
#define MKR_IMAGE_MAX_SIDE 16384

typedef struct mkr_image {
    int width, height;
    uint8_t *pixels;   /* 4 * width * height bytes, RGBA, rows top to bottom, not premultiplied */
    float *depth;      /* width * height view depths; smaller is nearer, +INFINITY is empty */
} mkr_image;

/* Allocates a width x height image, cleared to opaque black with empty depth.
 * Errors: MK_ERROR_INVALID_ARGUMENT (NULL image, side < 1), MK_ERROR_LIMIT (side above
 * MKR_IMAGE_MAX_SIDE), MK_ERROR_OUT_OF_MEMORY. On error *img is zeroed. */
mk_result mkr_image_create(mkr_image *img, int width, int height, mk_error *err);
/* Frees the buffers and zeroes *img; NULL and zeroed images are fine. */
void mkr_image_destroy(mkr_image *img);

/* Every pixel to rgba and every depth to empty. */
void mkr_image_clear(mkr_image *img, const uint8_t rgba[4]);
/* Fills the rectangle (clipped to the image) with rgba blended over the pixels by rgba[3]
 * (255 replaces); depth is left alone. */
void mkr_image_fill_rect(mkr_image *img, int x, int y, int width, int height, const uint8_t rgba[4]);
/* The pixel at (x, y) (4 bytes), or NULL outside the image. */
uint8_t *mkr_image_pixel(const mkr_image *img, int x, int y);

#endif

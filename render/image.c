/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "image.h"

mk_result mkr_image_create(mkr_image *img, int width, int height, mk_error *err)
{
    if (!img) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "image: NULL image");
    memset(img, 0, sizeof *img);
    if (width < 1 || height < 1)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "image: size %dx%d is empty", width, height);
    if (width > MKR_IMAGE_MAX_SIDE || height > MKR_IMAGE_MAX_SIDE)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "image: size %dx%d exceeds %d pixels a side", width, height,
                             MKR_IMAGE_MAX_SIDE);
    size_t count = (size_t)width * (size_t)height;
    img->pixels = malloc(count * 4);
    img->depth = malloc(count * sizeof(float));
    if (!img->pixels || !img->depth) {
        mkr_image_destroy(img);
        return mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "image: out of memory for %dx%d pixels", width, height);
    }
    img->width = width;
    img->height = height;
    static const uint8_t black[4] = { 0, 0, 0, 255 };
    mkr_image_clear(img, black);
    return MK_OK;
}

void mkr_image_destroy(mkr_image *img)
{
    if (!img) return;
    free(img->pixels);
    free(img->depth);
    memset(img, 0, sizeof *img);
}

void mkr_image_clear(mkr_image *img, const uint8_t rgba[4])
{
    size_t count = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < count; i++) {
        memcpy(img->pixels + 4 * i, rgba, 4);
        img->depth[i] = INFINITY;
    }
}

void mkr_image_fill_rect(mkr_image *img, int x, int y, int width, int height, const uint8_t rgba[4])
{
    int x0 = x < 0 ? 0 : x, y0 = y < 0 ? 0 : y;
    /* In long long: x + width may exceed INT_MAX. */
    long long x1 = (long long)x + width, y1 = (long long)y + height;
    if (x1 > img->width) x1 = img->width;
    if (y1 > img->height) y1 = img->height;
    unsigned a = rgba[3];
    for (int py = y0; py < y1; py++) {
        uint8_t *p = img->pixels + 4 * ((size_t)py * (size_t)img->width + (size_t)x0);
        for (int px = x0; px < x1; px++, p += 4) {
            if (a == 255) {
                memcpy(p, rgba, 4);
                continue;
            }
            for (int c = 0; c < 3; c++) p[c] = (uint8_t)((rgba[c] * a + p[c] * (255 - a) + 127) / 255);
            p[3] = (uint8_t)(a + (p[3] * (255 - a) + 127) / 255);
        }
    }
}

uint8_t *mkr_image_pixel(const mkr_image *img, int x, int y)
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height) return NULL;
    return img->pixels + 4 * ((size_t)y * (size_t)img->width + (size_t)x);
}

/* SPDX-License-Identifier: MIT */
/* The one translation unit that compiles stb_image_write (Debian's libstb-dev). */
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "png.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb_image_write.h>

typedef struct sink {
    unsigned char *data;
    size_t size, capacity;
    int failed;
} sink;

static void sink_write(void *context, void *bytes, int size)
{
    sink *s = context;
    if (s->failed || size <= 0) return;
    if ((size_t)size > s->capacity - s->size) {
        size_t capacity = s->capacity ? s->capacity : 4096;
        while ((size_t)size > capacity - s->size) {
            if (capacity > SIZE_MAX / 2) { s->failed = 1; return; }
            capacity *= 2;
        }
        unsigned char *grown = realloc(s->data, capacity);
        if (!grown) { s->failed = 1; return; }
        s->data = grown;
        s->capacity = capacity;
    }
    memcpy(s->data + s->size, bytes, (size_t)size);
    s->size += (size_t)size;
}

mk_result mkr_png_encode(const mkr_image *img, mkr_png *out, mk_error *err)
{
    if (!out) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "png: NULL output");
    memset(out, 0, sizeof *out);
    if (!img || !img->pixels || img->width < 1 || img->height < 1)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "png: no image to encode");
    if (img->width > MKR_IMAGE_MAX_SIDE || img->height > MKR_IMAGE_MAX_SIDE)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "png: image %dx%d exceeds %d pixels a side", img->width, img->height,
                             MKR_IMAGE_MAX_SIDE);
    size_t count = (size_t)img->width * (size_t)img->height;
    int opaque = 1;
    for (size_t i = 0; i < count && opaque; i++) opaque = img->pixels[4 * i + 3] == 255;

    /* Opaque pictures drop the alpha channel: a quarter fewer bytes to compress. */
    const unsigned char *pixels = img->pixels;
    unsigned char *rgb = NULL;
    int channels = 4;
    if (opaque) {
        rgb = malloc(count * 3);
        if (!rgb) return mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "png: out of memory for %dx%d pixels", img->width, img->height);
        for (size_t i = 0; i < count; i++) memcpy(rgb + 3 * i, img->pixels + 4 * i, 3);
        pixels = rgb;
        channels = 3;
    }
    sink s = { 0 };
    int ok = stbi_write_png_to_func(sink_write, &s, img->width, img->height, channels, pixels, img->width * channels);
    free(rgb);
    if (!ok || s.failed) {
        free(s.data);
        return mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "png: out of memory encoding %dx%d pixels", img->width,
                             img->height);
    }
    out->data = s.data;
    out->size = s.size;
    return MK_OK;
}

void mkr_png_free(mkr_png *png)
{
    if (!png) return;
    free(png->data);
    png->data = NULL;
    png->size = 0;
}

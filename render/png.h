/* SPDX-License-Identifier: MIT */
/* PNG encoding of an mkr_image, in memory: the caller decides where the bytes go. */
#ifndef MKR_PNG_H
#define MKR_PNG_H

#include <stddef.h>
#include "image.h"
#include "morphkit.h"

typedef struct mkr_png {
    unsigned char *data;   /* malloc'ed; free with mkr_png_free */
    size_t size;
} mkr_png;

/* Encodes img as PNG: RGB when every pixel is opaque, else RGBA. *out is zeroed on error.
 * Errors: MK_ERROR_INVALID_ARGUMENT (NULL or empty image, NULL out), MK_ERROR_OUT_OF_MEMORY. */
mk_result mkr_png_encode(const mkr_image *img, mkr_png *out, mk_error *err);
void mkr_png_free(mkr_png *png);

#endif

/* SPDX-License-Identifier: MIT */
/* morphkit_render: pictures of meshes for people to look at (docs/rendering.md).
 *
 *   mkr_sheet_desc desc = { .cells = cells, .cell_count = n, .cell_width = 512, .cell_height = 512,
 *                           .view = MKR_VIEW_ISO, .title = "walk.morph  clip 0" };
 *   mkr_image img; mkr_png png; mk_error err;
 *   if (mkr_sheet_render(&desc, &img, &err) != MK_OK) { puts(err.message); ... }
 *   if (mkr_png_encode(&img, &png, &err) == MK_OK) { write png.data, png.size; mkr_png_free(&png); }
 *   mkr_image_destroy(&img);
 *
 * Depends on libc, libm and stb_image_write; of morphkit only on the mk_result and mk_error
 * types of runtime/morphkit.h. Allocates with malloc; no global state. */
#ifndef MKR_RENDER_H
#define MKR_RENDER_H

#include "camera.h"
#include "colormap.h"
#include "font.h"
#include "image.h"
#include "plot.h"
#include "png.h"
#include "raster.h"
#include "sheet.h"

#endif

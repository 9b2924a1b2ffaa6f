/* SPDX-License-Identifier: MIT */
/* A built-in 5x9 bitmap font (ASCII 32..126) and text drawing at integer scale.
 *
 * A glyph is 5 columns by 9 rows: rows 0-6 stand on the baseline (capitals and digits are 7
 * rows tall, lower case 5), rows 7-8 hold descenders. Characters advance 6 pixels and lines
 * 10 pixels (times the scale). */
#ifndef MKR_FONT_H
#define MKR_FONT_H

#include <stdint.h>
#include "image.h"

#define MKR_FONT_WIDTH 5
#define MKR_FONT_HEIGHT 9
#define MKR_FONT_ADVANCE 6
#define MKR_FONT_LINE 10
/* Box padding around drawn text, in font pixels. */
#define MKR_FONT_PADDING 2

/* The 9 rows of a character's glyph, bit 4 the leftmost column. Characters outside 32..126
 * get the '?' glyph. */
const uint8_t *mkr_font_glyph(int ch);

/* Size in pixels of the box mkr_draw_text fills for text at scale: the longest line times
 * the advance, the line count times the line height, plus the padding on every side. Lines
 * split at '\n'; a UTF-8 sequence counts as one character (drawn as '?'). */
void mkr_text_box(const char *text, int scale, int *width, int *height);

/* Draws text with its box's top-left corner at (x, y), clipped to the image: the box in bg
 * (blended by bg[3]; NULL: no box), then the glyph pixels in fg (blended by fg[3]), each
 * font pixel a scale x scale square. scale < 1 counts as 1. */
void mkr_draw_text(mkr_image *img, int x, int y, const char *text, int scale, const uint8_t fg[4], const uint8_t bg[4]);

#endif

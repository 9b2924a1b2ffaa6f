/* SPDX-License-Identifier: MIT */
#include <string.h>
#include "font.h"

/* Row patterns named by their pixels, 'X' on and 'o' off, leftmost first: the table below
 * reads as the glyphs themselves. */
enum {
    ooooo, ooooX, oooXo, oooXX, ooXoo, ooXoX, ooXXo, ooXXX,
    oXooo, oXooX, oXoXo, oXoXX, oXXoo, oXXoX, oXXXo, oXXXX,
    Xoooo, XoooX, XooXo, XooXX, XoXoo, XoXoX, XoXXo, XoXXX,
    XXooo, XXooX, XXoXo, XXoXX, XXXoo, XXXoX, XXXXo, XXXXX
};

static const uint8_t glyphs[95][MKR_FONT_HEIGHT] = {
    /* ' '  */ { ooooo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo },
    /* '!'  */ { ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooooo, ooXoo, ooooo, ooooo },
    /* '"'  */ { oXoXo, oXoXo, oXoXo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo },
    /* '#'  */ { oXoXo, oXoXo, XXXXX, oXoXo, XXXXX, oXoXo, oXoXo, ooooo, ooooo },
    /* '$'  */ { ooXoo, oXXXX, XoXoo, oXXXo, ooXoX, XXXXo, ooXoo, ooooo, ooooo },
    /* '%'  */ { XXooo, XXooX, oooXo, ooXoo, oXooo, XooXX, oooXX, ooooo, ooooo },
    /* '&'  */ { oXXoo, XooXo, XoXoo, oXooo, XoXoX, XooXo, oXXoX, ooooo, ooooo },
    /* '\'' */ { ooXoo, ooXoo, oXooo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo },
    /* '('  */ { oooXo, ooXoo, oXooo, oXooo, oXooo, ooXoo, oooXo, ooooo, ooooo },
    /* ')'  */ { oXooo, ooXoo, oooXo, oooXo, oooXo, ooXoo, oXooo, ooooo, ooooo },
    /* '*'  */ { ooooo, ooXoo, XoXoX, oXXXo, XoXoX, ooXoo, ooooo, ooooo, ooooo },
    /* '+'  */ { ooooo, ooXoo, ooXoo, XXXXX, ooXoo, ooXoo, ooooo, ooooo, ooooo },
    /* ','  */ { ooooo, ooooo, ooooo, ooooo, ooooo, oXXoo, oXXoo, ooXoo, oXooo },
    /* '-'  */ { ooooo, ooooo, ooooo, XXXXX, ooooo, ooooo, ooooo, ooooo, ooooo },
    /* '.'  */ { ooooo, ooooo, ooooo, ooooo, ooooo, oXXoo, oXXoo, ooooo, ooooo },
    /* '/'  */ { ooooX, oooXo, oooXo, ooXoo, oXooo, oXooo, Xoooo, ooooo, ooooo },
    /* '0'  */ { oXXXo, XoooX, XooXX, XoXoX, XXooX, XoooX, oXXXo, ooooo, ooooo },
    /* '1'  */ { ooXoo, oXXoo, ooXoo, ooXoo, ooXoo, ooXoo, oXXXo, ooooo, ooooo },
    /* '2'  */ { oXXXo, XoooX, ooooX, oooXo, ooXoo, oXooo, XXXXX, ooooo, ooooo },
    /* '3'  */ { XXXXX, oooXo, ooXoo, oooXo, ooooX, XoooX, oXXXo, ooooo, ooooo },
    /* '4'  */ { oooXo, ooXXo, oXoXo, XooXo, XXXXX, oooXo, oooXo, ooooo, ooooo },
    /* '5'  */ { XXXXX, Xoooo, XXXXo, ooooX, ooooX, XoooX, oXXXo, ooooo, ooooo },
    /* '6'  */ { ooXXo, oXooo, Xoooo, XXXXo, XoooX, XoooX, oXXXo, ooooo, ooooo },
    /* '7'  */ { XXXXX, ooooX, oooXo, ooXoo, oXooo, oXooo, oXooo, ooooo, ooooo },
    /* '8'  */ { oXXXo, XoooX, XoooX, oXXXo, XoooX, XoooX, oXXXo, ooooo, ooooo },
    /* '9'  */ { oXXXo, XoooX, XoooX, oXXXX, ooooX, oooXo, oXXoo, ooooo, ooooo },
    /* ':'  */ { ooooo, oXXoo, oXXoo, ooooo, oXXoo, oXXoo, ooooo, ooooo, ooooo },
    /* ';'  */ { ooooo, oXXoo, oXXoo, ooooo, oXXoo, oXXoo, ooXoo, oXooo, ooooo },
    /* '<'  */ { oooXo, ooXoo, oXooo, Xoooo, oXooo, ooXoo, oooXo, ooooo, ooooo },
    /* '='  */ { ooooo, ooooo, XXXXX, ooooo, XXXXX, ooooo, ooooo, ooooo, ooooo },
    /* '>'  */ { oXooo, ooXoo, oooXo, ooooX, oooXo, ooXoo, oXooo, ooooo, ooooo },
    /* '?'  */ { oXXXo, XoooX, ooooX, oooXo, ooXoo, ooooo, ooXoo, ooooo, ooooo },
    /* '@'  */ { oXXXo, XoooX, XoXXX, XoXoX, XoXXX, Xoooo, oXXXX, ooooo, ooooo },
    /* 'A'  */ { oXXXo, XoooX, XoooX, XXXXX, XoooX, XoooX, XoooX, ooooo, ooooo },
    /* 'B'  */ { XXXXo, XoooX, XoooX, XXXXo, XoooX, XoooX, XXXXo, ooooo, ooooo },
    /* 'C'  */ { oXXXo, XoooX, Xoooo, Xoooo, Xoooo, XoooX, oXXXo, ooooo, ooooo },
    /* 'D'  */ { XXXoo, XooXo, XoooX, XoooX, XoooX, XooXo, XXXoo, ooooo, ooooo },
    /* 'E'  */ { XXXXX, Xoooo, Xoooo, XXXXo, Xoooo, Xoooo, XXXXX, ooooo, ooooo },
    /* 'F'  */ { XXXXX, Xoooo, Xoooo, XXXXo, Xoooo, Xoooo, Xoooo, ooooo, ooooo },
    /* 'G'  */ { oXXXo, XoooX, Xoooo, XoXXX, XoooX, XoooX, oXXXX, ooooo, ooooo },
    /* 'H'  */ { XoooX, XoooX, XoooX, XXXXX, XoooX, XoooX, XoooX, ooooo, ooooo },
    /* 'I'  */ { oXXXo, ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, oXXXo, ooooo, ooooo },
    /* 'J'  */ { ooXXX, oooXo, oooXo, oooXo, oooXo, XooXo, oXXoo, ooooo, ooooo },
    /* 'K'  */ { XoooX, XooXo, XoXoo, XXooo, XoXoo, XooXo, XoooX, ooooo, ooooo },
    /* 'L'  */ { Xoooo, Xoooo, Xoooo, Xoooo, Xoooo, Xoooo, XXXXX, ooooo, ooooo },
    /* 'M'  */ { XoooX, XXoXX, XoXoX, XoXoX, XoooX, XoooX, XoooX, ooooo, ooooo },
    /* 'N'  */ { XoooX, XoooX, XXooX, XoXoX, XooXX, XoooX, XoooX, ooooo, ooooo },
    /* 'O'  */ { oXXXo, XoooX, XoooX, XoooX, XoooX, XoooX, oXXXo, ooooo, ooooo },
    /* 'P'  */ { XXXXo, XoooX, XoooX, XXXXo, Xoooo, Xoooo, Xoooo, ooooo, ooooo },
    /* 'Q'  */ { oXXXo, XoooX, XoooX, XoooX, XoXoX, XooXo, oXXoX, ooooo, ooooo },
    /* 'R'  */ { XXXXo, XoooX, XoooX, XXXXo, XoXoo, XooXo, XoooX, ooooo, ooooo },
    /* 'S'  */ { oXXXX, Xoooo, Xoooo, oXXXo, ooooX, ooooX, XXXXo, ooooo, ooooo },
    /* 'T'  */ { XXXXX, ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooooo, ooooo },
    /* 'U'  */ { XoooX, XoooX, XoooX, XoooX, XoooX, XoooX, oXXXo, ooooo, ooooo },
    /* 'V'  */ { XoooX, XoooX, XoooX, XoooX, XoooX, oXoXo, ooXoo, ooooo, ooooo },
    /* 'W'  */ { XoooX, XoooX, XoooX, XoXoX, XoXoX, XoXoX, oXoXo, ooooo, ooooo },
    /* 'X'  */ { XoooX, XoooX, oXoXo, ooXoo, oXoXo, XoooX, XoooX, ooooo, ooooo },
    /* 'Y'  */ { XoooX, XoooX, oXoXo, ooXoo, ooXoo, ooXoo, ooXoo, ooooo, ooooo },
    /* 'Z'  */ { XXXXX, ooooX, oooXo, ooXoo, oXooo, Xoooo, XXXXX, ooooo, ooooo },
    /* '['  */ { oXXXo, oXooo, oXooo, oXooo, oXooo, oXooo, oXXXo, ooooo, ooooo },
    /* '\\' */ { Xoooo, oXooo, oXooo, ooXoo, oooXo, oooXo, ooooX, ooooo, ooooo },
    /* ']'  */ { oXXXo, oooXo, oooXo, oooXo, oooXo, oooXo, oXXXo, ooooo, ooooo },
    /* '^'  */ { ooXoo, oXoXo, XoooX, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo },
    /* '_'  */ { ooooo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo, XXXXX, ooooo },
    /* '`'  */ { oXooo, ooXoo, oooXo, ooooo, ooooo, ooooo, ooooo, ooooo, ooooo },
    /* 'a'  */ { ooooo, ooooo, oXXXo, ooooX, oXXXX, XoooX, oXXXX, ooooo, ooooo },
    /* 'b'  */ { Xoooo, Xoooo, XoXXo, XXooX, XoooX, XoooX, XXXXo, ooooo, ooooo },
    /* 'c'  */ { ooooo, ooooo, oXXXo, Xoooo, Xoooo, XoooX, oXXXo, ooooo, ooooo },
    /* 'd'  */ { ooooX, ooooX, oXXoX, XooXX, XoooX, XoooX, oXXXX, ooooo, ooooo },
    /* 'e'  */ { ooooo, ooooo, oXXXo, XoooX, XXXXX, Xoooo, oXXXo, ooooo, ooooo },
    /* 'f'  */ { ooXXo, oXooX, oXooo, XXXoo, oXooo, oXooo, oXooo, ooooo, ooooo },
    /* 'g'  */ { ooooo, ooooo, oXXXX, XoooX, XoooX, XoooX, oXXXX, ooooX, oXXXo },
    /* 'h'  */ { Xoooo, Xoooo, XoXXo, XXooX, XoooX, XoooX, XoooX, ooooo, ooooo },
    /* 'i'  */ { ooXoo, ooooo, oXXoo, ooXoo, ooXoo, ooXoo, oXXXo, ooooo, ooooo },
    /* 'j'  */ { oooXo, ooooo, ooXXo, oooXo, oooXo, oooXo, oooXo, XooXo, oXXoo },
    /* 'k'  */ { Xoooo, Xoooo, XooXo, XoXoo, XXooo, XoXoo, XooXo, ooooo, ooooo },
    /* 'l'  */ { oXXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, oXXXo, ooooo, ooooo },
    /* 'm'  */ { ooooo, ooooo, XXoXo, XoXoX, XoXoX, XoXoX, XoXoX, ooooo, ooooo },
    /* 'n'  */ { ooooo, ooooo, XoXXo, XXooX, XoooX, XoooX, XoooX, ooooo, ooooo },
    /* 'o'  */ { ooooo, ooooo, oXXXo, XoooX, XoooX, XoooX, oXXXo, ooooo, ooooo },
    /* 'p'  */ { ooooo, ooooo, XXXXo, XoooX, XoooX, XoooX, XXXXo, Xoooo, Xoooo },
    /* 'q'  */ { ooooo, ooooo, oXXXX, XoooX, XoooX, XoooX, oXXXX, ooooX, ooooX },
    /* 'r'  */ { ooooo, ooooo, XoXXo, XXooX, Xoooo, Xoooo, Xoooo, ooooo, ooooo },
    /* 's'  */ { ooooo, ooooo, oXXXX, Xoooo, oXXXo, ooooX, XXXXo, ooooo, ooooo },
    /* 't'  */ { oXooo, oXooo, XXXoo, oXooo, oXooo, oXooX, ooXXo, ooooo, ooooo },
    /* 'u'  */ { ooooo, ooooo, XoooX, XoooX, XoooX, XooXX, oXXoX, ooooo, ooooo },
    /* 'v'  */ { ooooo, ooooo, XoooX, XoooX, XoooX, oXoXo, ooXoo, ooooo, ooooo },
    /* 'w'  */ { ooooo, ooooo, XoooX, XoooX, XoXoX, XoXoX, oXoXo, ooooo, ooooo },
    /* 'x'  */ { ooooo, ooooo, XoooX, oXoXo, ooXoo, oXoXo, XoooX, ooooo, ooooo },
    /* 'y'  */ { ooooo, ooooo, XoooX, XoooX, XoooX, XoooX, oXXXX, ooooX, oXXXo },
    /* 'z'  */ { ooooo, ooooo, XXXXX, oooXo, ooXoo, oXooo, XXXXX, ooooo, ooooo },
    /* '{'  */ { oooXX, ooXoo, ooXoo, oXooo, ooXoo, ooXoo, oooXX, ooooo, ooooo },
    /* '|'  */ { ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooXoo, ooooo, ooooo },
    /* '}'  */ { XXooo, ooXoo, ooXoo, oooXo, ooXoo, ooXoo, XXooo, ooooo, ooooo },
    /* '~'  */ { ooooo, ooooo, oXooo, XoXoX, oooXo, ooooo, ooooo, ooooo, ooooo },
};

static int is_continuation(unsigned char c) { return c >= 0x80 && c < 0xC0; }

const uint8_t *mkr_font_glyph(int ch)
{
    if (ch == '\t') ch = ' ';
    if (ch < 32 || ch > 126) ch = '?';
    return glyphs[ch - 32];
}

void mkr_text_box(const char *text, int scale, int *width, int *height)
{
    if (scale < 1) scale = 1;
    int lines = 1, longest = 0, column = 0;
    for (const unsigned char *s = (const unsigned char *)(text ? text : ""); *s; s++) {
        if (*s == '\n') {
            lines++;
            column = 0;
            continue;
        }
        if (is_continuation(*s)) continue;
        if (++column > longest) longest = column;
    }
    int w = longest ? longest * MKR_FONT_ADVANCE - 1 : 0;
    int h = lines * MKR_FONT_LINE - 1;
    if (width) *width = (w + 2 * MKR_FONT_PADDING) * scale;
    if (height) *height = (h + 2 * MKR_FONT_PADDING) * scale;
}

void mkr_draw_text(mkr_image *img, int x, int y, const char *text, int scale, const uint8_t fg[4], const uint8_t bg[4])
{
    if (!img || !img->pixels || !text) return;
    if (scale < 1) scale = 1;
    if (bg) {
        int w, h;
        mkr_text_box(text, scale, &w, &h);
        mkr_image_fill_rect(img, x, y, w, h, bg);
    }
    int pen_x = x + MKR_FONT_PADDING * scale, pen_y = y + MKR_FONT_PADDING * scale;
    for (const unsigned char *s = (const unsigned char *)text; *s; s++) {
        if (*s == '\n') {
            pen_x = x + MKR_FONT_PADDING * scale;
            pen_y += MKR_FONT_LINE * scale;
            continue;
        }
        if (is_continuation(*s)) continue;
        const uint8_t *g = mkr_font_glyph(*s);
        for (int row = 0; row < MKR_FONT_HEIGHT; row++)
            for (int col = 0; col < MKR_FONT_WIDTH; col++)
                if (g[row] & (0x10 >> col))
                    mkr_image_fill_rect(img, pen_x + col * scale, pen_y + row * scale, scale, scale, fg);
        pen_x += MKR_FONT_ADVANCE * scale;
    }
}

/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "colormap.h"
#include "font.h"

/* Oklab to linear sRGB: the published Oklab matrices (via the LMS cone-like space). */
static void oklab_to_linear(double L, double a, double b, double rgb[3])
{
    double l = L + 0.3963377774 * a + 0.2158037573 * b;
    double m = L - 0.1055613458 * a - 0.0638541728 * b;
    double s = L - 0.0894841775 * a - 1.2914855480 * b;
    l = l * l * l, m = m * m * m, s = s * s * s;
    rgb[0] = 4.0767416621 * l - 3.3077115913 * m + 0.2309699292 * s;
    rgb[1] = -1.2684380046 * l + 2.6097574011 * m - 0.3413193965 * s;
    rgb[2] = -0.0041960863 * l - 0.7034186147 * m + 1.7076147010 * s;
}

static int in_gamut(const double rgb[3])
{
    return rgb[0] >= 0 && rgb[0] <= 1 && rgb[1] >= 0 && rgb[1] <= 1 && rgb[2] >= 0 && rgb[2] <= 1;
}

/* Linear to the sRGB transfer curve, 8 bits. */
static uint8_t encode_srgb(double v)
{
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
    return (uint8_t)lround(v * 255);
}

void mkr_colormap(float t, uint8_t rgb[3])
{
    double u = !(t < 1) ? 1 : t > 0 ? t : 0;
    const double pi = 3.14159265358979323846;
    double L = 0.27 + (0.93 - 0.27) * u;
    double hue = (300 - 195 * u) * pi / 180;
    double chroma = 0.105 + (0.17 - 0.105) * u * u;
    double lin[3];
    oklab_to_linear(L, chroma * cos(hue), chroma * sin(hue), lin);
    if (!in_gamut(lin)) {
        /* The largest chroma sRGB can show at this lightness and hue (chroma 0, gray, always can). */
        double ok = 0, bad = chroma;
        for (int i = 0; i < 24; i++) {
            double mid = 0.5 * (ok + bad);
            oklab_to_linear(L, mid * cos(hue), mid * sin(hue), lin);
            if (in_gamut(lin)) ok = mid;
            else bad = mid;
        }
        oklab_to_linear(L, ok * cos(hue), ok * sin(hue), lin);
    }
    for (int i = 0; i < 3; i++) rgb[i] = encode_srgb(lin[i]);
}

void mkr_colormap_table(uint8_t table[3 * MKR_COLORMAP_SIZE])
{
    for (int i = 0; i < MKR_COLORMAP_SIZE; i++) mkr_colormap((float)i / (MKR_COLORMAP_SIZE - 1), table + 3 * i);
}

static int text_scale(const mkr_legend *legend) { return legend->text_scale < 1 ? 1 : legend->text_scale; }

static int bar_height(const mkr_legend *legend)
{
    return legend->bar_height > 0 ? legend->bar_height : 12 * text_scale(legend);
}

int mkr_legend_height(const mkr_legend *legend)
{
    int s = text_scale(legend), line;
    mkr_text_box("0", s, NULL, &line);
    int h = bar_height(legend) + 3 * s + line;   /* bar, tick marks, first label row */
    if (legend->caption) {
        int caption;
        mkr_text_box(legend->caption, s, NULL, &caption);
        h += caption;
    }
    if (legend->second_scale > 0) h += line;
    return h;
}

/* Draws label centered on x_center, kept within [left, right). */
static void draw_label(mkr_image *img, int x_center, int y, int left, int right, const char *label, int scale,
                       const uint8_t color[4])
{
    int w;
    mkr_text_box(label, scale, &w, NULL);
    int x = x_center - w / 2;
    if (x + w > right) x = right - w;
    if (x < left) x = left;
    mkr_draw_text(img, x, y, label, scale, color, NULL);
}

void mkr_legend_draw(mkr_image *img, int x, int y, int width, const mkr_legend *legend, const uint8_t color[4])
{
    if (!img || !legend || width < 2) return;
    int s = text_scale(legend), line;
    mkr_text_box("0", s, NULL, &line);
    if (legend->caption) {
        int h;
        mkr_text_box(legend->caption, s, NULL, &h);
        mkr_draw_text(img, x, y, legend->caption, s, color, NULL);
        y += h;
    }
    /* The bar, inset by the text padding so it lines up with the caption's letters. */
    int pad = MKR_FONT_PADDING * s, bar_x = x + pad, bar_w = width - 2 * pad, bar_h = bar_height(legend);
    if (bar_w < 2) bar_x = x, bar_w = width;
    for (int i = 0; i < bar_w; i++) {
        uint8_t rgba[4] = { 0, 0, 0, 255 };
        mkr_colormap((float)i / (float)(bar_w - 1), rgba);
        mkr_image_fill_rect(img, bar_x + i, y, 1, bar_h, rgba);
    }
    y += bar_h;
    int ticks = legend->ticks < 2 ? 2 : legend->ticks;
    for (int k = 0; k < ticks; k++) {
        double f = (double)k / (ticks - 1);
        int tx = bar_x + (int)lround(f * (bar_w - 1));
        mkr_image_fill_rect(img, tx - (s - 1) / 2, y, s, 3 * s, color);
        double value = legend->lo + f * ((double)legend->hi - legend->lo);
        char label[64];
        snprintf(label, sizeof label, "%.3g%s", value, legend->suffix ? legend->suffix : "");
        draw_label(img, tx, y + 3 * s, x, x + width, label, s, color);
        if (legend->second_scale > 0) {
            snprintf(label, sizeof label, "%.3g%s", value * legend->second_scale,
                     legend->second_suffix ? legend->second_suffix : "");
            draw_label(img, tx, y + 3 * s + line, x, x + width, label, s, color);
        }
    }
}

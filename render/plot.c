/* SPDX-License-Identifier: MIT */
#include "plot.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "font.h"

void mkr_draw_line(mkr_image *img, int x0, int y0, int x1, int y1, const uint8_t rgba[4], int dash)
{
    int dx = abs(x1 - x0), dy = -abs(y1 - y0), sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1, e = dx + dy;
    for (int step = 0;; step++) {
        uint8_t *p = mkr_image_pixel(img, x0, y0);
        if (p && (dash <= 0 || (step / dash) % 2 == 0))
            for (int c = 0; c < 4; c++) p[c] = rgba[c];
        if (x0 == x1 && y0 == y1) break;
        int e2 = 2 * e;
        if (e2 >= dy) { e += dy; x0 += sx; }
        if (e2 <= dx) { e += dx; y0 += sy; }
    }
}

void mkr_plot_draw(mkr_image *img, int x, int y, int width, int height, const mkr_plot *p)
{
    static const uint8_t panel[4] = { 32, 34, 40, 255 }, axis[4] = { 170, 170, 170, 255 },
                         text[4] = { 230, 230, 230, 255 }, limit_color[4] = { 235, 110, 80, 255 },
                         mark_color[4] = { 120, 160, 230, 255 }, curve_color[4] = { 250, 220, 90, 255 };
    mkr_image_fill_rect(img, x, y, width, height, panel);
    mkr_draw_text(img, x + 6, y + 4, p->title ? p->title : "", 1, text, panel);
    /* Plot area: room for y labels on the left, x labels below. */
    const int left = x + 64, right = x + width - 10, top = y + 22, bottom = y + height - 20;
    if (right - left < 10 || bottom - top < 10) return;
    double top_value = p->limit > 0 ? p->limit : 0;
    for (uint32_t k = 0; p->values && k < p->count; k++)
        if (isfinite(p->values[k]) && p->values[k] > top_value) top_value = p->values[k];
    if (!(top_value > 0)) top_value = 1;
    top_value *= 1.1;
    mkr_draw_line(img, left, bottom, right, bottom, axis, 0);
    mkr_draw_line(img, left, top, left, bottom, axis, 0);
    static const char *const x_ticks[3] = { "0", "0.5", "1" };
    for (int t = 0; t <= 2; t++) {
        int px = left + (int)lround((right - left) * t / 2.0), w, h;
        mkr_draw_line(img, px, bottom, px, bottom + 3, axis, 0);
        mkr_text_box(x_ticks[t], 1, &w, &h);
        mkr_draw_text(img, px - w / 2, bottom + 5, x_ticks[t], 1, text, panel);
    }
    char s[64];
    const char *unit = p->unit ? p->unit : "";
    double scale = p->label_scale > 0 ? p->label_scale : 1;
    double ticks[3] = { 0, p->limit, top_value };
    for (int t = 0; t < 3; t++) {    /* y ticks: 0, the limit, the top */
        if (t == 1 && !(p->limit > 0)) continue;
        int py = bottom - (int)lround((bottom - top) * ticks[t] / top_value);
        mkr_draw_line(img, left - 3, py, left, py, axis, 0);
        snprintf(s, sizeof s, "%.3g%s", ticks[t] * scale, unit);
        int w, h;
        mkr_text_box(s, 1, &w, &h);
        mkr_draw_text(img, left - 5 - w, py - h / 2, s, 1, t == 1 ? limit_color : text, panel);
    }
    if (p->limit > 0) {
        int py = bottom - (int)lround((bottom - top) * p->limit / top_value);
        mkr_draw_line(img, left + 1, py, right, py, limit_color, 4);
    }
    for (uint32_t k = 0; k < p->mark_count; k++) {
        double m = p->marks[k] < 0 ? 0 : p->marks[k] > 1 ? 1 : p->marks[k];
        int px = left + (int)lround((right - left) * m);
        mkr_draw_line(img, px, top, px, bottom - 1, mark_color, 2);
    }
    if (!p->values || p->count < 2) {
        if (p->note) mkr_draw_text(img, left + 8, top + 8, p->note, 1, text, panel);
        return;
    }
    int px0 = 0, py0 = 0;
    for (uint32_t k = 0; k < p->count; k++) {
        double v = isfinite(p->values[k]) ? p->values[k] : top_value;
        int px = left + (int)lround((right - left) * (double)k / (double)(p->count - 1));
        int py = bottom - (int)lround((bottom - top) * v / top_value);
        if (k) mkr_draw_line(img, px0, py0, px, py, curve_color, 0);
        px0 = px;
        py0 = py;
    }
}

const uint8_t *mkr_series_color(uint32_t i)
{
    static const uint8_t palette[6][4] = { { 250, 220, 90, 255 }, { 110, 190, 250, 255 }, { 240, 120, 110, 255 },
                                           { 140, 220, 130, 255 }, { 210, 150, 240, 255 }, { 240, 170, 80, 255 } };
    return palette[i % 6];
}

void mkr_lines_draw(mkr_image *img, int x, int y, int width, int height, const mkr_lines *p)
{
    static const uint8_t panel[4] = { 32, 34, 40, 255 }, axis[4] = { 170, 170, 170, 255 },
                         text[4] = { 230, 230, 230, 255 };
    mkr_image_fill_rect(img, x, y, width, height, panel);
    mkr_draw_text(img, x + 6, y + 4, p->title ? p->title : "", 1, text, panel);
    const int left = x + 64, right = x + width - 10, top = y + 22, bottom = y + height - 32;
    if (right - left < 10 || bottom - top < 10) return;
    uint32_t longest = 2;
    double y_max = p->y_max;
    for (uint32_t i = 0; i < p->series_count; i++) {
        const mkr_series *c = &p->series[i];
        if (c->count > longest) longest = c->count;
        for (uint32_t k = 0; p->y_max <= 0 && c->values && k < c->count; k++)
            if (isfinite(c->values[k]) && c->values[k] * 1.1 > y_max) y_max = c->values[k] * 1.1;
    }
    if (!(y_max > 0)) y_max = 1;
    const double x_end = longest - 1;
    mkr_draw_line(img, left, bottom, right, bottom, axis, 0);
    mkr_draw_line(img, left, top, left, bottom, axis, 0);
    char s[64];
    int w, h;
    for (int t = 0; t <= 2; t++) {
        int px = left + (int)lround((right - left) * t / 2.0);
        double v = x_end * t / 2.0 * (p->x_scale > 0 ? p->x_scale : 1);
        snprintf(s, sizeof s, "%.3g", v);
        mkr_draw_line(img, px, bottom, px, bottom + 3, axis, 0);
        mkr_text_box(s, 1, &w, &h);
        mkr_draw_text(img, px - w / 2, bottom + 5, s, 1, text, panel);
        int py = bottom - (int)lround((bottom - top) * t / 2.0);
        snprintf(s, sizeof s, "%.3g", y_max * t / 2.0);
        mkr_draw_line(img, left - 3, py, left, py, axis, 0);
        mkr_text_box(s, 1, &w, &h);
        mkr_draw_text(img, left - 5 - w, py - h / 2, s, 1, text, panel);
    }
    if (p->x_label) {
        mkr_text_box(p->x_label, 1, &w, &h);
        mkr_draw_text(img, (left + right - w) / 2, bottom + 18, p->x_label, 1, text, panel);
    }
    if (p->y_label) mkr_draw_text(img, left + 6, top + 2, p->y_label, 1, text, panel);
    int legend_y = top + 4;
    for (uint32_t i = 0; i < p->series_count; i++) {
        const mkr_series *c = &p->series[i];
        const uint8_t *color = mkr_series_color(i);
        int px0 = 0, py0 = 0;
        for (uint32_t k = 0; c->values && k < c->count; k++) {
            double v = isfinite(c->values[k]) ? c->values[k] : 0;
            int px = left + (int)lround((right - left) * (double)k / x_end);
            int py = bottom - (int)lround((bottom - top) * (v < y_max ? v : y_max) / y_max);
            if (k) mkr_draw_line(img, px0, py0, px, py, color, 0);
            px0 = px;
            py0 = py;
        }
        for (uint32_t k = 0; c->values && k < c->mark_count; k++) {
            if (c->marks[k] >= c->count) continue;
            double v = isfinite(c->values[c->marks[k]]) ? c->values[c->marks[k]] : 0;
            int px = left + (int)lround((right - left) * (double)c->marks[k] / x_end);
            int py = bottom - (int)lround((bottom - top) * (v < y_max ? v : y_max) / y_max);
            mkr_image_fill_rect(img, px - 2, py - 2, 5, 5, color);
        }
        if (c->label) {
            mkr_text_box(c->label, 1, &w, &h);
            mkr_image_fill_rect(img, right - w - 22, legend_y + h / 2 - 1, 14, 3, color);
            mkr_draw_text(img, right - w - 4, legend_y, c->label, 1, color, panel);
            legend_y += h + 4;
        }
    }
}

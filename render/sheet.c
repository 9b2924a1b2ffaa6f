/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "colormap.h"
#include "alloc.h"
#include "font.h"
#include "sheet.h"

#define DEFAULT_CELL 320
#define FRAME_MARGIN 0.06f     /* empty fraction of the viewport around the framed bounds */

static const uint8_t sheet_gutter[4] = { 72, 74, 80, 255 };
static const uint8_t title_background[4] = { 18, 19, 22, 255 };
static const uint8_t text_color[4] = { 236, 236, 236, 255 };
static const uint8_t label_background[4] = { 0, 0, 0, 150 };
/* Shaded sheets: dark cells so the lit meshes stand out. Diff sheets: mid gray, so both the
 * dark cold end and the light hot end of the ramp stand out. */
static const uint8_t cell_background[4] = { 38, 40, 45, 255 };
static const uint8_t diff_background[4] = { 112, 114, 120, 255 };
/* Base colors of a cell's meshes, by index within the cell. */
static const uint8_t mesh_colors[][3] = {
    { 200, 196, 188 }, { 140, 180, 220 }, { 222, 168, 132 }, { 160, 204, 150 }, { 204, 160, 208 }, { 214, 204, 130 },
};
/* Diff sheets light the ramp colors only this much (0 full light, 1 none). */
#define DIFF_UNLIT 0.6f

static int line_count(const char *text)
{
    int n = 1;
    for (; *text; text++) n += *text == '\n';
    return n;
}

static int label_lines(const mkr_cell *cell, int diff)
{
    return (isfinite(cell->time) ? 1 : 0) + (diff ? 1 : 0) + (cell->text && *cell->text ? line_count(cell->text) : 0);
}

int mkr_sheet_layout_get(const mkr_sheet_desc *desc, int diff, mkr_sheet_layout *layout)
{
    memset(layout, 0, sizeof *layout);
    if (!desc || !desc->cells || desc->cell_count == 0 || desc->cell_width < 0 || desc->cell_height < 0 ||
        desc->columns < 0 || desc->text_scale < 0)
        return 0;
    mkr_sheet_layout l = { 0 };
    l.cell_width = desc->cell_width ? desc->cell_width : DEFAULT_CELL;
    l.cell_height = desc->cell_height ? desc->cell_height : DEFAULT_CELL;
    l.columns = desc->columns;
    if (l.columns == 0) l.columns = (int)ceil(sqrt((double)desc->cell_count));
    if ((uint32_t)l.columns > desc->cell_count) l.columns = (int)desc->cell_count;
    l.rows = (int)((desc->cell_count + (uint32_t)l.columns - 1) / (uint32_t)l.columns);
    l.text_scale = desc->text_scale ? desc->text_scale : l.cell_width >= 384 ? 2 : 1;
    if (l.text_scale > 16) l.text_scale = 16;
    const int s = l.text_scale;
    if (desc->title) {
        mkr_text_box(desc->title, s, NULL, &l.title_height);
        l.title_height += 4 * s;
    }
    int lines = 0;
    for (uint32_t i = 0; i < desc->cell_count; i++) {
        int n = label_lines(&desc->cells[i], diff);
        if (n > lines) lines = n;
    }
    if (lines > 100000) lines = 100000;  /* far beyond any cell; keeps the sizes in int */
    if (lines) /* mkr_text_box's height for that many lines, and 2 pixels above and below */
        l.label_height = (lines * MKR_FONT_LINE - 1 + 2 * MKR_FONT_PADDING) * s + 4;
    if (diff) {
        mkr_legend legend = { .caption = "0", .second_scale = 1, .text_scale = s };
        l.legend_height = mkr_legend_height(&legend) + 8 * s;
    }
    /* In 64 bits: a hostile desc must not wrap. */
    long long w = (long long)l.columns * (l.cell_width + MKR_SHEET_GUTTER) + MKR_SHEET_GUTTER;
    long long h = (long long)l.title_height + (long long)l.rows * (l.cell_height + MKR_SHEET_GUTTER) +
                  MKR_SHEET_GUTTER + l.legend_height;
    l.width = w > MKR_IMAGE_MAX_SIDE + 1 ? MKR_IMAGE_MAX_SIDE + 1 : (int)w;
    l.height = h > MKR_IMAGE_MAX_SIDE + 1 ? MKR_IMAGE_MAX_SIDE + 1 : (int)h;
    *layout = l;
    return 1;
}

void mkr_sheet_cell_rect(const mkr_sheet_layout *layout, uint32_t index, int rect[4])
{
    int column = (int)(index % (uint32_t)layout->columns), row = (int)(index / (uint32_t)layout->columns);
    rect[0] = MKR_SHEET_GUTTER + column * (layout->cell_width + MKR_SHEET_GUTTER);
    rect[1] = layout->title_height + MKR_SHEET_GUTTER + row * (layout->cell_height + MKR_SHEET_GUTTER);
    rect[2] = layout->cell_width;
    rect[3] = layout->cell_height;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Fewest decimals (2 to 6) at which distinct cell times get distinct labels: sorted, only
 * neighbors can clash. Returns -1 when out of memory. */
static int time_decimals(const mkr_sheet_desc *desc)
{
    double *times = malloc(desc->cell_count * sizeof *times);
    if (!times) return -1;
    size_t n = 0;
    for (uint32_t i = 0; i < desc->cell_count; i++)
        if (isfinite(desc->cells[i].time)) times[n++] = desc->cells[i].time;
    qsort(times, n, sizeof *times, by_value);
    int d = 2;
    for (; d < 6; d++) {
        int clash = 0;
        for (size_t i = 1; i < n && !clash; i++) {
            if (times[i] == times[i - 1]) continue;
            char a[48], b[48];
            snprintf(a, sizeof a, "%.*f", d, times[i - 1]);
            snprintf(b, sizeof b, "%.*f", d, times[i]);
            clash = strcmp(a, b) == 0;
        }
        if (!clash) break;
    }
    free(times);
    return d;
}

/* Largest finite scalar of a cell and where it is (value 0, mesh -1 when none is above 0). */
typedef struct hottest {
    float value;
    int64_t mesh, vertex;
} hottest;

static hottest cell_hottest(const mkr_cell *cell)
{
    hottest h = { 0, -1, -1 };
    for (uint32_t k = 0; k < cell->mesh_count; k++) {
        const mkr_mesh_view *mesh = &cell->meshes[k];
        for (uint32_t v = 0; v < mesh->vertex_count; v++)
            if (mesh->scalars[v] > h.value && isfinite(mesh->scalars[v])) h = (hottest){ mesh->scalars[v], k, v };
    }
    return h;
}

/* A ring of radius r (pixels, thickness t) centered at (cx, cy) in rgba, within the clip
 * rectangle, outlined in black for contrast on any color. */
static void draw_ring(mkr_image *img, float cx, float cy, float r, float t, const uint8_t rgba[4], const int clip[4])
{
    static const uint8_t outline[4] = { 0, 0, 0, 255 };
    float outer = r + t + 1;
    int x0 = (int)floorf(cx - outer), x1 = (int)ceilf(cx + outer), y0 = (int)floorf(cy - outer), y1 = (int)ceilf(cy + outer);
    if (x0 < clip[0]) x0 = clip[0];
    if (y0 < clip[1]) y0 = clip[1];
    if (x1 > clip[0] + clip[2] - 1) x1 = clip[0] + clip[2] - 1;
    if (y1 > clip[1] + clip[3] - 1) y1 = clip[1] + clip[3] - 1;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            float dx = (float)x + 0.5f - cx, dy = (float)y + 0.5f - cy, d = sqrtf(dx * dx + dy * dy);
            if (d >= r - 1 && d <= r + t + 1)
                mkr_image_fill_rect(img, x, y, 1, 1, d >= r && d <= r + t ? rgba : outline);
        }
}

static mk_result render(const mkr_sheet_desc *desc, int diff, mkr_image *out, mk_error *err)
{
    if (!out) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "sheet: NULL output image");
    memset(out, 0, sizeof *out);
    mkr_sheet_layout l;
    if (!mkr_sheet_layout_get(desc, diff, &l))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "sheet: no cells, or a negative size, column count or text scale");
    const char *what = diff ? "diff sheet" : "sheet";
    for (uint32_t i = 0; i < desc->cell_count; i++) {
        const mkr_cell *cell = &desc->cells[i];
        if (cell->mesh_count && !cell->meshes)
            return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%s: cell %u has %u meshes but no array", what, i,
                                 cell->mesh_count);
        for (uint32_t k = 0; k < cell->mesh_count; k++) {
            const mkr_mesh_view *m = &cell->meshes[k];
            if (m->vertex_count && !m->positions)
                return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%s: cell %u mesh %u has no positions", what, i, k);
            if (diff && m->vertex_count && !m->scalars)
                return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "diff sheet: cell %u mesh %u has no scalars", i, k);
        }
    }
    if (l.width > MKR_IMAGE_MAX_SIDE || l.height > MKR_IMAGE_MAX_SIDE)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: %u cells of %dx%d need more than %d pixels a side", what,
                             desc->cell_count, l.cell_width, l.cell_height, MKR_IMAGE_MAX_SIDE);
    if (l.cell_height - l.label_height < 8)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%s: cells %d pixels tall leave no room under %d-pixel labels",
                             what, l.cell_height, l.label_height);
    mk_result r = mkr_image_create(out, l.width, l.height, err);
    if (r != MK_OK) return r;
    mkr_image_clear(out, sheet_gutter);
    const int s = l.text_scale;

    /* The union bounding box gives the diagonal the diff legend relates distances to. */
    float lo[3], hi[3];
    mkr_bounds_reset(lo, hi);
    for (uint32_t i = 0; i < desc->cell_count; i++)
        for (uint32_t k = 0; k < desc->cells[i].mesh_count; k++)
            mkr_bounds_add(lo, hi, desc->cells[i].meshes[k].positions, desc->cells[i].meshes[k].vertex_count);
    double diagonal = 0;
    if (lo[0] <= hi[0])
        diagonal = sqrt(((double)hi[0] - lo[0]) * ((double)hi[0] - lo[0]) + ((double)hi[1] - lo[1]) * ((double)hi[1] - lo[1]) +
                        ((double)hi[2] - lo[2]) * ((double)hi[2] - lo[2]));
    /* One camera for every cell, framed on the points of all frames: motion shows. */
    mkr_camera cam = { 0 };
    mkr_camera_set_view(&cam, desc->view);
    float ext_lo[3], ext_hi[3];
    mkr_bounds_reset(ext_lo, ext_hi);
    for (uint32_t i = 0; i < desc->cell_count; i++)
        for (uint32_t k = 0; k < desc->cells[i].mesh_count; k++)
            mkr_camera_extent_add(&cam, ext_lo, ext_hi, desc->cells[i].meshes[k].positions,
                                  desc->cells[i].meshes[k].vertex_count);
    mkr_camera_frame_extent(&cam, ext_lo, ext_hi, 0, 0, l.cell_width, l.cell_height - l.label_height, FRAME_MARGIN);

    uint8_t ramp[3 * MKR_COLORMAP_SIZE];
    float scale_max = 0;
    if (diff) {
        mkr_colormap_table(ramp);
        scale_max = desc->diff_max;
        if (!(scale_max > 0))
            for (uint32_t i = 0; i < desc->cell_count; i++) {
                float m = cell_hottest(&desc->cells[i]).value;
                if (m > scale_max) scale_max = m;
            }
    }

    if (l.title_height) {
        mkr_image_fill_rect(out, 0, 0, l.width, l.title_height, title_background);
        mkr_draw_text(out, 2 * s, 2 * s, desc->title, s, text_color, NULL);
    }

    const int decimals = time_decimals(desc);
    if (decimals < 0) r = mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "%s: out of memory for %u times", what, desc->cell_count);
    for (uint32_t i = 0; i < desc->cell_count && r == MK_OK; i++) {
        const mkr_cell *cell = &desc->cells[i];
        int rect[4];
        mkr_sheet_cell_rect(&l, i, rect);
        mkr_image_fill_rect(out, rect[0], rect[1], rect[2], rect[3], diff ? diff_background : cell_background);
        mkr_camera c = cam;
        c.x = rect[0], c.y = rect[1] + l.label_height;
        for (uint32_t k = 0; k < cell->mesh_count && r == MK_OK; k++) {
            mkr_style style = mkr_style_default();
            memcpy(style.color, mesh_colors[k % (sizeof mesh_colors / sizeof mesh_colors[0])], 3);
            if (diff) {
                style.ramp = ramp;
                style.scalar_lo = 0;
                style.scalar_hi = scale_max;
                style.unlit = DIFF_UNLIT;
            }
            r = mkr_draw_mesh(out, &c, &cell->meshes[k], &style, err);
        }
        if (r != MK_OK) break;
        hottest hot = { 0, -1, -1 };
        if (diff) {
            /* Ring the hottest vertex, drawn over the surface so even a hidden or single
             * moved vertex is found; the ring has the vertex's ramp color. */
            hot = cell_hottest(cell);
            if (hot.mesh >= 0) {
                float p[3];
                mkr_camera_project(&c, cell->meshes[hot.mesh].positions + 3 * hot.vertex, p);
                float f = scale_max > 0 ? hot.value / scale_max : 1;
                uint8_t rgba[4] = { 0, 0, 0, 255 };
                mkr_colormap(f, rgba);
                int clip[4] = { c.x, c.y, c.width, c.height };
                draw_ring(out, p[0], p[1], 6.0f * (float)s, (float)s, rgba, clip);
            }
        }

        /* The label: time, diff maximum, the cell's own lines. */
        size_t text_len = cell->text ? strlen(cell->text) : 0;
        char *label = malloc(text_len + 192);  /* time 64, maximum 112 */
        if (!label) {
            r = mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "%s: out of memory for a label", what);
            break;
        }
        label[0] = 0;
        if (isfinite(cell->time)) snprintf(label, 64, "t=%.*f s", decimals, cell->time);
        if (diff) {
            size_t n = strlen(label);
            char where[48] = "";
            if (hot.mesh >= 0 && cell->mesh_count > 1)
                snprintf(where, sizeof where, " at m%lld v%lld", (long long)hot.mesh, (long long)hot.vertex);
            else if (hot.mesh >= 0)
                snprintf(where, sizeof where, " at v%lld", (long long)hot.vertex);
            if (desc->scalar_caption)
                snprintf(label + n, 112, "%smax %.3g%.8s%s", n ? "\n" : "", hot.value,
                         desc->scalar_suffix ? desc->scalar_suffix : "", where);
            else if (diagonal > 0)
                snprintf(label + n, 112, "%smax %.3g (%.3g%%)%s", n ? "\n" : "", hot.value, 100.0 * hot.value / diagonal, where);
            else
                snprintf(label + n, 112, "%smax %.3g%s", n ? "\n" : "", hot.value, where);
        }
        if (text_len) {
            if (label[0]) strcat(label, "\n");
            strcat(label, cell->text);
        }
        if (label[0]) mkr_draw_text(out, rect[0] + 2, rect[1] + 2, label, s, text_color, label_background);
        free(label);
    }
    if (r == MK_OK && diff) {
        char caption[160];
        const int distances = !desc->scalar_caption;
        if (!distances)
            snprintf(caption, sizeof caption, "%.150s", desc->scalar_caption);
        else if (diagonal > 0)
            snprintf(caption, sizeof caption, "distance: mesh units, and %% of the bounding-box diagonal (%.4g)", diagonal);
        else
            snprintf(caption, sizeof caption, "distance: mesh units");
        mkr_image_fill_rect(out, 0, l.height - l.legend_height, l.width, l.legend_height, title_background);
        int pad = 4 * s, width = l.width - 2 * pad;
        if (width > 640 * s) width = 640 * s;
        int caption_width;
        mkr_text_box(caption, s, &caption_width, NULL);
        if (caption_width > width && diagonal > 0 && distances) /* a narrow sheet: the short form */
            snprintf(caption, sizeof caption, "distance (%% of diagonal %.4g)", diagonal);
        /* Labels like "0.000148%" are 9 characters: keep a tick per 80 font pixels. */
        int ticks = 1 + width / (80 * s);
        if (ticks > 5) ticks = 5;
        mkr_legend legend = { .lo = 0, .hi = scale_max, .ticks = ticks, .caption = caption, .text_scale = s,
                              .suffix = distances ? NULL : desc->scalar_suffix,
                              .second_scale = diagonal > 0 && distances ? (float)(100.0 / diagonal) : 0,
                              .second_suffix = "%" };
        mkr_legend_draw(out, pad, l.height - l.legend_height + pad, width, &legend, text_color);
    }
    if (r != MK_OK) mkr_image_destroy(out);
    return r;
}

mk_result mkr_sheet_render(const mkr_sheet_desc *desc, mkr_image *out, mk_error *err)
{
    return render(desc, 0, out, err);
}

mk_result mkr_diff_sheet_render(const mkr_sheet_desc *desc, mkr_image *out, mk_error *err)
{
    return render(desc, 1, out, err);
}

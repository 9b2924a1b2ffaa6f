/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "conform_report.h"
#include "pictures.h"

/* Panels of a frame's picture: modest, so a report of many frames stays small. */
#define PANEL 240

/* One compared mesh, copied out of the conformance check. */
typedef struct kept_mesh {
    uint32_t mesh, vertex_count;
    float *played, *played_normals, *reference, *reference_normals, *distance;
} kept_mesh;

/* One row of the table. */
typedef struct report_row {
    char case_name[128], frame[128], time[32], where[160], failure[512];
    int passed, has_picture;
    double error, allowed, normal_error;
    int normals_compared;
} report_row;

struct cli_report {
    const cli_verb *verb;
    const char *dir, *manifest;
    kept_mesh *meshes;
    uint32_t mesh_count, mesh_capacity;
    int out_of_memory;
    report_row *rows;
    mkr_png *pngs;  /* per row; empty where the frame has no picture */
    uint32_t row_count, row_capacity;
};

int cli_report_begin(const cli_verb *verb, const char *dir, const char *manifest, cli_report **out)
{
    *out = NULL;
    struct stat st;
    if (stat(dir, &st) == 0 && !S_ISDIR(st.st_mode))
        return cli_usage_error(verb, "--report %s: exists and is not a folder", dir);
    if (stat(dir, &st) != 0 && mkdir(dir, 0777) != 0) {
        fprintf(stderr, "morphkit %s: --report %s: cannot create the folder: %s\n", verb->name, dir, strerror(errno));
        return CLI_EXIT_FAILURE;
    }
    cli_report *r = calloc(1, sizeof *r);
    if (!r) {
        fprintf(stderr, "morphkit %s: out of memory\n", verb->name);
        return CLI_EXIT_FAILURE;
    }
    r->verb = verb;
    r->dir = dir;
    r->manifest = manifest;
    *out = r;
    return -1;
}

static void drop_meshes(cli_report *r)
{
    for (uint32_t i = 0; i < r->mesh_count; i++) {
        kept_mesh *k = &r->meshes[i];
        free(k->played);
        free(k->played_normals);
        free(k->reference);
        free(k->reference_normals);
        free(k->distance);
    }
    r->mesh_count = 0;
}

static void on_mesh(void *user, const pb_compared_mesh *cm)
{
    cli_report *r = user;
    if (r->mesh_count == r->mesh_capacity) {
        uint32_t cap = r->mesh_capacity ? 2 * r->mesh_capacity : 4;
        kept_mesh *grown = realloc(r->meshes, cap * sizeof *grown);
        if (!grown) { r->out_of_memory = 1; return; }
        r->meshes = grown;
        r->mesh_capacity = cap;
    }
    size_t n = 3 * (size_t)cm->vertex_count + 3;
    kept_mesh k = { cm->mesh, cm->vertex_count, malloc(4 * n), cm->normals ? malloc(4 * n) : NULL, malloc(4 * n),
                    cm->reference_normals ? malloc(4 * n) : NULL, malloc(4 * (size_t)cm->vertex_count + 4) };
    r->meshes[r->mesh_count++] = k;
    if (!k.played || (cm->normals && !k.played_normals) || !k.reference || (cm->reference_normals && !k.reference_normals) ||
        !k.distance) {
        r->out_of_memory = 1;
        return;
    }
    memcpy(k.played, cm->positions, 12 * (size_t)cm->vertex_count);
    if (cm->normals) memcpy(k.played_normals, cm->normals, 12 * (size_t)cm->vertex_count);
    for (uint32_t v = 0; v < cm->vertex_count; v++) {
        uint32_t p = cm->point ? cm->point[v] : v;
        for (int d = 0; d < 3; d++) {
            k.reference[3 * v + (uint32_t)d] = (float)cm->reference[3 * (size_t)p + (uint32_t)d];
            if (k.reference_normals) k.reference_normals[3 * v + (uint32_t)d] = (float)cm->reference_normals[3 * (size_t)p + (uint32_t)d];
        }
    }
    cli_distances(k.played, k.reference, cm->vertex_count, k.distance);
}

void cli_report_hook(cli_report *report, pb_conform_options *options)
{
    options->mesh_compared = on_mesh;
    options->user = report;
}

/* Copies src into dst with its top-left corner at (x, y) (clipped). */
static void paste(mkr_image *dst, const mkr_image *src, int x, int y)
{
    for (int j = 0; j < src->height && y + j < dst->height; j++) {
        int w = src->width < dst->width - x ? src->width : dst->width - x;
        if (w > 0) memcpy(mkr_image_pixel(dst, x, y + j), mkr_image_pixel(src, 0, j), 4 * (size_t)w);
    }
}

/* The frame's picture: played and reference shaded side by side, then the heat map. */
static mk_result draw_frame(cli_report *r, const mk_asset *a, const pb_frame_spec *f, mkr_png *png, mk_error *err)
{
    uint32_t n = r->mesh_count;
    mkr_mesh_view *views = calloc(3 * (size_t)n + 1, sizeof *views);
    if (!views) return mk_error_oom(err, "report views");
    for (uint32_t i = 0; i < n; i++) {
        const kept_mesh *k = &r->meshes[i];
        mk_mesh_info m;
        mk_mesh_get(a, k->mesh, &m);
        mkr_mesh_view base = { .vertex_count = k->vertex_count, .triangle_count = m.triangle_count,
                               .triangles = m.triangles };
        views[i] = base;
        views[i].positions = k->played;
        views[i].normals = k->played_normals;
        views[n + i] = base;
        views[n + i].positions = k->reference;
        views[n + i].normals = k->reference_normals;
        views[2 * n + i] = views[i];
        views[2 * n + i].scalars = k->distance;
    }
    double time = f->has_time && !f->forced ? f->time : NAN;
    mkr_cell shaded[2] = { { views, n, time, "morphkit" }, { views + n, n, time, "reference" } };
    mkr_cell heat = { views + 2 * n, n, time, "distance" };
    mkr_sheet_desc sd = { .cells = shaded, .cell_count = 2, .cell_width = PANEL, .cell_height = PANEL, .columns = 2,
                          .view = MKR_VIEW_ISO };
    mkr_sheet_desc dd = { .cells = &heat, .cell_count = 1, .cell_width = PANEL, .cell_height = PANEL, .view = MKR_VIEW_ISO };
    mkr_image a_img = { 0 }, d_img = { 0 }, all = { 0 };
    mk_result res = mkr_sheet_render(&sd, &a_img, err);
    if (res == MK_OK) res = mkr_diff_sheet_render(&dd, &d_img, err);
    if (res == MK_OK)
        res = mkr_image_create(&all, a_img.width + d_img.width, a_img.height > d_img.height ? a_img.height : d_img.height, err);
    if (res == MK_OK) {
        static const uint8_t gutter[4] = { 72, 74, 80, 255 };
        mkr_image_clear(&all, gutter);
        paste(&all, &a_img, 0, 0);
        paste(&all, &d_img, a_img.width, 0);
        res = mkr_png_encode(&all, png, err);
    }
    mkr_image_destroy(&a_img);
    mkr_image_destroy(&d_img);
    mkr_image_destroy(&all);
    free(views);
    return res;
}

int cli_report_frame(cli_report *r, const pb_case *c, const pb_frame_spec *f, const pb_frame_result *res,
                     const mk_asset *a)
{
    if (r->row_count == r->row_capacity) {
        uint32_t cap = r->row_capacity ? 2 * r->row_capacity : 16;
        report_row *rows = realloc(r->rows, cap * sizeof *rows);
        if (rows) r->rows = rows;
        mkr_png *pngs = rows ? realloc(r->pngs, cap * sizeof *pngs) : NULL;
        if (pngs) r->pngs = pngs;
        if (!rows || !pngs) {
            drop_meshes(r);
            fprintf(stderr, "morphkit %s: out of memory for the report\n", r->verb->name);
            return CLI_EXIT_FAILURE;
        }
        r->row_capacity = cap;
    }
    report_row *row = &r->rows[r->row_count];
    mkr_png *png = &r->pngs[r->row_count];
    memset(row, 0, sizeof *row);
    memset(png, 0, sizeof *png);
    r->row_count++;
    snprintf(row->case_name, sizeof row->case_name, "%s", c->name);
    snprintf(row->frame, sizeof row->frame, "%s", pb_frame_label(f));
    if (f->has_time && !f->forced) snprintf(row->time, sizeof row->time, "%g s", f->time);
    else snprintf(row->time, sizeof row->time, "static");
    row->passed = res->passed;
    row->error = res->position_error;
    row->allowed = res->relative_allowed > 0 && (!res->passed_by || !strcmp(res->passed_by, "relative_tolerance"))
                       ? res->relative_allowed : res->allowed;
    row->normal_error = res->normal_error_deg;
    row->normals_compared = res->normals_compared;
    snprintf(row->failure, sizeof row->failure, "%s", res->failure);
    if (res->worst_known && a) {
        mk_mesh_info m;
        mk_mesh_get(a, res->worst_mesh, &m);
        snprintf(row->where, sizeof row->where, "%.120s v%u", m.name, res->worst_vertex);
    }
    int status = -1;
    if (r->out_of_memory) {
        fprintf(stderr, "morphkit %s: out of memory for the report\n", r->verb->name);
        status = CLI_EXIT_FAILURE;
    } else if (a && r->mesh_count) {
        mk_error err;
        if (draw_frame(r, a, f, png, &err) != MK_OK) status = cli_fail(r->verb->name, &err);
        else row->has_picture = 1;
    }
    drop_meshes(r);
    r->out_of_memory = 0;
    return status;
}

/* Text with <, >, & and " escaped. */
static void html_text(FILE *f, const char *s)
{
    for (; *s; s++) {
        if (*s == '<') fputs("&lt;", f);
        else if (*s == '>') fputs("&gt;", f);
        else if (*s == '&') fputs("&amp;", f);
        else if (*s == '"') fputs("&quot;", f);
        else fputc(*s, f);
    }
}

static void write_html(const cli_report *r, FILE *f)
{
    uint32_t passed = 0;
    for (uint32_t i = 0; i < r->row_count; i++) passed += r->rows[i].passed != 0;
    fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Conformance: ", f);
    html_text(f, r->manifest);
    fputs("</title>\n<style>body{font-family:sans-serif;margin:1em 2em;background:#fafafa}table{border-collapse:collapse}"
          "td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}td.n{text-align:right;font-family:monospace}"
          ".fail{background:#fdd}.ok{background:#dfd}figure{margin:1em 0}figcaption{font-family:monospace}</style>\n"
          "</head><body>\n<h1>Conformance: ", f);
    html_text(f, r->manifest);
    fprintf(f, "</h1>\n<p>%u passed, %u failed. Error: the largest coordinate difference to the reference, in the "
               "reference's units; where: the mesh and vertex it is at. Pictures: the frame morphkit played and the "
               "reference, shaded with their normals, and the distance per vertex as a heat map (failing frames first).</p>\n",
            passed, r->row_count - passed);
    fputs("<table>\n<tr><th>case</th><th>frame</th><th>time</th><th>result</th><th>error</th><th>allowed</th>"
          "<th>where</th><th>normal</th><th>picture</th></tr>\n", f);
    for (uint32_t i = 0; i < r->row_count; i++) {
        const report_row *w = &r->rows[i];
        fprintf(f, "<tr class=\"%s\"><td>", w->passed ? "ok" : "fail");
        html_text(f, w->case_name);
        fputs("</td><td>", f);
        html_text(f, w->frame);
        fprintf(f, "</td><td>%s</td><td>%s", w->time, w->passed ? "pass" : "FAIL");
        if (w->failure[0]) {
            fputs(": ", f);
            html_text(f, w->failure);
        }
        fprintf(f, "</td><td class=\"n\">%.3g</td><td class=\"n\">%.3g</td><td>", w->error, w->allowed);
        html_text(f, w->where);
        if (w->normals_compared) fprintf(f, "</td><td class=\"n\">%.3g&deg;", w->normal_error);
        else fputs("</td><td>-", f);
        if (w->has_picture) fprintf(f, "</td><td><a href=\"#frame%04u\">frame_%04u.png</a></td></tr>\n", i, i);
        else fputs("</td><td>-</td></tr>\n", f);
    }
    fputs("</table>\n<h2>Pictures</h2>\n", f);
    for (int pass = 0; pass < 2; pass++)   /* failing frames first */
        for (uint32_t i = 0; i < r->row_count; i++) {
            const report_row *w = &r->rows[i];
            if (!w->has_picture || (w->passed != 0) != pass) continue;
            fprintf(f, "<figure id=\"frame%04u\"><img src=\"frame_%04u.png\" alt=\"", i, i);
            html_text(f, w->case_name);
            fputs(" ", f);
            html_text(f, w->frame);
            fprintf(f, "\"><figcaption>%s ", w->passed ? "pass" : "FAIL");
            html_text(f, w->case_name);
            fputs(" / ", f);
            html_text(f, w->frame);
            fprintf(f, " (%s): error %.3g, allowed %.3g</figcaption></figure>\n", w->time, w->error, w->allowed);
        }
    fputs("</body></html>\n", f);
}

int cli_report_finish(cli_report *r)
{
    uint32_t count = 1;
    for (uint32_t i = 0; i < r->row_count; i++) count += r->rows[i].has_picture != 0;
    mk_output *outs = calloc(count, sizeof *outs);
    char **paths = calloc(count, sizeof *paths);
    char *html = NULL;
    size_t html_size = 0;
    int status = CLI_EXIT_FAILURE;
    const char *inputs[] = { r->manifest };
    mk_error err;
    if (!outs || !paths) goto done;
    for (uint32_t i = 0, k = 1; i < r->row_count; i++) {
        if (!r->rows[i].has_picture) continue;
        paths[k] = malloc(strlen(r->dir) + 32);
        if (!paths[k]) goto done;
        sprintf(paths[k], "%s/frame_%04u.png", r->dir, i);
        outs[k].data = r->pngs[i].data;
        outs[k].size = r->pngs[i].size;
        k++;
    }
    paths[0] = malloc(strlen(r->dir) + 16);
    FILE *f = open_memstream(&html, &html_size);
    if (!paths[0] || !f) {
        if (f) fclose(f);
        goto done;
    }
    sprintf(paths[0], "%s/index.html", r->dir);
    write_html(r, f);
    fclose(f);
    outs[0].data = html;
    outs[0].size = html_size;
    for (uint32_t k = 0; k < count; k++) {
        const void *data = outs[k].data;
        size_t size = outs[k].size;
        outs[k].path = paths[k];
        mk_result checked = mk_output_check(&outs[k], inputs, 1, &err);
        outs[k].data = data;
        outs[k].size = size;
        if (checked != MK_OK) {
            status = cli_fail(r->verb->name, &err);
            goto done;
        }
    }
    status = mk_write_outputs(outs, count, &err) == MK_OK ? 0 : cli_fail(r->verb->name, &err);
done:
    if (status == CLI_EXIT_FAILURE && (!outs || !paths)) fprintf(stderr, "morphkit %s: out of memory\n", r->verb->name);
    for (uint32_t k = 0; paths && k < count; k++) free(paths[k]);
    free(paths);
    free(outs);
    free(html);
    cli_report_free(r);
    return status;
}

void cli_report_free(cli_report *r)
{
    if (!r) return;
    drop_meshes(r);
    free(r->meshes);
    for (uint32_t i = 0; i < r->row_count; i++) mkr_png_free(&r->pngs[i]);
    free(r->pngs);
    free(r->rows);
    free(r);
}

/* SPDX-License-Identifier: MIT */
/* morphkit render: a contact sheet of an asset's frames (docs/rendering.md), shaded with the
 * evaluated normals, or with --diff colored by the distance to another asset's frames, or with
 * --normal-error by the angle between the evaluated normals and the surface's. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "asset.h"
#include "frame_plan.h"
#include "normal_quality.h"
#include "pictures.h"

typedef struct render_args {
    const char *input, *output, *clip, *times, *weights, *size, *diff;
    uint64_t frames, columns;
    int view, stacking, stacking_given, normals, show_weights, scale_given, normal_error;
    double scale_max;
} render_args;

static int run_render(void *p);

static const cli_option options[] = {
    { "-o", "SHEET.png", CLI_STRING, offsetof(render_args, output),
      "The picture to write (a .png file, a device/FIFO, or - for standard output).", NULL, NULL, 0, 0, 1, 0 },
    { "--clip", "NAME|INDEX", CLI_STRING, offsetof(render_args, clip), "The clip whose times are drawn. Default: the first.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--frames", "N", CLI_UINT, offsetof(render_args, frames),
      "Cells at evenly spaced times over the clip, both ends included (ignored with --times or --weights).", "9", NULL, 1,
      10000, 0, 0 },
    { "--times", "T,...", CLI_STRING, offsetof(render_args, times), "Cells at these times (seconds) instead.", NULL, NULL, 0,
      0, 0, 0 },
    { "--weights", "SET;SET...", CLI_STRING, offsetof(render_args, weights),
      "Cells at forced weights instead of a clip: sets separated by ';', each NAME=V,... as for 'morphkit play'.", NULL,
      NULL, 0, 0, 0, 0 },
    { "--size", "WxH", CLI_STRING, offsetof(render_args, size),
      "Size of one cell in pixels, its label band included (32 to 4096 a side).", "320x320", NULL, 0, 0, 0, 0 },
    { "--columns", "N", CLI_UINT, offsetof(render_args, columns), "Cells per row; 0: about as many rows as columns.", "0",
      NULL, 0, 10000, 0, 0 },
    { "--view", "V", CLI_CHOICE, offsetof(render_args, view),
      "Where the fixed orthographic camera looks from (docs/rendering.md).", "iso", "front|side|top|iso", 0, 0, 0, 0 },
    { "--show-weights", NULL, CLI_FLAG, offsetof(render_args, show_weights),
      "Also label each cell with the weights of its active (non-zero) channels.", NULL, NULL, 0, 0, 0, 0 },
    { "--diff", "B", CLI_STRING, offsetof(render_args, diff),
      "Color each cell by the distance from every vertex to the same vertex of B played at the same frame (B: a .morph "
      "blob or any file 'morphkit import' reads, with the same meshes and vertex counts).",
      NULL, NULL, 0, 0, 0, 0 },
    { "--normal-error", NULL, CLI_FLAG, offsetof(render_args, normal_error),
      "Color each vertex by the angle in degrees between its evaluated normal (--normals) and the normal of the "
      "evaluated surface (docs/semantics.md, \"Normal quality\"), on one scale for all cells: where a normal mode "
      "shades combined shapes wrongly.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--scale-max", "D", CLI_NUMBER, offsetof(render_args, scale_max),
      "With --diff: the distance drawn hottest, in mesh units; with --normal-error: the angle, in degrees. Default: "
      "the largest in any cell.", NULL, NULL,
      1e-30, 1e30, 0, offsetof(render_args, scale_given) },
    { "--stacking", "MODE", CLI_CHOICE, offsetof(render_args, stacking),
      "Channel stacking. Default: each mesh's stored stacking.", NULL, "additive|sequential", 0, 0, 0,
      offsetof(render_args, stacking_given) },
    { "--normals", "MODE", CLI_CHOICE, offsetof(render_args, normals),
      "How normal changes combine; surface: recomputed from the evaluated surface.", "nlerp", "nlerp|slerp|surface", 0,
      0, 0, 0 },
};

const cli_verb cli_verb_render = {
    .name = "render",
    .usage = "FILE -o SHEET.png [options]",
    .summary = "draw frames as a contact sheet (PNG), or their distance to another asset",
    .description = "Plays FILE through the runtime and draws every frame as one cell of a grid, in world space, through "
                   "one orthographic camera framed on all frames (motion shows as change between cells), shaded with "
                   "the evaluated normals (a wrong normal shows as a wrong shade) and labelled with its time. With "
                   "--diff, each vertex is colored by its distance to B's same vertex instead, on one scale for all "
                   "cells, with a legend in mesh units and in percent of the bounding-box diagonal. With "
                   "--normal-error, by the angle between its normal and the evaluated surface's, in degrees.",
    .positional = "FILE",
    .positional_help = "A .morph blob, or any file 'morphkit import' reads.",
    .positional_offset = offsetof(render_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(render_args),
    .run = run_render,
};

/* Label lines with the frame's active channel weights (at most 6, then "+N more"). */
static char *weights_text(const mk_asset *a, const float *weights)
{
    size_t size = 6 * 48 + 32;
    char *text = malloc(size);
    if (!text) return NULL;
    text[0] = 0;
    uint32_t shown = 0, more = 0;
    for (uint32_t c = 0; c < a->channel_count; c++) {
        if (weights[c] == 0) continue;
        if (shown == 6) {
            more++;
            continue;
        }
        mk_channel_info ch;
        mk_channel_get(a, c, &ch);
        size_t n = strlen(text);
        snprintf(text + n, size - n, "%s%.24s %.3g", n ? "\n" : "", ch.name, (double)weights[c]);
        shown++;
    }
    if (more) snprintf(text + strlen(text), size - strlen(text), "\n+%u more", more);
    return text;
}

/* A cell's scalars for mesh k of frame f: the distance to the same vertex of ref (--diff), or
 * the angle between f's normals and ref's surface normals (--normal-error; ref NULL with
 * --normals surface, whose angles are 0 by definition). s is zeroed, vertex_count long. */
static void mesh_scalars(const pb_frame *f, const pb_frame *ref, int distances, uint32_t k, uint32_t vertex_count,
                         float *s)
{
    if (distances)
        cli_distances(f->positions[k], ref->positions[k], vertex_count, s);
    else if (ref && f->normals[k] && ref->normals[k])
        pb_normal_angles(f->normals[k], ref->normals[k], vertex_count, s);
}

/* B's meshes must be A's: same count, same vertex counts. Returns -1 or the exit status. */
static int check_same_meshes(const cli_verb *verb, const render_args *args, const mk_asset *a, const mk_asset *b)
{
    if (a->mesh_count != b->mesh_count)
        return cli_usage_error(verb, "--diff %s: it has %u meshes, %s has %u", args->diff, b->mesh_count, args->input,
                               a->mesh_count);
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info ma, mb;
        mk_mesh_get(a, i, &ma);
        mk_mesh_get(b, i, &mb);
        if (ma.vertex_count != mb.vertex_count)
            return cli_usage_error(verb, "--diff %s: mesh %u '%s' has %u vertices, in %s %u", args->diff, i, mb.name,
                                   mb.vertex_count, args->input, ma.vertex_count);
    }
    return -1;
}

static int run_render(void *p)
{
    render_args *args = p;
    const cli_verb *verb = &cli_verb_render;
    static const char *const extensions[] = { ".png", NULL };
    const char *inputs[] = { args->input, args->diff };
    cli_output out;
    int status = cli_output_check(verb, &out, "-o", args->output, extensions, "a PNG picture", 1, inputs,
                                  args->diff ? 2 : 1);
    if (status >= 0) return status;
    int cell_width, cell_height;
    if ((status = cli_parse_size(verb, "--size", args->size, &cell_width, &cell_height)) >= 0) return status;
    if (args->diff && args->normal_error) return cli_usage_error(verb, "--diff and --normal-error color by different things: pick one");
    if (args->scale_given && !args->diff && !args->normal_error)
        return cli_usage_error(verb, "--scale-max needs --diff or --normal-error");

    pb_asset la, lb;
    memset(&lb, 0, sizeof lb);
    mk_error err;
    mk_result r = pb_asset_load(args->input, NULL, NULL, &la, &err);
    int loaded_b = r == MK_OK && args->diff;
    if (loaded_b) r = pb_asset_load(args->diff, NULL, NULL, &lb, &err);
    cli_frame_plan plan, plan_b;
    memset(&plan, 0, sizeof plan);
    uint32_t n = 0;
    pb_frame *frames = NULL, *frames_b = NULL;
    mkr_cell *cells = NULL;
    mkr_mesh_view *views = NULL;
    float **scalars = NULL;
    char **texts = NULL;
    mkr_image img = { 0 };
    mkr_png png = { 0 };
    if (r != MK_OK) {
        status = cli_fail(verb->name, &err);
        goto done;
    }
    const mk_asset *a = &la.asset, *b = args->diff ? &lb.asset : NULL;
    /* Colored cells: by the distance to B's frames, or by the angle to the surface's normals
     * (the same frames played again with surface normals). */
    const int colored = b || args->normal_error;
    status = cli_frame_plan_make(verb, a, args->input, args->clip, args->times, args->weights, (uint32_t)args->frames, &plan);
    if (status >= 0) goto done;
    if (b && (status = check_same_meshes(verb, args, a, b)) >= 0) goto done;
    plan_b = plan;
    if (b && plan.clip >= 0) {
        mk_clip_info ci;
        mk_clip_get(a, (uint32_t)plan.clip, &ci);
        plan_b.clip = mk_find_clip(b, ci.name);
        if (plan_b.clip < 0) {
            status = cli_usage_error(verb, "--diff %s: it has no clip '%s'", args->diff, ci.name);
            goto done;
        }
    }
    n = plan.count;
    const uint32_t meshes = a->mesh_count;
    frames = calloc(n, sizeof *frames);
    frames_b = colored ? calloc(n, sizeof *frames_b) : NULL;
    cells = calloc(n, sizeof *cells);
    views = calloc((size_t)n * meshes + 1, sizeof *views);
    scalars = colored ? calloc((size_t)n * meshes + 1, sizeof *scalars) : NULL;
    texts = calloc(n, sizeof *texts);
    status = CLI_EXIT_FAILURE;
    if (!frames || (colored && (!frames_b || !scalars)) || !cells || !views || !texts) {
        fprintf(stderr, "morphkit render: out of memory for %u frames\n", n);
        goto done;
    }
    mk_stacking stacking = !args->stacking_given ? MK_STACKING_ASSET : args->stacking ? MK_STACKING_SEQUENTIAL : MK_STACKING_ADDITIVE;
    mk_normal_mode normals = args->normals == 1 ? MK_NORMALS_SLERP : MK_NORMALS_NLERP;
    int surface = args->normals == 2;
    float largest = 0;   /* the largest scalar of any cell */
    for (uint32_t i = 0; i < n; i++) {
        frames[i] = (pb_frame){ .asset = a, .stacking = stacking, .normal_mode = normals, .surface_normals = surface,
                                .world = 1, .skip_tangents = 1 };
        int played = cli_frame_play(verb, args->input, &plan, i, &frames[i]);
        if (played >= 0) { status = played; goto done; }
        /* Surface normals are the reference itself: their angles are 0 without a second play. */
        const int reference = colored && (b || !surface);
        if (reference) {
            frames_b[i] = (pb_frame){ .asset = b ? b : a, .stacking = stacking, .normal_mode = normals,
                                      .surface_normals = b ? surface : 1, .world = 1, .skip_tangents = 1 };
            played = cli_frame_play(verb, b ? args->diff : args->input, b ? &plan_b : &plan, i, &frames_b[i]);
            if (played >= 0) { status = played; goto done; }
        }
        for (uint32_t k = 0; k < meshes; k++) {
            mkr_mesh_view *v = &views[(size_t)i * meshes + k];
            *v = cli_mesh_view(&frames[i], k);
            if (!colored) continue;
            float *s = scalars[(size_t)i * meshes + k] = calloc((size_t)v->vertex_count + 1, 4);
            if (!s) { fprintf(stderr, "morphkit render: out of memory\n"); goto done; }
            mesh_scalars(&frames[i], reference ? &frames_b[i] : NULL, b != NULL, k, v->vertex_count, s);
            if (!b && i == 0 && !frames[i].normals[k]) {
                mk_mesh_info mi;
                mk_mesh_get(a, k, &mi);
                fprintf(stderr, "morphkit render: mesh %u '%s' has no normals; its angles are drawn as 0\n", k, mi.name);
            }
            for (uint32_t j = 0; j < v->vertex_count; j++)
                if (s[j] > largest) largest = s[j];
            v->scalars = s;
        }
        if (reference) cli_frame_clear(&frames_b[i]);   /* only its scalars are drawn */
        if (args->show_weights && !(texts[i] = weights_text(a, frames[i].weights))) {
            fprintf(stderr, "morphkit render: out of memory\n");
            goto done;
        }
        cells[i] = (mkr_cell){ .meshes = views + (size_t)i * meshes, .mesh_count = meshes,
                               .time = plan.clip >= 0 ? plan.frames[i].time : NAN, .text = texts[i] };
        if (plan.frames[i].weights && !args->show_weights) cells[i].text = plan.frames[i].weights;
    }
    char title[600];
    const char *views_names[] = { "front", "side", "top", "iso" };
    const char *against = b ? args->diff : args->normal_error ? "  normal error" : "";
    if (plan.clip >= 0) {
        mk_clip_info ci;
        mk_clip_get(a, (uint32_t)plan.clip, &ci);
        snprintf(title, sizeof title, "%.200s%s%.200s  clip '%.100s'  %s view", args->input, b ? " vs " : "", against,
                 ci.name, views_names[args->view]);
    } else {
        snprintf(title, sizeof title, "%.200s%s%.200s  %s  %s view", args->input, b ? " vs " : "", against,
                 plan.frames[0].weights ? "forced weights" : "default weights", views_names[args->view]);
    }
    mkr_sheet_desc desc = { .cells = cells, .cell_count = n, .cell_width = cell_width, .cell_height = cell_height,
                            .columns = (int)args->columns, .view = (mkr_view)args->view, .title = title,
                            .diff_max = args->scale_given ? (float)args->scale_max : 0 };
    static const char *const mode_names[] = { "nlerp", "slerp", "surface" };
    char caption[96];
    if (args->normal_error) {
        snprintf(caption, sizeof caption, "angle between the %s normals and the surface's: degrees", mode_names[args->normals]);
        desc.scalar_caption = caption;
        desc.scalar_suffix = " deg";
    }
    r = colored ? mkr_diff_sheet_render(&desc, &img, &err) : mkr_sheet_render(&desc, &img, &err);
    if (r != MK_OK) {
        status = cli_fail(verb->name, &err);
        goto done;
    }
    if ((status = cli_png_encode(verb, &img, &png, &out)) >= 0) goto done;
    status = cli_write_outputs(verb, &out, 1);
    if (status == 0) {
        FILE *to = out.to_stdout ? stderr : stdout;
        fprintf(to, "%s -> %s: %u cell%s of %dx%d, %s view, %dx%d pixels, %zu bytes", args->input,
                out.to_stdout ? "standard output" : args->output, n, n == 1 ? "" : "s", cell_width, cell_height,
                views_names[args->view], img.width, img.height, png.size);
        if (args->normal_error) fprintf(to, ", largest normal error %.4g degrees", (double)largest);
        fprintf(to, "\n");
    }
done:
    for (uint32_t i = 0; i < n; i++) {
        if (frames) cli_frame_clear(&frames[i]);
        if (frames_b) cli_frame_clear(&frames_b[i]);
        if (texts) free(texts[i]);
    }
    for (size_t i = 0; scalars && i < (size_t)n * la.asset.mesh_count; i++) free(scalars[i]);
    free(frames);
    free(frames_b);
    free(cells);
    free(views);
    free(scalars);
    free(texts);
    mkr_png_free(&png);
    mkr_image_destroy(&img);
    cli_frame_plan_free(&plan);
    pb_asset_free(&la);
    if (loaded_b) pb_asset_free(&lb);
    return status;
}

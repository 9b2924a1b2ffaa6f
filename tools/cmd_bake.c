/* SPDX-License-Identifier: MIT */
/* morphkit bake: applies a bake recipe (docs/baking.md) and writes the asset with the baked
 * channels added. Nothing is written when the recipe or any channel fails. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "bake.h"
#include "cli.h"
#include "fbx_write.h"
#include "gltf_writeback.h"
#include "json_write.h"
#include "pictures.h"
#include "render.h"

typedef struct bake_args {
    const char *input, *output, *recipe, *depfile, *plot;
    int precision, quiet, all_meshes, json;
    uint64_t threads;
} bake_args;

static int run_bake(void *p);

static const cli_option options[] = {
    { "--recipe", "RECIPE.json", CLI_STRING, offsetof(bake_args, recipe),
      "The bake recipe: which deformers make which channels (docs/baking.md). Paths in it are relative to its folder.",
      NULL, NULL, 0, 0, 1, 0 },
    { "-o", "OUT.morph", CLI_STRING, offsetof(bake_args, output),
      "The blob to write (a path ending in .morph, or a device/FIFO); or the input's own format with the baked "
      "channels added (docs/baking.md, \"Baking into your own file\"): OUT.fbx when IN is an FBX file, OUT.gltf/OUT.glb "
      "(the same container) when IN is .gltf/.glb, with the channel sidecar OUT.channels.json beside it.",
      NULL, NULL, 0, 0, 1, 0 },
    { "--precision", "P", CLI_CHOICE, offsetof(bake_args, precision),
      "How deltas are stored (as for 'morphkit import').", "q16", "q16|float", 0, 0, 0, 0 },
    { "--all-meshes", NULL, CLI_FLAG, offsetof(bake_args, all_meshes),
      "Also write meshes that end up without channels (by default they are left out).", NULL, NULL, 0, 0, 0, 0 },
    { "--threads", "N", CLI_UINT, offsetof(bake_args, threads),
      "Threads for the parts of a bake that run in parallel (the shell simulation's sweeps and collision tests); 0 = one per core; "
      "where other processes keep the cores busy, 1 can be faster. "
      "The blob is the same for any count.",
      "0", NULL, 0, 64, 0, 0 },
    { "--depfile", "PATH", CLI_STRING, offsetof(bake_args, depfile),
      "Also write a depfile for build systems (make syntax, as ninja and meson read it): the blob and every file the bake "
      "read (the input, the recipe, the cages it names).",
      NULL, NULL, 0, 0, 0, 0 },
    { "--plot", "FILE.png", CLI_STRING, offsetof(bake_args, plot),
      "Also draw each baked channel's playback error against its weight, with the tolerance and the in-between "
      "weights marked (one panel per channel), under a chart of the shell channels' volume ratios.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--quiet", NULL, CLI_FLAG, offsetof(bake_args, quiet),
      "No progress lines and no solver details (results are still printed).", NULL, NULL, 0, 0, 0, 0 },
    { "--json", NULL, CLI_FLAG, offsetof(bake_args, json),
      "Print one JSON object instead of the text report: per baked channel its name, op, mesh, targets, evaluations, "
      "max_error, moved_vertices and seconds (solver ops: factorizations and solves; transfer: correspondence, fit_mean "
      "and fit_max), then the totals and the blob's bytes and max_position_error.", NULL, NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_bake = {
    .name = "bake",
    .usage = "IN --recipe RECIPE.json -o OUT.morph|OUT.fbx|OUT.gltf|OUT.glb [options]",
    .summary = "bake deformers (FFD, bend, cage, Laplacian, ...) into channels",
    .description =
        "Reads IN (meshes with or without morph targets), applies the recipe's deformers and writes the asset with the "
        "baked "
        "channels added, each with adaptive in-betweens placed so playback stays within the recipe's tolerance.",
    .positional = "IN",
    .positional_help = "A .morph blob, or any file 'morphkit import' reads.",
    .positional_offset = offsetof(bake_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(bake_args),
    .run = run_bake,
};

/* A baked channel's report, kept for --plot and --json (its arrays live in the raw asset; its
 * name buffer is the baker's, reused for the next channel, so the name is copied). */
typedef struct kept_channel {
    mk_bake_channel_report r;
    char name[128];
} kept_channel;

typedef struct bake_ui {
    int quiet, json;
    cli_progress progress;
    cli_depfile deps;
    int plot;                      /* --plot: draw the kept reports */
    kept_channel *channels;
    uint32_t channel_count;
    int out_of_memory;
} bake_ui;

static void keep_channel(bake_ui *ui, const mk_bake_channel_report *c)
{
    kept_channel *grown = realloc(ui->channels, (ui->channel_count + 1) * sizeof *grown);
    if (!grown) { ui->out_of_memory = 1; return; }
    ui->channels = grown;
    kept_channel *k = &ui->channels[ui->channel_count++];
    k->r = *c;
    snprintf(k->name, sizeof k->name, "%s", c->name);
}

/* The volume ratio of every shell channel over its frames, on one chart (VOLUME_PANEL high). */
enum { VOLUME_PANEL = 260 };
static void draw_volumes(const bake_ui *ui, mkr_image *img)
{
    mkr_series series[6];
    uint32_t count = 0;
    double seconds = 0;
    for (uint32_t i = 0; i < ui->channel_count && count < 6; i++) {
        const kept_channel *k = &ui->channels[i];
        if (!k->r.volume_ratios) continue;
        series[count++] = (mkr_series){ k->r.volume_ratios, k->r.volume_frames, k->name, k->r.key_frames,
                                        k->r.key_weights ? k->r.targets : 0 };
        seconds = count == 1 || seconds == k->r.frame_seconds ? k->r.frame_seconds : -1;  /* -1: time steps differ */
    }
    mkr_lines lines = { .title = "shell: enclosed volume / rest volume per frame (dots: the frames baked as targets)",
                        .x_label = seconds > 0 ? "simulated time (s)" : "frame", .y_label = "V/V0",
                        .x_scale = seconds > 0 ? seconds : 0, .y_max = 1,
                        .series = series, .series_count = count };
    mkr_lines_draw(img, 0, 0, 720, VOLUME_PANEL - 2, &lines);
}

/* One 720 x 200 panel per channel, stacked, under one chart of the shell channels' volumes when
 * there are any. Returns -1 when fine, else the exit status. */
static int draw_plot(const cli_verb *verb, const bake_ui *ui, mkr_image *img, mkr_png *png, cli_output *out)
{
    mk_error err;
    uint32_t n = ui->channel_count ? ui->channel_count : 1, shells = 0;
    if (n > 80) n = 80;   /* a picture people can read; more channels are left out (said below) */
    for (uint32_t i = 0; i < ui->channel_count; i++) shells += ui->channels[i].r.volume_ratios != NULL;
    const int top = shells ? VOLUME_PANEL : 0;
    if (mkr_image_create(img, 720, top + 200 * (int)n, &err) != MK_OK) return cli_fail(verb->name, &err);
    static const uint8_t background[4] = { 20, 20, 24, 255 };
    mkr_image_clear(img, background);
    if (shells) draw_volumes(ui, img);
    if (shells > 6) fprintf(stderr, "morphkit bake: --plot draws the volumes of the first 6 of %u shell channels\n", shells);
    for (uint32_t i = 0; i < n && i < ui->channel_count; i++) {
        const mk_bake_channel_report *r = &ui->channels[i].r;
        char title[200];
        snprintf(title, sizeof title, "%s (%s, mesh %u): %u target%s, max %.3g%% of the diagonal", ui->channels[i].name,
                 r->op, r->mesh, r->targets, r->targets == 1 ? "" : "s", 100 * r->max_error);
        mkr_plot plot = { .title = title, .values = r->error_curve, .count = r->error_curve ? r->curve_samples + 1 : 0,
                          .limit = r->tolerance, .marks = r->key_weights, .mark_count = r->key_weights ? r->targets : 0,
                          .label_scale = 100, .unit = "%",
                          .note = "no error curve: a fixed count of an expensive deformer is checked at span midpoints" };
        mkr_plot_draw(img, 0, top + 200 * (int)i, 720, 198, &plot);
    }
    if (ui->channel_count > n)
        fprintf(stderr, "morphkit bake: --plot shows the first %u of %u channels\n", n, ui->channel_count);
    return cli_png_encode(verb, img, png, out);
}

static void on_file_read(void *user, const char *path)
{
    bake_ui *ui = user;
    cli_depfile_add(&ui->deps, path);
}

static void on_progress(void *user, const char *stage, double fraction)
{
    bake_ui *ui = user;
    cli_progress_update(&ui->progress, stage, fraction);
}

static void print_json(const bake_ui *ui, const bake_args *a, const mk_bake_report *report, const mk_write_report *wr,
                       size_t size)
{
    json_writer w;
    json_begin(&w, stdout, 1);
    json_object(&w, NULL);
    json_string(&w, "input", a->input);
    json_string(&w, "output", a->output);
    json_array(&w, "channels");
    for (uint32_t i = 0; i < ui->channel_count; i++) {
        const mk_bake_channel_report *j = &ui->channels[i].r;
        json_object(&w, NULL);
        json_string(&w, "name", ui->channels[i].name);
        json_string(&w, "op", j->op);
        json_int(&w, "mesh", j->mesh);
        json_int(&w, "targets", j->targets);
        json_int(&w, "evaluations", j->evaluations);
        json_number(&w, "max_error", j->max_error);
        json_int(&w, "moved_vertices", j->moved_vertices);
        json_number(&w, "seconds", j->seconds);
        if (j->factorizations || j->solves) {
            json_int(&w, "factorizations", j->factorizations);
            json_int(&w, "solves", j->solves);
        }
        if (j->correspondence) {
            json_string(&w, "correspondence", j->correspondence);
            if (!strcmp(j->correspondence, "iterative")) {
                json_number(&w, "fit_mean", j->fit_mean);
                json_number(&w, "fit_max", j->fit_max);
            }
        }
        json_end_object(&w);
    }
    json_end_array(&w);
    json_int(&w, "channels_added", report->channels_added);
    json_int(&w, "targets_added", report->targets_added);
    json_number(&w, "max_error", report->max_error);
    json_int(&w, "bytes", (long long)size);
    json_number(&w, "max_position_error", wr->max_position_error);
    json_end_object(&w);
}

static void on_channel(void *user, const mk_bake_channel_report *c)
{
    bake_ui *ui = user;
    if (ui->plot || ui->json) keep_channel(ui, c);
    if (ui->json) return;
    printf("channel \"%s\" (%s, mesh %u): %u target%s, %u evaluations, playback error %.3g x diagonal%s, "
           "%u vertices moved, %.3f s\n",
           c->name, c->op, c->mesh, c->targets, c->targets == 1 ? "" : "s", c->evaluations, c->max_error,
           c->error_measured_on_grid ? "" : " (span midpoints)", c->moved_vertices, c->seconds);
    if (c->factorizations && !ui->quiet)
        printf("  solver: %u factorization (%.3f s), %u solves (%.4f s each)\n", c->factorizations, c->factor_seconds,
               c->solves, c->solves ? c->solve_seconds / c->solves : 0.0);
    if (c->correspondence && !ui->quiet) {
        if (!strcmp(c->correspondence, "iterative"))
            printf("  correspondence: iterative, the fitted source %.3g (mean) and %.3g (max) x diagonal from the target\n",
                   c->fit_mean, c->fit_max);
        else printf("  correspondence: closest (one pass)\n");
    }
    if (c->iterations && !ui->quiet)
        printf("  arap: %u iterations (at most %u per evaluation%s), energy %.4g (initial guess %.4g)\n",
               c->iterations, c->max_iterations, c->unconverged ? ", some stopped by the cap" : "",
               c->energy, c->start_energy);
    if (c->inverted_vertices)
        printf("  %u vertices fold (det J <= 0): normals taken from the deformed surface\n", c->inverted_vertices);
}

/* Directory part of a path ("" for a bare file name). */
static void dir_of(const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        out[0] = 0;
        return;
    }
    size_t n = (size_t)(slash - path);
    if (n == 0) n = 1; /* "/file" -> "/" */
    if (n >= size) n = size - 1;
    memcpy(out, path, n);
    out[n] = 0;
}

/* -o OUT.fbx: what the write-back refuses about IN itself, before the bake. */
static mk_result check_fbx_input(const bake_args *a, const mk_raw_asset *raw, const void *input, size_t input_size,
                                 mk_error *err)
{
    if (strncmp(raw->source_format, "fbx", 3) != 0)
        return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "-o %s: an .fbx output is the FBX input with the baked channels added, and %s is not FBX (%s); "
                            "write a .morph, or export it as FBX first (morphkit export IN -o IN.fbx)",
                            a->output, a->input, raw->source_format[0] ? raw->source_format : "unknown");
    return mk_fbx_write_back_check(input, input_size, err);
}

/* -o OUT.fbx: the input FBX file (the bytes the import read) with the baked channels added. */
static mk_result write_back_fbx(const bake_args *a, mk_raw_asset *raw, const void *input, size_t input_size, void **out,
                                size_t *size, mk_error *err)
{
    mk_fbx_write_report rep;
    mk_result r = mk_fbx_write_back(input, input_size, raw, &raw->arena, out, size, &rep, err);
    if (r == MK_OK && !a->json)
        printf("FBX: %u channel%s with %u shape%s on %u mesh%s (%u new BlendShape deformer%s), %u clip%s as animation stacks\n",
               rep.channels, rep.channels == 1 ? "" : "s", rep.shapes, rep.shapes == 1 ? "" : "s", rep.meshes,
               rep.meshes == 1 ? "" : "es", rep.blend_shapes, rep.blend_shapes == 1 ? "" : "s", rep.clips,
               rep.clips == 1 ? "" : "s");
    if (r == MK_OK && !a->json && rep.progressive_channels)
        printf("note: %u channel%s with in-betweens (FBX's own progressive shapes, as Maya writes them; ufbx plays them; "
               "Blender 3.4's FBX importer cannot read in-betweens and refuses such files; \"inbetweens\": 1 bakes one target)\n",
               rep.progressive_channels, rep.progressive_channels == 1 ? "" : "s");
    return r;
}

/* -o OUT.gltf|OUT.glb: IN's own glTF with the baked channels appended as targets (formats/gltf_writeback),
 * and the channel sidecar OUT.channels.json (outs[*count]) beside it. The raw asset still has
 * its plain meshes. Returns -1 when outs[0] (and the sidecar) are filled, else the exit status. */
static int write_back_gltf(const cli_verb *verb, const bake_args *a, mk_raw_asset *raw, const void *in, size_t in_size,
                           cli_output *outs, uint32_t *count, size_t *size)
{
    static char sidecar_path[4200];
    const char *dot = strrchr(a->output, '.');
    snprintf(sidecar_path, sizeof sidecar_path, "%.*s.channels.json", (int)(dot - a->output), a->output);
    static const char *const json_ext[] = { ".json", NULL };
    const char *inputs[] = { a->input, a->recipe, a->output };
    void *out = NULL;
    char *sidecar = NULL;
    size_t sidecar_size = 0;
    mk_gltf_write_back_report rep;
    mk_error err;
    mk_result r = mk_gltf_write_back(in, in_size, a->input, a->output, raw, &raw->arena, &out, size, &sidecar, &sidecar_size,
                               &rep, &err);
    if (r != MK_OK) return cli_fail(verb->name, &err);
    outs[0].file.data = out;
    outs[0].file.size = *size;
    if (sidecar) {
        int status = cli_output_check(verb, &outs[*count], "-o", sidecar_path, json_ext, "a JSON channel sidecar", 0, inputs, 3);
        if (status >= 0) return status;
        outs[*count].file.data = sidecar;
        outs[(*count)++].file.size = sidecar_size;
    }
    if (!a->json) {
        printf("write-back: %u glTF meshes, %u channels as %u new targets (%u padding on other primitives), %u sparse and "
               "%u dense accessors (%u quantized), %u weight samplers extended, %u animations added, %zu new bytes\n",
               rep.meshes, rep.channels, rep.targets, rep.padding_targets, rep.sparse_accessors, rep.dense_accessors,
               rep.quantized_accessors, rep.rewritten_samplers, rep.animations_added, rep.added_bytes);
        for (uint32_t i = 0; i < rep.note_count && i < 8; i++) printf("note: %s\n", rep.notes[i]);
        if (sidecar)
            printf("channel sidecar: %s (re-import with: morphkit import %s --channels %s -o OUT.morph)\n", sidecar_path,
                   a->output, sidecar_path);
    }
    return -1;
}

static int run_bake(void *p)
{
    bake_args *a = p;
    const cli_verb *verb = &cli_verb_bake;
    static const char *const extensions[] = { ".morph", ".fbx", ".gltf", ".glb", NULL };
    const char *inputs[] = { a->input, a->recipe };
    static const char *const png_extensions[] = { ".png", NULL };
    cli_output outs[4];
    uint32_t out_count = 1, depfile_out = 0, plot_out = 0;
    int status = cli_output_check(verb, &outs[0], "-o", a->output, extensions, "a .morph blob, or the input's own FBX or glTF", 0, inputs, 2);
    if (status >= 0) return status;
    int write_back = mk_path_has_extension(a->output, ".gltf") || mk_path_has_extension(a->output, ".glb");
    if (write_back && !mk_path_has_extension(a->input, mk_path_has_extension(a->output, ".gltf") ? ".gltf" : ".glb"))
        return cli_usage_error(verb, "-o %s: a glTF output is IN itself with the baked channels added, so IN must be a %s",
                               a->output, mk_path_has_extension(a->output, ".gltf") ? ".gltf" : ".glb");
    if (a->depfile) {
        depfile_out = out_count++;
        if ((status = cli_output_check(verb, &outs[depfile_out], "--depfile", a->depfile, NULL, "a depfile", 0, inputs, 2)) >= 0)
            return status;
    }
    if (a->plot) {
        plot_out = out_count++;
        if ((status = cli_output_check(verb, &outs[plot_out], "--plot", a->plot, png_extensions, "a PNG picture", 0, inputs,
                                       2)) >= 0)
            return status;
    }

    bake_ui ui = { .quiet = a->quiet, .json = a->json, .plot = a->plot != NULL };
    mkr_image img = { 0 };
    mkr_png png = { 0 };
    cli_progress_init(&ui.progress, a->quiet);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    /* A plain mesh is a baker's natural input: meshes without targets are kept. */
    mk_import_options io = { .keep_plain_meshes = 1, .file_read = a->depfile ? cli_depfile_add : NULL,
                             .file_read_user = &ui.deps };
    void *recipe = NULL, *blob = NULL;
    size_t recipe_size = 0, size = 0;
    char *dep_text = NULL;
    const int to_fbx = mk_path_has_extension(a->output, ".fbx");
    /* A write-back puts the bake into the bytes the import read (the input is read once). */
    const void *input = NULL;
    size_t input_size = 0;
    mk_result r = write_back || to_fbx ? mk_import_file_keeping(a->input, &io, &raw, &input, &input_size, &err)
                                       : mk_import_file(a->input, &io, &raw, &err);
    if (r == MK_OK && to_fbx) r = check_fbx_input(a, &raw, input, input_size, &err);
    if (r == MK_OK) r = mk_read_file(&raw.arena, a->recipe, (size_t)64 << 20, &recipe, &recipe_size, &err);
    if (r == MK_OK && a->depfile) cli_depfile_add(&ui.deps, a->recipe);
    char dir[4096];
    dir_of(a->recipe, dir, sizeof dir);
    mk_bake_options bo = { .base_dir = dir, .progress = on_progress, .channel_done = on_channel, .user = &ui,
                           .file_read = a->depfile ? on_file_read : NULL, .load_asset = mk_import_load_asset,
                           .threads = (uint32_t)a->threads };
    mk_bake_report report;
    if (r == MK_OK) r = mk_bake_recipe(&raw, recipe, recipe_size, &bo, &report, &err);
    mk_write_report wr = { 0 };
    if (r == MK_OK && write_back) {
        cli_print_warnings(&raw);
        if ((status = write_back_gltf(verb, a, &raw, input, input_size, outs, &out_count, &size)) >= 0) goto done;
    } else {
        if (r == MK_OK && !a->all_meshes && !to_fbx)
            mk_raw_drop_plain_meshes(&raw, "not written (no channel; --all-meshes keeps it)");
        cli_print_warnings(&raw);
        mk_write_options wo = { .precision = a->precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16 };
        if (r == MK_OK) r = to_fbx ? write_back_fbx(a, &raw, input, input_size, &blob, &size, &err)
                                   : mk_write_blob(&raw, &wo, &raw.arena, &blob, &size, &wr, &err);
        if (r != MK_OK) {
            status = cli_fail(verb->name, &err);
            goto done;
        }
        outs[0].file.data = blob;
        outs[0].file.size = size;
    }
    if (a->depfile) {
        dep_text = cli_depfile_text(&ui.deps, a->output, &outs[depfile_out].file.size);
        outs[depfile_out].file.data = dep_text;
        if (!dep_text) { fprintf(stderr, "morphkit bake: out of memory\n"); status = CLI_EXIT_FAILURE; goto done; }
    }
    if (ui.out_of_memory) { fprintf(stderr, "morphkit bake: out of memory for the report\n"); status = CLI_EXIT_FAILURE; goto done; }
    if (a->plot) {
        if ((status = draw_plot(verb, &ui, &img, &png, &outs[plot_out])) >= 0) goto done;
    }
    status = cli_write_outputs(verb, outs, out_count);
    if (status == 0 && a->json) print_json(&ui, a, &report, &wr, size);
    else if (status == 0) {
        printf("%s -> %s: %u channels baked, %u targets, max playback error %.3g x diagonal, %zu bytes\n", a->input,
               a->output, report.channels_added, report.targets_added, report.max_error, size);
        if (!write_back && !to_fbx) cli_print_write_report(&wr);
    }
done:
    free(dep_text);
    free(ui.channels);
    mkr_png_free(&png);
    mkr_image_destroy(&img);
    cli_depfile_free(&ui.deps);
    mk_raw_free(&raw);
    return status;
}

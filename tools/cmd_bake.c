/* morphkit bake IN.morph|IN.fbx|IN.gltf --recipe RECIPE.json -o OUT.morph
 *                [--precision float|q16] [--quiet]
 * Applies a bake recipe (docs/baking.md) and writes the asset with the baked channels added.
 * Nothing is written when the recipe or any channel fails. */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bake.h"
#include "cli.h"

static int usage(void)
{
    fprintf(stderr, "usage: morphkit bake IN.morph|IN.fbx|IN.gltf --recipe RECIPE.json -o OUT.morph\n"
                    "       [--precision float|q16] [--quiet]\n");
    return 2;
}

typedef struct bake_ui {
    int quiet;
    char stage[256];
    int last_tenth;
    double stage_start;
} bake_ui;

static double now_seconds(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Progress on stderr for long bakes only: a stage prints once it has run for half a second,
 * then at most one line per tenth, so short bakes stay silent and logs stay small. */
static void on_progress(void *user, const char *stage, double fraction)
{
    bake_ui *ui = user;
    if (ui->quiet) return;
    int tenth = (int)(fraction * 10);
    if (strncmp(ui->stage, stage, sizeof ui->stage - 1) != 0) {
        snprintf(ui->stage, sizeof ui->stage, "%s", stage);
        ui->last_tenth = -1;
        ui->stage_start = now_seconds();
    }
    if (tenth <= ui->last_tenth || now_seconds() - ui->stage_start < 0.5) return;
    ui->last_tenth = tenth;
    fprintf(stderr, "  %s: %3d%%\n", stage, tenth * 10);
}

static void on_channel(void *user, const mk_bake_channel_report *c)
{
    bake_ui *ui = user;
    printf("channel \"%s\" (%s, mesh %u): %u target%s, %u evaluations, playback error %.3g x diagonal%s, "
           "%u vertices moved, %.3f s\n",
           c->name, c->op, c->mesh, c->targets, c->targets == 1 ? "" : "s", c->evaluations,
           c->max_error, c->error_measured_on_grid ? "" : " (span midpoints)", c->moved_vertices,
           c->seconds);
    if (c->factorizations && !ui->quiet)
        printf("  solver: %u factorization (%.3f s), %u solves (%.4f s each)\n", c->factorizations,
               c->factor_seconds, c->solves, c->solves ? c->solve_seconds / c->solves : 0.0);
    if (c->inverted_vertices)
        printf("  %u vertices fold (det J <= 0): normals taken from the deformed surface\n",
               c->inverted_vertices);
}

/* Directory part of a path ("" for a bare file name). */
static void dir_of(const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash) { out[0] = 0; return; }
    size_t n = (size_t)(slash - path);
    if (n == 0) n = 1;  /* "/file" -> "/" */
    if (n >= size) n = size - 1;
    memcpy(out, path, n);
    out[n] = 0;
}

int cmd_bake(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *recipe_path = NULL;
    mk_write_options wo = { 0 };
    bake_ui ui = { 0, "", -1, 0 };
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-o") && v) { out = v; i++; }
        else if (!strcmp(a, "--recipe") && v) { recipe_path = v; i++; }
        else if (!strcmp(a, "--precision") && v) {
            int p = cli_parse_precision(v);
            if (p < 0) return usage();
            wo.precision = (mk_precision)p;
            i++;
        }
        else if (!strcmp(a, "--quiet")) ui.quiet = 1;
        else if (!strcmp(a, "--help")) { usage(); return 0; }
        else if (a[0] != '-' && !in) in = a;
        else { fprintf(stderr, "morphkit bake: unexpected argument '%s'\n", a); return usage(); }
    }
    if (!in || !out || !recipe_path) return usage();

    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_import_options io = { 0 };
    mk_result r = cli_load_raw(in, &io, &raw, &err);
    if (r != MK_OK) { mk_raw_free(&raw); return cli_fail("bake", &err); }
    void *recipe = NULL;
    size_t recipe_size = 0;
    r = mk_read_file(&raw.arena, recipe_path, (size_t)64 << 20, &recipe, &recipe_size, &err);
    if (r != MK_OK) { mk_raw_free(&raw); return cli_fail("bake", &err); }

    char dir[4096];
    dir_of(recipe_path, dir, sizeof dir);
    mk_bake_options bo = { .base_dir = dir, .progress = on_progress, .channel_done = on_channel, .user = &ui };
    mk_bake_report report;
    uint32_t warnings_before = raw.warning_count;
    r = mk_bake_recipe_ex(&raw, recipe, recipe_size, &bo, &report, &err);
    if (r != MK_OK) { mk_raw_free(&raw); return cli_fail("bake", &err); }
    if (!ui.quiet || raw.warning_count > warnings_before) cli_print_warnings(&raw);

    void *blob = NULL;
    size_t size = 0;
    mk_write_report wr;
    r = mk_write_blob(&raw, &wo, &raw.arena, &blob, &size, &wr, &err);
    if (r == MK_OK) r = mk_write_file_atomic(out, blob, size, &err);
    if (r != MK_OK) { mk_raw_free(&raw); return cli_fail("bake", &err); }
    printf("%s -> %s: %u channels baked, %u targets, max playback error %.3g x diagonal, %zu bytes\n",
           in, out, report.channels_added, report.targets_added, report.max_error, size);
    if (!ui.quiet)
        printf("precision: %u int16 targets, %u float targets; max position quantization error %.3g\n",
               wr.quantized_targets, wr.float_targets, wr.max_position_error);
    mk_raw_free(&raw);
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* Shared helpers of the verbs. */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "cli.h"

void cli_print_warnings(const mk_raw_asset *raw)
{
    uint32_t shown = raw->warning_count < MK_RAW_MAX_WARNINGS ? raw->warning_count : MK_RAW_MAX_WARNINGS;
    for (uint32_t i = 0; i < shown && raw->warnings; i++) fprintf(stderr, "warning: %s\n", raw->warnings[i].message);
    if (raw->warning_count > shown) fprintf(stderr, "warning: ... %u more\n", raw->warning_count - shown);
}

int cli_fail(const char *verb, const mk_error *err)
{
    fprintf(stderr, "morphkit %s: %s\n", verb, err->message);
    return err->code == MK_ERROR_INVALID_ARGUMENT ? CLI_EXIT_USAGE : CLI_EXIT_FAILURE;
}

int cli_output_check(const cli_verb *verb, cli_output *out, const char *option, const char *path,
                     const char *const *extensions, const char *what, int allow_stdout, const char *const *inputs,
                     uint32_t input_count)
{
    memset(out, 0, sizeof *out);
    out->file.path = path;
    if (!strcmp(path, "-")) {
        if (!allow_stdout)
            return cli_usage_error(verb, "%s -: %s cannot go to standard output; name a file", option, what);
        out->to_stdout = 1;
        return -1;
    }
    mk_error err;
    if (mk_output_check(&out->file, inputs, input_count, &err) != MK_OK) return cli_fail(verb->name, &err);
    if (out->file.kind == MK_OUTPUT_STREAM || !extensions) return -1;
    for (const char *const *e = extensions; *e; e++)
        if (mk_path_has_extension(path, *e)) return -1;
    char list[128] = "";
    for (const char *const *e = extensions; *e; e++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", e == extensions ? "" : " or ", *e);
    return cli_usage_error(verb, "%s %s: %s writes %s, so the name must end in %s", option, path, verb->name, what,
                           list);
}

int cli_write_outputs(const cli_verb *verb, cli_output *outs, uint32_t count)
{
    mk_output files[8];
    uint32_t n = 0;
    for (uint32_t i = 0; i < count && n < 8; i++)
        if (!outs[i].to_stdout) files[n++] = outs[i].file;
    mk_error err;
    mk_result r = n ? mk_write_outputs(files, n, &err) : MK_OK;
    for (uint32_t i = 0; i < count; i++) outs[i].file.early = 0;   /* closed by mk_write_outputs */
    if (r != MK_OK) return cli_fail(verb->name, &err);
    for (uint32_t i = 0; i < count; i++) {
        if (!outs[i].to_stdout) continue;
        if (fwrite(outs[i].file.data, 1, outs[i].file.size, stdout) != outs[i].file.size || fflush(stdout) != 0) {
            fprintf(stderr, "morphkit %s: writing to standard output failed\n", verb->name);
            return CLI_EXIT_FAILURE;
        }
    }
    return 0;
}

void cli_depfile_add(void *user, const char *path)
{
    cli_depfile *d = user;
    for (size_t i = 0; i < d->count; i++)
        if (!strcmp(d->paths[i], path)) return;
    if (d->count == d->capacity) {
        size_t cap = d->capacity ? 2 * d->capacity : 8;
        char **grown = realloc(d->paths, cap * sizeof *grown);
        if (!grown) return;   /* a missing dependency only costs a rebuild that does not happen */
        d->paths = grown;
        d->capacity = cap;
    }
    size_t n = strlen(path);
    char *copy = malloc(n + 1);
    if (!copy) return;
    memcpy(copy, path, n + 1);
    d->paths[d->count++] = copy;
}

/* A path in make syntax: spaces and '#' escaped with '\\', '$' doubled. */
static size_t escape_path(char *out, const char *path)
{
    size_t n = 0;
    for (const char *p = path; *p; p++) {
        if (*p == ' ' || *p == '#') { if (out) out[n] = '\\'; n++; }
        if (*p == '$') { if (out) out[n] = '$'; n++; }
        if (out) out[n] = *p;
        n++;
    }
    return n;
}

char *cli_depfile_text(cli_depfile *d, const char *target, size_t *size)
{
    size_t n = escape_path(NULL, target) + 3;
    for (size_t i = 0; i < d->count; i++) n += escape_path(NULL, d->paths[i]) + 3;
    char *text = malloc(n + 1);
    size_t at = 0;
    if (text) {
        at += escape_path(text, target);
        text[at++] = ':';
        for (size_t i = 0; i < d->count; i++) {
            text[at++] = ' ';
            at += escape_path(text + at, d->paths[i]);
        }
        text[at++] = '\n';
        text[at] = 0;
    }
    cli_depfile_free(d);
    *size = at;
    return text;
}

void cli_depfile_free(cli_depfile *d)
{
    for (size_t i = 0; i < d->count; i++) free(d->paths[i]);
    free(d->paths);
    memset(d, 0, sizeof *d);
}

double cli_now_seconds(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_progress_init(cli_progress *p, int quiet)
{
    memset(p, 0, sizeof *p);
    p->enabled = !quiet && isatty(STDERR_FILENO);
    p->last_tenth = -1;
}

void cli_progress_update(cli_progress *p, const char *stage, double fraction)
{
    if (!p->enabled) return;
    if (fraction < 0) { /* announce a stage that reports no fractions */
        fprintf(stderr, "  %s ...\n", stage);
        return;
    }
    int tenth = (int)(fraction * 10);
    if (strncmp(p->stage, stage, sizeof p->stage - 1) != 0) {
        snprintf(p->stage, sizeof p->stage, "%s", stage);
        p->last_tenth = -1;
        p->stage_start = cli_now_seconds();
    }
    if (tenth <= p->last_tenth || cli_now_seconds() - p->stage_start < 0.5) return;
    p->last_tenth = tenth;
    fprintf(stderr, "  %s: %3d%%\n", stage, tenth * 10);
}

void cli_print_write_report(const mk_write_report *r)
{
    printf("precision: %u packed targets (%llu of %llu blocks float, %llu wide), %u float targets; "
           "max position quantization error %.3g (tolerance %.3g)\n",
           r->quantized_targets, (unsigned long long)r->float_entries, (unsigned long long)r->entry_count,
           (unsigned long long)r->wide_entries, r->float_targets, r->max_position_error, r->tolerance_used);
    if (r->max_normal_error > 0 || r->max_tangent_error > 0)
        printf("max normal quantization error %.3g, tangent %.3g\n", r->max_normal_error, r->max_tangent_error);
}

void cli_precision_of(const mk_asset *a, uint32_t *quantized, uint32_t *floats, double *max_error_bound)
{
    *quantized = *floats = 0;
    *max_error_bound = 0;
    for (uint32_t c = 0; c < a->channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(a, c, &ch);
        for (uint32_t k = 0; k < ch.target_count; k++) {
            mk_target_info t;
            mk_target_get(a, c, k, &t);
            if (t.quantized) {
                (*quantized)++;
                /* Rounding to the nearest step: the error is at most half a step. */
                if (t.position_scale * 0.5 > *max_error_bound) *max_error_bound = t.position_scale * 0.5;
            } else {
                (*floats)++;
            }
        }
    }
}

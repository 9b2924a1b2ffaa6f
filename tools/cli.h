/* SPDX-License-Identifier: MIT */
/* The morphkit command-line program: one verb per file (cmd_*.c), thin over the libraries.
 * Each verb declares its command line as a cli_verb (cli_args.h). */
#ifndef MK_CLI_H
#define MK_CLI_H

#include <stdio.h>
#include "blob_io.h"
#include "cli_args.h"
#include "import.h"

extern const cli_verb cli_verb_import, cli_verb_info, cli_verb_play, cli_verb_bake, cli_verb_export, cli_verb_conform,
    cli_verb_bench, cli_verb_embed, cli_verb_frames, cli_verb_render;

/* Prints the warnings of a raw model to stderr ("warning: ..."); nothing when there are none. */
void cli_print_warnings(const mk_raw_asset *raw);
/* Prints "morphkit <verb>: <error message>" to stderr; returns 1 (2 for invalid arguments). */
int cli_fail(const char *verb, const mk_error *err);

/* ---- outputs ---- */

/* One output of a command: a file written with the rules of blob_io.h, or standard output
 * ("-"). */
typedef struct cli_output {
    mk_output file;
    int to_stdout;
} cli_output;

/* Checks an output path before any work: "-" is standard output where allow_stdout; a file
 * name must end in one of `extensions` (NULL-terminated; not checked for devices and FIFOs),
 * whose content is described by `what` ("a .morph blob"); the output must not be one of
 * the inputs. Returns -1 when fine, else the exit status after printing the error. */
int cli_output_check(const cli_verb *verb, cli_output *out, const char *option, const char *path,
                     const char *const *extensions, const char *what, int allow_stdout, const char *const *inputs,
                     uint32_t input_count);
/* Writes the outputs all or none (standard output last). Returns 0 or the exit status. */
int cli_write_outputs(const cli_verb *verb, cli_output *outs, uint32_t count);

/* ---- depfiles ---- */

/* The files a command read, for a build system's depfile (make syntax, as ninja reads it):
 * "OUTPUT: INPUT...". Collect with cli_depfile_add (it fits the importers' and the bakers'
 * file_read callbacks); render with cli_depfile_text. */
typedef struct cli_depfile {
    char **paths;
    size_t count, capacity;
} cli_depfile;

void cli_depfile_add(void *depfile, const char *path);
/* The depfile's text for `target` (malloc'ed; NULL on OOM); frees the collected paths. */
char *cli_depfile_text(cli_depfile *d, const char *target, size_t *size);
void cli_depfile_free(cli_depfile *d);

/* ---- progress ---- */

/* Progress lines on stderr for long work: only when stderr is a terminal and not quiet;
 * a stage prints once it has run for half a second, then at most once per tenth. */
typedef struct cli_progress {
    int enabled;
    char stage[256];
    int last_tenth;
    double stage_start;
} cli_progress;

void cli_progress_init(cli_progress *p, int quiet);
/* fraction in [0, 1]; a negative fraction announces a stage right away (one line). */
void cli_progress_update(cli_progress *p, const char *stage, double fraction);
double cli_now_seconds(void);

/* Prints a blob writer's precision report to stdout: packed and float targets, the outlier
 * blocks (float32, or packed with int32 position offsets), the largest quantization errors and the
 * tolerance applied. */
void cli_print_write_report(const mk_write_report *r);

/* Targets stored quantized and as float, and the largest position error the quantized steps
 * allow (half a step). */
void cli_precision_of(const mk_asset *a, uint32_t *quantized, uint32_t *floats, double *max_error_bound);

#endif

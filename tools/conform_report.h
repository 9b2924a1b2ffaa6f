/* SPDX-License-Identifier: MIT */
/* `morphkit conform --report DIR`: DIR/index.html, a static page (no scripts) with a table of
 * every case and frame, and one PNG per compared frame: the played frame and the reference,
 * shaded, and the error heat map (distance per vertex), failing frames first. */
#ifndef MK_CONFORM_REPORT_H
#define MK_CONFORM_REPORT_H

#include "cli.h"
#include "conform.h"

typedef struct cli_report cli_report;

/* Checks DIR (created when absent; an error when it is not a folder). Returns -1 and *out,
 * else the exit status after printing the error. */
int cli_report_begin(const cli_verb *verb, const char *dir, const char *manifest, cli_report **out);
/* Makes options collect the compared meshes of the next frames. */
void cli_report_hook(cli_report *report, pb_conform_options *options);
/* After pb_conform_frame (asset: what was played, NULL when the import failed): draws the
 * frame's picture from the collected meshes and keeps its row. Returns -1 or the exit status. */
int cli_report_frame(cli_report *report, const pb_case *c, const pb_frame_spec *f, const pb_frame_result *r,
                     const mk_asset *asset);
/* Writes index.html and the pictures, all or none, and frees the report. Returns 0 or the exit
 * status. */
int cli_report_finish(cli_report *report);
void cli_report_free(cli_report *report);

#endif

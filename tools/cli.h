/* The morphkit command-line program: one verb per file (cmd_*.c), thin over the libraries. */
#ifndef MK_CLI_H
#define MK_CLI_H

#include <stdio.h>
#include "blob_io.h"
#include "import.h"

/* Each verb gets argv starting at the verb itself; returns the process exit status. */
int cmd_info(int argc, char **argv);
int cmd_play(int argc, char **argv);
int cmd_import(int argc, char **argv);
int cmd_export(int argc, char **argv);
int cmd_bake(int argc, char **argv);
int cmd_conform(int argc, char **argv);
int cmd_bench(int argc, char **argv);

/* Loads any supported input (.morph, .fbx, .gltf, .glb) into a raw model. */
mk_result cli_load_raw(const char *path, const mk_import_options *options, mk_raw_asset *raw,
                       mk_error *err);
/* Prints the warnings of a raw model to stderr ("warning: ..."), then "N warnings". */
void cli_print_warnings(const mk_raw_asset *raw);
/* Parses --precision float|q16 and --stacking additive|sequential values; -1 when invalid. */
int cli_parse_precision(const char *s);
int cli_parse_stacking(const char *s);
/* Prints "morphkit <verb>: <error message>" to stderr; returns 1 (or 2 for usage errors). */
int cli_fail(const char *verb, const mk_error *err);

#endif

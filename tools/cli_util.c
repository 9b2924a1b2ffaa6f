/* Shared helpers of the verbs. */
#include <string.h>
#include "cli.h"

mk_result cli_load_raw(const char *path, const mk_import_options *options, mk_raw_asset *raw, mk_error *err)
{
    mk_result r = mk_import_file(path, options, raw, err);
    if (r == MK_OK) r = mk_raw_group_channels(raw, err);
    return r;
}

void cli_print_warnings(const mk_raw_asset *raw)
{
    uint32_t shown = raw->warning_count < MK_RAW_MAX_WARNINGS ? raw->warning_count : MK_RAW_MAX_WARNINGS;
    for (uint32_t i = 0; i < shown && raw->warnings; i++) fprintf(stderr, "warning: %s\n", raw->warnings[i].message);
    if (raw->warning_count > shown) fprintf(stderr, "warning: ... %u more\n", raw->warning_count - shown);
    fprintf(stderr, "%u warning%s\n", raw->warning_count, raw->warning_count == 1 ? "" : "s");
}

int cli_parse_precision(const char *s)
{
    if (!s) return -1;
    if (!strcmp(s, "float")) return MK_PRECISION_FLOAT;
    if (!strcmp(s, "q16")) return MK_PRECISION_Q16;
    return -1;
}

int cli_parse_stacking(const char *s)
{
    if (!s) return -1;
    if (!strcmp(s, "additive")) return MK_STACKING_ADDITIVE;
    if (!strcmp(s, "sequential")) return MK_STACKING_SEQUENTIAL;
    return -1;
}

int cli_fail(const char *verb, const mk_error *err)
{
    fprintf(stderr, "morphkit %s: %s (%s)\n", verb, err->message, mk_result_name(err->code));
    return err->code == MK_ERROR_INVALID_ARGUMENT ? 2 : 1;
}

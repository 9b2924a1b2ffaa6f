/* morphkit import FILE -o OUT.morph [--stacking additive|sequential] [--precision float|q16]
 *                 [--tolerance D] [--channels SIDECAR.json] */
#include <stdlib.h>
#include <string.h>
#include "cli.h"

static int usage(void)
{
    fprintf(stderr, "usage: morphkit import FILE.fbx|FILE.gltf|FILE.glb -o OUT.morph [--stacking additive|sequential]\n"
                    "       [--precision float|q16] [--tolerance D] [--channels SIDECAR.json]\n");
    return 2;
}

int cmd_import(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    mk_import_options io = { 0 };
    mk_write_options wo = { 0 };
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-o") && v) { out = v; i++; }
        else if (!strcmp(a, "--stacking") && v) { int s = cli_parse_stacking(v); if (s < 0) return usage(); io.stacking = (mk_stacking)s; i++; }
        else if (!strcmp(a, "--precision") && v) { int p = cli_parse_precision(v); if (p < 0) return usage(); wo.precision = (mk_precision)p; i++; }
        else if (!strcmp(a, "--tolerance") && v) {
            char *end;
            wo.tolerance = strtof(v, &end);
            if (*end || !(wo.tolerance > 0)) { fprintf(stderr, "morphkit import: --tolerance needs a positive number\n"); return 2; }
            i++;
        }
        else if (!strcmp(a, "--channels") && v) { io.channels_sidecar = v; i++; }
        else if (!strcmp(a, "--help")) { usage(); return 0; }
        else if (a[0] != '-' && !in) in = a;
        else { fprintf(stderr, "morphkit import: unexpected argument '%s'\n", a); return usage(); }
    }
    if (!in || !out) return usage();
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_result r = cli_load_raw(in, &io, &raw, &err);
    cli_print_warnings(&raw);
    void *blob = NULL;
    size_t size = 0;
    mk_write_report report;
    if (r == MK_OK) r = mk_write_blob(&raw, &wo, &raw.arena, &blob, &size, &report, &err);
    if (r == MK_OK) r = mk_write_file_atomic(out, blob, size, &err);
    if (r != MK_OK) { mk_raw_free(&raw); return cli_fail("import", &err); }
    uint32_t targets = 0;
    for (uint32_t c = 0; c < raw.channel_count; c++) targets += raw.channels[c].target_count;
    printf("%s -> %s: %u meshes, %u channels, %u targets, %u clips, %zu bytes\n", in, out, raw.mesh_count,
           raw.channel_count, targets, raw.clip_count, size);
    printf("precision: %u int16 targets, %u float targets; max position quantization error %.3g (tolerance %.3g)\n",
           report.quantized_targets, report.float_targets, report.max_position_error, report.tolerance_used);
    if (report.max_normal_error > 0 || report.max_tangent_error > 0)
        printf("max normal quantization error %.3g, tangent %.3g\n", report.max_normal_error, report.max_tangent_error);
    mk_raw_free(&raw);
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* morphkit info FILE [--json]: meshes, channels with in-betweens and full weights, clips,
 * sizes, precision and the quantization error bound. Any input works; non-.morph inputs are
 * imported and written in memory with the default options first. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "asset.h"
#include "cli.h"
#include "frame_write.h"
#include "json_write.h"

/* Block entries over all meshes: of quantized targets stored as float32 (mk_mesh_float_entries),
 * or with int32 position offsets (mk_mesh_wide_entries). */
static uint64_t all_meshes(const mk_asset *a, uint64_t (*count)(const mk_asset *, uint32_t))
{
    uint64_t n = 0;
    for (uint32_t i = 0; i < a->mesh_count; i++) n += count(a, i);
    return n;
}

static void print_text(FILE *f, const pb_asset *l, const char *path)
{
    const mk_asset *a = &l->asset;
    uint32_t nq, nf;
    double bound;
    cli_precision_of(a, &nq, &nf, &bound);
    uint64_t fe = all_meshes(a, mk_mesh_float_entries), oe = all_meshes(a, mk_mesh_wide_entries);
    fprintf(f, "%s: %zu bytes, format v%u\n", path, l->blob_size, MK_FORMAT_VERSION);
    if (l->imported) {
        fprintf(f, "source: %s%s%s\n", l->raw.source_format[0] ? l->raw.source_format : "?",
                l->raw.source_creator[0] ? ", creator " : "", l->raw.source_creator);
        if (l->raw.unit_scale > 0) fprintf(f, "unit scale: %g cm per unit\n", (double)l->raw.unit_scale);
        if (l->raw.up_axis >= 0) fprintf(f, "up axis: %c\n", "XYZ"[l->raw.up_axis % 3]);
        fprintf(f, "import warnings: %u\n", l->raw.warning_count);
    }
    fprintf(f, "precision: %u quantized (packed) targets (%llu float blocks, %llu wide), %u float targets; "
               "max quantization error <= %.3g\n",
            nq, (unsigned long long)fe, (unsigned long long)oe, nf, bound);
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        fprintf(f, "mesh %u '%s': %u vertices (%u control points), %u triangles, %s%s%s stacking", i, m.name,
                m.vertex_count, m.control_point_count, m.triangle_count, m.has_normals ? "normals, " : "",
                m.has_tangents ? "tangents, " : "", m.stacking == MK_STACKING_SEQUENTIAL ? "sequential" : "additive");
        if (m.gltf_node >= 0)
            fprintf(f, ", glTF node %d mesh %d primitive %d", m.gltf_node, m.gltf_mesh, m.gltf_primitive);
        fprintf(f, "\n  target data: %llu bytes in %llu block entries (%llu float in quantized targets, %llu "
                   "wide)\n",
                (unsigned long long)m.target_bytes, (unsigned long long)m.entry_count,
                (unsigned long long)mk_mesh_float_entries(a, i), (unsigned long long)mk_mesh_wide_entries(a, i));
        for (uint32_t c = m.first_channel; c < m.first_channel + m.channel_count; c++) {
            mk_channel_info ch;
            mk_channel_get(a, c, &ch);
            fprintf(f, "  channel %u '%s': default %g, %u target%s%s\n", c, ch.name, (double)ch.default_weight,
                    ch.target_count, ch.target_count == 1 ? "" : "s", ch.target_count > 1 ? " (progressive)" : "");
            for (uint32_t k = 0; k < ch.target_count; k++) {
                mk_target_info t;
                mk_target_get(a, c, k, &t);
                fprintf(f, "    target '%s': full weight %g, %u vertices, %s%s%s\n", t.name, (double)t.full_weight,
                        t.moved_vertices, t.quantized ? "packed" : "float", t.has_normals ? ", normals" : "",
                        t.has_tangents ? ", tangents" : "");
            }
            if (ch.origin[0]) fprintf(f, "    baked from recipe: %s\n", ch.origin);
        }
    }
    for (uint32_t i = 0; i < a->clip_count; i++) {
        mk_clip_info c;
        mk_clip_get(a, i, &c);
        fprintf(f, "clip %u '%s': start %g s, duration %g s, %u tracks\n", i, c.name, (double)c.start,
                (double)c.duration, c.track_count);
    }
}

static void print_json(FILE *f, const pb_asset *l, const char *path)
{
    const mk_asset *a = &l->asset;
    uint32_t nq, nf;
    double bound;
    cli_precision_of(a, &nq, &nf, &bound);
    uint64_t fe = all_meshes(a, mk_mesh_float_entries), oe = all_meshes(a, mk_mesh_wide_entries);
    json_writer w;
    json_begin(&w, f, 1);
    json_object(&w, NULL);
    json_string(&w, "file", path);
    json_int(&w, "bytes", (long long)l->blob_size);
    json_int(&w, "format_version", MK_FORMAT_VERSION);
    if (l->imported) {
        json_string(&w, "source_format", l->raw.source_format);
        json_string(&w, "source_creator", l->raw.source_creator);
        json_number(&w, "unit_scale", l->raw.unit_scale);
        json_int(&w, "up_axis", l->raw.up_axis);
        json_int(&w, "warnings", l->raw.warning_count);
    }
    json_int(&w, "quantized_targets", nq);
    json_int(&w, "float_targets", nf);
    json_int(&w, "float_entries", (long long)fe);
    json_int(&w, "wide_entries", (long long)oe);
    json_number(&w, "max_quantization_error", bound);
    json_array(&w, "meshes");
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        pb_json_mesh_begin(&w, a, i, &m);
        json_int(&w, "triangles", m.triangle_count);
        json_bool(&w, "normals", m.has_normals);
        json_bool(&w, "tangents", m.has_tangents);
        json_string(&w, "stacking", m.stacking == MK_STACKING_SEQUENTIAL ? "sequential" : "additive");
        json_int(&w, "target_bytes", (long long)m.target_bytes);
        json_int(&w, "float_entries", (long long)mk_mesh_float_entries(a, i));
        json_int(&w, "wide_entries", (long long)mk_mesh_wide_entries(a, i));
        json_array(&w, "channels");
        for (uint32_t c = m.first_channel; c < m.first_channel + m.channel_count; c++) {
            mk_channel_info ch;
            mk_channel_get(a, c, &ch);
            json_object(&w, NULL);
            json_int(&w, "index", c);
            json_string(&w, "name", ch.name);
            json_number(&w, "default_weight", ch.default_weight);
            if (ch.origin[0]) json_string(&w, "origin", ch.origin);
            json_array(&w, "targets");
            for (uint32_t k = 0; k < ch.target_count; k++) {
                mk_target_info t;
                mk_target_get(a, c, k, &t);
                json_object(&w, NULL);
                json_string(&w, "name", t.name);
                json_number(&w, "full_weight", t.full_weight);
                json_int(&w, "vertices", t.moved_vertices);
                json_string(&w, "precision", t.quantized ? "q16" : "float");
                json_bool(&w, "normals", t.has_normals);
                json_bool(&w, "tangents", t.has_tangents);
                json_end_object(&w);
            }
            json_end_array(&w);
            json_end_object(&w);
        }
        json_end_array(&w);
        json_end_object(&w);
    }
    json_end_array(&w);
    json_array(&w, "clips");
    for (uint32_t i = 0; i < a->clip_count; i++) {
        mk_clip_info c;
        mk_clip_get(a, i, &c);
        json_object(&w, NULL);
        json_string(&w, "name", c.name);
        json_number(&w, "start", c.start);
        json_number(&w, "duration", c.duration);
        json_int(&w, "tracks", c.track_count);
        json_end_object(&w);
    }
    json_end_array(&w);
    json_end_object(&w);
}

typedef struct info_args {
    const char *input, *output;
    int json;
} info_args;

static int run_info(void *p);

static const cli_option options[] = {
    { "--json", NULL, CLI_FLAG, offsetof(info_args, json),
      "Print JSON (one object: file facts, meshes, channels, targets, clips) instead of text.", NULL, NULL, 0, 0, 0,
      0 },
    { "-o", "OUT", CLI_STRING, offsetof(info_args, output),
      "Where to write the description: a file, or - for standard output.", "-", NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_info = {
    .name = "info",
    .usage = "FILE [--json] [-o OUT]",
    .summary = "describe an asset: meshes, channels, in-betweens, clips, sizes",
    .description = "Describes FILE: its meshes (vertices, control points, triangles, normals, tangents, stacking), "
                   "channels with their "
                   "in-between targets and full weights, clips, byte sizes, precision and the quantization error "
                   "bound. A file that is "
                   "not a .morph blob is imported and written in memory with the default options first.",
    .positional = "FILE",
    .positional_help = "A .morph blob, or any file 'morphkit import' reads.",
    .positional_offset = offsetof(info_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(info_args),
    .run = run_info,
};

static int run_info(void *p)
{
    info_args *a = p;
    const cli_verb *verb = &cli_verb_info;
    cli_output out;
    const char *inputs[] = { a->input };
    int status = cli_output_check(verb, &out, "-o", a->output, NULL, "a description", 1, inputs, 1);
    if (status >= 0) return status;
    pb_asset l;
    mk_error err;
    if (pb_asset_load(a->input, NULL, NULL, &l, &err)) {
        pb_asset_free(&l);
        return cli_fail(verb->name, &err);
    }
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    if (!f) {
        pb_asset_free(&l);
        fprintf(stderr, "morphkit info: out of memory\n");
        return CLI_EXIT_FAILURE;
    }
    if (a->json)
        print_json(f, &l, a->input);
    else
        print_text(f, &l, a->input);
    fclose(f);
    out.file.data = text;
    out.file.size = size;
    status = cli_write_outputs(verb, &out, 1);
    free(text);
    pb_asset_free(&l);
    return status;
}

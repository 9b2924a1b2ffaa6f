/* SPDX-License-Identifier: MIT */
/* morphkit export: meshes, morph targets (baked ones included) and weight clips as glTF 2.0,
 * so any glTF viewer plays the result, plus the channel sidecar that lets
 * `morphkit import OUT.glb --channels OUT.channels.json` restore progressive channels.
 * Behaviour: docs/importing-gltf.md. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "fbx_write.h"
#include "gltf_export.h"

typedef struct export_args {
    const char *input, *output, *sidecar, *channels;
    int no_sidecar;
} export_args;

static int run_export(void *p);

static const cli_option options[] = {
    { "-o", "OUT.glb|OUT.gltf|OUT.fbx", CLI_STRING, offsetof(export_args, output),
      "The file to write: .glb (binary glTF), .gltf (JSON with the buffer embedded), or .fbx (binary FBX 7.4: "
      "channels with their in-betweens, clips as animation stacks; no sidecar needed).", NULL, NULL, 0, 0, 1, 0 },
    { "--sidecar", "PATH", CLI_STRING, offsetof(export_args, sidecar),
      "Where to write the channel sidecar (JSON). Default: OUT without its extension + .channels.json.", NULL, NULL, 0,
      0, 0, 0 },
    { "--no-sidecar", NULL, CLI_FLAG, offsetof(export_args, no_sidecar),
      "Write no sidecar (a re-import then sees one channel per glTF target).", NULL, NULL, 0, 0, 0, 0 },
    { "--channels", "SIDECAR.json", CLI_STRING, offsetof(export_args, channels),
      "glTF input only: the sidecar that groups the input's targets into channels.", NULL, NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_export = {
    .name = "export",
    .usage = "FILE -o OUT.glb|OUT.gltf|OUT.fbx [options]",
    .summary = "write an asset as glTF 2.0 (plus a channel sidecar) or FBX",
    .description = "Writes FILE's meshes, morph targets and weight clips as glTF 2.0. A progressive channel becomes "
                   "one glTF target "
                   "per in-between with weight tracks that reproduce morphkit's playback; the channel sidecar records "
                   "the grouping so "
                   "a re-import restores the channels. The glTF and the sidecar are written both or neither. As .fbx, "
                   "each mesh becomes a model with its geometry and blend shape channels, in-betweens as FBX "
                   "in-between shapes (docs/baking.md, \"Baking into your own file\").",
    .positional = "FILE",
    .positional_help = "A .morph blob, or any file 'morphkit import' reads.",
    .positional_offset = offsetof(export_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(export_args),
    .run = run_export,
};

/* -o OUT.fbx: the asset as a new binary FBX file. */
static int export_fbx(const cli_verb *verb, const export_args *a)
{
    static const char *const fbx_ext[] = { ".fbx", NULL };
    const char *inputs[] = { a->input, a->channels };
    cli_output out;
    int status = cli_output_check(verb, &out, "-o", a->output, fbx_ext, "an FBX file", 0, inputs, 2);
    if (status >= 0) return status;
    /* A scene: meshes without morph targets are written too. */
    mk_import_options io = { .channels_sidecar = a->channels, .keep_plain_meshes = 1 };
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_fbx_write_report rep;
    void *bytes = NULL;
    mk_result r = mk_import_file(a->input, &io, &raw, &err);
    cli_print_warnings(&raw);
    if (r == MK_OK) r = mk_fbx_export(&raw, &raw.arena, &bytes, &out.file.size, &rep, &err);
    out.file.data = bytes;
    if (r != MK_OK) {
        mk_raw_free(&raw);
        return cli_fail(verb->name, &err);
    }
    status = cli_write_outputs(verb, &out, 1);
    if (status == 0) {
        printf("%s -> %s: %u meshes, %u channels with %u shapes, %u clips as animation stacks, %zu bytes\n", a->input,
               a->output, rep.meshes, rep.channels, rep.shapes, rep.clips, out.file.size);
        if (rep.progressive_channels)
            printf("note: %u channel%s with in-betweens (FBX's own progressive shapes, as Maya writes them; ufbx plays "
                   "them; Blender 3.4's FBX importer cannot read in-betweens and refuses such files)\n",
                   rep.progressive_channels, rep.progressive_channels == 1 ? "" : "s");
    }
    mk_raw_free(&raw);
    return status;
}

static int run_export(void *p)
{
    export_args *a = p;
    const cli_verb *verb = &cli_verb_export;
    if (mk_path_has_extension(a->output, ".fbx")) {
        if (a->sidecar || a->no_sidecar)
            return cli_usage_error(verb, "--sidecar and --no-sidecar are for glTF output (an FBX holds its channels)");
        return export_fbx(verb, a);
    }
    if (a->no_sidecar && a->sidecar) return cli_usage_error(verb, "--sidecar and --no-sidecar contradict each other");
    int gltf_input = mk_path_has_extension(a->input, ".gltf") || mk_path_has_extension(a->input, ".glb");
    if (a->channels && !gltf_input)
        return cli_usage_error(verb, "--channels: channel sidecars apply to glTF input only (%s is not .gltf or .glb)",
                               a->input);
    /* Default sidecar: OUT.glb -> OUT.channels.json, next to the glTF. */
    char default_sidecar[4200];
    if (!a->sidecar && !a->no_sidecar) {
        const char *dot = strrchr(a->output, '.'), *slash = strrchr(a->output, '/');
        size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - a->output) : strlen(a->output);
        snprintf(default_sidecar, sizeof default_sidecar, "%.*s.channels.json", (int)stem, a->output);
        a->sidecar = default_sidecar;
    }
    static const char *const gltf_ext[] = { ".glb", ".gltf", NULL }, *const json_ext[] = { ".json", NULL };
    const char *inputs[] = { a->input, a->channels, a->output };
    cli_output outs[2];
    int status = cli_output_check(verb, &outs[0], "-o", a->output, gltf_ext, "glTF", 0, inputs, 2);
    if (status >= 0) return status;
    uint32_t count = 1;
    if (a->sidecar) {
        status =
            cli_output_check(verb, &outs[1], "--sidecar", a->sidecar, json_ext, "a JSON channel sidecar", 0, inputs, 3);
        if (status >= 0) return status;
        count = 2;
        if (!strcmp(outs[0].file.target, outs[1].file.target))
            return cli_usage_error(verb, "--sidecar %s is the same file as -o %s", a->sidecar, a->output);
    }
    mk_gltf_container container = mk_path_has_extension(a->output, ".gltf") ? MK_GLTF_JSON : MK_GLTF_GLB;

    mk_import_options io = { .channels_sidecar = a->channels };
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_gltf_export_report rep;
    void *gltf = NULL;
    char *sidecar = NULL;
    size_t gltf_size = 0, sidecar_size = 0;
    mk_result r = mk_import_file(a->input, &io, &raw, &err);
    cli_print_warnings(&raw);
    if (r == MK_OK)
        r = mk_export_gltf_memory(&raw, container, &raw.arena, &gltf, &gltf_size, count == 2 ? &sidecar : NULL,
                                  &sidecar_size, &rep, &err);
    if (r != MK_OK) {
        mk_raw_free(&raw);
        return cli_fail(verb->name, &err);
    }
    outs[0].file.data = gltf;
    outs[0].file.size = gltf_size;
    outs[1].file.data = sidecar;
    outs[1].file.size = sidecar_size;
    status = cli_write_outputs(verb, outs, count);
    if (status) {
        mk_raw_free(&raw);
        return status;
    }
    printf("%s -> %s: %u meshes, %u glTF targets, %u clips\n", a->input, a->output, rep.meshes, rep.targets, rep.clips);
    if (rep.progressive_channels)
        printf("note: %u progressive (in-between) channel%s exported as one glTF target per in-between, with weight\n"
               "      tracks that reproduce morphkit's piecewise-linear playback\n",
               rep.progressive_channels, rep.progressive_channels == 1 ? "" : "s");
    if (rep.resampled_tracks)
        printf("note: %u node weight animation%s sampled to LINEAR keys (in-betweens, differing key times,\n"
               "      weighted or constant-next tangents cannot be written exactly in glTF)\n",
               rep.resampled_tracks, rep.resampled_tracks == 1 ? "" : "s");
    if (rep.padding_targets)
        printf("note: %u empty padding target%s added so the primitives of a node have the same target list\n",
               rep.padding_targets, rep.padding_targets == 1 ? "" : "s");
    if (rep.fixed_normals)
        printf("note: %u zero-length base normal%s/tangents replaced by face normals (glTF requires unit vectors)\n",
               rep.fixed_normals, rep.fixed_normals == 1 ? "" : "s");
    if (count == 2)
        printf("channel sidecar: %s (re-import with: morphkit import %s --channels %s -o OUT.morph)\n", a->sidecar,
               a->output, a->sidecar);
    mk_raw_free(&raw);
    return 0;
}

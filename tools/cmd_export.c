/* morphkit export FILE -o OUT.glb|OUT.gltf [--sidecar PATH | --no-sidecar] [--channels SIDECAR.json]
 *
 * Writes meshes, morph targets (baked ones included) and weight clips as glTF 2.0, so any glTF
 * viewer plays the result, plus the channel sidecar (default: OUT without its extension +
 * ".channels.json") so `morphkit import OUT.glb --channels OUT.channels.json` restores
 * progressive channels. Behaviour: docs/importing-gltf.md. */
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "gltf_import.h"

static int usage(void)
{
    fprintf(stderr, "usage: morphkit export FILE.morph|FILE.fbx|FILE.gltf|FILE.glb -o OUT.glb|OUT.gltf\n"
                    "       [--sidecar PATH | --no-sidecar] [--channels SIDECAR.json]\n");
    return 2;
}

int cmd_export(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *sidecar = NULL;
    int no_sidecar = 0;
    mk_import_options io = { 0 };
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-o") && v) { out = v; i++; }
        else if (!strcmp(a, "--sidecar") && v) { sidecar = v; i++; }
        else if (!strcmp(a, "--no-sidecar")) no_sidecar = 1;
        else if (!strcmp(a, "--channels") && v) { io.channels_sidecar = v; i++; }
        else if (!strcmp(a, "--help")) { usage(); return 0; }
        else if (a[0] != '-' && !in) in = a;
        else { fprintf(stderr, "morphkit export: unexpected argument '%s'\n", a); return usage(); }
    }
    if (!in || !out) return usage();

    /* Default sidecar: OUT.glb -> OUT.channels.json, next to the glTF. */
    char *default_sidecar = NULL;
    if (!sidecar && !no_sidecar) {
        size_t n = strlen(out);
        const char *dot = strrchr(out, '.'), *slash = strrchr(out, '/');
        size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - out) : n;
        default_sidecar = malloc(stem + sizeof ".channels.json");
        if (!default_sidecar) { fprintf(stderr, "morphkit export: out of memory\n"); return 1; }
        memcpy(default_sidecar, out, stem);
        strcpy(default_sidecar + stem, ".channels.json");
        sidecar = default_sidecar;
    }
    if (no_sidecar) sidecar = NULL;

    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_gltf_export_report rep;
    mk_result r = cli_load_raw(in, &io, &raw, &err);
    cli_print_warnings(&raw);
    if (r == MK_OK) r = mk_export_gltf(&raw, out, sidecar, &rep, &err);
    if (r != MK_OK) {
        mk_raw_free(&raw);
        free(default_sidecar);
        return cli_fail("export", &err);
    }
    printf("%s -> %s: %u meshes, %u glTF targets, %u clips\n", in, out, rep.meshes, rep.targets, rep.clips);
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
    if (sidecar)
        printf("channel sidecar: %s (re-import with: morphkit import %s --channels %s -o OUT.morph)\n", sidecar, out, sidecar);
    mk_raw_free(&raw);
    free(default_sidecar);
    return 0;
}

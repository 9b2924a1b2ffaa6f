/* morphkit: one command-line program with verbs; all logic lives in the libraries. */
#include <string.h>
#include "cli.h"

static const struct verb {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} verbs[] = {
    { "import", cmd_import, "import FILE.fbx|FILE.gltf|FILE.glb -o OUT.morph   convert a source file" },
    { "info", cmd_info, "info FILE.morph [--json]                           describe an asset" },
    { "play", cmd_play, "play FILE.morph [--clip C] [--time T] ... -o OUT    evaluate one frame" },
    { "bake", cmd_bake, "bake IN --recipe RECIPE.json -o OUT.morph          add baked channels" },
    { "export", cmd_export, "export FILE.morph -o OUT.glb|OUT.gltf              write glTF" },
    { "conform", cmd_conform, "conform CASES.json [--case S] [--precision P]      check against reference frames" },
    { "bench", cmd_bench, "bench [FILE.morph] [--vertices N] ... [--json]     measure evaluation speed" },
};

static void usage(FILE *f)
{
    fprintf(f, "usage: morphkit VERB ...\n\nverbs:\n");
    for (size_t i = 0; i < sizeof verbs / sizeof verbs[0]; i++) fprintf(f, "  morphkit %s\n", verbs[i].summary);
    fprintf(f, "\n'morphkit VERB --help' shows a verb's options.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) { usage(stderr); return 2; }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) { usage(stdout); return 0; }
    if (!strcmp(argv[1], "--version")) { printf("morphkit 0.1.0 (format v%u)\n", MK_FORMAT_VERSION); return 0; }
    for (size_t i = 0; i < sizeof verbs / sizeof verbs[0]; i++)
        if (!strcmp(argv[1], verbs[i].name)) return verbs[i].run(argc - 1, argv + 1);
    fprintf(stderr, "morphkit: unknown verb '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}

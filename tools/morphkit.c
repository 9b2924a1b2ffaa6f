/* SPDX-License-Identifier: MIT */
/* morphkit: one command-line program with verbs; all logic lives in the libraries. */
#include <string.h>
#include "cli.h"
#include "page_recycle.h"
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__SANITIZE_ADDRESS__)
#define MK_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MK_ADDRESS_SANITIZER 1
#endif
#endif
#ifndef MK_ADDRESS_SANITIZER
#define MK_ADDRESS_SANITIZER 0
#endif

static const cli_verb *const verbs[] = {
    &cli_verb_import, &cli_verb_info, &cli_verb_play, &cli_verb_bake,
    &cli_verb_export, &cli_verb_embed, &cli_verb_frames, &cli_verb_render, &cli_verb_conform, &cli_verb_bench,
};
#define VERB_COUNT (sizeof verbs / sizeof verbs[0])

static void usage(FILE *f)
{
    fprintf(f, "usage: morphkit VERB [arguments]\n       morphkit help VERB\n       morphkit --version\n\nverbs:\n");
    for (size_t i = 0; i < VERB_COUNT; i++) fprintf(f, "  %-9s %s\n", verbs[i]->name, verbs[i]->summary);
    fprintf(f, "\n'morphkit help VERB' or 'morphkit VERB --help' shows a verb's arguments and options.\n"
               "exit status: 0 success, 1 failure, 2 usage error\n");
}

static const cli_verb *find_verb(const char *name)
{
    for (size_t i = 0; i < VERB_COUNT; i++)
        if (!strcmp(name, verbs[i]->name)) return verbs[i];
    return NULL;
}

int main(int argc, char **argv)
{
#if defined(__GLIBC__)
    /* glibc raises its trim threshold to twice the largest block freed so far (up to 64 MB) and
     * keeps that much freed memory in the process. An import frees its input and parse data
     * before its largest steps (target normals, the blob); a fixed threshold gives that memory
     * back to the system and lowers the peak (blob8: 245 MB -> 167 MB). */
    mallopt(M_TRIM_THRESHOLD, 1 << 20);
#endif
#if !MK_ADDRESS_SANITIZER
    /* Freed large blocks' pages go to the next large blocks instead of back to the system
     * (page_recycle.h): blob8's import touched 79k fresh pages for a 129 MB peak, 55k for a
     * 133 MB peak with this (docs/performance.md). The cap bounds the pages kept: 32 MB kept the
     * peak within 3x the input file there; larger caps saved a few thousand faults more and
     * reached it. Off under AddressSanitizer, which cannot see a use after free inside reused
     * pages. */
    mk_recycle_enable((size_t)32 << 20);
#endif
    mk_output_cleanup_on_signals();   /* Ctrl-C leaves no temporary files beside the outputs */
    if (argc < 2) {
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    const char *first = argv[1];
    if (!strcmp(first, "--help") || !strcmp(first, "-h") || (!strcmp(first, "help") && argc == 2)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    if (!strcmp(first, "--version")) {
        printf("morphkit %s (blob format v%u)\n", MK_VERSION_STRING, MK_FORMAT_VERSION);
        return CLI_EXIT_OK;
    }
    if (!strcmp(first, "help")) {
        const cli_verb *v = find_verb(argv[2]);
        if (!v || argc > 3) {
            fprintf(stderr, "morphkit help: unknown verb '%s'\n\n", argv[2]);
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
        cli_print_help(v, stdout);
        return CLI_EXIT_OK;
    }
    const cli_verb *v = find_verb(first);
    if (!v) {
        fprintf(stderr, "morphkit: unknown verb '%s'\n\n", first);
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    /* Each verb's arguments fit in a small struct; 256 bytes with 16-byte alignment is room
     * for all of them (checked below). */
    _Alignas(16) unsigned char args[256];
    if (v->args_size > sizeof args) return CLI_EXIT_FAILURE;
    int status = cli_parse(v, argc - 1, argv + 1, args);
    return status >= 0 ? status : v->run(args);
}

/* SPDX-License-Identifier: MIT */
/* morphkit embed: a .morph blob as C source, so a program carries its assets with no file
 * loading: a 16-byte aligned const array and its size, plus a header declaring them. */
#include <ctype.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"

typedef struct embed_args {
    const char *input, *output, *header, *symbol, *depfile;
} embed_args;

static int run_embed(void *p);

static const cli_option options[] = {
    { "-o", "OUT.c", CLI_STRING, offsetof(embed_args, output), "The C source to write.", NULL, NULL, 0, 0, 1, 0 },
    { "--header", "OUT.h", CLI_STRING, offsetof(embed_args, header),
      "The header declaring the array and its size. Default: OUT with .h for .c.", NULL, NULL, 0, 0, 0, 0 },
    { "--symbol", "NAME", CLI_STRING, offsetof(embed_args, symbol),
      "The array's name (a C identifier); NAME_size is its size in bytes. Default: the input's file name, with "
      "characters that are not letters, digits or _ replaced by _.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--depfile", "PATH", CLI_STRING, offsetof(embed_args, depfile),
      "Also write a depfile for build systems: the C source depends on the blob.", NULL, NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_embed = {
    .name = "embed",
    .usage = "FILE.morph -o OUT.c [options]",
    .summary = "write a .morph blob as a C array to compile into a program",
    .description = "Checks that FILE is a valid .morph blob (mk_asset_open) and writes it as C source: "
                   "'_Alignas(16) const unsigned char NAME[]' and 'const size_t NAME_size', and a header declaring both. "
                   "The program opens the array in place with mk_asset_open(NAME, NAME_size, ...).",
    .positional = "FILE.morph",
    .positional_help = "The blob to embed.",
    .positional_offset = offsetof(embed_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(embed_args),
    .run = run_embed,
};

/* A C identifier from a path's file name without extension. */
static void symbol_from_path(const char *path, char *out, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = 0;
    if (!isalpha((unsigned char)base[0]) && base[0] != '_' && n + 1 < size) out[n++] = '_';
    for (const char *p = base; *p && *p != '.' && n + 1 < size; p++)
        out[n++] = isalnum((unsigned char)*p) ? *p : '_';
    out[n] = 0;
}

static int valid_symbol(const char *s)
{
    if (!isalpha((unsigned char)s[0]) && s[0] != '_') return 0;
    for (; *s; s++)
        if (!isalnum((unsigned char)*s) && *s != '_') return 0;
    return 1;
}

static int run_embed(void *p)
{
    embed_args *a = p;
    const cli_verb *verb = &cli_verb_embed;
    char symbol[256], header_path[4200];
    if (a->symbol && !valid_symbol(a->symbol)) return cli_usage_error(verb, "--symbol: \"%s\" is not a C identifier", a->symbol);
    if (a->symbol) snprintf(symbol, sizeof symbol, "%s", a->symbol);
    else symbol_from_path(a->input, symbol, sizeof symbol);
    if (!a->header) {
        size_t n = strlen(a->output);
        if (mk_path_has_extension(a->output, ".c")) n -= 2;
        snprintf(header_path, sizeof header_path, "%.*s.h", (int)n, a->output);
        a->header = header_path;
    }
    static const char *const c_ext[] = { ".c", NULL }, *const h_ext[] = { ".h", NULL };
    const char *inputs[] = { a->input };
    cli_output outs[3];
    int status = cli_output_check(verb, &outs[0], "-o", a->output, c_ext, "C source", 0, inputs, 1);
    if (status < 0) status = cli_output_check(verb, &outs[1], "--header", a->header, h_ext, "a C header", 0, inputs, 1);
    if (status < 0 && a->depfile) status = cli_output_check(verb, &outs[2], "--depfile", a->depfile, NULL, "a depfile", 0, inputs, 1);
    if (status >= 0) return status;
    if (!strcmp(outs[0].file.target, outs[1].file.target))
        return cli_usage_error(verb, "--header %s is the same file as -o %s", a->header, a->output);

    mk_arena arena;
    mk_arena_init(&arena, NULL);
    void *blob;
    size_t size;
    mk_error err;
    mk_asset asset;
    mk_result r = mk_read_file(&arena, a->input, 0, &blob, &size, &err);
    if (r == MK_OK) r = mk_asset_open(blob, size, &asset, &err);
    if (r != MK_OK) {
        mk_arena_free_all(&arena);
        return cli_fail(verb->name, &err);
    }
    /* The source: 16 bytes a line as hex, so a large blob stays a quick compile. */
    size_t cap = size * 7 + 1024, n = 0;   /* "0xab, " per byte and 4 spaces per 16 */
    char *c = malloc(cap), *h = malloc(2048), *dep = NULL;
    if (!c || !h) {
        free(c);
        free(h);
        mk_arena_free_all(&arena);
        fprintf(stderr, "morphkit embed: out of memory\n");
        return CLI_EXIT_FAILURE;
    }
    const char *header_name = strrchr(a->header, '/') ? strrchr(a->header, '/') + 1 : a->header;
    n += (size_t)snprintf(c + n, cap - n,
                          "/* Generated by morphkit embed from a .morph blob (format v%u, %zu bytes); do not edit. */\n"
                          "#include \"%s\"\n\n_Alignas(16) const unsigned char %s[%zu] = {\n",
                          MK_FORMAT_VERSION, size, header_name, symbol, size);
    static const char hex[] = "0123456789abcdef";
    const unsigned char *bytes = blob;
    for (size_t i = 0; i < size; i++) {
        if (i % 16 == 0) { c[n++] = ' '; c[n++] = ' '; c[n++] = ' '; c[n++] = ' '; }
        c[n++] = '0'; c[n++] = 'x'; c[n++] = hex[bytes[i] >> 4]; c[n++] = hex[bytes[i] & 15]; c[n++] = ',';
        c[n++] = i % 16 == 15 || i + 1 == size ? '\n' : ' ';
    }
    n += (size_t)snprintf(c + n, cap - n, "};\nconst size_t %s_size = %zu;\n", symbol, size);
    size_t hn = (size_t)snprintf(h, 2048,
                                 "/* Generated by morphkit embed; do not edit. */\n#ifndef %s_MORPH_H\n#define %s_MORPH_H\n\n"
                                 "#include <stddef.h>\n\n/* A .morph blob, 16-byte aligned: mk_asset_open(%s, %s_size, ...). */\n"
                                 "extern const unsigned char %s[];\nextern const size_t %s_size;\n\n#endif\n",
                                 symbol, symbol, symbol, symbol, symbol, symbol);
    outs[0].file.data = c;
    outs[0].file.size = n;
    outs[1].file.data = h;
    outs[1].file.size = hn;
    if (a->depfile) {
        cli_depfile deps = { 0 };
        cli_depfile_add(&deps, a->input);
        dep = cli_depfile_text(&deps, a->output, &outs[2].file.size);
        outs[2].file.data = dep;
    }
    status = a->depfile && !dep ? CLI_EXIT_FAILURE : cli_write_outputs(verb, outs, a->depfile ? 3 : 2);
    if (status == 0)
        printf("%s -> %s, %s: %s[%zu], %u meshes, %u channels, %u clips\n", a->input, a->output, a->header, symbol, size,
               asset.mesh_count, asset.channel_count, asset.clip_count);
    free(c);
    free(h);
    free(dep);
    mk_arena_free_all(&arena);
    return status;
}

/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include "cli_args.h"

int cli_usage_error(const cli_verb *verb, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "morphkit %s: ", verb->name);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(see 'morphkit %s --help')\n", verb->name);
    va_end(ap);
    return CLI_EXIT_USAGE;
}

/* Index of `value` in "a|b|c", or -1. */
static int choice_index(const char *choices, const char *value)
{
    size_t n = strlen(value);
    int index = 0;
    for (const char *p = choices; *p; index++) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == n && !strncmp(p, value, n)) return index;
        if (!bar) break;
        p = bar + 1;
    }
    return -1;
}

/* Stores the value of option o; returns 0 or prints the error and returns -1. */
static int store_value(const cli_verb *verb, const cli_option *o, const char *v, void *args)
{
    char *at = (char *)args + o->offset;
    if (!v[0]) return cli_usage_error(verb, "%s: the value is empty", o->name), -1;
    switch (o->kind) {
    case CLI_FLAG:
        *(int *)(void *)at = 1;
        return 0;
    case CLI_STRING:
        *(const char **)(void *)at = v;
        return 0;
    case CLI_CHOICE: {
        int k = choice_index(o->choices, v);
        if (k < 0) return cli_usage_error(verb, "%s: \"%s\" is not %s", o->name, v, o->choices), -1;
        *(int *)(void *)at = k;
        return 0;
    }
    case CLI_UINT: {
        const char *p = v;
        while (*p >= '0' && *p <= '9') p++;
        if (*p || p == v)
            return cli_usage_error(verb, "%s: \"%s\" is not a whole number (accepted: %.0f to %.0f)", o->name, v,
                                   o->min, o->max),
                   -1;
        errno = 0;
        unsigned long long x = strtoull(v, NULL, 10);
        if (errno == ERANGE || (double)x < o->min || (double)x > o->max)
            return cli_usage_error(verb, "%s: %s is out of range (accepted: %.0f to %.0f)", o->name, v, o->min, o->max),
                   -1;
        *(uint64_t *)(void *)at = x;
        return 0;
    }
    case CLI_NUMBER: {
        char *end;
        errno = 0;
        double x = strtod(v, &end);
        if (*end || end == v || !isfinite(x) || errno == ERANGE)
            return cli_usage_error(verb, "%s: \"%s\" is not a finite number (accepted: %g to %g)", o->name, v, o->min,
                                   o->max),
                   -1;
        if (x < o->min || x > o->max)
            return cli_usage_error(verb, "%s: %s is out of range (accepted: %g to %g)", o->name, v, o->min, o->max), -1;
        *(double *)(void *)at = x;
        return 0;
    }
    }
    return -1;
}

static const cli_option *find_option(const cli_verb *verb, const char *name)
{
    for (size_t i = 0; i < verb->option_count; i++)
        if (!strcmp(verb->options[i].name, name)) return &verb->options[i];
    return NULL;
}

int cli_parse(const cli_verb *verb, int argc, char **argv, void *args)
{
    memset(args, 0, verb->args_size);
    for (size_t i = 0; i < verb->option_count; i++) {
        const cli_option *o = &verb->options[i];
        if (o->fallback && store_value(verb, o, o->fallback, args) != 0) return CLI_EXIT_USAGE;
    }
    unsigned char seen[64] = { 0 };
    int have_positional = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            cli_print_help(verb, stdout);
            return CLI_EXIT_OK;
        }
        if (a[0] == '-' && a[1]) {
            const cli_option *o = find_option(verb, a);
            if (!o) return cli_usage_error(verb, "unknown option '%s'", a);
            size_t k = (size_t)(o - verb->options);
            if (k < sizeof seen && seen[k]) return cli_usage_error(verb, "%s is given twice", a);
            if (k < sizeof seen) seen[k] = 1;
            if (o->given_offset) *(int *)(void *)((char *)args + o->given_offset) = 1;
            if (o->kind == CLI_FLAG) {
                *(int *)(void *)((char *)args + o->offset) = 1;
                continue;
            }
            if (i + 1 >= argc) {
                if (o->kind == CLI_CHOICE) return cli_usage_error(verb, "%s needs a value: %s", a, o->choices);
                return cli_usage_error(verb, "%s needs a value (%s)", a, o->value);
            }
            if (store_value(verb, o, argv[++i], args) != 0) return CLI_EXIT_USAGE;
            continue;
        }
        if (!verb->positional || have_positional) return cli_usage_error(verb, "unexpected argument '%s'", a);
        *(const char **)(void *)((char *)args + verb->positional_offset) = a;
        have_positional = 1;
    }
    if (verb->positional && verb->positional_required && !have_positional)
        return cli_usage_error(verb, "missing %s", verb->positional);
    for (size_t i = 0; i < verb->option_count; i++) {
        const cli_option *o = &verb->options[i];
        if (o->required && !(i < sizeof seen && seen[i]))
            return cli_usage_error(verb, "missing %s %s", o->name, o->value ? o->value : "");
    }
    return -1;
}

/* Prints text wrapped at `width` columns, every line indented by `indent` spaces except the
 * first, which continues at column `column`. */
static void print_wrapped(FILE *f, const char *text, int indent, int column, int width)
{
    int col = column;
    const char *p = text;
    while (*p) {
        while (*p == ' ') p++;
        const char *word = p;
        while (*p && *p != ' ' && *p != '\n') p++;
        int len = (int)(p - word);
        if (col > indent && col + 1 + len > width) {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
        } else if (col > indent) {
            fputc(' ', f);
            col++;
        } else if (col < indent) {
            fprintf(f, "%*s", indent - col, "");
            col = indent;
        }
        fprintf(f, "%.*s", len, word);
        col += len;
        if (*p == '\n') {
            p++;
            fprintf(f, "\n");
            col = 0;
        }
    }
    fputc('\n', f);
}

#define HELP_WIDTH  96
#define HELP_COLUMN 26

static void print_entry(FILE *f, const char *left, const char *text)
{
    int n = fprintf(f, "  %s", left);
    if (n + 2 > HELP_COLUMN) {
        fputc('\n', f);
        n = 0;
    }
    fprintf(f, "%*s", HELP_COLUMN - n, "");
    print_wrapped(f, text, HELP_COLUMN, HELP_COLUMN, HELP_WIDTH);
}

void cli_print_help(const cli_verb *verb, FILE *f)
{
    fprintf(f, "usage: morphkit %s %s\n\n", verb->name, verb->usage);
    print_wrapped(f, verb->description, 0, 0, HELP_WIDTH);
    if (verb->positional) {
        fprintf(f, "\narguments:\n");
        print_entry(f, verb->positional, verb->positional_help);
    }
    fprintf(f, "\noptions:\n");
    for (size_t i = 0; i < verb->option_count; i++) {
        const cli_option *o = &verb->options[i];
        char left[96], text[1024];
        snprintf(left, sizeof left, "%s%s%s", o->name, o->value ? " " : "", o->value ? o->value : "");
        int n = snprintf(text, sizeof text, "%s", o->help);
        if (o->kind == CLI_CHOICE && n < (int)sizeof text)
            n += snprintf(text + n, sizeof text - (size_t)n, " One of %s.", o->choices);
        if ((o->kind == CLI_UINT || o->kind == CLI_NUMBER) && n < (int)sizeof text)
            n += snprintf(text + n, sizeof text - (size_t)n,
                          o->kind == CLI_UINT ? " Accepted: %.0f to %.0f." : " Accepted: %g to %g.", o->min, o->max);
        if (o->fallback && n < (int)sizeof text)
            n += snprintf(text + n, sizeof text - (size_t)n, " Default: %s.", o->fallback);
        if (o->required && n < (int)sizeof text) snprintf(text + n, sizeof text - (size_t)n, " Required.");
        print_entry(f, left, text);
    }
    print_entry(f, "-h, --help", "Print this help and exit.");
    fprintf(f, "\nexit status: 0 success, 1 failure, 2 usage error\n");
}

/* SPDX-License-Identifier: MIT */
/* The command line of each verb, declared once as data: its usage line, description,
 * positional argument and options (value kind, accepted range or choices, default, unit,
 * meaning). One parser reads argv against that table, checks every value and prints exact
 * errors; the same table prints `morphkit help VERB` / `morphkit VERB --help`, which
 * docs/cli.md quotes (a test fails when they drift).
 *
 * Exit statuses: 0 success, 1 failure, 2 usage error (CLI_EXIT_*). */
#ifndef MK_CLI_ARGS_H
#define MK_CLI_ARGS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

enum { CLI_EXIT_OK = 0, CLI_EXIT_FAILURE = 1, CLI_EXIT_USAGE = 2 };

typedef enum cli_kind {
    CLI_FLAG,   /* no value; stores int 1 */
    CLI_STRING, /* stores const char * (non-empty) */
    CLI_CHOICE, /* one of `choices` ("a|b|c"); stores int index */
    CLI_UINT,   /* whole number in [min, max]; stores uint64_t */
    CLI_NUMBER  /* finite number in [min, max]; stores double */
} cli_kind;

typedef struct cli_option {
    const char *name;  /* "--vertices", "-o" */
    const char *value; /* placeholder shown in help ("N"); NULL for flags */
    cli_kind kind;
    size_t offset;        /* where the value goes in the verb's argument struct */
    const char *help;     /* meaning, with its unit */
    const char *fallback; /* default, parsed like a given value before argv; NULL: none */
    const char *choices;  /* CLI_CHOICE: "additive|sequential" */
    double min, max;      /* CLI_UINT / CLI_NUMBER: accepted range, inclusive */
    int required;
    size_t given_offset; /* when nonzero: an int set to 1 where the option was given */
} cli_option;

typedef struct cli_verb {
    const char *name;
    const char *usage;       /* after "morphkit VERB " */
    const char *summary;     /* one line for `morphkit --help` */
    const char *description; /* a paragraph (wrapped when printed) */
    const char *positional;  /* placeholder of the one positional argument, or NULL */
    const char *positional_help;
    size_t positional_offset;
    int positional_required;
    const cli_option *options;
    size_t option_count;
    size_t args_size; /* sizeof the verb's argument struct */
    int (*run)(void *args);
} cli_verb;

/* Parses argv (argv[0] is the verb) into args (args_size bytes, zeroed here, defaults
 * applied first). Returns -1 when parsing succeeded, else the exit status to return:
 * 0 after printing --help, CLI_EXIT_USAGE after printing the error. */
int cli_parse(const cli_verb *verb, int argc, char **argv, void *args);
/* Prints the verb's help (usage, description, arguments, options with defaults, exit codes). */
void cli_print_help(const cli_verb *verb, FILE *f);
/* Prints "morphkit VERB: message" and a hint to --help on stderr; returns CLI_EXIT_USAGE. */
int cli_usage_error(const cli_verb *verb, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#endif

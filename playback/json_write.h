/* SPDX-License-Identifier: MIT */
/* A minimal streaming JSON writer for the CLI's outputs (commas and nesting tracked). */
#ifndef MK_JSON_WRITE_H
#define MK_JSON_WRITE_H

#include <stdio.h>

typedef struct json_writer {
    FILE *f;
    int depth;
    int first[64]; /* per depth: no element written yet */
    int pretty;
} json_writer;

void json_begin(json_writer *w, FILE *f, int pretty);
void json_object(json_writer *w, const char *key); /* key NULL inside arrays / at top */
void json_array(json_writer *w, const char *key);
void json_end_object(json_writer *w);
void json_end_array(json_writer *w);
void json_string(json_writer *w, const char *key, const char *value);
void json_number(json_writer *w, const char *key, double value);
void json_int(json_writer *w, const char *key, long long value);
void json_bool(json_writer *w, const char *key, int value);
void json_null(json_writer *w, const char *key);
/* An array of floats on one line. */
void json_floats(json_writer *w, const char *key, const float *values, size_t count);

#endif

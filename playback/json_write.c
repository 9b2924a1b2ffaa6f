/* SPDX-License-Identifier: MIT */
#include <math.h>
#include "json_write.h"

void json_begin(json_writer *w, FILE *f, int pretty)
{
    w->f = f;
    w->depth = 0;
    w->first[0] = 1;
    w->pretty = pretty;
}

static void indent(json_writer *w)
{
    if (!w->pretty) return;
    fputc('\n', w->f);
    for (int i = 0; i < w->depth; i++) fputs("  ", w->f);
}

static void put_escaped(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') {
            fputc('\\', f);
            fputc(c, f);
        } else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void element(json_writer *w, const char *key)
{
    if (w->depth > 0) {
        if (!w->first[w->depth]) fputc(',', w->f);
        indent(w);
    }
    w->first[w->depth] = 0;
    if (key) {
        put_escaped(w->f, key);
        fputs(w->pretty ? ": " : ":", w->f);
    }
}

static void open_container(json_writer *w, const char *key, char c)
{
    element(w, key);
    fputc(c, w->f);
    if (w->depth < 63) w->depth++;
    w->first[w->depth] = 1;
}

static void close_container(json_writer *w, char c)
{
    int empty = w->first[w->depth];
    if (w->depth > 0) w->depth--;
    if (!empty) indent(w);
    fputc(c, w->f);
    if (w->depth == 0) fputc('\n', w->f);
}

void json_object(json_writer *w, const char *key)
{
    open_container(w, key, '{');
}
void json_array(json_writer *w, const char *key)
{
    open_container(w, key, '[');
}
void json_end_object(json_writer *w)
{
    close_container(w, '}');
}
void json_end_array(json_writer *w)
{
    close_container(w, ']');
}

void json_string(json_writer *w, const char *key, const char *value)
{
    element(w, key);
    put_escaped(w->f, value);
}

static void put_number(FILE *f, double v)
{
    if (!isfinite(v)) {
        fputs("null", f);
        return;
    }
    fprintf(f, "%.9g", v);
}

void json_number(json_writer *w, const char *key, double value)
{
    element(w, key);
    put_number(w->f, value);
}

void json_int(json_writer *w, const char *key, long long value)
{
    element(w, key);
    fprintf(w->f, "%lld", value);
}

void json_null(json_writer *w, const char *key)
{
    element(w, key);
    fputs("null", w->f);
}

void json_bool(json_writer *w, const char *key, int value)
{
    element(w, key);
    fputs(value ? "true" : "false", w->f);
}

void json_floats(json_writer *w, const char *key, const float *values, size_t count)
{
    element(w, key);
    fputc('[', w->f);
    for (size_t i = 0; i < count; i++) {
        if (i) fputc(',', w->f);
        put_number(w->f, values[i]);
    }
    fputc(']', w->f);
}

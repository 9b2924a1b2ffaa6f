/* SPDX-License-Identifier: MIT */
/* ASCII FBX reader (6.x and 7.x syntax) into the fbx_doc tree.
 *
 * Syntax (ufbx.c ASCII tokenizer; observed in Maya, Blender, ZBrush and 3ds Max files):
 *   Name: value, value, ... { children }
 * Values are integers, floats, "quoted strings" (entities &quot; &cr; &lf; &amp;), bare words
 * (T, Y, N, W: the first character is the value) and 7.x arrays `*N { a: v,v,v }`. A value list
 * continues on the next line after a trailing comma (6.x arrays span many lines). `;` starts a
 * comment anywhere a value may end, also inside arrays and on lines between the items of a
 * list. Node names may be quoted ("Transport Tool Settings":). A leading comma
 * (`Content: , "..."`) is allowed. NaN and infinity are numbers in every spelling exporters use
 * (fbx_ascii_not_finite), never characters: the importer then reports them where they are
 * used, exactly as for a binary file.
 *
 * Arrays keep their text span and are parsed on access (fbx_dom.c). The version comes from
 * the first comment line "; FBX 7.5.0 project file" (else FBXHeaderExtension/FBXVersion, read
 * by the scene step).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fbx_internal.h"

typedef struct ascii_parser {
    fbx_doc *doc;
    const char *text;
    size_t size, pos;
    fbx_node *nodes;
    size_t node_top, node_cap;
    fbx_value *values;
    size_t value_top, value_cap;
} ascii_parser;

static int is_space(char c) { return c == ' ' || c == '\t'; }
static int is_newline(char c) { return c == '\n' || c == '\r'; }
static int is_name_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           c == '_' || c == '|' || c == '-' || c == '.' || c == '+';
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

static char lower(char c) { return c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c; }

/* Case-insensitive comparison of [s, s + n) with the lower-case word `w`. */
static int word_is(const char *s, size_t n, const char *w)
{
    size_t l = strlen(w);
    if (n != l) return 0;
    for (size_t i = 0; i < n; i++)
        if (lower(s[i]) != w[i]) return 0;
    return 1;
}

int fbx_ascii_not_finite(const char *s, size_t n, double *out)
{
    size_t i = 0;
    int negative = 0;
    if (n && (s[0] == '-' || s[0] == '+')) negative = s[i++] == '-';
    const char *w = s + i;
    size_t m = n - i;
    if (word_is(w, m, "inf") || word_is(w, m, "infinity")) {
        *out = negative ? -(double)INFINITY : (double)INFINITY;
        return 1;
    }
    /* C99 allows "nan(n-char-sequence)"; MSVC prints "nan(ind)". */
    if (m >= 3 && word_is(w, 3, "nan") && (m == 3 || (w[3] == '(' && w[m - 1] == ')'))) {
        *out = (double)NAN;
        return 1;
    }
    /* Windows CRT: "1.#INF", "-1.#IND", "1.#QNAN", "1.#SNAN"; "%f" appends digits ("1.#INF00"). */
    size_t j = 0;
    while (j < m && is_digit(w[j])) j++;
    if (j == 0 || j + 2 > m || w[j] != '.' || w[j + 1] != '#') return 0;
    size_t word = j += 2;
    while (j < m && !is_digit(w[j])) j++;
    size_t word_length = j - word;
    while (j < m && is_digit(w[j])) j++;
    if (j != m) return 0;
    if (word_is(w + word, word_length, "inf")) {
        *out = negative ? -(double)INFINITY : (double)INFINITY;
        return 1;
    }
    if (word_is(w + word, word_length, "ind") || word_is(w + word, word_length, "qnan") ||
        word_is(w + word, word_length, "snan")) {
        *out = (double)NAN;
        return 1;
    }
    return 0;
}

int fbx_ascii_array_token(const char *s, size_t size, size_t *pos, size_t *start)
{
    size_t i = *pos;
    for (;;) {
        while (i < size && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r' || s[i] == ','))
            i++;
        if (i < size && s[i] == ';') {  /* a comment runs to the end of its line */
            while (i < size && s[i] != '\n') i++;
            continue;
        }
        break;
    }
    if (i >= size) {
        *pos = i;
        return 0;
    }
    *start = i;
    while (i < size && s[i] != ',' && s[i] != ' ' && s[i] != '\t' && s[i] != '\n' && s[i] != '\r' && s[i] != ';')
        i++;
    *pos = i;
    return 1;
}

static mk_result perr(ascii_parser *p, size_t at, const char *what)
{
    /* Line number helps humans; computing it only on error keeps parsing linear. */
    size_t line = 1;
    for (size_t i = 0; i < at && i < p->size; i++) line += p->text[i] == '\n';
    return mk_error_set(p->doc->err, MK_ERROR_PARSE, at, "FBX ASCII line %zu: %s", line, what);
}

static mk_result push_value(ascii_parser *p, const fbx_value *v)
{
    if (p->value_top == p->value_cap) {
        size_t cap = p->value_cap ? p->value_cap * 2 : 256;
        fbx_value *grown = mk_arena_realloc(p->doc->arena, p->values, p->value_cap * sizeof *p->values,
                                            cap * sizeof *p->values);
        if (!grown) return mk_error_oom(p->doc->err, "FBX values");
        p->values = grown;
        p->value_cap = cap;
    }
    p->values[p->value_top++] = *v;
    return MK_OK;
}

static mk_result push_node(ascii_parser *p, const fbx_node *n)
{
    if (p->node_top == p->node_cap) {
        size_t cap = p->node_cap ? p->node_cap * 2 : 256;
        fbx_node *grown = mk_arena_realloc(p->doc->arena, p->nodes, p->node_cap * sizeof *p->nodes,
                                           cap * sizeof *p->nodes);
        if (!grown) return mk_error_oom(p->doc->err, "FBX nodes");
        p->nodes = grown;
        p->node_cap = cap;
    }
    p->nodes[p->node_top++] = *n;
    return MK_OK;
}

static void skip_line(ascii_parser *p)
{
    while (p->pos < p->size && p->text[p->pos] != '\n') p->pos++;
}

/* Skips whitespace, newlines and comments between nodes. */
static void skip_blank(ascii_parser *p)
{
    while (p->pos < p->size) {
        char c = p->text[p->pos];
        if (is_space(c) || is_newline(c)) p->pos++;
        else if (c == ';') skip_line(p);
        else break;
    }
}

/* Decodes a quoted string's entities into arena memory (or points into the text when there
 * is nothing to decode). */
static mk_result read_string(ascii_parser *p, fbx_value *v)
{
    size_t start = ++p->pos;
    const char *end = memchr(p->text + start, '"', p->size - start);
    if (!end) return perr(p, start - 1, "unterminated string");
    size_t length = (size_t)(end - (p->text + start));
    p->pos = start + length + 1;
    if (length > UINT32_MAX) return perr(p, start, "string too long");
    v->kind = FBX_STRING;
    v->type = 'S';
    const char *s = p->text + start;
    if (!memchr(s, '&', length)) {
        v->u.s.data = s;
        v->u.s.length = (uint32_t)length;
        return MK_OK;
    }
    char *out = mk_arena_alloc(p->doc->arena, length + 1);
    if (!out) return mk_error_oom(p->doc->err, "FBX string");
    size_t n = 0;
    for (size_t i = 0; i < length;) {
        static const struct { const char *entity; char c; } entities[] = {
            { "&quot;", '"' }, { "&cr;", '\r' }, { "&lf;", '\n' }, { "&amp;", '&' },
            { "&lt;", '<' }, { "&gt;", '>' } };
        int matched = 0;
        if (s[i] == '&') {
            for (size_t e = 0; e < sizeof entities / sizeof entities[0]; e++) {
                size_t el = strlen(entities[e].entity);
                if (length - i >= el && memcmp(s + i, entities[e].entity, el) == 0) {
                    out[n++] = entities[e].c;
                    i += el;
                    matched = 1;
                    break;
                }
            }
        }
        if (!matched) out[n++] = s[i++];  /* a lone '&' is literal */
    }
    v->u.s.data = out;
    v->u.s.length = (uint32_t)n;
    return MK_OK;
}

/* Parses a number token [start, end) into v (integer when it has only digits and a sign). */
static mk_result parse_number(ascii_parser *p, size_t start, size_t end, fbx_value *v)
{
    size_t length = end - start;
    const char *s = p->text + start;
    int integer = 1;
    for (size_t i = 0; i < length; i++)
        if (!((s[i] >= '0' && s[i] <= '9') || (i == 0 && (s[i] == '-' || s[i] == '+')))) integer = 0;
    if (integer && length > 0 && !(length == 1 && (s[0] == '-' || s[0] == '+'))) {
        uint64_t value = 0;
        size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
        int overflow = 0;
        for (; i < length; i++) {
            uint64_t digit = (uint64_t)(s[i] - '0');
            if (value > (UINT64_MAX - digit) / 10) overflow = 1;
            value = value * 10 + digit;
        }
        if (!overflow && value <= (uint64_t)INT64_MAX + (s[0] == '-')) {
            v->kind = FBX_INT;
            v->type = 'L';
            v->u.i = s[0] == '-' ? (int64_t)(0 - value) : (int64_t)value;
            return MK_OK;
        }
    }
    double d;
    if (!fbx_ascii_not_finite(s, length, &d)) {
        /* strtod needs a terminated copy: the input buffer is not NUL-terminated. */
        char buffer[96];
        if (length >= sizeof buffer) return perr(p, start, "number token too long");
        memcpy(buffer, s, length);
        buffer[length] = 0;
        char *stop;
        d = strtod(buffer, &stop);
        if (stop == buffer || *stop) {
            char what[80];
            snprintf(what, sizeof what, "malformed number '%.40s'", buffer);
            return perr(p, start, what);
        }
    }
    /* NaN and infinity stay what they are: the importer reports them where the value is used
     * (the element and its byte offset), as it does for binary files. */
    v->kind = FBX_FLOAT;
    v->type = 'D';
    v->u.f = d;
    return MK_OK;
}

static mk_result parse_array(ascii_parser *p, fbx_value *v)
{
    size_t at = p->pos++;  /* '*' */
    uint64_t count = 0;
    size_t digits = 0;
    while (p->pos < p->size && p->text[p->pos] >= '0' && p->text[p->pos] <= '9') {
        count = count * 10 + (uint64_t)(p->text[p->pos] - '0');
        if (count > UINT32_MAX) return perr(p, at, "array count too large");
        p->pos++;
        digits++;
    }
    if (!digits) return perr(p, at, "'*' without an array count");
    skip_blank(p);
    if (p->pos >= p->size || p->text[p->pos] != '{') return perr(p, p->pos, "expected '{' after array count");
    p->pos++;
    skip_blank(p);
    size_t data_start = p->pos, data_end = p->pos;
    if (p->pos < p->size && p->text[p->pos] != '}') {
        /* "a:" introduces the values */
        while (p->pos < p->size && is_name_char(p->text[p->pos])) p->pos++;
        if (p->pos >= p->size || p->text[p->pos] != ':') return perr(p, p->pos, "expected 'a:' in array");
        p->pos++;
        data_start = p->pos;
        /* The closing brace, skipping comments (one may contain '}'). */
        size_t close = p->pos;
        while (close < p->size && p->text[close] != '}') {
            if (p->text[close] == ';') {
                while (close < p->size && p->text[close] != '\n') close++;
            } else {
                close++;
            }
        }
        if (close >= p->size) return perr(p, at, "unterminated array");
        data_end = close;
        p->pos = data_end;
    }
    if (p->pos >= p->size || p->text[p->pos] != '}') return perr(p, at, "unterminated array");
    p->pos++;
    /* Each element needs at least one character: bounds the declared count. */
    if (count > (uint64_t)(data_end - data_start) + 1)
        return perr(p, at, "array declares more elements than its text can hold");
    v->kind = FBX_ARRAY;
    v->type = 'a';
    v->count = (uint32_t)count;
    v->u.a.data = (const uint8_t *)p->text + data_start;
    v->u.a.size = data_end - data_start;
    return MK_OK;
}

static mk_result parse_node(ascii_parser *p, uint32_t depth);

/* Parses children until the matching '}' (or end of file at depth 0). */
static mk_result parse_children(ascii_parser *p, fbx_node *node, uint32_t depth, int top_level)
{
    size_t first = p->node_top;
    for (;;) {
        skip_blank(p);
        if (p->pos >= p->size) {
            if (!top_level) return perr(p, node->offset, "node is missing its closing '}'");
            break;
        }
        if (p->text[p->pos] == '}') {
            if (top_level) return perr(p, p->pos, "unexpected '}'");
            p->pos++;
            node->end = p->pos;
            break;
        }
        mk_result r = parse_node(p, depth);
        if (r != MK_OK) return r;
    }
    size_t count = p->node_top - first;
    if (count) {
        node->children = mk_arena_array(p->doc->arena, count, sizeof(fbx_node));
        if (!node->children) return mk_error_oom(p->doc->err, "FBX nodes");
        memcpy(node->children, p->nodes + first, count * sizeof(fbx_node));
        node->child_count = (uint32_t)count;
        p->node_top = first;
    }
    return MK_OK;
}

static mk_result parse_node(ascii_parser *p, uint32_t depth)
{
    if (depth >= FBX_MAX_DEPTH) return perr(p, p->pos, "nodes nested too deeply");
    fbx_node node;
    memset(&node, 0, sizeof node);
    node.offset = p->pos;
    node.depth = depth;
    /* Name: bare identifier or quoted string, then ':' */
    if (p->text[p->pos] == '"') {
        const char *end = memchr(p->text + p->pos + 1, '"', p->size - p->pos - 1);
        if (!end) return perr(p, p->pos, "unterminated quoted node name");
        node.name = p->text + p->pos + 1;
        node.name_length = (uint32_t)(end - node.name);
        p->pos = (size_t)(end - p->text) + 1;
    } else {
        size_t start = p->pos;
        while (p->pos < p->size && is_name_char(p->text[p->pos])) p->pos++;
        if (p->pos == start || p->pos - start > 255) return perr(p, start, "expected a node name");
        node.name = p->text + start;
        node.name_length = (uint32_t)(p->pos - start);
    }
    while (p->pos < p->size && is_space(p->text[p->pos])) p->pos++;
    if (p->pos >= p->size || p->text[p->pos] != ':') return perr(p, node.offset, "expected ':' after node name");
    p->pos++;

    size_t first_value = p->value_top;
    int pending_comma = 0, opens_children = 0;
    while (p->pos < p->size) {
        char c = p->text[p->pos];
        if (is_space(c)) { p->pos++; continue; }
        if (c == ';') { skip_line(p); continue; }
        if (is_newline(c)) {
            if (pending_comma) { p->pos++; continue; }
            /* Value lists may continue on the next line: Maya 6.x and ZBrush start
             * continuation lines with the comma; Blender 2.79 writes "Key:" alone on its
             * line with the numbers below. A node name never starts with these. */
            size_t look = p->pos;
            for (;;) {  /* blank and comment lines may separate the items */
                while (look < p->size && (is_space(p->text[look]) || is_newline(p->text[look]))) look++;
                if (look >= p->size || p->text[look] != ';') break;
                while (look < p->size && p->text[look] != '\n') look++;
            }
            if (look < p->size) {
                char d = p->text[look];
                int number = (d >= '0' && d <= '9') || d == '-' || d == '+' || d == '.';
                if (d == ',' || (number && p->value_top == first_value)) { p->pos = look; continue; }
            }
            break;
        }
        if (c == ',') { p->pos++; pending_comma = 1; continue; }
        if (c == '{') { p->pos++; opens_children = 1; break; }
        if (c == '}') break;
        fbx_value v;
        memset(&v, 0, sizeof v);
        v.offset = p->pos;
        mk_result r;
        if (c == '"') {
            r = read_string(p, &v);
        } else if (c == '*') {
            r = parse_array(p, &v);
        } else if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') {
            size_t start = p->pos;
            while (p->pos < p->size) {
                char d = p->text[p->pos];
                if (d == ',' || is_space(d) || is_newline(d) || d == '}' || d == ';' || d == '{') break;
                p->pos++;
            }
            r = parse_number(p, start, p->pos, &v);
        } else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_') {
            size_t start = p->pos;
            while (p->pos < p->size && is_name_char(p->text[p->pos])) p->pos++;
            /* "nan(ind)": the parenthesized part belongs to the number. */
            if (p->pos - start == 3 && word_is(p->text + start, 3, "nan") && p->pos < p->size && p->text[p->pos] == '(') {
                size_t close = p->pos;
                while (close < p->size && close - start < 64 && p->text[close] != ')' && !is_newline(p->text[close])) close++;
                if (close < p->size && p->text[close] == ')') p->pos = close + 1;
            }
            /* NaN and infinity spelled as words ("nan", "INF", "Infinity") are numbers, never
             * the character 'N' or 'I'; other bare words are characters. */
            double not_finite;
            if (fbx_ascii_not_finite(p->text + start, p->pos - start, &not_finite)) {
                r = parse_number(p, start, p->pos, &v);
            } else {
                v.kind = FBX_CHAR;
                v.type = 'C';
                v.u.i = (unsigned char)c;
                r = MK_OK;
            }
        } else {
            return perr(p, p->pos, "unexpected character in value list");
        }
        if (r != MK_OK) return r;
        r = push_value(p, &v);
        if (r != MK_OK) return r;
        pending_comma = 0;
    }
    size_t value_count = p->value_top - first_value;
    if (value_count > FBX_MAX_VALUES_PER_NODE) return perr(p, node.offset, "too many values in one node");
    if (value_count) {
        node.values = mk_arena_array(p->doc->arena, value_count, sizeof(fbx_value));
        if (!node.values) return mk_error_oom(p->doc->err, "FBX values");
        memcpy(node.values, p->values + first_value, value_count * sizeof(fbx_value));
        node.value_count = (uint32_t)value_count;
        p->value_top = first_value;
    }
    node.end = p->pos;
    if (opens_children) {
        mk_result r = parse_children(p, &node, depth + 1, 0);
        if (r != MK_OK) return r;
    }
    return push_node(p, &node);
}

mk_result fbx_parse_ascii(fbx_doc *doc)
{
    ascii_parser p;
    memset(&p, 0, sizeof p);
    p.doc = doc;
    p.text = (const char *)doc->data;
    p.size = doc->size;
    doc->version = 0;
    doc->header_version = 0;
    /* "; FBX 7.5.0 project file" on the first line gives the version. */
    {
        size_t i = 0;
        if (p.size >= 3 && (unsigned char)p.text[0] == 0xEF && (unsigned char)p.text[1] == 0xBB &&
            (unsigned char)p.text[2] == 0xBF)
            i = p.pos = 3;  /* UTF-8 byte order mark */
        const char *tag = "; FBX ";
        if (p.size - i > 11 && memcmp(p.text + i, tag, 6) == 0) {
            const char *s = p.text + i + 6;
            if (s[0] >= '0' && s[0] <= '9' && s[1] == '.' && s[2] >= '0' && s[2] <= '9' && s[3] == '.' &&
                s[4] >= '0' && s[4] <= '9')
                doc->version = (uint32_t)((s[0] - '0') * 1000 + (s[2] - '0') * 100 + (s[4] - '0') * 10);
        }
    }
    memset(&doc->root, 0, sizeof doc->root);
    doc->root.name = "";
    mk_result r = parse_children(&p, &doc->root, 0, 1);
    mk_arena_release(doc->arena, p.nodes);
    mk_arena_release(doc->arena, p.values);
    return r;
}

/* SPDX-License-Identifier: MIT */
/* New FBX nodes and their binary or ASCII bytes (fbx_node_write.h). The binary layout is the
 * reader's (fbx_binary.c): EndOffset, NumProperties, PropertyListLen (u32 below header version
 * 7500, u64 from it), NameLen, Name, the values, the children and a null record. Only
 * little-endian files are written. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "fbx_node_write.h"

void fbx_bytes_append(fbx_bytes *b, const void *data, size_t size)
{
    if (b->failed || size == 0) return;
    if (size > b->cap - b->size) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap - b->size < size) {
            if (cap > SIZE_MAX / 2) { b->failed = 1; return; }
            cap *= 2;
        }
        uint8_t *grown = mk_arena_realloc(b->arena, b->data, b->cap, cap);
        if (!grown) { b->failed = 1; return; }
        b->data = grown;
        b->cap = cap;
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
}

void fbx_bytes_printf(fbx_bytes *b, const char *fmt, ...)
{
    char small[256];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (n < 0) { b->failed = 1; return; }
    if ((size_t)n < sizeof small) { fbx_bytes_append(b, small, (size_t)n); return; }
    char *big = mk_arena_alloc(b->arena, (size_t)n + 1);
    if (!big) { b->failed = 1; return; }
    va_start(ap, fmt);
    vsnprintf(big, (size_t)n + 1, fmt, ap);
    va_end(ap);
    fbx_bytes_append(b, big, (size_t)n);
    mk_arena_release(b->arena, big);
}

/* ---- builder ---- */

fbx_wnode *fbx_wn_new(mk_arena *arena, const char *name)
{
    fbx_wnode *n = mk_arena_alloc(arena, sizeof *n);
    if (n) n->name = name;
    return n;
}

/* Grows *array (elements of `size` bytes, *cap slots) to hold one more. */
static int grow(mk_arena *arena, void **array, uint32_t count, uint32_t *cap, size_t size)
{
    if (count < *cap) return 1;
    uint32_t want = *cap ? *cap * 2 : 4;
    void *grown = mk_arena_realloc(arena, *array, *cap * size, want * size);
    if (!grown) return 0;
    *array = grown;
    *cap = want;
    return 1;
}

fbx_wnode *fbx_wn_child(mk_arena *arena, fbx_wnode *parent, const char *name)
{
    fbx_wnode *n = fbx_wn_new(arena, name);
    if (!n || !grow(arena, (void **)&parent->children, parent->child_count, &parent->child_cap, sizeof *parent->children))
        return NULL;
    parent->children[parent->child_count++] = n;
    return n;
}

int fbx_wn_add(mk_arena *arena, fbx_wnode *node, fbx_wvalue value)
{
    if (!grow(arena, (void **)&node->values, node->value_count, &node->value_cap, sizeof *node->values)) return 0;
    node->values[node->value_count++] = value;
    return 1;
}

int fbx_wn_int(mk_arena *arena, fbx_wnode *node, int32_t v)
{
    return fbx_wn_add(arena, node, (fbx_wvalue){ .type = 'I', .u.i = v });
}

int fbx_wn_long(mk_arena *arena, fbx_wnode *node, int64_t v)
{
    return fbx_wn_add(arena, node, (fbx_wvalue){ .type = 'L', .u.i = v });
}

int fbx_wn_double(mk_arena *arena, fbx_wnode *node, double v)
{
    return fbx_wn_add(arena, node, (fbx_wvalue){ .type = 'D', .u.d = v });
}

int fbx_wn_string(mk_arena *arena, fbx_wnode *node, const char *s, size_t length)
{
    char *copy = mk_arena_strndup(arena, s, length);
    return copy && fbx_wn_add(arena, node, (fbx_wvalue){ .type = 'S', .count = (uint32_t)length, .u.s = copy });
}

int fbx_wn_object_name(mk_arena *arena, fbx_wnode *node, int binary, const char *cls, const char *name)
{
    size_t c = strlen(cls), n = strlen(name);
    char *s = mk_arena_alloc(arena, c + n + 3);
    if (!s) return 0;
    if (binary) {
        memcpy(s, name, n);
        s[n] = 0;
        s[n + 1] = 1;
        memcpy(s + n + 2, cls, c);
    } else {
        memcpy(s, cls, c);
        s[c] = s[c + 1] = ':';
        memcpy(s + c + 2, name, n);
    }
    return fbx_wn_add(arena, node, (fbx_wvalue){ .type = 'S', .count = (uint32_t)(c + n + 2), .u.s = s });
}

fbx_wnode *fbx_wn_prop(mk_arena *arena, fbx_wnode *properties70, const char *name, const char *type,
                       const char *label, const char *flags, fbx_wvalue value)
{
    fbx_wnode *p = fbx_wn_child(arena, properties70, "P");
    if (!p || !fbx_wn_string(arena, p, name, strlen(name)) || !fbx_wn_string(arena, p, type, strlen(type)) ||
        !fbx_wn_string(arena, p, label, strlen(label)) || !fbx_wn_string(arena, p, flags, strlen(flags)) ||
        !fbx_wn_add(arena, p, value))
        return NULL;
    return p;
}

fbx_wnode *fbx_wn_array(mk_arena *arena, fbx_wnode *parent, const char *name, char type, const void *data,
                        uint32_t count)
{
    fbx_wnode *n = fbx_wn_child(arena, parent, name);
    fbx_wvalue v = { .type = type, .count = count };
    switch (type) {
    case 'i': v.u.ai = data; break;
    case 'l': v.u.al = data; break;
    case 'f': v.u.af = data; break;
    default: v.u.ad = data; break;
    }
    return n && fbx_wn_add(arena, n, v) ? n : NULL;
}

/* ---- binary ---- */

static void put_le(uint8_t *at, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++) at[i] = (uint8_t)(v >> (8 * i));
}

void fbx_record_header(fbx_bytes *out, size_t offset, int wide, uint64_t end, uint64_t value_count, uint64_t list_length,
                       uint8_t name_length)
{
    if (out->failed) return;
    if (!wide && (end > UINT32_MAX || value_count > UINT32_MAX || list_length > UINT32_MAX)) {
        out->too_large = 1;
        return;
    }
    uint8_t *at = out->data + offset;
    int w = wide ? 8 : 4;
    put_le(at, end, w);
    put_le(at + w, value_count, w);
    put_le(at + 2 * w, list_length, w);
    at[3 * w] = name_length;
}

static void append_le(fbx_bytes *out, uint64_t v, int bytes)
{
    uint8_t b[8];
    put_le(b, v, bytes);
    fbx_bytes_append(out, b, (size_t)bytes);
}

static void write_value(fbx_bytes *out, const fbx_wvalue *v)
{
    uint8_t type = (uint8_t)v->type;
    fbx_bytes_append(out, &type, 1);
    switch (v->type) {
    case 'I': append_le(out, (uint64_t)(uint32_t)(int32_t)v->u.i, 4); break;
    case 'L': append_le(out, (uint64_t)v->u.i, 8); break;
    case 'D': {
        uint64_t bits;
        memcpy(&bits, &v->u.d, 8);
        append_le(out, bits, 8);
        break;
    }
    case 'S': case 'R':
        append_le(out, v->count, 4);
        fbx_bytes_append(out, v->u.s, v->count);
        break;
    case 'i': case 'l': case 'f': case 'd': {
        const int elem = v->type == 'i' || v->type == 'f' ? 4 : 8;
        if ((uint64_t)v->count * (uint64_t)elem > UINT32_MAX) { out->too_large = 1; return; }
        append_le(out, v->count, 4);
        append_le(out, 0, 4);  /* raw, not deflated */
        append_le(out, (uint64_t)v->count * (uint64_t)elem, 4);
        for (uint32_t k = 0; k < v->count; k++) {
            uint32_t bits32;
            uint64_t bits64;
            switch (v->type) {
            case 'i': append_le(out, (uint64_t)(uint32_t)v->u.ai[k], 4); break;
            case 'l': append_le(out, (uint64_t)v->u.al[k], 8); break;
            case 'f': memcpy(&bits32, &v->u.af[k], 4); append_le(out, bits32, 4); break;
            default: memcpy(&bits64, &v->u.ad[k], 8); append_le(out, bits64, 8); break;
            }
        }
        break;
    }
    default: out->failed = 1; break;
    }
}

void fbx_wn_write_binary(fbx_bytes *out, const fbx_wnode *node, uint64_t base, int wide)
{
    const size_t header = wide ? 25 : 13;
    const size_t start = out->size;
    const size_t name_length = strlen(node->name);
    static const uint8_t zeros[25];
    if (name_length > 255) { out->failed = 1; return; }
    fbx_bytes_append(out, zeros, header);
    fbx_bytes_append(out, node->name, name_length);
    const size_t values_at = out->size;
    for (uint32_t i = 0; i < node->value_count; i++) write_value(out, &node->values[i]);
    const size_t list_length = out->size - values_at;
    for (uint32_t i = 0; i < node->child_count; i++) fbx_wn_write_binary(out, node->children[i], base, wide);
    if (node->child_count || !node->value_count) fbx_bytes_append(out, zeros, header);
    fbx_record_header(out, start, wide, base + out->size, node->value_count, list_length, (uint8_t)name_length);
}

/* ---- ASCII ---- */

static void tabs(fbx_bytes *out, uint32_t depth)
{
    for (uint32_t i = 0; i < depth; i++) fbx_bytes_append(out, "\t", 1);
}

/* Shortest text that reads back as the same double. */
static void write_double(fbx_bytes *out, double d)
{
    char text[40];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, d);
        double back;
        if (sscanf(text, "%lf", &back) == 1 && back == d) break;
    }
    fbx_bytes_append(out, text, strlen(text));
}

static void write_ascii_value(fbx_bytes *out, const fbx_wvalue *v, uint32_t depth)
{
    switch (v->type) {
    case 'I': case 'L': fbx_bytes_printf(out, "%lld", (long long)v->u.i); break;
    case 'D': write_double(out, v->u.d); break;
    case 'S':
        fbx_bytes_append(out, "\"", 1);
        fbx_bytes_append(out, v->u.s, v->count);
        fbx_bytes_append(out, "\"", 1);
        break;
    case 'i': case 'l': case 'f': case 'd':
        fbx_bytes_printf(out, "*%u {\n", v->count);
        tabs(out, depth + 1);
        fbx_bytes_append(out, "a: ", 3);
        for (uint32_t k = 0; k < v->count; k++) {
            if (k) fbx_bytes_append(out, ",", 1);
            switch (v->type) {
            case 'i': {  /* read as bytes: 'i' may carry other 4-byte values (float bits) */
                int32_t x;
                memcpy(&x, (const uint8_t *)v->u.ai + 4 * (size_t)k, 4);
                fbx_bytes_printf(out, "%d", (int)x);
                break;
            }
            case 'l': fbx_bytes_printf(out, "%lld", (long long)v->u.al[k]); break;
            case 'f': write_double(out, (double)v->u.af[k]); break;
            default: write_double(out, v->u.ad[k]); break;
            }
        }
        fbx_bytes_append(out, "\n", 1);
        tabs(out, depth);
        fbx_bytes_append(out, "} ", 2);
        break;
    default: out->failed = 1; break;
    }
}

void fbx_wn_write_ascii(fbx_bytes *out, const fbx_wnode *node, uint32_t depth)
{
    tabs(out, depth);
    fbx_bytes_printf(out, "%s: ", node->name);
    for (uint32_t i = 0; i < node->value_count; i++) {
        if (i) fbx_bytes_append(out, ", ", 2);
        write_ascii_value(out, &node->values[i], depth);
    }
    if (node->child_count || !node->value_count) {
        fbx_bytes_append(out, " {\n", 3);
        for (uint32_t i = 0; i < node->child_count; i++) fbx_wn_write_ascii(out, node->children[i], depth + 1);
        tabs(out, depth);
        fbx_bytes_append(out, "}", 1);
    }
    fbx_bytes_append(out, "\n", 1);
}

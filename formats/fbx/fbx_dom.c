/* SPDX-License-Identifier: MIT */
/* Accessors over the FBX document tree: child lookup, scalar values, properties and lazy array
 * decoding (zlib via libdeflate for binary arrays, text for ASCII arrays, scalar runs for
 * FBX 5.x/6.x binary), with the arrays decoded ahead (fbx_prefetch.c) handed over or dropped
 * here, and the document's decoder, spare arrays and prefetched arrays freed (fbx_doc_free).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <libdeflate.h>
#include "fbx_internal.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the FBX array decoder assumes a little-endian host (it copies little-endian payloads and swaps big-endian files); adapt it for this host"
#endif

void fbx_doc_free(fbx_doc *doc)
{
    fbx_prefetch_drop(doc);
    if (doc->inflater) libdeflate_free_decompressor(doc->inflater);
    doc->inflater = NULL;
    for (size_t i = 0; i < sizeof doc->spare / sizeof doc->spare[0]; i++)
        mk_arena_release(doc->arena, doc->spare[i].ptr);
    memset(doc->spare, 0, sizeof doc->spare);
}

/* Arrays smaller than this are allocated and released as usual. */
#define FBX_SPARE_MIN ((size_t)64 << 10)

/* Bytes allocated for a recyclable array of `size` bytes: the next power of two, so the next
 * shape's slightly longer array still fits. */
static size_t spare_capacity(size_t size)
{
    if (size < FBX_SPARE_MIN) return size;
    size_t c = FBX_SPARE_MIN;
    while (c < size && c <= SIZE_MAX / 2) c *= 2;
    return c < size ? size : c;
}

void fbx_recycle(fbx_doc *doc, void *ptr, size_t size)
{
    if (!ptr) return;
    if (size < FBX_SPARE_MIN) {
        mk_arena_release(doc->arena, ptr);
        return;
    }
    size_t slot = 0;  /* an empty slot, else the smallest spare */
    for (size_t i = 0; i < sizeof doc->spare / sizeof doc->spare[0]; i++) {
        if (!doc->spare[i].ptr) { slot = i; break; }
        if (doc->spare[i].size < doc->spare[slot].size) slot = i;
    }
    if (doc->spare[slot].ptr && doc->spare[slot].size >= size) {  /* every spare is bigger: keep them */
        mk_arena_release(doc->arena, ptr);
        return;
    }
    mk_arena_release(doc->arena, doc->spare[slot].ptr);
    doc->spare[slot].ptr = ptr;
    doc->spare[slot].size = spare_capacity(size);  /* at least what array_buffer allocated for it */
}

/* The smallest spare of at least `size` bytes (taken out), or a new zeroed block. */
static void *array_buffer(fbx_doc *doc, size_t size)
{
    const size_t n = sizeof doc->spare / sizeof doc->spare[0];
    size_t best = n;
    for (size_t i = 0; i < n && size >= FBX_SPARE_MIN; i++)
        if (doc->spare[i].ptr && doc->spare[i].size >= size && (best == n || doc->spare[i].size < doc->spare[best].size))
            best = i;
    if (best == n) return mk_arena_alloc(doc->arena, spare_capacity(size));
    void *p = doc->spare[best].ptr;
    doc->spare[best].ptr = NULL;
    doc->spare[best].size = 0;
    return p;
}

void fbx_link_parents(fbx_node *node)
{
    for (uint32_t i = 0; i < node->child_count; i++) {
        node->children[i].parent = node;
        fbx_link_parents(&node->children[i]);
    }
}

int fbx_name_is(const fbx_node *node, const char *name)
{
    size_t length = strlen(name);
    return node->name_length == length && memcmp(node->name, name, length) == 0;
}

const fbx_node *fbx_next_child(const fbx_node *node, const fbx_node *prev, const char *name)
{
    if (!node) return NULL;
    uint32_t start = prev ? (uint32_t)(prev - node->children) + 1 : 0;
    for (uint32_t i = start; i < node->child_count; i++)
        if (fbx_name_is(&node->children[i], name)) return &node->children[i];
    return NULL;
}

const fbx_node *fbx_child(const fbx_node *node, const char *name)
{
    return fbx_next_child(node, NULL, name);
}

int fbx_value_int(const fbx_value *v, int64_t *out)
{
    if (v->kind == FBX_INT || v->kind == FBX_CHAR) { *out = v->u.i; return 1; }
    if (v->kind == FBX_FLOAT && v->u.f >= -9.2e18 && v->u.f <= 9.2e18) { *out = (int64_t)v->u.f; return 1; }
    return 0;
}

int fbx_value_float(const fbx_value *v, double *out)
{
    if (v->kind == FBX_FLOAT) { *out = v->u.f; return 1; }
    if (v->kind == FBX_INT || v->kind == FBX_CHAR) { *out = (double)v->u.i; return 1; }
    return 0;
}

int fbx_value_string(const fbx_value *v, const char **data, uint32_t *length)
{
    if (v->kind != FBX_STRING) return 0;
    *data = v->u.s.data;
    *length = v->u.s.length;
    return 1;
}

int fbx_child_int(const fbx_node *node, const char *name, int64_t *out)
{
    const fbx_node *c = fbx_child(node, name);
    return c && c->value_count > 0 && fbx_value_int(&c->values[0], out);
}

int fbx_child_float(const fbx_node *node, const char *name, double *out)
{
    const fbx_node *c = fbx_child(node, name);
    return c && c->value_count > 0 && fbx_value_float(&c->values[0], out);
}

int fbx_child_string(const fbx_node *node, const char *name, const char **data, uint32_t *length)
{
    const fbx_node *c = fbx_child(node, name);
    return c && c->value_count > 0 && fbx_value_string(&c->values[0], data, length);
}

void fbx_node_path(const fbx_node *node, char *buffer, size_t size)
{
    const fbx_node *chain[FBX_MAX_DEPTH + 2];
    int n = 0;
    for (const fbx_node *it = node; it && it->name_length && n < FBX_MAX_DEPTH + 1; it = it->parent)
        chain[n++] = it;
    size_t used = 0;
    if (size) buffer[0] = 0;
    for (int i = n - 1; i >= 0 && used + 1 < size; i--) {
        int w = snprintf(buffer + used, size - used, "%s%.*s", used ? "/" : "",
                         (int)chain[i]->name_length, chain[i]->name);
        if (w < 0) break;
        used += (size_t)w;
        if (used >= size) { used = size - 1; break; }
    }
}

/* ---- Array decoding ---- */

static size_t elem_size(fbx_elem elem)
{
    return (elem == FBX_ELEM_F64 || elem == FBX_ELEM_I64) ? 8 : 4;
}

static mk_result array_error(fbx_doc *doc, const fbx_node *node, uint64_t offset, mk_result code,
                             const char *what)
{
    char path[160];
    fbx_node_path(node, path, sizeof path);
    return mk_error_set(doc->err, code, offset, "FBX %s: %s", path, what);
}

/* Stores a double into the output element; fails on integers out of range or NaN. */
static int store_f64(void *out, size_t i, fbx_elem elem, double x)
{
    switch (elem) {
    case FBX_ELEM_F64: ((double *)out)[i] = x; return 1;
    case FBX_ELEM_F32: case FBX_ELEM_F32_BITS: ((float *)out)[i] = (float)x; return 1;
    case FBX_ELEM_I32:
        if (!(x >= -2147483648.0 && x <= 2147483647.0)) return 0;
        ((int32_t *)out)[i] = (int32_t)x;
        return 1;
    case FBX_ELEM_I64:
        if (!(x >= -9.2e18 && x <= 9.2e18)) return 0;
        ((int64_t *)out)[i] = (int64_t)x;
        return 1;
    }
    return 0;
}

static int store_i64(void *out, size_t i, fbx_elem elem, int64_t x)
{
    switch (elem) {
    case FBX_ELEM_F64: ((double *)out)[i] = (double)x; return 1;
    case FBX_ELEM_F32: ((float *)out)[i] = (float)x; return 1;
    case FBX_ELEM_F32_BITS: {
        /* ASCII >= 7200 writes KeyAttrDataFloat as the int32 bit patterns of the floats. */
        uint32_t bits = (uint32_t)x;
        float f;
        memcpy(&f, &bits, 4);
        ((float *)out)[i] = f;
        return 1;
    }
    case FBX_ELEM_I32:
        if (x < INT32_MIN || x > INT32_MAX) return 0;
        ((int32_t *)out)[i] = (int32_t)x;
        return 1;
    case FBX_ELEM_I64: ((int64_t *)out)[i] = x; return 1;
    }
    return 0;
}

/* Reverses the bytes of each of `count` elements of `size` bytes in place (big-endian files). */
static void swap_elements(void *data, size_t count, size_t size)
{
    uint8_t *p = data;
    for (size_t i = 0; i < count; i++, p += size)
        for (size_t a = 0, b = size - 1; a < b; a++, b--) {
            uint8_t t = p[a];
            p[a] = p[b];
            p[b] = t;
        }
}

/* One element of `size` bytes from p into dst, in host order. */
static void load_element(void *dst, const uint8_t *p, size_t size, int swap)
{
    memcpy(dst, p, size);
    if (swap) swap_elements(dst, 1, size);
}

static mk_result decode_binary(fbx_doc *doc, const fbx_node *node, const fbx_value *v, fbx_elem elem,
                               void *out)
{
    size_t src_size = (v->type == 'd' || v->type == 'l') ? 8 : (v->type == 'f' || v->type == 'i') ? 4 : 1;
    size_t bytes = (size_t)v->count * src_size;
    int swap = doc->big_endian && src_size > 1;  /* the payload (also inflated) is in the file's order */
    const uint8_t *src = v->u.a.data;
    void *inflated = NULL;
    int same = (v->type == 'd' && elem == FBX_ELEM_F64) || (v->type == 'l' && elem == FBX_ELEM_I64) ||
               (v->type == 'i' && elem == FBX_ELEM_I32) ||
               (v->type == 'f' && (elem == FBX_ELEM_F32 || elem == FBX_ELEM_F32_BITS));
    if (v->encoding == 1) {
        void *target = same ? out : (inflated = mk_arena_alloc(doc->arena, bytes ? bytes : 1));
        if (!target) return mk_error_oom(doc->err, "FBX array");
        if (!doc->inflater) doc->inflater = libdeflate_alloc_decompressor();
        struct libdeflate_decompressor *d = doc->inflater;
        if (!d) { mk_arena_release(doc->arena, inflated); return mk_error_oom(doc->err, "zlib decoder"); }
        size_t actual = 0;
        enum libdeflate_result lr = libdeflate_zlib_decompress(d, src, (size_t)v->u.a.size, target, bytes, &actual);
        if (lr != LIBDEFLATE_SUCCESS || actual != bytes) {
            mk_arena_release(doc->arena, inflated);
            /* The output buffer is exactly the declared size, so a stream that would inflate
             * beyond it stops with INSUFFICIENT_SPACE instead of writing more. */
            return array_error(doc, node, v->offset, MK_ERROR_PARSE,
                               lr == LIBDEFLATE_INSUFFICIENT_SPACE ? "compressed array inflates beyond its declared size"
                               : lr == LIBDEFLATE_SHORT_OUTPUT || (lr == LIBDEFLATE_SUCCESS && actual != bytes)
                                   ? "compressed array inflates to fewer bytes than declared"
                                   : "corrupt zlib stream in array");
        }
        if (same) {
            if (swap) swap_elements(out, v->count, src_size);
            return MK_OK;
        }
        src = inflated;
    } else if (same) {
        if (bytes) memcpy(out, src, bytes);
        if (swap) swap_elements(out, v->count, src_size);
        return MK_OK;
    }
    int ok = 1;
    for (size_t i = 0; i < v->count && ok; i++) {
        const uint8_t *p = src + i * src_size;
        switch (v->type) {
        case 'd': { double x; load_element(&x, p, 8, swap); ok = store_f64(out, i, elem, x); break; }
        case 'f': { float x; load_element(&x, p, 4, swap); ok = store_f64(out, i, elem, x); break; }
        case 'l': { int64_t x; load_element(&x, p, 8, swap); ok = store_i64(out, i, elem, x); break; }
        case 'i': { int32_t x; load_element(&x, p, 4, swap); ok = store_i64(out, i, elem, x); break; }
        default: ok = store_i64(out, i, elem, p[0]); break;
        }
    }
    mk_arena_release(doc->arena, inflated);
    if (!ok) return array_error(doc, node, v->offset, MK_ERROR_PARSE, "array value out of range for its use");
    return MK_OK;
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

/* File offset of an ASCII array's text (the values after "a:"). */
static uint64_t ascii_data_offset(const fbx_doc *doc, const fbx_value *v)
{
    return (uint64_t)(v->u.a.data - doc->data);
}

static mk_result decode_ascii(fbx_doc *doc, const fbx_node *node, const fbx_value *v, fbx_elem elem, void *out)
{
    const char *s = (const char *)v->u.a.data;
    size_t size = (size_t)v->u.a.size, pos = 0, n = 0, start;
    uint64_t base = ascii_data_offset(doc, v);
    while (fbx_ascii_array_token(s, size, &pos, &start)) {
        if (n >= v->count)
            return array_error(doc, node, base + start, MK_ERROR_PARSE, "array has more values than its *N count");
        size_t length = pos - start;
        /* Integer fast path (indices, KTime, bit patterns). */
        size_t k = (s[start] == '-' || s[start] == '+') ? 1 : 0;
        int integer = length > k && length - k <= 18;
        for (size_t j = k; j < length && integer; j++) integer = is_digit(s[start + j]);
        int ok;
        if (integer) {
            int64_t x = 0;
            for (size_t j = k; j < length; j++) x = x * 10 + (s[start + j] - '0');
            ok = store_i64(out, n, elem, s[start] == '-' ? -x : x);
        } else {
            double x;
            /* NaN and infinity (any spelling) are values like in a binary array; where the
             * importer uses them it reports the element (fbx_error_not_finite). */
            if (!fbx_ascii_not_finite(s + start, length, &x)) {
                char buffer[96];
                if (length >= sizeof buffer)
                    return array_error(doc, node, base + start, MK_ERROR_PARSE, "number token too long");
                memcpy(buffer, s + start, length);
                buffer[length] = 0;
                char *stop;
                x = strtod(buffer, &stop);
                if (stop == buffer || *stop) {
                    char what[160];
                    snprintf(what, sizeof what, "malformed number '%.40s' (value %zu) in array", buffer, n);
                    return array_error(doc, node, base + start, MK_ERROR_PARSE, what);
                }
            }
            ok = store_f64(out, n, elem, x);
        }
        if (!ok) return array_error(doc, node, base + start, MK_ERROR_PARSE, "array value out of range for its use");
        n++;
    }
    if (n != v->count)
        return array_error(doc, node, v->offset, MK_ERROR_PARSE, "array has fewer values than its *N count");
    return MK_OK;
}

/* Arrays decoded ahead by fbx_prefetch (fbx_prefetch.c), handed over by fbx_node_array. */
int fbx_prefetch_take(fbx_doc *doc, const fbx_node *node, fbx_elem elem, void **out, size_t *count, mk_result *r)
{
    for (uint32_t i = 0; i < doc->prefetched_count; i++) {
        fbx_prefetched *p = &doc->prefetched[i];
        if (p->node != node || p->elem != elem) continue;
        p->node = NULL;
        *out = p->data;
        *count = p->count;
        *r = p->result;
        if (p->result != MK_OK && doc->err) *doc->err = p->error;
        return 1;
    }
    return 0;
}

void fbx_prefetch_drop(fbx_doc *doc)
{
    for (uint32_t i = 0; i < doc->prefetched_count; i++)
        if (doc->prefetched[i].node) mk_arena_release(doc->arena, doc->prefetched[i].data);
    mk_arena_release(doc->arena, doc->prefetched);
    doc->prefetched = NULL;
    doc->prefetched_count = 0;
}

mk_result fbx_node_array(fbx_doc *doc, const fbx_node *node, fbx_elem elem, void **out, size_t *count)
{
    *out = NULL;
    *count = 0;
    mk_result taken;
    if (fbx_prefetch_take(doc, node, elem, out, count, &taken)) return taken;
    size_t esize = elem_size(elem);
    if (node->value_count == 1 && node->values[0].kind == FBX_ARRAY) {
        const fbx_value *v = &node->values[0];
        if ((uint64_t)v->count * esize > FBX_MAX_ARRAY_BYTES)
            return array_error(doc, node, v->offset, MK_ERROR_LIMIT, "array too large");
        void *data = array_buffer(doc, (size_t)v->count * esize);  /* every element is written below */
        if (!data) return mk_error_oom(doc->err, "FBX array");
        mk_result r = v->type == 'a' ? decode_ascii(doc, node, v, elem, data) : decode_binary(doc, node, v, elem, data);
        if (r != MK_OK) { mk_arena_release(doc->arena, data); return r; }
        *out = data;
        *count = v->count;
        return MK_OK;
    }
    /* FBX 5.x/6.x: a run of scalar values (every one written below). */
    void *data = node->value_count <= SIZE_MAX / esize ? array_buffer(doc, (size_t)node->value_count * esize) : NULL;
    if (!data) return mk_error_oom(doc->err, "FBX array");
    for (uint32_t i = 0; i < node->value_count; i++) {
        const fbx_value *v = &node->values[i];
        int ok;
        if (v->kind == FBX_FLOAT) ok = store_f64(data, i, elem == FBX_ELEM_F32_BITS ? FBX_ELEM_F32 : elem, v->u.f);
        else if (v->kind == FBX_INT || v->kind == FBX_CHAR) ok = store_i64(data, i, elem == FBX_ELEM_F32_BITS ? FBX_ELEM_F32 : elem, v->u.i);
        else ok = 0;
        if (!ok) {
            mk_arena_release(doc->arena, data);
            return array_error(doc, node, v->offset, MK_ERROR_PARSE, "expected a number in the value list");
        }
    }
    *out = data;
    *count = node->value_count;
    return MK_OK;
}

size_t fbx_node_array_length(const fbx_node *node)
{
    if (node->value_count == 1 && node->values[0].kind == FBX_ARRAY) return node->values[0].count;
    return node->value_count;
}

mk_result fbx_child_array(fbx_doc *doc, const fbx_node *node, const char *name, fbx_elem elem,
                          void **out, size_t *count)
{
    *out = NULL;
    *count = 0;
    const fbx_node *c = fbx_child(node, name);
    if (!c) return MK_OK;
    return fbx_node_array(doc, c, elem, out, count);
}

uint64_t fbx_value_offset(const fbx_doc *doc, const fbx_node *node, size_t index, int *zlib)
{
    *zlib = 0;
    if (node->value_count == 1 && node->values[0].kind == FBX_ARRAY) {
        const fbx_value *v = &node->values[0];
        if (v->type == 'a') {
            const char *s = (const char *)v->u.a.data;
            size_t pos = 0, start = 0, n = 0;
            while (fbx_ascii_array_token(s, (size_t)v->u.a.size, &pos, &start))
                if (n++ == index) return ascii_data_offset(doc, v) + start;
            return v->offset;
        }
        if (v->encoding != 0 || index >= v->count) {
            *zlib = v->encoding != 0;
            return v->offset;
        }
        size_t size = (v->type == 'd' || v->type == 'l') ? 8 : (v->type == 'f' || v->type == 'i') ? 4 : 1;
        return (uint64_t)(v->u.a.data - doc->data) + (uint64_t)index * size;
    }
    return index < node->value_count ? node->values[index].offset : node->offset;
}

mk_result fbx_error_not_finite(fbx_doc *doc, const fbx_node *node, size_t index, const char *what_fmt, ...)
{
    char what[160], path[160];
    va_list ap;
    va_start(ap, what_fmt);
    vsnprintf(what, sizeof what, what_fmt, ap);
    va_end(ap);
    if (!node) return mk_error_set(doc->err, MK_ERROR_NOT_FINITE, UINT64_MAX, "FBX: %s is not finite", what);
    fbx_node_path(node, path, sizeof path);
    int zlib;
    uint64_t at = fbx_value_offset(doc, node, index, &zlib);
    return mk_error_set(doc->err, MK_ERROR_NOT_FINITE, at,
                        "FBX %s: %s is not finite (NaN, infinite or beyond float range; value %zu %sat byte %llu)", path,
                        what, index, zlib ? "of the zlib array " : "", (unsigned long long)at);
}

/* ---- Properties ---- */

fbx_props fbx_props_of(const fbx_node *object)
{
    fbx_props props = { NULL, 0 };
    if (!object) return props;
    props.block = fbx_child(object, "Properties70");
    if (!props.block) {
        props.block = fbx_child(object, "Properties60");
        props.legacy = props.block != NULL;
    }
    return props;
}

uint32_t fbx_prop_payload(fbx_props props)
{
    return props.legacy ? 3u : 4u;
}

const fbx_node *fbx_prop_find(fbx_props props, const char *name)
{
    if (!props.block) return NULL;
    size_t length = strlen(name);
    const char *tag = props.legacy ? "Property" : "P";
    for (uint32_t i = 0; i < props.block->child_count; i++) {
        const fbx_node *p = &props.block->children[i];
        if (!fbx_name_is(p, tag) || p->value_count == 0) continue;
        const fbx_value *v = &p->values[0];
        if (v->kind == FBX_STRING && v->u.s.length == length && memcmp(v->u.s.data, name, length) == 0)
            return p;
    }
    return NULL;
}

int fbx_prop_number_opt(fbx_props props, const char *name, double *out)
{
    const fbx_node *p = fbx_prop_find(props, name);
    uint32_t at = fbx_prop_payload(props);
    if (!p || p->value_count <= at) return 0;
    return fbx_value_float(&p->values[at], out);
}

int fbx_prop_vec3(fbx_props props, const char *name, double out[3])
{
    const fbx_node *p = fbx_prop_find(props, name);
    uint32_t at = fbx_prop_payload(props);
    if (!p || p->value_count < at + 3) return 0;
    double v[3];
    for (int i = 0; i < 3; i++)
        if (!fbx_value_float(&p->values[at + (uint32_t)i], &v[i])) return 0;
    memcpy(out, v, sizeof v);
    return 1;
}

int fbx_prop_int64(fbx_props props, const char *name, int64_t *out)
{
    const fbx_node *p = fbx_prop_find(props, name);
    uint32_t at = fbx_prop_payload(props);
    if (!p || p->value_count <= at) return 0;
    return fbx_value_int(&p->values[at], out);
}

mk_result fbx_doc_parse(fbx_doc *doc, mk_arena *arena, const void *data, size_t size, mk_error *err)
{
    memset(doc, 0, sizeof *doc);
    doc->arena = arena;
    doc->data = data;
    doc->size = size;
    doc->err = err;
    doc->binary = fbx_is_binary(data, size);
    mk_result r = doc->binary ? fbx_parse_binary(doc) : fbx_parse_ascii(doc);
    if (r == MK_OK && doc->root.child_count == 0)
        r = mk_error_set(err, MK_ERROR_PARSE, 0, "not an FBX file: no nodes found (%zu bytes)", size);
    if (r != MK_OK) return r;
    fbx_link_parents(&doc->root);
    const fbx_node *header = fbx_child(&doc->root, "FBXHeaderExtension");
    int64_t fbx_version = 0;
    if (fbx_child_int(header, "FBXVersion", &fbx_version) && fbx_version > 0 && fbx_version < 100000 &&
        (doc->version == 0 || doc->version < 6000))
        doc->version = (uint32_t)fbx_version;
    if (doc->version == 0) doc->version = 7400;
    return MK_OK;
}

double fbx_doc_ticks(const fbx_doc *doc)
{
    const fbx_node *header = fbx_child(&doc->root, "FBXHeaderExtension");
    int64_t header_version = 0, tc = 0;
    if (fbx_child_int(header, "FBXHeaderVersion", &header_version) && header_version >= 1004 &&
        fbx_child_int(fbx_child(header, "OtherFlags"), "TCDefinition", &tc))
        return tc == 127 ? FBX_TICKS_PER_SECOND_OLD : FBX_TICKS_PER_SECOND_NEW;
    return doc->version < 8000 ? FBX_TICKS_PER_SECOND_OLD : FBX_TICKS_PER_SECOND_NEW;
}

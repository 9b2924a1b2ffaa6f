/* SPDX-License-Identifier: MIT */
/* Test-only FBX writer (see fbx_writer.h). Binary records follow the layout fbx_binary.c
 * reads (13-byte headers below 7500, 25-byte from 7500, a null record closing every child
 * list); ASCII follows the 7.x syntax with `*N { a: ... }` arrays and, from 7200, integer bit
 * patterns for KeyAttrDataFloat, as the FBX SDK writes them. Big-endian binary files (header
 * byte 22 = 1, as ufbx reads them) byte-swap every record counter, scalar, string/array length
 * and array element (before compression); the zlib stream's own header is big-endian anyway.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <libdeflate.h>
#include "fbx_writer.h"

typedef struct out {
    FILE *file;                /* streaming, or NULL for memory */
    unsigned char *data;
    size_t size, cap;
    int failed;
    int binary, wide, version;
    int depth;                 /* ASCII indentation */
    /* binary node stack */
    long long node_start[32];
    long long props_start[32];
    long long props_end[32];
    uint64_t prop_count[32];
    int has_values;            /* ASCII: a value was written on the current line */
    int top;
    struct libdeflate_compressor *compressor;
    int compress;
    int big;                   /* binary: big-endian */
    int type_mix;
} out;

static long long tell(out *o)
{
    return o->file ? (long long)ftell(o->file) : (long long)o->size;
}

static void put(out *o, const void *p, size_t n)
{
    if (o->failed || n == 0) return;
    if (o->file) {
        if (fwrite(p, 1, n, o->file) != n) o->failed = 1;
        return;
    }
    if (o->size + n > o->cap) {
        size_t cap = o->cap ? o->cap : 4096;
        while (cap < o->size + n) cap *= 2;
        unsigned char *d = realloc(o->data, cap);
        if (!d) { o->failed = 1; return; }
        o->data = d;
        o->cap = cap;
    }
    memcpy(o->data + o->size, p, n);
    o->size += n;
}

static void patch(out *o, long long at, const void *p, size_t n)
{
    if (o->failed) return;
    if (o->file) {
        long long here = tell(o);
        if (fseek(o->file, (long)at, SEEK_SET) || fwrite(p, 1, n, o->file) != n || fseek(o->file, (long)here, SEEK_SET))
            o->failed = 1;
        return;
    }
    memcpy(o->data + at, p, n);
}

static void put_u8(out *o, uint8_t v) { put(o, &v, 1); }

/* `bytes` bytes of v in the file's byte order. */
static void encode(const out *o, unsigned char *b, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++) b[o->big ? bytes - 1 - i : i] = (unsigned char)(v >> (8 * i));
}
static void put_uint(out *o, uint64_t v, int bytes)
{
    unsigned char b[8];
    encode(o, b, v, bytes);
    put(o, b, (size_t)bytes);
}
static void put_u32(out *o, uint32_t v) { put_uint(o, v, 4); }
static void put_u64(out *o, uint64_t v) { put_uint(o, v, 8); }

static void text(out *o, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#include <stdarg.h>
static void text(out *o, const char *fmt, ...)
{
    char buffer[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buffer, sizeof buffer, fmt, ap);
    va_end(ap);
    if (n < 0) { o->failed = 1; return; }
    if ((size_t)n >= sizeof buffer) n = (int)sizeof buffer - 1;
    put(o, buffer, (size_t)n);
}

static void indent(out *o)
{
    for (int i = 0; i < o->depth; i++) put(o, "\t", 1);
}

/* ---- nodes ---- */

static void begin(out *o, const char *name)
{
    if (o->binary) {
        int t = o->top++;
        o->node_start[t] = tell(o);
        o->prop_count[t] = 0;
        unsigned char zero[25] = { 0 };
        put(o, zero, (size_t)(o->wide ? 24 : 12));
        put_u8(o, (uint8_t)strlen(name));
        put(o, name, strlen(name));
        o->props_start[t] = tell(o);
    } else {
        indent(o);
        text(o, "%s: ", name);
        o->has_values = 0;
    }
}

/* Ends the value list; `children` says whether child nodes follow. */
static void values_end(out *o, int children)
{
    if (o->binary) {
        o->props_end[o->top - 1] = tell(o);
    } else if (children) {
        text(o, " {\n");
        o->depth++;
    } else {
        text(o, "\n");
    }
}

static void end(out *o, int children)
{
    if (o->binary) {
        int t = --o->top;
        unsigned char zero[25] = { 0 };
        put(o, zero, (size_t)(o->wide ? 25 : 13));
        uint64_t end_offset = (uint64_t)tell(o);
        uint64_t list_length = (uint64_t)(o->props_end[t] - o->props_start[t]);
        unsigned char header[24];
        size_t n = 0;
        uint64_t fields[3] = { end_offset, o->prop_count[t], list_length };
        for (int f = 0; f < 3; f++) {
            int bytes = o->wide ? 8 : 4;
            encode(o, header + n, fields[f], bytes);
            n += (size_t)bytes;
        }
        patch(o, o->node_start[t], header, n);
    } else if (children) {
        o->depth--;
        indent(o);
        text(o, "}\n");
    }
}

static void sep(out *o)
{
    if (o->has_values) put(o, ",", 1);
    o->has_values = 1;
}

/* Integers: 'I' (i32), 'L' (i64), 'Y' (i16), 'B'/'Z' (one byte). ASCII writes the number. */
static void v_i64(out *o, int64_t v, char type)
{
    if (o->binary) {
        put_u8(o, (uint8_t)type);
        if (type == 'L') put_u64(o, (uint64_t)v);
        else if (type == 'Y') put_uint(o, (uint16_t)(int16_t)v, 2);
        else if (type == 'B' || type == 'Z') put_u8(o, (uint8_t)v);
        else put_u32(o, (uint32_t)(int32_t)v);
        o->prop_count[o->top - 1]++;
    } else {
        sep(o);
        text(o, "%lld", (long long)v);
    }
}

static void v_f64(out *o, double v)
{
    if (o->binary) {
        uint64_t bits;
        memcpy(&bits, &v, 8);
        put_u8(o, 'D');
        put_u64(o, bits);
        o->prop_count[o->top - 1]++;
    } else {
        sep(o);
        text(o, "%.17g", v);
    }
}

/* A number as 'F' (f32) when the scene mixes types, else as 'D'. */
static void v_real(out *o, double v)
{
    if (!o->binary || !o->type_mix) { v_f64(o, v); return; }
    float f = (float)v;
    uint32_t bits;
    memcpy(&bits, &f, 4);
    put_u8(o, 'F');
    put_u32(o, bits);
    o->prop_count[o->top - 1]++;
}

/* Strings: 'S', or 'R' (raw bytes, length given) in binary. */
static void v_bytes(out *o, char type, const void *s, size_t n)
{
    put_u8(o, (uint8_t)type);
    put_u32(o, (uint32_t)n);
    put(o, s, n);
    o->prop_count[o->top - 1]++;
}

static void v_str(out *o, const char *s)
{
    if (o->binary) {
        put_u8(o, 'S');
        put_u32(o, (uint32_t)strlen(s));
        put(o, s, strlen(s));
        o->prop_count[o->top - 1]++;
    } else {
        sep(o);
        text(o, "\"%s\"", s);
    }
}

/* Object name: "Class::Name" in ASCII, "Name\0\1Class" in binary. */
static void v_name(out *o, const char *cls, const char *name)
{
    if (o->binary) {
        size_t a = strlen(name), b = strlen(cls);
        put_u8(o, 'S');
        put_u32(o, (uint32_t)(a + 2 + b));
        put(o, name, a);
        put(o, "\x00\x01", 2);
        put(o, cls, b);
        o->prop_count[o->top - 1]++;
    } else {
        sep(o);
        text(o, "\"%s::%s\"", cls, name);
    }
}

static void v_char(out *o, char c)
{
    if (o->binary) {
        put_u8(o, 'C');
        put_u8(o, (uint8_t)c);
        o->prop_count[o->top - 1]++;
    } else {
        sep(o);
        text(o, "%c", c);
    }
}

/* Binary array payload: the elements in the file's byte order (the host is little-endian),
 * zlib-compressed when `compress` (after swapping, as the stream holds the file's bytes). */
static void put_array(out *o, char kind, const void *data, size_t count, int compress)
{
    size_t elem = (kind == 'd' || kind == 'l') ? 8 : (kind == 'f' || kind == 'i') ? 4 : 1;
    size_t bytes = count * elem;
    const unsigned char *payload = data;
    unsigned char *swapped = NULL;
    if (o->big && elem > 1 && bytes) {
        swapped = malloc(bytes);
        if (!swapped) { o->failed = 1; return; }
        for (size_t i = 0; i < count; i++)
            for (size_t b = 0; b < elem; b++) swapped[i * elem + b] = payload[i * elem + elem - 1 - b];
        payload = swapped;
    }
    put_u8(o, (uint8_t)kind);
    put_u32(o, (uint32_t)count);
    if (compress && o->compressor) {
        size_t bound = libdeflate_zlib_compress_bound(o->compressor, bytes);
        unsigned char *z = malloc(bound);
        size_t zn = z ? libdeflate_zlib_compress(o->compressor, payload, bytes, z, bound) : 0;
        if (!zn) o->failed = 1;
        put_u32(o, 1);
        put_u32(o, (uint32_t)zn);
        put(o, z, zn);
        free(z);
    } else {
        put_u32(o, 0);
        put_u32(o, (uint32_t)bytes);
        put(o, payload, bytes);
    }
    free(swapped);
    o->prop_count[o->top - 1]++;
}

/* Arrays: kind 'd' (double), 'f' (float), 'i' (int32), 'l' (int64); `bits` writes floats as
 * their int32 bit patterns in ASCII (KeyAttrDataFloat from 7200). */
static void v_array(out *o, char kind, const void *data, size_t count, int bits)
{
    if (o->binary) {
        put_array(o, kind, data, count, o->compress == 2 ? count > 0 : o->compress && count > 64);
        return;
    }
    sep(o);
    text(o, "*%zu {\n", count);
    o->depth++;
    indent(o);
    text(o, "a: ");
    char buffer[64];
    for (size_t i = 0; i < count; i++) {
        int n;
        switch (kind) {
        case 'd': n = snprintf(buffer, sizeof buffer, "%.17g", ((const double *)data)[i]); break;
        case 'l': n = snprintf(buffer, sizeof buffer, "%lld", (long long)((const int64_t *)data)[i]); break;
        case 'i': n = snprintf(buffer, sizeof buffer, "%d", (int)((const int32_t *)data)[i]); break;
        default: {
            float f = ((const float *)data)[i];
            if (bits) {
                int32_t b;
                memcpy(&b, &f, 4);
                n = snprintf(buffer, sizeof buffer, "%d", (int)b);
            } else {
                n = snprintf(buffer, sizeof buffer, "%.9g", (double)f);
            }
        }
        }
        if (i) put(o, ",", 1);
        put(o, buffer, (size_t)n);
    }
    text(o, "\n");
    o->depth--;
    indent(o);
    text(o, "}");
}

/* Typed arrays for the type mix: the values (doubles or int64) written as `kind`. */
static void v_array_as(out *o, char kind, const double *d, const int64_t *l, size_t count)
{
    if (!o->binary || !o->type_mix) {
        if (d) v_array(o, 'd', d, count, 0);
        else v_array(o, 'l', l, count, 0);
        return;
    }
    size_t elem = (kind == 'd' || kind == 'l') ? 8 : (kind == 'f' || kind == 'i') ? 4 : 1;
    unsigned char *buffer = malloc(count * elem + 1);
    if (!buffer) { o->failed = 1; return; }
    for (size_t i = 0; i < count; i++) {
        double x = d ? d[i] : (double)l[i];
        int64_t y = l ? l[i] : (int64_t)d[i];
        float f = (float)x;
        int32_t w = (int32_t)y;
        switch (kind) {
        case 'd': memcpy(buffer + 8 * i, &x, 8); break;
        case 'f': memcpy(buffer + 4 * i, &f, 4); break;
        case 'l': memcpy(buffer + 8 * i, &y, 8); break;
        case 'i': memcpy(buffer + 4 * i, &w, 4); break;
        default: buffer[i] = (unsigned char)y; break;
        }
    }
    v_array(o, kind, buffer, count, 0);
    free(buffer);
}

/* Leaf helpers */
static void leaf_i64(out *o, const char *name, int64_t v, char type) { begin(o, name); v_i64(o, v, type); values_end(o, 0); end(o, 0); }
static void leaf_f64(out *o, const char *name, double v) { begin(o, name); v_f64(o, v); values_end(o, 0); end(o, 0); }
static void leaf_str(out *o, const char *name, const char *s) { begin(o, name); v_str(o, s); values_end(o, 0); end(o, 0); }
static void leaf_array(out *o, const char *name, char kind, const void *data, size_t count, int bits)
{
    begin(o, name);
    v_array(o, kind, data, count, bits);
    values_end(o, 0);
    end(o, 0);
}

/* P: "name", "type", "label", "flags", values... */
static void prop_begin(out *o, const char *name, const char *type, const char *label, const char *flags)
{
    begin(o, "P");
    v_str(o, name);
    v_str(o, type);
    v_str(o, label);
    v_str(o, flags);
}
static void prop_end(out *o) { values_end(o, 0); end(o, 0); }
static void prop_vec3(out *o, const char *name, const double v[3])
{
    prop_begin(o, name, "Lcl Translation", "", "A");
    for (int i = 0; i < 3; i++) v_f64(o, v[i]);
    prop_end(o);
}

/* A vec3 property unless all three components equal `fallback` (the FBX default). */
static void prop_vec3_unless(out *o, const char *name, const double v[3], double fallback)
{
    if (v[0] == fallback && v[1] == fallback && v[2] == fallback) return;
    prop_vec3(o, name, v);
}

/* Array leaf whose values are written as `kind` in a type-mixed binary file (else 'd'). */
static void leaf_array_as(out *o, const char *name, char kind, const double *values, size_t count)
{
    begin(o, name);
    v_array_as(o, kind, values, NULL, count);
    values_end(o, 0);
    end(o, 0);
}

/* Every property type and every array type (raw and zlib), with values whose bytes are not
 * palindromes, so a reader that ignores the byte order reads different values. */
static void write_type_zoo(out *o)
{
    begin(o, "MorphkitTypes");
    v_i64(o, -12345, 'Y');
    v_char(o, 'x');
    v_i64(o, 200, 'B');
    v_i64(o, 1, 'Z');
    v_i64(o, -123456789, 'I');
    v_i64(o, -1234567890123456789LL, 'L');
    v_real(o, -3.25e-3);
    v_f64(o, 0.1);
    v_bytes(o, 'S', "name\0\1Class", 11);  /* binary object name: Name, 0, 1, Class */
    v_bytes(o, 'R', "\x00\x01\x02\xff\x80", 5);
    values_end(o, 1);
    static const double d[5] = { 0.1, -2.5e10, 1e-300, 3.0, -0.0 };
    static const float f[5] = { 1e-3f, -7.5f, 3.0e38f, 0.0f, 1.0f / 3.0f };
    static const int64_t l[5] = { 0x0102030405060708LL, -2, INT64_MIN, 46186158000LL, 0 };
    static const int32_t i[5] = { 0x01020304, -2, INT32_MIN, 7, 0 };
    static const unsigned char b[5] = { 0, 1, 0xff, 0x80, 2 };
    static const char c[5] = { 'a', 'Y', 0, 'T', 'N' };
    static const struct { char kind; const void *data; } arrays[6] = {
        { 'd', d }, { 'f', f }, { 'l', l }, { 'i', i }, { 'b', b }, { 'c', c } };
    for (int a = 0; a < 6; a++)
        for (int z = 0; z < 2; z++) {
            char name[16];
            snprintf(name, sizeof name, "%c%s", arrays[a].kind, z ? "zlib" : "raw");
            begin(o, name);
            put_array(o, arrays[a].kind, arrays[a].data, 5, z);
            values_end(o, 0);
            end(o, 0);
        }
    end(o, 1);
}

/* ---- scene ---- */

typedef struct ids {
    int64_t next;
} ids;

static int64_t new_id(ids *g) { return g->next++; }

static void connect(out *o, const char *type, int64_t src, int64_t dst, const char *prop)
{
    begin(o, "C");
    v_str(o, type);
    v_i64(o, src, 'L');
    v_i64(o, dst, 'L');
    if (prop) v_str(o, prop);
    values_end(o, 0);
    end(o, 0);
}

/* An object's node and values: `node` (Geometry, Model, Deformer...) with the id, "class::name"
 * and the subclass; `nested` as values_end takes it. */
static void object_begin(out *o, const char *node, int64_t id, const char *cls, const char *name, const char *subclass,
                         int nested)
{
    begin(o, node);
    v_i64(o, id, 'L');
    v_name(o, cls, name);
    v_str(o, subclass);
    values_end(o, nested);
}

/* A by-polygon-vertex, direct layer element (normals, UVs) of `count` values. */
static void layer_element(out *o, const char *node, int64_t version, const char *name, const char *array,
                          const double *values, size_t count)
{
    begin(o, node);
    v_i64(o, 0, 'I');
    values_end(o, 1);
    leaf_i64(o, "Version", version, 'I');
    leaf_str(o, "Name", name);
    leaf_str(o, "MappingInformationType", "ByPolygonVertex");
    leaf_str(o, "ReferenceInformationType", "Direct");
    leaf_array_as(o, array, 'f', values, count);
    end(o, 1);
}

static void write_curve(out *o, int64_t id, const fbxw_curve *c, double default_value)
{
    object_begin(o, "AnimationCurve", id, "AnimCurve", "", "", 1);
    leaf_f64(o, "Default", default_value);
    leaf_i64(o, "KeyVer", 4009, 'I');
    leaf_array(o, "KeyTime", 'l', c->times, c->key_count, 0);
    leaf_array(o, "KeyValueFloat", 'f', c->values, c->key_count, 0);
    /* Run-length encode equal (flags, data) attributes, as the SDK does. */
    int32_t *flags = malloc((c->key_count + 1) * sizeof *flags);
    float *data = malloc((c->key_count + 1) * 4 * sizeof *data);
    int32_t *refs = malloc((c->key_count + 1) * sizeof *refs);
    size_t runs = 0;
    for (uint32_t k = 0; flags && data && refs && k < c->key_count; k++) {
        if (runs && flags[runs - 1] == c->flags[k] && memcmp(data + 4 * (runs - 1), c->data + 4 * k, 16) == 0) {
            refs[runs - 1]++;
            continue;
        }
        flags[runs] = c->flags[k];
        memcpy(data + 4 * runs, c->data + 4 * k, 16);
        refs[runs] = 1;
        runs++;
    }
    if (!flags || !data || !refs) o->failed = 1;
    leaf_array(o, "KeyAttrFlags", 'i', flags, runs, 0);
    leaf_array(o, "KeyAttrDataFloat", 'f', data, 4 * runs, o->version >= 7200);
    leaf_array(o, "KeyAttrRefCount", 'i', refs, runs, 0);
    free(flags);
    free(data);
    free(refs);
    end(o, 1);
}

static void write_scene(out *o, const fbxw_scene *sc)
{
    ids g = { 1000000 };
    if (o->binary) {
        put(o, "Kaydara FBX Binary  \0\x1a", 22);
        put_u8(o, o->big ? 1 : 0);  /* endianness */
        put_u32(o, sc->version);
    } else {
        text(o, "; FBX %u.%u.%u project file\n; written by the morphkit test writer\n", sc->version / 1000,
             sc->version / 100 % 10, sc->version / 10 % 10);
    }
    const char *creator = sc->creator ? sc->creator : "morphkit test writer";
    begin(o, "FBXHeaderExtension");
    values_end(o, 1);
    leaf_i64(o, "FBXHeaderVersion", 1003, 'I');
    leaf_i64(o, "FBXVersion", sc->version, 'I');
    leaf_str(o, "Creator", creator);
    end(o, 1);
    if (o->binary && o->type_mix) {
        begin(o, "Creator");
        v_bytes(o, 'R', creator, strlen(creator));
        values_end(o, 0);
        end(o, 0);
    } else {
        leaf_str(o, "Creator", creator);
    }
    begin(o, "GlobalSettings");
    values_end(o, 1);
    leaf_i64(o, "Version", 1000, 'I');
    begin(o, "Properties70");
    values_end(o, 1);
    prop_begin(o, "UpAxis", "int", "Integer", ""); v_i64(o, 1, o->binary && o->type_mix ? 'Y' : 'I'); prop_end(o);
    prop_begin(o, "UnitScaleFactor", "double", "Number", ""); v_f64(o, 1.0); prop_end(o);
    prop_begin(o, "TimeMode", "enum", "", ""); v_i64(o, 11, 'I'); prop_end(o);
    end(o, 1);
    end(o, 1);

    /* Ids are assigned in a fixed order so connections can be written afterwards. */
    uint32_t total_channels = 0, total_shapes = 0;
    for (uint32_t m = 0; m < sc->mesh_count; m++) {
        total_channels += sc->meshes[m].channel_count;
        for (uint32_t c = 0; c < sc->meshes[m].channel_count; c++) total_shapes += sc->meshes[m].channels[c].shape_count;
    }
    int64_t *model_id = calloc(sc->mesh_count + 1, sizeof(int64_t));
    int64_t *geom_id = calloc(sc->mesh_count + 1, sizeof(int64_t));
    int64_t *deformer_id = calloc(sc->mesh_count + 1, sizeof(int64_t));
    int64_t *channel_id = calloc(total_channels + 1, sizeof(int64_t));
    int64_t *node_id = calloc(total_channels + 1, sizeof(int64_t));
    int64_t *curve_id = calloc(total_channels + 1, sizeof(int64_t));
    int64_t *shape_id = calloc(total_shapes + 1, sizeof(int64_t));
    if (!model_id || !geom_id || !deformer_id || !channel_id || !node_id || !curve_id || !shape_id) o->failed = 1;
    int64_t stack_id = new_id(&g), layer_id = new_id(&g);
    int animated = 0;

    begin(o, "Objects");
    values_end(o, 1);
    uint32_t ci = 0, si = 0;
    for (uint32_t m = 0; m < sc->mesh_count && !o->failed; m++) {
        const fbxw_mesh *mesh = &sc->meshes[m];
        model_id[m] = new_id(&g);
        geom_id[m] = new_id(&g);
        object_begin(o, "Geometry", geom_id[m], "Geometry", "", "Mesh", 1);
        leaf_array(o, "Vertices", 'd', mesh->control_points, 3 * (size_t)mesh->control_point_count, 0);
        leaf_array(o, "PolygonVertexIndex", 'i', mesh->polygon_vertex_index, mesh->polygon_vertex_count, 0);
        leaf_i64(o, "GeometryVersion", 124, 'I');
        if (mesh->normals)
            layer_element(o, "LayerElementNormal", 102, "", "Normals", mesh->normals, 3 * (size_t)mesh->polygon_vertex_count);
        if (mesh->uvs)
            layer_element(o, "LayerElementUV", 101, "map1", "UV", mesh->uvs, 2 * (size_t)mesh->polygon_vertex_count);
        begin(o, "Layer"); v_i64(o, 0, 'I'); values_end(o, 1);
        leaf_i64(o, "Version", 100, 'I');
        end(o, 1);
        end(o, 1);

        object_begin(o, "Model", model_id[m], "Model", mesh->name, "Mesh", 1);
        leaf_i64(o, "Version", 232, 'I');
        begin(o, "Properties70");
        values_end(o, 1);
        double one[3] = { 1, 1, 1 };
        const double *s = (mesh->scaling[0] == 0 && mesh->scaling[1] == 0 && mesh->scaling[2] == 0) ? one : mesh->scaling;
        int inherit = mesh->inherit_type ? mesh->inherit_type - 1 : mesh->ignore_parent_scale ? 2 : 1;
        prop_begin(o, "RotationOrder", "enum", "", ""); v_i64(o, mesh->rotation_order, 'I'); prop_end(o);
        prop_begin(o, "InheritType", "enum", "", ""); v_i64(o, inherit, 'I'); prop_end(o);
        prop_vec3(o, "PreRotation", mesh->pre_rotation);
        prop_vec3_unless(o, "PostRotation", mesh->post_rotation, 0);
        prop_vec3_unless(o, "RotationOffset", mesh->rotation_offset, 0);
        prop_vec3(o, "RotationPivot", mesh->rotation_pivot);
        prop_vec3_unless(o, "ScalingOffset", mesh->scaling_offset, 0);
        prop_vec3_unless(o, "ScalingPivot", mesh->scaling_pivot, 0);
        prop_vec3(o, "GeometricTranslation", mesh->geometric_translation);
        prop_vec3_unless(o, "GeometricRotation", mesh->geometric_rotation, 0);
        if (mesh->geometric_scaling[0] != 0 || mesh->geometric_scaling[1] != 0 || mesh->geometric_scaling[2] != 0)
            prop_vec3_unless(o, "GeometricScaling", mesh->geometric_scaling, 1);
        prop_vec3(o, "Lcl Translation", mesh->translation);
        prop_vec3(o, "Lcl Rotation", mesh->rotation);
        prop_begin(o, "Lcl Scaling", "Lcl Scaling", "", "A");
        for (int k = 0; k < 3; k++) v_real(o, s[k]);
        prop_end(o);
        end(o, 1);
        if (o->binary && o->type_mix) {
            begin(o, "Shading");
            v_char(o, 'Y');
            values_end(o, 0);
            end(o, 0);
        }
        leaf_str(o, "Culling", "CullingOff");
        end(o, 1);

        if (mesh->channel_count) {
            deformer_id[m] = new_id(&g);
            object_begin(o, "Deformer", deformer_id[m], "Deformer", mesh->name, "BlendShape", 1);
            leaf_i64(o, "Version", 100, 'I');
            end(o, 1);
        }
        for (uint32_t c = 0; c < mesh->channel_count; c++, ci++) {
            const fbxw_channel *ch = &mesh->channels[c];
            channel_id[ci] = new_id(&g);
            object_begin(o, "Deformer", channel_id[ci], "SubDeformer", ch->name, "BlendShapeChannel", 1);
            leaf_i64(o, "Version", 100, 'I');
            if (!ch->deform_as_field_only) {
                begin(o, "Properties70");
                values_end(o, 1);
                prop_begin(o, "DeformPercent", "Number", "", "A"); v_f64(o, ch->deform_percent); prop_end(o);
                end(o, 1);
            }
            leaf_f64(o, "DeformPercent", ch->deform_percent);
            leaf_array_as(o, "FullWeights", 'f', ch->full_weights, ch->full_weight_count);
            end(o, 1);
            for (uint32_t k = 0; k < ch->shape_count; k++, si++) {
                const fbxw_shape *sh = &ch->shapes[k];
                shape_id[si] = new_id(&g);
                object_begin(o, "Geometry", shape_id[si], "Geometry", sh->name, "Shape", 1);
                leaf_i64(o, "Version", 100, 'I');
                if (o->binary && o->type_mix) {
                    int64_t *wide = malloc(((size_t)sh->count + 1) * sizeof *wide);
                    if (!wide) o->failed = 1;
                    for (uint32_t k = 0; wide && k < sh->count; k++) wide[k] = sh->indexes[k];
                    begin(o, "Indexes");
                    if (wide) v_array_as(o, 'l', NULL, wide, sh->count);
                    values_end(o, 0);
                    end(o, 0);
                    free(wide);
                } else {
                    leaf_array(o, "Indexes", 'i', sh->indexes, sh->count, 0);
                }
                leaf_array(o, "Vertices", 'd', sh->deltas, 3 * (size_t)(sh->count - sh->short_deltas), 0);
                if (sh->normals) leaf_array(o, "Normals", 'd', sh->normals, 3 * (size_t)sh->count, 0);
                end(o, 1);
            }
            if (ch->curve) {
                animated = 1;
                node_id[ci] = new_id(&g);
                curve_id[ci] = new_id(&g);
                object_begin(o, "AnimationCurveNode", node_id[ci], "AnimCurveNode", "DeformPercent", "", 1);
                begin(o, "Properties70");
                values_end(o, 1);
                prop_begin(o, "d|DeformPercent", "Number", "", "A"); v_f64(o, ch->deform_percent); prop_end(o);
                end(o, 1);
                end(o, 1);
                write_curve(o, curve_id[ci], ch->curve, ch->deform_percent);
            }
        }
    }
    if (animated) {
        object_begin(o, "AnimationStack", stack_id, "AnimStack", "Take 001", "", 1);
        begin(o, "Properties70");
        values_end(o, 1);
        prop_begin(o, "LocalStart", "KTime", "Time", ""); v_i64(o, sc->stack_start, 'L'); prop_end(o);
        prop_begin(o, "LocalStop", "KTime", "Time", ""); v_i64(o, sc->stack_stop, 'L'); prop_end(o);
        end(o, 1);
        end(o, 1);
        object_begin(o, "AnimationLayer", layer_id, "AnimLayer", "BaseLayer", "", 0);
        end(o, 0);
    }
    end(o, 1);

    begin(o, "Connections");
    values_end(o, 1);
    ci = si = 0;
    for (uint32_t m = 0; m < sc->mesh_count && !o->failed; m++) {
        const fbxw_mesh *mesh = &sc->meshes[m];
        int parent = mesh->parent;
        connect(o, "OO", model_id[m], parent >= 0 && (uint32_t)parent < sc->mesh_count ? model_id[parent] : 0, NULL);
        connect(o, "OO", geom_id[m], model_id[m], NULL);
        if (mesh->channel_count) connect(o, "OO", deformer_id[m], geom_id[m], NULL);
        for (uint32_t c = 0; c < mesh->channel_count; c++, ci++) {
            const fbxw_channel *ch = &mesh->channels[c];
            connect(o, "OO", channel_id[ci], deformer_id[m], NULL);
            for (uint32_t k = 0; k < ch->shape_count; k++, si++) connect(o, "OO", shape_id[si], channel_id[ci], NULL);
            if (ch->curve) {
                connect(o, "OO", node_id[ci], layer_id, NULL);
                connect(o, "OP", node_id[ci], channel_id[ci], "DeformPercent");
                connect(o, "OP", curve_id[ci], node_id[ci], "d|DeformPercent");
            }
        }
    }
    if (animated) connect(o, "OO", layer_id, stack_id, NULL);
    end(o, 1);
    if (o->binary && o->type_mix) write_type_zoo(o);
    if (o->binary) {
        unsigned char zero[25] = { 0 };
        put(o, zero, (size_t)(o->wide ? 25 : 13));  /* closes the top-level list */
        unsigned char footer[160] = { 0 };
        put(o, footer, sizeof footer);
    }
    free(model_id);
    free(geom_id);
    free(deformer_id);
    free(channel_id);
    free(node_id);
    free(curve_id);
    free(shape_id);
}

static void setup(out *o, const fbxw_scene *sc)
{
    memset(o, 0, sizeof *o);
    o->binary = sc->binary;
    o->version = (int)sc->version;
    o->wide = sc->version >= 7500;
    o->compress = sc->compress;
    o->big = sc->binary && sc->big_endian;
    o->type_mix = sc->binary && sc->type_mix;
    if (sc->binary && (sc->compress || sc->type_mix)) {  /* the type zoo has zlib arrays */
        o->compressor = libdeflate_alloc_compressor(1);  /* fast: tests and the benchmark */
        if (!o->compressor) o->failed = 1;
    }
}

int fbxw_write(const fbxw_scene *scene, unsigned char **data, size_t *size)
{
    out o;
    setup(&o, scene);
    write_scene(&o, scene);
    if (o.compressor) libdeflate_free_compressor(o.compressor);
    if (o.failed) { free(o.data); return -1; }
    *data = o.data;
    *size = o.size;
    return 0;
}

int fbxw_write_file(const fbxw_scene *scene, const char *path)
{
    out o;
    setup(&o, scene);
    o.file = fopen(path, "w+b");
    if (!o.file) { if (o.compressor) libdeflate_free_compressor(o.compressor); return -1; }
    write_scene(&o, scene);
    if (o.compressor) libdeflate_free_compressor(o.compressor);
    if (fclose(o.file)) o.failed = 1;
    return o.failed ? -1 : 0;
}

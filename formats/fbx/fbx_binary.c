/* SPDX-License-Identifier: MIT */
/* Binary FBX reader: node records into the fbx_doc tree.
 *
 * Layout (Blender's "FBX binary file format specification", 2013; fbx-book; ufbx.c
 * ufbxi_binary_parse_node): a 27-byte header ("Kaydara FBX Binary  \0", 0x1A, an endianness
 * byte, u32 version), then node records. A record is EndOffset, NumProperties,
 * PropertyListLen, NameLen(u8), Name, properties, child records, and a null record closing
 * the child list. The three counters are u32 below header version 7500 and u64 from 7500
 * (the null record is 13 or 25 zero bytes). The header version decides, never FBXVersion:
 * 3ds Max 7 writes header 3000 with FBXVersion 5000.
 *
 * A non-zero endianness byte means big-endian (as ufbx decides; Maya can write such files):
 * the version, every record counter, scalar, string/array length and array header is then
 * stored most significant byte first, and so are array elements, also inside zlib streams
 * (fbx_dom.c swaps those on decode).
 *
 * Every offset and length is checked against the enclosing record and the file size; arrays
 * are not decoded here (fbx_dom.c does it on access), only their bounds are checked.
 */
#include <string.h>
#include "fbx_internal.h"

static const char fbx_magic[21] = "Kaydara FBX Binary  ";  /* 20 chars + NUL = 21 bytes */

int fbx_is_binary(const void *data, size_t size)
{
    return size >= 23 && memcmp(data, fbx_magic, 21) == 0;
}

typedef struct bin_parser {
    fbx_doc *doc;
    const uint8_t *data;
    uint64_t size;
    int big;                /* big-endian file */
    int wide;               /* 25-byte record headers */
    uint32_t header_size;
    /* Sibling stack: children of every open node are collected here and copied into the
     * arena when their parent closes, so each node's children are one contiguous array. */
    fbx_node *stack;
    size_t top, cap;
} bin_parser;

/* Unsigned integer of `bytes` bytes at b in the file's byte order. */
static uint64_t rd_uint(int big, const uint8_t *b, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++) v |= (uint64_t)b[big ? bytes - 1 - i : i] << (8 * i);
    return v;
}

static uint16_t rd_u16(const bin_parser *p, const uint8_t *b) { return (uint16_t)rd_uint(p->big, b, 2); }
static uint32_t rd_u32(const bin_parser *p, const uint8_t *b) { return (uint32_t)rd_uint(p->big, b, 4); }
static uint64_t rd_u64(const bin_parser *p, const uint8_t *b) { return rd_uint(p->big, b, 8); }

static mk_result push_node(bin_parser *p, const fbx_node *node)
{
    if (p->top == p->cap) {
        size_t cap = p->cap ? p->cap * 2 : 256;
        fbx_node *grown = mk_arena_realloc(p->doc->arena, p->stack, p->cap * sizeof *p->stack,
                                           cap * sizeof *p->stack);
        if (!grown) return mk_error_oom(p->doc->err, "FBX node stack");
        p->stack = grown;
        p->cap = cap;
    }
    p->stack[p->top++] = *node;
    return MK_OK;
}

static mk_result parse_values(bin_parser *p, fbx_node *node, uint64_t pos, uint64_t count,
                              uint64_t end)
{
    fbx_doc *doc = p->doc;
    /* Every value takes at least 2 bytes (type code + payload), which bounds the count. */
    if (count > (end - pos) / 2 + 1 || count > FBX_MAX_VALUES_PER_NODE)
        return mk_error_set(doc->err, MK_ERROR_PARSE, pos,
                            "FBX node '%.*s': %llu properties cannot fit in %llu bytes",
                            (int)node->name_length, node->name, (unsigned long long)count,
                            (unsigned long long)(end - pos));
    node->values = mk_arena_array(doc->arena, (size_t)count ? (size_t)count : 1, sizeof(fbx_value));
    if (!node->values) return mk_error_oom(doc->err, "FBX values");
    node->value_count = (uint32_t)count;
    for (uint64_t i = 0; i < count; i++) {
        fbx_value *v = &node->values[i];
        if (pos >= end)
            return mk_error_set(doc->err, MK_ERROR_PARSE, pos,
                                "FBX node '%.*s': property %llu starts past the property list",
                                (int)node->name_length, node->name, (unsigned long long)i);
        uint8_t type = p->data[pos];
        uint64_t at = pos++;
        uint64_t left = end - pos;
        v->offset = at;
        v->type = type;
        switch (type) {
        case 'Y':
            if (left < 2) goto truncated;
            v->kind = FBX_INT;
            v->u.i = (int16_t)rd_u16(p, p->data + pos);
            pos += 2;
            break;
        case 'C':
            if (left < 1) goto truncated;
            v->kind = FBX_CHAR;
            v->u.i = p->data[pos];
            pos += 1;
            break;
        case 'B': case 'Z':
            if (left < 1) goto truncated;
            v->kind = FBX_INT;
            v->u.i = p->data[pos];
            pos += 1;
            break;
        case 'I':
            if (left < 4) goto truncated;
            v->kind = FBX_INT;
            v->u.i = (int32_t)rd_u32(p, p->data + pos);
            pos += 4;
            break;
        case 'L':
            if (left < 8) goto truncated;
            v->kind = FBX_INT;
            v->u.i = (int64_t)rd_u64(p, p->data + pos);
            pos += 8;
            break;
        case 'F': {
            if (left < 4) goto truncated;
            uint32_t bits = rd_u32(p, p->data + pos);
            float f;
            memcpy(&f, &bits, 4);
            v->kind = FBX_FLOAT;
            v->u.f = f;
            pos += 4;
            break;
        }
        case 'D': {
            if (left < 8) goto truncated;
            uint64_t bits = rd_u64(p, p->data + pos);
            double d;
            memcpy(&d, &bits, 8);
            v->kind = FBX_FLOAT;
            v->u.f = d;
            pos += 8;
            break;
        }
        case 'S': case 'R': {
            if (left < 4) goto truncated;
            uint32_t length = rd_u32(p, p->data + pos);
            pos += 4;
            if (length > end - pos) goto truncated;
            v->kind = FBX_STRING;
            v->u.s.data = (const char *)p->data + pos;
            v->u.s.length = length;
            pos += length;
            break;
        }
        case 'f': case 'd': case 'l': case 'i': case 'b': case 'c': {
            if (left < 12) goto truncated;
            uint32_t count32 = rd_u32(p, p->data + pos);
            uint32_t encoding = rd_u32(p, p->data + pos + 4);
            uint32_t stored = rd_u32(p, p->data + pos + 8);
            pos += 12;
            if (stored > end - pos) goto truncated;
            uint64_t elem = (type == 'd' || type == 'l') ? 8 : (type == 'f' || type == 'i') ? 4 : 1;
            uint64_t bytes = (uint64_t)count32 * elem;
            if (encoding == 0) {
                if (bytes != stored)
                    return mk_error_set(doc->err, MK_ERROR_PARSE, at,
                                        "FBX node '%.*s': array of %u '%c' needs %llu bytes, has %u",
                                        (int)node->name_length, node->name, count32, type,
                                        (unsigned long long)bytes, stored);
            } else if (encoding == 1) {
                if (bytes > FBX_MAX_ARRAY_BYTES || bytes > (uint64_t)stored * FBX_MAX_INFLATE_RATIO + 64)
                    return mk_error_set(doc->err, MK_ERROR_LIMIT, at,
                                        "FBX node '%.*s': compressed array claims %llu bytes from %u "
                                        "(beyond what deflate can produce)",
                                        (int)node->name_length, node->name,
                                        (unsigned long long)bytes, stored);
            } else {
                return mk_error_set(doc->err, MK_ERROR_PARSE, at,
                                    "FBX node '%.*s': unknown array encoding %u",
                                    (int)node->name_length, node->name, encoding);
            }
            v->kind = FBX_ARRAY;
            v->encoding = (uint8_t)encoding;
            v->count = count32;
            v->u.a.data = p->data + pos;
            v->u.a.size = stored;
            pos += stored;
            break;
        }
        default:
            return mk_error_set(doc->err, MK_ERROR_PARSE, at,
                                "FBX node '%.*s': unknown property type 0x%02x",
                                (int)node->name_length, node->name, type);
        }
    }
    return MK_OK;
truncated:
    return mk_error_set(doc->err, MK_ERROR_PARSE, pos,
                        "FBX node '%.*s': property runs past the end of its property list",
                        (int)node->name_length, node->name);
}

/* Reads the record at *pos whose parent ends at `limit`. *is_null is set for the null record
 * that closes a child list. */
static mk_result parse_node(bin_parser *p, uint64_t *pos, uint64_t limit, uint32_t depth,
                            int *is_null)
{
    fbx_doc *doc = p->doc;
    uint64_t at = *pos;
    *is_null = 0;
    if (limit - at < p->header_size)
        return mk_error_set(doc->err, MK_ERROR_PARSE, at,
                            "FBX truncated: node record header needs %u bytes, %llu left",
                            p->header_size, (unsigned long long)(limit - at));
    const uint8_t *h = p->data + at;
    uint64_t end, count, list_length;
    if (p->wide) {
        end = rd_u64(p, h); count = rd_u64(p, h + 8); list_length = rd_u64(p, h + 16);
    } else {
        end = rd_u32(p, h); count = rd_u32(p, h + 4); list_length = rd_u32(p, h + 8);
    }
    uint8_t name_length = h[p->header_size - 1];
    if (end == 0 && name_length == 0 && count == 0 && list_length == 0) {
        *is_null = 1;
        *pos = at + p->header_size;
        return MK_OK;
    }
    if (depth >= FBX_MAX_DEPTH)
        return mk_error_set(doc->err, MK_ERROR_LIMIT, at, "FBX nodes nested deeper than %d",
                            FBX_MAX_DEPTH);
    uint64_t body = at + p->header_size;
    if (end > limit || end < body || name_length > end - body || list_length > end - body - name_length)
        return mk_error_set(doc->err, MK_ERROR_PARSE, at,
                            "FBX node record at %llu: end offset %llu outside its parent (ends at %llu) "
                            "or shorter than its name and properties",
                            (unsigned long long)at, (unsigned long long)end, (unsigned long long)limit);
    fbx_node node;
    memset(&node, 0, sizeof node);
    node.offset = at;
    node.end = end;
    node.depth = depth;
    node.name = (const char *)p->data + body;
    node.name_length = name_length;
    uint64_t values_at = body + name_length;
    uint64_t values_end = values_at + list_length;
    mk_result r = parse_values(p, &node, values_at, count, values_end);
    if (r != MK_OK) return r;
    uint64_t cursor = values_end;
    size_t first_child = p->top;
    while (cursor < end) {
        int child_null;
        r = parse_node(p, &cursor, end, depth + 1, &child_null);
        if (r != MK_OK) return r;
        if (child_null) break;
    }
    size_t child_count = p->top - first_child;
    if (child_count) {
        node.children = mk_arena_array(doc->arena, child_count, sizeof(fbx_node));
        if (!node.children) return mk_error_oom(doc->err, "FBX nodes");
        memcpy(node.children, p->stack + first_child, child_count * sizeof(fbx_node));
        node.child_count = (uint32_t)child_count;
        p->top = first_child;
    }
    *pos = end;
    return push_node(p, &node);
}

mk_result fbx_parse_binary(fbx_doc *doc)
{
    bin_parser p;
    memset(&p, 0, sizeof p);
    p.doc = doc;
    p.data = doc->data;
    p.size = doc->size;
    if (doc->size < 27 || !fbx_is_binary(doc->data, doc->size))
        return mk_error_set(doc->err, MK_ERROR_PARSE, 0, "not a binary FBX file (bad magic)");
    /* Byte 22: 0 little-endian, anything else big-endian (as ufbx decides). */
    p.big = p.data[22] != 0;
    doc->big_endian = p.big;
    doc->header_version = rd_u32(&p, p.data + 23);
    doc->version = doc->header_version;
    p.wide = doc->header_version >= 7500;
    p.header_size = p.wide ? 25 : 13;
    uint64_t pos = 27;
    int terminated = 0;
    while (pos < p.size) {
        int is_null;
        mk_result r = parse_node(&p, &pos, p.size, 0, &is_null);
        if (r != MK_OK) {
            mk_arena_release(doc->arena, p.stack);
            return r;
        }
        if (is_null) { terminated = 1; break; }
    }
    if (!terminated) {
        mk_arena_release(doc->arena, p.stack);
        return mk_error_set(doc->err, MK_ERROR_PARSE, pos,
                            "FBX truncated: the top-level node list has no closing null record");
    }
    memset(&doc->root, 0, sizeof doc->root);
    doc->root.name = "";
    if (p.top) {
        doc->root.children = mk_arena_array(doc->arena, p.top, sizeof(fbx_node));
        if (!doc->root.children) return mk_error_oom(doc->err, "FBX nodes");
        memcpy(doc->root.children, p.stack, p.top * sizeof(fbx_node));
        doc->root.child_count = (uint32_t)p.top;
    }
    mk_arena_release(doc->arena, p.stack);
    return MK_OK;
}

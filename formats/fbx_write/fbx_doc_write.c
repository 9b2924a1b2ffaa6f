/* SPDX-License-Identifier: MIT */
/* A parsed FBX file written back with new nodes (fbx_doc_write.h).
 *
 * Binary: the 27-byte header is copied; every record is written again from its original
 * bytes (name, value list, and whatever follows its last child up to its end: the null record)
 * with its EndOffset set to where it now ends; inserted nodes go before that tail. The footer
 * after the top-level null record is copied too. It ends with the version, 120 zero bytes and
 * a 16-byte magic, after zero padding that aligns the file as the writer aligned it: when the
 * body grows by d bytes, (-d mod 16) more zero bytes of padding keep that alignment. */
#include <stdlib.h>
#include <string.h>
#include "fbx_doc_write.h"

static const uint8_t footer_magic[16] = { 0xf8, 0x5a, 0x8c, 0x6a, 0xde, 0xf5, 0xd9, 0x7e,
                                          0xec, 0xe9, 0x0c, 0xe3, 0x75, 0x8f, 0x29, 0x0b };

typedef struct doc_writer {
    const fbx_doc *doc;
    const fbx_insertion *ins;
    uint32_t ins_count;
    fbx_bytes *out;
    int wide;
    size_t header;
} doc_writer;

static const fbx_insertion *insertion_for(const doc_writer *w, const fbx_node *node)
{
    for (uint32_t i = 0; i < w->ins_count; i++)
        if (w->ins[i].parent == node) return &w->ins[i];
    return NULL;
}

static uint64_t rd_le(const uint8_t *b, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++) v |= (uint64_t)b[i] << (8 * i);
    return v;
}

static void copy_record(doc_writer *w, const fbx_node *node)
{
    const uint8_t *data = w->doc->data;
    const int word = w->wide ? 8 : 4;
    const uint8_t *h = data + node->offset;
    const uint64_t value_count = rd_le(h + word, word), list_length = rd_le(h + 2 * word, word);
    const uint64_t values_at = node->offset + w->header + node->name_length;
    const uint64_t children_end = node->child_count ? node->children[node->child_count - 1].end : values_at + list_length;
    fbx_bytes *out = w->out;
    const size_t start = out->size;
    /* header placeholder, name and value list as they were */
    fbx_bytes_append(out, h, (size_t)(values_at + list_length - node->offset));
    for (uint32_t i = 0; i < node->child_count; i++) copy_record(w, &node->children[i]);
    const fbx_insertion *ins = insertion_for(w, node);
    if (ins)
        for (uint32_t i = 0; i < ins->count; i++) fbx_wn_write_binary(out, ins->nodes[i], 0, w->wide);
    fbx_bytes_append(out, data + children_end, (size_t)(node->end - children_end));
    if (ins && ins->count && !node->child_count && node->end == children_end) {
        static const uint8_t zeros[25];
        fbx_bytes_append(out, zeros, w->header);  /* the null record closing the new children */
    }
    fbx_record_header(out, start, w->wide, out->size, value_count, list_length, (uint8_t)node->name_length);
}

static mk_result write_binary(doc_writer *w)
{
    const fbx_doc *doc = w->doc;
    if (doc->big_endian)
        return mk_error_set(doc->err, MK_ERROR_UNSUPPORTED, 22,
                            "FBX: big-endian binary files cannot be written back (only little-endian ones)");
    w->wide = doc->header_version >= 7500;
    w->header = w->wide ? 25 : 13;
    fbx_bytes *out = w->out;
    fbx_bytes_append(out, doc->data, 27);
    for (uint32_t i = 0; i < doc->root.child_count; i++) copy_record(w, &doc->root.children[i]);
    if (insertion_for(w, &doc->root))
        return mk_error_set(doc->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "FBX writer: no top-level insertions");
    /* The top-level null record, then the footer. */
    const uint64_t body_end = doc->root.child_count ? doc->root.children[doc->root.child_count - 1].end : 27;
    const uint64_t root_end = body_end + w->header <= doc->size ? body_end + w->header : doc->size;
    fbx_bytes_append(out, doc->data + body_end, (size_t)(root_end - body_end));
    const uint8_t *footer = doc->data + root_end;
    const size_t footer_size = (size_t)(doc->size - root_end);
    const int64_t grown = (int64_t)out->size - (int64_t)root_end;
    if (footer_size >= 156 && memcmp(footer + footer_size - 16, footer_magic, 16) == 0) {
        static const uint8_t zeros[16];
        fbx_bytes_append(out, footer, footer_size - 140);
        fbx_bytes_append(out, zeros, (size_t)((16 - (grown & 15)) & 15));
        fbx_bytes_append(out, footer + footer_size - 140, 140);
    } else {
        fbx_bytes_append(out, footer, footer_size);
    }
    return MK_OK;
}

static int by_position(const void *a, const void *b)
{
    const fbx_insertion *x = *(const fbx_insertion *const *)a, *y = *(const fbx_insertion *const *)b;
    return x->parent->end < y->parent->end ? -1 : x->parent->end > y->parent->end;
}

static mk_result write_ascii(doc_writer *w)
{
    const fbx_doc *doc = w->doc;
    const fbx_insertion **order = mk_arena_array(w->out->arena, w->ins_count + 1u, sizeof *order);
    if (!order) return mk_error_oom(doc->err, "FBX output");
    uint32_t n = 0;
    for (uint32_t i = 0; i < w->ins_count; i++) {
        const fbx_node *parent = w->ins[i].parent;
        if (parent == &doc->root || parent->end == 0 || parent->end > doc->size || doc->data[parent->end - 1] != '}')
            return mk_error_set(doc->err, MK_ERROR_INVALID_ARGUMENT, parent->offset,
                                "FBX writer: node '%.*s' has no closing '}' to insert before", (int)parent->name_length,
                                parent->name);
        order[n++] = &w->ins[i];
    }
    qsort(order, n, sizeof *order, by_position);
    /* The file's line ending: CRLF when its first line ends so. */
    const uint8_t *first_newline = memchr(doc->data, '\n', doc->size);
    const int crlf = first_newline && first_newline > doc->data && first_newline[-1] == '\r';
    fbx_bytes text = { .arena = w->out->arena };
    uint64_t copied = 0;
    for (uint32_t i = 0; i < n; i++) {
        const uint64_t brace = order[i]->parent->end - 1;
        fbx_bytes_append(w->out, doc->data + copied, (size_t)(brace - copied));
        /* The brace may follow other text on its line: the new nodes start on a line of their own. */
        uint64_t line = brace;
        while (line > 0 && (doc->data[line - 1] == ' ' || doc->data[line - 1] == '\t')) line--;
        if (line > 0 && doc->data[line - 1] != '\n') fbx_bytes_append(w->out, crlf ? "\r\n" : "\n", crlf ? 2 : 1);
        text.size = 0;
        for (uint32_t k = 0; k < order[i]->count; k++)
            fbx_wn_write_ascii(&text, order[i]->nodes[k], order[i]->parent->depth + 1);
        for (size_t c = 0; c < text.size; c++) {
            if (crlf && text.data[c] == '\n') fbx_bytes_append(w->out, "\r", 1);
            fbx_bytes_append(w->out, text.data + c, 1);
        }
        w->out->failed |= text.failed;
        copied = brace;
    }
    fbx_bytes_append(w->out, doc->data + copied, (size_t)(doc->size - copied));
    mk_arena_release(text.arena, text.data);
    mk_arena_release(w->out->arena, order);
    return MK_OK;
}

mk_result fbx_doc_write(const fbx_doc *doc, const fbx_insertion *insertions, uint32_t count, fbx_bytes *out)
{
    doc_writer w = { doc, insertions, count, out, 0, 0 };
    mk_result r = doc->binary ? write_binary(&w) : write_ascii(&w);
    if (r == MK_OK && out->failed) r = mk_error_oom(doc->err, "FBX output");
    if (r == MK_OK && out->too_large)
        r = mk_error_set(doc->err, MK_ERROR_LIMIT, UINT64_MAX,
                         "FBX output passes 4 GiB, which a file before FBX 7.5 (32-bit record offsets) cannot address");
    return r;
}

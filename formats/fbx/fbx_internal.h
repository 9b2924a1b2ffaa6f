/* SPDX-License-Identifier: MIT */
/* FBX importer internals: the document tree both parsers build, its accessors, and the
 * interpretation steps (scene, mesh, blend shapes, curves, transforms).
 *
 * The tree mirrors the file: a node has a name, a list of values ("properties" in the binary
 * spec) and children. Scalars and strings are decoded while parsing; arrays are decoded lazily
 * (binary arrays keep their file offset and encoding, ASCII arrays keep their text span), so a
 * large file never holds more than the arrays currently being converted. Everything lives in
 * the parse arena; accessors that decode arrays allocate from it and the caller releases them.
 */
#ifndef MK_FBX_INTERNAL_H
#define MK_FBX_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "fbx_import.h"

/* Limits against hostile input (files from real tools are far below these). */
#define FBX_MAX_DEPTH 64              /* node nesting */
#define FBX_MAX_VALUES_PER_NODE (1u << 28)
#define FBX_MAX_ARRAY_BYTES ((uint64_t)1 << 32)  /* one decoded array */
#define FBX_MAX_INFLATE_RATIO 1100u   /* deflate cannot exceed ~1032:1 */

typedef enum fbx_value_kind {
    FBX_INT,      /* Y, I, L, B, Z (and C when numeric) */
    FBX_FLOAT,    /* F, D */
    FBX_CHAR,     /* C: binary one-byte char/bool, ASCII bare word (first char) */
    FBX_STRING,   /* S, R, ASCII quoted string */
    FBX_ARRAY     /* typed binary array or ASCII *N { a: ... } */
} fbx_value_kind;

typedef struct fbx_value {
    uint8_t kind;           /* fbx_value_kind */
    uint8_t type;           /* binary type code ('i','l','f','d','b','c') or 'a' (ASCII array) */
    uint8_t encoding;       /* binary arrays: 0 raw, 1 zlib */
    uint32_t count;         /* arrays: declared element count */
    uint64_t offset;        /* byte offset of the value in the file */
    union {
        int64_t i;          /* FBX_INT, FBX_CHAR */
        double f;           /* FBX_FLOAT */
        struct { const char *data; uint32_t length; } s;     /* FBX_STRING (decoded copy or file span) */
        struct { const uint8_t *data; uint64_t size; } a;    /* FBX_ARRAY: payload bytes / text */
    } u;
} fbx_value;

typedef struct fbx_node fbx_node;
struct fbx_node {
    const char *name;
    uint32_t name_length;
    uint32_t value_count;
    uint32_t child_count;
    uint32_t depth;
    fbx_value *values;
    fbx_node *children;
    const fbx_node *parent;
    uint64_t offset;        /* byte offset of the record / line start */
    uint64_t end;           /* byte after the record (binary EndOffset) / after the closing '}' (ASCII; for a
                             * node without children, the end of its value list) */
};

typedef struct fbx_doc {
    mk_arena *arena;
    const uint8_t *data;
    size_t size;
    int binary;
    int big_endian;         /* binary file with the big-endian header flag: array elements are swapped on decode */
    uint32_t version;       /* header version (binary) or "; FBX x.y.z" (ASCII); may be raised from FBXVersion */
    uint32_t header_version;/* as found in the header (binary) */
    fbx_node root;          /* children = top-level nodes */
    mk_error *err;
    void *inflater;         /* libdeflate decompressor, made on first use, freed by fbx_doc_free */
    struct { void *ptr; size_t size; } spare[4]; /* recycled array buffers (fbx_recycle) */
    uint32_t threads;       /* mk_import_options.threads: worker threads for fbx_prefetch and the shapes */
    struct fbx_prefetched *prefetched; /* arrays decoded ahead (fbx_prefetch), handed over by fbx_node_array */
    uint32_t prefetched_count;
} fbx_doc;

void fbx_doc_free(fbx_doc *doc);
/* Parses data (binary or ASCII, told apart by the magic) into doc, its tree in `arena`, errors
 * into err, parents linked, doc->version settled (the header's, or FBXVersion where the header
 * says nothing or below 6000: 3ds Max 7 writes header 3000 with FBXVersion 5000; 7400 when
 * neither does). A file without nodes is an error. Free with fbx_doc_free (fbx_dom.c). */
mk_result fbx_doc_parse(fbx_doc *doc, mk_arena *arena, const void *data, size_t size, mk_error *err);
/* KTime ticks per second of the document (ufbx): 46186158000 before FBX 8000, 141120000 after;
 * from FBXHeaderVersion 1004 the OtherFlags/TCDefinition field decides (127 = the old rate). */
#define FBX_TICKS_PER_SECOND_OLD 46186158000.0
#define FBX_TICKS_PER_SECOND_NEW 141120000.0
double fbx_doc_ticks(const fbx_doc *doc);

/* Parsers (fbx_binary.c, fbx_ascii.c). Fill doc->root; errors carry offsets. */
mk_result fbx_parse_binary(fbx_doc *doc);
mk_result fbx_parse_ascii(fbx_doc *doc);
int fbx_is_binary(const void *data, size_t size);

/* ASCII number helpers (fbx_ascii.c), shared by the parser and the lazy array decoder. */
/* 1 and the value when [s, s + n) spells NaN or infinity as some exporter writes it (C99 and
 * glibc "nan", "nan(...)", "inf", "infinity" in any case with an optional sign; the Windows
 * CRT's "1.#INF", "-1.#IND", "1.#QNAN", "1.#SNAN", optionally followed by digits). */
int fbx_ascii_not_finite(const char *s, size_t n, double *out);
/* Next value of an ASCII array body [s, s + size) from *pos: skips spaces, newlines, commas
 * and `;` comments (to the end of their line). Returns 0 at the end, else 1 with the token
 * in [*start, *pos). */
int fbx_ascii_array_token(const char *s, size_t size, size_t *pos, size_t *start);

/* ---- Tree accessors (fbx_dom.c) ---- */
/* Sets parent pointers and depths after parsing (the parsers move nodes while building). */
void fbx_link_parents(fbx_node *node);
int fbx_name_is(const fbx_node *node, const char *name);
const fbx_node *fbx_child(const fbx_node *node, const char *name);
/* Next child named `name` after `prev` (NULL: first). */
const fbx_node *fbx_next_child(const fbx_node *node, const fbx_node *prev, const char *name);
int fbx_value_int(const fbx_value *v, int64_t *out);
int fbx_value_float(const fbx_value *v, double *out);
/* String as a NUL-free span; returns 0 when not a string. */
int fbx_value_string(const fbx_value *v, const char **data, uint32_t *length);
/* Convenience: the i-th value of a child node. */
int fbx_child_int(const fbx_node *node, const char *name, int64_t *out);
int fbx_child_float(const fbx_node *node, const char *name, double *out);
int fbx_child_string(const fbx_node *node, const char *name, const char **data, uint32_t *length);

/* Node path for messages: "Objects/Geometry/Vertices". */
void fbx_node_path(const fbx_node *node, char *buffer, size_t size);

/* Array of a node's data as the requested element type. Works for a typed binary array, an
 * ASCII *N array, or a run of scalar values (FBX 5.x/6.x); `first` skips leading values (for
 * `Key:` runs after scalar headers). Allocates from doc->arena (release with
 * mk_arena_release); count 0 gives a valid pointer. Errors name the node path and offset. */
typedef enum fbx_elem { FBX_ELEM_F64, FBX_ELEM_F32, FBX_ELEM_I32, FBX_ELEM_I64, FBX_ELEM_F32_BITS } fbx_elem;
mk_result fbx_node_array(fbx_doc *doc, const fbx_node *node, fbx_elem elem, void **out, size_t *count);
/* Same for the child named `name`; *out NULL and count 0 when the child is absent (MK_OK). */
mk_result fbx_child_array(fbx_doc *doc, const fbx_node *node, const char *name, fbx_elem elem,
                          void **out, size_t *count);
/* fbx_prefetch (fbx_prefetch.c) decodes the arrays of nodes[i] as elems[i] (a node may be NULL) on
 * doc->threads worker threads, so that the next fbx_node_array of each (node, elem) returns at
 * once what decoding it then would return: the array, or the error (with the same message).
 * Small arrays, and a single large one, are left to be decoded when asked; so is everything
 * when the bookkeeping cannot be allocated. fbx_prefetch_drop releases what was not asked
 * for (call it before the next fbx_prefetch and before the document is freed). fbx_prefetch_take
 * and fbx_prefetch_drop are in fbx_dom.c, beside the decoder that hands the arrays over. */
typedef struct fbx_prefetched {
    const fbx_node *node;   /* NULL once handed over */
    fbx_elem elem;
    void *data;             /* doc->arena */
    size_t count;
    mk_result result;
    mk_error error;
} fbx_prefetched;
void fbx_prefetch(fbx_doc *doc, const fbx_node *const *nodes, const fbx_elem *elems, uint32_t count);
void fbx_prefetch_drop(fbx_doc *doc);
/* The prefetched (node, elem) of fbx_prefetch: 1 and the result in *r when there is one. */
int fbx_prefetch_take(fbx_doc *doc, const fbx_node *node, fbx_elem elem, void **out, size_t *count, mk_result *r);

/* The element count fbx_node_array gives for `node` when it succeeds, without decoding. */
size_t fbx_node_array_length(const fbx_node *node);
/* Gives back an array of fbx_node_array (`size` bytes: its count times the element size) for
 * the next arrays to reuse: a blend shape's arrays are decoded, expanded and dropped, and a
 * fresh buffer for every shape costs a zeroed page for every page. Small arrays, and arrays
 * with no room left among the spares, are released. ptr may be NULL. */
void fbx_recycle(fbx_doc *doc, void *ptr, size_t size);
/* Byte offset in the file of value `index` of a node's data: the element of a raw binary
 * array, the token of an ASCII array, the scalar of a value run (FBX 5.x/6.x, and any node's
 * plain values). Elements of a zlib array have no offset of their own: the array's is given
 * and *zlib set. Used on error paths only (ASCII arrays are re-scanned). */
uint64_t fbx_value_offset(const fbx_doc *doc, const fbx_node *node, size_t index, int *zlib);
/* MK_ERROR_NOT_FINITE for value `index` of `node` (an array or a node's plain values, e.g. a
 * P property): "FBX <path>: <what> is not finite (NaN, infinite or beyond float range; value
 * <index> at byte <offset>)", with err->offset set to that byte. The binary and ASCII paths
 * report the same way: the value is checked where it is used, after decoding. */
mk_result fbx_error_not_finite(fbx_doc *doc, const fbx_node *node, size_t index, const char *what_fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* ---- Properties (fbx_dom.c): Properties70 "P" and Properties60 "Property" ---- */
typedef struct fbx_props {
    const fbx_node *block;  /* Properties70 / Properties60 node, or NULL */
    int legacy;             /* Properties60: 3 metadata strings instead of 4 */
} fbx_props;
fbx_props fbx_props_of(const fbx_node *object);
/* The P node with that name, or NULL. */
const fbx_node *fbx_prop_find(fbx_props props, const char *name);
/* Number (first value after the metadata); returns 0 and leaves out unchanged when absent. */
int fbx_prop_number_opt(fbx_props props, const char *name, double *out);
/* 3 numbers; returns 0 and leaves out unchanged when absent. */
int fbx_prop_vec3(fbx_props props, const char *name, double out[3]);
int fbx_prop_int64(fbx_props props, const char *name, int64_t *out);
/* Value index where a P node's payload starts. */
uint32_t fbx_prop_payload(fbx_props props);

/* ---- Interpretation (fbx_scene.c etc.) ---- */
mk_result fbx_convert(fbx_doc *doc, const mk_import_options *options, mk_raw_asset *out);
/* fbx_normals.c: target normals for the meshes from first_mesh on (after the parse data is released). */
mk_result fbx_target_normals(mk_raw_asset *raw, uint32_t first_mesh, const mk_import_options *options, mk_error *err);

#endif

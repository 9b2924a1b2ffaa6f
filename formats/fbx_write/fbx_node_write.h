/* SPDX-License-Identifier: MIT */
/* New FBX nodes made in memory, and their bytes: binary node records (either record width) or
 * ASCII text. The write-back (fbx_write_back.c) builds the objects and connections it adds with
 * these; the document writer (fbx_doc_write.c) puts them into the copied file.
 *
 * A node has a name, typed values and children, all in one arena. Value types are the binary
 * type codes: 'I' int32, 'L' int64, 'D' double, 'S' string, 'R' raw bytes (binary only), and the
 * arrays 'i' int32, 'l' int64, 'f' float, 'd' double.
 * An object name is the pair (class, name): binary files spell it "name\0\1class", ASCII files
 * "class::name" (fbx_wn_object_name).
 */
#ifndef MK_FBX_NODE_WRITE_H
#define MK_FBX_NODE_WRITE_H

#include <stddef.h>
#include <stdint.h>
#include "alloc.h"

typedef struct fbx_wvalue {
    char type;                 /* 'I', 'L', 'D', 'S', 'R', 'i', 'l', 'f', 'd' */
    uint32_t count;            /* arrays: element count; strings: byte length */
    union {
        int64_t i;
        double d;
        const char *s;
        const int32_t *ai;
        const int64_t *al;
        const float *af;
        const double *ad;
    } u;
} fbx_wvalue;

typedef struct fbx_wnode fbx_wnode;
struct fbx_wnode {
    const char *name;
    fbx_wvalue *values;
    uint32_t value_count, value_cap;
    fbx_wnode **children;
    uint32_t child_count, child_cap;
};

/* A growing byte buffer in an arena. Appends set `failed` instead of returning errors;
 * `too_large` is set when a record of a file with 13-byte record headers would end past 4 GiB
 * (its u32 EndOffset cannot say where). */
typedef struct fbx_bytes {
    mk_arena *arena;
    uint8_t *data;
    size_t size, cap;
    int failed, too_large;
} fbx_bytes;

void fbx_bytes_append(fbx_bytes *b, const void *data, size_t size);
void fbx_bytes_printf(fbx_bytes *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Node builder: each returns NULL (or 0) when the arena is out of memory. */
fbx_wnode *fbx_wn_new(mk_arena *arena, const char *name);
fbx_wnode *fbx_wn_child(mk_arena *arena, fbx_wnode *parent, const char *name);
int fbx_wn_add(mk_arena *arena, fbx_wnode *node, fbx_wvalue value);
int fbx_wn_int(mk_arena *arena, fbx_wnode *node, int32_t v);
int fbx_wn_long(mk_arena *arena, fbx_wnode *node, int64_t v);
int fbx_wn_double(mk_arena *arena, fbx_wnode *node, double v);
int fbx_wn_string(mk_arena *arena, fbx_wnode *node, const char *s, size_t length);
/* The object name value: "name\0\1class" (binary) or "class::name" (ASCII). */
int fbx_wn_object_name(mk_arena *arena, fbx_wnode *node, int binary, const char *cls, const char *name);
/* A "P" child of a Properties70 node: name, type, label, flags, value. */
fbx_wnode *fbx_wn_prop(mk_arena *arena, fbx_wnode *properties70, const char *name, const char *type,
                       const char *label, const char *flags, fbx_wvalue value);
/* An array child: `name` with one array value of `count` elements of `type` ('i','l','f','d'). */
fbx_wnode *fbx_wn_array(mk_arena *arena, fbx_wnode *parent, const char *name, char type, const void *data,
                        uint32_t count);

/* Appends the binary record of `node`; `base` is the file offset of out->data[0] (EndOffsets
 * count from the file's start). 25-byte record headers when `wide` (header version >= 7500),
 * else 13. A null record closes the children, and follows a node with neither values nor
 * children (as the FBX SDK and Blender write them). */
void fbx_wn_write_binary(fbx_bytes *out, const fbx_wnode *node, uint64_t base, int wide);
/* Record header fields at `at` of out (after the record is complete); sets out->too_large
 * when a narrow header cannot hold a field. */
void fbx_record_header(fbx_bytes *out, size_t at, int wide, uint64_t end, uint64_t value_count, uint64_t list_length,
                       uint8_t name_length);
/* ASCII text of `node` at nesting `depth` (tabs), ending with a newline. */
void fbx_wn_write_ascii(fbx_bytes *out, const fbx_wnode *node, uint32_t depth);

#endif

/* SPDX-License-Identifier: MIT */
/* A parsed FBX file written back with new nodes appended to some of its nodes (fbx_doc_write.c).
 * Everything else is copied: a binary file's records keep their names and value bytes (arrays
 * stay deflated as they were) and only their EndOffsets move; an ASCII file's text is copied and
 * the new nodes' text goes in before the closing '}' of their parent. */
#ifndef MK_FBX_DOC_WRITE_H
#define MK_FBX_DOC_WRITE_H

#include "fbx_internal.h"
#include "fbx_node_write.h"

typedef struct fbx_insertion {
    const fbx_node *parent;        /* a node of the document that has children (Objects, Connections) */
    fbx_wnode *const *nodes;       /* appended after its children, in order */
    uint32_t count;
} fbx_insertion;

/* Writes doc (parsed from doc->data, little-endian if binary) with the insertions into out;
 * errors go to doc->err. With no insertions the bytes are the input's. */
mk_result fbx_doc_write(const fbx_doc *doc, const fbx_insertion *insertions, uint32_t count, fbx_bytes *out);

#endif

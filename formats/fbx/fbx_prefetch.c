/* SPDX-License-Identifier: MIT */
/* A mesh's large arrays (control points, polygon vertices, normal and UV layers) decoded
 * together on worker threads (offline/parallel.h) before the mesh code asks for them one by
 * one: inflating them is most of the mesh step. Each worker decodes with its own copy of the
 * document (its own decoder and arena; the first worker, the calling thread, the document's
 * arena and spare arrays); the arrays are adopted by the document's arena afterwards. A decode
 * does not depend on which worker runs it, so what fbx_node_array hands over is what it would
 * have decoded itself, error messages included. Handing over and dropping the arrays
 * (fbx_prefetch_take, fbx_prefetch_drop) is the decoder's, in fbx_dom.c: this file only calls
 * the decoder. */
#include <string.h>
#include "fbx_internal.h"
#include "parallel.h"

/* Below this many decoded bytes an array is not worth a thread. */
#define PREFETCH_MIN_BYTES ((uint64_t)256 << 10)

typedef struct prefetch_worker {
    fbx_doc doc;
    mk_arena arena;            /* workers past the first */
} prefetch_worker;

typedef struct prefetch_loop {
    fbx_prefetched *items;
    prefetch_worker *workers;
} prefetch_loop;

static void prefetch_item(void *user, uint32_t item, uint32_t worker)
{
    prefetch_loop *l = user;
    fbx_prefetched *p = &l->items[item];
    fbx_doc *doc = &l->workers[worker].doc;
    doc->err = &p->error;
    p->result = fbx_node_array(doc, p->node, p->elem, &p->data, &p->count);
}

/* Decoded bytes of a node's array as `elem` (0 when it is not one array value). */
static uint64_t decoded_bytes(const fbx_node *node, fbx_elem elem)
{
    if (!node || node->value_count != 1 || node->values[0].kind != FBX_ARRAY) return 0;
    return (uint64_t)node->values[0].count * ((elem == FBX_ELEM_F64 || elem == FBX_ELEM_I64) ? 8u : 4u);
}

void fbx_prefetch(fbx_doc *doc, const fbx_node *const *nodes, const fbx_elem *elems, uint32_t count)
{
    fbx_prefetch_drop(doc);
    uint32_t n = 0;
    for (uint32_t i = 0; i < count; i++) n += decoded_bytes(nodes[i], elems[i]) >= PREFETCH_MIN_BYTES;
    uint32_t workers = mk_parallel_threads(mk_arena_threads(doc->arena, doc->threads), n);
    if (n < 2 || workers < 2) return;
    fbx_prefetched *items = mk_arena_array(doc->arena, n, sizeof *items);
    prefetch_worker *w = mk_arena_array(doc->arena, workers, sizeof *w);
    if (!items || !w) {
        mk_arena_release(doc->arena, items);
        mk_arena_release(doc->arena, w);
        return;
    }
    n = 0;
    for (uint32_t i = 0; i < count; i++)
        if (decoded_bytes(nodes[i], elems[i]) >= PREFETCH_MIN_BYTES) {
            items[n].node = nodes[i];
            items[n].elem = elems[i];
            n++;
        }
    for (uint32_t k = 0; k < workers; k++) {
        w[k].doc = *doc;  /* prefetched is NULL: fbx_node_array decodes */
        if (k == 0) continue;  /* the calling thread: the document's arena, decoder and spares */
        mk_arena_init(&w[k].arena, &doc->arena->allocator);
        w[k].doc.arena = &w[k].arena;
        w[k].doc.inflater = NULL;
        memset(w[k].doc.spare, 0, sizeof w[k].doc.spare);
    }
    prefetch_loop l = { items, w };
    mk_parallel_for(n, workers, prefetch_item, &l);
    doc->inflater = w[0].doc.inflater;
    memcpy(doc->spare, w[0].doc.spare, sizeof doc->spare);
    for (uint32_t k = 1; k < workers; k++) {
        fbx_doc_free(&w[k].doc);
        mk_arena_adopt(doc->arena, &w[k].arena);
    }
    mk_arena_release(doc->arena, w);
    doc->prefetched = items;
    doc->prefetched_count = n;
}

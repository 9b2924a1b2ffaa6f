/* SPDX-License-Identifier: MIT */
/* Prints the node tree of an FBX file (development aid; not a test). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fbx_internal.h"

static fbx_doc *g_doc;
static void dump(const fbx_node *n, int depth, int max_values)
{
    printf("%*s%.*s:", depth * 2, "", (int)n->name_length, n->name);
    for (uint32_t i = 0; i < n->value_count && (int)i < max_values; i++) {
        const fbx_value *v = &n->values[i];
        switch (v->kind) {
        case FBX_INT: printf(" %lld", (long long)v->u.i); break;
        case FBX_FLOAT: printf(" %.9g", v->u.f); break;
        case FBX_CHAR: printf(" '%c'", (char)v->u.i); break;
        case FBX_STRING: {
            printf(" \"");
            for (uint32_t k = 0; k < v->u.s.length && k < 80; k++) {
                char c = v->u.s.data[k];
                if (c >= 32 && c < 127) putchar(c); else printf("\\x%02x", (unsigned char)c);
            }
            printf("\"");
            break;
        }
        case FBX_ARRAY: {
            printf(" [%c x%u enc%u]", v->type, v->count, v->encoding);
            double *a;
            size_t c;
            if (n->value_count == 1 && fbx_node_array(g_doc, n, FBX_ELEM_F64, (void **)&a, &c) == MK_OK) {
                for (size_t k = 0; k < c && (int)k < max_values; k++) printf(" %.9g", a[k]);
                if (c > (size_t)max_values) printf(" ...");
            }
            break;
        }
        }
    }
    if (n->value_count > (uint32_t)max_values) printf(" ... (%u values)", n->value_count);
    printf("\n");
    for (uint32_t i = 0; i < n->child_count; i++) dump(&n->children[i], depth + 1, max_values);
}

int main(int argc, char **argv)
{
    if (argc < 2) { fprintf(stderr, "usage: fbx_dump file.fbx [max_values]\n"); return 2; }
    FILE *f = fopen(argv[1], "rb");
    if (!f) { perror(argv[1]); return 1; }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc((size_t)size + 1);
    if (fread(data, 1, (size_t)size, f) != (size_t)size) return 1;
    fclose(f);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_error err;
    memset(&err, 0, sizeof err);
    fbx_doc doc;
    memset(&doc, 0, sizeof doc);
    doc.arena = &arena;
    doc.data = data;
    doc.size = (size_t)size;
    doc.err = &err;
    mk_result r = fbx_is_binary(data, (size_t)size) ? fbx_parse_binary(&doc) : fbx_parse_ascii(&doc);
    if (r != MK_OK) {
        printf("error %d at %llu: %s\n", r, (unsigned long long)err.offset, err.message);
        mk_arena_free_all(&arena);
        free(data);
        return 1;
    }
    fbx_link_parents(&doc.root);
    g_doc = &doc;
    printf("version %u binary %d\n", doc.version, fbx_is_binary(data, (size_t)size));
    for (uint32_t i = 0; i < doc.root.child_count; i++) dump(&doc.root.children[i], 0, argc > 2 ? atoi(argv[2]) : 12);
    fbx_doc_free(&doc);
    mk_arena_free_all(&arena);
    free(data);
    return 0;
}

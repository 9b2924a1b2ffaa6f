/* SPDX-License-Identifier: MIT */
/* Writes fuzz seeds for fuzz_open: the test fixtures as blobs (q16 and float), each prefixed
 * with the "recompute checksum" selector byte. usage: make_seeds DIR */
#include <stdio.h>
#include "fixtures.h"

static int put(const char *dir, const char *name, const mk_raw_asset *raw, mk_precision p)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    size_t size;
    void *blob = fixture_blob(raw, p, &arena, &size);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    fputc(1, f);
    fwrite(blob, 1, size, f);
    fclose(f);
    mk_arena_free_all(&arena);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) return 2;
    mk_raw_asset a, b;
    mk_raw_init(&a, NULL);
    mk_raw_init(&b, NULL);
    fixture_basic(&a);
    fixture_line(&b, 200, 5, 3);
    int r = put(argv[1], "basic_q16", &a, MK_PRECISION_Q16) | put(argv[1], "basic_float", &a, MK_PRECISION_FLOAT)
          | put(argv[1], "line_q16", &b, MK_PRECISION_Q16);
    mk_raw_free(&a);
    mk_raw_free(&b);
    return r;
}

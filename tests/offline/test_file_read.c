/* SPDX-License-Identifier: MIT */
/* mk_read_file_threads: files around the 8 MB split threshold and the 4 MB part size, read on
 * 1, 2, 3 threads and one per core, give the same bytes as mk_read_file (and the NUL after
 * them); the size limit still applies to a split read. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "blob_io.h"
#include "check.h"

#define MB ((size_t)1 << 20)

static void pattern(uint8_t *p, size_t n, uint32_t seed)
{
    uint32_t x = seed;
    for (size_t i = 0; i < n; i++) {
        x = x * 1664525u + 1013904223u;
        p[i] = (uint8_t)(x >> 24);
    }
}

static int write_file(const char *path, const uint8_t *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(p, 1, n, f) == n;
    return fclose(f) == 0 && ok;
}

static void test_split_reads_give_the_same_bytes(void)
{
    const size_t sizes[] = { 1, 8 * MB - 1, 8 * MB, 8 * MB + 1, 12 * MB, 17 * MB + 3 };
    const uint32_t threads[] = { 1, 2, 3, 0 };
    char path[256];
    snprintf(path, sizeof path, "mk_file_read_test.%ld.bin", (long)getpid());
    uint8_t *expect = malloc(17 * MB + 3);
    CHECK(expect != NULL);
    if (!expect) return;
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        const size_t n = sizes[s];
        pattern(expect, n, (uint32_t)(s + 1));
        CHECK(write_file(path, expect, n));
        for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
            mk_arena arena;
            mk_arena_init(&arena, NULL);
            void *data = NULL;
            size_t size = 0;
            mk_error err;
            mk_result r = mk_read_file_threads(&arena, path, 0, threads[t], &data, &size, &err);
            CHECK_EQ_INT(r, MK_OK);
            CHECK_EQ_INT(size, n);
            if (r == MK_OK && size == n) {
                CHECK(memcmp(data, expect, n) == 0);
                CHECK(((const uint8_t *)data)[n] == 0);
            }
            mk_arena_free_all(&arena);
        }
    }
    /* The limit is checked before a split read. */
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    void *data = NULL;
    size_t size = 0;
    mk_error err;
    CHECK_EQ_INT(mk_read_file_threads(&arena, path, 16 * MB, 2, &data, &size, &err), MK_ERROR_LIMIT);
    CHECK(strstr(err.message, "exceeds the limit") != NULL);
    mk_arena_free_all(&arena);
    unlink(path);
    free(expect);
}

CHECK_MAIN(CASE(test_split_reads_give_the_same_bytes))

/* SPDX-License-Identifier: MIT */
/* The runtime never allocates: open, sample, evaluate (every mode) and surface normals under a malloc hook
 * that counts calls. The hook replaces the allocator for this test program only; under
 * AddressSanitizer (which owns malloc) the case reports itself skipped, and the symbol check
 * (check_runtime_symbols.sh) covers that the runtime references no allocator at all. */
#include <stdlib.h>
#include "check.h"
#include "fixtures.h"

#if defined(__SANITIZE_ADDRESS__)
#define HOOK 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HOOK 0
#endif
#endif
#ifndef HOOK
#define HOOK 1
#endif

#if HOOK
extern void *__libc_malloc(size_t);
extern void *__libc_calloc(size_t, size_t);
extern void *__libc_realloc(void *, size_t);
extern void __libc_free(void *);
static volatile int counting;
static volatile long calls;
void *malloc(size_t n) { if (counting) calls++; return __libc_malloc(n); }
void *calloc(size_t a, size_t b) { if (counting) calls++; return __libc_calloc(a, b); }
void *realloc(void *p, size_t n) { if (counting) calls++; return __libc_realloc(p, n); }
void free(void *p) { if (counting && p) calls++; __libc_free(p); }
#endif

static void test_runtime_allocates_nothing(void)
{
#if !HOOK
    SKIP("AddressSanitizer owns malloc; see check_runtime_symbols");
#else
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_basic(&raw);
    size_t size;
    void *blob = fixture_blob(&raw, MK_PRECISION_Q16, &raw.arena, &size);
    static float w[5], p[64], n[64], t[64];
    static _Alignas(16) unsigned char scratch[1024], topology[2048], surface_scratch[1024];
    mk_asset a;
    mk_error err;
    uint32_t cursors[2] = { 0, 0 };
    calls = 0;
    counting = 1;
    int ok = mk_asset_open(blob, size, &a, &err) == MK_OK;
    for (int frame = 0; ok && frame < 50; frame++) {
        mk_sample_job s = { .asset = &a, .clip = 0, .time = 0.02f * (float)frame, .weights = w, .weight_count = 5,
                            .cursors = cursors, .cursor_count = 2, .loop = frame & 1 };
        ok &= mk_sample_run(&s, &err) == MK_OK;
        mk_eval_job j = { .asset = &a, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = 4,
                          .stacking = (mk_stacking)(1 + frame % 2), .normal_mode = (mk_normal_mode)((frame / 2) % 2),
                          .scratch = scratch, .scratch_size = sizeof scratch, .positions = p, .positions_size = sizeof p,
                          .normals = n, .normals_size = sizeof n, .tangents = t, .tangents_size = sizeof t };
        ok &= mk_eval_run(&j, &err) == MK_OK;
        mk_surface_job sj = { .asset = &a, .mesh = 0, .topology = topology, .topology_size = sizeof topology,
                              .positions = p, .positions_size = sizeof p, .vertex_count = MK_VERTICES_TO_END,
                              .normals = n, .normals_size = sizeof n, .tangents = t, .tangents_size = sizeof t,
                              .scratch = surface_scratch, .scratch_size = sizeof surface_scratch };
        ok &= (frame == 0 ? mk_surface_topology_build(&a, 0, topology, sizeof topology, &err) : MK_OK) == MK_OK;
        ok &= mk_surface_run(&sj, &err) == MK_OK;
        j.weights = NULL;                      /* error paths must not allocate either */
        ok &= mk_eval_run(&j, &err) != MK_OK;
        sj.topology_size = 8;
        ok &= mk_surface_run(&sj, &err) != MK_OK;
    }
    counting = 0;
    CHECK(ok);
    CHECK_EQ_INT(calls, 0);
    mk_raw_free(&raw);
#endif
}

CHECK_MAIN(CASE(test_runtime_allocates_nothing))

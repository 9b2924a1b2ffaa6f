/* SPDX-License-Identifier: MIT */
/* libFuzzer target: bake recipes (baker/recipe/) on a small generated mesh. Any input must
 * give MK_OK or a clean error -- never a crash, an out-of-bounds access or a leak -- and on
 * error the raw model keeps its channels. Recipes run as untrusted (no file reads, capped work).
 * tests/baker/test_fuzz_recipe.c runs this same function over the sample recipes with
 * truncations and byte flips as a plain regression test. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "mat4.h"
#include "bake.h"

static void make_mesh(mk_raw_asset *raw)
{
    /* 5 x 5 vertex curved sheet named like the sample recipes' mesh (the samples/recipes JSON files
     * are the seeds), so every op has something to move */
    enum { N = 5 };
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    if (!m) return;
    m->name = "tube";
    m->vertex_count = N * N;
    m->positions = mk_arena_array(&raw->arena, 3 * N * N, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * N * N, sizeof(float));
    m->triangle_count = 2 * (N - 1) * (N - 1);
    m->triangles = mk_arena_array(&raw->arena, 3 * (size_t)m->triangle_count, sizeof(uint32_t));
    if (!m->positions || !m->normals || !m->triangles) { m->vertex_count = 0; m->triangle_count = 0; return; }
    for (uint32_t j = 0; j < N; j++)
        for (uint32_t i = 0; i < N; i++) {
            uint32_t v = j * N + i;
            m->positions[3 * v] = 0.5f * (float)i - 1;
            m->positions[3 * v + 1] = 0.5f * (float)j;
            m->positions[3 * v + 2] = 0.1f * (float)(i * i);
            m->normals[3 * v + 2] = 1;
        }
    uint32_t t = 0;
    for (uint32_t j = 0; j + 1 < N; j++)
        for (uint32_t i = 0; i + 1 < N; i++) {
            uint32_t a = j * N + i, b = a + 1, c = a + N, d = c + 1;
            uint32_t *tri = m->triangles + 6 * t++;
            tri[0] = a; tri[1] = b; tri[2] = d; tri[3] = a; tri[4] = d; tri[5] = c;
        }
    mk_mat4_identity(m->world);
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = -1;
    m->stacking = MK_STACKING_ADDITIVE;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 1 << 16) return 0;
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    make_mesh(&raw);
    mk_bake_options options;
    memset(&options, 0, sizeof options);
    options.untrusted = 1;
    mk_bake_report report;
    mk_error err;
    mk_result r = mk_bake_recipe(&raw, (const char *)data, size, &options, &report, &err);
    if (r != MK_OK && raw.channel_count != 0) abort();  /* all-or-nothing violated */
    if (r == MK_OK && mk_raw_validate(&raw, &err) != MK_OK) abort();  /* baked something invalid */
    mk_raw_free(&raw);
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* The synthetic benchmark asset: a wavy grid whose targets move spatially coherent regions. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include "synthetic.h"

/* A w x h grid (wavy height) with normals; targets move the vertices inside 3 disks. */
mk_result bench_build_synthetic(const bench_synthetic *o, mk_raw_asset *raw, mk_error *err)
{
    uint32_t w = (uint32_t)ceil(sqrt((double)o->vertices));
    uint32_t h = (o->vertices + w - 1) / w;
    uint32_t n = o->vertices;
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    if (!m) return mk_error_oom(err, "building the synthetic mesh");
    m->name = mk_arena_strdup(&raw->arena, "synthetic");
    m->vertex_count = n;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    uint32_t quads = (w - 1) * (h - 1);
    m->triangles = mk_arena_array(&raw->arena, 6 * (size_t)quads, sizeof(uint32_t));
    if (!m->name || !m->positions || !m->normals || !m->triangles)
        return mk_error_oom(err, "building the synthetic mesh");
    for (uint32_t v = 0; v < n; v++) {
        float x = (float)(v % w) / (float)w, y = (float)(v / w) / (float)h;
        m->positions[3 * v] = x;
        m->positions[3 * v + 1] = y;
        m->positions[3 * v + 2] = 0.02f * sinf(20 * x) * cosf(17 * y);
        m->normals[3 * v + 2] = 1;
    }
    uint32_t t = 0;
    for (uint32_t y = 0; y + 1 < h; y++)
        for (uint32_t x = 0; x + 1 < w; x++) {
            uint32_t a = y * w + x, b = a + 1, c = a + w, d = c + 1;
            if (d >= n) continue;
            uint32_t *tri = &m->triangles[6 * (size_t)t++];
            tri[0] = a;
            tri[1] = b;
            tri[2] = d;
            tri[3] = a;
            tri[4] = d;
            tri[5] = c;
        }
    m->triangle_count = 2 * t;
    uint32_t progressive = o->channels / 5;
    mk_raw_channel *channels = mk_raw_add_channels(raw, o->channels);
    if (!channels) return mk_error_oom(err, "building channels");
    uint32_t *scratch = mk_arena_array(&raw->arena, n, sizeof(uint32_t));
    if (!scratch) return mk_error_oom(err, "building channels");
    double radius = sqrt(o->density * (double)n / (3.0 * 3.14159265));
    uint64_t seed = 12345;
    for (uint32_t c = 0; c < o->channels; c++) {
        mk_raw_channel *ch = &channels[c];
        char name[32];
        snprintf(name, sizeof name, "channel%03u", c);
        ch->name = mk_arena_strdup(&raw->arena, name);
        uint32_t targets = c < progressive ? 2 : 1;
        if (!mk_raw_add_targets(raw, ch, targets)) return mk_error_oom(err, "building targets");
        /* Three disk centres per channel (an LCG keeps it deterministic). */
        double cx[3], cy[3];
        for (int k = 0; k < 3; k++) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            cx[k] = radius + (double)(seed >> 33) / 2147483648.0 * (w - 2 * radius);
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            cy[k] = radius + (double)(seed >> 33) / 2147483648.0 * (h - 2 * radius);
        }
        uint32_t count = 0;
        for (uint32_t v = 0; v < n; v++) {
            double x = v % w, y = v / w;
            for (int k = 0; k < 3; k++)
                if ((x - cx[k]) * (x - cx[k]) + (y - cy[k]) * (y - cy[k]) < radius * radius) {
                    scratch[count++] = v;
                    break;
                }
        }
        for (uint32_t k = 0; k < targets; k++) {
            mk_raw_target *tg = &ch->targets[k];
            tg->full_weight = targets == 2 ? (k == 0 ? 0.5f : 1.0f) : 1.0f;
            tg->name = ch->name;
            tg->count = count;
            tg->indices = mk_arena_array(&raw->arena, count + 1u, sizeof(uint32_t));
            tg->positions = mk_arena_array(&raw->arena, 3 * (size_t)count + 3, sizeof(float));
            tg->normals = mk_arena_array(&raw->arena, 3 * (size_t)count + 3, sizeof(float));
            if (!tg->indices || !tg->positions || !tg->normals) return mk_error_oom(err, "building targets");
            memcpy(tg->indices, scratch, count * sizeof(uint32_t));
            for (uint32_t j = 0; j < count; j++) {
                float s = (float)(k + 1) * 0.01f * (float)((j * 2654435761u) % 1000) / 1000.0f;
                tg->positions[3 * j + 2] = s;
                tg->positions[3 * j] = 0.3f * s;
                tg->normals[3 * j] = 0.2f * s;
                tg->normals[3 * j + 1] = -0.1f * s;
            }
        }
    }
    return MK_OK;
}

double bench_machine_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (double)pages * (double)page : 0;
}

double bench_synthetic_bytes(const bench_synthetic *o)
{
    double n = (double)o->vertices, targets = 1.2 * (double)o->channels;
    double base = n * (24 + 24 + 24 + 24 + 24);
    double deltas = targets * o->density * n * 28.0 * 3;
    double dense = 1.2 * (double)o->active * n * 24.0;
    return base + deltas + dense + (double)(512u << 20);
}

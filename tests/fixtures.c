/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "mat4.h"

static void *dup_array(mk_raw_asset *raw, const void *src, size_t bytes)
{
    void *p = mk_arena_alloc(&raw->arena, bytes);
    if (!p) { fprintf(stderr, "fixture: out of memory\n"); exit(2); }
    memcpy(p, src, bytes);
    return p;
}

static void add_target(mk_raw_asset *raw, mk_raw_channel *ch, float full, uint32_t count, const uint32_t *idx,
                       const float *pos, const float *nrm)
{
    mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
    t->name = mk_arena_strdup(&raw->arena, ch->name);
    t->full_weight = full;
    t->count = count;
    t->indices = dup_array(raw, idx, count * sizeof *idx);
    t->positions = dup_array(raw, pos, 3 * count * sizeof *pos);
    if (nrm) t->normals = dup_array(raw, nrm, 3 * count * sizeof *nrm);
}

static mk_raw_channel *add_channel(mk_raw_asset *raw, uint32_t mesh, const char *name)
{
    mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
    ch->name = mk_arena_strdup(&raw->arena, name);
    ch->mesh = mesh;
    return ch;
}

/* The unit quad (0,0,0) (1,0,0) (0,1,0) (1,1,0): normals +z, tangents +x (w 1; the last
 * vertex's w is last_w), two triangles. */
static void fill_quad(mk_raw_asset *raw, mk_raw_mesh *m, const char *name, float last_w)
{
    static const float p[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 };
    static const float n[] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
    static const uint32_t tri[] = { 0, 1, 3, 0, 3, 2 };
    float t[] = { 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, last_w };
    m->name = mk_arena_strdup(&raw->arena, name);
    m->vertex_count = 4;
    m->positions = dup_array(raw, p, sizeof p);
    m->normals = dup_array(raw, n, sizeof n);
    m->tangents = dup_array(raw, t, sizeof t);
    m->triangle_count = 2;
    m->triangles = dup_array(raw, tri, sizeof tri);
}

void fixture_basic(mk_raw_asset *raw)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 2);
    fill_quad(raw, &m[0], "quad", 1);
    static const float tri_p[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    static const uint32_t tri_i[] = { 0, 1, 2 };
    m = &raw->meshes[1];
    m->name = mk_arena_strdup(&raw->arena, "plain");
    m->vertex_count = 3;
    m->positions = dup_array(raw, tri_p, sizeof tri_p);
    m->triangle_count = 1;
    m->triangles = dup_array(raw, tri_i, sizeof tri_i);

    const uint32_t v0[] = { 0 }, v1[] = { 1 }, v2[] = { 2 };
    mk_raw_channel *ch = add_channel(raw, 0, "progressive");
    add_target(raw, ch, 0.5f, 1, v0, (const float[]){ 0, 0, 1 }, (const float[]){ 1, 0, -1 });
    add_target(raw, ch, 1.0f, 1, v0, (const float[]){ 0, 0, 3 }, (const float[]){ 0, 0, 0 });
    ch = add_channel(raw, 0, "negative");
    add_target(raw, ch, -1.0f, 1, v1, (const float[]){ 0, 1, 0 }, NULL);
    add_target(raw, ch, 1.0f, 1, v1, (const float[]){ 1, 0, 0 }, NULL);
    ch = add_channel(raw, 0, "seq_a");
    add_target(raw, ch, 1.0f, 1, v2, (const float[]){ 1, 0, 0 }, NULL);
    ch = add_channel(raw, 0, "seq_b");
    add_target(raw, ch, 1.0f, 1, v2, (const float[]){ 0, 2, 0 }, NULL);
    ch = add_channel(raw, 1, "lift");
    add_target(raw, ch, 1.0f, 3, tri_i, (const float[]){ 0, 0, 1, 0, 0, 1, 0, 0, 1 }, NULL);

    mk_raw_clip *clip = mk_raw_add_clips(raw, 1);
    clip->name = mk_arena_strdup(&raw->arena, "anim");
    clip->start = 0;
    clip->duration = 1;
    clip->track_count = 2;
    clip->tracks = mk_arena_array(&raw->arena, 2, sizeof(mk_raw_track));
    mk_key k0 = { 0, 0, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_LINEAR, 0 }, k1 = { 1, 1, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_LINEAR, 0 };
    mk_key keys[2] = { k0, k1 };
    clip->tracks[0].channel = 0;
    clip->tracks[0].key_count = 2;
    clip->tracks[0].keys = dup_array(raw, keys, sizeof keys);
    mk_key c0 = { 0, 0.5f, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_CONSTANT, 0 };
    clip->tracks[1].channel = 4;
    clip->tracks[1].key_count = 1;
    clip->tracks[1].keys = dup_array(raw, &c0, sizeof c0);
    /* Targets written above have normals only on channel 0; channels 1-3 compute none
     * here: validation allows a mix (absent normal deltas mean "normals do not change"). */
}

static void add_target_nt(mk_raw_asset *raw, mk_raw_channel *ch, float full, uint32_t count, const uint32_t *idx,
                          const float *pos, const float *nrm, const float *tan)
{
    add_target(raw, ch, full, count, idx, pos, nrm);
    if (tan) ch->targets[ch->target_count - 1].tangents = dup_array(raw, tan, 3 * count * sizeof *tan);
}

static mk_raw_track make_track(mk_raw_asset *raw, uint32_t channel, uint32_t key_count, const mk_key *keys)
{
    mk_raw_track t = { channel, key_count, dup_array(raw, keys, key_count * sizeof *keys) };
    return t;
}

void fixture_rich(mk_raw_asset *raw)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 4);
    static const uint32_t quad_cp[] = { 0, 1, 2, 2 };
    fill_quad(raw, &m[0], "face", -1);
    m[0].control_point_count = 3;
    m[0].control_points = dup_array(raw, quad_cp, sizeof quad_cp);
    mk_mat4_identity(m[0].world);
    m[0].gltf_node = m[0].gltf_mesh = m[0].gltf_primitive = -1;
    m[0].stacking = MK_STACKING_ADDITIVE;

    static const float prop_p[] = { 0, 0, 0, 2, 0, 0, 0, 2, 0 };
    static const uint32_t prop_tri[] = { 0, 1, 2 };
    m[1].name = mk_arena_strdup(&raw->arena, "prop");
    m[1].vertex_count = 3;
    m[1].positions = dup_array(raw, prop_p, sizeof prop_p);
    m[1].triangle_count = 1;
    m[1].triangles = dup_array(raw, prop_tri, sizeof prop_tri);
    mk_mat4_identity(m[1].world);
    m[1].world[12] = 5;
    m[1].gltf_node = 3;
    m[1].gltf_mesh = 1;
    m[1].gltf_primitive = 0;
    m[1].stacking = MK_STACKING_ADDITIVE;

    enum { N = 150 };
    m[2].name = mk_arena_strdup(&raw->arena, "strip");
    m[2].vertex_count = N;
    m[2].positions = mk_arena_array(&raw->arena, 3 * N, sizeof(float));
    m[2].normals = mk_arena_array(&raw->arena, 3 * N, sizeof(float));
    m[2].triangle_count = N - 2;
    m[2].triangles = mk_arena_array(&raw->arena, 3 * (N - 2), sizeof(uint32_t));
    if (!m[2].positions || !m[2].normals || !m[2].triangles) { fprintf(stderr, "fixture: out of memory\n"); exit(2); }
    for (uint32_t v = 0; v < N; v++) {
        m[2].positions[3 * v] = (float)(v / 2);
        m[2].positions[3 * v + 1] = (float)(v % 2);
        m[2].normals[3 * v + 2] = 1;
    }
    for (uint32_t t = 0; t + 2 < N; t++) {
        m[2].triangles[3 * t] = t;
        m[2].triangles[3 * t + 1] = t % 2 ? t + 2 : t + 1;
        m[2].triangles[3 * t + 2] = t % 2 ? t + 1 : t + 2;
    }
    mk_mat4_identity(m[2].world);
    m[2].gltf_node = m[2].gltf_mesh = m[2].gltf_primitive = -1;
    m[2].stacking = MK_STACKING_SEQUENTIAL;

    m[3].name = mk_arena_strdup(&raw->arena, "rigid");
    m[3].vertex_count = 3;
    m[3].positions = dup_array(raw, prop_p, sizeof prop_p);
    m[3].triangle_count = 1;
    m[3].triangles = dup_array(raw, prop_tri, sizeof prop_tri);
    mk_mat4_identity(m[3].world);
    m[3].gltf_node = m[3].gltf_mesh = m[3].gltf_primitive = -1;
    m[3].stacking = MK_STACKING_ADDITIVE;

    mk_raw_channel *ch = add_channel(raw, 0, "brow");
    add_target_nt(raw, ch, -0.5f, 1, (const uint32_t[]){ 0 }, (const float[]){ 0, 0, -1 },
                  (const float[]){ 0.1f, 0, 0 }, (const float[]){ 0, 0.1f, 0 });
    add_target_nt(raw, ch, 0.5f, 2, (const uint32_t[]){ 0, 1 }, (const float[]){ 0, 0, 0.5f, 0, 0, 0.25f },
                  (const float[]){ 0, 0.2f, 0, 0, 0.1f, 0 }, (const float[]){ 0, 0, 0.2f, 0, 0, 0.1f });
    add_target_nt(raw, ch, 1.0f, 3, (const uint32_t[]){ 0, 1, 3 }, (const float[]){ 0, 0, 1, 0, 0, 0.5f, 0, 0, 0.75f },
                  (const float[]){ 0.3f, 0, 0, 0, 0.3f, 0, 0.1f, 0.1f, 0 },
                  (const float[]){ 0, 0.3f, 0, 0, 0, 0.3f, 0, 0.1f, 0.1f });
    ch = add_channel(raw, 0, "jaw");
    add_target(raw, ch, 1.0f, 2, (const uint32_t[]){ 2, 3 }, (const float[]){ 0, -0.5f, 0, 0, -0.5f, 0 }, NULL);

    uint32_t *all = mk_arena_array(&raw->arena, N, sizeof(uint32_t));
    float *dense_p = mk_arena_array(&raw->arena, 3 * N, sizeof(float));
    float *dense_n = mk_arena_array(&raw->arena, 3 * N, sizeof(float));
    if (!all || !dense_p || !dense_n) { fprintf(stderr, "fixture: out of memory\n"); exit(2); }
    for (uint32_t v = 0; v < N; v++) {
        all[v] = v;
        dense_p[3 * v + 2] = 0.01f * (float)(v % 13);
        dense_n[3 * v] = 0.02f * (float)(v % 5);
    }
    ch = add_channel(raw, 2, "dense");
    add_target(raw, ch, 1.0f, N, all, dense_p, dense_n);
    uint32_t sparse[(N + 6) / 7];
    float sparse_p[3 * ((N + 6) / 7)];
    uint32_t n_sparse = 0;
    for (uint32_t v = 3; v < N; v += 7, n_sparse++) {
        sparse[n_sparse] = v;
        sparse_p[3 * n_sparse] = 0.1f;
        sparse_p[3 * n_sparse + 1] = -0.05f * (float)(v % 3);
        sparse_p[3 * n_sparse + 2] = 0.2f;
    }
    ch = add_channel(raw, 2, "sparse");
    add_target(raw, ch, 0.5f, n_sparse, sparse, sparse_p, NULL);
    add_target(raw, ch, 1.0f, n_sparse, sparse, sparse_p, NULL);
    ch->targets[1].positions[0] = 0.3f;
    uint32_t span[11];
    float span_p[33];
    for (uint32_t k = 0; k < 11; k++) {
        span[k] = 60 + k;
        span_p[3 * k] = 0;
        span_p[3 * k + 1] = 0.5f;
        span_p[3 * k + 2] = -0.01f * (float)k;
    }
    ch = add_channel(raw, 2, "span");
    add_target(raw, ch, 1.0f, 11, span, span_p, NULL);
    ch->default_weight = 0.25f;
    ch = add_channel(raw, 3, "lift");
    add_target(raw, ch, 1.0f, 3, prop_tri, (const float[]){ 0, 0, 1, 0, 0, 1, 0, 0, 1 }, NULL);

    mk_raw_clip *clip = mk_raw_add_clips(raw, 3);
    clip[0].name = mk_arena_strdup(&raw->arena, "talk");
    clip[0].start = 0;
    clip[0].duration = 2;
    clip[0].track_count = 3;
    clip[0].tracks = mk_arena_array(&raw->arena, 3, sizeof(mk_raw_track));
    clip[2].tracks = mk_arena_array(&raw->arena, 2, sizeof(mk_raw_track));
    if (!clip[0].tracks || !clip[2].tracks) { fprintf(stderr, "fixture: out of memory\n"); exit(2); }
    const float third = 1.0f / 3;
    const mk_key cubic[3] = { { 0, 0, 0.5f, third, 0, third, MK_INTERP_CUBIC, 0 },
                              { 1, 1, 0, third, -1, third, MK_INTERP_CUBIC, 0 },
                              { 2, -0.5f, 0, third, 0.25f, third, MK_INTERP_CUBIC, 0 } };
    const mk_key weighted[2] = { { 0, 0, 2, 0.25f, 0, 0.75f, MK_INTERP_CUBIC, 0 },
                                 { 1.5f, 1, 0, 0.75f, -1, 0.25f, MK_INTERP_CUBIC, 0 } };
    const mk_key step[2] = { { 0.25f, 0, 0, third, 0, third, MK_INTERP_CONSTANT_NEXT, 0 },
                             { 0.75f, 1, 0, third, 0, third, MK_INTERP_CONSTANT_NEXT, 0 } };
    clip[0].tracks[0] = make_track(raw, 0, 3, cubic);
    clip[0].tracks[1] = make_track(raw, 1, 2, weighted);
    clip[0].tracks[2] = make_track(raw, 3, 2, step);
    clip[1].name = mk_arena_strdup(&raw->arena, "still");
    clip[2].name = mk_arena_strdup(&raw->arena, "blink");
    clip[2].start = 0.5f;
    clip[2].duration = 1;
    clip[2].track_count = 2;
    const mk_key hold[1] = { { 0.5f, 0.75f, 0, third, 0, third, MK_INTERP_CONSTANT, 0 } };
    const mk_key linear[2] = { { 0.5f, 0, 0, third, 0, third, MK_INTERP_LINEAR, 0 },
                               { 1.5f, 1, 0, third, 0, third, MK_INTERP_LINEAR, 0 } };
    clip[2].tracks[0] = make_track(raw, 4, 1, hold);
    clip[2].tracks[1] = make_track(raw, 2, 2, linear);
}

void fixture_line(mk_raw_asset *raw, uint32_t n, uint32_t channels, uint32_t stride)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = mk_arena_strdup(&raw->arena, "line");
    m->vertex_count = n;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)n, sizeof(float));
    for (uint32_t v = 0; v < n; v++) {
        m->positions[3 * v] = (float)v;
        m->normals[3 * v + 1] = 1;
    }
    for (uint32_t c = 0; c < channels; c++) {
        char name[32];
        snprintf(name, sizeof name, "c%u", c);
        mk_raw_channel *ch = add_channel(raw, 0, name);
        mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
        t->name = ch->name;
        uint32_t count = 0;
        for (uint32_t v = c % stride; v < n; v += stride) count++;
        t->count = count;
        t->indices = mk_arena_array(&raw->arena, count + 1, sizeof(uint32_t));
        t->positions = mk_arena_array(&raw->arena, 3 * (size_t)count + 3, sizeof(float));
        t->normals = mk_arena_array(&raw->arena, 3 * (size_t)count + 3, sizeof(float));
        uint32_t j = 0;
        for (uint32_t v = c % stride; v < n; v += stride, j++) {
            t->indices[j] = v;
            t->positions[3 * j + 1] = 0.001f * (float)((v * 7 + c * 13) % 101);
            t->positions[3 * j + 2] = -0.002f * (float)((v * 3 + c) % 17);
            t->normals[3 * j] = 0.01f * (float)((v + c) % 5);
        }
    }
}

void *fixture_blob(const mk_raw_asset *raw, mk_precision precision, mk_arena *arena, size_t *size)
{
    mk_write_options o = { .precision = precision };
    void *blob;
    mk_error err;
    if (mk_write_blob(raw, &o, arena, &blob, size, NULL, &err) != MK_OK) {
        fprintf(stderr, "fixture: write failed: %s\n", err.message);
        exit(2);
    }
    return blob;
}

void fixture_wavy_grid(mk_raw_asset *raw, uint32_t n, uint32_t targets)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = "wavy";
    m->vertex_count = m->control_point_count = n * n;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)n * n, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)n * n, sizeof(float));
    m->control_points = mk_arena_array(&raw->arena, (size_t)n * n, sizeof(uint32_t));
    m->triangles = mk_arena_array(&raw->arena, 6 * (size_t)(n - 1) * (n - 1), sizeof(uint32_t));
    for (uint32_t v = 0; v < n * n; v++) {
        float x = (float)(v % n), y = (float)(v / n);
        m->control_points[v] = v;
        m->positions[3 * v] = x;
        m->positions[3 * v + 1] = y;
        m->positions[3 * v + 2] = 0.3f * sinf(0.7f * x) * cosf(0.4f * y);
        m->normals[3 * v + 2] = 1;
    }
    uint32_t t = 0;
    for (uint32_t y = 0; y + 1 < n; y++)
        for (uint32_t x = 0; x + 1 < n; x++) {
            uint32_t a = y * n + x, b = a + 1, c = a + n, d = c + 1, *tri = &m->triangles[6 * t++];
            tri[0] = a; tri[1] = b; tri[2] = d; tri[3] = a; tri[4] = d; tri[5] = c;
        }
    m->triangle_count = 2 * t;
    for (uint32_t k = 0; k < targets; k++) {
        mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
        ch->name = "lift";
        mk_raw_target *tg = mk_raw_add_targets(raw, ch, 1);
        tg->name = "lift";
        float cx = (float)((k * 7) % n), cy = (float)((k * 13) % n), r = 2.0f + (float)(k % 4);
        tg->indices = mk_arena_array(&raw->arena, (size_t)n * n, sizeof(uint32_t));
        tg->positions = mk_arena_array(&raw->arena, 3 * (size_t)n * n, sizeof(float));
        for (uint32_t v = 0; v < n * n; v++) {
            float dx = (float)(v % n) - cx, dy = (float)(v / n) - cy, q = dx * dx + dy * dy;
            if (q >= r * r) continue;
            tg->indices[tg->count] = v;
            tg->positions[3 * tg->count + 2] = 0.5f * (1 - q / (r * r));
            tg->positions[3 * tg->count] = 0.1f * dx;
            tg->count++;
        }
    }
}

void fixture_brute_normal(const mk_raw_mesh *m, const float *pos, uint32_t v, int split_by_normal, double out[3])
{
    double s[3] = { 0, 0, 0 };
    const uint32_t key = m->control_points ? m->control_points[v] : v;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = &m->triangles[3 * t];
        int touches = 0;
        for (int c = 0; c < 3; c++) {
            int same = (m->control_points ? m->control_points[tri[c]] : tri[c]) == key;
            if (same && split_by_normal)
                for (int d = 0; d < 3; d++) same &= fabsf(m->normals[3 * tri[c] + (uint32_t)d] - m->normals[3 * v + (uint32_t)d]) <= 1e-5f;
            touches |= same;
        }
        if (!touches) continue;
        const float *a = &pos[3 * tri[0]], *b = &pos[3 * tri[1]], *c = &pos[3 * tri[2]];
        double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        s[0] += e1[1] * e2[2] - e1[2] * e2[1];
        s[1] += e1[2] * e2[0] - e1[0] * e2[2];
        s[2] += e1[0] * e2[1] - e1[1] * e2[0];
    }
    double l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int d = 0; d < 3; d++) out[d] = s[d] / l;
}

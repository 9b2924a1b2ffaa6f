/* SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"

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

void fixture_basic(mk_raw_asset *raw)
{
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 2);
    static const float quad_p[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 };
    static const float quad_n[] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
    static const float quad_t[] = { 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1 };
    static const uint32_t quad_tri[] = { 0, 1, 3, 0, 3, 2 };
    m[0].name = mk_arena_strdup(&raw->arena, "quad");
    m[0].vertex_count = 4;
    m[0].positions = dup_array(raw, quad_p, sizeof quad_p);
    m[0].normals = dup_array(raw, quad_n, sizeof quad_n);
    m[0].tangents = dup_array(raw, quad_t, sizeof quad_t);
    m[0].triangle_count = 2;
    m[0].triangles = dup_array(raw, quad_tri, sizeof quad_tri);
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

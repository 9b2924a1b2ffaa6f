/* SPDX-License-Identifier: MIT */
/* Builds the bundled example asset by code (no external files): a tube with a "bulge"
 * channel and a progressive "bend" channel (four in-betweens sampled from an exact bend, so
 * playback follows the curved path), normals computed from the targets, and a clip "wave"
 * animating both. With --ball, a closed icosphere "ball" (642 vertices, no channels) instead:
 * the mesh the shell sample recipe deflates. With --heads DIR (created when missing), the
 * deformation transfer sample between two characters: DIR/head_template.morph (a head made by
 * code, offline/head.h, as a UV sphere of 48 rings with six expression channels),
 * DIR/head_character.morph (the same surface
 * with other proportions, as an icosphere of 2,562 vertices, no channels) and
 * DIR/transfer_heads.json, the recipe with 12 marker pairs at the same features of both heads.
 * usage: make_example [--ball] OUT.morph | make_example --heads DIR */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "blob_io.h"
#include "head.h"
#include "primitives.h"

#define SEGMENTS 32
#define RINGS 24
#define PI 3.14159265358979f

static mk_raw_target *fill_target(mk_raw_asset *raw, mk_raw_channel *ch, const mk_raw_mesh *m, float full,
                                  const float *deformed)
{
    mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
    t->name = ch->name;
    t->full_weight = full;
    t->count = m->vertex_count;
    t->indices = mk_arena_array(&raw->arena, m->vertex_count, sizeof(uint32_t));
    t->positions = mk_arena_array(&raw->arena, 3 * (size_t)m->vertex_count, sizeof(float));
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        t->indices[v] = v;
        for (int d = 0; d < 3; d++) t->positions[3 * v + (uint32_t)d] = deformed[3 * v + (uint32_t)d] - m->positions[3 * v + (uint32_t)d];
    }
    return t;
}

/* The ball: a closed icosphere of radius 1. */
static int write_ball(const char *path)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    void *blob = NULL;
    size_t size = 0;
    int status = 0;
    if (!mk_raw_add_icosphere(&raw, "ball", 1, 3)) { fprintf(stderr, "make_example: out of memory\n"); status = 1; }
    else if (mk_write_blob(&raw, NULL, &raw.arena, &blob, &size, NULL, &err) || mk_write_file(path, blob, size, &err)) {
        fprintf(stderr, "make_example: %s\n", err.message);
        status = 1;
    } else {
        printf("wrote %s: ball of %u vertices (closed, no channels); %zu bytes\n", path, raw.meshes[0].vertex_count, size);
    }
    mk_raw_free(&raw);
    return status;
}

static int write_asset(mk_raw_asset *raw, const char *path, mk_error *err)
{
    void *blob;
    size_t size;
    mk_write_report report;
    return mk_write_blob(raw, NULL, &raw->arena, &blob, &size, &report, err) == MK_OK &&
           mk_write_file(path, blob, size, err) == MK_OK;
}

/* The two heads and the recipe that carries the template's expressions onto the character. */
static int write_heads(const char *dir)
{
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {  /* the folder, when it is not there yet */
        fprintf(stderr, "make_example: cannot create the folder %s: %s\n", dir, strerror(errno));
        return 1;
    }
    mk_raw_asset tpl, chr;
    mk_raw_init(&tpl, NULL);
    mk_raw_init(&chr, NULL);
    double *tdir = NULL, *cdir = NULL;
    mk_raw_mesh *tm = mk_raw_add_head(&tpl, "template", 48, 1, 0, 0, 1, &tdir);
    mk_raw_mesh *cm = mk_raw_add_head(&chr, "character", 4, 0, 0.3, 1, 0, &cdir);
    int ok = tm && cm;
    char path[4096], json[2048];
    int n = snprintf(json, sizeof json, "{\n  \"mesh\": \"character\",\n  \"channels\": [\n    { \"op\": \"transfer\", "
                     "\"source\": \"head_template.morph\", \"prefix\": \"character_\",\n      \"markers\": [");
    /* a marker pair is one feature on both heads (mk_head_marker_pairs) */
    uint32_t pairs[12][2];
    if (ok) mk_head_marker_pairs(tm, tdir, cm, cdir, 1, 12, pairs);
    for (int m = 0; ok && m < 12; m++) n += snprintf(json + n, sizeof json - (size_t)n, "%s[%u, %u]", m ? ", " : "", pairs[m][0], pairs[m][1]);
    snprintf(json + n, sizeof json - (size_t)n, "] }\n  ]\n}\n");
    mk_error err;
    snprintf(path, sizeof path, "%s/head_template.morph", dir);
    ok = ok && write_asset(&tpl, path, &err);
    snprintf(path, sizeof path, "%s/head_character.morph", dir);
    ok = ok && write_asset(&chr, path, &err);
    snprintf(path, sizeof path, "%s/transfer_heads.json", dir);
    ok = ok && mk_write_file(path, json, strlen(json), &err) == MK_OK;
    if (ok)
        printf("wrote %s: head_template.morph (%u vertices, %u expression channels), head_character.morph (%u "
               "vertices), transfer_heads.json\n", dir, tm->vertex_count, (unsigned)MK_HEAD_EXPRESSIONS, cm->vertex_count);
    else if (tm && cm) fprintf(stderr, "make_example: %s\n", err.message);
    else fprintf(stderr, "make_example: out of memory\n");
    free(tdir);
    free(cdir);
    mk_raw_free(&tpl);
    mk_raw_free(&chr);
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "--ball")) return write_ball(argv[2]);
    if (argc == 3 && !strcmp(argv[1], "--heads")) return write_heads(argv[2]);
    if (argc != 2 || argv[1][0] == '-') {
        fprintf(stderr, "usage: make_example [--ball] OUT.morph | make_example --heads DIR\n");
        return 2;
    }
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_raw_mesh *m = mk_raw_add_tube(&raw, "tube", SEGMENTS, RINGS);
    if (!m) { fprintf(stderr, "make_example: out of memory\n"); return 1; }
    const uint32_t n = m->vertex_count;

    float deformed[3 * SEGMENTS * (RINGS + 1)];
    mk_raw_channel *ch = mk_raw_add_channels(&raw, 2);
    ch[0].name = "bulge";
    for (uint32_t v = 0; v < n; v++) {
        float y = m->positions[3 * v + 1], k = 1 + 0.4f * sinf(PI * y / 2);
        deformed[3 * v] = m->positions[3 * v] * k;
        deformed[3 * v + 1] = y;
        deformed[3 * v + 2] = m->positions[3 * v + 2] * k;
    }
    fill_target(&raw, &ch[0], m, 1.0f, deformed);
    /* Bend by amplitude * 90 degrees about the z axis through (R, 0, 0), R = 2 / (pi/2). */
    ch = &raw.channels[1];
    ch->name = "bend";
    for (int k = 1; k <= 4; k++) {
        float amplitude = 0.25f * (float)k, angle = amplitude * PI / 2, R = 2.0f / angle;
        for (uint32_t v = 0; v < n; v++) {
            float x = m->positions[3 * v], y = m->positions[3 * v + 1], theta = angle * y / 2;
            deformed[3 * v] = R - (R - x) * cosf(theta);
            deformed[3 * v + 1] = (R - x) * sinf(theta);
            deformed[3 * v + 2] = m->positions[3 * v + 2];
        }
        fill_target(&raw, ch, m, amplitude, deformed);
        ch = &raw.channels[1];
    }
    mk_error err;
    if (mk_raw_compute_target_normals(&raw, 0, 0, 0, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }

    mk_raw_clip *clip = mk_raw_add_clips(&raw, 1);
    clip->name = "wave";
    clip->duration = 2;
    clip->track_count = 2;
    clip->tracks = mk_arena_array(&raw.arena, 2, sizeof(mk_raw_track));
    static mk_key bulge[3] = { { 0, 0, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_CUBIC, 0 },
                               { 1, 1, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_CUBIC, 0 },
                               { 2, 0, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_CUBIC, 0 } };
    static mk_key bend[2] = { { 0, 0, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_LINEAR, 0 },
                              { 2, 1, 0, 1.0f / 3, 0, 1.0f / 3, MK_INTERP_LINEAR, 0 } };
    clip->tracks[0] = (mk_raw_track){ 0, 3, bulge };
    clip->tracks[1] = (mk_raw_track){ 1, 2, bend };

    void *blob;
    size_t size;
    mk_write_report report;
    if (mk_write_blob(&raw, NULL, &raw.arena, &blob, &size, &report, &err) || mk_write_file(argv[1], blob, size, &err)) {
        fprintf(stderr, "make_example: %s\n", err.message);
        return 1;
    }
    printf("wrote %s: tube of %u vertices, channels 'bulge' and 'bend' (4 in-betweens), clip 'wave' (2 s); "
           "%zu bytes, max quantization error %.2g\n", argv[1], n, size, report.max_position_error);
    mk_raw_free(&raw);
    return 0;
}

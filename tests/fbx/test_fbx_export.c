/* SPDX-License-Identifier: MIT */
/* FBX export (mk_fbx_export): every corpus case (FBX of every version and glTF), imported,
 * exported as FBX and imported again, has the same meshes (names, control points, world
 * transforms), the same channels (names, defaults, full weights) and plays the same: the rest
 * pose, each channel alone at four weights, and each clip at nine times, per control point. A
 * transform with shear is refused. SKIPs when the corpus is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "corpus_cases.h"
#include "fbx_test_util.h"
#include "fbx_write.h"
#include "import.h"

/* Largest difference between the control points of mesh m played both ways (-1: failed). */
static double played_apart(const mk_raw_asset *a, const mk_raw_asset *b, uint32_t m, int32_t clip, float time,
                           const float *wa, const float *wb)
{
    float *pa = NULL, *pb = NULL;
    uint32_t na = 0, nb = 0;
    double worst = -1;
    if (ft_eval_control_points(a, m, clip, time, wa, 0, &pa, &na) == 0 &&
        ft_eval_control_points(b, m, clip, time, wb, 0, &pb, &nb) == 0 && na == nb) {
        worst = 0;
        for (uint32_t k = 0; k < 3 * na; k++) worst = fmax(worst, fabs((double)pa[k] - pb[k]));
    }
    free(pa);
    free(pb);
    return worst;
}

/* The mesh's size for tolerances: its diagonal, at least 1. */
static double diagonal(const mk_raw_mesh *m) { return fmax((double)mk_raw_mesh_diagonal(m), 1); }

/* The triangles of m on control points, each rotated to start at its smallest, sorted. */
static int by_triple(const void *a, const void *b) { return memcmp(a, b, 3 * sizeof(uint32_t)); }
static uint32_t *cp_triangles(const mk_raw_mesh *m)
{
    uint32_t *t = malloc(3 * sizeof *t * ((size_t)m->triangle_count + 1));
    for (uint32_t i = 0; i < m->triangle_count; i++) {
        uint32_t c[3];
        for (int k = 0; k < 3; k++) c[k] = m->control_points[m->triangles[3 * i + k]];
        int first = c[0] <= c[1] && c[0] <= c[2] ? 0 : c[1] <= c[2] ? 1 : 2;
        for (int k = 0; k < 3; k++) t[3 * i + k] = c[(first + k) % 3];
    }
    qsort(t, m->triangle_count, 3 * sizeof *t, by_triple);
    return t;
}

static void compare(const char *name, const mk_raw_asset *a, const mk_raw_asset *b, double *worst_seen)
{
    CHECK_MSG(a->mesh_count == b->mesh_count, "%s: %u meshes, exported %u", name, a->mesh_count, b->mesh_count);
    CHECK_MSG(a->channel_count == b->channel_count, "%s: %u channels, exported %u", name, a->channel_count, b->channel_count);
    CHECK_MSG(a->clip_count == b->clip_count, "%s: %u clips, exported %u", name, a->clip_count, b->clip_count);
    if (a->mesh_count != b->mesh_count || a->channel_count != b->channel_count) return;
    for (uint32_t c = 0; c < a->channel_count; c++) {
        const mk_raw_channel *x = &a->channels[c], *y = &b->channels[c];
        CHECK_MSG(!strcmp(x->name, y->name) && x->mesh == y->mesh && x->target_count == y->target_count,
                  "%s: channel %u '%s' (mesh %u, %u targets) exported as '%s' (mesh %u, %u targets)", name, c, x->name,
                  x->mesh, x->target_count, y->name, y->mesh, y->target_count);
        CHECK_NEAR(x->default_weight, y->default_weight, 1e-6);
        for (uint32_t t = 0; t < x->target_count && t < y->target_count; t++)
            CHECK_NEAR(x->targets[t].full_weight, y->targets[t].full_weight, 1e-6);
    }
    float *wa = calloc(a->channel_count + 1, sizeof *wa), *wb = calloc(b->channel_count + 1, sizeof *wb);
    for (uint32_t m = 0; m < a->mesh_count; m++) {
        const mk_raw_mesh *x = &a->meshes[m], *y = &b->meshes[m];
        CHECK_MSG(!strcmp(x->name, y->name), "%s: mesh %u '%s' exported as '%s'", name, m, x->name, y->name);
        CHECK_EQ_INT(y->control_point_count, x->control_point_count);
        CHECK_MSG(y->triangle_count == x->triangle_count, "%s mesh '%s': %u triangles, exported %u", name, x->name,
                  x->triangle_count, y->triangle_count);
        if (y->triangle_count == x->triangle_count) {
            uint32_t *tx = cp_triangles(x), *ty = cp_triangles(y);
            CHECK_MSG(memcmp(tx, ty, 3 * sizeof *tx * x->triangle_count) == 0, "%s mesh '%s': other triangles", name, x->name);
            free(tx);
            free(ty);
        }
        double size = 1;
        for (int k = 0; k < 16; k++) size = fmax(size, fabs(x->world[k]));
        for (int k = 0; k < 16; k++)
            CHECK_MSG(fabs(y->world[k] - x->world[k]) <= 1e-5 * size, "%s mesh '%s': world[%d] %.9g, exported %.9g",
                      name, x->name, k, x->world[k], y->world[k]);
        const double tol = 1e-6 * diagonal(x);
        /* the rest pose and every channel alone at four weights */
        for (uint32_t c = 0; c <= a->channel_count; c++) {
            if (c < a->channel_count && a->channels[c].mesh != m) continue;
            for (int k = 0; k < (c < a->channel_count ? 4 : 1); k++) {
                memset(wa, 0, (a->channel_count + 1) * sizeof *wa);
                memset(wb, 0, (b->channel_count + 1) * sizeof *wb);
                if (c < a->channel_count) wa[c] = wb[c] = -0.5f + 0.5f * (float)k;
                double d = played_apart(a, b, m, -1, 0, wa, wb);
                CHECK_MSG(d >= 0 && d <= tol, "%s mesh '%s' channel %d at weight %g: played %g apart", name, x->name,
                          c < a->channel_count ? (int)c : -1, (double)wa[c], d);
                if (d / diagonal(x) > worst_seen[0]) worst_seen[0] = d / diagonal(x);
            }
        }
        /* every clip at nine times over its span */
        for (uint32_t k = 0; k < a->clip_count && k < b->clip_count; k++) {
            CHECK_NEAR(b->clips[k].duration, a->clips[k].duration, 1e-5);
            for (int i = 0; i <= 8; i++) {
                float time = a->clips[k].start + a->clips[k].duration * (float)i / 8.0f;
                double d = played_apart(a, b, m, (int32_t)k, time, NULL, NULL);
                CHECK_MSG(d >= 0 && d <= 1e-4 * diagonal(x), "%s mesh '%s' clip %u at %g s: played %g apart", name,
                          x->name, k, (double)time, d);
                if (d / diagonal(x) > worst_seen[1]) worst_seen[1] = d / diagonal(x);
            }
        }
    }
    free(wa);
    free(wb);
}

static void test_corpus_round_trip(void)
{
    pb_manifest manifest;
    CHECK_CORPUS_MANIFEST(&manifest);
    char path[4200];
    int cases = 0;
    double worst[2] = { 0, 0 };
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        const pb_case *c = &manifest.cases[i];
        pb_manifest_path(&manifest, c->source, path, sizeof path);
        mk_raw_asset a, b;
        mk_error err;
        mk_raw_init(&a, NULL);
        mk_raw_init(&b, NULL);
        mk_result r = mk_import_file(path, NULL, &a, &err);
        CHECK_MSG(r == MK_OK, "%s: import: %s", c->name, err.message);
        void *fbx = NULL;
        size_t size = 0;
        mk_fbx_write_report rep;
        if (r == MK_OK) r = mk_fbx_export(&a, &a.arena, &fbx, &size, &rep, &err);
        CHECK_MSG(r == MK_OK, "%s: export: %s", c->name, err.message);
        if (r == MK_OK) {
            r = mk_import_memory(fbx, size, NULL, &b, &err);
            CHECK_MSG(r == MK_OK, "%s: re-import: %s", c->name, err.message);
            CHECK_EQ_INT(rep.meshes, a.mesh_count);
            CHECK_EQ_INT(rep.channels, a.channel_count);
            if (r == MK_OK) compare(c->name, &a, &b, worst);
            cases++;
        }
        mk_raw_free(&a);
        mk_raw_free(&b);
    }
    fprintf(stderr, "fbx export: %d corpus cases, worst playback difference (x diagonal): channels %.3g, clips %.3g\n",
            cases, worst[0], worst[1]);
    CHECK(cases > 0);
    pb_manifest_free(&manifest);
}

/* world = T R S, R = Rz(c) Ry(b) Rx(a), column-major. */
static void set_world(float w[16], double a, double b, double c, const double s[3], const double t[3])
{
    const double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
    const double R[3][3] = { { cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa },
                             { sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa },
                             { -sb, cb * sa, cb * ca } };
    memset(w, 0, 16 * sizeof *w);
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++) w[4 * j + i] = (float)(R[i][j] * s[j]);
        w[12 + j] = (float)t[j];
    }
    w[15] = 1;
}

/* Transforms FBX can hold come back (rotations about every axis, non-uniform and mirroring
 * scale, near the gimbal pole); shear is refused. */
static void test_transforms(void)
{
    size_t size;
    unsigned char *data = ft_read_corpus("maya_blend_shape_cube_7700_binary", &size);
    if (!data) SKIP("corpus not found at %s", check_corpus_dir());
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    void *out = NULL;
    size_t out_size = 0;
    CHECK(mk_fbx_export(&raw, &raw.arena, &out, &out_size, NULL, &err) == MK_OK);
    static const double angles[][3] = { { 1.2, -0.7, 0.5 }, { -2.5, 0.3, 2.9 }, { 0.4, 1.5707, -1.1 }, { 0, -1.5707963, 0.8 } };
    static const double scales[][3] = { { 2, 0.5, 1.5 }, { -1, 1, 1 }, { 1, 1, 1 }, { 3, -2, 0.25 } };
    const double t[3] = { 1.5, -2, 0.25 };
    for (int i = 0; i < 4; i++) {
        set_world(raw.meshes[0].world, angles[i][0], angles[i][1], angles[i][2], scales[i], t);
        mk_raw_asset back;
        out = NULL;
        mk_result r = mk_fbx_export(&raw, &raw.arena, &out, &out_size, NULL, &err);
        CHECK_MSG(r == MK_OK, "transform %d: %s", i, err.message);
        CHECK(out && ft_import(out, out_size, NULL, &back, &err) == MK_OK);
        if (!out) continue;
        for (int k = 0; k < 16; k++)
            CHECK_MSG(fabs(back.meshes[0].world[k] - raw.meshes[0].world[k]) <= 1e-5 * 3, "transform %d: world[%d] %.7g, exported %.7g",
                      i, k, raw.meshes[0].world[k], back.meshes[0].world[k]);
        mk_raw_free(&back);
    }
    raw.meshes[0].world[4] += 0.5f;  /* column 1 leans into x: shear */
    out = NULL;
    CHECK(mk_fbx_export(&raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
    CHECK_MSG(strstr(err.message, "shear") && strstr(err.message, "pCube1"), "%s", err.message);
    CHECK(out == NULL);
    mk_raw_free(&raw);
    free(data);
}

CHECK_MAIN(CASE(test_corpus_round_trip), CASE(test_transforms))

/* SPDX-License-Identifier: MIT */
/* glTF import against the corpus: every "gltf" case of cases.json matches its three.js
 * reference frames (positions within the case tolerance, normal directions), and every
 * derived variant (sparse, Draco, quantized, meshopt, gltfpack) evaluates to the same world
 * positions as its source model, matched by rest position where a tool reordered vertices.
 * Evaluation goes through the public runtime (float blob, mk_sample_run, mk_eval_run). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "corpus_cases.h"
#include "gltf_test_util.h"

static void test_corpus_references(void)
{
    pb_manifest manifest;
    CHECK_CORPUS_MANIFEST(&manifest);
    int n = 0, frames = 0;
    double wp = 0, wn = 0;
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        if (!manifest.cases[i].gltf) continue;
        gt_check_case(&manifest, &manifest.cases[i], NULL, &wp, &wn, &frames);
        n++;
    }
    CHECK(n >= 8);
    printf("  %d glTF cases, %d frames: max position error %.3g, max normal angle %.3g deg\n", n, frames, wp, wn);
    pb_manifest_free(&manifest);
}

/* ---- variants ---- */

typedef struct frame_spec { int clip; float time; } frame_spec;

/* World positions of every vertex of every mesh, for each frame: [frame][vertex*3]. */
static float *world_frames(const gt_model *m, const frame_spec *fs, int nf, uint32_t *total)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < m->asset.mesh_count; i++) { mk_mesh_info info; mk_mesh_get(&m->asset, i, &info); n += info.vertex_count; }
    *total = n;
    float *out = calloc((size_t)(nf + 1) * 3 * n + 1, sizeof *out);
    float *w = calloc(m->asset.channel_count + 1, sizeof *w);
    for (int f = 0; f <= nf; f++) {
        uint32_t at = 0;
        if (f < nf) gt_weights(m, fs[f].clip, fs[f].time, NULL, 0, w);
        for (uint32_t i = 0; i < m->asset.mesh_count; i++) {
            mk_mesh_info info;
            mk_mesh_get(&m->asset, i, &info);
            float *local = calloc(3 * (size_t)info.vertex_count + 1, sizeof *local);
            if (f < nf) gt_eval(m, i, w, local, NULL);
            else memcpy(local, info.positions, 12 * (size_t)info.vertex_count);   /* frame nf = rest (base) */
            gt_to_world(m, i, local, info.vertex_count, out + (size_t)f * 3 * n + 3 * (size_t)at);
            free(local);
            at += info.vertex_count;
        }
    }
    free(w);
    return out;
}

static double dist3(const float *a, const float *b)
{
    return sqrt((double)(a[0] - b[0]) * (a[0] - b[0]) + (double)(a[1] - b[1]) * (a[1] - b[1]) + (double)(a[2] - b[2]) * (a[2] - b[2]));
}

/* Largest error of the variant against the source over the frames, relative to the source's
 * bounding-box diagonal. */
static double compare_variant(const gt_model *src, const gt_model *var, const frame_spec *fs, int nf)
{
    uint32_t ns, nv;
    float *a = world_frames(src, fs, nf, &ns), *b = world_frames(var, fs, nf, &nv);
    const float *ra = a + (size_t)nf * 3 * ns, *rb = b + (size_t)nf * 3 * nv;
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t i = 0; i < ns; i++)
        for (int q = 0; q < 3; q++) { if (ra[3 * i + q] < lo[q]) lo[q] = ra[3 * i + q]; if (ra[3 * i + q] > hi[q]) hi[q] = ra[3 * i + q]; }
    double diag = dist3(lo, hi), worst = 0;
    for (uint32_t v = 0; v < nv; v++) {
        double best = 1e30;
        for (uint32_t s = 0; s < ns; s++) { double d = dist3(rb + 3 * v, ra + 3 * s); if (d < best) best = d; }
        /* Coincident source vertices (seams) are all candidates; take the one that fits best. */
        double err_v = 1e30;
        for (uint32_t s = 0; s < ns; s++) {
            if (dist3(rb + 3 * v, ra + 3 * s) > best + 1e-4 * diag) continue;
            double e = 0;
            for (int f = 0; f <= nf; f++) {
                double d = dist3(b + (size_t)f * 3 * nv + 3 * v, a + (size_t)f * 3 * ns + 3 * s);
                if (d > e) e = d;
            }
            if (e < err_v) err_v = e;
        }
        if (err_v > worst) worst = err_v;
    }
    free(a);
    free(b);
    return diag > 0 ? worst / diag : worst;
}

static void test_variants(void)
{
    static const struct { const char *model, *source; } models[] = {
        {"AnimatedMorphCube", "glTF/AnimatedMorphCube.gltf"},
        {"MorphPrimitivesTest", "glTF/MorphPrimitivesTest.gltf"},
        {"MorphStressTest", "glTF/MorphStressTest.gltf"},
        {"SimpleMorph", "glTF/SimpleMorph.gltf"},
    };
    /* Allowed error relative to the bounding-box diagonal: exact formats vs quantizing ones
     * (16-bit normalized or gltfpack's 14-bit positions and 8-bit normalized weights). */
    static const struct { const char *suffix; double tol; } variants[] = {
        {"sparse.glb", 1e-6}, {"draco.glb", 1e-3}, {"quantized.glb", 1e-3}, {"meshopt.glb", 1e-3},
        {"gltfpack-c.glb", 5e-3}, {"step.gltf", -1}, {"cubic.gltf", -1},
    };
    const char *corpus = check_corpus_dir();
    char path[1024], msg[512];
    int compared = 0;
    for (size_t mi = 0; mi < sizeof models / sizeof *models; mi++) {
        snprintf(path, sizeof path, "%s/gltf/%s/%s", corpus, models[mi].model, models[mi].source);
        gt_model src;
        if (gt_load(&src, path, NULL, msg, sizeof msg)) {
            gt_free(&src);
            if (mi == 0 && !fopen(path, "rb")) SKIP("corpus not found at %s", corpus);
            CHECK_MSG(0, "%s: %s", models[mi].model, msg);
            continue;
        }
        /* Frames: 8 times over each clip (they include 0 and the last key), or rest weights. */
        frame_spec fs[64];
        int nf = 0;
        for (uint32_t c = 0; c < src.asset.clip_count && nf < 56; c++) {
            mk_clip_info ci;
            mk_clip_get(&src.asset, c, &ci);
            for (int k = 0; k < 8; k++) fs[nf++] = (frame_spec){(int)c, ci.start + ci.duration * (float)k / 7.0f};
        }
        if (nf == 0) fs[nf++] = (frame_spec){-1, 0};
        for (size_t vi = 0; vi < sizeof variants / sizeof *variants; vi++) {
            if (variants[vi].tol < 0) continue;   /* step/cubic: covered by their own reference cases */
            snprintf(path, sizeof path, "%s/gltf/%s/variants/%s.%s", corpus, models[mi].model, models[mi].model, variants[vi].suffix);
            FILE *probe = fopen(path, "rb");
            if (!probe) continue;
            fclose(probe);
            gt_model var;
            if (gt_load(&var, path, NULL, msg, sizeof msg)) {
                CHECK_MSG(0, "%s.%s: %s", models[mi].model, variants[vi].suffix, msg);
                gt_free(&var);
                continue;
            }
            CHECK_EQ_INT(var.asset.clip_count, src.asset.clip_count);
            double e = compare_variant(&src, &var, fs, nf);
            printf("  %s.%s: max world error %.3g x diagonal (allowed %g)\n", models[mi].model, variants[vi].suffix, e, variants[vi].tol);
            CHECK_MSG(e <= variants[vi].tol, "%s.%s: error %g x diagonal > %g", models[mi].model, variants[vi].suffix, e, variants[vi].tol);
            compared++;
            gt_free(&var);
        }
        gt_free(&src);
    }
    CHECK(compared >= 15);
}

CHECK_MAIN(CASE(test_corpus_references), CASE(test_variants))

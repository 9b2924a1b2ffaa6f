/* SPDX-License-Identifier: MIT */
/* The corpus frames under the modes its references do not cover. The corpus references
 * (ufbx, three.js, the authoring tools) are additive stacking with nlerp normals only; here
 * every case of cases.json is imported (mk_import_file), written as a float32 and a quantized
 * blob, and for every frame's weights (the clip sampled at the frame time, or the static
 * state: default weights, forced weights where the frame gives them) every mesh with channels
 * is evaluated with sequential stacking and with slerp normals (and additive/nlerp) through
 * the runtime and through the reference evaluator (reference_eval.c), compared with the
 * reference's derived tolerances. SKIPs when the corpus is absent. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "corpus_cases.h"
#include "blob_io.h"
#include "conform.h"
#include "import.h"
#include "reference_eval.h"

typedef struct corpus_totals {
    int frames, jobs;
    ref_stats stats[2];
} corpus_totals;

/* The frame's asset-wide weights as the conformance check plays it (pb_conform_weights: the
 * static state for "time": null or forced weights, else the clip at the time), with forced
 * weights replacing each mesh's channels in order. */
static int frame_weights(const pb_case *c, const pb_frame_spec *f, const mk_asset *a, float *weights)
{
    mk_error err;
    if (pb_conform_weights(c, f, a, weights, &err) != MK_OK) return 0;
    for (uint32_t mi = 0; f->forced && mi < a->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(a, mi, &m);
        for (uint32_t k = 0; k < f->forced_count && k < m.channel_count; k++) weights[m.first_channel + k] = (float)f->forced[k];
    }
    return 1;
}

static void check_mesh(const char *name, const char *frame_file, const mk_raw_asset *raw, const mk_asset *asset,
                       uint32_t mi, const float *weights, int q, ref_stored_error stored, corpus_totals *tot)
{
    mk_mesh_info m;
    mk_mesh_get(asset, mi, &m);
    const uint32_t n = m.vertex_count;
    size_t scratch_size = mk_eval_scratch_size(asset, mi);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    float *p = malloc(12u * n), *nr = malloc(12u * n), *tg = malloc(16u * n);
    ref_vertex *expected = malloc(sizeof(ref_vertex) * n);
    for (int stacking = MK_STACKING_ADDITIVE; stacking <= MK_STACKING_SEQUENTIAL; stacking++)
        for (int mode = MK_NORMALS_NLERP; mode <= MK_NORMALS_SLERP; mode++) {
            const float *w = weights + m.first_channel;
            mk_eval_job job = { .asset = asset, .mesh = mi, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = m.channel_count,
                                .stacking = (mk_stacking)stacking, .normal_mode = (mk_normal_mode)mode,
                                .scratch = scratch, .scratch_size = scratch_size, .positions = p,
                                .positions_size = 12u * (size_t)n, .normals = m.has_normals ? nr : NULL,
                                .normals_size = 12u * (size_t)n, .tangents = m.has_tangents ? tg : NULL,
                                .tangents_size = 16u * (size_t)n };
            mk_error err;
            mk_result r = mk_eval_run(&job, &err);
            CHECK_MSG(r == MK_OK, "%s %s mesh %u: eval: %s", name, frame_file, mi, err.message);
            if (r != MK_OK) continue;
            tot->jobs++;
            ref_job rj;
            ref_job_init(&rj, raw, mi, w, (mk_stacking)stacking, (mk_normal_mode)mode, stored);
            ref_eval_mesh(&rj, expected);
            ref_mismatch mm;
            uint32_t bad = ref_compare(&rj, expected, 0, n, p, job.normals, job.tangents, &mm, &tot->stats[q]);
            CHECK_MSG(bad == 0,
                      "%s %s mesh %u '%s' (%s blob, %s, %s): %u mismatches; first: vertex %u %s[%d] = %.9g, expected "
                      "%.9g (tolerance %.3g)",
                      name, frame_file, mi, m.name, q ? "q16" : "float",
                      stacking == MK_STACKING_SEQUENTIAL ? "sequential" : "additive", mode ? "slerp" : "nlerp", bad,
                      mm.vertex, mm.what, mm.component, mm.got, mm.expected, mm.tolerance);
        }
    free(expected);
    free(tg);
    free(nr);
    free(p);
    free(scratch);
}

static void run_case(const pb_manifest *manifest, const pb_case *c, corpus_totals *tot)
{
    const char *name = c->name;
    char path[4200];
    pb_manifest_path(manifest, c->source, path, sizeof path);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_result r = mk_import_file(path, NULL, &raw, &err);
    CHECK_MSG(r == MK_OK, "%s: import %s: %s", name, path, err.message);
    if (r != MK_OK) { mk_raw_free(&raw); return; }

    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset assets[2];
    ref_stored_error stored[2] = { { 0, 0, 0 }, { 0, 0, 0 } };
    for (int q = 0; q < 2; q++) {
        mk_write_options o = { .precision = q ? MK_PRECISION_Q16 : MK_PRECISION_FLOAT };
        void *blob;
        size_t size;
        mk_write_report report;
        r = mk_write_blob(&raw, &o, &arena, &blob, &size, &report, &err);
        if (r == MK_OK) r = mk_asset_open(blob, size, &assets[q], &err);
        CHECK_MSG(r == MK_OK, "%s: %s blob: %s", name, q ? "q16" : "float", err.message);
        if (r != MK_OK) { mk_arena_free_all(&arena); mk_raw_free(&raw); return; }
        if (q) stored[q] = (ref_stored_error){ report.max_position_error, report.max_normal_error, report.max_tangent_error };
    }
    float *weights = calloc(assets[0].channel_count + 1u, sizeof(float));
    for (uint32_t k = 0; k < c->frame_count; k++) {
        const char *short_name = pb_frame_label(&c->frames[k]);
        int ok = frame_weights(c, &c->frames[k], &assets[0], weights);
        CHECK_MSG(ok, "%s %s: no weights for the frame (clip missing or sampling failed)", name, short_name);
        if (!ok) continue;
        tot->frames++;
        for (uint32_t mi = 0; mi < assets[0].mesh_count; mi++) {
            mk_mesh_info m;
            mk_mesh_get(&assets[0], mi, &m);
            if (!m.channel_count) continue;
            for (int q = 0; q < 2; q++) check_mesh(name, short_name, &raw, &assets[q], mi, weights, q, stored[q], tot);
        }
    }
    free(weights);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

static void test_corpus_other_modes(void)
{
    pb_manifest manifest;
    CHECK_CORPUS_MANIFEST(&manifest);
    corpus_totals tot;
    memset(&tot, 0, sizeof tot);
    for (uint32_t i = 0; i < manifest.case_count; i++) run_case(&manifest, &manifest.cases[i], &tot);
    pb_manifest_free(&manifest);
    CHECK(tot.frames > 0);
    printf("corpus: %d frames, %d jobs (additive/sequential x nlerp/slerp x float/q16), %llu + %llu vertices "
           "compared, %llu + %llu unstable normals skipped\n",
           tot.frames, tot.jobs, (unsigned long long)tot.stats[0].vertices, (unsigned long long)tot.stats[1].vertices,
           (unsigned long long)tot.stats[0].normals_skipped, (unsigned long long)tot.stats[1].normals_skipped);
    for (int q = 0; q < 2; q++)
        printf("  %s blobs: worst error / tolerance: positions %.3g, normal angles %.3g, tangent angles %.3g\n",
               q ? "q16" : "float", tot.stats[q].worst_ratio[0], tot.stats[q].worst_ratio[1], tot.stats[q].worst_ratio[2]);
}

CHECK_MAIN(CASE(test_corpus_other_modes))

/* SPDX-License-Identifier: MIT */
/* glTF export: export → re-import → the original's reference frames still match (every glTF
 * case of the corpus, .glb and .gltf, with and without the channel sidecar); progressive
 * channels and mixed curves survive a round trip through the sidecar; exported files pass the
 * Khronos validator (tests/gltf/validate.js; SKIP when node or the npm package is missing). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "check.h"
#include "corpus_cases.h"
#include "gltf_test_util.h"

/* Output files carry the process id so parallel builds (plain, ASan) do not collide. */
static const char *out_prefix(void)
{
    static char prefix[64];
    if (!prefix[0]) snprintf(prefix, sizeof prefix, "/tmp/morphkit_export_%ld", (long)getpid());
    return prefix;
}

/* 0 valid, 1 errors, 77 validator unavailable. */
static int validate(const char *path)
{
    static int have_node = -1;
    if (have_node < 0) have_node = system("node --version > /dev/null 2>&1") == 0;
    if (!have_node) return 77;
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "node '%s/tests/gltf/validate.js' '%s'", MK_SOURCE_ROOT, path);
    int rc = system(cmd);
    if (rc == -1 || !WIFEXITED(rc)) return 1;
    return WEXITSTATUS(rc);
}

static int validated, validator_missing;

static void check_valid(const char *path)
{
    int v = validate(path);
    if (v == 77) { validator_missing = 1; return; }
    CHECK_MSG(v == 0, "%s does not pass the glTF validator", path);
    validated++;
}

static void test_round_trip_corpus(void)
{
    char path[4200], out[1024], side[1024], msg[512];
    pb_manifest manifest;
    mk_error err = {0};
    CHECK_CORPUS_MANIFEST(&manifest);
    int n = 0, frames = 0;
    double wp = 0, wn = 0;
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        const pb_case *c = &manifest.cases[i];
        if (!c->gltf) continue;
        pb_manifest_path(&manifest, c->source, path, sizeof path);
        for (int variant = 0; variant < 2; variant++) {
            const char *ext = variant ? "gltf" : "glb";
            gt_model orig;
            if (gt_load(&orig, path, NULL, msg, sizeof msg)) { CHECK_MSG(0, "%s: %s", c->name, msg); gt_free(&orig); continue; }
            snprintf(out, sizeof out, "%s_%s.%s", out_prefix(), c->name, ext);
            snprintf(side, sizeof side, "%s_%s.%s.channels.json", out_prefix(), c->name, ext);
            mk_gltf_export_report rep;
            mk_result r = mk_export_gltf(&orig.raw, out, side, &rep, &err);
            CHECK_MSG(r == MK_OK, "%s: export: %s", c->name, err.message);
            gt_free(&orig);
            if (r != MK_OK) continue;
            check_valid(out);
            /* With the sidecar, and without it (glTF sources have only plain channels). */
            for (int with_sidecar = 1; with_sidecar >= 0; with_sidecar--) {
                gt_model back;
                if (gt_load(&back, out, with_sidecar ? side : NULL, msg, sizeof msg)) {
                    CHECK_MSG(0, "%s re-import: %s", c->name, msg);
                } else {
                    gt_check_case(&manifest, c, &back, &wp, &wn, &frames);
                }
                gt_free(&back);
            }
            remove(out);
            remove(side);
        }
        n++;
    }
    CHECK(n >= 8);
    printf("  %d cases exported as .glb and .gltf, %d re-imported frames: max position error %.3g, normal angle %.3g deg\n",
           n, frames, wp, wn);
    pb_manifest_free(&manifest);
}

/* ---- a synthetic asset with what glTF cannot say directly ---- */

static mk_key key(float t, float v, mk_interp interp)
{
    mk_key k;
    memset(&k, 0, sizeof k);
    k.time = t;
    k.value = v;
    k.interp = (uint32_t)interp;
    k.left_weight = k.right_weight = 1.0f / 3.0f;
    return k;
}

/* A quad with a progressive channel (full weights -0.5, 0.5, 1), a plain channel, sequential
 * stacking, a non-identity control-point map, and a clip with linear (crossing every full
 * weight, extrapolating both ways), cubic and constant segments. */
static void make_synthetic(mk_raw_asset *raw)
{
    mk_raw_init(raw, NULL);
    mk_arena *a = &raw->arena;
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    static const uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
    m->name = mk_arena_strdup(a, "quad");
    m->vertex_count = 4;
    m->positions = mk_arena_array(a, 12, sizeof(float));
    memcpy(m->positions, pos, sizeof pos);
    m->normals = mk_arena_array(a, 12, sizeof(float));
    memcpy(m->normals, nrm, sizeof nrm);
    m->triangle_count = 2;
    m->triangles = mk_arena_array(a, 6, sizeof(uint32_t));
    memcpy(m->triangles, tri, sizeof tri);
    m->control_point_count = 3;
    m->control_points = mk_arena_array(a, 4, sizeof(uint32_t));
    m->control_points[0] = 0; m->control_points[1] = 1; m->control_points[2] = 2; m->control_points[3] = 0;
    m->world[12] = 5.0f;
    m->stacking = MK_STACKING_SEQUENTIAL;

    mk_raw_channel *ch = mk_raw_add_channels(raw, 2);
    static const float fw[3] = {-0.5f, 0.5f, 1.0f};
    ch[0].name = mk_arena_strdup(a, "bend");
    ch[0].mesh = 0;
    ch[0].default_weight = 0.3f;
    mk_raw_target *t = mk_raw_add_targets(raw, &ch[0], 3);
    for (int k = 0; k < 3; k++) {
        char name[32];
        snprintf(name, sizeof name, "bend_%d", k);
        t[k].name = mk_arena_strdup(a, name);
        t[k].full_weight = fw[k];
        t[k].count = 2;
        t[k].indices = mk_arena_array(a, 2, sizeof(uint32_t));
        t[k].indices[0] = 2; t[k].indices[1] = 3;
        t[k].positions = mk_arena_array(a, 6, sizeof(float));
        t[k].normals = mk_arena_array(a, 6, sizeof(float));
        /* Curved path: the in-betweens are not on one line. */
        t[k].positions[2] = (float)(k + 1) * 0.3f;
        t[k].positions[3] = (float)(k * k) * 0.1f - 0.2f;
        t[k].positions[5] = 0.25f * (float)k;
        t[k].normals[0] = 0.1f * (float)k;
    }
    ch = &raw->channels[1];
    ch->name = mk_arena_strdup(a, "lift");
    ch->mesh = 0;
    t = mk_raw_add_targets(raw, ch, 1);
    t->name = mk_arena_strdup(a, "lift");
    t->count = 1;
    t->indices = mk_arena_array(a, 1, sizeof(uint32_t));
    t->indices[0] = 1;
    t->positions = mk_arena_array(a, 3, sizeof(float));
    t->positions[2] = 0.7f;

    mk_raw_clip *clip = mk_raw_add_clips(raw, 1);
    clip->name = mk_arena_strdup(a, "mix");
    clip->start = 0.0f;
    clip->duration = 4.0f;   /* longer than the last key: only the sidecar can keep it */
    clip->track_count = 2;
    clip->tracks = mk_arena_array(a, 2, sizeof(mk_raw_track));
    mk_key *k0 = mk_arena_array(a, 3, sizeof(mk_key));
    k0[0] = key(0.0f, -0.8f, MK_INTERP_LINEAR);
    k0[1] = key(1.5f, 1.4f, MK_INTERP_LINEAR);
    k0[2] = key(3.0f, 0.2f, MK_INTERP_LINEAR);
    clip->tracks[0] = (mk_raw_track){0, 3, k0};
    mk_key *k1 = mk_arena_array(a, 4, sizeof(mk_key));
    k1[0] = key(0.0f, 0.0f, MK_INTERP_CUBIC);
    k1[0].right_slope = 2.0f;
    k1[1] = key(1.0f, 1.0f, MK_INTERP_CONSTANT);
    k1[1].left_slope = -1.0f;
    k1[2] = key(2.0f, 0.5f, MK_INTERP_CUBIC);
    k1[2].right_slope = 0.5f;
    k1[2].right_weight = 0.2f;   /* weighted tangent: not a glTF Hermite */
    k1[3] = key(3.0f, 0.0f, MK_INTERP_LINEAR);
    clip->tracks[1] = (mk_raw_track){1, 4, k1};
}

/* Largest world-position difference over 301 times of clip 0 (mesh 0). */
static double max_difference(const gt_model *a, const gt_model *b)
{
    double worst = 0;
    float wa[16], wb[16], pa[12], pb[12], qa[12], qb[12];
    for (int i = 0; i <= 300; i++) {
        float t = 3.0f * (float)i / 300.0f;
        gt_weights(a, 0, t, NULL, 0, wa);
        gt_weights(b, 0, t, NULL, 0, wb);
        gt_eval(a, 0, wa, pa, NULL);
        gt_eval(b, 0, wb, pb, NULL);
        gt_to_world(a, 0, pa, 4, qa);
        gt_to_world(b, 0, pb, 4, qb);
        for (int q = 0; q < 12; q++) worst = fmax(worst, fabs((double)qa[q] - qb[q]));
    }
    return worst;
}

static void test_progressive_round_trip(void)
{
    gt_model orig;
    memset(&orig, 0, sizeof orig);
    make_synthetic(&orig.raw);
    char msg[512];
    mk_error err = {0};
    CHECK_MSG(mk_raw_validate(&orig.raw, &err) == MK_OK, "%s", err.message);
    if (gt_open_raw(&orig, msg, sizeof msg)) { CHECK_MSG(0, "%s", msg); gt_free(&orig); return; }
    char out[256], side[256];
    snprintf(out, sizeof out, "%s_synthetic.glb", out_prefix());
    snprintf(side, sizeof side, "%s_synthetic.channels.json", out_prefix());
    mk_gltf_export_report rep;
    CHECK_MSG(mk_export_gltf(&orig.raw, out, side, &rep, &err) == MK_OK, "%s", err.message);
    CHECK_EQ_INT(rep.progressive_channels, 1);
    CHECK_EQ_INT(rep.targets, 4);
    CHECK_EQ_INT(rep.resampled_tracks, 1);
    check_valid(out);

    gt_model back;
    if (gt_load(&back, out, side, msg, sizeof msg)) {
        CHECK_MSG(0, "re-import with sidecar: %s", msg);
    } else {
        const mk_raw_asset *r = &back.raw;
        CHECK_EQ_INT(r->channel_count, 2);
        CHECK(r->channel_count == 2 && strcmp(r->channels[0].name, "bend") == 0);
        CHECK(r->channel_count == 2 && r->channels[0].target_count == 3);
        if (r->channel_count == 2 && r->channels[0].target_count == 3) {
            CHECK_NEAR(r->channels[0].targets[0].full_weight, -0.5, 0);
            CHECK_NEAR(r->channels[0].targets[2].full_weight, 1.0, 0);
            CHECK(strcmp(r->channels[0].targets[1].name, "bend_1") == 0);
            CHECK_NEAR(r->channels[0].default_weight, 0.3, 1e-6);
        }
        CHECK_EQ_INT(r->meshes[0].stacking, MK_STACKING_SEQUENTIAL);
        CHECK_EQ_INT(r->meshes[0].control_point_count, 3);
        CHECK_EQ_INT(r->meshes[0].control_points[3], 0);
        CHECK(strcmp(r->meshes[0].name, "quad") == 0);
        CHECK_EQ_INT(r->clip_count, 1);
        if (r->clip_count == 1) CHECK_NEAR(r->clips[0].duration, 4.0, 0);
        /* The progressive channel is linear between keys and exported with its bend points, so
         * it is exact; the cubic/constant/weighted curve of "lift" is sampled at 60 Hz. */
        double d = max_difference(&orig, &back);
        printf("  round trip with sidecar: max world difference %.3g over 301 times\n", d);
        CHECK(d <= 2e-3);
    }
    gt_free(&back);

    /* Without the sidecar every in-between is its own channel, driven by the exported slot
     * weights; stacking falls back to additive, so compare against an additive original. */
    if (gt_load(&back, out, NULL, msg, sizeof msg)) {
        CHECK_MSG(0, "re-import without sidecar: %s", msg);
    } else {
        CHECK_EQ_INT(back.raw.channel_count, 4);
        gt_model additive;
        memset(&additive, 0, sizeof additive);
        make_synthetic(&additive.raw);
        additive.raw.meshes[0].stacking = MK_STACKING_ADDITIVE;
        if (gt_open_raw(&additive, msg, sizeof msg) == 0) {
            double d = max_difference(&additive, &back);
            printf("  round trip without sidecar (additive): max world difference %.3g\n", d);
            CHECK(d <= 2e-3);
        }
        gt_free(&additive);
    }
    gt_free(&back);
    gt_free(&orig);
    remove(out);
    remove(side);
}

/* FBX sources: the exported glTF + sidecar re-imports to the same channels, control points and
 * world-space frames as the FBX import itself (so the FBX references still hold). Curves with
 * weighted or auto tangents are resampled at 60 Hz, hence the small tolerance. */
static void test_round_trip_fbx(void)
{
    const char *corpus = check_corpus_dir();
    char path[1024], msg[512];
    snprintf(path, sizeof path, "%s/cases.json", corpus);
    cJSON *cases = gt_read_json(path);
    if (!cases) SKIP("corpus not found at %s", corpus);
    int done = 0, refused = 0;
    double worst = 0;
    const cJSON *c;
    cJSON_ArrayForEach(c, cJSON_GetObjectItem(cases, "cases")) {
        if (strcmp(cJSON_GetObjectItem(c, "format")->valuestring, "fbx") != 0) continue;
        const char *name = cJSON_GetObjectItem(c, "name")->valuestring;
        snprintf(path, sizeof path, "%s/%s", corpus, cJSON_GetObjectItem(c, "source")->valuestring);
        gt_model orig;
        memset(&orig, 0, sizeof orig);
        mk_raw_init(&orig.raw, NULL);
        mk_error err = {0};
        if (mk_import_file(path, NULL, &orig.raw, &err) != MK_OK || mk_raw_group_channels(&orig.raw, &err) != MK_OK
            || gt_open_raw(&orig, msg, sizeof msg)) {
            printf("  %s: FBX import refused (%s); not a glTF export matter\n", name, err.message);
            refused++;
            gt_free(&orig);
            continue;
        }
        char out[1024], side[1024];
        snprintf(out, sizeof out, "%s_%s.glb", out_prefix(), name);
        snprintf(side, sizeof side, "%s_%s.channels.json", out_prefix(), name);
        CHECK_MSG(mk_export_gltf(&orig.raw, out, side, NULL, &err) == MK_OK, "%s: %s", name, err.message);
        check_valid(out);
        gt_model back;
        if (gt_load(&back, out, side, msg, sizeof msg)) {
            CHECK_MSG(0, "%s: re-import: %s", name, msg);
            gt_free(&back);
            gt_free(&orig);
            continue;
        }
        /* Meshes without channels are not imported from glTF (nothing to morph), so compare
         * the meshes that have channels, in order. */
        const mk_raw_asset *a = &orig.raw, *b = &back.raw;
        uint32_t *morphed = calloc(a->mesh_count + 1, sizeof *morphed), nm = 0;
        for (uint32_t m = 0; m < a->mesh_count; m++) {
            int has = 0;
            for (uint32_t i = 0; i < a->channel_count; i++) has |= a->channels[i].mesh == m;
            if (has) morphed[nm++] = m;
        }
        CHECK_EQ_INT(b->mesh_count, nm);
        CHECK_EQ_INT(b->channel_count, a->channel_count);
        CHECK_EQ_INT(b->clip_count, a->clip_count);
        for (uint32_t i = 0; i < a->channel_count && i < b->channel_count; i++) {
            CHECK_EQ_INT(b->channels[i].target_count, a->channels[i].target_count);
            CHECK(strcmp(a->channels[i].name ? a->channels[i].name : "", b->channels[i].name) == 0);
            for (uint32_t k = 0; k < a->channels[i].target_count && k < b->channels[i].target_count; k++)
                CHECK_NEAR(b->channels[i].targets[k].full_weight, a->channels[i].targets[k].full_weight, 0);
        }
        if (b->mesh_count == nm && b->channel_count == a->channel_count) {
            double diag = 0;
            for (uint32_t j = 0; j < nm; j++) {
                const mk_raw_mesh *ma = &a->meshes[morphed[j]], *mb = &b->meshes[j];
                CHECK_EQ_INT(mb->control_point_count, ma->control_point_count);
                CHECK(memcmp(mb->control_points, ma->control_points, 4 * (size_t)ma->vertex_count) == 0);
                CHECK(strcmp(mb->name, ma->name) == 0);
                float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
                for (uint32_t v = 0; v < ma->vertex_count; v++)
                    for (int q = 0; q < 3; q++) {
                        lo[q] = fminf(lo[q], ma->positions[3 * v + q]);
                        hi[q] = fmaxf(hi[q], ma->positions[3 * v + q]);
                    }
                diag = fmax(diag, sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) + (double)(hi[1] - lo[1]) * (hi[1] - lo[1])
                                       + (double)(hi[2] - lo[2]) * (hi[2] - lo[2])));
            }
            float *wa = calloc(a->channel_count + 1, sizeof(float)), *wb = calloc(a->channel_count + 1, sizeof(float));
            double e = 0;
            const cJSON *f;
            cJSON_ArrayForEach(f, cJSON_GetObjectItem(c, "frames")) {
                const cJSON *tm = cJSON_GetObjectItem(f, "time");
                int clip = cJSON_IsNumber(tm) && a->clip_count ? 0 : -1;
                float t = cJSON_IsNumber(tm) ? (float)tm->valuedouble : 0.0f;
                gt_weights(&orig, clip, t, NULL, 0, wa);
                gt_weights(&back, clip, t, NULL, 0, wb);
                for (uint32_t j = 0; j < nm; j++) {
                    size_t n = a->meshes[morphed[j]].vertex_count;
                    float *pa = calloc(3 * n, sizeof(float)), *pb = calloc(3 * n, sizeof(float));
                    float *qa = calloc(3 * n, sizeof(float)), *qb = calloc(3 * n, sizeof(float));
                    CHECK(gt_eval(&orig, morphed[j], wa, pa, NULL) == 0);
                    CHECK(gt_eval(&back, j, wb, pb, NULL) == 0);
                    gt_to_world(&orig, morphed[j], pa, (uint32_t)n, qa);
                    gt_to_world(&back, j, pb, (uint32_t)n, qb);
                    for (size_t q = 0; q < 3 * n; q++) e = fmax(e, fabs((double)qa[q] - qb[q]));
                    free(pa); free(pb); free(qa); free(qb);
                }
            }
            free(wa);
            free(wb);
            double rel = diag > 0 ? e / diag : e;
            CHECK_MSG(rel <= 1e-3, "%s: round trip differs by %g x diagonal", name, rel);
            worst = fmax(worst, rel);
        }
        free(morphed);
        gt_free(&back);
        gt_free(&orig);
        remove(out);
        remove(side);
        done++;
    }
    cJSON_Delete(cases);
    if (!done && refused) SKIP("no FBX case imports yet");
    CHECK(done > 0);
    printf("  %d FBX cases round-tripped through glTF (%d refused by the FBX importer): max difference %.3g x diagonal\n",
           done, refused, worst);
}

static void test_validator_ran(void)
{
    if (validator_missing || !validated) SKIP("glTF validator not available (npm install --prefix tests/gltf)");
    printf("  %d exported files passed the Khronos glTF validator\n", validated);
}

CHECK_MAIN(CASE(test_round_trip_corpus), CASE(test_progressive_round_trip), CASE(test_round_trip_fbx),
           CASE(test_validator_ran))

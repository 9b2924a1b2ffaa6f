#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "gltf_test_util.h"

int gt_open_raw(gt_model *m, char *msg, size_t msg_size)
{
    mk_error err = {0};
    mk_write_options wo = {0};
    wo.precision = MK_PRECISION_FLOAT;
    mk_arena_init(&m->arena, NULL);
    if (mk_write_blob(&m->raw, &wo, &m->arena, &m->blob, &m->size, NULL, &err) != MK_OK) {
        snprintf(msg, msg_size, "write: %s", err.message);
        return 1;
    }
    if (mk_asset_open(m->blob, m->size, &m->asset, &err) != MK_OK) {
        snprintf(msg, msg_size, "open: %s", err.message);
        return 1;
    }
    return 0;
}

int gt_load(gt_model *m, const char *path, const char *sidecar, char *msg, size_t msg_size)
{
    memset(m, 0, sizeof *m);
    mk_raw_init(&m->raw, NULL);
    mk_arena_init(&m->arena, NULL);
    mk_import_options o = {0};
    o.channels_sidecar = sidecar;
    mk_error err = {0};
    if (mk_import_file(path, &o, &m->raw, &err) != MK_OK) {
        snprintf(msg, msg_size, "import: %s", err.message);
        return 1;
    }
    return gt_open_raw(m, msg, msg_size);
}

void gt_free(gt_model *m)
{
    mk_raw_free(&m->raw);
    mk_arena_free_all(&m->arena);
}

int gt_weights(const gt_model *m, int clip, double time, const double *forced, int forced_count, float *w)
{
    uint32_t n = m->asset.channel_count;
    for (uint32_t c = 0; c < n; c++) {
        mk_channel_info ci;
        mk_channel_get(&m->asset, c, &ci);
        w[c] = ci.default_weight;
    }
    if (clip >= 0) {
        mk_sample_job s;
        memset(&s, 0, sizeof s);
        s.asset = &m->asset;
        s.clip = (uint32_t)clip;
        s.time = time;
        s.weights = w;
        s.weight_count = n;
        mk_error err;
        if (mk_sample_run(&s, &err) != MK_OK) {
            fprintf(stderr, "sample: %s\n", err.message);
            return 1;
        }
    } else if (forced) {
        for (uint32_t mi = 0; mi < m->asset.mesh_count; mi++) {
            mk_mesh_info info;
            mk_mesh_get(&m->asset, mi, &info);
            for (uint32_t k = 0; k < info.channel_count && (int)k < forced_count; k++) w[info.first_channel + k] = (float)forced[k];
        }
    }
    return 0;
}

int gt_eval(const gt_model *m, uint32_t mesh, const float *weights, float *positions, float *normals)
{
    mk_mesh_info info;
    if (!mk_mesh_get(&m->asset, mesh, &info)) return 1;
    size_t scratch_size = mk_eval_scratch_size(&m->asset, mesh);
    void *scratch = NULL;
    if (scratch_size && !(scratch = aligned_alloc(16, (scratch_size + 15) / 16 * 16))) return 1;
    mk_eval_job e;
    memset(&e, 0, sizeof e);
    e.asset = &m->asset;
    e.mesh = mesh;
    e.vertex_count = MK_VERTICES_TO_END;
    e.weights = weights + info.first_channel;
    e.weight_count = info.channel_count;
    e.scratch = scratch;
    e.scratch_size = scratch_size;
    e.positions = positions;
    e.positions_size = (size_t)info.vertex_count * 12;
    if (normals && info.has_normals) {
        e.normals = normals;
        e.normals_size = (size_t)info.vertex_count * 12;
    }
    mk_error err;
    mk_result r = mk_eval_run(&e, &err);
    free(scratch);
    if (r != MK_OK) {
        fprintf(stderr, "eval: %s\n", err.message);
        return 1;
    }
    return 0;
}

int gt_find(const gt_model *m, int node, int mesh, int primitive)
{
    for (uint32_t i = 0; i < m->asset.mesh_count; i++) {
        mk_mesh_info info;
        mk_mesh_get(&m->asset, i, &info);
        if (info.gltf_node == node && info.gltf_mesh == mesh && info.gltf_primitive == primitive) return (int)i;
    }
    return -1;
}

void gt_to_world(const gt_model *m, uint32_t mesh, const float *local, uint32_t n, float *world)
{
    mk_mesh_info info;
    mk_mesh_get(&m->asset, mesh, &info);
    const float *w = info.world;
    for (uint32_t v = 0; v < n; v++) {
        const float *p = local + 3 * v;
        for (int r = 0; r < 3; r++) world[3 * v + r] = w[r] * p[0] + w[4 + r] * p[1] + w[8 + r] * p[2] + w[12 + r];
    }
}

cJSON *gt_read_json(const char *path)
{
    size_t n;
    unsigned char *data = check_read_file(path, &n);
    if (!data) return NULL;
    cJSON *j = cJSON_ParseWithLength((const char *)data, n);
    free(data);
    return j;
}

/* Normal directions must agree to this (|unit(ours) - unit(reference)|). */
#define NORMAL_TOLERANCE 1e-4

void gt_check_case(const char *corpus, const cJSON *c, gt_model *loaded, double *worst_pos, double *worst_nrm, int *frames_done)
{
    const char *name = cJSON_GetObjectItem(c, "name")->valuestring;
    const char *source = cJSON_GetObjectItem(c, "source")->valuestring;
    double tol = cJSON_GetObjectItem(cJSON_GetObjectItem(c, "reference"), "tolerance")->valuedouble;
    char path[1024], msg[512];
    snprintf(path, sizeof path, "%s/%s", corpus, source);
    gt_model own, *mp = loaded;
    if (!mp) {
        mp = &own;
        if (gt_load(&own, path, NULL, msg, sizeof msg)) {
            CHECK_MSG(0, "%s: %s", name, msg);
            gt_free(&own);
            return;
        }
    }
    gt_model m = *mp;
    float *w = calloc(m.asset.channel_count + 1, sizeof *w);
    const cJSON *f;
    cJSON_ArrayForEach(f, cJSON_GetObjectItem(c, "frames")) {
        snprintf(path, sizeof path, "%s/%s", corpus, cJSON_GetObjectItem(f, "file")->valuestring);
        cJSON *ref = gt_read_json(path);
        CHECK_MSG(ref != NULL, "%s: cannot read %s", name, path);
        if (!ref) continue;
        const cJSON *clip = cJSON_GetObjectItem(f, "clip"), *time = cJSON_GetObjectItem(f, "time");
        const cJSON *forced = cJSON_GetObjectItem(f, "weights");
        double fw[64];
        int nf = 0;
        const cJSON *e;
        if (cJSON_IsArray(forced)) cJSON_ArrayForEach(e, forced) if (nf < 64) fw[nf++] = e->valuedouble;
        int clip_index = cJSON_IsNumber(clip) ? clip->valueint : -1;
        CHECK(gt_weights(&m, clip_index, cJSON_IsNumber(time) ? time->valuedouble : 0.0,
                         cJSON_IsArray(forced) ? fw : NULL, nf, w) == 0);
        const cJSON *rm;
        cJSON_ArrayForEach(rm, cJSON_GetObjectItem(ref, "meshes")) {
            int node = cJSON_GetObjectItem(rm, "node")->valueint, mesh = cJSON_GetObjectItem(rm, "mesh")->valueint,
                prim = cJSON_GetObjectItem(rm, "primitive")->valueint;
            const cJSON *rw = cJSON_GetObjectItem(rm, "weights");
            int mi = gt_find(&m, node, mesh, prim);
            if (mi < 0) {
                /* A reference mesh without channels may be absent from the import. */
                CHECK_MSG(!cJSON_IsArray(rw) || cJSON_GetArraySize(rw) == 0, "%s: node %d mesh %d primitive %d not imported",
                          name, node, mesh, prim);
                continue;
            }
            mk_mesh_info info;
            mk_mesh_get(&m.asset, (uint32_t)mi, &info);
            /* The sampled channel weights are three.js's morphTargetInfluences. */
            int k = 0;
            cJSON_ArrayForEach(e, rw) {
                if ((uint32_t)k < info.channel_count)
                    CHECK_NEAR(w[info.first_channel + k], e->valuedouble, 1e-6);
                k++;
            }
            CHECK_EQ_INT(k, info.channel_count);
            const cJSON *rp = cJSON_GetObjectItem(rm, "positions"), *rn = cJSON_GetObjectItem(rm, "normals");
            CHECK_EQ_INT(cJSON_GetArraySize(rp), 3 * (int)info.vertex_count);
            if (cJSON_GetArraySize(rp) != 3 * (int)info.vertex_count) continue;
            float *pos = calloc(3 * (size_t)info.vertex_count, sizeof *pos);
            float *nrm = calloc(3 * (size_t)info.vertex_count, sizeof *nrm);
            CHECK(gt_eval(&m, (uint32_t)mi, w, pos, nrm) == 0);
            double ep = 0, en = 0;
            int i = 0;
            cJSON_ArrayForEach(e, rp) { double d = fabs(pos[i++] - e->valuedouble); if (d > ep) ep = d; }
            if (cJSON_IsArray(rn) && info.has_normals) {
                CHECK_EQ_INT(cJSON_GetArraySize(rn), 3 * (int)info.vertex_count);
                for (uint32_t v = 0; v < info.vertex_count && cJSON_GetArraySize(rn) == 3 * (int)info.vertex_count; v++) {
                    double r[3], len = 0;
                    for (int q = 0; q < 3; q++) { r[q] = cJSON_GetArrayItem(rn, (int)(3 * v) + q)->valuedouble; len += r[q] * r[q]; }
                    len = sqrt(len);
                    if (len < 1e-6) continue;
                    double d = 0;
                    for (int q = 0; q < 3; q++) d += (nrm[3 * v + q] - r[q] / len) * (nrm[3 * v + q] - r[q] / len);
                    if (sqrt(d) > en) en = sqrt(d);
                }
            }
            CHECK_MSG(ep <= tol, "%s %s %s: position error %g > %g", name, cJSON_GetObjectItem(f, "file")->valuestring,
                      cJSON_GetObjectItem(rm, "label")->valuestring, ep, tol);
            CHECK_MSG(en <= NORMAL_TOLERANCE, "%s %s %s: normal direction error %g", name,
                      cJSON_GetObjectItem(f, "file")->valuestring, cJSON_GetObjectItem(rm, "label")->valuestring, en);
            if (ep > *worst_pos) *worst_pos = ep;
            if (en > *worst_nrm) *worst_nrm = en;
            free(pos);
            free(nrm);
        }
        (*frames_done)++;
        cJSON_Delete(ref);
    }
    free(w);
    if (!loaded) gt_free(&own);
}


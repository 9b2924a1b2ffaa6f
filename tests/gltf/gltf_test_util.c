/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "frame.h"
#include "gltf_test_util.h"

int gt_open_raw(gt_model *m, char *msg, size_t msg_size)
{
    mk_error err = {0};
    mk_write_options wo = { .precision = MK_PRECISION_FLOAT };
    if (pb_asset_open_raw(m, &wo, &err) != MK_OK) {
        snprintf(msg, msg_size, "write/open: %s", err.message);
        return 1;
    }
    return 0;
}

int gt_load(gt_model *m, const char *path, const char *sidecar, char *msg, size_t msg_size)
{
    mk_import_options o = { .channels_sidecar = sidecar };
    mk_write_options wo = { .precision = MK_PRECISION_FLOAT };
    mk_error err = {0};
    if (pb_asset_load(path, &o, &wo, m, &err) != MK_OK) {
        snprintf(msg, msg_size, "import: %s", err.message);
        return 1;
    }
    return 0;
}

void gt_free(gt_model *m) { pb_asset_free(m); }

int gt_weights(const gt_model *m, int clip, double time, const double *forced, int forced_count, float *w)
{
    mk_error err;
    if (pb_frame_weights(&m->asset, clip, time, w, &err) != MK_OK) {
        fprintf(stderr, "sample: %s\n", err.message);
        return 1;
    }
    if (clip < 0 && forced)
        for (uint32_t mi = 0; mi < m->asset.mesh_count; mi++) {
            mk_mesh_info info;
            mk_mesh_get(&m->asset, mi, &info);
            for (uint32_t k = 0; k < info.channel_count && (int)k < forced_count; k++) w[info.first_channel + k] = (float)forced[k];
        }
    return 0;
}

int gt_eval(const gt_model *m, uint32_t mesh, const float *weights, float *positions, float *normals)
{
    mk_error err;
    if (pb_eval_mesh(&m->asset, mesh, weights, MK_STACKING_ASSET, MK_NORMALS_NLERP, positions, normals, &err) != MK_OK) {
        fprintf(stderr, "eval: %s\n", err.message);
        return 1;
    }
    return 0;
}

void gt_to_world(const gt_model *m, uint32_t mesh, const float *local, uint32_t n, float *world)
{
    mk_mesh_info info;
    mk_mesh_get(&m->asset, mesh, &info);
    memcpy(world, local, 12 * (size_t)n);
    pb_to_world(info.world, world, NULL, n);
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

void gt_check_case(const pb_manifest *manifest, const pb_case *c, gt_model *loaded, double *worst_pos,
                   double *worst_normal_deg, int *frames_done)
{
    char path[4200], msg[512];
    gt_model own, *m = loaded;
    if (!m) {
        m = &own;
        pb_manifest_path(manifest, c->source, path, sizeof path);
        if (gt_load(&own, path, NULL, msg, sizeof msg)) {
            CHECK_MSG(0, "%s: %s", c->name, msg);
            gt_free(&own);
            return;
        }
    }
    /* three.js's normals agree in direction to 1e-4 (0.006 degrees); its weights are the
     * sampled morphTargetInfluences. */
    pb_conform_options o = { .normal_tolerance_deg = 0.006, .weight_tolerance = 1e-6 };
    for (uint32_t k = 0; k < c->frame_count; k++) {
        pb_frame_result r;
        pb_conform_frame(manifest, c, &c->frames[k], m, &o, &r);
        CHECK_MSG(r.passed, "%s %s: position error %g (allowed %g), normal %g deg, weight %g%s%s", c->name, c->frames[k].file,
                  r.position_error, r.allowed, r.normal_error_deg, r.weight_error, r.failure[0] ? ": " : "", r.failure);
        CHECK_MSG(r.weights_compared, "%s %s: no weights compared", c->name, c->frames[k].file);
        if (r.position_error > *worst_pos) *worst_pos = r.position_error;
        if (r.normal_error_deg > *worst_normal_deg) *worst_normal_deg = r.normal_error_deg;
        (*frames_done)++;
    }
    if (!loaded) gt_free(&own);
}

char *gt_base64(const unsigned char *in, size_t n)
{
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *out = malloc(4 * (n / 3 + 1) + 1);
    if (!out) return NULL;
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = t[v >> 18 & 63];
        out[o++] = t[v >> 12 & 63];
        out[o++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? t[v & 63] : '=';
    }
    out[o] = 0;
    return out;
}

mk_result gt_import_text(const char *json, const mk_import_options *options, mk_raw_asset *raw, mk_error *err)
{
    mk_raw_init(raw, NULL);
    memset(err, 0, sizeof *err);
    return mk_import_gltf(json, strlen(json), options, raw, err);
}

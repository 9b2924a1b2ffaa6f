#include <stdlib.h>
#include <string.h>
#include "fbx_test_util.h"

mk_result ft_import(const void *data, size_t size, const mk_import_options *options, mk_raw_asset *raw, mk_error *err)
{
    mk_raw_init(raw, NULL);
    /* The tests look at every mesh the file has, with or without blend shapes. */
    mk_import_options keep = { .keep_plain_meshes = 1 };
    return mk_import_fbx(data, size, options ? options : &keep, raw, err);
}

int32_t ft_find_mesh(const mk_raw_asset *raw, const char *name)
{
    for (uint32_t i = 0; i < raw->mesh_count; i++)
        if (raw->meshes[i].name && strcmp(raw->meshes[i].name, name) == 0) return (int32_t)i;
    return -1;
}

int ft_eval_control_points(const mk_raw_asset *raw, uint32_t mesh, int32_t clip, float time, const float *weights,
                           int world, float **out, uint32_t *control_point_count)
{
    *out = NULL;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_write_options wo;
    memset(&wo, 0, sizeof wo);
    wo.precision = MK_PRECISION_FLOAT;
    void *blob = NULL;
    size_t size = 0;
    mk_error err;
    int status = -1;
    float *w = NULL, *positions = NULL, *result = NULL;
    void *scratch = NULL;
    if (mk_write_blob(raw, &wo, &arena, &blob, &size, NULL, &err) != MK_OK) goto done;
    mk_asset asset;
    if (mk_asset_open(blob, size, &asset, &err) != MK_OK) goto done;
    w = calloc(asset.channel_count + 1, sizeof *w);
    if (!w) goto done;
    for (uint32_t c = 0; c < asset.channel_count; c++) {
        mk_channel_info info;
        mk_channel_get(&asset, c, &info);
        w[c] = weights ? weights[c] : info.default_weight;
    }
    if (clip >= 0 && !weights) {
        mk_sample_job job;
        memset(&job, 0, sizeof job);
        job.asset = &asset;
        job.clip = (uint32_t)clip;
        job.time = time;
        job.weights = w;
        job.weight_count = asset.channel_count;
        if (mk_sample_run(&job, &err) != MK_OK) goto done;
    }
    mk_mesh_info m;
    if (!mk_mesh_get(&asset, mesh, &m)) goto done;
    size_t scratch_size = mk_eval_scratch_size(&asset, mesh);
    scratch = aligned_alloc(16, (scratch_size + 16) & ~(size_t)15);
    positions = malloc((size_t)m.vertex_count * 12 + 12);
    result = calloc((size_t)m.control_point_count * 3 + 3, sizeof(float));
    if (!scratch || !positions || !result) goto done;
    mk_eval_job job;
    memset(&job, 0, sizeof job);
    job.asset = &asset;
    job.mesh = mesh;
    job.vertex_count = MK_VERTICES_TO_END;
    job.weights = w + m.first_channel;
    job.weight_count = m.channel_count;
    job.scratch = scratch;
    job.scratch_size = scratch_size;
    job.positions = positions;
    job.positions_size = (size_t)m.vertex_count * 12;
    if (mk_eval_run(&job, &err) != MK_OK) goto done;
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        uint32_t cp = m.control_points[v];
        const float *p = positions + 3 * (size_t)v;
        float *q = result + 3 * (size_t)cp;
        if (world) {
            const float *x = m.world;
            for (int r = 0; r < 3; r++)
                q[r] = (float)((double)x[r] * p[0] + (double)x[4 + r] * p[1] + (double)x[8 + r] * p[2] + x[12 + r]);
        } else {
            memcpy(q, p, 12);
        }
    }
    *control_point_count = m.control_point_count;
    *out = result;
    result = NULL;
    status = 0;
done:
    free(w);
    free(positions);
    free(result);
    free(scratch);
    mk_arena_free_all(&arena);
    return status;
}

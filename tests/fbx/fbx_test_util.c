/* SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fbx_test_util.h"
#include "frame.h"

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
    mk_write_options wo = { .precision = MK_PRECISION_FLOAT };
    void *blob = NULL;
    size_t size = 0;
    mk_error err;
    mk_asset asset;
    mk_mesh_info m;
    int status = -1;
    float *w = NULL, *positions = NULL, *result = NULL;
    if (mk_write_blob(raw, &wo, &arena, &blob, &size, NULL, &err) != MK_OK || mk_asset_open(blob, size, &asset, &err) != MK_OK
        || !mk_mesh_get(&asset, mesh, &m))
        goto done;
    w = calloc(asset.channel_count + 1, sizeof *w);
    positions = malloc((size_t)m.vertex_count * 12 + 12);
    result = calloc((size_t)m.control_point_count * 3 + 3, sizeof(float));
    if (!w || !positions || !result) goto done;
    if (weights) memcpy(w, weights, asset.channel_count * sizeof *w);
    else if (pb_frame_weights(&asset, clip, time, w, &err) != MK_OK) goto done;
    if (pb_eval_mesh(&asset, mesh, w, MK_STACKING_ASSET, MK_NORMALS_NLERP, positions, NULL, &err) != MK_OK) goto done;
    if (world) pb_to_world(m.world, positions, NULL, m.vertex_count);
    for (uint32_t v = 0; v < m.vertex_count; v++) memcpy(result + 3 * (size_t)m.control_points[v], positions + 3 * (size_t)v, 12);
    *control_point_count = m.control_point_count;
    *out = result;
    result = NULL;
    status = 0;
done:
    free(w);
    free(positions);
    free(result);
    mk_arena_free_all(&arena);
    return status;
}

unsigned char *ft_read_corpus(const char *name, size_t *size)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/fbx/%s.fbx", check_corpus_dir(), name);
    return check_read_file(path, size);
}

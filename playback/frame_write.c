/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "frame.h"
#include "frame_write.h"
#include "json_write.h"

void pb_frame_free(pb_frame *f)
{
    for (uint32_t i = 0; f->asset && i < f->asset->mesh_count; i++) {
        if (f->positions) free(f->positions[i]);
        if (f->normals) free(f->normals[i]);
        if (f->tangents) free(f->tangents[i]);
    }
    free(f->positions);
    free(f->normals);
    free(f->tangents);
    f->positions = f->normals = f->tangents = NULL;
}

/* Tangent directions to world space: the upper 3x3, normalized (w kept). */
static void tangents_to_world(const float world[16], float *tangents, uint32_t count)
{
    for (uint32_t v = 0; v < count; v++) {
        float *t = tangents + 4 * (size_t)v, x = t[0], y = t[1], z = t[2];
        double o[3];
        for (int k = 0; k < 3; k++) o[k] = (double)world[k] * x + (double)world[4 + k] * y + (double)world[8 + k] * z;
        double len = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
        if (len > 0)
            for (int k = 0; k < 3; k++) t[k] = (float)(o[k] / sqrt(len));
    }
}

mk_result pb_frame_evaluate(pb_frame *f, mk_error *err)
{
    const mk_asset *a = f->asset;
    f->positions = calloc(a->mesh_count + 1u, sizeof(float *));
    f->normals = calloc(a->mesh_count + 1u, sizeof(float *));
    f->tangents = calloc(a->mesh_count + 1u, sizeof(float *));
    if (!f->positions || !f->normals || !f->tangents) return mk_error_oom(err, "frame");
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        f->positions[i] = malloc(12u * (size_t)m.vertex_count + 12);
        f->normals[i] = m.has_normals ? malloc(12u * (size_t)m.vertex_count + 12) : NULL;
        f->tangents[i] = m.has_tangents && !f->skip_tangents ? malloc(16u * (size_t)m.vertex_count + 16) : NULL;
        if (!f->positions[i] || (m.has_normals && !f->normals[i]) || (m.has_tangents && !f->skip_tangents && !f->tangents[i]))
            return mk_error_oom(err, "frame");
        /* Surface normals and tangents come from the positions: nothing blended is needed. */
        int surface = f->surface_normals && f->normals[i] && mk_surface_topology_size(a, i);
        mk_result r = pb_eval_mesh_with(f->evaluator, a, i, f->weights, f->stacking, f->normal_mode, f->positions[i],
                                        surface ? NULL : f->normals[i], surface ? NULL : f->tangents[i], err);
        if (r == MK_OK && surface) r = pb_surface_normals(a, i, f->positions[i], f->normals[i], f->tangents[i], err);
        if (r != MK_OK) return r;
        if (f->world) pb_to_world(m.world, f->positions[i], f->normals[i], m.vertex_count);
        if (f->world && f->tangents[i]) tangents_to_world(m.world, f->tangents[i], m.vertex_count);
    }
    return MK_OK;
}

static const char *stacking_name(mk_stacking s)
{
    return s == MK_STACKING_SEQUENTIAL ? "sequential" : s == MK_STACKING_ADDITIVE ? "additive" : "asset";
}

void pb_json_mesh_begin(json_writer *w, const mk_asset *a, uint32_t mesh, mk_mesh_info *info)
{
    mk_mesh_get(a, mesh, info);
    const mk_mesh_info m = *info;
    json_object(w, NULL);
    json_string(w, "name", m.name);
    json_string(w, "node", m.name);
    json_int(w, "mesh_index", mesh);
    if (m.gltf_node >= 0) {
        json_int(w, "gltf_node", m.gltf_node);
        json_int(w, "gltf_mesh", m.gltf_mesh);
        json_int(w, "gltf_primitive", m.gltf_primitive);
    }
    json_int(w, "vertices", m.vertex_count);
    json_int(w, "control_point_count", m.control_point_count);
    json_floats(w, "world", m.world, 16);
}

void pb_frame_write_json(FILE *file, const pb_frame *f, const char *producer)
{
    const mk_asset *a = f->asset;
    json_writer w;
    json_begin(&w, file, 0);
    json_object(&w, NULL);
    json_string(&w, "reference", producer);
    if (f->clip >= 0) {
        json_int(&w, "clip", f->clip);
        json_number(&w, "time", f->time);
    }
    json_string(&w, "coordinates", f->world ? "world" : "mesh-local");
    json_string(&w, "stacking", stacking_name(f->stacking));
    json_string(&w, "normals", f->surface_normals ? "surface" : f->normal_mode == MK_NORMALS_SLERP ? "slerp" : "nlerp");
    json_array(&w, "meshes");
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        pb_json_mesh_begin(&w, a, i, &m);
        json_array(&w, "channels");
        for (uint32_t c = m.first_channel; c < m.first_channel + m.channel_count; c++) {
            mk_channel_info ch;
            mk_channel_get(a, c, &ch);
            json_object(&w, NULL);
            json_string(&w, "name", ch.name);
            json_number(&w, "weight", f->weights[c]);
            json_end_object(&w);
        }
        json_end_array(&w);
        json_floats(&w, "positions", f->positions[i], 3u * (size_t)m.vertex_count);
        if (f->normals[i]) json_floats(&w, "normals", f->normals[i], 3u * (size_t)m.vertex_count);
        if (f->tangents && f->tangents[i]) json_floats(&w, "tangents", f->tangents[i], 4u * (size_t)m.vertex_count);
        json_array(&w, "control_points");
        for (uint32_t v = 0; v < m.vertex_count; v++) json_int(&w, NULL, m.control_points[v]);
        json_end_array(&w);
        json_end_object(&w);
    }
    json_end_array(&w);
    json_end_object(&w);
    fputc('\n', file);
}

void pb_frame_write_obj(FILE *file, const pb_frame *f, const char *producer)
{
    const mk_asset *a = f->asset;
    fprintf(file, "# %s\n", producer);
    uint32_t base = 1;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        const float *p = f->positions[i], *n = f->normals[i];
        fprintf(file, "o %s\n", m.name);
        for (uint32_t v = 0; v < m.vertex_count; v++)
            fprintf(file, "v %.9g %.9g %.9g\n", (double)p[3 * v], (double)p[3 * v + 1], (double)p[3 * v + 2]);
        if (n)
            for (uint32_t v = 0; v < m.vertex_count; v++)
                fprintf(file, "vn %.9g %.9g %.9g\n", (double)n[3 * v], (double)n[3 * v + 1], (double)n[3 * v + 2]);
        for (uint32_t t = 0; t < m.triangle_count; t++) {
            uint32_t x = m.triangles[3 * t] + base, y = m.triangles[3 * t + 1] + base, z = m.triangles[3 * t + 2] + base;
            if (n) fprintf(file, "f %u//%u %u//%u %u//%u\n", x, x, y, y, z, z);
            else fprintf(file, "f %u %u %u\n", x, y, z);
        }
        base += m.vertex_count;
    }
}

static void put_u32(FILE *file, uint32_t v)
{
    unsigned char b[4] = { (unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)(v >> 24) };
    fwrite(b, 1, 4, file);
}

static void put_floats(FILE *file, const float *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &p[i], 4);
        put_u32(file, u);
    }
}

void pb_frame_write_mkf(FILE *file, const pb_frame *f)
{
    const mk_asset *a = f->asset;
    fwrite(PB_MKF_MAGIC, 1, 8, file);
    put_u32(file, 1);                                   /* version */
    put_u32(file, a->mesh_count);
    put_u32(file, a->channel_count);
    put_u32(file, f->world ? PB_MKF_WORLD : 0);
    put_u32(file, (uint32_t)f->clip);                   /* -1 (0xffffffff): no clip */
    put_u32(file, (uint32_t)f->stacking);
    put_u32(file, (uint32_t)f->normal_mode);
    put_u32(file, 0);                                   /* reserved */
    uint64_t t;
    double time = f->clip >= 0 ? f->time : 0.0;
    memcpy(&t, &time, 8);
    put_u32(file, (uint32_t)t);
    put_u32(file, (uint32_t)(t >> 32));
    put_floats(file, f->weights, a->channel_count);
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        int has_n = f->normals[i] != NULL, has_t = f->tangents && f->tangents[i];
        put_u32(file, m.vertex_count);
        put_u32(file, m.first_channel);
        put_u32(file, m.channel_count);
        put_u32(file, (has_n ? PB_MKF_NORMALS : 0u) | (has_t ? PB_MKF_TANGENTS : 0u));
        put_floats(file, f->positions[i], 3u * (size_t)m.vertex_count);
        if (has_n) put_floats(file, f->normals[i], 3u * (size_t)m.vertex_count);
        if (has_t) put_floats(file, f->tangents[i], 4u * (size_t)m.vertex_count);
    }
}

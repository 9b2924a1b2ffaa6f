/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "mesh_groups.h"

/* Bits of a float with -0 folded onto +0, so welding treats them as the same position. */
static uint32_t float_bits(float f)
{
    if (f == 0.0f) f = 0.0f;
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

typedef struct position_key {
    uint32_t bits[3];
    uint32_t vertex;
} position_key;

static int position_key_cmp(const void *pa, const void *pb)
{
    const position_key *a = pa, *b = pb;
    for (int i = 0; i < 3; i++)
        if (a->bits[i] != b->bits[i]) return a->bits[i] < b->bits[i] ? -1 : 1;
    return a->vertex < b->vertex ? -1 : a->vertex > b->vertex;
}

uint32_t *mk_mesh_weld(const mk_raw_mesh *mesh, mk_arena *arena, uint32_t *welded_count)
{
    uint32_t n = mesh->vertex_count;
    uint32_t *weld = mk_arena_array(arena, n ? n : 1, sizeof *weld);
    position_key *keys = mk_arena_array(arena, n ? n : 1, sizeof *keys);
    uint32_t *first = mk_arena_array(arena, n ? n : 1, sizeof *first);
    if (!weld || !keys || !first) return NULL;
    for (uint32_t v = 0; v < n; v++) {
        for (int c = 0; c < 3; c++) keys[v].bits[c] = float_bits(mesh->positions[3 * (size_t)v + c]);
        keys[v].vertex = v;
    }
    qsort(keys, n, sizeof *keys, position_key_cmp);
    /* Welded indices follow the first render vertex of each position, so vertex order is kept
     * as much as possible (better locality for the solvers' orderings). */
    for (uint32_t k = 0; k < n;) {
        uint32_t e = k + 1;
        while (e < n && memcmp(keys[e].bits, keys[k].bits, sizeof keys[k].bits) == 0) e++;
        for (uint32_t q = k; q < e; q++) first[keys[q].vertex] = keys[k].vertex; /* the smallest v */
        k = e;
    }
    uint32_t count = 0;
    for (uint32_t v = 0; v < n; v++) weld[v] = first[v] == v ? count++ : weld[first[v]];
    mk_arena_release(arena, keys);
    mk_arena_release(arena, first);
    *welded_count = count;
    return weld;
}

int mk_csr_build(mk_arena *arena, const uint32_t *key, uint32_t items, uint32_t keys, uint32_t **first_out,
                     uint32_t **list_out)
{
    uint32_t *first = mk_arena_array(arena, (size_t)keys + 1, sizeof *first);
    uint32_t *list = mk_arena_array(arena, items ? items : 1, sizeof *list);
    uint32_t *fill = mk_arena_array(arena, keys ? keys : 1, sizeof *fill);
    if (!first || !list || !fill) return 0;
    for (uint32_t i = 0; i < items; i++) first[key[i] + 1]++;
    for (uint32_t k = 0; k < keys; k++) first[k + 1] += first[k];
    memcpy(fill, first, (size_t)keys * sizeof *fill);
    for (uint32_t i = 0; i < items; i++) list[fill[key[i]]++] = i;
    mk_arena_release(arena, fill);
    *first_out = first;
    *list_out = list;
    return 1;
}

mk_result mk_normal_groups_build(const mk_raw_mesh *m, mk_grouping grouping, mk_arena *arena, mk_normal_groups *g,
                                 mk_error *err)
{
    uint32_t n = m->vertex_count;
    memset(g, 0, sizeof *g);
    g->group_of = mk_arena_array(arena, n ? n : 1, sizeof(uint32_t));
    if (!g->group_of) return mk_error_oom(err, "smoothing groups");
    /* The key of a vertex: its control point, or its welded position. */
    const uint32_t *key = m->control_points;
    uint32_t key_count = m->control_point_count;
    uint32_t *welded = NULL;
    if (grouping == MK_GROUP_BY_POSITION || !key || !key_count) {
        welded = mk_mesh_weld(m, arena, &key_count);
        if (!welded) return mk_error_oom(err, "smoothing groups");
        key = welded;
    }
    void *scratch = mk_arena_alloc(arena, mk_smoothing_groups_scratch_size(key_count, n));
    if (!scratch) return mk_error_oom(err, "smoothing groups");
    g->group_count = mk_smoothing_groups(key, key_count, m->normals, n, g->group_of, scratch);
    mk_arena_release(arena, scratch);
    if (welded) mk_arena_release(arena, welded);
    if (!mk_csr_build(arena, g->group_of, n, g->group_count, &g->group_vert_first, &g->group_verts))
        return mk_error_oom(err, "smoothing groups");
    /* group -> triangles: each triangle once per distinct corner group. */
    uint32_t *tri_group = mk_arena_array(arena, 3 * (size_t)m->triangle_count + 1, sizeof(uint32_t));
    uint32_t *tri_index = mk_arena_array(arena, 3 * (size_t)m->triangle_count + 1, sizeof(uint32_t));
    if (!tri_group || !tri_index) return mk_error_oom(err, "smoothing groups");
    uint32_t pairs = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        uint32_t g0 = g->group_of[m->triangles[3u * t]], g1 = g->group_of[m->triangles[3u * t + 1]],
                 g2 = g->group_of[m->triangles[3u * t + 2]];
        tri_group[pairs] = g0;
        tri_index[pairs++] = t;
        if (g1 != g0) {
            tri_group[pairs] = g1;
            tri_index[pairs++] = t;
        }
        if (g2 != g0 && g2 != g1) {
            tri_group[pairs] = g2;
            tri_index[pairs++] = t;
        }
    }
    uint32_t *slots;
    if (!mk_csr_build(arena, tri_group, pairs, g->group_count, &g->group_tri_first, &slots))
        return mk_error_oom(err, "smoothing groups");
    for (uint32_t k = 0; k < pairs; k++) slots[k] = tri_index[slots[k]];
    g->group_tris = slots;
    mk_arena_release(arena, tri_group);
    mk_arena_release(arena, tri_index);
    return MK_OK;
}

void mk_face_normal(const mk_raw_mesh *m, const double *positions, uint32_t t, double out[3])
{
    const uint32_t *tri = &m->triangles[3u * t];
    double p[3][3];
    for (int q = 0; q < 3; q++)
        for (int d = 0; d < 3; d++)
            p[q][d] = positions ? positions[3u * tri[q] + (uint32_t)d] : m->positions[3u * tri[q] + (uint32_t)d];
    mk_triangle_normal(p[0], p[1], p[2], out);
}

mk_result mk_normal_groups_smooth(const mk_normal_groups *g, const mk_raw_mesh *m, const double *positions,
                                  const unsigned char *flags, double *normals, mk_arena *arena, mk_error *err)
{
    double *face = mk_arena_array(arena, 3 * (size_t)m->triangle_count + 3, sizeof(double));
    if (!face) return mk_error_oom(err, "normals");
    for (uint32_t t = 0; t < m->triangle_count; t++) mk_face_normal(m, positions, t, &face[3u * t]);
    for (uint32_t grp = 0; grp < g->group_count; grp++) {
        double sum[3] = { 0, 0, 0 };
        for (uint32_t k = g->group_tri_first[grp]; k < g->group_tri_first[grp + 1]; k++)
            for (int d = 0; d < 3; d++) sum[d] += face[3u * g->group_tris[k] + (uint32_t)d];
        double len = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
        for (uint32_t i = g->group_vert_first[grp]; i < g->group_vert_first[grp + 1]; i++) {
            uint32_t v = g->group_verts[i];
            if (flags && !flags[v]) continue;
            for (int d = 0; d < 3; d++)
                normals[3u * v + (uint32_t)d] = len > 0      ? sum[d] / len
                                                : m->normals ? m->normals[3u * v + (uint32_t)d]
                                                             : 0.0;
        }
    }
    mk_arena_release(arena, face);
    return MK_OK;
}

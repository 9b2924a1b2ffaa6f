/* SPDX-License-Identifier: MIT */
/* Target normals computed from target positions: a target without normal data gets normals
 * computed at import from its positions with the base mesh's triangles and smoothing (hard
 * edges kept); docs/semantics.md, "Normals and tangents".
 *
 * Smoothing groups: render vertices with the same control point and the same base normal
 * share one computed normal, so vertices split only for UVs are smoothed together while
 * vertices split for a hard edge (different base normals) stay apart. A group's normal is
 * the normalized sum of the area-weighted face normals (cross products) of the triangles
 * around it.
 *
 * The delta stored is N_target - N_base with both computed by this same rule, so at weight 0
 * the authored base normals are untouched and at weight w the runtime gets
 * normalize(B + w (N_target - N_base)). Neighbours of moved vertices change normal without
 * moving, so the target's index set grows to include them (with zero position delta). When
 * the mesh has tangents, the base tangent is re-orthogonalized against the new normal
 * (Gram-Schmidt) and its change stored as the tangent delta.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>
#include "mesh_groups.h"
#include "parallel.h"

typedef struct topology {
    mk_normal_groups g;        /* smoothing groups (mesh_groups.h) */
    double *face;              /* per triangle: area-weighted base face normal (cross product) */
    float *base_normal;        /* per group, unit */
} topology;

/* Per-target work arrays, allocated once per mesh and reset after each target. */
typedef struct work {
    int32_t *moved;            /* per vertex: index in the target, or -1 */
    int32_t *group_slot;       /* per group: index in groups[], or -1 */
    int32_t *tri_slot;         /* per triangle: index in tris[], or -1 */
    uint8_t *vert_mark;        /* per vertex: joined the index set */
    uint32_t *groups, *tris, *extra;   /* affected groups, triangles; added vertices */
    double *deformed;          /* per affected triangle: its deformed face normal */
    float *group_new;          /* per affected group: its new unit normal */
} work;

static void face_normal(const float *p0, const float *p1, const float *p2, double out[3])
{
    /* In double, as mk_face_normal computes the base faces, so an unmoved triangle's normal
     * delta is exactly zero. */
    double e1[3] = { (double)p1[0] - p0[0], (double)p1[1] - p0[1], (double)p1[2] - p0[2] };
    double e2[3] = { (double)p2[0] - p0[0], (double)p2[1] - p0[1], (double)p2[2] - p0[2] };
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* Unit normal of group g: the sum of its triangles' face normals, taking a triangle's
 * deformed normal from `deformed` where tri_slot says it has one. */
static void group_normal(const topology *topo, uint32_t g, const int32_t *tri_slot, const double *deformed,
                         float out[3])
{
    double sum[3] = { 0, 0, 0 };
    for (uint32_t k = topo->g.group_tri_first[g]; k < topo->g.group_tri_first[g + 1]; k++) {
        uint32_t t = topo->g.group_tris[k];
        const double *n = tri_slot && tri_slot[t] >= 0 ? &deformed[3u * (uint32_t)tri_slot[t]] : &topo->face[3u * t];
        sum[0] += n[0]; sum[1] += n[1]; sum[2] += n[2];
    }
    double len = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    if (len < 1e-30) { out[0] = out[1] = out[2] = 0.0f; return; }
    out[0] = (float)(sum[0] / len); out[1] = (float)(sum[1] / len); out[2] = (float)(sum[2] / len);
}

static mk_result build_topology(mk_arena *arena, const mk_raw_mesh *m, topology *topo, mk_error *err)
{
    memset(topo, 0, sizeof *topo);
    mk_result r = mk_normal_groups_build(m, MK_GROUP_BY_CONTROL_POINT, arena, &topo->g, err);
    if (r != MK_OK) return r;
    topo->face = mk_arena_array(arena, (size_t)m->triangle_count * 3 + 3, sizeof(double));
    topo->base_normal = mk_arena_array(arena, (size_t)topo->g.group_count * 3 + 3, sizeof(float));
    if (!topo->face || !topo->base_normal) return mk_error_oom(err, "computing target normals");
    for (uint32_t t = 0; t < m->triangle_count; t++) mk_face_normal(m, NULL, t, &topo->face[3u * t]);
    for (uint32_t g = 0; g < topo->g.group_count; g++) group_normal(topo, g, NULL, NULL, &topo->base_normal[3u * g]);
    return MK_OK;
}

/* Tangent re-orthogonalized against normal n: normalize(t - n (n.t)); t unchanged if degenerate. */
static void orthogonal_tangent(const float *t, const float *n, float out[3])
{
    float d = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
    float v[3] = { t[0] - n[0] * d, t[1] - n[1] * d, t[2] - n[2] * d };
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len < 1e-12f) { out[0] = t[0]; out[1] = t[1]; out[2] = t[2]; return; }
    out[0] = v[0] / len; out[1] = v[1] / len; out[2] = v[2] / len;
}

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* One target, in time proportional to what it touches: the triangles around moved vertices
 * get deformed face normals, the groups around those triangles new normals, and the
 * target's index set grows by the vertices of those groups. New arrays come from `arena`;
 * with an `owner` (the arena of the target's arrays, shared by the workers through
 * owner_lock), the indices and positions grow in place instead (mk_arena_grow keeps their
 * pages) and the merge runs from the end, so it never overwrites an entry it has yet to read. */
static mk_result compute_target(mk_arena *arena, mk_arena *owner, mtx_t *owner_lock, const mk_raw_mesh *m,
                                const topology *topo, mk_raw_target *t, work *w, mk_error *err)
{
    for (uint32_t j = 0; j < t->count; j++) w->moved[t->indices[j]] = (int32_t)j;
    uint32_t tri_count = 0, group_count = 0, extra = 0;
    /* Triangles with a moved corner (found through the moved vertices' groups). */
    for (uint32_t j = 0; j < t->count; j++) {
        uint32_t g = topo->g.group_of[t->indices[j]];
        for (uint32_t k = topo->g.group_tri_first[g]; k < topo->g.group_tri_first[g + 1]; k++) {
            uint32_t tri = topo->g.group_tris[k];
            if (w->tri_slot[tri] >= 0) continue;
            const uint32_t *c = &m->triangles[3u * tri];
            if (w->moved[c[0]] < 0 && w->moved[c[1]] < 0 && w->moved[c[2]] < 0) continue;
            w->tri_slot[tri] = (int32_t)tri_count;
            w->tris[tri_count++] = tri;
            for (int q = 0; q < 3; q++) {
                uint32_t gc = topo->g.group_of[c[q]];
                if (w->group_slot[gc] < 0) { w->group_slot[gc] = (int32_t)group_count; w->groups[group_count++] = gc; }
            }
        }
    }
    double *deformed = w->deformed;
    float *group_new = w->group_new;
    for (uint32_t k = 0; k < tri_count; k++) {
        const uint32_t *c = &m->triangles[3u * w->tris[k]];
        float p[3][3];
        for (int q = 0; q < 3; q++)
            for (int d = 0; d < 3; d++) {
                p[q][d] = m->positions[3u * c[q] + (uint32_t)d];
                if (w->moved[c[q]] >= 0) p[q][d] += t->positions[3u * (uint32_t)w->moved[c[q]] + (uint32_t)d];
            }
        face_normal(p[0], p[1], p[2], &deformed[3u * k]);
    }
    for (uint32_t k = 0; k < group_count; k++) {
        group_normal(topo, w->groups[k], w->tri_slot, deformed, &group_new[3u * k]);
        uint32_t g = w->groups[k];
        for (uint32_t i = topo->g.group_vert_first[g]; i < topo->g.group_vert_first[g + 1]; i++) {
            uint32_t v = topo->g.group_verts[i];
            if (w->moved[v] < 0 && !w->vert_mark[v]) { w->vert_mark[v] = 1; w->extra[extra++] = v; }
        }
    }
    qsort(w->extra, extra, sizeof *w->extra, compare_u32);
    uint32_t total = t->count + extra;
    uint32_t *indices = NULL;
    float *positions = NULL;
    const uint32_t *old_indices = t->indices;
    const float *old_positions = t->positions;
    const int grows = owner && t->count;
    if (grows) {
        mtx_lock(owner_lock);
        indices = mk_arena_grow(owner, t->indices, ((size_t)total + 1) * sizeof(uint32_t));
        if (indices) t->indices = indices;  /* the old pointer is gone once grown */
        positions = indices ? mk_arena_grow(owner, t->positions, ((size_t)total * 3 + 3) * sizeof(float)) : NULL;
        if (positions) t->positions = positions;
        mtx_unlock(owner_lock);
        old_indices = indices;
        old_positions = positions;
    } else {
        indices = mk_arena_array(arena, (size_t)total + 1, sizeof(uint32_t));
        positions = mk_arena_array(arena, (size_t)total * 3 + 3, sizeof(float));
    }
    float *normals = mk_arena_array(arena, (size_t)total * 3 + 3, sizeof(float));
    /* Authored tangent deltas are kept (re-spread to the grown index set); otherwise the
     * base tangent is re-orthogonalized against the new normal. */
    const float *authored_tangents = t->tangents;
    float *tangents = m->tangents ? mk_arena_array(arena, (size_t)total * 3 + 3, sizeof(float)) : NULL;
    if (!indices || !positions || !normals || (m->tangents && !tangents)) return mk_error_oom(err, "computing target normals");
    /* The moved marks are cleared now: the merge may overwrite the moved indices. */
    for (uint32_t j = 0; j < t->count; j++) w->moved[old_indices[j]] = -1;
    /* Merge the sorted moved indices with the sorted added vertices, from the end. */
    uint32_t a = t->count, b = extra;
    for (uint32_t out = total; out-- > 0;) {
        int from_moved = b == 0 || (a > 0 && old_indices[a - 1] > w->extra[b - 1]);
        uint32_t v = from_moved ? old_indices[a - 1] : w->extra[b - 1];
        uint32_t src = from_moved ? --a : 0;
        if (!from_moved) b--;
        indices[out] = v;
        if (from_moved) memmove(&positions[3u * out], &old_positions[3u * src], 3 * sizeof(float));
        else memset(&positions[3u * out], 0, 3 * sizeof(float));
        uint32_t g = topo->g.group_of[v];
        const float *nb = &topo->base_normal[3u * g];
        const float *nt = w->group_slot[g] >= 0 ? &group_new[3u * (uint32_t)w->group_slot[g]] : nb;
        for (int d = 0; d < 3; d++) normals[3u * out + (uint32_t)d] = nt[d] - nb[d];
        if (tangents && authored_tangents) {
            for (int d = 0; d < 3; d++) tangents[3u * out + (uint32_t)d] = from_moved ? authored_tangents[3u * src + (uint32_t)d] : 0.0f;
        } else if (tangents) {
            const float *bt = &m->tangents[4u * v];
            float tb[3], tt[3];
            orthogonal_tangent(bt, nb, tb);
            orthogonal_tangent(bt, nt, tt);
            for (int d = 0; d < 3; d++) tangents[3u * out + (uint32_t)d] = tt[d] - tb[d];
        }
    }
    /* Reset the other work arrays for the next target. */
    for (uint32_t k = 0; k < tri_count; k++) w->tri_slot[w->tris[k]] = -1;
    for (uint32_t k = 0; k < group_count; k++) w->group_slot[w->groups[k]] = -1;
    for (uint32_t k = 0; k < extra; k++) w->vert_mark[w->extra[k]] = 0;
    /* The old arrays are grown or replaced; the replaced ones go back to the owner (without one
     * they may belong to the importer: left to the arena). */
    if (owner) {
        void *replaced[] = { grows ? NULL : t->indices, grows ? NULL : t->positions, t->normals, t->tangents };
        mk_arena_release_locked(owner, owner_lock, replaced, sizeof replaced / sizeof replaced[0]);
    }
    t->indices = indices;
    t->positions = positions;
    t->normals = normals;
    t->tangents = tangents;
    t->count = total;
    return MK_OK;
}

static mk_result alloc_work(mk_arena *arena, const mk_raw_mesh *m, const topology *topo, work *w, mk_error *err)
{
    w->moved = mk_arena_array(arena, m->vertex_count, sizeof(int32_t));
    w->vert_mark = mk_arena_array(arena, m->vertex_count, 1);
    w->extra = mk_arena_array(arena, m->vertex_count, sizeof(uint32_t));
    w->group_slot = mk_arena_array(arena, topo->g.group_count + 1u, sizeof(int32_t));
    w->groups = mk_arena_array(arena, topo->g.group_count + 1u, sizeof(uint32_t));
    w->tri_slot = mk_arena_array(arena, (size_t)m->triangle_count + 1, sizeof(int32_t));
    w->tris = mk_arena_array(arena, (size_t)m->triangle_count + 1, sizeof(uint32_t));
    /* Sized for a target that moves everything; only what the largest target uses is ever
     * touched (allocating them per target cost a fresh zeroed page for every page, every time). */
    w->deformed = mk_arena_array(arena, (size_t)m->triangle_count * 3 + 3, sizeof(double));
    w->group_new = mk_arena_array(arena, (size_t)topo->g.group_count * 3 + 3, sizeof(float));
    if (!w->moved || !w->vert_mark || !w->extra || !w->group_slot || !w->groups || !w->tri_slot || !w->tris ||
        !w->deformed || !w->group_new)
        return mk_error_oom(err, "computing target normals");
    for (uint32_t v = 0; v < m->vertex_count; v++) w->moved[v] = -1;
    for (uint32_t g = 0; g < topo->g.group_count; g++) w->group_slot[g] = -1;
    for (uint32_t t = 0; t < m->triangle_count; t++) w->tri_slot[t] = -1;
    return MK_OK;
}

static void release_work(mk_arena *arena, work *w)
{
    void *scratch[] = { w->moved, w->vert_mark, w->extra, w->group_slot, w->groups, w->tri_slot, w->tris, w->deformed,
                        w->group_new };
    for (size_t i = 0; i < sizeof scratch / sizeof scratch[0]; i++) mk_arena_release(arena, scratch[i]);
}

/* The targets of a mesh are independent: each worker thread has its own work arrays and
 * allocates the new target arrays from an arena of its own, adopted by the raw asset after
 * the loop. Every target's result is the same whichever thread computes it. */
typedef struct normals_loop {
    const mk_raw_mesh *m;
    const topology *topo;
    mk_raw_target **targets;
    mk_result *results;
    mk_error *errors;
    work *works;
    mk_arena *arenas;
    mk_arena *owner;           /* replaced arrays go back here at once (NULL: left alone) */
    mtx_t *owner_lock;         /* the owner arena is shared by the workers */
} normals_loop;

static void normals_item(void *user, uint32_t item, uint32_t worker)
{
    normals_loop *l = user;
    l->results[item] = compute_target(&l->arenas[worker], l->owner, l->owner_lock, l->m, l->topo, l->targets[item],
                                      &l->works[worker], &l->errors[item]);
}

static mk_result compute_normals(mk_raw_asset *raw, uint32_t mesh, int force, uint32_t threads, int release,
                                 mk_error *err);

mk_result mk_raw_compute_target_normals(mk_raw_asset *raw, uint32_t mesh, int force, uint32_t threads, mk_error *err)
{
    return compute_normals(raw, mesh, force, threads, 0, err);
}

mk_result mk_raw_compute_target_normals_replacing(mk_raw_asset *raw, uint32_t mesh, int force, uint32_t threads,
                                                  mk_error *err)
{
    return compute_normals(raw, mesh, force, threads, 1, err);
}

static mk_result compute_normals(mk_raw_asset *raw, uint32_t mesh, int force, uint32_t threads, int release,
                                 mk_error *err)
{
    if (mesh >= raw->mesh_count)
        return mk_error_set(err, MK_ERROR_OUT_OF_RANGE, UINT64_MAX, "compute normals: mesh %u does not exist", mesh);
    const mk_raw_mesh *m = &raw->meshes[mesh];
    if (!m->normals || m->triangle_count == 0) return MK_OK;  /* nothing to morph, or no surface */
    uint32_t count = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (raw->channels[c].mesh == mesh)
            for (uint32_t k = 0; k < raw->channels[c].target_count; k++)
                if (force || !raw->channels[c].targets[k].normals) count++;
    if (!count) return MK_OK;
    mk_arena *arena = &raw->arena;
    topology topo;
    mk_result r = build_topology(arena, m, &topo, err);
    if (r != MK_OK) return r;
    uint32_t workers = mk_parallel_threads(mk_arena_threads(arena, threads), count);
    normals_loop l = { m, &topo, NULL, NULL, NULL, NULL, NULL, NULL, NULL };
    l.targets = mk_arena_array(arena, count, sizeof *l.targets);
    l.results = mk_arena_array(arena, count, sizeof *l.results);
    l.errors = mk_arena_array(arena, count, sizeof *l.errors);
    l.works = mk_arena_array(arena, workers, sizeof *l.works);
    l.arenas = mk_arena_array(arena, workers, sizeof *l.arenas);
    if (!l.targets || !l.results || !l.errors || !l.works || !l.arenas) return mk_error_oom(err, "computing target normals");
    count = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (raw->channels[c].mesh == mesh)
            for (uint32_t k = 0; k < raw->channels[c].target_count; k++)
                if (force || !raw->channels[c].targets[k].normals) l.targets[count++] = &raw->channels[c].targets[k];
    uint32_t ready = 0;
    for (; ready < workers && r == MK_OK; ready++) {
        mk_arena_init(&l.arenas[ready], &arena->allocator);
        r = alloc_work(&l.arenas[ready], m, &topo, &l.works[ready], err);
    }
    mtx_t lock;
    if (r == MK_OK && release) {
        if (mtx_init(&lock, mtx_plain) != thrd_success) r = mk_error_oom(err, "computing target normals");
        l.owner = arena;
        l.owner_lock = &lock;
    }
    if (r == MK_OK) mk_parallel_for(count, workers, normals_item, &l);
    if (l.owner) mtx_destroy(&lock);
    for (uint32_t i = 0; i < count && r == MK_OK; i++)
        if (l.results[i] != MK_OK) {  /* the first failing target in asset order, whatever the threads */
            r = l.results[i];
            if (err) *err = l.errors[i];
        }
    for (uint32_t w = 0; w < ready; w++) {
        release_work(&l.arenas[w], &l.works[w]);
        mk_arena_adopt(arena, &l.arenas[w]);
    }
    /* Work and topology memory is only needed here: give it back (lowers the import peak). */
    void *scratch[] = { l.targets, l.results, l.errors, l.works, l.arenas, topo.g.group_of, topo.g.group_vert_first,
                        topo.g.group_verts, topo.g.group_tri_first, topo.g.group_tris, topo.face, topo.base_normal };
    for (size_t i = 0; i < sizeof scratch / sizeof scratch[0]; i++) mk_arena_release(arena, scratch[i]);
    return r;
}

/* SPDX-License-Identifier: MIT */
/* glTF 2.0 → raw model (docs/importing-gltf.md).
 *
 * Every (node, primitive) whose mesh has morph targets becomes one raw mesh: render vertex i is
 * glTF vertex i (identity control-point map), positions are mesh-local, `world` is the node's
 * rest world transform. glTF target k becomes channel k of that raw mesh with one target of full
 * weight 1, unless the channel sidecar groups several targets into one progressive channel.
 *
 * Targets without NORMAL: the spec (§3.7.2.2) says an attribute absent from a target keeps its
 * base value (delta 0), and the three.js reference frames of the corpus (MorphPrimitivesTest:
 * base NORMAL, POSITION-only targets) show exactly the base normals. We follow the spec and do
 * not synthesize normal deltas for glTF (docs/importing-gltf.md).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "mat4.h"
#include "blob_io.h"
#include "gltf_internal.h"

typedef struct importer {
    mk_gltf_doc doc;
    mk_gltf_reader reader;
    mk_arena *tmp;
    mk_raw_asset *out;
    const mk_import_options *options;
    const mk_gltf_sidecar *sidecar;
    double (*world)[16];          /* per node */
    mk_gltf_instance *instances;
    uint32_t instance_count, instance_cap;
} importer;

/* ---- transforms ---- */

/* Local matrix of a node: `matrix`, else T * R * S (spec §3.5.3), column-major. */
static void node_local(const mk_gltf_node *n, double m[16])
{
    if (n->has_matrix) { memcpy(m, n->matrix, 16 * sizeof(double)); return; }
    double x = n->rotation[0], y = n->rotation[1], z = n->rotation[2], w = n->rotation[3];
    double sx = n->scale[0], sy = n->scale[1], sz = n->scale[2];
    m[0] = (1 - 2 * (y * y + z * z)) * sx; m[1] = 2 * (x * y + z * w) * sx;       m[2] = 2 * (x * z - y * w) * sx;       m[3] = 0;
    m[4] = 2 * (x * y - z * w) * sy;       m[5] = (1 - 2 * (x * x + z * z)) * sy; m[6] = 2 * (y * z + x * w) * sy;       m[7] = 0;
    m[8] = 2 * (x * z + y * w) * sz;       m[9] = 2 * (y * z - x * w) * sz;       m[10] = (1 - 2 * (x * x + y * y)) * sz; m[11] = 0;
    m[12] = n->translation[0]; m[13] = n->translation[1]; m[14] = n->translation[2]; m[15] = 1;
}

/* World matrices of all nodes. The hierarchy must be a forest: a child index out of range, a
 * node with two parents or a cycle is an error naming the node. */
static mk_result compute_world(importer *im, mk_error *err)
{
    const mk_gltf_doc *d = &im->doc;
    uint32_t n = d->node_count;
    int32_t *parent = mk_arena_array(im->tmp, n + 1u, sizeof *parent);
    im->world = mk_arena_array(im->tmp, n + 1u, sizeof *im->world);
    if (!parent || !im->world) return mk_error_oom(err, "glTF node hierarchy");
    for (uint32_t i = 0; i < n; i++) parent[i] = -1;
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t k = 0; k < d->nodes[i].child_count; k++) {
            int32_t c = d->nodes[i].children[k];
            if (c < 0 || (uint32_t)c >= n)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "node %u: child %d out of range (%u nodes)", i, c, n);
            if (parent[c] != -1 || (uint32_t)c == i)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "node %d has more than one parent or is its own child", c);
            parent[c] = (int32_t)i;
        }
    for (uint32_t i = 0; i < n; i++) {
        double m[16];
        node_local(&d->nodes[i], m);
        uint32_t steps = 0;
        for (int32_t p = parent[i]; p >= 0; p = parent[p]) {
            if (++steps > n) return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "node %u: the node hierarchy has a cycle", i);
            double pm[16];
            node_local(&d->nodes[p], pm);
            mk_mat4d_multiply(m, pm, m);
        }
        memcpy(im->world[i], m, sizeof m);
    }
    return MK_OK;
}

/* ---- geometry ---- */

static const mk_gltf_draco_attribute *draco_attribute(const mk_gltf_primitive *p, const char *semantic)
{
    for (uint32_t i = 0; p->draco && i < p->draco_attribute_count; i++)
        if (strcmp(p->draco_attributes[i].semantic, semantic) == 0) return &p->draco_attributes[i];
    return NULL;
}

static int32_t find_attribute(const mk_gltf_attribute *a, uint32_t n, const char *semantic)
{
    for (uint32_t i = 0; i < n; i++)
        if (strcmp(a[i].semantic, semantic) == 0) return a[i].accessor;
    return -1;
}

/* A base attribute: decoded Draco data when the extension lists it, else the accessor. */
static mk_result base_attribute(importer *im, const mk_gltf_primitive *p, const char *semantic, int components,
                                const char *what, float **out, uint64_t *count, mk_error *err)
{
    const mk_gltf_draco_attribute *da = draco_attribute(p, semantic);
    if (da) {
        if ((int)da->components != components)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: Draco attribute has %u components, expected %d", what,
                                da->components, components);
        for (uint64_t i = 0; i < (uint64_t)p->draco_point_count * components; i++)
            if (!isfinite(da->values[i]))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "%s: Draco value %llu is NaN or infinite", what,
                                    (unsigned long long)i);
        *out = da->values;
        *count = p->draco_point_count;
        return MK_OK;
    }
    int32_t acc = find_attribute(p->attributes, p->attribute_count, semantic);
    if (acc < 0) { *out = NULL; *count = 0; return MK_OK; }
    return mk_gltf_read_floats(&im->reader, acc, components, what, out, count, err);
}

/* Triangles of a primitive from its index list (or 0..n-1) and mode (spec §3.7.2.1). */
static mk_result build_triangles(importer *im, const mk_gltf_primitive *p, uint32_t vertex_count, mk_raw_mesh *m,
                                 const char *what, mk_error *err)
{
    uint32_t *idx = NULL;
    uint64_t n = 0;
    mk_result r;
    if (p->draco) {
        idx = p->draco_indices;
        n = p->draco_index_count;
    } else if (p->indices >= 0) {
        if ((r = mk_gltf_read_indices(&im->reader, p->indices, what, &idx, &n, err)) != MK_OK) return r;
    } else {
        n = vertex_count;
        idx = mk_arena_array(im->tmp, (size_t)n + 1, sizeof *idx);
        if (!idx) return mk_error_oom(err, what);
        for (uint32_t i = 0; i < vertex_count; i++) idx[i] = i;
    }
    for (uint64_t i = 0; i < n; i++)
        if (idx[i] >= vertex_count)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: index %llu is vertex %u, past the %u vertices", what,
                                (unsigned long long)i, idx[i], vertex_count);
    uint64_t tris;
    switch (p->mode) {
    case 4: tris = n / 3; break;
    case 5: case 6: tris = n >= 3 ? n - 2 : 0; break;
    default:
        mk_raw_warn(im->out, "%s: mode %d has no triangles; imported as a point set", what, p->mode);
        return MK_OK;
    }
    if (p->mode == 4 && n % 3)
        mk_raw_warn(im->out, "%s: %llu indices is not a multiple of 3; the last %llu are ignored", what,
                    (unsigned long long)n, (unsigned long long)(n % 3));
    uint32_t *t = mk_arena_array(&im->out->arena, (size_t)tris * 3 + 1, sizeof *t);
    if (!t) return mk_error_oom(err, what);
    for (uint64_t i = 0; i < tris; i++) {
        uint32_t a, b, c;
        if (p->mode == 4) { a = idx[3 * i]; b = idx[3 * i + 1]; c = idx[3 * i + 2]; }
        else if (p->mode == 5) {   /* strip: odd triangles flip winding */
            if (i % 2 == 0) { a = idx[i]; b = idx[i + 1]; c = idx[i + 2]; }
            else { a = idx[i + 1]; b = idx[i]; c = idx[i + 2]; }
        } else { a = idx[0]; b = idx[i + 1]; c = idx[i + 2]; }   /* fan */
        t[3 * i] = a; t[3 * i + 1] = b; t[3 * i + 2] = c;
    }
    m->triangles = t;
    m->triangle_count = (uint32_t)tris;
    return MK_OK;
}

/* Dense deltas of one glTF target of a primitive. */
typedef struct dense_target {
    float *pos, *nrm, *tan;       /* 3 per vertex or NULL */
} dense_target;

static mk_result read_target(importer *im, const mk_gltf_primitive *p, uint32_t t, uint32_t vertex_count, int has_n,
                             int has_t, dense_target *dt, const char *where, mk_error *err)
{
    const mk_gltf_target *tg = &p->targets[t];
    memset(dt, 0, sizeof *dt);
    int warned = 0;
    for (uint32_t a = 0; a < tg->attribute_count; a++) {
        const char *sem = tg->attributes[a].semantic;
        float **dst = NULL;
        if (strcmp(sem, "POSITION") == 0) dst = &dt->pos;
        else if (strcmp(sem, "NORMAL") == 0) {
            if (!has_n) { mk_raw_warn(im->out, "%s target %u: NORMAL deltas ignored, the base has no normals", where, t); continue; }
            dst = &dt->nrm;
        } else if (strcmp(sem, "TANGENT") == 0) {
            if (!has_t || !has_n) { mk_raw_warn(im->out, "%s target %u: TANGENT deltas ignored, the base has no tangents/normals", where, t); continue; }
            dst = &dt->tan;
        } else {
            if (!warned) mk_raw_warn(im->out, "%s target %u: %s deltas are not supported and ignored", where, t, sem);
            warned = 1;
            continue;
        }
        char what[160];
        snprintf(what, sizeof what, "%s target %u %s", where, t, sem);
        uint64_t n;
        mk_result r = mk_gltf_read_floats(&im->reader, tg->attributes[a].accessor, 3, what, dst, &n, err);
        if (r != MK_OK) return r;
        if (n != vertex_count)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d has %llu elements, the primitive has %u vertices",
                                what, tg->attributes[a].accessor, (unsigned long long)n, vertex_count);
    }
    return MK_OK;
}

/* Sparse raw target from dense deltas: a vertex is stored when any of its deltas is nonzero. */
static mk_result make_sparse(importer *im, const dense_target *dt, uint32_t vertex_count, mk_raw_target *out, mk_error *err)
{
    uint32_t moved = 0;
    for (uint32_t v = 0; v < vertex_count; v++) {
        int nz = 0;
        for (int c = 0; c < 3; c++)
            nz |= (dt->pos && dt->pos[3 * v + c] != 0.0f) | (dt->nrm && dt->nrm[3 * v + c] != 0.0f)
                | (dt->tan && dt->tan[3 * v + c] != 0.0f);
        moved += nz ? 1u : 0u;
    }
    mk_arena *a = &im->out->arena;
    out->count = moved;
    out->indices = mk_arena_array(a, moved + 1u, sizeof(uint32_t));
    out->positions = mk_arena_array(a, 3u * moved + 1u, sizeof(float));
    out->normals = dt->nrm ? mk_arena_array(a, 3u * moved + 1u, sizeof(float)) : NULL;
    out->tangents = dt->tan ? mk_arena_array(a, 3u * moved + 1u, sizeof(float)) : NULL;
    if (!out->indices || !out->positions || (dt->nrm && !out->normals) || (dt->tan && !out->tangents))
        return mk_error_oom(err, "glTF target");
    uint32_t k = 0;
    for (uint32_t v = 0; v < vertex_count; v++) {
        int nz = 0;
        for (int c = 0; c < 3; c++)
            nz |= (dt->pos && dt->pos[3 * v + c] != 0.0f) | (dt->nrm && dt->nrm[3 * v + c] != 0.0f)
                | (dt->tan && dt->tan[3 * v + c] != 0.0f);
        if (!nz) continue;
        out->indices[k] = v;
        for (int c = 0; c < 3; c++) {
            out->positions[3 * k + c] = dt->pos ? dt->pos[3 * v + c] : 0.0f;
            if (dt->nrm) out->normals[3 * k + c] = dt->nrm[3 * v + c];
            if (dt->tan) out->tangents[3 * k + c] = dt->tan[3 * v + c];
        }
        k++;
    }
    return MK_OK;
}

static const mk_gltf_sidecar_mesh *sidecar_for(const importer *im, int32_t node, int32_t prim)
{
    if (!im->sidecar) return NULL;
    for (uint32_t i = 0; i < im->sidecar->mesh_count; i++)
        if (im->sidecar->meshes[i].node == node && im->sidecar->meshes[i].primitive == prim) return &im->sidecar->meshes[i];
    return NULL;
}

static const char *target_name(const importer *im, const mk_gltf_mesh *gm, const mk_gltf_primitive *p, uint32_t k, char *buf, size_t n)
{
    (void)im;
    if (gm->target_name_count == p->target_count && gm->target_names[k][0]) return gm->target_names[k];
    if (p->target_name_count == p->target_count && p->target_names[k][0]) return p->target_names[k];
    snprintf(buf, n, "target%u", k);
    return buf;
}

/* Channels of one instance: one per glTF target, or as the sidecar groups them. */
static mk_result make_channels(importer *im, mk_gltf_instance *inst, const mk_gltf_mesh *gm, const mk_gltf_primitive *p,
                               dense_target *dts, uint32_t vertex_count, const double *defaults, const char *where,
                               mk_error *err)
{
    uint32_t T = p->target_count;
    const mk_gltf_sidecar_mesh *sc = sidecar_for(im, inst->node, inst->primitive);
    uint8_t *used = mk_arena_array(im->tmp, T + 1u, 1);
    inst->target_channel = mk_arena_array(im->tmp, T + 1u, sizeof(uint32_t));
    inst->target_full_weight = mk_arena_array(im->tmp, T + 1u, sizeof(float));
    if (!used || !inst->target_channel || !inst->target_full_weight) return mk_error_oom(err, "glTF channels");
    for (uint32_t k = 0; k < T; k++) { inst->target_channel[k] = UINT32_MAX; inst->target_full_weight[k] = 1.0f; }
    mk_result r;
    char buf[32];

    if (sc) {
        for (uint32_t u = 0; u < sc->unused_count; u++) {
            if (sc->unused[u] >= T)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "sidecar: %s: unused target %u past its %u targets", where, sc->unused[u], T);
            used[sc->unused[u]] = 1;
        }
        for (uint32_t c = 0; c < sc->channel_count; c++) {
            const mk_gltf_sidecar_channel *sch = &sc->channels[c];
            mk_raw_channel *ch = mk_raw_add_channels(im->out, 1);
            if (!ch) return mk_error_oom(err, "glTF channels");
            uint32_t ci = im->out->channel_count - 1;
            ch->mesh = inst->raw_mesh;
            ch->name = mk_arena_strdup(&im->out->arena, sch->name);
            ch->origin = sch->origin ? mk_arena_strdup(&im->out->arena, sch->origin) : NULL;
            mk_raw_target *tg = mk_raw_add_targets(im->out, ch, sch->target_count);
            if (!ch->name || !tg) return mk_error_oom(err, "glTF channels");
            double dw = 0;
            for (uint32_t k = 0; k < sch->target_count; k++) {
                uint32_t g = sch->targets[k];
                if (g >= T || used[g])
                    return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "sidecar: %s channel '%s': target %u is past its %u targets or used twice",
                                        where, sch->name, g, T);
                used[g] = 1;
                inst->target_channel[g] = ci;
                inst->target_full_weight[g] = sch->full_weights[k];
                tg[k].full_weight = sch->full_weights[k];
                tg[k].name = mk_arena_strdup(&im->out->arena, sch->target_names && sch->target_names[k] ? sch->target_names[k]
                                                              : target_name(im, gm, p, g, buf, sizeof buf));
                if (!tg[k].name) return mk_error_oom(err, "glTF channels");
                if ((r = make_sparse(im, &dts[g], vertex_count, &tg[k], err)) != MK_OK) return r;
                /* The exporter writes hat-function weights u_k, so w = sum f_k u_k (docs). */
                dw += (double)sch->full_weights[k] * defaults[g];
            }
            ch->default_weight = (float)dw;
        }
    }
    for (uint32_t k = 0; k < T; k++) {
        if (used[k]) continue;
        mk_raw_channel *ch = mk_raw_add_channels(im->out, 1);
        if (!ch) return mk_error_oom(err, "glTF channels");
        uint32_t ci = im->out->channel_count - 1;
        ch->mesh = inst->raw_mesh;
        ch->name = mk_arena_strdup(&im->out->arena, target_name(im, gm, p, k, buf, sizeof buf));
        ch->default_weight = (float)defaults[k];
        mk_raw_target *tg = mk_raw_add_targets(im->out, ch, 1);
        if (!ch->name || !tg) return mk_error_oom(err, "glTF channels");
        tg->full_weight = 1.0f;
        tg->name = mk_arena_strdup(&im->out->arena, ch->name);
        if (!tg->name) return mk_error_oom(err, "glTF channels");
        if ((r = make_sparse(im, &dts[k], vertex_count, tg, err)) != MK_OK) return r;
        inst->target_channel[k] = ci;
    }
    return MK_OK;
}

static mk_result import_primitive(importer *im, uint32_t node_index, uint32_t prim_index, mk_error *err)
{
    const mk_gltf_doc *d = &im->doc;
    const mk_gltf_node *node = &d->nodes[node_index];
    const mk_gltf_mesh *gm = &d->meshes[node->mesh];
    const mk_gltf_primitive *p = &gm->primitives[prim_index];
    char where[96];
    snprintf(where, sizeof where, "node %u mesh %d primitive %u", node_index, node->mesh, prim_index);
    mk_result r;

    float *pos, *nrm, *tan;
    uint64_t np, nn, nt;
    char what[128];
    snprintf(what, sizeof what, "%s POSITION", where);
    if ((r = base_attribute(im, p, "POSITION", 3, what, &pos, &np, err)) != MK_OK) return r;
    if (!pos || np == 0) {
        mk_raw_warn(im->out, "%s '%s': no POSITION; primitive skipped", where, node->name ? node->name : "");
        return MK_OK;
    }
    if (np > (1u << 28)) return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: %llu vertices", where, (unsigned long long)np);
    uint32_t vc = (uint32_t)np;
    snprintf(what, sizeof what, "%s NORMAL", where);
    if ((r = base_attribute(im, p, "NORMAL", 3, what, &nrm, &nn, err)) != MK_OK) return r;
    snprintf(what, sizeof what, "%s TANGENT", where);
    if ((r = base_attribute(im, p, "TANGENT", 4, what, &tan, &nt, err)) != MK_OK) return r;
    if (nrm && nn != vc)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: NORMAL has %llu elements, POSITION %u", where, (unsigned long long)nn, vc);
    if (tan && nt != vc)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: TANGENT has %llu elements, POSITION %u", where, (unsigned long long)nt, vc);
    if (tan && !nrm) {
        mk_raw_warn(im->out, "%s: TANGENT without NORMAL ignored (spec §3.7.2.1)", where);
        tan = NULL;
    }

    uint32_t T = p->target_count;
    dense_target *dts = mk_arena_array(im->tmp, T + 1u, sizeof *dts);
    if (!dts) return mk_error_oom(err, where);
    for (uint32_t t = 0; t < T; t++)
        if ((r = read_target(im, p, t, vc, nrm != NULL, tan != NULL, &dts[t], where, err)) != MK_OK) return r;

    /* Default weights: node.weights, else mesh.weights, else 0 (spec §3.7.4). */
    double *defaults = mk_arena_array(im->tmp, T + 1u, sizeof(double));
    if (!defaults) return mk_error_oom(err, where);
    const double *w = NULL;
    uint32_t wn = 0;
    if (node->weight_count) { w = node->weights; wn = node->weight_count; }
    else if (gm->weight_count) { w = gm->weights; wn = gm->weight_count; }
    if (w && wn != T)
        mk_raw_warn(im->out, "%s: %u default weights for %u targets; missing ones are 0", where, wn, T);
    for (uint32_t k = 0; k < T && k < wn; k++) {
        if (!isfinite(w[k])) return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "%s: default weight %u is not finite", where, k);
        defaults[k] = w[k];
    }

    mk_raw_mesh *m = mk_raw_add_meshes(im->out, 1);
    if (!m) return mk_error_oom(err, where);
    uint32_t mi = im->out->mesh_count - 1;
    mk_arena *a = &im->out->arena;
    const mk_gltf_sidecar_mesh *sc = sidecar_for(im, (int32_t)node_index, (int32_t)prim_index);
    if (sc && sc->name) m->name = mk_arena_strdup(a, sc->name);
    else if (node->name[0]) m->name = mk_arena_strdup(a, node->name);
    else { char nb[32]; snprintf(nb, sizeof nb, "node%u", node_index); m->name = mk_arena_strdup(a, nb); }
    m->vertex_count = vc;
    m->positions = mk_arena_array(a, 3u * vc, sizeof(float));
    m->normals = nrm ? mk_arena_array(a, 3u * vc, sizeof(float)) : NULL;
    m->tangents = tan ? mk_arena_array(a, 4u * vc, sizeof(float)) : NULL;
    m->control_points = mk_arena_array(a, vc, sizeof(uint32_t));
    if (!m->name || !m->positions || (nrm && !m->normals) || (tan && !m->tangents) || !m->control_points)
        return mk_error_oom(err, where);
    memcpy(m->positions, pos, 3u * vc * sizeof(float));
    if (nrm) memcpy(m->normals, nrm, 3u * vc * sizeof(float));
    if (tan) memcpy(m->tangents, tan, 4u * vc * sizeof(float));
    m->control_point_count = vc;
    for (uint32_t v = 0; v < vc; v++) m->control_points[v] = v;
    if (sc && sc->control_point_map_count) {
        if (sc->control_point_map_count != vc)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "sidecar: %s: %u control points listed for %u vertices", where,
                                sc->control_point_map_count, vc);
        for (uint32_t v = 0; v < vc; v++) {
            if (sc->control_points[v] >= sc->control_point_count)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "sidecar: %s: control point %u out of range", where, sc->control_points[v]);
            m->control_points[v] = sc->control_points[v];
        }
        m->control_point_count = sc->control_point_count;
    }
    for (int k = 0; k < 16; k++) m->world[k] = (float)im->world[node_index][k];
    m->gltf_node = (int32_t)node_index;
    m->gltf_mesh = node->mesh;
    m->gltf_primitive = (int32_t)prim_index;
    m->stacking = MK_STACKING_ADDITIVE;  /* mk_import_finish applies the option */
    if (sc && sc->stacking) m->stacking = (mk_stacking)sc->stacking;
    if ((r = build_triangles(im, p, vc, m, where, err)) != MK_OK) return r;

    if (im->instance_count == im->instance_cap) {
        uint32_t cap = im->instance_cap ? im->instance_cap * 2 : 16;
        mk_gltf_instance *ni = mk_arena_realloc(im->tmp, im->instances, im->instance_cap * sizeof *ni, cap * sizeof *ni);
        if (!ni) return mk_error_oom(err, where);
        im->instances = ni;
        im->instance_cap = cap;
    }
    mk_gltf_instance *inst = &im->instances[im->instance_count++];
    memset(inst, 0, sizeof *inst);
    inst->node = (int32_t)node_index;
    inst->mesh = node->mesh;
    inst->primitive = (int32_t)prim_index;
    inst->raw_mesh = mi;
    inst->target_count = T;
    return make_channels(im, inst, gm, p, dts, vc, defaults, where, err);
}

/* Extensions that change how geometry must be read: refuse the file when one is required and
 * unknown, instead of importing garbage. Material/texture/light extensions do not matter here. */
static mk_result check_required(const mk_gltf_doc *d, mk_error *err)
{
    static const char *known[] = {"KHR_draco_mesh_compression", "KHR_mesh_quantization", "EXT_meshopt_compression"};
    static const char *harmless[] = {"KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_", "KHR_animation_pointer"};
    for (uint32_t i = 0; i < d->required_count; i++) {
        const char *e = d->extensions_required[i];
        int ok = 0;
        for (size_t k = 0; k < sizeof known / sizeof *known; k++) ok |= strcmp(e, known[k]) == 0;
        for (size_t k = 0; k < sizeof harmless / sizeof *harmless; k++) ok |= strncmp(e, harmless[k], strlen(harmless[k])) == 0;
        if (!ok) return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "glTF requires extension %s, which morphkit does not support", e);
    }
    return MK_OK;
}

static mk_result import_doc(importer *im, mk_error *err)
{
    const mk_gltf_doc *d = &im->doc;
    mk_result r;
    if ((r = check_required(d, err)) != MK_OK) return r;
    if ((r = mk_gltf_reader_init(&im->reader, d, im->tmp, err)) != MK_OK) return r;
    if ((r = compute_world(im, err)) != MK_OK) return r;
    snprintf(im->out->source_format, sizeof im->out->source_format, "gltf");
    snprintf(im->out->source_creator, sizeof im->out->source_creator, "%s", d->generator ? d->generator : "");

    for (uint32_t i = 0; i < d->node_count; i++) {
        const mk_gltf_node *n = &d->nodes[i];
        if (n->mesh < 0) continue;
        if ((uint32_t)n->mesh >= d->mesh_count)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "node %u: mesh %d out of range (%u meshes)", i, n->mesh, d->mesh_count);
        const mk_gltf_mesh *gm = &d->meshes[n->mesh];
        int keep_plain = im->options && im->options->keep_plain_meshes;
        if (gm->primitive_count == 0 || (gm->primitives[0].target_count == 0 && !keep_plain)) {
            /* Only morphing meshes are imported unless asked; say which node is left out, it
             * may be the one the user expected to see. */
            mk_raw_warn(im->out, "node %u '%s' mesh %d: no morph targets; skipped", i, n->name ? n->name : "", n->mesh);
            continue;
        }
        for (uint32_t p = 1; p < gm->primitive_count; p++)
            if (gm->primitives[p].target_count != gm->primitives[0].target_count)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "mesh %d: primitive %u has %u targets, primitive 0 has %u (they must agree)",
                                    n->mesh, p, gm->primitives[p].target_count, gm->primitives[0].target_count);
        for (uint32_t p = 0; p < gm->primitive_count; p++)
            if ((r = import_primitive(im, i, p, err)) != MK_OK) return r;
    }
    if (im->sidecar) {
        for (uint32_t s = 0; s < im->sidecar->mesh_count; s++) {
            int found = 0;
            for (uint32_t k = 0; k < im->instance_count; k++)
                found |= im->instances[k].node == im->sidecar->meshes[s].node && im->instances[k].primitive == im->sidecar->meshes[s].primitive;
            if (!found)
                mk_raw_warn(im->out, "sidecar: node %d primitive %d has no morph targets in the glTF; entry ignored",
                            im->sidecar->meshes[s].node, im->sidecar->meshes[s].primitive);
        }
    }
    if (im->instance_count == 0) mk_raw_warn(im->out, "glTF has no mesh with morph targets");
    if ((r = mk_gltf_import_animations(&im->reader, im->instances, im->instance_count, im->out, err)) != MK_OK) return r;
    if (im->sidecar && im->sidecar->clip_count) {
        /* glTF has no clip range: the sidecar keeps the original start and duration. */
        if (im->sidecar->clip_count != im->out->clip_count)
            mk_raw_warn(im->out, "sidecar: %u clips listed, the glTF has %u animations; clip ranges ignored",
                        im->sidecar->clip_count, im->out->clip_count);
        else
            for (uint32_t c = 0; c < im->out->clip_count; c++) {
                im->out->clips[c].start = im->sidecar->clips[c].start;
                im->out->clips[c].duration = im->sidecar->clips[c].duration;
            }
    }
    return MK_OK;
}

mk_result mk_import_gltf(const void *data, size_t size, const mk_import_options *options, mk_raw_asset *out,
                         mk_error *err)
{
    if (!out || (!data && size)) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "glTF import: invalid argument");
    mk_result r = mk_import_options_check(options, size, "glTF", err);
    if (r != MK_OK) return r;
    size_t limit = options && options->max_input_size ? options->max_input_size : MK_IMPORT_DEFAULT_MAX_INPUT;
    mk_arena tmp;
    mk_arena_init(&tmp, &out->arena.allocator);
    importer im;
    memset(&im, 0, sizeof im);
    im.tmp = &tmp;
    im.out = out;
    im.options = options;
    mk_gltf_sidecar sc;
    const char *sidecar_text = options ? options->channels_sidecar_text : NULL;
    size_t sidecar_size = options ? options->channels_sidecar_size : 0;
    if (options && options->channels_sidecar) {
        void *text;
        r = mk_read_file(&tmp, options->channels_sidecar, (size_t)1 << 28, &text, &sidecar_size, err);
        sidecar_text = text;
        if (r == MK_OK && options->file_read) options->file_read(options->file_read_user, options->channels_sidecar);
    }
    if (r == MK_OK && sidecar_text) {
        r = mk_gltf_sidecar_parse(&tmp, sidecar_text, sidecar_size, options->channels_sidecar ? options->channels_sidecar : "sidecar",
                                  &sc, err);
        im.sidecar = &sc;
    }
    if (r == MK_OK)
        r = mk_gltf_doc_load(&tmp, data, size, -1, options ? options->base_dir : NULL, limit, options ? options->file_read : NULL,
                             options ? options->file_read_user : NULL, &im.doc, err);
    mk_phase_log *phases = options ? options->phases : NULL;
    mk_phase_log_mark(phases, "parse");
    if (r == MK_OK) r = import_doc(&im, err);
    mk_phase_log_mark(phases, "convert");
    mk_gltf_doc_free(&im.doc);
    mk_arena_free_all(&tmp);
    mk_phase_log_mark(phases, "release parse data");
    return r != MK_OK ? r : mk_import_finish(out, options, err);
}

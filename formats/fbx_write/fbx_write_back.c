/* SPDX-License-Identifier: MIT */
/* FBX write-back (fbx_write_back.h): the baked channels of a raw asset as FBX 7 objects added to
 * the file it was imported from.
 *
 * Per baked channel (its `origin` is set), on the mesh's Geometry G:
 *   Deformer "BlendShape" B  -OO-> G   (the first one G has, else a new one)
 *   Deformer "BlendShapeChannel" C -OO-> B: DeformPercent (property and field) = default
 *       weight x 100, FullWeights = the targets' full weights x 100
 *   Geometry "Shape" S_k -OO-> C, one per target in full-weight order: Indexes (control
 *       points) and Vertices (their position deltas, geometry space). Normals are left out:
 *       readers compute them from the positions, as morphkit's bake does.
 * Per clip that animates only baked channels: AnimationStack (LocalStart/Stop) <-OO-
 * AnimationLayer <-OO- AnimationCurveNode "DeformPercent" -OP "DeformPercent"-> C, and an
 * AnimationCurve -OP "d|DeformPercent"-> the curve node, one key attribute per key.
 *
 * A baked target is on render vertices; the file holds one delta per control point. All render
 * vertices of a control point must carry the same delta (a pointwise deformer gives that; so do
 * the solvers, which weld the seams): within 1e-6 of the mesh's diagonal, else the write-back
 * refuses, naming the channel, the target and the control point.
 *
 * Blender reads a one-shape channel's FullWeights as per-vertex weights, and so do ufbx and
 * morphkit's importer for files whose Creator is Blender's exporter: in such files a one-target
 * channel gets FullWeights of 100 for every index, and a channel with in-betweens (or a full
 * weight other than 1) is refused, as those readers cannot play it. (Blender 3.4's importer
 * cannot read in-betweens from any file: it asserts that FullWeights has one value per index.)
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fbx_doc_write.h"
#include "fbx_write_back.h"

#define KTIME_PER_SECOND 46186158000.0  /* FBX 7.x */

typedef struct write_back {
    fbx_doc *doc;
    const mk_raw_asset *raw;
    mk_arena *a;               /* the scratch arena (doc->arena) */
    mk_error *err;
    int binary, blender;
    int64_t next_id;
    const fbx_node *objects, *connections;
    fbx_wnode **new_objects, **new_connections;
    uint32_t object_count, object_cap, connection_count, connection_cap;
    mk_fbx_write_back_report *report;
} write_back;

static mk_result oom(write_back *w) { return mk_error_oom(w->err, "FBX write-back"); }

static int push(write_back *w, fbx_wnode ***list, uint32_t *count, uint32_t *cap, fbx_wnode *node)
{
    if (!node) return 0;
    if (*count == *cap) {
        uint32_t want = *cap ? *cap * 2 : 64;
        fbx_wnode **grown = mk_arena_realloc(w->a, *list, *cap * sizeof **list, want * sizeof **list);
        if (!grown) return 0;
        *list = grown;
        *cap = want;
    }
    (*list)[(*count)++] = node;
    return 1;
}

/* A new object node "Type: id, name, subclass" in Objects. */
static fbx_wnode *new_object(write_back *w, const char *type, const char *cls, const char *name, const char *sub,
                             int64_t *id)
{
    fbx_wnode *n = fbx_wn_new(w->a, type);
    *id = w->next_id++;
    if (!n || !fbx_wn_long(w->a, n, *id) || !fbx_wn_object_name(w->a, n, w->binary, cls, name) ||
        !fbx_wn_string(w->a, n, sub, strlen(sub)) ||
        !push(w, &w->new_objects, &w->object_count, &w->object_cap, n))
        return NULL;
    return n;
}

/* C: "OO"|"OP", child, parent[, property]. */
static int connect(write_back *w, const char *kind, int64_t child, int64_t parent, const char *property)
{
    fbx_wnode *c = fbx_wn_new(w->a, "C");
    return c && fbx_wn_string(w->a, c, kind, 2) && fbx_wn_long(w->a, c, child) && fbx_wn_long(w->a, c, parent) &&
           (!property || fbx_wn_string(w->a, c, property, strlen(property))) &&
           push(w, &w->new_connections, &w->connection_count, &w->connection_cap, c);
}

/* A name the output can hold: ASCII files cannot quote '"' or a line break. (Binary object
 * names cannot hold the "\0\1" separator, and a C string has no NUL.) */
static mk_result check_name(write_back *w, const char *what, const char *name)
{
    for (const char *c = name; *c; c++) {
        if (!w->binary && (*c == '"' || *c == '\n' || *c == '\r'))
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX write-back: %s '%s' has a quote or line break, which an ASCII FBX name cannot hold",
                                what, name);
    }
    return MK_OK;
}

/* ---- the document ---- */

static int64_t node_id(const fbx_node *n)
{
    int64_t id = 0;
    return n->value_count && fbx_value_int(&n->values[0], &id) ? id : 0;
}

static int string_is(const fbx_value *v, const char *s)
{
    const char *d;
    uint32_t n;
    return fbx_value_string(v, &d, &n) && n == strlen(s) && memcmp(d, s, n) == 0;
}

/* The Objects child with that id, or NULL. */
static const fbx_node *object_by_id(const write_back *w, int64_t id)
{
    for (uint32_t i = 0; i < w->objects->child_count; i++)
        if (node_id(&w->objects->children[i]) == id) return &w->objects->children[i];
    return NULL;
}

/* The first BlendShape deformer connected to geometry `g` (0: none). */
static int64_t blend_shape_of(const write_back *w, int64_t g)
{
    for (uint32_t i = 0; i < w->connections->child_count; i++) {
        const fbx_node *c = &w->connections->children[i];
        int64_t src, dst;
        if (!fbx_name_is(c, "C") || c->value_count < 3 || !string_is(&c->values[0], "OO") ||
            !fbx_value_int(&c->values[1], &src) || !fbx_value_int(&c->values[2], &dst) || dst != g)
            continue;
        const fbx_node *o = object_by_id(w, src);
        if (o && fbx_name_is(o, "Deformer") && o->value_count >= 3 && string_is(&o->values[2], "BlendShape")) return src;
    }
    return 0;
}

static mk_result find_document(write_back *w)
{
    fbx_doc *doc = w->doc;
    int64_t version = doc->version;
    const fbx_node *header = fbx_child(&doc->root, "FBXHeaderExtension");
    int64_t stated;
    if (header && fbx_child_int(header, "FBXVersion", &stated)) version = stated;
    if (version < 7200)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX write-back: this is an FBX %lld file; files before 7.2 keep shapes inside the geometry, "
                            "and write-back adds FBX 7.2+ blend shape deformers (save the file as FBX 2012 or later)",
                            (long long)version);
    w->objects = fbx_child(&doc->root, "Objects");
    w->connections = fbx_child(&doc->root, "Connections");
    if (!w->objects || !w->connections || !w->objects->child_count || !w->connections->child_count)
        return mk_error_set(w->err, MK_ERROR_PARSE, UINT64_MAX, "FBX write-back: the file has no Objects or no Connections");
    int64_t top = 0;
    for (uint32_t i = 0; i < w->objects->child_count; i++) {
        int64_t id = node_id(&w->objects->children[i]);
        if (id > top) top = id;
    }
    if (top > INT64_MAX - 1000000)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "FBX write-back: object ids leave no room for new ones");
    w->next_id = top + 1;
    return MK_OK;
}

/* ---- channels ---- */

static double mesh_diagonal(const mk_raw_mesh *m)
{
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            float x = m->positions[3 * v + k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
    double d = 0;
    for (int k = 0; k < 3 && m->vertex_count; k++) d += ((double)hi[k] - lo[k]) * ((double)hi[k] - lo[k]);
    return sqrt(d);
}

/* The target's deltas on control points: indexes (increasing) and 3 doubles each. */
static mk_result control_point_deltas(write_back *w, const mk_raw_mesh *m, const uint32_t *render_count,
                                      const mk_raw_channel *ch, uint32_t t, double tolerance, int32_t **indexes,
                                      double **deltas, uint32_t *count)
{
    const mk_raw_target *tg = &ch->targets[t];
    const uint32_t cps = m->control_point_count;
    double *sum = mk_arena_array(w->a, cps ? cps : 1, 3 * sizeof(double));
    uint32_t *seen = mk_arena_array(w->a, cps ? cps : 1, sizeof(uint32_t));
    if (!sum || !seen) return oom(w);
    for (uint32_t e = 0; e < tg->count; e++) {
        uint32_t v = tg->indices[e], cp = m->control_points[v];
        const float *d = tg->positions + 3 * (size_t)e;
        if (seen[cp]++ == 0) {
            for (int k = 0; k < 3; k++) sum[3 * cp + k] = d[k];
            continue;
        }
        for (int k = 0; k < 3; k++)
            if (fabs(sum[3 * cp + k] - d[k]) > tolerance)
                return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "FBX write-back: channel '%s' target %u moves the render vertices of control point %u "
                                    "of mesh '%s' differently (%g apart); the file holds one delta per control point",
                                    ch->name, t, cp, m->name, fabs(sum[3 * cp + k] - d[k]));
    }
    uint32_t n = 0;
    for (uint32_t cp = 0; cp < cps; cp++) {
        if (!seen[cp]) continue;
        double size = fabs(sum[3 * cp]) + fabs(sum[3 * cp + 1]) + fabs(sum[3 * cp + 2]);
        if (seen[cp] < render_count[cp] && size > tolerance)
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX write-back: channel '%s' target %u moves some render vertices of control point %u of "
                                "mesh '%s' and not others; the file holds one delta per control point",
                                ch->name, t, cp, m->name);
        if (size > 0) n++;
    }
    *indexes = mk_arena_array(w->a, n ? n : 1, sizeof(int32_t));
    *deltas = mk_arena_array(w->a, n ? n : 1, 3 * sizeof(double));
    if (!*indexes || !*deltas) return oom(w);
    n = 0;
    for (uint32_t cp = 0; cp < cps; cp++) {
        if (!seen[cp] || fabs(sum[3 * cp]) + fabs(sum[3 * cp + 1]) + fabs(sum[3 * cp + 2]) == 0) continue;
        (*indexes)[n] = (int32_t)cp;
        memcpy(*deltas + 3 * (size_t)n, sum + 3 * (size_t)cp, 3 * sizeof(double));
        n++;
    }
    *count = n;
    mk_arena_release(w->a, sum);
    mk_arena_release(w->a, seen);
    return MK_OK;
}

static mk_result add_channel(write_back *w, const mk_raw_mesh *m, const uint32_t *render_count, double tolerance,
                             const mk_raw_channel *ch, int64_t blend_shape, int64_t *channel_id)
{
    mk_result r = check_name(w, "channel", ch->name);
    if (r != MK_OK) return r;
    if (w->blender && ch->target_count > 1)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX write-back: channel '%s' has %u in-between targets, but this file comes from Blender's "
                            "exporter, and readers take the FullWeights of such files as per-vertex weights (ufbx and "
                            "Blender would play every in-between at full weight); bake it with \"inbetweens\": 1 (one target), or "
                            "write a .morph or glTF",
                            ch->name, ch->target_count);
    fbx_wnode *c = new_object(w, "Deformer", "SubDeformer", ch->name, "BlendShapeChannel", channel_id);
    if (!c || !fbx_wn_int(w->a, fbx_wn_child(w->a, c, "Version"), 100)) return oom(w);
    fbx_wnode *props = fbx_wn_child(w->a, c, "Properties70");
    if (!props || !fbx_wn_prop(w->a, props, "DeformPercent", "Number", "", "A", (fbx_wvalue){ .type = 'D', .u.d = 100.0 * ch->default_weight }) ||
        !fbx_wn_double(w->a, fbx_wn_child(w->a, c, "DeformPercent"), 100.0 * ch->default_weight))
        return oom(w);
    if (!connect(w, "OO", *channel_id, blend_shape, NULL)) return oom(w);
    double *full = mk_arena_array(w->a, ch->target_count ? ch->target_count : 1, sizeof(double));
    if (!full) return oom(w);
    uint32_t full_count = ch->target_count;
    for (uint32_t t = 0; t < ch->target_count; t++) {
        const mk_raw_target *tg = &ch->targets[t];
        int32_t *indexes = NULL;
        double *deltas = NULL;
        uint32_t n = 0;
        if ((r = control_point_deltas(w, m, render_count, ch, t, tolerance, &indexes, &deltas, &n)) != MK_OK) return r;
        char fallback[160];
        snprintf(fallback, sizeof fallback, "%s_%u", ch->name, t);
        const char *name = tg->name && *tg->name ? tg->name : fallback;
        if ((r = check_name(w, "target", name)) != MK_OK) return r;
        int64_t shape_id;
        fbx_wnode *s = new_object(w, "Geometry", "Geometry", name, "Shape", &shape_id);
        if (!s || !fbx_wn_int(w->a, fbx_wn_child(w->a, s, "Version"), 100) ||
            !fbx_wn_array(w->a, s, "Indexes", 'i', indexes, n) || !fbx_wn_array(w->a, s, "Vertices", 'd', deltas, 3 * n) ||
            !connect(w, "OO", shape_id, *channel_id, NULL))
            return oom(w);
        full[t] = 100.0 * tg->full_weight;
        if (w->blender && ch->target_count == 1) {
            if (tg->full_weight != 1.0f)
                return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "FBX write-back: channel '%s' has one target at full weight %g; this file comes from "
                                    "Blender, whose FullWeights of a one-shape channel are per-vertex weights",
                                    ch->name, (double)tg->full_weight);
            full_count = n ? n : 1;
            full = mk_arena_array(w->a, full_count, sizeof(double));
            if (!full) return oom(w);
            for (uint32_t k = 0; k < full_count; k++) full[k] = 100.0;
            w->report->blender_weights++;
        }
        w->report->shapes++;
    }
    if (!fbx_wn_array(w->a, c, "FullWeights", 'd', full, full_count)) return oom(w);
    w->report->channels++;
    return MK_OK;
}

/* ---- clips ---- */

static int is_baked(const mk_raw_channel *ch) { return ch->origin && *ch->origin; }

static mk_result add_curve(write_back *w, const mk_raw_track *track, int64_t layer, int64_t channel_id)
{
    const uint32_t n = track->key_count;
    int64_t node_id_, curve_id;
    fbx_wnode *node = new_object(w, "AnimationCurveNode", "AnimCurveNode", "DeformPercent", "", &node_id_);
    fbx_wnode *props = node ? fbx_wn_child(w->a, node, "Properties70") : NULL;
    if (!props || !fbx_wn_prop(w->a, props, "d|DeformPercent", "Number", "", "A",
                               (fbx_wvalue){ .type = 'D', .u.d = 100.0 * track->keys[0].value }))
        return oom(w);
    fbx_wnode *curve = new_object(w, "AnimationCurve", "AnimCurve", "", "", &curve_id);
    int64_t *times = mk_arena_array(w->a, n, sizeof(int64_t));
    float *values = mk_arena_array(w->a, n, sizeof(float));
    int32_t *flags = mk_arena_array(w->a, n, sizeof(int32_t)), *refs = mk_arena_array(w->a, n, sizeof(int32_t));
    float *data = mk_arena_array(w->a, n, 4 * sizeof(float));
    if (!curve || !times || !values || !flags || !refs || !data) return oom(w);
    for (uint32_t i = 0; i < n; i++) {
        const mk_key *k = &track->keys[i];
        times[i] = (int64_t)llround((double)k->time * KTIME_PER_SECOND);
        values[i] = 100.0f * k->value;
        refs[i] = 1;
        uint32_t f;
        switch (k->interp) {
        case MK_INTERP_CONSTANT: f = 0x2; break;
        case MK_INTERP_CONSTANT_NEXT: f = 0x102; break;
        case MK_INTERP_LINEAR: f = 0x4; break;
        default: f = 0x8 | 0x400; break;  /* cubic, user tangents */
        }
        float next_left_slope = i + 1 < n ? track->keys[i + 1].left_slope : 0.0f;
        float next_left_weight = i + 1 < n ? track->keys[i + 1].left_weight : 1.0f / 3.0f;
        uint32_t packed = 0;
        if (k->interp == MK_INTERP_CUBIC && (fabsf(k->right_weight - 1.0f / 3.0f) > 1e-6f ||
                                             fabsf(next_left_weight - 1.0f / 3.0f) > 1e-6f)) {
            f |= 0x1000000u | 0x2000000u;
            packed = (uint32_t)lrintf(k->right_weight * 10000.0f) | ((uint32_t)lrintf(next_left_weight * 10000.0f) << 16);
        }
        flags[i] = (int32_t)f;
        data[4 * i] = k->interp == MK_INTERP_CUBIC ? 100.0f * k->right_slope : 0.0f;
        data[4 * i + 1] = k->interp == MK_INTERP_CUBIC ? 100.0f * next_left_slope : 0.0f;
        memcpy(&data[4 * i + 2], &packed, 4);
        data[4 * i + 3] = 0.0f;
    }
    /* ASCII files from 7.2 on spell the attribute floats as their int32 bit patterns. */
    int32_t *bits = mk_arena_array(w->a, n, 4 * sizeof(int32_t));
    if (!bits) return oom(w);
    memcpy(bits, data, 4 * (size_t)n * sizeof(float));
    if (!fbx_wn_double(w->a, fbx_wn_child(w->a, curve, "Default"), 100.0 * track->keys[0].value) ||
        !fbx_wn_int(w->a, fbx_wn_child(w->a, curve, "KeyVer"), 4009) ||
        !fbx_wn_array(w->a, curve, "KeyTime", 'l', times, n) || !fbx_wn_array(w->a, curve, "KeyValueFloat", 'f', values, n) ||
        !fbx_wn_array(w->a, curve, "KeyAttrFlags", 'i', flags, n) ||
        (w->binary ? !fbx_wn_array(w->a, curve, "KeyAttrDataFloat", 'f', data, 4 * n)
                    : !fbx_wn_array(w->a, curve, "KeyAttrDataFloat", 'i', bits, 4 * n)) ||
        !fbx_wn_array(w->a, curve, "KeyAttrRefCount", 'i', refs, n))
        return oom(w);
    if (!connect(w, "OO", node_id_, layer, NULL) || !connect(w, "OP", node_id_, channel_id, "DeformPercent") ||
        !connect(w, "OP", curve_id, node_id_, "d|DeformPercent"))
        return oom(w);
    return MK_OK;
}

static mk_result add_clip(write_back *w, const mk_raw_clip *clip, const int64_t *channel_ids)
{
    mk_result r = check_name(w, "clip", clip->name ? clip->name : "");
    if (r != MK_OK) return r;
    int64_t stack, layer;
    fbx_wnode *s = new_object(w, "AnimationStack", "AnimStack", clip->name ? clip->name : "", "", &stack);
    fbx_wnode *props = s ? fbx_wn_child(w->a, s, "Properties70") : NULL;
    const int64_t start = (int64_t)llround((double)clip->start * KTIME_PER_SECOND);
    const int64_t stop = (int64_t)llround(((double)clip->start + clip->duration) * KTIME_PER_SECOND);
    static const char *const names[4] = { "LocalStart", "LocalStop", "ReferenceStart", "ReferenceStop" };
    for (int i = 0; i < 4; i++)
        if (!props || !fbx_wn_prop(w->a, props, names[i], "KTime", "Time", "", (fbx_wvalue){ .type = 'L', .u.i = i & 1 ? stop : start }))
            return oom(w);
    if (!new_object(w, "AnimationLayer", "AnimLayer", "BaseLayer", "", &layer) || !connect(w, "OO", layer, stack, NULL))
        return oom(w);
    for (uint32_t t = 0; t < clip->track_count; t++) {
        const mk_raw_track *track = &clip->tracks[t];
        if (!track->key_count) continue;
        if ((r = add_curve(w, track, layer, channel_ids[track->channel])) != MK_OK) return r;
    }
    w->report->clips++;
    return MK_OK;
}

/* ---- the whole ---- */

static mk_result add_all(write_back *w)
{
    const mk_raw_asset *raw = w->raw;
    int64_t *channel_ids = mk_arena_array(w->a, raw->channel_count ? raw->channel_count : 1, sizeof(int64_t));
    if (!channel_ids) return oom(w);
    for (uint32_t mi = 0; mi < raw->mesh_count; mi++) {
        const mk_raw_mesh *m = &raw->meshes[mi];
        uint32_t baked = 0;
        for (uint32_t c = 0; c < raw->channel_count; c++) baked += raw->channels[c].mesh == mi && is_baked(&raw->channels[c]);
        if (!baked) continue;
        if (!m->fbx_geometry)
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX write-back: mesh '%s' has no FBX geometry of its own to write to", m->name);
        for (uint32_t other = 0; other < raw->mesh_count; other++)
            if (other != mi && raw->meshes[other].fbx_geometry == m->fbx_geometry)
                return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "FBX write-back: the geometry of mesh '%s' is also used by model '%s'; a channel baked "
                                    "on one would deform both",
                                    m->name, raw->meshes[other].name);
        const fbx_node *g = object_by_id(w, m->fbx_geometry);
        if (!g || !fbx_name_is(g, "Geometry"))
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX write-back: mesh '%s': geometry %lld is not in this file's Objects (was the asset "
                                "imported from this file?)", m->name, (long long)m->fbx_geometry);
        if (!m->control_points || !m->control_point_count) return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "FBX write-back: mesh '%s' has no control point map", m->name);
        uint32_t *render_count = mk_arena_array(w->a, m->control_point_count, sizeof(uint32_t));
        if (!render_count) return oom(w);
        for (uint32_t v = 0; v < m->vertex_count; v++) {
            if (m->control_points[v] >= m->control_point_count)
                return mk_error_set(w->err, MK_ERROR_CORRUPT, UINT64_MAX, "FBX write-back: mesh '%s' vertex %u maps to "
                                    "control point %u of %u", m->name, v, m->control_points[v], m->control_point_count);
            render_count[m->control_points[v]]++;
        }
        int64_t blend = blend_shape_of(w, m->fbx_geometry);
        if (!blend) {
            mk_result r = check_name(w, "mesh", m->name);
            if (r != MK_OK) return r;
            fbx_wnode *b = new_object(w, "Deformer", "Deformer", m->name, "BlendShape", &blend);
            if (!b || !fbx_wn_int(w->a, fbx_wn_child(w->a, b, "Version"), 100) || !connect(w, "OO", blend, m->fbx_geometry, NULL))
                return oom(w);
            w->report->blend_shapes++;
        }
        const double tolerance = 1e-6 * fmax(mesh_diagonal(m), 1e-30);
        for (uint32_t c = 0; c < raw->channel_count; c++) {
            if (raw->channels[c].mesh != mi || !is_baked(&raw->channels[c])) continue;
            mk_result r = add_channel(w, m, render_count, tolerance, &raw->channels[c], blend, &channel_ids[c]);
            if (r != MK_OK) return r;
        }
        w->report->meshes++;
    }
    for (uint32_t k = 0; k < raw->clip_count; k++) {
        const mk_raw_clip *clip = &raw->clips[k];
        uint32_t baked = 0;
        for (uint32_t t = 0; t < clip->track_count; t++)
            baked += clip->tracks[t].channel < raw->channel_count && is_baked(&raw->channels[clip->tracks[t].channel]);
        if (!baked || baked != clip->track_count) continue;  /* the file's own clips are in it already */
        mk_result r = add_clip(w, clip, channel_ids);
        if (r != MK_OK) return r;
    }
    return MK_OK;
}

mk_result mk_fbx_write_back(const void *input, size_t input_size, const mk_raw_asset *raw, mk_arena *arena,
                            void **out, size_t *out_size, mk_fbx_write_back_report *report, mk_error *err)
{
    mk_fbx_write_back_report local_report;
    mk_error local_err;
    if (!report) report = &local_report;
    if (!err) err = &local_err;
    memset(report, 0, sizeof *report);
    if (!input || !raw || !arena || !out || !out_size)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_fbx_write_back: NULL argument");
    mk_arena scratch;
    mk_arena_init(&scratch, &arena->allocator);
    fbx_doc doc;
    mk_result r = fbx_doc_parse(&doc, &scratch, input, input_size, err);
    const char *tag = "Blender (stable FBX IO)";
    write_back w = { .doc = &doc, .raw = raw, .a = &scratch, .err = err, .binary = doc.binary,
                     .blender = doc.binary && strncmp(raw->source_creator, tag, strlen(tag)) == 0, .report = report };
    if (r == MK_OK) r = find_document(&w);
    if (r == MK_OK) r = add_all(&w);
    fbx_bytes bytes = { .arena = arena };
    if (r == MK_OK) {
        fbx_insertion ins[2] = { { w.objects, w.new_objects, w.object_count },
                                 { w.connections, w.new_connections, w.connection_count } };
        r = fbx_doc_write(&doc, ins, 2, &bytes);
    }
    if (r == MK_OK) {
        *out = bytes.data;
        *out_size = bytes.size;
    } else {
        mk_arena_release(arena, bytes.data);
        memset(report, 0, sizeof *report);
    }
    fbx_doc_free(&doc);
    mk_arena_free_all(&scratch);
    return r;
}

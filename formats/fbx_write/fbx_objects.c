/* SPDX-License-Identifier: MIT */
/* FBX 7 objects for channels and clips (fbx_objects.h), shared by the write-back and the export.
 *
 * Per channel, on a mesh's BlendShape deformer B:
 *   Deformer "BlendShapeChannel" C -OO-> B: DeformPercent (property and field) = default
 *       weight x 100, FullWeights = the targets' full weights x 100
 *   Geometry "Shape" S_k -OO-> C, one per target in full-weight order: Indexes (control
 *       points) and Vertices (their position deltas, geometry space). Normals are left out:
 *       readers compute them from the positions (morphkit's importer, ufbx, Blender, engines).
 * Per clip: AnimationStack (LocalStart/Stop) <-OO- AnimationLayer <-OO- AnimationCurveNode
 * "DeformPercent" -OP "DeformPercent"-> C, and an AnimationCurve -OP "d|DeformPercent"-> the
 * curve node, one key attribute per key.
 *
 * A target is on render vertices; the file holds one delta per control point. All render
 * vertices of a control point must carry the same delta (a pointwise deformer gives that; so do
 * the solvers, which weld the seams; so does every import): within 1e-6 of the mesh's diagonal,
 * else the writer refuses, naming the channel, the target and the control point.
 *
 * Blender reads a one-shape channel's FullWeights as per-vertex weights, and so do ufbx and
 * morphkit's importer for files whose Creator is Blender's exporter: in such files a one-target
 * channel gets FullWeights of 100 for every index, and a channel with in-betweens (or a full
 * weight other than 1) is refused, as those readers cannot play it. (Blender 3.4's importer
 * cannot read in-betweens from any file: it asserts that FullWeights has one value per index.)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fbx_anim.h"
#include "fbx_objects.h"

/* The longest time an int64 KTime holds at the file's tick rate, with a margin. */
static double max_seconds(const fbx_objects *w) { return 9.0e18 / w->ticks; }

mk_result fbx_objects_oom(fbx_objects *w) { return mk_error_oom(w->err, "FBX objects"); }

static int push(fbx_objects *w, fbx_wnode ***list, uint32_t *count, uint32_t *cap, fbx_wnode *node)
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
fbx_wnode *fbx_object_new(fbx_objects *w, const char *type, const char *cls, const char *name, const char *sub,
                             int64_t *id)
{
    fbx_wnode *n = fbx_wn_new(w->a, type);
    *id = w->next_id++;
    if (!n || !fbx_wn_long(w->a, n, *id) || !fbx_wn_object_name(w->a, n, w->binary, cls, name) ||
        !fbx_wn_string(w->a, n, sub, strlen(sub)) ||
        !push(w, &w->objects, &w->object_count, &w->object_cap, n))
        return NULL;
    return n;
}

/* C: "OO"|"OP", child, parent[, property]. */
int fbx_object_connect(fbx_objects *w, const char *kind, int64_t child, int64_t parent, const char *property)
{
    fbx_wnode *c = fbx_wn_new(w->a, "C");
    return c && fbx_wn_string(w->a, c, kind, 2) && fbx_wn_long(w->a, c, child) && fbx_wn_long(w->a, c, parent) &&
           (!property || fbx_wn_string(w->a, c, property, strlen(property))) &&
           push(w, &w->connections, &w->connection_count, &w->connection_cap, c);
}

/* A name the output can hold: ASCII files cannot quote '"' or a line break. (Binary object
 * names cannot hold the "\0\1" separator, and a C string has no NUL.) */
mk_result fbx_object_check_name(fbx_objects *w, const char *what, const char *name)
{
    for (const char *c = name; *c; c++) {
        if (!w->binary && (*c == '"' || *c == '\n' || *c == '\r'))
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX: %s '%s' has a quote or line break, which an ASCII FBX name cannot hold",
                                what, name);
    }
    return MK_OK;
}

/* ---- channels ---- */

mk_result fbx_objects_mesh(fbx_objects *w, const mk_raw_mesh *m, uint32_t **render_count, double *tolerance)
{
    if (!m->control_points || !m->control_point_count)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "FBX: mesh '%s' has no control point map", m->name);
    uint32_t *count = mk_arena_array(w->a, m->control_point_count, sizeof(uint32_t));
    if (!count) return fbx_objects_oom(w);
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        if (m->control_points[v] >= m->control_point_count)
            return mk_error_set(w->err, MK_ERROR_CORRUPT, UINT64_MAX, "FBX: mesh '%s' vertex %u maps to control point %u of %u",
                                m->name, v, m->control_points[v], m->control_point_count);
        count[m->control_points[v]]++;
    }
    *render_count = count;
    *tolerance = 1e-6 * fmax((double)mk_raw_mesh_diagonal(m), 1e-30);
    return MK_OK;
}

/* The target's deltas on control points: indexes (increasing) and 3 doubles each. */
mk_result fbx_objects_target(fbx_objects *w, const mk_raw_mesh *m, const uint32_t *render_count,
                                      const mk_raw_channel *ch, uint32_t t, double tolerance, int32_t **indexes,
                                      double **deltas, uint32_t *count)
{
    const mk_raw_target *tg = &ch->targets[t];
    const uint32_t cps = m->control_point_count;
    double *sum = mk_arena_array(w->a, cps ? cps : 1, 3 * sizeof(double));
    uint32_t *seen = mk_arena_array(w->a, cps ? cps : 1, sizeof(uint32_t));
    if (!sum || !seen) return fbx_objects_oom(w);
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
                                    "FBX: channel '%s' target %u moves the render vertices of control point %u "
                                    "of mesh '%s' differently (%g apart); the file holds one delta per control point",
                                    ch->name, t, cp, m->name, fabs(sum[3 * cp + k] - d[k]));
    }
    /* Control points that moved: seen[] keeps them (zero deltas are dropped). */
    uint32_t n = 0;
    for (uint32_t cp = 0; cp < cps; cp++) {
        if (!seen[cp]) continue;
        double size = fabs(sum[3 * cp]) + fabs(sum[3 * cp + 1]) + fabs(sum[3 * cp + 2]);
        if (seen[cp] < render_count[cp] && size > tolerance)
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX: channel '%s' target %u moves some render vertices of control point %u of "
                                "mesh '%s' and not others; the file holds one delta per control point",
                                ch->name, t, cp, m->name);
        seen[cp] = size > 0;
        n += seen[cp];
    }
    /* A target that moves nothing keeps one entry, control point 0 by zero: Blender requires
     * FullWeights to have one value per index, and a shape without indexes fails its import. */
    *indexes = mk_arena_array(w->a, n ? n : 1, sizeof(int32_t));
    *deltas = mk_arena_array(w->a, n ? n : 1, 3 * sizeof(double));
    if (!*indexes || !*deltas) return fbx_objects_oom(w);
    *count = n ? n : 1;
    for (uint32_t cp = 0, e = 0; cp < cps; cp++) {
        if (!seen[cp]) continue;
        (*indexes)[e] = (int32_t)cp;
        memcpy(*deltas + 3 * (size_t)e++, sum + 3 * (size_t)cp, 3 * sizeof(double));
    }
    mk_arena_release(w->a, sum);
    mk_arena_release(w->a, seen);
    return MK_OK;
}

mk_result fbx_objects_add_channel(fbx_objects *w, const mk_raw_mesh *m, const uint32_t *render_count, double tolerance,
                             const mk_raw_channel *ch, int64_t blend_shape, int64_t *channel_id)
{
    mk_result r = fbx_object_check_name(w, "channel", ch->name);
    if (r != MK_OK) return r;
    if (w->blender && ch->target_count > 1)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX: channel '%s' has %u in-between targets, but this file comes from Blender's "
                            "exporter, and readers take the FullWeights of such files as per-vertex weights (ufbx and "
                            "Blender would play every in-between at full weight); bake it with \"inbetweens\": 1 (one target), or "
                            "write a .morph or glTF",
                            ch->name, ch->target_count);
    fbx_wnode *c = fbx_object_new(w, "Deformer", "SubDeformer", ch->name, "BlendShapeChannel", channel_id);
    if (!c || !fbx_wn_int(w->a, fbx_wn_child(w->a, c, "Version"), 100)) return fbx_objects_oom(w);
    fbx_wnode *props = fbx_wn_child(w->a, c, "Properties70");
    if (!props || !fbx_wn_prop(w->a, props, "DeformPercent", "Number", "", "A", (fbx_wvalue){ .type = 'D', .u.d = 100.0 * ch->default_weight }) ||
        !fbx_wn_double(w->a, fbx_wn_child(w->a, c, "DeformPercent"), 100.0 * ch->default_weight))
        return fbx_objects_oom(w);
    if (!fbx_object_connect(w, "OO", *channel_id, blend_shape, NULL)) return fbx_objects_oom(w);
    /* Files made by Blender: a one-target channel's FullWeights are per-index weights (100 each). */
    const int per_index = w->blender;   /* in-betweens were refused above */
    if (per_index && ch->targets[0].full_weight != 1.0f)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX: channel '%s' has one target at full weight %g; this file comes from "
                            "Blender, whose FullWeights of a one-shape channel are per-vertex weights",
                            ch->name, (double)ch->targets[0].full_weight);
    double *full = mk_arena_array(w->a, ch->target_count ? ch->target_count : 1, sizeof(double));
    if (!full) return fbx_objects_oom(w);
    uint32_t full_count = ch->target_count;
    for (uint32_t t = 0; t < ch->target_count; t++) {
        const mk_raw_target *tg = &ch->targets[t];
        int32_t *indexes = NULL;
        double *deltas = NULL;
        uint32_t n = 0;
        if ((r = fbx_objects_target(w, m, render_count, ch, t, tolerance, &indexes, &deltas, &n)) != MK_OK) return r;
        if (n > UINT32_MAX / 3)
            return mk_error_set(w->err, MK_ERROR_LIMIT, UINT64_MAX, "FBX: channel '%s' target %u moves more control points "
                                "than an FBX array can hold", ch->name, t);
        char fallback[160];
        snprintf(fallback, sizeof fallback, "%s_%u", ch->name, t);
        const char *name = tg->name && *tg->name ? tg->name : fallback;
        if ((r = fbx_object_check_name(w, "target", name)) != MK_OK) return r;
        int64_t shape_id;
        fbx_wnode *s = fbx_object_new(w, "Geometry", "Geometry", name, "Shape", &shape_id);
        if (!s || !fbx_wn_int(w->a, fbx_wn_child(w->a, s, "Version"), 100) ||
            !fbx_wn_array(w->a, s, "Indexes", 'i', indexes, n) || !fbx_wn_array(w->a, s, "Vertices", 'd', deltas, 3 * n) ||
            !fbx_object_connect(w, "OO", shape_id, *channel_id, NULL))
            return fbx_objects_oom(w);
        full[t] = 100.0 * tg->full_weight;
        if (per_index) {
            full_count = n;
            full = mk_arena_array(w->a, n, sizeof(double));
            if (!full) return fbx_objects_oom(w);
            for (uint32_t k = 0; k < n; k++) full[k] = 100.0;
            w->report->blender_weights++;
        }
        w->report->shapes++;
    }
    if (!fbx_wn_array(w->a, c, "FullWeights", 'd', full, full_count)) return fbx_objects_oom(w);
    w->report->channels++;
    w->report->progressive_channels += ch->target_count > 1;
    return MK_OK;
}

/* ---- clips ---- */

/* A curve animating property `prop` of object `owner` (a channel's DeformPercent; in FBX 7.1 the
 * Geometry property named after the shape). */
static mk_result add_curve(fbx_objects *w, const mk_raw_track *track, int64_t layer, int64_t owner, const char *prop)
{
    char d_prop[300];
    snprintf(d_prop, sizeof d_prop, "d|%s", prop);
    const uint32_t n = track->key_count;
    int64_t curve_node, curve_id;
    fbx_wnode *node = fbx_object_new(w, "AnimationCurveNode", "AnimCurveNode", prop, "", &curve_node);
    fbx_wnode *props = node ? fbx_wn_child(w->a, node, "Properties70") : NULL;
    if (!props || !fbx_wn_prop(w->a, props, d_prop, "Number", "", "A",
                               (fbx_wvalue){ .type = 'D', .u.d = 100.0 * track->keys[0].value }))
        return fbx_objects_oom(w);
    fbx_wnode *curve = fbx_object_new(w, "AnimationCurve", "AnimCurve", "", "", &curve_id);
    int64_t *times = mk_arena_array(w->a, n, sizeof(int64_t));
    float *values = mk_arena_array(w->a, n, sizeof(float));
    int32_t *flags = mk_arena_array(w->a, n, sizeof(int32_t)), *refs = mk_arena_array(w->a, n, sizeof(int32_t));
    float *data = mk_arena_array(w->a, n, 4 * sizeof(float));
    if (!curve || !times || !values || !flags || !refs || !data) return fbx_objects_oom(w);
    for (uint32_t i = 0; i < n; i++) {
        const mk_key *k = &track->keys[i];
        if (fabs((double)k->time) > max_seconds(w))
            return mk_error_set(w->err, MK_ERROR_LIMIT, UINT64_MAX, "FBX: key %u of a clip's track for channel %u is at %g s; "
                                "FBX key times (int64 ticks of 1/%.0f s) reach %.3g s", i, track->channel,
                                (double)k->time, w->ticks, max_seconds(w));
        times[i] = (int64_t)llround((double)k->time * w->ticks);
        values[i] = 100.0f * k->value;
        refs[i] = 1;
        uint32_t f;
        switch (k->interp) {
        case MK_INTERP_CONSTANT: f = KEY_CONSTANT; break;
        case MK_INTERP_CONSTANT_NEXT: f = KEY_CONSTANT | KEY_CONSTANT_NEXT; break;
        case MK_INTERP_LINEAR: f = KEY_LINEAR; break;
        default: f = KEY_CUBIC | KEY_USER; break;  /* the slopes as stored */
        }
        float next_left_slope = i + 1 < n ? track->keys[i + 1].left_slope : 0.0f;
        float next_left_weight = i + 1 < n ? track->keys[i + 1].left_weight : 1.0f / 3.0f;
        uint32_t packed = 0;
        if (k->interp == MK_INTERP_CUBIC && (fabsf(k->right_weight - 1.0f / 3.0f) > 1e-6f ||
                                             fabsf(next_left_weight - 1.0f / 3.0f) > 1e-6f)) {
            f |= KEY_WEIGHTED_RIGHT | KEY_WEIGHTED_NEXT_LEFT;
            packed = (uint32_t)lrintf(k->right_weight * 10000.0f) | ((uint32_t)lrintf(next_left_weight * 10000.0f) << 16);
        }
        flags[i] = (int32_t)f;
        data[4 * i] = k->interp == MK_INTERP_CUBIC ? 100.0f * k->right_slope : 0.0f;
        data[4 * i + 1] = k->interp == MK_INTERP_CUBIC ? 100.0f * next_left_slope : 0.0f;
        memcpy(&data[4 * i + 2], &packed, 4);
        data[4 * i + 3] = 0.0f;
    }
    /* ASCII files from 7.2 on spell the attribute floats as their int32 bit patterns (before,
     * as decimal floats): the same bytes as an 'i' array. */
    if (!fbx_wn_double(w->a, fbx_wn_child(w->a, curve, "Default"), 100.0 * track->keys[0].value) ||
        !fbx_wn_int(w->a, fbx_wn_child(w->a, curve, "KeyVer"), 4009) ||
        !fbx_wn_array(w->a, curve, "KeyTime", 'l', times, n) || !fbx_wn_array(w->a, curve, "KeyValueFloat", 'f', values, n) ||
        !fbx_wn_array(w->a, curve, "KeyAttrFlags", 'i', flags, n) ||
        !fbx_wn_array(w->a, curve, "KeyAttrDataFloat", w->ascii_float_bits ? 'i' : 'f', data, 4 * n) ||
        !fbx_wn_array(w->a, curve, "KeyAttrRefCount", 'i', refs, n))
        return fbx_objects_oom(w);
    if (!fbx_object_connect(w, "OO", curve_node, layer, NULL) || !fbx_object_connect(w, "OP", curve_node, owner, prop) ||
        !fbx_object_connect(w, "OP", curve_id, curve_node, d_prop))
        return fbx_objects_oom(w);
    return MK_OK;
}

mk_result fbx_objects_add_clip(fbx_objects *w, const mk_raw_clip *clip, const int64_t *channel_ids,
                               const char *const *channel_props)
{
    mk_result r = fbx_object_check_name(w, "clip", clip->name ? clip->name : "");
    if (r != MK_OK) return r;
    int64_t stack, layer;
    fbx_wnode *s = fbx_object_new(w, "AnimationStack", "AnimStack", clip->name ? clip->name : "", "", &stack);
    fbx_wnode *props = s ? fbx_wn_child(w->a, s, "Properties70") : NULL;
    if (fabs((double)clip->start) > max_seconds(w) || fabs((double)clip->start + clip->duration) > max_seconds(w))
        return mk_error_set(w->err, MK_ERROR_LIMIT, UINT64_MAX, "FBX: clip '%s' runs to %g s; FBX times (int64 ticks of "
                            "1/%.0f s) reach %.3g s", clip->name ? clip->name : "", (double)clip->start + clip->duration,
                            w->ticks, max_seconds(w));
    const int64_t start = (int64_t)llround((double)clip->start * w->ticks);
    const int64_t stop = (int64_t)llround(((double)clip->start + clip->duration) * w->ticks);
    static const char *const names[4] = { "LocalStart", "LocalStop", "ReferenceStart", "ReferenceStop" };
    for (int i = 0; i < 4; i++)
        if (!props || !fbx_wn_prop(w->a, props, names[i], "KTime", "Time", "", (fbx_wvalue){ .type = 'L', .u.i = i & 1 ? stop : start }))
            return fbx_objects_oom(w);
    if (!fbx_object_new(w, "AnimationLayer", "AnimLayer", "BaseLayer", "", &layer) || !fbx_object_connect(w, "OO", layer, stack, NULL))
        return fbx_objects_oom(w);
    for (uint32_t t = 0; t < clip->track_count; t++) {
        const mk_raw_track *track = &clip->tracks[t];
        if (!track->key_count) continue;
        const char *prop = channel_props ? channel_props[track->channel] : "DeformPercent";
        if ((r = add_curve(w, track, layer, channel_ids[track->channel], prop)) != MK_OK) return r;
    }
    w->report->clips++;
    return MK_OK;
}

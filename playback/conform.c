/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "conform.h"
#include "frame.h"
#include "reference.h"

/* Half the spacing of float32 values around |x|: the rounding error of storing x as float.
 * Results are float32, so nothing can be closer to a reference than that. */
static double float32_half_ulp(double x)
{
    int exponent;
    frexp(fabs(x), &exponent); /* 2^(exponent-1) <= |x| < 2^exponent */
    return x != 0 ? ldexp(1.0, exponent - 25) : 0.0;
}

static double max_column_norm(const float *w)
{
    double m = 0;
    for (int c = 0; c < 3; c++) {
        double s = sqrt((double)w[4 * c] * w[4 * c] + (double)w[4 * c + 1] * w[4 * c + 1] +
                        (double)w[4 * c + 2] * w[4 * c + 2]);
        if (s > m) m = s;
    }
    return m;
}

/* The largest position error quantization can add to a vertex of the mesh at these weights:
 * each contributing target adds |coefficient| x half its int16 step (0 for float targets). */
static double quantization_bound(const mk_asset *a, const mk_mesh_info *m, const float *weights)
{
    double sum = 0;
    for (uint32_t c = m->first_channel; c < m->first_channel + m->channel_count; c++) {
        int32_t ia, ib;
        float ca, cb;
        pb_channel_span(a, c, weights[c], &ia, &ca, &ib, &cb);
        for (int side = 0; side < 2; side++) {
            int32_t k = side ? ib : ia;
            mk_target_info t;
            if (k >= 0 && mk_target_get(a, c, (uint32_t)k, &t)) sum += fabs(side ? cb : ca) * 0.5 * t.position_scale;
        }
    }
    return sum;
}

mk_result pb_conform_weights(const pb_case *c, const pb_frame_spec *f, const mk_asset *a, float *weights, mk_error *err)
{
    int32_t clip = -1;
    if (f->has_time && !f->forced) clip = f->clip >= 0 ? f->clip : !c->gltf && a->clip_count ? 0 : -1;
    if (clip >= (int32_t)a->clip_count)
        return mk_error_set(err, MK_ERROR_OUT_OF_RANGE, UINT64_MAX, "the frame needs clip %d, the import has %u clips",
                            clip, a->clip_count);
    return pb_frame_weights(a, clip, f->has_time ? f->time : 0.0, weights, err);
}

/* The import mesh a reference mesh names, or -1. */
static int find_mesh(const mk_asset *a, const pb_ref_mesh *rm)
{
    if (rm->mesh_index >= 0) return rm->mesh_index < (int32_t)a->mesh_count ? rm->mesh_index : -1;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        if (rm->gltf_node >= 0) {
            if (m.gltf_node == rm->gltf_node && m.gltf_mesh == rm->gltf_mesh && m.gltf_primitive == rm->gltf_primitive)
                return (int)i;
        } else if (rm->node && !strcmp(m.name, rm->node)) {
            return (int)i;
        }
    }
    return -1;
}

typedef struct frame_state {
    const pb_case *c;
    const pb_conform_options *o;
    const pb_frame_spec *f;
    const mk_asset *a;
    float *weights;
    double quantization, largest; /* the largest allowance terms over the compared meshes */
    double lo[3], hi[3];          /* reference bounds over the compared points */
    pb_frame_result *res;
} frame_state;

static void compare_mesh(frame_state *s, uint32_t mi, const pb_ref_mesh *rm)
{
    pb_frame_result *res = s->res;
    const mk_asset *a = s->a;
    mk_mesh_info m;
    mk_mesh_get(a, mi, &m);
    /* Forced weights, in the mesh's channel order, replace its channels' weights (meshes own
     * disjoint channel ranges, so the frame's weight array takes them in place). */
    for (uint32_t k = 0; k < s->f->forced_count && k < m.channel_count; k++)
        s->weights[m.first_channel + k] = (float)s->f->forced[k];
    if (s->f->weights_from_reference)
        for (uint32_t k = 0; k < rm->weight_count && k < m.channel_count; k++)
            s->weights[m.first_channel + k] = (float)rm->weights[k];
    if (rm->weights && rm->weight_count) {
        if (rm->weight_count != m.channel_count) {
            snprintf(res->failure, sizeof res->failure, "mesh '%.100s': the reference has %u channels, the import %u",
                     m.name, rm->weight_count, m.channel_count);
            return;
        }
        for (uint32_t k = 0; k < m.channel_count; k++) {
            double e = fabs((double)s->weights[m.first_channel + k] - rm->weights[k]);
            if (!(e <= res->weight_error)) res->weight_error = e; /* NaN fails closed */
        }
        res->weights_compared = 1;
    }
    uint32_t expected = s->c->by_control_point ? m.control_point_count : m.vertex_count;
    if (rm->point_count != expected) {
        snprintf(res->failure, sizeof res->failure, "mesh '%.100s': the reference has %u %s, the import %u", m.name,
                 rm->point_count, s->c->by_control_point ? "control points" : "vertices", expected);
        return;
    }
    float *pos = malloc(12u * (size_t)m.vertex_count + 12),
          *nrm = m.has_normals ? malloc(12u * (size_t)m.vertex_count + 12) : NULL;
    mk_error err;
    if (!pos || (m.has_normals && !nrm)) {
        snprintf(res->failure, sizeof res->failure, "out of memory");
    } else if (pb_eval_mesh_with(s->o->evaluator, a, mi, s->weights, s->o->stacking ? s->o->stacking : s->c->stacking,
                                 s->o->normal_mode_given ? s->o->normal_mode : s->c->normal_mode, pos, nrm, NULL,
                                 &err) != MK_OK) {
        snprintf(res->failure, sizeof res->failure, "mesh '%.100s': evaluation failed: %.300s", m.name, err.message);
    } else {
        if (s->c->world) pb_to_world(m.world, pos, nrm, m.vertex_count);
        double q = quantization_bound(a, &m, s->weights) * (s->c->world ? max_column_norm(m.world) : 1.0);
        if (q > s->quantization) s->quantization = q;
        for (uint32_t v = 0; v < m.vertex_count; v++) {
            uint32_t r = s->c->by_control_point ? m.control_points[v] : v;
            for (int d = 0; d < 3; d++) {
                double ref = rm->positions[3 * r + (uint32_t)d], e = fabs((double)pos[3 * v + (uint32_t)d] - ref);
                if (!(e <= res->position_error)) { /* NaN propagates as failure */
                    res->position_error = e;
                    res->worst_known = 1;
                    res->worst_mesh = mi;
                    res->worst_vertex = v;
                }
                if (fabs(ref) > s->largest) s->largest = fabs(ref);
                if (ref < s->lo[d]) s->lo[d] = ref;
                if (ref > s->hi[d]) s->hi[d] = ref;
            }
            if (!rm->normals || !nrm) continue;
            const double *rn = &rm->normals[3 * r];
            const float *n = &nrm[3 * v];
            double rl = sqrt(rn[0] * rn[0] + rn[1] * rn[1] + rn[2] * rn[2]);
            double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (rl <= 1e-12) continue; /* the reference has no direction here */
            double dot = (n[0] * rn[0] + n[1] * rn[1] + n[2] * rn[2]) / (rl * nl);
            dot = dot > 1 ? 1 : dot < -1 ? -1 : dot;
            double angle = acos(dot) * (180.0 / 3.14159265358979323846);
            if (!(angle <= res->normal_error_deg)) res->normal_error_deg = angle; /* NaN fails closed */
            res->normals_compared = 1;
        }
        res->meshes_compared++;
        if (s->o->mesh_compared) {
            pb_compared_mesh cm = { mi, m.vertex_count, pos, nrm, rm->positions, rm->normals,
                                    s->c->by_control_point ? m.control_points : NULL };
            s->o->mesh_compared(s->o->user, &cm);
        }
    }
    free(pos);
    free(nrm);
}

void pb_conform_frame(const pb_manifest *manifest, const pb_case *c, const pb_frame_spec *f, const pb_asset *loaded,
                      const pb_conform_options *options, pb_frame_result *res)
{
    memset(res, 0, sizeof *res);
    pb_conform_options defaults = { 0 };
    const pb_conform_options *o = options ? options : &defaults;
    double normal_tolerance = o->normal_tolerance_deg > 0 ? o->normal_tolerance_deg : 1.0;
    double weight_tolerance = o->weight_tolerance > 0 ? o->weight_tolerance : 1e-5;
    const mk_asset *a = &loaded->asset;
    frame_state s = {
        c, o, f, a, NULL, 0, 0, { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY }, res
    };
    s.weights = calloc(a->channel_count + 1u, sizeof(float));
    if (!s.weights) {
        snprintf(res->failure, sizeof res->failure, "out of memory");
        return;
    }
    mk_error err;
    char path[4200];
    pb_manifest_path(manifest, f->file, path, sizeof path);
    pb_reference ref;
    if (pb_conform_weights(c, f, a, s.weights, &err) != MK_OK) {
        snprintf(res->failure, sizeof res->failure, "%.500s", err.message);
        free(s.weights);
        return;
    }
    if (pb_reference_read(path, c->kind, &ref, &err) != MK_OK) {
        snprintf(res->failure, sizeof res->failure, "%.500s", err.message);
    } else if (c->kind == PB_REF_OBJ) {
        /* An OBJ frame holds one deformed mesh: the import's one mesh with channels. */
        int32_t only = -1, with_channels = 0;
        for (uint32_t i = 0; i < a->mesh_count; i++) {
            mk_mesh_info m;
            mk_mesh_get(a, i, &m);
            if (m.channel_count) {
                only = (int32_t)i;
                with_channels++;
            }
        }
        if (with_channels != 1)
            snprintf(res->failure, sizeof res->failure,
                     "an OBJ reference needs exactly one mesh with channels; the import has %d", with_channels);
        else
            compare_mesh(&s, (uint32_t)only, &ref.meshes[0]);
    } else {
        for (uint32_t k = 0; k < ref.mesh_count && !res->failure[0]; k++) {
            const pb_ref_mesh *rm = &ref.meshes[k];
            /* A reference mesh without channels is not compared: references evaluate whole
             * scenes (node animation, skinning), and such a mesh is not imported by default. */
            if (!rm->has_channels) continue;
            int mi = find_mesh(a, rm);
            if (mi < 0)
                snprintf(res->failure, sizeof res->failure,
                         "reference mesh '%.200s' with channels is not in the import", rm->label);
            else
                compare_mesh(&s, (uint32_t)mi, rm);
        }
        if (!res->failure[0] && res->meshes_compared == 0)
            snprintf(res->failure, sizeof res->failure, "no reference mesh with channels matched the import");
    }
    pb_reference_free(&ref);
    free(s.weights);
    double rounding = float32_half_ulp(s.largest);
    res->allowed = c->tolerance + s.quantization + rounding;
    if (c->relative_tolerance > 0 && res->meshes_compared) {
        double diagonal = sqrt((s.hi[0] - s.lo[0]) * (s.hi[0] - s.lo[0]) + (s.hi[1] - s.lo[1]) * (s.hi[1] - s.lo[1]) +
                               (s.hi[2] - s.lo[2]) * (s.hi[2] - s.lo[2]));
        res->reference_size = c->relative_to_largest ? s.largest : diagonal;
        res->relative_allowed = c->relative_tolerance * res->reference_size + s.quantization + rounding;
    }
    if (res->failure[0]) return;
    int other_ok = res->normal_error_deg <= normal_tolerance && res->weight_error <= weight_tolerance;
    if (!other_ok) return;
    if (c->tolerance > 0 && res->position_error <= res->allowed)
        res->passed_by = "tolerance";
    else if (c->relative_tolerance > 0 && res->position_error <= res->relative_allowed)
        res->passed_by = "relative_tolerance";
    else if (c->tolerance == 0 && c->relative_tolerance == 0 && res->position_error <= res->allowed)
        res->passed_by = "tolerance";
    res->passed = res->passed_by != NULL;
}

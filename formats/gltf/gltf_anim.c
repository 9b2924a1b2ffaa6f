/* SPDX-License-Identifier: MIT */
/* glTF weight animations → raw clips (spec §3.11 and Appendix C).
 *
 * One clip per glTF animation, in the same order, so a reference frame that names glTF
 * animation k is clip k. A "weights" channel targets a node: its sampler drives every glTF
 * target of the node's mesh, and therefore every primitive's raw mesh of that node
 * (target k → the raw channel the importer made for target k).
 *
 * Interpolation: STEP → MK_INTERP_CONSTANT, LINEAR → MK_INTERP_LINEAR, CUBICSPLINE →
 * MK_INTERP_CUBIC. glTF's cubic segment is the Hermite spline
 *   v(t) = h00 v_k + h10 t_d b_k + h01 v_k+1 + h11 t_d a_k+1,
 * whose out/in tangents b_k, a_k+1 are derivatives per second (they are multiplied by the key
 * interval t_d inside the formula). mk_key slopes are also per second, and tangent weights of
 * 1/3 make the runtime's Bezier exactly that Hermite, so right_slope = b_k, left_slope = a_k
 * with no scaling. Output values are floats or normalized integers (decoded by the accessor
 * reader). Times before the first key clamp to it (the runtime's rule, also the spec's).
 *
 * With sidecar groups, glTF target k has full weight f_k inside its channel and the channel
 * weight is w = Σ f_k u_k over the channel's targets; values and tangents are linear in u,
 * so the sum is exact for all three interpolations.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "gltf_internal.h"

static mk_result read_input(mk_gltf_reader *r, int32_t acc, const char *what, float **t, uint64_t *n, mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    if (acc >= 0 && (uint32_t)acc < d->accessor_count && d->accessors[acc].component_type != MK_GLTF_FLOAT)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: input accessor %d must be FLOAT", what, acc);
    mk_result res = mk_gltf_read_floats(r, acc, 1, what, t, n, err);
    if (res != MK_OK) return res;
    if (*n == 0) return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: input accessor %d has no keys", what, acc);
    for (uint64_t i = 1; i < *n; i++)
        if (!((*t)[i] > (*t)[i - 1]))
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: input accessor %d: key %llu time %g does not increase",
                                what, acc, (unsigned long long)i, (double)(*t)[i]);
    return MK_OK;
}

static mk_result add_track(mk_arena *tmp, mk_raw_track **tracks, uint32_t *count, uint32_t *cap, mk_raw_track tr, mk_error *err)
{
    if (*count == *cap) {
        uint32_t nc = *cap ? *cap * 2 : 8;
        mk_raw_track *nt = mk_arena_realloc(tmp, *tracks, *cap * sizeof *nt, nc * sizeof *nt);
        if (!nt) return mk_error_oom(err, "glTF tracks");
        *tracks = nt;
        *cap = nc;
    }
    (*tracks)[(*count)++] = tr;
    return MK_OK;
}

static mk_result import_channel(mk_gltf_reader *r, const mk_gltf_animation *an, uint32_t ai, uint32_t ci,
                                const mk_gltf_instance *inst, uint32_t ninst, mk_raw_asset *out, mk_arena *tmp,
                                mk_raw_track **tracks, uint32_t *track_count, uint32_t *track_cap, uint8_t *node_done,
                                float *duration, mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    const mk_gltf_channel *ch = &an->channels[ci];
    char what[96];
    snprintf(what, sizeof what, "animation %u channel %u", ai, ci);
    if (ch->sampler < 0 || (uint32_t)ch->sampler >= an->sampler_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: sampler %d out of range (%u samplers)", what, ch->sampler, an->sampler_count);
    const mk_gltf_sampler *s = &an->samplers[ch->sampler];
    int weights = strcmp(ch->path, "weights") == 0;
    if (!weights) {
        /* Other paths only count toward the clip's length; damaged TRS data is not ours to judge. */
        mk_error ignored;
        float *t; uint64_t n;
        if (read_input(r, s->input, what, &t, &n, &ignored) == MK_OK && t[n - 1] > *duration) *duration = t[n - 1];
        return MK_OK;
    }
    if (ch->node < 0) {
        mk_raw_warn(out, "%s: weights channel without target node ignored", what);
        return MK_OK;
    }
    if ((uint32_t)ch->node >= d->node_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: target node %d out of range (%u nodes)", what, ch->node, d->node_count);
    uint32_t first = UINT32_MAX, count = 0;
    for (uint32_t i = 0; i < ninst; i++)
        if (inst[i].node == ch->node) { if (first == UINT32_MAX) first = i; count++; }
    if (!count) {
        mk_raw_warn(out, "%s: node %d has no mesh with morph targets; weights channel ignored", what, ch->node);
        return MK_OK;
    }
    if (node_done[ch->node]) {
        mk_raw_warn(out, "%s: node %d already has a weights channel in this animation; ignored", what, ch->node);
        return MK_OK;
    }
    node_done[ch->node] = 1;
    if (s->interpolation == MK_GLTF_INTERP_UNKNOWN)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: unknown interpolation", what);
    float *t, *v;
    uint64_t nk, nv;
    mk_result res;
    if ((res = read_input(r, s->input, what, &t, &nk, err)) != MK_OK) return res;
    if (t[nk - 1] > *duration) *duration = t[nk - 1];
    if (nk > (1u << 24)) return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: %llu keys", what, (unsigned long long)nk);
    int cubic = s->interpolation == MK_GLTF_CUBICSPLINE;
    if (cubic && nk < 2)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: CUBICSPLINE needs at least 2 keys, input accessor %d has %llu",
                            what, s->input, (unsigned long long)nk);
    if (s->output >= 0 && (uint32_t)s->output < d->accessor_count) {
        const mk_gltf_accessor *oa = &d->accessors[s->output];
        if (oa->component_type != MK_GLTF_FLOAT && !oa->normalized)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: weights output accessor %d must be FLOAT or normalized", what, s->output);
    }
    if ((res = mk_gltf_read_floats(r, s->output, 1, what, &v, &nv, err)) != MK_OK) return res;
    uint64_t T = inst[first].target_count;
    uint64_t per_key = T * (cubic ? 3u : 1u);
    if (nv != nk * per_key)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX,
                            "%s: output accessor %d has %llu values, expected %llu keys x %llu targets%s = %llu", what, s->output,
                            (unsigned long long)nv, (unsigned long long)nk, (unsigned long long)T, cubic ? " x 3" : "",
                            (unsigned long long)(nk * per_key));
    uint32_t interp = s->interpolation == MK_GLTF_STEP ? MK_INTERP_CONSTANT : cubic ? MK_INTERP_CUBIC : MK_INTERP_LINEAR;

    for (uint32_t i = first; i < ninst; i++) {
        if (inst[i].node != ch->node) continue;
        /* One track per distinct raw channel of this instance. */
        for (uint64_t k = 0; k < T; k++) {
            uint32_t c = inst[i].target_channel[k];
            if (c == UINT32_MAX) continue;
            int seen = 0;
            for (uint64_t j = 0; j < k; j++) seen |= inst[i].target_channel[j] == c;
            if (seen) continue;
            mk_key *keys = mk_arena_array(&out->arena, (size_t)nk, sizeof *keys);
            if (!keys) return mk_error_oom(err, "glTF keys");
            for (uint64_t q = 0; q < nk; q++) {
                double val = 0, in = 0, outt = 0;
                for (uint64_t j = k; j < T; j++) {
                    if (inst[i].target_channel[j] != c) continue;
                    double f = inst[i].target_full_weight[j];
                    if (cubic) {
                        in += f * v[q * per_key + j];
                        val += f * v[q * per_key + T + j];
                        outt += f * v[q * per_key + 2 * T + j];
                    } else {
                        val += f * v[q * per_key + j];
                    }
                }
                mk_key *key = &keys[q];
                key->time = t[q];
                key->value = (float)val;
                key->left_slope = (float)in;
                key->right_slope = (float)outt;
                key->left_weight = key->right_weight = 1.0f / 3.0f;
                key->interp = interp;
            }
            mk_raw_track tr = {c, (uint32_t)nk, keys};
            if ((res = add_track(tmp, tracks, track_count, track_cap, tr, err)) != MK_OK) return res;
        }
    }
    return MK_OK;
}

mk_result mk_gltf_import_animations(mk_gltf_reader *r, const mk_gltf_instance *inst, uint32_t ninst, mk_raw_asset *out,
                                    mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    mk_arena *tmp = r->arena;
    uint8_t *node_done = mk_arena_array(tmp, d->node_count + 1u, 1);
    if (!node_done) return mk_error_oom(err, "glTF animations");
    for (uint32_t ai = 0; ai < d->animation_count; ai++) {
        const mk_gltf_animation *an = &d->animations[ai];
        memset(node_done, 0, d->node_count + 1u);
        mk_raw_track *tracks = NULL;
        uint32_t count = 0, cap = 0;
        float duration = 0;
        for (uint32_t ci = 0; ci < an->channel_count; ci++) {
            mk_result res = import_channel(r, an, ai, ci, inst, ninst, out, tmp, &tracks, &count, &cap, node_done, &duration, err);
            if (res != MK_OK) return res;
        }
        mk_raw_clip *clip = mk_raw_add_clips(out, 1);
        if (!clip) return mk_error_oom(err, "glTF clips");
        char buf[32];
        if (!an->name[0]) snprintf(buf, sizeof buf, "animation%u", ai);
        clip->name = mk_arena_strdup(&out->arena, an->name[0] ? an->name : buf);
        clip->start = 0.0f;   /* glTF times are relative to the animation's start (§3.11) */
        clip->duration = duration;
        clip->track_count = count;
        clip->tracks = mk_arena_array(&out->arena, count + 1u, sizeof *clip->tracks);
        if (!clip->name || !clip->tracks) return mk_error_oom(err, "glTF clips");
        if (count) memcpy(clip->tracks, tracks, count * sizeof *tracks);
    }
    return MK_OK;
}

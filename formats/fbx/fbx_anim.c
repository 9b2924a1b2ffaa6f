/* SPDX-License-Identifier: MIT */
/* FBX weight curves into mk_key tracks.
 *
 * 7.x AnimationCurve (FbxAnimCurveDef; ufbx.c ufbxi_read_animation_curve): KeyTime (KTime),
 * KeyValueFloat, and run-length-encoded attributes: KeyAttrRefCount[j] consecutive keys share
 * KeyAttrFlags[j] and KeyAttrDataFloat[4j..4j+3] = {right slope, next key's left slope, packed
 * weights, packed velocities}. Packed weights are u32 bits: low 16 = right weight x 10000,
 * high 16 = next-left weight x 10000, used only with the weighted flags 0x1000000/0x2000000.
 * ASCII >= 7200 writes DataFloat as int32 bit patterns (the caller picks the decoding).
 *
 * Flags: constant 0x2 (0x100 = take the next key's value), linear 0x4, cubic 0x8 with tangent
 * mode auto 0x100, TCB 0x200, user 0x400 (break 0x800), clamp 0x1000, time-independent 0x2000,
 * clamp-progressive 0x4000.
 *
 * Auto tangents are not stored (Maya writes 0 slopes): they are recomputed as ufbx does
 * (ufbx.c ufbxi_read_animation_curve / ufbxi_solve_auto_tangent{,_left,_right}, 2026):
 * interior keys take the neighbour secant (v[k+1]-v[k-1])/(t[k+1]-t[k-1]); without the
 * time-independent flag it is averaged with the time-weighted one-sided secants and pulled by
 * the auto bias (the stored slope fields); clamp-progressive limits the slope so neither
 * Bezier handle passes a neighbouring value (extrema get 0) and flattens end keys; clamp
 * flattens keys equal to a neighbour. End keys otherwise take their one-sided secant. TCB keys
 * use Kochanek-Bartels weights on the one-sided secants (tension, continuity, bias =
 * DataFloat[0..2]); the next key's left slope is then 0, as in ufbx.
 *
 * Legacy (5.x/6.x Takes, ufbx ufbxi_read_take_anim_channel): `Key:` is one heterogeneous list
 * per key: time, value, mode ('U' cubic, 'L' linear, 'C' constant + 'n'/'s'); cubic is followed
 * by a slope mode ('s'/'b' + right slope + next-left slope, 'a' auto, 'p' 2 values, 't' 3
 * values, 'd' 1 value) and weight modes ('n' default, 'a' right + next-left, 'l' next-left,
 * 'r' right, 'c').
 *
 * Output: times in seconds (KTime / ticks per second), values and slopes scaled (x 0.01 for
 * DeformPercent), tangent weights as fractions of the key interval (1/3 = plain Hermite). Keys
 * whose float time does not increase are dropped with a warning (the runtime needs strictly
 * increasing times).
 */
#include <math.h>
#include <string.h>
#include "fbx_anim.h"


#define THIRD (1.0 / 3.0)

/* One key in double precision while converting (times in seconds, values unscaled). */
typedef struct dkey {
    double time, value;
    int interp;
    double left_slope, left_weight, right_slope, right_weight;
} dkey;

/* Interior auto tangent (see the header comment). bias: the stored slope field. */
static double auto_tangent(double t0, double t1, double t2, double v0, double v1, double v2, double weight_left,
                           double weight_right, double bias, uint32_t flags)
{
    if ((flags & KEY_CLAMP) && fmin(fabs(v0 - v1), fabs(v2 - v1)) <= 0.0) return 0.0;
    double slope = (v2 - v0) / (t2 - t0);
    if (!(flags & KEY_TIME_INDEPENDENT)) {
        double left = (v1 - v0) / (t1 - t0), right = (v2 - v1) / (t2 - t1);
        double delta = (t1 - t0) / (t2 - t0);
        slope = slope * 0.5 + (left * (1.0 - delta) + right * delta) * 0.5;
        double bias_weight = fabs(bias) / 100.0;
        if (bias_weight > 0.0001) {
            double target = bias > 0.0 ? right : left;
            double bias_delta = target - slope;
            slope = slope * (1.0 - bias_weight) + target * bias_weight;
            double extra = bias_weight - 5.0;  /* |bias| > 500 adds ((|bias|-500)/100)^2 * 40 */
            if (extra > 0.0) {
                double sign = fabs(bias_delta) > 0.00001 ? bias_delta : bias;
                slope += extra * extra * (sign > 0.0 ? 1.0 : -1.0) * 40.0;
            }
        }
    }
    if (flags & KEY_CLAMP_PROGRESSIVE) {
        double sign = slope >= 0.0 ? 1.0 : -1.0, mag = sign * slope;
        double range_left = weight_left * (t1 - t0), range_right = weight_right * (t2 - t1);
        double max_left = range_left > 0.0 ? sign * (v1 - v0) / range_left : 0.0;
        double max_right = range_right > 0.0 ? sign * (v2 - v1) / range_right : 0.0;
        if (!(max_left > 0.0)) max_left = 0.0;
        if (!(max_right > 0.0)) max_right = 0.0;
        if (mag > max_left) mag = max_left;
        if (mag > max_right) mag = max_right;
        slope = sign * mag;
    }
    return slope;
}

/* End key auto tangent: the one-sided secant (0 with clamp-progressive). */
static double auto_tangent_end(double ta, double tb, double va, double vb, double bias, uint32_t flags)
{
    if (flags & KEY_CLAMP_PROGRESSIVE) return 0.0;
    if ((flags & KEY_CLAMP) && fabs(vb - va) <= 0.0) return 0.0;
    double slope = (vb - va) / (tb - ta);
    if (!(flags & KEY_TIME_INDEPENDENT)) {
        double extra = fabs(bias) / 100.0 - 5.0;
        if (extra > 0.0) slope += extra * extra * (bias > 0.0 ? 1.0 : -1.0) * 40.0;
    }
    return slope;
}

static double clamp_weight(double w)
{
    return w > 1e-4 && w <= 1.0 ? w : w > 1.0 ? 1.0 : 1e-4;
}

/* Scales and writes the mk_key array (raw arena), dropping keys whose float time does not
 * increase. */
static mk_result finish(fbx_doc *doc, mk_raw_asset *raw, const char *path, const dkey *k, size_t n, double scale,
                        mk_key **out_keys, uint32_t *out_count)
{
    mk_key *keys = mk_arena_array(&raw->arena, n ? n : 1, sizeof(mk_key));
    if (!keys) return mk_error_oom(doc->err, "FBX keys");
    size_t w = 0, dropped = 0;
    for (size_t i = 0; i < n; i++) {
        mk_key key;
        memset(&key, 0, sizeof key);
        key.time = (float)k[i].time;
        key.value = (float)(k[i].value * scale);
        key.interp = (uint32_t)k[i].interp;
        key.right_slope = (float)(k[i].right_slope * scale);
        key.left_slope = (float)(k[i].left_slope * scale);
        key.right_weight = (float)clamp_weight(k[i].right_weight);
        key.left_weight = (float)clamp_weight(k[i].left_weight);
        if (!isfinite(key.time) || !isfinite(key.value) || !isfinite(key.right_slope) || !isfinite(key.left_slope)) {
            mk_arena_release(&raw->arena, keys);
            return mk_error_set(doc->err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                "FBX %s: key %zu has a NaN or infinite time/value/slope", path, i);
        }
        if (w > 0 && !(key.time > keys[w - 1].time)) { dropped++; continue; }
        keys[w++] = key;
    }
    if (dropped) mk_raw_warn(raw, "FBX %s: %zu keys dropped (time not after the previous key)", path, dropped);
    *out_keys = keys;
    *out_count = (uint32_t)w;
    return MK_OK;
}


/* Stores a key's tangents; the next key's left tangent becomes the current one. */
static void put_tangents(dkey *key, double *slope_left, double *weight_left, double right_slope, double right_weight,
                         double next_slope_left, double next_weight_left)
{
    key->left_slope = *slope_left;
    key->left_weight = *weight_left;
    key->right_slope = right_slope;
    key->right_weight = right_weight;
    *slope_left = next_slope_left;
    *weight_left = next_weight_left;
}
mk_result fbx_convert_curve(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *curve, double ticks_per_second,
                            double scale, mk_key **out_keys, uint32_t *out_count)
{
    char path[160];
    fbx_node_path(curve, path, sizeof path);
    *out_keys = NULL;
    *out_count = 0;
    int64_t *times = NULL;
    double *values = NULL;
    int32_t *flags = NULL, *refs = NULL;
    float *data = NULL;
    dkey *k = NULL;
    size_t n_times, n_values, n_flags, n_data, n_refs;
    /* ASCII files from 7200 on write the attribute floats as integer bit patterns. */
    fbx_elem data_elem = (!doc->binary && doc->version >= 7200) ? FBX_ELEM_F32_BITS : FBX_ELEM_F32;
    mk_result r;
    if ((r = fbx_child_array(doc, curve, "KeyTime", FBX_ELEM_I64, (void **)&times, &n_times)) != MK_OK) goto done;
    if ((r = fbx_child_array(doc, curve, "KeyValueFloat", FBX_ELEM_F64, (void **)&values, &n_values)) != MK_OK) goto done;
    if ((r = fbx_child_array(doc, curve, "KeyAttrFlags", FBX_ELEM_I32, (void **)&flags, &n_flags)) != MK_OK) goto done;
    if ((r = fbx_child_array(doc, curve, "KeyAttrDataFloat", data_elem, (void **)&data, &n_data)) != MK_OK) goto done;
    if ((r = fbx_child_array(doc, curve, "KeyAttrRefCount", FBX_ELEM_I32, (void **)&refs, &n_refs)) != MK_OK) goto done;
    if (n_times != n_values) {
        r = mk_error_set(doc->err, MK_ERROR_PARSE, curve->offset, "FBX %s: %zu KeyTime but %zu KeyValueFloat", path, n_times, n_values);
        goto done;
    }
    if (n_flags != n_refs || n_data != 4 * n_refs) {
        r = mk_error_set(doc->err, MK_ERROR_PARSE, curve->offset,
                         "FBX %s: key attributes disagree (%zu flags, %zu data floats, %zu ref counts)", path, n_flags, n_data, n_refs);
        goto done;
    }
    size_t n = n_times;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(values[i])) {
            r = fbx_error_not_finite(doc, fbx_child(curve, "KeyValueFloat"), i, "key %zu", i);
            goto done;
        }
    }
    k = mk_arena_array(doc->arena, n ? n : 1, sizeof *k);
    if (!k) { r = mk_error_oom(doc->err, "FBX curve"); goto done; }
    size_t attr = 0;
    int64_t left_in_run = n_refs ? refs[0] : 0;
    double slope_left = 0.0, weight_left = THIRD, prev_time = 0.0;
    for (size_t i = 0; i < n; i++) {
        while (attr < n_refs && left_in_run <= 0) {
            attr++;
            left_in_run = attr < n_refs ? refs[attr] : 0;
        }
        if (attr >= n_refs) {
            r = mk_error_set(doc->err, MK_ERROR_PARSE, curve->offset,
                             "FBX %s: KeyAttrRefCount covers fewer keys than the %zu keys", path, n);
            goto done;
        }
        left_in_run--;
        uint32_t f = (uint32_t)flags[attr];
        const float *d = data + 4 * attr;
        dkey *key = &k[i];
        double t = (double)times[i] / ticks_per_second, v = values[i];
        int has_next = i + 1 < n;
        double next_t = has_next ? (double)times[i + 1] / ticks_per_second : t;
        double next_v = has_next ? values[i + 1] : v;
        double right_slope = d[0], right_weight = THIRD, next_slope_left = d[1], next_weight_left = THIRD;
        if (f & (KEY_WEIGHTED_RIGHT | KEY_WEIGHTED_NEXT_LEFT)) {
            uint32_t packed;
            memcpy(&packed, &d[2], 4);
            if (f & KEY_WEIGHTED_RIGHT) right_weight = (double)(packed & 0xffffu) * 0.0001;
            if (f & KEY_WEIGHTED_NEXT_LEFT) next_weight_left = (double)(packed >> 16) * 0.0001;
        }
        key->time = t;
        key->value = v;
        if (f & KEY_CONSTANT) {
            key->interp = (f & KEY_CONSTANT_NEXT) ? MK_INTERP_CONSTANT_NEXT : MK_INTERP_CONSTANT;
            right_weight = next_weight_left = THIRD;
            right_slope = next_slope_left = 0.0;
        } else if (f & KEY_CUBIC) {
            key->interp = MK_INTERP_CUBIC;
            /* Cubic keys read their slopes (TCB: tension, continuity, bias) from the data. */
            for (int c = 0; c < ((f & KEY_TCB) ? 3 : 2); c++) {
                if (!isfinite(d[c])) {
                    r = fbx_error_not_finite(doc, fbx_child(curve, "KeyAttrDataFloat"), 4 * attr + (size_t)c,
                                             "tangent data of key %zu", i);
                    goto done;
                }
            }
            int has_prev = i > 0 && t > prev_time, after = has_next && next_t > t;
            if (f & KEY_TCB) {
                /* Kochanek-Bartels on the one-sided secants; factor 1 at an end. */
                double left = has_prev ? (v - values[i - 1]) / (t - prev_time) : 0.0;
                double right = after ? (next_v - v) / (next_t - t) : 0.0;
                double factor = has_prev && after ? 0.5 : 1.0;
                double tension = d[0], continuity = d[1], bias = d[2];
                slope_left = factor * (1 - tension) * ((1 + bias) * (1 - continuity) * left + (1 - bias) * (1 + continuity) * right);
                right_slope = factor * (1 - tension) * ((1 + bias) * (1 + continuity) * left + (1 - bias) * (1 - continuity) * right);
                next_slope_left = 0.0;
                next_weight_left = THIRD;
            } else if (f & KEY_USER) {
                /* stored slopes as they are */
            } else if (has_prev && after) {
                if (fabs(slope_left + right_slope) <= 0.0001) {
                    slope_left = right_slope = auto_tangent(prev_time, t, next_t, values[i - 1], v, next_v, weight_left,
                                                            right_weight, right_slope, f);
                } else {
                    double left_bias = -slope_left, right_bias = right_slope;
                    slope_left = auto_tangent(prev_time, t, next_t, values[i - 1], v, next_v, weight_left, right_weight, left_bias, f);
                    right_slope = auto_tangent(prev_time, t, next_t, values[i - 1], v, next_v, weight_left, right_weight, right_bias, f);
                }
            } else if (has_prev) {
                slope_left = right_slope = auto_tangent_end(prev_time, t, values[i - 1], v, -slope_left, f);
            } else if (after) {
                slope_left = right_slope = auto_tangent_end(t, next_t, v, next_v, right_slope, f);
            } else {
                slope_left = right_slope = 0.0;
            }
        } else {
            /* Linear (or unknown): straight to the next key. */
            key->interp = MK_INTERP_LINEAR;
            right_weight = next_weight_left = THIRD;
            right_slope = next_slope_left = next_t > t ? (next_v - v) / (next_t - t) : 0.0;
        }
        put_tangents(key, &slope_left, &weight_left, right_slope, right_weight, next_slope_left, next_weight_left);
        prev_time = t;
    }
    r = finish(doc, raw, path, k, n, scale, out_keys, out_count);
done:
    mk_arena_release(doc->arena, times);
    mk_arena_release(doc->arena, values);
    mk_arena_release(doc->arena, flags);
    mk_arena_release(doc->arena, data);
    mk_arena_release(doc->arena, refs);
    mk_arena_release(doc->arena, k);
    return r;
}

/* Mode letters are stored as numbers in the key list: out-of-range values are not letters. */
static char key_char(double x)
{
    return x >= 0.0 && x < 128.0 ? (char)(int)x : 0;
}

mk_result fbx_convert_legacy_curve(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *channel, double ticks_per_second,
                                   double scale, mk_key **out_keys, uint32_t *out_count)
{
    char path[160];
    fbx_node_path(channel, path, sizeof path);
    *out_keys = NULL;
    *out_count = 0;
    const fbx_node *key_node = fbx_child(channel, "Key");
    if (!key_node) return MK_OK;
    int64_t key_count = 0, key_version = 0;
    if (!fbx_child_int(channel, "KeyCount", &key_count) || key_count < 0)
        return mk_error_set(doc->err, MK_ERROR_PARSE, channel->offset, "FBX %s: Key without a valid KeyCount", path);
    fbx_child_int(channel, "KeyVer", &key_version);
    double *data = NULL;
    size_t size;
    mk_result r = fbx_node_array(doc, key_node, FBX_ELEM_F64, (void **)&data, &size);
    if (r != MK_OK) return r;
    /* Each key takes at least 3 values: bounds KeyCount before allocating. */
    if ((uint64_t)key_count > size / 3 + 1) {
        mk_arena_release(doc->arena, data);
        return mk_error_set(doc->err, MK_ERROR_PARSE, key_node->offset, "FBX %s: KeyCount %lld exceeds the %zu key values",
                            path, (long long)key_count, size);
    }
    size_t n = (size_t)key_count;
    dkey *k = mk_arena_array(doc->arena, n ? n : 1, sizeof *k);
    if (!k) { mk_arena_release(doc->arena, data); return mk_error_oom(doc->err, "FBX curve"); }
    size_t pos = 0;
    const char *problem = NULL;
    double slope_left = 0.0, weight_left = THIRD, prev_time = 0.0;
#define NEED(count) do { if (size - pos < (size_t)(count)) { problem = "key list ends inside a key"; goto fail; } } while (0)
    /* Values the key uses (time, value, slopes, weights) must be finite; skipped ones need not. */
#define USE(at) do { if (!isfinite(data[at])) { bad = (at); goto not_finite; } } while (0)
    size_t i = 0, bad = 0;
    for (; i < n; i++) {
        dkey *key = &k[i];
        NEED(3);
        USE(pos);
        USE(pos + 1);
        double t = data[pos] / ticks_per_second, v = data[pos + 1];
        char mode = key_char(data[pos + 2]);
        pos += 3;
        double right_slope = 0.0, right_weight = THIRD, next_slope_left = 0.0, next_weight_left = THIRD;
        int auto_slope = 0;
        if (mode == 'U') {
            key->interp = MK_INTERP_CUBIC;
            NEED(1);
            char slope_mode = key_char(data[pos++]);
            int weights = 1;
            if (slope_mode == 's' || slope_mode == 'b') {
                NEED(2);
                USE(pos);
                USE(pos + 1);
                right_slope = data[pos];
                next_slope_left = data[pos + 1];
                pos += 2;
            } else if (slope_mode == 'a') {
                auto_slope = 1;
                if (doc->version == 5000) weights = 0;
            } else if (slope_mode == 'p' || slope_mode == 'q') {
                NEED(2);
                pos += 2;
                weights = 2;
                auto_slope = 1;
            } else if (slope_mode == 't') {
                NEED(3);
                pos += 3;
                weights = 0;
                auto_slope = 1;
            } else if (slope_mode == 'd') {
                NEED(1);
                pos += 1;
                auto_slope = 1;
            } else {
                problem = "unknown cubic slope mode";
                goto fail;
            }
            for (; weights > 0; weights--) {
                NEED(1);
                char weight_mode = key_char(data[pos++]);
                if (weight_mode == 'a') {
                    NEED(2);
                    USE(pos);
                    USE(pos + 1);
                    right_weight = data[pos];
                    next_weight_left = data[pos + 1];
                    pos += 2;
                } else if (weight_mode == 'l') {
                    NEED(1);
                    USE(pos);
                    next_weight_left = data[pos++];
                } else if (weight_mode == 'r') {
                    NEED(1);
                    USE(pos);
                    right_weight = data[pos++];
                } else if (weight_mode != 'n' && weight_mode != 'c') {
                    problem = "unknown tangent weight mode";
                    goto fail;
                }
            }
        } else if (mode == 'L') {
            key->interp = MK_INTERP_LINEAR;
        } else if (mode == 'C') {
            /* The constant sub-mode ('n' next / 's' standard) exists from KeyVer 4004. */
            key->interp = MK_INTERP_CONSTANT;
            if (key_version >= 4004 || key_version == 0) {
                NEED(1);
                if (key_char(data[pos]) == 'n') key->interp = MK_INTERP_CONSTANT_NEXT;
                pos++;
            }
        } else {
            problem = "unknown key interpolation mode";
            goto fail;
        }
        /* Peek the next key for auto and linear slopes. */
        int has_next = i + 1 < n && size - pos >= 2;
        double next_t = has_next ? data[pos] / ticks_per_second : t, next_v = has_next ? data[pos + 1] : v;
        if (auto_slope) {
            /* Legacy auto keys: symmetric, time-independent, clamp-progressive; first key flat. */
            slope_left = right_slope = i > 0 && t > prev_time && next_t > t
                ? auto_tangent(prev_time, t, next_t, k[i - 1].value, v, next_v, weight_left, right_weight, 0.0,
                               KEY_TIME_INDEPENDENT | KEY_CLAMP_PROGRESSIVE)
                : 0.0;
        }
        if (key->interp == MK_INTERP_LINEAR)
            right_slope = next_slope_left = next_t > t ? (next_v - v) / (next_t - t) : 0.0;
        key->time = t;
        key->value = v;
        put_tangents(key, &slope_left, &weight_left, right_slope, right_weight, next_slope_left, next_weight_left);
        prev_time = t;
    }
#undef NEED
#undef USE
    if (pos != size) mk_raw_warn(raw, "FBX %s: %zu trailing key values ignored", path, size - pos);
    r = finish(doc, raw, path, k, n, scale, out_keys, out_count);
    mk_arena_release(doc->arena, data);
    mk_arena_release(doc->arena, k);
    return r;
fail:
    mk_arena_release(doc->arena, data);
    mk_arena_release(doc->arena, k);
    return mk_error_set(doc->err, MK_ERROR_PARSE, key_node->offset, "FBX %s: %s (key value %zu)", path, problem, pos);
not_finite:
    mk_arena_release(doc->arena, data);
    mk_arena_release(doc->arena, k);
    return fbx_error_not_finite(doc, key_node, bad, "key %zu", i);
}

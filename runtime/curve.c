/* SPDX-License-Identifier: MIT */
/* Weight curves and the clip sampling job.
 *
 * A curve is a list of mk_key with strictly increasing times. Segment k -> k+1 follows the
 * interpolation of key k:
 *   constant       v_k
 *   constant-next  v_{k+1} (FBX "constant next": the step happens right after key k)
 *   linear         v_k + (v_{k+1} - v_k) s, s = (t - t_k) / (t_{k+1} - t_k)
 *   cubic          the Bezier in (time, value) with control points
 *                    P0 = (t_k, v_k), P1 = (t_k + wr dt, v_k + sr wr dt),
 *                    P2 = (t_{k+1} - wl dt, v_{k+1} - sl wl dt), P3 = (t_{k+1}, v_{k+1})
 *                  (sr, wr: key k's right slope and weight; sl, wl: key k+1's left ones).
 *                  With wr = wl = 1/3 time is linear in the curve parameter and this is the
 *                  Hermite cubic with slopes sr, sl (glTF CUBICSPLINE, FBX non-weighted keys);
 *                  otherwise the parameter is solved from the time (FBX weighted tangents).
 * Before the first key the curve holds the first value, after the last key the last value.
 */
#include <float.h>
#include <math.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"
#include "determinism.h"
#include "error.h"

static double bezier1(double p0, double p1, double p2, double p3, double u)
{
    double v = 1.0 - u;
    return v * v * v * p0 + 3.0 * v * v * u * p1 + 3.0 * v * u * u * p2 + u * u * u * p3;
}

/* Solves x(u) = s for u in [0, 1] where x is the normalized time Bezier (0, a, b, 1).
 * Newton steps guarded by bisection: x(0) = 0 <= s <= 1 = x(1), so a root is bracketed even
 * when large weights make x non-monotonic; fixed iteration cap keeps it deterministic. */
static double solve_bezier_parameter(double a, double b, double s)
{
    double lo = 0.0, hi = 1.0, u = s;
    for (int i = 0; i < 40; i++) {
        double x = bezier1(0.0, a, b, 1.0, u) - s;
        if (fabs(x) < 1e-12) break;
        if (x > 0) hi = u; else lo = u;
        double v = 1.0 - u;
        double dx = 3.0 * (v * v * a + 2.0 * v * u * (b - a) + u * u * (1.0 - b));
        double next = dx > 1e-12 ? u - x / dx : 0.5 * (lo + hi);
        u = (next <= lo || next >= hi) ? 0.5 * (lo + hi) : next;
    }
    return u;
}

static float segment_value(const mk_key *k0, const mk_key *k1, double time)
{
    double dt = (double)k1->time - (double)k0->time;
    double s = (time - (double)k0->time) / dt;
    switch (k0->interp) {
    case MK_INTERP_CONSTANT: return k0->value;
    case MK_INTERP_CONSTANT_NEXT: return s > 0 ? k1->value : k0->value;
    case MK_INTERP_LINEAR: return (float)((double)k0->value + ((double)k1->value - (double)k0->value) * s);
    default: break;
    }
    double wr = k0->right_weight, wl = k1->left_weight;
    double p1 = (double)k0->value + (double)k0->right_slope * wr * dt;
    double p2 = (double)k1->value - (double)k1->left_slope * wl * dt;
    double u = s;
    if (fabs(wr - 1.0 / 3.0) > 1e-6 || fabs(wl - 1.0 / 3.0) > 1e-6)
        u = solve_bezier_parameter(wr, 1.0 - wl, s);
    /* Steep finite slopes can exceed float range: saturate so sampling stays finite. */
    double v = bezier1(k0->value, p1, p2, k1->value, u);
    return (float)(v > FLT_MAX ? FLT_MAX : v < -FLT_MAX ? -FLT_MAX : v);
}

/* Index k of the segment with keys[k].time <= time < keys[k+1].time (count >= 2, time inside). */
static uint32_t find_segment(const mk_key *keys, uint32_t count, double time, uint32_t *cursor)
{
    if (cursor && *cursor < count - 1) {   /* count >= 2 here; no wrap for any cursor value */
        uint32_t c = *cursor;
        if (keys[c].time <= time && time < keys[c + 1].time) return c;
        if (c + 2 < count && keys[c + 1].time <= time && time < keys[c + 2].time) return *cursor = c + 1;
    }
    uint32_t lo = 0, hi = count - 1; /* invariant: keys[lo].time <= time < keys[hi].time */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (keys[mid].time <= time) lo = mid; else hi = mid;
    }
    if (cursor) *cursor = lo;
    return lo;
}

float mk_curve_eval(const mk_key *keys, uint32_t count, double time, uint32_t *cursor)
{
    if (!keys || count == 0) return 0.0f;
    if (!(time > keys[0].time)) return keys[0].value;  /* also NaN-safe */
    if (time >= keys[count - 1].time) return keys[count - 1].value;
    uint32_t k = find_segment(keys, count, time, cursor);
    return segment_value(&keys[k], &keys[k + 1], time);
}

mk_result mk_sample_validate(const mk_sample_job *job, mk_error *err)
{
    if (!job || !job->asset) return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "sample job or its asset is NULL");
    const mk_asset *a = job->asset;
    if (job->clip >= a->clip_count) return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "sample job: clip index out of range");
    if (!isfinite(job->time)) return mk_error_fail(err, MK_ERROR_NOT_FINITE, MK_NO_OFFSET, "sample job: time is NaN or infinite");
    if (a->channel_count && !job->weights)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "sample job: weights output is NULL");
    if (job->weight_count < a->channel_count)
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "sample job: weight_count is less than the asset's channel count");
    if (job->cursors && job->cursor_count < a->clips[job->clip].track_count)
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "sample job: fewer cursors than the clip has tracks");
    return MK_OK;
}

mk_result mk_sample_run(const mk_sample_job *job, mk_error *err)
{
    mk_result r = mk_sample_validate(job, err);
    if (r != MK_OK) return r;
    const mk_asset *a = job->asset;
    const mk_blob_clip *clip = &a->clips[job->clip];
    double time = job->time;
    if (job->loop && clip->duration > 0) {
        double local = fmod(time - clip->start, clip->duration);
        if (local < 0) local += clip->duration;
        if (local >= clip->duration) local = 0;   /* rounding of a tiny negative remainder */
        time = clip->start + local;
    }
    for (uint32_t c = 0; c < a->channel_count; c++) job->weights[c] = a->channels[c].default_weight;
    for (uint32_t k = 0; k < clip->track_count; k++) {
        const mk_blob_track *t = &a->tracks[clip->first_track + k];
        uint32_t *cursor = job->cursors ? &job->cursors[k] : NULL;
        job->weights[t->channel] = mk_curve_eval(&a->keys[t->first_key], t->key_count, time, cursor);
    }
    return MK_OK;
}

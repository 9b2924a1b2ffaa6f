/* SPDX-License-Identifier: MIT */
/* The reference evaluator (see reference_eval.h): docs/semantics.md in double precision.
 *
 * The semantics part (key points, span rule, D(w), beta, the stacking recurrence, nlerp,
 * slerp, tangents) follows the document's wording one rule per function. The bookkeeping part
 * bounds what a float32 runtime may differ by:
 *   - float rounding: each float operation errs by at most u = 2^-24 of its result. A value
 *     the runtime computes as B + sum of coefficient * delta, with coefficients from a few
 *     float operations per channel (t, 1 - t, beta, 1 - beta, the products), errs by at most
 *     gamma * (|B| + sum_c (1 + |t_c|)(|delta_a| + |delta_b|)), gamma = u (8C + 16) for C
 *     channels: a few ulps per operation on the chain, of the magnitudes involved;
 *   - quantized deltas: each stored component is within the writer's reported error q of the
 *     exact delta, so a sum errs by q * sum |coefficients| (the stacked coefficient sum);
 *   - normalizing: a vector error e moves the direction of a vector of length L by at most
 *     asin(e / L); slerp's sensitivity to its ends and to the angle's rounding is bounded by
 *     sampling its weights over the angle's error interval (see slerp_error). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "reference_eval.h"

#define UNIT_ROUNDOFF ((double)FLT_EPSILON / 2)   /* u = 2^-24 */
#define SHORT_VECTOR 1e-8                         /* docs/semantics.md: shorter vectors fall back */
#define SLERP_MIN_SIN 1e-6                        /* docs/semantics.md: below, slerp is the lerp */
#define MAX_KEYS 256
#define PI 3.14159265358979323846

void ref_job_init(ref_job *job, const mk_raw_asset *raw, uint32_t mesh, const float *weights, mk_stacking stacking,
                  mk_normal_mode normal_mode, ref_stored_error stored)
{
    memset(job, 0, sizeof *job);
    job->raw = raw;
    job->mesh = mesh;
    job->weights = weights;
    job->stacking = stacking;
    job->normal_mode = normal_mode;
    job->stored = stored;
    uint32_t c = 0;
    while (c < raw->channel_count && raw->channels[c].mesh != mesh) c++;
    job->first_channel = c;
    while (c < raw->channel_count && raw->channels[c].mesh == mesh) c++;
    job->channel_count = c - job->first_channel;
}

/* ---- vectors ---- */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double length3(const double *a) { return sqrt(dot3(a, a)); }

/* normalize(x) = x / |x|; a vector shorter than 1e-8 is replaced by the fallback. */
static void normalize_or(const double *x, const double *fallback, double *out)
{
    double len = length3(x);
    for (int k = 0; k < 3; k++) out[k] = len < SHORT_VECTOR ? fallback[k] : x[k] / len;
}

/* ---- channel displacement D(w) ---- */

typedef enum attribute { POSITIONS, NORMALS, TANGENTS } attribute;

/* A key point: (full weight, target), target NULL for the implicit (0, 0). */
typedef struct key_point {
    double weight;
    const mk_raw_target *target;
} key_point;

/* The channel's key points, the implicit (0, 0) and each (f_k, delta_k), sorted by weight. */
static uint32_t key_points(const mk_raw_channel *ch, key_point *keys)
{
    if (ch->target_count + 1 > MAX_KEYS) {
        fprintf(stderr, "reference: channel '%s' has more than %d targets\n", ch->name ? ch->name : "", MAX_KEYS - 1);
        abort();
    }
    uint32_t n = 0;
    keys[n++] = (key_point){ 0.0, NULL };
    for (uint32_t k = 0; k < ch->target_count; k++) keys[n++] = (key_point){ ch->targets[k].full_weight, &ch->targets[k] };
    for (uint32_t i = 1; i < n; i++)   /* insertion sort: a handful of keys */
        for (uint32_t j = i; j > 0 && keys[j].weight < keys[j - 1].weight; j--) {
            key_point tmp = keys[j];
            keys[j] = keys[j - 1];
            keys[j - 1] = tmp;
        }
    return n;
}

/* The span of w: key points a and b and the span parameter t. */
typedef struct span {
    const mk_raw_target *a, *b;     /* NULL: the implicit zero key */
    double t;
} span;

/* "span j covers key points j and j+1; the span is the first whose upper end is >= w, else
 * the last"; t = (w - w_a) / (w_b - w_a). */
static span channel_span(const mk_raw_channel *ch, double w)
{
    key_point keys[MAX_KEYS];
    uint32_t n = key_points(ch, keys);
    uint32_t j = 0;
    while (j < n - 2 && !(keys[j + 1].weight >= w)) j++;
    span s = { keys[j].target, keys[j + 1].target, (w - keys[j].weight) / (keys[j + 1].weight - keys[j].weight) };
    return s;
}

/* Where a target stores render vertex v: its entry, or -1 where it does not move v (or for
 * the implicit key). Indices are strictly increasing: binary search. */
static int64_t target_entry(const mk_raw_target *target, uint32_t v)
{
    if (!target) return -1;
    uint32_t lo = 0, hi = target->count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (target->indices[mid] < v) lo = mid + 1; else hi = mid;
    }
    return lo < target->count && target->indices[lo] == v ? (int64_t)lo : -1;
}

/* A target's delta of one attribute at its entry: 0 where it does not move the vertex, for a
 * target without that attribute, and for the implicit key. */
static void target_delta(const mk_raw_target *target, int64_t entry, attribute which, double *out)
{
    out[0] = out[1] = out[2] = 0.0;
    if (!target || entry < 0) return;
    const float *values = which == POSITIONS ? target->positions : which == NORMALS ? target->normals : target->tangents;
    if (!values) return;
    for (int k = 0; k < 3; k++) out[k] = values[3 * (size_t)entry + (size_t)k];
}

/* The span's ends at one vertex: the targets and their entries for it. */
typedef struct span_ends {
    const mk_raw_target *a, *b;
    int64_t entry_a, entry_b;
    double t;
} span_ends;

/* D(w) = (1 - t) delta_a + t delta_b, delta = 0 for the implicit key. */
static void displacement(const span_ends *s, attribute which, double *out)
{
    double da[3], db[3];
    target_delta(s->a, s->entry_a, which, da);
    target_delta(s->b, s->entry_b, which, db);
    for (int k = 0; k < 3; k++) out[k] = (1.0 - s->t) * da[k] + s->t * db[k];
}

/* ---- stacking ---- */

/* beta_c = clamp(w_c / f_first, 0, 1), f_first the smallest positive full weight, 0 without
 * one; additive stacking is the recurrence with beta = 0. */
static double stacking_beta(mk_stacking stacking, const mk_raw_channel *ch, double w)
{
    if (stacking != MK_STACKING_SEQUENTIAL) return 0.0;
    double f_first = 0.0;
    for (uint32_t k = 0; k < ch->target_count; k++) {
        double f = ch->targets[k].full_weight;
        if (f > 0 && (f_first == 0.0 || f < f_first)) f_first = f;
    }
    if (f_first == 0.0) return 0.0;
    double beta = w / f_first;
    return beta < 0 ? 0 : beta > 1 ? 1 : beta;
}

/* ---- slerp ---- */

/* sin theta = |n_a x n_b| */
static double sin_between(const double *a, const double *b)
{
    double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
    return length3(c);
}

/* Weights of n_a and n_b in slerp(n_a, n_b, t) at angle theta with sine s:
 * sin((1 - t) theta) / s and sin(t theta) / s, or the lerp's 1 - t and t where s < 1e-6. */
static void slerp_weights(double theta, double s, double t, double *wa, double *wb)
{
    if (s < SLERP_MIN_SIN) {
        *wa = 1.0 - t;
        *wb = t;
    } else {
        *wa = sin((1.0 - t) * theta) / s;
        *wb = sin(t * theta) / s;
    }
}

/* theta = atan2(|n_a x n_b|, n_a . n_b) */
static void slerp(const double *na, const double *nb, double t, double *out)
{
    double s = sin_between(na, nb), theta = atan2(s, dot3(na, nb)), wa, wb;
    slerp_weights(theta, s, t, &wa, &wb);
    for (int k = 0; k < 3; k++) out[k] = wa * na[k] + wb * nb[k];
}

/* Bound on |float32 slerp - slerp| (bookkeeping). delta_a, delta_b bound the errors of the
 * runtime's unit ends; the angle it computes (atan2, accurate to a few ulps) errs by about
 * delta_a + delta_b + 8u. In the slerp branch the weights are sampled at both ends of that
 * interval (over so short an interval the deviation grows monotonically); twice the largest
 * deviation is allowed. Sets *unstable where sin theta is so close to 1e-6 at nearly opposite
 * ends that float may take the other branch (near parallel ends both branches agree). */
static double slerp_error(const double *na, const double *nb, double t, double delta_a, double delta_b, int *unstable,
                          double *weight_sum)
{
    const double u = UNIT_ROUNDOFF;
    double s = sin_between(na, nb), theta = atan2(s, dot3(na, nb)), wa, wb;
    slerp_weights(theta, s, t, &wa, &wb);
    *weight_sum = fabs(wa) + fabs(wb);
    double delta = delta_a + delta_b, theta_error = delta + 8 * u;
    if (theta > PI / 2 && fabs(s - SLERP_MIN_SIN) <= 2 * theta_error) *unstable = 1;
    double deviation = 0;
    for (int i = -1; i <= 1 && s >= SLERP_MIN_SIN; i += 2) {
        double th = theta + theta_error * i, a2, b2, e[3];
        th = th < 0 ? 0 : th > PI ? PI : th;
        slerp_weights(th, sin(th), t, &a2, &b2);
        for (int k = 0; k < 3; k++) e[k] = (a2 - wa) * na[k] + (b2 - wb) * nb[k];
        double len = length3(e);
        if (len > deviation) deviation = len;
    }
    return 2 * (*weight_sum * delta + deviation) + 8 * u * *weight_sum;
}

/* Error bound of the runtime's unit vector normalize(x), x = B_n + delta (exact here): the
 * stored delta's error (a quantized delta also rounds when scaled back, by u |delta|; a float
 * one is read exactly), the float sum's rounding (u |x| per component, so an exact zero stays
 * zero) and the normalization's (4u), divided by |x|. Sets *unstable when |x| is so close to
 * 1e-8 that the fallback choice is uncertain. */
static double unit_error(const double *x, double delta_length, double stored, int *unstable)
{
    const double u = UNIT_ROUNDOFF;
    double len = length3(x), e = sqrt(3.0) * (stored > 0 ? stored + u * delta_length : 0.0) + sqrt(3.0) * u * len;
    if (fabs(len - SHORT_VECTOR) <= e + 0.01 * SHORT_VECTOR) *unstable = 1;
    return len < SHORT_VECTOR ? 4 * u : 2 * e / len + 4 * u;
}

/* ---- one vertex ---- */

void ref_eval_vertex(const ref_job *job, uint32_t v, ref_vertex *out)
{
    const double u = UNIT_ROUNDOFF;
    const mk_raw_mesh *m = &job->raw->meshes[job->mesh];
    double base[3], base_n[3] = { 0, 0, 0 }, base_t[4] = { 0, 0, 0, 0 }, n0[3] = { 0, 0, 0 };
    for (int k = 0; k < 3; k++) base[k] = m->positions[3 * (size_t)v + (size_t)k];
    if (m->normals) {
        for (int k = 0; k < 3; k++) base_n[k] = m->normals[3 * (size_t)v + (size_t)k];
        normalize_or(base_n, base_n, n0);   /* n0 = normalize(B_n), B_n itself if shorter than 1e-8 */
    }
    if (m->tangents)
        for (int k = 0; k < 4; k++) base_t[k] = m->tangents[4 * (size_t)v + (size_t)k];

    /* d_0 = 0; d_c = (1 - beta_c) d_{c-1} + D_c(w_c), for positions, normals, tangents. */
    double d[3] = { 0, 0, 0 }, dn[3] = { 0, 0, 0 }, dt[3] = { 0, 0, 0 };
    /* bookkeeping */
    double mag_p[3], mag_n[3], mag_t[3], coefficient_sum = 0, slerp_err = 0, slerp_mag = 0;
    int unstable = 0;
    for (int k = 0; k < 3; k++) {
        mag_p[k] = fabs(base[k]);
        mag_n[k] = fabs(base_n[k]);
        mag_t[k] = fabs(base_t[k]);
    }

    for (uint32_t c = 0; c < job->channel_count; c++) {
        const mk_raw_channel *ch = &job->raw->channels[job->first_channel + c];
        const double w = job->weights[c];
        const span sp = channel_span(ch, w);
        const span_ends s = { sp.a, sp.b, target_entry(sp.a, v), target_entry(sp.b, v), sp.t };
        const double beta = stacking_beta(job->stacking, ch, w);

        double D[3];
        displacement(&s, POSITIONS, D);
        for (int k = 0; k < 3; k++) d[k] = (1.0 - beta) * d[k] + D[k];

        if (m->normals) {
            double Dn[3] = { 0, 0, 0 };
            if (job->normal_mode == MK_NORMALS_NLERP) {
                displacement(&s, NORMALS, Dn);
            } else {
                int has_normal_data = 0;
                for (uint32_t k = 0; k < ch->target_count; k++) has_normal_data |= ch->targets[k].normals != NULL;
                if (has_normal_data) {
                    /* n_a = normalize(B_n + dn_a) (n0 for the implicit key and short vectors). */
                    double da[3], db[3], xa[3], xb[3], na[3], nb[3], sl[3];
                    target_delta(s.a, s.entry_a, NORMALS, da);
                    target_delta(s.b, s.entry_b, NORMALS, db);
                    for (int k = 0; k < 3; k++) {
                        xa[k] = base_n[k] + da[k];
                        xb[k] = base_n[k] + db[k];
                    }
                    if (s.a) normalize_or(xa, n0, na); else memcpy(na, n0, sizeof na);
                    if (s.b) normalize_or(xb, n0, nb); else memcpy(nb, n0, sizeof nb);
                    slerp(na, nb, s.t, sl);
                    for (int k = 0; k < 3; k++) Dn[k] = sl[k] - n0[k];

                    /* bookkeeping: this channel's Dn error, stacked like Dn */
                    double qa = s.a && s.a->normals ? job->stored.normal : 0, qb = s.b && s.b->normals ? job->stored.normal : 0;
                    double ea = s.a ? unit_error(xa, length3(da), qa, &unstable) : 4 * u;
                    double eb = s.b ? unit_error(xb, length3(db), qb, &unstable) : 4 * u;
                    double weight_sum;
                    slerp_err = (1.0 - beta) * slerp_err + slerp_error(na, nb, s.t, ea, eb, &unstable, &weight_sum) + 4 * u;
                    slerp_mag += weight_sum + 1;
                }
            }
            for (int k = 0; k < 3; k++) dn[k] = (1.0 - beta) * dn[k] + Dn[k];
        }
        if (m->tangents) {
            double Dt[3];
            displacement(&s, TANGENTS, Dt);
            for (int k = 0; k < 3; k++) dt[k] = (1.0 - beta) * dt[k] + Dt[k];
        }

        /* bookkeeping: magnitudes (not decayed: an upper bound) and the stacked sum of
         * |coefficients| of stored deltas. */
        double pa[3], pb[3], na_[3], nb_[3], ta[3], tb[3];
        target_delta(s.a, s.entry_a, POSITIONS, pa);
        target_delta(s.b, s.entry_b, POSITIONS, pb);
        target_delta(s.a, s.entry_a, NORMALS, na_);
        target_delta(s.b, s.entry_b, NORMALS, nb_);
        target_delta(s.a, s.entry_a, TANGENTS, ta);
        target_delta(s.b, s.entry_b, TANGENTS, tb);
        double reach = 1.0 + fabs(s.t);
        for (int k = 0; k < 3; k++) {
            mag_p[k] += reach * (fabs(pa[k]) + fabs(pb[k]));
            mag_n[k] += reach * (fabs(na_[k]) + fabs(nb_[k]));
            mag_t[k] += reach * (fabs(ta[k]) + fabs(tb[k]));
        }
        coefficient_sum = (1.0 - beta) * coefficient_sum + (s.a ? fabs(1.0 - s.t) : 0.0) + (s.b ? fabs(s.t) : 0.0);
    }

    /* P = B + d; n = normalize(B_n + d_n), B_n kept below 1e-8; tangents likewise, base w. */
    double sum_n[3], sum_t[3];
    for (int k = 0; k < 3; k++) {
        out->position[k] = base[k] + d[k];
        sum_n[k] = base_n[k] + dn[k];
        sum_t[k] = base_t[k] + dt[k];
    }
    out->normal_length = length3(sum_n);
    normalize_or(sum_n, base_n, out->normal);
    out->tangent_length = length3(sum_t);
    normalize_or(sum_t, base_t, out->tangent);
    out->tangent[3] = base_t[3];

    /* bookkeeping: tolerances */
    const double gamma = u * (8.0 * job->channel_count + 16.0);
    double en2 = 0, et2 = 0;
    for (int k = 0; k < 3; k++) {
        out->position_tolerance[k] = gamma * mag_p[k] + job->stored.position * coefficient_sum;
        double en = gamma * mag_n[k] + job->stored.normal * coefficient_sum;
        double et = gamma * mag_t[k] + job->stored.tangent * coefficient_sum;
        en2 += en * en;
        et2 += et * et;
    }
    out->normal_error = job->normal_mode == MK_NORMALS_NLERP ? sqrt(en2)
                                                             : slerp_err + gamma * (length3(base_n) + slerp_mag);
    out->tangent_error = sqrt(et2);
    out->normal_unstable = unstable;
}

/* ---- comparison ---- */

static double angle_between(const double *a, const double *b)
{
    double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
    return atan2(length3(c), dot3(a, b));
}

typedef struct compare_state {
    ref_mismatch *mismatch;
    ref_stats *stats;
    uint32_t count;
} compare_state;

static void record(compare_state *st, uint32_t v, const char *what, int component, double got, double expected,
                   double tolerance)
{
    double error = fabs(got - expected);
    if (component < 0) error = got;   /* angles: got is the angle, expected 0 */
    if (error <= tolerance) {
        int kind = what[0] == 'p' ? 0 : what[0] == 'n' ? 1 : 2;
        if (component >= 0 && kind) return;   /* unit length and tangent w: not ratios of interest */
        if (tolerance > 0 && st->stats && error / tolerance > st->stats->worst_ratio[kind])
            st->stats->worst_ratio[kind] = error / tolerance;
        return;
    }
    if (st->count++ == 0 && st->mismatch) *st->mismatch = (ref_mismatch){ v, what, component, got, expected, tolerance };
}

/* A unit direction (normal or tangent xyz) of the runtime against the reference: exactly the
 * base where the reference sum is surely below the 1e-8 fallback, within the angle bound where
 * it is surely above, not compared in between. */
static void compare_direction(compare_state *st, uint32_t v, const char *what, const float *got, const float *base,
                              const double *expected, double length, double error, int unstable)
{
    const double u = UNIT_ROUNDOFF;
    if (unstable) { if (st->stats) st->stats->normals_skipped++; return; }
    if (length + error < 0.99 * SHORT_VECTOR) {
        for (int k = 0; k < 3; k++) record(st, v, what, k, got[k], base[k], 0.0);
        return;
    }
    if (!(length - error > 1.01 * SHORT_VECTOR) || error >= length) {
        if (st->stats) st->stats->normals_skipped++;
        return;
    }
    double g[3] = { got[0], got[1], got[2] };
    double len = length3(g);
    record(st, v, what, 3, len, 1.0, 8 * u);   /* unit length */
    double angle = angle_between(g, expected);
    record(st, v, what, -1, angle != angle ? INFINITY : angle, 0.0, asin(error / length) + 4 * u);
}

void ref_eval_mesh(const ref_job *job, ref_vertex *out)
{
    for (uint32_t v = 0; v < job->raw->meshes[job->mesh].vertex_count; v++) ref_eval_vertex(job, v, &out[v]);
}

uint32_t ref_compare(const ref_job *job, const ref_vertex *expected, uint32_t first, uint32_t count,
                     const float *positions, const float *normals, const float *tangents, ref_mismatch *mismatch,
                     ref_stats *stats)
{
    const mk_raw_mesh *m = &job->raw->meshes[job->mesh];
    compare_state st = { mismatch, stats, 0 };
    for (uint32_t i = 0; i < count; i++) {
        const uint32_t v = first + i;
        const ref_vertex *r = &expected[v];
        if (stats) stats->vertices++;
        for (int k = 0; k < 3; k++)
            record(&st, v, "position", k, positions[3 * (size_t)i + (size_t)k], r->position[k], r->position_tolerance[k]);
        if (normals && m->normals)
            compare_direction(&st, v, "normal", normals + 3 * (size_t)i, m->normals + 3 * (size_t)v, r->normal,
                              r->normal_length, r->normal_error, r->normal_unstable);
        if (tangents && m->tangents) {
            compare_direction(&st, v, "tangent", tangents + 4 * (size_t)i, m->tangents + 4 * (size_t)v, r->tangent,
                              r->tangent_length, r->tangent_error, 0);
            record(&st, v, "tangent w", 3, tangents[4 * (size_t)i + 3], r->tangent[3], 0.0);
        }
    }
    return st.count;
}

/* SPDX-License-Identifier: MIT */
/* Adaptive in-betweens: sample a deformation at amplitudes 0..1 and write the targets that make
 * the runtime's piecewise-linear playback follow it within a tolerance.
 *
 * Conventions fixed here:
 * - Weight w plays amplitude w; keys sit on the sampling grid k/M (M = options.samples), and a
 *   key's target is the deformation evaluated at exactly its stored float full weight.
 * - Playback error at weight w is max over vertices of |D_true(w) - D_play(w)| (Euclidean, mesh
 *   units), reported as a fraction of the mesh's bounding-box diagonal. D_play uses the
 *   runtime's own span coefficients (mk_channel_span), so the reported number is what plays.
 * - The search works against 0.99 x tolerance: float rounding of the stored deltas and of the
 *   runtime's arithmetic then cannot push a sampled weight over the tolerance.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "inbetween.h"
#include "bake_util.h"

/* Dense per-sample caches above this size fall back to recomputing samples. */
#define CACHE_LIMIT_BYTES ((size_t)512 << 20)

typedef struct sampler {
    mk_arena *arena;
    const mk_raw_mesh *mesh;
    const mk_deformer *deformer;
    uint32_t samples;           /* M */
    size_t n;                   /* vertex count */
    double *work;               /* 3n doubles: deformer output */
    float **cache;              /* M + 1 slots of 3n float deltas, or NULL */
    float *slot[3];             /* no-cache mode: a few buffers with the sample they hold */
    int64_t slot_k[3];
    uint32_t evaluations;
    uint32_t inverted;
} sampler;

static double grid_weight(uint32_t k, uint32_t m)
{
    /* The float the runtime will see as full weight, back in double. */
    return (double)(float)((double)k / (double)m);
}

static mk_result eval_deltas(sampler *s, double amplitude, float *out, mk_error *err)
{
    uint32_t inverted = 0;
    mk_result r = s->deformer->eval(s->deformer->user, amplitude, s->work, NULL, NULL, &inverted, err);
    if (r != MK_OK) return r;
    s->evaluations++;
    if (inverted > s->inverted) s->inverted = inverted;
    for (size_t i = 0; i < 3 * s->n; i++) {
        if (!isfinite(s->work[i]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                "deformation is not finite at vertex %zu (amplitude %g)", i / 3, amplitude);
        out[i] = (float)(s->work[i] - (double)s->mesh->positions[i]);
    }
    return MK_OK;
}

/* Deltas at grid index k (k = 0 is the rest pose: zeros). `which` picks the scratch slot in
 * no-cache mode (0: span start, 1: span end, 2: interior sample). */
static const float *get_sample(sampler *s, uint32_t k, int which, mk_error *err)
{
    if (s->cache) {
        if (!s->cache[k]) {
            float *buf = mk_arena_array(s->arena, s->n ? 3 * s->n : 1, sizeof(float));
            if (!buf) { mk_error_oom(err, "in-between samples"); return NULL; }
            if (k > 0 && eval_deltas(s, grid_weight(k, s->samples), buf, err) != MK_OK) return NULL;
            s->cache[k] = buf;
        }
        return s->cache[k];
    }
    if (s->slot_k[which] == (int64_t)k) return s->slot[which];
    for (int i = 0; i < 3; i++)
        if (s->slot_k[i] == (int64_t)k) {
            memcpy(s->slot[which], s->slot[i], 3 * s->n * sizeof(float));
            s->slot_k[which] = k;
            return s->slot[which];
        }
    if (k == 0) memset(s->slot[which], 0, 3 * s->n * sizeof(float));
    else if (eval_deltas(s, grid_weight(k, s->samples), s->slot[which], err) != MK_OK) return NULL;
    s->slot_k[which] = k;
    return s->slot[which];
}

/* max_v |D(s) - ((1 - t) D(a) + t D(c))| for one interior sample. */
static double sample_error(const float *da, const float *dc, const float *ds, double t, size_t n)
{
    double worst2 = 0;
    for (size_t v = 0; v < n; v++) {
        double e2 = 0;
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * v + (size_t)c;
            double play = (1 - t) * (double)da[i] + t * (double)dc[i];
            double e = (double)ds[i] - play;
            e2 += e * e;
        }
        if (e2 > worst2) worst2 = e2;
    }
    return sqrt(worst2);
}

/* Error of linear playback over the span (a, c) of grid indices; stops early above `limit`
 * (returns a value > limit then). Returns < 0 on error. The midpoint is checked first: that
 * is where the chord of a smooth path is farthest from it, so failing spans fail fast. */
static double span_error(sampler *s, uint32_t a, uint32_t c, double limit, mk_error *err)
{
    const float *da = get_sample(s, a, 0, err);
    if (!da) return -1;
    const float *dc = get_sample(s, c, 1, err);
    if (!dc) return -1;
    if (!s->cache) da = get_sample(s, a, 0, err);  /* slot 0 still holds a; re-fetch is free */
    if (!da) return -1;
    double fa = grid_weight(a, s->samples), fc = grid_weight(c, s->samples);
    double worst = 0;
    uint32_t mid = a + (c - a) / 2;
    for (uint32_t q = 0; q + a + 1 < c; q++) {
        /* visit mid first, then the others in order */
        uint32_t k = q == 0 ? mid : (a + q < mid ? a + q : a + q + 1);
        if (k <= a || k >= c) continue;
        const float *ds = get_sample(s, k, 2, err);
        if (!ds) return -1;
        double t = (grid_weight(k, s->samples) - fa) / (fc - fa);
        double e = sample_error(da, dc, ds, t, s->n);
        if (e > worst) worst = e;
        if (worst > limit) break;
    }
    return worst;
}

/* Playback error of the keys at every grid weight, with the runtime's span coefficients.
 * key_deltas[i] holds the stored deltas of the target at full weight full[i]. Returns < 0 on
 * error. */
static double verify_grid(sampler *s, const float *full, float *const *key_deltas,
                          uint32_t key_count, void (*progress)(void *, const char *, double),
                          void *user, const char *name, double *curve, mk_error *err)
{
    double worst = 0;
    if (curve) curve[0] = 0;
    for (uint32_t k = 1; k <= s->samples; k++) {
        int32_t ia, ib;
        float ca, cb, t;
        mk_channel_span(full, key_count, (float)((double)k / s->samples), &ia, &ca, &ib, &cb, &t);
        const float *ds = get_sample(s, k, 2, err);
        if (!ds) return -1;
        const float *da = ia >= 0 ? key_deltas[ia] : NULL;
        const float *db = ib >= 0 ? key_deltas[ib] : NULL;
        double worst2 = 0;
        for (size_t v = 0; v < s->n; v++) {
            double e2 = 0;
            for (int c = 0; c < 3; c++) {
                size_t i = 3 * v + (size_t)c;
                double play = (da ? (double)ca * da[i] : 0) + (db ? (double)cb * db[i] : 0);
                double e = (double)ds[i] - play;
                e2 += e * e;
            }
            if (e2 > worst2) worst2 = e2;
        }
        if (sqrt(worst2) > worst) worst = sqrt(worst2);
        if (curve) curve[k] = sqrt(worst2);
        if (progress && (k & 15) == 0) progress(user, name, (double)k / s->samples);
    }
    return worst;
}

/* Does the deformation move vertex v (position beyond eps_p, or normal/tangent beyond eps_n)?
 * nrm/tan NULL when the target stores none. */
static int vertex_moved(const mk_raw_mesh *mesh, size_t v, const double *pos, const double *nrm, const double *tan,
                        double eps_p, double eps_n)
{
    double dp[3], dn = 0, dt = 0;
    for (int c = 0; c < 3; c++) {
        size_t i = 3 * v + (size_t)c;
        dp[c] = pos[i] - mesh->positions[i];
        if (nrm) dn = fmax(dn, fabs(nrm[i] - mesh->normals[i]));
        if (tan) dt = fmax(dt, fabs(tan[i] - mesh->tangents[4 * v + (size_t)c]));
    }
    return vec3_length(dp) > eps_p || dn > eps_n || dt > eps_n;
}

static mk_result write_target(mk_raw_asset *raw, mk_raw_channel *channel, uint32_t mesh_index,
                              const mk_deformer *deformer, double weight, const char *name,
                              double diagonal, const float *deltas, double *pos, double *nrm,
                              double *tan, uint32_t *moved, uint32_t *inverted, mk_error *err)
{
    const mk_raw_mesh *mesh = &raw->meshes[mesh_index];
    size_t n = mesh->vertex_count;
    int want_normals = deformer->analytic_normals && mesh->normals;
    int want_tangents = deformer->analytic_normals && mesh->normals && mesh->tangents;
    if (deltas && !want_normals) {
        /* Already evaluated while placing the keys (same float rounding): no second solve. */
        for (size_t i = 0; i < 3 * n; i++) pos[i] = (double)mesh->positions[i] + (double)deltas[i];
    } else {
        uint32_t inv = 0;
        mk_result r = deformer->eval(deformer->user, weight, pos, want_normals ? nrm : NULL,
                                     want_tangents ? tan : NULL, &inv, err);
        if (r != MK_OK) return r;
        if (inv > *inverted) *inverted = inv;
    }
    return bake_store_target(raw, channel, mesh_index, weight, name, diagonal, pos, want_normals ? nrm : NULL,
                             want_tangents ? tan : NULL, moved, err);
}

mk_result bake_store_target(mk_raw_asset *raw, mk_raw_channel *channel, uint32_t mesh_index, double weight,
                            const char *name, double diagonal, const double *pos, const double *nrm,
                            const double *tan, uint32_t *moved, mk_error *err)
{
    const mk_raw_mesh *mesh = &raw->meshes[mesh_index];
    size_t n = mesh->vertex_count;
    int want_normals = nrm != NULL, want_tangents = tan != NULL;
    double eps_p = 1e-7 * diagonal, eps_n = 1e-6;
    uint32_t count = 0;
    for (size_t v = 0; v < n; v++) {
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * v + (size_t)c;
            if (!isfinite(pos[i]) || (want_normals && !isfinite(nrm[i])) ||
                (want_tangents && !isfinite(tan[i])))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                    "deformation is not finite at vertex %zu (weight %g)", v, weight);
        }
        /* finite doubles whose deltas overflow the stored floats (a huge taper scale) */
        for (int c = 0; c < 3; c++)
            if (!isfinite((float)(pos[3 * v + (size_t)c] - (double)mesh->positions[3 * v + (size_t)c])))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                    "deformation moves vertex %zu beyond the float range (weight %g)", v, weight);
        if (vertex_moved(mesh, v, pos, want_normals ? nrm : NULL, want_tangents ? tan : NULL, eps_p, eps_n)) count++;
    }
    mk_raw_target *target = mk_raw_add_targets(raw, channel, 1);
    if (!target) return mk_error_oom(err, "baked target");
    target->name = mk_arena_strdup(&raw->arena, name);
    target->full_weight = (float)weight;
    target->count = count;
    target->indices = mk_arena_array(&raw->arena, count ? count : 1, sizeof(uint32_t));
    target->positions = mk_arena_array(&raw->arena, count ? 3 * (size_t)count : 1, sizeof(float));
    if (want_normals)
        target->normals = mk_arena_array(&raw->arena, count ? 3 * (size_t)count : 1, sizeof(float));
    if (want_tangents)
        target->tangents = mk_arena_array(&raw->arena, count ? 3 * (size_t)count : 1, sizeof(float));
    if (!target->name || !target->indices || !target->positions ||
        (want_normals && !target->normals) || (want_tangents && !target->tangents))
        return mk_error_oom(err, "baked target");
    uint32_t k = 0;
    for (size_t v = 0; v < n; v++) {
        if (!vertex_moved(mesh, v, pos, want_normals ? nrm : NULL, want_tangents ? tan : NULL, eps_p, eps_n)) continue;
        target->indices[k] = (uint32_t)v;
        for (int c = 0; c < 3; c++) {
            /* Same float rounding as the sampler's deltas, so verified error == stored error. */
            target->positions[3 * (size_t)k + c] = (float)(pos[3 * v + (size_t)c] - (double)mesh->positions[3 * v + (size_t)c]);
            if (want_normals)
                target->normals[3 * (size_t)k + c] = (float)(nrm[3 * v + (size_t)c] - mesh->normals[3 * v + (size_t)c]);
            if (want_tangents)
                target->tangents[3 * (size_t)k + c] = (float)(tan[3 * v + (size_t)c] - mesh->tangents[4 * v + (size_t)c]);
        }
        k++;
    }
    *moved = count;
    return MK_OK;
}

static mk_result bake_channel(mk_raw_asset *raw, uint32_t mesh_index, const char *name,
                              const char *origin, const mk_deformer *deformer,
                              const mk_inbetween_options *options,
                              void (*progress)(void *, const char *, double), void *user,
                              mk_inbetween_result *result, mk_arena *scratch, mk_error *err)
{
    const mk_raw_mesh *mesh = &raw->meshes[mesh_index];
    size_t n = mesh->vertex_count;
    uint32_t m = options && options->samples ? options->samples : 100;
    double tol = options && options->tolerance > 0 ? options->tolerance : 0.001;
    uint32_t max_targets = options && options->max_targets ? options->max_targets : 64;
    uint32_t fixed = options ? options->count : 0;
    if (max_targets > 256) max_targets = 256;
    char stage_search[200], stage_check[200];
    snprintf(stage_search, sizeof stage_search, "%s: placing in-betweens", name);
    snprintf(stage_check, sizeof stage_check, "%s: checking playback", name);
    if (m > 100000)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "samples: %u is above 100000", m);
    if (fixed > 256)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "inbetweens: %u is above 256", fixed);
    double bmin[3], bmax[3], diagonal;
    bake_bounds(mesh, bmin, bmax, &diagonal);
    if (!(diagonal > 0)) diagonal = 1;  /* single point: report errors in mesh units */

    sampler s;
    memset(&s, 0, sizeof s);
    s.arena = scratch;
    s.mesh = mesh;
    s.deformer = deformer;
    s.samples = m;
    s.n = n;
    s.work = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(double));
    if (!s.work) return mk_error_oom(err, "in-between samples");
    int cheap_grid = !(fixed && deformer->expensive);
    if ((size_t)(m + 1) * (3 * n * sizeof(float) + 16) <= CACHE_LIMIT_BYTES && cheap_grid) {
        s.cache = mk_arena_array(scratch, (size_t)m + 1, sizeof(float *));
        if (!s.cache) return mk_error_oom(err, "in-between samples");
    } else {
        for (int i = 0; i < 3; i++) {
            s.slot[i] = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(float));
            if (!s.slot[i]) return mk_error_oom(err, "in-between samples");
            s.slot_k[i] = -1;
        }
    }

    /* Key amplitudes as grid indices (adaptive) or as exact weights k/count (fixed). */
    uint32_t keys[256];
    double key_weight[256];
    uint32_t key_count = 0;
    double error = 0;
    int on_grid = 1;
    if (!fixed) {
        double limit = 0.99 * tol * diagonal;
        uint32_t a = 0;
        while (a < m) {
            if (progress) progress(user, stage_search, (double)a / m);
            /* Exponential then binary search for the farthest acceptable end c. */
            uint32_t good = a + 1, bad = 0, step = 2;
            double good_error = 0;
            for (;;) {
                uint32_t c = a + step > m ? m : a + step;
                if (c <= good) break;
                double e = span_error(&s, a, c, limit, err);
                if (e < 0) return err ? err->code : MK_ERROR_INVALID_ARGUMENT;
                if (e <= limit) { good = c; good_error = e; if (c == m) break; step *= 2; }
                else { bad = c; break; }
            }
            while (bad && bad - good > 1) {
                uint32_t c = good + (bad - good) / 2;
                double e = span_error(&s, a, c, limit, err);
                if (e < 0) return err ? err->code : MK_ERROR_INVALID_ARGUMENT;
                if (e <= limit) { good = c; good_error = e; } else bad = c;
            }
            if (key_count == max_targets)
                return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX,
                                    "inbetweens: more than %u targets needed for tolerance %g "
                                    "(raise max_targets or the tolerance)", max_targets, tol);
            if (good_error > error) error = good_error;
            keys[key_count++] = good;
            a = good;
        }
        for (uint32_t i = 0; i < key_count; i++) key_weight[i] = grid_weight(keys[i], m);
    } else {
        key_count = fixed;
        for (uint32_t i = 0; i < key_count; i++)
            key_weight[i] = (double)(float)(options->weights ? options->weights[i] : (double)(i + 1) / fixed);
    }

    float *key_deltas[256];
    memset(key_deltas, 0, sizeof key_deltas);
    double *grid_curve = NULL;      /* the error at every sampled weight, when measured */
    float *grid_weights = NULL;
    if (s.cache) {
        /* Measure at every grid weight with the runtime's span coefficients. In fixed mode the
         * keys k/count are generally off the grid: evaluate them separately. */
        float full[256];
        for (uint32_t i = 0; i < key_count; i++) {
            full[i] = (float)key_weight[i];
            if (!fixed) {
                key_deltas[i] = s.cache[keys[i]];
                continue;
            }
            key_deltas[i] = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(float));
            if (!key_deltas[i]) return mk_error_oom(err, "in-between samples");
            mk_result r = eval_deltas(&s, key_weight[i], key_deltas[i], err);
            if (r != MK_OK) return r;
        }
        double *curve = mk_arena_array(&raw->arena, (size_t)s.samples + 1, sizeof(double));
        float *weights = mk_arena_array(&raw->arena, key_count ? key_count : 1, sizeof(float));
        if (!curve || !weights) return mk_error_oom(err, "in-between error curve");
        error = verify_grid(&s, full, key_deltas, key_count, progress, user, stage_check, curve, err);
        if (error >= 0) {
            memcpy(weights, full, key_count * sizeof(float));
            grid_curve = curve;
            grid_weights = weights;
        }
        if (error < 0) return err ? err->code : MK_ERROR_OUT_OF_MEMORY;
    } else if (fixed) {
        /* Expensive deformer with a fixed count: estimate at the midpoint of every span. */
        on_grid = 0;
        const float *prev = s.slot[0];
        float *mid = s.slot[2];
        memset(s.slot[0], 0, 3 * n * sizeof(float));
        double wa = 0;
        for (uint32_t i = 0; i < key_count; i++) {
            double wc = key_weight[i], wm = 0.5 * (wa + wc);
            key_deltas[i] = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(float));
            if (!key_deltas[i]) return mk_error_oom(err, "in-between samples");
            mk_result r = eval_deltas(&s, wc, key_deltas[i], err);
            if (r == MK_OK) r = eval_deltas(&s, wm, mid, err);
            if (r != MK_OK) return r;
            double e = sample_error(prev, key_deltas[i], mid, (wm - wa) / (wc - wa), n);
            if (e > error) error = e;
            prev = key_deltas[i];
            wa = wc;
            if (progress) progress(user, stage_check, (double)(i + 1) / key_count);
        }
    }

    /* Write the channel. Deformers with analytic normals are evaluated once more per key (they
     * are cheap) to get the normals; the others reuse the key deltas computed above. */
    uint32_t old_count = raw->channel_count;
    mk_raw_channel *channel = mk_raw_add_channels(raw, 1);
    if (!channel) return mk_error_oom(err, "baked channel");
    channel->name = mk_arena_strdup(&raw->arena, name);
    channel->origin = mk_arena_strdup(&raw->arena, origin ? origin : "");
    channel->mesh = mesh_index;
    channel->default_weight = 0;
    if (!channel->name || !channel->origin) {
        raw->channel_count = old_count;
        return mk_error_oom(err, "baked channel");
    }
    double *pos = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(double));
    double *nrm = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(double));
    double *tan = mk_arena_array(scratch, n ? 3 * n : 1, sizeof(double));
    if (!pos || !nrm || !tan) { raw->channel_count = old_count; return mk_error_oom(err, "baked target"); }
    uint32_t moved = 0, inverted = s.inverted, evaluations = s.evaluations;
    for (uint32_t i = 0; i < key_count; i++) {
        char tname[300];
        if (i + 1 == key_count) snprintf(tname, sizeof tname, "%s", name);
        else snprintf(tname, sizeof tname, "%s@%.4g", name, key_weight[i]);
        mk_result r = write_target(raw, channel, mesh_index, deformer, key_weight[i], tname,
                                   diagonal, key_deltas[i], pos, nrm, tan, &moved, &inverted, err);
        if (!key_deltas[i] || deformer->analytic_normals) evaluations++;
        if (r != MK_OK) { raw->channel_count = old_count; return r; }
    }
    if (!deformer->analytic_normals && mesh->normals) {
        mk_result r = mk_raw_compute_target_normals(raw, mesh_index, 0, 0, err);
        if (r != MK_OK) { raw->channel_count = old_count; return r; }
    }
    if (result) {
        result->targets = key_count;
        result->evaluations = evaluations;
        result->max_error = error / diagonal;
        result->error_on_grid = on_grid;
        result->tolerance = fixed ? 0 : tol;
        if (grid_curve) {
            for (uint32_t k = 0; k <= s.samples; k++) grid_curve[k] /= diagonal;
            result->error_curve = grid_curve;
            result->curve_samples = s.samples;
            result->key_weights = grid_weights;
        }
        result->moved_vertices = moved;
        result->inverted_vertices = inverted;
    }
    if (progress) progress(user, stage_check, 1.0);
    return MK_OK;
}

mk_result mk_bake_channel(mk_raw_asset *raw, uint32_t mesh, const char *name, const char *origin,
                          const mk_deformer *deformer, const mk_inbetween_options *options,
                          void (*progress)(void *user, const char *stage, double fraction),
                          void *user, mk_inbetween_result *result, mk_error *err)
{
    if (!raw || !name || !deformer || !deformer->eval || mesh >= raw->mesh_count)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "mk_bake_channel: invalid argument (mesh %u of %u)", mesh,
                            raw ? raw->mesh_count : 0);
    mk_arena scratch;
    mk_arena_init(&scratch, &raw->arena.allocator);
    uint32_t old_count = raw->channel_count;
    mk_result r = bake_channel(raw, mesh, name, origin, deformer, options, progress, user, result,
                               &scratch, err);
    if (r != MK_OK) raw->channel_count = old_count;
    mk_arena_free_all(&scratch);
    return r;
}

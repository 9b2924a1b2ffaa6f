/* Morph evaluation (DESIGN.md "Evaluation semantics", docs/semantics.md).
 *
 * Per frame, once per job: every target of the mesh gets one scalar coefficient from the
 * channel weights (mk_channel_span: piecewise-linear through the implicit (0,0) key and the
 * targets' full weights, extrapolated at both ends). Sequential stacking
 *     d_c = (1 - beta_c) d_{c-1} + D_c(w_c)
 * unrolls to d = sum_c D_c * prod_{c' > c} (1 - beta_c'), so it only multiplies each channel's
 * coefficients by a suffix product: it costs what additive costs.
 *
 * Per block of 64 vertices: an accumulator (positions, normals, tangents as planar float[64]
 * arrays, 2.3 KB, in L1) receives every active target's entry for the block (entries of a
 * block are stored together, so a vertex range finds its data without a search), then each
 * output vertex is written once. Inactive targets cost one 16-byte entry header per touched
 * block; dense int16 entries are plain vectorizable loops.
 */
#include <math.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"

/* ---- channel spans ---- */

/* Full weights read with a byte stride, so the evaluator can read them straight from the
 * target records and tools from a plain float array. */
static float full_weight_at(const float *full_weights, size_t stride, uint32_t k)
{
    return *(const float *)(const void *)((const uint8_t *)full_weights + stride * k);
}

static void channel_span_strided(const float *full_weights, size_t stride, uint32_t count, float w,
                                 int32_t *ia, float *ca, int32_t *ib, float *cb, float *t_out)
{
    /* Key points sorted by full weight with the implicit zero key inserted after the
     * negative ones: virtual index j -> (weight, target), target -1 = the zero key. */
    if (count == 0) {       /* no targets: D(w) = 0 */
        *ia = *ib = -1;
        *ca = *cb = 0.0f;
        if (t_out) *t_out = 0.0f;
        return;
    }
    uint32_t zero = 0;
    while (zero < count && full_weight_at(full_weights, stride, zero) < 0) zero++;
#define KEY_W(j) ((j) < zero ? full_weight_at(full_weights, stride, (j)) \
                  : (j) == zero ? 0.0f : full_weight_at(full_weights, stride, (j) - 1))
#define KEY_T(j) ((j) < zero ? (int32_t)(j) : (j) == zero ? -1 : (int32_t)(j) - 1)
    /* Span j covers [key j, key j+1]; outside the range the first/last span extrapolates.
     * Linear search: channels have few in-betweens and the search runs once per frame. */
    uint32_t j = 0;
    while (j + 1 < count && w > KEY_W(j + 1)) j++;
    float wa = KEY_W(j), wb = KEY_W(j + 1);
    float t = (w - wa) / (wb - wa);
    *ia = KEY_T(j);
    *ib = KEY_T(j + 1);
    *ca = 1.0f - t;
    *cb = t;
    if (t_out) *t_out = t;
#undef KEY_W
#undef KEY_T
}

void mk_channel_span(const float *full_weights, uint32_t count, float w,
                     int32_t *ia, float *ca, int32_t *ib, float *cb, float *t_out)
{
    channel_span_strided(full_weights, sizeof(float), count, w, ia, ca, ib, cb, t_out);
}

/* ---- scratch layout ---- */

typedef struct channel_span {
    int32_t target_a, target_b;  /* mesh-local targets, -1 = implicit zero key */
    float t;                     /* position in the span (may be outside [0,1]: extrapolation) */
    float scale;                 /* sequential suffix product (1 for additive) */
} channel_span;

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

static size_t scratch_bytes(uint32_t targets, uint32_t channels)
{
    return align16((size_t)targets * sizeof(float)) + align16((size_t)targets * sizeof(int32_t))
         + align16((size_t)channels * sizeof(channel_span));
}

size_t mk_eval_scratch_size(const mk_asset *asset, uint32_t mesh)
{
    if (!asset || mesh >= asset->mesh_count) return 0;
    const mk_blob_mesh *m = &asset->meshes[mesh];
    return scratch_bytes(m->target_count, m->channel_count) + 16;
}

/* ---- validation ---- */

static mk_result job_fail(mk_error *err, mk_result code, const char *message)
{
    if (err) {
        err->code = code;
        err->offset = UINT64_MAX;
        size_t n = strlen(message);
        if (n > sizeof err->message - 1) n = sizeof err->message - 1;
        memcpy(err->message, message, n);
        err->message[n] = 0;
    }
    return code;
}

static int span_ok(const void *p, size_t stride, size_t size, uint32_t count, size_t elem)
{
    if ((uintptr_t)p % 4 || stride % 4 || stride < elem) return 0;
    if (count == 0) return 1;
    return (count - 1) <= (SIZE_MAX - elem) / stride && size >= stride * (count - 1) + elem;
}

static size_t stride_or(size_t stride, size_t fallback) { return stride ? stride : fallback; }

static uint32_t job_vertex_count(const mk_eval_job *job)
{
    const mk_blob_mesh *m = &job->asset->meshes[job->mesh];
    return job->vertex_count ? job->vertex_count : m->vertex_count - job->first_vertex;
}

mk_result mk_eval_validate(const mk_eval_job *job, mk_error *err)
{
    if (!job || !job->asset) return job_fail(err, MK_ERROR_INVALID_ARGUMENT, "eval job or its asset is NULL");
    const mk_asset *a = job->asset;
    if (job->mesh >= a->mesh_count) return job_fail(err, MK_ERROR_OUT_OF_RANGE, "eval job: mesh index out of range");
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    if (job->first_vertex >= m->vertex_count
        || (job->vertex_count && job->vertex_count > m->vertex_count - job->first_vertex))
        return job_fail(err, MK_ERROR_OUT_OF_RANGE, "eval job: vertex range exceeds the mesh");
    if (job->weight_count != m->channel_count)
        return job_fail(err, MK_ERROR_OUT_OF_RANGE, "eval job: weight_count differs from the mesh's channel count");
    if (m->channel_count && !job->weights)
        return job_fail(err, MK_ERROR_INVALID_ARGUMENT, "eval job: weights is NULL");
    for (uint32_t c = 0; c < m->channel_count; c++)
        if (!isfinite(job->weights[c])) return job_fail(err, MK_ERROR_NOT_FINITE, "eval job: a weight is NaN or infinite");
    if ((unsigned)job->stacking > MK_STACKING_SEQUENTIAL)
        return job_fail(err, MK_ERROR_INVALID_ARGUMENT, "eval job: unknown stacking mode");
    if ((unsigned)job->normal_mode > MK_NORMALS_SLERP)
        return job_fail(err, MK_ERROR_INVALID_ARGUMENT, "eval job: unknown normal mode");
    if (!job->scratch || (uintptr_t)job->scratch % 16)
        return job_fail(err, MK_ERROR_INVALID_ARGUMENT, "eval job: scratch is NULL or not 16-byte aligned");
    if (job->scratch_size < scratch_bytes(m->target_count, m->channel_count))
        return job_fail(err, MK_ERROR_BUFFER_TOO_SMALL, "eval job: scratch is smaller than mk_eval_scratch_size()");
    uint32_t n = job_vertex_count(job);
    if (!job->positions) return job_fail(err, MK_ERROR_INVALID_ARGUMENT, "eval job: positions output is NULL");
    if (!span_ok(job->positions, stride_or(job->positions_stride, 12), job->positions_size, n, 12))
        return job_fail(err, MK_ERROR_BUFFER_TOO_SMALL, "eval job: positions span is too small or misaligned");
    if (job->normals) {
        if (!(m->flags & MK_MESH_HAS_NORMALS))
            return job_fail(err, MK_ERROR_UNSUPPORTED, "eval job: normals requested but the mesh has no normals");
        if (!span_ok(job->normals, stride_or(job->normals_stride, 12), job->normals_size, n, 12))
            return job_fail(err, MK_ERROR_BUFFER_TOO_SMALL, "eval job: normals span is too small or misaligned");
    }
    if (job->tangents) {
        if (!(m->flags & MK_MESH_HAS_TANGENTS))
            return job_fail(err, MK_ERROR_UNSUPPORTED, "eval job: tangents requested but the mesh has no tangents");
        if (!span_ok(job->tangents, stride_or(job->tangents_stride, 16), job->tangents_size, n, 16))
            return job_fail(err, MK_ERROR_BUFFER_TOO_SMALL, "eval job: tangents span is too small or misaligned");
    }
    return MK_OK;
}

/* ---- per-frame coefficients ---- */

typedef struct frame {
    const mk_asset *asset;
    const mk_blob_mesh *mesh;
    const mk_blob_target *targets;  /* mesh's first target */
    float *coef;                    /* per mesh-local target */
    int32_t *slerp_channel;         /* per target: mesh-local channel whose normals slerp, or -1 */
    channel_span *spans;            /* per mesh-local channel */
    int slerp;
} frame;

static void compute_coefficients(frame *f, const mk_eval_job *job, mk_stacking stacking)
{
    const mk_blob_mesh *m = f->mesh;
    const mk_asset *a = f->asset;
    for (uint32_t t = 0; t < m->target_count; t++) { f->coef[t] = 0.0f; f->slerp_channel[t] = -1; }
    float suffix = 1.0f;
    for (uint32_t c = m->channel_count; c-- > 0;) {
        const mk_blob_channel *ch = &a->channels[m->first_channel + c];
        uint32_t first = ch->first_target - m->first_target;
        float w = job->weights[c];
        channel_span *s = &f->spans[c];
        s->target_a = s->target_b = -1;
        s->t = 0.0f;
        s->scale = suffix;
        if (w != 0.0f && suffix != 0.0f) {
            int32_t ia, ib;
            float ca, cb;
            channel_span_strided(&f->targets[first].full_weight, sizeof(mk_blob_target), ch->target_count, w,
                                 &ia, &ca, &ib, &cb, &s->t);
            if (ia >= 0) { f->coef[first + (uint32_t)ia] = ca * suffix; s->target_a = (int32_t)first + ia; }
            if (ib >= 0) { f->coef[first + (uint32_t)ib] = cb * suffix; s->target_b = (int32_t)first + ib; }
            if (f->slerp) {
                if (ia >= 0) f->slerp_channel[first + (uint32_t)ia] = (int32_t)c;
                if (ib >= 0) f->slerp_channel[first + (uint32_t)ib] = (int32_t)c;
            }
        }
        if (stacking == MK_STACKING_SEQUENTIAL) {
            /* beta = clamp(w / f_first, 0, 1) with f_first the smallest positive full weight. */
            float f_first = 0.0f;
            for (uint32_t k = 0; k < ch->target_count; k++)
                if (f->targets[first + k].full_weight > 0) { f_first = f->targets[first + k].full_weight; break; }
            float beta = f_first > 0 ? w / f_first : 0.0f;
            beta = beta < 0 ? 0 : beta > 1 ? 1 : beta;
            suffix *= 1.0f - beta;
        }
    }
}

/* ---- block accumulation ---- */

/* The block loop is compiled twice where the compiler and platform allow it: for the
 * baseline ISA and for x86-64-v3 (AVX2, FMA, BMI, POPCNT), picked once at load time by feature
 * level, not CPU model ("arch=haswell" would check the model and never match an AMD CPU),
 * (GCC/Clang target_clones through a glibc ifunc). The helpers it calls are force-inlined so each
 * clone gets its own vector code. Define MK_NO_TARGET_CLONES to build one baseline copy.
 * GCC only: clang 14 emits the resolver as a global symbol. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__) && \
    !defined(MK_NO_TARGET_CLONES) && !defined(__SANITIZE_ADDRESS__)
#define MK_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define MK_CLONES
#endif
#if defined(__GNUC__) || defined(__clang__)
#define MK_INLINE static inline __attribute__((always_inline))
#else
#define MK_INLINE static inline
#endif

enum { PX, PY, PZ, NX, NY, NZ, TX, TY, TZ, ACC_ROWS };
typedef float block_acc[ACC_ROWS][MK_BLOCK_SIZE];

/* acc[0..2][i] += factor * src[component][j] for the j-th set bit i of mask (m values per
 * component). Quantized sources are int16. */
MK_INLINE void add_q16(float (*acc)[MK_BLOCK_SIZE], uint64_t mask, uint32_t m, const int16_t *src, float factor)
{
    if (m == MK_BLOCK_SIZE) {
        for (int c = 0; c < 3; c++) {
            float *restrict out = acc[c];
            const int16_t *restrict in = src + (size_t)c * MK_BLOCK_SIZE;
            for (uint32_t i = 0; i < MK_BLOCK_SIZE; i++) out[i] += factor * (float)in[i];
        }
        return;
    }
    if ((mask & (mask + 1)) == 0) { /* contiguous from bit 0: the partial last block stored dense */
        for (int c = 0; c < 3; c++) {
            float *restrict out = acc[c];
            const int16_t *restrict in = src + (size_t)c * m;
            for (uint32_t i = 0; i < m; i++) out[i] += factor * (float)in[i];
        }
        return;
    }
    for (uint32_t j = 0; mask; j++, mask &= mask - 1) {
        unsigned i = (unsigned)mk_ctz64(mask);
        acc[0][i] += factor * (float)src[j];
        acc[1][i] += factor * (float)src[m + j];
        acc[2][i] += factor * (float)src[2 * m + j];
    }
}

MK_INLINE void add_f32(float (*acc)[MK_BLOCK_SIZE], uint64_t mask, uint32_t m, const float *src, float factor)
{
    if ((mask & (mask + 1)) == 0) {
        for (int c = 0; c < 3; c++) {
            float *restrict out = acc[c];
            const float *restrict in = src + (size_t)c * m;
            for (uint32_t i = 0; i < m; i++) out[i] += factor * in[i];
        }
        return;
    }
    for (uint32_t j = 0; mask; j++, mask &= mask - 1) {
        unsigned i = (unsigned)mk_ctz64(mask);
        acc[0][i] += factor * src[j];
        acc[1][i] += factor * src[m + j];
        acc[2][i] += factor * src[2 * m + j];
    }
}

/* Adds one attribute (3 planar components) of an entry; returns the next attribute's data. */
MK_INLINE const uint8_t *add_attribute(float (*acc)[MK_BLOCK_SIZE], uint64_t mask, uint32_t m, const uint8_t *data,
                                    int quantized, float factor)
{
    if (quantized) {
        add_q16(acc, mask, m, (const int16_t *)(const void *)data, factor);
        return data + 6u * m;
    }
    add_f32(acc, mask, m, (const float *)(const void *)data, factor);
    return data + 12u * m;
}

static void normalize3(float *v, const float *fallback)
{
    float len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (len2 < 1e-16f) { v[0] = fallback[0]; v[1] = fallback[1]; v[2] = fallback[2]; return; }
    float inv = 1.0f / sqrtf(len2);
    v[0] *= inv; v[1] *= inv; v[2] *= inv;
}

/* Slerp of unit vectors; t may lie outside [0, 1] (extrapolation along the great circle). */
static void slerp3(const float *a, const float *b, float t, float *out)
{
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    d = d > 1 ? 1 : d < -1 ? -1 : d;
    float theta = acosf(d);
    float s = sinf(theta);
    float wa, wb;
    if (s < 1e-6f) { wa = 1.0f - t; wb = t; }   /* nearly parallel: lerp is exact enough */
    else { wa = sinf((1.0f - t) * theta) / s; wb = sinf(t * theta) / s; }
    for (int k = 0; k < 3; k++) out[k] = wa * a[k] + wb * b[k];
}

/* Adds channel `span`'s slerped normal displacement for the vertices in `touched`:
 * slerp(n_a, n_b, t) - n_base, scaled by the sequential factor. */
static void add_slerp_normals(float (*acc_n)[MK_BLOCK_SIZE], const float (*delta_a)[MK_BLOCK_SIZE],
                              const float (*delta_b)[MK_BLOCK_SIZE], uint64_t touched, const channel_span *span,
                              const float *base_normals, uint32_t block_start)
{
    for (; touched; touched &= touched - 1) {
        unsigned i = (unsigned)mk_ctz64(touched);
        const float *bn = base_normals + 3u * (block_start + i);
        float base[3] = { bn[0], bn[1], bn[2] };
        normalize3(base, bn);
        float na[3] = { base[0], base[1], base[2] }, nb[3] = { base[0], base[1], base[2] };
        if (span->target_a >= 0) {
            na[0] = bn[0] + delta_a[0][i]; na[1] = bn[1] + delta_a[1][i]; na[2] = bn[2] + delta_a[2][i];
            normalize3(na, base);
        }
        if (span->target_b >= 0) {
            nb[0] = bn[0] + delta_b[0][i]; nb[1] = bn[1] + delta_b[1][i]; nb[2] = bn[2] + delta_b[2][i];
            normalize3(nb, base);
        }
        float s[3];
        slerp3(na, nb, span->t, s);
        for (int k = 0; k < 3; k++) acc_n[k][i] += span->scale * (s[k] - base[k]);
    }
}

/* Normalizes rows x,y,z in place for i in [lo, hi); where the length is below 1e-8 the
 * base vector (bx, by, bz) is used. Written as arithmetic selects over planar arrays so it
 * vectorizes (the build adds -fno-math-errno and -fvect-cost-model=dynamic for the runtime;
 * without them it is still correct, only scalar). */
MK_INLINE void normalize_rows(float *restrict x, float *restrict y, float *restrict z, const float *restrict bx,
                           const float *restrict by, const float *restrict bz, size_t lo, size_t hi)
{
    for (size_t i = lo; i < hi; i++) {
        float len2 = x[i] * x[i] + y[i] * y[i] + z[i] * z[i];
        float keep = len2 < 1e-16f ? 1.0f : 0.0f;
        float inv = (1.0f - keep) / sqrtf(len2 + keep);
        x[i] = x[i] * inv + bx[i] * keep;
        y[i] = y[i] * inv + by[i] * keep;
        z[i] = z[i] * inv + bz[i] * keep;
    }
}

/* Loads three planar rows from an xyz-first base array (stride floats per vertex). */
MK_INLINE void load_rows(float *restrict x, float *restrict y, float *restrict z, const float *restrict base,
                         size_t stride, size_t lo, size_t hi)
{
    for (size_t i = lo; i < hi; i++) {
        x[i] = base[stride * i];
        y[i] = base[stride * i + 1];
        z[i] = base[stride * i + 2];
    }
}

/* The accumulator starts as the base (so no zeroing pass and no separate base add);
 * normals/tangents also keep a planar copy of the base for the normalization fallback.
 * Lanes outside [lo, hi) are zeroed: they may lie past the mesh end. */
MK_INLINE void init_block(block_acc acc, int rows, size_t lo, size_t hi, const float *restrict base_p,
                          const float *restrict base_n, const float *restrict base_t,
                          float (*restrict copy_n)[MK_BLOCK_SIZE], float (*restrict copy_t)[MK_BLOCK_SIZE])
{
    if (lo != 0 || hi != MK_BLOCK_SIZE) {
        memset(acc, 0, sizeof(float) * MK_BLOCK_SIZE * (size_t)rows);
        if (base_n) memset(copy_n, 0, sizeof(float) * 3 * MK_BLOCK_SIZE);
        if (base_t) memset(copy_t, 0, sizeof(float) * 3 * MK_BLOCK_SIZE);
    }
    load_rows(acc[PX], acc[PY], acc[PZ], base_p, 3, lo, hi);
    if (base_n) {
        load_rows(copy_n[0], copy_n[1], copy_n[2], base_n, 3, lo, hi);
        memcpy(acc[NX], copy_n, sizeof(float) * 3 * MK_BLOCK_SIZE);
    }
    if (base_t) {
        load_rows(copy_t[0], copy_t[1], copy_t[2], base_t, 4, lo, hi);
        memcpy(acc[TX], copy_t, sizeof(float) * 3 * MK_BLOCK_SIZE);
    }
}

/* acc (base + deltas) becomes the final planar outputs: normals/tangents normalized. */
MK_INLINE void finish_block(block_acc acc, size_t lo, size_t hi, float (*copy_n)[MK_BLOCK_SIZE],
                            float (*copy_t)[MK_BLOCK_SIZE], int normals, int tangents)
{
    if (normals) normalize_rows(acc[NX], acc[NY], acc[NZ], copy_n[0], copy_n[1], copy_n[2], lo, hi);
    if (tangents) normalize_rows(acc[TX], acc[TY], acc[TZ], copy_t[0], copy_t[1], copy_t[2], lo, hi);
}

/* Interleaves three planar rows into a strided xyz output. Tightly packed outputs (stride
 * 12) take a loop with a constant stride, which the compiler vectorizes. */
MK_INLINE void store_rows(const float *restrict x, const float *restrict y, const float *restrict z, size_t lo,
                          size_t hi, uint8_t *restrict out, size_t stride)
{
    if (stride == 12) {
        float *restrict o = (float *)(void *)out;
        const size_t n = hi - lo;
        x += lo; y += lo; z += lo;
        for (size_t i = 0; i < n; i++) {
            o[3 * i] = x[i];
            o[3 * i + 1] = y[i];
            o[3 * i + 2] = z[i];
        }
        return;
    }
    for (size_t i = lo; i < hi; i++, out += stride) {
        float *o = (float *)(void *)out;
        o[0] = x[i]; o[1] = y[i]; o[2] = z[i];
    }
}

/* Interleaves the planar results into the strided outputs (pointers address vertex lo). */
MK_INLINE void store_block(block_acc acc, uint32_t lo, uint32_t hi, uint8_t *pos, size_t ps, uint8_t *nrm,
                        size_t ns, uint8_t *tan, size_t ts, const float *base_t)
{
    store_rows(acc[PX], acc[PY], acc[PZ], lo, hi, pos, ps);
    if (nrm) store_rows(acc[NX], acc[NY], acc[NZ], lo, hi, nrm, ns);
    if (tan)
        for (uint32_t i = lo; i < hi; i++, tan += ts) {
            float *o = (float *)(void *)tan;
            o[0] = acc[TX][i]; o[1] = acc[TY][i]; o[2] = acc[TZ][i]; o[3] = base_t[4 * i + 3];
        }
}

/* The per-block work of one job (see the top of this file). */
static MK_CLONES void eval_blocks(const mk_eval_job *job, const frame *frame_in)
{
    const frame f = *frame_in;
    const mk_asset *a = f.asset;
    const mk_blob_mesh *m = f.mesh;
    const int want_normals = job->normals != NULL, want_tangents = job->tangents != NULL;
    const uint32_t first = job->first_vertex, end = first + job_vertex_count(job);
    const float *base_p = (const float *)(a->data + m->positions);
    const float *base_n = want_normals ? (const float *)(a->data + m->normals) : NULL;
    const float *base_t = want_tangents ? (const float *)(a->data + m->tangents) : NULL;
    const uint32_t *block_first = (const uint32_t *)(a->data + m->block_entries);
    const mk_blob_entry *entries = (const mk_blob_entry *)(a->data + m->entries);
    const uint8_t *data = a->data + m->target_data;
    const size_t ps = stride_or(job->positions_stride, 12), ns = stride_or(job->normals_stride, 12),
                 ts = stride_or(job->tangents_stride, 16);

    block_acc acc;
    float copy_n[3][MK_BLOCK_SIZE], copy_t[3][MK_BLOCK_SIZE];
    float slerp_a[3][MK_BLOCK_SIZE], slerp_b[3][MK_BLOCK_SIZE];
    const uint32_t block_end = (end + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    for (uint32_t b = first / MK_BLOCK_SIZE; b < block_end; b++) {
        const uint32_t block_start = b * MK_BLOCK_SIZE;
        const int rows = want_tangents ? ACC_ROWS : want_normals ? TX : NX;
        const uint32_t lo = block_start > first ? block_start : first;
        const uint32_t hi = block_start + MK_BLOCK_SIZE < end ? block_start + MK_BLOCK_SIZE : end;
        init_block(acc, rows, lo - block_start, hi - block_start, base_p + 3u * (size_t)block_start,
                   want_normals ? base_n + 3u * (size_t)block_start : NULL,
                   want_tangents ? base_t + 4u * (size_t)block_start : NULL, copy_n, copy_t);
        int32_t open_channel = -1;          /* slerp channel whose deltas are being gathered */
        uint64_t touched = 0;
        for (uint32_t e = block_first[b]; e < block_first[b + 1]; e++) {
            const mk_blob_entry *en = &entries[e];
            float c = f.coef[en->target];
            if (c == 0.0f) continue;
            const mk_blob_target *tg = &f.targets[en->target];
            const uint32_t count = mk_popcount64(en->mask);
            const int q = (tg->flags & MK_TARGET_QUANTIZED) != 0;
            const uint8_t *p = data + (size_t)en->data * MK_ALIGN;
            p = add_attribute(&acc[PX], en->mask, count, p, q, c * (q ? tg->position_scale : 1.0f));
            if (!want_normals && !want_tangents) continue;
            if (tg->flags & MK_TARGET_HAS_NORMALS) {
                int32_t sc = f.slerp_channel[en->target];
                if (sc < 0) {
                    if (want_normals) add_attribute(&acc[NX], en->mask, count, p, q, c * (q ? tg->normal_scale : 1.0f));
                } else {
                    /* Gather this channel's two span targets' raw normal deltas. */
                    if (sc != open_channel) {
                        if (open_channel >= 0)
                            add_slerp_normals(&acc[NX], (const float (*)[MK_BLOCK_SIZE])slerp_a,
                                              (const float (*)[MK_BLOCK_SIZE])slerp_b, touched,
                                              &f.spans[open_channel], base_n, block_start);
                        memset(slerp_a, 0, sizeof slerp_a);
                        memset(slerp_b, 0, sizeof slerp_b);
                        open_channel = sc;
                        touched = 0;
                    }
                    float (*dst)[MK_BLOCK_SIZE] = (int32_t)en->target == f.spans[sc].target_a ? slerp_a : slerp_b;
                    add_attribute(dst, en->mask, count, p, q, q ? tg->normal_scale : 1.0f);
                    touched |= en->mask;
                }
                p += q ? 6u * count : 12u * count;
            }
            if (want_tangents && (tg->flags & MK_TARGET_HAS_TANGENTS))
                add_attribute(&acc[TX], en->mask, count, p, q, c * (q ? tg->tangent_scale : 1.0f));
        }
        if (open_channel >= 0)
            add_slerp_normals(&acc[NX], (const float (*)[MK_BLOCK_SIZE])slerp_a,
                              (const float (*)[MK_BLOCK_SIZE])slerp_b, touched, &f.spans[open_channel], base_n,
                              block_start);

        /* Write each output vertex of the block once: finish in planar form (vectorizable),
         * then interleave into the caller's strided buffers. */
        finish_block(acc, lo - block_start, hi - block_start, copy_n, copy_t, want_normals, want_tangents);
        store_block(acc, lo - block_start, hi - block_start, (uint8_t *)job->positions + (size_t)(lo - first) * ps, ps,
                    want_normals ? (uint8_t *)job->normals + (size_t)(lo - first) * ns : NULL, ns,
                    want_tangents ? (uint8_t *)job->tangents + (size_t)(lo - first) * ts : NULL, ts,
                    want_tangents ? base_t + 4u * (size_t)block_start : NULL);
    }
}

mk_result mk_eval_run(const mk_eval_job *job, mk_error *err)
{
    mk_result r = mk_eval_validate(job, err);
    if (r != MK_OK) return r;
    const mk_asset *a = job->asset;
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    mk_stacking stacking = job->stacking == MK_STACKING_ASSET ? (mk_stacking)m->stacking : job->stacking;

    uint8_t *scratch = job->scratch;
    frame f;
    f.asset = a;
    f.mesh = m;
    f.targets = &a->targets[m->first_target];
    f.coef = (float *)(void *)scratch;
    f.slerp_channel = (int32_t *)(void *)(scratch + align16((size_t)m->target_count * sizeof(float)));
    f.spans = (channel_span *)(void *)(scratch + align16((size_t)m->target_count * sizeof(float))
                                       + align16((size_t)m->target_count * sizeof(int32_t)));
    f.slerp = job->normals != NULL && job->normal_mode == MK_NORMALS_SLERP;
    compute_coefficients(&f, job, stacking);

    eval_blocks(job, &f);
    return MK_OK;
}

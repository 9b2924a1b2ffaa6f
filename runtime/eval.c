/* SPDX-License-Identifier: MIT */
/* Morph evaluation (docs/semantics.md).
 *
 * Per frame, once per job: the frame's plan (plan.h) in the job's scratch gives every target
 * of the mesh one scalar coefficient from the channel weights, sequential stacking included.
 *
 * Per block of 64 vertices: an accumulator per attribute (float xyz triples interleaved like
 * the base arrays and the outputs, 768 bytes each, in L1) starts as a copy of the base and
 * receives every active target's entry for the block (entries of a block are stored together,
 * so a vertex range finds its data without a search); then each output vertex is written once.
 * A packed entry (docs/format.md) stores each component's values apart, in as few bits as its
 * range needs: they are unpacked eight at a time (AVX2 where the CPU has it: a byte shuffle and
 * a shift per lane; else a portable loop giving the same floats), interleaved, and added: a
 * whole block as one pass of 192 values, a partial one run by run of consecutive mask bits,
 * like the float32 entries. Inactive targets cost one entry header per touched block.
 */
#include <math.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>   /* compiler intrinsics (non-temporal stores), not a library */
#define MK_HAVE_STREAMING 1
#else
#define MK_HAVE_STREAMING 0
#endif
/* The AVX2 unpacking of packed values, picked once per job by the CPU (GCC and clang on x86-64);
 * MK_NO_TARGET_CLONES builds the portable loop alone. Both give the same floats. */
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && !defined(MK_NO_TARGET_CLONES)
#include <immintrin.h>
#define MK_HAVE_AVX2_UNPACK 1
#else
#define MK_HAVE_AVX2_UNPACK 0
#endif
#include "format.h"
#include "morphkit.h"
#include "error.h"
#include "span.h"
#include "plan.h"
#include "clones.h"
#include "determinism.h"

/* ---- scratch layout ---- */

size_t mk_eval_scratch_size(const mk_asset *asset, uint32_t mesh)
{
    if (!asset || mesh >= asset->mesh_count) return 0;
    const mk_blob_mesh *m = &asset->meshes[mesh];
    return mk_plan_bytes(m->target_count, m->channel_count) + 16;   /* the scratch is the frame's plan */
}

/* ---- validation ---- */

static uint32_t job_vertex_count(const mk_eval_job *job)
{
    const mk_blob_mesh *m = &job->asset->meshes[job->mesh];
    return job->vertex_count == MK_VERTICES_TO_END ? m->vertex_count - job->first_vertex : job->vertex_count;
}

mk_result mk_eval_validate(const mk_eval_job *job, mk_error *err)
{
    if (!job || !job->asset) return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "eval job or its asset is NULL");
    const mk_asset *a = job->asset;
    if (job->mesh >= a->mesh_count) return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "eval job: mesh index out of range");
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    if (job->first_vertex > m->vertex_count
        || (job->vertex_count != MK_VERTICES_TO_END && job->vertex_count > m->vertex_count - job->first_vertex))
        return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "eval job: vertex range exceeds the mesh");
    mk_result r = mk_plan_validate_weights(m, job->weights, job->weight_count, job->stacking, job->normal_mode,
                                           "eval job", err);
    if (r != MK_OK) return r;
    if ((unsigned)job->store_mode > MK_STORE_STREAMING)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "eval job: unknown store mode");
    if (!job->scratch || (uintptr_t)job->scratch % 16)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "eval job: scratch is NULL or not 16-byte aligned");
    if (job->scratch_size < mk_plan_bytes(m->target_count, m->channel_count))
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "eval job: scratch is smaller than mk_eval_scratch_size()");
    uint32_t n = job_vertex_count(job);
    if (!job->positions) return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "eval job: positions output is NULL");
    if (!mk_span_ok(job->positions, mk_stride_or(job->positions_stride, 12), job->positions_size, n, 12))
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "eval job: positions span is too small or misaligned");
    if (job->normals) {
        if (!(m->flags & MK_MESH_HAS_NORMALS))
            return mk_error_fail(err, MK_ERROR_UNSUPPORTED, MK_NO_OFFSET, "eval job: normals requested but the mesh has no normals");
        if (!mk_span_ok(job->normals, mk_stride_or(job->normals_stride, 12), job->normals_size, n, 12))
            return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "eval job: normals span is too small or misaligned");
    }
    if (job->tangents) {
        if (!(m->flags & MK_MESH_HAS_TANGENTS))
            return mk_error_fail(err, MK_ERROR_UNSUPPORTED, MK_NO_OFFSET, "eval job: tangents requested but the mesh has no tangents");
        if (!mk_span_ok(job->tangents, mk_stride_or(job->tangents_stride, 16), job->tangents_size, n, 16))
            return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "eval job: tangents span is too small or misaligned");
    }
    return MK_OK;
}

/* ---- per-frame coefficients ---- */

typedef struct frame {
    const mk_asset *asset;
    const mk_blob_mesh *mesh;
    const mk_blob_target *targets;  /* mesh's first target */
    mk_plan plan;                   /* in the job's scratch */
} frame;

/* ---- block accumulation ---- */

/* Software prefetch. Delta data is target-major, so each active target is its own sequential
 * stream, and a frame reads tens of them besides the base arrays: more streams than hardware
 * prefetchers follow. So when a block's entry (or base) is read, the same number of bytes
 * MK_PREFETCH_AHEAD further on in that stream (the target's next blocks) is prefetched into
 * L2. The whole entry is prefetched even when only positions are evaluated, so the prefetches
 * cover the stream without gaps. Measured on the default bench (docs/performance.md): 1.5 to
 * 4 KB ahead is a plateau and 0.75 KB too short; locality 1 (L2) beats L1 (which evicts the
 * accumulators) and non-temporal hints. The address may lie past the data: prefetches never
 * fault, and it is formed as an integer, so no pointer leaves its object. */
#define MK_PREFETCH_AHEAD 2048u
#if defined(__GNUC__) || defined(__clang__)
#define MK_PREFETCH(address) __builtin_prefetch((const void *)(address), 0, 1)
#else
#define MK_PREFETCH(address) ((void)(address))
#endif

MK_INLINE void prefetch_ahead(const uint8_t *p, size_t bytes)
{
    const uintptr_t ahead = (uintptr_t)p + MK_PREFETCH_AHEAD;
    for (size_t off = 0; off < bytes; off += 64) MK_PREFETCH(ahead + off);
}

/* An attribute of a block, interleaved like the outputs: xyz of the block's vertex i at
 * [3i, 3i + 3). */
typedef float block_acc[3 * MK_BLOCK_SIZE];

/* acc[k] += factor * src[k] for k < n. */
MK_INLINE void add_span_f32(float *restrict acc, const float *restrict src, uint32_t n, float factor)
{
    for (uint32_t k = 0; k < n; k++) acc[k] += factor * src[k];
}

/* Adds one attribute of a float entry: xyz triples of the mask's vertices in bit order. A run
 * of consecutive mask bits is one contiguous span of both the data and the accumulator, so a
 * dense block is a single loop of 192 values and a sparse one a short loop per run. */
MK_INLINE void add_float_attribute(float *restrict acc, uint64_t mask, const uint8_t *data, float factor)
{
    const float *src = (const float *)(const void *)data;
    if (mask == ~(uint64_t)0) {     /* constant trip count: no loop epilogue */
        add_span_f32(acc, src, 3 * MK_BLOCK_SIZE, factor);
        return;
    }
    for (uint32_t j = 0; mask; mask &= mask + (mask & (0 - mask))) {   /* clears the lowest run */
        const unsigned lo = mk_ctz64(mask);
        const uint32_t len = mk_ctz64(~(mask >> lo));   /* mask != ~0, so ~(mask >> lo) != 0 */
        add_span_f32(acc + 3 * lo, src + 3 * j, 3 * len, factor);
        j += len;
    }
}

/* One packed component's m values as floats, offset + u by rank (docs/format.md). offset + u
 * is an integer below 2^24, so its conversion is exact whichever way it is computed. */
MK_INLINE void unpack_portable(float *restrict out, const uint8_t *restrict p, uint32_t m, uint32_t w, int32_t offset)
{
    for (uint32_t j = 0; j < m; j++) out[j] = (float)(offset + (int32_t)mk_unpack(p, w, j));
}

#if MK_HAVE_AVX2_UNPACK
/* Eight values of width w lie in w bytes from byte 8 w g on: per width, the byte shuffle that
 * gives each 32-bit lane l the four bytes from its value's first byte (l w / 8; past the 16
 * loaded bytes only where no bit of the value lies there), and the lane's bit shift. */
#define MK_UB(w, l, i) ((((l) * (w)) >> 3) + (i) > 15 ? 0x80 : (((l) * (w)) >> 3) + (i))
#define MK_ULANE(w, l) MK_UB(w, l, 0), MK_UB(w, l, 1), MK_UB(w, l, 2), MK_UB(w, l, 3)
#define MK_UROW(w) { MK_ULANE(w, 0), MK_ULANE(w, 1), MK_ULANE(w, 2), MK_ULANE(w, 3), \
                     MK_ULANE(w, 4), MK_ULANE(w, 5), MK_ULANE(w, 6), MK_ULANE(w, 7) }
#define MK_USHIFT(w) { 0, ((w) * 1) & 7, ((w) * 2) & 7, ((w) * 3) & 7, ((w) * 4) & 7, ((w) * 5) & 7, \
                       ((w) * 6) & 7, ((w) * 7) & 7 }
static const uint8_t unpack_shuffle[MK_MAX_WIDTH + 1][32] __attribute__((aligned(32))) = {
    MK_UROW(0), MK_UROW(1), MK_UROW(2), MK_UROW(3), MK_UROW(4), MK_UROW(5), MK_UROW(6), MK_UROW(7), MK_UROW(8),
    MK_UROW(9), MK_UROW(10), MK_UROW(11), MK_UROW(12), MK_UROW(13), MK_UROW(14), MK_UROW(15), MK_UROW(16)
};
static const uint32_t unpack_shift[MK_MAX_WIDTH + 1][8] __attribute__((aligned(32))) = {
    MK_USHIFT(0), MK_USHIFT(1), MK_USHIFT(2), MK_USHIFT(3), MK_USHIFT(4), MK_USHIFT(5), MK_USHIFT(6), MK_USHIFT(7),
    MK_USHIFT(8), MK_USHIFT(9), MK_USHIFT(10), MK_USHIFT(11), MK_USHIFT(12), MK_USHIFT(13), MK_USHIFT(14),
    MK_USHIFT(15), MK_USHIFT(16)
};

/* Eight values (group g) of a packed component as floats. */
__attribute__((target("avx2"))) static inline __m256 unpack8_avx2(const mk_packed_layout *pe, uint32_t k, uint32_t g)
{
    const uint32_t w = pe->width[k];
    const __m256i shuffle = _mm256_load_si256((const __m256i *)(const void *)unpack_shuffle[w]);
    const __m256i shift = _mm256_load_si256((const __m256i *)(const void *)unpack_shift[w]);
    const __m128i bytes = _mm_loadu_si128((const __m128i *)(const void *)(pe->at[k] + (size_t)g * w));
    __m256i v = _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(bytes), shuffle);
    v = _mm256_and_si256(_mm256_srlv_epi32(v, shift), _mm256_set1_epi32((int)((1u << w) - 1u)));
    return _mm256_cvtepi32_ps(_mm256_add_epi32(v, _mm256_set1_epi32(pe->offset[k])));
}

/* Components k0..k0 + 2 of eight vertices (group g) interleaved in registers: one permute per
 * component and output vector, two blends:
 * x0 y0 z0 x1 y1 z1 x2 y2 | z2 x3 y3 z3 x4 y4 z4 x5 | y5 z5 x6 y6 z6 x7 y7 z7. */
__attribute__((target("avx2"))) static inline void triples8_avx2(const mk_packed_layout *pe, uint32_t k0, uint32_t g,
                                                                 __m256 o[3])
{
    const __m256i i0 = _mm256_setr_epi32(0, 0, 0, 1, 1, 1, 2, 2), i1 = _mm256_setr_epi32(2, 3, 3, 3, 4, 4, 4, 5),
                  i2 = _mm256_setr_epi32(5, 5, 6, 6, 6, 7, 7, 7);
    const __m256 x = unpack8_avx2(pe, k0, g), y = unpack8_avx2(pe, k0 + 1, g), z = unpack8_avx2(pe, k0 + 2, g);
    o[0] = _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(x, i0), _mm256_permutevar8x32_ps(y, i0), 0x92),
                           _mm256_permutevar8x32_ps(z, i0), 0x24);
    o[1] = _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(x, i1), _mm256_permutevar8x32_ps(y, i1), 0x24),
                           _mm256_permutevar8x32_ps(z, i1), 0x49);
    o[2] = _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(x, i2), _mm256_permutevar8x32_ps(y, i2), 0x49),
                           _mm256_permutevar8x32_ps(z, i2), 0x92);
}

/* A whole block's components k0..k0 + 2 added to the interleaved accumulator eight vertices at
 * a time: acc += factor x value as the portable loop does, so the sums are the same. */
__attribute__((target("avx2"))) static void add_packed_block_avx2(float *restrict acc, const mk_packed_layout *pe,
                                                                  uint32_t k0, float factor)
{
    const __m256 f = _mm256_set1_ps(factor);
    for (uint32_t g = 0; g < MK_BLOCK_SIZE / 8; g++) {
        __m256 o[3];
        triples8_avx2(pe, k0, g, o);
        float *a = acc + 24 * g;
        for (int k = 0; k < 3; k++)
            _mm256_storeu_ps(a + 8 * k, _mm256_add_ps(_mm256_loadu_ps(a + 8 * k), _mm256_mul_ps(f, o[k])));
    }
}

/* The m xyz triples of components k0..k0 + 2 (a multiple of 8 written: triples holds 192). */
__attribute__((target("avx2"))) static void packed_triples_avx2(float *restrict triples, const mk_packed_layout *pe,
                                                                uint32_t k0)
{
    for (uint32_t g = 0; 8 * g < pe->m; g++) {
        __m256 o[3];
        triples8_avx2(pe, k0, g, o);
        for (int k = 0; k < 3; k++) _mm256_storeu_ps(triples + 24 * g + 8 * k, o[k]);
    }
}
#endif

/* Adds factor x the values of the packed components k0, k0 + 1, k0 + 2 to the interleaved
 * accumulator: each component is unpacked by rank; a whole block is added as it is interleaved,
 * a partial one interleaved into xyz triples first and those added run by run of the mask as a
 * float entry's are. */
MK_INLINE void add_packed_attribute(float *restrict acc, uint64_t mask, const mk_packed_layout *pe, uint32_t k0,
                                    float factor, int avx2)
{
    block_acc triples;
#if MK_HAVE_AVX2_UNPACK
    if (avx2) {
        if (mask == ~(uint64_t)0) {
            add_packed_block_avx2(acc, pe, k0, factor);
            return;
        }
        packed_triples_avx2(triples, pe, k0);
        add_float_attribute(acc, mask, (const uint8_t *)triples, factor);
        return;
    }
#else
    (void)avx2;
#endif
    float v[3][MK_BLOCK_SIZE];
    for (uint32_t c = 0; c < 3; c++) unpack_portable(v[c], pe->at[k0 + c], pe->m, pe->width[k0 + c], pe->offset[k0 + c]);
    if (mask == ~(uint64_t)0) {   /* a whole block: interleaved as it is added */
        for (uint32_t i = 0; i < MK_BLOCK_SIZE; i++) {
            acc[3 * i] += factor * v[0][i];
            acc[3 * i + 1] += factor * v[1][i];
            acc[3 * i + 2] += factor * v[2][i];
        }
        return;
    }
    for (uint32_t j = 0; j < pe->m; j++) {
        triples[3 * j] = v[0][j];
        triples[3 * j + 1] = v[1][j];
        triples[3 * j + 2] = v[2][j];
    }
    add_float_attribute(acc, mask, (const uint8_t *)triples, factor);
}

/* Adds the attribute whose first component is k0 of an entry times factor (times the
 * attribute's step for a packed entry, which the caller folds into factor): from its packed
 * layout pe, or (pe NULL) from float_at, its float triples in a float entry. avx2: the CPU has
 * AVX2 (asked once per job). */
MK_INLINE void add_entry_attribute(float *restrict acc, const mk_blob_entry *en, const mk_packed_layout *pe, uint32_t k0,
                                   const uint8_t *float_at, float factor, int avx2)
{
    if (pe) add_packed_attribute(acc, en->mask, pe, k0, factor, avx2);
    else add_float_attribute(acc, en->mask, float_at, factor);
}

static void normalize3(float *v, const float *fallback)
{
    float len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (len2 < 1e-16f) { v[0] = fallback[0]; v[1] = fallback[1]; v[2] = fallback[2]; return; }
    float inv = 1.0f / sqrtf(len2);
    v[0] *= inv; v[1] *= inv; v[2] *= inv;
}

/* Slerp of unit vectors; t may lie outside [0, 1] (extrapolation along the great circle).
 * The angle is atan2(|a x b|, a . b) and sin theta = |a x b|, not acos(a . b): in float acos
 * cannot tell angles within 3.4e-4 of 0 or pi apart (the float below 1 is 1 - 6e-8, and acos
 * of it 3.4e-4), so exactly opposite ends whose dot product rounded to -0.99999994 took the
 * slerp branch with sin theta = 3.4e-4 instead of the lerp, and the slerp of nearly opposite
 * ends erred by ~1e-7 / sin^2 theta. The cross product of parallel or opposite float vectors
 * is 0 (or a rounding residue), and atan2 keeps the angle accurate everywhere. */
static void slerp3(const float *a, const float *b, float t, float *out)
{
    const float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const float c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
    const float s = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    float wa, wb;
    if (s < 1e-6f) { wa = 1.0f - t; wb = t; }   /* parallel or opposite: the lerp */
    else {
        const float theta = atan2f(s, d);
        wa = sinf((1.0f - t) * theta) / s;
        wb = sinf(t * theta) / s;
    }
    for (int k = 0; k < 3; k++) out[k] = wa * a[k] + wb * b[k];
}

/* Adds channel `span`'s slerped normal displacement for the vertices in `touched`:
 * slerp(n_a, n_b, t) - n_base, scaled by the sequential factor. base_normals addresses the
 * block's vertex 0. */
static void add_slerp_normals(float *acc_n, const float *delta_a, const float *delta_b, uint64_t touched,
                              const mk_plan_span *span, const float *base_normals)
{
    for (; touched; touched &= touched - 1) {
        unsigned i = (unsigned)mk_ctz64(touched);
        const float *bn = base_normals + 3u * i;
        float base[3] = { bn[0], bn[1], bn[2] };
        normalize3(base, bn);
        float na[3] = { base[0], base[1], base[2] }, nb[3] = { base[0], base[1], base[2] };
        if (span->target_a >= 0) {
            for (int k = 0; k < 3; k++) na[k] = bn[k] + delta_a[3 * i + k];
            normalize3(na, base);
        }
        if (span->target_b >= 0) {
            for (int k = 0; k < 3; k++) nb[k] = bn[k] + delta_b[3 * i + k];
            normalize3(nb, base);
        }
        float s[3];
        slerp3(na, nb, span->t, s);
        for (int k = 0; k < 3; k++) acc_n[3 * i + k] += span->scale * (s[k] - base[k]);
    }
}

/* The accumulator starts as the base: vertices [lo, hi) of the block from base (the block's
 * vertex 0, base_stride floats per vertex), the rest zero (they may lie past the mesh end). */
MK_INLINE void init_block(float *restrict acc, const float *restrict base, size_t base_stride, uint32_t lo,
                          uint32_t hi)
{
    const int full = lo == 0 && hi == MK_BLOCK_SIZE;
    if (!full) memset(acc, 0, sizeof(block_acc));
    if (base_stride == 3) {
        if (full) memcpy(acc, base, sizeof(block_acc));    /* constant size: inlined */
        else memcpy(acc + 3 * lo, base + 3 * lo, sizeof(float) * 3 * (hi - lo));
        return;
    }
    for (uint32_t i = lo; i < hi; i++)
        for (int k = 0; k < 3; k++) acc[3 * i + k] = base[base_stride * i + (size_t)k];
}

/* Normalizes the triples [lo, hi) in place; where the length is below 1e-8 the base vector is
 * used instead. The first loop is written as arithmetic selects, so it vectorizes (the build
 * adds -fno-math-errno and -fvect-cost-model=dynamic for the runtime); short vectors are rare
 * and replaced afterwards. */
MK_INLINE void normalize_block(float *restrict v, const float *restrict base, size_t base_stride, size_t lo, size_t hi)
{
    int short_count = 0;
    for (size_t i = lo; i < hi; i++) {
        float x = v[3 * i], y = v[3 * i + 1], z = v[3 * i + 2];
        float len2 = x * x + y * y + z * z;
        float keep = len2 < 1e-16f ? 1.0f : 0.0f;
        float inv = 1.0f / sqrtf(len2 + keep);
        v[3 * i] = x * inv;
        v[3 * i + 1] = y * inv;
        v[3 * i + 2] = z * inv;
        short_count += len2 < 1e-16f;
    }
    if (!short_count) return;
    for (size_t i = lo; i < hi; i++) {
        float *o = v + 3 * i;
        if (o[0] * o[0] + o[1] * o[1] + o[2] * o[2] < 1e-16f)
            for (int k = 0; k < 3; k++) o[k] = base[base_stride * i + (size_t)k];
    }
}

/* Writes the triples [lo, hi) to a strided output addressing vertex lo. With `stream`, a
 * whole block going to a packed, 16-byte aligned output is written with non-temporal stores
 * (x86 SSE2): 768 bytes that bypass the caches and need no read-for-ownership. */
MK_INLINE void store_block(const float *restrict acc, uint32_t lo, uint32_t hi, uint8_t *restrict out, size_t stride,
                           int stream)
{
    const int full = lo == 0 && hi == MK_BLOCK_SIZE;
#if MK_HAVE_STREAMING
    if (stream && full && stride == 12 && (uintptr_t)out % 16 == 0) {
        for (uint32_t k = 0; k < 3 * MK_BLOCK_SIZE; k += 4)
            _mm_stream_ps((float *)(void *)out + k, _mm_loadu_ps(acc + k));
        return;
    }
#else
    (void)stream;
#endif
    if (stride == 12) {
        if (full) memcpy(out, acc, sizeof(block_acc));   /* constant size: inlined */
        else memcpy(out, acc + 3 * lo, sizeof(float) * 3 * (hi - lo));
        return;
    }
    for (uint32_t i = lo; i < hi; i++, out += stride) memcpy(out, acc + 3 * i, 12);
}

/* Whether a job's outputs are written with non-temporal stores (see mk_store_mode). */
static int job_streams(const mk_eval_job *job)
{
    if (job->store_mode != MK_STORE_AUTO) return job->store_mode == MK_STORE_STREAMING;
    /* The whole mesh's outputs, not the job's: a job system splitting a big mesh into small
     * ranges still writes more per frame than the caches keep. */
    size_t per_vertex = 12u + (job->normals ? 12u : 0u) + (job->tangents ? 16u : 0u);
    return (size_t)job->asset->meshes[job->mesh].vertex_count * per_vertex >= MK_STREAM_MIN_BYTES;
}

/* The per-block work of one job (see the top of this file), compiled per ISA level
 * (clones.h). */
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
    const uint8_t *entries = a->data + m->entries;
    const uint32_t stride = mk_entry_stride(m->flags), components = mk_mesh_components(m->flags);
    const uint32_t tangent_component = mk_attribute_component(m->flags, 2);
    const uint8_t *data = a->data + m->target_data;
    const size_t ps = mk_stride_or(job->positions_stride, 12), ns = mk_stride_or(job->normals_stride, 12),
                 ts = mk_stride_or(job->tangents_stride, 16);

    const int stream = job_streams(job);
#if MK_HAVE_AVX2_UNPACK
    const int avx2 = __builtin_cpu_supports("avx2");
#else
    const int avx2 = 0;
#endif
    block_acc acc_p, acc_n, acc_t, slerp_a, slerp_b;
    const uint32_t block_end = (end + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    for (uint32_t b = first / MK_BLOCK_SIZE; b < block_end; b++) {
        const uint32_t block_start = b * MK_BLOCK_SIZE;
        const uint32_t lo = (block_start > first ? block_start : first) - block_start;
        const uint32_t hi = (block_start + MK_BLOCK_SIZE < end ? block_start + MK_BLOCK_SIZE : end) - block_start;
        const float *bp = base_p + 3u * (size_t)block_start;
        const float *bn = want_normals ? base_n + 3u * (size_t)block_start : NULL;
        const float *bt = want_tangents ? base_t + 4u * (size_t)block_start : NULL;
        prefetch_ahead((const uint8_t *)bp, sizeof(block_acc));   /* the base arrays too */
        if (want_normals) prefetch_ahead((const uint8_t *)bn, sizeof(block_acc));
        if (want_tangents) prefetch_ahead((const uint8_t *)bt, 4 * sizeof(float) * MK_BLOCK_SIZE);
        init_block(acc_p, bp, 3, lo, hi);
        if (want_normals) init_block(acc_n, bn, 3, lo, hi);
        if (want_tangents) init_block(acc_t, bt, 4, lo, hi);
        int32_t open_channel = -1;          /* slerp channel whose deltas are being gathered */
        uint64_t touched = 0;
        for (uint32_t e = block_first[b]; e < block_first[b + 1]; e++) {
            const mk_blob_entry *en = mk_entry_at(entries, stride, e);
            const uint32_t ti = mk_entry_target(en);
            const float c = f.plan.coef[ti];
            if (c == 0.0f) continue;
            const mk_blob_target *tg = &f.targets[ti];
            const int packed = mk_entry_packed(en);   /* per entry: a quantized target's outliers are float */
            const uint8_t *p = data + (size_t)en->data * MK_DATA_UNIT;
            mk_packed_layout pe;
            const size_t float_bytes = 12u * (size_t)mk_popcount64(en->mask);   /* one attribute of a float entry */
            prefetch_ahead(p, (size_t)(packed ? mk_packed_layout_of(&pe, en, components, p)
                                              : mk_entry_bytes(en, m->flags, tg->flags)));
            const mk_packed_layout *pk = packed ? &pe : NULL;
            add_entry_attribute(acc_p, en, pk, 0, p, c * (packed ? tg->position_scale : 1.0f), avx2);
            if (!want_normals && !want_tangents) continue;
            p += float_bytes;
            if (tg->flags & MK_TARGET_HAS_NORMALS) {
                const int32_t sc = f.plan.slerp_channel[ti];
                if (sc < 0) {
                    if (want_normals) add_entry_attribute(acc_n, en, pk, 3, p, c * (packed ? tg->normal_scale : 1.0f), avx2);
                } else {
                    /* Gather this channel's two span targets' raw normal deltas. */
                    if (sc != open_channel) {
                        if (open_channel >= 0) add_slerp_normals(acc_n, slerp_a, slerp_b, touched, &f.plan.spans[open_channel], bn);
                        memset(slerp_a, 0, sizeof slerp_a);
                        memset(slerp_b, 0, sizeof slerp_b);
                        open_channel = sc;
                        touched = 0;
                    }
                    float *dst = (int32_t)ti == f.plan.spans[sc].target_a ? slerp_a : slerp_b;
                    add_entry_attribute(dst, en, pk, 3, p, packed ? tg->normal_scale : 1.0f, avx2);
                    touched |= en->mask;
                }
                p += float_bytes;
            }
            if (want_tangents && (tg->flags & MK_TARGET_HAS_TANGENTS))
                add_entry_attribute(acc_t, en, pk, tangent_component, p, c * (packed ? tg->tangent_scale : 1.0f), avx2);
        }
        if (open_channel >= 0) add_slerp_normals(acc_n, slerp_a, slerp_b, touched, &f.plan.spans[open_channel], bn);

        /* Each output vertex is written once. */
        const size_t out = (size_t)(block_start + lo - first);
        store_block(acc_p, lo, hi, (uint8_t *)job->positions + out * ps, ps, stream);
        if (want_normals) {
            normalize_block(acc_n, bn, 3, lo, hi);
            store_block(acc_n, lo, hi, (uint8_t *)job->normals + out * ns, ns, stream);
        }
        if (want_tangents) {
            normalize_block(acc_t, bt, 4, lo, hi);
            uint8_t *o = (uint8_t *)job->tangents + out * ts;
            for (uint32_t i = lo; i < hi; i++, o += ts) {
                memcpy(o, acc_t + 3 * i, 12);
                memcpy(o + 12, bt + 4 * i + 3, 4);
            }
        }
    }
#if MK_HAVE_STREAMING
    if (stream) _mm_sfence();   /* order the non-temporal stores before the job's completion */
#endif
}

/* The frame's per-target coefficients in the job's scratch. */
static void prepare_frame(const mk_eval_job *job, frame *f)
{
    const mk_asset *a = job->asset;
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    f->asset = a;
    f->mesh = m;
    f->targets = &a->targets[m->first_target];
    f->plan = mk_plan_at(job->scratch, m->target_count);
    mk_plan_fill(a, m, job->weights, job->stacking, job->normals != NULL && job->normal_mode == MK_NORMALS_SLERP, &f->plan);
}

mk_result mk_eval_run(const mk_eval_job *job, mk_error *err)
{
    mk_result r = mk_eval_validate(job, err);
    if (r != MK_OK || job_vertex_count(job) == 0) return r;
    frame f;
    prepare_frame(job, &f);
    eval_blocks(job, &f);
    return MK_OK;
}

uint64_t mk_eval_traffic(const mk_eval_job *job)
{
    if (mk_eval_validate(job, NULL) != MK_OK || job_vertex_count(job) == 0) return 0;
    frame f;
    prepare_frame(job, &f);
    const mk_blob_mesh *m = f.mesh;
    const uint32_t first = job->first_vertex, n = job_vertex_count(job), end = first + n;
    const uint32_t *block_first = (const uint32_t *)(job->asset->data + m->block_entries);
    const uint8_t *entries = job->asset->data + m->entries;
    const uint32_t stride = mk_entry_stride(m->flags);
    uint32_t strip = 0;
    if (!job->normals) strip |= MK_TARGET_HAS_NORMALS;
    if (!job->tangents) strip |= MK_TARGET_HAS_TANGENTS;
    const uint32_t b0 = first / MK_BLOCK_SIZE, b1 = (end + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    uint64_t bytes = 4u * (uint64_t)(b1 - b0 + 1);                      /* block table */
    for (uint32_t e = block_first[b0]; e < block_first[b1]; e++) {
        const mk_blob_entry *en = mk_entry_at(entries, stride, e);
        bytes += stride;                                                /* every header is read */
        const uint32_t ti = mk_entry_target(en);
        if (f.plan.coef[ti] == 0.0f) continue;
        bytes += mk_entry_bytes(en, m->flags, f.targets[ti].flags & ~strip);
    }
    /* Base arrays read and outputs written. */
    bytes += (uint64_t)n * 12u * 2u * (job->normals ? 2u : 1u);
    if (job->tangents) bytes += (uint64_t)n * 16u * 2u;
    return bytes;
}

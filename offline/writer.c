/* SPDX-License-Identifier: MIT */
/* mk_write_blob: raw model -> .morph blob (runtime/format.h, docs/format.md).
 *
 * Layout: header | section table | STRINGS | MESHES | CHANNELS | TARGETS | CLIPS | TRACKS |
 * KEYS | DATA, every piece 16-aligned. DATA holds, per mesh: base positions, normals,
 * tangents, triangles, control-point map, the block table, the entries and the delta data.
 *
 * Targets are cut into blocks of 64 vertices, one entry per touched block. An entry's mask
 * (mk_block_mask) holds the moved vertices plus short gaps between them, or the whole block
 * when little of it is unmoved, so the runtime adds few, long runs (a whole block is its
 * constant-trip loop) while few zeros are stored. Quantized targets store int16 per component
 * with a per-target, per-attribute scale = max|component| / 32767 over their int16 entries;
 * when the whole target's position error would exceed the tolerance, the entries whose deltas
 * do not fit it (outliers) are stored as int16 around a position offset where their spread
 * allows it (MK_ENTRY_OFFSET), else as float32, and the scales come from the int16 entries (a
 * target with no entry that fits either way is stored as float32).
 *
 * Deterministic: fixed iteration order, all padding zero, nothing taken from pointers/time.
 */
#include <float.h>
#include <math.h>
#include <string.h>
#include <threads.h>
#include "blob_io.h"
#include "block_mask.h"
#include "format.h"
#include "parallel.h"

typedef struct bytes {
    mk_arena *arena;
    uint8_t *data;
    size_t size, capacity;
    int failed;
} bytes;

static size_t pad16(size_t n) { return (n + 15u) & ~(size_t)15u; }

static int bytes_reserve(bytes *b, size_t extra)
{
    if (b->failed) return 0;
    if (extra > SIZE_MAX / 2 - b->size) { b->failed = 1; return 0; }
    if (b->size + extra <= b->capacity) return 1;
    size_t cap = b->capacity ? b->capacity : 4096;
    while (cap < b->size + extra) cap *= 2;
    uint8_t *p = mk_arena_realloc(b->arena, b->data, b->size, cap);
    if (!p) { b->failed = 1; return 0; }
    b->data = p;
    b->capacity = cap;
    return 1;
}

/* String table: offset of each string, appended in first-use order (deterministic). */
static uint32_t put_string(bytes *strings, const char *s)
{
    if (!s) s = "";
    size_t n = strlen(s) + 1;
    size_t at = strings->size;
    if (!bytes_reserve(strings, n)) return 0;
    memcpy(strings->data + at, s, n);
    strings->size += n;
    return (uint32_t)at;
}

/* ---- quantization ---- */

static float max_abs(const float *p, size_t n)
{
    float m = 0;
    for (size_t i = 0; i < n; i++) m = fabsf(p[i]) > m ? fabsf(p[i]) : m;
    return m;
}

static float quant_scale(float maxabs) { return maxabs > 0 ? maxabs / 32767.0f : 0.0f; }

/* roundf(v / scale) clamped to +-32767, without the libm call (a tenth of an import's time
 * went to roundf): clamping first gives the same integer (both bounds are integers), and the
 * clamped quotient converts to int32 exactly; its fraction (exact below 2^23) decides the
 * rounding, halves away from zero as roundf. */
static int16_t quantize(float v, float scale)
{
    if (scale == 0) return 0;
    float x = v / scale;
    x = x > 32767.f ? 32767.f : x < -32767.f ? -32767.f : x;
    int32_t i = (int32_t)x;
    float frac = x - (float)i;
    i += (frac >= 0.5f) - (frac <= -0.5f);
    return (int16_t)i;
}

/* |dequantized - exact| of one value stored as q around offset o (0 but in an offset entry). */
static double quant_error_of(float v, float o, int16_t q, float scale) { return fabs((double)o + (double)q * scale - (double)v); }

/* Largest |dequantized - exact| over the array. */
static double quant_error(const float *p, size_t n, float scale)
{
    double e = 0;
    for (size_t i = 0; i < n; i++) {
        double d = quant_error_of(p[i], 0.0f, quantize(p[i], scale), scale);
        if (d > e) e = d;
    }
    return e;
}

/* An upper bound of quant_error for a normal (not subnormal) scale: v / scale rounds to within
 * 2^-24 of |v / scale| <= 32767.002, i.e. within 2^-9, then to the nearest integer, so every
 * value errs by at most scale (0.5 + 2^-9) before the last double rounding. The bound allows
 * 2^-8: the other 2^-9 covers an offset entry's value - offset, which rounds by at most
 * 2^-24 x 32767 scale < 2^-9 scale (offset_fits). */
static double quant_error_bound(float scale) { return (double)scale * (0.5 + 1.0 / 256); }

typedef struct target_plan {
    uint32_t flags;
    float position_scale, normal_scale, tangent_scale;
    /* A quantized target's entries whose largest |position component| exceeds this are
     * float32 (INFINITY: none). */
    float entry_limit;
    double tolerance;                  /* the mesh's */
} target_plan;

/* The moved vertices [first, end) of a target in one block: from `first`, the target's
 * indices below the block's end. */
static uint32_t block_end(const mk_raw_target *t, uint32_t first, uint32_t block_limit)
{
    uint32_t end = first;
    while (end < t->count && t->indices[end] < block_limit) end++;
    return end;
}

/* The largest position magnitude an int16 entry may hold: the largest L whose scale
 * L / 32767 keeps quant_error_bound within the tolerance (0 when even the smallest normal
 * scale does not). */
static float entry_limit_for(double tolerance)
{
    float limit = (float)(tolerance / (0.5 + 1.0 / 256) * 32767.0);
    if (!(limit < FLT_MAX)) limit = FLT_MAX;
    while (limit > 0 && !(quant_scale(limit) >= FLT_MIN && quant_error_bound(quant_scale(limit)) <= tolerance))
        limit = quant_scale(limit) >= FLT_MIN ? nextafterf(limit, 0.0f) : 0.0f;
    return limit;
}

/* Whether a block's positions fit int16 around a common offset (the middle of each component's
 * range, written to offset[]): every |value - offset| within 0.99 of the entry limit, so a scale
 * these spreads set keeps quant_error_bound a hundredth below the tolerance. The rounding of
 * value - offset (at most 2^-24 |value - offset| <= 2^-9 scale) is within that bound's own
 * allowance. Returns the largest |value - offset|, or -1 when they do not fit. */
static float offset_fits(const float *positions, uint32_t count, float limit, float offset[3])
{
    float spread = 0;
    for (int c = 0; c < 3; c++) {
        float lo = INFINITY, hi = -INFINITY;
        for (uint32_t k = 0; k < count; k++) {
            const float v = positions[3u * k + (uint32_t)c];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
        offset[c] = lo + (hi - lo) * 0.5f;
        const float d = fmaxf(fabsf(hi - offset[c]), fabsf(lo - offset[c]));
        if (!(d <= 0.99f * limit)) return -1;
        spread = d > spread ? d : spread;
    }
    return spread;
}

/* Per-entry precision of a target the tolerance does not fit whole: the blocks whose
 * positions exceed entry_limit_for(tolerance) are int16 around an offset where their spread
 * allows it (offset_fits), else float32; the scales come from the int16 blocks and the offset
 * blocks' spreads. A target without such a rest stays float32. */
static void plan_entries(const mk_raw_target *t, target_plan *p)
{
    const float limit = entry_limit_for(p->tolerance);
    float pm = 0, nm = 0, tm = 0;
    int any_int16 = 0, any_outlier = 0;
    for (uint32_t first = 0; first < t->count;) {
        const uint32_t start = t->indices[first] / MK_BLOCK_SIZE * MK_BLOCK_SIZE;
        const uint32_t end = block_end(t, first, start + MK_BLOCK_SIZE), count = end - first;
        const size_t at = 3u * (size_t)first, n = 3u * (size_t)count;
        const float bm = max_abs(t->positions + at, n);
        first = end;
        float offset[3], spread = bm;
        if (bm > limit) {
            any_outlier = 1;
            spread = offset_fits(t->positions + at, count, limit, offset);
        }
        if (spread < 0) continue;   /* float32: its deltas set no scale */
        any_int16 = 1;   /* int16, or int16 around an offset (its spread then sets the scale too) */
        pm = spread > pm ? spread : pm;
        if (t->normals) { float x = max_abs(t->normals + at, n); nm = x > nm ? x : nm; }
        if (t->tangents) { float x = max_abs(t->tangents + at, n); tm = x > tm ? x : tm; }
    }
    if (!any_int16) return;
    p->flags |= MK_TARGET_QUANTIZED;
    p->entry_limit = any_outlier ? limit : INFINITY;  /* no block above it: the later passes need not look */
    p->position_scale = quant_scale(pm);
    if (t->normals) p->normal_scale = quant_scale(nm);
    if (t->tangents) p->tangent_scale = quant_scale(tm);
}

/* Decides a target's storage: int16 with per-attribute scales when the positions' error stays
 * within the tolerance, else per entry (plan_entries); float32 when asked. */
static void plan_target(const mk_raw_target *t, mk_precision precision, target_plan *p)
{
    p->flags = (t->normals ? MK_TARGET_HAS_NORMALS : 0u) | (t->tangents ? MK_TARGET_HAS_TANGENTS : 0u);
    p->entry_limit = INFINITY;
    if (precision == MK_PRECISION_FLOAT) return;
    size_t n = 3 * (size_t)t->count;
    float ps = quant_scale(max_abs(t->positions, n));
    /* The error pass only where the bound cannot decide (the errors reported are measured
     * while writing the data, in write_block). */
    if (!(ps >= FLT_MIN && quant_error_bound(ps) <= p->tolerance) && ps != 0) {
        double pe = quant_error(t->positions, n, ps);
        if (pe > p->tolerance) { plan_entries(t, p); return; }
    }
    p->flags |= MK_TARGET_QUANTIZED;
    p->position_scale = ps;
    if (t->normals) p->normal_scale = quant_scale(max_abs(t->normals, n));
    if (t->tangents) p->tangent_scale = quant_scale(max_abs(t->tangents, n));
}

/* How a target's moved vertices [first, end) of one block are stored. */
typedef enum entry_kind { ENTRY_INT16, ENTRY_FLOAT, ENTRY_OFFSET } entry_kind;

static entry_kind entry_kind_of(const mk_raw_target *t, const target_plan *p, uint32_t first, uint32_t end,
                                float offset[3])
{
    if (!(p->flags & MK_TARGET_QUANTIZED)) return ENTRY_FLOAT;
    if (p->entry_limit == INFINITY) return ENTRY_INT16;
    const float *positions = t->positions + 3u * (size_t)first;
    if (max_abs(positions, 3u * (size_t)(end - first)) <= p->entry_limit) return ENTRY_INT16;
    return offset_fits(positions, end - first, p->entry_limit, offset) >= 0 ? ENTRY_OFFSET : ENTRY_FLOAT;
}

typedef struct plan_loop {
    const mk_raw_target **targets;
    target_plan *plans;
    mk_precision precision;
} plan_loop;

static void plan_item(void *user, uint32_t item, uint32_t worker)
{
    plan_loop *l = user;
    (void)worker;
    plan_target(l->targets[item], l->precision, &l->plans[item]);
}

/* Writes one entry's data for the vertices of `mask` in block `block`, in bit order: the
 * position triples, then the normal triples, then the tangent triples (`attr` bytes each),
 * int16 when `quantized`, else float32. A vertex the mask covers but the target does not move
 * keeps the zeros dst already holds (the blob is zeroed, and 0 quantizes to 0 without error).
 * cursor is the target's first index in the block; each vertex is looked up once for all
 * attributes. The largest int16 error per attribute is kept in error[] (every value is
 * written once, so this is the error over the whole target). */
static void put_entry(uint8_t *dst, const mk_raw_target *t, const target_plan *p, int quantized,
                      const float *offset, uint32_t cursor, uint64_t mask, uint32_t block, size_t attr,
                      double error[3])
{
    const float *src[3] = { t->positions, t->normals, t->tangents };
    const float scale[3] = { p->position_scale, p->normal_scale, p->tangent_scale };
    uint8_t *out[3] = { dst, dst + attr, dst + (t->normals ? 2 * attr : attr) };
    /* Per attribute, what its values are stored relative to: an offset entry's positions to its
     * offset, everything else to zero. */
    static const float zero[3] = { 0, 0, 0 };
    const float *base[3] = { offset ? offset : zero, zero, zero };
    uint32_t k = cursor;
    size_t j = 0;
    for (uint64_t bits = mask; bits; bits &= bits - 1, j++) {
        uint32_t v = block * MK_BLOCK_SIZE + mk_ctz64(bits);
        while (k < t->count && t->indices[k] < v) k++;
        if (k == t->count || t->indices[k] != v) continue;
        for (int a = 0; a < 3; a++) {
            if (!src[a]) continue;
            const float *value = &src[a][3u * k];
            if (quantized) {
                const float *o = base[a];
                int16_t q[3] = { quantize(value[0] - o[0], scale[a]), quantize(value[1] - o[1], scale[a]),
                                 quantize(value[2] - o[2], scale[a]) };
                memcpy(out[a] + 6 * j, q, 6);
                for (int c = 0; c < 3; c++) {
                    double e = quant_error_of(value[c], o[c], q[c], scale[a]);
                    error[a] = e > error[a] ? e : error[a];
                }
            } else {
                memcpy(out[a] + 12 * j, value, 12);
            }
        }
    }
}

/* One target's share of a mesh's block data. */
typedef struct target_layout {
    const mk_raw_target *t;
    uint64_t entry_count, data_size;   /* counted first: blocks touched, bytes (entries 16-aligned) */
    uint64_t first_entry, base;        /* then placed: its first entry, its data's offset */
    uint64_t cursor;                   /* the entry merge's position */
    double error[3];                   /* written: largest quantization error per attribute */
    mk_raw_target *own;                /* consumed (mk_write_blob_consuming): emptied once written */
} target_layout;

typedef struct layout_loop {
    const mk_raw_mesh *m;
    const target_plan *plans;
    uint32_t gap;                      /* mk_block_mask's */
    target_layout *targets;
    uint32_t *entry_block;             /* per entry, target-major */
    uint8_t *entry_kind;               /* per entry: its entry_kind */
    uint64_t *entry_mask, *entry_data; /* the entry's vertices; its data's offset in the target data */
    uint8_t *data;                     /* the mesh's target data, in the blob */
    mk_arena *owner;                   /* consuming: the raw arena the written targets go back to */
    mtx_t *owner_lock;
    const mk_write_options *options;   /* its ready callback hears of each target's finished data */
    const uint8_t *blob;               /* where data lies in it: its ready offsets count from here */
} layout_loop;

/* Calls fn(user, block, first, end, mask, kind, offset) for each block a target touches, in
 * block order: the target's moved vertices in it are indices [first, end); kind and offset are
 * entry_kind_of's; the mask is mk_block_mask's, or exactly the moved vertices for an offset entry
 * (a covered vertex the target does not move would read as the offset). */
typedef void (*block_fn)(void *user, uint32_t block, uint32_t first, uint32_t end, uint64_t mask, entry_kind kind,
                         const float offset[3]);

static void target_blocks(const layout_loop *l, const mk_raw_target *tg, const target_plan *plan, block_fn fn,
                          void *user)
{
    const uint32_t vertex_count = l->m->vertex_count;
    for (uint32_t first = 0; first < tg->count;) {
        uint32_t block = tg->indices[first] / MK_BLOCK_SIZE, start = block * MK_BLOCK_SIZE;
        uint32_t in_block = vertex_count - start < MK_BLOCK_SIZE ? vertex_count - start : MK_BLOCK_SIZE;
        uint32_t end = block_end(tg, first, start + in_block);
        uint64_t moved = 0;
        for (uint32_t k = first; k < end; k++) moved |= 1ull << (tg->indices[k] - start);
        float offset[3] = { 0, 0, 0 };
        const entry_kind kind = entry_kind_of(tg, plan, first, end, offset);
        const uint64_t mask = kind == ENTRY_OFFSET ? moved : mk_block_mask(moved, in_block, l->gap);
        fn(user, block, first, end, mask, kind, offset);
        first = end;
    }
}

/* Bytes of an entry's data: the offset, then the attributes. */
static uint64_t entry_bytes(const target_plan *p, entry_kind kind, uint64_t mask)
{
    return (kind == ENTRY_OFFSET ? MK_ENTRY_OFFSET_BYTES : 0u) +
           mk_entry_data_size(mk_entry_flags(p->flags, kind != ENTRY_FLOAT), mk_popcount64(mask));
}

typedef struct layout_item {
    const layout_loop *l;
    target_layout *tl;
    uint32_t index;
} layout_item;

static void count_block(void *user, uint32_t block, uint32_t first, uint32_t end, uint64_t mask, entry_kind kind,
                        const float offset[3])
{
    layout_item *it = user;
    (void)block;
    (void)first;
    (void)end;
    (void)offset;
    uint64_t size = entry_bytes(&it->l->plans[it->index], kind, mask);
    it->tl->data_size = pad16((size_t)it->tl->data_size) + size;
    it->tl->entry_count++;
}

static void layout_count(void *user, uint32_t item, uint32_t worker)
{
    layout_loop *l = user;
    (void)worker;
    layout_item it = { l, &l->targets[item], item };
    target_blocks(l, it.tl->t, &l->plans[item], count_block, &it);
}

static void write_block(void *user, uint32_t block, uint32_t first, uint32_t end, uint64_t mask, entry_kind kind,
                        const float offset[3])
{
    layout_item *it = user;
    const layout_loop *l = it->l;
    target_layout *tl = it->tl;
    const mk_raw_target *tg = tl->t;
    const target_plan *p = &l->plans[it->index];
    (void)end;
    uint64_t e = tl->cursor++;
    uint64_t at = pad16((size_t)tl->data_size);
    tl->data_size = at + entry_bytes(p, kind, mask);
    l->entry_block[e] = block;
    l->entry_kind[e] = (uint8_t)kind;
    l->entry_mask[e] = mask;
    l->entry_data[e] = tl->base + at;
    uint8_t *dst = l->data + tl->base + at;
    if (kind == ENTRY_OFFSET) {   /* x, y, z, then the 4 zero bytes the blob already holds */
        memcpy(dst, offset, 3 * sizeof(float));
        dst += MK_ENTRY_OFFSET_BYTES;
    }
    const size_t attr = (size_t)mk_entry_data_size(mk_entry_flags(0u, kind != ENTRY_FLOAT), mk_popcount64(mask));
    put_entry(dst, tg, p, kind != ENTRY_FLOAT, kind == ENTRY_OFFSET ? offset : NULL, first, mask, block, attr,
              tl->error);
}

static void layout_write(void *user, uint32_t item, uint32_t worker)
{
    layout_loop *l = user;
    (void)worker;
    layout_item it = { l, &l->targets[item], item };
    it.tl->cursor = it.tl->first_entry;
    it.tl->data_size = 0;
    target_blocks(l, it.tl->t, &l->plans[item], write_block, &it);
    if (l->options->ready && it.tl->data_size)
        l->options->ready(l->options->ready_user, l->blob, (uint64_t)(l->data - l->blob) + it.tl->base,
                          pad16((size_t)it.tl->data_size));
    mk_raw_target *own = it.tl->own;
    if (!own) return;
    void *arrays[] = { own->indices, own->positions, own->normals, own->tangents };
    mk_arena_release_locked(l->owner, l->owner_lock, arrays, sizeof arrays / sizeof arrays[0]);
    own->indices = NULL;
    own->positions = own->normals = own->tangents = NULL;
    own->count = 0;
}

typedef struct mesh_out {
    uint64_t positions, normals, tangents, triangles, control_points, block_entries, entries, target_data;
    uint64_t entry_count, target_data_size;
    uint32_t target_count, blocks;
    layout_loop l;                     /* the targets' layout, counted by plan_mesh_data */
} mesh_out;

/* Offset of the next n bytes of the data section (16-aligned); advances the cursor. */
static uint64_t place(uint64_t *cursor, uint64_t n)
{
    uint64_t at = (*cursor + 15u) & ~(uint64_t)15u;
    *cursor = at + n;
    return at;
}

/* Places one mesh's arrays in the data section (offsets relative to it, from *cursor on) and
 * counts its targets' blocks and bytes; nothing is written yet.
 *
 * Delta data is laid out target-major (all blocks of target 0, then target 1, ...) while
 * the entries stay block-major: a frame then reads each active target as one sequential
 * stream, which the hardware prefetcher and the TLB handle well, and never touches the
 * pages of inactive targets. Targets are independent: their sizes are counted here, their
 * data written straight into the blob by write_mesh_data, both on worker threads (no
 * allocation there); the entries are merged block by block afterwards. */
static mk_result plan_mesh_data(const mk_raw_asset *raw, mk_raw_asset *consume, uint32_t mi, uint32_t first_channel,
                                uint32_t channel_count, const target_plan *plans, uint32_t gap,
                                uint32_t threads, mk_arena *arena, uint64_t *cursor, mesh_out *out, mk_error *err)
{
    const mk_raw_mesh *m = &raw->meshes[mi];
    memset(out, 0, sizeof *out);
    out->positions = place(cursor, 12u * (uint64_t)m->vertex_count);
    if (m->normals) out->normals = place(cursor, 12u * (uint64_t)m->vertex_count);
    if (m->tangents) out->tangents = place(cursor, 16u * (uint64_t)m->vertex_count);
    out->triangles = place(cursor, 12u * (uint64_t)m->triangle_count);
    out->control_points = place(cursor, 4u * (uint64_t)m->vertex_count);

    uint32_t target_count = 0;
    for (uint32_t c = first_channel; c < first_channel + channel_count; c++) target_count += raw->channels[c].target_count;
    layout_loop *l = &out->l;
    if (target_count > MK_MAX_MESH_TARGETS)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: more than 2^24 targets", mi);
    *l = (layout_loop){ .m = m, .plans = plans, .gap = gap, .owner = consume ? &consume->arena : NULL };
    l->targets = mk_arena_array(arena, target_count + 1, sizeof *l->targets);
    if (!l->targets) return mk_error_oom(err, "planning blocks");
    uint32_t k = 0;
    for (uint32_t c = first_channel; c < first_channel + channel_count; c++)
        for (uint32_t j = 0; j < raw->channels[c].target_count; j++, k++) {
            l->targets[k].t = &raw->channels[c].targets[j];
            if (consume) l->targets[k].own = &consume->channels[c].targets[j];
        }
    mk_parallel_for(target_count, threads, layout_count, l);
    uint64_t entry_count = 0, total = 0;
    for (uint32_t t = 0; t < target_count; t++) {
        l->targets[t].first_entry = entry_count;
        l->targets[t].base = total;
        entry_count += l->targets[t].entry_count;
        total += pad16(l->targets[t].data_size);
    }
    if (entry_count > UINT32_MAX)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: more than 2^32 block entries", mi);
    if (total / MK_ALIGN > UINT32_MAX)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: target data exceeds 64 GiB", mi);
    out->target_count = target_count;
    out->blocks = (m->vertex_count + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    out->block_entries = place(cursor, 4u * ((uint64_t)out->blocks + 1));
    out->entries = place(cursor, entry_count * sizeof(mk_blob_entry));
    out->entry_count = entry_count;
    out->target_data = place(cursor, total);
    out->target_data_size = total;
    return MK_OK;
}

/* Writes one mesh's arrays, target data and entries into the data section `data` (zeroed:
 * the padding is left as it is) at the offsets plan_mesh_data chose. */
static mk_result write_mesh_data(const mk_raw_mesh *m, const mk_write_options *options, mk_arena *arena,
                                 uint8_t *blob, uint64_t data_base, mesh_out *out, mk_write_report *report,
                                 mk_error *err)
{
    uint8_t *data = blob + data_base;
    const uint32_t threads = options->threads;
    memcpy(data + out->positions, m->positions, 12u * (size_t)m->vertex_count);
    if (m->normals) memcpy(data + out->normals, m->normals, 12u * (size_t)m->vertex_count);
    if (m->tangents) memcpy(data + out->tangents, m->tangents, 16u * (size_t)m->vertex_count);
    if (m->triangle_count) memcpy(data + out->triangles, m->triangles, 12u * (size_t)m->triangle_count);
    uint32_t *cp = (uint32_t *)(void *)(data + out->control_points);
    for (uint32_t v = 0; v < m->vertex_count; v++) cp[v] = m->control_points ? m->control_points[v] : v;

    layout_loop *l = &out->l;
    const uint32_t target_count = out->target_count, blocks = out->blocks;
    const uint64_t entry_count = out->entry_count;
    /* Per target entry (target-major): its block, mask and data offset. */
    uint32_t *block_first = (uint32_t *)(void *)(data + out->block_entries);
    l->entry_block = mk_arena_array(arena, entry_count + 1, sizeof *l->entry_block);
    l->entry_mask = mk_arena_array(arena, entry_count + 1, sizeof *l->entry_mask);
    l->entry_data = mk_arena_array(arena, entry_count + 1, sizeof *l->entry_data);
    l->entry_kind = mk_arena_array(arena, entry_count + 1, sizeof *l->entry_kind);
    if (!l->entry_block || !l->entry_mask || !l->entry_data || !l->entry_kind)
        return mk_error_oom(err, "planning blocks");
    l->data = data + out->target_data;
    l->options = options;
    l->blob = blob;
    mtx_t lock;
    if (l->owner) {
        if (mtx_init(&lock, mtx_plain) != thrd_success) return mk_error_oom(err, "writing block data");
        l->owner_lock = &lock;
    }
    mk_parallel_for(target_count, threads, layout_write, l);
    if (l->owner) mtx_destroy(&lock);
    /* Entries block-major, targets in blob order within a block. */
    mk_blob_entry *entries = (mk_blob_entry *)(void *)(data + out->entries);
    uint64_t e = 0;
    for (uint32_t t = 0; t < target_count; t++) l->targets[t].cursor = l->targets[t].first_entry;
    for (uint32_t b = 0; b < blocks; b++) {
        block_first[b] = (uint32_t)e;
        for (uint32_t t = 0; t < target_count; t++) {
            target_layout *tl = &l->targets[t];
            if (tl->cursor == tl->first_entry + tl->entry_count || l->entry_block[tl->cursor] != b) continue;
            const entry_kind kind = (entry_kind)l->entry_kind[tl->cursor];
            const uint32_t flags = kind == ENTRY_FLOAT ? (uint32_t)MK_ENTRY_FLOAT
                                 : kind == ENTRY_OFFSET ? (uint32_t)MK_ENTRY_OFFSET : 0u;
            mk_blob_entry be = { t | flags, (uint32_t)(l->entry_data[tl->cursor] / MK_ALIGN), l->entry_mask[tl->cursor] };
            report->float_entries += kind == ENTRY_FLOAT && (l->plans[t].flags & MK_TARGET_QUANTIZED);
            report->offset_entries += kind == ENTRY_OFFSET;
            entries[e++] = be;
            tl->cursor++;
        }
    }
    block_first[blocks] = (uint32_t)e;
    report->target_bytes += entry_count * sizeof(mk_blob_entry) + out->target_data_size;
    report->entry_count += entry_count;
    for (uint32_t t = 0; t < target_count; t++) {
        const double *te = l->targets[t].error;
        if (te[0] > report->max_position_error) report->max_position_error = te[0];
        if (te[1] > report->max_normal_error) report->max_normal_error = te[1];
        if (te[2] > report->max_tangent_error) report->max_tangent_error = te[2];
    }
    void *scratch[] = { l->targets, l->entry_block, l->entry_mask, l->entry_data, l->entry_kind };
    for (size_t i = 0; i < sizeof scratch / sizeof scratch[0]; i++) mk_arena_release(arena, scratch[i]);
    l->targets = NULL;
    return MK_OK;
}

static mk_result write_blob(const mk_raw_asset *raw, mk_raw_asset *consume, const mk_write_options *options,
                            mk_arena *arena, void **blob_out, size_t *size_out, mk_write_report *report_out,
                            mk_error *err);

mk_result mk_write_blob(const mk_raw_asset *raw, const mk_write_options *options, mk_arena *arena,
                        void **blob_out, size_t *size_out, mk_write_report *report_out, mk_error *err)
{
    return write_blob(raw, NULL, options, arena, blob_out, size_out, report_out, err);
}

mk_result mk_write_blob_consuming(mk_raw_asset *raw, const mk_write_options *options, void **blob_out, size_t *size_out,
                                  mk_write_report *report_out, mk_error *err)
{
    return write_blob(raw, raw, options, &raw->arena, blob_out, size_out, report_out, err);
}

/* consume: NULL, or raw itself (its targets are emptied as they are written). */
static mk_result write_blob(const mk_raw_asset *raw, mk_raw_asset *consume, const mk_write_options *options,
                            mk_arena *arena, void **blob_out, size_t *size_out, mk_write_report *report_out,
                            mk_error *err)
{
    mk_write_options opt = options ? *options : (mk_write_options){ 0 };
    if (opt.gap_limit == 0) opt.gap_limit = MK_DEFAULT_FILL_GAP + 1;
    if (opt.gap_limit > MK_BLOCK_SIZE + 1) opt.gap_limit = MK_BLOCK_SIZE + 1;   /* 65: every touched block whole */
    if (opt.precision != MK_PRECISION_Q16 && opt.precision != MK_PRECISION_FLOAT)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "write: unknown precision");
    if (!(opt.tolerance >= 0) || !isfinite(opt.tolerance))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "write: tolerance must be finite and >= 0");
    mk_result r = mk_raw_validate(raw, err);
    if (r) return r;

    mk_write_report report;
    memset(&report, 0, sizeof report);
    uint32_t target_count = 0, track_count = 0, key_count = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++) target_count += raw->channels[c].target_count;
    for (uint32_t c = 0; c < raw->clip_count; c++) {
        track_count += raw->clips[c].track_count;
        for (uint32_t t = 0; t < raw->clips[c].track_count; t++) key_count += raw->clips[c].tracks[t].key_count;
    }

    bytes strings = { arena, NULL, 0, 0, 0 };
    uint64_t data_size = 0;   /* the data section, placed mesh by mesh before anything is written */
    mk_blob_mesh *meshes = mk_arena_array(arena, raw->mesh_count + 1, sizeof *meshes);
    mk_blob_channel *channels = mk_arena_array(arena, raw->channel_count + 1, sizeof *channels);
    mk_blob_target *targets = mk_arena_array(arena, target_count + 1, sizeof *targets);
    target_plan *plans = mk_arena_array(arena, target_count + 1, sizeof *plans);
    mk_blob_clip *clips = mk_arena_array(arena, raw->clip_count + 1, sizeof *clips);
    mk_blob_track *tracks = mk_arena_array(arena, track_count + 1, sizeof *tracks);
    mk_key *keys = mk_arena_array(arena, key_count + 1, sizeof *keys);
    mesh_out *mesh_data = mk_arena_array(arena, raw->mesh_count + 1, sizeof *mesh_data);
    if (!meshes || !channels || !targets || !plans || !clips || !tracks || !keys || !mesh_data)
        return mk_error_oom(err, "writing the blob tables");
    put_string(&strings, "");

    /* Per-target precision under each mesh's tolerance, decided on worker threads. */
    const mk_raw_target **all_targets = mk_arena_array(arena, target_count + 1, sizeof *all_targets);
    if (!all_targets) return mk_error_oom(err, "writing the blob tables");
    for (uint32_t mi = 0, c = 0, k = 0; mi < raw->mesh_count; mi++) {
        double tolerance = opt.tolerance > 0 ? opt.tolerance : 1e-4 * mk_raw_mesh_diagonal(&raw->meshes[mi]);
        if (tolerance > report.tolerance_used) report.tolerance_used = tolerance;
        for (; c < raw->channel_count && raw->channels[c].mesh == mi; c++)
            for (uint32_t j = 0; j < raw->channels[c].target_count; j++, k++) {
                all_targets[k] = &raw->channels[c].targets[j];
                memset(&plans[k], 0, sizeof plans[k]);
                plans[k].tolerance = tolerance;
            }
    }
    plan_loop pl = { all_targets, plans, opt.precision };
    mk_parallel_for(target_count, opt.threads, plan_item, &pl);
    mk_arena_release(arena, all_targets);
    for (uint32_t k = 0; k < target_count; k++) {
        if (!(plans[k].flags & MK_TARGET_QUANTIZED)) { report.float_targets++; continue; }
        report.quantized_targets++;
    }
    mk_phase_log_mark(opt.phases, "quantize");

    /* Channels and targets. */
    uint32_t t_index = 0;
    for (uint32_t mi = 0, c = 0; mi < raw->mesh_count; mi++) {
        const mk_raw_mesh *m = &raw->meshes[mi];
        mk_blob_mesh *bm = &meshes[mi];
        bm->name = put_string(&strings, m->name);
        bm->first_channel = c;
        bm->first_target = t_index;
        for (; c < raw->channel_count && raw->channels[c].mesh == mi; c++) {
            const mk_raw_channel *ch = &raw->channels[c];
            mk_blob_channel *bc = &channels[c];
            bc->name = put_string(&strings, ch->name);
            bc->origin = put_string(&strings, ch->origin);
            bc->mesh = mi;
            bc->first_target = t_index;
            bc->target_count = ch->target_count;
            bc->default_weight = ch->default_weight;
            for (uint32_t k = 0; k < ch->target_count; k++, t_index++) {
                const mk_raw_target *t = &ch->targets[k];
                mk_blob_target *bt = &targets[t_index];
                bt->name = put_string(&strings, t->name);
                bt->channel = c;
                bt->full_weight = t->full_weight;
                bt->flags = plans[t_index].flags;
                bt->position_scale = plans[t_index].position_scale;
                bt->normal_scale = plans[t_index].normal_scale;
                bt->tangent_scale = plans[t_index].tangent_scale;
                bt->moved_vertices = t->count;
            }
            bm->channel_count++;
        }
        bm->target_count = t_index - bm->first_target;
        mk_phase_log_mark(opt.phases, "quantize");
        r = plan_mesh_data(raw, consume, mi, bm->first_channel, bm->channel_count, &plans[bm->first_target],
                           opt.gap_limit - 1, opt.threads, arena, &data_size, &mesh_data[mi], err);
        mk_phase_log_mark(opt.phases, "lay out blocks");
        if (r) return r;
        bm->vertex_count = m->vertex_count;
        bm->control_point_count = m->control_points ? m->control_point_count : m->vertex_count;
        bm->triangle_count = m->triangle_count;
        bm->stacking = (uint32_t)m->stacking;
        bm->flags = (m->normals ? MK_MESH_HAS_NORMALS : 0u) | (m->tangents ? MK_MESH_HAS_TANGENTS : 0u);
        bm->gltf_node = m->gltf_node;
        bm->gltf_mesh = m->gltf_mesh;
        bm->gltf_primitive = m->gltf_primitive;
        bm->block_count = (m->vertex_count + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
        memcpy(bm->world, m->world, sizeof bm->world);
    }
    for (uint32_t ci = 0, tr = 0, ki = 0; ci < raw->clip_count; ci++) {
        const mk_raw_clip *clip = &raw->clips[ci];
        clips[ci].name = put_string(&strings, clip->name);
        clips[ci].first_track = tr;
        clips[ci].track_count = clip->track_count;
        clips[ci].start = clip->start;
        clips[ci].duration = clip->duration;
        for (uint32_t t = 0; t < clip->track_count; t++, tr++) {
            tracks[tr].channel = clip->tracks[t].channel;
            tracks[tr].first_key = ki;
            tracks[tr].key_count = clip->tracks[t].key_count;
            for (uint32_t k = 0; k < clip->tracks[t].key_count; k++, ki++) {
                keys[ki] = clip->tracks[t].keys[k];
                keys[ki].reserved = 0;
            }
        }
    }
    if (strings.failed) return mk_error_oom(err, "writing strings");
    if (strings.size > UINT32_MAX)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "write: names exceed 4 GiB");

    /* Final placement: header, table, the sections in kind order, then DATA. */
    struct { uint32_t kind, elem; uint64_t count; const void *src; } parts[MK_SECTION_KIND_COUNT - 1] = {
        { MK_SECTION_STRINGS, 1, strings.size, strings.data },
        { MK_SECTION_MESHES, sizeof(mk_blob_mesh), raw->mesh_count, meshes },
        { MK_SECTION_CHANNELS, sizeof(mk_blob_channel), raw->channel_count, channels },
        { MK_SECTION_TARGETS, sizeof(mk_blob_target), target_count, targets },
        { MK_SECTION_CLIPS, sizeof(mk_blob_clip), raw->clip_count, clips },
        { MK_SECTION_TRACKS, sizeof(mk_blob_track), track_count, tracks },
        { MK_SECTION_KEYS, sizeof(mk_key), key_count, keys },
        { MK_SECTION_DATA, 1, data_size, NULL },  /* written in place below */
    };
    const uint32_t section_count = MK_SECTION_KIND_COUNT - 1;
    mk_blob_section table[MK_SECTION_KIND_COUNT - 1];
    uint64_t at = sizeof(mk_blob_header) + sizeof table;
    for (uint32_t i = 0; i < section_count; i++) {
        at = pad16(at);
        table[i].kind = parts[i].kind;
        table[i].element_size = parts[i].elem;
        table[i].count = parts[i].count;
        table[i].offset = at;
        table[i].size = parts[i].count * parts[i].elem;
        at += table[i].size;
    }
    uint64_t total = pad16(at);
    uint64_t data_base = table[section_count - 1].offset;
    for (uint32_t mi = 0; mi < raw->mesh_count; mi++) {
        const mesh_out *o = &mesh_data[mi];
        mk_blob_mesh *bm = &meshes[mi];
        bm->positions = data_base + o->positions;
        bm->normals = raw->meshes[mi].normals ? data_base + o->normals : 0;
        bm->tangents = raw->meshes[mi].tangents ? data_base + o->tangents : 0;
        bm->triangles = data_base + o->triangles;
        bm->control_points = data_base + o->control_points;
        bm->block_entries = data_base + o->block_entries;
        bm->entries = data_base + o->entries;
        bm->entry_count = o->entry_count;
        bm->target_data = data_base + o->target_data;
        bm->target_data_size = o->target_data_size;
    }
    if (total > SIZE_MAX) return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "write: blob exceeds the address space");
    /* One zeroed allocation for the whole blob: the meshes' data is written straight into it
     * (no growing buffer copied at the end) and every padding byte stays zero. */
    uint8_t *blob = mk_arena_alloc(arena, (size_t)total);
    if (!blob) return mk_error_oom(err, "allocating the blob");
    for (uint32_t mi = 0; mi < raw->mesh_count; mi++) {
        r = write_mesh_data(&raw->meshes[mi], &opt, arena, blob, data_base, &mesh_data[mi], &report, err);
        if (r) return r;
    }
    mk_phase_log_mark(opt.phases, "lay out blocks");
    mk_blob_header header;
    memset(&header, 0, sizeof header);
    memcpy(header.magic, MK_MAGIC, 8);
    header.version = MK_FORMAT_VERSION;
    header.header_size = sizeof header;
    header.file_size = total;
    header.section_count = section_count;
    memcpy(blob + sizeof header, table, sizeof table);
    for (uint32_t i = 0; i < section_count; i++)
        if (table[i].size && parts[i].src) memcpy(blob + table[i].offset, parts[i].src, (size_t)table[i].size);
    memcpy(blob, &header, sizeof header);
    header.checksum = mk_checksum(blob + 32, total - 32);
    memcpy(blob, &header, sizeof header);

    mk_arena_release(arena, strings.data);
    mk_arena_release(arena, meshes);
    mk_arena_release(arena, channels);
    mk_arena_release(arena, targets);
    mk_arena_release(arena, plans);
    mk_arena_release(arena, clips);
    mk_arena_release(arena, tracks);
    mk_arena_release(arena, keys);
    mk_arena_release(arena, mesh_data);
    mk_phase_log_mark(opt.phases, "assemble and checksum");
    report.total_bytes = total;
    if (report_out) *report_out = report;
    *blob_out = blob;
    *size_out = (size_t)total;
    return MK_OK;
}

/* SPDX-License-Identifier: MIT */
/* mk_write_blob: raw model -> .morph blob (runtime/format.h, docs/format.md).
 *
 * Layout: header | section table | STRINGS | MESHES | CHANNELS | TARGETS | CLIPS | TRACKS |
 * KEYS | DATA, every piece 16-aligned. DATA holds, per mesh: base positions, normals,
 * tangents, triangles, control-point map, the block table, the entries and the delta data.
 *
 * Targets are cut into blocks of 64 vertices, one entry per block where a target keeps a
 * nonzero value. Quantized targets store integers at one step per attribute and mesh (the
 * position step from the tolerance, the normal and tangent step from the normal tolerance):
 * per entry and component the smallest value is the offset and the rest are packed in as few
 * bits as their range needs (0-16), vertices whose values are all zero left out of the mask
 * (mk_block_mask may fill short gaps). An entry whose values span more than 16 bits is stored
 * as float32; one whose position offsets leave int16 carries int32 offsets (MK_ENTRY_WIDE).
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

/* The error bound of a value stored as the nearest multiple of `step`: half a step, and 2^-8
 * of a step more for the float32 arithmetic that evaluates it (the step times an integer below
 * 2^24 rounds by at most 2^-24 of it). */
static double quant_error_bound(float step) { return (double)step * (0.5 + 1.0 / 256); }

/* The largest step whose bound stays within the tolerance (0: none does, store float32). */
static float step_for(double tolerance)
{
    float step = (float)(tolerance / (0.5 + 1.0 / 256));
    if (!(step < FLT_MAX)) step = FLT_MAX;
    while (step > 0 && !(step >= FLT_MIN && quant_error_bound(step) <= tolerance))
        step = step >= FLT_MIN ? nextafterf(step, 0.0f) : 0.0f;
    return step;
}

/* The nearest integer to value / step (halves away from zero), from the reciprocal in double
 * (within 2^-40 of a step of the quotient: no libm call in the writer's hottest loop), clamped
 * beyond any storable magnitude so the conversion is defined. */
static int64_t quantize(float value, double inverse_step)
{
    double x = (double)value * inverse_step;
    x = x > 0x1p40 ? 0x1p40 : x < -0x1p40 ? -0x1p40 : x;
    return (int64_t)(x < 0 ? x - 0.5 : x + 0.5);
}

typedef struct target_plan {
    uint32_t flags;
    float position_scale, normal_scale, tangent_scale;   /* the steps of a quantized target */
} target_plan;

/* The moved vertices [first, end) of a target in one block: from `first`, the target's
 * indices below the block's end. */
static uint32_t block_end(const mk_raw_target *t, uint32_t first, uint32_t block_limit)
{
    uint32_t end = first;
    while (end < t->count && t->indices[end] < block_limit) end++;
    return end;
}

/* A target's storage: packed at the mesh's steps (every entry whose values do not fit 16 bits
 * around its offsets is float32), or float32 when asked or when a step is 0 (a tolerance too
 * small for a normal float). */
static void plan_target(const mk_raw_target *t, mk_precision precision, const float steps[2], target_plan *p)
{
    p->flags = (t->normals ? MK_TARGET_HAS_NORMALS : 0u) | (t->tangents ? MK_TARGET_HAS_TANGENTS : 0u);
    if (precision == MK_PRECISION_FLOAT || steps[0] == 0 || (t->normals || t->tangents ? steps[1] == 0 : 0)) return;
    p->flags |= MK_TARGET_QUANTIZED;
    p->position_scale = steps[0];
    if (t->normals) p->normal_scale = steps[1];
    if (t->tangents) p->tangent_scale = steps[1];
}

typedef struct plan_loop {
    const mk_raw_target **targets;
    target_plan *plans;
    const float (*steps)[2];           /* per target: its mesh's position and normal (and tangent) steps */
    mk_precision precision;
} plan_loop;

static void plan_item(void *user, uint32_t item, uint32_t worker)
{
    plan_loop *l = user;
    (void)worker;
    plan_target(l->targets[item], l->precision, l->steps[item], &l->plans[item]);
}

/* How a target's vertices of one block are stored (docs/format.md, "Blocks and entries"). */
typedef enum entry_kind { ENTRY_PACKED, ENTRY_FLOAT, ENTRY_WIDE } entry_kind;

/* One entry as the writer decides it: its mask, kind, and per component its width and offset
 * (the smallest value), with every value of the block (zeros where the mask covers a vertex the
 * target does not move) by mask bit. */
typedef struct entry_pack {
    entry_kind kind;
    uint64_t mask;
    uint32_t components;               /* the mesh's */
    uint32_t width[MK_MAX_COMPONENTS];
    int32_t offset[MK_MAX_COMPONENTS];
    uint64_t given;                    /* the rows of q written: the target's vertices in the block */
    int32_t q[MK_BLOCK_SIZE][MK_MAX_COMPONENTS];
} entry_pack;

/* Component k of the block's vertex i at the steps (0 for a vertex the target does not move). */
static int32_t entry_value(const entry_pack *e, unsigned i, uint32_t k)
{
    return (e->given >> i) & 1u ? e->q[i][k] : 0;
}

/* Bits of the unsigned range r (0 for 0). */
static uint32_t bits_of(uint64_t r)
{
    uint32_t w = 0;
    while (r) { w++; r >>= 1; }
    return w;
}

/* Decides the entry of a target's vertices [first, end) in the block starting at vertex
 * `start` (in_block vertices): packed, its vertices those with a nonzero value at the steps
 * (and the gaps mk_block_mask fills); WIDE when a position offset leaves int16; float32 when a
 * component spans more than 16 bits or leaves the WIDE range, or the target is float. Returns
 * 0 when no vertex keeps a nonzero value (the block gets no entry). */
static int pack_entry(const mk_raw_target *t, const target_plan *p, uint32_t mesh_flags, uint32_t first, uint32_t end,
                      uint32_t start, uint32_t in_block, uint32_t gap, entry_pack *e)
{
    const float *src[3] = { t->positions, t->normals, t->tangents };
    const float steps[3] = { p->position_scale, p->normal_scale, p->tangent_scale };
    e->components = mk_mesh_components(mesh_flags);
    uint64_t given = 0;
    for (uint32_t k = first; k < end; k++) given |= 1ull << (t->indices[k] - start);
    if (!(p->flags & MK_TARGET_QUANTIZED)) {
        e->kind = ENTRY_FLOAT;
        e->mask = mk_block_mask(given, in_block, gap);
        return 1;
    }
    /* Rows of q are written for the given vertices only (every component: zero where the target
     * lacks the attribute); the others read as zero below. */
    double inverse[3] = { 0, 0, 0 };
    uint32_t first_component[3] = { 0, 0, 0 };
    for (uint32_t a = 0; a < 3; a++)
        if (src[a]) {
            inverse[a] = 1.0 / (double)steps[a];
            first_component[a] = mk_attribute_component(mesh_flags, a);
        }
    int64_t largest = 0;
    uint64_t moved = 0;
    for (uint32_t k = first; k < end; k++) {
        const unsigned i = t->indices[k] - start;
        int nonzero = 0;
        memset(e->q[i], 0, sizeof e->q[i]);
        for (uint32_t a = 0; a < 3; a++) {
            if (!src[a]) continue;
            const uint32_t k0 = first_component[a];
            for (uint32_t c = 0; c < 3; c++) {
                const int64_t q = quantize(src[a][3u * (size_t)k + c], inverse[a]);
                const int64_t mag = q < 0 ? -q : q;
                largest = mag > largest ? mag : largest;
                e->q[i][k0 + c] = (int32_t)(q > MK_WIDE_OFFSET_MAX ? MK_WIDE_OFFSET_MAX : q < -MK_WIDE_OFFSET_MAX ? -MK_WIDE_OFFSET_MAX : q);
                nonzero |= q != 0;
            }
        }
        if (nonzero) moved |= 1ull << i;
    }
    if (!moved) return 0;
    e->kind = ENTRY_PACKED;
    if (largest > MK_WIDE_OFFSET_MAX) {
        e->kind = ENTRY_FLOAT;
        e->mask = mk_block_mask(given, in_block, gap);
        return 1;
    }
    e->mask = mk_block_mask(moved, in_block, gap);
    e->given = given;
    for (uint32_t k = 0; k < e->components; k++) {
        int32_t lo = INT32_MAX, hi = INT32_MIN;
        for (uint64_t bits = e->mask; bits; bits &= bits - 1) {
            const int32_t v = entry_value(e, mk_ctz64(bits), k);
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
        uint32_t w = bits_of((uint64_t)((int64_t)hi - lo));
        if (w == MK_WIDTH_CODE_16) w = 16;   /* code 15 means 16 bits: 15-bit ranges take 16 */
        if (w > MK_MAX_WIDTH || (k >= 3 && (lo < INT16_MIN || lo > INT16_MAX))) {
            e->kind = ENTRY_FLOAT;   /* the exact deltas of the given vertices */
            e->mask = mk_block_mask(given, in_block, gap);
            return 1;
        }
        if (k < 3 && (lo < INT16_MIN || lo > INT16_MAX)) e->kind = ENTRY_WIDE;
        e->width[k] = w;
        e->offset[k] = lo;
    }
    return 1;
}

static size_t pad4(size_t n) { return (n + 3u) & ~(size_t)3u; }

/* ORs u (below 2^w, w <= 16) into the zeroed bytes at bit `bit` of dst: only the bytes its bits
 * reach, so a neighbour's bytes (another thread's target) are never rewritten. */
static void put_bits(uint8_t *dst, uint64_t bit, uint32_t w, uint32_t u)
{
    uint8_t *p = dst + (bit >> 3);
    const uint32_t v = u << (bit & 7u), bytes = ((uint32_t)(bit & 7u) + w + 7u) >> 3;
    for (uint32_t b = 0; b < bytes; b++) p[b] |= (uint8_t)(v >> (8u * b));
}

/* Writes an entry's data at dst (zeroed): float32 triples of the vertices the mask covers (zeros
 * for those the target does not move), or the packed values. cursor is the target's first
 * index in the block, start the block's first vertex. The largest error per attribute of the
 * target's vertices in the block, dropped ones included, goes into error[]. */
static void put_entry(uint8_t *dst, const mk_raw_target *t, const target_plan *p, uint32_t mesh_flags,
                      const entry_pack *e, uint32_t cursor, uint32_t end, uint32_t start, double error[3])
{
    const float *src[3] = { t->positions, t->normals, t->tangents };
    const uint32_t m = mk_popcount64(e->mask);
    if (e->kind == ENTRY_FLOAT) {
        uint8_t *out[3] = { dst, dst + 12u * (size_t)m, dst + 12u * (size_t)m * (t->normals ? 2u : 1u) };
        uint32_t k = cursor;
        size_t j = 0;
        for (uint64_t bits = e->mask; bits; bits &= bits - 1, j++) {
            const uint32_t v = start + mk_ctz64(bits);
            while (k < end && t->indices[k] < v) k++;
            if (k == end || t->indices[k] != v) continue;
            for (int a = 0; a < 3; a++)
                if (src[a]) memcpy(out[a] + 12 * j, &src[a][3u * (size_t)k], 12);
        }
        return;
    }
    const float steps[3] = { p->position_scale, p->normal_scale, p->tangent_scale };
    for (uint32_t k = cursor; k < end; k++) {
        const unsigned i = t->indices[k] - start;
        for (uint32_t a = 0; a < 3; a++) {
            if (!src[a]) continue;
            const uint32_t k0 = mk_attribute_component(mesh_flags, a);
            for (uint32_t c = 0; c < 3; c++) {
                const double d = fabs((double)e->q[i][k0 + c] * steps[a] - (double)src[a][3u * (size_t)k + c]);
                error[a] = d > error[a] ? d : error[a];
            }
        }
    }
    if (e->kind == ENTRY_WIDE) {
        for (uint32_t c = 0; c < 3; c++) {
            const uint32_t u = (uint32_t)e->offset[c];
            const uint8_t le[4] = { (uint8_t)u, (uint8_t)(u >> 8), (uint8_t)(u >> 16), (uint8_t)(u >> 24) };
            memcpy(dst + 4u * c, le, 4);
        }
        dst += MK_ENTRY_WIDE_BYTES;
    }
    for (uint32_t k = 0; k < e->components; k++) {
        const uint32_t w = e->width[k];
        if (w) {
            uint64_t bit = 0;
            for (uint64_t bits = e->mask; bits; bits &= bits - 1, bit += w)
                put_bits(dst, bit, w, (uint32_t)(entry_value(e, mk_ctz64(bits), k) - e->offset[k]));
        }
        dst += mk_packed_bytes(m, w);
    }
}

/* The entry's head (mk_entry_stride bytes, zeroed): target and flags, data offset (4-byte
 * units), mask, width codes, int16 offsets (a WIDE entry's position offsets are in its data). */
static void put_head(uint8_t *head, const entry_pack *e, uint32_t target, uint64_t data)
{
    const uint32_t flags = e->kind == ENTRY_FLOAT ? (uint32_t)MK_ENTRY_FLOAT : e->kind == ENTRY_WIDE ? (uint32_t)MK_ENTRY_WIDE : 0u;
    mk_blob_entry be = { target | flags, (uint32_t)(data / MK_DATA_UNIT), e->mask };
    memcpy(head, &be, sizeof be);
    if (e->kind == ENTRY_FLOAT) return;
    uint8_t *codes = head + MK_ENTRY_HEAD;
    uint8_t *offsets = codes + mk_entry_code_bytes(e->components);
    for (uint32_t k = 0; k < e->components; k++) {
        codes[k >> 1] |= (uint8_t)(mk_code_of_width(e->width[k]) << (4u * (k & 1u)));
        const int32_t o = e->kind == ENTRY_WIDE && k < 3 ? 0 : e->offset[k];
        offsets[2u * k] = (uint8_t)((uint32_t)o & 0xFFu);
        offsets[2u * k + 1u] = (uint8_t)(((uint32_t)o >> 8) & 0xFFu);
    }
}

/* One target's share of a mesh's block data. */
typedef struct target_layout {
    const mk_raw_target *t;
    uint64_t entry_count, data_size;   /* counted first: blocks with an entry, bytes (entries 4-aligned) */
    uint64_t first_entry, base;        /* then placed: its first entry, its data's offset */
    uint64_t cursor;                   /* the entry merge's position */
    double error[3];                   /* written: largest quantization error per attribute */
    uint64_t float_entries, wide_entries;
    mk_raw_target *own;                /* consumed (mk_write_blob_consuming): emptied once written */
} target_layout;

typedef struct layout_loop {
    const mk_raw_mesh *m;
    const target_plan *plans;
    uint32_t gap;                      /* mk_block_mask's */
    uint32_t mesh_flags, stride;       /* the mesh's MK_MESH_* and entry size */
    target_layout *targets;
    uint32_t *entry_block;             /* per entry, target-major */
    uint8_t *entry_head;               /* per entry, target-major: its head, stride bytes */
    uint8_t *data;                     /* the mesh's target data, in the blob */
    mk_arena *owner;                   /* consuming: the raw arena the written targets go back to */
    mtx_t *owner_lock;
    const mk_write_options *options;   /* its ready callback hears of each target's finished data */
    const uint8_t *blob;               /* where data lies in it: its ready offsets count from here */
} layout_loop;

/* Calls fn(user, block, first, end, entry) for each block a target touches that gets an entry,
 * in block order: the target's vertices in it are indices [first, end); the entry is
 * pack_entry's. error (or NULL) receives, per attribute, the largest error of the target's
 * blocks that get no entry. */
typedef void (*block_fn)(void *user, uint32_t block, uint32_t first, uint32_t end, const entry_pack *e);

static void target_blocks(const layout_loop *l, const mk_raw_target *tg, const target_plan *plan, block_fn fn,
                          void *user, double error[3])
{
    const uint32_t vertex_count = l->m->vertex_count;
    const float *src[3] = { tg->positions, tg->normals, tg->tangents };
    entry_pack e;
    for (uint32_t first = 0; first < tg->count;) {
        uint32_t block = tg->indices[first] / MK_BLOCK_SIZE, start = block * MK_BLOCK_SIZE;
        uint32_t in_block = vertex_count - start < MK_BLOCK_SIZE ? vertex_count - start : MK_BLOCK_SIZE;
        uint32_t end = block_end(tg, first, start + in_block);
        if (pack_entry(tg, plan, l->mesh_flags, first, end, start, in_block, l->gap, &e)) fn(user, block, first, end, &e);
        else if (error) {
            /* No entry: every value rounded to 0 steps, so each one's error is its magnitude
             * (put_entry never sees this block, and the report must still cover it). */
            for (uint32_t a = 0; a < 3; a++)
                for (size_t i = 3u * (size_t)first; src[a] && i < 3u * (size_t)end; i++)
                    error[a] = fabs((double)src[a][i]) > error[a] ? fabs((double)src[a][i]) : error[a];
        }
        first = end;
    }
}

typedef struct layout_item {
    const layout_loop *l;
    target_layout *tl;
    uint32_t index;
} layout_item;

/* Bytes of an entry's data (before its padding to 4) as every reader sizes it: mk_entry_bytes
 * of its head (8-aligned, mk_entry_stride bytes) for target `index` of the mesh. */
static uint64_t entry_bytes(const uint8_t *head, const layout_loop *l, uint32_t index)
{
    return mk_entry_bytes((const mk_blob_entry *)(const void *)head, l->mesh_flags, l->plans[index].flags);
}

static void count_block(void *user, uint32_t block, uint32_t first, uint32_t end, const entry_pack *e)
{
    layout_item *it = user;
    (void)block;
    (void)first;
    (void)end;
    _Alignas(8) uint8_t head[MK_ENTRY_MAX_BYTES] = { 0 };
    put_head(head, e, 0, 0);
    it->tl->data_size = pad4((size_t)it->tl->data_size) + entry_bytes(head, it->l, it->index);
    it->tl->entry_count++;
}

static void layout_count(void *user, uint32_t item, uint32_t worker)
{
    layout_loop *l = user;
    (void)worker;
    layout_item it = { l, &l->targets[item], item };
    target_blocks(l, it.tl->t, &l->plans[item], count_block, &it, NULL);
}

static void write_block(void *user, uint32_t block, uint32_t first, uint32_t end, const entry_pack *e)
{
    layout_item *it = user;
    const layout_loop *l = it->l;
    target_layout *tl = it->tl;
    const target_plan *p = &l->plans[it->index];
    uint64_t n = tl->cursor++;
    uint64_t at = pad4((size_t)tl->data_size);
    uint8_t *head = l->entry_head + n * l->stride;
    put_head(head, e, it->index, tl->base + at);
    tl->data_size = at + entry_bytes(head, l, it->index);
    tl->float_entries += e->kind == ENTRY_FLOAT && (p->flags & MK_TARGET_QUANTIZED);
    tl->wide_entries += e->kind == ENTRY_WIDE;
    l->entry_block[n] = block;
    put_entry(l->data + tl->base + at, tl->t, p, l->mesh_flags, e, first, end, block * MK_BLOCK_SIZE, tl->error);
}

static void layout_write(void *user, uint32_t item, uint32_t worker)
{
    layout_loop *l = user;
    (void)worker;
    layout_item it = { l, &l->targets[item], item };
    it.tl->cursor = it.tl->first_entry;
    it.tl->data_size = 0;
    target_blocks(l, it.tl->t, &l->plans[item], write_block, &it, it.tl->error);
    if (l->options->ready && it.tl->data_size)
        l->options->ready(l->options->ready_user, l->blob, (uint64_t)(l->data - l->blob) + it.tl->base,
                          pad4((size_t)it.tl->data_size));
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
    const uint32_t mesh_flags = (m->normals ? MK_MESH_HAS_NORMALS : 0u) | (m->tangents ? MK_MESH_HAS_TANGENTS : 0u);
    *l = (layout_loop){ .m = m, .plans = plans, .gap = gap, .mesh_flags = mesh_flags, .stride = mk_entry_stride(mesh_flags),
                        .owner = consume ? &consume->arena : NULL };
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
        total += pad4(l->targets[t].data_size);
    }
    if (entry_count > UINT32_MAX)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: more than 2^32 block entries", mi);
    if (total / MK_DATA_UNIT > UINT32_MAX)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: target data exceeds 16 GiB", mi);
    total += MK_TARGET_DATA_TAIL;   /* zeros a decoder may load past an entry's last byte */
    out->target_count = target_count;
    out->blocks = (m->vertex_count + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    out->block_entries = place(cursor, 4u * ((uint64_t)out->blocks + 1));
    out->entries = place(cursor, entry_count * l->stride);
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
    /* Per target entry (target-major): its block and head. */
    uint32_t *block_first = (uint32_t *)(void *)(data + out->block_entries);
    l->entry_block = mk_arena_array(arena, entry_count + 1, sizeof *l->entry_block);
    l->entry_head = mk_arena_array(arena, entry_count + 1, l->stride);
    if (!l->entry_block || !l->entry_head) return mk_error_oom(err, "planning blocks");
    memset(l->entry_head, 0, (size_t)(entry_count + 1) * l->stride);
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
    uint8_t *entries = data + out->entries;
    uint64_t e = 0;
    for (uint32_t t = 0; t < target_count; t++) l->targets[t].cursor = l->targets[t].first_entry;
    for (uint32_t b = 0; b < blocks; b++) {
        block_first[b] = (uint32_t)e;
        for (uint32_t t = 0; t < target_count; t++) {
            target_layout *tl = &l->targets[t];
            if (tl->cursor == tl->first_entry + tl->entry_count || l->entry_block[tl->cursor] != b) continue;
            memcpy(entries + e++ * l->stride, l->entry_head + tl->cursor * l->stride, l->stride);
            tl->cursor++;
        }
    }
    block_first[blocks] = (uint32_t)e;
    report->target_bytes += entry_count * l->stride + out->target_data_size;
    report->entry_count += entry_count;
    for (uint32_t t = 0; t < target_count; t++) {
        const double *te = l->targets[t].error;
        if (te[0] > report->max_position_error) report->max_position_error = te[0];
        if (te[1] > report->max_normal_error) report->max_normal_error = te[1];
        if (te[2] > report->max_tangent_error) report->max_tangent_error = te[2];
        report->float_entries += l->targets[t].float_entries;
        report->wide_entries += l->targets[t].wide_entries;
    }
    void *scratch[] = { l->targets, l->entry_block, l->entry_head };
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
    if (!(opt.normal_tolerance >= 0) || !isfinite(opt.normal_tolerance))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "write: normal tolerance must be finite and >= 0");
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
    float (*steps)[2] = mk_arena_array(arena, target_count + 1, sizeof *steps);
    if (!steps) return mk_error_oom(err, "writing the blob tables");
    const float normal_step = step_for(opt.normal_tolerance > 0 ? opt.normal_tolerance : MK_DEFAULT_NORMAL_TOLERANCE);
    for (uint32_t mi = 0, c = 0, k = 0; mi < raw->mesh_count; mi++) {
        double tolerance = opt.tolerance > 0 ? opt.tolerance : 1e-4 * mk_raw_mesh_diagonal(&raw->meshes[mi]);
        if (tolerance > report.tolerance_used) report.tolerance_used = tolerance;
        const float position_step = step_for(tolerance);
        for (; c < raw->channel_count && raw->channels[c].mesh == mi; c++)
            for (uint32_t j = 0; j < raw->channels[c].target_count; j++, k++) {
                all_targets[k] = &raw->channels[c].targets[j];
                memset(&plans[k], 0, sizeof plans[k]);
                steps[k][0] = position_step;
                steps[k][1] = normal_step;
            }
    }
    plan_loop pl = { all_targets, plans, (const float (*)[2])steps, opt.precision };
    mk_parallel_for(target_count, opt.threads, plan_item, &pl);
    mk_arena_release(arena, all_targets);
    mk_arena_release(arena, steps);
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

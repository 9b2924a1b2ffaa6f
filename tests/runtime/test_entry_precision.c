/* SPDX-License-Identifier: MIT */
/* The writer's per-entry choices (format v5: packed at one step per attribute and mesh, WIDE,
 * float32) on adversarial deltas, and what the runtime and the reader make of them.
 *
 * Every case goes through the writer, mk_asset_open, evaluation (mk_eval_run) and the reader
 * (mk_read_blob) and is compared with the exact float deltas:
 *   - check_entries recomputes, from the source deltas alone, what each entry must be (its
 *     kind, mask, and per component width and offset) and reads the blob's entries with the
 *     format.h helpers; it counts float and WIDE entries for the report and mk_mesh_*_entries;
 *   - check_read_back: each read-back value within step x (0.5 + 2^-8) of the exact delta (plus
 *     the one rounding of the decode), float32 entries bit-exact, nothing NaN;
 *   - check_eval: every output within sum |coef| x step x (0.5 + 2^-8) of the exact morph, plus
 *     float rounding (eval_rounding says why it is that much);
 * and each case states its own expected counts, widths and offsets as well.
 * And the mask rule (mk_block_mask): which vertices an entry stores. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "block_mask.h"
#include "check.h"
#include "fixtures.h"
#include "format.h"

#define QUANT_BOUND (0.5 + 0x1p-8)   /* the error bound of a packed value, in steps */
#define WIDE_MAX ((int64_t)MK_WIDE_OFFSET_MAX)
/* A tolerance whose step is exactly 2^-10 (2^-10 x (0.5 + 2^-8) = 129 x 2^-18, a float): every
 * multiple of it below 2^24 steps is a float, so the cases at the int16 and 2^23 edges put
 * values exactly where they mean to. Normals: 2^-12. */
#define POW2_TOLERANCE (129 * 0x1p-18f)
#define POW2_NORMAL_TOLERANCE (129 * 0x1p-20f)

/* ---- a mesh and its targets ---- */

/* Mesh 0: n vertices at (0.01 v, 0.002 (v % 5), 0), normals +z and tangents +x (w alternating)
 * when asked. */
static mk_raw_mesh *make_mesh(mk_raw_asset *raw, uint32_t n, int normals, int tangents)
{
    mk_raw_init(raw, NULL);
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    m->name = mk_arena_strdup(&raw->arena, "m");
    m->vertex_count = n;
    m->control_point_count = n;
    m->gltf_node = m->gltf_mesh = m->gltf_primitive = -1;
    m->positions = mk_arena_array(&raw->arena, 3u * n, sizeof(float));
    for (uint32_t v = 0; v < n; v++) {
        m->positions[3 * v] = 0.01f * (float)v;
        m->positions[3 * v + 1] = 0.002f * (float)(v % 5);
    }
    if (normals) {
        m->normals = mk_arena_array(&raw->arena, 3u * n, sizeof(float));
        for (uint32_t v = 0; v < n; v++) m->normals[3 * v + 2] = 1;
    }
    if (tangents) {
        m->tangents = mk_arena_array(&raw->arena, 4u * n, sizeof(float));
        for (uint32_t v = 0; v < n; v++) { m->tangents[4 * v] = 1; m->tangents[4 * v + 3] = v % 2 ? 1.0f : -1.0f; }
    }
    return m;
}

/* A single-target channel (full weight 1) moving every vertex of the mesh, all deltas 0, with
 * normal and tangent deltas where asked (the mesh must have those attributes). */
static mk_raw_target *add_target(mk_raw_asset *raw, int normals, int tangents)
{
    const uint32_t n = raw->meshes[0].vertex_count;
    mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
    ch->name = mk_arena_strdup(&raw->arena, "c");
    ch->mesh = 0;
    mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
    t->name = ch->name;
    t->full_weight = 1;
    t->count = n;
    t->indices = mk_arena_array(&raw->arena, n + 1, sizeof(uint32_t));
    for (uint32_t v = 0; v < n; v++) t->indices[v] = v;
    t->positions = mk_arena_array(&raw->arena, 3u * n + 3, sizeof(float));
    if (normals) t->normals = mk_arena_array(&raw->arena, 3u * n + 3, sizeof(float));
    if (tangents) t->tangents = mk_arena_array(&raw->arena, 3u * n + 3, sizeof(float));
    return t;
}

/* Removes the vertices `drop` says of a dense target (the target then does not give them). */
static void drop_vertices(mk_raw_target *t, int (*drop)(uint32_t v))
{
    uint32_t kept = 0;
    for (uint32_t j = 0; j < t->count; j++) {
        if (drop(t->indices[j])) continue;
        t->indices[kept] = t->indices[j];
        memmove(&t->positions[3 * kept], &t->positions[3 * j], 12);
        if (t->normals) memmove(&t->normals[3 * kept], &t->normals[3 * j], 12);
        if (t->tangents) memmove(&t->tangents[3 * kept], &t->tangents[3 * j], 12);
        kept++;
    }
    t->count = kept;
}

/* A small deterministic spread: -50..50 steps, never a tie at half a step (the fractions are
 * k / 7 away from 0.5). */
static float small(uint32_t v, uint32_t k, float step)
{
    return step * ((float)((v * 37 + k * 11) % 101) - 50.0f + (float)((v + k) % 7) / 7.0f);
}

/* ---- the exact model ---- */

/* The largest float s with s x (0.5 + 2^-8) <= tolerance, by its definition. */
static float step_of(double tolerance)
{
    float s = (float)(tolerance / QUANT_BOUND);
    while ((double)s * QUANT_BOUND > tolerance) s = nextafterf(s, 0.0f);
    while ((double)nextafterf(s, INFINITY) * QUANT_BOUND <= tolerance) s = nextafterf(s, INFINITY);
    return s;
}

/* The exact delta of attribute a (0 positions, 1 normals, 2 tangents) of vertex v, component c:
 * 0 where the target does not give the vertex or lacks the attribute. */
static float exact(const mk_raw_target *t, uint32_t a, uint32_t v, uint32_t c)
{
    const float *src = a == 0 ? t->positions : a == 1 ? t->normals : t->tangents;
    if (!src) return 0;
    for (uint32_t j = 0; j < t->count; j++)
        if (t->indices[j] == v) return src[3 * j + c];
    return 0;
}

/* The nearest integer to value / step, halves away from zero (the data never holds a tie). */
static int64_t steps_of(float value, float step)
{
    const double x = (double)value / (double)step;
    return (int64_t)(x < 0 ? x - 0.5 : x + 0.5);
}

static uint32_t bits_of(int64_t r)
{
    uint32_t w = 0;
    for (; r; r >>= 1) w++;
    return w;
}

typedef struct steps3 { float s[3]; } steps3;

static steps3 target_steps(const mk_asset *a, uint32_t t)
{
    const mk_blob_target *bt = &a->targets[t];
    return (steps3){ { bt->position_scale, bt->normal_scale, bt->tangent_scale } };
}

/* What a case expects and what it saw. */
typedef struct counts {
    uint64_t float_entries, wide_entries, entries;
} counts;

/* The entry of target t in block b (NULL: none; a second one fails). */
static const mk_blob_entry *entry_of(const mk_asset *a, uint32_t t, uint32_t b)
{
    const mk_blob_mesh *bm = &a->meshes[0];
    const uint32_t *first = (const uint32_t *)(a->data + bm->block_entries);
    const uint32_t stride = mk_entry_stride(bm->flags);
    const mk_blob_entry *found = NULL;
    for (uint32_t e = first[b]; e < first[b + 1]; e++) {
        const mk_blob_entry *en = mk_entry_at(a->data + bm->entries, stride, e);
        if (mk_entry_target(en) != t) continue;
        CHECK_MSG(!found, "target %u has two entries in block %u", t, b);
        found = en;
    }
    return found;
}

/* The offset of component k of a packed entry: the head's int16, or a WIDE entry's int32 for
 * positions (its head's are then zero). */
static int64_t offset_of(const mk_asset *a, const mk_blob_entry *en, uint32_t k)
{
    const mk_blob_mesh *bm = &a->meshes[0];
    const uint32_t components = mk_mesh_components(bm->flags);
    if (!mk_entry_wide(en) || k >= 3) return mk_entry_offset(en, components, k);
    CHECK_MSG(mk_entry_offset(en, components, k) == 0, "WIDE entry: head offset %u is %d, not 0", k,
              mk_entry_offset(en, components, k));
    return (int32_t)mk_load_u32le(a->data + bm->target_data + (size_t)en->data * MK_DATA_UNIT + 4u * k);
}

/* Every entry of the blob (written with exact masks: gap_limit 1) against what the source
 * deltas call for. Returns the counts seen and adds each entry's bytes to *position_bytes
 * (positions only) and *all_bytes (every attribute of its target), for mk_eval_traffic. */
static counts check_entries(const mk_raw_asset *raw, const mk_asset *a, uint64_t *position_bytes, uint64_t *all_bytes)
{
    const mk_blob_mesh *bm = &a->meshes[0];
    const uint32_t n = bm->vertex_count, components = mk_mesh_components(bm->flags);
    counts seen = { 0, 0, 0 };
    CHECK_EQ_INT(mk_entry_stride(bm->flags), MK_ENTRY_HEAD + mk_entry_code_bytes(components) + 2 * components);
    for (uint32_t t = 0; t < raw->channel_count; t++) {
        const mk_raw_target *tg = &raw->channels[t].targets[0];
        const steps3 st = target_steps(a, t);
        CHECK(a->targets[t].flags & MK_TARGET_QUANTIZED);
        for (uint32_t b = 0; b * MK_BLOCK_SIZE < n; b++) {
            int64_t q[MK_BLOCK_SIZE][MK_MAX_COMPONENTS];
            uint64_t given = 0, moved = 0;
            int64_t largest = 0;
            memset(q, 0, sizeof q);
            for (uint32_t j = 0; j < tg->count; j++) {
                const uint32_t v = tg->indices[j];
                if (v / MK_BLOCK_SIZE != b) continue;
                const uint32_t i = v % MK_BLOCK_SIZE;
                given |= 1ull << i;
                for (uint32_t at = 0; at < 3; at++) {
                    if ((at == 1 && !bm->normals) || (at == 2 && !bm->tangents)) continue;
                    const uint32_t k0 = mk_attribute_component(bm->flags, at);
                    for (uint32_t c = 0; c < 3; c++) {
                        const float x = exact(tg, at, v, c);
                        q[i][k0 + c] = x == 0 ? 0 : steps_of(x, st.s[at]);
                        const int64_t mag = q[i][k0 + c] < 0 ? -q[i][k0 + c] : q[i][k0 + c];
                        largest = mag > largest ? mag : largest;
                        if (q[i][k0 + c]) moved |= 1ull << i;
                    }
                }
            }
            const mk_blob_entry *en = entry_of(a, t, b);
            if (!moved) {
                CHECK_MSG(!en, "target %u block %u: every value rounds to 0 steps, yet it has an entry", t, b);
                continue;
            }
            if (!en) {
                CHECK_MSG(0, "target %u block %u: no entry", t, b);
                continue;
            }
            seen.entries++;
            int is_float = largest > WIDE_MAX, is_wide = 0;
            int64_t lo[MK_MAX_COMPONENTS], hi[MK_MAX_COMPONENTS];
            for (uint32_t k = 0; k < components; k++) {
                lo[k] = INT64_MAX;
                hi[k] = INT64_MIN;
                for (uint64_t bits = moved; bits; bits &= bits - 1) {
                    const int64_t x = q[mk_ctz64(bits)][k];
                    lo[k] = x < lo[k] ? x : lo[k];
                    hi[k] = x > hi[k] ? x : hi[k];
                }
                if (hi[k] - lo[k] > 0xFFFF) is_float = 1;
                if (lo[k] < INT16_MIN || lo[k] > INT16_MAX) {
                    if (k < 3) is_wide = 1;
                    else is_float = 1;   /* normals and tangents have no int32 offsets */
                }
            }
            if (is_float) is_wide = 0;
            CHECK_MSG(mk_entry_packed(en) == !is_float && mk_entry_wide(en) == is_wide,
                      "target %u block %u: flags %#x, expected %s", t, b, (unsigned)en->target_and_flags,
                      is_float ? "FLOAT" : is_wide ? "WIDE" : "packed");
            const uint32_t m = mk_popcount64(en->mask);
            if (is_float) {
                seen.float_entries++;
                CHECK_MSG(en->mask == given, "target %u block %u: float entry mask %016llx, given %016llx", t, b,
                          (unsigned long long)en->mask, (unsigned long long)given);
                for (uint32_t k = 0; k < components; k++)
                    CHECK(mk_entry_code(en, k) == 0 && mk_entry_offset(en, components, k) == 0);
                *position_bytes += 12u * (uint64_t)m;
                *all_bytes += 12u * (uint64_t)m * (1u + (tg->normals ? 1u : 0u) + (tg->tangents ? 1u : 0u));
                continue;
            }
            seen.wide_entries += (uint64_t)is_wide;
            /* The mask is the vertices with a nonzero value at the steps: no all-zero vertex. */
            CHECK_MSG(en->mask == moved, "target %u block %u: mask %016llx, moved %016llx", t, b,
                      (unsigned long long)en->mask, (unsigned long long)moved);
            *position_bytes += is_wide ? MK_ENTRY_WIDE_BYTES : 0u;
            *all_bytes += is_wide ? MK_ENTRY_WIDE_BYTES : 0u;
            for (uint32_t k = 0; k < components; k++) {
                const uint32_t w = bits_of(hi[k] - lo[k]);
                CHECK_MSG(mk_width_of_code(mk_entry_code(en, k)) == w && offset_of(a, en, k) == lo[k],
                          "target %u block %u component %u: width %u offset %lld, expected %u and %lld", t, b, k,
                          mk_width_of_code(mk_entry_code(en, k)), (long long)offset_of(a, en, k), w, (long long)lo[k]);
                if (k < 3) *position_bytes += mk_packed_bytes(m, w);
                *all_bytes += mk_packed_bytes(m, w);   /* 0 for an attribute the target lacks: width 0 */
            }
        }
    }
    return seen;
}

/* Write (gap_limit 1: exact masks), open, and check the entries and the counts: the report's,
 * mk_mesh_float_entries / mk_mesh_wide_entries and the case's own. */
static void write_checked(const mk_raw_asset *raw, mk_write_options o, mk_arena *arena, mk_asset *a,
                          mk_write_report *rep, uint64_t expect_float, uint64_t expect_wide)
{
    void *blob;
    size_t size;
    mk_error err;
    o.gap_limit = 1;
    if (!o.precision) o.precision = MK_PRECISION_Q16;
    CHECK_MSG(mk_write_blob(raw, &o, arena, &blob, &size, rep, &err) == MK_OK, "write: %s", err.message);
    CHECK_MSG(mk_asset_open(blob, size, a, &err) == MK_OK, "open: %s", err.message);
    uint64_t position_bytes = 0, all_bytes = 0;
    const counts seen = check_entries(raw, a, &position_bytes, &all_bytes);
    CHECK_EQ_INT(seen.float_entries, expect_float);
    CHECK_EQ_INT(seen.wide_entries, expect_wide);
    CHECK_EQ_INT(rep->float_entries, expect_float);
    CHECK_EQ_INT(rep->wide_entries, expect_wide);
    CHECK_EQ_INT(mk_mesh_float_entries(a, 0), expect_float);
    CHECK_EQ_INT(mk_mesh_wide_entries(a, 0), expect_wide);
    CHECK_EQ_INT(a->meshes[0].entry_count, seen.entries);
    CHECK_EQ_INT(rep->quantized_targets, raw->channel_count);
    /* Steps: the largest float within the tolerance, per attribute. */
    const double tolerance = o.tolerance > 0 ? o.tolerance : 1e-4 * mk_raw_mesh_diagonal(&raw->meshes[0]);
    const double normal_tolerance = o.normal_tolerance > 0 ? o.normal_tolerance : MK_DEFAULT_NORMAL_TOLERANCE;
    for (uint32_t t = 0; t < raw->channel_count; t++) {
        const mk_raw_target *tg = &raw->channels[t].targets[0];
        const steps3 st = target_steps(a, t);
        CHECK_MSG(st.s[0] == step_of(tolerance), "position step %.9g, expected %.9g", (double)st.s[0],
                  (double)step_of(tolerance));
        CHECK(st.s[1] == (tg->normals ? step_of(normal_tolerance) : 0.0f));
        CHECK(st.s[2] == (tg->tangents ? step_of(normal_tolerance) : 0.0f));
    }
    /* mk_eval_traffic of a positions-only job with every target active: the block table, every
     * header, each entry's position bytes (from the widths above), the base read and the
     * output written. */
    const uint32_t n = raw->meshes[0].vertex_count, blocks = (n + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    float *w = malloc(4u * raw->channel_count), *p = malloc(12u * n);
    for (uint32_t t = 0; t < raw->channel_count; t++) w[t] = 1;
    size_t scratch_size = mk_eval_scratch_size(a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    mk_eval_job job = { .asset = a, .vertex_count = MK_VERTICES_TO_END, .weights = w, .weight_count = raw->channel_count,
                        .scratch = scratch, .scratch_size = scratch_size, .positions = p, .positions_size = 12u * n };
    CHECK_EQ_INT(mk_eval_traffic(&job), 4u * (uint64_t)(blocks + 1) + mk_entry_stride(a->meshes[0].flags) * seen.entries
                                            + position_bytes + 24u * (uint64_t)n);
    /* And with every attribute the mesh has: each entry's whole data, the base and output
     * normals (12 + 12 bytes a vertex) and tangents (16 + 16). */
    const mk_raw_mesh *rm = &raw->meshes[0];
    float *nr = malloc(12u * n), *tn = malloc(16u * n);
    if (rm->normals) { job.normals = nr; job.normals_size = 12u * n; }
    if (rm->tangents) { job.tangents = tn; job.tangents_size = 16u * n; }
    CHECK_EQ_INT(mk_eval_traffic(&job), 4u * (uint64_t)(blocks + 1) + mk_entry_stride(a->meshes[0].flags) * seen.entries
                                            + all_bytes + 24u * (uint64_t)n * (rm->normals ? 2u : 1u)
                                            + (rm->tangents ? 32u * (uint64_t)n : 0u));
    free(scratch);
    free(w);
    free(p);
    free(nr);
    free(tn);
}

/* ---- read-back ---- */

/* Whether vertex v of target t is in a float entry. */
static int in_float_entry(const mk_asset *a, uint32_t t, uint32_t v)
{
    const mk_blob_entry *en = entry_of(a, t, v / MK_BLOCK_SIZE);
    return en && !mk_entry_packed(en) && (en->mask >> (v % MK_BLOCK_SIZE) & 1);
}

/* mk_read_blob: each value within step x (0.5 + 2^-8) of the exact delta plus 2^-24 of itself
 * (the decode's one rounding of (offset + u) x step), float entries bit-exact, none NaN; and
 * the largest error per attribute (vertices dropped from the mask and blocks left without an
 * entry included) within what the report says, but for that rounding (rep may be NULL). */
static void check_read_back(const mk_raw_asset *raw, const mk_asset *a, const mk_write_report *rep)
{
    mk_raw_asset back;
    mk_raw_init(&back, NULL);
    mk_error err;
    CHECK_MSG(mk_read_blob(a, &back, &err) == MK_OK, "read: %s", err.message);
    const uint32_t n = raw->meshes[0].vertex_count;
    for (uint32_t t = 0; t < raw->channel_count && t < back.channel_count; t++) {
        const mk_raw_target *src = &raw->channels[t].targets[0], *u = &back.channels[t].targets[0];
        const steps3 st = target_steps(a, t);
        CHECK((src->normals != NULL) == (u->normals != NULL) && (src->tangents != NULL) == (u->tangents != NULL));
        double worst[3] = { 0, 0, 0 }, rounding = 0;
        for (uint32_t v = 0; v < n; v++) {
            const int fl = in_float_entry(a, t, v);
            for (uint32_t at = 0; at < 3; at++) {
                if ((at == 1 && !src->normals) || (at == 2 && !src->tangents)) continue;
                for (uint32_t c = 0; c < 3; c++) {
                    const float want = exact(src, at, v, c), got = exact(u, at, v, c);
                    CHECK_MSG(isfinite(got), "target %u vertex %u attribute %u: read %g", t, v, at, (double)got);
                    if (fl) {
                        CHECK_MSG(memcmp(&want, &got, 4) == 0, "target %u vertex %u attribute %u.%u: float entry read %.9g, stored %.9g",
                                  t, v, at, c, (double)got, (double)want);
                        continue;
                    }
                    const double d = fabs((double)got - want), bound = st.s[at] * QUANT_BOUND + 0x1p-24 * fabs(got);
                    worst[at] = fmax(worst[at], d);
                    rounding = fmax(rounding, 0x1p-24 * fabs(got));
                    CHECK_MSG(d <= bound, "target %u vertex %u attribute %u.%u: read %.9g, exact %.9g (error %g, bound %g)", t,
                              v, at, c, (double)got, (double)want, d, bound);
                }
            }
        }
        if (rep) {
            const double reported[3] = { rep->max_position_error, rep->max_normal_error, rep->max_tangent_error };
            for (uint32_t at = 0; at < 3; at++)
                CHECK_MSG(worst[at] <= reported[at] + rounding, "target %u attribute %u: read back with error %g, reported %g",
                          t, at, worst[at], reported[at]);
        }
    }
    mk_raw_free(&back);
}

/* ---- evaluation ---- */

/* The float rounding of one evaluated component beyond the quantization: the runtime forms
 * coef x step (one rounding, 2^-24 relative), times the exact integer offset + u (another), or
 * coef x delta for a float entry (one), and adds each of the `terms` products to the running
 * sum (one rounding each, 2^-24 of a partial sum, which never exceeds `magnitude` = |base| +
 * sum |coef| (|delta| + step)). So 2^-23 of the products plus terms x 2^-24 of the magnitude;
 * this bounds it by (terms + 2) x 2^-23 x magnitude. */
static double eval_rounding(uint32_t terms, double magnitude) { return (terms + 2) * 0x1p-23 * magnitude; }

static void eval_all(const mk_asset *a, const float *w, uint32_t weight_count, uint32_t first, uint32_t count, float *p,
                     float *nr, float *tn)
{
    size_t scratch_size = mk_eval_scratch_size(a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    const mk_blob_mesh *bm = &a->meshes[0];
    mk_eval_job job = { .asset = a, .first_vertex = first, .vertex_count = count, .weights = w,
                        .weight_count = weight_count, .scratch = scratch, .scratch_size = scratch_size,
                        .positions = p + 3 * first, .positions_size = 12u * count };
    if (bm->flags & MK_MESH_HAS_NORMALS) { job.normals = nr + 3 * first; job.normals_size = 12u * count; }
    if (bm->flags & MK_MESH_HAS_TANGENTS) { job.tangents = tn + 4 * first; job.tangents_size = 16u * count; }
    mk_error err;
    CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "eval: %s", err.message);
    free(scratch);
}

/* Normalized outputs: the exact sum b = base + sum coef delta and the runtime's a differ by
 * |a - b| <= sqrt(3) E (E per component), and |a/|a| - b/|b|| <= 2 |a - b| / |b|; plus 1e-6 for
 * the normalization's own float rounding (a few ulps of a unit vector). */
static void check_unit(const char *what, uint32_t v, const float *got, const double *sum, double e)
{
    const double len = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    CHECK_MSG(len > 0.05, "%s vertex %u: the case's exact sum has length %g (pick other deltas)", what, v, len);
    const double bound = 2 * sqrt(3.0) * e / len + 1e-6;
    for (int c = 0; c < 3; c++)
        CHECK_MSG(fabs(got[c] - sum[c] / len) <= bound, "%s vertex %u.%d: %.9g, exact %.9g (bound %g)", what, v, c,
                  (double)got[c], sum[c] / len, bound);
}

/* Evaluation at several weight sets (nlerp, additive: each target's coefficient is its
 * channel's weight) against the exact morph, and range jobs against the whole-mesh job. */
static void check_eval(const mk_raw_asset *raw, const mk_asset *a)
{
    static const float patterns[][4] = { { 1, 1, 1, 1 }, { -0.75f, 1.5f, 0.25f, -1 }, { 2.5f, 0, -1.25f, 0.5f } };
    const mk_raw_mesh *m = &raw->meshes[0];
    const uint32_t n = m->vertex_count, T = raw->channel_count;
    float *w = malloc(4u * T), *p = malloc(12u * n), *nr = malloc(12u * n), *tn = malloc(16u * n);
    float *p2 = malloc(12u * n), *nr2 = malloc(12u * n), *tn2 = malloc(16u * n);
    for (size_t s = 0; s < sizeof patterns / sizeof patterns[0]; s++) {
        for (uint32_t t = 0; t < T; t++) w[t] = patterns[s][t % 4];
        eval_all(a, w, T, 0, n, p, nr, tn);
        for (uint32_t v = 0; v < n; v++)
            for (uint32_t at = 0; at < 3; at++) {
                if ((at == 1 && !m->normals) || (at == 2 && !m->tangents)) continue;
                const float *base = at == 0 ? m->positions + 3 * v : at == 1 ? m->normals + 3 * v : m->tangents + 4 * v;
                const float *got = at == 0 ? p + 3 * v : at == 1 ? nr + 3 * v : tn + 4 * v;
                double sum[3], e = 0;
                for (uint32_t c = 0; c < 3; c++) {
                    double magnitude = fabs(base[c]), quant = 0;
                    sum[c] = base[c];
                    for (uint32_t t = 0; t < T; t++) {
                        const float d = exact(&raw->channels[t].targets[0], at, v, c), step = target_steps(a, t).s[at];
                        sum[c] += (double)w[t] * d;
                        magnitude += fabs(w[t]) * (fabs(d) + step);
                        quant += fabs(w[t]) * step * QUANT_BOUND;
                    }
                    const double bound = quant + eval_rounding(T, magnitude);
                    CHECK_MSG(isfinite(got[c]), "weights %zu vertex %u attribute %u: %g", s, v, at, (double)got[c]);
                    if (at == 0)
                        CHECK_MSG(fabs(got[c] - sum[c]) <= bound, "weights %zu vertex %u position %u: %.9g, exact %.9g (error %g, bound %g)",
                                  s, v, c, (double)got[c], sum[c], fabs(got[c] - sum[c]), bound);
                    e = fmax(e, bound);
                }
                if (at == 1) check_unit("normal", v, got, sum, e);
                if (at == 2) {
                    check_unit("tangent", v, got, sum, e);
                    CHECK(got[3] == base[3]);
                }
            }
        /* Range jobs cutting blocks give the whole-mesh job's bytes. */
        const uint32_t cuts[] = { 0, n / 3, n / 3 + 1, 2 * n / 3 + 5 < n ? 2 * n / 3 + 5 : n, n };
        for (size_t r = 0; r + 1 < sizeof cuts / sizeof cuts[0]; r++)
            if (cuts[r + 1] > cuts[r]) eval_all(a, w, T, cuts[r], cuts[r + 1] - cuts[r], p2, nr2, tn2);
        CHECK_MSG(memcmp(p, p2, 12u * n) == 0 && (!m->normals || memcmp(nr, nr2, 12u * n) == 0)
                  && (!m->tangents || memcmp(tn, tn2, 16u * n) == 0), "weights %zu: range jobs differ from the whole-mesh job", s);
    }
    free(w); free(p); free(nr); free(tn); free(p2); free(nr2); free(tn2);
}

/* The whole round: write, entries and counts, read-back, evaluation. */
static void round_trip(const mk_raw_asset *raw, mk_write_options o, mk_asset *a, mk_arena *arena, uint64_t expect_float,
                       uint64_t expect_wide)
{
    mk_write_report rep;
    write_checked(raw, o, arena, a, &rep, expect_float, expect_wide);
    check_read_back(raw, a, &rep);
    check_eval(raw, a);
}

/* ---- the cases ---- */

/* A huge range in one block: vertex 70 (block 1) of target 1 moved 2 x 10^5 steps along y,
 * next to values of +-50 steps: 18 bits, so that entry is float32 (normal deltas too, exact),
 * the target's other blocks and target 0 packed. */
static void test_huge_range_is_float(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 192, 1, 0);
    const float step = step_of(1e-3), nstep = step_of(MK_DEFAULT_NORMAL_TOLERANCE);
    for (uint32_t t = 0; t < 2; t++) {
        mk_raw_target *tg = add_target(&raw, 1, 0);
        for (uint32_t v = 0; v < 192; v++)
            for (uint32_t c = 0; c < 3; c++) {
                tg->positions[3 * v + c] = small(v + t, c, step);
                tg->normals[3 * v + c] = small(v, c + 3 * t, nstep) * 0.5f;
            }
    }
    raw.channels[1].targets[0].positions[3 * 70 + 1] = 200000.3f * step;
    raw.channels[1].targets[0].normals[3 * 70 + 2] = 0.125f;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 1, 0);
    const mk_blob_entry *en = entry_of(&a, 1, 1);
    CHECK(en && !mk_entry_packed(en) && en->mask == ~0ull);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* One outlier vertex in a block of small values: 40000 steps (block 0) fits 16 bits, the
 * widest packing (code 15); 70000 (block 1) does not: float32; -60000 next to +5000 (block 2)
 * spans 16 bits from an offset beyond int16: WIDE at width 16. */
static void test_outlier_vertex(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 192, 0, 0);
    const float step = step_of(1e-3);
    mk_raw_target *tg = add_target(&raw, 0, 0);
    for (uint32_t v = 0; v < 192; v++)
        for (uint32_t c = 0; c < 3; c++) tg->positions[3 * v + c] = small(v, c, step) + (v >= 128 && c == 1 ? 5000 * step : 0);
    tg->positions[3 * 9 + 1] = 40000.2f * step;
    tg->positions[3 * 100 + 1] = 70000.2f * step;
    tg->positions[3 * 150 + 1] = -60000.2f * step;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 1, 1);
    const mk_blob_entry *e0 = entry_of(&a, 0, 0), *e2 = entry_of(&a, 0, 2);
    CHECK(e0 && mk_entry_code(e0, 1) == MK_WIDTH_CODE_16 && mk_entry_packed(e0) && !mk_entry_wide(e0));
    CHECK(e2 && mk_entry_code(e2, 1) == MK_WIDTH_CODE_16 && mk_entry_wide(e2) && offset_of(&a, e2, 1) == -60000);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

static int every_third_of_block_0(uint32_t v) { return v < 64 && v % 3 == 0; }

/* Large deltas with a narrow spread: 10^5 steps along x (block 0, every third vertex not given,
 * which the mask must leave out), -10^5 (block 1): WIDE, int32 offsets in the data; 3 x 10^4
 * (block 2) fits int16: packed. */
static void test_wide(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 192, 1, 0);
    const float step = step_of(1e-3);
    mk_raw_target *tg = add_target(&raw, 1, 0);
    for (uint32_t v = 0; v < 192; v++) {
        const float base = v < 64 ? 100000 : v < 128 ? -100000 : 30000;
        tg->positions[3 * v] = step * (base + (float)(v % 7) + 0.25f);
        tg->positions[3 * v + 2] = small(v, 2, step);
        tg->normals[3 * v] = small(v, 0, step_of(MK_DEFAULT_NORMAL_TOLERANCE));
    }
    drop_vertices(tg, every_third_of_block_0);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 0, 2);
    const mk_blob_entry *e0 = entry_of(&a, 0, 0), *e1 = entry_of(&a, 0, 1), *e2 = entry_of(&a, 0, 2);
    CHECK(e0 && mk_entry_wide(e0) && offset_of(&a, e0, 0) == 100000 && mk_entry_code(e0, 0) == 3);
    CHECK(e1 && mk_entry_wide(e1) && offset_of(&a, e1, 0) == -100000 && mk_entry_code(e1, 0) == 3);
    CHECK(e2 && !mk_entry_wide(e2) && mk_entry_packed(e2) && offset_of(&a, e2, 0) == 30000);
    uint64_t given = 0;
    for (uint32_t i = 0; i < 64; i++) given |= (uint64_t)(i % 3 != 0) << i;
    CHECK(e0 && e0->mask == given);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* At a step of exactly 2^-10: 2^23 - 1 steps is the largest WIDE offset (blocks 0 and 2, +-),
 * 2^23 steps and beyond are float32 (blocks 1 and 3); a range of exactly 2^16 - 1 steps packs
 * at width 16 (block 4), 2^16 does not (block 5). */
static void test_2p23_and_2p16_edges(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 6 * 64, 0, 0);
    const float step = 0x1p-10f;
    mk_raw_target *tg = add_target(&raw, 0, 0);
    static const float edge[4] = { 0x7FFFFF, 0x800000, -0x7FFFFF, -0x800001 };
    for (uint32_t v = 0; v < 6 * 64; v++) {
        const uint32_t b = v / 64;
        tg->positions[3 * v + 2] = step * (float)(v % 3 + 1);
        if (b < 4) tg->positions[3 * v] = step * edge[b];
        else tg->positions[3 * v + 1] = v % 64 == 7 ? step * (b == 4 ? 65535.0f : 65536.0f) : 0.0f;
    }
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = POW2_TOLERANCE }, &a, &arena, 3, 2);
    CHECK(a.targets[0].position_scale == step);
    const mk_blob_entry *e0 = entry_of(&a, 0, 0), *e2 = entry_of(&a, 0, 2), *e4 = entry_of(&a, 0, 4);
    CHECK(e0 && mk_entry_wide(e0) && offset_of(&a, e0, 0) == MK_WIDE_OFFSET_MAX && mk_entry_code(e0, 0) == 0);
    CHECK(e2 && mk_entry_wide(e2) && offset_of(&a, e2, 0) == -MK_WIDE_OFFSET_MAX);
    CHECK(e4 && mk_entry_packed(e4) && mk_entry_code(e4, 1) == MK_WIDTH_CODE_16);
    for (uint32_t b = 1; b < 6; b += 2) CHECK(entry_of(&a, 0, b) && !mk_entry_packed(entry_of(&a, 0, b)));
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Denormals and tiny values round to 0 steps: block 0 holds nothing else (no entry), block 1
 * mixes them with values of a few steps (those vertices leave the mask), block 2 with a huge one
 * (float32: the denormals stored bit-exact). Nothing reads back or evaluates as NaN. */
static void test_tiny_values(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 192, 1, 1);
    const float step = step_of(1e-3);
    static const float tiny[] = { 1e-40f, -1e-45f, FLT_MIN, -FLT_MIN, 1e-30f, 0.0f, -0.0f };
    mk_raw_target *tg = add_target(&raw, 1, 1);
    for (uint32_t v = 0; v < 192; v++)
        for (uint32_t c = 0; c < 3; c++) {
            const float t = tiny[(v + c) % 7];
            tg->positions[3 * v + c] = v % 4 == 3 && v >= 64 ? (c == 0 ? 0.49f * step : 3.3f * step) : t;
            tg->normals[3 * v + c] = v % 8 == 5 && v >= 64 ? -2.2f * step_of(MK_DEFAULT_NORMAL_TOLERANCE) : -t;
            tg->tangents[3 * v + c] = t * 0.5f;
        }
    tg->positions[3 * 140] = 300000.0f * step;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 1, 0);
    CHECK(entry_of(&a, 0, 0) == NULL);
    const mk_blob_entry *e1 = entry_of(&a, 0, 1);
    uint64_t moved = 0;
    for (uint32_t i = 0; i < 64; i++) moved |= (uint64_t)((i + 64) % 4 == 3 || (i + 64) % 8 == 5) << i;
    CHECK(e1 && e1->mask == moved);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Exact zeros mixed in: every vertex given, those with three zero deltas (every other one, and
 * all of block 2 but vertex 130) are not in the mask, a vertex with only z nonzero is. */
static void test_zeros_dropped(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 192, 0, 0);
    const float step = step_of(1e-3);
    mk_raw_target *tg = add_target(&raw, 0, 0);
    for (uint32_t v = 0; v < 192; v++) {
        if (v % 2 || (v >= 128 && v != 130)) continue;
        tg->positions[3 * v + 2] = small(v, 2, step) + (small(v, 2, step) > 0 ? 2 * step : -2 * step);
        if (v % 4 == 0) tg->positions[3 * v] = small(v, 0, step) + 100 * step;
    }
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 0, 0);
    const mk_blob_entry *e0 = entry_of(&a, 0, 0), *e2 = entry_of(&a, 0, 2);
    CHECK(e0 && e0->mask == 0x5555555555555555ull);
    CHECK(e2 && e2->mask == 1ull << 2);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* All-equal values: block 0 of target 0 moves every vertex by (7, -3, 12) steps and normal
 * (0, 5, 0): width 0 everywhere, the values in the offsets, no data; block 1 equal in x only;
 * target 1 equal at 10^5 steps: a WIDE entry of width 0. */
static void test_all_equal_width_0(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 128, 1, 0);
    const float step = step_of(1e-3), nstep = step_of(MK_DEFAULT_NORMAL_TOLERANCE);
    mk_raw_target *t0 = add_target(&raw, 1, 0), *t1 = add_target(&raw, 0, 0);
    for (uint32_t v = 0; v < 128; v++) {
        t0->positions[3 * v] = 7.1f * step;
        t0->positions[3 * v + 1] = v < 64 ? -3.2f * step : small(v, 1, step);
        t0->positions[3 * v + 2] = v < 64 ? 12.3f * step : small(v, 2, step);
        t0->normals[3 * v + 1] = v < 64 ? 5.4f * nstep : small(v, 1, nstep);
        t1->positions[3 * v + 1] = 100000.2f * step;
    }
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 0, 2);
    const mk_blob_entry *e0 = entry_of(&a, 0, 0), *e1 = entry_of(&a, 0, 1), *w0 = entry_of(&a, 1, 0);
    static const int32_t want[6] = { 7, -3, 12, 0, 5, 0 };
    for (uint32_t k = 0; k < 6; k++) CHECK(e0 && mk_entry_code(e0, k) == 0 && offset_of(&a, e0, k) == want[k]);
    CHECK(e0 && mk_entry_bytes(e0, a.meshes[0].flags, a.targets[0].flags) == 0);
    CHECK(e1 && mk_entry_code(e1, 0) == 0 && offset_of(&a, e1, 0) == 7 && mk_entry_code(e1, 1) != 0);
    CHECK(w0 && mk_entry_wide(w0) && mk_entry_code(w0, 1) == 0 && offset_of(&a, w0, 1) == 100000
          && mk_entry_bytes(w0, a.meshes[0].flags, a.targets[1].flags) == MK_ENTRY_WIDE_BYTES);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* The int16 offset edges at a step of exactly 2^-10 (normals 2^-12): a position offset of
 * -32768 or 32767 steps stays in the head, -32769 or 32768 makes the entry WIDE; a normal or
 * tangent offset beyond int16 has no WIDE form: float32. */
static void test_int16_edges(void)
{
    mk_raw_asset raw;
    make_mesh(&raw, 8 * 64, 1, 1);
    const float step = 0x1p-10f, nstep = 0x1p-12f;
    mk_raw_target *tg = add_target(&raw, 1, 1);
    static const float lo[8] = { -32768, -32769, 32767, 32768, 0, 0, 0, 0 };
    static const float nlo[8] = { 0, 0, 0, 0, -32768, 32768, -32769, 0 };
    for (uint32_t v = 0; v < 8 * 64; v++) {
        const uint32_t b = v / 64;
        const float spread = (float)(v % 3);
        tg->positions[3 * v] = step * (lo[b] + spread);
        tg->positions[3 * v + 1] = step * (lo[b] == 0 ? 1 + spread : 0);
        tg->normals[3 * v + 1] = nstep * (nlo[b] + spread);
        tg->tangents[3 * v + 2] = nstep * (b == 7 ? 32768 + spread : spread);
        tg->tangents[3 * v] = nstep * 3;   /* the tangents' x: all equal */
    }
    /* Unit-ish normal sums: the deltas of 8 units along y are only ever added to +z. */
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .tolerance = POW2_TOLERANCE, .normal_tolerance = POW2_NORMAL_TOLERANCE }, &a,
               &arena, 3, 2);
    CHECK(a.targets[0].normal_scale == nstep && a.targets[0].tangent_scale == nstep);
    static const int kind[8] = { 0, 1, 0, 1, 0, 2, 2, 2 };   /* packed, WIDE, float */
    for (uint32_t b = 0; b < 8; b++) {
        const mk_blob_entry *en = entry_of(&a, 0, b);
        CHECK_MSG(en && (kind[b] == 2 ? !mk_entry_packed(en) : mk_entry_packed(en) && mk_entry_wide(en) == (kind[b] == 1)),
                  "block %u: expected kind %d", b, kind[b]);
    }
    const mk_blob_entry *e0 = entry_of(&a, 0, 0), *e4 = entry_of(&a, 0, 4);
    CHECK(e0 && offset_of(&a, e0, 0) == -32768 && mk_entry_offset(e0, 9, 0) == -32768);
    CHECK(e4 && offset_of(&a, e4, 4) == -32768 && offset_of(&a, e4, 6) == 3 && mk_entry_code(e4, 6) == 0);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Normals and tangents at their own step (the normal tolerance, here 3e-4; positions at the
 * default 1e-4 x the bounding-box diagonal): three targets (positions only; normals; normals and
 * tangents), a vertex moved only by its tangent is in the mask. */
static void test_normals_tangents_own_step(void)
{
    mk_raw_asset raw;
    mk_raw_mesh *m = make_mesh(&raw, 150, 1, 1);
    const float nstep = step_of(3e-4f);
    mk_raw_target *t0 = add_target(&raw, 0, 0), *t1 = add_target(&raw, 1, 0), *t2 = add_target(&raw, 1, 1);
    const float step = step_of(1e-4 * mk_raw_mesh_diagonal(m));
    for (uint32_t v = 0; v < 150; v++)
        for (uint32_t c = 0; c < 3; c++) {
            t0->positions[3 * v + c] = small(v, c, step) * 3;
            t1->positions[3 * v + c] = small(v, c + 1, step);
            t1->normals[3 * v + c] = small(v, c + 2, nstep) * 5;
            t2->normals[3 * v + c] = small(v, c + 3, nstep) * 7;
            t2->tangents[3 * v + c] = small(v, c + 4, nstep) * 11;
        }
    for (uint32_t c = 0; c < 3; c++) {
        t2->positions[3 * 77 + c] = t2->normals[3 * 77 + c] = 0;
        t2->tangents[3 * 77 + c] = c == 1 ? 4.2f * nstep : 0;
    }
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset a;
    round_trip(&raw, (mk_write_options){ .normal_tolerance = 3e-4f }, &a, &arena, 0, 0);
    CHECK(a.targets[2].normal_scale == nstep && a.targets[2].tangent_scale == nstep && a.targets[2].position_scale == step);
    CHECK(step != nstep);
    const mk_blob_entry *en = entry_of(&a, 2, 1);
    CHECK(en && (en->mask >> (77 - 64) & 1));
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* Component order: a mesh with tangents but no normals keeps the tangents at components 3-5;
 * with normals too, a target with tangents only has zero normal codes and its tangents at 6-8.
 * Each component moves by its own constant, so a swap shows in the offsets and the values. In
 * block 1 one vertex of target 1 moves 10^6 steps: a float entry whose tangent triples follow
 * the positions directly (the target has no normals, whatever the mesh has). */
static void test_component_order(void)
{
    for (int with_normals = 0; with_normals < 2; with_normals++) {
        mk_raw_asset raw;
        make_mesh(&raw, 100, with_normals, 1);
        const float step = step_of(1e-3), nstep = step_of(MK_DEFAULT_NORMAL_TOLERANCE);
        mk_raw_target *tg = add_target(&raw, 0, 1), *t1 = add_target(&raw, 0, 1);
        for (uint32_t v = 0; v < 100; v++) {
            static const float pos[3] = { 21, -22, 23 }, tan[3] = { 31, -32, 33 };
            for (uint32_t c = 0; c < 3; c++) {
                tg->positions[3 * v + c] = pos[c] * step;
                tg->tangents[3 * v + c] = tan[c] * nstep;
                t1->positions[3 * v + c] = small(v, c, step);
                t1->tangents[3 * v + c] = small(v, c + 5, nstep);
            }
        }
        mk_arena arena;
        mk_arena_init(&arena, NULL);
        mk_asset a;
        t1->positions[3 * 80] = 1e6f * step;
        round_trip(&raw, (mk_write_options){ .tolerance = 1e-3f }, &a, &arena, 1, 0);
        const uint32_t flags = a.meshes[0].flags, k0 = mk_attribute_component(flags, 2);
        CHECK_EQ_INT(k0, with_normals ? 6 : 3);
        CHECK_EQ_INT(mk_attribute_component(flags, 0), 0);
        CHECK_EQ_INT(mk_entry_stride(flags), with_normals ? 40 : 32);
        const mk_blob_entry *en = entry_of(&a, 0, 0);
        static const int32_t want[9] = { 21, -22, 23, 31, -32, 33, 0, 0, 0 };
        for (uint32_t k = 0; k < 3; k++) {
            CHECK(en && offset_of(&a, en, k) == want[k] && offset_of(&a, en, k0 + k) == want[3 + k]);
            if (with_normals) CHECK(en && mk_entry_code(en, 3 + k) == 0 && offset_of(&a, en, 3 + k) == 0);
        }
        mk_arena_free_all(&arena);
        mk_raw_free(&raw);
    }
}

/* The outlier block's float entry in normals and tangents too, with nlerp and slerp, and in
 * range jobs: the mixed blob plays like the all-float one within the quantization error, and
 * any split of the vertices gives the whole-mesh bytes. */
#define VERTICES 300u
#define OUTLIER 70u                /* vertex in block 1 */
#define TOLERANCE 0.001f

static void write_open(const mk_raw_asset *raw, const mk_write_options *o, mk_arena *arena, mk_asset *a,
                       mk_write_report *rep)
{
    void *blob;
    size_t size;
    mk_error err;
    CHECK_MSG(mk_write_blob(raw, o, arena, &blob, &size, rep, &err) == MK_OK, "write: %s", err.message);
    CHECK_MSG(mk_asset_open(blob, size, a, &err) == MK_OK, "open: %s", err.message);
}

static void eval_range(const mk_asset *a, const float *w, mk_normal_mode mode, uint32_t first, uint32_t count, float *p,
                       float *n, float *t)
{
    size_t scratch_size = mk_eval_scratch_size(a, 0);
    void *scratch = aligned_alloc(16, (scratch_size + 15) & ~(size_t)15);
    mk_eval_job job = { .asset = a, .first_vertex = first, .vertex_count = count, .weights = w, .weight_count = 4,
                        .normal_mode = mode, .scratch = scratch, .scratch_size = scratch_size,
                        .positions = p + 3 * first, .positions_size = 12u * count,
                        .normals = n + 3 * first, .normals_size = 12u * count,
                        .tangents = t + 4 * first, .tangents_size = 16u * count };
    mk_error err;
    CHECK_MSG(mk_eval_run(&job, &err) == MK_OK, "%s", err.message);
    free(scratch);
}

static void test_outlier_block_every_path(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, VERTICES, 4, 1);
    mk_raw_mesh *m = &raw.meshes[0];
    m->tangents = mk_arena_array(&raw.arena, 4u * VERTICES, sizeof(float));
    for (uint32_t v = 0; v < VERTICES; v++) { m->tangents[4 * v] = 1; m->tangents[4 * v + 3] = v % 2 ? 1.0f : -1.0f; }
    for (uint32_t c = 0; c < 4; c++) {
        mk_raw_target *t = &raw.channels[c].targets[0];
        t->tangents = mk_arena_array(&raw.arena, 3u * t->count, sizeof(float));
        for (uint32_t j = 0; j < t->count; j++) t->tangents[3 * j + 2] = 0.02f * (float)((t->indices[j] + c) % 4);
    }
    mk_raw_target *t3 = &raw.channels[3].targets[0];
    t3->positions[3 * OUTLIER + 1] = 1000.0f;   /* 5 x 10^5 steps next to values below 0.1: float32 */
    t3->normals[3 * OUTLIER + 2] = 0.5f;        /* the outlier block's normal and tangent deltas are float too */
    t3->tangents[3 * OUTLIER + 1] = 0.25f;
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    mk_asset mixed, exact_blob;
    mk_write_report rep;
    mk_write_options q = { .precision = MK_PRECISION_Q16, .tolerance = TOLERANCE }, f = { .precision = MK_PRECISION_FLOAT };
    write_open(&raw, &q, &arena, &mixed, &rep);
    CHECK_EQ_INT(rep.float_entries, 1);
    CHECK_EQ_INT(rep.wide_entries, 0);
    CHECK(mixed.targets[3].normal_scale == step_of(MK_DEFAULT_NORMAL_TOLERANCE));
    write_open(&raw, &f, &arena, &exact_blob, &rep);
    CHECK_EQ_INT(rep.float_entries, 0);   /* counted in quantized targets only */
    CHECK_EQ_INT(rep.float_targets, 4);
    static const float w[4] = { 0.5f, -1, 0.25f, 0.75f };
    float *p = malloc(12u * VERTICES), *n = malloc(12u * VERTICES), *t = malloc(16u * VERTICES);
    float *pe = malloc(12u * VERTICES), *ne = malloc(12u * VERTICES), *te = malloc(16u * VERTICES);
    float *ps = malloc(12u * VERTICES), *ns = malloc(12u * VERTICES), *ts = malloc(16u * VERTICES);
    for (int mode = 0; mode < 2; mode++) {
        mk_normal_mode nm = mode ? MK_NORMALS_SLERP : MK_NORMALS_NLERP;
        eval_range(&mixed, w, nm, 0, VERTICES, p, n, t);
        eval_range(&exact_blob, w, nm, 0, VERTICES, pe, ne, te);
        double dp = 0, dn = 0, dt = 0;
        for (uint32_t k = 0; k < 3 * VERTICES; k++) { dp = fmax(dp, fabs(p[k] - pe[k])); dn = fmax(dn, fabs(n[k] - ne[k])); }
        for (uint32_t k = 0; k < 4 * VERTICES; k++) dt = fmax(dt, fabs(t[k] - te[k]));
        CHECK_MSG(dp <= 2.5 * TOLERANCE && dn <= 2.5e-3 && dt <= 2.5e-3, "mode %d: positions %g, normals %g, tangents %g from the float blob",
                  mode, dp, dn, dt);
        /* With only the outlier's target playing, its block plays exactly as in the float blob
         * (the whole entry, normals and tangents too, is float). */
        static const float only3[4] = { 0, 0, 0, 0.75f };
        eval_range(&mixed, only3, nm, 0, VERTICES, ps, ns, ts);
        eval_range(&exact_blob, only3, nm, 0, VERTICES, pe, ne, te);
        const size_t b0 = OUTLIER / 64 * 64;
        CHECK_MSG(memcmp(&ps[3 * b0], &pe[3 * b0], 12 * 64) == 0 && memcmp(&ns[3 * b0], &ne[3 * b0], 12 * 64) == 0
                  && memcmp(&ts[4 * b0], &te[4 * b0], 16 * 64) == 0,
                  "mode %d: the outlier block differs from the float blob's", mode);
        static const uint32_t cuts[] = { 0, 70, 128, 129, VERTICES };
        for (size_t r = 0; r + 1 < sizeof cuts / sizeof cuts[0]; r++)
            eval_range(&mixed, w, nm, cuts[r], cuts[r + 1] - cuts[r], ps, ns, ts);
        CHECK_MSG(memcmp(p, ps, 12u * VERTICES) == 0 && memcmp(n, ns, 12u * VERTICES) == 0 && memcmp(t, ts, 16u * VERTICES) == 0,
                  "mode %d: range jobs differ from the whole-mesh job", mode);
    }
    free(p); free(n); free(t); free(pe); free(ne); free(te); free(ps); free(ns); free(ts);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

/* ---- the mask rule ---- */

static uint64_t bits(const unsigned *list, size_t n)
{
    uint64_t m = 0;
    for (size_t i = 0; i < n; i++) m |= 1ull << list[i];
    return m;
}

static uint64_t range(unsigned lo, unsigned hi) { return (hi >= 63 ? ~0ull : (1ull << (hi + 1)) - 1) & ~((1ull << lo) - 1); }

static void test_gap_rule(void)
{
    static const unsigned moved[] = { 0, 1, 2, 5, 20 };
    const uint64_t m = bits(moved, 5);
    CHECK_EQ_INT(mk_block_mask(m, 64, 2), range(0, 5) | 1ull << 20);   /* gap 3-4 filled, 6-19 not */
    CHECK_EQ_INT(mk_block_mask(m, 64, 1), m);                           /* a gap of 2 stays */
    CHECK_EQ_INT(mk_block_mask(m, 64, 0), m);
    CHECK_EQ_INT(mk_block_mask(m, 64, 14), range(0, 20));   /* 6-19 is 14; 43 left (tail 21-63) > 3 x 14 */
    CHECK_EQ_INT(mk_block_mask(m, 64, 15), ~0ull);          /* 43 left <= 3 x 15: the whole block */
    /* Only the head and tail missing, each short: the whole block (the runtime's fast path). */
    CHECK_EQ_INT(mk_block_mask(range(2, 62), 64, 1), ~0ull);       /* 3 left <= 3 x 1 */
    CHECK_EQ_INT(mk_block_mask(range(2, 62), 64, 0), range(2, 62));
    CHECK_EQ_INT(mk_block_mask(range(0, 61), 64, 2), ~0ull);
    static const unsigned ends[] = { 0, 1, 2, 3, 60, 61, 62 };    /* 57 left: 4-59 and the tail 63 */
    CHECK_EQ_INT(mk_block_mask(bits(ends, 7), 64, 18), bits(ends, 7));
    CHECK_EQ_INT(mk_block_mask(bits(ends, 7), 64, 19), ~0ull);
    /* Interior gaps filled, head 1 + tail 1 <= 2. */
    static const unsigned sparse[] = { 1, 3, 5, 60, 62 };
    CHECK_EQ_INT(mk_block_mask(bits(sparse, 5) | range(5, 60), 64, 2), ~0ull);
    /* A partial last block (40 vertices): full means its 40 bits. */
    CHECK_EQ_INT(mk_block_mask(range(1, 38), 40, 2), range(0, 39));
    CHECK_EQ_INT(mk_block_mask(range(1, 38), 40, 0), range(1, 38));
    /* Every bit, the last bit, one bit. */
    CHECK_EQ_INT(mk_block_mask(~0ull, 64, 0), ~0ull);
    CHECK_EQ_INT(mk_block_mask(1ull << 63, 64, 4), 1ull << 63);
    /* Nothing moved: nothing stored; a gap so large that 3 x gap would wrap in 32 bits still
     * stores the whole block. */
    CHECK_EQ_INT(mk_block_mask(0, 64, 8), 0);
    CHECK_EQ_INT(mk_block_mask(1, 64, 0x55555556u), ~0ull);
    CHECK_EQ_INT(mk_block_mask(1ull << 63, 64, 64), ~0ull);
    CHECK_EQ_INT(mk_block_mask(1, 1, 0), 1);
    static const unsigned pair[] = { 62, 63 };
    CHECK_EQ_INT(mk_block_mask(bits(pair, 2) | 1, 64, 20), bits(pair, 2) | 1);   /* the gap 1-61: 61 > 3 x 20 */
    CHECK_EQ_INT(mk_block_mask(bits(pair, 2) | 1, 64, 21), ~0ull);
}

/* The writer uses the rule: a target moving {0, 1, 2, 5, 20} of block 0 stores bits 0-5 and 20
 * with gap_limit 3 (G = 2); with gap_limit 1 exactly the moved vertices. The filled-in vertices
 * read as zero: evaluation and read-back are the same either way. */
static void test_writer_masks(void)
{
    static const unsigned moved[] = { 0, 1, 2, 5, 20 };
    for (int g = 0; g < 2; g++) {
        mk_raw_asset raw;
        mk_raw_init(&raw, NULL);
        fixture_line(&raw, 64, 1, 1);
        mk_raw_target *t = &raw.channels[0].targets[0];
        for (uint32_t j = 0; j < 5; j++) {
            t->indices[j] = moved[j];
            for (int k = 0; k < 3; k++) t->positions[3 * j + (uint32_t)k] = 0.01f * (float)(j + 1);
        }
        t->count = 5;
        mk_write_options o = { .gap_limit = g ? 3 : 1 };
        mk_asset a;
        mk_write_report rep;
        write_open(&raw, &o, &raw.arena, &a, &rep);
        const mk_blob_entry *e = (const mk_blob_entry *)(a.data + a.meshes[0].entries);
        CHECK_EQ_INT(a.meshes[0].entry_count, 1);
        CHECK_EQ_INT(e->mask, g ? range(0, 5) | 1ull << 20 : bits(moved, 5));
        check_read_back(&raw, &a, &rep);
        check_eval(&raw, &a);
        mk_raw_free(&raw);
    }
}

CHECK_MAIN(CASE(test_huge_range_is_float), CASE(test_outlier_vertex), CASE(test_wide), CASE(test_2p23_and_2p16_edges),
           CASE(test_tiny_values), CASE(test_zeros_dropped), CASE(test_all_equal_width_0), CASE(test_int16_edges),
           CASE(test_normals_tangents_own_step), CASE(test_component_order), CASE(test_outlier_block_every_path),
           CASE(test_gap_rule), CASE(test_writer_masks))

/* SPDX-License-Identifier: MIT */
/* mk_write_blob: raw model -> .morph blob (runtime/format.h, docs/format.md).
 *
 * Layout: header | section table | STRINGS | MESHES | CHANNELS | TARGETS | CLIPS | TRACKS |
 * KEYS | DATA, every piece 16-aligned. DATA holds, per mesh: base positions, normals,
 * tangents, triangles, control-point map, the block table, the entries and the delta data.
 *
 * Targets are cut into blocks of 64 vertices. A block where a target moves at least
 * dense_threshold vertices is stored dense (all the block's vertices, zeros included), so
 * the runtime runs a plain vectorized loop; sparser blocks store only the moved vertices
 * with a bit mask. Quantized targets store int16 per component with a per-target,
 * per-attribute scale = max|component| / 32767; a target whose position error would exceed
 * the tolerance is stored as float32 instead.
 *
 * Deterministic: fixed iteration order, all padding zero, nothing taken from pointers/time.
 */
#include <math.h>
#include <string.h>
#include "blob_io.h"
#include "format.h"

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

/* Appends n bytes (zeros if src is NULL) at a 16-aligned position; returns that position. */
static size_t bytes_put(bytes *b, const void *src, size_t n)
{
    size_t at = pad16(b->size);
    if (!bytes_reserve(b, at - b->size + n)) return 0;
    memset(b->data + b->size, 0, at - b->size);
    if (src && n) memcpy(b->data + at, src, n); else if (n) memset(b->data + at, 0, n);
    b->size = at + n;
    return at;
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

static int16_t quantize(float v, float scale)
{
    if (scale == 0) return 0;
    float q = roundf(v / scale);
    q = q > 32767.f ? 32767.f : q < -32767.f ? -32767.f : q;
    return (int16_t)q;
}

/* Largest |dequantized - exact| over the array. */
static double quant_error(const float *p, size_t n, float scale)
{
    double e = 0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)quantize(p[i], scale) * scale - (double)p[i]);
        if (d > e) e = d;
    }
    return e;
}

static float mesh_diagonal(const mk_raw_mesh *m)
{
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int d = 0; d < 3; d++) {
            float x = m->positions[3u * v + (uint32_t)d];
            lo[d] = x < lo[d] ? x : lo[d];
            hi[d] = x > hi[d] ? x : hi[d];
        }
    float s = 0;
    for (int d = 0; d < 3; d++) s += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    return sqrtf(s);
}

typedef struct target_plan {
    uint32_t flags;
    float position_scale, normal_scale, tangent_scale;
} target_plan;

static target_plan plan_target(const mk_raw_target *t, mk_precision precision, double tolerance,
                               mk_write_report *report)
{
    target_plan p = { 0, 0, 0, 0 };
    if (t->normals) p.flags |= MK_TARGET_HAS_NORMALS;
    if (t->tangents) p.flags |= MK_TARGET_HAS_TANGENTS;
    if (precision == MK_PRECISION_FLOAT) { report->float_targets++; return p; }
    size_t n = 3 * (size_t)t->count;
    float ps = quant_scale(max_abs(t->positions, n));
    double pe = quant_error(t->positions, n, ps);
    if (pe > tolerance) { report->float_targets++; return p; }
    p.flags |= MK_TARGET_QUANTIZED;
    p.position_scale = ps;
    if (pe > report->max_position_error) report->max_position_error = pe;
    if (t->normals) {
        p.normal_scale = quant_scale(max_abs(t->normals, n));
        double ne = quant_error(t->normals, n, p.normal_scale);
        if (ne > report->max_normal_error) report->max_normal_error = ne;
    }
    if (t->tangents) {
        p.tangent_scale = quant_scale(max_abs(t->tangents, n));
        double te = quant_error(t->tangents, n, p.tangent_scale);
        if (te > report->max_tangent_error) report->max_tangent_error = te;
    }
    report->quantized_targets++;
    return p;
}

/* Writes one attribute's xyz triples for the vertices of `mask` in block `block`, in bit order.
 * src/index describe the target's sparse data; cursor is the first target entry in the block. */
static void put_triples(uint8_t *dst, const mk_raw_target *t, const float *src, uint32_t cursor, uint64_t mask,
                        uint32_t block, int quantized, float scale)
{
    for (int c = 0; c < 3; c++) {
        uint32_t j = 0, k = cursor;
        for (uint64_t bits = mask; bits; bits &= bits - 1, j++) {
            uint32_t v = block * MK_BLOCK_SIZE + mk_ctz64(bits);
            while (k < t->count && t->indices[k] < v) k++;
            float value = (k < t->count && t->indices[k] == v) ? src[3u * k + (uint32_t)c] : 0.0f;
            if (quantized) {
                int16_t q = quantize(value, scale);
                memcpy(dst + (3 * (size_t)j + (size_t)c) * 2, &q, 2);
            } else {
                memcpy(dst + (3 * (size_t)j + (size_t)c) * 4, &value, 4);
            }
        }
    }
}

typedef struct mesh_out {
    uint64_t positions, normals, tangents, triangles, control_points, block_entries, entries, target_data;
    uint64_t entry_count, target_data_size;
} mesh_out;

/* Appends one mesh's arrays to data; offsets are relative to the data section. */
static mk_result write_mesh_data(const mk_raw_asset *raw, uint32_t mi, uint32_t first_channel, uint32_t channel_count,
                                 const target_plan *plans, uint32_t dense_threshold, bytes *data, mesh_out *out,
                                 mk_write_report *report, mk_error *err)
{
    const mk_raw_mesh *m = &raw->meshes[mi];
    mk_arena *arena = data->arena;
    memset(out, 0, sizeof *out);
    out->positions = bytes_put(data, m->positions, 12u * (size_t)m->vertex_count);
    if (m->normals) out->normals = bytes_put(data, m->normals, 12u * (size_t)m->vertex_count);
    if (m->tangents) out->tangents = bytes_put(data, m->tangents, 16u * (size_t)m->vertex_count);
    out->triangles = bytes_put(data, m->triangles, 12u * (size_t)m->triangle_count);
    out->control_points = bytes_put(data, NULL, 4u * (size_t)m->vertex_count);
    if (data->failed) return mk_error_oom(err, "writing mesh arrays");
    uint32_t *cp = (uint32_t *)(void *)(data->data + out->control_points);
    for (uint32_t v = 0; v < m->vertex_count; v++) cp[v] = m->control_points ? m->control_points[v] : v;

    /* Targets of the mesh in blob order, with a cursor each into its sorted indices. */
    uint32_t target_count = 0;
    for (uint32_t c = first_channel; c < first_channel + channel_count; c++) target_count += raw->channels[c].target_count;
    const mk_raw_target **targets = mk_arena_array(arena, target_count + 1, sizeof *targets);
    uint32_t *cursor = mk_arena_array(arena, target_count + 1, sizeof *cursor);
    uint32_t blocks = (m->vertex_count + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE;
    uint32_t *block_first = mk_arena_array(arena, (size_t)blocks + 1, sizeof *block_first);
    /* Delta data is laid out target-major (all blocks of target 0, then target 1, ...) while
     * the entries stay block-major: a frame then reads each active target as one sequential
     * stream, which the hardware prefetcher and the TLB handle well, and never touches the
     * pages of inactive targets. Each target's data goes to its own buffer first; entry data
     * offsets are rebased once the buffers are concatenated. */
    bytes *per_target = mk_arena_array(arena, target_count + 1, sizeof *per_target);
    bytes entries = { arena, NULL, 0, 0, 0 }, offsets = { arena, NULL, 0, 0, 0 }; /* offsets: per entry, in its target's buffer */
    if (!targets || !cursor || !block_first || !per_target) return mk_error_oom(err, "planning blocks");
    for (uint32_t t = 0; t < target_count; t++) per_target[t].arena = arena;
    uint32_t k = 0;
    for (uint32_t c = first_channel; c < first_channel + channel_count; c++)
        for (uint32_t j = 0; j < raw->channels[c].target_count; j++) targets[k++] = &raw->channels[c].targets[j];

    uint64_t entry_count = 0;
    for (uint32_t b = 0; b < blocks; b++) {
        block_first[b] = (uint32_t)entry_count;
        uint32_t start = b * MK_BLOCK_SIZE;
        uint32_t in_block = m->vertex_count - start < MK_BLOCK_SIZE ? m->vertex_count - start : MK_BLOCK_SIZE;
        uint64_t all = in_block == 64 ? ~0ull : ((1ull << in_block) - 1);
        for (uint32_t t = 0; t < target_count; t++) {
            const mk_raw_target *tg = targets[t];
            uint32_t first = cursor[t], end = first;
            uint64_t mask = 0;
            while (end < tg->count && tg->indices[end] < start + in_block) mask |= 1ull << (tg->indices[end++] - start);
            cursor[t] = end;
            if (!mask) continue;
            uint32_t moved = mk_popcount64(mask);
            if (moved >= dense_threshold) mask = all;
            uint32_t count = mk_popcount64(mask);
            const target_plan *p = &plans[t];
            int q = (p->flags & MK_TARGET_QUANTIZED) != 0;
            size_t size = (size_t)mk_entry_data_size(p->flags, count);
            bytes *dst_buf = &per_target[t];
            size_t at = bytes_put(dst_buf, NULL, size);
            if (dst_buf->failed) return mk_error_oom(err, "writing target data");
            size_t attr = size / (1u + (tg->normals ? 1u : 0u) + (tg->tangents ? 1u : 0u));
            uint8_t *dst = dst_buf->data + at;
            put_triples(dst, tg, tg->positions, first, mask, b, q, p->position_scale);
            if (tg->normals) put_triples(dst += attr, tg, tg->normals, first, mask, b, q, p->normal_scale);
            if (tg->tangents) put_triples(dst + attr, tg, tg->tangents, first, mask, b, q, p->tangent_scale);
            /* data is filled in once the target buffers are concatenated (below). */
            mk_blob_entry e = { t, 0, mask };
            size_t e_at = entries.size;
            uint64_t local = at;
            if (!bytes_reserve(&entries, sizeof e) || !bytes_reserve(&offsets, sizeof local))
                return mk_error_oom(err, "writing entries");
            memcpy(entries.data + e_at, &e, sizeof e);
            entries.size += sizeof e;
            memcpy(offsets.data + offsets.size, &local, sizeof local);
            offsets.size += sizeof local;
            if (++entry_count > UINT32_MAX)
                return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: more than 2^32 block entries", mi);
        }
    }
    block_first[blocks] = (uint32_t)entry_count;
    /* Concatenate the per-target buffers and rebase the entries. */
    uint64_t *base = mk_arena_array(arena, target_count + 1, sizeof *base);
    if (!base) return mk_error_oom(err, "writing target data");
    uint64_t total = 0;
    for (uint32_t t = 0; t < target_count; t++) { base[t] = total; total += pad16(per_target[t].size); }
    if (total / MK_ALIGN > UINT32_MAX)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "mesh %u: target data exceeds 64 GiB", mi);
    mk_blob_entry *all_entries = (mk_blob_entry *)(void *)entries.data;
    const uint64_t *local_offsets = (const uint64_t *)(void *)offsets.data;
    for (uint64_t e = 0; e < entry_count; e++)
        all_entries[e].data = (uint32_t)((base[all_entries[e].target] + local_offsets[e]) / MK_ALIGN);
    out->block_entries = bytes_put(data, block_first, 4u * ((size_t)blocks + 1));
    out->entries = bytes_put(data, entries.data, entries.size);
    out->entry_count = entry_count;
    out->target_data = bytes_put(data, NULL, (size_t)total);
    out->target_data_size = total;
    if (data->failed) return mk_error_oom(err, "writing block data");
    for (uint32_t t = 0; t < target_count; t++) {
        if (per_target[t].size) memcpy(data->data + out->target_data + base[t], per_target[t].data, per_target[t].size);
        mk_arena_release(arena, per_target[t].data);
    }
    report->target_bytes += entries.size + total;
    mk_arena_release(arena, entries.data);
    mk_arena_release(arena, offsets.data);
    mk_arena_release(arena, per_target);
    mk_arena_release(arena, base);
    mk_arena_release(arena, targets);
    mk_arena_release(arena, cursor);
    mk_arena_release(arena, block_first);
    return MK_OK;
}

mk_result mk_write_blob(const mk_raw_asset *raw, const mk_write_options *options, mk_arena *arena,
                        void **blob_out, size_t *size_out, mk_write_report *report_out, mk_error *err)
{
    mk_write_options opt = options ? *options : (mk_write_options){ 0 };
    if (opt.dense_threshold == 0) opt.dense_threshold = 24;
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

    bytes strings = { arena, NULL, 0, 0, 0 }, data = { arena, NULL, 0, 0, 0 };
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

    /* Channels and targets, with per-target precision decided per mesh tolerance. */
    uint32_t t_index = 0;
    for (uint32_t mi = 0, c = 0; mi < raw->mesh_count; mi++) {
        const mk_raw_mesh *m = &raw->meshes[mi];
        double tolerance = opt.tolerance > 0 ? opt.tolerance : 1e-4 * mesh_diagonal(m);
        if (tolerance > report.tolerance_used) report.tolerance_used = tolerance;
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
                plans[t_index] = plan_target(t, opt.precision, tolerance, &report);
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
        r = write_mesh_data(raw, mi, bm->first_channel, bm->channel_count, &plans[bm->first_target],
                            opt.dense_threshold, &data, &mesh_data[mi], &report, err);
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
    if (strings.failed || data.failed) return mk_error_oom(err, "writing strings");
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
        { MK_SECTION_DATA, 1, data.size, data.data },
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
    uint8_t *blob = mk_arena_alloc(arena, (size_t)total);
    if (!blob) return mk_error_oom(err, "allocating the blob");
    mk_blob_header header;
    memset(&header, 0, sizeof header);
    memcpy(header.magic, MK_MAGIC, 8);
    header.version = MK_FORMAT_VERSION;
    header.header_size = sizeof header;
    header.file_size = total;
    header.section_count = section_count;
    memcpy(blob + sizeof header, table, sizeof table);
    for (uint32_t i = 0; i < section_count; i++)
        if (table[i].size) memcpy(blob + table[i].offset, parts[i].src, (size_t)table[i].size);
    memcpy(blob, &header, sizeof header);
    header.checksum = mk_checksum(blob + 32, total - 32);
    memcpy(blob, &header, sizeof header);

    mk_arena_release(arena, strings.data);
    mk_arena_release(arena, data.data);
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

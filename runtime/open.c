/* SPDX-License-Identifier: MIT */
/* mk_asset_open: validates a .morph blob once, in one O(size) pass, so that no hot path ever
 * checks again. Every offset, count and index is checked against the blob size with
 * overflow-safe arithmetic; every float is checked finite; sorted data is checked sorted.
 * Also the read-only queries over an opened asset.
 *
 * Error messages are built without stdio/stdarg (the runtime includes only libc basics and
 * never allocates, not even in a formatting routine). */
#include <math.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"
#include "determinism.h"

/* ---- error message building ---- */

static void append(char *buf, size_t *len, const char *s)
{
    while (*s && *len + 1 < 256) buf[(*len)++] = *s++;
    buf[*len] = 0;
}

static void append_u64(char *buf, size_t *len, uint64_t v)
{
    char digits[24];
    int n = 0;
    do { digits[n++] = (char)('0' + v % 10); v /= 10; } while (v);
    char tmp[2] = { 0, 0 };
    while (n--) { tmp[0] = digits[n]; append(buf, len, tmp); }
}

#define NO_INDEX UINT64_MAX
#define NO_OFFSET UINT64_MAX

/* Message: "<a><i1><b><i2><c>" (an index of NO_INDEX is left out) plus " (byte offset N)"
 * when the offset is known. */
static mk_result fail_with(mk_error *err, mk_result code, uint64_t offset, const char *a, uint64_t i1,
                           const char *b, uint64_t i2, const char *c)
{
    if (!err) return code;
    size_t len = 0;
    err->code = code;
    err->offset = offset;
    err->message[0] = 0;
    append(err->message, &len, a);
    if (i1 != NO_INDEX) append_u64(err->message, &len, i1);
    append(err->message, &len, b);
    if (i2 != NO_INDEX) append_u64(err->message, &len, i2);
    append(err->message, &len, c);
    if (offset != NO_OFFSET) {
        append(err->message, &len, " (byte offset ");
        append_u64(err->message, &len, offset);
        append(err->message, &len, ")");
    }
    return code;
}

static mk_result fail(mk_error *err, mk_result code, uint64_t offset, const char *a, uint64_t index,
                      const char *b)
{
    return fail_with(err, code, offset, a, index, b, NO_INDEX, "");
}

const char *mk_result_name(mk_result code)
{
    static const char *const names[MK_RESULT_COUNT] = {
        "ok", "invalid argument", "truncated", "bad magic", "bad version", "bad checksum",
        "bad alignment", "corrupt", "out of range", "buffer too small", "not finite",
        "unsupported", "i/o error", "out of memory", "parse error", "limit exceeded",
    };
    return (unsigned)code < MK_RESULT_COUNT ? names[code] : "unknown";
}

/* ---- validation helpers ---- */

typedef struct validator {
    const uint8_t *data;
    uint64_t size;
    mk_error *err;
} validator;

/* Is [offset, offset + count * elem) inside the blob and offset 16-aligned? */
static mk_result check_array(const validator *v, uint64_t offset, uint64_t count, uint64_t elem,
                             const char *what, uint64_t index, const char *field)
{
    (void)field;
    if (offset % MK_ALIGN)
        return fail(v->err, MK_ERROR_BAD_ALIGNMENT, offset, what, index, ": array is not 16-byte aligned");
    if (elem && count > (UINT64_MAX / elem))
        return fail(v->err, MK_ERROR_CORRUPT, offset, what, index, ": array size overflows");
    uint64_t bytes = count * elem;
    if (offset > v->size || bytes > v->size - offset)
        return fail(v->err, MK_ERROR_TRUNCATED, offset, what, index, ": array extends past the end of the blob");
    return MK_OK;
}

static int all_finite(const float *p, uint64_t n)
{
    for (uint64_t i = 0; i < n; i++)
        if (!isfinite(p[i])) return 0;
    return 1;
}

static int valid_string(const mk_asset *a, uint32_t offset) { return offset < a->strings_size; }

/* Reserved fields must be zero, so a later version can give them a meaning. */
static int all_zero(const uint32_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i]) return 0;
    return 1;
}


static mk_result validate_sections(validator *v, mk_asset *a)
{
    const mk_blob_header *h = a->header;
    uint64_t table = sizeof(mk_blob_header);
    if ((uint64_t)h->section_count > (v->size - table) / sizeof(mk_blob_section))
        return fail(v->err, MK_ERROR_TRUNCATED, table, "section table of ", h->section_count,
                    " sections extends past the end of the blob");
    static const uint32_t element_sizes[MK_SECTION_KIND_COUNT] = {
        0, 1, sizeof(mk_blob_mesh), sizeof(mk_blob_channel), sizeof(mk_blob_target),
        sizeof(mk_blob_clip), sizeof(mk_blob_track), sizeof(mk_key), 1,
    };
    const mk_blob_section *sections = (const mk_blob_section *)(v->data + table);
    const mk_blob_section *found[MK_SECTION_KIND_COUNT] = { 0 };
    for (uint32_t i = 0; i < h->section_count; i++) {
        const mk_blob_section *s = &sections[i];
        uint64_t at = table + (uint64_t)i * sizeof(mk_blob_section);
        if (s->kind == 0 || s->kind >= MK_SECTION_KIND_COUNT)
            return fail(v->err, MK_ERROR_CORRUPT, at, "section ", i, ": unknown kind");
        if (found[s->kind])
            return fail(v->err, MK_ERROR_CORRUPT, at, "section ", i, ": kind appears twice");
        if (s->element_size != element_sizes[s->kind])
            return fail(v->err, MK_ERROR_CORRUPT, at, "section ", i, ": wrong element size for its kind");
        if (s->count > UINT64_MAX / s->element_size || s->size != s->count * s->element_size)
            return fail(v->err, MK_ERROR_CORRUPT, at, "section ", i, ": size does not match count");
        mk_result r = check_array(v, s->offset, s->count, s->element_size, "section ", i, "");
        if (r) return r;
        if (s->kind != MK_SECTION_STRINGS && s->kind != MK_SECTION_DATA && s->count > UINT32_MAX)
            return fail(v->err, MK_ERROR_CORRUPT, at, "section ", i, ": more than 2^32 elements");
        found[s->kind] = s;
    }
    for (uint32_t k = 1; k < MK_SECTION_KIND_COUNT; k++)
        if (!found[k]) return fail(v->err, MK_ERROR_CORRUPT, table, "required section kind ", k, " is missing");

    a->strings = (const char *)(v->data + found[MK_SECTION_STRINGS]->offset);
    a->strings_size = found[MK_SECTION_STRINGS]->size;
    if (a->strings_size == 0 || a->strings[0] != 0 || a->strings[a->strings_size - 1] != 0)
        return fail(v->err, MK_ERROR_CORRUPT, found[MK_SECTION_STRINGS]->offset, "string section", NO_INDEX,
                    " does not start and end with a NUL byte");
    a->meshes = (const mk_blob_mesh *)(v->data + found[MK_SECTION_MESHES]->offset);
    a->mesh_count = (uint32_t)found[MK_SECTION_MESHES]->count;
    a->channels = (const mk_blob_channel *)(v->data + found[MK_SECTION_CHANNELS]->offset);
    a->channel_count = (uint32_t)found[MK_SECTION_CHANNELS]->count;
    a->targets = (const mk_blob_target *)(v->data + found[MK_SECTION_TARGETS]->offset);
    a->target_count = (uint32_t)found[MK_SECTION_TARGETS]->count;
    a->clips = (const mk_blob_clip *)(v->data + found[MK_SECTION_CLIPS]->offset);
    a->clip_count = (uint32_t)found[MK_SECTION_CLIPS]->count;
    a->tracks = (const mk_blob_track *)(v->data + found[MK_SECTION_TRACKS]->offset);
    a->track_count = (uint32_t)found[MK_SECTION_TRACKS]->count;
    a->keys = (const mk_key *)(v->data + found[MK_SECTION_KEYS]->offset);
    a->key_count = (uint32_t)found[MK_SECTION_KEYS]->count;
    return MK_OK;
}

static mk_result validate_channels_and_targets(validator *v, const mk_asset *a)
{
    for (uint32_t c = 0; c < a->channel_count; c++) {
        const mk_blob_channel *ch = &a->channels[c];
        uint64_t at = (uint64_t)((const uint8_t *)ch - v->data);
        if (!valid_string(a, ch->name) || !valid_string(a, ch->origin))
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": name or origin string out of range");
        if (ch->mesh >= a->mesh_count)
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": mesh index out of range");
        const mk_blob_mesh *m = &a->meshes[ch->mesh];
        if (c < m->first_channel || c - m->first_channel >= m->channel_count)
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": not inside its mesh's channel range");
        if (ch->target_count == 0 || ch->first_target > a->target_count
            || ch->target_count > a->target_count - ch->first_target)
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": target range out of bounds");
        if (ch->first_target < m->first_target
            || ch->first_target + ch->target_count > m->first_target + m->target_count)
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": targets outside its mesh's target range");
        /* Channels tile their mesh's targets in order: the first starts at the mesh's first
         * target, each next one where the previous ended. */
        uint32_t expected = c == m->first_channel ? m->first_target
                          : a->channels[c - 1].first_target + a->channels[c - 1].target_count;
        if (ch->first_target != expected)
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": targets do not follow the previous channel's");
        if (!isfinite(ch->default_weight))
            return fail(v->err, MK_ERROR_NOT_FINITE, at, "channel ", c, ": default weight is not finite");
        if (!all_zero(ch->reserved, 2))
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": reserved fields are not zero");
        for (uint32_t k = 0; k < ch->target_count; k++) {
            uint32_t t = ch->first_target + k;
            const mk_blob_target *tg = &a->targets[t];
            uint64_t tat = (uint64_t)((const uint8_t *)tg - v->data);
            if (tg->channel != c)
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": channel index does not match");
            if (!valid_string(a, tg->name))
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": name string out of range");
            if (!isfinite(tg->full_weight) || fabsf(tg->full_weight) < MK_MIN_FULL_WEIGHT_GAP)
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": full weight is (nearly) zero or not finite");
            if (k > 0 && !(tg->full_weight - a->targets[t - 1].full_weight >= MK_MIN_FULL_WEIGHT_GAP))
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t,
                            ": full weights of a channel must increase (by at least 1e-6)");
            if (tg->flags & ~7u)
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": unknown flags");
            if (((tg->flags & MK_TARGET_HAS_NORMALS) && !(m->flags & MK_MESH_HAS_NORMALS))
                || ((tg->flags & MK_TARGET_HAS_TANGENTS) && !(m->flags & MK_MESH_HAS_TANGENTS)))
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t,
                            ": has normal/tangent deltas but its mesh has no base normals/tangents");
            if (!isfinite(tg->position_scale) || !isfinite(tg->normal_scale) || !isfinite(tg->tangent_scale)
                || tg->position_scale < 0 || tg->normal_scale < 0 || tg->tangent_scale < 0)
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": bad quantization scale");
        }
    }
    /* Channels must tile each mesh's targets completely (no target without a channel). */
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const mk_blob_mesh *m = &a->meshes[i];
        uint32_t end = m->channel_count ? a->channels[m->first_channel + m->channel_count - 1].first_target
                                            + a->channels[m->first_channel + m->channel_count - 1].target_count
                                        : m->first_target;
        if (end != m->first_target + m->target_count)
            return fail(v->err, MK_ERROR_CORRUPT, (uint64_t)((const uint8_t *)m - v->data), "mesh ", i,
                        ": its channels do not cover its targets");
    }
    return MK_OK;
}

/* Checks the block table, entries and delta data of one mesh. */
static mk_result validate_blocks(validator *v, const mk_asset *a, uint32_t mi)
{
    const mk_blob_mesh *m = &a->meshes[mi];
    mk_result r;
    if ((r = check_array(v, m->block_entries, (uint64_t)m->block_count + 1, 4, "mesh ", mi, "block table"))) return r;
    if ((r = check_array(v, m->entries, m->entry_count, sizeof(mk_blob_entry), "mesh ", mi, "entries"))) return r;
    if ((r = check_array(v, m->target_data, m->target_data_size, 1, "mesh ", mi, "target data"))) return r;
    const uint32_t *first = (const uint32_t *)(v->data + m->block_entries);
    const mk_blob_entry *entries = (const mk_blob_entry *)(v->data + m->entries);
    if (first[0] != 0 || first[m->block_count] != m->entry_count)
        return fail(v->err, MK_ERROR_CORRUPT, m->block_entries, "mesh ", mi, ": block table does not span the entries");
    /* The whole table first: non-decreasing (so every value is <= entry_count) before any
     * block's entries are read. */
    for (uint32_t b = 0; b < m->block_count; b++)
        if (first[b + 1] < first[b])
            return fail(v->err, MK_ERROR_CORRUPT, m->block_entries + 4ull * b, "mesh ", mi,
                        ": block table is not increasing");
    for (uint32_t b = 0; b < m->block_count; b++) {
        uint32_t in_block = m->vertex_count - b * MK_BLOCK_SIZE;
        if (in_block > MK_BLOCK_SIZE) in_block = MK_BLOCK_SIZE;
        uint64_t allowed = in_block == 64 ? ~0ull : ((1ull << in_block) - 1);
        for (uint32_t e = first[b]; e < first[b + 1]; e++) {
            const mk_blob_entry *en = &entries[e];
            uint64_t at = m->entries + (uint64_t)e * sizeof(mk_blob_entry);
            if (en->target >= m->target_count)
                return fail(v->err, MK_ERROR_CORRUPT, at, "entry ", e, ": target index out of range");
            if (e > first[b] && en->target <= entries[e - 1].target)
                return fail(v->err, MK_ERROR_CORRUPT, at, "entry ", e, ": targets of a block are not strictly increasing");
            if (en->mask == 0 || (en->mask & ~allowed))
                return fail(v->err, MK_ERROR_CORRUPT, at, "entry ", e, ": vertex mask is empty or past the mesh end");
            const mk_blob_target *tg = &a->targets[m->first_target + en->target];
            uint32_t count = mk_popcount64(en->mask);
            uint64_t bytes = mk_entry_data_size(tg->flags, count);
            uint64_t offset = (uint64_t)en->data * MK_ALIGN;
            if (offset > m->target_data_size || bytes > m->target_data_size - offset)
                return fail(v->err, MK_ERROR_CORRUPT, at, "entry ", e, ": data extends past the mesh's target data");
            if (!(tg->flags & MK_TARGET_QUANTIZED)
                && !all_finite((const float *)(v->data + m->target_data + offset), bytes / 4))
                return fail(v->err, MK_ERROR_NOT_FINITE, m->target_data + offset, "entry ", e,
                            ": delta data is not finite");
        }
    }
    return MK_OK;
}

static mk_result validate_meshes(validator *v, const mk_asset *a)
{
    uint32_t next_channel = 0, next_target = 0;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const mk_blob_mesh *m = &a->meshes[i];
        uint64_t at = (uint64_t)((const uint8_t *)m - v->data);
        mk_result r;
        if (!valid_string(a, m->name))
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": name string out of range");
        if (m->vertex_count == 0)
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": has no vertices");
        if (m->vertex_count > MK_MAX_VERTICES)   /* block arithmetic in eval stays in uint32 */
            return fail(v->err, MK_ERROR_UNSUPPORTED, at, "mesh ", i, ": has more vertices than a mesh may have (2^32 - 64)");
        if ((uint64_t)m->block_count != ((uint64_t)m->vertex_count + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE)
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": block count does not match vertex count");
        if (m->first_channel != next_channel || m->channel_count > a->channel_count - next_channel)
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": channel range does not follow the previous mesh's");
        if (m->first_target != next_target || m->target_count > a->target_count - next_target)
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": target range does not follow the previous mesh's");
        next_channel += m->channel_count;
        next_target += m->target_count;
        if (m->stacking != MK_STACKING_ADDITIVE && m->stacking != MK_STACKING_SEQUENTIAL)
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": unknown stacking mode");
        if (m->flags & ~3u)
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": unknown flags");
        if (!all_zero(m->reserved, 2))
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": reserved fields are not zero");
        if ((!(m->flags & MK_MESH_HAS_NORMALS) && m->normals) || (!(m->flags & MK_MESH_HAS_TANGENTS) && m->tangents))
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i,
                        ": normal or tangent offset is set but the mesh's flags say it has none");
        if (!all_finite(m->world, 16))
            return fail(v->err, MK_ERROR_NOT_FINITE, at, "mesh ", i, ": world transform is not finite");
        if ((r = check_array(v, m->positions, m->vertex_count, 12, "mesh ", i, "positions"))) return r;
        if (!all_finite((const float *)(v->data + m->positions), 3ull * m->vertex_count))
            return fail(v->err, MK_ERROR_NOT_FINITE, m->positions, "mesh ", i, ": base positions are not finite");
        if (m->flags & MK_MESH_HAS_NORMALS) {
            if ((r = check_array(v, m->normals, m->vertex_count, 12, "mesh ", i, "normals"))) return r;
            if (!all_finite((const float *)(v->data + m->normals), 3ull * m->vertex_count))
                return fail(v->err, MK_ERROR_NOT_FINITE, m->normals, "mesh ", i, ": base normals are not finite");
        }
        if (m->flags & MK_MESH_HAS_TANGENTS) {
            if ((r = check_array(v, m->tangents, m->vertex_count, 16, "mesh ", i, "tangents"))) return r;
            if (!all_finite((const float *)(v->data + m->tangents), 4ull * m->vertex_count))
                return fail(v->err, MK_ERROR_NOT_FINITE, m->tangents, "mesh ", i, ": base tangents are not finite");
        }
        if ((r = check_array(v, m->triangles, m->triangle_count, 12, "mesh ", i, "triangles"))) return r;
        const uint32_t *tri = (const uint32_t *)(v->data + m->triangles);
        for (uint64_t k = 0; k < 3ull * m->triangle_count; k++)
            if (tri[k] >= m->vertex_count)
                return fail(v->err, MK_ERROR_CORRUPT, m->triangles + 4 * k, "mesh ", i, ": triangle index out of range");
        if ((r = check_array(v, m->control_points, m->vertex_count, 4, "mesh ", i, "control points"))) return r;
        const uint32_t *cp = (const uint32_t *)(v->data + m->control_points);
        for (uint32_t k = 0; k < m->vertex_count; k++)
            if (cp[k] >= m->control_point_count)
                return fail(v->err, MK_ERROR_CORRUPT, m->control_points + 4ull * k, "mesh ", i,
                            ": control point index out of range");
    }
    if (next_channel != a->channel_count || next_target != a->target_count)
        return fail(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "meshes cover ", next_channel,
                    " channels; the channel or target table has entries no mesh owns");
    return MK_OK;
}

static mk_result validate_clips(validator *v, const mk_asset *a)
{
    for (uint32_t i = 0; i < a->clip_count; i++) {
        const mk_blob_clip *c = &a->clips[i];
        uint64_t at = (uint64_t)((const uint8_t *)c - v->data);
        if (!valid_string(a, c->name))
            return fail(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": name string out of range");
        /* Clips tile the track table in order, so every track is validated once. */
        uint32_t expected_track = i == 0 ? 0 : a->clips[i - 1].first_track + a->clips[i - 1].track_count;
        if (c->first_track != expected_track || c->track_count > a->track_count - c->first_track)
            return fail(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": track range does not follow the previous clip's");
        if (!isfinite(c->start) || !isfinite(c->duration) || c->duration < 0)
            return fail(v->err, MK_ERROR_NOT_FINITE, at, "clip ", i, ": start or duration is not finite or negative");
        if (!all_zero(c->reserved, 3))
            return fail(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": reserved fields are not zero");
    }
    uint32_t tracks_used = a->clip_count ? a->clips[a->clip_count - 1].first_track + a->clips[a->clip_count - 1].track_count : 0;
    if (tracks_used != a->track_count)
        return fail(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "clips cover ", tracks_used,
                    " tracks; the track table has tracks no clip owns");
    for (uint32_t i = 0; i < a->track_count; i++) {
        const mk_blob_track *t = &a->tracks[i];
        uint64_t at = (uint64_t)((const uint8_t *)t - v->data);
        if (t->channel >= a->channel_count)
            return fail(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": channel index out of range");
        if (t->reserved)
            return fail(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": reserved field is not zero");
        /* Tracks tile the key table in order, so every key is validated once (O(size)). */
        uint32_t expected_key = i == 0 ? 0 : a->tracks[i - 1].first_key + a->tracks[i - 1].key_count;
        if (t->key_count == 0 || t->first_key != expected_key || t->key_count > a->key_count - t->first_key)
            return fail(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": key range empty or not following the previous track's");
        for (uint32_t k = 0; k < t->key_count; k++) {
            const mk_key *key = &a->keys[t->first_key + k];
            uint64_t kat = (uint64_t)((const uint8_t *)key - v->data);
            if (!isfinite(key->time) || !isfinite(key->value) || !isfinite(key->right_slope)
                || !isfinite(key->left_slope) || !isfinite(key->right_weight) || !isfinite(key->left_weight))
                return fail(v->err, MK_ERROR_NOT_FINITE, kat, "key ", t->first_key + k, ": value is not finite");
            if (key->interp >= MK_INTERP_COUNT)
                return fail(v->err, MK_ERROR_CORRUPT, kat, "key ", t->first_key + k, ": unknown interpolation");
            if (key->reserved)
                return fail(v->err, MK_ERROR_CORRUPT, kat, "key ", t->first_key + k, ": reserved field is not zero");
            /* Bezier tangent weights must stay inside the interval so time is monotonic. */
            if (!(key->right_weight > 0 && key->right_weight <= 1 && key->left_weight > 0 && key->left_weight <= 1))
                return fail(v->err, MK_ERROR_CORRUPT, kat, "key ", t->first_key + k, ": tangent weight outside (0, 1]");
            if (k > 0 && !(key->time > key[-1].time))
                return fail(v->err, MK_ERROR_CORRUPT, kat, "key ", t->first_key + k, ": key times are not strictly increasing");
        }
    }
    uint32_t keys_used = a->track_count ? a->tracks[a->track_count - 1].first_key + a->tracks[a->track_count - 1].key_count : 0;
    if (keys_used != a->key_count)
        return fail(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "tracks cover ", keys_used, " keys; the key table has keys no track owns");
    return MK_OK;
}

mk_result mk_asset_open(const void *data, size_t size, mk_asset *out, mk_error *err)
{
    if (err) { err->code = MK_OK; err->offset = NO_OFFSET; err->message[0] = 0; }
    if (!out) return fail(err, MK_ERROR_INVALID_ARGUMENT, NO_OFFSET, "output asset is NULL", NO_INDEX, "");
    memset(out, 0, sizeof *out);
    if (!data) return fail(err, MK_ERROR_INVALID_ARGUMENT, NO_OFFSET, "blob pointer is NULL", NO_INDEX, "");
    if ((uintptr_t)data % MK_ALIGN)
        return fail(err, MK_ERROR_BAD_ALIGNMENT, NO_OFFSET, "blob memory is not 16-byte aligned", NO_INDEX, "");
    if (size < sizeof(mk_blob_header))
        return fail(err, MK_ERROR_TRUNCATED, size, "blob of ", size, " bytes is shorter than the 64-byte header");
    mk_asset a;
    memset(&a, 0, sizeof a);
    a.data = data;
    a.size = size;
    a.header = (const mk_blob_header *)data;
    if (memcmp(a.header->magic, MK_MAGIC, 8) != 0)
        return fail(err, MK_ERROR_BAD_MAGIC, 0, "not a .morph blob (magic is not MORPHKIT)", NO_INDEX, "");
    if (a.header->version != MK_FORMAT_VERSION)
        return fail_with(err, MK_ERROR_BAD_VERSION, 8, "blob format version ", a.header->version,
                         " is not supported; this runtime reads version ", MK_FORMAT_VERSION, "");
    if (a.header->header_size != sizeof(mk_blob_header) || a.header->flags != 0 || !all_zero(a.header->reserved, 6))
        return fail(err, MK_ERROR_CORRUPT, 12, "header size, flags or reserved fields", NO_INDEX,
                    " are not those of this version (64, 0, 0)");
    if (a.header->file_size != size)
        return fail(err, size < a.header->file_size ? MK_ERROR_TRUNCATED : MK_ERROR_CORRUPT, 16,
                    "blob is ", size, a.header->file_size > size ? " bytes, shorter than the header's file size"
                                                                 : " bytes, longer than the header's file size");
    if (mk_checksum((const uint8_t *)data + 32, size - 32) != a.header->checksum)
        return fail(err, MK_ERROR_BAD_CHECKSUM, 24, "checksum mismatch: the blob was modified or damaged", NO_INDEX, "");

    validator v = { (const uint8_t *)data, size, err };
    mk_result r;
    if ((r = validate_sections(&v, &a))) return r;
    if ((r = validate_meshes(&v, &a))) return r;
    if ((r = validate_channels_and_targets(&v, &a))) return r;
    for (uint32_t i = 0; i < a.mesh_count; i++)
        if ((r = validate_blocks(&v, &a, i))) return r;
    if ((r = validate_clips(&v, &a))) return r;
    *out = a;
    return MK_OK;
}

/* ---- queries ---- */

static const char *string_at(const mk_asset *a, uint32_t offset) { return a->strings + offset; }

uint32_t mk_version(void) { return MK_VERSION; }

int mk_is_blob(const void *data, size_t size)
{
    return data && size >= 8 && memcmp(data, MK_MAGIC, 8) == 0;
}

int mk_mesh_get(const mk_asset *a, uint32_t mesh, mk_mesh_info *out)
{
    if (!a || !out || mesh >= a->mesh_count) return 0;
    const mk_blob_mesh *m = &a->meshes[mesh];
    memset(out, 0, sizeof *out);
    out->name = string_at(a, m->name);
    out->vertex_count = m->vertex_count;
    out->control_point_count = m->control_point_count;
    out->triangle_count = m->triangle_count;
    out->first_channel = m->first_channel;
    out->channel_count = m->channel_count;
    out->target_count = m->target_count;
    out->target_bytes = m->target_data_size;
    out->entry_count = m->entry_count;
    out->stacking = (mk_stacking)m->stacking;
    out->has_normals = (m->flags & MK_MESH_HAS_NORMALS) != 0;
    out->has_tangents = (m->flags & MK_MESH_HAS_TANGENTS) != 0;
    out->gltf_node = m->gltf_node;
    out->gltf_mesh = m->gltf_mesh;
    out->gltf_primitive = m->gltf_primitive;
    out->world = m->world;
    out->positions = (const float *)(a->data + m->positions);
    out->normals = out->has_normals ? (const float *)(a->data + m->normals) : NULL;
    out->tangents = out->has_tangents ? (const float *)(a->data + m->tangents) : NULL;
    out->triangles = (const uint32_t *)(a->data + m->triangles);
    out->control_points = (const uint32_t *)(a->data + m->control_points);
    return 1;
}

int mk_channel_get(const mk_asset *a, uint32_t channel, mk_channel_info *out)
{
    if (!a || !out || channel >= a->channel_count) return 0;
    const mk_blob_channel *c = &a->channels[channel];
    out->name = string_at(a, c->name);
    out->origin = string_at(a, c->origin);
    out->mesh = c->mesh;
    out->target_count = c->target_count;
    out->default_weight = c->default_weight;
    return 1;
}

int mk_target_get(const mk_asset *a, uint32_t channel, uint32_t target, mk_target_info *out)
{
    if (!a || !out || channel >= a->channel_count || target >= a->channels[channel].target_count) return 0;
    const mk_blob_target *t = &a->targets[a->channels[channel].first_target + target];
    out->name = string_at(a, t->name);
    out->full_weight = t->full_weight;
    out->channel = t->channel;
    out->moved_vertices = t->moved_vertices;
    out->quantized = (t->flags & MK_TARGET_QUANTIZED) != 0;
    out->has_normals = (t->flags & MK_TARGET_HAS_NORMALS) != 0;
    out->has_tangents = (t->flags & MK_TARGET_HAS_TANGENTS) != 0;
    out->position_scale = t->position_scale;
    return 1;
}

int mk_clip_get(const mk_asset *a, uint32_t clip, mk_clip_info *out)
{
    if (!a || !out || clip >= a->clip_count) return 0;
    const mk_blob_clip *c = &a->clips[clip];
    out->name = string_at(a, c->name);
    out->start = c->start;
    out->duration = c->duration;
    out->track_count = c->track_count;
    return 1;
}

int mk_track_get(const mk_asset *a, uint32_t clip, uint32_t track, uint32_t *channel,
                 const mk_key **keys, uint32_t *key_count)
{
    if (!a || clip >= a->clip_count || track >= a->clips[clip].track_count) return 0;
    const mk_blob_track *t = &a->tracks[a->clips[clip].first_track + track];
    if (channel) *channel = t->channel;
    if (keys) *keys = &a->keys[t->first_key];
    if (key_count) *key_count = t->key_count;
    return 1;
}

int32_t mk_find_mesh(const mk_asset *a, const char *name)
{
    for (uint32_t i = 0; a && name && i < a->mesh_count; i++)
        if (strcmp(string_at(a, a->meshes[i].name), name) == 0) return (int32_t)i;
    return -1;
}

int32_t mk_find_channel(const mk_asset *a, const char *name)
{
    for (uint32_t i = 0; a && name && i < a->channel_count; i++)
        if (strcmp(string_at(a, a->channels[i].name), name) == 0) return (int32_t)i;
    return -1;
}

uint32_t mk_find_channels(const mk_asset *a, const char *name, uint32_t *out, uint32_t capacity)
{
    uint32_t n = 0;
    for (uint32_t i = 0; a && name && i < a->channel_count; i++)
        if (strcmp(string_at(a, a->channels[i].name), name) == 0) {
            if (out && n < capacity) out[n] = i;
            n++;
        }
    return n;
}

int32_t mk_find_clip(const mk_asset *a, const char *name)
{
    for (uint32_t i = 0; a && name && i < a->clip_count; i++)
        if (strcmp(string_at(a, a->clips[i].name), name) == 0) return (int32_t)i;
    return -1;
}

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
#include "error.h"

/* ---- named checks ----
 *
 * Every way mk_asset_open rejects its input is one check with a unique name, "area.rule". A
 * check is written `if (FAILS("area.rule", condition)) return fail...(...)`; the arrays checked
 * by check_array are named once per call site, CHECK_ARRAY("area.array", ...), which stands
 * for two checks, "area.array.align" and "area.array.bounds". Nothing else returns an error.
 *
 * In normal builds FAILS(name, condition) is just the condition. Test builds
 * (-DMK_OPEN_CHECK_IDS, tests/runtime/test_open_checks.c) record the name of the check that
 * rejected the last blob in mk_open_rejected_by, and can force one check's condition false
 * (mk_open_disabled_check) to prove that its test fails without it. That test reads this file,
 * lists every FAILS and CHECK_ARRAY name, and fails when one has no corruption test that trips
 * it, when a name is used twice, when a failure return is not guarded by FAILS, or when
 * docs/format.md does not list the name. */
#ifdef MK_OPEN_CHECK_IDS
extern const char *mk_open_rejected_by;
extern const char *mk_open_disabled_check;
const char *mk_open_rejected_by;
const char *mk_open_disabled_check;
static int check_fails(const char *name)
{
    if (mk_open_disabled_check && strcmp(name, mk_open_disabled_check) == 0) return 0;
    mk_open_rejected_by = name;
    return 1;
}
#define FAILS(name, condition) ((condition) && check_fails(name))
#else
#define FAILS(name, condition) (condition)
#endif

/* ---- error messages (runtime/error.h) ---- */

#define NONE UINT64_MAX            /* a number left out of a message */
#define NO_OFFSET MK_NO_OFFSET
#define say mk_error_text
#define say_u64 mk_error_number
#define start_message mk_error_start
#define end_message mk_error_end

/* Message "<s0><n0><s1><n1><s2><n2><s3>" (a number of NONE is left out), then
 * " (byte offset N)" when the offset is known. */
static mk_result fail3(mk_error *err, mk_result code, uint64_t offset, const char *s0, uint64_t n0, const char *s1,
                       uint64_t n1, const char *s2, uint64_t n2, const char *s3)
{
    start_message(err, code, offset);
    say(err, s0);
    if (n0 != NONE) say_u64(err, n0);
    say(err, s1);
    if (n1 != NONE) say_u64(err, n1);
    say(err, s2);
    if (n2 != NONE) say_u64(err, n2);
    say(err, s3);
    return end_message(err, code);
}

static mk_result fail2(mk_error *err, mk_result code, uint64_t offset, const char *s0, uint64_t n0, const char *s1,
                       uint64_t n1, const char *s2)
{
    return fail3(err, code, offset, s0, n0, s1, n1, s2, NONE, "");
}

static mk_result fail(mk_error *err, mk_result code, uint64_t offset, const char *s0, uint64_t n0, const char *s1)
{
    return fail3(err, code, offset, s0, n0, s1, NONE, "", NONE, "");
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

/* Where arrays may lie: the whole blob (sections) or the DATA section (mesh arrays). */
typedef struct region {
    uint64_t begin, end;
    const char *name;
    mk_result code;                /* of an array outside it */
} region;

typedef struct validator {
    const uint8_t *data;
    uint64_t size;
    mk_error *err;
    region blob, data_section;
} validator;

static const char *const kind_names[MK_SECTION_KIND_COUNT] = {
    "", " (STRINGS)", " (MESHES)", " (CHANNELS)", " (TARGETS)", " (CLIPS)", " (TRACKS)", " (KEYS)", " (DATA)",
};

/* The array [offset, offset + count * elem) must start 16-aligned and lie inside `in`
 * (overflow-safe). The message names the array: "<what><index><field>: ...". */
#define CHECK_ARRAY(name, ...) check_array(v, name ".align", name ".bounds", __VA_ARGS__)
static mk_result check_array(const validator *v, const char *align_check, const char *bounds_check, uint64_t offset,
                             uint64_t count, uint64_t elem, const region *in, const char *what, uint64_t index,
                             const char *field)
{
    (void)align_check;             /* used by FAILS in test builds only */
    (void)bounds_check;
    if (FAILS(align_check, offset % MK_ALIGN != 0)) {
        start_message(v->err, MK_ERROR_BAD_ALIGNMENT, offset);
        say(v->err, what);
        say_u64(v->err, index);
        say(v->err, field);
        say(v->err, ": array is not 16-byte aligned");
        return end_message(v->err, MK_ERROR_BAD_ALIGNMENT);
    }
    if (FAILS(bounds_check, offset < in->begin || offset > in->end || (elem && count > (in->end - offset) / elem))) {
        start_message(v->err, in->code, offset);
        say(v->err, what);
        say_u64(v->err, index);
        say(v->err, field);
        say(v->err, ": array of ");
        say_u64(v->err, count);
        say(v->err, " x ");
        say_u64(v->err, elem);
        say(v->err, " bytes is not inside ");
        say(v->err, in->name);
        say(v->err, " [");
        say_u64(v->err, in->begin);
        say(v->err, ", ");
        say_u64(v->err, in->end);
        say(v->err, ")");
        return end_message(v->err, in->code);
    }
    return MK_OK;
}

/* Index of the first element of p[0..n) that is not finite, or n. */
static uint64_t first_not_finite(const float *p, uint64_t n)
{
    for (uint64_t i = 0; i < n; i++)
        if (!isfinite(p[i])) return i;
    return n;
}

static int valid_string(const mk_asset *a, uint32_t offset) { return offset < a->strings_size; }

/* Index of the first nonzero element of p[0..n) (reserved fields must be zero, so a later
 * version can give them a meaning), or n. */
static size_t first_nonzero(const uint32_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i]) return i;
    return n;
}

/* Index of the first nonzero byte of p[0..n), or n. */
static uint64_t first_nonzero_byte(const uint8_t *p, uint64_t n)
{
    for (uint64_t i = 0; i < n; i++)
        if (p[i]) return i;
    return n;
}

static uint64_t offset_of(const validator *v, const void *p) { return (uint64_t)((const uint8_t *)p - v->data); }

static mk_result validate_sections(validator *v, mk_asset *a)
{
    const mk_blob_header *h = a->header;
    const uint64_t table = sizeof(mk_blob_header);
    if (FAILS("section.table", (uint64_t)h->section_count > (v->size - table) / sizeof(mk_blob_section)))
        return fail(v->err, MK_ERROR_TRUNCATED, table, "section table of ", h->section_count,
                    " sections extends past the end of the blob");
    static const uint32_t element_sizes[MK_SECTION_KIND_COUNT] = {
        0, 1, sizeof(mk_blob_mesh), sizeof(mk_blob_channel), sizeof(mk_blob_target),
        sizeof(mk_blob_clip), sizeof(mk_blob_track), sizeof(mk_key), 1,
    };
    const mk_blob_section *sections = (const mk_blob_section *)(v->data + table);
    const mk_blob_section *found[MK_SECTION_KIND_COUNT] = { 0 };
    uint32_t found_at[MK_SECTION_KIND_COUNT] = { 0 };
    for (uint32_t i = 0; i < h->section_count; i++) {
        const mk_blob_section *s = &sections[i];
        uint64_t at = table + (uint64_t)i * sizeof(mk_blob_section);
        if (FAILS("section.kind", s->kind == 0 || s->kind >= MK_SECTION_KIND_COUNT))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "section ", i, ": unknown kind ", s->kind, "");
        const char *kind = kind_names[s->kind];
        if (FAILS("section.duplicate", found[s->kind] != NULL))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "section ", i, kind, NONE, ": kind appears twice (also section ",
                         found_at[s->kind], ")");
        if (FAILS("section.element_size", s->element_size != element_sizes[s->kind]))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "section ", i, kind, NONE, ": element size ", s->element_size,
                         " is wrong for its kind");
        if (FAILS("section.size", s->count > UINT64_MAX / s->element_size || s->size != s->count * s->element_size))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "section ", i, kind, NONE, ": size ", s->size,
                         " is not count x element size");
        if (FAILS("section.count", s->kind != MK_SECTION_STRINGS && s->kind != MK_SECTION_DATA && s->count > UINT32_MAX))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "section ", i, kind, NONE, ": more than 2^32 elements");
        mk_result r = CHECK_ARRAY("section", s->offset, s->count, s->element_size, &v->blob, "section ", i, kind);
        if (r) return r;
        found[s->kind] = s;
        found_at[s->kind] = i;
    }
    for (uint32_t k = 1; k < MK_SECTION_KIND_COUNT; k++)
        if (FAILS("section.missing", found[k] == NULL))
            return fail2(v->err, MK_ERROR_CORRUPT, table, "required section kind ", k, kind_names[k], NONE, " is missing");
    /* Sections never overlap each other or the header and section table (empty ones lie
     * anywhere). */
    const uint64_t table_end = table + (uint64_t)h->section_count * sizeof(mk_blob_section);
    for (uint32_t k = 1; k < MK_SECTION_KIND_COUNT; k++) {
        const mk_blob_section *s = found[k];
        if (FAILS("section.overlaps_table", s->size && s->offset < table_end))
            return fail3(v->err, MK_ERROR_CORRUPT, s->offset, "section ", found_at[k], kind_names[k], NONE,
                         ": overlaps the header and section table, which end at byte ", table_end, "");
        for (uint32_t j = k + 1; j < MK_SECTION_KIND_COUNT; j++) {
            const mk_blob_section *t = found[j];
            if (FAILS("section.overlap", s->size && t->size && s->offset < t->offset + t->size && t->offset < s->offset + s->size)) {
                start_message(v->err, MK_ERROR_CORRUPT, t->offset);
                say(v->err, "section ");
                say_u64(v->err, found_at[j]);
                say(v->err, kind_names[j]);
                say(v->err, " overlaps section ");
                say_u64(v->err, found_at[k]);
                say(v->err, kind_names[k]);
                return end_message(v->err, MK_ERROR_CORRUPT);
            }
        }
    }

    a->strings = (const char *)(v->data + found[MK_SECTION_STRINGS]->offset);
    a->strings_size = found[MK_SECTION_STRINGS]->size;
    if (FAILS("strings.leading_nul", a->strings_size == 0 || a->strings[0] != 0))
        return fail(v->err, MK_ERROR_CORRUPT, found[MK_SECTION_STRINGS]->offset, "string section", NONE,
                    " does not start with a NUL byte (string offset 0 is the empty string)");
    if (FAILS("strings.trailing_nul", a->strings[a->strings_size - 1] != 0))
        return fail(v->err, MK_ERROR_CORRUPT, found[MK_SECTION_STRINGS]->offset + a->strings_size - 1, "string section",
                    NONE, " does not end with a NUL byte: its last string is unterminated");
    v->data_section.begin = found[MK_SECTION_DATA]->offset;
    v->data_section.end = found[MK_SECTION_DATA]->offset + found[MK_SECTION_DATA]->size;
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

static mk_result validate_meshes(validator *v, const mk_asset *a)
{
    uint32_t next_channel = 0, next_target = 0;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const mk_blob_mesh *m = &a->meshes[i];
        uint64_t at = offset_of(v, m);
        mk_result r;
        if (FAILS("mesh.name", !valid_string(a, m->name)))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": name string offset ", m->name, " is out of range");
        if (FAILS("mesh.vertex_count_zero", m->vertex_count == 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": has no vertices");
        if (FAILS("mesh.vertex_count_max", m->vertex_count > MK_MAX_VERTICES))   /* block arithmetic in eval stays in uint32 */
            return fail2(v->err, MK_ERROR_UNSUPPORTED, at, "mesh ", i, ": has ", m->vertex_count,
                         " vertices, more than a mesh may have (2^32 - 64)");
        if (FAILS("mesh.block_count", (uint64_t)m->block_count != ((uint64_t)m->vertex_count + MK_BLOCK_SIZE - 1) / MK_BLOCK_SIZE))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": block count ", m->block_count,
                         " does not match its ", m->vertex_count, " vertices");
        /* Meshes own consecutive channel and target ranges, in order. */
        if (FAILS("mesh.first_channel", m->first_channel != next_channel))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": first channel ", m->first_channel,
                         " does not follow the previous mesh's channels (expected ", next_channel, ")");
        if (FAILS("mesh.channel_count", m->channel_count > a->channel_count - next_channel))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": its ", m->channel_count,
                         " channels run past the end of the channel table (", a->channel_count, " channels)");
        if (FAILS("mesh.first_target", m->first_target != next_target))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": first target ", m->first_target,
                         " does not follow the previous mesh's targets (expected ", next_target, ")");
        if (FAILS("mesh.target_count_max", m->target_count > MK_MAX_MESH_TARGETS))   /* an entry holds 24 bits */
            return fail2(v->err, MK_ERROR_UNSUPPORTED, at, "mesh ", i, ": has ", m->target_count,
                         " targets, more than a mesh may have (2^24)");
        if (FAILS("mesh.target_count", m->target_count > a->target_count - next_target))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": its ", m->target_count,
                         " targets run past the end of the target table (", a->target_count, " targets)");
        next_channel += m->channel_count;
        next_target += m->target_count;
        if (FAILS("mesh.stacking", m->stacking != MK_STACKING_ADDITIVE && m->stacking != MK_STACKING_SEQUENTIAL))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": unknown stacking mode ", m->stacking, "");
        if (FAILS("mesh.flags", (m->flags & ~3u) != 0))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": unknown flags (", m->flags, ")");
        size_t reserved = first_nonzero(m->reserved, 2);
        if (FAILS("mesh.reserved", reserved < 2))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "mesh ", i, ": reserved field ", reserved, " is not zero");
        if (FAILS("mesh.normals_offset", !(m->flags & MK_MESH_HAS_NORMALS) && m->normals != 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i,
                        ": normals offset is set but the mesh's flags say it has no normals");
        if (FAILS("mesh.tangents_offset", !(m->flags & MK_MESH_HAS_TANGENTS) && m->tangents != 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "mesh ", i,
                        ": tangents offset is set but the mesh's flags say it has no tangents");
        uint64_t bad = first_not_finite(m->world, 16);
        if (FAILS("mesh.world", bad < 16))
            return fail2(v->err, MK_ERROR_NOT_FINITE, at, "mesh ", i, ": world transform element ", bad, " is not finite");
        if ((r = CHECK_ARRAY("mesh.positions", m->positions, m->vertex_count, 12, &v->data_section, "mesh ", i, " positions")))
            return r;
        bad = first_not_finite((const float *)(v->data + m->positions), 3ull * m->vertex_count);
        if (FAILS("mesh.positions_finite", bad < 3ull * m->vertex_count))
            return fail2(v->err, MK_ERROR_NOT_FINITE, m->positions + 4 * bad, "mesh ", i, ": base position of vertex ",
                         bad / 3, " is not finite");
        if (m->flags & MK_MESH_HAS_NORMALS) {
            if ((r = CHECK_ARRAY("mesh.normals", m->normals, m->vertex_count, 12, &v->data_section, "mesh ", i, " normals")))
                return r;
            bad = first_not_finite((const float *)(v->data + m->normals), 3ull * m->vertex_count);
            if (FAILS("mesh.normals_finite", bad < 3ull * m->vertex_count))
                return fail2(v->err, MK_ERROR_NOT_FINITE, m->normals + 4 * bad, "mesh ", i, ": base normal of vertex ",
                             bad / 3, " is not finite");
        }
        if (m->flags & MK_MESH_HAS_TANGENTS) {
            if ((r = CHECK_ARRAY("mesh.tangents", m->tangents, m->vertex_count, 16, &v->data_section, "mesh ", i, " tangents")))
                return r;
            bad = first_not_finite((const float *)(v->data + m->tangents), 4ull * m->vertex_count);
            if (FAILS("mesh.tangents_finite", bad < 4ull * m->vertex_count))
                return fail2(v->err, MK_ERROR_NOT_FINITE, m->tangents + 4 * bad, "mesh ", i, ": base tangent of vertex ",
                             bad / 4, " is not finite");
        }
        if ((r = CHECK_ARRAY("mesh.triangles", m->triangles, m->triangle_count, 12, &v->data_section, "mesh ", i, " triangles")))
            return r;
        const uint32_t *tri = (const uint32_t *)(v->data + m->triangles);
        for (uint64_t k = 0; k < 3ull * m->triangle_count; k++)
            if (FAILS("mesh.triangle_index", tri[k] >= m->vertex_count))
                return fail3(v->err, MK_ERROR_CORRUPT, m->triangles + 4 * k, "mesh ", i, ": triangle ", k / 3,
                             " has vertex index ", tri[k], " out of range");
        if ((r = CHECK_ARRAY("mesh.control_points", m->control_points, m->vertex_count, 4, &v->data_section, "mesh ", i,
                             " control points")))
            return r;
        const uint32_t *cp = (const uint32_t *)(v->data + m->control_points);
        for (uint32_t k = 0; k < m->vertex_count; k++)
            if (FAILS("mesh.control_point_index", cp[k] >= m->control_point_count))
                return fail3(v->err, MK_ERROR_CORRUPT, m->control_points + 4ull * k, "mesh ", i, ": vertex ", k,
                             " has control point ", cp[k], " out of range");
    }
    if (FAILS("meshes.channels_owned", next_channel != a->channel_count))
        return fail2(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "meshes own ", next_channel, " of the ", a->channel_count,
                     " channels; the others belong to no mesh");
    if (FAILS("meshes.targets_owned", next_target != a->target_count))
        return fail2(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "meshes own ", next_target, " of the ", a->target_count,
                     " targets; the others belong to no mesh");
    return MK_OK;
}

static mk_result validate_channels_and_targets(validator *v, const mk_asset *a)
{
    for (uint32_t c = 0; c < a->channel_count; c++) {
        const mk_blob_channel *ch = &a->channels[c];
        uint64_t at = offset_of(v, ch);
        if (FAILS("channel.name", !valid_string(a, ch->name)))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": name string offset ", ch->name, " is out of range");
        if (FAILS("channel.origin", !valid_string(a, ch->origin)))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": origin string offset ", ch->origin, " is out of range");
        if (FAILS("channel.mesh", ch->mesh >= a->mesh_count))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": mesh index ", ch->mesh, " is out of range");
        const mk_blob_mesh *m = &a->meshes[ch->mesh];
        if (FAILS("channel.outside_mesh", c < m->first_channel || c - m->first_channel >= m->channel_count))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": is not one of mesh ", ch->mesh, "'s channels");
        if (FAILS("channel.target_count", ch->target_count == 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": has no targets");
        if (FAILS("channel.target_range", ch->first_target > a->target_count || ch->target_count > a->target_count - ch->first_target))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": its ", ch->target_count, " targets from ",
                         ch->first_target, " run past the end of the target table");
        if (FAILS("channel.targets_outside_mesh", ch->first_target < m->first_target
                  || ch->first_target + ch->target_count > m->first_target + m->target_count))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": its targets are not inside mesh ", ch->mesh, "'s targets");
        /* Channels tile their mesh's targets in order: the first starts at the mesh's first
         * target, each next one where the previous ended. */
        uint32_t expected = c == m->first_channel ? m->first_target
                          : a->channels[c - 1].first_target + a->channels[c - 1].target_count;
        if (FAILS("channel.targets_order", ch->first_target != expected))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": first target ", ch->first_target,
                         " does not follow the previous channel's targets (expected ", expected, ")");
        if (FAILS("channel.default_weight", !isfinite(ch->default_weight)))
            return fail(v->err, MK_ERROR_NOT_FINITE, at, "channel ", c, ": default weight is not finite");
        size_t reserved = first_nonzero(ch->reserved, 2);
        if (FAILS("channel.reserved", reserved < 2))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "channel ", c, ": reserved field ", reserved, " is not zero");
        for (uint32_t k = 0; k < ch->target_count; k++) {
            uint32_t t = ch->first_target + k;
            const mk_blob_target *tg = &a->targets[t];
            uint64_t tat = offset_of(v, tg);
            if (FAILS("target.channel", tg->channel != c))
                return fail3(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": channel index ", tg->channel,
                             " does not match its channel ", c, "");
            if (FAILS("target.name", !valid_string(a, tg->name)))
                return fail2(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": name string offset ", tg->name, " is out of range");
            if (FAILS("target.full_weight_finite", !isfinite(tg->full_weight)))
                return fail(v->err, MK_ERROR_NOT_FINITE, tat, "target ", t, ": full weight is not finite");
            if (FAILS("target.full_weight_zero", fabsf(tg->full_weight) < MK_MIN_FULL_WEIGHT_GAP))
                return fail(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": full weight is zero or nearly (|f| < 1e-6)");
            if (FAILS("target.full_weight_order", k > 0 && !(tg->full_weight - a->targets[t - 1].full_weight >= MK_MIN_FULL_WEIGHT_GAP)))
                return fail2(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": full weight does not exceed target ", t - 1,
                             "'s by at least 1e-6 (a channel's full weights increase)");
            if (FAILS("target.flags", (tg->flags & ~7u) != 0))
                return fail2(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": unknown flags (", tg->flags, ")");
            if (FAILS("target.normals", (tg->flags & MK_TARGET_HAS_NORMALS) && !(m->flags & MK_MESH_HAS_NORMALS)))
                return fail2(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": has normal deltas but its mesh ", ch->mesh,
                             " has no base normals");
            if (FAILS("target.tangents", (tg->flags & MK_TARGET_HAS_TANGENTS) && !(m->flags & MK_MESH_HAS_TANGENTS)))
                return fail2(v->err, MK_ERROR_CORRUPT, tat, "target ", t, ": has tangent deltas but its mesh ", ch->mesh,
                             " has no base tangents");
            const float scales[3] = { tg->position_scale, tg->normal_scale, tg->tangent_scale };
            static const char *const scale_names[3] = { ": position scale", ": normal scale", ": tangent scale" };
            for (int s = 0; s < 3; s++) {
                if (FAILS("target.scale_finite", !isfinite(scales[s])))
                    return fail2(v->err, MK_ERROR_NOT_FINITE, tat, "target ", t, scale_names[s], NONE, " is not finite");
                if (FAILS("target.scale_negative", scales[s] < 0))
                    return fail2(v->err, MK_ERROR_CORRUPT, tat, "target ", t, scale_names[s], NONE, " is negative");
            }
        }
    }
    /* Channels must tile each mesh's targets completely (no target without a channel). */
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        const mk_blob_mesh *m = &a->meshes[i];
        uint32_t end = m->channel_count ? a->channels[m->first_channel + m->channel_count - 1].first_target
                                            + a->channels[m->first_channel + m->channel_count - 1].target_count
                                        : m->first_target;
        if (FAILS("mesh.targets_without_channel", end != m->first_target + m->target_count))
            return fail3(v->err, MK_ERROR_CORRUPT, offset_of(v, m), "mesh ", i, ": its channels end at target ", end,
                         ", before its targets end at ", m->first_target + m->target_count, "");
    }
    return MK_OK;
}

/* The first component of an entry that belongs to an attribute of the mesh its target lacks
 * and still has a width code or offset, or the mesh's component count. Such a component stores
 * nothing: a nonzero code would move the later components' data away from where
 * mk_entry_bytes (which counts the target's attributes only) says it ends. */
static uint32_t first_absent_component(const mk_blob_entry *en, uint32_t mesh_flags, uint32_t target_flags)
{
    const uint32_t components = mk_mesh_components(mesh_flags);
    static const uint32_t mesh_has[3] = { 0, MK_MESH_HAS_NORMALS, MK_MESH_HAS_TANGENTS };
    static const uint32_t target_has[3] = { 0, MK_TARGET_HAS_NORMALS, MK_TARGET_HAS_TANGENTS };
    for (uint32_t attribute = 1; attribute < 3; attribute++) {
        if (!(mesh_flags & mesh_has[attribute]) || (target_flags & target_has[attribute])) continue;
        const uint32_t k0 = mk_attribute_component(mesh_flags, attribute);
        for (uint32_t k = k0; k < k0 + 3; k++)
            if (mk_entry_code(en, k) != 0 || mk_entry_offset(en, components, k) != 0) return k;
    }
    return components;
}

/* A WIDE entry's int32 position offset at p is within +-MK_WIDE_OFFSET_MAX, so offset + value
 * stays exact in float32 and cannot overflow int32. */
static int wide_offset_ok(const uint8_t *p)
{
    const int32_t o = (int32_t)mk_load_u32le(p);
    return o >= -MK_WIDE_OFFSET_MAX && o <= MK_WIDE_OFFSET_MAX;
}

/* Checks the block table, entries and delta data of one mesh. */
static mk_result validate_blocks(validator *v, const mk_asset *a, uint32_t mi)
{
    const mk_blob_mesh *m = &a->meshes[mi];
    mk_result r;
    if ((r = CHECK_ARRAY("mesh.block_table", m->block_entries, (uint64_t)m->block_count + 1, 4, &v->data_section, "mesh ",
                         mi, " block table")))
        return r;
    const uint32_t stride = mk_entry_stride(m->flags), components = mk_mesh_components(m->flags);
    const uint32_t code_bytes = mk_entry_code_bytes(components);
    if ((r = CHECK_ARRAY("mesh.entries", m->entries, m->entry_count, stride, &v->data_section, "mesh ", mi,
                         " entries")))
        return r;
    if ((r = CHECK_ARRAY("mesh.target_data", m->target_data, m->target_data_size, 1, &v->data_section, "mesh ", mi,
                         " target data")))
        return r;
    const uint32_t *first = (const uint32_t *)(v->data + m->block_entries);
    const uint8_t *entries = v->data + m->entries;
    if (FAILS("block_table.first", first[0] != 0))
        return fail2(v->err, MK_ERROR_CORRUPT, m->block_entries, "mesh ", mi, ": block table starts at entry ", first[0],
                     " instead of 0");
    if (FAILS("block_table.last", first[m->block_count] != m->entry_count))
        return fail3(v->err, MK_ERROR_CORRUPT, m->block_entries + 4ull * m->block_count, "mesh ", mi,
                     ": block table ends at entry ", first[m->block_count], " instead of the entry count ", m->entry_count, "");
    /* The whole table first: non-decreasing (so every value is <= entry_count) before any
     * block's entries are read. */
    for (uint32_t b = 0; b < m->block_count; b++)
        if (FAILS("block_table.order", first[b + 1] < first[b]))
            return fail3(v->err, MK_ERROR_CORRUPT, m->block_entries + 4ull * (b + 1), "mesh ", mi, ": block table decreases at block ",
                         b + 1, " (entry ", first[b + 1], " after a later one)");
    for (uint32_t b = 0; b < m->block_count; b++) {
        uint32_t in_block = m->vertex_count - b * MK_BLOCK_SIZE;
        if (in_block > MK_BLOCK_SIZE) in_block = MK_BLOCK_SIZE;
        uint64_t allowed = in_block == 64 ? ~0ull : ((1ull << in_block) - 1);
        for (uint32_t e = first[b]; e < first[b + 1]; e++) {
            const mk_blob_entry *en = mk_entry_at(entries, stride, e);
            uint64_t at = m->entries + (uint64_t)e * stride;
            const uint32_t target = mk_entry_target(en);
            if (FAILS("entry.flags", (en->target_and_flags & ~(MK_ENTRY_TARGET_MASK | MK_ENTRY_FLAGS_KNOWN)) != 0))
                return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": unknown flag bits ",
                             en->target_and_flags & ~(MK_ENTRY_TARGET_MASK | MK_ENTRY_FLAGS_KNOWN), "");
            if (FAILS("entry.target", target >= m->target_count))
                return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": target index ", target,
                             " is out of range");
            if (FAILS("entry.order", e > first[b] && target <= mk_entry_target(mk_entry_at(entries, stride, e - 1))))
                return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": target ", target,
                             " repeats or precedes the previous entry's (a block's targets strictly increase)");
            if (FAILS("entry.mask_empty", en->mask == 0))
                return fail2(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": vertex mask is empty");
            if (FAILS("entry.mask_past_end", (en->mask & ~allowed) != 0))
                return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": vertex mask has bits past the mesh's last vertex (block ",
                             b, ")");
            const mk_blob_target *tg = &a->targets[m->first_target + target];
            if (FAILS("entry.precision", mk_entry_packed(en) && !(tg->flags & MK_TARGET_QUANTIZED)))
                return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": packed data for float target ", target,
                             "");
            if (FAILS("entry.wide_precision", mk_entry_wide(en) && !mk_entry_packed(en)))
                return fail2(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e,
                             ": WIDE on float32 data (only packed entries have int32 position offsets)");
            /* The packing (width codes, then offsets) must say exactly what the data holds, so
             * that every decoder finds the same bytes: zero where nothing is stored. */
            const uint8_t *codes = (const uint8_t *)en + MK_ENTRY_HEAD;
            const uint64_t codes_at = at + MK_ENTRY_HEAD, offsets_at = codes_at + code_bytes;
            uint64_t stray = first_nonzero_byte(codes, stride - MK_ENTRY_HEAD);
            if (FAILS("entry.float_packing", !mk_entry_packed(en) && stray < stride - MK_ENTRY_HEAD))
                return fail2(v->err, MK_ERROR_CORRUPT, codes_at + stray, "mesh ", mi, " entry ", e,
                             ": float32 entry has a nonzero width code or offset");
            uint32_t nibble = components;
            while (nibble < 2 * code_bytes && mk_entry_code(en, nibble) == 0) nibble++;   /* the codes' padding */
            if (FAILS("entry.code_padding", nibble < 2 * code_bytes))
                return fail3(v->err, MK_ERROR_CORRUPT, codes_at + nibble / 2, "mesh ", mi, " entry ", e, ": width code ",
                             nibble, " is not zero (it pads the codes past the mesh's last component)");
            const uint32_t absent = first_absent_component(en, m->flags, tg->flags);
            const int absent_tangent = (m->flags & MK_MESH_HAS_TANGENTS) && absent >= mk_attribute_component(m->flags, 2);
            if (FAILS("entry.absent_attribute", absent < components))
                return fail3(v->err, MK_ERROR_CORRUPT, mk_entry_code(en, absent) ? codes_at + absent / 2 : offsets_at + 2ull * absent,
                             "mesh ", mi, " entry ", e, ": component ", absent,
                             absent_tangent ? " has a width code or offset but its target has no tangent deltas"
                                            : " has a width code or offset but its target has no normal deltas");
            uint32_t head = 0;
            while (head < 3 && mk_entry_offset(en, components, head) == 0) head++;
            if (FAILS("entry.wide_head", mk_entry_wide(en) && head < 3))
                return fail3(v->err, MK_ERROR_CORRUPT, offsets_at + 2ull * head, "mesh ", mi, " entry ", e, ": WIDE entry's head position offset ",
                             head, " is not zero (its offsets are the int32 ones in its data)");
            uint64_t bytes = mk_entry_bytes(en, m->flags, tg->flags);
            uint64_t offset = (uint64_t)en->data * MK_DATA_UNIT;   /* no overflow: at most 2^34 */
            /* The tail lets decoders load 16 bytes at any byte of the data. */
            if (FAILS("entry.data", offset > m->target_data_size || bytes + MK_TARGET_DATA_TAIL > m->target_data_size - offset))
                return fail3(v->err, MK_ERROR_CORRUPT, at, "mesh ", mi, " entry ", e, ": its ", bytes,
                             " bytes of data and the 16-byte tail run past the mesh's target data");
            const uint8_t *d = v->data + m->target_data + offset;
            uint32_t wide = 0;
            while (mk_entry_wide(en) && wide < 3 && wide_offset_ok(d + 4 * wide)) wide++;
            if (FAILS("entry.wide_range", mk_entry_wide(en) && wide < 3))
                return fail3(v->err, MK_ERROR_CORRUPT, m->target_data + offset + 4ull * wide, "mesh ", mi, " entry ", e,
                             ": WIDE position offset ", wide, " is beyond +-8388607 (2^23 - 1)");
            if (mk_entry_packed(en)) continue;   /* packed values are finite */
            uint64_t bad = first_not_finite((const float *)(const void *)d, bytes / 4);
            if (FAILS("entry.data_finite", bad < bytes / 4))
                return fail3(v->err, MK_ERROR_NOT_FINITE, m->target_data + offset + 4 * bad, "mesh ", mi, " entry ", e,
                             ": delta value ", bad, " is not finite");
        }
    }
    return MK_OK;
}

static mk_result validate_clips(validator *v, const mk_asset *a)
{
    for (uint32_t i = 0; i < a->clip_count; i++) {
        const mk_blob_clip *c = &a->clips[i];
        uint64_t at = offset_of(v, c);
        if (FAILS("clip.name", !valid_string(a, c->name)))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": name string offset ", c->name, " is out of range");
        /* Clips tile the track table in order, so every track is validated once. */
        uint32_t expected = i == 0 ? 0 : a->clips[i - 1].first_track + a->clips[i - 1].track_count;
        if (FAILS("clip.first_track", c->first_track != expected))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": first track ", c->first_track,
                         " does not follow the previous clip's tracks (expected ", expected, ")");
        if (FAILS("clip.track_count", c->track_count > a->track_count - c->first_track))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": its ", c->track_count,
                         " tracks run past the end of the track table (", a->track_count, " tracks)");
        if (FAILS("clip.start", !isfinite(c->start)))
            return fail(v->err, MK_ERROR_NOT_FINITE, at, "clip ", i, ": start is not finite");
        if (FAILS("clip.duration_finite", !isfinite(c->duration)))
            return fail(v->err, MK_ERROR_NOT_FINITE, at, "clip ", i, ": duration is not finite");
        if (FAILS("clip.duration_negative", c->duration < 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": duration is negative");
        size_t reserved = first_nonzero(c->reserved, 3);
        if (FAILS("clip.reserved", reserved < 3))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "clip ", i, ": reserved field ", reserved, " is not zero");
    }
    uint32_t tracks_used = a->clip_count ? a->clips[a->clip_count - 1].first_track + a->clips[a->clip_count - 1].track_count : 0;
    if (FAILS("clips.tracks_owned", tracks_used != a->track_count))
        return fail2(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "clips own ", tracks_used, " of the ", a->track_count,
                     " tracks; the others belong to no clip");
    static const char *const key_fields[6] = {
        ": time", ": value", ": right slope", ": right tangent weight", ": left slope", ": left tangent weight",
    };
    for (uint32_t i = 0; i < a->track_count; i++) {
        const mk_blob_track *t = &a->tracks[i];
        uint64_t at = offset_of(v, t);
        if (FAILS("track.channel", t->channel >= a->channel_count))
            return fail2(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": channel index ", t->channel, " is out of range");
        if (FAILS("track.reserved", t->reserved != 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": reserved field is not zero");
        /* Tracks tile the key table in order, so every key is validated once (O(size)). */
        if (FAILS("track.key_count", t->key_count == 0))
            return fail(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": has no keys");
        uint32_t expected = i == 0 ? 0 : a->tracks[i - 1].first_key + a->tracks[i - 1].key_count;
        if (FAILS("track.first_key", t->first_key != expected))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": first key ", t->first_key,
                         " does not follow the previous track's keys (expected ", expected, ")");
        if (FAILS("track.key_range", t->key_count > a->key_count - t->first_key))
            return fail3(v->err, MK_ERROR_CORRUPT, at, "track ", i, ": its ", t->key_count,
                         " keys run past the end of the key table (", a->key_count, " keys)");
        for (uint32_t k = 0; k < t->key_count; k++) {
            const mk_key *key = &a->keys[t->first_key + k];
            uint64_t kat = offset_of(v, key);
            const float fields[6] = { key->time, key->value, key->right_slope, key->right_weight, key->left_slope,
                                      key->left_weight };
            uint64_t bad = first_not_finite(fields, 6);
            if (FAILS("key.finite", bad < 6))
                return fail3(v->err, MK_ERROR_NOT_FINITE, kat, "track ", i, " key ", k, key_fields[bad], NONE, " is not finite");
            if (FAILS("key.interp", key->interp >= MK_INTERP_COUNT))
                return fail3(v->err, MK_ERROR_CORRUPT, kat, "track ", i, " key ", k, ": unknown interpolation ", key->interp, "");
            if (FAILS("key.reserved", key->reserved != 0))
                return fail2(v->err, MK_ERROR_CORRUPT, kat, "track ", i, " key ", k, ": reserved field is not zero");
            /* Bezier tangent weights must stay inside the interval so time is monotonic. */
            int weight = !(key->right_weight > 0 && key->right_weight <= 1) ? 3 : !(key->left_weight > 0 && key->left_weight <= 1) ? 5 : 0;
            if (FAILS("key.tangent_weight", weight != 0))
                return fail3(v->err, MK_ERROR_CORRUPT, kat, "track ", i, " key ", k, key_fields[weight], NONE,
                             " is outside (0, 1]");
            if (FAILS("key.time_order", k > 0 && !(key->time > key[-1].time)))
                return fail2(v->err, MK_ERROR_CORRUPT, kat, "track ", i, " key ", k,
                             ": time is not after the previous key's (times strictly increase)");
        }
    }
    uint32_t keys_used = a->track_count ? a->tracks[a->track_count - 1].first_key + a->tracks[a->track_count - 1].key_count : 0;
    if (FAILS("tracks.keys_owned", keys_used != a->key_count))
        return fail2(v->err, MK_ERROR_CORRUPT, NO_OFFSET, "tracks own ", keys_used, " of the ", a->key_count,
                     " keys; the others belong to no track");
    return MK_OK;
}

mk_result mk_asset_open(const void *data, size_t size, mk_asset *out, mk_error *err)
{
    if (err) { err->code = MK_OK; err->offset = NO_OFFSET; err->message[0] = 0; }
    if (FAILS("args.output", out == NULL))
        return fail(err, MK_ERROR_INVALID_ARGUMENT, NO_OFFSET, "output asset is NULL", NONE, "");
    memset(out, 0, sizeof *out);
    if (FAILS("args.data", data == NULL))
        return fail(err, MK_ERROR_INVALID_ARGUMENT, NO_OFFSET, "blob pointer is NULL", NONE, "");
    if (FAILS("blob.alignment", (uintptr_t)data % MK_ALIGN != 0))
        return fail(err, MK_ERROR_BAD_ALIGNMENT, NO_OFFSET, "blob memory is not 16-byte aligned", NONE, "");
    if (FAILS("header.truncated", size < sizeof(mk_blob_header)))
        return fail(err, MK_ERROR_TRUNCATED, size, "blob of ", size, " bytes is shorter than the 64-byte header");
    mk_asset a;
    memset(&a, 0, sizeof a);
    a.data = data;
    a.size = size;
    a.header = (const mk_blob_header *)data;
    const mk_blob_header *h = a.header;
    if (FAILS("header.magic", memcmp(h->magic, MK_MAGIC, 8) != 0))
        return fail(err, MK_ERROR_BAD_MAGIC, 0, "not a .morph blob (magic is not MORPHKIT)", NONE, "");
    /* Versions 2-4 are this format's earlier layouts, which the tools wrote from sources:
     * the message says how to get a current blob. */
    const char *older = h->version >= 2 && h->version < MK_FORMAT_VERSION
                      ? ": the format is older, re-import the source with this version's tools" : "";
    if (FAILS("header.version", h->version != MK_FORMAT_VERSION))
        return fail2(err, MK_ERROR_BAD_VERSION, 8, "blob format version ", h->version,
                     " is not supported; this runtime reads version ", MK_FORMAT_VERSION, older);
    if (FAILS("header.size", h->header_size != sizeof(mk_blob_header)))
        return fail(err, MK_ERROR_CORRUPT, 12, "header size ", h->header_size, " is not 64");
    if (FAILS("header.flags", h->flags != 0))
        return fail(err, MK_ERROR_CORRUPT, 36, "header flags (", h->flags, ") are not zero");
    size_t reserved = first_nonzero(h->reserved, 6);
    if (FAILS("header.reserved", reserved < 6))
        return fail(err, MK_ERROR_CORRUPT, 40 + 4 * reserved, "header reserved field ", reserved, " is not zero");
    if (FAILS("header.file_size_short", h->file_size > size))
        return fail2(err, MK_ERROR_TRUNCATED, 16, "blob is ", size, " bytes, shorter than the header's file size ",
                     h->file_size, "");
    if (FAILS("header.file_size_long", h->file_size < size))
        return fail2(err, MK_ERROR_CORRUPT, 16, "blob is ", size, " bytes, longer than the header's file size ",
                     h->file_size, "");
    if (FAILS("header.checksum", mk_checksum((const uint8_t *)data + 32, size - 32) != h->checksum))
        return fail(err, MK_ERROR_BAD_CHECKSUM, 24, "checksum mismatch: the blob was modified or damaged", NONE, "");

    validator v;
    memset(&v, 0, sizeof v);
    v.data = (const uint8_t *)data;
    v.size = size;
    v.err = err;
    v.blob = (region){ 0, size, "the blob", MK_ERROR_TRUNCATED };
    v.data_section = (region){ 0, 0, "the DATA section", MK_ERROR_CORRUPT };
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

/* Entries of a mesh's quantized targets stored as float32 (offsets 0) or int16 around a
 * position offset (offsets 1). */
static uint64_t count_outlier_entries(const mk_asset *a, uint32_t mesh, int offsets)
{
    if (!a || mesh >= a->mesh_count) return 0;
    const mk_blob_mesh *m = &a->meshes[mesh];
    const uint32_t stride = mk_entry_stride(m->flags);
    uint64_t n = 0;
    for (uint64_t e = 0; e < m->entry_count; e++) {
        const mk_blob_entry *en = mk_entry_at(a->data + m->entries, stride, e);
        if (offsets) n += mk_entry_wide(en) != 0;
        else n += !mk_entry_packed(en) && (a->targets[m->first_target + mk_entry_target(en)].flags & MK_TARGET_QUANTIZED);
    }
    return n;
}

uint64_t mk_mesh_float_entries(const mk_asset *a, uint32_t mesh) { return count_outlier_entries(a, mesh, 0); }
uint64_t mk_mesh_wide_entries(const mk_asset *a, uint32_t mesh) { return count_outlier_entries(a, mesh, 1); }

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

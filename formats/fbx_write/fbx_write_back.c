/* SPDX-License-Identifier: MIT */
/* FBX write-back (fbx_write.h): the baked channels of a raw asset (those whose `origin` is
 * set) added to the file it was imported from, as the objects of fbx_objects.c: on each deformed
 * mesh's Geometry G, the first BlendShape deformer G has (else a new one -OO-> G) gets the
 * channels; every clip that animates only baked channels becomes an animation stack. The file's
 * own nodes are copied (fbx_doc_write.c). */
#include <string.h>
#include "fbx_doc_write.h"
#include "fbx_objects.h"

typedef struct write_back {
    fbx_objects o;             /* the new objects (their arena: the document's scratch) */
    fbx_doc *doc;
    const mk_raw_asset *raw;
    mk_error *err;
    const fbx_node *objects, *connections;
} write_back;

/* ---- the document ---- */

static int64_t node_id(const fbx_node *n)
{
    int64_t id = 0;
    return n->value_count && fbx_value_int(&n->values[0], &id) ? id : 0;
}

static int string_is(const fbx_value *v, const char *s)
{
    const char *d;
    uint32_t n;
    return fbx_value_string(v, &d, &n) && n == strlen(s) && memcmp(d, s, n) == 0;
}

/* The Objects child with that id, or NULL. */
static const fbx_node *object_by_id(const write_back *w, int64_t id)
{
    for (uint32_t i = 0; i < w->objects->child_count; i++)
        if (node_id(&w->objects->children[i]) == id) return &w->objects->children[i];
    return NULL;
}

/* The first BlendShape deformer connected to geometry `g` (0: none). */
static int64_t blend_shape_of(const write_back *w, int64_t g)
{
    for (uint32_t i = 0; i < w->connections->child_count; i++) {
        const fbx_node *c = &w->connections->children[i];
        int64_t src, dst;
        if (!fbx_name_is(c, "C") || c->value_count < 3 || !string_is(&c->values[0], "OO") ||
            !fbx_value_int(&c->values[1], &src) || !fbx_value_int(&c->values[2], &dst) || dst != g)
            continue;
        const fbx_node *o = object_by_id(w, src);
        if (o && fbx_name_is(o, "Deformer") && o->value_count >= 3 && string_is(&o->values[2], "BlendShape")) return src;
    }
    return 0;
}

static mk_result find_document(write_back *w)
{
    fbx_doc *doc = w->doc;
    if (doc->binary && doc->big_endian)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, 22,
                            "FBX write-back: big-endian binary files cannot be written back (only little-endian ones)");
    int64_t version = doc->version;
    const fbx_node *header = fbx_child(&doc->root, "FBXHeaderExtension");
    int64_t stated;
    if (header && fbx_child_int(header, "FBXVersion", &stated)) version = stated;
    if (version < 7200)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX write-back: this is an FBX %lld file; files before 7.2 keep shapes inside the geometry, "
                            "and write-back adds FBX 7.2+ blend shape deformers (save the file as FBX 2012 or later)",
                            (long long)version);
    w->objects = fbx_child(&doc->root, "Objects");
    w->connections = fbx_child(&doc->root, "Connections");
    if (!w->objects || !w->connections || !w->objects->child_count || !w->connections->child_count)
        return mk_error_set(w->err, MK_ERROR_PARSE, UINT64_MAX, "FBX write-back: the file has no Objects or no Connections");
    int64_t top = 0;
    for (uint32_t i = 0; i < w->objects->child_count; i++) {
        int64_t id = node_id(&w->objects->children[i]);
        if (id > top) top = id;
    }
    if (top > INT64_MAX - 1000000)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "FBX write-back: object ids leave no room for new ones");
    w->o.next_id = top + 1;
    return MK_OK;
}

/* ---- the whole ---- */

static int is_baked(const mk_raw_channel *ch) { return ch->origin && *ch->origin; }

static mk_result add_all(write_back *w)
{
    const mk_raw_asset *raw = w->raw;
    fbx_objects *o = &w->o;
    int64_t *channel_ids = mk_arena_array(o->a, raw->channel_count ? raw->channel_count : 1, sizeof(int64_t));
    if (!channel_ids) return fbx_objects_oom(o);
    for (uint32_t mi = 0; mi < raw->mesh_count; mi++) {
        const mk_raw_mesh *m = &raw->meshes[mi];
        uint32_t baked = 0;
        for (uint32_t c = 0; c < raw->channel_count; c++) baked += raw->channels[c].mesh == mi && is_baked(&raw->channels[c]);
        if (!baked) continue;
        if (!m->fbx_geometry)
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX write-back: mesh '%s' has no FBX geometry of its own to write to", m->name);
        for (uint32_t other = 0; other < raw->mesh_count; other++)
            if (other != mi && raw->meshes[other].fbx_geometry == m->fbx_geometry)
                return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "FBX write-back: the geometry of mesh '%s' is also used by model '%s'; a channel baked "
                                    "on one would deform both",
                                    m->name, raw->meshes[other].name);
        const fbx_node *g = object_by_id(w, m->fbx_geometry);
        if (!g || !fbx_name_is(g, "Geometry"))
            return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                "FBX write-back: mesh '%s': geometry %lld is not in this file's Objects (was the asset "
                                "imported from this file?)", m->name, (long long)m->fbx_geometry);
        uint32_t *render_count;
        double tolerance;
        mk_result r = fbx_objects_mesh(o, m, &render_count, &tolerance);
        if (r != MK_OK) return r;
        int64_t blend = blend_shape_of(w, m->fbx_geometry);
        if (!blend) {
            if ((r = fbx_object_check_name(o, "mesh", m->name)) != MK_OK) return r;
            fbx_wnode *b = fbx_object_new(o, "Deformer", "Deformer", m->name, "BlendShape", &blend);
            if (!b || !fbx_wn_int(o->a, fbx_wn_child(o->a, b, "Version"), 100) ||
                !fbx_object_connect(o, "OO", blend, m->fbx_geometry, NULL))
                return fbx_objects_oom(o);
            o->report->blend_shapes++;
        }
        for (uint32_t c = 0; c < raw->channel_count; c++) {
            if (raw->channels[c].mesh != mi || !is_baked(&raw->channels[c])) continue;
            r = fbx_objects_add_channel(o, m, render_count, tolerance, &raw->channels[c], blend, &channel_ids[c]);
            if (r != MK_OK) return r;
        }
        o->report->meshes++;
    }
    for (uint32_t k = 0; k < raw->clip_count; k++) {
        const mk_raw_clip *clip = &raw->clips[k];
        uint32_t baked = 0;
        for (uint32_t t = 0; t < clip->track_count; t++)
            baked += clip->tracks[t].channel < raw->channel_count && is_baked(&raw->channels[clip->tracks[t].channel]);
        if (!baked || baked != clip->track_count) continue;  /* the file's own clips are in it already */
        mk_result r = fbx_objects_add_clip(o, clip, channel_ids);
        if (r != MK_OK) return r;
    }
    return MK_OK;
}

mk_result mk_fbx_write_back(const void *input, size_t input_size, const mk_raw_asset *raw, mk_arena *arena,
                            void **out, size_t *out_size, mk_fbx_write_report *report, mk_error *err)
{
    mk_fbx_write_report local_report;
    mk_error local_err;
    if (!report) report = &local_report;
    if (!err) err = &local_err;
    memset(report, 0, sizeof *report);
    if (!input || !raw || !arena || !out || !out_size)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_fbx_write_back: NULL argument");
    mk_arena scratch;
    mk_arena_init(&scratch, &arena->allocator);
    fbx_doc doc;
    mk_result r = fbx_doc_parse(&doc, &scratch, input, input_size, err);
    const char *tag = "Blender (stable FBX IO)";
    write_back w = { .o = { .a = &scratch, .err = err, .binary = doc.binary, .report = report,
                            .blender = doc.binary && strncmp(raw->source_creator, tag, strlen(tag)) == 0 },
                     .doc = &doc, .raw = raw, .err = err };
    if (r == MK_OK) r = find_document(&w);
    if (r == MK_OK) r = add_all(&w);
    fbx_bytes bytes = { .arena = arena };
    if (r == MK_OK) {
        fbx_insertion ins[2] = { { w.objects, w.o.objects, w.o.object_count },
                                 { w.connections, w.o.connections, w.o.connection_count } };
        r = fbx_doc_write(&doc, ins, 2, &bytes);
    }
    if (r == MK_OK) {
        *out = bytes.data;
        *out_size = bytes.size;
    } else {
        mk_arena_release(arena, bytes.data);
        memset(report, 0, sizeof *report);
    }
    fbx_doc_free(&doc);
    mk_arena_free_all(&scratch);
    return r;
}

mk_result mk_fbx_write_back_check(const void *input, size_t input_size, mk_error *err)
{
    mk_error local_err;
    if (!err) err = &local_err;
    if (!input) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_fbx_write_back_check: NULL input");
    mk_arena scratch;
    mk_arena_init(&scratch, NULL);
    fbx_doc doc;
    mk_result r = fbx_doc_parse(&doc, &scratch, input, input_size, err);
    write_back w = { .doc = &doc, .err = err };
    if (r == MK_OK) r = find_document(&w);
    fbx_doc_free(&doc);
    mk_arena_free_all(&scratch);
    return r;
}

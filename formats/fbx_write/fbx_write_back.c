/* SPDX-License-Identifier: MIT */
/* FBX write-back (fbx_write.h): the baked channels of a raw asset (those whose `origin` is
 * set) added to the file it was imported from, as the objects of fbx_objects.c: on each deformed
 * mesh's Geometry G, the first BlendShape deformer G has (else a new one -OO-> G) gets the
 * channels; every clip that animates only baked channels becomes an animation stack. The file's
 * own nodes are copied (fbx_doc_write.c).
 *
 * FBX 7.1 has no blend shape deformers: a shape is a `Shape: "NAME"` child of the Geometry
 * (Indexes, Vertices, Normals) and its weight the Geometry property NAME (percent), animated by
 * a curve node OP-connected to the Geometry with that property name. A channel is one shape
 * there: in-betweens are refused, and so is a name the Geometry's properties already use. */
#include <string.h>
#include "fbx_doc_write.h"
#include "fbx_objects.h"

typedef struct write_back {
    fbx_objects o;             /* the new objects (their arena: the document's scratch) */
    fbx_doc *doc;
    const mk_raw_asset *raw;
    mk_error *err;
    const fbx_node *objects, *connections;
    int shapes_in_geometry;    /* FBX 7.1 */
    fbx_insertion *ins;        /* Objects, Connections, then (7.1) per Geometry its shapes and properties */
    uint32_t ins_count;
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
    const int64_t version = doc->version;   /* as the reader settles it (fbx_doc_parse) */
    if (version < 7100)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX write-back: this is an FBX %lld file; write-back writes FBX 7.1 and later (6.x and "
                            "earlier address objects by name and keep animation in takes; save the file as FBX 2011 or later)",
                            (long long)version);
    w->shapes_in_geometry = version < 7200;
    w->o.ascii_float_bits = !doc->binary && version >= 7200;
    w->o.ticks = fbx_doc_ticks(doc);
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

/* ---- FBX 7.1: shapes inside the geometry ---- */

/* Appends `node` to the children inserted into `parent` (one insertion per parent). */
static int insert_into(write_back *w, const fbx_node *parent, fbx_wnode *node)
{
    fbx_insertion *in = NULL;
    for (uint32_t i = 0; i < w->ins_count; i++)
        if (w->ins[i].parent == parent) in = &w->ins[i];
    if (!in) {
        fbx_insertion *grown = mk_arena_realloc(w->o.a, w->ins, w->ins_count * sizeof *w->ins, (w->ins_count + 1) * sizeof *w->ins);
        if (!grown) return 0;
        w->ins = grown;
        in = &w->ins[w->ins_count++];
        memset(in, 0, sizeof *in);
        in->parent = parent;
    }
    fbx_wnode **nodes = mk_arena_realloc(w->o.a, (void *)in->nodes, in->count * sizeof *nodes, (in->count + 1) * sizeof *nodes);
    if (!nodes) return 0;
    nodes[in->count++] = node;
    in->nodes = nodes;
    return 1;
}

/* One baked channel as a Shape of geometry g, its weight a P of g's Properties70, or of the
 * Properties70 made for g (*made) when g has none. */
static mk_result add_shape_71(write_back *w, const fbx_node *g, const mk_raw_mesh *m, const uint32_t *render_count,
                              double tolerance, const mk_raw_channel *ch, fbx_wnode **made)
{
    fbx_objects *o = &w->o;
    mk_result r = fbx_object_check_name(o, "channel", ch->name);
    if (r != MK_OK) return r;
    if (ch->target_count != 1 || ch->targets[0].full_weight != 1.0f)
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX write-back: channel '%s' has %u targets; FBX 7.1 shapes have no in-betweens (bake it "
                            "with \"inbetweens\": 1, or save the file as FBX 2012 or later)", ch->name, ch->target_count);
    const fbx_node *props = fbx_child(g, "Properties70");
    if (fbx_prop_find(fbx_props_of(g), ch->name))
        return mk_error_set(w->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX write-back: channel '%s': the geometry of mesh '%s' has a property of that name already "
                            "(FBX 7.1 weights are geometry properties named after the shape)", ch->name, m->name);
    int32_t *indexes;
    double *deltas;
    uint32_t n;
    if ((r = fbx_objects_target(o, m, render_count, ch, 0, tolerance, &indexes, &deltas, &n)) != MK_OK) return r;
    double *normals = mk_arena_array(o->a, n, 3 * sizeof(double));
    fbx_wnode *shape = fbx_wn_new(o->a, "Shape");
    if (!normals || !shape || !fbx_wn_string(o->a, shape, ch->name, strlen(ch->name)) ||
        !fbx_wn_array(o->a, shape, "Indexes", 'i', indexes, n) || !fbx_wn_array(o->a, shape, "Vertices", 'd', deltas, 3 * n) ||
        !fbx_wn_array(o->a, shape, "Normals", 'd', normals, 3 * n) || !insert_into(w, g, shape))
        return fbx_objects_oom(o);
    const fbx_wvalue percent = { .type = 'D', .u.d = 100.0 * ch->default_weight };
    if (props) {
        fbx_wnode *holder = fbx_wn_new(o->a, "Properties70");   /* builds the P, which goes into props */
        fbx_wnode *p = holder ? fbx_wn_prop(o->a, holder, ch->name, "Number", "", "A+", percent) : NULL;
        if (!p || !insert_into(w, props, p)) return fbx_objects_oom(o);
    } else {
        if (!*made && (!(*made = fbx_wn_new(o->a, "Properties70")) || !insert_into(w, g, *made))) return fbx_objects_oom(o);
        if (!fbx_wn_prop(o->a, *made, ch->name, "Number", "", "A+", percent)) return fbx_objects_oom(o);
    }
    o->report->channels++;
    o->report->shapes++;
    return MK_OK;
}

/* ---- the whole ---- */

static int is_baked(const mk_raw_channel *ch) { return ch->origin && *ch->origin; }

static mk_result add_all(write_back *w)
{
    const mk_raw_asset *raw = w->raw;
    fbx_objects *o = &w->o;
    int64_t *channel_ids = mk_arena_array(o->a, raw->channel_count ? raw->channel_count : 1, sizeof(int64_t));
    const char **channel_props = mk_arena_array(o->a, raw->channel_count ? raw->channel_count : 1, sizeof(char *));
    if (!channel_ids || !channel_props) return fbx_objects_oom(o);
    for (uint32_t c = 0; c < raw->channel_count; c++) channel_props[c] = w->shapes_in_geometry ? raw->channels[c].name : "DeformPercent";
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
        if (w->shapes_in_geometry) {
            fbx_wnode *made = NULL;
            for (uint32_t c = 0; c < raw->channel_count; c++) {
                if (raw->channels[c].mesh != mi || !is_baked(&raw->channels[c])) continue;
                if ((r = add_shape_71(w, g, m, render_count, tolerance, &raw->channels[c], &made)) != MK_OK) return r;
                channel_ids[c] = m->fbx_geometry;
            }
            o->report->meshes++;
            continue;
        }
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
        mk_result r = fbx_objects_add_clip(o, clip, channel_ids, channel_props);
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
        fbx_insertion *ins = mk_arena_array(&scratch, w.ins_count + 2, sizeof *ins);
        if (!ins) r = mk_error_oom(err, "FBX write-back");
        if (r == MK_OK) {
            ins[0] = (fbx_insertion){ w.objects, w.o.objects, w.o.object_count };
            ins[1] = (fbx_insertion){ w.connections, w.o.connections, w.o.connection_count };
            if (w.ins_count) memcpy(ins + 2, w.ins, w.ins_count * sizeof *ins);
            r = fbx_doc_write(&doc, ins, w.ins_count + 2, &bytes);
        }
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

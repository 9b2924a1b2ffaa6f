/* SPDX-License-Identifier: MIT */
/* FBX scene interpretation: objects, connections, meshes, blend shapes and weight animation
 * into the raw model.
 *
 * Object graph (docs/importing-fbx.md):
 *   7.x:  Model <-OO- Geometry(Mesh) <-OO- Deformer(BlendShape) <-OO- Deformer(BlendShapeChannel)
 *         <-OO- Geometry(Shape) x N (in-between order = connection order, matching FullWeights);
 *         AnimationStack <-OO- AnimationLayer <-OO- AnimationCurveNode -OP "DeformPercent"->
 *         channel; AnimationCurve -OP "d|DeformPercent"-> curve node. Connections name the
 *         child (source) first.
 *   7100: no BlendShape objects: `Shape:` children of the Geometry, weights are Geometry
 *         properties named after the shape, animated through curve nodes OP-connected to the
 *         Geometry with that property name.
 *   6.x:  objects are addressed by "Class::Name"; the Model holds its geometry and `Shape:`
 *         children; weights are Model properties; animation lives in Takes/Take/Model/Channel.
 *   5.x (3ds Max 7): Models at the top level, hierarchy by `Children:` names, shape weights as
 *         Channel: "<shape> (Shape)" both in the Model (Default) and in Takes.
 *
 * Tool quirks handled (sources in the notes): duplicate connections (ZBrush connects a
 * deformer twice) are dropped with a warning; Blender binary exporters (Creator "Blender
 * (stable FBX IO)...") write per-vertex weights into FullWeights, which are then applied to the
 * deltas instead of being full weights; Blender also animates a Geometry property named after
 * each shape, which only 7100-style files use, so it is applied once; DeformPercent is read
 * from the property or the plain field; channel names drop the "SubDeformer::" class prefix.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mat4.h"
#include "fbx_anim.h"
#include "fbx_mesh.h"
#include "fbx_shapes.h"
#include "fbx_transform.h"

enum {
    OBJ_OTHER, OBJ_MODEL, OBJ_MESH, OBJ_SHAPE, OBJ_BLEND, OBJ_CHANNEL, OBJ_STACK, OBJ_LAYER, OBJ_CURVE_NODE, OBJ_CURVE
};

typedef struct object {
    int64_t id;
    const fbx_node *node;
    const char *name;          /* without the class prefix */
    uint32_t name_length;
    int kind;
    uint32_t parents_first, parents_count;    /* connections where this object is the source */
    uint32_t children_first, children_count;  /* connections where this object is the destination */
    int32_t raw_mesh;
} object;

typedef struct conn {
    uint32_t src, dst;
    const char *prop;
    uint32_t prop_length;
    uint32_t order;
} conn;

typedef struct binding {
    uint32_t object;
    const char *prop;
    uint32_t prop_length;
    uint32_t channel;
} binding;

typedef struct scene {
    fbx_doc *doc;
    mk_raw_asset *raw;
    const mk_import_options *options;
    int legacy_ids;            /* < 7000: objects addressed by name */
    int blender;               /* Creator says Blender binary exporter */
    double ticks;              /* KTime ticks per second */
    object *objects;
    uint32_t object_count;
    uint64_t *table;           /* id hash -> object index + 1 */
    size_t table_size;
    conn *conns;
    uint32_t conn_count;
    uint32_t *by_src, *by_dst; /* connection indices grouped by object, file order */
    binding *bindings;
    uint32_t binding_count, binding_cap;
    uint32_t *binding_table;   /* hash slots: binding index + 1 */
    size_t binding_table_size;
    int32_t *parent;           /* parent Model per object, -1 for roots */
    double *world;             /* 16 per object, valid when world_state == 2 */
    uint8_t *world_state;
    uint32_t *track_seen;      /* per raw channel: clip index + 1 that already has its track */
    uint32_t track_clip, track_cap; /* clip index + 1 whose tracks array has track_cap slots */
} scene;

/* ---- names and ids ---- */

/* "Class::Name" (ASCII) or "Name\0\1Class" (binary) -> Name. */
static void split_name(const char *s, uint32_t n, const char **name, uint32_t *name_length)
{
    for (uint32_t i = 0; i + 1 < n; i++) {
        if (s[i] == 0 && s[i + 1] == 1) { *name = s; *name_length = i; return; }
    }
    for (uint32_t i = 0; i + 1 < n; i++) {
        if (s[i] == ':' && s[i + 1] == ':') { *name = s + i + 2; *name_length = n - i - 2; return; }
    }
    *name = s;
    *name_length = n;
}

static uint64_t fnv(uint64_t h, const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) { h ^= (unsigned char)s[i]; h *= 1099511628211ull; }
    return h;
}

/* Canonical id of a pre-7000 object name: hash of "Class::Name" whatever the spelling. */
static int64_t legacy_id(const char *s, uint32_t n)
{
    const char *cls = "", *name = s;
    uint32_t cls_length = 0, name_length = n;
    for (uint32_t i = 0; i + 1 < n; i++) {
        if (s[i] == 0 && s[i + 1] == 1) { name_length = i; cls = s + i + 2; cls_length = n - i - 2; break; }
        if (s[i] == ':' && s[i + 1] == ':') { cls = s; cls_length = i; name = s + i + 2; name_length = n - i - 2; break; }
    }
    uint64_t h = fnv(1469598103934665603ull, cls, cls_length);
    h = fnv(h, "::", 2);
    h = fnv(h, name, name_length);
    return (int64_t)(h & 0x7fffffffffffffffull);
}

static uint64_t mix(uint64_t x)
{
    x ^= x >> 33; x *= 0xff51afd7ed558ccdull; x ^= x >> 33; x *= 0xc4ceb9fe1a85ec53ull; x ^= x >> 33;
    return x;
}

static int32_t find_object(const scene *s, int64_t id)
{
    if (!s->table_size) return -1;
    size_t mask = s->table_size - 1;
    for (size_t i = mix((uint64_t)id) & mask;; i = (i + 1) & mask) {
        uint64_t e = s->table[i];
        if (!e) return -1;
        if (s->objects[e - 1].id == id) return (int32_t)(e - 1);
    }
}

static int str_eq(const char *a, uint32_t an, const char *b)
{
    size_t bn = strlen(b);
    return an == bn && memcmp(a, b, bn) == 0;
}

/* ---- object table ---- */

static int classify(const fbx_node *node, const char *sub, uint32_t sub_length)
{
    if (fbx_name_is(node, "Model")) return OBJ_MODEL;
    if (fbx_name_is(node, "Geometry")) {
        if (str_eq(sub, sub_length, "Mesh")) return OBJ_MESH;
        if (str_eq(sub, sub_length, "Shape")) return OBJ_SHAPE;
        return OBJ_OTHER;
    }
    if (fbx_name_is(node, "Deformer")) {
        if (str_eq(sub, sub_length, "BlendShape")) return OBJ_BLEND;
        if (str_eq(sub, sub_length, "BlendShapeChannel")) return OBJ_CHANNEL;
        return OBJ_OTHER;
    }
    if (fbx_name_is(node, "AnimationStack")) return OBJ_STACK;
    if (fbx_name_is(node, "AnimationLayer")) return OBJ_LAYER;
    if (fbx_name_is(node, "AnimationCurveNode")) return OBJ_CURVE_NODE;
    if (fbx_name_is(node, "AnimationCurve")) return OBJ_CURVE;
    return OBJ_OTHER;
}

/* Objects under `parent`: counted (fill 0) or stored (fill 1). */
static void add_object_nodes(scene *s, const fbx_node *parent, uint32_t *count, int fill)
{
    for (uint32_t i = 0; i < parent->child_count; i++) {
        const fbx_node *node = &parent->children[i];
        object o;
        memset(&o, 0, sizeof o);
        o.node = node;
        o.raw_mesh = -1;
        const char *full = "", *sub = "";
        uint32_t full_length = 0, sub_length = 0;
        if (!s->legacy_ids) {
            /* 7.x: id, "Class::Name", "SubClass" */
            if (node->value_count < 2 || node->values[0].kind != FBX_INT) continue;
            if (!fbx_value_string(&node->values[1], &full, &full_length)) continue;
            if (node->value_count >= 3) fbx_value_string(&node->values[2], &sub, &sub_length);
            o.id = node->values[0].u.i;
        } else {
            /* 6.x: "Class::Name", "SubClass"; 5.x top-level Model: "Name" */
            if (node->value_count < 1 || !fbx_value_string(&node->values[0], &full, &full_length)) continue;
            if (node->value_count >= 2) fbx_value_string(&node->values[1], &sub, &sub_length);
            o.id = legacy_id(full, full_length);
        }
        split_name(full, full_length, &o.name, &o.name_length);
        o.kind = classify(node, sub, sub_length);
        if (fill) s->objects[*count] = o;
        (*count)++;
    }
}

static mk_result build_objects(scene *s)
{
    fbx_doc *doc = s->doc;
    const fbx_node *objects = fbx_child(&doc->root, "Objects");
    /* FBX 5: Models sit at the top level. */
    const fbx_node *holders[2] = { objects, doc->version < 6000 ? &doc->root : NULL };
    uint32_t count = 0;
    for (int h = 0; h < 2; h++)
        if (holders[h]) add_object_nodes(s, holders[h], &count, 0);
    s->objects = mk_arena_array(doc->arena, count ? count : 1, sizeof(object));
    if (!s->objects) return mk_error_oom(doc->err, "FBX objects");
    uint32_t filled = 0;
    for (int h = 0; h < 2; h++)
        if (holders[h]) add_object_nodes(s, holders[h], &filled, 1);
    s->object_count = filled;
    size_t size = 16;
    while (size < (size_t)filled * 2) size *= 2;
    s->table = mk_arena_array(doc->arena, size, sizeof(uint64_t));
    if (!s->table) return mk_error_oom(doc->err, "FBX object table");
    s->table_size = size;
    size_t duplicates = 0;
    for (uint32_t i = 0; i < filled; i++) {
        size_t mask = size - 1, slot = mix((uint64_t)s->objects[i].id) & mask;
        int dup = 0;
        while (s->table[slot]) {
            if (s->objects[s->table[slot] - 1].id == s->objects[i].id) { dup = 1; break; }
            slot = (slot + 1) & mask;
        }
        if (dup) { duplicates++; continue; }  /* first definition wins */
        s->table[slot] = (uint64_t)i + 1;
    }
    if (duplicates) mk_raw_warn(s->raw, "FBX: %zu objects reuse an id already defined; the first one is used", duplicates);
    return MK_OK;
}

/* ---- connections ---- */

static int cmp_conn(const void *a, const void *b)
{
    const conn *x = a, *y = b;
    if (x->src != y->src) return x->src < y->src ? -1 : 1;
    if (x->dst != y->dst) return x->dst < y->dst ? -1 : 1;
    if (x->prop_length != y->prop_length) return x->prop_length < y->prop_length ? -1 : 1;
    int c = x->prop_length ? memcmp(x->prop, y->prop, x->prop_length) : 0;
    if (c) return c;
    return x->order < y->order ? -1 : x->order > y->order;
}

static int cmp_order(const void *a, const void *b)
{
    const conn *x = a, *y = b;
    return x->order < y->order ? -1 : x->order > y->order;
}

static mk_result build_connections(scene *s)
{
    fbx_doc *doc = s->doc;
    const fbx_node *block = fbx_child(&doc->root, "Connections");
    uint32_t capacity = block ? block->child_count : 0;
    s->conns = mk_arena_array(doc->arena, capacity ? capacity : 1, sizeof(conn));
    if (!s->conns) return mk_error_oom(doc->err, "FBX connections");
    uint32_t n = 0;
    for (uint32_t i = 0; i < capacity; i++) {
        const fbx_node *c = &block->children[i];
        if (!(fbx_name_is(c, "C") || fbx_name_is(c, "Connect")) || c->value_count < 3) continue;
        const char *type;
        uint32_t type_length;
        if (!fbx_value_string(&c->values[0], &type, &type_length)) continue;
        int oo = str_eq(type, type_length, "OO"), op = str_eq(type, type_length, "OP");
        if (!oo && !op) continue;  /* PO/PP connect properties to properties: not used here */
        int64_t src_id, dst_id;
        if (!s->legacy_ids) {
            if (c->values[1].kind != FBX_INT || c->values[2].kind != FBX_INT) continue;
            src_id = c->values[1].u.i;
            dst_id = c->values[2].u.i;
        } else {
            const char *a, *b;
            uint32_t an, bn;
            if (!fbx_value_string(&c->values[1], &a, &an) || !fbx_value_string(&c->values[2], &b, &bn)) continue;
            src_id = legacy_id(a, an);
            dst_id = legacy_id(b, bn);
        }
        int32_t src = find_object(s, src_id), dst = find_object(s, dst_id);
        if (src < 0 || dst < 0) continue;  /* the scene root (id 0, "Model::Scene") or unknown objects */
        conn *e = &s->conns[n];
        memset(e, 0, sizeof *e);
        e->src = (uint32_t)src;
        e->dst = (uint32_t)dst;
        e->order = n;
        if (op && c->value_count >= 4) fbx_value_string(&c->values[3], &e->prop, &e->prop_length);
        n++;
    }
    /* Drop exact duplicates (ZBrush connects the same deformer twice). */
    qsort(s->conns, n, sizeof(conn), cmp_conn);
    uint32_t w = 0, dropped = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (w > 0) {
            const conn *p = &s->conns[w - 1], *q = &s->conns[i];
            if (p->src == q->src && p->dst == q->dst && p->prop_length == q->prop_length &&
                (!p->prop_length || memcmp(p->prop, q->prop, p->prop_length) == 0)) { dropped++; continue; }
        }
        s->conns[w++] = s->conns[i];
    }
    n = w;
    qsort(s->conns, n, sizeof(conn), cmp_order);
    if (dropped) mk_raw_warn(s->raw, "FBX: %u duplicate connections ignored", dropped);
    s->conn_count = n;
    /* Group by source and by destination (counting sort keeps file order). */
    s->by_src = mk_arena_array(doc->arena, n ? n : 1, sizeof(uint32_t));
    s->by_dst = mk_arena_array(doc->arena, n ? n : 1, sizeof(uint32_t));
    if (!s->by_src || !s->by_dst) return mk_error_oom(doc->err, "FBX connections");
    for (uint32_t i = 0; i < n; i++) {
        s->objects[s->conns[i].src].parents_count++;
        s->objects[s->conns[i].dst].children_count++;
    }
    uint32_t a = 0, b = 0;
    for (uint32_t i = 0; i < s->object_count; i++) {
        s->objects[i].parents_first = a;
        s->objects[i].children_first = b;
        a += s->objects[i].parents_count;
        b += s->objects[i].children_count;
        s->objects[i].parents_count = 0;
        s->objects[i].children_count = 0;
    }
    for (uint32_t i = 0; i < n; i++) {
        object *src = &s->objects[s->conns[i].src], *dst = &s->objects[s->conns[i].dst];
        s->by_src[src->parents_first + src->parents_count++] = i;
        s->by_dst[dst->children_first + dst->children_count++] = i;
    }
    return MK_OK;
}

/* k-th child connection of object o whose source has `kind`; returns the connection or NULL. */
static const conn *child_of_kind(const scene *s, uint32_t o, int kind, uint32_t *cursor)
{
    const object *obj = &s->objects[o];
    for (; *cursor < obj->children_count; (*cursor)++) {
        const conn *c = &s->conns[s->by_dst[obj->children_first + *cursor]];
        if (s->objects[c->src].kind == kind) { (*cursor)++; return c; }
    }
    return NULL;
}

static const conn *parent_of_kind(const scene *s, uint32_t o, int kind, uint32_t *cursor)
{
    const object *obj = &s->objects[o];
    for (; *cursor < obj->parents_count; (*cursor)++) {
        const conn *c = &s->conns[s->by_src[obj->parents_first + *cursor]];
        if (s->objects[c->dst].kind == kind) { (*cursor)++; return c; }
    }
    return NULL;
}

/* ---- bindings (animated property -> raw channel) ---- */

/* Hash of (object, property name); the table is rebuilt when it fills past half. */
static uint64_t binding_hash(uint32_t object_index, const char *prop, uint32_t prop_length)
{
    return mix(fnv(1469598103934665603ull ^ object_index, prop, prop_length));
}

/* Open addressing with linear probing; slot value = binding index + 1 (0 = empty). */
static void table_insert(scene *s, uint32_t index)
{
    const binding *b = &s->bindings[index];
    size_t mask = s->binding_table_size - 1;
    size_t slot = binding_hash(b->object, b->prop, b->prop_length) & mask;
    while (s->binding_table[slot]) slot = (slot + 1) & mask;
    s->binding_table[slot] = index + 1;
}

static mk_result bind(scene *s, uint32_t object_index, const char *prop, uint32_t prop_length, uint32_t channel)
{
    if (s->binding_count == s->binding_cap) {
        uint32_t cap = s->binding_cap ? s->binding_cap * 2 : 16;
        binding *b =
            mk_arena_realloc(s->doc->arena, s->bindings, s->binding_cap * sizeof(binding), cap * sizeof(binding));
        if (!b) return mk_error_oom(s->doc->err, "FBX bindings");
        s->bindings = b;
        s->binding_cap = cap;
        /* Rehash into a table of 2 x capacity slots (slot = binding index + 1). */
        mk_arena_release(s->doc->arena, s->binding_table);
        s->binding_table_size = (size_t)cap * 2;
        s->binding_table = mk_arena_array(s->doc->arena, s->binding_table_size, sizeof(uint32_t));
        if (!s->binding_table) return mk_error_oom(s->doc->err, "FBX bindings");
        for (uint32_t i = 0; i < s->binding_count; i++) table_insert(s, i);
    }
    uint32_t index = s->binding_count++;
    binding *b = &s->bindings[index];
    b->object = object_index;
    b->prop = prop;
    b->prop_length = prop_length;
    b->channel = channel;
    table_insert(s, index);
    return MK_OK;
}

/* Channels bound to (object, property): a geometry instanced by several models has one raw
 * channel per model for the same FBX channel. *slot starts at SIZE_MAX; returns -1 when done. */
static int32_t next_binding(const scene *s, uint32_t object_index, const char *prop, uint32_t prop_length, size_t *slot)
{
    if (!s->binding_table_size) return -1;
    size_t mask = s->binding_table_size - 1;
    size_t i = *slot == SIZE_MAX ? binding_hash(object_index, prop, prop_length) & mask : (*slot + 1) & mask;
    for (; s->binding_table[i]; i = (i + 1) & mask) {
        const binding *b = &s->bindings[s->binding_table[i] - 1];
        if (b->object == object_index && b->prop_length == prop_length && memcmp(b->prop, prop, prop_length) == 0) {
            *slot = i;
            return (int32_t)b->channel;
        }
    }
    return -1;
}

/* ---- transforms ---- */

/* Parent Model of every object (-1 for roots): OO connection to a Model (6.x/7.x), or the
 * `Children:` name lists of FBX 5 parents, resolved through the name hash. */
static mk_result build_parents(scene *s)
{
    s->parent = mk_arena_array(s->doc->arena, s->object_count ? s->object_count : 1, sizeof(int32_t));
    if (!s->parent) return mk_error_oom(s->doc->err, "FBX hierarchy");
    for (uint32_t o = 0; o < s->object_count; o++) {
        s->parent[o] = -1;
        if (s->objects[o].kind != OBJ_MODEL || s->doc->version < 6000) continue;
        uint32_t cursor = 0;
        const conn *c;
        while ((c = parent_of_kind(s, o, OBJ_MODEL, &cursor)) != NULL)
            if (!c->prop_length && c->dst != o) { s->parent[o] = (int32_t)c->dst; break; }
    }
    if (s->doc->version < 6000) {
        for (uint32_t o = 0; o < s->object_count; o++) {
            if (s->objects[o].kind != OBJ_MODEL) continue;
            const fbx_node *children = fbx_child(s->objects[o].node, "Children");
            for (uint32_t k = 0; children && k < children->value_count; k++) {
                const char *name;
                uint32_t n;
                if (!fbx_value_string(&children->values[k], &name, &n)) continue;
                int32_t child = find_object(s, legacy_id(name, n));
                if (child < 0) {
                    /* FBX 5 names carry no class: objects were hashed as "::Name". */
                    continue;
                }
                if ((uint32_t)child != o) s->parent[child] = (int32_t)o;
            }
        }
    }
    return MK_OK;
}

/* World matrices, memoized per object; a parent cycle (hostile files) is cut with a warning. */
static void node_world(scene *s, uint32_t o, double out[16])
{
    if (s->world_state[o] == 2) { memcpy(out, s->world + 16 * (size_t)o, 16 * sizeof(double)); return; }
    /* Walk up to the first computed ancestor (or root), then compute downwards. */
    uint32_t chain[256];
    int n = 0;
    int32_t cur = (int32_t)o;
    while (cur >= 0 && s->world_state[cur] != 2) {
        if (s->world_state[cur] == 1 || n == 256) {
            mk_raw_warn(s->raw, "FBX: node parent chain has a cycle or is deeper than 256; cut");
            break;
        }
        s->world_state[cur] = 1;
        chain[n++] = (uint32_t)cur;
        cur = s->parent[cur];
    }
    double parent[16];
    if (cur >= 0 && s->world_state[cur] == 2) memcpy(parent, s->world + 16 * (size_t)cur, sizeof parent);
    else mk_mat4d_identity(parent);
    for (int i = n - 1; i >= 0; i--) {
        double local[16], geometric[16];
        const fbx_node *node = s->objects[chain[i]].node;
        fbx_model_transforms(node, local, geometric);
        double *w = s->world + 16 * (size_t)chain[i];
        int32_t up = s->parent[chain[i]];
        if (up >= 0 && fbx_model_inherit_type(node) == 2) {
            /* Rrs (Maya segment scale compensate): the parent's scale still moves the child
             * (its translation is scaled) but does not scale it: Local' = T S_parent^-1 T^-1 Local
             * (exact when the parent has no scaling pivot). */
            double scale[3], t[3] = { 0, 0, 0 }, undo[16], move[16];
            fbx_model_scaling(s->objects[up].node, scale);
            fbx_prop_vec3(fbx_props_of(node), "Lcl Translation", t);
            mk_mat4d_identity(move);
            for (int k = 0; k < 3; k++) move[12 + k] = -t[k];
            mk_mat4d_multiply(local, move, local);
            mk_mat4d_identity(undo);
            for (int k = 0; k < 3; k++) undo[5 * k] = scale[k] != 0.0 ? 1.0 / scale[k] : 1.0;
            mk_mat4d_multiply(local, undo, local);
            for (int k = 0; k < 3; k++) move[12 + k] = t[k];
            mk_mat4d_multiply(local, move, local);
        }
        mk_mat4d_multiply(w, parent, local);
        s->world_state[chain[i]] = 2;
        memcpy(parent, w, sizeof parent);
    }
    for (int i = 0; i < n; i++) if (s->world_state[chain[i]] == 1) s->world_state[chain[i]] = 2;
    memcpy(out, s->world + 16 * (size_t)o, 16 * sizeof(double));
}

static void world_transform(scene *s, uint32_t o, float out[16])
{
    double world[16], local[16], geometric[16];
    node_world(s, o, world);
    fbx_model_transforms(s->objects[o].node, local, geometric);
    mk_mat4d_multiply(world, world, geometric);
    for (int i = 0; i < 16; i++) out[i] = (float)world[i];
}

static int finite16(const float m[16])
{
    for (int i = 0; i < 16; i++) if (!isfinite(m[i])) return 0;
    return 1;
}

/* A mesh's world transform is not finite: name the property that made it so, on the model or
 * on an ancestor (the transform stack reads these; fbx_transform.c). Falls back to naming the
 * model when every value is finite and only the product overflowed. */
static mk_result transform_not_finite(scene *s, uint32_t o, const char *mesh_name)
{
    static const char *const names[] = { "Lcl Translation", "Lcl Rotation", "Lcl Scaling", "RotationOffset",
                                         "RotationPivot", "ScalingOffset", "ScalingPivot", "PreRotation",
                                         "PostRotation", "GeometricTranslation", "GeometricRotation", "GeometricScaling" };
    int32_t cur = (int32_t)o;
    for (int depth = 0; cur >= 0 && depth < 256; depth++, cur = s->parent[cur]) {
        fbx_props props = fbx_props_of(s->objects[cur].node);
        uint32_t at = fbx_prop_payload(props);
        for (size_t n = 0; n < sizeof names / sizeof names[0]; n++) {
            if (depth > 0 && n >= 9) break;  /* an ancestor's geometric transform is not inherited */
            const fbx_node *p = fbx_prop_find(props, names[n]);
            for (uint32_t k = at; p && k < p->value_count && k < at + 3; k++) {
                double x;
                if (fbx_value_float(&p->values[k], &x) && !isfinite(x))
                    return fbx_error_not_finite(s->doc, p, k, "'%s' %c of model '%.*s' (transform of mesh '%s')", names[n],
                                                "xyz"[k - at], (int)s->objects[cur].name_length, s->objects[cur].name,
                                                mesh_name);
            }
        }
    }
    char path[160];
    fbx_node_path(s->objects[o].node, path, sizeof path);
    return mk_error_set(s->doc->err, MK_ERROR_NOT_FINITE, s->objects[o].node->offset,
                        "FBX %s '%s' (byte %llu): transform is not finite (NaN, infinite or beyond float range)", path,
                        mesh_name, (unsigned long long)s->objects[o].node->offset);
}

/* ---- blend shapes ---- */

static char *dup_name(scene *s, const char *name, uint32_t length)
{
    return mk_arena_strndup(&s->raw->arena, name ? name : "", name ? length : 0);
}

/* A mesh's channels in file order (fbx_add_channels adds them), each with the (object,
 * property) its animation is bound to. */
typedef struct channel_key {
    uint32_t object;
    const char *prop;
    uint32_t prop_length;
} channel_key;

typedef struct found_channels {
    fbx_channel_plan *plans;
    channel_key *keys;
    uint32_t count, cap;
} found_channels;

/* Appends a channel; takes `shapes` and `full_weights` (doc arena), also when it fails. */
static mk_result found_add(scene *s, found_channels *f, const char *name, uint32_t name_length, double default_percent,
                           fbx_shape_ref *shapes, uint32_t shape_count, double *full_weights, size_t full_weight_count,
                           const fbx_node *vertex_weights, channel_key key)
{
    fbx_doc *doc = s->doc;
    if (f->count == f->cap) {
        uint32_t cap = f->cap ? f->cap * 2 : 16;
        fbx_channel_plan *plans = mk_arena_realloc(doc->arena, f->plans, f->cap * sizeof *plans, cap * sizeof *plans);
        if (plans) f->plans = plans;
        channel_key *keys =
            plans ? mk_arena_realloc(doc->arena, f->keys, f->cap * sizeof *keys, cap * sizeof *keys) : NULL;
        if (!keys) {
            mk_arena_release(doc->arena, shapes);
            mk_arena_release(doc->arena, full_weights);
            return mk_error_oom(doc->err, "FBX channels");
        }
        f->keys = keys;
        f->cap = cap;
    }
    f->plans[f->count] = (fbx_channel_plan){ .name = name, .name_length = name_length, .default_percent = default_percent,
                                            .shapes = shapes, .shape_count = shape_count, .full_weights = full_weights,
                                            .full_weight_count = full_weight_count, .vertex_weights = vertex_weights,
                                            .channel = UINT32_MAX };
    f->keys[f->count++] = key;
    return MK_OK;
}

static void found_free(scene *s, found_channels *f)
{
    for (uint32_t i = 0; i < f->count; i++) {
        mk_arena_release(s->doc->arena, f->plans[i].shapes);
        mk_arena_release(s->doc->arena, (void *)f->plans[i].full_weights);
    }
    mk_arena_release(s->doc->arena, f->plans);
    mk_arena_release(s->doc->arena, f->keys);
    memset(f, 0, sizeof *f);
}

/* DeformPercent from the Properties70 property, else the plain field (Blender, ZBrush). */
static double deform_percent(const fbx_node *node)
{
    double value;
    if (fbx_prop_number_opt(fbx_props_of(node), "DeformPercent", &value)) return value;
    if (fbx_child_float(node, "DeformPercent", &value)) return value;
    return 0.0;
}

static mk_result find_channels_7x(scene *s, uint32_t geometry, found_channels *found)
{
    fbx_doc *doc = s->doc;
    uint32_t deformer_cursor = 0;
    const conn *dc;
    while ((dc = child_of_kind(s, geometry, OBJ_BLEND, &deformer_cursor)) != NULL) {
        uint32_t deformer = dc->src, channel_cursor = 0;
        const conn *cc;
        while ((cc = child_of_kind(s, deformer, OBJ_CHANNEL, &channel_cursor)) != NULL) {
            const object *ch = &s->objects[cc->src];
            uint32_t count = 0, cursor = 0;
            while (child_of_kind(s, cc->src, OBJ_SHAPE, &cursor)) count++;
            fbx_shape_ref *shapes = mk_arena_array(doc->arena, count ? count : 1, sizeof(fbx_shape_ref));
            if (!shapes) return mk_error_oom(doc->err, "FBX shapes");
            cursor = 0;
            for (uint32_t i = 0; i < count; i++) {
                const conn *sc = child_of_kind(s, cc->src, OBJ_SHAPE, &cursor);
                shapes[i].node = s->objects[sc->src].node;
                shapes[i].name = s->objects[sc->src].name;
                shapes[i].name_length = s->objects[sc->src].name_length;
            }
            /* Blender: a one-shape channel's FullWeights are per-vertex weights (fbx_shapes.h). */
            const fbx_node *fw_node = fbx_child(ch->node, "FullWeights");
            const fbx_node *vertex_weights =
                s->blender && count == 1 && fw_node && fbx_node_array_length(fw_node) > 0 ? fw_node : NULL;
            double *full_weights = NULL;
            size_t fw_count = 0;
            mk_result r = vertex_weights ? MK_OK
                          : fbx_child_array(doc, ch->node, "FullWeights", FBX_ELEM_F64, (void **)&full_weights, &fw_count);
            if (r != MK_OK) {
                mk_arena_release(doc->arena, shapes);
                return r;
            }
            channel_key key = { cc->src, "DeformPercent", 13 };
            r = found_add(s, found, ch->name, ch->name_length, deform_percent(ch->node), shapes, count, full_weights,
                          fw_count, vertex_weights, key);
            if (r != MK_OK) return r;
        }
    }
    return MK_OK;
}

/* FBX <= 7100: `Shape: "Name"` children of the geometry node, weight = same-named property of
 * `weight_holder` (Geometry in 7100, Model in 6.x), animation bound to (bind_object, name). */
static mk_result find_legacy_shapes(scene *s, const fbx_node *geometry, const fbx_node *weight_holder,
                                    uint32_t bind_object, found_channels *found)
{
    const fbx_node *shape = NULL;
    fbx_props props = fbx_props_of(weight_holder);
    while ((shape = fbx_next_child(geometry, shape, "Shape")) != NULL) {
        fbx_shape_ref *ref = mk_arena_alloc(s->doc->arena, sizeof *ref);
        if (!ref) return mk_error_oom(s->doc->err, "FBX shapes");
        ref->node = shape;
        if (shape->value_count < 1 || !fbx_value_string(&shape->values[0], &ref->name, &ref->name_length)) {
            ref->name = "";
            ref->name_length = 0;
        }
        split_name(ref->name, ref->name_length, &ref->name, &ref->name_length);
        /* Weight: property named after the shape; FBX 5 keeps it as Channel: "<name> (Shape)" Default. */
        double percent = 0.0;
        char prop_name[300];
        if (ref->name_length < 256) {
            memcpy(prop_name, ref->name, ref->name_length);
            prop_name[ref->name_length] = 0;
            if (!fbx_prop_number_opt(props, prop_name, &percent)) {
                const fbx_node *ch = NULL;
                memcpy(prop_name + ref->name_length, " (Shape)", 9);
                while ((ch = fbx_next_child(weight_holder, ch, "Channel")) != NULL) {
                    const char *n;
                    uint32_t nl;
                    if (ch->value_count && fbx_value_string(&ch->values[0], &n, &nl) && str_eq(n, nl, prop_name))
                        fbx_child_float(ch, "Default", &percent);
                }
            }
        }
        channel_key key = { bind_object, ref->name, ref->name_length };
        mk_result r = found_add(s, found, ref->name, ref->name_length, percent, ref, 1, NULL, 0, NULL, key);
        if (r != MK_OK) return r;
    }
    return MK_OK;
}

/* The blend shape channels of a mesh: found in file order, added by fbx_add_channels (shapes
 * decoded and expanded on worker threads), then bound to their animation. An error while
 * finding them is reported after the channels found before it, as those come first in the file. */
static mk_result mesh_channels(scene *s, const fbx_node *geometry, int32_t geometry_object, uint32_t model,
                               uint32_t mesh, fbx_mesh_map *map)
{
    found_channels found;
    memset(&found, 0, sizeof found);
    mk_result r;
    if (geometry_object >= 0) {
        r = find_channels_7x(s, (uint32_t)geometry_object, &found);
        if (r == MK_OK && fbx_child(geometry, "Shape"))
            r = find_legacy_shapes(s, geometry, geometry, (uint32_t)geometry_object, &found);
    } else {
        r = find_legacy_shapes(s, geometry, geometry, model, &found);
    }
    mk_result added = fbx_add_channels(s->doc, s->raw, s->options, mesh, map, found.plans, found.count);
    if (added != MK_OK) r = added;
    for (uint32_t i = 0; i < found.count && r == MK_OK; i++)
        if (found.plans[i].channel != UINT32_MAX)
            r = bind(s, found.keys[i].object, found.keys[i].prop, found.keys[i].prop_length, found.plans[i].channel);
    found_free(s, &found);
    return r;
}

/* ---- meshes ---- */

/* Model subclass "Mesh" (7.x: id, name, subclass; 6.x: name, subclass). FBX 5 models have no
 * subclass, so for them only the presence of Vertices says "mesh". */
static int model_is_mesh(const scene *s, const fbx_node *model)
{
    uint32_t at = s->legacy_ids ? 1u : 2u;
    const char *sub;
    uint32_t n;
    return model->value_count > at && fbx_value_string(&model->values[at], &sub, &n) && str_eq(sub, n, "Mesh");
}

/* Blend shape channels that hang off a geometry (7.x deformers and legacy `Shape:` children),
 * so a warning about a skipped mesh can say what is lost with it. */
static uint32_t geometry_channel_count(const scene *s, int32_t geometry_object, const fbx_node *geometry)
{
    uint32_t n = 0;
    if (geometry_object >= 0) {
        uint32_t deformer_cursor = 0;
        const conn *dc;
        while ((dc = child_of_kind(s, (uint32_t)geometry_object, OBJ_BLEND, &deformer_cursor)) != NULL) {
            uint32_t channel_cursor = 0;
            while (child_of_kind(s, dc->src, OBJ_CHANNEL, &channel_cursor)) n++;
        }
    }
    for (const fbx_node *shape = NULL; (shape = fbx_next_child(geometry, shape, "Shape")) != NULL;) n++;
    return n;
}

/* Warning for a mesh that is not imported: the model's name (what the user sees in the
 * authoring tool), where its geometry is, why, and what goes with it. Library code never
 * prints: warnings are the caller's to show. */
static void warn_skipped_mesh(scene *s, uint32_t model, const fbx_node *geometry, const char *why, uint32_t channels)
{
    char path[160];
    fbx_node_path(geometry, path, sizeof path);
    const object *m = &s->objects[model];
    if (channels)
        mk_raw_warn(s->raw, "FBX model '%.*s' (%s at byte %llu): %s; skipped with its %u blend shape channel%s",
                    (int)m->name_length, m->name, path, (unsigned long long)geometry->offset, why, channels,
                    channels == 1 ? "" : "s");
    else
        mk_raw_warn(s->raw, "FBX model '%.*s' (%s at byte %llu): %s; skipped", (int)m->name_length, m->name,
                    path, (unsigned long long)geometry->offset, why);
}

/* 7.x mesh geometries that no model uses are never imported: say so, they may be what the
 * user expected to see. */
static void warn_unused_geometries(scene *s)
{
    for (uint32_t o = 0; o < s->object_count; o++) {
        if (s->objects[o].kind != OBJ_MESH) continue;
        uint32_t cursor = 0;
        if (parent_of_kind(s, o, OBJ_MODEL, &cursor)) continue;
        char path[160];
        fbx_node_path(s->objects[o].node, path, sizeof path);
        mk_raw_warn(s->raw, "FBX geometry '%.*s' (%s at byte %llu): mesh connected to no model; skipped",
                    (int)s->objects[o].name_length, s->objects[o].name, path,
                    (unsigned long long)s->objects[o].node->offset);
    }
}

/* The mesh geometry of model `o`, or NULL (geometry_object -1 for 5.x/6.x, where the Model
 * holds its geometry). Mesh models that end up without geometry are reported here. */
static const fbx_node *model_geometry(scene *s, uint32_t o, int32_t *geometry_object)
{
    const fbx_node *model = s->objects[o].node;
    *geometry_object = -1;
    if (s->legacy_ids) {
        if (fbx_child(model, "Vertices")) return model;
        if (model_is_mesh(s, model)) warn_skipped_mesh(s, o, model, "mesh has no vertices", geometry_channel_count(s, -1, model));
        return NULL;
    }
    uint32_t cursor = 0;
    const conn *c = child_of_kind(s, o, OBJ_MESH, &cursor);
    if (!c) {
        if (model_is_mesh(s, model)) warn_skipped_mesh(s, o, model, "mesh model has no mesh geometry", 0);
        return NULL;
    }
    for (const conn *extra; (extra = child_of_kind(s, o, OBJ_MESH, &cursor)) != NULL;) {
        const object *g = &s->objects[extra->src];
        char path[160];
        fbx_node_path(g->node, path, sizeof path);
        mk_raw_warn(s->raw, "FBX model '%.*s': second mesh geometry '%.*s' (%s at byte %llu) skipped; only the first is used",
                    (int)s->objects[o].name_length, s->objects[o].name, (int)g->name_length, g->name, path,
                    (unsigned long long)g->node->offset);
    }
    *geometry_object = (int32_t)c->src;
    return s->objects[c->src].node;
}

static mk_result convert_meshes(scene *s)
{
    fbx_doc *doc = s->doc;
    mk_raw_asset *raw = s->raw;
    if (!s->legacy_ids) warn_unused_geometries(s);
    for (uint32_t o = 0; o < s->object_count; o++) {
        if (s->objects[o].kind != OBJ_MODEL) continue;
        int32_t geometry_object;
        const fbx_node *geometry = model_geometry(s, o, &geometry_object);
        if (!geometry) continue;
        uint32_t mesh_index = raw->mesh_count;
        mk_raw_mesh *mesh = mk_raw_add_meshes(raw, 1);
        if (!mesh) return mk_error_oom(doc->err, "FBX mesh");
        fbx_mesh_map map;
        mk_phase_log_mark(s->options->phases, "scene");
        mk_result r = fbx_build_mesh(doc, raw, geometry, mesh, &map);
        mk_phase_log_mark(s->options->phases, "meshes");
        if (r != MK_OK) return r;
        mesh = &raw->meshes[mesh_index];
        if (mesh->vertex_count == 0) {
            /* A prop with an empty Vertices array must not refuse the whole file. Give the
             * slot back (the arena keeps its bytes; the next mesh reuses it). */
            raw->mesh_count = mesh_index;
            warn_skipped_mesh(s, o, geometry, "mesh has no vertices", geometry_channel_count(s, geometry_object, geometry));
            continue;
        }
        mesh->name = dup_name(s, s->objects[o].name, s->objects[o].name_length);
        if (!mesh->name) { fbx_mesh_map_free(doc, &map); return mk_error_oom(doc->err, "FBX mesh"); }
        mesh->stacking = MK_STACKING_ADDITIVE;  /* mk_import_finish applies the option */
        world_transform(s, o, mesh->world);
        if (!finite16(mesh->world)) {
            fbx_mesh_map_free(doc, &map);
            return transform_not_finite(s, o, mesh->name);
        }
        s->objects[o].raw_mesh = (int32_t)mesh_index;
        if (!s->legacy_ids) mesh->fbx_geometry = s->objects[geometry_object].id;
        r = mesh_channels(s, geometry, geometry_object, o, mesh_index, &map);
        fbx_mesh_map_free(doc, &map);
        mk_phase_log_mark(s->options->phases, "shapes");
        if (r != MK_OK) return r;
        /* Target normals are computed by mk_import_fbx once the parse data is released. */
    }
    return MK_OK;
}

/* ---- animation ---- */

static mk_result add_track(scene *s, uint32_t clip_index, uint32_t channel, mk_key *keys, uint32_t key_count,
                           const char *where)
{
    if (key_count == 0) return MK_OK;
    mk_raw_clip *clip = &s->raw->clips[clip_index];
    if (!s->track_seen) {
        s->track_seen = mk_arena_array(s->doc->arena, s->raw->channel_count ? s->raw->channel_count : 1, sizeof(uint32_t));
        if (!s->track_seen) return mk_error_oom(s->doc->err, "FBX tracks");
    }
    if (s->track_seen[channel] == clip_index + 1) {
        mk_raw_warn(s->raw, "FBX %s: channel '%s' is animated twice in one stack (layers?); the first curve is used",
                    where, s->raw->channels[channel].name ? s->raw->channels[channel].name : "");
        return MK_OK;
    }
    s->track_seen[channel] = clip_index + 1;
    if (s->track_clip != clip_index + 1) {  /* capacity is tracked for the clip being built */
        s->track_clip = clip_index + 1;
        s->track_cap = clip->track_count;
    }
    if (clip->track_count == s->track_cap) {
        uint32_t cap = s->track_cap ? s->track_cap * 2 : 8;
        mk_raw_track *grown = mk_arena_realloc(&s->raw->arena, clip->tracks,
                                               clip->track_count * sizeof(mk_raw_track), cap * sizeof(mk_raw_track));
        if (!grown) return mk_error_oom(s->doc->err, "FBX tracks");
        clip->tracks = grown;
        s->track_cap = cap;
    }
    mk_raw_track *tracks = clip->tracks;
    mk_raw_track *tr = &tracks[clip->track_count++];
    tr->channel = channel;
    tr->keys = keys;
    tr->key_count = key_count;
    return MK_OK;
}

static void clip_range(mk_raw_clip *clip, int has_start, double start, int has_stop, double stop)
{
    double lo = INFINITY, hi = -INFINITY;
    for (uint32_t t = 0; t < clip->track_count; t++) {
        const mk_raw_track *tr = &clip->tracks[t];
        if (tr->keys[0].time < lo) lo = tr->keys[0].time;
        if (tr->keys[tr->key_count - 1].time > hi) hi = tr->keys[tr->key_count - 1].time;
    }
    if (!has_start) start = isfinite(lo) ? lo : 0.0;
    if (!has_stop) stop = isfinite(hi) ? hi : start;
    if (!isfinite(start)) start = 0;
    if (!isfinite(stop) || stop < start) stop = start;
    clip->start = (float)start;
    clip->duration = (float)(stop - start);
}

static mk_result animation_7x(scene *s)
{
    fbx_doc *doc = s->doc;
    mk_raw_asset *raw = s->raw;
    for (uint32_t o = 0; o < s->object_count; o++) {
        if (s->objects[o].kind != OBJ_STACK) continue;
        uint32_t clip_index = raw->clip_count;
        mk_raw_clip *clip = mk_raw_add_clips(raw, 1);
        if (!clip) return mk_error_oom(doc->err, "FBX clip");
        clip->name = dup_name(s, s->objects[o].name, s->objects[o].name_length);
        if (!clip->name) return mk_error_oom(doc->err, "FBX clip");
        uint32_t layer_cursor = 0;
        const conn *lc;
        while ((lc = child_of_kind(s, o, OBJ_LAYER, &layer_cursor)) != NULL) {
            uint32_t node_cursor = 0;
            const conn *nc;
            while ((nc = child_of_kind(s, lc->src, OBJ_CURVE_NODE, &node_cursor)) != NULL) {
                const object *cn = &s->objects[nc->src];
                for (uint32_t p = 0; p < cn->parents_count; p++) {
                    const conn *target = &s->conns[s->by_src[cn->parents_first + p]];
                    if (!target->prop_length) continue;
                    size_t slot = SIZE_MAX;
                    int32_t channel = next_binding(s, target->dst, target->prop, target->prop_length, &slot);
                    if (channel < 0) continue;
                    /* The curve on the node's "d|<prop>" (any "d|" component). */
                    uint32_t curve_cursor = 0;
                    const conn *cc;
                    const fbx_node *curve = NULL;
                    while ((cc = child_of_kind(s, nc->src, OBJ_CURVE, &curve_cursor)) != NULL)
                        if (cc->prop_length >= 2 && cc->prop[0] == 'd' && cc->prop[1] == '|') { curve = s->objects[cc->src].node; break; }
                    if (!curve) continue;
                    mk_key *keys;
                    uint32_t key_count;
                    mk_result r = fbx_convert_curve(doc, raw, curve, s->ticks, 0.01, &keys, &key_count);
                    if (r != MK_OK) return r;
                    char path[160];
                    fbx_node_path(curve, path, sizeof path);
                    /* Instanced geometry: every model's copy of the channel shares the keys. */
                    for (; channel >= 0; channel = next_binding(s, target->dst, target->prop, target->prop_length, &slot))
                        if ((r = add_track(s, clip_index, (uint32_t)channel, keys, key_count, path)) != MK_OK) return r;
                }
            }
        }
        clip = &raw->clips[clip_index];
        fbx_props props = fbx_props_of(s->objects[o].node);
        int64_t start = 0, stop = 0;
        int has_start = fbx_prop_int64(props, "LocalStart", &start);
        int has_stop = fbx_prop_int64(props, "LocalStop", &stop);
        clip_range(clip, has_start, (double)start / s->ticks, has_stop, (double)stop / s->ticks);
    }
    return MK_OK;
}

static mk_result animation_takes(scene *s)
{
    fbx_doc *doc = s->doc;
    mk_raw_asset *raw = s->raw;
    const fbx_node *takes = fbx_child(&doc->root, "Takes");
    const fbx_node *take = NULL;
    while ((take = fbx_next_child(takes, take, "Take")) != NULL) {
        uint32_t clip_index = raw->clip_count;
        mk_raw_clip *clip = mk_raw_add_clips(raw, 1);
        if (!clip) return mk_error_oom(doc->err, "FBX clip");
        const char *name = "";
        uint32_t name_length = 0;
        if (take->value_count) fbx_value_string(&take->values[0], &name, &name_length);
        clip->name = dup_name(s, name, name_length);
        if (!clip->name) return mk_error_oom(doc->err, "FBX clip");
        const fbx_node *model = NULL;
        while ((model = fbx_next_child(take, model, "Model")) != NULL) {
            const char *full;
            uint32_t full_length;
            if (!model->value_count || !fbx_value_string(&model->values[0], &full, &full_length)) continue;
            int32_t o = find_object(s, legacy_id(full, full_length));
            if (o < 0) continue;
            const fbx_node *ch = NULL;
            while ((ch = fbx_next_child(model, ch, "Channel")) != NULL) {
                const char *cname;
                uint32_t cname_length;
                if (!ch->value_count || !fbx_value_string(&ch->values[0], &cname, &cname_length)) continue;
                /* Pre-6000 files name shape channels "<shape> (Shape)" (ufbx). */
                if (doc->version < 6000 && cname_length > 8 && memcmp(cname + cname_length - 8, " (Shape)", 8) == 0)
                    cname_length -= 8;
                size_t slot = SIZE_MAX;
                int32_t channel = next_binding(s, (uint32_t)o, cname, cname_length, &slot);
                if (channel < 0) continue;
                mk_key *keys;
                uint32_t key_count;
                mk_result r = fbx_convert_legacy_curve(doc, raw, ch, s->ticks, 0.01, &keys, &key_count);
                if (r != MK_OK) return r;
                char path[160];
                fbx_node_path(ch, path, sizeof path);
                for (; channel >= 0; channel = next_binding(s, (uint32_t)o, cname, cname_length, &slot))
                    if ((r = add_track(s, clip_index, (uint32_t)channel, keys, key_count, path)) != MK_OK) return r;
            }
        }
        clip = &raw->clips[clip_index];
        const fbx_node *local = fbx_child(take, "LocalTime");
        int64_t start = 0, stop = 0;
        int has = local && local->value_count >= 2 && fbx_value_int(&local->values[0], &start) &&
                  fbx_value_int(&local->values[1], &stop);
        clip_range(clip, has, (double)start / s->ticks, has, (double)stop / s->ticks);
    }
    return MK_OK;
}

/* ---- global settings ---- */

static void read_globals(scene *s)
{
    fbx_doc *doc = s->doc;
    mk_raw_asset *raw = s->raw;
    const fbx_node *header = fbx_child(&doc->root, "FBXHeaderExtension");
    const char *creator = NULL;
    uint32_t creator_length = 0;
    if (!fbx_child_string(&doc->root, "Creator", &creator, &creator_length))
        fbx_child_string(header, "Creator", &creator, &creator_length);
    if (creator) {
        size_t n = creator_length < sizeof raw->source_creator - 1 ? creator_length : sizeof raw->source_creator - 1;
        memcpy(raw->source_creator, creator, n);
        raw->source_creator[n] = 0;
        const char *tag = "Blender (stable FBX IO)";
        s->blender = doc->binary && creator_length >= strlen(tag) && memcmp(creator, tag, strlen(tag)) == 0;
    }
    const fbx_node *settings = fbx_child(&doc->root, "GlobalSettings");
    if (!settings) {
        const fbx_node *objects = fbx_child(&doc->root, "Objects");
        settings = fbx_child(objects, "GlobalSettings");
    }
    fbx_props props = fbx_props_of(settings);
    raw->up_axis = -1;
    raw->unit_scale = 0;
    if (props.block) {
        int64_t up;
        if (fbx_prop_int64(props, "UpAxis", &up) && up >= 0 && up <= 2) raw->up_axis = (int32_t)up;
        double unit;
        if (fbx_prop_number_opt(props, "UnitScaleFactor", &unit) && isfinite(unit)) raw->unit_scale = (float)unit;
    }
    s->ticks = fbx_doc_ticks(doc);
}

mk_result fbx_convert(fbx_doc *doc, const mk_import_options *options, mk_raw_asset *raw)
{
    scene s;
    memset(&s, 0, sizeof s);
    s.doc = doc;
    s.raw = raw;
    s.options = options;
    s.legacy_ids = doc->version < 7000;
    snprintf(raw->source_format, sizeof raw->source_format, "fbx %u %s", doc->version, doc->binary ? "binary" : "ascii");
    read_globals(&s);
    mk_result r = build_objects(&s);
    if (r == MK_OK) r = build_connections(&s);
    if (r == MK_OK) r = build_parents(&s);
    if (r == MK_OK) {
        s.world = mk_arena_array(doc->arena, s.object_count ? s.object_count : 1, 16 * sizeof(double));
        s.world_state = mk_arena_array(doc->arena, s.object_count ? s.object_count : 1, 1);
        if (!s.world || !s.world_state) r = mk_error_oom(doc->err, "FBX transforms");
    }
    if (r == MK_OK) r = convert_meshes(&s);
    mk_phase_log_mark(options->phases, "scene");
    if (r == MK_OK) r = doc->version >= 7000 ? animation_7x(&s) : animation_takes(&s);
    mk_phase_log_mark(options->phases, "animation");
    return r;
}

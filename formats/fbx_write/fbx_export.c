/* SPDX-License-Identifier: MIT */
/* A raw asset as a new binary FBX 7.4 file (fbx_write.h, mk_fbx_export).
 *
 * Top level: FBXHeaderExtension, FileId, CreationTime, Creator, GlobalSettings (axes and unit
 * of the source when the asset knows them: an FBX's own, glTF's Y up in metres; else Y up and
 * 1 cm per unit), Definitions (object
 * counts), Objects, Connections, then the footer. FileId, CreationTime and the footer's 16
 * bytes are the fixed values Blender's exporter writes (every FBX reader accepts that triple).
 *
 * Per mesh: Model "Mesh" at the root (Lcl Translation / Rotation (XYZ, degrees) / Scaling from
 * the world transform) <-OO- Geometry "Mesh": Vertices (one per control point: the position of
 * its render vertices, which must agree), PolygonVertexIndex (the triangles on control points,
 * the last corner of each as ~index), a LayerElementNormal by polygon vertex (the render
 * vertices' normals) in layer 0. A mesh with channels gets a BlendShape deformer -OO-> the
 * Geometry, its channels and the clips as fbx_objects.c writes them. */
#include <math.h>
#include <string.h>
#include "fbx_internal.h"
#include "fbx_objects.h"

#define FBX_EXPORT_VERSION 7400
#define DEGREES_PER_RADIAN 57.295779513082320876798154814105

static const uint8_t file_id[16] = { 0x28, 0xb3, 0x2a, 0xeb, 0xb6, 0x24, 0xcc, 0xc2,
                                     0xbf, 0xc8, 0xb0, 0x2a, 0xa9, 0x2b, 0xfc, 0xf1 };
static const uint8_t footer_id[16] = { 0xfa, 0xbc, 0xab, 0x09, 0xd0, 0xc8, 0xd4, 0x66,
                                       0xb1, 0x76, 0xfb, 0x83, 0x1c, 0xf7, 0x26, 0x7e };
static const uint8_t footer_magic[16] = { 0xf8, 0x5a, 0x8c, 0x6a, 0xde, 0xf5, 0xd9, 0x7e,
                                          0xec, 0xe9, 0x0c, 0xe3, 0x75, 0x8f, 0x29, 0x0b };

typedef struct exporter {
    fbx_objects o;
    const mk_raw_asset *raw;
    fbx_wnode **top;          /* top-level nodes */
    uint32_t top_count;
} exporter;

#define OOM(e) fbx_objects_oom(&(e)->o)

static fbx_wnode *top_node(exporter *e, const char *name)
{
    static const uint32_t cap = 16;
    if (!e->top) e->top = mk_arena_array(e->o.a, cap, sizeof *e->top);
    if (!e->top || e->top_count == cap) return NULL;
    fbx_wnode *n = fbx_wn_new(e->o.a, name);
    if (n) e->top[e->top_count++] = n;
    return n;
}

static int child_int(exporter *e, fbx_wnode *parent, const char *name, int32_t v)
{
    return fbx_wn_int(e->o.a, fbx_wn_child(e->o.a, parent, name), v);
}

static int child_string(exporter *e, fbx_wnode *parent, const char *name, const char *s)
{
    fbx_wnode *n = fbx_wn_child(e->o.a, parent, name);
    return n && fbx_wn_string(e->o.a, n, s, strlen(s));
}

static int prop_int(exporter *e, fbx_wnode *props, const char *name, int32_t v)
{
    return fbx_wn_prop(e->o.a, props, name, "int", "Integer", "", (fbx_wvalue){ .type = 'I', .u.i = v }) != NULL;
}

static int prop_vec3(exporter *e, fbx_wnode *props, const char *name, const double v[3])
{
    fbx_wnode *p = fbx_wn_prop(e->o.a, props, name, name, "", "A", (fbx_wvalue){ .type = 'D', .u.d = v[0] });
    return p && fbx_wn_double(e->o.a, p, v[1]) && fbx_wn_double(e->o.a, p, v[2]);
}

static mk_result header(exporter *e)
{
    fbx_wnode *h = top_node(e, "FBXHeaderExtension");
    fbx_wnode *stamp = h ? fbx_wn_child(e->o.a, h, "CreationTimeStamp") : NULL;
    static const char *const stamp_fields[8] = { "Version", "Year", "Month", "Day", "Hour", "Minute", "Second", "Millisecond" };
    static const int32_t stamp_values[8] = { 1000, 1970, 1, 1, 10, 0, 0, 0 };
    if (!stamp || !child_int(e, h, "FBXHeaderVersion", 1003) || !child_int(e, h, "FBXVersion", FBX_EXPORT_VERSION) ||
        !child_int(e, h, "EncryptionType", 0))
        return OOM(e);
    for (int i = 0; i < 8; i++)
        if (!child_int(e, stamp, stamp_fields[i], stamp_values[i])) return OOM(e);
    if (!child_string(e, h, "Creator", "morphkit")) return OOM(e);
    fbx_wnode *id = top_node(e, "FileId"), *time = top_node(e, "CreationTime"), *creator = top_node(e, "Creator");
    if (!id || !fbx_wn_add(e->o.a, id, (fbx_wvalue){ .type = 'R', .count = 16, .u.s = (const char *)file_id }) ||
        !time || !fbx_wn_string(e->o.a, time, "1970-01-01 10:00:00:000", 23) || !creator ||
        !fbx_wn_string(e->o.a, creator, "morphkit", 8))
        return OOM(e);
    const mk_raw_asset *raw = e->raw;
    /* glTF is Y up in metres (100 cm per unit); an FBX source says its own; a blob does not
     * record them: Y up, 1 cm per unit. */
    const int gltf = strncmp(raw->source_format, "gltf", 4) == 0;
    const int up = !gltf && raw->up_axis >= 0 && raw->up_axis <= 2 ? raw->up_axis : 1;
    const double unit = gltf ? 100.0 : raw->unit_scale > 0 ? raw->unit_scale : 1.0;
    fbx_wnode *g = top_node(e, "GlobalSettings");
    fbx_wnode *props = g ? fbx_wn_child(e->o.a, g, "Properties70") : NULL;
    /* Right-handed axes: up, front and coordinate axes as Maya (Y up: front Z, coord X) and
     * 3ds Max (Z up: front -Y, coord X) write them. */
    const int front = up == 2 ? 1 : 2, front_sign = up == 2 ? -1 : 1, coord = up == 0 ? 1 : 0;
    if (!props || !child_int(e, g, "Version", 1000) || !prop_int(e, props, "UpAxis", up) ||
        !prop_int(e, props, "UpAxisSign", 1) || !prop_int(e, props, "FrontAxis", front) ||
        !prop_int(e, props, "FrontAxisSign", front_sign) || !prop_int(e, props, "CoordAxis", coord) ||
        !prop_int(e, props, "CoordAxisSign", 1) ||
        !fbx_wn_prop(e->o.a, props, "UnitScaleFactor", "double", "Number", "", (fbx_wvalue){ .type = 'D', .u.d = unit }))
        return OOM(e);
    return MK_OK;
}

/* World (column-major) = T R S with R = Rz Ry Rx (FBX's XYZ order): translation, rotation in
 * degrees and scale, or MK_ERROR_UNSUPPORTED when the matrix has shear or projection. */
static mk_result decompose(exporter *e, const mk_raw_mesh *m, double t[3], double r[3], double s[3])
{
    const float *w = m->world;
    double c[3][3];  /* c[j]: column j */
    for (int j = 0; j < 3; j++) {
        t[j] = w[12 + j];
        for (int i = 0; i < 3; i++) c[j][i] = w[4 * j + i];
        s[j] = sqrt(c[j][0] * c[j][0] + c[j][1] * c[j][1] + c[j][2] * c[j][2]);
    }
    const double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) - c[1][0] * (c[0][1] * c[2][2] - c[0][2] * c[2][1]) +
                       c[2][0] * (c[0][1] * c[1][2] - c[0][2] * c[1][1]);
    if (det < 0) s[0] = -s[0];
    double R[3][3];  /* R[row][col] */
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) R[i][j] = s[j] != 0 ? c[j][i] / s[j] : (i == j);
    const double cos_b = sqrt(R[0][0] * R[0][0] + R[1][0] * R[1][0]);
    const double b = atan2(-R[2][0], cos_b);
    double a, g;
    if (cos_b > 1e-6) {
        a = atan2(R[2][1], R[2][2]);
        g = atan2(R[1][0], R[0][0]);
    } else {  /* gimbal lock: only a - g (b = 90 degrees) or a + g (b = -90) is known; g = 0 */
        a = atan2(-R[1][2], R[1][1]);
        g = 0;
    }
    r[0] = a * DEGREES_PER_RADIAN;
    r[1] = b * DEGREES_PER_RADIAN;
    r[2] = g * DEGREES_PER_RADIAN;
    /* Recompose and compare: what FBX can say must give the same matrix. */
    const double ca = cos(a), sa = sin(a), cb = cos(b), sbb = sin(b), cg = cos(g), sg = sin(g);
    const double Q[3][3] = { { cg * cb, cg * sbb * sa - sg * ca, cg * sbb * ca + sg * sa },
                             { sg * cb, sg * sbb * sa + cg * ca, sg * sbb * ca - cg * sa },
                             { -sbb, cb * sa, cb * ca } };
    double scale = 1e-30, worst = 0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            scale = fmax(scale, fabs(c[j][i]));
            worst = fmax(worst, fabs(Q[i][j] * s[j] - c[j][i]));
        }
    if (worst > 1e-5 * scale || w[3] != 0 || w[7] != 0 || w[11] != 0 || w[15] != 1)
        return mk_error_set(e->o.err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                            "FBX export: mesh '%s' has a transform with shear or projection (%g off); an FBX model holds "
                            "translation, rotation and scale",
                            m->name, worst);
    return MK_OK;
}

static mk_result mesh(exporter *e, uint32_t mi, int64_t *channel_ids)
{
    fbx_objects *o = &e->o;
    const mk_raw_asset *raw = e->raw;
    const mk_raw_mesh *m = &raw->meshes[mi];
    uint32_t *render_count;
    double tolerance;
    mk_result r = fbx_objects_mesh(o, m, &render_count, &tolerance);
    if (r == MK_OK) r = fbx_object_check_name(o, "mesh", m->name);
    double t[3], rot[3], s[3];
    if (r == MK_OK) r = decompose(e, m, t, rot, s);
    if (r != MK_OK) return r;
    const uint32_t cps = m->control_point_count;
    if (cps > UINT32_MAX / 3 || m->triangle_count > UINT32_MAX / 9)
        return mk_error_set(o->err, MK_ERROR_LIMIT, UINT64_MAX, "FBX export: mesh '%s' is larger than an FBX array can hold",
                            m->name);
    double *points = mk_arena_array(o->a, cps, 3 * sizeof(double));
    int32_t *corners = mk_arena_array(o->a, 3 * (size_t)m->triangle_count + 1, sizeof(int32_t));
    double *normals = m->normals ? mk_arena_array(o->a, 9 * (size_t)m->triangle_count + 1, sizeof(double)) : NULL;
    uint8_t *seen = mk_arena_array(o->a, cps, 1);
    if (!points || !corners || (m->normals && !normals) || !seen) return OOM(e);
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        const uint32_t cp = m->control_points[v];
        for (int k = 0; k < 3; k++) {
            const double p = m->positions[3 * v + k];
            if (seen[cp] && fabs(points[3 * cp + k] - p) > tolerance)
                return mk_error_set(o->err, MK_ERROR_UNSUPPORTED, UINT64_MAX,
                                    "FBX export: mesh '%s': render vertices of control point %u are %g apart; an FBX "
                                    "control point has one position", m->name, cp, fabs(points[3 * cp + k] - p));
            if (!seen[cp]) points[3 * cp + k] = p;
        }
        seen[cp] = 1;
    }
    for (uint32_t i = 0; i < 3 * m->triangle_count; i++) {
        const uint32_t v = m->triangles[i];
        const int32_t cp = (int32_t)m->control_points[v];
        corners[i] = i % 3 == 2 ? ~cp : cp;
        for (int k = 0; normals && k < 3; k++) normals[3 * (size_t)i + k] = m->normals[3 * v + k];
    }
    int64_t model_id, geometry_id;
    fbx_wnode *model = fbx_object_new(o, "Model", "Model", m->name, "Mesh", &model_id);
    fbx_wnode *props = model ? fbx_wn_child(o->a, model, "Properties70") : NULL;
    if (!props || !child_int(e, model, "Version", 232) || !prop_vec3(e, props, "Lcl Translation", t) ||
        !prop_vec3(e, props, "Lcl Rotation", rot) || !prop_vec3(e, props, "Lcl Scaling", s) ||
        !child_string(e, model, "Culling", "CullingOff") || !fbx_object_connect(o, "OO", model_id, 0, NULL))
        return OOM(e);
    fbx_wnode *g = fbx_object_new(o, "Geometry", "Geometry", m->name, "Mesh", &geometry_id);
    if (!g || !fbx_wn_array(o->a, g, "Vertices", 'd', points, 3 * cps) ||
        !fbx_wn_array(o->a, g, "PolygonVertexIndex", 'i', corners, 3 * m->triangle_count) ||
        !child_int(e, g, "GeometryVersion", 124) || !fbx_object_connect(o, "OO", geometry_id, model_id, NULL))
        return OOM(e);
    if (normals) {
        fbx_wnode *layer_normals = fbx_wn_child(o->a, g, "LayerElementNormal");
        fbx_wnode *layer = fbx_wn_child(o->a, g, "Layer");
        fbx_wnode *element = layer ? fbx_wn_child(o->a, layer, "LayerElement") : NULL;
        if (!layer_normals || !fbx_wn_int(o->a, layer_normals, 0) || !child_int(e, layer_normals, "Version", 101) ||
            !child_string(e, layer_normals, "Name", "") ||
            !child_string(e, layer_normals, "MappingInformationType", "ByPolygonVertex") ||
            !child_string(e, layer_normals, "ReferenceInformationType", "Direct") ||
            !fbx_wn_array(o->a, layer_normals, "Normals", 'd', normals, 9 * m->triangle_count) ||
            !element || !fbx_wn_int(o->a, layer, 0) || !child_int(e, layer, "Version", 100) ||
            !child_string(e, element, "Type", "LayerElementNormal") || !child_int(e, element, "TypedIndex", 0))
            return OOM(e);
    }
    int64_t blend = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++) {
        if (raw->channels[c].mesh != mi) continue;
        if (!blend) {
            fbx_wnode *b = fbx_object_new(o, "Deformer", "Deformer", m->name, "BlendShape", &blend);
            if (!b || !child_int(e, b, "Version", 100) || !fbx_object_connect(o, "OO", blend, geometry_id, NULL))
                return OOM(e);
            o->report->blend_shapes++;
        }
        if ((r = fbx_objects_add_channel(o, m, render_count, tolerance, &raw->channels[c], blend, &channel_ids[c])) != MK_OK)
            return r;
    }
    o->report->meshes++;
    return MK_OK;
}

/* Definitions: the count of each object type written. */
static mk_result definitions(exporter *e, fbx_wnode *defs)
{
    static const char *const types[] = { "Model", "Geometry", "Deformer", "AnimationStack", "AnimationLayer",
                                         "AnimationCurveNode", "AnimationCurve" };
    const uint32_t ntypes = sizeof types / sizeof *types;
    int32_t counts[sizeof types / sizeof *types] = { 0 }, total = 1;
    for (uint32_t i = 0; i < e->o.object_count; i++)
        for (uint32_t k = 0; k < ntypes; k++)
            if (!strcmp(e->o.objects[i]->name, types[k])) counts[k]++;
    for (uint32_t k = 0; k < ntypes; k++) total += counts[k];
    fbx_wnode *global = fbx_wn_child(e->o.a, defs, "ObjectType");
    if (!child_int(e, defs, "Version", 100) || !child_int(e, defs, "Count", total) || !global ||
        !fbx_wn_string(e->o.a, global, "GlobalSettings", 14) || !child_int(e, global, "Count", 1))
        return OOM(e);
    for (uint32_t k = 0; k < ntypes; k++) {
        if (!counts[k]) continue;
        fbx_wnode *t = fbx_wn_child(e->o.a, defs, "ObjectType");
        if (!t || !fbx_wn_string(e->o.a, t, types[k], strlen(types[k])) || !child_int(e, t, "Count", counts[k]))
            return OOM(e);
    }
    return MK_OK;
}

static mk_result build(exporter *e)
{
    const mk_raw_asset *raw = e->raw;
    mk_result r = header(e);
    if (r != MK_OK) return r;
    fbx_wnode *defs = top_node(e, "Definitions");
    fbx_wnode *objects = top_node(e, "Objects"), *connections = top_node(e, "Connections");
    int64_t *channel_ids = mk_arena_array(e->o.a, raw->channel_count ? raw->channel_count : 1, sizeof(int64_t));
    if (!defs || !objects || !connections || !channel_ids) return OOM(e);
    for (uint32_t mi = 0; mi < raw->mesh_count; mi++)
        if ((r = mesh(e, mi, channel_ids)) != MK_OK) return r;
    for (uint32_t k = 0; k < raw->clip_count; k++)
        if ((r = fbx_objects_add_clip(&e->o, &raw->clips[k], channel_ids, NULL)) != MK_OK) return r;
    if ((r = definitions(e, defs)) != MK_OK) return r;
    objects->children = e->o.objects;
    objects->child_count = objects->child_cap = e->o.object_count;
    connections->children = e->o.connections;
    connections->child_count = connections->child_cap = e->o.connection_count;
    return MK_OK;
}

mk_result mk_fbx_export(const mk_raw_asset *raw, mk_arena *arena, void **out, size_t *out_size,
                        mk_fbx_write_report *report, mk_error *err)
{
    mk_fbx_write_report local_report;
    mk_error local_err;
    if (!report) report = &local_report;
    if (!err) err = &local_err;
    memset(report, 0, sizeof *report);
    if (!raw || !arena || !out || !out_size)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_fbx_export: NULL argument");
    mk_arena scratch;
    mk_arena_init(&scratch, &arena->allocator);
    /* FBX 7.4 with FBXHeaderVersion 1003: the old tick rate */
    exporter e = { .o = { .a = &scratch, .err = err, .binary = 1, .next_id = 1000000, .ticks = FBX_TICKS_PER_SECOND_OLD,
                          .report = report },
                   .raw = raw };
    mk_result r = build(&e);
    fbx_bytes bytes = { .arena = arena };
    if (r == MK_OK) {
        static const uint8_t zeros[160];
        uint8_t head[27];
        memcpy(head, "Kaydara FBX Binary  \0\x1a\0", 23);
        for (int i = 0; i < 4; i++) head[23 + i] = (uint8_t)(FBX_EXPORT_VERSION >> (8 * i));
        fbx_bytes_append(&bytes, head, sizeof head);
        for (uint32_t i = 0; i < e.top_count; i++) fbx_wn_write_binary(&bytes, e.top[i], 0, 0);
        fbx_bytes_append(&bytes, zeros, 13);  /* the top-level null record */
        fbx_bytes_append(&bytes, footer_id, 16);
        fbx_bytes_append(&bytes, zeros, 4);
        /* zero padding to a 16-byte boundary (a full 16 when already there), the version, 120 zero bytes */
        const size_t pad = 16 - (bytes.size & 15);
        fbx_bytes_append(&bytes, zeros, pad);
        uint8_t version[4];
        for (int i = 0; i < 4; i++) version[i] = (uint8_t)(FBX_EXPORT_VERSION >> (8 * i));
        fbx_bytes_append(&bytes, version, 4);
        fbx_bytes_append(&bytes, zeros, 120);
        fbx_bytes_append(&bytes, footer_magic, 16);
        if (bytes.failed) r = mk_error_oom(err, "FBX output");
        else if (bytes.too_large)
            r = mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "FBX export: the file would pass 4 GiB (FBX 7.4's record offsets are 32-bit)");
    }
    if (r == MK_OK) {
        *out = bytes.data;
        *out_size = bytes.size;
    } else {
        mk_arena_release(arena, bytes.data);
        memset(report, 0, sizeof *report);
    }
    mk_arena_free_all(&scratch);
    return r;
}

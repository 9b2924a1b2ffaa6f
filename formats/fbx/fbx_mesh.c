/* SPDX-License-Identifier: MIT */
/* FBX mesh geometry into a raw mesh: control points, polygons, normal and UV layer elements,
 * render vertices and triangles; and blend shape deltas expanded onto render vertices.
 *
 * Render vertices: one per distinct (control point, normal, UV) of the polygon vertices, as an
 * engine's vertex buffer splits them at hard edges and UV seams. mk_raw_mesh.control_points
 * maps each back to its control point. Control points no polygon uses still get one isolated
 * render vertex, so every control point of the file has a position in the output.
 *
 * Layer elements (FBX SDK FbxLayerElement; ufbx.c ufbxi_read_vertex_element): mapping
 * ByPolygonVertex / ByVertex (ByVertice, ByControlPoint) / ByPolygon / AllSame, reference
 * Direct or IndexToDirect (the presence of the <Name>Index array decides, as in ufbx). Some old
 * exporters write ByPolygon meaning ByPolygonVertex: when the element count equals the
 * polygon-vertex count it is read that way (ufbx does the same). ByEdge is not supported.
 *
 * Triangulation: polygons are fanned from their first vertex once, with base positions, and
 * every target reuses these triangles (three.js #28378 shows what goes wrong otherwise).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fbx_mesh.h"

enum { MAP_NONE, MAP_PV, MAP_CP, MAP_POLY, MAP_ALL };

typedef struct layer {
    const fbx_node *node;   /* the data array's node (for error messages) */
    int mapping;
    int stride;
    float *data;            /* decoded as float: what the raw model keeps, half the scratch */
    size_t data_count;      /* elements (data floats / stride) */
    int32_t *index;
    size_t index_count;
} layer;

static int str_is(const char *s, uint32_t n, const char *lit)
{
    size_t l = strlen(lit);
    return n == l && memcmp(s, lit, l) == 0;
}

static int parse_mapping(const fbx_node *element)
{
    const char *s;
    uint32_t n;
    if (!fbx_child_string(element, "MappingInformationType", &s, &n)) return MAP_PV;
    if (str_is(s, n, "ByPolygonVertex")) return MAP_PV;
    if (str_is(s, n, "ByVertex") || str_is(s, n, "ByVertice") || str_is(s, n, "ByControlPoint")) return MAP_CP;
    if (str_is(s, n, "ByPolygon")) return MAP_POLY;
    if (str_is(s, n, "AllSame")) return MAP_ALL;
    return MAP_NONE;  /* ByEdge, NoMappingInformation */
}

static mk_result read_layer(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *element, const char *data_name,
                            const char *index_name, int stride, size_t pv_count, layer *out)
{
    memset(out, 0, sizeof *out);
    if (!element) return MK_OK;
    out->mapping = parse_mapping(element);
    out->stride = stride;
    if (out->mapping == MAP_NONE) {
        mk_raw_warn(raw, "FBX layer element '%.*s': unsupported mapping (ByEdge?); ignored",
                    (int)element->name_length, element->name);
        return MK_OK;
    }
    size_t count;
    mk_result r = fbx_child_array(doc, element, data_name, FBX_ELEM_F32, (void **)&out->data, &count);
    if (r != MK_OK) return r;
    if (!out->data) { out->mapping = MAP_NONE; return MK_OK; }
    out->node = fbx_child(element, data_name);
    out->data_count = count / (size_t)stride;
    if (index_name) {
        r = fbx_child_array(doc, element, index_name, FBX_ELEM_I32, (void **)&out->index, &out->index_count);
        if (r != MK_OK) return r;
    }
    size_t addressed = out->index ? out->index_count : out->data_count;
    if (out->mapping == MAP_POLY && addressed == pv_count) out->mapping = MAP_PV;
    return MK_OK;
}

static void free_layer(fbx_doc *doc, layer *l)
{
    mk_arena_release(doc->arena, l->data);
    mk_arena_release(doc->arena, l->index);
    l->data = NULL;
    l->index = NULL;
}

/* Element of a layer for one polygon vertex; NULL when missing or out of range. *element is
 * its index in the data array. */
static const float *layer_value(const layer *l, size_t pv, uint32_t cp, size_t poly, size_t *bad, size_t *element)
{
    if (l->mapping == MAP_NONE || !l->data) return NULL;
    size_t i;
    switch (l->mapping) {
    case MAP_PV: i = pv; break;
    case MAP_CP: i = cp; break;
    case MAP_POLY: i = poly; break;
    default: i = 0; break;
    }
    if (l->index) {
        if (i >= l->index_count) { (*bad)++; return NULL; }
        int32_t k = l->index[i];
        if (k < 0) return NULL;  /* -1: no value for this vertex */
        i = (size_t)k;
    }
    if (i >= l->data_count) { (*bad)++; return NULL; }
    *element = i;
    return l->data + i * (size_t)l->stride;
}

/* Finds the first layer element child named `name` (index 0 is the one Layer 0 uses). */
static const fbx_node *first_element(const fbx_node *geometry, const char *name)
{
    return fbx_child(geometry, name);
}

typedef struct rv_key {
    float normal[3];
    float uv[2];
} rv_key;

static mk_result grow_vertices(mk_arena *arena, uint32_t **next, uint32_t **cp, rv_key **keys, size_t *cap, mk_error *err)
{
    size_t grown = *cap * 2;
    uint32_t *a = mk_arena_realloc(arena, *next, *cap * sizeof **next, grown * sizeof **next);
    if (a) *next = a;
    uint32_t *b = a ? mk_arena_realloc(arena, *cp, *cap * sizeof **cp, grown * sizeof **cp) : NULL;
    if (b) *cp = b;
    rv_key *c = b ? mk_arena_realloc(arena, *keys, *cap * sizeof **keys, grown * sizeof **keys) : NULL;
    if (!c) return mk_error_oom(err, "FBX render vertices");
    *keys = c;
    *cap = grown;
    return MK_OK;
}

mk_result fbx_build_mesh(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *geometry, mk_raw_mesh *mesh,
                         fbx_mesh_map *map)
{
    mk_arena *arena = doc->arena;
    mk_result r;
    char path[160];
    memset(map, 0, sizeof *map);
    double *vertices = NULL;
    int32_t *polygon_index = NULL;
    size_t vertex_doubles = 0, pv_count = 0;
    layer normals, uvs;
    memset(&normals, 0, sizeof normals);
    memset(&uvs, 0, sizeof uvs);
    uint32_t *pv_rv = NULL, *cp_head = NULL, *rv_next = NULL, *rv_cp = NULL;
    rv_key *rv_keys = NULL;
    int normals_present = 0;

    fbx_node_path(geometry, path, sizeof path);
    /* The large arrays read below, decoded together on worker threads (fbx_prefetch.c). */
    const fbx_node *normal_element = first_element(geometry, "LayerElementNormal");
    const fbx_node *uv_element = first_element(geometry, "LayerElementUV");
    const fbx_node *uv_info = uv_element ? NULL : fbx_child(geometry, "GeometryUVInfo");
    const fbx_node *ahead[] = { fbx_child(geometry, "Vertices"), fbx_child(geometry, "PolygonVertexIndex"),
                                fbx_child(normal_element, "Normals"), fbx_child(normal_element, "NormalsIndex"),
                                normal_element ? NULL : fbx_child(geometry, "Normals"), fbx_child(uv_element, "UV"),
                                fbx_child(uv_element, "UVIndex"), fbx_child(uv_info, "TextureUV"),
                                fbx_child(uv_info, "TextureUVVerticeIndex") };
    const fbx_elem as[] = { FBX_ELEM_F64, FBX_ELEM_I32, FBX_ELEM_F32, FBX_ELEM_I32, FBX_ELEM_F32,
                            FBX_ELEM_F32, FBX_ELEM_I32, FBX_ELEM_F32, FBX_ELEM_I32 };
    fbx_prefetch(doc, ahead, as, (uint32_t)(sizeof ahead / sizeof ahead[0]));
    r = fbx_child_array(doc, geometry, "Vertices", FBX_ELEM_F64, (void **)&vertices, &vertex_doubles);
    if (r != MK_OK) goto done;
    if (vertex_doubles % 3 != 0) {
        r = mk_error_set(doc->err, MK_ERROR_PARSE, geometry->offset, "FBX %s: Vertices has %zu values, not a multiple of 3",
                         path, vertex_doubles);
        goto done;
    }
    size_t cp_count = vertex_doubles / 3;
    if (cp_count == 0) {
        /* Nothing to draw or morph: the caller skips the mesh with a warning rather than
         * refusing a file whose other meshes are fine (polygons are not even read). */
        mesh->vertex_count = 0;
        r = MK_OK;
        goto done;
    }
    if (cp_count >= UINT32_MAX / 2) {
        r = mk_error_set(doc->err, MK_ERROR_LIMIT, geometry->offset, "FBX %s: too many control points", path);
        goto done;
    }
    r = fbx_child_array(doc, geometry, "PolygonVertexIndex", FBX_ELEM_I32, (void **)&polygon_index, &pv_count);
    if (r != MK_OK) goto done;
    if (pv_count >= UINT32_MAX / 2) {
        r = mk_error_set(doc->err, MK_ERROR_LIMIT, geometry->offset, "FBX %s: too many polygon vertices", path);
        goto done;
    }

    /* Normals: LayerElementNormal (6.x/7.x), or a plain Normals array on the geometry (FBX 5). */
    if (normal_element) {
        r = read_layer(doc, raw, normal_element, "Normals", "NormalsIndex", 3, pv_count, &normals);
    } else if (fbx_child(geometry, "Normals") && !fbx_child(geometry, "Indexes")) {
        size_t count;
        r = fbx_child_array(doc, geometry, "Normals", FBX_ELEM_F32, (void **)&normals.data, &count);
        normals.node = fbx_child(geometry, "Normals");
        normals.stride = 3;
        normals.data_count = count / 3;
        normals.mapping = normals.data_count == cp_count ? MAP_CP : normals.data_count == pv_count ? MAP_PV : MAP_NONE;
    }
    if (r != MK_OK) goto done;
    if (uv_element) {
        r = read_layer(doc, raw, uv_element, "UV", "UVIndex", 2, pv_count, &uvs);
    } else if (uv_info) {
        r = read_layer(doc, raw, uv_info, "TextureUV", "TextureUVVerticeIndex", 2, pv_count, &uvs);
    }
    if (r != MK_OK) goto done;
    normals_present = normals.mapping != MAP_NONE && normals.data;

    /* Render vertices: dedupe the polygon vertices of each control point by (normal, uv). */
    pv_rv = mk_arena_array(arena, pv_count ? pv_count : 1, sizeof *pv_rv);
    cp_head = mk_arena_array(arena, cp_count ? cp_count : 1, sizeof *cp_head);
    /* Render vertices: usually about one per control point; grown on demand (at most one
     * per polygon vertex plus one per isolated control point). */
    size_t rv_cap = cp_count + cp_count / 4 + 16;
    rv_next = mk_arena_array(arena, rv_cap, sizeof *rv_next);
    rv_cp = mk_arena_array(arena, rv_cap, sizeof *rv_cp);
    rv_keys = mk_arena_array(arena, rv_cap, sizeof *rv_keys);
    if (!pv_rv || !cp_head || !rv_next || !rv_cp || !rv_keys) { r = mk_error_oom(doc->err, "FBX mesh"); goto done; }
    for (size_t i = 0; i < cp_count; i++) cp_head[i] = UINT32_MAX;
    size_t rv_count = 0, poly = 0, bad_layer = 0, triangle_count = 0, degenerate = 0, poly_start = 0;
    for (size_t i = 0; i < pv_count; i++) {
        int32_t raw_index = polygon_index[i];
        int last = raw_index < 0;
        uint32_t cp = (uint32_t)(last ? ~raw_index : raw_index);
        if (cp >= cp_count) {
            r = mk_error_set(doc->err, MK_ERROR_PARSE, geometry->offset,
                             "FBX %s: PolygonVertexIndex[%zu] = %d addresses control point %u of %zu", path, i,
                             (int)raw_index, cp, cp_count);
            goto done;
        }
        rv_key key;
        memset(&key, 0, sizeof key);
        size_t element = 0;
        const float *n = normals_present ? layer_value(&normals, i, cp, poly, &bad_layer, &element) : NULL;
        if (n) {
            for (int k = 0; k < 3; k++) {
                /* Checked where a polygon vertex uses it: an unused bad normal is harmless. */
                if (!isfinite(n[k])) {
                    r = fbx_error_not_finite(doc, normals.node, 3 * element + (size_t)k, "normal %zu (of control point %u)",
                                             element, cp);
                    goto done;
                }
                key.normal[k] = n[k];
            }
        }
        const float *t = uvs.data ? layer_value(&uvs, i, cp, poly, &bad_layer, &element) : NULL;
        if (t) for (int k = 0; k < 2; k++) key.uv[k] = t[k];
        /* Walk the control point's vertices; the walk is capped so a hostile file with
         * thousands of distinct normals on one point stays linear (it just welds less). */
        uint32_t found = UINT32_MAX;
        int steps = 0;
        for (uint32_t v = cp_head[cp]; v != UINT32_MAX && steps < 32; v = rv_next[v], steps++)
            if (memcmp(&rv_keys[v], &key, sizeof key) == 0) { found = v; break; }
        if (found == UINT32_MAX) {
            if (rv_count == rv_cap && (r = grow_vertices(arena, &rv_next, &rv_cp, &rv_keys, &rv_cap, doc->err)) != MK_OK)
                goto done;
            found = (uint32_t)rv_count++;
            rv_keys[found] = key;
            rv_cp[found] = cp;
            rv_next[found] = cp_head[cp];
            cp_head[cp] = found;
        }
        pv_rv[i] = found;
        if (last || i + 1 == pv_count) {
            size_t corners = i + 1 - poly_start;
            if (corners >= 3) triangle_count += corners - 2;
            else degenerate++;
            poly_start = i + 1;
            poly++;
        }
    }
    if (pv_count && polygon_index[pv_count - 1] >= 0)
        mk_raw_warn(raw, "FBX %s: last polygon is not closed by a negative index; closed it", path);
    if (degenerate) mk_raw_warn(raw, "FBX %s: %zu polygons with fewer than 3 vertices skipped", path, degenerate);
    if (bad_layer)
        mk_raw_warn(raw, "FBX %s: %zu normal/UV layer lookups out of range (used zero)", path, bad_layer);
    /* Isolated control points (used by no polygon) still get a vertex. */
    size_t isolated = 0;
    /* The layers are no longer needed: release them before the raw arrays are allocated. */
    free_layer(doc, &normals);
    free_layer(doc, &uvs);
    for (size_t cp = 0; cp < cp_count; cp++) {
        if (cp_head[cp] != UINT32_MAX) continue;
        if (rv_count == rv_cap && (r = grow_vertices(arena, &rv_next, &rv_cp, &rv_keys, &rv_cap, doc->err)) != MK_OK)
            goto done;
        uint32_t v = (uint32_t)rv_count++;
        memset(&rv_keys[v], 0, sizeof rv_keys[v]);
        rv_cp[v] = (uint32_t)cp;
        rv_next[v] = UINT32_MAX;
        cp_head[cp] = v;
        isolated++;
    }
    (void)isolated;
    if (triangle_count > UINT32_MAX / 3) {
        r = mk_error_set(doc->err, MK_ERROR_LIMIT, geometry->offset, "FBX %s: too many triangles", path);
        goto done;
    }

    /* Raw mesh arrays (raw arena). */
    mk_arena *out = &raw->arena;
    mesh->vertex_count = (uint32_t)rv_count;
    mesh->control_point_count = (uint32_t)cp_count;
    mesh->positions = mk_arena_array(out, rv_count, 3 * sizeof(float));
    mesh->normals = mk_arena_array(out, rv_count, 3 * sizeof(float));
    mesh->control_points = mk_arena_array(out, rv_count, sizeof(uint32_t));
    mesh->triangle_count = (uint32_t)triangle_count;
    mesh->triangles = mk_arena_array(out, triangle_count ? triangle_count : 1, 3 * sizeof(uint32_t));
    if (!mesh->positions || !mesh->normals || !mesh->control_points || !mesh->triangles) {
        r = mk_error_oom(doc->err, "FBX mesh");
        goto done;
    }
    for (size_t v = 0; v < rv_count; v++) {
        uint32_t cp = rv_cp[v];
        mesh->control_points[v] = cp;
        for (int k = 0; k < 3; k++) {
            float x = (float)vertices[3 * (size_t)cp + (size_t)k];
            if (!isfinite(x)) {
                r = fbx_error_not_finite(doc, fbx_child(geometry, "Vertices"), 3 * (size_t)cp + (size_t)k, "control point %u", cp);
                goto done;
            }
            mesh->positions[3 * v + (size_t)k] = x;
        }
    }
    size_t tri = 0;
    poly_start = 0;
    for (size_t i = 0; i < pv_count; i++) {
        if (polygon_index[i] < 0 || i + 1 == pv_count) {
            size_t corners = i + 1 - poly_start;
            for (size_t k = 1; corners >= 3 && k + 1 < corners; k++) {
                mesh->triangles[3 * tri + 0] = pv_rv[poly_start];
                mesh->triangles[3 * tri + 1] = pv_rv[poly_start + k];
                mesh->triangles[3 * tri + 2] = pv_rv[poly_start + k + 1];
                tri++;
            }
            poly_start = i + 1;
        }
    }
    if (normals_present) {
        for (size_t v = 0; v < rv_count; v++) memcpy(mesh->normals + 3 * v, rv_keys[v].normal, 3 * sizeof(float));
    } else {
        /* No normals in the file: area-weighted smooth normals per control point, so targets
         * can still get normal deltas computed the same way. */
        double *acc = mk_arena_array(arena, cp_count, 3 * sizeof(double));
        if (!acc) { r = mk_error_oom(doc->err, "FBX normals"); goto done; }
        for (size_t t = 0; t < triangle_count; t++) {
            const uint32_t *tv = mesh->triangles + 3 * t;
            const double *a = vertices + 3 * (size_t)rv_cp[tv[0]];
            const double *b = vertices + 3 * (size_t)rv_cp[tv[1]];
            const double *c = vertices + 3 * (size_t)rv_cp[tv[2]];
            double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
            double e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
            double n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++) acc[3 * (size_t)rv_cp[tv[k]] + (size_t)j] += n[j];
        }
        for (size_t v = 0; v < rv_count; v++) {
            const double *n = acc + 3 * (size_t)rv_cp[v];
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int k = 0; k < 3; k++) mesh->normals[3 * v + (size_t)k] = len > 0 && isfinite(len) ? (float)(n[k] / len) : 0.0f;
        }
        mk_arena_release(arena, acc);
    }

    /* Control point -> render vertices (CSR, increasing vertex order) for blend shapes. */
    map->control_point_count = (uint32_t)cp_count;
    map->vertex_count = (uint32_t)rv_count;
    map->first = mk_arena_array(arena, cp_count + 1, sizeof(uint32_t));
    map->vertices = mk_arena_array(arena, rv_count, sizeof(uint32_t));
    map->vertex_cp = mesh->control_points;
    if (!map->first || !map->vertices) { r = mk_error_oom(doc->err, "FBX mesh map"); goto done; }
    for (size_t v = 0; v < rv_count; v++) map->first[rv_cp[v] + 1]++;
    for (size_t cp = 0; cp < cp_count; cp++) map->first[cp + 1] += map->first[cp];
    for (size_t cp = 0; cp < cp_count; cp++) cp_head[cp] = map->first[cp];
    for (size_t v = 0; v < rv_count; v++) map->vertices[cp_head[rv_cp[v]]++] = (uint32_t)v;
    r = MK_OK;

done:
    fbx_prefetch_drop(doc);  /* what was not asked for */
    mk_arena_release(arena, vertices);
    mk_arena_release(arena, polygon_index);
    free_layer(doc, &normals);
    free_layer(doc, &uvs);
    mk_arena_release(arena, pv_rv);
    mk_arena_release(arena, cp_head);
    mk_arena_release(arena, rv_next);
    mk_arena_release(arena, rv_cp);
    mk_arena_release(arena, rv_keys);
    if (r != MK_OK) fbx_mesh_map_free(doc, map);
    return r;
}

void fbx_mesh_map_free(fbx_doc *doc, fbx_mesh_map *map)
{
    mk_arena_release(doc->arena, map->first);
    mk_arena_release(doc->arena, map->vertices);
    mk_arena_release(doc->arena, map->cp_entry);
    mk_arena_release(doc->arena, map->entry_cp);
    mk_arena_release(doc->arena, map->sum_pos);
    mk_arena_release(doc->arena, map->sum_nrm);
    mk_arena_release(doc->arena, map->pairs);
    map->first = map->vertices = NULL;
    map->cp_entry = map->entry_cp = NULL;
    map->sum_pos = map->sum_nrm = NULL;
    map->pairs = NULL;
}

/* ---- Blend shape expansion ---- */

typedef struct pair { uint32_t vertex, entry; } pair;

static int cmp_pair(const void *a, const void *b)
{
    const pair *x = a, *y = b;
    if (x->vertex != y->vertex) return x->vertex < y->vertex ? -1 : 1;
    return x->entry < y->entry ? -1 : x->entry > y->entry;
}

mk_result fbx_expand_shape(fbx_doc *doc, mk_arena *out, fbx_mesh_map *map, const fbx_shape_data *shape,
                           mk_raw_target *target, size_t *skipped)
{
    mk_arena *arena = doc->arena;
    *skipped = 0;
    size_t n = shape->count;
    /* Per control point: the summed delta of its entries (a file may list a point twice;
     * evaluation adds every offset, as ufbx does). Dense accumulation keyed through cp_entry;
     * the scratch stays allocated across shapes of the mesh and cp_entry is reset after each use. */
    const size_t cps = map->control_point_count ? map->control_point_count : 1;
    if (!map->cp_entry) {
        map->cp_entry = mk_arena_array(arena, cps, sizeof(uint32_t));
        map->entry_cp = mk_arena_array(arena, cps, sizeof(uint32_t));
        map->sum_pos = mk_arena_array(arena, cps, 3 * sizeof(double));
        if (!map->cp_entry || !map->entry_cp || !map->sum_pos) return mk_error_oom(doc->err, "FBX shape");
        for (uint32_t i = 0; i < map->control_point_count; i++) map->cp_entry[i] = UINT32_MAX;
    }
    if (shape->normals && !map->sum_nrm && !(map->sum_nrm = mk_arena_array(arena, cps, 3 * sizeof(double))))
        return mk_error_oom(doc->err, "FBX shape");
    double *sum_pos = map->sum_pos;
    double *sum_nrm = shape->normals ? map->sum_nrm : NULL;
    uint32_t *entry_cp = map->entry_cp;
    mk_result r = MK_OK;
    size_t unique = 0;
    for (size_t i = 0; i < n; i++) {
        int32_t cp = shape->indexes[i];
        if (cp < 0 || (uint32_t)cp >= map->control_point_count) { (*skipped)++; continue; }
        for (int k = 0; k < 6; k++) {
            /* Name the file's value; sums that only overflow float are caught below. */
            const double *values = k < 3 ? shape->positions : shape->normals;
            if (values && !isfinite(values[3 * i + (size_t)(k % 3)])) {
                r = fbx_error_not_finite(doc, fbx_child(shape->node, k < 3 ? "Vertices" : "Normals"), 3 * i + (size_t)(k % 3),
                                         "shape '%.*s' entry %zu (control point %d)", (int)shape->name_length, shape->name,
                                         i, (int)cp);
                goto done;
            }
        }
        double scale = shape->vertex_weights ? shape->vertex_weights[i] : 1.0;
        uint32_t e = map->cp_entry[cp];
        if (e == UINT32_MAX) {
            e = (uint32_t)unique++;
            map->cp_entry[cp] = e;
            entry_cp[e] = (uint32_t)cp;
            for (int k = 0; k < 3; k++) sum_pos[3 * e + (size_t)k] = 0;
            if (sum_nrm) for (int k = 0; k < 3; k++) sum_nrm[3 * e + (size_t)k] = 0;
        }
        for (int k = 0; k < 3; k++) sum_pos[3 * e + (size_t)k] += scale * shape->positions[3 * i + (size_t)k];
        if (sum_nrm) for (int k = 0; k < 3; k++) sum_nrm[3 * e + (size_t)k] += shape->normals[3 * i + (size_t)k];
    }
    for (size_t e = 0; e < unique; e++) {
        for (int k = 0; k < 3; k++) {
            if (!isfinite((float)sum_pos[3 * e + (size_t)k]) || (sum_nrm && !isfinite((float)sum_nrm[3 * e + (size_t)k]))) {
                r = mk_error_set(doc->err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                 "FBX %s: delta of control point %u is NaN, infinite or beyond float range",
                                 shape->path ? shape->path : "shape", entry_cp[e]);
                goto done;
            }
        }
    }
    /* Drop entries that move nothing (exactly zero delta and normal delta). */
    size_t total = 0;
    for (size_t e = 0; e < unique; e++) {
        const double *p = sum_pos + 3 * e;
        const double *q = sum_nrm ? sum_nrm + 3 * e : NULL;
        int moves = (float)p[0] != 0 || (float)p[1] != 0 || (float)p[2] != 0 ||
                    (q && ((float)q[0] != 0 || (float)q[1] != 0 || (float)q[2] != 0));
        uint32_t cp = entry_cp[e];
        if (!moves) { map->cp_entry[cp] = UINT32_MAX - 1; continue; }  /* marked "present but zero" */
        total += map->first[cp + 1] - map->first[cp];
    }
    if (total > UINT32_MAX) { r = mk_error_set(doc->err, MK_ERROR_LIMIT, UINT64_MAX, "FBX shape too large"); goto done; }
    target->count = (uint32_t)total;
    target->indices = mk_arena_array(out, total ? total : 1, sizeof(uint32_t));
    target->positions = mk_arena_array(out, total ? total : 1, 3 * sizeof(float));
    target->normals = sum_nrm ? mk_arena_array(out, total ? total : 1, 3 * sizeof(float)) : NULL;
    if (!target->indices || !target->positions || (sum_nrm && !target->normals)) { r = mk_error_oom(doc->err, "FBX target"); goto done; }
    size_t w = 0;
    /* Render vertices in increasing order: scan all of them when the shape touches a good
     * fraction of the mesh, else sort the (vertex, entry) pairs of the touched ones. */
    if (total * 16 >= map->vertex_count) {
        for (uint32_t v = 0; v < map->vertex_count; v++) {
            uint32_t e = map->cp_entry[map->vertex_cp[v]];
            if (e >= UINT32_MAX - 1) continue;
            target->indices[w] = v;
            for (int k = 0; k < 3; k++) target->positions[3 * w + (size_t)k] = (float)sum_pos[3 * e + (size_t)k];
            if (sum_nrm) for (int k = 0; k < 3; k++) target->normals[3 * w + (size_t)k] = (float)sum_nrm[3 * e + (size_t)k];
            w++;
        }
    } else {
        if (!map->pairs) map->pairs = mk_arena_array(arena, map->vertex_count ? map->vertex_count : 1, sizeof(pair));
        pair *pairs = map->pairs;  /* total <= vertex_count: each render vertex has one control point */
        if (!pairs) { r = mk_error_oom(doc->err, "FBX shape"); goto done; }
        size_t np = 0;
        for (size_t e = 0; e < unique; e++) {
            uint32_t cp = entry_cp[e];
            if (map->cp_entry[cp] >= UINT32_MAX - 1) continue;
            for (uint32_t j = map->first[cp]; j < map->first[cp + 1]; j++) {
                pairs[np].vertex = map->vertices[j];
                pairs[np].entry = (uint32_t)e;
                np++;
            }
        }
        qsort(pairs, np, sizeof *pairs, cmp_pair);
        for (size_t j = 0; j < np; j++) {
            uint32_t e = pairs[j].entry;
            target->indices[w] = pairs[j].vertex;
            for (int k = 0; k < 3; k++) target->positions[3 * w + (size_t)k] = (float)sum_pos[3 * e + (size_t)k];
            if (sum_nrm) for (int k = 0; k < 3; k++) target->normals[3 * w + (size_t)k] = (float)sum_nrm[3 * e + (size_t)k];
            w++;
        }
    }
    target->count = (uint32_t)w;
done:
    for (size_t e = 0; e < unique; e++) map->cp_entry[entry_cp[e]] = UINT32_MAX;
    return r;
}

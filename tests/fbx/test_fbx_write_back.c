/* SPDX-License-Identifier: MIT */
/* FBX write-back (formats/fbx_write): every corpus FBX of version 7.2 or later, written back with
 * nothing baked, gives its own bytes; baked with a recipe, the output keeps every node of the
 * input (compared node by node: names, values, array bytes) and re-imports with the original
 * channels unchanged and the baked ones as the bake made them (deltas, full weights, defaults,
 * playback at several weights, the clip's keys). Refusals name what cannot be written. The
 * corpus cases SKIP when the corpus is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bake.h"
#include "check.h"
#include "fbx_internal.h"
#include "fbx_node_write.h"
#include "fbx_test_util.h"
#include "fbx_write.h"

static const char *const corpus_files[] = {
    "maya_blend_inbetween_7500_ascii", "maya_blend_shape_cube_7700_binary", "maya_blend_shape_cube_7700_ascii",
    "zbrush_d20_7500_binary",          "zbrush_d20_7500_ascii",             "blender440_shape_weight_anim_7400_binary",
    "blender_279_shape_weights_7400_binary", "synthetic_blend_shape_order_7500_ascii",
    "maya_blend_shape_cube_7100_binary",     "maya_blend_shape_cube_7100_ascii",
};

/* Pointwise deformers (one with in-betweens) and a travelling lattice with its clip. Files made
 * by Blender take the recipe without in-betweens (recipe_flat): readers of such files take
 * FullWeights as per-vertex weights. */
#define RECIPE(INBETWEENS) \
    "{ \"mesh\": 0, \"channels\": [" \
    "  { \"name\": \"taper_top\", \"op\": \"taper\", \"axis\": \"y\", \"scale\": 0.3 }," \
    "  { \"name\": \"twist_quarter\", \"op\": \"twist\", \"axis\": [0, 1, 0], \"center\": [0, 0, 0], \"angle\": -90," \
    "    \"inbetweens\": " INBETWEENS ", \"default_weight\": 0.25 }," \
    "  { \"name\": \"wave\", \"op\": \"ffd_travel\", \"dims\": [4, 2, 2], \"duration\": 2," \
    "    \"origin\": [-2.4, -0.6, -0.6], \"axes\": [[1.2, 0, 0], [0, 1.2, 0], [0, 0, 1.2]]," \
    "    \"moves\": [ { \"i\": 1, \"translate\": [0, 0, 0.2] } ], \"travel\": { \"translate\": [2.4, 0, 0] } } ] }"
static const char recipe[] = RECIPE("3");
static const char recipe_flat[] = RECIPE("1");

static int made_by_blender(const char *file) { return strncmp(file, "blender", 7) == 0; }
/* FBX 7.1 keeps shapes inside the geometry, one per channel: no in-betweens. */
static int shapes_in_geometry(const char *file) { return strstr(file, "_7100_") != NULL; }

static const mk_raw_channel *find_channel(const mk_raw_asset *raw, const char *name, uint32_t *index)
{
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (strcmp(raw->channels[c].name, name) == 0) {
            if (index) *index = c;
            return &raw->channels[c];
        }
    return NULL;
}

/* ---- node by node ---- */

static int same_value(const fbx_value *a, const fbx_value *b)
{
    if (a->kind != b->kind || a->type != b->type) return 0;
    switch (a->kind) {
    case FBX_INT: case FBX_CHAR: return a->u.i == b->u.i;
    case FBX_FLOAT: return memcmp(&a->u.f, &b->u.f, sizeof a->u.f) == 0;
    case FBX_STRING: return a->u.s.length == b->u.s.length && memcmp(a->u.s.data, b->u.s.data, a->u.s.length) == 0;
    default:
        return a->encoding == b->encoding && a->count == b->count && a->u.a.size == b->u.a.size &&
               memcmp(a->u.a.data, b->u.a.data, (size_t)a->u.a.size) == 0;
    }
}

/* Whether node `in` may gain children in a write-back: Objects and Connections; in FBX 7.1 a
 * Geometry (its shapes) and its Properties70 (their weights). */
static int may_grow(const fbx_node *in, int top)
{
    if (top) return fbx_name_is(in, "Objects") || fbx_name_is(in, "Connections");
    const fbx_node *p = in->parent;
    if (fbx_name_is(in, "Geometry")) return p && fbx_name_is(p, "Objects");
    return fbx_name_is(in, "Properties70") && p && fbx_name_is(p, "Geometry") && p->parent && fbx_name_is(p->parent, "Objects");
}

/* Every node of `in` is in `out` with the same name and values; only the nodes of may_grow may
 * have more children, after the input's. Returns the number of differences. */
static int compare_nodes(const fbx_node *in, const fbx_node *out, int top)
{
    int bad = 0;
    if (in->name_length != out->name_length || memcmp(in->name, out->name, in->name_length) != 0) return 1;
    if (in->value_count != out->value_count) return 1;
    for (uint32_t i = 0; i < in->value_count; i++) bad += !same_value(&in->values[i], &out->values[i]);
    const int grows = may_grow(in, top);
    if (grows ? out->child_count < in->child_count : out->child_count != in->child_count) return bad + 1;
    for (uint32_t i = 0; i < in->child_count; i++) bad += compare_nodes(&in->children[i], &out->children[i], 0);
    return bad;
}

/* Differences between the trees of two files (-1: one does not parse). */
static int tree_differences(const void *in, size_t in_size, const void *out, size_t out_size)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    fbx_doc a, b;
    mk_error err;
    int bad = -1;
    if (fbx_doc_parse(&a, &arena, in, in_size, &err) == MK_OK && fbx_doc_parse(&b, &arena, out, out_size, &err) == MK_OK) {
        bad = a.root.child_count != b.root.child_count;
        for (uint32_t i = 0; !bad && i < a.root.child_count; i++) bad += compare_nodes(&a.root.children[i], &b.root.children[i], 1);
    } else {
        fprintf(stderr, "parse: %s\n", err.message);
    }
    fbx_doc_free(&a);
    fbx_doc_free(&b);
    mk_arena_free_all(&arena);
    return bad;
}

/* ---- cases ---- */

/* Nothing baked: the output is the input, byte for byte (binary records re-written with their
 * end offsets, footer included; ASCII text copied). */
static void test_nothing_baked_is_identity(void)
{
    int files = 0;
    for (size_t f = 0; f < sizeof corpus_files / sizeof *corpus_files; f++) {
        size_t size;
        unsigned char *data = ft_read_corpus(corpus_files[f], &size);
        if (!data) SKIP("corpus not found at %s", check_corpus_dir());
        mk_raw_asset raw;
        mk_error err;
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
        void *out = NULL;
        size_t out_size = 0;
        mk_result r = mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err);
        CHECK_MSG(r == MK_OK, "%s: %s", corpus_files[f], err.message);
        CHECK_MSG(r == MK_OK && out_size == size && memcmp(out, data, size) == 0, "%s: %zu bytes written for %zu read",
                  corpus_files[f], out_size, size);
        mk_raw_free(&raw);
        free(data);
        files++;
    }
    CHECK_EQ_INT(files, (int)(sizeof corpus_files / sizeof *corpus_files));
}

/* A target's deltas on every render vertex (3 per vertex; normals zero when absent). */
static float *dense(const mk_raw_target *t, uint32_t vertex_count, int normals)
{
    float *d = calloc(3 * (size_t)vertex_count + 1, sizeof *d);
    const float *src = normals ? t->normals : t->positions;
    for (uint32_t e = 0; src && e < t->count; e++) memcpy(d + 3 * (size_t)t->indices[e], src + 3 * (size_t)e, 3 * sizeof *d);
    return d;
}

/* Channel a (of raw ra) and channel b (of the re-import rb): same default, full weights and
 * position deltas on every render vertex (the file holds the floats as doubles: exact), normal
 * deltas within `normal_tolerance`. */
static void compare_channel(const char *file, const mk_raw_asset *ra, const mk_raw_channel *a, const mk_raw_asset *rb,
                            const mk_raw_channel *b, double normal_tolerance)
{
    CHECK_MSG(a->target_count == b->target_count, "%s '%s': %u targets, re-imported %u", file, a->name, a->target_count,
              b->target_count);
    CHECK_NEAR(a->default_weight, b->default_weight, 1e-6);
    const uint32_t n = ra->meshes[a->mesh].vertex_count;
    CHECK_EQ_INT(rb->meshes[b->mesh].vertex_count, n);
    if (rb->meshes[b->mesh].vertex_count != n) return;
    for (uint32_t t = 0; t < a->target_count && t < b->target_count; t++) {
        const mk_raw_target *x = &a->targets[t], *y = &b->targets[t];
        CHECK_NEAR(x->full_weight, y->full_weight, 1e-6);
        double worst = 0, worst_normal = 0;
        for (int normals = 0; normals < 2; normals++) {
            float *dx = dense(x, n, normals), *dy = dense(y, n, normals);
            for (uint32_t k = 0; k < 3 * n; k++) {
                double d = fabs((double)dx[k] - dy[k]);
                if (normals) worst_normal = fmax(worst_normal, d);
                else worst = fmax(worst, d);
            }
            free(dx);
            free(dy);
        }
        CHECK_MSG(worst == 0, "%s '%s' target %u: positions %g apart", file, a->name, t, worst);
        CHECK_MSG(worst_normal <= normal_tolerance, "%s '%s' target %u: normals %g apart", file, a->name, t, worst_normal);
    }
}

/* The k-th channel named like original channel c (names may repeat: ZBrush leaves them empty). */
static const mk_raw_channel *same_channel(const mk_raw_asset *original, uint32_t c, const mk_raw_asset *other)
{
    uint32_t nth = 0;
    for (uint32_t i = 0; i < c; i++) nth += strcmp(original->channels[i].name, original->channels[c].name) == 0;
    for (uint32_t i = 0; i < other->channel_count; i++)
        if (strcmp(other->channels[i].name, original->channels[c].name) == 0 && nth-- == 0) return &other->channels[i];
    return NULL;
}

static void test_baked_round_trip(void)
{
    int files = 0;
    for (size_t f = 0; f < sizeof corpus_files / sizeof *corpus_files; f++) {
        const char *file = corpus_files[f];
        size_t size;
        unsigned char *data = ft_read_corpus(file, &size);
        if (!data) SKIP("corpus not found at %s", check_corpus_dir());
        mk_raw_asset original, baked, back;
        mk_error err;
        CHECK(ft_import(data, size, NULL, &original, &err) == MK_OK);
        CHECK(ft_import(data, size, NULL, &baked, &err) == MK_OK);
        mk_bake_report report;
        const int blender = made_by_blender(file), flat = blender || shapes_in_geometry(file);
        mk_result r = flat ? mk_bake_recipe(&baked, recipe_flat, sizeof recipe_flat - 1, NULL, &report, &err)
                              : mk_bake_recipe(&baked, recipe, sizeof recipe - 1, NULL, &report, &err);
        CHECK_MSG(r == MK_OK, "%s: bake: %s", file, err.message);
        void *out = NULL;
        size_t out_size = 0;
        mk_fbx_write_report wr;
        if (r == MK_OK) r = mk_fbx_write_back(data, size, &baked, &baked.arena, &out, &out_size, &wr, &err);
        CHECK_MSG(r == MK_OK, "%s: write-back: %s", file, err.message);
        if (r != MK_OK) { mk_raw_free(&original); mk_raw_free(&baked); free(data); continue; }
        CHECK_EQ_INT(wr.channels, 3);
        CHECK_EQ_INT(wr.shapes, flat ? 3 : 5);
        CHECK_EQ_INT(wr.blender_weights, blender ? 3 : 0);
        CHECK_EQ_INT(wr.clips, 1);
        CHECK_MSG(tree_differences(data, size, out, out_size) == 0, "%s: input nodes changed in the output", file);
        CHECK_MSG(fbx_is_binary(out, out_size) == fbx_is_binary(data, size), "%s: binary/ASCII changed", file);
        r = ft_import(out, out_size, NULL, &back, &err);
        CHECK_MSG(r == MK_OK, "%s: re-import: %s", file, err.message);
        if (r == MK_OK) {
            CHECK_EQ_INT(back.channel_count, original.channel_count + 3);
            for (uint32_t c = 0; c < original.channel_count; c++) {
                const mk_raw_channel *again = same_channel(&original, c, &back);
                CHECK_MSG(again != NULL, "%s: channel '%s' lost", file, original.channels[c].name);
                if (again) compare_channel(file, &original, &original.channels[c], &back, again, 0);
            }
            /* The file keeps positions; readers compute the normals from them, as the importer
             * does for a bake without its own (the bake's analytic normals are not in FBX). */
            CHECK(mk_raw_compute_target_normals(&baked, 0, 1, 1, &err) == MK_OK);
            const char *names[3] = { "taper_top", "twist_quarter", "wave" };
            for (int n = 0; n < 3; n++) {
                uint32_t bi = 0, ri = 0;
                const mk_raw_channel *a = find_channel(&baked, names[n], &bi), *b = find_channel(&back, names[n], &ri);
                CHECK_MSG(a && b, "%s: channel '%s' missing after re-import", file, names[n]);
                if (!a || !b) continue;
                compare_channel(file, &baked, a, &back, b, 1e-5);
                /* Playback of the channel alone at three weights, on the control points. */
                for (int k = 1; k <= 3; k++) {
                    float *wa = calloc(baked.channel_count, sizeof *wa), *wb = calloc(back.channel_count, sizeof *wb);
                    wa[bi] = wb[ri] = 0.35f * (float)k;
                    float *pa = NULL, *pb = NULL;
                    uint32_t na = 0, nb = 0;
                    int ok = ft_eval_control_points(&baked, a->mesh, -1, 0, wa, 0, &pa, &na) == 0 &&
                             ft_eval_control_points(&back, b->mesh, -1, 0, wb, 0, &pb, &nb) == 0 && na == nb;
                    CHECK_MSG(ok, "%s '%s': evaluation failed", file, names[n]);
                    double worst = 0;
                    for (uint32_t v = 0; ok && v < 3 * na; v++) worst = fmax(worst, fabs((double)pa[v] - pb[v]));
                    CHECK_MSG(worst <= 1e-6, "%s '%s' at weight %.2f: played %g apart", file, names[n], 0.35 * k, worst);
                    free(pa); free(pb); free(wa); free(wb);
                }
            }
            /* The travelling lattice's clip: one stack with its keys. */
            CHECK_EQ_INT(back.clip_count, original.clip_count + 1);
            const mk_raw_clip *ca = &baked.clips[baked.clip_count - 1], *cb = &back.clips[back.clip_count - 1];
            CHECK_EQ_INT(cb->track_count, 1);
            CHECK_NEAR(cb->duration, ca->duration, 1e-6);
            if (cb->track_count == 1 && ca->track_count == 1) {
                CHECK_EQ_INT(cb->tracks[0].key_count, ca->tracks[0].key_count);
                for (uint32_t k = 0; k < ca->tracks[0].key_count && k < cb->tracks[0].key_count; k++) {
                    CHECK_NEAR(cb->tracks[0].keys[k].time, ca->tracks[0].keys[k].time, 1e-6);
                    CHECK_NEAR(cb->tracks[0].keys[k].value, ca->tracks[0].keys[k].value, 1e-6);
                    CHECK_EQ_INT(cb->tracks[0].keys[k].interp, ca->tracks[0].keys[k].interp);
                }
                CHECK(strcmp(back.channels[cb->tracks[0].channel].name, "wave") == 0);
            }
            mk_raw_free(&back);
        }
        mk_raw_free(&original);
        mk_raw_free(&baked);
        free(data);
        files++;
    }
    CHECK_EQ_INT(files, (int)(sizeof corpus_files / sizeof *corpus_files));
}

static int message_has(const mk_error *err, const char *text) { return strstr(err->message, text) != NULL; }

/* What the file cannot say is refused, naming it, and nothing is written. */
static void test_refusals(void)
{
    size_t size;
    unsigned char *data = ft_read_corpus("maya_blend_shape_cube_7700_binary", &size);
    if (!data) SKIP("corpus not found at %s", check_corpus_dir());
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    CHECK(mk_bake_recipe(&raw, recipe, sizeof recipe - 1, NULL, NULL, &err) == MK_OK);
    void *out = NULL;
    size_t out_size = 0;

    /* Two render vertices of one control point moved differently. */
    uint32_t twist = 0;
    CHECK(find_channel(&raw, "twist_quarter", &twist) != NULL);
    mk_raw_target *t = &raw.channels[twist].targets[0];
    float saved = t->positions[0];
    t->positions[0] += 0.01f;
    out = NULL;
    CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
    CHECK_MSG(message_has(&err, "twist_quarter") && message_has(&err, "differently"), "%s", err.message);
    CHECK(out == NULL);
    t->positions[0] = saved;

    /* A render vertex of a moved control point left out of the target (its siblings moved). */
    {
        const mk_raw_mesh *m = &raw.meshes[raw.channels[twist].mesh];
        uint32_t e = 0;
        for (; e < t->count; e++) {
            uint32_t siblings = 0;
            for (uint32_t v = 0; v < m->vertex_count; v++) siblings += m->control_points[v] == m->control_points[t->indices[e]];
            if (siblings > 1 && fabsf(t->positions[3 * e]) + fabsf(t->positions[3 * e + 1]) + fabsf(t->positions[3 * e + 2]) > 0.01f) break;
        }
        CHECK(e < t->count);
        uint32_t kept_index = t->indices[e];
        float kept[3] = { t->positions[3 * e], t->positions[3 * e + 1], t->positions[3 * e + 2] };
        /* swap the entry to the end and shorten the target by one */
        const uint32_t last = t->count - 1;
        t->indices[e] = t->indices[last];
        memcpy(t->positions + 3 * e, t->positions + 3 * last, 3 * sizeof(float));
        t->count--;
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
        CHECK_MSG(message_has(&err, "some render vertices") && message_has(&err, "twist_quarter"), "%s", err.message);
        t->count++;
        t->indices[last] = t->indices[e];
        memcpy(t->positions + 3 * last, t->positions + 3 * e, 3 * sizeof(float));
        t->indices[e] = kept_index;
        memcpy(t->positions + 3 * e, kept, sizeof kept);
    }

    /* A geometry shared by two models (an instanced mesh). */
    mk_raw_mesh *copy = mk_raw_add_meshes(&raw, 1);
    CHECK(copy != NULL);
    if (copy) {
        *copy = raw.meshes[0];
        copy->name = "instance";
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
        CHECK_MSG(message_has(&err, "instance") && message_has(&err, "also used"), "%s", err.message);
        raw.mesh_count--;
    }

    /* A geometry id that is not in the file. */
    int64_t id = raw.meshes[0].fbx_geometry;
    raw.meshes[0].fbx_geometry = 12345;
    CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
    CHECK_MSG(message_has(&err, "12345"), "%s", err.message);
    raw.meshes[0].fbx_geometry = id;

    /* Truncated input: a parse error, never a crash. */
    for (size_t cut = 0; cut < size; cut += 997)
        CHECK(mk_fbx_write_back(data, cut, &raw, &raw.arena, &out, &out_size, NULL, &err) != MK_OK);
    /* And the file itself still writes. */
    CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_OK);
    mk_raw_free(&raw);
    free(data);

    /* In-betweens in a file made by Blender (here one in-between and the full target): its
     * readers cannot play them. */
    data = ft_read_corpus("blender440_shape_weight_anim_7400_binary", &size);
    CHECK(data != NULL);
    if (data) {
        static const char two_targets[] = RECIPE("2");
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
        CHECK(mk_bake_recipe(&raw, two_targets, sizeof two_targets - 1, NULL, NULL, &err) == MK_OK);
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
        CHECK_MSG(message_has(&err, "twist_quarter") && message_has(&err, "Blender"), "%s", err.message);
        mk_raw_free(&raw);
        free(data);
    }

    /* FBX 7.1: one shape per channel, no in-betweens; a name the geometry's properties use. */
    data = ft_read_corpus("maya_blend_shape_cube_7100_binary", &size);
    CHECK(data != NULL);
    if (data) {
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
        CHECK(mk_bake_recipe(&raw, recipe, sizeof recipe - 1, NULL, NULL, &err) == MK_OK);
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
        CHECK_MSG(message_has(&err, "twist_quarter") && message_has(&err, "7.1"), "%s", err.message);
        mk_raw_free(&raw);
        static const char clash[] = "{ \"mesh\": 0, \"channels\": [ { \"name\": \"TopH\", \"op\": \"taper\", \"axis\": \"y\", "
                                    "\"scale\": 0.5 } ] }";
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
        CHECK(mk_bake_recipe(&raw, clash, sizeof clash - 1, NULL, NULL, &err) == MK_OK);
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
        CHECK_MSG(message_has(&err, "TopH") && message_has(&err, "property"), "%s", err.message);
        mk_raw_free(&raw);
        free(data);
    }
    /* FBX 6.1: objects by name, animation in takes; refused, naming the version. */
    data = ft_read_corpus("maya_blend_shape_cube_6100_binary", &size);
    CHECK(data != NULL);
    if (data) {
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
        CHECK(mk_bake_recipe(&raw, recipe_flat, sizeof recipe_flat - 1, NULL, NULL, &err) == MK_OK);
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
        CHECK_MSG(message_has(&err, "6100"), "%s", err.message);
        mk_raw_free(&raw);
        free(data);
    }
}

/* ASCII names cannot hold a quote. */
static void test_ascii_name_refused(void)
{
    size_t size;
    unsigned char *data = ft_read_corpus("maya_blend_inbetween_7500_ascii", &size);
    if (!data) SKIP("corpus not found at %s", check_corpus_dir());
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    static const char quoted[] = "{ \"mesh\": 0, \"channels\": [ { \"name\": \"say \\\"hi\\\"\", \"op\": \"taper\", "
                                 "\"axis\": \"y\", \"scale\": 0.5 } ] }";
    CHECK(mk_bake_recipe(&raw, quoted, sizeof quoted - 1, NULL, NULL, &err) == MK_OK);
    void *out = NULL;
    size_t out_size = 0;
    CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_ERROR_UNSUPPORTED);
    CHECK_MSG(message_has(&err, "quote"), "%s", err.message);
    mk_raw_free(&raw);
    free(data);
}

/* A new node with neither values nor children is closed by a null record (as the FBX SDK
 * writes an empty Properties70); one with values and no children is not. */
static void test_node_records(void)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    for (int wide = 0; wide < 2; wide++) {
        const size_t header = wide ? 25 : 13;
        fbx_bytes out = { .arena = &arena };
        fbx_wnode *empty = fbx_wn_new(&arena, "Properties70"), *leaf = fbx_wn_new(&arena, "Version");
        CHECK(empty && leaf && fbx_wn_int(&arena, leaf, 100));
        fbx_wn_write_binary(&out, empty, 1000, wide);
        CHECK_EQ_INT(out.size, 2 * header + strlen("Properties70"));
        CHECK_EQ_INT(out.data[0] | out.data[1] << 8, 1000 + out.size);  /* EndOffset counts from the file's start */
        const size_t before = out.size;
        fbx_wn_write_binary(&out, leaf, 1000, wide);
        CHECK_EQ_INT(out.size - before, header + strlen("Version") + 5);
        CHECK(!out.failed && !out.too_large);
        /* a record ending past 4 GiB: only the 25-byte headers of FBX 7.5 can say where */
        fbx_wn_write_binary(&out, leaf, (uint64_t)UINT32_MAX - 8, wide);
        CHECK_EQ_INT(out.too_large, !wide);
    }
    mk_arena_free_all(&arena);
}

/* The array length of child `name` of the Objects child of that type whose name value starts
 * with `object` (-1: none). */
static long array_length(const fbx_doc *doc, const char *type, const char *object, const char *name)
{
    const fbx_node *objects = fbx_child(&doc->root, "Objects");
    for (uint32_t i = 0; objects && i < objects->child_count; i++) {
        const fbx_node *o = &objects->children[i];
        const char *s;
        uint32_t n;
        if (!fbx_name_is(o, type) || o->value_count < 2 || !fbx_value_string(&o->values[1], &s, &n) || n < strlen(object) ||
            memcmp(s, object, strlen(object)) != 0)
            continue;
        const fbx_node *c = fbx_child(o, name);
        return c ? (long)fbx_node_array_length(c) : -1;
    }
    return -1;
}

/* A baked target that moves nothing keeps one index (control point 0, by zero) and FullWeights
 * as long as the indexes in a file made by Blender, whose importer refuses a file otherwise. */
static void test_still_target(void)
{
    static const char still[] = "{ \"mesh\": 0, \"channels\": [ { \"name\": \"still\", \"op\": \"taper\", \"axis\": \"y\", "
                                "\"scale\": 1 } ] }";
    const char *files[2] = { "blender440_shape_weight_anim_7400_binary", "maya_blend_shape_cube_7700_binary" };
    for (int f = 0; f < 2; f++) {
        size_t size;
        unsigned char *data = ft_read_corpus(files[f], &size);
        if (!data) SKIP("corpus not found at %s", check_corpus_dir());
        mk_raw_asset raw, back;
        mk_error err;
        CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
        CHECK(mk_bake_recipe(&raw, still, sizeof still - 1, NULL, NULL, &err) == MK_OK);
        void *out = NULL;
        size_t out_size = 0;
        CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_OK);
        mk_arena arena;
        mk_arena_init(&arena, NULL);
        fbx_doc doc;
        CHECK(out && fbx_doc_parse(&doc, &arena, out, out_size, &err) == MK_OK);
        if (out) {
            CHECK_EQ_INT(array_length(&doc, "Geometry", "still", "Indexes"), 1);
            CHECK_EQ_INT(array_length(&doc, "Geometry", "still", "Vertices"), 3);
            CHECK_EQ_INT(array_length(&doc, "Deformer", "still", "FullWeights"), 1);
            CHECK(ft_import(out, out_size, NULL, &back, &err) == MK_OK);
            const mk_raw_channel *c = find_channel(&back, "still", NULL);
            CHECK(c && c->target_count == 1);
            mk_raw_free(&back);
        }
        fbx_doc_free(&doc);
        mk_arena_free_all(&arena);
        mk_raw_free(&raw);
        free(data);
    }
}

/* FBX 7.1 weights go into the geometry's Properties70; a geometry without one gets a single new
 * one for all its baked channels. */
static void test_71_properties(void)
{
    size_t size;
    unsigned char *data = ft_read_corpus("maya_blend_shape_cube_7100_ascii", &size);
    if (!data) SKIP("corpus not found at %s", check_corpus_dir());
    /* the geometry's Properties70 (the first one after "Geometry:") cut out */
    char *text = (char *)data, *geometry = strstr(text, "Geometry:");
    char *props = geometry ? strstr(geometry, "Properties70:") : NULL, *close = props ? strstr(props, "}") : NULL;
    CHECK(props && close);
    if (!props || !close) { free(data); return; }
    while (props > text && props[-1] == '\t') props--;
    close = strchr(close, '\n') + 1;
    memmove(props, close, size - (size_t)(close - text));
    size -= (size_t)(close - props);
    static const char two[] = "{ \"mesh\": 0, \"channels\": [ { \"name\": \"taper_a\", \"op\": \"taper\", \"axis\": \"y\", "
                              "\"scale\": 0.5 }, { \"name\": \"taper_b\", \"op\": \"taper\", \"axis\": \"x\", \"scale\": 0.5 } ] }";
    mk_raw_asset raw, back;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    CHECK(mk_bake_recipe(&raw, two, sizeof two - 1, NULL, NULL, &err) == MK_OK);
    void *out = NULL;
    size_t out_size = 0;
    CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_OK);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    fbx_doc doc;
    memset(&doc, 0, sizeof doc);
    if (out && fbx_doc_parse(&doc, &arena, out, out_size, &err) == MK_OK) {
        const fbx_node *g = fbx_child(fbx_child(&doc.root, "Objects"), "Geometry");
        int blocks = 0;
        for (const fbx_node *p = NULL; g && (p = fbx_next_child(g, p, "Properties70")) != NULL;) blocks++;
        CHECK_EQ_INT(blocks, 1);
        CHECK(ft_import(out, out_size, NULL, &back, &err) == MK_OK);
        CHECK(find_channel(&back, "taper_a", NULL) && find_channel(&back, "taper_b", NULL));
        mk_raw_free(&back);
    } else {
        CHECK_MSG(0, "%s", err.message);
    }
    fbx_doc_free(&doc);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
    free(data);
}

/* A file at FBX's newer tick rate (TCDefinition 0: 141120000 per second) gets its new keys at
 * that rate: the clip plays at the same times after a re-import. */
static void test_tick_rate(void)
{
    size_t size;
    unsigned char *data = ft_read_corpus("maya_blend_shape_cube_7700_ascii", &size);
    if (!data) SKIP("corpus not found at %s", check_corpus_dir());
    char *tc = strstr((char *)data, "TCDefinition: 127");
    CHECK(tc != NULL);
    if (!tc) { free(data); return; }
    memcpy(tc + strlen("TCDefinition: "), "  0", 3);
    mk_raw_asset raw, back;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    CHECK(mk_bake_recipe(&raw, recipe, sizeof recipe - 1, NULL, NULL, &err) == MK_OK);
    void *out = NULL;
    size_t out_size = 0;
    CHECK(mk_fbx_write_back(data, size, &raw, &raw.arena, &out, &out_size, NULL, &err) == MK_OK);
    CHECK(out && ft_import(out, out_size, NULL, &back, &err) == MK_OK);
    if (out) {
        const mk_raw_clip *a = &raw.clips[raw.clip_count - 1], *b = &back.clips[back.clip_count - 1];
        CHECK_NEAR(b->duration, a->duration, 1e-6);
        CHECK(a->track_count == 1 && b->track_count == 1 && a->tracks[0].key_count == b->tracks[0].key_count);
        for (uint32_t k = 0; a->track_count == 1 && b->track_count == 1 && k < a->tracks[0].key_count; k++)
            CHECK_NEAR(b->tracks[0].keys[k].time, a->tracks[0].keys[k].time, 1e-6);
        mk_raw_free(&back);
    }
    mk_raw_free(&raw);
    free(data);
}

CHECK_MAIN(CASE(test_node_records), CASE(test_still_target), CASE(test_71_properties), CASE(test_tick_rate), CASE(test_nothing_baked_is_identity), CASE(test_baked_round_trip), CASE(test_refusals),
           CASE(test_ascii_name_refused))

/* SPDX-License-Identifier: MIT */
/* glTF write-back (formats/gltf_writeback): for every glTF case of the corpus, a recipe (a
 * progressive twist, a taper with a default weight, a travelling lattice with its clip) is baked
 * on the first mesh and written back into the file itself; the output is re-imported with its
 * channel sidecar and must give the original channels and clips bit for bit, the baked channels
 * within the quantization step of the accessors written, and a JSON tree that holds the input's
 * tree unchanged (only members and array elements added, the known replacements excepted). An
 * asset without baked channels writes the file back unchanged; a mesh instanced by two nodes
 * baked differently is refused. A glTF made here (two primitives, primitive.extras.targetNames,
 * node.weights other than mesh.weights, a weight animation to 3e10 s) gets a channel moving 2 of
 * 12 vertices (a sparse accessor) and a progressive one (dense, a default weight): accessors,
 * padding, weights, names, the extended sampler and both re-imports are checked. Outputs pass
 * the Khronos validator when it is installed (its exit status, no errors). */
#define _GNU_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <dirent.h>
#include "bake.h"
#include "blob_io.h"
#include "check.h"
#include "corpus_cases.h"
#include "gltf_test_util.h"
#include "gltf_writeback.h"

static char prefix[64];

static int validated, validator_missing;

static void check_valid(const char *path)
{
    static int have_node = -1;
    if (have_node < 0) have_node = system("node --version > /dev/null 2>&1") == 0;
    char cmd[2048];
    /* The validator's status, not head's: sh has no pipefail. */
    snprintf(cmd, sizeof cmd, "out=$(node '%s/tests/gltf/validate.js' '%s'); rc=$?; printf '%%s\\n' \"$out\" | head -1; exit $rc",
             MK_SOURCE_ROOT, path);
    int rc = have_node ? system(cmd) : -1;
    if (rc == -1 || !WIFEXITED(rc) || WEXITSTATUS(rc) == 77) { validator_missing = 1; return; }
    CHECK_MSG(WEXITSTATUS(rc) == 0, "%s does not pass the glTF validator", path);
    validated++;
}

static mk_result import_path(const char *path, const char *sidecar, mk_raw_asset *raw, mk_error *err)
{
    mk_import_options io = { .keep_plain_meshes = 1, .channels_sidecar = sidecar };
    mk_raw_init(raw, NULL);
    return mk_import_file(path, &io, raw, err);
}

/* The JSON of a .gltf or .glb's bytes. */
static cJSON *json_of(const uint8_t *d, size_t n)
{
    if (n >= 20 && !memcmp(d, "glTF", 4)) {
        uint32_t jl;
        memcpy(&jl, d + 12, 4);
        return jl <= n - 20 ? cJSON_ParseWithLength((const char *)d + 20, jl) : NULL;
    }
    return cJSON_ParseWithLength((const char *)d, n);
}

/* Every member of `in` is in `out` with the same value and in the same order; arrays may have
 * grown. Allowed replacements: a weight sampler's output, buffers[0].byteLength (the BIN chunk
 * grew), a relative uri that now resolves from out_dir to the same file as from in_dir. */
static int contains(const cJSON *in, const cJSON *out, const char *path, const char *in_dir, const char *out_dir, char *why,
                    size_t why_size)
{
    if (cJSON_IsObject(in)) {
        if (!cJSON_IsObject(out)) { snprintf(why, why_size, "%s: not an object", path); return 0; }
        const cJSON *a, *last = NULL;
        cJSON_ArrayForEach(a, in) {
            const cJSON *b = cJSON_GetObjectItemCaseSensitive(out, a->string);
            char sub[512];
            snprintf(sub, sizeof sub, "%s.%s", path, a->string);
            if (!b) { snprintf(why, why_size, "%s: missing", sub); return 0; }
            int after = !last;
            for (const cJSON *x = last ? last->next : NULL; x; x = x->next) after |= x == b;
            if (!after) { snprintf(why, why_size, "%s: member order changed", sub); return 0; }
            last = b;
            if (strstr(sub, ".samplers[") && !strcmp(a->string, "output")) continue;
            if (!strcmp(sub, "$.buffers[0].byteLength") && b->valuedouble >= a->valuedouble) continue;
            if (!strcmp(a->string, "uri") && cJSON_IsString(a) && cJSON_IsString(b) && strcmp(a->valuestring, b->valuestring)) {
                char p1[PATH_MAX + 600], p2[PATH_MAX + 600], r1[PATH_MAX], r2[PATH_MAX];
                snprintf(p1, sizeof p1, "%s/%s", in_dir, a->valuestring);
                snprintf(p2, sizeof p2, "%s/%s", out_dir, b->valuestring);
                if (realpath(p1, r1) && realpath(p2, r2) && !strcmp(r1, r2)) continue;
                snprintf(why, why_size, "%s: '%s' does not resolve to the input's file", sub, b->valuestring);
                return 0;
            }
            if (!contains(a, b, sub, in_dir, out_dir, why, why_size)) return 0;
        }
        return 1;
    }
    if (cJSON_IsArray(in)) {
        if (!cJSON_IsArray(out) || cJSON_GetArraySize(out) < cJSON_GetArraySize(in)) {
            snprintf(why, why_size, "%s: not an array as long", path);
            return 0;
        }
        int i = 0;
        const cJSON *a;
        cJSON_ArrayForEach(a, in) {
            char sub[512];
            snprintf(sub, sizeof sub, "%s[%d]", path, i);
            if (!contains(a, cJSON_GetArrayItem(out, i), sub, in_dir, out_dir, why, why_size)) return 0;
            i++;
        }
        return 1;
    }
    if (cJSON_Compare(in, out, 1)) return 1;
    snprintf(why, why_size, "%s: value changed", path);
    return 0;
}

static int same_target(const mk_raw_target *a, const mk_raw_target *b)
{
    if (a->count != b->count || a->full_weight != b->full_weight || strcmp(a->name, b->name)) return 0;
    if (memcmp(a->indices, b->indices, 4 * (size_t)a->count) || memcmp(a->positions, b->positions, 12 * (size_t)a->count)) return 0;
    if ((a->normals == NULL) != (b->normals == NULL) || (a->tangents == NULL) != (b->tangents == NULL)) return 0;
    if (a->normals && memcmp(a->normals, b->normals, 12 * (size_t)a->count)) return 0;
    if (a->tangents && memcmp(a->tangents, b->tangents, 12 * (size_t)a->count)) return 0;
    return 1;
}

/* Channels of raw mesh m, in order. */
static uint32_t mesh_channels(const mk_raw_asset *raw, uint32_t m, uint32_t *out)
{
    uint32_t n = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (raw->channels[c].mesh == m) out[n++] = c;
    return n;
}

static const mk_raw_track *find_track(const mk_raw_clip *clip, uint32_t channel)
{
    for (uint32_t t = 0; t < clip->track_count; t++)
        if (clip->tracks[t].channel == channel) return &clip->tracks[t];
    return NULL;
}

/* Largest |a - b| of one delta array, both dense over the mesh (NULL: zeros). */
static double dense_diff(const mk_raw_target *a, const mk_raw_target *b, uint32_t V, int which)
{
    float *d = calloc(3 * (size_t)V + 1, sizeof(float));
    const mk_raw_target *t[2] = { a, b };
    for (int s = 0; s < 2; s++) {
        const float *src = which == 0 ? t[s]->positions : which == 1 ? t[s]->normals : t[s]->tangents;
        for (uint32_t i = 0; src && i < t[s]->count; i++)
            for (int k = 0; k < 3; k++) d[3 * (size_t)t[s]->indices[i] + k] += (s ? -1.0f : 1.0f) * src[3 * (size_t)i + k];
    }
    double e = 0;
    for (size_t i = 0; i < 3 * (size_t)V; i++) e = fmax(e, fabs((double)d[i]));
    free(d);
    return e;
}

/* Half the quantization step of the accessors a primitive's new targets were written with
 * (decoded units; 0 for float): the largest rounding error allowed. */
static double half_step(const cJSON *doc, int32_t mesh, int32_t prim, uint32_t target, const char *semantic)
{
    const cJSON *t = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(
        cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "meshes"), mesh), "primitives"), prim), "targets"), (int)target);
    const cJSON *a = cJSON_GetObjectItem(t, semantic);
    if (!a) return 0;
    const cJSON *acc = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "accessors"), a->valueint);
    int ct = cJSON_GetObjectItem(acc, "componentType")->valueint, norm = cJSON_IsTrue(cJSON_GetObjectItem(acc, "normalized"));
    if (ct == 5126) return 0;
    return norm ? 0.5 / (ct == 5122 ? 32767.0 : 127.0) : 0.5;
}

static mk_result bake_case(mk_raw_asset *raw, mk_error *err)
{
    const mk_raw_mesh *m = &raw->meshes[0];
    float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++) { lo[k] = fminf(lo[k], m->positions[3 * v + k]); hi[k] = fmaxf(hi[k], m->positions[3 * v + k]); }
    double s[3], o[3];
    for (int k = 0; k < 3; k++) { s[k] = (hi[k] - lo[k]) * 1.5 + 1e-3; o[k] = lo[k] - (hi[k] - lo[k]) * 0.25 - 5e-4; }
    int ax = 0;   /* twist and taper along the longest side (MorphPrimitivesTest is flat in y) */
    for (int k = 1; k < 3; k++) if (hi[k] - lo[k] > hi[ax] - lo[ax]) ax = k;
    const char *axis = ax == 0 ? "x" : ax == 1 ? "y" : "z";
    /* The lattice waits beside the mesh along x (at rest where the mesh starts) and the mesh
     * travels through it: ffd_travel's sample, scaled to the mesh. */
    double sx = hi[0] - lo[0] + 1e-3;
    char recipe[2048];
    snprintf(recipe, sizeof recipe,
             "{ \"mesh\": 0, \"channels\": ["
             " { \"name\": \"wb_twist\", \"op\": \"twist\", \"axis\": \"%s\", \"angle\": 120, \"inbetweens\": 3 },"
             " { \"name\": \"wb_taper\", \"op\": \"taper\", \"axis\": \"%s\", \"scale\": 0.5, \"default_weight\": 0.25 },"
             " { \"name\": \"wb_travel\", \"op\": \"ffd_travel\", \"dims\": [4, 2, 2], \"duration\": 2,"
             "   \"origin\": [%.9g, %.9g, %.9g], \"axes\": [[%.9g, 0, 0], [0, %.9g, 0], [0, 0, %.9g]],"
             "   \"moves\": [ { \"i\": 1, \"translate\": [0, %.9g, 0] }, { \"i\": 2, \"translate\": [0, %.9g, 0] } ],"
             "   \"travel\": { \"translate\": [%.9g, 0, 0] }, \"tolerance\": 0.01 } ] }",
             axis, axis, hi[0] + 0.1 * sx, o[1], o[2], 3 * sx, s[1], s[2], s[1] * 0.2, -s[1] * 0.2, 4.5 * sx);
    mk_bake_report rep;
    return mk_bake_recipe(raw, recipe, strlen(recipe), NULL, &rep, err);
}

static void dir_of(const char *path, char *out, size_t n)
{
    const char *sl = strrchr(path, '/');
    snprintf(out, n, "%.*s", sl ? (int)(sl - path) : 1, sl ? path : ".");
}

/* Alignment glTF requires of what the write-back adds: every new bufferView starts on a 4-byte
 * boundary (float components), and a GLB's chunks have lengths that are multiples of 4. */
static int aligned(const cJSON *ji, const cJSON *jo, const uint8_t *bytes, size_t size, char *why, size_t n)
{
    const cJSON *vi = cJSON_GetObjectItemCaseSensitive(ji, "bufferViews"), *vo = cJSON_GetObjectItemCaseSensitive(jo, "bufferViews");
    for (int i = cJSON_GetArraySize(vi); i < cJSON_GetArraySize(vo); i++) {
        const cJSON *off = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(vo, i), "byteOffset");
        if (off && (!cJSON_IsNumber(off) || (long long)off->valuedouble % 4 != 0)) {
            snprintf(why, n, "bufferViews[%d].byteOffset %g is not a multiple of 4", i, off->valuedouble);
            return 0;
        }
    }
    if (size >= 12 && memcmp(bytes, "glTF", 4) == 0)
        for (size_t at = 12; at + 8 <= size;) {
            uint32_t length = (uint32_t)bytes[at] | (uint32_t)bytes[at + 1] << 8 | (uint32_t)bytes[at + 2] << 16 |
                              (uint32_t)bytes[at + 3] << 24;
            if (length % 4) { snprintf(why, n, "GLB chunk at byte %zu has length %u", at, length); return 0; }
            at += 8 + (size_t)length;
        }
    return 1;
}

static void test_corpus_write_back(void)
{
    pb_manifest manifest;
    CHECK_CORPUS_MANIFEST(&manifest);
    snprintf(prefix, sizeof prefix, "/tmp/morphkit_writeback_%ld", (long)getpid());
    int done = 0;
    double worst_rel = 0, worst_float = 0, worst_quantized = 0;
    /* The cases' sources, then every variant beside them (quantized, meshopt, gltfpack, sparse). */
    char (*files)[4200] = calloc(256, sizeof *files), (*names)[256] = calloc(256, sizeof *names);
    uint32_t nf = 0;
    for (uint32_t ci = 0; ci < manifest.case_count && nf < 256; ci++) {
        if (!manifest.cases[ci].gltf) continue;
        pb_manifest_path(&manifest, manifest.cases[ci].source, files[nf], sizeof files[0]);
        snprintf(names[nf++], sizeof names[0], "%s", manifest.cases[ci].name);
    }
    for (uint32_t i = 0, n0 = nf; i < n0; i++) {
        char dir[4300];
        dir_of(files[i], dir, sizeof dir);
        char *sl = strrchr(dir, '/');
        if (!sl) continue;
        snprintf(sl, sizeof dir - (size_t)(sl - dir), "/variants");
        DIR *d = opendir(dir);
        struct dirent *e;
        while (d && (e = readdir(d)) && nf < 256) {
            size_t l = strlen(e->d_name);
            if (!(l > 4 && !strcmp(e->d_name + l - 4, ".glb")) && !(l > 5 && !strcmp(e->d_name + l - 5, ".gltf"))) continue;
            char p[4600];
            snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            int dup = 0;
            for (uint32_t k = 0; k < nf; k++) {
                char a[PATH_MAX], b[PATH_MAX];
                dup |= realpath(files[k], a) && realpath(p, b) && !strcmp(a, b);
            }
            if (dup) continue;
            snprintf(files[nf], sizeof files[0], "%.4199s", p);
            snprintf(names[nf++], sizeof names[0], "%s", e->d_name);
        }
        if (d) closedir(d);
    }
    for (uint32_t ci = 0; ci < nf; ci++) {
        struct { const char *name; } case_, *c = &case_;
        case_.name = names[ci];
        char path[4200], out[1024], side[1100], in_dir[4200], out_dir[1024];
        snprintf(path, sizeof path, "%s", files[ci]);
        int glb = strstr(path, ".glb") != NULL;
        snprintf(out, sizeof out, "%s_%s.%s", prefix, c->name, glb ? "glb" : "gltf");
        snprintf(side, sizeof side, "%s_%s.channels.json", prefix, c->name);
        dir_of(path, in_dir, sizeof in_dir);
        dir_of(out, out_dir, sizeof out_dir);
        mk_error err = { 0 };
        mk_raw_asset orig, baked, back;
        mk_arena arena;
        mk_arena_init(&arena, NULL);
        void *in = NULL, *bytes = NULL;
        char *sc = NULL;
        size_t in_size = 0, size = 0, sc_size = 0;
        mk_gltf_write_back_report rep;
        CHECK_MSG(import_path(path, NULL, &orig, &err) == MK_OK, "%s: %s", c->name, err.message);
        CHECK_MSG(import_path(path, NULL, &baked, &err) == MK_OK, "%s: %s", c->name, err.message);
        CHECK_MSG(mk_read_file(&arena, path, (size_t)1 << 30, &in, &in_size, &err) == MK_OK, "%s: %s", c->name, err.message);

        /* Nothing baked: the same file (or, where URIs had to change, an import equal to the original). */
        mk_result r = mk_gltf_write_back(in, in_size, path, out, &orig, &arena, &bytes, &size, &sc, &sc_size, &rep, &err);
        CHECK_MSG(r == MK_OK, "%s: empty write-back: %s", c->name, err.message);
        CHECK(sc == NULL);
        if (r == MK_OK && !rep.rewritten_uris) CHECK(size == in_size && memcmp(bytes, in, size) == 0);

        r = bake_case(&baked, &err);
        CHECK_MSG(r == MK_OK, "%s: bake: %s", c->name, err.message);
        if (r == MK_OK)
            r = mk_gltf_write_back(in, in_size, path, out, &baked, &arena, &bytes, &size, &sc, &sc_size, &rep, &err);
        CHECK_MSG(r == MK_OK, "%s: write-back: %s", c->name, err.message);
        if (r != MK_OK) { mk_raw_free(&orig); mk_raw_free(&baked); mk_arena_free_all(&arena); continue; }
        CHECK(sc != NULL && rep.channels == 3 && rep.animations_added == 1);
        FILE *f = fopen(out, "wb");
        CHECK(f && fwrite(bytes, 1, size, f) == size);
        if (f) fclose(f);
        f = fopen(side, "wb");
        CHECK(f && fwrite(sc, 1, sc_size, f) == sc_size);
        if (f) fclose(f);
        check_valid(out);

        /* The JSON tree: the input's, with members added. */
        cJSON *ji = json_of(in, in_size), *jo = json_of(bytes, size);
        char why[700] = "";
        CHECK_MSG(ji && jo && contains(ji, jo, "$", in_dir, out_dir, why, sizeof why), "%s: %s", c->name, why);
        CHECK_MSG(ji && jo && aligned(ji, jo, bytes, size, why, sizeof why), "%s: %s", c->name, why);

        r = import_path(out, side, &back, &err);
        CHECK_MSG(r == MK_OK, "%s: re-import: %s", c->name, err.message);
        /* nothing the importer had to mend (e.g. repeated sample times of an extended sampler) */
        CHECK_MSG(r != MK_OK || back.warning_count == orig.warning_count, "%s: re-import has %u warnings, the input %u%s%s",
                  c->name, back.warning_count, orig.warning_count, back.warning_count ? ": " : "",
                  back.warning_count ? back.warnings[0].message : "");
        if (r == MK_OK && back.mesh_count == baked.mesh_count && back.clip_count == baked.clip_count) {
            uint32_t *la = calloc(baked.channel_count + 1, 4), *lb = calloc(back.channel_count + 1, 4), *lo = calloc(orig.channel_count + 1, 4);
            for (uint32_t m = 0; m < baked.mesh_count; m++) {
                uint32_t na = mesh_channels(&baked, m, la), nb = mesh_channels(&back, m, lb), no = mesh_channels(&orig, m, lo);
                CHECK_MSG(na == nb, "%s mesh %u: %u channels, re-imported %u", c->name, m, na, nb);
                if (na != nb) continue;
                const mk_raw_mesh *mm = &baked.meshes[m];
                double diag = 0;
                {
                    float l[3] = { 1e30f, 1e30f, 1e30f }, h[3] = { -1e30f, -1e30f, -1e30f };
                    for (uint32_t v = 0; v < mm->vertex_count; v++)
                        for (int k = 0; k < 3; k++) { l[k] = fminf(l[k], mm->positions[3 * v + k]); h[k] = fmaxf(h[k], mm->positions[3 * v + k]); }
                    diag = sqrt((double)(h[0] - l[0]) * (h[0] - l[0]) + (double)(h[1] - l[1]) * (h[1] - l[1]) + (double)(h[2] - l[2]) * (h[2] - l[2]));
                }
                uint32_t slot = 0;
                for (uint32_t k = 0; k < na; k++) {
                    const mk_raw_channel *a = &baked.channels[la[k]], *b = &back.channels[lb[k]];
                    CHECK(strcmp(a->name, b->name) == 0 && a->target_count == b->target_count);
                    if (k < no) {   /* an original channel: bit for bit */
                        CHECK(a->default_weight == b->default_weight);
                        for (uint32_t t = 0; t < a->target_count && t < b->target_count; t++)
                            CHECK_MSG(same_target(a->targets + t, b->targets + t), "%s: channel '%s' changed", c->name, a->name);
                        continue;
                    }
                    CHECK(strcmp(a->origin, b->origin ? b->origin : "") == 0);
                    CHECK_NEAR(b->default_weight, a->default_weight, 1e-6);
                    for (uint32_t t = 0; t < a->target_count && t < b->target_count; t++, slot++) {
                        CHECK(a->targets[t].full_weight == b->targets[t].full_weight);
                        static const char *const sem[] = { "POSITION", "NORMAL", "TANGENT" };
                        for (int s = 0; s < 3; s++) {
                            double e = dense_diff(a->targets + t, b->targets + t, mm->vertex_count, s);
                            double hs = half_step(jo, mm->gltf_mesh, mm->gltf_primitive, no + slot, sem[s]);
                            CHECK_MSG(e <= hs * 1.0001 + 1e-6 * (hs > 0), "%s: channel '%s' target %u %s differs by %g (half step %g)",
                                      c->name, a->name, t, sem[s], e, hs);
                            if (s == 0) worst_rel = fmax(worst_rel, diag > 0 ? e / diag : e);
                            if (s == 0 && hs == 0) worst_float = fmax(worst_float, e);
                            if (s == 0 && hs > 0) worst_quantized = fmax(worst_quantized, diag > 0 ? e / diag : e);
                        }
                    }
                }
            }
            /* Clips: original tracks bit for bit, baked channels held at their default there; the bake's
             * clip played back within the in-between sampling of the weights. */
            for (uint32_t k = 0; k < baked.clip_count; k++) {
                const mk_raw_clip *a = &baked.clips[k], *b = &back.clips[k];
                CHECK(a->start == b->start && a->duration == b->duration);
                for (uint32_t t = 0; t < a->track_count; t++) {
                    const mk_raw_track *ta = &a->tracks[t], *tb = find_track(b, ta->channel);
                    CHECK_MSG(tb != NULL, "%s clip %u: channel %u lost its track", c->name, k, ta->channel);
                    if (!tb) continue;
                    if (k < orig.clip_count) {
                        CHECK(ta->key_count == tb->key_count && memcmp(ta->keys, tb->keys, sizeof(mk_key) * ta->key_count) == 0);
                    } else {
                        for (int q = 0; q <= 200; q++) {
                            double tm = a->duration * q / 200.0;
                            CHECK_NEAR(mk_curve_eval(tb->keys, tb->key_count, tm, NULL), mk_curve_eval(ta->keys, ta->key_count, tm, NULL), 1e-5);
                        }
                    }
                }
                for (uint32_t t = 0; t < b->track_count; t++) {
                    if (find_track(a, b->tracks[t].channel)) continue;
                    const mk_raw_track *tb = &b->tracks[t];
                    for (uint32_t q = 0; q < tb->key_count; q++)
                        CHECK_NEAR(tb->keys[q].value, back.channels[tb->channel].default_weight, 1e-6);
                }
            }
            free(la);
            free(lb);
            free(lo);
        } else if (r == MK_OK) {
            CHECK_MSG(0, "%s: re-import has %u meshes / %u clips, expected %u / %u", c->name, back.mesh_count, back.clip_count,
                      baked.mesh_count, baked.clip_count);
        }
        if (r == MK_OK) mk_raw_free(&back);
        /* Without the sidecar every glTF target is a channel of its own. */
        r = import_path(out, NULL, &back, &err);
        CHECK_MSG(r == MK_OK, "%s: re-import without sidecar: %s", c->name, err.message);
        if (r == MK_OK) {
            uint32_t instances = 0;
            for (uint32_t m = 0; m < orig.mesh_count; m++) instances += orig.meshes[m].gltf_mesh == orig.meshes[0].gltf_mesh;
            CHECK_EQ_INT(back.channel_count, orig.channel_count + rep.targets * instances);
            mk_raw_free(&back);
        }
        cJSON_Delete(ji);
        cJSON_Delete(jo);
        remove(out);
        remove(side);
        mk_raw_free(&orig);
        mk_raw_free(&baked);
        mk_arena_free_all(&arena);
        done++;
    }
    pb_manifest_free(&manifest);
    free(files);
    free(names);
    CHECK(done > 0);
    printf("  %d corpus files baked into themselves: new position deltas within %.3g x diagonal of the bake "
           "(float accessors: max %.3g absolute; quantized: %.3g x diagonal)\n", done, worst_rel, worst_float, worst_quantized);
}

/* A mesh instanced by two nodes, baked on one of them only: refused, naming the mesh. */
static void test_instanced_refused(void)
{
    pb_manifest manifest;
    CHECK_CORPUS_MANIFEST(&manifest);
    char path[4200];
    pb_manifest_path(&manifest, "gltf/AnimatedMorphCube/variants/AnimatedMorphCube.quantized.glb", path, sizeof path);
    pb_manifest_free(&manifest);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    void *in;
    size_t n;
    mk_error err = { 0 };
    if (mk_read_file(&arena, path, (size_t)1 << 30, &in, &n, &err) != MK_OK) SKIP("%s", err.message);
    uint32_t jl;
    memcpy(&jl, (uint8_t *)in + 12, 4);
    cJSON *j = cJSON_ParseWithLength((const char *)in + 20, jl);
    CHECK(j != NULL);
    cJSON *nodes = cJSON_GetObjectItem(j, "nodes"), *second = cJSON_CreateObject();
    cJSON_AddNumberToObject(second, "mesh", 0);
    cJSON_AddStringToObject(second, "name", "copy");
    cJSON_AddItemToArray(nodes, second);
    char *text = cJSON_PrintUnformatted(j);
    size_t tl = strlen(text), tp = (tl + 3) & ~(size_t)3, rest = n - 20 - jl;
    uint8_t *glb = calloc(20 + tp + rest, 1);
    memcpy(glb, in, 20);
    uint32_t total = (uint32_t)(20 + tp + rest), jp = (uint32_t)tp;
    memcpy(glb + 8, &total, 4);
    memcpy(glb + 12, &jp, 4);
    memcpy(glb + 20, text, tl);
    memset(glb + 20 + tl, ' ', tp - tl);
    memcpy(glb + 20 + tp, (uint8_t *)in + 20 + jl, rest);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_import_options io = { .keep_plain_meshes = 1 };
    CHECK(mk_import_memory(glb, total, &io, &raw, &err) == MK_OK);
    CHECK_EQ_INT(raw.mesh_count, 2);
    const char *recipe = "{ \"mesh\": 0, \"channels\": [ { \"op\": \"taper\", \"axis\": \"y\", \"scale\": 0.5 } ] }";
    mk_bake_report br;
    CHECK(mk_bake_recipe(&raw, recipe, strlen(recipe), NULL, &br, &err) == MK_OK);
    void *out = NULL;
    size_t size = 0;
    mk_result r = mk_gltf_write_back(glb, total, NULL, NULL, &raw, &arena, &out, &size, NULL, NULL, NULL, &err);
    CHECK_EQ_INT(r, MK_ERROR_UNSUPPORTED);
    CHECK(out == NULL && strstr(err.message, "mesh 0") && strstr(err.message, "instanced by nodes 0 and 1"));
    printf("  refused: %s\n", err.message);
    /* Baked alike on both: written, one set of targets for the shared mesh. */
    mk_raw_free(&raw);
    mk_raw_init(&raw, NULL);
    CHECK(mk_import_memory(glb, total, &io, &raw, &err) == MK_OK);
    const char *both = "{ \"channels\": [ { \"name\": \"t\", \"mesh\": 0, \"op\": \"taper\", \"axis\": \"y\", \"scale\": 0.5 },"
                       " { \"name\": \"t\", \"mesh\": 1, \"op\": \"taper\", \"axis\": \"y\", \"scale\": 0.5 } ] }";
    CHECK(mk_bake_recipe(&raw, both, strlen(both), NULL, &br, &err) == MK_OK);
    mk_gltf_write_back_report rep;
    r = mk_gltf_write_back(glb, total, NULL, NULL, &raw, &arena, &out, &size, NULL, NULL, &rep, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    CHECK(rep.targets == 1 && rep.meshes == 1);
    /* Bad input: the wrong container for the output, and a damaged GLB. */
    r = mk_gltf_write_back(glb, total, NULL, "x.gltf", &raw, &arena, &out, &size, NULL, NULL, NULL, &err);
    CHECK(r == MK_ERROR_INVALID_ARGUMENT && strstr(err.message, ".glb"));
    glb[12] = 0xff;
    r = mk_gltf_write_back(glb, total, NULL, NULL, &raw, &arena, &out, &size, NULL, NULL, NULL, &err);
    CHECK(r != MK_OK && out == NULL);
    mk_raw_free(&raw);
    free(glb);
    free(text);
    cJSON_Delete(j);
    mk_arena_free_all(&arena);
}

/* ---- a glTF made here: sparse targets, primitive.extras.targetNames, node.weights ---- */

/* Two primitives (12 and 3 vertices, one float target each, named in primitive.extras
 * targetNames), mesh.weights and node.weights that differ, and a weight animation whose last key
 * is 3e10 s (a clip range the sidecar must carry). Buffer as a data: URI. */
static char *synthetic_gltf(void)
{
    float bin[12 * 3 * 2 + 3 * 3 * 2 + 2 + 2];
    size_t o = 0;
    for (int v = 0; v < 12; v++) { bin[o++] = (float)(v % 4); bin[o++] = (float)(v / 4); bin[o++] = (float)(v % 3) * 0.5f; }
    for (int v = 0; v < 12; v++) { bin[o++] = 0; bin[o++] = 0.125f; bin[o++] = 0; }
    for (int v = 0; v < 3; v++) { bin[o++] = 5.0f + (float)v; bin[o++] = (float)(v == 2); bin[o++] = 0; }
    for (int v = 0; v < 3; v++) { bin[o++] = 0; bin[o++] = 0; bin[o++] = -0.25f; }
    bin[o++] = 0; bin[o++] = 3e10f;       /* key times */
    bin[o++] = 0.75f; bin[o++] = 0.25f;   /* weights of the one target */
    char *b64 = gt_base64((const unsigned char *)bin, sizeof bin);
    char *json = malloc(8192);
    snprintf(json, 8192,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"name\":\"n\",\"mesh\":0,\"weights\":[0.3]}],"
             "\"meshes\":[{\"name\":\"m\",\"weights\":[0.5],\"primitives\":["
             "{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":1}],\"extras\":{\"targetNames\":[\"orig\"]}},"
             "{\"attributes\":{\"POSITION\":2},\"targets\":[{\"POSITION\":3}],\"extras\":{\"targetNames\":[\"orig\"],\"keep\":1}}]}],"
             "\"animations\":[{\"name\":\"far\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}],"
             "\"samplers\":[{\"input\":4,\"output\":5,\"interpolation\":\"LINEAR\"}]}],"
             "\"accessors\":["
             "{\"bufferView\":0,\"componentType\":5126,\"count\":12,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[3,2,1]},"
             "{\"bufferView\":0,\"byteOffset\":144,\"componentType\":5126,\"count\":12,\"type\":\"VEC3\",\"min\":[0,0.125,0],\"max\":[0,0.125,0]},"
             "{\"bufferView\":0,\"byteOffset\":288,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[5,0,0],\"max\":[7,1,0]},"
             "{\"bufferView\":0,\"byteOffset\":324,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,-0.25],\"max\":[0,0,-0.25]},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[3e10]},"
             "{\"bufferView\":1,\"byteOffset\":8,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":360,\"byteStride\":12,\"target\":34962},{\"buffer\":0,\"byteOffset\":360,\"byteLength\":16}],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}]}",
             sizeof bin, b64);
    free(b64);
    return json;
}

/* The render vertex of raw mesh m that is glTF vertex g. */
static uint32_t render_vertex(const mk_raw_mesh *m, uint32_t g)
{
    for (uint32_t v = 0; v < m->vertex_count; v++)
        if (m->control_points[v] == g) return v;
    return UINT32_MAX;
}

static const cJSON *at(const cJSON *j, const char *path)
{
    /* "a.b.3.c": members and array indices */
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *tok = strtok(buf, "."); tok && j; tok = strtok(NULL, "."))
        j = (*tok >= '0' && *tok <= '9') ? cJSON_GetArrayItem(j, atoi(tok)) : cJSON_GetObjectItemCaseSensitive(j, tok);
    return j;
}

static int numbers_are(const cJSON *a, const double *v, int n)
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return 0;
    for (int i = 0; i < n; i++)
        if (fabs(cJSON_GetArrayItem(a, i)->valuedouble - v[i]) > 1e-6) return 0;
    return 1;
}

static int strings_are(const cJSON *a, const char *const *v, int n)
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return 0;
    for (int i = 0; i < n; i++)
        if (!cJSON_IsString(cJSON_GetArrayItem(a, i)) || strcmp(cJSON_GetArrayItem(a, i)->valuestring, v[i])) return 0;
    return 1;
}

static void test_synthetic(void)
{
    char *json = synthetic_gltf();
    size_t json_size = strlen(json);
    mk_raw_asset raw;
    mk_error err;
    mk_import_options io = { .keep_plain_meshes = 1 };
    CHECK_MSG(gt_import_text(json, &io, &raw, &err) == MK_OK, "%s", err.message);
    CHECK_EQ_INT(raw.mesh_count, 2);
    CHECK_EQ_INT(raw.channel_count, 2);
    CHECK_EQ_INT(raw.clip_count, 1);
    if (raw.mesh_count != 2 || raw.channel_count != 2 || raw.clip_count != 1) { mk_raw_free(&raw); free(json); return; }
    CHECK(raw.clips[0].duration == 3e10f);
    uint32_t a = raw.meshes[0].gltf_primitive == 0 ? 0 : 1;
    const mk_raw_mesh *ma = &raw.meshes[a];
    CHECK_NEAR(raw.channels[raw.channels[0].mesh == a ? 0 : 1].default_weight, 0.3, 1e-6);   /* node.weights */

    /* wb_sparse moves glTF vertices 1, 3 and 5 of primitive 0 (3 of 12: a sparse accessor, whose
     * 3 uint16 indices end off a 4-byte boundary); wb_prog has two in-betweens moving every
     * vertex (dense) and a default weight of 0.25. */
    static const float sparse_delta[3][3] = { { 0.5f, 0.125f, -0.25f }, { 0.25f, 0.25f, -0.125f }, { 0.375f, 0.125f, -0.125f } };
    mk_raw_channel *sp = mk_raw_add_channels(&raw, 1);
    sp->name = "wb_sparse";
    sp->origin = "{\"op\":\"made_up\"}";
    sp->mesh = a;
    mk_raw_target *t = mk_raw_add_targets(&raw, sp, 1);
    t->name = "wb_sparse";
    t->full_weight = 1;
    t->count = 3;
    t->indices = mk_arena_array(&raw.arena, 3, sizeof *t->indices);
    t->positions = mk_arena_array(&raw.arena, 3, 3 * sizeof *t->positions);
    {
        uint32_t rv[3] = { render_vertex(ma, 1), render_vertex(ma, 3), render_vertex(ma, 5) }, order[3] = { 0, 1, 2 };
        for (int i = 0; i < 3; i++)   /* target indices increase */
            for (int j = i + 1; j < 3; j++)
                if (rv[order[j]] < rv[order[i]]) { uint32_t x = order[i]; order[i] = order[j]; order[j] = x; }
        for (int i = 0; i < 3; i++) {
            t->indices[i] = rv[order[i]];
            memcpy(t->positions + 3 * i, sparse_delta[order[i]], sizeof sparse_delta[0]);
        }
    }
    mk_raw_channel *pg = mk_raw_add_channels(&raw, 1);
    pg->name = "wb_prog";
    pg->origin = "{\"op\":\"made_up\"}";
    pg->mesh = a;
    pg->default_weight = 0.25f;
    t = mk_raw_add_targets(&raw, pg, 2);
    for (int k = 0; k < 2; k++) {
        t[k].name = k ? "wb_prog_full" : "wb_prog_half";
        t[k].full_weight = k ? 1.0f : 0.5f;
        t[k].count = ma->vertex_count;
        t[k].indices = mk_arena_array(&raw.arena, ma->vertex_count, sizeof *t->indices);
        t[k].positions = mk_arena_array(&raw.arena, ma->vertex_count, 3 * sizeof *t->positions);
        for (uint32_t v = 0; v < ma->vertex_count; v++) {
            t[k].indices[v] = v;
            t[k].positions[3 * v] = 0;
            t[k].positions[3 * v + 1] = 0;
            t[k].positions[3 * v + 2] = (float)(k + 1) * 0.0625f * (float)(ma->control_points[v] + 1);
        }
    }
    CHECK(mk_raw_group_channels(&raw, &err) == MK_OK && mk_raw_validate(&raw, &err) == MK_OK);

    mk_arena arena;
    mk_arena_init(&arena, NULL);
    void *out = NULL;
    char *sc = NULL;
    size_t size = 0, sc_size = 0;
    mk_gltf_write_back_report rep;
    mk_result r = mk_gltf_write_back(json, json_size, NULL, NULL, &raw, &arena, &out, &size, &sc, &sc_size, &rep, &err);
    CHECK_MSG(r == MK_OK, "%s", err.message);
    if (r != MK_OK) { mk_raw_free(&raw); mk_arena_free_all(&arena); free(json); return; }
    CHECK(rep.channels == 2 && rep.targets == 3 && rep.padding_targets == 3 && rep.sparse_accessors == 1 &&
          rep.dense_accessors == 2 && rep.rewritten_samplers == 1 && rep.sidecar_needed && sc != NULL);
    char path[96], side[112];
    snprintf(path, sizeof path, "/tmp/morphkit_writeback_%ld_synthetic.gltf", (long)getpid());
    snprintf(side, sizeof side, "/tmp/morphkit_writeback_%ld_synthetic.channels.json", (long)getpid());
    FILE *f = fopen(path, "wb");
    CHECK(f && fwrite(out, 1, size, f) == size);
    if (f) fclose(f);
    f = fopen(side, "wb");
    CHECK(f && fwrite(sc, 1, sc_size, f) == sc_size);
    if (f) fclose(f);
    check_valid(path);

    cJSON *ji = json_of((const uint8_t *)json, json_size), *jo = json_of(out, size);
    char why[700] = "";
    CHECK_MSG(ji && jo && contains(ji, jo, "$", ".", ".", why, sizeof why), "%s", why);
    CHECK_MSG(ji && jo && aligned(ji, jo, out, size, why, sizeof why), "%s", why);
    /* The sparse target: 3 indices (unsigned short) and values, no bufferView; the
     * in-betweens dense; the other primitive's padding: accessors without data (zeros). */
    const cJSON *acc = cJSON_GetObjectItemCaseSensitive(jo, "accessors");
    int pos[2][4];
    for (int q = 0; q < 2; q++)
        for (int k = 0; k < 4; k++) {
            char p[64];
            snprintf(p, sizeof p, "meshes.0.primitives.%d.targets.%d.POSITION", q, k);
            const cJSON *x = at(jo, p);
            pos[q][k] = cJSON_IsNumber(x) ? x->valueint : -1;
            CHECK_MSG(pos[q][k] >= 0 && pos[q][k] < cJSON_GetArraySize(acc), "%s", p);
        }
    CHECK_EQ_INT(cJSON_GetArraySize(at(jo, "meshes.0.primitives.0.targets")), 4);
    CHECK_EQ_INT(cJSON_GetArraySize(at(jo, "meshes.0.primitives.1.targets")), 4);
    if (pos[0][1] >= 0) {
        const cJSON *s1 = cJSON_GetArrayItem(acc, pos[0][1]);
        CHECK(!cJSON_GetObjectItemCaseSensitive(s1, "bufferView"));
        CHECK_EQ_INT(at(s1, "sparse.count") ? at(s1, "sparse.count")->valueint : -1, 3);
        CHECK_EQ_INT(at(s1, "sparse.indices.componentType") ? at(s1, "sparse.indices.componentType")->valueint : -1, 5123);
        CHECK_EQ_INT(at(s1, "count") ? at(s1, "count")->valueint : -1, 12);
        /* the untouched vertices' zeros count: no moved delta is 0 on any axis */
        static const double lo[3] = { 0, 0, -0.25 }, hi[3] = { 0.5, 0.25, 0 };
        CHECK(numbers_are(at(s1, "min"), lo, 3) && numbers_are(at(s1, "max"), hi, 3));
    }
    for (int k = 2; k < 4; k++)
        if (pos[0][k] >= 0) {
            const cJSON *d = cJSON_GetArrayItem(acc, pos[0][k]);
            CHECK(cJSON_GetObjectItemCaseSensitive(d, "bufferView") && !cJSON_GetObjectItemCaseSensitive(d, "sparse"));
        }
    for (int k = 1; k < 4; k++)
        if (pos[1][k] >= 0) {
            const cJSON *z = cJSON_GetArrayItem(acc, pos[1][k]);
            CHECK(!cJSON_GetObjectItemCaseSensitive(z, "bufferView") && !cJSON_GetObjectItemCaseSensitive(z, "sparse"));
        }
    /* Weights: the defaults of the new targets (wb_prog at 0.25 = half of its 0.5 in-between)
     * appended to node.weights and mesh.weights alike. */
    static const double node_w[4] = { 0.3, 0, 0.5, 0 }, mesh_w[4] = { 0.5, 0, 0.5, 0 };
    CHECK_MSG(numbers_are(at(jo, "nodes.0.weights"), node_w, 4), "node.weights not extended");
    CHECK_MSG(numbers_are(at(jo, "meshes.0.weights"), mesh_w, 4), "mesh.weights not extended");
    /* Target names: both primitives' extras.targetNames and the mesh's (created). */
    static const char *const names[4] = { "orig", "wb_sparse", "wb_prog_half", "wb_prog_full" };
    CHECK_MSG(strings_are(at(jo, "meshes.0.primitives.0.extras.targetNames"), names, 4), "primitive 0 targetNames");
    CHECK_MSG(strings_are(at(jo, "meshes.0.primitives.1.extras.targetNames"), names, 4), "primitive 1 targetNames");
    CHECK_MSG(strings_are(at(jo, "meshes.0.extras.targetNames"), names, 4), "mesh targetNames");
    cJSON_Delete(ji);
    cJSON_Delete(jo);

    /* Re-imported with the sidecar: the same channels (sparse deltas exact, float accessors),
     * defaults, the clip's weights held, the clip's 3e10 s range. */
    mk_raw_asset back;
    r = import_path(path, side, &back, &err);
    CHECK_MSG(r == MK_OK, "re-import: %s", err.message);
    if (r == MK_OK) {
        CHECK_EQ_INT(back.channel_count, 4);
        CHECK(back.clip_count == 1 && back.clips[0].duration == 3e10f);
        for (uint32_t c = 0; c < back.channel_count && back.channel_count == 4; c++) {
            const mk_raw_channel *x = &back.channels[c], *y = NULL;
            for (uint32_t d = 0; d < raw.channel_count; d++)
                if (raw.channels[d].mesh == x->mesh && !strcmp(raw.channels[d].name, x->name)) y = &raw.channels[d];
            CHECK_MSG(y != NULL, "re-imported channel '%s' on mesh %u was not written", x->name, x->mesh);
            if (!y) continue;
            CHECK_NEAR(x->default_weight, y->default_weight, 1e-6);
            CHECK_EQ_INT(x->target_count, y->target_count);
            for (uint32_t k = 0; k < x->target_count && x->target_count == y->target_count; k++)
                CHECK_MSG(same_target(&x->targets[k], &y->targets[k]), "channel '%s' target %u differs", x->name, k);
        }
        const mk_raw_clip *clip = &back.clips[0];
        for (uint32_t k = 0; k < clip->track_count; k++) {
            const mk_raw_channel *x = &back.channels[clip->tracks[k].channel];
            if (!strcmp(x->name, "orig")) continue;
            for (uint32_t q = 0; q < clip->tracks[k].key_count; q++)
                CHECK_NEAR(clip->tracks[k].keys[q].value, x->default_weight, 1e-6);
        }
        mk_raw_free(&back);
    }
    /* Without it: one channel per target, named from the target names. */
    r = import_path(path, NULL, &back, &err);
    CHECK_MSG(r == MK_OK, "re-import without sidecar: %s", err.message);
    if (r == MK_OK) {
        CHECK_EQ_INT(back.channel_count, 8);
        for (uint32_t c = 0; c < back.channel_count && back.channel_count == 8; c++)
            CHECK_MSG(!strcmp(back.channels[c].name, names[c % 4]), "channel %u is '%s'", c, back.channels[c].name);
        mk_raw_free(&back);
    }
    if (!getenv("MK_KEEP_OUTPUT")) { remove(path); remove(side); }
    mk_raw_free(&raw);
    mk_arena_free_all(&arena);
    free(json);
}

/* ffd_keys bakes one channel per key span and one clip whose tracks share their key times: the
 * clip's new animation samples each time once (repeated sampler input times are invalid glTF),
 * and a re-import has the bake's keys. */
static void test_keyed_clip(void)
{
    char path[4200], dir[4200];
    snprintf(path, sizeof path, "%s/gltf/SimpleMorph/glTF/SimpleMorph.gltf", check_corpus_dir());
    mk_raw_asset baked, back;
    mk_error err;
    if (import_path(path, NULL, &baked, &err) != MK_OK) SKIP("corpus not found at %s", check_corpus_dir());
    dir_of(path, dir, sizeof dir);
    static const char recipe[] =
        "{ \"mesh\": 0, \"channels\": [ { \"name\": \"sway\", \"op\": \"ffd_keys\", \"dims\": [2, 3, 2],"
        "  \"origin\": [-0.6, -0.6, -0.6], \"axes\": [[2.4, 0, 0], [0, 2.4, 0], [0, 0, 2.4]],"
        "  \"keys\": [ { \"time\": 0 }, { \"time\": 0.5, \"moves\": [ { \"j\": 2, \"translate\": [0.3, 0, 0] } ] },"
        "            { \"time\": 1.0, \"moves\": [ { \"j\": 2, \"translate\": [-0.3, 0, 0] } ] }, { \"time\": 1.5 } ] } ] }";
    mk_result r = mk_bake_recipe(&baked, recipe, sizeof recipe - 1, NULL, NULL, &err);
    CHECK_MSG(r == MK_OK, "bake: %s", err.message);
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    void *in = NULL, *bytes = NULL;
    char *sc = NULL;
    size_t in_size = 0, size = 0, sc_size = 0;
    mk_gltf_write_back_report rep;
    if (r == MK_OK) r = mk_read_file(&arena, path, (size_t)1 << 30, &in, &in_size, &err);
    if (r == MK_OK) r = mk_gltf_write_back(in, in_size, path, path, &baked, &arena, &bytes, &size, &sc, &sc_size, &rep, &err);
    CHECK_MSG(r == MK_OK, "write-back: %s", err.message);
    const mk_raw_clip *clip = r == MK_OK ? &baked.clips[baked.clip_count - 1] : NULL;
    CHECK(!clip || clip->track_count >= 2);
    if (r == MK_OK) {
        mk_import_options io = { .keep_plain_meshes = 1, .base_dir = dir, .channels_sidecar_text = sc,
                                 .channels_sidecar_size = sc_size };
        mk_raw_init(&back, NULL);
        r = mk_import_memory(bytes, size, &io, &back, &err);
        CHECK_MSG(r == MK_OK, "re-import: %s", err.message);
        CHECK_EQ_INT(back.warning_count, 0);
        const mk_raw_clip *again = r == MK_OK && back.clip_count ? &back.clips[back.clip_count - 1] : NULL;
        CHECK(again != NULL);
        /* Each baked track plays the same from the re-import (glTF samples the union of the
         * tracks' times, so the re-imported tracks have more keys), keys strictly increasing. */
        for (uint32_t t = 0; again && t < clip->track_count; t++) {
            const mk_raw_track *x = &clip->tracks[t];
            const char *name = baked.channels[x->channel].name;
            const mk_raw_track *y = NULL;
            for (uint32_t u = 0; u < again->track_count; u++)
                if (!strcmp(back.channels[again->tracks[u].channel].name, name)) y = &again->tracks[u];
            CHECK_MSG(y != NULL, "track of '%s' lost", name);
            for (uint32_t k = 1; y && k < y->key_count; k++) CHECK(y->keys[k].time > y->keys[k - 1].time);
            for (int i = 0; y && i <= 30; i++) {
                float time = 0.05f * (float)i;
                CHECK_NEAR(mk_curve_eval(y->keys, y->key_count, time, NULL), mk_curve_eval(x->keys, x->key_count, time, NULL),
                           1e-5);
            }
        }
        mk_raw_free(&back);
    }
    mk_arena_free_all(&arena);
    mk_raw_free(&baked);
}

static void test_validator_ran(void)
{
    if (validator_missing || !validated) SKIP("glTF validator not available (npm install --prefix tests/gltf)");
    printf("  %d written-back files passed the Khronos glTF validator\n", validated);
}

CHECK_MAIN(CASE(test_corpus_write_back), CASE(test_instanced_refused), CASE(test_synthetic), CASE(test_keyed_clip), CASE(test_validator_ran))

/* morphkit play FILE [--clip NAME|INDEX] [--time T] [--weights NAME=V,...]
 *   [--stacking additive|sequential] [--normals nlerp|slerp] [--space world|local] -o OUT.json|OUT.obj
 * Evaluates one frame through the runtime and writes it: JSON shaped like the corpus's
 * reference frames (meshes[] with name, positions, normals), or OBJ. */
#include <stdlib.h>
#include <string.h>
#include "asset_load.h"
#include "frame.h"
#include "json_write.h"

static int usage(void)
{
    fprintf(stderr, "usage: morphkit play FILE [--clip NAME|INDEX] [--time T] [--weights NAME=V,...]\n"
                    "       [--stacking additive|sequential] [--normals nlerp|slerp] [--space world|local] -o OUT.json|OUT.obj\n");
    return 2;
}

/* "name=0.5,other=1" or "3=0.5": channel by name or index. */
static int apply_weights(const mk_asset *a, const char *spec, float *weights)
{
    char buf[4096];
    if (strlen(spec) >= sizeof buf) return 0;
    strcpy(buf, spec);
    for (char *item = strtok(buf, ","); item; item = strtok(NULL, ",")) {
        char *eq = strrchr(item, '=');
        if (!eq) { fprintf(stderr, "morphkit play: --weights item '%s' needs NAME=VALUE\n", item); return 0; }
        *eq = 0;
        char *end;
        float v = strtof(eq + 1, &end);
        if (*end || eq[1] == 0) { fprintf(stderr, "morphkit play: bad weight value '%s'\n", eq + 1); return 0; }
        int32_t c = mk_find_channel(a, item);
        if (c < 0) {
            long idx = strtol(item, &end, 10);
            if (*end || idx < 0 || idx >= (long)a->channel_count) {
                fprintf(stderr, "morphkit play: no channel named '%s'\n", item);
                return 0;
            }
            c = (int32_t)idx;
        }
        weights[c] = v;
    }
    return 1;
}

static void write_json(FILE *f, const mk_asset *a, float **pos, float **nrm, const char *space, double time, int32_t clip,
                       const float *weights)
{
    json_writer w;
    json_begin(&w, f, 0);
    json_object(&w, NULL);
    json_string(&w, "reference", "morphkit play");
    if (clip >= 0) json_number(&w, "time", time);
    json_string(&w, "coordinates", space);
    json_array(&w, "meshes");
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        json_object(&w, NULL);
        json_string(&w, "name", m.name);
        json_string(&w, "node", m.name);
        if (m.gltf_node >= 0) {
            json_int(&w, "gltf_node", m.gltf_node);
            json_int(&w, "gltf_mesh", m.gltf_mesh);
            json_int(&w, "gltf_primitive", m.gltf_primitive);
        }
        json_int(&w, "vertices", m.vertex_count);
        json_array(&w, "channels");
        for (uint32_t c = m.first_channel; c < m.first_channel + m.channel_count; c++) {
            mk_channel_info ch;
            mk_channel_get(a, c, &ch);
            json_object(&w, NULL);
            json_string(&w, "name", ch.name);
            json_number(&w, "weight", weights[c]);
            json_end_object(&w);
        }
        json_end_array(&w);
        json_floats(&w, "positions", pos[i], 3u * (size_t)m.vertex_count);
        if (nrm[i]) json_floats(&w, "normals", nrm[i], 3u * (size_t)m.vertex_count);
        json_array(&w, "control_points");
        for (uint32_t v = 0; v < m.vertex_count; v++) json_int(&w, NULL, m.control_points[v]);
        json_end_array(&w);
        json_end_object(&w);
    }
    json_end_array(&w);
    json_end_object(&w);
}

static void write_obj(FILE *f, const mk_asset *a, float **pos, float **nrm)
{
    fprintf(f, "# morphkit play\n");
    uint32_t base = 1;
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        fprintf(f, "o %s\n", m.name);
        for (uint32_t v = 0; v < m.vertex_count; v++)
            fprintf(f, "v %.9g %.9g %.9g\n", (double)pos[i][3 * v], (double)pos[i][3 * v + 1], (double)pos[i][3 * v + 2]);
        if (nrm[i])
            for (uint32_t v = 0; v < m.vertex_count; v++)
                fprintf(f, "vn %.9g %.9g %.9g\n", (double)nrm[i][3 * v], (double)nrm[i][3 * v + 1], (double)nrm[i][3 * v + 2]);
        for (uint32_t t = 0; t < m.triangle_count; t++) {
            uint32_t x = m.triangles[3 * t] + base, y = m.triangles[3 * t + 1] + base, z = m.triangles[3 * t + 2] + base;
            if (nrm[i]) fprintf(f, "f %u//%u %u//%u %u//%u\n", x, x, y, y, z, z);
            else fprintf(f, "f %u %u %u\n", x, y, z);
        }
        base += m.vertex_count;
    }
}

int cmd_play(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *clip_arg = NULL, *weights_arg = NULL, *space = "world";
    double time = 0;
    int have_time = 0;
    mk_stacking stacking = MK_STACKING_ASSET;
    mk_normal_mode nmode = MK_NORMALS_NLERP;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-o") && v) { out = v; i++; }
        else if (!strcmp(a, "--clip") && v) { clip_arg = v; i++; }
        else if (!strcmp(a, "--time") && v) {
            char *end;
            time = strtod(v, &end);
            if (*end) return usage();
            have_time = 1;
            i++;
        }
        else if (!strcmp(a, "--weights") && v) { weights_arg = v; i++; }
        else if (!strcmp(a, "--stacking") && v) { int s = cli_parse_stacking(v); if (s < 0) return usage(); stacking = (mk_stacking)s; i++; }
        else if (!strcmp(a, "--normals") && v) {
            if (!strcmp(v, "nlerp")) nmode = MK_NORMALS_NLERP;
            else if (!strcmp(v, "slerp")) nmode = MK_NORMALS_SLERP;
            else return usage();
            i++;
        }
        else if (!strcmp(a, "--space") && v) {
            if (strcmp(v, "world") && strcmp(v, "local")) return usage();
            space = v;
            i++;
        }
        else if (!strcmp(a, "--help")) { usage(); return 0; }
        else if (a[0] != '-' && !in) in = a;
        else { fprintf(stderr, "morphkit play: unexpected argument '%s'\n", a); return usage(); }
    }
    if (!in || !out) return usage();
    loaded_asset l;
    mk_error err;
    if (load_asset(in, NULL, NULL, &l, &err)) { loaded_asset_free(&l); return cli_fail("play", &err); }
    const mk_asset *a = &l.asset;
    int32_t clip = -1;
    if (clip_arg) {
        clip = mk_find_clip(a, clip_arg);
        if (clip < 0) {
            char *end;
            long idx = strtol(clip_arg, &end, 10);
            if (*end || idx < 0 || idx >= (long)a->clip_count) {
                fprintf(stderr, "morphkit play: no clip '%s' (the asset has %u clips)\n", clip_arg, a->clip_count);
                loaded_asset_free(&l);
                return 2;
            }
            clip = (int32_t)idx;
        }
    } else if (have_time && a->clip_count) {
        clip = 0;
    }
    float *weights = calloc(a->channel_count + 1u, sizeof(float));
    float **pos = calloc(a->mesh_count + 1u, sizeof(float *)), **nrm = calloc(a->mesh_count + 1u, sizeof(float *));
    int status = 0;
    if (!weights || !pos || !nrm) { fprintf(stderr, "morphkit play: out of memory\n"); status = 1; goto done; }
    if (frame_weights(a, clip, time, weights, &err)) { status = cli_fail("play", &err); goto done; }
    if (weights_arg && !apply_weights(a, weights_arg, weights)) { status = 2; goto done; }
    for (uint32_t i = 0; i < a->mesh_count; i++) {
        mk_mesh_info m;
        mk_mesh_get(a, i, &m);
        pos[i] = malloc(12u * (size_t)m.vertex_count);
        nrm[i] = m.has_normals ? malloc(12u * (size_t)m.vertex_count) : NULL;
        if (!pos[i] || (m.has_normals && !nrm[i])) { fprintf(stderr, "morphkit play: out of memory\n"); status = 1; goto done; }
        if (frame_eval_mesh(a, i, weights, stacking, nmode, pos[i], nrm[i], &err)) { status = cli_fail("play", &err); goto done; }
        if (!strcmp(space, "world")) frame_to_world(m.world, pos[i], nrm[i], m.vertex_count);
    }
    {
        /* Atomic output: render to memory, then temp file + rename. */
        char *text = NULL;
        size_t text_size = 0;
        FILE *f = open_memstream(&text, &text_size);
        if (!f) { fprintf(stderr, "morphkit play: out of memory\n"); status = 1; goto done; }
        if (mk_path_has_extension(out, ".obj")) write_obj(f, a, pos, nrm);
        else write_json(f, a, pos, nrm, space, time, clip, weights);
        fclose(f);
        mk_result r = mk_write_file_atomic(out, text, text_size, &err);
        free(text);
        if (r) { status = cli_fail("play", &err); goto done; }
    }
    printf("%s: %s frame of %u mesh%s written to %s\n", in, clip >= 0 ? "animated" : "rest-pose", a->mesh_count,
           a->mesh_count == 1 ? "" : "es", out);
    if (clip >= 0) {
        mk_clip_info ci;
        mk_clip_get(a, (uint32_t)clip, &ci);
        printf("clip '%s' at %g s\n", ci.name, time);
    }
    for (uint32_t c = 0; c < a->channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(a, c, &ch);
        printf("  %-32s %8.4f\n", ch.name, (double)weights[c]);
    }
done:
    for (uint32_t i = 0; pos && i < a->mesh_count; i++) free(pos[i]);
    for (uint32_t i = 0; nrm && i < a->mesh_count; i++) free(nrm[i]);
    free(pos);
    free(nrm);
    free(weights);
    loaded_asset_free(&l);
    return status;
}

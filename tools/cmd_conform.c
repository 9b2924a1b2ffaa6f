/* morphkit conform: playback checked against reference frames made by other software.
 *
 * With q16 precision the allowed error is the case tolerance plus the quantization bound the
 * writer reports, propagated through the frame's channel coefficients and the world scale. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "asset_load.h"
#include "frame.h"

typedef struct conform_options {
    const char *filter;
    mk_precision precision;
    double normal_tolerance_deg;
} conform_options;

typedef struct counts { int passed, failed; } counts;

/* Reference files are read whole through mk_read_file (size limit, errors naming the file). */
#define CONFORM_MAX_FILE ((size_t)1 << 30)

/* The whole file as NUL-terminated text in arena memory; on failure NULL and the reason in why. */
static char *read_reference(mk_arena *arena, const char *path, size_t *size, char *why, size_t why_size)
{
    void *data;
    mk_error err;
    if (mk_read_file(arena, path, CONFORM_MAX_FILE, &data, size, &err) == MK_OK) return data;
    snprintf(why, why_size, "%s", err.message);
    return NULL;
}

/* Parses a JSON file; on failure NULL and the reason in why. */
static cJSON *read_json(const char *path, char *why, size_t why_size)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    size_t size;
    const char *text = read_reference(&arena, path, &size, why, why_size), *end = NULL;
    cJSON *j = text ? cJSON_ParseWithLengthOpts(text, size, &end, 0) : NULL;
    if (text && !j)
        snprintf(why, why_size, "%.900s: JSON parse error at byte %zu", path, end ? (size_t)(end - text) : (size_t)0);
    mk_arena_free_all(&arena);
    return j;
}

/* Reference mesh positions from an OBJ: every 'v' line, in order (one per control point).
 * On failure NULL and the reason in why. */
static double *read_obj_positions(const char *path, uint32_t *count, char *why, size_t why_size)
{
    mk_arena arena;
    mk_arena_init(&arena, NULL);
    size_t size;
    char *text = read_reference(&arena, path, &size, why, why_size);
    if (!text) {
        mk_arena_free_all(&arena);
        return NULL;
    }
    size_t cap = 1024, n = 0;
    double *p = malloc(cap * sizeof(double));
    for (char *line = strtok(text, "\n"); line && p; line = strtok(NULL, "\n")) {
        if (line[0] != 'v' || line[1] != ' ') continue;
        double x, y, z;
        if (sscanf(line + 2, "%lf %lf %lf", &x, &y, &z) != 3) continue;
        if (n + 3 > cap) {
            cap *= 2;
            double *q = realloc(p, cap * sizeof(double));
            if (!q) { free(p); p = NULL; break; }
            p = q;
        }
        p[n++] = x; p[n++] = y; p[n++] = z;
    }
    mk_arena_free_all(&arena);
    if (!p) snprintf(why, why_size, "%.900s: out of memory", path);
    *count = (uint32_t)(n / 3);
    return p;
}

static double *json_double_array(const cJSON *array, uint32_t *count)
{
    int n = cJSON_GetArraySize(array);
    if (!cJSON_IsArray(array) || n <= 0) { *count = 0; return NULL; }
    double *p = malloc((size_t)n * sizeof(double));
    int i = 0;
    for (const cJSON *e = array->child; e && p; e = e->next) p[i++] = e->valuedouble;
    *count = (uint32_t)n;
    return p;
}

/* Half the spacing of float32 values around |x|: the rounding error of storing x as float. */
static double float32_half_ulp(double x)
{
    int exponent;
    frexp(x, &exponent);  /* 2^(exponent-1) <= |x| < 2^exponent */
    return x > 0 ? ldexp(1.0, exponent - 25) : 0.0;
}

/* A manifest path: relative to the manifest's folder unless absolute. */
static void join_path(char *out, size_t size, const char *base_dir, const char *path)
{
    if (path[0] == '/') snprintf(out, size, "%s", path);
    else snprintf(out, size, "%s/%s", base_dir, path);
}

static double max_column_norm(const float *w)
{
    double m = 0;
    for (int c = 0; c < 3; c++) {
        double s = sqrt((double)w[4 * c] * w[4 * c] + (double)w[4 * c + 1] * w[4 * c + 1] + (double)w[4 * c + 2] * w[4 * c + 2]);
        if (s > m) m = s;
    }
    return m;
}

/* Sum over the mesh's channels of |ca| + |cb|: how many quantized deltas a vertex can add. */
static double coefficient_sum(const mk_asset *a, const mk_mesh_info *m, const float *weights)
{
    double sum = 0;
    for (uint32_t c = m->first_channel; c < m->first_channel + m->channel_count; c++) {
        int32_t ia, ib;
        float ca, cb;
        frame_channel_span(a, c, weights[c], &ia, &ca, &ib, &cb);
        sum += (ia >= 0 ? fabs(ca) : 0) + (ib >= 0 ? fabs(cb) : 0);
    }
    return sum;
}

typedef struct frame_result {
    double position_error, normal_error_deg, allowed;
    int meshes_compared, normals_compared;
    char failure[1024];
} frame_result;

static int find_mesh_for(const mk_asset *a, const cJSON *ref_mesh, int gltf)
{
    if (gltf) {
        const cJSON *node = cJSON_GetObjectItem(ref_mesh, "node"), *mesh = cJSON_GetObjectItem(ref_mesh, "mesh"),
                    *prim = cJSON_GetObjectItem(ref_mesh, "primitive");
        for (uint32_t i = 0; i < a->mesh_count; i++) {
            mk_mesh_info m;
            mk_mesh_get(a, i, &m);
            if (cJSON_IsNumber(node) && m.gltf_node == node->valueint && cJSON_IsNumber(mesh) && m.gltf_mesh == mesh->valueint
                && cJSON_IsNumber(prim) && m.gltf_primitive == prim->valueint)
                return (int)i;
        }
        return -1;
    }
    const cJSON *node = cJSON_GetObjectItem(ref_mesh, "node");
    return cJSON_IsString(node) ? mk_find_mesh(a, node->valuestring) : -1;
}

/* Compares one mesh; updates result. ref_pos has 3 floats per control point or vertex. */
static void compare_mesh(const mk_asset *a, uint32_t mi, const float *weights, const double *ref_pos, uint32_t ref_count,
                         const double *ref_nrm, int world, int by_control_point, double quant_error, frame_result *res)
{
    mk_mesh_info m;
    mk_mesh_get(a, mi, &m);
    uint32_t expected = by_control_point ? m.control_point_count : m.vertex_count;
    if (ref_count != expected) {
        snprintf(res->failure, sizeof res->failure, "mesh '%s': reference has %u %s, import has %u", m.name, ref_count,
                 by_control_point ? "control points" : "vertices", expected);
        return;
    }
    float *pos = malloc(12u * (size_t)m.vertex_count), *nrm = m.has_normals ? malloc(12u * (size_t)m.vertex_count) : NULL;
    mk_error err;
    if (!pos || (m.has_normals && !nrm)) { snprintf(res->failure, sizeof res->failure, "out of memory"); goto done; }
    if (frame_eval_mesh(a, mi, weights, MK_STACKING_ASSET, MK_NORMALS_NLERP, pos, nrm, &err)) {
        snprintf(res->failure, sizeof res->failure, "mesh '%.200s': evaluation failed: %.300s", m.name, err.message);
        goto done;
    }
    if (world) frame_to_world(m.world, pos, nrm, m.vertex_count);
    double scale = world ? max_column_norm(m.world) : 1.0;
    double allowed_extra = quant_error * scale * coefficient_sum(a, &m, weights), largest = 0;
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        uint32_t r = by_control_point ? m.control_points[v] : v;
        for (int d = 0; d < 3; d++) {
            double ref = ref_pos[3 * r + (uint32_t)d], e = fabs((double)pos[3 * v + (uint32_t)d] - ref);
            if (fabs(ref) > largest) largest = fabs(ref);
            if (!(e <= res->position_error)) res->position_error = e;   /* NaN propagates as failure */
        }
        if (ref_nrm && nrm) {
            const double *rn = &ref_nrm[3 * r];
            const float *n = &nrm[3 * v];
            double rl = sqrt(rn[0] * rn[0] + rn[1] * rn[1] + rn[2] * rn[2]);
            double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (rl > 1e-12) {
                double dot = (n[0] * rn[0] + n[1] * rn[1] + n[2] * rn[2]) / (rl * nl);
                dot = dot > 1 ? 1 : dot < -1 ? -1 : dot;
                double angle = acos(dot) * 180.0 / 3.14159265358979323846;
                if (!(angle <= res->normal_error_deg)) res->normal_error_deg = angle;  /* NaN fails closed */
                res->normals_compared = 1;
            }
        }
    }
    /* Results are float32: nothing can be closer to the reference than half a float32 ulp of
     * its coordinates, so that much is allowed on top of the case's tolerance. */
    allowed_extra += float32_half_ulp(largest);
    if (allowed_extra > res->allowed) res->allowed = allowed_extra;
    res->meshes_compared++;
done:
    free(pos);
    free(nrm);
}

/* A frame's forced weights, in mesh mi's channel order, replace that mesh's channel weights
 * (channels past the list keep theirs). Meshes own disjoint channel ranges, so the frame's
 * weight array can take them in place. */
static void force_mesh_weights(const mk_asset *a, uint32_t mi, const cJSON *forced, float *weights)
{
    mk_mesh_info m;
    mk_mesh_get(a, mi, &m);
    uint32_t k = 0;
    for (const cJSON *v = cJSON_IsArray(forced) ? forced->child : NULL; v && k < m.channel_count; v = v->next, k++)
        weights[m.first_channel + k] = (float)v->valuedouble;
}

static void run_frame(const loaded_asset *l, const cJSON *cs, const cJSON *frame, const char *base_dir,
                      frame_result *res)
{
    const mk_asset *a = &l->asset;
    const cJSON *reference = cJSON_GetObjectItem(cs, "reference");
    const char *kind = cJSON_GetStringValue(cJSON_GetObjectItem(reference, "kind"));
    const char *space = cJSON_GetStringValue(cJSON_GetObjectItem(reference, "space"));
    const char *match = cJSON_GetStringValue(cJSON_GetObjectItem(reference, "match"));
    const char *file = cJSON_GetStringValue(cJSON_GetObjectItem(frame, "file"));
    int world = space && !strcmp(space, "world"), by_cp = match && !strcmp(match, "control_points");
    const char *format = cJSON_GetStringValue(cJSON_GetObjectItem(cs, "format"));
    int gltf = format && !strcmp(format, "gltf");
    if (!kind || !file) { snprintf(res->failure, sizeof res->failure, "case has no reference kind or frame file"); return; }

    float *weights = calloc(a->channel_count + 1u, sizeof(float));
    if (!weights) { snprintf(res->failure, sizeof res->failure, "out of memory"); return; }
    const cJSON *time = cJSON_GetObjectItem(frame, "time"), *clip = cJSON_GetObjectItem(frame, "clip"),
                *forced = cJSON_GetObjectItem(frame, "weights");
    /* A frame with "time": null, or with forced "weights", shows the file's static state: the
     * channels' default weights (FBX DeformPercent, glTF mesh weights), no animation applied.
     * Otherwise its time is in the named "clip" (a glTF animation index); FBX frames name none
     * and use the file's first animation stack; a glTF frame that names none is static. */
    int32_t clip_index = -1;
    if (cJSON_IsNumber(time) && !forced)
        clip_index = cJSON_IsNumber(clip) ? clip->valueint : !gltf && a->clip_count ? 0 : -1;
    mk_error err;
    if (clip_index >= (int32_t)a->clip_count) {
        snprintf(res->failure, sizeof res->failure, "frame needs clip %d, import has %u clips", clip_index, a->clip_count);
        free(weights);
        return;
    }
    if (frame_weights(a, clip_index, cJSON_IsNumber(time) ? time->valuedouble : 0.0, weights, &err)) {
        snprintf(res->failure, sizeof res->failure, "sampling failed: %.300s", err.message);
        free(weights);
        return;
    }

    char path[4096];
    join_path(path, sizeof path, base_dir, file);
    if (!strcmp(kind, "obj")) {
        uint32_t count;
        double *ref = read_obj_positions(path, &count, res->failure, sizeof res->failure);
        if (!ref) { free(weights); return; }
        /* An OBJ frame holds the one deformed mesh: the asset's mesh with channels. */
        for (uint32_t i = 0; i < a->mesh_count && !res->failure[0]; i++) {
            mk_mesh_info m;
            mk_mesh_get(a, i, &m);
            if (!m.channel_count) continue;
            force_mesh_weights(a, i, forced, weights);
            compare_mesh(a, i, weights, ref, count, NULL, world, by_cp, l->report.max_position_error, res);
        }
        free(ref);
        free(weights);
        return;
    }
    cJSON *ref = read_json(path, res->failure, sizeof res->failure);
    if (!ref) { free(weights); return; }
    const cJSON *meshes = cJSON_GetObjectItem(ref, "meshes");
    for (const cJSON *rm = meshes ? meshes->child : NULL; rm && !res->failure[0]; rm = rm->next) {
        const cJSON *chans = cJSON_GetObjectItem(rm, gltf ? "weights" : "channels");
        int has_morph = cJSON_GetArraySize(chans) > 0;
        /* A reference mesh without channels is not compared: references evaluate whole scenes
         * (node animation, skinning), and such a mesh is not imported by default. */
        if (!has_morph) continue;
        int mi = find_mesh_for(a, rm, gltf);
        if (mi < 0) {
            const char *label = cJSON_GetStringValue(cJSON_GetObjectItem(rm, gltf ? "label" : "node"));
            snprintf(res->failure, sizeof res->failure, "reference mesh '%s' with morph channels is not in the import",
                     label ? label : "?");
            continue;
        }
        force_mesh_weights(a, (uint32_t)mi, forced, weights);
        uint32_t count, ncount = 0;
        double *pos = json_double_array(cJSON_GetObjectItem(rm, "positions"), &count);
        double *nrm = json_double_array(cJSON_GetObjectItem(rm, "normals"), &ncount);
        if (!pos) snprintf(res->failure, sizeof res->failure, "reference mesh has no positions");
        else compare_mesh(a, (uint32_t)mi, weights, pos, count / 3, ncount == count ? nrm : NULL, world, by_cp,
                          l->report.max_position_error, res);
        free(pos);
        free(nrm);
    }
    if (!res->failure[0] && res->meshes_compared == 0)
        snprintf(res->failure, sizeof res->failure, "no reference mesh matched the import");
    cJSON_Delete(ref);
    free(weights);
}

static int case_matches(const cJSON *cs, const char *filter)
{
    const char *name = cJSON_GetStringValue(cJSON_GetObjectItem(cs, "name"));
    const char *source = cJSON_GetStringValue(cJSON_GetObjectItem(cs, "source"));
    return !filter || (name && strstr(name, filter)) || (source && strstr(source, filter));
}

static const char *frame_label(const cJSON *frame)
{
    const char *file = cJSON_GetStringValue(cJSON_GetObjectItem(frame, "file"));
    const char *slash = file ? strrchr(file, '/') : NULL;
    return slash ? slash + 1 : file ? file : "?";
}

static void run_case(const cJSON *cs, const char *base_dir, const conform_options *opt, int name_width, int frame_width,
                     counts *total)
{
    const char *name = cJSON_GetStringValue(cJSON_GetObjectItem(cs, "name"));
    const char *source = cJSON_GetStringValue(cJSON_GetObjectItem(cs, "source"));
    const cJSON *frames = cJSON_GetObjectItem(cs, "frames");
    const cJSON *tol = cJSON_GetObjectItem(cJSON_GetObjectItem(cs, "reference"), "tolerance");
    if (!name || !source || !cJSON_IsArray(frames) || !cJSON_IsNumber(tol) || !(tol->valuedouble >= 0)) {
        printf("%-*s FAIL malformed case entry (needs name, source, reference.tolerance >= 0 and frames[])\n", name_width,
               name ? name : "?");
        total->failed++;
        return;
    }
    double tolerance = tol->valuedouble;
    char path[4096];
    join_path(path, sizeof path, base_dir, source);
    mk_write_options wo = { .precision = opt->precision };
    loaded_asset l;
    mk_error err;
    mk_result r = load_asset(path, NULL, &wo, &l, &err);
    for (const cJSON *frame = frames->child; frame; frame = frame->next) {
        const char *label = frame_label(frame);
        if (r != MK_OK) {
            printf("%-*s %-*s FAIL import: %s\n", name_width, name, frame_width, label, err.message);
            total->failed++;
            continue;
        }
        frame_result res;
        memset(&res, 0, sizeof res);
        run_frame(&l, cs, frame, base_dir, &res);
        double allowed = tolerance + res.allowed;
        int ok = !res.failure[0] && res.position_error <= allowed && res.normal_error_deg <= opt->normal_tolerance_deg;
        char normal[64];
        if (res.normals_compared) snprintf(normal, sizeof normal, "%.3g deg", res.normal_error_deg);
        else snprintf(normal, sizeof normal, "-");
        printf("%-*s %-*s pos %-9.3g (<= %-9.3g) normal %-10s %s", name_width, name, frame_width, label,
               res.position_error, allowed, normal, ok ? "ok" : "FAIL");
        if (res.failure[0]) printf(" %s", res.failure);
        printf("\n");
        if (ok) total->passed++; else total->failed++;
    }
    loaded_asset_free(&l);
}

typedef struct conform_args {
    const char *manifest, *filter;
    int precision;
    double normal_tolerance;
} conform_args;

static int run_conform(void *p);

static const cli_option options[] = {
    { "--case", "SUBSTRING", CLI_STRING, offsetof(conform_args, filter),
      "Only the cases whose name or source path contains SUBSTRING (an error when none does).", NULL, NULL, 0, 0, 0, 0 },
    { "--precision", "P", CLI_CHOICE, offsetof(conform_args, precision),
      "How sources are written before playback: q16 (the allowed error grows by the writer's reported quantization bound) "
      "or float.", "q16", "q16|float", 0, 0, 0, 0 },
    { "--normal-tolerance", "DEG", CLI_NUMBER, offsetof(conform_args, normal_tolerance),
      "Largest angle, in degrees, between a normal and the reference's (where the reference has normals).", "1", NULL, 0, 180,
      0, 0 },
};

const cli_verb cli_verb_conform = {
    "conform", "CASES.json [options]", "check playback against reference frames made by other software",
    "For each case of the manifest CASES.json: imports its source, writes it with the chosen precision, opens it with the "
    "runtime and, for every reference frame, samples the clip (or the static state, or forced weights), evaluates every "
    "mesh with channels and compares positions (and normals where the reference has them). One line per frame, then "
    "'N passed, N failed'. Exit status 1 when a frame fails.",
    "CASES.json", "The manifest; paths in it are relative to its folder.", offsetof(conform_args, manifest), 1,
    options, sizeof options / sizeof options[0], sizeof(conform_args), run_conform,
};

static int run_conform(void *p)
{
    conform_args *args = p;
    conform_options opt = { args->filter, args->precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16, args->normal_tolerance };
    char why[1024];
    cJSON *root = read_json(args->manifest, why, sizeof why);
    if (!root) { fprintf(stderr, "morphkit conform: %s\n", why); return CLI_EXIT_FAILURE; }
    const cJSON *cases = cJSON_GetObjectItem(root, "cases");
    if (!cJSON_IsObject(root) || !cJSON_IsArray(cases)) {
        fprintf(stderr, "morphkit conform: %s: not a conformance manifest (expected an object with a \"cases\" array)\n",
                args->manifest);
        cJSON_Delete(root);
        return CLI_EXIT_FAILURE;
    }
    char base_dir[4096];
    snprintf(base_dir, sizeof base_dir, "%s", args->manifest);
    char *slash = strrchr(base_dir, '/');
    if (slash) *slash = 0; else strcpy(base_dir, ".");
    int name_width = 8, frame_width = 8, matched = 0;
    for (const cJSON *cs = cases->child; cs; cs = cs->next) {
        if (!case_matches(cs, opt.filter)) continue;
        matched++;
        const char *name = cJSON_GetStringValue(cJSON_GetObjectItem(cs, "name"));
        if (name && (int)strlen(name) > name_width) name_width = (int)strlen(name);
        const cJSON *frames = cJSON_GetObjectItem(cs, "frames");
        for (const cJSON *f = cJSON_IsArray(frames) ? frames->child : NULL; f; f = f->next)
            if ((int)strlen(frame_label(f)) > frame_width) frame_width = (int)strlen(frame_label(f));
    }
    if (!matched) {
        if (opt.filter) fprintf(stderr, "morphkit conform: --case '%s' matches none of the %d cases of %s\n", opt.filter,
                                cJSON_GetArraySize(cases), args->manifest);
        else fprintf(stderr, "morphkit conform: %s has no cases\n", args->manifest);
        cJSON_Delete(root);
        return CLI_EXIT_FAILURE;
    }
    counts total = { 0, 0 };
    for (const cJSON *cs = cases->child; cs; cs = cs->next)
        if (case_matches(cs, opt.filter)) run_case(cs, base_dir, &opt, name_width, frame_width, &total);
    cJSON_Delete(root);
    printf("%d passed, %d failed\n", total.passed, total.failed);
    return total.failed || total.passed == 0 ? CLI_EXIT_FAILURE : CLI_EXIT_OK;
}

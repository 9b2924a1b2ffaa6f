/* FBX import against the shared corpus: every "fbx" case of cases.json is imported with
 * mk_import_fbx, evaluated through the runtime (float blob, mk_sample_run on clip 0 at the
 * frame time, or the default weights for a "time": null frame: the static state), moved to
 * world space with the mesh's world transform and compared per control point with the
 * reference (ufbx JSON frames and the authoring tools' OBJ exports) at the case's tolerance
 * plus float32 rounding. SKIPs when the corpus is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cjson/cJSON.h>
#include "check.h"
#include "fbx_test_util.h"

static cJSON *read_json(const char *path)
{
    size_t size;
    unsigned char *text = check_read_file(path, &size);
    if (!text) return NULL;
    cJSON *json = cJSON_ParseWithLength((const char *)text, size);
    free(text);
    return json;
}

/* OBJ `v` lines (world positions, one per FBX control point). */
static double *read_obj(const char *path, uint32_t *count)
{
    size_t size;
    unsigned char *text = check_read_file(path, &size);
    if (!text) return NULL;
    double *v = malloc((size / 4 + 3) * sizeof(double));
    uint32_t n = 0;
    char *line = (char *)text;
    char *end = (char *)text + size;
    while (v && line < end) {
        char *next = memchr(line, '\n', (size_t)(end - line));
        if (!next) next = end;
        if (next - line > 2 && line[0] == 'v' && line[1] == ' ') {
            char buffer[256];
            size_t len = (size_t)(next - line) < sizeof buffer - 1 ? (size_t)(next - line) : sizeof buffer - 1;
            memcpy(buffer, line, len);
            buffer[len] = 0;
            double x, y, z;
            if (sscanf(buffer + 2, "%lf %lf %lf", &x, &y, &z) == 3) {
                v[3 * n] = x;
                v[3 * n + 1] = y;
                v[3 * n + 2] = z;
                n++;
            }
        }
        line = next + 1;
    }
    free(text);
    *count = n;
    return v;
}

/* Results are float32: nothing can be closer to a reference coordinate than half a float32
 * ulp of it, so that much is allowed on top of the case's tolerance. */
static double float32_half_ulp(double x)
{
    int exponent;
    frexp(fabs(x), &exponent);
    return x != 0 ? ldexp(1.0, exponent - 25) : 0.0;
}

static void run_case(const char *corpus, const cJSON *c, double *worst)
{
    const char *name = cJSON_GetObjectItem(c, "name")->valuestring;
    const char *source = cJSON_GetObjectItem(c, "source")->valuestring;
    const cJSON *reference = cJSON_GetObjectItem(c, "reference");
    double tolerance = cJSON_GetObjectItem(reference, "tolerance")->valuedouble;
    const char *kind = cJSON_GetObjectItem(reference, "kind")->valuestring;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", corpus, source);
    size_t size;
    unsigned char *data = check_read_file(path, &size);
    CHECK_MSG(data != NULL, "%s: cannot read %s", name, path);
    if (!data) return;
    mk_raw_asset raw;
    mk_error err;
    mk_result r = ft_import(data, size, NULL, &raw, &err);
    free(data);
    CHECK_MSG(r == MK_OK, "%s: import failed: %s", name, err.message);
    if (r != MK_OK) { mk_raw_free(&raw); return; }
    CHECK_MSG(mk_raw_validate(&raw, &err) == MK_OK, "%s: invalid raw model: %s", name, err.message);
    const cJSON *frame;
    cJSON_ArrayForEach(frame, cJSON_GetObjectItem(c, "frames")) {
        const cJSON *time = cJSON_GetObjectItem(frame, "time");
        snprintf(path, sizeof path, "%s/%s", corpus, cJSON_GetObjectItem(frame, "file")->valuestring);
        int clip = cJSON_IsNumber(time) ? 0 : -1;
        float t = cJSON_IsNumber(time) ? (float)time->valuedouble : 0.0f;
        if (clip >= 0 && raw.clip_count == 0) {
            CHECK_MSG(0, "%s: frame at %g s but the import has no clip", name, t);
            continue;
        }
        if (strcmp(kind, "obj") == 0) {
            uint32_t n = 0;
            double *ref = read_obj(path, &n);
            CHECK_MSG(ref != NULL, "%s: cannot read %s", name, path);
            /* The OBJ frames are of the one mesh with channels. */
            int32_t mesh = -1;
            for (uint32_t m = 0; m < raw.mesh_count && mesh < 0; m++)
                for (uint32_t k = 0; k < raw.channel_count; k++)
                    if (raw.channels[k].mesh == m) { mesh = (int32_t)m; break; }
            CHECK(mesh >= 0);
            float *ours = NULL;
            uint32_t cps = 0;
            if (ref && mesh >= 0 && ft_eval_control_points(&raw, (uint32_t)mesh, clip, t, NULL, 1, &ours, &cps) == 0) {
                CHECK_EQ_INT(cps, n);
                double err_max = 0;
                for (uint32_t i = 0; i < 3 * n && cps == n; i++)
                    err_max = fmax(err_max, fabs((double)ours[i] - ref[i]) - float32_half_ulp(ref[i]));
                CHECK_MSG(err_max <= tolerance, "%s %s: max error %g > %g", name, path, err_max, tolerance);
                if (err_max > *worst) *worst = err_max;
            } else {
                CHECK_MSG(0, "%s: evaluation failed", name);
            }
            free(ours);
            free(ref);
            continue;
        }
        cJSON *json = read_json(path);
        CHECK_MSG(json != NULL, "%s: cannot read %s", name, path);
        if (!json) continue;
        const cJSON *rm;
        cJSON_ArrayForEach(rm, cJSON_GetObjectItem(json, "meshes")) {
            const char *node = cJSON_GetObjectItem(rm, "node")->valuestring;
            const cJSON *channels = cJSON_GetObjectItem(rm, "channels");
            int32_t mesh = ft_find_mesh(&raw, node);
            if (mesh < 0) {
                CHECK_MSG(cJSON_GetArraySize(channels) == 0, "%s: mesh '%s' with channels not imported", name, node);
                continue;
            }
            /* Channel names and count as ufbx reports them. */
            uint32_t ours_channels = 0;
            for (uint32_t k = 0; k < raw.channel_count; k++) ours_channels += raw.channels[k].mesh == (uint32_t)mesh;
            CHECK_MSG(ours_channels == (uint32_t)cJSON_GetArraySize(channels), "%s '%s': %u channels, reference %d", name,
                      node, ours_channels, cJSON_GetArraySize(channels));
            float *ours = NULL;
            uint32_t cps = 0;
            if (ft_eval_control_points(&raw, (uint32_t)mesh, clip, t, NULL, 1, &ours, &cps) != 0) {
                CHECK_MSG(0, "%s: evaluation failed", name);
                continue;
            }
            const cJSON *positions = cJSON_GetObjectItem(rm, "positions");
            CHECK_EQ_INT(3 * cps, cJSON_GetArraySize(positions));
            double err_max = 0;
            int i = 0;
            const cJSON *e;
            cJSON_ArrayForEach(e, positions) {
                if ((uint32_t)i < 3 * cps)
                    err_max = fmax(err_max, fabs(ours[i] - e->valuedouble) - float32_half_ulp(e->valuedouble));
                i++;
            }
            CHECK_MSG(err_max <= tolerance, "%s %s '%s': max error %g > %g", name, path, node, err_max, tolerance);
            if (err_max > *worst) *worst = err_max;
            free(ours);
        }
        cJSON_Delete(json);
    }
    mk_raw_free(&raw);
}

static void test_corpus_frames(void)
{
    const char *corpus = check_corpus_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/cases.json", corpus);
    cJSON *cases = read_json(path);
    if (!cases) SKIP("corpus not found at %s", corpus);
    double worst = 0;
    int count = 0;
    const cJSON *c;
    cJSON_ArrayForEach(c, cJSON_GetObjectItem(cases, "cases")) {
        const cJSON *format = cJSON_GetObjectItem(c, "format");
        if (!cJSON_IsString(format) || strcmp(format->valuestring, "fbx") != 0) continue;
        run_case(corpus, c, &worst);
        count++;
    }
    CHECK(count > 0);
    fprintf(stderr, "fbx corpus: %d cases, worst position error %.3g\n", count, worst);
    cJSON_Delete(cases);
}

/* Facts the frames do not show: names, in-between order, quirks. */
static void test_corpus_structure(void)
{
    const char *corpus = check_corpus_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/fbx/maya_blend_inbetween_7500_ascii.fbx", corpus);
    size_t size;
    unsigned char *data = check_read_file(path, &size);
    if (!data) SKIP("corpus not found at %s", corpus);
    mk_raw_asset raw;
    mk_error err;
    CHECK(ft_import(data, size, NULL, &raw, &err) == MK_OK);
    free(data);
    CHECK_EQ_INT(raw.mesh_count, 1);
    CHECK(raw.mesh_count && strcmp(raw.meshes[0].name, "pCube1") == 0);
    CHECK_EQ_INT(raw.channel_count, 2);
    if (raw.channel_count == 2) {
        /* In-betweens sorted by full weight, negative ones first (FullWeights in connection order). */
        const mk_raw_channel *lift = &raw.channels[0], *side = &raw.channels[1];
        CHECK(strcmp(lift->name, "KeyBlend.LiftTop") == 0);
        CHECK(strcmp(side->name, "KeyBlend.MoveToSide") == 0);
        CHECK_EQ_INT(lift->target_count, 2);
        CHECK_EQ_INT(side->target_count, 3);
        if (lift->target_count == 2) {
            CHECK_NEAR(lift->targets[0].full_weight, 0.5, 1e-6);
            CHECK_NEAR(lift->targets[1].full_weight, 1.0, 1e-6);
        }
        if (side->target_count == 3) {
            CHECK_NEAR(side->targets[0].full_weight, -0.499, 1e-6);
            CHECK_NEAR(side->targets[1].full_weight, -0.249, 1e-6);
            CHECK_NEAR(side->targets[2].full_weight, 1.0, 1e-6);
        }
    }
    CHECK_EQ_INT(raw.clip_count, 1);
    if (raw.clip_count == 1) CHECK_EQ_INT(raw.clips[0].track_count, 2);
    CHECK(strncmp(raw.source_format, "fbx 7500 ascii", 14) == 0);
    CHECK(strstr(raw.source_creator, "FBX SDK") != NULL);
    CHECK_EQ_INT(raw.up_axis, 1);
    mk_raw_free(&raw);
}

CHECK_MAIN(CASE(test_corpus_frames), CASE(test_corpus_structure))

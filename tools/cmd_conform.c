/* SPDX-License-Identifier: MIT */
/* morphkit conform: playback checked against reference frames made by other software. The
 * checking itself is playback/conform.c, shared with the corpus tests. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "conform.h"
#include "conform_report.h"
#include "gpu_eval.h"
#include "json_write.h"
#include "normal_quality.h"

typedef struct conform_args {
    const char *manifest, *filter, *report;
    int precision, stacking, stacking_given, normals, normals_given, json, normal_quality, gpu;
    double normal_tolerance, weight_tolerance;
} conform_args;

static int run_conform(void *p);

static const cli_option options[] = {
    { "--case", "SUBSTRING", CLI_STRING, offsetof(conform_args, filter),
      "Only the cases whose name or source path contains SUBSTRING (an error when none does).", NULL, NULL, 0, 0, 0,
      0 },
    { "--gpu", NULL, CLI_FLAG, offsetof(conform_args, gpu), CLI_GPU_OPTION_HELP, NULL, NULL, 0, 0, 0, 0 },
    { "--precision", "P", CLI_CHOICE, offsetof(conform_args, precision),
      "How sources are written before playback: q16 (the allowed error grows by each target's quantization step) "
      "or float.",
      "q16", "q16|float", 0, 0, 0, 0 },
    { "--stacking", "MODE", CLI_CHOICE, offsetof(conform_args, stacking),
      "Channel stacking to play with. Default: the case's \"stacking\", else each mesh's stored one.",
      NULL, "additive|sequential", 0, 0, 0, offsetof(conform_args, stacking_given) },
    { "--normals", "MODE", CLI_CHOICE, offsetof(conform_args, normals),
      "How normal changes combine. Default: the case's \"normals\" (nlerp when it names none).", NULL, "nlerp|slerp", 0,
      0, 0, offsetof(conform_args, normals_given) },
    { "--normal-tolerance", "DEG", CLI_NUMBER, offsetof(conform_args, normal_tolerance),
      "Largest angle, in degrees, between a normal and the reference's (where the reference has normals).", "1", NULL,
      1e-9, 180, 0, 0 },
    { "--weight-tolerance", "W", CLI_NUMBER, offsetof(conform_args, weight_tolerance),
      "Largest difference between a sampled channel weight and the reference's (where the reference lists weights).",
      "1e-5", NULL, 1e-12, 1e6, 0, 0 },
    { "--report", "DIR", CLI_STRING, offsetof(conform_args, report),
      "Also write DIR/index.html (created if absent): a static page with every case and frame (pass/fail, error, "
      "where) and one picture per compared frame, frame_NNNN.png: the played frame beside the reference and the "
      "error heat map, failing frames first.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--normal-quality", NULL, CLI_FLAG, offsetof(conform_args, normal_quality),
      "Also measure, per case over its frames, how far each normal mode (nlerp, slerp, surface, base normals kept) "
      "is from the normals of the evaluated surface: mean, 99th percentile and largest angle over the moved vertices "
      "(docs/semantics.md, Normal quality).",
      NULL, NULL, 0, 0, 0, 0 },
    { "--json", NULL, CLI_FLAG, offsetof(conform_args, json),
      "Print one JSON object: every frame's errors and allowances, and the counts.", NULL, NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_conform = {
    .name = "conform",
    .usage = "CASES.json [options]",
    .summary = "check playback against reference frames made by other software",
    .description =
        "For each case of the manifest CASES.json (docs/conformance.md): imports its source, writes it with the chosen "
        "precision, opens it with the runtime and, for every reference frame, plays the frame (a clip at a time, the "
        "static "
        "state, or forced weights), evaluates every mesh with channels and compares positions, normals and channel "
        "weights "
        "where the reference has them. One line per frame, then 'N passed, N failed'. Exit status 1 when a frame "
        "fails.",
    .positional = "CASES.json",
    .positional_help = "The manifest; paths in it are relative to its folder.",
    .positional_offset = offsetof(conform_args, manifest),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(conform_args),
    .run = run_conform,
};

static int case_matches(const pb_case *c, const char *filter)
{
    return !filter || strstr(c->name, filter) || strstr(c->source, filter);
}

static void print_text(const pb_case *c, const pb_frame_spec *f, const pb_frame_result *r, int name_width,
                       int frame_width)
{
    char allowed[64], normal[32];
    if (r->relative_allowed > 0 && (r->passed_by == NULL || !strcmp(r->passed_by, "relative_tolerance")))
        snprintf(allowed, sizeof allowed, "%.3g rel", r->relative_allowed);
    else
        snprintf(allowed, sizeof allowed, "%.3g", r->allowed);
    if (r->normals_compared)
        snprintf(normal, sizeof normal, "%.3g deg", r->normal_error_deg);
    else
        snprintf(normal, sizeof normal, "-");
    printf("%-*s %-*s pos %-9.3g <= %-12s normal %-10s %s", name_width, c->name, frame_width, pb_frame_label(f),
           r->position_error, allowed, normal, r->passed ? "ok" : "FAIL");
    if (r->failure[0])
        printf(" %s", r->failure);
    else if (!r->passed && r->weights_compared)
        printf(" (weight error %.3g)", r->weight_error);
    printf("\n");
}

static void json_frame(json_writer *w, const pb_case *c, const pb_frame_spec *f, const pb_frame_result *r)
{
    json_object(w, NULL);
    json_string(w, "case", c->name);
    json_string(w, "frame", f->file);
    json_bool(w, "passed", r->passed);
    if (r->passed_by) json_string(w, "passed_by", r->passed_by);
    json_number(w, "position_error", r->position_error);
    json_number(w, "allowed", r->allowed);
    if (r->relative_allowed > 0) {
        json_number(w, "relative_allowed", r->relative_allowed);
        json_number(w, "reference_size", r->reference_size);
    }
    if (r->normals_compared)
        json_number(w, "normal_error_deg", r->normal_error_deg);
    else
        json_null(w, "normal_error_deg");
    if (r->weights_compared)
        json_number(w, "weight_error", r->weight_error);
    else
        json_null(w, "weight_error");
    json_int(w, "meshes_compared", r->meshes_compared);
    if (r->failure[0]) json_string(w, "failure", r->failure);
    json_end_object(w);
}

/* One case's normal quality (--normal-quality), kept for the JSON written after the frames. */
typedef struct case_quality {
    const char *name;
    pb_normal_stats stats[PB_QUALITY_MODES];
    char failure[256];
} case_quality;

/* Every frame of case c played on a through the normal-quality measure. */
static void measure_case(const pb_case *c, const pb_asset *a, mk_stacking stacking, case_quality *out)
{
    memset(out, 0, sizeof *out);
    out->name = c->name;
    pb_normal_quality q;
    memset(&q, 0, sizeof q);
    float *weights = malloc(((size_t)a->asset.channel_count + 1) * sizeof(float));
    mk_error err;
    mk_result r = weights ? MK_OK : mk_error_oom(&err, "normal quality");
    for (uint32_t k = 0; k < c->frame_count && r == MK_OK; k++) {
        r = pb_conform_weights(c, &c->frames[k], &a->asset, weights, &err);
        if (r == MK_OK) r = pb_normal_quality_add(&q, &a->asset, &a->raw, weights, stacking, &err);
    }
    if (r != MK_OK) snprintf(out->failure, sizeof out->failure, "%.200s", err.message);
    for (int m = 0; m < PB_QUALITY_MODES && r == MK_OK; m++) out->stats[m] = pb_normal_quality_stats(&q, m);
    pb_normal_quality_free(&q);
    free(weights);
}

static void print_quality(const case_quality *q)
{
    if (q->failure[0]) {
        printf("%s: normal quality not measured: %s\n", q->name, q->failure);
        return;
    }
    if (!q->stats[0].count) {
        printf("%s: normal quality: no moved vertex with normals and triangles in its frames\n", q->name);
        return;
    }
    printf("%s: normal quality over %zu moved vertex-frames (degrees, mean / p99 / max):", q->name, q->stats[0].count);
    for (int m = 0; m < PB_QUALITY_MODES; m++)
        printf("%s %s %.4g / %.4g / %.4g", m ? "," : "", pb_quality_label(m), q->stats[m].mean, q->stats[m].p99,
               q->stats[m].max);
    printf("\n");
}

static void json_quality(json_writer *w, const case_quality *q)
{
    json_object(w, NULL);
    json_string(w, "case", q->name);
    if (q->failure[0]) {
        json_string(w, "failure", q->failure);
    } else {
        json_int(w, "measured", (long long)q->stats[0].count);
        for (int m = 0; m < PB_QUALITY_MODES; m++) {
            json_object(w, pb_quality_name(m));
            json_number(w, "mean_deg", q->stats[m].mean);
            json_number(w, "p99_deg", q->stats[m].p99);
            json_number(w, "max_deg", q->stats[m].max);
            json_end_object(w);
        }
    }
    json_end_object(w);
}

static int run_conform(void *p)
{
    conform_args *args = p;
    const cli_verb *verb = &cli_verb_conform;
    pb_manifest manifest;
    mk_error err;
    cli_report *report = NULL;
    if (args->report) {
        int status = cli_report_begin(verb, args->report, args->manifest, &report);
        if (status >= 0) return status;
    }
    if (pb_manifest_read(args->manifest, &manifest, &err) != MK_OK) {
        pb_manifest_free(&manifest);
        cli_report_free(report);
        return cli_fail(verb->name, &err);
    }
    int name_width = 8, frame_width = 8, matched = 0;
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        const pb_case *c = &manifest.cases[i];
        if (!case_matches(c, args->filter)) continue;
        matched++;
        if ((int)strlen(c->name) > name_width) name_width = (int)strlen(c->name);
        for (uint32_t k = 0; k < c->frame_count; k++)
            if ((int)strlen(pb_frame_label(&c->frames[k])) > frame_width)
                frame_width = (int)strlen(pb_frame_label(&c->frames[k]));
    }
    if (!matched) {
        if (args->filter)
            fprintf(stderr, "morphkit conform: --case '%s' matches none of the %u cases of %s\n", args->filter,
                    manifest.case_count, args->manifest);
        else
            fprintf(stderr, "morphkit conform: %s has no cases\n", args->manifest);
        pb_manifest_free(&manifest);
        cli_report_free(report);
        return CLI_EXIT_FAILURE;
    }
    pb_conform_options opt = {
        .stacking = !args->stacking_given ? MK_STACKING_ASSET
                    : args->stacking      ? MK_STACKING_SEQUENTIAL
                                          : MK_STACKING_ADDITIVE,
        .normal_mode = args->normals ? MK_NORMALS_SLERP : MK_NORMALS_NLERP,
        .normal_mode_given = args->normals_given,
        .normal_tolerance_deg = args->normal_tolerance,
        .weight_tolerance = args->weight_tolerance,
    };
    cli_gpu *gpu = NULL;
    pb_evaluator evaluator;
    if (args->gpu) {
        if (cli_gpu_open(&gpu, &evaluator, args->json, &err) != MK_OK) {
            pb_manifest_free(&manifest);
            cli_report_free(report);
            return cli_fail("conform", &err);
        }
        opt.evaluator = &evaluator;
    }
    if (report) cli_report_hook(report, &opt);
    int report_status = -1;
    mk_write_options wo = { .precision = args->precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16 };
    json_writer w;
    if (args->json) {
        json_begin(&w, stdout, 1);
        json_object(&w, NULL);
        json_string(&w, "manifest", args->manifest);
        json_string(&w, "precision", args->precision ? "float" : "q16");
        json_array(&w, "frames");
    }
    int passed = 0, failed = 0;
    case_quality *quality = NULL;
    uint32_t quality_count = 0;
    if (args->normal_quality && !(quality = calloc(manifest.case_count, sizeof *quality))) {
        fprintf(stderr, "morphkit conform: out of memory\n");
        pb_manifest_free(&manifest);
        cli_report_free(report);
        return CLI_EXIT_FAILURE;
    }
    for (uint32_t i = 0; i < manifest.case_count; i++) {
        const pb_case *c = &manifest.cases[i];
        if (!case_matches(c, args->filter)) continue;
        char path[4200];
        pb_manifest_path(&manifest, c->source, path, sizeof path);
        pb_asset asset;
        mk_result r = pb_asset_load(path, NULL, &wo, &asset, &err);
        for (uint32_t k = 0; k < c->frame_count; k++) {
            pb_frame_result res;
            if (r != MK_OK) {
                memset(&res, 0, sizeof res);
                snprintf(res.failure, sizeof res.failure, "import: %.480s", err.message);
            } else {
                pb_conform_frame(&manifest, c, &c->frames[k], &asset, &opt, &res);
            }
            if (report && report_status < 0)
                report_status = cli_report_frame(report, c, &c->frames[k], &res, r == MK_OK ? &asset.asset : NULL);
            if (args->json)
                json_frame(&w, c, &c->frames[k], &res);
            else
                print_text(c, &c->frames[k], &res, name_width, frame_width);
            if (res.passed)
                passed++;
            else
                failed++;
        }
        if (quality && r == MK_OK) {
            case_quality *q = &quality[quality_count++];
            measure_case(c, &asset, opt.stacking, q);
            if (!args->json) print_quality(q);
        }
        pb_asset_free(&asset);
    }
    if (cli_gpu_close(gpu)) failed++;   /* validation messages (MORPHKIT_VK_VALIDATION=1) fail the run */
    if (args->json) {
        json_end_array(&w);
        if (quality) {
            json_array(&w, "normal_quality");
            for (uint32_t k = 0; k < quality_count; k++) json_quality(&w, &quality[k]);
            json_end_array(&w);
        }
        json_int(&w, "passed", passed);
        json_int(&w, "failed", failed);
        json_end_object(&w);
        printf("\n");
    } else {
        printf("%d passed, %d failed\n", passed, failed);
    }
    free(quality);
    pb_manifest_free(&manifest);
    if (report && report_status >= 0) {
        cli_report_free(report);
        return report_status;
    }
    if (report) {
        int status = cli_report_finish(report);
        if (status) return status;
        fprintf(args->json ? stderr : stdout, "report: %s/index.html\n", args->report);
    }
    return failed || passed == 0 ? CLI_EXIT_FAILURE : CLI_EXIT_OK;
}

/* SPDX-License-Identifier: MIT */
/* From a shell simulation to a channel: run it, pick the frames that become targets (chosen
 * frames or the first frames reaching chosen volume ratios), and play the recorded trajectory
 * as an mk_deformer whose amplitude a is time: a = frame / last chosen frame, linearly
 * interpolated between recorded frames. A clip playing the weight linearly over the simulated
 * duration therefore plays the frames at their simulated times. */
#include <math.h>
#include <string.h>
#include "shell_channel.h"

typedef struct progress_adapter {
    void (*progress)(void *, const char *, double);
    void *user;
    const char *stage;
} progress_adapter;

static void report_progress(void *user, double fraction)
{
    const progress_adapter *a = user;
    a->progress(a->user, a->stage, fraction);
}

static mk_result pick_frames(shell_bake *b, const shell_params *p, const double *at, uint32_t at_count, int at_ratios,
                             mk_error *err)
{
    const shell_run *run = &b->run;
    uint32_t frame[SHELL_MAX_KEYS];
    uint32_t count = 0;
    if (at_count == 0) {
        /* Default: up to 10 evenly spaced frames of the simulated run. */
        count = run->frames < 10 ? run->frames : 10;
        for (uint32_t k = 0; k < count; k++)
            frame[k] = (uint32_t)(((uint64_t)(k + 1) * run->frames + count / 2) / count);
    } else {
        for (uint32_t k = 0; k < at_count; k++) {
            if (at_ratios) {
                uint32_t f = 1;
                while (f <= run->frames && !(run->stats[f].volume_ratio <= at[k])) f++;
                if (f > run->frames)
                    return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                        "at_volume_ratios[%u]: V/V0 = %g was not reached (V/V0 = %.6g after %u frames%s)", k,
                                        at[k], run->stats[run->frames].volume_ratio, run->frames,
                                        run->stopped_by_epsilon ? ", stopped by epsilon" : ": raise frames or pressure");
                if (count && f <= frame[count - 1])
                    return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                        "at_volume_ratios[%u]: V/V0 = %g is reached at frame %u, as the previous ratio "
                                        "(use a smaller dt or ratios farther apart)", k, at[k], f);
                frame[count++] = f;
            } else {
                uint32_t f = (uint32_t)at[k];
                if (f > run->frames)
                    return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                        "at_frames[%u]: frame %u was not simulated (the run stopped at frame %u: V/V0 = %.6g < epsilon %g)",
                                        k, f, run->frames, run->stats[run->frames].volume_ratio, p->epsilon);
                frame[count++] = f;
            }
        }
    }
    if (count == 0)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "frames: no frame was simulated");
    b->last = frame[count - 1];
    b->keys = count;
    for (uint32_t k = 0; k < count; k++) {
        b->frames[k] = frame[k];
        b->weights[k] = (double)frame[k] / b->last;
    }
    return MK_OK;
}

mk_result shell_bake_prepare(const mk_raw_mesh *mesh, const shell_params *params, const unsigned char *region,
                             const double *at, uint32_t at_count, int at_ratios, mk_arena *arena,
                             void (*progress)(void *, const char *, double), void *user, const char *stage,
                             shell_bake *b, mk_error *err)
{
    memset(b, 0, sizeof *b);
    b->render = mesh;
    shell_params p = *params;
    mk_result r = shell_mesh_build(mesh, p.density, arena, &b->mesh, err);
    if (r != MK_OK) return r;
    if (region) {
        unsigned char *welded = mk_arena_array(arena, b->mesh.n, 1);
        if (!welded) return mk_error_oom(err, "shell region");
        for (uint32_t v = 0; v < mesh->vertex_count; v++)
            if (region[v]) welded[b->mesh.weld[v]] = 1;
        p.aniso_region = welded;
    }
    progress_adapter pa = { progress, user, stage };
    r = shell_simulate(&b->mesh, &p, arena, progress ? report_progress : NULL, &pa, &b->run, err);
    if (r != MK_OK) return r;
    return pick_frames(b, &p, at, at_count, at_ratios, err);
}

mk_result shell_bake_eval(void *user, double amplitude, double *positions, double *normals, double *tangents,
                          uint32_t *inverted, mk_error *err)
{
    (void)normals; (void)tangents; (void)err;
    const shell_bake *b = user;
    const mk_raw_mesh *mesh = b->render;
    double t = amplitude * b->last;
    double i0 = floor(t), frac = t - i0;
    if (frac < 1e-6) frac = 0;
    if (frac > 1 - 1e-6) { i0 += 1; frac = 0; }
    if (i0 >= b->last) { i0 = b->last; frac = 0; }
    if (i0 < 0) { i0 = 0; frac = 0; }
    size_t n3 = 3 * (size_t)b->mesh.n, f = (size_t)i0;
    const float *a = b->run.positions + n3 * f, *c = frac > 0 ? a + n3 : a;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        size_t w = 3 * (size_t)b->mesh.weld[v];
        for (int k = 0; k < 3; k++) {
            size_t i = 3 * (size_t)v + (size_t)k;
            positions[i] = f == 0 && frac == 0 ? (double)mesh->positions[i]
                                               : (1 - frac) * (double)a[w + (size_t)k] + frac * (double)c[w + (size_t)k];
        }
    }
    if (inverted) *inverted = 0;
    return MK_OK;
}

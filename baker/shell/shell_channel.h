/* SPDX-License-Identifier: MIT */
/* A shell simulation recorded as a channel (shell_channel.c). Internal to baker/. */
#ifndef SHELL_CHANNEL_H
#define SHELL_CHANNEL_H

#include "shell.h"

#define SHELL_MAX_KEYS 256

typedef struct shell_bake {
    const mk_raw_mesh *render;
    shell_mesh mesh;
    shell_run run;
    uint32_t last;                     /* the last chosen frame: weight 1 */
    uint32_t keys;                     /* chosen frames */
    uint32_t frames[SHELL_MAX_KEYS];
    double weights[SHELL_MAX_KEYS];    /* frame / last */
} shell_bake;

/* Builds the shell of mesh, runs the simulation and picks the frames that become targets:
 * at_count values of at (frames, increasing; or volume ratios, decreasing, when at_ratios), or
 * with at_count 0 up to 10 evenly spaced frames of the run. region: per render vertex flag of
 * the anisotropic region, or NULL. progress(user, stage, fraction) may be NULL. */
mk_result shell_bake_prepare(const mk_raw_mesh *mesh, const shell_params *params, const unsigned char *region,
                             const double *at, uint32_t at_count, int at_ratios, mk_arena *arena,
                             void (*progress)(void *, const char *, double), void *user, const char *stage,
                             shell_bake *b, mk_error *err);

/* mk_deformer eval over the recorded run (user = shell_bake *). */
mk_result shell_bake_eval(void *user, double amplitude, double *positions, double *normals, double *tangents,
                          uint32_t *inverted, mk_error *err);

#endif

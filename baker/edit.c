/* SPDX-License-Identifier: MIT */
/* Surface editing's entry for a bake: the constrained targets at an amplitude, then the
 * method's solve (Laplacian or ARAP), copied back to the render vertices. */
#include "surface_edit_internal.h"

mk_result mk_surface_edit_eval(void *edit, double amplitude, double *positions, double *normals,
                               double *tangents, uint32_t *inverted, mk_error *err)
{
    (void)normals; (void)tangents;
    mk_surface_edit *s = edit;
    edit_targets(s, amplitude);
    mk_result r;
    if (s->params.method == MK_EDIT_ARAP) {
        /* Initial guess: the Laplacian-like solve with R_i = I (handled inside). */
        r = edit_arap_solve(s, err);
    } else {
        r = edit_laplacian_solve(s, err);
    }
    if (r != MK_OK) return r;
    for (uint32_t v = 0; v < s->mesh->vertex_count; v++)
        for (int c = 0; c < 3; c++)
            positions[3 * (size_t)v + c] = s->solution[3 * (size_t)s->weld[v] + c];
    if (inverted) *inverted = 0;
    return MK_OK;
}


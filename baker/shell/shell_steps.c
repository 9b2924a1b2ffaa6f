/* SPDX-License-Identifier: MIT */
/* How many substeps a frame of the shell simulation needs (shell.h, docs/baking.md "shell").
 *
 * A Gauss-Seidel sweep moves a correction about one element further, so a fixed number of sweeps
 * per frame resolves the in-plane (membrane) stress only while the stress wave crosses fewer
 * elements than that in a step. That number grows as 1/h with the edge length h: with 5 sweeps
 * a 20 000-triangle sphere was effectively several times softer than a 1 280-triangle one, and
 * collapsed whatever its bending stiffness. The measure is the triangle's natural frequency
 * omega_t, with omega_t^2 = k A sum_i w_i |grad N_i|^2 (an upper bound of the largest eigenvalue of
 * M^-1 K for the triangle: A its rest area, N_i its linear shape functions, w_i the inverse masses,
 * k = 2 (mu + lambda), the membrane's largest plane-stress modulus, plus mu_a in the anisotropic
 * region). omega dt is the wave's crossing count per step up to a constant. The slowest
 * (smoothest) error of a sweep shrinks by about 1 / (1 + (omega h)^2) with the substep h, so
 * `iterations` sweeps per substep resolve it when omega h <= sqrt(iterations).
 *
 * omega is the area-weighted mean over the triangles, not the maximum: a few slivers (a UV
 * sphere's poles) have stiff modes of their own, but those are local, and a sweep resolves local
 * modes at once. Bending is not counted for the same reason: its frequency grows as 1/h^2, but
 * only for short (element-scale) waves; the long waves that decide buckling are soft. */
#include <math.h>
#include "shell.h"

double shell_membrane_frequency(const shell_mesh *m, const shell_params *p)
{
    double sum = 0, area = 0;
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *tri = m->tris + 3 * (size_t)t;
        const double *inv = m->Dm_inv + 4 * (size_t)t;
        /* grad N_1, grad N_2 are the rows of Dm^-1; grad N_0 = -(grad N_1 + grad N_2). */
        double g0x = -(inv[0] + inv[2]), g0y = -(inv[1] + inv[3]);
        double s = m->inv_mass[tri[0]] * (g0x * g0x + g0y * g0y) + m->inv_mass[tri[1]] * (inv[0] * inv[0] + inv[1] * inv[1]) +
                   m->inv_mass[tri[2]] * (inv[2] * inv[2] + inv[3] * inv[3]);
        double k = 2 * (p->mu + p->lambda);
        if (p->aniso_region && p->aniso_region[tri[0]] && p->aniso_region[tri[1]] && p->aniso_region[tri[2]]) k += p->aniso_mu;
        sum += m->area[t] * sqrt(k * m->area[t] * s);
        area += m->area[t];
    }
    return area > 0 ? sum / area : 0;
}

uint32_t shell_substeps(const shell_mesh *m, const shell_params *p)
{
    if (p->substeps) return p->substeps;
    double n = ceil(p->dt * shell_membrane_frequency(m, p) / sqrt((double)(p->iterations ? p->iterations : 1)));
    return n < 1 ? 1 : n > SHELL_MAX_SUBSTEPS ? SHELL_MAX_SUBSTEPS : (uint32_t)n;
}

/* SPDX-License-Identifier: MIT */
/* Laplacian surface editing: keep the differential coordinates in the least-squares sense
 * while constrained vertices go where the handles put them.
 *
 * Paper: O. Sorkine, D. Cohen-Or, Y. Lipman, M. Alexa, C. Roessl, H.-P. Seidel, "Laplacian
 * Surface Editing", SGP 2004 (delta = L x0).
 *
 * Energy |L x - L x0|^2 in displacement form: with hard constraints the known vertices are
 * eliminated and (L_u^T L_u) dx_u = -L_u^T L_k dx_k; with soft constraints
 * (L^T L + w^2 S) dx = w^2 S (c - x0). Zero handle motion gives exactly zero displacement.
 * Details are not rotated with the handles (Sorkine 2004 without the implicit transforms); use
 * ARAP (arap.c) for large rotations. The operator, weights and factorization: surface_edit.c.
 */
#include <string.h>
#include "surface_edit_internal.h"

/* Laplacian editing at amplitude a into s->solution (welded). */
mk_result edit_laplacian_solve(mk_surface_edit *s, mk_error *err)
{
    uint32_t n = s->welded, nu = s->unknown_count;
    double *dx = s->work;  /* displacement of constrained vertices, 0 elsewhere */
    for (uint32_t v = 0; v < n; v++)
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * (size_t)v + (size_t)c;
            dx[i] = s->constraint[v] >= 0 ? s->target[i] - s->rest[i] : 0;
        }
    if (nu == 0) {
        for (size_t i = 0; i < 3 * (size_t)n; i++) s->solution[i] = s->rest[i] + dx[i];
        return MK_OK;
    }
    double *b = s->spd.rhs->x;
    memset(b, 0, 3 * (size_t)nu * sizeof(double));
    if (s->params.soft) {
        double w2 = s->params.soft_weight * s->params.soft_weight;
        for (uint32_t v = 0; v < n; v++)
            if (s->constraint[v] >= 0)
                for (int c = 0; c < 3; c++) b[(size_t)c * nu + s->unknown[v]] = w2 * dx[3 * (size_t)v + c];
    } else {
        /* rhs_u = -(L^T (L dx_k))_u, row by row: y_r = l_r . dx, then rhs += -y_r l_r. */
        uint32_t cols[1024];
        double vals[1024];
        for (uint32_t v = 0; v < n; v++) {
            uint32_t deg = s->offsets[v + 1] - s->offsets[v];
            if (deg + 1 > 1024) return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "vertex valence above 1023");
            uint32_t m = edit_laplacian_row(s, v, cols, vals);
            double y[3] = { 0, 0, 0 };
            int any = 0;
            for (uint32_t a = 0; a < m; a++)
                if (s->constraint[cols[a]] >= 0) {
                    any = 1;
                    for (int c = 0; c < 3; c++) y[c] += vals[a] * dx[3 * (size_t)cols[a] + c];
                }
            if (!any) continue;
            for (uint32_t a = 0; a < m; a++) {
                uint32_t u = s->unknown[cols[a]];
                if (u == UINT32_MAX) continue;
                for (int c = 0; c < 3; c++) b[(size_t)c * nu + u] -= vals[a] * y[c];
            }
        }
    }
    return edit_solve_positions(s, dx, s->rest, err);
}


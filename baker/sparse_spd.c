/* SPDX-License-Identifier: MIT */
/* One CHOLMOD factorization reused for every solve (sparse_spd.h). */
#include <string.h>
#include "sparse_spd.h"
#include "bake_util.h"

void bake_spd_start(bake_spd *s, int simplicial, int few_solves)
{
    memset(s, 0, sizeof *s);
    cholmod_start(&s->cm);
    s->started = 1;
    s->cm.print = 0;
    if (simplicial) s->cm.supernodal = CHOLMOD_SIMPLICIAL;
    if (few_solves) {
        s->cm.nmethods = 1;
        s->cm.method[0].ordering = CHOLMOD_AMD;
    }
}

/* Numeric factorization of A with the analysis in s->factor, and the checks of a usable factor. */
static mk_result factor_numbers(bake_spd *s, cholmod_sparse *A, mk_error *err)
{
    double t0 = bake_now();
    int ok = cholmod_factorize(A, s->factor, &s->cm);
    s->factor_seconds += bake_now() - t0;
    s->factorizations++;
    if (!ok || s->cm.status != CHOLMOD_OK)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "CHOLMOD could not factor the system (status %d): the matrix is not "
                            "positive definite", s->cm.status);
    double rc = cholmod_rcond(s->factor, &s->cm);
    if (!(rc > 1e-15))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "the system is numerically singular (rcond %g): degenerate triangles?", rc);
    s->factor_nonzeros = s->cm.lnz;
    return MK_OK;
}

mk_result bake_spd_factor_matrix(bake_spd *s, cholmod_sparse *A, uint32_t columns, mk_error *err)
{
    double t0 = bake_now();
    s->factor = cholmod_analyze(A, &s->cm);
    s->factor_seconds += bake_now() - t0;
    if (!s->factor)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "CHOLMOD could not factor the system (status %d): the matrix is not "
                            "positive definite", s->cm.status);
    mk_result r = factor_numbers(s, A, err);
    if (r != MK_OK) return r;
    s->rhs = cholmod_zeros(A->nrow, columns, CHOLMOD_REAL, &s->cm);
    if (!s->rhs) return mk_error_oom(err, "right-hand sides");
    return MK_OK;
}

mk_result bake_spd_refactor(bake_spd *s, cholmod_sparse *A, mk_error *err)
{
    return factor_numbers(s, A, err);
}

mk_result bake_spd_factor(bake_spd *s, cholmod_triplet **T, uint32_t columns, mk_error *err)
{
    cholmod_sparse *A = cholmod_triplet_to_sparse(*T, 0, &s->cm);
    cholmod_free_triplet(T, &s->cm);
    if (!A) return mk_error_oom(err, "system matrix");
    mk_result r = bake_spd_factor_matrix(s, A, columns, err);
    cholmod_free_sparse(&A, &s->cm);
    return r;
}

mk_result bake_spd_solve(bake_spd *s, mk_error *err)
{
    double t0 = bake_now();
    if (!cholmod_solve2(CHOLMOD_A, s->factor, s->rhs, NULL, &s->x, NULL, &s->y, &s->e, &s->cm))
        return mk_error_set(err, MK_ERROR_OUT_OF_MEMORY, UINT64_MAX, "CHOLMOD solve failed (status %d)", s->cm.status);
    s->solves++;
    s->solve_seconds += bake_now() - t0;
    return MK_OK;
}

void bake_spd_finish(bake_spd *s)
{
    if (!s->started) return;
    if (s->factor) cholmod_free_factor(&s->factor, &s->cm);
    if (s->rhs) cholmod_free_dense(&s->rhs, &s->cm);
    if (s->x) cholmod_free_dense(&s->x, &s->cm);
    if (s->y) cholmod_free_dense(&s->y, &s->cm);
    if (s->e) cholmod_free_dense(&s->e, &s->cm);
    cholmod_finish(&s->cm);
    s->started = 0;
}

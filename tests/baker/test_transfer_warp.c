/* SPDX-License-Identifier: MIT */
/* Deformation transfer between different characters, against a known truth: a template head
 * (offline/head.h) tessellated as a UV sphere carries six expressions; the target is the same
 * surface under a smooth non-rigid warp W (wider brow, curved midline, deeper mid-face),
 * tessellated as an icosphere turned about y. The expression k carried onto the target should be
 * W(x + d_k(x)) at the target vertex W(x) (to first order, for a smooth W). Printed per case:
 * the correspondence error (each target triangle's matched source point against the point the
 * triangle came from, x diagonal), the fit's residual and, per key, the RMS distance to the truth
 * over the RMS of the true displacement (0: exact, 1: as far as the head at rest). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "head.h"
#include "primitives.h"
#include "fixtures.h"
#include "transfer.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

typedef struct warp_case {
    double corr_mean, corr_max;        /* correspondence error, x diagonal */
    double face_mean;                  /* the same over the face (target triangles facing +z) */
    uint32_t face_count;
    double rel[MK_HEAD_EXPRESSIONS];   /* per key: RMS error / RMS true displacement */
    double median, worst;
    mk_transfer_stats stats;
} warp_case;

static int run_case(double warp, mk_transfer_correspondence mode, uint32_t markers, warp_case *out)
{
    mk_raw_asset src, dst;
    mk_raw_init(&src, NULL);
    mk_raw_init(&dst, NULL);
    double *sdir = NULL, *tdir = NULL;
    mk_raw_mesh *sm = mk_raw_add_head(&src, "template", 48, 1, 0, 0, 1, &sdir);
    mk_raw_mesh *tm = mk_raw_add_head(&dst, "character", 4, 0, 0.3, warp, 0, &tdir);
    int ok = sm && tm;
    CHECK(ok);
    uint32_t pairs[12][2];
    if (ok) mk_head_marker_pairs(sm, sdir, tm, tdir, warp, markers, pairs);
    mk_transfer_params p = { .source = sm, .target = tm, .marker_count = markers, .markers = (const uint32_t (*)[2])pairs,
                             .correspondence = mode };
    mk_transfer *x = NULL;
    mk_error err;
    if (ok && mk_transfer_create(&p, NULL, &x, &err) != MK_OK) {
        CHECK_MSG(0, "create: %s", err.message);
        ok = 0;
    }
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (uint32_t v = 0; ok && v < sm->vertex_count; v++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], sm->positions[3 * v + c]);
            hi[c] = fmax(hi[c], sm->positions[3 * v + c]);
        }
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    memset(out, 0, sizeof *out);
    /* correspondence: the matched source point against the surface point the triangle came from */
    uint32_t counted = 0;
    for (uint32_t t = 0; ok && t < tm->triangle_count; t++) {
        double b[3], dt[3] = { 0, 0, 0 }, ds[3] = { 0, 0, 0 }, truth[3], at[3];
        uint32_t s = mk_transfer_match(x, t, b);
        if (s == UINT32_MAX) continue;
        /* both points taken to the smooth surface by their directions, so the tessellations'
         * chords do not count */
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) {
                dt[c] += tdir[3 * (size_t)tm->triangles[3 * t + k] + c];
                ds[c] += b[k] * sdir[3 * (size_t)sm->triangles[3 * s + k] + c];
            }
        mk_head_surface(dt, truth);
        mk_head_surface(ds, at);
        double d = sqrt((truth[0] - at[0]) * (truth[0] - at[0]) + (truth[1] - at[1]) * (truth[1] - at[1]) +
                        (truth[2] - at[2]) * (truth[2] - at[2])) / diag;
        out->corr_mean += d;
        out->corr_max = fmax(out->corr_max, d);
        counted++;
        if (dt[2] > 0.3 * sqrt(dt[0] * dt[0] + dt[1] * dt[1] + dt[2] * dt[2])) { out->face_mean += d; out->face_count++; }
    }
    out->corr_mean /= counted ? counted : 1;
    out->face_mean /= out->face_count ? out->face_count : 1;
    /* every expression at full weight against W(x + d_k(x)) */
    double *spos = malloc(3 * (size_t)sm->vertex_count * sizeof(double));
    double *tpos = malloc(3 * (size_t)tm->vertex_count * sizeof(double));
    ok = ok && spos && tpos;
    for (uint32_t k = 0; ok && k < MK_HEAD_EXPRESSIONS; k++) {
        const mk_raw_channel *ch = &src.channels[k];
        const mk_raw_target *tg = &ch->targets[ch->target_count - 1];
        for (size_t i = 0; i < 3 * (size_t)sm->vertex_count; i++) spos[i] = sm->positions[i];
        for (uint32_t i = 0; i < tg->count; i++)
            for (int c = 0; c < 3; c++) spos[3 * (size_t)tg->indices[i] + c] += tg->positions[3 * (size_t)i + c];
        if (mk_transfer_apply(x, spos, tpos, &err) != MK_OK) { CHECK_MSG(0, "apply: %s", err.message); ok = 0; break; }
        double e2 = 0, d2 = 0;
        for (uint32_t v = 0; v < tm->vertex_count; v++) {
            double surf[3], moved[3], truth[3];
            mk_head_surface(tdir + 3 * (size_t)v, surf);
            mk_head_expression(k, 1, surf, moved);
            mk_head_warp(warp, moved, truth);
            for (int c = 0; c < 3; c++) {
                double e = tpos[3 * (size_t)v + c] - truth[c], d = truth[c] - tm->positions[3 * (size_t)v + c];
                e2 += e * e;
                d2 += d * d;
            }
        }
        out->rel[k] = sqrt(e2 / d2);
    }
    if (ok) {
        double sorted[MK_HEAD_EXPRESSIONS];
        memcpy(sorted, out->rel, sizeof sorted);
        qsort(sorted, MK_HEAD_EXPRESSIONS, sizeof(double), cmp_double);
        out->median = 0.5 * (sorted[MK_HEAD_EXPRESSIONS / 2 - 1] + sorted[MK_HEAD_EXPRESSIONS / 2]);
        out->worst = sorted[MK_HEAD_EXPRESSIONS - 1];
        mk_transfer_stats_get(x, &out->stats);
    }
    free(spos);
    free(tpos);
    free(sdir);
    free(tdir);
    mk_transfer_destroy(x);
    mk_raw_free(&src);
    mk_raw_free(&dst);
    return ok;
}

static void print_case(const char *label, const warp_case *c)
{
    printf("%-34s correspondence %.4f mean %.4f max (face %.4f); keys median %.3f worst %.3f (", label, c->corr_mean, c->corr_max, c->face_mean,
           c->median, c->worst);
    for (int k = 0; k < MK_HEAD_EXPRESSIONS; k++) printf("%s%.3f", k ? " " : "", c->rel[k]);
    printf(")");
    if (c->stats.iterative)
        printf("; fit %.4f mean %.4f max, markers %.2g, %u solves %.2f s", c->stats.fit_mean, c->stats.fit_max,
               c->stats.marker_distance, c->stats.register_solves, c->stats.register_seconds);
    printf("\n");
}

/* The full warp: the one-pass match against the iterative correspondence. */
static void iterative_correspondence_follows_a_warped_remeshed_head(void)
{
    warp_case closest, iterative;
    if (!run_case(1, MK_TRANSFER_CLOSEST, 12, &closest) || !run_case(1, MK_TRANSFER_ITERATIVE, 12, &iterative)) return;
    print_case("full warp, closest (one pass):", &closest);
    print_case("full warp, iterative:", &iterative);
    /* The correspondence error falls, though not tenfold: between the markers the fit's tangential
     * placement comes from its smoothness, not from W (docs/baking.md has the figures). */
    CHECK_MSG(closest.corr_mean >= 1.4 * iterative.corr_mean && closest.face_mean >= 1.6 * iterative.face_mean,
              "correspondence error %.4f -> %.4f (face %.4f -> %.4f)", closest.corr_mean, iterative.corr_mean,
              closest.face_mean, iterative.face_mean);
    CHECK_MSG(iterative.median <= 0.2 && iterative.worst <= 0.5, "keys: median %.3f, worst %.3f", iterative.median,
              iterative.worst);
    CHECK_MSG(iterative.worst < closest.worst, "worst key %.3f, one pass %.3f", iterative.worst, closest.worst);
    CHECK_MSG(iterative.stats.marker_distance <= 1e-6, "markers %.3g x diagonal apart", iterative.stats.marker_distance);
    CHECK(iterative.stats.pairs > closest.stats.pairs);  /* matched both ways */
}

/* A third of the warp, and none (the same surface, another tessellation). */
static void smaller_warps_transfer_closer(void)
{
    warp_case third, none, none_auto;
    if (!run_case(1.0 / 3, MK_TRANSFER_ITERATIVE, 12, &third) || !run_case(0, MK_TRANSFER_ITERATIVE, 12, &none) ||
        !run_case(0, MK_TRANSFER_AUTO, 12, &none_auto)) return;
    print_case("a third of the warp, iterative:", &third);
    print_case("no warp, iterative:", &none);
    print_case("no warp, auto:", &none_auto);
    warp_case nc;
    if (run_case(0, MK_TRANSFER_CLOSEST, 12, &nc)) print_case("no warp, closest:", &nc);
    if (run_case(0, MK_TRANSFER_ITERATIVE, 0, &nc)) {
        print_case("no warp, iterative, no markers:", &nc);
        /* the schedule's four weights; the first solve (w_C = 0) only with markers */
        CHECK_EQ_INT(nc.stats.register_solves, 4);
        CHECK_EQ_INT(third.stats.register_solves, 5);
    }
    CHECK_MSG(third.median <= 0.08, "a third of the warp: median %.3f", third.median);
    CHECK_MSG(none.median <= 0.05, "no warp: median %.3f", none.median);
    CHECK(none_auto.stats.iterative);  /* other tessellations do not coincide */
}

/* A copy of mesh m of `from` into `to` with `extra_vertices` more vertices (positions given) and
 * `extra_triangles` more triangles (given); NULL when memory runs out. */
static mk_raw_mesh *copy_with(mk_raw_asset *to, const mk_raw_mesh *m, uint32_t extra_vertices, const float *positions,
                              uint32_t extra_triangles, const uint32_t *triangles)
{
    const mk_raw_mesh from = *m;  /* m may live in to's mesh array, which adding a mesh moves */
    m = &from;
    mk_raw_mesh *c = mk_raw_add_meshes(to, 1);
    if (!c) return NULL;
    c->name = "copy";
    c->vertex_count = m->vertex_count + extra_vertices;
    c->triangle_count = m->triangle_count + extra_triangles;
    c->positions = mk_arena_array(&to->arena, 3 * (size_t)c->vertex_count, sizeof(float));
    c->triangles = mk_arena_array(&to->arena, 3 * (size_t)c->triangle_count, sizeof(uint32_t));
    if (!c->positions || !c->triangles) return NULL;
    memcpy(c->positions, m->positions, 3 * (size_t)m->vertex_count * sizeof(float));
    if (extra_vertices) memcpy(c->positions + 3 * (size_t)m->vertex_count, positions, 3 * (size_t)extra_vertices * sizeof(float));
    memcpy(c->triangles, m->triangles, 3 * (size_t)m->triangle_count * sizeof(uint32_t));
    memcpy(c->triangles + 3 * (size_t)m->triangle_count, triangles, 3 * (size_t)extra_triangles * sizeof(uint32_t));
    return c;
}

/* Transfers the source at rest onto the target: the target's rest shape must come back. Returns
 * the largest distance (x diagonal 3, about the heads'), or -1 when the transfer failed. */
static double rest_back(const mk_raw_mesh *sm, const mk_raw_mesh *tm, uint32_t markers, const uint32_t (*pairs)[2],
                        mk_transfer_correspondence mode, mk_transfer_stats *stats)
{
    mk_transfer_params p = { .source = sm, .target = tm, .marker_count = markers, .markers = pairs, .correspondence = mode };
    mk_transfer *x = NULL;
    mk_error err;
    if (mk_transfer_create(&p, NULL, &x, &err) != MK_OK) {
        printf("  create: %s\n", err.message);
        return -1;
    }
    double *spos = malloc(3 * (size_t)sm->vertex_count * sizeof(double)), *tpos = malloc(3 * (size_t)tm->vertex_count * sizeof(double));
    double worst = -1;
    for (size_t i = 0; spos && i < 3 * (size_t)sm->vertex_count; i++) spos[i] = sm->positions[i];
    if (spos && tpos && mk_transfer_apply(x, spos, tpos, &err) == MK_OK) {
        worst = 0;
        for (size_t i = 0; i < 3 * (size_t)tm->vertex_count; i++) worst = fmax(worst, fabs(tpos[i] - tm->positions[i]) / 3);
    }
    mk_transfer_stats_get(x, stats);
    free(spos);
    free(tpos);
    mk_transfer_destroy(x);
    return worst;
}

/* Sources as real files have them: a second component without markers (an eye), a vertex in no
 * triangle, triangles without an area (collinear corners, which the fit could give an area and
 * so a zero gradient), a position that is not finite; and a target copy with one degenerate
 * triangle, which must still count as coinciding. */
static void iterative_correspondence_takes_odd_sources(void)
{
    mk_raw_asset src, dst, eye;
    mk_raw_init(&src, NULL);
    mk_raw_init(&dst, NULL);
    mk_raw_init(&eye, NULL);
    double *sdir = NULL, *tdir = NULL;
    mk_raw_mesh *head = mk_raw_add_head(&src, "template", 24, 1, 0, 0, 0, &sdir);
    mk_raw_mesh *tm = mk_raw_add_head(&dst, "character", 3, 0, 0.3, 1, 0, &tdir);
    mk_raw_mesh *ball = mk_raw_add_icosphere(&eye, "eye", 0.1f, 1);
    CHECK(head && tm && ball);
    if (!head || !tm || !ball) goto done;
    uint32_t pairs[12][2];
    mk_head_marker_pairs(head, sdir, tm, tdir, 1, 12, pairs);
    uint32_t nh = head->vertex_count;
    /* the eye (a second component), a loose vertex, a midpoint making a triangle without area */
    uint32_t ne = ball->vertex_count, extra_v = ne + 2, extra_t = ball->triangle_count + 2;
    float *ev = malloc(3 * (size_t)extra_v * sizeof(float));
    uint32_t *et = malloc(3 * (size_t)extra_t * sizeof(uint32_t));
    if (!ev || !et) { free(ev); free(et); goto done; }
    for (uint32_t v = 0; v < ne; v++) {
        ev[3 * v] = ball->positions[3 * v] + 0.3f;
        ev[3 * v + 1] = ball->positions[3 * v + 1] + 0.15f;
        ev[3 * v + 2] = ball->positions[3 * v + 2] + 0.6f;
    }
    const uint32_t *t0 = head->triangles;  /* the midpoint of the first triangle's first edge */
    for (int c = 0; c < 3; c++) {
        ev[3 * ne + c] = 5;  /* loose */
        ev[3 * (ne + 1) + c] = 0.5f * (head->positions[3 * t0[0] + c] + head->positions[3 * t0[1] + c]);
    }
    for (uint32_t i = 0; i < 3 * ball->triangle_count; i++) et[i] = ball->triangles[i] + nh;
    uint32_t *flat = et + 3 * ball->triangle_count;
    flat[0] = t0[0]; flat[1] = nh + ne + 1; flat[2] = t0[1];
    flat[3] = nh + ne + 1; flat[4] = t0[1]; flat[5] = t0[2];  /* so the midpoint moves with the fit */
    mk_raw_mesh *odd = copy_with(&src, head, extra_v, ev, extra_t, et);
    free(ev);
    free(et);
    CHECK(odd != NULL);
    if (!odd) goto done;
    mk_transfer_stats st;
    double e = rest_back(odd, tm, 12, (const uint32_t (*)[2])pairs, MK_TRANSFER_ITERATIVE, &st);
    printf("eye, loose vertex and a flat triangle in the source: rest gives back the target's rest within %.2g\n", e);
    CHECK_MSG(e >= 0 && e < 1e-9, "rest came back %.3g off", e);
    /* a position that is not finite is an error, not a crash */
    float keep = odd->positions[3];
    odd->positions[3] = NAN;
    mk_transfer_params bad = { .source = odd, .target = tm, .marker_count = 12, .markers = (const uint32_t (*)[2])pairs,
                               .correspondence = MK_TRANSFER_ITERATIVE };
    mk_transfer *x = NULL;
    mk_error err;
    CHECK(mk_transfer_create(&bad, NULL, &x, &err) == MK_ERROR_NOT_FINITE && x == NULL);
    odd->positions[3] = keep;
    /* a copy of the target with one triangle without area still coincides: auto takes the one pass */
    uint32_t degenerate[3] = { tm->triangles[0], tm->triangles[0], tm->triangles[1] };
    mk_raw_mesh *copy = copy_with(&dst, tm, 0, NULL, 1, degenerate);
    tm = &dst.meshes[0];
    CHECK(copy != NULL);
    if (copy) {
        uint32_t same[3][2] = { { 0, 0 }, { 5, 5 }, { 9, 9 } };
        e = rest_back(tm, copy, 3, (const uint32_t (*)[2])same, MK_TRANSFER_AUTO, &st);
        CHECK_MSG(e >= 0 && !st.iterative, "auto on a copy with a degenerate triangle: iterative %d", st.iterative);
    }
done:
    free(sdir);
    free(tdir);
    mk_raw_free(&src);
    mk_raw_free(&dst);
    mk_raw_free(&eye);
}

/* Source triangles without an area at rest (three corners on one row of a flat sheet) get an
 * area once the sheet is fitted to a bumped one; they have no gradient to give and must not be
 * paired (the rest source must give back the rest target). */
static void flat_source_triangles_are_not_paired(void)
{
    mk_raw_asset src, dst;
    mk_raw_init(&src, NULL);
    mk_raw_init(&dst, NULL);
    mk_raw_mesh *sheet = fixture_grid(&src, "sheet", 2, 2, 12, 12), *tm = fixture_grid(&dst, "bumped", 2, 2, 17, 13);
    for (uint32_t v = 0; v < tm->vertex_count; v++) {
        float x = tm->positions[3 * v] - 1, y = tm->positions[3 * v + 1] - 1;
        tm->positions[3 * v + 2] = 0.3f * expf(-(x * x + y * y) / 0.3f);
    }
    uint32_t row[12 * 11 * 3], n = 0;
    for (uint32_t j = 0; j <= 12; j += 2)
        for (uint32_t i = 0; i + 2 <= 12; i++) {
            row[3 * n] = j * 13 + i; row[3 * n + 1] = j * 13 + i + 1; row[3 * n + 2] = j * 13 + i + 2;
            n++;
        }
    /* the row triangles first, so that they would win the ties of the closest-point searches */
    mk_raw_mesh *flat = copy_with(&src, sheet, 0, NULL, n, row);
    if (flat) {
        uint32_t *t = flat->triangles, rows = 3 * n, sheet_tris = 3 * (flat->triangle_count - n);
        uint32_t *tmp = malloc((size_t)(rows + sheet_tris) * sizeof(uint32_t));
        if (tmp) {
            memcpy(tmp, t + sheet_tris, rows * sizeof(uint32_t));
            memcpy(tmp + rows, t, sheet_tris * sizeof(uint32_t));
            memcpy(t, tmp, (size_t)(rows + sheet_tris) * sizeof(uint32_t));
            free(tmp);
        }
    }
    CHECK(flat != NULL);
    uint32_t corners[4][2] = { { 0, 0 }, { 12, 17 }, { 13 * 12, 18 * 13 }, { 13 * 13 - 1, 18 * 14 - 1 } };
    mk_transfer_stats st;
    double e = flat ? rest_back(flat, &dst.meshes[0], 4, (const uint32_t (*)[2])corners, MK_TRANSFER_ITERATIVE, &st) : -1;
    printf("flat source triangles onto a bumped sheet: rest gives back the target's rest within %.2g\n", e);
    CHECK_MSG(e >= 0 && e < 1e-9, "rest came back %.3g off", e);
    mk_raw_free(&src);
    mk_raw_free(&dst);
}

CHECK_MAIN(CASE(iterative_correspondence_follows_a_warped_remeshed_head),
           CASE(smaller_warps_transfer_closer),
           CASE(iterative_correspondence_takes_odd_sources),
           CASE(flat_source_triangles_are_not_paired))

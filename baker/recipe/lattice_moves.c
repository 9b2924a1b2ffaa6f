/* SPDX-License-Identifier: MIT */
/* Moves of lattice control points (the "moves" of every FFD op, ffd_prism's "rest_moves"):
 * index ranges i, j, k, then scale, rotate and translate about a pivot (docs/baking.md). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fields.h"
#include "lattice_moves.h"

static mk_result parse_index_range(recipe_ctx *ctx, const cJSON *mv, const char *path, const char *field,
                                   uint32_t dim, uint32_t *lo, uint32_t *hi)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(mv, field);
    *lo = 0; *hi = dim - 1;
    if (!item) return MK_OK;
    double a, b;
    if (cJSON_IsNumber(item)) a = b = item->valuedouble;
    else if (cJSON_IsArray(item) && cJSON_GetArraySize(item) == 2 && cJSON_IsNumber(item->child) &&
             cJSON_IsNumber(item->child->next)) {
        a = item->child->valuedouble; b = item->child->next->valuedouble;
    } else return recipe_field_error(ctx, path, field, "must be an index or [first, last]%s", NULL);
    if (!isfinite(a) || !isfinite(b) || a != floor(a) || b != floor(b) || a < 0 || b < a || b >= dim) {
        char msg[64];
        snprintf(msg, sizeof msg, "must lie in 0..%u with first <= last", dim - 1);
        return recipe_field_error(ctx, path, field, "%s", msg);
    }
    *lo = (uint32_t)a; *hi = (uint32_t)b;
    return MK_OK;
}
/* Positions j of row i of a lattice: dims[1] for a box, the sides * i points of ring i (1 for
 * the centre) for a prism. */
static uint32_t grid_positions(const uint32_t dims[3], const mk_prism_lattice *prism, uint32_t i)
{
    return prism ? (i ? prism->sides * i : 1) : dims[1];
}

static size_t grid_index(const uint32_t dims[3], const mk_prism_lattice *prism, uint32_t i, uint32_t j, uint32_t k)
{
    return prism ? mk_prism_index(prism, i, j, k) : i + dims[0] * ((size_t)j + dims[1] * k);
}

mk_result recipe_lattice_moves(recipe_ctx *ctx, const uint32_t dims[3], const mk_prism_lattice *prism,
                               const cJSON *obj, const char *path, const char *field, const double *rest,
                               double *current, double *displacements)
{
    size_t points = prism ? mk_prism_point_count(prism) : (size_t)dims[0] * dims[1] * dims[2];
    memcpy(current, rest, 3 * points * sizeof(double));
    const cJSON *moves = cJSON_GetObjectItemCaseSensitive(obj, field);
    if (moves && !cJSON_IsArray(moves))
        return recipe_field_error(ctx, path, field, "must be an array of moves%s", NULL);
    int m = 0;
    for (const cJSON *mv = moves ? moves->child : NULL; mv; mv = mv->next, m++) {
        static const char *const move_fields[] = { "i", "j", "k", "translate", "rotate", "scale", "pivot", NULL };
        char mpath[256];
        snprintf(mpath, sizeof mpath, "%s.%s[%d]", path, field, m);
        if (!cJSON_IsObject(mv)) return recipe_field_error(ctx, mpath, "", "must be an object%s", NULL);
        mk_result r = recipe_check_fields(ctx, mv, mpath, move_fields, NULL);
        if (r != MK_OK) return r;
        uint32_t lo[3], hi[3];
        static const char *const ijk[3] = { "i", "j", "k" };
        for (int a = 0; a < 3; a++)
            if ((r = parse_index_range(ctx, mv, mpath, ijk[a], a == 1 ? grid_positions(dims, prism, lo[0]) : dims[a],
                                       &lo[a], &hi[a])) != MK_OK) return r;
        int all_j = !cJSON_HasObjectItem(mv, "j");
#define LAST_J(i) (all_j ? grid_positions(dims, prism, i) - 1 : hi[1])
        /* Default pivot: centroid of the selected control points (current positions). */
        double centroid[3] = { 0, 0, 0 };
        size_t sel = 0;
        for (uint32_t k = lo[2]; k <= hi[2]; k++)
            for (uint32_t i = lo[0]; i <= hi[0]; i++)
                for (uint32_t j = lo[1]; j <= LAST_J(i); j++, sel++)
                    for (int c = 0; c < 3; c++)
                        centroid[c] += current[3 * grid_index(dims, prism, i, j, k) + c];
        for (int c = 0; c < 3; c++) centroid[c] /= (double)sel;
        double pivot[3] = { centroid[0], centroid[1], centroid[2] };
        if (recipe_get_vec3(ctx, mv, mpath, "pivot", pivot) < 0) return ctx->err->code;
        double scale[3] = { 1, 1, 1 }, translate[3] = { 0, 0, 0 }, axis[3], angle, rpivot[3];
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(mv, "scale");
        if (sc && cJSON_IsNumber(sc)) {
            if (!isfinite(sc->valuedouble)) return recipe_field_error(ctx, mpath, "scale", "is not finite%s", NULL);
            scale[0] = scale[1] = scale[2] = sc->valuedouble;
        } else if (sc && recipe_get_vec3(ctx, mv, mpath, "scale", scale) < 0) return ctx->err->code;
        if (recipe_get_vec3(ctx, mv, mpath, "translate", translate) < 0) return ctx->err->code;
        if ((r = recipe_rotate(ctx, mv, mpath, axis, &angle, rpivot, pivot)) != MK_OK) return r;
        double R[9];
        mat3_rotation(R, axis, angle);
        /* P <- rotate(scale(P about pivot)) about rotate.pivot, then translate. */
        for (uint32_t k = lo[2]; k <= hi[2]; k++)
            for (uint32_t i = lo[0]; i <= hi[0]; i++)
                for (uint32_t j = lo[1]; j <= LAST_J(i); j++) {
                    double *p = current + 3 * grid_index(dims, prism, i, j, k);
                    double q[3], o[3];
                    for (int c = 0; c < 3; c++) q[c] = pivot[c] + scale[c] * (p[c] - pivot[c]) - rpivot[c];
                    mat3_mul_vec(o, R, q);
                    for (int c = 0; c < 3; c++) p[c] = rpivot[c] + o[c] + translate[c];
                }
    }
#undef LAST_J
    for (size_t q = 0; q < 3 * points; q++) displacements[q] = current[q] - rest[q];
    return MK_OK;
}

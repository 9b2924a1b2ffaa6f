/* SPDX-License-Identifier: MIT */
/* Readers of recipe fields (fields.c). Each reads `field` of the JSON object `obj` found at
 * `path` and, on a bad value, sets ctx->err to "PATH.FIELD: what is wrong" (MK_ERROR_PARSE) and
 * returns its code. */
#ifndef MORPHKIT_RECIPE_FIELDS_H
#define MORPHKIT_RECIPE_FIELDS_H

#include "recipe_op.h"

/* Nonzero for a recipe from an untrusted source (mk_bake_options.untrusted): smaller limits, no
 * files read or written. */
int recipe_untrusted(const recipe_ctx *ctx);

/* Sets "PATH[.FIELD]: " followed by fmt with detail for its one %s (NULL: ""). */
mk_result recipe_field_error(recipe_ctx *ctx, const char *path, const char *field, const char *fmt,
                             const char *detail);

/* A finite number; absent: *out unchanged, an error only when required. */
mk_result recipe_get_number(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                            double *out, int required);

/* A number in lo..hi, > lo when lo_open, < hi always; `range` words the bounds for the error. */
mk_result recipe_get_bounded(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field, double *out,
                             double lo, int lo_open, double hi, const char *range);

/* An integer in min..max; absent: *out unchanged. */
mk_result recipe_get_uint(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                          uint32_t *out, uint32_t min, uint32_t max);

/* `item` (the value of field) as an array of 3 finite numbers. */
mk_result recipe_vec3_item(recipe_ctx *ctx, const cJSON *item, const char *path, const char *field,
                           double out[3]);

/* Returns 1 when present (and parsed), 0 when absent, -1 on error. */
int recipe_get_vec3(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field, double out[3]);

/* Every field of obj is in a or b (NULL-terminated lists; either may be NULL). */
mk_result recipe_check_fields(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *const *a,
                              const char *const *b);

/* The object field `field` of obj (NULL in *out when absent): checked to be an object with only
 * the given fields; subpath receives "path.field" for its own errors. */
mk_result recipe_get_object(recipe_ctx *ctx, const cJSON *obj, const char *path, const char *field,
                            const char *const *fields, const char *usage, char *subpath, size_t subpath_size,
                            const cJSON **out);

/* Selection object: {"indices": [...]} | {"center": [x,y,z], "radius": r} |
 * {"min": [..], "max": [..]} (with allow_extra also "translate" and "rotate", a handle's).
 * Appends the matching vertices not marked yet to *list (a scratch array of *capacity) and marks
 * them; an empty result is an error. */
mk_result recipe_selection(recipe_ctx *ctx, const mk_raw_mesh *mesh, const cJSON *sel, const char *path,
                           unsigned char *mark, uint32_t **list, uint32_t *count, uint32_t *capacity,
                           int allow_extra);

/* Rotation object {"axis": [..], "degrees": d, "pivot": [..]} in field "rotate" of obj; pivot
 * defaults to def_pivot. Absent: angle 0 about z. */
mk_result recipe_rotate(recipe_ctx *ctx, const cJSON *obj, const char *path, double axis[3], double *angle,
                        double pivot[3], const double def_pivot[3]);

/* Field "axis": "x", "-y", ... or [x, y, z] (nonzero, not normalized); default +y. */
mk_result recipe_axis(recipe_ctx *ctx, const cJSON *obj, const char *path, double axis[3]);

/* A recipe's file path resolved against options.base_dir (absolute paths are kept). */
void recipe_path(const recipe_ctx *ctx, const char *name, char *full, size_t size);

/* A mesh of `raw` by name or index (field `field` of the object at path). */
mk_result recipe_resolve_mesh(recipe_ctx *ctx, const mk_raw_asset *raw, const cJSON *item, const char *path,
                              const char *field, uint32_t *mesh);

/* Appends "name" (NULL: "") to a list of quoted names ("a", "b", ...) in list[size]; when it would
 * not fit, appends ", ..." instead and returns 0: stop adding. */
int recipe_list_name(char *list, size_t size, const char *name);

/* A zeroed op state of `size` bytes in the scratch arena, set as ch->state (NULL when out of
 * memory). */
void *recipe_state_new(recipe_ctx *ctx, recipe_channel *ch, size_t size);

#endif

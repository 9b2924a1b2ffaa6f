/* Placeholder until the bakers land (issue #5). */
#include "bake.h"

mk_result mk_bake_recipe(mk_raw_asset *raw, const char *recipe_json, size_t recipe_size,
                         void (*progress)(void *user, const char *stage, double fraction),
                         void *user, mk_bake_report *report, mk_error *err)
{
    (void)raw; (void)recipe_json; (void)recipe_size; (void)progress; (void)user; (void)report;
    return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "baking is not implemented yet");
}

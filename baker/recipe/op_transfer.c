/* SPDX-License-Identifier: MIT */
/* Recipe op transfer: deformation transfer (transfer.h) of a source asset's channels onto the
 * mesh, one channel per source channel, all from one factorization. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "fields.h"
#include "transfer.h"
#include "transfer_internal.h"

typedef struct transfer_state {
    mk_raw_asset *source;         /* the loaded source asset (freed by release_transfer) */
    uint32_t source_mesh;
    uint32_t source_channel_count;/* the source's channels to carry over */
    uint32_t *source_channels;
    uint32_t marker_count;        /* (source vertex, target vertex) pairs */
    uint32_t (*markers)[2];
    char prefix[64];              /* prepended to the source channel names */
    int has_default_weight;
    mk_transfer_correspondence correspondence;
    uint32_t step_count;          /* the schedule's closest-point weights (0: the default) */
    double *steps;
    double fit_tolerance;         /* iterative: largest mean distance of the fit, x diagonal */
} transfer_state;

/* correspondence ("auto", "closest", "iterative"), schedule (the closest-point weights) and
 * fit_tolerance (docs/baking.md). */
static mk_result parse_correspondence(recipe_ctx *ctx, transfer_state *st, const cJSON *ch, const char *path)
{
    static const char *const modes[] = { "auto", "closest", "iterative" };
    const cJSON *mode = cJSON_GetObjectItemCaseSensitive(ch, "correspondence");
    st->correspondence = MK_TRANSFER_AUTO;
    if (mode) {
        int k = -1;
        for (int i = 0; i < 3 && cJSON_IsString(mode); i++)
            if (!strcmp(mode->valuestring, modes[i])) k = i;
        if (k < 0) return recipe_field_error(ctx, path, "correspondence", "must be \"auto\", \"closest\" or \"iterative\"%s", NULL);
        st->correspondence = (mk_transfer_correspondence)k;
    }
    const cJSON *schedule = cJSON_GetObjectItemCaseSensitive(ch, "schedule");
    if (schedule) {
        int count = cJSON_IsArray(schedule) ? cJSON_GetArraySize(schedule) : 0;
        if (count < 1 || count > 16)
            return recipe_field_error(ctx, path, "schedule", "must be an array of 1..16 closest-point weights%s", NULL);
        st->steps = mk_arena_array(ctx->scratch, (size_t)count, sizeof(double));
        if (!st->steps) return mk_error_oom(ctx->err, "schedule");
        int k = 0;
        for (const cJSON *e = schedule->child; e; e = e->next, k++) {
            double v = e->valuedouble;
            if (!cJSON_IsNumber(e) || !isfinite(v) || !(v > 0) || v > 1e12 || (k > 0 && !(v > st->steps[k - 1]))) {
                char msg[120];
                snprintf(msg, sizeof msg, "entry %d must be a weight in (0, 1e12], larger than the previous entry", k);
                return recipe_field_error(ctx, path, "schedule", "%s", msg);
            }
            st->steps[k] = v;
        }
        st->step_count = (uint32_t)count;
    }
    st->fit_tolerance = TRANSFER_FIT_TOLERANCE;
    mk_result r = recipe_get_number(ctx, ch, path, "fit_tolerance", &st->fit_tolerance, 0);
    if (r != MK_OK) return r;
    if (!(st->fit_tolerance > 0 && st->fit_tolerance < 1))
        return recipe_field_error(ctx, path, "fit_tolerance", "must be in (0, 1): a fraction of the target's diagonal%s", NULL);
    if (st->correspondence == MK_TRANSFER_CLOSEST && (schedule || cJSON_HasObjectItem(ch, "fit_tolerance")))
        return recipe_field_error(ctx, path, schedule ? "schedule" : "fit_tolerance",
                                  "applies to the iterative correspondence only (correspondence is \"closest\")%s", NULL);
    return MK_OK;
}

/* transfer: load the source asset through options.load_asset, pick its mesh and channels, read
 * the markers. The source stays loaded until the bake ends (release_transfer). */
static mk_result parse_transfer(recipe_ctx *ctx, recipe_channel *plan, const cJSON *ch, const char *path)
{
    static const char *const not_for_transfer[] = { "name", "inbetweens", "tolerance", "samples", "max_targets", NULL };
    for (int i = 0; not_for_transfer[i]; i++)
        if (cJSON_HasObjectItem(ch, not_for_transfer[i]))
            return recipe_field_error(ctx, path, not_for_transfer[i],
                                      "does not apply to transfer%s (channels are named after the source's, with prefix; "
                                      "in-betweens are carried over one to one)", NULL);
    transfer_state *st = recipe_state_new(ctx, plan, sizeof *st);
    if (!st) return mk_error_oom(ctx->err, "transfer");
    st->has_default_weight = cJSON_HasObjectItem(ch, "default_weight");
    const cJSON *prefix = cJSON_GetObjectItemCaseSensitive(ch, "prefix");
    if (prefix && (!cJSON_IsString(prefix) || strlen(prefix->valuestring) >= sizeof st->prefix))
        return recipe_field_error(ctx, path, "prefix", "must be a string under 64 bytes%s", NULL);
    if (prefix) snprintf(st->prefix, sizeof st->prefix, "%s", prefix->valuestring);
    mk_result r = parse_correspondence(ctx, st, ch, path);
    if (r != MK_OK) return r;

    if (recipe_untrusted(ctx)) return recipe_field_error(ctx, path, "source", "files are not read for untrusted recipes%s", NULL);
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(ch, "source");
    if (!item) return recipe_field_error(ctx, path, "source", "missing (path of the asset whose channels are transferred)%s", NULL);
    if (!cJSON_IsString(item) || !*item->valuestring)
        return recipe_field_error(ctx, path, "source", "must be the path of an asset file (.fbx, .gltf, .glb, .morph)%s", NULL);
    if (!ctx->options || !ctx->options->load_asset)
        return recipe_field_error(ctx, path, "source", "this bake has no asset loader (mk_bake_options.load_asset)%s", NULL);
    char full[4096];
    recipe_path(ctx, item->valuestring, full, sizeof full);
    st->source = mk_arena_alloc(ctx->scratch, sizeof *st->source);
    if (!st->source) return mk_error_oom(ctx->err, "transfer source");
    mk_raw_init(st->source, &ctx->raw->arena.allocator);
    mk_error inner;
    memset(&inner, 0, sizeof inner);
    if (ctx->options->load_asset(ctx->options->user, full, st->source, &inner) != MK_OK)
        return mk_error_set(ctx->err, inner.code ? inner.code : MK_ERROR_IO, inner.offset, "%s.source: %s", path,
                            inner.message);  /* the loader names the file */
    if (ctx->options->file_read) ctx->options->file_read(ctx->options->user, full);
    const mk_raw_asset *src = st->source;
    st->source_mesh = 0;
    const cJSON *sm = cJSON_GetObjectItemCaseSensitive(ch, "source_mesh");
    if (sm && (r = recipe_resolve_mesh(ctx, src, sm, path, "source_mesh", &st->source_mesh)) != MK_OK) return r;
    if (st->source_mesh >= src->mesh_count)
        return recipe_field_error(ctx, path, "source", "the asset has no mesh%s", NULL);
    const mk_raw_mesh *smesh = &src->meshes[st->source_mesh];
    if (smesh->vertex_count == 0 || smesh->triangle_count == 0)
        return recipe_field_error(ctx, path, sm ? "source_mesh" : "source", "the source mesh has no triangles%s", NULL);

    /* the source mesh's channels, all by default */
    st->source_channels = mk_arena_array(ctx->scratch, (size_t)src->channel_count + 1, sizeof(uint32_t));
    if (!st->source_channels) return mk_error_oom(ctx->err, "transfer channels");
    const cJSON *names = cJSON_GetObjectItemCaseSensitive(ch, "channels");
    char cpath[128];
    if (!names) {
        for (uint32_t c = 0; c < src->channel_count; c++)
            if (src->channels[c].mesh == st->source_mesh) st->source_channels[st->source_channel_count++] = c;
        if (st->source_channel_count == 0) {
            char msg[160];
            snprintf(msg, sizeof msg, "the source mesh %u (\"%.60s\") has no channels to transfer", st->source_mesh,
                     smesh->name ? smesh->name : "");
            return recipe_field_error(ctx, path, "source", "%s", msg);
        }
    } else {
        if (!cJSON_IsArray(names) || cJSON_GetArraySize(names) == 0)
            return recipe_field_error(ctx, path, "channels", "must be a non-empty array of source channel names%s", NULL);
        int i = 0;
        for (const cJSON *n = names->child; n; n = n->next, i++) {
            snprintf(cpath, sizeof cpath, "%s.channels[%d]", path, i);
            if (!cJSON_IsString(n)) return recipe_field_error(ctx, cpath, "", "must be a channel name (a string)%s", NULL);
            uint32_t found = UINT32_MAX;
            for (uint32_t c = 0; c < src->channel_count && found == UINT32_MAX; c++)
                if (src->channels[c].mesh == st->source_mesh && src->channels[c].name &&
                    !strcmp(src->channels[c].name, n->valuestring)) found = c;
            if (found == UINT32_MAX) {
                char list[120] = "";
                for (uint32_t c = 0; c < src->channel_count; c++)
                    if (src->channels[c].mesh == st->source_mesh && !recipe_list_name(list, sizeof list, src->channels[c].name))
                        break;
                char msg[240];
                snprintf(msg, sizeof msg, "no channel \"%.40s\" on the source mesh; its channels are %s", n->valuestring,
                         *list ? list : "(none)");
                return recipe_field_error(ctx, cpath, "", "%s", msg);
            }
            st->source_channels[st->source_channel_count++] = found;
        }
    }
    for (uint32_t k = 0; k < st->source_channel_count; k++) {
        const mk_raw_channel *sc = &src->channels[st->source_channels[k]];
        if (sc->target_count == 0)
            return recipe_field_error(ctx, path, "source", "channel \"%s\" of the source has no targets", sc->name ? sc->name : "");
        if (strlen(st->prefix) + strlen(sc->name ? sc->name : "") >= sizeof plan->name)
            return recipe_field_error(ctx, path, "prefix", "with the source channel \"%.60s\" makes a name of 128 bytes or more", sc->name);
    }

    /* markers: [[source vertex, target vertex], ...] */
    const cJSON *markers = cJSON_GetObjectItemCaseSensitive(ch, "markers");
    if (markers) {
        if (!cJSON_IsArray(markers))
            return recipe_field_error(ctx, path, "markers", "must be an array of [source_vertex, target_vertex] pairs%s", NULL);
        int count = cJSON_GetArraySize(markers);
        st->markers = mk_arena_array(ctx->scratch, (size_t)count + 1, sizeof *st->markers);
        if (!st->markers) return mk_error_oom(ctx->err, "markers");
        uint32_t limit[2] = { smesh->vertex_count, ctx->raw->meshes[plan->mesh].vertex_count };
        static const char *const side[2] = { "source", "target" };
        int i = 0;
        for (const cJSON *m = markers->child; m; m = m->next, i++) {
            snprintf(cpath, sizeof cpath, "%s.markers[%d]", path, i);
            if (!cJSON_IsArray(m) || cJSON_GetArraySize(m) != 2)
                return recipe_field_error(ctx, cpath, "", "must be a pair [source_vertex, target_vertex]%s", NULL);
            int k = 0;
            for (const cJSON *e = m->child; e; e = e->next, k++) {
                double v = e->valuedouble;
                if (!cJSON_IsNumber(e) || !isfinite(v) || v != floor(v) || v < 0 || v >= limit[k]) {
                    char msg[120];
                    snprintf(msg, sizeof msg, "the %s vertex must be an integer in 0..%u", side[k], limit[k] ? limit[k] - 1 : 0);
                    return recipe_field_error(ctx, cpath, "", "%s", msg);
                }
                st->markers[i][k] = (uint32_t)v;
            }
        }
        st->marker_count = (uint32_t)count;
    }
    return MK_OK;
}
/* transfer: one channel per source channel, all from one factorization. */
static mk_result bake_transfer(recipe_ctx *ctx, recipe_channel *plan, int index, mk_bake_report *report)
{
    mk_raw_asset *raw = ctx->raw;
    const mk_bake_options *o = ctx->options;
    const transfer_state *st = plan->state;
    const mk_raw_mesh *smesh = &st->source->meshes[st->source_mesh];
    double t0 = bake_now();
    if (o && o->progress) o->progress(o->user, "transfer: matching triangles", 0);
    mk_transfer_params tp = { smesh, &raw->meshes[plan->mesh], st->marker_count, (const uint32_t (*)[2])st->markers,
                              st->correspondence, st->step_count, st->steps };
    mk_transfer *x = NULL;
    mk_error inner;
    mk_result r = mk_transfer_create(&tp, &raw->arena.allocator, &x, &inner);
    mk_transfer_stats fit;
    if (r == MK_OK) {
        mk_transfer_stats_get(x, &fit);
        if (fit.iterative && fit.fit_mean > st->fit_tolerance) {
            mk_transfer_destroy(x);
            return mk_error_set(ctx->err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                "channels[%d].schedule: the fit did not converge: the fitted source lies %.3g of the "
                                "target's diagonal from it on average (max %.3g; fit_tolerance %.3g): give markers "
                                "where the meshes differ most, or a larger last weight", index, fit.fit_mean,
                                fit.fit_max, st->fit_tolerance);
        }
    }
    uint32_t solves_before = 0;
    double solve_seconds_before = 0;
    for (uint32_t k = 0; r == MK_OK && k < st->source_channel_count; k++) {
        const mk_raw_channel *sc = &st->source->channels[st->source_channels[k]];
        snprintf(plan->name, sizeof plan->name, "%s%s", st->prefix, sc->name ? sc->name : "");
        if (o && o->progress) o->progress(o->user, plan->name, (double)k / st->source_channel_count);
        uint32_t moved = 0;
        r = mk_transfer_channel(raw, plan->mesh, plan->name, plan->origin, x, smesh, sc, &moved, &inner);
        if (r != MK_OK) break;
        if (st->has_default_weight) raw->channels[raw->channel_count - 1].default_weight = plan->default_weight;
        mk_transfer_stats ts;
        mk_transfer_stats_get(x, &ts);
        mk_bake_channel_report cr;
        memset(&cr, 0, sizeof cr);
        cr.name = plan->name;
        cr.op = plan->op->name;
        cr.mesh = plan->mesh;
        cr.targets = sc->target_count;
        cr.evaluations = sc->target_count;
        cr.moved_vertices = moved;
        /* the one factorization is reported with the first channel, each channel its own solves */
        cr.factorizations = k == 0;
        cr.factor_seconds = k == 0 ? ts.factor_seconds : 0;
        if (k == 0) {
            cr.correspondence = ts.iterative ? "iterative" : "closest";
            cr.fit_mean = ts.fit_mean;
            cr.fit_max = ts.fit_max;
        }
        cr.solves = ts.solves - solves_before;
        cr.solve_seconds = ts.solve_seconds - solve_seconds_before;
        solves_before = ts.solves;
        solve_seconds_before = ts.solve_seconds;
        cr.seconds = bake_now() - t0;
        t0 = bake_now();
        if (o && o->channel_done) o->channel_done(o->user, &cr);
        report->channels_added++;
        report->targets_added += sc->target_count;
    }
    if (r == MK_OK) {
        mk_transfer_stats ts;
        mk_transfer_stats_get(x, &ts);
        if (ts.flipped || ts.unmatched)
            mk_raw_warn(raw, "transfer channels[%d]: %u target triangles matched a farther source triangle facing "
                        "their way, %u matched none (they follow their neighbors%s)", index, ts.flipped, ts.unmatched,
                        ts.iterative ? " unless a source triangle was paired with them" : "");
    }
    mk_transfer_destroy(x);
    if (r != MK_OK)
        return mk_error_set(ctx->err, inner.code, inner.offset, "channels[%d] (transfer): %s", index, inner.message);
    return MK_OK;
}

static void release_transfer(recipe_channel *plan)
{
    transfer_state *st = plan->state;
    if (st && st->source) mk_raw_free(st->source);
}

static const char *const transfer_fields[] = { "source", "source_mesh", "channels", "markers", "prefix",
                                               "correspondence", "schedule", "fit_tolerance", NULL };

const recipe_op recipe_op_transfer = { .name = "transfer", .fields = transfer_fields, .parse = parse_transfer,
                                       .bake = bake_transfer, .release = release_transfer };

/* SPDX-License-Identifier: MIT */
/* Blend shape channels of one mesh into raw channels and targets, in three steps:
 *
 * 1. Every channel's shapes get their full weights (Blender: per-vertex weights instead) and
 *    are sorted by them; a shape whose full weight the runtime cannot place is no job.
 * 2. The jobs run on worker threads (offline/parallel.h): decode Indexes, Vertices and Normals
 *    (the inflation is most of an import's shape time) and expand the deltas to render
 *    vertices. Each worker has its own decoder, arrays, expansion scratch and output arena;
 *    every job keeps its own result, error and what its warnings need.
 * 3. In channel and in-between order, on the calling thread: the skip rules, warnings,
 *    channels and targets, exactly as going through the shapes one by one, and the first error
 *    in that order. A shape whose full weight repeats the previous job's in its channel is not
 *    run in step 2 (the duplicate rule usually drops it, and a file can repeat one cheap-to-store
 *    shape many times); it runs here, on the calling thread, only if the rule keeps it (when the
 *    shapes before it were unusable).
 */
#include <math.h>
#include <string.h>
#include "fbx_shapes.h"
#include "parallel.h"

typedef struct shape_job {
    const fbx_shape_ref *ref;      /* NULL: no job (the full weight already drops the shape) */
    int deferred;                  /* its full weight repeats the previous job's: run in step 3 if kept */
    const fbx_node *vertex_weights;/* Blender per-vertex FullWeights (percent), or NULL */
    size_t full_weight_count;      /* their count once decoded */
    mk_result result;
    mk_error error;
    int decoded;                   /* the three arrays were decoded (else result is why not) */
    int usable;
    size_t n_idx, n_pos, n_nrm;
    int normals_mismatch;          /* Normals ignored: its count differs from Vertices' */
    int weights_mismatch;          /* Blender FullWeights ignored: its count differs from Indexes' */
    size_t skipped;                /* Indexes entries outside the control points */
    mk_raw_target target;          /* count, indices, positions, normals (a worker's out arena) */
} shape_job;

typedef struct shape_worker {
    fbx_doc doc;                   /* the file's tree with this worker's arena, decoder and spare arrays */
    mk_arena *out;                 /* target arrays */
    fbx_mesh_map map;              /* the mesh's map with this worker's expansion scratch */
    mk_arena scratch, own_out;     /* workers past the first: their arenas (out adopted by the raw asset) */
} shape_worker;

typedef struct shape_loop {
    const mk_import_options *options;
    shape_job *jobs;
    shape_worker *workers;
} shape_loop;

static int any_nonzero(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++) if (v[i] != 0.0) return 1;
    return 0;
}

static mk_result decode_and_expand(const shape_loop *l, shape_worker *w, shape_job *j)
{
    fbx_doc *doc = &w->doc;
    const fbx_node *node = j->ref->node;
    int32_t *indexes = NULL;
    double *positions = NULL, *normals = NULL, *weights = NULL;
    size_t n_idx = 0, n_pos = 0, n_nrm = 0, n_w = 0;
    mk_result r = MK_OK;
    if (j->vertex_weights) r = fbx_node_array(doc, j->vertex_weights, FBX_ELEM_F64, (void **)&weights, &n_w);
    if (r == MK_OK) r = fbx_child_array(doc, node, "Indexes", FBX_ELEM_I32, (void **)&indexes, &n_idx);
    if (r == MK_OK) r = fbx_child_array(doc, node, "Vertices", FBX_ELEM_F64, (void **)&positions, &n_pos);
    if (r == MK_OK && l->options->target_normals != MK_TARGET_NORMALS_NONE)   /* not even decoded */
        r = fbx_child_array(doc, node, "Normals", FBX_ELEM_F64, (void **)&normals, &n_nrm);
    if (r != MK_OK) {
        mk_arena_release(doc->arena, weights);
        mk_arena_release(doc->arena, indexes);
        mk_arena_release(doc->arena, positions);
        mk_arena_release(doc->arena, normals);
        return r;
    }
    j->decoded = 1;
    j->n_idx = n_idx;
    j->n_pos = n_pos;
    j->n_nrm = n_nrm;
    j->full_weight_count = n_w;
    j->usable = indexes && positions && n_pos == 3 * n_idx;
    if (j->usable) {
        char path[160];
        fbx_node_path(node, path, sizeof path);
        fbx_shape_data data = { .count = n_idx, .indexes = indexes, .positions = positions, .path = path, .node = node,
                                .name = j->ref->name, .name_length = j->ref->name_length };
        if (normals && n_nrm != n_pos) j->normals_mismatch = 1;
        else if (normals && (l->options->keep_shape_normals || any_nonzero(normals, n_nrm))) data.normals = normals;
        if (j->vertex_weights) {
            if (n_w == n_idx) {
                for (size_t k = 0; k < n_w; k++) weights[k] /= 100.0;  /* percent to 0..1 */
                data.vertex_weights = weights;
            } else {
                j->weights_mismatch = 1;
            }
        }
        r = fbx_expand_shape(doc, w->out, &w->map, &data, &j->target, &j->skipped);
    }
    fbx_recycle(doc, indexes, n_idx * sizeof *indexes);  /* this worker's next shape reuses them */
    fbx_recycle(doc, positions, n_pos * sizeof *positions);
    fbx_recycle(doc, normals, n_nrm * sizeof *normals);
    fbx_recycle(doc, weights, n_w * sizeof *weights);
    return r;
}

static void shape_item(void *user, uint32_t item, uint32_t worker)
{
    shape_loop *l = user;
    shape_job *j = &l->jobs[item];
    if (!j->ref || j->deferred) return;
    shape_worker *w = &l->workers[worker];
    w->doc.err = &j->error;
    j->result = decode_and_expand(l, w, j);
}

static void drop_job_arrays(mk_raw_asset *raw, shape_job *j)
{
    mk_arena_release(&raw->arena, j->target.indices);
    mk_arena_release(&raw->arena, j->target.positions);
    mk_arena_release(&raw->arena, j->target.normals);
    memset(&j->target, 0, sizeof j->target);
}

static mk_result job_error(fbx_doc *doc, const shape_job *j)
{
    if (doc->err) *doc->err = j->error;
    return j->result;
}

/* Step 3 for one channel: its shapes' jobs are jobs[0 .. plan->shape_count); a deferred job
 * runs on the loop's first worker (the calling thread's). */
static mk_result add_channel(fbx_doc *doc, mk_raw_asset *raw, uint32_t mesh, uint32_t control_points,
                             fbx_channel_plan *plan, shape_job *jobs, shape_loop *l)
{
    plan->channel = UINT32_MAX;
    char path[160];
    mk_raw_channel *channel = NULL;
    uint32_t index = raw->channel_count;
    float last_weight = 0;
    for (uint32_t i = 0; i < plan->shape_count; i++) {
        const fbx_shape_ref *shape = &plan->shapes[i];
        shape_job *j = &jobs[i];
        fbx_node_path(shape->node, path, sizeof path);
        float fw = (float)(shape->full_weight / 100.0);
        /* The same gaps mk_raw_validate and the runtime require (format.h): a full weight the
         * runtime cannot place is skipped here with a warning, never passed on to fail later. */
        if (!j->ref) {
            mk_raw_warn(raw, "FBX %s '%.*s': full weight %g is zero (closer than 1e-6) or not finite; shape skipped", path,
                        (int)shape->name_length, shape->name, shape->full_weight);
            continue;
        }
        if (channel && channel->target_count > 0 && !(fw - last_weight >= MK_MIN_FULL_WEIGHT_GAP)) {
            mk_raw_warn(raw, "FBX %s '%.*s': full weight %g repeats the previous in-between (closer than 1e-6); duplicate dropped",
                        path, (int)shape->name_length, shape->name, shape->full_weight);
            drop_job_arrays(raw, j);
            continue;
        }
        if (j->deferred) {
            j->deferred = 0;
            shape_item(l, (uint32_t)(j - l->jobs), 0);
        }
        if (!j->decoded) return job_error(doc, j);
        if (!j->usable) {
            mk_raw_warn(raw, "FBX %s: shape needs Indexes and 3 Vertices values per index (%zu, %zu); skipped", path,
                        j->n_idx, j->n_pos);
            continue;
        }
        if (j->normals_mismatch)
            mk_raw_warn(raw, "FBX %s: Normals has %zu values for %zu vertices; ignored", path, j->n_nrm, j->n_pos);
        if (j->weights_mismatch)
            mk_raw_warn(raw, "FBX %s: Blender FullWeights count %zu differs from %zu indexes; ignored", path,
                        j->full_weight_count, j->n_idx);
        if (j->result != MK_OK) return job_error(doc, j);
        if (!channel) {
            channel = mk_raw_add_channels(raw, 1);
            if (!channel) return mk_error_oom(doc->err, "FBX channel");
            channel->mesh = mesh;
            channel->name = mk_arena_strndup(&raw->arena, plan->name ? plan->name : "", plan->name ? plan->name_length : 0);
            channel->origin = NULL;
            channel->default_weight = (float)(plan->default_percent / 100.0);
            if (!channel->name) return mk_error_oom(doc->err, "FBX channel");
        }
        mk_raw_target *target = mk_raw_add_targets(raw, channel, 1);
        if (!target) return mk_error_oom(doc->err, "FBX target");
        target->full_weight = fw;
        target->name = mk_arena_strndup(&raw->arena, shape->name ? shape->name : "", shape->name ? shape->name_length : 0);
        if (!target->name) return mk_error_oom(doc->err, "FBX target");
        target->count = j->target.count;
        target->indices = j->target.indices;
        target->positions = j->target.positions;
        target->normals = j->target.normals;
        memset(&j->target, 0, sizeof j->target);
        if (j->skipped)
            mk_raw_warn(raw, "FBX %s: %zu Indexes entries outside the %u control points skipped", path, j->skipped,
                        control_points);
        last_weight = fw;
    }
    if (!channel) {
        mk_raw_warn(raw, "FBX channel '%.*s': no usable shape; channel dropped", (int)plan->name_length,
                    plan->name ? plan->name : "");
        return MK_OK;
    }
    if (!isfinite(channel->default_weight)) channel->default_weight = 0;
    plan->channel = index;
    return MK_OK;
}

/* Step 1 for one channel: full weights, then a stable insertion sort by them (in-betweens come
 * in connection order). */
static void sort_shapes(fbx_channel_plan *plan)
{
    fbx_shape_ref *shapes = plan->shapes;
    for (uint32_t i = 0; i < plan->shape_count; i++)
        shapes[i].full_weight = (!plan->vertex_weights && i < plan->full_weight_count) ? plan->full_weights[i] : 100.0;
    for (uint32_t i = 1; i < plan->shape_count; i++) {
        fbx_shape_ref t = shapes[i];
        uint32_t j = i;
        while (j > 0 && shapes[j - 1].full_weight > t.full_weight) { shapes[j] = shapes[j - 1]; j--; }
        shapes[j] = t;
    }
}

mk_result fbx_add_channels(fbx_doc *doc, mk_raw_asset *raw, const mk_import_options *options, uint32_t mesh,
                           fbx_mesh_map *map, fbx_channel_plan *plans, uint32_t plan_count)
{
    size_t total = 0;
    for (uint32_t p = 0; p < plan_count; p++) {
        sort_shapes(&plans[p]);
        total += plans[p].shape_count;
    }
    if (total > UINT32_MAX) return mk_error_set(doc->err, MK_ERROR_LIMIT, UINT64_MAX, "FBX: too many shapes");
    shape_loop l;
    l.options = options;
    l.jobs = mk_arena_array(doc->arena, total ? total : 1, sizeof *l.jobs);
    uint32_t workers = mk_parallel_threads(mk_arena_threads(&raw->arena, options->threads), (uint32_t)total);
    l.workers = mk_arena_array(doc->arena, workers, sizeof *l.workers);
    if (!l.jobs || !l.workers) {
        mk_arena_release(doc->arena, l.jobs);
        mk_arena_release(doc->arena, l.workers);
        return mk_error_oom(doc->err, "FBX shapes");
    }
    size_t n = 0;
    for (uint32_t p = 0; p < plan_count; p++) {
        const fbx_channel_plan *plan = &plans[p];
        float previous = 0;
        int have_previous = 0;
        for (uint32_t i = 0; i < plan->shape_count; i++, n++) {
            float fw = (float)(plan->shapes[i].full_weight / 100.0);
            if (!isfinite(fw) || fabsf(fw) < MK_MIN_FULL_WEIGHT_GAP) continue;  /* dropped in step 3 */
            l.jobs[n].ref = &plan->shapes[i];
            l.jobs[n].vertex_weights = plan->vertex_weights;
            if (have_previous && !(fw - previous >= MK_MIN_FULL_WEIGHT_GAP)) {
                l.jobs[n].deferred = 1;
            } else {
                previous = fw;
                have_previous = 1;
            }
        }
    }
    for (uint32_t w = 0; w < workers; w++) {
        shape_worker *sw = &l.workers[w];
        sw->doc = *doc;
        sw->doc.prefetched = NULL;  /* the mesh's arrays were handed over or dropped */
        sw->doc.prefetched_count = 0;
        sw->map = *map;
        sw->out = &raw->arena;
        if (w == 0) continue;  /* the calling thread: the document's and the raw asset's own */
        mk_arena_init(&sw->scratch, &doc->arena->allocator);
        mk_arena_init(&sw->own_out, &raw->arena.allocator);
        sw->doc.arena = &sw->scratch;
        sw->doc.inflater = NULL;
        memset(sw->doc.spare, 0, sizeof sw->doc.spare);
        sw->out = &sw->own_out;
        sw->map.cp_entry = sw->map.entry_cp = NULL;
        sw->map.sum_pos = sw->map.sum_nrm = NULL;
        sw->map.pairs = NULL;
    }
    mk_parallel_for((uint32_t)total, workers, shape_item, &l);
    for (uint32_t w = 1; w < workers; w++) {
        fbx_doc_free(&l.workers[w].doc);
        mk_arena_free_all(&l.workers[w].scratch);
        mk_arena_adopt(&raw->arena, &l.workers[w].own_out);
    }
    mk_result r = MK_OK;
    n = 0;
    for (uint32_t p = 0; p < plan_count && r == MK_OK; p++) {
        r = add_channel(doc, raw, mesh, map->control_point_count, &plans[p], &l.jobs[n], &l);
        n += plans[p].shape_count;
    }
    /* The first worker's decoder, spare arrays and scratch go back to the document and map. */
    doc->inflater = l.workers[0].doc.inflater;
    memcpy(doc->spare, l.workers[0].doc.spare, sizeof doc->spare);
    *map = l.workers[0].map;
    for (size_t i = 0; i < total; i++) drop_job_arrays(raw, &l.jobs[i]);  /* after an error: what was not used */
    mk_arena_release(doc->arena, l.workers);
    mk_arena_release(doc->arena, l.jobs);
    return r;
}

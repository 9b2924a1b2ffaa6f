/* SPDX-License-Identifier: MIT */
#include "surface.h"
#include <stdlib.h>
#include "clock.h"
#include "frame.h"
#include "timing.h"

void bench_surface_frames(const pb_asset *nlerp_asset, const pb_asset *surface_asset, const float *weight_sets,
                          uint32_t frames, double *ns_nlerp, double *ns_surface)
{
    *ns_nlerp = *ns_surface = 0;
    const mk_asset *an = &nlerp_asset->asset, *as = &surface_asset->asset;
    double total[2] = { 0, 0 };
    for (uint32_t mi = 0; mi < an->mesh_count && mi < as->mesh_count; mi++) {
        mk_mesh_info m;
        mk_mesh_get(an, mi, &m);
        pb_surface surf;
        mk_error err;
        if (!mk_surface_topology_size(as, mi) || pb_surface_prepare(&surf, as, mi, &err) != MK_OK) continue;
        size_t scratch_size = mk_eval_scratch_size(an, mi), ss = mk_eval_scratch_size(as, mi);
        scratch_size = ss > scratch_size ? ss : scratch_size;
        void *scratch = aligned_alloc(16, (scratch_size + 31) & ~(size_t)15);
        float *positions = malloc(12 * (size_t)m.vertex_count + 16), *normals = malloc(12 * (size_t)m.vertex_count + 16);
        int ok = scratch && positions && normals;
        double mesh_total[2] = { 0, 0 };
        /* Per frame, the two alternately (which goes first alternates too), best of
         * BENCH_PASSES each: a busy second core or a slow moment hits both alike. */
        for (uint32_t f = 0; ok && f < frames; f++) {
            double best[2] = { 0, 0 };
            for (int pass = 0; ok && pass < 2 * BENCH_PASSES; pass++) {
                int surface = (pass ^ (pass >> 1)) & 1;
                mk_eval_job job = { .asset = surface ? as : an, .mesh = mi, .vertex_count = MK_VERTICES_TO_END,
                                    .weights = weight_sets + (size_t)f * an->channel_count + m.first_channel,
                                    .weight_count = m.channel_count, .scratch = scratch, .scratch_size = scratch_size,
                                    .positions = positions, .positions_size = 12 * (size_t)m.vertex_count,
                                    .normals = surface ? NULL : normals, .normals_size = 12 * (size_t)m.vertex_count };
                double t0 = bench_now_ns();
                ok = mk_eval_run(&job, &err) == MK_OK;
                if (ok && surface) ok = pb_surface_run(&surf, positions, normals, NULL, &err) == MK_OK;
                double ns = bench_now_ns() - t0;
                if (best[surface] == 0 || ns < best[surface]) best[surface] = ns;
            }
            mesh_total[0] += best[0];
            mesh_total[1] += best[1];
        }
        if (ok && frames) { total[0] += mesh_total[0] / frames; total[1] += mesh_total[1] / frames; }
        pb_surface_free(&surf);
        free(scratch);
        free(positions);
        free(normals);
    }
    *ns_nlerp = total[0];
    *ns_surface = total[1];
}

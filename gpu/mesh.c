/* SPDX-License-Identifier: MIT */
/* A mesh evaluated into fixed outputs: the windows of the blob its shader reads, its plan slots
 * and descriptor sets (made once), and the per-frame recording. */
#include <stdlib.h>
#include <string.h>
#include "format.h"
#include "internal.h"

typedef struct window {
    VkDeviceSize offset, range;     /* the bound part of a buffer */
} window;

static VkDeviceSize align_down(VkDeviceSize x, VkDeviceSize a) { return x / a * a; }
static VkDeviceSize align_up(VkDeviceSize x, VkDeviceSize a) { return (x + a - 1) / a * a; }

/* Widens [*lo, *hi) to hold the array [offset, offset + size) when it is not empty. */
static void cover(uint64_t *lo, uint64_t *hi, uint64_t offset, uint64_t size)
{
    if (!size) return;
    if (offset < *lo) *lo = offset;
    if (offset + size > *hi) *hi = offset + size;
}

/* The window of the blob holding the mesh's arrays, and each array's word offset in it. */
static mk_result data_window(const mkg_mesh *gm, const mk_blob_mesh *m, window *w, mkg_params *p, mk_error *err)
{
    const VkPhysicalDeviceLimits *lim = &gm->asset->ctx->props.limits;
    const uint64_t v = m->vertex_count;
    uint64_t lo = UINT64_MAX, hi = 0;
    cover(&lo, &hi, m->positions, 12 * v);
    if (m->flags & MK_MESH_HAS_NORMALS) cover(&lo, &hi, m->normals, 12 * v);
    if (m->flags & MK_MESH_HAS_TANGENTS) cover(&lo, &hi, m->tangents, 16 * v);
    cover(&lo, &hi, m->block_entries, 4 * ((uint64_t)m->block_count + 1));
    cover(&lo, &hi, m->entries, (uint64_t)mk_entry_stride(m->flags) * m->entry_count);
    /* The size counts the zero tail after the last entry's data (mk_asset_open checks every entry
     * leaves MK_TARGET_DATA_TAIL bytes), so the shader's two-word reads of packed values stay in
     * the window. */
    cover(&lo, &hi, m->target_data, m->target_data_size);
    /* The shader reads whole 32-bit words, and the blob's sizes need not be multiples of 4 (the
     * uploaded buffer is padded to whole words). */
    w->offset = align_down(lo, gm->asset->ctx->offset_alignment);
    w->range = align_up(hi, 4) - w->offset;
    if (w->range > lim->maxStorageBufferRange)
        return mkg_fail(err, MK_ERROR_UNSUPPORTED,
                        "mesh %u: its blob data spans %llu bytes, more than one storage buffer binding of this device "
                        "holds (maxStorageBufferRange %u)",
                        gm->mesh, (unsigned long long)w->range, lim->maxStorageBufferRange);
    const uint64_t o = w->offset;
    p->positions = (uint32_t)((m->positions - o) / 4);
    p->normals = (m->flags & MK_MESH_HAS_NORMALS) ? (uint32_t)((m->normals - o) / 4) : 0;
    p->tangents = (m->flags & MK_MESH_HAS_TANGENTS) ? (uint32_t)((m->tangents - o) / 4) : 0;
    p->block_table = (uint32_t)((m->block_entries - o) / 4);
    p->entries = m->entry_count ? (uint32_t)((m->entries - o) / 4) : 0;
    p->target_data = m->target_data_size ? (uint32_t)((m->target_data - o) / 4) : 0;
    return MK_OK;
}

/* The window of the blob holding the mesh's target records. */
static mk_result targets_window(const mkg_mesh *gm, const mk_blob_mesh *m, window *w, mkg_params *p, mk_error *err)
{
    const mk_asset *a = gm->asset->asset;
    const VkPhysicalDeviceLimits *lim = &gm->asset->ctx->props.limits;
    const uint64_t first = (uint64_t)((const uint8_t *)&a->targets[m->first_target] - a->data);
    if (!m->target_count) {   /* nothing is read: bind the header, never an empty or outside range */
        *w = (window){ 0, 16 };
        p->first_target = 0;
        return MK_OK;
    }
    w->offset = align_down(first, gm->asset->ctx->offset_alignment);
    w->range = first + 32u * (uint64_t)m->target_count - w->offset;
    if (w->range > lim->maxStorageBufferRange)
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "mesh %u: its %u target records exceed maxStorageBufferRange (%u bytes)",
                        gm->mesh, m->target_count, lim->maxStorageBufferRange);
    p->first_target = (uint32_t)((first - w->offset) / 4);
    return MK_OK;
}

/* Checks one output and makes its binding and word offset and stride. */
static mk_result output_window(const mkg_mesh *gm, const mkg_output *o, const char *name, VkDeviceSize elem,
                               uint32_t vertex_count, window *w, uint32_t *word, uint32_t *word_stride, mk_error *err)
{
    const VkPhysicalDeviceLimits *lim = &gm->asset->ctx->props.limits;
    const VkDeviceSize stride = o->stride ? o->stride : elem;
    if (o->offset % 4 || stride % 4 || stride < elem || stride > lim->maxStorageBufferRange)
        return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT,
                        "mesh %u: the %s output's offset (%llu) and stride (%llu) must be multiples of 4, the stride at "
                        "least %llu and at most maxStorageBufferRange (%u)",
                        gm->mesh, name, (unsigned long long)o->offset, (unsigned long long)stride, (unsigned long long)elem,
                        lim->maxStorageBufferRange);
    const VkDeviceSize need = stride * (vertex_count - 1u) + elem;
    if (o->size < need)
        return mkg_fail(err, MK_ERROR_BUFFER_TOO_SMALL,
                        "mesh %u: the %s output needs %llu bytes for %u vertices at stride %llu; %llu given", gm->mesh,
                        name, (unsigned long long)need, vertex_count, (unsigned long long)stride,
                        (unsigned long long)o->size);
    w->offset = align_down(o->offset, gm->asset->ctx->offset_alignment);
    w->range = o->offset - w->offset + need;
    if (w->range > lim->maxStorageBufferRange)
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "mesh %u: the %s output spans %llu bytes, more than maxStorageBufferRange (%u)",
                        gm->mesh, name, (unsigned long long)w->range, lim->maxStorageBufferRange);
    *word = (uint32_t)((o->offset - w->offset) / 4);
    *word_stride = (uint32_t)(stride / 4);
    return MK_OK;
}

static mk_result make_sets(mkg_mesh *gm, const mkg_mesh_desc *d, const window win[MKG_BINDINGS], mk_error *err)
{
    const mkg_context *ctx = gm->asset->ctx;
    VkDevice dev = ctx->dev.device;
    VkDescriptorPoolSize size = { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, MKG_BINDINGS * gm->slots };
    VkDescriptorPoolCreateInfo pi = { .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, .maxSets = gm->slots,
                                      .poolSizeCount = 1, .pPoolSizes = &size };
    VkResult r = vkCreateDescriptorPool(dev, &pi, ctx->dev.allocator, &gm->pool);
    for (uint32_t s = 0; r == VK_SUCCESS && s < gm->slots; s++) {
        VkDescriptorSetAllocateInfo ai = { .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
                                           .descriptorPool = gm->pool, .descriptorSetCount = 1,
                                           .pSetLayouts = &ctx->set_layout };
        r = vkAllocateDescriptorSets(dev, &ai, &gm->sets[s]);
        if (r != VK_SUCCESS) break;
        const VkBuffer buffers[MKG_BINDINGS] = {
            gm->asset->buffer, gm->asset->buffer, gm->plan_buffer, d->positions.buffer,
            d->normals.buffer ? d->normals.buffer : d->positions.buffer,
            d->tangents.buffer ? d->tangents.buffer : d->positions.buffer,
        };
        VkDescriptorBufferInfo info[MKG_BINDINGS];
        VkWriteDescriptorSet writes[MKG_BINDINGS];
        for (uint32_t b = 0; b < MKG_BINDINGS; b++) {
            info[b] = (VkDescriptorBufferInfo){ buffers[b], win[b].offset, win[b].range };
            if (b == 2) info[b].offset = (VkDeviceSize)s * gm->plan_stride;
            writes[b] = (VkWriteDescriptorSet){ .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = gm->sets[s],
                                                .dstBinding = b, .descriptorCount = 1,
                                                .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                .pBufferInfo = &info[b] };
        }
        vkUpdateDescriptorSets(dev, MKG_BINDINGS, writes, 0, NULL);
    }
    if (r != VK_SUCCESS)
        return mkg_fail(err, MK_ERROR_OUT_OF_MEMORY, "mesh %u: creating descriptor sets failed (%s)", gm->mesh,
                        mkg_vk_result_name(r));
    return MK_OK;
}

mk_result mkg_mesh_create(mkg_asset *asset, const mkg_mesh_desc *d, mkg_mesh **out, mk_error *err)
{
    if (!out) return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_mesh_create: out is NULL");
    *out = NULL;
    if (!asset || !d) return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_mesh_create: asset or description is NULL");
    const mk_asset *a = asset->asset;
    if (d->mesh >= a->mesh_count)
        return mkg_fail(err, MK_ERROR_OUT_OF_RANGE, "mkg_mesh_create: mesh %u does not exist (%u meshes)", d->mesh,
                        a->mesh_count);
    const mk_blob_mesh *m = &a->meshes[d->mesh];
    if (!d->positions.buffer)
        return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mesh %u: the positions output has no buffer", d->mesh);
    if (d->normals.buffer && !(m->flags & MK_MESH_HAS_NORMALS))
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "mesh %u: normals requested but the mesh has no normals", d->mesh);
    if (d->tangents.buffer && !(m->flags & MK_MESH_HAS_TANGENTS))
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "mesh %u: tangents requested but the mesh has no tangents", d->mesh);
    const mkg_context *ctx = asset->ctx;
    const VkPhysicalDeviceLimits *lim = &ctx->props.limits;
    mkg_mesh *gm = calloc(1, sizeof *gm);
    if (gm) {
        gm->slots = d->frames_in_flight ? d->frames_in_flight : 1;
        gm->sets = calloc(gm->slots, sizeof *gm->sets);
    }
    if (!gm || !gm->sets) {
        if (gm) free(gm->sets);
        free(gm);
        return mkg_fail(err, MK_ERROR_OUT_OF_MEMORY, "mkg_mesh_create: out of memory");
    }
    gm->asset = asset;
    gm->mesh = d->mesh;
    gm->plan_size = mk_gpu_plan_size(a, d->mesh);
    gm->plan_stride = align_up(gm->plan_size ? gm->plan_size : 16, ctx->offset_alignment);
    mkg_params *p = &gm->params;
    p->vertex_count = m->vertex_count;
    p->target_count = m->target_count;
    p->block_count = m->block_count;
    p->entry_words = mk_entry_stride(m->flags) / 4;   /* 24, 32 or 40 bytes */
    p->components = mk_mesh_components(m->flags);
    p->mesh_flags = m->flags;
    window win[MKG_BINDINGS];
    mk_result res = data_window(gm, m, &win[0], p, err);
    if (res == MK_OK) res = targets_window(gm, m, &win[1], p, err);
    win[2] = (window){ 0, gm->plan_stride };
    if (res == MK_OK)
        res = output_window(gm, &d->positions, "positions", 12, m->vertex_count, &win[3], &p->out_p, &p->out_p_stride, err);
    win[4] = win[3];
    win[5] = win[3];
    if (res == MK_OK && d->normals.buffer) {
        p->flags |= MKG_WANT_NORMALS;
        res = output_window(gm, &d->normals, "normals", 12, m->vertex_count, &win[4], &p->out_n, &p->out_n_stride, err);
    }
    if (res == MK_OK && d->tangents.buffer) {
        p->flags |= MKG_WANT_TANGENTS;
        res = output_window(gm, &d->tangents, "tangents", 16, m->vertex_count, &win[5], &p->out_t, &p->out_t_stride, err);
    }
    /* One workgroup per block, in rows of at most the device's x limit. */
    const uint32_t max_x = lim->maxComputeWorkGroupCount[0];
    p->groups_x = m->block_count < max_x ? m->block_count : max_x;
    gm->groups_y = (m->block_count + p->groups_x - 1) / p->groups_x;
    if (res == MK_OK && gm->groups_y > lim->maxComputeWorkGroupCount[1])
        res = mkg_fail(err, MK_ERROR_UNSUPPORTED, "mesh %u: %u blocks need more workgroups than this device dispatches",
                       d->mesh, m->block_count);
    if (res == MK_OK) {
        void *mapped = NULL;
        VkResult r = mkg_buffer_create(ctx, gm->plan_stride * gm->slots, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                       &gm->plan_buffer, &gm->plan_memory, &mapped);
        gm->plan_mapped = mapped;
        if (r != VK_SUCCESS)
            res = mkg_fail(err, MK_ERROR_OUT_OF_MEMORY, "mesh %u: creating the plan buffer failed (%s)", d->mesh,
                           mkg_vk_result_name(r));
        else memset(mapped, 0, (size_t)(gm->plan_stride * gm->slots));
    }
    if (res == MK_OK) res = make_sets(gm, d, win, err);
    if (res != MK_OK) {
        mkg_mesh_destroy(gm);
        return res;
    }
    *out = gm;
    return MK_OK;
}

void mkg_mesh_destroy(mkg_mesh *gm)
{
    if (!gm) return;
    const mkg_context *ctx = gm->asset->ctx;
    if (gm->pool) vkDestroyDescriptorPool(ctx->dev.device, gm->pool, ctx->dev.allocator);   /* frees the sets */
    mkg_buffer_destroy(ctx, gm->plan_buffer, gm->plan_memory);
    free(gm->sets);
    free(gm);
}

mk_result mkg_mesh_record(mkg_mesh *gm, VkCommandBuffer cmd, const mkg_frame *f, mk_error *err)
{
    if (!gm || !cmd || !f) return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_mesh_record: mesh, command buffer or frame is NULL");
    if (f->slot >= gm->slots)
        return mkg_fail(err, MK_ERROR_OUT_OF_RANGE, "mkg_mesh_record: slot %u, but the mesh has %u frames in flight",
                        f->slot, gm->slots);
    const mkg_context *ctx = gm->asset->ctx;
    mk_gpu_plan_job job = {
        .asset = gm->asset->asset, .mesh = gm->mesh, .weights = f->weights, .weight_count = f->weight_count,
        .stacking = f->stacking, .normal_mode = f->normal_mode,
        .plan = gm->plan_mapped + (size_t)f->slot * gm->plan_stride, .plan_size = gm->plan_size,
    };
    mk_result r = mk_gpu_plan_run(&job, err);
    if (r != MK_OK) return r;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx->pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx->pipeline_layout, 0, 1, &gm->sets[f->slot], 0, NULL);
    vkCmdPushConstants(cmd, ctx->pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof gm->params, &gm->params);
    vkCmdDispatch(cmd, gm->params.groups_x, gm->groups_y, 1);
    return MK_OK;
}

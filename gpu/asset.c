/* SPDX-License-Identifier: MIT */
/* A blob uploaded once into a device-local storage buffer, unchanged. */
#include <stdlib.h>
#include <string.h>
#include "internal.h"

/* One-shot copy of size bytes from a staging buffer into dst on queue, waited for. */
static VkResult copy_and_wait(const mkg_context *ctx, VkQueue queue, uint32_t family, VkBuffer src, VkBuffer dst,
                              VkDeviceSize size)
{
    VkDevice dev = ctx->dev.device;
    const VkAllocationCallbacks *ac = ctx->dev.allocator;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkCommandPoolCreateInfo pi = { .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                   .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT, .queueFamilyIndex = family };
    VkResult r = vkCreateCommandPool(dev, &pi, ac, &pool);
    if (r == VK_SUCCESS) {
        VkCommandBufferAllocateInfo ai = { .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, .commandPool = pool,
                                           .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1 };
        r = vkAllocateCommandBuffers(dev, &ai, &cmd);
    }
    if (r == VK_SUCCESS) {
        VkFenceCreateInfo fi = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
        r = vkCreateFence(dev, &fi, ac, &fence);
    }
    if (r == VK_SUCCESS) {
        VkCommandBufferBeginInfo bi = { .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT };
        r = vkBeginCommandBuffer(cmd, &bi);
    }
    if (r == VK_SUCCESS) {
        VkBufferCopy region = { 0, 0, size };
        vkCmdCopyBuffer(cmd, src, dst, 1, &region);
        /* The copy's writes are made available to the compute shaders that read the blob. */
        VkMemoryBarrier b = { .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER, .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
                              .dstAccessMask = VK_ACCESS_SHADER_READ_BIT };
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &b, 0, NULL,
                             0, NULL);
        r = vkEndCommandBuffer(cmd);
    }
    if (r == VK_SUCCESS) {
        VkSubmitInfo si = { .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &cmd };
        r = vkQueueSubmit(queue, 1, &si, fence);
    }
    if (r == VK_SUCCESS) r = vkWaitForFences(dev, 1, &fence, VK_TRUE, UINT64_MAX);
    if (fence) vkDestroyFence(dev, fence, ac);
    if (pool) vkDestroyCommandPool(dev, pool, ac);   /* frees cmd */
    return r;
}

mk_result mkg_asset_upload(mkg_context *ctx, const mk_asset *asset, VkQueue queue, uint32_t queue_family,
                           mkg_asset **out, mk_error *err)
{
    if (!out) return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_asset_upload: out is NULL");
    *out = NULL;
    if (!ctx || !asset || !asset->data || !queue)
        return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_asset_upload: context, opened asset or queue missing");
    mkg_asset *a = calloc(1, sizeof *a);
    if (!a) return mkg_fail(err, MK_ERROR_OUT_OF_MEMORY, "mkg_asset_upload: out of memory");
    a->ctx = ctx;
    a->asset = asset;
    const VkDeviceSize size = (asset->size + 3u) & ~(VkDeviceSize)3u;   /* whole words for the shader */
    VkBuffer staging = VK_NULL_HANDLE;
    VkDeviceMemory staging_memory = VK_NULL_HANDLE;
    VkResult r = mkg_buffer_create(ctx, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                   VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &a->buffer, &a->memory, NULL);
    const char *step = "creating the blob's buffer";
    void *mapped = NULL;
    if (r == VK_SUCCESS) {
        step = "creating the staging buffer";
        r = mkg_buffer_create(ctx, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                              VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, &staging,
                              &staging_memory, &mapped);
    }
    if (r == VK_SUCCESS) {
        memcpy(mapped, asset->data, asset->size);
        memset((uint8_t *)mapped + asset->size, 0, (size_t)(size - asset->size));
        step = "copying the blob to the GPU";
        r = copy_and_wait(ctx, queue, queue_family, staging, a->buffer, size);
    }
    mkg_buffer_destroy(ctx, staging, staging_memory);
    if (r != VK_SUCCESS) {
        mkg_asset_destroy(a);
        return mkg_fail(err,
                        r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY ? MK_ERROR_OUT_OF_MEMORY
                                                                                              : MK_ERROR_UNSUPPORTED,
                        "mkg_asset_upload: %s (%llu bytes) failed: %s", step, (unsigned long long)size,
                        mkg_vk_result_name(r));
    }
    *out = a;
    return MK_OK;
}

void mkg_asset_destroy(mkg_asset *a)
{
    if (!a) return;
    mkg_buffer_destroy(a->ctx, a->buffer, a->memory);
    free(a);
}

VkBuffer mkg_asset_buffer(const mkg_asset *a) { return a ? a->buffer : VK_NULL_HANDLE; }

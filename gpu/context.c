/* SPDX-License-Identifier: MIT */
/* The compute pipeline, errors and buffers of the GPU library. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include "internal.h"

/* The shader's SPIR-V, compiled by glslc at build time (gpu/meson.build). */
static const uint32_t morph_eval_spv[] =
#include "morph_eval.spv.inc"
;

/* offline's mk_error_set does the same, but this library is for engines and links only the
 * runtime and libvulkan, not the offline core. */
mk_result mkg_fail(mk_error *err, mk_result code, const char *format, ...)
{
    if (!err) return code;
    err->code = code;
    err->offset = UINT64_MAX;
    va_list ap;
    va_start(ap, format);
    vsnprintf(err->message, sizeof err->message, format, ap);
    va_end(ap);
    return code;
}

const char *mkg_vk_result_name(VkResult r)
{
    switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_NOT_READY: return "VK_NOT_READY";
    default: return "a Vulkan error";
    }
}

static int memory_type(const mkg_context *ctx, uint32_t type_bits, VkMemoryPropertyFlags properties)
{
    for (uint32_t i = 0; i < ctx->memory.memoryTypeCount; i++)
        if ((type_bits & (1u << i)) && (ctx->memory.memoryTypes[i].propertyFlags & properties) == properties)
            return (int)i;
    return -1;
}

VkResult mkg_buffer_create(const mkg_context *ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                           VkMemoryPropertyFlags properties, VkBuffer *buffer, VkDeviceMemory *memory, void **mapped)
{
    VkDevice dev = ctx->dev.device;
    const VkAllocationCallbacks *ac = ctx->dev.allocator;
    *buffer = VK_NULL_HANDLE;
    *memory = VK_NULL_HANDLE;
    VkBufferCreateInfo bi = { .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, .size = size, .usage = usage,
                              .sharingMode = VK_SHARING_MODE_EXCLUSIVE };
    VkResult r = vkCreateBuffer(dev, &bi, ac, buffer);
    if (r != VK_SUCCESS) return r;
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(dev, *buffer, &req);
    int type = memory_type(ctx, req.memoryTypeBits, properties);
    if (type < 0) {   /* no memory type with these properties for this buffer */
        mkg_buffer_destroy(ctx, *buffer, VK_NULL_HANDLE);
        *buffer = VK_NULL_HANDLE;
        return VK_ERROR_FEATURE_NOT_PRESENT;
    }
    VkMemoryAllocateInfo ai = { .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .allocationSize = req.size,
                                .memoryTypeIndex = (uint32_t)type };
    r = vkAllocateMemory(dev, &ai, ac, memory);
    if (r == VK_SUCCESS) r = vkBindBufferMemory(dev, *buffer, *memory, 0);
    if (r == VK_SUCCESS && mapped) r = vkMapMemory(dev, *memory, 0, VK_WHOLE_SIZE, 0, mapped);
    if (r != VK_SUCCESS) {
        mkg_buffer_destroy(ctx, *buffer, *memory);
        *buffer = VK_NULL_HANDLE;
        *memory = VK_NULL_HANDLE;
    }
    return r;
}

void mkg_buffer_destroy(const mkg_context *ctx, VkBuffer buffer, VkDeviceMemory memory)
{
    if (buffer) vkDestroyBuffer(ctx->dev.device, buffer, ctx->dev.allocator);
    if (memory) vkFreeMemory(ctx->dev.device, memory, ctx->dev.allocator);
}

mk_result mkg_context_create(const mkg_device *device, mkg_context **out, mk_error *err)
{
    if (!out) return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_context_create: out is NULL");
    *out = NULL;
    if (!device || !device->physical_device || !device->device)
        return mkg_fail(err, MK_ERROR_INVALID_ARGUMENT, "mkg_context_create: no physical device or device given");
    mkg_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx) return mkg_fail(err, MK_ERROR_OUT_OF_MEMORY, "mkg_context_create: out of memory");
    ctx->dev = *device;
    vkGetPhysicalDeviceProperties(device->physical_device, &ctx->props);
    vkGetPhysicalDeviceMemoryProperties(device->physical_device, &ctx->memory);
    if (ctx->props.apiVersion < VK_API_VERSION_1_1) {
        mkg_fail(err, MK_ERROR_UNSUPPORTED, "the GPU path needs Vulkan 1.1; %s offers %u.%u", ctx->props.deviceName,
                 VK_API_VERSION_MAJOR(ctx->props.apiVersion), VK_API_VERSION_MINOR(ctx->props.apiVersion));
        free(ctx);
        return MK_ERROR_UNSUPPORTED;
    }
    if (ctx->props.limits.maxPerStageDescriptorStorageBuffers < MKG_BINDINGS) {
        mkg_fail(err, MK_ERROR_UNSUPPORTED, "the GPU path binds %u storage buffers; %s allows %u per stage", MKG_BINDINGS,
                 ctx->props.deviceName, ctx->props.limits.maxPerStageDescriptorStorageBuffers);
        free(ctx);
        return MK_ERROR_UNSUPPORTED;
    }
    ctx->offset_alignment = ctx->props.limits.minStorageBufferOffsetAlignment;
    const VkDeviceSize coarser = device->offset_alignment;
    if (coarser > ctx->offset_alignment && coarser <= 65536 && (coarser & (coarser - 1)) == 0)
        ctx->offset_alignment = coarser;
    VkDevice dev = device->device;
    const VkAllocationCallbacks *ac = device->allocator;
    VkDescriptorSetLayoutBinding bindings[MKG_BINDINGS];
    for (uint32_t i = 0; i < MKG_BINDINGS; i++)
        bindings[i] = (VkDescriptorSetLayoutBinding){ .binding = i, .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                      .descriptorCount = 1, .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT };
    VkDescriptorSetLayoutCreateInfo li = { .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                           .bindingCount = MKG_BINDINGS, .pBindings = bindings };
    VkPushConstantRange push = { .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT, .offset = 0, .size = sizeof(mkg_params) };
    VkShaderModuleCreateInfo si = { .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                    .codeSize = sizeof morph_eval_spv, .pCode = morph_eval_spv };
    VkResult r = vkCreateDescriptorSetLayout(dev, &li, ac, &ctx->set_layout);
    if (r == VK_SUCCESS) {
        VkPipelineLayoutCreateInfo pi = { .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 1,
                                          .pSetLayouts = &ctx->set_layout, .pushConstantRangeCount = 1,
                                          .pPushConstantRanges = &push };
        r = vkCreatePipelineLayout(dev, &pi, ac, &ctx->pipeline_layout);
    }
    if (r == VK_SUCCESS) r = vkCreateShaderModule(dev, &si, ac, &ctx->shader);
    if (r == VK_SUCCESS) {
        VkComputePipelineCreateInfo ci = {
            .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
            .stage = { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                       .module = ctx->shader, .pName = "main" },
            .layout = ctx->pipeline_layout,
        };
        r = vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, ac, &ctx->pipeline);
    }
    if (r != VK_SUCCESS) {
        mkg_context_destroy(ctx);
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "mkg_context_create: creating the compute pipeline failed (%s)",
                        mkg_vk_result_name(r));
    }
    *out = ctx;
    return MK_OK;
}

void mkg_context_destroy(mkg_context *ctx)
{
    if (!ctx) return;
    VkDevice dev = ctx->dev.device;
    const VkAllocationCallbacks *ac = ctx->dev.allocator;
    if (ctx->pipeline) vkDestroyPipeline(dev, ctx->pipeline, ac);
    if (ctx->shader) vkDestroyShaderModule(dev, ctx->shader, ac);
    if (ctx->pipeline_layout) vkDestroyPipelineLayout(dev, ctx->pipeline_layout, ac);
    if (ctx->set_layout) vkDestroyDescriptorSetLayout(dev, ctx->set_layout, ac);
    free(ctx);
}

void mkg_cmd_output_acquire(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access)
{
    /* The earlier uses (reads or writes at src_stage) and the last evaluation's writes happen before
     * this evaluation writes. */
    VkMemoryBarrier b = { .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER, .srcAccessMask = src_access | VK_ACCESS_SHADER_WRITE_BIT,
                          .dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT };
    vkCmdPipelineBarrier(cmd, src_stage | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                         &b, 0, NULL, 0, NULL);
}

void mkg_cmd_output_barrier(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access)
{
    VkMemoryBarrier b = { .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER, .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT,
                          .dstAccessMask = dst_access };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, dst_stage, 0, 1, &b, 0, NULL, 0, NULL);
}

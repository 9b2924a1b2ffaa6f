/* SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "harness.h"
#include "internal.h"

static const char *const validation_layer = "VK_LAYER_KHRONOS_validation";

static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT type,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)type;
    mkg_harness *h = user;
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
        h->validation_messages++;
        fprintf(stderr, "vulkan validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

static int has_layer(const char *name)
{
    uint32_t n = 0;
    if (vkEnumerateInstanceLayerProperties(&n, NULL) != VK_SUCCESS || !n) return 0;
    VkLayerProperties *layers = calloc(n, sizeof *layers);
    int found = 0;
    if (layers && vkEnumerateInstanceLayerProperties(&n, layers) == VK_SUCCESS)
        for (uint32_t i = 0; i < n && !found; i++) found = strcmp(layers[i].layerName, name) == 0;
    free(layers);
    return found;
}

static int device_rank(VkPhysicalDeviceType t)
{
    return t == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ? 0 : t == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 1
         : t == VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU ? 2 : t == VK_PHYSICAL_DEVICE_TYPE_CPU ? 3 : 4;
}

/* The best-ranked device with a compute queue and Vulkan 1.1, and that queue's family. */
static int pick_device(mkg_harness *h)
{
    uint32_t n = 0;
    if (vkEnumeratePhysicalDevices(h->instance, &n, NULL) != VK_SUCCESS || !n) return 0;
    VkPhysicalDevice *devs = calloc(n, sizeof *devs);
    if (!devs || vkEnumeratePhysicalDevices(h->instance, &n, devs) != VK_SUCCESS) { free(devs); return 0; }
    int best = 5;
    for (uint32_t i = 0; i < n; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devs[i], &p);
        if (p.apiVersion < VK_API_VERSION_1_1 || device_rank(p.deviceType) >= best) continue;
        uint32_t qn = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(devs[i], &qn, NULL);
        VkQueueFamilyProperties q[16];
        if (qn > 16) qn = 16;
        vkGetPhysicalDeviceQueueFamilyProperties(devs[i], &qn, q);
        for (uint32_t f = 0; f < qn; f++)
            if (q[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
                best = device_rank(p.deviceType);
                h->physical = devs[i];
                h->family = f;
                h->props = p;
                h->timestamps = q[f].timestampValidBits != 0;
                h->timestamp_bits = q[f].timestampValidBits;
                break;
            }
    }
    free(devs);
    return h->physical != VK_NULL_HANDLE;
}

mk_result mkg_harness_open(mkg_harness *h, unsigned flags, mk_error *err)
{
    memset(h, 0, sizeof *h);
    const int want = (flags & (MKG_HARNESS_VALIDATION | MKG_HARNESS_REQUIRE_VALIDATION)) != 0;
    h->validation = want && has_layer(validation_layer);
    if ((flags & MKG_HARNESS_REQUIRE_VALIDATION) && !h->validation)
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "the Vulkan validation layer (%s) is not installed", validation_layer);
    VkApplicationInfo app = { .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .pApplicationName = "morphkit",
                              .apiVersion = VK_API_VERSION_1_1 };
    const char *ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkDebugUtilsMessengerCreateInfoEXT mi = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
        .pfnUserCallback = on_message, .pUserData = h,
    };
    VkInstanceCreateInfo ii = { .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, .pApplicationInfo = &app,
                                .pNext = h->validation ? &mi : NULL,
                                .enabledLayerCount = h->validation ? 1u : 0u, .ppEnabledLayerNames = &validation_layer,
                                .enabledExtensionCount = h->validation ? 1u : 0u, .ppEnabledExtensionNames = &ext };
    VkResult r = vkCreateInstance(&ii, NULL, &h->instance);
    if (r != VK_SUCCESS) {
        h->instance = VK_NULL_HANDLE;
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "no Vulkan instance (%s): is a Vulkan driver installed?",
                        mkg_vk_result_name(r));
    }
    if (h->validation) {
        PFN_vkCreateDebugUtilsMessengerEXT create =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(h->instance, "vkCreateDebugUtilsMessengerEXT");
        if (create) create(h->instance, &mi, NULL, &h->messenger);
    }
    if (!pick_device(h)) {
        mkg_harness_close(h);
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "no Vulkan 1.1 device with a compute queue");
    }
    VkPhysicalDeviceFeatures have, on = { 0 };
    vkGetPhysicalDeviceFeatures(h->physical, &have);
    h->robust = (flags & MKG_HARNESS_ROBUST) && have.robustBufferAccess;
    on.robustBufferAccess = h->robust ? VK_TRUE : VK_FALSE;
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qi = { .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, .queueFamilyIndex = h->family,
                                   .queueCount = 1, .pQueuePriorities = &priority };
    VkDeviceCreateInfo di = { .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .queueCreateInfoCount = 1,
                              .pQueueCreateInfos = &qi, .pEnabledFeatures = &on };
    r = vkCreateDevice(h->physical, &di, NULL, &h->device);
    if (r != VK_SUCCESS) {
        h->device = VK_NULL_HANDLE;
        mkg_harness_close(h);
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "creating a Vulkan device failed (%s)", mkg_vk_result_name(r));
    }
    vkGetDeviceQueue(h->device, h->family, 0, &h->queue);
    VkCommandPoolCreateInfo pi = { .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                   .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, .queueFamilyIndex = h->family };
    r = vkCreateCommandPool(h->device, &pi, NULL, &h->pool);
    if (r == VK_SUCCESS) {
        VkCommandBufferAllocateInfo ai = { .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, .commandPool = h->pool,
                                           .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1 };
        r = vkAllocateCommandBuffers(h->device, &ai, &h->cmd);
    }
    if (r == VK_SUCCESS) {
        VkFenceCreateInfo fi = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
        r = vkCreateFence(h->device, &fi, NULL, &h->fence);
    }
    if (r != VK_SUCCESS) {
        mkg_harness_close(h);
        return mkg_fail(err, MK_ERROR_UNSUPPORTED, "creating a command buffer failed (%s)", mkg_vk_result_name(r));
    }
    /* MORPHKIT_GPU_OFFSET_ALIGNMENT=N: bindings cut as a device asking for N-byte offsets would (the
     * tests use 256 where lavapipe asks for 16, so windows do not all start at their arrays). */
    const char *coarser = getenv("MORPHKIT_GPU_OFFSET_ALIGNMENT");
    mkg_device dev = { h->physical, h->device, NULL, coarser ? strtoull(coarser, NULL, 10) : 0 };
    mk_result res = mkg_context_create(&dev, &h->ctx, err);
    if (res != MK_OK) mkg_harness_close(h);
    return res;
}

void mkg_harness_close(mkg_harness *h)
{
    if (h->device) vkDeviceWaitIdle(h->device);
    mkg_context_destroy(h->ctx);
    if (h->fence) vkDestroyFence(h->device, h->fence, NULL);
    if (h->pool) vkDestroyCommandPool(h->device, h->pool, NULL);
    if (h->device) vkDestroyDevice(h->device, NULL);
    if (h->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(h->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy) destroy(h->instance, h->messenger, NULL);
    }
    if (h->instance) vkDestroyInstance(h->instance, NULL);
    unsigned messages = h->validation_messages;
    int validation = h->validation;
    memset(h, 0, sizeof *h);
    h->validation_messages = messages;   /* still readable after closing */
    h->validation = validation;
}

mk_result mkg_harness_begin(mkg_harness *h, mk_error *err)
{
    VkCommandBufferBeginInfo bi = { .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                    .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT };
    VkResult r = vkResetCommandBuffer(h->cmd, 0);
    if (r == VK_SUCCESS) r = vkBeginCommandBuffer(h->cmd, &bi);
    return r == VK_SUCCESS ? MK_OK : mkg_fail(err, MK_ERROR_UNSUPPORTED, "vkBeginCommandBuffer failed (%s)", mkg_vk_result_name(r));
}

mk_result mkg_harness_submit(mkg_harness *h, mk_error *err)
{
    VkResult r = vkEndCommandBuffer(h->cmd);
    VkSubmitInfo si = { .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &h->cmd };
    if (r == VK_SUCCESS) r = vkResetFences(h->device, 1, &h->fence);
    if (r == VK_SUCCESS) r = vkQueueSubmit(h->queue, 1, &si, h->fence);
    if (r == VK_SUCCESS) r = vkWaitForFences(h->device, 1, &h->fence, VK_TRUE, UINT64_MAX);
    return r == VK_SUCCESS ? MK_OK : mkg_fail(err, MK_ERROR_UNSUPPORTED, "submitting to the GPU failed (%s)", mkg_vk_result_name(r));
}

static mk_result buffer_create(mkg_harness *h, VkDeviceSize size, int host, mkg_host_buffer *b, mk_error *err)
{
    memset(b, 0, sizeof *b);
    b->size = size ? size : 16;
    VkResult r = mkg_buffer_create(h->ctx, b->size,
                                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                   host ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                        : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                   &b->buffer, &b->memory, host ? &b->mapped : NULL);
    if (r != VK_SUCCESS) {
        mkg_host_buffer_destroy(h, b);
        return mkg_fail(err, MK_ERROR_OUT_OF_MEMORY, "a %s buffer of %llu bytes failed (%s)",
                        host ? "host-visible" : "device-local", (unsigned long long)size, mkg_vk_result_name(r));
    }
    return MK_OK;
}

mk_result mkg_host_buffer_create(mkg_harness *h, VkDeviceSize size, mkg_host_buffer *b, mk_error *err)
{
    return buffer_create(h, size, 1, b, err);
}

mk_result mkg_device_buffer_create(mkg_harness *h, VkDeviceSize size, mkg_host_buffer *b, mk_error *err)
{
    return buffer_create(h, size, 0, b, err);
}

void mkg_host_buffer_destroy(mkg_harness *h, mkg_host_buffer *b)
{
    mkg_buffer_destroy(h->ctx, b->buffer, b->memory);
    memset(b, 0, sizeof *b);
}

mk_result mkg_harness_eval(mkg_harness *h, mkg_asset *asset, uint32_t mesh, const float *weights, uint32_t weight_count,
                           mk_stacking stacking, mk_normal_mode normal_mode, float *positions, float *normals,
                           float *tangents, mk_error *err)
{
    mk_mesh_info mi;
    if (!mk_mesh_get(asset->asset, mesh, &mi))
        return mkg_fail(err, MK_ERROR_OUT_OF_RANGE, "mesh %u does not exist", mesh);
    const VkDeviceSize v = mi.vertex_count;
    /* Planar outputs in one buffer: positions, normals, tangents. */
    const VkDeviceSize pos_bytes = 12 * v, nrm_bytes = normals ? 12 * v : 0, tan_bytes = tangents ? 16 * v : 0;
    mkg_host_buffer out;
    mk_result r = mkg_host_buffer_create(h, pos_bytes + nrm_bytes + tan_bytes, &out, err);
    if (r != MK_OK) return r;
    mkg_mesh_desc d = {
        .mesh = mesh, .frames_in_flight = 1,
        .positions = { out.buffer, 0, 12, pos_bytes },
        .normals = { normals ? out.buffer : VK_NULL_HANDLE, pos_bytes, 12, nrm_bytes },
        .tangents = { tangents ? out.buffer : VK_NULL_HANDLE, pos_bytes + nrm_bytes, 16, tan_bytes },
    };
    mkg_mesh *gm = NULL;
    r = mkg_mesh_create(asset, &d, &gm, err);
    if (r == MK_OK) r = mkg_harness_begin(h, err);
    if (r == MK_OK) {
        mkg_frame f = { .weights = weights, .weight_count = weight_count, .stacking = stacking,
                        .normal_mode = normal_mode, .slot = 0 };
        r = mkg_mesh_record(gm, h->cmd, &f, err);
        mkg_cmd_output_barrier(h->cmd, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        mk_error ignored;
        mk_result submitted = mkg_harness_submit(h, r == MK_OK ? err : &ignored);   /* ends the command buffer either way */
        if (r == MK_OK) r = submitted;
    }
    if (r == MK_OK) {
        const uint8_t *p = out.mapped;
        memcpy(positions, p, (size_t)pos_bytes);
        if (normals) memcpy(normals, p + pos_bytes, (size_t)nrm_bytes);
        if (tangents) memcpy(tangents, p + pos_bytes + nrm_bytes, (size_t)tan_bytes);
    }
    mkg_mesh_destroy(gm);
    mkg_host_buffer_destroy(h, &out);
    return r;
}

/* SPDX-License-Identifier: MIT */
/* A headless Vulkan device standing in for an engine's, for the morphkit command, the samples
 * and the tests (not installed): instance, the first device with a compute queue (discrete
 * before integrated before CPU), one queue, one command buffer, optional validation layers
 * whose messages are counted, and a whole-mesh evaluation read back to host memory. */
#ifndef MKG_HARNESS_H
#define MKG_HARNESS_H

#include "morphkit_gpu.h"

typedef struct mkg_harness {
    VkInstance instance;
    VkPhysicalDevice physical;
    VkDevice device;
    VkQueue queue;
    uint32_t family;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    VkFence fence;
    VkDebugUtilsMessengerEXT messenger;
    mkg_context *ctx;
    VkPhysicalDeviceProperties props;
    int validation;                     /* the validation layer is on */
    int robust;                         /* robustBufferAccess is on */
    int timestamps;                     /* the queue has timestamps */
    uint32_t timestamp_bits;            /* their valid bits */
    unsigned validation_messages;       /* warnings and errors the layer reported; still set after
                                         * mkg_harness_close, which counts those at destruction
                                         * (objects left alive) too */
} mkg_harness;

enum {
    MKG_HARNESS_VALIDATION = 1,         /* the validation layer, when present */
    MKG_HARNESS_REQUIRE_VALIDATION = 2, /* fail when the validation layer is missing */
    MKG_HARNESS_ROBUST = 4              /* robust buffer access, when the device has it (it hides
                                         * out-of-bounds writes from the tests: they are dropped) */
};

/* Opens the device; MK_ERROR_UNSUPPORTED when Vulkan has no device with a compute queue. */
mk_result mkg_harness_open(mkg_harness *h, unsigned flags, mk_error *err);
void mkg_harness_close(mkg_harness *h);

/* Begins recording h->cmd (reset first). */
mk_result mkg_harness_begin(mkg_harness *h, mk_error *err);
/* Ends h->cmd, submits it and waits. */
mk_result mkg_harness_submit(mkg_harness *h, mk_error *err);

/* Evaluates a whole mesh on the GPU for mesh-local weights and copies the outputs back:
 * positions (3 floats per vertex, required), normals (3, optional), tangents (4, optional). */
mk_result mkg_harness_eval(mkg_harness *h, mkg_asset *asset, uint32_t mesh, const float *weights, uint32_t weight_count,
                           mk_stacking stacking, mk_normal_mode normal_mode, float *positions, float *normals,
                           float *tangents, mk_error *err);

/* A host-visible, coherent, mapped buffer (storage and transfer) for outputs and readback. */
typedef struct mkg_host_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *mapped;
    VkDeviceSize size;
} mkg_host_buffer;
mk_result mkg_host_buffer_create(mkg_harness *h, VkDeviceSize size, mkg_host_buffer *b, mk_error *err);
/* The same in device-local memory, not mapped (mapped stays NULL): outputs and copies to time. */
mk_result mkg_device_buffer_create(mkg_harness *h, VkDeviceSize size, mkg_host_buffer *b, mk_error *err);
void mkg_host_buffer_destroy(mkg_harness *h, mkg_host_buffer *b);

#endif

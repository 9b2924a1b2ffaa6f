/* SPDX-License-Identifier: MIT */
/* The GPU library's private parts: the objects behind the public handles, errors and memory. */
#ifndef MKG_INTERNAL_H
#define MKG_INTERNAL_H

#include "morphkit_gpu.h"

struct mkg_context {
    mkg_device dev;
    VkPhysicalDeviceProperties props;
    VkDeviceSize offset_alignment;   /* of storage-buffer bindings: the device's minimum or mkg_device's */
    VkPhysicalDeviceMemoryProperties memory;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout pipeline_layout;
    VkShaderModule shader;
    VkPipeline pipeline;
};

struct mkg_asset {
    mkg_context *ctx;
    const mk_asset *asset;
    VkBuffer buffer;
    VkDeviceMemory memory;
};

/* The shader's push constants (gpu/shaders/morph_eval.comp, Params), in 32-bit words. */
typedef struct mkg_params {
    uint32_t positions, normals, tangents, block_table, entries, target_data, first_target;
    uint32_t vertex_count, target_count, block_count, flags, groups_x;
    uint32_t out_p, out_p_stride, out_n, out_n_stride, out_t, out_t_stride;
    uint32_t entry_words, components, mesh_flags;   /* the mesh's entry layout (format.h) */
} mkg_params;

enum { MKG_WANT_NORMALS = 1u, MKG_WANT_TANGENTS = 2u };
enum { MKG_BINDINGS = 6 };

struct mkg_mesh {
    mkg_asset *asset;
    uint32_t mesh, slots;
    VkDeviceSize plan_stride;       /* bytes between slots, aligned for storage-buffer offsets */
    size_t plan_size;               /* mk_gpu_plan_size */
    VkBuffer plan_buffer;
    VkDeviceMemory plan_memory;
    uint8_t *plan_mapped;
    VkDescriptorPool pool;
    VkDescriptorSet *sets;          /* one per slot */
    mkg_params params;
    uint32_t groups_y;              /* rows of params.groups_x workgroups */
};

/* Fills err (optional) with code and a printf-style message; returns code. */
mk_result mkg_fail(mk_error *err, mk_result code, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* The failing Vulkan call's result as text. */
const char *mkg_vk_result_name(VkResult r);

/* A buffer with memory of the given properties bound to it, and mapped whole into *mapped when
 * mapped is not NULL (host-visible properties); VK_SUCCESS or the failing call's result.
 * mkg_buffer_destroy frees the memory, which unmaps it. */
VkResult mkg_buffer_create(const mkg_context *ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                           VkMemoryPropertyFlags properties, VkBuffer *buffer, VkDeviceMemory *memory, void **mapped);
void mkg_buffer_destroy(const mkg_context *ctx, VkBuffer buffer, VkDeviceMemory memory);

#endif

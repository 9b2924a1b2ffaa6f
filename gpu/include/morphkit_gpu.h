/* SPDX-License-Identifier: MIT */
/* morphkit on the GPU (Vulkan 1.1 compute): the same .morph blob and the same evaluation as the
 * CPU runtime (docs/gpu.md).
 *
 * The engine owns the instance, device, queues and command buffers. This library creates one
 * compute pipeline (SPIR-V built into it), uploads a blob once into a device-local storage
 * buffer, and records a mesh's evaluation into the engine's command buffer: per frame it writes
 * the frame's plan (mk_gpu_plan_run: a few bytes per target) into host-visible memory and
 * records one dispatch. Nothing is allocated per frame.
 *
 *   mkg_context *ctx;   mkg_context_create(&(mkg_device){ phys, dev, NULL }, &ctx, &err);
 *   mkg_asset *ga;      mkg_asset_upload(ctx, &asset, queue, family, &ga, &err);
 *   mkg_mesh *gm;       mkg_mesh_create(ga, &(mkg_mesh_desc){ .mesh = 0, .frames_in_flight = 2,
 *                           .positions = { vbuf, 0, 32, size } }, &gm, &err);
 *   per frame:          mkg_cmd_output_acquire(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
 *                           VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);   (last frame's draws are done with vbuf)
 *                       mkg_mesh_record(gm, cmd, &(mkg_frame){ .weights = w, .weight_count = n,
 *                           .slot = frame % 2 }, &err);
 *                       mkg_cmd_output_barrier(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
 *                           VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);   (this frame's draws see the results)
 *
 * Requirements: the instance was created with apiVersion 1.1 or later (the shader is SPIR-V 1.3)
 * and the device allows 6 storage buffers per stage. The blob is uploaded on, and frames are
 * recorded for, queues of one family (the buffer is not shared between families).
 *
 * State: mkg_mesh_record binds its compute pipeline, descriptor set 0 and push constants on the
 * command buffer; rebind your own compute state after it.
 *
 * Lifetime: destroy meshes, then assets, then the context, each once the GPU has finished every
 * command buffer that uses it (the library does not wait).
 *
 * Thread safety: objects are not locked; record one mkg_mesh from one thread at a time. */
#ifndef MORPHKIT_GPU_H
#define MORPHKIT_GPU_H

#include <vulkan/vulkan.h>
#include "morphkit.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mkg_context mkg_context;
typedef struct mkg_asset mkg_asset;
typedef struct mkg_mesh mkg_mesh;

/* The engine's device. The library uses the Vulkan functions it links against (libvulkan). */
typedef struct mkg_device {
    VkPhysicalDevice physical_device;
    VkDevice device;
    const VkAllocationCallbacks *allocator;   /* optional, used for every Vulkan object */
    VkDeviceSize offset_alignment;            /* optional: cut buffer bindings at offsets of this power of two
                                               * when it exceeds minStorageBufferOffsetAlignment (0: the device's) */
} mkg_device;

/* The pipeline and its layouts. */
mk_result mkg_context_create(const mkg_device *device, mkg_context **out, mk_error *err);
void mkg_context_destroy(mkg_context *ctx);

/* Copies the whole blob, unchanged, into a device-local storage buffer (through a staging
 * buffer and one submission on `queue` of family `queue_family`, waited for before returning).
 * The mk_asset (and so its blob) must stay alive while the mkg_asset is used: frames are
 * planned from it on the CPU. */
mk_result mkg_asset_upload(mkg_context *ctx, const mk_asset *asset, VkQueue queue, uint32_t queue_family,
                           mkg_asset **out, mk_error *err);
void mkg_asset_destroy(mkg_asset *asset);
/* The storage buffer holding the blob (for engines that want to alias or inspect it). */
VkBuffer mkg_asset_buffer(const mkg_asset *asset);

/* Where one output attribute goes: vertex v's xyz (tangents: xyzw) at offset + v * stride bytes
 * in buffer. offset and stride are multiples of 4 (stride 0: packed, 12 or 16); size is the
 * bytes the buffer has from offset on. A VK_NULL_HANDLE buffer: the attribute is not written.
 * The three may share one buffer (interleaved vertices) or not (planar). The buffer needs
 * VK_BUFFER_USAGE_STORAGE_BUFFER_BIT (and VERTEX_BUFFER_BIT to draw from it). */
typedef struct mkg_output {
    VkBuffer buffer;
    VkDeviceSize offset, stride, size;
} mkg_output;

typedef struct mkg_mesh_desc {
    uint32_t mesh;                /* index in the asset */
    uint32_t frames_in_flight;    /* plan slots (0 means 1): a slot's plan is rewritten when it is recorded again */
    mkg_output positions;         /* required */
    mkg_output normals;           /* optional; the mesh must have normals */
    mkg_output tangents;          /* optional; the mesh must have tangents (w copied from the base) */
} mkg_mesh_desc;

/* One mesh evaluated into fixed outputs: its plan slots (host-visible, coherent) and
 * descriptor sets, made once. Fails with a message when an output is too small or misaligned
 * or the mesh's data does not fit one storage-buffer binding of this device. */
mk_result mkg_mesh_create(mkg_asset *asset, const mkg_mesh_desc *desc, mkg_mesh **out, mk_error *err);
void mkg_mesh_destroy(mkg_mesh *mesh);

typedef struct mkg_frame {
    const float *weights;         /* one per channel of the mesh (mesh-local order), finite */
    uint32_t weight_count;        /* the mesh's channel count */
    mk_stacking stacking;         /* MK_STACKING_ASSET: the blob's setting */
    mk_normal_mode normal_mode;
    uint32_t slot;                /* < frames_in_flight; the GPU must be done with this slot's last use */
} mkg_frame;

/* Plans the frame into the slot's memory and records the dispatch into cmd (a primary or
 * secondary command buffer in the recording state, on a queue with compute). Nothing reaches
 * the command buffer when the frame is refused (bad weights, slot out of range). */
mk_result mkg_mesh_record(mkg_mesh *mesh, VkCommandBuffer cmd, const mkg_frame *frame, mk_error *err);

/* A barrier from earlier uses of the outputs (e.g. the previous frame's draws reading them at the
 * vertex input stage) and from the previous evaluation's writes, to this frame's evaluation:
 * record it before mkg_mesh_record when the outputs are reused across frames. */
void mkg_cmd_output_acquire(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access);

/* A barrier from the evaluation's writes to a later use of the outputs (e.g. the vertex input
 * stage reading vertex attributes, or VK_PIPELINE_STAGE_TRANSFER_BIT for a copy). */
void mkg_cmd_output_barrier(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* `--gpu` of play, frames, conform and bench: the frames evaluated through the GPU path
 * (gpu/, docs/gpu.md) on a headless Vulkan device, read back and handed to the same writers and
 * checks as the CPU's (a pb_evaluator). Each asset is uploaded once, on first use. In a build
 * without the GPU path, opening says so. */
#ifndef MK_CLI_GPU_EVAL_H
#define MK_CLI_GPU_EVAL_H

#include "frame.h"

typedef struct cli_gpu cli_gpu;

/* The help of the --gpu option of play, frames and conform. */
#define CLI_GPU_OPTION_HELP \
    "Evaluate on the GPU path (Vulkan compute on the first GPU, else lavapipe; docs/gpu.md) instead of the CPU runtime."

/* Opens the device (validation layer on when MORPHKIT_VK_VALIDATION=1) and fills evaluator.
 * Prints the device on stderr unless quiet. */
mk_result cli_gpu_open(cli_gpu **out, pb_evaluator *evaluator, int quiet, mk_error *err);
/* Closes it; returns nonzero when the validation layer reported messages (those at destruction,
 * such as objects left alive, included). */
int cli_gpu_close(cli_gpu *gpu);
/* The opened device, for the commands that record their own work on it (bench --gpu). */
struct mkg_harness *cli_gpu_harness(cli_gpu *gpu);

#endif

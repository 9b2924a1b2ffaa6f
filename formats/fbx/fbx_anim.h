/* SPDX-License-Identifier: MIT */
/* FBX weight curves into mk_key tracks (fbx_anim.c). */
#ifndef MK_FBX_ANIM_H
#define MK_FBX_ANIM_H

#include "fbx_internal.h"

/* KeyAttrFlags (fbx_anim.c reads them, the writer's fbx_objects.c writes them). */
#define KEY_CONSTANT 0x2u
#define KEY_LINEAR 0x4u
#define KEY_CONSTANT_NEXT 0x100u
#define KEY_CUBIC 0x8u
#define KEY_TCB 0x200u
#define KEY_USER 0x400u
#define KEY_CLAMP 0x1000u
#define KEY_TIME_INDEPENDENT 0x2000u
#define KEY_CLAMP_PROGRESSIVE 0x4000u
#define KEY_WEIGHTED_RIGHT 0x1000000u
#define KEY_WEIGHTED_NEXT_LEFT 0x2000000u

/* A 7.x AnimationCurve node. Keys are allocated in raw's arena; values and slopes are
 * multiplied by `scale` (0.01 for DeformPercent). *count may be 0 (no keys). */
mk_result fbx_convert_curve(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *curve, double ticks_per_second,
                            double scale, mk_key **keys, uint32_t *count);
/* A legacy Takes `Channel:` node with KeyCount/Key. */
mk_result fbx_convert_legacy_curve(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *channel, double ticks_per_second,
                                   double scale, mk_key **keys, uint32_t *count);

#endif

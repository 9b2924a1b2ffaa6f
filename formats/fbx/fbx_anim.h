/* SPDX-License-Identifier: MIT */
/* FBX weight curves into mk_key tracks (fbx_anim.c). */
#ifndef MK_FBX_ANIM_H
#define MK_FBX_ANIM_H

#include "fbx_internal.h"

/* A 7.x AnimationCurve node. Keys are allocated in raw's arena; values and slopes are
 * multiplied by `scale` (0.01 for DeformPercent). *count may be 0 (no keys). */
mk_result fbx_convert_curve(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *curve, double ticks_per_second,
                            double scale, mk_key **keys, uint32_t *count);
/* A legacy Takes `Channel:` node with KeyCount/Key. */
mk_result fbx_convert_legacy_curve(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *channel, double ticks_per_second,
                                   double scale, mk_key **keys, uint32_t *count);

#endif

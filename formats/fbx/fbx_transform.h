/* SPDX-License-Identifier: MIT */
/* FBX node transforms at rest (fbx_transform.c). Column-major doubles, m[col * 4 + row]. */
#ifndef MK_FBX_TRANSFORM_H
#define MK_FBX_TRANSFORM_H

#include "fbx_internal.h"

/* Local transform of a Model (relative to its parent) and its geometric transform. */
void fbx_model_transforms(const fbx_node *model, double local[16], double geometric[16]);
/* InheritType (0 RrSs, 1 RSrs = plain matrix product, 2 Rrs = parent scale ignored) and the
 * model's Lcl Scaling (1,1,1 when absent). */
int fbx_model_inherit_type(const fbx_node *model);
void fbx_model_scaling(const fbx_node *model, double out[3]);

#endif

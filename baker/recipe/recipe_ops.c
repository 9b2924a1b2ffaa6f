/* SPDX-License-Identifier: MIT */
/* The recipe ops, in the order error messages list them. An op is its file op_NAME.c and its
 * line here (recipe_op.h). */
#include "recipe_op.h"

extern const recipe_op recipe_op_ffd, recipe_op_ffd_travel, recipe_op_ffd_keys, recipe_op_ffd_cylinder,
    recipe_op_ffd_prism, recipe_op_taper, recipe_op_twist, recipe_op_bend, recipe_op_cage, recipe_op_laplacian,
    recipe_op_arap, recipe_op_transfer, recipe_op_shell;

const recipe_op *const recipe_ops[] = {
    &recipe_op_ffd,
    &recipe_op_ffd_travel,
    &recipe_op_ffd_keys,
    &recipe_op_ffd_cylinder,
    &recipe_op_ffd_prism,
    &recipe_op_taper,
    &recipe_op_twist,
    &recipe_op_bend,
    &recipe_op_cage,
    &recipe_op_laplacian,
    &recipe_op_arap,
    &recipe_op_transfer,
    &recipe_op_shell,
};
const unsigned recipe_op_count = sizeof recipe_ops / sizeof recipe_ops[0];

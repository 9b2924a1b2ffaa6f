/* SPDX-License-Identifier: MIT */
/* 4x4 transforms of the offline code (column-major, as mk_mesh_info.world): node transforms of
 * the importers, fixtures of the tests. */
#ifndef MK_MAT4_H
#define MK_MAT4_H

void mk_mat4_identity(float m[16]);
void mk_mat4d_identity(double m[16]);
/* out = a * b (out may alias a or b). */
void mk_mat4d_multiply(double out[16], const double a[16], const double b[16]);

#endif

/* SPDX-License-Identifier: MIT */
/* Best-fitting rotation (internal to baker/): used by ARAP's local step and by the marker
 * alignment of deformation transfer. */
#ifndef BAKE_ROTATION_FIT_H
#define BAKE_ROTATION_FIT_H

/* Rotation R (row-major, det +1) maximizing tr(R S) for S = sum_i w_i e_i e'_i^T, i.e. the
 * rotation that best maps the vectors e_i onto e'_i in the weighted least-squares sense. */
void bake_fit_rotation(const double S[9], double R[9]);

#endif

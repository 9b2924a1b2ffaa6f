/* SPDX-License-Identifier: MIT */
/* Barr's global deformations (taper, twist, bend) along an arbitrary axis. See barr.c. */
#ifndef MK_BARR_H
#define MK_BARR_H

#include "raw.h"

typedef enum mk_barr_op {
    MK_BARR_TAPER = 0,
    MK_BARR_TWIST = 1,
    MK_BARR_BEND = 2
} mk_barr_op;

typedef struct mk_barr {
    mk_barr_op op;
    double axis[3];       /* axis direction (any length; normalized by mk_barr_prepare) */
    double center[3];     /* a point on the axis line (mesh units); recipe default: bbox centre */
    double range[2];      /* [a_min, a_max] of a = p . axis_unit (mesh units), a_min < a_max */
    double angle;         /* twist / bend: radians at amplitude 1 (right-hand rule about axis) */
    double scale;         /* taper: radial scale at a_max at amplitude 1 (1 at a_min) */
    double direction[3];  /* bend: the mesh bends toward +direction (made perpendicular to axis) */
    /* Filled by mk_barr_prepare: rows of the world-to-local rotation. Twist/taper: (e1, e2,
     * axis); bend: (axis x dir, axis, dir), i.e. Barr's (x, y, z) with y the axis. */
    double frame[9];
    double local_min, local_max; /* range relative to the centre */
} mk_barr;

/* Checks and normalizes the parameters (zero axis, empty range, non-finite values, bend
 * direction parallel to the axis); err names the field. */
mk_result mk_barr_prepare(mk_barr *barr, mk_error *err);

/* Deforms one point at amplitude a (angle -> a*angle, scale -> 1 + a*(scale - 1)) and gives
 * the Jacobian J = dout/dp (row-major 3x3). user is a const mk_barr * (bake_point_map). */
void mk_barr_map(const void *barr, double amplitude, const double p[3], double out[3], double J[9]);

#endif

/* SPDX-License-Identifier: MIT */
/* Animated FFD: a mesh travelling rigidly through a fixed deformed lattice. See ffd_travel.c. */
#ifndef MK_FFD_TRAVEL_H
#define MK_FFD_TRAVEL_H

#include "ffd.h"

typedef struct mk_ffd_travel {
    const mk_ffd_lattice *lattice; /* prepared, with its (full) control point displacements */
    double translate[3];   /* mesh units at travel 1 */
    double axis[3];        /* unit rotation axis (ignored when angle == 0) */
    double angle;          /* radians at travel 1, right-hand rule about axis */
    double pivot[3];       /* a point on the rotation axis (mesh units) */
} mk_ffd_travel;

/* Position at travel fraction a: FFD(pivot + R(a angle)(p - pivot) + a translate), the lattice
 * at full displacement; J = J_ffd R (row-major). user is a const mk_ffd_travel *
 * (bake_point_map). */
void mk_ffd_travel_map(const void *travel, double amplitude, const double p[3], double out[3],
                       double J[9]);

#endif

/* SPDX-License-Identifier: MIT */
/* Animated free-form deformation: the lattice is deformed once and the object moves through it
 * (a snake swimming along a winding tube of space), as in the animated FFD of
 * S. Coquillart, P. Jancene, "Animated Free-Form Deformation: An Interactive Animation
 * Technique", SIGGRAPH 1991.
 *
 * Conventions fixed here:
 * - The travel is a rigid motion of the mesh through the lattice's rest space, played from
 *   a = 0 to 1: M(a) p = pivot + R(axis, a angle)(p - pivot) + a translate. The position at
 *   a is FFD(M(a) p) with the lattice fully deformed (ffd.c's displacement form).
 * - That is not linear in a (the lattice bends the path), so the channel gets in-betweens; at
 *   a = 0 it must be the rest mesh, which the recipe checks (the lattice may not move the
 *   start pose).
 * - Jacobian: d/dp FFD(M p) = J_ffd(M p) R, so normals follow the bent lattice exactly.
 */
#include "ffd_travel.h"
#include "bake_util.h"

void mk_ffd_travel_map(const void *user, double amplitude, const double p[3], double out[3], double J[9])
{
    const mk_ffd_travel *t = user;
    double R[9], d[3], q[3], Jf[9];
    mat3_rotation(R, t->axis, amplitude * t->angle);
    vec3_sub(d, p, t->pivot);
    mat3_mul_vec(q, R, d);
    for (int c = 0; c < 3; c++) q[c] += t->pivot[c] + amplitude * t->translate[c];
    mk_ffd_map(t->lattice, 1, q, out, Jf);
    mat3_mul(J, Jf, R);
}

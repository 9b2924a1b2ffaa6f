/* SPDX-License-Identifier: MIT */
/* EXT_meshopt_compression filters (extension README, "Appendix B: Filters"), decoded by our own
 * code so the result is the specification's formula and not whatever rounding a particular
 * libmeshoptimizer build uses (Debian's 0.18 rounds some octahedral normals one step away from
 * the formula). The byte-stream codecs (ATTRIBUTES,
 * TRIANGLES, INDICES) are still libmeshoptimizer's.
 *
 * Every function works in place on `count` elements of `stride` bytes, little-endian, and
 * follows the README's pseudo-code step by step, evaluated in double precision, with `round`
 * rounding half away from zero (C99 round). The README writes float32 and allows results within
 * one unit of the output's last place; double gives the formula's real-number value (the value
 * a hand computation gives) to about 1e-12, so the result does not depend on the float32
 * operation order, fused multiply-add or compiler flags. For 8-bit octahedral normals this is
 * also what a careful float32 evaluation gives; 16-bit outputs may differ by one unit from a
 * float32 decoder (the README's allowance). Inputs the README calls invalid (a third
 * octahedral component that is not a positive K-bit 1.0, exponents outside [-100, 100]) give
 * unspecified but deterministic results: integer outputs are clamped to the component range
 * (NaN becomes 0), so they never overflow, and exponential outputs may be infinite (the accessor
 * reader then rejects them). The caller checks the stride rules (OCTAHEDRAL 4 or 8, QUATERNION 8, EXPONENTIAL a multiple
 * of 4); the functions do nothing for any other stride. */
#ifndef MK_GLTF_MESHOPT_H
#define MK_GLTF_MESHOPT_H

#include <stddef.h>
#include <stdint.h>

/* OCTAHEDRAL: stride 4 (four int8) or 8 (four int16 at the start of the element). */
void mk_meshopt_filter_octahedral(void *data, size_t count, size_t stride);
/* QUATERNION: stride 8 (four int16). */
void mk_meshopt_filter_quaternion(void *data, size_t count, size_t stride);
/* EXPONENTIAL: every 32-bit word of the element becomes the float 2^e * m. */
void mk_meshopt_filter_exponential(void *data, size_t count, size_t stride);

#endif

/* SPDX-License-Identifier: MIT */
/* The runtime's results are the same bytes whatever the compiler, its flags (c11 or gnu11,
 * -O2 or -O3, -march=native or not) and the CPU's instruction set (the AVX2 clone or the
 * baseline): no floating-point contraction of a * b + c into a fused multiply-add, which rounds
 * once instead of twice. GCC contracts by default in GNU modes and clang by default within
 * expressions; both are turned off for every runtime source here, so an engine compiling these
 * files with its own flags gets the bytes the tests check (tests/runtime/flag_matrix.sh).
 * -ffast-math (reassociation, reciprocal approximations) cannot be undone per file and is
 * refused. Included by every runtime source after its other headers. */
#ifndef MK_DETERMINISM_H
#define MK_DETERMINISM_H

#if defined(__FAST_MATH__) && !defined(MK_ALLOW_FAST_MATH)
#error "morphkit's runtime must not be compiled with -ffast-math: its results would depend on the flags (define MK_ALLOW_FAST_MATH to accept that)"
#endif

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#else
#pragma STDC FP_CONTRACT OFF
#endif

#endif

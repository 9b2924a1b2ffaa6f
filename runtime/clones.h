/* SPDX-License-Identifier: MIT */
/* Hot loops compiled per ISA level (private): MK_CLONES on a function builds it twice where the
 * compiler and platform allow it, for the baseline ISA and for x86-64-v3 (AVX2, FMA, BMI,
 * POPCNT), picked once at load time by feature level, not CPU model ("arch=haswell" would check
 * the model and never match an AMD CPU) through a glibc ifunc (GCC target_clones). The helpers
 * such a function calls are MK_INLINE (force-inlined), so each clone gets its own vector code.
 * Both clones give the same bytes: determinism.h keeps multiplies and adds from being fused
 * into FMA, and the loops use only correctly rounded operations. Define MK_NO_TARGET_CLONES to
 * build one baseline copy. GCC only: clang 14 emits the resolver as a global symbol. */
#ifndef MK_RUNTIME_CLONES_H
#define MK_RUNTIME_CLONES_H

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__) && \
    !defined(MK_NO_TARGET_CLONES) && !defined(__SANITIZE_ADDRESS__)
#define MK_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define MK_CLONES
#endif
#if defined(__GNUC__) || defined(__clang__)
#define MK_INLINE static inline __attribute__((always_inline))
#else
#define MK_INLINE static inline
#endif

#endif

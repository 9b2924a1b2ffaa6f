/* SPDX-License-Identifier: MIT */
/* Output spans of the runtime's jobs (private): pointer + byte stride + byte size. */
#ifndef MK_RUNTIME_SPAN_H
#define MK_RUNTIME_SPAN_H

#include <stddef.h>
#include <stdint.h>

/* A span of count elements of elem bytes: 4-byte aligned, stride a multiple of 4 and at least
 * elem, size at least stride * (count - 1) + elem. */
static inline int mk_span_ok(const void *p, size_t stride, size_t size, uint32_t count, size_t elem)
{
    if ((uintptr_t)p % 4 || stride % 4 || stride < elem) return 0;
    if (count == 0) return 1;
    return (count - 1) <= (SIZE_MAX - elem) / stride && size >= stride * (count - 1) + elem;
}

/* stride 0 means packed. */
static inline size_t mk_stride_or(size_t stride, size_t packed) { return stride ? stride : packed; }

#endif

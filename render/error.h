/* Internal to morphkit_render: fills an mk_error (runtime/morphkit.h) the way the offline
 * tools do, without linking the offline library. */
#ifndef MKR_ERROR_H
#define MKR_ERROR_H

#include "morphkit.h"

/* Sets err (may be NULL) to code, no input offset, and a printf-style message; returns code. */
mk_result mkr_error_set(mk_error *err, mk_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif

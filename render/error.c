#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include "error.h"

mk_result mkr_error_set(mk_error *err, mk_result code, const char *fmt, ...)
{
    if (!err) return code;
    err->code = code;
    err->offset = UINT64_MAX;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return code;
}

/* SPDX-License-Identifier: MIT */
#include <string.h>
#include "error.h"

void mk_error_start(mk_error *err, mk_result code, uint64_t offset)
{
    if (!err) return;
    err->code = code;
    err->offset = offset;
    err->message[0] = 0;
}

void mk_error_text(mk_error *err, const char *text)
{
    if (!err) return;
    size_t len = strlen(err->message);
    while (*text && len + 1 < sizeof err->message) err->message[len++] = *text++;
    err->message[len] = 0;
}

void mk_error_number(mk_error *err, uint64_t value)
{
    char digits[24];
    int n = 0;
    do { digits[n++] = (char)('0' + value % 10); value /= 10; } while (value);
    char one[2] = { 0, 0 };
    while (n--) { one[0] = digits[n]; mk_error_text(err, one); }
}

mk_result mk_error_end(mk_error *err, mk_result code)
{
    if (err && err->offset != MK_NO_OFFSET) {
        mk_error_text(err, " (byte offset ");
        mk_error_number(err, err->offset);
        mk_error_text(err, ")");
    }
    return code;
}

mk_result mk_error_fail(mk_error *err, mk_result code, uint64_t offset, const char *message)
{
    mk_error_start(err, code, offset);
    mk_error_text(err, message);
    return mk_error_end(err, code);
}

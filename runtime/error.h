/* SPDX-License-Identifier: MIT */
/* The runtime's one way to fill an mk_error (private to the runtime). No stdio, no stdarg, no
 * allocation: a message is started with its code and byte offset, built from text and decimal
 * numbers (truncated at the message buffer's size), and ended, which appends
 * " (byte offset N)" when the offset is known. Every function accepts a NULL err. */
#ifndef MK_RUNTIME_ERROR_H
#define MK_RUNTIME_ERROR_H

#include <stdint.h>
#include "morphkit.h"

#define MK_NO_OFFSET UINT64_MAX

void mk_error_start(mk_error *err, mk_result code, uint64_t offset);
void mk_error_text(mk_error *err, const char *text);
void mk_error_number(mk_error *err, uint64_t value);
/* Returns code. */
mk_result mk_error_end(mk_error *err, mk_result code);
/* A whole message in one call: start, text, end. */
mk_result mk_error_fail(mk_error *err, mk_result code, uint64_t offset, const char *message);

#endif

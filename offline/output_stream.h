/* SPDX-License-Identifier: MIT */
/* Writing an output's finished parts while the rest is still computed (output_stream.c). A
 * blob's target data is most of its bytes and is final long before the blob is (its header
 * and checksum come last), and a large write is bound by the device: a thread of its own
 * writes the parts reported ready into the output's early temporary file (mk_output_open_early),
 * in file order, and mk_write_outputs writes the rest. */
#ifndef MK_OUTPUT_STREAM_H
#define MK_OUTPUT_STREAM_H

#include <stdint.h>
#include "blob_io.h"

typedef struct mk_output_stream mk_output_stream;

/* Starts a writer thread for an early output (mk_output_open_early). NULL when there is nothing
 * to write early (not an early output) or no thread could be started: then everything is
 * written at the end, as for any output. out must stay where it is until the finish. */
mk_output_stream *mk_output_stream_start(mk_output *out);
/* A mk_write_options ready callback: bytes [offset, offset + size) of the blob at `blob` are
 * final. Any thread, any order; each byte at most once. user is the stream (may be NULL). */
void mk_output_stream_ready(void *user, const void *blob, uint64_t offset, uint64_t size);
/* Waits for the thread's current write or flush and stops it; out's written range then says
 * what is in the file. A piece whose write failed is not in it (mk_write_outputs writes it
 * again, and fails if that fails too); a failed flush is kept in out->early_errno and fails
 * the output. Frees the stream. NULL: nothing. */
void mk_output_stream_finish(mk_output_stream *stream);

#endif

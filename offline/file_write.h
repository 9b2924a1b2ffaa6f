/* SPDX-License-Identifier: MIT */
/* Writing a buffer to a file descriptor (file_write.c). */
#ifndef MK_FILE_WRITE_H
#define MK_FILE_WRITE_H

#include <stddef.h>
#include <stdint.h>

/* Parts this large or larger go to a regular file's device around the page cache. */
#define MK_WRITE_DIRECT_MIN ((size_t)1 << 20)

/* Writes size bytes at fd's offset (write), retrying short and interrupted writes: the way
 * outputs that are devices or FIFOs are written, in place. 0 on success, -1 with errno set. */
int mk_write_fd(int fd, const void *data, size_t size);
/* Writes size bytes at a given offset of a regular file (pwrite; fd's own offset is left alone),
 * so an output's parts can be written in any order: every file output's bytes go this way. When
 * the offset is 4096-byte aligned, the size is at least MK_WRITE_DIRECT_MIN and the file system
 * allows it, the whole 4096-byte blocks are written with O_DIRECT (through an aligned 1 MB buffer;
 * the data needs no alignment) and the rest through the page cache. *direct_bytes (may be NULL)
 * receives how many bytes went directly. 0 on success, -1 with errno set. fd must not have
 * O_DIRECT set already. The caller still fsyncs. */
int mk_write_fd_at(int fd, const void *data, size_t size, uint64_t offset, size_t *direct_bytes);

#endif

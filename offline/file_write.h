/* SPDX-License-Identifier: MIT */
/* Writing a buffer to a file descriptor (file_write.c). */
#ifndef MK_FILE_WRITE_H
#define MK_FILE_WRITE_H

#include <stddef.h>
#include <stdint.h>

/* Outputs this large or larger go to a regular file's device around the page cache. */
#define MK_WRITE_DIRECT_MIN ((size_t)1 << 20)

/* Writes size bytes at fd's offset, retrying short and interrupted writes. When fd is a regular
 * file at a 4096-byte aligned offset, the size is at least MK_WRITE_DIRECT_MIN and the file
 * system allows it, the whole 4096-byte blocks are written with O_DIRECT (through an aligned 1 MB buffer; the data needs
 * no alignment) and the rest through the page cache. *direct_bytes (may be NULL) receives how
 * many bytes went directly. 0 on success, -1 with errno set. fd must not have O_DIRECT set
 * already. The caller still fsyncs. */
int mk_write_fd(int fd, const void *data, size_t size, size_t *direct_bytes);
/* The same at a given offset of a regular file (pwrite; fd's own offset is left alone): for
 * writing an output's parts in any order. */
int mk_write_fd_at(int fd, const void *data, size_t size, uint64_t offset, size_t *direct_bytes);

#endif

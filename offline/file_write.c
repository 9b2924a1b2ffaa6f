/* SPDX-License-Identifier: MIT */
/* Writing an output's bytes: a regular file's at given offsets (mk_write_fd_at; every file
 * output goes this way, from file_io.c and output_stream.c), a device's or FIFO's in order
 * through plain writes (mk_write_fd). The tools flush every file output to disk before renaming
 * it into place (file_io.c), so a large output's bytes must reach the device before the command
 * ends anyway.
 * Written through the page cache they are first copied into freshly allocated cache pages, and
 * first use of fresh memory is what such a write mostly costs on a virtual machine whose host
 * backs guest memory lazily (a 48 MB blob: up to 0.26 s of copying, then 0.03 s of flushing;
 * docs/performance.md). Written with O_DIRECT (where the system has it; whole 4096-byte blocks
 * from an aligned buffer) they go from one reused buffer to the device: 0.04-0.09 s there. On a
 * network file system each direct write is its own round trip (not measured). Where the file
 * system refuses O_DIRECT, or a direct write fails part way, the rest is written the ordinary
 * way; a real error (no space, I/O) then shows there. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "file_write.h"

#define DIRECT_ALIGN ((size_t)4096)   /* covers 512- and 4096-byte logical blocks and the page */
#define DIRECT_CHUNK ((size_t)1 << 20)

/* size bytes through the page cache, retrying short and interrupted writes: at fd's offset
 * (write) when `at` is negative, else at file offset `at` (pwrite). */
static int write_buffered(int fd, const uint8_t *p, size_t size, int64_t at)
{
    while (size) {
        ssize_t k = at < 0 ? write(fd, p, size) : pwrite(fd, p, size, (off_t)at);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0) return -1;
        if (k == 0) {
            errno = EIO;
            return -1;
        }
        p += k;
        size -= (size_t)k;
        if (at >= 0) at += k;
    }
    return 0;
}

/* The whole blocks of data[0 .. size) with O_DIRECT at file offset `at` (pwrite: fd's offset is
 * left alone); *done: how many bytes were written (0 when O_DIRECT is not available). fd's
 * status flags are as they were afterwards: -1 (errno set) when they could not be put back,
 * else 0. */
static int write_direct(int fd, const uint8_t *data, size_t size, uint64_t at, size_t *done)
{
    *done = 0;
#ifdef O_DIRECT
    struct stat st;
    if (size < MK_WRITE_DIRECT_MIN || at % DIRECT_ALIGN || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return 0;
    const int flags = fcntl(fd, F_GETFL), direct = flags | O_DIRECT;
    if (flags < 0 || (flags & O_DIRECT) || fcntl(fd, F_SETFL, direct) != 0) return 0;
    uint8_t *chunk = aligned_alloc(DIRECT_ALIGN, DIRECT_CHUNK);
    const size_t whole = size & ~(DIRECT_ALIGN - 1);
    while (chunk && *done < whole) {
        size_t n = whole - *done < DIRECT_CHUNK ? whole - *done : DIRECT_CHUNK;
        memcpy(chunk, data + *done, n);
        ssize_t k = pwrite(fd, chunk, n, (off_t)(at + *done));
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) break;                  /* refused or failed: the rest buffered */
        *done += (size_t)k;
        if ((size_t)k % DIRECT_ALIGN) break; /* the offset is no longer aligned */
    }
    free(chunk);
    if (fcntl(fd, F_SETFL, flags) != 0) return -1;
#else
    (void)fd;
    (void)data;
    (void)size;
    (void)at;
#endif
    return 0;
}

int mk_write_fd(int fd, const void *data, size_t size)
{
    return write_buffered(fd, data, size, -1);
}

int mk_write_fd_at(int fd, const void *data, size_t size, uint64_t offset, size_t *direct_bytes)
{
    const uint8_t *p = data;
    size_t done = 0;
    if (write_direct(fd, p, size, offset, &done) != 0) return -1;
    if (direct_bytes) *direct_bytes = done;
    return write_buffered(fd, p + done, size - done, (int64_t)(offset + done));
}

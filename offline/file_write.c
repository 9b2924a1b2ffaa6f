/* SPDX-License-Identifier: MIT */
/* Writing a file's bytes. The tools flush every output to disk before renaming it into place
 * (file_io.c), so a large output's bytes must reach the device before the command ends anyway.
 * Written through the page cache they are first copied into freshly allocated cache pages, and
 * first use of fresh memory is what such a write mostly costs on a virtual machine whose host
 * backs guest memory lazily (a 48 MB blob: 0.24-0.28 s of copying, then 0.03 s of flushing;
 * docs/performance.md). Written with O_DIRECT (Linux; whole 4096-byte blocks from an aligned
 * buffer) they go from one reused buffer to the device: 0.05-0.06 s there. Where the file
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

static int write_buffered(int fd, const uint8_t *p, size_t size)
{
    while (size) {
        ssize_t k = write(fd, p, size);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0) return -1;
        if (k == 0) {
            errno = EIO;
            return -1;
        }
        p += k;
        size -= (size_t)k;
    }
    return 0;
}

/* The whole blocks of data[0 .. size) with O_DIRECT; returns how many bytes were written (0
 * when O_DIRECT is not available). fd's status flags are as they were afterwards. */
static size_t write_direct(int fd, const uint8_t *data, size_t size)
{
    size_t done = 0;
#ifdef O_DIRECT
    struct stat st;
    if (size < MK_WRITE_DIRECT_MIN || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return 0;
    off_t at = lseek(fd, 0, SEEK_CUR);
    if (at < 0 || (uint64_t)at % DIRECT_ALIGN) return 0;
    int flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags | O_DIRECT) != 0) return 0;
    uint8_t *chunk = aligned_alloc(DIRECT_ALIGN, DIRECT_CHUNK);
    const size_t whole = size & ~(DIRECT_ALIGN - 1);
    while (chunk && done < whole) {
        size_t n = whole - done < DIRECT_CHUNK ? whole - done : DIRECT_CHUNK;
        memcpy(chunk, data + done, n);
        ssize_t k = write(fd, chunk, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) break;                  /* refused or failed: the rest buffered */
        done += (size_t)k;
        if ((size_t)k % DIRECT_ALIGN) break; /* the offset is no longer aligned */
    }
    free(chunk);
    (void)fcntl(fd, F_SETFL, flags);
#else
    (void)fd;
    (void)data;
    (void)size;
#endif
    return done;
}

int mk_write_fd(int fd, const void *data, size_t size, size_t *direct_bytes)
{
    const uint8_t *p = data;
    size_t done = write_direct(fd, p, size);
    if (direct_bytes) *direct_bytes = done;
    return write_buffered(fd, p + done, size - done);
}

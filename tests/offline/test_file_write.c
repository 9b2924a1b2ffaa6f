/* SPDX-License-Identifier: MIT */
/* mk_write_fd_at (every file output's way): every byte arrives for sizes around the direct-write
 * threshold and the 4096-byte block, from unaligned memory, at aligned and unaligned offsets,
 * on the build folder's file system and on tmpfs; large parts go around the page cache where the
 * file system allows it, the descriptor's flags and offset are left as they were; parts at any
 * offsets, in any order, make the file; errors come back with errno. mk_write_fd (devices and
 * FIFOs): the bytes in order, and a device's error with errno. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>
#include "check.h"
#include "file_write.h"

/* Whether files in dir accept O_DIRECT writes of aligned blocks. */
static int direct_possible(const char *dir)
{
#ifdef O_DIRECT
    char path[512];
    snprintf(path, sizeof path, "%s/mk_direct_probe.%ld", dir, (long)getpid());
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_DIRECT, 0600);
    if (fd < 0) return 0;
    void *block = aligned_alloc(4096, 4096);
    int ok = block && (memset(block, 0, 4096), write(fd, block, 4096) == 4096);
    free(block);
    close(fd);
    unlink(path);
    return ok;
#else
    (void)dir;
    return 0;
#endif
}

/* How many of the file's first `bytes` bytes (whole pages) are in the page cache; -1 if unknown. */
static long cached_pages(const char *path, size_t bytes)
{
    long page = sysconf(_SC_PAGESIZE);
    size_t pages = page > 0 ? bytes / (size_t)page : 0;
    int fd = open(path, O_RDONLY);
    if (fd < 0 || pages == 0) {
        if (fd >= 0) close(fd);
        return -1;
    }
    void *map = mmap(NULL, pages * (size_t)page, PROT_READ, MAP_SHARED, fd, 0);
    close(fd);
    if (map == MAP_FAILED) return -1;
    unsigned char *vec = malloc(pages);
    long n = -1;
    if (vec && mincore(map, pages * (size_t)page, vec) == 0) {
        n = 0;
        for (size_t i = 0; i < pages; i++) n += vec[i] & 1;
    }
    free(vec);
    munmap(map, pages * (size_t)page);
    return n;
}

static void write_and_compare(const char *dir)
{
    static const size_t sizes[] = { 0, 1, 4095, 4096, 4097, MK_WRITE_DIRECT_MIN - 1, MK_WRITE_DIRECT_MIN,
                                    MK_WRITE_DIRECT_MIN + 1, MK_WRITE_DIRECT_MIN + 4096,
                                    3 * MK_WRITE_DIRECT_MIN + 123 };
    const size_t most = 3 * MK_WRITE_DIRECT_MIN + 123;
    const int direct = direct_possible(dir);
    struct statfs fs;
    /* tmpfs keeps every file in the page cache: there a direct write is not visible as such */
    const int cache_visible = statfs(dir, &fs) == 0 && fs.f_type != 0x01021994 /* TMPFS_MAGIC */;
    long direct_cases = 0;
    uint8_t *mem = malloc(most + 1);
    CHECK(mem != NULL);
    if (!mem) return;
    uint8_t *data = mem + 1;   /* never 4096-aligned: the data needs no alignment */
    uint32_t x = 12345;
    for (size_t i = 0; i < most; i++) data[i] = (uint8_t)((x = x * 1664525u + 1013904223u) >> 24);
    char path[512];
    snprintf(path, sizeof path, "%s/mk_file_write_test.%ld", dir, (long)getpid());
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++)
        for (size_t prefix = 0; prefix <= 2; prefix += 2) {
            /* After a 2-byte prefix the offset is not aligned: everything goes the ordinary way. */
            const size_t size = sizes[k];
            int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
            CHECK(fd >= 0);
            if (fd < 0) break;
            CHECK(write(fd, "ab", prefix) == (ssize_t)prefix);
            size_t went_direct = 99;
            const int flags_before = fcntl(fd, F_GETFL);
            CHECK_EQ_INT(mk_write_fd_at(fd, data, size, prefix, &went_direct), 0);
            CHECK_EQ_INT(fcntl(fd, F_GETFL), flags_before);
            CHECK_EQ_INT(lseek(fd, 0, SEEK_CUR), (long long)prefix);
            size_t expect = direct && !prefix && size >= MK_WRITE_DIRECT_MIN ? size & ~(size_t)4095 : 0;
            CHECK_MSG(went_direct == expect, "%s, %zu bytes after %zu: %zu direct, expected %zu", dir, size, prefix,
                      went_direct, expect);
            CHECK(fsync(fd) == 0);
            CHECK(close(fd) == 0);
            if (expect && cache_visible) {
                /* written around the page cache: none of the direct part is cached (a buffered
                 * write leaves all of it there) */
                long cached = cached_pages(path, expect);
                CHECK_MSG(cached == 0, "%s, %zu bytes: %ld pages of the direct part in the page cache", dir, size, cached);
                direct_cases++;
            }
            size_t n = 0;
            unsigned char *got = check_read_file(path, &n);
            CHECK_EQ_INT(n, size + prefix);
            if (got && n == size + prefix)
                CHECK_MSG(memcmp(got, "ab", prefix) == 0 && memcmp(got + prefix, data, size) == 0,
                          "%s, %zu bytes after %zu: contents differ", dir, size, prefix);
            free(got);
        }
    unlink(path);
    printf("  %s: O_DIRECT %s; %ld writes checked to have left the page cache alone\n", dir,
           direct ? "used" : "not available on this file system", direct_cases);
    free(mem);
}

static void every_byte_arrives_in_order(void)
{
    write_and_compare(".");
    struct stat st;
    if (stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) && access("/dev/shm", W_OK) == 0) write_and_compare("/dev/shm");
}

static void errors_come_back(void)
{
    size_t size = 2 * MK_WRITE_DIRECT_MIN, went_direct = 99;
    uint8_t *data = calloc(1, size);
    CHECK(data != NULL);
    if (!data) return;
    int fd = open("/dev/full", O_WRONLY);
    if (fd >= 0) {   /* a device: written in place, and its error comes back */
        errno = 0;
        CHECK_EQ_INT(mk_write_fd(fd, data, size), -1);
        CHECK_EQ_INT(errno, ENOSPC);
        close(fd);
    }
    fd = open(".", O_RDONLY);   /* not open for writing */
    CHECK(fd >= 0);
    errno = 0;
    CHECK_EQ_INT(mk_write_fd(fd, data, size), -1);
    CHECK(errno != 0);
    close(fd);
    /* a regular file open for reading only: the direct write is refused, the ordinary one fails */
    char path[512];
    snprintf(path, sizeof path, "./mk_file_write_ro.%ld", (long)getpid());
    fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    CHECK(fd >= 0 && close(fd) == 0);
    fd = open(path, O_RDONLY);
    CHECK(fd >= 0);
    errno = 0;
    CHECK_EQ_INT(mk_write_fd_at(fd, data, size, 0, &went_direct), -1);
    CHECK_EQ_INT(errno, EBADF);
    CHECK_EQ_INT(went_direct, 0);
    close(fd);
    unlink(path);
    free(data);
}

/* mk_write_fd: the bytes in order at the descriptor's offset (the way of a FIFO). */
static void bytes_in_order_through_a_pipe(void)
{
    int p[2];
    CHECK(pipe(p) == 0);
    static const char first[] = "first ", second[] = "second";
    CHECK_EQ_INT(mk_write_fd(p[1], first, 6), 0);
    CHECK_EQ_INT(mk_write_fd(p[1], second, 6), 0);
    close(p[1]);
    char got[16] = { 0 };
    CHECK_EQ_INT(read(p[0], got, sizeof got), 12);
    CHECK(memcmp(got, "first second", 12) == 0);
    close(p[0]);
}

/* mk_write_fd_at: parts written out of order, at aligned and unaligned offsets, make the file;
 * fd's own offset stays where it was. */
static void parts_at_offsets(void)
{
    const size_t size = 3 * MK_WRITE_DIRECT_MIN + 5000;
    uint8_t *data = malloc(size);
    CHECK(data != NULL);
    if (!data) return;
    uint32_t x = 777;
    for (size_t i = 0; i < size; i++) data[i] = (uint8_t)((x = x * 1664525u + 1013904223u) >> 24);
    char path[512];
    snprintf(path, sizeof path, "./mk_file_write_at.%ld", (long)getpid());
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    CHECK(fd >= 0);
    if (fd < 0) {
        free(data);
        return;
    }
    /* the last part first (it extends the file past a hole), then an unaligned middle, then
     * the aligned head large enough to go directly */
    const size_t cut1 = MK_WRITE_DIRECT_MIN + 4096, cut2 = 2 * MK_WRITE_DIRECT_MIN + 777;
    size_t went_direct = 99;
    CHECK_EQ_INT(mk_write_fd_at(fd, data + cut2, size - cut2, cut2, &went_direct), 0);
    CHECK_EQ_INT(went_direct, 0);   /* unaligned offset: the ordinary way */
    CHECK_EQ_INT(mk_write_fd_at(fd, data + cut1, cut2 - cut1, cut1, NULL), 0);
    CHECK_EQ_INT(mk_write_fd_at(fd, data, cut1, 0, &went_direct), 0);
    CHECK_EQ_INT(lseek(fd, 0, SEEK_CUR), 0);
    CHECK(close(fd) == 0);
    size_t n = 0;
    unsigned char *got = check_read_file(path, &n);
    CHECK_EQ_INT(n, size);
    if (got && n == size) CHECK_MSG(memcmp(got, data, size) == 0, "parts written at offsets differ");
    free(got);
    unlink(path);
    free(data);
}

CHECK_MAIN(CASE(every_byte_arrives_in_order), CASE(errors_come_back), CASE(bytes_in_order_through_a_pipe),
           CASE(parts_at_offsets))

/* SPDX-License-Identifier: MIT */
/* Whole-file reads into arena memory, and output writing that never loses data: a regular
 * file is replaced atomically (temporary file beside it, flushed, renamed), a symbolic link is
 * followed (the file it points at is replaced, the link stays a link), a device, FIFO or
 * socket is written directly, a directory is an error, and several outputs are written all
 * together or not at all. Also the file-extension test shared by the importers and the CLI. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "blob_io.h"
#include "file_write.h"
#include "parallel.h"

static mk_result io_error(mk_error *err, const char *path, const char *what, int e)
{
    return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: %s: %s", path, what, strerror(e));
}

/* Reads everything from fd, growing the buffer (pipes and devices have no size up front). */
static mk_result read_stream(mk_arena *arena, int fd, const char *path, size_t max_size, uint8_t **data, size_t *size,
                             mk_error *err)
{
    size_t cap = 1 << 16, n = 0;
    uint8_t *p = mk_arena_alloc(arena, cap + 1);
    if (!p) return mk_error_oom(err, "reading a file");
    for (;;) {
        if (n == cap) {
            if (max_size && cap >= max_size)
                return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%.200s: more than the limit of %zu bytes", path,
                                    max_size);
            uint8_t *q = mk_arena_realloc(arena, p, cap + 1, 2 * cap + 1);
            if (!q) return mk_error_oom(err, "reading a file");
            p = q;
            cap *= 2;
        }
        ssize_t got = read(fd, p + n, cap - n);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) return io_error(err, path, "read failed", errno);
        if (got == 0) break;
        n += (size_t)got;
    }
    if (max_size && n > max_size)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%.200s: %zu bytes exceeds the limit of %zu bytes", path,
                            n, max_size);
    p[n] = 0;
    *data = p;
    *size = n;
    return MK_OK;
}

/* A regular file of at least READ_SPLIT_MIN bytes is read by several threads at once, in at
 * most READ_PARTS parts of at least READ_PART_MIN bytes (pread). Most of such a read's time is
 * the first touch of the fresh destination pages, which the threads then take in parallel. */
#define READ_SPLIT_MIN ((size_t)8 << 20)
#define READ_PART_MIN ((size_t)4 << 20)
#define READ_PARTS 64u

typedef struct read_parts {
    int fd;
    uint8_t *p;
    size_t n, part;
    int error[READ_PARTS];     /* errno of a part's failed read, else 0 */
    size_t end[READ_PARTS];    /* where a part's reading stopped (its end unless the file shrank) */
} read_parts;

/* Where part i ends: its size on, or the file's end. */
static size_t part_end(const read_parts *rp, uint32_t i)
{
    const size_t at = (size_t)i * rp->part;
    return rp->n - at < rp->part ? rp->n : at + rp->part;
}

static void read_part(void *user, uint32_t item, uint32_t worker)
{
    (void)worker;
    read_parts *rp = user;
    size_t at = (size_t)item * rp->part, end = part_end(rp, item);
    rp->error[item] = 0;
    while (at < end) {
        ssize_t k = pread(rp->fd, rp->p + at, end - at, (off_t)at);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0) { rp->error[item] = errno; break; }
        if (k == 0) break;
        at += (size_t)k;
    }
    rp->end[item] = at;
}

/* Reads n bytes of fd into p on up to `threads` threads; errors as the serial read gives them
 * (the first part in file order that failed or came up short). */
static mk_result read_split(int fd, const char *path, uint8_t *p, size_t n, uint32_t threads, mk_error *err)
{
    read_parts rp = { .fd = fd, .p = p, .n = n };
    rp.part = (n + READ_PARTS - 1) / READ_PARTS;
    if (rp.part < READ_PART_MIN) rp.part = READ_PART_MIN;
    const uint32_t parts = (uint32_t)((n + rp.part - 1) / rp.part);
    mk_parallel_for(parts, threads, read_part, &rp);
    for (uint32_t i = 0; i < parts; i++) {
        if (rp.error[i]) return io_error(err, path, "read failed", rp.error[i]);
        if (rp.end[i] != part_end(&rp, i))
            return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: read %zu of %zu bytes (file shrank?)", path,
                                rp.end[i], n);
    }
    return MK_OK;
}

mk_result mk_read_file(mk_arena *arena, const char *path, size_t max_size, void **data, size_t *size, mk_error *err)
{
    return mk_read_file_threads(arena, path, max_size, 1, data, size, err);
}

mk_result mk_read_file_threads(mk_arena *arena, const char *path, size_t max_size, uint32_t threads, void **data,
                               size_t *size, mk_error *err)
{
    int fd = open(path, O_RDONLY | O_NOCTTY);
    if (fd < 0) return io_error(err, path, "cannot open", errno);
    struct stat st;
    mk_result r = MK_OK;
    uint8_t *p = NULL;
    size_t n = 0;
    if (fstat(fd, &st) != 0) {
        r = io_error(err, path, "cannot read its status", errno);
    } else if (S_ISDIR(st.st_mode)) {
        r = mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: is a directory, not a file", path);
    } else if (!S_ISREG(st.st_mode)) {
        r = read_stream(arena, fd, path, max_size, &p, &n, err);
    } else if (max_size && (uint64_t)st.st_size > max_size) {
        r = mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%.200s: %lld bytes exceeds the limit of %zu bytes", path,
                         (long long)st.st_size, max_size);
    } else if ((uint64_t)st.st_size >= SIZE_MAX) {
        r = mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%.200s: too large for this machine", path);
    } else {
        n = (size_t)st.st_size;
        p = mk_arena_alloc(arena, n + 1);
        if (!p) r = mk_error_oom(err, "reading a file");
        size_t got = 0;
        if (r == MK_OK && n >= READ_SPLIT_MIN && mk_parallel_threads(threads, 2) > 1) {
            r = read_split(fd, path, p, n, threads, err);
            got = n;
        }
        while (r == MK_OK && got < n) {
            ssize_t k = read(fd, p + got, n - got);
            if (k < 0 && errno == EINTR) continue;
            if (k < 0)
                r = io_error(err, path, "read failed", errno);
            else if (k == 0)
                r = mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: read %zu of %zu bytes (file shrank?)", path,
                                 got, n);
            else
                got += (size_t)k;
        }
        if (p) p[n] = 0;
    }
    close(fd);
    if (r == MK_OK && n == 0) r = mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: empty file", path);
    if (r != MK_OK) {
        if (p) mk_arena_release(arena, p);
        return r;
    }
    *data = p;
    *size = n;
    return MK_OK;
}

/* ---- outputs ---- */

void mk_path_dir(const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        snprintf(out, size, ".");
        return;
    }
    size_t n = slash == path ? 1 : (size_t)(slash - path);
    snprintf(out, size, "%.*s", (int)n, path);
}

/* Follows path's symbolic links (also dangling ones) to the file that would be written. */
static mk_result resolve_links(const char *path, char *target, size_t size, mk_error *err)
{
    if ((size_t)snprintf(target, size, "%s", path) >= size)
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: path too long", path);
    for (int hops = 0; hops < 40; hops++) {
        struct stat st;
        if (lstat(target, &st) != 0 || !S_ISLNK(st.st_mode)) return MK_OK;
        char link[PATH_MAX], joined[PATH_MAX];
        ssize_t n = readlink(target, link, sizeof link - 1);
        if (n < 0) return io_error(err, path, "cannot read the symbolic link", errno);
        link[n] = 0;
        if (link[0] == '/') {
            snprintf(joined, sizeof joined, "%s", link);
        } else {
            char dir[PATH_MAX];
            mk_path_dir(target, dir, sizeof dir);
            if ((size_t)snprintf(joined, sizeof joined, "%s/%s", dir, link) >= sizeof joined)
                return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: link target path too long", path);
        }
        snprintf(target, size, "%s", joined);
    }
    return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: too many levels of symbolic links", path);
}

mk_result mk_output_check(mk_output *out, const char *const *inputs, uint32_t input_count, mk_error *err)
{
    const char *path = out->path;
    if (!path || !path[0]) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "empty output path");
    mk_result r = resolve_links(path, out->target, sizeof out->target, err);
    if (r != MK_OK) return r;
    struct stat st;
    int exists = stat(out->target, &st) == 0;
    if (!exists && errno != ENOENT) return io_error(err, path, "cannot write", errno);
    if (exists) {
        for (uint32_t i = 0; i < input_count; i++) {
            struct stat in;
            if (inputs[i] && stat(inputs[i], &in) == 0 && in.st_dev == st.st_dev && in.st_ino == st.st_ino)
                return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                                    "refusing to overwrite the input %.200s (it is the same file as the output %.200s)",
                                    inputs[i], path);
        }
        if (S_ISDIR(st.st_mode))
            return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: is a directory; give a file name", path);
        if (!S_ISREG(st.st_mode)) {
            if (S_ISSOCK(st.st_mode))
                return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: is a socket; cannot write to it", path);
            if (access(out->target, W_OK) != 0) return io_error(err, path, "cannot write", errno);
            out->kind = MK_OUTPUT_STREAM;
            return MK_OK;
        }
    }
    char dir[PATH_MAX];
    mk_path_dir(out->target, dir, sizeof dir);
    struct stat ds;
    if (stat(dir, &ds) != 0)
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: cannot create it: folder %.200s: %s", path, dir,
                            strerror(errno));
    if (!S_ISDIR(ds.st_mode))
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: cannot create it: %.200s is not a folder", path,
                            dir);
    if (access(dir, W_OK) != 0)
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%.200s: cannot write in folder %.200s: %s", path, dir,
                            strerror(errno));
    out->kind = exists ? MK_OUTPUT_REPLACE_FILE : MK_OUTPUT_NEW_FILE;
    out->mode = exists ? (uint32_t)(st.st_mode & 07777) : 0;
    return MK_OK;
}

/* ---- the files an interrupted command leaves behind ----
 * Every temporary and backup file beside an output is listed here from its creation until it
 * is renamed or removed, so a signal handler can remove them (unlink is async-signal-safe). A
 * slot's name is complete before its flag is set. More files at once than slots (a command
 * writes at most a few outputs) are simply not listed. */
#define PENDING_SLOTS 16
static char pending_name[PENDING_SLOTS][4200];
static volatile sig_atomic_t pending_used[PENDING_SLOTS];

static void pending_add(const char *name)
{
    for (int i = 0; i < PENDING_SLOTS; i++) {
        if (pending_used[i]) continue;
        snprintf(pending_name[i], sizeof pending_name[i], "%s", name);
        atomic_signal_fence(memory_order_seq_cst);
        pending_used[i] = 1;
        return;
    }
}

static void pending_forget(const char *name)
{
    for (int i = 0; i < PENDING_SLOTS; i++)
        if (pending_used[i] && !strcmp(pending_name[i], name)) pending_used[i] = 0;
}

static void remove_pending_and_reraise(int sig)
{
    for (int i = 0; i < PENDING_SLOTS; i++)
        if (pending_used[i]) unlink(pending_name[i]);
    signal(sig, SIG_DFL);
    raise(sig);
}

void mk_output_cleanup_on_signals(void)
{
    static const int signals[] = { SIGINT, SIGTERM, SIGHUP };
    for (size_t i = 0; i < sizeof signals / sizeof signals[0]; i++) {
        struct sigaction old;
        if (sigaction(signals[i], NULL, &old) != 0 || old.sa_handler != SIG_DFL) continue;   /* ignored: stays so */
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = remove_pending_and_reraise;
        sigemptyset(&sa.sa_mask);
        sigaction(signals[i], &sa, NULL);
    }
}

/* A new file "<target><suffix>.<pid>.<n>" created exclusively (the umask applies); listed as
 * pending until pending_forget. */
static int create_beside(const char *target, const char *suffix, char *name, size_t size)
{
    for (int n = 0; n < 1000; n++) {
        if ((size_t)snprintf(name, size, "%s%s.%ld.%d", target, suffix, (long)getpid(), n) >= size) {
            errno = ENAMETOOLONG;
            return -1;
        }
        int fd = open(name, O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd >= 0) pending_add(name);
        if (fd >= 0 || errno != EEXIST) return fd;
    }
    return -1;
}

/* Removes a temporary or backup file and its listing. */
static void remove_pending(const char *name)
{
    unlink(name);
    pending_forget(name);
}

static void sync_dir_of(const char *target)
{
    char dir[PATH_MAX];
    mk_path_dir(target, dir, sizeof dir);
    int fd = open(dir, O_RDONLY);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
}

mk_result mk_output_open_early(mk_output *out, mk_error *err)
{
    if (out->kind == MK_OUTPUT_STREAM || out->early) return MK_OK;
    int fd = create_beside(out->target, ".tmp", out->temp, sizeof out->temp);
    if (fd < 0) {
        out->temp[0] = 0;
        return io_error(err, out->path, "cannot create a temporary file beside it", errno);
    }
    out->early = 1;
    out->fd = fd;
    out->written_from = out->written_to = 0;
    out->early_errno = 0;
    return MK_OK;
}

void mk_output_discard(mk_output *out)
{
    if (!out->early) return;
    close(out->fd);
    remove_pending(out->temp);
    out->temp[0] = 0;
    out->early = 0;
}

/* An output's bytes that are not in its temporary file yet: all of them, or those before and
 * after the range written early (while they were computed). */
static int write_rest(const mk_output *o)
{
    if (o->early_errno) {
        errno = o->early_errno;
        return -1;
    }
    const uint8_t *p = o->data;
    uint64_t from = o->written_from, to = o->written_to;
    if (from >= to || to > o->size) from = to = 0;   /* nothing written early */
    if (from && mk_write_fd_at(o->fd, p, (size_t)from, 0, NULL) != 0) return -1;
    if (mk_write_fd_at(o->fd, p + to, o->size - (size_t)to, to, NULL) != 0) return -1;
    return ftruncate(o->fd, (off_t)o->size);   /* the file is the data, nothing past it */
}

mk_result mk_write_outputs(mk_output *outs, uint32_t count, mk_error *err)
{
    mk_result r = MK_OK;
    uint32_t written = 0, renamed = 0;
    for (uint32_t i = 0; i < count; i++) {
        if (!outs[i].early) outs[i].temp[0] = 0;
        outs[i].backup[0] = 0;
    }
    /* 1. Every file's bytes into a temporary file beside its target: created now unless it was
     * opened early, and given the bytes that are not in it yet. */
    for (; written < count && r == MK_OK; written++) {
        mk_output *o = &outs[written];
        if (o->kind == MK_OUTPUT_STREAM) continue;
        if ((r = mk_output_open_early(o, err)) != MK_OK) break;
        const int fd = o->fd;
        o->early = 0;   /* its descriptor is closed below */
        int failed = write_rest(o) != 0;
        int e = errno;
        if (!failed && o->kind == MK_OUTPUT_REPLACE_FILE) (void)fchmod(fd, (mode_t)o->mode);
        if (!failed && fsync(fd) != 0) {
            failed = 1;
            e = errno;
        }
        if (close(fd) != 0 && !failed) {
            failed = 1;
            e = errno;
        }
        if (failed) r = io_error(err, o->path, "write failed", e);
    }
    /* 2. Streams (devices, FIFOs) are written directly; they cannot be taken back, so they
     * come after everything that can fail before them and before anything is renamed. */
    for (uint32_t i = 0; i < count && r == MK_OK; i++) {
        mk_output *o = &outs[i];
        if (o->kind != MK_OUTPUT_STREAM) continue;
        int fd = open(o->target, O_WRONLY | O_NOCTTY);
        if (fd < 0) {
            r = io_error(err, o->path, "cannot open", errno);
            break;
        }
        int failed = mk_write_fd(fd, o->data, o->size) != 0;
        int e = errno;
        if (close(fd) != 0 && !failed) {
            failed = 1;
            e = errno;
        }
        if (failed) r = io_error(err, o->path, "write failed", e);
    }
    /* 3. Renames into place; a replaced file keeps a hard-linked backup until all succeeded,
     * so a failed rename puts every earlier output back as it was. */
    for (; renamed < count && r == MK_OK; renamed++) {
        mk_output *o = &outs[renamed];
        if (o->kind == MK_OUTPUT_STREAM) continue;
        if (o->kind == MK_OUTPUT_REPLACE_FILE && count > 1) {
            int fd = create_beside(o->target, ".bak", o->backup, sizeof o->backup);
            if (fd >= 0) {
                close(fd);
                if (unlink(o->backup) != 0 || link(o->target, o->backup) != 0) {
                    remove_pending(o->backup);
                    o->backup[0] = 0;
                }
            } else {
                o->backup[0] = 0;
            }
        }
        if (rename(o->temp, o->target) != 0) {
            r = io_error(err, o->path, "cannot rename into place", errno);
            break;
        }
        pending_forget(o->temp);
        o->temp[0] = 0;
    }
    if (r != MK_OK) {
        for (uint32_t i = 0; i < renamed; i++) {
            mk_output *o = &outs[i];
            if (o->kind == MK_OUTPUT_STREAM) continue;
            if (o->backup[0]) {
                rename(o->backup, o->target);
                pending_forget(o->backup);
            }
            else if (o->kind == MK_OUTPUT_NEW_FILE)
                unlink(o->target);
            o->backup[0] = 0;
        }
    }
    for (uint32_t i = 0; i < count; i++) {
        if (outs[i].early) close(outs[i].fd);   /* not reached: an earlier output failed */
        outs[i].early = 0;
        if (outs[i].temp[0]) remove_pending(outs[i].temp);
        if (outs[i].backup[0]) remove_pending(outs[i].backup);
        if (r == MK_OK && outs[i].kind != MK_OUTPUT_STREAM) sync_dir_of(outs[i].target);
    }
    return r;
}

mk_result mk_write_file(const char *path, const void *data, size_t size, mk_error *err)
{
    mk_output out = { .path = path, .data = data, .size = size };
    mk_result r = mk_output_check(&out, NULL, 0, err);
    return r != MK_OK ? r : mk_write_outputs(&out, 1, err);
}

int mk_path_has_extension(const char *path, const char *extension)
{
    size_t n = strlen(path), k = strlen(extension);
    if (k > n) return 0;
    for (size_t i = 0; i < k; i++) {
        char a = path[n - k + i], b = extension[i];
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (a != b) return 0;
    }
    return 1;
}

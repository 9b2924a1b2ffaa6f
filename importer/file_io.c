/* Whole-file reads into arena memory, atomic writes (temporary file + rename), so a
 * failed or interrupted write never leaves a half-written output behind, and the
 * file-extension test shared by the importers and the CLI. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include "blob_io.h"

mk_result mk_read_file(mk_arena *arena, const char *path, size_t max_size, void **data, size_t *size, mk_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: cannot open: %s", path, strerror(errno));
    if (fseek(f, 0, SEEK_END) != 0) { fclose(f); return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: cannot seek", path); }
    long n = ftell(f);
    if (n < 0) { fclose(f); return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: cannot tell size (not a regular file?)", path); }
    if (max_size && (unsigned long)n > max_size) {
        fclose(f);
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: %ld bytes exceeds the limit of %zu bytes", path, n, max_size);
    }
    rewind(f);
    uint8_t *p = mk_arena_alloc(arena, (size_t)n + 1);
    if (!p) { fclose(f); return mk_error_oom(err, "reading a file"); }
    size_t got = fread(p, 1, (size_t)n, f);
    int failed = ferror(f);
    fclose(f);
    if (failed || got != (size_t)n) {
        mk_arena_release(arena, p);
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: read %zu of %ld bytes", path, got, n);
    }
    p[n] = 0;
    *data = p;
    *size = (size_t)n;
    return MK_OK;
}

mk_result mk_write_file_atomic(const char *path, const void *data, size_t size, mk_error *err)
{
    char tmp[4096];
    int n = snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof tmp) return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: path too long", path);
    FILE *f = fopen(tmp, "wb");
    if (!f) return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: cannot create: %s", tmp, strerror(errno));
    size_t put = size ? fwrite(data, 1, size, f) : 0;
    int failed = put != size || fflush(f) != 0 || fsync(fileno(f)) != 0;
    failed |= fclose(f) != 0;
    if (failed) {
        remove(tmp);
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: write failed (disk full?)", path);
    }
    if (rename(tmp, path) != 0) {
        int e = errno;
        remove(tmp);
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "%s: cannot rename into place: %s", path, strerror(e));
    }
    return MK_OK;
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

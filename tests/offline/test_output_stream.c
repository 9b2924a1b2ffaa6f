/* SPDX-License-Identifier: MIT */
/* Early outputs (mk_output_open_early) and the thread that writes finished parts while the rest
 * is computed (output_stream.h): whatever was written early, in whatever order the parts were
 * reported, the file that lands is exactly the data; a discarded early output leaves nothing
 * and an existing file untouched; a failed early flush fails the write and keeps the old file;
 * a signal that ends the command removes the temporary file. */
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "blob_io.h"
#include "check.h"
#include "output_stream.h"

#define DATA_SIZE ((size_t)12 << 20)

static uint8_t *make_data(uint32_t seed)
{
    uint8_t *data = malloc(DATA_SIZE);
    if (!data) return NULL;
    for (size_t i = 0; i < DATA_SIZE; i++) data[i] = (uint8_t)((seed = seed * 1664525u + 1013904223u) >> 24);
    return data;
}

static void path_of(char *path, size_t size, const char *name)
{
    snprintf(path, size, "./mk_output_stream_%s.%ld", name, (long)getpid());
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

static int same_file_as(const char *path, const uint8_t *data, size_t size)
{
    size_t n = 0;
    unsigned char *got = check_read_file(path, &n);
    int same = got && n == size && memcmp(got, data, size) == 0;
    free(got);
    return same;
}

static void sleep_ms(long ms)
{
    struct timespec t = { ms / 1000, (ms % 1000) * 1000000L };
    nanosleep(&t, NULL);
}

/* An early output at a fresh path named after `name`: a new file (old NULL) or one replacing
 * an existing file holding `old`; temp (may be NULL) receives its temporary file's name. */
static void open_early(mk_output *out, char *path, size_t path_size, const char *name, const char *old, char *temp)
{
    path_of(path, path_size, name);
    if (old) write_text(path, old);
    else unlink(path);
    *out = (mk_output){ .path = path };
    mk_error err;
    CHECK_EQ_INT(mk_output_check(out, NULL, 0, &err), MK_OK);
    CHECK_EQ_INT(out->kind, old ? MK_OUTPUT_REPLACE_FILE : MK_OUTPUT_NEW_FILE);
    CHECK_EQ_INT(mk_output_open_early(out, &err), MK_OK);
    CHECK(out->early);
    struct stat st;
    CHECK_MSG(stat(out->temp, &st) == 0, "the early temporary file %s exists", out->temp);
    if (temp) memcpy(temp, out->temp, sizeof out->temp);
}

/* Parts of the data from `first` on, 16-byte multiples of uneven sizes (as a blob's targets),
 * reported in a shuffled order, then the early bytes waited for; the output then lands whole. */
static void parts_in_any_order_land_whole(void)
{
    uint8_t *data = make_data(99);
    CHECK(data != NULL);
    if (!data) return;
    char path[256];
    mk_output out;
    open_early(&out, path, sizeof path, "whole", NULL, NULL);
    mk_error err;
    struct stat st;
    mk_output_stream *s = mk_output_stream_start(&out);
    CHECK(s != NULL);
    enum { PARTS = 40 };
    uint64_t at[PARTS + 1];
    const uint64_t first = 1234560;   /* 16-aligned, not 4096-aligned */
    at[0] = first;
    uint32_t x = 5;
    for (int i = 1; i <= PARTS; i++) {
        x = x * 1664525u + 1013904223u;
        at[i] = at[i - 1] + 16u * (4096u + (x >> 16) % 8192u);   /* 64 KB to 192 KB */
    }
    CHECK(at[PARTS] < DATA_SIZE);
    int order[PARTS];
    for (int i = 0; i < PARTS; i++) order[i] = i;
    for (int i = PARTS - 1; i > 0; i--) {
        x = x * 1664525u + 1013904223u;
        int j = (int)((x >> 8) % (uint32_t)(i + 1)), t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
    for (int i = 0; i < PARTS; i++) mk_output_stream_ready(s, data, at[order[i]], at[order[i] + 1] - at[order[i]]);
    /* The thread writes everything contiguous but its last megabyte (and anything before its
     * start); wait until it has, at most 10 s. */
    const uint64_t expect_at_least = (at[PARTS] & ~(uint64_t)4095) - ((uint64_t)1 << 20);
    for (int k = 0; k < 1000 && (stat(out.temp, &st) != 0 || (uint64_t)st.st_size < expect_at_least); k++) sleep_ms(10);
    mk_output_stream_finish(s);
    CHECK_MSG(out.written_to >= expect_at_least, "written early up to %llu, expected at least %llu",
              (unsigned long long)out.written_to, (unsigned long long)expect_at_least);
    CHECK(out.written_from >= first && out.written_from < out.written_to);
    CHECK_EQ_INT(out.written_from % 4096, 0);
    CHECK_EQ_INT(out.written_to % 4096, 0);
    /* those bytes are in the file already */
    size_t n = 0;
    unsigned char *got = check_read_file(out.temp, &n);
    CHECK(got && n >= out.written_to);
    if (got && n >= out.written_to)
        CHECK_MSG(memcmp(got + out.written_from, data + out.written_from, out.written_to - out.written_from) == 0,
                  "the early bytes differ from the data");
    free(got);
    out.data = data;
    out.size = DATA_SIZE;
    char temp[sizeof out.temp];
    memcpy(temp, out.temp, sizeof temp);
    CHECK_EQ_INT(mk_write_outputs(&out, 1, &err), MK_OK);
    CHECK_MSG(same_file_as(path, data, DATA_SIZE), "the output differs from the data");
    CHECK_MSG(stat(temp, &st) != 0, "the temporary file %s is gone", temp);
    unlink(path);
    free(data);
}

/* Nothing reported (or too little to start): the early output is still written whole. */
static void nothing_early_still_lands(void)
{
    uint8_t *data = make_data(7);
    CHECK(data != NULL);
    if (!data) return;
    char path[256];
    mk_output out;
    open_early(&out, path, sizeof path, "none", NULL, NULL);
    mk_error err;
    mk_output_stream *s = mk_output_stream_start(&out);
    mk_output_stream_ready(s, data, 4096, 1000);   /* under the thread's start size */
    mk_output_stream_finish(s);
    CHECK_EQ_INT(out.written_to, out.written_from);
    out.data = data;
    out.size = 100000;
    CHECK_EQ_INT(mk_write_outputs(&out, 1, &err), MK_OK);
    CHECK_MSG(same_file_as(path, data, 100000), "the output differs from the data");
    /* An empty early range anywhere, or one past the data, counts as nothing written early. */
    static const uint64_t ranges[][2] = { { 8192, 8192 }, { 4096, 100000 + 8192 } };
    for (int k = 0; k < 2; k++) {
        CHECK_EQ_INT(mk_output_check(&out, NULL, 0, &err), MK_OK);
        CHECK_EQ_INT(mk_output_open_early(&out, &err), MK_OK);
        out.written_from = ranges[k][0];
        out.written_to = ranges[k][1];
        out.data = data + 1 + k;
        CHECK_EQ_INT(mk_write_outputs(&out, 1, &err), MK_OK);
        CHECK_MSG(same_file_as(path, data + 1 + k, 100000), "range %d: the output differs from the data", k);
    }
    unlink(path);
    free(data);
}

/* A discarded early output (the command failed) leaves the existing file as it was and no
 * temporary file. */
static void discard_leaves_nothing(void)
{
    static mk_output out;
    char path[256], temp[sizeof out.temp];
    open_early(&out, path, sizeof path, "discard", "keep me", temp);
    mk_output_discard(&out);
    struct stat st;
    CHECK_MSG(stat(temp, &st) != 0, "the temporary file %s is gone", temp);
    CHECK(!out.early);
    CHECK_MSG(same_file_as(path, (const uint8_t *)"keep me", 7), "the existing file is untouched");
    unlink(path);
}

/* A flush of the early bytes that failed fails the write with its error: the old file stays. */
static void failed_flush_fails_the_write(void)
{
    static mk_output out;
    char path[256], temp[sizeof out.temp];
    open_early(&out, path, sizeof path, "flush", "old", temp);
    out.early_errno = EIO;   /* as the stream's finish leaves it after a failed fdatasync */
    out.data = "new";
    out.size = 3;
    mk_error err;
    CHECK_EQ_INT(mk_write_outputs(&out, 1, &err), MK_ERROR_IO);
    CHECK_MSG(strstr(err.message, "write failed") != NULL, "message: %s", err.message);
    CHECK_MSG(same_file_as(path, (const uint8_t *)"old", 3), "the old file stays");
    struct stat st;
    CHECK_MSG(stat(temp, &st) != 0, "the temporary file %s is gone", temp);
    unlink(path);
}

/* A stream output (a device) is never opened early: it is written whole at the end. */
static void devices_are_not_early(void)
{
    struct stat st;
    if (stat("/dev/null", &st) != 0) return;
    mk_output out = { .path = "/dev/null" };
    mk_error err;
    CHECK_EQ_INT(mk_output_check(&out, NULL, 0, &err), MK_OK);
    CHECK_EQ_INT(mk_output_open_early(&out, &err), MK_OK);
    CHECK(!out.early);
    CHECK(mk_output_stream_start(&out) == NULL);
    mk_output_stream_ready(NULL, "x", 0, 1);   /* a NULL stream ignores reports */
    mk_output_stream_finish(NULL);
}

/* A command interrupted while its output is being written (mk_output_cleanup_on_signals):
 * the signal still ends the process, and the early temporary file is gone; an ignored signal
 * stays ignored. */
static void signals_remove_temporary_files(void)
{
    static const int sigs[] = { SIGTERM, SIGINT };
    for (int k = 0; k < 2; k++) {
        int link_fds[2];
        CHECK(pipe(link_fds) == 0);
        pid_t child = fork();
        CHECK(child >= 0);
        if (child == 0) {
            close(link_fds[0]);
            mk_output_cleanup_on_signals();
            static mk_output out;
            char path[256];
            path_of(path, sizeof path, "signal");
            out = (mk_output){ .path = path };
            mk_error err;
            if (mk_output_check(&out, NULL, 0, &err) != MK_OK || mk_output_open_early(&out, &err) != MK_OK) _exit(3);
            if (write(link_fds[1], out.temp, strlen(out.temp) + 1) < 0) _exit(4);
            raise(sigs[k]);
            _exit(5);   /* not reached: the signal ends the process */
        }
        close(link_fds[1]);
        char temp[4300] = "";
        ssize_t n = read(link_fds[0], temp, sizeof temp - 1);
        close(link_fds[0]);
        int status = 0;
        CHECK(waitpid(child, &status, 0) == child);
        CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == sigs[k], "signal %d: the child ended by status %d",
                  sigs[k], status);
        CHECK(n > 0);
        struct stat st;
        CHECK_MSG(n > 0 && stat(temp, &st) != 0, "signal %d: the temporary file %s was left", sigs[k], temp);
        if (n > 0) unlink(temp);
    }
    /* An ignored SIGHUP (nohup) stays ignored. */
    pid_t child = fork();
    CHECK(child >= 0);
    if (child == 0) {
        signal(SIGHUP, SIG_IGN);
        mk_output_cleanup_on_signals();
        raise(SIGHUP);
        _exit(0);
    }
    int status = -1;
    CHECK(waitpid(child, &status, 0) == child);
    CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "an ignored SIGHUP ended the process (status %d)", status);
}

CHECK_MAIN(CASE(parts_in_any_order_land_whole), CASE(signals_remove_temporary_files), CASE(nothing_early_still_lands), CASE(discard_leaves_nothing),
           CASE(failed_flush_fails_the_write), CASE(devices_are_not_early))

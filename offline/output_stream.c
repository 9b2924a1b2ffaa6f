/* SPDX-License-Identifier: MIT */
/* Writing an output's finished parts early (output_stream.h).
 *
 * The parts reported ready are kept merged (adjacent parts join: a mesh's targets lie back to
 * back). The thread writes one range of the file, [from, to): it starts at the first ready
 * part with at least STREAM_MIN bytes of whole 4096-byte blocks and grows while the ready
 * bytes right after it do, in pieces of 4096-byte blocks (so they go around the page cache:
 * file_write.c) of at most STREAM_PIECE bytes, whenever at least STREAM_MIN such bytes are
 * ready past its end (the last, shorter stretch is left for the end).
 * Everything else is written by mk_write_outputs at the end: the header, tables and entries,
 * which are final last; parts that were ready too late; a mesh's data after the first one's. */
#include <errno.h>
#include <stdlib.h>
#include <threads.h>
#include <unistd.h>
#include "file_write.h"
#include "output_stream.h"

#define STREAM_ALIGN ((uint64_t)4096)
#define STREAM_MIN ((uint64_t)1 << 20)
#define STREAM_PIECE ((uint64_t)4 << 20)
#define STREAM_SYNC ((uint64_t)8 << 20)

typedef struct range {
    uint64_t from, to;
} range;

struct mk_output_stream {
    mk_output *out;
    mtx_t lock;
    cnd_t wake;
    thrd_t thread;
    const uint8_t *blob;
    range *ready;                  /* sorted, disjoint, adjacent parts merged */
    uint32_t ready_count, ready_capacity;
    uint64_t from, to;             /* written so far */
    uint64_t unsynced;             /* of it, bytes written since the last flush */
    int started, stop, failed;     /* failed: a write or a bookkeeping allocation failed */
    int sync_errno;                /* a flush failed: the output fails with this error */
};

static uint64_t align_up(uint64_t n) { return (n + STREAM_ALIGN - 1) & ~(STREAM_ALIGN - 1); }
static uint64_t align_down(uint64_t n) { return n & ~(STREAM_ALIGN - 1); }

/* Adds [from, to) to the sorted ready list, merging it with adjacent parts. */
static int add_ready(mk_output_stream *s, uint64_t from, uint64_t to)
{
    uint32_t i = 0;
    while (i < s->ready_count && s->ready[i].to < from) i++;
    if (i < s->ready_count && s->ready[i].to == from) {          /* extends part i */
        s->ready[i].to = to;
        if (i + 1 < s->ready_count && s->ready[i + 1].from == to) { /* and joins part i + 1 */
            s->ready[i].to = s->ready[i + 1].to;
            for (uint32_t k = i + 1; k + 1 < s->ready_count; k++) s->ready[k] = s->ready[k + 1];
            s->ready_count--;
        }
        return 0;
    }
    if (i < s->ready_count && s->ready[i].from == to) {          /* precedes part i */
        s->ready[i].from = from;
        return 0;
    }
    if (s->ready_count == s->ready_capacity) {
        uint32_t capacity = s->ready_capacity ? 2 * s->ready_capacity : 64;
        range *grown = realloc(s->ready, capacity * sizeof *grown);
        if (!grown) return -1;
        s->ready = grown;
        s->ready_capacity = capacity;
    }
    for (uint32_t k = s->ready_count; k > i; k--) s->ready[k] = s->ready[k - 1];
    s->ready[i] = (range){ from, to };
    s->ready_count++;
    return 0;
}

/* The next piece to write, [s->to, *end); 0 when there is none yet. */
static int next_piece(mk_output_stream *s, uint64_t *end)
{
    if (!s->started) {
        for (uint32_t i = 0; i < s->ready_count; i++) {
            uint64_t a = align_up(s->ready[i].from), b = align_down(s->ready[i].to);
            if (b > a && b - a >= STREAM_MIN) {
                s->from = s->to = a;
                s->started = 1;
                break;
            }
        }
        if (!s->started) return 0;
    }
    for (uint32_t i = 0; i < s->ready_count; i++) {
        if (s->ready[i].from > s->to || s->ready[i].to <= s->to) continue;
        uint64_t b = align_down(s->ready[i].to);
        if (b <= s->to || b - s->to < STREAM_MIN) return 0;
        *end = b - s->to > STREAM_PIECE ? s->to + STREAM_PIECE : b;
        return 1;
    }
    return 0;
}

static int stream_thread(void *arg)
{
    mk_output_stream *s = arg;
    mtx_lock(&s->lock);
    while (!s->stop && !s->failed) {
        uint64_t end;
        if (!next_piece(s, &end)) {
            cnd_wait(&s->wake, &s->lock);
            continue;
        }
        const uint64_t at = s->to;
        mtx_unlock(&s->lock);
        int ok = mk_write_fd_at(s->out->fd, s->blob + at, (size_t)(end - at), at, NULL) == 0;
        mtx_lock(&s->lock);
        if (!ok) {
            s->failed = 1;
            break;
        }
        s->to = end;
        s->unsynced += end - at;
        if (s->unsynced >= STREAM_SYNC) {
            /* Flushed as it goes: what a flush costs grows with the bytes since the last one,
             * and here it overlaps the computation instead of following it. */
            mtx_unlock(&s->lock);
            int e = fdatasync(s->out->fd) == 0 ? 0 : errno;
            mtx_lock(&s->lock);
            s->unsynced = 0;
            if (e) {
                s->sync_errno = e;
                s->failed = 1;
            }
        }
    }
    mtx_unlock(&s->lock);
    return 0;
}

mk_output_stream *mk_output_stream_start(mk_output *out)
{
    if (!out->early) return NULL;
    mk_output_stream *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->out = out;
    int locks = 0;
    if (mtx_init(&s->lock, mtx_plain) == thrd_success) {
        locks = 1;
        if (cnd_init(&s->wake) == thrd_success) {
            locks = 2;
            if (thrd_create(&s->thread, stream_thread, s) == thrd_success) return s;
        }
    }
    if (locks == 2) cnd_destroy(&s->wake);
    if (locks) mtx_destroy(&s->lock);
    free(s);
    return NULL;
}

void mk_output_stream_ready(void *user, const void *blob, uint64_t offset, uint64_t size)
{
    mk_output_stream *s = user;
    if (!s || !size) return;
    mtx_lock(&s->lock);
    if (!s->blob) s->blob = blob;
    if (s->blob != blob || add_ready(s, offset, offset + size) != 0) s->failed = 1;   /* stops early writing */
    cnd_signal(&s->wake);
    mtx_unlock(&s->lock);
}

void mk_output_stream_finish(mk_output_stream *s)
{
    if (!s) return;
    mtx_lock(&s->lock);
    s->stop = 1;
    cnd_signal(&s->wake);
    mtx_unlock(&s->lock);
    thrd_join(s->thread, NULL);
    s->out->written_from = s->started ? s->from : 0;
    s->out->written_to = s->started ? s->to : 0;
    s->out->early_errno = s->sync_errno;
    cnd_destroy(&s->wake);
    mtx_destroy(&s->lock);
    free(s->ready);
    free(s);
}

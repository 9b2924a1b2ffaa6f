/* SPDX-License-Identifier: MIT */
#define _POSIX_C_SOURCE 200809L
#include "phase_log.h"
#include <string.h>
#include <time.h>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/resource.h>
#endif

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static double peak_resident_bytes(void)
{
#if defined(__unix__) || defined(__APPLE__)
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
#if defined(__APPLE__)
    return (double)ru.ru_maxrss;          /* bytes */
#else
    return (double)ru.ru_maxrss * 1024.0; /* kilobytes */
#endif
#else
    return 0;
#endif
}

void mk_phase_log_start(mk_phase_log *log)
{
    if (!log) return;
    memset(log, 0, sizeof *log);
    log->started = log->last_mark = now_seconds();
}

void mk_phase_log_mark(mk_phase_log *log, const char *name)
{
    if (!log || !name) return;
    double t = now_seconds();
    uint32_t i = 0;
    while (i < log->count && strcmp(log->phases[i].name, name) != 0) i++;
    if (i == log->count) {
        if (log->count == MK_PHASE_MAX) i = MK_PHASE_MAX - 1;  /* full: the last line collects the rest */
        else log->phases[log->count++].name = name;
    }
    log->phases[i].seconds += t - log->last_mark;
    log->phases[i].peak_bytes = peak_resident_bytes();
    log->last_mark = t;
}

void mk_phase_log_print(const mk_phase_log *log, FILE *out)
{
    if (!log || !out) return;
    double total = log->last_mark - log->started;
    fprintf(out, "%-22s %9s %6s %14s\n", "phase", "seconds", "share", "peak memory");
    double peak = 0;
    for (uint32_t i = 0; i < log->count; i++) {
        const mk_phase *p = &log->phases[i];
        if (p->peak_bytes > peak) peak = p->peak_bytes;
        fprintf(out, "%-22s %9.3f %5.1f%% %11.1f MB\n", p->name, p->seconds,
                total > 0 ? 100.0 * p->seconds / total : 0.0, p->peak_bytes / 1e6);
    }
    fprintf(out, "%-22s %9.3f %6s %11.1f MB\n", "total", total, "", peak / 1e6);
}

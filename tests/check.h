/* SPDX-License-Identifier: MIT */
/* A tiny test harness: plain C, one runner per test program, a closing summary line
 * "N passed, N failed" (the format CI reads). A test case is a function; CHECK records a
 * failure with file:line and keeps going, so one run shows every broken property. */
#ifndef MK_CHECK_H
#define MK_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct check_state {
    int failures;      /* failed CHECKs in the current case */
    int cases_passed, cases_failed, cases_skipped;
    const char *current;
} check_state;

extern check_state check_global;

#define CHECK(cond) do { if (!(cond)) { check_global.failures++; \
    fprintf(stderr, "%s:%d: %s: CHECK(%s) failed\n", __FILE__, __LINE__, check_global.current, #cond); } } while (0)
#define CHECK_MSG(cond, ...) do { if (!(cond)) { check_global.failures++; \
    fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, check_global.current); \
    fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); } } while (0)
#define CHECK_NEAR(a, b, tol) do { double check_a_ = (double)(a), check_b_ = (double)(b); \
    if (!(fabs(check_a_ - check_b_) <= (tol))) { check_global.failures++; \
    fprintf(stderr, "%s:%d: %s: %s = %.9g, expected %s = %.9g (tol %g)\n", __FILE__, __LINE__, \
            check_global.current, #a, check_a_, #b, check_b_, (double)(tol)); } } while (0)
#define CHECK_EQ_INT(a, b) do { long long check_a_ = (long long)(a), check_b_ = (long long)(b); \
    if (check_a_ != check_b_) { check_global.failures++; \
    fprintf(stderr, "%s:%d: %s: %s = %lld, expected %lld\n", __FILE__, __LINE__, \
            check_global.current, #a, check_a_, check_b_); } } while (0)

/* A case calls SKIP("why") when a resource (e.g. the corpus) is missing: counted as skipped. */
#define SKIP(...) do { check_global.failures = -1; fprintf(stderr, "skip: %s: ", check_global.current); \
    fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); return; } while (0)

typedef struct check_case { const char *name; void (*fn)(void); } check_case;

/* Runs the cases (argv[1], if given, keeps only names containing it; "-text" keeps the names
 * that do not contain text) and prints the summary.
 * Exit: 0 if none failed (77, meson's "skipped", if all were skipped), else 1. */
int check_run(const check_case *cases, int count, int argc, char **argv);

/* Path of the shared corpus: $MORPHKIT_CORPUS, else ../shared/corpus from the source root. */
const char *check_corpus_dir(void);
/* Reads a whole file into malloc'ed memory (NULL if missing). */
unsigned char *check_read_file(const char *path, size_t *size);

#define CHECK_MAIN(...) \
    int main(int argc, char **argv) { static const check_case cases_[] = { __VA_ARGS__ }; \
        return check_run(cases_, (int)(sizeof cases_ / sizeof cases_[0]), argc, argv); }
#define CASE(fn) { #fn, fn }

#endif

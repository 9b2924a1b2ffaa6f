/* SPDX-License-Identifier: MIT */
#include "check.h"

check_state check_global;

int check_run(const check_case *cases, int count, int argc, char **argv)
{
    const char *filter = argc > 1 ? argv[1] : NULL;
    const int exclude = filter && filter[0] == '-';   /* "-text": every case but those */
    for (int i = 0; i < count; i++) {
        if (filter && (exclude ? strstr(cases[i].name, filter + 1) != NULL : !strstr(cases[i].name, filter))) continue;
        check_global.current = cases[i].name;
        check_global.failures = 0;
        cases[i].fn();
        if (check_global.failures < 0) {
            check_global.cases_skipped++;
            printf("skip %s\n", cases[i].name);
        } else if (check_global.failures == 0) {
            check_global.cases_passed++;
            printf("ok   %s\n", cases[i].name);
        } else {
            check_global.cases_failed++;
            printf("FAIL %s (%d checks)\n", cases[i].name, check_global.failures);
        }
        fflush(stdout);
    }
    printf("%d passed, %d failed, %d skipped\n", check_global.cases_passed,
           check_global.cases_failed, check_global.cases_skipped);
    if (check_global.cases_failed) return 1;
    if (check_global.cases_passed == 0 && check_global.cases_skipped > 0) return 77;
    return 0;
}

const char *check_corpus_dir(void)
{
    const char *env = getenv("MORPHKIT_CORPUS");
    if (env && *env) return env;
    return MK_SOURCE_ROOT "/../shared/corpus";
}

unsigned char *check_read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) != 0) { fclose(f); return NULL; }
    long n = ftell(f);
    if (n < 0) { fclose(f); return NULL; }
    rewind(f);
    unsigned char *data = malloc((size_t)n + 1);
    if (data && fread(data, 1, (size_t)n, f) != (size_t)n) { free(data); data = NULL; }
    fclose(f);
    if (data) { data[n] = 0; if (size) *size = (size_t)n; }
    return data;
}

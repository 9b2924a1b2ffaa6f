/* SPDX-License-Identifier: MIT */
/* samples/recipes/tube_source.gltf is what samples/make_tube_source writes: regenerated in the
 * build folder, byte for byte the committed file.
 * usage (from meson): test_tube_source MAKE_TUBE_SOURCE COMMITTED.gltf WORK_DIR */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"

static const char *program, *committed, *work;

static void regenerated_file_is_the_committed_one(void)
{
    char out[1024], cmd[4096];
    snprintf(out, sizeof out, "%s/tube_source_regenerated.gltf", work);
    remove(out);
    snprintf(cmd, sizeof cmd, "\"%s\" \"%s\" > /dev/null", program, out);
    CHECK_EQ_INT(system(cmd), 0);
    size_t n_new = 0, n_old = 0;
    unsigned char *made = check_read_file(out, &n_new), *kept = check_read_file(committed, &n_old);
    CHECK_MSG(made && kept, "cannot read %s or %s", out, committed);
    if (made && kept) {
        size_t i = 0;
        while (i < n_new && i < n_old && made[i] == kept[i]) i++;
        CHECK_MSG(n_new == n_old && i == n_new, "%s (%zu bytes) differs from %s (%zu bytes) from byte %zu on", out, n_new,
                  committed, n_old, i);
    }
    free(made);
    free(kept);
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: test_tube_source MAKE_TUBE_SOURCE COMMITTED.gltf WORK_DIR\n");
        return 2;
    }
    program = argv[1];
    committed = argv[2];
    work = argv[3];
    static const check_case cases[] = { CASE(regenerated_file_is_the_committed_one) };
    return check_run(cases, 1, 1, argv);
}

/* SPDX-License-Identifier: MIT */
#include "corpus_cases.h"
#include <stdio.h>

int check_corpus_manifest(pb_manifest *manifest)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/cases.json", check_corpus_dir());
    mk_error err;
    if (pb_manifest_read(path, manifest, &err) == MK_OK) return 0;
    pb_manifest_free(manifest);
    return -1;
}

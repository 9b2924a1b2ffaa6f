/* SPDX-License-Identifier: MIT */
/* The shared corpus's case list for tests: read once per case, SKIP when the corpus is absent. */
#ifndef MK_TESTS_CORPUS_CASES_H
#define MK_TESTS_CORPUS_CASES_H

#include "check.h"
#include "manifest.h"

/* Reads check_corpus_dir()/cases.json into *manifest; 0 when read, -1 when the corpus is
 * absent or unreadable (the manifest is then freed). */
int check_corpus_manifest(pb_manifest *manifest);

/* In a test case: the manifest, or SKIP the case when the corpus is absent. */
#define CHECK_CORPUS_MANIFEST(manifest) do { \
    if (check_corpus_manifest(manifest) != 0) SKIP("corpus not found at %s", check_corpus_dir()); } while (0)

#endif

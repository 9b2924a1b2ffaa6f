/* SPDX-License-Identifier: MIT */
/* One version: the header's MK_VERSION_* agree with the project version meson reads from
 * VERSION (passed in as MK_PROJECT_VERSION), and the library reports the header's number. */
#include <stdio.h>
#include <string.h>
#include "check.h"
#include "morphkit.h"

static void test_header_matches_project(void)
{
    char numbers[32];
    snprintf(numbers, sizeof numbers, "%d.%d.%d", MK_VERSION_MAJOR, MK_VERSION_MINOR, MK_VERSION_PATCH);
    CHECK_MSG(!strcmp(numbers, MK_PROJECT_VERSION), "morphkit.h says %s, VERSION says %s", numbers, MK_PROJECT_VERSION);
    CHECK_MSG(!strcmp(MK_VERSION_STRING, MK_PROJECT_VERSION), "MK_VERSION_STRING %s, VERSION %s", MK_VERSION_STRING,
              MK_PROJECT_VERSION);
    CHECK_EQ_INT(MK_VERSION, MK_VERSION_MAJOR * 10000 + MK_VERSION_MINOR * 100 + MK_VERSION_PATCH);
}

static void test_library_matches_header(void) { CHECK_EQ_INT(mk_version(), MK_VERSION); }

CHECK_MAIN(CASE(test_header_matches_project), CASE(test_library_matches_header))

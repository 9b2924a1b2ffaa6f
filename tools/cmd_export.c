/* Placeholder until glTF export lands (issue #4). */
#include "cli.h"

int cmd_export(int argc, char **argv)
{
    (void)argc; (void)argv;
    fprintf(stderr, "morphkit export: glTF export is not implemented yet\n");
    return 2;
}

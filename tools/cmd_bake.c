/* Placeholder until the bakers land (issue #5). */
#include "cli.h"

int cmd_bake(int argc, char **argv)
{
    (void)argc; (void)argv;
    fprintf(stderr, "morphkit bake: baking is not implemented yet\n");
    return 2;
}

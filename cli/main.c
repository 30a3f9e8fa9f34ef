/*
 * main.c - the paprsek program: dispatches to the subcommands. Built on the
 * public header alone.
 */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static void usage(FILE *f)
{
    fputs("usage: paprsek <command> [options]\n"
          "\n"
          "commands:\n"
          "  render [SCENE] -o OUT     render a scene (.obj or .json; the built-in Cornell box\n"
          "                            when SCENE is omitted) to OUT (.png or .pfm)\n"
          "  bench rays SCENE RAYS     time an accelerator on a ray file\n"
          "  bench gen-rays SCENE ...  make the standard ray files\n"
          "  bench compare A B         check that two hit files agree\n"
          "  help, --help              this text; `paprsek render --help` for render options\n"
          "  --version                 print the version\n",
          f);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "render") == 0) return cli_render(argc - 1, argv + 1);
    if (strcmp(cmd, "bench") == 0) return cli_bench(argc - 1, argv + 1);
    if (strcmp(cmd, "help") == 0 || strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(cmd, "--version") == 0) {
        printf("paprsek %s\n", PK_VERSION_STRING);
        return 0;
    }
    fprintf(stderr, "paprsek: unknown command '%s' (see paprsek --help)\n", cmd);
    return 2;
}

/*
 * main.c - the paprsek program: dispatches to the subcommands. Built on the
 * public header alone.
 */
#include "cli.h"
#if PK_HAVE_VIEW
#include "view_server.h"
#endif

#include <stdio.h>
#include <string.h>

static void usage(FILE *f)
{
    fputs("usage: paprsek <command> [options]\n"
          "\n"
          "commands:\n"
          "  render [SCENE] -o OUT     render a scene (.obj, .json, .xml, .pbrt, .gltf or .glb;\n"
          "                            without SCENE the built-in Cornell box) to OUT (.png,\n"
          "                            .pfm or .exr)\n"
          "  view [SCENE]              render a scene progressively in the browser: move the\n"
          "                            camera, focus, expose, save (serves http://127.0.0.1)\n"
          "  denoise IN -o OUT         denoise a rendered image (its albedo and normal too)\n"
          "  convert SCENE -o OUT.json write any scene as a Paprsek JSON scene that renders\n"
          "                            the same image\n"
          "  bench rays SCENE RAYS     time an accelerator on a ray file\n"
          "  bench gen-rays SCENE ...  make the standard ray files\n"
          "  bench compare A B         check that two hit files agree\n"
          "  help [COMMAND]            this text, or a command's options (as COMMAND --help)\n"
          "  -h, --help                this text\n"
          "  -v, --version             print the version\n"
          "\n"
          "exit status: 0 success; 1 a runtime failure (a file that cannot be read or\n"
          "written, a malformed scene, a scene beyond the limits); 2 a usage error\n"
          "(unknown option or command, bad value, unknown image format); 130 and 143 a\n"
          "render interrupted by SIGINT and SIGTERM.\n",
          f);
}

static const char *const commands[] = {"render", "view", "denoise", "convert", "bench", "help"};

#if !PK_HAVE_VIEW
static int view_missing(void)
{
    return cli_failure("view: not built in: the viewer needs GNU libmicrohttpd (Debian: libmicrohttpd-dev); "
                       "install it and rebuild");
}
#endif
#define NCOMMANDS (sizeof commands / sizeof commands[0])

static int unknown_command(const char *cmd)
{
    const char *near = cli_nearest(cmd, strlen(cmd), commands, NCOMMANDS);
    if (near) return cli_usage_error("unknown command '%s'; did you mean %s?", cmd, near);
    return cli_usage_error("unknown command '%s' (see paprsek --help)", cmd);
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
    if (strcmp(cmd, "denoise") == 0) return cli_denoise(argc - 1, argv + 1);
    if (strcmp(cmd, "convert") == 0) return cli_convert(argc - 1, argv + 1);
#if PK_HAVE_VIEW
    if (strcmp(cmd, "view") == 0) return cli_view(argc - 1, argv + 1);
#else
    if (strcmp(cmd, "view") == 0) return view_missing();
#endif
    if (strcmp(cmd, "help") == 0) {
        if (argc < 3) {
            usage(stdout);
            return 0;
        }
        if (argc > 3) return cli_usage_error("help takes one command, not %d words", argc - 2);
        if (strcmp(argv[2], "render") == 0) {
            cli_render_help(stdout);
            return 0;
        }
        if (strcmp(argv[2], "bench") == 0) {
            cli_bench_help(stdout);
            return 0;
        }
        if (strcmp(argv[2], "denoise") == 0) {
            cli_denoise_help(stdout);
            return 0;
        }
        if (strcmp(argv[2], "convert") == 0) {
            cli_convert_help(stdout);
            return 0;
        }
        if (strcmp(argv[2], "view") == 0) {
#if PK_HAVE_VIEW
            cli_view_help(stdout);
            return 0;
#else
            return view_missing();
#endif
        }
        if (strcmp(argv[2], "help") == 0) {
            usage(stdout);
            return 0;
        }
        return unknown_command(argv[2]);
    }
    if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(cmd, "--version") == 0 || strcmp(cmd, "-v") == 0) {
        printf("paprsek %s\n", PK_VERSION_STRING);
        return 0;
    }
    if (cmd[0] == '-') {
        static const char *const flags[] = {"help", "version"};
        const char *name = cmd + (cmd[1] == '-' ? 2 : 1);
        const char *near = cli_nearest(name, strlen(name), flags, 2);
        if (near) return cli_usage_error("unknown option '%s'; did you mean --%s?", cmd, near);
        return cli_usage_error("unknown option '%s' (see paprsek --help)", cmd);
    }
    return unknown_command(cmd);
}

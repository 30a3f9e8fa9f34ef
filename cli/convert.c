/*
 * convert.c - `paprsek convert SCENE -o OUT.json`: any scene the library
 * reads, written as a Paprsek JSON scene (pk_scene_write_json) that renders
 * the same bytes.
 */
#include "cli.h"

#include <stdio.h>
#include <string.h>

enum { C_OUTPUT = 1, C_DEFINE, C_CONFIG, C_QUIET, C_HELP };

static const cli_option c_opts[] = {
    {.name = "output", .short_name = 'o', .id = C_OUTPUT, .kind = CLI_STRING, .arg = "FILE",
     .help = "the JSON scene to write (required; .json); its meshes, images and grids are written beside it as "
             "FILE's name with .meshN.ply, .textureN.bin, ... (existing files of those names are replaced)"},
    {.name = "define", .short_name = 'D', .id = C_DEFINE, .kind = CLI_STRING, .arg = "NAME=VALUE",
     .help = "a parameter of the scene, as for paprsek render (Mitsuba's $NAME, glTF's camera=N and variant=NAME); repeatable"},
    {.name = "config", .id = C_CONFIG, .kind = CLI_STRING, .arg = "KEY=VALUE,...",
     .help = "library configuration, as for paprsek render; render the converted scene with the same "
             "scene.instances"},
    {.name = "quiet", .short_name = 'q', .id = C_QUIET, .kind = CLI_FLAG, .help = "no warnings"},
    {.name = "help", .short_name = 'h', .id = C_HELP, .kind = CLI_FLAG, .help = "this text"},
};
#define C_NOPTS (sizeof c_opts / sizeof c_opts[0])

void cli_convert_help(FILE *f)
{
    fputs("usage: paprsek convert SCENE -o OUT.json [options]\n"
          "\n"
          "Writes SCENE (.obj, .json, .xml, .pbrt, .gltf or .glb) as a Paprsek JSON\n"
          "scene (docs/scene-format.md, \"Records\"): the scene as loaded, its\n"
          "triangles in binary PLY files beside OUT (instances that the renderer\n"
          "keeps stay instances), its materials, lights, media and environment\n"
          "field by field, and every number written so that it reads back bit for\n"
          "bit. Rendering OUT with the same options gives the same image, byte for\n"
          "byte. The files are written under temporary names and renamed into\n"
          "place at the end: on failure nothing is left.\n"
          "\n"
          "options:\n",
          f);
    cli_print_options(f, c_opts, C_NOPTS);
    fputs("\nexit status: 0 the scene was written; 1 a runtime failure (a scene that cannot\n"
          "be read, or written as JSON, a file that cannot be written); 2 a usage error.\n",
          f);
}

static int ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), e = strlen(ext);
    return n >= e && strcmp(s + n - e, ext) == 0;
}

int cli_convert(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *config = NULL;
    const char *defines[64];
    size_t ndefines = 0;
    int quiet = 0;
    cli_parser p;
    cli_parser_init(&p, "convert", c_opts, C_NOPTS, argc, argv);
    int r;
    while ((r = cli_next(&p)) != CLI_END) {
        if (r == CLI_ERROR) return 2;
        if (r == CLI_ARGUMENT) {
            if (in) return cli_usage_error("convert: more than one scene ('%s' and '%s')", in, p.value);
            in = p.value;
            continue;
        }
        switch (c_opts[p.index].id) {
        case C_OUTPUT: out = p.value; break;
        case C_DEFINE:
            if (!strchr(p.value, '=')) return cli_usage_error("-D: expected NAME=VALUE, not '%s'", p.value);
            if (ndefines == sizeof defines / sizeof defines[0]) return cli_usage_error("-D: at most 64 parameters");
            defines[ndefines++] = p.value;
            break;
        case C_CONFIG: config = p.value; break;
        case C_QUIET: quiet = 1; break;
        case C_HELP: cli_convert_help(stdout); return 0;
        }
    }
    if (!in) return cli_usage_error("convert: no scene (paprsek convert SCENE -o OUT.json)");
    if (!out) return cli_usage_error("convert: no output file (-o OUT.json)");
    if (!ends_with(out, ".json")) return cli_usage_error("convert: %s: the output is a JSON scene (.json)", out);
    if (config && cli_check_config(config)) return 2;
    if (cli_check_output(out, 1)) return 1;

    pk_context *ctx;
    if (pk_context_create(NULL, &ctx) != PK_OK) return cli_failure("out of memory");
    if (!quiet) pk_context_set_warning_handler(ctx, cli_print_warning, NULL);
    int rc = cli_configure(ctx, config);
    pk_scene *scene = NULL;
    if (rc) goto out;
    if (pk_scene_load_file_params(ctx, in, ndefines ? defines : NULL, ndefines, &scene) != PK_OK ||
        pk_scene_write_json(ctx, scene, out) != PK_OK)
        rc = cli_fail_ctx(ctx);
out:
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return rc;
}

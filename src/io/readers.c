/*
 * readers.c - the scene formats as a table: each row names a format, the
 * file extensions that choose it, the folder its relative files come from
 * when a memory buffer has none, and the reader's door. The library's
 * loaders (api.c) and the command line find formats here, so a new format
 * is one row and one parser.
 */
#include "readers.h"

#include <string.h>

static pk_status parse_obj(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                           const char *base_dir, const char *const *params, size_t nparams)
{
    (void)params, (void)nparams;
    return obj_parse(ctx, s, data, size, name, base_dir, NULL);
}

static pk_status parse_json(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                            const char *base_dir, const char *const *params, size_t nparams)
{
    (void)params, (void)nparams;
    return scene_json_parse(ctx, s, data, size, name, base_dir);
}

static pk_status parse_pbrt(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                            const char *base_dir, const char *const *params, size_t nparams)
{
    (void)params, (void)nparams;
    return scene_pbrt_parse(ctx, s, data, size, name, base_dir);
}

/* base_dir NULL for OBJ: its material libraries are not read (a buffer
 * with no folder); the others read their files from the current folder. */
static const scene_reader readers[] = {
    {"obj", {".obj"}, NULL, parse_obj},
    {"json", {".json"}, ".", parse_json},
    {"xml", {".xml"}, ".", scene_xml_parse},
    {"pbrt", {".pbrt"}, ".", parse_pbrt},
    {"gltf", {".gltf", ".glb"}, ".", scene_gltf_parse_params},
};

/* Whether path ends with ext, ignoring ASCII case. */
static bool ends_with(const char *path, const char *ext)
{
    const size_t lp = strlen(path), le = strlen(ext);
    if (lp < le) return false;
    const char *p = path + lp - le;
    for (size_t i = 0; i < le; i++) {
        char c = p[i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != ext[i]) return false;
    }
    return true;
}

const scene_reader *scene_reader_for_path(const char *path)
{
    for (size_t i = 0; i < sizeof readers / sizeof readers[0]; i++)
        for (int k = 0; k < SCENE_READER_EXTS && readers[i].exts[k]; k++)
            if (ends_with(path, readers[i].exts[k])) return &readers[i];
    return NULL;
}

const scene_reader *scene_reader_named(const char *format)
{
    for (size_t i = 0; i < sizeof readers / sizeof readers[0]; i++) {
        if (strcmp(readers[i].name, format) == 0) return &readers[i];
        for (int k = 0; k < SCENE_READER_EXTS && readers[i].exts[k]; k++)
            if (strcmp(readers[i].exts[k] + 1, format) == 0) return &readers[i];
    }
    return NULL;
}

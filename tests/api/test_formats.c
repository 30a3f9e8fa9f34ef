/*
 * test_formats.c - the table of scene formats: pk_scene_format names the
 * format a path's extension chooses (case ignored, only at the end), and
 * pk_scene_load_memory reads every format from a buffer into the same scene
 * as pk_scene_load_file reads from the file: the two render the same bytes.
 * An unknown format is refused with a message and no scene.
 */
#include "paprsek.h"
#include "test.h"

#include <stdio.h>

static pk_context *ctx;

/* The whole file at path (malloc'd), its size in *size. */
static char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    REQUIRE(fseek(f, 0, SEEK_END) == 0);
    long n = ftell(f);
    REQUIRE(n >= 0 && fseek(f, 0, SEEK_SET) == 0);
    char *b = malloc((size_t)n + 1);
    REQUIRE(b && fread(b, 1, (size_t)n, f) == (size_t)n);
    fclose(f);
    *size = (size_t)n;
    return b;
}

/* The scene rendered at 24x24, 2 samples a pixel. */
static pk_image *render(const pk_scene *s)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = 24;
    o.spp = 2;
    o.threads = 1;
    pk_image *img = NULL;
    CHECKF(pk_render(ctx, s, &o, &img, NULL) == PK_OK, "%s", pk_context_error(ctx));
    return img;
}

static void check_same(const char *file, const char *want_format)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", PK_TEST_DATA, file);
    const char *format = pk_scene_format(path);
    CHECKF(format && strcmp(format, want_format) == 0, "%s: %s", file, format ? format : "(none)");
    if (!format) return;
    pk_scene *a = NULL, *b = NULL;
    CHECKF(pk_scene_load_file(ctx, path, &a) == PK_OK, "%s", pk_context_error(ctx));
    size_t size;
    char *data = slurp(path, &size);
    char dir[512];
    snprintf(dir, sizeof dir, "%s", path);
    *strrchr(dir, '/') = '\0';
    const char *name = strrchr(path, '/') + 1;
    CHECKF(pk_scene_load_memory(ctx, format, data, size, name, dir, &b) == PK_OK, "%s", pk_context_error(ctx));
    free(data);
    if (!a || !b) return;
    pk_image *ia = render(a), *ib = render(b);
    REQUIRE(ia && ib);
    CHECKF(memcmp(pk_image_pixels(ia), pk_image_pixels(ib), 24 * 24 * 3 * sizeof(float)) == 0, "%s", file);
    pk_image_destroy(ia), pk_image_destroy(ib);
    pk_scene_destroy(a), pk_scene_destroy(b);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    static const struct {
        const char *path, *format;
    } names[] = {{"a.obj", "obj"},      {"A.OBJ", "obj"},   {"dir.json/x.json", "json"}, {"s.Xml", "xml"},
                 {"s.pbrt", "pbrt"},    {"m.gltf", "gltf"}, {"m.GLB", "gltf"},           {"m.gltf.bak", NULL},
                 {"obj", NULL},         {"", NULL},         {"a.ply", NULL},             {".obj/readme", NULL}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        const char *f = pk_scene_format(names[i].path);
        CHECKF(names[i].format ? f && strcmp(f, names[i].format) == 0 : f == NULL, "'%s': %s", names[i].path,
               f ? f : "(none)");
    }
    CHECK(pk_scene_format(NULL) == NULL);

    check_same("conformance/box.obj", "obj");
    check_same("conformance/box.json", "json");
    check_same("conformance/box.xml", "xml");
    check_same("conformance/box.pbrt", "pbrt");
    check_same("conformance/box.gltf", "gltf");
    check_same("gltf/cube.glb", "gltf");
    check_same("media/fog.pbrt", "pbrt");

    pk_scene *s = (pk_scene *)&s;
    CHECK(pk_scene_load_memory(ctx, "ply", "ply", 3, NULL, NULL, &s) == PK_ERR_INVALID_ARGUMENT && s == NULL);
    CHECKF(strstr(pk_context_error(ctx), "unknown scene format 'ply'") != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(pk_scene_load_memory(ctx, NULL, "", 0, NULL, NULL, &s) == PK_ERR_INVALID_ARGUMENT && s == NULL);
    pk_context_clear_error(ctx);
    /* without a name, messages name the buffer memory.FORMAT */
    CHECK(pk_scene_load_memory(ctx, "pbrt", "Shape \"nonsense\"", 16, NULL, NULL, &s) != PK_OK && s == NULL);
    CHECKF(strncmp(pk_context_error(ctx), "memory.pbrt:1:", 14) == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);

    pk_context_destroy(ctx);
    return test_done("test_formats");
}

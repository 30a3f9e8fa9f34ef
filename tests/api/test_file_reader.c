/*
 * test_file_reader.c - pk_context_set_file_reader: scenes whose files exist
 * only in memory load exactly as from the file system (OBJ + MTL, an MTL name
 * holding a blank, JSON + OBJ meshes); every path the library asks for is the
 * one it would open; a texture map comes through it too; a reader's refusal is latched as "path: reason"; sizes
 * beyond PK_MAX_FILE_BYTES are refused; NULL restores the file system.
 */
#include "paprsek.h"
#include "test.h"

typedef struct mem_file {
    const char *path;
    const char *text;
} mem_file;

typedef struct archive {
    const mem_file *files;
    size_t n;
    char asked[16][256]; /* the paths the library asked for, in order */
    size_t nasked;
    size_t huge;         /* > 0: every file claims this size */
} archive;

static pk_status serve(void *user, const char *path, const void **data, size_t *size, char *why, size_t why_cap)
{
    archive *a = user;
    if (a->nasked < 16) snprintf(a->asked[a->nasked++], sizeof a->asked[0], "%s", path);
    for (size_t i = 0; i < a->n; i++)
        if (strcmp(a->files[i].path, path) == 0) {
            *data = a->files[i].text;
            *size = a->huge ? a->huge : strlen(a->files[i].text);
            return PK_OK;
        }
    snprintf(why, why_cap, "not in the archive");
    return PK_ERR_IO;
}

/* serve, and the texture t/mpi_tex.pfm (binary: not a C string) */
static const char *g_pfm;
static size_t g_pfm_size;
static pk_status serve_tex(void *user, const char *path, const void **data, size_t *size, char *why, size_t why_cap)
{
    archive *a = user;
    if (strcmp(path, "t/mpi_tex.pfm") == 0) {
        if (a->nasked < 16) snprintf(a->asked[a->nasked++], sizeof a->asked[0], "%s", path);
        *data = g_pfm;
        *size = g_pfm_size;
        return PK_OK;
    }
    return serve(user, path, data, size, why, why_cap);
}

/* The scene at path read from the file system; its info. */
static void info_from_disk(const char *path, pk_scene_info *info)
{
    pk_context *ctx = NULL;
    pk_scene *s = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
    pk_scene_get_info(s, info);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
}

/* A file's text (the test's fixtures are small). */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    static char bufs[8][65536];
    static int next;
    char *b = bufs[next++ % 8];
    size_t n = fread(b, 1, sizeof bufs[0] - 1, f);
    b[n] = '\0';
    fclose(f);
    return b;
}

static int same_info(const pk_scene_info *a, const pk_scene_info *b)
{
    return a->triangles == b->triangles && a->materials == b->materials && a->spheres == b->spheres &&
           a->emissive_triangles == b->emissive_triangles && a->point_lights == b->point_lights &&
           memcmp(a->bounds_min, b->bounds_min, sizeof a->bounds_min) == 0 &&
           memcmp(a->bounds_max, b->bounds_max, sizeof a->bounds_max) == 0;
}

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *s = NULL;
    pk_scene_info disk, mem;

    /* OBJ + MTL, served under paths that do not exist on disk */
    const mem_file f1[] = {{"nowhere/obj_mat.obj", slurp(PK_TEST_DATA "/obj_mat.obj")},
                           {"nowhere/obj_mat.mtl", slurp(PK_TEST_DATA "/obj_mat.mtl")}};
    archive a1 = {.files = f1, .n = 2};
    pk_context_set_file_reader(ctx, serve, &a1);
    CHECKF(pk_scene_load_file(ctx, "nowhere/obj_mat.obj", &s) == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s);
    pk_scene_get_info(s, &mem);
    pk_scene_destroy(s);
    s = NULL;
    info_from_disk(PK_TEST_DATA "/obj_mat.obj", &disk);
    CHECK(same_info(&mem, &disk));
    CHECK(mem.materials >= 3); /* the MTL file was read through the reader */
    /* the OBJ, its MTL, then whatever the MTL names (texture maps), all
     * under the scene's folder as the library would open them */
    CHECK(a1.nasked >= 2);
    CHECK(strcmp(a1.asked[0], "nowhere/obj_mat.obj") == 0);
    CHECK(strcmp(a1.asked[1], "nowhere/obj_mat.mtl") == 0);
    for (size_t i = 2; i < a1.nasked; i++) CHECKF(strncmp(a1.asked[i], "nowhere/", 8) == 0, "%s", a1.asked[i]);

    /* a texture map named by the MTL file comes through the reader too (a
     * 2x2 PFM, in memory only) */
    static const char pfm[] = "PF\n2 2\n-1.0\n"
                              "\0\0\x80\x3f\0\0\0\x3e\0\0\0\x3e\0\0\0\x3e\0\0\x80\x3f\0\0\0\x3e"
                              "\0\0\0\x3e\0\0\0\x3e\0\0\x80\x3f\0\0\x80\x3f\0\0\x80\x3f\0\0\x80\x3f";
    const mem_file ft[] = {{"t/mpi_tex.obj", slurp(PK_TEST_DATA "/mpi_tex.obj")},
                           {"t/mpi_tex.mtl", slurp(PK_TEST_DATA "/mpi_tex.mtl")}};
    archive at = {.files = ft, .n = 2};
    pk_context_set_file_reader(ctx, serve_tex, &at);
    g_pfm = pfm;
    g_pfm_size = sizeof pfm - 1;
    CHECKF(pk_scene_load_file(ctx, "t/mpi_tex.obj", &s) == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s);
    pk_scene_get_info(s, &mem);
    pk_scene_destroy(s);
    s = NULL;
    CHECKF(mem.textures == 1, "%zu textures", mem.textures);
    CHECK(at.nasked == 3 && strcmp(at.asked[2], "t/mpi_tex.pfm") == 0);

    /* "mtllib odd library.mtl": one file whose name holds a blank; the
     * reader answers the library's question whether it exists */
    const mem_file f2[] = {{"v/odd_space.obj", slurp(PK_TEST_DATA "/odd_space.obj")},
                           {"v/odd library.mtl", slurp(PK_TEST_DATA "/odd library.mtl")}};
    archive a2 = {.files = f2, .n = 2};
    pk_context_set_file_reader(ctx, serve, &a2);
    CHECKF(pk_scene_load_file(ctx, "v/odd_space.obj", &s) == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s);
    pk_scene_get_info(s, &mem);
    pk_scene_destroy(s);
    s = NULL;
    info_from_disk(PK_TEST_DATA "/odd_space.obj", &disk);
    CHECK(same_info(&mem, &disk));
    CHECK(mem.emissive_triangles == disk.emissive_triangles && disk.emissive_triangles > 0);

    /* a JSON scene and the OBJ meshes it names */
    const mem_file f3[] = {{"j/json_example.json", slurp(PK_TEST_DATA "/json_example.json")},
                           {"j/json_floor.obj", slurp(PK_TEST_DATA "/json_floor.obj")},
                           {"j/json_lamp.obj", slurp(PK_TEST_DATA "/json_lamp.obj")}};
    archive a3 = {.files = f3, .n = 3};
    pk_context_set_file_reader(ctx, serve, &a3);
    CHECKF(pk_scene_load_file(ctx, "j/json_example.json", &s) == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s);
    pk_scene_get_info(s, &mem);
    pk_scene_destroy(s);
    s = NULL;
    info_from_disk(PK_TEST_DATA "/json_example.json", &disk);
    CHECK(same_info(&mem, &disk));

    /* a mesh the reader does not have: the JSON loader's message names the
     * field and carries the reader's reason */
    archive a4 = {.files = f3, .n = 2};
    pk_context_set_file_reader(ctx, serve, &a4);
    CHECK(pk_scene_load_file(ctx, "j/json_example.json", &s) != PK_OK);
    CHECK(s == NULL);
    CHECKF(strstr(pk_context_error(ctx), "j/json_lamp.obj: not in the archive") != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);

    /* a scene the reader does not have: "path: reason", the reader's status */
    CHECK(pk_scene_load_file(ctx, "j/absent.obj", &s) == PK_ERR_IO);
    CHECKF(strcmp(pk_context_error(ctx), "j/absent.obj: not in the archive") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);

    /* a reader that claims more than PK_MAX_FILE_BYTES */
    archive a5 = {.files = f1, .n = 2, .huge = PK_MAX_FILE_BYTES + 1};
    pk_context_set_file_reader(ctx, serve, &a5);
    CHECK(pk_scene_load_file(ctx, "nowhere/obj_mat.obj", &s) == PK_ERR_LIMIT);
    CHECKF(strstr(pk_context_error(ctx), "nowhere/obj_mat.obj: file is larger") != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);

    /* NULL: the file system again */
    pk_context_set_file_reader(ctx, NULL, NULL);
    CHECK(pk_scene_load_file(ctx, "nowhere/obj_mat.obj", &s) == PK_ERR_IO);
    CHECKF(strstr(pk_context_error(ctx), "cannot open") != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECKF(pk_scene_load_file(ctx, PK_TEST_DATA "/obj_mat.obj", &s) == PK_OK, "%s", pk_context_error(ctx));
    pk_scene_destroy(s);

    pk_context_destroy(ctx);
    return test_done("test_file_reader");
}

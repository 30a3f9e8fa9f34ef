/*
 * test_json.c - the JSON scene loader and the built-in Cornell box: every
 * field of the documented example lands in the scene, defaults, mesh
 * transforms, inline and named materials, the exact text of each error,
 * allocation failures at every step, and the Cornell box's geometry.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "scene/scene.h"

#define NAME "scene.json"

static warning_log wl;

static pk_context *new_ctx(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wl);
    return ctx;
}

/* Parses json (as NAME, meshes relative to the test data folder) into a new scene. */
static pk_status parse(pk_context *ctx, const char *json, pk_scene **out)
{
    REQUIRE(scene_create(ctx, NAME, out) == PK_OK);
    return scene_json_parse(ctx, *out, json, strlen(json), NAME, PK_TEST_DATA);
}

static bool near3(vec3 a, float x, float y, float z, float tol)
{
    return fabsf(a.x - x) <= tol && fabsf(a.y - y) <= tol && fabsf(a.z - z) <= tol;
}

static const material *find_mat(const pk_scene *s, const char *name)
{
    int64_t i = scene_find_material(s, name);
    return i < 0 ? NULL : &s->materials[i];
}

/* ---- the documented example ------------------------------------------------ */

static void test_example(void)
{
    pk_context *ctx = new_ctx();
    char *data;
    size_t size;
    REQUIRE(file_read_all(ctx, PK_TEST_DATA "/json_example.json", &data, &size) == PK_OK);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "json_example.json", &s) == PK_OK);
    pk_status st = scene_json_parse(ctx, s, data, size, "json_example.json", PK_TEST_DATA);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECKF(wl.count == 0, "%s", wl.msg[0]);

    CHECK(s->has_camera);
    CHECK(s->camera.look_from[0] == 0.0f && s->camera.look_from[1] == 1.5f && s->camera.look_from[2] == 5.0f);
    CHECK(s->camera.look_at[0] == 0.0f && s->camera.look_at[1] == 1.0f && s->camera.look_at[2] == 0.0f);
    CHECK(s->camera.up[0] == 0.0f && s->camera.up[1] == 1.0f && s->camera.up[2] == 0.0f);
    CHECK(s->camera.fov_deg == 40.0f);

    const scene_render_settings *r = &s->render;
    CHECK(r->has_width && r->opt.width == 320);
    CHECK(r->has_height && r->opt.height == 240);
    CHECK(r->has_spp && r->opt.spp == 4);
    CHECK(r->has_light_samples && r->opt.light_samples == 16);
    CHECK(r->has_max_depth && r->opt.max_depth == 6);
    CHECK(r->has_threads && r->opt.threads == 2);
    CHECK(r->has_accel && r->opt.accel == PK_ACCEL_BVH);
    CHECK(r->has_fresnel && r->opt.fresnel == 0);
    CHECK(near3(s->ambient, 0.02f, 0.02f, 0.03f, 0.0f));

    const material *white = find_mat(s, "white"), *mirror = find_mat(s, "mirror");
    const material *glass = find_mat(s, "glass"), *lamp = find_mat(s, "lamp");
    REQUIRE(white && mirror && glass && lamp);
    CHECK(near3(white->kd, 0.73f, 0.73f, 0.73f, 0.0f));
    CHECK(white->illum == 2 && white->ni == 1.0f && white->d == 1.0f); /* MTL defaults */
    CHECK(near3(mirror->kd, 0, 0, 0, 0) && near3(mirror->ks, 0.9f, 0.9f, 0.9f, 0) && mirror->illum == 3);
    CHECK(near3(glass->tf, 0.9f, 1.0f, 0.9f, 0) && glass->ni == 1.5f && glass->illum == 7);
    CHECK(near3(lamp->ke, 12, 11, 9, 0) && near3(lamp->kd, 0.8f, 0.8f, 0.8f, 0));

    /* three quads, four vertices each */
    CHECK(s->npositions == 12);
    CHECK(s->ntris == 6);
    uint32_t iwhite = (uint32_t)scene_find_material(s, "white"), ilamp = (uint32_t)scene_find_material(s, "lamp");
    if (s->ntris == 6) {
        CHECK(s->tris[0].material == iwhite && s->tris[1].material == iwhite);
        CHECK(s->tris[2].material == ilamp && s->tris[3].material == ilamp);
        CHECK(s->tris[4].material == iwhite && s->tris[5].material == iwhite);
    }

    REQUIRE(s->nspheres == 3);
    CHECK(near3(s->spheres[0].center, -1.0f, 0.8f, 0.0f, 0) && s->spheres[0].radius == 0.8f);
    CHECK(s->spheres[0].material == (uint32_t)scene_find_material(s, "mirror"));
    CHECK(near3(s->spheres[1].center, 1.1f, 0.6f, 0.4f, 0) && s->spheres[1].radius == 0.6f);
    CHECK(s->spheres[1].material == (uint32_t)scene_find_material(s, "glass"));
    CHECK(near3(s->spheres[2].center, 0.0f, 0.3f, 1.4f, 0) && s->spheres[2].radius == 0.3f);
    /* the inline material is a new one of its own */
    const material *in = &s->materials[s->spheres[2].material];
    CHECK(s->spheres[2].material == s->nmaterials - 1);
    CHECK(strcmp(in->name, "spheres[2].material") == 0);
    CHECK(near3(in->kd, 0.8f, 0.2f, 0.1f, 0) && near3(in->ks, 0.3f, 0.3f, 0.3f, 0) && in->ns == 50.0f);

    REQUIRE(s->nlights == 2);
    CHECK(near3(s->lights[0].position, 2, 4, 3, 0) && near3(s->lights[0].intensity, 20, 20, 20, 0));
    CHECK(near3(s->lights[1].position, -3, 3, 2, 0) && near3(s->lights[1].intensity, 10, 8, 6, 1e-5f));

    st = scene_commit(ctx, s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECK(s->nemissive == 2);
    scene_destroy(s);
    mem_free(&ctx->alloc, data);
    pk_context_destroy(ctx);
}

/* The example printed in docs/scene-format.md is the tested file. */
static void test_doc_example(void)
{
    pk_context *ctx = new_ctx();
    char *doc, *file;
    size_t ndoc, nfile;
    REQUIRE(file_read_all(ctx, PK_TEST_DATA "/../../docs/scene-format.md", &doc, &ndoc) == PK_OK);
    REQUIRE(file_read_all(ctx, PK_TEST_DATA "/json_example.json", &file, &nfile) == PK_OK);
    const char *start = strstr(doc, "```json\n");
    CHECK(start != NULL);
    if (start) {
        start += strlen("```json\n");
        const char *end = strstr(start, "```");
        CHECK(end && (size_t)(end - start) == nfile && memcmp(start, file, nfile) == 0);
    }
    mem_free(&ctx->alloc, doc);
    mem_free(&ctx->alloc, file);
    pk_context_destroy(ctx);
}

/* ---- transforms ---------------------------------------------------------------- */

static void test_transforms(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx, "{\"materials\": {\"white\": {}, \"lamp\": {}}, \"meshes\": ["
                              "{\"obj\": \"json_floor.obj\", \"transform\": {\"scale\": [4, 1, 4]}},"
                              "{\"obj\": \"json_lamp.obj\", \"transform\": {\"translate\": [0, 2.9, 0],"
                              " \"rotate\": [180, 1, 0, 0], \"scale\": 0.5}},"
                              "{\"obj\": \"json_floor.obj\", \"transform\": [4,0,0,0, 0,0,-4,2, 0,4,0,-2, 0,0,0,1]},"
                              "{\"obj\": \"json_floor.obj\", \"transform\": {\"rotate\": [90, 0, 0, 2],"
                              " \"translate\": [10, 0, 0]}},"
                              "{\"obj\": \"json_floor.obj\"}]}",
                     &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s->npositions == 20);
    /* the quad's corners: (-.5,0,-.5) (-.5,0,.5) (.5,0,.5) (.5,0,-.5) */
    const vec3 *p = s->positions;
    const float e = 1e-5f;
    /* scale only */
    CHECK(near3(p[0], -2, 0, -2, e) && near3(p[1], -2, 0, 2, e) && near3(p[2], 2, 0, 2, e) && near3(p[3], 2, 0, -2, e));
    /* T * R * S: halve, turn upside down about x (z flips), lift to 2.9 */
    CHECK(near3(p[4], -0.25f, 2.9f, 0.25f, e) && near3(p[5], -0.25f, 2.9f, -0.25f, e));
    CHECK(near3(p[6], 0.25f, 2.9f, -0.25f, e) && near3(p[7], 0.25f, 2.9f, 0.25f, e));
    /* a row-major matrix: the wall at z = -2 spanning y 0..4 */
    CHECK(near3(p[8], -2, 4, -2, e) && near3(p[9], -2, 0, -2, e) && near3(p[10], 2, 0, -2, e) && near3(p[11], 2, 4, -2, e));
    /* rotate 90 degrees about +z (an unnormalised axis), then translate */
    CHECK(near3(p[12], 10, -0.5f, -0.5f, e) && near3(p[14], 10, 0.5f, 0.5f, e));
    /* no transform */
    CHECK(near3(p[16], -0.5f, 0, -0.5f, 0) && near3(p[18], 0.5f, 0, 0.5f, 0));
    /* the lamp was turned upside down: its geometric normal points down */
    vec3 a, b, c;
    scene_tri_verts(s, 2, &a, &b, &c);
    CHECK(v3_cross(v3_sub(b, a), v3_sub(c, a)).y < 0.0f);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- defaults, materials, warnings ---------------------------------------------- */

static void test_defaults(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx, "{\"camera\": {\"look_from\": [1, 2, 3], \"look_at\": [0, 0, 0]},"
                              " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}],"
                              " \"lights\": [{\"position\": [0, 5, 0]}]}",
                     &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECK(s->has_camera);
    CHECK(s->camera.up[0] == 0.0f && s->camera.up[1] == 1.0f && s->camera.up[2] == 0.0f);
    CHECK(s->camera.fov_deg == 45.0f);
    CHECK(!s->render.has_width && !s->render.has_height && !s->render.has_spp && !s->render.has_accel &&
          !s->render.has_fresnel && !s->render.has_threads && !s->render.has_max_depth &&
          !s->render.has_light_samples && !s->render.has_energy_compensation);
    CHECK(s->render.opt.width == 512 && s->render.opt.height == 512);
    CHECK(near3(s->ambient, 0, 0, 0, 0));
    REQUIRE(s->nspheres == 1 && s->nlights == 1);
    CHECK(s->spheres[0].material == 0);
    CHECK(near3(s->lights[0].intensity, 1, 1, 1, 0));
    CHECK(s->nmaterials == 1);
    scene_destroy(s);

    /* an empty object is a valid (empty) scene description */
    st = parse(ctx, " {} ", &s);
    CHECK(st == PK_OK && s->ntris == 0 && !s->has_camera);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_materials(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    /* the array form; a later material of the same name wins; inline
     * materials are never found by name, even when their name matches */
    pk_status st = parse(ctx,
                         "{\"materials\": [{\"name\": \"red\", \"kd\": [1, 0, 0]},"
                         " {\"name\": \"spheres[0].material\", \"kd\": [0, 0, 1]},"
                         " {\"name\": \"red\", \"kd\": [0.5, 0, 0], \"d\": 0.25, \"ka\": [0.1, 0.1, 0.1]}],"
                         " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": {\"kd\": [0, 1, 0]}},"
                         " {\"center\": [3, 0, 0], \"radius\": 1, \"material\": \"spheres[0].material\"},"
                         " {\"center\": [6, 0, 0], \"radius\": 1, \"material\": \"red\"}]}",
                         &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s->nspheres == 3);
    CHECK(near3(s->materials[s->spheres[0].material].kd, 0, 1, 0, 0));
    CHECK(near3(s->materials[s->spheres[1].material].kd, 0, 0, 1, 0));
    const material *red = &s->materials[s->spheres[2].material];
    CHECK(near3(red->kd, 0.5f, 0, 0, 0) && red->d == 0.25f && near3(red->ka, 0.1f, 0.1f, 0.1f, 0));
    CHECK(s->nmaterials == 5);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_warnings(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx,
                         "{\"comment\": \"made by hand\",\n"
                         " \"spheres\": [\n"
                         "  {\"center\": [0, 0, 0], \"radius\": 1, \"colour\": [1, 0, 0]},\n"
                         "  {\"center\": [0, 0, 0], \"radius\": 1, \"colour\": [1, 0, 0]}\n"
                         " ],\n"
                         " \"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0], \"aperture\": 2}\n"
                         "}",
                         &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECK(wl.count == 3);
    CHECK(strcmp(wl.msg[0], "scene.json:1: comment: unknown key ignored") == 0);
    /* sections are read in a fixed order (camera before spheres); the
     * second sphere's colour is not reported again */
    CHECKF(strcmp(wl.msg[1], "scene.json:6: camera.aperture: unknown key ignored") == 0, "%s", wl.msg[1]);
    CHECKF(strcmp(wl.msg[2], "scene.json:3: spheres[0].colour: unknown key ignored") == 0, "%s", wl.msg[2]);
    scene_destroy(s);

    /* many different unknown keys: the first 32 are reported, then one line */
    char json[4096] = "{";
    for (int i = 0; i < 40; i++) snprintf(json + strlen(json), sizeof json - strlen(json), "\"k%d\": %d, ", i, i);
    strcat(json, "\"ambient\": [0, 0, 0]}");
    warning_log_clear(&wl);
    st = parse(ctx, json, &s);
    CHECK(st == PK_OK && wl.count == 33);
    CHECK(strcmp(wl.msg[0], "scene.json:1: k0: unknown key ignored") == 0);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- errors: exact text, line and status ---------------------------------------- */

static void expect_error(int line, const char *json, pk_status status, const char *message)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx, json, &s);
    if (st != status || strcmp(pk_context_error(ctx), message) != 0) {
        fprintf(stderr, "%s:%d: expected %d \"%s\"\n    got %d \"%s\"\n", __FILE__, line, (int)status, message,
                (int)st, pk_context_error(ctx));
        test_failures++;
    }
    CHECK(pk_context_status(ctx) == status);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

#define EXPECT_ERROR(json, status, message) expect_error(__LINE__, json, status, message)

static void test_errors(void)
{
    /* syntax */
    EXPECT_ERROR("", PK_ERR_PARSE, "scene.json:1: empty document (expected a JSON object)");
    EXPECT_ERROR("{\n  \"camera\": {\n    \"fov\": 40,\n  }\n}", PK_ERR_PARSE,
                 "scene.json:4: invalid JSON near '}'");
    EXPECT_ERROR("{\"spheres\": [\n  {\"radius\": 1}\n", PK_ERR_PARSE,
                 "scene.json:2: invalid JSON: unexpected end of file");
    EXPECT_ERROR("{\n \"a\": tru\n}", PK_ERR_PARSE, "scene.json:2: invalid JSON near 'tru'");
    EXPECT_ERROR("{}\n{}", PK_ERR_PARSE, "scene.json:2: unexpected text after the JSON document");
    EXPECT_ERROR("\n[1, 2]", PK_ERR_PARSE, "scene.json:2: the top level must be a JSON object");

    /* types and missing fields */
    EXPECT_ERROR("{\n \"camera\": {\n  \"look_from\": \"here\",\n  \"look_at\": [0, 0, 0]\n }\n}", PK_ERR_PARSE,
                 "scene.json:3: camera.look_from: must be an array of 3 numbers");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [0, 0, 1, 0], \"look_at\": [0, 0, 0]}}", PK_ERR_PARSE,
                 "scene.json:1: camera.look_from: must be an array of 3 numbers");
    EXPECT_ERROR("{\n \"camera\": {\n  \"look_from\": [0, 0, 1]\n }\n}", PK_ERR_PARSE,
                 "scene.json:2: camera: missing \"look_at\"");
    EXPECT_ERROR("{\"camera\": [0, 0, 1]}", PK_ERR_PARSE, "scene.json:1: camera: must be an object");
    EXPECT_ERROR("{\"spheres\": {\"center\": [0, 0, 0]}}", PK_ERR_PARSE, "scene.json:1: spheres: must be an array");
    EXPECT_ERROR("{\"spheres\": [\n  {\"center\": [0, 0, 0]}\n]}", PK_ERR_PARSE,
                 "scene.json:2: spheres[0]: missing \"radius\"");
    EXPECT_ERROR("{\"spheres\": [1]}", PK_ERR_PARSE, "scene.json:1: spheres[0]: must be an object");
    EXPECT_ERROR("{\"lights\": [\n\n {\"intensity\": 3}]}", PK_ERR_PARSE,
                 "scene.json:3: lights[0]: missing \"position\"");
    EXPECT_ERROR("{\"lights\": [{\"position\": [0, 1, 0],\n \"intensity\": \"bright\"}]}", PK_ERR_PARSE,
                 "scene.json:2: lights[0].intensity: must be a number or an array of 3 numbers");
    EXPECT_ERROR("{\"render\": {\"fresnel\": 1}}", PK_ERR_PARSE, "scene.json:1: render.fresnel: must be true or false");
    EXPECT_ERROR("{\"render\": {\"energy_compensation\": \"on\"}}", PK_ERR_PARSE,
                 "scene.json:1: render.energy_compensation: must be true or false");
    EXPECT_ERROR("{\"render\": {\"accel\": \"kd-tree\"}}", PK_ERR_PARSE,
                 "scene.json:1: render.accel: must be one of \"none\", \"midpoint\", \"bvh\", \"embree\"");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0]},\n"
                 " \"camera\": {\"look_from\": [0, 0, 2], \"look_at\": [0, 0, 0]}}",
                 PK_ERR_PARSE, "scene.json:2: camera: duplicate key");

    /* values: the example of the brief, on line 7 */
    EXPECT_ERROR("{\n"
                 "  \"spheres\": [\n"
                 "    {\n"
                 "      \"center\": [0, 0, 0], \"radius\": 1\n"
                 "    },\n"
                 "    { \"center\": [2, 0, 0],\n"
                 "      \"radius\": 0 }\n"
                 "  ]\n"
                 "}",
                 PK_ERR_PARSE, "scene.json:7: spheres[1].radius: must be a positive number");
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": -2}]}", PK_ERR_PARSE,
                 "scene.json:1: spheres[0].radius: must be a positive number");
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": \"1\"}]}", PK_ERR_PARSE,
                 "scene.json:1: spheres[0].radius: must be a positive number");
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1e39}]}", PK_ERR_PARSE,
                 "scene.json:1: spheres[0].radius: must be a positive number");
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 1e300, 0], \"radius\": 1}]}", PK_ERR_PARSE,
                 "scene.json:1: spheres[0].center: numbers must be finite");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0],\n \"fov\": 0}}", PK_ERR_PARSE,
                 "scene.json:2: camera.fov: must be between 0 and 180 degrees (exclusive)");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0], \"fov\": 180}}", PK_ERR_PARSE,
                 "scene.json:1: camera.fov: must be between 0 and 180 degrees (exclusive)");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [1, 2, 3],\n \"look_at\": [1, 2, 3]}}", PK_ERR_PARSE,
                 "scene.json:2: camera.look_at: must differ from look_from");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [1, 0, 0],\n\n \"up\": [-2, 0, 0]}}",
                 PK_ERR_PARSE, "scene.json:3: camera.up: is parallel to the view direction");
    EXPECT_ERROR("{\"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [0, 0, 0.5], \"up\": [0, 0, 0]}}", PK_ERR_PARSE,
                 "scene.json:1: camera.up: must not be zero");
    EXPECT_ERROR("{\n\"camera\": {\"look_from\": [0, 5, 0], \"look_at\": [0, 0, 0]}}", PK_ERR_PARSE,
                 "scene.json:2: camera: the default up [0, 1, 0] is parallel to the view direction; give \"up\"");

    /* sizes */
    EXPECT_ERROR("{\"film\": {\"width\": 100000, \"height\": 10}}", PK_ERR_LIMIT,
                 "scene.json:1: film.width: must be an integer in 1..16384");
    EXPECT_ERROR("{\"film\": {\"width\": 0}}", PK_ERR_PARSE, "scene.json:1: film.width: must be an integer in 1..16384");
    EXPECT_ERROR("{\"film\": {\"width\": 64.5}}", PK_ERR_PARSE, "scene.json:1: film.width: must be an integer");
    EXPECT_ERROR("{\"film\":\n {\"width\": 16384, \"height\": 16384}}", PK_ERR_LIMIT,
                 "scene.json:2: film: 16384x16384 is more than 67108864 pixels");
    EXPECT_ERROR("{\"film\": {\"width\": 16384}, \"render\": {\"height\": 8192}}", PK_ERR_LIMIT,
                 "scene.json:1: render: 16384x8192 is more than 67108864 pixels");
    EXPECT_ERROR("{\"render\": {\"spp\": 0}}", PK_ERR_PARSE, "scene.json:1: render.spp: must be an integer in 1..65536");
    EXPECT_ERROR("{\"render\": {\"spp\": 1e12}}", PK_ERR_LIMIT,
                 "scene.json:1: render.spp: must be an integer in 1..65536");
    EXPECT_ERROR("{\"render\": {\"max_depth\": 1025}}", PK_ERR_LIMIT,
                 "scene.json:1: render.max_depth: must be an integer in -1..1024");
    EXPECT_ERROR("{\"render\": {\"threads\": -1}}", PK_ERR_PARSE,
                 "scene.json:1: render.threads: must be an integer in 0..1024");
    /* the same range as the API and the CLI (0 = point lights only) */
    EXPECT_ERROR("{\"render\": {\"light_samples\": 5000}}", PK_ERR_LIMIT,
                 "scene.json:1: render.light_samples: must be an integer in 0..4096");
    EXPECT_ERROR("{\"render\": {\"light_samples\": -1}}", PK_ERR_PARSE,
                 "scene.json:1: render.light_samples: must be an integer in 0..4096");

    /* materials */
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1,\n \"material\": \"gold\"}]}", PK_ERR_PARSE,
                 "scene.json:2: spheres[0].material: unknown material \"gold\"");
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": 3}]}", PK_ERR_PARSE,
                 "scene.json:1: spheres[0].material: must be a material name or a material object");
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": {\"ni\": 0}}]}", PK_ERR_PARSE,
                 "scene.json:1: spheres[0].material.ni: must be a positive number");
    EXPECT_ERROR("{\"materials\": {\"red\": {\"kd\": [1, -0.5, 0]}}}", PK_ERR_PARSE,
                 "scene.json:1: materials.red.kd: colour components must not be negative");
    EXPECT_ERROR("{\"materials\": {\"red\": {\"illum\": 2.5}}}", PK_ERR_PARSE,
                 "scene.json:1: materials.red.illum: must be an integer");
    EXPECT_ERROR("{\"materials\": {\"red\": {\"d\": 2}}}", PK_ERR_PARSE, "scene.json:1: materials.red.d: must be in 0..1");
    EXPECT_ERROR("{\"materials\": [{\"kd\": [1, 0, 0]}]}", PK_ERR_PARSE, "scene.json:1: materials[0]: missing \"name\"");
    EXPECT_ERROR("{\"materials\": [{\"name\": \"\"}]}", PK_ERR_PARSE,
                 "scene.json:1: materials[0].name: must be a non-empty string");
    EXPECT_ERROR("{\"materials\": 4}", PK_ERR_PARSE,
                 "scene.json:1: materials: must be an object (name: material) or an array");
    EXPECT_ERROR("{\"ambient\": [0.1, 0.1]}", PK_ERR_PARSE, "scene.json:1: ambient: must be an array of 3 numbers");

    /* meshes */
    char msg[1024];
    snprintf(msg, sizeof msg,
             "scene.json:3: meshes[0].obj: %s/json_missing.obj: cannot open: No such file or directory", PK_TEST_DATA);
    EXPECT_ERROR("{\"meshes\": [\n {\n  \"obj\": \"json_missing.obj\"}]}", PK_ERR_IO, msg);
    EXPECT_ERROR("{\"meshes\": [{\"transform\": {}}]}", PK_ERR_PARSE, "scene.json:1: meshes[0]: missing \"obj\"");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": 7}]}", PK_ERR_PARSE,
                 "scene.json:1: meshes[0].obj: must be a non-empty string (a path)");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": \"json_floor.obj\",\n \"transform\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]}]}",
                 PK_ERR_PARSE, "scene.json:2: meshes[0].transform: the last row must be 0 0 0 1");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": [1,0,0]}]}", PK_ERR_PARSE,
                 "scene.json:1: meshes[0].transform: must be an array of 16 numbers");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": {\"scale\": [1, 0, 1]}}]}", PK_ERR_PARSE,
                 "scene.json:1: meshes[0].transform.scale: must not be zero");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": {\"rotate\": [30, 0, 0, 0]}}]}",
                 PK_ERR_PARSE, "scene.json:1: meshes[0].transform.rotate: the axis must not be zero");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": [1,0,0,0, 0,1,0,0, 0,0,0,0, 0,0,0,1]}]}",
                 PK_ERR_PARSE, "scene.json:1: meshes[0].transform: the transform is singular");
    EXPECT_ERROR("{\"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": \"identity\"}]}", PK_ERR_PARSE,
                 "scene.json:1: meshes[0].transform: must be an array of 16 numbers or an object with "
                 "translate, scale, rotate");
}

/* Lines are found by position, not by searching for the key: strings that
 * look like keys, escapes and repeated keys do not mislead them. */
static void test_error_lines(void)
{
    EXPECT_ERROR("{\"materials\": {\n"
                 "  \"say \\\"radius\\\": 0\": {\"kd\": [1, 1, 1]},\n"
                 "  \"radius\": {\"kd\": [1, 1, 1]}\n"
                 " },\n"
                 " \"spheres\": [\n"
                 "  {\"center\": [0, 0, 0], \"radius\": 1},\n"
                 "  {\"center\": [0, 0, 0], \"radius\": 1},\n"
                 "  {\"center\": [0, 0, 0], \"radius\":\n"
                 "      -1}\n"
                 " ]\n"
                 "}",
                 PK_ERR_PARSE, "scene.json:9: spheres[2].radius: must be a positive number");
    /* a byte-order mark and CRLF line ends */
    EXPECT_ERROR("\xEF\xBB\xBF{\r\n\"spheres\": [\r\n{\"center\": [0, 0, 0], \"radius\": 0}]}", PK_ERR_PARSE,
                 "scene.json:3: spheres[0].radius: must be a positive number");
    /* control characters in a key are not copied into the message */
    EXPECT_ERROR("{\"materials\": {\"a\\u0001b\": {\"ns\": -1}}}", PK_ERR_PARSE,
                 "scene.json:1: materials.a?b.ns: must not be negative");
}

/* ---- allocation failures --------------------------------------------------------- */

typedef struct failing {
    long calls, fail_at; /* the fail_at-th call fails (0: none) */
    long live;
} failing;

static void *failing_realloc(void *user, void *ptr, size_t size)
{
    failing *f = user;
    if (size == 0) {
        if (ptr) f->live--;
        free(ptr);
        return NULL;
    }
    if (++f->calls == f->fail_at) return NULL;
    void *q = realloc(ptr, size);
    if (q && !ptr) f->live++;
    return q;
}

static void test_alloc_failures(void)
{
    char *data;
    size_t size;
    pk_context *ctx0 = new_ctx();
    REQUIRE(file_read_all(ctx0, PK_TEST_DATA "/json_example.json", &data, &size) == PK_OK);
    int failures_seen = 0;
    for (long n = 1; n < 100000; n++) {
        failing f = {0, 0, 0};
        pk_allocator a = {failing_realloc, &f};
        pk_context *ctx = NULL;
        REQUIRE(pk_context_create(&a, &ctx) == PK_OK);
        f.fail_at = f.calls + n;
        pk_scene *s = NULL;
        pk_status st = scene_create(ctx, "x", &s);
        if (st == PK_OK) st = scene_json_parse(ctx, s, data, size, "json_example.json", PK_TEST_DATA);
        if (st == PK_OK) st = scene_commit(ctx, s);
        scene_destroy(s);
        pk_context_destroy(ctx);
        CHECKF(f.live == 0, "failing call %ld: %ld blocks leaked", n, f.live);
        if (st == PK_OK) break;
        CHECKF(st == PK_ERR_NOMEM, "failing call %ld: status %d", n, (int)st);
        failures_seen++;
    }
    CHECK(failures_seen > 10);
    mem_free(&ctx0->alloc, data);
    pk_context_destroy(ctx0);
}

/* ---- the Cornell box --------------------------------------------------------------- */

static vec3 scene_tri_normal(const pk_scene *s, size_t k)
{
    vec3 a, b, c;
    scene_tri_verts(s, k, &a, &b, &c);
    return v3_cross(v3_sub(b, a), v3_sub(c, a));
}

static vec3 tri_centroid(const pk_scene *s, size_t k)
{
    vec3 a, b, c;
    scene_tri_verts(s, k, &a, &b, &c);
    return v3_scale(v3_add(v3_add(a, b), c), 1.0f / 3.0f);
}

static void test_cornell(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    REQUIRE(scene_create(ctx, "cornell", &s) == PK_OK);
    REQUIRE(scene_build_cornell(ctx, s) == PK_OK);
    pk_status st = scene_commit(ctx, s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    char why[256];
    CHECKF(scene_check(s, why, sizeof why), "%s", why);
    CHECK(wl.count == 0);

    /* 5 walls + light + 2 boxes of 5 faces, 2 triangles each */
    CHECK(s->ntris == 32);
    CHECK(s->ndegenerate == 0);
    for (size_t k = 0; k < s->ntris; k++) {
        vec3 a, b, c;
        scene_tri_verts(s, k, &a, &b, &c);
        CHECKF(!tri_is_degenerate(a, b, c) && v3_len(scene_tri_normal(s, k)) > 1e-4f, "triangle %zu", k);
    }

    /* the camera: in front of the open side (z < 0), looking in */
    REQUIRE(s->has_camera);
    const pk_camera *cam = &s->camera;
    vec3 from = v3(cam->look_from[0], cam->look_from[1], cam->look_from[2]);
    vec3 at = v3(cam->look_at[0], cam->look_at[1], cam->look_at[2]);
    vec3 up = v3(cam->up[0], cam->up[1], cam->up[2]);
    vec3 fwd = v3_norm(v3_sub(at, from));
    vec3 right = v3_norm(v3_cross(fwd, up));
    CHECK_NEAR(cam->fov_deg, 39.3077, 0.01);
    CHECK(from.z < s->bounds.lo.z);
    CHECK(fwd.z > 0.99f);
    CHECK(!s->render.has_width && s->render.opt.width == 512 && s->render.opt.height == 512);

    int64_t red = scene_find_material(s, "red"), green = scene_find_material(s, "green");
    int64_t white = scene_find_material(s, "white"), light = scene_find_material(s, "light");
    REQUIRE(red > 0 && green > 0 && white > 0 && light > 0);
    CHECK(near3(s->materials[red].kd, 0.63f, 0.065f, 0.05f, 0.0f));
    CHECK(near3(s->materials[green].kd, 0.14f, 0.45f, 0.09f, 0.0f));
    CHECK(near3(s->materials[white].kd, 0.73f, 0.73f, 0.73f, 0.0f));

    vec3 box_center = aabb_center(s->bounds);
    int nred = 0, ngreen = 0, nlight = 0;
    for (size_t k = 0; k < s->ntris; k++) {
        uint32_t m = s->tris[k].material;
        vec3 cen = tri_centroid(s, k), n = scene_tri_normal(s, k);
        float side = v3_dot(v3_sub(cen, from), right); /* < 0: left of the camera */
        if (m == red) {
            nred++;
            CHECKF(side < -0.2f, "red triangle %zu is not on the left (%g)", k, (double)side);
            CHECK(v3_dot(n, v3_sub(box_center, cen)) > 0.0f); /* faces into the box */
        } else if (m == green) {
            ngreen++;
            CHECKF(side > 0.2f, "green triangle %zu is not on the right (%g)", k, (double)side);
            CHECK(v3_dot(n, v3_sub(box_center, cen)) > 0.0f);
        } else if (m == light) {
            nlight++;
            CHECKF(n.y < 0.0f && fabsf(n.x) < 1e-6f && fabsf(n.z) < 1e-6f, "light triangle %zu faces up", k);
            CHECK(cen.y < s->bounds.hi.y && cen.y > s->bounds.hi.y - 0.01f); /* just below the ceiling */
        } else {
            CHECK(m == white);
        }
    }
    CHECK(nred == 2 && ngreen == 2 && nlight == 2);
    CHECK(s->nemissive == 2);
    for (size_t i = 0; i < s->nemissive; i++) CHECK(s->tris[s->emissive[i]].material == light);
    vec3 ke = s->materials[light].ke;
    CHECK(ke.x > ke.y && ke.y > ke.z && ke.z > 0.0f);

    /* the box spans about 0.56 m in metres */
    CHECK(s->bounds.lo.x > -0.001f && s->bounds.hi.x < 0.557f && s->bounds.hi.y < 0.549f && s->bounds.hi.z < 0.56f);
    CHECK(s->nspheres == 0 && s->nlights == 0);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

int main(void)
{
    test_example();
    test_doc_example();
    test_transforms();
    test_defaults();
    test_materials();
    test_warnings();
    test_errors();
    test_error_lines();
    test_alloc_failures();
    test_cornell();
    return test_done("test_json");
}

/*
 * test_scene_api.c - the scene-building API through the public header:
 * a scene built by calls renders the bytes of the same scene read from
 * JSON (materials and lights go through the same creators), and the
 * refusals with their messages: an unknown type, an unknown parameter (the
 * one warning), non-finite numbers, indices out of range, a bad transform,
 * objects and instances, building after commit and rendering before it.
 * A call that fails adds nothing.
 */
#include "paprsek.h"
#include "test.h"
#include "warnings.h"

#include <math.h>
#include <string.h>

#define CHECK_MSG(ctx, want)                                                                        \
    do {                                                                                            \
        CHECKF(strcmp(pk_context_error(ctx), want) == 0, "got \"%s\"", pk_context_error(ctx));     \
        pk_context_clear_error(ctx);                                                                \
    } while (0)

static const char json_scene[] =
    "{\"camera\": {\"look_from\": [0, 1, 4], \"look_at\": [0, 0.5, 0], \"fov\": 40},\n"
    " \"materials\": {\"shiny\": {\"type\": \"plastic\", \"albedo\": [0.7, 0.2, 0.1], \"roughness\": 0.3},\n"
    "                \"metal\": {\"type\": \"conductor\", \"specular\": [0.9, 0.8, 0.5], \"alpha\": 0.05},\n"
    "                \"floor\": {\"kd\": [0.6, 0.6, 0.6]}},\n"
    " \"spheres\": [{\"center\": [-0.6, 0.5, 0], \"radius\": 0.5, \"material\": \"shiny\"},\n"
    "             {\"center\": [0.6, 0.5, 0], \"radius\": 0.5, \"material\": \"metal\"},\n"
    "             {\"center\": [0, -1000, 0], \"radius\": 1000, \"material\": \"floor\"}],\n"
    " \"lights\": [{\"type\": \"spot\", \"position\": [0, 3, 2], \"direction\": [0, -3, -2], \"intensity\": 30,\n"
    "              \"outer_angle\": 40},\n"
    "            {\"type\": \"distant\", \"direction\": [1, -1, 0], \"intensity\": [0.5, 0.5, 0.6]}]}\n";

/* The scene of json_scene, built by calls. */
static pk_status build_same(pk_context *ctx, pk_scene **out)
{
    pk_scene *s = NULL;
    pk_params *p = NULL;
    uint32_t shiny = 0, metal = 0, floor_m = 0;
    pk_status st = pk_scene_create(ctx, "built", &s);
    if (st == PK_OK) st = pk_params_create(ctx, &p);
    if (st == PK_OK) st = pk_params_set_rgb(p, "albedo", 0.7f, 0.2f, 0.1f);
    if (st == PK_OK) st = pk_params_set_float(p, "roughness", 0.3f);
    if (st == PK_OK) st = pk_scene_add_material(ctx, s, "shiny", "plastic", p, &shiny);
    pk_params_clear(p);
    if (st == PK_OK) st = pk_params_set_rgb(p, "specular", 0.9f, 0.8f, 0.5f);
    if (st == PK_OK) st = pk_params_set_float(p, "alpha", 0.05f);
    if (st == PK_OK) st = pk_scene_add_material(ctx, s, "metal", "conductor", p, &metal);
    pk_params_clear(p);
    if (st == PK_OK) st = pk_params_set_rgb(p, "kd", 0.6f, 0.6f, 0.6f);
    if (st == PK_OK) st = pk_scene_add_material(ctx, s, "floor", NULL, p, &floor_m);
    const float c0[3] = {-0.6f, 0.5f, 0.0f}, c1[3] = {0.6f, 0.5f, 0.0f}, c2[3] = {0.0f, -1000.0f, 0.0f};
    if (st == PK_OK) st = pk_scene_add_sphere(ctx, s, c0, 0.5f, shiny);
    if (st == PK_OK) st = pk_scene_add_sphere(ctx, s, c1, 0.5f, metal);
    if (st == PK_OK) st = pk_scene_add_sphere(ctx, s, c2, 1000.0f, floor_m);
    pk_params_clear(p);
    if (st == PK_OK) st = pk_params_set_rgb(p, "position", 0.0f, 3.0f, 2.0f);
    if (st == PK_OK) st = pk_params_set_rgb(p, "direction", 0.0f, -3.0f, -2.0f);
    if (st == PK_OK) st = pk_params_set_float(p, "intensity", 30.0f);
    if (st == PK_OK) st = pk_params_set_float(p, "outer_angle", 40.0f);
    if (st == PK_OK) st = pk_scene_add_light(ctx, s, "spot", p);
    pk_params_clear(p);
    if (st == PK_OK) st = pk_params_set_rgb(p, "direction", 1.0f, -1.0f, 0.0f);
    if (st == PK_OK) st = pk_params_set_rgb(p, "intensity", 0.5f, 0.5f, 0.6f);
    if (st == PK_OK) st = pk_scene_add_light(ctx, s, "distant", p);
    pk_camera cam;
    pk_camera_init(&cam);
    const float from[3] = {0.0f, 1.0f, 4.0f}, at[3] = {0.0f, 0.5f, 0.0f};
    memcpy(cam.look_from, from, sizeof from);
    memcpy(cam.look_at, at, sizeof at);
    cam.fov_deg = 40.0f;
    if (st == PK_OK) st = pk_scene_set_camera(ctx, s, &cam);
    if (st == PK_OK) st = pk_scene_commit(ctx, s);
    pk_params_destroy(p);
    if (st != PK_OK) {
        pk_scene_destroy(s);
        return st;
    }
    *out = s;
    return PK_OK;
}

static pk_image *render(pk_context *ctx, const pk_scene *s)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 48;
    o.height = 32;
    o.spp = 2;
    o.threads = 2;
    pk_image *img = NULL;
    return pk_render(ctx, s, &o, &img, NULL) == PK_OK ? img : NULL;
}

/* A quad of two triangles at height y. */
static const float quad_pos[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
static const uint32_t quad_idx[6] = {0, 2, 1, 0, 3, 2};

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log w;
    warning_log_attach(ctx, &w);

    /* the same scene from JSON and from calls: the same bytes */
    pk_scene *a = NULL, *b = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, json_scene, strlen(json_scene), "same.json", NULL, &a) == PK_OK);
    REQUIRE(build_same(ctx, &b) == PK_OK);
    CHECKF(w.count == 0, "%s", w.all);
    pk_image *ia = render(ctx, a), *ib = render(ctx, b);
    REQUIRE(ia && ib);
    CHECK(memcmp(pk_image_pixels(ia), pk_image_pixels(ib), 48 * 32 * 3 * sizeof(float)) == 0);
    double sum = 0.0;
    for (int k = 0; k < 48 * 32 * 3; k++) sum += (double)pk_image_pixels(ia)[k];
    CHECK(sum > 48 * 32 * 0.05); /* a lit picture, not black */
    pk_image_destroy(ia);
    pk_image_destroy(ib);
    pk_scene_destroy(a);
    pk_scene_destroy(b);

    /* refusals */
    pk_scene *s = NULL;
    pk_params *p = NULL;
    REQUIRE(pk_scene_create(ctx, "t", &s) == PK_OK);
    REQUIRE(pk_params_create(ctx, &p) == PK_OK);
    uint32_t m = 99;
    CHECK(pk_scene_add_material(ctx, s, "x", "velvet", NULL, &m) == PK_ERR_PARSE && m == 99);
    CHECK_MSG(ctx, "t: material \"x\": type: must be one of \"diffuse\", \"conductor\", \"dielectric\", \"plastic\", "
                   "\"metallic_roughness\", \"emitter\", \"two_sided\", \"interface\", \"thin_dielectric\", "
                   "\"diffuse_transmission\", \"mix\", \"rough_diffuse\", \"phong\", \"coated\", \"principled\"");
    REQUIRE(pk_params_set_rgb(p, "albedo", 0.5f, 0.5f, 0.5f) == PK_OK);
    REQUIRE(pk_params_set_float(p, "albedoo", 1.0f) == PK_OK);
    warning_log_clear(&w);
    CHECK(pk_scene_add_material(ctx, s, "grey", "diffuse", p, &m) == PK_OK && m == 1);
    CHECK(w.count == 1);
    CHECKF(strcmp(w.last, "t: material \"grey\": albedoo: unknown parameter ignored") == 0, "%s", w.last);
    pk_params_clear(p);
    REQUIRE(pk_params_set_rgb(p, "kd", 0.5f, NAN, 0.5f) == PK_OK);
    CHECK(pk_scene_add_material(ctx, s, "bad", NULL, p, &m) == PK_ERR_PARSE);
    CHECK_MSG(ctx, "t: material \"bad\": kd[1]: numbers must be finite");
    pk_params_clear(p);
    REQUIRE(pk_params_set_float(p, "roughness", 2.0f) == PK_OK);
    CHECK(pk_scene_add_material(ctx, s, "bad", "plastic", p, &m) == PK_ERR_PARSE);
    CHECK_MSG(ctx, "t: material \"bad\": roughness: must be in 0..1");
    pk_params_clear(p);
    REQUIRE(pk_params_set_string(p, "type", "diffuse") == PK_OK);
    CHECK(pk_scene_add_material(ctx, s, "bad", "diffuse", p, &m) == PK_ERR_PARSE);
    CHECK_MSG(ctx, "t: material \"bad\": type: duplicate key");
    pk_params_clear(p);
    REQUIRE(pk_params_set_string(p, "interior", "fog") == PK_OK);
    CHECK(pk_scene_add_material(ctx, s, "bad", "dielectric", p, &m) == PK_ERR_UNSUPPORTED);
    CHECK_MSG(ctx, "t: material \"bad\": interior: media are not taken through the API yet");
    CHECK(pk_scene_add_material(ctx, s, "", "diffuse", NULL, &m) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: a material needs a name");

    pk_mesh_desc md = {0};
    md.positions = quad_pos;
    md.npositions = 4;
    md.indices = quad_idx;
    md.ntriangles = 2;
    md.material = 7;
    CHECK(pk_scene_add_mesh(ctx, s, &md) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: mesh: material 7 is not in the scene (it has 2)");
    md.material = 1;
    const uint32_t bad_idx[6] = {0, 2, 1, 0, 4, 2};
    md.indices = bad_idx;
    CHECK(pk_scene_add_mesh(ctx, s, &md) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: mesh: triangle 1: index 4 is out of range (4 positions)");
    md.indices = quad_idx;
    float nan_pos[12];
    memcpy(nan_pos, quad_pos, sizeof nan_pos);
    nan_pos[7] = INFINITY;
    md.positions = nan_pos;
    CHECK(pk_scene_add_mesh(ctx, s, &md) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: mesh: position 2 is not finite");
    md.positions = quad_pos;
    const float singular[12] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0};
    md.transform = singular;
    md.transform_rows = 3;
    CHECK(pk_scene_add_mesh(ctx, s, &md) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: mesh: the transform is singular");
    const float not_affine[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1};
    md.transform = not_affine;
    md.transform_rows = 4;
    CHECK(pk_scene_add_mesh(ctx, s, &md) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: mesh: the transform's last row must be 0 0 0 1");
    md.transform = NULL;
    const float centre[3] = {0.0f, 0.0f, 0.0f};
    CHECK(pk_scene_add_sphere(ctx, s, centre, -1.0f, 0) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: sphere: radius: must be a positive number");
    pk_params_clear(p);
    REQUIRE(pk_params_set_rgb(p, "position", 0.0f, 1.0f, 0.0f) == PK_OK);
    CHECK(pk_scene_add_light(ctx, s, "spot", p) == PK_ERR_PARSE);
    CHECK_MSG(ctx, "t: light 0: missing \"direction\"");
    CHECK(pk_scene_add_light(ctx, s, "area", p) == PK_ERR_PARSE);
    CHECK_MSG(ctx, "t: light 0: type: must be \"point\", \"spot\" or \"distant\"");
    REQUIRE(pk_params_set_float(p, "intensity", -2.0f) == PK_OK);
    CHECK(pk_scene_add_light(ctx, s, NULL, p) == PK_ERR_PARSE);
    CHECK_MSG(ctx, "t: light 0: intensity: must not be negative");
    pk_scene_info info;
    pk_scene_get_info(s, &info);
    CHECK(info.triangles == 0 && info.spheres == 0 && info.point_lights == 0 && info.materials == 2);

    /* objects and instances: one quad placed twice */
    uint32_t obj = 0;
    REQUIRE(pk_scene_begin_object(ctx, s) == PK_OK);
    CHECK(pk_scene_begin_object(ctx, s) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: an object is being defined already (objects do not nest)");
    REQUIRE(pk_scene_add_mesh(ctx, s, &md) == PK_OK);
    CHECK(pk_scene_commit(ctx, s) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: an object is still being defined (pk_scene_end_object)");
    REQUIRE(pk_scene_end_object(ctx, s, &obj) == PK_OK);
    const float up[12] = {1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 0};
    CHECK(pk_scene_add_instance(ctx, s, obj, NULL, 0) == PK_OK);
    CHECK(pk_scene_add_instance(ctx, s, obj, up, 3) == PK_OK);
    CHECK(pk_scene_add_instance(ctx, s, obj + 1, up, 3) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: instance: object 1 is not in the scene (it has 1)");
    pk_params_clear(p);
    REQUIRE(pk_params_set_rgb(p, "position", 0.0f, 3.0f, 0.0f) == PK_OK);
    CHECK(pk_scene_add_light(ctx, s, "point", p) == PK_OK);

    /* rendering before commit is refused; after it, building is */
    pk_image *img = NULL;
    CHECK(pk_render(ctx, s, NULL, &img, NULL) == PK_ERR_INVALID_ARGUMENT && !img);
    CHECK_MSG(ctx, "t: the scene is not committed (pk_scene_commit ends building it)");
    REQUIRE(pk_scene_commit(ctx, s) == PK_OK);
    CHECK(pk_scene_commit(ctx, s) == PK_OK); /* again: nothing to do */
    pk_scene_get_info(s, &info);
    CHECK(info.triangles == 4 && info.point_lights == 1);
    CHECK(info.bounds_max[1] == 1.0f);
    CHECK(pk_scene_add_mesh(ctx, s, &md) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "t: the scene is committed and takes no more geometry, materials or lights");
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = 8;
    o.threads = 1;
    CHECK(pk_render(ctx, s, &o, &img, NULL) == PK_OK && img);
    pk_image_destroy(img);
    pk_scene_destroy(s);

    /* a loaded scene takes no building calls */
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    CHECK(pk_scene_add_sphere(ctx, s, centre, 1.0f, 0) == PK_ERR_INVALID_ARGUMENT);
    CHECK_MSG(ctx, "cornell-box (built in): a scene read from a file takes no more geometry (build scenes with "
                   "pk_scene_create)");
    pk_scene_destroy(s);

    pk_params_destroy(p);
    pk_context_destroy(ctx);
    return test_done("test_scene_api");
}

/*
 * test_lights.c - the scene's light and emission constructors: each kind is
 * stored as given, anything a light cannot be is refused with
 * PK_ERR_INVALID_ARGUMENT and leaves the scene as it was, and the sensor
 * rule (scene_scale_emission) reaches every emitter; area emission is a
 * copy of a shape's material (scene_material_with_emission); the camera is
 * set only when it passes the one camera rule (scene_set_camera).
 */
#include "test.h"

#include "scene/camera.h"
#include "scene/scene.h"

static pk_context *ctx;

static bool same(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* st must be the refusal, leave n lights, and latch a message naming kind. */
static void refused(pk_status st, const pk_scene *s, size_t n, const char *kind)
{
    CHECK(st == PK_ERR_INVALID_ARGUMENT);
    CHECK(s->nlights == n);
    CHECKF(strstr(pk_context_error(ctx), kind) != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
}

static void check_kinds(void)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "lights", &s) == PK_OK);
    const vec3 p = v3(1.0f, 2.0f, 3.0f), I = v3(4.0f, 5.0f, 6.0f), z = v3(0.0f, 0.0f, 1.0f);
    REQUIRE(scene_light_point(ctx, s, p, I) == PK_OK);
    REQUIRE(scene_light_spot(ctx, s, p, z, 0.9f, 0.8f, SPOT_FALLOFF_ANGLE, I) == PK_OK);
    REQUIRE(scene_light_spot(ctx, s, p, z, 0.8f, 0.8f, SPOT_FALLOFF_SQUARED, I) == PK_OK); /* a hard edge */
    REQUIRE(scene_light_distant(ctx, s, z, I) == PK_OK);
    REQUIRE(s->nlights == 4);
    const point_light *l = s->lights;
    CHECK(same(l[0].position, p) && same(l[0].intensity, I) && same(l[0].spot_dir, v3s(0.0f)) && !l[0].distant);
    CHECK(same(l[1].spot_dir, z) && l[1].cos_inner == 0.9f && l[1].cos_outer == 0.8f &&
          l[1].spot_falloff == SPOT_FALLOFF_ANGLE && !l[1].distant);
    CHECK(l[2].spot_falloff == SPOT_FALLOFF_SQUARED);
    CHECK(l[3].distant && same(l[3].position, z) && same(l[3].intensity, I));

    const float nan = nanf("");
    refused(scene_light_point(ctx, s, v3(nan, 0.0f, 0.0f), I), s, 4, "point light");
    refused(scene_light_point(ctx, s, p, v3(1.0f, -1.0f, 1.0f)), s, 4, "point light");
    refused(scene_light_point(ctx, s, p, v3(1.0f, INFINITY, 1.0f)), s, 4, "point light");
    refused(scene_light_spot(ctx, s, p, v3(0.0f, 0.0f, 2.0f), 0.9f, 0.8f, 0, I), s, 4, "spot light");
    refused(scene_light_spot(ctx, s, p, z, 0.7f, 0.8f, 0, I), s, 4, "spot light");  /* inner outside outer */
    refused(scene_light_spot(ctx, s, p, z, 0.9f, nan, 0, I), s, 4, "spot light");
    refused(scene_light_spot(ctx, s, p, z, 0.9f, 0.8f, 7, I), s, 4, "spot light");
    refused(scene_light_distant(ctx, s, v3s(0.0f), I), s, 4, "distant light");
    refused(scene_light_distant(ctx, s, z, v3(nan, 1.0f, 1.0f)), s, 4, "distant light");
    scene_destroy(s);
}

static void check_scale(void)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "scale", &s) == PK_OK);
    uint32_t m;
    REQUIRE(scene_add_material(ctx, s, "lamp", &m) == PK_OK);
    s->materials[m].ke = v3(1.0f, 2.0f, 3.0f);
    REQUIRE(scene_light_point(ctx, s, v3s(0.0f), v3s(2.0f)) == PK_OK);
    scene_env_add_radiance(s, v3(0.5f, 0.25f, 1.0f));
    scene_env_add_radiance(s, v3(0.5f, 0.25f, 1.0f)); /* adds up */
    CHECK(s->env.set && same(s->env.radiance, v3(1.0f, 0.5f, 2.0f)));
    medium med;
    medium_init(&med);
    med.le = v3s(3.0f);
    uint32_t mi;
    REQUIRE(scene_add_medium(ctx, s, &med, &mi) == PK_OK);
    s->env.has_sun = true, s->env.sun_radiance = v3s(10.0f);
    s->env.has_sky = true, s->env.sky_scale = 1.0f;
    scene_scale_emission(s, 2.0f);
    CHECK(same(s->materials[m].ke, v3(2.0f, 4.0f, 6.0f)));
    CHECK(same(s->materials[0].ke, v3s(0.0f)));
    CHECK(same(s->lights[0].intensity, v3s(4.0f)));
    CHECK(same(s->env.radiance, v3(2.0f, 1.0f, 4.0f)));
    CHECK(same(s->media[mi].le, v3s(6.0f)));
    CHECK(same(s->env.sun_radiance, v3s(20.0f)) && s->env.sky_scale == 2.0f);
    scene_destroy(s);
}

static void check_emission(void)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "emission", &s) == PK_OK);
    uint32_t m, e;
    REQUIRE(scene_add_material(ctx, s, "white", &m) == PK_OK);
    s->materials[m].kd = v3(0.7f, 0.6f, 0.5f);
    s->materials[m].two_sided = true;
    REQUIRE(scene_material_with_emission(ctx, s, m, "white+lamp", v3s(5.0f), false, &e) == PK_OK);
    CHECK(e != m && s->nmaterials == 3);
    CHECK(same(s->materials[e].kd, s->materials[m].kd) && same(s->materials[e].ke, v3s(5.0f)));
    CHECK(!s->materials[e].two_sided && strcmp(s->materials[e].name, "white+lamp") == 0);
    CHECK(same(s->materials[m].ke, v3s(0.0f)) && s->materials[m].two_sided); /* the original is untouched */
    CHECK(scene_find_material(s, "white") == (int64_t)m);
    uint32_t bad = 99;
    CHECK(scene_material_with_emission(ctx, s, m, "neg", v3(1.0f, -1.0f, 1.0f), false, &bad) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    CHECK(scene_material_with_emission(ctx, s, 42, "none", v3s(1.0f), false, &bad) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    CHECK(s->nmaterials == 3 && bad == 99);
    scene_destroy(s);
}

static void check_camera(void)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "camera", &s) == PK_OK);
    pk_camera cam, def;
    pk_camera_init(&def);
    camera_look(&cam, v3(1.0f, 2.0f, 3.0f), v3(1.0f, 2.0f, 0.0f), v3(0.0f, 1.0f, 0.0f));
    CHECK(cam.look_from[0] == 1.0f && cam.look_from[1] == 2.0f && cam.look_from[2] == 3.0f);
    CHECK(cam.look_at[2] == 0.0f && cam.up[1] == 1.0f && cam.fov_deg == def.fov_deg && cam.projection == def.projection);
    CHECK(!s->has_camera);
    CHECK(scene_set_camera(s, &cam) == CAMERA_OK && s->has_camera && memcmp(&s->camera, &cam, sizeof cam) == 0);
    pk_camera bad = cam;
    bad.up[0] = 0.0f, bad.up[1] = 0.0f, bad.up[2] = 1.0f; /* parallel to the view */
    CHECK(scene_set_camera(s, &bad) == CAMERA_UP_PARALLEL);
    bad = cam;
    bad.fov_deg = 180.0f;
    CHECK(scene_set_camera(s, &bad) == CAMERA_FOV);
    CHECK(memcmp(&s->camera, &cam, sizeof cam) == 0); /* refused: unchanged */
    scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_kinds();
    check_scale();
    check_emission();
    check_camera();
    pk_context_destroy(ctx);
    return test_done("test_lights");
}

/*
 * test_lights.c - the scene's light and emission constructors: each kind is
 * stored as given, anything a light cannot be is refused with
 * PK_ERR_INVALID_ARGUMENT and leaves the scene as it was, and the sensor
 * rule (scene_scale_emission) reaches every emitter; area emission is a
 * copy of a shape's material (scene_material_with_emission); the camera is
 * set only when it passes the one camera rule (scene_set_camera); the
 * environment's sun, sky, frame and map constructors store what they are
 * given and refuse what the environment cannot be, and the sun's radiance
 * from an irradiance agrees with the irradiance integrated over its disc;
 * render settings are set and marked only within their options' ranges.
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

/* st must be a refusal that latched a message naming what. */
static void env_refused(pk_status st, pk_status want, const char *what)
{
    CHECK(st == want);
    CHECKF(strstr(pk_context_error(ctx), what) != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
}

static void check_environment(void)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "environment", &s) == PK_OK);
    CHECK(!s->env.set && !s->env.has_sun && !s->env.has_sky);
    const vec3 up = v3(0.0f, 1.0f, 0.0f), L = v3(1.0f, 2.0f, 3.0f);
    env_refused(scene_env_sun(ctx, s, v3(0.0f, 2.0f, 0.0f), L, 0.53f), PK_ERR_INVALID_ARGUMENT, "sun");
    env_refused(scene_env_sun(ctx, s, up, v3(-1.0f, 0.0f, 0.0f), 0.53f), PK_ERR_INVALID_ARGUMENT, "sun");
    env_refused(scene_env_sun(ctx, s, up, L, 0.0f), PK_ERR_INVALID_ARGUMENT, "sun");
    env_refused(scene_env_sun(ctx, s, up, L, 91.0f), PK_ERR_INVALID_ARGUMENT, "sun");
    CHECK(!s->env.set && !s->env.has_sun); /* refused: unchanged */
    CHECK(scene_env_sun(ctx, s, up, L, 2.0f) == PK_OK);
    CHECK(s->env.set && s->env.has_sun && same(s->env.sun_dir, up) && same(s->env.sun_radiance, L) &&
          s->env.sun_angle == 2.0f);
    env_refused(scene_env_sky(ctx, s, up, 11.0f, 1.0f, false, v3s(0.0f)), PK_ERR_INVALID_ARGUMENT, "sky");
    env_refused(scene_env_sky(ctx, s, up, 3.0f, -1.0f, false, v3s(0.0f)), PK_ERR_INVALID_ARGUMENT, "sky");
    env_refused(scene_env_sky(ctx, s, up, 3.0f, 1.0f, true, v3s(1.5f)), PK_ERR_INVALID_ARGUMENT, "sky");
    CHECK(!s->env.has_sky);
    CHECK(scene_env_sky(ctx, s, up, 4.0f, 0.5f, true, v3s(0.3f)) == PK_OK);
    CHECK(s->env.has_sky && s->env.sky_hosek && s->env.sky_turbidity == 4.0f && s->env.sky_scale == 0.5f &&
          same(s->env.sky_albedo, v3s(0.3f)));
    float rot[9];
    scene_rotation_y(90.0f, rot);
    scene_env_frame(s, rot);
    CHECK(memcmp(s->env.to_world, rot, sizeof rot) == 0);
    CHECK(fabsf(rot[2] - 1.0f) < 1e-6f && fabsf(rot[6] + 1.0f) < 1e-6f && rot[4] == 1.0f); /* +x to -z */
    /* decoded pixels: taken, one map per scene (the second's pixels freed) */
    float *px = mem_calloc(&s->alloc, 3 * 2, sizeof *px);
    REQUIRE(px);
    CHECK(scene_env_map_pixels(ctx, s, "sky.exr", px, 2, 1, 2.0f) == PK_OK);
    CHECK(s->env.map_rgb == px && s->env.map_w == 2 && s->env.map_h == 1 && s->env.map_scale == 2.0f &&
          strcmp(s->env.map, "sky.exr") == 0);
    float *px2 = mem_calloc(&s->alloc, 3, sizeof *px2);
    REQUIRE(px2);
    env_refused(scene_env_map_pixels(ctx, s, "b.exr", px2, 1, 1, 1.0f), PK_ERR_UNSUPPORTED, "one environment map");
    env_refused(scene_env_map(ctx, s, "b.exr", 1.0f), PK_ERR_UNSUPPORTED, "one environment map");
    CHECK(s->env.map_rgb == px);
    scene_destroy(s);

    /* a file that cannot be read: the error, and no map left behind */
    REQUIRE(scene_create(ctx, "environment", &s) == PK_OK);
    CHECK(scene_env_map(ctx, s, "/nonexistent/sky.hdr", 1.0f) != PK_OK);
    pk_context_clear_error(ctx);
    CHECK(!s->env.map && !s->env.map_rgb);
    env_refused(scene_env_map(ctx, s, "sky.hdr", -1.0f), PK_ERR_INVALID_ARGUMENT, "environment map");
    scene_destroy(s);

    /* a disc of uniform radiance L and angular diameter A gives, on a surface
     * facing it, E = int L cos(t) dw over the disc; integrated here by the
     * midpoint rule in t (dw = 2 pi sin t dt) */
    const float angles[3] = {0.53f, 5.0f, 60.0f};
    for (int i = 0; i < 3; i++) {
        const vec3 E = v3(100.0f, 50.0f, 1.0f);
        const vec3 Ls = scene_sun_radiance(E, angles[i]);
        const double h = 0.5 * (double)angles[i] * 3.14159265358979323846 / 180.0;
        const int n = 20000;
        double e = 0.0;
        for (int k = 0; k < n; k++) {
            const double t = (k + 0.5) * h / n;
            e += cos(t) * 2.0 * 3.14159265358979323846 * sin(t) * (h / n);
        }
        CHECKF(fabs(e * (double)Ls.x / 100.0 - 1.0) < 1e-4 && fabs(e * (double)Ls.z - 1.0) < 1e-4, "angle %g: E %g",
               (double)angles[i],
               e * (double)Ls.x);
    }
}

static void check_render_settings(void)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "settings", &s) == PK_OK);
    CHECK(!s->render.has_spp && !s->render.has_width);
    CHECK(scene_render_int(ctx, s, "spp", 16) == PK_OK && s->render.has_spp && s->render.opt.spp == 16);
    CHECK(scene_render_int(ctx, s, "max-depth", 5) == PK_OK && s->render.has_max_depth && s->render.opt.max_depth == 5);
    env_refused(scene_render_int(ctx, s, "spp", 0), PK_ERR_INVALID_ARGUMENT, "spp");
    env_refused(scene_render_int(ctx, s, "width", -3), PK_ERR_INVALID_ARGUMENT, "width");
    env_refused(scene_render_int(ctx, s, "colour", 1), PK_ERR_INVALID_ARGUMENT, "not known");
    CHECK(s->render.opt.spp == 16 && !s->render.has_width); /* refused: unchanged */
    env_refused(scene_render_clamp(ctx, s, -1.0f), PK_ERR_INVALID_ARGUMENT, "clamp");
    CHECK(!s->render.has_clamp_indirect);
    CHECK(scene_render_clamp(ctx, s, 10.0f) == PK_OK && s->render.opt.clamp_indirect == 10.0f);
    scene_render_fresnel(s, false);
    scene_render_integrator(s, PK_INTEGRATOR_WHITTED);
    CHECK(s->render.has_fresnel && s->render.opt.fresnel == 0 && s->render.has_integrator &&
          s->render.opt.integrator == PK_INTEGRATOR_WHITTED);
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    CHECK(o.spp == 16 && o.max_depth == 5 && o.fresnel == 0 && o.clamp_indirect == 10.0f);
    scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_kinds();
    check_scale();
    check_emission();
    check_camera();
    check_environment();
    check_render_settings();
    pk_context_destroy(ctx);
    return test_done("test_lights");
}

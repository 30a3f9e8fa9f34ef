/*
 * test_metallic_roughness.c - glTF 2.0's metallic-roughness material in the
 * renderers, from a JSON scene: light sampling, material sampling and both
 * weighted by MIS must give the same image (block means within confidence
 * intervals, block_stats.h), with the metal, a clearcoated dielectric, a
 * mixture and the thin sheet's transmission (KHR_materials_transmission) in
 * view, lit
 * through the sheet as well as in front of it; the Whitted integrator
 * renders the scene (with a point light); nothing is NaN. The light behind
 * the sheet is reached by light sampling too: its shadow rays leave from
 * the sheet's far side. The same scene with a rough glass wall checks that
 * for the dielectric's transmission.
 */
#include "test.h"

#include "paprsek.h"
#include "render/path.h"
#include "render/render.h"
#include "render/shading.h"
#include "scene/scene.h"

#include "block_stats.h"

#define SIZE 32
#define BLOCK 8
/* two-sided p = 1e-3 over 16 blocks x 3 channels x 2 comparisons x 2 scenes:
 * Phi^-1(1 - 0.001 / 384) */
#define Z_CRIT 4.56

static pk_context *ctx;

static void render_strategy(const pk_scene *s, int strategy, int spp, block_estimate *e)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = o.height = SIZE;
    o.spp = spp;
    o.max_depth = 8;
    o.threads = 2;
    pk_image *img[2];
    for (int k = 0; k < 2; k++) {
        o.seed = 500 + 31 * k + strategy;
        pk_renderer *r = NULL;
        pk_film *f = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        renderer_set_path_strategy(r, strategy);
        REQUIRE(pk_film_create(ctx, SIZE, SIZE, &f) == PK_OK);
        REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
        REQUIRE(pk_film_resolve(ctx, f, &img[k]) == PK_OK);
        const float *px = pk_image_pixels_const(img[k]);
        size_t nan = 0;
        for (size_t i = 0; i < 3 * (size_t)SIZE * SIZE; i++) nan += !isfinite(px[i]);
        CHECKF(nan == 0, "strategy %d: %zu non-finite values", strategy, nan);
        pk_film_destroy(f);
        pk_renderer_destroy(r);
    }
    block_estimate_from(img[0], img[1], BLOCK, e);
    pk_image_destroy(img[0]);
    pk_image_destroy(img[1]);
}

/* Every pixel of a Whitted render is finite and some are lit. */
static void render_whitted(const pk_scene *s)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_WHITTED;
    o.width = o.height = SIZE;
    o.threads = 2;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    const float *px = pk_image_pixels_const(img);
    size_t nan = 0, lit = 0;
    for (size_t i = 0; i < 3 * (size_t)SIZE * SIZE; i++) nan += !isfinite(px[i]), lit += px[i] > 0.0f;
    CHECKF(nan == 0 && lit > 0, "Whitted: %zu non-finite values, %zu lit", nan, lit);
    pk_image_destroy(img);
}

/* The maps at a hit: base colour from map_kd, metallic from map_mr's blue
 * channel and roughness from its green one, each times its constant. */
static void test_maps(void)
{
    const char *json =
        "{\"materials\": {\"m\": {\"type\": \"metallic_roughness\", \"metallic\": 0.5, \"roughness\": 0.8,"
        " \"base_color\": {\"checker\": {\"even\": [0.2, 0.4, 0.6], \"odd\": [0.2, 0.4, 0.6]}},"
        " \"metallic_roughness_map\": {\"checker\": {\"even\": [0.9, 0.25, 0.75], \"odd\": [0.9, 0.25, 0.75]}}}},"
        " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}]}";
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, json, strlen(json), "maps.json", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    REQUIRE(s->nmaterials >= 1 && s->has_textured);
    const scene_view v = scene_view_of(s);
    const ray r = {{0.0f, 5.0f, 0.0f}, 0.0f, {0.0f, -1.0f, 0.0f}, INFINITY};
    const hit h = {4.0f, 0, 0.0f, 0.0f};
    material tm;
    surface sf = surface_at(&v, &r, &h);
    CHECK(sf.m->textured && sf.m->map_mr.kind == TEX_CHECKER);
    sf = surface_texture(&v, &r, &h, 0.0f, sf, &tm);
    CHECKF(fabsf(tm.kd.x - 0.2f) < 1e-6f && fabsf(tm.kd.y - 0.4f) < 1e-6f && fabsf(tm.kd.z - 0.6f) < 1e-6f,
           "base colour %g %g %g", (double)tm.kd.x, (double)tm.kd.y, (double)tm.kd.z);
    CHECKF(fabsf(tm.metallic - 0.375f) < 1e-6f && fabsf(tm.roughness - 0.2f) < 1e-6f,
           "metallic %g, roughness %g", (double)tm.metallic, (double)tm.roughness);
    const shading sh = shading_at(&sf);
    CHECK(sh.b.type == PBSDF_METALLIC_ROUGHNESS && fabsf(sh.b.metallic - 0.375f) < 1e-6f);
    CHECK(fabsf(sh.b.alpha - 0.04f) < 1e-6f && sh.b.transmission == 0.0f && sh.b.ior == 1.5f);
    pk_scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_maps();
    /* A huge sphere of a rough thin sheet is a wall at z = -3 in front of the
     * camera; a small bright light sits behind it (inside the sphere), a
     * large dim one in front. In front of the wall: a metal ball, a
     * dielectric ball and a half-metallic transmissive one. */
    const char *json =
        "{\"materials\": {"
        " \"sheet\": %s,"
        " \"metal\": {\"type\": \"metallic_roughness\", \"base_color\": [0.95, 0.64, 0.54], \"roughness\": 0.35},"
        " \"plastic\": {\"type\": \"metallic_roughness\", \"base_color\": [0.2, 0.5, 0.8], \"metallic\": 0,"
        "   \"roughness\": 0.5, \"clearcoat\": 1, \"clearcoat_roughness\": 0.2},"
        " \"mixed\": {\"type\": \"metallic_roughness\", \"base_color\": [0.8, 0.8, 0.3], \"metallic\": 0.4,"
        "   \"roughness\": 0.6, \"transmission\": 0.5, \"ior\": 1.4},"
        " \"big\": {\"type\": \"emitter\", \"radiance\": [1.5, 1.5, 1.5]},"
        " \"small\": {\"type\": \"emitter\", \"radiance\": [30, 27, 24]}},"
        " \"camera\": {\"look_from\": [0, 0, 6], \"look_at\": [0, 0, 0], \"fov\": 45},"
        " \"spheres\": [{\"center\": [0, 0, -1003], \"radius\": 1000, \"material\": \"sheet\"},"
        "   {\"center\": [0.4, 0.6, -5], \"radius\": 0.4, \"material\": \"small\"},"
        "   {\"center\": [-1.3, -0.6, -1], \"radius\": 0.8, \"material\": \"metal\"},"
        "   {\"center\": [1.3, -0.6, -1], \"radius\": 0.8, \"material\": \"plastic\"},"
        "   {\"center\": [0, 1.1, -1.5], \"radius\": 0.6, \"material\": \"mixed\"},"
        "   {\"center\": [-6, 8, 8], \"radius\": 4, \"material\": \"big\"}]%s}";
    /* the wall: the thin sheet, or rough glass (the light then inside it) */
    const char *walls[2][2] = {
        {"thin sheet", "{\"type\": \"metallic_roughness\", \"base_color\": [0.9, 0.8, 0.7], \"metallic\": 0,"
                       " \"roughness\": 0.45, \"transmission\": 1}"},
        {"rough glass", "{\"type\": \"dielectric\", \"ior\": 1.5, \"roughness\": 0.45}"},
    };
    char text[4096];
    pk_scene *s = NULL;
    pk_status st;
    for (int k = 0; k < 2; k++) {
        snprintf(text, sizeof text, json, walls[k][1], "");
        st = pk_scene_load_json_memory(ctx, text, strlen(text), "mr.json", ".", &s);
        CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
        REQUIRE(st == PK_OK);
        static block_estimate mis, lights, bsdf;
        render_strategy(s, PATH_MIS, 64, &mis);
        render_strategy(s, PATH_LIGHTS_ONLY, 64, &lights);
        /* material sampling alone reaches the small light through rough
         * glass rarely: at 256 samples some blocks see it in neither render */
        render_strategy(s, PATH_BSDF_ONLY, k ? 4096 : 256, &bsdf);
        block_compare(walls[k][0], "MIS vs light sampling", &mis, &lights, Z_CRIT);
        block_compare(walls[k][0], "MIS vs BSDF sampling", &mis, &bsdf, Z_CRIT);
        pk_scene_destroy(s);
    }
    /* Whitted, with a point light (it does not sample emitting spheres) */
    snprintf(text, sizeof text, json, walls[0][1], ", \"lights\": [{\"position\": [2, 3, 3], \"intensity\": 8}]");
    st = pk_scene_load_json_memory(ctx, text, strlen(text), "mr.json", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    render_whitted(s);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_metallic_roughness");
}

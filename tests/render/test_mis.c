/*
 * test_mis.c - light sampling alone, material (BSDF) sampling alone and both
 * weighted by multiple importance sampling are three estimators of the same
 * image: on a scene with a small and a large light (and on the Cornell box),
 * their block means must agree within confidence intervals, each block's
 * variance measured from two renders with different seeds (block_stats.h).
 */
#include "test.h"

#include "paprsek.h"
#include "render/path.h"
#include "render/render.h"

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
    o.max_depth = 16;
    o.threads = 2;
    pk_image *img[2];
    for (int k = 0; k < 2; k++) {
        o.seed = 1000 + 17 * k + strategy;
        pk_renderer *r = NULL;
        pk_film *f = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        renderer_set_path_strategy(r, strategy);
        REQUIRE(pk_film_create(ctx, SIZE, SIZE, &f) == PK_OK);
        REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
        REQUIRE(pk_film_resolve(ctx, f, &img[k]) == PK_OK);
        pk_film_destroy(f);
        pk_renderer_destroy(r);
    }
    block_estimate_from(img[0], img[1], BLOCK, e);
    pk_image_destroy(img[0]);
    pk_image_destroy(img[1]);
}

static void check_scene(const char *name, const pk_scene *s, int spp)
{
    static block_estimate mis, lights, bsdf;
    render_strategy(s, PATH_MIS, spp, &mis);
    render_strategy(s, PATH_LIGHTS_ONLY, spp, &lights);
    /* material sampling alone finds small lights rarely: its pixel means are
     * the most skewed, so it gets more samples to be near normal */
    render_strategy(s, PATH_BSDF_ONLY, 4 * spp, &bsdf);
    block_compare(name, "MIS vs light sampling", &mis, &lights, Z_CRIT);
    block_compare(name, "MIS vs BSDF sampling", &mis, &bsdf, Z_CRIT);
    double vm = 0.0, vl = 0.0, vb = 0.0;
    for (int by = 0; by < mis.nb; by++)
        for (int bx = 0; bx < mis.nb; bx++)
            for (int c = 0; c < 3; c++) vm += mis.var[by][bx][c], vl += lights.var[by][bx][c], vb += bsdf.var[by][bx][c];
    printf("%s: summed block variances: MIS %.3g, lights %.3g, BSDF %.3g (at 4x the samples)\n", name, vm, vl, vb);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    /* a diffuse floor and ball under a large dim light and a small bright one */
    const char *json =
        "{\"materials\": {\"white\": {\"kd\": [0.7, 0.7, 0.7]}, \"red\": {\"kd\": [0.6, 0.15, 0.1]},"
        " \"big\": {\"kd\": [0, 0, 0], \"ke\": [1.5, 1.5, 1.5]}, \"small\": {\"kd\": [0, 0, 0], \"ke\": [20, 18, 15]}},"
        " \"camera\": {\"look_from\": [0, 2.5, 8], \"look_at\": [0, 1, 0], \"fov\": 40},"
        " \"spheres\": [{\"center\": [0, -1000, 0], \"radius\": 1000, \"material\": \"white\"},"
        "   {\"center\": [0, 1, 0], \"radius\": 1, \"material\": \"red\"},"
        "   {\"center\": [-7, 9, -5], \"radius\": 4, \"material\": \"big\"},"
        "   {\"center\": [2.5, 2.5, 1.5], \"radius\": 0.35, \"material\": \"small\"}]}";
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, json, strlen(json), "lights.json", ".", &s) == PK_OK);
    check_scene("two lights", s, 64);
    pk_scene_destroy(s);
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    check_scene("cornell", s, 64);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_mis");
}

/*
 * test_aov.c - the arbitrary outputs against what they must be: inside a
 * sphere of radius 10 seen from its centre, every camera ray travels 10, the
 * normal faces back along the ray, the albedo is the material's; the heatmap
 * counts at least the one node and the one sphere tested. The image itself
 * does not change when AOVs are asked for, and AOV films merge.
 */
#include "test.h"

#include "paprsek.h"

static pk_context *ctx;

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    const char *json =
        "{\"materials\": {\"w\": {\"kd\": [0.25, 0.5, 0.75], \"ke\": [1, 1, 1], \"two_sided\": true}},"
        " \"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [0, 0, -1], \"fov\": 60},"
        " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 10, \"material\": \"w\"}]}";
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, json, strlen(json), "aov.json", ".", &s) == PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 17;
    o.height = 13;
    o.spp = 4;
    o.threads = 2;
    const unsigned all = PK_AOV_ALBEDO | PK_AOV_NORMAL | PK_AOV_DEPTH | PK_AOV_HEATMAP;
    for (int integ = 0; integ < 2; integ++) {
        o.integrator = integ ? PK_INTEGRATOR_WHITTED : PK_INTEGRATOR_PATH;
        pk_renderer *r = NULL;
        pk_film *f = NULL, *plain = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        REQUIRE(pk_film_create_aovs(ctx, 17, 13, all, &f) == PK_OK);
        REQUIRE(pk_film_create(ctx, 17, 13, &plain) == PK_OK);
        CHECK(pk_film_aovs(f) == all && pk_film_aovs(plain) == 0);
        CHECK(pk_renderer_render(r, NULL, 0, f) == PK_OK);
        CHECK(pk_renderer_render(r, NULL, 0, plain) == PK_OK);
        pk_image *img = NULL, *ref = NULL, *alb = NULL, *nor = NULL, *dep = NULL, *heat = NULL;
        REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK && pk_film_resolve(ctx, plain, &ref) == PK_OK);
        CHECK(memcmp(pk_image_pixels_const(img), pk_image_pixels_const(ref), sizeof(float) * 3 * 17 * 13) == 0);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_ALBEDO, &alb) == PK_OK);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_NORMAL, &nor) == PK_OK);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_DEPTH, &dep) == PK_OK);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_HEATMAP, &heat) == PK_OK);
        const float *a = pk_image_pixels_const(alb), *n = pk_image_pixels_const(nor), *d = pk_image_pixels_const(dep),
                    *h = pk_image_pixels_const(heat);
        int bad = 0;
        for (int i = 0; i < 17 * 13; i++) {
            bad += fabsf(a[3 * i] - 0.25f) > 1e-6f || fabsf(a[3 * i + 1] - 0.5f) > 1e-6f ||
                   fabsf(a[3 * i + 2] - 0.75f) > 1e-6f;
            bad += fabsf(d[3 * i] - 10.0f) > 1e-3f || d[3 * i + 1] != d[3 * i] || d[3 * i + 2] != d[3 * i];
            bad += !(h[3 * i] >= 2.0f); /* the root and the sphere at least */
            /* the mean of unit normals facing the camera: nearly unit, pointing back (+z side) */
            float len = sqrtf(n[3 * i] * n[3 * i] + n[3 * i + 1] * n[3 * i + 1] + n[3 * i + 2] * n[3 * i + 2]);
            bad += !(len > 0.99f && len < 1.0001f) || !(n[3 * i + 2] > 0.5f);
        }
        /* the centre pixel looks along -z: its normal is +z */
        const int c = 6 * 17 + 8;
        CHECKF(fabsf(n[3 * c + 2] - 1.0f) < 1e-3f, "centre normal z %g", (double)n[3 * c + 2]);
        CHECKF(bad == 0, "%s: %d AOV values wrong", integ ? "whitted" : "path", bad);
        /* a film without the AOV refuses it; AOV films merge */
        pk_image *none = NULL;
        CHECK(pk_film_resolve_aov(ctx, plain, PK_AOV_DEPTH, &none) == PK_ERR_INVALID_ARGUMENT && !none);
        pk_context_clear_error(ctx);
        pk_film *g = NULL;
        REQUIRE(pk_film_create_aovs(ctx, 17, 13, all, &g) == PK_OK);
        CHECK(pk_film_merge(ctx, g, f) == PK_OK && pk_film_merge(ctx, g, f) == PK_OK);
        pk_image *dep2 = NULL;
        REQUIRE(pk_film_resolve_aov(ctx, g, PK_AOV_DEPTH, &dep2) == PK_OK);
        CHECK(memcmp(pk_image_pixels_const(dep2), d, sizeof(float) * 3 * 17 * 13) == 0);
        pk_image_destroy(dep2);
        pk_film_destroy(g);
        pk_image_destroy(img), pk_image_destroy(ref), pk_image_destroy(alb), pk_image_destroy(nor);
        pk_image_destroy(dep), pk_image_destroy(heat);
        pk_film_destroy(f), pk_film_destroy(plain);
        pk_renderer_destroy(r);
    }
    CHECK(pk_aov_parse("depth") == PK_AOV_DEPTH && pk_aov_parse("colour") == 0);
    CHECK(strcmp(pk_aov_name(PK_AOV_HEATMAP), "heatmap") == 0);
    pk_film *x = NULL;
    CHECK(pk_film_create_aovs(ctx, 4, 4, 64u, &x) == PK_ERR_INVALID_ARGUMENT && !x);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_aov");
}

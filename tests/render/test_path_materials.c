/*
 * test_path_materials.c - the JSON material types in the path tracer,
 * through the public API: furnaces.
 *
 * A sphere of the material under test sits inside a closed sphere (the
 * shell) that emits radiance E on both sides and reflects diffusely with
 * albedo r (r = 0: a JSON "emitter"; r > 0: an MTL-field material with kd
 * and ke). The radiance field inside is then E / (1 - r) everywhere, in every
 * direction. A lossless material (a smooth dielectric with white
 * transmittance, a white smooth mirror, a white diffuse) must render
 * as that field: the image's mean within Z_MEAN standard errors measured on
 * the image itself (plus float rounding, for the cases without any noise).
 * A material that loses energy (rough conductor, plastic, rough dielectric)
 * must render darker or equal, and never NaN.
 */
#include "test.h"

#include "paprsek.h"

#include <math.h>
#include <stdbool.h>

static pk_context *ctx;

#define Z_MEAN 3.89 /* two-sided p = 1e-4 */
#define SIZE 16
#define SPP 256

/* The shell (radius 10, radiance e, albedo r) around a sphere of material
 * inner (a JSON material object), the camera inside looking at it. */
static pk_scene *furnace(const char *inner, float r, float e)
{
    char shell[256], text[2048];
    if (r > 0.0f)
        snprintf(shell, sizeof shell, "{\"kd\": [%g, %g, %g], \"ke\": [%g, %g, %g], \"two_sided\": true}", (double)r,
                 (double)r, (double)r, (double)e, (double)e, (double)e);
    else
        snprintf(shell, sizeof shell, "{\"type\": \"emitter\", \"radiance\": [%g, %g, %g], \"two_sided\": true}",
                 (double)e, (double)e, (double)e);
    snprintf(text, sizeof text,
             "{\"materials\": {\"shell\": %s, \"inner\": %s},"
             " \"camera\": {\"look_from\": [0, 1, 5], \"look_at\": [0, 0, -4], \"fov\": 50},"
             " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 10, \"material\": \"shell\"},"
             "               {\"center\": [0, 0, -4], \"radius\": 2, \"material\": \"inner\"}]}",
             shell, inner);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "furnace.json", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return s;
}

/* Renders; returns the mean of the green channel and its standard error;
 * *nan counts non-finite values in all channels. */
static double render_mean(const pk_scene *s, double *se, size_t *nan)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = o.height = SIZE;
    o.spp = SPP;
    o.max_depth = 64;
    o.threads = 2;
    o.seed = 3;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    const float *px = pk_image_pixels_const(img);
    const size_t P = SIZE * SIZE;
    double sum = 0.0, sum2 = 0.0;
    *nan = 0;
    for (size_t i = 0; i < P; i++) {
        for (int c = 0; c < 3; c++)
            if (!isfinite(px[3 * i + c])) (*nan)++;
        double v = (double)px[3 * i + 1];
        sum += v, sum2 += v * v;
    }
    const double mean = sum / (double)P, var = (sum2 - sum * sum / (double)P) / (double)(P - 1);
    *se = sqrt(var > 0.0 ? var : 0.0) / sqrt((double)P);
    pk_image_destroy(img);
    return mean;
}

/* lossless: mean == field; else mean <= field. */
static void check(const char *inner, float r, float e, bool lossless)
{
    const double want = (double)e / (1.0 - (double)r);
    pk_scene *s = furnace(inner, r, e);
    double se;
    size_t nan;
    const double mean = render_mean(s, &se, &nan);
    const double slack = Z_MEAN * se + 1e-5 * want; /* the float sums of a noiseless render */
    printf("%s in a shell of albedo %.2f, E %.2f: mean %.5f, field %.5f (se %.5f)\n", inner, (double)r, (double)e,
           mean, want, se);
    CHECKF(nan == 0, "%s: %zu non-finite values", inner, nan);
    if (lossless)
        CHECKF(fabs(mean - want) <= slack, "%s: mean %.5f, want %.5f (%.2f standard errors)", inner, mean, want,
               se > 0.0 ? fabs(mean - want) / se : HUGE_VAL);
    else
        CHECKF(mean <= want + slack, "%s: mean %.5f brighter than the field %.5f", inner, mean, want);
    pk_scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    const char *lossless[] = {
        "{\"type\": \"dielectric\", \"ior\": 1.5, \"roughness\": 0, \"transmittance\": [1, 1, 1]}",
        "{\"type\": \"conductor\", \"specular\": [1, 1, 1], \"roughness\": 0}",
        "{\"type\": \"dielectric\", \"ior\": 1.0}",
        "{\"type\": \"diffuse\", \"albedo\": [1, 1, 1]}",
        /* textured: a white image (sRGB 255 is 1), a checker of white */
        "{\"type\": \"diffuse\", \"albedo\": {\"texture\": \"" PK_TEST_DATA "/tex_white.png\", \"scale\": 3}}",
        "{\"type\": \"diffuse\", \"albedo\": {\"checker\": {\"even\": [1, 1, 1], \"odd\": 1}}}",
        "{\"type\": \"diffuse\", \"albedo\": [1, 1, 1], \"two_sided\": true}",
        /* glTF metallic-roughness: the smooth white metal is a perfect mirror;
         * the smooth white thin sheet reflects F and transmits 1 - F; a white
         * metallic-roughness map leaves metallic 1 and roughness 0 */
        "{\"type\": \"metallic_roughness\", \"base_color\": [1, 1, 1], \"metallic\": 1, \"roughness\": 0}",
        "{\"type\": \"metallic_roughness\", \"base_color\": [1, 1, 1], \"metallic\": 0, \"roughness\": 0,"
        " \"transmission\": 1}",
        "{\"type\": \"metallic_roughness\", \"roughness\": 0,"
        " \"metallic_roughness_map\": {\"texture\": \"" PK_TEST_DATA "/tex_white.png\"}}",
    };
    const char *lossy[] = {
        "{\"type\": \"conductor\", \"roughness\": 0.7}",
        "{\"type\": \"conductor\", \"specular\": [1, 1, 1], \"alpha\": 1}",
        "{\"type\": \"plastic\", \"albedo\": [1, 1, 1], \"roughness\": 0.5}",
        "{\"type\": \"plastic\", \"albedo\": [1, 1, 1]}",
        "{\"type\": \"dielectric\", \"ior\": 1.5, \"roughness\": 0.6}",
        "{\"type\": \"dielectric\", \"ior\": 1.5, \"transmittance\": [0.5, 0.8, 1]}",
        "{\"type\": \"diffuse\", \"albedo\": [0.5, 0.5, 0.5]}",
        "{\"type\": \"diffuse\", \"albedo\": {\"texture\": \"" PK_TEST_DATA "/tex_rgbw.png\"}}",
        "{\"type\": \"diffuse\", \"albedo\": {\"checker\": {\"even\": 1, \"odd\": 0.25}}}",
        "{\"type\": \"metallic_roughness\", \"roughness\": 0.7}",
        "{\"type\": \"metallic_roughness\", \"base_color\": [0.9, 0.6, 0.3], \"metallic\": 0.5, \"roughness\": 0.4}",
        "{\"type\": \"metallic_roughness\", \"base_color\": [1, 1, 1], \"metallic\": 0, \"roughness\": 0.5,"
        " \"transmission\": 1, \"ior\": 1.33}",
        "{\"type\": \"metallic_roughness\", \"base_color\": [0.8, 0.8, 0.8], \"metallic\": 0, \"roughness\": 1}",
        "{\"type\": \"metallic_roughness\", \"base_color\": [1, 1, 1], \"roughness\": 0.3, \"clearcoat\": 1,"
        " \"clearcoat_roughness\": 0.1}",
        "{\"type\": \"metallic_roughness\", \"base_color\": {\"texture\": \"" PK_TEST_DATA "/tex_rgbw.png\"},"
        " \"roughness\": 0.3, \"metallic_roughness_map\": {\"texture\": \"" PK_TEST_DATA "/tex_rgbw.png\"}}",
    };
    for (size_t i = 0; i < sizeof lossless / sizeof lossless[0]; i++) {
        check(lossless[i], 0.0f, 0.5f, true); /* a pure emitter shell: no noise at all */
        check(lossless[i], 0.5f, 0.5f, true); /* a diffuse shell: noise */
    }
    for (size_t i = 0; i < sizeof lossy / sizeof lossy[0]; i++) {
        check(lossy[i], 0.0f, 0.5f, false);
        check(lossy[i], 0.5f, 0.5f, false);
    }
    pk_context_destroy(ctx);
    return test_done("test_path_materials");
}

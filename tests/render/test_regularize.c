/*
 * test_regularize.c - path regularisation (pk_render_options.regularize):
 * it leaves scenes without near-specular surfaces bit for bit as they were,
 * and on a caustic (a glass ball on a diffuse floor under a small lamp:
 * floor -> glass -> lamp paths that only BSDF sampling could find) it
 * lowers the variance measured from two seeds, at the price of a small,
 * printed bias in the image's mean.
 */
#include "test.h"

#include "paprsek.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static pk_context *ctx;

#define SIZE 48

static pk_scene *scene(const char *ball)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"materials\": {\"floor\": {\"kd\": [0.8, 0.8, 0.8]}, \"ball\": %s,"
             "                \"lamp\": {\"type\": \"emitter\", \"radiance\": [300, 300, 300]}},"
             " \"camera\": {\"look_from\": [0, 3, 6], \"look_at\": [0, 0.5, 0], \"fov\": 40},"
             " \"spheres\": [{\"center\": [0, -1000, 0], \"radius\": 1000, \"material\": \"floor\"},"
             "               {\"center\": [0, 1, 0], \"radius\": 1, \"material\": \"ball\"},"
             "               {\"center\": [0.5, 4.5, -0.5], \"radius\": 0.2, \"material\": \"lamp\"}]}",
             ball);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "caustic.json", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return s;
}

static pk_image *render(const pk_scene *s, int regularize, int seed, int spp)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = SIZE;
    o.spp = spp;
    o.seed = seed;
    o.threads = 2;
    o.regularize = regularize;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    return img;
}

static double lum(const float *p) { return 0.2126 * (double)p[0] + 0.7152 * (double)p[1] + 0.0722 * (double)p[2]; }

/* Mean luminance of a, and the per-pixel variance of one render estimated
 * from two seeds: mean of (a - b)^2 / 2. */
static void stats(const pk_image *a, const pk_image *b, double *mean, double *var)
{
    const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b);
    double m = 0.0, v = 0.0;
    for (int i = 0; i < SIZE * SIZE; i++) {
        double x = lum(pa + 3 * i), y = lum(pb + 3 * i);
        m += (x + y) / 2.0;
        v += (x - y) * (x - y) / 2.0;
    }
    *mean = m / (SIZE * SIZE);
    *var = v / (SIZE * SIZE);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    /* nothing near-specular: the same bits */
    pk_scene *diffuse = scene("{\"kd\": [0.5, 0.4, 0.3]}");
    pk_image *d0 = render(diffuse, 0, 1, 8), *d1 = render(diffuse, 1, 1, 8);
    CHECK(memcmp(pk_image_pixels_const(d0), pk_image_pixels_const(d1), sizeof(float) * 3 * SIZE * SIZE) == 0);
    pk_image_destroy(d0);
    pk_image_destroy(d1);
    pk_scene_destroy(diffuse);

    /* a glass ball's caustic */
    pk_scene *glass = scene("{\"type\": \"dielectric\", \"ior\": 1.5}");
    double m[2], v[2];
    for (int r = 0; r < 2; r++) {
        pk_image *a = render(glass, r, 1, 16), *b = render(glass, r, 2, 16);
        stats(a, b, &m[r], &v[r]);
        pk_image_destroy(a);
        pk_image_destroy(b);
    }
    pk_image *ref_a = render(glass, 0, 3, 256), *ref_b = render(glass, 0, 4, 256);
    double mref, vref;
    stats(ref_a, ref_b, &mref, &vref);
    pk_image_destroy(ref_a);
    pk_image_destroy(ref_b);
    pk_scene_destroy(glass);
    printf("caustic, 16 spp: off: mean %.4f, variance %.4g; regularised: mean %.4f, variance %.4g (%.2fx); "
           "reference (512 spp unregularised) mean %.4f, the regularised mean %+.1f %% from it\n",
           m[0], v[0], m[1], v[1], v[0] / v[1], mref, 100.0 * (m[1] / mref - 1.0));
    CHECKF(v[1] < v[0], "regularisation did not lower the variance: %.4g against %.4g", v[1], v[0]);
    /* unregularised agrees with the reference within its own noise (sanity) */
    CHECK(fabs(m[0] - mref) < 5.0 * sqrt(v[0] / (SIZE * SIZE)) + 1e-3 * mref);
    pk_context_destroy(ctx);
    return test_done("test_regularize");
}

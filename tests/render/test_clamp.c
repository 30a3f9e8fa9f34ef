/*
 * test_clamp.c - indirect clamping (pk_render_options.clamp_indirect): it
 * touches only light that bounced after the first visible surface, so a
 * render of direct light alone (max_depth 1) is the same bit for bit with
 * any clamp, as is a render with a clamp above every contribution; on a
 * caustic (a glass ball on a floor under a small lamp) it lowers the
 * variance measured from two seeds and can only darken the image (its
 * bias, printed); a scene file's render.clamp_indirect is read and a
 * negative one refused.
 */
#include "test.h"

#include "paprsek.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

static pk_context *ctx;

#define SIZE 48

static pk_scene *scene(const char *render)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"materials\": {\"floor\": {\"kd\": [0.8, 0.8, 0.8]}, \"ball\": {\"type\": \"dielectric\", \"ior\": 1.5},"
             "                \"lamp\": {\"type\": \"emitter\", \"radiance\": [300, 300, 300]}},"
             " \"camera\": {\"look_from\": [0, 3, 6], \"look_at\": [0, 0.5, 0], \"fov\": 40},"
             " %s"
             " \"spheres\": [{\"center\": [0, -1000, 0], \"radius\": 1000, \"material\": \"floor\"},"
             "               {\"center\": [0, 1, 0], \"radius\": 1, \"material\": \"ball\"},"
             "               {\"center\": [0.5, 4.5, -0.5], \"radius\": 0.2, \"material\": \"lamp\"}]}",
             render);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "caustic.json", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    return st == PK_OK ? s : NULL;
}

static pk_image *render(const pk_scene *s, float clamp, int depth, int seed, int spp)
{
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.width = o.height = SIZE;
    o.spp = spp;
    o.seed = seed;
    o.threads = 2;
    o.max_depth = depth;
    if (clamp >= 0.0f) o.clamp_indirect = clamp;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    return img;
}

static bool same(const pk_image *a, const pk_image *b)
{
    return memcmp(pk_image_pixels_const(a), pk_image_pixels_const(b), sizeof(float) * 3 * SIZE * SIZE) == 0;
}

static double lum(const float *p) { return 0.2126 * (double)p[0] + 0.7152 * (double)p[1] + 0.0722 * (double)p[2]; }

static void stats(const pk_image *a, const pk_image *b, double *mean, double *var)
{
    const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b);
    double m = 0.0, v = 0.0;
    for (int i = 0; i < SIZE * SIZE; i++) {
        const double x = lum(pa + 3 * i), y = lum(pb + 3 * i);
        m += (x + y) / 2.0;
        v += (x - y) * (x - y) / 2.0;
    }
    *mean = m / (SIZE * SIZE);
    *var = v / (SIZE * SIZE);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *s = scene("");
    REQUIRE(s != NULL);
    /* direct light only: nothing to clamp, whatever the clamp */
    pk_image *d0 = render(s, 0.0f, 1, 1, 4), *d1 = render(s, 1e-3f, 1, 1, 4);
    CHECK(same(d0, d1));
    pk_image_destroy(d0), pk_image_destroy(d1);
    /* a clamp above everything changes nothing */
    pk_image *h0 = render(s, 0.0f, 8, 1, 4), *h1 = render(s, 3e38f, 8, 1, 4);
    CHECK(same(h0, h1));
    pk_image_destroy(h0), pk_image_destroy(h1);
    /* the caustic: less variance, never brighter */
    pk_image *a0 = render(s, 0.0f, 8, 1, 16), *a1 = render(s, 0.0f, 8, 2, 16);
    pk_image *c0 = render(s, 4.0f, 8, 1, 16), *c1 = render(s, 4.0f, 8, 2, 16);
    double m_off, v_off, m_on, v_on;
    stats(a0, a1, &m_off, &v_off);
    stats(c0, c1, &m_on, &v_on);
    int brighter = 0;
    const float *pa = pk_image_pixels_const(a0), *pc = pk_image_pixels_const(c0);
    for (int i = 0; i < 3 * SIZE * SIZE; i++) brighter += pc[i] > pa[i] * (1.0f + 1e-5f) + 1e-7f;
    CHECKF(brighter == 0, "%d values brighter with the clamp (same seed)", brighter);
    CHECKF(v_on < 0.5 * v_off, "variance %.4g with the clamp, %.4g without", v_on, v_off);
    printf("  caustic, 16 spp, clamp 4: variance %.4g -> %.4g (%.1fx less), mean %.5f -> %.5f (%+.1f %%)\n", v_off, v_on,
           v_off / v_on, m_off, m_on, 100.0 * (m_on / m_off - 1.0));
    pk_image_destroy(a0), pk_image_destroy(a1), pk_image_destroy(c0), pk_image_destroy(c1);
    pk_scene_destroy(s);
    /* the scene file's setting */
    s = scene("\"render\": {\"clamp_indirect\": 4},");
    if (s) {
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        CHECK(o.clamp_indirect == 4.0f);
        pk_scene_destroy(s);
    }
    pk_scene *bad = NULL;
    const char *text = "{\"render\": {\"clamp_indirect\": -1}}";
    CHECK(pk_scene_load_json_memory(ctx, text, strlen(text), "bad.json", ".", &bad) != PK_OK && !bad);
    CHECKF(strstr(pk_context_error(ctx), "render.clamp_indirect") != NULL, "%s", pk_context_error(ctx));
    pk_context_destroy(ctx);
    return test_done("test_clamp");
}

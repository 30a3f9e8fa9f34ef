/*
 * test_mix.c - the mix material (MAT_MIX), chosen per hit by a hash of the
 * hit point and the direction (render/surface.h): the share of hits that
 * take the second material matches the amount within a binomial bound, for
 * one mix and for a mix of mixes (whose levels must be independent); the
 * choice is the same for the same hit; and a white sphere under a uniform
 * sky, mixed with black at amount 0.3, renders 0.7 times as bright as the
 * white sphere alone (within the renders' measured standard errors), the
 * same bytes on a second render. Fixed seeds.
 */
#include "test.h"

#include "paprsek.h"
#include "render/sampling.h"
#include "render/surface.h"

#include <math.h>
#include <string.h>

/* Random hits: a point in the unit cube, a unit direction. */
static void random_hit(rng *g, vec3 *p, vec3 *d)
{
    *p = v3(rng_float(g), rng_float(g), rng_float(g));
    const float z = 1.0f - 2.0f * rng_float(g), phi = 2.0f * PK_PI * rng_float(g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    *d = v3(r * cosf(phi), r * sinf(phi), z);
}

static void test_choice(void)
{
    /* 0 white, 1 black, 2 grey, 3 mix(0, 1, 0.3), 4 mix(2, 3, 0.4): P(2) = 0.6, P(0) = 0.4 * 0.7, P(1) = 0.4 * 0.3 */
    material mats[5];
    for (int i = 0; i < 5; i++) material_init(&mats[i]);
    material_diffuse(&mats[0], v3s(1.0f));
    material_diffuse(&mats[1], v3s(0.0f));
    material_diffuse(&mats[2], v3s(0.5f));
    material_mix(&mats[3], 0, 1, 0.3f);
    material_mix(&mats[4], 2, 3, 0.4f);
    scene_view v;
    memset(&v, 0, sizeof v);
    v.materials = mats;
    v.nmaterials = 5;
    rng g = rng_seed(3, 0x5eed);
    const long n = 200000;
    long one[2] = {0, 0}, two[3] = {0, 0, 0}, unstable = 0;
    for (long k = 0; k < n; k++) {
        vec3 p, d;
        random_hit(&g, &p, &d);
        const ray r = {v3_sub(p, d), 0.0f, d, INFINITY};
        const hit h = {1.0f, 0u, 0.0f, 0.0f};
        const material *a = surface_mix_choose(&v, &r, &h, p, &mats[3]);
        const material *b = surface_mix_choose(&v, &r, &h, p, &mats[4]);
        one[a - mats]++; /* 0 or 1 */
        two[b == &mats[2] ? 0 : b == &mats[0] ? 1 : 2]++;
        unstable += surface_mix_choose(&v, &r, &h, p, &mats[3]) != a || surface_mix_choose(&v, &r, &h, p, &mats[4]) != b;
    }
    CHECK(one[0] + one[1] == n && two[0] + two[1] + two[2] == n);
    CHECKF(unstable == 0, "%ld hits chose differently a second time", unstable);
    /* binomial bounds, 4.5 standard deviations */
    const double want1 = 0.3, want2[3] = {0.6, 0.4 * 0.7, 0.4 * 0.3};
    const double f1 = (double)one[1] / n;
    CHECKF(fabs(f1 - want1) <= 4.5 * sqrt(want1 * (1.0 - want1) / n), "mix 0.3: %.5f of hits took the second", f1);
    for (int i = 0; i < 3; i++) {
        const double f = (double)two[i] / n;
        CHECKF(fabs(f - want2[i]) <= 4.5 * sqrt(want2[i] * (1.0 - want2[i]) / n),
               "mix of mixes: material %d taken at %.5f, expected %.3f", i, f, want2[i]);
    }
    printf("  mix 0.3: %.5f; mix of mixes: %.5f %.5f %.5f\n", f1, (double)two[0] / n, (double)two[1] / n,
           (double)two[2] / n);
    /* amounts 0 and 1: always the first, always the second */
    material_mix(&mats[3], 0, 1, 0.0f);
    vec3 p = v3(0.2f, 0.3f, 0.4f), d = v3(0.0f, 0.0f, 1.0f);
    const ray r = {p, 0.0f, d, INFINITY};
    const hit h = {1.0f, 0u, 0.0f, 0.0f};
    CHECK(surface_mix_choose(&v, &r, &h, p, &mats[3]) == &mats[0]);
    material_mix(&mats[3], 0, 1, 1.0f);
    CHECK(surface_mix_choose(&v, &r, &h, p, &mats[3]) == &mats[1]);
}

/* A sphere under a uniform sky of radiance 1, its material given. */
static pk_scene *sphere_scene(pk_context *ctx, const char *materials, const char *mat)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"camera\": {\"look_from\": [0, 0, 4], \"look_at\": [0, 0, 0], \"fov\": 30},"
             " \"materials\": {%s}, \"environment\": [1, 1, 1],"
             " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"%s\"}]}",
             materials, mat);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_memory(ctx, "json", json, strlen(json), "mix", NULL, &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return s;
}

#define SIZE 48
static pk_image *render(pk_context *ctx, const pk_scene *s)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = SIZE;
    o.spp = 16;
    o.seed = 5;
    o.threads = 2;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    return img;
}

/* Mean and standard error of the green channel over the pixels well inside
 * the sphere's disc (radius 1 at distance 4, fov 30: about 0.27 of the
 * frame's height across). */
static void disc_stats(const pk_image *img, double *mean, double *se)
{
    const float *px = pk_image_pixels_const(img);
    double s = 0.0, s2 = 0.0;
    long n = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            const double dx = (x + 0.5) / SIZE - 0.5, dy = (y + 0.5) / SIZE - 0.5;
            if (dx * dx + dy * dy > 0.18 * 0.18) continue;
            const double v = px[3 * (y * SIZE + x) + 1];
            s += v, s2 += v * v, n++;
        }
    *mean = s / n;
    *se = sqrt(fmax(s2 / n - *mean * *mean, 0.0) / (n - 1));
}

static void test_furnace(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    const char *mats = "\"white\": {\"type\": \"diffuse\", \"albedo\": [0.8, 0.8, 0.8]},"
                       " \"black\": {\"type\": \"diffuse\", \"albedo\": [0, 0, 0]},"
                       " \"mixed\": {\"type\": \"mix\", \"materials\": [\"white\", \"black\"], \"amount\": 0.3}";
    pk_scene *w = sphere_scene(ctx, mats, "white"), *m = sphere_scene(ctx, mats, "mixed");
    pk_image *iw = render(ctx, w), *im = render(ctx, m), *im2 = render(ctx, m);
    double mw, sw, mm, sm;
    disc_stats(iw, &mw, &sw);
    disc_stats(im, &mm, &sm);
    const double bound = 4.5 * sqrt(sm * sm + 0.49 * sw * sw);
    printf("  furnace: white %.5f (+-%.2g), mix 0.3 with black %.5f (+-%.2g), 0.7 x white %.5f\n", mw, sw, mm, sm,
           0.7 * mw);
    CHECKF(fabs(mm - 0.7 * mw) <= bound, "mix: %.5f, expected 0.7 x %.5f = %.5f (bound %.2g)", mm, mw, 0.7 * mw, bound);
    CHECK(fabs(mw - 0.8) < 0.02); /* a convex white sphere under a sky of 1 reflects its albedo */
    CHECKF(memcmp(pk_image_pixels_const(im), pk_image_pixels_const(im2), sizeof(float) * 3 * SIZE * SIZE) == 0,
           "two renders of the mix differ");
    pk_image_destroy(iw);
    pk_image_destroy(im);
    pk_image_destroy(im2);
    pk_scene_destroy(w);
    pk_scene_destroy(m);
    pk_context_destroy(ctx);
}

int main(void)
{
    test_choice();
    test_furnace();
    return test_done("test_mix");
}

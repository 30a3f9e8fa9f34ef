/*
 * test_mis.c - light sampling alone, material (BSDF) sampling alone and both
 * weighted by multiple importance sampling are three estimators of the same
 * image: on a scene with a small and a large light (and on the Cornell box),
 * their block means must agree within confidence intervals.
 *
 * The variance of a block mean is measured, not assumed: each strategy
 * renders the image twice with different seeds; for every pixel the
 * difference of the two renders has mean 0 and variance 2 sigma_p^2, so
 * sum_p (a_p - b_p)^2 / 2 estimates sum_p sigma_p^2 without bias, and the
 * mean of the two renders over a block of n pixels has variance
 * sum_p sigma_p^2 / (2 n^2).
 */
#include "test.h"

#include "paprsek.h"
#include "render/path.h"
#include "render/render.h"

#define SIZE 32
#define BLOCK 8
#define NB (SIZE / BLOCK)
/* two-sided p = 1e-3 over 16 blocks x 3 channels x 2 comparisons x 2 scenes:
 * Phi^-1(1 - 0.001 / 384) */
#define Z_CRIT 4.56

static pk_context *ctx;

typedef struct estimate {
    double mean[NB][NB][3], var[NB][NB][3];
} estimate;

static void render_strategy(const pk_scene *s, int strategy, int spp, estimate *e)
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
    const float *a = pk_image_pixels_const(img[0]), *b = pk_image_pixels_const(img[1]);
    const double n = BLOCK * BLOCK;
    memset(e, 0, sizeof *e);
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            for (int c = 0; c < 3; c++) {
                size_t i = 3 * ((size_t)y * SIZE + (size_t)x) + (size_t)c;
                double va = (double)a[i], vb = (double)b[i];
                e->mean[y / BLOCK][x / BLOCK][c] += 0.5 * (va + vb) / n;
                e->var[y / BLOCK][x / BLOCK][c] += (va - vb) * (va - vb) / 2.0 / (2.0 * n * n);
            }
    pk_image_destroy(img[0]);
    pk_image_destroy(img[1]);
}

static void compare(const char *scene, const char *what, const estimate *p, const estimate *q)
{
    double worst = 0.0;
    int bad = 0;
    for (int by = 0; by < NB; by++)
        for (int bx = 0; bx < NB; bx++)
            for (int c = 0; c < 3; c++) {
                double d = p->mean[by][bx][c] - q->mean[by][bx][c];
                double sd = sqrt(p->var[by][bx][c] + q->var[by][bx][c]);
                double z = sd > 0.0 ? fabs(d) / sd : (d == 0.0 ? 0.0 : (double)INFINITY);
                if (z > worst) worst = z;
                if (z > Z_CRIT) {
                    bad++;
                    fprintf(stderr, "%s: %s: block (%d, %d) channel %d: %.5f vs %.5f, z = %.2f\n", scene, what, bx, by,
                            c, p->mean[by][bx][c], q->mean[by][bx][c], z);
                }
            }
    printf("%s: %s: largest |z| over %d block means %.2f (bound %.2f)\n", scene, what, NB * NB * 3, worst, Z_CRIT);
    CHECKF(bad == 0, "%s: %s: %d block means outside their confidence intervals", scene, what, bad);
}

static void check_scene(const char *name, const pk_scene *s, int spp)
{
    static estimate mis, lights, bsdf;
    render_strategy(s, PATH_MIS, spp, &mis);
    render_strategy(s, PATH_LIGHTS_ONLY, spp, &lights);
    /* material sampling alone finds small lights rarely: its pixel means are
     * the most skewed, so it gets more samples to be near normal */
    render_strategy(s, PATH_BSDF_ONLY, 4 * spp, &bsdf);
    compare(name, "MIS vs light sampling", &mis, &lights);
    compare(name, "MIS vs BSDF sampling", &mis, &bsdf);
    double vm = 0.0, vl = 0.0, vb = 0.0;
    for (int by = 0; by < NB; by++)
        for (int bx = 0; bx < NB; bx++)
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

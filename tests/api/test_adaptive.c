/*
 * test_adaptive.c - adaptive sampling (pk_renderer_render_adaptive) through
 * the public header, on the built-in Cornell box:
 *  - its noise estimate is unbiased: at a fixed sample count (min = max, so
 *    no tile stops on a lucky estimate) it equals the relative variance that
 *    two renders with different seeds show, within four standard errors of
 *    that measurement (the halves of one scrambled sequence overstate it
 *    1.5 times here, which this tells apart);
 *  - with a target, the two-seed noise of the result lands within 30 % of it;
 *  - it converges to the same image: its mean equals a fixed-count render's
 *    within four standard errors (measured from the seeds' differences);
 *  - every pixel gets min_spp .. max_spp samples, the same in a tile, and the
 *    result's figures add up; the same film at 1 and 2 threads;
 *  - the errors: a target that is not positive, min > max, a film of another
 *    size or with samples already.
 */
#include "test.h"

#include "paprsek.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define W 64
#define H 64

static pk_context *ctx;
static pk_scene *box;

/* Renders the box adaptively with a (seed, threads) into a new film. */
static pk_film *render(const pk_adaptive *a, int seed, int threads, pk_adaptive_result *res, pk_status *st)
{
    pk_render_options o;
    pk_scene_get_render_options(box, &o);
    o.width = W, o.height = H, o.spp = 1, o.seed = seed, o.threads = threads;
    pk_renderer *r;
    REQUIRE(pk_renderer_create(ctx, box, &o, &r) == PK_OK);
    pk_film *f;
    REQUIRE(pk_film_create(ctx, W, H, &f) == PK_OK);
    *st = pk_renderer_render_adaptive(r, a, f, res);
    pk_renderer_destroy(r);
    return f;
}

static double mean_of(const pk_film *cf, int p, int c)
{
    pk_film *f = (pk_film *)(uintptr_t)cf;
    return (double)pk_film_sums(f)[3 * p + c] / (double)pk_film_counts(f)[p];
}

/* The two-seed relative variance of films a and b, mean((a - b)^2 / 2 /
 * (m^2 + 0.01)) over pixels and channels, and its standard error. */
static void two_seed(const pk_film *a, const pk_film *b, double *rv, double *se)
{
    double s = 0.0, s2 = 0.0;
    const int n = 3 * W * H;
    for (int p = 0; p < W * H; p++)
        for (int c = 0; c < 3; c++) {
            const double x = mean_of(a, p, c), y = mean_of(b, p, c), m = 0.5 * (x + y);
            const double t = (x - y) * (x - y) / 2.0 / (m * m + 0.01);
            s += t, s2 += t * t;
        }
    *rv = s / n;
    *se = sqrt(fmax(s2 / n - *rv * *rv, 0.0) / n);
}

static void test_estimate(void)
{
    /* fixed: 32 samples a pixel, nothing stops early */
    pk_adaptive a;
    pk_adaptive_init(&a);
    a.noise = 1e-6f, a.min_spp = 32, a.max_spp = 32;
    pk_adaptive_result r1, r2;
    pk_status s1, s2;
    pk_film *f1 = render(&a, 1, 0, &r1, &s1), *f2 = render(&a, 2, 0, &r2, &s2);
    REQUIRE(s1 == PK_OK && s2 == PK_OK);
    CHECK(r1.min_spp == 32 && r1.max_spp == 32 && r1.tiles_reached == 0 && r1.passes == 32);
    double rv, se;
    two_seed(f1, f2, &rv, &se);
    const double est = 0.5 * ((double)r1.noise * (double)r1.noise + (double)r2.noise * (double)r2.noise);
    /* each estimate is a mean of the same kind over the same pixels: its
     * standard error is taken as the measurement's */
    CHECKF(fabs(est - rv) <= 4.0 * sqrt(2.0) * se, "estimated relative variance %g, two-seed %g (se %g)", est, rv, se);
    printf("fixed 32 spp: estimated noise %.4f, two-seed %.4f (se of the variance %.2g)\n", sqrt(est), sqrt(rv), se);

    /* a target: the result's two-seed noise within 30 % of it, and the same mean as a fixed render */
    for (int k = 0; k < 2; k++) {
        pk_adaptive t;
        pk_adaptive_init(&t);
        t.noise = k ? 0.05f : 0.1f;
        t.min_spp = 8;
        pk_adaptive_result q1, q2;
        pk_film *g1 = render(&t, 3, 0, &q1, &s1), *g2 = render(&t, 4, 0, &q2, &s2);
        REQUIRE(s1 == PK_OK && s2 == PK_OK);
        two_seed(g1, g2, &rv, &se);
        CHECKF(fabs(sqrt(rv) / (double)t.noise - 1.0) <= 0.3, "target %g: two-seed noise %g", (double)t.noise, sqrt(rv));
        CHECK(q1.tiles_reached == q1.tiles); /* (max_spp 1024 is far away) */
        printf("target %.2f: two-seed noise %.4f, estimated %.4f, %.1f spp on average (%u..%u)\n", (double)t.noise,
               sqrt(rv), (double)q1.noise, (double)q1.samples / (W * H), q1.min_spp, q1.max_spp);
        /* the image mean against the fixed renders', each side's variance from its seeds' differences */
        double ma = 0.0, mf = 0.0, va = 0.0, vf = 0.0;
        for (int p = 0; p < W * H; p++)
            for (int c = 0; c < 3; c++) {
                const double x1 = mean_of(g1, p, c), x2 = mean_of(g2, p, c);
                const double y1 = mean_of(f1, p, c), y2 = mean_of(f2, p, c);
                ma += x1 + x2, mf += y1 + y2;
                va += (x1 - x2) * (x1 - x2) / 2.0, vf += (y1 - y2) * (y1 - y2) / 2.0;
            }
        const double n = 3.0 * W * H;
        ma /= 2.0 * n, mf /= 2.0 * n;
        /* the variance of a two-render mean of n pixel-channels (their errors independent) */
        const double se_m = sqrt(va / n / n / 2.0 + vf / n / n / 2.0);
        CHECKF(fabs(ma - mf) <= 4.0 * se_m, "image mean %g adaptive, %g fixed (se %g)", ma, mf, se_m);
        pk_film_destroy(g1), pk_film_destroy(g2);
    }
    pk_film_destroy(f1), pk_film_destroy(f2);
}

static void test_counts_and_threads(void)
{
    pk_adaptive a;
    pk_adaptive_init(&a);
    a.noise = 0.08f, a.min_spp = 6, a.max_spp = 40;
    pk_adaptive_result r1, r2;
    pk_status s1, s2;
    pk_film *f1 = render(&a, 7, 1, &r1, &s1), *f2 = render(&a, 7, 2, &r2, &s2);
    REQUIRE(s1 == PK_OK && s2 == PK_OK);
    CHECK(memcmp(pk_film_sums(f1), pk_film_sums(f2), sizeof(float) * 3 * W * H) == 0);
    CHECK(memcmp(pk_film_counts(f1), pk_film_counts(f2), sizeof(uint32_t) * W * H) == 0);
    CHECK(memcmp(&r1, &r2, sizeof r1) == 0);
    const uint32_t *c = pk_film_counts(f1);
    uint64_t total = 0;
    uint32_t lo = UINT32_MAX, hi = 0;
    int bad = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint32_t n = c[y * W + x];
            total += n, lo = n < lo ? n : lo, hi = n > hi ? n : hi;
            bad += n < 6 || n > 40 || n != c[(y / 16 * 16) * W + x / 16 * 16]; /* one count a tile */
        }
    CHECK(bad == 0);
    CHECK(total == r1.samples && lo == r1.min_spp && hi == r1.max_spp && r1.tiles == 16);
    CHECKF(lo < hi, "min %u, max %u: the tiles should differ", lo, hi);
    pk_film_destroy(f1), pk_film_destroy(f2);
}

static void test_errors(void)
{
    pk_render_options o;
    pk_scene_get_render_options(box, &o);
    o.width = W, o.height = H, o.spp = 1;
    pk_renderer *r;
    REQUIRE(pk_renderer_create(ctx, box, &o, &r) == PK_OK);
    pk_film *f, *g;
    REQUIRE(pk_film_create(ctx, W, H, &f) == PK_OK && pk_film_create(ctx, W + 1, H, &g) == PK_OK);
    pk_adaptive a;
    pk_adaptive_init(&a);
    CHECK(a.noise > 0.0f && a.min_spp == 16 && a.max_spp == 1024 && a.seconds == 0.0);
    a.noise = 0.0f;
    CHECK(pk_renderer_render_adaptive(r, &a, f, NULL) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(pk_context_error(ctx), "noise target"), "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    pk_adaptive_init(&a);
    a.min_spp = 64, a.max_spp = 32;
    CHECK(pk_renderer_render_adaptive(r, &a, f, NULL) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    pk_adaptive_init(&a);
    CHECK(pk_renderer_render_adaptive(r, &a, g, NULL) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    CHECK(pk_renderer_render_adaptive(r, &a, f, NULL) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(pk_context_error(ctx), "empty film"), "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(pk_renderer_render_adaptive(NULL, &a, f, NULL) == PK_ERR_INVALID_ARGUMENT);
    pk_film_destroy(f), pk_film_destroy(g);
    pk_renderer_destroy(r);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    REQUIRE(pk_scene_create_cornell_box(ctx, &box) == PK_OK);
    test_errors();
    test_counts_and_threads();
    test_estimate();
    pk_scene_destroy(box);
    pk_context_destroy(ctx);
    return test_done("test_adaptive");
}

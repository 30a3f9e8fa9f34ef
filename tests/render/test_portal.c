/*
 * test_portal.c - the environment seen through a portal (render/env.h;
 * pbrt-v4's infinite light with "point3 portal").
 *
 * Sampling: from a point in front of the portal, directions drawn by
 * env_sample_from fall into cells of the portal's (u, v) window as often as
 * the integral of env_pdf_from times d(omega)/d(u, v) over each cell says
 * (chi-square); env_pdf_from integrates to 1 over the sphere (estimated with
 * uniform directions, which know nothing of the portal's parameterisation);
 * radiance / pdf estimates the integral of env_eval_from, which a uniform
 * estimator measures independently; the light is zero outside the window.
 *
 * Renders: a closed room lit through a window that is the portal
 * (tests/data/pbrt/portal_room.pbrt). Every path that leaves the room goes
 * through the window, so with and without the portal the image has the
 * same expectation: the mean over the image of two seeds each must agree
 * within Z_MEAN standard errors, the variance measured from the seeds'
 * differences; light sampling alone through the portal must agree too; and
 * the portal must lower the noise (the ratio is printed).
 */
#include "test.h"

#include "chi2.h"
#include "paprsek.h"
#include "render/env.h"
#include "render/path.h"
#include "render/render.h"
#include "render/sampling.h"

#include <stdint.h>
#include <string.h>
#include <unistd.h>

#define Z_MEAN 3.89 /* two-sided p = 1e-4 per check */
#define P_MIN 1e-4

static pk_context *ctx;

/* ---- sampling ------------------------------------------------------------------ */

#define MW 64
#define MH 32

/* A sky gradient, a dark lower half, and a bright patch. */
static void make_map(float *rgb)
{
    for (int j = 0; j < MH; j++)
        for (int i = 0; i < MW; i++) {
            float v = ((float)j + 0.5f) / MH, u = ((float)i + 0.5f) / MW;
            float *p = &rgb[3 * (j * MW + i)];
            if (v < 0.5f)
                p[0] = 0.2f + v, p[1] = 0.4f + v, p[2] = 1.0f;
            else
                p[0] = p[1] = p[2] = 0.1f;
            if (fabsf(u - 0.45f) < 0.05f && fabsf(v - 0.2f) < 0.06f) p[0] = 40.0f, p[1] = 30.0f, p[2] = 20.0f;
        }
}

/* A 1 x 0.6 portal in the plane y = 1, facing +y (away from the origin). */
static env_light build_portal_env(const float *rgb)
{
    scene_environment d;
    scene_env_init(&d);
    d.set = true;
    d.has_portal = true;
    d.portal[0] = v3(-0.5f, 1.0f, -0.3f);
    d.portal[1] = v3(0.5f, 1.0f, -0.3f);
    d.portal[2] = v3(0.5f, 1.0f, 0.3f);
    d.portal[3] = v3(-0.5f, 1.0f, 0.3f);
    aabb b = {{-1, -1, -1}, {1, 1, 1}};
    env_light e;
    REQUIRE(env_build(ctx, &d, rgb, MW, MH, b, &e) == PK_OK);
    REQUIRE(e.portal);
    return e;
}

#define NC 12 /* cells a side of the window */
#define N_DRAWS 400000

static void test_sampling(vec3 o)
{
    static float rgb[3 * MW * MH];
    make_map(rgb);
    env_light e = build_portal_env(rgb);
    float b[4];
    REQUIRE(portal_window(&e, o, b));
    /* the expected share of each cell: the pdf over (u, v) by the midpoint rule */
    static double prob[NC * NC];
    static int count[NC * NC];
    const int q = 24;
    double total = 0.0;
    for (int c = 0; c < NC * NC; c++) {
        const int ci = c % NC, cj = c / NC;
        double s = 0.0;
        for (int a = 0; a < q; a++)
            for (int bb = 0; bb < q; bb++) {
                const float u = b[0] + (b[2] - b[0]) * ((float)ci + ((float)bb + 0.5f) / (float)q) / NC;
                const float v = b[1] + (b[3] - b[1]) * ((float)cj + ((float)a + 0.5f) / (float)q) / NC;
                float jac;
                const vec3 d = portal_dir(&e, u, v, &jac);
                s += (double)env_pdf_from(&e, o, d) * (double)jac;
            }
        prob[c] = s * (double)(b[2] - b[0]) * (double)(b[3] - b[1]) / ((double)NC * NC * q * q);
        total += prob[c];
        count[c] = 0;
    }
    printf("portal from (%g %g %g): integral of the pdf over the window (quadrature) = %.5f\n", (double)o.x,
           (double)o.y, (double)o.z, total);
    /* exactly 1 in theory; the midpoint rule misplaces mass where the pdf jumps */
    CHECKF(fabs(total - 1.0) < 3e-3, "integral of the pdf over the window %g", total);
    rng r = rng_seed(7, (uint64_t)(o.x * 1000.0f));
    double sum = 0.0, sum2 = 0.0;
    int mismatched = 0, outside = 0, n = 0;
    for (int k = 0; k < N_DRAWS; k++) {
        vec3 d, le;
        float pdf, u, v;
        if (!env_sample_from(&e, o, rng_float(&r), rng_float(&r), &d, &le, &pdf)) {
            mismatched++;
            continue;
        }
        n++;
        if (fabsf(pdf - env_pdf_from(&e, o, d)) > 1e-5f * pdf || !(fabsf(v3_len(d) - 1.0f) < 1e-5f)) mismatched++;
        if (!portal_uv(&e, d, &u, &v, NULL) || u < b[0] || u > b[2] || v < b[1] || v > b[3]) {
            outside++;
            continue;
        }
        int ci = (int)((u - b[0]) / (b[2] - b[0]) * NC), cj = (int)((v - b[1]) / (b[3] - b[1]) * NC);
        ci = ci < 0 ? 0 : ci >= NC ? NC - 1 : ci;
        cj = cj < 0 ? 0 : cj >= NC ? NC - 1 : cj;
        count[cj * NC + ci]++;
        const double x = (double)v3_luminance(le) / (double)pdf;
        sum += x, sum2 += x * x;
    }
    CHECKF(mismatched == 0, "%d draws failed or disagree with env_pdf_from", mismatched);
    CHECKF(outside == 0, "%d draws outside the window", outside);
    double chi2 = 0.0, pooled_e = 0.0, pooled_o = 0.0;
    int dof = -1;
    for (int c = 0; c < NC * NC; c++) {
        const double ex = prob[c] / total * n;
        if (ex < 5.0) {
            pooled_e += ex, pooled_o += count[c];
            continue;
        }
        chi2 += (count[c] - ex) * (count[c] - ex) / ex;
        dof++;
    }
    if (pooled_e >= 5.0) chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e, dof++;
    const double pv = chi2_pvalue(chi2, dof);
    printf("portal: directions chi2 %.1f, %d dof, p = %.3g\n", chi2, dof, pv);
    CHECKF(pv > P_MIN, "portal directions: p = %g", pv);

    /* independent checks with uniform directions over the sphere: the pdf's
     * integral is 1, and the integral of the radiance through the portal */
    rng r2 = rng_seed(11, (uint64_t)(o.x * 1000.0f));
    const int nu = 2000000;
    double ps = 0.0, ps2 = 0.0, ls = 0.0, ls2 = 0.0;
    int leak = 0;
    for (int k = 0; k < nu; k++) {
        const float z = 1.0f - 2.0f * rng_float(&r2), rr = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        const float phi = 2.0f * PK_PI * rng_float(&r2);
        const vec3 d = v3(rr * cosf(phi), rr * sinf(phi), z);
        const double p = 4.0 * (double)PK_PI * (double)env_pdf_from(&e, o, d);
        const double l = 4.0 * (double)PK_PI * (double)v3_luminance(env_eval_from(&e, o, d));
        /* the light is zero outside the portal: no radiance where the pdf is 0 */
        if (p == 0.0 && l > 0.0) leak++;
        ps += p, ps2 += p * p, ls += l, ls2 += l * l;
    }
    CHECKF(leak == 0, "%d directions with radiance outside the portal", leak);
    const double pm = ps / nu, pse = sqrt((ps2 / nu - pm * pm) / nu);
    printf("portal: integral of the pdf over the sphere (uniform estimate) %.5f +- %.5f\n", pm, pse);
    CHECKF(fabs(pm - 1.0) < Z_MEAN * pse, "integral of the pdf %g +- %g", pm, pse);
    const double lm = ls / nu, lse = sqrt((ls2 / nu - lm * lm) / nu);
    const double em = sum / n, ese = sqrt((sum2 / n - em * em) / n);
    const double z = fabs(lm - em) / sqrt(lse * lse + ese * ese);
    printf("portal: integral of L: portal estimate %.5f +- %.5f, uniform %.5f +- %.5f (z = %.2f); noise ratio %.1f\n",
           em, ese, lm, lse, z, lse * sqrt((double)nu) / (ese * sqrt((double)n)));
    CHECKF(z < Z_MEAN, "integral of L through the portal: %g vs %g, z = %g", em, lm, z);
    /* behind the portal's plane nothing is seen */
    float bb[4];
    CHECK(!portal_window(&e, v3(0.0f, 2.0f, 0.0f), bb));
    CHECK(v3_max_comp(env_eval_from(&e, v3(0.0f, 2.0f, 0.0f), v3(0.0f, 1.0f, 0.0f))) == 0.0f);
    env_free(&ctx->alloc, &e);
}

/* ---- renders --------------------------------------------------------------------- */

#define RW 48
#define RH 36

/* The luminance of each pixel of s rendered at spp with seed. */
static void render_lum(const pk_scene *s, int strategy, int spp, int seed, double *lum)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = RW, o.height = RH;
    o.spp = spp;
    o.threads = 2;
    o.seed = seed;
    pk_renderer *r = NULL;
    pk_film *f = NULL;
    pk_image *img = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    renderer_set_path_strategy(r, strategy);
    REQUIRE(pk_film_create(ctx, RW, RH, &f) == PK_OK);
    REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK);
    const float *px = pk_image_pixels_const(img);
    for (int i = 0; i < RW * RH; i++) lum[i] = (double)v3_luminance(v3(px[3 * i], px[3 * i + 1], px[3 * i + 2]));
    pk_image_destroy(img);
    pk_film_destroy(f);
    pk_renderer_destroy(r);
}

/* The image's mean over two seeds, its standard error (from the seeds'
 * per-pixel differences) and the per-pixel noise of one seed (rms). */
static void two_seeds(const pk_scene *s, int strategy, int spp, double *mean, double *se, double *rms)
{
    static double a[RW * RH], b[RW * RH];
    render_lum(s, strategy, spp, 1, a);
    render_lum(s, strategy, spp, 2, b);
    const int n = RW * RH;
    double sum = 0.0, var = 0.0;
    for (int i = 0; i < n; i++) {
        sum += 0.5 * (a[i] + b[i]);
        var += 0.5 * (a[i] - b[i]) * (a[i] - b[i]); /* one seed's variance of pixel i */
    }
    *mean = sum / n;
    *se = sqrt(var / 2.0) / n; /* the mean of n pixels, two seeds each */
    *rms = sqrt(var / n);
}

static pk_scene *load(const char *path)
{
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
    return s;
}

static void test_room(const char *dir)
{
    /* the scene, and a copy without its portal */
    char path[600], text[16384];
    snprintf(path, sizeof path, "%s/pbrt/portal_room.pbrt", PK_TEST_DATA);
    FILE *f = fopen(path, "r");
    REQUIRE(f);
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = '\0';
    char *pl = strstr(text, "\"point3 portal\"");
    REQUIRE(pl);
    char *eol = strchr(pl, '\n');
    REQUIRE(eol);
    memmove(pl, eol, strlen(eol) + 1);
    char *fn = strstr(text, "\"portal_sky.pfm\"");
    REQUIRE(fn);
    char out[600];
    snprintf(out, sizeof out, "%s/no_portal.pbrt", dir);
    f = fopen(out, "w");
    REQUIRE(f);
    fwrite(text, 1, (size_t)(fn - text), f);
    fprintf(f, "\"%s/pbrt/portal_sky.pfm\"", PK_TEST_DATA);
    fputs(fn + strlen("\"portal_sky.pfm\""), f);
    fclose(f);

    pk_scene *with = load(path), *without = load(out);
    const int spp = 16;
    double mp, sp, rp, mn, sn, rn, ml, sl, rl;
    two_seeds(with, PATH_MIS, spp, &mp, &sp, &rp);
    two_seeds(without, PATH_MIS, spp, &mn, &sn, &rn);
    two_seeds(with, PATH_LIGHTS_ONLY, spp, &ml, &sl, &rl);
    const double z = fabs(mp - mn) / sqrt(sp * sp + sn * sn), zl = fabs(ml - mn) / sqrt(sl * sl + sn * sn);
    printf("room, %d spp: portal %.5f +- %.5f, whole environment %.5f +- %.5f (z = %.2f); portal, light sampling "
           "only %.5f +- %.5f (z = %.2f)\n",
           spp, mp, sp, mn, sn, z, ml, sl, zl);
    printf("room, %d spp: per-pixel noise (rms of one seed) portal %.5f, whole environment %.5f: ratio %.2f\n", spp,
           rp, rn, rn / rp);
    CHECKF(z < Z_MEAN, "room with and without the portal: %g vs %g, z = %g", mp, mn, z);
    CHECKF(zl < Z_MEAN, "room, light sampling through the portal: %g vs %g, z = %g", ml, mn, zl);
    CHECKF(rp < rn, "the portal does not lower the noise: %g vs %g", rp, rn);
    pk_scene_destroy(with);
    pk_scene_destroy(without);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    char dir[] = "/tmp/pk_test_portal_XXXXXX";
    REQUIRE(mkdtemp(dir));
    test_sampling(v3(0.0f, 0.0f, 0.0f));
    test_sampling(v3(0.7f, 0.2f, -0.4f));
    test_room(dir);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
    pk_context_destroy(ctx);
    return test_done("test_portal");
}

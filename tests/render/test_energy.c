/*
 * test_energy.c - energy compensation of the rough microfacet lobes
 * (pbsdf_compensate, render/energy.h):
 *  - the tables are what their generator (render/energy_gen.h) computes:
 *    entries recomputed and compared, E_avg recomputed from the rows;
 *  - white furnace: a white conductor (F = 1) with compensation reflects 1
 *    within 1 % at alpha 0.25, 0.5, 0.75 and 1 and several angles, by
 *    quadrature of eval over the half vectors and by Monte Carlo over the
 *    sampler's weights (tolerance 4 standard errors of the measured
 *    variance on top of the 1 %);
 *  - a rough dielectric of index 1.5 with compensation: R + T = 1 within
 *    1 % from either side (Monte Carlo over the sample weights);
 *  - coloured conductors: the compensated cosine-weighted albedo A exceeds
 *    the single-scattering one by F_ms (1 - E_avg), and differs from Kulla
 *    and Conty's closed form F_avg E_avg / (1 - F_avg (1 - E_avg)) by
 *    exactly what the single-scattering albedo differs from F_avg E_avg;
 *  - F_avg by the 4-point rule against a fine quadrature, for metals and
 *    glass: within 1e-3 (F_ms moves by about twice that times 1 - E_avg,
 *    a tenth of the 1 % budget).
 *  - the path tracer: a rough white metal ball and a rough glass ball
 *    (transmittance 1) in a white furnace (a constant environment of 1)
 *    render 1 everywhere within 1 % with compensation on (and visibly less
 *    with it off), through the renderer's light sampling and MIS.
 * The chi-square, pdf and reciprocity tests of the compensated lobes are
 * test_bsdf's (its "comp" cases). Prints the furnace numbers before and
 * after (docs/materials.md quotes them).
 */
#include "test.h"

#include "paprsek.h"
#include "render/energy_gen.h"
#include "render/sampling.h"

#include <stdint.h>
#include <string.h>

static vec3 dir_deg(double theta)
{
    const double t = theta * M_PI / 180.0;
    return v3((float)sin(t), 0.0f, (float)cos(t));
}

/* The integral of eval(wo, wi) over wi (wo.z > 0, reflection only) by
 * Simpson's rule over the half vector h: wi = 2 (wo.h) h - wo, dwi = 4 (wo.h)
 * dh; h in theta_h [0, pi/2] x phi [0, 2 pi). */
static void quad_albedo(const pbsdf *b, vec3 wo, int nt, int np, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    const double ht = (M_PI / 2.0) / nt, hp = (2.0 * M_PI) / np;
    for (int i = 0; i <= nt; i++) {
        const double t = i * ht, wt = (i == 0 || i == nt) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        const double st = sin(t), ct = cos(t);
        if (st <= 0.0) continue;
        for (int j = 0; j < np; j++) { /* periodic in phi: the trapezoid rule */
            const double p = (j + 0.5) * hp;
            const vec3 h = v3((float)(st * cos(p)), (float)(st * sin(p)), (float)ct);
            const float oh = v3_dot(wo, h);
            if (!(oh > 0.0f)) continue;
            const vec3 wi = v3_norm(v3_sub(v3_scale(h, 2.0f * oh), wo));
            if (!(wi.z > 0.0f)) continue;
            const vec3 f = pbsdf_eval(b, wo, wi);
            const double w = wt * ht / 3.0 * hp * st * 4.0 * (double)oh;
            out[0] += w * (double)f.x, out[1] += w * (double)f.y, out[2] += w * (double)f.z;
        }
    }
}

typedef struct mc {
    double mean[3], se[3];
} mc;

/* The mean of the sample weights (failed samples count 0), N samples. */
static mc mc_albedo(const pbsdf *b, vec3 wo, long n, uint64_t seed)
{
    rng g = rng_seed(seed, 0xe1e);
    double s[3] = {0}, s2[3] = {0};
    for (long i = 0; i < n; i++) {
        const float u[3] = {rng_float(&g), rng_float(&g), rng_float(&g)};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta)) continue;
        const double v[3] = {w.x, w.y, w.z};
        for (int c = 0; c < 3; c++) s[c] += v[c], s2[c] += v[c] * v[c];
    }
    mc r;
    for (int c = 0; c < 3; c++) {
        r.mean[c] = s[c] / (double)n;
        r.se[c] = sqrt(fmax(0.0, s2[c] / (double)n - r.mean[c] * r.mean[c]) / (double)(n - 1));
    }
    return r;
}

/* ---- the tables are the generator's ---------------------------------------------- */

static void test_tables(void)
{
    int checked = 0;
    double worst = 0.0;
    for (int d = 0; d < 2; d++)
        for (int a = 0; a < PK_EN_ALPHA; a += 3)
            for (int m = 0; m < PK_EN_MU; m += 5) {
                const double e = energy_gen_conductor(d == 1, energy_gen_node(a, PK_EN_ALPHA),
                                                      energy_gen_mu(m, PK_EN_MU), ENERGY_GEN_N_CONDUCTOR);
                const double diff = fabs(e - (double)pk_energy_e[d][a][m]);
                worst = fmax(worst, diff);
                CHECKF(diff <= 2e-6, "E[%d][%d][%d] = %.7f, the generator gives %.7f", d, a, m,
                       (double)pk_energy_e[d][a][m], e);
                checked++;
            }
    for (int d = 0; d < 2; d++)
        for (int a = 0; a < PK_EN_ALPHA; a++) {
            double row[PK_EN_MU];
            for (int m = 0; m < PK_EN_MU; m++) row[m] = (double)pk_energy_e[d][a][m];
            const double avg = energy_gen_avg(row, PK_EN_MU);
            CHECKF(fabs(avg - (double)pk_energy_eavg[d][a]) <= 2e-6, "E_avg[%d][%d] = %.7f, from the row %.7f", d, a,
                   (double)pk_energy_eavg[d][a], avg);
            /* the average is the integral of the interpolated E, by Simpson over a fine grid */
            double s = 0.0;
            const int n = 3100;
            for (int i = 0; i <= n; i++) {
                const double mu = (double)i / n, w = (i == 0 || i == n) ? 1.0 : (i & 1) ? 4.0 : 2.0;
                s += w * (double)energy_e(d == 1, energy_gen_node(a, PK_EN_ALPHA), (float)mu) * mu;
            }
            CHECKF(fabs(2.0 * s / (3.0 * n) - (double)pk_energy_eavg[d][a]) <= 1e-5, "E_avg[%d][%d]: %.7f vs %.7f", d,
                   a, 2.0 * s / (3.0 * n), (double)pk_energy_eavg[d][a]);
            checked++;
        }
    for (int d = 0; d < 2; d++)
        for (int s = 0; s < 2; s++)
            for (int k = 1; k < PK_EN_DETA; k += 4)
                for (int a = 2; a < PK_EN_DALPHA; a += 4)
                    for (int m = 0; m < PK_EN_DMU; m += 6) {
                        const double e = energy_gen_dielectric(d == 1, s == 1, energy_gen_eta(k),
                                                               energy_gen_node(a, PK_EN_DALPHA), energy_gen_mu(m, PK_EN_DMU),
                                                               ENERGY_GEN_N_DIELECTRIC);
                        const double diff = fabs(e - (double)pk_energy_d[d][s][k][a][m]);
                        worst = fmax(worst, diff);
                        CHECKF(diff <= 2e-6, "E_d[%d][%d][%d][%d][%d] = %.7f, the generator gives %.7f", d, s, k, a, m,
                               (double)pk_energy_d[d][s][k][a][m], e);
                        checked++;
                    }
    printf("tables: %d entries recomputed, worst difference %.2g\n", checked, worst);
}

/* ---- white furnace ------------------------------------------------------------- */

static const float alphas[] = {0.25f, 0.5f, 0.75f, 1.0f};
static const double thetas[] = {0.0, 35.0, 60.0, 75.0}; /* mu 1, 0.82, 0.5, 0.26 */

static void test_white_conductor(void)
{
    printf("white conductor (F = 1), albedo before -> after (quadrature; Monte Carlo after):\n");
    for (int bk = 0; bk < 2; bk++)
        for (int a = 0; a < 4; a++)
            for (int t = 0; t < 4; t++) {
                pbsdf b = pbsdf_conductor_schlick(v3s(1.0f), alphas[a]);
                if (bk) b.flags |= PBSDF_BECKMANN;
                const vec3 wo = dir_deg(thetas[t]);
                double before[3], after[3];
                quad_albedo(&b, wo, 800, 256, before);
                pbsdf_compensate(&b);
                REQUIRE(b.flags & PBSDF_ENERGY);
                quad_albedo(&b, wo, 800, 256, after);
                const mc m = mc_albedo(&b, wo, 200000, 17u + (uint64_t)(bk * 100 + a * 10 + t));
                printf("  %-8s alpha %.2f mu %.3f: %.4f -> %.4f  (MC %.4f +- %.4f)\n", bk ? "Beckmann" : "GGX",
                       (double)alphas[a], (double)wo.z, before[0], after[0], m.mean[0], m.se[0]);
                CHECKF(fabs(after[0] - 1.0) <= 0.01, "%s alpha %g theta %g: compensated albedo %.5f", bk ? "bk" : "ggx",
                       (double)alphas[a], thetas[t], after[0]);
                CHECKF(fabs(m.mean[0] - 1.0) <= 0.01 + 4.0 * m.se[0], "%s alpha %g theta %g: MC albedo %.5f +- %.2g",
                       bk ? "bk" : "ggx", (double)alphas[a], thetas[t], m.mean[0], m.se[0]);
                /* quadrature and sampling agree (eval, pdf and sample consistent) */
                CHECKF(fabs(m.mean[0] - after[0]) <= 4.0 * m.se[0] + 1e-3, "%s alpha %g theta %g: MC %.5f, quad %.5f",
                       bk ? "bk" : "ggx", (double)alphas[a], thetas[t], m.mean[0], after[0]);
            }
}

/* ---- rough dielectric: R + T = 1 ---------------------------------------------------------- */

static void test_dielectric(void)
{
    printf("dielectric 1.5 (transmittance 1), R + T before -> after (Monte Carlo):\n");
    const double th[] = {0.0, 35.0, 60.0, 180.0, 145.0, 120.0}; /* > 90: from inside (120: beyond the critical angle) */
    for (int bk = 0; bk < 2; bk++)
        for (int a = 0; a < 4; a++)
            for (int t = 0; t < 6; t++) {
                pbsdf b = pbsdf_dielectric(1.5f, alphas[a], v3s(1.0f));
                if (bk) b.flags |= PBSDF_BECKMANN;
                const vec3 wo = dir_deg(th[t]);
                const uint64_t seed = 91u + (uint64_t)(bk * 100 + a * 10 + t);
                const mc m0 = mc_albedo(&b, wo, 200000, seed);
                pbsdf_compensate(&b);
                REQUIRE(b.flags & PBSDF_ENERGY);
                const mc m = mc_albedo(&b, wo, 200000, seed);
                printf("  %-8s alpha %.2f cos_o %+.3f: %.4f -> %.4f +- %.4f\n", bk ? "Beckmann" : "GGX",
                       (double)alphas[a], (double)wo.z, m0.mean[0], m.mean[0], m.se[0]);
                CHECKF(fabs(m.mean[0] - 1.0) <= 0.01 + 4.0 * m.se[0], "%s alpha %g theta %g: R + T = %.5f +- %.2g",
                       bk ? "bk" : "ggx", (double)alphas[a], th[t], m.mean[0], m.se[0]);
            }
}

/* ---- coloured conductors: Kulla and Conty's prediction ------------------------------------ */

/* 2 * integral of F(mu) mu dmu by Simpson over 2000 intervals. */
static double favg_fine(float eta, float k)
{
    double s = 0.0;
    const int n = 2000;
    for (int i = 0; i <= n; i++) {
        const double mu = (double)i / n, w = (i == 0 || i == n) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        const double f = k < 0.0f ? (double)pbsdf_fresnel_dielectric((float)mu, eta)
                                  : (double)pbsdf__fresnel_conductor1((float)mu, eta, k);
        s += w * f * mu;
    }
    return 2.0 * s / (3.0 * n);
}

/* The cosine-weighted albedo 2 * integral of albedo(mu_o) mu_o dmu_o, by
 * 16-point Gauss-Legendre in mu_o (on [0, 1] in two halves). */
static void avg_albedo(const pbsdf *b, double out[3])
{
    static const double x[8] = {0.0950125098, 0.2816035508, 0.4580167777, 0.6178762444,
                                0.7554044084, 0.8656312024, 0.9445750231, 0.9894009350};
    static const double w[8] = {0.1894506105, 0.1826034150, 0.1691565194, 0.1495959888,
                                0.1246289713, 0.0951585117, 0.0622535239, 0.0271524594};
    out[0] = out[1] = out[2] = 0.0;
    for (int i = 0; i < 8; i++)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            const double mu = 0.5 + 0.5 * sgn * x[i];
            const vec3 wo = v3((float)sqrt(1.0 - mu * mu), 0.0f, (float)mu);
            double a[3];
            quad_albedo(b, wo, 400, 128, a);
            for (int c = 0; c < 3; c++) out[c] += 0.5 * w[i] * 2.0 * a[c] * mu;
        }
}

static void test_coloured(void)
{
    /* F_avg: the 4-point rule against a fine quadrature (metals: gold, copper,
     * silver, aluminium, a made-up dark and a bright one; glass k < 0) */
    const float etas[3] = {0.143f, 0.374f, 1.442f}, ks[3] = {3.983f, 2.385f, 1.603f};
    static const float metals[][2] = {{0.143f, 3.983f}, {0.374f, 2.385f}, {1.442f, 1.603f}, {0.2f, 3.91f},
                                      {0.92f, 2.45f},   {1.1f, 2.39f},   {0.155f, 4.83f},   {1.66f, 8.06f},
                                      {2.9f, 3.0f},     {0.05f, 0.5f},   {4.0f, 0.1f},      {1.33f, -1.0f},
                                      {1.5f, -1.0f},    {2.4f, -1.0f}};
    double worst = 0.0;
    for (size_t i = 0; i < sizeof metals / sizeof metals[0]; i++) {
        const double a = (double)pbsdf__favg(metals[i][0], metals[i][1]), f = favg_fine(metals[i][0], metals[i][1]);
        worst = fmax(worst, fabs(a - f));
        CHECKF(fabs(a - f) <= 1e-3, "F_avg(%g, %g): %.6f vs %.6f", (double)metals[i][0], (double)metals[i][1], a, f);
    }
    printf("F_avg by 4 points: worst difference %.2g from a fine quadrature\n", worst);

    printf("coloured conductors: cosine-weighted albedo A, single scattering -> compensated; Kulla-Conty's\n"
           "F_avg E_avg / (1 - F_avg (1 - E_avg)):\n");
    const float as[] = {0.5f, 1.0f};
    for (int kind = 0; kind < 2; kind++)
        for (int ai = 0; ai < 2; ai++) {
            const float alpha = as[ai];
            pbsdf b = kind ? pbsdf_conductor_schlick(v3(0.9f, 0.6f, 0.3f), alpha)
                           : pbsdf_conductor(v3(etas[0], etas[1], etas[2]), v3(ks[0], ks[1], ks[2]), alpha);
            double favg[3];
            for (int c = 0; c < 3; c++) {
                const double f0 = c == 0 ? 0.9 : c == 1 ? 0.6 : 0.3;
                favg[c] = kind ? f0 + (1.0 - f0) / 21.0 : favg_fine(etas[c], ks[c]);
            }
            const double eavg = (double)energy_eavg(false, alpha);
            double ass[3], acomp[3];
            avg_albedo(&b, ass);
            pbsdf_compensate(&b);
            avg_albedo(&b, acomp);
            for (int c = 0; c < 3; c++) {
                const double fms = favg[c] * favg[c] * eavg / (1.0 - favg[c] * (1.0 - eavg));
                const double pred = favg[c] * eavg / (1.0 - favg[c] * (1.0 - eavg));
                printf("  %-12s alpha %.1f [%d]: F_avg %.4f  A %.4f -> %.4f  closed form %.4f\n",
                       kind ? "schlick" : "gold", (double)alpha, c, favg[c], ass[c], acomp[c], pred);
                /* the lobe adds F_ms (1 - E_avg) (F_avg by the 8-point rule: 2e-4) */
                CHECKF(fabs(acomp[c] - ass[c] - fms * (1.0 - eavg)) <= 2e-3,
                       "%s alpha %g [%d]: added %.5f, F_ms (1 - E_avg) = %.5f", kind ? "schlick" : "gold",
                       (double)alpha, c, acomp[c] - ass[c], fms * (1.0 - eavg));
                /* so A - closed form = A_ss - F_avg E_avg */
                CHECKF(fabs((acomp[c] - pred) - (ass[c] - favg[c] * eavg)) <= 2e-3,
                       "%s alpha %g [%d]: A - closed form %.5f, A_ss - F_avg E_avg %.5f", kind ? "schlick" : "gold",
                       (double)alpha, c, acomp[c] - pred, ass[c] - favg[c] * eavg);
                CHECKF(acomp[c] <= 1.0 + 2e-3, "%s alpha %g [%d]: A = %.5f > 1", kind ? "schlick" : "gold",
                       (double)alpha, c, acomp[c]);
            }
        }
}

/* ---- the path tracer in a white furnace -------------------------------------------- */

#define FSIZE 24

/* Mean and standard error of the image's mean (pixels independent). */
static void furnace_render(const char *ball, int energy, int integrator, double *mean, double *se)
{
    char text[1024];
    snprintf(text, sizeof text,
             "{\"materials\": {\"ball\": %s},"
             " \"camera\": {\"look_from\": [0, 0, 4], \"look_at\": [0, 0, 0], \"fov\": 26},"
             " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"ball\"}],"
             " \"environment\": [1, 1, 1]}",
             ball);
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "furnace.json", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    CHECK(o.energy_compensation == 0); /* JSON: off unless asked */
    o.width = o.height = FSIZE;
    o.spp = 64;
    o.threads = 2;
    o.energy_compensation = energy;
    o.integrator = integrator ? PK_INTEGRATOR_VOLPATH : PK_INTEGRATOR_PATH;
    pk_image *img = NULL;
    st = pk_render(ctx, s, &o, &img, NULL);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    const float *px = pk_image_pixels_const(img);
    double m = 0.0, m2 = 0.0;
    const int n = FSIZE * FSIZE * 3;
    for (int i = 0; i < n; i++) m += (double)px[i], m2 += (double)px[i] * (double)px[i];
    m /= n;
    *mean = m;
    *se = sqrt(fmax(0.0, m2 / n - m * m) / (n - 1));
    pk_image_destroy(img);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_render(void)
{
    static const char *const balls[] = {
        "{\"type\": \"conductor\", \"specular\": [1, 1, 1], \"roughness\": 1}",
        "{\"type\": \"conductor\", \"specular\": [1, 1, 1], \"roughness\": 0.7}",
        "{\"type\": \"dielectric\", \"ior\": 1.5, \"roughness\": 0.8}",
    };
    for (int b = 0; b < 3; b++)
        for (int integ = 0; integ < 2; integ++) {
            double m0, s0, m1, s1;
            furnace_render(balls[b], 0, integ, &m0, &s0);
            furnace_render(balls[b], 1, integ, &m1, &s1);
            printf("furnace render (%s) %s: image mean %.4f +- %.4f off, %.4f +- %.4f on\n",
                   integ ? "volpath" : "path", balls[b], m0, s0, m1, s1);
            CHECKF(fabs(m1 - 1.0) <= 0.01 + 4.0 * s1, "%s: compensated furnace %.5f +- %.2g", balls[b], m1, s1);
            CHECKF(m0 < 1.0 - 4.0 * s0, "%s: uncompensated furnace %.5f +- %.2g", balls[b], m0, s0);
        }
}

int main(void)
{
    test_render();
    test_coloured();
    test_white_conductor();
    test_dielectric();
    test_tables();
    return test_done("test_energy");
}

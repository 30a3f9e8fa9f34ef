/*
 * test_bsdf_sheets.c - closed forms of the thin dielectric, diffuse
 * transmission, Oren-Nayar and modified Phong BSDFs (render/pbsdf.h), written
 * out again here in double precision, and Monte Carlo estimates of their
 * lobes' shares against them with bounds from the binomial or sample variance.
 * (test_bsdf holds their chi-square, furnace and reciprocity tests with the
 * other types'.) Fixed seeds: the results are the same on every run.
 */
#include "test.h"

#include "render/pbsdf.h"
#include "render/sampling.h"

#include <stdint.h>

static double fresnel_d(double cos_i, double eta)
{
    double s2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if (s2 >= 1.0) return 1.0;
    double ct = sqrt(1.0 - s2);
    double rs = (cos_i - eta * ct) / (cos_i + eta * ct), rp = (eta * cos_i - ct) / (eta * cos_i + ct);
    return 0.5 * (rs * rs + rp * rp);
}

/* The sheet: R' = R + T^2 R / (1 - R^2), T' = 1 - R'. */
static double thin_r(double cos_i, double eta)
{
    double r = fresnel_d(cos_i, eta), t = 1.0 - r;
    return r < 1.0 ? r + t * t * r / (1.0 - r * r) : 1.0;
}

static vec3 dir_deg(double theta, double phi)
{
    double t = theta * M_PI / 180.0;
    return v3((float)(sin(t) * cos(phi)), (float)(sin(t) * sin(phi)), (float)cos(t));
}

static void test_thin_dielectric(void)
{
    static const double iors[] = {1.5, 1.33, 2.4};
    static const double angles[] = {0.0, 30.0, 60.0, 80.0, 89.0};
    rng g = rng_seed(7, 0x5eed);
    for (int i = 0; i < 3; i++) {
        const vec3 tint = v3(0.9f, 0.6f, 0.3f);
        pbsdf b = pbsdf_thin_dielectric((float)iors[i], tint);
        CHECK(!pbsdf_has_nondelta(&b));
        for (int a = 0; a < 5; a++) {
            for (int side = 0; side < 2; side++) {
                vec3 wo = dir_deg(angles[a], 0.3);
                if (side) wo.z = -wo.z;
                const double ref = thin_r(fabs((double)wo.z), iors[i]);
                const float r = pbsdf_thin_reflectance(wo.z, (float)iors[i]);
                /* float Fresnel against double: a few ulps of 1 */
                CHECKF(fabs((double)r - ref) <= 2e-6 + 1e-5 * ref, "ior %g theta %g: R' %.8f, closed form %.8f",
                       iors[i], angles[a], (double)r, ref);
                /* the two lobes: mirror with pdf R' and weight 1, straight
                 * through with pdf T' and weight the tint; R' + T' = 1 */
                vec3 wr, wt, w1, w2;
                float pr, pt;
                bool d1, d2;
                const float u0[3] = {0.0f, 0.5f, 0.5f}, u1[3] = {0.9999999f, 0.5f, 0.5f};
                REQUIRE(pbsdf_sample(&b, wo, u0, &wr, &w1, &pr, &d1));
                REQUIRE(pbsdf_sample(&b, wo, u1, &wt, &w2, &pt, &d2));
                CHECK(d1 && d2);
                CHECKF(fabs((double)pr + (double)pt - 1.0) <= 1e-6, "R' + T' = %.8f", (double)pr + (double)pt);
                CHECK(fabs((double)pr - ref) <= 2e-6 + 1e-5 * ref);
                CHECK(wr.x == -wo.x && wr.y == -wo.y && wr.z == wo.z);
                CHECK(wt.x == -wo.x && wt.y == -wo.y && wt.z == -wo.z);
                CHECK(w1.x == 1.0f && w1.y == 1.0f && w1.z == 1.0f);
                CHECK(w2.x == tint.x && w2.y == tint.y && w2.z == tint.z);
                /* the Monte Carlo share of reflections: binomial, 4.5 sigma */
                const long n = 100000;
                long nr = 0;
                for (long k = 0; k < n; k++) {
                    const float u[3] = {rng_float(&g), rng_float(&g), rng_float(&g)};
                    vec3 wi, w;
                    float pdf;
                    bool dl;
                    REQUIRE(pbsdf_sample(&b, wo, u, &wi, &w, &pdf, &dl));
                    if (wi.z * wo.z > 0.0f) nr++;
                }
                const double f = (double)nr / n, se = sqrt(fmax(ref * (1.0 - ref), 1e-12) / n);
                CHECKF(fabs(f - ref) <= 4.5 * se + 1e-9, "ior %g theta %g: reflected share %.5f, R' %.5f (se %.2g)",
                       iors[i], angles[a], f, ref, se);
            }
        }
    }
    /* index 1: no sheet at all */
    pbsdf one = pbsdf_thin_dielectric(1.0f, v3s(1.0f));
    CHECK(pbsdf_thin_reflectance(0.5f, 1.0f) == 0.0f);
    (void)one;
}

/* Diffuse transmission: the shares of reflected and transmitted energy. */
static void test_diffuse_transmission(void)
{
    const vec3 r = v3(0.6f, 0.3f, 0.1f), t = v3(0.2f, 0.5f, 0.85f);
    pbsdf b = pbsdf_diffuse_transmission(r, t);
    rng g = rng_seed(11, 0x5eed);
    for (int side = 0; side < 2; side++) {
        vec3 wo = dir_deg(40.0, 1.0);
        if (side) wo.z = -wo.z;
        const long n = 200000;
        double sr[3] = {0}, st[3] = {0}, qr[3] = {0}, qt[3] = {0};
        for (long k = 0; k < n; k++) {
            const float u[3] = {rng_float(&g), rng_float(&g), rng_float(&g)};
            vec3 wi, w;
            float pdf;
            bool dl;
            REQUIRE(pbsdf_sample(&b, wo, u, &wi, &w, &pdf, &dl));
            CHECK(!dl);
            const double v[3] = {w.x, w.y, w.z};
            const bool refl = wi.z * wo.z > 0.0f;
            for (int c = 0; c < 3; c++) {
                const double vr = refl ? v[c] : 0.0, vt = refl ? 0.0 : v[c];
                sr[c] += vr, qr[c] += vr * vr, st[c] += vt, qt[c] += vt * vt;
            }
        }
        const float rr[3] = {r.x, r.y, r.z}, tt[3] = {t.x, t.y, t.z};
        for (int c = 0; c < 3; c++) {
            const double mr = sr[c] / n, mt = st[c] / n;
            const double ser = sqrt(fmax(qr[c] / n - mr * mr, 0.0) / (n - 1)),
                         set = sqrt(fmax(qt[c] / n - mt * mt, 0.0) / (n - 1));
            CHECKF(fabs(mr - (double)rr[c]) <= 4.5 * ser + 1e-6, "side %d: reflected [%d] %.5f, R %.5f (se %.2g)", side, c, mr,
                   (double)rr[c], ser);
            CHECKF(fabs(mt - (double)tt[c]) <= 4.5 * set + 1e-6, "side %d: transmitted [%d] %.5f, T %.5f (se %.2g)", side, c,
                   mt, (double)tt[c], set);
        }
    }
    /* f itself: R / pi on wo's side, T / pi on the other */
    const vec3 wo = dir_deg(20.0, 0.0), wu = dir_deg(50.0, 2.0), wd = v3(wu.x, wu.y, -wu.z);
    const vec3 fu = pbsdf_eval(&b, wo, wu), fd = pbsdf_eval(&b, wo, wd);
    CHECK(fabs((double)fu.y - 0.3 * (double)wu.z / M_PI) <= 1e-7);
    CHECK(fabs((double)fd.y - 0.5 * (double)wu.z / M_PI) <= 1e-7);
}

/* Oren-Nayar's qualitative model in double, by angles. */
static double on_ref(double sigma, vec3 wo, vec3 wi)
{
    double s2 = sigma * sigma, A = 1.0 - 0.5 * s2 / (s2 + 0.33), B = 0.45 * s2 / (s2 + 0.09);
    double to = acos(fmin(1.0, (double)wo.z)), ti = acos(fmin(1.0, (double)wi.z));
    double po = atan2((double)wo.y, (double)wo.x), pi = atan2((double)wi.y, (double)wi.x);
    double al = fmax(to, ti), be = fmin(to, ti);
    return (A + B * fmax(0.0, cos(pi - po)) * sin(al) * tan(be)) / M_PI;
}

static void test_oren_nayar(void)
{
    rng g = rng_seed(13, 0x5eed);
    const vec3 alb = v3(0.9f, 0.5f, 0.2f);
    pbsdf l = pbsdf_diffuse(alb), o = pbsdf_oren_nayar(alb, 0.0f);
    int same = 0, close = 0;
    const int n = 20000;
    for (int k = 0; k < n; k++) {
        vec3 d[2];
        for (int j = 0; j < 2; j++) {
            const float z = fmaxf(1e-3f, rng_float(&g)), phi = 2.0f * PK_PI * rng_float(&g);
            const float s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            d[j] = v3(s * cosf(phi), s * sinf(phi), z);
        }
        /* sigma = 0 is Lambert: the same f, pdf and samples, bit for bit */
        const vec3 a = pbsdf_eval(&l, d[0], d[1]), b = pbsdf_eval(&o, d[0], d[1]);
        const float u[3] = {rng_float(&g), rng_float(&g), rng_float(&g)};
        vec3 w1, w2, x1, x2;
        float p1, p2;
        bool q1, q2;
        const bool s1 = pbsdf_sample(&l, d[0], u, &w1, &x1, &p1, &q1), s2 = pbsdf_sample(&o, d[0], u, &w2, &x2, &p2, &q2);
        same += memcmp(&a, &b, sizeof a) == 0 && pbsdf_pdf(&l, d[0], d[1]) == pbsdf_pdf(&o, d[0], d[1]) && s1 == s2 &&
                (!s1 || (memcmp(&w1, &w2, sizeof w1) == 0 && memcmp(&x1, &x2, sizeof x1) == 0 && p1 == p2));
        /* the model against its formula by angles, sigma 0.5 */
        pbsdf r = pbsdf_oren_nayar(v3s(1.0f), 0.5f);
        const double f = (double)pbsdf_eval(&r, d[0], d[1]).x / (double)d[1].z, fr = on_ref(0.5, d[0], d[1]);
        close += fabs(f - fr) <= 1e-4 * fr + 1e-6;
    }
    CHECKF(same == n, "Oren-Nayar sigma 0 differs from Lambert at %d of %d", n - same, n);
    /* its albedo (quadrature of the double formula above, checked against
     * eval there): at most 1 up to 65 degrees, and the small gain toward
     * grazing angles (docs/materials.md) stays below 1.6 % */
    static const double sigmas[] = {0.05, 0.1, 0.2, 0.3, 0.6, 1.5};
    double worst = 0.0, worst65 = 0.0;
    for (int si = 0; si < 6; si++)
        for (int t = 0; t <= 89; t += 4) {
            const vec3 wo = dir_deg(t, 0.0);
            const int nq = 160;
            double rho = 0.0;
            for (int a = 0; a < nq; a++) {
                const double ti = (a + 0.5) / nq * 0.5 * M_PI;
                for (int c = 0; c < 2 * nq; c++) {
                    const double ph = (c + 0.5) / (2 * nq) * 2.0 * M_PI;
                    const vec3 wi = v3((float)(sin(ti) * cos(ph)), (float)(sin(ti) * sin(ph)), (float)cos(ti));
                    rho += on_ref(sigmas[si], wo, wi) * cos(ti) * sin(ti) * (0.5 * M_PI / nq) * (M_PI / nq);
                }
            }
            if (rho > worst) worst = rho;
            if (t <= 65 && rho > worst65) worst65 = rho;
        }
    CHECKF(worst65 <= 1.0 + 1e-3, "Oren-Nayar albedo up to 65 degrees: %.5f", worst65);
    CHECKF(worst <= 1.016, "Oren-Nayar albedo: %.5f", worst);
    printf("Oren-Nayar's albedo: at most %.4f up to 65 degrees, %.4f at any angle\n", worst65, worst);
    CHECKF(close == n, "Oren-Nayar differs from its formula at %d of %d", n - close, n);
}

/* Phong: at normal incidence the lobe's integral of f cos is exactly ks
 * ((n + 2) / (2 pi) times the integral of cos^(n+1) over the hemisphere);
 * midpoint quadrature in cos theta and phi. */
static void test_phong(void)
{
    static const float ns[] = {1.0f, 10.0f, 100.0f};
    for (int i = 0; i < 3; i++) {
        pbsdf b = pbsdf_phong(v3s(0.0f), v3s(0.8f), ns[i]);
        const vec3 wo = v3(0.0f, 0.0f, 1.0f);
        const int nt = 4000, np = 16;
        double sum = 0.0;
        for (int a = 0; a < nt; a++) {
            /* denser toward the normal, where the lobe is: z = 1 - s^2 */
            const double s = (a + 0.5) / nt, z = 1.0 - s * s, dz = 2.0 * s / nt, r = sqrt(fmax(0.0, 1.0 - z * z));
            for (int c = 0; c < np; c++) {
                const double phi = 2.0 * M_PI * (c + 0.5) / np;
                const vec3 wi = v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
                sum += (double)pbsdf_eval(&b, wo, wi).x * dz * (2.0 * M_PI / np);
            }
        }
        CHECKF(fabs(sum - 0.8) <= 2e-3, "Phong n=%g: albedo at normal incidence %.5f, expected 0.8", (double)ns[i], sum);
    }
}

int main(void)
{
    test_thin_dielectric();
    test_diffuse_transmission();
    test_oren_nayar();
    test_phong();
    return test_done("test_bsdf_sheets");
}

/*
 * test_bsdf_aniso.c - anisotropic GGX and Beckmann (render/pbsdf.h): the
 * distributions' normalisation and Smith's masking against numeric
 * integrals, equal roughnesses against the isotropic functions, a tangent
 * turned by 90 degrees against swapped roughnesses, reciprocity, and
 * chi-square tests of the conductor's and the dielectric's sampling
 * (reflection and transmission, from either side) against their pdfs.
 * Kept apart from test_bsdf (and smaller) so that neither grows long.
 * Fixed seeds: the results are the same on every run.
 */
#include "test.h"

#include "chi2.h"

#include "math/frame.h"
#include "render/pbsdf.h"
#include "render/sampling.h"
#include "render/shading.h"

#include <stdint.h>

static vec3 dir_from(float theta_deg, float phi)
{
    float t = theta_deg * PK_PI / 180.0f;
    return v3(sinf(t) * cosf(phi), sinf(t) * sinf(phi), cosf(t));
}
static vec3 rand_dir(rng *g, bool upper)
{
    const float z = upper ? rng_float(g) : 2.0f * rng_float(g) - 1.0f, phi = 2.0f * PK_PI * rng_float(g);
    const float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return v3(r * cosf(phi), r * sinf(phi), z);
}
static double rel(double a, double b) { return fabs(a - b) / fmax(fabs(a), fmax(fabs(b), 1e-30)); }

/* ---- the distribution alone ---------------------------------------------- */

/* f(m) over the hemisphere of m by Simpson in (theta, phi), n x 4n intervals;
 * kind 0: D(m) m.z (the normalisation), 1: D(m) max(0, w.m) (the projected
 * area seen from w). theta is split at 0.5 rad so that narrow lobes get
 * nodes. */
static double integrate_d(bool beckmann, float ax, float ay, int kind, vec3 w, int n)
{
    double total = 0.0;
    const double edges[3] = {0.0, 0.5, M_PI / 2.0};
    for (int part = 0; part < 2; part++) {
        const double t0 = edges[part], t1 = edges[part + 1], ht = (t1 - t0) / n, hp = 2.0 * M_PI / (4 * n);
        double s = 0.0;
        for (int i = 0; i <= n; i++) {
            const double t = t0 + i * ht, wt = (i == 0 || i == n) ? 1.0 : (i & 1) ? 4.0 : 2.0;
            for (int j = 0; j <= 4 * n; j++) {
                const double p = j * hp, wp = (j == 0 || j == 4 * n) ? 1.0 : (j & 1) ? 4.0 : 2.0;
                const vec3 m = v3((float)(sin(t) * cos(p)), (float)(sin(t) * sin(p)), (float)cos(t));
                const double d = beckmann ? pbsdf_beckmann_d_aniso(ax, ay, m) : pbsdf_ggx_d_aniso(ax, ay, m);
                const double f = kind == 0 ? (double)m.z : fmax(0.0, (double)v3_dot(w, m));
                s += wt * wp * d * f * sin(t);
            }
        }
        total += s * ht * hp / 9.0;
    }
    return total;
}

static void test_normalisation_and_masking(void)
{
    static const float rough[][2] = {{0.1f, 0.4f}, {0.5f, 0.15f}, {0.3f, 0.3f}, {0.8f, 0.2f}};
    for (int bk = 0; bk < 2; bk++)
        for (int r = 0; r < 4; r++) {
            const float ax = rough[r][0], ay = rough[r][1];
            /* the error of the quadrature: the change from n to 2n intervals */
            const double i1 = integrate_d(bk, ax, ay, 0, v3s(0.0f), 200), i2 = integrate_d(bk, ax, ay, 0, v3s(0.0f), 400);
            const double tol = fmax(4.0 * fabs(i2 - i1), 2e-5);
            printf("  %s %.2f x %.2f: integral of D cos = %.6f (n/2: %.6f)\n", bk ? "Beckmann" : "GGX", (double)ax,
                   (double)ay, i2, i1);
            CHECKF(fabs(i2 - 1.0) <= tol, "%s %g x %g: integral of D(m) cos = %.6f, tol %.2g", bk ? "Beckmann" : "GGX",
                   (double)ax, (double)ay, i2, tol);
            /* Smith: the microfacets' projected area toward w is w.z (1 + Lambda(w)) */
            static const float th[] = {20.0f, 55.0f, 80.0f};
            static const float ph[] = {0.0f, 0.7f, 1.5707963f, 2.6f};
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 4; b++) {
                    const vec3 w = dir_from(th[a], ph[b]);
                    const double lam =
                        bk ? pbsdf_beckmann_lambda_aniso(ax, ay, w) : pbsdf_ggx_lambda_aniso(ax, ay, w);
                    const double closed = (double)w.z * (1.0 + lam);
                    const double n1 = integrate_d(bk, ax, ay, 1, w, 200), n2 = integrate_d(bk, ax, ay, 1, w, 400);
                    const double t2 = fmax(4.0 * fabs(n2 - n1), 3e-5);
                    CHECKF(fabs(n2 - closed) <= t2, "%s %g x %g, w at %g deg, phi %g: projected area %.6f, "
                                                    "w.z (1 + Lambda) %.6f, tol %.2g",
                           bk ? "Beckmann" : "GGX", (double)ax, (double)ay, (double)th[a], (double)ph[b], n2, closed,
                           t2);
                }
        }
}

/* ---- equal roughnesses: the isotropic functions -------------------------- */

static void test_isotropic_limit(void)
{
    rng g = rng_seed(11, 0x5eed);
    double worst[7] = {0};
    static const float alphas[] = {0.02f, 0.1f, 0.35f, 0.8f, 1.0f};
    for (int k = 0; k < 5; k++) {
        const float a = alphas[k];
        for (int i = 0; i < 2000; i++) {
            const vec3 m = rand_dir(&g, true), w = rand_dir(&g, false);
            const float u1 = rng_float(&g), u2 = rng_float(&g);
            double e[8];
            e[0] = rel(pbsdf_ggx_d_aniso(a, a, m), pbsdf_ggx_d(a, m));
            /* Lambda = (sqrt(1 + t) - 1) / 2 loses digits where it is small: as the masking */
            e[1] = rel(1.0 / (1.0 + (double)pbsdf_ggx_lambda_aniso(a, a, w)), 1.0 / (1.0 + (double)pbsdf_ggx_lambda(a, w)));
            e[2] = rel(pbsdf_ggx_vndf_pdf_aniso(a, a, w, m), pbsdf_ggx_vndf_pdf(a, w, m));
            const vec3 s1 = pbsdf_ggx_vndf_sample_aniso(a, a, w, u1, u2), s2 = pbsdf_ggx_vndf_sample(a, w, u1, u2);
            e[3] = v3_len(v3_sub(s1, s2));
            e[4] = rel(pbsdf_beckmann_d_aniso(a, a, m), pbsdf_beckmann_d(a, m));
            /* Beckmann's Lambda is a difference of near-equal terms where it
             * is small: compared as the masking 1 / (1 + Lambda) that uses it */
            e[5] = rel(1.0 / (1.0 + (double)pbsdf_beckmann_lambda_aniso(a, a, w)),
                       1.0 / (1.0 + (double)pbsdf_beckmann_lambda(a, w)));
            /* the isotropic sampler's m and the slope sampler's: the same
             * tilt for u1; the azimuths differ by pi */
            const vec3 b1 = pbsdf_beckmann_sample_aniso(a, a, u1, u2), b2 = pbsdf_beckmann_sample(a, u1, u2);
            e[6] = fabs((double)b1.z - (double)b2.z);
            /* Beckmann's D is exp(-x) of x = tan^2 / alpha^2, which the two
             * write differently ((1 - z^2) / z^2 against (x^2 + y^2) / z^2):
             * x's rounding, a few float epsilons of x, becomes D's relative
             * error, so its bound grows with x */
            const double mz = m.z, x = (1.0 - mz * mz) / (mz * mz) / ((double)a * (double)a);
            /* GGX's isotropic D divides by t^2, t = z^2 (alpha^2 - 1) + 1, whose
             * rounding (an epsilon of the terms, about 1) is a relative error
             * of eps / t: large at the peak of a narrow lobe (t = alpha^2) */
            const double ti = mz * mz * ((double)a * (double)a - 1.0) + 1.0, dt = 2e-6 + 4.0 * 1.2e-7 / ti;
            const double tol[7] = {dt, 2e-6, dt + 2e-6, 2e-6, 2e-6 + 8.0 * 1.2e-7 * x, 2e-6, 2e-6};
            for (int j = 0; j < 7; j++) {
                /* Beckmann's D underflows differently past its cut-off */
                if ((j == 4 && pbsdf_beckmann_d(a, m) < 1e-30f) || !isfinite(e[j])) continue;
                if (e[j] > worst[j]) worst[j] = e[j];
                CHECKF(e[j] <= tol[j], "alpha %g, quantity %d: relative difference %.3g", (double)a, j, e[j]);
            }
        }
    }
    printf("  equal roughnesses, largest relative differences to the isotropic functions: GGX D %.3g, Lambda %.3g, "
           "VNDF pdf %.3g, sample %.3g; Beckmann D %.3g, Lambda %.3g, sample's z %.3g\n",
           worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], worst[6]);
    /* the pbsdf with alpha_v == alpha stays isotropic: the same code, the same bits */
    pbsdf b = pbsdf_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.9f, 2.4f, 2.1f), 0.3f);
    pbsdf_anisotropic(&b, 0.3f);
    CHECK(!(b.flags & PBSDF_ANISO));
    pbsdf_anisotropic(&b, -1.0f);
    CHECK(!(b.flags & PBSDF_ANISO));
    /* and an anisotropic one forced to equal roughnesses evaluates the same */
    const int types[3] = {PBSDF_CONDUCTOR, PBSDF_DIELECTRIC, PBSDF_PLASTIC};
    for (int bk = 0; bk < 2; bk++)
        for (int t = 0; t < 3; t++) {
            pbsdf iso = types[t] == PBSDF_CONDUCTOR    ? pbsdf_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.9f, 2.4f, 2.1f), 0.3f)
                        : types[t] == PBSDF_DIELECTRIC ? pbsdf_dielectric(1.5f, 0.3f, v3s(1.0f))
                                                       : pbsdf_plastic(v3s(0.5f), 1.5f, 0.3f);
            if (bk) iso.flags |= PBSDF_BECKMANN;
            pbsdf an = iso;
            an.flags |= PBSDF_ANISO;
            an.alpha_v = an.alpha;
            double w2 = 0.0;
            for (int i = 0; i < 2000; i++) {
                const vec3 wo = rand_dir(&g, types[t] != PBSDF_DIELECTRIC), wi = rand_dir(&g, types[t] != PBSDF_DIELECTRIC);
                const vec3 f1 = pbsdf_eval(&iso, wo, wi), f2 = pbsdf_eval(&an, wo, wi);
                const double d[4] = {rel(f1.x, f2.x), rel(f1.y, f2.y), rel(f1.z, f2.z),
                                     rel(pbsdf_pdf(&iso, wo, wi), pbsdf_pdf(&an, wo, wi))};
                for (int j = 0; j < 4; j++)
                    if (d[j] > w2) w2 = d[j];
            }
            printf("  %s type %d forced anisotropic at equal roughness: largest relative difference %.3g\n",
                   bk ? "Beckmann" : "GGX", types[t], w2);
            /* Beckmann: exp(-x) for x up to 80 turns x's rounding (8 float
             * epsilons) into up to 80 * 8 eps = 8e-5 of D */
            CHECKF(w2 <= (bk ? 1e-4 : 1e-5), "type %d%s: eval/pdf differ by %.3g from the isotropic ones", types[t],
                   bk ? " (Beckmann)" : "", w2);
        }
}

/* ---- the tangent turned by 90 degrees ------------------------------------ */

static vec3 rot90(vec3 v) { return v3(v.y, -v.x, v.z); } /* local coordinates in the frame (t, -s, n) */

static void test_rotation_and_reciprocity(void)
{
    rng g = rng_seed(12, 0x5eed);
    double worst_rot = 0.0, worst_rec = 0.0, worst_rec_iso = 0.0;
    for (int bk = 0; bk < 2; bk++)
        for (int t = 0; t < 2; t++) {
            pbsdf a = t == 0 ? pbsdf_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.9f, 2.4f, 2.1f), 0.08f)
                             : pbsdf_dielectric(1.5f, 0.08f, v3s(1.0f));
            if (bk) a.flags |= PBSDF_BECKMANN;
            pbsdf b = a;
            pbsdf_anisotropic(&a, 0.45f);
            b.alpha = 0.45f;
            pbsdf_anisotropic(&b, 0.08f);
            for (int i = 0; i < 4000; i++) {
                const vec3 wo = rand_dir(&g, t == 0), wi = rand_dir(&g, t == 0);
                const vec3 f1 = pbsdf_eval(&a, wo, wi), f2 = pbsdf_eval(&b, rot90(wo), rot90(wi));
                const float p1 = pbsdf_pdf(&a, wo, wi), p2 = pbsdf_pdf(&b, rot90(wo), rot90(wi));
                const double d[4] = {rel(f1.x, f2.x), rel(f1.y, f2.y), rel(f1.z, f2.z), rel(p1, p2)};
                for (int j = 0; j < 4; j++)
                    if (d[j] > worst_rot && (j < 3 ? f1.x + f2.x > 1e-20f : p1 + p2 > 1e-20f)) worst_rot = d[j];
                /* reciprocity of the reflection: f(wo, wi) = f(wi, wo) */
                if (wo.z * wi.z > 0.0f) {
                    const vec3 r1 = pbsdf_eval(&a, wo, wi), r2 = pbsdf_eval(&a, wi, wo);
                    const double x = (double)r1.x / fabs(wi.z), y = (double)r2.x / fabs(wo.z);
                    if (x + y > 1e-6) {
                        const double e = rel(x, y);
                        if (e > worst_rec) worst_rec = e;
                    }
                    /* the isotropic lobe of the same alpha, for the float rounding's measure */
                    pbsdf iso = a;
                    iso.flags &= ~PBSDF_ANISO;
                    const vec3 q1 = pbsdf_eval(&iso, wo, wi), q2 = pbsdf_eval(&iso, wi, wo);
                    const double xi = (double)q1.x / fabs(wi.z), yi = (double)q2.x / fabs(wo.z);
                    if (xi + yi > 1e-6 && rel(xi, yi) > worst_rec_iso) worst_rec_iso = rel(xi, yi);
                }
            }
        }
    printf("  tangent turned by 90 degrees vs roughnesses swapped: largest relative difference %.3g\n", worst_rot);
    printf("  reciprocity of the reflection: largest relative difference %.3g (isotropic lobes, the same "
           "directions: %.3g)\n", worst_rec, worst_rec_iso);
    CHECKF(worst_rot <= 1e-4, "turned tangent: %.3g", worst_rot);
    /* as reciprocal as the isotropic lobes are in float (their rounding: the bound) */
    CHECKF(worst_rec <= fmax(2.0 * worst_rec_iso, 1e-5), "reciprocity: %.3g (isotropic %.3g)", worst_rec, worst_rec_iso);

    /* the shading frame: x along dp/du made perpendicular to n, right-handed */
    for (int i = 0; i < 1000; i++) {
        const vec3 n = rand_dir(&g, false), d = v3_scale(rand_dir(&g, false), 3.0f);
        const onb f = shading_frame(n, d);
        const vec3 proj = v3_sub(d, v3_scale(n, v3_dot(n, d)));
        if (v3_len(proj) < 1e-3f) continue;
        CHECK(fabsf(v3_len(f.s) - 1.0f) < 1e-5f && fabsf(v3_len(f.t) - 1.0f) < 1e-5f);
        CHECK(fabsf(v3_dot(f.s, n)) < 1e-5f && fabsf(v3_dot(f.t, n)) < 1e-5f && fabsf(v3_dot(f.s, f.t)) < 1e-5f);
        CHECK(v3_len(v3_sub(v3_cross(f.s, f.t), n)) < 1e-5f);
        CHECK(v3_dot(f.s, proj) > 0.9999f * v3_len(proj));
        /* turning dp/du by 90 degrees about n turns the frame: (s, t) -> (t, -s) */
        const onb f2 = shading_frame(n, v3_cross(n, proj));
        CHECK(v3_len(v3_sub(f2.s, f.t)) < 1e-4f && v3_len(v3_add(f2.t, f.s)) < 1e-4f);
    }
    /* no tangent: the isotropic frame, bit for bit */
    const vec3 n = v3_norm(v3(0.3f, -0.5f, 0.8f));
    const onb f0 = shading_frame(n, v3s(0.0f)), fi = onb_from_normal(n);
    CHECK(memcmp(&f0, &fi, sizeof f0) == 0);
}

/* ---- chi-square of the sampling against the pdf -------------------------- */

#define N_THETA 10
#define N_PHI 20
#define N_CELLS (N_THETA * N_PHI)
#define N_SAMPLES 200000
#define MIN_EXPECTED 5.0

static double simpson_cell(const pbsdf *b, vec3 wo, double t0, double t1, double p0, double p1, int n)
{
    const bool upper = t0 + t1 < M_PI;
    double s = 0.0, ht = (t1 - t0) / n, hp = (p1 - p0) / n;
    for (int i = 0; i <= n; i++) {
        const double t = t0 + i * ht, wt = (i == 0 || i == n) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        double ct = cos(t);
        if (upper ? ct < 0.0 : ct > 0.0) ct = 0.0;
        for (int j = 0; j <= n; j++) {
            const double p = p0 + j * hp, wp = (j == 0 || j == n) ? 1.0 : (j & 1) ? 4.0 : 2.0;
            const vec3 wi = v3((float)(sin(t) * cos(p)), (float)(sin(t) * sin(p)), upper ? (float)ct : -(float)fabs(ct));
            s += wt * wp * sin(t) * (double)pbsdf_pdf(b, wo, wi);
        }
    }
    return s * ht * hp / 9.0;
}
static double cell_pdf(const pbsdf *b, vec3 wo, int ci, int pi)
{
    const double c0 = -1.0 + 2.0 * ci / N_THETA, c1 = -1.0 + 2.0 * (ci + 1) / N_THETA;
    const double t0 = acos(c1), t1 = acos(c0);
    const double p0 = 2.0 * M_PI * pi / N_PHI, p1 = 2.0 * M_PI * (pi + 1) / N_PHI;
    double lo = simpson_cell(b, wo, t0, t1, p0, p1, 16), hi = lo;
    for (int n = 32; n <= 512; n *= 2) {
        hi = simpson_cell(b, wo, t0, t1, p0, p1, n);
        /* an expected-count error of 0.05 standard deviations at most */
        if (fabs(hi - lo) < 0.05 * sqrt(fmax(MIN_EXPECTED, N_SAMPLES * hi)) / N_SAMPLES) break;
        lo = hi;
    }
    return hi;
}
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The p-value of the sampled directions against the pdf's cell integrals;
 * *mismatch counts samples whose own pdf or weight disagree with
 * pbsdf_pdf and pbsdf_eval / pbsdf_pdf. */
static double chi2_run(const pbsdf *b, vec3 wo, uint64_t seed, int *dof_out, double *pdf_total, long *mismatch)
{
    static long obs[N_CELLS + 1];
    static double expct[N_CELLS + 1];
    memset(obs, 0, sizeof obs);
    rng g = rng_seed(seed, 0x5eed);
    long nondelta = 0;
    *mismatch = 0;
    for (long s = 0; s < N_SAMPLES; s++) {
        const float u[3] = {rng_float(&g), rng_float(&g), rng_float(&g)};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta) || delta) continue;
        nondelta++;
        const float z = fminf(1.0f, fmaxf(-1.0f, wi.z));
        int ci = (int)((z + 1.0f) * 0.5f * N_THETA);
        if (ci >= N_THETA) ci = N_THETA - 1;
        double phi = atan2(wi.y, wi.x);
        if (phi < 0.0) phi += 2.0 * M_PI;
        int pi = (int)(phi / (2.0 * M_PI) * N_PHI);
        if (pi >= N_PHI) pi = N_PHI - 1;
        obs[ci * N_PHI + pi]++;
        const float p2 = pbsdf_pdf(b, wo, wi);
        const vec3 e = pbsdf_eval(b, wo, wi);
        if (!(fabsf(p2 - pdf) <= 1e-3f * fmaxf(p2, pdf) + 1e-6f) || !(fabsf(e.x / p2 - w.x) <= 1e-3f * fabsf(w.x) + 1e-6f))
            (*mismatch)++;
    }
    obs[N_CELLS] = N_SAMPLES - nondelta;
    double total = 0.0;
    for (int ci = 0; ci < N_THETA; ci++)
        for (int pi = 0; pi < N_PHI; pi++) {
            const double c = cell_pdf(b, wo, ci, pi);
            expct[ci * N_PHI + pi] = c * N_SAMPLES;
            total += c;
        }
    *pdf_total = total;
    expct[N_CELLS] = fmax(0.0, 1.0 - total) * N_SAMPLES;
    double key[N_CELLS + 1][2];
    for (int i = 0; i <= N_CELLS; i++) key[i][0] = expct[i], key[i][1] = i;
    qsort(key, N_CELLS + 1, sizeof key[0], cmp_double);
    double chi2 = 0.0, pool_exp = 0.0, pool_obs = 0.0;
    int dof = 0;
    for (int k = 0; k <= N_CELLS; k++) {
        const int i = (int)key[k][1];
        if (expct[i] < MIN_EXPECTED || (pool_exp > 0.0 && pool_exp < MIN_EXPECTED)) {
            pool_exp += expct[i];
            pool_obs += obs[i];
        } else {
            const double d = obs[i] - expct[i];
            chi2 += d * d / expct[i];
            dof++;
        }
    }
    if (pool_exp > 0.0) {
        const double d = pool_obs - pool_exp;
        chi2 += d * d / pool_exp;
        dof++;
    }
    dof -= 1;
    *dof_out = dof;
    return dof > 0 ? chi2_pvalue(chi2, dof) : 1.0;
}

static void test_chi2(void)
{
    typedef struct {
        const char *name;
        pbsdf b;
    } ccase;
    ccase cs[6];
    int nc = 0;
    for (int bk = 0; bk < 2; bk++) {
        pbsdf c = pbsdf_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.9f, 2.4f, 2.1f), bk ? 0.4f : 0.1f);
        pbsdf d = pbsdf_dielectric(1.5f, bk ? 0.5f : 0.15f, v3(1.0f, 0.9f, 0.8f));
        if (bk) c.flags |= PBSDF_BECKMANN, d.flags |= PBSDF_BECKMANN;
        pbsdf_anisotropic(&c, bk ? 0.1f : 0.4f);
        pbsdf_anisotropic(&d, bk ? 0.15f : 0.5f);
        cs[nc++] = (ccase){bk ? "Beckmann conductor 0.4 x 0.1" : "GGX conductor 0.1 x 0.4", c};
        cs[nc++] = (ccase){bk ? "Beckmann dielectric 0.5 x 0.15" : "GGX dielectric 0.15 x 0.5", d};
        pbsdf_compensate(&c);
        cs[nc++] = (ccase){bk ? "Beckmann conductor, compensated" : "GGX conductor, compensated", c};
    }
    /* wo: outside at two angles (dielectrics also from inside), at an azimuth
     * between the axes so that the lobe's anisotropy shows */
    static const float angles[] = {30.0f, 70.0f, 140.0f};
    int n_tests = 0;
    for (int c = 0; c < nc; c++) n_tests += cs[c].b.type == PBSDF_DIELECTRIC ? 3 : 2;
    const double threshold = 1.0 - pow(1.0 - 0.01, 1.0 / n_tests);
    printf("%d chi-square tests, %d samples each; per-test significance %.3g (Sidak, overall 0.01)\n", n_tests,
           N_SAMPLES, threshold);
    uint64_t seed = 100;
    for (int c = 0; c < nc; c++)
        for (int a = 0; a < 3; a++) {
            if (angles[a] > 90.0f && cs[c].b.type != PBSDF_DIELECTRIC) continue;
            const vec3 wo = dir_from(angles[a], 0.6f);
            int dof;
            double total;
            long mism;
            const double p = chi2_run(&cs[c].b, wo, seed++, &dof, &total, &mism);
            printf("  %-34s theta_o=%5.1f  dof=%3d p=%.4f  integral of pdf %.5f  mismatches %ld\n", cs[c].name,
                   (double)angles[a], dof, p, total, mism);
            CHECKF(p >= threshold, "%s theta_o %g: p = %.3g < %.3g", cs[c].name, (double)angles[a], p, threshold);
            CHECKF(mism == 0, "%s theta_o %g: %ld samples whose pdf or weight disagree", cs[c].name, (double)angles[a],
                   mism);
            CHECKF(total <= 1.0 + 1e-3, "%s theta_o %g: the pdf integrates to %.5f", cs[c].name, (double)angles[a],
                   total);
        }
}

int main(void)
{
    test_isotropic_limit();
    test_rotation_and_reciprocity();
    test_normalisation_and_masking();
    test_chi2();
    if (test_failures) fprintf(stderr, "%d check(s) failed\n", test_failures);
    return test_failures ? 1 : 0;
}

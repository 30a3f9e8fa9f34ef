/*
 * test_layered.c - the coated (layered) BSDF, pbrt-v4's LayeredBxDF
 * (render/pbsdf.h, PBSDF_COATED), against an independent photon random walk
 * through the same layer written here in double precision with its own
 * generator: a photon arrives from wo, meets the coat (Fresnel's equations;
 * a rough coat's facets drawn from D(m) cos(m), not the BSDF's visible
 * normals), crosses the slab (exponential free paths, Henyey-Greenstein
 * scattering by rejection-free inversion), meets the base (Lambert or a
 * conductor) and so on until it leaves or is absorbed. By reciprocity the
 * share of photons from wo that leave toward a set of directions is the
 * integral of f(wo, wi) cos(wi) over that set, which the BSDF's eval, sample
 * and pdf must reproduce. Bounds are 4.5 standard errors of the difference
 * of the two estimates, both standard errors measured.
 */
#include "test.h"
#include "chi2.h"
#include "warnings.h"

#include "paprsek.h"
#include "render/pbsdf.h"
#include "scene/scene.h"
#include "render/sampling.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

static bool near3(vec3 a, vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

/* ---- the oracle ---------------------------------------------------------- */

typedef struct { uint64_t s; } orng;
static double orand(orng *r) /* splitmix64 -> [0, 1) */
{
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1p-53;
}

typedef struct { double x, y, z; } d3;
static d3 d3m(double x, double y, double z) { d3 r = {x, y, z}; return r; }
static double dot3(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 sc3(d3 a, double s) { return d3m(a.x * s, a.y * s, a.z * s); }
static d3 add3(d3 a, d3 b) { return d3m(a.x + b.x, a.y + b.y, a.z + b.z); }
static d3 nrm3(d3 a) { return sc3(a, 1.0 / sqrt(dot3(a, a))); }

/* Fresnel reflectance for light at cosine c (> 0) to the facet, going from
 * index n1 into n2; 1 under total internal reflection. */
static double ofresnel(double c, double n1, double n2)
{
    double s2 = (n1 / n2) * (n1 / n2) * (1.0 - c * c);
    if (s2 >= 1.0) return 1.0;
    double ct = sqrt(1.0 - s2);
    double rs = (n1 * c - n2 * ct) / (n1 * c + n2 * ct), rp = (n2 * c - n1 * ct) / (n2 * c + n1 * ct);
    return 0.5 * (rs * rs + rp * rp);
}
static double ofresnel_cond(double c, double eta, double k) /* conductor, eta + i k relative */
{
    /* |r_s|^2, |r_p|^2 with complex arithmetic spelled out */
    double s2 = 1.0 - c * c;
    /* n^2 = (eta + i k)^2 */
    double n2r = eta * eta - k * k, n2i = 2.0 * eta * k;
    /* w = sqrt(n^2 - s2) */
    double ar = n2r - s2, ai = n2i, mod = sqrt(ar * ar + ai * ai);
    double wr = sqrt(0.5 * (mod + ar)), wi = (ai >= 0 ? 1 : -1) * sqrt(0.5 * (mod - ar));
    /* rs = (c - w) / (c + w) */
    double rs = ((c - wr) * (c - wr) + wi * wi) / ((c + wr) * (c + wr) + wi * wi);
    /* rp = (n^2 c - w) / (n^2 c + w) */
    double pr = n2r * c - wr, pi_ = n2i * c - wi, qr = n2r * c + wr, qi = n2i * c + wi;
    double rp = (pr * pr + pi_ * pi_) / (qr * qr + qi * qi);
    return 0.5 * (rs + rp);
}

static double olambda(double a, d3 w) /* GGX Smith Lambda */
{
    double t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
    return 0.5 * (sqrt(1.0 + a * a * t2) - 1.0);
}
/* a facet normal from D(m) cos(m): tan^2 = a^2 u / (1 - u) */
static d3 ofacet(double a, orng *r)
{
    double u = orand(r), t2 = a * a * u / (1.0 - u), c = 1.0 / sqrt(1.0 + t2), s = sqrt(1.0 - c * c);
    double ph = 2.0 * M_PI * orand(r);
    return d3m(s * cos(ph), s * sin(ph), c);
}
static d3 oframe(d3 n, double c, double ph) /* a direction at cosine c to n */
{
    d3 t = fabs(n.x) > 0.5 ? nrm3(d3m(-n.y, n.x, 0)) : nrm3(d3m(0, -n.z, n.y));
    d3 b = d3m(n.y * t.z - n.z * t.y, n.z * t.x - n.x * t.z, n.x * t.y - n.y * t.x);
    double s = sqrt(fmax(0.0, 1.0 - c * c));
    return add3(add3(sc3(t, s * cos(ph)), sc3(b, s * sin(ph))), sc3(n, c));
}

typedef struct {
    double eta, alpha;          /* the coat */
    int metal;                  /* base: 0 Lambert (rho), 1 conductor (ce, ck relative to the coat; balpha) */
    double rho, ce, ck, balpha;
    double th, alb, g;          /* the slab */
} olayer;

/* A photon meets a dielectric boundary (normal +z, index eta below, 1
 * above) travelling along d; returns the new direction and multiplies *w by
 * the facet weight (1 for a smooth boundary). False: lost (the weight 0). */
static int oboundary(const olayer *L, d3 *d, double *w, orng *r)
{
    const int from_above = d->z < 0.0;
    const double n1 = from_above ? 1.0 : L->eta, n2 = from_above ? L->eta : 1.0;
    d3 o = sc3(*d, -1.0); /* toward where it came from */
    d3 m = d3m(0, 0, 1);
    double wt = 1.0;
    if (L->alpha > 0.0) {
        m = ofacet(L->alpha, r);
        if (!from_above) m = d3m(m.x, m.y, -m.z); /* facets seen from below: the same surface */
        double om = dot3(o, m);
        if (om <= 0.0) return 0;
        /* D cos sampling: weight |o.m| / (|o.z| |m.z|) times G2 / ... (G2 below) */
        wt = om / (fabs(o.z) * fabs(m.z));
    } else if (!from_above) {
        m = d3m(0, 0, -1);
    }
    double c = dot3(o, m);
    double F = ofresnel(c, n1, n2);
    d3 out;
    const int chose_refl = orand(r) < F;
    if (chose_refl) {
        out = add3(sc3(m, 2.0 * c), sc3(o, -1.0));
    } else {
        double e = n1 / n2, ct = sqrt(1.0 - e * e * (1.0 - c * c));
        out = add3(sc3(sc3(o, -1.0), e), sc3(m, e * c - ct));
        out = nrm3(out);
    }
    if (L->alpha > 0.0) {
        /* height-correlated masking-shadowing of o and out; out must leave
         * on its own side of the macro surface */
        if (chose_refl ? out.z * o.z <= 0 : out.z * o.z >= 0) return 0;
        /* facet m must face out on its side */
        d3 mz = m.z > 0 ? m : sc3(m, -1.0);
        if (dot3(out, mz) * out.z < 0.0) return 0;
        wt *= 1.0 / (1.0 + olambda(L->alpha, o) + olambda(L->alpha, out));
    }
    *w *= wt;
    *d = out;
    return 1;
}

/* One photon from wo; *out its exit direction. Returns its weight when it
 * leaves (0 when absorbed or lost). */
static double ophoton(const olayer *L, d3 wo, d3 *out, int *spec, orng *r)
{
    d3 d = sc3(wo, -1.0);
    double w = 1.0, z = L->th;
    *spec = L->alpha == 0.0;
    if (!oboundary(L, &d, &w, r)) return 0.0;
    if (d.z > 0) {
        *out = d;
        return w;
    }
    for (int n = 0; n < 4000; n++) {
        if (L->alb > 0.0) {
            double t = -log(1.0 - orand(r)), zp = z + t * d.z;
            if (zp > 0.0 && zp < L->th) {
                w *= L->alb;
                *spec = 0;
                double c;
                if (fabs(L->g) < 1e-4) c = 1.0 - 2.0 * orand(r);
                else {
                    double s = (1.0 - L->g * L->g) / (1.0 - L->g + 2.0 * L->g * orand(r));
                    c = (1.0 + L->g * L->g - s * s) / (2.0 * L->g);
                }
                d = nrm3(oframe(d, fmax(-1.0, fmin(1.0, c)), 2.0 * M_PI * orand(r)));
                z = zp;
                if (d.z == 0.0) return 0.0;
                continue;
            }
            z = d.z > 0 ? L->th : 0.0;
        } else {
            w *= exp(-L->th / fabs(d.z));
            z = d.z > 0 ? L->th : 0.0;
        }
        if (z == 0.0) { /* the base */
            d3 o = sc3(d, -1.0);
            if (!L->metal || L->balpha > 0.0) *spec = 0;
            if (!L->metal) {
                if (orand(r) >= L->rho) return 0.0;
                double u = orand(r);
                d = oframe(d3m(0, 0, 1), sqrt(u), 2.0 * M_PI * orand(r));
            } else if (L->balpha > 0.0) {
                d3 m = ofacet(L->balpha, r);
                double om = dot3(o, m);
                if (om <= 0.0) return 0.0;
                d3 wi = add3(sc3(m, 2.0 * om), sc3(o, -1.0));
                if (wi.z <= 0.0) return 0.0;
                w *= ofresnel_cond(om, L->ce, L->ck) * om / (o.z * m.z) /
                     (1.0 + olambda(L->balpha, o) + olambda(L->balpha, wi));
                d = wi;
            } else {
                w *= ofresnel_cond(o.z, L->ce, L->ck);
                d = d3m(-o.x, -o.y, o.z);
            }
        } else {
            if (!oboundary(L, &d, &w, r)) return 0.0;
            if (d.z > 0) {
                *out = d;
                return w;
            }
        }
        if (w == 0.0) return 0.0;
    }
    return 0.0;
}

/* ---- the BSDF's estimates --------------------------------------------------- */

static pbsdf make(const olayer *L, int maxdepth, int nsamples)
{
    pbsdf b;
    if (L->metal)
        b = pbsdf_coated_conductor(v3s((float)L->ce), v3s((float)L->ck), (float)L->balpha, (float)L->eta,
                                   (float)L->alpha, (float)L->th, v3s((float)L->alb), (float)L->g, maxdepth, nsamples);
    else
        b = pbsdf_coated(v3s((float)L->rho), (float)L->eta, (float)L->alpha, (float)L->th, v3s((float)L->alb),
                         (float)L->g, maxdepth, nsamples);
    b.seed = 12345u;
    return b;
}

typedef struct { double mean, se; } est;
static est finish(double s, double s2, long n)
{
    est e;
    e.mean = s / n;
    e.se = sqrt(fmax(0.0, s2 / n - e.mean * e.mean) / n);
    return e;
}
static vec3 dir_theta(double theta_deg, double phi_deg)
{
    double t = theta_deg * M_PI / 180.0, p = phi_deg * M_PI / 180.0;
    return v3((float)(sin(t) * cos(p)), (float)(sin(t) * sin(p)), (float)cos(t));
}

/* The oracle's albedo toward wo and its shares in NB bins of cos(theta_i). */
#define NB 4
static void oracle(const olayer *L, vec3 wo, long n, est *alb, est bins[NB], est *delta)
{
    double ds = 0, ds2 = 0;
    orng r = {0x1234567ull + (uint64_t)(L->alpha * 1000) + (uint64_t)(L->th * 777)};
    double s = 0, s2 = 0, bs[NB] = {0}, bs2[NB] = {0};
    const d3 o = d3m(wo.x, wo.y, wo.z);
    for (long i = 0; i < n; i++) {
        d3 out = {0, 0, 1};
        int spec;
        double w = ophoton(L, o, &out, &spec, &r);
        s += w, s2 += w * w;
        if (spec) {
            ds += w, ds2 += w * w;
        } else if (w > 0.0) {
            int k = (int)(out.z * NB);
            if (k >= NB) k = NB - 1;
            if (k >= 0) bs[k] += w, bs2[k] += w * w;
        }
    }
    *alb = finish(s, s2, n);
    *delta = finish(ds, ds2, n);
    for (int k = 0; k < NB; k++) bins[k] = finish(bs[k], bs2[k], n);
}

/* The BSDF's albedo toward wo by its sampler (the mean weight), and by eval
 * over uniform directions in each bin of cos(theta_i) (plus, for a smooth
 * coat, its mirror reflection, which eval leaves out). */
static void bsdf_est(const pbsdf *b, vec3 wo, long n, est *alb_s, est bins[NB], est *delta)
{
    rng r = rng_seed(77, 99);
    double s = 0, s2 = 0, dl = 0, dl2 = 0;
    for (long i = 0; i < n; i++) {
        const float u[3] = {rng_float(&r), rng_float(&r), rng_float(&r)};
        vec3 wi, wt;
        float pdf;
        bool is_delta;
        double w = 0;
        if (pbsdf_sample(b, wo, u, &wi, &wt, &pdf, &is_delta)) {
            w = wt.x;
            if (is_delta) dl += w, dl2 += w * w;
        }
        s += w, s2 += w * w;
    }
    *alb_s = finish(s, s2, n);
    *delta = finish(dl, dl2, n);
    for (int k = 0; k < NB; k++) {
        double e = 0, e2 = 0;
        for (long i = 0; i < n / NB; i++) {
            /* uniform in solid angle within the bin: cos uniform in [k, k+1) / NB */
            double c = (k + (double)rng_float(&r)) / NB, ph = 2.0 * M_PI * (double)rng_float(&r), sn = sqrt(1.0 - c * c);
            vec3 wi = v3((float)(sn * cos(ph)), (float)(sn * sin(ph)), (float)c);
            double v = (double)pbsdf_eval(b, wo, wi).x * (2.0 * M_PI / NB); /* f cos / (pdf = NB / 2 pi) */
            e += v, e2 += v * v;
        }
        bins[k] = finish(e, e2, n / NB);
    }
}

static int agree(est a, est b, double extra)
{
    return fabs(a.mean - b.mean) <= 4.5 * sqrt(a.se * a.se + b.se * b.se) + extra;
}

static void compare(const char *name, const olayer *L, float theta)
{
    const vec3 wo = dir_theta(theta, 30.0);
    const long n = 60000;
    est oa, ob[NB], od, sa, sb[NB], sd;
    oracle(L, wo, 4 * n, &oa, ob, &od);
    pbsdf b = make(L, 200, 1);
    bsdf_est(&b, wo, n, &sa, sb, &sd);
    CHECKF(agree(oa, sa, 0.0), "%s theta %g: albedo, walk %.5f +- %.5f, sample weights %.5f +- %.5f", name,
           (double)theta, oa.mean, oa.se, sa.mean, sa.se);
    CHECKF(agree(od, sd, 0.0), "%s theta %g: delta part, walk %.5f +- %.5f, sampler %.5f +- %.5f", name,
           (double)theta, od.mean, od.se, sd.mean, sd.se);
    for (int k = 0; k < NB; k++)
        CHECKF(agree(ob[k], sb[k], 0.0), "%s theta %g: cos bin %d, walk %.5f +- %.5f, eval %.5f +- %.5f", name,
               (double)theta, k, ob[k].mean, ob[k].se, sb[k].mean, sb[k].se);
}

/* 1: against the oracle, smooth and rough coats, clear and scattering
 * slabs, Lambert and conductor bases */
static void test_oracle(void)
{
    const olayer cases[] = {
        {1.5, 0.0, 0, 0.5, 0, 0, 0, 0.01, 0.0, 0.0},   /* pbrt's default coateddiffuse */
        {1.5, 0.3, 0, 0.8, 0, 0, 0, 0.01, 0.0, 0.0},   /* rough coat */
        {1.33, 0.0, 0, 0.7, 0, 0, 0, 0.5, 0.8, 0.5},   /* a forward-scattering slab */
        {1.5, 0.2, 0, 0.3, 0, 0, 0, 1.0, 0.9, -0.3},   /* rough, thick, back-scattering */
        {1.5, 0.0, 1, 0, 0.2 / 1.5, 3.0 / 1.5, 0.0, 0.01, 0.0, 0.0}, /* smooth metal under a smooth coat: all delta */
        {1.5, 0.1, 1, 0, 0.2 / 1.5, 3.0 / 1.5, 0.3, 0.01, 0.0, 0.0}, /* rough over rough metal */
        {1.5, 0.0, 1, 0, 1.1 / 1.5, 2.5 / 1.5, 0.2, 0.1, 0.5, 0.3},  /* smooth coat, rough metal, scattering */
    };
    const char *names[] = {"smooth/lambert", "rough/lambert", "smooth/slab g .5", "rough/slab g -.3",
                           "smooth/smooth metal", "rough/rough metal", "smooth/rough metal slab"};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        compare(names[i], &cases[i], 20.0f);
        compare(names[i], &cases[i], 65.0f);
    }
}

/* 2: the furnace: a white Lambertian base under a clear coat reflects all
 * the light, but for what the walks' truncation at maxdepth drops; with an
 * absorbing slab less, as the oracle says. */
static void test_furnace(void)
{
    const olayer white = {1.5, 0.0, 0, 1.0, 0, 0, 0, 1e-6, 0.0, 0.0};
    const olayer rough = {1.5, 0.4, 0, 1.0, 0, 0, 0, 1e-6, 0.0, 0.0};
    const long n = 100000;
    for (int t = 0; t < 2; t++) {
        const vec3 wo = dir_theta(t ? 70.0 : 10.0, 0.0);
        est a, bins[NB], dl;
        /* smooth coat, white base: every walk's weight is exactly 1 */
        pbsdf b = make(&white, 1000, 1);
        bsdf_est(&b, wo, n, &a, bins, &dl);
        CHECKF(fabs(a.mean - 1.0) <= 4.5 * a.se + 1e-4, "furnace, smooth coat: %.5f +- %.5f", a.mean, a.se);
        /* pbrt's default maxdepth 10: the loss is the light still inside after
         * 5 base bounces, at most Fi^5 where Fi is the coat's largest
         * internal reflectance over diffuse light (0.6 for 1.5: bound 0.08) */
        double fi = 0.0;
        for (int i = 0; i < 20000; i++) {
            double mu = (i + 0.5) / 20000.0;
            fi += 2.0 * ofresnel(mu, 1.5, 1.0) * mu / 20000.0;
        }
        b = make(&white, 10, 1);
        bsdf_est(&b, wo, n, &a, bins, &dl);
        CHECKF(a.mean <= 1.0 + 4.5 * a.se && a.mean >= 1.0 - pow(fi, 5) - 4.5 * a.se,
               "furnace, maxdepth 10: %.5f +- %.5f (Fi %.4f)", a.mean, a.se, fi);
        /* a rough coat loses the light its single-scattering facets lose, as
         * the oracle's facets do */
        est oa, ob[NB], od;
        oracle(&rough, wo, 4 * n, &oa, ob, &od);
        b = make(&rough, 1000, 1);
        bsdf_est(&b, wo, n, &a, bins, &dl);
        CHECKF(agree(oa, a, 0.0) && a.mean < 1.0, "furnace, rough coat: %.5f +- %.5f, walk %.5f +- %.5f", a.mean,
               a.se, oa.mean, oa.se);
    }
    /* an absorbing slab (no scattering: albedo 0, thickness 0.3) */
    const olayer absorb = {1.5, 0.0, 0, 1.0, 0, 0, 0, 0.3, 0.0, 0.0};
    const vec3 wo = dir_theta(40.0, 0.0);
    est oa, ob[NB], od, a, bins[NB], dl;
    oracle(&absorb, wo, 400000, &oa, ob, &od);
    pbsdf b = make(&absorb, 1000, 1);
    bsdf_est(&b, wo, 100000, &a, bins, &dl);
    CHECKF(agree(oa, a, 0.0) && a.mean < 0.8, "absorbing slab: %.5f +- %.5f, walk %.5f +- %.5f", a.mean, a.se,
           oa.mean, oa.se);
}

/* 3: the sampler's directions: with a smooth coat over a white base and a
 * thin clear slab every walk has weight 1, so the non-delta directions are
 * distributed as eval (f cos) normalised; eval's integral over each cell
 * is estimated here by many eval calls, whose variance enters the
 * statistic. */
static void test_sampling(void)
{
    const olayer L = {1.5, 0.0, 0, 1.0, 0, 0, 0, 1e-9, 0.0, 0.0};
    const pbsdf b = make(&L, 100, 1);
    const vec3 wo = dir_theta(50.0, 0.0);
    enum { NT = 8, NP = 8, NC = NT * NP };
    const long n = 200000;
    double cnt[NC] = {0};
    long nd = 0, bad = 0;
    rng r = rng_seed(5, 6);
    for (long i = 0; i < n; i++) {
        const float u[3] = {rng_float(&r), rng_float(&r), rng_float(&r)};
        vec3 wi, wt;
        float pdf;
        bool delta;
        if (!pbsdf_sample(&b, wo, u, &wi, &wt, &pdf, &delta) || delta) continue;
        if (!(fabsf(wt.x - 1.0f) < 1e-4f)) bad++;
        int t = (int)(wi.z * wi.z * NT), p = (int)((atan2(wi.y, wi.x) / (2.0 * M_PI) + 0.5) * NP);
        if (t >= NT) t = NT - 1;
        if (p >= NP) p = NP - 1;
        cnt[t * NP + p] += 1.0;
        nd++;
    }
    CHECKF(bad == 0, "%ld walks of weight other than 1", bad);
    /* cells equal in projected solid angle (cos^2 uniform): eval / cos is
     * integrated with the cosine-weighted density */
    double e[NC], ev[NC], tot = 0.0;
    const long m = 6000;
    for (int c = 0; c < NC; c++) {
        double s = 0, s2 = 0;
        const int t = c / NP, p = c % NP;
        for (long i = 0; i < m; i++) {
            double c2 = (t + (double)rng_float(&r)) / NT, ph = ((p + (double)rng_float(&r)) / NP - 0.5) * 2.0 * M_PI;
            double cz = sqrt(c2), sn = sqrt(1.0 - c2);
            vec3 wi = v3((float)(sn * cos(ph)), (float)(sn * sin(ph)), (float)cz);
            double v = (double)pbsdf_eval(&b, wo, wi).x / cz * (M_PI / NC); /* f cos / (cos / (pi / NC)) */
            s += v, s2 += v * v;
        }
        e[c] = s / m;
        ev[c] = fmax(0.0, s2 / m - e[c] * e[c]) / m;
        tot += e[c];
    }
    double x2 = 0.0;
    for (int c = 0; c < NC; c++) {
        const double ex = e[c] / tot * (double)nd, vx = ev[c] / (tot * tot) * (double)nd * (double)nd;
        x2 += (cnt[c] - ex) * (cnt[c] - ex) / (ex + vx);
    }
    const double pv = chi2_pvalue(x2, NC - 1);
    CHECKF(pv > 1e-3, "sampling: chi2 %.1f over %d cells, p %.2g", x2, NC, pv);
    /* the non-delta share of the albedo equals 1 - R(wo) */
    CHECK_NEAR((double)nd / n, 1.0 - ofresnel(wo.z, 1.0, 1.5), 4.5 * sqrt(0.25 / n));
}

/* 4: determinism: the same directions and seed give the same values; the
 * seed (a hit elsewhere) changes them; pdf is positive where eval is */
static void test_determinism(void)
{
    const olayer L = {1.5, 0.2, 0, 0.6, 0, 0, 0, 0.3, 0.7, 0.4};
    pbsdf b = make(&L, 10, 1);
    const vec3 wo = dir_theta(35.0, 10.0), wi = dir_theta(55.0, 200.0);
    const vec3 f1 = pbsdf_eval(&b, wo, wi), f2 = pbsdf_eval(&b, wo, wi);
    CHECK(memcmp(&f1, &f2, sizeof f1) == 0 && f1.x > 0.0f);
    const float p1 = pbsdf_pdf(&b, wo, wi), p2 = pbsdf_pdf(&b, wo, wi);
    CHECK(p1 == p2 && p1 > 0.0f);
    const float u[3] = {0.7f, 0.3f, 0.9f};
    vec3 a1, a2, w1, w2;
    float q1, q2;
    bool d1, d2;
    const bool s1 = pbsdf_sample(&b, wo, u, &a1, &w1, &q1, &d1), s2 = pbsdf_sample(&b, wo, u, &a2, &w2, &q2, &d2);
    CHECK(s1 == s2 && (!s1 || (memcmp(&a1, &a2, sizeof a1) == 0 && memcmp(&w1, &w2, sizeof w1) == 0 && q1 == q2)));
    int differ = 0;
    for (unsigned k = 1; k <= 8; k++) {
        pbsdf c = b;
        c.seed = b.seed + k;
        const vec3 f3 = pbsdf_eval(&c, wo, wi);
        differ += memcmp(&f1, &f3, sizeof f1) != 0;
    }
    CHECK(differ >= 6);
    /* two-sided: wo below mirrors the whole BSDF */
    const vec3 f4 = pbsdf_eval(&b, v3_neg(wo), v3_neg(wi));
    CHECK(f4.x > 0.0f);
    CHECK(pbsdf_eval(&b, wo, v3_neg(wi)).x == 0.0f && pbsdf_pdf(&b, wo, v3_neg(wi)) == 0.0f);
    CHECK(pbsdf_has_nondelta(&b));
    const olayer S = {1.5, 0.0, 1, 0, 0.2, 3.0, 0.0, 0.01, 0.0, 0.0};
    const pbsdf sm = make(&S, 10, 1);
    CHECK(!pbsdf_has_nondelta(&sm));
}

/* 5: a pbrt-v4 scene with both materials and every parameter: read with no
 * warning, each parameter where it belongs, and rendered */
static void test_pbrt_file(void)
{
    pk_context *ctx;
    warning_log warnings;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    warning_log_clear(&warnings);
    pk_scene *s;
    REQUIRE(pk_scene_load_file(ctx, PK_TEST_DATA "/pbrt/coated.pbrt", &s) == PK_OK);
    CHECKF(warnings.count == 0, "%s", warnings.all);
    int n = 0;
    for (size_t i = 0; i < s->nmaterials; i++) {
        const material *m = &s->materials[i];
        if (m->type != MAT_COATED) continue;
        n++;
        if (m->coat_base == MATERIAL_BASE_DIFFUSE && m->layer.nsamples == 2) /* the first sphere */
            CHECK(near3(m->kd, v3(.7f, .2f, .1f), 1e-6f) && fabsf(m->alpha - 0.1f) < 1e-6f && m->ni == 1.5f &&
                  m->layer.thickness == 0.05f && near3(m->layer.albedo, v3(.8f, .8f, .9f), 1e-6f) &&
                  m->layer.g == 0.3f && m->layer.maxdepth == 12);
        if (m->coat_base == MATERIAL_BASE_CONDUCTOR && m->schlick) /* the fourth: reflectance */
            CHECK(near3(m->ks, v3(.9f, .6f, .4f), 1e-6f) && m->alpha == 0.0f &&
                  fabsf(m->base_alpha - sqrtf(0.1f)) < 1e-6f && m->layer.g == -0.2f && m->layer.thickness == 0.2f);
        if (m->coat_base == MATERIAL_BASE_CONDUCTOR && !m->schlick) /* the third: gold */
            CHECK(fabsf(m->alpha - sqrtf(0.05f)) < 1e-6f && fabsf(m->base_alpha - sqrtf(0.2f)) < 1e-6f &&
                  m->eta.x > 0.1f && m->k.x > 1.0f);
    }
    CHECK(n == 4);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 40, o.height = 24, o.spp = 2, o.threads = 2;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    const float *p = pk_image_pixels_const(img);
    double sum = 0.0;
    bool finite = true;
    for (int i = 0; i < 3 * 40 * 24; i++) finite = finite && isfinite(p[i]), sum += (double)p[i];
    CHECK(finite && sum > 0.0);
    pk_image_destroy(img);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
}

int main(void)
{
    test_pbrt_file();
    test_determinism();
    test_sampling();
    test_furnace();
    test_oracle();
    return test_done("test_layered");
}

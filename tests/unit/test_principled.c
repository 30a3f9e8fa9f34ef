/*
 * test_principled.c - Mitsuba 3's principled BSDF (PBSDF_PRINCIPLED): eval
 * and pdf against an independent double-precision reading of Mitsuba's
 * formulas (checked in turn against the values Mitsuba's own test
 * publishes), chi-square of the sampling against the pdf, sample weights
 * against eval / pdf, reciprocity of the reflection, and directional albedo.
 */
#include "test.h"
#include "chi2.h"
#include "render/pbsdf.h"

#include <stdint.h>

/* ---- the reference: Mitsuba's formulas in double, Mitsuba's convention
 * (wi = towards the viewer, wo = the other direction; eval = f |cos wo|;
 * importance transport: no 1/eta^2, as pbsdf.h) ---- */

typedef struct { double x, y, z; } d3;
static d3 d3v(double x, double y, double z) { d3 r = {x, y, z}; return r; }
static double dd(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 dadd(d3 a, d3 b) { return d3v(a.x + b.x, a.y + b.y, a.z + b.z); }
static d3 dsc(d3 a, double s) { return d3v(a.x * s, a.y * s, a.z * s); }
static d3 dnorm(d3 a) { return dsc(a, 1.0 / sqrt(dd(a, a))); }

typedef struct {
    double base[3], metallic, roughness, anisotropic, spec_trans, eta, spec_tint, sheen, sheen_tint, flatness,
        clearcoat, clearcoat_gloss, srate[3]; /* spec, clearcoat, diffuse */
} rparams;

static double r_fresnel(double ci, double eta)
{
    double eta_it = ci >= 0 ? eta : 1 / eta, eta_ti = 1 / eta_it;
    double ct2 = 1 - (1 - ci * ci) * eta_ti * eta_ti;
    double cia = fabs(ci), cta = ct2 > 0 ? sqrt(ct2) : 0;
    if (eta == 1) return 0;
    if (cia == 0) return 1;
    double as = (cia - eta_it * cta) / (cia + eta_it * cta), ap = (cta - eta_it * cia) / (cta + eta_it * cia);
    return 0.5 * (as * as + ap * ap);
}
static double r_sw(double c)
{
    double m = 1 - fmin(1, fmax(0, c));
    return m * m * m * m * m;
}
static double r_schlick(double r0, double ci, double eta)
{
    double eta_it = ci >= 0 ? eta : 1 / eta, eta_ti = 1 / eta_it;
    double ct2 = 1 - (1 - ci * ci) * eta_ti * eta_ti;
    double w = eta_it > 1 ? r_sw(fabs(ci)) : r_sw(ct2 > 0 ? sqrt(ct2) : 0);
    return r0 + (1 - r0) * w;
}
static double r_ggx_d(double ax, double ay, d3 m)
{
    if (m.z <= 0) return 0;
    double t = m.x * m.x / (ax * ax) + m.y * m.y / (ay * ay) + m.z * m.z;
    return 1 / (M_PI * ax * ay * t * t);
}
static double r_g1(double ax, double ay, d3 v, d3 m)
{
    if (dd(v, m) * v.z <= 0) return 0;
    double xy = ax * ax * v.x * v.x + ay * ay * v.y * v.y;
    if (xy == 0) return 1;
    return 2 / (1 + sqrt(1 + xy / (v.z * v.z)));
}
static double r_gtr1(double a, d3 m)
{
    double a2 = a * a, d = (a2 - 1) / (M_PI * log(a2) * (1 + (a2 - 1) * m.z * m.z));
    return d * m.z > 1e-20 ? d : 0;
}
/* the clearcoat's G1 (Mitsuba's smith_ggx1): tan^2 from |v.z| alone, so
 * for an unnormalised v (Mitsuba's test) it differs from r_g1; for unit
 * vectors the two agree */
static double r_g1cc(d3 v, d3 m)
{
    if (dd(v, m) * v.z <= 0) return 0;
    double c2 = v.z * v.z, t2 = (1 - c2) / c2;
    return v.z == 1 ? 1 : 2 / (1 + sqrt(1 + 0.0625 * t2));
}
static void r_alphas(const rparams *q, double *ax, double *ay)
{
    double r2 = q->roughness * q->roughness, asp = sqrt(1 - 0.9 * q->anisotropic);
    *ax = fmax(0.001, r2 / asp), *ay = fmax(0.001, r2 * asp);
}

/* eval (channel c) and pdf of Mitsuba's principled */
static void ref_eval_pdf(const rparams *q, d3 wi, d3 wo, double val[3], double *pdf)
{
    val[0] = val[1] = val[2] = 0;
    *pdf = 0;
    double ci = wi.z, co = wo.z;
    if (ci == 0) return;
    double brdf = (1 - q->metallic) * (1 - q->spec_trans), bsdf = (1 - q->metallic) * q->spec_trans;
    int reflect = ci * co > 0, refract = ci * co < 0, front = ci > 0;
    double eta_path = front ? q->eta : 1 / q->eta;
    double ax, ay;
    r_alphas(q, &ax, &ay);
    d3 wh = dnorm(dadd(wi, dsc(wo, reflect ? 1 : eta_path)));
    if (wh.z < 0) wh = dsc(wh, -1);
    double F = r_fresnel(dd(wi, wh), q->eta);
    d3 hs = ci >= 0 ? wh : dsc(wh, -1);
    int refl_ok = dd(wi, hs) > 0 && dd(wo, hs) > 0, refr_ok = dd(wi, hs) > 0 && dd(wo, hs) < 0;
    double D = r_ggx_d(ax, ay, wh), G = r_g1(ax, ay, wi, wh) * r_g1(ax, ay, wo, wh);
    double lum = 0.212671 * q->base[0] + 0.715160 * q->base[1] + 0.072169 * q->base[2];
    for (int c = 0; c < 3; c++) {
        double bc = q->base[c], v = 0, ctint = lum > 0 ? bc / lum : 1;
        if (reflect && refl_ok && F > 0) {
            double cih = dd(wi, wh), eit = cih >= 0 ? q->eta : 1 / q->eta, r0 = (eit - 1) / (eit + 1);
            double fs = q->metallic * r_schlick(bc, cih, q->eta) +
                        (1 - q->metallic) * q->spec_tint * r_schlick(ctint * r0 * r0, cih, q->eta);
            double fp = front ? (1 - q->metallic) * (1 - q->spec_tint) * F + fs : bsdf * F;
            v += fp * D * G / (4 * fabs(ci));
        }
        if (refract && refr_ok && bsdf > 0 && F < 1) {
            double a = dd(wi, wh), b = dd(wo, wh), den = a + eta_path * b;
            v += sqrt(bc) * bsdf * fabs((1 - F) * D * G * eta_path * eta_path * a * b / (ci * den * den));
        }
        if (q->clearcoat > 0 && reflect && refl_ok && front) {
            double fcc = r_schlick(0.04, dd(wi, wh), q->eta);
            double a = 0.1 + (0.001 - 0.1) * q->clearcoat_gloss;
            v += q->clearcoat * 0.25 * fcc * r_gtr1(a, wh) * r_g1cc(wi, wh) * r_g1cc(wo, wh) * fabs(co);
        }
        if (brdf > 0 && reflect && front) {
            double Fo = r_sw(fabs(co)), Fi = r_sw(fabs(ci));
            double fd = (1 - 0.5 * Fi) * (1 - 0.5 * Fo), cd = dd(wh, wo), Rr = 2 * q->roughness * cd * cd;
            double fr = Rr * (Fo + Fi + Fo * Fi * (Rr - 1));
            double Fss90 = Rr / 2, Fss = (1 + (Fss90 - 1) * Fo) * (1 + (Fss90 - 1) * Fi);
            double fss = 1.25 * (Fss * (1 / (fabs(co) + fabs(ci)) - 0.5) + 0.5);
            v += brdf * fabs(co) * bc / M_PI * ((fd + fr) * (1 - q->flatness) + fss * q->flatness);
            if (q->sheen > 0 && q->metallic < 1) {
                double cs = 1 + (ctint - 1) * q->sheen_tint;
                v += q->sheen * (1 - q->metallic) * r_sw(fabs(cd)) * cs * fabs(co);
            }
        }
        val[c] = v;
    }
    /* pdf */
    double p_sr = front ? q->srate[0] * (1 - bsdf * (1 - F)) : F;
    double p_st = q->spec_trans > 0 ? (front ? q->srate[0] * bsdf * (1 - F) : 1 - F) : 0;
    double p_cc = q->clearcoat > 0 && front ? 0.25 * q->clearcoat * q->srate[1] : 0;
    double p_d = front ? brdf * q->srate[2] : 0;
    double tot = p_sr + p_st + p_cc + p_d;
    p_sr /= tot, p_st /= tot, p_cc /= tot, p_d /= tot;
    double a = dd(wi, wh), b = dd(wo, wh);
    double jac = reflect ? fabs(1 / (4 * b)) : fabs(eta_path * eta_path * b / ((a + eta_path * b) * (a + eta_path * b)));
    d3 wv = ci >= 0 ? wi : dsc(wi, -1);
    double vn = r_g1(ax, ay, wv, wh) > 0 ? D * r_g1(ax, ay, wv, wh) * fabs(dd(wv, wh)) / wv.z : 0;
    double p = 0;
    if (refl_ok && reflect) p += p_sr * vn * jac;
    if (reflect) p += p_d * co / M_PI;
    if (refr_ok && refract) p += p_st * vn * jac;
    if (q->clearcoat > 0 && refl_ok && reflect)
        p += p_cc * r_gtr1(0.1 + (0.001 - 0.1) * q->clearcoat_gloss, wh) * wh.z * jac;
    *pdf = p;
}

static rparams rdefault(void)
{
    rparams q;
    memset(&q, 0, sizeof q);
    q.base[0] = q.base[1] = q.base[2] = 0.5;
    q.roughness = 0.5;
    q.eta = 2 / (1 - sqrt(0.08 * 0.5)) - 1;
    q.srate[0] = q.srate[1] = q.srate[2] = 1;
    return q;
}

static pbsdf to_pbsdf(const rparams *q)
{
    double ax, ay;
    r_alphas(q, &ax, &ay);
    pbsdf b = pbsdf_principled(v3((float)q->base[0], (float)q->base[1], (float)q->base[2]), (float)q->metallic,
                               (float)q->roughness, (float)ax, (float)ay, (float)q->spec_trans, (float)q->eta);
    b.coat = (float)q->clearcoat;
    b.coat_alpha = (float)(0.1 + (0.001 - 0.1) * q->clearcoat_gloss);
    b.pr_spec_tint = (float)q->spec_tint, b.pr_sheen = (float)q->sheen, b.pr_sheen_tint = (float)q->sheen_tint;
    b.pr_flatness = (float)q->flatness;
    b.pr_srate_spec = (float)q->srate[0], b.pr_srate_cc = (float)q->srate[1], b.pr_srate_diff = (float)q->srate[2];
    return b;
}

/* ---- random numbers ---- */
static uint64_t rng_s = 0x9E3779B97F4A7C15ull;
static double rnd(void)
{
    rng_s ^= rng_s << 13, rng_s ^= rng_s >> 7, rng_s ^= rng_s << 17;
    return (double)(rng_s >> 11) * (1.0 / 9007199254740992.0);
}
static d3 rnd_dir(void)
{
    double z = 2 * rnd() - 1, phi = 2 * M_PI * rnd(), s = sqrt(fmax(0, 1 - z * z));
    return d3v(s * cos(phi), s * sin(phi), z);
}
static vec3 tof(d3 a) { return v3((float)a.x, (float)a.y, (float)a.z); }

/* The reference's eval and pdf at Mitsuba's 20 published test directions
 * against Mitsuba's values, with its tolerance (dr::allclose: rtol 1e-5, atol
 * 1e-8, float precision in Mitsuba). */
static void compare_published(const char *what, const double *ev, const double *pdf, const double *eval_true,
                              const double *pdf_true)
{
    int bad = 0;
    for (int i = 0; i < 20; i++)
        if (fabs(pdf[i] - pdf_true[i]) > 1e-8 + 1e-5 * fabs(pdf_true[i]) ||
            fabs(ev[i] - eval_true[i]) > 1e-8 + 1e-5 * fabs(eval_true[i])) {
            fprintf(stderr, "%s: Mitsuba's value %d: pdf %.9g vs %.9g, eval %.9g vs %.9g\n", what, i, pdf[i],
                    pdf_true[i], ev[i], eval_true[i]);
            bad++;
        }
    CHECKF(bad == 0, "%s: %d of Mitsuba's 20 published values differ", what, bad);
}

/* Mitsuba's own published values (src/bsdfs/tests/test_principled.py,
 * test05_eval_pdf: si.wi = (1, 0, 1) unnormalised, wo in the xz plane) */
static void test_mitsuba_values(void)
{
    static const double pdf_true[20] = {
        0.17007458209991455,  0.15398569405078888,  0.14061447978019714,  0.12924496829509735,
        0.1193309798836708,   0.1104581207036972,   0.10231398791074753,  0.09466464817523956,
        0.08733665198087692,  0.08020336925983429,  0.07317451387643814,  0.06618815660476685,
        0.0592045858502388,   0.052201706916093826, 0.045171335339546204, 0.03811638057231903,
        0.031048627570271492, 0.02398696169257164,  0.016955917701125145, 0.009984553791582584};
    static const double eval_true[20] = {
        0.06804995983839035,  0.06425636261701584,  0.060901228338479996, 0.057847555726766586,
        0.05498623475432396,  0.05223095044493675,  0.049513764679431915, 0.04678140580654144,
        0.04399249702692032,  0.04111534729599953,  0.03812596574425697,  0.03500543162226677,
        0.031735487282276154, 0.02829158864915371,  0.024633212015032768, 0.02069348469376564,
        0.01637275144457817,  0.011544802226126194, 0.006091561634093523, 4.703659982886835e-18};
    rparams q = rdefault();
    q.metallic = 0.3, q.spec_tint = 0.6, q.eta = 2 / (1 - sqrt(0.08 * 0.4)) - 1, q.anisotropic = 0.3;
    q.clearcoat = 0.3, q.clearcoat_gloss = 0.5, q.sheen = 0.9, q.sheen_tint = 0.9, q.spec_trans = 0.5;
    q.flatness = 0.5;
    double ev[20], pdf[20];
    for (int i = 0; i < 20; i++) {
        double th = i / 19.0 * (M_PI / 2), v[3];
        ref_eval_pdf(&q, d3v(1, 0, 1), d3v(sin(th), 0, cos(th)), v, &pdf[i]);
        ev[i] = v[0];
    }
    compare_published("principled", ev, pdf, eval_true, pdf_true);
}

static rparams random_params(void)
{
    rparams q = rdefault();
    for (int c = 0; c < 3; c++) q.base[c] = rnd();
    q.metallic = rnd() < 0.3 ? 0 : rnd();
    q.roughness = 0.2 + 0.8 * rnd();
    q.anisotropic = rnd() < 0.5 ? 0 : rnd();
    q.spec_trans = rnd() < 0.4 ? 0 : rnd();
    q.eta = 1.1 + rnd();
    if (rnd() < 0.2) q.eta = 1 / q.eta;
    q.spec_tint = rnd(), q.sheen = rnd(), q.sheen_tint = rnd(), q.flatness = rnd() < 0.5 ? 0 : rnd();
    q.clearcoat = rnd() < 0.4 ? 0 : rnd(), q.clearcoat_gloss = rnd();
    for (int k = 0; k < 3; k++) q.srate[k] = 0.2 + rnd();
    return q;
}

/* pbsdf_eval(wo = view, wi = light) against the reference, and reciprocity */
static void test_eval_vs_reference(void)
{
    int n = 0, bad_e = 0, bad_p = 0, bad_r = 0;
    for (int s = 0; s < 200; s++) {
        rparams q = random_params();
        pbsdf b = to_pbsdf(&q);
        for (int k = 0; k < 500; k++) {
            d3 a = rnd_dir(), c = rnd_dir();
            if (fabs(a.z) < 0.05 || fabs(c.z) < 0.05) continue;
            double v[3], p;
            ref_eval_pdf(&q, a, c, v, &p);
            vec3 e = pbsdf_eval(&b, tof(a), tof(c));
            float pf = pbsdf_pdf(&b, tof(a), tof(c));
            const double ec[3] = {e.x, e.y, e.z};
            n++;
            for (int ch = 0; ch < 3; ch++)
                if (fabs(ec[ch] - v[ch]) > 2e-3 * fabs(v[ch]) + 1e-5) {
                    if (bad_e++ < 5)
                        fprintf(stderr, "eval ch %d: %.7g vs ref %.7g (wo %g %g %g wi %g %g %g)\n", ch, ec[ch],
                                v[ch], a.x, a.y, a.z, c.x, c.y, c.z);
                    break;
                }
            if (fabs((double)pf - p) > 2e-3 * fabs(p) + 1e-5) {
                if (bad_p++ < 5) fprintf(stderr, "pdf: %.7g vs ref %.7g\n", (double)pf, p);
            }
            if (a.z > 0 && c.z > 0) { /* reflection: f(a, c) = f(c, a) */
                vec3 e2 = pbsdf_eval(&b, tof(c), tof(a));
                double f1 = (double)e.x / c.z, f2 = (double)e2.x / a.z;
                if (fabs(f1 - f2) > 2e-3 * fabs(f1) + 1e-5) bad_r++;
            }
        }
    }
    printf("eval/pdf vs reference: %d pairs, %d eval and %d pdf mismatches, %d not reciprocal\n", n, bad_e, bad_p,
           bad_r);
    CHECK(bad_e == 0);
    CHECK(bad_p == 0);
    CHECK(bad_r == 0);
}

/* chi-square of pbsdf_sample against pbsdf_pdf over (z, phi) cells of the
 * sphere; the pdf integrated per cell by a midpoint rule */
#define NZ 32
#define NP 64
/* QN x QN midpoint nodes per cell: with 6 the quadrature error alone of the
 * narrow refracted lobe (alpha 0.25 seen through eta 1.5) was significant at
 * 400000 samples (p 0.003 against 0.07 with 20) */
#define QN 20
static double chi2_run(const pbsdf *b, vec3 wo, int nsamp, double *total_out, int *bad_weight)
{
    static double expct[NZ * NP + 1], obs[NZ * NP + 1];
    memset(obs, 0, sizeof obs);
    double total = 0;
    for (int iz = 0; iz < NZ; iz++)
        for (int ip = 0; ip < NP; ip++) {
            double acc = 0;
            for (int a = 0; a < QN; a++)
                for (int c = 0; c < QN; c++) {
                    double z = -1 + 2.0 * (iz + (a + 0.5) / QN) / NZ, ph = 2 * M_PI * (ip + (c + 0.5) / QN) / NP;
                    double s = sqrt(fmax(0, 1 - z * z));
                    acc += (double)pbsdf_pdf(b, wo, v3((float)(s * cos(ph)), (float)(s * sin(ph)), (float)z));
                }
            double cell = acc / (QN * QN) * (2.0 / NZ) * (2 * M_PI / NP);
            expct[iz * NP + ip] = cell * nsamp;
            total += cell;
        }
    expct[NZ * NP] = fmax(0, 1 - total) * nsamp;
    for (int i = 0; i < nsamp; i++) {
        float u[3] = {(float)rnd(), (float)rnd(), (float)rnd()};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta)) {
            obs[NZ * NP] += 1;
            continue;
        }
        /* the weight is eval cos / pdf, pdf is pbsdf_pdf */
        vec3 e = pbsdf_eval(b, wo, wi);
        float p2 = pbsdf_pdf(b, wo, wi);
        if (delta || fabsf(p2 - pdf) > 1e-4f * p2 || fabsf(w.x - e.x / pdf) > 1e-4f * fabsf(w.x) + 1e-7f)
            (*bad_weight)++;
        double z = wi.z, ph = atan2(wi.y, wi.x);
        if (ph < 0) ph += 2 * M_PI;
        int iz = (int)((z + 1) / 2 * NZ), ip = (int)(ph / (2 * M_PI) * NP);
        iz = iz < 0 ? 0 : iz >= NZ ? NZ - 1 : iz;
        ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
        obs[iz * NP + ip] += 1;
    }
    /* pool cells with fewer than 5 expected */
    double chi2 = 0, pe = 0, po = 0;
    int dof = 0;
    for (int i = 0; i <= NZ * NP; i++) {
        if (expct[i] < 5) {
            pe += expct[i], po += obs[i];
        } else {
            double d = obs[i] - expct[i];
            chi2 += d * d / expct[i];
            dof++;
        }
    }
    if (pe > 0) {
        chi2 += (po - pe) * (po - pe) / pe;
        dof++;
    }
    *total_out = total;
    return dof > 1 ? chi2_pvalue(chi2, dof - 1) : 1.0;
}

static void test_chi2(void)
{
    struct {
        const char *name;
        double metallic, spec_trans, clearcoat, sheen, roughness, eta, wz, anisotropic;
    } cases[] = {
        {"diffuse only", 0, 0, 0, 0, 0.6, 1.5, 0.7, 0},
        {"metallic", 1, 0, 0, 0, 0.5, 1.5, 0.6, 0},
        {"spec_trans 1", 0, 1, 0, 0, 0.5, 1.5, 0.6, 0},
        {"spec_trans 0.5", 0.2, 0.5, 0.8, 0, 0.6, 1.33, 0.7, 0},
        {"clearcoat", 0.4, 0, 1, 0, 0.6, 1.33, 0.7, 0},
        {"sheen", 0, 0, 0, 1, 0.7, 1.5, 0.4, 0},
        {"from inside", 0, 0.7, 0.8, 0, 0.5, 1.5, -0.7, 0},
        {"eta < 1", 0.2, 0.5, 1, 0, 0.8, 0.5, 0.7, 0},
        /* anisotropic (ax != ay), wo at an azimuth off both axes */
        {"aniso metal", 1, 0, 0, 0, 0.6, 1.5, 0.6, 0.9},
        {"aniso mixed", 0.3, 0.4, 0.5, 0.5, 0.7, 1.5, 0.5, 0.6},
        {"aniso inside", 0, 0.8, 0, 0, 0.6, 1.4, -0.6, 0.8},
    };
    const int nc = (int)(sizeof cases / sizeof cases[0]);
    /* nc tests at once: each at a significance of about 0.01 / nc (Sidak) */
    const double alpha = 1 - pow(1 - 0.01, 1.0 / nc);
    for (int i = 0; i < nc; i++) {
        rparams q = rdefault();
        q.base[0] = 0.8, q.base[1] = 0.5, q.base[2] = 0.3;
        q.metallic = cases[i].metallic, q.spec_trans = cases[i].spec_trans, q.clearcoat = cases[i].clearcoat;
        q.sheen = cases[i].sheen, q.roughness = cases[i].roughness, q.eta = cases[i].eta;
        q.anisotropic = cases[i].anisotropic;
        pbsdf b = to_pbsdf(&q);
        CHECK(((b.flags & PBSDF_ANISO) != 0) == (q.anisotropic > 0));
        double wz = cases[i].wz, s = sqrt(1 - wz * wz), phi = q.anisotropic > 0 ? 0.6 : 0.0;
        vec3 wo = v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)wz);
        double total;
        int badw = 0;
        double pv = chi2_run(&b, wo, 400000, &total, &badw);
        printf("chi2 %-15s p = %.4f, pdf integral %.4f, bad weights %d\n", cases[i].name, pv, total, badw);
        CHECKF(pv > alpha, "%s: p-value %g", cases[i].name, pv);
        CHECKF(total <= 1.0 + 2e-3, "%s: the pdf integrates to %g", cases[i].name, total);
        CHECK(badw == 0);
    }
}

/* directional albedo of a white base colour by sampling (mean weight):
 * at most 1 plus 4 standard errors for the metal and the glass; the opaque
 * dielectric's is reported (the model adds specular on top of diffuse) */
static void test_albedo(void)
{
    struct { const char *name; double metallic, spec_trans, roughness, anisotropic; int bounded; } cases[] = {
        {"metal r0.2", 1, 0, 0.2, 0, 1},      {"metal r0.8", 1, 0, 0.8, 0, 1},     {"glass r0.3", 0, 1, 0.3, 0, 1},
        {"glass r0.8", 0, 1, 0.8, 0, 1},      {"dielectric r0.5", 0, 0, 0.5, 0, 0}, {"aniso metal", 1, 0, 0.5, 0.9, 1},
        {"aniso glass", 0, 1, 0.5, 0.9, 1},
    };
    for (int i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++) {
        rparams q = rdefault();
        q.base[0] = q.base[1] = q.base[2] = 1;
        q.metallic = cases[i].metallic, q.spec_trans = cases[i].spec_trans, q.roughness = cases[i].roughness;
        q.anisotropic = cases[i].anisotropic;
        pbsdf b = to_pbsdf(&q);
        double worst = 0, worst_err = 0, worst_z = 0;
        bool first = true;
        for (int iz = 1; iz <= 8; iz++) {
            for (int side = 0; side < (q.spec_trans > 0 ? 2 : 1); side++) {
                double wz = iz / 8.0 * (side ? -1 : 1), s = sqrt(1 - wz * wz);
                vec3 wo = v3((float)s, 0.0f, (float)wz);
                const int n = 100000;
                double sum = 0, sum2 = 0;
                for (int k = 0; k < n; k++) {
                    float u[3] = {(float)rnd(), (float)rnd(), (float)rnd()};
                    vec3 wi, w;
                    float pdf;
                    bool delta;
                    double x = 0;
                    if (pbsdf_sample(&b, wo, u, &wi, &w, &pdf, &delta)) x = w.x;
                    sum += x, sum2 += x * x;
                }
                double mean = sum / n, err = sqrt(fmax(0, sum2 / n - mean * mean) / n);
                if (first || mean - 4 * err > worst - 4 * worst_err) worst = mean, worst_err = err, worst_z = wz;
                first = false;
            }
        }
        printf("albedo %-16s max %.4f +- %.4f (wo.z %.3f)\n", cases[i].name, worst, worst_err, worst_z);
        if (cases[i].bounded) CHECKF(worst <= 1 + 4 * worst_err, "%s: albedo %g", cases[i].name, worst);
    }
}

/* ---- principledthin (PBSDF_PRINCIPLED_THIN) ---- */

typedef struct {
    double base[3], roughness, anisotropic, spec_trans, eta, spec_tint, sheen, sheen_tint, flatness;
    double diff_trans;  /* Mitsuba's 0 ... 2 */
    double srate[4];    /* specular reflection and transmission, diffuse reflection and transmission */
} tparams;

static void t_alphas(double r, double an, double *ax, double *ay)
{
    double r2 = r * r, asp = sqrt(1 - 0.9 * an);
    *ax = fmax(0.001, r2 / asp), *ay = fmax(0.001, r2 * asp);
}

/* Mitsuba's principledthin eval (channel c) and pdf, Mitsuba's convention
 * (wi = towards the viewer) */
static void ref_thin(const tparams *q, d3 wi, d3 wo, double val[3], double *pdf)
{
    val[0] = val[1] = val[2] = 0;
    *pdf = 0;
    if (wi.z == 0) return;
    double sg = wi.z < 0 ? -1 : 1;
    wi = dsc(wi, sg), wo = dsc(wo, sg);
    double ci = wi.z, co = wo.z, st = q->spec_trans, dt = q->diff_trans / 2;
    int reflect = co > 0, refract = co < 0;
    d3 wr = d3v(wo.x, wo.y, fabs(wo.z)), wh = dnorm(dadd(wi, wr));
    double ax, ay, tx, ty;
    t_alphas(q->roughness, q->anisotropic, &ax, &ay);
    t_alphas((0.65 * q->eta - 0.35) * q->roughness, q->anisotropic, &tx, &ty);
    int refl_mm = dd(wi, wh) > 0 && dd(wo, wh) > 0, trans_mm = dd(wi, wh) > 0 && dd(wo, wh) < 0;
    double F = r_fresnel(dd(wi, wh), q->eta);
    double lum = 0.212671 * q->base[0] + 0.715160 * q->base[1] + 0.072169 * q->base[2];
    for (int c = 0; c < 3; c++) {
        double bc = q->base[c], v = 0, ctint = lum > 0 ? bc / lum : 1;
        if (st > 0 && reflect && refl_mm) {
            double r0 = (q->eta - 1) / (q->eta + 1);
            double fs = r_schlick(ctint * r0 * r0, dd(wi, wh), q->eta);
            double ft = F + (fs - F) * q->spec_tint;
            v += st * ft * r_ggx_d(ax, ay, wh) * r_g1(ax, ay, wi, wh) * r_g1(ax, ay, wo, wh) / (4 * ci);
        }
        if (st > 0 && refract && trans_mm)
            v += st * bc * (1 - F) * r_ggx_d(tx, ty, wh) * r_g1(tx, ty, wi, wh) * r_g1(tx, ty, wo, wh) / (4 * ci);
        if (reflect && st < 1 && dt < 1) {
            double Fo = r_sw(fabs(co)), Fi = r_sw(ci);
            double fd = (1 - 0.5 * Fi) * (1 - 0.5 * Fo), cd = dd(wh, wo), Rr = 2 * q->roughness * cd * cd;
            double fr = Rr * (Fo + Fi + Fo * Fi * (Rr - 1));
            double Fss90 = Rr / 2, Fss = (1 + (Fss90 - 1) * Fo) * (1 + (Fss90 - 1) * Fi);
            double fss = 1.25 * (Fss * (1 / (fabs(co) + fabs(ci)) - 0.5) + 0.5);
            v += (1 - st) * co * bc / M_PI * (1 - dt) * ((fd + fr) * (1 - q->flatness) + fss * q->flatness);
            if (q->sheen > 0) {
                double cs = 1 + (ctint - 1) * q->sheen_tint;
                v += q->sheen * (1 - st) * r_sw(fabs(cd)) * cs * (1 - dt) * fabs(co);
            }
        }
        if (refract && st < 1 && dt > 0) v += (1 - st) * dt * bc / M_PI * fabs(co);
        val[c] = v;
    }
    double p[4] = {st * q->srate[0] / 2, st * q->srate[1] / 2, q->srate[2] * (1 - st) * (1 - dt),
                   q->srate[3] * (1 - st) * dt};
    double tot = p[0] + p[1] + p[2] + p[3];
    for (int k = 0; k < 4; k++) p[k] /= tot;
    double jac = fabs(1 / (4 * dd(wr, wh)));
    double pp = 0;
    if (refl_mm && reflect)
        pp += p[0] * r_ggx_d(ax, ay, wh) * r_g1(ax, ay, wi, wh) * fabs(dd(wi, wh)) / wi.z * jac;
    if (trans_mm && refract)
        pp += p[1] * r_ggx_d(tx, ty, wh) * r_g1(tx, ty, wi, wh) * fabs(dd(wi, wh)) / wi.z * jac;
    if (reflect) pp += p[2] * co / M_PI;
    if (refract) pp += p[3] * -co / M_PI;
    *pdf = pp;
}

static tparams tdefault(void)
{
    tparams q;
    memset(&q, 0, sizeof q);
    q.base[0] = q.base[1] = q.base[2] = 0.5;
    q.roughness = 0.5, q.eta = 1.5;
    for (int k = 0; k < 4; k++) q.srate[k] = 1;
    return q;
}

/* as shading.h makes it from the material */
static pbsdf to_pbsdf_thin(const tparams *q)
{
    double ax, ay, tx, ty;
    t_alphas(q->roughness, q->anisotropic, &ax, &ay);
    t_alphas((0.65 * q->eta - 0.35) * q->roughness, q->anisotropic, &tx, &ty);
    pbsdf b = pbsdf_principled_thin(v3((float)q->base[0], (float)q->base[1], (float)q->base[2]), (float)q->roughness,
                                    (float)ax, (float)ay, (float)tx, (float)ty, (float)q->spec_trans,
                                    (float)(q->diff_trans / 2), (float)q->eta);
    b.pr_spec_tint = (float)q->spec_tint, b.pr_sheen = (float)q->sheen, b.pr_sheen_tint = (float)q->sheen_tint;
    b.pr_flatness = (float)q->flatness;
    b.pr_srate_spec = (float)q->srate[0], b.pr_srate_st = (float)q->srate[1];
    b.pr_srate_diff = (float)q->srate[2], b.pr_srate_dt = (float)q->srate[3];
    return b;
}

/* Mitsuba's published values (test_principledthin.py, test03_eval_pdf_thin:
 * si.wi = (1, 0, 1) unnormalised, wo in the xz plane) */
static void test_thin_mitsuba_values(void)
{
    static const double pdf_true[20] = {
        0.18230389058589935, 0.17071931064128876, 0.1604636013507843,  0.15113641321659088, 0.1424213945865631,
        0.13407252728939056, 0.1259022206068039,  0.1177704930305481,  0.10957615822553635, 0.1012495756149292,
        0.09274674206972122, 0.0840444564819336,  0.07513649761676788, 0.06603056192398071, 0.05674567073583603,
        0.04731012135744095, 0.03775978833436966, 0.028136683627963066, 0.01848774217069149, 0.008863822557032108};
    static const double eval_true[20] = {
        0.04944333806633949, 0.04872140288352966, 0.047846242785453796, 0.0468028225004673,  0.04557877406477928,
        0.04416417330503464, 0.042551249265670776, 0.04073421657085419, 0.03870923072099686, 0.036474503576755524,
        0.03403010591864586, 0.0313769206404686,  0.028513599187135696, 0.025431113317608833, 0.02210502326488495,
        0.01848825439810753, 0.014510626904666424, 0.01009628176689148, 0.005216196645051241, 3.899415020768372e-18};
    tparams q = tdefault();
    q.eta = 1.5, q.anisotropic = 0.5, q.sheen = 0.5, q.sheen_tint = 0.2, q.spec_trans = 0.5, q.flatness = 0.5;
    q.diff_trans = 0.6;
    double ev[20], pdf[20];
    for (int i = 0; i < 20; i++) {
        double th = i / 19.0 * (M_PI / 2), v[3];
        ref_thin(&q, d3v(1, 0, 1), d3v(sin(th), 0, cos(th)), v, &pdf[i]);
        ev[i] = v[0];
    }
    compare_published("principledthin", ev, pdf, eval_true, pdf_true);
}

static tparams random_tparams(void)
{
    tparams q = tdefault();
    for (int c = 0; c < 3; c++) q.base[c] = rnd();
    q.roughness = 0.2 + 0.8 * rnd();
    q.anisotropic = rnd() < 0.5 ? 0 : rnd();
    q.spec_trans = rnd() < 0.3 ? 0 : rnd();
    q.eta = 1.05 + rnd();
    q.spec_tint = rnd(), q.sheen = rnd() < 0.5 ? 0 : rnd(), q.sheen_tint = rnd();
    q.flatness = rnd() < 0.5 ? 0 : rnd();
    q.diff_trans = rnd() < 0.3 ? 0 : 2 * rnd();
    for (int k = 0; k < 4; k++) q.srate[k] = 0.2 + rnd();
    return q;
}

/* eval and pdf against the reference (wo on both sides: the sheet is
 * two-sided), reciprocity of reflection and transmission */
static void test_thin_eval(void)
{
    int n = 0, bad_e = 0, bad_p = 0, bad_r = 0, nonrecip_t = 0;
    for (int s = 0; s < 200; s++) {
        tparams q = random_tparams();
        pbsdf b = to_pbsdf_thin(&q);
        for (int k = 0; k < 500; k++) {
            d3 a = rnd_dir(), c = rnd_dir();
            if (fabs(a.z) < 0.05 || fabs(c.z) < 0.05) continue;
            double v[3], p;
            ref_thin(&q, a, c, v, &p);
            vec3 e = pbsdf_eval(&b, tof(a), tof(c));
            const double pf = (double)pbsdf_pdf(&b, tof(a), tof(c)), ec[3] = {e.x, e.y, e.z};
            n++;
            for (int ch = 0; ch < 3; ch++)
                if (fabs(ec[ch] - v[ch]) > 2e-3 * fabs(v[ch]) + 1e-5) {
                    if (bad_e++ < 5)
                        fprintf(stderr, "thin eval ch %d: %.7g vs ref %.7g (wo %g %g %g wi %g %g %g)\n", ch, ec[ch],
                                v[ch], a.x, a.y, a.z, c.x, c.y, c.z);
                    break;
                }
            if (fabs(pf - p) > 2e-3 * fabs(p) + 1e-5 && bad_p++ < 5)
                fprintf(stderr, "thin pdf: %.7g vs ref %.7g\n", pf, p);
            /* f(a, c) = f(c, a) for reflection (eval / |cos| both ways);
             * Mitsuba's specular transmission is not reciprocal (its
             * microfacet test, wo.h > 0 > wi.h, holds one way only), so
             * there the reverse is only checked against the reference */
            vec3 e2 = pbsdf_eval(&b, tof(c), tof(a));
            double f1 = (double)e.x / fabs(c.z), f2 = (double)e2.x / fabs(a.z);
            if (a.z * c.z > 0 && fabs(f1 - f2) > 2e-3 * fabs(f1) + 1e-5) bad_r++;
            if (a.z * c.z < 0 && fabs(f1 - f2) > 2e-3 * fabs(f1) + 1e-5) nonrecip_t++;
        }
    }
    printf("thin eval/pdf vs reference: %d pairs, %d eval and %d pdf mismatches, %d reflections not reciprocal "
           "(transmissions: %d, Mitsuba's model)\n",
           n, bad_e, bad_p, bad_r, nonrecip_t);
    CHECK(bad_e == 0);
    CHECK(bad_p == 0);
    CHECK(bad_r == 0);
}

static void test_thin_chi2(void)
{
    struct {
        const char *name;
        double spec_trans, diff_trans, roughness, anisotropic, eta, wz;
    } cases[] = {
        {"thin diffuse", 0, 0.6, 0.6, 0, 1.5, 0.7},          {"thin spec_trans 1", 1, 0, 0.5, 0, 1.5, 0.6},
        {"thin mixed", 0.5, 1.2, 0.6, 0, 1.33, 0.5},         {"thin back side", 0.6, 0.9, 0.6, 0.5, 1.3296, -0.7},
        {"thin aniso", 0.4, 0.6, 0.6, 0.5, 1.3296, 0.7},
    };
    const int nc = (int)(sizeof cases / sizeof cases[0]);
    const double alpha = 1 - pow(1 - 0.01, 1.0 / nc);
    for (int i = 0; i < nc; i++) {
        tparams q = tdefault();
        q.base[0] = 0.8, q.base[1] = 0.5, q.base[2] = 0.3;
        q.spec_trans = cases[i].spec_trans, q.diff_trans = cases[i].diff_trans, q.roughness = cases[i].roughness;
        q.anisotropic = cases[i].anisotropic, q.eta = cases[i].eta, q.sheen = 0.5;
        pbsdf b = to_pbsdf_thin(&q);
        double wz = cases[i].wz, s = sqrt(1 - wz * wz), phi = q.anisotropic > 0 ? 0.6 : 0.0;
        vec3 wo = v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)wz);
        double total;
        int badw = 0;
        double pv = chi2_run(&b, wo, 400000, &total, &badw);
        printf("chi2 %-17s p = %.4f, pdf integral %.4f, bad weights %d\n", cases[i].name, pv, total, badw);
        CHECKF(pv > alpha, "%s: p-value %g", cases[i].name, pv);
        CHECKF(total <= 1.0 + 2e-3, "%s: the pdf integrates to %g", cases[i].name, total);
        CHECK(badw == 0);
    }
}

/* white sheet: diff_trans 2 (all diffuse transmission) has albedo exactly 1;
 * spec_trans 1 (rough reflection and transmission) at most 1 */
static void test_thin_albedo(void)
{
    struct { const char *name; double spec_trans, diff_trans; int exact; } cases[] = {
        {"thin diff_trans 2", 0, 2, 1}, {"thin spec_trans 1", 1, 0, 0}};
    for (int i = 0; i < 2; i++) {
        tparams q = tdefault();
        q.base[0] = q.base[1] = q.base[2] = 1;
        q.spec_trans = cases[i].spec_trans, q.diff_trans = cases[i].diff_trans;
        pbsdf b = to_pbsdf_thin(&q);
        for (int iz = 1; iz <= 4; iz++) {
            double wz = (iz - 2.5) / 2.5, s = sqrt(1 - wz * wz); /* both sides */
            vec3 wo = v3((float)s, 0.0f, (float)wz);
            const int n = 100000;
            double sum = 0, sum2 = 0;
            for (int k = 0; k < n; k++) {
                float u[3] = {(float)rnd(), (float)rnd(), (float)rnd()};
                vec3 wi, w;
                float pdf;
                bool delta;
                double x = 0;
                if (pbsdf_sample(&b, wo, u, &wi, &w, &pdf, &delta)) x = w.x;
                sum += x, sum2 += x * x;
            }
            double mean = sum / n, err = sqrt(fmax(0, sum2 / n - mean * mean) / n);
            if (iz == 1 || iz == 4) printf("albedo %-17s wo.z %+.2f: %.4f +- %.4f\n", cases[i].name, wz, mean, err);
            if (cases[i].exact) CHECKF(fabs(mean - 1) < 1e-4, "%s: albedo %g", cases[i].name, mean);
            else CHECKF(mean <= 1 + 4 * err, "%s: albedo %g +- %g", cases[i].name, mean, err);
        }
    }
}

int main(void)
{
    test_mitsuba_values();
    test_eval_vs_reference();
    test_chi2();
    test_albedo();
    test_thin_mitsuba_values();
    test_thin_eval();
    test_thin_chi2();
    test_thin_albedo();
    return test_done("test_principled");
}

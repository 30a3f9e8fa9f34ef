/*
 * test_bsdf.c - statistical tests of the path tracer's BSDFs (render/pbsdf.h)
 * for every type, several roughnesses and incident angles (grazing among
 * them), as Mitsuba and pbrt test theirs: a chi-square goodness-of-fit of the
 * sampled directions against the pdf, the pdf's integral over the sphere,
 * eval/pdf == sample weight, reciprocity, and white-furnace energy bounds.
 * Fixed seeds: the results are the same on every run.
 */
#include "test.h"

#include "chi2.h"

#include "math/frame.h"
#include "render/pbsdf.h"
#include "render/sampling.h"

#include <stdint.h>

/* ---- random numbers: the renderer's PCG32 (render/sampling.h) ----------- */

typedef rng prng;
static prng prng_make(uint64_t seed) { return rng_seed(seed, 0x5eed); }
static float prng_f(prng *r) { return rng_float(r); }
/* ---- the cases -------------------------------------------------------------- */

#define N_THETA 10 /* cells in cos(theta) over [-1, 1] */
#define N_PHI 20   /* cells in phi over [0, 2 pi) */
#define N_CELLS (N_THETA * N_PHI)
#define N_SAMPLES 400000
#define N_FURNACE 200000
#define MIN_EXPECTED 5.0

static const float roughs[] = {0.05f, 0.2f, 0.5f, 1.0f};
/* incident angles in degrees; > 90 means from inside (dielectrics only) */
static const float angles_out[] = {3.0f, 35.0f, 65.0f, 87.0f};
static const float angles_in[] = {145.0f, 125.0f, 93.0f}; /* 125: beyond the critical angle of 1.5 */

typedef struct bcase {
    char name[64];
    pbsdf b;
    bool lossless; /* white furnace == 1 exactly (every sample weighs 1) */
    double tol;    /* energy compensation: the albedo may exceed 1 by this much (the tables' 1 %) */
} bcase;

/* glTF's metallic-roughness with a diffuse base reflects more than it
 * receives toward grazing angles: Appendix B's fresnel_mix weights the base
 * by 1 - F(|wo.h|), which the specification itself says breaks energy
 * conservation (test_metallic_roughness measures by how much). Its energy
 * bound is checked up to this angle of wo. */
#define MR_ENERGY_MAX_THETA 40.0f
static bool gains_at_grazing(const pbsdf *b)
{
    return b->type == PBSDF_METALLIC_ROUGHNESS && (1.0f - b->metallic) * (1.0f - b->transmission) > 0.0f;
}
/* Oren-Nayar's qualitative model reflects a little more than it receives
 * toward grazing angles for small sigma (1.3 % at 87 degrees for sigma 0.2:
 * the B term's sin(alpha) tan(beta) grows faster than A shrinks;
 * test_bsdf_sheets bounds it by its closed form): bounded up to 65 degrees. */
#define ON_ENERGY_MAX_THETA 65.0f

static vec3 dir_from(float theta_deg, float phi)
{
    float t = theta_deg * PK_PI / 180.0f;
    return v3(sinf(t) * cosf(phi), sinf(t) * sinf(phi), cosf(t));
}

/* ---- numerical integration of pdf (and eval) over one cell --------------- */

typedef struct cell_int {
    double pdf, eval[3];
    double err;                /* estimate of the pdf integral's error */
    long eval_without_pdf;     /* points where eval > 0 but pdf == 0 */
} cell_int;

/* Composite Simpson in (theta, phi) with n x n intervals over the cell
 * theta in [t0, t1] (dw = sin theta dtheta dphi), phi in [p0, p1]. */
static cell_int simpson_cell(const pbsdf *b, vec3 wo, double t0, double t1, double p0, double p1, int n)
{
    bool upper = t0 + t1 < M_PI;
    cell_int r = {0};
    double ht = (t1 - t0) / n, hp = (p1 - p0) / n;
    for (int i = 0; i <= n; i++) {
        double t = t0 + i * ht, wt = (i == 0 || i == n) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        double st = sin(t), ct = cos(t);
        /* keep the horizon row on the cell's own side: cos(acos(0)) is 6e-17 */
        if (upper ? ct < 0.0 : ct > 0.0) ct = 0.0;
        for (int j = 0; j <= n; j++) {
            double p = p0 + j * hp, wp = (j == 0 || j == n) ? 1.0 : (j & 1) ? 4.0 : 2.0;
            vec3 wi = v3((float)(st * cos(p)), (float)(st * sin(p)), upper ? (float)ct : -(float)fabs(ct));
            float pdf = pbsdf_pdf(b, wo, wi);
            vec3 e = pbsdf_eval(b, wo, wi);
            double w = wt * wp * st;
            r.pdf += w * (double)pdf;
            r.eval[0] += w * (double)e.x;
            r.eval[1] += w * (double)e.y;
            r.eval[2] += w * (double)e.z;
            if (!(pdf > 0.0f) && (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f)) r.eval_without_pdf++;
        }
    }
    double s = ht * hp / 9.0;
    r.pdf *= s;
    for (int c = 0; c < 3; c++) r.eval[c] *= s;
    return r;
}

/* The first resolution of the cell quadrature. A lobe without tails
 * (Beckmann's at small alpha, seen through a dielectric) can be narrower than
 * the first nodes' spacing and slip between them twice, which ends the
 * refinement with the peak unseen: such cases start finer. */
static int quad_n0 = 8;

/* Doubles the resolution until two successive estimates of the cell's
 * probability agree to within tol (or 512 x 512 intervals). */
static cell_int integrate_cell(const pbsdf *b, vec3 wo, int ci, int pi, double n_samples)
{
    double c0 = -1.0 + 2.0 * ci / N_THETA, c1 = -1.0 + 2.0 * (ci + 1) / N_THETA;
    double t0 = acos(c1), t1 = acos(c0);
    double p0 = 2.0 * M_PI * pi / N_PHI, p1 = 2.0 * M_PI * (pi + 1) / N_PHI;
    cell_int lo = simpson_cell(b, wo, t0, t1, p0, p1, quad_n0), hi = lo;
    for (int n = 2 * quad_n0; n <= 512; n *= 2) {
        hi = simpson_cell(b, wo, t0, t1, p0, p1, n);
        hi.eval_without_pdf += lo.eval_without_pdf;
        double err = fabs(hi.pdf - lo.pdf);
        /* an expected-count error of 0.05 standard deviations at most */
        double tol = 0.05 * sqrt(fmax(MIN_EXPECTED, n_samples * hi.pdf)) / n_samples;
        hi.err = err;
        if (err < tol) break;
        lo = hi;
    }
    return hi;
}

/* ---- one chi-square test ------------------------------------------------- */

typedef struct result {
    double chi2, pvalue;
    int dof;
    bool zero_cell_hit;        /* samples where the pdf integrates to 0 */
    double pdf_integral, pdf_err, eval_integral[3];
    double nondelta_frac;      /* sampled non-delta directions / all attempts */
    long weight_mismatch, pdf_mismatch, eval_without_pdf;
    double max_weight_rel;
} result;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static result chi2_test(const pbsdf *b, vec3 wo, uint64_t seed)
{
    static long obs[N_CELLS + 1];
    static double expct[N_CELLS + 1];
    result r = {0};
    memset(obs, 0, sizeof obs);
    prng g = prng_make(seed);
    long nondelta = 0;
    for (long s = 0; s < N_SAMPLES; s++) {
        float u[3] = {prng_f(&g), prng_f(&g), prng_f(&g)};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta) || delta) continue;
        nondelta++;
        float z = fminf(1.0f, fmaxf(-1.0f, wi.z));
        int ci = (int)((z + 1.0f) * 0.5f * N_THETA);
        if (ci >= N_THETA) ci = N_THETA - 1;
        double phi = atan2(wi.y, wi.x);
        if (phi < 0.0) phi += 2.0 * M_PI;
        int pi = (int)(phi / (2.0 * M_PI) * N_PHI);
        if (pi >= N_PHI) pi = N_PHI - 1;
        obs[ci * N_PHI + pi]++;
        /* the sample's own pdf and weight against pdf() and eval()/pdf() */
        float p2 = pbsdf_pdf(b, wo, wi);
        vec3 e = pbsdf_eval(b, wo, wi);
        if (!(fabsf(p2 - pdf) <= 1e-3f * fmaxf(p2, pdf) + 1e-6f)) r.pdf_mismatch++;
        float we[3] = {e.x / p2, e.y / p2, e.z / p2}, ws[3] = {w.x, w.y, w.z};
        for (int c = 0; c < 3; c++) {
            double rel = fabs((double)we[c] - (double)ws[c]) / fmax(1e-6, fabs((double)we[c]));
            if (rel > r.max_weight_rel) r.max_weight_rel = rel;
            if (!(fabsf(we[c] - ws[c]) <= 1e-3f * fabsf(we[c]) + 1e-6f)) {
                r.weight_mismatch++;
                break;
            }
        }
    }
    r.nondelta_frac = (double)nondelta / N_SAMPLES;
    obs[N_CELLS] = N_SAMPLES - nondelta;

    double total = 0.0, err = 0.0, ev[3] = {0, 0, 0};
    for (int ci = 0; ci < N_THETA; ci++)
        for (int pi = 0; pi < N_PHI; pi++) {
            cell_int c = integrate_cell(b, wo, ci, pi, N_SAMPLES);
            expct[ci * N_PHI + pi] = c.pdf * N_SAMPLES;
            total += c.pdf;
            err += c.err;
            for (int k = 0; k < 3; k++) ev[k] += c.eval[k];
            r.eval_without_pdf += c.eval_without_pdf;
        }
    r.pdf_integral = total;
    r.pdf_err = err;
    for (int k = 0; k < 3; k++) r.eval_integral[k] = ev[k];
    /* the last category: delta samples and failed ones */
    expct[N_CELLS] = fmax(0.0, 1.0 - total) * N_SAMPLES;

    /* Pool the cells with expected counts below MIN_EXPECTED, smallest first
     * (Mitsuba's chi2 test). */
    int idx[N_CELLS + 1];
    double key[N_CELLS + 1][2];
    for (int i = 0; i <= N_CELLS; i++) {
        key[i][0] = expct[i];
        key[i][1] = i;
    }
    qsort(key, N_CELLS + 1, sizeof key[0], cmp_double);
    for (int i = 0; i <= N_CELLS; i++) idx[i] = (int)key[i][1];
    double chi2 = 0.0, pool_exp = 0.0, pool_obs = 0.0;
    int dof = 0;
    for (int k = 0; k <= N_CELLS; k++) {
        int i = idx[k];
        if (expct[i] == 0.0 && obs[i] > 0) r.zero_cell_hit = true;
        if (expct[i] < MIN_EXPECTED || (pool_exp > 0.0 && pool_exp < MIN_EXPECTED)) {
            pool_exp += expct[i];
            pool_obs += obs[i];
        } else {
            double d = obs[i] - expct[i];
            chi2 += d * d / expct[i];
            dof++;
        }
    }
    if (pool_exp > 0.0) {
        double d = pool_obs - pool_exp;
        chi2 += d * d / pool_exp;
        dof++;
    }
    dof -= 1;
    r.chi2 = chi2;
    r.dof = dof;
    r.pvalue = dof > 0 ? chi2_pvalue(chi2, dof) : 1.0;
    return r;
}

/* ---- white furnace: mean and standard error of the sample weights ------- */

typedef struct furnace {
    double mean[3], se[3];
    double nondelta_mean[3], nondelta_se[3];
} furnace;

static furnace white_furnace(const pbsdf *b, vec3 wo, uint64_t seed)
{
    furnace f;
    memset(&f, 0, sizeof f);
    double s[3] = {0}, s2[3] = {0}, n1[3] = {0}, n2[3] = {0};
    prng g = prng_make(seed);
    for (long i = 0; i < N_FURNACE; i++) {
        float u[3] = {prng_f(&g), prng_f(&g), prng_f(&g)};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta)) continue;
        double v[3] = {w.x, w.y, w.z};
        for (int c = 0; c < 3; c++) {
            s[c] += v[c];
            s2[c] += v[c] * v[c];
            if (!delta) {
                n1[c] += v[c];
                n2[c] += v[c] * v[c];
            }
        }
    }
    for (int c = 0; c < 3; c++) {
        double m = s[c] / N_FURNACE, var = fmax(0.0, s2[c] / N_FURNACE - m * m);
        f.mean[c] = m;
        f.se[c] = sqrt(var / (N_FURNACE - 1));
        m = n1[c] / N_FURNACE;
        var = fmax(0.0, n2[c] / N_FURNACE - m * m);
        f.nondelta_mean[c] = m;
        f.nondelta_se[c] = sqrt(var / (N_FURNACE - 1));
    }
    return f;
}

/* ---- reciprocity: f(wo, wi) == f(wi, wo) for reflection ----------------- */

static void test_reciprocity(const bcase *bc, uint64_t seed)
{
    /* KHR_materials_clearcoat weights its layer by the view's Fresnel alone:
     * not reciprocal by its definition (test_metallic_roughness checks it
     * against that definition instead) */
    if (bc->b.type == PBSDF_METALLIC_ROUGHNESS && bc->b.coat > 0.0f) return;
    /* nor is the compensated dielectric's reflection: Turquin's factor 1 / E(wo) is of wo alone */
    if (bc->b.type == PBSDF_DIELECTRIC && (bc->b.flags & PBSDF_ENERGY)) return;
    prng g = prng_make(seed);
    int bad = 0;
    double worst = 0.0;
    for (int i = 0; i < 20000; i++) {
        /* uniform directions on the upper hemisphere; dielectrics: both sides */
        float sgn = (bc->b.type == PBSDF_DIELECTRIC && (i & 1)) ? -1.0f : 1.0f;
        vec3 d[2];
        for (int k = 0; k < 2; k++) {
            float z = fmaxf(1e-3f, prng_f(&g)), phi = 2.0f * PK_PI * prng_f(&g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            d[k] = v3(r * cosf(phi), r * sinf(phi), sgn * z);
        }
        vec3 a = pbsdf_eval(&bc->b, d[0], d[1]), b = pbsdf_eval(&bc->b, d[1], d[0]);
        if (bc->b.type == PBSDF_DIFFUSE_TRANSMISSION && (i & 1)) {
            /* the transmission: wi on the other side; a two-sided sheet */
            d[1].z = -d[1].z;
            a = pbsdf_eval(&bc->b, d[0], d[1]);
            b = pbsdf_eval(&bc->b, d[1], d[0]);
        }
        if (bc->b.type == PBSDF_METALLIC_ROUGHNESS && (i & 1)) {
            /* a thin sheet's transmission: wi below; from below, the frame
             * turns over (wo.z > 0 always), here by mirroring z */
            d[1].z = -d[1].z;
            a = pbsdf_eval(&bc->b, d[0], d[1]);
            b = pbsdf_eval(&bc->b, pbsdf__mirror_z(d[1]), pbsdf__mirror_z(d[0]));
        }
        float fa[3] = {a.x / fabsf(d[1].z), a.y / fabsf(d[1].z), a.z / fabsf(d[1].z)};
        float fb[3] = {b.x / fabsf(d[0].z), b.y / fabsf(d[0].z), b.z / fabsf(d[0].z)};
        for (int c = 0; c < 3; c++) {
            double diff = fabs((double)fa[c] - (double)fb[c]), scale = fmax(fabs((double)fa[c]), fabs((double)fb[c]));
            if (scale > 0.0 && diff / scale > worst) worst = diff / scale;
            if (diff > 2e-4 * scale + 1e-7) bad++;
        }
    }
    CHECKF(bad == 0, "%s: reciprocity fails for %d channel values (worst relative difference %.3g)", bc->name, bad,
           worst);
}

/* ---- glTF 2.0 metallic-roughness ------------------------------------------------ */

/* The specification's formulas, written out again here in double precision
 * (Appendix B; KHR_materials_transmission's thin-sheet lobe with the same
 * height-correlated visibility), f(wo, wi) |wi.z| for wo.z > 0. */
static double ref_d(double a, double nh)
{
    if (nh <= 0.0) return 0.0;
    double a2 = a * a, t = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (M_PI * t * t);
}
static double ref_vis(double a, double nl, double nv)
{
    double a2 = a * a;
    return 1.0 / (2.0 * (nv * sqrt(a2 + (1.0 - a2) * nl * nl) + nl * sqrt(a2 + (1.0 - a2) * nv * nv)));
}
static void ref_mr(vec3 base, double metal, double a, double trans, double ior, double coat, double coat_a, vec3 wo,
                   vec3 wi, double out[3])
{
    const double c[3] = {base.x, base.y, base.z};
    const double f0 = ((1.0 - ior) / (1.0 + ior)) * ((1.0 - ior) / (1.0 + ior));
    const bool below = wi.z < 0.0f;
    double l[3] = {wi.x, wi.y, below ? -wi.z : wi.z}, v[3] = {wo.x, wo.y, wo.z};
    double h[3] = {v[0] + l[0], v[1] + l[1], v[2] + l[2]};
    double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    for (int k = 0; k < 3; k++) h[k] /= hl;
    const double vh = fabs(v[0] * h[0] + v[1] * h[1] + v[2] * h[2]), w = pow(1.0 - vh, 5.0);
    const double spec = ref_d(a, h[2]) * ref_vis(a, l[2], v[2]);
    const double fd = f0 + (1.0 - f0) * w;
    for (int k = 0; k < 3; k++) {
        double dielectric, metal_brdf = 0.0;
        if (below) {
            dielectric = (1.0 - fd) * trans * spec * c[k];
        } else {
            dielectric = (1.0 - fd) * (1.0 - trans) * c[k] / M_PI + fd * spec;
            metal_brdf = (c[k] + (1.0 - c[k]) * w) * spec;
        }
        out[k] = ((1.0 - metal) * dielectric + metal * metal_brdf) * l[2];
        /* KHR_materials_clearcoat: mix(material, coat_brdf, coat Fc(N.V)) */
        const double fc = coat * (0.04 + 0.96 * pow(1.0 - v[2], 5.0));
        out[k] = (1.0 - fc) * out[k] + (below ? 0.0 : fc * ref_d(coat_a, h[2]) * ref_vis(coat_a, l[2], v[2]) * l[2]);
    }
}

/* Single-scattering albedo of GGX (F = 1) toward wo by quadrature. */
static double ref_ggx_albedo(double a, vec3 wo)
{
    const int nu = 800, np = 800;
    double sum = 0.0;
    for (int i = 0; i < nu; i++) {
        double z = (i + 0.5) / nu, r = sqrt(1.0 - z * z);
        for (int j = 0; j < np; j++) {
            double phi = 2.0 * M_PI * (j + 0.5) / np;
            double l[3] = {r * cos(phi), r * sin(phi), z}, h[3] = {(double)wo.x + l[0], (double)wo.y + l[1], (double)wo.z + l[2]};
            double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
            sum += ref_d(a, h[2] / hl) * ref_vis(a, z, wo.z) * z;
        }
    }
    return sum * (1.0 / nu) * (2.0 * M_PI / np);
}

static bool same3(vec3 a, vec3 b) { return memcmp(&a, &b, sizeof a) == 0; }

static void test_metallic_roughness(void)
{
    prng g = prng_make(21);
    /* eval against the specification's formulas */
    const struct { vec3 base; float m, a, t, ior, coat, coat_a; } p[] = {
        {{1.0f, 1.0f, 1.0f}, 0.0f, 0.3f, 0.0f, 1.5f, 0.0f, 0.0f},  {{0.9f, 0.5f, 0.2f}, 1.0f, 0.5f, 0.0f, 1.5f, 0.0f, 0.0f},
        {{0.9f, 0.5f, 0.2f}, 0.4f, 0.1f, 0.0f, 1.5f, 0.0f, 0.0f},  {{0.8f, 0.9f, 1.0f}, 0.0f, 0.6f, 1.0f, 1.5f, 0.0f, 0.0f},
        {{0.7f, 0.8f, 0.3f}, 0.3f, 0.25f, 0.6f, 1.33f, 0.0f, 0.0f}, {{0.2f, 0.4f, 0.6f}, 0.7f, 1.0f, 0.2f, 2.4f, 0.0f, 0.0f},
        {{0.9f, 0.2f, 0.1f}, 0.5f, 0.4f, 0.3f, 1.5f, 0.8f, 0.05f}, {{0.5f, 0.5f, 0.5f}, 1.0f, 0.7f, 0.0f, 1.5f, 1.0f, 0.3f},
    };
    for (size_t k = 0; k < sizeof p / sizeof p[0]; k++) {
        pbsdf b = pbsdf_with_clearcoat(pbsdf_metallic_roughness(p[k].base, p[k].m, p[k].a, p[k].t, p[k].ior), p[k].coat,
                                       p[k].coat_a);
        int bad = 0;
        double worst = 0.0;
        for (int i = 0; i < 20000; i++) {
            vec3 d[2];
            for (int j = 0; j < 2; j++) {
                float z = fmaxf(0.01f, prng_f(&g)), phi = 2.0f * PK_PI * prng_f(&g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
                d[j] = v3(r * cosf(phi), r * sinf(phi), z);
            }
            if (i & 1) d[1].z = -d[1].z; /* transmission */
            double want[3];
            ref_mr(p[k].base, p[k].m, p[k].a, p[k].t, p[k].ior, p[k].coat, p[k].coat_a, d[0], d[1], want);
            vec3 got = pbsdf_eval(&b, d[0], d[1]);
            const float gv[3] = {got.x, got.y, got.z};
            for (int c = 0; c < 3; c++) {
                double diff = fabs((double)gv[c] - want[c]);
                if (want[c] > 0.0 && diff / want[c] > worst) worst = diff / want[c];
                if (diff > 2e-4 * want[c] + 1e-6) bad++;
            }
        }
        CHECKF(bad == 0, "metallic-roughness case %zu: eval differs from the specification's formula at %d values "
               "(worst relative %.3g)", k, bad, worst);
    }

    /* metallic 1 is the Schlick conductor of F0 = base colour: the same bits */
    const float alphas[] = {0.0f, 0.05f, 0.3f, 1.0f};
    for (int k = 0; k < 4; k++) {
        const vec3 base = v3(0.95f, 0.64f, 0.54f);
        pbsdf mr = pbsdf_metallic_roughness(base, 1.0f, alphas[k], 0.0f, 1.5f);
        pbsdf co = pbsdf_conductor_schlick(base, alphas[k]);
        int diff_eval = 0, diff_pdf = 0, diff_dir = 0, diff_weight = 0;
        for (int i = 0; i < 20000; i++) {
            float z = fmaxf(1e-3f, prng_f(&g)), phi = 2.0f * PK_PI * prng_f(&g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            vec3 wo = v3(r * cosf(phi), r * sinf(phi), z);
            z = fmaxf(1e-3f, prng_f(&g)), phi = 2.0f * PK_PI * prng_f(&g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            vec3 wi = v3(r * cosf(phi), r * sinf(phi), z);
            diff_eval += !same3(pbsdf_eval(&mr, wo, wi), pbsdf_eval(&co, wo, wi));
            float pa = pbsdf_pdf(&mr, wo, wi), pb = pbsdf_pdf(&co, wo, wi);
            diff_pdf += memcmp(&pa, &pb, sizeof pa) != 0;
            const float u[3] = {prng_f(&g), prng_f(&g), prng_f(&g)};
            vec3 wa, wb, ca, cb;
            float qa, qb;
            bool da, db;
            bool oka = pbsdf_sample(&mr, wo, u, &wa, &ca, &qa, &da), okb = pbsdf_sample(&co, wo, u, &wb, &cb, &qb, &db);
            if (oka != okb || (oka && (!same3(wa, wb) || da != db || memcmp(&qa, &qb, sizeof qa) != 0))) {
                diff_dir++;
                continue;
            }
            if (oka && (da ? !same3(ca, cb) : v3_len(v3_sub(ca, cb)) > 1e-5f * v3_len(cb)))
                diff_weight++;
        }
        CHECKF(diff_eval == 0 && diff_pdf == 0 && diff_dir == 0 && diff_weight == 0,
               "metallic 1, alpha %g: not the Schlick conductor (eval %d, pdf %d, direction %d, weight %d differ)",
               (double)alphas[k], diff_eval, diff_pdf, diff_dir, diff_weight);
    }

    /* white furnace of the white metal: GGX's single-scattering loss */
    const float rough_a[] = {0.2f, 0.5f, 1.0f};
    const float thetas[] = {0.0f, 35.0f, 65.0f};
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) {
            vec3 wo = dir_from(thetas[j], 0.3f);
            pbsdf b = pbsdf_metallic_roughness(v3s(1.0f), 1.0f, rough_a[k], 0.0f, 1.5f);
            furnace f = white_furnace(&b, wo, 77u + (uint64_t)(3 * k + j));
            double want = ref_ggx_albedo(rough_a[k], wo);
            printf("  mr metal white a=%.2f theta_o=%4.1f  furnace %.4f +- %.4f, GGX albedo by quadrature %.4f\n",
                   (double)rough_a[k], (double)thetas[j], f.mean[1], f.se[1], want);
            CHECKF(fabs(f.mean[1] - want) <= 4.0 * f.se[1] + 2e-3, "metal white a=%g theta_o=%g: furnace %.5f, GGX %.5f",
                   (double)rough_a[k], (double)thetas[j], f.mean[1], want);
            CHECK(want < 1.0 && want > 0.3);
        }
    pbsdf smooth_metal = pbsdf_metallic_roughness(v3s(1.0f), 1.0f, 0.05f, 0.0f, 1.5f);
    furnace fs = white_furnace(&smooth_metal, dir_from(0.0f, 0.0f), 99u);
    CHECKF(fs.mean[1] > 0.99 && fs.mean[1] <= 1.0 + 4.0 * fs.se[1], "metal white a=0.05: furnace %.5f", fs.mean[1]);

    /* the white dielectric: energy <= 1 up to MR_ENERGY_MAX_THETA; beyond,
     * Appendix B's coupling reflects more than 1 (printed, for the docs) */
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++) {
            const float th = angles_out[j];
            pbsdf b = pbsdf_metallic_roughness(v3s(1.0f), 0.0f, alphas[k], 0.0f, 1.5f);
            furnace f = white_furnace(&b, dir_from(th, 0.3f), 131u + (uint64_t)(4 * k + j));
            printf("  mr dielectric white a=%.2f theta_o=%4.1f  furnace %.4f +- %.4f\n", (double)alphas[k], (double)th,
                   f.mean[1], f.se[1]);
            if (th <= MR_ENERGY_MAX_THETA)
                CHECKF(f.mean[1] <= 1.0 + 4.0 * f.se[1], "dielectric white a=%g theta_o=%g: furnace %.5f > 1",
                       (double)alphas[k], (double)th, f.mean[1]);
        }
    /* the thin sheet, smooth, white, all transmission: R + T = 1 exactly */
    pbsdf sheet = pbsdf_metallic_roughness(v3s(1.0f), 0.0f, 0.0f, 1.0f, 1.5f);
    for (int j = 0; j < 4; j++) {
        furnace f = white_furnace(&sheet, dir_from(angles_out[j], 0.3f), 171u + (uint64_t)j);
        CHECKF(fabs(f.mean[1] - 1.0) <= 1e-5, "smooth white sheet theta_o=%g: furnace %.6f", (double)angles_out[j],
               f.mean[1]);
    }
}

/* ---- driver ------------------------------------------------------------------ */

#define MAX_CASES 120
static bcase cases[MAX_CASES];
static int n_cases;

static void add_case(const char *name, float alpha, pbsdf b, bool lossless)
{
    REQUIRE(n_cases < MAX_CASES);
    bcase *c = &cases[n_cases++];
    if (alpha >= 0.0f)
        snprintf(c->name, sizeof c->name, "%s a=%.2f", name, (double)alpha);
    else
        snprintf(c->name, sizeof c->name, "%s", name);
    c->b = b;
    c->lossless = lossless;
    c->tol = 0.0;
}
/* The same BSDF with energy compensation (pbsdf_compensate). */
static void add_comp(const char *name, float alpha, pbsdf b)
{
    pbsdf_compensate(&b);
    REQUIRE(b.flags & PBSDF_ENERGY);
    add_case(name, alpha, b, false);
    cases[n_cases - 1].tol = 0.01;
}

static void build_cases(void)
{
    vec3 white = v3s(1.0f);
    add_case("diffuse white", -1.0f, pbsdf_diffuse(white), true);
    add_case("diffuse coloured", -1.0f, pbsdf_diffuse(v3(0.8f, 0.4f, 0.1f)), false);
    add_case("conductor smooth white", 0.0f, pbsdf_conductor_schlick(white, 0.0f), true);
    add_case("conductor smooth gold", 0.0f, pbsdf_conductor(v3(0.143f, 0.374f, 1.442f), v3(3.983f, 2.385f, 1.603f), 0.0f),
             false);
    add_case("dielectric smooth 1.5", 0.0f, pbsdf_dielectric(1.5f, 0.0f, white), true);
    add_case("plastic smooth", 0.0f, pbsdf_plastic(white, 1.5f, 0.0f), false);
    add_case("glossy smooth", 0.0f, pbsdf_glossy(v3s(0.5f), v3s(0.5f), 0.0f), false);
    for (int r = 0; r < 4; r++) {
        float a = roughs[r];
        add_case("conductor gold", a, pbsdf_conductor(v3(0.143f, 0.374f, 1.442f), v3(3.983f, 2.385f, 1.603f), a), false);
        add_case("conductor schlick white", a, pbsdf_conductor_schlick(white, a), false);
        add_case("dielectric 1.5", a, pbsdf_dielectric(1.5f, a, white), false);
        add_case("plastic white", a, pbsdf_plastic(white, 1.5f, a), false);
        add_case("glossy kd.5 ks.5", a, pbsdf_glossy(v3s(0.5f), v3s(0.5f), a), false);
    }
    /* glTF metallic-roughness: the dielectric, the metal, mixtures, the thin
     * sheet's transmission (KHR_materials_transmission) and another ior */
    add_case("mr smooth m.5 t.5", 0.0f, pbsdf_metallic_roughness(v3(0.9f, 0.6f, 0.3f), 0.5f, 0.0f, 0.5f, 1.5f), false);
    for (int r = 0; r < 4; r++) {
        float a = roughs[r];
        add_case("mr dielectric white", a, pbsdf_metallic_roughness(white, 0.0f, a, 0.0f, 1.5f), false);
        add_case("mr metal white", a, pbsdf_metallic_roughness(white, 1.0f, a, 0.0f, 1.5f), false);
        add_case("mr m.5 coloured", a, pbsdf_metallic_roughness(v3(0.9f, 0.5f, 0.2f), 0.5f, a, 0.0f, 1.5f), false);
        add_case("mr transmission t1", a, pbsdf_metallic_roughness(v3(0.8f, 0.9f, 1.0f), 0.0f, a, 1.0f, 1.5f), false);
        add_case("mr m.3 t.6 ior1.33", a, pbsdf_metallic_roughness(v3(0.7f, 0.8f, 0.3f), 0.3f, a, 0.6f, 1.33f), false);
        /* KHR_materials_clearcoat: a rough coat over a smooth base, the coat as rough as the base */
        add_case("mr coat .8 over smooth", a,
                 pbsdf_with_clearcoat(pbsdf_metallic_roughness(v3(0.9f, 0.2f, 0.1f), 0.5f, 0.0f, 0.3f, 1.5f), 0.8f, a),
                 false);
        add_case("mr coat 1 over m1", a,
                 pbsdf_with_clearcoat(pbsdf_metallic_roughness(v3(1.0f, 1.0f, 1.0f), 1.0f, a, 0.0f, 1.5f), 1.0f, a),
                 false);
    }
    add_case("mr smooth coat over rough", 0.0f,
             pbsdf_with_clearcoat(pbsdf_metallic_roughness(v3(0.2f, 0.6f, 0.9f), 0.0f, 0.3f, 0.0f, 1.5f), 1.0f, 0.0f),
             false);
    /* the Beckmann distribution (Mitsuba's default) for the conductor,
     * dielectric and plastic, sampled from the whole distribution */
    for (int r = 0; r < 4; r++) {
        float a = roughs[r];
        pbsdf g = pbsdf_conductor(v3(0.143f, 0.374f, 1.442f), v3(3.983f, 2.385f, 1.603f), a);
        g.flags |= PBSDF_BECKMANN;
        add_case("beckmann conductor gold", a, g, false);
        pbsdf d = pbsdf_dielectric(1.5f, a, white);
        d.flags |= PBSDF_BECKMANN;
        add_case("beckmann dielectric 1.5", a, d, false);
        pbsdf pl = pbsdf_plastic(v3(0.9f, 0.5f, 0.2f), 1.5f, a);
        pl.flags |= PBSDF_BECKMANN;
        add_case("beckmann plastic", a, pl, false);
    }
    {
        pbsdf w = pbsdf_conductor_schlick(white, 0.5f);
        w.flags |= PBSDF_BECKMANN;
        add_case("beckmann schlick white", 0.5f, w, false);
    }
    /* energy compensation (test_energy checks the energy; here the sampling, pdf and reciprocity) */
    for (int r = 2; r < 4; r++) {
        float a = roughs[r];
        add_comp("comp conductor gold", a, pbsdf_conductor(v3(0.143f, 0.374f, 1.442f), v3(3.983f, 2.385f, 1.603f), a));
        add_comp("comp schlick white", a, pbsdf_conductor_schlick(white, a));
        add_comp("comp dielectric 1.5", a, pbsdf_dielectric(1.5f, a, white));
        add_comp("comp plastic", a, pbsdf_plastic(v3(0.9f, 0.5f, 0.2f), 1.5f, a));
        add_comp("comp plastic black", a, pbsdf_plastic(v3s(0.0f), 1.5f, a));
        add_comp("comp mr metal white", a, pbsdf_metallic_roughness(white, 1.0f, a, 0.0f, 1.5f));
        add_comp("comp mr m.5 t.3 coloured", a, pbsdf_metallic_roughness(v3(0.9f, 0.5f, 0.2f), 0.5f, a, 0.3f, 1.5f));
        pbsdf g = pbsdf_conductor(v3(0.143f, 0.374f, 1.442f), v3(3.983f, 2.385f, 1.603f), a);
        g.flags |= PBSDF_BECKMANN;
        add_comp("comp beckmann gold", a, g);
        pbsdf d = pbsdf_dielectric(1.5f, a, white);
        d.flags |= PBSDF_BECKMANN;
        add_comp("comp beckmann dielectric", a, d);
    }
    /* MTL-style glossy with kd + ks = 1 in one channel, from an Ns */
    add_case("glossy mtl Ns=100", -1.0f, pbsdf_glossy_mtl(v3(0.7f, 0.2f, 0.1f), v3(0.3f, 0.3f, 0.3f), 100.0f), false);
    /* the thin sheet (delta lobes only), diffuse transmission (R + T = 1 per
     * channel is lossless on average), Oren-Nayar and the modified Phong */
    add_case("thin dielectric 1.5", -1.0f, pbsdf_thin_dielectric(1.5f, white), true);
    add_case("thin dielectric 1.33 tinted", -1.0f, pbsdf_thin_dielectric(1.33f, v3(0.9f, 0.5f, 0.2f)), false);
    add_case("diffuse transmission .25 .25", -1.0f, pbsdf_diffuse_transmission(v3s(0.25f), v3s(0.25f)), false);
    add_case("diffuse transmission sum 1", -1.0f,
             pbsdf_diffuse_transmission(v3(0.7f, 0.5f, 0.2f), v3(0.3f, 0.5f, 0.8f)), true);
    add_case("diffuse transmission t only", -1.0f, pbsdf_diffuse_transmission(v3s(0.0f), v3(0.9f, 0.6f, 0.3f)), false);
    add_case("oren-nayar s=0.2", -1.0f, pbsdf_oren_nayar(white, 0.2f), false);
    add_case("oren-nayar s=0.6", -1.0f, pbsdf_oren_nayar(v3(0.8f, 0.4f, 0.1f), 0.6f), false);
    add_case("oren-nayar s=1.5", -1.0f, pbsdf_oren_nayar(white, 1.5f), false);
    add_case("phong kd.5 ks.5 n10", -1.0f, pbsdf_phong(v3s(0.5f), v3s(0.5f), 10.0f), false);
    add_case("phong kd.2 ks.7 n100", -1.0f, pbsdf_phong(v3(0.2f, 0.1f, 0.0f), v3s(0.7f), 100.0f), false);
    add_case("phong ks1 n1", -1.0f, pbsdf_phong(v3s(0.0f), white, 1.0f), false);
}
/* Types whose wo may lie on either side (the cases' incident angles from
 * inside are tried for them too). */
static bool two_sided_type(int t)
{
    return t == PBSDF_DIELECTRIC || t == PBSDF_THIN_DIELECTRIC || t == PBSDF_DIFFUSE_TRANSMISSION;
}

/* Beckmann by quadrature: D is normalised (the integral of D(m) m.z over the
 * hemisphere is 1), and Smith's Lambda makes the visible normals' density
 * integrate to 1 (the integral of G1(w) max(0, w.m) D(m) / w.z is 1 for
 * every w); G1 agrees with the rational fit that Mitsuba uses for it. */
static void test_beckmann(void)
{
    const float as[] = {0.05f, 0.2f, 0.5f, 1.0f};
    for (int k = 0; k < 4; k++) {
        pbsdf b = pbsdf_conductor_schlick(v3s(1.0f), as[k]);
        b.flags |= PBSDF_BECKMANN;
        const int nt = 4000, np = 256;
        const double tmax = M_PI / 2;
        for (int o = 0; o < 4; o++) {
            vec3 w = dir_from(angles_out[o], 0.3f);
            double proj = 0.0, vis = 0.0;
            for (int i = 0; i < nt; i++) {
                double t = (i + 0.5) * tmax / nt, st = sin(t), ct = cos(t);
                for (int j = 0; j < np; j++) {
                    double ph = (j + 0.5) * 2.0 * M_PI / np;
                    vec3 m = v3((float)(st * cos(ph)), (float)(st * sin(ph)), (float)ct);
                    double dw = st * (tmax / nt) * (2.0 * M_PI / np), d = (double)pbsdf_mf_d(&b, m);
                    proj += d * ct * dw;
                    vis += d * fmax(0.0, (double)v3_dot(w, m)) * dw;
                }
            }
            double g1 = 1.0 / (1.0 + (double)pbsdf_mf_lambda(&b, w)), wz = (double)w.z;
            CHECKF(fabs(proj - 1.0) < 2e-3, "beckmann a=%g: integral of D cos = %.5f", (double)as[k], proj);
            CHECKF(fabs(g1 * vis / wz - 1.0) < 2e-3, "beckmann a=%g theta=%g: visible normals integrate to %.5f",
                   (double)as[k], (double)angles_out[o], g1 * vis / wz);
            /* Mitsuba's rational approximation of G1 (accurate to about 0.35 %) */
            double a = wz / ((double)as[k] * sqrt(1.0 - wz * wz)), fit = 1.0;
            if (a < 1.6) fit = (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
            CHECKF(fabs(g1 - fit) < 5e-3, "beckmann a=%g theta=%g: G1 %.5f, rational fit %.5f", (double)as[k],
                   (double)angles_out[o], g1, fit);
        }
    }
}

static void test_frame(void)
{
    prng g = prng_make(7);
    for (int i = 0; i < 10000; i++) {
        vec3 n;
        if (i < 4) {
            n = i == 0 ? v3(0, 0, 1) : i == 1 ? v3(0, 0, -1) : i == 2 ? v3(1, 0, 0) : v3(0, -1, 0);
        } else {
            float z = 2.0f * prng_f(&g) - 1.0f, phi = 2.0f * PK_PI * prng_f(&g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            n = v3(r * cosf(phi), r * sinf(phi), z);
        }
        onb f = onb_from_normal(n);
        CHECK(fabsf(v3_len(f.s) - 1.0f) < 1e-5f && fabsf(v3_len(f.t) - 1.0f) < 1e-5f);
        CHECK(fabsf(v3_dot(f.s, f.t)) < 1e-5f && fabsf(v3_dot(f.s, n)) < 1e-5f && fabsf(v3_dot(f.t, n)) < 1e-5f);
        CHECK(v3_len(v3_sub(v3_cross(f.s, f.t), n)) < 1e-5f);
        vec3 v = v3(prng_f(&g) - 0.5f, prng_f(&g) - 0.5f, prng_f(&g) - 0.5f);
        vec3 back = onb_to_world(f, onb_to_local(f, v));
        CHECK(v3_len(v3_sub(back, v)) < 1e-5f);
        CHECK(fabsf(onb_to_local(f, n).z - 1.0f) < 1e-5f);
    }
}

static void test_fresnel(void)
{
    /* normal incidence: ((n - 1) / (n + 1))^2, the same from both sides */
    CHECK_NEAR(pbsdf_fresnel_dielectric(1.0f, 1.5f), 0.04, 1e-6);
    CHECK_NEAR(pbsdf_fresnel_dielectric(-1.0f, 1.5f), 0.04, 1e-6);
    CHECK(pbsdf_fresnel_dielectric(-0.5f, 1.5f) == 1.0f); /* 60 degrees inside: beyond critical */
    CHECK_NEAR(pbsdf_fresnel_dielectric(0.0f, 1.5f), 1.0, 1e-6);
    /* conductor at normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2) */
    pbsdf g = pbsdf_conductor(v3(0.2f, 1.0f, 2.0f), v3(3.0f, 0.0f, 1.0f), 0.0f);
    vec3 f = pbsdf__fresnel_conductor(&g, 1.0f);
    CHECK_NEAR(f.x, (0.64 + 9.0) / (1.44 + 9.0), 1e-5);
    CHECK_NEAR(f.y, 0.0, 1e-6);
    CHECK_NEAR(f.z, (1.0 + 1.0) / (9.0 + 1.0), 1e-5);
    /* conductor with k = 0 is a dielectric */
    for (float c = 0.05f; c < 1.0f; c += 0.1f)
        CHECK_NEAR(pbsdf__fresnel_conductor1(c, 1.5f, 0.0f), pbsdf_fresnel_dielectric(c, 1.5f), 1e-5);
    /* at grazing incidence every interface reflects all (eta 1, k 0 was 0 / 0) */
    CHECK_NEAR(pbsdf__fresnel_conductor1(0.0f, 1.0f, 0.0f), 1.0, 1e-6);
    CHECK_NEAR(pbsdf__fresnel_conductor1(0.0f, 0.2f, 3.0f), 1.0, 1e-5);
    CHECK_NEAR(pbsdf__fresnel_conductor1(0.0f, 1.5f, 0.0f), 1.0, 1e-5);
    CHECK_NEAR(pbsdf_alpha_from_ns(0.0f), 1.0, 1e-6);
    CHECK_NEAR(pbsdf_alpha_from_ns(98.0f), sqrt(0.02), 1e-6);
}

int main(void)
{
    test_frame();
    test_fresnel();
    test_beckmann();
    test_metallic_roughness();
    build_cases();

    /* how many chi-square tests: the Sidak correction needs it up front */
    int n_tests = 0;
    for (int i = 0; i < n_cases; i++) {
        if (!pbsdf_has_nondelta(&cases[i].b)) continue;
        n_tests += 4 + (two_sided_type(cases[i].b.type) ? 3 : 0);
    }
    const double alpha_sig = 0.01;
    double threshold = 1.0 - pow(1.0 - alpha_sig, 1.0 / n_tests);
    printf("%d chi-square tests, %d samples each; per-test significance %.3g (Sidak, overall %.2f)\n", n_tests,
           N_SAMPLES, threshold, alpha_sig);

    double min_p = 1.0, sum_p = 0.0;
    int below_05 = 0, runs = 0;
    uint64_t seed = 1;
    for (int i = 0; i < n_cases; i++) {
        const bcase *bc = &cases[i];
        test_reciprocity(bc, 1000 + (uint64_t)i);
        int na = 4 + (two_sided_type(bc->b.type) ? 3 : 0);
        for (int k = 0; k < na; k++) {
            float th = k < 4 ? angles_out[k] : angles_in[k - 4];
            vec3 wo = dir_from(th, 0.7f);
            seed++;

            /* white furnace (non-white cases: each channel still <= 1) */
            furnace f = white_furnace(&bc->b, wo, seed * 7919u);
            const bool bounded = !(gains_at_grazing(&bc->b) && th > MR_ENERGY_MAX_THETA) &&
                                 !(bc->b.type == PBSDF_OREN_NAYAR && th > ON_ENERGY_MAX_THETA);
            for (int c = 0; c < 3; c++) {
                CHECKF(!bounded || f.mean[c] <= 1.0 + 4.0 * f.se[c] + 1e-6 + bc->tol, "%s theta_o=%g: furnace[%d] = %.6f +- %.2g > 1",
                       bc->name, (double)th, c, f.mean[c], f.se[c]);
                if (bc->lossless)
                    CHECKF(fabs(f.mean[c] - 1.0) <= 4.0 * f.se[c] + 1e-6,
                           "%s theta_o=%g: lossless furnace[%d] = %.6f +- %.2g", bc->name, (double)th, c,
                           f.mean[c], f.se[c]);
            }
            if (!pbsdf_has_nondelta(&bc->b)) {
                printf("  %-28s theta_o=%5.1f  furnace %.4f %.4f %.4f (delta only)\n", bc->name, (double)th,
                       f.mean[0], f.mean[1], f.mean[2]);
                continue;
            }

            quad_n0 = (bc->b.flags & PBSDF_BECKMANN) ? 32 : 8;
            result r = chi2_test(&bc->b, wo, seed);
            runs++;
            sum_p += r.pvalue;
            if (r.pvalue < min_p) min_p = r.pvalue;
            if (r.pvalue < 0.05) below_05++;
            printf("  %-28s theta_o=%5.1f  chi2=%8.2f dof=%3d p=%.4f  int pdf=%.5f (+-%.1e, sampled %.5f)"
                   "  furnace %.4f %.4f %.4f\n",
                   bc->name, (double)th, r.chi2, r.dof, r.pvalue, r.pdf_integral, r.pdf_err, r.nondelta_frac,
                   f.mean[0], f.mean[1], f.mean[2]);
            CHECKF(r.pvalue >= threshold, "%s theta_o=%g: chi2 %.2f, dof %d, p = %.3g < %.3g", bc->name, (double)th,
                   r.chi2, r.dof, r.pvalue, threshold);
            CHECKF(!r.zero_cell_hit, "%s theta_o=%g: samples in a cell where the pdf is 0", bc->name, (double)th);
            CHECKF(r.pdf_mismatch == 0, "%s theta_o=%g: %ld sampled pdfs differ from pdf()", bc->name, (double)th,
                   r.pdf_mismatch);
            CHECKF(r.weight_mismatch == 0, "%s theta_o=%g: %ld weights differ from eval/pdf (worst rel %.3g)",
                   bc->name, (double)th, r.weight_mismatch, r.max_weight_rel);
            CHECKF(r.eval_without_pdf == 0, "%s theta_o=%g: eval > 0 where pdf == 0 at %ld points", bc->name,
                   (double)th, r.eval_without_pdf);
            /* the pdf integrates to the share of non-delta samples (1 when
             * there are neither delta lobes nor failed samples) */
            double se = sqrt(fmax(r.nondelta_frac * (1.0 - r.nondelta_frac), 1e-12) / N_SAMPLES);
            double itol = 2.0 * r.pdf_err + 1e-4;
            CHECKF(fabs(r.pdf_integral - r.nondelta_frac) <= 4.0 * se + itol,
                   "%s theta_o=%g: pdf integrates to %.6f (+-%.2g), sampled non-delta share %.6f", bc->name,
                   (double)th, r.pdf_integral, itol, r.nondelta_frac);
            CHECKF(r.pdf_integral <= 1.0 + itol, "%s theta_o=%g: pdf integrates to %.6f > 1", bc->name, (double)th,
                   r.pdf_integral);
            if (bc->b.type == PBSDF_DIFFUSE)
                CHECKF(fabs(r.pdf_integral - 1.0) <= itol, "%s: pdf integrates to %.6f", bc->name, r.pdf_integral);
            /* energy by quadrature of eval (independent of the sampler), and
             * its agreement with the non-delta sample weights */
            for (int c = 0; c < 3; c++) {
                double qtol = 4.0 * f.nondelta_se[c] + 2e-3 * fmax(1.0, r.eval_integral[c]) + 1e-4;
                CHECKF(!bounded || r.eval_integral[c] <= 1.0 + 2e-3 + bc->tol, "%s theta_o=%g: integral of f cos [%d] = %.6f > 1",
                       bc->name, (double)th, c, r.eval_integral[c]);
                CHECKF(fabs(r.eval_integral[c] - f.nondelta_mean[c]) <= qtol,
                       "%s theta_o=%g: integral of f cos [%d] = %.6f, sampled %.6f +- %.2g", bc->name, (double)th,
                       c, r.eval_integral[c], f.nondelta_mean[c], f.nondelta_se[c]);
            }
        }
    }
    printf("%d chi-square tests: min p = %.4g, mean p = %.3f, %d below 0.05 (expected about %.1f)\n", runs, min_p,
           sum_p / runs, below_05, 0.05 * runs);
    return test_done("test_bsdf");
}

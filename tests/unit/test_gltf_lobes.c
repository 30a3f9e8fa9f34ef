/*
 * test_gltf_lobes.c - glTF's KHR_materials_specular, _sheen, _iridescence
 * and _anisotropy on the metallic-roughness BSDF (render/pbsdf.h's
 * pbsdf__gx_*, render/sheen.h) and in the glTF reader:
 *  - the BSDF against a reference written here in double precision from
 *    the specifications' formulas (fresnel_mix with weight and F0 colour,
 *    the Charlie sheen with its visibility and albedo scaling, Belcour and
 *    Barla's thin film, Burley's anisotropic GGX), and with default
 *    extension values against the plain model;
 *  - sampling against the pdf by a chi-square test per lobe, the sample
 *    weight against eval / pdf;
 *  - reciprocity, white furnace bounds;
 *  - the sheen's albedo table against its generator and an independent
 *    quadrature of the renderer's own lobe;
 *  - a glTF file with the four extensions and their textures: the
 *    parameters land in the material and its maps.
 */
#include "test.h"
#include "chi2.h"
#include "warnings.h"

#include "io/readers.h"
#include "render/sampling.h"
#include "render/shading.h"
#include "render/sheen_gen.h"
#include "scene/scene.h"

#include <stdint.h>

/* ---- materials ------------------------------------------------------------------ */

typedef struct mparams {
    vec3 base;
    float metal, rough, trans, ior, coat;
    float spec;
    vec3 spec_col, sheen;
    float sheen_r, irid, irid_ior, irid_d, aniso;
    bool comp; /* energy compensation (pbsdf_compensate), as glTF assets render */
    vec3 coat_n; /* the clearcoat's own normal (local; zero: none) */
} mparams;

static mparams plain(vec3 base, float metal, float rough) {
    mparams p = {base,      metal, rough, 0.0f, 1.5f,   0.0f, 1.0f, v3s(1.0f),
                 v3s(0.0f), 0.5f,  0.0f,  1.3f, 400.0f, 0.0f, false, v3s(0.0f)};
    return p;
}

/* The BSDF as the renderer makes it from a material record (shading.h). */
static pbsdf make(const mparams *p) {
    material m;
    material_init(&m);
    material_metallic_roughness(&m, p->base, p->metal, p->rough);
    m.transmission = p->trans;
    m.ni = p->ior;
    m.specular = p->spec, m.specular_color = p->spec_col;
    m.sheen_color = p->sheen, m.sheen_roughness = p->sheen_r;
    m.iridescence = p->irid, m.iridescence_ior = p->irid_ior, m.iridescence_thickness = p->irid_d;
    m.anisotropy = p->aniso;
    pbsdf b = pbsdf_metallic_roughness(p->base, p->metal, p->rough * p->rough, p->trans, p->ior);
    if (p->coat > 0.0f) b = pbsdf_with_clearcoat(b, p->coat, 0.09f);
    shading__gltf_ext(&b, &m);
    if (p->comp) pbsdf_compensate(&b);
    if (v3_len2(p->coat_n) > 0.0f) pbsdf_clearcoat_normal(&b, v3_norm(p->coat_n));
    return b;
}

typedef rng prng;
static prng prng_make(uint64_t seed) { return rng_seed(seed, 0x9e37); }
static float prng_f(prng *r) { return rng_float(r); }
static vec3 hemi(prng *g) {
    const float z = prng_f(g), r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * PK_PI * prng_f(g);
    return v3(r * cosf(phi), r * sinf(phi), fmaxf(z, 1e-3f));
}
static vec3 dir_deg(float theta, float phi) {
    const float t = theta * PK_PI / 180.0f;
    return v3(sinf(t) * cosf(phi), sinf(t) * sinf(phi), cosf(t));
}

/* ---- references in double precision ----------------------------------------------- */

typedef struct d3 {
    double v[3];
} d3;

static double schlick(double f0, double c) { return f0 + (1.0 - f0) * pow(1.0 - c, 5.0); }

/* Belcour and Barla's film as KHR_materials_iridescence writes it. */
static d3 ref_film(double outside, double film, double c1, double d, const double f0[3]) {
    d3 r;
    const double s2 = (outside / film) * (outside / film) * (1.0 - c1 * c1);
    if (1.0 - s2 < 0.0) {
        r.v[0] = r.v[1] = r.v[2] = 1.0;
        return r;
    }
    const double c2 = sqrt(1.0 - s2);
    const double R12 = schlick(pow((film - outside) / (film + outside), 2.0), c1), T121 = 1.0 - R12;
    const double phi12 = film < outside ? M_PI : 0.0, phi21 = M_PI - phi12;
    double R23[3], phi[3];
    for (int k = 0; k < 3; k++) {
        const double q = sqrt(fmin(fmax(f0[k], 0.0), 0.9999)), n3 = (1.0 + q) / (1.0 - q);
        R23[k] = schlick(pow((n3 - film) / (n3 + film), 2.0), c2);
        phi[k] = phi21 + (n3 < film ? M_PI : 0.0);
    }
    const double opd = 2.0 * film * d * c2;
    static const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13}, pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06},
                        var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
    double S[3][3]; /* [order][rgb] */
    for (int m = 1; m <= 2; m++) {
        const double ph = 2.0 * M_PI * m * opd * 1e-9;
        double xyz[3];
        for (int k = 0; k < 3; k++)
            xyz[k] = val[k] * sqrt(2.0 * M_PI * var[k]) * cos(pos[k] * ph + m * phi[k]) * exp(-ph * ph * var[k]);
        xyz[0] +=
            9.7470e-14 * sqrt(2.0 * M_PI * 4.5282e+09) * cos(2.2399e+06 * ph + m * phi[0]) * exp(-4.5282e+09 * ph * ph);
        for (int k = 0; k < 3; k++) xyz[k] /= 1.0685e-7;
        S[m][0] = 3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2];
        S[m][1] = -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2];
        S[m][2] = 0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2];
    }
    for (int k = 0; k < 3; k++) {
        const double R123 = fmin(fmax(R12 * R23[k], 1e-5), 0.9999), r123 = sqrt(R123);
        const double Rs = T121 * T121 * R23[k] / (1.0 - R123);
        double I = R12 + Rs, Cm = Rs - T121;
        for (int m = 1; m <= 2; m++) {
            Cm *= r123;
            I += Cm * 2.0 * S[m][k];
        }
        r.v[k] = fmax(I, 0.0);
    }
    return r;
}

static double ref_sheen_l(double x, double a) {
    const double t = (1.0 - a) * (1.0 - a);
    return (21.5473 * (1 - t) + 25.3245 * t) /
               (1.0 + (3.82987 * (1 - t) + 3.32435 * t) * pow(x, 0.19823 * (1 - t) + 0.16801 * t)) +
           (-1.97760 * (1 - t) - 1.27393 * t) * x + (-4.32054 * (1 - t) - 4.85967 * t);
}
static double ref_sheen_lambda(double c, double a) {
    return c < 0.5 ? exp(ref_sheen_l(c, a)) : exp(2.0 * ref_sheen_l(0.5, a) - ref_sheen_l(1.0 - c, a));
}

/* f cos of a material with the extensions, reflection (wo.z, wi.z > 0), no
 * clearcoat or compensation, x along the anisotropy's direction. */
static d3 ref_eval(const mparams *p, vec3 wo, vec3 wi) {
    const double rough = p->rough, aniso = p->aniso, ior = p->ior, spec_w = p->spec, irid = p->irid;
    const double irid_ior = p->irid_ior, irid_d = p->irid_d, trans = p->trans, metal = p->metal;
    const double ox = wo.x, oy = wo.y, oz = wo.z, ix = wi.x, iy = wi.y, iz = wi.z;
    double hx = ox + ix, hy = oy + iy, hz = oz + iz;
    const double hl = sqrt(hx * hx + hy * hy + hz * hz);
    hx /= hl, hy /= hl, hz /= hl;
    const double c = fabs(ox * hx + oy * hy + oz * hz);
    /* KHR_materials_anisotropy: alpha_t = mix(alpha, 1, s^2) along x, alpha_b = alpha */
    const double a = rough * rough, st = aniso;
    const double at = a + (1.0 - a) * st * st, ab = a;
    const double q = hx * hx / (at * at) + hy * hy / (ab * ab) + hz * hz;
    const double D = 1.0 / (M_PI * at * ab * q * q);
    const double lo = 0.5 * (sqrt(1.0 + (at * at * ox * ox + ab * ab * oy * oy) / (oz * oz)) - 1.0);
    const double li = 0.5 * (sqrt(1.0 + (at * at * ix * ix + ab * ab * iy * iy) / (iz * iz)) - 1.0);
    const double spec = D / (1.0 + lo + li) / (4.0 * oz); /* D G2 / (4 cos_o cos_i) * cos_i */
    /* KHR_materials_specular: Fd = spec (f0c + (1 - f0c) w) */
    const double r0 = pow((ior - 1.0) / (ior + 1.0), 2.0);
    const double sc[3] = {p->spec_col.x, p->spec_col.y, p->spec_col.z}, base[3] = {p->base.x, p->base.y, p->base.z};
    double f0c[3], Fd[3], Fm[3], sf0[3];
    for (int k = 0; k < 3; k++) {
        f0c[k] = fmin(r0 * sc[k], 1.0);
        sf0[k] = spec_w * f0c[k];
        Fd[k] = spec_w * schlick(f0c[k], c);
        Fm[k] = schlick(base[k], c);
    }
    if (irid > 0.0) { /* KHR_materials_iridescence */
        const d3 id = ref_film(1.0, irid_ior, c, irid_d, sf0), im = ref_film(1.0, irid_ior, c, irid_d, base);
        for (int k = 0; k < 3; k++) {
            Fd[k] += (id.v[k] - Fd[k]) * irid;
            Fm[k] += (im.v[k] - Fm[k]) * irid;
        }
    }
    const double fdmax = fmax(Fd[0], fmax(Fd[1], Fd[2]));
    /* KHR_materials_sheen */
    const double sh[3] = {p->sheen.x, p->sheen.y, p->sheen.z}, shmax = fmax(sh[0], fmax(sh[1], sh[2]));
    double scale = 1.0, shf = 0.0;
    if (shmax > 0.0) {
        const double r = fmax((double)p->sheen_r, (double)PK_SH_R_MIN), sa = r * r;
        scale = fmax(
            0.0, fmin(1.0 - shmax * (double)sheen_e((float)r, wo.z), 1.0 - shmax * (double)sheen_e((float)r, wi.z)));
        const double Ds = (2.0 + 1.0 / sa) * pow(1.0 - hz * hz, 0.5 / sa) / (2.0 * M_PI);
        shf = Ds / ((1.0 + ref_sheen_lambda(oz, sa) + ref_sheen_lambda(iz, sa)) * 4.0 * oz);
    }
    d3 out;
    for (int k = 0; k < 3; k++) {
        const double diel = (1.0 - fdmax) * (1.0 - trans) * base[k] * iz / M_PI + Fd[k] * spec;
        out.v[k] = ((1.0 - metal) * diel + metal * Fm[k] * spec) * scale + sh[k] * shf;
    }
    return out;
}

static bool close3(vec3 got, d3 want, double rel, double abs_tol) {
    const double g[3] = {got.x, got.y, got.z};
    for (int k = 0; k < 3; k++)
        if (!(fabs(g[k] - want.v[k]) <= rel * fabs(want.v[k]) + abs_tol)) return false;
    return true;
}

/* ---- the cases --------------------------------------------------------------------- */

typedef struct lcase {
    const char *name;
    mparams p;
} lcase;

static lcase cases[12];
static int ncases;

static void build_cases(void) {
    mparams p = plain(v3(0.8f, 0.5f, 0.3f), 0.0f, 0.5f);
    p.spec = 0.6f, p.spec_col = v3(1.5f, 0.6f, 0.2f);
    cases[ncases++] = (lcase){"specular", p};
    p = plain(v3(0.2f, 0.3f, 0.6f), 0.0f, 0.7f);
    p.sheen = v3(0.9f, 0.7f, 0.8f), p.sheen_r = 0.4f;
    cases[ncases++] = (lcase){"sheen", p};
    p = plain(v3(0.9f, 0.8f, 0.6f), 0.6f, 0.45f);
    p.irid = 0.8f, p.irid_d = 350.0f, p.irid_ior = 1.6f;
    cases[ncases++] = (lcase){"iridescence", p};
    p = plain(v3(0.95f, 0.9f, 0.85f), 1.0f, 0.4f);
    p.aniso = 0.7f;
    cases[ncases++] = (lcase){"anisotropy", p};
    p = plain(v3(0.7f, 0.6f, 0.5f), 0.2f, 0.5f);
    p.trans = 0.5f, p.spec = 0.8f, p.spec_col = v3(1.0f, 0.8f, 0.9f), p.sheen = v3s(0.5f), p.sheen_r = 0.8f;
    p.irid = 0.5f, p.aniso = 0.5f;
    cases[ncases++] = (lcase){"all, transmission", p};
    p.coat = 0.7f;
    cases[ncases++] = (lcase){"all, clearcoat", p};
    p.coat_n = v3(0.35f, -0.25f, 1.0f); /* glTF's clearcoatNormalTexture */
    cases[ncases++] = (lcase){"all, coat normal", p};
    p.coat = 0.0f, p.comp = true, p.coat_n = v3s(0.0f);
    cases[ncases++] = (lcase){"all, compensated", p};
    p = plain(v3(0.6f, 0.5f, 0.4f), 0.3f, 0.5f);
    p.coat = 0.8f, p.coat_n = v3(-0.4f, 0.2f, 1.0f);
    cases[ncases++] = (lcase){"coat normal, plain", p};
}

/* ---- formulas ---------------------------------------------------------------------- */

static void test_film(void) {
    const float cs[] = {1.0f, 0.8f, 0.5f, 0.2f, 0.05f}, ds[] = {0.0f, 120.0f, 300.0f, 550.0f, 900.0f};
    const float iors[] = {1.3f, 1.6f, 2.0f};
    const vec3 f0s[] = {v3s(0.04f), v3(0.95f, 0.64f, 0.54f), v3(0.2f, 0.6f, 0.9f)};
    int bad = 0;
    double worst = 0.0;
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 5; b++)
            for (int i = 0; i < 3; i++)
                for (int f = 0; f < 3; f++) {
                    const vec3 got = pbsdf_iridescence(1.0f, iors[i], cs[a], ds[b], f0s[f]);
                    const double f0[3] = {f0s[f].x, f0s[f].y, f0s[f].z};
                    d3 want;
                    if (ds[b] == 0.0f) /* no film: the base's Schlick Fresnel */
                        for (int k = 0; k < 3; k++) want.v[k] = schlick(f0[k], cs[a]);
                    else
                        want = ref_film(1.0, iors[i], cs[a], ds[b], f0);
                    const double g[3] = {got.x, got.y, got.z};
                    for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(g[k] - want.v[k]));
                    bad += !close3(got, want, 1e-4, 2e-5);
                }
    CHECKF(bad == 0, "thin film: %d of 225 settings differ from the reference (worst %.2e)", bad, worst);
    printf("  thin film vs reference: worst |difference| %.2e\n", worst);
    /* a thick film: the interference averages out over the spectrum, leaving
     * the incoherent sum of the two interfaces' reflections,
     * R12 + T121^2 R23 / (1 - R12 R23) */
    const double r12 = schlick(pow(0.3 / 2.3, 2.0), 0.6), n3 = (1.0 + sqrt(0.5)) / (1.0 - sqrt(0.5));
    const double c2 = sqrt(1.0 - (1.0 - 0.36) / (1.3 * 1.3)), r23 = schlick(pow((n3 - 1.3) / (n3 + 1.3), 2.0), c2);
    const vec3 g = pbsdf_iridescence(1.0f, 1.3f, 0.6f, 1e5f, v3s(0.5f));
    CHECK_NEAR(g.y, r12 + (1.0 - r12) * (1.0 - r12) * r23 / (1.0 - r12 * r23), 1e-5);
}

static void test_formulas(void) {
    prng g = prng_make(7);
    for (int c = 0; c < ncases; c++) {
        if (cases[c].p.coat > 0.0f || cases[c].p.comp) continue;
        const pbsdf b = make(&cases[c].p);
        CHECKF(b.flags & PBSDF_GLTF_EXT, "%s: not the extended model", cases[c].name);
        int bad = 0;
        double worst = 0.0;
        for (int i = 0; i < 2000; i++) {
            const vec3 wo = hemi(&g), wi = hemi(&g);
            const vec3 got = pbsdf_eval(&b, wo, wi);
            const d3 want = ref_eval(&cases[c].p, wo, wi);
            const double gv[3] = {got.x, got.y, got.z};
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(gv[k] - want.v[k]) / fmax(1e-3, fabs(want.v[k])));
            bad += !close3(got, want, 2e-3, 1e-5);
        }
        CHECKF(bad == 0, "%s: %d of 2000 evaluations differ from the reference (worst rel %.2e)", cases[c].name, bad,
               worst);
    }
    /* default extension values leave the plain model; forced through the
     * extended code they give what the plain code gives */
    mparams p = plain(v3(0.6f, 0.5f, 0.4f), 0.3f, 0.5f);
    p.trans = 0.4f, p.coat = 0.5f;
    pbsdf b = make(&p);
    CHECK(!(b.flags & PBSDF_GLTF_EXT));
    pbsdf x = b;
    x.flags |= PBSDF_GLTF_EXT;
    int bad = 0;
    for (int i = 0; i < 2000; i++) {
        vec3 wo = hemi(&g), wi = hemi(&g);
        if (i & 1) wi.z = -wi.z;
        const vec3 e0 = pbsdf_eval(&b, wo, wi), e1 = pbsdf_eval(&x, wo, wi);
        const float p0 = pbsdf_pdf(&b, wo, wi), p1 = pbsdf_pdf(&x, wo, wi);
        bad += !(fabsf(e0.x - e1.x) <= 1e-5f * e0.x + 1e-7f && fabsf(e0.z - e1.z) <= 1e-5f * e0.z + 1e-7f &&
                 fabsf(p0 - p1) <= 1e-5f * p0 + 1e-7f);
    }
    CHECKF(bad == 0, "plain values through the extended code: %d of 2000 differ", bad);

    /* the clearcoat's own normal cn: f = (1 - cw) f_under + cw D G2 / (4 cos_o), every cosine
     * about cn, cw = coat (0.04 + 0.96 (1 - wo.cn)^5) (the glTF sample renderer's coupling),
     * in double against the BSDF; f_under is the BSDF without the coat. A coat normal of +z
     * gives the plain coat. */
    for (int c = 0; c < ncases; c++) {
        const mparams *cp = &cases[c].p;
        if (!(v3_len2(cp->coat_n) > 0.0f)) continue;
        const pbsdf cb = make(cp);
        CHECKF(cb.flags & PBSDF_COAT_NORMAL, "%s: no coat normal", cases[c].name);
        mparams up = *cp;
        up.coat = 0.0f, up.coat_n = v3s(0.0f);
        const pbsdf under = make(&up);
        const vec3 cnf = v3_norm(cp->coat_n);
        const double cn[3] = {cnf.x, cnf.y, cnf.z}, a2 = 0.09 * 0.09;
        int nbad = 0, below = 0;
        for (int i = 0; i < 4000; i++) {
            const vec3 wo = hemi(&g), wi = hemi(&g);
            const double o[3] = {wo.x, wo.y, wo.z}, in[3] = {wi.x, wi.y, wi.z};
            double co = 0.0, ci = 0.0, h[3], hl = 0.0, ch = 0.0;
            for (int k = 0; k < 3; k++) co += o[k] * cn[k], ci += in[k] * cn[k], h[k] = o[k] + in[k];
            for (int k = 0; k < 3; k++) hl += h[k] * h[k];
            for (int k = 0; k < 3; k++) ch += h[k] / sqrt(hl) * cn[k];
            const double cw = (double)cp->coat * (0.04 + 0.96 * pow(1.0 - fmin(1.0, fmax(0.0, co)), 5.0));
            double lobe = 0.0;
            if (co > 0.0 && ci > 0.0) {
                const double dd = 1.0 + (a2 - 1.0) * ch * ch, D = a2 / (M_PI * dd * dd);
                const double lo = 0.5 * (sqrt(1.0 + a2 * (1.0 - co * co) / (co * co)) - 1.0);
                const double li = 0.5 * (sqrt(1.0 + a2 * (1.0 - ci * ci) / (ci * ci)) - 1.0);
                lobe = D / (1.0 + lo + li) / (4.0 * co);
            } else {
                below++;
            }
            const vec3 fu = pbsdf_eval(&under, wo, wi), got = pbsdf_eval(&cb, wo, wi);
            const double fuv[3] = {fu.x, fu.y, fu.z}, gv[3] = {got.x, got.y, got.z};
            for (int k = 0; k < 3; k++) {
                const double want = (1.0 - cw) * fuv[k] + cw * lobe;
                nbad += !(fabs(gv[k] - want) <= 2e-3 * fabs(want) + 1e-5);
            }
        }
        CHECKF(nbad == 0 && below > 0, "%s: %d of 12000 values differ from the coat-normal formula (%d pairs below "
               "the coat)", cases[c].name, nbad, below);
        /* cn = +z is the plain coat */
        mparams zp = *cp;
        zp.coat_n = v3(0.0f, 0.0f, 1.0f);
        mparams np = *cp;
        np.coat_n = v3s(0.0f);
        const pbsdf bz = make(&zp), bn = make(&np);
        int zbad = 0;
        for (int i = 0; i < 2000; i++) {
            const vec3 wo = hemi(&g), wi = hemi(&g);
            const vec3 e0 = pbsdf_eval(&bn, wo, wi), e1 = pbsdf_eval(&bz, wo, wi);
            const float p0 = pbsdf_pdf(&bn, wo, wi), p1 = pbsdf_pdf(&bz, wo, wi);
            zbad += !(fabsf(e0.x - e1.x) <= 1e-5f * e0.x + 1e-7f && fabsf(e0.z - e1.z) <= 1e-5f * e0.z + 1e-7f &&
                      fabsf(p0 - p1) <= 1e-5f * p0 + 1e-7f);
        }
        CHECKF(zbad == 0, "%s: a coat normal of +z differs from the plain coat for %d of 2000 pairs", cases[c].name,
               zbad);
    }
}

/* ---- chi-square of sampling against the pdf ------------------------------------------------- */

#define N_THETA 10
#define N_PHI 20
#define N_CELLS (N_THETA * N_PHI)
#define N_SAMPLES 100000
#define QUAD_N 64 /* (a clearcoat normal cuts its lobe off across cells: 32 was too coarse there) */
#define MIN_EXPECTED 5.0

static double cell_pdf(const pbsdf *b, vec3 wo, int ci, int pj) {
    const double c0 = -1.0 + 2.0 * ci / N_THETA, c1 = -1.0 + 2.0 * (ci + 1) / N_THETA;
    const double p0 = 2.0 * M_PI * pj / N_PHI, p1 = 2.0 * M_PI * (pj + 1) / N_PHI;
    const double hc = (c1 - c0) / QUAD_N, hp = (p1 - p0) / QUAD_N;
    double s = 0.0;
    for (int i = 0; i <= QUAD_N; i++) { /* Simpson in (cos theta, phi) */
        const double z = c0 + i * hc, wz = (i == 0 || i == QUAD_N) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        const double r = sqrt(fmax(0.0, 1.0 - z * z));
        for (int j = 0; j <= QUAD_N; j++) {
            const double ph = p0 + j * hp, wp = (j == 0 || j == QUAD_N) ? 1.0 : (j & 1) ? 4.0 : 2.0;
            vec3 wi = v3((float)(r * cos(ph)), (float)(r * sin(ph)), (float)z);
            if (z == 0.0) continue;
            s += wz * wp * (double)pbsdf_pdf(b, wo, wi);
        }
    }
    return s * hc * hp / 9.0;
}

static int cmp_pair(const void *a, const void *b) {
    const double x = ((const double *)a)[0], y = ((const double *)b)[0];
    return (x > y) - (x < y);
}

static void chi2_case(const char *name, const pbsdf *b, vec3 wo, uint64_t seed, double alpha) {
    static long obs[N_CELLS + 1];
    static double ex[N_CELLS + 1];
    memset(obs, 0, sizeof obs);
    prng g = prng_make(seed);
    long nondelta = 0, mismatch = 0;
    for (long s = 0; s < N_SAMPLES; s++) {
        const float u[3] = {prng_f(&g), prng_f(&g), prng_f(&g)};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta) || delta) continue;
        nondelta++;
        int ci = (int)((fminf(1.0f, fmaxf(-1.0f, wi.z)) + 1.0f) * 0.5f * N_THETA);
        if (ci >= N_THETA) ci = N_THETA - 1;
        double phi = atan2(wi.y, wi.x);
        if (phi < 0.0) phi += 2.0 * M_PI;
        int pj = (int)(phi / (2.0 * M_PI) * N_PHI);
        if (pj >= N_PHI) pj = N_PHI - 1;
        obs[ci * N_PHI + pj]++;
        const float p2 = pbsdf_pdf(b, wo, wi);
        const vec3 e = pbsdf_eval(b, wo, wi);
        if (!(fabsf(p2 - pdf) <= 1e-3f * p2 + 1e-6f) || !(fabsf(e.x / p2 - w.x) <= 1e-3f * w.x + 1e-6f) ||
            !(fabsf(e.z / p2 - w.z) <= 1e-3f * w.z + 1e-6f))
            mismatch++;
    }
    obs[N_CELLS] = N_SAMPLES - nondelta;
    double total = 0.0;
    for (int ci = 0; ci < N_THETA; ci++)
        for (int pj = 0; pj < N_PHI; pj++) {
            const double p = cell_pdf(b, wo, ci, pj);
            ex[ci * N_PHI + pj] = p * N_SAMPLES;
            total += p;
        }
    ex[N_CELLS] = fmax(0.0, 1.0 - total) * N_SAMPLES;
    /* cells expecting fewer than MIN_EXPECTED pooled, smallest first */
    double key[N_CELLS + 1][2];
    for (int i = 0; i <= N_CELLS; i++) key[i][0] = ex[i], key[i][1] = i;
    qsort(key, N_CELLS + 1, sizeof key[0], cmp_pair);
    double chi = 0.0, pe = 0.0, po = 0.0;
    int dof = 0;
    for (int k = 0; k <= N_CELLS; k++) {
        const int i = (int)key[k][1];
        if (ex[i] < MIN_EXPECTED || (pe > 0.0 && pe < MIN_EXPECTED)) {
            pe += ex[i], po += (double)obs[i];
        } else {
            const double d = (double)obs[i] - ex[i];
            chi += d * d / ex[i], dof++;
        }
    }
    if (pe > 0.0) chi += (po - pe) * (po - pe) / pe, dof++;
    dof--;
    const double pv = dof > 0 ? chi2_pvalue(chi, dof) : 1.0;
    printf("  %-20s theta_o %4.1f: chi2 %7.1f dof %3d p %.3f, pdf integral %.4f, sampled %.4f\n", name,
           (double)(acosf(wo.z) * 180.0f / PK_PI), chi, dof, pv, total, (double)nondelta / N_SAMPLES);
    CHECKF(pv > alpha, "%s: chi-square p = %.2e (chi2 %.1f, dof %d)", name, pv, chi, dof);
    CHECKF(mismatch == 0, "%s: %ld samples whose pdf or weight differ from pdf() and eval() / pdf()", name, mismatch);
    /* the lobes' samplers cover what is sampled: the density integrates to the non-delta share */
    const double share = (double)nondelta / N_SAMPLES, sd = sqrt(share * (1.0 - share) / N_SAMPLES);
    CHECKF(fabs(total - share) < 4.5 * sd + 2e-3, "%s: pdf integrates to %.4f, sampled share %.4f", name, total, share);
}

static void test_chi2(void) {
    const float th[] = {30.0f, 70.0f};
    const double alpha = 1e-3 / (2.0 * ncases); /* the family's false-alarm rate 1e-3 */
    for (int c = 0; c < ncases; c++) {
        const pbsdf b = make(&cases[c].p);
        for (int t = 0; t < 2; t++)
            chi2_case(cases[c].name, &b, dir_deg(th[t], 0.7f), 1000u + 17u * (unsigned)c + (unsigned)t, alpha);
    }
}

/* ---- reciprocity, white furnace ----------------------------------------------------- */

static void test_reciprocity(void) {
    prng g = prng_make(11);
    for (int c = 0; c < ncases; c++) {
        if (cases[c].p.coat > 0.0f) continue; /* the clearcoat weighs by the view's Fresnel alone */
        const pbsdf b = make(&cases[c].p);
        int bad = 0;
        for (int i = 0; i < 5000; i++) {
            const vec3 wo = hemi(&g), wi = hemi(&g);
            const vec3 a = v3_scale(pbsdf_eval(&b, wo, wi), wo.z), r = v3_scale(pbsdf_eval(&b, wi, wo), wi.z);
            bad += !(fabsf(a.x - r.x) <= 1e-4f * fmaxf(a.x, r.x) + 1e-7f &&
                     fabsf(a.y - r.y) <= 1e-4f * fmaxf(a.y, r.y) + 1e-7f &&
                     fabsf(a.z - r.z) <= 1e-4f * fmaxf(a.z, r.z) + 1e-7f);
        }
        CHECKF(bad == 0, "%s: f(wo, wi) != f(wi, wo) for %d of 5000 pairs", cases[c].name, bad);
    }
}

/* Mean sample weight toward wo and its standard error, per channel. */
static void albedo(const pbsdf *b, vec3 wo, long n, uint64_t seed, double m[3], double se[3]) {
    double s[3] = {0}, s2[3] = {0};
    prng g = prng_make(seed);
    for (long i = 0; i < n; i++) {
        const float u[3] = {prng_f(&g), prng_f(&g), prng_f(&g)};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta)) continue;
        const double v[3] = {w.x, w.y, w.z};
        for (int k = 0; k < 3; k++) s[k] += v[k], s2[k] += v[k] * v[k];
    }
    for (int k = 0; k < 3; k++) {
        m[k] = s[k] / n;
        se[k] = sqrt(fmax(0.0, s2[k] / n - m[k] * m[k]) / (n - 1));
    }
}

static void furnace(const char *name, const mparams *p, float max_theta) {
    /* compensation gives back light up to the tables' interpolation: 1 % (test_bsdf's tolerance) */
    const double tol = p->comp ? 0.01 : 0.0;
    const pbsdf b = make(p);
    double worst = 0.0;
    for (float th = 0.0f; th <= max_theta + 1e-3f; th += max_theta / 4.0f) {
        double m[3], se[3];
        albedo(&b, dir_deg(th, 0.3f), 40000, 77u + (unsigned)th, m, se);
        for (int k = 0; k < 3; k++) {
            worst = fmax(worst, m[k]);
            /* 4.5 standard errors: a false alarm below 1e-5 per test */
            CHECKF(m[k] <= 1.0 + tol + 4.5 * se[k], "%s at %.0f degrees: albedo %.4f +- %.4f exceeds 1", name,
                   (double)th, m[k], se[k]);
        }
    }
    printf("  furnace %-32s up to %2.0f degrees: largest albedo %.4f\n", name, (double)max_theta, worst);
}

static void test_furnace(void) {
    /* the dielectric's diffuse base under fresnel_mix gains toward grazing
     * (Appendix B, test_bsdf): bounded up to 40 degrees, as there */
    const float rs[] = {0.3f, 0.6f, 1.0f};
    for (int i = 0; i < 3; i++) {
        mparams p = plain(v3s(1.0f), 0.0f, 0.5f);
        p.sheen = v3s(1.0f), p.sheen_r = rs[i];
        char nm[64];
        snprintf(nm, sizeof nm, "white sheen %.1f, white base", (double)rs[i]);
        furnace(nm, &p, 40.0f);
        p.metal = 1.0f; /* over a white metal (no gain of its own): up to 80 degrees */
        snprintf(nm, sizeof nm, "white sheen %.1f, white metal", (double)rs[i]);
        furnace(nm, &p, 80.0f);
    }
    mparams p = plain(v3s(1.0f), 1.0f, 0.3f);
    p.aniso = 0.9f;
    furnace("anisotropic white metal", &p, 85.0f);
    p.comp = true, p.rough = 0.8f; /* compensated: up to the tables' 1 % */
    p.sheen = v3s(1.0f), p.sheen_r = 0.5f;
    furnace("compensated aniso metal + sheen", &p, 80.0f);
    p = plain(v3s(1.0f), 0.0f, 0.4f);
    p.spec_col = v3s(40.0f); /* F0 clamped to 1 */
    furnace("specular colour 40", &p, 40.0f);
    /* fresnel_mix's gain comes sooner with a film: its Fresnel rises and
     * falls with the angle, and the base is weighted by 1 - max3(F) at the
     * half vector of each pair of directions, not by the specular lobe's
     * albedo: bounded up to 20 degrees, measured beyond */
    p = plain(v3s(1.0f), 0.0f, 0.4f);
    p.irid = 1.0f, p.irid_d = 300.0f;
    furnace("iridescent white dielectric", &p, 20.0f);
    for (int t = 30; t <= 60; t += 30) {
        double m[3], se[3];
        const pbsdf b = make(&p);
        albedo(&b, dir_deg((float)t, 0.3f), 40000, 99u, m, se);
        printf("    (measured: at %d degrees %.4f %.4f %.4f)\n", t, m[0], m[1], m[2]);
    }
    p = plain(v3s(0.9f), 1.0f, 0.4f);
    p.irid = 1.0f, p.irid_d = 300.0f;
    furnace("iridescent 0.9 metal", &p, 80.0f);
    /* a clearcoat with a normal of its own over a white metal: the coat's
     * lobe about its normal and the base under 1 - coat Fc never add light */
    p = plain(v3s(1.0f), 1.0f, 0.3f);
    p.coat = 1.0f, p.coat_n = v3(0.4f, -0.3f, 1.0f);
    furnace("coat normal over white metal", &p, 80.0f);
}

/* ---- the sheen's albedo table ------------------------------------------------------------- */

static void test_sheen_table(void) {
    /* entries against the generator (sheen_gen.h) */
    const int rs[] = {0, 5, 13, 31}, ms[] = {0, 3, 16, 31};
    double worst = 0.0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j += 1) {
            if ((i + j) & 1) continue;
            const double e = sheen_gen_e(sheen_gen_r(rs[i]), sheen_gen_mu(ms[j]), SHEEN_GEN_N);
            worst = fmax(worst, fabs(e - (double)pk_sheen_e[rs[i]][ms[j]]));
        }
    CHECKF(worst < 2e-6, "sheen table: entries differ from the generator by up to %.2e", worst);
    /* an independent quadrature of the renderer's float lobe (midpoint in
     * theta and phi over the hemisphere) between the nodes, against the
     * bilinear lookup: the interpolation's error bounds the difference */
    const float rq[] = {0.33f, 0.55f, 0.8f}, mq[] = {0.2f, 0.45f, 0.77f, 0.95f};
    double wq = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) {
            const float a = rq[i] * rq[i], mu = mq[j];
            const vec3 wo = v3(sqrtf(1.0f - mu * mu), 0.0f, mu);
            const int nt = 400, np = 200;
            double s = 0.0;
            for (int t = 0; t < nt; t++) {
                const double th = 0.5 * M_PI * (t + 0.5) / nt;
                for (int q = 0; q < np; q++) {
                    const double ph = M_PI * (q + 0.5) / np;
                    const vec3 wi = v3((float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th));
                    s += (double)sheen_cos(a, wo, wi) * sin(th);
                }
            }
            s *= 2.0 * (0.5 * M_PI / nt) * (M_PI / np);
            const double e = sheen_e(rq[i], mu);
            wq = fmax(wq, fabs(s - e));
            CHECKF(fabs(s - e) < 0.01 * e + 1e-3, "sheen E(%.2f, r %.2f): table %.5f, quadrature %.5f", (double)mu,
                   (double)rq[i], e, s);
        }
    /* the lobe reflects at most what it receives, but toward grazing at low
     * roughness, where the fitted visibility lets it exceed 1 */
    double emax = 0.0;
    for (int r = 0; r < PK_SH_R; r++)
        for (int m = 4; m < PK_SH_MU; m++) emax = fmax(emax, pk_sheen_e[r][m]);
    CHECKF(emax <= 1.0, "sheen albedo %.4f above 1 at cos_o >= 0.13", emax);
    printf("  sheen table: generator within %.1e, quadrature between nodes within %.1e; E <= %.4f for cos_o >= 0.13, "
           "E(0.001, r %.2f) = %.3f\n",
           worst, wq, emax, (double)PK_SH_R_MIN, (double)pk_sheen_e[0][0]);
}

/* ---- the glTF reader -------------------------------------------------------------------- */

static char msg[1024];
static warning_log wlog;
/* A document of one triangle with uvs (texture 0: tex_rgbw.png) and the
 * given materials, the triangle's primitive of material 0, a second one of
 * material 1 when two. */
static void gltf_doc(char *j, size_t n, const char *materials, bool two) {
    const float pu[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1};
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const uint8_t *p = (const uint8_t *)pu;
    char uri[256], *q = uri;
    q += sprintf(q, "data:application/octet-stream;base64,");
    for (size_t i = 0; i < sizeof pu; i += 3) {
        const uint32_t w = (uint32_t)p[i] << 16 | (uint32_t)p[i + 1] << 8 | p[i + 2];
        *q++ = al[w >> 18 & 63], *q++ = al[w >> 12 & 63], *q++ = al[w >> 6 & 63], *q++ = al[w & 63];
    }
    *q = '\0';
    snprintf(j, n,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":60,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
             "\"images\":[{\"uri\":\"tex_rgbw.png\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[%s],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}%s]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             uri, materials, two ? ",{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1}" : "");
}

static pk_status load(const char *j, pk_scene **out) {
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_clear(&wlog);
    warning_log_attach(ctx, &wlog);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse_params(ctx, s, j, strlen(j), "t.gltf", PK_TEST_DATA, NULL, 0);
    if (st == PK_OK) st = scene_commit(ctx, s);
    snprintf(msg, sizeof msg, "%s", pk_context_error(ctx));
    if (st == PK_OK) {
        char why[256];
        CHECKF(scene_check(s, why, sizeof why), "%s", why);
        *out = s;
    } else {
        scene_destroy(s);
        *out = NULL;
    }
    pk_context_destroy(ctx);
    return st;
}

static void test_reader(void) {
    char j[4096];
    gltf_doc(j, sizeof j,
             "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.4,0.3,1],\"metallicFactor\":0,\"roughnessFactor\":0.6},"
             "\"extensions\":{"
             "\"KHR_materials_specular\":{\"specularFactor\":0.7,\"specularColorFactor\":[1.5,0.5,0.25],"
             "\"specularTexture\":{\"index\":0},\"specularColorTexture\":{\"index\":0}},"
             "\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.9,0.5,0.1],\"sheenRoughnessFactor\":0.35,"
             "\"sheenColorTexture\":{\"index\":0},\"sheenRoughnessTexture\":{\"index\":0}},"
             "\"KHR_materials_iridescence\":{\"iridescenceFactor\":0.8,\"iridescenceIor\":1.45,"
             "\"iridescenceThicknessMinimum\":150,\"iridescenceThicknessMaximum\":650,"
             "\"iridescenceTexture\":{\"index\":0},\"iridescenceThicknessTexture\":{\"index\":0}},"
             "\"KHR_materials_anisotropy\":{\"anisotropyStrength\":0.6,\"anisotropyRotation\":1.25,"
             "\"anisotropyTexture\":{\"index\":0}}}},"
             "{\"extensions\":{\"KHR_materials_specular\":{},\"KHR_materials_sheen\":{\"sheenColorTexture\":{\"index\":"
             "0}}}}",
             true);
    pk_scene *s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        REQUIRE(s->ntris == 2);
        const material *m = &s->materials[s->tris[0].material], *d = &s->materials[s->tris[1].material];
        CHECK(m->type == MAT_METALLIC_ROUGHNESS && m->specular == 0.7f);
        CHECK(m->specular_color.x == 1.5f && m->specular_color.y == 0.5f && m->specular_color.z == 0.25f);
        CHECK(m->sheen_color.x == 0.9f && m->sheen_color.z == 0.1f && m->sheen_roughness == 0.35f);
        CHECK(m->iridescence == 0.8f && m->iridescence_ior == 1.45f && m->iridescence_thickness_min == 150.0f &&
              m->iridescence_thickness == 650.0f);
        CHECK(m->anisotropy == 0.6f && m->anisotropy_rotation == 1.25f && material_anisotropic(m));
        const tex_ref *maps[7] = {&m->map_spec, &m->map_spec_color, &m->map_sheen, &m->map_sheen_rough,
                                  &m->map_irid, &m->map_irid_thick, &m->map_aniso};
        for (int k = 0; k < 7; k++) CHECKF(maps[k]->kind == TEX_IMAGE, "map %d of the extensions is missing", k);
        /* the colour textures decoded from sRGB, the others as data: two textures of one image */
        CHECK(m->map_spec_color.tex == m->map_sheen.tex && m->map_spec.tex == m->map_aniso.tex &&
              m->map_spec.tex != m->map_sheen.tex);
        CHECK(m->textured && s->has_textured);
        /* the Whitted approximation: the specular's F0 as the glossy weight, the sheen's mean albedo */
        CHECK_NEAR(m->ks.x, 0.7 * 0.04 * 1.5, 1e-6);
        CHECK(m->whitted_sheen > 0.0f && m->whitted_sheen < 1.0f);
        /* empty extensions: the plain model; a texture on a black sheen dropped */
        CHECK(d->specular == 1.0f && d->specular_color.y == 1.0f && d->sheen_color.x == 0.0f &&
              d->map_sheen.kind == TEX_NONE && !material_anisotropic(d));
        CHECKF(!warning_log_has(&wlog, "not supported"), "%s", wlog.all);
        scene_destroy(s);
    }
    /* bad values: an error naming the field */
    const char *bad[][2] = {
        {"\"KHR_materials_sheen\":{\"sheenColorFactor\":[2,0,0]}", "sheenColorFactor: 2 is outside [0, 1]"},
        {"\"KHR_materials_specular\":{\"specularColorFactor\":[1,-1,0]}", "specularColorFactor: -1 is negative"},
        {"\"KHR_materials_anisotropy\":{\"anisotropyStrength\":1.5}", "anisotropyStrength"},
        {"\"KHR_materials_iridescence\":{\"iridescenceIor\":0.5}", "iridescenceIor"},
        {"\"KHR_materials_sheen\":{\"sheenRoughnessTexture\":{\"index\":3}}", "sheenRoughnessTexture"},
    };
    for (int k = 0; k < 5; k++) {
        char mat[256];
        snprintf(mat, sizeof mat, "{\"extensions\":{%s}}", bad[k][0]);
        gltf_doc(j, sizeof j, mat, false);
        const pk_status st = load(j, &s);
        CHECKF(st != PK_OK && strstr(msg, bad[k][1]) && strstr(msg, "/materials/0/extensions/KHR_materials_"), "%s: %s",
               bad[k][0], msg);
        if (s) scene_destroy(s);
    }
}

int main(void) {
    build_cases();
    test_film();
    test_formulas();
    test_sheen_table();
    test_reciprocity();
    test_furnace();
    test_chi2();
    test_reader();
    return test_done("test_gltf_lobes");
}

/*
 * pbsdf.h - physically based BSDFs for the path tracer: Lambert, GGX
 * (or Beckmann) conductors, smooth and rough dielectrics (Walter et al. 2007), plastic (a
 * diffuse base under a dielectric coating), the MTL "glossy over diffuse"
 * model, glTF 2.0's metallic-roughness material, and (last) a thin dielectric
 * sheet, diffuse transmission, Oren-Nayar, the modified Phong model and
 * pbrt-v4's stochastic layered BSDF (coated: a dielectric coat over a
 * diffuse or conductor base, a scattering slab between). Plain static inline PK_HD C over one plain struct: no context, no
 * allocation, no function pointers, so that nvcc can compile the same code.
 * docs/materials.md describes the models, their parameters and conventions.
 *
 * Conventions (all functions):
 *  - Directions are unit vectors in the LOCAL shading frame (z = shading
 *    normal; math/frame.h converts), both pointing AWAY from the surface.
 *  - pbsdf_eval returns f(wo, wi) * |cos theta_i| (cos theta_i = wi.z), the
 *    non-delta part only; pbsdf_pdf is the solid-angle density of sampling wi
 *    (non-delta part only, 0 for directions only a delta lobe reaches).
 *  - Reflection-only types (diffuse, conductor, plastic, glossy) are one-sided:
 *    they scatter only for wo.z > 0 and wi.z > 0. A two-sided material is
 *    the caller's business (flip the frame so that wo.z > 0). The
 *    metallic-roughness type is a thin sheet: wo.z > 0 as for those, and wi
 *    below (wi.z < 0) where it transmits.
 *  - The thin dielectric and diffuse transmission are two-sided sheets: wo on
 *    either side, wi on its side (reflection) or the other (transmission).
 *    Oren-Nayar and Phong are one-sided reflectors like diffuse.
 *  - Coated is a two-sided reflector: wo below is mirrored to +z with wi.
 *    Its eval, pdf and sample weight are estimates (random walks seeded by
 *    the directions and the hit), so for it pbsdf_sample's weight is not
 *    pbsdf_eval / pbsdf_pdf but an estimate of the same mean.
 *  - Dielectrics are two-sided: wo.z < 0 means wo is inside (the side with
 *    index `ior`), and wi may lie on either side.
 *  - Transmitted light is not scaled by 1/eta^2 (the radiance compression at
 *    a refracting boundary), so that a lossless smooth dielectric has
 *    R + T = 1; for light that enters and leaves a closed object the factors
 *    cancel. An integrator that needs it can apply it.
 *  - Colours are linear RGB.
 */
#ifndef PK_PBSDF_H
#define PK_PBSDF_H

#include "../math/frame.h"
#include "../math/vec3.h"
#include "energy.h"
#include "optics.h"
#include "sampling.h"
#include "sheen.h"

#include <stdbool.h>

typedef enum pbsdf_type {
    PBSDF_DIFFUSE = 0,  /* Lambert: albedo */
    PBSDF_CONDUCTOR,    /* GGX metal: eta, k (or specular with PBSDF_SCHLICK), alpha */
    PBSDF_DIELECTRIC,   /* glass: ior, alpha, transmittance */
    PBSDF_PLASTIC,      /* diffuse albedo under a dielectric coating: ior, alpha */
    PBSDF_GLOSSY,       /* MTL Kd + Ks + Ns: albedo (kd) + specular (ks), alpha; no Fresnel */
    PBSDF_METALLIC_ROUGHNESS, /* glTF 2.0: albedo (base colour), metallic, alpha, transmission, ior */
    PBSDF_THIN_DIELECTRIC,    /* a smooth thin sheet: ior, transmittance (tint of what goes through) */
    PBSDF_DIFFUSE_TRANSMISSION, /* Lambert reflection (albedo) and transmission (transmittance) */
    PBSDF_OREN_NAYAR,         /* rough diffuse (Oren-Nayar's qualitative model): albedo, on_a, on_b */
    PBSDF_PHONG,              /* modified Phong: albedo (diffuse) + specular, exponent */
    PBSDF_COATED,             /* pbrt-v4's layered BSDF: a dielectric coat (ior, alpha) over a Lambertian
                                 (albedo) or conductor (PBSDF_COATED_METAL: eta, k, base_alpha) base, a slab
                                 (thickness, medium, g) between them, maxdepth, nsamples, seed */
    PBSDF_PRINCIPLED,         /* Mitsuba 3's principled: base colour (albedo), metallic, ... (pbsdf_principled) */
    PBSDF_PRINCIPLED_THIN,    /* Mitsuba 3's principledthin: a thin sheet (pbsdf_principled_thin) */
    PBSDF_TYPE_COUNT
} pbsdf_type;

/* flags */
#define PBSDF_SCHLICK 1u /* conductor: Schlick's Fresnel with F0 = specular, not eta/k */
/* conductor, dielectric, plastic: the Beckmann distribution of slopes
 * instead of GGX (the same alpha: the RMS slope of the microfacets) */
#define PBSDF_BECKMANN 2u
/* energy compensation of the rough lobes (pbsdf_compensate sets it) */
#define PBSDF_ENERGY 4u
/* conductor, dielectric, plastic: anisotropic roughness, alpha along the
 * local x axis (the surface's tangent, dp/du) and alpha_v along y
 * (pbsdf_anisotropic sets it) */
#define PBSDF_ANISO 8u
/* coated: the base is a conductor (eta, k relative to the coat, base_alpha), not Lambert */
#define PBSDF_COATED_METAL 16u
/* metallic-roughness: the surface bounds a volume (KHR_materials_volume):
 * its transmission refracts (a rough dielectric of ior and alpha) instead
 * of passing straight through a thin sheet, and wo may lie inside (wo.z <
 * 0, the frame's z the outward normal) */
#define PBSDF_MR_VOLUME 32u
/* metallic-roughness: glTF's KHR_materials_specular, _sheen, _iridescence
 * or _anisotropy (the gx_ fields, PBSDF_ANISO) are in use (pbsdf_gltf_ext):
 * pbsdf__gx_* evaluate it (the plain model's code is left as it was) */
#define PBSDF_GLTF_EXT 64u
/* metallic-roughness: the clearcoat has a normal of its own (glTF's
 * clearcoatNormalTexture), coat_n in the local frame (pbsdf_clearcoat_normal) */
#define PBSDF_COAT_NORMAL 128u

/* Below this roughness a microfacet lobe is treated as perfectly smooth (a
 * delta lobe): the GGX density would exceed float range long before 0. */
#define PBSDF_ALPHA_SMOOTH 1e-3f

/* One BSDF instance. Fields a type does not use are ignored.
 * Valid ranges (the constructors below do not clamp; the scene's material
 * mapping must):
 *   albedo        [0, 1] per channel       diffuse, plastic; glossy (kd)
 *   specular      [0, 1] per channel       glossy (ks, with albedo + specular <= 1
 *                                          per channel), conductor F0 with PBSDF_SCHLICK
 *   tint          [0, 1] per channel       conductor: a factor on the Fresnel reflectance
 *                                          (Mitsuba's specular_reflectance); 1 by default
 *   eta, k        eta > 0, k >= 0          conductor: complex index of the metal
 *                                          relative to the outside medium, per channel
 *   transmittance [0, 1] per channel       dielectric: tint of refracted light (MTL Tf)
 *   alpha         [0, 1]                   GGX roughness (alpha = perceptual roughness^2);
 *                                          < PBSDF_ALPHA_SMOOTH: smooth (delta lobes)
 *   alpha_v       [0, 1]                   with PBSDF_ANISO: the roughness along local y
 *                                          (alpha is then the one along x)
 *   ior           > 0, != 1 for dielectric dielectric, plastic: inside / outside index;
 *                                          metallic-roughness: the dielectric's Fresnel
 *                                          (Schlick, F0 = ((ior - 1) / (ior + 1))^2)
 *   metallic      [0, 1]                   metallic-roughness: the metal's share
 *   transmission  [0, 1]                   metallic-roughness: the share of the dielectric's
 *                                          base that is transmitted rather than diffuse
 *   coat          [0, 1]                   metallic-roughness: the clearcoat's weight
 *   coat_alpha    [0, 1]                   metallic-roughness: the clearcoat's GGX alpha
 *   gx_spec, gx_spec_color  [0, 1], >= 0   metallic-roughness (KHR_materials_specular): the
 *                                          dielectric's specular weight and F0 colour
 *   gx_sheen, gx_sheen_r    [0, 1]         (KHR_materials_sheen) the sheen's colour and roughness
 *   gx_irid, gx_irid_ior, gx_irid_d        (KHR_materials_iridescence) the film's strength in
 *                                          [0, 1], index (> 0) and thickness in nm (>= 0)
 *   ms, ms_albedo                          set by pbsdf_compensate (the multiple-scattering lobe)
 *   on_a, on_b    A, B >= 0                Oren-Nayar: the model's A and B (pbsdf_oren_nayar)
 *   exponent      >= 0                     Phong: the lobe's exponent
 *   thickness     > 0                      coated: the slab's optical thickness (unit extinction)
 *   medium        [0, 1] per channel       coated: the slab medium's single-scattering albedo (0 = clear)
 *   g             (-1, 1)                  coated: the medium's Henyey-Greenstein asymmetry
 *   base_alpha    [0, 1]                   coated: the conductor base's GGX alpha
 *   maxdepth      >= 1                     coated: the longest random walk in the slab
 *   nsamples      >= 1                     coated: walks averaged per estimate
 *   seed                                   coated: a hash of the hit, mixed into the walks' seeds */
typedef struct pbsdf {
    int type;            /* pbsdf_type */
    unsigned flags;      /* PBSDF_SCHLICK, PBSDF_BECKMANN, PBSDF_ENERGY */
    vec3 albedo;
    vec3 specular;
    vec3 tint;
    vec3 eta, k;
    vec3 transmittance;
    float alpha;
    float alpha_v;       /* with PBSDF_ANISO */
    float ior;
    float metallic, transmission;
    float coat, coat_alpha;
    vec3 coat_n;         /* with PBSDF_COAT_NORMAL: the clearcoat's unit normal, local, z > 0 */
    vec3 gx_spec_color, gx_sheen;
    float gx_spec, gx_sheen_r, gx_irid, gx_irid_ior, gx_irid_d;
    vec3 ms;             /* F_ms / (pi (1 - E_avg)) per channel, with PBSDF_ENERGY */
    float ms_albedo;     /* the mean of F_ms: the lobe's albedo is ms_albedo (1 - E(wo.z)) */
    float on_a, on_b, exponent;
    vec3 medium;
    float thickness, g, base_alpha;
    int maxdepth, nsamples;
    unsigned seed;
    /* principled (pbsdf_principled): the perceptual roughness (the diffuse
     * lobe's), spec_tint, sheen, sheen_tint, flatness in [0, 1], and the
     * sampling rates of the main specular, clearcoat and diffuse lobes */
    float roughness, pr_spec_tint, pr_sheen, pr_sheen_tint, pr_flatness;
    float pr_srate_spec, pr_srate_cc, pr_srate_diff;
    /* principledthin: diff_trans in [0, 1] (Mitsuba's / 2), the GGX alphas
     * of the transmission lobe (of the roughness scaled by 0.65 eta - 0.35)
     * and the sampling rates of the specular and diffuse transmission */
    float pr_diff_trans, pr_tax, pr_tay, pr_srate_st, pr_srate_dt;
} pbsdf;

/* The layered and principled BSDFs are large: on the GPU they are called,
 * not inlined into every kernel that shades (inlined, ptxas spent tens of
 * minutes on the path kernels); on the CPU the compiler decides. */
#ifdef __CUDA_ARCH__
#define PBSDF_CALLED __noinline__
#else
#define PBSDF_CALLED
#endif

/* ---- constructors ------------------------------------------------------- */

static inline PK_HD pbsdf pbsdf__blank(int type)
{
    pbsdf b;
    b.type = type;
    b.flags = 0;
    b.albedo = b.specular = b.transmittance = v3s(0.0f);
    b.tint = v3s(1.0f);
    b.eta = v3s(1.0f);
    b.k = v3s(0.0f);
    b.alpha = b.alpha_v = 0.0f;
    b.ior = 1.5f;
    b.metallic = b.transmission = 0.0f;
    b.coat = b.coat_alpha = 0.0f;
    b.coat_n = v3(0.0f, 0.0f, 1.0f);
    b.gx_spec_color = v3s(1.0f), b.gx_sheen = v3s(0.0f);
    b.gx_spec = 1.0f, b.gx_sheen_r = 0.5f, b.gx_irid = 0.0f, b.gx_irid_ior = 1.3f, b.gx_irid_d = 0.0f;
    b.ms = v3s(0.0f);
    b.ms_albedo = 0.0f;
    b.on_a = 1.0f, b.on_b = b.exponent = 0.0f;
    b.medium = v3s(0.0f);
    b.thickness = 0.01f, b.g = 0.0f, b.base_alpha = 0.0f;
    b.maxdepth = 10, b.nsamples = 1;
    b.seed = 0u;
    b.roughness = b.pr_spec_tint = b.pr_sheen = b.pr_sheen_tint = b.pr_flatness = 0.0f;
    b.pr_srate_spec = b.pr_srate_cc = b.pr_srate_diff = 1.0f;
    b.pr_diff_trans = b.pr_tax = b.pr_tay = 0.0f;
    b.pr_srate_st = b.pr_srate_dt = 1.0f;
    return b;
}
static inline PK_HD pbsdf pbsdf_diffuse(vec3 albedo)
{
    pbsdf b = pbsdf__blank(PBSDF_DIFFUSE);
    b.albedo = albedo;
    return b;
}
static inline PK_HD pbsdf pbsdf_conductor(vec3 eta, vec3 k, float alpha)
{
    pbsdf b = pbsdf__blank(PBSDF_CONDUCTOR);
    b.eta = eta;
    b.k = k;
    b.alpha = alpha;
    return b;
}
static inline PK_HD pbsdf pbsdf_conductor_schlick(vec3 f0, float alpha)
{
    pbsdf b = pbsdf__blank(PBSDF_CONDUCTOR);
    b.flags = PBSDF_SCHLICK;
    b.specular = f0;
    b.alpha = alpha;
    return b;
}
static inline PK_HD pbsdf pbsdf_dielectric(float ior, float alpha, vec3 transmittance)
{
    pbsdf b = pbsdf__blank(PBSDF_DIELECTRIC);
    b.ior = ior;
    b.alpha = alpha;
    b.transmittance = transmittance;
    return b;
}
static inline PK_HD pbsdf pbsdf_plastic(vec3 albedo, float ior, float alpha)
{
    pbsdf b = pbsdf__blank(PBSDF_PLASTIC);
    b.albedo = albedo;
    b.ior = ior;
    b.alpha = alpha;
    return b;
}
static inline PK_HD pbsdf pbsdf_glossy(vec3 kd, vec3 ks, float alpha)
{
    pbsdf b = pbsdf__blank(PBSDF_GLOSSY);
    b.albedo = kd;
    b.specular = ks;
    b.alpha = alpha;
    return b;
}
/* glTF 2.0's metallic-roughness material: base colour, metallic, GGX alpha
 * (the glTF roughness squared), transmission (KHR_materials_transmission)
 * and the dielectric's ior (KHR_materials_ior). */
static inline PK_HD pbsdf pbsdf_metallic_roughness(vec3 base_color, float metallic, float alpha, float transmission,
                                                   float ior)
{
    pbsdf b = pbsdf__blank(PBSDF_METALLIC_ROUGHNESS);
    b.albedo = base_color;
    b.metallic = metallic;
    b.alpha = alpha;
    b.transmission = transmission;
    b.ior = ior;
    return b;
}
/* KHR_materials_clearcoat over a metallic-roughness BSDF: a clear layer of
 * ior 1.5 and GGX alpha coat_alpha (the clearcoat roughness squared) with
 * weight coat. */
static inline PK_HD pbsdf pbsdf_with_clearcoat(pbsdf b, float coat, float coat_alpha)
{
    b.coat = coat;
    b.coat_alpha = coat_alpha;
    return b;
}
/* The clearcoat's own unit normal n, in b's local frame (PBSDF_COAT_NORMAL);
 * one at or below the surface's horizon is not used. */
static inline PK_HD void pbsdf_clearcoat_normal(pbsdf *b, vec3 n)
{
    if (!(n.z > 1e-4f) || !v3_finite(n)) return;
    b->coat_n = n;
    b->flags |= PBSDF_COAT_NORMAL;
}
/* Marks a metallic-roughness b whose glTF extension fields (gx_: specular,
 * sheen, iridescence) or anisotropy (pbsdf_anisotropic, after it) differ
 * from the plain model's, so that the extended model evaluates it. */
static inline PK_HD void pbsdf_gltf_ext(pbsdf *b)
{
    if (b->type != PBSDF_METALLIC_ROUGHNESS || (b->flags & PBSDF_MR_VOLUME)) return; /* a volume's: without them */
    if (b->gx_spec != 1.0f || b->gx_spec_color.x != 1.0f || b->gx_spec_color.y != 1.0f ||
        b->gx_spec_color.z != 1.0f || b->gx_sheen.x > 0.0f || b->gx_sheen.y > 0.0f || b->gx_sheen.z > 0.0f ||
        b->gx_irid > 0.0f || (b->flags & PBSDF_ANISO))
        b->flags |= PBSDF_GLTF_EXT;
}
/* Anisotropic roughness for a conductor, dielectric or plastic b made with
 * alpha (the roughness along the local x axis, the surface's tangent):
 * alpha_v along y. alpha_v < 0 or equal to alpha leaves b isotropic. A lobe
 * rough in one direction is at least PBSDF_ALPHA_SMOOTH in the other (the
 * density would overflow as one roughness goes to 0). */
static inline PK_HD void pbsdf_anisotropic(pbsdf *b, float alpha_v)
{
    if (!(alpha_v >= 0.0f) || alpha_v == b->alpha) return;
    b->alpha_v = alpha_v;
    b->flags |= PBSDF_ANISO;
    if (fmaxf(b->alpha, alpha_v) >= PBSDF_ALPHA_SMOOTH) {
        b->alpha = fmaxf(b->alpha, PBSDF_ALPHA_SMOOTH);
        b->alpha_v = fmaxf(b->alpha_v, PBSDF_ALPHA_SMOOTH);
    }
}
/* GGX roughness for an MTL Phong exponent: alpha = sqrt(2 / (Ns + 2)). */
static inline PK_HD float pbsdf_alpha_from_ns(float ns)
{
    return sqrtf(2.0f / (fmaxf(ns, 0.0f) + 2.0f));
}
/* MTL Kd, Ks, Ns -> glossy over diffuse. Where Kd + Ks > 1 in a channel both
 * are scaled down in that channel so that the pair conserves energy. */
static inline PK_HD pbsdf pbsdf_glossy_mtl(vec3 kd, vec3 ks, float ns)
{
    float *d[3] = {&kd.x, &kd.y, &kd.z}, *s[3] = {&ks.x, &ks.y, &ks.z};
    for (int c = 0; c < 3; c++) {
        float sum = *d[c] + *s[c];
        if (sum > 1.0f) {
            *d[c] /= sum;
            *s[c] /= sum;
        }
    }
    return pbsdf_glossy(kd, ks, pbsdf_alpha_from_ns(ns));
}

/* ---- Fresnel ------------------------------------------------------------ */

/* Unpolarised Fresnel reflectance of a dielectric boundary; cos_i is the
 * cosine to the normal on the side wo is on: cos_i >= 0 means outside
 * (relative index eta = inside / outside), cos_i < 0 inside. 1 under total
 * internal reflection. The Fresnel equations are optics.h's; only cos_t is
 * found here (see fresnel_dielectric there for why it is not shared). */
static inline PK_HD float pbsdf_fresnel_dielectric(float cos_i, float eta)
{
    cos_i = fminf(1.0f, fmaxf(-1.0f, cos_i));
    if (cos_i < 0.0f) {
        eta = 1.0f / eta;
        cos_i = -cos_i;
    }
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin2_t));
    return fresnel_equations(cos_i, cos_t, 1.0f, eta);
}

/* Fresnel reflectance of a conductor with complex index eta + i k (relative
 * to the outside), unpolarised, one channel; cos_i in [0, 1]. */
static inline PK_HD float pbsdf__fresnel_conductor1(float cos_i, float eta, float k)
{
    cos_i = fminf(1.0f, fmaxf(0.0f, cos_i));
    float cos2 = cos_i * cos_i, sin2 = 1.0f - cos2;
    float eta2 = eta * eta, k2 = k * k;
    float t0 = eta2 - k2 - sin2;
    float a2b2 = sqrtf(fmaxf(0.0f, t0 * t0 + 4.0f * eta2 * k2));
    float t1 = a2b2 + cos2;
    float a = sqrtf(fmaxf(0.0f, 0.5f * (a2b2 + t0)));
    float t2 = 2.0f * cos_i * a;
    if (!(t1 + t2 > 0.0f)) return 1.0f; /* grazing on an index-matched surface (eta 1, k 0): the limit */
    float rs = (t1 - t2) / (t1 + t2);
    float t3 = cos2 * a2b2 + sin2 * sin2;
    float t4 = t2 * sin2;
    float rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5f * (rp + rs);
}

static inline PK_HD vec3 pbsdf__fresnel_conductor(const pbsdf *b, float cos_i)
{
    if (b->flags & PBSDF_SCHLICK) {
        float m = 1.0f - fminf(1.0f, fmaxf(0.0f, cos_i));
        float m5 = m * m * m * m * m;
        return v3_mul(b->tint, v3_add(b->specular, v3_scale(v3_sub(v3s(1.0f), b->specular), m5)));
    }
    return v3_mul(b->tint, v3(pbsdf__fresnel_conductor1(cos_i, b->eta.x, b->k.x),
                              pbsdf__fresnel_conductor1(cos_i, b->eta.y, b->k.y),
                              pbsdf__fresnel_conductor1(cos_i, b->eta.z, b->k.z)));
}

/* ---- GGX (Trowbridge-Reitz), isotropic, local frame ---------------------- */

/* Normal distribution D(m) for m.z > 0. */
static inline PK_HD float pbsdf_ggx_d(float alpha, vec3 m)
{
    if (m.z <= 0.0f) return 0.0f;
    float a2 = alpha * alpha;
    float t = m.z * m.z * (a2 - 1.0f) + 1.0f;
    return a2 / (PK_PI * t * t);
}

/* Smith's Lambda(w); G1(w) = 1 / (1 + Lambda(w)). */
static inline PK_HD float pbsdf_ggx_lambda(float alpha, vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) return INFINITY;
    float t2 = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;
    return 0.5f * (sqrtf(1.0f + t2) - 1.0f);
}
static inline PK_HD float pbsdf_ggx_g1(float alpha, vec3 w) { return 1.0f / (1.0f + pbsdf_ggx_lambda(alpha, w)); }
/* Height-correlated masking-shadowing (Heitz 2014), used (as pbrt-v4 does)
 * for reflection and transmission alike. Symmetric in wo, wi. */
static inline PK_HD float pbsdf_ggx_g2(float alpha, vec3 wo, vec3 wi)
{
    return 1.0f / (1.0f + pbsdf_ggx_lambda(alpha, wo) + pbsdf_ggx_lambda(alpha, wi));
}

/* Density of the visible normals seen from w (either hemisphere; it is
 * mirrored to +z): G1(w) max(0, w.m) D(m) / |w.z|, per unit solid angle of m. */
static inline PK_HD float pbsdf_ggx_vndf_pdf(float alpha, vec3 w, vec3 m)
{
    if (w.z < 0.0f) w = v3_neg(w);
    float wm = v3_dot(w, m);
    if (wm <= 0.0f || w.z <= 0.0f) return 0.0f;
    return pbsdf_ggx_g1(alpha, w) * wm * pbsdf_ggx_d(alpha, m) / w.z;
}

/* Samples a visible normal from w (either hemisphere; mirrored to +z),
 * Heitz 2018, "Sampling the GGX Distribution of Visible Normals". */
static inline PK_HD vec3 pbsdf_ggx_vndf_sample(float alpha, vec3 w, float u1, float u2)
{
    if (w.z < 0.0f) w = v3_neg(w);
    vec3 vh = v3_norm(v3(alpha * w.x, alpha * w.y, w.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(lensq)) : v3(1.0f, 0.0f, 0.0f);
    vec3 t2 = v3_cross(vh, t1);
    float r = sqrtf(u1), phi = 2.0f * PK_PI * u2;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(fmaxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)),
                     v3_scale(vh, sqrtf(fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2))));
    return v3_norm(v3(alpha * nh.x, alpha * nh.y, fmaxf(1e-7f, nh.z)));
}

/* ---- Beckmann, isotropic, local frame ------------------------------------- */

/* D(m) = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4) for m.z > 0. */
static inline PK_HD float pbsdf_beckmann_d(float alpha, vec3 m)
{
    if (m.z <= 0.0f) return 0.0f;
    float c2 = m.z * m.z, a2 = alpha * alpha;
    float t2 = fmaxf(0.0f, 1.0f - c2) / c2, e = t2 / a2;
    /* 0 where exp would fall below 1e-35 (and products of it to denormals,
     * which some builds flush to 0 in one expression and not another) */
    if (e > 80.0f) return 0.0f;
    return expf(-e) / (PK_PI * a2 * c2 * c2);
}

/* Smith's Lambda(w) for Beckmann, exact: with a = 1 / (alpha tan theta),
 * Lambda = (exp(-a^2) / (a sqrt(pi)) - erfc(a)) / 2. */
static inline PK_HD float pbsdf_beckmann_lambda(float alpha, vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) return INFINITY;
    float s2 = w.x * w.x + w.y * w.y;
    if (s2 <= 0.0f) return 0.0f;
    float a = sqrtf(z2 / s2) / alpha;
    if (a > 9.0f) return 0.0f; /* below 1e-37 */
    return 0.5f * (expf(-a * a) / (a * 1.7724538509f) - erfcf(a));
}

/* Samples m from D(m) cos theta_m (the whole distribution, not only the
 * normals visible from wo: a back-facing m is the caller's to reject). */
static inline PK_HD vec3 pbsdf_beckmann_sample(float alpha, float u1, float u2)
{
    float t2 = -alpha * alpha * logf(fmaxf(1.0f - u1, 1e-30f));
    float c = 1.0f / sqrtf(1.0f + t2), sn = sqrtf(fmaxf(0.0f, 1.0f - c * c)), phi = 2.0f * PK_PI * u2;
    return v3(sn * cosf(phi), sn * sinf(phi), c);
}

/* ---- anisotropic GGX and Beckmann, local frame ------------------------------ */

/* The same distributions stretched: roughness ax along x, ay along y (the
 * isotropic functions above are these with ax = ay, written for speed and
 * kept as they were). m and w are unit vectors. */
static inline PK_HD float pbsdf_ggx_d_aniso(float ax, float ay, vec3 m)
{
    if (m.z <= 0.0f) return 0.0f;
    const float x = m.x / ax, y = m.y / ay, t = x * x + y * y + m.z * m.z;
    return 1.0f / (PK_PI * ax * ay * t * t);
}
static inline PK_HD float pbsdf_ggx_lambda_aniso(float ax, float ay, vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) return INFINITY;
    float t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / z2;
    return 0.5f * (sqrtf(1.0f + t2) - 1.0f);
}
static inline PK_HD float pbsdf_ggx_vndf_pdf_aniso(float ax, float ay, vec3 w, vec3 m)
{
    if (w.z < 0.0f) w = v3_neg(w);
    float wm = v3_dot(w, m);
    if (wm <= 0.0f || w.z <= 0.0f) return 0.0f;
    return wm * pbsdf_ggx_d_aniso(ax, ay, m) / ((1.0f + pbsdf_ggx_lambda_aniso(ax, ay, w)) * w.z);
}
/* Heitz 2018 with the view stretched by (ax, ay) and the normal back. */
static inline PK_HD vec3 pbsdf_ggx_vndf_sample_aniso(float ax, float ay, vec3 w, float u1, float u2)
{
    if (w.z < 0.0f) w = v3_neg(w);
    vec3 vh = v3_norm(v3(ax * w.x, ay * w.y, w.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(lensq)) : v3(1.0f, 0.0f, 0.0f);
    vec3 t2 = v3_cross(vh, t1);
    float r = sqrtf(u1), phi = 2.0f * PK_PI * u2;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(fmaxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)),
                     v3_scale(vh, sqrtf(fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2))));
    return v3_norm(v3(ax * nh.x, ay * nh.y, fmaxf(1e-7f, nh.z)));
}
/* D(m) = exp(-(x^2 / ax^2 + y^2 / ay^2) / z^2) / (pi ax ay z^4). */
static inline PK_HD float pbsdf_beckmann_d_aniso(float ax, float ay, vec3 m)
{
    if (m.z <= 0.0f) return 0.0f;
    float c2 = m.z * m.z;
    float e = (m.x * m.x / (ax * ax) + m.y * m.y / (ay * ay)) / c2;
    if (e > 80.0f) return 0.0f;
    return expf(-e) / (PK_PI * ax * ay * c2 * c2);
}
/* Lambda with a = 1 / (alpha tan theta) for the roughness alpha of w's
 * azimuth: alpha tan theta = sqrt(ax^2 x^2 + ay^2 y^2) / |z|. */
static inline PK_HD float pbsdf_beckmann_lambda_aniso(float ax, float ay, vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) return INFINITY;
    float s2 = ax * ax * w.x * w.x + ay * ay * w.y * w.y;
    if (s2 <= 0.0f) return 0.0f;
    float a = sqrtf(z2 / s2);
    if (a > 9.0f) return 0.0f;
    return 0.5f * (expf(-a * a) / (a * 1.7724538509f) - erfcf(a));
}
/* m from D(m) cos theta_m: a Gaussian slope (ax r cos phi, ay r sin phi). */
static inline PK_HD vec3 pbsdf_beckmann_sample_aniso(float ax, float ay, float u1, float u2)
{
    float r = sqrtf(-logf(fmaxf(1.0f - u1, 1e-30f))), phi = 2.0f * PK_PI * u2;
    return v3_norm(v3(-ax * r * cosf(phi), -ay * r * sinf(phi), 1.0f));
}

/* ---- the distribution of a conductor, dielectric or plastic --------------- */

static inline PK_HD bool pbsdf__bk(const pbsdf *b) { return (b->flags & PBSDF_BECKMANN) != 0u; }
static inline PK_HD bool pbsdf__an(const pbsdf *b) { return (b->flags & PBSDF_ANISO) != 0u; }
static inline PK_HD float pbsdf_mf_d(const pbsdf *b, vec3 m)
{
    if (pbsdf__an(b))
        return pbsdf__bk(b) ? pbsdf_beckmann_d_aniso(b->alpha, b->alpha_v, m)
                            : pbsdf_ggx_d_aniso(b->alpha, b->alpha_v, m);
    return pbsdf__bk(b) ? pbsdf_beckmann_d(b->alpha, m) : pbsdf_ggx_d(b->alpha, m);
}
static inline PK_HD float pbsdf_mf_lambda(const pbsdf *b, vec3 w)
{
    if (pbsdf__an(b))
        return pbsdf__bk(b) ? pbsdf_beckmann_lambda_aniso(b->alpha, b->alpha_v, w)
                            : pbsdf_ggx_lambda_aniso(b->alpha, b->alpha_v, w);
    return pbsdf__bk(b) ? pbsdf_beckmann_lambda(b->alpha, w) : pbsdf_ggx_lambda(b->alpha, w);
}
/* Height-correlated Smith masking-shadowing, as for GGX. */
static inline PK_HD float pbsdf_mf_g2(const pbsdf *b, vec3 wo, vec3 wi)
{
    return 1.0f / (1.0f + pbsdf_mf_lambda(b, wo) + pbsdf_mf_lambda(b, wi));
}
/* A microfacet normal for wo: GGX's visible normals, Beckmann's whole
 * distribution. */
static inline PK_HD vec3 pbsdf_mf_sample(const pbsdf *b, vec3 wo, float u1, float u2)
{
    if (pbsdf__an(b))
        return pbsdf__bk(b) ? pbsdf_beckmann_sample_aniso(b->alpha, b->alpha_v, u1, u2)
                            : pbsdf_ggx_vndf_sample_aniso(b->alpha, b->alpha_v, wo, u1, u2);
    return pbsdf__bk(b) ? pbsdf_beckmann_sample(b->alpha, u1, u2) : pbsdf_ggx_vndf_sample(b->alpha, wo, u1, u2);
}
/* Solid-angle density of pbsdf_mf_sample returning m (m.z > 0) for wo
 * (either hemisphere); 0 where m faces away from wo. */
static inline PK_HD float pbsdf_mf_pdf(const pbsdf *b, vec3 wo, vec3 m)
{
    if (!pbsdf__bk(b))
        return pbsdf__an(b) ? pbsdf_ggx_vndf_pdf_aniso(b->alpha, b->alpha_v, wo, m) : pbsdf_ggx_vndf_pdf(b->alpha, wo, m);
    if (v3_dot(wo, m) * wo.z <= 0.0f) return 0.0f;
    return pbsdf_mf_d(b, m) * m.z;
}

/* ---- lobes (local frame, wo.z > 0 and wi.z > 0 checked by the caller) -- */

static inline PK_HD bool pbsdf__smooth(const pbsdf *b)
{
    return (pbsdf__an(b) ? fmaxf(b->alpha, b->alpha_v) : b->alpha) < PBSDF_ALPHA_SMOOTH;
}
static inline PK_HD float pbsdf__mean(vec3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }
static inline PK_HD vec3 pbsdf__mirror(vec3 w) { return v3(-w.x, -w.y, w.z); }

/* GGX reflection without Fresnel: D G2 / (4 cos_o cos_i) * cos_i. */
static inline PK_HD float pbsdf__ggx_refl_cos(float alpha, vec3 wo, vec3 wi, vec3 *h_out)
{
    vec3 h = v3_add(wo, wi);
    if (v3_len2(h) <= 0.0f) return 0.0f;
    h = v3_norm(h);
    *h_out = h;
    return pbsdf_ggx_d(alpha, h) * pbsdf_ggx_g2(alpha, wo, wi) / (4.0f * wo.z);
}
/* Density of wi for a VNDF-sampled half vector reflected about it. */
static inline PK_HD float pbsdf__ggx_refl_pdf(float alpha, vec3 wo, vec3 wi)
{
    vec3 h = v3_add(wo, wi);
    if (v3_len2(h) <= 0.0f) return 0.0f;
    h = v3_norm(h);
    float oh = v3_dot(wo, h);
    if (oh <= 0.0f) return 0.0f;
    return pbsdf_ggx_vndf_pdf(alpha, wo, h) / (4.0f * oh);
}

/* The same for the BSDF's own distribution (GGX or Beckmann). */
static inline PK_HD float pbsdf__mf_refl_cos(const pbsdf *b, vec3 wo, vec3 wi, vec3 *h_out)
{
    if (!pbsdf__bk(b) && !pbsdf__an(b)) return pbsdf__ggx_refl_cos(b->alpha, wo, wi, h_out);
    vec3 h = v3_add(wo, wi);
    if (v3_len2(h) <= 0.0f) return 0.0f;
    h = v3_norm(h);
    *h_out = h;
    return pbsdf_mf_d(b, h) * pbsdf_mf_g2(b, wo, wi) / (4.0f * wo.z);
}
static inline PK_HD float pbsdf__mf_refl_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!pbsdf__bk(b) && !pbsdf__an(b)) return pbsdf__ggx_refl_pdf(b->alpha, wo, wi);
    vec3 h = v3_add(wo, wi);
    if (v3_len2(h) <= 0.0f) return 0.0f;
    h = v3_norm(h);
    float oh = v3_dot(wo, h);
    if (oh <= 0.0f) return 0.0f;
    return pbsdf_mf_pdf(b, wo, h) / (4.0f * oh);
}

/* ---- energy compensation ------------------------------------------------------ */

/* A single-scattering microfacet lobe loses the light that meets a second
 * microfacet before it leaves: a white GGX conductor of alpha 1 reflects
 * 0.31 at normal incidence. With PBSDF_ENERGY (pbsdf_compensate) that light
 * is given back (docs/materials.md, "Energy compensation"):
 *  - conductor, plastic's coat, glTF's metal and specular lobes: Kulla and
 *    Conty's (2017) multiple-scattering lobe, added to the lobe,
 *      f_ms cos = F_ms (1 - E(cos_o)) (1 - E(cos_i)) / (pi (1 - E_avg)) cos_i,
 *      F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),
 *    F_avg the cosine-weighted mean of the Fresnel term. For F = 1 it makes
 *    the albedo exactly 1 (up to the table's interpolation); it is symmetric
 *    in wo and wi (reciprocal) and diffuse-like, so it is sampled by a
 *    cosine-weighted direction (the conductor chooses it with probability
 *    pbsdf__ms_prob; plastic and glTF through their diffuse lobe's sampler);
 *  - rough dielectric: Turquin's (2019) scaling, f / E_d(cos_o), E_d the
 *    single-scattering R + T toward wo. A lobe like the conductor's would
 *    have to split its light between reflection and transmission by more
 *    tables in eta; the scaling keeps the lobe's shape, sampler and pdf and
 *    makes R + T = 1. It is a factor of
 *    wo alone, so the compensated reflection is not reciprocal (the
 *    transmission was not before either). */

/* F_avg = 2 * integral of F(mu) mu dmu over [0, 1], by 4-point
 * Gauss-Legendre (nodes 0.5 -+ d[i], weights w[i]; within 5e-4 of a fine
 * quadrature for metals and glass, test_energy): of a conductor's channel
 * (eta, k), or of a dielectric (k < 0: index eta, from outside). Once per
 * shading point, so few nodes. */
static inline PK_HD float pbsdf__favg(float eta, float k)
{
    const float d[2] = {0.1699905218f, 0.4305681558f};
    const float w[2] = {0.3260725774f, 0.1739274226f};
    float s = 0.0f;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            const float mu = j ? 0.5f + d[i] : 0.5f - d[i];
            const float f = k < 0.0f ? pbsdf_fresnel_dielectric(mu, eta) : pbsdf__fresnel_conductor1(mu, eta, k);
            s += w[i] * f * mu;
        }
    return 2.0f * s;
}
/* F_avg of Schlick's F0 + (1 - F0) (1 - mu)^5: F0 + (1 - F0) / 21. */
static inline PK_HD float pbsdf__favg_schlick(float f0) { return f0 + (1.0f - f0) * (1.0f / 21.0f); }
static inline PK_HD float pbsdf__fms(float favg, float eavg)
{
    return favg * favg * eavg / (1.0f - favg * (1.0f - eavg));
}

/* The roughness the (isotropic) tables are read at: alpha, or for an
 * anisotropic lobe the isotropic equivalent sqrt(alpha alpha_v) (the
 * geometric mean: the same area of the slope distribution's ellipse). */
static inline PK_HD float pbsdf__ealpha(const pbsdf *b)
{
    return pbsdf__an(b) ? sqrtf(b->alpha * b->alpha_v) : b->alpha;
}
/* E(mu) of the BSDF's lobe (alpha, distribution). */
static inline PK_HD float pbsdf__e(const pbsdf *b, float mu) { return energy_e(pbsdf__bk(b), pbsdf__ealpha(b), mu); }

/* Turns energy compensation on for a rough conductor, dielectric, plastic
 * or metallic-roughness BSDF (others, and smooth lobes, stay as they are).
 * Call it after anything that changes the roughness (pbsdf_regularize). */
static inline PK_HD void pbsdf_compensate(pbsdf *b)
{
    if (pbsdf__smooth(b)) return;
    if (b->type == PBSDF_DIELECTRIC) {
        b->flags |= PBSDF_ENERGY;
        return;
    }
    if (b->type != PBSDF_CONDUCTOR && b->type != PBSDF_PLASTIC && b->type != PBSDF_METALLIC_ROUGHNESS) return;
    const float eavg = energy_eavg(pbsdf__bk(b), pbsdf__ealpha(b));
    if (!(eavg < 0.99999f)) return;
    vec3 fms;
    if (b->type == PBSDF_CONDUCTOR) {
        vec3 favg;
        if (b->flags & PBSDF_SCHLICK)
            favg = v3(pbsdf__favg_schlick(b->specular.x), pbsdf__favg_schlick(b->specular.y),
                      pbsdf__favg_schlick(b->specular.z));
        else
            favg = v3(pbsdf__favg(b->eta.x, b->k.x), pbsdf__favg(b->eta.y, b->k.y), pbsdf__favg(b->eta.z, b->k.z));
        favg = v3_mul(favg, b->tint);
        fms = v3(pbsdf__fms(favg.x, eavg), pbsdf__fms(favg.y, eavg), pbsdf__fms(favg.z, eavg));
    } else if (b->type == PBSDF_PLASTIC) {
        fms = v3s(pbsdf__fms(pbsdf__favg(b->ior, -1.0f), eavg));
    } else if (b->flags & PBSDF_GLTF_EXT) { /* the same with KHR_materials_specular's weight and F0 colour
                                              (the iridescent film's Fresnel is left out) */
        const float r = (b->ior - 1.0f) / (b->ior + 1.0f), m = b->metallic, s = b->gx_spec;
        const vec3 f0c = v3_min(v3_scale(b->gx_spec_color, r * r), v3s(1.0f));
        fms = v3((1.0f - m) * pbsdf__fms(s * pbsdf__favg_schlick(f0c.x), eavg) +
                     m * pbsdf__fms(pbsdf__favg_schlick(b->albedo.x), eavg),
                 (1.0f - m) * pbsdf__fms(s * pbsdf__favg_schlick(f0c.y), eavg) +
                     m * pbsdf__fms(pbsdf__favg_schlick(b->albedo.y), eavg),
                 (1.0f - m) * pbsdf__fms(s * pbsdf__favg_schlick(f0c.z), eavg) +
                     m * pbsdf__fms(pbsdf__favg_schlick(b->albedo.z), eavg));
    } else { /* glTF: the dielectric's specular lobe (Schlick, f0 of ior) and the metal (Schlick, f0 = base) */
        const float r = (b->ior - 1.0f) / (b->ior + 1.0f), m = b->metallic;
        const float fd = (1.0f - m) * pbsdf__fms(pbsdf__favg_schlick(r * r), eavg);
        fms = v3(fd + m * pbsdf__fms(pbsdf__favg_schlick(b->albedo.x), eavg),
                 fd + m * pbsdf__fms(pbsdf__favg_schlick(b->albedo.y), eavg),
                 fd + m * pbsdf__fms(pbsdf__favg_schlick(b->albedo.z), eavg));
    }
    b->ms = v3_scale(fms, 1.0f / (PK_PI * (1.0f - eavg)));
    b->ms_albedo = pbsdf__mean(fms);
    b->flags |= PBSDF_ENERGY;
}

/* f_ms cos of the multiple-scattering lobe (wo.z > 0, wi.z > 0). */
static inline PK_HD vec3 pbsdf__ms_cos(const pbsdf *b, vec3 wo, vec3 wi)
{
    return v3_scale(b->ms, (1.0f - pbsdf__e(b, wo.z)) * (1.0f - pbsdf__e(b, wi.z)) * wi.z);
}
/* Its albedo toward wo. */
static inline PK_HD float pbsdf__ms_alb(const pbsdf *b, vec3 wo) { return b->ms_albedo * (1.0f - pbsdf__e(b, wo.z)); }
/* The compensated conductor's probability of sampling the multiple-scattering
 * lobe: its albedo's share, the single-scattering lobe's taken as E(wo.z). */
static inline PK_HD float pbsdf__ms_prob(const pbsdf *b, vec3 wo)
{
    const float e = pbsdf__e(b, wo.z), ms = b->ms_albedo * (1.0f - e);
    return ms + e > 0.0f ? ms / (ms + e) : 0.0f;
}
/* Turquin's factor of the dielectric: 1 / E_d toward wo. */
static inline PK_HD float pbsdf__dielectric_comp(const pbsdf *b, vec3 wo)
{
    const float e = energy_dielectric(pbsdf__bk(b), b->ior, pbsdf__ealpha(b), wo.z);
    return e > 0.05f ? 1.0f / e : 20.0f;
}

/* Probability of choosing the specular lobe over the diffuse one, from
 * estimates of their albedos. */
static inline PK_HD float pbsdf__spec_prob(const pbsdf *b, vec3 wo)
{
    float es, ed;
    if (b->type == PBSDF_PLASTIC) {
        float f = pbsdf_fresnel_dielectric(wo.z, b->ior);
        es = f;
        ed = (1.0f - f) * pbsdf__mean(b->albedo);
        if (b->flags & PBSDF_ENERGY) ed += pbsdf__ms_alb(b, wo); /* sampled by the cosine lobe */
    } else { /* glossy */
        es = pbsdf__mean(b->specular);
        ed = pbsdf__mean(b->albedo);
    }
    if (!(es + ed > 0.0f)) return 0.5f;
    return es / (es + ed);
}

/* Plastic's diffuse base: albedo / pi, through the coating twice. */
static inline PK_HD vec3 pbsdf__plastic_diffuse_cos(const pbsdf *b, vec3 wo, vec3 wi)
{
    float t = (1.0f - pbsdf_fresnel_dielectric(wo.z, b->ior)) * (1.0f - pbsdf_fresnel_dielectric(wi.z, b->ior));
    return v3_scale(b->albedo, t * wi.z / PK_PI);
}

/* ---- glTF 2.0 metallic-roughness ------------------------------------------------ */

/* The glTF specification's Appendix B, term by term, with x = |wo.h| for the
 * half vector h of wo and wi (of wo and wi mirrored to wo's side for the
 * transmitted part) and w = (1 - x)^5:
 *   metal      = specular(alpha) (base + (1 - base) w)       conductor_fresnel
 *   dielectric = mix(base_lobe, specular(alpha), F)          fresnel_mix,
 *                F = f0 + (1 - f0) w, f0 = ((1 - ior) / (1 + ior))^2
 *   base_lobe  = mix(base / pi, specular_t(alpha) base, transmission)
 *   material   = mix(dielectric, metal, metallic)
 * specular is the GGX lobe with the height-correlated Smith G2 (as the
 * specification writes it and the conductor uses); specular_t is the thin
 * sheet's transmission of KHR_materials_transmission: the same lobe about
 * the direction straight through (no refraction, ior only in F). All terms
 * are symmetric in wo and wi (|wo.h| = |wi.h|), so the BSDF is reciprocal.
 * KHR_materials_clearcoat lays a clear coat over all of it:
 *   coated     = mix(material, specular(coat_alpha), coat Fc),
 *                Fc = 0.04 + 0.96 (1 - wo.z)^5
 * with Fc of the view alone, as the extension defines it (so a coated
 * surface is not reciprocal).
 * As the specification says of its fresnel_mix, the diffuse base weighted by
 * 1 - F(|wo.h|) does not conserve energy toward grazing angles: a white
 * dielectric reflects up to 1.05 of the light at 65 degrees from the normal
 * and 1.4 to 1.7 (smooth) at 87 (docs/materials.md; test_bsdf measures it). */
static inline PK_HD float pbsdf__schlick_w(float c)
{
    float m = 1.0f - fminf(1.0f, fmaxf(0.0f, c));
    return m * m * m * m * m;
}
static inline PK_HD float pbsdf__mr_f0(const pbsdf *b)
{
    float r = (b->ior - 1.0f) / (b->ior + 1.0f);
    return r * r;
}
static inline PK_HD vec3 pbsdf__mirror_z(vec3 w) { return v3(w.x, w.y, -w.z); }

/* The clearcoat's own normal (PBSDF_COAT_NORMAL, glTF's
 * clearcoatNormalTexture): the coat's Fresnel weight and its GGX lobe are
 * those of the frame about coat_n, as the glTF sample renderer has them: the
 * cosines in Fc and in the lobe's f cos are taken about coat_n (a lobe with a
 * shading normal of its own). Directions below the coat's hemisphere get
 * none of its lobe (its weight there is the whole coat, Fc(0) = 1). Without
 * the flag: +z, and the arithmetic of the plain model. */
static inline PK_HD float pbsdf__coat_cos(const pbsdf *b, vec3 w)
{
    return b->flags & PBSDF_COAT_NORMAL ? v3_dot(b->coat_n, w) : w.z;
}

/* The clearcoat's weight toward wo: coat Fc(wo.z) (wo . coat_n). */
static inline PK_HD float pbsdf__mr_coat(const pbsdf *b, vec3 wo)
{
    return b->coat > 0.0f ? b->coat * (0.04f + 0.96f * pbsdf__schlick_w(pbsdf__coat_cos(b, wo))) : 0.0f;
}
static inline PK_HD bool pbsdf__coat_smooth(const pbsdf *b) { return b->coat_alpha < PBSDF_ALPHA_SMOOTH; }

/* The coat's rough lobe, f cos (without the weight Fc), wo and wi above the
 * surface; its density; a sample of it (false where it leaves the coat's or
 * the surface's hemisphere), and the smooth coat's mirror direction. */
static inline PK_HD float pbsdf__coat_lobe(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 h;
    if (b->flags & PBSDF_COAT_NORMAL) {
        const onb f = onb_from_normal(b->coat_n);
        wo = onb_to_local(f, wo), wi = onb_to_local(f, wi);
        if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    }
    return pbsdf__ggx_refl_cos(b->coat_alpha, wo, wi, &h);
}
static inline PK_HD float pbsdf__coat_lobe_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (b->flags & PBSDF_COAT_NORMAL) {
        const onb f = onb_from_normal(b->coat_n);
        wo = onb_to_local(f, wo), wi = onb_to_local(f, wi);
        if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    }
    return pbsdf__ggx_refl_pdf(b->coat_alpha, wo, wi);
}
/* (Called for a coat with its own normal only, PBSDF_COAT_NORMAL: a plain
 * coat's callers sample it in the shading frame themselves.) */
static inline PK_HD bool pbsdf__coat_lobe_sample(const pbsdf *b, vec3 wo, float u1, float u2, vec3 *wi)
{
    const onb f = onb_from_normal(b->coat_n);
    wo = onb_to_local(f, wo);
    if (!(wo.z > 0.0f)) return false;
    const vec3 m = pbsdf_ggx_vndf_sample(b->coat_alpha, wo, u1, u2);
    const float om = v3_dot(wo, m);
    vec3 w = v3_sub(v3_scale(m, 2.0f * om), wo);
    if (!(om > 0.0f) || !(w.z > 0.0f)) return false;
    *wi = onb_to_world(f, w);
    return true;
}
static inline PK_HD bool pbsdf__coat_mirror(const pbsdf *b, vec3 wo, vec3 *wi)
{
    if (!(b->flags & PBSDF_COAT_NORMAL)) {
        *wi = pbsdf__mirror(wo);
        return true;
    }
    const float c = v3_dot(b->coat_n, wo);
    const vec3 w = v3_sub(v3_scale(b->coat_n, 2.0f * c), wo);
    if (!(c > 0.0f) || !(w.z > 0.0f)) return false;
    *wi = w;
    return true;
}

/* The probabilities of sampling the specular reflection (p[0]), the diffuse
 * base (p[1]), the transmission (p[2]) and the clearcoat (p[3]), in
 * proportion to the lobes' weights at normal-to-wo incidence. */
static inline PK_HD void pbsdf__mr_probs(const pbsdf *b, vec3 wo, float p[4])
{
    const float w = pbsdf__schlick_w(wo.z), f0 = pbsdf__mr_f0(b), m = b->metallic, t = b->transmission;
    const float f = f0 + (1.0f - f0) * w, base = pbsdf__mean(b->albedo), cw = pbsdf__mr_coat(b, wo);
    const float es = ((1.0f - m) * f + m * (base + (1.0f - base) * w)) * (1.0f - cw);
    const float eb = (1.0f - m) * (1.0f - f) * base * (1.0f - cw);
    float ed = eb * (1.0f - t);
    if (b->flags & PBSDF_ENERGY) ed += pbsdf__ms_alb(b, wo) * (1.0f - cw); /* sampled by the cosine lobe */
    const float et = eb * t, sum = es + ed + et + cw;
    if (!(sum > 0.0f)) {
        p[0] = 1.0f, p[1] = p[2] = p[3] = 0.0f;
        return;
    }
    p[1] = ed / sum, p[2] = et / sum, p[3] = cw / sum;
    p[0] = 1.0f - p[1] - p[2] - p[3];
}

/* The delta lobes of a smooth surface toward wo (h = the normal): the
 * mirror's weight and the straight-through transmission's (under the
 * clearcoat, which takes its share, pbsdf__mr_coat). */
static inline PK_HD vec3 pbsdf__mr_delta_reflect(const pbsdf *b, vec3 wo)
{
    const float w = pbsdf__schlick_w(wo.z), f0 = pbsdf__mr_f0(b), m = b->metallic;
    const vec3 fm = v3_add(b->albedo, v3_scale(v3_sub(v3s(1.0f), b->albedo), w));
    return v3_add(v3s((1.0f - m) * (f0 + (1.0f - f0) * w)), v3_scale(fm, m));
}
static inline PK_HD vec3 pbsdf__mr_delta_transmit(const pbsdf *b, vec3 wo)
{
    const float w = pbsdf__schlick_w(wo.z), f0 = pbsdf__mr_f0(b);
    return v3_scale(b->albedo, (1.0f - b->metallic) * b->transmission * (1.0f - (f0 + (1.0f - f0) * w)));
}

/* f cos of the non-delta part (wo.z > 0; wi on either side), without the
 * clearcoat. */
static inline PK_HD vec3 pbsdf__mr_eval_base(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f) || wi.z == 0.0f) return v3s(0.0f);
    const float m = b->metallic, t = b->transmission, f0 = pbsdf__mr_f0(b);
    const bool smooth = pbsdf__smooth(b);
    vec3 h;
    if (wi.z < 0.0f) { /* the thin sheet's transmission */
        if (smooth || !((1.0f - m) * t > 0.0f)) return v3s(0.0f);
        const float s = pbsdf__ggx_refl_cos(b->alpha, wo, pbsdf__mirror_z(wi), &h);
        if (!(s > 0.0f)) return v3s(0.0f);
        const float f = f0 + (1.0f - f0) * pbsdf__schlick_w(fabsf(v3_dot(wo, h)));
        return v3_scale(b->albedo, (1.0f - m) * t * (1.0f - f) * s);
    }
    h = v3_norm(v3_add(wo, wi));
    const float w = pbsdf__schlick_w(fabsf(v3_dot(wo, h)));
    const float f = f0 + (1.0f - f0) * w;
    vec3 r = v3_scale(b->albedo, (1.0f - m) * (1.0f - t) * (1.0f - f) * wi.z / PK_PI);
    if (!smooth) {
        const float s = pbsdf__ggx_refl_cos(b->alpha, wo, wi, &h);
        if (s > 0.0f) {
            const vec3 fm = v3_add(b->albedo, v3_scale(v3_sub(v3s(1.0f), b->albedo), w));
            r = v3_add(r, v3_scale(v3_add(v3s((1.0f - m) * f), v3_scale(fm, m)), s));
        }
        if (b->flags & PBSDF_ENERGY) r = v3_add(r, pbsdf__ms_cos(b, wo, wi));
    }
    return r;
}

/* f cos of the non-delta part, the clearcoat included. */
static inline PK_HD vec3 pbsdf__mr_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 r = pbsdf__mr_eval_base(b, wo, wi);
    if (!(b->coat > 0.0f)) return r;
    const float cw = pbsdf__mr_coat(b, wo);
    r = v3_scale(r, 1.0f - cw);
    if (wi.z > 0.0f && wo.z > 0.0f && !pbsdf__coat_smooth(b)) {
        const float s = pbsdf__coat_lobe(b, wo, wi);
        if (s > 0.0f) r = v3_add(r, v3s(cw * s));
    }
    return r;
}

/* The mixture density of the lobes' samplers. */
static inline PK_HD float pbsdf__mr_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f) || wi.z == 0.0f) return 0.0f;
    float pr[4];
    pbsdf__mr_probs(b, wo, pr);
    const bool smooth = pbsdf__smooth(b);
    if (wi.z < 0.0f)
        return smooth || !(pr[2] > 0.0f) ? 0.0f : pr[2] * pbsdf__ggx_refl_pdf(b->alpha, wo, pbsdf__mirror_z(wi));
    float p = pr[1] * wi.z / PK_PI;
    if (!smooth && pr[0] > 0.0f) p += pr[0] * pbsdf__ggx_refl_pdf(b->alpha, wo, wi);
    if (!pbsdf__coat_smooth(b) && pr[3] > 0.0f) p += pr[3] * pbsdf__coat_lobe_pdf(b, wo, wi);
    return p;
}

/* ---- glTF 2.0 PBR extensions on metallic-roughness (PBSDF_GLTF_EXT) ------------ */

/* The extensions of the Khronos specifications, term by term, over the model
 * above (x = |wo.h|, w = (1 - x)^5, docs/materials.md):
 *  - KHR_materials_specular: the dielectric's Fresnel colour
 *      Fd = spec (f0c + (1 - f0c) w),  f0c = min(f0(ior) spec_color, 1),
 *    its specular lobe weighted by Fd and its base by 1 - max3(Fd)
 *    (fresnel_mix with weight and f0 colour);
 *  - KHR_materials_iridescence: Fd and the metal's Fresnel are mixed by the
 *    strength with the thin film's (pbsdf_iridescence) over base F0 spec f0c
 *    and the base colour;
 *  - KHR_materials_anisotropy: the specular and transmission lobes' GGX is
 *    anisotropic (PBSDF_ANISO: alpha along the frame's x, alpha_v along y);
 *  - KHR_materials_sheen: sheen colour times the Charlie lobe (sheen.h) over
 *    the rest, scaled by max(0, min(1 - max3(sheen) E(cos_o), 1 - max3(sheen)
 *    E(cos_i))) (the specification's reciprocal albedo scaling; clamped at 0
 *    because the lobe's own albedo exceeds 1 toward grazing at low sheen
 *    roughness);
 *  - the clearcoat lies over all of it, as in the plain model.
 * Every term but the clearcoat's is a function of |wo.h| = |wi.h|, cos_o and
 * cos_i symmetric in wo and wi: the BSDF is reciprocal without a clearcoat. */
static inline PK_HD float pbsdf__max3(vec3 c) { return fmaxf(c.x, fmaxf(c.y, c.z)); }

/* The spectral sensitivity of Belcour and Barla (2017), their Gaussian fit
 * of the CIE XYZ functions in Fourier space, at optical path difference opd
 * (nm) and phase shift (per X, Y, Z), turned into linear sRGB (Rec. 709). */
static inline PK_HD vec3 pbsdf__irid_sensitivity(float opd, vec3 shift)
{
    const float ph = 2.0f * PK_PI * opd * 1e-9f, ph2 = ph * ph, n = 1.0f / 1.0685e-7f;
    const float x = 5.4856e-13f * sqrtf(2.0f * PK_PI * 4.3278e9f) * cosf(1.6810e6f * ph + shift.x) *
                        expf(-4.3278e9f * ph2) +
                    9.7470e-14f * sqrtf(2.0f * PK_PI * 4.5282e9f) * cosf(2.2399e6f * ph + shift.x) *
                        expf(-4.5282e9f * ph2);
    const float y = 4.4201e-13f * sqrtf(2.0f * PK_PI * 9.3046e9f) * cosf(1.7953e6f * ph + shift.y) *
                    expf(-9.3046e9f * ph2);
    const float z = 5.2481e-13f * sqrtf(2.0f * PK_PI * 6.6121e9f) * cosf(2.2084e6f * ph + shift.z) *
                    expf(-6.6121e9f * ph2);
    return v3_scale(v3(3.2404542f * x - 1.5371385f * y - 0.4985314f * z,
                       -0.9692660f * x + 1.8760108f * y + 0.0415560f * z,
                       0.0556434f * x - 0.2040259f * y + 1.0572252f * z),
                    n);
}
static inline PK_HD float pbsdf__schlick(float f0, float c) { return f0 + (1.0f - f0) * pbsdf__schlick_w(c); }
/* The thin film's Fresnel reflectance (KHR_materials_iridescence, after
 * Belcour and Barla 2017): a film of index film_ior and thickness d (nm)
 * between the outside (index outside) and a base of normal-incidence
 * reflectance f0 (per channel; its index (1 + sqrt f0) / (1 - sqrt f0)),
 * seen at cos1; Schlick's Fresnel at both interfaces, phase shifts 0 or pi,
 * the first two orders of the film's interference integrated over the
 * spectrum analytically. A film of thickness 0 is no film. */
static inline PBSDF_CALLED PK_HD vec3 pbsdf_iridescence(float outside, float film_ior, float cos1, float d, vec3 f0)
{
    cos1 = fminf(fmaxf(cos1, 0.0f), 1.0f);
    if (!(d > 0.0f))
        return v3(pbsdf__schlick(f0.x, cos1), pbsdf__schlick(f0.y, cos1), pbsdf__schlick(f0.z, cos1));
    const float e = outside / film_ior, c2sq = 1.0f - e * e * (1.0f - cos1 * cos1);
    if (c2sq < 0.0f) return v3s(1.0f); /* total internal reflection */
    const float cos2 = sqrtf(c2sq);
    const float r0 = (film_ior - outside) * (film_ior - outside) / ((film_ior + outside) * (film_ior + outside));
    const float r12 = pbsdf__schlick(r0, cos1), t121 = 1.0f - r12;
    const float phi21 = film_ior < outside ? 0.0f : PK_PI; /* pi - phi12 */
    const float f[3] = {f0.x, f0.y, f0.z};
    float r23[3], phi[3];
    for (int k = 0; k < 3; k++) {
        const float s = sqrtf(fminf(fmaxf(f[k], 0.0f), 0.9999f)), bior = (1.0f + s) / (1.0f - s);
        const float r1 = (bior - film_ior) * (bior - film_ior) / ((bior + film_ior) * (bior + film_ior));
        r23[k] = pbsdf__schlick(r1, cos2);
        phi[k] = phi21 + (bior < film_ior ? PK_PI : 0.0f);
    }
    const float opd = 2.0f * film_ior * d * cos2;
    float out[3];
    vec3 s1 = pbsdf__irid_sensitivity(opd, v3(phi[0], phi[1], phi[2]));
    vec3 s2 = pbsdf__irid_sensitivity(2.0f * opd, v3(2.0f * phi[0], 2.0f * phi[1], 2.0f * phi[2]));
    const float sv1[3] = {s1.x, s1.y, s1.z}, sv2[3] = {s2.x, s2.y, s2.z};
    for (int k = 0; k < 3; k++) {
        const float r123 = fminf(fmaxf(r12 * r23[k], 1e-5f), 0.9999f), rr = sqrtf(r123);
        const float rs = t121 * t121 * r23[k] / (1.0f - r123);
        float cm = rs - t121, i = r12 + rs;
        cm *= rr;
        i += cm * 2.0f * sv1[k];
        cm *= rr;
        i += cm * 2.0f * sv2[k];
        out[k] = fmaxf(i, 0.0f);
    }
    return v3(out[0], out[1], out[2]);
}

/* The dielectric's (*fd) and the metal's (*fm) Fresnel colours at |wo.h| = c;
 * irid false leaves the film out (the lobe choice's estimate). */
static inline PK_HD void pbsdf__gx_fresnel(const pbsdf *b, float c, bool irid, vec3 *fd, vec3 *fm)
{
    const float w = pbsdf__schlick_w(c);
    const vec3 f0c = v3_min(v3_scale(b->gx_spec_color, pbsdf__mr_f0(b)), v3s(1.0f));
    *fd = v3_scale(v3_add(f0c, v3_scale(v3_sub(v3s(1.0f), f0c), w)), b->gx_spec);
    *fm = v3_add(b->albedo, v3_scale(v3_sub(v3s(1.0f), b->albedo), w));
    if (!irid || !(b->gx_irid > 0.0f)) return;
    const float t = b->gx_irid;
    if (b->metallic < 1.0f)
        *fd = v3_lerp(*fd, pbsdf_iridescence(1.0f, b->gx_irid_ior, c, b->gx_irid_d, v3_scale(f0c, b->gx_spec)), t);
    if (b->metallic > 0.0f) *fm = v3_lerp(*fm, pbsdf_iridescence(1.0f, b->gx_irid_ior, c, b->gx_irid_d, b->albedo), t);
}
static inline PK_HD float pbsdf__gx_sheen_a(const pbsdf *b)
{
    const float r = sheen_clamp_r(b->gx_sheen_r);
    return r * r;
}
/* The sheen's albedo scaling of what lies under it for cosines co and ci. */
static inline PK_HD float pbsdf__gx_sheen_scale(const pbsdf *b, float co, float ci)
{
    const float c = pbsdf__max3(b->gx_sheen);
    if (!(c > 0.0f)) return 1.0f;
    const float e = fmaxf(sheen_e(b->gx_sheen_r, fabsf(co)), sheen_e(b->gx_sheen_r, fabsf(ci)));
    return fmaxf(0.0f, 1.0f - c * e);
}

/* f cos of the non-delta part (wo.z > 0; wi on either side), without the
 * clearcoat. */
static inline PBSDF_CALLED PK_HD vec3 pbsdf__gx_eval_base(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f) || wi.z == 0.0f) return v3s(0.0f);
    const float m = b->metallic, t = b->transmission;
    const bool smooth = pbsdf__smooth(b);
    vec3 h, fd, fm;
    if (wi.z < 0.0f) { /* the thin sheet's transmission */
        if (smooth || !((1.0f - m) * t > 0.0f)) return v3s(0.0f);
        const float s = pbsdf__mf_refl_cos(b, wo, pbsdf__mirror_z(wi), &h);
        if (!(s > 0.0f)) return v3s(0.0f);
        pbsdf__gx_fresnel(b, fabsf(v3_dot(wo, h)), true, &fd, &fm);
        return v3_scale(b->albedo, (1.0f - m) * t * (1.0f - pbsdf__max3(fd)) * s *
                                       pbsdf__gx_sheen_scale(b, wo.z, wi.z));
    }
    h = v3_norm(v3_add(wo, wi));
    pbsdf__gx_fresnel(b, fabsf(v3_dot(wo, h)), true, &fd, &fm);
    vec3 r = v3_scale(b->albedo, (1.0f - m) * (1.0f - t) * (1.0f - pbsdf__max3(fd)) * wi.z / PK_PI);
    if (!smooth) {
        const float s = pbsdf__mf_refl_cos(b, wo, wi, &h);
        if (s > 0.0f) r = v3_add(r, v3_scale(v3_add(v3_scale(fd, 1.0f - m), v3_scale(fm, m)), s));
        if (b->flags & PBSDF_ENERGY) r = v3_add(r, pbsdf__ms_cos(b, wo, wi));
    }
    r = v3_scale(r, pbsdf__gx_sheen_scale(b, wo.z, wi.z));
    if (pbsdf__max3(b->gx_sheen) > 0.0f) r = v3_add(r, v3_scale(b->gx_sheen, sheen_cos(pbsdf__gx_sheen_a(b), wo, wi)));
    return r;
}
static inline PK_HD vec3 pbsdf__gx_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 r = pbsdf__gx_eval_base(b, wo, wi);
    if (!(b->coat > 0.0f)) return r;
    const float cw = pbsdf__mr_coat(b, wo);
    r = v3_scale(r, 1.0f - cw);
    if (wi.z > 0.0f && wo.z > 0.0f && !pbsdf__coat_smooth(b)) {
        const float s = pbsdf__coat_lobe(b, wo, wi);
        if (s > 0.0f) r = v3_add(r, v3s(cw * s));
    }
    return r;
}
/* The delta lobes of a smooth surface toward wo, under the clearcoat's
 * share: the mirror's weight and the straight-through transmission's. */
static inline PK_HD vec3 pbsdf__gx_delta(const pbsdf *b, vec3 wo, bool transmit)
{
    vec3 fd, fm;
    pbsdf__gx_fresnel(b, wo.z, true, &fd, &fm);
    const float m = b->metallic, k = pbsdf__gx_sheen_scale(b, wo.z, wo.z) * (1.0f - pbsdf__mr_coat(b, wo));
    if (transmit) return v3_scale(b->albedo, (1.0f - m) * b->transmission * (1.0f - pbsdf__max3(fd)) * k);
    return v3_scale(v3_add(v3_scale(fd, 1.0f - m), v3_scale(fm, m)), k);
}
/* The probabilities of sampling the specular reflection (p[0]), the diffuse
 * base (p[1]), the transmission (p[2]), the clearcoat (p[3]) and the sheen
 * (p[4]), in proportion to estimates of the lobes' albedos toward wo. */
static inline PK_HD void pbsdf__gx_probs(const pbsdf *b, vec3 wo, float p[5])
{
    vec3 fd, fm;
    pbsdf__gx_fresnel(b, wo.z, false, &fd, &fm);
    const float m = b->metallic, t = b->transmission, cw = pbsdf__mr_coat(b, wo);
    const float k = pbsdf__gx_sheen_scale(b, wo.z, wo.z) * (1.0f - cw);
    const float es = ((1.0f - m) * pbsdf__mean(fd) + m * pbsdf__mean(fm)) * k;
    const float eb = (1.0f - m) * (1.0f - pbsdf__max3(fd)) * pbsdf__mean(b->albedo) * k;
    float ed = eb * (1.0f - t);
    if (b->flags & PBSDF_ENERGY) ed += pbsdf__ms_alb(b, wo) * k; /* sampled by the cosine lobe */
    const float esh = pbsdf__mean(b->gx_sheen) > 0.0f
                          ? pbsdf__mean(b->gx_sheen) * fminf(sheen_e(b->gx_sheen_r, wo.z), 1.0f) * (1.0f - cw)
                          : 0.0f;
    const float et = eb * t, sum = es + ed + et + cw + esh;
    if (!(sum > 0.0f)) {
        p[0] = 1.0f, p[1] = p[2] = p[3] = p[4] = 0.0f;
        return;
    }
    p[1] = ed / sum, p[2] = et / sum, p[3] = cw / sum, p[4] = esh / sum;
    p[0] = fmaxf(0.0f, 1.0f - p[1] - p[2] - p[3] - p[4]);
}
/* The mixture density of the lobes' samplers (the sheen's: uniform over the
 * hemisphere). */
static inline PBSDF_CALLED PK_HD float pbsdf__gx_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f) || wi.z == 0.0f) return 0.0f;
    float pr[5];
    pbsdf__gx_probs(b, wo, pr);
    const bool smooth = pbsdf__smooth(b);
    if (wi.z < 0.0f)
        return smooth || !(pr[2] > 0.0f) ? 0.0f : pr[2] * pbsdf__mf_refl_pdf(b, wo, pbsdf__mirror_z(wi));
    float p = pr[1] * wi.z / PK_PI + pr[4] * (1.0f / (2.0f * PK_PI));
    if (!smooth && pr[0] > 0.0f) p += pr[0] * pbsdf__mf_refl_pdf(b, wo, wi);
    if (!pbsdf__coat_smooth(b) && pr[3] > 0.0f) p += pr[3] * pbsdf__coat_lobe_pdf(b, wo, wi);
    return p;
}
static inline PBSDF_CALLED PK_HD bool pbsdf__gx_sample(const pbsdf *b, vec3 wo, const float u[3], vec3 *wi,
                                                       vec3 *weight, float *pdf, bool *is_delta)
{
    *is_delta = false;
    *weight = v3s(0.0f);
    if (!(wo.z > 0.0f)) return false;
    float pr[5];
    pbsdf__gx_probs(b, wo, pr);
    const bool smooth = pbsdf__smooth(b);
    int lobe = 0;
    float c = pr[0];
    while (lobe < 4 && !(u[0] < c)) c += pr[++lobe];
    while (!(pr[lobe] > 0.0f)) lobe = (lobe + 1) % 5; /* float rounding: a lobe that has weight */
    vec3 w;
    if (lobe == 0 || lobe == 3) { /* specular reflection, or the clearcoat's */
        const bool coat = lobe == 3;
        if (coat ? pbsdf__coat_smooth(b) : smooth) {
            if (!coat) *wi = pbsdf__mirror(wo);
            else if (!pbsdf__coat_mirror(b, wo, wi)) return false;
            const vec3 f = coat ? v3s(pbsdf__mr_coat(b, wo)) : pbsdf__gx_delta(b, wo, false);
            *weight = v3_scale(f, 1.0f / pr[lobe]);
            *pdf = pr[lobe];
            *is_delta = true;
            return true;
        }
        if (coat && (b->flags & PBSDF_COAT_NORMAL)) {
            if (!pbsdf__coat_lobe_sample(b, wo, u[1], u[2], &w)) return false;
        } else {
            const vec3 m = coat ? pbsdf_ggx_vndf_sample(b->coat_alpha, wo, u[1], u[2]) : pbsdf_mf_sample(b, wo, u[1], u[2]);
            const float om = v3_dot(wo, m);
            if (!(om > 0.0f)) return false;
            w = v3_sub(v3_scale(m, 2.0f * om), wo);
        }
    } else if (lobe == 1) { /* the diffuse base */
        const float r = sqrtf(u[1]), phi = 2.0f * PK_PI * u[2];
        w = v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[1])));
    } else if (lobe == 4) { /* the sheen: uniform over the hemisphere */
        const float z = u[1], r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * PK_PI * u[2];
        w = v3(r * cosf(phi), r * sinf(phi), z);
    } else { /* transmission: the specular lobe mirrored through the sheet */
        if (smooth) {
            *wi = v3_neg(wo);
            *weight = v3_scale(pbsdf__gx_delta(b, wo, true), 1.0f / pr[2]);
            *pdf = pr[2];
            *is_delta = true;
            return true;
        }
        const vec3 m = pbsdf_mf_sample(b, wo, u[1], u[2]);
        const float om = v3_dot(wo, m);
        if (!(om > 0.0f)) return false;
        w = v3_sub(v3_scale(m, 2.0f * om), wo);
        if (!(w.z > 0.0f)) return false;
        w = pbsdf__mirror_z(w);
    }
    if (lobe != 2 && !(w.z > 0.0f)) return false;
    const float p = pbsdf__gx_pdf(b, wo, w);
    if (!(p > 0.0f)) return false;
    *wi = w;
    *pdf = p;
    *weight = v3_scale(pbsdf__gx_eval(b, wo, w), 1.0f / p);
    return true;
}

/* ---- dielectric ------------------------------------------------------------ */

/* Generalised half vector of a rough dielectric (Walter 2007), facing +z;
 * *etap = relative index across the boundary as seen from wo (1 for
 * reflection). False where no microfacet connects wo and wi. */
static inline PK_HD bool pbsdf__dielectric_half(const pbsdf *b, vec3 wo, vec3 wi, vec3 *m, float *etap)
{
    bool reflect = wo.z * wi.z > 0.0f;
    float e = 1.0f;
    if (!reflect) e = wo.z > 0.0f ? b->ior : 1.0f / b->ior;
    vec3 h = v3_add(v3_scale(wi, e), wo);
    if (wo.z == 0.0f || wi.z == 0.0f || v3_len2(h) <= 0.0f) return false;
    h = v3_norm(h);
    if (h.z < 0.0f) h = v3_neg(h);
    /* microfacets seen from behind by either direction do not count, nor
     * those that wo sees edge-on (no projected area: the pdf is 0 there) */
    if (v3_dot(h, wi) * wi.z < 0.0f || v3_dot(h, wo) * wo.z <= 0.0f) return false;
    *m = h;
    *etap = e;
    return true;
}

static inline PK_HD vec3 pbsdf__dielectric_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 m;
    float e;
    if (pbsdf__smooth(b) || !pbsdf__dielectric_half(b, wo, wi, &m, &e)) return v3s(0.0f);
    float f = pbsdf_fresnel_dielectric(v3_dot(wo, m), b->ior);
    float dg = pbsdf_mf_d(b, m) * pbsdf_mf_g2(b, wo, wi);
    if (b->flags & PBSDF_ENERGY) dg *= pbsdf__dielectric_comp(b, wo);
    if (wo.z * wi.z > 0.0f) return v3s(dg * f / (4.0f * fabsf(wo.z)));
    float im = v3_dot(wi, m), om = v3_dot(wo, m);
    float den = im + om / e;
    den *= den;
    /* f_t |cos_i| = D G (1 - F) |i.m| |o.m| / (den |cos_o|) */
    float t = dg * (1.0f - f) * fabsf(im * om) / (den * fabsf(wo.z));
    return v3_scale(b->transmittance, t);
}

static inline PK_HD float pbsdf__dielectric_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 m;
    float e;
    if (pbsdf__smooth(b) || !pbsdf__dielectric_half(b, wo, wi, &m, &e)) return 0.0f;
    float om = v3_dot(wo, m);
    float r = pbsdf_fresnel_dielectric(om, b->ior);
    float pm = pbsdf_mf_pdf(b, wo, m);
    if (wo.z * wi.z > 0.0f) return pm / (4.0f * fabsf(om)) * r;
    float im = v3_dot(wi, m);
    float den = im + om / e;
    return pm * fabsf(im) / (den * den) * (1.0f - r);
}

/* Refracts w (pointing away, either side) through the facet m (m.z > 0,
 * ior = inside / outside). False on total internal reflection. (optics.h's
 * refract_dir, the Whitted integrator's, rounds differently: see there.) */
static inline PK_HD bool pbsdf__refract(vec3 w, vec3 m, float ior, vec3 *out)
{
    float c = v3_dot(w, m), eta = ior;
    if (c < 0.0f) {
        eta = 1.0f / eta;
        c = -c;
        m = v3_neg(m);
    }
    float s2t = fmaxf(0.0f, 1.0f - c * c) / (eta * eta);
    if (s2t >= 1.0f) return false;
    float ct = sqrtf(1.0f - s2t);
    *out = v3_norm(v3_add(v3_scale(v3_neg(w), 1.0f / eta), v3_scale(m, c / eta - ct)));
    return true;
}

/* ---- glTF metallic-roughness bounding a volume (PBSDF_MR_VOLUME) ----------- */

/* Outside (wo.z > 0) the reflection is the metallic-roughness BSDF's as
 * above; its transmitted share, (1 - metallic) transmission under the
 * clearcoat, refracts as a rough dielectric of ior and alpha (Walter et al.
 * with exact Fresnel: the part of the glTF BTDF that the volume extension
 * makes refract) into the inside. Inside (wo.z < 0) the boundary is that
 * dielectric seen from within: its internal reflection (total beyond the
 * critical angle) in full, its transmission out weighted by the same share;
 * the rest of the light (the metal's and the diffuse base's part of the
 * surface, opaque sheets seen from behind) is absorbed. The share takes the
 * clearcoat's weight of the outside direction and the square root of the
 * base colour at every crossing (in and out: one base colour for light
 * that passes through a closed object, as the material's own tint), so the
 * transmission is reciprocal (the eta^2 rule of a refracting boundary). */
static inline PK_HD pbsdf pbsdf__mrv_glass(const pbsdf *b)
{
    pbsdf g = pbsdf_dielectric(b->ior, b->alpha, v3s(1.0f));
    g.flags = b->flags & PBSDF_ENERGY;
    return g;
}
/* The transmitted share through the boundary, by the direction outside. */
static inline PK_HD vec3 pbsdf__mrv_share(const pbsdf *b, vec3 w_out)
{
    const float s = (1.0f - b->metallic) * b->transmission * (1.0f - pbsdf__mr_coat(b, w_out));
    return v3_scale(v3(sqrtf(b->albedo.x), sqrtf(b->albedo.y), sqrtf(b->albedo.z)), s);
}
static inline PBSDF_CALLED PK_HD vec3 pbsdf__mrv_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (wo.z == 0.0f || wi.z == 0.0f) return v3s(0.0f);
    if (wo.z > 0.0f && wi.z > 0.0f) return pbsdf__mr_eval(b, wo, wi);
    const pbsdf g = pbsdf__mrv_glass(b);
    const vec3 f = pbsdf__dielectric_eval(&g, wo, wi);
    if (wo.z < 0.0f && wi.z < 0.0f) return f; /* internal reflection */
    return v3_mul(pbsdf__mrv_share(b, wo.z > 0.0f ? wo : wi), f);
}
static inline PBSDF_CALLED PK_HD float pbsdf__mrv_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (wo.z == 0.0f || wi.z == 0.0f) return 0.0f;
    const pbsdf g = pbsdf__mrv_glass(b);
    if (wo.z < 0.0f) return pbsdf__dielectric_pdf(&g, wo, wi);
    float pr[4];
    pbsdf__mr_probs(b, wo, pr);
    float p = pr[2] > 0.0f ? pr[2] * pbsdf__dielectric_pdf(&g, wo, wi) : 0.0f;
    if (wi.z > 0.0f) p += pbsdf__mr_pdf(b, wo, wi);
    return p;
}
/* Samples the boundary's glass: for wo inside all of it (prob = 1), for wo
 * outside the transmission lobe, chosen with probability prob (the
 * metallic-roughness BSDF's other lobes sample the rest); u0 in [0, 1). */
static inline PBSDF_CALLED PK_HD bool pbsdf__mrv_sample(const pbsdf *b, vec3 wo, float u0, float u1, float u2, float prob,
                                                 vec3 *wi, vec3 *weight, float *pdf, bool *is_delta)
{
    const pbsdf g = pbsdf__mrv_glass(b);
    *is_delta = false;
    if (pbsdf__smooth(b)) {
        const float r = pbsdf_fresnel_dielectric(wo.z, b->ior);
        *is_delta = true;
        if (wo.z < 0.0f && u0 < r) { /* internal reflection */
            *wi = pbsdf__mirror(wo);
            *weight = v3s(1.0f);
            *pdf = r;
            return true;
        }
        vec3 w;
        if (!pbsdf__refract(wo, v3(0.0f, 0.0f, 1.0f), b->ior, &w)) return false;
        const vec3 share = pbsdf__mrv_share(b, wo.z > 0.0f ? wo : w);
        *wi = w;
        if (wo.z < 0.0f) { /* f / p = (1 - r) share / (1 - r) */
            *weight = share;
            *pdf = 1.0f - r;
        } else {
            *weight = v3_scale(share, (1.0f - r) / prob);
            *pdf = prob;
        }
        return true;
    }
    vec3 m = pbsdf_mf_sample(&g, wo, u1, u2);
    if (!(v3_dot(wo, m) * wo.z > 0.0f)) return false;
    const float r = pbsdf_fresnel_dielectric(v3_dot(wo, m), b->ior);
    vec3 w;
    if (u0 < r) {
        w = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
        if (!(w.z * wo.z > 0.0f)) return false;
    } else {
        if (!pbsdf__refract(wo, m, b->ior, &w) || !(w.z * wo.z < 0.0f)) return false;
    }
    const float p = pbsdf__mrv_pdf(b, wo, w);
    if (!(p > 0.0f)) return false;
    *wi = w;
    *pdf = p;
    *weight = v3_scale(pbsdf__mrv_eval(b, wo, w), 1.0f / p);
    return true;
}

/* ---- thin dielectric, diffuse transmission, Oren-Nayar, modified Phong ---- */

/* These four are two-sided where they transmit (the thin dielectric and the
 * diffuse transmitter: wo on either side, mirrored to +z and back) and
 * one-sided reflectors otherwise (Oren-Nayar, Phong: wo.z > 0, wi.z > 0).
 * docs/materials.md describes the models. */

/* A smooth thin sheet of relative index ior (pbrt-v4's ThinDielectricBxDF,
 * Mitsuba's thindielectric): light reflects off it by the sheet's
 * reflectance R' (pbsdf_thin_reflectance) and passes straight through,
 * undeviated, with T' = 1 - R', tinted by transmittance. Both lobes are
 * delta lobes. */
static inline PK_HD pbsdf pbsdf_thin_dielectric(float ior, vec3 transmittance)
{
    pbsdf b = pbsdf__blank(PBSDF_THIN_DIELECTRIC);
    b.ior = ior;
    b.transmittance = transmittance;
    return b;
}
/* Lambertian reflection of albedo r on the side of wo and Lambertian
 * transmission of t to the other side (pbrt-v4's DiffuseTransmissionBxDF);
 * r + t <= 1 per channel conserves energy. */
static inline PK_HD pbsdf pbsdf_diffuse_transmission(vec3 r, vec3 t)
{
    pbsdf b = pbsdf__blank(PBSDF_DIFFUSE_TRANSMISSION);
    b.albedo = r;
    b.transmittance = t;
    return b;
}
/* Oren-Nayar's qualitative model of a rough diffuse surface of albedo and
 * facet-slope deviation sigma (radians): f = albedo / pi (A + B
 * max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta)), alpha the larger polar
 * angle, beta the smaller, A = 1 - sigma^2 / (2 (sigma^2 + 0.33)),
 * B = 0.45 sigma^2 / (sigma^2 + 0.09). sigma = 0 is Lambert. */
static inline PK_HD pbsdf pbsdf_oren_nayar(vec3 albedo, float sigma)
{
    pbsdf b = pbsdf__blank(PBSDF_OREN_NAYAR);
    const float s2 = sigma * sigma;
    b.albedo = albedo;
    b.on_a = 1.0f - 0.5f * s2 / (s2 + 0.33f);
    b.on_b = 0.45f * s2 / (s2 + 0.09f);
    return b;
}
/* The modified (energy-normalised) Phong model, as Mitsuba's phong:
 * f = kd / pi + ks (n + 2) / (2 pi) max(0, wi . mirror(wo))^n. */
static inline PK_HD pbsdf pbsdf_phong(vec3 kd, vec3 ks, float exponent)
{
    pbsdf b = pbsdf__blank(PBSDF_PHONG);
    b.albedo = kd;
    b.specular = ks;
    b.exponent = exponent;
    return b;
}

/* The thin sheet's reflectance toward cos_o (either side): with R the
 * Fresnel reflectance of one face and T = 1 - R, light bounces between the
 * faces, R' = R + T^2 R / (1 - R^2). */
static inline PK_HD float pbsdf_thin_reflectance(float cos_o, float ior)
{
    float r = pbsdf_fresnel_dielectric(fabsf(cos_o), ior);
    if (r < 1.0f) {
        const float t = 1.0f - r;
        r += t * t * r / (1.0f - r * r);
    }
    return r;
}

/* The probability of sampling the diffuse transmitter's reflection. */
static inline PK_HD float pbsdf__dt_prob(const pbsdf *b)
{
    const float r = pbsdf__mean(b->albedo), t = pbsdf__mean(b->transmittance);
    return r + t > 0.0f ? r / (r + t) : 0.5f;
}
/* The Phong lobe's sampling probability (Mitsuba's specular sampling
 * weight: the mean specular over the mean of both). */
static inline PK_HD float pbsdf__phong_prob(const pbsdf *b)
{
    const float d = pbsdf__mean(b->albedo), s = pbsdf__mean(b->specular);
    return d + s > 0.0f ? s / (d + s) : 0.5f;
}
/* Oren-Nayar's factor A + B max(0, cos(dphi)) sin(alpha) tan(beta) for
 * wo.z > 0, wi.z > 0. */
static inline PK_HD float pbsdf__on_factor(const pbsdf *b, vec3 wo, vec3 wi)
{
    const float so = sqrtf(fmaxf(0.0f, 1.0f - wo.z * wo.z)), si = sqrtf(fmaxf(0.0f, 1.0f - wi.z * wi.z));
    float cphi = 0.0f;
    if (so > 1e-4f && si > 1e-4f) cphi = fmaxf(0.0f, (wi.x * wo.x + wi.y * wo.y) / (so * si));
    /* alpha = max(theta_i, theta_o), beta = min: the larger cosine is beta's */
    const float sin_a = wi.z > wo.z ? so : si, tan_b = wi.z > wo.z ? si / wi.z : so / wo.z;
    return b->on_a + b->on_b * cphi * sin_a * tan_b;
}
/* The Phong lobe's density about the mirror direction of wo (per solid
 * angle of wi): (n + 1) / (2 pi) cos^n. */
static inline PK_HD float pbsdf__phong_lobe_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    const float c = v3_dot(wi, pbsdf__mirror(wo));
    return c > 0.0f ? (b->exponent + 1.0f) * (0.5f / PK_PI) * powf(c, b->exponent) : 0.0f;
}

static inline PK_HD vec3 pbsdf__ext_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (b->type == PBSDF_DIFFUSE_TRANSMISSION) {
        if (wo.z < 0.0f) wo = pbsdf__mirror_z(wo), wi = pbsdf__mirror_z(wi);
        if (!(wo.z > 0.0f) || wi.z == 0.0f) return v3s(0.0f);
        return wi.z > 0.0f ? v3_scale(b->albedo, wi.z / PK_PI) : v3_scale(b->transmittance, -wi.z / PK_PI);
    }
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return v3s(0.0f);
    if (b->type == PBSDF_OREN_NAYAR) return v3_scale(b->albedo, pbsdf__on_factor(b, wo, wi) * wi.z / PK_PI);
    if (b->type == PBSDF_PHONG) {
        vec3 r = v3_scale(b->albedo, wi.z / PK_PI);
        const float c = v3_dot(wi, pbsdf__mirror(wo));
        if (c > 0.0f)
            r = v3_add(r, v3_scale(b->specular, (b->exponent + 2.0f) * (0.5f / PK_PI) * powf(c, b->exponent) * wi.z));
        return r;
    }
    return v3s(0.0f); /* the thin dielectric: delta lobes only */
}

static inline PK_HD float pbsdf__ext_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (b->type == PBSDF_DIFFUSE_TRANSMISSION) {
        if (wo.z < 0.0f) wo = pbsdf__mirror_z(wo), wi = pbsdf__mirror_z(wi);
        if (!(wo.z > 0.0f) || wi.z == 0.0f) return 0.0f;
        const float pr = pbsdf__dt_prob(b);
        return wi.z > 0.0f ? pr * wi.z / PK_PI : (1.0f - pr) * -wi.z / PK_PI;
    }
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    if (b->type == PBSDF_OREN_NAYAR) return wi.z / PK_PI;
    if (b->type == PBSDF_PHONG) {
        const float ps = pbsdf__phong_prob(b);
        return ps * pbsdf__phong_lobe_pdf(b, wo, wi) + (1.0f - ps) * wi.z / PK_PI;
    }
    return 0.0f;
}

/* A cosine-weighted direction about +z. */
static inline PK_HD vec3 pbsdf__cosine_dir(float u1, float u2)
{
    const float r = sqrtf(u1), phi = 2.0f * PK_PI * u2;
    return v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u1)));
}

static inline PK_HD bool pbsdf__ext_sample(const pbsdf *b, vec3 wo, const float u[3], vec3 *wi, vec3 *weight,
                                           float *pdf, bool *is_delta)
{
    *is_delta = false;
    if (b->type == PBSDF_THIN_DIELECTRIC) {
        if (wo.z == 0.0f) return false;
        const float r = pbsdf_thin_reflectance(wo.z, b->ior);
        *is_delta = true;
        if (u[0] < r) {
            *wi = pbsdf__mirror(wo);
            *weight = v3s(1.0f);
            *pdf = r;
        } else {
            *wi = v3_neg(wo);
            *weight = b->transmittance;
            *pdf = 1.0f - r;
        }
        return true;
    }
    if (b->type == PBSDF_DIFFUSE_TRANSMISSION) {
        const bool flip = wo.z < 0.0f;
        if (wo.z == 0.0f || !(pbsdf__mean(b->albedo) + pbsdf__mean(b->transmittance) > 0.0f)) return false;
        const float pr = pbsdf__dt_prob(b);
        vec3 w = pbsdf__cosine_dir(u[1], u[2]);
        if (!(w.z > 0.0f)) return false;
        if (u[0] < pr) {
            *weight = v3_scale(b->albedo, 1.0f / pr);
            *pdf = pr * w.z / PK_PI;
        } else {
            *weight = v3_scale(b->transmittance, 1.0f / (1.0f - pr));
            *pdf = (1.0f - pr) * w.z / PK_PI;
            w = pbsdf__mirror_z(w);
        }
        *wi = flip ? pbsdf__mirror_z(w) : w;
        return true;
    }
    if (!(wo.z > 0.0f)) return false;
    vec3 w;
    if (b->type == PBSDF_PHONG && u[0] < pbsdf__phong_prob(b)) {
        /* cos^n about the mirror direction, in a basis around it */
        const vec3 n = pbsdf__mirror(wo);
        const float sg = n.z >= 0.0f ? 1.0f : -1.0f, a = -1.0f / (sg + n.z), c = n.x * n.y * a;
        const vec3 t = v3(1.0f + sg * n.x * n.x * a, sg * c, -sg * n.x), bt = v3(c, sg + n.y * n.y * a, -n.y);
        const float ca = powf(u[1], 1.0f / (b->exponent + 1.0f)), sa = sqrtf(fmaxf(0.0f, 1.0f - ca * ca));
        const float phi = 2.0f * PK_PI * u[2];
        w = v3_norm(v3_add(v3_add(v3_scale(t, sa * cosf(phi)), v3_scale(bt, sa * sinf(phi))), v3_scale(n, ca)));
    } else {
        w = pbsdf__cosine_dir(u[1], u[2]);
    }
    if (!(w.z > 0.0f)) return false;
    *wi = w;
    if (b->type == PBSDF_OREN_NAYAR) { /* f cos / pdf = albedo (A + B ...): Lambert's weight at sigma 0 */
        *pdf = w.z / PK_PI;
        *weight = v3_scale(b->albedo, pbsdf__on_factor(b, wo, w));
        return true;
    }
    const float p = pbsdf__ext_pdf(b, wo, w);
    if (!(p > 0.0f)) return false;
    *pdf = p;
    *weight = v3_scale(pbsdf__ext_eval(b, wo, w), 1.0f / p);
    return true;
}

/* ---- coated: pbrt-v4's stochastic layered BSDF ------------------------------ */

/* A dielectric coat of relative index ior (GGX alpha, smooth below
 * PBSDF_ALPHA_SMOOTH) over a base (Lambert of albedo, or with
 * PBSDF_COATED_METAL a conductor of eta + i k relative to the coat and GGX
 * base_alpha), with a slab of `thickness` between them that holds a
 * homogeneous medium of unit extinction, single-scattering albedo `medium`
 * and Henyey-Greenstein asymmetry g (medium 0: clear, light crossing it
 * attenuated by exp(-thickness / |cos|)). eval, pdf and sample are pbrt-v4's
 * LayeredBxDF estimators (docs/materials.md): random walks between the two
 * interfaces, at most maxdepth scattering events each, nsamples of them
 * averaged, with next-event connections through the coat combined by the
 * power heuristic (each weight from the two densities of the same inside
 * direction: where pbrt-v4 weighs the walk's exit by the density of wi
 * given the inside direction, the reverse of what the connection from wi
 * samples, this uses the forward one, so the weights sum to 1:
 * test_layered checks eval against an independent walk); the pdf is
 * estimated from one bounce off the base and
 * mixed with a uniform density (0.1 / (4 pi)). The walks draw their numbers
 * from a PCG32 seeded by a hash of the directions and `seed` (the hit), so
 * no sampler dimension is used and the same (wo, wi, seed) gives the same
 * value. The material is two-sided: wo below is mirrored to +z with wi.
 * The transmitted light's 1 / eta^2 is applied here as pbrt applies it in
 * radiance mode (only the product of the factors through the coat matters,
 * and it is 1: a white base under a clear coat reflects all of the light). */
static inline PK_HD pbsdf pbsdf_coated(vec3 albedo, float ior, float alpha, float thickness, vec3 slab_albedo,
                                       float g, int maxdepth, int nsamples)
{
    pbsdf b = pbsdf__blank(PBSDF_COATED);
    b.albedo = albedo;
    b.ior = ior;
    b.alpha = alpha;
    b.transmittance = v3s(1.0f); /* the coat's dielectric lobes are clear */
    b.thickness = thickness;
    b.medium = slab_albedo;
    b.g = g;
    b.maxdepth = maxdepth;
    b.nsamples = nsamples;
    return b;
}
/* The same over a conductor of eta + i k (relative to the coat) and GGX
 * base_alpha. */
static inline PK_HD pbsdf pbsdf_coated_conductor(vec3 eta, vec3 k, float base_alpha, float ior, float alpha,
                                                 float thickness, vec3 slab_albedo, float g, int maxdepth,
                                                 int nsamples)
{
    pbsdf b = pbsdf_coated(v3s(0.0f), ior, alpha, thickness, slab_albedo, g, maxdepth, nsamples);
    b.flags |= PBSDF_COATED_METAL;
    b.eta = eta;
    b.k = k;
    b.base_alpha = base_alpha;
    return b;
}

/* One sampled direction of an interface: wi, f (without the cosine), pdf
 * and whether it came from a delta lobe. */
typedef struct pbsdf__lsample {
    vec3 wi, f;
    float pdf;
    bool spec;
} pbsdf__lsample;

#define PBSDF__LREFL 1
#define PBSDF__LTRANS 2

static inline PK_HD float pbsdf__power(float a, float b)
{
    const float a2 = a * a, b2 = b * b;
    if (!(a2 < INFINITY)) return 1.0f;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}
/* exp(-|dz / cos|): the slab's transmittance over a height dz along w */
static inline PK_HD float pbsdf__lay_tr(float dz, vec3 w)
{
    if (fabsf(dz) <= 1e-30f) return 1.0f;
    return expf(-fabsf(dz / w.z));
}
/* Henyey-Greenstein for a walk travelling along d turning to wi. */
static inline PK_HD float pbsdf__hg(float g, vec3 d, vec3 wi)
{
    const float c = v3_dot(d, wi), den = 1.0f + g * g - 2.0f * g * c;
    return (1.0f - g * g) / (4.0f * PK_PI * den * sqrtf(fmaxf(den, 1e-12f)));
}
static inline PK_HD vec3 pbsdf__hg_sample(float g, vec3 d, float u1, float u2)
{
    float c;
    if (fabsf(g) < 1e-3f) c = 1.0f - 2.0f * u1;
    else {
        const float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u1);
        c = (1.0f + g * g - s * s) / (2.0f * g);
    }
    c = fminf(1.0f, fmaxf(-1.0f, c));
    const float sn = sqrtf(fmaxf(0.0f, 1.0f - c * c)), phi = 2.0f * PK_PI * u2;
    const float sg = d.z >= 0.0f ? 1.0f : -1.0f, a = -1.0f / (sg + d.z), bb = d.x * d.y * a;
    const vec3 t = v3(1.0f + sg * d.x * d.x * a, sg * bb, -sg * d.x), bt = v3(bb, sg + d.y * d.y * a, -d.y);
    return v3_norm(v3_add(v3_add(v3_scale(t, sn * cosf(phi)), v3_scale(bt, sn * sinf(phi))), v3_scale(d, c)));
}

/* The coat (a dielectric, wo on either side: below is inside). f is without
 * the cosine; rad applies the radiance-mode 1 / eta'^2 to transmission. */
static inline PK_HD float pbsdf__coat_f(const pbsdf *b, vec3 wo, vec3 wi, bool rad)
{
    if (pbsdf__smooth(b) || wi.z == 0.0f) return 0.0f;
    float f = pbsdf__dielectric_eval(b, wo, wi).x / fabsf(wi.z);
    if (rad && wo.z * wi.z < 0.0f) f *= wo.z > 0.0f ? 1.0f / (b->ior * b->ior) : b->ior * b->ior;
    return f;
}
static inline PK_HD float pbsdf__coat_pdf(const pbsdf *b, vec3 wo, vec3 wi, int want)
{
    vec3 m;
    float e;
    if (pbsdf__smooth(b) || !pbsdf__dielectric_half(b, wo, wi, &m, &e)) return 0.0f;
    const bool refl = wo.z * wi.z > 0.0f;
    if (!(want & (refl ? PBSDF__LREFL : PBSDF__LTRANS))) return 0.0f;
    const float r = pbsdf_fresnel_dielectric(v3_dot(wo, m), b->ior);
    const float pr = (want & PBSDF__LREFL) ? r : 0.0f, pt = (want & PBSDF__LTRANS) ? 1.0f - r : 0.0f;
    if (!(pr + pt > 0.0f)) return 0.0f;
    return pbsdf__dielectric_pdf(b, wo, wi) / (pr + pt);
}
static inline PK_HD bool pbsdf__coat_sample(const pbsdf *b, vec3 wo, float uc, float u1, float u2, int want, bool rad,
                                            pbsdf__lsample *s)
{
    if (wo.z == 0.0f) return false;
    if (pbsdf__smooth(b)) {
        const float r = pbsdf_fresnel_dielectric(wo.z, b->ior);
        const float pr = (want & PBSDF__LREFL) ? r : 0.0f, pt = (want & PBSDF__LTRANS) ? 1.0f - r : 0.0f;
        if (!(pr + pt > 0.0f)) return false;
        s->spec = true;
        if (uc < pr / (pr + pt)) {
            s->wi = pbsdf__mirror(wo);
            s->f = v3s(r / fabsf(s->wi.z));
            s->pdf = pr / (pr + pt);
            return s->wi.z != 0.0f;
        }
        if (!pbsdf__refract(wo, v3(0.0f, 0.0f, 1.0f), b->ior, &s->wi) || s->wi.z == 0.0f) return false;
        float t = (1.0f - r) / fabsf(s->wi.z);
        if (rad) t *= wo.z > 0.0f ? 1.0f / (b->ior * b->ior) : b->ior * b->ior;
        s->f = v3s(t);
        s->pdf = pt / (pr + pt);
        return true;
    }
    const vec3 m = pbsdf_ggx_vndf_sample(b->alpha, wo, u1, u2);
    const float om = v3_dot(wo, m);
    if (!(om * wo.z > 0.0f)) return false;
    const float r = pbsdf_fresnel_dielectric(om, b->ior);
    const float pr = (want & PBSDF__LREFL) ? r : 0.0f, pt = (want & PBSDF__LTRANS) ? 1.0f - r : 0.0f;
    if (!(pr + pt > 0.0f)) return false;
    vec3 w;
    if (uc < pr / (pr + pt)) {
        w = v3_sub(v3_scale(m, 2.0f * om), wo);
        if (!(w.z * wo.z > 0.0f)) return false;
    } else if (!pbsdf__refract(wo, m, b->ior, &w) || !(w.z * wo.z < 0.0f)) {
        return false;
    }
    s->spec = false;
    s->wi = w;
    s->pdf = pbsdf__coat_pdf(b, wo, w, want);
    s->f = v3s(pbsdf__coat_f(b, wo, w, rad));
    return s->pdf > 0.0f;
}

/* The base (wo.z > 0 from inside the slab; reflection only). */
static inline PK_HD bool pbsdf__base_smooth(const pbsdf *b)
{
    return (b->flags & PBSDF_COATED_METAL) && b->base_alpha < PBSDF_ALPHA_SMOOTH;
}
static inline PK_HD vec3 pbsdf__base_fresnel(const pbsdf *b, float c)
{
    return v3(pbsdf__fresnel_conductor1(c, b->eta.x, b->k.x), pbsdf__fresnel_conductor1(c, b->eta.y, b->k.y),
              pbsdf__fresnel_conductor1(c, b->eta.z, b->k.z));
}
static inline PK_HD vec3 pbsdf__base_f(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return v3s(0.0f);
    if (!(b->flags & PBSDF_COATED_METAL)) return v3_scale(b->albedo, 1.0f / PK_PI);
    if (pbsdf__base_smooth(b)) return v3s(0.0f);
    vec3 h;
    const float s = pbsdf__ggx_refl_cos(b->base_alpha, wo, wi, &h);
    if (!(s > 0.0f)) return v3s(0.0f);
    return v3_scale(pbsdf__base_fresnel(b, fabsf(v3_dot(wo, h))), s / wi.z);
}
static inline PK_HD float pbsdf__base_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    if (!(b->flags & PBSDF_COATED_METAL)) return wi.z / PK_PI;
    if (pbsdf__base_smooth(b)) return 0.0f;
    return pbsdf__ggx_refl_pdf(b->base_alpha, wo, wi);
}
static inline PK_HD bool pbsdf__base_sample(const pbsdf *b, vec3 wo, float u1, float u2, pbsdf__lsample *s)
{
    if (!(wo.z > 0.0f)) return false;
    s->spec = false;
    if (!(b->flags & PBSDF_COATED_METAL)) {
        s->wi = pbsdf__cosine_dir(u1, u2);
        if (!(s->wi.z > 0.0f)) return false;
        s->pdf = s->wi.z / PK_PI;
        s->f = v3_scale(b->albedo, 1.0f / PK_PI);
        return true;
    }
    if (pbsdf__base_smooth(b)) {
        s->wi = pbsdf__mirror(wo);
        s->f = v3_scale(pbsdf__base_fresnel(b, wo.z), 1.0f / wo.z);
        s->pdf = 1.0f;
        s->spec = true;
        return true;
    }
    const vec3 m = pbsdf_ggx_vndf_sample(b->base_alpha, wo, u1, u2);
    const float om = v3_dot(wo, m);
    s->wi = v3_sub(v3_scale(m, 2.0f * om), wo);
    if (!(om > 0.0f) || !(s->wi.z > 0.0f)) return false;
    s->pdf = pbsdf__ggx_refl_pdf(b->base_alpha, wo, s->wi);
    s->f = pbsdf__base_f(b, wo, s->wi);
    return s->pdf > 0.0f;
}

/* The walks' generator, seeded by two hashes of the directions and the hit. */
static inline PK_HD uint64_t pbsdf__hash3(vec3 w, unsigned seed)
{
    union {
        float f;
        uint32_t u;
    } x, y, z;
    x.f = w.x, y.f = w.y, z.f = w.z;
    uint64_t h = mix64(((uint64_t)x.u << 32) ^ y.u ^ ((uint64_t)seed << 17));
    return mix64(h ^ ((uint64_t)z.u * 0x9e3779b97f4a7c15ull));
}
static inline PK_HD float pbsdf__r(rng *r) { return rng_float(r); }
static inline PK_HD bool pbsdf__clear(const pbsdf *b) { return !(v3_max_comp(b->medium) > 0.0f); }

/* f cos of the layered BSDF (pbrt-v4's LayeredBxDF::f, reflection only:
 * the bases are opaque). */
static inline PBSDF_CALLED PK_HD vec3 pbsdf__coated_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (wo.z < 0.0f) wo = v3_neg(wo), wi = v3_neg(wi);
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return v3s(0.0f);
    const int ns = b->nsamples > 0 ? b->nsamples : 1;
    const float th = b->thickness, ez = th; /* the coat is the exit: z = thickness */
    const bool top_spec = pbsdf__smooth(b), base_spec = pbsdf__base_smooth(b), clear = pbsdf__clear(b);
    vec3 f = v3s((float)ns * pbsdf__coat_f(b, wo, wi, true));
    rng r = rng_seed(pbsdf__hash3(wo, b->seed), pbsdf__hash3(wi, ~b->seed));
    for (int s = 0; s < ns; s++) {
        pbsdf__lsample wos, wis;
        if (!pbsdf__coat_sample(b, wo, pbsdf__r(&r), pbsdf__r(&r), pbsdf__r(&r), PBSDF__LTRANS, true, &wos) ||
            !(wos.pdf > 0.0f) || wos.wi.z == 0.0f)
            continue;
        if (!pbsdf__coat_sample(b, wi, pbsdf__r(&r), pbsdf__r(&r), pbsdf__r(&r), PBSDF__LTRANS, false, &wis) ||
            !(wis.pdf > 0.0f) || wis.wi.z == 0.0f)
            continue;
        vec3 beta = v3_scale(wos.f, fabsf(wos.wi.z) / wos.pdf);
        const vec3 wisw = v3_scale(wis.f, 1.0f / wis.pdf); /* wis.f / wis.pdf */
        float z = th;
        vec3 w = wos.wi;
        for (int depth = 0; depth < b->maxdepth; depth++) {
            const float bm = v3_max_comp(beta);
            if (depth > 3 && bm < 0.25f) {
                const float q = fmaxf(0.0f, 1.0f - bm);
                if (pbsdf__r(&r) < q) break;
                beta = v3_scale(beta, 1.0f / (1.0f - q));
            }
            if (clear) {
                z = z == th ? 0.0f : th;
                beta = v3_scale(beta, pbsdf__lay_tr(th, w));
            } else {
                const float dz = -logf(1.0f - pbsdf__r(&r)) * fabsf(w.z);
                const float zp = w.z > 0.0f ? z + dz : z - dz;
                if (zp == z) continue;
                if (0.0f < zp && zp < th) { /* scattered in the slab */
                    const vec3 din = v3_neg(wis.wi);
                    float wt = 1.0f;
                    if (!top_spec) wt = pbsdf__power(wis.pdf, pbsdf__hg(b->g, w, din));
                    f = v3_add(f, v3_scale(v3_mul(v3_mul(beta, b->medium), wisw),
                                           pbsdf__hg(b->g, w, din) * wt * pbsdf__lay_tr(zp - ez, wis.wi)));
                    const vec3 nw = pbsdf__hg_sample(b->g, w, pbsdf__r(&r), pbsdf__r(&r));
                    if (nw.z == 0.0f) continue;
                    const float pp = pbsdf__hg(b->g, w, nw);
                    beta = v3_mul(beta, b->medium); /* p / pdf = 1 */
                    w = nw;
                    z = zp;
                    if (!top_spec && ((z < ez && w.z > 0.0f) || (z > ez && w.z < 0.0f))) {
                        const float fe = pbsdf__coat_f(b, v3_neg(w), wi, true);
                        if (fe > 0.0f) {
                            const float pe = pbsdf__coat_pdf(b, wi, v3_neg(w), PBSDF__LTRANS);
                            f = v3_add(f, v3_scale(beta, pbsdf__lay_tr(zp - ez, w) * fe * pbsdf__power(pp, pe)));
                        }
                    }
                    continue;
                }
                z = fminf(fmaxf(zp, 0.0f), th);
            }
            pbsdf__lsample bs;
            if (z == ez) { /* back down off the coat's underside */
                if (!pbsdf__coat_sample(b, v3_neg(w), pbsdf__r(&r), pbsdf__r(&r), pbsdf__r(&r), PBSDF__LREFL, true, &bs))
                    break;
                beta = v3_mul(beta, v3_scale(bs.f, fabsf(bs.wi.z) / bs.pdf));
                w = bs.wi;
                continue;
            }
            /* at the base: connect to wi through the coat, then bounce */
            if (!base_spec) {
                float wt = 1.0f;
                if (!top_spec) wt = pbsdf__power(wis.pdf, pbsdf__base_pdf(b, v3_neg(w), v3_neg(wis.wi)));
                const vec3 fb = pbsdf__base_f(b, v3_neg(w), v3_neg(wis.wi));
                f = v3_add(f, v3_scale(v3_mul(v3_mul(beta, fb), wisw),
                                       fabsf(wis.wi.z) * wt * pbsdf__lay_tr(th, wis.wi)));
            }
            (void)pbsdf__r(&r); /* pbrt's lobe choice: one number, unused by one-lobe bases */
            if (!pbsdf__base_sample(b, v3_neg(w), pbsdf__r(&r), pbsdf__r(&r), &bs)) break;
            beta = v3_mul(beta, v3_scale(bs.f, fabsf(bs.wi.z) / bs.pdf));
            w = bs.wi;
            if (!top_spec) {
                const float fe = pbsdf__coat_f(b, v3_neg(w), wi, true);
                if (fe > 0.0f) {
                    float wt = 1.0f;
                    if (!base_spec) wt = pbsdf__power(bs.pdf, pbsdf__coat_pdf(b, wi, v3_neg(w), PBSDF__LTRANS));
                    f = v3_add(f, v3_scale(beta, pbsdf__lay_tr(th, bs.wi) * fe * wt));
                }
            }
        }
    }
    return v3_scale(f, wi.z / (float)ns);
}

/* The estimated density of pbsdf__coated_sample (pbrt-v4's LayeredBxDF::PDF):
 * the coat's reflection and one bounce off the base through the coat, mixed
 * with a uniform density. */
static inline PBSDF_CALLED PK_HD float pbsdf__coated_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (wo.z < 0.0f) wo = v3_neg(wo), wi = v3_neg(wi);
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    const int ns = b->nsamples > 0 ? b->nsamples : 1;
    const bool top_spec = pbsdf__smooth(b), base_spec = pbsdf__base_smooth(b);
    float sum = (float)ns * pbsdf__coat_pdf(b, wo, wi, PBSDF__LREFL | PBSDF__LTRANS);
    rng r = rng_seed(pbsdf__hash3(wi, b->seed ^ 0x5bd1e995u), pbsdf__hash3(wo, ~b->seed));
    for (int s = 0; s < ns; s++) {
        pbsdf__lsample wos, wis, rs;
        if (!pbsdf__coat_sample(b, wo, pbsdf__r(&r), pbsdf__r(&r), pbsdf__r(&r), PBSDF__LTRANS, true, &wos) ||
            !(wos.pdf > 0.0f))
            continue;
        if (!pbsdf__coat_sample(b, wi, pbsdf__r(&r), pbsdf__r(&r), pbsdf__r(&r), PBSDF__LTRANS, false, &wis) ||
            !(wis.pdf > 0.0f))
            continue;
        if (top_spec) {
            sum += pbsdf__base_pdf(b, v3_neg(wos.wi), v3_neg(wis.wi));
            continue;
        }
        (void)pbsdf__r(&r);
        if (!pbsdf__base_sample(b, v3_neg(wos.wi), pbsdf__r(&r), pbsdf__r(&r), &rs) || !(rs.pdf > 0.0f)) continue;
        if (base_spec) {
            sum += pbsdf__coat_pdf(b, v3_neg(rs.wi), wi, PBSDF__LREFL | PBSDF__LTRANS);
        } else {
            const float rp = pbsdf__base_pdf(b, v3_neg(wos.wi), v3_neg(wis.wi));
            sum += pbsdf__power(wis.pdf, rp) * rp;
            const float tp = pbsdf__coat_pdf(b, v3_neg(rs.wi), wi, PBSDF__LREFL | PBSDF__LTRANS);
            sum += pbsdf__power(rs.pdf, tp) * tp;
        }
    }
    return 0.1f / (4.0f * PK_PI) + 0.9f * sum / (float)ns;
}

/* Samples by one random walk (pbrt-v4's LayeredBxDF::Sample_f): the weight
 * is the walk's f cos / pdf, an unbiased estimate of the BSDF's; *pdf is
 * pbsdf_pdf's estimate (for MIS), or for an all-delta walk the product of
 * its lobes' probabilities. */
static inline PBSDF_CALLED PK_HD bool pbsdf__coated_sample(const pbsdf *b, vec3 wo, const float u[3], vec3 *wi, vec3 *weight,
                                              float *pdf, bool *is_delta)
{
    *is_delta = false;
    const bool flip = wo.z < 0.0f;
    if (flip) wo = v3_neg(wo);
    if (!(wo.z > 0.0f)) return false;
    pbsdf__lsample bs;
    if (!pbsdf__coat_sample(b, wo, u[0], u[1], u[2], PBSDF__LREFL | PBSDF__LTRANS, true, &bs) || !(bs.pdf > 0.0f))
        return false;
    if (bs.wi.z > 0.0f) { /* reflected by the coat */
        *wi = flip ? v3_neg(bs.wi) : bs.wi;
        *weight = v3_scale(bs.f, bs.wi.z / bs.pdf);
        *is_delta = bs.spec;
        *pdf = bs.spec ? bs.pdf : pbsdf__coated_pdf(b, wo, bs.wi);
        return true;
    }
    vec3 w = bs.wi, f = v3_scale(bs.f, fabsf(bs.wi.z));
    float p = bs.pdf, z = b->thickness;
    const float th = b->thickness;
    bool spec = bs.spec;
    const bool clear = pbsdf__clear(b);
    union {
        float f;
        uint32_t u;
    } a, c, d;
    a.f = u[0], c.f = u[1], d.f = u[2];
    rng r = rng_seed(pbsdf__hash3(wo, b->seed), mix64(((uint64_t)a.u << 32 | c.u) ^ mix64(d.u)));
    for (int depth = 0; depth < b->maxdepth; depth++) {
        const float rb = v3_max_comp(f) / p;
        if (depth > 3 && rb < 0.25f) {
            const float q = fmaxf(0.0f, 1.0f - rb);
            if (pbsdf__r(&r) < q) return false;
            p *= 1.0f - q;
        }
        if (w.z == 0.0f) return false;
        if (!clear) {
            const float dz = -logf(1.0f - pbsdf__r(&r)) * fabsf(w.z);
            const float zp = w.z > 0.0f ? z + dz : z - dz;
            if (zp == z) return false;
            if (0.0f < zp && zp < th) {
                const vec3 nw = pbsdf__hg_sample(b->g, w, pbsdf__r(&r), pbsdf__r(&r));
                const float pp = pbsdf__hg(b->g, w, nw);
                if (!(pp > 0.0f) || nw.z == 0.0f) return false;
                f = v3_scale(v3_mul(f, b->medium), pp);
                p *= pp;
                spec = false;
                w = nw;
                z = zp;
                continue;
            }
            z = fminf(fmaxf(zp, 0.0f), th);
        } else {
            z = z == th ? 0.0f : th;
            f = v3_scale(f, pbsdf__lay_tr(th, w));
        }
        if (z == 0.0f) {
            (void)pbsdf__r(&r);
            if (!pbsdf__base_sample(b, v3_neg(w), pbsdf__r(&r), pbsdf__r(&r), &bs)) return false;
        } else if (!pbsdf__coat_sample(b, v3_neg(w), pbsdf__r(&r), pbsdf__r(&r), pbsdf__r(&r),
                                       PBSDF__LREFL | PBSDF__LTRANS, true, &bs)) {
            return false;
        }
        if (!(bs.pdf > 0.0f)) return false;
        f = v3_mul(f, bs.f);
        p *= bs.pdf;
        spec = spec && bs.spec;
        w = bs.wi;
        if (z == th && w.z > 0.0f) { /* out through the coat */
            *wi = flip ? v3_neg(w) : w;
            *weight = v3_scale(f, w.z / p);
            *is_delta = spec;
            *pdf = spec ? p : pbsdf__coated_pdf(b, wo, w);
            return true;
        }
        f = v3_scale(f, fabsf(w.z));
    }
    return false;
}

/* ---- Mitsuba 3's principled BSDF ------------------------------------------- */

/* Mitsuba 3's "principled" (its reading of Burley's Disney BSDF, 2012/2015),
 * lobe by lobe as Mitsuba defines it (docs/materials.md): a Disney diffuse
 * with retro-reflection and the flatness blend, sheen, a GGX specular lobe
 * (anisotropic: PBSDF_ANISO, alpha along x, alpha_v along y) whose Fresnel blends the dielectric's, a metal's (Schlick,
 * F0 = base colour) and a tinted Schlick one, a rough dielectric
 * transmission tinted by sqrt(base colour), and a GTR1 clearcoat. Fields:
 * albedo = base colour, metallic, transmission = spec_trans, ior = eta,
 * alpha (, alpha_v) = GGX alphas, roughness (the diffuse's), coat = clearcoat, coat_alpha
 * = the GTR1 alpha, and pr_* below. wo.z < 0 is the inside (the frame is the
 * outward normal as for the dielectric); there only the specular reflection
 * and transmission scatter, as in Mitsuba. */
static inline PK_HD pbsdf pbsdf_principled(vec3 base_color, float metallic, float roughness, float ax, float ay,
                                           float spec_trans, float eta)
{
    pbsdf b = pbsdf__blank(PBSDF_PRINCIPLED);
    b.albedo = base_color;
    b.metallic = metallic;
    b.roughness = roughness;
    b.alpha = ax; /* GGX along the local x axis (dp/du) and, where they differ, alpha_v = ay along y */
    if (ay != ax) {
        b.alpha_v = ay;
        b.flags |= PBSDF_ANISO;
    }
    b.transmission = spec_trans;
    b.ior = eta;
    return b;
}

static inline PK_HD float pbsdf__pr_lum(vec3 c) { return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z; }
/* Schlick's Fresnel as Mitsuba's principled has it: the cosine on the
 * optically thinner side (cos_i's own side when light enters the denser). */
static inline PK_HD float pbsdf__pr_schlick_w(float cos_i, float eta)
{
    const float eta_it = cos_i >= 0.0f ? eta : 1.0f / eta;
    if (eta_it > 1.0f) return pbsdf__schlick_w(fabsf(cos_i));
    const float ct2 = 1.0f - (1.0f - cos_i * cos_i) / (eta_it * eta_it);
    return pbsdf__schlick_w(sqrtf(fmaxf(0.0f, ct2)));
}
static inline PK_HD vec3 pbsdf__pr_schlick(vec3 r0, float w)
{
    return v3(r0.x + (1.0f - r0.x) * w, r0.y + (1.0f - r0.y) * w, r0.z + (1.0f - r0.z) * w);
}
/* GTR1 (Berry) of alpha a: D(m) and the sampling of m by D(m) m.z */
static inline PK_HD float pbsdf__gtr1_d(float a, vec3 m)
{
    const float a2 = a * a;
    const float d = (a2 - 1.0f) / (PK_PI * logf(a2) * (1.0f + (a2 - 1.0f) * m.z * m.z));
    return d * m.z > 1e-20f ? d : 0.0f;
}
static inline PK_HD vec3 pbsdf__gtr1_sample(float a, float u1, float u2)
{
    const float a2 = a * a, phi = 2.0f * PK_PI * u1;
    const float c2 = (1.0f - powf(a2, 1.0f - u2)) / (1.0f - a2);
    const float s = sqrtf(fmaxf(0.0f, 1.0f - c2)), c = sqrtf(fmaxf(0.0f, c2));
    return v3(cosf(phi) * s, sinf(phi) * s, c);
}
/* Smith's G1 of GGX with alpha a, 0 for a microfacet m seen from behind
 * (the clearcoat's), and the same of the main lobe (anisotropic or not) */
static inline PK_HD float pbsdf__pr_g1(float a, vec3 v, vec3 m)
{
    if (v3_dot(v, m) * v.z <= 0.0f) return 0.0f;
    return v.z == 1.0f ? 1.0f : pbsdf_ggx_g1(a, v);
}
static inline PK_HD float pbsdf__pr_g1m(const pbsdf *b, vec3 v, vec3 m)
{
    if (v3_dot(v, m) * v.z <= 0.0f) return 0.0f;
    return v.z == 1.0f ? 1.0f : 1.0f / (1.0f + pbsdf_mf_lambda(b, v));
}
/* The half vector of wo, wi (+z side), the relative index along the path,
 * whether it reflects, and the macro/micro compatibility of the pair. */
typedef struct pbsdf__pr_geo {
    vec3 h;
    float eta_path, f;
    bool reflect, refl_ok, refr_ok;
} pbsdf__pr_geo;
static inline PK_HD pbsdf__pr_geo pbsdf__pr_geometry(const pbsdf *b, vec3 wo, vec3 wi)
{
    pbsdf__pr_geo g;
    g.reflect = wo.z * wi.z > 0.0f;
    g.eta_path = wo.z > 0.0f ? b->ior : 1.0f / b->ior;
    vec3 h = v3_add(wo, v3_scale(wi, g.reflect ? 1.0f : g.eta_path));
    const float l2 = v3_len2(h);
    h = l2 > 0.0f ? v3_scale(h, 1.0f / sqrtf(l2)) : v3(0.0f, 0.0f, 1.0f);
    if (h.z < 0.0f) h = v3_neg(h);
    g.h = h;
    const vec3 hs = wo.z > 0.0f ? h : v3_neg(h);
    g.refl_ok = v3_dot(wo, hs) > 0.0f && v3_dot(wi, hs) > 0.0f;
    g.refr_ok = v3_dot(wo, hs) > 0.0f && v3_dot(wi, hs) < 0.0f;
    g.f = pbsdf_fresnel_dielectric(v3_dot(wo, h), b->ior);
    return g;
}
/* The probabilities of the lobes (diffuse, clearcoat, transmission,
 * reflection) for a dielectric Fresnel f, Mitsuba's sampling rates included. */
static inline PK_HD void pbsdf__pr_probs(const pbsdf *b, bool front, float f, float p[4])
{
    const float brdf = (1.0f - b->metallic) * (1.0f - b->transmission);
    const float bsdf = (1.0f - b->metallic) * b->transmission;
    if (front) {
        p[0] = brdf * b->pr_srate_diff;
        p[1] = 0.25f * b->coat * b->pr_srate_cc;
        p[2] = b->pr_srate_spec * bsdf * (1.0f - f);
        p[3] = b->pr_srate_spec * (1.0f - bsdf * (1.0f - f));
    } else {
        p[0] = p[1] = 0.0f;
        p[2] = bsdf > 0.0f ? 1.0f - f : 0.0f;
        p[3] = f;
    }
    const float t = p[0] + p[1] + p[2] + p[3];
    const float r = t > 0.0f ? 1.0f / t : 0.0f;
    for (int k = 0; k < 4; k++) p[k] *= r;
}

static inline PBSDF_CALLED PK_HD vec3 pbsdf__pr_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 v = v3s(0.0f);
    if (wo.z == 0.0f || wi.z == 0.0f) return v;
    const float brdf = (1.0f - b->metallic) * (1.0f - b->transmission);
    const float bsdf = (1.0f - b->metallic) * b->transmission;
    const bool front = wo.z > 0.0f;
    const pbsdf__pr_geo g = pbsdf__pr_geometry(b, wo, wi);
    const vec3 h = g.h, base = b->albedo;
    const float d = pbsdf_mf_d(b, h);
    const float gg = pbsdf__pr_g1m(b, wo, h) * pbsdf__pr_g1m(b, wi, h);
    const float oh = v3_dot(wo, h), ih = v3_dot(wi, h);
    if (g.reflect && g.refl_ok && g.f > 0.0f) {
        vec3 fr;
        if (front) {
            const float lum = pbsdf__pr_lum(base), eta_it = oh >= 0.0f ? b->ior : 1.0f / b->ior;
            const vec3 ctint = lum > 0.0f ? v3_scale(base, 1.0f / lum) : v3s(1.0f);
            const float r0 = (eta_it - 1.0f) / (eta_it + 1.0f), w = pbsdf__pr_schlick_w(oh, b->ior);
            fr = v3s((1.0f - b->metallic) * (1.0f - b->pr_spec_tint) * g.f);
            fr = v3_add(fr, v3_scale(pbsdf__pr_schlick(base, w), b->metallic));
            fr = v3_add(fr, v3_scale(pbsdf__pr_schlick(v3_scale(ctint, r0 * r0), w),
                                     (1.0f - b->metallic) * b->pr_spec_tint));
        } else {
            fr = v3s(bsdf * g.f);
        }
        v = v3_add(v, v3_scale(fr, d * gg / (4.0f * fabsf(wo.z))));
    }
    if (!g.reflect && g.refr_ok && bsdf > 0.0f && g.f < 1.0f) {
        /* no 1/eta^2 radiance compression (the file's convention) */
        const float den = oh + g.eta_path * ih;
        const float t = bsdf * fabsf((1.0f - g.f) * d * gg * g.eta_path * g.eta_path * oh * ih / (wo.z * den * den));
        v = v3_add(v, v3_scale(v3(sqrtf(base.x), sqrtf(base.y), sqrtf(base.z)), t));
    }
    if (!front || !g.reflect) return v;
    if (b->coat > 0.0f && g.refl_ok) {
        /* Mitsuba's clearcoat: 0.25 clearcoat F D G (Schlick F0 0.04, GTR1, Smith G of GGX 0.25) */
        const float fcc = 0.04f + 0.96f * pbsdf__pr_schlick_w(oh, b->ior);
        const float gcc = pbsdf__pr_g1(0.25f, wo, h) * pbsdf__pr_g1(0.25f, wi, h);
        v = v3_add(v, v3s(0.25f * b->coat * fcc * pbsdf__gtr1_d(b->coat_alpha, h) * gcc * fabsf(wi.z)));
    }
    if (brdf > 0.0f) {
        const float fo = pbsdf__schlick_w(fabsf(wi.z)), fi = pbsdf__schlick_w(fabsf(wo.z));
        const float f_diff = (1.0f - 0.5f * fi) * (1.0f - 0.5f * fo);
        const float cd = v3_dot(h, wi), rr = 2.0f * b->roughness * cd * cd;
        const float f_retro = rr * (fo + fi + fo * fi * (rr - 1.0f));
        float f = f_diff + f_retro;
        if (b->pr_flatness != 0.0f) {
            const float fss90 = 0.5f * rr;
            const float fss = (1.0f + (fss90 - 1.0f) * fo) * (1.0f + (fss90 - 1.0f) * fi);
            const float f_ss = 1.25f * (fss * (1.0f / (fabsf(wi.z) + fabsf(wo.z)) - 0.5f) + 0.5f);
            f += (f_ss - f) * b->pr_flatness;
        }
        v = v3_add(v, v3_scale(base, brdf * fabsf(wi.z) * f / PK_PI));
        if (b->pr_sheen > 0.0f && b->metallic < 1.0f) {
            const float lum = pbsdf__pr_lum(base);
            const vec3 ctint = lum > 0.0f ? v3_scale(base, 1.0f / lum) : v3s(1.0f);
            const vec3 cs = v3_add(v3s(1.0f - b->pr_sheen_tint), v3_scale(ctint, b->pr_sheen_tint));
            v = v3_add(v, v3_scale(cs, b->pr_sheen * (1.0f - b->metallic) * pbsdf__schlick_w(fabsf(cd)) * fabsf(wi.z)));
        }
    }
    return v;
}

static inline PBSDF_CALLED PK_HD float pbsdf__pr_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (wo.z == 0.0f || wi.z == 0.0f) return 0.0f;
    const bool front = wo.z > 0.0f;
    const pbsdf__pr_geo g = pbsdf__pr_geometry(b, wo, wi);
    float p[4];
    pbsdf__pr_probs(b, front, g.f, p);
    const float oh = v3_dot(wo, g.h), ih = v3_dot(wi, g.h);
    float jac;
    if (g.reflect) {
        jac = fabsf(1.0f / (4.0f * ih));
    } else {
        const float den = oh + g.eta_path * ih;
        jac = fabsf(g.eta_path * g.eta_path * ih / (den * den));
    }
    if (!isfinite(jac)) return 0.0f;
    const float vn = pbsdf_mf_pdf(b, wo, g.h);
    float pdf = 0.0f;
    if (g.reflect) {
        if (g.refl_ok) {
            pdf += p[3] * vn * jac;
            if (p[1] > 0.0f) pdf += p[1] * pbsdf__gtr1_d(b->coat_alpha, g.h) * g.h.z * jac;
        }
        pdf += p[0] * fmaxf(0.0f, wi.z) / PK_PI;
    } else if (g.refr_ok) {
        pdf += p[2] * vn * jac;
    }
    return pdf;
}

static inline PBSDF_CALLED PK_HD bool pbsdf__pr_sample(const pbsdf *b, vec3 wo, const float u[3], vec3 *wi, vec3 *weight,
                                          float *pdf)
{
    if (wo.z == 0.0f) return false;
    const bool front = wo.z > 0.0f;
    if (!front && !((1.0f - b->metallic) * b->transmission > 0.0f)) return false;
    const vec3 m = pbsdf_mf_sample(b, wo, u[1], u[2]);
    float p[4];
    pbsdf__pr_probs(b, front, pbsdf_fresnel_dielectric(v3_dot(wo, m), b->ior), p);
    vec3 w;
    if (u[0] < p[0]) {
        w = pbsdf__cosine_dir(u[1], u[2]);
    } else if (u[0] < p[0] + p[1]) {
        const vec3 mc = pbsdf__gtr1_sample(b->coat_alpha, u[1], u[2]);
        w = v3_sub(v3_scale(mc, 2.0f * v3_dot(wo, mc)), wo);
        if (!(w.z * wo.z > 0.0f)) return false; /* through the surface: lost (the pdf would read a transmission) */
    } else if (u[0] < p[0] + p[1] + p[2]) {
        if (!pbsdf__refract(wo, m, b->ior, &w)) return false;
        if (!(w.z * wo.z < 0.0f)) return false;
    } else {
        w = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
        if (!(w.z * wo.z > 0.0f)) return false; /* as the clearcoat's */
    }
    const float pd = pbsdf__pr_pdf(b, wo, w);
    if (!(pd > 0.0f)) return false;
    *wi = w;
    *pdf = pd;
    *weight = v3_scale(pbsdf__pr_eval(b, wo, w), 1.0f / pd);
    return true;
}

/* ---- Mitsuba 3's principledthin ------------------------------------------- */

/* Mitsuba 3's "principledthin": a thin sheet, the same from both sides (wo
 * and wi are mirrored so that wo.z > 0). Lobes: the specular reflection
 * spec_trans F_thin D G / (4 cos_o) (GGX alpha, alpha_v as principled's;
 * F_thin = lerp(F, the tinted Schlick, spec_tint), F the dielectric Fresnel
 * of eta), the specular transmission spec_trans base (1 - F) D_t G_t /
 * (4 cos_o) about the mirror image of the reflection (alphas pr_tax,
 * pr_tay), the principled diffuse (with flatness) and sheen scaled by
 * (1 - spec_trans)(1 - diff_trans), and a Lambertian transmission
 * (1 - spec_trans) diff_trans base / pi. Fields as pbsdf_principled's with
 * transmission = spec_trans, ior = eta, pr_diff_trans, pr_tax, pr_tay and
 * the rates pr_srate_spec (specular reflection), pr_srate_st, pr_srate_diff,
 * pr_srate_dt. */
static inline PK_HD pbsdf pbsdf_principled_thin(vec3 base_color, float roughness, float ax, float ay, float tax,
                                                float tay, float spec_trans, float diff_trans, float eta)
{
    pbsdf b = pbsdf_principled(base_color, 0.0f, roughness, ax, ay, spec_trans, eta);
    b.type = PBSDF_PRINCIPLED_THIN;
    b.pr_diff_trans = diff_trans;
    b.pr_tax = tax, b.pr_tay = tay;
    return b;
}
/* the lobes' probabilities: specular reflection, specular transmission,
 * diffuse reflection, diffuse transmission */
static inline PK_HD void pbsdf__th_probs(const pbsdf *b, float p[4])
{
    const float st = b->transmission, dt = b->pr_diff_trans;
    p[0] = st * b->pr_srate_spec * 0.5f;
    p[1] = st * b->pr_srate_st * 0.5f;
    p[2] = b->pr_srate_diff * (1.0f - st) * (1.0f - dt);
    p[3] = b->pr_srate_dt * (1.0f - st) * dt;
    const float t = p[0] + p[1] + p[2] + p[3];
    const float r = t > 0.0f ? 1.0f / t : 0.0f;
    for (int k = 0; k < 4; k++) p[k] *= r;
}
/* the transmission lobe's distribution: b with its alphas */
static inline PK_HD pbsdf pbsdf__th_trans_lobe(const pbsdf *b)
{
    pbsdf t = *b;
    t.alpha = b->pr_tax;
    t.alpha_v = b->pr_tay;
    if (b->pr_tax != b->pr_tay) t.flags |= PBSDF_ANISO;
    else t.flags &= ~PBSDF_ANISO;
    return t;
}
/* mirrors wo, wi so that wo.z > 0; the half vector of wo and wi's mirror
 * image above the sheet */
static inline PK_HD vec3 pbsdf__th_half(vec3 *wo, vec3 *wi)
{
    if (wo->z < 0.0f) *wo = v3_neg(*wo), *wi = v3_neg(*wi);
    vec3 h = v3_add(*wo, v3(wi->x, wi->y, fabsf(wi->z)));
    const float l2 = v3_len2(h);
    return l2 > 0.0f ? v3_scale(h, 1.0f / sqrtf(l2)) : v3(0.0f, 0.0f, 1.0f);
}
static inline PBSDF_CALLED PK_HD vec3 pbsdf__th_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    vec3 v = v3s(0.0f);
    if (wo.z == 0.0f) return v;
    const vec3 h = pbsdf__th_half(&wo, &wi);
    const bool reflect = wi.z > 0.0f, refract = wi.z < 0.0f;
    const float st = b->transmission, dt = b->pr_diff_trans, oh = v3_dot(wo, h), ih = v3_dot(wi, h);
    const vec3 base = b->albedo;
    if (st > 0.0f) {
        const float f = pbsdf_fresnel_dielectric(oh, b->ior);
        if (reflect && oh > 0.0f && ih > 0.0f) {
            const float lum = pbsdf__pr_lum(base), eta_it = oh >= 0.0f ? b->ior : 1.0f / b->ior;
            const vec3 ctint = lum > 0.0f ? v3_scale(base, 1.0f / lum) : v3s(1.0f);
            const float r0 = (eta_it - 1.0f) / (eta_it + 1.0f);
            const vec3 fs = pbsdf__pr_schlick(v3_scale(ctint, r0 * r0), pbsdf__pr_schlick_w(oh, b->ior));
            const vec3 ft = v3_add(v3s((1.0f - b->pr_spec_tint) * f), v3_scale(fs, b->pr_spec_tint));
            const float dg = pbsdf_mf_d(b, h) * pbsdf__pr_g1m(b, wo, h) * pbsdf__pr_g1m(b, wi, h);
            v = v3_add(v, v3_scale(ft, st * dg / (4.0f * wo.z)));
        }
        if (refract && oh > 0.0f && ih < 0.0f) {
            const pbsdf t = pbsdf__th_trans_lobe(b);
            const float dg = pbsdf_mf_d(&t, h) * pbsdf__pr_g1m(&t, wo, h) * pbsdf__pr_g1m(&t, wi, h);
            v = v3_add(v, v3_scale(base, st * (1.0f - f) * dg / (4.0f * wo.z)));
        }
    }
    if (reflect && st < 1.0f && dt < 1.0f) {
        const float fo = pbsdf__schlick_w(wi.z), fi = pbsdf__schlick_w(wo.z);
        const float f_diff = (1.0f - 0.5f * fi) * (1.0f - 0.5f * fo);
        const float rr = 2.0f * b->roughness * ih * ih;
        float f = f_diff + rr * (fo + fi + fo * fi * (rr - 1.0f));
        if (b->pr_flatness != 0.0f) {
            const float fss90 = 0.5f * rr;
            const float fss = (1.0f + (fss90 - 1.0f) * fo) * (1.0f + (fss90 - 1.0f) * fi);
            const float f_ss = 1.25f * (fss * (1.0f / (wi.z + wo.z) - 0.5f) + 0.5f);
            f += (f_ss - f) * b->pr_flatness;
        }
        const float w = (1.0f - st) * (1.0f - dt);
        v = v3_add(v, v3_scale(base, w * wi.z * f / PK_PI));
        if (b->pr_sheen > 0.0f) {
            const float lum = pbsdf__pr_lum(base);
            const vec3 ctint = lum > 0.0f ? v3_scale(base, 1.0f / lum) : v3s(1.0f);
            const vec3 cs = v3_add(v3s(1.0f - b->pr_sheen_tint), v3_scale(ctint, b->pr_sheen_tint));
            v = v3_add(v, v3_scale(cs, b->pr_sheen * w * pbsdf__schlick_w(fabsf(ih)) * wi.z));
        }
    }
    if (refract && st < 1.0f && dt > 0.0f) v = v3_add(v, v3_scale(base, (1.0f - st) * dt * -wi.z / PK_PI));
    return v;
}
static inline PBSDF_CALLED PK_HD float pbsdf__th_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (wo.z == 0.0f) return 0.0f;
    const vec3 h = pbsdf__th_half(&wo, &wi);
    float p[4];
    pbsdf__th_probs(b, p);
    const float oh = v3_dot(wo, h), ih = v3_dot(wi, h);
    /* the mirror image of wi above the sheet reflects wo about h */
    const float jac = fabsf(1.0f / (4.0f * v3_dot(v3(wi.x, wi.y, fabsf(wi.z)), h)));
    float pdf = 0.0f;
    if (wi.z > 0.0f) {
        if (oh > 0.0f && ih > 0.0f && p[0] > 0.0f) pdf += p[0] * pbsdf_mf_pdf(b, wo, h) * jac;
        pdf += p[2] * wi.z / PK_PI;
    } else if (wi.z < 0.0f) {
        if (oh > 0.0f && ih < 0.0f && p[1] > 0.0f) {
            const pbsdf t = pbsdf__th_trans_lobe(b);
            pdf += p[1] * pbsdf_mf_pdf(&t, wo, h) * jac;
        }
        pdf += p[3] * -wi.z / PK_PI;
    }
    return isfinite(pdf) ? pdf : 0.0f;
}
static inline PBSDF_CALLED PK_HD bool pbsdf__th_sample(const pbsdf *b, vec3 wo, const float u[3], vec3 *wi, vec3 *weight,
                                          float *pdf)
{
    if (wo.z == 0.0f) return false;
    const float s = wo.z < 0.0f ? -1.0f : 1.0f;
    const vec3 v = v3_scale(wo, s);
    float p[4];
    pbsdf__th_probs(b, p);
    vec3 w;
    if (u[0] < p[0]) {
        const vec3 m = pbsdf_mf_sample(b, v, u[1], u[2]);
        w = v3_sub(v3_scale(m, 2.0f * v3_dot(v, m)), v);
        if (!(w.z > 0.0f) || !(v3_dot(w, m) > 0.0f)) return false;
    } else if (u[0] < p[0] + p[1]) {
        const pbsdf t = pbsdf__th_trans_lobe(b);
        const vec3 m = pbsdf_mf_sample(&t, v, u[1], u[2]);
        w = v3_sub(v3_scale(m, 2.0f * v3_dot(v, m)), v);
        w.z = -w.z;
        if (!(w.z < 0.0f) || !(v3_dot(w, m) < 0.0f)) return false;
    } else if (u[0] < p[0] + p[1] + p[2]) {
        w = pbsdf__cosine_dir(u[1], u[2]);
    } else {
        w = v3_neg(pbsdf__cosine_dir(u[1], u[2]));
    }
    if (w.z == 0.0f) return false;
    w = v3_scale(w, s);
    const float pd = pbsdf__th_pdf(b, wo, w);
    if (!(pd > 0.0f)) return false;
    *wi = w;
    *pdf = pd;
    *weight = v3_scale(pbsdf__th_eval(b, wo, w), 1.0f / pd);
    return true;
}

/* ---- the interface --------------------------------------------------------- */

/* True if the BSDF has a non-delta part, i.e. light sampling and MIS can
 * reach it (eval and pdf are not identically 0). */
/* Path regularisation (pbrt-v4's Regularize): a lobe smoother than GGX
 * alpha 0.3 gets twice its roughness, at least 0.1 and at most 0.3. The
 * Lambertian lobe has no roughness and is left alone. */
static inline PK_HD void pbsdf_regularize(pbsdf *b)
{
    if (b->type != PBSDF_DIFFUSE && b->alpha < 0.3f) b->alpha = fminf(fmaxf(2.0f * b->alpha, 0.1f), 0.3f);
    if (pbsdf__an(b) && b->alpha_v < 0.3f) b->alpha_v = fminf(fmaxf(2.0f * b->alpha_v, 0.1f), 0.3f);
    if (b->type == PBSDF_COATED && (b->flags & PBSDF_COATED_METAL) && b->base_alpha < 0.3f)
        b->base_alpha = fminf(fmaxf(2.0f * b->base_alpha, 0.1f), 0.3f);
    if (b->coat > 0.0f && b->coat_alpha < 0.3f) b->coat_alpha = fminf(fmaxf(2.0f * b->coat_alpha, 0.1f), 0.3f);
}

static inline PK_HD bool pbsdf_has_nondelta(const pbsdf *b)
{
    if (b->type == PBSDF_COATED) return !pbsdf__smooth(b) || !pbsdf__base_smooth(b) || !pbsdf__clear(b);
    if (b->type >= PBSDF_THIN_DIELECTRIC) return b->type != PBSDF_THIN_DIELECTRIC;
    switch (b->type) {
    case PBSDF_DIFFUSE: case PBSDF_PLASTIC: case PBSDF_GLOSSY: return true;
    case PBSDF_METALLIC_ROUGHNESS:
        return !pbsdf__smooth(b) || (1.0f - b->metallic) * (1.0f - b->transmission) > 0.0f ||
               (b->coat > 0.0f && !pbsdf__coat_smooth(b)) || pbsdf__max3(b->gx_sheen) > 0.0f;
    default: return !pbsdf__smooth(b);
    }
}

/* f(wo, wi) * |wi.z| of the non-delta part. Local frame, unit vectors. */
static inline PK_HD vec3 pbsdf_eval(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (b->type == PBSDF_COATED) return pbsdf__coated_eval(b, wo, wi);
    if (b->type == PBSDF_PRINCIPLED) return pbsdf__pr_eval(b, wo, wi);
    if (b->type == PBSDF_PRINCIPLED_THIN) return pbsdf__th_eval(b, wo, wi);
    if (b->type >= PBSDF_THIN_DIELECTRIC) return pbsdf__ext_eval(b, wo, wi);
    if (b->type == PBSDF_DIELECTRIC) return pbsdf__dielectric_eval(b, wo, wi);
    if (b->type == PBSDF_METALLIC_ROUGHNESS)
        return b->flags & PBSDF_MR_VOLUME ? pbsdf__mrv_eval(b, wo, wi)
               : b->flags & PBSDF_GLTF_EXT ? pbsdf__gx_eval(b, wo, wi)
                                           : pbsdf__mr_eval(b, wo, wi);
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return v3s(0.0f);
    vec3 h = v3(0.0f, 0.0f, 1.0f);
    switch (b->type) {
    case PBSDF_DIFFUSE:
        return v3_scale(b->albedo, wi.z / PK_PI);
    case PBSDF_CONDUCTOR: {
        if (pbsdf__smooth(b)) return v3s(0.0f);
        float s = pbsdf__mf_refl_cos(b, wo, wi, &h);
        if (b->flags & PBSDF_ENERGY) {
            vec3 r = pbsdf__ms_cos(b, wo, wi);
            return s > 0.0f ? v3_add(r, v3_scale(pbsdf__fresnel_conductor(b, v3_dot(wo, h)), s)) : r;
        }
        if (s <= 0.0f) return v3s(0.0f);
        return v3_scale(pbsdf__fresnel_conductor(b, v3_dot(wo, h)), s);
    }
    case PBSDF_PLASTIC: {
        vec3 r = pbsdf__plastic_diffuse_cos(b, wo, wi);
        if (!pbsdf__smooth(b)) {
            float s = pbsdf__mf_refl_cos(b, wo, wi, &h);
            if (s > 0.0f) r = v3_add(r, v3s(s * pbsdf_fresnel_dielectric(v3_dot(wo, h), b->ior)));
            if (b->flags & PBSDF_ENERGY) r = v3_add(r, pbsdf__ms_cos(b, wo, wi));
        }
        return r;
    }
    case PBSDF_GLOSSY: {
        vec3 r = v3_scale(b->albedo, wi.z / PK_PI);
        if (!pbsdf__smooth(b)) {
            float s = pbsdf__ggx_refl_cos(b->alpha, wo, wi, &h);
            if (s > 0.0f) r = v3_add(r, v3_scale(b->specular, s));
        }
        return r;
    }
    default:
        return v3s(0.0f);
    }
}

/* Solid-angle density with which pbsdf_sample returns wi as a non-delta
 * sample (the lobe choice included). */
static inline PK_HD float pbsdf_pdf(const pbsdf *b, vec3 wo, vec3 wi)
{
    if (b->type == PBSDF_COATED) return pbsdf__coated_pdf(b, wo, wi);
    if (b->type == PBSDF_PRINCIPLED) return pbsdf__pr_pdf(b, wo, wi);
    if (b->type == PBSDF_PRINCIPLED_THIN) return pbsdf__th_pdf(b, wo, wi);
    if (b->type >= PBSDF_THIN_DIELECTRIC) return pbsdf__ext_pdf(b, wo, wi);
    if (b->type == PBSDF_DIELECTRIC) return pbsdf__dielectric_pdf(b, wo, wi);
    if (b->type == PBSDF_METALLIC_ROUGHNESS)
        return b->flags & PBSDF_MR_VOLUME ? pbsdf__mrv_pdf(b, wo, wi)
               : b->flags & PBSDF_GLTF_EXT ? pbsdf__gx_pdf(b, wo, wi)
                                           : pbsdf__mr_pdf(b, wo, wi);
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    switch (b->type) {
    case PBSDF_DIFFUSE:
        return wi.z / PK_PI;
    case PBSDF_CONDUCTOR:
        if (pbsdf__smooth(b)) return 0.0f;
        if (b->flags & PBSDF_ENERGY) {
            const float pc = pbsdf__ms_prob(b, wo);
            return (1.0f - pc) * pbsdf__mf_refl_pdf(b, wo, wi) + pc * wi.z / PK_PI;
        }
        return pbsdf__mf_refl_pdf(b, wo, wi);
    case PBSDF_PLASTIC:
    case PBSDF_GLOSSY: {
        float ps = pbsdf__spec_prob(b, wo);
        float p = (1.0f - ps) * wi.z / PK_PI;
        if (!pbsdf__smooth(b)) p += ps * pbsdf__mf_refl_pdf(b, wo, wi);
        return p;
    }
    default:
        return 0.0f;
    }
}

/* Samples wi for wo from u (three numbers in [0, 1): u[0] picks the lobe,
 * u[1], u[2] the direction). On success: *wi, *weight = f |cos theta_i| / pdf
 * (the throughput factor), *pdf and *is_delta. For a non-delta sample *pdf
 * equals pbsdf_pdf(b, wo, *wi) and *weight pbsdf_eval / pbsdf_pdf; for a delta
 * sample *pdf is the discrete probability of having chosen that lobe (the
 * weight already contains it). False when no direction was produced (wo
 * below a one-sided surface, a reflection below the horizon, ...): the path
 * ends there, and those samples count as weight 0 in every estimate. */
static inline PK_HD bool pbsdf_sample(const pbsdf *b, vec3 wo, const float u[3], vec3 *wi, vec3 *weight, float *pdf,
                                bool *is_delta)
{
    if (b->type == PBSDF_COATED) return pbsdf__coated_sample(b, wo, u, wi, weight, pdf, is_delta);
    if (b->type == PBSDF_PRINCIPLED) {
        *is_delta = false;
        *weight = v3s(0.0f); /* (gcc cannot see that a true return sets it) */
        return pbsdf__pr_sample(b, wo, u, wi, weight, pdf);
    }
    if (b->type == PBSDF_PRINCIPLED_THIN) {
        *is_delta = false;
        *weight = v3s(0.0f);
        return pbsdf__th_sample(b, wo, u, wi, weight, pdf);
    }
    if (b->type >= PBSDF_THIN_DIELECTRIC) return pbsdf__ext_sample(b, wo, u, wi, weight, pdf, is_delta);
    *is_delta = false;
    if (b->type == PBSDF_DIELECTRIC) {
        if (wo.z == 0.0f) return false;
        if (pbsdf__smooth(b)) {
            float r = pbsdf_fresnel_dielectric(wo.z, b->ior);
            *is_delta = true;
            if (u[0] < r) {
                *wi = pbsdf__mirror(wo);
                *weight = v3s(1.0f);
                *pdf = r;
                return true;
            }
            if (!pbsdf__refract(wo, v3(0.0f, 0.0f, 1.0f), b->ior, wi)) return false;
            *weight = b->transmittance;
            *pdf = 1.0f - r;
            return true;
        }
        vec3 m = pbsdf_mf_sample(b, wo, u[1], u[2]);
        if (!(v3_dot(wo, m) * wo.z > 0.0f)) return false; /* a facet turned away (Beckmann) */
        float r = pbsdf_fresnel_dielectric(v3_dot(wo, m), b->ior);
        vec3 w;
        if (u[0] < r) {
            w = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
            if (!(w.z * wo.z > 0.0f)) return false;
        } else {
            if (!pbsdf__refract(wo, m, b->ior, &w) || !(w.z * wo.z < 0.0f)) return false;
        }
        float p = pbsdf__dielectric_pdf(b, wo, w);
        if (!(p > 0.0f)) return false;
        *wi = w;
        *pdf = p;
        *weight = v3_scale(pbsdf__dielectric_eval(b, wo, w), 1.0f / p);
        return true;
    }
    if (b->type == PBSDF_METALLIC_ROUGHNESS && (b->flags & PBSDF_MR_VOLUME) && wo.z < 0.0f)
        return pbsdf__mrv_sample(b, wo, u[0], u[1], u[2], 1.0f, wi, weight, pdf, is_delta);
    if (!(wo.z > 0.0f)) return false;
    vec3 w;
    switch (b->type) {
    case PBSDF_DIFFUSE: {
        float r = sqrtf(u[1]), phi = 2.0f * PK_PI * u[2];
        w = v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[1])));
        if (!(w.z > 0.0f)) return false;
        *wi = w;
        *pdf = w.z / PK_PI;
        *weight = b->albedo;
        return true;
    }
    case PBSDF_CONDUCTOR: {
        if (pbsdf__smooth(b)) {
            *wi = pbsdf__mirror(wo);
            *weight = pbsdf__fresnel_conductor(b, wo.z);
            *pdf = 1.0f;
            *is_delta = true;
            return true;
        }
        if (b->flags & PBSDF_ENERGY) { /* the lobe or the multiple-scattering one, by u[0] */
            if (u[0] < pbsdf__ms_prob(b, wo)) {
                float r = sqrtf(u[1]), phi = 2.0f * PK_PI * u[2];
                w = v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[1])));
            } else {
                vec3 m = pbsdf_mf_sample(b, wo, u[1], u[2]);
                float om = v3_dot(wo, m);
                if (!(om > 0.0f)) return false;
                w = v3_sub(v3_scale(m, 2.0f * om), wo);
            }
            if (!(w.z > 0.0f)) return false;
            float p = pbsdf_pdf(b, wo, w);
            if (!(p > 0.0f)) return false;
            *wi = w;
            *pdf = p;
            *weight = v3_scale(pbsdf_eval(b, wo, w), 1.0f / p);
            return true;
        }
        vec3 m = pbsdf_mf_sample(b, wo, u[1], u[2]);
        float om = v3_dot(wo, m);
        w = v3_sub(v3_scale(m, 2.0f * om), wo);
        if (!(w.z > 0.0f) || !(om > 0.0f)) return false;
        *wi = w;
        *pdf = pbsdf__mf_refl_pdf(b, wo, w);
        if (!(*pdf > 0.0f)) return false;
        if (pbsdf__bk(b)) { /* f cos / pdf = F D G2 / (4 cos_o) / (D cos_m / (4 o.m)) */
            *weight = v3_scale(pbsdf__fresnel_conductor(b, om), pbsdf_mf_g2(b, wo, w) * om / (wo.z * m.z));
            return true;
        }
        /* f cos / pdf = F D G2 / (4 cos_o) / (G1(wo) D / (4 cos_o)) = F G2 / G1(wo) */
        if (pbsdf__an(b)) {
            *weight = v3_scale(pbsdf__fresnel_conductor(b, om), pbsdf_mf_g2(b, wo, w) * (1.0f + pbsdf_mf_lambda(b, wo)));
            return true;
        }
        *weight = v3_scale(pbsdf__fresnel_conductor(b, om),
                           pbsdf_ggx_g2(b->alpha, wo, w) / pbsdf_ggx_g1(b->alpha, wo));
        return true;
    }
    case PBSDF_METALLIC_ROUGHNESS: {
        if (b->flags & PBSDF_GLTF_EXT) return pbsdf__gx_sample(b, wo, u, wi, weight, pdf, is_delta);
        float pr[4];
        pbsdf__mr_probs(b, wo, pr);
        *weight = v3s(0.0f);
        const bool smooth = pbsdf__smooth(b);
        int lobe = 0;
        float c = pr[0];
        while (lobe < 3 && !(u[0] < c)) c += pr[++lobe];
        while (!(pr[lobe] > 0.0f)) lobe = (lobe + 1) & 3; /* float rounding: a lobe that has weight */
        const float under = 1.0f - pbsdf__mr_coat(b, wo);
        if (lobe == 0 || lobe == 3) { /* specular reflection, or the clearcoat's */
            const bool coat = lobe == 3;
            if (coat ? pbsdf__coat_smooth(b) : smooth) {
                if (!coat) *wi = pbsdf__mirror(wo);
                else if (!pbsdf__coat_mirror(b, wo, wi)) return false;
                vec3 f = coat ? v3s(pbsdf__mr_coat(b, wo)) : pbsdf__mr_delta_reflect(b, wo);
                if (!coat && b->coat > 0.0f) f = v3_scale(f, under);
                *weight = v3_scale(f, 1.0f / pr[lobe]);
                *pdf = pr[lobe];
                *is_delta = true;
                return true;
            }
            if (coat && (b->flags & PBSDF_COAT_NORMAL)) {
                if (!pbsdf__coat_lobe_sample(b, wo, u[1], u[2], &w)) return false;
            } else {
                vec3 m = pbsdf_ggx_vndf_sample(coat ? b->coat_alpha : b->alpha, wo, u[1], u[2]);
                w = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
            }
            if (!(w.z > 0.0f)) return false;
        } else if (lobe == 1) { /* the diffuse base */
            float r = sqrtf(u[1]), phi = 2.0f * PK_PI * u[2];
            w = v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[1])));
            if (!(w.z > 0.0f)) return false;
        } else if (b->flags & PBSDF_MR_VOLUME) { /* transmission: refracted into the volume */
            const float u0 = fminf(fmaxf((u[0] - (c - pr[2])) / pr[2], 0.0f), 0.99999994f);
            return pbsdf__mrv_sample(b, wo, u0, u[1], u[2], pr[2], wi, weight, pdf, is_delta);
        } else { /* transmission: the specular lobe mirrored through the sheet */
            if (smooth) {
                *wi = v3_neg(wo);
                vec3 f = pbsdf__mr_delta_transmit(b, wo);
                if (b->coat > 0.0f) f = v3_scale(f, under);
                *weight = v3_scale(f, 1.0f / pr[2]);
                *pdf = pr[2];
                *is_delta = true;
                return true;
            }
            vec3 m = pbsdf_ggx_vndf_sample(b->alpha, wo, u[1], u[2]);
            w = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
            if (!(w.z > 0.0f)) return false;
            w = pbsdf__mirror_z(w);
        }
        if (b->flags & PBSDF_MR_VOLUME) {
            const float p = pbsdf__mrv_pdf(b, wo, w);
            if (!(p > 0.0f)) return false;
            *wi = w;
            *pdf = p;
            *weight = v3_scale(pbsdf__mrv_eval(b, wo, w), 1.0f / p);
            return true;
        }
        float p = pbsdf__mr_pdf(b, wo, w);
        if (!(p > 0.0f)) return false;
        *wi = w;
        *pdf = p;
        *weight = v3_scale(pbsdf__mr_eval(b, wo, w), 1.0f / p);
        return true;
    }
    case PBSDF_PLASTIC:
    case PBSDF_GLOSSY: {
        float ps = pbsdf__spec_prob(b, wo);
        if (u[0] < ps) {
            if (pbsdf__smooth(b)) {
                *wi = pbsdf__mirror(wo);
                vec3 s = b->type == PBSDF_PLASTIC ? v3s(pbsdf_fresnel_dielectric(wo.z, b->ior)) : b->specular;
                *weight = v3_scale(s, 1.0f / ps);
                *pdf = ps;
                *is_delta = true;
                return true;
            }
            vec3 m = pbsdf_mf_sample(b, wo, u[1], u[2]);
            if (!(v3_dot(wo, m) > 0.0f)) return false; /* a facet turned away (Beckmann) */
            w = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
        } else {
            float r = sqrtf(u[1]), phi = 2.0f * PK_PI * u[2];
            w = v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[1])));
        }
        if (!(w.z > 0.0f)) return false;
        float p = pbsdf_pdf(b, wo, w);
        if (!(p > 0.0f)) return false;
        *wi = w;
        *pdf = p;
        *weight = v3_scale(pbsdf_eval(b, wo, w), 1.0f / p);
        return true;
    }
    default:
        return false;
    }
}

#endif

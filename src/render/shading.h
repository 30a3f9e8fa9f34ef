/*
 * shading.h - the material at a hit as a BSDF: the one place where a
 * material record (scene/scene.h) becomes a physically based scattering
 * function (pbsdf.h) for any integrator, on the CPU and the GPU (PK_HD).
 * The MTL illumination models are decoded here (docs/materials.md): Kd
 * diffuse; Ks with Ns a GGX lobe over it (illum 2); illum 3 an ideal mirror
 * weighted by Ks over the diffuse part, illum 5 a mirror with Fresnel;
 * illum 4, 6, 7 smooth dielectrics (Ni, Tf) with exact Fresnel; dissolve
 * d < 1 lets a fraction of the light pass straight through. The physically
 * based types (diffuse, conductor, dielectric, plastic, metallic-roughness,
 * thin dielectric, diffuse transmission, rough diffuse, Phong) map to their
 * pbsdf directly; a mix was resolved to one of its materials by surface_at. Directions are world space, unit, pointing
 * away from the surface.
 */
#ifndef PK_SHADING_H
#define PK_SHADING_H

#include "../math/frame.h"
#include "pbsdf.h"
#include "surface.h"

static inline PK_HD bool black(vec3 c) { return !(c.x > 0.0f || c.y > 0.0f || c.z > 0.0f); }

/* The BSDF at a surface, its frame, and the dissolve: with probability
 * 1 - opaque the path passes straight through (a delta lobe of its own). */
typedef struct shading {
    pbsdf b;
    onb frame;           /* z = the shading normal; for dielectrics the outward one */
    float opaque;
    bool nondelta;       /* the BSDF has a part that light sampling can reach */
} shading;

/* The shading frame about the unit normal n: its x axis along the tangent
 * dpdu made perpendicular to n (where the roughness is anisotropic: the u
 * roughness lies along dp/du, as pbrt and Mitsuba have it), or, where
 * dpdu is zero or along n, onb_from_normal's. */
static inline PK_HD onb shading_frame(vec3 n, vec3 dpdu)
{
    vec3 s = v3_sub(dpdu, v3_scale(n, v3_dot(n, dpdu)));
    const float l2 = v3_len2(s);
    if (!(l2 > 1e-12f * v3_len2(dpdu)) || !v3_finite(s)) return onb_from_normal(n);
    onb f;
    f.s = v3_scale(s, 1.0f / sqrtf(l2));
    f.t = v3_cross(n, f.s);
    f.n = n;
    return f;
}

/* A coated material's layered BSDF; the hit point seeds its random walks
 * (pbsdf.h). A conductor base's index is relative to the coat (pbrt-v4
 * divides it by the coat's), a reflectance r becomes eta 1, k 2 sqrt(r) /
 * sqrt(1 - r) as pbrt-v4 does. */
static inline PK_HD pbsdf shading__coated(const material *m, vec3 p)
{
    const material_layer *l = &m->layer;
    if (m->coat_base != MATERIAL_BASE_CONDUCTOR) {
        pbsdf b = pbsdf_coated(surface_clamp_rgb(m->kd), m->ni, m->alpha, l->thickness, l->albedo, l->g, l->maxdepth,
                               l->nsamples);
        b.seed = (unsigned)pbsdf__hash3(p, 0x2545f491u);
        return b;
    }
    vec3 eta = m->eta, k = m->k;
    if (m->schlick) {
        const vec3 r = v3_min(surface_clamp_rgb(m->ks), v3s(0.9999f));
        eta = v3s(1.0f);
        k = v3(2.0f * sqrtf(r.x) / sqrtf(1.0f - r.x), 2.0f * sqrtf(r.y) / sqrtf(1.0f - r.y),
               2.0f * sqrtf(r.z) / sqrtf(1.0f - r.z));
    }
    const float ie = 1.0f / m->ni;
    pbsdf b = pbsdf_coated_conductor(v3_scale(eta, ie), v3_scale(k, ie), m->base_alpha, m->ni, m->alpha, l->thickness,
                                     l->albedo, l->g, l->maxdepth, l->nsamples);
    b.seed = (unsigned)pbsdf__hash3(p, 0x2545f491u);
    return b;
}

/* glTF's KHR_materials_specular, _sheen, _iridescence and _anisotropy on a
 * metallic-roughness BSDF b (made from m, alpha = roughness^2). */
static inline PK_HD void shading__gltf_ext(pbsdf *b, const material *m)
{
    b->gx_spec = fminf(fmaxf(m->specular, 0.0f), 1.0f);
    b->gx_spec_color = v3_max(m->specular_color, v3s(0.0f));
    b->gx_sheen = surface_clamp_rgb(m->sheen_color);
    b->gx_sheen_r = fminf(fmaxf(m->sheen_roughness, 0.0f), 1.0f);
    b->gx_irid = fminf(fmaxf(m->iridescence, 0.0f), 1.0f);
    b->gx_irid_ior = fmaxf(m->iridescence_ior, 1e-3f);
    b->gx_irid_d = fmaxf(m->iridescence_thickness, 0.0f);
    const float st = fminf(fmaxf(m->anisotropy, 0.0f), 1.0f);
    if (st > 0.0f) { /* alpha_t = mix(alpha, 1, strength^2) along the frame's x, alpha across */
        const float ab = b->alpha;
        b->alpha = ab + (1.0f - ab) * st * st;
        pbsdf_anisotropic(b, ab);
    }
    pbsdf_gltf_ext(b);
}

static inline PK_HD shading shading_at(const surface *sf)
{
    const material *m = sf->m;
    shading sh;
    const bool glass = m->type == MAT_MTL && material_mtl_glass(m);
    sh.opaque = glass || m->type == MAT_DIELECTRIC ? 1.0f : fminf(fmaxf(m->d, 0.0f), 1.0f);
    vec3 n = sf->ns;
    if (m->type != MAT_MTL) { /* the physically based types of JSON scenes */
        switch (m->type) {
        case MAT_CONDUCTOR:
            sh.b = m->schlick ? pbsdf_conductor_schlick(m->ks, m->alpha) : pbsdf_conductor(m->eta, m->k, m->alpha);
            sh.b.tint = m->tint;
            break;
        case MAT_DIELECTRIC:
            sh.b = pbsdf_dielectric(m->ni, m->alpha, sf->front ? m->tf : v3s(1.0f));
            if (!sf->front) n = v3_neg(n); /* the outward normal: wo.z < 0 inside */
            break;
        case MAT_PLASTIC: sh.b = pbsdf_plastic(m->kd, m->ni, m->alpha); break;
        case MAT_INTERFACE: sh.b = pbsdf_dielectric(1.0f, 0.0f, v3s(1.0f)); break; /* straight through */
        case MAT_METALLIC_ROUGHNESS: { /* a thin sheet: the frame faces wo on either side */
            const float r = fminf(fmaxf(m->roughness, 0.0f), 1.0f);
            sh.b = pbsdf_metallic_roughness(surface_clamp_rgb(m->kd), fminf(fmaxf(m->metallic, 0.0f), 1.0f), r * r,
                                            fminf(fmaxf(m->transmission, 0.0f), 1.0f), m->ni);
            if (m->clearcoat > 0.0f) {
                const float cr = fminf(fmaxf(m->clearcoat_roughness, 0.0f), 1.0f);
                sh.b = pbsdf_with_clearcoat(sh.b, fminf(m->clearcoat, 1.0f), cr * cr);
            }
            if (m->volume) { /* bounds a volume: refracts, the frame the outward normal (wo.z < 0 inside) */
                sh.b.flags |= PBSDF_MR_VOLUME;
                if (!sf->front) n = v3_neg(n);
            } else {
                shading__gltf_ext(&sh.b, m); /* KHR_materials_specular, _sheen, ... (not on a volume's boundary) */
            }
            break;
        }
        case MAT_THIN_DIELECTRIC: sh.b = pbsdf_thin_dielectric(m->eta.x, m->tf); break;
        case MAT_DIFFUSE_TRANSMISSION: sh.b = pbsdf_diffuse_transmission(m->kd, m->tf); break;
        case MAT_ROUGH_DIFFUSE: sh.b = pbsdf_oren_nayar(m->kd, m->alpha * 0.70710678f); break; /* Mitsuba's sigma */
        case MAT_PHONG: sh.b = pbsdf_phong(m->kd, m->ks, m->ns); break;
        case MAT_COATED: sh.b = shading__coated(m, sf->p); break;
        case MAT_PRINCIPLED: { /* the frame is the outward normal where it transmits (wo.z < 0 inside) */
            /* Mitsuba's calc_dist_params: ax along dp/du (the frame's x, below) */
            const float r = fminf(fmaxf(m->roughness, 0.0f), 1.0f), r2 = r * r;
            const float asp = sqrtf(1.0f - 0.9f * fminf(fmaxf(m->anisotropic, 0.0f), 1.0f));
            const float ax = fmaxf(1e-3f, r2 / asp), ay = fmaxf(1e-3f, r2 * asp);
            if (m->thin) { /* principledthin: its transmission's roughness scaled by 0.65 eta - 0.35 */
                const float rt = (0.65f * m->ni - 0.35f) * r, rt2 = rt * rt;
                sh.b = pbsdf_principled_thin(surface_clamp_rgb(m->kd), r, ax, ay, fmaxf(1e-3f, rt2 / asp),
                                             fmaxf(1e-3f, rt2 * asp), m->transmission, m->diff_trans, m->ni);
                sh.b.pr_spec_tint = m->spec_tint, sh.b.pr_sheen = m->sheen, sh.b.pr_sheen_tint = m->sheen_tint;
                sh.b.pr_flatness = m->flatness;
                sh.b.pr_srate_spec = m->srate_spec, sh.b.pr_srate_diff = m->srate_diff;
                sh.b.pr_srate_st = m->srate_st, sh.b.pr_srate_dt = m->srate_dt;
                break;
            }
            sh.b = pbsdf_principled(surface_clamp_rgb(m->kd), m->metallic, r, ax, ay, m->transmission, m->ni);
            sh.b.coat = m->clearcoat;
            sh.b.coat_alpha = 0.1f + (0.001f - 0.1f) * m->clearcoat_gloss;
            sh.b.pr_spec_tint = m->spec_tint, sh.b.pr_sheen = m->sheen, sh.b.pr_sheen_tint = m->sheen_tint;
            sh.b.pr_flatness = m->flatness;
            sh.b.pr_srate_spec = m->srate_spec, sh.b.pr_srate_cc = m->srate_cc, sh.b.pr_srate_diff = m->srate_diff;
            if (m->transmission > 0.0f && m->metallic < 1.0f && !sf->front) n = v3_neg(n);
            break;
        }
        default: sh.b = pbsdf_diffuse(m->kd); break;
        }
        if (m->beckmann && (m->type == MAT_CONDUCTOR || m->type == MAT_DIELECTRIC || m->type == MAT_PLASTIC))
            sh.b.flags |= PBSDF_BECKMANN;
        if (material_anisotropic(m)) pbsdf_anisotropic(&sh.b, m->alpha_v);
    } else if (glass) {
        sh.b = pbsdf_dielectric(m->ni, 0.0f, sf->front ? material_mtl_tint(m) : v3s(1.0f));
        if (!sf->front) n = v3_neg(n); /* the outward normal: wo.z < 0 inside */
    } else if (m->illum == 5) {
        sh.b = pbsdf_conductor_schlick(m->ks, 0.0f); /* a mirror with Fresnel */
    } else if (m->illum == 3) {
        sh.b = pbsdf_glossy(m->kd, m->ks, 0.0f); /* diffuse + an ideal mirror weighted by Ks */
    } else if (material_mtl_glossy(m)) {
        sh.b = pbsdf_glossy_mtl(m->kd, m->ks, m->ns);
    } else {
        sh.b = pbsdf_diffuse(m->kd);
    }
    sh.frame = sh.b.flags & PBSDF_ANISO ? shading_frame(n, sf->dpdu) : onb_from_normal(n);
    if ((sh.b.flags & PBSDF_ANISO) && m->type == MAT_METALLIC_ROUGHNESS && m->anisotropy_rotation != 0.0f) {
        /* glTF's anisotropy direction: rotated from the tangent toward n x tangent */
        const float c = cosf(m->anisotropy_rotation), s = sinf(m->anisotropy_rotation);
        sh.frame = shading_frame(n, v3_add(v3_scale(sh.frame.s, c), v3_scale(sh.frame.t, s)));
    }
    if (m->type == MAT_METALLIC_ROUGHNESS && sh.b.coat > 0.0f && v3_len2(sf->nc) > 0.0f)
        /* the clearcoat's own normal, turned with the frame (a volume's inside: the outward one) */
        pbsdf_clearcoat_normal(&sh.b, onb_to_local(sh.frame, v3_dot(n, sf->ns) < 0.0f ? v3_neg(sf->nc) : sf->nc));
    sh.nondelta = sh.opaque > 0.0f && pbsdf_has_nondelta(&sh.b) &&
                  (sh.b.type != PBSDF_DIFFUSE || !black(sh.b.albedo));
    return sh;
}

/* The Whitted integrator's reflectance (the MTL record as the classic
 * models have it, not a pbsdf: Lambert of material_whitted_kd plus, for
 * illum 2, a normalised Phong lobe of Ks and exponent Ns around the mirror
 * direction), worked out once for the many directions in which light
 * reaches one point. World space, like the functions above. */
typedef struct phong_terms {
    vec3 ns, ng;
    vec3 diffuse;  /* the Whitted diffuse reflectance over pi */
    vec3 ks;       /* the Phong lobe's colour, when glossy */
    float n, norm; /* its exponent and normalisation (n + 2) / (2 pi) */
    bool glossy;   /* illum 2 with a Ks */
} phong_terms;

static inline PK_HD phong_terms phong_terms_at(const surface *sf)
{
    const material *m = sf->m;
    phong_terms b;
    b.ns = sf->ns, b.ng = sf->ng;
    b.diffuse = v3_scale(material_whitted_kd(m), 1.0f / PK_PI);
    b.glossy = material_mtl_glossy(m);
    b.ks = m->ks;
    b.n = m->ns;
    b.norm = (b.n + 2.0f) / (2.0f * PK_PI);
    return b;
}

/* BRDF times cos(theta_i) for light arriving from wi, seen from wo (unit
 * vectors pointing away from the surface); zero through the surface. */
static inline PK_HD vec3 phong_cos(const phong_terms *b, vec3 wo, vec3 wi)
{
    float cos_i = v3_dot(b->ns, wi);
    if (cos_i <= 0.0f || v3_dot(b->ng, wi) <= 0.0f) return v3s(0.0f); /* no light through surfaces */
    vec3 f = b->diffuse;
    if (b->glossy) {
        vec3 r = v3_reflect(v3_neg(wi), b->ns);
        float c = v3_dot(r, wo);
        if (c > 0.0f) f = v3_add(f, v3_scale(b->ks, b->norm * powf(c, b->n)));
    }
    return v3_scale(f, cos_i);
}

/* The shading of a regularised path (pbsdf_regularize): near-specular lobes
 * roughened, so light sampling now reaches them. */
static inline PK_HD void shading_regularize(shading *sh)
{
    pbsdf_regularize(&sh->b);
    sh->nondelta = sh->opaque > 0.0f && pbsdf_has_nondelta(&sh->b) &&
                   (sh->b.type != PBSDF_DIFFUSE || !black(sh->b.albedo));
}

/* f * cos toward wi (world, unit) and its pdf, the dissolve included; zero
 * where the geometric normal says the light comes through the surface. */
static inline PK_HD vec3 shading_eval(const surface *sf, const shading *sh, vec3 wo, vec3 wi, float *pdf)
{
    *pdf = 0.0f;
    const float side = v3_dot(wi, sf->ng), shade = v3_dot(wi, sf->ns);
    if (sh->b.type == PBSDF_METALLIC_ROUGHNESS || sh->b.type == PBSDF_DIFFUSE_TRANSMISSION ||
        sh->b.type == PBSDF_PRINCIPLED_THIN) {
        /* reflects and transmits: both normals must agree */
        if (!(side * shade > 0.0f)) return v3s(0.0f);
    } else if (sh->b.type != PBSDF_DIELECTRIC && !(sh->b.type == PBSDF_PRINCIPLED && sh->b.transmission > 0.0f) &&
               (side <= 0.0f || shade <= 0.0f)) {
        return v3s(0.0f);
    }
    vec3 lo = onb_to_local(sh->frame, wo), li = onb_to_local(sh->frame, wi);
    *pdf = sh->opaque * pbsdf_pdf(&sh->b, lo, li);
    return v3_scale(pbsdf_eval(&sh->b, lo, li), sh->opaque);
}

/* Samples the next direction. Returns false when the path ends. */
static inline PK_HD bool shading_sample(const surface *sf, const shading *sh, vec3 wo, float u0, float u1, float u2, vec3 *wi,
                           vec3 *weight, float *pdf, bool *delta)
{
    if (u0 >= sh->opaque) { /* straight through (dissolve) */
        *wi = v3_neg(wo);
        *weight = v3s(1.0f);
        *pdf = 0.0f;
        *delta = true;
        return true;
    }
    const float u[3] = {u0 / sh->opaque, u1, u2};
    vec3 lo = onb_to_local(sh->frame, wo), li, w;
    float p;
    bool d;
    if (!pbsdf_sample(&sh->b, lo, u, &li, &w, &p, &d)) return false;
    vec3 out = v3_norm(onb_to_world(sh->frame, li));
    /* reflection stays on the side of the incoming ray, transmission crosses:
     * by the geometric normal, so that shading normals never leak light */
    const bool transmit = li.z * lo.z < 0.0f;
    if (transmit ? v3_dot(out, sf->ng) >= 0.0f : v3_dot(out, sf->ng) <= 0.0f) return false;
    *wi = out;
    *weight = w;
    *pdf = d ? 0.0f : p * sh->opaque;
    *delta = d;
    return true;
}

#endif

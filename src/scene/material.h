/*
 * material.h - the material model: one record per material with a closed
 * set of kinds, and one constructor per kind that fills the physically
 * based parameters and, in this one place, the MTL fields that the Whitted
 * integrator renders as an approximation of the kind. Readers (JSON,
 * Mitsuba XML, and those to come) describe what a file says by calling the
 * constructors; they never write a kind's approximation themselves. The
 * path tracer turns a record into a BSDF in render/shading.h.
 *
 * Kinds: MAT_MTL (an MTL material: Kd, Ks, Ns, Ni, Tf, d and the illum code,
 * set field by field by the MTL reader), diffuse, conductor (a complex
 * index or a normal-incidence reflectance), dielectric, plastic (a diffuse
 * base under a dielectric coat), metallic-roughness (glTF 2.0's BRDF: a
 * metal and a dielectric mixed by metalness), thin dielectric, diffuse
 * transmission, mix (one of two materials per hit), rough diffuse
 * (Oren-Nayar), Phong and coated (pbrt-v4's layered coateddiffuse and
 * coatedconductor). Emission (ke) and
 * two-sidedness go with any kind; texture maps (texture.h) scale the
 * constants.
 */
#ifndef PK_MATERIAL_H
#define PK_MATERIAL_H

#include "../math/vec3.h"
#include "texture.h"

#include <stdbool.h>

typedef enum material_type {
    MAT_MTL,
    MAT_DIFFUSE,
    MAT_CONDUCTOR,
    MAT_DIELECTRIC,
    MAT_PLASTIC,
    MAT_METALLIC_ROUGHNESS,
    MAT_INTERFACE,  /* no surface: the boundary of a medium, which rays pass straight through */
    MAT_THIN_DIELECTRIC,      /* a smooth thin sheet (a window pane) */
    MAT_DIFFUSE_TRANSMISSION, /* Lambertian reflection and transmission */
    MAT_MIX,                  /* one of two materials, chosen per hit */
    MAT_ROUGH_DIFFUSE,        /* Oren-Nayar */
    MAT_PHONG,                /* the modified Phong model */
    MAT_COATED,               /* pbrt-v4's layered BSDF: a dielectric coat over a diffuse or conductor base */
    MAT_PRINCIPLED,           /* Mitsuba 3's principled BSDF */
    MAT_LAST = MAT_PRINCIPLED
} material_type;

/* The deepest nesting of mixes (a mix of mixes ...) that readers accept. */
#define MATERIAL_MIX_DEPTH 16

/* The slab between a coated material's coat and its base (MAT_COATED). */
typedef struct material_layer {
    float thickness; /* > 0 */
    vec3 albedo;     /* the medium's single-scattering albedo, 0..1; 0 = clear */
    float g;         /* its Henyey-Greenstein asymmetry, -1..1 */
    int maxdepth;    /* >= 1: the longest random walk */
    int nsamples;    /* >= 1: walks averaged per estimate */
} material_layer;

/* Colours are linear RGB. illum follows the MTL convention: 3/5 add mirror
 * reflection weighted by ks, 4/6/7 make the surface a dielectric of index
 * ni tinted by tf. */
typedef struct material {
    char *name;    /* owned */
    vec3 kd;       /* diffuse albedo */
    vec3 ks;       /* specular (Phong lobe, or mirror weight) */
    vec3 ke;       /* emitted radiance; non-zero makes every triangle an area light */
    vec3 tf;       /* transmission filter for refraction */
    vec3 ka;       /* ambient; only used when the scene sets an ambient light */
    float ns;      /* Phong exponent */
    float ni;      /* index of refraction */
    float d;       /* dissolve, 1 = opaque (Tr = 1 - d) */
    int illum;
    /* Emission on both sides (the path tracer; area lights are one-sided by
     * default, emitting on the side of the winding normal, counter-clockwise
     * v0 v1 v2, and of a sphere's outward normal). The Whitted integrator
     * treats every emitter as two-sided. */
    bool two_sided;
    /* The kind (material_type). MAT_MTL (material_init's default, every MTL
     * material) is the MTL model of the fields above. The others are for
     * the path tracer: MAT_DIFFUSE has the albedo kd; MAT_CONDUCTOR the
     * complex index eta + i k, or with schlick the normal-incidence
     * reflectance ks (Schlick's Fresnel); MAT_DIELECTRIC the index ni and
     * the transmittance tf; MAT_PLASTIC the albedo kd under a coating of
     * index ni. alpha is the GGX roughness of the conductor, dielectric and
     * plastic (0 = smooth). MAT_METALLIC_ROUGHNESS is glTF 2.0's material:
     * base colour kd, metallic and perceptual roughness in 0..1 (GGX alpha =
     * roughness^2 at shading), transmission in 0..1 (KHR_materials_
     * transmission: the thin-walled transmitted share of the dielectric's
     * base) and the dielectric's index ni (KHR_materials_ior, 1.5 by
     * default), clearcoat and clearcoat_roughness in 0..1 (KHR_materials_
     * clearcoat: a clear layer of ior 1.5 over it all; 0 = none). Their
     * constructors also set the MTL fields to what the
     * Whitted integrator renders of them (for metallic-roughness,
     * material_whitted_kd gives the Whitted diffuse, since kd holds the base
     * colour). */
    int type;
    float alpha;
    /* conductor, dielectric, plastic: anisotropic roughness when >= 0 and
     * not alpha (material_init: -1, isotropic): alpha is then the roughness
     * along the surface's tangent dp/du (pbrt's uroughness, Mitsuba's
     * alpha_u) and alpha_v the one across it. map_alpha scales both. */
    float alpha_v;
    vec3 eta, k;
    bool schlick;
    /* conductor: a factor on its Fresnel reflectance, per channel in [0, 1]
     * (Mitsuba's specular_reflectance, Tungsten's albedo: both multiply the
     * whole microfacet BRDF by it); 1 (material_init) leaves it alone */
    vec3 tint;
    /* conductor, dielectric, plastic: alpha is the roughness of the Beckmann
     * distribution instead of GGX (Mitsuba's default microfacet model) */
    bool beckmann;
    /* MAT_MIX: the materials mix_a and mix_b (indices into the scene's
     * materials, both below the mix's own index), and amount in [0, 1], the
     * probability of mix_b at a hit (map_alpha, when set, multiplies it). */
    int mix_a, mix_b;
    float amount;
    float metallic, roughness, transmission, clearcoat, clearcoat_roughness;
    /* MAT_METALLIC_ROUGHNESS: the surface bounds a volume (KHR_materials_
     * volume with a thickness): its transmission refracts into the inside
     * (a rough dielectric of ni and the roughness) instead of passing
     * through a thin sheet, and the inside sees the boundary from within */
    bool volume;
    /* MAT_COATED: a dielectric coat of index ni and GGX alpha over a base,
     * MATERIAL_BASE_DIFFUSE (Lambert of kd) or MATERIAL_BASE_CONDUCTOR (a
     * metal of complex index eta + i k as a file gives it, relative to
     * vacuum, or with schlick of normal-incidence reflectance ks; GGX
     * base_alpha), and between them the layer (material_layer). */
    int coat_base;
    float base_alpha;
    material_layer layer;
    /* MAT_PRINCIPLED (Mitsuba 3's principled, material_principled): base
     * colour kd, metallic, roughness (GGX alpha = max(0.001, roughness^2)),
     * transmission (spec_trans), clearcoat, the index ni (eta, or Mitsuba's
     * specular mapped to it), and these, all in [0, 1]: anisotropic (GGX
     * alphas ax along dp/du and ay across it, Mitsuba's calc_dist_params;
     * alpha = sqrt(ax ay) for the Whitted integrator), spec_tint, sheen,
     * sheen_tint, flatness, clearcoat_gloss; and the sampling rates of the
     * main specular, clearcoat and diffuse lobes (>= 0, 1 by default).
     * map_kd multiplies the base colour and map_alpha the roughness. */
    float anisotropic, ax, ay, spec_tint, sheen, sheen_tint, flatness, clearcoat_gloss;
    float srate_spec, srate_cc, srate_diff;
    /* thin: Mitsuba's principledthin instead (a two-sided sheet of index ni,
     * no metallic or clearcoat; srate_spec is its specular reflection's
     * rate) with diff_trans in [0, 1] (Mitsuba's 0 ... 2 halved) and the
     * sampling rates of its specular and diffuse transmission */
    bool thin;
    float diff_trans, srate_st, srate_dt;
    /* MAT_METALLIC_ROUGHNESS, glTF's PBR extensions (material_init's
     * defaults leave the plain model): KHR_materials_specular's specular
     * (weight of the dielectric's specular layer, 0..1; 1) and specular_color
     * (its F0 colour, >= 0; 1); KHR_materials_sheen's sheen_color (0..1; 0 =
     * no sheen) and sheen_roughness (0..1); KHR_materials_iridescence's
     * iridescence (strength 0..1; 0 = none), iridescence_ior (the film's
     * index; 1.3) and its thickness in nm, iridescence_thickness (the
     * maximum; 400) and iridescence_thickness_min (100): without
     * map_irid_thick the film is iridescence_thickness thick;
     * KHR_materials_anisotropy's anisotropy (strength 0..1; 0) and
     * anisotropy_rotation (radians from the tangent dp/du toward n x dp/du):
     * the specular lobe's GGX alpha along that direction is mix(alpha, 1,
     * strength^2), across it alpha. */
    float specular;
    vec3 specular_color, sheen_color;
    float sheen_roughness, iridescence, iridescence_ior, iridescence_thickness, iridescence_thickness_min;
    float anisotropy, anisotropy_rotation;
    float whitted_sheen; /* derived (material_gltf_update): the sheen's mean albedo, for the Whitted integrator */
    /* Texture maps (docs/materials.md), kind TEX_NONE when absent. A map's
     * value multiplies its constant: map_kd kd, map_ks ks, map_ns ns,
     * map_alpha alpha; map_mr is glTF's metallic-roughness texture (data,
     * not sRGB): its blue channel multiplies metallic, its green roughness
     * (a grey texture multiplies both). map_d cuts holes: where its opacity is below 0.5 the
     * surface is not there for any ray (the constant d still dissolves the
     * rest). map_bump is a height field (heights times bm, in scene units);
     * map_norm a tangent-space normal map. map_ke multiplies the emission ke
     * (linear colour, values above 1 allowed): a textured emitter. map_eta
     * and map_k multiply a conductor's eta and k (not clamped above: pbrt's
     * spectrum textures on conductor.eta and .k); map_tf multiplies the
     * transmittance tf of a dielectric, thin dielectric or diffuse
     * transmitter (clamped to 0..1). glTF's layers (data, not sRGB; each
     * value multiplies its constant, clamped to 0..1): map_tr's red channel
     * the transmission (KHR_materials_transmission), map_cc's red the
     * clearcoat and map_ccr's green the clearcoat roughness (a grey texture:
     * its grey); map_ccn is the clearcoat's own normal map (tangent space,
     * as map_norm, its x and y scaled by coat_norm_scale). */
    tex_ref map_kd, map_ks, map_ns, map_d, map_alpha, map_bump, map_norm, map_mr, map_ke, map_eta, map_k, map_tf;
    tex_ref map_tr, map_cc, map_ccr, map_ccn;
    /* glTF's extension maps (metallic-roughness): map_spec's alpha
     * multiplies specular, map_spec_color specular_color, map_sheen
     * sheen_color, map_sheen_rough's alpha sheen_roughness, map_irid's red
     * iridescence; map_irid_thick's green g makes the film
     * iridescence_thickness_min + g (iridescence_thickness -
     * iridescence_thickness_min) thick; map_aniso's red and green are a
     * direction (2 c - 1) in the tangent frame that rotates the anisotropy's
     * (by its angle), its blue multiplies the strength. */
    tex_ref map_spec, map_spec_color, map_sheen, map_sheen_rough, map_irid, map_irid_thick, map_aniso;
    /* map_norm's scale (glTF's normalTexture.scale): the map's x and y are
     * multiplied by it before the normal is normalised; 1 by default */
    float norm_scale, coat_norm_scale;
    /* glTF's alphaMode BLEND as stochastic transparency: the surface is
     * there for a ray with probability blend_alpha times map_d's alpha
     * (when map_d is set; then it is no cut-out), decided by a hash of the
     * ray and the hit (surface_is_hole), for shadow rays as for the others */
    bool blend;
    float blend_alpha;
    /* the triangles' vertex colours (glTF's COLOR_0; white where a vertex
     * has none) multiply kd, and with blend their alpha blend_alpha;
     * emit_vertex_color: they multiply ke too (glTF's unlit materials, whose
     * base colour is their emission) */
    bool vertex_color, emit_vertex_color;
    /* The media on either side (medium.h): medium_out on the side the
     * geometric normal points to, medium_in on the other; an index into the
     * scene's media, MEDIUM_NONE (vacuum) or MEDIUM_INHERIT (the surface
     * does not change the ray's medium; material_init's default). */
    int32_t medium_in, medium_out;
    /* derived by scene_commit: a map other than map_d is set, or the
     * roughness is anisotropic (the shading then needs the surface's
     * tangent, which surface_texture finds with the texture coordinates) */
    bool textured;
    bool cutout;     /* derived by scene_commit: map_d is set */
} material;

/* Every texture map of a material, once: X(field) for each, in the order
 * scene files write them. The lists below (names, offsets) and every loop
 * over a material's maps come from it, so that a new map is added here and
 * in the struct only. */
#define MATERIAL_MAPS(X)                                                                                            \
    X(map_kd) X(map_ks) X(map_ns) X(map_d) X(map_alpha) X(map_bump) X(map_norm) X(map_mr) X(map_ke) X(map_eta)     \
    X(map_k) X(map_tf) X(map_tr) X(map_cc) X(map_ccr) X(map_spec) X(map_spec_color) X(map_sheen)                  \
    X(map_sheen_rough) X(map_irid) X(map_irid_thick) X(map_aniso) X(map_ccn)
#define MATERIAL__ONE(f) +1
enum { MATERIAL_NMAPS = 0 MATERIAL_MAPS(MATERIAL__ONE) };
/* The maps' field names ("map_kd", ...) and their offsets in material, in
 * MATERIAL_MAPS's order. */
PK_HIDDEN extern const char *const material_map_names[MATERIAL_NMAPS];
PK_HIDDEN extern const size_t material_map_offsets[MATERIAL_NMAPS];
/* Map k (< MATERIAL_NMAPS) of m. */
static inline tex_ref *material_map(material *m, int k)
{
    return (tex_ref *)(void *)((char *)m + material_map_offsets[k]);
}
static inline const tex_ref *material_map_c(const material *m, int k)
{
    return (const tex_ref *)(const void *)((const char *)m + material_map_offsets[k]);
}

/* The MTL defaults (Kd 0.8, illum 2, opaque, no maps, no name). */
PK_HIDDEN void material_init(material *m);

/* The constructors set the kind, its parameters and its Whitted
 * approximation, and nothing else (name, maps, dissolve, emission and
 * two-sidedness stay as they were). alpha is the GGX roughness, 0 smooth. */

/* Lambert of albedo kd. */
PK_HIDDEN void material_diffuse(material *m, vec3 albedo);
/* A metal of complex index eta + i k (relative to the outside). */
PK_HIDDEN void material_conductor(material *m, vec3 eta, vec3 k, float alpha);
/* A metal by its normal-incidence reflectance f0 (Schlick's Fresnel). */
PK_HIDDEN void material_conductor_f0(material *m, vec3 f0, float alpha);
/* Scales a conductor's Fresnel reflectance by tint (after one of the two
 * above): Mitsuba's specular_reflectance. The Whitted approximation (ks) of
 * a metal given by eta and k is scaled too; a Schlick metal's ks is its F0
 * for the path tracer as well, so its Whitted mirror keeps F0 unscaled. */
PK_HIDDEN void material_conductor_tint(material *m, vec3 tint);
/* Glass of relative index ior; transmittance tints the light that enters. */
PK_HIDDEN void material_dielectric(material *m, float ior, float alpha, vec3 transmittance);
/* An index-matched boundary between media (Mitsuba's null BSDF, pbrt's
 * interface material): invisible to rays, it only says which media lie on
 * either side. The Whitted integrator and the path tracer see it as glass of
 * index 1 (rays pass through unchanged). */
PK_HIDDEN void material_interface(material *m);
/* A diffuse base of albedo under a dielectric coat of index ior. */
PK_HIDDEN void material_plastic(material *m, vec3 albedo, float ior, float alpha);

/* A smooth thin sheet of relative index ior (both faces): it reflects by the
 * sheet's reflectance, light bouncing between its faces, and lets the rest
 * through undeviated, tinted by transmittance. The index is kept in eta
 * (every channel); ni is 1 and illum 7: the Whitted integrator sees a clear
 * sheet of glass of index 1 (straight through, its reflection lost). */
PK_HIDDEN void material_thin_dielectric(material *m, float ior, vec3 transmittance);
/* Lambertian reflection of reflectance (kd) on the side light arrives from
 * and Lambertian transmission of transmittance (tf) to the other side. The
 * Whitted integrator renders the reflection alone. */
PK_HIDDEN void material_diffuse_transmission(material *m, vec3 reflectance, vec3 transmittance);
/* One of the materials a and b (indices into the scene's materials, below
 * the mix's own), chosen per hit with probability amount for b (clamped to
 * 0..1) by a hash of the hit point and the direction to the viewer. */
PK_HIDDEN void material_mix(material *m, int a, int b, float amount);
/* Oren-Nayar's rough diffuse reflection of albedo and roughness alpha, the
 * RMS slope of its facets as Mitsuba gives it (sigma = alpha / sqrt(2));
 * the Whitted integrator renders it as Lambert. */
PK_HIDDEN void material_rough_diffuse(material *m, vec3 albedo, float alpha);
/* The modified Phong model: diffuse kd, a lobe of ks and exponent about the
 * mirror direction, normalised ((exponent + 2) / (2 pi)); where kd + ks > 1
 * in a channel both are scaled down in it. The Whitted integrator's own
 * Lambert + Phong is the same model (illum 2). */
PK_HIDDEN void material_phong(material *m, vec3 kd, vec3 ks, float exponent);

/* pbrt-v4's coated materials (MAT_COATED). The layer's defaults are pbrt's:
 * material_layer_default gives thickness 0.01, albedo 0, g 0, maxdepth 10,
 * nsamples 1; constructors clamp it into range. The Whitted integrator sees
 * the coat's Fresnel reflection (a mirror or a Phong lobe of its
 * roughness) over the base's diffuse (coateddiffuse) or the base's
 * reflectance (coatedconductor). */
enum { MATERIAL_BASE_DIFFUSE = 0, MATERIAL_BASE_CONDUCTOR = 1 };
PK_HIDDEN material_layer material_layer_default(void);
/* A Lambertian base of reflectance under a coat of index ior and alpha. */
PK_HIDDEN void material_coated_diffuse(material *m, vec3 reflectance, float ior, float alpha, material_layer layer);
/* A conductor base of eta + i k (relative to vacuum; the coat's index
 * divides them at shading, as pbrt-v4 does) and GGX base_alpha. */
PK_HIDDEN void material_coated_conductor(material *m, vec3 eta, vec3 k, float base_alpha, float ior, float alpha,
                                         material_layer layer);
/* The same by the conductor's normal-incidence reflectance (in ks: a map_ks
 * scales it), turned into eta = 1, k = 2 sqrt(r) / sqrt(1 - r) at shading as
 * pbrt-v4 does. */
PK_HIDDEN void material_coated_conductor_f0(material *m, vec3 reflectance, float base_alpha, float ior, float alpha,
                                            material_layer layer);

/* glTF 2.0's metallic-roughness material: base colour (linear), metallic and
 * perceptual roughness in 0..1; transmission 0, ior 1.5 and no clearcoat
 * (set the fields transmission, ni, clearcoat and clearcoat_roughness
 * afterwards for KHR_materials_transmission, _ior and _clearcoat;
 * material_whitted_kd reads transmission where it is used; the Whitted
 * approximation has no clearcoat). */
PK_HIDDEN void material_metallic_roughness(material *m, vec3 base_color, float metallic, float roughness);
/* After setting a metallic-roughness material's extension fields (above):
 * the Whitted approximation of them (the glossy weight ks of the specular's
 * F0, the sheen's mean albedo). */
PK_HIDDEN void material_gltf_update(material *m);
/* Mitsuba 3's principled with its defaults but for these (see the fields
 * above; set the others after it, then call material_principled_update). */
PK_HIDDEN void material_principled(material *m, vec3 base_color, float metallic, float roughness);
/* Derives alpha, ax, ay and the Whitted fields from the principled fields. */
PK_HIDDEN void material_principled_update(material *m);

/* The diffuse reflectance that the MTL model and the Whitted integrator use:
 * kd, but for metallic-roughness and principled the base colour's diffuse
 * share kd (1 - metallic) (1 - transmission) (principledthin: also
 * (1 - diff_trans)). */
static inline PK_HD vec3 material_whitted_kd(const material *m)
{
    if (m->type == MAT_METALLIC_ROUGHNESS && v3_max_comp(m->sheen_color) > 0.0f) {
        /* the sheen over the rest: its colour times its mean albedo (whitted_sheen) */
        const float c = v3_max_comp(m->sheen_color);
        return v3_add(v3_scale(m->kd, (1.0f - m->metallic) * (1.0f - m->transmission) *
                                          fmaxf(0.0f, 1.0f - c * m->whitted_sheen)),
                      v3_scale(m->sheen_color, m->whitted_sheen));
    }
    if (m->type == MAT_PRINCIPLED) /* principledthin: less its diffuse transmission */
        return v3_scale(m->kd, (1.0f - m->metallic) * (1.0f - m->transmission) * (1.0f - m->diff_trans));
    if (m->type != MAT_METALLIC_ROUGHNESS) return m->kd;
    return v3_scale(m->kd, (1.0f - m->metallic) * (1.0f - m->transmission));
}

/* The MTL illumination models (docs/materials.md), decoded here once for
 * both integrators: 4, 6 and 7 a smooth dielectric of index ni tinted by tf;
 * 3 and 5 an ideal mirror weighted by ks; 2 a glossy lobe of ks and ns over
 * the diffuse (Phong for the Whitted integrator, GGX for the path tracer). */
static inline PK_HD bool material_mtl_glass(const material *m)
{
    return m->illum == 4 || m->illum == 6 || m->illum == 7;
}
static inline PK_HD bool material_mtl_mirror(const material *m) { return m->illum == 3 || m->illum == 5; }
static inline PK_HD bool material_mtl_glossy(const material *m)
{
    return m->illum == 2 && (m->ks.x > 0.0f || m->ks.y > 0.0f || m->ks.z > 0.0f);
}
/* The glass's Tf as the tint of the light that enters: its hue, normalised
 * to the brightest channel (exporters write grey Tf of any strength for
 * clear glass); white for a black Tf. */
static inline PK_HD vec3 material_mtl_tint(const material *m)
{
    float tmax_c = v3_max_comp(m->tf);
    return tmax_c > 0.0f ? v3_scale(m->tf, 1.0f / tmax_c) : v3s(1.0f);
}

/* Whether the material's roughness is anisotropic (alpha_v, above; for
 * principled its anisotropic > 0). */
static inline PK_HD bool material_anisotropic(const material *m)
{
    if (m->type == MAT_PRINCIPLED) return m->anisotropic > 0.0f;
    if (m->type == MAT_METALLIC_ROUGHNESS) return m->anisotropy > 0.0f || m->map_aniso.kind != TEX_NONE;
    return (m->type == MAT_CONDUCTOR || m->type == MAT_DIELECTRIC || m->type == MAT_PLASTIC) && m->alpha_v >= 0.0f &&
           m->alpha_v != m->alpha;
}

/* Fresnel reflectance at normal incidence of a dielectric of index ior,
 * and of a conductor of index eta + i k (per channel). */
PK_HIDDEN float material_f0_dielectric(float ior);
PK_HIDDEN vec3 material_f0_conductor(vec3 eta, vec3 k);

#endif

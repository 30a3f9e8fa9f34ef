/*
 * material.c - the material model's constructors (see material.h).
 */
#include "material.h"

#include <stddef.h>

#define MATERIAL__NAME(f) #f,
#define MATERIAL__OFFSET(f) offsetof(material, f),
const char *const material_map_names[MATERIAL_NMAPS] = {MATERIAL_MAPS(MATERIAL__NAME)};
const size_t material_map_offsets[MATERIAL_NMAPS] = {MATERIAL_MAPS(MATERIAL__OFFSET)};

#include "../render/sheen.h"

#include <math.h>
#include <string.h>

void material_init(material *m)
{
    memset(m, 0, sizeof *m);
    m->kd = v3s(0.8f);
    m->tf = v3s(1.0f);
    m->tint = v3s(1.0f);
    m->ns = 1.0f;
    m->ni = 1.0f;
    m->d = 1.0f;
    m->illum = 2;
    m->medium_in = m->medium_out = -2; /* MEDIUM_INHERIT */
    m->alpha_v = -1.0f;                /* isotropic */
    m->norm_scale = m->coat_norm_scale = 1.0f;
    for (int k = 0; k < MATERIAL_NMAPS; k++) tex_ref_init(material_map(m, k));
    m->specular = 1.0f;
    m->specular_color = v3s(1.0f);
    m->iridescence_ior = 1.3f;
    m->iridescence_thickness = 400.0f, m->iridescence_thickness_min = 100.0f;
}

float material_f0_dielectric(float ior)
{
    float r = (ior - 1.0f) / (ior + 1.0f);
    return r * r;
}

vec3 material_f0_conductor(vec3 eta, vec3 k)
{
    /* ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2) */
    const float e[3] = {eta.x, eta.y, eta.z}, kk[3] = {k.x, k.y, k.z};
    float r[3];
    for (int c = 0; c < 3; c++)
        r[c] = ((e[c] - 1.0f) * (e[c] - 1.0f) + kk[c] * kk[c]) / ((e[c] + 1.0f) * (e[c] + 1.0f) + kk[c] * kk[c]);
    return v3(r[0], r[1], r[2]);
}

/* The MTL Phong exponent whose path tracer alpha (sqrt(2/(Ns+2))) is alpha. */
static float ns_from_alpha(float alpha) { return alpha < 1e-3f ? 1000.0f : fmaxf(2.0f / (alpha * alpha) - 2.0f, 0.0f); }

/* The Whitted approximation of a glossy lobe of roughness alpha over the
 * weight ks already set: an ideal mirror (illum 3) when it is smooth, else
 * the Phong lobe (illum 2) of matching width. */
static void whitted_gloss(material *m, float alpha)
{
    if (alpha < 1e-3f) m->illum = 3;
    else m->ns = ns_from_alpha(alpha);
}

void material_diffuse(material *m, vec3 albedo)
{
    m->type = MAT_DIFFUSE;
    m->kd = albedo;
}

void material_conductor(material *m, vec3 eta, vec3 k, float alpha)
{
    m->type = MAT_CONDUCTOR;
    m->schlick = false;
    m->eta = eta, m->k = k, m->alpha = alpha;
    m->kd = v3s(0.0f), m->ks = material_f0_conductor(eta, k);
    whitted_gloss(m, alpha);
}

void material_conductor_f0(material *m, vec3 f0, float alpha)
{
    m->type = MAT_CONDUCTOR;
    m->schlick = true;
    m->alpha = alpha;
    m->kd = v3s(0.0f), m->ks = f0;
    whitted_gloss(m, alpha);
}

void material_conductor_tint(material *m, vec3 tint)
{
    m->tint = tint;
    if (!m->schlick) m->ks = v3_mul(m->ks, tint);
}

void material_dielectric(material *m, float ior, float alpha, vec3 transmittance)
{
    m->type = MAT_DIELECTRIC;
    m->ni = ior, m->alpha = alpha, m->tf = transmittance;
    m->kd = v3s(0.0f), m->ks = v3s(material_f0_dielectric(ior));
    m->illum = 7;
}

void material_interface(material *m)
{
    m->type = MAT_INTERFACE;
    m->ni = 1.0f, m->alpha = 0.0f, m->tf = v3s(1.0f);
    m->kd = v3s(0.0f), m->ks = v3s(0.0f);
    m->illum = 7;
}

void material_plastic(material *m, vec3 albedo, float ior, float alpha)
{
    m->type = MAT_PLASTIC;
    m->kd = albedo, m->ni = ior, m->alpha = alpha;
    m->ks = v3s(material_f0_dielectric(ior));
    whitted_gloss(m, alpha);
}

void material_metallic_roughness(material *m, vec3 base_color, float metallic, float roughness)
{
    m->type = MAT_METALLIC_ROUGHNESS;
    m->kd = base_color;
    m->metallic = metallic, m->roughness = roughness, m->transmission = 0.0f;
    m->clearcoat = m->clearcoat_roughness = 0.0f;
    m->ni = 1.5f;
    m->alpha = roughness * roughness;
    /* Whitted: the diffuse share of kd (material_whitted_kd), and a glossy
     * lobe of the Fresnel reflectance at normal incidence, 0.04 for the
     * dielectric, the base colour for the metal */
    m->ks = v3_add(v3s((1.0f - metallic) * 0.04f), v3_scale(base_color, metallic));
    m->illum = 2;
    whitted_gloss(m, m->alpha);
}

void material_gltf_update(material *m)
{
    if (m->type != MAT_METALLIC_ROUGHNESS) return;
    const float f0 = material_f0_dielectric(m->ni), mt = m->metallic;
    const vec3 f0c = v3_scale(v3_min(v3_scale(m->specular_color, f0), v3s(1.0f)), m->specular);
    m->ks = v3_add(v3_scale(f0c, 1.0f - mt), v3_scale(m->kd, mt));
    m->whitted_sheen = v3_max_comp(m->sheen_color) > 0.0f ? sheen_eavg(m->sheen_roughness) : 0.0f;
}

void material_principled(material *m, vec3 base_color, float metallic, float roughness)
{
    m->type = MAT_PRINCIPLED;
    m->kd = base_color;
    m->metallic = metallic, m->roughness = roughness;
    m->transmission = m->clearcoat = m->clearcoat_roughness = 0.0f;
    m->anisotropic = m->spec_tint = m->sheen = m->sheen_tint = m->flatness = m->clearcoat_gloss = 0.0f;
    m->srate_spec = m->srate_cc = m->srate_diff = 1.0f;
    m->thin = false;
    m->diff_trans = 0.0f;
    m->srate_st = m->srate_dt = 1.0f;
    m->ni = 2.0f / (1.0f - sqrtf(0.08f * 0.5f)) - 1.0f; /* Mitsuba's specular 0.5 */
    material_principled_update(m);
}

void material_principled_update(material *m)
{
    /* Mitsuba's calc_dist_params */
    const float r2 = m->roughness * m->roughness;
    const float aspect = sqrtf(1.0f - 0.9f * m->anisotropic);
    m->ax = fmaxf(1e-3f, r2 / aspect), m->ay = fmaxf(1e-3f, r2 * aspect);
    m->alpha = sqrtf(m->ax * m->ay);
    /* Whitted: the diffuse share of kd (material_whitted_kd) and a glossy
     * lobe of the Fresnel reflectance at normal incidence */
    const float f0 = material_f0_dielectric(m->ni);
    m->ks = v3_add(v3s((1.0f - m->metallic) * f0), v3_scale(m->kd, m->metallic));
    m->illum = 2;
    whitted_gloss(m, m->alpha);
}

void material_thin_dielectric(material *m, float ior, vec3 transmittance)
{
    m->type = MAT_THIN_DIELECTRIC;
    m->eta = v3s(ior), m->tf = transmittance, m->alpha = 0.0f;
    /* Whitted: a clear sheet (glass of index 1, weights Ks and Tf when
     * Fresnel is off: the sheet's reflectance at normal incidence) */
    const float r = material_f0_dielectric(ior);
    m->ni = 1.0f;
    m->kd = v3s(0.0f), m->ks = v3s(r < 1.0f ? r + (1.0f - r) * (1.0f - r) * r / (1.0f - r * r) : 1.0f);
    m->illum = 7;
}

void material_diffuse_transmission(material *m, vec3 reflectance, vec3 transmittance)
{
    m->type = MAT_DIFFUSE_TRANSMISSION;
    m->kd = reflectance, m->tf = transmittance;
    m->ks = v3s(0.0f);
    m->illum = 2;
}

void material_mix(material *m, int a, int b, float amount)
{
    m->type = MAT_MIX;
    m->mix_a = a, m->mix_b = b;
    m->amount = fminf(fmaxf(amount, 0.0f), 1.0f);
    /* never shaded itself (shading meets one of the two); Whitted likewise */
    m->kd = v3s(0.5f), m->ks = v3s(0.0f);
    m->illum = 2;
}

void material_rough_diffuse(material *m, vec3 albedo, float alpha)
{
    m->type = MAT_ROUGH_DIFFUSE;
    m->kd = albedo, m->alpha = fmaxf(alpha, 0.0f);
    m->ks = v3s(0.0f);
    m->illum = 2;
}

void material_phong(material *m, vec3 kd, vec3 ks, float exponent)
{
    float *d[3] = {&kd.x, &kd.y, &kd.z}, *s[3] = {&ks.x, &ks.y, &ks.z};
    for (int c = 0; c < 3; c++) {
        const float sum = *d[c] + *s[c];
        if (sum > 1.0f) *d[c] /= sum, *s[c] /= sum;
    }
    m->type = MAT_PHONG;
    m->kd = kd, m->ks = ks, m->ns = fmaxf(exponent, 0.0f);
    m->illum = 2;
}

material_layer material_layer_default(void)
{
    material_layer l;
    l.thickness = 0.01f, l.albedo = v3s(0.0f), l.g = 0.0f, l.maxdepth = 10, l.nsamples = 1;
    return l;
}

static void coated(material *m, int base, float ior, float alpha, material_layer layer)
{
    m->type = MAT_COATED;
    m->coat_base = base;
    m->ni = ior, m->alpha = fminf(fmaxf(alpha, 0.0f), 1.0f);
    if (!(layer.thickness > 0.0f) || !isfinite(layer.thickness)) layer.thickness = 1e-6f;
    layer.albedo = v3_min(v3_max(layer.albedo, v3s(0.0f)), v3s(1.0f));
    layer.g = fminf(fmaxf(layer.g, -0.99f), 0.99f);
    if (layer.maxdepth < 1) layer.maxdepth = 1;
    if (layer.nsamples < 1) layer.nsamples = 1;
    m->layer = layer;
}

void material_coated_diffuse(material *m, vec3 reflectance, float ior, float alpha, material_layer layer)
{
    coated(m, MATERIAL_BASE_DIFFUSE, ior, alpha, layer);
    m->kd = reflectance;
    m->schlick = false;
    m->base_alpha = 0.0f;
    m->ks = v3s(material_f0_dielectric(ior));
    whitted_gloss(m, m->alpha);
}

void material_coated_conductor(material *m, vec3 eta, vec3 k, float base_alpha, float ior, float alpha,
                               material_layer layer)
{
    coated(m, MATERIAL_BASE_CONDUCTOR, ior, alpha, layer);
    m->schlick = false;
    m->eta = eta, m->k = k;
    m->base_alpha = fminf(fmaxf(base_alpha, 0.0f), 1.0f);
    m->kd = v3s(0.0f), m->ks = material_f0_conductor(v3_scale(eta, 1.0f / ior), v3_scale(k, 1.0f / ior));
    whitted_gloss(m, fmaxf(m->alpha, m->base_alpha));
}

void material_coated_conductor_f0(material *m, vec3 reflectance, float base_alpha, float ior, float alpha,
                                  material_layer layer)
{
    coated(m, MATERIAL_BASE_CONDUCTOR, ior, alpha, layer);
    m->schlick = true;
    m->base_alpha = fminf(fmaxf(base_alpha, 0.0f), 1.0f);
    m->kd = v3s(0.0f), m->ks = reflectance;
    whitted_gloss(m, fmaxf(m->alpha, m->base_alpha));
}

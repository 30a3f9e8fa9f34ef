/*
 * bsdf.h - the materials as scattering functions, from the MTL illumination
 * models: Lambert + normalised Phong (illum 2), ideal mirrors (3, 5) and
 * dielectrics (4, 6, 7, see optics.h). Plain functions over plain structs.
 */
#ifndef PK_BSDF_H
#define PK_BSDF_H

#include "surface.h"

static inline bool is_black(vec3 c) { return !(c.x > 0.0f || c.y > 0.0f || c.z > 0.0f); }
static inline bool is_mirror(const material *m) { return m->illum == 3 || m->illum == 5; }
static inline bool is_dielectric(const material *m) { return m->illum == 4 || m->illum == 6 || m->illum == 7; }
/* The material has a diffuse or glossy part that direct light can reach. */
static inline bool has_direct_lobe(const material *m)
{
    return !is_black(material_whitted_kd(m)) || (m->illum == 2 && !is_black(m->ks));
}

/* What brdf_cos reads of a surface, worked out once for the many
 * directions in which light reaches one point (the Whitted integrator's
 * light samples): its normals, the diffuse term and the Phong lobe. */
typedef struct brdf_terms {
    vec3 ns, ng;
    vec3 diffuse;  /* the Whitted diffuse reflectance over pi */
    vec3 ks;       /* the Phong lobe's colour, when glossy */
    float n, norm; /* its exponent and normalisation (n + 2) / (2 pi) */
    bool glossy;   /* illum 2 with a Ks */
} brdf_terms;

static inline brdf_terms brdf_terms_at(const surface *sf)
{
    const material *m = sf->m;
    brdf_terms b;
    b.ns = sf->ns, b.ng = sf->ng;
    b.diffuse = v3_scale(material_whitted_kd(m), 1.0f / PK_PI);
    b.glossy = m->illum == 2 && !is_black(m->ks);
    b.ks = m->ks;
    b.n = m->ns;
    b.norm = (b.n + 2.0f) / (2.0f * PK_PI);
    return b;
}

/* BRDF times cos(theta_i) for light arriving from wi, seen from wo (unit
 * vectors pointing away from the surface). */
static inline vec3 brdf_terms_cos(const brdf_terms *b, vec3 wo, vec3 wi)
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

/* The same for one direction. */
static inline vec3 brdf_cos(const surface *sf, vec3 wo, vec3 wi)
{
    const brdf_terms b = brdf_terms_at(sf);
    return brdf_terms_cos(&b, wo, wi);
}

#endif

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

/* BRDF times cos(theta_i) for light arriving from wi, seen from wo (unit
 * vectors pointing away from the surface). */
static inline vec3 brdf_cos(const surface *sf, vec3 wo, vec3 wi)
{
    float cos_i = v3_dot(sf->ns, wi);
    if (cos_i <= 0.0f || v3_dot(sf->ng, wi) <= 0.0f) return v3s(0.0f); /* no light through surfaces */
    vec3 f = v3_scale(material_whitted_kd(sf->m), 1.0f / PK_PI);
    if (sf->m->illum == 2 && !is_black(sf->m->ks)) {
        vec3 r = v3_reflect(v3_neg(wi), sf->ns);
        float c = v3_dot(r, wo);
        if (c > 0.0f) {
            float n = sf->m->ns;
            f = v3_add(f, v3_scale(sf->m->ks, (n + 2.0f) / (2.0f * PK_PI) * powf(c, n)));
        }
    }
    return v3_scale(f, cos_i);
}

#endif

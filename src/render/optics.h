/*
 * optics.h - reflection, refraction and the exact dielectric Fresnel
 * equations for unpolarised light. Directions are unit vectors; n faces the
 * side the incident ray comes from.
 */
#ifndef PK_OPTICS_H
#define PK_OPTICS_H

#include "../math/vec3.h"

/* Fresnel reflectance of a dielectric interface for light arriving with
 * cos_i = cos(angle to the normal) >= 0 from a medium of index eta_i into one
 * of index eta_t. Returns 1 on total internal reflection. */
static inline PK_HD float fresnel_dielectric(float cos_i, float eta_i, float eta_t)
{
    cos_i = fminf(1.0f, fmaxf(0.0f, cos_i));
    float sin_i = sqrtf(fmaxf(0.0f, 1.0f - cos_i * cos_i));
    float sin_t = eta_i / eta_t * sin_i;
    if (sin_t >= 1.0f) return 1.0f;
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin_t * sin_t));
    float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

/* Refracts the incident direction d (unit, pointing at the surface) through a
 * surface with normal n (unit, dot(d, n) < 0) and relative index
 * eta = eta_i / eta_t. Returns false on total internal reflection. */
static inline PK_HD bool refract_dir(vec3 d, vec3 n, float eta, vec3 *out)
{
    float cos_i = -v3_dot(d, n);
    float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
    if (k < 0.0f) return false;
    *out = v3_norm(v3_add(v3_scale(d, eta), v3_scale(n, eta * cos_i - sqrtf(k))));
    return true;
}

#endif

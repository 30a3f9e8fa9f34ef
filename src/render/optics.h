/*
 * optics.h - reflection, refraction and the exact dielectric Fresnel
 * equations for unpolarised light. Directions are unit vectors; n faces the
 * side the incident ray comes from.
 */
#ifndef PK_OPTICS_H
#define PK_OPTICS_H

#include "../math/vec3.h"

/* The Fresnel equations: unpolarised reflectance of a dielectric interface
 * for light crossing from index eta_i to eta_t at cos_i, refracted to cos_t
 * (both >= 0). The one copy of them: fresnel_dielectric below and the path
 * tracer's pbsdf_fresnel_dielectric (pbsdf.h, with eta_i = 1, which is exact)
 * differ only in how they find cos_t by Snell's law. */
static inline PK_HD float fresnel_equations(float cos_i, float cos_t, float eta_i, float eta_t)
{
    float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

/* Fresnel reflectance of a dielectric interface for light arriving with
 * cos_i = cos(angle to the normal) >= 0 from a medium of index eta_i into one
 * of index eta_t. Returns 1 on total internal reflection. The Whitted
 * integrator's: sin_t = eta_i / eta_t sin_i, where pbsdf_fresnel_dielectric
 * takes sin_t^2 = (1 - cos_i^2) / eta^2; the two round differently (about one
 * input in five differs in the last bits), so each integrator keeps its own
 * and its images stay the same. */
static inline PK_HD float fresnel_dielectric(float cos_i, float eta_i, float eta_t)
{
    cos_i = fminf(1.0f, fmaxf(0.0f, cos_i));
    float sin_i = sqrtf(fmaxf(0.0f, 1.0f - cos_i * cos_i));
    float sin_t = eta_i / eta_t * sin_i;
    if (sin_t >= 1.0f) return 1.0f;
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin_t * sin_t));
    return fresnel_equations(cos_i, cos_t, eta_i, eta_t);
}

/* Refracts the incident direction d (unit, pointing at the surface) through a
 * surface with normal n (unit, dot(d, n) < 0) and relative index
 * eta = eta_i / eta_t. Returns false on total internal reflection. The
 * Whitted integrator's; the path tracer's pbsdf__refract (pbsdf.h) is the
 * same law written with 1 / eta (c / eta, sin_t^2 = (1 - c^2) / eta^2 where
 * this one has eta c and eta^2 (1 - c^2)), which rounds differently. */
static inline PK_HD bool refract_dir(vec3 d, vec3 n, float eta, vec3 *out)
{
    float cos_i = -v3_dot(d, n);
    float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
    if (k < 0.0f) return false;
    *out = v3_norm(v3_add(v3_scale(d, eta), v3_scale(n, eta * cos_i - sqrtf(k))));
    return true;
}

#endif

/*
 * sheen.h - the sheen lobe of glTF's KHR_materials_sheen: the "Charlie"
 * distribution of fibres (Estevez and Kulla 2017) with their fitted
 * visibility term, and the lobe's directional albedo E(mu, r), tabulated,
 * which scales the material under the sheen (pbsdf.h, docs/materials.md).
 *
 *   D(h)   = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi),  a = r^2
 *   V      = 1 / ((1 + Lambda(cos_o) + Lambda(cos_i)) 4 cos_o cos_i)
 *   Lambda = exp(L(c)) for c < 1/2, exp(2 L(1/2) - L(1 - c)) above,
 *   L(x)   = A / (1 + B x^C) + D x + E, A..E interpolated in (1 - a)^2
 *   E(mu, r) = integral over the hemisphere of D V cos_i (colour 1)
 *
 * r is the sheen roughness (glTF's sheenRoughness), clamped to
 * [PK_SH_R_MIN, 1]: below it the distribution is a spike at grazing that
 * float cannot hold. The table has PK_SH_MU nodes in mu over [0, 1] (node 0
 * computed at mu = PK_EN_MU_MIN) and PK_SH_R in r over [PK_SH_R_MIN, 1];
 * sheen_table.inc holds it, written by bench/sheen_table.c with
 * sheen_gen.h's quadrature; tests/unit/test_gltf_lobes.c recomputes entries.
 */
#ifndef PK_SHEEN_H
#define PK_SHEEN_H

#include "../math/vec3.h"
#include "energy.h"

#define PK_SH_MU 32
#define PK_SH_R 32
#define PK_SH_R_MIN 0.07f

PK_HIDDEN extern const float pk_sheen_e[PK_SH_R][PK_SH_MU];
#if defined(__CUDACC__)
#include "sheen_table.inc"
static __device__ const float pk_sheen_e_dev[PK_SH_R][PK_SH_MU] = PK_SHEEN_E_INIT;
#endif

static inline PK_HD float sheen_clamp_r(float r) { return fminf(fmaxf(r, PK_SH_R_MIN), 1.0f); }

/* D(h) for cos_h = h.z (h in the upper hemisphere), a = r^2. */
static inline PK_HD float sheen_d(float a, float cos_h)
{
    const float inv = 1.0f / a, s2 = fmaxf(0.0f, 1.0f - cos_h * cos_h);
    return (2.0f + inv) * powf(s2, 0.5f * inv) * (1.0f / (2.0f * PK_PI));
}
static inline PK_HD float sheen__l(float x, float a)
{
    const float t = (1.0f - a) * (1.0f - a);
    const float A = 21.5473f + (25.3245f - 21.5473f) * t, B = 3.82987f + (3.32435f - 3.82987f) * t;
    const float C = 0.19823f + (0.16801f - 0.19823f) * t, D = -1.97760f + (-1.27393f + 1.97760f) * t;
    const float E = -4.32054f + (-4.85967f + 4.32054f) * t;
    return A / (1.0f + B * powf(x, C)) + D * x + E;
}
static inline PK_HD float sheen_lambda(float a, float c)
{
    c = fabsf(c);
    return c < 0.5f ? expf(sheen__l(c, a)) : expf(2.0f * sheen__l(0.5f, a) - sheen__l(1.0f - c, a));
}
/* D V cos_i of colour 1 (wo.z > 0, wi.z > 0; local frame). */
static inline PK_HD float sheen_cos(float a, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    vec3 h = v3_add(wo, wi);
    if (!(v3_len2(h) > 0.0f)) return 0.0f;
    h = v3_norm(h);
    return sheen_d(a, h.z) / ((1.0f + sheen_lambda(a, wo.z) + sheen_lambda(a, wi.z)) * 4.0f * wo.z);
}

/* E(mu, r) by bilinear interpolation (r clamped as above). */
static inline PK_HD float sheen_e(float r, float mu)
{
    const float(*e)[PK_SH_MU] = PK_EN_TABLE(pk_sheen_e);
    float tr, tm;
    const int ir = energy__cell((sheen_clamp_r(r) - PK_SH_R_MIN) / (1.0f - PK_SH_R_MIN), PK_SH_R, &tr);
    const int im = energy__cell(mu, PK_SH_MU, &tm);
    const float lo = e[ir][im] + (e[ir][im + 1] - e[ir][im]) * tm;
    const float hi = e[ir + 1][im] + (e[ir + 1][im + 1] - e[ir + 1][im]) * tm;
    return lo + (hi - lo) * tr;
}

/* The cosine-weighted mean 2 * integral of E(mu) mu dmu, by the table's
 * nodes (trapezoids in mu): for the Whitted integrator's approximation. */
static inline PK_HD float sheen_eavg(float r)
{
    float s = 0.0f;
    for (int i = 0; i + 1 < PK_SH_MU; i++) {
        const float a = (float)i / (float)(PK_SH_MU - 1), b = (float)(i + 1) / (float)(PK_SH_MU - 1);
        s += 0.5f * (sheen_e(r, a) * a + sheen_e(r, b) * b) * (b - a);
    }
    return 2.0f * s;
}

#endif

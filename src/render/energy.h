/*
 * energy.h - the directional albedo of the single-scattering microfacet
 * lobes (pbsdf.h), tabulated, for energy compensation (pbsdf_compensate,
 * docs/materials.md "Energy compensation"). The numbers are in
 * energy_tables.inc, written by bench/energy_tables.c from the lobes' own
 * sampling code (render/energy_gen.h); tests/render/test_energy.c
 * recomputes entries and compares.
 *
 *   E(mu, alpha)          a white conductor's albedo (Fresnel = 1) toward
 *                         wo with wo.z = mu, GGX and Beckmann
 *   E_avg(alpha)          2 * integral of E(mu) mu dmu over [0, 1], of the
 *                         table's own piecewise linear E, so that a lobe
 *                         built from the lookups integrates exactly
 *   E_d(mu, alpha, n)     a rough dielectric's reflection plus transmission
 *                         (transmittance 1), for light meeting the boundary
 *                         from the side of lower index (n = the relative
 *                         index > 1) and from the side of higher index
 *
 * Node i of an axis of N nodes lies at i / (N - 1) of its range: mu and
 * alpha in [0, 1] (mu = 0 holds the value at mu = 1e-3; alpha = 0 is
 * smooth: E = 1), n in [1, 3]. Lookups interpolate linearly between nodes
 * and clamp outside. Compiled for the GPU too: there the tables are
 * __device__ arrays of the same numbers.
 */
#ifndef PK_ENERGY_H
#define PK_ENERGY_H

#include "../paprsek_internal.h"
#include "../pk_hd.h"

#include <math.h>
#include <stdbool.h>

#define PK_EN_MU 32     /* conductor: nodes in mu */
#define PK_EN_ALPHA 32  /* conductor: nodes in alpha */
#define PK_EN_DMU 32    /* dielectric: nodes in mu */
#define PK_EN_DALPHA 16 /* dielectric: nodes in alpha */
#define PK_EN_DETA 16   /* dielectric: nodes in the relative index n */
#define PK_EN_ETA_MAX 3.0f
#define PK_EN_MU_MIN 1e-3f /* where node mu = 0 is computed */

/* The CPU's tables (energy.c), and under nvcc the same numbers in the
 * GPU's memory (each kernel module its own copy). */
PK_HIDDEN extern const float pk_energy_e[2][PK_EN_ALPHA][PK_EN_MU];
PK_HIDDEN extern const float pk_energy_eavg[2][PK_EN_ALPHA];
PK_HIDDEN extern const float pk_energy_d[2][2][PK_EN_DETA][PK_EN_DALPHA][PK_EN_DMU];
#if defined(__CUDACC__)
#include "energy_tables.inc"
static __device__ const float pk_energy_e_dev[2][PK_EN_ALPHA][PK_EN_MU] = PK_ENERGY_E_INIT;
static __device__ const float pk_energy_eavg_dev[2][PK_EN_ALPHA] = PK_ENERGY_EAVG_INIT;
static __device__ const float pk_energy_d_dev[2][2][PK_EN_DETA][PK_EN_DALPHA][PK_EN_DMU] = PK_ENERGY_D_INIT;
#endif
#if defined(__CUDA_ARCH__)
#define PK_EN_TABLE(name) name##_dev
#else
#define PK_EN_TABLE(name) name
#endif

/* x in [0, 1] over n nodes: the lower node and the weight of the upper. */
static inline PK_HD int energy__cell(float x, int n, float *t)
{
    float s = fminf(fmaxf(x, 0.0f), 1.0f) * (float)(n - 1);
    int i = (int)s;
    if (i > n - 2) i = n - 2;
    *t = s - (float)i;
    return i;
}

/* E(mu, alpha) of GGX (beckmann false) or Beckmann. */
static inline PK_HD float energy_e(bool beckmann, float alpha, float mu)
{
    const float(*e)[PK_EN_MU] = PK_EN_TABLE(pk_energy_e)[beckmann ? 1 : 0];
    float ta, tm;
    const int ia = energy__cell(alpha, PK_EN_ALPHA, &ta), im = energy__cell(mu, PK_EN_MU, &tm);
    const float lo = e[ia][im] + (e[ia][im + 1] - e[ia][im]) * tm;
    const float hi = e[ia + 1][im] + (e[ia + 1][im + 1] - e[ia + 1][im]) * tm;
    return lo + (hi - lo) * ta;
}

/* E_avg(alpha). */
static inline PK_HD float energy_eavg(bool beckmann, float alpha)
{
    const float *e = PK_EN_TABLE(pk_energy_eavg)[beckmann ? 1 : 0];
    float ta;
    const int ia = energy__cell(alpha, PK_EN_ALPHA, &ta);
    return e[ia] + (e[ia + 1] - e[ia]) * ta;
}

/* E_d of a rough dielectric of index ior (inside / outside) toward wo with
 * wo.z = cos_o (negative: wo inside). */
static inline PK_HD float energy_dielectric(bool beckmann, float ior, float alpha, float cos_o)
{
    const float e = cos_o >= 0.0f ? ior : 1.0f / ior;
    const int side = e >= 1.0f ? 0 : 1;
    const float n = side ? 1.0f / e : e;
    const float(*d)[PK_EN_DALPHA][PK_EN_DMU] = PK_EN_TABLE(pk_energy_d)[beckmann ? 1 : 0][side];
    float tn, ta, tm;
    const int in = energy__cell((n - 1.0f) / (PK_EN_ETA_MAX - 1.0f), PK_EN_DETA, &tn);
    const int ia = energy__cell(alpha, PK_EN_DALPHA, &ta), im = energy__cell(fabsf(cos_o), PK_EN_DMU, &tm);
    float v[2];
    for (int k = 0; k < 2; k++) {
        const float(*p)[PK_EN_DMU] = d[in + k];
        const float lo = p[ia][im] + (p[ia][im + 1] - p[ia][im]) * tm;
        const float hi = p[ia + 1][im] + (p[ia + 1][im + 1] - p[ia + 1][im]) * tm;
        v[k] = lo + (hi - lo) * ta;
    }
    return v[0] + (v[1] - v[0]) * tn;
}

#endif

/*
 * energy_gen.h - how the tables of energy.h are computed (host code only):
 * bench/energy_tables.c writes energy_tables.inc with these functions, and
 * tests/render/test_energy.c recomputes entries with them and compares.
 *
 * Every entry is the mean of the lobe's own sample weights (pbsdf_sample's
 * f cos / pdf, the single-scattering lobes without compensation) over a
 * grid of n x n stratified points (u1, u2): the sampler's warp is smooth,
 * so the mean converges much faster than random samples would, and the
 * table is the albedo of exactly the code that renders. For the dielectric
 * the choice between reflection and refraction is not drawn: both are
 * taken, weighted by the Fresnel term that would choose them.
 */
#ifndef PK_ENERGY_GEN_H
#define PK_ENERGY_GEN_H

#include "pbsdf.h"

/* The value of node i of n over [0, 1] (energy.h's rule). */
static inline float energy_gen_node(int i, int n) { return (float)i / (float)(n - 1); }
static inline float energy_gen_mu(int i, int n) { return i == 0 ? PK_EN_MU_MIN : energy_gen_node(i, n); }
static inline float energy_gen_eta(int k) { return 1.0f + (PK_EN_ETA_MAX - 1.0f) * energy_gen_node(k, PK_EN_DETA); }

static inline vec3 energy_gen_wo(float mu)
{
    return v3(sqrtf(fmaxf(0.0f, 1.0f - mu * mu)), 0.0f, mu);
}

/* E(mu, alpha): a white conductor (Schlick with F0 = 1: F = 1). */
static inline double energy_gen_conductor(bool beckmann, float alpha, float mu, int n)
{
    if (alpha < PBSDF_ALPHA_SMOOTH) return 1.0;
    pbsdf b = pbsdf_conductor_schlick(v3s(1.0f), alpha);
    if (beckmann) b.flags |= PBSDF_BECKMANN;
    const vec3 wo = energy_gen_wo(mu);
    double sum = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const float u[3] = {0.5f, ((float)i + 0.5f) / (float)n, ((float)j + 0.5f) / (float)n};
            vec3 wi, w;
            float pdf;
            bool delta;
            if (pbsdf_sample(&b, wo, u, &wi, &w, &pdf, &delta)) sum += (double)w.x;
        }
    return sum / ((double)n * (double)n);
}

/* E_d(mu, alpha, eta): a rough dielectric of relative index eta > 1 seen
 * from outside (inside false: wo.z = mu) or from inside (wo.z = -mu). */
static inline double energy_gen_dielectric(bool beckmann, bool inside, float eta, float alpha, float mu, int n)
{
    if (alpha < PBSDF_ALPHA_SMOOTH || eta <= 1.0f) return 1.0;
    pbsdf b = pbsdf_dielectric(eta, alpha, v3s(1.0f));
    if (beckmann) b.flags |= PBSDF_BECKMANN;
    vec3 wo = energy_gen_wo(mu);
    if (inside) wo.z = -wo.z;
    double sum = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const vec3 m = pbsdf_mf_sample(&b, wo, ((float)i + 0.5f) / (float)n, ((float)j + 0.5f) / (float)n);
            const float om = v3_dot(wo, m);
            if (!(om * wo.z > 0.0f)) continue; /* a facet turned away (Beckmann) */
            const float f = pbsdf_fresnel_dielectric(om, b.ior);
            const vec3 r = v3_sub(v3_scale(m, 2.0f * om), wo);
            if (f > 0.0f && r.z * wo.z > 0.0f) {
                const float p = pbsdf_pdf(&b, wo, r);
                if (p > 0.0f) sum += (double)f * (double)pbsdf_eval(&b, wo, r).x / (double)p;
            }
            vec3 t;
            if (f < 1.0f && pbsdf__refract(wo, m, b.ior, &t) && t.z * wo.z < 0.0f) {
                const float p = pbsdf_pdf(&b, wo, t);
                if (p > 0.0f) sum += (1.0 - (double)f) * (double)pbsdf_eval(&b, wo, t).x / (double)p;
            }
        }
    return sum / ((double)n * (double)n);
}

/* 2 * integral over [0, 1] of e(mu) mu dmu for e linear between the nodes
 * e[0..n-1] at mu = i / (n - 1) (as energy.h interpolates). */
static inline double energy_gen_avg(const double *e, int n)
{
    double s = 0.0, h = 1.0 / (double)(n - 1);
    for (int i = 0; i + 1 < n; i++) {
        const double a = i * h, b = a + h;
        /* integral of (e0 (b - mu) + e1 (mu - a)) / h * mu over [a, b] */
        const double i0 = (b * (b * b - a * a) / 2.0 - (b * b * b - a * a * a) / 3.0) / h;
        const double i1 = ((b * b * b - a * a * a) / 3.0 - a * (b * b - a * a) / 2.0) / h;
        s += e[i] * i0 + e[i + 1] * i1;
    }
    return 2.0 * s;
}

/* Grid sizes of the tables as written. */
#define ENERGY_GEN_N_CONDUCTOR 256
#define ENERGY_GEN_N_DIELECTRIC 64

#endif

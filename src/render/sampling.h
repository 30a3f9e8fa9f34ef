/*
 * sampling.h - the per-pixel random number generator (PCG32, seeded from the
 * pixel and sample index so images do not depend on the thread count) and
 * the warps the integrator needs.
 */
#ifndef PK_SAMPLING_H
#define PK_SAMPLING_H

#include "../math/vec3.h"

#include <stdint.h>

typedef struct rng {
    uint64_t state, inc;
} rng;

static inline PK_HD uint32_t rng_u32(rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ull + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
}

static inline PK_HD uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline PK_HD rng rng_seed(uint64_t a, uint64_t b)
{
    rng r;
    r.state = 0;
    r.inc = (mix64(b + 0x9e3779b97f4a7c15ull) << 1u) | 1u;
    rng_u32(&r);
    r.state += mix64(a);
    rng_u32(&r);
    return r;
}

/* Uniform in [0, 1). */
static inline PK_HD float rng_float(rng *r) { return (float)(rng_u32(r) >> 8) * 0x1p-24f; }

/* Cosine-weighted direction about the unit normal n. */
static inline PK_HD vec3 sample_cosine(vec3 n, float u1, float u2)
{
    float r = sqrtf(u1), phi = 2.0f * PK_PI * u2;
    vec3 t = fabsf(n.x) > 0.5f ? v3(-n.y, n.x, 0.0f) : v3(0.0f, -n.z, n.y);
    t = v3_norm(t);
    vec3 b = v3_cross(n, t);
    float z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    return v3_norm(v3_add(v3_add(v3_scale(t, r * cosf(phi)), v3_scale(b, r * sinf(phi))), v3_scale(n, z)));
}

/* A point of the unit disk, uniform in area, from (u1, u2) in [0, 1)^2 by the
 * concentric map (Shirley and Chiu): each square ring about the centre goes
 * onto the disk's ring of the same area fraction, so strata of the square
 * stay compact on the disk (a low-discrepancy pattern stays one). */
static inline PK_HD void sample_disk_concentric(float u1, float u2, float *x, float *y)
{
    const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    if (a == 0.0f && b == 0.0f) {
        *x = *y = 0.0f;
        return;
    }
    float r, phi;
    if (fabsf(a) > fabsf(b)) {
        r = a;
        phi = 0.25f * PK_PI * (b / a);
    } else {
        r = b;
        phi = 0.5f * PK_PI - 0.25f * PK_PI * (a / b);
    }
    *x = r * cosf(phi);
    *y = r * sinf(phi);
}

/* Uniform point on triangle (a, b, c). */
static inline PK_HD vec3 sample_triangle(vec3 a, vec3 b, vec3 c, float u1, float u2)
{
    float su = sqrtf(u1);
    float b0 = 1.0f - su, b1 = u2 * su;
    return v3_add(v3_add(v3_scale(a, b0), v3_scale(b, b1)), v3_scale(c, 1.0f - b0 - b1));
}

#endif

/*
 * test_rng.h - a small seeded PCG32 for the tests that draw random rays and
 * triangles (tests/unit/test_bvh.c, test_bvh_gpu.c): the same numbers on
 * every run and machine.
 */
#ifndef PK_TEST_RNG_H
#define PK_TEST_RNG_H

#include "math/vec3.h"

#include <stdint.h>

typedef struct rng {
    uint64_t s;
} rng;

static inline uint32_t rng_u32(rng *r)
{
    r->s = r->s * 6364136223846793005ull + 1442695040888963407ull;
    uint64_t x = r->s;
    uint32_t xs = (uint32_t)(((x >> 18u) ^ x) >> 27u);
    uint32_t rot = (uint32_t)(x >> 59u);
    return (xs >> rot) | (xs << ((32u - rot) & 31u));
}
static inline float rng_f(rng *r) { return (float)(rng_u32(r) >> 8) * (1.0f / 16777216.0f); }
static inline float rng_range(rng *r, float lo, float hi) { return lo + (hi - lo) * rng_f(r); }

/* A direction inside the unit ball (not normalised), away from zero. */
static inline vec3 rng_dir(rng *r)
{
    for (;;) {
        vec3 d = v3(rng_range(r, -1, 1), rng_range(r, -1, 1), rng_range(r, -1, 1));
        float l = v3_len2(d);
        if (l > 1e-4f && l <= 1.0f) return d;
    }
}

#endif

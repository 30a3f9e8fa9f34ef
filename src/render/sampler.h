/*
 * sampler.h - the path tracer's random numbers: a Sobol (0,2)-sequence in
 * each pair of dimensions, Owen-scrambled by hashing (nested uniform
 * scrambling of the digits), with the sample index shuffled per pixel and per
 * pair so that pairs are decorrelated (padding). Everything is a function of
 * (pixel, sample index, dimension, seed): images do not depend on threads,
 * tiles or regions, and another seed gives another noise pattern.
 */
#ifndef PK_SAMPLER_H
#define PK_SAMPLER_H

#include "../pk_hd.h"

#include <stdint.h>

static inline PK_HD uint32_t smp_reverse_bits(uint32_t x)
{
#if defined(__CUDA_ARCH__)
    return __brev(x); /* one instruction on the GPU, the same result */
#else
    x = __builtin_bswap32(x);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
#endif
}

/* A 32-bit mixing hash (a good avalanche, from the murmur finaliser family). */
static inline PK_HD uint32_t smp_hash(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x21f0aaadu;
    x ^= x >> 15;
    x *= 0x735a2d97u;
    x ^= x >> 15;
    return x;
}

static inline PK_HD uint32_t smp_hash2(uint32_t a, uint32_t b) { return smp_hash(a ^ smp_hash(b + 0x9e3779b9u)); }

/* The hash of Owen scrambling on a bit-reversed value: bit k of the result
 * is bit k of x flipped by a function of the bits below k (which, reversed
 * back, are the digits above): multiplications by even constants and
 * additions carry information only upwards. */
static inline PK_HD uint32_t smp_owen_rev(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* Owen scrambling of the bits of x read as a binary fraction (most significant
 * bit first): each bit is flipped by a hash of the bits above it. */
static inline PK_HD uint32_t smp_owen(uint32_t x, uint32_t seed)
{
    return smp_reverse_bits(smp_owen_rev(smp_reverse_bits(x), seed));
}

/* The first two Sobol dimensions of point i: van der Corput (bit reversal)
 * and the dimension of primitive polynomial x + 1. */
static inline PK_HD uint32_t smp_sobol0(uint32_t i) { return smp_reverse_bits(i); }
static inline PK_HD uint32_t smp_sobol1(uint32_t i)
{
    uint32_t v = 1u << 31, x = 0;
    for (; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) x ^= v;
    return x;
}

/* smp_sobol1(i), bit-reversed, without a loop: the generator matrix of that
 * dimension is Pascal's triangle mod 2, whose entry (j, k) is 1 exactly when
 * the bits of j are a subset of those of k (Lucas), so bit j of the reversed
 * value is the parity of the bits k of i that are supersets of j: five
 * shift-and-xor steps, one per bit of the bit position. */
static inline PK_HD uint32_t smp_sobol1_rev(uint32_t i)
{
    i ^= (i & 0xaaaaaaaau) >> 1;
    i ^= (i & 0xccccccccu) >> 2;
    i ^= (i & 0xf0f0f0f0u) >> 4;
    i ^= (i & 0xff00ff00u) >> 8;
    i ^= (i & 0xffff0000u) >> 16;
    return i;
}

static inline PK_HD float smp_to_float(uint32_t x)
{
    return (float)(x >> 8) * 0x1p-24f; /* [0, 1): 24 bits, never rounds up to 1 */
}

/* The dimension plan of a camera sample: dimensions 0 and 1 place it in the
 * pixel (the film), 2 and 3 on the lens, for cameras that have one, and the
 * path takes every dimension after the camera's. */
enum { SAMPLER_DIM_FILM = 0, SAMPLER_DIM_LENS = 2 };
#define SAMPLER_DIM_PATH(has_lens) (SAMPLER_DIM_LENS + ((has_lens) ? 2u : 0u))

typedef struct sampler {
    uint32_t pixel_seed;  /* from the pixel and the user's seed */
    uint32_t index;       /* sample index within the pixel */
    uint32_t dim;         /* next dimension */
} sampler;

/* SAMPLER_SECOND_HALF: indices with this bit are a second, independent
 * sequence of the pixel (another scrambling, index counted without the
 * bit), so that adaptive sampling's two halves are independent estimates
 * whose difference measures the error of their mean (adaptive.c); plain
 * renders never reach it (2^31 samples of a pixel). */
#define SAMPLER_SECOND_HALF 0x80000000u
static inline PK_HD sampler sampler_start(uint32_t px, uint32_t py, uint32_t index, uint32_t seed)
{
    sampler s;
    if (index & SAMPLER_SECOND_HALF) seed = smp_hash(seed ^ 0x2f6b4c1du), index &= ~SAMPLER_SECOND_HALF;
    s.pixel_seed = smp_hash2(smp_hash2(px, py), seed);
    s.index = index;
    s.dim = 0;
    return s;
}

/* The next two dimensions as one 2-D point of the scrambled sequence. */
static inline PK_HD void sampler_2d(sampler *s, float *u, float *v)
{
    const uint32_t pair = s->dim >> 1;
    s->dim += 2;
    const uint32_t ps = smp_hash2(s->pixel_seed, pair);
    /* shuffled index: an Owen scramble of the index is a permutation of each
     * power-of-two block, so every 2^k samples still form a (0,k,2)-net */
    const uint32_t i = smp_owen(s->index, smp_hash(ps ^ 0x5bd1e995u));
    /* smp_owen(smp_sobol0(i)) and smp_owen(smp_sobol1(i)), the reversals
     * that cancel left out */
    *u = smp_to_float(smp_reverse_bits(smp_owen_rev(i, smp_hash(ps ^ 0x68e31da4u))));
    *v = smp_to_float(smp_reverse_bits(smp_owen_rev(smp_sobol1_rev(i), smp_hash(ps ^ 0xb5297a4du))));
}

static inline PK_HD float sampler_1d(sampler *s)
{
    float u, v;
    sampler_2d(s, &u, &v);
    return u;
}

#endif

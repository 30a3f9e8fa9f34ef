/*
 * distrib.h - picking from a discrete distribution by its cumulative
 * distribution function: the light set (render/lights.h) and the rows and
 * columns of an environment map (render/env.c).
 */
#ifndef PK_MATH_DISTRIB_H
#define PK_MATH_DISTRIB_H

#include "../pk_hd.h"
#include "vec3.h"

#include <stddef.h>

/* The index i of a CDF of n > 0 entries (non-decreasing, last = 1) with
 * cdf[i-1] <= u < cdf[i]. */
static inline PK_HD size_t cdf_pick(const float *cdf, size_t n, float u)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (u < cdf[mid])
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Where u lies within the interval of entry i that cdf_pick chose, in
 * [0, 1): the remaining random number, uniform within the entry. */
static inline PK_HD float cdf_remainder(const float *cdf, size_t i, float u)
{
    const float a = i > 0 ? cdf[i - 1] : 0.0f, b = cdf[i];
    const float r = b > a ? (u - a) / (b - a) : 0.5f;
    return r > 0.0f ? (r < 0x1.fffffep-1f ? r : 0x1.fffffep-1f) : 0.0f;
}

/* The point (u, v) of the unit square whose direction is the unit vector d
 * in Clarberg's equal-area octahedral mapping (pbrt-v4's environment images
 * and goniometric lights): the upper hemisphere (z > 0) fills the inner
 * diamond |2u - 1| + |2v - 1| <= 1, the lower one the corners; the signs
 * of x and y choose the quadrant. */
static inline PK_HD void equal_area_sphere_to_square(vec3 d, float *u, float *v)
{
    float x = fabsf(d.x), y = fabsf(d.y), z = fabsf(d.z);
    float r = sqrtf(fmaxf(1.0f - z, 0.0f));
    float phi = atan2f(y, x); /* [0, pi/2] */
    float b = r * (phi * (2.0f / PK_PI));  /* v' */
    float a = r - b;                        /* u' */
    if (d.z < 0.0f) {
        float t = a;
        a = 1.0f - b, b = 1.0f - t;
    }
    a = copysignf(a, d.x), b = copysignf(b, d.y);
    *u = 0.5f * (a + 1.0f), *v = 0.5f * (b + 1.0f);
}

#endif

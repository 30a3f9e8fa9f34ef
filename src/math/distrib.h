/*
 * distrib.h - picking from a discrete distribution by its cumulative
 * distribution function: the light set (render/lights.h) and the rows and
 * columns of an environment map (render/env.c).
 */
#ifndef PK_MATH_DISTRIB_H
#define PK_MATH_DISTRIB_H

#include "../pk_hd.h"

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

#endif

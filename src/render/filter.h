/*
 * filter.h - the pixel filter as the renderer uses it: where a camera
 * sample lies in its pixel and the weight it carries (filter importance
 * sampling). A filter f(x, y) = fx(x) fy(y) is sampled axis by axis from
 * |fx| and |fy|: the box uniformly, the triangle by inverting its CDF,
 * the others from a table of FILTER_CELLS cells per axis (each cell holds
 * the mean of the filter over it; within a cell the position is uniform).
 * A sample's weight is f / pdf over the filter's integral: 1 for filters
 * that are never negative, +-W for those with negative lobes (W = the
 * integral of |f| over that of f, per axis), so that the mean of weight x
 * radiance over a pixel's samples is the filtered image (the film divides
 * by the sample count, as for the box).
 *
 * The sample's random numbers are the pixel jitter the integrators already
 * draw: the box of radius 0.5 maps them to the same positions as before
 * filters existed (FILTER_PIXEL), bit for bit.
 *
 * PK_HD: the table is a fixed-size part of the path tracer, which the GPU
 * receives by value.
 */
#ifndef PK_RENDER_FILTER_H
#define PK_RENDER_FILTER_H

#include "../paprsek_internal.h"
#include "../pk_hd.h"

#include <math.h>
#include <stdint.h>

#define FILTER_CELLS 128
#define FILTER_GUIDE 128 /* entries of the guide table: where in cdf[] the search for u starts */
_Static_assert(FILTER_CELLS <= 256, "guide[] holds cell numbers in bytes");

/* How an axis is sampled. */
enum {
    FILTER_PIXEL,   /* the box of radius 0.5: the offset is the random number itself */
    FILTER_UNIFORM, /* a box of another radius */
    FILTER_TENT,    /* the triangle, by inversion */
    FILTER_TABLE    /* cdf[] */
};

typedef struct filter_axis {
    int kind;      /* FILTER_* */
    float radius;  /* pixels */
    float weight;  /* |weight| of a sample (W; 1 when the filter is never negative) */
    /* FILTER_TABLE: the CDF of |f| at the cells' edges (cdf[0] = 0,
     * cdf[FILTER_CELLS] = 1), cell i covering [-r + 2r i / N, -r + 2r (i + 1) / N) */
    float cdf[FILTER_CELLS + 1];
    uint32_t negative[FILTER_CELLS / 32]; /* bit i: the filter is negative over cell i */
    /* guide[j]: the last cell i with cdf[i] <= j / FILTER_GUIDE (a search for
     * u starts there, usually ending within a step or two) */
    uint8_t guide[FILTER_GUIDE];
} filter_axis;

typedef struct pixel_filter {
    filter_axis x, y;
} pixel_filter;

/* The offset from the pixel's corner (in [0.5 - r, 0.5 + r)) of random
 * number u in [0, 1) along axis a; *w is multiplied by its weight. */
static inline PK_HD float filter_axis_sample(const filter_axis *a, float u, float *w)
{
    const float r = a->radius;
    if (a->kind == FILTER_PIXEL) return u;
    if (a->kind == FILTER_UNIFORM) return 0.5f + r * (2.0f * u - 1.0f);
    if (a->kind == FILTER_TENT) {
        const float t = u < 0.5f ? sqrtf(2.0f * u) - 1.0f : 1.0f - sqrtf(2.0f - 2.0f * u);
        return 0.5f + r * t;
    }
    /* the cell lo with cdf[lo] <= u < cdf[lo + 1], from the guide's start */
    int j = (int)(u * (float)FILTER_GUIDE);
    j = j < 0 ? 0 : j >= FILTER_GUIDE ? FILTER_GUIDE - 1 : j;
    int lo = a->guide[j];
    while (lo < FILTER_CELLS - 1 && a->cdf[lo + 1] <= u) lo++;
    const float du = a->cdf[lo + 1] - a->cdf[lo];
    float t = du > 0.0f ? (u - a->cdf[lo]) / du : 0.5f;
    t = fminf(fmaxf(t, 0.0f), 0.99999994f);
    if ((a->negative[lo >> 5] >> (lo & 31)) & 1u) *w = -*w;
    *w *= a->weight;
    return 0.5f + r * (2.0f * ((float)lo + t) / (float)FILTER_CELLS - 1.0f);
}

/* The offsets from pixel (0, 0)'s corner of the jitter (u, v) and the
 * sample's weight. */
static inline PK_HD void filter_sample(const pixel_filter *f, float u, float v, float *ox, float *oy, float *w)
{
    *w = 1.0f;
    *ox = filter_axis_sample(&f->x, u, w);
    *oy = filter_axis_sample(&f->y, v, w);
}

#ifndef __CUDACC__
/* The filter's 1-D profile along an axis of radius r at offset x from the
 * pixel centre (not normalised; 0 outside the radius). */
static inline double filter_profile(const pk_filter *f, double r, double x)
{
    const double ax = fabs(x);
    if (ax > r) return 0.0;
    switch (f->type) {
    case PK_FILTER_BOX: return 1.0;
    case PK_FILTER_TRIANGLE: return r - ax;
    case PK_FILTER_GAUSSIAN: {
        const double s2 = 2.0 * (double)f->sigma * (double)f->sigma;
        const double g = exp(-x * x / s2) - exp(-r * r / s2);
        return g > 0.0 ? g : 0.0;
    }
    case PK_FILTER_MITCHELL: {
        const double b = f->b, c = f->c, t = 2.0 * ax / r;
        if (t > 1.0)
            return ((-b - 6.0 * c) * t * t * t + (6.0 * b + 30.0 * c) * t * t + (-12.0 * b - 48.0 * c) * t +
                    (8.0 * b + 24.0 * c)) /
                   6.0;
        return ((12.0 - 9.0 * b - 6.0 * c) * t * t * t + (-18.0 + 12.0 * b + 6.0 * c) * t * t + (6.0 - 2.0 * b)) /
               6.0;
    }
    case PK_FILTER_BLACKMAN_HARRIS: {
        const double p = 3.14159265358979323846 * x / r;
        return 0.35875 + 0.48829 * cos(p) + 0.14128 * cos(2.0 * p) + 0.01168 * cos(3.0 * p);
    }
    case PK_FILTER_LANCZOS: {
        const double pi = 3.14159265358979323846;
        const double a = pi * x, b = pi * x / (double)f->tau;
        return (fabs(a) < 1e-6 ? 1.0 : sin(a) / a) * (fabs(b) < 1e-6 ? 1.0 : sin(b) / b);
    }
    }
    return 0.0;
}

/* The sampling of filter f (options_check_filter has passed it). Fails
 * (latched) when an axis of the filter integrates to 0 or less. */
PK_HIDDEN pk_status filter_build(pk_context *ctx, const pk_filter *f, pixel_filter *out);
#endif

#endif

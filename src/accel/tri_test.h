/*
 * tri_test.h - the core of the watertight ray-triangle test (Woop, Benthin
 * and Wald, JCGT 2013), written once for the CPU (geom.h) and the GPU
 * (bvh_gpu.h, compiled by nvcc too: plain C, PK_HD, no intrinsics). Both
 * callers translate the vertices to the ray's origin and permute them to the
 * ray's axes (kx, ky, kz); this function does the rest, so that the CPU and
 * the GPU perform the same float operations in the same order and find the
 * same hits bit for bit (the GPU build forbids fused multiply-adds).
 */
#ifndef PK_TRI_TEST_H
#define PK_TRI_TEST_H

#include "../paprsek_internal.h"

#include <math.h>

/* a0 = (ax0, ay0, az0) etc.: the vertices minus the origin, on the axes
 * (kx, ky, kz); (sx, sy, sz) the ray's shear. On a hit with t in
 * [tmin, tmax] (and finite) returns true with t, u (weight of b) and v
 * (weight of c). */
static inline PK_HD bool tri_test_watertight(float ax0, float ay0, float az0, float bx0, float by0, float bz0,
                                             float cx0, float cy0, float cz0, float sx, float sy, float sz,
                                             float tmin, float tmax, float *t_out, float *u_out, float *v_out)
{
    const float ax = ax0 - sx * az0, ay = ay0 - sy * az0;
    const float bx = bx0 - sx * bz0, by = by0 - sy * bz0;
    const float cx = cx0 - sx * cz0, cy = cy0 - sy * cz0;
    float U = cx * by - cy * bx;
    float V = ax * cy - ay * cx;
    float W = bx * ay - by * ax;
    if (PK_UNLIKELY(U == 0.0f || V == 0.0f || W == 0.0f)) { /* on an edge: decide in double */
        U = (float)((double)cx * (double)by - (double)cy * (double)bx);
        V = (float)((double)ax * (double)cy - (double)ay * (double)cx);
        W = (float)((double)bx * (double)ay - (double)by * (double)ax);
    }
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
    const float det = U + V + W;
    if (det == 0.0f) return false;
    const float az = sz * az0, bz = sz * bz0, cz = sz * cz0;
    const float T = U * az + V * bz + W * cz;
    const float rcp = 1.0f / det;
    const float t = T * rcp;
    /* t may overflow to +inf for huge coordinates: a hit at infinity is no hit */
    if (!(t >= tmin && t <= tmax && t < INFINITY)) return false;
    *t_out = t;
    *u_out = V * rcp;
    *v_out = W * rcp;
    return true;
}

#endif

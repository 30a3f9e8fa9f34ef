/*
 * tri.h - triangle math shared by the scene, the accelerators and the
 * renderer: the degenerate-triangle rule and robust unit normals.
 */
#ifndef PK_TRI_H
#define PK_TRI_H

#include "vec3.h"

#include <stdbool.h>

/* Triangles that can never be hit: a non-finite vertex or zero area. The
 * cross product is taken in double so that huge (1e30) and tiny (1e-30)
 * triangles are not mistaken for degenerate ones by overflow or underflow. */
static inline PK_HD bool tri_is_degenerate(vec3 a, vec3 b, vec3 c)
{
    if (!v3_finite(a) || !v3_finite(b) || !v3_finite(c)) return true;
    double ex = (double)b.x - (double)a.x, ey = (double)b.y - (double)a.y, ez = (double)b.z - (double)a.z;
    double fx = (double)c.x - (double)a.x, fy = (double)c.y - (double)a.y, fz = (double)c.z - (double)a.z;
    double nx = ey * fz - ez * fy, ny = ez * fx - ex * fz, nz = ex * fy - ey * fx;
    return nx == 0.0 && ny == 0.0 && nz == 0.0;
}

/* Unit normal of triangle abc (unnormalised orientation cross(b-a, c-a)),
 * taken in double so that huge (1e30) and tiny (1e-30) triangles, which
 * scenes keep, do not get an overflowed or vanished normal. */
static inline PK_HD vec3 tri_normal_double(vec3 a, vec3 b, vec3 c)
{
    double ex = (double)b.x - (double)a.x, ey = (double)b.y - (double)a.y, ez = (double)b.z - (double)a.z;
    double fx = (double)c.x - (double)a.x, fy = (double)c.y - (double)a.y, fz = (double)c.z - (double)a.z;
    double nx = ey * fz - ez * fy, ny = ez * fx - ex * fz, nz = ex * fy - ey * fx;
    double m = fmax(fabs(nx), fmax(fabs(ny), fabs(nz)));
    if (!(m > 0.0)) return v3s(0.0f);
    nx /= m, ny /= m, nz /= m;
    double l = sqrt(nx * nx + ny * ny + nz * nz);
    return v3((float)(nx / l), (float)(ny / l), (float)(nz / l));
}

/* The float cross product serves all but extreme triangles, whose squared
 * length overflows or vanishes; those take the double path. */
static inline PK_HD vec3 tri_normal(vec3 a, vec3 b, vec3 c)
{
    vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    float l2 = v3_len2(n);
    if (l2 > 1e-30f && l2 < 1e30f) return v3_scale(n, 1.0f / sqrtf(l2));
    return tri_normal_double(a, b, c);
}

#endif

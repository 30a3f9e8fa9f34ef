/*
 * frame.h - an orthonormal shading basis (s, t, n) built from a unit normal,
 * and the change of coordinates between world space and the local frame in
 * which n is +z (the frame the BSDFs of render/pbsdf.h work in).
 * Plain static inline PK_HD functions over a plain struct.
 */
#ifndef PK_MATH_FRAME_H
#define PK_MATH_FRAME_H

#include "vec3.h"

/* Invariants: s, t, n are unit length, mutually orthogonal, and right-handed
 * (cross(s, t) == n), up to float rounding. */
typedef struct onb {
    vec3 s, t, n;
} onb;

/* The basis around the unit normal n, without branches on the normal's
 * direction except its sign (Duff et al. 2017, "Building an Orthonormal
 * Basis, Revisited"): continuous everywhere but on the n.z = 0 seam. */
static inline PK_HD onb onb_from_normal(vec3 n)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    onb f;
    f.s = v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.t = v3(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}

/* World direction -> local coordinates (z along n). */
static inline PK_HD vec3 onb_to_local(onb f, vec3 v)
{
    return v3(v3_dot(v, f.s), v3_dot(v, f.t), v3_dot(v, f.n));
}

/* Local coordinates -> world direction. */
static inline PK_HD vec3 onb_to_world(onb f, vec3 v)
{
    return v3_add(v3_add(v3_scale(f.s, v.x), v3_scale(f.t, v.y)), v3_scale(f.n, v.z));
}

#endif

/*
 * vec3.h - three-component float vectors, passed by value. All static inline:
 * the hot loops of traversal and shading use them.
 */
#ifndef PK_VEC3_H
#define PK_VEC3_H

#include "../pk_hd.h"

#include <math.h>
#include <stdbool.h>

#define PK_PI 3.14159265358979323846f

typedef struct vec3 {
    float x, y, z;
} vec3;

static inline PK_HD vec3 v3(float x, float y, float z) { vec3 r = {x, y, z}; return r; }
static inline PK_HD vec3 v3s(float s) { return v3(s, s, s); }
static inline PK_HD vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline PK_HD vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline PK_HD vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline PK_HD vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline PK_HD vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline PK_HD float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline PK_HD vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline PK_HD float v3_len2(vec3 a) { return v3_dot(a, a); }
static inline PK_HD float v3_len(vec3 a) { return sqrtf(v3_dot(a, a)); }
/* Unit vector; the zero vector stays zero. */
static inline PK_HD vec3 v3_norm(vec3 a)
{
    float l = v3_len(a);
    return l > 0.0f ? v3_scale(a, 1.0f / l) : a;
}
/* Unit vector for any finite a, however large (1e30) or small (1e-30) its
 * components: a is divided by its largest |component| first, so that the
 * squared length neither overflows nor underflows. Zero stays zero. */
static inline PK_HD vec3 v3_norm_scaled(vec3 a)
{
    float m = fmaxf(fabsf(a.x), fmaxf(fabsf(a.y), fabsf(a.z)));
    if (!(m > 0.0f) || !isfinite(m)) return v3_norm(a);
    return v3_norm(v3(a.x / m, a.y / m, a.z / m));
}
static inline PK_HD vec3 v3_min(vec3 a, vec3 b) { return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static inline PK_HD vec3 v3_max(vec3 a, vec3 b) { return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }
static inline PK_HD float v3_get(vec3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
static inline PK_HD float v3_max_comp(vec3 a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
static inline PK_HD float v3_min_comp(vec3 a) { return fminf(a.x, fminf(a.y, a.z)); }
static inline PK_HD bool v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline PK_HD vec3 v3_lerp(vec3 a, vec3 b, float t) { return v3_add(a, v3_scale(v3_sub(b, a), t)); }
/* Index of the largest |component|. */
static inline PK_HD int v3_max_axis_abs(vec3 a)
{
    float x = fabsf(a.x), y = fabsf(a.y), z = fabsf(a.z);
    return (x > y) ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
}
/* Luminance of linear Rec.709 RGB. */
static inline PK_HD float v3_luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
/* Mirror d about n (n unit). */
static inline PK_HD vec3 v3_reflect(vec3 d, vec3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

/* Axis-aligned box. Empty box: lo = +inf, hi = -inf. */
typedef struct aabb {
    vec3 lo, hi;
} aabb;

static inline PK_HD aabb aabb_empty(void)
{
    aabb b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    return b;
}
static inline PK_HD aabb aabb_grow(aabb b, vec3 p) { b.lo = v3_min(b.lo, p); b.hi = v3_max(b.hi, p); return b; }
static inline PK_HD aabb aabb_union(aabb a, aabb b) { a.lo = v3_min(a.lo, b.lo); a.hi = v3_max(a.hi, b.hi); return a; }
static inline PK_HD vec3 aabb_center(aabb b) { return v3_scale(v3_add(b.lo, b.hi), 0.5f); }
static inline PK_HD vec3 aabb_extent(aabb b) { return v3_sub(b.hi, b.lo); }
static inline PK_HD float aabb_area(aabb b)
{
    vec3 e = aabb_extent(b);
    if (e.x < 0.0f || e.y < 0.0f || e.z < 0.0f) return 0.0f;
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}
static inline PK_HD bool aabb_contains(aabb outer, aabb inner)
{
    return inner.lo.x >= outer.lo.x && inner.lo.y >= outer.lo.y && inner.lo.z >= outer.lo.z &&
           inner.hi.x <= outer.hi.x && inner.hi.y <= outer.hi.y && inner.hi.z <= outer.hi.z;
}

#endif

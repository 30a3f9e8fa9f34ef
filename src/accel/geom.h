/*
 * geom.h - rays, hits and the reference ray-primitive tests that every
 * accelerator uses, so that all of them return bit-identical hits.
 *
 * Triangle test: watertight (Woop, Benthin and Wald, JCGT 2013): the ray is
 * sheared to +z, the edge functions are evaluated in 2D and recomputed in
 * double when one is exactly zero, so no hit is lost on a shared edge.
 * Closest-hit rule: t in [tmin, tmax] and finite; among equal t the lower prim wins.
 * SIMD versions must perform the same float operations in the same order
 * (the build uses -ffp-contract=off), which keeps them bit-identical.
 */
#ifndef PK_GEOM_H
#define PK_GEOM_H

#include "../math/vec3.h"
#include "../paprsek_internal.h"
#include "tri_test.h"

#include <string.h>

/* Same layout as pk_ray and a .rays record. */
typedef struct ray {
    vec3 o;
    float tmin;
    vec3 d;
    float tmax;
} ray;

/* Same layout as pk_hit and a .hits record. */
typedef struct hit {
    float t;
    uint32_t prim;
    float u, v;
} hit;

/* The public records are cast to these (api.c, cuda.c, bvh_gpu.h): the same
 * fields at the same offsets. */
_Static_assert(sizeof(ray) == 32 && sizeof(pk_ray) == 32, "ray layout");
_Static_assert(offsetof(ray, o) == offsetof(pk_ray, org) && offsetof(ray, tmin) == offsetof(pk_ray, tmin) &&
                   offsetof(ray, d) == offsetof(pk_ray, dir) && offsetof(ray, tmax) == offsetof(pk_ray, tmax) &&
                   sizeof(vec3) == 3 * sizeof(float),
               "ray fields at pk_ray's offsets");
_Static_assert(sizeof(hit) == 16 && sizeof(pk_hit) == 16, "hit layout");
_Static_assert(offsetof(hit, t) == offsetof(pk_hit, t) && offsetof(hit, prim) == offsetof(pk_hit, prim) &&
                   offsetof(hit, u) == offsetof(pk_hit, u) && offsetof(hit, v) == offsetof(pk_hit, v),
               "hit fields at pk_hit's offsets");

static inline PK_HD void hit_clear(hit *h)
{
    h->t = INFINITY;
    h->prim = PK_NO_HIT;
    h->u = h->v = 0.0f;
}

/* Ray data derived once per ray for traversal and the watertight test. */
typedef struct ray_pre {
    vec3 o, d;
    vec3 inv_d;        /* ray_rcp(d) per axis */
    int kx, ky, kz;    /* shear axes: kz is the largest |d| component */
    float sx, sy, sz;  /* shear constants */
    float tmin;
} ray_pre;

/* 1/d for the slab tests: +-inf for a zero component (the ray never moves
 * on that axis, exactly), NaN for a nonzero component whose reciprocal
 * overflows (|d| <= 2^-128). inf there would be wrong: the ray does move, by
 * |d| t, which matters for boxes only denormals apart; the slab tests take a
 * NaN distance as "no limit on this axis" (conservative), and the triangle
 * test decides exactly. */
static inline PK_HD float ray_rcp(float d)
{
    const float r = 1.0f / d;
    return d != 0.0f && isinf(r) ? NAN : r;
}

/* true when a direction component is nonzero but too small for its
 * reciprocal: 1/d rounds to inf exactly when 0 < |d| <= 2^-128 (the next
 * float above 2^-128 has a finite reciprocal). Compares only: it runs once
 * per ray of every packet. */
static inline PK_HD bool ray_dir_tiny(vec3 d)
{
    return (fabsf(d.x) <= 0x1p-128f && d.x != 0.0f) || (fabsf(d.y) <= 0x1p-128f && d.y != 0.0f) ||
           (fabsf(d.z) <= 0x1p-128f && d.z != 0.0f);
}

/* A ray that can hit something: a finite origin, no NaN in its direction or
 * interval. Others hit nothing (the triangle and sphere tests say so too),
 * and must not reach a slab test: there NaN means "no limit on this axis",
 * which would let them into empty child slots (boxes of +inf..-inf). */
static inline PK_HD bool ray_traceable(const ray *r)
{
    return v3_finite(r->o) && !isnan(r->d.x) && !isnan(r->d.y) && !isnan(r->d.z) && !isnan(r->tmin) &&
           !isnan(r->tmax);
}

static inline PK_HD ray_pre ray_prepare(const ray *r)
{
    ray_pre p;
    p.o = r->o;
    p.d = r->d;
    p.tmin = r->tmin;
    p.inv_d = v3(ray_rcp(r->d.x), ray_rcp(r->d.y), ray_rcp(r->d.z));
    int kz = v3_max_axis_abs(r->d);
    int kx = kz + 1 == 3 ? 0 : kz + 1;
    int ky = kx + 1 == 3 ? 0 : kx + 1;
    float dz = v3_get(r->d, kz);
    if (dz < 0.0f) {
        int tmp = kx;
        kx = ky;
        ky = tmp;
    }
    p.kx = kx;
    p.ky = ky;
    p.kz = kz;
    p.sx = v3_get(r->d, kx) / dz;
    p.sy = v3_get(r->d, ky) / dz;
    p.sz = 1.0f / dz;
    return p;
}

/* Watertight ray-triangle test. On a hit with t in [tmin, tmax] returns true
 * with t, u (weight of b) and v (weight of c). */
static inline PK_HD bool tri_intersect(const ray_pre *r, vec3 a, vec3 b, vec3 c, float tmax, float *t_out,
                                 float *u_out, float *v_out)
{
    const float ox = v3_get(r->o, r->kx), oy = v3_get(r->o, r->ky), oz = v3_get(r->o, r->kz);
    return tri_test_watertight(v3_get(a, r->kx) - ox, v3_get(a, r->ky) - oy, v3_get(a, r->kz) - oz,
                               v3_get(b, r->kx) - ox, v3_get(b, r->ky) - oy, v3_get(b, r->kz) - oz,
                               v3_get(c, r->kx) - ox, v3_get(c, r->ky) - oy, v3_get(c, r->kz) - oz, r->sx, r->sy,
                               r->sz, r->tmin, tmax, t_out, u_out, v_out);
}

/* Ray-sphere test (geometric form, robust for rays starting inside). Returns
 * the nearest root in [tmin, tmax]; u, v are the spherical coordinates of the
 * hit point scaled to [0,1]. */
static inline PK_HD bool sphere_intersect(const ray_pre *r, vec3 center, float radius, float tmax,
                                    float *t_out, float *u_out, float *v_out)
{
    vec3 oc = v3_sub(r->o, center);
    float a = v3_dot(r->d, r->d);
    float b = v3_dot(oc, r->d);
    /* c computed as |oc - (oc.d/a) d|^2 - r^2 avoids cancellation far away */
    vec3 perp = v3_sub(oc, v3_scale(r->d, b / a));
    float disc = radius * radius - v3_dot(perp, perp);
    if (disc < 0.0f) return false;
    float c = v3_dot(oc, oc) - radius * radius;
    float sq = sqrtf(a * disc);
    float q = b > 0.0f ? -(b + sq) : -(b - sq);
    float t0 = c / q, t1 = q / a;
    if (q == 0.0f) t0 = t1 = 0.0f;
    if (t0 > t1) {
        float tmp = t0;
        t0 = t1;
        t1 = tmp;
    }
    float t = t0;
    if (!(t >= r->tmin && t <= tmax && t < INFINITY)) {
        t = t1;
        if (!(t >= r->tmin && t <= tmax && t < INFINITY)) return false;
    }
    vec3 p = v3_scale(v3_sub(v3_add(r->o, v3_scale(r->d, t)), center), 1.0f / radius);
    float phi = atan2f(p.z, p.x);
    float theta = acosf(fminf(1.0f, fmaxf(-1.0f, p.y)));
    *t_out = t;
    *u_out = (phi + PK_PI) * (0.5f / PK_PI);
    *v_out = theta * (1.0f / PK_PI);
    return true;
}

/* The closest-hit rule shared by all accelerators. */
static inline PK_HD bool hit_better(float t, uint32_t prim, const hit *best)
{
    return t < best->t || (t == best->t && prim < best->prim);
}

#endif

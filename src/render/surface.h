/*
 * surface.h - what an integrator needs to know about a hit: the point, the
 * geometric and shading normals turned toward the incoming ray, the side
 * that was hit and the material; and where spawned rays start.
 */
#ifndef PK_SURFACE_H
#define PK_SURFACE_H

#include "../accel/geom.h"
#include "../scene/scene.h"

typedef struct surface {
    vec3 p;        /* world-space hit point */
    vec3 ng;       /* geometric normal, facing the incoming ray */
    vec3 ns;       /* shading normal, same hemisphere as ng */
    bool front;    /* the ray hit the side the geometric normal points to */
    const material *m;
} surface;

/* The surface that ray r hit at h (h->prim is a triangle or a sphere of s). */
PK_HIDDEN surface surface_at(const pk_scene *s, const ray *r, const hit *h);

/* Origin for a ray leaving p on the side of normal n: a robust offset of eps
 * (the frame's, proportional to the scene's size) plus a part proportional
 * to the magnitude of p. */
static inline vec3 offset_origin(float eps, vec3 p, vec3 n)
{
    float mag = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    return v3_add(p, v3_scale(n, eps + mag * 4e-6f));
}

#endif

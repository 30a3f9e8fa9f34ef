/*
 * surface.h - what an integrator needs to know about a hit: the point, the
 * geometric and shading normals turned toward the incoming ray, the side
 * that was hit and the material; and where spawned rays start.
 */
#ifndef PK_SURFACE_H
#define PK_SURFACE_H

#include "../accel/accel.h"
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

/* Texture coordinates at a hit: a triangle's interpolated vt (or its
 * barycentric coordinates (0,0), (1,0), (0,1) when it has none), a sphere's
 * latitude-longitude (u around +y from -x, v = 1 at the top). dpdu, dpdv:
 * the position's derivatives (unnormalised tangents); uv_per_len: the uv
 * length of a unit of scene length on the surface (the square root of the
 * area ratio), which turns a world footprint into a uv one. */
typedef struct surface_uv {
    float u, v;
    vec3 dpdu, dpdv;
    float uv_per_len;
} surface_uv;
PK_HIDDEN surface_uv surface_uv_at(const pk_scene *s, const ray *r, const hit *h);

/* For a material with texture maps (sf.m->textured): looks its maps up
 * for a ray cone of width cone_width (scene units) where it meets the
 * surface, writes the textured material into *tm and returns sf with m
 * pointing at it; bump and normal maps bend its ns. (sf by value, so that
 * callers keep theirs in registers.) */
PK_HIDDEN surface surface_texture(const pk_scene *s, const ray *r, const hit *h, float cone_width, surface sf,
                                  material *tm);

/* True when the hit lies in a hole of its material's map_d (opacity < 0.5). */
PK_HIDDEN bool surface_is_hole(const pk_scene *s, const ray *r, const hit *h);

/* Steps past holes: while h (a hit of *r) is a hole, looks further along *r
 * (tmin just past the hole). Returns false when nothing else is hit. For
 * scenes with cut-outs (s->has_cutout); every accelerator gives the same. */
PK_HIDDEN bool trace_past_holes(const accel *a, const pk_scene *s, ray *r, hit *h, accel_counters *cp);
/* Any-hit test that sees through holes: the fast any-hit when the scene has
 * no cut-out, else closest hits stepped past holes. */
PK_HIDDEN bool occluded_past_holes(const accel *a, const pk_scene *s, const ray *r, accel_counters *cp);

/* Origin for a ray leaving p on the side of normal n: a robust offset of eps
 * (the frame's, proportional to the scene's size) plus a part proportional
 * to the magnitude of p. */
static inline vec3 offset_origin(float eps, vec3 p, vec3 n)
{
    float mag = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    return v3_add(p, v3_scale(n, eps + mag * 4e-6f));
}

#endif

/*
 * path.h - the path tracer: unidirectional paths from the camera with
 * next-event estimation toward every light (emissive triangles and spheres,
 * point lights) and BSDF sampling, combined by multiple importance sampling
 * (power heuristic), Russian roulette after a few bounces. Built on the frame
 * (accelerator), surface.h and the light set. Conventions: docs/integrators.md.
 */
#ifndef PK_PATH_H
#define PK_PATH_H

#include "frame.h"
#include "sampler.h"

/* How direct light is found: both strategies weighted by MIS (the renderer's
 * choice), or one alone (tests: all three converge to the same image). */
enum { PATH_MIS, PATH_LIGHTS_ONLY, PATH_BSDF_ONLY };

/* Read-only during a render. */
typedef struct path_tracer {
    const frame *f;
    light_set lights;
    int max_depth;       /* bounces after the camera ray */
    uint32_t seed;
    int strategy;        /* PATH_* */
    float spread;        /* ray cone spread angle per unit length: the camera's pixel angle (textures) */
} path_tracer;

typedef struct path_thread {
    uint64_t rays_camera, rays_bounce, rays_shadow;
    accel_counters counters;
    accel_counters *cp;  /* &counters when statistics are on, else NULL */
} path_thread;

PK_HIDDEN pk_status path_init(pk_context *ctx, path_tracer *pt, const frame *f, const pk_render_options *opt);
PK_HIDDEN void path_free(const pk_allocator *al, path_tracer *pt);
/* Radiance along camera ray r (already traced: h), with the sampler of its
 * pixel sample (the first two dimensions were the pixel position). */
PK_HIDDEN vec3 path_radiance(const path_tracer *pt, path_thread *t, sampler *smp, const ray *r, const hit *h);

#endif

/*
 * whitted.h - the Whitted integrator's state, shared by render.c (frame loop)
 * and whitted.c (shading). Private to render/.
 */
#ifndef PK_WHITTED_H
#define PK_WHITTED_H

#include "render.h"
#include "sampling.h"

/* Secondary rays (reflection, refraction, dissolve) traced for one camera
 * ray at most. The ray tree of a dielectric branches in two at every hit, so
 * without it the work would grow as 2^max_depth (2^64 at PK_MAX_DEPTH) and a
 * render could neither finish nor be cancelled; at the default depth (8) the
 * tree has at most 2^9 - 2 = 510 rays and the budget never binds. */
#define WHITTED_RAY_BUDGET 4096

/* Ray kinds, for the statistics. */
enum { RAY_CAMERA, RAY_SHADOW, RAY_REFLECTION, RAY_REFRACTION, RAY_KINDS };

/* Read-only during a render. */
typedef struct integrator {
    const pk_scene *s;
    const accel *a;
    int light_samples, max_depth;
    bool fresnel;
    float *light_cdf;    /* nemissive entries, cumulative power, last = 1 */
    float *light_area;   /* area of each emissive triangle */
    vec3 *light_normal;  /* unit geometric normal of each emissive triangle */
    float light_power;   /* total emitted power (luminance * area) */
    float eps;           /* base offset for spawned rays, world units */
} integrator;

/* Per-thread scratch, allocated once per render. */
typedef struct thread_state {
    uint64_t rays[RAY_KINDS];
    accel_counters counters;
    accel_counters *cp;  /* &counters when statistics are on, else NULL */
    ray *shadow_rays;    /* light_samples + nlights entries */
    hit *shadow_hits;
    vec3 *shadow_weight;
    rng rng;
    uint32_t ray_budget; /* secondary rays left for the current camera ray */
} thread_state;

PK_HIDDEN pk_status integrator_init(pk_context *ctx, integrator *in, const pk_scene *s, const accel *a,
                                    const pk_render_options *opt);
PK_HIDDEN void integrator_free(const pk_allocator *al, integrator *in);
/* Radiance arriving along r that hit h (r traced already, depth 0 for camera
 * rays; set ts->ray_budget = WHITTED_RAY_BUDGET before each camera ray). */
PK_HIDDEN vec3 whitted_shade(const integrator *in, thread_state *ts, const ray *r, const hit *h, int depth);

#endif

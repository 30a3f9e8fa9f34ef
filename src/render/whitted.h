/*
 * whitted.h - the Whitted integrator: direct light from point lights and
 * area lights with shadow rays, Lambert + Phong, recursive mirror reflection
 * and refraction. Built on the frame (accelerator, light set), surface.h
 * and the MTL reflectance of shading.h, beside the path tracer's BSDFs.
 */
#ifndef PK_WHITTED_H
#define PK_WHITTED_H

#include "filter.h"
#include "frame.h"
#include "integrator.h"
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
typedef struct whitted {
    const frame *f;
    int light_samples, max_depth;
    bool fresnel;
    float spread;        /* ray cone spread angle: the camera's pixel angle (textures) */
    float cone0;         /* the ray cone's width where camera rays start (camera_frame) */
    bool lens;           /* the camera has a lens (camera_has_lens) */
    pixel_filter filter; /* pk_render_options.filter (above 1 sample per pixel) */
    /* The lights it samples: those of the frame's light set that are not
     * point lights or the sun (each gets a shadow ray of its own) or
     * emissive spheres (not lights for this integrator), with the set's
     * weights renormalised over them. */
    size_t nsampled;
    uint32_t *sampled;   /* their numbers in the set */
    float *cdf;          /* nsampled entries, last = 1 */
    size_t nsingle;
    uint32_t *single;    /* the point lights' and the sun's numbers in the set */
} whitted;

/* Per-thread scratch, allocated once per renderer. */
/* One per worker thread, on cache lines of its own (as path_thread). */
typedef struct whitted_thread {
    _Alignas(64) uint64_t rays[RAY_KINDS];
    accel_counters counters;
    accel_counters *cp;  /* &counters when statistics are on, else NULL */
    ray *shadow_rays;    /* light_samples + point lights entries */
    hit *shadow_hits;
    vec3 *shadow_weight;
    rng rng;
    uint32_t ray_budget; /* secondary rays left for the current camera ray */
    float cone;          /* ray cone width at the origin of the ray being shaded (cone0 for camera rays) */
} whitted_thread;

/* The Whitted integrator (integrator.h) is integrator_whitted; its self is a
 * whitted, its thread state a whitted_thread. */

#endif

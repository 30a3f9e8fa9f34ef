/*
 * path.h - the path tracer: unidirectional paths from the camera with
 * next-event estimation toward every light (emissive triangles and spheres,
 * point lights) and BSDF sampling, combined by multiple importance sampling
 * (power heuristic), Russian roulette after a few bounces. Built on the frame
 * (accelerator), surface.h and the light set. Conventions: docs/integrators.md.
 */
#ifndef PK_PATH_H
#define PK_PATH_H

#include "camera.h"
#include "filter.h"
#include "frame.h"
#include "sampler.h"

/* How direct light is found: both strategies weighted by MIS (the renderer's
 * choice), or one alone (tests: all three converge to the same image). */
enum { PATH_MIS, PATH_LIGHTS_ONLY, PATH_BSDF_ONLY };

/* Read-only during a render. */
typedef struct path_tracer {
    const frame *f;
    /* the frame's light set (a copy of the struct, not of its arrays: the
     * GPU's copy points at device arrays while the frame's stays the host's) */
    light_set lights;
    int max_depth;       /* bounces after the camera ray */
    uint32_t seed;
    int strategy;        /* PATH_* */
    /* the camera's (set_camera; path_gpu_render copies them to the GPU's copy, spread to lens): */
    float spread;        /* ray cone spread angle per unit length: the camera's pixel angle (textures) */
    float cone0;         /* the ray cone's width where camera rays start (camera_frame) */
    int lens;            /* camera samples take the sampler's lens dimensions (camera_has_lens) */
    int regularize;      /* pk_render_options.regularize */
    float clamp_indirect; /* pk_render_options.clamp_indirect (0: off) */
    int energy;          /* pk_render_options.energy_compensation */
    pixel_filter filter;  /* pk_render_options.filter: where camera samples lie, their weights */
    const void *gpu_nodes, *gpu_tris;  /* in the GPU's copy only: the device BVH (bvh_gpu.h) */
} path_tracer;

/* One per worker thread, each on cache lines of its own (the renderer
 * allocates them 64-byte aligned): the threads update their counters all
 * the time, and entries sharing a line would make it bounce between cores. */
typedef struct path_thread {
    _Alignas(64) uint64_t rays_camera; /* the GPU's count; on the CPU the renderer counts camera rays */
    uint64_t rays_bounce, rays_shadow;
    accel_counters counters;
    accel_counters *cp;  /* &counters when statistics are on, else NULL */
} path_thread;

/* The path tracer's integrator (integrator.h) is integrator_path; its self
 * is a path_tracer, its thread state a path_thread. */
PK_HIDDEN pk_status path_init(pk_context *ctx, path_tracer *pt, const frame *f, const pk_render_options *opt);
PK_HIDDEN void path_free(const pk_allocator *al, path_tracer *pt);

#endif

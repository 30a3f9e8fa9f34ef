/*
 * frame.h - what a renderer builds once for a scene and then only reads:
 * the acceleration structure, the environment, the light set and the ray
 * offset scale.
 */
#ifndef PK_FRAME_H
#define PK_FRAME_H

#include "../accel/accel.h"
#include "env.h"
#include "lights.h"

typedef struct frame {
    const pk_scene *s;   /* the authored scene (host code: lights, environment, warnings) */
    scene_view v;        /* what kernels read of it */
    accel *a;
    env_light env;       /* the surroundings: environment and sun */
    light_set lights;    /* every light, the environment's and the sun's included */
    float eps;           /* base offset for spawned rays, world units */
    double build_s;      /* acceleration build, seconds */
} frame;

/* Builds an accelerator of kind over the scene's triangles and spheres with
 * up to threads threads (0 = all). */
PK_HIDDEN pk_status frame_build_accel(pk_context *ctx, const pk_scene *s, pk_accel_kind kind, int threads,
                                      accel **out);
/* The accelerator, the environment, the light set and eps. A scene
 * without any light and without an environment of its own is lit by a
 * uniform white environment of radiance 1 (with a warning). */
PK_HIDDEN pk_status frame_init(pk_context *ctx, frame *f, const pk_scene *s, pk_accel_kind kind, int threads);
PK_HIDDEN void frame_free(const pk_allocator *al, frame *f);

#endif

/*
 * render.h - the renderer's interface to api.c: building an accelerator over
 * a scene, rendering a frame with the Whitted integrator, tracing ray batches.
 */
#ifndef PK_RENDER_H
#define PK_RENDER_H

#include "../accel/accel.h"
#include "../scene/scene.h"

/* Renders the committed scene through cam with options opt (already checked). */
PK_HIDDEN pk_status render_scene(pk_context *ctx, const pk_scene *s, const pk_camera *cam,
                                 const pk_render_options *opt, pk_image **out, pk_stats *stats);
/* Builds an accelerator of kind over the scene's triangles and spheres. */
PK_HIDDEN pk_status render_build_accel(pk_context *ctx, const pk_scene *s, pk_accel_kind kind, int threads,
                                       accel **out);
/* Traces n rays in parallel (threads 0 = all); flags as PK_TRACE_*. */
PK_HIDDEN void render_trace_rays(const accel *a, const ray *rays, hit *hits, size_t n, int threads,
                                 unsigned flags, pk_trace_counters *counters);

#endif

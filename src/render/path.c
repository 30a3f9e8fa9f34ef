/*
 * path.c - the path tracer (see path.h and docs/integrators.md).
 *
 * The sampling itself is in path_kernel.h, shared with the GPU; here rays
 * are traced by the frame's accelerator.
 */
#include "path.h"

#include <string.h>

/* the CPU's tracing: the frame's accelerator, counting into the thread's counters */
#define PATH_TRACE(pt, t, r, h) ((pt)->f->a->ops->intersect((pt)->f->a, (r), (h), (t)->cp))
#define PATH_OCCLUDED(pt, t, r) ((pt)->f->a->ops->occluded((pt)->f->a, (r), NULL, (t)->cp))
#include "path_kernel.h"

pk_status path_init(pk_context *ctx, path_tracer *pt, const frame *f, const pk_render_options *opt)
{
    memset(pt, 0, sizeof *pt);
    pt->f = f;
    pt->max_depth = pk_render_options_max_depth(opt);
    pt->seed = (uint32_t)opt->seed;
    return light_set_build(ctx, f->s, &f->env, &pt->lights);
}

void path_free(const pk_allocator *al, path_tracer *pt) { light_set_free(al, &pt->lights); }

ray path_camera(const path_tracer *pt, const camera_frame *cf, int px, int py, uint32_t index)
{
    return path_camera_ray(pt, cf, px, py, index);
}

bool path_sample(const path_tracer *pt, path_thread *t, int px, int py, uint32_t index, const ray *r, const hit *h,
                 vec3 *out)
{
    return path_camera_sample(pt, t, px, py, index, r, h, out);
}

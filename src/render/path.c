/*
 * path.c - the path tracer and the volumetric path tracer (see path.h,
 * docs/integrators.md and docs/media.md).
 *
 * The sampling itself is in path_kernel.h, shared with the GPU, and
 * volpath_kernel.h; here rays are traced by the frame's accelerator. The
 * two integrators share everything but the camera sample.
 */
#include "path.h"

#include <string.h>

/* the CPU's tracing: the frame's accelerator, counting into the thread's counters */
#define PATH_TRACE(pt, t, r, h) ((pt)->f->a->ops->intersect((pt)->f->a, (r), (h), (t)->cp))
#define PATH_OCCLUDED(pt, t, r) ((pt)->f->a->ops->occluded((pt)->f->a, (r), NULL, (t)->cp))
#include "volpath_kernel.h"

pk_status path_init(pk_context *ctx, path_tracer *pt, const frame *f, const pk_render_options *opt)
{
    memset(pt, 0, sizeof *pt);
    pt->f = f;
    pt->max_depth = pk_render_options_max_depth(opt);
    pt->regularize = opt->regularize;
    pt->energy = opt->energy_compensation;
    pt->clamp_indirect = opt->clamp_indirect > 0.0f && isfinite(opt->clamp_indirect) ? opt->clamp_indirect : 0.0f;
    pt->seed = (uint32_t)opt->seed;
    const pk_status st = filter_build(ctx, &opt->filter, &pt->filter);
    if (st != PK_OK) return st;
    pt->lights = f->lights;
    const size_t placed = f->lights.tree ? (f->lights.ntree + 1) / 2 : 0;
    pt->lights.use_tree = f->lights.tree && (opt->light_tree == 1 || (opt->light_tree < 0 && placed >= LIGHT_TREE_MIN));
    return PK_OK;
}

void path_free(const pk_allocator *al, path_tracer *pt) { (void)al, (void)pt; }

/* ---- the integrator interface (integrator.h) ------------------------------------ */

static pk_status ig_init(pk_context *ctx, void *self, const frame *f, const pk_render_options *opt)
{
    return path_init(ctx, self, f, opt);
}

/* The volumetric path tracer's: its own default depth (pk_render_options_max_depth
 * for volpath), whichever way it was chosen. */
static pk_status ig_vol_init(pk_context *ctx, void *self, const frame *f, const pk_render_options *opt)
{
    pk_render_options o = *opt;
    o.integrator = PK_INTEGRATOR_VOLPATH;
    return path_init(ctx, self, f, &o);
}

static void ig_free(const pk_allocator *al, void *self) { path_free(al, self); }

static pk_status ig_thread_init(pk_context *ctx, const void *self, void *ts, bool stats)
{
    (void)ctx, (void)self;
    path_thread *t = ts;
    memset(t, 0, sizeof *t);
    t->cp = stats ? &t->counters : NULL;
    return PK_OK;
}

static void ig_thread_free(const pk_allocator *al, void *ts) { (void)al, (void)ts; }

static void ig_set_camera(void *self, const camera_frame *cf)
{
    path_tracer *pt = self;
    pt->spread = cf->spread;
    pt->cone0 = cf->cone0;
    pt->lens = camera_has_lens(cf);
}

static camera_sample ig_camera_sample(const void *self, int px, int py, uint64_t index, int smp, int spp)
{
    (void)smp, (void)spp;
    return path_camera_place(self, px, py, (uint32_t)index); /* the sampler's indices wrap at 2^32 */
}

static bool ig_sample(const void *self, void *ts, int px, int py, uint64_t index, const ray *r, const hit *h, vec3 *L,
                      aov_sample *aov)
{
    return path_camera_sample_aov(self, ts, px, py, (uint32_t)index, r, h, L, aov);
}

static bool ig_vol_sample(const void *self, void *ts, int px, int py, uint64_t index, const ray *r, const hit *h,
                          vec3 *L, aov_sample *aov)
{
    return vol_camera_sample_aov(self, ts, px, py, (uint32_t)index, r, h, L, aov);
}

static void ig_take_counters(void *ts, pk_stats *st)
{
    path_thread *t = ts;
    st->rays_camera += t->rays_camera;
    st->rays_bounce += t->rays_bounce;
    st->rays_shadow += t->rays_shadow;
    st->intersection_tests += t->counters.tests;
    st->nodes_visited += t->counters.nodes;
    t->rays_camera = t->rays_bounce = t->rays_shadow = 0;
    t->counters = (accel_counters){0, 0};
}

_Static_assert(sizeof(path_thread) % 64 == 0, "path_thread: whole cache lines");

const integrator_ops integrator_path = {
    "path", sizeof(path_tracer), sizeof(path_thread), ig_init, ig_free, ig_thread_init, ig_thread_free,
    ig_set_camera, ig_camera_sample, ig_sample, ig_take_counters,
};

const integrator_ops integrator_volpath = {
    "volpath", sizeof(path_tracer), sizeof(path_thread), ig_vol_init, ig_free, ig_thread_init, ig_thread_free,
    ig_set_camera, ig_camera_sample, ig_vol_sample, ig_take_counters,
};

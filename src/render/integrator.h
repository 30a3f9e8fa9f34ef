/*
 * integrator.h - what the renderer asks of an integrator (shaped like
 * accel_ops): built once per renderer over a frame, per-thread state that
 * the renderer allocates, and one camera sample at a time: where in the
 * pixel (and on the lens) the sample lies, then the radiance arriving along
 * its camera ray, whose closest hit the renderer has traced in a batch, and
 * the AOV sample of the first surface it sees. The path tracer (path.c) and
 * the Whitted integrator (whitted.c) each export one.
 */
#ifndef PK_INTEGRATOR_H
#define PK_INTEGRATOR_H

#include "camera.h"
#include "frame.h"
#include "surface.h"

/* What a camera sample saw first, for the AOVs (zero where it saw nothing):
 * the material's diffuse reflectance, the shading normal and the distance
 * along the ray, at the first surface that is not a hole. */
typedef struct aov_sample {
    vec3 albedo, normal;
    float depth;
} aov_sample;

typedef struct integrator_ops {
    const char *name;
    size_t self_size;    /* bytes of the integrator, allocated (zeroed) by the renderer */
    size_t thread_size;  /* bytes of one thread's state, a multiple of 64: each on cache lines of its own */
    /* Built once per renderer over f (which outlives it). */
    pk_status (*init)(pk_context *ctx, void *self, const frame *f, const pk_render_options *opt);
    void (*free)(const pk_allocator *al, void *self);
    /* A zeroed thread state; stats: count traversal work into it. */
    pk_status (*thread_init)(pk_context *ctx, const void *self, void *t, bool stats);
    void (*thread_free)(const pk_allocator *al, void *t);
    /* The camera of the next renders (its pixel angle widens texture lookups). */
    void (*set_camera)(void *self, const camera_frame *cf);
    /* Where sample index (counted over all passes; smp of spp in this pass)
     * of pixel (px, py) lies on the film and the lens. */
    camera_sample (*camera_sample)(const void *self, int px, int py, uint64_t index, int smp, int spp);
    /* The radiance arriving along camera ray r of that sample, whose closest
     * hit is *h (NULL: it missed); aov (NULL: not wanted, else zeroed by the
     * caller) gets what the ray saw first. False for a lost sample (not
     * finite), which the renderer leaves out of the pixel. */
    bool (*sample)(const void *self, void *t, int px, int py, uint64_t index, const ray *r, const hit *h, vec3 *L,
                   aov_sample *aov);
    /* Adds the thread's rays and traversal work to st, and zeroes them. */
    void (*take_counters)(void *t, pk_stats *st);
} integrator_ops;

PK_HIDDEN extern const integrator_ops integrator_path, integrator_whitted;

/* The AOV sample of surface sf (textured already) seen along r at hit h. */
static inline PK_HD void aov_from_surface(const surface *sf, const ray *r, const hit *h, aov_sample *a)
{
    a->albedo = sf->m->kd;
    a->normal = sf->ns;
    a->depth = h->t * v3_len(r->d);
}

#endif

/*
 * integrator.h - what the renderer asks of an integrator (shaped like
 * accel_ops): built once per renderer over a frame, per-thread state that
 * the renderer allocates, and one camera sample at a time: where in the
 * pixel (and on the lens) the sample lies, then the radiance arriving along
 * its camera ray, whose closest hit the renderer has traced in a batch, and
 * its AOV sample (aov_sample). The path tracer (path.c) and the Whitted
 * integrator (whitted.c) each export one.
 */
#ifndef PK_INTEGRATOR_H
#define PK_INTEGRATOR_H

#include "camera.h"
#include "frame.h"
#include "surface.h"

/* What a camera sample saw, for the AOVs (the renderer averages them over
 * the samples of a pixel; zero where it saw nothing):
 *
 *  - depth: the distance along the camera ray to the first surface that is
 *    not a hole (0 for a miss), whatever that surface is;
 *  - albedo, normal: what a denoiser (Open Image Denoise) wants, at the
 *    first NON-specular vertex of the path. The path tracer follows
 *    perfectly specular (delta) chains through mirrors and smooth glass, the
 *    albedo multiplied by each specular bounce's weight (path_kernel.h
 *    path_aov_vertex says what each material gives); the normal is the
 *    shading normal there, facing the ray that arrived, zero for a miss.
 *    The Whitted integrator (whose mirrors and glass branch into both
 *    reflection and refraction rather than pick one, so there is no one
 *    chain to follow) and the CPU trace that gives a GPU render its AOVs
 *    (renderer.c) take both at the first surface (aov_from_surface). */
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

PK_HIDDEN extern const integrator_ops integrator_path, integrator_volpath, integrator_whitted;

/* The first-surface AOV sample of surface sf (textured already) seen along
 * r at hit h: the material's diffuse reflectance Kd, the shading normal and
 * the distance (Whitted, and the AOVs of GPU renders). */
static inline PK_HD void aov_from_surface(const surface *sf, const ray *r, const hit *h, aov_sample *a)
{
    a->albedo = sf->m->kd;
    a->normal = sf->ns;
    a->depth = h->t * v3_len(r->d);
}

/* A radiance as a denoiser's albedo: c divided by its largest component
 * (zero when that is not positive and finite). Emitters and the
 * environment give their colour this way. */
static inline PK_HD vec3 aov_normalised(vec3 c)
{
    const float m = v3_max_comp(c);
    return m > 0.0f && isfinite(m) ? v3_scale(c, 1.0f / m) : v3s(0.0f);
}

#endif

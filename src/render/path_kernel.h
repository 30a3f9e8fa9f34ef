/*
 * path_kernel.h - the path tracer's sampling of one camera sample, written
 * once for the CPU (path.c, wavefront.c) and the GPU (src/render/cuda/):
 * plain C over the read-only structures of a render (path_tracer, its
 * frame, the scene, the light set, the environment, the textures), every
 * function PK_HD. What differs is how rays are traced; the includer defines
 *
 *   PATH_TRACE(pt, t, r, h)   closest hit of ray *r into *h: true when hit
 *   PATH_OCCLUDED(pt, t, r)   whether anything lies on ray *r (any hit)
 *
 * before including this file (pt: const path_tracer *, t: path_thread *).
 * A path's vertex is path_step: holes, then path_shade (which traces
 * nothing and leaves a shadow ray and the next ray), the shadow ray's test,
 * and path_arrive with the next ray's hit; the wavefront runs the same
 * phases with its rays traced in queues.
 *
 * The BSDF at each vertex comes from shading.h (the material at a hit as a
 * pbsdf), the lights' sampling from lights.h. The AOVs (integrator.h
 * aov_sample) are taken along the path while it is traced, at its first
 * non-specular vertex (path_aov_*); the GPU asks for none.
 */
#ifndef PK_PATH_KERNEL_H
#define PK_PATH_KERNEL_H

#if !defined(PATH_TRACE) || !defined(PATH_OCCLUDED)
#error "define PATH_TRACE and PATH_OCCLUDED before including path_kernel.h"
#endif

#include "../math/frame.h"
#include "camera.h"
#include "integrator.h"
#include "path.h"
#include "pbsdf.h"
#include "sampler.h"
#include "sampling.h"
#include "shading.h"
#include "surface.h"

#define RR_START 3            /* Russian roulette from this bounce on */

/* ---- rays through map_d holes ------------------------------------------------- */

/* Steps past holes (surface.h trace_past_holes, with the includer's tracing). */
static inline PK_HD bool path_past_holes(const path_tracer *pt, path_thread *t, ray *r, hit *h)
{
    for (int k = 0; k < HOLE_STEPS && surface_is_hole(&pt->f->v, r, h); k++) {
        r->tmin = nextafterf(h->t, INFINITY);
        if (!PATH_TRACE(pt, t, r, h)) return false;
    }
    return true;
}

/* Whether a shadow ray is blocked, seeing through holes. */
static inline PK_HD bool path_occluded(const path_tracer *pt, path_thread *t, const ray *r)
{
    if (!pt->f->v.has_cutout) return PATH_OCCLUDED(pt, t, r);
    ray rr = *r;
    hit h;
    if (!PATH_TRACE(pt, t, &rr, &h)) return false;
    return path_past_holes(pt, t, &rr, &h);
}

static inline PK_HD float power_heuristic(float a, float b)
{
    a *= a, b *= b;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

/* Radiance a surface emits toward wo (unit, pointing away from it). */
static inline PK_HD vec3 emitted(const surface *sf) { return sf->front || sf->m->two_sided ? sf->m->ke : v3s(0.0f); }

/* ---- lights ------------------------------------------------------------------- */

/* What a path leaving the scene from o toward d (unit) gathers from the
 * environment and the sun, each weighted by MIS against its light
 * sampling when the last bounce was not a delta one. */
static inline PK_HD vec3 leaving(const path_tracer *pt, vec3 o, vec3 d, bool prev_delta, float prev_pdf)
{
    const env_light *e = &pt->f->env;
    const light_set *ls = &pt->lights;
    vec3 L = v3s(0.0f);
    const int parts[2] = {ls->env, ls->sun};
    for (int k = 0; k < 2; k++) {
        if (parts[k] < 0) continue;
        vec3 le;
        float pl;
        if (k == 0) {
            le = env_eval_from(e, o, d);
            pl = prev_delta ? 0.0f : env_pdf_from(e, o, d);
        } else {
            if (!sun_covers(e, d)) continue;
            le = e->sun_le;
            pl = sun_pdf(e);
        }
        float w = 1.0f;
        if (!prev_delta && pt->strategy == PATH_LIGHTS_ONLY) w = 0.0f;
        if (!prev_delta && pt->strategy == PATH_MIS) w = power_heuristic(prev_pdf, ls->pmf[parts[k]] * pl);
        L = v3_add(L, v3_scale(le, w));
    }
    return L;
}

/* ---- the path ------------------------------------------------------------------ */

/* A path in progress: what it has gathered, its throughput, the ray it
 * follows and that ray's closest hit, and what MIS needs of the vertex it
 * left. */
typedef struct path_state {
    vec3 L, beta;
    ray r;
    hit h;
    bool prev_delta;   /* the last bounce was a delta one (the camera counts as one) */
    bool rough_seen;   /* some bounce so far was not a delta one (regularisation starts after it) */
    float prev_pdf;    /* its solid-angle pdf */
    vec3 prev_p;       /* the vertex it left */
    vec3 prev_n;       /* its geometric normal (light_pdf_li: triangles are sampled toward its cosine) */
    float cone;        /* the ray cone's width where the path left the last vertex */
    int depth;
    sampler smp;
} path_state;

/* ---- AOVs for a denoiser ------------------------------------------------------ */

/* The AOVs of a path in progress: out (zeroed by the caller) gets them;
 * open while every vertex so far was specular, i.e. the first non-specular
 * vertex (or the end of the path) is still to come. */
typedef struct path_aov {
    aov_sample *out;
    bool open;
} path_aov;

/* Whether the material at a vertex scatters by delta lobes alone, so that
 * the AOVs look through it to what it shows: a smooth mirror or smooth
 * glass, a surface dissolved entirely, or a smooth mirror lobe or coating
 * over a black base (the MTL mirror, illum 3 with Kd 0: the path tracer
 * then always takes the mirror lobe). */
static inline PK_HD bool path_aov_specular(const shading *sh)
{
    const pbsdf *b = &sh->b;
    if (!(sh->opaque > 0.0f) || !pbsdf_has_nondelta(b)) return true;
    if (b->alpha >= PBSDF_ALPHA_SMOOTH || !black(b->albedo)) return false;
    return b->type == PBSDF_PLASTIC || (b->type == PBSDF_GLOSSY && !black(b->specular));
}

/* The albedo of a non-specular vertex, by its BSDF: the diffuse reflectance
 * Kd (textured) of diffuse, plastic and MTL (Phong, illum 3 over a diffuse
 * base) surfaces; a rough conductor's Fresnel reflectance at normal
 * incidence (F0: its tint, the same from every view); a rough dielectric's
 * transmittance (white for clear glass, the tint of what enters
 * otherwise); a coated conductor's base at normal incidence. A surface
 * partly dissolved (d < 1) counts as opaque here. */
static inline PK_HD vec3 path_aov_albedo(const surface *sf, const shading *sh)
{
    switch (sh->b.type) {
    case PBSDF_CONDUCTOR: return pbsdf__fresnel_conductor(&sh->b, 1.0f);
    case PBSDF_DIELECTRIC: return sh->b.transmittance;
    case PBSDF_COATED:
        return (sh->b.flags & PBSDF_COATED_METAL) ? pbsdf__base_fresnel(&sh->b, 1.0f) : sf->m->kd;
    default: return sf->m->kd;
    }
}

/* The AOVs at a vertex of the path, reached along ray r (hit h) with
 * throughput beta, while they are open: the depth at the first vertex;
 * then an emitter gives its colour normalised (aov_normalised), a
 * non-specular surface path_aov_albedo, either times beta, with its shading
 * normal, and closes the AOVs; a specular one leaves them open for the
 * next vertex. On a chain of specular bounces beta is the product of their
 * weights f cos / pdf (a mirror's tint; glass picks reflection or
 * refraction at random, each with weight 1 or its transmittance, so the
 * mean over the samples is the Fresnel mixture), and of Russian roulette's
 * 1 / q where it spared the path: the paths it ends give zeros, and the
 * mean stays the same. */
static inline PK_HD void path_aov_vertex(path_aov *pa, const surface *sf, const ray *r, const hit *h, int depth,
                                         vec3 beta)
{
    aov_sample *a = pa->out;
    if (depth == 0) a->depth = h->t * v3_len(r->d);
    const vec3 le = emitted(sf);
    vec3 albedo;
    if (!black(le)) {
        albedo = aov_normalised(le);
    } else {
        const shading sh = shading_at(sf);
        if (path_aov_specular(&sh)) return;
        albedo = path_aov_albedo(sf, &sh);
    }
    a->albedo = v3_mul(beta, albedo);
    a->normal = sf->ns;
    pa->open = false;
}

/* The AOVs of a path that leaves the scene from o toward d (unit) while they are
 * open (the camera ray, or a chain of specular bounces of throughput beta):
 * what it sees there (env_background: environment and sun) normalised,
 * times beta; the normal stays zero. */
static inline PK_HD void path_aov_miss(const path_tracer *pt, path_aov *pa, vec3 o, vec3 d, vec3 beta)
{
    pa->out->albedo = v3_mul(beta, aov_normalised(env_background(&pt->f->env, o, d)));
    pa->open = false;
}

/* The state of a path whose camera ray r hit at h, with the sampler of its
 * pixel sample (past the pixel position). */
static inline PK_HD void path_begin(path_state *ps, const ray *r, const hit *h, const sampler *smp)
{
    ps->L = v3s(0.0f);
    ps->beta = v3s(1.0f);
    ps->r = *r;
    ps->h = *h;
    ps->prev_delta = true; /* the camera: emission is counted in full */
    ps->rough_seen = false;
    ps->prev_pdf = 0.0f;
    ps->prev_p = r->o;
    ps->prev_n = v3s(0.0f);
    ps->cone = 0.0f;
    ps->depth = 0;
    ps->smp = *smp;
}

/* Adds the contribution c to the path's radiance; indirect (light that has
 * bounced at least once after the first surface the camera sees) is
 * clamped when the tracer asks for it (pk_render_options.clamp_indirect). */
static inline PK_HD void path_add(const path_tracer *pt, path_state *ps, vec3 c, bool indirect)
{
    if (indirect && pt->clamp_indirect > 0.0f) {
        const float m = v3_max_comp(c);
        if (m > pt->clamp_indirect) c = v3_scale(c, pt->clamp_indirect / m);
    }
    ps->L = v3_add(ps->L, c);
}

/* The MIS weight of emission that the path reached at surface sf (hit h)
 * by its last bounce: 1 after a delta bounce (or the camera); else, against
 * light sampling of the emitter from the vertex the path left. */
static inline PK_HD float path_emission_weight(const path_tracer *pt, const path_state *ps, const surface *sf)
{
    if (ps->prev_delta) return 1.0f;
    if (pt->strategy == PATH_LIGHTS_ONLY) return 0.0f; /* light sampling found it */
    if (pt->strategy != PATH_MIS) return 1.0f;
    const scene_view *s = &pt->f->v;
    const int32_t li = pt->lights.of_prim[ps->h.prim];
    if (li < 0) return 1.0f;
    const light *l = &pt->lights.lights[li];
    const float pl = light_pmf(&pt->lights, s, ps->prev_p, ps->prev_n, (size_t)li) *
                     light_pdf_li(s, l, ps->prev_p, ps->prev_n, sf->p, l->kind == LIGHT_TRIANGLE ? l->normal : sf->ng);
    return power_heuristic(ps->prev_pdf, pl);
}

/* What a vertex leaves to trace besides the path's next ray: the shadow ray
 * toward its light sample, and what that sample adds to the path's radiance
 * (path_add) when nothing blocks the ray. */
typedef struct path_shadow {
    ray r;
    vec3 c;
    bool indirect; /* c is indirect light (path_add) */
} path_shadow;

/* What path_shade leaves to trace (bits): its shadow ray (*sr), the path's
 * next ray (ps->r; none: the path has ended once the shadow ray is done). */
enum { PATH_NEXT_SHADOW = 1, PATH_NEXT_BOUNCE = 2 };

/* A path whose ray leaves the scene toward d (unit): what it gathers there
 * (leaving), indirect as path_add; the AOVs see the surroundings if they
 * are still open. */
static inline PK_HD void path_miss(const path_tracer *pt, path_state *ps, path_aov *aov, vec3 d, bool indirect)
{
    if (aov && aov->open) path_aov_miss(pt, aov, ps->r.o, d, ps->beta);
    path_add(pt, ps, v3_mul(ps->beta, leaving(pt, ps->r.o, d, ps->prev_delta, ps->prev_pdf)), indirect);
}

/* The vertex at ps's hit, which is not a hole: its emission, its light
 * sample (the shadow ray and what it brings, in *sr, to be added by the
 * caller unless blocked), then the next direction from the material and
 * Russian roulette; ps->r becomes the next ray. Returns PATH_NEXT_* bits.
 * aov as for path_step. Traces nothing: path_step traces what it leaves
 * at once, the wavefront (wavefront.h) in queues. */
static inline PK_HD int path_shade(const path_tracer *pt, path_state *ps, path_aov *aov, path_shadow *sr)
{
    const frame *fr = pt->f;
    const scene_view *s = &fr->v;
    sampler *smp = &ps->smp;
    surface sf = surface_at(s, &ps->r, &ps->h);
    material textured;
    if (s->has_textured) { /* the ray cone, widened by the distance travelled */
        ps->cone += pt->spread * ps->h.t * v3_len(ps->r.d);
        if (sf.m->textured) sf = surface_texture(s, &ps->r, &ps->h, ps->cone, sf, &textured);
    }
    if (aov && aov->open) path_aov_vertex(aov, &sf, &ps->r, &ps->h, ps->depth, ps->beta);
    const vec3 wo = v3_neg(v3_norm(ps->r.d));
    /* emission reached by the path */
    vec3 le = emitted(&sf);
    if (!black(le)) path_add(pt, ps, v3_mul(ps->beta, v3_scale(le, path_emission_weight(pt, ps, &sf))), ps->depth >= 2);
    if (ps->depth >= pt->max_depth) return 0;
    shading sh = shading_at(&sf);
    if (pt->regularize && ps->rough_seen) shading_regularize(&sh);
    if (pt->energy) pbsdf_compensate(&sh.b);
    float u0, u1, u2, u3, u4, u5;
    sampler_2d(smp, &u0, &u1);
    sampler_2d(smp, &u2, &u3);
    sampler_2d(smp, &u4, &u5);
    int next = 0;
    /* next-event estimation: one light, chosen by power */
    if (sh.nondelta && pt->lights.n && pt->strategy != PATH_BSDF_ONLY) {
        light_sample ls;
        const light_ctx lc = {sf.p, sf.ng, offset_origin(fr->eps, sf.p, sf.ng), false};
        if (light_sample_li(&pt->lights, s, &fr->env, &lc, u0, u1, u2, &ls)) {
            float pb;
            vec3 f = shading_eval(&sf, &sh, wo, ls.wi, &pb);
            if (!black(f) && v3_dot(ls.wi, sf.ng) < 0.0f) {
                /* through a transmitting surface: the shadow ray leaves from
                 * its other side, toward the same point of the light */
                const vec3 o2 = offset_origin(fr->eps, sf.p, v3_neg(sf.ng));
                if (isfinite(ls.shadow.tmax)) ls.shadow.d = v3_sub(v3_add(ls.shadow.o, ls.shadow.d), o2);
                ls.shadow.o = o2;
            }
            if (!black(f)) {
                float w = ls.delta || pt->strategy == PATH_LIGHTS_ONLY ? 1.0f : power_heuristic(ls.pdf, pb);
                sr->r = ls.shadow;
                sr->c = v3_mul(ps->beta, v3_scale(v3_mul(f, ls.le), w / ls.pdf));
                sr->indirect = ps->depth >= 1;
                next = PATH_NEXT_SHADOW;
            }
        }
    }
    /* the next direction, from the material */
    vec3 wi, weight;
    float pdf;
    bool delta;
    if (!shading_sample(&sf, &sh, wo, u3, u4, u5, &wi, &weight, &pdf, &delta)) return next;
    ps->beta = v3_mul(ps->beta, weight);
    if (black(ps->beta) || !v3_finite(ps->beta)) return next;
    /* Russian roulette on the throughput: a path carrying less than 1
     * survives with probability max(beta) and is weighted up by its
     * inverse (unbiased) */
    if (ps->depth + 1 >= RR_START) {
        float q = v3_max_comp(ps->beta);
        if (q < 1.0f) {
            if (sampler_1d(smp) >= q) return next;
            ps->beta = v3_scale(ps->beta, 1.0f / q);
        }
    }
    const bool below = v3_dot(wi, sf.ng) < 0.0f;
    ps->r = (ray){offset_origin(fr->eps, sf.p, below ? v3_neg(sf.ng) : sf.ng), 0.0f, wi, INFINITY};
    ps->prev_delta = delta;
    ps->rough_seen = ps->rough_seen || !delta;
    ps->prev_pdf = pdf;
    ps->prev_p = sf.p;
    ps->prev_n = sf.ng;
    return next | PATH_NEXT_BOUNCE;
}

/* The path's next ray (path_shade's) traced: found says whether it hit,
 * at ps->h. A miss ends the path with what the surroundings give; a hit makes
 * it one bounce longer. False when the path has ended. */
static inline PK_HD bool path_arrive(const path_tracer *pt, path_state *ps, path_aov *aov, bool found)
{
    if (!found) { /* (aov open: the vertex left was specular) */
        path_miss(pt, ps, aov, ps->r.d, ps->depth >= 1);
        return false;
    }
    ps->depth++;
    return true;
}

/* One vertex of the path: past map_d holes to the surface at its hit,
 * path_shade there, then its shadow ray and the next ray traced. False when
 * the path has ended (ps->L is then its radiance). aov (NULL: not wanted)
 * follows the path to its first non-specular vertex (path_aov_vertex); it
 * draws no random numbers and changes nothing of the path. The CPU loops
 * over it per sample; the wavefront (wavefront.h) runs the same phases
 * with its rays traced in queues. */
static inline PK_HD bool path_step(const path_tracer *pt, path_thread *t, path_state *ps, path_aov *aov)
{
    if (pt->f->v.has_cutout && !path_past_holes(pt, t, &ps->r, &ps->h)) { /* through map_d holes, out */
        path_miss(pt, ps, aov, v3_norm(ps->r.d), ps->depth >= 2); /* the ray came from vertex depth - 1 */
        return false;
    }
    path_shadow sr;
    const int next = path_shade(pt, ps, aov, &sr);
    if (next & PATH_NEXT_SHADOW) {
        t->rays_shadow++;
        if (!path_occluded(pt, t, &sr.r)) path_add(pt, ps, sr.c, sr.indirect);
    }
    if (!(next & PATH_NEXT_BOUNCE)) return false;
    t->rays_bounce++;
    return path_arrive(pt, ps, aov, PATH_TRACE(pt, t, &ps->r, &ps->h));
}

/* ---- camera samples -------------------------------------------------------------- */

/* Where sample index of pixel (px, py) lies: the sampler's film dimensions
 * place it about the pixel by the pixel filter (filter.h; the box of radius
 * 0.5: in the pixel, uniformly), its lens dimensions on the lens (when the
 * camera has one). */
static inline PK_HD camera_sample path_camera_place(const path_tracer *pt, int px, int py, uint32_t index)
{
    sampler sm = sampler_start((uint32_t)px, (uint32_t)py, index, pt->seed);
    float jx, jy, ox, oy, w;
    sampler_2d(&sm, &jx, &jy); /* SAMPLER_DIM_FILM */
    filter_sample(&pt->filter, jx, jy, &ox, &oy, &w);
    camera_sample cs = {(float)px + ox, (float)py + oy, 0.5f, 0.5f, w};
    if (pt->lens) sampler_2d(&sm, &cs.lens_u, &cs.lens_v); /* SAMPLER_DIM_LENS */
    return cs;
}

/* Starts sample index of pixel (px, py) along its camera ray r, whose
 * closest hit is *h (NULL: it left the scene). True with *ps ready for
 * path_step; false when the ray sees the surroundings, *bg. */
static inline PK_HD bool path_start(const path_tracer *pt, int px, int py, uint32_t index, const ray *r, const hit *h,
                                    path_state *ps, vec3 *bg)
{
    if (!h) {
        *bg = env_background(&pt->f->env, r->o, v3_norm(r->d));
        return false;
    }
    sampler sm = sampler_start((uint32_t)px, (uint32_t)py, index, pt->seed);
    sm.dim = SAMPLER_DIM_PATH(pt->lens); /* past the camera's dimensions */
    path_begin(ps, r, h, &sm);
    ps->cone = pt->cone0;
    return true;
}

/* A finished path's radiance; false for a lost sample (not finite), which
 * the caller leaves out rather than let it poison the pixel. */
static inline PK_HD bool path_result(const path_state *ps, vec3 *out)
{
    if (!v3_finite(ps->L)) return false;
    *out = ps->L;
    return true;
}

/* What sample index of pixel (px, py) sees along its camera ray r (path_start's
 * arguments); false for a lost sample. aov (NULL: not wanted; else zeroed)
 * gets the sample's AOVs (path_aov_vertex). */
static inline PK_HD bool path_camera_sample_aov(const path_tracer *pt, path_thread *t, int px, int py,
                                                uint32_t index, const ray *r, const hit *h, vec3 *out,
                                                aov_sample *aov)
{
    path_state ps;
    path_aov pa = {aov, true};
    if (!path_start(pt, px, py, index, r, h, &ps, out)) {
        if (aov) aov->albedo = aov_normalised(*out); /* the camera ray's miss: what it sees */
        return true;
    }
    while (path_step(pt, t, &ps, aov ? &pa : NULL)) {
    }
    return path_result(&ps, out);
}

static inline PK_HD bool path_camera_sample(const path_tracer *pt, path_thread *t, int px, int py, uint32_t index,
                                            const ray *r, const hit *h, vec3 *out)
{
    return path_camera_sample_aov(pt, t, px, py, index, r, h, out, NULL);
}

#endif

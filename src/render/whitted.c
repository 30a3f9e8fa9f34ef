/*
 * whitted.c - the Whitted integrator: emission, direct light from point
 * lights and from the frame's light set (emissive triangles, environment,
 * sun: sampled by power with stratified samples and any-hit shadow rays),
 * Lambert + Phong, recursive mirror reflection and refraction with exact
 * Fresnel (or fixed weights).
 */
#include "whitted.h"

#include "optics.h"
#include "shading.h"

#include <string.h>

static void whitted_thread_free(const pk_allocator *al, whitted_thread *t);

static pk_status whitted_thread_init(pk_context *ctx, const whitted *w, whitted_thread *t, bool stats)
{
    memset(t, 0, sizeof *t);
    const pk_allocator *al = &ctx->alloc;
    /* light samples, point lights and the sun */
    size_t nshadow = (size_t)w->light_samples + w->f->s->nlights + 1;
    if (nshadow == 0) nshadow = 1;
    t->cp = stats ? &t->counters : NULL;
    t->shadow_rays = mem_realloc_array(al, NULL, nshadow, sizeof(ray));
    t->shadow_hits = mem_realloc_array(al, NULL, nshadow, sizeof(hit));
    t->shadow_weight = mem_realloc_array(al, NULL, nshadow, sizeof(vec3));
    if (!t->shadow_rays || !t->shadow_hits || !t->shadow_weight) {
        whitted_thread_free(al, t);
        return ctx_nomem(ctx);
    }
    return PK_OK;
}

static void whitted_thread_free(const pk_allocator *al, whitted_thread *t)
{
    mem_free(al, t->shadow_rays);
    mem_free(al, t->shadow_hits);
    mem_free(al, t->shadow_weight);
    t->shadow_rays = NULL;
    t->shadow_hits = NULL;
    t->shadow_weight = NULL;
}

static vec3 whitted_shade(const whitted *w, whitted_thread *t, const ray *r, const hit *h, int depth,
                          aov_sample *aov);

static vec3 trace(const whitted *w, whitted_thread *ts, const ray *r, int depth, int kind)
{
    if (depth > w->max_depth || ts->ray_budget == 0) return v3s(0.0f);
    ts->ray_budget--;
    ts->rays[kind]++;
    hit h;
    if (!accel_intersect(w->f->a, r, &h, ts->cp)) return env_background(&w->f->env, r->o, v3_norm(r->d));
    return whitted_shade(w, ts, r, &h, depth, NULL);
}

/* A light other than a triangle (the environment, the sun, a point light),
 * out of the sampling loop's line: their code (calls to sincosf and the
 * like) would otherwise keep the loop's values out of registers. */
__attribute__((noinline)) static bool sample_other(const light_set *set, const scene_view *s, const env_light *e,
                                                  size_t li, const light_ctx *lc, float u1, float u2, light_sample *ls)
{
    return light_sample_one_with(set, s, e, li, lc, LIGHT_TRI_AREA, u1, u2, ls);
}

/* Direct light at sf toward wo: every point light and the sun with a
 * shadow ray of its own, and light_samples samples of the other lights of
 * the frame's light set (emissive triangles and the environment; emissive
 * spheres are not lights here) chosen by the set's weights, stratified in
 * the choice; the offset within the chosen light's stratum is reused as its
 * first coordinate. Every emitter is two-sided here, and triangles are
 * sampled by area (cheaper than the path tracer's solid angle; lights.h).
 * Shadow rays go to the accelerator as one batch. */
/* flatten: the lights' sampling inlined here, as it is into the path tracer's step */
__attribute__((flatten)) static vec3 direct_light(const whitted *w, whitted_thread *ts, const surface *sf, vec3 wo)
{
    const frame *fr = w->f;
    const scene_view *s = &fr->v;
    const light_set *set = &fr->lights;
    vec3 L = v3s(0.0f);
    const light_ctx lc = {sf->p, sf->ng, offset_origin(fr->eps, sf->p, sf->ng), true};
    const phong_terms bt = phong_terms_at(sf);
    rng r = ts->rng; /* in a register, not through ts */
    size_t n = 0;
    /* point lights and the sun: one shadow ray each */
    for (size_t j = 0; j < w->nsingle; j++) {
        const size_t li = w->single[j];
        const uint32_t kind = set->lights[li].kind;
        const float u1 = kind == LIGHT_SUN ? rng_float(&r) : 0.5f, u2 = kind == LIGHT_SUN ? rng_float(&r) : 0.5f;
        light_sample ls;
        if (!sample_other(set, s, &fr->env, li, &lc, u1, u2, &ls)) continue;
        vec3 f = phong_cos(&bt, wo, ls.wi);
        if (black(f)) continue;
        ts->shadow_weight[n] = v3_scale(v3_mul(f, ls.le), 1.0f / ls.pdf);
        ts->shadow_rays[n] = ls.shadow;
        n++;
    }
    const int ns = w->light_samples;
    if (w->nsampled && ns > 0) {
        const float inv_n = 1.0f / (float)ns;
        for (int k = 0; k < ns; k++) {
            float u = ((float)k + rng_float(&r)) * inv_n;
            if (u >= 1.0f) u = 0x1.fffffep-1f;
            const size_t j = cdf_pick(w->cdf, w->nsampled, u);
            const float lo = j ? w->cdf[j - 1] : 0.0f, p_pick = w->cdf[j] - lo;
            float u1 = (u - lo) / p_pick;
            u1 = u1 > 0.0f ? (u1 < 0x1.fffffep-1f ? u1 : 0x1.fffffep-1f) : 0.0f;
            const float u2 = rng_float(&r);
            if (!(p_pick > 0.0f)) continue;
            const light *l = &set->lights[w->sampled[j]];
            light_sample ls;
            if (l->kind == LIGHT_TRIANGLE) {
                if (!light_sample_tri_area(l, &lc, u1, u2, &ls)) continue;
            } else {
                light_sample other; /* its own, so that ls stays out of memory */
                if (!sample_other(set, s, &fr->env, w->sampled[j], &lc, u1, u2, &other)) continue;
                ls = other;
            }
            vec3 f = phong_cos(&bt, wo, ls.wi);
            if (black(f)) continue;
            ts->shadow_weight[n] = v3_scale(v3_mul(f, ls.le), inv_n / (p_pick * ls.pdf));
            ts->shadow_rays[n] = ls.shadow;
            n++;
        }
    }
    ts->rng = r;
    if (n == 0) return L;
    ts->rays[RAY_SHADOW] += n;
    accel_intersect_many(fr->a, ts->shadow_rays, ts->shadow_hits, n, true, ts->cp);
    if (!s->has_cutout) {
        for (size_t i = 0; i < n; i++)
            if (ts->shadow_hits[i].prim == PK_NO_HIT) L = v3_add(L, ts->shadow_weight[i]);
        return L;
    }
    for (size_t i = 0; i < n; i++) /* map_d holes: a blocked ray may pass through them */
        if (ts->shadow_hits[i].prim == PK_NO_HIT || !occluded_past_holes(fr->a, s, &ts->shadow_rays[i], ts->cp))
            L = v3_add(L, ts->shadow_weight[i]);
    return L;
}

static vec3 shade_opaque(const whitted *w, whitted_thread *ts, const ray *r, const hit *h, int depth, aov_sample *aov)
{
    const frame *fr = w->f;
    surface sf = surface_at(&fr->v, r, h);
    const float cone = fr->v.has_textured ? ts->cone + w->spread * h->t * v3_len(r->d) : 0.0f;
    material textured;
    if (sf.m->textured) sf = surface_texture(&fr->v, r, h, cone, sf, &textured);
    if (aov) aov_from_surface(&sf, r, h, aov);
    const material *m = sf.m;
    vec3 wo = v3_neg(v3_norm(r->d));
    vec3 L = m->ke; /* emitters are two-sided */
    if (m->illum == 0) return v3_add(L, m->kd);
    bool dielectric = material_mtl_glass(m);
    if (!black(material_whitted_kd(m)) || material_mtl_glossy(m)) L = v3_add(L, direct_light(w, ts, &sf, wo));
    if (!black(fr->s->ambient))
        L = v3_add(L, v3_mul(fr->s->ambient, black(m->ka) ? material_whitted_kd(m) : m->ka));
    vec3 dn = v3_norm(r->d);
    if (depth < w->max_depth) {
        if (material_mtl_mirror(m) && !black(m->ks)) {
            vec3 wr = v3_reflect(dn, sf.ns);
            if (v3_dot(wr, sf.ng) <= 0.0f) wr = v3_reflect(dn, sf.ng);
            ray rr = {offset_origin(fr->eps, sf.p, sf.ng), 0.0f, wr, INFINITY};
            ts->cone = cone;
            L = v3_add(L, v3_mul(m->ks, trace(w, ts, &rr, depth + 1, RAY_REFLECTION)));
        } else if (dielectric) {
            /* entering when the ray hits the front of the geometric normal */
            float eta_i = sf.front ? 1.0f : m->ni, eta_t = sf.front ? m->ni : 1.0f;
            float cos_i = fminf(1.0f, -v3_dot(dn, sf.ns));
            vec3 wt;
            bool tir = !refract_dir(dn, sf.ns, eta_i / eta_t, &wt) || v3_dot(wt, sf.ng) >= 0.0f;
            float F = tir ? 1.0f : fresnel_dielectric(cos_i, eta_i, eta_t);
            vec3 wr = v3_reflect(dn, sf.ns);
            if (v3_dot(wr, sf.ng) <= 0.0f) wr = v3_reflect(dn, sf.ng);
            vec3 tint = sf.front ? material_mtl_tint(m) : v3s(1.0f); /* Tf tints the light that enters */
            vec3 kr, kt;
            if (w->fresnel) {
                kr = v3s(F);
                kt = tir ? v3s(0.0f) : v3_scale(tint, 1.0f - F);
            } else { /* fixed weights: Ks for reflection and the tint for refraction */
                kr = tir ? v3s(1.0f) : m->ks;
                kt = tir ? v3s(0.0f) : tint;
            }
            if (!black(kr)) {
                ray rr = {offset_origin(fr->eps, sf.p, sf.ng), 0.0f, wr, INFINITY};
                ts->cone = cone;
                L = v3_add(L, v3_mul(kr, trace(w, ts, &rr, depth + 1, RAY_REFLECTION)));
            }
            if (!black(kt)) {
                ray rt = {offset_origin(fr->eps, sf.p, v3_neg(sf.ng)), 0.0f, wt, INFINITY};
                ts->cone = cone;
                L = v3_add(L, v3_mul(kt, trace(w, ts, &rt, depth + 1, RAY_REFRACTION)));
            }
        }
        if (!dielectric && m->d < 1.0f) { /* dissolve: see through the surface */
            ray rt = {offset_origin(fr->eps, sf.p, v3_neg(sf.ng)), 0.0f, r->d, INFINITY};
            ts->cone = cone;
            vec3 behind = trace(w, ts, &rt, depth + 1, RAY_REFRACTION);
            L = v3_add(v3_scale(L, m->d), v3_scale(behind, 1.0f - m->d));
        }
    }
    return L;
}

/* Radiance arriving along r that hit h (r traced already, depth 0 for camera
 * rays, with t->ray_budget set to WHITTED_RAY_BUDGET before each). */
static vec3 whitted_shade(const whitted *w, whitted_thread *ts, const ray *r, const hit *h, int depth,
                          aov_sample *aov)
{
    const scene_view *s = &w->f->v;
    if (s->has_cutout && surface_is_hole(s, r, h)) { /* map_d holes: what lies behind */
        ray rr = *r;
        hit hh = *h;
        if (!trace_past_holes(w->f->a, s, &rr, &hh, ts->cp)) return env_background(&w->f->env, rr.o, v3_norm(rr.d));
        return shade_opaque(w, ts, &rr, &hh, depth, aov);
    }
    return shade_opaque(w, ts, r, h, depth, aov);
}

/* ---- the integrator interface (integrator.h) ------------------------------------ */

static pk_status ig_init(pk_context *ctx, void *self, const frame *f, const pk_render_options *opt)
{
    whitted *w = self;
    *w = (whitted){.f = f, .light_samples = opt->light_samples, .max_depth = pk_render_options_max_depth(opt),
                   .fresnel = opt->fresnel != 0};
    const pk_status st = filter_build(ctx, &opt->filter, &w->filter);
    if (st != PK_OK) return st;
    const light_set *set = &f->lights;
    if (set->n == 0) return PK_OK;
    w->sampled = mem_realloc_array(&ctx->alloc, NULL, set->n, sizeof *w->sampled);
    w->cdf = mem_realloc_array(&ctx->alloc, NULL, set->n, sizeof *w->cdf);
    w->single = mem_realloc_array(&ctx->alloc, NULL, set->n, sizeof *w->single);
    if (!w->sampled || !w->cdf || !w->single) return ctx_nomem(ctx);
    double total = 0.0;
    for (size_t i = 0; i < set->n; i++) {
        const uint32_t kind = set->lights[i].kind;
        if (kind == LIGHT_POINT || kind == LIGHT_SUN) w->single[w->nsingle++] = (uint32_t)i;
        if (kind == LIGHT_POINT || kind == LIGHT_SUN || kind == LIGHT_SPHERE || !(set->pmf[i] > 0.0f)) continue;
        total += (double)set->pmf[i];
        w->sampled[w->nsampled] = (uint32_t)i;
        w->cdf[w->nsampled++] = (float)total;
    }
    for (size_t k = 0; k < w->nsampled; k++) w->cdf[k] = (float)((double)w->cdf[k] / total);
    if (w->nsampled) w->cdf[w->nsampled - 1] = 1.0f;
    return PK_OK;
}

static void ig_free(const pk_allocator *al, void *self)
{
    whitted *w = self;
    mem_free(al, w->sampled);
    mem_free(al, w->cdf);
    mem_free(al, w->single);
    w->sampled = NULL, w->cdf = NULL, w->single = NULL;
}

static pk_status ig_thread_init(pk_context *ctx, const void *self, void *t, bool stats)
{
    return whitted_thread_init(ctx, self, t, stats);
}

static void ig_thread_free(const pk_allocator *al, void *t) { whitted_thread_free(al, t); }

static void ig_set_camera(void *self, const camera_frame *cf)
{
    whitted *w = self;
    w->spread = cf->spread;
    w->cone0 = cf->cone0;
    w->lens = camera_has_lens(cf);
}

/* Through the pixel centre at 1 sample per pixel (weight 1, whatever the
 * filter), above that jittered in sx x sy strata of [0, 1)^2 (a PCG stream
 * seeded by pixel and sample), which the pixel filter maps about the pixel
 * (the box of radius 0.5: the strata of the pixel); on the lens, when the
 * camera has one, uniform from the same stream. */
static camera_sample ig_camera_sample(const void *self, int px, int py, uint64_t index, int smp, int spp)
{
    const whitted *w = self;
    camera_sample cs = {(float)px + 0.5f, (float)py + 0.5f, 0.5f, 0.5f, 1.0f};
    if (spp <= 1 && !w->lens) return cs; /* the pixel centre: no stream to seed */
    rng jr = rng_seed(((uint64_t)py << 32) | (uint32_t)px, index * 2 + 1);
    if (spp > 1) {
        const int sx = (int)ceilf(sqrtf((float)spp)), sy = (spp + sx - 1) / sx;
        const float u = ((float)(smp % sx) + rng_float(&jr)) / (float)sx;
        const float v = ((float)(smp / sx) + rng_float(&jr)) / (float)sy;
        float ox, oy;
        filter_sample(&w->filter, u, v, &ox, &oy, &cs.weight);
        cs.film_x = (float)px + ox;
        cs.film_y = (float)py + oy;
    }
    if (w->lens) {
        cs.lens_u = rng_float(&jr);
        cs.lens_v = rng_float(&jr);
    }
    return cs;
}

static bool ig_sample(const void *self, void *t, int px, int py, uint64_t index, const ray *r, const hit *h, vec3 *L,
                      aov_sample *aov)
{
    const whitted *w = self;
    whitted_thread *ts = t;
    if (!h) {
        *L = env_background(&w->f->env, r->o, v3_norm(r->d));
        return true;
    }
    ts->rng = rng_seed(((uint64_t)py << 32) | (uint32_t)px, index * 2);
    ts->ray_budget = WHITTED_RAY_BUDGET;
    ts->cone = w->cone0;
    *L = whitted_shade(w, ts, r, h, 0, aov);
    return true;
}

static void ig_take_counters(void *t, pk_stats *st)
{
    whitted_thread *ts = t;
    st->rays_camera += ts->rays[RAY_CAMERA];
    st->rays_shadow += ts->rays[RAY_SHADOW];
    st->rays_reflection += ts->rays[RAY_REFLECTION];
    st->rays_refraction += ts->rays[RAY_REFRACTION];
    st->intersection_tests += ts->counters.tests;
    st->nodes_visited += ts->counters.nodes;
    memset(ts->rays, 0, sizeof ts->rays);
    ts->counters = (accel_counters){0, 0};
}

_Static_assert(sizeof(whitted_thread) % 64 == 0, "whitted_thread: whole cache lines");

const integrator_ops integrator_whitted = {
    "whitted", sizeof(whitted), sizeof(whitted_thread), ig_init, ig_free, ig_thread_init, ig_thread_free,
    ig_set_camera, ig_camera_sample, ig_sample, ig_take_counters,
};

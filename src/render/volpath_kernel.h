/*
 * volpath_kernel.h - the volumetric path tracer's sampling of one camera
 * sample: path_kernel.h's path tracer with participating media (scene/
 * medium.h) between the surfaces. Plain C over the same read-only
 * structures, every function PK_HD; the includer defines PATH_TRACE and
 * PATH_OCCLUDED as for path_kernel.h (which it includes).
 *
 * The method is the null-scattering path integral of Miller, Georgiev and
 * Jarosz (2019), as pbrt-v4 uses it, with one scalar majorant per segment
 * (medium.h majorant_iter: the medium's largest extinction over all
 * channels, or a cell of its majorant grid):
 *
 *  - distances by delta tracking: tentative collisions at the majorant's
 *    rate; at each, absorption, real scattering or a null collision is
 *    chosen with probabilities sigma_a, sigma_s and sigma_n = majorant -
 *    sigma_t of the path's hero channel (one of R, G, B drawn per path);
 *  - chromatic media by spectral MIS: the throughput beta is the path's
 *    value over its hero channel's pdf, r_u the ratio of each channel's pdf
 *    to the hero's, and every contribution is divided by the mean of r_u:
 *    the balance heuristic over the three channels as sampling strategies
 *    (one-sample MIS, each hero equally likely). Achromatic media keep
 *    r_u = 1 and beta constant (analog tracking);
 *  - emission of the medium sigma_a le at every tentative collision;
 *  - next-event estimation from surface and medium vertices, its shadow
 *    rays passing through interface surfaces and holes, the transmittance
 *    of each medium on the way estimated by ratio tracking (exp(-sigma_t
 *    d) in closed form in homogeneous media), combined with BSDF / phase
 *    sampling by MIS (power heuristic) over the direction's pdfs: both
 *    strategies estimate the same transmittance without bias, so weights of
 *    the direction alone keep the sum exact;
 *  - Russian roulette on beta / mean(r_u).
 *
 * Media between surfaces follow medium.h's rule: a ray that crosses a
 * surface takes the medium of the side it enters; MAT_INTERFACE surfaces
 * are only crossed (no vertex, no bounce counted).
 */
#ifndef PK_VOLPATH_KERNEL_H
#define PK_VOLPATH_KERNEL_H

#include "../scene/medium.h"
#include "path_kernel.h"

#define VOL_MAX_CROSSINGS 256   /* interfaces and holes one ray passes at most */
/* Tentative collisions one tracking walk takes at most: past them the path
 * (or shadow ray) ends, so that a grid with an absurd value next to empty
 * space (a majorant cell of 1e30 over zeros) cannot stall a render. */
#define VOL_MAX_COLLISIONS (1 << 18)

enum { VOL_PASS, VOL_SCATTER, VOL_ABSORB };

typedef struct vol_state {
    path_state ps;       /* beta is over the hero channel's pdf */
    vec3 r_u;            /* each channel's pdf over the hero's (spectral MIS) */
    int hero;            /* 0, 1, 2 */
    int32_t medium;      /* the medium the ray is in, or MEDIUM_NONE */
    rng rr;              /* tracking's random numbers after a walk's first collision (cheaper than the sampler's) */
    bool has_hit;        /* ps.h is the ray's closest hit (else it leaves the scene) */
} vol_state;

static inline PK_HD float vol_comp(vec3 v, int c) { return c == 0 ? v.x : c == 1 ? v.y : v.z; }

/* 1 / mean(r_u): what turns beta into the MIS-weighted estimate. */
static inline PK_HD float vol_mis(const vol_state *vs)
{
    const float m = (vs->r_u.x + vs->r_u.y + vs->r_u.z) * (1.0f / 3.0f);
    return m > 0.0f ? 1.0f / m : 0.0f;
}

/* The medium a ray is in after it crosses a surface of material m, having
 * hit the surface's front (the side its geometric normal points to) or not,
 * coming from medium cur. */
static inline PK_HD int32_t vol_cross(const material *m, bool front, int32_t cur)
{
    const int32_t n = front ? m->medium_in : m->medium_out;
    return n == MEDIUM_INHERIT ? cur : n;
}

/* exp(-(maj - sh) d) per channel: a channel's majorant transmittance over
 * the hero's along d (1 where they are equal, also for infinite d). */
static inline PK_HD vec3 vol_ratio(vec3 maj, float sh, float d)
{
    const float x = maj.x - sh, y = maj.y - sh, z = maj.z - sh;
    return v3(x == 0.0f ? 1.0f : expf(-x * d), y == 0.0f ? 1.0f : expf(-y * d), z == 0.0f ? 1.0f : expf(-z * d));
}

/* Delta tracking along ray r (any length of d) in medium m from r->tmin to
 * tmax: adds the medium's emission to the path at every tentative
 * collision, and returns VOL_ABSORB (the path ends), VOL_SCATTER (a real
 * scattering at *t_out, beta and r_u updated) or VOL_PASS (no collision
 * before tmax). The first real collision of a path whose AOVs are open
 * (aov non-NULL) gives them the medium's albedo there, times the
 * MIS-weighted throughput that reached it, and closes them (no normal; the
 * depth of a camera ray's collision). */
static inline PK_HD int vol_track(const path_tracer *pt, vol_state *vs, const medium *m, const ray *r, float tmax,
                                  float *t_out, path_aov *aov)
{
    path_state *ps = &vs->ps;
    const float dlen = v3_len(r->d);
    majorant_iter it = majorant_start(m, r->o, r->d, r->tmin, tmax);
    float t0, t1, sig;
    const int h = vs->hero;
    int budget = VOL_MAX_COLLISIONS;
    bool first = true;
    while (majorant_next(&it, &t0, &t1, &sig)) {
        /* the majorant of each channel: a homogeneous medium's own
         * extinction (no null collisions), a grid cell's bound in all three */
        const vec3 maj = it.homogeneous ? m->sigma_t : v3s(sig);
        const bool uniform = maj.x == maj.y && maj.y == maj.z;
        const float sh = vol_comp(maj, h);
        if (!(sh > 0.0f)) { /* nothing to collide with in the hero's channel: the others' transmittance */
            if (!uniform) {
                const vec3 w = vol_ratio(maj, 0.0f, (t1 - t0) * dlen);
                ps->beta = v3_mul(ps->beta, w);
                vs->r_u = v3_mul(vs->r_u, w);
            }
            continue;
        }
        const float rate = sh * dlen; /* collisions per unit of the ray's parameter */
        float t = t0;
        for (;;) {
            float ud, ue;
            if (first) { /* the walk's first collision from the sampler (stratified), the rest from a stream */
                sampler_2d(&ps->smp, &ud, &ue);
                first = false;
            } else {
                ud = rng_float(&vs->rr), ue = rng_float(&vs->rr);
            }
            const float tn = t - log1pf(-ud) / rate;
            if (!(tn < t1)) { /* past the segment: each channel's transmittance over the hero's */
                if (!uniform) {
                    const vec3 w = vol_ratio(maj, sh, (t1 - t) * dlen);
                    ps->beta = v3_mul(ps->beta, w);
                    vs->r_u = v3_mul(vs->r_u, w);
                }
                break;
            }
            if (--budget < 0) return VOL_ABSORB;
            const vec3 tr = uniform ? v3s(1.0f) : vol_ratio(maj, sh, (tn - t) * dlen); /* T_maj / T_maj,hero */
            t = tn;
            const medium_point mp = medium_at(m, v3_add(r->o, v3_scale(r->d, t)));
            if (!black(mp.le) && !black(mp.sigma_a)) { /* emission, weighted over the channels' pdfs of this point */
                const vec3 re = v3_mul(vs->r_u, v3_scale(v3_mul(tr, maj), 1.0f / sh));
                const float mre = (re.x + re.y + re.z) * (1.0f / 3.0f);
                if (mre > 0.0f)
                    path_add(pt, ps, v3_scale(v3_mul(v3_mul(ps->beta, tr), v3_mul(mp.sigma_a, mp.le)), 1.0f / (sh * mre)),
                             ps->depth >= 1);
            }
            const float pa = vol_comp(mp.sigma_a, h) / sh, pscat = vol_comp(mp.sigma_s, h) / sh;
            if (ue < pa + pscat && aov && aov->open) {
                const vec3 st = v3_add(mp.sigma_a, mp.sigma_s);
                const vec3 al = v3(st.x > 0.0f ? mp.sigma_s.x / st.x : 0.0f, st.y > 0.0f ? mp.sigma_s.y / st.y : 0.0f,
                                   st.z > 0.0f ? mp.sigma_s.z / st.z : 0.0f);
                if (ps->depth == 0) aov->out->depth = t * dlen;
                aov->out->albedo = v3_scale(v3_mul(ps->beta, al), vol_mis(vs));
                aov->open = false;
            }
            if (ue < pa) return VOL_ABSORB;
            if (ue < pa + pscat) {
                const vec3 w = v3_mul(tr, v3_scale(mp.sigma_s, 1.0f / vol_comp(mp.sigma_s, h)));
                ps->beta = v3_mul(ps->beta, w);
                vs->r_u = v3_mul(vs->r_u, w);
                *t_out = t;
                return VOL_SCATTER;
            }
            /* a null collision: on, weighted by sigma_n over the hero's */
            const vec3 sn = v3_max(v3_sub(maj, v3_add(mp.sigma_a, mp.sigma_s)), v3s(0.0f));
            const float snh = vol_comp(sn, h);
            if (!(snh > 0.0f)) return VOL_ABSORB; /* (probability zero) */
            if (m->chromatic || !uniform) {
                const vec3 w = v3_mul(tr, v3_scale(sn, 1.0f / snh));
                ps->beta = v3_mul(ps->beta, w);
                vs->r_u = v3_mul(vs->r_u, w);
            }
        }
    }
    return VOL_PASS;
}

/* The transmittance of medium m along ray r from r->tmin to tmax: exact in
 * a homogeneous medium, else ratio tracking (an unbiased estimate per
 * channel) with Russian roulette once it is small. */
static inline PK_HD vec3 vol_transmittance(const medium *m, const ray *r, float tmax, rng *rr)
{
    const float dlen = v3_len(r->d);
    if (m->kind == MEDIUM_HOMOGENEOUS) {
        if (!(tmax < INFINITY)) return black(m->sigma_t) ? v3s(1.0f) : v3s(0.0f);
        const float d = (tmax - r->tmin) * dlen;
        return v3(expf(-m->sigma_t.x * d), expf(-m->sigma_t.y * d), expf(-m->sigma_t.z * d));
    }
    vec3 T = v3s(1.0f);
    int budget = VOL_MAX_COLLISIONS;
    majorant_iter it = majorant_start(m, r->o, r->d, r->tmin, tmax);
    float t0, t1, sig;
    while (majorant_next(&it, &t0, &t1, &sig)) {
        if (!(sig > 0.0f)) continue;
        const float rate = sig * dlen;
        float t = t0;
        for (;;) {
            const float ud = rng_float(rr), urr = rng_float(rr);
            t -= log1pf(-ud) / rate;
            if (!(t < t1)) break;
            if (--budget < 0) return v3s(0.0f);
            const medium_point mp = medium_at(m, v3_add(r->o, v3_scale(r->d, t)));
            const vec3 st = v3_add(mp.sigma_a, mp.sigma_s);
            T = v3_mul(T, v3_max(v3_sub(v3s(1.0f), v3_scale(st, 1.0f / sig)), v3s(0.0f)));
            const float tm = v3_max_comp(T);
            if (!(tm > 0.0f)) return v3s(0.0f);
            if (tm < 0.05f) { /* roulette: survive with probability 0.25 ... */
                if (urr >= 0.25f) return v3s(0.0f);
                T = v3_scale(T, 4.0f);
            }
        }
    }
    return T;
}

/* What arrives along shadow ray sh (tracing from sh.tmin to sh.tmax) that
 * starts in medium med: the product of the media's transmittances, through
 * interface surfaces and holes; zero when anything else is in the way. */
static inline PK_HD vec3 vol_shadow(const path_tracer *pt, path_thread *t, const ray *sh, int32_t med, rng *rr)
{
    const scene_view *s = &pt->f->v;
    if (!s->has_interfaces && (med < 0 || s->media[med].kind == MEDIUM_HOMOGENEOUS)) {
        /* nothing to pass through but holes, and a transmittance in closed
         * form: an occlusion test will do */
        if (path_occluded(pt, t, sh)) return v3s(0.0f);
        return med < 0 ? v3s(1.0f) : vol_transmittance(&s->media[med], sh, sh->tmax, rr);
    }
    ray r = *sh;
    vec3 T = v3s(1.0f);
    for (int k = 0; k < VOL_MAX_CROSSINGS; k++) {
        hit h;
        const bool found = PATH_TRACE(pt, t, &r, &h);
        const float tend = found ? h.t : r.tmax;
        if (med >= 0) {
            T = v3_mul(T, vol_transmittance(&s->media[med], &r, tend, rr));
            if (black(T)) return T;
        }
        if (!found) return T;
        const material *m = &s->materials[view_prim_material(s, h.prim)];
        if (m->type == MAT_INTERFACE) {
            const surface sf = surface_at(s, &r, &h);
            med = vol_cross(m, sf.front, med);
        } else if (!(s->has_cutout && surface_is_hole(s, &r, &h))) {
            return v3s(0.0f);
        }
        r.tmin = nextafterf(h.t, INFINITY);
    }
    return v3s(0.0f);
}

/* Next-event estimation from a vertex: light sample ls (its pdf includes
 * the light's choice) seen with BSDF or phase value f and that strategy's
 * pdf pf, its shadow ray starting in medium med. */
static inline PK_HD void vol_nee(const path_tracer *pt, path_thread *t, vol_state *vs, light_sample *ls, vec3 f,
                                 float pf, int32_t med)
{
    path_state *ps = &vs->ps;
    if (black(f)) return;
    t->rays_shadow++;
    const vec3 T = vol_shadow(pt, t, &ls->shadow, med, &vs->rr);
    if (black(T)) return;
    const float w = ls->delta || pt->strategy == PATH_LIGHTS_ONLY ? 1.0f : power_heuristic(ls->pdf, pf);
    path_add(pt, ps, v3_scale(v3_mul(v3_mul(ps->beta, T), v3_mul(f, ls->le)), w * vol_mis(vs) / ls->pdf),
             ps->depth >= 1);
}

/* Russian roulette on the MIS-weighted throughput; false when the path ends. */
static inline PK_HD bool vol_roulette(vol_state *vs)
{
    path_state *ps = &vs->ps;
    if (black(ps->beta) || !v3_finite(ps->beta)) return false;
    if (ps->depth + 1 >= RR_START) {
        const float q = v3_max_comp(ps->beta) * vol_mis(vs);
        if (q < 1.0f) {
            if (sampler_1d(&ps->smp) >= q) return false;
            ps->beta = v3_scale(ps->beta, 1.0f / q);
        }
    }
    return true;
}

/* Traces vs's ray (ps.r) to its closest hit, setting has_hit. */
static inline PK_HD void vol_trace(const path_tracer *pt, path_thread *t, vol_state *vs)
{
    vs->has_hit = PATH_TRACE(pt, t, &vs->ps.r, &vs->ps.h);
}

/* A scattering in the medium at parameter ts of the ray: NEE, then the
 * phase function's direction. False when the path ends. */
static inline PK_HD bool vol_scatter(const path_tracer *pt, path_thread *t, vol_state *vs, float ts)
{
    path_state *ps = &vs->ps;
    const frame *fr = pt->f;
    const scene_view *s = &fr->v;
    const medium *m = &s->media[vs->medium];
    const vec3 p = v3_add(ps->r.o, v3_scale(ps->r.d, ts));
    const vec3 wo = v3_neg(v3_norm(ps->r.d));
    if (ps->depth >= pt->max_depth) return false;
    float u0, u1, u2, u3, u4, u5;
    sampler_2d(&ps->smp, &u0, &u1);
    sampler_2d(&ps->smp, &u2, &u3);
    sampler_2d(&ps->smp, &u4, &u5);
    (void)u5;
    if (pt->lights.n && pt->strategy != PATH_BSDF_ONLY) {
        light_sample ls;
        const light_ctx lc = {p, v3s(0.0f), p, false};
        if (light_sample_li(&pt->lights, s, &fr->env, &lc, u0, u1, u2, &ls)) {
            const float f = phase_hg_eval(m->g, wo, ls.wi);
            vol_nee(pt, t, vs, &ls, v3s(f), f, vs->medium);
        }
    }
    float pdf;
    const vec3 wi = phase_hg_sample(m->g, wo, u3, u4, &pdf); /* f / pdf = 1 */
    if (!(pdf > 0.0f)) return false;
    if (!vol_roulette(vs)) return false;
    ps->r = (ray){p, 0.0f, wi, INFINITY};
    ps->prev_delta = false;
    ps->rough_seen = true;
    ps->prev_pdf = pdf;
    ps->prev_p = p;
    ps->prev_n = v3s(0.0f);
    ps->depth++;
    t->rays_bounce++;
    vol_trace(pt, t, vs);
    return true;
}

/* One step of the path: through the medium to the ray's hit (or out of the
 * scene), a scattering in the medium or the surface there. False when the
 * path has ended. */
static inline PK_HD bool vol_step(const path_tracer *pt, path_thread *t, vol_state *vs, path_aov *aov)
{
    path_state *ps = &vs->ps;
    const frame *fr = pt->f;
    const scene_view *s = &fr->v;
    if (vs->medium >= 0) {
        float ts;
        const int ev = vol_track(pt, vs, &s->media[vs->medium], &ps->r, vs->has_hit ? ps->h.t : INFINITY, &ts, aov);
        if (ev == VOL_ABSORB) return false;
        if (ev == VOL_SCATTER) return vol_scatter(pt, t, vs, ts);
    }
    if (!vs->has_hit) { /* out of the scene */
        const vec3 d = v3_norm(ps->r.d);
        if (aov && aov->open) path_aov_miss(pt, aov, ps->r.o, d, v3_scale(ps->beta, vol_mis(vs)));
        path_add(pt, ps,
                 v3_scale(v3_mul(ps->beta, leaving(pt, ps->r.o, d, ps->prev_delta, ps->prev_pdf)), vol_mis(vs)),
                 ps->depth >= 1);
        return false;
    }
    const material *hm = &s->materials[view_prim_material(s, ps->h.prim)];
    if (hm->type == MAT_INTERFACE || (s->has_cutout && surface_is_hole(s, &ps->r, &ps->h))) {
        /* only a boundary (or a hole): on along the same ray */
        if (hm->type == MAT_INTERFACE) {
            const surface sf = surface_at(s, &ps->r, &ps->h);
            vs->medium = vol_cross(hm, sf.front, vs->medium);
        }
        ps->r.tmin = nextafterf(ps->h.t, INFINITY);
        vol_trace(pt, t, vs);
        return true;
    }
    surface sf = surface_at(s, &ps->r, &ps->h);
    material textured;
    if (s->has_textured) {
        ps->cone += pt->spread * ps->h.t * v3_len(ps->r.d);
        if (sf.m->textured) sf = surface_texture(s, &ps->r, &ps->h, ps->cone, sf, &textured);
    }
    if (aov && aov->open) path_aov_vertex(aov, &sf, &ps->r, &ps->h, ps->depth, v3_scale(ps->beta, vol_mis(vs)));
    const vec3 wo = v3_neg(v3_norm(ps->r.d));
    const vec3 le = emitted(&sf);
    if (!black(le))
        path_add(pt, ps, v3_scale(v3_mul(ps->beta, le), path_emission_weight(pt, ps, &sf) * vol_mis(vs)),
                 ps->depth >= 2);
    if (ps->depth >= pt->max_depth) return false;
    shading sh = shading_at(&sf);
    if (pt->regularize && ps->rough_seen) shading_regularize(&sh);
    if (pt->energy) pbsdf_compensate(&sh.b);
    float u0, u1, u2, u3, u4, u5;
    sampler_2d(&ps->smp, &u0, &u1);
    sampler_2d(&ps->smp, &u2, &u3);
    sampler_2d(&ps->smp, &u4, &u5);
    const int32_t beyond = vol_cross(sf.m, sf.front, vs->medium); /* the medium past the surface */
    if (sh.nondelta && pt->lights.n && pt->strategy != PATH_BSDF_ONLY) {
        light_sample ls;
        const light_ctx lc = {sf.p, sf.ng, offset_origin(fr->eps, sf.p, sf.ng), false};
        if (light_sample_li(&pt->lights, s, &fr->env, &lc, u0, u1, u2, &ls)) {
            float pb;
            const vec3 f = shading_eval(&sf, &sh, wo, ls.wi, &pb);
            int32_t med = vs->medium;
            if (!black(f) && v3_dot(ls.wi, sf.ng) < 0.0f) {
                const vec3 o2 = offset_origin(fr->eps, sf.p, v3_neg(sf.ng));
                if (isfinite(ls.shadow.tmax)) ls.shadow.d = v3_sub(v3_add(ls.shadow.o, ls.shadow.d), o2);
                ls.shadow.o = o2;
                med = beyond;
            }
            vol_nee(pt, t, vs, &ls, f, pb, med);
        }
    }
    vec3 wi, weight;
    float pdf;
    bool delta;
    if (!shading_sample(&sf, &sh, wo, u3, u4, u5, &wi, &weight, &pdf, &delta)) return false;
    ps->beta = v3_mul(ps->beta, weight);
    if (!vol_roulette(vs)) return false;
    const bool below = v3_dot(wi, sf.ng) < 0.0f;
    if (below) vs->medium = beyond;
    ps->r = (ray){offset_origin(fr->eps, sf.p, below ? v3_neg(sf.ng) : sf.ng), 0.0f, wi, INFINITY};
    ps->prev_delta = delta;
    ps->rough_seen = ps->rough_seen || !delta;
    ps->prev_pdf = pdf;
    ps->prev_p = sf.p;
    ps->prev_n = sf.ng;
    ps->depth++;
    t->rays_bounce++;
    vol_trace(pt, t, vs);
    return true;
}

/* What sample index of pixel (px, py) sees along camera ray r, whose closest
 * hit is *h (NULL: none); path_camera_sample_aov's contract. */
static inline PK_HD bool vol_camera_sample_aov(const path_tracer *pt, path_thread *t, int px, int py, uint32_t index,
                                               const ray *r, const hit *h, vec3 *out, aov_sample *aov)
{
    const scene_view *s = &pt->f->v;
    vol_state vs;
    sampler sm = sampler_start((uint32_t)px, (uint32_t)py, index, pt->seed);
    sm.dim = SAMPLER_DIM_PATH(pt->lens);
    const hit none = {0};
    path_begin(&vs.ps, r, h ? h : &none, &sm);
    vs.ps.cone = pt->cone0;
    vs.has_hit = h != NULL;
    vs.medium = s->camera_medium;
    vs.r_u = v3s(1.0f);
    vs.rr = rng_seed(((uint64_t)vs.ps.smp.pixel_seed << 32) | index, 0x766f6c70u); /* per pixel sample */
    vs.hero = (int)(sampler_1d(&vs.ps.smp) * 3.0f);
    if (vs.hero > 2) vs.hero = 2;
    path_aov pa = {aov, true};
    int steps = 0;
    while (vol_step(pt, t, &vs, aov ? &pa : NULL))
        if (++steps > 64 * (pt->max_depth + 1) + VOL_MAX_CROSSINGS) break; /* interfaces without end */
    return path_result(&vs.ps, out);
}

#endif

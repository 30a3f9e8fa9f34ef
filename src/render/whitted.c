/*
 * whitted.c - the Whitted integrator: emission, direct light from point lights
 * and area lights (emissive triangles sampled by power with stratified
 * samples and any-hit shadow rays), Lambert + Phong, recursive mirror
 * reflection and refraction with exact Fresnel (or the seed's fixed mix).
 */
#include "whitted.h"

#include "optics.h"

#include <string.h>

typedef struct surface {
    vec3 p;        /* world-space hit point */
    vec3 ng;       /* geometric normal, facing the incoming ray */
    vec3 ns;       /* shading normal, same hemisphere as ng */
    bool front;    /* the ray hit the side the geometric normal points to */
    const material *m;
} surface;

/* Unit normal of triangle abc (unnormalised orientation cross(b-a, c-a)),
 * taken in double so that huge (1e30) and tiny (1e-30) triangles, which
 * scene_commit keeps, do not get an overflowed or vanished normal. */
static vec3 tri_normal_double(vec3 a, vec3 b, vec3 c)
{
    double ex = (double)b.x - (double)a.x, ey = (double)b.y - (double)a.y, ez = (double)b.z - (double)a.z;
    double fx = (double)c.x - (double)a.x, fy = (double)c.y - (double)a.y, fz = (double)c.z - (double)a.z;
    double nx = ey * fz - ez * fy, ny = ez * fx - ex * fz, nz = ex * fy - ey * fx;
    double m = fmax(fabs(nx), fmax(fabs(ny), fabs(nz)));
    if (!(m > 0.0)) return v3s(0.0f);
    nx /= m, ny /= m, nz /= m;
    double l = sqrt(nx * nx + ny * ny + nz * nz);
    return v3((float)(nx / l), (float)(ny / l), (float)(nz / l));
}

/* The float cross product serves all but extreme triangles, whose squared
 * length overflows or vanishes; those take the double path. */
static inline vec3 tri_normal(vec3 a, vec3 b, vec3 c)
{
    vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    float l2 = v3_len2(n);
    if (PK_LIKELY(l2 > 1e-30f && l2 < 1e30f)) return v3_scale(n, 1.0f / sqrtf(l2));
    return tri_normal_double(a, b, c);
}

static surface surface_at(const integrator *in, const ray *r, const hit *h)
{
    const pk_scene *s = in->s;
    surface sf;
    vec3 ng, ns;
    if (h->prim < s->ntris) {
        const triangle *t = &s->tris[h->prim];
        vec3 a, b, c;
        scene_tri_verts(s, h->prim, &a, &b, &c);
        float w = 1.0f - h->u - h->v;
        sf.p = v3_add(v3_add(v3_scale(a, w), v3_scale(b, h->u)), v3_scale(c, h->v));
        ng = tri_normal(a, b, c);
        ns = ng;
        if (t->n[0] >= 0 && t->n[1] >= 0 && t->n[2] >= 0) {
            vec3 n = v3_add(v3_add(v3_scale(s->normals[t->n[0]], w), v3_scale(s->normals[t->n[1]], h->u)),
                            v3_scale(s->normals[t->n[2]], h->v));
            if (v3_len2(n) > 0.0f) {
                n = v3_norm(n);
                /* vertex normals pointing against the face are taken as flipped faces */
                ns = v3_dot(n, ng) >= 0.0f ? n : v3_neg(n);
            }
        }
        sf.m = &s->materials[t->material];
    } else {
        const sphere *sp = &s->spheres[h->prim - s->ntris];
        vec3 p = v3_add(r->o, v3_scale(r->d, h->t));
        ng = v3_norm_scaled(v3_sub(p, sp->center));
        sf.p = v3_add(sp->center, v3_scale(ng, sp->radius));
        ns = ng;
        sf.m = &s->materials[sp->material];
    }
    sf.front = v3_dot(ng, r->d) < 0.0f;
    if (!sf.front) {
        ng = v3_neg(ng);
        ns = v3_neg(ns);
    }
    sf.ng = ng;
    sf.ns = ns;
    return sf;
}

/* Origin for a ray leaving p on the side of normal n (a robust offset
 * proportional to the magnitude of p and to the scene's size). */
static inline vec3 offset_origin(const integrator *in, vec3 p, vec3 n)
{
    float mag = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    return v3_add(p, v3_scale(n, in->eps + mag * 4e-6f));
}

static inline bool is_black(vec3 c) { return !(c.x > 0.0f || c.y > 0.0f || c.z > 0.0f); }
static inline bool is_mirror(const material *m) { return m->illum == 3 || m->illum == 5; }
static inline bool is_dielectric(const material *m) { return m->illum == 4 || m->illum == 6 || m->illum == 7; }

/* BRDF times cos(theta_i) for light arriving from wi, seen from wo. */
static inline vec3 brdf_cos(const surface *sf, vec3 wo, vec3 wi)
{
    float cos_i = v3_dot(sf->ns, wi);
    if (cos_i <= 0.0f || v3_dot(sf->ng, wi) <= 0.0f) return v3s(0.0f); /* no light through surfaces */
    vec3 f = v3_scale(sf->m->kd, 1.0f / PK_PI);
    if (sf->m->illum == 2 && !is_black(sf->m->ks)) {
        vec3 r = v3_reflect(v3_neg(wi), sf->ns);
        float c = v3_dot(r, wo);
        if (c > 0.0f) {
            float n = sf->m->ns;
            f = v3_add(f, v3_scale(sf->m->ks, (n + 2.0f) / (2.0f * PK_PI) * powf(c, n)));
        }
    }
    return v3_scale(f, cos_i);
}

static vec3 trace(const integrator *in, thread_state *ts, const ray *r, int depth, int kind)
{
    if (depth > in->max_depth || ts->ray_budget == 0) return v3s(0.0f);
    ts->ray_budget--;
    ts->rays[kind]++;
    hit h;
    if (!accel_intersect(in->a, r, &h, ts->cp)) return v3s(0.0f);
    return whitted_shade(in, ts, r, &h, depth);
}

static size_t light_pick(const integrator *in, float u)
{
    size_t lo = 0, hi = in->s->nemissive - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (u < in->light_cdf[mid])
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

static vec3 direct_light(const integrator *in, thread_state *ts, const surface *sf, vec3 wo)
{
    const pk_scene *s = in->s;
    vec3 L = v3s(0.0f);
    vec3 o = offset_origin(in, sf->p, sf->ng);
    size_t n = 0;
    /* point lights */
    for (size_t i = 0; i < s->nlights; i++) {
        vec3 d = v3_sub(s->lights[i].position, o);
        float dist2 = v3_len2(d);
        if (!(dist2 > 0.0f)) continue;
        vec3 wi = v3_scale(d, 1.0f / sqrtf(dist2));
        vec3 f = brdf_cos(sf, wo, wi);
        if (is_black(f)) continue;
        ts->shadow_weight[n] = v3_scale(v3_mul(f, s->lights[i].intensity), 1.0f / dist2);
        ts->shadow_rays[n] = (ray){o, 0.0f, d, 1.0f};
        n++;
    }
    /* area lights: stratified in the power CDF; the offset within the chosen
     * triangle's stratum is reused as the first triangle coordinate */
    int ns = in->light_samples;
    if (s->nemissive && ns > 0) {
        float inv_n = 1.0f / (float)ns;
        for (int k = 0; k < ns; k++) {
            float u = ((float)k + rng_float(&ts->rng)) * inv_n;
            if (u >= 1.0f) u = 0x1.fffffep-1f;
            size_t li = light_pick(in, u);
            float lo = li ? in->light_cdf[li - 1] : 0.0f;
            float p_tri = in->light_cdf[li] - lo;
            float u1 = (u - lo) / p_tri;
            u1 = u1 > 0.0f ? (u1 < 0x1.fffffep-1f ? u1 : 0x1.fffffep-1f) : 0.0f;
            float u2 = rng_float(&ts->rng);
            uint32_t tri = s->emissive[li];
            vec3 a, b, c;
            scene_tri_verts(s, tri, &a, &b, &c);
            vec3 lp = sample_triangle(a, b, c, u1, u2);
            vec3 d = v3_sub(lp, o);
            float dist2 = v3_len2(d);
            if (!(dist2 > 0.0f)) continue;
            vec3 wi = v3_scale(d, 1.0f / sqrtf(dist2));
            vec3 nl = in->light_normal[li];
            float cos_l = fabsf(v3_dot(nl, wi)); /* emitters are two-sided */
            vec3 f = brdf_cos(sf, wo, wi);
            if (is_black(f) || cos_l <= 0.0f) continue;
            float pdf_area = p_tri / in->light_area[li];
            vec3 le = s->materials[s->tris[tri].material].ke;
            ts->shadow_weight[n] = v3_scale(v3_mul(f, le), cos_l / (dist2 * pdf_area) * inv_n);
            /* stop just short of the light so the emitter itself does not occlude */
            ts->shadow_rays[n] = (ray){o, 0.0f, d, 1.0f - 1e-3f};
            n++;
        }
    }
    if (n == 0) return L;
    ts->rays[RAY_SHADOW] += n;
    accel_intersect_many(in->a, ts->shadow_rays, ts->shadow_hits, n, true, ts->cp);
    for (size_t i = 0; i < n; i++)
        if (ts->shadow_hits[i].prim == PK_NO_HIT) L = v3_add(L, ts->shadow_weight[i]);
    return L;
}

vec3 whitted_shade(const integrator *in, thread_state *ts, const ray *r, const hit *h, int depth)
{
    surface sf = surface_at(in, r, h);
    const material *m = sf.m;
    vec3 wo = v3_neg(v3_norm(r->d));
    vec3 L = m->ke; /* emitters are two-sided */
    if (m->illum == 0) return v3_add(L, m->kd);
    bool dielectric = is_dielectric(m);
    if (!is_black(m->kd) || (m->illum == 2 && !is_black(m->ks))) L = v3_add(L, direct_light(in, ts, &sf, wo));
    if (!is_black(in->s->ambient)) L = v3_add(L, v3_mul(in->s->ambient, is_black(m->ka) ? m->kd : m->ka));
    vec3 dn = v3_norm(r->d);
    if (depth < in->max_depth) {
        if (is_mirror(m) && !is_black(m->ks)) {
            vec3 wr = v3_reflect(dn, sf.ns);
            if (v3_dot(wr, sf.ng) <= 0.0f) wr = v3_reflect(dn, sf.ng);
            ray rr = {offset_origin(in, sf.p, sf.ng), 0.0f, wr, INFINITY};
            L = v3_add(L, v3_mul(m->ks, trace(in, ts, &rr, depth + 1, RAY_REFLECTION)));
        } else if (dielectric) {
            /* entering when the ray hits the front of the geometric normal */
            float eta_i = sf.front ? 1.0f : m->ni, eta_t = sf.front ? m->ni : 1.0f;
            float cos_i = fminf(1.0f, -v3_dot(dn, sf.ns));
            vec3 wt;
            bool tir = !refract_dir(dn, sf.ns, eta_i / eta_t, &wt) || v3_dot(wt, sf.ng) >= 0.0f;
            float F = tir ? 1.0f : fresnel_dielectric(cos_i, eta_i, eta_t);
            vec3 wr = v3_reflect(dn, sf.ns);
            if (v3_dot(wr, sf.ng) <= 0.0f) wr = v3_reflect(dn, sf.ng);
            /* Tf tints the light that enters: its hue, normalised to the brightest
             * channel (exporters write grey Tf of any strength for clear glass) */
            float tmax_c = v3_max_comp(m->tf);
            vec3 tint = sf.front && tmax_c > 0.0f ? v3_scale(m->tf, 1.0f / tmax_c) : v3s(1.0f);
            vec3 kr, kt;
            if (in->fresnel) {
                kr = v3s(F);
                kt = tir ? v3s(0.0f) : v3_scale(tint, 1.0f - F);
            } else { /* the seed: fixed weights, Ks for reflection and the tint for refraction */
                kr = tir ? v3s(1.0f) : m->ks;
                kt = tir ? v3s(0.0f) : tint;
            }
            if (!is_black(kr)) {
                ray rr = {offset_origin(in, sf.p, sf.ng), 0.0f, wr, INFINITY};
                L = v3_add(L, v3_mul(kr, trace(in, ts, &rr, depth + 1, RAY_REFLECTION)));
            }
            if (!is_black(kt)) {
                ray rt = {offset_origin(in, sf.p, v3_neg(sf.ng)), 0.0f, wt, INFINITY};
                L = v3_add(L, v3_mul(kt, trace(in, ts, &rt, depth + 1, RAY_REFRACTION)));
            }
        }
        if (!dielectric && m->d < 1.0f) { /* dissolve: see through the surface */
            ray rt = {offset_origin(in, sf.p, v3_neg(sf.ng)), 0.0f, r->d, INFINITY};
            vec3 behind = trace(in, ts, &rt, depth + 1, RAY_REFRACTION);
            L = v3_add(v3_scale(L, m->d), v3_scale(behind, 1.0f - m->d));
        }
    }
    return L;
}

pk_status integrator_init(pk_context *ctx, integrator *in, const pk_scene *s, const accel *a,
                          const pk_render_options *opt)
{
    memset(in, 0, sizeof *in);
    in->s = s;
    in->a = a;
    in->light_samples = opt->light_samples;
    in->max_depth = opt->max_depth;
    in->fresnel = opt->fresnel != 0;
    vec3 ext = aabb_extent(s->bounds);
    in->eps = 1e-5f * fmaxf(v3_max_comp(ext), 1e-6f);
    if (s->nemissive == 0) return PK_OK;
    in->light_cdf = mem_realloc_array(&ctx->alloc, NULL, s->nemissive, sizeof(float));
    in->light_area = mem_realloc_array(&ctx->alloc, NULL, s->nemissive, sizeof(float));
    in->light_normal = mem_realloc_array(&ctx->alloc, NULL, s->nemissive, sizeof(vec3));
    if (!in->light_cdf || !in->light_area || !in->light_normal) {
        integrator_free(&ctx->alloc, in);
        return ctx_nomem(ctx);
    }
    double total = 0.0;
    for (size_t i = 0; i < s->nemissive; i++) {
        vec3 a0, b0, c0;
        scene_tri_verts(s, s->emissive[i], &a0, &b0, &c0);
        float area = 0.5f * v3_len(v3_cross(v3_sub(b0, a0), v3_sub(c0, a0)));
        in->light_area[i] = area;
        in->light_normal[i] = tri_normal(a0, b0, c0);
        float lum = v3_luminance(s->materials[s->tris[s->emissive[i]].material].ke);
        total += (double)fmaxf(lum, 1e-6f) * (double)area;
        in->light_cdf[i] = (float)total;
    }
    for (size_t i = 0; i < s->nemissive; i++) in->light_cdf[i] = (float)((double)in->light_cdf[i] / total);
    in->light_cdf[s->nemissive - 1] = 1.0f;
    in->light_power = (float)total;
    return PK_OK;
}

void integrator_free(const pk_allocator *al, integrator *in)
{
    mem_free(al, in->light_cdf);
    mem_free(al, in->light_area);
    mem_free(al, in->light_normal);
    in->light_cdf = in->light_area = NULL;
    in->light_normal = NULL;
}

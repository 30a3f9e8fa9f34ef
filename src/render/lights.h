/*
 * lights.h - every light of a frame in one set (emissive triangles and
 * spheres, point lights, the environment, the sun), chosen in proportion to
 * emitted power, and each light's sampling: a direction toward it from a
 * shading context, with its radiance and solid-angle pdf, and that pdf for
 * a direction found otherwise (MIS). Built once per renderer; every
 * function below is PK_HD, so the GPU's path tracer runs the same code.
 *
 * Triangles are sampled by the solid angle they subtend
 * (spherical_triangle.h), optionally warped toward the cosine at the
 * receiver, or by area (LIGHT_TRI_*): the path tracer's light_sample_li and
 * light_pdf_li use the warped solid angle, the Whitted integrator asks for
 * area (light_sample_tri_area for its triangles, light_sample_one_with with
 * LIGHT_TRI_AREA for the other kinds; both give the same sample, and
 * Whitted's loop, 32 samples a point by default, keeps the other kinds'
 * code out of line). Solid-angle sampling spends no samples on
 * the parts of a near light that look small from the receiver (area
 * sampling's r^2 / cos in the estimate is what makes fireflies next to
 * lights), and the warp follows the receiver's cosine across the light.
 * Where the triangle subtends less than SPH_TRI_MIN_SOLID_ANGLE area
 * sampling is as good and cheaper, and from almost on it (more than
 * SPH_TRI_MAX_SOLID_ANGLE) more robust, so the solid-angle modes fall back
 * to it there. In every mode the pdf that sampling returns and the one
 * light_pdf_at (light_pdf_li) gives for the same direction are the same
 * function of (receiver, direction), as MIS needs.
 */
#ifndef PK_LIGHTS_H
#define PK_LIGHTS_H

#include "../accel/geom.h"
#include "../math/distrib.h"
#include "../scene/scene_view.h"
#include "env.h"
#include "sampling.h"
#include "light_tree.h"
#include "spherical_triangle.h"
#include "surface.h"

enum { LIGHT_TRIANGLE, LIGHT_SPHERE, LIGHT_POINT, LIGHT_ENV, LIGHT_SUN };

typedef struct light {
    uint32_t kind;       /* LIGHT_* */
    uint32_t index;      /* triangle number, sphere number or point light number */
    float area;          /* triangles and spheres */
    vec3 normal;         /* triangles: unit winding normal */
    /* Triangles: what sampling one reads, copied from the scene (which a
     * renderer's scene may not change): its vertices and its material's
     * emission and sidedness, so that a sample reads this record and not
     * triangle, index, position and material in turn. */
    vec3 v[3];
    vec3 le;
    bool two_sided;
} light;

/* The record of emissive triangle number index, (a, b, c) of material m. */
static inline PK_HD light light_of_triangle(uint32_t index, vec3 a, vec3 b, vec3 c, const material *m)
{
    light l;
    l.kind = LIGHT_TRIANGLE;
    l.index = index;
    l.area = 0.5f * v3_len(v3_cross(v3_sub(b, a), v3_sub(c, a)));
    l.normal = tri_normal(a, b, c);
    l.v[0] = a, l.v[1] = b, l.v[2] = c;
    l.le = m->ke;
    l.two_sided = m->two_sided;
    return l;
}

/* Emissive triangles, emissive spheres, point lights, the environment and
 * the sun, chosen in proportion to their emitted power. */
typedef struct light_set {
    size_t n;
    light *lights;
    float *cdf;          /* n entries, last = 1 */
    float *pmf;          /* probability of choosing each light */
    int32_t *of_prim;    /* ntris + nspheres entries: the light a primitive is, or -1 */
    int32_t env, sun;    /* the environment's and the sun's light, or -1 */
    double power;
    /* The light tree (light_tree.h) over the lights with a place, built when
     * there are at least two: ntree nodes, each light's path in it (trail,
     * n entries, meaningful for those lights), the lights without a place
     * (inf, ninf: the environment, the sun, distant lights) with their CDF
     * among themselves, and the probability p_tree of choosing from the
     * tree (the power of the lights in it over all). light_pick and
     * light_pmf use it when use_tree is set; else the power CDF. */
    light_tree_node *tree;
    size_t ntree;
    uint64_t *trail;
    uint32_t *inf;
    float *inf_cdf;
    size_t ninf;
    float p_tree;
    int use_tree;
} light_set;

/* When a light set is sampled through its tree by default (the path
 * tracer's light_tree option -1): from this many lights with a place. */
#define LIGHT_TREE_MIN 8

PK_HIDDEN pk_status light_set_build(pk_context *ctx, const pk_scene *s, const env_light *env, light_set *ls);
PK_HIDDEN void light_set_free(const pk_allocator *al, light_set *ls);

static inline PK_HD size_t light_set_pick(const light_set *ls, float u) { return cdf_pick(ls->cdf, ls->n, u); }

/* ---- sampling ------------------------------------------------------------ */

#define SHADOW_SHORTEN 1e-3f  /* shadow rays toward area lights stop this fraction short of them */

/* How triangle lights are sampled (light_sample_one_with, light_pdf_at). */
enum {
    LIGHT_TRI_SOLID_ANGLE = 0, /* uniform in the subtended solid angle */
    LIGHT_TRI_AREA = 1,        /* uniform in area (the Whitted integrator: cheaper, its images unchanged) */
    LIGHT_TRI_SOLID_ANGLE_COS = 2 /* the solid angle warped toward |cos| at the receiver of normal n */
};

/* Where light is gathered: the shading point p, its geometric normal n
 * (zero for a point in a medium), o where shadow rays leave (p moved off
 * the surface), and whether every emitter counts as two-sided (the Whitted
 * integrator's rule; else a material's two_sided says). */
typedef struct light_ctx {
    vec3 p, n, o;
    bool two_sided;
} light_ctx;

typedef struct light_sample {
    vec3 wi;       /* unit direction from p to the light */
    vec3 le;       /* radiance (or intensity / dist^2 for point lights) arriving at p */
    float pdf;     /* solid angle (1 for point lights); light_sample_li: the light's choice included */
    bool delta;
    ray shadow;
} light_sample;

/* Solid-angle pdf of light l (a triangle or sphere of s) sampled by area
 * (a sphere seen from outside: uniform in its cone) at the point q, of
 * normal nq, from p, the choice of the light excluded. */
static inline PK_HD float light_pdf_area(const scene_view *s, const light *l, vec3 p, vec3 q, vec3 nq)
{
    vec3 d = v3_sub(q, p);
    float dist2 = v3_len2(d);
    if (!(dist2 > 0.0f)) return 0.0f;
    if (l->kind == LIGHT_SPHERE) {
        const sphere *sp = &s->spheres[l->index];
        float dc2 = v3_len2(v3_sub(sp->center, p)), r2 = sp->radius * sp->radius;
        if (dc2 > r2 * 1.0001f) { /* outside: uniform in the cone of the sphere */
            float sin2 = r2 / dc2, cos_max = sqrtf(fmaxf(0.0f, 1.0f - sin2));
            float one_minus = sin2 / (1.0f + cos_max);
            return 1.0f / (2.0f * PK_PI * one_minus);
        }
    }
    /* uniform by area, converted to solid angle */
    float cos_l = fabsf(v3_dot(nq, v3_scale(d, 1.0f / sqrtf(dist2))));
    if (!(cos_l > 0.0f) || !(l->area > 0.0f)) return 0.0f;
    return dist2 / (cos_l * l->area);
}

/* Whether triangle light l is sampled by its solid angle from p (else by
 * area), with the spherical triangle *st when it is: the one rule of both
 * the sampling and the pdf. */
static inline PK_HD bool light_tri_spherical(const light *l, vec3 p, sph_tri *st)
{
    const vec3 a = l->v[0], b = l->v[1], c = l->v[2];
    /* Cheaply first: the solid angle, the integral of h / r^3 over the
     * triangle (h: p's distance from its plane), is at most area h / r^3
     * for any r below p's distance from it, such as the distance to the
     * centroid less the centroid's farthest vertex. */
    const vec3 cen = v3_scale(v3_add(v3_add(a, b), c), 1.0f / 3.0f);
    const float ra = v3_len2(v3_sub(a, cen)), rb = v3_len2(v3_sub(b, cen)), rc = v3_len2(v3_sub(c, cen));
    const float rmax = sph_sqrt(ra > rb ? (ra > rc ? ra : rc) : (rb > rc ? rb : rc));
    const float h = fabsf(v3_dot(l->normal, v3_sub(p, a))), d = sph_sqrt(v3_len2(v3_sub(p, cen))) - rmax;
    const float r = d > h ? d : h;
    if (l->area * h < SPH_TRI_MIN_SOLID_ANGLE * (r * r * r)) return false;
    return sph_tri_setup(st, p, a, b, c, SPH_TRI_MIN_SOLID_ANGLE, SPH_TRI_MAX_SOLID_ANGLE);
}

/* Solid-angle pdf of light l (a triangle or sphere of s) sampling the point
 * q, of normal nq, from p with the receiver normal n and triangle mode tri
 * (LIGHT_TRI_*), the choice of the light excluded: what light_sample_one
 * returns as pdf for the direction from p to q. */
static inline PK_HD float light_pdf_at(const scene_view *s, const light *l, vec3 p, vec3 n, uint32_t tri, vec3 q,
                                       vec3 nq)
{
    if (l->kind == LIGHT_TRIANGLE && tri != LIGHT_TRI_AREA) {
        sph_tri st;
        if (light_tri_spherical(l, p, &st)) {
            if (tri != LIGHT_TRI_SOLID_ANGLE_COS) return 1.0f / st.area;
            float u0, u1, w[4];
            const vec3 d = v3_sub(q, p);
            const float id = 1.0f / sph_sqrt(v3_len2(d));
            if (!(id > 0.0f) || !isfinite(id)) return 0.0f;
            sph_tri_invert(&st, v3_scale(d, id), &u0, &u1);
            sph_tri_cos_weights(&st, n, w);
            return bilinear_pdf(u0, u1, w) / st.area;
        }
    }
    return light_pdf_area(s, l, p, q, nq);
}

/* The same for the path tracer's mode (LIGHT_TRI_SOLID_ANGLE_COS): n is
 * the receiver's normal, what light_ctx.n was when it sampled lights. */
static inline PK_HD float light_pdf_li(const scene_view *s, const light *l, vec3 p, vec3 n, vec3 q, vec3 nq)
{
    return light_pdf_at(s, l, p, n, LIGHT_TRI_SOLID_ANGLE_COS, q, nq);
}

/* Samples triangle light l by the solid angle st it subtends from lc->p:
 * false when it sends nothing toward lc->p. */
static inline PK_HD bool light_sample_tri_solid_angle(const light *l, const light_ctx *lc, uint32_t tri,
                                                      const sph_tri *st, float u1, float u2, light_sample *ls)
{
    const vec3 v0 = l->v[0], v1 = l->v[1], v2 = l->v[2];
    const vec3 p = lc->p, o = lc->o;
    const bool front = v3_dot(l->normal, v3_sub(p, v0)) > 0.0f;
    if (!front && !l->two_sided && !lc->two_sided) return false;
    float x = u1, y = u2, pdf;
    if (tri == LIGHT_TRI_SOLID_ANGLE_COS) {
        float w[4];
        sph_tri_cos_weights(st, lc->n, w);
        sample_bilinear(u1, u2, w, &x, &y);
        pdf = bilinear_pdf(x, y, w) / st->area;
    } else {
        pdf = 1.0f / st->area;
    }
    const vec3 w = sph_tri_sample(st, x, y);
    /* where w meets the triangle (Moeller-Trumbore), kept on it */
    const vec3 e1 = v3_sub(v1, v0), e2 = v3_sub(v2, v0), s1 = v3_cross(w, e2);
    const float idiv = 1.0f / v3_dot(s1, e1);
    if (!isfinite(idiv)) return false;
    const vec3 sv = v3_sub(p, v0);
    float b1 = v3_dot(sv, s1) * idiv, b2 = v3_dot(w, v3_cross(sv, e1)) * idiv;
    b1 = b1 > 0.0f ? b1 : 0.0f, b2 = b2 > 0.0f ? b2 : 0.0f;
    if (b1 + b2 > 1.0f) {
        const float sum = b1 + b2;
        b1 /= sum, b2 /= sum;
    }
    const vec3 q = v3_add(v3_add(v3_scale(v0, 1.0f - b1 - b2), v3_scale(v1, b1)), v3_scale(v2, b2));
    if (!(pdf > 0.0f) || !isfinite(pdf) || !v3_finite(q)) return false;
    const vec3 d = v3_sub(q, o);
    const float dist2 = v3_len2(d);
    if (!(dist2 > 0.0f)) return false;
    ls->wi = v3_scale(d, 1.0f / sph_sqrt(dist2));
    ls->le = l->le;
    ls->pdf = pdf;
    ls->delta = false;
    ls->shadow = (ray){o, 0.0f, d, 1.0f - SHADOW_SHORTEN};
    return true;
}

/* Samples triangle light l uniformly by area from lc with (u1, u2): false
 * when it sends nothing toward lc->p. ls->pdf is the solid
 * angle pdf at lc->p (light_pdf_area), ls->wi and the shadow ray leave from
 * lc->o. What light_sample_one_with does for a triangle by area (the
 * Whitted integrator's measure, and the solid-angle modes' fallback), on
 * its own so that a caller that knows it has a triangle light calls it
 * without the other kinds' code. */
static inline PK_HD bool light_sample_tri_area(const light *l, const light_ctx *lc, float u1, float u2,
                                               light_sample *ls)
{
    const vec3 p = lc->p, o = lc->o, nq = l->normal;
    const vec3 q = sample_triangle(l->v[0], l->v[1], l->v[2], u1, u2);
    if (!lc->two_sided && !l->two_sided && !(v3_dot(nq, v3_sub(p, q)) > 0.0f)) return false;
    /* light_pdf_area of a triangle; where it would return 0 (p on the
     * light, cos_l or the area 0 or NaN) the pdf here is 0, infinite or
     * NaN, which the one test after it refuses, so that it is the only one */
    const vec3 dp = v3_sub(q, p);
    const float dist2p = v3_len2(dp);
    const float cos_l = fabsf(v3_dot(nq, v3_scale(dp, 1.0f / sqrtf(dist2p))));
    const float pdf = dist2p / (cos_l * l->area);
    if (!(pdf > 0.0f) || !isfinite(pdf)) return false;
    const vec3 d = v3_sub(q, o);
    const float dist2 = v3_len2(d);
    if (!(dist2 > 0.0f)) return false;
    ls->wi = v3_scale(d, 1.0f / sqrtf(dist2));
    ls->le = l->le;
    ls->pdf = pdf;
    ls->delta = false;
    ls->shadow = (ray){o, 0.0f, d, 1.0f - SHADOW_SHORTEN};
    return true;
}

/* The fraction of a point light's intensity it sends in the unit direction
 * w (from the light): 1 for point lights, a spot light's cone and falloff
 * (SPOT_FALLOFF_*). */
static inline PK_HD float spot_falloff(const point_light *pl, vec3 w)
{
    if (!(v3_len2(pl->spot_dir) > 0.0f)) return 1.0f;
    const float c = v3_dot(pl->spot_dir, w);
    if (c >= pl->cos_inner) return 1.0f;
    if (c <= pl->cos_outer) return 0.0f;
    const float t = (c - pl->cos_outer) / (pl->cos_inner - pl->cos_outer);
    if (pl->spot_falloff == SPOT_FALLOFF_SQUARED) return t * t;
    if (pl->spot_falloff == SPOT_FALLOFF_ANGLE) {
        const float a = acosf(fminf(c, 1.0f)), ai = acosf(pl->cos_inner), ao = acosf(pl->cos_outer);
        return ao > ai ? fminf(fmaxf((ao - a) / (ao - ai), 0.0f), 1.0f) : 1.0f;
    }
    return t * t * (3.0f - 2.0f * t);
}

/* What a point light's image map (LIGHT_MAP_*) multiplies its intensity by
 * in the direction w (from the light, world space; scene.h, point_light). */
static inline PK_HD vec3 point_light_map(const scene_view *s, const point_light *pl, vec3 w)
{
    const float *m = pl->to_light;
    vec3 d = v3(m[0] * w.x + m[1] * w.y + m[2] * w.z, m[3] * w.x + m[4] * w.y + m[5] * w.z,
                m[6] * w.x + m[7] * w.y + m[8] * w.z);
    d = v3_norm_scaled(d);
    if (!v3_finite(d)) return v3s(0.0f);
    float x, y;
    if (pl->map_kind == LIGHT_MAP_GONIOMETRIC) {
        equal_area_sphere_to_square(d, &x, &y);
    } else {
        if (!(d.z >= 1e-3f)) return v3s(0.0f); /* behind the projector (pbrt-v4's near plane) */
        const float px = d.x / (d.z * pl->proj_tan), py = d.y / (d.z * pl->proj_tan);
        if (!(fabsf(px) <= pl->proj_sx && fabsf(py) <= pl->proj_sy)) return v3s(0.0f);
        x = 0.5f * (px / pl->proj_sx + 1.0f), y = 0.5f * (py / pl->proj_sy + 1.0f);
    }
    const texture *t = &s->textures[pl->map_tex];
    const tex_level *l = &t->lv[0];
    int ix = (int)(x * (float)l->w), iy = (int)(y * (float)l->h);
    ix = ix < 0 ? 0 : ix >= l->w ? l->w - 1 : ix;
    iy = iy < 0 ? 0 : iy >= l->h ? l->h - 1 : iy;
    float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    tex_fetch(t, l, ix, iy, c);
    if (t->nc < 3) c[1] = c[2] = c[0];
    if (pl->map_kind == LIGHT_MAP_GONIOMETRIC) return v3s(fmaxf((c[0] + c[1] + c[2]) * (1.0f / 3.0f), 0.0f));
    const float k = pl->map_kind == LIGHT_MAP_PROJECTOR ? 1.0f / (d.z * d.z * d.z) : 1.0f; /* d.z >= 1e-3 */
    return v3(fmaxf(c[0], 0.0f) * k, fmaxf(c[1], 0.0f) * k, fmaxf(c[2], 0.0f) * k);
}

/* The radiance that emitter l (a triangle or sphere) sends from its point q
 * when its material has an emission map (map_ke): ke times the map at q's
 * texture coordinates, found as a hit there would find them (the finest
 * level: a light sample has no ray cone), and times the vertex colour at q
 * where they multiply the emission (emit_vertex_color). Otherwise le as it
 * is. */
static inline PK_HD vec3 light_le_at(const scene_view *s, const light *l, vec3 q, vec3 le)
{
    const uint32_t prim = l->kind == LIGHT_TRIANGLE ? l->index : (uint32_t)s->ntris + l->index;
    const material *m = &s->materials[view_prim_material(s, prim)];
    if (!m->map_ke.kind && !m->emit_vertex_color) return le;
    hit h = {0.0f, prim, 0.0f, 0.0f};
    if (l->kind == LIGHT_TRIANGLE) { /* q's barycentric coordinates (of v[1] and v[2]) */
        const vec3 e1 = v3_sub(l->v[1], l->v[0]), e2 = v3_sub(l->v[2], l->v[0]), d = v3_sub(q, l->v[0]);
        const float d00 = v3_dot(e1, e1), d01 = v3_dot(e1, e2), d11 = v3_dot(e2, e2);
        const float d20 = v3_dot(d, e1), d21 = v3_dot(d, e2), den = d00 * d11 - d01 * d01;
        if (!(den > 0.0f)) return le;
        h.u = fminf(fmaxf((d11 * d20 - d01 * d21) / den, 0.0f), 1.0f);
        h.v = fminf(fmaxf((d00 * d21 - d01 * d20) / den, 0.0f), 1.0f - h.u);
    }
    if (m->emit_vertex_color && l->kind == LIGHT_TRIANGLE) {
        const rgba c = view_tri_color(s, prim, h.u, h.v);
        le = v3_mul(le, v3(fmaxf(c.r, 0.0f), fmaxf(c.g, 0.0f), fmaxf(c.b, 0.0f)));
    }
    if (!m->map_ke.kind) return le;
    const ray r = {q, 0.0f, v3s(0.0f), 1.0f}; /* a sphere's uv is that of r.o + t r.d = q */
    const surface_uv uv = surface_uv_at(s, &r, &h);
    const tex_query tq = surface_query(s, &uv, 0.0f, q, l->normal);
    const vec3 c = tex_eval_rgb(s->textures, &m->map_ke, tq);
    return v3_mul(le, v3(fmaxf(c.x, 0.0f), fmaxf(c.y, 0.0f), fmaxf(c.z, 0.0f)));
}

/* Samples light li of the set from lc with (u1, u2), triangles as tri
 * says (LIGHT_TRI_*): false when it sends nothing toward lc->p. ls->pdf
 * excludes the light's choice; it is light_pdf_at(s, l, lc->p, lc->n, tri,
 * the point sampled, its normal). */
static inline PK_HD bool light_sample_one_with(const light_set *set, const scene_view *s, const env_light *e,
                                               size_t li, const light_ctx *lc, uint32_t tri, float u1, float u2,
                                               light_sample *ls)
{
    const light *l = &set->lights[li];
    const vec3 o = lc->o, p = lc->p;
    vec3 q, nq, le;
    float pdf;
    if (l->kind == LIGHT_ENV || l->kind == LIGHT_SUN) { /* a direction toward the surroundings */
        vec3 d;
        if (l->kind == LIGHT_ENV) {
            if (!env_sample_from(e, o, u1, u2, &d, &le, &pdf)) return false;
        } else {
            d = sun_sample(e, u1, u2);
            le = e->sun_le, pdf = sun_pdf(e);
        }
        ls->wi = d;
        ls->le = le;
        ls->pdf = pdf;
        ls->delta = false;
        ls->shadow = (ray){o, 0.0f, d, INFINITY};
        return true;
    }
    if (l->kind == LIGHT_POINT) {
        const point_light *pl = &s->lights[l->index];
        if (pl->distant) {
            ls->wi = pl->position;
            ls->le = pl->intensity;
            ls->pdf = 1.0f;
            ls->delta = true;
            ls->shadow = (ray){o, 0.0f, pl->position, INFINITY};
            return true;
        }
        /* the inverse square from the shading point itself, not from o
         * (lifted off the surface by an offset that grows with the scene) */
        const vec3 d = v3_sub(pl->position, o), dp = v3_sub(pl->position, p);
        const float dist2 = v3_len2(dp);
        if (!(dist2 > 0.0f) || !(v3_len2(d) > 0.0f)) return false;
        ls->wi = v3_scale(dp, 1.0f / sqrtf(dist2));
        const float f = spot_falloff(pl, v3_neg(ls->wi));
        if (!(f > 0.0f)) return false;
        ls->le = v3_scale(pl->intensity, f / dist2);
        if (pl->map_kind != LIGHT_MAP_NONE) {
            ls->le = v3_mul(ls->le, point_light_map(s, pl, v3_neg(ls->wi)));
            if (!(ls->le.x > 0.0f || ls->le.y > 0.0f || ls->le.z > 0.0f)) return false;
        }
        ls->pdf = 1.0f;
        ls->delta = true;
        ls->shadow = (ray){o, 0.0f, d, 1.0f};
        return true;
    }
    if (l->kind == LIGHT_TRIANGLE) {
        bool ok = false, done = false;
        if (tri != LIGHT_TRI_AREA) {
            sph_tri st;
            if (light_tri_spherical(l, p, &st)) ok = light_sample_tri_solid_angle(l, lc, tri, &st, u1, u2, ls), done = true;
        }
        if (!done) ok = light_sample_tri_area(l, lc, u1, u2, ls);
        if (ok && s->has_emission_maps) ls->le = light_le_at(s, l, v3_add(ls->shadow.o, ls->shadow.d), ls->le);
        return ok;
    }
    const material *m;
    {
        const sphere *sp = &s->spheres[l->index];
        m = &s->materials[sp->material];
        vec3 dc = v3_sub(sp->center, p);
        float dc2 = v3_len2(dc), r2 = sp->radius * sp->radius;
        if (dc2 > r2 * 1.0001f) {
            /* a direction uniform in the cone, then the point where it meets the sphere */
            float dcl = sqrtf(dc2), sin2 = r2 / dc2, cos_max = sqrtf(fmaxf(0.0f, 1.0f - sin2));
            float one_minus = sin2 / (1.0f + cos_max);
            float cos_t = 1.0f - u1 * one_minus, sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t));
            float phi = 2.0f * PK_PI * u2;
            vec3 w = v3_scale(dc, 1.0f / dcl);
            vec3 t = fabsf(w.x) > 0.5f ? v3(-w.y, w.x, 0.0f) : v3(0.0f, -w.z, w.y);
            t = v3_norm(t);
            vec3 bb = v3_cross(w, t);
            vec3 dir = v3_add(v3_add(v3_scale(t, sin_t * cosf(phi)), v3_scale(bb, sin_t * sinf(phi))), v3_scale(w, cos_t));
            /* nearest intersection of p + s dir with the sphere */
            float bq = v3_dot(dir, dc), disc = bq * bq - (dc2 - r2);
            float sdist = bq - sqrtf(fmaxf(0.0f, disc));
            q = v3_add(p, v3_scale(dir, sdist));
            nq = v3_norm_scaled(v3_sub(q, sp->center)); /* seen from outside: the emitting side */
        } else {
            /* inside: uniform on the sphere, seen from within (its back) */
            float z = 1.0f - 2.0f * u1, rr = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * PK_PI * u2;
            nq = v3(rr * cosf(phi), rr * sinf(phi), z);
            q = v3_add(sp->center, v3_scale(nq, sp->radius));
            if (!m->two_sided && !lc->two_sided) return false;
        }
    }
    le = s->has_emission_maps ? light_le_at(s, l, q, m->ke) : m->ke;
    pdf = light_pdf_area(s, l, p, q, nq);
    if (!(pdf > 0.0f) || !isfinite(pdf)) return false;
    vec3 d = v3_sub(q, o);
    float dist2 = v3_len2(d);
    if (!(dist2 > 0.0f)) return false;
    ls->wi = v3_scale(d, 1.0f / sqrtf(dist2));
    ls->le = le;
    ls->pdf = pdf;
    ls->delta = false;
    ls->shadow = (ray){o, 0.0f, d, 1.0f - SHADOW_SHORTEN};
    return true;
}

/* The same with the path tracer's triangles (LIGHT_TRI_SOLID_ANGLE_COS),
 * whose pdf is light_pdf_li. */
static inline PK_HD bool light_sample_one(const light_set *set, const scene_view *s, const env_light *e, size_t li,
                                          const light_ctx *lc, float u1, float u2, light_sample *ls)
{
    return light_sample_one_with(set, s, e, li, lc, LIGHT_TRI_SOLID_ANGLE_COS, u1, u2, ls);
}

/* Whether light li has a place (is in the tree when there is one). */
static inline PK_HD bool light_has_place(const light_set *set, const scene_view *s, size_t li)
{
    const light *l = &set->lights[li];
    return l->kind == LIGHT_TRIANGLE || l->kind == LIGHT_SPHERE || (l->kind == LIGHT_POINT && !s->lights[l->index].distant);
}

/* Chooses a light for the point p of normal n with u: by power, or through
 * the tree when the set uses it; *pmf the probability of the choice. */
static inline PK_HD bool light_pick(const light_set *set, const scene_view *s, vec3 p, vec3 n, float u, size_t *li,
                                    float *pmf)
{
    (void)s;
    if (set->n == 0) return false;
    if (!set->use_tree) {
        *li = light_set_pick(set, u);
        *pmf = set->pmf[*li];
        return *pmf > 0.0f;
    }
    if (u < set->p_tree) {
        uint32_t l;
        float pr;
        float ut = u / set->p_tree;
        ut = ut < 0x1.fffffep-1f ? ut : 0x1.fffffep-1f;
        if (!light_tree_pick(set->tree, p, n, ut, &l, &pr)) return false;
        *li = l;
        *pmf = set->p_tree * pr;
        return *pmf > 0.0f;
    }
    if (set->ninf == 0) return false;
    *li = set->inf[cdf_pick(set->inf_cdf, set->ninf, (u - set->p_tree) / (1.0f - set->p_tree))];
    *pmf = set->pmf[*li];
    return *pmf > 0.0f;
}

/* The probability light_pick gives light li at p, of normal n. */
static inline PK_HD float light_pmf(const light_set *set, const scene_view *s, vec3 p, vec3 n, size_t li)
{
    if (!set->use_tree || !light_has_place(set, s, li)) return set->pmf[li];
    return set->p_tree * light_tree_pmf(set->tree, set->trail[li], p, n);
}

/* One light chosen with u0 (light_pick), then sampled with (u1, u2),
 * triangles as tri says; ls->pdf includes the choice. */
static inline PK_HD bool light_sample_li_with(const light_set *set, const scene_view *s, const env_light *e,
                                              const light_ctx *lc, uint32_t tri, float u0, float u1, float u2,
                                              light_sample *ls)
{
    size_t li;
    float psel;
    if (!light_pick(set, s, lc->p, lc->n, u0, &li, &psel)) return false;
    if (!light_sample_one_with(set, s, e, li, lc, tri, u1, u2, ls)) return false;
    ls->pdf = psel * ls->pdf;
    return true;
}

/* The path tracer's: triangles by solid angle warped toward the cosine at
 * lc->n; the pdf of a direction found otherwise is pmf * light_pdf_li. */
static inline PK_HD bool light_sample_li(const light_set *set, const scene_view *s, const env_light *e,
                                         const light_ctx *lc, float u0, float u1, float u2, light_sample *ls)
{
    return light_sample_li_with(set, s, e, lc, LIGHT_TRI_SOLID_ANGLE_COS, u0, u1, u2, ls);
}

#endif

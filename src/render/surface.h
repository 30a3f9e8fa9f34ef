/*
 * surface.h - what an integrator needs to know about a hit: the point, the
 * geometric and shading normals turned toward the incoming ray, the side
 * that was hit and the material; and where spawned rays start.
 */
#ifndef PK_SURFACE_H
#define PK_SURFACE_H

#include "../accel/accel.h"
#include "../accel/geom.h"
#include "../scene/scene_view.h"

typedef struct surface {
    vec3 p;        /* world-space hit point */
    vec3 ng;       /* geometric normal, facing the incoming ray */
    vec3 ns;       /* shading normal, same hemisphere as ng */
    bool front;    /* the ray hit the side the geometric normal points to */
    const material *m;
    vec3 dpdu;     /* the tangent dp/du (unnormalised; zero unless the material is anisotropic) */
    vec3 nc;       /* the clearcoat's own normal (glTF's clearcoatNormalTexture), same side as ng; zero: none */
} surface;

/* Whether hit number prim is a triangle (of the world arrays or of a kept
 * instance) rather than a sphere. */
static inline PK_HD bool surface_is_tri(const scene_view *s, uint32_t prim)
{
    return prim < s->ntris || (size_t)prim - s->ntris >= s->nspheres;
}

/* Texture coordinates at a hit (surface_uv_at, below). */
typedef struct surface_uv {
    float u, v;
    vec3 dpdu, dpdv;
    float uv_per_len;
    float u1, v1;        /* the same in the second set (scene_view's uvs1; the first's where there is none) */
    vec3 dpdu1, dpdv1;
    float uv_per_len1;
} surface_uv;
static inline PK_HD surface_uv surface_uv_at(const scene_view *s, const ray *r, const hit *h);
static inline PK_HD tex_query surface_query(const scene_view *s, const surface_uv *uv, float width, vec3 p, vec3 n);

/* A number in [0, 1) from the bits of a hit point p, the direction wo and
 * the level of a mix among nested mixes (MurmurHash3's mixing steps): the
 * same arguments give the same number on the CPU and the GPU, and a scene
 * gives the same choices whatever order its file defines the materials in. */
static inline PK_HD float surface_mix_hash(vec3 p, vec3 wo, int level)
{
    union {
        float f[6];
        uint32_t u[6];
    } w;
    w.f[0] = p.x, w.f[1] = p.y, w.f[2] = p.z, w.f[3] = wo.x, w.f[4] = wo.y, w.f[5] = wo.z;
    uint32_t h = 0x9747b28cu ^ ((uint32_t)level * 0x85ebca6bu);
    for (int i = 0; i < 6; i++) {
        uint32_t k = w.u[i] * 0xcc9e2d51u;
        k = (k << 15) | (k >> 17);
        h ^= k * 0x1b873593u;
        h = ((h << 13) | (h >> 19)) * 5u + 0xe6546b64u;
    }
    h ^= h >> 16, h *= 0x85ebca6bu, h ^= h >> 13, h *= 0xc2b2ae35u, h ^= h >> 16;
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}

/* The material a mix (MAT_MIX) stands for at a hit, as pbrt-v4 chooses it:
 * mix_b where the hash of the hit point p and the direction wo toward the
 * viewer (and the level, for mixes of mixes) falls below the amount, mix_a
 * elsewhere; a mix of mixes is
 * followed down (at most MATERIAL_MIX_DEPTH levels, as readers ensure). No
 * random number is drawn, so the sampler's dimensions stay as they were. */
static inline PK_HD const material *surface_mix_choose(const scene_view *s, const ray *r, const hit *h, vec3 p,
                                                       const material *m)
{
    const vec3 wo = v3_neg(v3_norm(r->d));
    for (int k = 0; k < MATERIAL_MIX_DEPTH && m->type == MAT_MIX; k++) {
        float amount = m->amount;
        if (m->map_alpha.kind) {
            const surface_uv uv = surface_uv_at(s, r, h);
            const tex_query q = surface_query(s, &uv, 0.0f, p, v3s(0.0f));
            amount *= fminf(fmaxf(tex_eval_scalar(s->textures, &m->map_alpha, q), 0.0f), 1.0f);
        }
        int pick = m->mix_a;
        if (amount >= 1.0f) pick = m->mix_b;
        else if (amount > 0.0f && surface_mix_hash(p, wo, k) < amount) pick = m->mix_b;
        m = &s->materials[pick];
    }
    return m;
}

/* The surface that ray r hit at h (h->prim is a triangle, a sphere or a
 * kept instance's triangle of s: view_tri_get gives every triangle in
 * world space, so this is the one place a hit becomes a surface). A mix is
 * resolved here to the material it stands for at the hit. */
static inline PK_HD surface surface_at(const scene_view *s, const ray *r, const hit *h)
{
    surface sf;
    vec3 ng, ns;
    if (surface_is_tri(s, h->prim)) {
        view_tri t;
        view_tri_get(s, h->prim, &t);
        const vec3 a = t.p[0], b = t.p[1], c = t.p[2];
        float w = 1.0f - h->u - h->v;
        sf.p = v3_add(v3_add(v3_scale(a, w), v3_scale(b, h->u)), v3_scale(c, h->v));
        ng = tri_normal(a, b, c);
        ns = ng;
        if (t.has_n) {
            vec3 n = v3_add(v3_add(v3_scale(t.n[0], w), v3_scale(t.n[1], h->u)), v3_scale(t.n[2], h->v));
            if (v3_len2(n) > 0.0f) {
                n = v3_norm(n);
                /* vertex normals pointing against the face are taken as flipped faces */
                ns = v3_dot(n, ng) >= 0.0f ? n : v3_neg(n);
            }
        }
        sf.m = &s->materials[t.material];
    } else {
        const sphere *sp = &s->spheres[h->prim - s->ntris];
        vec3 p = v3_add(r->o, v3_scale(r->d, h->t));
        ng = v3_norm_scaled(v3_sub(p, sp->center));
        sf.p = v3_add(sp->center, v3_scale(ng, sp->radius));
        ns = ng;
        sf.m = &s->materials[sp->material];
    }
    if (sf.m->type == MAT_MIX) sf.m = surface_mix_choose(s, r, h, sf.p, sf.m);
    sf.front = v3_dot(ng, r->d) < 0.0f;
    if (!sf.front) {
        ng = v3_neg(ng);
        ns = v3_neg(ns);
    }
    sf.ng = ng;
    sf.ns = ns;
    sf.dpdu = v3s(0.0f);
    sf.nc = v3s(0.0f);
    return sf;
}

/* Texture coordinates at a hit: a triangle's interpolated vt (or its
 * barycentric coordinates (0,0), (1,0), (0,1) when it has none), a sphere's
 * latitude-longitude (u around +y from -x, v = 1 at the top). dpdu, dpdv:
 * the position's derivatives (unnormalised tangents); uv_per_len: the uv
 * length of a unit of scene length on the surface (the square root of the
 * area ratio), which turns a world footprint into a uv one. */
#define SURFACE_MIN_COS 0.05f    /* footprints of grazing hits stop growing here */
/* One texture-coordinate set of a triangle (a, b, c with uvs ta, tb, tc) at
 * barycentric (bu, bv): *u, *v, the derivatives and the uv length per unit
 * length (surface_uv_at). */
static inline PK_HD void surface__tri_uv(vec3 a, vec3 b, vec3 c, uv2 ta, uv2 tb, uv2 tc, float bu, float bv, float *u,
                                         float *v, vec3 *dpdu, vec3 *dpdv, float *uv_per_len)
{
    const float w = 1.0f - bu - bv;
    *u = ta.u * w + tb.u * bu + tc.u * bv;
    *v = ta.v * w + tb.v * bu + tc.v * bv;
    /* dp/du, dp/dv from the two edges (pbrt's construction) */
    const float du1 = tb.u - ta.u, dv1 = tb.v - ta.v, du2 = tc.u - ta.u, dv2 = tc.v - ta.v;
    const vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a);
    const float det = du1 * dv2 - dv1 * du2;
    const float area = v3_len(v3_cross(e1, e2));
    if (fabsf(det) > 1e-20f && isfinite(1.0f / det)) {
        const float inv = 1.0f / det;
        *dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), inv);
        *dpdv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), inv);
    } else { /* uv degenerate: any frame around the normal */
        *dpdu = v3_norm_scaled(e1);
        *dpdv = v3_cross(v3_norm_scaled(v3_cross(e1, e2)), *dpdu);
    }
    *uv_per_len = area > 0.0f ? sqrtf(fabsf(det) / area) : 0.0f;
}

static inline PK_HD surface_uv surface_uv_at(const scene_view *s, const ray *r, const hit *h)
{
    surface_uv q;
    if (surface_is_tri(s, h->prim)) {
        view_tri t;
        view_tri_get(s, h->prim, &t);
        uv2 ta = {0.0f, 0.0f}, tb = {1.0f, 0.0f}, tc = {0.0f, 1.0f};
        if (t.has_t) {
            ta = t.t[0];
            tb = t.t[1];
            tc = t.t[2];
        }
        surface__tri_uv(t.p[0], t.p[1], t.p[2], ta, tb, tc, h->u, h->v, &q.u, &q.v, &q.dpdu, &q.dpdv, &q.uv_per_len);
        if (t.has_t1) {
            surface__tri_uv(t.p[0], t.p[1], t.p[2], t.t1[0], t.t1[1], t.t1[2], h->u, h->v, &q.u1, &q.v1, &q.dpdu1,
                            &q.dpdv1, &q.uv_per_len1);
        } else {
            q.u1 = q.u, q.v1 = q.v, q.dpdu1 = q.dpdu, q.dpdv1 = q.dpdv, q.uv_per_len1 = q.uv_per_len;
        }
    } else {
        const sphere *sp = &s->spheres[h->prim - s->ntris];
        vec3 p = v3_add(r->o, v3_scale(r->d, h->t));
        vec3 n = v3_norm_scaled(v3_sub(p, sp->center));
        const float phi = atan2f(n.z, n.x), theta = acosf(fminf(1.0f, fmaxf(-1.0f, n.y)));
        q.u = (phi + PK_PI) * (0.5f / PK_PI);
        q.v = 1.0f - theta * (1.0f / PK_PI);
        const float rr = sp->radius, st = sinf(theta);
        /* p = c + r (-cos(2 pi u) sin t, cos t, -sin(2 pi u) sin t), t = pi (1 - v) */
        q.dpdu = v3(-2.0f * PK_PI * rr * n.z, 0.0f, 2.0f * PK_PI * rr * n.x);
        q.dpdv = v3_scale(v3(n.x * n.y / fmaxf(st, 1e-6f), -st, n.z * n.y / fmaxf(st, 1e-6f)), -PK_PI * rr);
        if (st < 1e-6f) q.dpdu = v3_cross(q.dpdv, n);
        /* uv area 1 over the sphere's 4 pi r^2 */
        q.uv_per_len = 1.0f / (rr * 2.0f * sqrtf(PK_PI));
        q.u1 = q.u, q.v1 = q.v, q.dpdu1 = q.dpdu, q.dpdv1 = q.dpdv, q.uv_per_len1 = q.uv_per_len;
    }
    return q;
}

/* The lookup at uv (both sets) with footprint width (in scene length; the
 * sets' uv_per_len turn it into uv widths) at point p with normal n. */
static inline PK_HD tex_query surface_query(const scene_view *s, const surface_uv *uv, float width, vec3 p, vec3 n)
{
    tex_query q = {uv->u, uv->v, width * uv->uv_per_len, p, n, s->tex_nodes, uv->u1, uv->v1, width * uv->uv_per_len1};
    if (!isfinite(q.width)) q.width = 0.0f;
    if (!isfinite(q.width1)) q.width1 = 0.0f;
    return q;
}

static inline PK_HD vec3 surface_clamp_rgb(vec3 c)
{
    return v3(fminf(fmaxf(c.x, 0.0f), 1.0f), fminf(fmaxf(c.y, 0.0f), 1.0f), fminf(fmaxf(c.z, 0.0f), 1.0f));
}

/* Height of a bump map at (u, v) of its own uv set and the point p with
 * normal n (which procedural textures read), the fine level. */
static inline PK_HD float surface_bump_height(const scene_view *s, const tex_ref *ref, float u, float v, vec3 p, vec3 n)
{
    tex_query q = {u, v, 0.0f, p, n, s->tex_nodes, u, v, 0.0f};
    return tex_eval_scalar(s->textures, ref, q);
}

/* A texture's alpha (ch 3; 1 where it has none), red or green channel. */
static inline PK_HD float surface__channel(const scene_view *s, const tex_ref *r, tex_query q, int ch)
{
    float c[4];
    const int nc = tex_eval_raw(s->textures, r, q, c);
    const float v = ch == 3 ? (nc == 2 || nc == 4 ? c[nc - 1] : 1.0f) : nc >= 3 ? c[ch] : c[0];
    return fminf(fmaxf(v, 0.0f), 1.0f);
}
/* glTF's extension maps of a metallic-roughness material (material.h). */
static inline PK_HD void surface__gltf_maps(const scene_view *s, const material *m, material *tm, tex_query q)
{
    if (m->map_spec.kind) tm->specular = m->specular * surface__channel(s, &m->map_spec, q, 3);
    if (m->map_spec_color.kind)
        tm->specular_color =
            v3_mul(m->specular_color, surface_clamp_rgb(tex_eval_rgb(s->textures, &m->map_spec_color, q)));
    if (m->map_sheen.kind)
        tm->sheen_color = v3_mul(m->sheen_color, surface_clamp_rgb(tex_eval_rgb(s->textures, &m->map_sheen, q)));
    if (m->map_sheen_rough.kind)
        tm->sheen_roughness = m->sheen_roughness * surface__channel(s, &m->map_sheen_rough, q, 3);
    if (m->map_irid.kind) tm->iridescence = m->iridescence * surface__channel(s, &m->map_irid, q, 0);
    if (m->map_irid_thick.kind)
        tm->iridescence_thickness = m->iridescence_thickness_min + (m->iridescence_thickness -
                                                                    m->iridescence_thickness_min) *
                                                                       surface__channel(s, &m->map_irid_thick, q, 1);
    if (m->map_aniso.kind) { /* rg: a direction in the tangent frame (2 c - 1), b: the strength */
        float c[4];
        if (tex_eval_raw(s->textures, &m->map_aniso, q, c) >= 3) {
            const float x = 2.0f * c[0] - 1.0f, y = 2.0f * c[1] - 1.0f;
            if (x != 0.0f || y != 0.0f) tm->anisotropy_rotation = m->anisotropy_rotation + atan2f(y, x);
            tm->anisotropy = m->anisotropy * fminf(fmaxf(c[2], 0.0f), 1.0f);
        }
    }
}

/* A tangent-space normal map's normal (unnormalised) in the frame (t, b, n):
 * the texel's 2 c - 1, its x and y times scale (glTF's normalTexture.scale). */
static inline PK_HD vec3 surface__map_normal(const scene_view *s, const tex_ref *r, tex_query q, float scale, vec3 t,
                                             vec3 b, vec3 n)
{
    const vec3 c = tex_eval_rgb(s->textures, r, q);
    vec3 tl = v3(2.0f * c.x - 1.0f, 2.0f * c.y - 1.0f, 2.0f * c.z - 1.0f);
    if (scale != 1.0f) tl.x *= scale, tl.y *= scale;
    return v3_add(v3_add(v3_scale(t, tl.x), v3_scale(b, tl.y)), v3_scale(n, tl.z));
}

static inline PK_HD void surface_texture_at(const scene_view *s, const ray *r, const hit *h, float cone_width, surface *sf, material *tm)
{
    const material *m = sf->m;
    *tm = *m;
    const surface_uv uv = surface_uv_at(s, r, h);
    const float dl = v3_len(r->d);
    const float cosv = dl > 0.0f ? fabsf(v3_dot(r->d, sf->ng)) / dl : 1.0f;
    tex_query q = surface_query(s, &uv, cone_width / fmaxf(cosv, SURFACE_MIN_COS), sf->p, sf->ng);
#ifdef PK_TEX_NO_CONES /* (-D for measurements: the finest level always, bilinear) */
    q.width = q.width1 = 0.0f;
#endif
    /* texture values: colours and alpha in 0..1 (HDR images may hold more), Ns >= 0 */
    if (m->map_kd.kind) tm->kd = v3_mul(m->kd, surface_clamp_rgb(tex_eval_rgb(s->textures, &m->map_kd, q)));
    if (m->vertex_color && surface_is_tri(s, h->prim)) {
        const rgba c = view_tri_color(s, h->prim, h->u, h->v);
        tm->kd = v3_mul(tm->kd, surface_clamp_rgb(v3(c.r, c.g, c.b)));
    }
    if (m->map_ks.kind) tm->ks = v3_mul(m->ks, surface_clamp_rgb(tex_eval_rgb(s->textures, &m->map_ks, q)));
    if (m->map_ns.kind) tm->ns = m->ns * fmaxf(tex_eval_scalar(s->textures, &m->map_ns, q), 0.0f);
    if (m->map_alpha.kind) {
        float a = fminf(fmaxf(tex_eval_scalar(s->textures, &m->map_alpha, q), 0.0f), 1.0f);
        tm->alpha = fminf(m->alpha * (m->map_alpha.squared ? a * a : a), 1.0f);
        if (m->alpha_v >= 0.0f) tm->alpha_v = fminf(m->alpha_v * (m->map_alpha.squared ? a * a : a), 1.0f);
        if (m->type == MAT_PRINCIPLED) tm->roughness = fminf(m->roughness * a, 1.0f); /* its roughness map */
    }
    if (m->map_mr.kind) { /* glTF: blue metallic, green roughness (a grey map: both) */
        float c[4];
        const int nc = tex_eval_raw(s->textures, &m->map_mr, q, c);
        const float mt = nc >= 3 ? c[2] : c[0], rg = nc >= 3 ? c[1] : c[0];
        tm->metallic = fminf(fmaxf(m->metallic * mt, 0.0f), 1.0f);
        tm->roughness = fminf(fmaxf(m->roughness * rg, 0.0f), 1.0f);
        tm->alpha = tm->roughness * tm->roughness;
    }
    if (m->map_eta.kind) { /* a conductor's complex index: not clamped above */
        const vec3 e = tex_eval_rgb(s->textures, &m->map_eta, q);
        tm->eta = v3_mul(m->eta, v3(fmaxf(e.x, 0.0f), fmaxf(e.y, 0.0f), fmaxf(e.z, 0.0f)));
    }
    if (m->map_k.kind) {
        const vec3 k = tex_eval_rgb(s->textures, &m->map_k, q);
        tm->k = v3_mul(m->k, v3(fmaxf(k.x, 0.0f), fmaxf(k.y, 0.0f), fmaxf(k.z, 0.0f)));
    }
    if (m->map_tf.kind) tm->tf = v3_mul(m->tf, surface_clamp_rgb(tex_eval_rgb(s->textures, &m->map_tf, q)));
    if (m->map_tr.kind | m->map_cc.kind | m->map_ccr.kind) { /* glTF's layers: red, red, green */
        float c[4];
        if (m->map_tr.kind) {
            tex_eval_raw(s->textures, &m->map_tr, q, c);
            tm->transmission = fminf(fmaxf(m->transmission * c[0], 0.0f), 1.0f);
        }
        if (m->map_cc.kind) {
            tex_eval_raw(s->textures, &m->map_cc, q, c);
            tm->clearcoat = fminf(fmaxf(m->clearcoat * c[0], 0.0f), 1.0f);
        }
        if (m->map_ccr.kind) {
            const int nc = tex_eval_raw(s->textures, &m->map_ccr, q, c);
            tm->clearcoat_roughness = fminf(fmaxf(m->clearcoat_roughness * (nc >= 3 ? c[1] : c[0]), 0.0f), 1.0f);
        }
    }
    if (m->type == MAT_METALLIC_ROUGHNESS) surface__gltf_maps(s, m, tm, q);
    if (m->map_ke.kind) { /* the finest level, as light sampling sees it (lights.h), so that both agree */
        const tex_query qe = surface_query(s, &uv, 0.0f, sf->p, sf->ng);
        const vec3 e = tex_eval_rgb(s->textures, &m->map_ke, qe);
        tm->ke = v3_mul(m->ke, v3(fmaxf(e.x, 0.0f), fmaxf(e.y, 0.0f), fmaxf(e.z, 0.0f)));
    }
    if (m->emit_vertex_color && surface_is_tri(s, h->prim)) {
        const rgba c = view_tri_color(s, h->prim, h->u, h->v);
        tm->ke = v3_mul(tm->ke, v3(fmaxf(c.r, 0.0f), fmaxf(c.g, 0.0f), fmaxf(c.b, 0.0f)));
    }
    sf->m = tm;
    /* the vertex tangents where the mesh has them (glTF's TANGENT, given or
     * generated), else the uv set of the normal map (or of the anisotropy's
     * direction map) */
    const int ts = m->map_norm.kind ? m->map_norm.uvset : m->map_aniso.kind ? m->map_aniso.uvset : 0;
    vec3 vt = ts ? uv.dpdu1 : uv.dpdu;
    float vw = 0.0f;
    const bool has_vt = surface_is_tri(s, h->prim) && view_tri_tangent(s, h->prim, h->u, h->v, &vt, &vw);
    if (material_anisotropic(m)) sf->dpdu = vt; /* the u roughness's direction */
    if (!m->map_bump.kind && !m->map_norm.kind && !m->map_ccn.kind) return;
    /* a frame on the surface, z = the shading normal as it faces the ray */
    const vec3 n = sf->ns;
    vec3 t = v3_sub(vt, v3_scale(n, v3_dot(n, vt)));
    if (!(v3_len2(t) > 0.0f) || !v3_finite(t)) return;
    t = v3_norm(t);
    vec3 b = v3_cross(n, t);
    if (has_vt) { /* the bitangent w (n x t), n the normal on the side the vertex normals give */
        if (!sf->front) b = v3_neg(b);
        if (vw < 0.0f) b = v3_neg(b);
    } else if (v3_dot(b, ts ? uv.dpdv1 : uv.dpdv) < 0.0f) {
        b = v3_neg(b);
    }
    if (m->map_ccn.kind) { /* the clearcoat's normal: its own map on the interpolated normal */
        vec3 cn = surface__map_normal(s, &m->map_ccn, q, m->coat_norm_scale, t, b, n);
        if (v3_finite(cn) && v3_len2(cn) > 0.0f) {
            cn = v3_norm(cn);
            if (v3_dot(cn, sf->ng) > 0.0f) sf->nc = cn; /* one facing away: the surface's normal */
        }
    }
    if (!m->map_bump.kind && !m->map_norm.kind) return;
    vec3 nn = n;
    if (m->map_norm.kind) {
        nn = surface__map_normal(s, &m->map_norm, q, m->norm_scale, t, b, n);
    } else {
        /* heights times bm displace along n: n' = (dp/du + dh/du n) x (dp/dv + dh/dv n) */
        const tex_ref *ref = &m->map_bump;
        int size = 1;
        if (ref->kind == TEX_IMAGE) {
            const texture *tx = &s->textures[ref->tex];
            size = tx->lv[0].w > tx->lv[0].h ? tx->lv[0].w : tx->lv[0].h;
        }
        float du = 0.5f / (float)size;
        /* a procedural texture (of the point, not only of uv): differences
         * over the ray's footprint in uv (pbrt's BumpMap: du = (|du/dx| +
         * |du/dy|) / 2, 0.0005 without one), read at the points moved
         * along dp/du and dp/dv */
        const bool expr = ref->kind == TEX_EXPR, one = ref->uvset != 0;
        const float bu = one ? uv.u1 : uv.u, bv = one ? uv.v1 : uv.v, bw = one ? q.width1 : q.width;
        const vec3 dpdu = one ? uv.dpdu1 : uv.dpdu, dpdv = one ? uv.dpdv1 : uv.dpdv;
        if (expr) du = bw > 0.0f ? bw : 0.0005f;
        const float dv = du;
        const vec3 pn = expr ? sf->p : v3s(0.0f), nn0 = expr ? sf->ng : v3s(0.0f);
        const vec3 pu = expr ? v3_add(sf->p, v3_scale(dpdu, du)) : pn;
        const vec3 pv = expr ? v3_add(sf->p, v3_scale(dpdv, dv)) : pn;
        const float h0 = surface_bump_height(s, ref, bu, bv, pn, nn0);
        const float hu = (surface_bump_height(s, ref, bu + du, bv, pu, nn0) - h0) / du * ref->bm;
        const float hv = (surface_bump_height(s, ref, bu, bv + dv, pv, nn0) - h0) / dv * ref->bm;
        /* in the frame (t, b, n) with dp/du ~ |dpdu| t and dp/dv ~ |dpdv| b */
        const float lu = v3_len(dpdu), lv = v3_len(dpdv);
        if (!(lu > 0.0f) || !(lv > 0.0f)) return;
        nn = v3_sub(n, v3_add(v3_scale(t, hu / lu), v3_scale(b, hv / lv)));
        if (material_anisotropic(m)) sf->dpdu = v3_add(dpdu, v3_scale(n, hu)); /* the displaced surface's */
    }
    if (!v3_finite(nn) || !(v3_len2(nn) > 0.0f)) return;
    nn = v3_norm(nn);
    if (v3_dot(nn, sf->ng) <= 0.0f) return; /* would face away: kept as it was */
    sf->ns = nn;
}

/* For a material with texture maps (sf.m->textured): looks its maps up
 * for a ray cone of width cone_width (scene units) where it meets the
 * surface, writes the textured material into *tm and returns sf with m
 * pointing at it; bump and normal maps bend its ns. (sf by value, so that
 * callers keep theirs in registers.) */
static inline PK_HD surface surface_texture(const scene_view *s, const ray *r, const hit *h, float cone_width, surface sf, material *tm)
{
    surface_texture_at(s, r, h, cone_width, &sf, tm);
    return sf;
}

#define HOLE_STEPS 256   /* holes passed along one ray at most; then the surface counts */

/* Whether a ray r that hits a surface of coverage a (0 ... 1) at h passes
 * through it: with probability 1 - a, by a hash of the hit point and the
 * ray's direction, so that the choice is the same for the same ray
 * whatever the thread or the device, and differs between the rays of a
 * pixel's samples, the bounces of a path and the layers one ray passes. */
static inline PK_HD bool surface_blend_pass(const ray *r, const hit *h, float a)
{
    if (a >= 1.0f) return false;
    if (!(a > 0.0f)) return true;
    const vec3 p = v3_add(r->o, v3_scale(r->d, h->t));
    return surface_mix_hash(p, r->d, 0x51ed) >= a;
}

/* True when the hit lies in a hole of its material's map_d (opacity < 0.5),
 * or passes through a stochastically transparent surface (material.blend). */
static inline PK_HD bool surface_is_hole(const scene_view *s, const ray *r, const hit *h)
{
    const material *m = &s->materials[view_prim_material(s, h->prim)];
    if (!m->cutout) return false;
    float ca = 1.0f; /* the vertex colours' alpha */
    if (m->vertex_color && surface_is_tri(s, h->prim))
        ca = fminf(fmaxf(view_tri_color(s, h->prim, h->u, h->v).a, 0.0f), 1.0f);
    if (m->blend && !m->map_d.kind) return surface_blend_pass(r, h, m->blend_alpha * ca);
    const surface_uv uv = surface_uv_at(s, r, h);
    tex_query q = surface_query(s, &uv, 0.0f, v3s(0.0f), v3s(0.0f));
    if (m->map_d.kind == TEX_EXPR) {
        const surface sf = surface_at(s, r, h);
        q.p = sf.p, q.n = sf.ng;
    }
    const float a = tex_eval_alpha(s->textures, &m->map_d, q);
    if (m->blend) return surface_blend_pass(r, h, m->blend_alpha * ca * fminf(fmaxf(a, 0.0f), 1.0f));
    return a < 0.5f;
}

/* Steps past holes: while h (a hit of *r) is a hole, looks further along *r
 * (tmin just past the hole). Returns false when nothing else is hit. For
 * scenes with cut-outs (s->has_cutout); every accelerator gives the same. */
PK_HIDDEN bool trace_past_holes(const accel *a, const scene_view *s, ray *r, hit *h, accel_counters *cp);
/* Any-hit test that sees through holes: the fast any-hit when the scene has
 * no cut-out, else closest hits stepped past holes. */
PK_HIDDEN bool occluded_past_holes(const accel *a, const scene_view *s, const ray *r, accel_counters *cp);

/* Origin for a ray leaving p on the side of normal n: a robust offset of eps
 * (the frame's, proportional to the scene's size) plus a part proportional
 * to the magnitude of p. */
static inline PK_HD vec3 offset_origin(float eps, vec3 p, vec3 n)
{
    float mag = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    return v3_add(p, v3_scale(n, eps + mag * 4e-6f));
}

#endif

/*
 * lights.c - building the light set (see lights.h).
 */
#include "lights.h"

#include <string.h>

static bool emits(vec3 ke) { return ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f; }

/* The luminance that chooses among emitters: ke's, times the mean of an
 * emission map over the whole image (spheres, and triangles that take it
 * from emitted_luminance_tri), or of a checker's two colours. */
static double emitted_luminance(const pk_scene *s, const material *m)
{
    vec3 ke = m->ke;
    if (m->map_ke.kind == TEX_IMAGE) ke = v3_mul(ke, texture_mean_rgb(&s->textures[m->map_ke.tex]));
    if (m->map_ke.kind == TEX_CHECKER) ke = v3_mul(ke, v3_scale(v3_add(m->map_ke.even, m->map_ke.odd), 0.5f));
    return (double)fmaxf(v3_luminance(ke), 1e-6f);
}

/* The share of the image's mean that a triangle's own mean never falls
 * below: a triangle over black texels still emits where bilinear filtering
 * reaches across its edges, so it keeps a chance of being sampled. */
#define EMISSION_MAP_FLOOR 1e-3

/* The same for emitting triangle t: with an image emission map, ke times
 * the map's mean over the triangle's own texture coordinates (as shading
 * finds them: the vertices' uvs of the map's set, or (0,0), (1,0), (0,1), through the
 * reference's scale and offset), so that the bright parts of an emitting
 * texture draw the samples. */
static double emitted_luminance_tri(const pk_scene *s, const scene_view *v, const material *m, uint32_t t)
{
    const tex_ref *r = &m->map_ke;
    if (m->emit_vertex_color) {
        /* the vertex colours' mean over the triangle: their value at the centroid */
        const rgba c = view_tri_color(v, t, 1.0f / 3.0f, 1.0f / 3.0f);
        material mc = *m;
        mc.ke = v3_mul(m->ke, v3(fmaxf(c.r, 0.0f), fmaxf(c.g, 0.0f), fmaxf(c.b, 0.0f)));
        mc.emit_vertex_color = false;
        return emitted_luminance_tri(s, v, &mc, t);
    }
    if (r->kind != TEX_IMAGE) return emitted_luminance(s, m);
    view_tri vt;
    view_tri_get(v, t, &vt);
    static const uv2 plain[3] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
    double tu[3], tv[3];
    for (int k = 0; k < 3; k++) {
        const uv2 q = r->uvset && vt.has_t1 ? vt.t1[k] : vt.has_t ? vt.t[k] : plain[k];
        tu[k] = (double)r->s[0] * (double)q.u + (double)r->o[0];
        tv[k] = (double)r->s[1] * (double)q.v + (double)r->o[1];
    }
    const texture *tex = &s->textures[r->tex];
    const double tri = (double)v3_luminance(v3_mul(m->ke, texture_triangle_mean(tex, tu, tv, r->clamp)));
    const double all = (double)v3_luminance(v3_mul(m->ke, texture_mean_rgb(tex)));
    const double lum = fmax(tri, EMISSION_MAP_FLOOR * all);
    return isfinite(lum) && lum > 1e-6 ? lum : 1e-6;
}

/* The radius of a sphere about the centre of the scene's bounds that holds
 * its triangles and spheres (1 for an empty scene). */
static double scene_radius(const pk_scene *s)
{
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    for (size_t i = 0; i < s->npositions; i++) lo = v3_min(lo, s->positions[i]), hi = v3_max(hi, s->positions[i]);
    for (size_t i = 0; i < s->nspheres; i++) {
        const vec3 r = v3s(s->spheres[i].radius);
        lo = v3_min(lo, v3_sub(s->spheres[i].center, r)), hi = v3_max(hi, v3_add(s->spheres[i].center, r));
    }
    if (!(lo.x <= hi.x)) return 1.0;
    const double r = 0.5 * (double)v3_len(v3_sub(hi, lo));
    return r > 0.0 && isfinite(r) ? r : 1.0;
}

/* ---- the light tree ------------------------------------------------------ */

/* A node's bounds while building, in double where it adds up. */
typedef struct lt_bounds {
    vec3 lo, hi;
    vec3 axis;
    float cos_o, cos_e;
    double phi;
    bool two_sided;
} lt_bounds;

static float clampf1(float x) { return x < -1.0f ? -1.0f : x > 1.0f ? 1.0f : x; }

/* The smallest cone (pbrt's DirectionCone union, in our words): a cone
 * that holds both cones (axis, cos of half-angle). */
static void cone_union(vec3 a, float ca, vec3 b, float cb, vec3 *axis, float *cos_o)
{
    const float ta = acosf(clampf1(ca)), tb = acosf(clampf1(cb));
    const float td = acosf(clampf1(v3_dot(a, b)));
    if (fminf(td + tb, PK_PI) <= ta) { *axis = a, *cos_o = ca; return; }
    if (fminf(td + ta, PK_PI) <= tb) { *axis = b, *cos_o = cb; return; }
    const float to = 0.5f * (ta + td + tb);
    if (to >= PK_PI) { *axis = a, *cos_o = -1.0f; return; }
    const float tr = to - ta, sd = sinf(td);
    if (!(sd > 1e-6f)) { *axis = a, *cos_o = -1.0f; return; }
    /* a turned toward b by tr in their plane */
    const vec3 perp = v3_scale(v3_sub(b, v3_scale(a, cosf(td))), 1.0f / sd);
    vec3 w = v3_add(v3_scale(a, cosf(tr)), v3_scale(perp, sinf(tr)));
    const float len = v3_len(w);
    if (!(len > 0.0f) || !isfinite(len)) { *axis = a, *cos_o = -1.0f; return; }
    *axis = v3_scale(w, 1.0f / len);
    *cos_o = cosf(to);
}

static lt_bounds lt_union(const lt_bounds *a, const lt_bounds *b)
{
    if (!(a->phi > 0.0)) return *b;
    if (!(b->phi > 0.0)) return *a;
    lt_bounds u;
    u.lo = v3_min(a->lo, b->lo), u.hi = v3_max(a->hi, b->hi);
    cone_union(a->axis, a->cos_o, b->axis, b->cos_o, &u.axis, &u.cos_o);
    u.cos_e = fminf(a->cos_e, b->cos_e);
    u.phi = a->phi + b->phi;
    u.two_sided = a->two_sided || b->two_sided;
    return u;
}

/* The orientation measure of a cone (Conty Estevez and Kulla's M_Omega):
 * the solid angle of the normals' cone plus the cosine-weighted spread of
 * emission around it. */
static double lt_m_omega(const lt_bounds *b)
{
    const double to = acos((double)clampf1(b->cos_o)), te = acos((double)clampf1(b->cos_e));
    const double tw = fmin(to + te, 3.14159265358979323846);
    const double so = sin(to), co = cos(to);
    return 2.0 * 3.14159265358979323846 * (1.0 - co) +
           3.14159265358979323846 / 2.0 * (2.0 * tw * so - cos(to - 2.0 * tw) - 2.0 * to * so + co);
}

static double lt_area(const lt_bounds *b)
{
    const vec3 e = v3_sub(b->hi, b->lo);
    return 2.0 * ((double)e.x * (double)e.y + (double)e.y * (double)e.z + (double)e.z * (double)e.x);
}

typedef struct lt_item {
    lt_bounds b;
    vec3 c;      /* centroid */
    uint32_t light;
} lt_item;

typedef struct lt_builder {
    light_tree_node *nodes;
    size_t nnodes;
    uint64_t *trail;
} lt_builder;

static void lt_store(light_tree_node *nd, const lt_bounds *b)
{
    nd->lo[0] = b->lo.x, nd->lo[1] = b->lo.y, nd->lo[2] = b->lo.z;
    nd->hi[0] = b->hi.x, nd->hi[1] = b->hi.y, nd->hi[2] = b->hi.z;
    nd->axis[0] = b->axis.x, nd->axis[1] = b->axis.y, nd->axis[2] = b->axis.z;
    nd->phi = (float)b->phi;
    nd->cos_o = b->cos_o, nd->cos_e = b->cos_e;
    nd->flags = b->two_sided ? LIGHT_TREE_TWO_SIDED : 0u;
}

#define LT_BUCKETS 12

/* The bucket of centroid coordinate c among LT_BUCKETS over [lo, lo + e]
 * (e > 0), clamped in float before the conversion: for emitters more than
 * FLT_MAX / 12 apart, 12 * (c - lo) overflows to infinity (and with e
 * infinite, (c - lo) / e can be NaN), and converting a float out of int's
 * range is undefined. Infinity goes to the last bucket, NaN to the first;
 * every finite value to the bucket it always had. */
static int lt_bucket(float c, float lo, float e)
{
    const float k = (float)LT_BUCKETS * (c - lo) / e;
    if (!(k > 0.0f)) return 0;
    if (k >= (float)(LT_BUCKETS - 1)) return LT_BUCKETS - 1;
    return (int)k;
}

/* Builds the subtree of items [0, n) at node *at, depth deep, the path bits
 * so far in trail. Splits by the cost of pbrt-v4's SAOH over centroid
 * buckets on each axis (power x orientation measure x area, the box made
 * cubic-ish by its aspect); past depth 48 (never with sane inputs) by count
 * halves, so that no path passes 63 levels. */
static void lt_build(lt_builder *tb, lt_item *it, size_t n, int depth, uint64_t trail)
{
    const size_t me = tb->nnodes++;
    lt_bounds all = it[0].b;
    for (size_t i = 1; i < n; i++) all = lt_union(&all, &it[i].b);
    light_tree_node *nd = &tb->nodes[me];
    lt_store(nd, &all);
    if (n == 1) {
        nd->flags |= LIGHT_TREE_LEAF;
        nd->next = it[0].light;
        tb->trail[it[0].light] = trail;
        return;
    }
    vec3 clo = it[0].c, chi = it[0].c;
    for (size_t i = 1; i < n; i++) clo = v3_min(clo, it[i].c), chi = v3_max(chi, it[i].c);
    const vec3 ext = v3_sub(chi, clo), bext = v3_sub(all.hi, all.lo);
    const float bmax = v3_max_comp(bext);
    size_t mid = n / 2;
    if (depth < 48) {
        double best = INFINITY;
        int best_axis = -1, best_split = 0;
        for (int ax = 0; ax < 3; ax++) {
            const float lo = ax == 0 ? clo.x : ax == 1 ? clo.y : clo.z;
            const float e = ax == 0 ? ext.x : ax == 1 ? ext.y : ext.z;
            if (!(e > 0.0f)) continue;
            lt_bounds bk[LT_BUCKETS];
            bool used[LT_BUCKETS] = {false};
            for (size_t i = 0; i < n; i++) {
                const float c = ax == 0 ? it[i].c.x : ax == 1 ? it[i].c.y : it[i].c.z;
                const int k = lt_bucket(c, lo, e);
                bk[k] = used[k] ? lt_union(&bk[k], &it[i].b) : it[i].b;
                used[k] = true;
            }
            const float be = ax == 0 ? bext.x : ax == 1 ? bext.y : bext.z;
            const double kr = be > 0.0f ? (double)bmax / (double)be : 1.0;
            for (int sp = 1; sp < LT_BUCKETS; sp++) {
                lt_bounds l = {0}, r = {0};
                bool hl = false, hr = false;
                for (int k = 0; k < sp; k++)
                    if (used[k]) l = hl ? lt_union(&l, &bk[k]) : bk[k], hl = true;
                for (int k = sp; k < LT_BUCKETS; k++)
                    if (used[k]) r = hr ? lt_union(&r, &bk[k]) : bk[k], hr = true;
                if (!hl || !hr) continue;
                const double cost = kr * (l.phi * lt_m_omega(&l) * lt_area(&l) + r.phi * lt_m_omega(&r) * lt_area(&r));
                if (cost < best) best = cost, best_axis = ax, best_split = sp;
            }
        }
        if (best_axis >= 0) {
            const float lo = best_axis == 0 ? clo.x : best_axis == 1 ? clo.y : clo.z;
            const float e = best_axis == 0 ? ext.x : best_axis == 1 ? ext.y : ext.z;
            size_t a = 0, b = n;
            while (a < b) { /* partition by bucket < best_split */
                const float c = best_axis == 0 ? it[a].c.x : best_axis == 1 ? it[a].c.y : it[a].c.z;
                if (lt_bucket(c, lo, e) < best_split) {
                    a++;
                } else {
                    const lt_item t = it[a];
                    it[a] = it[--b], it[b] = t;
                }
            }
            if (a > 0 && a < n) mid = a;
        }
    }
    lt_build(tb, it, mid, depth + 1, trail);
    tb->nodes[me].next = (uint32_t)tb->nnodes;
    lt_build(tb, it + mid, n - mid, depth + 1, trail | ((uint64_t)1 << depth));
}

/* The tree over the set's lights with a place, and the CDF of the others. */
static pk_status light_tree_build(pk_context *ctx, const pk_scene *s, light_set *ls)
{
    const pk_allocator *al = &ctx->alloc;
    const scene_view v = scene_view_of(s);
    size_t nt = 0, ni = 0;
    for (size_t i = 0; i < ls->n; i++) nt += light_has_place(ls, &v, i);
    ni = ls->n - nt;
    if (nt < 2) return PK_OK;
    lt_item *it = mem_realloc_array(al, NULL, nt, sizeof *it);
    ls->tree = mem_realloc_array(al, NULL, 2 * nt - 1, sizeof *ls->tree);
    ls->trail = mem_realloc_array(al, NULL, ls->n, sizeof *ls->trail);
    ls->inf = ni ? mem_realloc_array(al, NULL, ni, sizeof *ls->inf) : NULL;
    ls->inf_cdf = ni ? mem_realloc_array(al, NULL, ni, sizeof *ls->inf_cdf) : NULL;
    if (!it || !ls->tree || !ls->trail || (ni && (!ls->inf || !ls->inf_cdf))) {
        mem_free(al, it);
        return ctx_nomem(ctx);
    }
    memset(ls->trail, 0, ls->n * sizeof *ls->trail);
    size_t k = 0, j = 0;
    double p_tree = 0.0, p_inf = 0.0;
    for (size_t i = 0; i < ls->n; i++) {
        const light *l = &ls->lights[i];
        if (!light_has_place(ls, &v, i)) {
            ls->inf[j++] = (uint32_t)i;
            p_inf += (double)ls->pmf[i];
            ls->inf_cdf[j - 1] = (float)p_inf;
            continue;
        }
        lt_item *t = &it[k++];
        t->light = (uint32_t)i;
        lt_bounds *b = &t->b;
        b->two_sided = false;
        b->phi = (double)ls->pmf[i]; /* power, in shares of the whole */
        p_tree += b->phi;
        if (l->kind == LIGHT_TRIANGLE) {
            vec3 a, bb, c;
            scene_tri_verts(s, l->index, &a, &bb, &c);
            b->lo = v3_min(a, v3_min(bb, c)), b->hi = v3_max(a, v3_max(bb, c));
            b->axis = l->normal;
            b->cos_o = 1.0f, b->cos_e = 0.0f; /* one normal, light over the hemisphere */
            b->two_sided = s->materials[s->tris[l->index].material].two_sided;
            if (!(v3_len2(b->axis) > 0.0f)) b->axis = v3(0.0f, 0.0f, 1.0f), b->cos_o = -1.0f;
        } else if (l->kind == LIGHT_SPHERE) {
            const sphere *sp = &s->spheres[l->index];
            const vec3 r = v3s(sp->radius);
            b->lo = v3_sub(sp->center, r), b->hi = v3_add(sp->center, r);
            b->axis = v3(0.0f, 0.0f, 1.0f), b->cos_o = -1.0f, b->cos_e = 0.0f;
        } else {
            const point_light *pl = &s->lights[l->index];
            b->lo = b->hi = pl->position;
            if (v3_len2(pl->spot_dir) > 0.0f) {
                b->axis = pl->spot_dir, b->cos_o = 1.0f, b->cos_e = pl->cos_outer;
            } else {
                b->axis = v3(0.0f, 0.0f, 1.0f), b->cos_o = -1.0f, b->cos_e = 0.0f;
            }
        }
        t->c = v3_scale(v3_add(b->lo, b->hi), 0.5f);
    }
    for (size_t i = 0; i < ni; i++) ls->inf_cdf[i] = p_inf > 0.0 ? (float)((double)ls->inf_cdf[i] / p_inf) : (float)(i + 1) / (float)ni;
    if (ni) ls->inf_cdf[ni - 1] = 1.0f;
    ls->ninf = ni;
    ls->p_tree = ni ? (float)(p_tree / (p_tree + p_inf)) : 1.0f;
    lt_builder tb = {ls->tree, 0, ls->trail};
    lt_build(&tb, it, nt, 0, 0);
    ls->ntree = tb.nnodes;
    mem_free(al, it);
    return PK_OK;
}

pk_status light_set_build(pk_context *ctx, const pk_scene *s, const env_light *env, light_set *ls)
{
    memset(ls, 0, sizeof *ls);
    ls->env = ls->sun = -1;
    const pk_allocator *al = &ctx->alloc;
    size_t nsph = 0;
    for (size_t i = 0; i < s->nspheres; i++) nsph += emits(s->materials[s->spheres[i].material].ke);
    const size_t n = s->nemissive + nsph + s->nlights + (env->active ? 1 : 0) + (env->sun ? 1 : 0);
    ls->of_prim = mem_realloc_array(al, NULL, s->ntris + s->nspheres + 1, sizeof(int32_t));
    if (!ls->of_prim) return ctx_nomem(ctx);
    for (size_t i = 0; i < s->ntris + s->nspheres; i++) ls->of_prim[i] = -1;
    if (n == 0) return PK_OK;
    ls->lights = mem_realloc_array(al, NULL, n, sizeof(light));
    ls->cdf = mem_realloc_array(al, NULL, n, sizeof(float));
    ls->pmf = mem_realloc_array(al, NULL, n, sizeof(float));
    double *power = mem_realloc_array(al, NULL, n, sizeof(double));
    if (!ls->lights || !ls->cdf || !ls->pmf || !power) {
        mem_free(al, power);
        light_set_free(al, ls);
        return ctx_nomem(ctx);
    }
    memset(ls->lights, 0, n * sizeof(light)); /* the fields a kind leaves unused are zero */
    size_t k = 0;
    const scene_view view = scene_view_of(s);
    /* emitted flux (luminance): pi * L * area per emitting side; 4 pi I for points */
    for (size_t i = 0; i < s->nemissive; i++) {
        const uint32_t t = s->emissive[i];
        vec3 a, b, c;
        scene_tri_verts(s, t, &a, &b, &c);
        const material *m = &s->materials[s->tris[t].material];
        light *l = &ls->lights[k];
        *l = light_of_triangle(t, a, b, c, m);
        power[k] = emitted_luminance_tri(s, &view, m, t) * (double)l->area * (double)PK_PI * (m->two_sided ? 2.0 : 1.0);
        ls->of_prim[t] = (int32_t)k;
        k++;
    }
    for (size_t i = 0; i < s->nspheres; i++) {
        const sphere *sp = &s->spheres[i];
        const material *m = &s->materials[sp->material];
        if (!emits(m->ke)) continue;
        light *l = &ls->lights[k];
        l->kind = LIGHT_SPHERE;
        l->index = (uint32_t)i;
        l->area = 4.0f * PK_PI * sp->radius * sp->radius;
        l->normal = v3s(0.0f);
        power[k] = emitted_luminance(s, m) * (double)l->area * (double)PK_PI * (m->two_sided ? 2.0 : 1.0);
        ls->of_prim[s->ntris + i] = (int32_t)k;
        k++;
    }
    double radius = -1.0; /* of the scene's bounding sphere, for distant lights' power */
    for (size_t i = 0; i < s->nlights; i++) {
        const point_light *pl = &s->lights[i];
        light *l = &ls->lights[k];
        l->kind = LIGHT_POINT;
        l->index = (uint32_t)i;
        l->area = 0.0f;
        l->normal = v3s(0.0f);
        double flux = 4.0 * (double)PK_PI; /* per unit of intensity: the whole sphere */
        if (pl->distant) {
            if (radius < 0.0) radius = scene_radius(s);
            flux = (double)PK_PI * radius * radius; /* irradiance through the scene's disc */
        } else if (v3_len2(pl->spot_dir) > 0.0f) {
            /* the cone, its falloff counted as half the band between the cones */
            flux = 2.0 * (double)PK_PI * (1.0 - 0.5 * ((double)pl->cos_inner + (double)pl->cos_outer));
        }
        if (pl->map_kind != LIGHT_MAP_NONE) flux *= (double)pl->map_mean; /* the image's mean over the cone */
        power[k] = (double)fmaxf(v3_luminance(pl->intensity), 1e-6f) * fmax(flux, 1e-9);
        k++;
    }
    if (env->active) {
        ls->lights[k] = (light){.kind = LIGHT_ENV};
        power[k] = fmax(env->power_env, 1e-6);
        ls->env = (int32_t)k++;
    }
    if (env->sun) {
        ls->lights[k] = (light){.kind = LIGHT_SUN};
        power[k] = fmax(env->power_sun, 1e-6);
        ls->sun = (int32_t)k++;
    }
    double total = 0.0;
    for (size_t i = 0; i < n; i++) total += isfinite(power[i]) ? power[i] : 0.0;
    double acc = 0.0;
    for (size_t i = 0; i < n; i++) {
        /* lights of infinite power (overflowing areas) share what is left equally */
        const double p = total > 0.0 && isfinite(total) ? (isfinite(power[i]) ? power[i] / total : 0.0) : 1.0 / (double)n;
        ls->pmf[i] = (float)p;
        acc += p;
        ls->cdf[i] = (float)acc;
    }
    ls->cdf[n - 1] = 1.0f;
    ls->n = n;
    ls->power = total;
    mem_free(al, power);
    pk_status st = light_tree_build(ctx, s, ls);
    if (st != PK_OK) light_set_free(al, ls);
    return st;
}

void light_set_free(const pk_allocator *al, light_set *ls)
{
    mem_free(al, ls->lights);
    mem_free(al, ls->cdf);
    mem_free(al, ls->pmf);
    mem_free(al, ls->of_prim);
    mem_free(al, ls->tree);
    mem_free(al, ls->trail);
    mem_free(al, ls->inf);
    mem_free(al, ls->inf_cdf);
    memset(ls, 0, sizeof *ls);
    ls->env = ls->sun = -1;
}

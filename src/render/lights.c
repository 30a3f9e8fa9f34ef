/*
 * lights.c - building the light set (see lights.h).
 */
#include "lights.h"

#include <string.h>

static bool emits(vec3 ke) { return ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f; }

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
    size_t k = 0;
    /* emitted flux (luminance): pi * L * area per emitting side; 4 pi I for points */
    for (size_t i = 0; i < s->nemissive; i++) {
        const uint32_t t = s->emissive[i];
        vec3 a, b, c;
        scene_tri_verts(s, t, &a, &b, &c);
        const material *m = &s->materials[s->tris[t].material];
        light *l = &ls->lights[k];
        l->kind = LIGHT_TRIANGLE;
        l->index = t;
        l->area = 0.5f * v3_len(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        l->normal = tri_normal(a, b, c);
        power[k] = (double)fmaxf(v3_luminance(m->ke), 1e-6f) * (double)l->area * (double)PK_PI * (m->two_sided ? 2.0 : 1.0);
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
        power[k] = (double)fmaxf(v3_luminance(m->ke), 1e-6f) * (double)l->area * (double)PK_PI * (m->two_sided ? 2.0 : 1.0);
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
        power[k] = (double)fmaxf(v3_luminance(pl->intensity), 1e-6f) * fmax(flux, 1e-9);
        k++;
    }
    if (env->active) {
        ls->lights[k] = (light){LIGHT_ENV, 0, 0.0f, v3s(0.0f)};
        power[k] = fmax(env->power_env, 1e-6);
        ls->env = (int32_t)k++;
    }
    if (env->sun) {
        ls->lights[k] = (light){LIGHT_SUN, 0, 0.0f, v3s(0.0f)};
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
    return PK_OK;
}

void light_set_free(const pk_allocator *al, light_set *ls)
{
    mem_free(al, ls->lights);
    mem_free(al, ls->cdf);
    mem_free(al, ls->pmf);
    mem_free(al, ls->of_prim);
    memset(ls, 0, sizeof *ls);
    ls->env = ls->sun = -1;
}

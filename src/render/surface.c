/*
 * surface.c - surface reconstruction at a hit: interpolated vertex normals
 * (flipped to the face's side), sphere normals, sides.
 */
#include "surface.h"

surface surface_at(const pk_scene *s, const ray *r, const hit *h)
{
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

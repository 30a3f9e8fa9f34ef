/*
 * accel.c - chooses an acceleration structure by kind, and the primitive set
 * shared by the scalar accelerators (none, midpoint).
 */
#include "accel.h"

#include "../math/tri.h"

#include <string.h>

pk_status accel_create(pk_context *ctx, pk_accel_kind kind, const accel_input *in, accel **out)
{
    *out = NULL;
    if (in->ntris + in->nspheres >= (size_t)UINT32_MAX)
        return ctx_error(ctx, PK_ERR_LIMIT, "too many primitives (%zu)", in->ntris + in->nspheres);
    double t0 = time_now();
    pk_status st;
    switch (kind) {
    case PK_ACCEL_NONE: st = accel_none_create(ctx, in, out); break;
    case PK_ACCEL_MIDPOINT: st = accel_midpoint_create(ctx, in, out); break;
    case PK_ACCEL_DEFAULT:
    case PK_ACCEL_BVH: st = accel_bvh_create(ctx, in, out); break;
    case PK_ACCEL_EMBREE: st = accel_embree_create(ctx, in, out); break;
    default: return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown accelerator %d", (int)kind);
    }
    if (st == PK_OK && *out) {
        (*out)->ntris = in->ntris;
        (*out)->nspheres = in->nspheres;
        if ((*out)->info.build_ms <= 0.0) (*out)->info.build_ms = (time_now() - t0) * 1e3;
    }
    return st;
}

void accel_destroy(accel *a)
{
    if (a) a->ops->destroy(a);
}

void accel_intersect_many(const accel *a, const ray *r, hit *h, size_t n, bool any_hit, accel_counters *c)
{
    if (a->ops->intersect_packet) {
        a->ops->intersect_packet(a, r, h, n, any_hit, c);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        if (any_hit)
            a->ops->occluded(a, &r[i], &h[i], c);
        else
            a->ops->intersect(a, &r[i], &h[i], c);
    }
}

pk_status prim_set_init(pk_context *ctx, const pk_allocator *a, const accel_input *in, prim_set *ps)
{
    memset(ps, 0, sizeof *ps);
    if (in->ntris) {
        ps->verts = mem_realloc_array(a, NULL, in->ntris, 3 * sizeof *ps->verts); /* overflow-checked */
        if (!ps->verts) return ctx_nomem(ctx);
        memcpy(ps->verts, in->verts, in->ntris * 3 * sizeof *ps->verts);
    }
    if (in->nspheres) {
        ps->spheres = mem_realloc_array(a, NULL, in->nspheres, sizeof *ps->spheres);
        if (!ps->spheres) {
            prim_set_free(a, ps);
            return ctx_nomem(ctx);
        }
        memcpy(ps->spheres, in->spheres, in->nspheres * sizeof *ps->spheres);
    }
    ps->ntris = (uint32_t)in->ntris;
    ps->nspheres = (uint32_t)in->nspheres;
    return PK_OK;
}

void prim_set_free(const pk_allocator *a, prim_set *ps)
{
    mem_free(a, ps->verts);
    mem_free(a, ps->spheres);
    memset(ps, 0, sizeof *ps);
}

bool prim_bounds(const prim_set *ps, uint32_t id, aabb *box)
{
    if (id < ps->ntris) {
        const vec3 *p = ps->verts + 3 * (size_t)id;
        if (tri_is_degenerate(p[0], p[1], p[2])) return false;
        *box = aabb_grow(aabb_grow(aabb_grow(aabb_empty(), p[0]), p[1]), p[2]);
        return true;
    }
    const accel_sphere *s = &ps->spheres[id - ps->ntris];
    if (!v3_finite(s->center) || !(s->radius > 0.0f) || !isfinite(s->radius)) return false;
    box->lo = v3_sub(s->center, v3s(s->radius));
    box->hi = v3_add(s->center, v3s(s->radius));
    return true;
}

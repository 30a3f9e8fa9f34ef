/*
 * prim_set.c - the copy of the primitives that the scalar accelerators
 * (none, midpoint) test, and their bounds.
 */
#include "accel.h"

#include "../math/tri.h"

#include <string.h>

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

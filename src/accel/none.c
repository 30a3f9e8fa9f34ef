/*
 * none.c - no acceleration: every ray tests every primitive. The reference
 * that every other accelerator must agree with.
 */
#include "accel.h"

typedef struct accel_none {
    accel base;
    prim_set ps;
    uint32_t *ids;  /* the primitives that can be hit, ascending */
    uint32_t nids;
} accel_none;

static void none_destroy(accel *a)
{
    accel_none *n = (accel_none *)a;
    const pk_allocator *al = a->alloc;
    prim_set_free(al, &n->ps);
    mem_free(al, n->ids);
    mem_free(al, n);
}

static bool none_intersect(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    const accel_none *n = (const accel_none *)a;
    ray_pre rp = ray_prepare(r);
    hit_clear(h);
    h->t = r->tmax;
    for (uint32_t i = 0; i < n->nids; i++) prim_test(&n->ps, n->ids[i], &rp, h);
    if (c) c->tests += n->nids;
    if (h->prim == PK_NO_HIT) {
        h->t = INFINITY;
        return false;
    }
    return true;
}

static bool none_occluded(const accel *a, const ray *r, hit *out, accel_counters *c)
{
    const accel_none *n = (const accel_none *)a;
    ray_pre rp = ray_prepare(r);
    hit h;
    hit_clear(&h);
    h.t = r->tmax;
    for (uint32_t i = 0; i < n->nids; i++) {
        if (prim_test(&n->ps, n->ids[i], &rp, &h)) {
            if (c) c->tests += i + 1;
            if (out) *out = h;
            return true;
        }
    }
    if (c) c->tests += n->nids;
    if (out) hit_clear(out);
    return false;
}

static const accel_ops none_ops = {none_destroy, none_intersect, none_occluded, NULL, NULL, NULL};

pk_status accel_none_create(pk_context *ctx, const accel_input *in, accel **out)
{
    *out = NULL;
    accel_none *n = mem_calloc(&ctx->alloc, 1, sizeof *n);
    if (!n) return ctx_nomem(ctx);
    n->base.ops = &none_ops;
    n->base.alloc = &ctx->alloc;
    if (prim_set_init(ctx, &ctx->alloc, in, &n->ps) != PK_OK) {
        mem_free(&ctx->alloc, n);
        return PK_ERR_NOMEM;
    }
    size_t total = in->ntris + in->nspheres;
    if (total) {
        n->ids = mem_realloc_array(&ctx->alloc, NULL, total, sizeof *n->ids);
        if (!n->ids) {
            none_destroy(&n->base);
            return ctx_nomem(ctx);
        }
    }
    for (uint32_t id = 0; id < total; id++) {
        aabb b;
        if (prim_bounds(&n->ps, id, &b)) n->ids[n->nids++] = id;
    }
    n->base.info.name = "none";
    n->base.info.primitives = n->nids;
    n->base.info.bytes = sizeof *n + total * sizeof *n->ids + in->ntris * 3 * sizeof(vec3) +
                         in->nspheres * sizeof(accel_sphere);
    *out = &n->base;
    return PK_OK;
}

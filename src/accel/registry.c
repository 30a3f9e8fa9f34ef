/*
 * registry.c - chooses an acceleration structure by kind; packets or single
 * rays for a batch.
 */
#include "accel.h"

pk_status accel_create(pk_context *ctx, pk_accel_kind kind, const accel_input *in, accel **out)
{
    return accel_create_instanced(ctx, kind, in, NULL, out);
}

pk_status accel_create_instanced(pk_context *ctx, pk_accel_kind kind, const accel_input *in, const accel_instances *ti,
                                 accel **out)
{
    *out = NULL;
    if (in->ntris + in->nspheres >= (size_t)UINT32_MAX)
        return ctx_error(ctx, PK_ERR_LIMIT, "too many primitives (%zu)", in->ntris + in->nspheres);
    double t0 = time_now();
    pk_status st;
    if (ti && ti->ninstances) {
        if (kind == PK_ACCEL_CUDA)
            return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                             "accelerator 'cuda' traces flattened triangles only: the scene keeps %zu instances "
                             "(config scene.instances=flatten flattens them)", ti->ninstances);
        if (kind == PK_ACCEL_EMBREE) st = accel_embree_create_instanced(ctx, in, ti, out);
        else st = accel_instances_create(ctx, kind, in, ti, out);
    } else
    switch (kind) {
    case PK_ACCEL_NONE: st = accel_none_create(ctx, in, out); break;
    case PK_ACCEL_MIDPOINT: st = accel_midpoint_create(ctx, in, out); break;
    case PK_ACCEL_DEFAULT:
    case PK_ACCEL_BVH: st = accel_bvh_create(ctx, in, out); break;
    case PK_ACCEL_EMBREE: st = accel_embree_create(ctx, in, out); break;
    case PK_ACCEL_CUDA: st = accel_cuda_create(ctx, in, out); break;
    default: return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown accelerator %d", (int)kind);
    }
    if (st == PK_OK && *out) {
        (*out)->ntris = in->ntris;
        (*out)->nspheres = in->nspheres;
        if ((*out)->info.build_ms <= 0.0) (*out)->info.build_ms = (time_now() - t0) * 1e3;
    }
    return st;
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

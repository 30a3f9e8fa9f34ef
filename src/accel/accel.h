/*
 * accel.h - the interface every acceleration structure implements.
 *
 * An accelerator is built over a flat list of primitives: triangles
 * 0..ntris-1 (three vertices each, in file order, degenerate ones included but
 * never hit) followed by spheres ntris..ntris+nspheres-1. It knows nothing of
 * materials. All accelerators return the same closest hit (see geom.h).
 */
#ifndef PK_ACCEL_H
#define PK_ACCEL_H

#include "../math/xform.h"
#include "geom.h"

typedef struct accel_sphere {
    vec3 center;
    float radius;
} accel_sphere;

/* An object-space mesh that instances place: 3*ntris vertices. */
typedef struct accel_mesh {
    const vec3 *verts;
    size_t ntris;
} accel_mesh;

/* A mesh placed by to_world (finite, affine, invertible); its triangle k is
 * primitive prim0 + k. prim0 ascends with the instance, past the triangles
 * and spheres (prim0 >= ntris + nspheres), and every instance's numbers stay
 * below PK_NO_HIT. */
typedef struct accel_instance {
    xform to_world;
    uint32_t mesh;
    uint32_t prim0;
} accel_instance;

/* Borrowed by the builder for the duration of accel_create only. */
typedef struct accel_input {
    const vec3 *verts;           /* 3*ntris vertices: triangle k is verts[3k..3k+2] */
    size_t ntris;
    const accel_sphere *spheres;
    size_t nspheres;
    int threads;                 /* build threads, >= 1 */
} accel_input;

/* Instances (instances.c, Embree's instance geometry): a two-level
 * structure, one bottom level per mesh and a top level over the instances'
 * world boxes. A ray meets a mesh in its object space: the origin and
 * direction go through the instance's inverse transform and the direction
 * is not renormalised, so t is the world ray's parameter and hits compare
 * across instances. Borrowed like accel_input. */
typedef struct accel_instances {
    const accel_mesh *meshes;
    size_t nmeshes;
    const accel_instance *instances;
    size_t ninstances;
} accel_instances;

/* Counters are per thread; NULL means "do not count" and must cost nothing. */
typedef struct accel_counters {
    uint64_t tests; /* ray-primitive tests */
    uint64_t nodes; /* nodes visited */
} accel_counters;

typedef struct accel accel;

typedef struct accel_ops {
    void (*destroy)(accel *a);
    /* Closest hit in [r->tmin, r->tmax]; fills *h (cleared on a miss). */
    bool (*intersect)(const accel *a, const ray *r, hit *h, accel_counters *c);
    /* Any hit in [r->tmin, r->tmax]? h (may be NULL) receives the hit found
     * (not necessarily the closest), or is cleared on a miss. */
    bool (*occluded)(const accel *a, const ray *r, hit *h, accel_counters *c);
    /* Optional (may be NULL): n coherent rays at once; results as intersect.
     * any_hit: only occlusion (h[i].t finite on a hit). */
    void (*intersect_packet)(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                             accel_counters *c);
    /* Optional (may be NULL): a whole batch at once (a device accelerator);
     * accel_trace_batch uses it when present. flags as PK_TRACE_*. On a
     * failure the error is latched in the context the accelerator was
     * created with and every hit is a miss. */
    void (*trace_batch)(const accel *a, const ray *rays, hit *hits, size_t n, unsigned flags,
                        pk_trace_counters *counters);
    /* Optional: what a device accelerator reports (pk_accel_get_device_info). */
    void (*device_info)(const accel *a, pk_accel_device_info *info);
} accel_ops;

/* Every accelerator starts with this header. */
struct accel {
    const accel_ops *ops;
    const pk_allocator *alloc;
    pk_accel_info info;      /* name, build_ms, nodes, leaves, bytes, sah_cost */
    const char *isa;         /* the CPU kernels' instruction set where there is a choice, else NULL */
    size_t ntris, nspheres;
};

/* Builds kind over in. Errors (NOMEM, UNSUPPORTED) are latched in ctx. */
PK_HIDDEN pk_status accel_create(pk_context *ctx, pk_accel_kind kind, const accel_input *in, accel **out);
/* The same with instances placed too (ti NULL or without instances:
 * accel_create). The GPU accelerator refuses instances. */
PK_HIDDEN pk_status accel_create_instanced(pk_context *ctx, pk_accel_kind kind, const accel_input *in,
                                           const accel_instances *ti, accel **out);
/* Inline, so that an accelerator built on another (cuda.c on the BVH)
 * needs nothing of registry.c. NULL is ignored. */
static inline void accel_destroy(accel *a)
{
    if (a) a->ops->destroy(a);
}

static inline bool accel_intersect(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    return a->ops->intersect(a, r, h, c);
}
static inline bool accel_occluded(const accel *a, const ray *r, accel_counters *c)
{
    return a->ops->occluded(a, r, NULL, c);
}
/* Packets when the accelerator has them, single rays otherwise. */
PK_HIDDEN void accel_intersect_many(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                                    accel_counters *c);

/* Traces n rays in parallel with up to threads threads (0 = all); flags as
 * PK_TRACE_* (any-hit, coherent packets); counters may be NULL (trace.c). */
PK_HIDDEN void accel_trace_batch(const accel *a, const ray *rays, hit *hits, size_t n, int threads,
                                 unsigned flags, pk_trace_counters *counters);

/* Constructors, one per file (builders latch their own errors). */
PK_HIDDEN pk_status accel_none_create(pk_context *ctx, const accel_input *in, accel **out);
PK_HIDDEN pk_status accel_midpoint_create(pk_context *ctx, const accel_input *in, accel **out);
PK_HIDDEN pk_status accel_bvh_create(pk_context *ctx, const accel_input *in, accel **out);
/* The wide BVH with another cost model for collapsing the binary tree (the
 * GPU's): a wide node visit costs `node` leaf tests, a leaf test covers
 * `lanes` primitives (a leaf of n costs ceil(n / lanes) tests), leaves hold
 * at most leaf_max primitives (4..16). NULL: the CPU's (accel_bvh_create). */
typedef struct bvh_costs {
    float node;
    uint32_t lanes, leaf_max;
} bvh_costs;
PK_HIDDEN pk_status accel_bvh_create_costs(pk_context *ctx, const accel_input *in, const bvh_costs *costs,
                                           accel **out);
PK_HIDDEN pk_status accel_embree_create(pk_context *ctx, const accel_input *in, accel **out);
/* The two-level structure of kind (none, midpoint, bvh) for an input with
 * instances: kind over the world's triangles and spheres, kind over each
 * mesh, a binary SAH tree over the instances (kind none: every instance is
 * tested, the brute-force reference). instances.c. */
PK_HIDDEN pk_status accel_instances_create(pk_context *ctx, pk_accel_kind kind, const accel_input *in,
                                           const accel_instances *ti, accel **out);
/* Embree with its instance geometry: one Embree scene per mesh (embree.c). */
PK_HIDDEN pk_status accel_embree_create_instanced(pk_context *ctx, const accel_input *in, const accel_instances *ti,
                                                  accel **out);
/* Invariants of a two-level structure (tests): its top level holds every
 * instance once, boxes contain their children and their instances' placed
 * meshes; the bottom levels pass their own checker (bvh_check for bvh).
 * False with a reason when broken, or when a is not two-level. */
PK_HIDDEN bool accel_instances_check(const accel *a, char *why, size_t n);
/* Can ctx's Embree library (config embree.library; ctx NULL: the default) be loaded? */
PK_HIDDEN bool accel_embree_available(const pk_context *ctx);
/* The GPU accelerator (cuda.c): built in? (a driver and a device are looked
 * for only when one is created) */
PK_HIDDEN pk_status accel_cuda_create(pk_context *ctx, const accel_input *in, accel **out);
PK_HIDDEN bool accel_cuda_built(void);
/* The same with the reference kernels (gpu_trace_v0), for the tests. */
PK_HIDDEN pk_status accel_cuda_create_reference(pk_context *ctx, const accel_input *in, accel **out);
/* The device addresses of a CUDA accelerator's structure (bvh_gpu.h's
 * nodes and triangle records), for other kernels that trace in the same
 * process (the GPU path tracer): valid while a lives. */
PK_HIDDEN void accel_cuda_bvh(const accel *a, uint64_t *nodes, uint64_t *tris);
/* When Embree is not available: latches why (PK_ERR_UNSUPPORTED) and returns it. */
PK_HIDDEN pk_status accel_embree_unavailable(pk_context *ctx);
/* Invariant checkers (tests): false with a reason when the structure is broken. */
PK_HIDDEN bool midpoint_check(const accel *a, char *why, size_t n);

/* A copy of the primitives for the scalar accelerators (none, midpoint). */
typedef struct prim_set {
    vec3 *verts;              /* 3 per triangle */
    accel_sphere *spheres;
    uint32_t ntris, nspheres;
} prim_set;

PK_HIDDEN pk_status prim_set_init(pk_context *ctx, const pk_allocator *a, const accel_input *in, prim_set *ps);
PK_HIDDEN void prim_set_free(const pk_allocator *a, prim_set *ps);
/* Bounds of primitive id; false when it can never be hit (degenerate). */
PK_HIDDEN bool prim_bounds(const prim_set *ps, uint32_t id, aabb *box);

/* Tests primitive id; updates *h when it is a better hit (closest-hit rule). */
static inline bool prim_test(const prim_set *ps, uint32_t id, const ray_pre *r, hit *h)
{
    float t, u, v;
    bool ok;
    if (id < ps->ntris) {
        const vec3 *p = ps->verts + 3 * (size_t)id;
        ok = tri_intersect(r, p[0], p[1], p[2], h->t, &t, &u, &v);
    } else {
        const accel_sphere *s = &ps->spheres[id - ps->ntris];
        ok = sphere_intersect(r, s->center, s->radius, h->t, &t, &u, &v);
    }
    if (ok && hit_better(t, id, h)) {
        h->t = t;
        h->prim = id;
        h->u = u;
        h->v = v;
        return true;
    }
    return false;
}

#endif

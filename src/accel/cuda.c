/*
 * cuda.c - the GPU as an accelerator (--accel cuda): the wide BVH collapsed
 * for the GPU (accel_bvh_create_costs) and converted to the layout of
 * bvh_gpu.h, copied to the device, and batches of rays traced there by the
 * kernels of cuda/trace.cu, one thread per ray, with the traversal functions
 * of bvh_gpu.h. Single rays (the intersect and occluded operations) run the
 * very same functions on the host.
 *
 * The kernels are compiled by nvcc into a fat binary (machine code for sm_80
 * and sm_90, PTX for later GPUs) that the build embeds as a byte array in
 * the kernels' module (device/cuda_kernels.h, "trace"); the device itself (driver, context, memory,
 * launches) is device/cuda.h's. Without CUDA at build time (PK_HAVE_CUDA 0)
 * creating one is refused.
 */
#include "accel.h"
#include "bvh_gpu.h"
#include "device/cuda.h"

#include <stdio.h>
#include <string.h>

#if defined(PK_HAVE_CUDA) && PK_HAVE_CUDA
#include <omp.h>
#include <pthread.h>

bool accel_cuda_built(void) { return true; }

#define WHO "accelerator 'cuda'"

/* Ray and hit buffers hold at most this many rays; longer batches go in chunks. */
#define CHUNK_RAYS ((size_t)1 << 24)

/* The binary tree collapsed for the GPU: a node visit costs N triangle
 * tests, N = 4 (the fastest on the H100; docs/gpu.md). */
#define GPU_TREE_NODE_COST 4.0f

/* The kernels of cuda/trace.cu: the default (pk_trace_*: GPU_TEST_WIDE,
 * one thread per ray) and the reference (pk_trace_*_ref: gpu_trace_v0, the
 * first kernel, which the tests hold the others to). */
static const char *const kernel_names[3][2] = {{"pk_trace_closest", "pk_trace_any"},
                                               {"pk_trace_closest_ref", "pk_trace_any_ref"},
                                               {"pk_trace_closest_ordered", "pk_trace_any_ordered"}};

/* Invariants:
 *  1. layout is the converted BVH; d_nodes and d_tris hold copies of its
 *     arrays on the device (structure_bytes in all);
 *  2. d_rays and d_hits hold room for cap rays (0: not allocated yet);
 *  3. lock serialises the batches (the buffers and the device's marks are
 *     shared). */
typedef struct cuda_accel {
    accel base;
    pk_context *ctx;          /* where batch errors are latched */
    gpu_layout layout;
    cuda_device *dev;
    cuda_kernel k_closest, k_any;
    uint64_t d_nodes, d_tris, d_rays, d_hits;
    size_t cap;
    pthread_mutex_t lock;
    pk_accel_device_info stats;
} cuda_accel;

static void cuda_destroy(accel *a)
{
    cuda_accel *c = (cuda_accel *)a;
    const pk_allocator *al = a->alloc;
    if (c->dev) {
        cuda_device_free(c->dev, c->d_nodes);
        cuda_device_free(c->dev, c->d_tris);
        cuda_device_free(c->dev, c->d_rays);
        cuda_device_free(c->dev, c->d_hits);
        cuda_device_close(c->dev);
    }
    pthread_mutex_destroy(&c->lock);
    gpu_layout_free(al, &c->layout);
    mem_free(al, c);
}

static bool cuda_intersect(const accel *a, const ray *r, hit *h, accel_counters *cnt)
{
    const cuda_accel *c = (const cuda_accel *)a;
    gpu_counters g = {0, 0};
    bool found = gpu_trace(c->layout.nodes, c->layout.tris, (const pk_ray *)r, false, (pk_hit *)h, cnt ? &g : NULL);
    if (cnt) cnt->nodes += g.nodes, cnt->tests += g.tests;
    return found;
}

static bool cuda_occluded(const accel *a, const ray *r, hit *h, accel_counters *cnt)
{
    const cuda_accel *c = (const cuda_accel *)a;
    gpu_counters g = {0, 0};
    pk_hit tmp;
    bool found = gpu_trace(c->layout.nodes, c->layout.tris, (const pk_ray *)r, true, h ? (pk_hit *)h : &tmp,
                           cnt ? &g : NULL);
    if (cnt) cnt->nodes += g.nodes, cnt->tests += g.tests;
    return found;
}

/* Device buffers for up to want rays; latches an error when they do not fit. */
static pk_status ensure_buffers(cuda_accel *c, size_t want)
{
    if (want <= c->cap) return PK_OK;
    cuda_device_free(c->dev, c->d_rays);
    cuda_device_free(c->dev, c->d_hits);
    c->d_rays = c->d_hits = 0;
    c->cap = 0;
    c->stats.device_bytes = c->stats.structure_bytes;
    const size_t need = want * (sizeof(pk_ray) + sizeof(pk_hit));
    char what[48];
    snprintf(what, sizeof what, "%zu rays", want);
    pk_status st = cuda_device_check_room(c->dev, need, what);
    if (st == PK_OK) st = cuda_device_alloc(c->dev, NULL, want * sizeof(pk_ray), what, &c->d_rays);
    if (st == PK_OK) st = cuda_device_alloc(c->dev, NULL, want * sizeof(pk_hit), what, &c->d_hits);
    if (st != PK_OK) {
        cuda_device_free(c->dev, c->d_rays);
        c->d_rays = 0;
        return st;
    }
    c->cap = want;
    c->stats.device_bytes = c->stats.structure_bytes + need;
    return PK_OK;
}

static void cuda_trace_batch(const accel *a, const ray *rays, hit *hits, size_t n, unsigned flags,
                             pk_trace_counters *counters)
{
    cuda_accel *c = (cuda_accel *)(uintptr_t)a; /* the buffers and timings change; lock serialises */
    const bool any = (flags & PK_TRACE_ANY_HIT) != 0;
    pthread_mutex_lock(&c->lock);
    c->stats.rays_upload_ms = c->stats.kernel_ms = c->stats.download_ms = 0.0;
    const size_t chunk = n < CHUNK_RAYS ? n : CHUNK_RAYS;
    pk_status st = ensure_buffers(c, chunk);
    cuda_device *d = c->dev;
    for (size_t lo = 0; st == PK_OK && lo < n; lo += chunk) {
        size_t m = n - lo < chunk ? n - lo : chunk;
        unsigned count = (unsigned)m;
        void *params[] = {&c->d_nodes, &c->d_tris, &c->d_rays, &c->d_hits, &count};
        const unsigned block = 128;
        const unsigned grid = (unsigned)((m + block - 1) / block);
        const char *what = "copying rays to the device";
        if ((st = cuda_device_mark(d, 0, what)) != PK_OK ||
            (st = cuda_device_copy(d, (void *)(uintptr_t)(rays + lo), c->d_rays, m * sizeof(pk_ray), true, what)) !=
                PK_OK ||
            (st = cuda_device_mark(d, 1, what)) != PK_OK)
            break;
        what = "the traversal kernel";
        if ((st = cuda_device_launch(d, any ? &c->k_any : &c->k_closest, grid, block, params, what)) != PK_OK ||
            (st = cuda_device_mark(d, 2, what)) != PK_OK)
            break;
        what = "copying hits from the device";
        if ((st = cuda_device_copy(d, hits + lo, c->d_hits, m * sizeof(pk_hit), false, what)) != PK_OK ||
            (st = cuda_device_mark(d, 3, what)) != PK_OK || (st = cuda_device_wait(d, 3, what)) != PK_OK)
            break;
        c->stats.rays_upload_ms += cuda_device_elapsed(d, 0, 1);
        c->stats.kernel_ms += cuda_device_elapsed(d, 1, 2);
        c->stats.download_ms += cuda_device_elapsed(d, 2, 3);
    }
    pthread_mutex_unlock(&c->lock);
    if (st != PK_OK) {
        for (size_t i = 0; i < n; i++) hit_clear(&hits[i]);
        return;
    }
    if (counters) {
        /* the device does not count: the same traversal counts on the host */
        const long nn = (long)n;
        uint64_t nodes = 0, tests = 0;
#pragma omp parallel for schedule(dynamic, 1024) reduction(+ : nodes, tests)
        for (long i = 0; i < nn; i++) {
            gpu_counters g = {0, 0};
            pk_hit h;
            gpu_trace(c->layout.nodes, c->layout.tris, (const pk_ray *)&rays[i], any, &h, &g);
            nodes += g.nodes;
            tests += g.tests;
        }
        counters->nodes_visited += nodes;
        counters->intersection_tests += tests;
    }
}

static void cuda_device_info(const accel *a, pk_accel_device_info *info)
{
    cuda_accel *c = (cuda_accel *)(uintptr_t)a;
    pthread_mutex_lock(&c->lock);
    *info = c->stats;
    pthread_mutex_unlock(&c->lock);
}

static const accel_ops cuda_ops = {
    .destroy = cuda_destroy,
    .intersect = cuda_intersect,
    .occluded = cuda_occluded,
    .intersect_packet = NULL,
    .trace_batch = cuda_trace_batch,
    .device_info = cuda_device_info,
};

/* The device side: the device with the traversal kernels, the structure on it. */
static pk_status cuda_setup(pk_context *ctx, cuda_accel *c, int kernel)
{
    pk_status st = cuda_device_open(ctx, WHO, "trace", &c->dev);
    if (st != PK_OK) return st;
    snprintf(c->stats.device, sizeof c->stats.device, "%s", cuda_device_name(c->dev));
    if ((st = cuda_device_kernel(c->dev, kernel_names[kernel][0], &c->k_closest)) != PK_OK ||
        (st = cuda_device_kernel(c->dev, kernel_names[kernel][1], &c->k_any)) != PK_OK)
        return st;
    const size_t bn = c->layout.nnodes * sizeof(gpu_node), bt = (c->layout.ntris ? c->layout.ntris : 1) * sizeof(gpu_tri);
    double t0 = time_now();
    /* room for both first (the message gives the structure's whole size) */
    st = cuda_device_check_room(c->dev, bn + bt, "the BVH");
    if (st == PK_OK) st = cuda_device_alloc(c->dev, c->layout.nodes, bn, "the BVH", &c->d_nodes);
    if (st == PK_OK) st = cuda_device_alloc(c->dev, c->layout.tris, bt, "the BVH", &c->d_tris);
    if (st != PK_OK) return st;
    c->stats.upload_ms = (time_now() - t0) * 1e3;
    c->stats.structure_bytes = c->stats.device_bytes = bn + bt;
    return PK_OK;
}

static pk_status cuda_create(pk_context *ctx, const accel_input *in, int kernel, accel **out)
{
    *out = NULL;
    if (in->nspheres)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, WHO ": the GPU traces triangles only (the scene has "
                                                  "%zu sphere%s)", in->nspheres, in->nspheres == 1 ? "" : "s");
    const double t0 = time_now();
    /* cuda.leaf: the largest leaf of the GPU's tree (16, 8 or 4 triangles) */
    const uint32_t leaf_max = ctx->config.cuda_leaf == 2 ? 4u : ctx->config.cuda_leaf == 1 ? 8u : GPU_LEAF_MAX;
    const bvh_costs costs = {GPU_TREE_NODE_COST, 1, leaf_max};
    accel *b = NULL;
    pk_status st = accel_bvh_create_costs(ctx, in, &costs, &b);
    if (st != PK_OK) return st;
    const pk_allocator *al = &ctx->alloc;
    cuda_accel *c = mem_calloc(al, 1, sizeof *c);
    if (!c) {
        accel_destroy(b);
        return ctx_nomem(ctx);
    }
    pthread_mutex_init(&c->lock, NULL);
    c->base.ops = &cuda_ops;
    c->base.alloc = al;
    c->ctx = ctx;
    b->ntris = in->ntris; /* (accel_create sets these after the constructor) */
    b->nspheres = in->nspheres;
    st = gpu_layout_build(ctx, al, b, &c->layout);
    c->base.info = b->info;
    accel_destroy(b);
    if (st != PK_OK) {
        cuda_destroy(&c->base);
        return st;
    }
    c->base.info.name = "cuda";
    c->base.info.build_ms = (time_now() - t0) * 1e3;
    c->base.info.bytes = c->layout.nnodes * sizeof(gpu_node) + c->layout.ntris * sizeof(gpu_tri);
    /* cuda.traversal=ordered: the ordered kernels (cuda/trace.cu), where
     * their stack suffices for the tree */
    if (kernel == 0 && ctx->config.cuda_traversal == 1) {
        if (gpu_layout_ordered(&c->layout))
            kernel = 2;
        else
            ctx_warn(ctx, WHO ": cuda.traversal=ordered needs a stack of %u entries (at most %d): traversing sorted",
                     c->layout.ordered_need, GPU_OSTACK);
    }
    if ((st = cuda_setup(ctx, c, kernel)) != PK_OK) {
        cuda_destroy(&c->base);
        return st;
    }
    *out = &c->base;
    return PK_OK;
}

pk_status accel_cuda_create(pk_context *ctx, const accel_input *in, accel **out)
{
    return cuda_create(ctx, in, 0, out);
}

pk_status accel_cuda_create_reference(pk_context *ctx, const accel_input *in, accel **out)
{
    return cuda_create(ctx, in, 1, out);
}

void accel_cuda_bvh(const accel *a, uint64_t *nodes, uint64_t *tris)
{
    const cuda_accel *c = (const cuda_accel *)a;
    *nodes = c->d_nodes;
    *tris = c->d_tris;
}

#else /* no CUDA at build time */

bool accel_cuda_built(void) { return false; }

pk_status accel_cuda_create(pk_context *ctx, const accel_input *in, accel **out)
{
    (void)in;
    *out = NULL;
    return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                     "accelerator 'cuda' is not available in this build (configure where nvcc is, with -DPK_WITH_CUDA=ON)");
}

pk_status accel_cuda_create_reference(pk_context *ctx, const accel_input *in, accel **out)
{
    return accel_cuda_create(ctx, in, out);
}

void accel_cuda_bvh(const accel *a, uint64_t *nodes, uint64_t *tris)
{
    (void)a;
    *nodes = *tris = 0;
}

#endif

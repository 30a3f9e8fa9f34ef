/*
 * wavefront.cu - the wavefront path tracer's stages as GPU kernels (see
 * src/render/wavefront.h): one kernel per stage, one thread per queue
 * entry, each running the stage function the CPU's wavefront runs
 * (wf_stage_*), with rays traced by gpu_trace_box as in path.cu. The
 * queues are filled with atomics (their order changes no sample: a
 * sample's radiance depends only on its pixel and index). The pool (wf_pool)
 * holds device arrays; queue lengths and counters live in device memory
 * (wf_counts), so the launch sequence needs no copy back until the pool
 * is empty.
 *
 * Launch sequence for samples c0..c1-1 (wf_counts.next = c0, end = c1),
 * until a round leaves nrq at 0:
 *   pk_wf_assign (one thread per slot), pk_wf_generate, pk_wf_intersect,
 *   pk_wf_shade, pk_wf_shadow, pk_wf_finish (one thread per slot: entries
 *   past nrq or nsq return at once).
 */
#include "accel/bvh_gpu.h"
#include "render/path.h"

#ifndef PK_PATH_BOX
#define PK_PATH_BOX GPU_TEST_FMA
#endif

/* closest and any hit on the device BVH of the path tracer's copy */
static __device__ __forceinline__ bool wf_gpu_trace(const path_tracer *pt, const ray *r, hit *h, bool any)
{
    return gpu_trace_box((const gpu_node *)pt->gpu_nodes, (const gpu_tri *)pt->gpu_tris, (const pk_ray *)r, any,
                         (pk_hit *)h, NULL, PK_PATH_BOX);
}
static __device__ __forceinline__ bool wf_gpu_occluded(const path_tracer *pt, const ray *r)
{
    hit h;
    return wf_gpu_trace(pt, r, &h, true);
}
#define PATH_TRACE(pt, t, r, h) wf_gpu_trace((pt), (r), (h), false)
#define PATH_OCCLUDED(pt, t, r) wf_gpu_occluded((pt), (r))
#include "render/wavefront.h"

/* Queue lengths and counters of a round, in device memory. */
typedef struct wf_counts {
    unsigned long long next, end; /* the next sample to start, the chunk's end */
    int nrq, nsq;
    unsigned long long rays[3];   /* camera, bounce, shadow */
} wf_counts;

static __device__ __forceinline__ void wf_thread_init(path_thread *t)
{
    t->rays_camera = t->rays_bounce = t->rays_shadow = 0;
    t->cp = NULL;
}

/* the thread's rays into the counters: one atomic per warp and counter */
static __device__ __forceinline__ void wf_thread_count(const path_thread *t, wf_counts *c)
{
    unsigned long long c0 = t->rays_camera, c1 = t->rays_bounce, c2 = t->rays_shadow;
    for (int off = 16; off > 0; off >>= 1) {
        c0 += __shfl_down_sync(0xffffffffu, c0, off);
        c1 += __shfl_down_sync(0xffffffffu, c1, off);
        c2 += __shfl_down_sync(0xffffffffu, c2, off);
    }
    if ((threadIdx.x & 31) == 0) {
        if (c0) atomicAdd(&c->rays[0], c0);
        if (c1) atomicAdd(&c->rays[1], c1);
        if (c2) atomicAdd(&c->rays[2], c2);
    }
}

/* generate, first half: free slots take the next samples; slots with a ray
 * to trace join the ray queue. Clears nsq for the round. (Resets nrq to 0
 * before the launch: the host's, or pk_wf_finish's of the last round.) */
extern "C" __global__ void pk_wf_assign(wf_pool p, wf_counts *c)
{
    const int s = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    if (s == 0) c->nsq = 0;
    if (s >= p.n) return;
    if (p.stage[s] == WF_FREE) {
        const unsigned long long k = atomicAdd(&c->next, 1ull);
        if (k < c->end) {
            p.item[s] = k;
            p.stage[s] = WF_CAMERA;
        }
    }
    if (p.stage[s] == WF_CAMERA || p.stage[s] == WF_BOUNCE) p.rq_slot[atomicAdd(&c->nrq, 1)] = s;
}

extern "C" __global__ void pk_wf_generate(const path_tracer *__restrict__ pt, camera_frame cf, wf_pool p,
                                          wf_pixels pix, unsigned long long first, wf_counts *c)
{
    const int q = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    path_thread t;
    wf_thread_init(&t);
    if (q < c->nrq) wf_stage_generate(pt, &cf, &p, &pix, first, q, &t);
    wf_thread_count(&t, c);
}

extern "C" __global__ void pk_wf_intersect(const path_tracer *__restrict__ pt, wf_pool p, const wf_counts *c)
{
    const int q = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    if (q >= c->nrq) return;
    path_thread t;
    wf_thread_init(&t);
    wf_stage_intersect(pt, &p, q, &t);
}

/* shade, and the shadow queue filled */
extern "C" __global__ void pk_wf_shade(const path_tracer *__restrict__ pt, wf_pool p, wf_pixels pix,
                                       unsigned long long first, int want_aov, wf_counts *c)
{
    const int q = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    path_thread t;
    wf_thread_init(&t);
    if (q < c->nrq) {
        wf_stage_shade(pt, &p, &pix, first, want_aov != 0, q, &t);
        if (p.sq_has[q]) p.sq[atomicAdd(&c->nsq, 1)] = q;
    }
    wf_thread_count(&t, c);
}

extern "C" __global__ void pk_wf_shadow(const path_tracer *__restrict__ pt, wf_pool p, wf_counts *c)
{
    const int j = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    path_thread t;
    wf_thread_init(&t);
    if (j < c->nsq) wf_stage_shadow(pt, &p, p.sq[j], &t);
    wf_thread_count(&t, c);
}

/* accumulate: finished paths into their samples (p.out numbered from c0).
 * The host reads nrq after this launch (0: the chunk is done) and clears
 * it before the next pk_wf_assign. */
extern "C" __global__ void pk_wf_finish(wf_pool p, unsigned long long c0, int want_aov, const wf_counts *c)
{
    const int q = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    if (q < c->nrq) wf_stage_finish(&p, c0, want_aov != 0, q);
}

/*
 * trace.cu - the GPU kernels of the cuda accelerator, each running a
 * traversal of bvh_gpu.h (the code the CPU tests check on the host) for one
 * ray per thread. Compiled by nvcc alone into a fat binary embedded in the
 * library (see CMakeLists.txt and docs/gpu.md), with -fmad=false so that
 * the triangle test rounds as the CPU's does.
 *
 * Versions, chosen at run time by cuda.c (PAPRSEK_CUDA_KERNEL, for timing
 * them against each other; all give the same hits bit for bit):
 *   v0  gpu_trace_v0, one thread per ray (the first kernel);
 *   v1  gpu_trace_box with GPU_TEST_EXACT (nodes and triangles read into
 *       registers with 16-byte loads, the nearest child kept in a register),
 *       one thread per ray;
 *   v2  as v1, with persistent warps: as many threads as the GPU holds at
 *       once, each warp taking the next 32 rays from a global counter
 *       (Aila and Laine 2009) until none are left;
 *   v3  GPU_TEST_FMA (the same distances, one operation less per plane),
 *       one thread per ray;
 *   v4  GPU_TEST_LOOSE (one fma per plane, boxes loosened by a bound on the
 *       rounding), one thread per ray;
 *   v5  as v4, with persistent warps;
 *   v6  GPU_TEST_WIDE (as v4 without the add that makes a byte a float),
 *       one thread per ray;
 *   v7  as v6, with persistent warps;
 *   v8  as v6, with persistent warps whose lanes take new rays as theirs
 *       finish (dynamic fetch, below);
 *   v9  as v3, with dynamic fetch.
 * Every kernel takes (nodes, tris, rays, hits, n, counter); counter is a
 * device word set to 0 before a persistent launch (ignored by the others).
 * Blocks of 128 threads. v4-v7 ask for 7 blocks per multiprocessor (at most
 * 72 registers a thread, which they fit without spilling, where they would
 * take 77); the others are left to the compiler (v1, v3: 64 registers, 8
 * blocks; v2, v9: 72, 7 blocks; v8: 80, 6 blocks), v0 as it was (64). */
#include "accel/bvh_gpu.h"

#define PK_KERNEL_PARAMS                                                                                       \
    const gpu_node *__restrict__ nodes, const gpu_tri *__restrict__ tris, const pk_ray *__restrict__ rays, \
        pk_hit *__restrict__ hits, unsigned n, unsigned *__restrict__ counter

#define PK_ONE_PER_THREAD(name, trace, any, blocks)                                \
    extern "C" __global__ void __launch_bounds__(128, blocks) name(PK_KERNEL_PARAMS) \
    {                                                                              \
        (void)counter;                                                             \
        const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;                  \
        if (i >= n) return;                                                        \
        const pk_ray r = rays[i];                                                  \
        pk_hit h;                                                                  \
        trace(nodes, tris, &r, any, &h, NULL);                                     \
        hits[i] = h;                                                               \
    }

PK_ONE_PER_THREAD(pk_trace_closest_v0, gpu_trace_v0, false, 0)
PK_ONE_PER_THREAD(pk_trace_any_v0, gpu_trace_v0, true, 0)
#define PK_TRACE_WITH(box)                                                                                \
    static __device__ __forceinline__ bool trace_##box(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *r, \
                                                       bool any, pk_hit *h, gpu_counters *c)               \
    {                                                                                                      \
        return gpu_trace_box(nodes, tris, r, any, h, c, box);                                              \
    }
PK_TRACE_WITH(GPU_TEST_EXACT)
PK_TRACE_WITH(GPU_TEST_FMA)
PK_TRACE_WITH(GPU_TEST_LOOSE)
PK_TRACE_WITH(GPU_TEST_WIDE)

PK_ONE_PER_THREAD(pk_trace_closest_v1, trace_GPU_TEST_EXACT, false, 0)
PK_ONE_PER_THREAD(pk_trace_any_v1, trace_GPU_TEST_EXACT, true, 0)
PK_ONE_PER_THREAD(pk_trace_closest_v3, trace_GPU_TEST_FMA, false, 0)
PK_ONE_PER_THREAD(pk_trace_any_v3, trace_GPU_TEST_FMA, true, 0)
PK_ONE_PER_THREAD(pk_trace_closest_v4, trace_GPU_TEST_LOOSE, false, 7)
PK_ONE_PER_THREAD(pk_trace_any_v4, trace_GPU_TEST_LOOSE, true, 7)
PK_ONE_PER_THREAD(pk_trace_closest_v6, trace_GPU_TEST_WIDE, false, 7)
PK_ONE_PER_THREAD(pk_trace_any_v6, trace_GPU_TEST_WIDE, true, 7)

#define PK_PERSISTENT(name, trace, any, blocks)                                    \
    extern "C" __global__ void __launch_bounds__(128, blocks) name(PK_KERNEL_PARAMS) \
    {                                                                              \
        const unsigned lane = threadIdx.x & 31u;                                   \
        for (;;) {                                                                 \
            unsigned base = 0;                                                     \
            if (lane == 0) base = atomicAdd(counter, 32u);                         \
            base = __shfl_sync(0xFFFFFFFFu, base, 0);                              \
            if (base >= n) return;                                                 \
            const unsigned i = base + lane;                                        \
            if (i < n) {                                                           \
                const pk_ray r = rays[i];                                          \
                pk_hit h;                                                          \
                trace(nodes, tris, &r, any, &h, NULL);                             \
                hits[i] = h;                                                       \
            }                                                                      \
        }                                                                          \
    }

/* Persistent warps that keep every lane busy (Aila and Laine 2009, "dynamic
 * fetch"): each lane walks its ray a step at a time (gpu_walk_step: down to
 * a leaf, its triangles, the next pop); when at least a quarter of the
 * warp's lanes are done, those lanes take the next rays from the counter
 * together (one atomic add a warp). The same steps as one thread per ray,
 * so the same hits. */
#define PK_FETCHING(name, box, any, blocks)                                                     \
    extern "C" __global__ void __launch_bounds__(128, blocks) name(PK_KERNEL_PARAMS)             \
    {                                                                                           \
        const unsigned lane = threadIdx.x & 31u;                                                \
        gpu_stack_entry stack[GPU_STACK];                                                       \
        gpu_walk w;                                                                             \
        unsigned ray = 0;                                                                       \
        bool busy = false, exhausted = false;                                                   \
        for (;;) {                                                                              \
            const unsigned idle = __ballot_sync(0xFFFFFFFFu, !busy);                            \
            if (!exhausted && __popc(idle) >= 8) {                                              \
                unsigned base = 0;                                                              \
                if (lane == (unsigned)(__ffs(idle) - 1)) base = atomicAdd(counter, __popc(idle)); \
                base = __shfl_sync(0xFFFFFFFFu, base, __ffs(idle) - 1);                         \
                if (base + __popc(idle) >= n) exhausted = true;                                 \
                if (!busy) {                                                                    \
                    ray = base + __popc(idle & ((1u << lane) - 1u));                            \
                    while (ray < n) {                                                           \
                        const pk_ray r = rays[ray];                                             \
                        if (gpu_walk_init(&w, &r, box)) {                                       \
                            busy = true;                                                        \
                            break;                                                              \
                        }                                                                       \
                        gpu_walk_hit(&w, &hits[ray]);                                           \
                        ray = n;                                                                \
                    }                                                                           \
                }                                                                               \
            }                                                                                   \
            if (!__any_sync(0xFFFFFFFFu, busy)) {                                               \
                if (exhausted) return;                                                          \
                continue;                                                                       \
            }                                                                                   \
            if (busy && gpu_walk_step(&w, stack, nodes, tris, any, NULL, box)) {                \
                gpu_walk_hit(&w, &hits[ray]);                                                   \
                busy = false;                                                                   \
            }                                                                                   \
        }                                                                                       \
    }

PK_FETCHING(pk_trace_closest_v8, GPU_TEST_WIDE, false, 0)
PK_FETCHING(pk_trace_any_v8, GPU_TEST_WIDE, true, 0)
PK_FETCHING(pk_trace_closest_v9, GPU_TEST_FMA, false, 0)
PK_FETCHING(pk_trace_any_v9, GPU_TEST_FMA, true, 0)

PK_PERSISTENT(pk_trace_closest_v2, trace_GPU_TEST_EXACT, false, 0)
PK_PERSISTENT(pk_trace_any_v2, trace_GPU_TEST_EXACT, true, 0)
PK_PERSISTENT(pk_trace_closest_v5, trace_GPU_TEST_LOOSE, false, 7)
PK_PERSISTENT(pk_trace_any_v5, trace_GPU_TEST_LOOSE, true, 7)
PK_PERSISTENT(pk_trace_closest_v7, trace_GPU_TEST_WIDE, false, 7)
PK_PERSISTENT(pk_trace_any_v7, trace_GPU_TEST_WIDE, true, 7)

/* the path tracer (left out to check the traversal's PTX alone: tests/cuda/test_cuda_ptx.sh) */
#ifndef PK_TRAVERSAL_ONLY
#include "path.cu"
#endif

/*
 * trace.cu - the GPU kernels of the cuda accelerator, each running a
 * traversal of bvh_gpu.h (the code the CPU tests check on the host) for one
 * ray per thread. Compiled by nvcc alone into a fat binary embedded in the
 * library (see CMakeLists.txt and docs/gpu.md), with -fmad=false so that
 * the triangle test rounds as the CPU's does.
 *
 * Three kernels, giving the same closest hits:
 *   pk_trace_*      gpu_trace_box with GPU_TEST_WIDE (the box test with one
 *                   fma a plane, boxes loosened by a bound on the rounding,
 *                   the byte made a float by the permute itself), one thread
 *                   per ray: the fastest measured on the H100 (docs/gpu.md);
 *   pk_trace_*_ref  gpu_trace_v0, the first kernel (nodes read byte by byte,
 *                   every hit child pushed), which the tests hold the
 *                   default to.
 * The other versions measured (persistent warps, dynamic fetch, other box
 * tests) were removed after the measurements; docs/gpu.md says where they
 * are in the history. Every kernel takes (nodes, tris, rays, hits, n).
 * Blocks of 128 threads; the default asks for 7 blocks per multiprocessor
 * (at most 72 registers a thread, which it fits without spilling, where it
 * would take 77). */
#include "accel/bvh_gpu.h"

#define PK_KERNEL_PARAMS                                                                                       \
    const gpu_node *__restrict__ nodes, const gpu_tri *__restrict__ tris, const pk_ray *__restrict__ rays, \
        pk_hit *__restrict__ hits, unsigned n

#define PK_ONE_PER_THREAD(name, trace, any, blocks)                                \
    extern "C" __global__ void __launch_bounds__(128, blocks) name(PK_KERNEL_PARAMS) \
    {                                                                              \
        const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;                  \
        if (i >= n) return;                                                        \
        const pk_ray r = rays[i];                                                  \
        pk_hit h;                                                                  \
        trace(nodes, tris, &r, any, &h, NULL);                                     \
        hits[i] = h;                                                               \
    }

static __device__ __forceinline__ bool trace_wide(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *r,
                                                  bool any, pk_hit *h, gpu_counters *c)
{
    return gpu_trace_box(nodes, tris, r, any, h, c, GPU_TEST_WIDE);
}

/* The ordered traversal (octant-ordered slots, a stack of (node, mask,
 * distance) entries: cuda.traversal=ordered), with the same box test; 6
 * blocks a multiprocessor (at most 80 registers: with 72 it spills). */
static __device__ __forceinline__ bool trace_ordered(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *r,
                                                     bool any, pk_hit *h, gpu_counters *c)
{
    return gpu_trace_ordered(nodes, tris, r, any, h, c, GPU_TEST_WIDE);
}

PK_ONE_PER_THREAD(pk_trace_closest, trace_wide, false, 7)
PK_ONE_PER_THREAD(pk_trace_any, trace_wide, true, 7)
PK_ONE_PER_THREAD(pk_trace_closest_ref, gpu_trace_v0, false, 0)
PK_ONE_PER_THREAD(pk_trace_any_ref, gpu_trace_v0, true, 0)
PK_ONE_PER_THREAD(pk_trace_closest_ordered, trace_ordered, false, 6)
PK_ONE_PER_THREAD(pk_trace_any_ordered, trace_ordered, true, 6)

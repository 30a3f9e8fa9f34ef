/*
 * trace.cu - the GPU kernels of the cuda accelerator: one thread per ray,
 * each running gpu_trace of bvh_gpu.h, the traversal the CPU tests check on
 * the host. Compiled by nvcc alone into a fat binary embedded in the
 * library (see CMakeLists.txt and docs/gpu.md), with -fmad=false so that
 * the triangle test rounds as the CPU's does.
 */
#include "accel/bvh_gpu.h"

extern "C" __global__ void __launch_bounds__(128) pk_trace_closest(const gpu_node *__restrict__ nodes,
                                                                  const gpu_tri *__restrict__ tris,
                                                                  const pk_ray *__restrict__ rays,
                                                                  pk_hit *__restrict__ hits, unsigned n)
{
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const pk_ray r = rays[i];
    pk_hit h;
    gpu_trace(nodes, tris, &r, false, &h, NULL);
    hits[i] = h;
}

extern "C" __global__ void __launch_bounds__(128) pk_trace_any(const gpu_node *__restrict__ nodes,
                                                              const gpu_tri *__restrict__ tris,
                                                              const pk_ray *__restrict__ rays,
                                                              pk_hit *__restrict__ hits, unsigned n)
{
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const pk_ray r = rays[i];
    pk_hit h;
    gpu_trace(nodes, tris, &r, true, &h, NULL);
    hits[i] = h;
}

/* the path tracer (left out to check the traversal's PTX alone: tests/cuda/test_cuda_ptx.sh) */
#ifndef PK_TRAVERSAL_ONLY
#include "path.cu"
#endif

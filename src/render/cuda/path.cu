/*
 * path.cu - the GPU path tracer's kernels (see src/render/path_gpu.h): the
 * CPU's sampling code (path_kernel.h) with rays traced by gpu_trace_box of
 * bvh_gpu.h on the cuda accelerator's structure, one thread per pixel, a
 * few samples per launch. Compiled by nvcc alone into a module of its own
 * (pk_cuda_path_fatbin.h), which render/path_gpu.c loads through the device
 * layer (device/cuda.h).
 */
#include "accel/bvh_gpu.h"
#include "render/path.h"

/* The box test of the path tracer's traversal (bvh_gpu.h GPU_TEST_*): the
 * exact one with fused plane distances (GPU_TEST_FMA). The loosened one of
 * the fastest ray kernel measured slower here on the H100 (220 against 250
 * M samples/s on CornellBox-Original, 62 against 70 M on Sponza; not
 * profiled, so why is open). */
#ifndef PK_PATH_BOX
#define PK_PATH_BOX GPU_TEST_FMA
#endif

/* closest and any hit on the device BVH of the path tracer's copy */
static __device__ __forceinline__ bool path_gpu_trace(const path_tracer *pt, const ray *r, hit *h, bool any)
{
    return gpu_trace_box((const gpu_node *)pt->gpu_nodes, (const gpu_tri *)pt->gpu_tris, (const pk_ray *)r, any,
                         (pk_hit *)h, NULL, PK_PATH_BOX);
}
static __device__ __forceinline__ bool path_gpu_occluded(const path_tracer *pt, const ray *r)
{
    hit h;
    return path_gpu_trace(pt, r, &h, true);
}
#define PATH_TRACE(pt, t, r, h) path_gpu_trace((pt), (r), (h), false)
#define PATH_OCCLUDED(pt, t, r) path_gpu_occluded((pt), (r))
#include "render/path_gpu.h"
#include "render/path_kernel.h"

/* The sizes of the structures the host copies, as laid out here (path_gpu.c
 * compares them with its own). */
extern "C" __global__ void pk_path_layout(unsigned long long *out)
{
    if (threadIdx.x != 0 || blockIdx.x != 0) return;
    out[0] = sizeof(scene_view);
    out[1] = sizeof(material);
    out[2] = sizeof(texture);
    out[3] = sizeof(env_light);
    out[4] = sizeof(light_set);
    out[5] = sizeof(path_tracer);
    out[6] = sizeof(frame);
    out[7] = sizeof(camera_frame);
}

/* Samples first..first+n-1 of pixel (thread % 256) of tile (thread / 256):
 * their sum is written to (accumulate = 0) or added to acc; rays counts
 * camera, bounce and shadow rays. Each sample's path runs to its end before
 * the next starts. (Starting a lane's next sample as soon as its path ends,
 * one path_step at a time, measured slower on the H100: 195 against 208 M
 * samples/s on CornellBox-Original; docs/gpu.md.) At most 80 registers a
 * thread (6 blocks of 128 a multiprocessor): 259 M samples/s against 212 M
 * with the compiler's 168 registers and fewer threads.
 * Two kernels: pk_path_render for the pinhole camera, pk_path_render_camera
 * for a lens or the orthographic projection (camera_ray): with those in
 * the one kernel, the compiler spilled more registers (164 bytes stored
 * against 76), also for pinholes. */
template <bool pinhole>
static __device__ __forceinline__ void path_render(const path_tracer *__restrict__ pt, const camera_frame &cf,
                                                   const gpu_tile *__restrict__ tiles, unsigned nthreads,
                                                   unsigned first, unsigned n, int accumulate,
                                                   float *__restrict__ acc, unsigned long long *rays)
{
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= nthreads) return; /* (nthreads is a multiple of 256: whole warps) */
    const gpu_tile tl = tiles[i / GPU_TILE_PIXELS];
    const int k = (int)(i % GPU_TILE_PIXELS);
    path_thread t;
    t.rays_camera = t.rays_bounce = t.rays_shadow = 0;
    t.cp = NULL;
    vec3 sum = v3s(0.0f);
    if (k < tl.w * tl.h) {
        const int px = tl.x + k % tl.w, py = tl.y + k / tl.w;
        for (unsigned s = 0; s < n; s++) {
            const uint32_t index = first + s;
            const camera_sample cs = path_camera_place(pt, px, py, index);
            const ray r = pinhole ? camera_ray_pinhole(&cf, &cs) : camera_ray(&cf, &cs);
            hit h;
            const bool got = path_gpu_trace(pt, &r, &h, false);
            t.rays_camera++;
            vec3 c;
            if (path_camera_sample(pt, &t, px, py, index, &r, got ? &h : NULL, &c))
                sum = v3_add(sum, v3_scale(c, cs.weight)); /* the pixel filter's weight (1 but in negative lobes) */
        }
    }
    float *a = &acc[3 * (size_t)i];
    if (accumulate) sum = v3_add(sum, v3(a[0], a[1], a[2]));
    a[0] = sum.x, a[1] = sum.y, a[2] = sum.z;
    /* one atomic per warp and counter */
    unsigned long long c0 = t.rays_camera, c1 = t.rays_bounce, c2 = t.rays_shadow;
    for (int off = 16; off > 0; off >>= 1) {
        c0 += __shfl_down_sync(0xffffffffu, c0, off);
        c1 += __shfl_down_sync(0xffffffffu, c1, off);
        c2 += __shfl_down_sync(0xffffffffu, c2, off);
    }
    if ((threadIdx.x & 31) == 0) {
        atomicAdd(&rays[0], c0);
        atomicAdd(&rays[1], c1);
        atomicAdd(&rays[2], c2);
    }
}

extern "C" __global__ void __launch_bounds__(128, 6)
    pk_path_render(const path_tracer *__restrict__ pt, camera_frame cf, const gpu_tile *__restrict__ tiles,
                   unsigned nthreads, unsigned first, unsigned n, int accumulate, float *__restrict__ acc,
                   unsigned long long *rays)
{
    path_render<true>(pt, cf, tiles, nthreads, first, n, accumulate, acc, rays);
}

extern "C" __global__ void __launch_bounds__(128, 6)
    pk_path_render_camera(const path_tracer *__restrict__ pt, camera_frame cf, const gpu_tile *__restrict__ tiles,
                          unsigned nthreads, unsigned first, unsigned n, int accumulate, float *__restrict__ acc,
                          unsigned long long *rays)
{
    path_render<false>(pt, cf, tiles, nthreads, first, n, accumulate, acc, rays);
}

/*
 * path_gpu.h - the path tracer on an NVIDIA GPU: the read-only structures
 * of a render (the path tracer with its light set, its frame and
 * environment, the scene with its materials and textures) copied to the
 * device with their pointers turned into device addresses, and the kernel
 * pk_path_render (src/render/cuda/path.cu), which runs path_kernel.h, the
 * CPU's sampling code, one thread per pixel of a tile list.
 */
#ifndef PK_PATH_GPU_H
#define PK_PATH_GPU_H

#include "path.h"

typedef struct path_gpu path_gpu;

/* A tile of the image: pixels x..x+w-1, y..y+h-1 (w, h <= 16). */
typedef struct gpu_tile {
    int x, y, w, h;
} gpu_tile;
#define GPU_TILE_PIXELS 256

/* Copies pt (whose frame's accelerator is a CUDA one, PK_ACCEL_CUDA) to the
 * device. Errors (device memory, a scene the GPU cannot render) are latched
 * in ctx. */
PK_HIDDEN pk_status path_gpu_create(pk_context *ctx, const path_tracer *pt, path_gpu **out);
PK_HIDDEN void path_gpu_destroy(path_gpu *g);
/* Device memory held (bytes), and the device's name. */
PK_HIDDEN size_t path_gpu_bytes(const path_gpu *g);

/* Progress between kernel launches: samples finished of total; returns
 * false to stop. */
typedef bool (*path_gpu_progress)(void *user, uint64_t done, uint64_t total);

/* Renders samples first..first+spp-1 of every pixel of tiles[0..ntiles-1]
 * into acc (ntiles * GPU_TILE_PIXELS * 3 floats: each tile's pixels in rows
 * of its width, the sums of the samples), counting rays into rays[3]
 * (camera, bounce, shadow). Several kernel launches, each a few samples
 * per pixel (sized to take about 50 ms), with progress between them.
 * PK_ERR_CANCELLED (not latched in the context) when progress asked to
 * stop; acc is then incomplete. */
PK_HIDDEN pk_status path_gpu_render(path_gpu *g, const camera_frame *cf, const gpu_tile *tiles, size_t ntiles,
                                    uint32_t first, int spp, float *acc, uint64_t rays[3], path_gpu_progress progress,
                                    void *user);

#endif

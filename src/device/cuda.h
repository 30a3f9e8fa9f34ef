/*
 * cuda.h - an NVIDIA GPU through the CUDA Driver API: the driver loaded at
 * run time (dynlib: libcuda.so.1, or the config's cuda.library), device 0's
 * primary context, a module of kernels, device memory, copies and kernel
 * launches. It knows no accelerator and no integrator: the ray kernels'
 * glue (accel/cuda.c) and the GPU path tracer (render/path_gpu.c) each open
 * a device with their own kernels (of the kernels' module, paprsek_cuda.so). Device addresses are uint64_t; every
 * module opened in the process shares the device's primary context, so an
 * address from one device handle is valid in the kernels of another.
 *
 * Errors are latched in the context the device was opened with, worded
 * "WHO: what failed: the driver's reason" (who as given to cuda_device_open).
 * Nothing here needs CUDA at build time; without a driver or a GPU opening
 * a device fails cleanly.
 */
#ifndef PK_DEVICE_CUDA_H
#define PK_DEVICE_CUDA_H

#include "paprsek_internal.h"

typedef struct cuda_device cuda_device;

/* Loads the driver (ctx's config cuda.library), the kernels' module
 * (cuda_kernels.h: ctx's config cuda.module, or the installed one), opens
 * device 0 and loads the kernels named kernels ("trace", "path") as the
 * device's module. who prefixes messages ("accelerator 'cuda'"), a static
 * string. Errors: PK_ERR_UNSUPPORTED (no driver, no kernels' module, no
 * device, a driver too old for the kernels), PK_ERR_NOMEM, PK_ERR_IO. */
PK_HIDDEN pk_status cuda_device_open(pk_context *ctx, const char *who, const char *kernels, cuda_device **out);
PK_HIDDEN void cuda_device_close(cuda_device *d);
PK_HIDDEN const char *cuda_device_name(const cuda_device *d);
PK_HIDDEN unsigned cuda_device_multiprocessors(const cuda_device *d);

/* Free and total device memory. */
PK_HIDDEN pk_status cuda_device_mem_info(cuda_device *d, size_t *free_bytes, size_t *total);
/* PK_OK when bytes more fit in the device's free memory; else
 * PK_ERR_NOMEM: "not enough device memory for WHAT: N needed, F free of T". */
PK_HIDDEN pk_status cuda_device_check_room(cuda_device *d, size_t bytes, const char *what);
/* A new buffer of bytes, with src's bytes copied in when src is not NULL
 * (*out 0 for 0 bytes). what names the buffer in messages ("the BVH"):
 * "not enough device memory for WHAT: N needed, F free of T". */
PK_HIDDEN pk_status cuda_device_alloc(cuda_device *d, const void *src, size_t bytes, const char *what, uint64_t *out);
PK_HIDDEN void cuda_device_free(cuda_device *d, uint64_t p);
/* Copies bytes between host and dev (to_device: host to device). what: for
 * messages ("copying rays to the device"; NULL: a generic one). */
PK_HIDDEN pk_status cuda_device_copy(cuda_device *d, void *host, uint64_t dev, size_t bytes, bool to_device,
                                     const char *what);

/* A kernel of the module by name. */
typedef struct cuda_kernel {
    void *fn;
    const char *name;
} cuda_kernel;
PK_HIDDEN pk_status cuda_device_kernel(cuda_device *d, const char *name, cuda_kernel *out);
/* Launches k over grid blocks of block threads with params (the kernel's
 * arguments, as cuLaunchKernel takes them) without waiting. what: for
 * messages (NULL: "the kernel NAME"). */
PK_HIDDEN pk_status cuda_device_launch(cuda_device *d, const cuda_kernel *k, unsigned grid, unsigned block,
                                       void **params, const char *what);
/* Runs kernel (by name) over threads threads in blocks of block, waits for
 * it and gives its time in ms (ms may be NULL). Serialised per device. */
PK_HIDDEN pk_status cuda_device_run(cuda_device *d, const char *kernel, size_t threads, unsigned block,
                                    void **params, double *ms);

/* Timing marks on the device's stream: record mark k (0..CUDA_MARKS-1),
 * wait until mark k has passed, the time between two passed marks (ms; 0
 * when the driver cannot tell). The caller serialises its use of marks. */
#define CUDA_MARKS 4
PK_HIDDEN pk_status cuda_device_mark(cuda_device *d, int k, const char *what);
PK_HIDDEN pk_status cuda_device_wait(cuda_device *d, int k, const char *what);
PK_HIDDEN double cuda_device_elapsed(cuda_device *d, int from, int to);

#endif

/*
 * cuda_kernels.h - the C interface of the CUDA kernels' module
 * (paprsek_cuda.so, cuda_kernels_module.c): the fat binaries nvcc compiled
 * from src/accel/cuda/trace.cu ("trace") and src/render/cuda/path.cu
 * ("path"), kept out of the library so that building the library and its
 * programs does not wait for nvcc; cuda.c loads the module (device/module.h:
 * the config's cuda.module, or the one installed beside the library) the
 * first time a device is opened. The entry point's name carries the
 * interface's version.
 */
#ifndef PK_CUDA_KERNELS_H
#define PK_CUDA_KERNELS_H

#define CUDA_KERNELS_MODULE_FILE "paprsek_cuda.so"
#define CUDA_KERNELS_ENTRY "pk_cuda_kernels_v1"

/* The image of the kernels named name, and the CUDA version (major, minor)
 * that compiled them; NULL when the module has none by that name. */
typedef const void *(*cuda_kernels_fn)(const char *name, int *cuda_major, int *cuda_minor);

#endif

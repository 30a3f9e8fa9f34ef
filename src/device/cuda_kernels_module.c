/*
 * cuda_kernels_module.c - the CUDA kernels' module (paprsek_cuda.so; see
 * cuda_kernels.h): the fat binaries embedded by cmake/embed_fatbin.cmake,
 * handed out by name. Built by `make build` where nvcc is found, not part of
 * the library (CMakeLists.txt leaves *_module.c out of it).
 */
#include "cuda_kernels.h"

#include "pk_cuda_path_fatbin.h"  /* generated: pk_cuda_path_fatbin[] */
#include "pk_cuda_trace_fatbin.h" /* generated: pk_cuda_trace_fatbin[], PK_CUDA_VERSION_* */

#include <string.h>

__attribute__((visibility("default"))) const void *pk_cuda_kernels_v1(const char *name, int *cuda_major,
                                                                      int *cuda_minor);

const void *pk_cuda_kernels_v1(const char *name, int *cuda_major, int *cuda_minor)
{
    *cuda_major = PK_CUDA_VERSION_MAJOR;
    *cuda_minor = PK_CUDA_VERSION_MINOR;
    if (strcmp(name, "trace") == 0) return pk_cuda_trace_fatbin;
    if (strcmp(name, "path") == 0) return pk_cuda_path_fatbin;
    return NULL;
}

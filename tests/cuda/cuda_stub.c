/*
 * cuda_stub.c - a stand-in for the CUDA driver (libcuda.so.1) that has no
 * GPU behind it, loaded through PAPRSEK_CUDA_LIBRARY by test_cuda_errors.sh
 * so that the error paths of src/accel/cuda.c run on machines without a
 * GPU. PK_CUDA_STUB says which failure to play:
 *   nodevice    cuInit answers CUDA_ERROR_NO_DEVICE
 *   zero        cuInit succeeds, cuDeviceGetCount answers 0
 *   oldptx      loading the kernels answers CUDA_ERROR_UNSUPPORTED_PTX_VERSION
 *   nomem       64 bytes of device memory free
 *   kernelfail  everything works (host memory stands in for the device's)
 *               but the kernel launch answers CUDA_ERROR_LAUNCH_FAILED
 * Only the entry points src/accel/cuda.c looks up are here.
 */
#include <stdlib.h>
#include <string.h>

typedef int CUresult;
typedef unsigned long long CUdeviceptr;

static int mode(const char *m)
{
    const char *s = getenv("PK_CUDA_STUB");
    return s && strcmp(s, m) == 0;
}

static int dummy;

CUresult cuInit(unsigned flags)
{
    (void)flags;
    return mode("nodevice") ? 100 : 0;
}
CUresult cuDriverGetVersion(int *v)
{
    *v = 11040;
    return 0;
}
CUresult cuGetErrorString(CUresult e, const char **s)
{
    switch (e) {
    case 2: *s = "out of memory"; return 0;
    case 100: *s = "no CUDA-capable device is detected"; return 0;
    case 222: *s = "the provided PTX was compiled with an unsupported toolchain."; return 0;
    case 719: *s = "unspecified launch failure"; return 0;
    default: *s = "stub error"; return 0;
    }
}
CUresult cuDeviceGetCount(int *n)
{
    *n = mode("zero") ? 0 : 1;
    return 0;
}
CUresult cuDeviceGet(int *d, int i)
{
    *d = i;
    return 0;
}
CUresult cuDeviceGetName(char *name, int len, int d)
{
    (void)d;
    strncpy(name, "Stub GPU", (size_t)len);
    return 0;
}
CUresult cuDeviceGetAttribute(int *v, int attr, int d)
{
    (void)d;
    *v = attr == 75 ? 9 : 0;
    return 0;
}
CUresult cuDevicePrimaryCtxRetain(void **c, int d)
{
    (void)d;
    *c = &dummy;
    return 0;
}
CUresult cuDevicePrimaryCtxRelease_v2(int d)
{
    (void)d;
    return 0;
}
CUresult cuCtxSetCurrent(void *c)
{
    (void)c;
    return 0;
}
CUresult cuCtxSynchronize(void) { return 0; }
CUresult cuModuleLoadData(void **m, const void *image)
{
    (void)image;
    if (mode("oldptx")) return 222;
    *m = &dummy;
    return 0;
}
CUresult cuModuleUnload(void *m)
{
    (void)m;
    return 0;
}
CUresult cuModuleGetFunction(void **f, void *m, const char *name)
{
    (void)m, (void)name;
    *f = &dummy;
    return 0;
}
CUresult cuMemGetInfo_v2(size_t *free_b, size_t *total)
{
    *total = (size_t)16 << 30;
    *free_b = mode("nomem") ? 64 : *total;
    return 0;
}
CUresult cuMemAlloc_v2(CUdeviceptr *p, size_t bytes)
{
    void *m = malloc(bytes);
    if (!m) return 2;
    *p = (CUdeviceptr)(size_t)m;
    return 0;
}
CUresult cuMemFree_v2(CUdeviceptr p)
{
    free((void *)(size_t)p);
    return 0;
}
CUresult cuMemcpyHtoD_v2(CUdeviceptr dst, const void *src, size_t bytes)
{
    memcpy((void *)(size_t)dst, src, bytes);
    return 0;
}
CUresult cuMemcpyDtoH_v2(void *dst, CUdeviceptr src, size_t bytes)
{
    memcpy(dst, (const void *)(size_t)src, bytes);
    return 0;
}
CUresult cuLaunchKernel(void *f, unsigned gx, unsigned gy, unsigned gz, unsigned bx, unsigned by, unsigned bz,
                        unsigned shared, void *s, void **params, void **extra)
{
    (void)f, (void)gx, (void)gy, (void)gz, (void)bx, (void)by, (void)bz, (void)shared, (void)s, (void)params;
    (void)extra;
    return 719;
}
CUresult cuEventCreate(void **e, unsigned flags)
{
    (void)flags;
    *e = &dummy;
    return 0;
}
CUresult cuEventDestroy_v2(void *e)
{
    (void)e;
    return 0;
}
CUresult cuEventRecord(void *e, void *s)
{
    (void)e, (void)s;
    return 0;
}
CUresult cuEventSynchronize(void *e)
{
    (void)e;
    return 0;
}
CUresult cuEventElapsedTime(float *ms, void *a, void *b)
{
    (void)a, (void)b;
    *ms = 0.0f;
    return 0;
}

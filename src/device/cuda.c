/*
 * cuda.c - an NVIDIA GPU through the CUDA Driver API (see cuda.h).
 *
 * Nothing here links against CUDA: the driver, libcuda.so.1 (or the
 * config's cuda.library), is loaded by dynlib the first time a device is
 * opened, and its functions are called through the table cu, filled with
 * dlsym. The few Driver API types and values used are declared here, so the
 * library compiles without CUDA's headers; where they are at hand, a
 * compile-only build of this file (the pk_cuda_decls target,
 * PK_CHECK_CUDA_DECLS) checks every function pointer against cuda.h.
 */
#include "cuda.h"
#include "cuda_kernels.h"
#include "module.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

/* ---- the Driver API, as much of it as is used ------------------------- */

#if defined(PK_CHECK_CUDA_DECLS)
#include <cuda.h>
#else
typedef int CUresult;
typedef int CUdevice;
typedef int CUdevice_attribute;
typedef unsigned long long CUdeviceptr;
typedef struct CUctx_st *CUcontext;
typedef struct CUmod_st *CUmodule;
typedef struct CUfunc_st *CUfunction;
typedef struct CUevent_st *CUevent;
typedef struct CUstream_st *CUstream;

enum {
    CUDA_SUCCESS = 0,
    CUDA_ERROR_OUT_OF_MEMORY = 2,
    CUDA_ERROR_NO_DEVICE = 100,
    CUDA_ERROR_NO_BINARY_FOR_GPU = 209,
    CUDA_ERROR_UNSUPPORTED_PTX_VERSION = 222,
    CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT = 16,
    CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR = 75,
    CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR = 76
};
#endif

/* X(field, symbol, parameters); every one returns CUresult. */
#define CU_FUNCTIONS(X)                                                                                   \
    X(Init, cuInit, (unsigned flags))                                                                     \
    X(DriverGetVersion, cuDriverGetVersion, (int *version))                                               \
    X(GetErrorString, cuGetErrorString, (CUresult e, const char **s))                                     \
    X(DeviceGetCount, cuDeviceGetCount, (int *count))                                                     \
    X(DeviceGet, cuDeviceGet, (CUdevice * d, int ordinal))                                                \
    X(DeviceGetName, cuDeviceGetName, (char *name, int len, CUdevice d))                                 \
    X(DeviceGetAttribute, cuDeviceGetAttribute, (int *v, CUdevice_attribute attr, CUdevice d))            \
    X(DevicePrimaryCtxRetain, cuDevicePrimaryCtxRetain, (CUcontext * c, CUdevice d))                      \
    X(DevicePrimaryCtxRelease, cuDevicePrimaryCtxRelease_v2, (CUdevice d))                                \
    X(CtxSetCurrent, cuCtxSetCurrent, (CUcontext c))                                                      \
    X(CtxSynchronize, cuCtxSynchronize, (void))                                                           \
    X(ModuleLoadData, cuModuleLoadData, (CUmodule * m, const void *image))                                \
    X(ModuleUnload, cuModuleUnload, (CUmodule m))                                                         \
    X(ModuleGetFunction, cuModuleGetFunction, (CUfunction * f, CUmodule m, const char *name))             \
    X(MemGetInfo, cuMemGetInfo_v2, (size_t * free_bytes, size_t * total))                                 \
    X(MemAlloc, cuMemAlloc_v2, (CUdeviceptr * p, size_t bytes))                                           \
    X(MemFree, cuMemFree_v2, (CUdeviceptr p))                                                             \
    X(MemcpyHtoD, cuMemcpyHtoD_v2, (CUdeviceptr dst, const void *src, size_t bytes))                      \
    X(MemcpyDtoH, cuMemcpyDtoH_v2, (void *dst, CUdeviceptr src, size_t bytes))                            \
    X(LaunchKernel, cuLaunchKernel,                                                                       \
      (CUfunction f, unsigned gx, unsigned gy, unsigned gz, unsigned bx, unsigned by, unsigned bz,        \
       unsigned shared, CUstream s, void **params, void **extra))                                         \
    X(EventCreate, cuEventCreate, (CUevent * e, unsigned flags))                                          \
    X(EventDestroy, cuEventDestroy_v2, (CUevent e))                                                       \
    X(EventRecord, cuEventRecord, (CUevent e, CUstream s))                                                \
    X(EventSynchronize, cuEventSynchronize, (CUevent e))

/* Filled once, under the loader's lock, when the driver is ready; never
 * changed afterwards. */
static struct cu_table {
#define CU_FIELD(field, symbol, params) CUresult (*field) params;
    CU_FUNCTIONS(CU_FIELD)
#undef CU_FIELD
    CUresult (*EventElapsedTime)(float *ms, CUevent start, CUevent end);
} cu;

#if defined(PK_CHECK_CUDA_DECLS)
#define CU_CHECK(field, symbol, params)                                                       \
    _Static_assert(__builtin_types_compatible_p(__typeof__(cu.field), __typeof__(&symbol)), \
                   #symbol " is declared differently by cuda.h");
CU_FUNCTIONS(CU_CHECK)
#undef CU_CHECK
#if CUDA_VERSION >= 12080 /* (the _v2 came with CUDA 12.8) */
_Static_assert(__builtin_types_compatible_p(__typeof__(cu.EventElapsedTime), __typeof__(&cuEventElapsedTime_v2)),
               "cuEventElapsedTime_v2 is declared differently by cuda.h");
#else
_Static_assert(__builtin_types_compatible_p(__typeof__(cu.EventElapsedTime), __typeof__(&cuEventElapsedTime)),
               "cuEventElapsedTime is declared differently by cuda.h");
#endif
#endif

/* ---- loading the driver -------------------------------------------------- */

static dynlib driver = DYNLIB_INIT;

/* cuInit's answer, asked once when the driver is ready (under init_lock). */
static pthread_mutex_t init_lock = PTHREAD_MUTEX_INITIALIZER;
static bool init_done;
static CUresult init_result;

static const char *cu_error(CUresult e)
{
    const char *s = NULL;
    if (cu.GetErrorString && cu.GetErrorString(e, &s) == CUDA_SUCCESS && s) return s;
    return "unknown CUDA error";
}

static bool init_driver(void *h, const char *name, char *why, size_t n)
{
    struct cu_table t;
    void *sym;
#define CU_LOAD(field, symbol, params)                                                  \
    sym = dynlib_symbol(h, #symbol);                                                    \
    if (!sym) {                                                                         \
        snprintf(why, n, "no CUDA driver (%s has no " #symbol ": too old?)", name);     \
        return false;                                                                   \
    }                                                                                   \
    memcpy(&t.field, &sym, sizeof sym);
    CU_FUNCTIONS(CU_LOAD)
#undef CU_LOAD
    /* CUDA 12.8 renamed it (_v2); older drivers have the first version */
    sym = dynlib_symbol(h, "cuEventElapsedTime_v2");
    if (!sym) sym = dynlib_symbol(h, "cuEventElapsedTime");
    if (!sym) {
        snprintf(why, n, "no CUDA driver (%s has no cuEventElapsedTime)", name);
        return false;
    }
    memcpy(&t.EventElapsedTime, &sym, sizeof sym);
    cu = t;
    return true;
}

/* The driver of ctx's config, loaded and started; else an error latched
 * as "WHO: why". */
static pk_status driver_ready(pk_context *ctx, const char *who)
{
    char why[400];
    if (!dynlib_load(&driver, config_cuda_library(ctx), init_driver, why, sizeof why)) {
        /* dynlib says "NAME could not be loaded (...)" or init's reason */
        if (strncmp(why, "no CUDA driver", 14) == 0) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: %s", who, why);
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: no CUDA driver (%s)", who, why);
    }
    pthread_mutex_lock(&init_lock);
    if (!init_done) {
        init_result = cu.Init(0);
        init_done = true;
    }
    const CUresult e = init_result;
    pthread_mutex_unlock(&init_lock);
    if (e == CUDA_ERROR_NO_DEVICE) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: no CUDA device", who);
    if (e != CUDA_SUCCESS)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: the CUDA driver does not start (cuInit: %s)", who, cu_error(e));
    return PK_OK;
}

/* ---- the kernels' module ------------------------------------------------ */

/* A module's code: a fat binary image and the CUDA version that compiled it
 * (for the message when the driver is too old). */
typedef struct cuda_image {
    const void *data;
    int cuda_major, cuda_minor;
} cuda_image;

static dynlib kernels_module = DYNLIB_INIT;
static cuda_kernels_fn kernels_get; /* set once under the loader's lock */

static bool init_kernels(void *h, const char *name, char *why, size_t n)
{
    void *sym = dynlib_symbol(h, CUDA_KERNELS_ENTRY);
    if (!sym) {
        snprintf(why, n, "%s has no %s (not the kernels' module of this version of the library)", name,
                 CUDA_KERNELS_ENTRY);
        return false;
    }
    memcpy(&kernels_get, &sym, sizeof sym);
    return true;
}

/* The kernels named name from the kernels' module (loaded once). */
static pk_status kernels_image(pk_context *ctx, const char *who, const char *name, cuda_image *image)
{
    char why[600];
    bool missing = false;
    if (!module_load(&kernels_module, ctx->config.cuda_module, CUDA_KERNELS_MODULE_FILE, init_kernels, &missing, why,
                     sizeof why)) {
        if (missing)
            return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: the CUDA kernels' module is not there (%s): `make build` "
                             "builds it where nvcc is found (`make demo` does not)", who, why);
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: the CUDA kernels' module could not be loaded: %s", who, why);
    }
    image->data = kernels_get(name, &image->cuda_major, &image->cuda_minor);
    if (!image->data)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: the CUDA kernels' module has no kernels '%s'", who, name);
    return PK_OK;
}

/* ---- a device ------------------------------------------------------------ */

/* Invariants: the primary context of dev is retained while retained is
 * true (released by close); module is loaded in it; ev[] are events of that
 * context (NULL where creation failed); lock serialises cuda_device_run. */
struct cuda_device {
    pk_context *ctx;
    const char *who;
    CUdevice dev;
    CUcontext pctx;
    bool retained;
    CUmodule module;
    CUevent ev[CUDA_MARKS];
    unsigned sms;
    char name[128];
    pthread_mutex_t lock;
};

static pk_status cu_fail(cuda_device *d, const char *what, CUresult e)
{
    if (e == CUDA_ERROR_OUT_OF_MEMORY)
        return ctx_error(d->ctx, PK_ERR_NOMEM, "%s: %s: out of device memory", d->who, what);
    return ctx_error(d->ctx, PK_ERR_IO, "%s: %s failed: %s", d->who, what, cu_error(e));
}

/* "123 bytes" below a mebibyte, "12.3 MiB" above, for messages. */
typedef struct size_text {
    char s[32];
} size_text;

static size_text size_str(size_t bytes)
{
    size_text t;
    if (bytes < ((size_t)1 << 20))
        snprintf(t.s, sizeof t.s, "%zu bytes", bytes);
    else
        snprintf(t.s, sizeof t.s, "%.1f MiB", (double)bytes / (1024.0 * 1024.0));
    return t;
}

static pk_status make_current(cuda_device *d)
{
    const CUresult e = cu.CtxSetCurrent(d->pctx);
    return e == CUDA_SUCCESS ? PK_OK : cu_fail(d, "cuCtxSetCurrent", e);
}

static pk_status device_setup(cuda_device *d, const cuda_image *image)
{
    pk_context *ctx = d->ctx;
    CUresult e;
    int count = 0;
    if ((e = cu.DeviceGetCount(&count)) != CUDA_SUCCESS) return cu_fail(d, "cuDeviceGetCount", e);
    if (count < 1) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: no CUDA device", d->who);
    if ((e = cu.DeviceGet(&d->dev, 0)) != CUDA_SUCCESS) return cu_fail(d, "cuDeviceGet", e);
    if (cu.DeviceGetName(d->name, (int)sizeof d->name, d->dev) != CUDA_SUCCESS)
        snprintf(d->name, sizeof d->name, "CUDA device 0");
    d->name[sizeof d->name - 1] = '\0';
    if ((e = cu.DevicePrimaryCtxRetain(&d->pctx, d->dev)) != CUDA_SUCCESS)
        return cu_fail(d, "creating a context on the device", e);
    d->retained = true;
    if ((e = cu.CtxSetCurrent(d->pctx)) != CUDA_SUCCESS) return cu_fail(d, "cuCtxSetCurrent", e);
    if ((e = cu.ModuleLoadData(&d->module, image->data)) != CUDA_SUCCESS) {
        d->module = NULL;
        int major = 0, minor = 0, drv = 0;
        cu.DeviceGetAttribute(&major, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR, d->dev);
        cu.DeviceGetAttribute(&minor, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR, d->dev);
        cu.DriverGetVersion(&drv);
        if (e == CUDA_ERROR_UNSUPPORTED_PTX_VERSION || e == CUDA_ERROR_NO_BINARY_FOR_GPU)
            return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                             "%s: the kernels, built with CUDA %d.%d, do not run on %s (compute "
                             "capability %d.%d) with driver %d.%d (%s): they need a driver for CUDA %d.%d or newer",
                             d->who, image->cuda_major, image->cuda_minor, d->name, major, minor, drv / 1000,
                             drv % 1000 / 10, cu_error(e), image->cuda_major, image->cuda_minor);
        return cu_fail(d, "loading the kernels", e);
    }
    int sms = 0;
    if (cu.DeviceGetAttribute(&sms, CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT, d->dev) != CUDA_SUCCESS || sms < 1)
        sms = 1;
    d->sms = (unsigned)sms;
    for (int i = 0; i < CUDA_MARKS; i++)
        if ((e = cu.EventCreate(&d->ev[i], 0)) != CUDA_SUCCESS) {
            d->ev[i] = NULL;
            return cu_fail(d, "cuEventCreate", e);
        }
    return PK_OK;
}

pk_status cuda_device_open(pk_context *ctx, const char *who, const char *kernels, cuda_device **out)
{
    *out = NULL;
    pk_status st = driver_ready(ctx, who);
    if (st != PK_OK) return st;
    cuda_image image_s;
    const cuda_image *image = &image_s;
    if ((st = kernels_image(ctx, who, kernels, &image_s)) != PK_OK) return st;
    cuda_device *d = mem_calloc(&ctx->alloc, 1, sizeof *d);
    if (!d) return ctx_nomem(ctx);
    d->ctx = ctx;
    d->who = who;
    pthread_mutex_init(&d->lock, NULL);
    if ((st = device_setup(d, image)) != PK_OK) {
        cuda_device_close(d);
        return st;
    }
    *out = d;
    return PK_OK;
}

void cuda_device_close(cuda_device *d)
{
    if (!d) return;
    if (d->retained) {
        cu.CtxSetCurrent(d->pctx);
        for (int i = 0; i < CUDA_MARKS; i++)
            if (d->ev[i]) cu.EventDestroy(d->ev[i]);
        if (d->module) cu.ModuleUnload(d->module);
        cu.DevicePrimaryCtxRelease(d->dev);
    }
    pthread_mutex_destroy(&d->lock);
    mem_free(&d->ctx->alloc, d);
}

const char *cuda_device_name(const cuda_device *d) { return d->name; }
unsigned cuda_device_multiprocessors(const cuda_device *d) { return d->sms; }

pk_status cuda_device_mem_info(cuda_device *d, size_t *free_bytes, size_t *total)
{
    *free_bytes = *total = 0;
    pk_status st = make_current(d);
    if (st != PK_OK) return st;
    const CUresult e = cu.MemGetInfo(free_bytes, total);
    return e == CUDA_SUCCESS ? PK_OK : cu_fail(d, "cuMemGetInfo", e);
}

static pk_status check_room(cuda_device *d, size_t bytes, const char *what)
{
    size_t free_b = 0, total = 0;
    pk_status st = cuda_device_mem_info(d, &free_b, &total);
    if (st != PK_OK || bytes <= free_b) return st;
    if (what)
        return ctx_error(d->ctx, PK_ERR_NOMEM, "%s: not enough device memory for %s: %s needed, %s free of %s", d->who,
                         what, size_str(bytes).s, size_str(free_b).s, size_str(total).s);
    return ctx_error(d->ctx, PK_ERR_NOMEM, "%s: not enough device memory: %s more needed, %s free of %s", d->who,
                     size_str(bytes).s, size_str(free_b).s, size_str(total).s);
}

pk_status cuda_device_check_room(cuda_device *d, size_t bytes, const char *what)
{
    return check_room(d, bytes, what);
}

pk_status cuda_device_alloc(cuda_device *d, const void *src, size_t bytes, const char *what, uint64_t *out)
{
    *out = 0;
    if (bytes == 0) return PK_OK;
    pk_status st = check_room(d, bytes, what);
    if (st != PK_OK) return st;
    CUdeviceptr p = 0;
    CUresult e = cu.MemAlloc(&p, bytes);
    if (e != CUDA_SUCCESS)
        return ctx_error(d->ctx, PK_ERR_NOMEM, "%s: cannot allocate %s%s%s: %s", d->who, size_str(bytes).s,
                         what ? " for " : "", what ? what : "", cu_error(e));
    if (src && (e = cu.MemcpyHtoD(p, src, bytes)) != CUDA_SUCCESS) {
        cu.MemFree(p);
        return cu_fail(d, "copying to the device", e);
    }
    *out = (uint64_t)p;
    return PK_OK;
}

void cuda_device_free(cuda_device *d, uint64_t p)
{
    if (!p) return;
    cu.CtxSetCurrent(d->pctx);
    cu.MemFree((CUdeviceptr)p);
}

pk_status cuda_device_copy(cuda_device *d, void *host, uint64_t dev, size_t bytes, bool to_device, const char *what)
{
    CUresult e = cu.CtxSetCurrent(d->pctx);
    if (e == CUDA_SUCCESS && bytes)
        e = to_device ? cu.MemcpyHtoD((CUdeviceptr)dev, host, bytes) : cu.MemcpyDtoH(host, (CUdeviceptr)dev, bytes);
    if (e == CUDA_SUCCESS) return PK_OK;
    return cu_fail(d, what ? what : to_device ? "copying to the device" : "copying from the device", e);
}

pk_status cuda_device_kernel(cuda_device *d, const char *name, cuda_kernel *out)
{
    out->fn = NULL;
    out->name = name;
    pk_status st = make_current(d);
    if (st != PK_OK) return st;
    CUfunction f;
    const CUresult e = cu.ModuleGetFunction(&f, d->module, name);
    if (e != CUDA_SUCCESS) return cu_fail(d, "finding the kernels", e);
    out->fn = f;
    return PK_OK;
}

pk_status cuda_device_launch(cuda_device *d, const cuda_kernel *k, unsigned grid, unsigned block, void **params,
                             const char *what)
{
    const CUresult e = cu.LaunchKernel((CUfunction)k->fn, grid, 1, 1, block, 1, 1, 0, NULL, params, NULL);
    if (e == CUDA_SUCCESS) return PK_OK;
    char buf[96];
    if (!what) {
        snprintf(buf, sizeof buf, "the kernel %s", k->name);
        what = buf;
    }
    return cu_fail(d, what, e);
}

pk_status cuda_device_run(cuda_device *d, const char *kernel, size_t threads, unsigned block, void **params,
                          double *ms)
{
    cuda_kernel k;
    pk_status st = cuda_device_kernel(d, kernel, &k);
    if (st != PK_OK) return st;
    const size_t grid = (threads + block - 1) / block;
    if (grid == 0) return PK_OK;
    if (grid > 0x7fffffffu) return ctx_error(d->ctx, PK_ERR_LIMIT, "%s: %zu threads are too many", d->who, threads);
    pthread_mutex_lock(&d->lock);
    CUresult e;
    if ((e = cu.EventRecord(d->ev[0], NULL)) == CUDA_SUCCESS &&
        (e = cu.LaunchKernel((CUfunction)k.fn, (unsigned)grid, 1, 1, block, 1, 1, 0, NULL, params, NULL)) ==
            CUDA_SUCCESS &&
        (e = cu.EventRecord(d->ev[1], NULL)) == CUDA_SUCCESS)
        e = cu.EventSynchronize(d->ev[1]);
    float t = 0.0f;
    if (e == CUDA_SUCCESS && ms) *ms = cu.EventElapsedTime(&t, d->ev[0], d->ev[1]) == CUDA_SUCCESS ? (double)t : 0.0;
    pthread_mutex_unlock(&d->lock);
    if (e != CUDA_SUCCESS) {
        char what[96];
        snprintf(what, sizeof what, "the kernel %s", kernel);
        return cu_fail(d, what, e);
    }
    return PK_OK;
}

pk_status cuda_device_mark(cuda_device *d, int k, const char *what)
{
    const CUresult e = cu.EventRecord(d->ev[k], NULL);
    return e == CUDA_SUCCESS ? PK_OK : cu_fail(d, what, e);
}

pk_status cuda_device_wait(cuda_device *d, int k, const char *what)
{
    const CUresult e = cu.EventSynchronize(d->ev[k]);
    return e == CUDA_SUCCESS ? PK_OK : cu_fail(d, what, e);
}

double cuda_device_elapsed(cuda_device *d, int from, int to)
{
    float t = 0.0f;
    return cu.EventElapsedTime(&t, d->ev[from], d->ev[to]) == CUDA_SUCCESS ? (double)t : 0.0;
}

/*
 * cuda.c - the GPU as an accelerator (--accel cuda): the CPU's wide BVH
 * (accel_bvh_create) converted to the layout of bvh_gpu.h, copied to the
 * device, and batches of rays traced there by the kernels of
 * cuda/trace.cu, one thread per ray, with the traversal functions of
 * bvh_gpu.h. Single rays (the intersect and occluded operations) run the
 * very same functions on the host.
 *
 * Nothing here links against CUDA: the kernels are compiled by nvcc into a
 * fat binary (machine code for sm_80 and sm_90, PTX for later GPUs) that the
 * build embeds as a byte array (pk_cuda_fatbin.h), and the driver,
 * libcuda.so.1, is loaded with dlopen the first time a CUDA accelerator is
 * created; its functions are called through the table cu, filled with
 * dlsym. The few Driver API types and values used are declared here, so
 * the library compiles without CUDA's headers. Without CUDA at build time
 * (PK_HAVE_CUDA 0) only the host side remains and creating one is refused.
 */
#include "accel.h"
#include "bvh_gpu.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(PK_HAVE_CUDA) && PK_HAVE_CUDA
#include "pk_cuda_fatbin.h" /* generated: pk_cuda_fatbin[], pk_cuda_fatbin_size */

#include <dlfcn.h>
#include <omp.h>
#include <pthread.h>

bool accel_cuda_built(void) { return true; }

/* ---- the Driver API, as much of it as is used ------------------------- */

#if defined(PK_CHECK_CUDA_DECLS)
/* A compile-only build of this file (the pk_cuda_decls target) takes the
 * types from CUDA's own header, and the assertions below check that every
 * function pointer here has the type of CUDA's declaration. */
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

#define CUDA_LIBRARY "libcuda.so.1"

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

/* Invariant: after load_once has run, driver_ok says whether every field
 * of cu is set and cuInit succeeded; otherwise load_error says why. The
 * handle is never closed. */
static pthread_once_t load_once = PTHREAD_ONCE_INIT;
static bool driver_ok;
static char load_error[320];

static const char *cu_error(CUresult e)
{
    const char *s = NULL;
    if (cu.GetErrorString && cu.GetErrorString(e, &s) == CUDA_SUCCESS && s) return s;
    return "unknown CUDA error";
}

static void load_driver(void)
{
    /* PAPRSEK_CUDA_LIBRARY names another driver library to load (a path or
     * a soname): for tests, or a driver in a place of its own. */
    const char *name = getenv("PAPRSEK_CUDA_LIBRARY");
    if (!name || !name[0]) name = CUDA_LIBRARY;
    void *h = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *why = dlerror();
        snprintf(load_error, sizeof load_error, "no CUDA driver (%s)", why ? why : name);
        return;
    }
    struct cu_table t;
    void *sym;
#define CU_LOAD(field, symbol, params)                                                                \
    sym = dlsym(h, #symbol);                                                                          \
    if (!sym) {                                                                                       \
        snprintf(load_error, sizeof load_error, "no CUDA driver (%s has no " #symbol ": too old?)", name); \
        dlclose(h);                                                                                   \
        return;                                                                                       \
    }                                                                                                 \
    memcpy(&t.field, &sym, sizeof sym);
    CU_FUNCTIONS(CU_LOAD)
#undef CU_LOAD
    /* CUDA 12.8 renamed it (_v2); older drivers have the first version */
    sym = dlsym(h, "cuEventElapsedTime_v2");
    if (!sym) sym = dlsym(h, "cuEventElapsedTime");
    if (!sym) {
        snprintf(load_error, sizeof load_error, "no CUDA driver (%s has no cuEventElapsedTime)", name);
        dlclose(h);
        return;
    }
    memcpy(&t.EventElapsedTime, &sym, sizeof sym);
    cu = t;
    CUresult e = cu.Init(0);
    if (e == CUDA_ERROR_NO_DEVICE) {
        snprintf(load_error, sizeof load_error, "no CUDA device");
        return;
    }
    if (e != CUDA_SUCCESS) {
        snprintf(load_error, sizeof load_error, "the CUDA driver does not start (cuInit: %s)", cu_error(e));
        return;
    }
    driver_ok = true;
}

static bool driver_loaded(void) { return pthread_once(&load_once, load_driver) == 0 && driver_ok; }

/* Ray and hit buffers hold at most this many rays; longer batches go in chunks. */
#define CHUNK_RAYS ((size_t)1 << 24)

/* The kernel versions of cuda/trace.cu; PAPRSEK_CUDA_KERNEL picks one by
 * name (for timing them against each other: they give the same hits). */
static const char *const kernel_names[] = {"v0", "v1", "v2", "v3", "v4", "v5", "v6", "v7", "v8", "v9"};
#define GPU_TREE_NODE_COST 4.0f
#define KERNEL_DEFAULT 6 /* v6: the fastest on the H100 (docs/gpu.md) */
/* v2, v5, v7, v8 and v9: persistent warps, a ray counter on the device */
static bool kernel_persistent(int k) { return k == 2 || k == 5 || k >= 7; }

/* Invariants:
 *  1. layout is the converted BVH; d_nodes and d_tris hold copies of its
 *     arrays on the device (structure_bytes in all); d_counter is one word
 *     for the persistent kernel's ray counter;
 *  2. d_rays and d_hits hold room for cap rays (0: not allocated yet);
 *  3. the primary context of dev is retained (released by destroy); lock
 *     serialises the batches (the buffers are shared). */
typedef struct cuda_accel {
    accel base;
    pk_context *ctx;          /* where batch errors are latched */
    gpu_layout layout;
    CUdevice dev;
    CUcontext pctx;
    bool retained;
    CUmodule module;
    CUfunction k_closest, k_any;
    int kernel;               /* index in kernel_names */
    unsigned persistent_grid; /* blocks of a persistent launch: as many as the GPU holds at once */
    CUevent ev[4];
    CUdeviceptr d_nodes, d_tris, d_rays, d_hits, d_counter;
    size_t cap;
    pthread_mutex_t lock;
    pk_accel_device_info stats;
} cuda_accel;

static void cuda_destroy(accel *a)
{
    cuda_accel *c = (cuda_accel *)a;
    const pk_allocator *al = a->alloc;
    if (c->retained) {
        cu.CtxSetCurrent(c->pctx);
        if (c->d_nodes) cu.MemFree(c->d_nodes);
        if (c->d_tris) cu.MemFree(c->d_tris);
        if (c->d_rays) cu.MemFree(c->d_rays);
        if (c->d_hits) cu.MemFree(c->d_hits);
        if (c->d_counter) cu.MemFree(c->d_counter);
        for (int i = 0; i < 4; i++)
            if (c->ev[i]) cu.EventDestroy(c->ev[i]);
        if (c->module) cu.ModuleUnload(c->module);
        cu.DevicePrimaryCtxRelease(c->dev);
    }
    pthread_mutex_destroy(&c->lock);
    gpu_layout_free(al, &c->layout);
    mem_free(al, c);
}

static bool cuda_intersect(const accel *a, const ray *r, hit *h, accel_counters *cnt)
{
    const cuda_accel *c = (const cuda_accel *)a;
    gpu_counters g = {0, 0};
    bool found = gpu_trace(c->layout.nodes, c->layout.tris, (const pk_ray *)r, false, (pk_hit *)h, cnt ? &g : NULL);
    if (cnt) cnt->nodes += g.nodes, cnt->tests += g.tests;
    return found;
}

static bool cuda_occluded(const accel *a, const ray *r, hit *h, accel_counters *cnt)
{
    const cuda_accel *c = (const cuda_accel *)a;
    gpu_counters g = {0, 0};
    pk_hit tmp;
    bool found = gpu_trace(c->layout.nodes, c->layout.tris, (const pk_ray *)r, true, h ? (pk_hit *)h : &tmp,
                           cnt ? &g : NULL);
    if (cnt) cnt->nodes += g.nodes, cnt->tests += g.tests;
    return found;
}

static pk_status cu_fail(pk_context *ctx, const char *what, CUresult e)
{
    if (e == CUDA_ERROR_OUT_OF_MEMORY)
        return ctx_error(ctx, PK_ERR_NOMEM, "accelerator 'cuda': %s: out of device memory", what);
    return ctx_error(ctx, PK_ERR_IO, "accelerator 'cuda': %s failed: %s", what, cu_error(e));
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

/* Device buffers for up to want rays; latches an error when they do not fit. */
static pk_status ensure_buffers(cuda_accel *c, size_t want)
{
    if (want <= c->cap) return PK_OK;
    if (c->d_rays) cu.MemFree(c->d_rays);
    if (c->d_hits) cu.MemFree(c->d_hits);
    c->d_rays = c->d_hits = 0;
    c->cap = 0;
    c->stats.device_bytes = c->stats.structure_bytes;
    const size_t need = want * (sizeof(pk_ray) + sizeof(pk_hit));
    size_t free_b = 0, total = 0;
    CUresult e = cu.MemGetInfo(&free_b, &total);
    if (e != CUDA_SUCCESS) return cu_fail(c->ctx, "cuMemGetInfo", e);
    if (need > free_b)
        return ctx_error(c->ctx, PK_ERR_NOMEM,
                         "accelerator 'cuda': not enough device memory for %zu rays: %s needed, %s free of %s", want,
                         size_str(need).s, size_str(free_b).s, size_str(total).s);
    if ((e = cu.MemAlloc(&c->d_rays, want * sizeof(pk_ray))) != CUDA_SUCCESS ||
        (e = cu.MemAlloc(&c->d_hits, want * sizeof(pk_hit))) != CUDA_SUCCESS) {
        if (c->d_rays) cu.MemFree(c->d_rays);
        c->d_rays = 0;
        return ctx_error(c->ctx, PK_ERR_NOMEM, "accelerator 'cuda': cannot allocate %s for %zu rays: %s",
                         size_str(need).s, want, cu_error(e));
    }
    c->cap = want;
    c->stats.device_bytes = c->stats.structure_bytes + need;
    return PK_OK;
}

static void cuda_trace_batch(const accel *a, const ray *rays, hit *hits, size_t n, unsigned flags,
                             pk_trace_counters *counters)
{
    cuda_accel *c = (cuda_accel *)(uintptr_t)a; /* the buffers and timings change; lock serialises */
    const bool any = (flags & PK_TRACE_ANY_HIT) != 0;
    pthread_mutex_lock(&c->lock);
    c->stats.rays_upload_ms = c->stats.kernel_ms = c->stats.download_ms = 0.0;
    pk_status st = PK_OK;
    CUresult e = cu.CtxSetCurrent(c->pctx);
    if (e != CUDA_SUCCESS) st = cu_fail(c->ctx, "cuCtxSetCurrent", e);
    const size_t chunk = n < CHUNK_RAYS ? n : CHUNK_RAYS;
    if (st == PK_OK) st = ensure_buffers(c, chunk);
    for (size_t lo = 0; st == PK_OK && lo < n; lo += chunk) {
        size_t m = n - lo < chunk ? n - lo : chunk;
        unsigned count = (unsigned)m;
        void *params[] = {&c->d_nodes, &c->d_tris, &c->d_rays, &c->d_hits, &count, &c->d_counter};
        const unsigned block = 128;
        unsigned grid = (unsigned)((m + block - 1) / block);
        if (kernel_persistent(c->kernel) && c->persistent_grid < grid) grid = c->persistent_grid;
        const uint32_t zero = 0;
        const char *what = "copying rays to the device";
        if ((e = cu.EventRecord(c->ev[0], NULL)) != CUDA_SUCCESS ||
            (e = cu.MemcpyHtoD(c->d_rays, rays + lo, m * sizeof(pk_ray))) != CUDA_SUCCESS ||
            (e = cu.MemcpyHtoD(c->d_counter, &zero, sizeof zero)) != CUDA_SUCCESS ||
            (e = cu.EventRecord(c->ev[1], NULL)) != CUDA_SUCCESS) {
            st = cu_fail(c->ctx, what, e);
            break;
        }
        what = "the traversal kernel";
        if ((e = cu.LaunchKernel(any ? c->k_any : c->k_closest, grid, 1, 1, block, 1, 1, 0, NULL, params, NULL)) !=
                CUDA_SUCCESS ||
            (e = cu.EventRecord(c->ev[2], NULL)) != CUDA_SUCCESS) {
            st = cu_fail(c->ctx, what, e);
            break;
        }
        what = "copying hits from the device";
        if ((e = cu.MemcpyDtoH(hits + lo, c->d_hits, m * sizeof(pk_hit))) != CUDA_SUCCESS ||
            (e = cu.EventRecord(c->ev[3], NULL)) != CUDA_SUCCESS || (e = cu.EventSynchronize(c->ev[3])) != CUDA_SUCCESS) {
            st = cu_fail(c->ctx, what, e);
            break;
        }
        float t01 = 0.0f, t12 = 0.0f, t23 = 0.0f;
        if (cu.EventElapsedTime(&t01, c->ev[0], c->ev[1]) == CUDA_SUCCESS &&
            cu.EventElapsedTime(&t12, c->ev[1], c->ev[2]) == CUDA_SUCCESS &&
            cu.EventElapsedTime(&t23, c->ev[2], c->ev[3]) == CUDA_SUCCESS) {
            c->stats.rays_upload_ms += (double)t01;
            c->stats.kernel_ms += (double)t12;
            c->stats.download_ms += (double)t23;
        }
    }
    pthread_mutex_unlock(&c->lock);
    if (st != PK_OK) {
        for (size_t i = 0; i < n; i++) hit_clear(&hits[i]);
        return;
    }
    if (counters) {
        /* the device does not count: the same traversal counts on the host */
        const long nn = (long)n;
        uint64_t nodes = 0, tests = 0;
#pragma omp parallel for schedule(dynamic, 1024) reduction(+ : nodes, tests)
        for (long i = 0; i < nn; i++) {
            gpu_counters g = {0, 0};
            pk_hit h;
            gpu_trace(c->layout.nodes, c->layout.tris, (const pk_ray *)&rays[i], any, &h, &g);
            nodes += g.nodes;
            tests += g.tests;
        }
        counters->nodes_visited += nodes;
        counters->intersection_tests += tests;
    }
}

static void cuda_device_info(const accel *a, pk_accel_device_info *info)
{
    cuda_accel *c = (cuda_accel *)(uintptr_t)a;
    pthread_mutex_lock(&c->lock);
    *info = c->stats;
    pthread_mutex_unlock(&c->lock);
}

static const accel_ops cuda_ops = {
    .destroy = cuda_destroy,
    .intersect = cuda_intersect,
    .occluded = cuda_occluded,
    .intersect_packet = NULL,
    .trace_batch = cuda_trace_batch,
    .device_info = cuda_device_info,
};

/* The device side: context, module, structure on the device. */
static pk_status cuda_setup(pk_context *ctx, cuda_accel *c)
{
    CUresult e;
    int count = 0;
    if ((e = cu.DeviceGetCount(&count)) != CUDA_SUCCESS) return cu_fail(ctx, "cuDeviceGetCount", e);
    if (count < 1) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "accelerator 'cuda': no CUDA device");
    if ((e = cu.DeviceGet(&c->dev, 0)) != CUDA_SUCCESS) return cu_fail(ctx, "cuDeviceGet", e);
    if (cu.DeviceGetName(c->stats.device, (int)sizeof c->stats.device, c->dev) != CUDA_SUCCESS)
        snprintf(c->stats.device, sizeof c->stats.device, "CUDA device 0");
    c->stats.device[sizeof c->stats.device - 1] = '\0';
    if ((e = cu.DevicePrimaryCtxRetain(&c->pctx, c->dev)) != CUDA_SUCCESS)
        return cu_fail(ctx, "creating a context on the device", e);
    c->retained = true;
    if ((e = cu.CtxSetCurrent(c->pctx)) != CUDA_SUCCESS) return cu_fail(ctx, "cuCtxSetCurrent", e);
    if ((e = cu.ModuleLoadData(&c->module, pk_cuda_fatbin)) != CUDA_SUCCESS) {
        int major = 0, minor = 0, drv = 0;
        cu.DeviceGetAttribute(&major, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR, c->dev);
        cu.DeviceGetAttribute(&minor, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR, c->dev);
        cu.DriverGetVersion(&drv);
        if (e == CUDA_ERROR_UNSUPPORTED_PTX_VERSION || e == CUDA_ERROR_NO_BINARY_FOR_GPU)
            return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                             "accelerator 'cuda': the kernels, built with CUDA %d.%d, do not run on %s (compute "
                             "capability %d.%d) with driver %d.%d (%s): they need a driver for CUDA %d.%d or newer",
                             PK_CUDA_VERSION_MAJOR, PK_CUDA_VERSION_MINOR, c->stats.device, major, minor, drv / 1000,
                             drv % 1000 / 10, cu_error(e), PK_CUDA_VERSION_MAJOR, PK_CUDA_VERSION_MINOR);
        return cu_fail(ctx, "loading the kernels", e);
    }
    char kname[2][40];
    snprintf(kname[0], sizeof kname[0], "pk_trace_closest_%s", kernel_names[c->kernel]);
    snprintf(kname[1], sizeof kname[1], "pk_trace_any_%s", kernel_names[c->kernel]);
    if ((e = cu.ModuleGetFunction(&c->k_closest, c->module, kname[0])) != CUDA_SUCCESS ||
        (e = cu.ModuleGetFunction(&c->k_any, c->module, kname[1])) != CUDA_SUCCESS)
        return cu_fail(ctx, "finding the kernels", e);
    /* a persistent launch: 2048 threads (16 blocks of 128) per multiprocessor */
    int sms = 0;
    if (cu.DeviceGetAttribute(&sms, CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT, c->dev) != CUDA_SUCCESS || sms < 1)
        sms = 1;
    c->persistent_grid = (unsigned)sms * 16u;
    for (int i = 0; i < 4; i++)
        if ((e = cu.EventCreate(&c->ev[i], 0)) != CUDA_SUCCESS) return cu_fail(ctx, "cuEventCreate", e);
    const size_t bn = c->layout.nnodes * sizeof(gpu_node), bt = (c->layout.ntris ? c->layout.ntris : 1) * sizeof(gpu_tri);
    size_t free_b = 0, total = 0;
    if ((e = cu.MemGetInfo(&free_b, &total)) != CUDA_SUCCESS) return cu_fail(ctx, "cuMemGetInfo", e);
    if (bn + bt > free_b)
        return ctx_error(ctx, PK_ERR_NOMEM,
                         "accelerator 'cuda': not enough device memory for the BVH: %s needed, %s free of %s",
                         size_str(bn + bt).s, size_str(free_b).s, size_str(total).s);
    double t0 = time_now();
    if ((e = cu.MemAlloc(&c->d_nodes, bn)) != CUDA_SUCCESS || (e = cu.MemAlloc(&c->d_tris, bt)) != CUDA_SUCCESS ||
        (e = cu.MemAlloc(&c->d_counter, sizeof(uint32_t))) != CUDA_SUCCESS)
        return ctx_error(ctx, PK_ERR_NOMEM, "accelerator 'cuda': cannot allocate %s for the BVH: %s",
                         size_str(bn + bt).s, cu_error(e));
    if ((e = cu.MemcpyHtoD(c->d_nodes, c->layout.nodes, bn)) != CUDA_SUCCESS ||
        (e = cu.MemcpyHtoD(c->d_tris, c->layout.tris, bt)) != CUDA_SUCCESS || (e = cu.CtxSynchronize()) != CUDA_SUCCESS)
        return cu_fail(ctx, "copying the BVH to the device", e);
    c->stats.upload_ms = (time_now() - t0) * 1e3;
    c->stats.structure_bytes = c->stats.device_bytes = bn + bt;
    return PK_OK;
}

pk_status accel_cuda_create(pk_context *ctx, const accel_input *in, accel **out)
{
    *out = NULL;
    if (in->nspheres)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "accelerator 'cuda': the GPU traces triangles only (the scene has "
                                                  "%zu sphere%s)", in->nspheres, in->nspheres == 1 ? "" : "s");
    /* PAPRSEK_CUDA_KERNEL=v0..v9 picks the kernel version (for timing) */
    int kernel = KERNEL_DEFAULT;
    const char *kv = getenv("PAPRSEK_CUDA_KERNEL");
    if (kv && kv[0]) {
        kernel = -1;
        for (int i = 0; i < (int)(sizeof kernel_names / sizeof *kernel_names); i++)
            if (strcmp(kv, kernel_names[i]) == 0) kernel = i;
        if (kernel < 0)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                             "accelerator 'cuda': PAPRSEK_CUDA_KERNEL=%.40s is not a kernel version (v0 to v9)", kv);
    }
    /* The binary tree collapsed for the GPU: a node visit costs N triangle
     * tests, N = 4 (the fastest on the H100) unless PAPRSEK_CUDA_TREE=N says
     * otherwise; PAPRSEK_CUDA_TREE=cpu takes the CPU's tree */
    bvh_costs costs = {GPU_TREE_NODE_COST, 1, GPU_LEAF_MAX};
    const char *tv = getenv("PAPRSEK_CUDA_TREE");
    if (tv && strcmp(tv, "cpu") == 0) {
        costs.node = 0.0f;
    } else if (tv && tv[0]) {
        char *end = NULL;
        const double v = strtod(tv, &end);
        if (*end || !(v >= 0.25 && v <= 64.0))
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                             "accelerator 'cuda': PAPRSEK_CUDA_TREE=%.40s is not a node cost from 0.25 to 64", tv);
        costs.node = (float)v;
    }
    if (!driver_loaded()) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "accelerator 'cuda': %s", load_error);
    const double t0 = time_now();
    accel *b = NULL;
    pk_status st = accel_bvh_create_costs(ctx, in, costs.node > 0.0f ? &costs : NULL, &b);
    if (st != PK_OK) return st;
    const pk_allocator *al = &ctx->alloc;
    cuda_accel *c = mem_calloc(al, 1, sizeof *c);
    if (!c) {
        accel_destroy(b);
        return ctx_nomem(ctx);
    }
    pthread_mutex_init(&c->lock, NULL);
    c->base.ops = &cuda_ops;
    c->base.alloc = al;
    c->ctx = ctx;
    c->kernel = kernel;
    b->ntris = in->ntris; /* (accel_create sets these after the constructor) */
    b->nspheres = in->nspheres;
    st = gpu_layout_build(ctx, al, b, &c->layout);
    c->base.info = b->info;
    accel_destroy(b);
    if (st != PK_OK) {
        cuda_destroy(&c->base);
        return st;
    }
    c->base.info.name = "cuda";
    c->base.info.build_ms = (time_now() - t0) * 1e3;
    c->base.info.bytes = c->layout.nnodes * sizeof(gpu_node) + c->layout.ntris * sizeof(gpu_tri);
    if ((st = cuda_setup(ctx, c)) != PK_OK) {
        cuda_destroy(&c->base);
        return st;
    }
    *out = &c->base;
    return PK_OK;
}


/* ---- the device, for the module's other kernels (the GPU path tracer) ---------- */

static cuda_accel *as_cuda(const accel *a) { return (cuda_accel *)(uintptr_t)a; }

pk_status cuda_device_alloc(const accel *a, const void *src, size_t bytes, uint64_t *out)
{
    cuda_accel *c = as_cuda(a);
    *out = 0;
    if (bytes == 0) return PK_OK;
    CUresult e = cu.CtxSetCurrent(c->pctx);
    if (e != CUDA_SUCCESS) return cu_fail(c->ctx, "cuCtxSetCurrent", e);
    size_t free_b = 0, total = 0;
    if ((e = cu.MemGetInfo(&free_b, &total)) != CUDA_SUCCESS) return cu_fail(c->ctx, "cuMemGetInfo", e);
    if (bytes > free_b)
        return ctx_error(c->ctx, PK_ERR_NOMEM, "device 'cuda': not enough device memory: %s more needed, %s free of %s",
                         size_str(bytes).s, size_str(free_b).s, size_str(total).s);
    CUdeviceptr p = 0;
    if ((e = cu.MemAlloc(&p, bytes)) != CUDA_SUCCESS)
        return ctx_error(c->ctx, PK_ERR_NOMEM, "device 'cuda': cannot allocate %s: %s", size_str(bytes).s, cu_error(e));
    if (src && (e = cu.MemcpyHtoD(p, src, bytes)) != CUDA_SUCCESS) {
        cu.MemFree(p);
        return cu_fail(c->ctx, "copying the scene to the device", e);
    }
    *out = (uint64_t)p;
    return PK_OK;
}

void cuda_device_free(const accel *a, uint64_t p)
{
    if (!p) return;
    cuda_accel *c = as_cuda(a);
    cu.CtxSetCurrent(c->pctx);
    cu.MemFree((CUdeviceptr)p);
}

pk_status cuda_device_copy(const accel *a, void *host, uint64_t dev, size_t bytes, bool to_device)
{
    cuda_accel *c = as_cuda(a);
    CUresult e = cu.CtxSetCurrent(c->pctx);
    if (e == CUDA_SUCCESS)
        e = to_device ? cu.MemcpyHtoD((CUdeviceptr)dev, host, bytes) : cu.MemcpyDtoH(host, (CUdeviceptr)dev, bytes);
    return e == CUDA_SUCCESS ? PK_OK : cu_fail(c->ctx, to_device ? "copying to the device" : "copying from the device", e);
}

pk_status cuda_device_launch(const accel *a, const char *kernel, size_t threads, unsigned block, void **params,
                             double *ms)
{
    cuda_accel *c = as_cuda(a);
    CUfunction f;
    CUresult e = cu.CtxSetCurrent(c->pctx);
    if (e != CUDA_SUCCESS) return cu_fail(c->ctx, "cuCtxSetCurrent", e);
    if ((e = cu.ModuleGetFunction(&f, c->module, kernel)) != CUDA_SUCCESS)
        return cu_fail(c->ctx, "finding the kernels", e);
    const size_t grid = (threads + block - 1) / block;
    if (grid == 0) return PK_OK;
    if (grid > 0x7fffffffu) return ctx_error(c->ctx, PK_ERR_LIMIT, "device 'cuda': %zu threads are too many", threads);
    pthread_mutex_lock(&c->lock);
    if ((e = cu.EventRecord(c->ev[0], NULL)) == CUDA_SUCCESS &&
        (e = cu.LaunchKernel(f, (unsigned)grid, 1, 1, block, 1, 1, 0, NULL, params, NULL)) == CUDA_SUCCESS &&
        (e = cu.EventRecord(c->ev[1], NULL)) == CUDA_SUCCESS)
        e = cu.EventSynchronize(c->ev[1]);
    float t = 0.0f;
    if (e == CUDA_SUCCESS && ms) *ms = cu.EventElapsedTime(&t, c->ev[0], c->ev[1]) == CUDA_SUCCESS ? (double)t : 0.0;
    pthread_mutex_unlock(&c->lock);
    if (e != CUDA_SUCCESS) {
        char what[96];
        snprintf(what, sizeof what, "the kernel %s", kernel);
        return cu_fail(c->ctx, what, e);
    }
    return PK_OK;
}

void cuda_device_bvh(const accel *a, uint64_t *nodes, uint64_t *tris)
{
    const cuda_accel *c = as_cuda(a);
    *nodes = (uint64_t)c->d_nodes;
    *tris = (uint64_t)c->d_tris;
}

const char *cuda_device_name(const accel *a) { return as_cuda(a)->stats.device; }

#else /* no CUDA at build time */

bool accel_cuda_built(void) { return false; }

pk_status accel_cuda_create(pk_context *ctx, const accel_input *in, accel **out)
{
    (void)in;
    *out = NULL;
    return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                     "accelerator 'cuda' is not available in this build (configure where nvcc is, with -DPK_WITH_CUDA=ON)");
}


pk_status cuda_device_alloc(const accel *a, const void *src, size_t bytes, uint64_t *out)
{
    (void)a, (void)src, (void)bytes;
    *out = 0;
    return PK_ERR_UNSUPPORTED;
}
void cuda_device_free(const accel *a, uint64_t p) { (void)a, (void)p; }
pk_status cuda_device_copy(const accel *a, void *host, uint64_t dev, size_t bytes, bool to_device)
{
    (void)a, (void)host, (void)dev, (void)bytes, (void)to_device;
    return PK_ERR_UNSUPPORTED;
}
pk_status cuda_device_launch(const accel *a, const char *kernel, size_t threads, unsigned block, void **params,
                             double *ms)
{
    (void)a, (void)kernel, (void)threads, (void)block, (void)params, (void)ms;
    return PK_ERR_UNSUPPORTED;
}
void cuda_device_bvh(const accel *a, uint64_t *nodes, uint64_t *tris)
{
    (void)a;
    *nodes = *tris = 0;
}
const char *cuda_device_name(const accel *a)
{
    (void)a;
    return "";
}

#endif

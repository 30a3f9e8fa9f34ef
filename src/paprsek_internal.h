/*
 * paprsek_internal.h - what every module shares: the context (allocator,
 * error latch, warnings), checked allocation helpers and the hidden-symbol
 * macro. Nothing here is part of the public interface.
 */
#ifndef PAPRSEK_INTERNAL_H
#define PAPRSEK_INTERNAL_H

#include "paprsek.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define PK_HIDDEN __attribute__((visibility("hidden")))
#define PK_PRINTF(a, b) __attribute__((format(printf, a, b)))
#define PK_LIKELY(x) __builtin_expect(!!(x), 1)
#define PK_UNLIKELY(x) __builtin_expect(!!(x), 0)
#else
#define PK_HIDDEN
#define PK_PRINTF(a, b)
#define PK_LIKELY(x) (x)
#define PK_UNLIKELY(x) (x)
#endif

#include "pk_hd.h"

#ifdef NDEBUG
#define PK_ASSERT(x) ((void)0)
#else
#include <assert.h>
#define PK_ASSERT(x) assert(x)
#endif

#define PK_ERRMSG_MAX 512

/* The context's configuration (pk_context_set_config, config.c): what the
 * back ends read when an accelerator or a device is created. The library
 * reads no environment variable; programs pass what they read as config. */
#define PK_CONFIG_NAME_MAX 256
typedef struct pk_config {
    bool cpu_avx2;        /* cpu.isa=avx2: the BVH's AVX2 kernels even where the CPU has AVX-512 */
    bool bvh_fast;        /* bvh.quality=fast: the BVH without spatial splits */
    int embree_quality;   /* embree.quality: 0 low, 1 medium (default), 2 high */
    char embree_library[PK_CONFIG_NAME_MAX]; /* embree.library: "" for libembree3.so.3 */
    char cuda_library[PK_CONFIG_NAME_MAX];   /* cuda.library: "" for libcuda.so.1 */
    char dnnl_library[PK_CONFIG_NAME_MAX];   /* dnnl.library: "" for libdnnl.so.2 (the denoiser) */
    char openvdb_module[PK_CONFIG_NAME_MAX]; /* openvdb.module: "" for the installed one (device/module.h) */
    char cuda_module[PK_CONFIG_NAME_MAX];    /* cuda.module: "" for the installed one (device/cuda_kernels.h) */
    int instances;        /* scene.instances: 0 auto, 1 flatten every instance, 2 keep them (scene_commit) */
    int cuda_traversal;   /* cuda.traversal: 0 sorted (default), 1 ordered (bvh_gpu.h gpu_trace_ordered) */
    int cuda_leaf;        /* cuda.leaf: the GPU tree's largest leaf, 0: 16 (default), 1: 8, 2: 4 triangles */
    char draco_module[PK_CONFIG_NAME_MAX];   /* draco.module: "" for the installed one (io/gltf_draco_module.h) */
} pk_config;

/* Invariants:
 *  1. status == PK_OK exactly when message[0] == '\0'.
 *  2. Once set, status and message stay until pk_context_clear_error. */
struct pk_context {
    pk_allocator alloc;
    pk_status status;
    char message[PK_ERRMSG_MAX];
    pk_warning_fn warn;
    void *warn_user;
    pk_file_reader_fn read_file; /* NULL: files are read from the file system */
    void *read_file_user;
    pk_config config;            /* zeroed: every key at its default */
};

/* The libraries loaded for Embree and CUDA: the configured name or the
 * default soname (ctx may be NULL: the defaults). */
PK_HIDDEN const char *config_embree_library(const pk_context *ctx);
PK_HIDDEN const char *config_cuda_library(const pk_context *ctx);
PK_HIDDEN const char *config_dnnl_library(const pk_context *ctx);

/* ---- allocation: every library allocation goes through the context's hook */

/* NULL on failure or on size 0. */
PK_HIDDEN void *mem_alloc(const pk_allocator *a, size_t size);
/* Zeroed; count*size is overflow-checked. */
PK_HIDDEN void *mem_calloc(const pk_allocator *a, size_t count, size_t size);
/* count*size overflow-checked; on failure the old block is kept and NULL returned. */
PK_HIDDEN void *mem_realloc_array(const pk_allocator *a, void *ptr, size_t count, size_t size);
PK_HIDDEN void mem_free(const pk_allocator *a, void *ptr);
/* Aligned block (align a power of two <= 256); free with mem_free_aligned. */
PK_HIDDEN void *mem_alloc_aligned(const pk_allocator *a, size_t size, size_t align);
PK_HIDDEN void mem_free_aligned(const pk_allocator *a, void *ptr);
PK_HIDDEN char *mem_strdup(const pk_allocator *a, const char *s);
PK_HIDDEN char *mem_strndup(const pk_allocator *a, const char *s, size_t n);
/* Grows *ptr so that it holds at least need elements (capacity doubles).
 * Returns false (leaving *ptr and *cap unchanged) on overflow or failure. */
PK_HIDDEN bool mem_grow(const pk_allocator *a, void **ptr, size_t *cap, size_t need, size_t elem);

/* true when a*b overflows size_t; otherwise *out = a*b. */
static inline bool size_mul_overflows(size_t a, size_t b, size_t *out)
{
    if (b != 0 && a > SIZE_MAX / b) return true;
    *out = a * b;
    return false;
}

/* ---- errors and warnings -------------------------------------------- */

/* Latches the first error (later ones are ignored) and returns status. */
PK_HIDDEN pk_status ctx_error(pk_context *ctx, pk_status status, const char *fmt, ...) PK_PRINTF(3, 4);
PK_HIDDEN pk_status ctx_errorv(pk_context *ctx, pk_status status, const char *fmt, va_list ap);
/* Records PK_ERR_NOMEM with a generic message. */
PK_HIDDEN pk_status ctx_nomem(pk_context *ctx);
PK_HIDDEN void ctx_warn(pk_context *ctx, const char *fmt, ...) PK_PRINTF(2, 3);

/* ---- files ------------------------------------------------------------ */

/* Reads a whole file (at most PK_MAX_FILE_BYTES) into a NUL-terminated buffer
 * owned by the caller (mem_free). Errors are latched in ctx. */
PK_HIDDEN pk_status file_read_all(pk_context *ctx, const char *path, char **data, size_t *size);
/* True when file_read_all would find a file at path: a regular file, or one
 * the context's file reader gives. Latches nothing. */
PK_HIDDEN bool file_exists(pk_context *ctx, const char *path);
/* Directory part of path ("." when none), caller frees. */
PK_HIDDEN char *path_dirname(const pk_allocator *a, const char *path);
/* dir + "/" + rel (rel kept when absolute), caller frees. */
PK_HIDDEN char *path_join(const pk_allocator *a, const char *dir, const char *rel);
/* Wall clock in seconds (monotonic). */
PK_HIDDEN double time_now(void);

#endif

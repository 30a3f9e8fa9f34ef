/*
 * config.c - the context's configuration (pk_context_set_config): one table
 * of keys, each with its parser and printer, so that what is accepted, what
 * is reported (pk_context_get_config, --stats) and the defaults cannot
 * drift apart.
 */
#include "paprsek_internal.h"

#include <stdio.h>
#include <string.h>

#define EMBREE_DEFAULT "libembree3.so.3"
#define CUDA_DEFAULT "libcuda.so.1"
#define DNNL_DEFAULT "libdnnl.so.2"

static const char *const isa_names[] = {"auto", "avx2"};
static const char *const bvh_names[] = {"high", "fast"};
static const char *const embree_names[] = {"low", "medium", "high"};
static const char *const instance_names[] = {"auto", "flatten", "keep"};
static const char *const traversal_names[] = {"sorted", "ordered"};
static const char *const leaf_names[] = {"16", "8", "4"};

/* A choice among names: its index, or -1. */
static int choose(const char *v, size_t n, const char *const *names, size_t count)
{
    for (size_t i = 0; i < count; i++)
        if (strlen(names[i]) == n && strncmp(v, names[i], n) == 0) return (int)i;
    return -1;
}

typedef enum {
    KEY_ISA, KEY_BVH, KEY_EMBREE_QUALITY, KEY_EMBREE_LIBRARY, KEY_CUDA_LIBRARY, KEY_DNNL_LIBRARY, KEY_INSTANCES,
    KEY_CUDA_TRAVERSAL, KEY_CUDA_LEAF, KEY_OPENVDB_MODULE, KEY_CUDA_MODULE, KEY_DRACO_MODULE, NKEYS
} key_id;

static const char *const key_names[NKEYS] = {"cpu.isa",      "bvh.quality",  "embree.quality",  "embree.library",
                                             "cuda.library", "dnnl.library", "scene.instances",
                                             "cuda.traversal", "cuda.leaf",    "openvdb.module", "cuda.module",
                                             "draco.module"};

/* Sets key k of c from the value v[0..n-1] (n 0: the default); false with a
 * message in ctx when the value is not one the key takes. */
static bool set_key(pk_context *ctx, pk_config *c, key_id k, const char *v, size_t n)
{
    int i = 0;
    switch (k) {
    case KEY_ISA:
        if (n && (i = choose(v, n, isa_names, 2)) < 0) goto bad;
        c->cpu_avx2 = i == 1;
        return true;
    case KEY_BVH:
        if (n && (i = choose(v, n, bvh_names, 2)) < 0) goto bad;
        c->bvh_fast = i == 1;
        return true;
    case KEY_EMBREE_QUALITY:
        i = 1;
        if (n && (i = choose(v, n, embree_names, 3)) < 0) goto bad;
        c->embree_quality = i;
        return true;
    case KEY_INSTANCES:
        if (n && (i = choose(v, n, instance_names, 3)) < 0) goto bad;
        c->instances = i;
        return true;
    case KEY_CUDA_TRAVERSAL:
        if (n && (i = choose(v, n, traversal_names, 2)) < 0) goto bad;
        c->cuda_traversal = i;
        return true;
    case KEY_CUDA_LEAF:
        if (n && (i = choose(v, n, leaf_names, 3)) < 0) goto bad;
        c->cuda_leaf = i;
        return true;
    case KEY_EMBREE_LIBRARY:
    case KEY_CUDA_LIBRARY:
    case KEY_DNNL_LIBRARY:
    case KEY_OPENVDB_MODULE:
    case KEY_CUDA_MODULE:
    case KEY_DRACO_MODULE: {
        char *dst = k == KEY_CUDA_LIBRARY     ? c->cuda_library
                    : k == KEY_DNNL_LIBRARY   ? c->dnnl_library
                    : k == KEY_OPENVDB_MODULE ? c->openvdb_module
                    : k == KEY_CUDA_MODULE    ? c->cuda_module
                    : k == KEY_DRACO_MODULE   ? c->draco_module
                                              : c->embree_library;
        if (n >= PK_CONFIG_NAME_MAX) {
            ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "config: %s: a library name of %zu bytes (at most %d)",
                      key_names[k], n, PK_CONFIG_NAME_MAX - 1);
            return false;
        }
        memcpy(dst, v, n);
        dst[n] = '\0';
        return true;
    }
    case NKEYS: break;
    }
bad:
    ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "config: %s=%.*s: expected %s", key_names[k], (int)(n > 64 ? 64 : n), v,
              k == KEY_ISA               ? "auto or avx2"
              : k == KEY_BVH           ? "high or fast"
              : k == KEY_INSTANCES     ? "auto, flatten or keep"
              : k == KEY_CUDA_TRAVERSAL ? "sorted or ordered"
              : k == KEY_CUDA_LEAF     ? "16, 8 or 4"
                                       : "low, medium or high");
    return false;
}

static bool blank(char ch) { return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r'; }

pk_status pk_context_set_config(pk_context *ctx, const char *config)
{
    if (!ctx) return PK_ERR_INVALID_ARGUMENT;
    if (!config) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "config: NULL");
    pk_config c = ctx->config; /* changed only when every item is good */
    for (const char *p = config; *p;) {
        const char *end = strchr(p, ',');
        if (!end) end = p + strlen(p);
        const char *a = p, *b = end;
        p = *end ? end + 1 : end;
        while (a < b && blank(*a)) a++;
        while (b > a && blank(b[-1])) b--;
        if (a == b) continue; /* an empty item */
        const char *eq = memchr(a, '=', (size_t)(b - a));
        const char *kend = eq ? eq : b;
        while (kend > a && blank(kend[-1])) kend--;
        int k = -1;
        for (int i = 0; i < NKEYS; i++)
            if (strlen(key_names[i]) == (size_t)(kend - a) && strncmp(a, key_names[i], (size_t)(kend - a)) == 0) k = i;
        if (k < 0)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                             "config: unknown key '%.*s' (cpu.isa, bvh.quality, embree.quality, embree.library, "
                             "cuda.library, dnnl.library, scene.instances, cuda.traversal, cuda.leaf, openvdb.module, cuda.module, draco.module)", (int)(kend - a > 64 ? 64 : kend - a), a);
        if (!eq) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "config: %s: expected %s=VALUE", key_names[k], key_names[k]);
        const char *v = eq + 1;
        while (v < b && blank(*v)) v++;
        if (!set_key(ctx, &c, (key_id)k, v, (size_t)(b - v))) return PK_ERR_INVALID_ARGUMENT;
    }
    ctx->config = c;
    return PK_OK;
}

const char *config_embree_library(const pk_context *ctx)
{
    return ctx && ctx->config.embree_library[0] ? ctx->config.embree_library : EMBREE_DEFAULT;
}

const char *config_cuda_library(const pk_context *ctx)
{
    return ctx && ctx->config.cuda_library[0] ? ctx->config.cuda_library : CUDA_DEFAULT;
}

const char *config_dnnl_library(const pk_context *ctx)
{
    return ctx && ctx->config.dnnl_library[0] ? ctx->config.dnnl_library : DNNL_DEFAULT;
}

size_t pk_context_get_config(const pk_context *ctx, char *buf, size_t size)
{
    static const pk_config defaults = {false, false, 1, "", "", "", "", "", 0, 0, 0, ""};
    const pk_config *c = ctx ? &ctx->config : &defaults;
    int n = snprintf(buf, size, "cpu.isa=%s,bvh.quality=%s,embree.quality=%s,embree.library=%s,cuda.library=%s,"
                     "dnnl.library=%s,scene.instances=%s,cuda.traversal=%s,cuda.leaf=%s,openvdb.module=%s,cuda.module=%s,"
                     "draco.module=%s",
                     isa_names[c->cpu_avx2], bvh_names[c->bvh_fast], embree_names[c->embree_quality],
                     config_embree_library(ctx), config_cuda_library(ctx), config_dnnl_library(ctx),
                     instance_names[c->instances >= 0 && c->instances < 3 ? c->instances : 0],
                     traversal_names[c->cuda_traversal == 1], leaf_names[c->cuda_leaf >= 0 && c->cuda_leaf < 3 ? c->cuda_leaf : 0],
                     c->openvdb_module, c->cuda_module, c->draco_module);
    return n < 0 ? 0 : (size_t)n;
}

/*
 * context.c - the context (error latch, warnings), allocation through the
 * context's hook, whole-file reading and small path helpers.
 */
#include "paprsek_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static void *default_realloc(void *user, void *ptr, size_t size)
{
    (void)user;
    if (size == 0) {
        free(ptr);
        return NULL;
    }
    return realloc(ptr, size);
}

void *mem_alloc(const pk_allocator *a, size_t size)
{
    if (size == 0) return NULL;
    return a->realloc(a->user, NULL, size);
}

void *mem_calloc(const pk_allocator *a, size_t count, size_t size)
{
    size_t total;
    if (size_mul_overflows(count, size, &total) || total == 0) return NULL;
    void *p = a->realloc(a->user, NULL, total);
    if (p) memset(p, 0, total);
    return p;
}

void *mem_realloc_array(const pk_allocator *a, void *ptr, size_t count, size_t size)
{
    size_t total;
    if (size_mul_overflows(count, size, &total) || total == 0) return NULL;
    return a->realloc(a->user, ptr, total);
}

void mem_free(const pk_allocator *a, void *ptr)
{
    if (ptr) a->realloc(a->user, ptr, 0);
}

void *mem_alloc_aligned(const pk_allocator *a, size_t size, size_t align)
{
    if (size == 0 || align == 0 || (align & (align - 1)) || align > 256 || size > SIZE_MAX - align)
        return NULL;
    unsigned char *raw = mem_alloc(a, size + align);
    if (!raw) return NULL;
    size_t off = align - ((uintptr_t)raw & (align - 1)); /* 1..align */
    raw[off - 1] = (unsigned char)(off - 1);
    return raw + off;
}

void mem_free_aligned(const pk_allocator *a, void *ptr)
{
    if (!ptr) return;
    unsigned char *p = ptr;
    mem_free(a, p - 1 - p[-1]);
}

char *mem_strndup(const pk_allocator *a, const char *s, size_t n)
{
    char *d = mem_alloc(a, n + 1);
    if (!d) return NULL;
    memcpy(d, s, n);
    d[n] = '\0';
    return d;
}

char *mem_strdup(const pk_allocator *a, const char *s) { return mem_strndup(a, s, strlen(s)); }

bool mem_grow(const pk_allocator *a, void **ptr, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return true;
    size_t ncap = *cap ? *cap : 16;
    while (ncap < need) {
        if (ncap > SIZE_MAX / 2) return false;
        ncap *= 2;
    }
    void *p = mem_realloc_array(a, *ptr, ncap, elem);
    if (!p) return false;
    *ptr = p;
    *cap = ncap;
    return true;
}

/* ---- context ------------------------------------------------------------ */

pk_status pk_context_create(const pk_allocator *alloc, pk_context **out)
{
    if (!out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_allocator a = {default_realloc, NULL};
    if (alloc) {
        if (!alloc->realloc) return PK_ERR_INVALID_ARGUMENT;
        a = *alloc;
    }
    pk_context *ctx = a.realloc(a.user, NULL, sizeof *ctx);
    if (!ctx) return PK_ERR_NOMEM;
    memset(ctx, 0, sizeof *ctx);
    ctx->alloc = a;
    ctx->config.embree_quality = 1; /* medium; the other keys' defaults are zero */
    *out = ctx;
    return PK_OK;
}

void pk_context_destroy(pk_context *ctx)
{
    if (!ctx) return;
    pk_allocator a = ctx->alloc;
    a.realloc(a.user, ctx, 0);
}

const char *pk_context_error(const pk_context *ctx) { return ctx ? ctx->message : "no context"; }
pk_status pk_context_status(const pk_context *ctx) { return ctx ? ctx->status : PK_ERR_INVALID_ARGUMENT; }

void pk_context_clear_error(pk_context *ctx)
{
    if (!ctx) return;
    ctx->status = PK_OK;
    ctx->message[0] = '\0';
}

void pk_context_set_warning_handler(pk_context *ctx, pk_warning_fn fn, void *user)
{
    if (!ctx) return;
    ctx->warn = fn;
    ctx->warn_user = user;
}

void pk_context_set_file_reader(pk_context *ctx, pk_file_reader_fn fn, void *user)
{
    if (!ctx) return;
    ctx->read_file = fn;
    ctx->read_file_user = fn ? user : NULL;
}

const char *pk_status_string(pk_status status)
{
    switch (status) {
    case PK_OK: return "ok";
    case PK_ERR_INVALID_ARGUMENT: return "invalid argument";
    case PK_ERR_IO: return "input/output error";
    case PK_ERR_PARSE: return "parse error";
    case PK_ERR_LIMIT: return "limit exceeded";
    case PK_ERR_NOMEM: return "out of memory";
    case PK_ERR_UNSUPPORTED: return "not supported";
    case PK_ERR_CANCELLED: return "cancelled";
    case PK_ERR_EMPTY_SCENE: return "nothing to render";
    }
    return "unknown status";
}

pk_status ctx_errorv(pk_context *ctx, pk_status status, const char *fmt, va_list ap)
{
    if (!ctx || status == PK_OK) return status;
    if (ctx->status != PK_OK) return status;
    ctx->status = status;
    vsnprintf(ctx->message, sizeof ctx->message, fmt, ap);
    if (!ctx->message[0]) snprintf(ctx->message, sizeof ctx->message, "%s", pk_status_string(status));
    return status;
}

pk_status ctx_error(pk_context *ctx, pk_status status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    ctx_errorv(ctx, status, fmt, ap);
    va_end(ap);
    return status;
}

pk_status ctx_nomem(pk_context *ctx) { return ctx_error(ctx, PK_ERR_NOMEM, "out of memory"); }

void ctx_warn(pk_context *ctx, const char *fmt, ...)
{
    if (!ctx || !ctx->warn) return;
    char buf[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    ctx->warn(ctx->warn_user, buf);
}

/* ---- files -------------------------------------------------------------- */

/* A file through the context's reader: its bytes copied into a buffer of
 * the library's own, or its failure latched as "path: reason". */
static pk_status read_through_hook(pk_context *ctx, const char *path, char **data, size_t *size)
{
    const void *bytes = NULL;
    size_t n = 0;
    char why[PK_ERRMSG_MAX];
    why[0] = '\0';
    pk_status st = ctx->read_file(ctx->read_file_user, path, &bytes, &n, why, sizeof why);
    why[sizeof why - 1] = '\0';
    if (st != PK_OK) {
        if (st == PK_ERR_NOMEM) return ctx_nomem(ctx);
        return ctx_error(ctx, st, "%s: %s", path, why[0] ? why : "the file reader does not have this file");
    }
    if (!bytes && n > 0) return ctx_error(ctx, PK_ERR_IO, "%s: the file reader gave no bytes", path);
    if (n > PK_MAX_FILE_BYTES)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: file is larger than %zu bytes", path, (size_t)PK_MAX_FILE_BYTES);
    char *buf = mem_alloc(&ctx->alloc, n + 1);
    if (!buf) return ctx_nomem(ctx);
    if (n) memcpy(buf, bytes, n);
    buf[n] = '\0';
    *data = buf;
    *size = n;
    return PK_OK;
}

bool file_exists(pk_context *ctx, const char *path)
{
    if (ctx->read_file) {
        const void *bytes = NULL;
        size_t n = 0;
        char why[PK_ERRMSG_MAX];
        return ctx->read_file(ctx->read_file_user, path, &bytes, &n, why, sizeof why) == PK_OK;
    }
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

pk_status file_read_all(pk_context *ctx, const char *path, char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    if (ctx->read_file) return read_through_hook(ctx, path, data, size);
    /* O_NONBLOCK: opening a FIFO (mtllib /some/fifo) must not wait for a
     * writer; it is refused below like any file that is not regular. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return ctx_error(ctx, PK_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return ctx_error(ctx, PK_ERR_IO, "%s: not a regular file", path);
    }
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        close(fd);
        return ctx_nomem(ctx);
    }
    if ((unsigned long long)st.st_size > (unsigned long long)PK_MAX_FILE_BYTES) {
        fclose(f);
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: file is larger than %zu bytes", path, (size_t)PK_MAX_FILE_BYTES);
    }
    size_t n = (size_t)st.st_size;
    char *buf = mem_alloc(&ctx->alloc, n + 1);
    if (!buf) {
        fclose(f);
        return ctx_nomem(ctx);
    }
    size_t got = n ? fread(buf, 1, n, f) : 0;
    int err = ferror(f);
    fclose(f);
    if (got != n || err) {
        mem_free(&ctx->alloc, buf);
        return ctx_error(ctx, PK_ERR_IO, "%s: read error", path);
    }
    buf[n] = '\0';
    *data = buf;
    *size = n;
    return PK_OK;
}

char *path_dirname(const pk_allocator *a, const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return mem_strdup(a, ".");
    if (slash == path) return mem_strdup(a, "/");
    return mem_strndup(a, path, (size_t)(slash - path));
}

char *path_join(const pk_allocator *a, const char *dir, const char *rel)
{
    if (rel[0] == '/' || !dir || !dir[0]) return mem_strdup(a, rel);
    size_t ld = strlen(dir), lr = strlen(rel);
    char *p = mem_alloc(a, ld + lr + 2);
    if (!p) return NULL;
    memcpy(p, dir, ld);
    p[ld] = '/';
    memcpy(p + ld + 1, rel, lr + 1);
    return p;
}

double time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

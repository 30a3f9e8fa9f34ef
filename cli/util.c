/*
 * util.c - small helpers shared by the paprsek subcommands: messages, strict
 * number parsing and the check that an output file can be written.
 */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

const char *cli_program = "paprsek";

int cli_fail_ctx(pk_context *ctx)
{
    const char *msg = pk_context_error(ctx);
    fprintf(stderr, "%s: %s\n", cli_program, msg && msg[0] ? msg : "unknown error");
    return 1;
}

int cli_usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s: ", cli_program);
    vfprintf(stderr, fmt, ap);
    fputs("\n", stderr);
    va_end(ap);
    return 2;
}

int cli_failure(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s: ", cli_program);
    vfprintf(stderr, fmt, ap);
    fputs("\n", stderr);
    va_end(ap);
    return 1;
}

int cli_parse_int(const char *s, long lo, long hi, int *out)
{
    if (!s || !*s) return 0;
    errno = 0;
    char *end;
    long v = strtol(s, &end, 10);
    if (errno || *end || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

int cli_parse_vec3(const char *s, float out[3])
{
    if (!s) return 0;
    const char *p = s;
    for (int i = 0; i < 3; i++) {
        errno = 0;
        char *end;
        float v = strtof(p, &end);
        if (end == p || errno || !isfinite(v)) return 0;
        out[i] = v;
        p = end;
        if (i < 2) {
            if (*p != ',') return 0;
            p++;
        }
    }
    return *p == '\0';
}

void cli_print_warning(void *user, const char *message)
{
    (void)user;
    fprintf(stderr, "%s: warning: %s\n", cli_program, message);
}

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int cli_check_output(const char *path, int replace_by_rename)
{
    struct stat sb;
    if (stat(path, &sb) == 0) {
        if (S_ISDIR(sb.st_mode)) return cli_failure("%s: is a folder; name a file in it", path);
        if (!replace_by_rename) {
            if (access(path, W_OK) == 0) return 0;
            return cli_failure("%s: cannot write: %s", path, strerror(errno));
        }
    }
    /* The folder: what is before the last '/' (without trailing slashes),
     * "/" for a file at the root, "." for a bare name. */
    size_t n = strlen(path);
    char *dir = malloc(n + 2);
    if (!dir) return cli_failure("%s: out of memory", path);
    const char *slash = strrchr(path, '/');
    if (!slash) {
        strcpy(dir, ".");
    } else {
        size_t k = (size_t)(slash - path);
        while (k > 0 && path[k - 1] == '/') k--;
        if (k == 0) k = 1; /* the root */
        memcpy(dir, path, k);
        dir[k] = '\0';
    }
    int rc = 0;
    if (stat(dir, &sb) != 0) {
        if (errno == ENOENT)
            rc = cli_failure("%s: folder '%s' does not exist", path, dir);
        else if (errno == ENOTDIR)
            rc = cli_failure("%s: folder '%s' does not exist (part of its path is a file)", path, dir);
        else
            rc = cli_failure("%s: folder '%s': %s", path, dir, strerror(errno));
    } else if (!S_ISDIR(sb.st_mode)) {
        rc = cli_failure("%s: '%s' is not a folder", path, dir);
    } else if (access(dir, W_OK) != 0) {
        rc = cli_failure("%s: cannot write in folder '%s': %s", path, dir, strerror(errno));
    }
    free(dir);
    return rc;
}

/* ---- the library's config ---------------------------------------------------- */

/* The library reads no environment variable; the program reads the ones it
 * always honoured and passes them on as config keys. */
static const struct {
    const char *var, *key;
    const char *only; /* the one value that counts (others were always ignored), or NULL: any */
} config_vars[] = {
    {"PAPRSEK_CPU_ISA", "cpu.isa", "avx2"},
    {"PAPRSEK_BVH_QUALITY", "bvh.quality", "fast"},
    {"PAPRSEK_EMBREE_QUALITY", "embree.quality", NULL},
    {"PAPRSEK_EMBREE_LIBRARY", "embree.library", NULL},
    {"PAPRSEK_CUDA_LIBRARY", "cuda.library", NULL},
};

/* The library's message without its "config: " prefix. */
static const char *config_message(pk_context *ctx)
{
    const char *m = pk_context_error(ctx);
    return strncmp(m, "config: ", 8) == 0 ? m + 8 : m;
}

int cli_configure(pk_context *ctx, const char *config)
{
    for (size_t i = 0; i < sizeof config_vars / sizeof config_vars[0]; i++) {
        const char *v = getenv(config_vars[i].var);
        if (!v || !v[0] || (config_vars[i].only && strcmp(v, config_vars[i].only) != 0)) continue;
        if (strchr(v, ','))
            return cli_usage_error("%s=%s: a comma cannot be passed on to the library", config_vars[i].var, v);
        char item[1024];
        snprintf(item, sizeof item, "%s=%s", config_vars[i].key, v);
        if (pk_context_set_config(ctx, item) != PK_OK) {
            const int rc = cli_usage_error("%s: %s", config_vars[i].var, config_message(ctx));
            pk_context_clear_error(ctx);
            return rc;
        }
    }
    if (config && pk_context_set_config(ctx, config) != PK_OK) {
        const int rc = cli_usage_error("--config: %s", config_message(ctx));
        pk_context_clear_error(ctx);
        return rc;
    }
    return 0;
}

int cli_check_config(const char *config)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return cli_failure("out of memory");
    const int rc = cli_configure(ctx, config);
    pk_context_destroy(ctx);
    return rc;
}

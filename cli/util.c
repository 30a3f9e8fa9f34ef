/*
 * util.c - small helpers shared by the paprsek subcommands: messages and
 * strict number parsing.
 */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

int cli_fail_ctx(pk_context *ctx)
{
    const char *msg = pk_context_error(ctx);
    fprintf(stderr, "paprsek: %s\n", msg && msg[0] ? msg : "unknown error");
    return 1;
}

int cli_usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("paprsek: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputs("\n", stderr);
    va_end(ap);
    return 2;
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
    fprintf(stderr, "paprsek: warning: %s\n", message);
}

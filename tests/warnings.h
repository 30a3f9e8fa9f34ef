/*
 * warnings.h - a context's warnings captured for a test to check: attach a
 * warning_log to a context, then ask how many warnings came and whether
 * one says something. The first WARNING_LOG_KEEP messages are kept one by
 * one (msg), every message in `all` (one a line) until it is full; the
 * count goes on.
 */
#ifndef PK_TEST_WARNINGS_H
#define PK_TEST_WARNINGS_H

#include "paprsek.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#define WARNING_LOG_KEEP 64

typedef struct warning_log {
    int count;
    bool echo;                       /* also print each warning on stderr */
    char last[1024];
    char msg[WARNING_LOG_KEEP][512]; /* the first messages */
    char all[16384];                 /* every message, one a line */
} warning_log;

static void warning_log_fn(void *user, const char *message)
{
    warning_log *w = user;
    if (w->count < WARNING_LOG_KEEP) snprintf(w->msg[w->count], sizeof w->msg[0], "%s", message);
    w->count++;
    snprintf(w->last, sizeof w->last, "%s", message);
    const size_t n = strlen(w->all);
    snprintf(w->all + n, sizeof w->all - n, "%s\n", message);
    if (w->echo) fprintf(stderr, "  warning: %s\n", message);
}

/* Empties w and turns echo off (set it after warning_log_attach). */
static inline void warning_log_clear(warning_log *w)
{
    w->count = 0;
    w->echo = false;
    w->last[0] = w->all[0] = '\0';
    for (int i = 0; i < WARNING_LOG_KEEP; i++) w->msg[i][0] = '\0';
}

/* Clears w and sends ctx's warnings to it. */
static inline void warning_log_attach(pk_context *ctx, warning_log *w)
{
    warning_log_clear(w);
    pk_context_set_warning_handler(ctx, warning_log_fn, w);
}

/* How many of the kept messages contain part. */
static inline int warning_log_count(const warning_log *w, const char *part)
{
    int n = 0;
    for (const char *s = w->all; *s;) {
        const char *eol = strchr(s, '\n');
        const size_t len = eol ? (size_t)(eol - s) : strlen(s);
        char line[2048];
        snprintf(line, sizeof line, "%.*s", (int)len, s);
        n += strstr(line, part) != NULL;
        s += len + (eol != NULL);
    }
    return n;
}

static inline bool warning_log_has(const warning_log *w, const char *part) { return strstr(w->all, part) != NULL; }

#endif

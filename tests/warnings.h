/*
 * warnings.h - a context's warnings captured for a test to check: attach a
 * warning_log to a context, then ask how many warnings came and whether
 * one says something. Every message is kept (in order, one a line) until
 * the text is full; the count goes on.
 */
#ifndef PK_TEST_WARNINGS_H
#define PK_TEST_WARNINGS_H

#include "paprsek.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

typedef struct warning_log {
    int count;
    bool echo;          /* also print each warning on stderr */
    char last[1024];
    char text[16384];   /* every message, one a line */
} warning_log;

static void warning_log_fn(void *user, const char *message)
{
    warning_log *w = user;
    w->count++;
    snprintf(w->last, sizeof w->last, "%s", message);
    const size_t n = strlen(w->text);
    snprintf(w->text + n, sizeof w->text - n, "%s\n", message);
    if (w->echo) fprintf(stderr, "  warning: %s\n", message);
}

static inline void warning_log_clear(warning_log *w)
{
    w->count = 0;
    w->last[0] = w->text[0] = '\0';
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
    for (const char *s = w->text; *s;) {
        const char *eol = strchr(s, '\n');
        const size_t len = eol ? (size_t)(eol - s) : strlen(s);
        char line[2048];
        snprintf(line, sizeof line, "%.*s", (int)len, s);
        n += strstr(line, part) != NULL;
        s += len + (eol != NULL);
    }
    return n;
}

static inline bool warning_log_has(const warning_log *w, const char *part) { return strstr(w->text, part) != NULL; }

#endif

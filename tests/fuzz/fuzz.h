/*
 * fuzz.h - the libFuzzer entry point every harness defines. Harnesses are
 * linked either with libFuzzer (make fuzz) or with replay.c, which runs a
 * corpus through them as an ordinary test.
 */
#ifndef PK_FUZZ_H
#define PK_FUZZ_H

#include "paprsek.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A warning handler that reads the whole message, so that the formatting of
 * every warning runs (without a handler the library skips it) and ASan sees
 * a message that is not NUL-terminated. */
static inline void fuzz_warning(void *user, const char *message)
{
    size_t *total = (size_t *)user;
    size_t n = 0;
    while (message[n]) n++;
    *total += n;
}

/* Every failure must leave its message in the context (paprsek.h): a status
 * without one is a finding. */
static inline void fuzz_check_error(const pk_context *ctx, pk_status st)
{
    if (st == PK_OK) return;
    if (pk_context_status(ctx) == PK_OK || pk_context_error(ctx)[0] == '\0') {
        fprintf(stderr, "fuzz: status %d (%s) without a message\n", (int)st, pk_status_string(st));
        abort();
    }
}

#endif

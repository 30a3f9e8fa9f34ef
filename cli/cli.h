/*
 * cli.h - the pieces of the paprsek program, built on include/paprsek.h alone.
 */
#ifndef PK_CLI_H
#define PK_CLI_H

#include "paprsek.h"

/* `paprsek render ...` (cli/render.c). argv[0] is "render". Returns the exit status. */
int cli_render(int argc, char **argv);
/* `paprsek bench rays|gen-rays ...` (cli/bench.c). argv[0] is "bench". */
int cli_bench(int argc, char **argv);

/* Shared helpers (cli/util.c). */
/* Prints "paprsek: <ctx error>" to stderr and returns 1. */
int cli_fail_ctx(pk_context *ctx);
/* Prints "paprsek: <fmt>" to stderr and returns 2 (usage errors). */
int cli_usage_error(const char *fmt, ...);
/* Parses an int in [lo, hi]; false on junk or out of range. */
int cli_parse_int(const char *s, long lo, long hi, int *out);
/* Parses "x,y,z"; false on junk or non-finite values. */
int cli_parse_vec3(const char *s, float out[3]);
/* Prints warnings from the library to stderr as "paprsek: warning: ...". */
void cli_print_warning(void *user, const char *message);

#endif

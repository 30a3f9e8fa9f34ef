/*
 * view_server.h - the server of `paprsek view` (cli/view_server.c): a render
 * thread that refines the image pass after pass, and an HTTP server
 * (libmicrohttpd) that serves the page, the current image, its updates and
 * the camera and settings (docs/viewer.md). A unit of its own, so that the
 * program (cli/view.c) and the tests (tests/view) run the same server.
 */
#ifndef PK_VIEW_SERVER_H
#define PK_VIEW_SERVER_H

#include "paprsek.h"

#include <stddef.h>
#include <stdio.h>
#include <stdint.h>

#define VIEW_MAX_BODY (64 * 1024)  /* bytes of a request body; more is refused with 413 */
#define VIEW_DEFAULT_MAX_SPP 1024  /* samples per pixel after which the image is left as it is */
#define VIEW_PREVIEW_FACTOR 4      /* the first pass after a change: 1 sample per pixel at 1/4 of the size */
#define VIEW_KEEPALIVE_S 15        /* seconds between ": keepalive" lines of the event stream */

typedef struct view_config {
    pk_context *ctx;        /* the scene's context; the render thread uses it (borrowed) */
    pk_scene *scene;        /* borrowed; unchanged while the server runs */
    const char *scene_name; /* shown by the page ("name" in /api/status) */
    /* The render: size, threads, device, integrator, max_depth, ... Each
     * pass adds ro.spp samples per pixel (1 is the interactive choice). */
    pk_render_options ro;
    int max_spp;            /* stop refining at this many samples per pixel; 0: VIEW_DEFAULT_MAX_SPP */
    const char *bind;       /* an IPv4 address; NULL: 127.0.0.1 */
    int port;               /* 0: a free one */
    int require_token;      /* 1: a token on every request (always so for an address other than 127.x.x.x) */
    float exposure;         /* the initial exposure, stops */
    int tonemap;            /* the initial tone curve, PK_TONEMAP_* */
    int denoise;            /* denoise from the start (needs dopt) */
    const pk_denoise_options *dopt; /* NULL: no denoiser here; denoise cannot be turned on */
    const char *no_denoise_why;     /* with dopt NULL: why (said in the 400) */
    pk_warning_fn warn;     /* the warning handler the program set on ctx (NULL: none) */
    void *warn_user;
} view_config;

typedef struct view_server view_server;

/* Builds the renderers, starts the render thread and the HTTP server.
 * Returns 0, or 1 after writing why into err (cap bytes). */
int view_server_start(const view_config *cfg, view_server **out, char *err, size_t cap);
/* The port listened on (the one chosen when cfg.port was 0). */
int view_server_port(const view_server *s);
/* The page's address: http://ADDR:PORT/, with ?token=T when a token is required. */
const char *view_server_url(const view_server *s);
/* The token ("" when none is required). */
const char *view_server_token(const view_server *s);
/* Stops the HTTP server (open event streams end), cancels the render and
 * frees everything but the borrowed context and scene. NULL: nothing. */
void view_server_stop(view_server *s);
/* The same, but waits at most seconds for the render thread, which cannot
 * stop in the middle of a denoising: returns 0 when all is stopped and
 * freed, 1 when the thread was still busy (the HTTP server is stopped; the
 * rest is left for the process's exit, which should follow). */
int view_server_stop_within(view_server *s, double seconds);

/* `paprsek view ...` (cli/view.c). argv[0] is "view". Returns the exit status. */
int cli_view(int argc, char **argv);
void cli_view_help(FILE *f);

#endif

/*
 * view_server.c - the server of `paprsek view` (view_server.h).
 *
 * One render thread owns the renderers (the full-size one and the small one
 * of the first pass after a change) and the film; it renders pass after
 * pass and publishes each displayable image as a snapshot (a frame). The
 * HTTP server (libmicrohttpd, a thread per connection) answers from the
 * shared state under one mutex: requests change the wanted camera and
 * settings and wake the render thread, which cancels its pass (the
 * renderer's cancel flag, checked per tile) when accumulation restarts.
 * Images are encoded on demand, once per frame, through the library's
 * writers into a private temporary folder and served from memory.
 */
#include "view_server.h"

#include "cli.h"
#include "view_page.h"

#include <arpa/inet.h>
#include <cjson/cJSON.h>
#include <dlfcn.h>
#include <errno.h>
#include <math.h>
#include <microhttpd.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* libmicrohttpd is loaded when a viewer starts (mhd_load), not linked: a
 * program linked against it loads it, GnuTLS and their dependencies on
 * every run (some 2,800 symbol relocations, 3.7 M instructions under
 * callgrind before main), which `paprsek render` never needs. The calls
 * below go through this table, filled from the library (by the prototypes
 * of <microhttpd.h>, so that a mismatch does not compile). */
static struct {
    __typeof__(MHD_start_daemon) *start_daemon;
    __typeof__(MHD_stop_daemon) *stop_daemon;
    __typeof__(MHD_get_daemon_info) *get_daemon_info;
    __typeof__(MHD_lookup_connection_value) *lookup_connection_value;
    __typeof__(MHD_create_response_from_buffer) *create_response_from_buffer;
    __typeof__(MHD_create_response_from_callback) *create_response_from_callback;
    __typeof__(MHD_add_response_header) *add_response_header;
    __typeof__(MHD_queue_response) *queue_response;
    __typeof__(MHD_destroy_response) *destroy_response;
} mhd;
#define MHD_start_daemon mhd.start_daemon
#define MHD_stop_daemon mhd.stop_daemon
#define MHD_get_daemon_info mhd.get_daemon_info
#define MHD_lookup_connection_value mhd.lookup_connection_value
#define MHD_create_response_from_buffer mhd.create_response_from_buffer
#define MHD_create_response_from_callback mhd.create_response_from_callback
#define MHD_add_response_header mhd.add_response_header
#define MHD_queue_response mhd.queue_response
#define MHD_destroy_response mhd.destroy_response

/* Loads libmicrohttpd and fills mhd once per process; false with the
 * reason in err (cap bytes) when it cannot. */
static bool mhd_load(char *err, size_t cap)
{
    static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    static bool ready;
    pthread_mutex_lock(&lock);
    if (!ready) {
        static const char *const names[] = {"libmicrohttpd.so.12", "libmicrohttpd.so"};
        void *h = NULL;
        for (size_t i = 0; i < sizeof names / sizeof names[0] && !h; i++) h = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
        if (!h) {
            const char *e = dlerror();
            snprintf(err, cap, "paprsek view needs GNU libmicrohttpd (Debian: libmicrohttpd12), which could not be loaded (%s)",
                     e ? e : "not found");
            pthread_mutex_unlock(&lock);
            return false;
        }
        bool ok = true;
#define MHD_SYM(field, sym)                                          \
    if (ok && !(*(void **)&mhd.field = dlsym(h, sym))) {             \
        snprintf(err, cap, "libmicrohttpd has no %s: too old?", sym); \
        ok = false;                                                  \
    }
        MHD_SYM(start_daemon, "MHD_start_daemon")
        MHD_SYM(stop_daemon, "MHD_stop_daemon")
        MHD_SYM(get_daemon_info, "MHD_get_daemon_info")
        MHD_SYM(lookup_connection_value, "MHD_lookup_connection_value")
        MHD_SYM(create_response_from_buffer, "MHD_create_response_from_buffer")
        MHD_SYM(create_response_from_callback, "MHD_create_response_from_callback")
        MHD_SYM(add_response_header, "MHD_add_response_header")
        MHD_SYM(queue_response, "MHD_queue_response")
        MHD_SYM(destroy_response, "MHD_destroy_response")
#undef MHD_SYM
        if (!ok) {
            dlclose(h);
            pthread_mutex_unlock(&lock);
            return false;
        }
        ready = true; /* the handle stays open: the daemons' threads run its code */
    }
    pthread_mutex_unlock(&lock);
    return true;
}

/* ---- snapshots: one displayable image and its encodings -------------------- */

enum { AOV_COLOR = 0 }; /* else a PK_AOV_* */

typedef struct snap {
    int refs;          /* under view_server.mu */
    uint64_t frame;
    pk_image *img;     /* width x height, linear: the colour (denoised or not) or the AOV's values */
    unsigned aov;
    float exposure;
    int tonemap;       /* PK_TONEMAP_* of the PNG */
    pk_image *alpha;   /* the coverage when the colour is premultiplied (transparent background), else NULL */
    pthread_mutex_t enc_mu; /* guards the encodings */
    unsigned char *png, *exr;
    size_t png_len, exr_len;
} snap;

struct view_server {
    view_config cfg;
    int width, height, max_spp;
    char bind[INET_ADDRSTRLEN];
    int loopback;
    int port;
    char token[33];  /* "" when none is required */
    char url[128];
    char allowed_host[2][80]; /* "ADDR:PORT", "localhost:PORT" (loopback only) */
    int nallowed;
    char tmpdir[256];
    int denoise_available;

    pthread_mutex_t mu;
    pthread_cond_t work;   /* the render thread waits here for something to do */
    pthread_cond_t frames; /* event streams wait here for a new frame */
    int quit;

    /* wanted state (under mu) */
    pk_camera cam, initial_cam;
    uint64_t restart_gen;  /* bumped by every change that restarts accumulation */
    uint64_t rebuild_gen;  /* bumped by an integrator or max_depth change */
    int integrator;        /* pk_integrator_kind, never DEFAULT */
    int max_depth;         /* -1: the integrator's default */
    float exposure;
    int tonemap;           /* PK_TONEMAP_* */
    int transparent;       /* the environment seen by the camera has alpha 0 */
    int denoise;
    unsigned aov;
    int display_dirty;     /* exposure, tone curve, aov or denoise changed: make the display again */

    /* what the render thread reports (under mu) */
    snap *cur;             /* the latest frame (NULL before the first) */
    uint64_t frame;
    uint32_t passes;
    double t_restart, t_last;
    double rays_per_s;
    int rendering;

    /* the renderers: replaced by the render thread under rlock (written),
     * used by pick under rlock (read) */
    pthread_rwlock_t rlock;
    pk_renderer *r_full, *r_prev;
    volatile int cancel;

    pthread_t thread;
    int thread_started;
    int thread_done;       /* the render thread has left its loop (under mu) */
    struct MHD_Daemon *daemon;
    unsigned long enc_counter; /* temporary file names (under mu) */
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void snap_unref_locked(snap *p)
{
    if (!p || --p->refs > 0) return;
    pk_image_destroy(p->img);
    pk_image_destroy(p->alpha);
    free(p->png);
    free(p->exr);
    pthread_mutex_destroy(&p->enc_mu);
    free(p);
}

/* The latest frame with a reference, or NULL. */
static snap *snap_get(view_server *s)
{
    pthread_mutex_lock(&s->mu);
    snap *p = s->cur;
    if (p) p->refs++;
    pthread_mutex_unlock(&s->mu);
    return p;
}

static void snap_put(view_server *s, snap *p)
{
    pthread_mutex_lock(&s->mu);
    snap_unref_locked(p);
    pthread_mutex_unlock(&s->mu);
}

/* The whole file at path into memory (malloc'ed); NULL on failure. */
static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (cap - n < 65536) {
            size_t nc = cap ? 2 * cap : 1 << 20;
            unsigned char *nb = realloc(buf, nc);
            if (!nb) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = nb;
            cap = nc;
        }
        size_t k = fread(buf + n, 1, cap - n, f);
        n += k;
        if (k == 0) break;
    }
    const int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

/* For the 8-bit image only (as `paprsek render --aov` writes PNGs): normals
 * from [-1, 1] to [0, 1], depth divided by its largest value, the heat map
 * on a blue-green-red scale between its smallest and largest value. */
static void aov_to_display(pk_image *img, unsigned aov)
{
    float *px = pk_image_pixels(img);
    const size_t n = (size_t)pk_image_width(img) * (size_t)pk_image_height(img);
    if (aov == PK_AOV_NORMAL) {
        for (size_t i = 0; i < 3 * n; i++) px[i] = 0.5f * px[i] + 0.5f;
        return;
    }
    if (aov != PK_AOV_DEPTH && aov != PK_AOV_HEATMAP) return;
    float lo = INFINITY, hi = 0.0f;
    for (size_t i = 0; i < n; i++) {
        lo = fminf(lo, px[3 * i]);
        hi = fmaxf(hi, px[3 * i]);
    }
    for (size_t i = 0; i < n; i++) {
        if (aov == PK_AOV_DEPTH) {
            const float v = hi > 0.0f ? px[3 * i] / hi : 0.0f;
            px[3 * i] = px[3 * i + 1] = px[3 * i + 2] = v;
            continue;
        }
        const float t = hi > lo ? (px[3 * i] - lo) / (hi - lo) : 0.0f;
        px[3 * i] = t > 0.5f ? 2.0f * t - 1.0f : 0.0f;
        px[3 * i + 1] = t < 0.5f ? 2.0f * t : 2.0f - 2.0f * t;
        px[3 * i + 2] = t < 0.5f ? 1.0f - 2.0f * t : 0.0f;
    }
}

/* Encodes the frame as PNG (exr 0) or EXR (exr 1) once; the bytes stay in
 * the snapshot. Written by the library's writer (a temporary file renamed
 * into place) in the server's own folder, read back and removed. Returns 0,
 * or 1 with why. */
static int snap_encode(view_server *s, snap *p, int exr, char *why, size_t cap)
{
    pthread_mutex_lock(&p->enc_mu);
    if (exr ? p->exr != NULL : p->png != NULL) {
        pthread_mutex_unlock(&p->enc_mu);
        return 0;
    }
    pthread_mutex_lock(&s->mu);
    const unsigned long k = s->enc_counter++;
    pthread_mutex_unlock(&s->mu);
    char path[320];
    snprintf(path, sizeof path, "%s/frame-%lu.%s", s->tmpdir, k, exr ? "exr" : "png");
    pk_context *ctx = NULL;
    int rc = 1;
    pk_image *copy = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) {
        snprintf(why, cap, "out of memory");
        goto out;
    }
    pk_write_options wo;
    pk_write_options_init(&wo);
    const pk_image *src = p->img;
    if (exr && p->aov == AOV_COLOR) wo.alpha = p->alpha;
    if (!exr) {
        if (p->aov == AOV_COLOR) {
            wo.exposure_ev = p->exposure;
            wo.tonemap = p->tonemap;
            wo.alpha = p->alpha;
        } else {
            const int w = pk_image_width(p->img), h = pk_image_height(p->img);
            if (pk_image_create(ctx, w, h, &copy) != PK_OK) {
                snprintf(why, cap, "%s", pk_context_error(ctx));
                goto out;
            }
            memcpy(pk_image_pixels(copy), pk_image_pixels_const(p->img), (size_t)w * (size_t)h * 3 * sizeof(float));
            aov_to_display(copy, p->aov);
            src = copy;
        }
    }
    if (pk_image_write_ex(ctx, src, path, &wo) != PK_OK) {
        snprintf(why, cap, "%s", pk_context_error(ctx));
        goto out;
    }
    size_t len = 0;
    unsigned char *bytes = slurp(path, &len);
    unlink(path);
    if (!bytes) {
        snprintf(why, cap, "%s: cannot read back the image", path);
        goto out;
    }
    if (exr) {
        p->exr = bytes;
        p->exr_len = len;
    } else {
        p->png = bytes;
        p->png_len = len;
    }
    rc = 0;
out:
    pk_image_destroy(copy);
    pk_context_destroy(ctx);
    pthread_mutex_unlock(&p->enc_mu);
    return rc;
}

/* ---- status JSON ------------------------------------------------------------ */

typedef struct sbuf {
    char *p;
    size_t n, cap;
    int oom;
} sbuf;

static void sb_printf(sbuf *b, const char *fmt, ...)
{
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const int k = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            b->oom = 1;
            return;
        }
        if (b->p && (size_t)k < b->cap - b->n) {
            b->n += (size_t)k;
            return;
        }
        size_t nc = b->cap ? b->cap : 1024;
        while (nc < b->n + (size_t)k + 1) nc *= 2;
        char *np = realloc(b->p, nc);
        if (!np) {
            b->oom = 1;
            return;
        }
        b->p = np;
        b->cap = nc;
    }
}

static void sb_string(sbuf *b, const char *s)
{
    sb_printf(b, "\"");
    for (; *s; s++) {
        const unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            sb_printf(b, "\\%c", c);
        else if (c < 0x20)
            sb_printf(b, "\\u%04x", c);
        else
            sb_printf(b, "%c", c);
    }
    sb_printf(b, "\"");
}

/* A float as the shortest decimal that reads back as the same float
 * (0.278, not 0.277999997). */
static void sb_float(sbuf *b, float x)
{
    char t[32];
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(t, sizeof t, "%.*g", digits, (double)x);
        if (strtof(t, NULL) == x) break;
    }
    sb_printf(b, "%s", t);
}

static void sb_floats(sbuf *b, const float *x, int n)
{
    sb_printf(b, "[");
    for (int i = 0; i < n; i++) {
        if (i) sb_printf(b, ",");
        sb_float(b, x[i]);
    }
    sb_printf(b, "]");
}

static void sb_camera(sbuf *b, const pk_camera *c)
{
    sb_printf(b, "{\"look_from\":");
    sb_floats(b, c->look_from, 3);
    sb_printf(b, ",\"look_at\":");
    sb_floats(b, c->look_at, 3);
    sb_printf(b, ",\"up\":");
    sb_floats(b, c->up, 3);
    sb_printf(b, ",\"fov\":");
    sb_float(b, c->fov_deg);
    sb_printf(b, ",\"lens_radius\":");
    sb_float(b, c->lens_radius);
    sb_printf(b, ",\"focus_distance\":");
    sb_float(b, c->focus_distance);
    sb_printf(b, "}");
}

static const char *aov_label(unsigned aov) { return aov == AOV_COLOR ? "color" : pk_aov_name(aov); }

static const char *integrator_label(int k)
{
    return k == PK_INTEGRATOR_WHITTED ? "whitted" : k == PK_INTEGRATOR_VOLPATH ? "volpath" : "path";
}

/* The status as JSON (malloc'ed), under mu. */
static char *status_json_locked(view_server *s)
{
    sbuf b = {0};
    const double end = s->rendering ? now_s() : s->t_last;
    pk_render_options ro = s->cfg.ro;
    ro.integrator = s->integrator;
    ro.max_depth = s->max_depth;
    sb_printf(&b,
              "{\"frame\":%llu,\"spp\":%llu,\"passes\":%u,\"width\":%d,\"height\":%d,\"elapsed_s\":%.3f,"
              "\"rays_per_s\":%.0f,\"rendering\":%s,\"scene\":",
              (unsigned long long)s->frame, (unsigned long long)s->passes * (unsigned long long)s->cfg.ro.spp,
              s->passes, s->width, s->height, end > s->t_restart ? end - s->t_restart : 0.0, s->rays_per_s,
              s->rendering ? "true" : "false");
    sb_string(&b, s->cfg.scene_name ? s->cfg.scene_name : "");
    sb_printf(&b, ",\"camera\":");
    sb_camera(&b, &s->cam);
    sb_printf(&b, ",\"settings\":{\"exposure\":");
    sb_float(&b, s->exposure);
    sb_printf(&b, ",\"denoise\":%s,\"aov\":\"%s\",\"integrator\":\"%s\",\"max_depth\":%d",
              s->denoise ? "true" : "false", aov_label(s->aov), integrator_label(s->integrator),
              pk_render_options_max_depth(&ro));
    sb_printf(&b, ",\"tonemap\":\"%s\",\"transparent\":%s}", pk_tonemap_name(s->tonemap),
              s->transparent ? "true" : "false");
    sb_printf(&b, ",\"initial_camera\":");
    sb_camera(&b, &s->initial_cam);
    sb_printf(&b, ",\"denoise_available\":%s}", s->denoise_available ? "true" : "false");
    if (b.oom) {
        free(b.p);
        return NULL;
    }
    return b.p;
}

/* ---- the render thread ------------------------------------------------------ */

typedef struct rstate {
    pk_film *film, *pfilm;
    pk_image *den;        /* the denoised colour of den_passes passes, NULL when none */
    uint32_t den_passes;
    int den_failed;       /* the denoiser failed: denoising is turned off */
    double den_cost, den_end;
    pk_denoiser *denoiser;
    int transparent;      /* the renderers' pk_render_options.transparent: the colour is premultiplied */
} rstate;

/* The renderers for the settings (integrator, max_depth); on failure the
 * old ones stay and the error is printed. */
static pk_status make_renderers(view_server *s, int integrator, int max_depth, int transparent, pk_renderer **full,
                                pk_renderer **prev)
{
    pk_render_options ro = s->cfg.ro;
    ro.transparent = transparent;
    ro.integrator = integrator;
    ro.max_depth = max_depth;
    ro.cancel = &s->cancel;
    ro.progress = NULL;
    ro.collect_stats = 1; /* rays per second */
    *full = *prev = NULL;
    pk_status st = pk_renderer_create(s->cfg.ctx, s->cfg.scene, &ro, full);
    if (st != PK_OK) return st;
    ro.width = (s->width + VIEW_PREVIEW_FACTOR - 1) / VIEW_PREVIEW_FACTOR;
    ro.height = (s->height + VIEW_PREVIEW_FACTOR - 1) / VIEW_PREVIEW_FACTOR;
    ro.spp = 1;
    /* the warnings were given for the full-size renderer */
    pk_context_set_warning_handler(s->cfg.ctx, NULL, NULL);
    st = pk_renderer_create(s->cfg.ctx, s->cfg.scene, &ro, prev);
    pk_context_set_warning_handler(s->cfg.ctx, s->cfg.warn, s->cfg.warn_user);
    if (st != PK_OK) {
        pk_renderer_destroy(*full);
        *full = NULL;
    }
    return st;
}

/* The preview's image (pw x ph) scaled to the full size, nearest pixel. */
static pk_image *upscale(pk_context *ctx, const pk_image *small, int w, int h)
{
    pk_image *img = NULL;
    if (pk_image_create(ctx, w, h, &img) != PK_OK) return NULL;
    const int pw = pk_image_width(small), ph = pk_image_height(small);
    const float *sp = pk_image_pixels_const(small);
    float *dp = pk_image_pixels(img);
    for (int y = 0; y < h; y++) {
        const int sy = (int)((long long)y * ph / h);
        for (int x = 0; x < w; x++) {
            const int sx = (int)((long long)x * pw / w);
            memcpy(dp + 3 * ((size_t)y * (size_t)w + (size_t)x), sp + 3 * ((size_t)sy * (size_t)pw + (size_t)sx),
                   3 * sizeof(float));
        }
    }
    return img;
}

static pk_image *copy_image(pk_context *ctx, const pk_image *src)
{
    pk_image *img = NULL;
    if (pk_image_create(ctx, pk_image_width(src), pk_image_height(src), &img) != PK_OK) return NULL;
    memcpy(pk_image_pixels(img), pk_image_pixels_const(src),
           (size_t)pk_image_width(src) * (size_t)pk_image_height(src) * 3 * sizeof(float));
    return img;
}

/* The image to show from film (the preview's when preview), for aov;
 * the denoised colour when den is given. NULL on failure (printed). */
static pk_image *display_image(view_server *s, const pk_film *film, int preview, unsigned aov, const pk_image *den);

/* The coverage of film (scaled up from the preview's) when the colour is
 * premultiplied (a transparent background) and shown; else NULL. */
static pk_image *display_alpha(view_server *s, const pk_film *film, int preview, unsigned aov, int transparent)
{
    if (!transparent || aov != AOV_COLOR) return NULL;
    return display_image(s, film, preview, PK_AOV_ALPHA, NULL);
}

static pk_image *display_image(view_server *s, const pk_film *film, int preview, unsigned aov, const pk_image *den)
{
    pk_context *ctx = s->cfg.ctx;
    pk_image *img = NULL;
    if (aov == AOV_COLOR && den) return copy_image(ctx, den);
    pk_status st = aov == AOV_COLOR ? pk_film_resolve(ctx, film, &img) : pk_film_resolve_aov(ctx, film, aov, &img);
    if (st != PK_OK) {
        fprintf(stderr, "paprsek: view: %s\n", pk_context_error(ctx));
        pk_context_clear_error(ctx);
        return NULL;
    }
    if (preview) {
        pk_image *big = upscale(ctx, img, s->width, s->height);
        pk_image_destroy(img);
        img = big;
    }
    return img;
}

/* Publishes img (taken) as the next frame. Under mu. */
static void publish_locked(view_server *s, pk_image *img, pk_image *alpha, unsigned aov, float exposure, int tonemap)
{
    snap *p = calloc(1, sizeof *p);
    if (!p) {
        pk_image_destroy(img);
        pk_image_destroy(alpha);
        return;
    }
    p->refs = 1;
    p->img = img;
    p->alpha = alpha;
    p->aov = aov;
    p->exposure = exposure;
    p->tonemap = tonemap;
    pthread_mutex_init(&p->enc_mu, NULL);
    p->frame = ++s->frame;
    snap_unref_locked(s->cur);
    s->cur = p;
    pthread_cond_broadcast(&s->frames);
}

/* Denoises the film's colour into st->den. 0 on success. */
static int run_denoise(view_server *s, rstate *st, uint32_t passes)
{
    pk_context *ctx = s->cfg.ctx;
    const double t0 = now_s();
    pk_image *img = NULL;
    if (pk_film_resolve(ctx, st->film, &img) != PK_OK) goto fail;
    if (!st->denoiser && pk_denoiser_create(ctx, s->cfg.dopt, &st->denoiser) != PK_OK) goto fail;
    pk_image *alb = NULL, *nrm = NULL;
    pk_status rs = pk_film_resolve_aov(ctx, st->film, PK_AOV_ALBEDO, &alb);
    if (rs == PK_OK) rs = pk_film_resolve_aov(ctx, st->film, PK_AOV_NORMAL, &nrm);
    if (rs == PK_OK) rs = pk_denoiser_run(st->denoiser, img, alb, nrm, img);
    pk_image_destroy(alb);
    pk_image_destroy(nrm);
    if (rs != PK_OK) goto fail;
    pk_image_destroy(st->den);
    st->den = img;
    st->den_passes = passes;
    st->den_end = now_s();
    st->den_cost = st->den_end - t0;
    return 0;
fail:
    pk_image_destroy(img);
    fprintf(stderr, "paprsek: view: denoising failed, and is turned off: %s\n", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    st->den_failed = 1;
    return 1;
}

enum { JOB_NONE, JOB_PREVIEW, JOB_PASS, JOB_DENOISE, JOB_DISPLAY };

static uint64_t rays_of(const pk_stats *st)
{
    return st->rays_camera + st->rays_shadow + st->rays_reflection + st->rays_refraction + st->rays_bounce;
}

static void *render_main(void *arg)
{
    view_server *s = arg;
    pk_context *ctx = s->cfg.ctx;
    rstate st = {0};
    const unsigned all_aovs = PK_AOV_ALBEDO | PK_AOV_NORMAL | PK_AOV_DEPTH | PK_AOV_HEATMAP | PK_AOV_ALPHA;
    st.transparent = s->transparent; /* what the renderers were made with */
    pk_render_options po;
    pk_renderer_get_options(s->r_prev, &po);
    if (pk_film_create_aovs(ctx, s->width, s->height, all_aovs, &st.film) != PK_OK ||
        pk_film_create_aovs(ctx, po.width, po.height, all_aovs, &st.pfilm) != PK_OK) {
        fprintf(stderr, "paprsek: view: %s\n", pk_context_error(ctx));
        pk_context_clear_error(ctx);
        pthread_mutex_lock(&s->mu);
        s->rendering = 0;
        pthread_mutex_unlock(&s->mu);
        pk_film_destroy(st.film);
        pk_film_destroy(st.pfilm);
        return NULL;
    }
    uint64_t restart_done = 0, rebuild_done = 0;
    uint32_t passes = 0;
    int stage = 0; /* 0: the preview is next; 1: full passes */
    pk_camera cam = s->initial_cam; /* replaced at the first restart, under the lock */
    uint64_t rays0 = 0;
    double render_s0 = 0.0;
    pthread_mutex_lock(&s->mu);
    for (;;) {
        if (s->quit) break;
        if (s->rebuild_gen != rebuild_done) {
            rebuild_done = s->rebuild_gen;
            const int integrator = s->integrator, depth = s->max_depth, transparent = s->transparent;
            s->rendering = 1;
            pthread_mutex_unlock(&s->mu);
            pk_renderer *full, *prev;
            if (make_renderers(s, integrator, depth, transparent, &full, &prev) != PK_OK) {
                fprintf(stderr, "paprsek: view: %s\n", pk_context_error(ctx));
                pk_context_clear_error(ctx);
            } else {
                pthread_rwlock_wrlock(&s->rlock);
                pk_renderer_destroy(s->r_full);
                pk_renderer_destroy(s->r_prev);
                s->r_full = full;
                s->r_prev = prev;
                st.transparent = transparent;
                pthread_rwlock_unlock(&s->rlock);
            }
            pthread_mutex_lock(&s->mu);
            continue;
        }
        if (s->restart_gen != restart_done) {
            restart_done = s->restart_gen;
            cam = s->cam;
            passes = 0;
            stage = 0;
            pk_image_destroy(st.den);
            st.den = NULL;
            s->passes = 0;
            s->t_restart = s->t_last = now_s();
            s->rays_per_s = 0.0;
            pk_stats ps;
            pk_renderer_get_stats(s->r_full, &ps);
            rays0 = rays_of(&ps);
            render_s0 = ps.render_s;
        }
        const unsigned aov = s->aov;
        const float exposure = s->exposure;
        const int tonemap = s->tonemap;
        const int denoise = s->denoise && s->cfg.dopt;
        int job;
        const int more = (uint64_t)passes * (uint64_t)s->cfg.ro.spp < (uint64_t)s->max_spp;
        if (stage == 0)
            job = JOB_PREVIEW;
        else if (more)
            job = JOB_PASS;
        else if (denoise && aov == AOV_COLOR && (!st.den || st.den_passes != passes))
            job = JOB_DENOISE;
        else if (s->display_dirty)
            job = JOB_DISPLAY;
        else
            job = JOB_NONE;
        if (job == JOB_NONE) {
            s->rendering = 0;
            pthread_cond_wait(&s->work, &s->mu);
            continue;
        }
        const int dirty = s->display_dirty;
        s->display_dirty = 0;
        s->rendering = 1;
        s->cancel = 0;
        pthread_mutex_unlock(&s->mu);

        pk_status rs = PK_OK;
        pk_image *img = NULL, *alpha = NULL;
        int show = 1;
        if (job == JOB_PREVIEW) {
            pk_film_clear(st.pfilm);
            pk_film_clear(st.film);
            rs = pk_renderer_set_camera(s->r_prev, &cam);
            if (rs == PK_OK) rs = pk_renderer_set_camera(s->r_full, &cam);
            pk_renderer_set_pass(s->r_prev, 0);
            if (rs == PK_OK) rs = pk_renderer_render(s->r_prev, NULL, 0, st.pfilm);
            if (rs == PK_OK) {
                stage = 1;
                img = display_image(s, st.pfilm, 1, aov, NULL);
                alpha = display_alpha(s, st.pfilm, 1, aov, st.transparent);
            }
        } else if (job == JOB_PASS) {
            pk_renderer_set_pass(s->r_full, passes);
            rs = pk_renderer_render(s->r_full, NULL, 0, st.film);
            if (rs == PK_OK) {
                passes++;
                const int last = (uint64_t)passes * (uint64_t)s->cfg.ro.spp >= (uint64_t)s->max_spp;
                if (denoise && aov == AOV_COLOR) {
                    /* the first pass, then as often as the denoiser's own cost allows */
                    const double wait = fmax(1.0, 3.0 * st.den_cost);
                    if (!st.den || last || now_s() - st.den_end >= wait)
                        run_denoise(s, &st, passes);
                    else if (!dirty)
                        show = 0; /* the denoised image stays until the next denoising */
                }
                if (show) {
                    img = display_image(s, st.film, 0, aov, denoise ? st.den : NULL);
                    alpha = display_alpha(s, st.film, 0, aov, st.transparent);
                }
            }
        } else if (job == JOB_DENOISE) {
            if (run_denoise(s, &st, passes) == 0) {
                img = display_image(s, st.film, 0, aov, st.den);
                alpha = display_alpha(s, st.film, 0, aov, st.transparent);
            }
        } else { /* JOB_DISPLAY */
            if (passes > 0) {
                img = display_image(s, st.film, 0, aov, denoise && st.den ? st.den : NULL);
                alpha = display_alpha(s, st.film, 0, aov, st.transparent);
            } else {
                img = display_image(s, st.pfilm, 1, aov, NULL);
                alpha = display_alpha(s, st.pfilm, 1, aov, st.transparent);
            }
        }
        if (rs != PK_OK && rs != PK_ERR_CANCELLED) {
            fprintf(stderr, "paprsek: view: %s\n", pk_context_error(ctx));
            pk_context_clear_error(ctx);
        } else if (rs == PK_ERR_CANCELLED) {
            pk_context_clear_error(ctx);
        }
        pk_stats ps;
        pk_renderer_get_stats(s->r_full, &ps);

        pthread_mutex_lock(&s->mu);
        if (st.den_failed) {
            st.den_failed = 0;
            s->denoise = 0;
            s->display_dirty = 1;
        }
        if (rs != PK_OK && rs != PK_ERR_CANCELLED && s->restart_gen == restart_done) {
            /* a failing render would fail again: wait for a change */
            stage = 1;
            passes = (uint32_t)((s->max_spp + s->cfg.ro.spp - 1) / s->cfg.ro.spp);
        }
        if (s->restart_gen == restart_done) {
            s->passes = passes;
            s->t_last = now_s();
            if (ps.render_s > render_s0) s->rays_per_s = (double)(rays_of(&ps) - rays0) / (ps.render_s - render_s0);
            if (img) {
                publish_locked(s, img, alpha, aov, exposure, tonemap);
                img = alpha = NULL;
            }
        }
        pk_image_destroy(img);
        pk_image_destroy(alpha);
    }
    s->rendering = 0;
    s->thread_done = 1;
    pthread_cond_broadcast(&s->frames);
    pthread_mutex_unlock(&s->mu);
    pk_image_destroy(st.den);
    pk_denoiser_destroy(st.denoiser);
    pk_film_destroy(st.film);
    pk_film_destroy(st.pfilm);
    return NULL;
}

/* ---- HTTP ------------------------------------------------------------------------ */

typedef struct request {
    char *body;
    size_t len;
    int too_big;
    int checked; /* the security checks passed */
} request;

static enum MHD_Result send_bytes(struct MHD_Connection *c, unsigned code, const char *type, const void *data,
                                  size_t len, enum MHD_ResponseMemoryMode mode)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, (void *)data, mode);
    if (!r) return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
    const enum MHD_Result ret = MHD_queue_response(c, code, r);
    MHD_destroy_response(r);
    return ret;
}

static enum MHD_Result send_json(struct MHD_Connection *c, unsigned code, char *json /* taken */)
{
    if (!json) return MHD_NO;
    return send_bytes(c, code, "application/json", json, strlen(json), MHD_RESPMEM_MUST_FREE);
}

static enum MHD_Result send_error(struct MHD_Connection *c, unsigned code, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sbuf b = {0};
    sb_printf(&b, "{\"error\":");
    sb_string(&b, msg);
    sb_printf(&b, "}");
    if (b.oom) {
        free(b.p);
        return MHD_NO;
    }
    return send_json(c, code, b.p);
}

static enum MHD_Result send_status(view_server *s, struct MHD_Connection *c)
{
    pthread_mutex_lock(&s->mu);
    char *j = status_json_locked(s);
    pthread_mutex_unlock(&s->mu);
    return send_json(c, MHD_HTTP_OK, j);
}

/* Constant-time comparison of two strings of which b is the secret. */
static int same_secret(const char *a, const char *b)
{
    const size_t la = strlen(a), lb = strlen(b);
    unsigned diff = la != lb;
    for (size_t i = 0; i < lb; i++) diff |= (unsigned char)b[i] ^ (unsigned char)(i < la ? a[i] : 0);
    return diff == 0;
}

/* The rules of docs/viewer.md, Security: NULL when the request may go on,
 * else why not (403). */
static const char *refused(view_server *s, struct MHD_Connection *c, const char *method)
{
    if (s->token[0]) {
        const char *t = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "token");
        if (!t) t = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Paprsek-Token");
        if (!t || !same_secret(t, s->token)) return "a valid token is required (the one in the URL the program printed)";
    }
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST);
    if (s->nallowed) {
        int ok = 0;
        for (int i = 0; host && i < s->nallowed; i++) ok |= strcasecmp(host, s->allowed_host[i]) == 0;
        if (!ok) return "the Host header does not name this server";
    }
    if (strcmp(method, "POST") == 0) {
        const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
        if (origin) {
            char want[128];
            snprintf(want, sizeof want, "http://%s", host ? host : "");
            if (!host || strcasecmp(origin, want) != 0) return "requests from other sites are refused";
        }
    }
    return NULL;
}

/* A finite number of the JSON value, or a message. */
static const char *get_number(const cJSON *v, double *out)
{
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble)) return "must be a finite number";
    *out = v->valuedouble;
    return NULL;
}

static const char *get_vec3(const cJSON *v, float out[3])
{
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) return "must be an array of three numbers";
    for (int i = 0; i < 3; i++) {
        const cJSON *e = cJSON_GetArrayItem(v, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 3.0e38)
            return "must be an array of three finite numbers";
        out[i] = (float)e->valuedouble;
    }
    return NULL;
}

static cJSON *parse_object(request *rq, struct MHD_Connection *c, enum MHD_Result *ret)
{
    cJSON *root = cJSON_ParseWithLength(rq->body ? rq->body : "", rq->len);
    if (!root) {
        *ret = send_error(c, MHD_HTTP_BAD_REQUEST, "the body is not JSON");
        return NULL;
    }
    if (!cJSON_IsObject(root)) {
        cJSON_Delete(root);
        *ret = send_error(c, MHD_HTTP_BAD_REQUEST, "the body must be a JSON object");
        return NULL;
    }
    return root;
}

static enum MHD_Result post_camera(view_server *s, struct MHD_Connection *c, request *rq)
{
    enum MHD_Result ret = MHD_NO;
    cJSON *root = parse_object(rq, c, &ret);
    if (!root) return ret;
    pthread_mutex_lock(&s->mu);
    pk_camera cam = s->cam;
    const pk_camera initial = s->initial_cam;
    pthread_mutex_unlock(&s->mu);
    const cJSON *reset = cJSON_GetObjectItemCaseSensitive(root, "reset");
    if (reset) {
        if (!cJSON_IsBool(reset)) {
            cJSON_Delete(root);
            return send_error(c, MHD_HTTP_BAD_REQUEST, "reset: must be true or false");
        }
        if (cJSON_IsTrue(reset)) cam = initial;
    }
    const cJSON *it;
    cJSON_ArrayForEach(it, root)
    {
        const char *k = it->string, *why = NULL;
        double x = 0.0;
        if (strcmp(k, "reset") == 0) continue;
        if (strcmp(k, "look_from") == 0)
            why = get_vec3(it, cam.look_from);
        else if (strcmp(k, "look_at") == 0)
            why = get_vec3(it, cam.look_at);
        else if (strcmp(k, "up") == 0)
            why = get_vec3(it, cam.up);
        else if (strcmp(k, "fov") == 0) {
            if (!(why = get_number(it, &x)) && !(x > 0.0 && x < 180.0)) why = "must be between 0 and 180 degrees";
            cam.fov_deg = (float)x;
        } else if (strcmp(k, "lens_radius") == 0 || strcmp(k, "focus_distance") == 0) {
            if (!(why = get_number(it, &x)) && !(x >= 0.0 && x <= 3.0e38)) why = "must be 0 or more";
            *(k[0] == 'l' ? &cam.lens_radius : &cam.focus_distance) = (float)x;
        } else {
            char msg[192];
            snprintf(msg, sizeof msg,
                     "unknown field '%.64s' (look_from, look_at, up, fov, lens_radius, focus_distance, reset)", k);
            cJSON_Delete(root); /* k is the tree's */
            return send_error(c, MHD_HTTP_BAD_REQUEST, "%s", msg);
        }
        if (why) {
            char msg[160];
            snprintf(msg, sizeof msg, "%.64s: %s", k, why);
            cJSON_Delete(root);
            return send_error(c, MHD_HTTP_BAD_REQUEST, "%s", msg);
        }
    }
    cJSON_Delete(root);
    pk_context *vctx = NULL;
    if (pk_context_create(NULL, &vctx) != PK_OK) return MHD_NO;
    if (pk_camera_check(vctx, &cam) != PK_OK) {
        ret = send_error(c, MHD_HTTP_BAD_REQUEST, "%s", pk_context_error(vctx));
        pk_context_destroy(vctx);
        return ret;
    }
    pk_context_destroy(vctx);
    pthread_mutex_lock(&s->mu);
    s->cam = cam;
    s->restart_gen++;
    s->cancel = 1;
    s->passes = 0; /* as the reply says: accumulation starts again */
    s->t_restart = s->t_last = now_s();
    s->rays_per_s = 0.0;
    pthread_cond_signal(&s->work);
    char *j = status_json_locked(s);
    pthread_mutex_unlock(&s->mu);
    return send_json(c, MHD_HTTP_OK, j);
}

static enum MHD_Result post_settings(view_server *s, struct MHD_Connection *c, request *rq)
{
    enum MHD_Result ret = MHD_NO;
    cJSON *root = parse_object(rq, c, &ret);
    if (!root) return ret;
    pthread_mutex_lock(&s->mu);
    float exposure = s->exposure;
    int tonemap = s->tonemap, transparent = s->transparent;
    int denoise = s->denoise, integrator = s->integrator, depth = s->max_depth;
    unsigned aov = s->aov;
    pthread_mutex_unlock(&s->mu);
    const pk_int_option *depth_opt = pk_int_option_find("max_depth");
    const cJSON *it;
    char msg[256] = "";
    cJSON_ArrayForEach(it, root)
    {
        const char *k = it->string;
        double x = 0.0;
        const char *why = NULL;
        if (strcmp(k, "exposure") == 0) {
            if (!(why = get_number(it, &x)) && !(x >= -PK_MAX_EXPOSURE_EV && x <= PK_MAX_EXPOSURE_EV))
                why = "must be a number of stops in -20..20";
            exposure = (float)x;
        } else if (strcmp(k, "tonemap") == 0) {
            const char *v = cJSON_GetStringValue(it);
            if (!v || pk_tonemap_parse(v) < 0) why = "must be one of clamp, agx, pbr-neutral, aces";
            else tonemap = pk_tonemap_parse(v);
        } else if (strcmp(k, "transparent") == 0) {
            if (!cJSON_IsBool(it))
                why = "must be true or false";
            else if (cJSON_IsTrue(it) && (s->cfg.ro.device == PK_DEVICE_CUDA || s->cfg.ro.accel == PK_ACCEL_CUDA))
                snprintf(msg, sizeof msg, "transparent: a transparent background is rendered on the CPU only");
            else
                transparent = cJSON_IsTrue(it);
        } else if (strcmp(k, "denoise") == 0) {
            if (!cJSON_IsBool(it))
                why = "must be true or false";
            else if (cJSON_IsTrue(it) && !s->cfg.dopt)
                snprintf(msg, sizeof msg, "denoise: not available here: %.200s",
                         s->cfg.no_denoise_why ? s->cfg.no_denoise_why : "no denoiser");
            else
                denoise = cJSON_IsTrue(it);
        } else if (strcmp(k, "aov") == 0) {
            const char *v = cJSON_GetStringValue(it);
            if (v && strcmp(v, "color") == 0)
                aov = AOV_COLOR;
            else if (v && pk_aov_parse(v))
                aov = pk_aov_parse(v);
            else
                why = "must be one of color, albedo, normal, depth, heatmap";
        } else if (strcmp(k, "integrator") == 0) {
            const char *v = cJSON_GetStringValue(it);
            if (v && strcmp(v, "path") == 0)
                integrator = PK_INTEGRATOR_PATH;
            else if (v && strcmp(v, "whitted") == 0)
                integrator = PK_INTEGRATOR_WHITTED;
            else if (v && strcmp(v, "volpath") == 0)
                integrator = PK_INTEGRATOR_VOLPATH;
            else
                why = "must be one of path, whitted, volpath";
        } else if (strcmp(k, "max_depth") == 0) {
            if (!(why = get_number(it, &x))) {
                if (x != floor(x) || !depth_opt || x < depth_opt->min || x > depth_opt->max) {
                    snprintf(msg, sizeof msg, "max_depth: must be a whole number in %d..%d", depth_opt ? depth_opt->min : 0,
                             depth_opt ? depth_opt->max : 0);
                } else {
                    depth = (int)x;
                }
            }
        } else {
            snprintf(msg, sizeof msg, "unknown field '%.64s' (exposure, tonemap, transparent, denoise, aov, integrator, max_depth)", k);
        }
        if (why) snprintf(msg, sizeof msg, "%.64s: %s", k, why);
        if (msg[0]) break;
    }
    cJSON_Delete(root);
    if (msg[0]) return send_error(c, MHD_HTTP_BAD_REQUEST, "%s", msg);
    pthread_mutex_lock(&s->mu);
    if (exposure != s->exposure || tonemap != s->tonemap || aov != s->aov || denoise != s->denoise)
        s->display_dirty = 1;
    s->exposure = exposure;
    s->tonemap = tonemap;
    s->aov = aov;
    s->denoise = denoise;
    if (integrator != s->integrator || depth != s->max_depth || transparent != s->transparent) {
        s->integrator = integrator;
        s->max_depth = depth;
        s->transparent = transparent;
        s->rebuild_gen++;
        s->restart_gen++;
        s->cancel = 1;
        s->passes = 0;
        s->t_restart = s->t_last = now_s();
        s->rays_per_s = 0.0;
    }
    pthread_cond_signal(&s->work);
    char *j = status_json_locked(s);
    pthread_mutex_unlock(&s->mu);
    return send_json(c, MHD_HTTP_OK, j);
}

/* A number of the query (x=, y=) or a message. */
static int query_number(struct MHD_Connection *c, const char *name, double *out)
{
    const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, name);
    if (!v || !*v) return 0;
    char *end;
    *out = strtod(v, &end);
    return *end == '\0' && isfinite(*out);
}

static enum MHD_Result get_pick(view_server *s, struct MHD_Connection *c)
{
    double x, y;
    if (!query_number(c, "x", &x) || !query_number(c, "y", &y))
        return send_error(c, MHD_HTTP_BAD_REQUEST, "pick: x and y must be numbers (pixels, from the top-left corner)");
    if (!(x >= 0.0 && x < s->width && y >= 0.0 && y < s->height))
        return send_error(c, MHD_HTTP_BAD_REQUEST, "pick: (%g, %g) is outside the %dx%d image", x, y, s->width,
                          s->height);
    /* whole numbers name a pixel: its centre */
    if (x == floor(x)) x += 0.5;
    if (y == floor(y)) y += 0.5;
    pthread_mutex_lock(&s->mu);
    const pk_camera cam = s->cam;
    pthread_mutex_unlock(&s->mu);
    pk_pick pk;
    pthread_rwlock_rdlock(&s->rlock);
    const pk_status st = pk_renderer_pick(s->r_full, &cam, x, y, &pk);
    sbuf b = {0};
    if (st != PK_OK) {
        pthread_rwlock_unlock(&s->rlock);
        return send_error(c, MHD_HTTP_BAD_REQUEST, "pick: (%g, %g) cannot be picked", x, y);
    }
    if (!pk.hit) {
        sb_printf(&b, "{\"hit\":false}");
    } else {
        sb_printf(&b, "{\"hit\":true,\"distance\":");
        sb_float(&b, pk.distance);
        sb_printf(&b, ",\"t\":");
        sb_float(&b, pk.t);
        sb_printf(&b, ",\"position\":");
        sb_floats(&b, pk.position, 3);
        sb_printf(&b, ",\"normal\":");
        sb_floats(&b, pk.normal, 3);
        sb_printf(&b, ",\"prim\":%u,\"material\":", (unsigned)pk.prim);
        sb_string(&b, pk.material);
        sb_printf(&b, "}");
    }
    pthread_rwlock_unlock(&s->rlock);
    if (b.oom) {
        free(b.p);
        return MHD_NO;
    }
    return send_json(c, MHD_HTTP_OK, b.p);
}

static enum MHD_Result get_frame(view_server *s, struct MHD_Connection *c, int exr)
{
    snap *p = NULL;
    /* before the first frame: wait for it (a second at most) */
    pthread_mutex_lock(&s->mu);
    if (!s->cur && !s->quit) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_sec += 1;
        pthread_cond_timedwait(&s->frames, &s->mu, &ts);
    }
    pthread_mutex_unlock(&s->mu);
    p = snap_get(s);
    if (!p) return send_error(c, MHD_HTTP_SERVICE_UNAVAILABLE, "no image yet");
    char why[512];
    if (snap_encode(s, p, exr, why, sizeof why) != 0) {
        snap_put(s, p);
        return send_error(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "%s", why);
    }
    /* the bytes stay with the snapshot, which the response keeps alive */
    const unsigned char *data = exr ? p->exr : p->png;
    const size_t len = exr ? p->exr_len : p->png_len;
    void *copy = malloc(len ? len : 1);
    if (!copy) {
        snap_put(s, p);
        return MHD_NO;
    }
    memcpy(copy, data, len);
    const uint64_t frame = p->frame;
    snap_put(s, p);
    struct MHD_Response *r = MHD_create_response_from_buffer(len, copy, MHD_RESPMEM_MUST_FREE);
    if (!r) {
        free(copy);
        return MHD_NO;
    }
    char fr[32];
    snprintf(fr, sizeof fr, "%llu", (unsigned long long)frame);
    MHD_add_response_header(r, "Content-Type", exr ? "image/x-exr" : "image/png");
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
    MHD_add_response_header(r, "X-Paprsek-Frame", fr);
    MHD_add_response_header(r, "Access-Control-Expose-Headers", "X-Paprsek-Frame");
    const char *dl = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "download");
    if (dl && strcmp(dl, "0") != 0)
        MHD_add_response_header(r, "Content-Disposition",
                                exr ? "attachment; filename=\"paprsek.exr\"" : "attachment; filename=\"paprsek.png\"");
    const enum MHD_Result ret = MHD_queue_response(c, MHD_HTTP_OK, r);
    MHD_destroy_response(r);
    return ret;
}

/* ---- server-sent events ----------------------------------------------------------- */

typedef struct sse {
    view_server *s;
    uint64_t sent_frame; /* the frame of the last event; UINT64_MAX: none yet */
    char *pending;       /* what is still to be written */
    size_t off, len;
} sse;

static ssize_t sse_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    sse *e = cls;
    view_server *s = e->s;
    (void)pos;
    if (!e->pending) {
        pthread_mutex_lock(&s->mu);
        const double t0 = now_s();
        for (;;) {
            if (s->quit) {
                pthread_mutex_unlock(&s->mu);
                return MHD_CONTENT_READER_END_OF_STREAM;
            }
            if (s->frame != e->sent_frame || e->sent_frame == UINT64_MAX) {
                char *j = status_json_locked(s);
                e->sent_frame = s->frame;
                pthread_mutex_unlock(&s->mu);
                if (!j) return MHD_CONTENT_READER_END_WITH_ERROR;
                sbuf b = {0};
                sb_printf(&b, "event: frame\ndata: %s\n\n", j);
                free(j);
                if (b.oom) {
                    free(b.p);
                    return MHD_CONTENT_READER_END_WITH_ERROR;
                }
                e->pending = b.p;
                e->len = b.n;
                e->off = 0;
                break;
            }
            if (now_s() - t0 >= VIEW_KEEPALIVE_S) {
                pthread_mutex_unlock(&s->mu);
                e->pending = strdup(": keepalive\n\n");
                if (!e->pending) return MHD_CONTENT_READER_END_WITH_ERROR;
                e->len = strlen(e->pending);
                e->off = 0;
                break;
            }
            struct timespec ts;
            clock_gettime(CLOCK_REALTIME, &ts);
            ts.tv_sec += VIEW_KEEPALIVE_S;
            pthread_cond_timedwait(&s->frames, &s->mu, &ts);
        }
    }
    size_t k = e->len - e->off;
    if (k > max) k = max;
    memcpy(buf, e->pending + e->off, k);
    e->off += k;
    if (e->off == e->len) {
        free(e->pending);
        e->pending = NULL;
    }
    return (ssize_t)k;
}

static void sse_free(void *cls)
{
    sse *e = cls;
    free(e->pending);
    free(e);
}

static enum MHD_Result get_events(view_server *s, struct MHD_Connection *c)
{
    sse *e = calloc(1, sizeof *e);
    if (!e) return MHD_NO;
    e->s = s;
    e->sent_frame = UINT64_MAX;
    struct MHD_Response *r = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 4096, sse_read, e, sse_free);
    if (!r) {
        free(e);
        return MHD_NO;
    }
    MHD_add_response_header(r, "Content-Type", "text/event-stream");
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    const enum MHD_Result ret = MHD_queue_response(c, MHD_HTTP_OK, r);
    MHD_destroy_response(r);
    return ret;
}

/* ---- dispatch ------------------------------------------------------------------ */

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                                  const char *version, const char *upload_data, size_t *upload_data_size,
                                  void **con_cls)
{
    view_server *s = cls;
    (void)version;
    request *rq = *con_cls;
    const int is_get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    const int is_post = strcmp(method, "POST") == 0;
    if (!rq) {
        rq = calloc(1, sizeof *rq);
        if (!rq) return MHD_NO;
        *con_cls = rq;
        const char *why = refused(s, c, method);
        if (why) return send_error(c, MHD_HTTP_FORBIDDEN, "%s", why);
        rq->checked = 1;
        const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
        if (cl && strtoull(cl, NULL, 10) > VIEW_MAX_BODY)
            return send_error(c, MHD_HTTP_CONTENT_TOO_LARGE, "the body is larger than %d bytes", VIEW_MAX_BODY);
        if (is_post) return MHD_YES; /* the body comes next */
    }
    if (!rq->checked) return MHD_NO;
    if (*upload_data_size) {
        if (!rq->too_big && rq->len + *upload_data_size <= VIEW_MAX_BODY) {
            char *nb = realloc(rq->body, rq->len + *upload_data_size + 1);
            if (!nb) return MHD_NO;
            rq->body = nb;
            memcpy(rq->body + rq->len, upload_data, *upload_data_size);
            rq->len += *upload_data_size;
            rq->body[rq->len] = '\0';
        } else {
            rq->too_big = 1;
        }
        *upload_data_size = 0;
        return MHD_YES;
    }
    if (rq->too_big) return send_error(c, MHD_HTTP_CONTENT_TOO_LARGE, "the body is larger than %d bytes", VIEW_MAX_BODY);

    const int post_only = strcmp(url, "/api/camera") == 0 || strcmp(url, "/api/settings") == 0;
    const int get_only = strcmp(url, "/") == 0 || strcmp(url, "/index.html") == 0 || strcmp(url, "/api/status") == 0 ||
                         strcmp(url, "/api/frame.png") == 0 || strcmp(url, "/api/frame.exr") == 0 ||
                         strcmp(url, "/api/events") == 0 || strcmp(url, "/api/pick") == 0;
    if (!post_only && !get_only) return send_error(c, MHD_HTTP_NOT_FOUND, "no such page");
    if ((post_only && !is_post) || (get_only && !is_get)) {
        char body[128];
        snprintf(body, sizeof body, "{\"error\":\"%s is not allowed here (use %s)\"}", is_post ? "POST" : "this method",
                 post_only ? "POST" : "GET");
        struct MHD_Response *r = MHD_create_response_from_buffer(strlen(body), body, MHD_RESPMEM_MUST_COPY);
        if (!r) return MHD_NO;
        MHD_add_response_header(r, "Content-Type", "application/json");
        MHD_add_response_header(r, "Cache-Control", "no-store");
        MHD_add_response_header(r, "Allow", post_only ? "POST" : "GET, HEAD");
        const enum MHD_Result ret = MHD_queue_response(c, MHD_HTTP_METHOD_NOT_ALLOWED, r);
        MHD_destroy_response(r);
        return ret;
    }
    if (strcmp(url, "/") == 0 || strcmp(url, "/index.html") == 0)
        return send_bytes(c, MHD_HTTP_OK, "text/html; charset=utf-8", view_page, (size_t)view_page_len,
                          MHD_RESPMEM_PERSISTENT);
    if (strcmp(url, "/api/status") == 0) return send_status(s, c);
    if (strcmp(url, "/api/frame.png") == 0) return get_frame(s, c, 0);
    if (strcmp(url, "/api/frame.exr") == 0) return get_frame(s, c, 1);
    if (strcmp(url, "/api/events") == 0) return get_events(s, c);
    if (strcmp(url, "/api/pick") == 0) return get_pick(s, c);
    if (strcmp(url, "/api/camera") == 0) return post_camera(s, c, rq);
    return post_settings(s, c, rq);
}

static void on_completed(void *cls, struct MHD_Connection *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)cls, (void)c, (void)toe;
    request *rq = *con_cls;
    if (!rq) return;
    free(rq->body);
    free(rq);
    *con_cls = NULL;
}

/* ---- start and stop ------------------------------------------------------------- */

static int fail(char *err, size_t cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, cap, fmt, ap);
    va_end(ap);
    return 1;
}

static void rmtree_flat(const char *dir)
{
    if (dir[0]) rmdir(dir); /* the encodings remove their files; the folder is then empty */
}

int view_server_start(const view_config *cfg, view_server **out, char *err, size_t cap)
{
    *out = NULL;
    if (!mhd_load(err, cap)) return 1;
    view_server *s = calloc(1, sizeof *s);
    if (!s) return fail(err, cap, "out of memory");
    s->cfg = *cfg;
    s->width = cfg->ro.width;
    s->height = cfg->ro.height;
    if (s->cfg.ro.spp < 1) s->cfg.ro.spp = 1;
    s->max_spp = cfg->max_spp > 0 ? cfg->max_spp : VIEW_DEFAULT_MAX_SPP;
    pthread_mutex_init(&s->mu, NULL);
    pthread_cond_init(&s->work, NULL);
    pthread_cond_init(&s->frames, NULL);
    pthread_rwlock_init(&s->rlock, NULL);

    const char *bind = cfg->bind ? cfg->bind : "127.0.0.1";
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)(cfg->port > 0 ? cfg->port : 0));
    if (cfg->port < 0 || cfg->port > 65535 || inet_pton(AF_INET, bind, &addr.sin_addr) != 1) {
        free(s);
        return fail(err, cap, "--bind: '%s' is not an IPv4 address (such as 127.0.0.1)", bind);
    }
    inet_ntop(AF_INET, &addr.sin_addr, s->bind, sizeof s->bind);
    s->loopback = (ntohl(addr.sin_addr.s_addr) >> 24) == 127;
    const int wildcard = addr.sin_addr.s_addr == htonl(INADDR_ANY);
    if (cfg->require_token || !s->loopback) {
        unsigned char rnd[16];
        if (getrandom(rnd, sizeof rnd, 0) != (ssize_t)sizeof rnd) {
            free(s);
            return fail(err, cap, "no random numbers for the token: %s", strerror(errno));
        }
        for (int i = 0; i < 16; i++) snprintf(s->token + 2 * i, 3, "%02x", rnd[i]);
    }

    /* the settings and the camera */
    pk_scene_info si;
    pk_scene_get_info(cfg->scene, &si);
    s->integrator = cfg->ro.integrator != PK_INTEGRATOR_DEFAULT ? (int)cfg->ro.integrator
                    : si.has_media                                ? PK_INTEGRATOR_VOLPATH
                                                                  : PK_INTEGRATOR_PATH;
    s->max_depth = cfg->ro.max_depth;
    s->exposure = cfg->exposure;
    s->tonemap = cfg->tonemap;
    s->transparent = cfg->ro.transparent;
    s->denoise_available = cfg->dopt != NULL;
    s->denoise = cfg->denoise && cfg->dopt;
    s->aov = AOV_COLOR;
    pk_scene_get_camera(cfg->scene, &s->cam);
    s->initial_cam = s->cam;
    s->restart_gen = 1;
    s->t_restart = s->t_last = now_s();

    const char *tmp = getenv("TMPDIR");
    snprintf(s->tmpdir, sizeof s->tmpdir, "%s/paprsek-view-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(s->tmpdir)) {
        const int e = errno;
        free(s);
        return fail(err, cap, "cannot make a temporary folder in %s: %s", tmp && *tmp ? tmp : "/tmp", strerror(e));
    }
    if (make_renderers(s, s->integrator, s->max_depth, s->transparent, &s->r_full, &s->r_prev) != PK_OK) {
        fail(err, cap, "%s", pk_context_error(cfg->ctx));
        view_server_stop(s);
        return 1;
    }

    s->daemon = MHD_start_daemon(MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION | MHD_USE_POLL,
                                 0, NULL, NULL, on_request, s, MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
                                 MHD_OPTION_NOTIFY_COMPLETED, on_completed, s, MHD_OPTION_CONNECTION_LIMIT,
                                 (unsigned)64, MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)120, MHD_OPTION_END);
    if (!s->daemon) {
        fail(err, cap, "cannot listen on %s:%d (in use, or not an address of this machine?)", s->bind, cfg->port);
        view_server_stop(s);
        return 1;
    }
    const union MHD_DaemonInfo *di = MHD_get_daemon_info(s->daemon, MHD_DAEMON_INFO_BIND_PORT);
    s->port = di ? di->port : cfg->port;
    if (!wildcard) {
        snprintf(s->allowed_host[s->nallowed++], sizeof s->allowed_host[0], "%s:%d", s->bind, s->port);
        if (s->loopback) snprintf(s->allowed_host[s->nallowed++], sizeof s->allowed_host[0], "localhost:%d", s->port);
    }
    snprintf(s->url, sizeof s->url, "http://%s:%d/%s%s", s->bind, s->port, s->token[0] ? "?token=" : "", s->token);

    if (pthread_create(&s->thread, NULL, render_main, s) != 0) {
        fail(err, cap, "cannot start the render thread");
        view_server_stop(s);
        return 1;
    }
    s->thread_started = 1;
    *out = s;
    return 0;
}

int view_server_port(const view_server *s) { return s->port; }
const char *view_server_url(const view_server *s) { return s->url; }
const char *view_server_token(const view_server *s) { return s->token; }

int view_server_stop_within(view_server *s, double seconds)
{
    if (!s) return 0;
    pthread_mutex_lock(&s->mu);
    s->quit = 1;
    s->cancel = 1;
    pthread_cond_broadcast(&s->work);
    pthread_cond_broadcast(&s->frames);
    pthread_mutex_unlock(&s->mu);
    if (s->daemon) MHD_stop_daemon(s->daemon);
    s->daemon = NULL;
    rmtree_flat(s->tmpdir); /* no request encodes any more */
    s->tmpdir[0] = '\0';
    if (s->thread_started && seconds >= 0.0) {
        /* a render stops within a tile; the denoiser cannot be stopped */
        pthread_mutex_lock(&s->mu);
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        const double end = (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9 + seconds;
        ts.tv_sec = (time_t)end;
        ts.tv_nsec = (long)((end - (double)ts.tv_sec) * 1e9);
        while (!s->thread_done && pthread_cond_timedwait(&s->frames, &s->mu, &ts) == 0) {
        }
        const int done = s->thread_done;
        pthread_mutex_unlock(&s->mu);
        if (!done) return 1;
    }
    if (s->thread_started) pthread_join(s->thread, NULL);
    pk_renderer_destroy(s->r_full);
    pk_renderer_destroy(s->r_prev);
    snap_unref_locked(s->cur);
    pthread_rwlock_destroy(&s->rlock);
    pthread_cond_destroy(&s->work);
    pthread_cond_destroy(&s->frames);
    pthread_mutex_destroy(&s->mu);
    free(s);
    return 0;
}

void view_server_stop(view_server *s) { view_server_stop_within(s, -1.0); }

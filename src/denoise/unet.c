/*
 * unet.c - the U-Net of unet.h: weights checked and converted, the oneDNN
 * convolutions made once per image size, pooling and upsampling written
 * here (they move memory, they do no arithmetic worth a library), and one
 * pass over an image.
 *
 * The layer plan, with C1..C5 the encoder's channels, D4..D1 the decoder's,
 * I the input channels rounded up to 16, and [a | b] a concatenated tensor
 * whose parts are written by their producers in place:
 *   level 0 (full size):  cat1 = [up(D2b) | input I]
 *     enc_conv0 cat1.in -> t0b (C1); enc_conv1 -> t0a (C1); pool -> cat2.skip
 *   level 1: cat2 = [up(D3) | C1]; enc_conv2 -> t1a (C2); pool -> cat3.skip
 *   level 2: cat3 = [up(D4) | C2]; enc_conv3 -> t2a (C3); pool -> cat4.skip
 *   level 3: cat4 = [up(C5) | C3]; enc_conv4 -> t3a (C4); pool -> t4a
 *   level 4: enc_conv5a t4a -> t4b; enc_conv5b -> t4a; up -> cat4.up
 *   back up: dec_conv4a cat4 -> t3a; 4b -> t3b; up -> cat3.up; dec_conv3a
 *   cat3 -> t2a; 3b -> t2b; up -> cat2.up; dec_conv2a cat2 -> t1a; 2b -> t1b;
 *   up -> cat1.up; dec_conv1a cat1 -> t0a; 1b -> t0b; dec_conv0 -> t0a (3).
 */
#include "unet.h"

#include "device/dynlib.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/mman.h>
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 /* Linux 5.14; older kernels refuse it (EINVAL) */
#endif
#endif
#include <stdio.h>
#include <string.h>

const char *const unet_conv_names[UNET_CONVS] = {
    "enc_conv0", "enc_conv1", "enc_conv2", "enc_conv3", "enc_conv4", "enc_conv5a", "enc_conv5b", "dec_conv4a",
    "dec_conv4b", "dec_conv3a", "dec_conv3b", "dec_conv2a", "dec_conv2b", "dec_conv1a", "dec_conv1b", "dec_conv0"};

enum {
    ENC0, ENC1, ENC2, ENC3, ENC4, ENC5A, ENC5B, DEC4A, DEC4B, DEC3A, DEC3B, DEC2A, DEC2B, DEC1A, DEC1B, DEC0
};

static int round16(int c) { return (c + 15) / 16 * 16; }
static int unet_block(const pk_context *ctx);

#if PK_HAVE_DNNL
#include <oneapi/dnnl/dnnl.h>

/* ---- oneDNN, loaded at run time ------------------------------------------ */

#define DNNL_FUNCS(X)                                                                                             \
    X(engine_create) X(engine_destroy) X(stream_create) X(stream_destroy) X(stream_wait)                         \
    X(memory_desc_init_by_tag) X(memory_desc_get_size) X(memory_create) X(memory_destroy)                        \
    X(convolution_forward_desc_init) X(post_ops_create) X(post_ops_destroy) X(post_ops_append_eltwise)           \
    X(primitive_attr_create) X(primitive_attr_destroy) X(primitive_attr_set_post_ops)                            \
    X(primitive_attr_set_scratchpad_mode)                                                                         \
    X(primitive_desc_create) X(primitive_desc_destroy) X(primitive_desc_query_md) X(primitive_desc_query)        \
    X(primitive_create) X(primitive_destroy) X(primitive_execute) X(reorder_primitive_desc_create)

static struct {
#define X(fn) __typeof__(dnnl_##fn) *fn;
    DNNL_FUNCS(X)
#undef X
} dn;

static dynlib dnnl_lib = DYNLIB_INIT;

static bool init_dnnl(void *h, const char *name, char *why, size_t n)
{
    void *sym;
#define X(fn)                                                                                                     \
    sym = dynlib_symbol(h, "dnnl_" #fn);                                                                          \
    if (!sym) {                                                                                                   \
        snprintf(why, n, "%s has no dnnl_%s (oneDNN 2.x is needed)", name, #fn);                                  \
        return false;                                                                                             \
    }                                                                                                             \
    memcpy(&dn.fn, &sym, sizeof sym);
    DNNL_FUNCS(X)
#undef X
    return true;
}

bool unet_backend_available(pk_context *ctx, char *why, size_t n)
{
    return dynlib_load(&dnnl_lib, config_dnnl_library(ctx), init_dnnl, why, n);
}
#else
bool unet_backend_available(pk_context *ctx, char *why, size_t n)
{
    (void)ctx;
    snprintf(why, n, "this build has no denoiser: oneDNN's headers (Debian libdnnl-dev) were missing when it was "
                     "compiled");
    return false;
}
#endif

/* ---- the network -------------------------------------------------------- */

typedef struct conv_layer {
    int ic, oc;      /* as the weights have them */
    int icp, ocp;    /* input channels as stored (padded), output rounded to 16 */
    float *w;        /* oc x icp x 3 x 3 (oihw), the padding input channels zero */
    float *b;        /* oc */
    bool relu;
#if PK_HAVE_DNNL
    dnnl_primitive_t prim;
    dnnl_memory_t wmem, bmem, pad;
    dnnl_memory_desc_t scratch; /* its scratchpad's description (size 0: none) */
    void *wbuf;      /* weights in the primitive's layout */
#endif
} conv_layer;

struct unet {
    pk_context *ctx;
    const pk_allocator *al;
    int ic, icp;     /* input channels, and rounded to 16 */
    int blk;         /* the channel block of the tensors, 8 or 16 (unet_block) */
    int c[6];        /* encoder channels c[1..5] */
    int d4, d3, d2a, d2b, d1a, d1b;
    conv_layer conv[UNET_CONVS];
    /* made for one image size */
    int h, w, threads;
    float *buf;      /* every activation, one block (aligned, inside block) */
    void *block;
    float *cat1, *cat2, *cat3, *cat4, *t0a, *t0b, *t1a, *t1b, *t2a, *t2b, *t3a, *t3b, *t4a, *t4b;
    char impl[128];
    double t_plan, t_conv[UNET_CONVS], t_total; /* seconds of the last run */
#if PK_HAVE_DNNL
    dnnl_engine_t engine;
    dnnl_stream_t stream;
    dnnl_memory_t src[UNET_CONVS], dst[UNET_CONVS];
    size_t scratch_bytes; /* the largest layer's scratchpad */
    void *scratch_block;
    char *scratch;
#endif
};

int unet_input_channels(const unet *u) { return u->ic; }
const char *unet_backend_impl(const unet *u) { return u->impl[0] ? u->impl : "none"; }

/* Checks tensor NAME.weight (oc x ic x 3 x 3, oihw) and NAME.bias (oc). */
static pk_status check_conv(pk_context *ctx, const char *file, const tza_archive *a, int k, int ic, int *oc)
{
    char wn[TZA_MAX_NAME + 8], bn[TZA_MAX_NAME + 8];
    snprintf(wn, sizeof wn, "%s.weight", unet_conv_names[k]);
    snprintf(bn, sizeof bn, "%s.bias", unet_conv_names[k]);
    const tza_tensor *w = tza_find(a, wn), *b = tza_find(a, bn);
    if (!w || !b)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: no tensor %s: not the weights of a U-Net this denoiser runs",
                         file, w ? bn : wn);
    if (w->ndims != 4 || strcmp(w->layout, "oihw") != 0 || w->dims[2] != 3 || w->dims[3] != 3)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: %s is not a 3x3 convolution in oihw layout", file, wn);
    if (ic > 0 && (int)w->dims[1] != ic)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: %s takes %u channels where the U-Net gives it %d", file, wn,
                         w->dims[1], ic);
    if (b->ndims != 1 || b->dims[0] != w->dims[0])
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: %s has %u values for %u output channels", file, bn,
                         b->dims[0], w->dims[0]);
    *oc = (int)w->dims[0];
    return PK_OK;
}

/* The weights of layer k into l, for an input stored with icp channels:
 * the weights' ic channels first, zero weights for the padding after them
 * (the input image's channels are the last part of what a layer reads). */
static pk_status load_conv(pk_context *ctx, const tza_archive *a, int k, int icp, bool relu, conv_layer *l)
{
    char wn[TZA_MAX_NAME + 8], bn[TZA_MAX_NAME + 8];
    snprintf(wn, sizeof wn, "%s.weight", unet_conv_names[k]);
    snprintf(bn, sizeof bn, "%s.bias", unet_conv_names[k]);
    const tza_tensor *w = tza_find(a, wn), *b = tza_find(a, bn);
    l->oc = (int)w->dims[0];
    l->ic = (int)w->dims[1];
    l->icp = icp;
    l->ocp = round16(l->oc);
    l->relu = relu;
    l->w = mem_calloc(&ctx->alloc, (size_t)l->oc * (size_t)icp * 9, sizeof(float));
    l->b = mem_calloc(&ctx->alloc, (size_t)l->oc, sizeof(float));
    if (!l->w || !l->b) return ctx_nomem(ctx);
    for (int o = 0; o < l->oc; o++) {
        l->b[o] = tza_get(b, (size_t)o);
        for (int i = 0; i < l->ic; i++)
            for (int t = 0; t < 9; t++)
                l->w[((size_t)o * icp + (size_t)i) * 9 + (size_t)t] = tza_get(w, ((size_t)o * l->ic + (size_t)i) * 9 + (size_t)t);
    }
    for (size_t i = 0; i < (size_t)l->oc * (size_t)icp * 9; i++)
        if (!isfinite(l->w[i])) return ctx_error(ctx, PK_ERR_PARSE, "weights: %s holds a value that is not finite", wn);
    for (int o = 0; o < l->oc; o++)
        if (!isfinite(l->b[o])) return ctx_error(ctx, PK_ERR_PARSE, "weights: %s holds a value that is not finite", bn);
    return PK_OK;
}

pk_status unet_create(pk_context *ctx, const char *name, const tza_archive *a, unet **out)
{
    *out = NULL;
    int ic = 0, c1, c2, c3, c4, c5, c5b, d4, d4b, d3, d3b, d2a, d2b, d1a, d1b, oc;
    pk_status st;
    const tza_tensor *w0 = tza_find(a, "enc_conv0.weight");
    if (w0 && w0->ndims == 4) ic = (int)w0->dims[1];
    if ((st = check_conv(ctx, name, a, ENC0, 0, &c1)) || (st = check_conv(ctx, name, a, ENC1, c1, &c1)) ||
        (st = check_conv(ctx, name, a, ENC2, c1, &c2)) || (st = check_conv(ctx, name, a, ENC3, c2, &c3)) ||
        (st = check_conv(ctx, name, a, ENC4, c3, &c4)) || (st = check_conv(ctx, name, a, ENC5A, c4, &c5)) ||
        (st = check_conv(ctx, name, a, ENC5B, c5, &c5b)) || (st = check_conv(ctx, name, a, DEC4A, c5b + c3, &d4)) ||
        (st = check_conv(ctx, name, a, DEC4B, d4, &d4b)) || (st = check_conv(ctx, name, a, DEC3A, d4b + c2, &d3)) ||
        (st = check_conv(ctx, name, a, DEC3B, d3, &d3b)) || (st = check_conv(ctx, name, a, DEC2A, d3b + c1, &d2a)) ||
        (st = check_conv(ctx, name, a, DEC2B, d2a, &d2b)) || (st = check_conv(ctx, name, a, DEC1A, d2b + ic, &d1a)) ||
        (st = check_conv(ctx, name, a, DEC1B, d1a, &d1b)) || (st = check_conv(ctx, name, a, DEC0, d1b, &oc)))
        return st;
    if (ic < 3 || ic > 16 || oc != 3)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: a U-Net of %d input and %d output channels (3 to 16 in, 3 out "
                         "are run)", name, ic, oc);
    int chans[] = {c1, c2, c3, c4, c5, c5b, d4, d4b, d3, d3b, d2a, d2b, d1a, d1b};
    for (size_t i = 0; i < sizeof chans / sizeof chans[0]; i++)
        if (chans[i] % 16 != 0)
            return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: a layer of %d channels (multiples of 16 are run)", name,
                             chans[i]);
    if (c5b != c5 || d4b != d4 || d3b != d3)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: the bottleneck or decoder pairs change channel counts", name);
    unet *u = mem_calloc(&ctx->alloc, 1, sizeof *u);
    if (!u) return ctx_nomem(ctx);
    u->ctx = ctx;
    u->al = &ctx->alloc;
    u->ic = ic;
    u->icp = round16(ic);
    u->blk = unet_block(ctx);
    u->c[1] = c1, u->c[2] = c2, u->c[3] = c3, u->c[4] = c4, u->c[5] = c5;
    u->d4 = d4, u->d3 = d3, u->d2a = d2a, u->d2b = d2b, u->d1a = d1a, u->d1b = d1b;
    /* stored input channels of each layer; for dec_conv1a the weights'
     * channels d2b.. are the input's, which the store pads to icp */
    const int icp[UNET_CONVS] = {u->icp, c1, c1, c2, c3, c4, c5, c5 + c3, d4, d4 + c2, d3, d3 + c1, d2a,
                                 d2b + u->icp, d1a, d1b};
    for (int k = 0; k < UNET_CONVS; k++) {
        if ((st = load_conv(ctx, a, k, icp[k], k != DEC0, &u->conv[k]))) {
            unet_destroy(u);
            return st;
        }
    }
    *out = u;
    return PK_OK;
}

#if PK_HAVE_DNNL
static void release_plan(unet *u)
{
    for (int k = 0; k < UNET_CONVS; k++) {
        conv_layer *l = &u->conv[k];
        if (l->prim) dn.primitive_destroy(l->prim);
        if (l->wmem) dn.memory_destroy(l->wmem);
        if (l->bmem) dn.memory_destroy(l->bmem);
        if (l->pad) dn.memory_destroy(l->pad);
        l->pad = NULL;
        mem_free_aligned(u->al, l->wbuf);
        l->prim = NULL, l->wmem = NULL, l->bmem = NULL, l->wbuf = NULL;
        if (u->src[k]) dn.memory_destroy(u->src[k]);
        if (u->dst[k]) dn.memory_destroy(u->dst[k]);
        u->src[k] = u->dst[k] = NULL;
    }
    mem_free(u->al, u->block);
    u->block = NULL;
    u->buf = NULL;
    mem_free(u->al, u->scratch_block);
    u->scratch_block = NULL;
    u->scratch = NULL;
    u->scratch_bytes = 0;
    u->h = u->w = 0;
}
#endif

void unet_destroy(unet *u)
{
    if (!u) return;
#if PK_HAVE_DNNL
    release_plan(u);
    if (u->stream) dn.stream_destroy(u->stream);
    if (u->engine) dn.engine_destroy(u->engine);
#endif
    for (int k = 0; k < UNET_CONVS; k++) {
        mem_free(u->al, u->conv[k].w);
        mem_free(u->al, u->conv[k].b);
    }
    mem_free(u->al, u);
}

/* Channels of every activation buffer, in the order of the plan's block. */
typedef struct plan_sizes {
    int cat1, cat2, cat3, cat4, t0a, t0b, t1a, t1b, t2a, t2b, t3a, t3b, t4a, t4b;
} plan_sizes;

static int imax(int a, int b) { return a > b ? a : b; }

static plan_sizes sizes_of(const unet *u)
{
    plan_sizes s;
    s.cat1 = u->d2b + u->icp;
    s.cat2 = u->d3 + u->c[1];
    s.cat3 = u->d4 + u->c[2];
    s.cat4 = u->c[5] + u->c[3];
    s.t0a = imax(u->c[1], imax(u->d1a, 16));
    s.t0b = imax(u->c[1], u->d1b);
    s.t1a = imax(u->c[2], u->d2a);
    s.t1b = u->d2b;
    s.t2a = imax(u->c[3], u->d3);
    s.t2b = u->d3;
    s.t3a = imax(u->c[4], u->d4);
    s.t3b = u->d4;
    s.t4a = imax(u->c[4], u->c[5]);
    s.t4b = u->c[5];
    return s;
}

size_t unet_activation_bytes(const unet *u, int h, int w)
{
    plan_sizes s = sizes_of(u);
    size_t p0 = (size_t)h * (size_t)w;
    size_t fl = p0 * (size_t)(s.cat1 + s.t0a + s.t0b) + p0 / 4 * (size_t)(s.cat2 + s.t1a + s.t1b) +
                p0 / 16 * (size_t)(s.cat3 + s.t2a + s.t2b) + p0 / 64 * (size_t)(s.cat4 + s.t3a + s.t3b) +
                p0 / 256 * (size_t)(s.t4a + s.t4b);
    return fl * sizeof(float);
}

static const int level[UNET_CONVS] = {0, 0, 1, 2, 3, 4, 4, 3, 3, 2, 2, 1, 1, 0, 0, 0};

void unet_layer_shape(const unet *u, int k, int *ic, int *oc, int *lv)
{
    *ic = u->conv[k].ic, *oc = u->conv[k].oc, *lv = level[k];
}

void unet_last_times(const unet *u, double *plan, double conv[UNET_CONVS], double *rest)
{
    double sum = 0.0;
    for (int k = 0; k < UNET_CONVS; k++) conv[k] = u->t_conv[k], sum += u->t_conv[k];
    *plan = u->t_plan;
    *rest = u->t_total - u->t_plan - sum;
}

double unet_flops(const unet *u, int h, int w)
{
    double f = 0.0;
    for (int k = 0; k < UNET_CONVS; k++) {
        const conv_layer *l = &u->conv[k];
        double px = (double)(h >> level[k]) * (double)(w >> level[k]);
        f += 2.0 * 9.0 * (double)l->ic * (double)l->oc * px;
    }
    return f;
}

/* ---- pooling and upsampling on nChwBc ------------------------------------
 * Tensors are blocked by B channels (nChwBc: B = 16 where oneDNN has its
 * AVX-512 kernels, 8 on AVX2, where its fast convolutions take nChw8c and
 * nChw16c would fall back to its reference code, about 300x slower; see
 * unet_block). Channel counts stay multiples of 16, so of B. */

/* The channel block of the CPU: 16 with AVX-512 (F, BW, VL, DQ, which
 * oneDNN's avx512_core kernels need), else 8; 8 also where the config says
 * cpu.isa=avx2, so that an AVX-512 machine can run (and test) the kernels
 * of an AVX2 one. */
static int unet_block(const pk_context *ctx)
{
    if (ctx->config.cpu_avx2) return 8;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq"))
        return 16;
    return 8;
#else
    return 8;
#endif
}

/* dst (c channels, h/2 x w/2) = 2x2 maximum of src (c, h x w). */
static void pool2(const float *src, int c, int h, int w, float *dst, int threads, int B)
{
    const int h2 = h / 2, w2 = w / 2, rows = c / B * h2;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int r = 0; r < rows; r++) {
        const int cb = r / h2, y = r % h2;
        const float *a = src + (((size_t)cb * (size_t)h + 2 * (size_t)y) * (size_t)w) * (size_t)B;
        const float *b = a + (size_t)w * (size_t)B;
        float *o = dst + (((size_t)cb * (size_t)h2 + (size_t)y) * (size_t)w2) * (size_t)B;
        for (int x = 0; x < w2; x++)
            for (int k = 0; k < B; k++) {
                float m0 = fmaxf(a[2 * B * x + k], a[2 * B * x + B + k]), m1 = fmaxf(b[2 * B * x + k], b[2 * B * x + B + k]);
                o[B * x + k] = fmaxf(m0, m1);
            }
    }
}

/* dst (c, 2h x 2w) = src (c, h x w), each pixel repeated 2x2. */
static void upsample2(const float *src, int c, int h, int w, float *dst, int threads, int B)
{
    const int rows = c / B * h;
    const size_t px = (size_t)B * sizeof(float);
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int r = 0; r < rows; r++) {
        const int cb = r / h, y = r % h;
        const float *s = src + (((size_t)cb * (size_t)h + (size_t)y) * (size_t)w) * (size_t)B;
        float *o = dst + (((size_t)cb * 2 * (size_t)h + 2 * (size_t)y) * 2 * (size_t)w) * (size_t)B;
        for (int x = 0; x < w; x++) {
            memcpy(o + 2 * (size_t)B * (size_t)x, s + (size_t)B * (size_t)x, px);
            memcpy(o + 2 * (size_t)B * (size_t)x + (size_t)B, s + (size_t)B * (size_t)x, px);
        }
        memcpy(o + (size_t)w * 2 * (size_t)B, o, (size_t)w * 2 * px);
    }
}

/* planar (c, h x w) <-> nChwBc (round16(c) channels; padding channels zero) */
static void to_blocked(const float *planar, int c, int h, int w, float *dst, int threads, int B)
{
    const int cb_n = round16(c) / B;
    const size_t plane = (size_t)h * (size_t)w;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int r = 0; r < cb_n * h; r++) {
        const int cb = r / h, y = r % h;
        float *o = dst + ((size_t)cb * plane + (size_t)y * (size_t)w) * (size_t)B;
        for (int x = 0; x < w; x++)
            for (int k = 0; k < B; k++) {
                int ch = cb * B + k;
                o[B * x + k] = ch < c ? planar[(size_t)ch * plane + (size_t)y * (size_t)w + (size_t)x] : 0.0f;
            }
    }
}

static void from_blocked(const float *src, int c, int h, int w, float *planar, int B)
{
    const size_t plane = (size_t)h * (size_t)w;
    for (int ch = 0; ch < c; ch++)
        for (size_t p = 0; p < plane; p++)
            planar[(size_t)ch * plane + p] = src[((size_t)(ch / B) * plane + p) * (size_t)B + (size_t)(ch % B)];
}

#if PK_HAVE_DNNL

static pk_status dnnl_fail(pk_context *ctx, const char *what, dnnl_status_t s)
{
    if (s == dnnl_out_of_memory) return ctx_nomem(ctx);
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, "denoiser: oneDNN could not %s (status %d)", what, (int)s);
}

#define DN(call, what)                                                                                            \
    do {                                                                                                          \
        dnnl_status_t s_ = (call);                                                                                \
        if (s_ != dnnl_success) return dnnl_fail(u->ctx, what, s_);                                               \
    } while (0)

/* The convolution k from src (l->icp channels) to dst (l->oc channels) at
 * h x w, its weights reordered into the layout it chose. */
static pk_status make_conv(unet *u, int k, int h, int w, float *src, float *dst)
{
    conv_layer *l = &u->conv[k];
    dnnl_memory_desc_t smd, dmd, wmd, bmd, wplain;
    dnnl_dims_t sd = {1, l->icp, h, w}, dd = {1, l->oc, h, w}, wd = {l->oc, l->icp, 3, 3}, bd = {l->oc};
    dnnl_dims_t one = {1, 1}, pad = {1, 1};
    const dnnl_format_tag_t blocked = u->blk == 16 ? dnnl_nChw16c : dnnl_nChw8c;
    DN(dn.memory_desc_init_by_tag(&smd, 4, sd, dnnl_f32, blocked), "describe a tensor");
    DN(dn.memory_desc_init_by_tag(&dmd, 4, dd, dnnl_f32, blocked), "describe a tensor");
    DN(dn.memory_desc_init_by_tag(&wmd, 4, wd, dnnl_f32, dnnl_format_tag_any), "describe weights");
    DN(dn.memory_desc_init_by_tag(&wplain, 4, wd, dnnl_f32, dnnl_oihw), "describe weights");
    DN(dn.memory_desc_init_by_tag(&bmd, 1, bd, dnnl_f32, dnnl_x), "describe a bias");
    /* The direct convolution only, never oneDNN's Winograd kernels: which
     * of them it picks (F(4x4, 3x3) or F(2x2, 3x3)) and how F(4x4, 3x3)
     * blocks its sums both depend on the thread count (measured with
     * oneDNN 2.6 on AVX-512: 128->64 at 32x32 gives other bits with 2
     * threads than with 1, 3 or 4; 80->64 at 256x256 switches kernel at 16
     * threads), so an image would depend on --threads. The direct kernel
     * sums each output in the same order whatever the threads (checked
     * from 1 to 64 threads on every layer shape: docs/denoising.md). */
    dnnl_convolution_desc_t cd;
    DN(dn.convolution_forward_desc_init(&cd, dnnl_forward_inference, dnnl_convolution_direct, &smd, &wmd, &bmd,
                                        &dmd, one, pad, pad),
       "describe a convolution");
    dnnl_primitive_attr_t attr = NULL;
    dnnl_post_ops_t po = NULL;
    DN(dn.primitive_attr_create(&attr), "make attributes");
    /* one scratchpad for every layer (they run one after the other) */
    if (dn.primitive_attr_set_scratchpad_mode(attr, dnnl_scratchpad_mode_user) != dnnl_success) {
        dn.primitive_attr_destroy(attr);
        return dnnl_fail(u->ctx, "set the scratchpad mode", dnnl_runtime_error);
    }
    if (l->relu) {
        dnnl_status_t s = dn.post_ops_create(&po);
        if (s == dnnl_success) s = dn.post_ops_append_eltwise(po, 1.0f, dnnl_eltwise_relu, 0.0f, 0.0f);
        if (s == dnnl_success) s = dn.primitive_attr_set_post_ops(attr, po);
        if (po) dn.post_ops_destroy(po);
        if (s != dnnl_success) {
            dn.primitive_attr_destroy(attr);
            return dnnl_fail(u->ctx, "add a ReLU", s);
        }
    }
    dnnl_primitive_desc_t pd;
    dnnl_status_t s = dn.primitive_desc_create(&pd, &cd, attr, u->engine, NULL);
    dn.primitive_attr_destroy(attr);
    if (s != dnnl_success) return dnnl_fail(u->ctx, "make a convolution", s);
    const char *impl = NULL;
    if (dn.primitive_desc_query(pd, dnnl_query_impl_info_str, 0, &impl) == dnnl_success && impl &&
        !strstr(u->impl, impl) && strlen(u->impl) + strlen(impl) + 3 < sizeof u->impl)
        snprintf(u->impl + strlen(u->impl), sizeof u->impl - strlen(u->impl), "%s%s", u->impl[0] ? ", " : "", impl);
    const dnnl_memory_desc_t *pad_md = dn.primitive_desc_query_md(pd, dnnl_query_scratchpad_md, 0);
    l->scratch = pad_md ? *pad_md : (dnnl_memory_desc_t){0};
    const size_t pad_bytes = pad_md ? dn.memory_desc_get_size(pad_md) : 0;
    if (pad_bytes > u->scratch_bytes) u->scratch_bytes = pad_bytes;
    const dnnl_memory_desc_t chosen_md = *dn.primitive_desc_query_md(pd, dnnl_query_weights_md, 0);
    const dnnl_memory_desc_t *chosen = &chosen_md; /* a copy: pd goes below */
    size_t wbytes = dn.memory_desc_get_size(chosen);
    l->wbuf = mem_alloc_aligned(u->al, wbytes ? wbytes : 64, 64);
    if (!l->wbuf) {
        dn.primitive_desc_destroy(pd);
        return ctx_nomem(u->ctx);
    }
    s = dn.primitive_create(&l->prim, pd);
    if (s == dnnl_success) s = dn.memory_create(&l->wmem, chosen, u->engine, l->wbuf);
    dn.primitive_desc_destroy(pd);
    if (s == dnnl_success) s = dn.memory_create(&l->bmem, &bmd, u->engine, l->b);
    if (s == dnnl_success) s = dn.memory_create(&u->src[k], &smd, u->engine, src);
    if (s == dnnl_success) s = dn.memory_create(&u->dst[k], &dmd, u->engine, dst);
    if (s != dnnl_success) return dnnl_fail(u->ctx, "make a convolution's memory", s);
    /* weights: plain oihw -> the chosen layout */
    dnnl_memory_t plain = NULL;
    dnnl_primitive_desc_t rpd = NULL;
    dnnl_primitive_t reorder = NULL;
    s = dn.memory_create(&plain, &wplain, u->engine, l->w);
    if (s == dnnl_success) s = dn.reorder_primitive_desc_create(&rpd, &wplain, u->engine, chosen, u->engine, NULL);
    if (s == dnnl_success) s = dn.primitive_create(&reorder, rpd);
    if (s == dnnl_success) {
        dnnl_exec_arg_t args[2] = {{DNNL_ARG_FROM, plain}, {DNNL_ARG_TO, l->wmem}};
        s = dn.primitive_execute(reorder, u->stream, 2, args);
        if (s == dnnl_success) s = dn.stream_wait(u->stream);
    }
    if (reorder) dn.primitive_destroy(reorder);
    if (rpd) dn.primitive_desc_destroy(rpd);
    if (plain) dn.memory_destroy(plain);
    if (s != dnnl_success) return dnnl_fail(u->ctx, "reorder weights", s);
    return PK_OK;
}

/* size bytes, 64-byte aligned: the block to free is returned, *at the
 * aligned start inside it. On Linux the block's pages are asked to be huge
 * (transparent huge pages, where the system allows them on request) and are
 * made present at once (MADV_POPULATE_WRITE, Linux 5.14): on a virtual
 * machine with 4 KiB pages, the 70 000 page faults of the first touch of
 * 280 MiB and the TLB misses that follow cost more than the network itself
 * (the first pass at 512x512 on a Zen 5 EPYC guest: 740-890 ms, 270-314 ms
 * with both requests, 540-630 ms with either alone; later passes 205 ms in
 * every case: docs/denoising.md). Both are requests: where the kernel
 * refuses them, nothing changes but the time. */
static void *block_alloc(const pk_allocator *al, size_t size, void **at)
{
    void *block = mem_alloc(al, size + 64);
    if (!block) return NULL;
    *at = (void *)(((uintptr_t)block + 63) & ~(uintptr_t)63);
#ifdef __linux__
    const long pg = sysconf(_SC_PAGESIZE);
    const uintptr_t page = pg > 0 ? (uintptr_t)pg : 4096, a = ((uintptr_t)*at + page - 1) & ~(page - 1),
                    e = ((uintptr_t)*at + size) & ~(page - 1);
    if (e > a) {
#ifdef MADV_HUGEPAGE
        (void)madvise((void *)a, e - a, MADV_HUGEPAGE);
#endif
        (void)madvise((void *)a, e - a, MADV_POPULATE_WRITE);
    }
#endif
    return block;
}

static pk_status make_plan(unet *u, int h, int w, int threads)
{
    if (u->buf && u->h == h && u->w == w && u->threads == threads) return PK_OK;
    release_plan(u);
    u->impl[0] = '\0';
    if (!u->engine) {
        DN(dn.engine_create(&u->engine, dnnl_cpu, 0), "open the CPU engine");
        DN(dn.stream_create(&u->stream, u->engine, dnnl_stream_default_flags), "open a stream");
    }
    omp_set_num_threads(threads);
    plan_sizes s = sizes_of(u);
    size_t total = unet_activation_bytes(u, h, w);
    /* Hundreds of MiB touched once per image: every byte is written before
     * it is read (each layer's output, each part of a concatenation), so
     * nothing is cleared. */
    u->block = block_alloc(u->al, total, (void **)&u->buf);
    if (!u->block) return ctx_nomem(u->ctx);
    const size_t p0 = (size_t)h * (size_t)w;
    float *p = u->buf;
#define TAKE(name, ch, lv) (u->name = p, p += p0 / ((size_t)1 << (2 * (lv))) * (size_t)(ch))
    TAKE(cat1, s.cat1, 0); TAKE(t0a, s.t0a, 0); TAKE(t0b, s.t0b, 0);
    TAKE(cat2, s.cat2, 1); TAKE(t1a, s.t1a, 1); TAKE(t1b, s.t1b, 1);
    TAKE(cat3, s.cat3, 2); TAKE(t2a, s.t2a, 2); TAKE(t2b, s.t2b, 2);
    TAKE(cat4, s.cat4, 3); TAKE(t3a, s.t3a, 3); TAKE(t3b, s.t3b, 3);
    TAKE(t4a, s.t4a, 4); TAKE(t4b, s.t4b, 4);
#undef TAKE
    const size_t p1 = p0 / 4, p2 = p0 / 16, p3 = p0 / 64;
    struct { float *src, *dst; int lv; } io[UNET_CONVS] = {
        {u->cat1 + (size_t)u->d2b * p0, u->t0b, 0}, {u->t0b, u->t0a, 0},
        {u->cat2 + (size_t)u->d3 * p1, u->t1a, 1}, {u->cat3 + (size_t)u->d4 * p2, u->t2a, 2},
        {u->cat4 + (size_t)u->c[5] * p3, u->t3a, 3}, {u->t4a, u->t4b, 4}, {u->t4b, u->t4a, 4},
        {u->cat4, u->t3a, 3}, {u->t3a, u->t3b, 3}, {u->cat3, u->t2a, 2}, {u->t2a, u->t2b, 2},
        {u->cat2, u->t1a, 1}, {u->t1a, u->t1b, 1}, {u->cat1, u->t0a, 0}, {u->t0a, u->t0b, 0},
        {u->t0b, u->t0a, 0}};
    for (int k = 0; k < UNET_CONVS; k++) {
        pk_status st = make_conv(u, k, h >> io[k].lv, w >> io[k].lv, io[k].src, io[k].dst);
        if (st) {
            release_plan(u);
            return st;
        }
    }
    if (u->scratch_bytes) {
        u->scratch_block = block_alloc(u->al, u->scratch_bytes, (void **)&u->scratch);
        if (!u->scratch_block) {
            release_plan(u);
            return ctx_nomem(u->ctx);
        }
    }
    for (int k = 0; k < UNET_CONVS; k++) {
        conv_layer *l = &u->conv[k];
        if (dn.memory_desc_get_size(&l->scratch) == 0) continue;
        dnnl_status_t ms = dn.memory_create(&l->pad, &l->scratch, u->engine, u->scratch);
        if (ms != dnnl_success) {
            release_plan(u);
            return dnnl_fail(u->ctx, "make a scratchpad", ms);
        }
    }
    u->h = h, u->w = w, u->threads = threads;
    return PK_OK;
}

static pk_status run_conv(unet *u, int k)
{
    const double t0 = time_now();
    conv_layer *l = &u->conv[k];
    dnnl_exec_arg_t args[5] = {{DNNL_ARG_SRC, u->src[k]}, {DNNL_ARG_WEIGHTS, l->wmem}, {DNNL_ARG_BIAS, l->bmem},
                               {DNNL_ARG_DST, u->dst[k]}, {DNNL_ARG_SCRATCHPAD, l->pad}};
    DN(dn.primitive_execute(l->prim, u->stream, l->pad ? 5 : 4, args), "run a convolution");
    DN(dn.stream_wait(u->stream), "finish a convolution");
    u->t_conv[k] = time_now() - t0;
    return PK_OK;
}

/* Reports layer k's output (blocked, c channels at level lv) to the test hook. */
static pk_status report(unet *u, unet_layer_fn layer, void *user, const char *name, const float *blocked, int c,
                        int lv)
{
    if (!layer) return PK_OK;
    int hl = u->h >> lv, wl = u->w >> lv;
    float *pl = mem_alloc(u->al, (size_t)c * (size_t)hl * (size_t)wl * sizeof(float));
    if (!pl) return ctx_nomem(u->ctx);
    from_blocked(blocked, c, hl, wl, pl, u->blk);
    layer(user, name, c, hl, wl, pl);
    mem_free(u->al, pl);
    return PK_OK;
}

pk_status unet_run(pk_context *ctx, unet *u, int h, int w, int threads, const float *in, float *out,
                   unet_layer_fn layer, void *user)
{
    if (h <= 0 || w <= 0 || h % 16 || w % 16)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "denoiser: a network pass over %dx%d (sides are multiples of 16)", w, h);
    char why[384];
    if (!unet_backend_available(ctx, why, sizeof why)) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "denoiser: %s", why);
    u->ctx = ctx;
    if (threads < 1) threads = 1;
    const double t0 = time_now();
    pk_status st = make_plan(u, h, w, threads);
    if (st) return st;
    u->t_plan = time_now() - t0;
    omp_set_num_threads(threads);
    const size_t p0 = (size_t)h * (size_t)w, p1 = p0 / 4, p2 = p0 / 16, p3 = p0 / 64;
    float *input = u->cat1 + (size_t)u->d2b * p0;
    to_blocked(in, u->ic, h, w, input, threads, u->blk);
#define CONV(k, dstp, c, lv)                                                                                      \
    do {                                                                                                          \
        if ((st = run_conv(u, k)) || (st = report(u, layer, user, unet_conv_names[k], dstp, c, lv))) return st;  \
    } while (0)
    CONV(ENC0, u->t0b, u->c[1], 0);
    CONV(ENC1, u->t0a, u->c[1], 0);
    pool2(u->t0a, u->c[1], h, w, u->cat2 + (size_t)u->d3 * p1, threads, u->blk);
    CONV(ENC2, u->t1a, u->c[2], 1);
    pool2(u->t1a, u->c[2], h >> 1, w >> 1, u->cat3 + (size_t)u->d4 * p2, threads, u->blk);
    CONV(ENC3, u->t2a, u->c[3], 2);
    pool2(u->t2a, u->c[3], h >> 2, w >> 2, u->cat4 + (size_t)u->c[5] * p3, threads, u->blk);
    CONV(ENC4, u->t3a, u->c[4], 3);
    pool2(u->t3a, u->c[4], h >> 3, w >> 3, u->t4a, threads, u->blk);
    CONV(ENC5A, u->t4b, u->c[5], 4);
    CONV(ENC5B, u->t4a, u->c[5], 4);
    upsample2(u->t4a, u->c[5], h >> 4, w >> 4, u->cat4, threads, u->blk);
    CONV(DEC4A, u->t3a, u->d4, 3);
    CONV(DEC4B, u->t3b, u->d4, 3);
    upsample2(u->t3b, u->d4, h >> 3, w >> 3, u->cat3, threads, u->blk);
    CONV(DEC3A, u->t2a, u->d3, 2);
    CONV(DEC3B, u->t2b, u->d3, 2);
    upsample2(u->t2b, u->d3, h >> 2, w >> 2, u->cat2, threads, u->blk);
    CONV(DEC2A, u->t1a, u->d2a, 1);
    CONV(DEC2B, u->t1b, u->d2b, 1);
    upsample2(u->t1b, u->d2b, h >> 1, w >> 1, u->cat1, threads, u->blk);
    CONV(DEC1A, u->t0a, u->d1a, 0);
    CONV(DEC1B, u->t0b, u->d1b, 0);
    CONV(DEC0, u->t0a, 3, 0);
#undef CONV
    from_blocked(u->t0a, 3, h, w, out, u->blk);
    u->t_total = time_now() - t0;
    return PK_OK;
}

#else

pk_status unet_run(pk_context *ctx, unet *u, int h, int w, int threads, const float *in, float *out,
                   unet_layer_fn layer, void *user)
{
    (void)u, (void)h, (void)w, (void)threads, (void)in, (void)out, (void)layer, (void)user;
    (void)pool2, (void)upsample2, (void)to_blocked, (void)from_blocked, (void)unet_block;
    char why[384];
    unet_backend_available(ctx, why, sizeof why);
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, "denoiser: %s", why);
}

#endif

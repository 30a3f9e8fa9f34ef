/*
 * denoise_dump.c - runs the denoiser's network and its whole pipeline on
 * random inputs and writes every input, layer output and result as raw
 * float32 files, for the NumPy oracle (oracle.py) to recompute
 * independently. It checks here that the results are bit-identical for 1, 2
 * and 3 threads (the network) and 1, 2, 3 and 8 (the pipeline).
 *   denoise_dump WEIGHTS.tza OUTDIR
 */
#include "denoise/denoise.h"
#include "denoise/tza.h"
#include "denoise/unet.h"

#include "test_rng.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *outdir;
static int failures;

static void put(const char *name, const float *v, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.bin", outdir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(v, sizeof(float), n, f) != n) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    fclose(f);
}

static void on_layer(void *user, const char *name, int c, int h, int w, const float *planar)
{
    (void)user;
    char n[128];
    snprintf(n, sizeof n, "layer_%s", name);
    put(n, planar, (size_t)c * (size_t)h * (size_t)w);
}

static float *fill(size_t n, rng *r, float lo, float hi)
{
    float *v = malloc(n * sizeof(float));
    for (size_t i = 0; i < n; i++) v[i] = lo + (hi - lo) * rng_f(r);
    return v;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: denoise_dump WEIGHTS.tza OUTDIR\n");
        return 2;
    }
    outdir = argv[2];
    pk_context *ctx;
    pk_context_create(NULL, &ctx);
    /* PAPRSEK_CPU_ISA=avx2: the AVX2 path (8-channel blocks) on any CPU */
    const char *isa = getenv("PAPRSEK_CPU_ISA");
    if (isa && *isa) {
        char kv[64];
        snprintf(kv, sizeof kv, "cpu.isa=%s", isa);
        if (pk_context_set_config(ctx, kv)) {
            fprintf(stderr, "%s\n", pk_context_error(ctx));
            return 2;
        }
    }
    char why[384];
    if (!unet_backend_available(ctx, why, sizeof why)) {
        printf("SKIP: %s\n", why);
        return 77;
    }
    FILE *f = fopen(argv[1], "rb");
    if (!f) {
        printf("SKIP: no weights at %s (make weights)\n", argv[1]);
        return 77;
    }
    fseek(f, 0, SEEK_END);
    size_t size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    char *data = malloc(size);
    if (fread(data, 1, size, f) != size) return 1;
    fclose(f);
    tza_archive a;
    unet *u;
    if (tza_parse(ctx, argv[1], data, size, &a) || unet_create(ctx, argv[1], &a, &u)) {
        fprintf(stderr, "%s\n", pk_context_error(ctx));
        return 1;
    }
    rng gen = {7};

    /* 1. the network alone on random input in [0, 1) */
    const int H = 48, W = 32, ic = unet_input_channels(u);
    float *in = fill((size_t)ic * H * W, &gen, 0.0f, 1.0f);
    float *out[3];
    put("net_in", in, (size_t)ic * H * W);
    for (int t = 1; t <= 3; t++) {
        out[t - 1] = malloc(3 * H * W * sizeof(float));
        if (unet_run(ctx, u, H, W, t, in, out[t - 1], t == 1 ? on_layer : NULL, NULL)) {
            fprintf(stderr, "%s\n", pk_context_error(ctx));
            return 1;
        }
        if (t > 1 && memcmp(out[0], out[t - 1], 3 * H * W * sizeof(float)) != 0) {
            fprintf(stderr, "FAIL: the network's output with %d threads differs from 1 thread's\n", t);
            failures++;
        }
    }
    put("net_out", out[0], 3 * H * W);
    printf("network %dx%d, %d input channels: %s, %.1f MFLOP\n", W, H, ic, unet_backend_impl(u),
           unet_flops(u, H, W) * 1e-6);

    /* 2. the whole pipeline: HDR colour with a few bad values, albedo, normal;
     * tiled (64, overlap 16) and whole, with 1 thread and with 2, 3 and 8
     * (oneDNN's choices of kernel and of work split depend on the thread
     * count: the bits must not) */
    const int IW = 150, IH = 110;
    const size_t n = 3 * (size_t)IW * IH;
    float *color = malloc(n * sizeof(float)), *alb = fill(n, &gen, -0.1f, 1.2f), *nrm = fill(n, &gen, -1.1f, 1.1f);
    for (size_t i = 0; i < n; i++) color[i] = -logf(1.0f - rng_f(&gen) * 0.999f) * 3.0f;
    color[5] = NAN, color[300] = INFINITY, color[1000] = -2.0f, color[2000] = 1e6f;
    put("img_color", color, n);
    put("img_albedo", alb, n);
    put("img_normal", nrm, n);
    pk_denoise_options o;
    pk_denoise_options_init(&o);
    o.weights = argv[1];
    const struct { const char *name; int tile, ov; } runs[] = {{"img_tiled", 64, 16}, {"img_whole", 0, 0}};
    const int threads[] = {1, 2, 3, 8};
    float *res[4];
    for (int r = 0; r < 2; r++)
        for (int t = 0; t < 4; t++) {
            o.tile_size = runs[r].tile, o.tile_overlap = runs[r].ov, o.threads = threads[t];
            pk_denoiser *d;
            res[t] = malloc(n * sizeof(float));
            if (pk_denoiser_create(ctx, &o, &d) || denoise_raw(d, IW, IH, color, alb, nrm, res[t])) {
                fprintf(stderr, "%s\n", pk_context_error(ctx));
                return 1;
            }
            pk_denoiser_destroy(d);
            if (t == 0) put(runs[r].name, res[t], n);
            else if (memcmp(res[t], res[0], n * sizeof(float)) != 0) {
                fprintf(stderr, "FAIL: %s with %d threads differs from 1 thread's\n", runs[r].name, threads[t]);
                failures++;
            }
            if (t == 3)
                for (int k = 0; k < 4; k++) free(res[k]);
        }
    float scale = (float)denoise_autoexposure(color, IW, IH);
    put("img_scale", &scale, 1);
    printf("pipeline %dx%d: exposure scale %g\n", IW, IH, (double)scale);
    for (int t = 0; t < 3; t++) free(out[t]);
    free(in);
    free(color);
    free(alb);
    free(nrm);
    unet_destroy(u);
    tza_free(&ctx->alloc, &a);
    free(data);
    pk_context_destroy(ctx);
    return failures ? 1 : 0;
}

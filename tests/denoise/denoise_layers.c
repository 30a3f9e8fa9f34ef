/*
 * denoise_layers.c - the network's time layer by layer, for
 * bench/denoise_layers.sh (not a test): REPS passes over a W x H image of
 * random input after one pass that also plans; for each convolution its
 * shape, its GFLOP, the median of its times and its GFLOP/s, and its share
 * of PEAK (GFLOP/s, the CPU's FMA peak at this thread count, from
 * bench/fma_peak.c; 0 leaves the column out).
 *   denoise_layers WEIGHTS.tza W H THREADS REPS [PEAK]
 */
#include "denoise/tza.h"
#include "denoise/unet.h"

#include "test_rng.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: denoise_layers WEIGHTS.tza W H THREADS REPS [PEAK]\n");
        return 2;
    }
    const int W = atoi(argv[2]), H = atoi(argv[3]), T = atoi(argv[4]), R = atoi(argv[5]);
    const double peak = argc > 6 ? atof(argv[6]) : 0.0;
    if (W <= 0 || H <= 0 || W % 16 || H % 16 || T < 1 || R < 1 || R > 1000) {
        fprintf(stderr, "denoise_layers: sides are multiples of 16, threads and passes at least 1\n");
        return 2;
    }
    pk_context *ctx;
    pk_context_create(NULL, &ctx);
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
    if (!data || fread(data, 1, size, f) != size) return 1;
    fclose(f);
    tza_archive a;
    unet *u;
    if (tza_parse(ctx, argv[1], data, size, &a) || unet_create(ctx, argv[1], &a, &u)) {
        fprintf(stderr, "%s\n", pk_context_error(ctx));
        return 1;
    }
    rng gen = {11};
    const int ic = unet_input_channels(u);
    float *in = malloc(sizeof(float) * (size_t)ic * (size_t)W * (size_t)H);
    float *out = malloc(sizeof(float) * 3 * (size_t)W * (size_t)H);
    for (size_t i = 0; i < (size_t)ic * (size_t)W * (size_t)H; i++) in[i] = rng_f(&gen);
    double *t = malloc(sizeof(double) * (size_t)R * (UNET_CONVS + 2)), plan0 = 0.0, first = 0.0;
    for (int r = -1; r < R; r++) {
        double plan, conv[UNET_CONVS], rest;
        if (unet_run(ctx, u, H, W, T, in, out, NULL, NULL)) {
            fprintf(stderr, "%s\n", pk_context_error(ctx));
            return 1;
        }
        unet_last_times(u, &plan, conv, &rest);
        if (r < 0) {
            plan0 = plan;
            first = rest + plan;
            for (int k = 0; k < UNET_CONVS; k++) first += conv[k];
            continue;
        }
        double sum = rest;
        for (int k = 0; k < UNET_CONVS; k++) t[k * R + r] = conv[k], sum += conv[k];
        t[UNET_CONVS * R + r] = rest;
        t[(UNET_CONVS + 1) * R + r] = sum;
    }
    printf("%dx%d, %d threads, %d passes (medians); kernels: %s; the first pass %.1f ms, of which planning %.1f ms\n",
           W, H, T, R, unet_backend_impl(u), first * 1e3, plan0 * 1e3);
    printf("| layer | channels | size | GFLOP | ms | GFLOP/s |%s\n", peak > 0 ? " of peak |" : "");
    printf("|---|---|---|---|---|---|%s\n", peak > 0 ? "---|" : "");
    double flop_all = 0.0;
    for (int k = 0; k < UNET_CONVS; k++) {
        int lic, loc, lv;
        unet_layer_shape(u, k, &lic, &loc, &lv);
        const double fl = 2.0 * 9.0 * lic * loc * (double)(W >> lv) * (double)(H >> lv);
        const double ms = median(t + k * R, R) * 1e3;
        flop_all += fl;
        printf("| %s | %d→%d | %dx%d | %.2f | %.2f | %.0f |", unet_conv_names[k], lic, loc, W >> lv, H >> lv, fl * 1e-9,
               ms, fl / ms * 1e-6);
        if (peak > 0) printf(" %.0f %% |", 100.0 * fl / ms * 1e-6 / peak);
        printf("\n");
    }
    const double rest = median(t + UNET_CONVS * R, R) * 1e3, all = median(t + (UNET_CONVS + 1) * R, R) * 1e3;
    printf("| pooling, upsampling, layouts | | | | %.2f | |%s\n", rest, peak > 0 ? " |" : "");
    printf("| network | | %dx%d | %.2f | %.2f | %.0f |", W, H, flop_all * 1e-9, all, flop_all / all * 1e-6);
    if (peak > 0) printf(" %.0f %% |", 100.0 * flop_all / all * 1e-6 / peak);
    printf("\n");
    unet_destroy(u);
    tza_free(&ctx->alloc, &a);
    free(data);
    free(in);
    free(out);
    free(t);
    pk_context_destroy(ctx);
    return 0;
}

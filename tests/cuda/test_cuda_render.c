/*
 * test_cuda_render.c - the GPU path tracer (--device cuda) renders the same
 * image as the CPU's, statistically: each scene is rendered K times on each
 * device with independent seeds; for every region of the image (a grid of
 * blocks) and colour channel, the K per-render means of the two devices are
 * compared by Welch's t-test, and every p-value must exceed 1e-3 divided by
 * the number of comparisons (Bonferroni: a correct GPU fails this test with
 * probability below 1e-3). Tolerances come from the measured spread of the
 * renders, nothing else.
 *
 * Also: a long render stops soon after its progress callback asks.
 *
 * usage: test_cuda_render SCENE... (exit 77: no CUDA device; skipped)
 */
#include "paprsek.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define K 12        /* renders per device */
#define SIDE 48     /* image side */
#define GRID 4      /* GRID x GRID regions */
#define SPP 16
#define ALPHA 1e-3

/* Student's t density with nu degrees of freedom. */
static double t_pdf(double x, double nu)
{
    return exp(lgamma((nu + 1) / 2) - lgamma(nu / 2) - 0.5 * log(nu * M_PI) - (nu + 1) / 2 * log1p(x * x / nu));
}

/* Two-sided p-value of t (Simpson's rule on the tail, in u = 1/(1+x)). */
static double t_pvalue(double t, double nu)
{
    t = fabs(t);
    const int n = 4000;
    const double a = 0.0, b = 1.0 / (1.0 + t); /* x = 1/u - 1, dx = du / u^2 */
    double s = 0.0;
    for (int i = 0; i <= n; i++) {
        double u = a + (b - a) * i / n;
        double f = u > 0.0 ? t_pdf(1.0 / u - 1.0, nu) / (u * u) : 0.0;
        s += f * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
    }
    return 2.0 * s * (b - a) / (3.0 * n);
}

/* Region means (GRID*GRID*3) of one render; false on an error (printed). */
static int render_means(pk_context *ctx, const pk_scene *sc, pk_accel_kind kind, int seed, double *means,
                        int *skipped)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = SIDE;
    o.spp = SPP;
    o.seed = seed;
    o.accel = kind;
    pk_image *img = NULL;
    pk_status st = pk_render(ctx, sc, &o, &img, NULL);
    if (st != PK_OK) {
        const char *msg = pk_context_error(ctx);
        if (kind == PK_ACCEL_CUDA && msg && (strstr(msg, "no CUDA") || strstr(msg, "not available"))) {
            printf("SKIP: %s\n", msg);
            *skipped = 1;
        } else {
            fprintf(stderr, "render failed: %s\n", msg ? msg : "?");
        }
        pk_image_destroy(img);
        return 0;
    }
    const float *px = pk_image_pixels_const(img);
    memset(means, 0, sizeof(double) * GRID * GRID * 3);
    const int cell = SIDE / GRID;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++)
            for (int c = 0; c < 3; c++) {
                float v = px[3 * (y * SIDE + x) + c];
                if (!isfinite(v)) {
                    fprintf(stderr, "pixel %d,%d is not finite\n", x, y);
                    pk_image_destroy(img);
                    return 0;
                }
                means[3 * ((y / cell) * GRID + x / cell) + c] += (double)v / (double)(cell * cell);
            }
    pk_image_destroy(img);
    return 1;
}

/* Cancels at the first report after some work was done. */
static int cancel_soon(void *user, uint64_t done, uint64_t total, double elapsed)
{
    (void)total, (void)elapsed;
    int *calls = user;
    ++*calls;
    return done > 0;
}

/* A long render on the GPU stops soon after its progress callback asks,
 * with PK_ERR_CANCELLED and the message. */
static int check_cancel(pk_context *ctx, const pk_scene *sc)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = 256;
    o.spp = 1 << 16; /* minutes on any GPU */
    o.accel = PK_ACCEL_CUDA;
    int calls = 0;
    o.progress = cancel_soon;
    o.progress_user = &calls;
    pk_image *img = NULL;
    const pk_status st = pk_render(ctx, sc, &o, &img, NULL);
    pk_image_destroy(img);
    const char *msg = pk_context_error(ctx);
    if (st != PK_ERR_CANCELLED || !msg || !strstr(msg, "cancelled")) {
        fprintf(stderr, "cancelling: status %d, message %s\n", (int)st, msg ? msg : "(none)");
        return 0;
    }
    printf("cancelled after %d progress report(s): %s\n", calls, msg);
    pk_context_clear_error(ctx);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_cuda_render SCENE...\n");
        return 2;
    }
    if (!pk_accel_available(PK_ACCEL_CUDA)) {
        printf("SKIP: built without CUDA\n");
        return 77;
    }
    int failures = 0, skipped = 0;
    const int ncmp = GRID * GRID * 3;
    const double p_min = ALPHA / ((double)ncmp * (double)(argc - 1));
    for (int a = 1; a < argc; a++) {
        pk_context *ctx = NULL;
        pk_scene *sc = NULL;
        if (pk_context_create(NULL, &ctx) != PK_OK) return 1;
        /* the kernels' module this build made (the library looks for it
         * beside itself, and this test runs from tests/) */
        char cfg[600];
        snprintf(cfg, sizeof cfg, "cuda.module=%s", PK_CUDA_MODULE);
        if (pk_context_set_config(ctx, cfg) != PK_OK) return 1;
        if (pk_scene_load_file(ctx, argv[a], &sc) != PK_OK) {
            fprintf(stderr, "%s: %s\n", argv[a], pk_context_error(ctx));
            pk_context_destroy(ctx);
            return 1;
        }
        static double m[2][K][GRID * GRID * 3];
        int rendered = 1;
        for (int d = 0; d < 2 && rendered; d++)
            for (int k = 0; k < K && rendered; k++)
                /* independent seeds: 1..K on the CPU, K+1..2K on the GPU */
                rendered = render_means(ctx, sc, d ? PK_ACCEL_CUDA : PK_ACCEL_BVH, 1 + d * K + k, m[d][k], &skipped);
        if (!rendered) {
            pk_scene_destroy(sc);
            pk_context_destroy(ctx);
            return skipped ? 77 : 1;
        }
        double worst_p = 1.0, sum_cpu = 0.0, sum_gpu = 0.0;
        int worst = 0;
        for (int i = 0; i < ncmp; i++) {
            double mean[2] = {0, 0}, var[2] = {0, 0};
            for (int d = 0; d < 2; d++) {
                for (int k = 0; k < K; k++) mean[d] += m[d][k][i] / K;
                for (int k = 0; k < K; k++) var[d] += (m[d][k][i] - mean[d]) * (m[d][k][i] - mean[d]) / (K - 1);
            }
            sum_cpu += mean[0];
            sum_gpu += mean[1];
            const double se2 = var[0] / K + var[1] / K;
            double p;
            if (se2 > 0.0) {
                const double t = (mean[1] - mean[0]) / sqrt(se2);
                const double nu = se2 * se2 / ((var[0] / K) * (var[0] / K) / (K - 1) + (var[1] / K) * (var[1] / K) / (K - 1));
                p = t_pvalue(t, nu);
            } else {
                p = mean[0] == mean[1] ? 1.0 : 0.0; /* no noise at all: they must be equal */
            }
            if (p < worst_p) worst_p = p, worst = i;
            if (p < p_min) {
                fprintf(stderr, "%s: region %d channel %d: CPU %.5f, GPU %.5f (p = %.2g < %.2g)\n", argv[a],
                        i / 3, i % 3, mean[0], mean[1], p, p_min);
                failures++;
            }
        }
        printf("%s: image mean CPU %.5f GPU %.5f (ratio %.4f); smallest p %.3g (region %d channel %d), bound %.2g\n",
               argv[a], sum_cpu / ncmp, sum_gpu / ncmp, sum_gpu / sum_cpu, worst_p, worst / 3, worst % 3, p_min);
        if (a == 1 && !check_cancel(ctx, sc)) failures++;
        if (!(sum_cpu > 0.0)) {
            fprintf(stderr, "%s: the CPU image is black: not a test of anything\n", argv[a]);
            failures++;
        }
        pk_scene_destroy(sc);
        pk_context_destroy(ctx);
    }
    return failures ? 1 : 0;
}

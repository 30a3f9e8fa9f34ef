/*
 * fma_peak.c - the CPU's own single-precision FMA peak, to judge how close a
 * convolution comes to it (bench/denoise_layers.sh). Each thread runs
 * independent chains of fused multiply-adds on registers, enough of them
 * to hide the FMA latency (4 cycles) behind the throughput of two FMA
 * pipes, in 256-bit (AVX2) and 512-bit (AVX-512) registers, and the
 * program prints GFLOP/s per width for 1 thread and for N threads
 * (counting an FMA as 2 FLOP per lane).
 *
 *   gcc -O2 -fopenmp bench/fma_peak.c -o fma_peak && ./fma_peak [THREADS]
 *
 * On a CPU whose 512-bit FMAs run as two 256-bit halves (AMD Zen 4) both
 * widths give about the same figure; on one with two 512-bit FMA pipes
 * (Intel server cores) the 512-bit figure is twice the 256-bit one.
 */
#include <immintrin.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define CHAINS 12
#define ITERS 20000000L

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* FLOP done; the sum is returned through sink so nothing is optimised away */
__attribute__((target("avx2,fma"))) static double run256(long iters, float *sink)
{
    __m256 acc[CHAINS];
    const __m256 a = _mm256_set1_ps(0.999999f), b = _mm256_set1_ps(1e-7f);
    for (int i = 0; i < CHAINS; i++) acc[i] = _mm256_set1_ps((float)i);
    for (long k = 0; k < iters; k++) {
#pragma GCC unroll 12
        for (int i = 0; i < CHAINS; i++) acc[i] = _mm256_fmadd_ps(acc[i], a, b);
    }
    __m256 s = acc[0];
    for (int i = 1; i < CHAINS; i++) s = _mm256_add_ps(s, acc[i]);
    float v[8];
    _mm256_storeu_ps(v, s);
    *sink += v[0];
    return 2.0 * 8.0 * CHAINS * (double)iters;
}

__attribute__((target("avx512f"))) static double run512(long iters, float *sink)
{
    __m512 acc[CHAINS];
    const __m512 a = _mm512_set1_ps(0.999999f), b = _mm512_set1_ps(1e-7f);
    for (int i = 0; i < CHAINS; i++) acc[i] = _mm512_set1_ps((float)i);
    for (long k = 0; k < iters; k++) {
#pragma GCC unroll 12
        for (int i = 0; i < CHAINS; i++) acc[i] = _mm512_fmadd_ps(acc[i], a, b);
    }
    __m512 s = acc[0];
    for (int i = 1; i < CHAINS; i++) s = _mm512_add_ps(s, acc[i]);
    *sink += _mm512_reduce_add_ps(s);
    return 2.0 * 16.0 * CHAINS * (double)iters;
}

static double measure(int width, int threads)
{
    double flop = 0.0, best = 0.0;
    float sink = 0.0f;
    for (int rep = 0; rep < 3; rep++) { /* the best of 3: the machine is shared */
        double t0 = now();
        flop = 0.0;
#pragma omp parallel num_threads(threads) reduction(+ : flop, sink)
        {
            long iters = width == 512 ? ITERS / 2 : ITERS;
            flop += width == 512 ? run512(iters, &sink) : run256(iters, &sink);
        }
        double g = flop / (now() - t0) * 1e-9;
        if (g > best) best = g;
    }
    if (sink == 12345.0f) printf(" ");
    return best;
}

int main(int argc, char **argv)
{
    int threads = argc > 1 ? atoi(argv[1]) : omp_get_num_procs();
    __builtin_cpu_init();
    const int has512 = __builtin_cpu_supports("avx512f");
    if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
        printf("this CPU has no AVX2 with FMA\n");
        return 1;
    }
    printf("width  threads  GFLOP/s\n");
    const int counts[2] = {1, threads};
    for (int i = 0; i < (threads > 1 ? 2 : 1); i++) {
        printf("256    %-7d  %.1f\n", counts[i], measure(256, counts[i]));
        if (has512) printf("512    %-7d  %.1f\n", counts[i], measure(512, counts[i]));
    }
    if (!has512) printf("512    (no AVX-512 on this CPU)\n");
    return 0;
}

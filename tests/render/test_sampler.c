/*
 * test_sampler.c - the path tracer's sampler (render/sampler.h).
 *
 * The loop-free second Sobol dimension equals the direction-number loop;
 * the first 2^k samples of every pixel form a (0, k, 2)-net in every pair of
 * dimensions (each of the 2^k elementary intervals of every shape holds
 * exactly one point), which is what Owen scrambling and the index shuffle
 * must preserve; pairs are uncorrelated; and across pixels the points are
 * uniform (chi-square).
 */
#include "test.h"

#include "chi2.h"
#include "render/sampler.h"
#include "render/sampling.h"

#include <stdint.h>

static uint32_t naive_reverse(uint32_t x)
{
    uint32_t r = 0;
    for (int b = 0; b < 32; b++)
        if (x & (1u << b)) r |= 1u << (31 - b);
    return r;
}

static void test_bits(void)
{
    rng r = rng_seed(1, 2);
    int bad_rev = 0, bad_sobol = 0;
    for (uint32_t k = 0; k < (1u << 20) + 4096; k++) {
        uint32_t i = k < (1u << 20) ? k : rng_u32(&r); /* every 20-bit index, then random 32-bit ones */
        if (smp_reverse_bits(i) != naive_reverse(i)) bad_rev++;
        if (smp_sobol1_rev(i) != smp_reverse_bits(smp_sobol1(i))) bad_sobol++;
    }
    CHECKF(bad_rev == 0, "%d bit reversals wrong", bad_rev);
    CHECKF(bad_sobol == 0, "%d loop-free Sobol values differ from the loop", bad_sobol);
}

/* Whether n = 2^k points (u, v) form a (0, k, 2)-net. */
static bool is_net(const float *u, const float *v, int k)
{
    const int n = 1 << k;
    static int cells[1 << 12];
    for (int a = 0; a <= k; a++) { /* intervals 2^-a wide, 2^-(k-a) high */
        memset(cells, 0, sizeof(int) * (size_t)n);
        for (int i = 0; i < n; i++) {
            int x = (int)(u[i] * (float)(1 << a)), y = (int)(v[i] * (float)(1 << (k - a)));
            if (x < 0 || x >= (1 << a) || y < 0 || y >= (1 << (k - a))) return false;
            if (++cells[(y << a) | x] > 1) return false;
        }
    }
    return true;
}

static void test_nets(void)
{
    static float u[4][1 << 12], v[4][1 << 12];
    int bad = 0, checked = 0;
    for (uint32_t px = 0; px < 6; px++)
        for (uint32_t seed = 0; seed < 2; seed++) {
            const int k_max = 12;
            for (int i = 0; i < (1 << k_max); i++) {
                sampler s = sampler_start(px, 3 * px + 1, (uint32_t)i, seed);
                for (int d = 0; d < 4; d++) sampler_2d(&s, &u[d][i], &v[d][i]);
            }
            for (int d = 0; d < 4; d++)
                for (int k = 1; k <= k_max; k++) {
                    checked++;
                    if (!is_net(u[d], v[d], k)) bad++;
                }
            /* pairs are not correlated with one another: |r| within 4.5 / sqrt(n) */
            const int n = 1 << k_max;
            for (int d = 1; d < 4; d++) {
                double su = 0, sv = 0, suu = 0, svv = 0, suv = 0;
                for (int i = 0; i < n; i++) {
                    double a = u[0][i], b = u[d][i];
                    su += a, sv += b, suu += a * a, svv += b * b, suv += a * b;
                }
                double cov = suv / n - su / n * sv / n;
                double corr = cov / sqrt((suu / n - su / n * su / n) * (svv / n - sv / n * sv / n));
                CHECKF(fabs(corr) < 4.5 / sqrt((double)n), "pixel %u pair %d: correlation %g with pair 0", px, d,
                       corr);
            }
        }
    printf("(0,k,2)-nets: %d of %d prefixes are nets\n", checked - bad, checked);
    CHECK(bad == 0);
}

/* Sample 0 over many pixels: uniform in 16 x 16 cells. */
static void test_across_pixels(void)
{
    enum { G = 16, N = 256 * 256 };
    static int cells[G * G];
    for (uint32_t p = 0; p < N; p++) {
        sampler s = sampler_start(p & 255u, p >> 8, 0, 7);
        float a, b;
        sampler_2d(&s, &a, &b);
        cells[(int)(b * G) * G + (int)(a * G)]++;
    }
    double chi2 = 0.0, e = (double)N / (G * G);
    for (int c = 0; c < G * G; c++) chi2 += (cells[c] - e) * (cells[c] - e) / e;
    double pv = chi2_pvalue(chi2, G * G - 1);
    printf("sample 0 across pixels: chi2 %.1f, p = %.3g\n", chi2, pv);
    CHECK(pv > 1e-4);
}

int main(void)
{
    test_bits();
    test_nets();
    test_across_pixels();
    return test_done("test_sampler");
}

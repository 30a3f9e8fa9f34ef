/*
 * block_stats.h - comparing two Monte Carlo estimators of one image, block
 * by block, with variances measured rather than assumed (tests/render).
 *
 * Each estimator renders the image twice with independent random numbers.
 * For every pixel the difference of the two renders has mean 0 and variance
 * 2 sigma_p^2, so sum_p (a_p - b_p)^2 / 2 estimates sum_p sigma_p^2 without
 * bias, and the mean of the two renders over a block of n pixels has
 * variance sum_p sigma_p^2 / (2 n^2). Two estimators agree on a block when
 * the difference of their means is within z_crit standard deviations.
 */
#ifndef PK_TEST_BLOCK_STATS_H
#define PK_TEST_BLOCK_STATS_H

#include "test.h"

#include "paprsek.h"

#define BS_MAX_BLOCKS 8 /* per side */

typedef struct block_estimate {
    int nb;              /* blocks per side */
    double mean[BS_MAX_BLOCKS][BS_MAX_BLOCKS][3], var[BS_MAX_BLOCKS][BS_MAX_BLOCKS][3];
} block_estimate;

/* From two independent renders a, b (square, side a multiple of block). */
static inline void block_estimate_from(const pk_image *a, const pk_image *b, int block, block_estimate *e)
{
    const int size = pk_image_width(a);
    REQUIRE(pk_image_height(a) == size && pk_image_width(b) == size && size % block == 0 &&
            size / block <= BS_MAX_BLOCKS);
    const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b);
    const double n = (double)block * (double)block;
    memset(e, 0, sizeof *e);
    e->nb = size / block;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++)
            for (int c = 0; c < 3; c++) {
                size_t i = 3 * ((size_t)y * (size_t)size + (size_t)x) + (size_t)c;
                double va = (double)pa[i], vb = (double)pb[i];
                e->mean[y / block][x / block][c] += 0.5 * (va + vb) / n;
                e->var[y / block][x / block][c] += (va - vb) * (va - vb) / 2.0 / (2.0 * n * n);
            }
}

/* Checks every block and channel of p against q; prints the largest |z|. */
static inline void block_compare(const char *scene, const char *what, const block_estimate *p,
                                 const block_estimate *q, double z_crit)
{
    double worst = 0.0;
    int bad = 0;
    for (int by = 0; by < p->nb; by++)
        for (int bx = 0; bx < p->nb; bx++)
            for (int c = 0; c < 3; c++) {
                double d = p->mean[by][bx][c] - q->mean[by][bx][c];
                double sd = sqrt(p->var[by][bx][c] + q->var[by][bx][c]);
                /* a block without noise (it sees only a constant background) must agree
                 * to the rounding of float sums of different numbers of samples */
                const double tiny = 1e-5 * fmax(fabs(p->mean[by][bx][c]), fabs(q->mean[by][bx][c]));
                double z = sd > 0.0 ? fabs(d) / sd : (fabs(d) <= tiny ? 0.0 : (double)INFINITY);
                if (z > worst) worst = z;
                if (z > z_crit) {
                    bad++;
                    fprintf(stderr, "%s: %s: block (%d, %d) channel %d: %.5f vs %.5f, z = %.2f\n", scene, what, bx, by,
                            c, p->mean[by][bx][c], q->mean[by][bx][c], z);
                }
            }
    printf("%s: %s: largest |z| over %d block means %.2f (bound %.2f)\n", scene, what, p->nb * p->nb * 3, worst,
           z_crit);
    CHECKF(bad == 0, "%s: %s: %d block means outside their confidence intervals", scene, what, bad);
}

#endif

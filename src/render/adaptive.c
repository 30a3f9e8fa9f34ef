/*
 * adaptive.c - adaptive sampling (pk_renderer_render_adaptive): passes over
 * the 16 x 16 tiles whose estimated noise is above a target. Even passes go
 * into the caller's film, odd ones into a second film of the same size; a
 * tile's noise comes from the difference of the two halves' means (the way
 * Cycles and others estimate it), and the halves are merged at the end.
 * The halves are independent: the odd passes take the sample numbers of
 * the sampler's second sequence (SAMPLER_SECOND_HALF), a scrambling of its
 * own. Within one scrambled sequence the halves' difference would overstate
 * the error of their mean (measured: 1.24 x and 1.33 x on the Cornell box at 32 and 64 spp),
 * because the sequence's points fill each other's gaps; between
 * independent halves (a - b)^2 / 4 is an unbiased estimate of its variance.
 * Every decision reads only the films, so the result does not depend on the
 * threads.
 */
#include "render.h"
#include "sampler.h"

#include <math.h>
#include <string.h>

#define ATILE 16 /* the renderer's tiles (renderer.c): a region of whole tiles renders them as they are */

void pk_adaptive_init(pk_adaptive *a)
{
    if (!a) return;
    a->noise = 0.05f;
    a->min_spp = 16;
    a->max_spp = 1024;
    a->seconds = 0.0;
}

/* The relative variance of the mean, summed over the pixels and channels of
 * the w x h block at (x, y) (even: the caller's film, odd: the other half). */
static double block_relvar(const pk_film *even, const pk_film *odd, int x, int y, int w, int h)
{
    double sum = 0.0;
    for (int j = y; j < y + h; j++)
        for (int i = x; i < x + w; i++) {
            const size_t p = (size_t)j * (size_t)even->width + (size_t)i;
            const uint32_t ca = even->counts[p], cb = odd->counts[p];
            if (!ca || !cb) continue;
            for (int c = 0; c < 3; c++) {
                const double a = (double)even->sums[3 * p + (size_t)c] / ca;
                const double b = (double)odd->sums[3 * p + (size_t)c] / cb;
                const double m = ((double)even->sums[3 * p + (size_t)c] + (double)odd->sums[3 * p + (size_t)c]) /
                                 (double)(ca + cb);
                const double d = 0.5 * (a - b);
                const double v = d * d / (m * m + 0.01);
                if (isfinite(v)) sum += v;
            }
        }
    return sum;
}

/* The samples of the tile at (x, y): both halves of its first pixel (a
 * tile's pixels are rendered together, so all have as many). */
static uint32_t tile_spp(const pk_film *even, const pk_film *odd, int x, int y)
{
    const size_t p = (size_t)y * (size_t)even->width + (size_t)x;
    return even->counts[p] + odd->counts[p];
}

pk_status pk_renderer_render_adaptive(pk_renderer *r, const pk_adaptive *a, pk_film *film, pk_adaptive_result *result)
{
    if (!r || !a || !film) return PK_ERR_INVALID_ARGUMENT;
    pk_context *ctx = renderer_context(r);
    const pk_render_options *opt = renderer_options(r);
    if (!(a->noise > 0.0f) || !isfinite(a->noise))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "adaptive sampling: the noise target must be a positive number");
    if (a->min_spp < 1 || a->max_spp < a->min_spp || !(a->seconds >= 0.0))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "adaptive sampling: need 1 <= min_spp <= max_spp (%d, %d) and seconds >= 0", a->min_spp,
                         a->max_spp);
    if (film->width != opt->width || film->height != opt->height)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "the film is %dx%d but the renderer makes %dx%d images",
                         film->width, film->height, opt->width, opt->height);
    const int w = opt->width, h = opt->height;
    for (size_t p = 0; p < (size_t)w * (size_t)h; p++)
        if (film->counts[p])
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "adaptive sampling needs an empty film");
    const int tx = (w + ATILE - 1) / ATILE, ty = (h + ATILE - 1) / ATILE;
    const size_t ntiles = (size_t)tx * (size_t)ty;
    pk_film *odd = NULL;
    uint8_t *active = mem_calloc(&ctx->alloc, ntiles, 1);
    uint8_t *below = mem_calloc(&ctx->alloc, ntiles, 1); /* the last check found the tile at the target */
    pk_region *reg = mem_realloc_array(&ctx->alloc, NULL, ntiles, sizeof *reg);
    pk_status st = active && below && reg ? film_create(ctx, w, h, film->aovs, &odd) : ctx_nomem(ctx);
    const uint32_t pass0 = renderer_pass(r);
    uint32_t pass = pass0; /* passes rendered: (pass - pass0 + 1) / 2 even ones, (pass - pass0) / 2 odd ones */
    const uint32_t step = (uint32_t)opt->spp;
    /* the odd half's first pass number: its sample numbers start at the second sequence */
    const uint32_t odd0 = (SAMPLER_SECOND_HALF + step - 1) / step;
    if ((uint64_t)pass0 * step >= SAMPLER_SECOND_HALF)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "adaptive sampling: the pass number %u is too large", pass0);
    size_t reached = 0;
    if (st == PK_OK) memset(active, 1, ntiles);
    const double t0 = time_now();
    while (st == PK_OK) {
        /* the active tiles, as runs along each row of tiles */
        size_t n = 0;
        for (int j = 0; j < ty; j++)
            for (int i = 0; i < tx; i++) {
                if (!active[(size_t)j * (size_t)tx + (size_t)i]) continue;
                const int x = i * ATILE, y = j * ATILE, th = y + ATILE < h ? ATILE : h - y;
                int x1 = x;
                while (i < tx && active[(size_t)j * (size_t)tx + (size_t)i]) x1 = ++i * ATILE;
                reg[n++] = (pk_region){x, y, (x1 < w ? x1 : w) - x, th};
            }
        if (!n) break;
        const uint32_t done = pass - pass0;
        renderer_set_pass(r, done % 2 ? odd0 + pass0 + done / 2 : pass0 + done / 2);
        st = renderer_render(r, reg, n, done % 2 ? odd : film);
        if (st != PK_OK) break;
        pass++;
        if ((pass - pass0) % 2 == 0) { /* both halves have the same samples: judge the tiles */
            for (int j = 0; j < ty; j++)
                for (int i = 0; i < tx; i++) {
                    const size_t k = (size_t)j * (size_t)tx + (size_t)i;
                    const int x = i * ATILE, y = j * ATILE;
                    if (!active[k] || tile_spp(film, odd, x, y) < (uint32_t)a->min_spp) continue;
                    const int bw = x + ATILE < w ? ATILE : w - x, bh = y + ATILE < h ? ATILE : h - y;
                    const double rv = block_relvar(film, odd, x, y, bw, bh) / (3.0 * bw * bh);
                    /* below the target at two checks in a row: one lucky estimate (a tile whose
                     * fireflies fell on neither half yet) does not stop it */
                    if (!(sqrt(rv) <= (double)a->noise)) {
                        below[k] = 0;
                    } else if (below[k]++) {
                        active[k] = 0;
                        reached++;
                    }
                }
        }
        /* a tile at max_spp stops; so does the render once the time is up (after a whole pass) */
        for (int j = 0; j < ty; j++)
            for (int i = 0; i < tx; i++) {
                const size_t k = (size_t)j * (size_t)tx + (size_t)i;
                if (active[k] && tile_spp(film, odd, i * ATILE, j * ATILE) + step > (uint32_t)a->max_spp) active[k] = 0;
            }
        if (a->seconds > 0.0 && time_now() - t0 >= a->seconds) break;
        if ((uint64_t)(pass0 + (pass - pass0) / 2 + 1) * step >= SAMPLER_SECOND_HALF) break; /* (2^31 samples) */
    }
    if (odd && (st == PK_OK || st == PK_ERR_CANCELLED)) {
        if (result) {
            memset(result, 0, sizeof *result);
            result->passes = pass - pass0;
            result->tiles = ntiles;
            result->tiles_reached = reached;
            result->noise = (float)sqrt(block_relvar(film, odd, 0, 0, w, h) / (3.0 * (double)w * (double)h));
            result->min_spp = UINT32_MAX;
            for (size_t p = 0; p < (size_t)w * (size_t)h; p++) {
                const uint32_t c = film->counts[p] + odd->counts[p];
                result->samples += c;
                if (c < result->min_spp) result->min_spp = c;
                if (c > result->max_spp) result->max_spp = c;
            }
        }
        film_merge(film, odd);
    }
    renderer_set_pass(r, pass0 + (pass - pass0 + 1) / 2); /* after the even half's last pass */
    film_destroy(odd);
    mem_free(&ctx->alloc, active);
    mem_free(&ctx->alloc, below);
    mem_free(&ctx->alloc, reg);
    return st;
}

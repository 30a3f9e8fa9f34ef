/*
 * image.h - pixel storage behind pk_image (linear RGB floats) and pk_film
 * (per-pixel sums of samples and their counts: merged, then resolved into an
 * image). Depends only on the context.
 */
#ifndef PK_IMAGE_STORAGE_H
#define PK_IMAGE_STORAGE_H

#include "../paprsek_internal.h"

/* Linear RGB image. Invariant: pixels holds 3*width*height floats, rows top first. */
struct pk_image {
    pk_allocator alloc;
    int width, height;
    float *pixels;
};

/* Invariants: sums holds 3*width*height floats and counts width*height
 * sample counts, rows top first; a pixel with count 0 has zero sums. */
#define FILM_AOVS 5 /* albedo, normal, depth, heatmap, alpha: bit k of the mask is aov[k] */

struct pk_film {
    pk_allocator alloc;
    int width, height;
    float *sums;
    uint32_t *counts;
    unsigned aovs;              /* PK_AOV_* held in aov[] (bits below FILM_AOVS) */
    bool samples;               /* PK_AOV_SAMPLES asked for (read from counts) */
    float *aov[FILM_AOVS];      /* 3 floats per pixel each (sums), NULL when not held */
};

/* Checks the size against PK_MAX_IMAGE_SIDE and PK_MAX_IMAGE_PIXELS;
 * latches "what WxH is out of range (...)". */
PK_HIDDEN pk_status image_check_size(pk_context *ctx, const char *what, int width, int height);
/* Zeroed storage of the given size (checked). */
PK_HIDDEN pk_status image_create(pk_context *ctx, int width, int height, pk_image **out);
PK_HIDDEN void image_destroy(pk_image *img);
PK_HIDDEN pk_status film_create(pk_context *ctx, int width, int height, unsigned aovs, pk_film **out);
PK_HIDDEN void film_destroy(pk_film *film);
PK_HIDDEN void film_clear(pk_film *film);
/* dst += src (same size, checked by the caller). */
PK_HIDDEN void film_merge(pk_film *dst, const pk_film *src);
/* Adds a block of w x h pixels at (x, y): rgb holds 3 floats per pixel, row
 * after row, each the sum of spp samples. */
PK_HIDDEN void film_add_block(pk_film *film, int x, int y, int w, int h, const float *rgb, uint32_t spp);
/* Adds AOV k's block (3 floats per pixel, sums over the same samples). */
PK_HIDDEN void film_add_aov_block(pk_film *film, int k, int x, int y, int w, int h, const float *v);
/* img = AOV k's sums / counts. */
PK_HIDDEN void film_resolve_aov_into(const pk_film *film, int k, pk_image *img);
/* img (same size) = sums / counts, 0 where there is no sample or the mean is not finite. */
PK_HIDDEN void film_resolve_into(const pk_film *film, pk_image *img);

#endif

/*
 * denoise.h - the denoiser's parts below pk_denoise (include/paprsek.h),
 * for the tests: tiling, automatic exposure and a run on raw pixel arrays.
 */
#ifndef PK_DENOISE_H
#define PK_DENOISE_H

#include "paprsek_internal.h"

/* One axis of the image cut into tiles of at most t pixels that overlap by
 * ov: tile k reads pixels [start, start + size) and writes [out0, out1). */
typedef struct tile_span {
    int start, size, out0, out1;
} tile_span;

/* The tiles of an axis of n pixels into out (at most max of them); returns
 * how many there are (out may be NULL with max 0 to count them). */
PK_HIDDEN int denoise_tiles(int n, int t, int ov, tile_span *out, int max);
/* The input scale that Open Image Denoise's automatic exposure gives the
 * RGB image rgb (w x h). */
PK_HIDDEN double denoise_autoexposure(const float *rgb, int w, int h);
/* pk_denoiser_run on arrays of 3 floats per pixel (albedo, normal may be NULL). */
PK_HIDDEN pk_status denoise_raw(pk_denoiser *d, int w, int h, const float *color, const float *albedo,
                                const float *normal, float *out);

#endif

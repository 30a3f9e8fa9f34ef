/*
 * image_write.h - image writers (PNG 8-bit sRGB, PFM linear float, OpenEXR linear
 * float). Every writer writes to a temporary file in the target's folder and
 * renames it into place.
 */
#ifndef PK_IMAGE_WRITE_H
#define PK_IMAGE_WRITE_H

#include "image.h"

/* Writes img by the extension of path (.png, .pfm, .exr) with the default
 * options. */
PK_HIDDEN pk_status image_write(pk_context *ctx, const pk_image *img, const char *path);
/* The same with options (wo NULL: the defaults; see pk_write_options). */
PK_HIDDEN pk_status image_write_ex(pk_context *ctx, const pk_image *img, const char *path,
                                   const pk_write_options *wo);
/* The tone curve PK_TONEMAP_* on one linear colour (after the exposure):
 * out (may be in) is linear display RGB in [0, 1], to be sRGB-encoded.
 * Negative and NaN components count as 0. */
PK_HIDDEN void image_tonemap(int tonemap, const float in[3], float out[3]);
/* Linear [0,1] to 8-bit sRGB, clamped: the PNG tone curve after exposure. */
PK_HIDDEN unsigned char srgb_encode(float linear);

/* ---- OpenEXR (exr.c) ---- */

/* The compression of .exr files: ZIP (zlib over 16-scanline blocks), lossless.
 * (Measured on a 512x512 render in docs/design.md, against PIZ.) */
#ifndef PK_EXR_COMPRESSION /* (-D for measurements) */
#define PK_EXR_COMPRESSION EXR_COMPRESSION_ZIP
#endif
/* At most this many channels in one file. */
#define PK_EXR_MAX_CHANNELS 64

/* One float channel of a width x height image: the sample of pixel (x, y),
 * rows top to bottom, is data[y * row_stride + x * pixel_stride]. name is
 * the channel's name in the file: "R", "G", "B" for the image; a layer's
 * channels are "layer.C" ("albedo.R", "normal.X", "depth.Z"). */
typedef struct exr_channel {
    const char *name;
    const float *data;
    size_t pixel_stride, row_stride; /* in floats */
} exr_channel;

/* Writes the n channels (names distinct, 1 <= n <= PK_EXR_MAX_CHANNELS) as
 * 32-bit floats into a single-part scanline OpenEXR file through fd (an
 * empty file open for writing; written with pwrite, not closed). Returns 0,
 * or -1 with why filled ("OpenEXR: ...", "write error: ..."). Prints nothing. */
PK_HIDDEN int exr_write_channels(int fd, int width, int height, const exr_channel *ch, int n, char *why,
                                 size_t nwhy);

#endif

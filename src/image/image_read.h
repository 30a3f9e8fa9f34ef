/*
 * image_read.h - image readers for textures and environment maps: PNG
 * (libpng), JPEG (libjpeg-turbo: baseline, progressive, greyscale), OpenEXR
 * (OpenEXRCore), Radiance .hdr (RLE and flat), PFM and WebP (libwebp, loaded
 * at run time). Every reader decodes
 * a (data, size) buffer, so that files are read only through file_read_all
 * and the fuzzers reach the decoders directly. The format is told by the
 * first bytes, not by the file name.
 *
 * Sizes are bounded before anything is allocated: each side at most
 * PK_MAX_TEXTURE_SIDE, at most PK_MAX_TEXTURE_PIXELS pixels
 * (include/paprsek.h), so that a small compressed file cannot ask for
 * gigabytes (a decompression bomb).
 */
#ifndef PK_IMAGE_READ_H
#define PK_IMAGE_READ_H

#include "../paprsek_internal.h"

/* A decoded image, rows top to bottom, samples interleaved. nc is 1 (grey),
 * 2 (grey, alpha), 3 (RGB) or 4 (RGBA). Exactly one of px8 and pxf is set:
 * px8 for the 8-bit formats (PNG, JPEG, WebP), the bytes as stored in the file
 * (sRGB-encoded for colour); pxf for the HDR formats (OpenEXR, .hdr, PFM),
 * linear floats, every sample finite and within +-IMAGE_MAX_SAMPLE (larger
 * ones are clamped, non-finite ones read as 0). */
#define IMAGE_MAX_SAMPLE 1e30f
typedef struct image_buf {
    int w, h, nc;
    uint8_t *px8;
    float *pxf;
} image_buf;

typedef enum image_format {
    IMAGE_UNKNOWN, IMAGE_PNG, IMAGE_JPEG, IMAGE_EXR, IMAGE_HDR, IMAGE_PFM, IMAGE_WEBP
} image_format;

/* The format the first bytes of data announce (IMAGE_UNKNOWN when none). */
PK_HIDDEN image_format image_sniff(const void *data, size_t size);

/* Decodes data (any format above) into *out (owned by the caller: image_buf_free).
 * name is for messages. Errors are latched in ctx as "name: what is wrong":
 * PK_ERR_PARSE for a corrupt or truncated image, PK_ERR_UNSUPPORTED for a
 * variant that is not read (CMYK JPEG, deep OpenEXR), PK_ERR_LIMIT past the
 * bounds, PK_ERR_NOMEM. */
PK_HIDDEN pk_status image_decode(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
/* The decoders one by one (image_decode calls the one the bytes announce). */
PK_HIDDEN pk_status image_decode_png(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
PK_HIDDEN pk_status image_decode_jpeg(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
PK_HIDDEN pk_status image_decode_exr(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
/* The channels LAYER.R, LAYER.G, LAYER.B (and .A, or .Y alone) of an
 * OpenEXR image (layer NULL: the channels without a layer prefix). */
PK_HIDDEN pk_status image_decode_exr_layer(pk_context *ctx, const void *data, size_t size, const char *name,
                                           const char *layer, image_buf *out);
PK_HIDDEN pk_status image_decode_hdr(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
PK_HIDDEN pk_status image_decode_pfm(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
/* WebP (lossy or lossless, alpha; not animated) through libwebp, loaded at
 * run time: PK_ERR_UNSUPPORTED naming the package where it is missing. */
PK_HIDDEN pk_status image_decode_webp(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out);
/* Whether WebP images are read here (libwebp built for and loadable). */
PK_HIDDEN bool image_have_webp(void);
PK_HIDDEN void image_buf_free(const pk_allocator *a, image_buf *img);

/* Reads the file at path (through file_read_all) and decodes it. */
PK_HIDDEN pk_status image_read_file(pk_context *ctx, const char *path, image_buf *out);

/* Loads any supported image file as linear RGB floats: *rgb (allocated with
 * the context's allocator, mem_free) holds 3 floats per pixel, *w * *h
 * pixels, row 0 at the top. 8-bit images are decoded from sRGB; grey is
 * copied to the three channels; alpha is dropped. */
PK_HIDDEN pk_status image_load_rgb(pk_context *ctx, const char *path, int *w, int *h, float **rgb);

/* 8-bit sRGB to linear: the exact IEC 61966-2-1 curve, tabulated. */
PK_HIDDEN extern const float image_srgb_to_linear[256];

#endif

/*
 * image.h - image writers (PNG 8-bit sRGB, PFM linear float). Every writer
 * writes to a temporary file in the target's folder and renames it into place.
 */
#ifndef PK_IMAGE_H
#define PK_IMAGE_H

#include "../image/image.h"

/* Writes img by the extension of path (.png, .pfm). */
PK_HIDDEN pk_status image_write(pk_context *ctx, const pk_image *img, const char *path);
/* Linear [0,1] to 8-bit sRGB, clamped. */
PK_HIDDEN unsigned char srgb_encode(float linear);

#endif

/*
 * image_write.c - PNG (8-bit sRGB through libpng, after exposure), PFM
 * (linear float RGB) and OpenEXR (linear float RGB, exr.c) writers. Each
 * writes to a temporary file beside the target and renames it into place,
 * so an existing image is only ever replaced by a complete one.
 */
#include "image_write.h"

#include <errno.h>
#include <math.h>
#include <sys/stat.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

unsigned char srgb_encode(float x)
{
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    float s = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
    int v = (int)(s * 255.0f + 0.5f);
    return (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : v);
}

static bool ends_with(const char *s, const char *ext)
{
    size_t ls = strlen(s), le = strlen(ext);
    if (ls < le) return false;
    for (size_t i = 0; i < le; i++) {
        char c = s[ls - le + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != ext[i]) return false;
    }
    return true;
}

typedef struct png_err {
    char msg[200];
} png_err;

static void png_error_fn(png_structp png, png_const_charp msg)
{
    png_err *e = png_get_error_ptr(png);
    snprintf(e->msg, sizeof e->msg, "%s", msg);
    png_longjmp(png, 1);
}

static void png_warn_fn(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

/* Returns 0 on success, or -1 with why filled. The row buffer is allocated
 * before setjmp so that a longjmp cannot leak it. */
static int write_png(FILE *f, const pk_image *img, float scale, unsigned char *row, char *why, size_t nwhy)
{
    png_err err = {{0}};
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_error_fn, png_warn_fn);
    if (!png) {
        snprintf(why, nwhy, "cannot start PNG encoder");
        return -1;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        snprintf(why, nwhy, "cannot start PNG encoder");
        return -1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        snprintf(why, nwhy, "PNG encoder: %s", err.msg);
        return -1;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < img->height; y++) {
        const float *src = img->pixels + (size_t)y * (size_t)img->width * 3;
        for (int i = 0; i < img->width * 3; i++) row[i] = srgb_encode(src[i] * scale);
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return 0;
}

static int write_pfm(FILE *f, const pk_image *img, char *why, size_t nwhy)
{
    /* PFM: rows bottom to top; a negative scale means little-endian floats */
    if (fprintf(f, "PF\n%d %d\n-1.0\n", img->width, img->height) < 0) goto fail;
    for (int y = img->height - 1; y >= 0; y--) {
        const float *src = img->pixels + (size_t)y * (size_t)img->width * 3;
        if (fwrite(src, sizeof(float) * 3, (size_t)img->width, f) != (size_t)img->width) goto fail;
    }
    return 0;
fail:
    snprintf(why, nwhy, "write error: %s", strerror(errno));
    return -1;
}

#define EXR_MAX_LAYERS ((PK_EXR_MAX_CHANNELS - 3) / 3)

/* The image's R, G, B as three channels of one OpenEXR part, and each layer's
 * as "NAME.R", "NAME.G", "NAME.B" (checked by the caller). */
static int write_exr(FILE *f, const pk_image *img, const pk_write_options *wo, char *why, size_t nwhy)
{
    const size_t row = (size_t)img->width * 3;
    exr_channel ch[PK_EXR_MAX_CHANNELS];
    char names[EXR_MAX_LAYERS][3][72];
    int n = 0;
    ch[n++] = (exr_channel){"R", img->pixels + 0, 3, row};
    ch[n++] = (exr_channel){"G", img->pixels + 1, 3, row};
    ch[n++] = (exr_channel){"B", img->pixels + 2, 3, row};
    for (size_t l = 0; l < wo->nlayers; l++)
        for (int c = 0; c < 3; c++) {
            snprintf(names[l][c], sizeof names[l][c], "%s.%c", wo->layer_names[l], "RGB"[c]);
            ch[n++] = (exr_channel){names[l][c], wo->layers[l]->pixels + c, 3, row};
        }
    return exr_write_channels(fileno(f), img->width, img->height, ch, n, why, nwhy);
}

void pk_write_options_init(pk_write_options *wo)
{
    if (!wo) return;
    memset(wo, 0, sizeof *wo);
    wo->exposure_ev = 0.0f;
}

pk_status pk_image_write_ex(pk_context *ctx, const pk_image *img, const char *path, const pk_write_options *wo)
{
    if (!ctx || !img || !path) return PK_ERR_INVALID_ARGUMENT;
    return image_write_ex(ctx, img, path, wo);
}

pk_status image_write(pk_context *ctx, const pk_image *img, const char *path)
{
    return image_write_ex(ctx, img, path, NULL);
}

pk_status image_write_ex(pk_context *ctx, const pk_image *img, const char *path, const pk_write_options *wo)
{
    pk_write_options defaults;
    if (!wo) {
        pk_write_options_init(&defaults);
        wo = &defaults;
    }
    if (!(wo->exposure_ev >= -(float)PK_MAX_EXPOSURE_EV && wo->exposure_ev <= (float)PK_MAX_EXPOSURE_EV))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: exposure %g EV is not a number in %d..%d", path,
                         (double)wo->exposure_ev, -PK_MAX_EXPOSURE_EV, PK_MAX_EXPOSURE_EV);
    /* exact for whole EVs (a power of two); 1 at the default, so that PNG
     * output without exposure is what it was before the option existed */
    const float scale = exp2f(wo->exposure_ev);
    bool png = ends_with(path, ".png"), pfm = ends_with(path, ".pfm"), exr = ends_with(path, ".exr");
    if (!png && !pfm && !exr)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: unknown image format (use .png, .pfm or .exr)", path);
    if (wo->nlayers) {
        if (!exr) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: layers are written to .exr files only", path);
        if (wo->nlayers > EXR_MAX_LAYERS || !wo->layers || !wo->layer_names)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: at most %d layers, each with an image and a name", path,
                             (int)EXR_MAX_LAYERS);
        for (size_t l = 0; l < wo->nlayers; l++) {
            const pk_image *li = wo->layers[l];
            const char *nm = wo->layer_names[l];
            if (!li || li->width != img->width || li->height != img->height)
                return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: layer %zu is not a %dx%d image", path, l,
                                 img->width, img->height);
            if (!nm || !nm[0] || strlen(nm) > 64 || strchr(nm, '.'))
                return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: layer %zu needs a name of 1..64 characters without '.'",
                                 path, l);
            for (size_t m = 0; m < l; m++)
                if (strcmp(nm, wo->layer_names[m]) == 0)
                    return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: two layers named '%s'", path, nm);
        }
    }
    size_t lp = strlen(path);
    char *tmp = mem_alloc(&ctx->alloc, lp + 16);
    unsigned char *row = png ? mem_alloc(&ctx->alloc, (size_t)img->width * 3) : NULL;
    if (!tmp || (png && !row)) {
        mem_free(&ctx->alloc, tmp);
        mem_free(&ctx->alloc, row);
        return ctx_nomem(ctx);
    }
    memcpy(tmp, path, lp);
    memcpy(tmp + lp, ".tmp.XXXXXX", 12);
    pk_status st = PK_OK;
    char why[256] = "";
    int fd = mkstemp(tmp);
    if (fd < 0) {
        st = ctx_error(ctx, PK_ERR_IO, "%s: cannot create a temporary file beside it: %s", path, strerror(errno));
        goto out;
    }
    (void)fchmod(fd, 0644);
    FILE *f = fdopen(fd, "wb");
    if (!f) {
        close(fd);
        unlink(tmp);
        st = ctx_error(ctx, PK_ERR_IO, "%s: %s", path, strerror(errno));
        goto out;
    }
    int rc = png   ? write_png(f, img, scale, row, why, sizeof why)
             : exr ? write_exr(f, img, wo, why, sizeof why)
                   : write_pfm(f, img, why, sizeof why);
    if (rc == 0 && fflush(f) != 0) {
        rc = -1;
        snprintf(why, sizeof why, "write error: %s", strerror(errno));
    }
    if (rc == 0 && fsync(fileno(f)) != 0 && errno != EINVAL) {
        rc = -1;
        snprintf(why, sizeof why, "write error: %s", strerror(errno));
    }
    if (fclose(f) != 0 && rc == 0) {
        rc = -1;
        snprintf(why, sizeof why, "write error: %s", strerror(errno));
    }
    if (rc == 0 && rename(tmp, path) != 0) {
        rc = -1;
        snprintf(why, sizeof why, "cannot rename into place: %s", strerror(errno));
    }
    if (rc != 0) {
        unlink(tmp);
        st = ctx_error(ctx, PK_ERR_IO, "%s: %s", path, why);
    }
out:
    mem_free(&ctx->alloc, tmp);
    mem_free(&ctx->alloc, row);
    return st;
}

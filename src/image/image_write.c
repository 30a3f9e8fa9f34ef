/*
 * image_write.c - PNG (8-bit sRGB through libpng, after exposure and a tone
 * curve; RGBA with a coverage image), PFM (linear float RGB) and OpenEXR
 * (linear float RGB, A with a coverage image; exr.c) writers. Each
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

/* ---- tone curves (pk_write_options.tonemap) ---------------------------------- */

static const char *const tonemap_names[PK_TONEMAP_COUNT] = {"clamp", "agx", "pbr-neutral", "aces"};

int pk_tonemap_parse(const char *name)
{
    if (!name) return -1;
    for (int k = 0; k < PK_TONEMAP_COUNT; k++)
        if (strcmp(name, tonemap_names[k]) == 0) return k;
    return -1;
}

const char *pk_tonemap_name(int tonemap)
{
    return tonemap >= 0 && tonemap < PK_TONEMAP_COUNT ? tonemap_names[tonemap] : "unknown";
}

static void mat3_apply(const double m[3][3], const double in[3], double out[3])
{
    for (int i = 0; i < 3; i++) out[i] = m[i][0] * in[0] + m[i][1] * in[1] + m[i][2] * in[2];
}

/* Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral): an offset
 * that removes the 0.04 of a dielectric's Fresnel reflection (blended to 0
 * in the darks), then highlights above 0.76 compressed toward a peak of 1
 * and desaturated by how much they were compressed. */
static void tonemap_pbr_neutral(double c[3])
{
    const double start = 0.8 - 0.04, desat = 0.15;
    const double x = fmin(c[0], fmin(c[1], c[2]));
    const double offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    for (int i = 0; i < 3; i++) c[i] -= offset;
    const double peak = fmax(c[0], fmax(c[1], c[2]));
    if (peak < start) return;
    const double d = 1.0 - start;
    const double new_peak = 1.0 - d * d / (peak + d - start);
    const double g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0);
    for (int i = 0; i < 3; i++) c[i] = (1.0 - g) * c[i] * (new_peak / peak) + g * new_peak;
}

/* Blender's AgX, its base look (Eary Chow's definition, which generates
 * Blender's AgX LUT), without the LUT's guard rails for negative and
 * out-of-gamut values (negatives are clipped first). Linear Rec.709 in and
 * out; the matrices are Rec.709 -> Rec.2020 (ITU-R BT.2087) times AgX's
 * inset, and AgX's outset times Rec.2020 -> Rec.709. */
static const double agx_inset[3][3] = {{0.544908136763631, 0.373779459598123, 0.081384976686408},
                                       {0.140440058840013, 0.754109598640138, 0.105433585368578},
                                       {0.088827411851915, 0.178877124650438, 0.732249999569484}};
static const double agx_outset[3][3] = {{1.964550960273333, -0.855858451178075, -0.108867108268316},
                                        {-0.299322433909111, 1.326451074150236, -0.027084020983875},
                                        {-0.164368338060804, -0.238224640688606, 1.402665347143272}};
#define AGX_LOG2_MIN (-10.0) /* stops below middle grey (0.18) */
#define AGX_LOG2_MAX 6.5     /* stops above */
#define AGX_SLOPE 2.4        /* at the pivot, in the encoded output */
#define AGX_POWER 1.5        /* of the toe and the shoulder */

/* AgX's sigmoid on the normalised log2 value x in [0, 1]: through the pivot
 * (middle grey: x_p = 10 / 16.5, y_p = 0.18^(1/2.4)) with slope 2.4, and
 * y = y_p + s (x - x_p) / (1 + |s (x - x_p) / k|^p)^(1/p) on either side,
 * k chosen so that the curve meets (0, 0) and (1, 1). Returns the encoded
 * value (linear = y^2.4). */
static double agx_sigmoid(double x)
{
    const double xp = -AGX_LOG2_MIN / (AGX_LOG2_MAX - AGX_LOG2_MIN), yp = pow(0.18, 1.0 / 2.4);
    const double s = AGX_SLOPE, p = AGX_POWER;
    double a;
    if (x < xp) /* (s x_p / k)^p = (s x_p / y_p)^p - 1 */
        a = (pow(s / yp, p) - pow(xp, -p)) * pow(xp - x, p);
    else /* (s (1 - x_p) / k)^p = (s (1 - x_p) / (1 - y_p))^p - 1 */
        a = (pow(s * (1.0 - xp) / (1.0 - yp), p) - 1.0) * pow((x - xp) / (1.0 - xp), p);
    return yp + s * (x - xp) / pow(1.0 + a, 1.0 / p);
}

static void tonemap_agx(double c[3])
{
    double in[3], e[3];
    for (int i = 0; i < 3; i++) in[i] = c[i] > 1e-10 ? c[i] : 1e-10;
    mat3_apply(agx_inset, in, e);
    for (int i = 0; i < 3; i++) {
        double x = (log2(fmax(e[i], 1e-10) / 0.18) - AGX_LOG2_MIN) / (AGX_LOG2_MAX - AGX_LOG2_MIN);
        x = x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
        e[i] = pow(agx_sigmoid(x), 2.4);
    }
    mat3_apply(agx_outset, e, c);
}

/* ACES: Stephen Hill's fit of the RRT and the sRGB ODT (the BakingLab
 * fit): sRGB -> the RRT's working space with its saturation, a rational
 * curve fitted to RRT + ODT, then back to sRGB with the ODT's saturation.
 * Chosen over Narkowicz's curve (the same shape per channel, no matrices)
 * because bright saturated colours go toward white as ACES makes them,
 * instead of staying saturated. */
static const double aces_in[3][3] = {{0.59719, 0.35458, 0.04823}, {0.07600, 0.90834, 0.01566}, {0.02840, 0.13383, 0.83777}};
static const double aces_out[3][3] = {
    {1.60475, -0.53108, -0.07367}, {-0.10208, 1.10813, -0.00605}, {-0.00327, -0.07276, 1.07602}};

static void tonemap_aces(double c[3])
{
    double v[3];
    mat3_apply(aces_in, c, v);
    for (int i = 0; i < 3; i++) {
        const double x = v[i];
        v[i] = (x * (x + 0.0245786) - 0.000090537) / (x * (0.983729 * x + 0.4329510) + 0.238081);
    }
    mat3_apply(aces_out, v, c);
}

void image_tonemap(int tonemap, const float in[3], float out[3])
{
    double c[3];
    for (int i = 0; i < 3; i++) c[i] = in[i] > 0.0f ? (double)in[i] : 0.0; /* NaN and negatives: 0 */
    /* (large values are finite for every curve: keep infinity out of log2) */
    for (int i = 0; i < 3; i++)
        if (c[i] > 1e30) c[i] = 1e30;
    switch (tonemap) {
    case PK_TONEMAP_AGX: tonemap_agx(c); break;
    case PK_TONEMAP_PBR_NEUTRAL: tonemap_pbr_neutral(c); break;
    case PK_TONEMAP_ACES: tonemap_aces(c); break;
    default: break;
    }
    for (int i = 0; i < 3; i++) out[i] = (float)(c[i] > 0.0 ? (c[i] < 1.0 ? c[i] : 1.0) : 0.0);
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
/* One row of 8-bit values: RGB, or RGBA when alpha (the coverage image) is
 * given; the colour is then un-premultiplied first. */
static void png_row(const pk_image *img, int y, float scale, int tonemap, const pk_image *alpha, unsigned char *row)
{
    const float *src = img->pixels + (size_t)y * (size_t)img->width * 3;
    if (!alpha && tonemap == PK_TONEMAP_CLAMP) { /* the bytes written before tone curves and alpha existed */
        for (int i = 0; i < img->width * 3; i++) row[i] = srgb_encode(src[i] * scale);
        return;
    }
    const float *al = alpha ? alpha->pixels + (size_t)y * (size_t)img->width * 3 : NULL;
    const int nc = alpha ? 4 : 3;
    for (int x = 0; x < img->width; x++) {
        float c[3] = {src[3 * x] * scale, src[3 * x + 1] * scale, src[3 * x + 2] * scale};
        unsigned char *o = row + (size_t)x * (size_t)nc;
        if (al) {
            const float a = al[3 * x];
            const float ac = a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f; /* (NaN: 0) */
            for (int k = 0; k < 3; k++) c[k] = ac > 0.0f ? c[k] / ac : 0.0f;
            o[3] = (unsigned char)(int)(ac * 255.0f + 0.5f);
        }
        if (tonemap != PK_TONEMAP_CLAMP) image_tonemap(tonemap, c, c);
        for (int k = 0; k < 3; k++) o[k] = srgb_encode(c[k]);
    }
}

static int write_png(FILE *f, const pk_image *img, float scale, int tonemap, const pk_image *alpha,
                     unsigned char *row, char *why, size_t nwhy)
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
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, 8,
                 alpha ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < img->height; y++) {
        png_row(img, y, scale, tonemap, alpha, row);
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

#define EXR_MAX_LAYERS ((PK_EXR_MAX_CHANNELS - 4) / 3)

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
    if (wo->alpha) ch[n++] = (exr_channel){"A", wo->alpha->pixels, 3, row};
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
    if (wo->tonemap < 0 || wo->tonemap >= PK_TONEMAP_COUNT)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: unknown tone curve %d", path, wo->tonemap);
    if (wo->alpha) {
        if (pfm) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: PFM has no alpha channel (use .png or .exr)", path);
        if (wo->alpha->width != img->width || wo->alpha->height != img->height)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: the alpha is not a %dx%d image", path, img->width,
                             img->height);
    }
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
    unsigned char *row = png ? mem_alloc(&ctx->alloc, (size_t)img->width * 4) : NULL;
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
    int rc = png   ? write_png(f, img, scale, wo->tonemap, wo->alpha, row, why, sizeof why)
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

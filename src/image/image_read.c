/*
 * image_read.c - the image readers (see image_read.h): PNG through libpng's
 * simplified API, JPEG through libjpeg (errors caught with setjmp/longjmp,
 * messages kept instead of printed), OpenEXR through OpenEXRCore reading
 * from memory, Radiance .hdr and PFM parsed here, and WebP through libwebp
 * (loaded at run time, as Embree is, where the build found its header).
 */
#include "image_read.h"

#include "image.h"

#include <limits.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "srgb_table.h"

#include <jpeglib.h>
#include <openexr.h>
#include <png.h>

#include "device/dynlib.h"
#if PK_HAVE_WEBP
#include <webp/decode.h>
#endif

const float image_srgb_to_linear[256] = PK_SRGB_TO_LINEAR_INIT;

void image_buf_free(const pk_allocator *a, image_buf *img)
{
    mem_free(a, img->px8);
    mem_free(a, img->pxf);
    memset(img, 0, sizeof *img);
}

/* Checks a size against the bounds; latches PK_ERR_LIMIT or PK_ERR_PARSE. */
static pk_status check_size(pk_context *ctx, const char *name, int64_t w, int64_t h)
{
    if (w <= 0 || h <= 0) return ctx_error(ctx, PK_ERR_PARSE, "%s: image size %lldx%lld is empty", name, (long long)w, (long long)h);
    if (w > PK_MAX_TEXTURE_SIDE || h > PK_MAX_TEXTURE_SIDE || (uint64_t)w * (uint64_t)h > PK_MAX_TEXTURE_PIXELS)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: image size %lldx%lld is beyond the limits (%d pixels a side, %u pixels)",
                         name, (long long)w, (long long)h, PK_MAX_TEXTURE_SIDE, PK_MAX_TEXTURE_PIXELS);
    return PK_OK;
}

/* Allocates out's samples (8-bit or float) for w x h x nc. */
static pk_status alloc_buf(pk_context *ctx, image_buf *out, int w, int h, int nc, bool hdr)
{
    memset(out, 0, sizeof *out);
    size_t n = (size_t)w * (size_t)h * (size_t)nc; /* bounded by check_size */
    if (hdr) out->pxf = mem_realloc_array(&ctx->alloc, NULL, n, sizeof(float));
    else out->px8 = mem_alloc(&ctx->alloc, n);
    if (!out->pxf && !out->px8) return ctx_nomem(ctx);
    out->w = w;
    out->h = h;
    out->nc = nc;
    return PK_OK;
}

/* Non-finite samples (NaN, inf) become 0, and magnitudes are kept within
 * IMAGE_MAX_SAMPLE: lookups, which interpolate and average, must stay finite. */
static void sanitize_floats(float *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(p[i])) p[i] = 0.0f;
        else if (p[i] > IMAGE_MAX_SAMPLE) p[i] = IMAGE_MAX_SAMPLE;
        else if (p[i] < -IMAGE_MAX_SAMPLE) p[i] = -IMAGE_MAX_SAMPLE;
    }
}

image_format image_sniff(const void *data, size_t size)
{
    const unsigned char *b = data;
    if (size >= 8 && memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0) return IMAGE_PNG;
    if (size >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return IMAGE_JPEG;
    if (size >= 4 && b[0] == 0x76 && b[1] == 0x2F && b[2] == 0x31 && b[3] == 0x01) return IMAGE_EXR;
    if (size >= 2 && b[0] == '#' && b[1] == '?') return IMAGE_HDR;
    if (size >= 3 && b[0] == 'P' && (b[1] == 'F' || b[1] == 'f') && (b[2] == '\n' || b[2] == ' ' || b[2] == '\r' || b[2] == '\t'))
        return IMAGE_PFM;
    if (size >= 12 && memcmp(b, "RIFF", 4) == 0 && memcmp(b + 8, "WEBP", 4) == 0) return IMAGE_WEBP;
    return IMAGE_UNKNOWN;
}

pk_status image_decode(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    memset(out, 0, sizeof *out);
    switch (image_sniff(data, size)) {
    case IMAGE_PNG: return image_decode_png(ctx, data, size, name, out);
    case IMAGE_JPEG: return image_decode_jpeg(ctx, data, size, name, out);
    case IMAGE_EXR: return image_decode_exr(ctx, data, size, name, out);
    case IMAGE_HDR: return image_decode_hdr(ctx, data, size, name, out);
    case IMAGE_PFM: return image_decode_pfm(ctx, data, size, name, out);
    case IMAGE_WEBP: return image_decode_webp(ctx, data, size, name, out);
    default: break;
    }
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: not a PNG, JPEG, OpenEXR, Radiance HDR, PFM or WebP image", name);
}

/* ---- WebP ------------------------------------------------------------------ */

static dynlib webp_lib = DYNLIB_INIT;

#if PK_HAVE_WEBP
static struct {
    VP8StatusCode (*features)(const uint8_t *, size_t, WebPBitstreamFeatures *, int);
    uint8_t *(*rgba)(const uint8_t *, size_t, uint8_t *, size_t, int);
    uint8_t *(*rgb)(const uint8_t *, size_t, uint8_t *, size_t, int);
} webp;

static bool webp_init(void *h, const char *name, char *why, size_t n)
{
    static const char *const names[3] = {"WebPGetFeaturesInternal", "WebPDecodeRGBAInto", "WebPDecodeRGBInto"};
    void *sym[3];
    for (int k = 0; k < 3; k++)
        if (!(sym[k] = dynlib_symbol(h, names[k]))) {
            snprintf(why, n, "%s has no %s", name, names[k]);
            return false;
        }
    memcpy(&webp.features, &sym[0], sizeof sym[0]);
    memcpy(&webp.rgba, &sym[1], sizeof sym[1]);
    memcpy(&webp.rgb, &sym[2], sizeof sym[2]);
    return true;
}
#endif

bool image_have_webp(void)
{
#if PK_HAVE_WEBP
    char why[8];
    return dynlib_load(&webp_lib, PK_WEBP_SONAME, webp_init, why, sizeof why);
#else
    (void)webp_lib;
    return false;
#endif
}

pk_status image_decode_webp(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    memset(out, 0, sizeof *out);
#if PK_HAVE_WEBP
    char why[400];
    if (!dynlib_load(&webp_lib, PK_WEBP_SONAME, webp_init, why, sizeof why))
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: a WebP image, and libwebp does not load (%.300s; Debian: libwebp7)",
                         name, why);
    WebPBitstreamFeatures f;
    memset(&f, 0, sizeof f);
    VP8StatusCode vs = webp.features(data, size, &f, WEBP_DECODER_ABI_VERSION);
    if (vs != VP8_STATUS_OK)
        return ctx_error(ctx, vs == VP8_STATUS_UNSUPPORTED_FEATURE ? PK_ERR_UNSUPPORTED : PK_ERR_PARSE,
                         "%s: bad WebP (%s)", name,
                         vs == VP8_STATUS_NOT_ENOUGH_DATA ? "truncated" : vs == VP8_STATUS_UNSUPPORTED_FEATURE
                                                                               ? "a feature libwebp does not decode"
                                                                               : "corrupt header");
    if (f.has_animation)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: an animated WebP (only still images are read)", name);
    pk_status st = check_size(ctx, name, f.width, f.height);
    if (st != PK_OK) return st;
    int nc = f.has_alpha ? 4 : 3;
    if ((st = alloc_buf(ctx, out, f.width, f.height, nc, false)) != PK_OK) return st;
    size_t row = (size_t)f.width * (size_t)nc, total = row * (size_t)f.height;
    uint8_t *r = nc == 4 ? webp.rgba(data, size, out->px8, total, (int)row) : webp.rgb(data, size, out->px8, total, (int)row);
    if (!r) {
        image_buf_free(&ctx->alloc, out);
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad WebP (corrupt or truncated image data)", name);
    }
    return PK_OK;
#else
    (void)data, (void)size, (void)webp_lib;
    return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                     "%s: a WebP image, and this build does not read WebP (libwebp's header, Debian libwebp-dev, was "
                     "missing when it was built)",
                     name);
#endif
}

/* ---- PNG ------------------------------------------------------------------ */

pk_status image_decode_png(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    memset(out, 0, sizeof *out);
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&im, data, size)) {
        pk_status st = ctx_error(ctx, PK_ERR_PARSE, "%s: bad PNG: %s", name, im.message);
        png_image_free(&im);
        return st;
    }
    pk_status st = check_size(ctx, name, im.width, im.height);
    if (st != PK_OK) {
        png_image_free(&im);
        return st;
    }
    int nc = (im.format & PNG_FORMAT_FLAG_COLOR) ? 3 : 1;
    if (im.format & PNG_FORMAT_FLAG_ALPHA) nc++;
    static const png_uint_32 formats[5] = {0, PNG_FORMAT_GRAY, PNG_FORMAT_GA, PNG_FORMAT_RGB, PNG_FORMAT_RGBA};
    im.format = formats[nc];
    st = alloc_buf(ctx, out, (int)im.width, (int)im.height, nc, false);
    if (st != PK_OK) {
        png_image_free(&im);
        return st;
    }
    if (!png_image_finish_read(&im, NULL, out->px8, 0, NULL)) {
        st = ctx_error(ctx, PK_ERR_PARSE, "%s: bad PNG: %s", name, im.message);
        png_image_free(&im);
        image_buf_free(&ctx->alloc, out);
        return st;
    }
    png_image_free(&im);
    return PK_OK;
}

/* ---- JPEG ------------------------------------------------------------------ */

#define JPEG_MAX_SCANS 1000                 /* a progressive file with more is refused */
#define JPEG_MAX_MEMORY ((long)1 << 30)     /* libjpeg's working memory */

typedef struct jpeg_err {
    struct jpeg_error_mgr pub;
    jmp_buf jb;
    char msg[JMSG_LENGTH_MAX];
} jpeg_err;

static void jpeg_on_error(j_common_ptr c)
{
    jpeg_err *e = (jpeg_err *)c->err;
    c->err->format_message(c, e->msg);
    longjmp(e->jb, 1);
}

static void jpeg_on_message(j_common_ptr c) { (void)c; } /* warnings: not printed */

static void jpeg_on_progress(j_common_ptr c)
{
    j_decompress_ptr d = (j_decompress_ptr)c;
    if (d->input_scan_number > JPEG_MAX_SCANS) {
        jpeg_err *e = (jpeg_err *)c->err;
        snprintf(e->msg, sizeof e->msg, "more than %d scans", JPEG_MAX_SCANS);
        longjmp(e->jb, 1);
    }
}

typedef struct jpeg_job {
    struct jpeg_decompress_struct d;
    jpeg_err err;
    struct jpeg_progress_mgr progress;
    image_buf img;
} jpeg_job;

pk_status image_decode_jpeg(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    memset(out, 0, sizeof *out);
    if (size > ULONG_MAX) return ctx_error(ctx, PK_ERR_LIMIT, "%s: JPEG too large", name);
    /* on the heap: what longjmp returns to must not live in registers */
    jpeg_job *volatile job = mem_calloc(&ctx->alloc, 1, sizeof *job);
    if (!job) return ctx_nomem(ctx);
    job->d.err = jpeg_std_error(&job->err.pub);
    job->err.pub.error_exit = jpeg_on_error;
    job->err.pub.output_message = jpeg_on_message;
    pk_status st = PK_OK;
    if (setjmp(job->err.jb)) {
        if (ctx->status == PK_OK) st = ctx_error(ctx, PK_ERR_PARSE, "%s: bad JPEG: %s", name, job->err.msg);
        else st = ctx->status;
        goto done;
    }
    jpeg_create_decompress(&job->d);
    job->d.mem->max_memory_to_use = JPEG_MAX_MEMORY;
    job->progress.progress_monitor = jpeg_on_progress;
    job->d.progress = &job->progress;
    jpeg_mem_src(&job->d, (const unsigned char *)data, (unsigned long)size);
    jpeg_read_header(&job->d, TRUE);
    int nc;
    switch (job->d.jpeg_color_space) {
    case JCS_GRAYSCALE: job->d.out_color_space = JCS_GRAYSCALE; nc = 1; break;
    case JCS_CMYK:
    case JCS_YCCK:
        st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: CMYK JPEG images are not supported", name);
        goto done;
    default: job->d.out_color_space = JCS_RGB; nc = 3; break;
    }
    st = check_size(ctx, name, job->d.image_width, job->d.image_height);
    if (st != PK_OK) goto done;
    jpeg_start_decompress(&job->d);
    if ((int)job->d.output_components != nc || job->d.output_width != job->d.image_width ||
        job->d.output_height != job->d.image_height) {
        st = ctx_error(ctx, PK_ERR_PARSE, "%s: bad JPEG: unexpected output layout", name);
        goto done;
    }
    st = alloc_buf(ctx, &job->img, (int)job->d.output_width, (int)job->d.output_height, nc, false);
    if (st != PK_OK) goto done;
    while (job->d.output_scanline < job->d.output_height) {
        JSAMPROW row = job->img.px8 + (size_t)job->d.output_scanline * (size_t)job->img.w * (size_t)nc;
        if (jpeg_read_scanlines(&job->d, &row, 1) != 1) {
            st = ctx_error(ctx, PK_ERR_PARSE, "%s: bad JPEG: truncated", name);
            goto done;
        }
    }
    jpeg_finish_decompress(&job->d);
    *out = job->img;
    memset(&job->img, 0, sizeof job->img);
done:
    jpeg_destroy_decompress(&job->d);
    image_buf_free(&ctx->alloc, &job->img);
    mem_free(&ctx->alloc, job);
    return st;
}

/* ---- OpenEXR ------------------------------------------------------------------ */

typedef struct exr_src {
    const unsigned char *data;
    size_t size;
    char msg[200];
} exr_src;

static void exr_on_error(exr_const_context_t e, exr_result_t code, const char *msg)
{
    void *user = NULL;
    exr_get_user_data(e, &user);
    exr_src *s = user;
    if (s && !s->msg[0])
        snprintf(s->msg, sizeof s->msg, "%s", msg && msg[0] ? msg : exr_get_default_error_message(code));
}

static int64_t exr_on_read(exr_const_context_t e, void *user, void *buffer, uint64_t sz, uint64_t offset,
                           exr_stream_error_func_ptr_t error_cb)
{
    (void)e;
    (void)error_cb;
    exr_src *s = user;
    if (offset >= s->size) return 0;
    uint64_t n = s->size - offset < sz ? s->size - offset : sz;
    memcpy(buffer, s->data + offset, (size_t)n);
    return (int64_t)n;
}

static int64_t exr_on_size(exr_const_context_t e, void *user)
{
    (void)e;
    return (int64_t)((exr_src *)user)->size;
}

/* Which of the file's channels go where: index into out's nc samples, -1 =
 * skipped. layer (NULL: the image's own channels) picks LAYER.R/G/B/A/Y. */
static int exr_pick_channels(const exr_attr_chlist_t *cl, const char *layer, int map[], int *nc)
{
    int r = -1, g = -1, b = -1, a = -1, y = -1;
    const size_t lp = layer ? strlen(layer) : 0;
    for (int i = 0; i < cl->num_channels; i++) {
        const char *n = cl->entries[i].name.str;
        if (!n) continue;
        if (layer) {
            if (strncmp(n, layer, lp) != 0 || n[lp] != '.') continue;
            n += lp + 1;
        } else if (strchr(n, '.')) {
            continue; /* another layer's */
        }
        if (!strcmp(n, "R")) r = i;
        else if (!strcmp(n, "G")) g = i;
        else if (!strcmp(n, "B")) b = i;
        else if (!strcmp(n, "A")) a = i;
        else if (!strcmp(n, "Y")) y = i;
    }
    for (int i = 0; i < cl->num_channels; i++) map[i] = -1;
    if (r >= 0 && g >= 0 && b >= 0) {
        map[r] = 0, map[g] = 1, map[b] = 2;
        *nc = 3;
    } else {
        int grey = y >= 0 ? y : r >= 0 ? r : g >= 0 ? g : b >= 0 ? b : -1;
        if (grey < 0 && !layer) { /* anything: the first channel that is not alpha */
            for (int i = 0; i < cl->num_channels && grey < 0; i++)
                if (i != a) grey = i;
        }
        if (grey < 0) return -1;
        map[grey] = 0;
        *nc = 1;
    }
    if (a >= 0) map[a] = (*nc)++;
    return 0;
}

pk_status image_decode_exr(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    return image_decode_exr_layer(ctx, data, size, name, NULL, out);
}

pk_status image_decode_exr_layer(pk_context *ctx, const void *data, size_t size, const char *name, const char *layer,
                                 image_buf *out)
{
    memset(out, 0, sizeof *out);
    exr_src src = {data, size, ""};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &src;
    init.read_fn = exr_on_read;
    init.size_fn = exr_on_size;
    init.error_handler_fn = exr_on_error;
    init.max_image_width = PK_MAX_TEXTURE_SIDE;
    init.max_image_height = PK_MAX_TEXTURE_SIDE;
    init.max_tile_width = PK_MAX_TEXTURE_SIDE;
    init.max_tile_height = PK_MAX_TEXTURE_SIDE;
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    exr_context_t e = NULL;
    exr_decode_pipeline_t dec;
    bool have_dec = false;
    float *scratch = NULL;  /* one chunk's decoded channels */
    size_t scratch_n = 0;
    int map[128];
    pk_status st = PK_OK;
    exr_result_t rv = exr_start_read(&e, name, &init);
    if (rv != EXR_ERR_SUCCESS) goto exr_fail;
    exr_storage_t storage;
    if ((rv = exr_get_storage(e, 0, &storage)) != EXR_ERR_SUCCESS) goto exr_fail;
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: deep OpenEXR images are not supported", name);
        goto done;
    }
    exr_attr_box2i_t dw;
    if ((rv = exr_get_data_window(e, 0, &dw)) != EXR_ERR_SUCCESS) goto exr_fail;
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if ((st = check_size(ctx, name, w, h)) != PK_OK) goto done;
    const exr_attr_chlist_t *cl = NULL;
    if ((rv = exr_get_channels(e, 0, &cl)) != EXR_ERR_SUCCESS) goto exr_fail;
    int nc = 0;
    if (!cl || cl->num_channels <= 0 || cl->num_channels > 128 || exr_pick_channels(cl, layer, map, &nc) != 0) {
        if (layer)
            st = ctx_error(ctx, PK_ERR_PARSE, "%s: OpenEXR image has no layer '%s' (channels %s.R, %s.G, %s.B)", name,
                           layer, layer, layer, layer);
        else
            st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: OpenEXR image has no usable channel", name);
        goto done;
    }
    for (int i = 0; i < cl->num_channels; i++)
        if (map[i] >= 0 && (cl->entries[i].x_sampling != 1 || cl->entries[i].y_sampling != 1)) {
            st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: subsampled OpenEXR channels are not supported", name);
            goto done;
        }
    if ((st = alloc_buf(ctx, out, (int)w, (int)h, nc, true)) != PK_OK) goto done;
    memset(out->pxf, 0, (size_t)w * (size_t)h * (size_t)nc * sizeof(float));

    /* the chunks: scanline blocks, or the tiles of level 0 */
    int32_t nx = 1, ny, lines = 1;
    uint32_t tw = 0, th = 0;
    if (storage == EXR_STORAGE_SCANLINE) {
        if ((rv = exr_get_scanlines_per_chunk(e, 0, &lines)) != EXR_ERR_SUCCESS) goto exr_fail;
        if (lines <= 0) goto exr_bad;
        ny = (int32_t)((h + lines - 1) / lines);
    } else {
        exr_tile_level_mode_t lm;
        exr_tile_round_mode_t rm;
        if ((rv = exr_get_tile_descriptor(e, 0, &tw, &th, &lm, &rm)) != EXR_ERR_SUCCESS) goto exr_fail;
        if (tw == 0 || th == 0) goto exr_bad;
        nx = (int32_t)((w + tw - 1) / tw);
        ny = (int32_t)((h + th - 1) / th);
    }
    for (int32_t cy = 0; cy < ny; cy++) {
        for (int32_t cx = 0; cx < nx; cx++) {
            exr_chunk_info_t ci;
            int64_t x0, y0;
            if (storage == EXR_STORAGE_SCANLINE) {
                const int64_t y = (int64_t)dw.min.y + (int64_t)cy * lines;
                if (y > INT32_MAX) goto exr_bad;
                rv = exr_read_scanline_chunk_info(e, 0, (int)y, &ci);
                x0 = 0;
                y0 = (int64_t)ci.start_y - dw.min.y;
            } else {
                rv = exr_read_tile_chunk_info(e, 0, cx, cy, 0, 0, &ci);
                x0 = (int64_t)cx * tw;
                y0 = (int64_t)cy * th;
            }
            if (rv != EXR_ERR_SUCCESS) goto exr_fail;
            if (x0 < 0 || y0 < 0 || ci.width <= 0 || ci.height <= 0 || x0 + ci.width > w || y0 + ci.height > h)
                goto exr_bad;
            const size_t plane = (size_t)ci.width * (size_t)ci.height; /* <= w * h */
            if (plane * (size_t)nc > scratch_n) {
                float *ns = mem_realloc_array(&ctx->alloc, scratch, plane * (size_t)nc, sizeof(float));
                if (!ns) {
                    st = ctx_nomem(ctx);
                    goto done;
                }
                scratch = ns;
                scratch_n = plane * (size_t)nc;
            }
            memset(scratch, 0, plane * (size_t)nc * sizeof(float));
            /* a pipeline per chunk: exr_decoding_update (OpenEXR 3.1) mixes up
             * the sizes of a full tile after a partial one */
            if (have_dec) exr_decoding_destroy(e, &dec);
            have_dec = false;
            rv = exr_decoding_initialize(e, 0, &ci, &dec);
            if (rv != EXR_ERR_SUCCESS) goto exr_fail;
            have_dec = true;
            for (int c = 0; c < dec.channel_count; c++) {
                exr_coding_channel_info_t *ch = &dec.channels[c];
                int k = -1;
                for (int i = 0; i < cl->num_channels; i++)
                    if (ch->channel_name && cl->entries[i].name.str && !strcmp(ch->channel_name, cl->entries[i].name.str))
                        k = map[i];
                if (k < 0 || ch->width != ci.width || ch->height != ci.height) {
                    ch->decode_to_ptr = NULL;
                    continue;
                }
                /* planar, one plane per channel: OpenEXR 3.1's routines for
                 * interleaved output assume the file's channel order */
                ch->decode_to_ptr = (uint8_t *)(scratch + (size_t)k * plane);
                ch->user_pixel_stride = (int32_t)sizeof(float);
                ch->user_line_stride = ci.width * (int32_t)sizeof(float);
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = 4;
            }
            if ((rv = exr_decoding_choose_default_routines(e, 0, &dec)) != EXR_ERR_SUCCESS) goto exr_fail;
            if ((rv = exr_decoding_run(e, 0, &dec)) != EXR_ERR_SUCCESS) goto exr_fail;
            for (int k = 0; k < nc; k++)
                for (int y = 0; y < ci.height; y++) {
                    const float *src_row = scratch + (size_t)k * plane + (size_t)y * (size_t)ci.width;
                    float *dst = out->pxf + ((size_t)(y0 + y) * (size_t)w + (size_t)x0) * (size_t)nc + (size_t)k;
                    for (int x = 0; x < ci.width; x++) dst[(size_t)x * (size_t)nc] = src_row[x];
                }
        }
    }
    sanitize_floats(out->pxf, (size_t)w * (size_t)h * (size_t)nc);
    goto done;
exr_bad:
    st = ctx_error(ctx, PK_ERR_PARSE, "%s: bad OpenEXR image: inconsistent chunk layout", name);
    goto done;
exr_fail:
    st = ctx_error(ctx, rv == EXR_ERR_OUT_OF_MEMORY ? PK_ERR_NOMEM : PK_ERR_PARSE, "%s: bad OpenEXR image: %s", name,
                   src.msg[0] ? src.msg : exr_get_default_error_message(rv));
done:
    if (have_dec) exr_decoding_destroy(e, &dec);
    if (e) exr_finish(&e);
    mem_free(&ctx->alloc, scratch);
    if (st != PK_OK) image_buf_free(&ctx->alloc, out);
    return st;
}

/* ---- Radiance .hdr --------------------------------------------------------- */

/* Next header line [*ls, *le) from *p; false at the end of the data. */
static bool hdr_line(const unsigned char **p, const unsigned char *end, const unsigned char **ls,
                     const unsigned char **le)
{
    const unsigned char *q = *p;
    if (q >= end) return false;
    const unsigned char *nl = memchr(q, '\n', (size_t)(end - q));
    if (!nl) return false;
    *ls = q;
    *le = nl;
    *p = nl + 1;
    return true;
}

/* Reads "[+-]Y n [+-]X m" style tokens: sign and axis, then a number. */
static bool hdr_axis(const unsigned char **p, const unsigned char *e, char *sign, char *axis, int64_t *n)
{
    const unsigned char *q = *p;
    while (q < e && *q == ' ') q++;
    if (e - q < 2 || (q[0] != '+' && q[0] != '-') || (q[1] != 'X' && q[1] != 'Y')) return false;
    *sign = (char)q[0];
    *axis = (char)q[1];
    q += 2;
    while (q < e && *q == ' ') q++;
    int64_t v = 0;
    const unsigned char *d = q;
    while (q < e && *q >= '0' && *q <= '9' && v < 100000000) v = v * 10 + (*q++ - '0');
    if (q == d) return false;
    *n = v;
    *p = q;
    return true;
}

static inline void rgbe_to_float(const unsigned char *c, float *out)
{
    if (c[3] == 0) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    float f = ldexpf(1.0f, (int)c[3] - (128 + 8));
    out[0] = ((float)c[0] + 0.5f) * f;
    out[1] = ((float)c[1] + 0.5f) * f;
    out[2] = ((float)c[2] + 0.5f) * f;
}

/* One scanline of w RGBE pixels into line (4w bytes): adaptive RLE, or flat
 * pixels with the old run-length repeats. Returns false on corrupt data. */
static bool hdr_scanline(const unsigned char **pp, const unsigned char *end, int w, unsigned char *line)
{
    const unsigned char *p = *pp;
    if (end - p < 4) return false;
    if (w >= 8 && w < 32768 && p[0] == 2 && p[1] == 2 && !(p[2] & 0x80)) {
        if (((int)p[2] << 8 | p[3]) != w) return false;
        p += 4;
        for (int c = 0; c < 4; c++) {
            int i = 0;
            while (i < w) {
                if (p >= end) return false;
                int n = *p++;
                if (n > 128) {
                    n -= 128;
                    if (n > w - i || p >= end) return false;
                    unsigned char v = *p++;
                    for (int k = 0; k < n; k++) line[4 * (i + k) + c] = v;
                } else {
                    if (n == 0 || n > w - i || end - p < n) return false;
                    for (int k = 0; k < n; k++) line[4 * (i + k) + c] = p[k];
                    p += n;
                }
                i += n;
            }
        }
        *pp = p;
        return true;
    }
    int i = 0, shift = 0;
    while (i < w) {
        if (end - p < 4) return false;
        if (p[0] == 1 && p[1] == 1 && p[2] == 1) { /* old RLE: repeat the previous pixel */
            if (i == 0 || shift > 16) return false;
            int64_t n = (int64_t)p[3] << shift;
            if (n > w - i) return false;
            for (int64_t k = 0; k < n; k++) memcpy(line + 4 * (i + k), line + 4 * (i - 1), 4);
            i += (int)n;
            shift += 8;
        } else {
            memcpy(line + 4 * i, p, 4);
            i++;
            shift = 0;
        }
        p += 4;
    }
    *pp = p;
    return true;
}

pk_status image_decode_hdr(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    memset(out, 0, sizeof *out);
    const unsigned char *p = data, *end = p + size, *ls, *le;
    if (!hdr_line(&p, end, &ls, &le) || le - ls < 2 || ls[0] != '#' || ls[1] != '?')
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad Radiance HDR image: no header", name);
    /* header lines up to an empty one */
    for (;;) {
        if (!hdr_line(&p, end, &ls, &le)) return ctx_error(ctx, PK_ERR_PARSE, "%s: bad Radiance HDR image: truncated header", name);
        if (le > ls && le[-1] == '\r') le--;
        if (le == ls) break;
        static const char fmt[] = "FORMAT=";
        if ((size_t)(le - ls) > sizeof fmt - 1 && memcmp(ls, fmt, sizeof fmt - 1) == 0) {
            const unsigned char *v = ls + sizeof fmt - 1;
            if (!((size_t)(le - v) == 15 && memcmp(v, "32-bit_rle_rgbe", 15) == 0))
                return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: Radiance HDR format '%.*s' is not supported (only 32-bit_rle_rgbe)",
                                 name, (int)(le - v > 40 ? 40 : le - v), (const char *)v);
        }
    }
    if (!hdr_line(&p, end, &ls, &le)) return ctx_error(ctx, PK_ERR_PARSE, "%s: bad Radiance HDR image: no resolution line", name);
    char s1, a1, s2, a2;
    int64_t n1, n2;
    const unsigned char *q = ls;
    if (!hdr_axis(&q, le, &s1, &a1, &n1) || !hdr_axis(&q, le, &s2, &a2, &n2) || a1 != 'Y' || a2 != 'X' || s2 != '+')
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: Radiance HDR resolution line is not '-Y h +X w' or '+Y h +X w'", name);
    pk_status st = check_size(ctx, name, n2, n1);
    if (st != PK_OK) return st;
    int w = (int)n2, h = (int)n1;
    if ((st = alloc_buf(ctx, out, w, h, 3, true)) != PK_OK) return st;
    unsigned char *line = mem_alloc(&ctx->alloc, (size_t)w * 4);
    if (!line) {
        image_buf_free(&ctx->alloc, out);
        return ctx_nomem(ctx);
    }
    for (int y = 0; y < h; y++) {
        if (!hdr_scanline(&p, end, w, line)) {
            mem_free(&ctx->alloc, line);
            image_buf_free(&ctx->alloc, out);
            return ctx_error(ctx, PK_ERR_PARSE, "%s: bad Radiance HDR image: scanline %d is corrupt or truncated", name, y);
        }
        int row = s1 == '-' ? y : h - 1 - y; /* +Y: bottom to top */
        float *o = out->pxf + (size_t)row * (size_t)w * 3;
        for (int x = 0; x < w; x++) rgbe_to_float(line + 4 * x, o + 3 * x);
    }
    mem_free(&ctx->alloc, line);
    sanitize_floats(out->pxf, (size_t)w * (size_t)h * 3);
    return PK_OK;
}

/* ---- PFM ------------------------------------------------------------------ */

/* A decimal token after blanks; false when none (or too long). */
static bool pfm_token(const unsigned char **pp, const unsigned char *end, char *buf, size_t n)
{
    const unsigned char *p = *pp;
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) p++;
    size_t k = 0;
    while (p < end && !(*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) {
        if (k + 1 >= n) return false;
        buf[k++] = (char)*p++;
    }
    buf[k] = '\0';
    *pp = p;
    return k > 0;
}

pk_status image_decode_pfm(pk_context *ctx, const void *data, size_t size, const char *name, image_buf *out)
{
    memset(out, 0, sizeof *out);
    const unsigned char *p = data, *end = p + size;
    if (size < 3 || p[0] != 'P' || (p[1] != 'F' && p[1] != 'f'))
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad PFM image: no PF or Pf header", name);
    int nc = p[1] == 'F' ? 3 : 1;
    p += 2;
    char tw[32], th[32], ts[64];
    if (!pfm_token(&p, end, tw, sizeof tw) || !pfm_token(&p, end, th, sizeof th) || !pfm_token(&p, end, ts, sizeof ts) ||
        p >= end)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad PFM image: truncated header", name);
    p++; /* the single whitespace character before the samples */
    char *e1, *e2, *e3;
    long long w = strtoll(tw, &e1, 10), h = strtoll(th, &e2, 10);
    double scale = strtod(ts, &e3);
    if (*e1 || *e2 || *e3 || !isfinite(scale) || scale == 0.0)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad PFM image: bad size or scale", name);
    pk_status st = check_size(ctx, name, w, h);
    if (st != PK_OK) return st;
    size_t n = (size_t)w * (size_t)h * (size_t)nc;
    if ((size_t)(end - p) / sizeof(float) < n)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad PFM image: truncated (%zu bytes of samples, %zu needed)", name,
                         (size_t)(end - p), n * sizeof(float));
    if ((st = alloc_buf(ctx, out, (int)w, (int)h, nc, true)) != PK_OK) return st;
    const bool little = scale < 0.0;
    const size_t row = (size_t)w * (size_t)nc;
    for (long long y = 0; y < h; y++) {
        const unsigned char *src = p + (size_t)y * row * 4;
        float *dst = out->pxf + (size_t)(h - 1 - y) * row; /* rows bottom to top */
        for (size_t i = 0; i < row; i++) {
            const unsigned char *b = src + 4 * i;
            uint32_t u = little ? (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24
                                : (uint32_t)b[3] | (uint32_t)b[2] << 8 | (uint32_t)b[1] << 16 | (uint32_t)b[0] << 24;
            float f;
            memcpy(&f, &u, sizeof f);
            dst[i] = f;
        }
    }
    sanitize_floats(out->pxf, n);
    return PK_OK;
}

/* ---- files ---------------------------------------------------------------------- */

pk_status image_read_file(pk_context *ctx, const char *path, image_buf *out)
{
    memset(out, 0, sizeof *out);
    char *data = NULL;
    size_t size = 0;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    st = image_decode(ctx, data, size, path, out);
    mem_free(&ctx->alloc, data);
    return st;
}

pk_status image_load_rgb(pk_context *ctx, const char *path, int *w, int *h, float **rgb)
{
    *w = *h = 0;
    *rgb = NULL;
    image_buf img;
    pk_status st = image_read_file(ctx, path, &img);
    if (st != PK_OK) return st;
    size_t np = (size_t)img.w * (size_t)img.h;
    float *o = mem_realloc_array(&ctx->alloc, NULL, np, 3 * sizeof(float));
    if (!o) {
        image_buf_free(&ctx->alloc, &img);
        return ctx_nomem(ctx);
    }
    const int nc = img.nc, colour = nc >= 3;
    for (size_t i = 0; i < np; i++) {
        for (int c = 0; c < 3; c++) {
            size_t k = i * (size_t)nc + (size_t)(colour ? c : 0);
            o[3 * i + (size_t)c] = img.pxf ? img.pxf[k] : image_srgb_to_linear[img.px8[k]];
        }
    }
    *w = img.w;
    *h = img.h;
    *rgb = o;
    image_buf_free(&ctx->alloc, &img);
    return PK_OK;
}

pk_status pk_image_read(pk_context *ctx, const char *path, const char *layer, pk_image **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!path) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "image: no file name");
    char *data;
    size_t size;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    image_buf img;
    if (layer && image_sniff(data, size) != IMAGE_EXR)
        st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: layer '%s' asked of an image that is not OpenEXR", path, layer);
    else
        st = layer ? image_decode_exr_layer(ctx, data, size, path, layer, &img) : image_decode(ctx, data, size, path, &img);
    mem_free(&ctx->alloc, data);
    if (st != PK_OK) return st;
    pk_image *im;
    if ((st = image_create(ctx, img.w, img.h, &im)) == PK_OK) {
        const size_t np = (size_t)img.w * (size_t)img.h;
        const int nc = img.nc, colour = nc >= 3;
        for (size_t i = 0; i < np; i++)
            for (int c = 0; c < 3; c++) {
                size_t k = i * (size_t)nc + (size_t)(colour ? c : 0);
                im->pixels[3 * i + (size_t)c] = img.pxf ? img.pxf[k] : image_srgb_to_linear[img.px8[k]];
            }
        *out = im;
    }
    image_buf_free(&ctx->alloc, &img);
    return st;
}

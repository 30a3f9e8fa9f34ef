/*
 * test_image_read.c - the image readers through their buffer entry points.
 * Each format is written here (PNG with libpng, JPEG with libjpeg in its
 * baseline, progressive and greyscale forms, OpenEXR with the library's
 * writer, Radiance .hdr flat and run-length encoded, PFM in both byte
 * orders) and read back: size, channels and samples. Truncated and corrupt
 * inputs and sizes past the limits are refused with a message naming the
 * file. The sRGB table matches the IEC 61966-2-1 curve, and image_load_rgb
 * decodes 8-bit files from sRGB and spreads grey to RGB.
 */
#include "test.h"

#include "paprsek.h"
#include "image/image_write.h"
#include "image/image_read.h"

#include <fcntl.h>
#include <jpeglib.h>
#include <openexr.h>
#include <png.h>
#include <stdint.h>

static pk_context *ctx;

static void reset(void) { pk_context_clear_error(ctx); }

/* ---- writers for the tests ------------------------------------------------ */

static unsigned char *png_encode(const unsigned char *px, int w, int h, png_uint_32 format, size_t *size)
{
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    im.width = (png_uint_32)w;
    im.height = (png_uint_32)h;
    im.format = format;
    png_alloc_size_t n = 0;
    REQUIRE(png_image_write_to_memory(&im, NULL, &n, 0, px, 0, NULL));
    unsigned char *buf = malloc(n);
    REQUIRE(buf);
    REQUIRE(png_image_write_to_memory(&im, buf, &n, 0, px, 0, NULL));
    *size = n;
    return buf;
}

static unsigned char *jpeg_encode(const unsigned char *px, int w, int h, int nc, bool progressive, size_t *size)
{
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr err;
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    unsigned char *buf = NULL;
    unsigned long n = 0;
    jpeg_mem_dest(&c, &buf, &n);
    c.image_width = (JDIMENSION)w;
    c.image_height = (JDIMENSION)h;
    c.input_components = nc;
    c.in_color_space = nc == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    if (progressive) jpeg_simple_progression(&c);
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = (JSAMPROW)(px + (size_t)c.next_scanline * (size_t)w * (size_t)nc);
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    *size = n;
    return buf;
}

/* ---- PNG -------------------------------------------------------------------- */

static void test_png(void)
{
    const int w = 5, h = 3;
    unsigned char px[5 * 3 * 4];
    for (int i = 0; i < w * h * 4; i++) px[i] = (unsigned char)(i * 7 + 3);
    size_t n;
    unsigned char *buf = png_encode(px, w, h, PNG_FORMAT_RGBA, &n);
    image_buf img;
    REQUIRE(image_decode(ctx, buf, n, "rgba.png", &img) == PK_OK);
    CHECK(img.w == w && img.h == h && img.nc == 4 && img.px8 && !img.pxf);
    CHECK(img.px8 && memcmp(img.px8, px, sizeof px) == 0);
    image_buf_free(&ctx->alloc, &img);

    /* truncated before the closing IEND chunk (12 bytes): an error naming
     * the file, nothing allocated */
    for (size_t cut = 0; cut < n - 12; cut += 7) {
        reset();
        CHECK(image_decode_png(ctx, buf, cut, "cut.png", &img) == PK_ERR_PARSE);
        CHECK(strstr(pk_context_error(ctx), "cut.png") != NULL);
        CHECK(!img.px8 && !img.pxf);
    }
    reset();
    /* a flipped byte in the data: the CRC or zlib stream says so */
    buf[n - 20] ^= 0x55;
    CHECK(image_decode(ctx, buf, n, "bad.png", &img) == PK_ERR_PARSE);
    reset();
    free(buf);

    /* grey stays one channel */
    unsigned char g[4] = {0, 64, 128, 255};
    buf = png_encode(g, 2, 2, PNG_FORMAT_GRAY, &n);
    REQUIRE(image_decode(ctx, buf, n, "grey.png", &img) == PK_OK);
    CHECK(img.nc == 1 && img.px8 && memcmp(img.px8, g, 4) == 0);
    image_buf_free(&ctx->alloc, &img);
    free(buf);

    /* wider than PK_MAX_TEXTURE_SIDE: refused before decoding */
    const int wide = PK_MAX_TEXTURE_SIDE + 1;
    unsigned char *row = calloc((size_t)wide, 1);
    REQUIRE(row);
    buf = png_encode(row, wide, 1, PNG_FORMAT_GRAY, &n);
    CHECK(image_decode(ctx, buf, n, "wide.png", &img) == PK_ERR_LIMIT);
    CHECK(strstr(pk_context_error(ctx), "wide.png") != NULL);
    reset();
    free(buf);
    free(row);
}

/* ---- JPEG ------------------------------------------------------------------- */

static void test_jpeg(void)
{
    const int w = 16, h = 16;
    unsigned char px[16 * 16 * 3];
    for (int i = 0; i < w * h; i++) px[3 * i] = 200, px[3 * i + 1] = 100, px[3 * i + 2] = 50;
    for (int prog = 0; prog < 2; prog++) {
        size_t n;
        unsigned char *buf = jpeg_encode(px, w, h, 3, prog, &n);
        image_buf img;
        REQUIRE(image_decode(ctx, buf, n, "flat.jpg", &img) == PK_OK);
        CHECK(img.w == w && img.h == h && img.nc == 3 && img.px8);
        int worst = 0;
        for (int i = 0; i < w * h * 3; i++) {
            int d = abs((int)img.px8[i] - (int)px[i]);
            if (d > worst) worst = d;
        }
        /* quality 100, a flat colour: only the colour conversion rounds */
        CHECKF(worst <= 2, "progressive %d: worst difference %d", prog, worst);
        image_buf_free(&ctx->alloc, &img);
        /* cut inside the header */
        CHECK(image_decode(ctx, buf, 40, "cut.jpg", &img) == PK_ERR_PARSE);
        CHECK(strstr(pk_context_error(ctx), "cut.jpg") != NULL);
        CHECK(!img.px8);
        reset();
        /* every cut: no crash, and an image or an error */
        for (size_t cut = 0; cut < n; cut += 13) {
            pk_status st = image_decode_jpeg(ctx, buf, cut, "cut.jpg", &img);
            CHECK(st == PK_OK ? img.px8 != NULL : img.px8 == NULL);
            image_buf_free(&ctx->alloc, &img);
            reset();
        }
        free(buf);
    }
    /* greyscale */
    unsigned char g[8 * 8];
    for (int i = 0; i < 64; i++) g[i] = 90;
    size_t n;
    unsigned char *buf = jpeg_encode(g, 8, 8, 1, false, &n);
    image_buf img;
    REQUIRE(image_decode(ctx, buf, n, "grey.jpg", &img) == PK_OK);
    CHECK(img.nc == 1 && img.px8 && abs((int)img.px8[27] - 90) <= 1);
    image_buf_free(&ctx->alloc, &img);
    free(buf);
}

/* ---- OpenEXR ----------------------------------------------------------------- */

static unsigned char *read_fd(int fd, size_t *size)
{
    off_t end = lseek(fd, 0, SEEK_END);
    REQUIRE(end > 0);
    unsigned char *buf = malloc((size_t)end);
    REQUIRE(buf && pread(fd, buf, (size_t)end, 0) == (ssize_t)end);
    *size = (size_t)end;
    return buf;
}

static void test_exr(void)
{
    const int w = 7, h = 37; /* more than one 16-line block */
    float *rgb = malloc(sizeof(float) * 3 * w * h);
    REQUIRE(rgb);
    for (int i = 0; i < 3 * w * h; i++) rgb[i] = (float)i * 0.37f - 3.0f;
    exr_channel ch[3] = {{"R", rgb, 3, 3 * (size_t)w}, {"G", rgb + 1, 3, 3 * (size_t)w}, {"B", rgb + 2, 3, 3 * (size_t)w}};
    char path[] = "/tmp/pk_image_read_XXXXXX";
    int fd = mkstemp(path);
    REQUIRE(fd >= 0);
    char why[256] = "";
    REQUIRE(exr_write_channels(fd, w, h, ch, 3, why, sizeof why) == 0);
    size_t n;
    unsigned char *buf = read_fd(fd, &n);
    close(fd);
    unlink(path);
    image_buf img;
    REQUIRE(image_decode(ctx, buf, n, "a.exr", &img) == PK_OK);
    CHECK(img.w == w && img.h == h && img.nc == 3 && img.pxf);
    CHECK(img.pxf && memcmp(img.pxf, rgb, sizeof(float) * 3 * w * h) == 0);
    image_buf_free(&ctx->alloc, &img);
    for (size_t cut = 0; cut < n; cut += 31) {
        pk_status st = image_decode_exr(ctx, buf, cut, "cut.exr", &img);
        CHECK(st != PK_OK);
        CHECK(strstr(pk_context_error(ctx), "cut.exr") != NULL);
        CHECK(!img.pxf);
        reset();
    }
    /* corrupt bytes anywhere: an image or an error, never a crash */
    for (size_t i = 0; i < n; i += 3) {
        buf[i] ^= 0xA5;
        if (image_decode_exr(ctx, buf, n, "flip.exr", &img) == PK_OK) image_buf_free(&ctx->alloc, &img);
        buf[i] ^= 0xA5;
        reset();
    }
    free(buf);
    free(rgb);
}

/* A ZIP chunk that does not compress is stored raw, and then holds the raw
 * pixels (the file format's rule: a chunk of the raw size is read as raw).
 * One chunk of 64x16 RGB floats, its first k bytes random and the rest zero: as k
 * grows the compressed size crosses the raw size (12288 bytes), and for
 * some k zlib's output is exactly that long, which OpenEXR 3.1's encoder
 * stored as it was (a denoised image came back with garbage in its first
 * 16 rows). Each k: the stored chunk is the raw pixels whenever it has the
 * raw size, and the image reads back bit for bit. (Three random fillings
 * per k; with Debian 12's zlib one of them hits the exact size.) */
static void test_exr_incompressible_chunks(void)
{
    enum { W = 64, H = 16, RAW = W * H * 3 * 4 };
    float *rgb = malloc(sizeof(float) * 3 * W * H);
    REQUIRE(rgb);
    uint32_t seed = 12345;
    int raw_chunks = 0, garbled = 0;
    for (int t = 0; t < 3 * 321; t++) {
        const int k = RAW - 320 + t / 3;
        unsigned char *bytes = (unsigned char *)rgb;
        for (int i = 0; i < RAW; i++) {
            seed = seed * 1664525u + 1013904223u;
            bytes[i] = i < k ? (unsigned char)(seed >> 24) : 0;
            if (i % 4 == 3) bytes[i] &= 0xBF; /* the exponent below 128: finite */
        }
        exr_channel ch[3] = {{"R", rgb, 3, 3 * (size_t)W}, {"G", rgb + 1, 3, 3 * (size_t)W}, {"B", rgb + 2, 3, 3 * (size_t)W}};
        char path[] = "/tmp/pk_exr_chunk_XXXXXX";
        int fd = mkstemp(path);
        REQUIRE(fd >= 0);
        char why[256] = "";
        REQUIRE(exr_write_channels(fd, W, H, ch, 3, why, sizeof why) == 0);
        size_t n;
        unsigned char *buf = read_fd(fd, &n);
        close(fd);
        unlink(path);
        /* the one chunk: after the header (attributes up to a 0 byte) and
         * its 8-byte offset: y, size, data */
        size_t p = 8;
        while (p < n && buf[p]) {
            p += strlen((char *)buf + p) + 1;
            p += strlen((char *)buf + p) + 1;
            int32_t sz;
            memcpy(&sz, buf + p, 4);
            p += 4 + (size_t)sz;
        }
        uint64_t off;
        REQUIRE(p + 9 <= n);
        memcpy(&off, buf + p + 1, 8);
        int32_t size;
        REQUIRE(off + 8 <= n);
        memcpy(&size, buf + off + 4, 4);
        if (size >= RAW) {
            raw_chunks++;
            CHECKF(size == RAW, "k %d: a chunk of %d bytes, more than raw", k, (int)size);
            /* raw layout: per line, the channels by name (B, G, R) */
            int same = 1;
            for (int y = 0; y < H && same; y++)
                for (int c = 0; c < 3 && same; c++)
                    for (int x = 0; x < W; x++) {
                        float v;
                        memcpy(&v, buf + off + 8 + (size_t)((y * 3 + c) * W + x) * 4, 4);
                        if (memcmp(&v, &rgb[(y * W + x) * 3 + (2 - c)], 4) != 0) {
                            same = 0;
                            break;
                        }
                    }
            CHECKF(same, "k %d: a chunk of the raw size that is not the raw pixels", k);
            if (!same) garbled++;
        }
        image_buf img;
        REQUIRE(image_decode(ctx, buf, n, "chunk.exr", &img) == PK_OK);
        CHECKF(img.pxf && memcmp(img.pxf, rgb, sizeof(float) * 3 * W * H) == 0, "k %d: read back differs", k);
        image_buf_free(&ctx->alloc, &img);
        free(buf);
    }
    /* the sweep must reach chunks stored raw, or it tests nothing */
    CHECKF(raw_chunks > 0, "no chunk was stored raw");
    CHECK(garbled == 0);
    free(rgb);
}

/* A tiled OpenEXR file of HALF channels R, G, B, A, tiles of tw x th
 * (partial ones at the right and bottom), written with OpenEXR's C API to
 * path. px: w*h*4 floats (RGBA), exact in HALF. Uncompressed: OpenEXR 3.1's
 * C encoder garbles a ZIP tile that follows a partial one (files from its
 * C++ library read correctly). */
static void write_tiled_exr(const char *path, int w, int h, int tw, int th, const float *px)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t e = NULL;
    REQUIRE(exr_start_write(&e, path, EXR_WRITE_FILE_DIRECTLY, &init) == EXR_ERR_SUCCESS);
    int part = 0;
    REQUIRE(exr_add_part(e, "tiles", EXR_STORAGE_TILED, &part) == EXR_ERR_SUCCESS);
    REQUIRE(exr_initialize_required_attr_simple(e, part, w, h, EXR_COMPRESSION_NONE) == EXR_ERR_SUCCESS);
    REQUIRE(exr_set_tile_descriptor(e, part, (uint32_t)tw, (uint32_t)th, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN) ==
            EXR_ERR_SUCCESS);
    static const char *const names = "RGBA";
    for (int c = 0; c < 4; c++) {
        char n[2] = {names[c], 0};
        REQUIRE(exr_add_channel(e, part, n, EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1) == EXR_ERR_SUCCESS);
    }
    REQUIRE(exr_write_header(e) == EXR_ERR_SUCCESS);
    float *planes = malloc(sizeof(float) * 4 * (size_t)w * (size_t)h);
    REQUIRE(planes);
    for (int i = 0; i < w * h; i++)
        for (int c = 0; c < 4; c++) planes[c * w * h + i] = px[4 * i + c];
    exr_encode_pipeline_t pipe;
    memset(&pipe, 0, sizeof pipe);
    bool have = false;
    for (int ty = 0; ty * th < h; ty++)
        for (int tx = 0; tx * tw < w; tx++) {
            exr_chunk_info_t ci;
            REQUIRE(exr_write_tile_chunk_info(e, part, tx, ty, 0, 0, &ci) == EXR_ERR_SUCCESS);
            if (have) exr_encoding_destroy(e, &pipe);
            REQUIRE(exr_encoding_initialize(e, part, &ci, &pipe) == EXR_ERR_SUCCESS);
            have = true;
            for (int k = 0; k < pipe.channel_count; k++) {
                exr_coding_channel_info_t *c = &pipe.channels[k];
                const float *plane = planes + (size_t)(strchr(names, c->channel_name[0]) - names) * (size_t)(w * h);
                c->user_bytes_per_element = 4;
                c->user_data_type = EXR_PIXEL_FLOAT;
                c->user_pixel_stride = 4;
                c->user_line_stride = w * 4;
                c->encode_from_ptr = (const uint8_t *)(plane + (size_t)(ty * th) * (size_t)w + (size_t)(tx * tw));
            }
            REQUIRE(exr_encoding_choose_default_routines(e, part, &pipe) == EXR_ERR_SUCCESS);
            REQUIRE(exr_encoding_run(e, part, &pipe) == EXR_ERR_SUCCESS);
        }
    if (have) exr_encoding_destroy(e, &pipe);
    REQUIRE(exr_finish(&e) == EXR_ERR_SUCCESS);
    free(planes);
}

/* Tiled, HALF, RGBA: four channels stored A, B, G, R in the file, read back
 * in RGBA order (OpenEXR 3.1's interleaving routines would swap them). */
static void test_exr_tiled(void)
{
    const int w = 10, h = 7;
    float px[10 * 7 * 4];
    for (int i = 0; i < w * h; i++) {
        px[4 * i] = (float)i * 0.25f;
        px[4 * i + 1] = (float)i * 0.5f;
        px[4 * i + 2] = -(float)i;
        px[4 * i + 3] = (float)(i % 5) * 0.125f;
    }
    char path[] = "/tmp/pk_image_read_XXXXXX";
    int fd = mkstemp(path);
    REQUIRE(fd >= 0);
    close(fd);
    write_tiled_exr(path, w, h, 4, 3, px);
    image_buf img;
    REQUIRE(image_read_file(ctx, path, &img) == PK_OK);
    unlink(path);
    CHECK(img.w == w && img.h == h && img.nc == 4 && img.pxf);
    for (int i = 0; img.pxf && i < w * h * 4; i++)
        if (img.pxf[i] != px[i]) {
            CHECKF(false, "sample %d (x %d y %d c %d): %g, want %g", i, (i / 4) % w, (i / 4) / w, i % 4,
                   (double)img.pxf[i], (double)px[i]);
            break;
        }
    image_buf_free(&ctx->alloc, &img);
}

/* ---- Radiance .hdr ------------------------------------------------------------- */

static float rgbe_value(int m, int e) { return e == 0 ? 0.0f : ((float)m + 0.5f) * ldexpf(1.0f, e - 136); }

static void test_hdr(void)
{
    /* flat: 3x2, one old-style repeat */
    unsigned char flat[256];
    int k = sprintf((char *)flat, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 3\n");
    const unsigned char pix[] = {128, 64, 32, 129, 10, 20, 30, 128, 1, 1, 1, 1, /* row 0: p, q, q */
                                 0, 0, 0, 0, 255, 255, 255, 130, 1, 2, 3, 127};
    memcpy(flat + k, pix, sizeof pix);
    size_t n = (size_t)k + sizeof pix;
    image_buf img;
    REQUIRE(image_decode(ctx, flat, n, "flat.hdr", &img) == PK_OK);
    CHECK(img.w == 3 && img.h == 2 && img.nc == 3 && img.pxf);
    if (img.pxf) {
        CHECK(img.pxf[0] == rgbe_value(128, 129) && img.pxf[1] == rgbe_value(64, 129));
        CHECK(img.pxf[3] == rgbe_value(10, 128) && img.pxf[6] == rgbe_value(10, 128) && img.pxf[8] == rgbe_value(30, 128));
        CHECK(img.pxf[9] == 0.0f && img.pxf[12] == rgbe_value(255, 130) && img.pxf[17] == rgbe_value(3, 127));
    }
    image_buf_free(&ctx->alloc, &img);
    for (size_t cut = 0; cut < n; cut++) {
        CHECK(image_decode_hdr(ctx, flat, cut, "cut.hdr", &img) == (cut < n ? PK_ERR_PARSE : PK_OK));
        reset();
    }

    /* adaptive RLE: width 10, one row, each channel a run and literals */
    unsigned char rle[256];
    k = sprintf((char *)rle, "#?RGBE\n\n+Y 1 +X 10\n");
    const unsigned char line[] = {2, 2, 0, 10,
                                  128 + 10, 50,               /* R: a run of 10 */
                                  10, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, /* G: 10 literals */
                                  128 + 5, 7, 5, 1, 1, 1, 1, 1, /* B: run of 5, 5 literals */
                                  128 + 10, 128};              /* E: all 128 */
    memcpy(rle + k, line, sizeof line);
    n = (size_t)k + sizeof line;
    REQUIRE(image_decode(ctx, rle, n, "rle.hdr", &img) == PK_OK);
    CHECK(img.w == 10 && img.h == 1);
    if (img.pxf) {
        CHECK(img.pxf[0] == rgbe_value(50, 128) && img.pxf[27] == rgbe_value(50, 128));
        CHECK(img.pxf[3 * 4 + 1] == rgbe_value(4, 128) && img.pxf[3 * 9 + 1] == rgbe_value(9, 128));
        CHECK(img.pxf[2] == rgbe_value(7, 128) && img.pxf[3 * 9 + 2] == rgbe_value(1, 128));
    }
    image_buf_free(&ctx->alloc, &img);
    /* a run past the end of the line */
    rle[k + 4] = 128 + 11;
    CHECK(image_decode(ctx, rle, n, "long.hdr", &img) == PK_ERR_PARSE);
    reset();
    /* not RGBE */
    const char *xyz = "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\x80\x80\x80\x80";
    CHECK(image_decode(ctx, xyz, strlen(xyz), "xyz.hdr", &img) == PK_ERR_UNSUPPORTED);
    reset();
    /* huge size in a tiny file */
    const char *big = "#?RADIANCE\n\n-Y 100000 +X 100000\n";
    CHECK(image_decode(ctx, big, strlen(big), "big.hdr", &img) == PK_ERR_LIMIT);
    reset();
}

/* ---- PFM ------------------------------------------------------------------------- */

static void put_f32(unsigned char *b, float f, bool little)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    for (int i = 0; i < 4; i++) b[little ? i : 3 - i] = (unsigned char)(u >> (8 * i));
}

static void test_pfm(void)
{
    for (int little = 0; little < 2; little++) {
        unsigned char buf[256];
        int k = sprintf((char *)buf, "PF\n2 2\n%s\n", little ? "-1.0" : "1.0");
        /* rows bottom to top in the file */
        for (int i = 0; i < 12; i++) put_f32(buf + k + 4 * i, (float)i + 0.5f, little);
        size_t n = (size_t)k + 48;
        image_buf img;
        REQUIRE(image_decode(ctx, buf, n, "a.pfm", &img) == PK_OK);
        CHECK(img.w == 2 && img.h == 2 && img.nc == 3 && img.pxf);
        if (img.pxf) {
            CHECK(img.pxf[0] == 6.5f && img.pxf[5] == 11.5f); /* top row = the file's last */
            CHECK(img.pxf[6] == 0.5f && img.pxf[11] == 5.5f);
        }
        image_buf_free(&ctx->alloc, &img);
        CHECK(image_decode(ctx, buf, n - 1, "short.pfm", &img) == PK_ERR_PARSE);
        CHECK(strstr(pk_context_error(ctx), "short.pfm") != NULL);
        reset();
    }
    /* NaN and infinity become 0 */
    unsigned char buf[64];
    int k = sprintf((char *)buf, "Pf\n2 1\n-1\n");
    put_f32(buf + k, NAN, true);
    put_f32(buf + k + 4, INFINITY, true);
    image_buf img;
    REQUIRE(image_decode(ctx, buf, (size_t)k + 8, "nan.pfm", &img) == PK_OK);
    CHECK(img.nc == 1 && img.pxf && img.pxf[0] == 0.0f && img.pxf[1] == 0.0f);
    image_buf_free(&ctx->alloc, &img);
    const char *bad = "PF\n-3 2\n1\n";
    CHECK(image_decode(ctx, bad, strlen(bad), "neg.pfm", &img) == PK_ERR_PARSE);
    reset();
    CHECK(image_decode(ctx, "GIF89a", 6, "x.gif", &img) == PK_ERR_UNSUPPORTED);
    CHECK(strstr(pk_context_error(ctx), "x.gif") != NULL);
    reset();
}

/* ---- sRGB and image_load_rgb ------------------------------------------------------- */

static void test_srgb_and_load(void)
{
    for (int i = 0; i < 256; i++) {
        double c = i / 255.0;
        double lin = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
        CHECK_NEAR(image_srgb_to_linear[i], lin, 1e-6 * (lin + 1e-3));
    }
    CHECK(image_srgb_to_linear[0] == 0.0f && image_srgb_to_linear[255] == 1.0f);

    unsigned char g[6] = {0, 128, 255, 64, 10, 200};
    size_t n;
    unsigned char *buf = png_encode(g, 3, 2, PNG_FORMAT_GRAY, &n);
    char path[] = "/tmp/pk_image_read_XXXXXX";
    int fd = mkstemp(path);
    REQUIRE(fd >= 0 && write(fd, buf, n) == (ssize_t)n);
    close(fd);
    free(buf);
    int w, h;
    float *rgb;
    REQUIRE(image_load_rgb(ctx, path, &w, &h, &rgb) == PK_OK);
    CHECK(w == 3 && h == 2);
    for (int i = 0; i < 6; i++)
        for (int c = 0; c < 3; c++) CHECK(rgb[3 * i + c] == image_srgb_to_linear[g[i]]);
    mem_free(&ctx->alloc, rgb);
    unlink(path);
    CHECK(image_load_rgb(ctx, path, &w, &h, &rgb) == PK_ERR_IO);
    CHECK(rgb == NULL && strstr(pk_context_error(ctx), path) != NULL);
    reset();
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_png();
    test_jpeg();
    test_exr();
    test_exr_incompressible_chunks();
    test_exr_tiled();
    test_hdr();
    test_pfm();
    test_srgb_and_load();
    pk_context_destroy(ctx);
    return test_done("test_image_read");
}

/*
 * test_image_write.c - the image writers. OpenEXR: what pk_image_write puts
 * in a .exr file is read back with OpenEXR's own C API (exr_start_read and
 * the decode pipeline) and must be the image bit for bit: size, channel
 * names and types, every sample (special values included); the internal
 * exr_write_channels writes extra named layers the same way; a write into a
 * missing folder fails with "path: ..." and leaves no file. PNG: a known
 * linear value at exposure +1 and -1 EV gives the expected 8-bit value; an
 * exposure out of range is refused and writes nothing; HDR outputs ignore
 * the exposure.
 */
#include "test.h"

#include "paprsek.h"
#include "image/image_write.h"

#include <dirent.h>
#include <fcntl.h>
#include <openexr.h>
#include <png.h>
#include <stdint.h>
#include <sys/stat.h>

static pk_context *ctx;
static char dir[] = "/tmp/pk_image_write_XXXXXX";

/* Files in dir (the temporary files of the writers included). */
static int count_files(void)
{
    int n = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.') n++;
    if (d) closedir(d);
    return n;
}

/* ---- reading an EXR back ---------------------------------------------------- */

#define MAXCH 8

typedef struct exr_read {
    int width, height, nch;
    char names[MAXCH][32]; /* in the file's order (sorted by name) */
    int types[MAXCH];
    float *planes[MAXCH];  /* width * height samples each, rows top to bottom */
    int compression, storage;
} exr_read;

static void report_exr_error(exr_const_context_t c, exr_result_t code, const char *msg)
{
    (void)c;
    fprintf(stderr, "OpenEXR (reading): %d %s\n", (int)code, msg);
}

/* 0 on success. */
static int read_exr(const char *path, exr_read *r)
{
    memset(r, 0, sizeof *r);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = report_exr_error;
    exr_context_t e = NULL;
    if (exr_start_read(&e, path, &init) != EXR_ERR_SUCCESS) return -1;
    int rc = -1, parts = 0;
    exr_storage_t storage;
    exr_compression_t comp;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    if (exr_get_count(e, &parts) || parts != 1 || exr_get_storage(e, 0, &storage) ||
        exr_get_compression(e, 0, &comp) || exr_get_data_window(e, 0, &dw) || exr_get_channels(e, 0, &chl) ||
        chl->num_channels > MAXCH)
        goto out;
    r->storage = (int)storage;
    r->compression = (int)comp;
    r->width = dw.max.x - dw.min.x + 1;
    r->height = dw.max.y - dw.min.y + 1;
    r->nch = chl->num_channels;
    for (int c = 0; c < r->nch; c++) {
        snprintf(r->names[c], sizeof r->names[c], "%s", chl->entries[c].name.str);
        r->types[c] = (int)chl->entries[c].pixel_type;
        r->planes[c] = calloc((size_t)r->width * (size_t)r->height, sizeof(float));
        if (!r->planes[c]) goto out;
    }
    int32_t lines = 0;
    if (exr_get_scanlines_per_chunk(e, 0, &lines) || lines <= 0) goto out;
    exr_decode_pipeline_t dec;
    memset(&dec, 0, sizeof dec);
    int have = 0;
    exr_result_t rv = EXR_ERR_SUCCESS;
    for (int y = dw.min.y; y <= dw.max.y && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_read_scanline_chunk_info(e, 0, y, &ci);
        if (rv) break;
        rv = have ? exr_decoding_update(e, 0, &ci, &dec) : exr_decoding_initialize(e, 0, &ci, &dec);
        if (rv) break;
        for (int c = 0; c < dec.channel_count; c++) {
            int k = 0;
            while (k < r->nch && strcmp(r->names[k], dec.channels[c].channel_name) != 0) k++;
            if (k == r->nch) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            dec.channels[c].user_bytes_per_element = 4;
            dec.channels[c].user_data_type = EXR_PIXEL_FLOAT;
            dec.channels[c].user_pixel_stride = 4;
            dec.channels[c].user_line_stride = 4 * r->width;
            dec.channels[c].decode_to_ptr =
                (uint8_t *)(r->planes[k] + (size_t)(ci.start_y - dw.min.y) * (size_t)r->width);
        }
        if (rv) break;
        if (!have) rv = exr_decoding_choose_default_routines(e, 0, &dec);
        have = 1;
        if (!rv) rv = exr_decoding_run(e, 0, &dec);
    }
    if (have) exr_decoding_destroy(e, &dec);
    if (rv == EXR_ERR_SUCCESS) rc = 0;
out:
    exr_finish(&e);
    return rc;
}

static void free_read(exr_read *r)
{
    for (int c = 0; c < MAXCH; c++) free(r->planes[c]);
}

static uint32_t bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

static float from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* A w x h image of values that differ in every bit position, with the
 * special ones a renderer may leave: negative zero, denormals, values
 * beyond half's range, infinity, NaN. */
static pk_image *test_image(int w, int h)
{
    pk_image *img = NULL;
    REQUIRE(pk_image_create(ctx, w, h, &img) == PK_OK);
    float *px = pk_image_pixels(img);
    uint32_t s = 12345;
    for (int i = 0; i < 3 * w * h; i++) {
        s = s * 1664525u + 1013904223u;
        px[i] = (float)(s >> 8) / (float)(1 << 24) * 4.0f;
    }
    const float special[] = {-0.0f, 1e-40f, from_bits(1), 65504.0f, 1e30f, -3.5f, INFINITY, from_bits(0x7fc01234)};
    for (size_t i = 0; i < sizeof special / sizeof special[0] && i * 7 < (size_t)(3 * w * h); i++)
        px[i * 7] = special[i];
    return img;
}

static void test_exr_round_trip(void)
{
    /* 37 x 23: not a whole number of 16-line chunks */
    const int w = 37, h = 23;
    pk_image *img = test_image(w, h);
    char path[256];
    snprintf(path, sizeof path, "%s/rt.EXR", dir);
    /* an existing file is replaced */
    FILE *f = fopen(path, "w");
    REQUIRE(f);
    fputs("old", f);
    fclose(f);
    CHECKF(pk_image_write(ctx, img, path) == PK_OK, "%s", pk_context_error(ctx));
    unsigned char magic[4] = {0};
    f = fopen(path, "rb");
    REQUIRE(f);
    CHECK(fread(magic, 1, 4, f) == 4);
    fclose(f);
    CHECK(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01);

    exr_read r;
    REQUIRE(read_exr(path, &r) == 0);
    CHECK(r.width == w && r.height == h);
    CHECK(r.storage == EXR_STORAGE_SCANLINE);
    CHECK(r.compression == EXR_COMPRESSION_ZIP);
    CHECK(r.nch == 3);
    CHECK(strcmp(r.names[0], "B") == 0 && strcmp(r.names[1], "G") == 0 && strcmp(r.names[2], "R") == 0);
    for (int c = 0; c < r.nch; c++) CHECK(r.types[c] == EXR_PIXEL_FLOAT);
    const float *px = pk_image_pixels_const(img);
    long bad = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                /* file channel 2 - c: B, G, R */
                float want = px[((size_t)y * w + x) * 3 + c];
                float got = r.planes[2 - c][(size_t)y * w + x];
                if (bits(want) != bits(got)) {
                    if (bad++ < 5) fprintf(stderr, "pixel %d,%d channel %d: %08x, wanted %08x\n", x, y, c,
                                           (unsigned)bits(got), (unsigned)bits(want));
                }
            }
    CHECKF(bad == 0, "%ld samples differ", bad);
    free_read(&r);

    /* exposure does not touch HDR output */
    pk_write_options wo;
    pk_write_options_init(&wo);
    wo.exposure_ev = 3.0f;
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_OK);
    REQUIRE(read_exr(path, &r) == 0);
    CHECK(bits(r.planes[2][5]) == bits(px[15]) && bits(r.planes[1][0]) == bits(px[1]));
    free_read(&r);
    CHECK(count_files() == 1);
    remove(path);
    pk_image_destroy(img);
}

/* exr_write_channels with layers beside the RGB: the AOV case. */
static void test_exr_layers(void)
{
    const int w = 9, h = 40;
    float *rgb = malloc(sizeof(float) * 3 * w * h), *depth = malloc(sizeof(float) * w * h);
    float *albedo = malloc(sizeof(float) * 3 * w * h);
    REQUIRE(rgb && depth && albedo);
    for (int i = 0; i < 3 * w * h; i++) {
        rgb[i] = (float)i * 0.25f;
        albedo[i] = 1.0f / (float)(i + 1);
    }
    for (int i = 0; i < w * h; i++) depth[i] = 100.0f + (float)i;
    const size_t row = (size_t)w * 3;
    const exr_channel ch[] = {
        {"R", rgb, 3, row},          {"G", rgb + 1, 3, row},        {"B", rgb + 2, 3, row},
        {"depth.Z", depth, 1, (size_t)w}, {"albedo.R", albedo, 3, row}, {"albedo.G", albedo + 1, 3, row},
        {"albedo.B", albedo + 2, 3, row},
    };
    const int n = (int)(sizeof ch / sizeof ch[0]);
    char path[256];
    snprintf(path, sizeof path, "%s/layers.exr", dir);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    REQUIRE(fd >= 0);
    char why[256] = "";
    CHECKF(exr_write_channels(fd, w, h, ch, n, why, sizeof why) == 0, "%s", why);
    close(fd);
    exr_read r;
    REQUIRE(read_exr(path, &r) == 0);
    CHECK(r.width == w && r.height == h && r.nch == n);
    const char *sorted[] = {"B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z"};
    for (int k = 0; k < r.nch && k < n; k++) {
        CHECKF(strcmp(r.names[k], sorted[k]) == 0, "channel %d is %s", k, r.names[k]);
        const exr_channel *in = NULL;
        for (int c = 0; c < n; c++)
            if (strcmp(ch[c].name, r.names[k]) == 0) in = &ch[c];
        REQUIRE(in);
        long bad = 0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                if (bits(in->data[y * in->row_stride + x * in->pixel_stride]) != bits(r.planes[k][y * w + x])) bad++;
        CHECKF(bad == 0, "%s: %ld samples differ", r.names[k], bad);
    }
    free_read(&r);
    /* a device that takes nothing: the write callback's error comes back */
    fd = open("/dev/full", O_WRONLY);
    if (fd >= 0) {
        why[0] = '\0';
        CHECK(exr_write_channels(fd, w, h, ch, n, why, sizeof why) == -1);
        CHECKF(strncmp(why, "write error: ", 13) == 0, "%s", why);
        printf("/dev/full: %s\n", why);
        close(fd);
    }
    /* refused: no channels */
    CHECK(exr_write_channels(-1, w, h, ch, 0, why, sizeof why) == -1 && why[0]);
    remove(path);
    free(rgb);
    free(depth);
    free(albedo);
}

static void test_exr_missing_folder(void)
{
    pk_image *img = test_image(4, 4);
    char path[300];
    snprintf(path, sizeof path, "%s/missing/out.exr", dir);
    pk_context_clear_error(ctx);
    CHECK(pk_image_write(ctx, img, path) == PK_ERR_IO);
    char want[400];
    snprintf(want, sizeof want, "%s: cannot create a temporary file beside it: No such file or directory", path);
    CHECKF(strcmp(pk_context_error(ctx), want) == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    struct stat sb;
    CHECK(stat(path, &sb) != 0);
    CHECK(count_files() == 0);
    pk_image_destroy(img);
}

/* ---- PNG exposure ------------------------------------------------------------ */

/* The first pixel's red byte of a PNG written from a 2x1 image whose pixels
 * are all v, at exposure ev; -1 when it cannot be read. */
static int png_first_byte(float v, float ev)
{
    pk_image *img = NULL;
    REQUIRE(pk_image_create(ctx, 2, 1, &img) == PK_OK);
    float *px = pk_image_pixels(img);
    for (int i = 0; i < 6; i++) px[i] = v;
    char path[256];
    snprintf(path, sizeof path, "%s/e.png", dir);
    pk_write_options wo;
    pk_write_options_init(&wo);
    wo.exposure_ev = ev;
    int out = -1;
    if (pk_image_write_ex(ctx, img, path, &wo) == PK_OK) {
        png_image pi;
        memset(&pi, 0, sizeof pi);
        pi.version = PNG_IMAGE_VERSION;
        unsigned char buf[2 * 3];
        if (png_image_begin_read_from_file(&pi, path)) {
            pi.format = PNG_FORMAT_RGB;
            if (pi.width == 2 && pi.height == 1 && png_image_finish_read(&pi, NULL, buf, 0, NULL)) out = buf[0];
            png_image_free(&pi);
        }
    } else {
        fprintf(stderr, "%s\n", pk_context_error(ctx));
    }
    remove(path);
    pk_image_destroy(img);
    return out;
}

static void test_png_exposure(void)
{
    pk_write_options wo;
    memset(&wo, 0xff, sizeof wo);
    pk_write_options_init(&wo);
    CHECK(wo.exposure_ev == 0.0f);
    /* sRGB(0.5) = 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357..., * 255 = 187.52 -> 188
     * sRGB(0.25) = 0.537099..., * 255 = 136.96 -> 137 */
    CHECK(png_first_byte(0.5f, 0.0f) == 188);
    CHECK(png_first_byte(0.25f, 1.0f) == 188);  /* 0.25 * 2 = 0.5 */
    CHECK(png_first_byte(0.5f, -1.0f) == 137);  /* 0.5 / 2 = 0.25 */
    CHECK(png_first_byte(0.25f, 0.0f) == 137);
    CHECK(png_first_byte(0.6f, 1.0f) == 255);   /* 1.2: clipped */
    CHECK(png_first_byte(1.0f / 1024.0f, 10.0f) == 255);
    CHECK(png_first_byte(4096.0f, -12.0f) == 255);
    CHECK(png_first_byte(4096.0f, -13.0f) == 188);
    CHECK(srgb_encode(0.5f) == 188 && srgb_encode(0.25f) == 137);

    /* out of range: refused, nothing written */
    pk_image *img = NULL;
    REQUIRE(pk_image_create(ctx, 2, 2, &img) == PK_OK);
    char path[256];
    snprintf(path, sizeof path, "%s/bad.png", dir);
    const float bad[] = {20.5f, -21.0f, NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pk_context_clear_error(ctx);
        pk_write_options_init(&wo);
        wo.exposure_ev = bad[i];
        CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
        CHECKF(strncmp(pk_context_error(ctx), path, strlen(path)) == 0 && strstr(pk_context_error(ctx), "-20..20"),
               "%s", pk_context_error(ctx));
    }
    pk_context_clear_error(ctx);
    wo.exposure_ev = 20.0f;
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_OK);
    wo.exposure_ev = -20.0f;
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_OK);
    CHECK(pk_image_write_ex(ctx, img, path, NULL) == PK_OK);
    CHECK(pk_image_write_ex(NULL, img, path, NULL) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_image_write_ex(ctx, NULL, path, NULL) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_image_write_ex(ctx, img, NULL, NULL) == PK_ERR_INVALID_ARGUMENT);
    remove(path);
    CHECK(count_files() == 0);
    pk_image_destroy(img);
}

/* pk_image_write_ex with layers: the image's R, G, B and each layer's
 * NAME.R/G/B, bit for bit; layers are refused for other formats, for another
 * size and for a repeated name, and nothing is written then. */
static void test_write_layers(void)
{
    pk_image *img = NULL, *lay = NULL, *small = NULL;
    REQUIRE(pk_image_create(ctx, 5, 3, &img) == PK_OK && pk_image_create(ctx, 5, 3, &lay) == PK_OK &&
            pk_image_create(ctx, 4, 3, &small) == PK_OK);
    for (int i = 0; i < 45; i++) {
        pk_image_pixels(img)[i] = (float)i + 0.5f;
        pk_image_pixels(lay)[i] = -1.0f / (float)(i + 1);
    }
    char path[256];
    snprintf(path, sizeof path, "%s/with_layers.exr", dir);
    const pk_image *layers[2] = {lay, lay};
    const char *names[2] = {"normal", "normal"};
    pk_write_options wo;
    pk_write_options_init(&wo);
    wo.nlayers = 1;
    wo.layers = layers;
    wo.layer_names = names;
    REQUIRE(pk_image_write_ex(ctx, img, path, &wo) == PK_OK);
    exr_read r;
    REQUIRE(read_exr(path, &r) == 0);
    const char *sorted[] = {"B", "G", "R", "normal.B", "normal.G", "normal.R"};
    CHECK(r.nch == 6);
    for (int k = 0; k < r.nch && k < 6; k++) {
        CHECKF(strcmp(r.names[k], sorted[k]) == 0, "channel %d is %s", k, r.names[k]);
        const pk_image *src = k < 3 ? img : lay;
        const int c = 2 - k % 3; /* B, G, R */
        long bad = 0;
        for (int i = 0; i < 15; i++)
            if (bits(pk_image_pixels_const(src)[3 * i + c]) != bits(r.planes[k][i])) bad++;
        CHECKF(bad == 0, "%s: %ld samples differ", r.names[k], bad);
    }
    free_read(&r);
    remove(path);
    /* refusals */
    const int before = count_files();
    snprintf(path, sizeof path, "%s/layers.png", dir);
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "layers are written to .exr files only") != NULL);
    pk_context_clear_error(ctx);
    snprintf(path, sizeof path, "%s/bad.exr", dir);
    wo.nlayers = 2;
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "two layers named 'normal'") != NULL);
    pk_context_clear_error(ctx);
    layers[1] = small;
    names[1] = "depth";
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "layer 1 is not a 5x3 image") != NULL);
    pk_context_clear_error(ctx);
    CHECK(count_files() == before);
    pk_image_destroy(img), pk_image_destroy(lay), pk_image_destroy(small);
}

/* ---- alpha (coverage) --------------------------------------------------------- */

/* A 4x1 premultiplied image with coverage 0, 0.25, 0.5, 1: the PNG is RGBA
 * with alpha round(255 a) and colour un-premultiplied (c / a, sRGB-encoded);
 * the EXR has A beside R, G, B, all bit for bit (colour still premultiplied);
 * PFM refuses alpha and writes nothing; an alpha of another size is refused. */
static void test_alpha(void)
{
    pk_image *img = NULL, *al = NULL, *small = NULL;
    REQUIRE(pk_image_create(ctx, 4, 1, &img) == PK_OK && pk_image_create(ctx, 4, 1, &al) == PK_OK &&
            pk_image_create(ctx, 3, 1, &small) == PK_OK);
    const float a[4] = {0.0f, 0.25f, 0.5f, 1.0f}, c[4] = {0.0f, 0.1f, 0.2f, 0.3f}; /* c = straight 0.4 * a, 0.3 */
    float *px = pk_image_pixels(img), *pa = pk_image_pixels(al);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) px[3 * i + k] = c[i], pa[3 * i + k] = a[i];
    pk_write_options wo;
    pk_write_options_init(&wo);
    wo.alpha = al;
    char path[256];
    snprintf(path, sizeof path, "%s/a.png", dir);
    REQUIRE(pk_image_write_ex(ctx, img, path, &wo) == PK_OK);
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    unsigned char buf[4 * 4];
    REQUIRE(png_image_begin_read_from_file(&pi, path));
    CHECK(pi.format & PNG_FORMAT_FLAG_ALPHA);
    pi.format = PNG_FORMAT_RGBA;
    REQUIRE(pi.width == 4 && pi.height == 1 && png_image_finish_read(&pi, NULL, buf, 0, NULL));
    for (int i = 0; i < 4; i++) {
        CHECKF(buf[4 * i + 3] == (int)floor(255.0 * (double)a[i] + 0.5), "pixel %d alpha %d", i, buf[4 * i + 3]);
        const double straight = a[i] > 0.0f ? (i == 3 ? 0.3 : 0.4) : 0.0;
        const double s = straight <= 0.0031308 ? 12.92 * straight : 1.055 * pow(straight, 1.0 / 2.4) - 0.055;
        CHECKF(buf[4 * i] == (int)floor(255.0 * s + 0.5), "pixel %d red %d, expected %.2f", i, buf[4 * i], 255.0 * s);
    }
    remove(path);
    snprintf(path, sizeof path, "%s/a.exr", dir);
    REQUIRE(pk_image_write_ex(ctx, img, path, &wo) == PK_OK);
    exr_read r;
    REQUIRE(read_exr(path, &r) == 0);
    CHECK(r.nch == 4);
    for (int ch = 0; ch < r.nch; ch++) {
        const int is_a = strcmp(r.names[ch], "A") == 0;
        CHECK(is_a || strlen(r.names[ch]) == 1);
        for (int i = 0; i < 4; i++) CHECK(bits(r.planes[ch][i]) == bits(is_a ? a[i] : c[i]));
    }
    CHECK(strcmp(r.names[0], "A") == 0); /* sorted: A, B, G, R */
    free_read(&r);
    remove(path);
    snprintf(path, sizeof path, "%s/a.pfm", dir);
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "alpha") != NULL);
    CHECK(access(path, F_OK) != 0);
    wo.alpha = small;
    snprintf(path, sizeof path, "%s/b.png", dir);
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
    CHECK(access(path, F_OK) != 0);
    wo.alpha = NULL;
    wo.tonemap = PK_TONEMAP_COUNT;
    CHECK(pk_image_write_ex(ctx, img, path, &wo) == PK_ERR_INVALID_ARGUMENT);
    CHECK(access(path, F_OK) != 0);
    pk_image_destroy(img);
    pk_image_destroy(al);
    pk_image_destroy(small);
}

int main(void)
{
    REQUIRE(mkdtemp(dir));
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_exr_round_trip();
    test_exr_layers();
    test_write_layers();
    test_exr_missing_folder();
    test_png_exposure();
    test_alpha();
    pk_context_destroy(ctx);
    rmdir(dir);
    return test_done("test_image_write");
}

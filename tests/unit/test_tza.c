/*
 * test_tza.c - the denoiser's file handling: SHA-256 against FIPS 180-4's
 * examples, binary16 widening, the tensor archive reader on good, corrupt
 * and truncated archives (one message each, never a read outside), the
 * U-Net's shape checks, and the library's answers to missing and foreign
 * weights files and to bad pixels.
 */
#include "test.h"

#include "denoise/denoise.h"
#include "denoise/sha256.h"
#include "denoise/tza.h"
#include "denoise/unet.h"
#include "denoise/tza_build.h"
#include "warnings.h"

#include <stdbool.h>

static void check_sha256(void)
{
    char hex[65];
    sha256_hex("", 0, hex);
    CHECK(strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855") == 0);
    sha256_hex("abc", 3, hex);
    CHECK(strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad") == 0);
    const char *two = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"; /* 56 bytes: padding spills */
    sha256_hex(two, strlen(two), hex);
    CHECK(strcmp(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1") == 0);
    char *mil = malloc(1000000);
    memset(mil, 'a', 1000000);
    sha256_hex(mil, 1000000, hex);
    CHECK(strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0") == 0);
    /* the SHA-extension path (where the CPU has it) against plain C, every tail length */
    for (size_t n = 0; n < 1000000; n = n < 300 ? n + 1 : n * 3) {
        for (size_t i = 0; i < n; i++) mil[i] = (char)(i * 2654435761u >> 13);
        char fast[65], slow[65];
        sha256_hex(mil, n, fast);
        sha256_hex_portable(mil, n, slow);
        CHECKF(strcmp(fast, slow) == 0, "SHA-256 of %zu bytes: %s against %s", n, fast, slow);
    }
    free(mil);
}

static void check_half(pk_context *ctx)
{
    const uint16_t h[] = {0x3c00, 0xc000, 0x0001, 0x03ff, 0x0400, 0x7bff, 0x7c00, 0x8000, 0x3555};
    const float want[] = {1.0f, -2.0f, 5.9604645e-8f, 6.0975552e-5f, 6.1035156e-5f, 65504.0f, INFINITY, -0.0f,
                          0.33325195f};
    const uint32_t d[1] = {9};
    tzab b;
    tzab_begin(&b);
    tzab_tensor(&b, "h", 1, d, "x", h);
    size_t n;
    unsigned char *data = tzab_end(&b, &n);
    tza_archive a;
    REQUIRE(tza_parse(ctx, "h.tza", data, n, &a) == PK_OK);
    const tza_tensor *t = tza_find(&a, "h");
    REQUIRE(t && t->count == 9 && t->ndims == 1 && strcmp(t->layout, "x") == 0);
    for (int i = 0; i < 9; i++) CHECKF(tza_get(t, (size_t)i) == want[i], "half %04x -> %g", h[i], (double)tza_get(t, (size_t)i));
    CHECK(signbit(tza_get(t, 7)));
    CHECK(tza_find(&a, "nothing") == NULL);
    tza_free(&ctx->alloc, &a);
    free(data);
}

/* Parses data expecting failure status st with a message holding what. */
static void expect_bad(const unsigned char *data, size_t n, pk_status st, const char *what)
{
    pk_context *ctx;
    pk_context_create(NULL, &ctx);
    tza_archive a;
    pk_status got = tza_parse(ctx, "bad.tza", data, n, &a);
    CHECKF(got == st, "%s: status %d, wanted %d (%s)", what, (int)got, (int)st, pk_context_error(ctx));
    CHECKF(strstr(pk_context_error(ctx), what) != NULL, "message '%s' lacks '%s'", pk_context_error(ctx), what);
    CHECK(strncmp(pk_context_error(ctx), "bad.tza", 7) == 0);
    if (got == PK_OK) tza_free(&ctx->alloc, &a);
    pk_context_destroy(ctx);
}

static void check_corrupt(pk_context *ctx)
{
    size_t n;
    unsigned char *good = tzab_unet(9, &n);
    tza_archive a;
    REQUIRE(tza_parse(ctx, "unet.tza", good, n, &a) == PK_OK);
    CHECK(a.n == 32);
    unet *u = NULL;
    REQUIRE(unet_create(ctx, "unet.tza", &a, &u) == PK_OK);
    CHECK(unet_input_channels(u) == 9);
    /* 16 layers of 16 channels: flops of a 16x16 pass, counted by hand */
    double fl = 0;
    const int ic[16] = {9, 16, 16, 16, 16, 16, 16, 32, 16, 32, 16, 32, 16, 25, 16, 16}, lv[16] = {0, 0, 1, 2, 3, 4, 4, 3, 3, 2, 2, 1, 1, 0, 0, 0};
    for (int k = 0; k < 16; k++) fl += 2.0 * 9 * ic[k] * (k == 15 ? 3 : 16) * (double)((16 >> lv[k]) * (16 >> lv[k]));
    CHECK(unet_flops(u, 16, 16) == fl);
    unet_destroy(u);
    tza_free(&ctx->alloc, &a);

    /* every truncation fails cleanly (the table is at the end) */
    for (size_t k = 0; k < n; k += (k < 64 ? 1 : 97)) {
        pk_context *c;
        pk_context_create(NULL, &c);
        unsigned char *cut = malloc(k ? k : 1);
        memcpy(cut, good, k);
        CHECKF(tza_parse(c, "cut.tza", cut, k, &a) == PK_ERR_PARSE, "truncated at %zu parsed", k);
        CHECK(pk_context_error(c)[0] != '\0');
        free(cut);
        pk_context_destroy(c);
    }
    unsigned char *bad = malloc(n);
    memcpy(bad, good, n);
    bad[0] ^= 1;
    expect_bad(bad, n, PK_ERR_PARSE, "wrong magic");
    memcpy(bad, good, n);
    bad[2] = 3;
    expect_bad(bad, n, PK_ERR_UNSUPPORTED, "version 3.0");
    memcpy(bad, good, n);
    tzab_u(bad + 4, n + 10, 8);
    expect_bad(bad, n, PK_ERR_PARSE, "table offset");
    /* the first tensor's record: name length, name, ndims, dims, layout, dtype, offset */
    uint64_t table = 0;
    for (int i = 0; i < 8; i++) table |= (uint64_t)good[4 + i] << (8 * i);
    const size_t rec = (size_t)table + 4, name_len = good[rec], nd_at = rec + 2 + name_len;
    memcpy(bad, good, n);
    bad[nd_at] = 5;
    expect_bad(bad, n, PK_ERR_PARSE, "more than four");
    memcpy(bad, good, n);
    tzab_u(bad + nd_at + 1, 0, 4);
    expect_bad(bad, n, PK_ERR_PARSE, "dimension is zero");
    memcpy(bad, good, n);
    bad[nd_at + 1 + 16 + 4] = 'q';
    expect_bad(bad, n, PK_ERR_UNSUPPORTED, "data type 'q'");
    memcpy(bad, good, n);
    tzab_u(bad + nd_at + 1 + 16 + 4 + 1, n - 8, 8);
    expect_bad(bad, n, PK_ERR_PARSE, "outside the file");
    memcpy(bad, good, n);
    memcpy(bad + rec + 2, "enc_conv1.weight", 16); /* "enc_conv0.weight" renamed to the second's name */
    expect_bad(bad, n, PK_ERR_PARSE, "appears twice");
    free(bad);
    free(good);

    /* a U-Net of the wrong shape: a layer missing, a channel count off */
    tzab b;
    tzab_begin(&b);
    const uint32_t d[4] = {16, 3, 3, 3};
    uint16_t *zeros = calloc(16 * 3 * 9, 2);
    tzab_tensor(&b, "enc_conv0.weight", 4, d, "oihw", zeros);
    free(zeros);
    unsigned char *one = tzab_end(&b, &n);
    REQUIRE(tza_parse(ctx, "one.tza", one, n, &a) == PK_OK);
    CHECK(unet_create(ctx, "one.tza", &a, &u) == PK_ERR_UNSUPPORTED);
    CHECKF(strstr(pk_context_error(ctx), "no tensor enc_conv0.bias") != NULL, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    tza_free(&ctx->alloc, &a);
    free(one);
}

/* The library's answers to weights that are missing or not OIDN's. */
static void check_weights_files(void)
{
    pk_context *ctx;
    pk_context_create(NULL, &ctx);
    pk_denoise_options o;
    pk_denoise_options_init(&o);
    o.weights = "/nonexistent/folder";
    CHECK(pk_denoise_check(ctx, &o) == PK_ERR_IO);
    CHECKF(strstr(pk_context_error(ctx), "/nonexistent/folder/rt_hdr_alb_nrm.tza: no such weights file") &&
               strstr(pk_context_error(ctx), "make weights"), "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    /* a well-formed archive that is not one of OIDN's files: refused by its hash */
    size_t n;
    unsigned char *synthetic = tzab_unet(9, &n);
    char path[] = "/tmp/pk_tza_XXXXXX.tza";
    int fd = mkstemps(path, 4);
    REQUIRE(fd >= 0 && write(fd, synthetic, n) == (ssize_t)n);
    close(fd);
    free(synthetic);
    o.weights = path;
    CHECK(pk_denoise_check(ctx, &o) == PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(ctx), "not one of Open Image Denoise 2.3's weights files"), "%s",
           pk_context_error(ctx));
    pk_context_clear_error(ctx);
    remove(path);
    /* options out of range */
    pk_denoise_options_init(&o);
    o.tile_size = 100;
    pk_denoiser *d;
    CHECK(pk_denoiser_create(ctx, &o, &d) == PK_ERR_INVALID_ARGUMENT && strstr(pk_context_error(ctx), "tile size"));
    pk_context_clear_error(ctx);
    o.tile_size = 64, o.tile_overlap = 32;
    CHECK(pk_denoiser_create(ctx, &o, &d) == PK_ERR_INVALID_ARGUMENT && strstr(pk_context_error(ctx), "overlap"));
    pk_context_clear_error(ctx);
    o.tile_overlap = 0, o.input_scale = -1.0f;
    CHECK(pk_denoiser_create(ctx, &o, &d) == PK_ERR_INVALID_ARGUMENT);
    pk_context_destroy(ctx);
}

/* Tiles cover each axis exactly once, every tile reads within the image. */
static void check_tiles(void)
{
    const int sizes[] = {1, 15, 16, 17, 64, 100, 255, 1024, 1025, 3000};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        const int n = sizes[i], t = 256, ov = 48;
        tile_span s[64];
        int k = denoise_tiles(n, t, ov, s, 64);
        REQUIRE(k >= 1 && k <= 64);
        int covered = 0;
        for (int j = 0; j < k; j++) {
            CHECK(s[j].start >= 0 && s[j].start + s[j].size <= n && s[j].size <= t);
            CHECK(s[j].out0 == covered && s[j].out1 > s[j].out0);
            CHECK(s[j].out0 >= s[j].start && s[j].out1 <= s[j].start + s[j].size);
            /* an interior edge has the full overlap of context */
            if (j > 0) CHECK(s[j].out0 - s[j].start >= ov);
            if (j < k - 1) CHECK(s[j].start + s[j].size - s[j].out1 >= ov);
            covered = s[j].out1;
        }
        CHECK(covered == n);
    }
}

/* With OIDN's weights (when built): sizes from 1x1, bad pixels warned
 * about and never propagated, results finite and non-negative. */
static void check_images(void)
{
    char probe[512];
    snprintf(probe, sizeof probe, "%s/rt_hdr_alb_nrm.tza", PK_WEIGHTS_DIR);
    pk_context *ctx;
    pk_context_create(NULL, &ctx);
    if (access(probe, R_OK) != 0) {
        printf("SKIP image checks: no weights at %s (make weights)\n", PK_WEIGHTS_DIR);
        pk_context_destroy(ctx);
        return;
    }
    pk_denoise_options o;
    pk_denoise_options_init(&o);
    o.weights = PK_WEIGHTS_DIR;
    if (pk_denoise_check(ctx, &o) != PK_OK) {
        printf("SKIP image checks: %s\n", pk_context_error(ctx));
        pk_context_destroy(ctx);
        return;
    }
    warning_log log;
    warning_log_attach(ctx, &log);
    const int dims[][2] = {{1, 1}, {1, 40}, {37, 3}, {16, 16}, {70, 33}};
    for (size_t i = 0; i < sizeof dims / sizeof dims[0]; i++) {
        const int w = dims[i][0], h = dims[i][1];
        pk_image *c, *al, *nm, *out = NULL;
        pk_image_create(ctx, w, h, &c);
        pk_image_create(ctx, w, h, &al);
        pk_image_create(ctx, w, h, &nm);
        float *pc = pk_image_pixels(c), *pa = pk_image_pixels(al), *pn = pk_image_pixels(nm);
        for (int k = 0; k < w * h * 3; k++) {
            pc[k] = 0.5f + 0.25f * (float)((k * 7) % 5);
            pa[k] = 0.6f;
            pn[k] = k % 3 == 2 ? 1.0f : 0.0f;
        }
        pc[0] = NAN;
        if (w * h > 1) pc[4] = -3.0f, pc[5] = INFINITY;
        warning_log_clear(&log);
        REQUIRE(pk_denoise(ctx, &o, c, al, nm, &out) == PK_OK);
        CHECKF(log.count == 1 && warning_log_has(&log, "not finite"), "%dx%d: %d warnings", w, h, log.count);
        const float *po = pk_image_pixels_const(out);
        bool fine = true;
        for (int k = 0; k < w * h * 3; k++) fine &= isfinite(po[k]) && po[k] >= 0.0f;
        CHECKF(fine, "%dx%d: a result is not finite or negative", w, h);
        pk_image_destroy(out);
        pk_image_destroy(c);
        pk_image_destroy(al);
        pk_image_destroy(nm);
    }
    /* a normal without an albedo is refused */
    pk_image *c;
    pk_image_create(ctx, 4, 4, &c);
    pk_image *out = NULL;
    CHECK(pk_denoise(ctx, &o, c, NULL, c, &out) == PK_ERR_INVALID_ARGUMENT && out == NULL);
    pk_image_destroy(c);
    pk_context_destroy(ctx);
}

int main(void)
{
    pk_context *ctx;
    pk_context_create(NULL, &ctx);
    check_sha256();
    check_half(ctx);
    check_corrupt(ctx);
    check_weights_files();
    check_tiles();
    check_images();
    pk_context_destroy(ctx);
    return test_done("test_tza");
}

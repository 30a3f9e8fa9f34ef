/*
 * test_image_webp.c - WebP images (image/image_read.c, told by their RIFF
 * "WEBP" magic bytes) and glTF's EXT_texture_webp (io/gltf_material.c):
 * images encoded here with libwebp's own encoders decode to exactly the
 * pixels encoded (lossless) or to exactly what libwebp's decoder gives
 * (lossy); corrupt files get one "name: what is wrong" error; a glTF
 * texture whose extension names a WebP image uses it rather than its
 * fallback source, and KHR_texture_basisu (not decoded) falls back to the
 * texture's own source with one warning. Skipped when the build has no
 * libwebp.
 */
#include "test.h"
#include "warnings.h"

#include "image/image_read.h"
#include "io/readers.h"
#include "scene/scene.h"
#include "scene/texture.h"

#include <png.h>
#include <stdint.h>

#if PK_HAVE_WEBP
#include <webp/decode.h>
#include <webp/encode.h>

static uint32_t rng = 7;
static uint8_t rnd8(void) { return rng = rng * 1664525u + 1013904223u, (uint8_t)(rng >> 24); }

/* A w x h picture of nc channels: smooth ramps plus a little noise; alpha
 * never 0 (libwebp's lossless encoder may change the colour under a fully
 * transparent pixel) nor everywhere 255 (it drops an opaque alpha channel). */
static uint8_t *picture(int w, int h, int nc)
{
    uint8_t *p = malloc((size_t)w * (size_t)h * (size_t)nc);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < nc; c++)
                p[((size_t)y * (size_t)w + (size_t)x) * (size_t)nc + (size_t)c] =
                    (uint8_t)(c == 3 ? 55 + (x * 7 + y * 3) % 200 : (x * (c + 1) * 7 + y * 5 + (rnd8() & 7)) & 255);
    return p;
}

static pk_context *ctx;

static void test_lossless(void)
{
    static const int sizes[][2] = {{1, 1}, {3, 5}, {64, 33}, {257, 129}};
    for (int s = 0; s < 4; s++)
        for (int nc = 3; nc <= 4; nc++) {
            int w = sizes[s][0], h = sizes[s][1];
            uint8_t *px = picture(w, h, nc), *enc = NULL;
            size_t n = nc == 4 ? WebPEncodeLosslessRGBA(px, w, h, w * 4, &enc) : WebPEncodeLosslessRGB(px, w, h, w * 3, &enc);
            REQUIRE(n > 0);
            CHECK(image_sniff(enc, n) == IMAGE_WEBP);
            image_buf img;
            pk_status st = image_decode(ctx, enc, n, "a.webp", &img);
            CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
            if (st == PK_OK) {
                CHECKF(img.w == w && img.h == h && img.nc == nc && img.px8 && !img.pxf, "%dx%dx%d", img.w, img.h, img.nc);
                if (img.w == w && img.h == h && img.nc == nc)
                    CHECKF(memcmp(img.px8, px, (size_t)w * (size_t)h * (size_t)nc) == 0, "%dx%d, %d channels: pixels differ",
                           w, h, nc);
                image_buf_free(&ctx->alloc, &img);
            }
            pk_context_clear_error(ctx);
            WebPFree(enc);
            free(px);
        }
}

static void test_lossy(void)
{
    const int w = 96, h = 80;
    uint8_t *px = picture(w, h, 3), *enc = NULL;
    size_t n = WebPEncodeRGB(px, w, h, w * 3, 80.0f, &enc);
    REQUIRE(n > 0);
    int dw, dh;
    uint8_t *want = WebPDecodeRGB(enc, n, &dw, &dh);
    REQUIRE(want && dw == w && dh == h);
    image_buf img;
    REQUIRE(image_decode(ctx, enc, n, "a.webp", &img) == PK_OK);
    CHECK(img.w == w && img.h == h && img.nc == 3);
    CHECK(memcmp(img.px8, want, (size_t)w * h * 3) == 0);
    double err = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++) err += fabs((double)img.px8[i] - (double)px[i]);
    printf("lossy WebP at quality 80: %zu bytes for %d, mean error %.2f of 255\n", n, w * h * 3, err / (w * h * 3));
    image_buf_free(&ctx->alloc, &img);
    WebPFree(want);
    /* corrupt: cut short, data damaged, a header that lies */
    static const size_t cuts[] = {12, 20, 30};
    for (int k = 0; k < 3; k++) {
        pk_status st = image_decode(ctx, enc, cuts[k], "cut.webp", &img);
        CHECKF(st == PK_ERR_PARSE && strncmp(pk_context_error(ctx), "cut.webp: bad WebP", 18) == 0, "%d: %s", (int)st,
               pk_context_error(ctx));
        pk_context_clear_error(ctx);
    }
    pk_status st = image_decode(ctx, enc, n / 2, "half.webp", &img);
    CHECKF(st == PK_ERR_PARSE && strstr(pk_context_error(ctx), "half.webp: bad WebP"), "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    uint8_t *bad = malloc(n);
    int refused = 0;
    for (int trial = 0; trial < 100; trial++) {
        memcpy(bad, enc, n);
        for (int f = 0; f < 4; f++) bad[12 + (size_t)(rnd8() * 131u + rnd8()) % (n - 12)] = rnd8();
        st = image_decode(ctx, bad, n, "bad.webp", &img);
        CHECK(st == PK_OK || st == PK_ERR_PARSE || st == PK_ERR_UNSUPPORTED || st == PK_ERR_LIMIT);
        if (st == PK_OK) image_buf_free(&ctx->alloc, &img);
        refused += st != PK_OK;
        pk_context_clear_error(ctx);
    }
    printf("100 damaged WebP files: %d refused, the others decoded\n", refused);
    free(bad);
    WebPFree(enc);
    free(px);
}

/* ---- EXT_texture_webp ---------------------------------------------------------------- */

static char *b64(const uint8_t *p, size_t n, const char *mime)
{
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *o = malloc(4 * (n / 3 + 1) + 64), *q = o;
    q += sprintf(q, "data:%s;base64,", mime);
    for (size_t i = 0; i < n; i += 3) {
        uint32_t w = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        *q++ = al[w >> 18 & 63];
        *q++ = al[w >> 12 & 63];
        *q++ = i + 1 < n ? al[w >> 6 & 63] : '=';
        *q++ = i + 2 < n ? al[w & 63] : '=';
    }
    *q = '\0';
    return o;
}

static char msg[1024];
static warning_log wlog;

static pk_status load(const char *json, pk_scene **out)
{
    pk_context *c;
    REQUIRE(pk_context_create(NULL, &c) == PK_OK);
    warning_log_attach(c, &wlog);
    pk_scene *s;
    REQUIRE(scene_create(c, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse(c, s, json, strlen(json), "t.gltf", PK_TEST_DATA);
    if (st == PK_OK) st = scene_commit(c, s);
    snprintf(msg, sizeof msg, "%s", pk_context_error(c));
    if (st != PK_OK || !out) scene_destroy(s);
    else *out = s;
    pk_context_destroy(c);
    return st;
}

/* A quad whose base colour texture has the extensions ext (the texture's
 * JSON after its source), over images PNG (2 x 2) and WebP (3 x 5). */
static char *quad(const char *png_uri, const char *webp_uri, const char *tex, const char *extra)
{
    static const float quad_pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const float quad_uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    static const uint16_t quad_idx[6] = {0, 1, 2, 0, 2, 3};
    uint8_t buf[128];
    memcpy(buf, quad_pos, 48);
    memcpy(buf + 48, quad_uv, 32);
    memcpy(buf + 80, quad_idx, 12);
    char *bu = b64(buf, 92, "application/octet-stream");
    size_t n = strlen(png_uri) + strlen(webp_uri) + strlen(bu) + 4096;
    char *j = malloc(n);
    snprintf(j, n,
             "{\"asset\":{\"version\":\"2.0\"}%s,\"buffers\":[{\"byteLength\":92,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":32},"
             "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
             "{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"
             "\"images\":[{\"uri\":\"%s\"},{\"uri\":\"%s\"}],\"textures\":[{%s}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2,"
             "\"material\":0}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             extra, bu, png_uri, webp_uri, tex);
    free(bu);
    return j;
}

static void test_gltf(void)
{
    /* the fallback: a 2 x 2 PNG; the WebP: 3 x 5 lossless RGBA */
    static const uint8_t png_px[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    im.width = im.height = 2;
    im.format = PNG_FORMAT_RGB;
    png_alloc_size_t pn = 0;
    REQUIRE(png_image_write_to_memory(&im, NULL, &pn, 0, png_px, 0, NULL));
    uint8_t *png = malloc(pn);
    REQUIRE(png_image_write_to_memory(&im, png, &pn, 0, png_px, 0, NULL));
    uint8_t *wpx = picture(3, 5, 4), *wenc = NULL;
    size_t wn = WebPEncodeLosslessRGBA(wpx, 3, 5, 12, &wenc);
    REQUIRE(wn > 0);
    char *pu = b64(png, pn, "image/png"), *wu = b64(wenc, wn, "image/webp");
    static const char *const used = ",\"extensionsUsed\":[\"EXT_texture_webp\",\"KHR_texture_basisu\"]";
    /* with a fallback source, and without one: the WebP is read */
    static const char *const texs[] = {"\"source\":0,\"extensions\":{\"EXT_texture_webp\":{\"source\":1}}",
                                       "\"extensions\":{\"EXT_texture_webp\":{\"source\":1}}"};
    for (int k = 0; k < 2; k++) {
        char *j = quad(pu, wu, texs[k], used);
        pk_scene *s;
        pk_status st = load(j, &s);
        CHECKF(st == PK_OK, "%s", msg);
        if (st == PK_OK) {
            CHECK(s->ntextures == 1);
            if (s->ntextures == 1) {
                const texture *t = &s->textures[0];
                CHECKF(t->lv[0].w == 3 && t->lv[0].h == 5 && t->nc == 4, "%dx%d, %d channels", t->lv[0].w, t->lv[0].h,
                       t->nc);
                if (t->lv[0].w == 3 && t->lv[0].h == 5 && t->nc == 4 && t->lv[0].px8)
                    CHECK(memcmp(t->lv[0].px8, wpx, 60) == 0);
            }
            CHECKF(wlog.count == 0, "%s", wlog.all);
            scene_destroy(s);
        }
        free(j);
    }
    /* KHR_texture_basisu is not decoded: the texture's own source, one warning naming it */
    char *j = quad(pu, wu, "\"source\":0,\"extensions\":{\"KHR_texture_basisu\":{\"source\":1}}", used);
    pk_scene *s;
    pk_status st = load(j, &s);
    CHECKF(st == PK_OK, "%s", msg);
    if (st == PK_OK) {
        CHECK(s->ntextures == 1 && s->textures[0].lv[0].w == 2 && s->textures[0].lv[0].h == 2);
        CHECKF(warning_log_count(&wlog, "t.gltf: /textures/0/extensions/KHR_texture_basisu: KTX2 / Basis Universal "
                                        "images are not decoded") == 1 &&
                   warning_log_has(&wlog, "the texture's fallback source image is read"),
               "%s", wlog.all);
        scene_destroy(s);
    }
    free(j);
    j = quad(pu, wu, "\"source\":0,\"extensions\":{\"KHR_texture_basisu\":{\"source\":1}}",
             ",\"extensionsRequired\":[\"KHR_texture_basisu\"]");
    CHECK(load(j, NULL) == PK_ERR_UNSUPPORTED);
    CHECKF(strstr(msg, "t.gltf: /extensionsRequired/0: KTX2 / Basis Universal textures (KHR_texture_basisu) are not "
                       "read") == msg,
           "%s", msg);
    free(j);
    /* a bad extension object, a source out of range */
    j = quad(pu, wu, "\"source\":0,\"extensions\":{\"EXT_texture_webp\":{\"source\":9}}", used);
    CHECK(load(j, NULL) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "t.gltf: /textures/0/extensions/EXT_texture_webp/source") == msg, "%s", msg);
    free(j);
    j = quad(pu, wu, "\"source\":0,\"extensions\":{\"EXT_texture_webp\":7}", used);
    CHECK(load(j, NULL) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "t.gltf: /textures/0/extensions/EXT_texture_webp: must be an object") == msg, "%s", msg);
    free(j);
    free(pu);
    free(wu);
    free(png);
    free(wpx);
    WebPFree(wenc);
}
#endif

int main(void)
{
#if PK_HAVE_WEBP
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    if (!image_have_webp()) SKIP("libwebp was built for but does not load here");
    test_lossless();
    test_lossy();
    test_gltf();
    pk_context_destroy(ctx);
    return test_done("test_image_webp");
#else
    SKIP("this build has no libwebp (Debian: libwebp-dev): WebP images are not read");
#endif
}

/* fuzz_image.c - the image readers (PNG, JPEG, OpenEXR, Radiance HDR, PFM)
 * through their (buffer, size) entry point, then a texture built from what
 * they decoded (the mip chain) and a few lookups. Oracle: a failure carries
 * a message; a decoded image is within the limits, its float samples are
 * finite, and lookups stay finite. */
#include "fuzz.h"

#include "image/image_read.h"
#include "scene/texture.h"

#include <math.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    size_t warned = 0;
    pk_context_set_warning_handler(ctx, fuzz_warning, &warned);
    image_buf img;
    pk_status st = image_decode(ctx, data, size, "fuzz.img", &img);
    fuzz_check_error(ctx, st);
    if (st == PK_OK) {
        if (img.w <= 0 || img.h <= 0 || img.w > PK_MAX_TEXTURE_SIDE || img.h > PK_MAX_TEXTURE_SIDE ||
            (size_t)img.w * (size_t)img.h > PK_MAX_TEXTURE_PIXELS || img.nc < 1 || img.nc > 4 || (!img.px8 == !img.pxf)) {
            fprintf(stderr, "fuzz: bad image %dx%dx%d\n", img.w, img.h, img.nc);
            abort();
        }
        const size_t n = (size_t)img.w * (size_t)img.h * (size_t)img.nc;
        for (size_t i = 0; img.pxf && i < n; i++)
            if (!isfinite(img.pxf[i])) {
                fprintf(stderr, "fuzz: sample %zu is not finite\n", i);
                abort();
            }
        /* the mip chain of small images (large ones cost time, not coverage) */
        if ((size_t)img.w * (size_t)img.h <= 4096) {
            texture t;
            st = texture_build(ctx, img.w, img.h, img.nc, img.px8, img.pxf, size & 1, &t);
            fuzz_check_error(ctx, st);
            if (st == PK_OK) {
                float out[4];
                const float uv[4][3] = {{0.5f, 0.5f, 0.0f}, {-3.2f, 7.9f, 0.01f}, {1e9f, -1e9f, 1.0f}, {0.0f, 1.0f, 1e-3f}};
                for (int k = 0; k < 4; k++) {
                    texture_lookup(&t, uv[k][0], uv[k][1], uv[k][2], k & 1, out);
                    for (int c = 0; c < t.nc; c++)
                        if (!isfinite(out[c])) {
                            fprintf(stderr, "fuzz: lookup %d is not finite\n", k);
                            abort();
                        }
                }
                texture_free(&ctx->alloc, &t);
            }
        }
        image_buf_free(&ctx->alloc, &img);
    }
    pk_context_destroy(ctx);
    return 0;
}

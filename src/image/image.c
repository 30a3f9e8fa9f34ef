/*
 * image.c - pixel storage: images (linear RGB floats) and films (sums of
 * samples and their counts).
 */
#include "image.h"

#include <math.h>
#include <string.h>

pk_status image_check_size(pk_context *ctx, const char *what, int width, int height)
{
    if (width < 1 || height < 1 || width > PK_MAX_IMAGE_SIDE || height > PK_MAX_IMAGE_SIDE ||
        (uint64_t)width * (uint64_t)height > PK_MAX_IMAGE_PIXELS)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s size %dx%d is out of range (1..%d per side, at most %u pixels)", what,
                         width, height, PK_MAX_IMAGE_SIDE, PK_MAX_IMAGE_PIXELS);
    return PK_OK;
}

pk_status image_create(pk_context *ctx, int width, int height, pk_image **out)
{
    *out = NULL;
    pk_status st = image_check_size(ctx, "image", width, height);
    if (st != PK_OK) return st;
    pk_image *img = mem_calloc(&ctx->alloc, 1, sizeof *img);
    if (!img) return ctx_nomem(ctx);
    img->alloc = ctx->alloc;
    img->width = width;
    img->height = height;
    img->pixels = mem_calloc(&ctx->alloc, (size_t)width * (size_t)height * 3, sizeof(float));
    if (!img->pixels) {
        mem_free(&ctx->alloc, img);
        return ctx_nomem(ctx);
    }
    *out = img;
    return PK_OK;
}

void image_destroy(pk_image *img)
{
    if (!img) return;
    pk_allocator a = img->alloc;
    mem_free(&a, img->pixels);
    mem_free(&a, img);
}

pk_status film_create(pk_context *ctx, int width, int height, unsigned aovs, pk_film **out)
{
    *out = NULL;
    pk_status st = image_check_size(ctx, "film", width, height);
    if (st != PK_OK) return st;
    pk_film *f = mem_calloc(&ctx->alloc, 1, sizeof *f);
    if (!f) return ctx_nomem(ctx);
    f->alloc = ctx->alloc;
    f->width = width;
    f->height = height;
    const size_t n = (size_t)width * (size_t)height;
    f->sums = mem_calloc(&ctx->alloc, n * 3, sizeof(float));
    f->counts = mem_calloc(&ctx->alloc, n, sizeof(uint32_t));
    if (!f->sums || !f->counts) {
        film_destroy(f);
        return ctx_nomem(ctx);
    }
    f->aovs = aovs & ((1u << FILM_AOVS) - 1u);
    f->samples = (aovs & PK_AOV_SAMPLES) != 0;
    for (int k = 0; k < FILM_AOVS; k++)
        if (f->aovs & (1u << k)) {
            f->aov[k] = mem_calloc(&ctx->alloc, n * 3, sizeof(float));
            if (!f->aov[k]) {
                film_destroy(f);
                return ctx_nomem(ctx);
            }
        }
    *out = f;
    return PK_OK;
}

void film_destroy(pk_film *f)
{
    if (!f) return;
    pk_allocator a = f->alloc;
    mem_free(&a, f->sums);
    mem_free(&a, f->counts);
    for (int k = 0; k < FILM_AOVS; k++) mem_free(&a, f->aov[k]);
    mem_free(&a, f);
}

void film_clear(pk_film *f)
{
    const size_t n = (size_t)f->width * (size_t)f->height;
    memset(f->sums, 0, n * 3 * sizeof(float));
    memset(f->counts, 0, n * sizeof(uint32_t));
    for (int k = 0; k < FILM_AOVS; k++)
        if (f->aov[k]) memset(f->aov[k], 0, n * 3 * sizeof(float));
}

void film_merge(pk_film *dst, const pk_film *src)
{
    const size_t n = (size_t)dst->width * (size_t)dst->height;
    for (size_t i = 0; i < 3 * n; i++) dst->sums[i] += src->sums[i];
    for (size_t i = 0; i < n; i++) dst->counts[i] += src->counts[i];
    for (int k = 0; k < FILM_AOVS; k++)
        if (dst->aov[k] && src->aov[k])
            for (size_t i = 0; i < 3 * n; i++) dst->aov[k][i] += src->aov[k][i];
}

void film_add_aov_block(pk_film *f, int k, int x, int y, int w, int h, const float *v)
{
    if (!f->aov[k]) return;
    for (int j = 0; j < h; j++) {
        float *dst = f->aov[k] + 3 * ((size_t)(y + j) * (size_t)f->width + (size_t)x);
        const float *src = v + 3 * (size_t)j * (size_t)w;
        for (int i = 0; i < 3 * w; i++) dst[i] += src[i];
    }
}

void film_resolve_aov_into(const pk_film *f, int k, pk_image *img)
{
    const size_t n = (size_t)f->width * (size_t)f->height;
    for (size_t i = 0; i < n; i++) {
        const uint32_t c = f->counts[i];
        const float inv = c ? 1.0f / (float)c : 0.0f;
        for (int ch = 0; ch < 3; ch++) {
            const float v = f->aov[k] ? f->aov[k][3 * i + (size_t)ch] * inv : 0.0f;
            img->pixels[3 * i + (size_t)ch] = c && isfinite(v) ? v : 0.0f;
        }
    }
}

void film_add_block(pk_film *f, int x, int y, int w, int h, const float *rgb, uint32_t spp)
{
    for (int j = 0; j < h; j++) {
        const size_t row = (size_t)(y + j) * (size_t)f->width + (size_t)x;
        float *dst = f->sums + 3 * row;
        const float *src = rgb + 3 * (size_t)j * (size_t)w;
        for (int i = 0; i < 3 * w; i++) dst[i] += src[i];
        for (int i = 0; i < w; i++) f->counts[row + (size_t)i] += spp;
    }
}

void film_resolve_into(const pk_film *f, pk_image *img)
{
    const size_t n = (size_t)f->width * (size_t)f->height;
    for (size_t i = 0; i < n; i++) {
        const uint32_t c = f->counts[i];
        /* the reciprocal first, as a single render has always computed it */
        const float inv = c ? 1.0f / (float)c : 0.0f;
        for (int ch = 0; ch < 3; ch++) {
            const float v = f->sums[3 * i + (size_t)ch] * inv;
            img->pixels[3 * i + (size_t)ch] = c && isfinite(v) ? v : 0.0f;
        }
    }
}

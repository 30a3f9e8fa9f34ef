/*
 * texture.c - textures: building the mip chain, bilinear and trilinear
 * lookups, checkerboards, and the scene's texture table, in which every
 * file is loaded once per decode mode (see texture.h).
 */
#include "texture.h"

#include "../io/image.h"
#include "../io/image_read.h"
#include "scene.h"

#include <math.h>
#include <string.h>

void tex_ref_init(tex_ref *r)
{
    memset(r, 0, sizeof *r);
    r->tex = -1;
    r->s[0] = r->s[1] = 1.0f;
    r->bm = 1.0f;
    r->checker_scale = 1.0f;
}

void texture_free(const pk_allocator *a, texture *t)
{
    for (int k = 0; k < t->nlevels; k++) {
        mem_free(a, t->lv[k].px8);
        mem_free(a, t->lv[k].pxf);
    }
    mem_free(a, t->key);
    memset(t, 0, sizeof *t);
}

/* Number of colour channels that the sRGB curve applies to (alpha never). */
static inline int colour_channels(int nc) { return nc >= 3 ? 3 : 1; }

/* Texel (x, y) of a level, linear, into out[0..nc-1]. */
static inline void fetch(const texture *t, const tex_level *l, int x, int y, float out[4])
{
    const size_t i = ((size_t)y * (size_t)l->w + (size_t)x) * (size_t)t->nc;
    if (l->pxf) {
        for (int c = 0; c < t->nc; c++) out[c] = l->pxf[i + (size_t)c];
        return;
    }
    const int cc = t->srgb ? colour_channels(t->nc) : 0;
    for (int c = 0; c < t->nc; c++) {
        uint8_t b = l->px8[i + (size_t)c];
        out[c] = c < cc ? image_srgb_to_linear[b] : (float)b * (1.0f / 255.0f);
    }
}

/* Level k+1 from level k: the mean of each 2x2 block (edge texels reused
 * for odd sizes), in linear light. */
static pk_status downsample(pk_context *ctx, texture *t, int k)
{
    const tex_level *src = &t->lv[k];
    tex_level *dst = &t->lv[k + 1];
    dst->w = src->w > 1 ? src->w / 2 : 1;
    dst->h = src->h > 1 ? src->h / 2 : 1;
    const size_t n = (size_t)dst->w * (size_t)dst->h * (size_t)t->nc;
    if (src->pxf) dst->pxf = mem_realloc_array(&ctx->alloc, NULL, n, sizeof(float));
    else dst->px8 = mem_alloc(&ctx->alloc, n);
    if (!dst->pxf && !dst->px8) return ctx_nomem(ctx);
    const int cc = t->srgb ? colour_channels(t->nc) : 0;
    for (int y = 0; y < dst->h; y++) {
        const int y0 = 2 * y < src->h ? 2 * y : src->h - 1, y1 = 2 * y + 1 < src->h ? 2 * y + 1 : src->h - 1;
        for (int x = 0; x < dst->w; x++) {
            const int x0 = 2 * x < src->w ? 2 * x : src->w - 1, x1 = 2 * x + 1 < src->w ? 2 * x + 1 : src->w - 1;
            float a[4], b[4], c[4], d[4];
            fetch(t, src, x0, y0, a);
            fetch(t, src, x1, y0, b);
            fetch(t, src, x0, y1, c);
            fetch(t, src, x1, y1, d);
            const size_t o = ((size_t)y * (size_t)dst->w + (size_t)x) * (size_t)t->nc;
            for (int ch = 0; ch < t->nc; ch++) {
                float m = 0.25f * (a[ch] + b[ch] + c[ch] + d[ch]);
                if (dst->pxf) dst->pxf[o + (size_t)ch] = m;
                else if (ch < cc) dst->px8[o + (size_t)ch] = srgb_encode(m);
                else {
                    int v = (int)(m * 255.0f + 0.5f);
                    dst->px8[o + (size_t)ch] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
                }
            }
        }
    }
    t->bytes += n * (dst->pxf ? sizeof(float) : 1);
    return PK_OK;
}

pk_status texture_build(pk_context *ctx, int w, int h, int nc, const uint8_t *px8, const float *pxf, bool colour,
                        texture *out)
{
    memset(out, 0, sizeof *out);
    if (w <= 0 || h <= 0 || w > PK_MAX_TEXTURE_SIDE || h > PK_MAX_TEXTURE_SIDE || nc < 1 || nc > 4 || (!px8 && !pxf))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "bad texture size or channels");
    out->nc = nc;
    out->srgb = colour && px8 != NULL;
    const size_t n = (size_t)w * (size_t)h * (size_t)nc;
    tex_level *l = &out->lv[0];
    l->w = w;
    l->h = h;
    if (pxf) {
        l->pxf = mem_realloc_array(&ctx->alloc, NULL, n, sizeof(float));
        if (l->pxf) memcpy(l->pxf, pxf, n * sizeof(float));
    } else {
        l->px8 = mem_alloc(&ctx->alloc, n);
        if (l->px8) memcpy(l->px8, px8, n);
    }
    if (!l->px8 && !l->pxf) return ctx_nomem(ctx);
    out->nlevels = 1;
    out->bytes = n * (pxf ? sizeof(float) : 1);
    while (out->lv[out->nlevels - 1].w > 1 || out->lv[out->nlevels - 1].h > 1) {
        pk_status st = downsample(ctx, out, out->nlevels - 1);
        out->nlevels++; /* the level is owned (freed) even when incomplete */
        if (st != PK_OK) {
            texture_free(&ctx->alloc, out);
            return st;
        }
    }
    return PK_OK;
}

/* ---- lookups --------------------------------------------------------------------- */

/* A texel coordinate folded into [0, n): repeat or clamp. */
static inline int wrap(int i, int n, bool clamp)
{
    if (clamp) return i < 0 ? 0 : i >= n ? n - 1 : i;
    int m = i % n;
    return m < 0 ? m + n : m;
}

/* Reduces a coordinate to [0, 1) for repeat (so that huge uv stay exact
 * enough), or clamps it to [0, 1]; non-finite uv read as 0. */
static inline float fold(float x, bool clamp)
{
    if (!isfinite(x)) return 0.0f;
    if (clamp) return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x;
    return x - floorf(x);
}

void texture_bilinear(const texture *t, int level, float u, float v, bool clamp, float out[4])
{
    if (level < 0) level = 0;
    if (level >= t->nlevels) level = t->nlevels - 1;
    const tex_level *l = &t->lv[level];
    const float x = fold(u, clamp) * (float)l->w - 0.5f;
    const float y = (1.0f - fold(v, clamp)) * (float)l->h - 0.5f;
    const float fx0 = floorf(x), fy0 = floorf(y);
    const float fx = x - fx0, fy = y - fy0;
    const int x0 = (int)fx0, y0 = (int)fy0;
    const int xa = wrap(x0, l->w, clamp), xb = wrap(x0 + 1, l->w, clamp);
    const int ya = wrap(y0, l->h, clamp), yb = wrap(y0 + 1, l->h, clamp);
    float a[4], b[4], c[4], d[4];
    fetch(t, l, xa, ya, a);
    fetch(t, l, xb, ya, b);
    fetch(t, l, xa, yb, c);
    fetch(t, l, xb, yb, d);
    for (int ch = 0; ch < t->nc; ch++) {
        float top = a[ch] + (b[ch] - a[ch]) * fx;
        float bot = c[ch] + (d[ch] - c[ch]) * fx;
        out[ch] = top + (bot - top) * fy;
    }
}

float texture_level(const texture *t, float width)
{
    const float size = (float)(t->lv[0].w > t->lv[0].h ? t->lv[0].w : t->lv[0].h);
    const float texels = width * size; /* the footprint in texels of level 0 */
    if (!(texels > 1.0f)) return 0.0f;  /* also NaN */
    float lod = log2f(texels);
    const float top = (float)(t->nlevels - 1);
    return lod < top ? lod : top;
}

void texture_lookup(const texture *t, float u, float v, float width, bool clamp, float out[4])
{
    const float lod = texture_level(t, width);
    const int k = (int)lod;
    const float f = lod - (float)k;
    texture_bilinear(t, k, u, v, clamp, out);
    if (f > 0.0f && k + 1 < t->nlevels) {
        float hi[4];
        texture_bilinear(t, k + 1, u, v, clamp, hi);
        for (int c = 0; c < t->nc; c++) out[c] += (hi[c] - out[c]) * f;
    }
}

/* The raw channels at q (nc returned), for an image or a checker (3 channels). */
static int eval_raw(const texture *textures, const tex_ref *r, tex_query q, float out[4])
{
    const float u = r->s[0] * q.u + r->o[0], v = r->s[1] * q.v + r->o[1];
    if (r->kind == TEX_CHECKER) {
        float fu = floorf(u * r->checker_scale), fv = floorf(v * r->checker_scale);
        bool odd = isfinite(fu) && isfinite(fv) && fmodf(fabsf(fu + fv), 2.0f) == 1.0f;
        vec3 c = odd ? r->odd : r->even;
        out[0] = c.x, out[1] = c.y, out[2] = c.z;
        return 3;
    }
    const texture *t = &textures[r->tex];
    /* the footprint scales with the uv transform */
    const float sc = fmaxf(fabsf(r->s[0]), fabsf(r->s[1]));
    texture_lookup(t, u, v, q.width * sc, r->clamp, out);
    return t->nc;
}

vec3 tex_eval_rgb(const texture *textures, const tex_ref *r, tex_query q)
{
    float c[4];
    int nc = eval_raw(textures, r, q, c);
    return nc >= 3 ? v3(c[0], c[1], c[2]) : v3s(c[0]);
}

float tex_eval_scalar(const texture *textures, const tex_ref *r, tex_query q)
{
    float c[4];
    int nc = eval_raw(textures, r, q, c);
    return nc >= 3 ? (c[0] + c[1] + c[2]) * (1.0f / 3.0f) : c[0];
}

float tex_eval_alpha(const texture *textures, const tex_ref *r, tex_query q)
{
    float c[4];
    int nc = eval_raw(textures, r, q, c);
    if (nc == 2 || nc == 4) return c[nc - 1];
    return nc >= 3 ? (c[0] + c[1] + c[2]) * (1.0f / 3.0f) : c[0];
}

/* ---- the scene's table ------------------------------------------------------------ */

pk_status texture_load(pk_context *ctx, pk_scene *s, const char *path, bool colour, int32_t *index)
{
    *index = -1;
    size_t lp = strlen(path);
    char *key = mem_alloc(&ctx->alloc, lp + 2);
    if (!key) return ctx_nomem(ctx);
    key[0] = colour ? 'c' : 'd';
    memcpy(key + 1, path, lp + 1);
    for (size_t i = 0; i < s->ntextures; i++)
        if (strcmp(s->textures[i].key, key) == 0) {
            mem_free(&ctx->alloc, key);
            *index = (int32_t)i;
            return PK_OK;
        }
    if (s->ntextures >= (size_t)INT32_MAX) {
        mem_free(&ctx->alloc, key);
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: too many textures", path);
    }
    image_buf img;
    pk_status st = image_read_file(ctx, path, &img);
    if (st != PK_OK) {
        mem_free(&ctx->alloc, key);
        return st;
    }
    texture t;
    st = texture_build(ctx, img.w, img.h, img.nc, img.px8, img.pxf, colour, &t);
    image_buf_free(&ctx->alloc, &img);
    if (st != PK_OK) {
        mem_free(&ctx->alloc, key);
        return st;
    }
    t.key = key;
    if (t.bytes > PK_MAX_TEXTURE_BYTES - s->texture_bytes) {
        size_t have = s->texture_bytes;
        texture_free(&ctx->alloc, &t);
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: the scene's textures would take more than %zu bytes (%zu already)", path,
                         (size_t)PK_MAX_TEXTURE_BYTES, have);
    }
    if (!mem_grow(&s->alloc, (void **)&s->textures, &s->cap_textures, s->ntextures + 1, sizeof *s->textures)) {
        texture_free(&ctx->alloc, &t);
        return ctx_nomem(ctx);
    }
    s->textures[s->ntextures] = t;
    s->texture_bytes += t.bytes;
    *index = (int32_t)s->ntextures++;
    return PK_OK;
}

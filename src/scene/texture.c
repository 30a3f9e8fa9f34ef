/*
 * texture.c - textures: building the mip chain, bilinear and trilinear
 * lookups, checkerboards, and the scene's texture table, in which every
 * file is loaded once per decode mode (see texture.h).
 */
#include "texture.h"

#include "../image/image_write.h"
#include "../image/image_read.h"
#include "scene.h"

#include <math.h>
#include <string.h>

const uint8_t tex_noise_perm[256] = PK_NOISE_PERM_INIT;

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
    const int cc = t->srgb ? tex_colour_channels(t->nc) : 0;
    for (int y = 0; y < dst->h; y++) {
        const int y0 = 2 * y < src->h ? 2 * y : src->h - 1, y1 = 2 * y + 1 < src->h ? 2 * y + 1 : src->h - 1;
        for (int x = 0; x < dst->w; x++) {
            const int x0 = 2 * x < src->w ? 2 * x : src->w - 1, x1 = 2 * x + 1 < src->w ? 2 * x + 1 : src->w - 1;
            float a[4], b[4], c[4], d[4];
            tex_fetch(t, src, x0, y0, a);
            tex_fetch(t, src, x1, y0, b);
            tex_fetch(t, src, x0, y1, c);
            tex_fetch(t, src, x1, y1, d);
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

/* ---- the scene's table ------------------------------------------------------------ */

pk_status texture_load(pk_context *ctx, pk_scene *s, const char *path, bool colour, int32_t *index)
{
    *index = texture_find(s, path, colour);
    if (*index >= 0) return PK_OK;
    if (s->ntextures >= (size_t)INT32_MAX) return ctx_error(ctx, PK_ERR_LIMIT, "%s: too many textures", path);
    image_buf img;
    pk_status st = image_read_file(ctx, path, &img);
    if (st != PK_OK) return st;
    st = texture_add_pixels(ctx, s, path, img.w, img.h, img.nc, img.px8, img.pxf, colour, index);
    image_buf_free(&ctx->alloc, &img);
    return st;
}

int32_t texture_find(const pk_scene *s, const char *key, bool colour)
{
    for (size_t i = 0; i < s->ntextures; i++)
        if (s->textures[i].key[0] == (colour ? 'c' : 'd') && strcmp(s->textures[i].key + 1, key) == 0)
            return (int32_t)i;
    return -1;
}

pk_status texture_add_pixels(pk_context *ctx, pk_scene *s, const char *key, int w, int h, int nc, const uint8_t *px8,
                             const float *pxf, bool colour, int32_t *index)
{
    *index = -1;
    if (s->ntextures >= (size_t)INT32_MAX) return ctx_error(ctx, PK_ERR_LIMIT, "%s: too many textures", key);
    size_t lk = strlen(key);
    char *k = mem_alloc(&ctx->alloc, lk + 2);
    if (!k) return ctx_nomem(ctx);
    k[0] = colour ? 'c' : 'd';
    memcpy(k + 1, key, lk + 1);
    texture t;
    pk_status st = texture_build(ctx, w, h, nc, px8, pxf, colour, &t);
    if (st != PK_OK) {
        mem_free(&ctx->alloc, k);
        return st;
    }
    t.key = k;
    if (t.bytes > PK_MAX_TEXTURE_BYTES - s->texture_bytes) {
        size_t have = s->texture_bytes;
        texture_free(&ctx->alloc, &t);
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: the scene's textures would take more than %zu bytes (%zu already)", key,
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

vec3 texture_mean_rgb(const texture *t)
{
    float c[4] = {1, 1, 1, 1};
    const tex_level *l = &t->lv[t->nlevels - 1];
    tex_fetch(t, l, 0, 0, c);
    return t->nc >= 3 ? v3(c[0], c[1], c[2]) : v3s(c[0]);
}

/* ---- the mean over a triangle of uv ------------------------------------------------ */

/* Clips polygon in[0..n) (x, y pairs) to the half-plane where coordinate
 * axis (0 x, 1 y) is >= c (keep_ge) or <= c; the result (at most n + 1
 * points) into out, its count returned. */
static int clip_half(const double *in, int n, double *out, int axis, double c, bool keep_ge)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = in + 2 * i, *b = in + 2 * ((i + 1) % n);
        const double da = keep_ge ? a[axis] - c : c - a[axis], db = keep_ge ? b[axis] - c : c - b[axis];
        if (da >= 0.0) out[2 * m] = a[0], out[2 * m + 1] = a[1], m++;
        if ((da >= 0.0) != (db >= 0.0)) {
            const double t = da / (da - db);
            out[2 * m] = a[0] + t * (b[0] - a[0]), out[2 * m + 1] = a[1] + t * (b[1] - a[1]);
            out[2 * m + axis] = c; /* exactly on the line */
            m++;
        }
    }
    return m;
}

static double poly_area(const double *p, int n)
{
    double a = 0.0;
    for (int i = 0; i < n; i++) {
        const double *q = p + 2 * i, *r = p + 2 * ((i + 1) % n);
        a += q[0] * r[1] - r[0] * q[1];
    }
    return 0.5 * fabs(a);
}

static int64_t wrap64(int64_t i, int64_t n, bool clamp)
{
    if (clamp) return i < 0 ? 0 : i >= n ? n - 1 : i;
    const int64_t m = i % n;
    return m < 0 ? m + n : m;
}

static vec3 texel_rgb(const texture *t, const tex_level *l, int x, int y)
{
    float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    tex_fetch(t, l, x, y, c);
    return t->nc >= 3 ? v3(c[0], c[1], c[2]) : v3s(c[0]);
}

/* Adds to sum the integral over triangle p (texel units of level l) of the
 * level's texels read as constant squares, repeat or clamp. */
static void box_integral(const texture *t, const tex_level *l, const double p[6], int clamp, double sum[3])
{
    const double ylo = fmin(p[1], fmin(p[3], p[5])), yhi = fmax(p[1], fmax(p[3], p[5]));
    double row[2 * 16], tmp[2 * 16], cell[2 * 16]; /* clipping adds at most 2 points a side */
    for (int64_t iy = (int64_t)floor(ylo); (double)iy <= yhi; iy++) {
        int n = clip_half(p, 3, tmp, 1, (double)iy, true);
        n = clip_half(tmp, n, row, 1, (double)(iy + 1), false);
        if (n < 3) continue;
        double rxlo = row[0], rxhi = row[0];
        for (int i = 1; i < n; i++) rxlo = fmin(rxlo, row[2 * i]), rxhi = fmax(rxhi, row[2 * i]);
        const int y = (int)wrap64(iy, l->h, (clamp & TEX_CLAMP_V) != 0);
        for (int64_t ix = (int64_t)floor(rxlo); (double)ix <= rxhi; ix++) {
            int m = clip_half(row, n, tmp, 0, (double)ix, true);
            m = clip_half(tmp, m, cell, 0, (double)(ix + 1), false);
            if (m < 3) continue;
            const double a = poly_area(cell, m);
            if (!(a > 0.0)) continue;
            const vec3 c = texel_rgb(t, l, (int)wrap64(ix, l->w, (clamp & TEX_CLAMP_U) != 0), y);
            sum[0] += a * (double)c.x, sum[1] += a * (double)c.y, sum[2] += a * (double)c.z;
        }
    }
}

/* (texture.h) On the finest level the lookups' bilinear filter is counted
 * too: the mean of the integrals over the triangle moved by (+-1/4, +-1/4)
 * texel. */
vec3 texture_triangle_mean(const texture *t, const double u[3], const double v[3], int clamp)
{
    const tex_level *top = &t->lv[t->nlevels - 1];
    const double du = fmax(u[0], fmax(u[1], u[2])) - fmin(u[0], fmin(u[1], u[2]));
    const double dv = fmax(v[0], fmax(v[1], v[2])) - fmin(v[0], fmin(v[1], v[2]));
    const double area_uv = 0.5 * fabs((u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]));
    if (!isfinite(du) || !isfinite(dv) || !isfinite(area_uv)) return texel_rgb(t, top, 0, 0);
    /* the finest level whose texels are no smaller than 1 / TEX_TRI_CELLS of the footprint's box */
    int k = 0;
    while (k + 1 < t->nlevels &&
           (du * (double)t->lv[k].w > TEX_TRI_CELLS || dv * (double)t->lv[k].h > TEX_TRI_CELLS))
        k++;
    const tex_level *l = &t->lv[k];
    if (l->w == 1 && l->h == 1) return texel_rgb(t, l, 0, 0);
    /* the triangle in the level's texel units: texel (x, y) is the square [x, x+1) x [y, y+1) */
    double p[6];
    for (int i = 0; i < 3; i++) p[2 * i] = u[i] * (double)l->w, p[2 * i + 1] = (1.0 - v[i]) * (double)l->h;
    const double xlo = fmin(p[0], fmin(p[2], p[4])), xhi = fmax(p[0], fmax(p[2], p[4]));
    const double ylo = fmin(p[1], fmin(p[3], p[5])), yhi = fmax(p[1], fmax(p[3], p[5]));
    const double area = area_uv * (double)l->w * (double)l->h;
    const double ncells = (floor(xhi) - floor(xlo) + 1.0) * (floor(yhi) - floor(ylo) + 1.0);
    if (!(area > 1e-9) || !(ncells <= 4.0 * TEX_TRI_CELLS * TEX_TRI_CELLS + 64.0)) {
        /* a sliver (no area: the texel at its centroid), or a box of more
         * texels than the level's side allows (a level that stopped halving
         * on one side under a footprint of many repeats): the image's mean */
        if (!(area > 1e-9)) {
            const int64_t x = wrap64((int64_t)floor((p[0] + p[2] + p[4]) / 3.0), l->w, (clamp & TEX_CLAMP_U) != 0);
            const int64_t y = wrap64((int64_t)floor((p[1] + p[3] + p[5]) / 3.0), l->h, (clamp & TEX_CLAMP_V) != 0);
            return texel_rgb(t, l, (int)x, (int)y);
        }
        return texel_rgb(t, top, 0, 0);
    }
    double sum[3] = {0.0, 0.0, 0.0};
    if (k > 0) {
        box_integral(t, l, p, clamp, sum);
    } else {
        /* on the finest level the lookups' bilinear filter, which spreads
         * each texel over a texel's width around it (the box function
         * convolved with a one-texel box), counts: the mean of the box
         * integral over the triangle moved by (+-1/4, +-1/4) texel (the
         * midpoint rule of that convolution), so that a triangle beside a
         * bright texel gets the light that reaches it */
        for (int j = 0; j < 4; j++) {
            double q[6];
            for (int i = 0; i < 3; i++)
                q[2 * i] = p[2 * i] + ((j & 1) ? 0.25 : -0.25), q[2 * i + 1] = p[2 * i + 1] + ((j & 2) ? 0.25 : -0.25);
            box_integral(t, l, q, clamp, sum);
        }
        sum[0] *= 0.25, sum[1] *= 0.25, sum[2] *= 0.25;
    }
    return v3((float)(sum[0] / area), (float)(sum[1] / area), (float)(sum[2] / area));
}

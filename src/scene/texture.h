/*
 * texture.h - image textures with their mipmaps, procedural checkerboards,
 * and how a material refers to them (a uv transform, repeat or clamp).
 *
 * Texel (x, y) of a level lies at uv ((x + 0.5) / w, 1 - (y + 0.5) / h):
 * row 0 of an image is its top, v = 1, as OBJ and MTL expect. A lookup is
 * bilinear within a level, and trilinear between the two levels that a
 * footprint (a width in uv units, from the ray cone) falls between.
 * 8-bit colour textures keep their sRGB bytes and are decoded through a
 * table at lookup (a quarter of the memory of floats); mipmaps are averaged
 * in linear light. Data textures (bump, roughness, alpha, normal maps) are
 * read as they are, without the sRGB curve.
 */
#ifndef PK_TEXTURE_H
#define PK_TEXTURE_H

#include "../math/vec3.h"
#include "../image/srgb_table.h"
#include "../paprsek_internal.h"

#include <math.h>

PK_HIDDEN extern const float image_srgb_to_linear[256];

#define TEX_MAX_LEVELS 17   /* 32768 (PK_MAX_TEXTURE_SIDE) down to 1 */

typedef struct tex_level {
    int w, h;
    uint8_t *px8;  /* w*h*nc bytes, or NULL */
    float *pxf;    /* w*h*nc floats, or NULL */
} tex_level;

/* Invariants: 1 <= nc <= 4; 1 <= nlevels <= TEX_MAX_LEVELS; level k+1 is
 * level k halved (at least 1 a side); every level has px8 (8-bit source) or
 * pxf (HDR source), the same for all levels. */
typedef struct texture {
    char *key;     /* the decode mode ('c' colour, 'd' data) then the resolved path (owned) */
    int nc;        /* 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA */
    bool srgb;     /* 8-bit colour channels are sRGB-encoded */
    int nlevels;
    tex_level lv[TEX_MAX_LEVELS];
    size_t bytes;  /* texels of all levels */
} texture;

typedef enum tex_kind { TEX_NONE, TEX_IMAGE, TEX_CHECKER } tex_kind;

/* A material parameter's texture. The texture's value multiplies the
 * parameter's constant. Lookups use uv' = (s[0] u + o[0], s[1] v + o[1]);
 * outside [0,1) the image repeats, or with clamp its edge texels continue.
 * A checker is even where floor(scale u') + floor(scale v') is even, else odd. */
typedef struct tex_ref {
    uint8_t kind;      /* tex_kind; TEX_NONE (0) = the constant alone */
    bool clamp;
    bool squared;      /* scalars: the value squared (roughness maps read as GGX alpha) */
    int32_t tex;       /* TEX_IMAGE: index into the scene's textures */
    float s[2], o[2];
    float bm;          /* bump maps: the multiplier of the heights (-bm) */
    vec3 even, odd;    /* TEX_CHECKER */
    float checker_scale;
} tex_ref;

/* A lookup: the uv and the footprint width in uv units (0 = the finest level). */
typedef struct tex_query {
    float u, v, width;
} tex_query;

/* Sets a reference to none with the identity transform. */
PK_HIDDEN void tex_ref_init(tex_ref *r);

/* Builds a texture (mipmaps included) from decoded pixels: 8-bit samples
 * (px8) or floats (pxf); colour says the 8-bit colour channels are sRGB.
 * Takes ownership of neither. */
PK_HIDDEN pk_status texture_build(pk_context *ctx, int w, int h, int nc, const uint8_t *px8, const float *pxf,
                                  bool colour, texture *out);
PK_HIDDEN void texture_free(const pk_allocator *a, texture *t);

/* The texture at path for the scene (colour: decoded from sRGB), loaded
 * once: a later request for the same path and mode returns the same index.
 * Errors (unreadable, corrupt, beyond the limits, the scene's texture
 * memory past PK_MAX_TEXTURE_BYTES) are latched in ctx with the file named. */
PK_HIDDEN pk_status texture_load(pk_context *ctx, struct pk_scene *s, const char *path, bool colour, int32_t *index);
/* The same for pixels decoded by the caller (an image held in a glTF
 * buffer or data: URI): key names them (a path is the usual key, any
 * unique string will do), and texture_find finds them again. The pixels are
 * copied (texture_build). */
PK_HIDDEN pk_status texture_add_pixels(pk_context *ctx, struct pk_scene *s, const char *key, int w, int h, int nc,
                                       const uint8_t *px8, const float *pxf, bool colour, int32_t *index);
/* The index of the texture loaded under key in that decode mode, or -1. */
/* The mean linear colour of a texture (its coarsest mip level); grey for one channel. */
PK_HIDDEN vec3 texture_mean_rgb(const texture *t);
PK_HIDDEN int32_t texture_find(const struct pk_scene *s, const char *key, bool colour);



/* ---- lookups (compiled for the GPU as well) ------------------------------------ */

/* The linear value of an 8-bit sRGB code: the CPU's table, or the same
 * numbers in the GPU's constant memory. */
#if defined(__CUDACC__)
static __constant__ float tex_srgb_dev[256] = PK_SRGB_TO_LINEAR_INIT;
#endif
static inline PK_HD float tex_srgb_to_linear(uint8_t b)
{
#if defined(__CUDA_ARCH__)
    return tex_srgb_dev[b];
#else
    return image_srgb_to_linear[b];
#endif
}

/* Number of colour channels that the sRGB curve applies to (alpha never). */
static inline PK_HD int tex_colour_channels(int nc) { return nc >= 3 ? 3 : 1; }

/* Texel (x, y) of a level, linear, into out[0..nc-1]. */
static inline PK_HD void tex_fetch(const texture *t, const tex_level *l, int x, int y, float out[4])
{
    const size_t i = ((size_t)y * (size_t)l->w + (size_t)x) * (size_t)t->nc;
    if (l->pxf) {
        for (int c = 0; c < t->nc; c++) out[c] = l->pxf[i + (size_t)c];
        return;
    }
    const int cc = t->srgb ? tex_colour_channels(t->nc) : 0;
    for (int c = 0; c < t->nc; c++) {
        uint8_t b = l->px8[i + (size_t)c];
        out[c] = c < cc ? tex_srgb_to_linear(b) : (float)b * (1.0f / 255.0f);
    }
}

/* ---- lookups --------------------------------------------------------------------- */

/* A texel coordinate folded into [0, n): repeat or clamp. */
static inline PK_HD int tex_wrap(int i, int n, bool clamp)
{
    if (clamp) return i < 0 ? 0 : i >= n ? n - 1 : i;
    int m = i % n;
    return m < 0 ? m + n : m;
}

/* Reduces a coordinate to [0, 1) for repeat (so that huge uv stay exact
 * enough), or clamps it to [0, 1]; non-finite uv read as 0. */
static inline PK_HD float tex_fold(float x, bool clamp)
{
    if (!isfinite(x)) return 0.0f;
    if (clamp) return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x;
    return x - floorf(x);
}

/* Bilinear lookup in level k (clamped to the levels there are); out[0..nc-1]. */
static inline PK_HD void texture_bilinear(const texture *t, int level, float u, float v, bool clamp, float out[4])
{
    if (level < 0) level = 0;
    if (level >= t->nlevels) level = t->nlevels - 1;
    const tex_level *l = &t->lv[level];
    const float x = tex_fold(u, clamp) * (float)l->w - 0.5f;
    const float y = (1.0f - tex_fold(v, clamp)) * (float)l->h - 0.5f;
    const float fx0 = floorf(x), fy0 = floorf(y);
    const float fx = x - fx0, fy = y - fy0;
    const int x0 = (int)fx0, y0 = (int)fy0;
    const int xa = tex_wrap(x0, l->w, clamp), xb = tex_wrap(x0 + 1, l->w, clamp);
    const int ya = tex_wrap(y0, l->h, clamp), yb = tex_wrap(y0 + 1, l->h, clamp);
    float a[4], b[4], c[4], d[4];
    tex_fetch(t, l, xa, ya, a);
    tex_fetch(t, l, xb, ya, b);
    tex_fetch(t, l, xa, yb, c);
    tex_fetch(t, l, xb, yb, d);
    for (int ch = 0; ch < t->nc; ch++) {
        float top = a[ch] + (b[ch] - a[ch]) * fx;
        float bot = c[ch] + (d[ch] - c[ch]) * fx;
        out[ch] = top + (bot - top) * fy;
    }
}

/* The (fractional) mip level a footprint of width selects, in [0, nlevels-1]. */
static inline PK_HD float texture_level(const texture *t, float width)
{
    const float size = (float)(t->lv[0].w > t->lv[0].h ? t->lv[0].w : t->lv[0].h);
    const float texels = width * size; /* the footprint in texels of level 0 */
    if (!(texels > 1.0f)) return 0.0f;  /* also NaN */
    float lod = log2f(texels);
    const float top = (float)(t->nlevels - 1);
    return lod < top ? lod : top;
}

/* Trilinear lookup for a footprint of width (uv units); out[0..nc-1]. */
static inline PK_HD void texture_lookup(const texture *t, float u, float v, float width, bool clamp, float out[4])
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
static inline PK_HD int tex_eval_raw(const texture *textures, const tex_ref *r, tex_query q, float out[4])
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

/* A reference's value as a colour (grey spread to RGB, alpha ignored),
 * as a scalar (grey, or the mean of RGB), and as an opacity (the alpha
 * channel where there is one, else the scalar). textures: the scene's. */
static inline PK_HD vec3 tex_eval_rgb(const texture *textures, const tex_ref *r, tex_query q)
{
    float c[4];
    int nc = tex_eval_raw(textures, r, q, c);
    return nc >= 3 ? v3(c[0], c[1], c[2]) : v3s(c[0]);
}

static inline PK_HD float tex_eval_scalar(const texture *textures, const tex_ref *r, tex_query q)
{
    float c[4];
    int nc = tex_eval_raw(textures, r, q, c);
    return nc >= 3 ? (c[0] + c[1] + c[2]) * (1.0f / 3.0f) : c[0];
}

static inline PK_HD float tex_eval_alpha(const texture *textures, const tex_ref *r, tex_query q)
{
    float c[4];
    int nc = tex_eval_raw(textures, r, q, c);
    if (nc == 2 || nc == 4) return c[nc - 1];
    return nc >= 3 ? (c[0] + c[1] + c[2]) * (1.0f / 3.0f) : c[0];
}

#endif

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

typedef enum tex_kind { TEX_NONE, TEX_IMAGE, TEX_CHECKER, TEX_EXPR } tex_kind;

/* Which axes of a lookup clamp instead of repeating (a mask; 0 repeats both). */
enum { TEX_CLAMP_U = 1, TEX_CLAMP_V = 2, TEX_CLAMP = 3 };

/* A material parameter's texture. The texture's value multiplies the
 * parameter's constant. Lookups use uv' = (s[0] u + o[0], s[1] v + o[1]);
 * outside [0,1) the image repeats, or along the axes clamp names (a mask of
 * TEX_CLAMP_U and TEX_CLAMP_V) its edge texels continue.
 * A checker is even where floor(scale u') + floor(scale v') is even, else odd.
 * TEX_EXPR: an expression of procedural nodes (tex_node), nnodes of the
 * scene's node table from index node on, evaluated in order; the last is
 * the value. */
typedef struct tex_ref {
    uint8_t kind;      /* tex_kind; TEX_NONE (0) = the constant alone */
    uint8_t clamp;     /* TEX_CLAMP_U | TEX_CLAMP_V: the axes that clamp; 0 repeats */
    bool squared;      /* scalars: the value squared (roughness maps read as GGX alpha) */
    uint8_t uvset;     /* the texture-coordinate set it reads: 0, or 1 (scene.h's uvs1) */
    int32_t tex;       /* TEX_IMAGE: index into the scene's textures */
    float s[2], o[2];
    float bm;          /* bump maps: the multiplier of the heights (-bm) */
    vec3 even, odd;    /* TEX_CHECKER */
    float checker_scale;
    int32_t node, nnodes; /* TEX_EXPR */
} tex_ref;

struct tex_node;

/* A lookup: the uv and the footprint width in uv units (0 = the finest
 * level); for procedural expressions also the world-space point p, the
 * geometric normal n and the scene's node table; u1, v1, width1: the same
 * in the second texture-coordinate set, which references with uvset 1 read. */
typedef struct tex_query {
    float u, v, width;
    vec3 p, n;
    const struct tex_node *nodes;
    float u1, v1, width1;
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
/* The mean of a texture over the triangle of texture coordinates (u[k],
 * v[k]) (a reference's transform applied), repeat or clamp (a TEX_CLAMP_*
 * mask, per axis), each texel read
 * as a constant square: from the finest mip level on which the triangle's
 * bounding box spans at most TEX_TRI_CELLS texels a side, every texel
 * weighted by the exact area it shares with the triangle. Mip texels are
 * means of the finer ones, so only texels on the triangle's edges are
 * approximate (off by at most the share of the triangle in the band of
 * such texels, times the image's contrast). A triangle of no uv area: the
 * texel at its centroid; non-finite uv: the image's mean. */
#define TEX_TRI_CELLS 8
PK_HIDDEN vec3 texture_triangle_mean(const texture *t, const double u[3], const double v[3], int clamp);



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

/* Bilinear lookup in level k (clamped to the levels there are); clamp: a
 * TEX_CLAMP_* mask, the axes that clamp instead of repeating; out[0..nc-1]. */
static inline PK_HD void texture_bilinear(const texture *t, int level, float u, float v, int clamp, float out[4])
{
    if (level < 0) level = 0;
    if (level >= t->nlevels) level = t->nlevels - 1;
    const tex_level *l = &t->lv[level];
    const bool cu = (clamp & TEX_CLAMP_U) != 0, cv = (clamp & TEX_CLAMP_V) != 0;
    const float x = tex_fold(u, cu) * (float)l->w - 0.5f;
    const float y = (1.0f - tex_fold(v, cv)) * (float)l->h - 0.5f;
    const float fx0 = floorf(x), fy0 = floorf(y);
    const float fx = x - fx0, fy = y - fy0;
    const int x0 = (int)fx0, y0 = (int)fy0;
    const int xa = tex_wrap(x0, l->w, cu), xb = tex_wrap(x0 + 1, l->w, cu);
    const int ya = tex_wrap(y0, l->h, cv), yb = tex_wrap(y0 + 1, l->h, cv);
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

/* Trilinear lookup for a footprint of width (uv units), clamp a TEX_CLAMP_*
 * mask; out[0..nc-1]. */
static inline PK_HD void texture_lookup(const texture *t, float u, float v, float width, int clamp, float out[4])
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

/* ---- procedural expressions (compiled for the GPU as well) ------------------------- */

/* Nodes of a procedural texture expression (pbrt-v4's textures,
 * docs/scene-format.md). An expression is a run of nodes in the scene's
 * node table; operands (a, b, c) are earlier nodes of the same run, given
 * as offsets from its first node (-1: none), so that one pass in order
 * evaluates it without recursion. Every node's value is an RGB triple
 * (float textures hold the same value in all three). */
#define TEX_MAX_NODES 32

typedef enum tex_op {
    TN_CONST,    /* k[0] */
    TN_IMAGE,    /* image tex at the mapped (s, t), times k[0]; grey: the mean of its channels */
    TN_CHECKER,  /* a where the cell (floor of each coordinate) sums even, else b; 2D or (map TMAP_3D) 3D */
    TN_BILERP,   /* (1-s)(1-t) k[0] + (1-s) t k[1] + s (1-t) k[2] + s t k[3] */
    TN_DOTS,     /* a inside the polka dots, b outside */
    TN_FBM,      /* FBm(p, omega, octaves) */
    TN_WRINKLED, /* Turbulence(p, omega, octaves) */
    TN_WINDY,    /* |FBm(p / 10, 0.5, 3)| FBm(p, 0.5, 6) */
    TN_MARBLE,   /* pbrt's marble spline at sin(scale p.y + variation FBm(scale p)) */
    TN_SCALE,    /* a times b (b a float) */
    TN_MIX,      /* (1 - c) a + c b */
    TN_DIRMIX,   /* |n . v1| a + (1 - |n . v1|) b */
    TN_SQRT,     /* sqrt(max(a, 0)) (pbrt's roughness remapping) */
    TN_COUNT
} tex_op;

/* How a node finds its coordinates: uv (s, t) = (su u + du, sv v + dv);
 * spherical, cylindrical and planar from the texture-space point xf p; 3D
 * is the texture-space point itself. */
typedef enum tex_mapping { TMAP_UV, TMAP_SPHERICAL, TMAP_CYLINDRICAL, TMAP_PLANAR, TMAP_3D, TMAP_COUNT } tex_mapping;

typedef struct tex_node {
    uint8_t op, map;
    uint8_t clamp;   /* TN_IMAGE: the axes that clamp instead of repeating (TEX_CLAMP_*) */
    bool grey;       /* TN_IMAGE: a float texture (the mean of the channels) */
    int8_t a, b, c;  /* operands */
    int32_t tex;     /* TN_IMAGE: index into the scene's textures */
    int32_t octaves; /* TN_FBM, TN_WRINKLED, TN_MARBLE */
    float xf[12];    /* texture space from world: three rows of an affine matrix */
    float su, sv, du, dv;
    vec3 v1, v2;     /* planar: the axes; TN_DIRMIX: v1, the direction in world space (unit) */
    vec3 k[4];       /* constants (TN_CONST, TN_IMAGE's scale, TN_BILERP's corners) */
    float omega, scale, variation;
} tex_node;

/* Perlin's permutation table (his improved noise, 2002): the CPU's copy, or
 * the same numbers in the GPU's constant memory. */
#define PK_NOISE_PERM_INIT                                                                                             \
    {151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,  69,  142,   \
     8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,  94,  252, 219, 203,   \
     117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165,   \
     71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,    \
     55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,    \
     18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250,   \
     124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189,   \
     28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,     \
     129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,    \
     242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,    \
     181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114,   \
     67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180}
PK_HIDDEN extern const uint8_t tex_noise_perm[256];
#if defined(__CUDACC__)
static __constant__ uint8_t tex_noise_perm_dev[256] = PK_NOISE_PERM_INIT;
#endif
static inline PK_HD int tex_perm(int i)
{
#if defined(__CUDA_ARCH__)
    return tex_noise_perm_dev[i & 255];
#else
    return tex_noise_perm[i & 255];
#endif
}

/* The dot product of the gradient that hash h picks (one of the 12 edge
 * directions of a cube, 4 of them twice) with (x, y, z). */
static inline PK_HD float tex_grad(int h, float x, float y, float z)
{
    h &= 15;
    const float a = h < 8 ? x : y;
    const float b = h < 4 ? y : (h == 12 || h == 14) ? x : z;
    return ((h & 1) ? -a : a) + ((h & 2) ? -b : b);
}

static inline PK_HD float tex_fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
static inline PK_HD float tex_lerp(float t, float a, float b) { return a + t * (b - a); }

/* Perlin's improved noise at (x, y, z): 0 at every lattice point, in
 * [-2, 2] (in practice about [-1, 1]), C2-continuous. Non-finite input: 0. */
static inline PK_HD float tex_noise(float x, float y, float z)
{
    if (!isfinite(x) || !isfinite(y) || !isfinite(z)) return 0.0f;
    const float big = 1073741824.0f; /* 2^30: keeps the cell in an int */
    x = fmodf(x, big), y = fmodf(y, big), z = fmodf(z, big);
    const float fx = floorf(x), fy = floorf(y), fz = floorf(z);
    const int X = (int)fx & 255, Y = (int)fy & 255, Z = (int)fz & 255;
    x -= fx, y -= fy, z -= fz;
    const float u = tex_fade(x), v = tex_fade(y), w = tex_fade(z);
    const int A = tex_perm(X) + Y, AA = tex_perm(A) + Z, AB = tex_perm(A + 1) + Z;
    const int B = tex_perm(X + 1) + Y, BA = tex_perm(B) + Z, BB = tex_perm(B + 1) + Z;
    const float x00 = tex_lerp(u, tex_grad(tex_perm(AA), x, y, z), tex_grad(tex_perm(BA), x - 1.0f, y, z));
    const float x10 = tex_lerp(u, tex_grad(tex_perm(AB), x, y - 1.0f, z), tex_grad(tex_perm(BB), x - 1.0f, y - 1.0f, z));
    const float x01 =
        tex_lerp(u, tex_grad(tex_perm(AA + 1), x, y, z - 1.0f), tex_grad(tex_perm(BA + 1), x - 1.0f, y, z - 1.0f));
    const float x11 = tex_lerp(u, tex_grad(tex_perm(AB + 1), x, y - 1.0f, z - 1.0f),
                               tex_grad(tex_perm(BB + 1), x - 1.0f, y - 1.0f, z - 1.0f));
    return tex_lerp(w, tex_lerp(v, x00, x10), tex_lerp(v, x01, x11));
}

/* Fractional Brownian motion: octaves of noise, each at 1.99 times the
 * frequency and omega times the weight of the one before. (pbrt fades
 * out the octaves finer than a pixel's footprint; here every octave is
 * summed, and the pixel samples average them.) */
static inline PK_HD float tex_fbm(vec3 p, float omega, int octaves)
{
    float sum = 0.0f, lambda = 1.0f, o = 1.0f;
    for (int i = 0; i < octaves; i++) {
        sum += o * tex_noise(lambda * p.x, lambda * p.y, lambda * p.z);
        lambda *= 1.99f;
        o *= omega;
    }
    return sum;
}

/* Turbulence: the same sum of |noise|, plus pbrt's allowance of 0.2 (the
 * mean of |noise|) for the octave after the last. */
static inline PK_HD float tex_turbulence(vec3 p, float omega, int octaves)
{
    float sum = 0.0f, lambda = 1.0f, o = 1.0f;
    for (int i = 0; i < octaves; i++) {
        sum += o * fabsf(tex_noise(lambda * p.x, lambda * p.y, lambda * p.z));
        lambda *= 1.99f;
        o *= omega;
    }
    return sum + 0.2f * o;
}

/* Whether (s, t) lies in a polka dot: cells of side 1 centred on the
 * integers; about half of them (noise > 0) hold a dot of radius 0.35,
 * moved by noise up to 0.15 from the centre. */
static inline PK_HD bool tex_in_dot(float s, float t)
{
    const float sc = floorf(s + 0.5f), tc = floorf(t + 0.5f);
    if (!(tex_noise(sc + 0.5f, tc + 0.5f, 0.5f) > 0.0f)) return false;
    const float radius = 0.35f, shift = 0.5f - radius;
    const float cs = sc + shift * tex_noise(sc + 1.5f, tc + 2.8f, 0.5f);
    const float ct = tc + shift * tex_noise(sc + 4.5f, tc + 9.8f, 0.5f);
    const float ds = s - cs, dt = t - ct;
    return ds * ds + dt * dt < radius * radius;
}

/* pbrt's marble: a cubic Bezier spline through nine greys and a blue at
 * t in [0, 1], times 1.5. */
static inline PK_HD vec3 tex_marble_colour(float t)
{
    const float c[9][3] = {{.58f, .58f, .6f}, {.58f, .58f, .6f}, {.58f, .58f, .6f},
                           {.5f, .5f, .5f},   {.6f, .59f, .58f}, {.58f, .58f, .6f},
                           {.58f, .58f, .6f}, {.2f, .2f, .33f},  {.58f, .58f, .6f}};
    const int nseg = 6;
    if (!(t >= 0.0f)) t = 0.0f; /* also NaN */
    if (t > 1.0f) t = 1.0f;
    int first = (int)floorf(t * (float)nseg);
    if (first > nseg - 1) first = nseg - 1;
    t = t * (float)nseg - (float)first;
    float out[3];
    for (int k = 0; k < 3; k++) {
        /* de Casteljau */
        float s0 = tex_lerp(t, c[first][k], c[first + 1][k]), s1 = tex_lerp(t, c[first + 1][k], c[first + 2][k]);
        float s2 = tex_lerp(t, c[first + 2][k], c[first + 3][k]);
        s0 = tex_lerp(t, s0, s1), s1 = tex_lerp(t, s1, s2);
        out[k] = 1.5f * tex_lerp(t, s0, s1);
    }
    return v3(out[0], out[1], out[2]);
}

static inline PK_HD vec3 tex_node_point(const tex_node *d, vec3 p)
{
    const float *m = d->xf;
    return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
              m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

/* A node's 2D coordinates (s, t) at q. */
static inline PK_HD void tex_node_st(const tex_node *d, tex_query q, float *s, float *t)
{
    if (d->map == TMAP_UV) {
        *s = d->su * q.u + d->du, *t = d->sv * q.v + d->dv;
        return;
    }
    const vec3 p = tex_node_point(d, q.p);
    if (d->map == TMAP_SPHERICAL) {
        const float l = sqrtf(p.x * p.x + p.y * p.y + p.z * p.z);
        const float z = l > 0.0f ? fminf(fmaxf(p.z / l, -1.0f), 1.0f) : 1.0f;
        float phi = atan2f(p.y, p.x);
        if (phi < 0.0f) phi += 2.0f * PK_PI;
        *s = acosf(z) * (1.0f / PK_PI), *t = phi * (0.5f / PK_PI);
    } else if (d->map == TMAP_CYLINDRICAL) {
        *s = (PK_PI + atan2f(p.y, p.x)) * (0.5f / PK_PI), *t = p.z;
    } else { /* planar */
        *s = d->du + v3_dot(p, d->v1), *t = d->dv + v3_dot(p, d->v2);
    }
}

/* The value of the expression of r (kind TEX_EXPR) at q. */
static inline PK_HD vec3 tex_expr_eval(const texture *textures, const tex_ref *r, tex_query q)
{
    vec3 val[TEX_MAX_NODES];
    const tex_node *e = q.nodes + r->node;
    const int n = r->nnodes < TEX_MAX_NODES ? r->nnodes : TEX_MAX_NODES;
    if (n <= 0) return v3s(0.0f);
    for (int i = 0; i < n; i++) {
        const tex_node *d = &e[i];
        const vec3 A = d->a >= 0 && d->a < i ? val[d->a] : v3s(0.0f);
        const vec3 B = d->b >= 0 && d->b < i ? val[d->b] : v3s(0.0f);
        const vec3 C = d->c >= 0 && d->c < i ? val[d->c] : v3s(0.0f);
        vec3 out = v3s(0.0f);
        float s = 0.0f, t = 0.0f;
        switch (d->op) {
        case TN_CONST: out = d->k[0]; break;
        case TN_IMAGE: {
            tex_node_st(d, q, &s, &t);
            const texture *tx = &textures[d->tex];
            float c[4];
            const float sc = d->map == TMAP_UV ? fmaxf(fabsf(d->su), fabsf(d->sv)) : 1.0f;
            texture_lookup(tx, s, t, q.width * sc, d->clamp, c);
            if (d->grey) {
                const float g = tx->nc >= 3 ? (c[0] + c[1] + c[2]) * (1.0f / 3.0f) : c[0];
                out = v3s(g);
            } else {
                out = tx->nc >= 3 ? v3(c[0], c[1], c[2]) : v3s(c[0]);
            }
            out = v3_mul(out, d->k[0]);
            break;
        }
        case TN_CHECKER: {
            float cell;
            if (d->map == TMAP_3D) {
                const vec3 p = tex_node_point(d, q.p);
                cell = floorf(p.x) + floorf(p.y) + floorf(p.z);
            } else {
                tex_node_st(d, q, &s, &t);
                cell = floorf(s) + floorf(t);
            }
            const bool odd = isfinite(cell) && fmodf(fabsf(cell), 2.0f) == 1.0f;
            out = odd ? B : A;
            break;
        }
        case TN_BILERP:
            tex_node_st(d, q, &s, &t);
            out = v3_add(v3_add(v3_scale(d->k[0], (1.0f - s) * (1.0f - t)), v3_scale(d->k[1], (1.0f - s) * t)),
                         v3_add(v3_scale(d->k[2], s * (1.0f - t)), v3_scale(d->k[3], s * t)));
            break;
        case TN_DOTS:
            tex_node_st(d, q, &s, &t);
            out = tex_in_dot(s, t) ? A : B;
            break;
        case TN_FBM: out = v3s(tex_fbm(tex_node_point(d, q.p), d->omega, d->octaves)); break;
        case TN_WRINKLED: out = v3s(tex_turbulence(tex_node_point(d, q.p), d->omega, d->octaves)); break;
        case TN_WINDY: {
            const vec3 p = tex_node_point(d, q.p);
            out = v3s(fabsf(tex_fbm(v3_scale(p, 0.1f), 0.5f, 3)) * tex_fbm(p, 0.5f, 6));
            break;
        }
        case TN_MARBLE: {
            const vec3 p = v3_scale(tex_node_point(d, q.p), d->scale);
            const float m = p.y + d->variation * tex_fbm(p, d->omega, d->octaves);
            out = tex_marble_colour(0.5f + 0.5f * sinf(m));
            break;
        }
        case TN_SCALE: out = v3_mul(A, B); break;
        case TN_MIX: out = v3_add(v3_mul(v3_sub(v3s(1.0f), C), A), v3_mul(C, B)); break;
        case TN_DIRMIX: {
            const float amt = fminf(fabsf(v3_dot(q.n, d->v1)), 1.0f);
            out = v3_add(v3_scale(A, amt), v3_scale(B, 1.0f - amt));
            break;
        }
        case TN_SQRT: out = v3(sqrtf(fmaxf(A.x, 0.0f)), sqrtf(fmaxf(A.y, 0.0f)), sqrtf(fmaxf(A.z, 0.0f))); break;
        default: break;
        }
        val[i] = out;
    }
    return val[n - 1];
}

/* The raw channels at q (nc returned), for an image, a checker or an
 * expression (3 channels). */
static inline PK_HD int tex_eval_raw(const texture *textures, const tex_ref *r, tex_query q, float out[4])
{
    if (r->uvset) q.u = q.u1, q.v = q.v1, q.width = q.width1;
    if (r->kind == TEX_EXPR) {
        const vec3 c = tex_expr_eval(textures, r, q);
        out[0] = c.x, out[1] = c.y, out[2] = c.z;
        return 3;
    }
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

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
#include "../paprsek_internal.h"

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

/* Bilinear lookup in level k (clamped to the levels there are); out[0..nc-1]. */
PK_HIDDEN void texture_bilinear(const texture *t, int level, float u, float v, bool clamp, float out[4]);
/* Trilinear lookup for a footprint of width (uv units); out[0..nc-1]. */
PK_HIDDEN void texture_lookup(const texture *t, float u, float v, float width, bool clamp, float out[4]);
/* The (fractional) mip level a footprint of width selects, in [0, nlevels-1]. */
PK_HIDDEN float texture_level(const texture *t, float width);

/* A reference's value as a colour (grey spread to RGB, alpha ignored),
 * as a scalar (grey, or the mean of RGB), and as an opacity (the alpha
 * channel where there is one, else the scalar). textures: the scene's. */
PK_HIDDEN vec3 tex_eval_rgb(const texture *textures, const tex_ref *r, tex_query q);
PK_HIDDEN float tex_eval_scalar(const texture *textures, const tex_ref *r, tex_query q);
PK_HIDDEN float tex_eval_alpha(const texture *textures, const tex_ref *r, tex_query q);

#endif

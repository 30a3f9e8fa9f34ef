/*
 * gltf_material.c - glTF materials as the scene's metallic-roughness kind:
 * base colour (factor and sRGB texture), the metallic-roughness texture,
 * normal maps, emission (+KHR_materials_emissive_strength), alpha modes,
 * double-sidedness, KHR_texture_transform, KHR_materials_transmission,
 * KHR_materials_ior, and KHR_materials_specular, _sheen, _iridescence and
 * _anisotropy with their textures; images from files, data: URIs and buffer views, with
 * their samplers' wrap modes. What the model cannot show is warned about
 * (docs/scene-format.md, "glTF 2.0").
 */
#include "gltf.h"
#include "io_util.h"
#include "../image/image_read.h"
#include "../scene/material.h"
#include "../scene/texture.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A texture reference as a glTF textureInfo describes it. */
typedef struct tex_info {
    bool present;
    int64_t texture;
    int texcoord;
    float m[6];     /* the uv transform in glTF's uv space: u' = m0 u + m1 v + m2, v' = m3 u + m4 v + m5 */
    bool has_transform;
    float scale;    /* normalTexture.scale */
} tex_info;

static pk_status read_tex_info(gltf *g, const cJSON *o, const char *path, tex_info *ti)
{
    memset(ti, 0, sizeof *ti);
    ti->m[0] = ti->m[4] = 1.0f;
    ti->scale = 1.0f;
    if (!o) return PK_OK;
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    pk_status st;
    int64_t tc;
    if ((st = gltf_index(g, o, path, "index", gltf_count(g, "textures"), true, &ti->texture))) return st;
    if ((st = gltf_int(g, o, path, "texCoord", 0, INT32_MAX, 0, &tc))) return st;
    if ((st = gltf_num(g, o, path, "scale", -1e30, 1e30, 1.0, &ti->scale))) return st;
    const cJSON *tt = gltf_ext(o, "KHR_texture_transform");
    if (tt) {
        char tp[300];
        snprintf(tp, sizeof tp, "%s/extensions/KHR_texture_transform", path);
        if (!cJSON_IsObject(tt)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", tp);
        float off[2] = {0, 0}, sc[2] = {1, 1}, rot;
        bool found;
        if ((st = gltf_nums(g, tt, tp, "offset", 2, off, &found))) return st;
        if ((st = gltf_nums(g, tt, tp, "scale", 2, sc, &found))) return st;
        if ((st = gltf_num(g, tt, tp, "rotation", -1e30, 1e30, 0.0, &rot))) return st;
        if ((st = gltf_int(g, tt, tp, "texCoord", 0, INT32_MAX, tc, &tc))) return st;
        /* T R S; R as the extension's sample model TextureTransformTest
         * checks it: (u, v) -> (c u + s v, -s u + c v) */
        const float c = cosf(rot), s = sinf(rot);
        ti->m[0] = c * sc[0], ti->m[1] = s * sc[1], ti->m[2] = off[0];
        ti->m[3] = -s * sc[0], ti->m[4] = c * sc[1], ti->m[5] = off[1];
        ti->has_transform = true;
    }
    ti->texcoord = (int)tc;
    ti->present = true;
    return PK_OK;
}

static bool same_transform(const tex_info *a, const tex_info *b)
{
    return memcmp(a->m, b->m, sizeof a->m) == 0;
}

/* ---- images ------------------------------------------------------------------- */

/* The bytes of image i (owned *buf, or borrowed from a buffer view). */
static pk_status image_bytes(gltf *g, int64_t i, const uint8_t **data, size_t *size, void **owned)
{
    *owned = NULL;
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "images"), (int)i);
    char path[48], up[64];
    snprintf(path, sizeof path, "/images/%lld", (long long)i);
    snprintf(up, sizeof up, "%s/uri", path);
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const char *uri;
    pk_status st;
    int64_t view;
    if ((st = gltf_string(g, o, path, "uri", &uri))) return st;
    if ((st = gltf_index(g, o, path, "bufferView", gltf_count(g, "bufferViews"), false, &view))) return st;
    if (uri && view >= 0) return gltf_fail(g, PK_ERR_PARSE, "%s: both uri and bufferView", path);
    if (view >= 0) {
        size_t stride;
        return gltf_view(g, view, data, size, &stride);
    }
    if (!uri) return gltf_fail(g, PK_ERR_PARSE, "%s: neither uri nor bufferView", path);
    if (strncmp(uri, "data:", 5) == 0) {
        uint8_t *b;
        if ((st = gltf_data_uri(g, uri, up, &b, size))) return st;
        *data = b;
        *owned = b;
        return PK_OK;
    }
    char *b;
    if ((st = gltf_read_uri_file(g, uri, up, &b, size))) return st;
    *data = (const uint8_t *)b;
    *owned = b;
    return PK_OK;
}

/* The scene texture of image i in a decode mode (-1 with a warning when it
 * cannot be used). */
static pk_status image_texture(gltf *g, int64_t i, bool colour, const char *user, int32_t *tex)
{
    *tex = -1;
    int32_t *slot = &g->images[colour ? 0 : 1][i];
    if (*slot) { /* tried before: -1 unusable, else the texture + 1 */
        *tex = *slot < 0 ? -1 : *slot - 1;
        return PK_OK;
    }
    const bool was_ok = g->ctx->status == PK_OK;
    const uint8_t *data = NULL;
    size_t size = 0;
    void *owned = NULL;
    char key[PK_ERRMSG_MAX];
    snprintf(key, sizeof key, "%s#/images/%lld", g->name, (long long)i);
    pk_status st = image_bytes(g, i, &data, &size, &owned);
    if (st == PK_OK) {
        image_buf img;
        pk_context scratch = io_scratch_context(g->ctx);
        st = image_decode(&scratch, data, size, key, &img);
        if (st == PK_ERR_NOMEM) st = ctx_nomem(g->ctx);
        else if (st != PK_OK) st = gltf_fail(g, st, "/images/%lld: %s", (long long)i, scratch.message);
        if (st == PK_OK) {
            st = texture_add_pixels(g->ctx, g->s, key, img.w, img.h, img.nc, img.px8, img.pxf, colour, tex);
            image_buf_free(&g->ctx->alloc, &img);
        }
    }
    mem_free(&g->ctx->alloc, owned);
    if (st != PK_OK) {
        char why[PK_ERRMSG_MAX];
        if (!io_demote_error(g->ctx, st, was_ok, why, sizeof why)) return st;
        ctx_warn(g->ctx, "%s (%s drawn without it)", why, user);
        *slot = -1; /* unusable: not tried again */
        *tex = -1;
        return PK_OK;
    }
    *slot = *tex + 1;
    return PK_OK;
}

/* The texture tex of image src doubled along s and/or t with its mirror
 * image (glTF's mirrored repeat as a plain repeat of half the frequency);
 * -1 with a warning when that would be too large. */
static pk_status mirror_texture(gltf *g, int64_t src, bool colour, bool ms, bool mt, int32_t tex, int32_t *out)
{
    char key[PK_ERRMSG_MAX];
    snprintf(key, sizeof key, "%s#/images/%lld/mirror%s%s", g->name, (long long)src, ms ? "S" : "", mt ? "T" : "");
    *out = texture_find(g->s, key, colour);
    if (*out >= 0) return PK_OK;
    const texture *t = &g->s->textures[tex];
    const tex_level *l = &t->lv[0];
    const size_t w = (size_t)l->w, h = (size_t)l->h, nc = (size_t)t->nc;
    const size_t W = ms ? 2 * w : w, H = mt ? 2 * h : h;
    if (W > PK_MAX_TEXTURE_SIDE || H > PK_MAX_TEXTURE_SIDE || W * H > PK_MAX_TEXTURE_PIXELS) {
        gltf_warn(g, "/images/%lld: too large to mirror; drawn with repeat", (long long)src);
        return PK_OK;
    }
    const size_t es = l->px8 ? 1 : sizeof(float);
    uint8_t *px = mem_alloc(&g->ctx->alloc, W * H * nc * es);
    if (!px) return ctx_nomem(g->ctx);
    const uint8_t *from = l->px8 ? l->px8 : (const uint8_t *)l->pxf;
    for (size_t y = 0; y < H; y++)
        for (size_t x = 0; x < W; x++) {
            size_t sx = x < w ? x : 2 * w - 1 - x, sy = y < h ? y : 2 * h - 1 - y;
            memcpy(px + (y * W + x) * nc * es, from + (sy * w + sx) * nc * es, nc * es);
        }
    pk_status st = texture_add_pixels(g->ctx, g->s, key, (int)W, (int)H, t->nc, l->px8 ? px : NULL,
                                      l->px8 ? NULL : (const float *)(const void *)px, colour, out);
    mem_free(&g->ctx->alloc, px);
    return st;
}

/* A texture's image from EXT_texture_webp (the WebP image where WebP is read
 * here, else *src, the texture's own source, as the fallback) and
 * KHR_texture_basisu (never read here: no KTX2 / Basis Universal decoder;
 * the fallback source, with one warning). */
static pk_status texture_ext_source(gltf *g, const cJSON *t, const char *path, int64_t *src)
{
    static const char *const names[2] = {"EXT_texture_webp", "KHR_texture_basisu"};
    for (int k = 0; k < 2; k++) {
        const cJSON *x = gltf_ext(t, names[k]);
        if (!x) continue;
        char xp[96];
        snprintf(xp, sizeof xp, "%s/extensions/%s", path, names[k]);
        if (!cJSON_IsObject(x)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", xp);
        int64_t xs;
        pk_status st = gltf_index(g, x, xp, "source", g->nimages, true, &xs);
        if (st) return st;
        if (k == 0 && image_have_webp()) {
            *src = xs;
            return PK_OK;
        }
        gltf_warn_once(g, k ? GW_BASISU : GW_WEBP, "%s: %s; %s", xp,
                       k ? "KTX2 / Basis Universal images are not decoded (no decoder in this build)"
                         : "WebP images are not decoded here (libwebp is needed: Debian libwebp-dev)",
                       *src >= 0 ? "the texture's fallback source image is read" : "and it has no fallback source");
    }
    return PK_OK;
}

/* Resolves a textureInfo into a tex_ref (kind TEX_NONE when unusable). bake:
 * the transform is baked into the primitive's uvs (identity here). */
static pk_status make_ref(gltf *g, const tex_info *ti, bool colour, bool bake, const char *user, tex_ref *r)
{
    tex_ref_init(r);
    if (!ti->present) return PK_OK;
    const cJSON *t = cJSON_GetArrayItem(gltf_array(g, "textures"), (int)ti->texture);
    char path[48];
    snprintf(path, sizeof path, "/textures/%lld", (long long)ti->texture);
    if (!cJSON_IsObject(t)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    int64_t src, smp;
    pk_status st;
    if ((st = gltf_index(g, t, path, "source", g->nimages, false, &src))) return st;
    if ((st = gltf_index(g, t, path, "sampler", gltf_count(g, "samplers"), false, &smp))) return st;
    if ((st = texture_ext_source(g, t, path, &src))) return st;
    if (src < 0) {
        gltf_warn(g, "%s: no source image this reader can decode (%s drawn without it)", path, user);
        return PK_OK;
    }
    if (g->images[colour ? 0 : 1][src] < 0) return PK_OK; /* known unusable */
    int32_t tex;
    if ((st = image_texture(g, src, colour, user, &tex))) return st;
    if (tex < 0) return PK_OK;
    r->kind = TEX_IMAGE;
    r->tex = tex;
    r->uvset = (uint8_t)(ti->texcoord == 1);
    bool ms = false, mt = false;
    if (smp >= 0) {
        const cJSON *so = cJSON_GetArrayItem(gltf_array(g, "samplers"), (int)smp);
        char sp[48];
        snprintf(sp, sizeof sp, "/samplers/%lld", (long long)smp);
        if (!cJSON_IsObject(so)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", sp);
        int64_t ws, wt;
        if ((st = gltf_int(g, so, sp, "wrapS", 0, INT32_MAX, 10497, &ws))) return st;
        if ((st = gltf_int(g, so, sp, "wrapT", 0, INT32_MAX, 10497, &wt))) return st;
        for (int k = 0; k < 2; k++) {
            int64_t w = k ? wt : ws;
            if (w != 10497 && w != 33071 && w != 33648)
                return gltf_fail(g, PK_ERR_PARSE, "%s: %s %lld is not a glTF wrap mode", sp, k ? "wrapT" : "wrapS",
                                 (long long)w);
        }
        r->clamp = (ws == 33071 ? TEX_CLAMP_U : 0) | (wt == 33071 ? TEX_CLAMP_V : 0);
        ms = ws == 33648;
        mt = wt == 33648;
    }
    if (!bake) {
        /* glTF's v runs down the image, the scene's up: v_scene = 1 - v_gltf */
        r->s[0] = ti->m[0];
        r->s[1] = ti->m[4];
        r->o[0] = ti->m[2];
        r->o[1] = 1.0f - ti->m[4] - ti->m[5];
        if (ti->m[1] != 0.0f || ti->m[3] != 0.0f)
            gltf_warn_once(g, GW_ROTATION,
                           "%s: a KHR_texture_transform rotation differs between the material's textures: "
                           "drawn without it (further ones not reported)",
                           user);
    }
    if (ms || mt) {
        /* mirrored repeat: the image and its mirror image side by side, repeated */
        int32_t mtex;
        if ((st = mirror_texture(g, src, colour, ms, mt, tex, &mtex))) return st;
        if (mtex >= 0) {
            r->tex = mtex;
            if (ms) r->s[0] *= 0.5f, r->o[0] *= 0.5f;
            if (mt) r->s[1] *= 0.5f, r->o[1] = 0.5f * r->o[1] + 0.5f;
        }
    }
    return PK_OK;
}

/* ---- the derived textures: cut-out masks ------------------------------------------ */

/* A one-channel mask (255 where alpha * factor >= cutoff) from the base
 * colour texture tex (or the constant factor alone when tex < 0). */
static pk_status make_mask(gltf *g, int64_t mi, int32_t tex, float factor, float cutoff, int32_t *out)
{
    char key[PK_ERRMSG_MAX];
    snprintf(key, sizeof key, "%s#/materials/%lld/alpha", g->name, (long long)mi);
    int w = 1, h = 1;
    const texture *t = tex >= 0 ? &g->s->textures[tex] : NULL;
    if (t) w = t->lv[0].w, h = t->lv[0].h;
    uint8_t *px = mem_alloc(&g->ctx->alloc, (size_t)w * (size_t)h);
    if (!px) return ctx_nomem(g->ctx);
    for (size_t k = 0; k < (size_t)w * (size_t)h; k++) {
        float a = 1.0f;
        if (t && (t->nc == 2 || t->nc == 4)) {
            size_t at = k * (size_t)t->nc + (size_t)t->nc - 1;
            a = t->lv[0].px8 ? (float)t->lv[0].px8[at] / 255.0f : t->lv[0].pxf[at];
        }
        px[k] = a * factor >= cutoff ? 255 : 0;
    }
    pk_status st = texture_add_pixels(g->ctx, g->s, key, w, h, 1, px, NULL, false, out);
    mem_free(&g->ctx->alloc, px);
    return st;
}

/* ---- materials ------------------------------------------------------------------------ */

/* KHR_materials_specular, _sheen, _iridescence and _anisotropy as read. */
enum { GX_SPEC, GX_SPEC_COLOR, GX_SHEEN, GX_SHEEN_ROUGH, GX_IRID, GX_IRID_THICK, GX_ANISO, GX_NTEX };
typedef struct gx_params {
    float specular, spec_color[3], sheen[3], sheen_rough, irid, irid_ior, irid_min, irid_max, aniso, aniso_rot;
    tex_info t[GX_NTEX];
} gx_params;

static void gx_init(gltf *g, gx_params *x)
{
    x->specular = 1.0f;
    x->spec_color[0] = x->spec_color[1] = x->spec_color[2] = 1.0f;
    x->sheen[0] = x->sheen[1] = x->sheen[2] = 0.0f;
    x->sheen_rough = x->irid = x->aniso = x->aniso_rot = 0.0f;
    x->irid_ior = 1.3f, x->irid_min = 100.0f, x->irid_max = 400.0f;
    for (int k = 0; k < GX_NTEX; k++) read_tex_info(g, NULL, "", &x->t[k]);
}
static pk_status gx_tex(gltf *g, const cJSON *e, const char *ep, const char *key, tex_info *ti)
{
    char tp[224];
    snprintf(tp, sizeof tp, "%s/%s", ep, key);
    return read_tex_info(g, cJSON_GetObjectItemCaseSensitive(e, key), tp, ti);
}
/* The extensions' parameters and maps onto the material m (after
 * material_metallic_roughness and the core maps). */
static pk_status gx_apply(gltf *g, const gx_params *x, bool bake, const char *path, material *m)
{
    m->specular = x->specular;
    m->specular_color = v3(x->spec_color[0], x->spec_color[1], x->spec_color[2]);
    m->sheen_color = v3(x->sheen[0], x->sheen[1], x->sheen[2]);
    m->sheen_roughness = x->sheen_rough;
    m->iridescence = x->irid;
    m->iridescence_ior = x->irid_ior;
    m->iridescence_thickness = x->irid_max;
    m->iridescence_thickness_min = x->irid_min;
    m->anisotropy = x->aniso;
    m->anisotropy_rotation = x->aniso_rot;
    /* colour textures are sRGB, the others data */
    static const bool colour[GX_NTEX] = {false, true, true, false, false, false, false};
    tex_ref *maps[GX_NTEX] = {&m->map_spec, &m->map_spec_color, &m->map_sheen, &m->map_sheen_rough,
                              &m->map_irid, &m->map_irid_thick, &m->map_aniso};
    pk_status st;
    for (int k = 0; k < GX_NTEX; k++)
        if ((st = make_ref(g, &x->t[k], colour[k], bake, path, maps[k]))) return st;
    /* a texture on a factor of 0 changes nothing: no texture */
    if (v3_max_comp(m->sheen_color) <= 0.0f) tex_ref_init(&m->map_sheen), tex_ref_init(&m->map_sheen_rough);
    if (m->iridescence <= 0.0f) tex_ref_init(&m->map_irid), tex_ref_init(&m->map_irid_thick);
    if (m->anisotropy <= 0.0f) tex_ref_init(&m->map_aniso);
    if (m->specular <= 0.0f) tex_ref_init(&m->map_spec);
    material_gltf_update(m);
    return PK_OK;
}

/* KHR_materials_volume on a transmissive material (thickness > 0): the mesh
 * bounds a volume. Its boundary refracts: a material that only transmits
 * (transmission 1, not metallic, no clearcoat, no base colour,
 * metallic-roughness or layer texture) becomes a dielectric of its index and
 * roughness whose transmittance is the base colour (applied as light
 * enters); any other is the metallic-roughness BSDF with its transmission
 * refracting (material.volume: mix(dielectric, metal, metallic), the
 * dielectric's transmitted share a rough refraction). The inside
 * absorbs: sigma_a = -ln(attenuationColor) / attenuationDistance, a medium
 * bounded by vacuum outside (a glTF scene has no other media); an infinite
 * distance absorbs nothing and makes no medium. */
static pk_status make_volume(gltf *g, const char *path, material *m, float transmission, float thickness,
                             float dist, const float col[3], bool textured)
{
    (void)thickness;
    if (transmission >= 1.0f && m->metallic == 0.0f && m->clearcoat == 0.0f && !textured) {
        const float r = m->roughness;
        material_dielectric(m, m->ni, r * r, m->kd);
    } else {
        m->volume = true; /* the metallic-roughness BSDF whose transmission refracts (pbsdf.h) */
    }
    if (!isfinite(dist)) return PK_OK;
    medium md;
    medium_init(&md);
    float sa[3];
    for (int k = 0; k < 3; k++) sa[k] = -logf(fmaxf(col[k], 1e-30f)) / dist;
    md.sigma_t = v3(sa[0], sa[1], sa[2]);
    md.albedo = v3s(0.0f);
    if (!v3_finite(md.sigma_t))
        return gltf_fail(g, PK_ERR_PARSE, "%s: KHR_materials_volume: the absorption -ln(attenuationColor) / "
                                          "attenuationDistance is not finite", path);
    char name[96];
    snprintf(name, sizeof name, "%.60s/volume", m->name ? m->name : path);
    if (!(md.name = mem_strdup(&g->s->alloc, name))) return ctx_nomem(g->ctx);
    uint32_t idx;
    pk_status st = scene_add_medium(g->ctx, g->s, &md, &idx);
    if (st) return st;
    m->medium_in = (int32_t)idx;
    m->medium_out = MEDIUM_NONE;
    return PK_OK;
}

static pk_status make_material(gltf *g, int64_t mi, uint32_t *out, int *uvsets)
{
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "materials"), (int)mi);
    char path[48], pp[96], ep[160];
    snprintf(path, sizeof path, "/materials/%lld", (long long)mi);
    snprintf(pp, sizeof pp, "%s/pbrMetallicRoughness", path);
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    pk_status st;
    const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(o, "pbrMetallicRoughness");
    if (pbr && !cJSON_IsObject(pbr)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", pp);
    float base[4] = {1, 1, 1, 1}, metallic = 1.0f, roughness = 1.0f, emissive[3] = {0, 0, 0};
    bool found;
    tex_info t_base, t_mr, t_norm, t_emit, t_occ, t_tr, t_cc, t_ccr, t_ccn, t_thick;
    char tp[192]; /* a pointer into an extension (ep) and a key */
    read_tex_info(g, NULL, path, &t_tr);
    read_tex_info(g, NULL, path, &t_cc);
    read_tex_info(g, NULL, path, &t_ccr);
    read_tex_info(g, NULL, path, &t_ccn);
    read_tex_info(g, NULL, path, &t_thick);
    if (pbr) {
        if ((st = gltf_nums(g, pbr, pp, "baseColorFactor", 4, base, &found))) return st;
        if ((st = gltf_num(g, pbr, pp, "metallicFactor", 0.0, 1.0, 1.0, &metallic))) return st;
        if ((st = gltf_num(g, pbr, pp, "roughnessFactor", 0.0, 1.0, 1.0, &roughness))) return st;
        snprintf(tp, sizeof tp, "%s/baseColorTexture", pp);
        if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(pbr, "baseColorTexture"), tp, &t_base))) return st;
        snprintf(tp, sizeof tp, "%s/metallicRoughnessTexture", pp);
        if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(pbr, "metallicRoughnessTexture"), tp, &t_mr)))
            return st;
    } else {
        read_tex_info(g, NULL, pp, &t_base);
        read_tex_info(g, NULL, pp, &t_mr);
    }
    for (int k = 0; k < 4; k++)
        if (base[k] < 0.0f || base[k] > 1.0f)
            return gltf_fail(g, PK_ERR_PARSE, "%s/baseColorFactor: %g is outside [0, 1]", pp, (double)base[k]);
    snprintf(tp, sizeof tp, "%s/normalTexture", path);
    if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(o, "normalTexture"), tp, &t_norm))) return st;
    snprintf(tp, sizeof tp, "%s/emissiveTexture", path);
    if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(o, "emissiveTexture"), tp, &t_emit))) return st;
    snprintf(tp, sizeof tp, "%s/occlusionTexture", path);
    if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(o, "occlusionTexture"), tp, &t_occ))) return st;
    if ((st = gltf_nums(g, o, path, "emissiveFactor", 3, emissive, &found))) return st;
    for (int k = 0; k < 3; k++)
        if (emissive[k] < 0.0f)
            return gltf_fail(g, PK_ERR_PARSE, "%s/emissiveFactor: %g is negative", path, (double)emissive[k]);
    const char *mode;
    if ((st = gltf_string(g, o, path, "alphaMode", &mode))) return st;
    int amode = 0; /* OPAQUE, MASK, BLEND */
    if (mode) {
        if (strcmp(mode, "OPAQUE") == 0) amode = 0;
        else if (strcmp(mode, "MASK") == 0) amode = 1;
        else if (strcmp(mode, "BLEND") == 0) amode = 2;
        else return gltf_fail(g, PK_ERR_PARSE, "%s/alphaMode: '%.16s' is not OPAQUE, MASK or BLEND", path, mode);
    }
    float cutoff;
    if ((st = gltf_num(g, o, path, "alphaCutoff", 0.0, 1e30, 0.5, &cutoff))) return st;
    const cJSON *ds = cJSON_GetObjectItemCaseSensitive(o, "doubleSided");
    if (ds && !cJSON_IsBool(ds)) return gltf_fail(g, PK_ERR_PARSE, "%s/doubleSided: must be true or false", path);

    /* extensions */
    float strength = 1.0f, transmission = 0.0f, ior = 1.5f, coat = 0.0f, coat_rough = 0.0f;
    float thickness = 0.0f, att_dist = INFINITY, att_col[3] = {1, 1, 1};
    bool unlit = false;
    gx_params gx;
    gx_init(g, &gx);
    bool gx_used = false;
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(o, "extensions");
    for (const cJSON *e = ext ? ext->child : NULL; e; e = e->next) {
        snprintf(ep, sizeof ep, "%s/extensions/%.40s", path, e->string ? e->string : "");
        if (!e->string) continue;
        if (strcmp(e->string, "KHR_materials_emissive_strength") == 0) {
            if ((st = gltf_num(g, e, ep, "emissiveStrength", 0.0, 1e30, 1.0, &strength))) return st;
        } else if (strcmp(e->string, "KHR_materials_transmission") == 0) {
            if ((st = gltf_num(g, e, ep, "transmissionFactor", 0.0, 1.0, 0.0, &transmission))) return st;
            snprintf(tp, sizeof tp, "%s/transmissionTexture", ep);
            if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(e, "transmissionTexture"), tp, &t_tr)))
                return st;
        } else if (strcmp(e->string, "KHR_materials_ior") == 0) {
            if ((st = gltf_num(g, e, ep, "ior", 0.0, 1e30, 1.5, &ior))) return st;
            if (ior == 0.0f) ior = 1.5f; /* never seen through: glTF's "0" is an infinite index; a dielectric default */
            else if (ior < 1.0f) return gltf_fail(g, PK_ERR_PARSE, "%s: ior %g is below 1", ep, (double)ior);
        } else if (strcmp(e->string, "KHR_materials_clearcoat") == 0) {
            if ((st = gltf_num(g, e, ep, "clearcoatFactor", 0.0, 1.0, 0.0, &coat))) return st;
            if ((st = gltf_num(g, e, ep, "clearcoatRoughnessFactor", 0.0, 1.0, 0.0, &coat_rough))) return st;
            snprintf(tp, sizeof tp, "%s/clearcoatTexture", ep);
            if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(e, "clearcoatTexture"), tp, &t_cc))) return st;
            snprintf(tp, sizeof tp, "%s/clearcoatRoughnessTexture", ep);
            if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(e, "clearcoatRoughnessTexture"), tp, &t_ccr)))
                return st;
            snprintf(tp, sizeof tp, "%s/clearcoatNormalTexture", ep);
            if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(e, "clearcoatNormalTexture"), tp, &t_ccn)))
                return st;
        } else if (strcmp(e->string, "KHR_materials_volume") == 0) {
            /* the mesh is a closed volume (thickness > 0) whose inside absorbs */
            if ((st = gltf_num(g, e, ep, "thicknessFactor", 0.0, 1e30, 0.0, &thickness))) return st;
            const cJSON *ad = cJSON_GetObjectItemCaseSensitive(e, "attenuationDistance");
            if (ad) {
                if ((st = gltf_num(g, e, ep, "attenuationDistance", 0.0, 3.4e38, 1.0, &att_dist))) return st;
                if (!(att_dist > 0.0f))
                    return gltf_fail(g, PK_ERR_PARSE, "%s/attenuationDistance: %g must be greater than 0", ep,
                                     (double)att_dist);
            }
            if ((st = gltf_nums(g, e, ep, "attenuationColor", 3, att_col, &found))) return st;
            for (int k = 0; k < 3; k++)
                if (!(att_col[k] >= 0.0f && att_col[k] <= 1.0f))
                    return gltf_fail(g, PK_ERR_PARSE, "%s/attenuationColor: %g is outside [0, 1]", ep, (double)att_col[k]);
            /* the thickness map is a rasterizer's estimate of what rays find
             * here: the extension tells ray tracers to ignore it (checked only) */
            snprintf(tp, sizeof tp, "%s/thicknessTexture", ep);
            if ((st = read_tex_info(g, cJSON_GetObjectItemCaseSensitive(e, "thicknessTexture"), tp, &t_thick)))
                return st;
        } else if (strcmp(e->string, "KHR_materials_specular") == 0) {
            gx_used = true;
            if ((st = gltf_num(g, e, ep, "specularFactor", 0.0, 1.0, 1.0, &gx.specular))) return st;
            if ((st = gltf_nums(g, e, ep, "specularColorFactor", 3, gx.spec_color, &found))) return st;
            for (int k = 0; k < 3; k++)
                if (!(gx.spec_color[k] >= 0.0f && gx.spec_color[k] < 3.4e38f))
                    return gltf_fail(g, PK_ERR_PARSE, "%s/specularColorFactor: %g is negative", ep,
                                     (double)gx.spec_color[k]);
            if ((st = gx_tex(g, e, ep, "specularTexture", &gx.t[GX_SPEC]))) return st;
            if ((st = gx_tex(g, e, ep, "specularColorTexture", &gx.t[GX_SPEC_COLOR]))) return st;
        } else if (strcmp(e->string, "KHR_materials_sheen") == 0) {
            gx_used = true;
            if ((st = gltf_nums(g, e, ep, "sheenColorFactor", 3, gx.sheen, &found))) return st;
            for (int k = 0; k < 3; k++)
                if (!(gx.sheen[k] >= 0.0f && gx.sheen[k] <= 1.0f))
                    return gltf_fail(g, PK_ERR_PARSE, "%s/sheenColorFactor: %g is outside [0, 1]", ep,
                                     (double)gx.sheen[k]);
            if ((st = gltf_num(g, e, ep, "sheenRoughnessFactor", 0.0, 1.0, 0.0, &gx.sheen_rough))) return st;
            if ((st = gx_tex(g, e, ep, "sheenColorTexture", &gx.t[GX_SHEEN]))) return st;
            if ((st = gx_tex(g, e, ep, "sheenRoughnessTexture", &gx.t[GX_SHEEN_ROUGH]))) return st;
        } else if (strcmp(e->string, "KHR_materials_iridescence") == 0) {
            gx_used = true;
            if ((st = gltf_num(g, e, ep, "iridescenceFactor", 0.0, 1.0, 0.0, &gx.irid))) return st;
            if ((st = gltf_num(g, e, ep, "iridescenceIor", 1.0, 1e30, 1.3, &gx.irid_ior))) return st;
            if ((st = gltf_num(g, e, ep, "iridescenceThicknessMinimum", 0.0, 1e30, 100.0, &gx.irid_min))) return st;
            if ((st = gltf_num(g, e, ep, "iridescenceThicknessMaximum", 0.0, 1e30, 400.0, &gx.irid_max))) return st;
            if ((st = gx_tex(g, e, ep, "iridescenceTexture", &gx.t[GX_IRID]))) return st;
            if ((st = gx_tex(g, e, ep, "iridescenceThicknessTexture", &gx.t[GX_IRID_THICK]))) return st;
        } else if (strcmp(e->string, "KHR_materials_anisotropy") == 0) {
            gx_used = true;
            if ((st = gltf_num(g, e, ep, "anisotropyStrength", 0.0, 1.0, 0.0, &gx.aniso))) return st;
            if ((st = gltf_num(g, e, ep, "anisotropyRotation", -1e30, 1e30, 0.0, &gx.aniso_rot))) return st;
            if ((st = gx_tex(g, e, ep, "anisotropyTexture", &gx.t[GX_ANISO]))) return st;
        } else if (strcmp(e->string, "KHR_materials_dispersion") == 0) {
            gltf_warn_once(g, GW_DISPERSION,
                           "%s: drawn without dispersion (needs spectral rendering; further ones not reported)", ep);
        } else if (strcmp(e->string, "KHR_materials_unlit") == 0) {
            unlit = true; /* below: an emitter of the base colour that does not scatter */
        } else {
            gltf_warn(g, "%s: unknown material extension ignored", ep);
        }
    }

    /* which uv sets, and whether one transform serves every texture (then
     * it is baked into the primitive's uvs, rotation included) */
    if (transmission == 0.0f) t_tr.present = false; /* (read, never looked up) */
    if (coat == 0.0f) t_cc.present = t_ccr.present = t_ccn.present = false;
    if (coat_rough == 0.0f) t_ccr.present = false;
    if (unlit) {
        t_mr.present = t_norm.present = t_emit.present = t_tr.present = t_cc.present = t_ccr.present = t_ccn.present =
            false;
        for (int k = 0; k < GX_NTEX; k++) gx.t[k].present = false;
        gx_used = false;
    }
    tex_info *all[8 + GX_NTEX] = {&t_base, &t_mr, &t_norm, &t_emit, &t_tr, &t_cc, &t_ccr, &t_ccn};
    for (int k = 0; k < GX_NTEX; k++) all[8 + k] = &gx.t[k];
    int sets = 0;
    bool same = true;
    const tex_info *first = NULL;
    for (int k = 0; k < 8 + GX_NTEX; k++) {
        if (!all[k]->present) continue;
        if (all[k]->texcoord > 1) {
            gltf_warn_once(g, GW_UV_SETS, "%s: a texture reads TEXCOORD_%d; only TEXCOORD_0 and _1 are read, so it reads "
                           "TEXCOORD_0 (further ones not reported)", path, all[k]->texcoord);
            all[k]->texcoord = 0;
        }
        sets |= 1 << all[k]->texcoord;
        if (!first) first = all[k];
        else if (!same_transform(first, all[k])) same = false;
    }
    *uvsets = sets;

    uint32_t idx;
    char mname[64];
    const char *nm;
    if ((st = gltf_string(g, o, path, "name", &nm))) return st;
    if (nm) snprintf(mname, sizeof mname, "%.60s", nm);
    else snprintf(mname, sizeof mname, "material%lld", (long long)mi);
    if ((st = scene_add_material(g->ctx, g->s, mname, &idx))) return st;
    material m = g->s->materials[idx];
    material_metallic_roughness(&m, v3(base[0], base[1], base[2]), metallic, roughness);
    m.transmission = transmission;
    m.ni = ior;
    m.clearcoat = coat;
    m.clearcoat_roughness = coat_rough;
    m.two_sided = cJSON_IsTrue(ds);
    m.ke = v3_scale(v3(emissive[0], emissive[1], emissive[2]), strength);

    const bool bake = same && first && first->has_transform;
    if ((st = make_ref(g, &t_base, true, bake, path, &m.map_kd))) goto fail;
    if ((st = make_ref(g, &t_mr, false, bake, path, &m.map_mr))) goto fail;
    if ((st = make_ref(g, &t_norm, false, bake, path, &m.map_norm))) goto fail;
    if (m.map_norm.kind) m.norm_scale = t_norm.scale;
    if (gx_used && (st = gx_apply(g, &gx, bake, path, &m))) goto fail;
    if (t_emit.present && v3_max_comp(m.ke) > 0.0f) {
        tex_ref er;
        if ((st = make_ref(g, &t_emit, true, bake, path, &er))) goto fail;
        m.map_ke = er;
    }
    if ((st = make_ref(g, &t_tr, false, bake, path, &m.map_tr))) goto fail;
    if ((st = make_ref(g, &t_cc, false, bake, path, &m.map_cc))) goto fail;
    if ((st = make_ref(g, &t_ccr, false, bake, path, &m.map_ccr))) goto fail;
    if ((st = make_ref(g, &t_ccn, false, bake, path, &m.map_ccn))) goto fail;
    if (m.map_ccn.kind) m.coat_norm_scale = t_ccn.scale;
    if (amode == 1 || amode == 2) {
        const bool tex_alpha =
            m.map_kd.kind == TEX_IMAGE && (g->s->textures[m.map_kd.tex].nc == 2 || g->s->textures[m.map_kd.tex].nc == 4);
        if (amode == 1) {
            /* MASK: the cut-out alpha * factor >= cutoff */
            int32_t mask;
            if ((st = make_mask(g, mi, tex_alpha ? m.map_kd.tex : -1, base[3], cutoff, &mask))) goto fail;
            tex_ref_init(&m.map_d);
            m.map_d = m.map_kd; /* the same uv transform and wrap */
            m.map_d.tex = mask;
        } else {
            /* BLEND: there with probability factor x the base colour texture's alpha, for every ray */
            m.blend = true;
            m.blend_alpha = base[3];
            if (tex_alpha) m.map_d = m.map_kd; /* its alpha channel (linear), the same uv transform and wrap */
        }
    }
    if (unlit) {
        /* KHR_materials_unlit: the surface shows its base colour (factor x
         * texture) whatever the lighting: it emits that radiance and
         * scatters nothing (docs/scene-format.md); the alpha modes and
         * doubleSided still apply */
        m.ke = v3(base[0], base[1], base[2]);
        tex_ref_init(&m.map_ke);
        if (m.map_kd.kind) m.map_ke = m.map_kd;
        /* COLOR_0 multiplies the base colour, so here the emission (white
         * where the primitive has no colours) */
        m.emit_vertex_color = true;
        tex_ref_init(&m.map_kd);
        tex_ref_init(&m.map_mr);
        tex_ref_init(&m.map_norm);
        material_diffuse(&m, v3s(0.0f));
        transmission = 0.0f;
    }
    if (transmission > 0.0f && thickness > 0.0f &&
        (st = make_volume(g, path, &m, transmission, thickness, att_dist, att_col,
                          t_base.present || t_mr.present || m.map_tr.kind || m.map_cc.kind || m.map_ccr.kind)))
        goto fail;
    if (gx_used && (m.volume || m.type == MAT_DIELECTRIC))
        gltf_warn(g, "%s: the boundary of a volume (KHR_materials_volume) is drawn without KHR_materials_specular, "
                     "_sheen, _iridescence and _anisotropy", path);
    g->s->materials[idx] = m;
    g->mat_uv[mi].bake = bake;
    if (bake) memcpy(g->mat_uv[mi].m, first->m, sizeof first->m);
    *out = idx;
    return PK_OK;
fail:
    g->s->materials[idx] = m;
    return st;
}

pk_status gltf_material(gltf *g, int64_t i, uint32_t *mat, int *uvsets)
{
    if (i < 0) {
        *mat = 0;
        *uvsets = 0;
        return PK_OK;
    }
    if (!g->materials[i]) {
        uint32_t m;
        int set;
        pk_status st = make_material(g, i, &m, &set);
        if (st) return st;
        g->materials[i] = m + 1;
        g->mat_uvset[i] = (uint8_t)set;
    }
    *mat = g->materials[i] - 1;
    *uvsets = g->mat_uvset[i];
    return PK_OK;
}

void gltf_materials_free(gltf *g)
{
    mem_free(&g->ctx->alloc, g->materials);
    mem_free(&g->ctx->alloc, g->mat_uvset);
    mem_free(&g->ctx->alloc, g->mat_uv);
    mem_free(&g->ctx->alloc, g->images[0]);
    mem_free(&g->ctx->alloc, g->images[1]);
}

/*
 * scene_gltf.c - glTF 2.0 assets (.gltf JSON with external or data: buffers,
 * and binary .glb): the default scene's node tree (matrix or T R S) walked
 * with the graphics state of scene_build.h, meshes used by several nodes
 * placed as instances, triangle lists, strips and fans, cameras
 * (perspective, orthographic) and KHR_lights_punctual lights. Buffers and
 * accessors are in gltf_data.c, materials and textures in gltf_material.c.
 * Errors name the JSON pointer of what is wrong: "model.gltf: /accessors/3:
 * count 100 exceeds bufferView 2 (1200 bytes)" (docs/scene-format.md).
 */
#include "gltf.h"
#include "io_util.h"
#include "readers.h"
#include "../image/image_read.h"
#include "../scene/camera.h"
#include "../scene/material.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* glTF's photometric units to the scene's radiometric ones: candela and lux
 * are lumens per steradian and per square metre; a lumen is 1/683 W at
 * 555 nm, the conversion other renderers use for glTF lights. */
#define GLTF_LUMENS_PER_WATT 683.0f
#define GLTF_DEFAULT_SIDE 512   /* the film's long side when a camera gives only its aspect */

/* ---- messages ----------------------------------------------------------------- */

pk_status gltf_fail(gltf *g, pk_status st, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return ctx_error(g->ctx, st, "%s: %s", g->name, msg);
}

void gltf_warn(gltf *g, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx_warn(g->ctx, "%s: %s", g->name, msg);
}

void gltf_warn_once(gltf *g, unsigned bit, const char *fmt, ...)
{
    if (g->warned & bit) return;
    g->warned |= bit;
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx_warn(g->ctx, "%s: %s", g->name, msg);
}

/* ---- JSON values ------------------------------------------------------------------ */

const cJSON *gltf_array(const gltf *g, const char *key)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(g->root, key);
    return cJSON_IsArray(a) ? a : NULL;
}

size_t gltf_count(const gltf *g, const char *key)
{
    const cJSON *a = gltf_array(g, key);
    return a ? (size_t)cJSON_GetArraySize(a) : 0;
}

static bool is_integer(const cJSON *v) { return cJSON_IsNumber(v) && isfinite(v->valuedouble) && v->valuedouble == floor(v->valuedouble); }

pk_status gltf_int(gltf *g, const cJSON *obj, const char *path, const char *key, int64_t lo, int64_t hi, int64_t def,
                   int64_t *out)
{
    *out = def;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return PK_OK;
    if (!is_integer(v)) return gltf_fail(g, PK_ERR_PARSE, "%s/%s: must be an integer", path, key);
    double d = v->valuedouble;
    if (d < (double)lo || d > (double)hi || d > 9.0e15 || d < -9.0e15)
        return gltf_fail(g, PK_ERR_PARSE, "%s/%s: %.0f is out of range", path, key, d);
    *out = (int64_t)d;
    return PK_OK;
}

pk_status gltf_index(gltf *g, const cJSON *obj, const char *path, const char *key, size_t limit, bool required,
                     int64_t *out)
{
    *out = -1;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return required ? gltf_fail(g, PK_ERR_PARSE, "%s: %s is required", path, key) : PK_OK;
    if (!is_integer(v) || v->valuedouble < 0) return gltf_fail(g, PK_ERR_PARSE, "%s/%s: must be an index", path, key);
    if (v->valuedouble >= (double)limit)
        return gltf_fail(g, PK_ERR_PARSE, "%s/%s: index %.0f out of range (%zu there)", path, key, v->valuedouble, limit);
    *out = (int64_t)v->valuedouble;
    return PK_OK;
}

pk_status gltf_num(gltf *g, const cJSON *obj, const char *path, const char *key, double lo, double hi, double def,
                   float *out)
{
    *out = (float)def;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return PK_OK;
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || !isfinite((float)v->valuedouble))
        return gltf_fail(g, PK_ERR_PARSE, "%s/%s: must be a finite number", path, key);
    if (v->valuedouble < lo || v->valuedouble > hi)
        return gltf_fail(g, PK_ERR_PARSE, "%s/%s: %g is out of range [%g, %g]", path, key, v->valuedouble, lo, hi);
    *out = (float)v->valuedouble;
    return PK_OK;
}

pk_status gltf_nums(gltf *g, const cJSON *obj, const char *path, const char *key, int n, float *out, bool *found)
{
    *found = false;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return PK_OK;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n)
        return gltf_fail(g, PK_ERR_PARSE, "%s/%s: must be an array of %d numbers", path, key, n);
    int k = 0;
    for (const cJSON *e = v->child; e; e = e->next, k++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || !isfinite((float)e->valuedouble))
            return gltf_fail(g, PK_ERR_PARSE, "%s/%s/%d: must be a finite number", path, key, k);
        out[k] = (float)e->valuedouble;
    }
    *found = true;
    return PK_OK;
}

pk_status gltf_string(gltf *g, const cJSON *obj, const char *path, const char *key, const char **out)
{
    *out = NULL;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return PK_OK;
    if (!cJSON_IsString(v)) return gltf_fail(g, PK_ERR_PARSE, "%s/%s: must be a string", path, key);
    *out = v->valuestring;
    return PK_OK;
}

const cJSON *gltf_ext(const cJSON *obj, const char *name)
{
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(obj, "extensions");
    return cJSON_IsObject(e) ? cJSON_GetObjectItemCaseSensitive(e, name) : NULL;
}

/* ---- the document ------------------------------------------------------------------ */

static bool ext_supported(const char *e)
{
    static const char *const known[] = {"KHR_mesh_quantization",        "KHR_texture_transform",
                                        "KHR_lights_punctual",          "KHR_materials_emissive_strength",
                                        "KHR_materials_transmission",   "KHR_materials_ior",
                                        "KHR_materials_unlit",          "KHR_materials_clearcoat",
                                        "EXT_meshopt_compression",      "KHR_draco_mesh_compression",
                                        "EXT_texture_webp",             "KHR_materials_variants",
                                        NULL};
    for (int i = 0; known[i]; i++)
        if (strcmp(e, known[i]) == 0) return true;
    return false;
}

static pk_status check_document(gltf *g)
{
    const cJSON *asset = cJSON_GetObjectItemCaseSensitive(g->root, "asset");
    if (!cJSON_IsObject(asset)) return gltf_fail(g, PK_ERR_PARSE, "/asset: required, and must be an object");
    const char *ver, *minv;
    pk_status st;
    if ((st = gltf_string(g, asset, "/asset", "version", &ver))) return st;
    if ((st = gltf_string(g, asset, "/asset", "minVersion", &minv))) return st;
    if (!ver) return gltf_fail(g, PK_ERR_PARSE, "/asset/version: required");
    if (strncmp(ver, "2.", 2) != 0)
        return gltf_fail(g, PK_ERR_UNSUPPORTED, "/asset/version: '%.16s' is not glTF 2.x", ver);
    if (minv && strcmp(minv, "2.0") != 0)
        return gltf_fail(g, PK_ERR_UNSUPPORTED, "/asset/minVersion: '%.16s' is newer than this reader's 2.0", minv);
    const cJSON *req = cJSON_GetObjectItemCaseSensitive(g->root, "extensionsRequired");
    if (req && !cJSON_IsArray(req)) return gltf_fail(g, PK_ERR_PARSE, "/extensionsRequired: must be an array");
    int k = 0;
    for (const cJSON *e = req ? req->child : NULL; e; e = e->next, k++) {
        if (!cJSON_IsString(e)) return gltf_fail(g, PK_ERR_PARSE, "/extensionsRequired/%d: must be a string", k);
        char why[700];
        if (strcmp(e->valuestring, "KHR_draco_mesh_compression") == 0 && !gltf_have_draco(g, why, sizeof why))
            return gltf_fail(g, PK_ERR_UNSUPPORTED,
                             "/extensionsRequired/%d: Draco-compressed meshes (KHR_draco_mesh_compression) are not "
                             "read here (%.200s); export the model without Draco compression",
                             k, why);
        if (strcmp(e->valuestring, "EXT_texture_webp") == 0 && !image_have_webp())
            return gltf_fail(g, PK_ERR_UNSUPPORTED,
                             "/extensionsRequired/%d: WebP textures (EXT_texture_webp) are not read here (libwebp is "
                             "needed: Debian libwebp-dev)",
                             k);
        if (strcmp(e->valuestring, "KHR_texture_basisu") == 0)
            return gltf_fail(g, PK_ERR_UNSUPPORTED,
                             "/extensionsRequired/%d: KTX2 / Basis Universal textures (KHR_texture_basisu) are not "
                             "read (no decoder); export the textures as PNG, JPEG or WebP",
                             k);
        if (!ext_supported(e->valuestring))
            return gltf_fail(g, PK_ERR_UNSUPPORTED, "/extensionsRequired/%d: extension '%.64s' is required and not supported",
                             k, e->valuestring);
    }
    const cJSON *used = cJSON_GetObjectItemCaseSensitive(g->root, "extensionsUsed");
    if (used && !cJSON_IsArray(used)) return gltf_fail(g, PK_ERR_PARSE, "/extensionsUsed: must be an array");
    for (const cJSON *e = used ? used->child : NULL; e; e = e->next) {
        if (!cJSON_IsString(e)) continue;
        if (strcmp(e->valuestring, "KHR_mesh_quantization") == 0) g->ext_quantization = true;
        if (strcmp(e->valuestring, "KHR_texture_transform") == 0) g->ext_texture_transform = true;
    }
    static const char *const arrays[] = {"buffers", "bufferViews", "accessors", "meshes", "nodes", "scenes",
                                         "materials", "textures", "images", "samplers", "cameras", "skins", NULL};
    for (int i = 0; arrays[i]; i++) {
        const cJSON *a = cJSON_GetObjectItemCaseSensitive(g->root, arrays[i]);
        if (a && !cJSON_IsArray(a)) return gltf_fail(g, PK_ERR_PARSE, "/%s: must be an array", arrays[i]);
    }
    if (cJSON_GetObjectItemCaseSensitive(g->root, "animations") && gltf_count(g, "animations"))
        gltf_warn_once(g, GW_ANIM, "/animations: not played; the model is drawn as it stands");
    return PK_OK;
}

/* ---- transforms ---------------------------------------------------------------------- */

/* A node's local transform: matrix (column-major) or T R S. */
static pk_status node_local(gltf *g, const cJSON *n, const char *path, xform *out)
{
    float mat[16], t[3] = {0, 0, 0}, r[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    bool hm, ht, hr, hs;
    pk_status st;
    if ((st = gltf_nums(g, n, path, "matrix", 16, mat, &hm))) return st;
    if ((st = gltf_nums(g, n, path, "translation", 3, t, &ht))) return st;
    if ((st = gltf_nums(g, n, path, "rotation", 4, r, &hr))) return st;
    if ((st = gltf_nums(g, n, path, "scale", 3, s, &hs))) return st;
    if (hm) {
        if (ht || hr || hs) return gltf_fail(g, PK_ERR_PARSE, "%s: both matrix and translation/rotation/scale", path);
        if (mat[3] != 0.0f || mat[7] != 0.0f || mat[11] != 0.0f || mat[15] != 1.0f)
            return gltf_fail(g, PK_ERR_PARSE, "%s/matrix: not affine (its last row is not 0 0 0 1)", path);
        for (int row = 0; row < 4; row++)
            for (int col = 0; col < 4; col++) out->m[4 * row + col] = mat[4 * col + row];
        return PK_OK;
    }
    double q[4] = {r[0], r[1], r[2], r[3]};
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(len > 1e-6)) return gltf_fail(g, PK_ERR_PARSE, "%s/rotation: not a unit quaternion", path);
    double x = q[0] / len, y = q[1] / len, z = q[2] / len, w = q[3] / len;
    double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                   2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                   2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    *out = xform_identity();
    for (int row = 0; row < 3; row++) {
        for (int col = 0; col < 3; col++) out->m[4 * row + col] = (float)(R[3 * row + col] * (double)s[col]);
        out->m[4 * row + 3] = t[row];
    }
    return PK_OK;
}

/* ---- meshes ------------------------------------------------------------------------------ */

/* The triangles of a primitive's vertex list (indices or 0..n-1) by mode. */
static pk_status triangulate(gltf *g, const char *path, int mode, const uint32_t *idx, size_t n, size_t nverts,
                             uint32_t **tris, size_t *ntris)
{
    *tris = NULL;
    *ntris = 0;
    size_t nt = mode == 4 ? n / 3 : n >= 3 ? n - 2 : 0;
    if (mode == 4 && n % 3) gltf_warn(g, "%s: %zu vertices is not a multiple of 3; the last %zu ignored", path, n, n % 3);
    if (!nt) return PK_OK;
    for (size_t k = 0; k < n; k++) {
        uint32_t v = idx ? idx[k] : (uint32_t)k;
        if (v >= nverts)
            return gltf_fail(g, PK_ERR_PARSE, "%s/indices: index %u out of range (%zu vertices)", path, v, nverts);
    }
    uint32_t *t = mem_calloc(&g->ctx->alloc, nt, 3 * sizeof *t);
    if (!t) return ctx_nomem(g->ctx);
#define V(k) (idx ? idx[k] : (uint32_t)(k))
    for (size_t i = 0; i < nt; i++) {
        uint32_t *o = t + 3 * i;
        if (mode == 4) o[0] = V(3 * i), o[1] = V(3 * i + 1), o[2] = V(3 * i + 2);
        else if (mode == 5) { /* strips: every other triangle turned to keep the winding */
            o[0] = V(i);
            o[1] = V(i + 1 + i % 2);
            o[2] = V(i + 2 - i % 2);
        } else { /* fans about the first vertex */
            o[0] = V(i + 1), o[1] = V(i + 2), o[2] = V(0);
        }
    }
#undef V
    *tris = t;
    *ntris = nt;
    return PK_OK;
}

/* One vertex attribute of a primitive as floats (*out NULL when absent);
 * ap: the JSON pointer of attrs. Integers that are not normalized are read
 * as their values (warned unless ints: joint numbers). */
static pk_status attribute_in(gltf *g, const cJSON *attrs, const char *ap, const char *key, int ncomp, bool required,
                              bool ints, size_t *count, float **out)
{
    *out = NULL;
    int64_t ai;
    pk_status st = gltf_index(g, attrs, ap, key, gltf_count(g, "accessors"), required, &ai);
    if (st || ai < 0) return st;
    gltf_accessor a;
    if ((st = gltf_accessor_get(g, ai, &a))) return st;
    if (a.ncomp != ncomp || a.matrix)
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: %s must have %d components", (long long)ai, key, ncomp);
    if (ints && (a.ctype == 5126 || a.normalized))
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: %s must be unsigned bytes or shorts", (long long)ai, key);
    if (!ints && a.ctype != 5126 && !g->ext_quantization && !a.normalized)
        gltf_warn(g, "/accessors/%lld: integer %s without KHR_mesh_quantization declared; read as its values",
                  (long long)ai, key);
    if (*count && a.count != *count)
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: %s has %zu elements, POSITION %zu", (long long)ai, key,
                         a.count, *count);
    *count = a.count;
    return gltf_read_floats(g, ai, &a, out);
}

static pk_status attribute(gltf *g, const cJSON *attrs, const char *path, const char *key, int ncomp, bool required,
                           size_t *count, float **out)
{
    char ap[128];
    snprintf(ap, sizeof ap, "%s/attributes", path);
    return attribute_in(g, attrs, ap, key, ncomp, required, false, count, out);
}

/* The accessor of COLOR_0 in attrs at ap (a primitive's or a morph
 * target's), checked: a VEC3 or VEC4 of floats or (deltas aside)
 * normalized unsigned bytes or shorts; -1 when absent. */
static pk_status color_accessor(gltf *g, const cJSON *attrs, const char *ap, bool deltas, int64_t *ai, int *ncomp)
{
    pk_status st = gltf_index(g, attrs, ap, "COLOR_0", gltf_count(g, "accessors"), false, ai);
    if (st || *ai < 0) return st;
    gltf_accessor a;
    if ((st = gltf_accessor_get(g, *ai, &a))) return st;
    const bool unorm = a.normalized && (a.ctype == 5121 || a.ctype == 5123);
    const bool snorm = a.normalized && (a.ctype == 5120 || a.ctype == 5122);
    if (a.matrix || (a.ncomp != 3 && a.ncomp != 4) || !(a.ctype == 5126 || unorm || (deltas && snorm)))
        return gltf_fail(g, PK_ERR_PARSE,
                         deltas ? "/accessors/%lld: COLOR_0 displacements must be a VEC3 or VEC4 of floats or "
                                  "normalized integers"
                                : "/accessors/%lld: COLOR_0 must be a VEC3 or VEC4 of floats or normalized unsigned "
                                  "bytes or shorts",
                         (long long)*ai);
    *ncomp = a.ncomp;
    return PK_OK;
}

/* COLOR_0 (VEC3 or VEC4 of floats or normalized unsigned bytes or shorts)
 * as RGBA (alpha 1 for VEC3), *out NULL when absent. */
static pk_status read_colors(gltf *g, const cJSON *attrs, const char *path, size_t *count, float **out)
{
    *out = NULL;
    char ap[128];
    snprintf(ap, sizeof ap, "%s/attributes", path);
    int64_t ai;
    int ncomp = 0;
    pk_status st = color_accessor(g, attrs, ap, false, &ai, &ncomp);
    if (st || ai < 0) return st;
    float *c = NULL;
    if ((st = attribute_in(g, attrs, ap, "COLOR_0", ncomp, false, false, count, &c))) return st;
    if (ncomp == 4) {
        *out = c;
        return PK_OK;
    }
    float *c4 = mem_calloc(&g->ctx->alloc, *count, 4 * sizeof *c4);
    if (!c4) {
        mem_free(&g->ctx->alloc, c);
        return ctx_nomem(g->ctx);
    }
    for (size_t k = 0; k < *count; k++) {
        c4[4 * k] = c[3 * k], c4[4 * k + 1] = c[3 * k + 1], c4[4 * k + 2] = c[3 * k + 2];
        c4[4 * k + 3] = 1.0f;
    }
    mem_free(&g->ctx->alloc, c);
    *out = c4;
    return PK_OK;
}

/* Applies the morph targets of primitive p (at path) with weights w[0..nw)
 * to its n vertices: each target's displacements times its weight are
 * added to the positions, the normals (nrm, may be NULL), the texture
 * coordinates (uv and uv1, TEXCOORD_0 and _1; may be NULL) and the colours (col, RGBA;
 * may be NULL; a VEC3 displacement leaves alpha). TANGENT displacements are
 * not read: a morphed primitive's tangents are generated from its posed
 * shape. */
static pk_status apply_morph(gltf *g, const cJSON *p, const char *path, const float *w, size_t nw, size_t n,
                             float *pos, float *nrm, float *uv, float *uv1, float *col)
{
    const cJSON *targets = cJSON_GetObjectItemCaseSensitive(p, "targets");
    if (!targets) return PK_OK;
    if (!cJSON_IsArray(targets)) return gltf_fail(g, PK_ERR_PARSE, "%s/targets: must be an array", path);
    size_t nt = (size_t)cJSON_GetArraySize(targets);
    if (nw && nw != nt)
        gltf_warn_once(g, GW_MORPH, "%s/targets: %zu targets and %zu weights; the missing weights are 0", path, nt, nw);
    size_t k = 0;
    for (const cJSON *t = targets->child; t; t = t->next, k++) {
        char tp[128];
        snprintf(tp, sizeof tp, "%s/targets/%zu", path, k);
        if (!cJSON_IsObject(t)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", tp);
        const float wk = k < nw ? w[k] : 0.0f;
        if (wk == 0.0f) continue;
        for (int a = 0; a < 5; a++) {
            static const char *const keys[5] = {"POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0", "TEXCOORD_1"};
            float *dst = a == 0 ? pos : a == 1 ? nrm : a == 2 ? uv : a == 3 ? col : uv1, *d = NULL;
            if (!dst) continue;
            int nc = a == 2 || a == 4 ? 2 : 3, stride = a == 3 ? 4 : nc;
            pk_status st;
            if (a == 3) {
                int64_t ci;
                if ((st = color_accessor(g, t, tp, true, &ci, &nc))) return st;
                if (ci < 0) continue;
            }
            size_t cnt = n;
            st = attribute_in(g, t, tp, keys[a], nc, false, false, &cnt, &d);
            if (st) return st;
            if (!d) continue;
            for (size_t i = 0; i < n; i++)
                for (int c = 0; c < nc; c++) dst[(size_t)stride * i + (size_t)c] += wk * d[(size_t)nc * i + (size_t)c];
            mem_free(&g->ctx->alloc, d);
        }
    }
    return PK_OK;
}

/* KHR_materials_variants: the material that primitive p's mappings give
 * the chosen variant (*mat unchanged when none names it). */
static pk_status variant_material(gltf *g, const cJSON *p, const char *path, int64_t *mat)
{
    const cJSON *e = gltf_ext(p, "KHR_materials_variants");
    if (!e) return PK_OK;
    char ep[160];
    snprintf(ep, sizeof ep, "%s/extensions/KHR_materials_variants/mappings", path);
    const cJSON *maps = cJSON_IsObject(e) ? cJSON_GetObjectItemCaseSensitive(e, "mappings") : NULL;
    if (!cJSON_IsArray(maps)) return gltf_fail(g, PK_ERR_PARSE, "%s: required, and must be an array", ep);
    int k = 0;
    for (const cJSON *m = maps->child; m; m = m->next, k++) {
        char mp[192];
        snprintf(mp, sizeof mp, "%s/%d", ep, k);
        if (!cJSON_IsObject(m)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", mp);
        const cJSON *vs = cJSON_GetObjectItemCaseSensitive(m, "variants");
        if (!cJSON_IsArray(vs)) return gltf_fail(g, PK_ERR_PARSE, "%s/variants: required, and must be an array", mp);
        bool hit = false;
        for (const cJSON *v = vs->child; v; v = v->next) {
            if (!is_integer(v) || v->valuedouble < 0)
                return gltf_fail(g, PK_ERR_PARSE, "%s/variants: not a variant index", mp);
            hit |= v->valuedouble == (double)g->variant;
        }
        if (!hit) continue;
        pk_status st = gltf_index(g, m, mp, "material", gltf_count(g, "materials"), true, mat);
        return st;
    }
    return PK_OK;
}

/* Finds the variant asked for among the asset's; an error naming them when
 * it is not one. */
static pk_status find_variant(gltf *g)
{
    g->variant = -1;
    if (!g->variant_name) return PK_OK;
    const cJSON *vs = cJSON_GetObjectItemCaseSensitive(gltf_ext(g->root, "KHR_materials_variants"), "variants");
    char list[512] = "";
    size_t at = 0;
    int k = 0;
    for (const cJSON *v = cJSON_IsArray(vs) ? vs->child : NULL; v; v = v->next, k++) {
        const cJSON *n = cJSON_IsObject(v) ? cJSON_GetObjectItemCaseSensitive(v, "name") : NULL;
        if (!cJSON_IsString(n))
            return gltf_fail(g, PK_ERR_PARSE, "/extensions/KHR_materials_variants/variants/%d/name: required, and must "
                                              "be a string", k);
        if (strcmp(n->valuestring, g->variant_name) == 0) {
            g->variant = k;
            return PK_OK;
        }
        if (at < sizeof list - 1)
            at += (size_t)snprintf(list + at, sizeof list - at, "%s'%.64s'", k ? ", " : "", n->valuestring);
    }
    if (!k)
        return gltf_fail(g, PK_ERR_INVALID_ARGUMENT, "variant '%.64s': the asset has no material variants",
                         g->variant_name);
    return gltf_fail(g, PK_ERR_INVALID_ARGUMENT, "variant '%.64s' is not one of the asset's: %s", g->variant_name, list);
}

/* Linear blend skinning with the node's joint matrices (g->skin): each
 * vertex moves by the sum of its joints' matrices times their weights (the
 * weights divided by their sum), over every set JOINTS_k / WEIGHTS_k (four
 * joints each); normals by the inverse transpose of that sum. */
#define GLTF_MAX_JOINT_SETS 8
static pk_status apply_skin(gltf *g, const cJSON *attrs, const char *path, size_t n, float *pos, float *nrm)
{
    float *jn = NULL, *wt = NULL, *acc = NULL; /* acc: per vertex the 12 summed matrix entries and the weights' sum */
    char ap[128];
    snprintf(ap, sizeof ap, "%s/attributes", path);
    pk_status st = PK_OK;
    int sets = 0;
    for (int k = 0; k < GLTF_MAX_JOINT_SETS; k++) {
        char jk[16], wk[16];
        snprintf(jk, sizeof jk, "JOINTS_%d", k);
        snprintf(wk, sizeof wk, "WEIGHTS_%d", k);
        size_t cnt = n;
        if ((st = attribute_in(g, attrs, ap, jk, 4, false, true, &cnt, &jn))) goto out;
        if ((st = attribute_in(g, attrs, ap, wk, 4, false, false, &cnt, &wt))) goto out;
        if (!jn || !wt) {
            if (jn || wt)
                gltf_warn_once(g, GW_SKIN, "%s: %s without %s is not used", path, jn ? jk : wk, jn ? wk : jk);
            break;
        }
        if (!acc && !(acc = mem_calloc(&g->ctx->alloc, n ? n : 1, 13 * sizeof *acc))) {
            st = ctx_nomem(g->ctx);
            goto out;
        }
        for (size_t i = 0; i < n; i++) {
            float *m = acc + 13 * i;
            for (int c = 0; c < 4; c++) {
                const float w = wt[4 * i + c], j = jn[4 * i + c];
                if (w == 0.0f) continue;
                if (!(j >= 0.0f) || j >= (float)g->nskin) {
                    st = gltf_fail(g, PK_ERR_PARSE,
                                   "%s/attributes/%s: joint %.0f of vertex %zu is not one of the skin's %zu", path, jk,
                                   (double)j, i, g->nskin);
                    goto out;
                }
                const xform *J = &g->skin[(size_t)j];
                for (int e = 0; e < 12; e++) m[e] += w * J->m[e];
                m[12] += w;
            }
        }
        mem_free(&g->ctx->alloc, jn);
        mem_free(&g->ctx->alloc, wt);
        jn = wt = NULL;
        sets++;
    }
    if (!sets) {
        gltf_warn_once(g, GW_SKIN, "%s: a skinned node's mesh without JOINTS_0 and WEIGHTS_0 is drawn as it stands", path);
        goto out;
    }
    for (size_t i = 0; i < n; i++) {
        const float *a = acc + 13 * i, sum = a[12];
        if (!(sum > 0.0f)) continue; /* no weight: left where it is */
        xform m;
        memset(&m, 0, sizeof m);
        for (int e = 0; e < 12; e++) m.m[e] = a[e] / sum;
        m.m[15] = 1.0f;
        vec3 *q = (vec3 *)(pos + 3 * i);
        *q = xform_point(&m, *q);
        if (nrm) {
            float nm[9];
            xform_normal_cofactors(&m, nm);
            vec3 *nq = (vec3 *)(nrm + 3 * i);
            *nq = xform_apply3(nm, *nq);
        }
    }
out:
    mem_free(&g->ctx->alloc, jn);
    mem_free(&g->ctx->alloc, wt);
    mem_free(&g->ctx->alloc, acc);
    return st;
}


/* ---- tangents --------------------------------------------------------------------------- */

/* A vertex's key for welding: its position, normal and uv bits. */
typedef struct weld_key {
    float f[8];
    uint32_t i;
} weld_key;

static int weld_cmp(const void *a, const void *b)
{
    const int c = memcmp(((const weld_key *)a)->f, ((const weld_key *)b)->f, sizeof ((const weld_key *)a)->f);
    if (c) return c;
    const uint32_t x = ((const weld_key *)a)->i, y = ((const weld_key *)b)->i;
    return x < y ? -1 : x > y;
}

/* Tangents for n vertices (pos, unit nrm, uv in the scene's convention: v
 * up) of triangles tris, after Mikkelsen's "Simulation of wrinkled surfaces
 * revisited" (the MikkTSpace of other tools): each triangle's dp/du from its
 * uv derivatives, projected on the tangent plane of each corner's normal
 * and weighted by the corner's angle there, summed over the corners of
 * vertices equal in position, normal and uv (welded, whatever their
 * indices) and of the same uv orientation (the sign of the uv area), then
 * made perpendicular to the normal; the handedness is that orientation.
 * Triangles without uv area add nothing (their vertices take their
 * neighbours' tangents); a vertex left without any gets one perpendicular
 * to its normal. Where one vertex index has corners of both orientations,
 * the heavier one is kept. *out: 4 floats a vertex. */
static pk_status gen_tangents(gltf *g, const float *pos, const float *nrm, const float *uv, size_t n,
                              const uint32_t *tris, size_t ntris, float **out)
{
    *out = NULL;
    const pk_allocator *al = &g->ctx->alloc;
    weld_key *keys = mem_calloc(al, n ? n : 1, sizeof *keys);
    uint32_t *weld = mem_calloc(al, n ? n : 1, sizeof *weld);
    float *acc = mem_calloc(al, n ? n : 1, 8 * sizeof *acc); /* per weld id and orientation: x y z weight */
    float *t = mem_calloc(al, n ? n : 1, 4 * sizeof *t);
    if (!keys || !weld || !acc || !t) {
        mem_free(al, keys), mem_free(al, weld), mem_free(al, acc), mem_free(al, t);
        return ctx_nomem(g->ctx);
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(keys[i].f, pos + 3 * i, 3 * sizeof(float));
        memcpy(keys[i].f + 3, nrm + 3 * i, 3 * sizeof(float));
        memcpy(keys[i].f + 6, uv + 2 * i, 2 * sizeof(float));
        for (int c = 0; c < 8; c++)
            if (keys[i].f[c] == 0.0f) keys[i].f[c] = 0.0f; /* -0 welds with 0 */
        keys[i].i = (uint32_t)i;
    }
    qsort(keys, n, sizeof *keys, weld_cmp);
    for (size_t k = 0; k < n; k++) /* a weld id: the first index of its run */
        weld[keys[k].i] = k && memcmp(keys[k].f, keys[k - 1].f, sizeof keys[k].f) == 0 ? weld[keys[k - 1].i] : keys[k].i;
    for (size_t f = 0; f < ntris; f++) {
        const uint32_t *v = tris + 3 * f;
        const vec3 p0 = v3(pos[3 * v[0]], pos[3 * v[0] + 1], pos[3 * v[0] + 2]);
        const vec3 e1 = v3_sub(v3(pos[3 * v[1]], pos[3 * v[1] + 1], pos[3 * v[1] + 2]), p0);
        const vec3 e2 = v3_sub(v3(pos[3 * v[2]], pos[3 * v[2] + 1], pos[3 * v[2] + 2]), p0);
        const float du1 = uv[2 * v[1]] - uv[2 * v[0]], dv1 = uv[2 * v[1] + 1] - uv[2 * v[0] + 1];
        const float du2 = uv[2 * v[2]] - uv[2 * v[0]], dv2 = uv[2 * v[2] + 1] - uv[2 * v[0] + 1];
        const float det = du1 * dv2 - dv1 * du2;
        if (!(fabsf(det) > 0.0f) || !isfinite(1.0f / det)) continue; /* no uv area */
        const vec3 dpdu = v3_norm_scaled(v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), det > 0.0f ? 1.0f : -1.0f));
        if (!v3_finite(dpdu) || !(v3_len2(dpdu) > 0.0f)) continue;
        const int o = det > 0.0f ? 0 : 1;
        for (int j = 0; j < 3; j++) {
            const uint32_t i = v[j];
            const vec3 nn = v3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
            const vec3 pi = v3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
            const uint32_t a = v[(j + 1) % 3], b = v[(j + 2) % 3];
            /* the corner's edges in the normal's tangent plane, and the angle between them */
            vec3 ea = v3_sub(v3(pos[3 * a], pos[3 * a + 1], pos[3 * a + 2]), pi);
            vec3 eb = v3_sub(v3(pos[3 * b], pos[3 * b + 1], pos[3 * b + 2]), pi);
            ea = v3_norm_scaled(v3_sub(ea, v3_scale(nn, v3_dot(nn, ea))));
            eb = v3_norm_scaled(v3_sub(eb, v3_scale(nn, v3_dot(nn, eb))));
            float ang = acosf(fminf(fmaxf(v3_dot(ea, eb), -1.0f), 1.0f));
            if (!isfinite(ang)) ang = 0.0f;
            const vec3 tp = v3_norm_scaled(v3_sub(dpdu, v3_scale(nn, v3_dot(nn, dpdu))));
            if (!v3_finite(tp)) continue;
            float *s = acc + 8 * (size_t)weld[i] + 4 * o;
            s[0] += ang * tp.x, s[1] += ang * tp.y, s[2] += ang * tp.z, s[3] += ang;
        }
    }
    for (size_t i = 0; i < n; i++) {
        const float *s = acc + 8 * (size_t)weld[i];
        /* the heavier orientation (the corners' total angle) */
        const int o = s[7] > s[3] ? 1 : 0;
        const vec3 nn = v3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
        vec3 x = v3(s[4 * o], s[4 * o + 1], s[4 * o + 2]);
        x = v3_norm_scaled(v3_sub(x, v3_scale(nn, v3_dot(nn, x))));
        if (!v3_finite(x) || !(v3_len2(x) > 0.5f)) { /* nothing to go by: any direction across the normal */
            const vec3 ax = fabsf(nn.x) < 0.9f ? v3(1.0f, 0.0f, 0.0f) : v3(0.0f, 1.0f, 0.0f);
            x = v3_norm_scaled(v3_sub(ax, v3_scale(nn, v3_dot(nn, ax))));
            if (!v3_finite(x)) x = v3(1.0f, 0.0f, 0.0f);
        }
        t[4 * i] = x.x, t[4 * i + 1] = x.y, t[4 * i + 2] = x.z;
        t[4 * i + 3] = o ? -1.0f : 1.0f;
    }
    mem_free(al, keys), mem_free(al, weld), mem_free(al, acc);
    *out = t;
    return PK_OK;
}

/* TANGENT (VEC4 of floats or normalized signed bytes or shorts) with unit
 * xyz and w = +1 or -1; *out NULL when absent. */
static pk_status read_tangents(gltf *g, const cJSON *attrs, const char *path, size_t *count, float **out)
{
    *out = NULL;
    char ap[128];
    snprintf(ap, sizeof ap, "%s/attributes", path);
    int64_t ai;
    pk_status st = gltf_index(g, attrs, ap, "TANGENT", gltf_count(g, "accessors"), false, &ai);
    if (st || ai < 0) return st;
    float *t = NULL;
    if ((st = attribute_in(g, attrs, ap, "TANGENT", 4, false, false, count, &t))) return st;
    for (size_t k = 0; k < *count; k++) {
        vec3 x = v3_norm_scaled(v3(t[4 * k], t[4 * k + 1], t[4 * k + 2]));
        if (!v3_finite(x)) x = v3s(0.0f);
        t[4 * k] = x.x, t[4 * k + 1] = x.y, t[4 * k + 2] = x.z;
        t[4 * k + 3] = t[4 * k + 3] < 0.0f ? -1.0f : 1.0f;
    }
    *out = t;
    return PK_OK;
}

/* Adds primitive p of mesh mi through the builder's current transform,
 * morphed by weights w[0..nw) and skinned by g->skin when set. */
static pk_status add_primitive(gltf *g, int64_t mi, int pi, const cJSON *p, bool flip, const float *w, size_t nw)
{
    char path[96];
    snprintf(path, sizeof path, "/meshes/%lld/primitives/%d", (long long)mi, pi);
    if (!cJSON_IsObject(p)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    pk_status st;
    int64_t mode, ii, mat;
    if ((st = gltf_int(g, p, path, "mode", 0, 6, 4, &mode))) return st;
    if (mode < 4) {
        gltf_warn_once(g, GW_POINTS, "%s: points and lines are not drawn (further ones not reported)", path);
        return PK_OK;
    }
    if (gltf_ext(p, "KHR_draco_mesh_compression") && (st = gltf_draco_primitive(g, p, path))) return st;
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(p, "attributes");
    if (!cJSON_IsObject(attrs)) return gltf_fail(g, PK_ERR_PARSE, "%s/attributes: required, and must be an object", path);
    if ((st = gltf_index(g, p, path, "indices", gltf_count(g, "accessors"), false, &ii))) return st;
    if ((st = gltf_index(g, p, path, "material", gltf_count(g, "materials"), false, &mat))) return st;
    if (g->variant >= 0 && (st = variant_material(g, p, path, &mat))) return st;
    uint32_t smat;
    int uvsets;
    if ((st = gltf_material(g, mat, &smat, &uvsets))) return st;

    float *pos = NULL, *nrm = NULL, *uv = NULL, *uv1 = NULL, *tmp = NULL, *col = NULL, *tan = NULL;
    uint32_t *idx = NULL, *tris = NULL;
    size_t n = 0, ntris = 0;
    if ((st = attribute(g, attrs, path, "POSITION", 3, true, &n, &pos))) goto out;
    if ((st = attribute(g, attrs, path, "NORMAL", 3, false, &n, &nrm))) goto out;
    if ((st = attribute(g, attrs, path, "TEXCOORD_0", 2, false, &n, &uv))) goto out;
    if ((uvsets & 2) && (st = attribute(g, attrs, path, "TEXCOORD_1", 2, false, &n, &uv1))) goto out;
    if ((uvsets & 2) && !uv1 && uv)
        gltf_warn_once(g, GW_UV1, "%s/attributes: a texture of the material reads TEXCOORD_1, which the primitive does "
                       "not have; it reads TEXCOORD_0 (further ones not reported)", path);
    if ((st = read_colors(g, attrs, path, &n, &col))) goto out;
    /* the vertex tangents, for the frame of a normal map or of anisotropic roughness */
    const material *sm = &g->s->materials[smat];
    const bool want_tan = sm->map_norm.kind != TEX_NONE || sm->map_ccn.kind != TEX_NONE || material_anisotropic(sm);
    bool posed = g->skin != NULL;
    for (size_t k = 0; k < nw; k++) posed |= w[k] != 0.0f && cJSON_GetObjectItemCaseSensitive(p, "targets");
    if (want_tan && !posed && (st = read_tangents(g, attrs, path, &n, &tan))) goto out;
    if ((st = apply_morph(g, p, path, w, nw, n, pos, nrm, uv, uv1, col))) goto out;
    if (g->skin && (st = apply_skin(g, attrs, path, n, pos, nrm))) goto out;
    size_t nidx = n;
    if (ii >= 0) {
        gltf_accessor a;
        if ((st = gltf_accessor_get(g, ii, &a))) goto out;
        if ((st = gltf_read_uints(g, ii, &a, &idx))) goto out;
        nidx = a.count;
    }
    if ((st = triangulate(g, path, (int)mode, idx, nidx, n, &tris, &ntris))) goto out;
    for (int set = 0; set < 2; set++) {
        float *t = set ? uv1 : uv;
        const gltf_uv_xform *x = mat >= 0 ? &g->mat_uv[mat] : NULL;
        for (size_t k = 0; t && k < n; k++) {
            float u = t[2 * k], v = t[2 * k + 1];
            if (x && x->bake) {
                float u2 = x->m[0] * u + x->m[1] * v + x->m[2], v2 = x->m[3] * u + x->m[4] * v + x->m[5];
                u = u2, v = v2;
            }
            t[2 * k] = u;
            t[2 * k + 1] = 1.0f - v; /* glTF's v runs down the image, the scene's up */
        }
    }
    if (nrm) /* unit normals as the specification requires (quantized ones are not) */
        for (size_t k = 0; k < n; k++) {
            vec3 *q = (vec3 *)(nrm + 3 * k);
            *q = v3_norm_scaled(*q);
            if (!v3_finite(*q)) *q = v3s(0.0f);
        }
    /* generated in the uv set of the normal map (or of the anisotropy's direction map) */
    const float *tuv = (sm->map_norm.kind ? sm->map_norm.uvset : sm->map_aniso.uvset) && uv1 ? uv1 : uv;
    if (want_tan && !tan && nrm && tuv && (st = gen_tangents(g, pos, nrm, tuv, n, tris, ntris, &tan))) goto out;
    if (col && smat == 0) { /* the default material with the colours: a copy of its own */
        if (!g->vc_default) {
            uint32_t c;
            if ((st = scene_material_copy(g->ctx, g->s, 0, "default+COLOR_0", &c))) goto out;
            g->vc_default = c;
        }
        smat = g->vc_default;
    }
    if (col) g->s->materials[smat].vertex_color = true;
    sb_set_material(&g->b, smat);
    const size_t pbase = g->s->npositions;
    sb_mesh m = {(const vec3 *)pos, (const vec3 *)nrm, uv, n, tris, ntris, flip};
    st = sb_add_mesh(&g->b, &m);
    for (size_t k = 0; col && st == PK_OK && k < n; k++) {
        const float *c = col + 4 * k;
        st = scene_set_color(g->ctx, g->s, pbase + k, (rgba){c[0], c[1], c[2], c[3]});
    }
    /* the second set where a texture reads it (TEXCOORD_0 where the primitive has none) */
    const float *t1 = uv1 ? uv1 : uv;
    for (size_t k = 0; t1 && (uvsets & 2) && st == PK_OK && k < n; k++)
        st = scene_set_uv1(g->ctx, g->s, pbase + k, (uv2){t1[2 * k], t1[2 * k + 1]});
    if (tan && st == PK_OK) { /* through the transform; a mirroring one turns the handedness */
        const xform *x = sb_transform(&g->b);
        const float hand = xform_det3(x) < 0.0 ? -1.0f : 1.0f;
        for (size_t k = 0; st == PK_OK && k < n; k++) {
            const float *c = tan + 4 * k;
            vtangent vt = {v3_norm_scaled(xform_vector(x, v3(c[0], c[1], c[2]))), c[3] * hand};
            if (!v3_finite(vt.t) || !(v3_len2(vt.t) > 0.0f)) vt = (vtangent){{0.0f, 0.0f, 0.0f}, 0.0f};
            st = scene_set_tangent(g->ctx, g->s, pbase + k, vt);
        }
    }
out:
    mem_free(&g->ctx->alloc, col);
    mem_free(&g->ctx->alloc, tan);
    mem_free(&g->ctx->alloc, pos);
    mem_free(&g->ctx->alloc, nrm);
    mem_free(&g->ctx->alloc, uv);
    mem_free(&g->ctx->alloc, uv1);
    mem_free(&g->ctx->alloc, tmp);
    mem_free(&g->ctx->alloc, idx);
    mem_free(&g->ctx->alloc, tris);
    return st;
}

#define GLTF_MAX_WEIGHTS 256   /* morph targets of a mesh applied */

/* obj's weights array (none: *n = 0) into w. */
static pk_status weights(gltf *g, const cJSON *obj, const char *path, float *w, size_t *n)
{
    *n = 0;
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, "weights");
    if (!a) return PK_OK;
    if (!cJSON_IsArray(a)) return gltf_fail(g, PK_ERR_PARSE, "%s/weights: must be an array of numbers", path);
    size_t k = 0;
    for (const cJSON *e = a->child; e; e = e->next, k++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || !isfinite((float)e->valuedouble))
            return gltf_fail(g, PK_ERR_PARSE, "%s/weights/%zu: must be a finite number", path, k);
        if (k >= GLTF_MAX_WEIGHTS) {
            gltf_warn_once(g, GW_MORPH, "%s/weights: morph targets past the first %d are not applied", path,
                           GLTF_MAX_WEIGHTS);
            break;
        }
        w[k] = (float)e->valuedouble;
    }
    *n = k;
    return PK_OK;
}

static pk_status add_mesh(gltf *g, int64_t mi, bool flip)
{
    const cJSON *m = cJSON_GetArrayItem(gltf_array(g, "meshes"), (int)mi);
    char path[48];
    snprintf(path, sizeof path, "/meshes/%lld", (long long)mi);
    if (!cJSON_IsObject(m)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(m, "primitives");
    if (!cJSON_IsArray(prims)) return gltf_fail(g, PK_ERR_PARSE, "%s/primitives: required, and must be an array", path);
    /* the node's morph weights, else the mesh's own, else none */
    float mw[GLTF_MAX_WEIGHTS];
    const float *w = g->node_weights;
    size_t nw = g->nnode_weights;
    pk_status st;
    if (!w && (st = weights(g, m, path, mw, &nw))) return st;
    if (!w) w = mw;
    int k = 0;
    for (const cJSON *p = prims->child; p; p = p->next, k++)
        if ((st = add_primitive(g, mi, k, p, flip, w, nw))) return st;
    return PK_OK;
}

/* ---- cameras and lights ----------------------------------------------------------------- */

static void set_film(gltf *g, float aspect)
{
    int w = GLTF_DEFAULT_SIDE, h = GLTF_DEFAULT_SIDE;
    if (aspect >= 1.0f) h = (int)lroundf((float)GLTF_DEFAULT_SIDE / aspect);
    else w = (int)lroundf((float)GLTF_DEFAULT_SIDE * aspect);
    /* both within 1..GLTF_DEFAULT_SIDE, inside the options' ranges */
    (void)scene_render_int(g->ctx, g->s, "width", w < 1 ? 1 : w);
    (void)scene_render_int(g->ctx, g->s, "height", h < 1 ? 1 : h);
}

static pk_status place_camera(gltf *g, int64_t ci, const xform *x, int64_t node)
{
    const cJSON *c = cJSON_GetArrayItem(gltf_array(g, "cameras"), (int)ci);
    char path[48], sp[64];
    snprintf(path, sizeof path, "/cameras/%lld", (long long)ci);
    if (!cJSON_IsObject(c)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const char *type;
    pk_status st;
    if ((st = gltf_string(g, c, path, "type", &type))) return st;
    if (!type) return gltf_fail(g, PK_ERR_PARSE, "%s: type is required", path);
    pk_camera cam;
    vec3 o = xform_point(x, v3s(0.0f));
    vec3 fwd = v3_norm_scaled(xform_vector(x, v3(0.0f, 0.0f, -1.0f)));
    vec3 up = v3_norm_scaled(xform_vector(x, v3(0.0f, 1.0f, 0.0f)));
    camera_look(&cam, o, v3_add(o, fwd), up);
    if (strcmp(type, "perspective") == 0) {
        snprintf(sp, sizeof sp, "%s/perspective", path);
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(c, "perspective");
        if (!cJSON_IsObject(p)) return gltf_fail(g, PK_ERR_PARSE, "%s: required, and must be an object", sp);
        float yfov, aspect;
        if ((st = gltf_num(g, p, sp, "yfov", 1e-6, 3.14159, -1.0, &yfov))) return st;
        if (yfov < 0.0f) return gltf_fail(g, PK_ERR_PARSE, "%s: yfov is required", sp);
        if ((st = gltf_num(g, p, sp, "aspectRatio", 1e-4, 1e4, 0.0, &aspect))) return st;
        cam.fov_deg = yfov * (180.0f / (float)PK_PI);
        if (aspect > 0.0f) set_film(g, aspect);
    } else if (strcmp(type, "orthographic") == 0) {
        snprintf(sp, sizeof sp, "%s/orthographic", path);
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(c, "orthographic");
        if (!cJSON_IsObject(p)) return gltf_fail(g, PK_ERR_PARSE, "%s: required, and must be an object", sp);
        float xmag, ymag;
        if ((st = gltf_num(g, p, sp, "xmag", -1e30, 1e30, 0.0, &xmag))) return st;
        if ((st = gltf_num(g, p, sp, "ymag", -1e30, 1e30, 0.0, &ymag))) return st;
        xmag = fabsf(xmag), ymag = fabsf(ymag);
        if (!(xmag > 0.0f) || !(ymag > 0.0f)) return gltf_fail(g, PK_ERR_PARSE, "%s: xmag and ymag must not be zero", sp);
        cam.projection = PK_PROJECTION_ORTHOGRAPHIC;
        cam.ortho_width = 2.0f * xmag;
        set_film(g, xmag / ymag);
    } else {
        return gltf_fail(g, PK_ERR_PARSE, "%s/type: '%.16s' is not perspective or orthographic", path, type);
    }
    if (scene_set_camera(g->s, &cam) != CAMERA_OK)
        return gltf_fail(g, PK_ERR_PARSE, "/nodes/%lld: the transform gives camera %lld no usable view", (long long)node,
                         (long long)ci);
    g->camera_done = true;
    return PK_OK;
}

static pk_status place_light(gltf *g, int64_t li, const xform *x)
{
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(gltf_ext(g->root, "KHR_lights_punctual"), "lights");
    const cJSON *l = cJSON_GetArrayItem(lights, (int)li);
    char path[80], sp[96];
    snprintf(path, sizeof path, "/extensions/KHR_lights_punctual/lights/%lld", (long long)li);
    if (!cJSON_IsObject(l)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const char *type;
    float col[3] = {1, 1, 1}, inten, inner, outer;
    bool found;
    pk_status st;
    if ((st = gltf_string(g, l, path, "type", &type))) return st;
    if (!type) return gltf_fail(g, PK_ERR_PARSE, "%s: type is required", path);
    if ((st = gltf_nums(g, l, path, "color", 3, col, &found))) return st;
    for (int k = 0; k < 3; k++)
        if (col[k] < 0.0f) return gltf_fail(g, PK_ERR_PARSE, "%s/color: %g is negative", path, (double)col[k]);
    if ((st = gltf_num(g, l, path, "intensity", 0.0, 1e30, 1.0, &inten))) return st;
    if (cJSON_GetObjectItemCaseSensitive(l, "range"))
        gltf_warn_once(g, GW_RANGE, "%s/range: lights fall off with the square of distance, without a range", path);
    const vec3 intensity = v3_scale(v3(col[0], col[1], col[2]), inten / GLTF_LUMENS_PER_WATT);
    const vec3 dir = v3_norm_scaled(xform_vector(x, v3(0.0f, 0.0f, -1.0f)));
    const vec3 position = xform_point(x, v3s(0.0f));
    if (strcmp(type, "directional") == 0) {
        if (!v3_finite(dir) || !(v3_len2(dir) > 0.0f))
            return gltf_fail(g, PK_ERR_PARSE, "%s: its node's transform gives no direction", path);
        return scene_light_distant(g->ctx, g->s, v3_neg(dir), intensity);
    }
    float cos_inner = 1.0f, cos_outer = 1.0f;
    const bool spot = strcmp(type, "spot") == 0;
    if (spot) {
        snprintf(sp, sizeof sp, "%s/spot", path);
        const cJSON *s = cJSON_GetObjectItemCaseSensitive(l, "spot");
        if (!cJSON_IsObject(s)) return gltf_fail(g, PK_ERR_PARSE, "%s: required, and must be an object", sp);
        if ((st = gltf_num(g, s, sp, "innerConeAngle", 0.0, PK_PI / 2, 0.0, &inner))) return st;
        if ((st = gltf_num(g, s, sp, "outerConeAngle", 0.0, PK_PI / 2, PK_PI / 4, &outer))) return st;
        if (!(inner < outer)) return gltf_fail(g, PK_ERR_PARSE, "%s: innerConeAngle must be less than outerConeAngle", sp);
        if (!v3_finite(dir) || !(v3_len2(dir) > 0.0f))
            return gltf_fail(g, PK_ERR_PARSE, "%s: its node's transform gives no direction", path);
        cos_inner = cosf(inner);
        cos_outer = cosf(outer);
    } else if (strcmp(type, "point") != 0) {
        return gltf_fail(g, PK_ERR_PARSE, "%s/type: '%.16s' is not point, spot or directional", path, type);
    }
    if (!v3_finite(position)) return gltf_fail(g, PK_ERR_PARSE, "%s: its node's position is not finite", path);
    if (spot) return scene_light_spot(g->ctx, g->s, position, dir, cos_inner, cos_outer, SPOT_FALLOFF_SQUARED, intensity);
    return scene_light_point(g->ctx, g->s, position, intensity);
}

/* ---- the node tree ------------------------------------------------------------------------- */

/* Node ni's transform in the world: its local transforms and its
 * ancestors' (g->parent). */
static pk_status node_world(gltf *g, int64_t ni, xform *out)
{
    *out = xform_identity();
    const cJSON *nodes = gltf_array(g, "nodes");
    for (int depth = 0; ni >= 0; depth++) {
        char path[48];
        snprintf(path, sizeof path, "/nodes/%lld", (long long)ni);
        if (depth >= GLTF_MAX_NODE_DEPTH)
            return gltf_fail(g, PK_ERR_LIMIT, "%s: nodes nested deeper than %d", path, GLTF_MAX_NODE_DEPTH);
        const cJSON *n = cJSON_GetArrayItem(nodes, (int)ni);
        if (!cJSON_IsObject(n)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
        xform local;
        pk_status st = node_local(g, n, path, &local);
        if (st) return st;
        *out = xform_mul(&local, out);
        ni = g->parent[ni];
    }
    if (!xform_finite(out)) return gltf_fail(g, PK_ERR_PARSE, "/nodes/%lld: the transform is not finite", (long long)ni);
    return PK_OK;
}

/* The joint matrices of skin si into g->skin: each joint's world transform
 * times its inverse bind matrix (the identity when there are none). */
static pk_status skin_matrices(gltf *g, int64_t si)
{
    char path[48];
    snprintf(path, sizeof path, "/skins/%lld", (long long)si);
    const cJSON *sk = cJSON_GetArrayItem(gltf_array(g, "skins"), (int)si);
    if (!cJSON_IsObject(sk)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const cJSON *joints = cJSON_GetObjectItemCaseSensitive(sk, "joints");
    if (!cJSON_IsArray(joints) || !cJSON_GetArraySize(joints))
        return gltf_fail(g, PK_ERR_PARSE, "%s/joints: required, and must be an array of node indices", path);
    const size_t nj = (size_t)cJSON_GetArraySize(joints), nn = gltf_count(g, "nodes");
    pk_status st;
    int64_t ibi;
    if ((st = gltf_index(g, sk, path, "inverseBindMatrices", gltf_count(g, "accessors"), false, &ibi))) return st;
    xform *ib = NULL;
    if (ibi >= 0) {
        gltf_accessor a;
        if ((st = gltf_accessor_get(g, ibi, &a))) return st;
        if (a.count < nj)
            return gltf_fail(g, PK_ERR_PARSE, "%s/inverseBindMatrices: %zu matrices for %zu joints", path, a.count, nj);
        if ((st = gltf_read_mat4(g, ibi, &a, &ib))) return st;
    }
    g->skin = mem_calloc(&g->ctx->alloc, nj, sizeof *g->skin);
    if (!g->skin) {
        mem_free(&g->ctx->alloc, ib);
        return ctx_nomem(g->ctx);
    }
    g->nskin = nj;
    size_t k = 0;
    st = PK_OK;
    for (const cJSON *j = joints->child; j && !st; j = j->next, k++) {
        if (!is_integer(j) || j->valuedouble < 0 || j->valuedouble >= (double)nn) {
            st = gltf_fail(g, PK_ERR_PARSE, "%s/joints/%zu: not a node index", path, k);
            break;
        }
        xform jw;
        if ((st = node_world(g, (int64_t)j->valuedouble, &jw))) break;
        g->skin[k] = ib ? xform_mul(&jw, &ib[k]) : jw;
    }
    mem_free(&g->ctx->alloc, ib);
    return st;
}

typedef struct walk {
    uint8_t *state;       /* per node: 0 not seen, 1 on the path, 2 done */
    uint32_t *mesh_uses;  /* per mesh: nodes that place it */
    int64_t *mesh_obj;    /* per mesh: the scene mesh of an instanced one, -1 not made */
    bool count_only;
} walk;

static pk_status visit(gltf *g, walk *w, int64_t ni, const xform *parent, int depth, const char *from)
{
    char path[48];
    snprintf(path, sizeof path, "/nodes/%lld", (long long)ni);
    if (w->state[ni] == 1) return gltf_fail(g, PK_ERR_PARSE, "%s: node %lld is its own ancestor (a cycle)", from, (long long)ni);
    if (w->state[ni] == 2)
        return gltf_fail(g, PK_ERR_PARSE, "%s: node %lld is reached a second time (two parents)", from, (long long)ni);
    if (depth >= GLTF_MAX_NODE_DEPTH)
        return gltf_fail(g, PK_ERR_LIMIT, "%s: nodes nested deeper than %d", path, GLTF_MAX_NODE_DEPTH);
    w->state[ni] = 1;
    const cJSON *n = cJSON_GetArrayItem(gltf_array(g, "nodes"), (int)ni);
    if (!cJSON_IsObject(n)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    pk_status st;
    xform local, x;
    if ((st = node_local(g, n, path, &local))) return st;
    x = xform_mul(parent, &local);
    if (!xform_finite(&x)) return gltf_fail(g, PK_ERR_PARSE, "%s: the transform is not finite", path);
    int64_t mi, ci;
    if ((st = gltf_index(g, n, path, "mesh", gltf_count(g, "meshes"), false, &mi))) return st;
    if ((st = gltf_index(g, n, path, "camera", gltf_count(g, "cameras"), false, &ci))) return st;
    const cJSON *le = gltf_ext(n, "KHR_lights_punctual");
    int64_t li = -1;
    if (le) {
        char lp[96];
        snprintf(lp, sizeof lp, "%s/extensions/KHR_lights_punctual", path);
        const cJSON *lights = cJSON_GetObjectItemCaseSensitive(gltf_ext(g->root, "KHR_lights_punctual"), "lights");
        size_t nl = cJSON_IsArray(lights) ? (size_t)cJSON_GetArraySize(lights) : 0;
        if ((st = gltf_index(g, le, lp, "light", nl, true, &li))) return st;
    }
    int64_t ski;
    if ((st = gltf_index(g, n, path, "skin", gltf_count(g, "skins"), false, &ski))) return st;
    /* a skinned or morphed node's mesh is its own, not an instance */
    const bool own = mi >= 0 && (ski >= 0 || cJSON_GetObjectItemCaseSensitive(n, "weights"));
    if (w->count_only) {
        if (mi >= 0 && !own && w->mesh_uses[mi] < UINT32_MAX) w->mesh_uses[mi]++;
    } else {
        double det = xform_det3(&x);
        if (own) {
            float *nw = mem_calloc(&g->ctx->alloc, GLTF_MAX_WEIGHTS, sizeof *nw); /* (visit recurses: not on the stack) */
            if (!nw) return ctx_nomem(g->ctx);
            size_t nnw = 0;
            if ((st = weights(g, n, path, nw, &nnw))) {
                mem_free(&g->ctx->alloc, nw);
                return st;
            }
            g->node_weights = cJSON_GetObjectItemCaseSensitive(n, "weights") ? nw : NULL;
            g->nnode_weights = nnw;
            if (ski >= 0) {
                /* the joints place the vertices; the node's own transform is not applied */
                xform id = xform_identity();
                sb_set_transform(&g->b, &id);
                if ((st = skin_matrices(g, ski)) == PK_OK) st = add_mesh(g, mi, false);
            } else {
                sb_set_transform(&g->b, &x);
                st = add_mesh(g, mi, det < 0.0);
            }
            g->node_weights = NULL;
            g->nnode_weights = 0;
            mem_free(&g->ctx->alloc, nw);
            mem_free(&g->ctx->alloc, g->skin);
            g->skin = NULL;
            g->nskin = 0;
            if (st) return st;
        } else if (mi >= 0 && w->mesh_uses[mi] > 1) {
            if (w->mesh_obj[mi] < 0) {
                /* the mesh in its own space, once */
                xform id = xform_identity();
                sb_set_transform(&g->b, &id);
                if (!sb_begin_object(&g->b)) return gltf_fail(g, PK_ERR_PARSE, "%s: objects do not nest", path);
                if ((st = add_mesh(g, mi, false))) return st;
                uint32_t sm;
                if ((st = sb_end_object(&g->b, &sm))) return st;
                w->mesh_obj[mi] = sm;
            }
            if (det == 0.0 || !isfinite(det)) {
                gltf_warn_once(g, GW_SINGULAR, "%s: a singular transform places nothing (further ones not reported)", path);
            } else {
                if (det < 0.0)
                    gltf_warn_once(g, GW_INSTANCE_MIRROR,
                                   "%s: a mirroring transform of a shared mesh keeps the mesh's winding (front faces "
                                   "of emitters turn inward)",
                                   path);
                sb_set_transform(&g->b, &x);
                if ((st = sb_add_instance(&g->b, (uint32_t)w->mesh_obj[mi]))) return st;
            }
        } else if (mi >= 0) {
            sb_set_transform(&g->b, &x);
            if ((st = add_mesh(g, mi, det < 0.0))) return st;
        }
        if (ci >= 0 && !g->camera_done && (g->camera_pick < 0 || g->camera_pick == ci))
            if ((st = place_camera(g, ci, &x, ni))) return st;
        if (li >= 0 && (st = place_light(g, li, &x))) return st;
    }
    const cJSON *ch = cJSON_GetObjectItemCaseSensitive(n, "children");
    if (ch) {
        if (!cJSON_IsArray(ch)) return gltf_fail(g, PK_ERR_PARSE, "%s/children: must be an array", path);
        char cp[64];
        snprintf(cp, sizeof cp, "%s/children", path);
        int k = 0;
        for (const cJSON *c = ch->child; c; c = c->next, k++) {
            char ep[80];
            snprintf(ep, sizeof ep, "%s/%d", cp, k);
            if (!is_integer(c) || c->valuedouble < 0 || c->valuedouble >= (double)gltf_count(g, "nodes"))
                return gltf_fail(g, PK_ERR_PARSE, "%s: not a node index", ep);
            if ((st = visit(g, w, (int64_t)c->valuedouble, &x, depth + 1, ep))) return st;
        }
    }
    w->state[ni] = 2;
    return PK_OK;
}

/* Walks the default scene's roots (every root node when there is no scene). */
static pk_status walk_scene(gltf *g, walk *w)
{
    size_t nn = gltf_count(g, "nodes");
    memset(w->state, 0, nn ? nn : 1);
    xform id = xform_identity();
    pk_status st;
    int64_t si;
    if ((st = gltf_index(g, g->root, "", "scene", gltf_count(g, "scenes"), false, &si))) return st;
    if (si < 0 && gltf_count(g, "scenes")) si = 0;
    if (si < 0) {
        /* no scene: every node that is no node's child */
        uint8_t *child = mem_calloc(&g->ctx->alloc, nn ? nn : 1, 1);
        if (!child) return ctx_nomem(g->ctx);
        size_t i = 0;
        for (const cJSON *n = gltf_array(g, "nodes") ? gltf_array(g, "nodes")->child : NULL; n; n = n->next, i++) {
            const cJSON *ch = cJSON_GetObjectItemCaseSensitive(n, "children");
            for (const cJSON *c = cJSON_IsArray(ch) ? ch->child : NULL; c; c = c->next)
                if (is_integer(c) && c->valuedouble >= 0 && c->valuedouble < (double)nn) child[(size_t)c->valuedouble] = 1;
        }
        st = PK_OK;
        for (i = 0; i < nn && st == PK_OK; i++)
            if (!child[i] && w->state[i] == 0) st = visit(g, w, (int64_t)i, &id, 0, "/nodes");
        mem_free(&g->ctx->alloc, child);
        return st;
    }
    const cJSON *sc = cJSON_GetArrayItem(gltf_array(g, "scenes"), (int)si);
    char path[48];
    snprintf(path, sizeof path, "/scenes/%lld", (long long)si);
    if (!cJSON_IsObject(sc)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const cJSON *roots = cJSON_GetObjectItemCaseSensitive(sc, "nodes");
    if (roots && !cJSON_IsArray(roots)) return gltf_fail(g, PK_ERR_PARSE, "%s/nodes: must be an array", path);
    int k = 0;
    for (const cJSON *r = roots ? roots->child : NULL; r; r = r->next, k++) {
        char ep[80];
        snprintf(ep, sizeof ep, "%s/nodes/%d", path, k);
        if (!is_integer(r) || r->valuedouble < 0 || r->valuedouble >= (double)nn)
            return gltf_fail(g, PK_ERR_PARSE, "%s: not a node index", ep);
        if ((st = visit(g, w, (int64_t)r->valuedouble, &id, 0, ep))) return st;
    }
    return PK_OK;
}

/* ---- the door ------------------------------------------------------------------------------- */

static pk_status read_params(gltf *g, const char *const *params, size_t nparams)
{
    g->camera_pick = -1;
    for (size_t i = 0; i < nparams; i++) {
        const char *p = params[i];
        if (!p) continue;
        if (strncmp(p, "camera=", 7) == 0) {
            char *end;
            long v = strtol(p + 7, &end, 10);
            if (end == p + 7 || *end || v < 0 || v > INT32_MAX)
                return gltf_fail(g, PK_ERR_INVALID_ARGUMENT, "camera '%.32s': expected a camera number", p + 7);
            g->camera_pick = (int)v;
        } else if (strncmp(p, "variant=", 8) == 0) {
            g->variant_name = p + 8;
        } else {
            gltf_warn(g, "parameter '%.64s' ignored (a glTF asset takes camera=N and variant=NAME)", p);
        }
    }
    return PK_OK;
}

pk_status scene_gltf_parse_params(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                                  const char *base_dir, const char *const *params, size_t nparams)
{
    if (!ctx || !s) return PK_ERR_INVALID_ARGUMENT;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "scene_gltf_parse: no data");
    gltf *g = mem_calloc(&ctx->alloc, 1, sizeof *g);
    if (!g) return ctx_nomem(ctx);
    g->ctx = ctx;
    g->s = s;
    g->name = name ? name : "model.gltf";
    g->base_dir = base_dir;
    sb_init(&g->b, ctx, s);
    walk w = {0};
    pk_status st = read_params(g, params, nparams);
    if (st) goto out;

    const char *json = data ? data : "";
    size_t jsize = size;
    if (size >= 4 && memcmp(data, "glTF", 4) == 0) {
        if ((st = gltf_glb_split(g, (const uint8_t *)data, size, &json, &jsize))) goto out;
    }
    if (jsize >= 3 && memcmp(json, "\xEF\xBB\xBF", 3) == 0) json += 3, jsize -= 3; /* a byte-order mark */
    if (jsize > PK_MAX_JSON_BYTES) {
        st = gltf_fail(g, PK_ERR_LIMIT, "the JSON part holds more than %zu bytes", (size_t)PK_MAX_JSON_BYTES);
        goto out;
    }
    const char *end = NULL;
    g->root = jsize ? cJSON_ParseWithLengthOpts(json, jsize, &end, 0) : NULL;
    if (!g->root) {
        size_t at = end && end >= json && end <= json + jsize ? (size_t)(end - json) : 0;
        st = gltf_fail(g, PK_ERR_PARSE, "JSON syntax error near byte %zu", at);
        goto out;
    }
    if (!cJSON_IsObject(g->root)) {
        st = gltf_fail(g, PK_ERR_PARSE, "the top level must be a JSON object");
        goto out;
    }
    if ((st = check_document(g))) goto out;
    if ((st = find_variant(g))) goto out;
    g->nbuffers = gltf_count(g, "buffers");
    g->nmaterials = gltf_count(g, "materials");
    g->nimages = gltf_count(g, "images");
    size_t nn = gltf_count(g, "nodes"), nm = gltf_count(g, "meshes");
    g->buffers = mem_calloc(&ctx->alloc, g->nbuffers + 1, sizeof *g->buffers);
    g->materials = mem_calloc(&ctx->alloc, g->nmaterials + 1, sizeof *g->materials);
    g->mat_uvset = mem_calloc(&ctx->alloc, g->nmaterials + 1, sizeof *g->mat_uvset);
    g->mat_uv = mem_calloc(&ctx->alloc, g->nmaterials + 1, sizeof *g->mat_uv);
    g->images[0] = mem_calloc(&ctx->alloc, g->nimages + 1, sizeof *g->images[0]);
    g->images[1] = mem_calloc(&ctx->alloc, g->nimages + 1, sizeof *g->images[1]);
    w.state = mem_calloc(&ctx->alloc, nn + 1, 1);
    w.mesh_uses = mem_calloc(&ctx->alloc, nm + 1, sizeof *w.mesh_uses);
    w.mesh_obj = mem_calloc(&ctx->alloc, nm + 1, sizeof *w.mesh_obj);
    if (!g->buffers || !g->materials || !g->mat_uvset || !g->mat_uv || !g->images[0] || !g->images[1] || !w.state ||
        !w.mesh_uses || !w.mesh_obj) {
        st = ctx_nomem(ctx);
        goto out;
    }
    for (size_t i = 0; i < nm; i++) w.mesh_obj[i] = -1;
    g->parent = mem_calloc(&ctx->alloc, nn + 1, sizeof *g->parent);
    if (!g->parent) {
        st = ctx_nomem(ctx);
        goto out;
    }
    for (size_t i = 0; i < nn; i++) g->parent[i] = -1;
    {
        size_t i = 0;
        for (const cJSON *n = gltf_array(g, "nodes") ? gltf_array(g, "nodes")->child : NULL; n; n = n->next, i++) {
            const cJSON *ch = cJSON_GetObjectItemCaseSensitive(n, "children");
            for (const cJSON *c = cJSON_IsArray(ch) ? ch->child : NULL; c; c = c->next)
                if (is_integer(c) && c->valuedouble >= 0 && c->valuedouble < (double)nn && g->parent[(size_t)c->valuedouble] < 0)
                    g->parent[(size_t)c->valuedouble] = (int64_t)i;
        }
    }
    if (g->camera_pick >= 0 && (size_t)g->camera_pick >= gltf_count(g, "cameras")) {
        st = gltf_fail(g, PK_ERR_INVALID_ARGUMENT, "camera %d: the asset has %zu camera%s", g->camera_pick,
                       gltf_count(g, "cameras"), gltf_count(g, "cameras") == 1 ? "" : "s");
        goto out;
    }
    w.count_only = true;
    if ((st = walk_scene(g, &w))) goto out;
    w.count_only = false;
    if ((st = walk_scene(g, &w))) goto out;
    if (g->camera_pick >= 0 && !g->camera_done) {
        st = gltf_fail(g, PK_ERR_INVALID_ARGUMENT, "camera %d: no node of the scene places it", g->camera_pick);
        goto out;
    }
    /* glTF viewers (and Blender's Cycles, which imports glTF) give back the
     * energy that rough microfacet lobes lose: so do we, unless told not to */
    scene_render_energy_compensation(s, true);
    st = PK_OK;
out:
    if (w.state) mem_free(&ctx->alloc, w.state);
    mem_free(&ctx->alloc, w.mesh_uses);
    mem_free(&ctx->alloc, w.mesh_obj);
    mem_free(&ctx->alloc, g->parent);
    mem_free(&ctx->alloc, g->skin);
    gltf_materials_free(g);
    gltf_buffers_free(g);
    if (g->root) cJSON_Delete(g->root);
    mem_free(&ctx->alloc, g);
    return st;
}

pk_status scene_gltf_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                           const char *base_dir)
{
    return scene_gltf_parse_params(ctx, s, data, size, name, base_dir, NULL, 0);
}

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
                                        "KHR_materials_variants",       NULL};
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
        if (strcmp(e->valuestring, "KHR_draco_mesh_compression") == 0)
            return gltf_fail(g, PK_ERR_UNSUPPORTED,
                             "/extensionsRequired/%d: Draco-compressed meshes (KHR_draco_mesh_compression) are not "
                             "read; export the model without Draco compression",
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
                                         "materials", "textures", "images", "samplers", "cameras", NULL};
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

/* One vertex attribute of a primitive as floats (*out NULL when absent). */
static pk_status attribute(gltf *g, const cJSON *attrs, const char *path, const char *key, int ncomp, bool required,
                           size_t *count, float **out)
{
    *out = NULL;
    int64_t ai;
    char ap[128];
    snprintf(ap, sizeof ap, "%s/attributes", path);
    pk_status st = gltf_index(g, attrs, ap, key, gltf_count(g, "accessors"), required, &ai);
    if (st || ai < 0) return st;
    gltf_accessor a;
    if ((st = gltf_accessor_get(g, ai, &a))) return st;
    if (a.ncomp != ncomp || a.matrix)
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: %s must have %d components", (long long)ai, key, ncomp);
    if (a.ctype != 5126 && !g->ext_quantization && !a.normalized)
        gltf_warn(g, "/accessors/%lld: integer %s without KHR_mesh_quantization declared; read as its values",
                  (long long)ai, key);
    if (*count && a.count != *count)
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: %s has %zu elements, POSITION %zu", (long long)ai, key,
                         a.count, *count);
    *count = a.count;
    return gltf_read_floats(g, ai, &a, out);
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

/* Adds primitive p of mesh mi through the builder's current transform. */
static pk_status add_primitive(gltf *g, int64_t mi, int pi, const cJSON *p, bool flip)
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
    if (gltf_ext(p, "KHR_draco_mesh_compression"))
        gltf_warn_once(g, GW_EXT, "%s: Draco-compressed data ignored; the uncompressed fallback is read", path);
    if (cJSON_GetObjectItemCaseSensitive(p, "targets"))
        gltf_warn_once(g, GW_MORPH, "%s: morph targets are not applied (further ones not reported)", path);
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(p, "attributes");
    if (!cJSON_IsObject(attrs)) return gltf_fail(g, PK_ERR_PARSE, "%s/attributes: required, and must be an object", path);
    if ((st = gltf_index(g, p, path, "indices", gltf_count(g, "accessors"), false, &ii))) return st;
    if ((st = gltf_index(g, p, path, "material", gltf_count(g, "materials"), false, &mat))) return st;
    if (g->variant >= 0 && (st = variant_material(g, p, path, &mat))) return st;
    uint32_t smat;
    int uvset;
    if ((st = gltf_material(g, mat, &smat, &uvset))) return st;

    float *pos = NULL, *nrm = NULL, *uv = NULL, *tmp = NULL;
    uint32_t *idx = NULL, *tris = NULL;
    size_t n = 0, ntris = 0;
    if ((st = attribute(g, attrs, path, "POSITION", 3, true, &n, &pos))) goto out;
    if ((st = attribute(g, attrs, path, "NORMAL", 3, false, &n, &nrm))) goto out;
    if ((st = attribute(g, attrs, path, uvset ? "TEXCOORD_1" : "TEXCOORD_0", 2, false, &n, &uv))) goto out;
    if (cJSON_GetObjectItemCaseSensitive(attrs, "COLOR_0"))
        gltf_warn_once(g, GW_COLOR, "%s/attributes/COLOR_0: vertex colours are not drawn (further ones not reported)",
                       path);
    if (!uvset && cJSON_GetObjectItemCaseSensitive(attrs, "TEXCOORD_1"))
        gltf_warn_once(g, GW_UV1, "%s/attributes/TEXCOORD_1: no texture of the material reads it; ignored", path);
    if (cJSON_GetObjectItemCaseSensitive(attrs, "JOINTS_0"))
        gltf_warn_once(g, GW_SKIN, "%s: skinning is not applied; drawn in the bind pose", path);
    size_t nidx = n;
    if (ii >= 0) {
        gltf_accessor a;
        if ((st = gltf_accessor_get(g, ii, &a))) goto out;
        if ((st = gltf_read_uints(g, ii, &a, &idx))) goto out;
        nidx = a.count;
    }
    if ((st = triangulate(g, path, (int)mode, idx, nidx, n, &tris, &ntris))) goto out;
    if (uv) {
        const gltf_uv_xform *x = mat >= 0 ? &g->mat_uv[mat] : NULL;
        for (size_t k = 0; k < n; k++) {
            float u = uv[2 * k], v = uv[2 * k + 1];
            if (x && x->bake) {
                float u2 = x->m[0] * u + x->m[1] * v + x->m[2], v2 = x->m[3] * u + x->m[4] * v + x->m[5];
                u = u2, v = v2;
            }
            uv[2 * k] = u;
            uv[2 * k + 1] = 1.0f - v; /* glTF's v runs down the image, the scene's up */
        }
    }
    if (nrm) /* unit normals as the specification requires (quantized ones are not) */
        for (size_t k = 0; k < n; k++) {
            vec3 *q = (vec3 *)(nrm + 3 * k);
            *q = v3_norm_scaled(*q);
            if (!v3_finite(*q)) *q = v3s(0.0f);
        }
    sb_set_material(&g->b, smat);
    sb_mesh m = {(const vec3 *)pos, (const vec3 *)nrm, uv, n, tris, ntris, flip};
    st = sb_add_mesh(&g->b, &m);
out:
    mem_free(&g->ctx->alloc, pos);
    mem_free(&g->ctx->alloc, nrm);
    mem_free(&g->ctx->alloc, uv);
    mem_free(&g->ctx->alloc, tmp);
    mem_free(&g->ctx->alloc, idx);
    mem_free(&g->ctx->alloc, tris);
    return st;
}

static pk_status add_mesh(gltf *g, int64_t mi, bool flip)
{
    const cJSON *m = cJSON_GetArrayItem(gltf_array(g, "meshes"), (int)mi);
    char path[48];
    snprintf(path, sizeof path, "/meshes/%lld", (long long)mi);
    if (!cJSON_IsObject(m)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(m, "primitives");
    if (!cJSON_IsArray(prims)) return gltf_fail(g, PK_ERR_PARSE, "%s/primitives: required, and must be an array", path);
    int k = 0;
    for (const cJSON *p = prims->child; p; p = p->next, k++) {
        pk_status st = add_primitive(g, mi, k, p, flip);
        if (st) return st;
    }
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
    if (w->count_only) {
        if (mi >= 0 && w->mesh_uses[mi] < UINT32_MAX) w->mesh_uses[mi]++;
    } else {
        if (cJSON_GetObjectItemCaseSensitive(n, "skin"))
            gltf_warn_once(g, GW_SKIN, "%s: skinning is not applied; drawn in the bind pose", path);
        double det = xform_det3(&x);
        if (mi >= 0 && w->mesh_uses[mi] > 1) {
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

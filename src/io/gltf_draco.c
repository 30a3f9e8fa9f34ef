/*
 * gltf_draco.c - KHR_draco_mesh_compression: a primitive's Draco stream
 * decoded by the Draco module (paprsek_draco.so, gltf_draco.cpp; the
 * interface is gltf_draco_module.h), loaded the first time such a primitive
 * is read (device/module.h: the config's draco.module, or the one installed
 * beside the library). The decoded points and faces are substituted for the
 * accessors the primitive's attributes and indices name (gltf->acc_dec), so
 * that the rest of the reader sees an uncompressed primitive: each decoded
 * attribute in the component type, count and normalization its accessor
 * declares; the indices as unsigned ints.
 */
#include "gltf.h"
#include "gltf_draco_module.h"

#include "device/module.h"

#include <stdio.h>
#include <string.h>

#define DRACO_MAX_POINTS ((uint64_t)1 << 26)
#define DRACO_MAX_FACES ((uint64_t)1 << 27)
#define DRACO_MAX_ATTRS 64

static dynlib draco_module = DYNLIB_INIT;
static gltf_draco_decode_fn draco_decode; /* set once under the loader's lock */

static bool init_draco(void *h, const char *name, char *why, size_t n)
{
    void *sym = dynlib_symbol(h, GLTF_DRACO_ENTRY);
    if (!sym) {
        snprintf(why, n, "%s has no %s (not the Draco module of this version of the library)", name, GLTF_DRACO_ENTRY);
        return false;
    }
    memcpy(&draco_decode, &sym, sizeof sym);
    return true;
}

/* True when draco_decode is ready; else why says why not. */
static bool draco_loaded(const pk_context *ctx, char *why, size_t n)
{
#if PK_HAVE_DRACO
    char reason[600];
    bool missing = false;
    if (module_load(&draco_module, ctx->config.draco_module, GLTF_DRACO_MODULE_FILE, init_draco, &missing, reason,
                    sizeof reason))
        return true;
    if (missing)
        snprintf(why, n, "the Draco module is not here (%.400s)", reason);
    else
        snprintf(why, n, "the Draco module does not load: %.400s; is Draco installed? (Debian: libdraco7)", reason);
#else
    (void)ctx, (void)draco_module, (void)init_draco;
    snprintf(why, n, "this build does not decode it (Draco, Debian libdraco-dev, was missing when it was built)");
#endif
    return false;
}

bool gltf_have_draco(gltf *g, char *why, size_t n) { return draco_loaded(g->ctx, why, n); }

static void *host_alloc(void *user, size_t size) { return mem_alloc(&((gltf *)user)->ctx->alloc, size); }
static void host_free(void *user, void *p) { mem_free(&((gltf *)user)->ctx->alloc, p); }

static int comp_size(int ctype) { return ctype == 5120 || ctype == 5121 ? 1 : ctype == 5122 || ctype == 5123 ? 2 : 4; }

/* The declared layout of accessor ai (componentType, components, normalized). */
static pk_status accessor_layout(gltf *g, int64_t ai, int *ctype, int *ncomp, bool *normalized)
{
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "accessors"), (int)ai);
    char path[48];
    snprintf(path, sizeof path, "/accessors/%lld", (long long)ai);
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    int64_t ct;
    const char *type;
    pk_status st;
    if ((st = gltf_int(g, o, path, "componentType", 5120, 5126, -1, &ct))) return st;
    if (ct != 5120 && ct != 5121 && ct != 5122 && ct != 5123 && ct != 5125 && ct != 5126)
        return gltf_fail(g, PK_ERR_PARSE, "%s: componentType %lld is not a glTF component type", path, (long long)ct);
    if ((st = gltf_string(g, o, path, "type", &type))) return st;
    static const char *const names[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
    *ncomp = 0;
    for (int k = 0; type && k < 4; k++)
        if (strcmp(type, names[k]) == 0) *ncomp = k + 1;
    if (!*ncomp)
        return gltf_fail(g, PK_ERR_PARSE, "%s: type '%.16s' is not a vertex attribute's (SCALAR .. VEC4)", path,
                         type ? type : "");
    *ctype = (int)ct;
    *normalized = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(o, "normalized"));
    return PK_OK;
}

/* Whether every accessor the primitive names has a buffer view (the
 * uncompressed fallback). */
static bool has_fallback(gltf *g, const cJSON *p)
{
    const cJSON *acc = gltf_array(g, "accessors");
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(p, "attributes");
    for (const cJSON *a = attrs ? attrs->child : NULL; a; a = a->next) {
        if (!cJSON_IsNumber(a)) return false;
        const cJSON *o = cJSON_GetArrayItem(acc, (int)a->valuedouble);
        if (!cJSON_GetObjectItemCaseSensitive(o, "bufferView")) return false;
    }
    const cJSON *ind = cJSON_GetObjectItemCaseSensitive(p, "indices");
    if (ind && (!cJSON_IsNumber(ind) ||
                !cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(acc, (int)ind->valuedouble), "bufferView")))
        return false;
    return true;
}

/* Substitutes data (owned) for accessor ai. */
static pk_status substitute(gltf *g, int64_t ai, uint8_t *data, size_t count, int ctype, int ncomp, bool normalized)
{
    if (!g->acc_dec) {
        size_t na = gltf_count(g, "accessors");
        g->acc_dec = mem_calloc(&g->ctx->alloc, na ? na : 1, sizeof *g->acc_dec);
        g->acc_data = mem_calloc(&g->ctx->alloc, na ? na : 1, sizeof *g->acc_data);
        if (!g->acc_dec || !g->acc_data) {
            mem_free(&g->ctx->alloc, g->acc_dec);
            mem_free(&g->ctx->alloc, g->acc_data);
            g->acc_dec = NULL;
            g->acc_data = NULL;
            mem_free(&g->ctx->alloc, data);
            return ctx_nomem(g->ctx);
        }
        g->nacc_dec = na;
    }
    mem_free(&g->ctx->alloc, g->acc_data[ai]);
    g->acc_data[ai] = data;
    gltf_accessor *a = &g->acc_dec[ai];
    memset(a, 0, sizeof *a);
    a->base = data;
    a->count = count;
    a->ctype = ctype;
    a->ncomp = ncomp;
    a->stride = (size_t)ncomp * (size_t)comp_size(ctype);
    a->normalized = normalized;
    return PK_OK;
}

pk_status gltf_draco_primitive(gltf *g, const cJSON *p, const char *path)
{
    const cJSON *ext = gltf_ext(p, "KHR_draco_mesh_compression");
    char ep[160];
    snprintf(ep, sizeof ep, "%s/extensions/KHR_draco_mesh_compression", path);
    if (!cJSON_IsObject(ext)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", ep);
    pk_status st;
    int64_t view;
    if ((st = gltf_index(g, ext, ep, "bufferView", gltf_count(g, "bufferViews"), true, &view))) return st;
    const cJSON *da = cJSON_GetObjectItemCaseSensitive(ext, "attributes");
    if (!cJSON_IsObject(da)) return gltf_fail(g, PK_ERR_PARSE, "%s/attributes: required, and must be an object", ep);
    const cJSON *pa = cJSON_GetObjectItemCaseSensitive(p, "attributes");
    if (!cJSON_IsObject(pa)) return gltf_fail(g, PK_ERR_PARSE, "%s/attributes: required, and must be an object", path);
    char why[700];
    if (!draco_loaded(g->ctx, why, sizeof why)) {
        if (!has_fallback(g, p))
            return gltf_fail(g, PK_ERR_UNSUPPORTED, "%s: a Draco-compressed primitive, and %s", ep, why);
        gltf_warn_once(g, GW_DRACO, "%s: Draco-compressed data not decoded (%s); the uncompressed fallback is read", ep,
                       why);
        return PK_OK;
    }
    /* what to ask for: each attribute the extension maps, in its accessor's layout */
    gltf_draco_attr req[DRACO_MAX_ATTRS];
    int64_t acc[DRACO_MAX_ATTRS];
    bool norm[DRACO_MAX_ATTRS];
    int nreq = 0;
    char ap[192];
    snprintf(ap, sizeof ap, "%s/attributes", ep);
    for (const cJSON *e = da->child; e; e = e->next) {
        if (nreq == DRACO_MAX_ATTRS)
            return gltf_fail(g, PK_ERR_LIMIT, "%s: more than %d attributes", ap, DRACO_MAX_ATTRS);
        int64_t id;
        if ((st = gltf_int(g, da, ap, e->string, 0, INT32_MAX, -1, &id))) return st;
        int64_t ai;
        char pp[128];
        snprintf(pp, sizeof pp, "%s/attributes", path);
        if ((st = gltf_index(g, pa, pp, e->string, gltf_count(g, "accessors"), false, &ai))) return st;
        if (ai < 0)
            return gltf_fail(g, PK_ERR_PARSE, "%s/%.64s: the primitive has no attribute %.64s", ap, e->string, e->string);
        req[nreq].id = (int)id;
        if ((st = accessor_layout(g, ai, &req[nreq].ctype, &req[nreq].ncomp, &norm[nreq]))) return st;
        req[nreq].data = NULL;
        acc[nreq++] = ai;
    }
    int64_t ii;
    if ((st = gltf_index(g, p, path, "indices", gltf_count(g, "accessors"), false, &ii))) return st;
    const uint8_t *data;
    size_t size, stride;
    if ((st = gltf_view(g, view, &data, &size, &stride))) return st;
    const gltf_draco_host host = {g, host_alloc, host_free, DRACO_MAX_POINTS, DRACO_MAX_FACES};
    gltf_draco_result r;
    memset(&r, 0, sizeof r);
    draco_decode(&host, data, size, req, nreq, &r);
    if (r.status == PK_ERR_NOMEM) return ctx_nomem(g->ctx);
    if (r.status != PK_OK) {
        r.message[sizeof r.message - 1] = '\0';
        return gltf_fail(g, (pk_status)r.status, "%s: %s", ep, r.message);
    }
    /* ownership passes to the substitutes as they are made */
    for (int k = 0; k < nreq; k++) {
        st = substitute(g, acc[k], req[k].data, r.npoints, req[k].ctype, req[k].ncomp, norm[k]);
        req[k].data = NULL;
        if (st) break;
    }
    if (st == PK_OK && ii >= 0) {
        st = substitute(g, ii, (uint8_t *)r.indices, 3 * r.nfaces, 5125, 1, false);
        r.indices = NULL;
    } else if (st == PK_OK) {
        /* no indices accessor: the faces must be the points in order */
        for (size_t k = 0; k < 3 * r.nfaces; k++)
            if (r.indices[k] != k || 3 * r.nfaces != r.npoints) {
                st = gltf_fail(g, PK_ERR_UNSUPPORTED,
                               "%s: the Draco mesh's faces index its points, and the primitive has no indices accessor "
                               "to carry them",
                               ep);
                break;
            }
    }
    for (int k = 0; k < nreq; k++) mem_free(&g->ctx->alloc, req[k].data);
    mem_free(&g->ctx->alloc, r.indices);
    return st;
}

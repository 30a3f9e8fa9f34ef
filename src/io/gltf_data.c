/*
 * gltf_data.c - the bytes of a glTF asset: GLB chunks, buffers (the GLB BIN
 * chunk, base64 data: URIs, files next to the asset), buffer views and
 * accessors (every component type, normalized integers, strides, sparse
 * substitutes). Every length, offset and count is checked against what
 * holds it before a byte is read, in arithmetic that cannot overflow.
 *
 * Buffer views with EXT_meshopt_compression are decoded by meshoptimizer
 * (libmeshoptimizer, loaded at run time when the build found its header):
 * the decoded bytes are kept for the rest of the read and stand for the
 * view. Without the library a view whose own buffer holds the uncompressed
 * data (not a fallback placeholder) is read from there, with one warning.
 */
#include "gltf.h"
#include "io_util.h"

#include "device/dynlib.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define GLB_MAGIC 0x46546C67u  /* "glTF" */
#define GLB_JSON 0x4E4F534Au   /* "JSON" */
#define GLB_BIN 0x004E4942u    /* "BIN\0" */
/* An accessor without a buffer view holds zeros (and sparse values): its
 * count is not bounded by any data, so by this. */
#define GLTF_MAX_ZERO_COUNT ((size_t)1 << 24)

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* ---- GLB -------------------------------------------------------------------- */

pk_status gltf_glb_split(gltf *g, const uint8_t *data, size_t size, const char **json, size_t *json_size)
{
    if (size < 12) return gltf_fail(g, PK_ERR_PARSE, "GLB: the %zu bytes are shorter than a GLB header", size);
    uint32_t version = rd32(data + 4), length = rd32(data + 8);
    if (version != 2) return gltf_fail(g, PK_ERR_UNSUPPORTED, "GLB: version %u is not 2", version);
    if (length != size)
        return gltf_fail(g, PK_ERR_PARSE, "GLB: the header says %u bytes, the file holds %zu", length, size);
    size_t at = 12;
    if (size - at < 8) return gltf_fail(g, PK_ERR_PARSE, "GLB: no JSON chunk");
    uint32_t jlen = rd32(data + at), jtype = rd32(data + at + 4);
    at += 8;
    if (jtype != GLB_JSON) return gltf_fail(g, PK_ERR_PARSE, "GLB: the first chunk is not JSON (type 0x%08x)", jtype);
    if (jlen > size - at)
        return gltf_fail(g, PK_ERR_PARSE, "GLB: the JSON chunk's length %u exceeds the %zu bytes left", jlen, size - at);
    *json = (const char *)data + at;
    *json_size = jlen;
    at += jlen;
    /* chunks are padded to 4 bytes; what is left may hold the BIN chunk */
    size_t pad = (4 - (at & 3)) & 3;
    at = pad <= size - at ? at + pad : size;
    if (size - at >= 8) {
        uint32_t blen = rd32(data + at), btype = rd32(data + at + 4);
        at += 8;
        if (blen > size - at)
            return gltf_fail(g, PK_ERR_PARSE, "GLB: the chunk's length %u exceeds the %zu bytes left", blen, size - at);
        if (btype == GLB_BIN) {
            g->bin = data + at;
            g->bin_size = blen;
        }
    } else if (size - at > 0) {
        return gltf_fail(g, PK_ERR_PARSE, "GLB: %zu stray bytes after the JSON chunk", size - at);
    }
    return PK_OK;
}

/* ---- base64 and URIs ---------------------------------------------------------- */

static int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

bool gltf_base64(const char *in, size_t n, uint8_t *out, size_t *size)
{
    *size = 0;
    if (n % 4) return false;
    size_t o = 0;
    for (size_t i = 0; i < n; i += 4) {
        int v[4];
        int npad = 0;
        for (int k = 0; k < 4; k++) {
            unsigned char c = (unsigned char)in[i + k];
            if (c == '=') {
                /* padding: only in the last group, only its last one or two */
                if (i + 4 != n || k < 2) return false;
                npad++;
                v[k] = 0;
                continue;
            }
            if (npad) return false; /* data after padding */
            v[k] = b64_value(c);
            if (v[k] < 0) return false;
        }
        uint32_t w = (uint32_t)v[0] << 18 | (uint32_t)v[1] << 12 | (uint32_t)v[2] << 6 | (uint32_t)v[3];
        out[o++] = (uint8_t)(w >> 16);
        if (npad < 2) out[o++] = (uint8_t)(w >> 8);
        if (npad < 1) out[o++] = (uint8_t)w;
        /* the bits that padding drops must be zero (one encoding per byte string) */
        if ((npad == 1 && (v[2] & 3)) || (npad == 2 && (v[1] & 15))) return false;
    }
    *size = o;
    return true;
}

pk_status gltf_data_uri(gltf *g, const char *uri, const char *path, uint8_t **out, size_t *size)
{
    *out = NULL;
    *size = 0;
    const char *comma = strchr(uri, ',');
    if (!comma) return gltf_fail(g, PK_ERR_PARSE, "%s: malformed data: URI (no ',')", path);
    size_t hl = (size_t)(comma - uri);
    if (hl < 12 || memcmp(comma - 7, ";base64", 7) != 0)
        return gltf_fail(g, PK_ERR_UNSUPPORTED, "%s: only base64 data: URIs are read", path);
    const char *b = comma + 1;
    size_t n = strlen(b);
    if (n == 0) return gltf_fail(g, PK_ERR_PARSE, "%s: empty data: URI", path);
    uint8_t *buf = mem_alloc(&g->ctx->alloc, n / 4 * 3 + 3);
    if (!buf) return ctx_nomem(g->ctx);
    if (!gltf_base64(b, n, buf, size)) {
        mem_free(&g->ctx->alloc, buf);
        return gltf_fail(g, PK_ERR_PARSE, "%s: malformed base64 in the data: URI", path);
    }
    *out = buf;
    return PK_OK;
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

pk_status gltf_read_uri_file(gltf *g, const char *uri, const char *path, char **out, size_t *size)
{
    *out = NULL;
    *size = 0;
    /* a scheme (two or more letters and ':') names something not on this disk */
    size_t k = 0;
    while ((uri[k] >= 'a' && uri[k] <= 'z') || (uri[k] >= 'A' && uri[k] <= 'Z') || (k && uri[k] >= '0' && uri[k] <= '9') ||
           (k && (uri[k] == '+' || uri[k] == '-' || uri[k] == '.')))
        k++;
    if (k >= 2 && uri[k] == ':')
        return gltf_fail(g, PK_ERR_UNSUPPORTED, "%s: '%.*s:' URIs are not read (only files and data: URIs)", path,
                         (int)(k > 16 ? 16 : k), uri);
    size_t n = strlen(uri);
    if (n == 0) return gltf_fail(g, PK_ERR_PARSE, "%s: empty URI", path);
    if (n >= GLTF_MAX_URI) return gltf_fail(g, PK_ERR_LIMIT, "%s: a URI of more than %d bytes", path, GLTF_MAX_URI);
    char dec[GLTF_MAX_URI];
    size_t o = 0;
    for (size_t i = 0; i < n; i++) {
        if (uri[i] == '%') {
            int h = i + 2 < n ? hexval(uri[i + 1]) : -1, l = i + 2 < n ? hexval(uri[i + 2]) : -1;
            if (i + 2 >= n) h = l = -1;
            if (h < 0 || l < 0 || (h == 0 && l == 0))
                return gltf_fail(g, PK_ERR_PARSE, "%s: malformed percent escape in the URI", path);
            dec[o++] = (char)(h * 16 + l);
            i += 2;
        } else {
            dec[o++] = uri[i];
        }
    }
    dec[o] = '\0';
    pk_context scratch = io_scratch_context(g->ctx);
    pk_status st = io_read_relative(g->ctx, &scratch, g->base_dir ? g->base_dir : ".", dec, NULL, out, size);
    return st ? gltf_fail(g, st, "%s: %s", path, scratch.message) : PK_OK;
}

/* ---- buffers and views --------------------------------------------------------- */

static pk_status load_buffer(gltf *g, int64_t i, const gltf_buffer **out)
{
    gltf_buffer *b = &g->buffers[i];
    *out = b;
    if (b->loaded) return PK_OK;
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "buffers"), (int)i);
    char path[48];
    snprintf(path, sizeof path, "/buffers/%lld", (long long)i);
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    int64_t len;
    pk_status st = gltf_int(g, o, path, "byteLength", 1, INT64_MAX, -1, &len);
    if (st) return st;
    if (len < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: byteLength is required", path);
    const char *uri;
    if ((st = gltf_string(g, o, path, "uri", &uri))) return st;
    char up[64];
    snprintf(up, sizeof up, "%s/uri", path);
    uint8_t *data = NULL;
    size_t have = 0;
    bool owned = true;
    if (!uri) {
        if (i != 0 || !g->bin)
            return gltf_fail(g, PK_ERR_PARSE, "%s: no uri, and it is not the GLB's BIN chunk", path);
        data = (uint8_t *)g->bin;
        have = g->bin_size;
        owned = false;
    } else if (strncmp(uri, "data:", 5) == 0) {
        if ((st = gltf_data_uri(g, uri, up, &data, &have))) return st;
    } else {
        char *d;
        if ((st = gltf_read_uri_file(g, uri, up, &d, &have))) return st;
        data = (uint8_t *)d;
    }
    if ((uint64_t)len > (uint64_t)have) {
        if (owned) mem_free(&g->ctx->alloc, data);
        return gltf_fail(g, PK_ERR_PARSE, "%s: byteLength %lld exceeds its data (%zu bytes)", path, (long long)len, have);
    }
    b->data = data;
    b->size = (size_t)len;
    b->owned = owned;
    b->loaded = true;
    return PK_OK;
}

void gltf_buffers_free(gltf *g)
{
    for (size_t i = 0; i < g->nbuffers; i++)
        if (g->buffers[i].owned) mem_free(&g->ctx->alloc, g->buffers[i].data);
    mem_free(&g->ctx->alloc, g->buffers);
    g->buffers = NULL;
    g->nbuffers = 0;
    for (size_t i = 0; i < g->nview_dec; i++) mem_free(&g->ctx->alloc, g->view_dec[i]);
    mem_free(&g->ctx->alloc, g->view_dec);
    g->view_dec = NULL;
    g->nview_dec = 0;
    for (size_t i = 0; i < g->nacc_dec; i++) mem_free(&g->ctx->alloc, g->acc_data[i]);
    mem_free(&g->ctx->alloc, g->acc_data);
    mem_free(&g->ctx->alloc, g->acc_dec);
    g->acc_data = NULL;
    g->acc_dec = NULL;
    g->nacc_dec = 0;
}

/* ---- EXT_meshopt_compression ------------------------------------------------------ */

/* meshoptimizer's decoders (meshoptimizer.h), loaded by soname */
typedef int (*meshopt_decode_fn)(void *dst, size_t count, size_t size, const unsigned char *src, size_t src_size);
typedef void (*meshopt_filter_fn)(void *buffer, size_t count, size_t stride);
static struct {
    meshopt_decode_fn vertex, index, sequence;
    meshopt_filter_fn oct, quat, exp;
} mo;
static dynlib mo_lib = DYNLIB_INIT;

#if PK_HAVE_MESHOPT
static bool mo_init(void *h, const char *name, char *why, size_t n)
{
    static const char *const names[6] = {"meshopt_decodeVertexBuffer", "meshopt_decodeIndexBuffer",
                                         "meshopt_decodeIndexSequence", "meshopt_decodeFilterOct",
                                         "meshopt_decodeFilterQuat", "meshopt_decodeFilterExp"};
    void *sym[6];
    for (int k = 0; k < 6; k++)
        if (!(sym[k] = dynlib_symbol(h, names[k]))) {
            snprintf(why, n, "%s has no %s (meshoptimizer 0.18 or later is needed)", name, names[k]);
            return false;
        }
    memcpy(&mo.vertex, &sym[0], sizeof sym[0]);
    memcpy(&mo.index, &sym[1], sizeof sym[1]);
    memcpy(&mo.sequence, &sym[2], sizeof sym[2]);
    memcpy(&mo.oct, &sym[3], sizeof sym[3]);
    memcpy(&mo.quat, &sym[4], sizeof sym[4]);
    memcpy(&mo.exp, &sym[5], sizeof sym[5]);
    return true;
}
#endif

/* True when meshoptimizer's decoders are ready; else why says why not. */
static bool mo_loaded(char *why, size_t n)
{
#if PK_HAVE_MESHOPT
    char reason[400];
    if (dynlib_load(&mo_lib, PK_MESHOPT_SONAME, mo_init, reason, sizeof reason)) return true;
    snprintf(why, n, "meshoptimizer does not load (%.300s; Debian: libmeshoptimizer2d)", reason);
#else
    (void)mo_lib;
    snprintf(why, n, "this build does not decode it (meshoptimizer's header, Debian libmeshoptimizer-dev, was "
                     "missing when it was built)");
#endif
    return false;
}

/* Whether buffer b is a placeholder: no uri and not the GLB's BIN chunk, or
 * marked as EXT_meshopt_compression's fallback. */
static bool buffer_is_placeholder(gltf *g, int64_t b)
{
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "buffers"), (int)b);
    const cJSON *fb = cJSON_GetObjectItemCaseSensitive(gltf_ext(o, "EXT_meshopt_compression"), "fallback");
    if (cJSON_IsTrue(fb)) return true;
    return !cJSON_IsString(cJSON_GetObjectItemCaseSensitive(o, "uri")) && !(b == 0 && g->bin);
}

/* Buffer view i (path) carries ext: its bytes decoded into g->view_dec[i]
 * (len bytes, the view's byteLength; vstride its byteStride or 0). *data
 * NULL and PK_OK: not decoded (no meshoptimizer), read the view's own buffer. */
static pk_status meshopt_view(gltf *g, int64_t i, const cJSON *ext, const char *path, int64_t buf, int64_t len,
                              int64_t vstride, const uint8_t **data)
{
    *data = NULL;
    char ep[96];
    snprintf(ep, sizeof ep, "%s/extensions/EXT_meshopt_compression", path);
    if (!cJSON_IsObject(ext)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", ep);
    pk_status st;
    int64_t cbuf, off, clen, stride, count;
    const char *mode, *filter;
    if ((st = gltf_index(g, ext, ep, "buffer", g->nbuffers, true, &cbuf))) return st;
    if ((st = gltf_int(g, ext, ep, "byteOffset", 0, INT64_MAX, 0, &off))) return st;
    if ((st = gltf_int(g, ext, ep, "byteLength", 1, INT64_MAX, -1, &clen))) return st;
    if (clen < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: byteLength is required", ep);
    if ((st = gltf_int(g, ext, ep, "byteStride", 1, 256, -1, &stride))) return st;
    if (stride < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: byteStride is required", ep);
    if ((st = gltf_int(g, ext, ep, "count", 1, INT64_MAX, -1, &count))) return st;
    if (count < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: count is required", ep);
    if ((st = gltf_string(g, ext, ep, "mode", &mode))) return st;
    if (!mode) return gltf_fail(g, PK_ERR_PARSE, "%s: mode is required", ep);
    if ((st = gltf_string(g, ext, ep, "filter", &filter))) return st;
    if (!filter) filter = "NONE";
    int m = strcmp(mode, "ATTRIBUTES") == 0 ? 0 : strcmp(mode, "TRIANGLES") == 0 ? 1 : strcmp(mode, "INDICES") == 0 ? 2 : -1;
    if (m < 0)
        return gltf_fail(g, PK_ERR_PARSE, "%s/mode: '%.32s' is not ATTRIBUTES, TRIANGLES or INDICES", ep, mode);
    int f = strcmp(filter, "NONE") == 0 ? 0 : strcmp(filter, "OCTAHEDRAL") == 0 ? 1 : strcmp(filter, "QUATERNION") == 0 ? 2
            : strcmp(filter, "EXPONENTIAL") == 0 ? 3 : -1;
    if (f < 0)
        return gltf_fail(g, PK_ERR_PARSE, "%s/filter: '%.32s' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL", ep,
                         filter);
    /* the extension's rules on strides, counts and filters */
    if (vstride && vstride != stride)
        return gltf_fail(g, PK_ERR_PARSE, "%s: byteStride %lld differs from the buffer view's %lld", ep,
                         (long long)stride, (long long)vstride);
    if ((uint64_t)count > (uint64_t)INT64_MAX / (uint64_t)stride || count * stride != len)
        return gltf_fail(g, PK_ERR_PARSE, "%s: count %lld times byteStride %lld is not the buffer view's byteLength %lld",
                         ep, (long long)count, (long long)stride, (long long)len);
    if (m == 0 && stride % 4)
        return gltf_fail(g, PK_ERR_PARSE, "%s: ATTRIBUTES with byteStride %lld, not a multiple of 4", ep, (long long)stride);
    if (m != 0 && stride != 2 && stride != 4)
        return gltf_fail(g, PK_ERR_PARSE, "%s: %s with byteStride %lld, not 2 or 4", ep, mode, (long long)stride);
    if (m == 1 && count % 3)
        return gltf_fail(g, PK_ERR_PARSE, "%s: TRIANGLES with count %lld, not a multiple of 3", ep, (long long)count);
    if (m != 0 && f != 0) return gltf_fail(g, PK_ERR_PARSE, "%s: the filter of %s must be NONE", ep, mode);
    if ((f == 1 && stride != 4 && stride != 8) || (f == 2 && stride != 8))
        return gltf_fail(g, PK_ERR_PARSE, "%s: filter %s with byteStride %lld (%s)", ep, filter, (long long)stride,
                         f == 1 ? "4 or 8 required" : "8 required");
    /* The densest stream holds a byte of headers per element byte of a block
     * of at most 256 elements (indices need more): a decoded length beyond
     * 256 times the compressed one is a lie, refused before allocating it. */
    if ((uint64_t)len / 256 > (uint64_t)clen)
        return gltf_fail(g, PK_ERR_PARSE, "%s: %lld decoded bytes cannot come from %lld compressed bytes", ep,
                         (long long)len, (long long)clen);
    char why[400];
    if (!mo_loaded(why, sizeof why)) {
        if (buffer_is_placeholder(g, buf))
            return gltf_fail(g, PK_ERR_UNSUPPORTED, "%s: meshopt-compressed data, and %s", ep, why);
        gltf_warn_once(g, GW_MESHOPT, "%s: meshopt-compressed data not decoded (%s); the uncompressed fallback is read",
                       ep, why);
        return PK_OK;
    }
    const gltf_buffer *b;
    if ((st = load_buffer(g, cbuf, &b))) return st;
    if ((uint64_t)off > b->size || (uint64_t)clen > b->size - (uint64_t)off)
        return gltf_fail(g, PK_ERR_PARSE, "%s: byteOffset %lld + byteLength %lld exceeds buffer %lld (%zu bytes)", ep,
                         (long long)off, (long long)clen, (long long)cbuf, b->size);
    if (!g->view_dec) {
        size_t nv = gltf_count(g, "bufferViews");
        g->view_dec = mem_calloc(&g->ctx->alloc, nv ? nv : 1, sizeof *g->view_dec);
        if (!g->view_dec) return ctx_nomem(g->ctx);
        g->nview_dec = nv;
    }
    uint8_t *out = mem_alloc(&g->ctx->alloc, (size_t)len);
    if (!out) return ctx_nomem(g->ctx);
    const uint8_t *src = b->data + off;
    int rc = m == 0   ? mo.vertex(out, (size_t)count, (size_t)stride, src, (size_t)clen)
             : m == 1 ? mo.index(out, (size_t)count, (size_t)stride, src, (size_t)clen)
                      : mo.sequence(out, (size_t)count, (size_t)stride, src, (size_t)clen);
    if (rc != 0) {
        mem_free(&g->ctx->alloc, out);
        return gltf_fail(g, PK_ERR_PARSE, "%s: corrupt %s stream (meshoptimizer's decoder says %d)", ep, mode, rc);
    }
    if (f == 1) mo.oct(out, (size_t)count, (size_t)stride);
    else if (f == 2) mo.quat(out, (size_t)count, (size_t)stride);
    else if (f == 3) mo.exp(out, (size_t)count, (size_t)stride);
    g->view_dec[i] = out;
    *data = out;
    return PK_OK;
}

pk_status gltf_view(gltf *g, int64_t i, const uint8_t **data, size_t *size, size_t *stride)
{
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "bufferViews"), (int)i);
    char path[48];
    snprintf(path, sizeof path, "/bufferViews/%lld", (long long)i);
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    int64_t buf, off, len, st_;
    pk_status st;
    if ((st = gltf_index(g, o, path, "buffer", g->nbuffers, true, &buf))) return st;
    if ((st = gltf_int(g, o, path, "byteOffset", 0, INT64_MAX, 0, &off))) return st;
    if ((st = gltf_int(g, o, path, "byteLength", 1, INT64_MAX, -1, &len))) return st;
    if (len < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: byteLength is required", path);
    if ((st = gltf_int(g, o, path, "byteStride", 4, 252, 0, &st_))) return st;
    if (st_ % 4) return gltf_fail(g, PK_ERR_PARSE, "%s: byteStride %lld is not a multiple of 4", path, (long long)st_);
    const cJSON *mx = gltf_ext(o, "EXT_meshopt_compression");
    if (mx) {
        const uint8_t *dec = (size_t)i < g->nview_dec ? g->view_dec[i] : NULL;
        if (!dec && (st = meshopt_view(g, i, mx, path, buf, len, st_, &dec))) return st;
        if (dec) {
            *data = dec;
            *size = (size_t)len;
            *stride = (size_t)st_;
            return PK_OK;
        }
    }
    const gltf_buffer *b;
    if ((st = load_buffer(g, buf, &b))) return st;
    if ((uint64_t)off > b->size || (uint64_t)len > b->size - (uint64_t)off)
        return gltf_fail(g, PK_ERR_PARSE, "%s: byteOffset %lld + byteLength %lld exceeds buffer %lld (%zu bytes)", path,
                         (long long)off, (long long)len, (long long)buf, b->size);
    *data = b->data + off;
    *size = (size_t)len;
    *stride = (size_t)st_;
    return PK_OK;
}

/* ---- accessors ------------------------------------------------------------------ */

static int comp_size(int ctype)
{
    switch (ctype) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

/* Components of a type (0: unknown); *cols: columns of a matrix, 0 for the others. */
static int type_comps(const char *t, int *cols)
{
    static const char *const names[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    static const int n[] = {1, 2, 3, 4, 4, 9, 16}, c[] = {0, 0, 0, 0, 2, 3, 4};
    for (int i = 0; i < 7; i++)
        if (strcmp(t, names[i]) == 0) {
            *cols = c[i];
            return n[i];
        }
    *cols = 0;
    return 0;
}

/* An element's bytes: matrix columns start on 4-byte boundaries. */
static size_t elem_size(int ncomp, int cols, int cs)
{
    if (cols) {
        size_t col = ((size_t)cols * (size_t)cs + 3) & ~(size_t)3;
        return col * (size_t)cols;
    }
    return (size_t)ncomp * (size_t)cs;
}

/* A component (raw value), little-endian. */
static double comp_raw(const uint8_t *p, int ctype)
{
    switch (ctype) {
    case 5120: return (double)(int8_t)p[0];
    case 5121: return (double)p[0];
    case 5122: return (double)(int16_t)(uint16_t)(p[0] | p[1] << 8);
    case 5123: return (double)(uint16_t)(p[0] | p[1] << 8);
    case 5125: return (double)rd32(p);
    default: {
        uint32_t w = rd32(p);
        float f;
        memcpy(&f, &w, 4);
        return (double)f;
    }
    }
}

/* The value the specification gives a normalized integer. */
static double comp_value(const uint8_t *p, int ctype, bool normalized)
{
    double v = comp_raw(p, ctype);
    if (!normalized) return v;
    switch (ctype) {
    case 5120: return fmax(v / 127.0, -1.0);
    case 5121: return v / 255.0;
    case 5122: return fmax(v / 32767.0, -1.0);
    case 5123: return v / 65535.0;
    default: return v;
    }
}

pk_status gltf_accessor_get(gltf *g, int64_t i, gltf_accessor *a)
{
    memset(a, 0, sizeof *a);
    if ((size_t)i < g->nacc_dec && g->acc_data[i]) { /* decoded from a Draco primitive */
        *a = g->acc_dec[i];
        return PK_OK;
    }
    const cJSON *o = cJSON_GetArrayItem(gltf_array(g, "accessors"), (int)i);
    char path[48];
    snprintf(path, sizeof path, "/accessors/%lld", (long long)i);
    if (!cJSON_IsObject(o)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", path);
    pk_status st;
    int64_t view, off, ctype, count;
    if ((st = gltf_index(g, o, path, "bufferView", gltf_count(g, "bufferViews"), false, &view))) return st;
    if ((st = gltf_int(g, o, path, "byteOffset", 0, INT64_MAX, 0, &off))) return st;
    if ((st = gltf_int(g, o, path, "componentType", 5120, 5126, -1, &ctype))) return st;
    if (ctype < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: componentType is required", path);
    int cs = comp_size((int)ctype);
    if (!cs) return gltf_fail(g, PK_ERR_PARSE, "%s: componentType %lld is not a glTF component type", path, (long long)ctype);
    if ((st = gltf_int(g, o, path, "count", 1, INT64_MAX, -1, &count))) return st;
    if (count < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: count is required", path);
    const char *type;
    if ((st = gltf_string(g, o, path, "type", &type))) return st;
    if (!type) return gltf_fail(g, PK_ERR_PARSE, "%s: type is required", path);
    int cols;
    int nc = type_comps(type, &cols);
    if (!nc) return gltf_fail(g, PK_ERR_PARSE, "%s: type '%.16s' is not a glTF accessor type", path, type);
    const cJSON *nm = cJSON_GetObjectItemCaseSensitive(o, "normalized");
    if (nm && !cJSON_IsBool(nm)) return gltf_fail(g, PK_ERR_PARSE, "%s/normalized: must be true or false", path);
    a->normalized = cJSON_IsTrue(nm);
    if (a->normalized && (ctype == 5125 || ctype == 5126))
        return gltf_fail(g, PK_ERR_PARSE, "%s: normalized applies to 8- and 16-bit integers only", path);
    a->ctype = (int)ctype;
    a->ncomp = nc;
    a->count = (size_t)count;
    if ((uint64_t)count != a->count) return gltf_fail(g, PK_ERR_LIMIT, "%s: count %lld is too large", path, (long long)count);
    size_t es = elem_size(nc, cols, cs);
    a->matrix = cols != 0;
    if (view >= 0) {
        const uint8_t *vd;
        size_t vlen, vstride;
        if ((st = gltf_view(g, view, &vd, &vlen, &vstride))) return st;
        size_t stride = vstride ? vstride : es;
        if (stride < es)
            return gltf_fail(g, PK_ERR_PARSE, "%s: bufferView %lld's byteStride %zu is less than an element (%zu bytes)",
                             path, (long long)view, stride, es);
        /* off + stride * (count - 1) + es <= vlen, without overflow */
        size_t need;
        if ((uint64_t)off > vlen || size_mul_overflows(stride, a->count - 1, &need) || need > vlen - (size_t)off ||
            es > vlen - (size_t)off - need)
            return gltf_fail(g, PK_ERR_PARSE, "%s: count %zu exceeds bufferView %lld (%zu bytes)", path, a->count,
                             (long long)view, vlen);
        a->base = vd + off;
        a->stride = stride;
    } else {
        if (off) return gltf_fail(g, PK_ERR_PARSE, "%s: byteOffset without a bufferView", path);
        if (a->count > GLTF_MAX_ZERO_COUNT)
            return gltf_fail(g, PK_ERR_LIMIT, "%s: count %zu without a bufferView is more than %zu", path, a->count,
                             GLTF_MAX_ZERO_COUNT);
        a->stride = es;
    }
    const cJSON *sp = cJSON_GetObjectItemCaseSensitive(o, "sparse");
    if (sp) {
        char sp_path[64], ip[80], vp[80];
        snprintf(sp_path, sizeof sp_path, "%s/sparse", path);
        if (!cJSON_IsObject(sp)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", sp_path);
        if (cols) return gltf_fail(g, PK_ERR_UNSUPPORTED, "%s: sparse matrices are not read", sp_path);
        int64_t n;
        if ((st = gltf_int(g, sp, sp_path, "count", 1, (int64_t)a->count, -1, &n))) return st;
        if (n < 0) return gltf_fail(g, PK_ERR_PARSE, "%s: count is required", sp_path);
        const cJSON *ind = cJSON_GetObjectItemCaseSensitive(sp, "indices");
        const cJSON *val = cJSON_GetObjectItemCaseSensitive(sp, "values");
        snprintf(ip, sizeof ip, "%s/indices", sp_path);
        snprintf(vp, sizeof vp, "%s/values", sp_path);
        if (!cJSON_IsObject(ind)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", ip);
        if (!cJSON_IsObject(val)) return gltf_fail(g, PK_ERR_PARSE, "%s: must be an object", vp);
        int64_t iv, ioff, it, vv, voff;
        if ((st = gltf_index(g, ind, ip, "bufferView", gltf_count(g, "bufferViews"), true, &iv))) return st;
        if ((st = gltf_int(g, ind, ip, "byteOffset", 0, INT64_MAX, 0, &ioff))) return st;
        if ((st = gltf_int(g, ind, ip, "componentType", 5121, 5125, -1, &it))) return st;
        if (it != 5121 && it != 5123 && it != 5125)
            return gltf_fail(g, PK_ERR_PARSE, "%s: componentType must be 5121, 5123 or 5125", ip);
        if ((st = gltf_index(g, val, vp, "bufferView", gltf_count(g, "bufferViews"), true, &vv))) return st;
        if ((st = gltf_int(g, val, vp, "byteOffset", 0, INT64_MAX, 0, &voff))) return st;
        const uint8_t *d;
        size_t len, stride_unused, need;
        if ((st = gltf_view(g, iv, &d, &len, &stride_unused))) return st;
        if ((uint64_t)ioff > len || size_mul_overflows((size_t)n, (size_t)comp_size((int)it), &need) ||
            need > len - (size_t)ioff)
            return gltf_fail(g, PK_ERR_PARSE, "%s: count %lld exceeds bufferView %lld (%zu bytes)", ip, (long long)n,
                             (long long)iv, len);
        a->sp_idx = d + ioff;
        if ((st = gltf_view(g, vv, &d, &len, &stride_unused))) return st;
        if ((uint64_t)voff > len || size_mul_overflows((size_t)n, es, &need) || need > len - (size_t)voff)
            return gltf_fail(g, PK_ERR_PARSE, "%s: count %lld exceeds bufferView %lld (%zu bytes)", vp, (long long)n,
                             (long long)vv, len);
        a->sp_val = d + voff;
        a->sp_itype = (int)it;
        a->nsparse = (size_t)n;
        /* every substituted index within the accessor */
        int is = comp_size((int)it);
        for (size_t k = 0; k < a->nsparse; k++) {
            double x = comp_raw(a->sp_idx + k * (size_t)is, a->sp_itype);
            if (x >= (double)a->count)
                return gltf_fail(g, PK_ERR_PARSE, "%s: index %.0f out of range (count %zu)", ip, x, a->count);
        }
    }
    return PK_OK;
}

pk_status gltf_read_floats(gltf *g, int64_t i, const gltf_accessor *a, float **out)
{
    *out = NULL;
    if (a->matrix) return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: a matrix where a vector is expected", (long long)i);
    float *f = mem_calloc(&g->ctx->alloc, a->count, (size_t)a->ncomp * sizeof *f);
    if (!f) return ctx_nomem(g->ctx);
    const int cs = comp_size(a->ctype);
    if (a->base)
        for (size_t k = 0; k < a->count; k++)
            for (int c = 0; c < a->ncomp; c++)
                f[k * (size_t)a->ncomp + (size_t)c] =
                    (float)comp_value(a->base + k * a->stride + (size_t)c * (size_t)cs, a->ctype, a->normalized);
    const int is = comp_size(a->sp_itype);
    const size_t es = (size_t)a->ncomp * (size_t)cs;
    for (size_t k = 0; k < a->nsparse; k++) {
        size_t at = (size_t)comp_raw(a->sp_idx + k * (size_t)is, a->sp_itype);
        for (int c = 0; c < a->ncomp; c++)
            f[at * (size_t)a->ncomp + (size_t)c] =
                (float)comp_value(a->sp_val + k * es + (size_t)c * (size_t)cs, a->ctype, a->normalized);
    }
    *out = f;
    return PK_OK;
}

pk_status gltf_read_mat4(gltf *g, int64_t i, const gltf_accessor *a, xform **out)
{
    *out = NULL;
    if (!a->matrix || a->ncomp != 16 || a->ctype != 5126)
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: must be a MAT4 of floats", (long long)i);
    xform *x = mem_calloc(&g->ctx->alloc, a->count, sizeof *x);
    if (!x) return ctx_nomem(g->ctx);
    for (size_t k = 0; k < a->count; k++) {
        float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        if (a->base)
            for (int c = 0; c < 16; c++) m[c] = (float)comp_raw(a->base + k * a->stride + (size_t)c * 4, 5126);
        if (m[3] != 0.0f || m[7] != 0.0f || m[11] != 0.0f || m[15] != 1.0f) {
            mem_free(&g->ctx->alloc, x);
            return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: matrix %zu is not affine (its last row is not 0 0 0 1)",
                             (long long)i, k);
        }
        for (int row = 0; row < 4; row++)
            for (int col = 0; col < 4; col++) x[k].m[4 * row + col] = m[4 * col + row];
    }
    *out = x;
    return PK_OK;
}

pk_status gltf_read_uints(gltf *g, int64_t i, const gltf_accessor *a, uint32_t **out)
{
    *out = NULL;
    if (a->ncomp != 1 || a->normalized || (a->ctype != 5121 && a->ctype != 5123 && a->ctype != 5125))
        return gltf_fail(g, PK_ERR_PARSE, "/accessors/%lld: indices must be SCALAR unsigned bytes, shorts or ints",
                         (long long)i);
    uint32_t *u = mem_calloc(&g->ctx->alloc, a->count, sizeof *u);
    if (!u) return ctx_nomem(g->ctx);
    const int cs = comp_size(a->ctype);
    if (a->base)
        for (size_t k = 0; k < a->count; k++) u[k] = (uint32_t)comp_raw(a->base + k * a->stride, a->ctype);
    const int is = comp_size(a->sp_itype);
    for (size_t k = 0; k < a->nsparse; k++) {
        size_t at = (size_t)comp_raw(a->sp_idx + k * (size_t)is, a->sp_itype);
        u[at] = (uint32_t)comp_raw(a->sp_val + k * (size_t)cs, a->ctype);
    }
    *out = u;
    return PK_OK;
}

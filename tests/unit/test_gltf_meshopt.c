/*
 * test_gltf_meshopt.c - EXT_meshopt_compression (io/gltf_data.c): buffer
 * views compressed here with meshoptimizer's own encoders, in every mode
 * (ATTRIBUTES, TRIANGLES, INDICES) and filter (OCTAHEDRAL, QUATERNION,
 * EXPONENTIAL), read back through gltf_view and compared with the data
 * they were made from: exactly where the codec is lossless (modes without a
 * filter; meshoptimizer's triangle encoder keeps the triangles' order but
 * may turn a triangle's vertices, its winding kept, for a smaller stream),
 * within the quantisation the filter's encoder was asked for otherwise; a
 * mesh whose views are all compressed gives the same scene, bit for bit (up
 * to those turns), as the same mesh uncompressed; fallback buffers, and corrupt
 * or lying streams get one "file: /json/pointer: what is wrong" error.
 * Skipped when the build has no meshoptimizer.
 */
#include "test.h"
#include "warnings.h"

#include "io/gltf.h"
#include "io/readers.h"
#include "scene/scene.h"

#include <stdint.h>

#if PK_HAVE_MESHOPT
#include <meshoptimizer.h>

/* ---- a buffer of streams, and a document over it ---------------------------------- */

typedef struct bytes {
    uint8_t d[1 << 17];
    size_t n;
} bytes;

static size_t put(bytes *b, const void *p, size_t n)
{
    REQUIRE(b->n + n + 4 <= sizeof b->d);
    size_t at = b->n;
    memcpy(b->d + b->n, p, n);
    b->n += n;
    while (b->n % 4) b->d[b->n++] = 0;
    return at;
}

static char *b64(const uint8_t *p, size_t n)
{
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *o = malloc(4 * (n / 3 + 1) + 64), *q = o;
    q += sprintf(q, "data:application/octet-stream;base64,");
    for (size_t i = 0; i < n; i += 3) {
        uint32_t w = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        *q++ = al[w >> 18 & 63];
        *q++ = al[w >> 12 & 63];
        *q++ = i + 1 < n ? al[w >> 6 & 63] : '=';
        *q++ = i + 2 < n ? al[w & 63] : '=';
    }
    *q = '\0';
    return o;
}

/* A compressed stream of mode (0 attributes, 1 triangles, 2 indices) put in b. */
static size_t encode(bytes *b, int mode, const void *data, size_t count, size_t stride, size_t *len)
{
    size_t cap = mode == 0 ? meshopt_encodeVertexBufferBound(count, stride)
                 : mode == 1 ? meshopt_encodeIndexBufferBound(count, 1u << 16)
                             : meshopt_encodeIndexSequenceBound(count, 1u << 16);
    uint8_t *tmp = malloc(cap);
    size_t n = mode == 0 ? meshopt_encodeVertexBuffer(tmp, cap, data, count, stride)
               : mode == 1 ? meshopt_encodeIndexBuffer(tmp, cap, data, count)
                           : meshopt_encodeIndexSequence(tmp, cap, data, count);
    REQUIRE(n > 0);
    size_t at = put(b, tmp, n);
    free(tmp);
    *len = n;
    return at;
}

/* The JSON of one compressed view over buffer 0 whose fallback is buffer 1. */
static void view_json(char *out, size_t n, size_t at, size_t len, size_t stride, size_t count, const char *mode,
                      const char *filter)
{
    snprintf(out, n,
             "{\"buffer\":1,\"byteLength\":%zu,\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,"
             "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":%zu,\"count\":%zu,\"mode\":\"%s\"%s%s%s}}}",
             stride * count, at, len, stride, count, mode, filter ? ",\"filter\":\"" : "", filter ? filter : "",
             filter ? "\"" : "");
}

static char *document(const bytes *b, const char *views, const char *fallback)
{
    char *uri = b64(b->d, b->n);
    size_t n = strlen(uri) + strlen(views) + strlen(fallback) + 512;
    char *j = malloc(n);
    snprintf(j, n,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_meshopt_compression\"],"
             "\"extensionsRequired\":[\"EXT_meshopt_compression\"],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"},%s],\"bufferViews\":[%s]}",
             b->n, uri, fallback, views);
    free(uri);
    return j;
}

static const char *const placeholder =
    "{\"byteLength\":1048576,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}";

/* The reader's state over a document (what scene_gltf_parse sets up for gltf_view). */
typedef struct doc {
    gltf g;
    pk_context *ctx;
} doc;

static void doc_open(doc *d, const char *json)
{
    memset(d, 0, sizeof *d);
    REQUIRE(pk_context_create(NULL, &d->ctx) == PK_OK);
    d->g.ctx = d->ctx;
    d->g.name = "t.gltf";
    d->g.root = cJSON_Parse(json);
    REQUIRE(d->g.root);
    d->g.nbuffers = gltf_count(&d->g, "buffers");
    d->g.buffers = calloc(d->g.nbuffers + 1, sizeof *d->g.buffers);
}

static void doc_close(doc *d)
{
    gltf_buffers_free(&d->g);
    cJSON_Delete(d->g.root);
    pk_context_destroy(d->ctx);
}

/* ---- lossless modes --------------------------------------------------------------- */

/* Triangle t of got (indices of size 2 or 4) is triangle t of want, turned
 * by 0, 1 or 2 (the same winding): how many are not. */
static int triangles_differ(const uint8_t *got, int size, const uint32_t *want, size_t ntri)
{
    int bad = 0;
    for (size_t t = 0; t < ntri; t++) {
        uint32_t g[3];
        for (int k = 0; k < 3; k++)
            g[k] = size == 2 ? ((const uint16_t *)(const void *)got)[3 * t + (size_t)k]
                             : ((const uint32_t *)(const void *)got)[3 * t + (size_t)k];
        bool same = false;
        for (int r = 0; r < 3; r++)
            same |= g[r] == want[3 * t] && g[(r + 1) % 3] == want[3 * t + 1] && g[(r + 2) % 3] == want[3 * t + 2];
        bad += !same;
    }
    return bad;
}

static uint32_t rng_state = 12345;
static uint32_t rnd(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return rng_state >> 8;
}
static float rndf(void) { return (float)rnd() / (float)(1u << 24); }

static void test_lossless(void)
{
    static bytes b;
    b.n = 0;
    /* positions: 700 float VEC3 (three attribute blocks of 256), smooth plus noise */
    enum { NV = 700, NI = 3 * 600 };
    static float pos[NV * 3];
    for (int i = 0; i < NV; i++)
        for (int c = 0; c < 3; c++) pos[3 * i + c] = (float)(i % 37) * 0.25f + (float)c + rndf() * 1e-3f;
    /* 16-byte elements: two floats, four bytes, two shorts (interleaved, as a stride allows) */
    static uint8_t mixed[NV * 16];
    for (size_t i = 0; i < sizeof mixed; i++) mixed[i] = (uint8_t)(i % 16 < 8 ? (i * 7) >> 3 : rnd());
    /* triangle indices (a strip of the vertices, as a mesh has) and an arbitrary sequence */
    static uint32_t tri[NI], seq[NI];
    for (int t = 0; t < NI / 3; t++) tri[3 * t] = (uint32_t)t, tri[3 * t + 1] = (uint32_t)t + 1, tri[3 * t + 2] = (uint32_t)t + 2;
    for (int i = 0; i < NI; i++) seq[i] = rnd() % NV;
    size_t len[5], at[5];
    at[0] = encode(&b, 0, pos, NV, 12, &len[0]);
    at[1] = encode(&b, 0, mixed, NV, 16, &len[1]);
    at[2] = encode(&b, 1, tri, NI, 0, &len[2]);
    at[3] = encode(&b, 2, seq, NI, 0, &len[3]);
    at[4] = at[2], len[4] = len[2]; /* the triangles again, decoded as 16-bit */
    char v[5][512], views[2600];
    view_json(v[0], sizeof v[0], at[0], len[0], 12, NV, "ATTRIBUTES", NULL);
    view_json(v[1], sizeof v[1], at[1], len[1], 16, NV, "ATTRIBUTES", "NONE");
    view_json(v[2], sizeof v[2], at[2], len[2], 4, NI, "TRIANGLES", NULL);
    view_json(v[3], sizeof v[3], at[3], len[3], 4, NI, "INDICES", NULL);
    view_json(v[4], sizeof v[4], at[4], len[4], 2, NI, "TRIANGLES", NULL);
    snprintf(views, sizeof views, "%s,%s,%s,%s,%s", v[0], v[1], v[2], v[3], v[4]);
    char *json = document(&b, views, placeholder);
    doc d;
    doc_open(&d, json);
    const uint8_t *p;
    size_t size, stride;
    REQUIRE(gltf_view(&d.g, 0, &p, &size, &stride) == PK_OK);
    CHECK(size == sizeof pos && memcmp(p, pos, size) == 0);
    REQUIRE(gltf_view(&d.g, 1, &p, &size, &stride) == PK_OK);
    CHECK(size == sizeof mixed && memcmp(p, mixed, size) == 0);
    REQUIRE(gltf_view(&d.g, 2, &p, &size, &stride) == PK_OK);
    CHECK(size == sizeof tri);
    int turned = triangles_differ(p, 4, tri, NI / 3);
    CHECKF(turned == 0, "%d 32-bit triangles differ", turned);
    REQUIRE(gltf_view(&d.g, 3, &p, &size, &stride) == PK_OK);
    CHECK(size == sizeof seq && memcmp(p, seq, size) == 0);
    REQUIRE(gltf_view(&d.g, 4, &p, &size, &stride) == PK_OK);
    REQUIRE(size == 2 * NI);
    turned = triangles_differ(p, 2, tri, NI / 3);
    CHECKF(turned == 0, "%d 16-bit triangles differ", turned);
    /* a second look returns the bytes decoded before */
    const uint8_t *again;
    REQUIRE(gltf_view(&d.g, 0, &again, &size, &stride) == PK_OK);
    REQUIRE(gltf_view(&d.g, 0, &p, &size, &stride) == PK_OK);
    CHECK(again == p);
    printf("lossless: %zu + %zu + %zu + %zu compressed bytes for %zu + %zu + %zu + %zu\n", len[0], len[1], len[2],
           len[3], sizeof pos, sizeof mixed, sizeof tri, sizeof seq);
    doc_close(&d);
    free(json);
}

/* ---- filters ----------------------------------------------------------------------- */

static void test_filters(void)
{
    static bytes b;
    b.n = 0;
    enum { N = 500 };
    /* unit vectors (w = 0), unit quaternions, and floats over twelve octaves */
    static float nrm[N * 4], quat[N * 4], val[N * 3];
    for (int i = 0; i < N; i++) {
        float x = 2 * rndf() - 1, y = 2 * rndf() - 1, z = 2 * rndf() - 1, w = 2 * rndf() - 1;
        float l3 = sqrtf(x * x + y * y + z * z), l4 = sqrtf(x * x + y * y + z * z + w * w);
        nrm[4 * i] = x / l3, nrm[4 * i + 1] = y / l3, nrm[4 * i + 2] = z / l3, nrm[4 * i + 3] = 0;
        quat[4 * i] = x / l4, quat[4 * i + 1] = y / l4, quat[4 * i + 2] = z / l4, quat[4 * i + 3] = w / l4;
        for (int c = 0; c < 3; c++) val[3 * i + c] = (2 * rndf() - 1) * ldexpf(1.0f, (int)(rnd() % 12) - 6);
    }
    /* the filters' encoders, at the precisions asked for */
    const int oct16 = 16, oct8 = 8, qbits = 12, ebits = 15;
    static int16_t oct16_data[N * 4], quat_data[N * 4];
    static int8_t oct8_data[N * 4];
    static uint32_t exp_data[N * 3];
    meshopt_encodeFilterOct(oct16_data, N, 8, oct16, nrm);
    meshopt_encodeFilterOct(oct8_data, N, 4, oct8, nrm);
    meshopt_encodeFilterQuat(quat_data, N, 8, qbits, quat);
    meshopt_encodeFilterExp(exp_data, N, 12, ebits, val);
    size_t len[4], at[4];
    at[0] = encode(&b, 0, oct16_data, N, 8, &len[0]);
    at[1] = encode(&b, 0, oct8_data, N, 4, &len[1]);
    at[2] = encode(&b, 0, quat_data, N, 8, &len[2]);
    at[3] = encode(&b, 0, exp_data, N, 12, &len[3]);
    char v[4][512], views[2100];
    view_json(v[0], sizeof v[0], at[0], len[0], 8, N, "ATTRIBUTES", "OCTAHEDRAL");
    view_json(v[1], sizeof v[1], at[1], len[1], 4, N, "ATTRIBUTES", "OCTAHEDRAL");
    view_json(v[2], sizeof v[2], at[2], len[2], 8, N, "ATTRIBUTES", "QUATERNION");
    view_json(v[3], sizeof v[3], at[3], len[3], 12, N, "ATTRIBUTES", "EXPONENTIAL");
    snprintf(views, sizeof views, "%s,%s,%s,%s", v[0], v[1], v[2], v[3]);
    char *json = document(&b, views, placeholder);
    doc d;
    doc_open(&d, json);
    const uint8_t *p;
    size_t size, stride;
    /* OCTAHEDRAL: K-bit octahedral coordinates (u, v) (a step of
     * 1 / (2^(K-1) - 1)), stored as normalized integers of the view's width.
     * Rounding moves (u, v) by at most step / sqrt 2; the map to the sphere,
     * (u, v, 1 - |u| - |v|) normalized, stretches that by at most
     * sqrt 2 * sqrt 3 (its derivative before normalization is at most sqrt 2
     * long, and the normalization divides by at least 1 / sqrt 3): at most
     * sqrt 3 steps; the normalized store adds half a step a component. So
     * each decoded component lies within 2.5 steps of the original. */
    for (int k = 0; k < 2; k++) {
        REQUIRE(gltf_view(&d.g, k, &p, &size, &stride) == PK_OK);
        const int bits = k ? oct8 : oct16;
        const double scale = k ? 127.0 : 32767.0, tol = 2.5 / (double)((1 << (bits - 1)) - 1);
        double worst = 0;
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                double got = k ? ((const int8_t *)(const void *)p)[4 * i + c] / scale
                               : ((const int16_t *)(const void *)p)[4 * i + c] / scale;
                worst = fmax(worst, fabs(got - (double)nrm[4 * i + c]));
            }
        CHECKF(worst <= tol, "OCTAHEDRAL %d bits: error %g beyond %g", bits, worst, tol);
        printf("OCTAHEDRAL %2d bits: largest error %.3g (bound %.3g)\n", bits, worst, tol);
    }
    /* QUATERNION: the three smallest components (each within 1/sqrt 2) in
     * K-bit steps of sqrt 2 / (2^(K-1) - 1), the largest made from them; the
     * decoded quaternion, as normalized shorts, is the original or its
     * negation (the same rotation) within two such steps a component */
    REQUIRE(gltf_view(&d.g, 2, &p, &size, &stride) == PK_OK);
    {
        const double tol = 2.0 * sqrt(2.0) / (double)((1 << (qbits - 1)) - 1);
        double worst = 0;
        for (int i = 0; i < N; i++) {
            const int16_t *q = (const int16_t *)(const void *)p + 4 * i;
            double dot = 0;
            for (int c = 0; c < 4; c++) dot += q[c] / 32767.0 * (double)quat[4 * i + c];
            double sgn = dot < 0 ? -1 : 1;
            for (int c = 0; c < 4; c++) worst = fmax(worst, fabs(sgn * q[c] / 32767.0 - (double)quat[4 * i + c]));
        }
        CHECKF(worst <= tol, "QUATERNION: error %g beyond %g", worst, tol);
        printf("QUATERNION %d bits: largest error %.3g (bound %.3g)\n", qbits, worst, tol);
    }
    /* EXPONENTIAL: a K-bit signed mantissa under an exponent shared by the
     * element's components, set by the largest, max|x| < 2^e: a unit of
     * 2^(e - (K-1)) <= 2 max|x| 2^(1-K), so each component within half a
     * unit, max|x| * 2^(1-K) */
    REQUIRE(gltf_view(&d.g, 3, &p, &size, &stride) == PK_OK);
    {
        double worst = 0;
        int bad = 0;
        for (int i = 0; i < N; i++) {
            double m = 0;
            for (int c = 0; c < 3; c++) m = fmax(m, fabs((double)val[3 * i + c]));
            const double tol = m * ldexp(1.0, 1 - ebits);
            for (int c = 0; c < 3; c++) {
                double e = fabs((double)((const float *)(const void *)p)[3 * i + c] - (double)val[3 * i + c]);
                worst = fmax(worst, e / m);
                bad += e > tol;
            }
        }
        CHECKF(bad == 0, "EXPONENTIAL: %d components beyond half a mantissa unit", bad);
        printf("EXPONENTIAL %d bits: largest error %.3g of the element's largest component (bound %.3g)\n", ebits, worst,
               ldexp(1.0, 1 - ebits));
    }
    doc_close(&d);
    free(json);
}

/* ---- a compressed mesh renders the same scene ------------------------------------- */

static pk_status load(const char *json, pk_scene **out, char *msg, size_t nmsg, warning_log *wl)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    if (wl) warning_log_attach(ctx, wl);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse(ctx, s, json, strlen(json), "t.gltf", PK_TEST_DATA);
    if (st == PK_OK) st = scene_commit(ctx, s);
    snprintf(msg, nmsg, "%s", pk_context_error(ctx));
    if (st != PK_OK || !out) scene_destroy(s);
    else *out = s;
    pk_context_destroy(ctx);
    return st;
}

static void test_scene(void)
{
    enum { G = 12, NV = G * G, NT = 2 * (G - 1) * (G - 1) };
    static float pos[NV * 3], uv[NV * 2];
    static uint16_t idx[NT * 3 + 2];
    static uint32_t idx32[NT * 3];
    for (int y = 0; y < G; y++)
        for (int x = 0; x < G; x++) {
            int i = y * G + x;
            pos[3 * i] = (float)x / (G - 1), pos[3 * i + 1] = (float)y / (G - 1);
            pos[3 * i + 2] = 0.1f * sinf((float)(x * y));
            uv[2 * i] = (float)x / (G - 1), uv[2 * i + 1] = 1.0f - (float)y / (G - 1);
        }
    int t = 0;
    for (int y = 0; y + 1 < G; y++)
        for (int x = 0; x + 1 < G; x++) {
            uint32_t a = (uint32_t)(y * G + x), bb = a + 1, c = a + G, e = c + 1;
            uint32_t q[6] = {a, bb, e, a, e, c};
            for (int k = 0; k < 6; k++) idx32[3 * t + k] = q[k], idx[3 * t + k] = (uint16_t)q[k];
            t += 2;
        }
    /* the same mesh plain (buffer 1) and compressed (buffer 0) */
    static bytes plain, packed;
    plain.n = packed.n = 0;
    size_t pp = put(&plain, pos, sizeof pos), pu = put(&plain, uv, sizeof uv), pi = put(&plain, idx, NT * 3 * 2);
    size_t lp, lu, li;
    size_t cp = encode(&packed, 0, pos, NV, 12, &lp), cu = encode(&packed, 0, uv, NV, 8, &lu),
           ci = encode(&packed, 1, idx32, NT * 3, 0, &li);
    char *u0 = b64(packed.d, packed.n), *u1 = b64(plain.d, plain.n);
    static const char *const acc = "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
                                   "{\"bufferView\":1,\"componentType\":5126,\"count\":%d,\"type\":\"VEC2\"},"
                                   "{\"bufferView\":2,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}],"
                                   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},"
                                   "\"indices\":2}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";
    char accs[1024];
    snprintf(accs, sizeof accs, acc, NV, NV, NT * 3);
    size_t n = strlen(u0) + strlen(u1) + 4096;
    char *a = malloc(n), *c = malloc(n);
    /* uncompressed: the views over buffer 1 */
    snprintf(a, n,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"},"
             "{\"byteLength\":%zu,\"uri\":\"%s\"}],\"bufferViews\":[{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%zu},"
             "{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%d}],%s",
             packed.n, u0, plain.n, u1, pp, sizeof pos, pu, sizeof uv, pi, NT * 3 * 2, accs);
    /* compressed, its fallback a placeholder without data */
    char v0[512], v1[512], v2[512];
    view_json(v0, sizeof v0, cp, lp, 12, NV, "ATTRIBUTES", NULL);
    view_json(v1, sizeof v1, cu, lu, 8, NV, "ATTRIBUTES", NULL);
    view_json(v2, sizeof v2, ci, li, 2, NT * 3, "TRIANGLES", NULL);
    snprintf(c, n,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_meshopt_compression\"],"
             "\"extensionsRequired\":[\"EXT_meshopt_compression\"],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"},%s],\"bufferViews\":[%s,%s,%s],%s",
             packed.n, u0, placeholder, v0, v1, v2, accs);
    pk_scene *sa, *sc;
    char msg[1024];
    REQUIRE(load(a, &sa, msg, sizeof msg, NULL) == PK_OK);
    pk_status st = load(c, &sc, msg, sizeof msg, NULL);
    CHECKF(st == PK_OK, "%s", msg);
    if (st == PK_OK) {
        CHECK(sa->ntris == NT && sc->ntris == NT);
        int diff = 0;
        for (size_t k = 0; k < sa->ntris && k < sc->ntris; k++) {
            /* the turn of the compressed triangle that matches (vertex 0's position) */
            const triangle *ta = &sa->tris[k], *tc = &sc->tris[k];
            int r = 0;
            while (r < 3 && memcmp(&sa->positions[ta->v[0]], &sc->positions[tc->v[r]], sizeof(vec3)) != 0) r++;
            if (r == 3) {
                diff++;
                continue;
            }
            for (int j = 0; j < 3; j++) {
                int jc = (j + r) % 3;
                diff += memcmp(&sa->positions[ta->v[j]], &sc->positions[tc->v[jc]], sizeof(vec3)) != 0;
                diff += (ta->t[j] < 0) != (tc->t[jc] < 0);
                if (ta->t[j] >= 0 && tc->t[jc] >= 0)
                    diff += memcmp(&sa->uvs[ta->t[j]], &sc->uvs[tc->t[jc]], sizeof(uv2)) != 0;
            }
        }
        CHECKF(diff == 0, "%d vertex values differ between the compressed and the plain mesh", diff);
        printf("scene: %zu triangles, compressed %zu bytes for %zu\n", sc->ntris, lp + lu + li,
               sizeof pos + sizeof uv + (size_t)NT * 6);
        scene_destroy(sc);
    }
    scene_destroy(sa);
    free(a);
    free(c);
    free(u0);
    free(u1);
}

/* ---- errors --------------------------------------------------------------------------- */

static void expect(const char *json, int64_t view, pk_status want, const char *text)
{
    doc d;
    doc_open(&d, json);
    const uint8_t *p;
    size_t size, stride;
    pk_status st = gltf_view(&d.g, view, &p, &size, &stride);
    const char *m = pk_context_error(d.ctx);
    CHECKF(st == want && strstr(m, text) != NULL && strncmp(m, "t.gltf: /bufferViews/", 21) == 0,
           "status %d (want %d), message '%s' (want '%s')", (int)st, (int)want, m, text);
    doc_close(&d);
}

static void test_errors(void)
{
    static bytes b;
    b.n = 0;
    enum { N = 300 };
    static float pos[N * 3];
    for (int i = 0; i < N * 3; i++) pos[i] = rndf();
    size_t len, at = encode(&b, 0, pos, N, 12, &len);
    static uint32_t tri[N];
    for (int i = 0; i < N; i++) tri[i] = (uint32_t)(i * 7 % N);
    size_t ilen, iat = encode(&b, 1, tri, N, 0, &ilen);
    char v[1024], *json;
    const char *ep = "/bufferViews/0/extensions/EXT_meshopt_compression";
    char want[160];
    snprintf(want, sizeof want, "%s: corrupt", ep);
    /* corrupt streams: cut short, a wrong header byte, garbage */
    view_json(v, sizeof v, at, len - 40, 12, N, "ATTRIBUTES", NULL);
    json = document(&b, v, placeholder);
    expect(json, 0, PK_ERR_PARSE, want);
    free(json);
    uint8_t keep = b.d[at];
    b.d[at] ^= 0x5a;
    view_json(v, sizeof v, at, len, 12, N, "ATTRIBUTES", NULL);
    json = document(&b, v, placeholder);
    expect(json, 0, PK_ERR_PARSE, want);
    free(json);
    b.d[at] = keep;
    uint8_t ikeep = b.d[iat];
    b.d[iat] = 0;
    view_json(v, sizeof v, iat, ilen, 4, N, "TRIANGLES", NULL);
    json = document(&b, v, placeholder);
    expect(json, 0, PK_ERR_PARSE, want);
    free(json);
    b.d[iat] = ikeep;
    /* the garbage of every byte value in every position: an error or data, never a crash */
    for (int trial = 0; trial < 200; trial++) {
        static bytes g;
        g.n = 0;
        uint8_t junk[256];
        for (size_t k = 0; k < sizeof junk; k++) junk[k] = (uint8_t)rnd();
        junk[0] = trial % 2 ? 0xa0 : 0xe1; /* the attribute and triangle codecs' header bytes */
        size_t ja = put(&g, junk, 1 + rnd() % 255);
        view_json(v, sizeof v, ja, g.n - ja, trial % 2 ? 12 : 4, trial % 2 ? 64 : 96, trial % 2 ? "ATTRIBUTES" : "TRIANGLES",
                  NULL);
        json = document(&g, v, placeholder);
        doc d;
        doc_open(&d, json);
        const uint8_t *p;
        size_t size, stride;
        pk_status st = gltf_view(&d.g, 0, &p, &size, &stride);
        CHECK(st == PK_OK || st == PK_ERR_PARSE);
        doc_close(&d);
        free(json);
    }
    /* the extension's rules */
    static const struct {
        const char *ext, *text;
    } rules[] = {
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"VERTICES\"", "/mode: 'VERTICES' is not"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"ATTRIBUTES\",\"filter\":\"X\"", "/filter: 'X'"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":299,\"mode\":\"ATTRIBUTES\"", "count 299 times byteStride 12"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":6,\"count\":600,\"mode\":\"ATTRIBUTES\"", "not a multiple of 4"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"INDICES\"", "not 2 or 4"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":4,\"count\":900,\"mode\":\"TRIANGLES\",\"filter\":\"OCTAHEDRAL\"", "must be NONE"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"ATTRIBUTES\",\"filter\":\"QUATERNION\"", "8 required"},
        {"\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"ATTRIBUTES\",\"filter\":\"OCTAHEDRAL\"", "4 or 8 required"},
        {"\"buffer\":0,\"byteLength\":%zu,\"count\":300,\"mode\":\"ATTRIBUTES\"", "byteStride is required"},
        {"\"buffer\":5,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"ATTRIBUTES\"", "/buffer"},
        {"\"buffer\":0,\"byteOffset\":100000,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"ATTRIBUTES\"", "exceeds buffer 0"},
    };
    for (size_t k = 0; k < sizeof rules / sizeof rules[0]; k++) {
        char ext[512];
        snprintf(ext, sizeof ext, rules[k].ext, len);
        snprintf(v, sizeof v, "{\"buffer\":1,\"byteLength\":3600,\"extensions\":{\"EXT_meshopt_compression\":{%s}}}", ext);
        json = document(&b, v, placeholder);
        expect(json, 0, PK_ERR_PARSE, rules[k].text);
        free(json);
    }
    /* a parent byteStride that disagrees; a decoded length no stream of that size can give */
    snprintf(v, sizeof v,
             "{\"buffer\":1,\"byteLength\":3600,\"byteStride\":16,\"extensions\":{\"EXT_meshopt_compression\":{"
             "\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":300,\"mode\":\"ATTRIBUTES\"}}}", len);
    json = document(&b, v, placeholder);
    expect(json, 0, PK_ERR_PARSE, "differs from the buffer view's 16");
    free(json);
    snprintf(v, sizeof v,
             "{\"buffer\":1,\"byteLength\":1200000000,\"extensions\":{\"EXT_meshopt_compression\":{"
             "\"buffer\":0,\"byteLength\":%zu,\"byteStride\":12,\"count\":100000000,\"mode\":\"ATTRIBUTES\"}}}", len);
    json = document(&b, v, placeholder);
    expect(json, 0, PK_ERR_PARSE, "cannot come from");
    free(json);
    /* a view on the placeholder without the extension has no data to read */
    json = document(&b, "{\"buffer\":1,\"byteLength\":16}", placeholder);
    doc d;
    doc_open(&d, json);
    const uint8_t *p;
    size_t size, stride;
    CHECK(gltf_view(&d.g, 0, &p, &size, &stride) == PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(d.ctx), "/buffers/1: no uri") != NULL, "%s", pk_context_error(d.ctx));
    doc_close(&d);
    free(json);
}
#endif

int main(void)
{
#if PK_HAVE_MESHOPT
    test_lossless();
    test_filters();
    test_scene();
    test_errors();
    return test_done("test_gltf_meshopt");
#else
    SKIP("this build has no meshoptimizer (Debian: libmeshoptimizer-dev): EXT_meshopt_compression is not read");
#endif
}

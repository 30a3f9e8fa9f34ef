/*
 * test_gltf_draco.c - KHR_draco_mesh_compression (io/gltf_draco.c and the
 * Draco module, io/gltf_draco.cpp): meshes compressed here with Draco's own
 * encoder (tests/unit/draco_encode.cpp) read back into the same scene as the
 * uncompressed mesh: bit for bit with Draco's sequential connectivity and
 * no quantization; triangle for triangle within the quantization asked for
 * with Edgebreaker (which reorders faces and points); without the module, the
 * uncompressed fallback with one warning, or one error where there is none;
 * corrupt streams and wrong attribute ids give one
 * "file: /json/pointer: what is wrong" error. Skipped when the build has no
 * Draco.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "scene/scene.h"

#include <float.h>
#include <stdint.h>

#if PK_HAVE_DRACO
size_t draco_encode_mesh(const float *pos, const float *nrm, const float *uv, const uint8_t *col, size_t np,
                         const uint32_t *faces, size_t nf, int sequential, int qpos, int qother, int ids[4], uint8_t *out,
                         size_t cap);

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

/* ---- the mesh: a bumpy grid with normals, uvs and colours -------------------------- */

enum { G = 16, NV = G * G, NT = 2 * (G - 1) * (G - 1) };
static float pos[NV * 3], nrm[NV * 3], uv[NV * 2];
static uint8_t col[NV * 4];
static uint32_t faces[NT * 3];
static uint16_t idx16[NT * 3];

static void make_mesh(void)
{
    for (int y = 0; y < G; y++)
        for (int x = 0; x < G; x++) {
            int i = y * G + x;
            float fx = (float)x / (G - 1), fy = (float)y / (G - 1);
            pos[3 * i] = 2 * fx - 1, pos[3 * i + 1] = 2 * fy - 1, pos[3 * i + 2] = 0.2f * sinf(5 * fx) * cosf(3 * fy);
            float nx = -cosf(5 * fx), ny = 0.3f * sinf(3 * fy), nz = 1, l = sqrtf(nx * nx + ny * ny + nz * nz);
            nrm[3 * i] = nx / l, nrm[3 * i + 1] = ny / l, nrm[3 * i + 2] = nz / l;
            uv[2 * i] = fx, uv[2 * i + 1] = 1 - fy;
            for (int c = 0; c < 4; c++) col[4 * i + c] = (uint8_t)((i * (c + 3) * 37) & 255);
        }
    int t = 0;
    for (int y = 0; y + 1 < G; y++)
        for (int x = 0; x + 1 < G; x++) {
            uint32_t a = (uint32_t)(y * G + x), b = a + 1, c = a + G, d = c + 1;
            uint32_t q[6] = {a, b, d, a, d, c};
            for (int k = 0; k < 6; k++) faces[3 * t + k] = q[k], idx16[3 * t + k] = (uint16_t)q[k];
            t += 2;
        }
}

/* The glTF accessors of the mesh (fallback: with buffer views 0..4 over
 * the uncompressed data, else none), its primitive with the Draco extension
 * (draco: false leaves it out), over buffer 0 holding stream then plain. */
static char *document(const uint8_t *stream, size_t slen, const int ids[4], bool fallback, bool draco, const char *ids_json)
{
    static uint8_t buf[1 << 16];
    size_t n = 0;
    memcpy(buf, stream, slen);
    n = (slen + 3) & ~(size_t)3;
    size_t off[5], len[5] = {sizeof pos, sizeof nrm, sizeof uv, sizeof col, sizeof idx16};
    const void *src[5] = {pos, nrm, uv, col, idx16};
    for (int k = 0; k < 5; k++) {
        off[k] = n;
        memcpy(buf + n, src[k], len[k]);
        n = (n + len[k] + 3) & ~(size_t)3;
    }
    char *uri = b64(buf, n);
    char views[1024], bv[5][32], ext[512], idsj[256];
    snprintf(views, sizeof views,
             "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}",
             slen, off[0], len[0], off[1], len[1], off[2], len[2], off[3], len[3], off[4], len[4]);
    for (int k = 0; k < 5; k++) {
        bv[k][0] = '\0';
        if (fallback) snprintf(bv[k], sizeof bv[k], "\"bufferView\":%d,", k + 1);
    }
    snprintf(idsj, sizeof idsj, "{\"POSITION\":%d,\"NORMAL\":%d,\"TEXCOORD_0\":%d,\"COLOR_0\":%d}", ids[0], ids[1],
             ids[2], ids[3]);
    snprintf(ext, sizeof ext, ",\"extensions\":{\"KHR_draco_mesh_compression\":{\"bufferView\":0,\"attributes\":%s}}",
             ids_json ? ids_json : idsj);
    size_t jn = strlen(uri) + 4096;
    char *j = malloc(jn);
    snprintf(j, jn,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],\"bufferViews\":[%s],\"accessors\":["
             "{%s\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
             "{%s\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
             "{%s\"componentType\":5126,\"count\":%d,\"type\":\"VEC2\"},"
             "{%s\"componentType\":5121,\"normalized\":true,\"count\":%d,\"type\":\"VEC4\"},"
             "{%s\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2,\"COLOR_0\":3},"
             "\"indices\":4%s}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             n, uri, views, bv[0], NV, bv[1], NV, bv[2], NV, bv[3], NV, bv[4], NT * 3, draco ? ext : "");
    free(uri);
    return j;
}

static char msg[1024];
static warning_log wlog;

static pk_status load(const char *json, const char *config, pk_scene **out)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wlog);
    REQUIRE(pk_context_set_config(ctx, config) == PK_OK);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse(ctx, s, json, strlen(json), "t.gltf", PK_TEST_DATA);
    if (st == PK_OK) st = scene_commit(ctx, s);
    snprintf(msg, sizeof msg, "%s", pk_context_error(ctx));
    if (st != PK_OK || !out) scene_destroy(s);
    else *out = s;
    pk_context_destroy(ctx);
    return st;
}

static const char *const module_config = "draco.module=" PK_DRACO_MODULE;

/* ---- without the module (first: a module slot keeps the first that loads) --------- */

static void test_no_module(const uint8_t *stream, size_t slen, const int ids[4])
{
    char *j = document(stream, slen, ids, true, true, NULL);
    pk_scene *s;
    pk_status st = load(j, "draco.module=/nonexistent/paprsek_draco.so", &s);
    CHECKF(st == PK_OK, "%s", msg);
    if (st == PK_OK) {
        CHECK(s->ntris == NT);
        CHECKF(warning_log_count(&wlog, "KHR_draco_mesh_compression: Draco-compressed data not decoded") == 1,
               "warnings: %s", wlog.all);
        scene_destroy(s);
    }
    free(j);
    j = document(stream, slen, ids, false, true, NULL);
    st = load(j, "draco.module=/nonexistent/paprsek_draco.so", NULL);
    CHECK(st == PK_ERR_UNSUPPORTED);
    CHECKF(strstr(msg, "t.gltf: /meshes/0/primitives/0/extensions/KHR_draco_mesh_compression: a Draco-compressed "
                       "primitive, and the Draco module is not here") == msg,
           "%s", msg);
    free(j);
}

/* ---- lossless: the same scene bit for bit ----------------------------------------- */

static int compare_exact(const pk_scene *a, const pk_scene *b)
{
    int diff = 0;
    if (a->ntris != b->ntris) return -1;
    for (size_t k = 0; k < a->ntris; k++)
        for (int j = 0; j < 3; j++) {
            const triangle *ta = &a->tris[k], *tb = &b->tris[k];
            diff += memcmp(&a->positions[ta->v[j]], &b->positions[tb->v[j]], sizeof(vec3)) != 0;
            diff += (ta->n[j] < 0) != (tb->n[j] < 0) || (ta->t[j] < 0) != (tb->t[j] < 0);
            if (ta->n[j] >= 0 && tb->n[j] >= 0)
                diff += memcmp(&a->normals[ta->n[j]], &b->normals[tb->n[j]], sizeof(vec3)) != 0;
            if (ta->t[j] >= 0 && tb->t[j] >= 0) diff += memcmp(&a->uvs[ta->t[j]], &b->uvs[tb->t[j]], sizeof(uv2)) != 0;
        }
    return diff;
}

static void test_lossless(const uint8_t *stream, size_t slen, const int ids[4])
{
    char *plain = document(stream, slen, ids, true, false, NULL);
    char *packed = document(stream, slen, ids, false, true, NULL);
    pk_scene *a, *b;
    REQUIRE(load(plain, module_config, &a) == PK_OK);
    pk_status st = load(packed, module_config, &b);
    CHECKF(st == PK_OK, "%s", msg);
    if (st == PK_OK) {
        CHECK(a->ntris == NT && b->ntris == NT);
        int d = compare_exact(a, b);
        CHECKF(d == 0, "%d vertex values differ between the Draco mesh and the plain one", d);
        printf("sequential, unquantized: %d triangles equal; %zu stream bytes for %zu\n", (int)b->ntris, slen,
               sizeof pos + sizeof nrm + sizeof uv + sizeof col + sizeof idx16);
        scene_destroy(b);
    }
    /* the same with the extension required */
    const char *at = strstr(packed, "\"extensionsUsed\"");
    REQUIRE(at);
    size_t n = strlen(packed) + 64;
    char *req = malloc(n);
    snprintf(req, n, "%.*s\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],%s", (int)(at - packed), packed, at);
    st = load(req, module_config, &b);
    CHECKF(st == PK_OK, "%s", msg);
    if (st == PK_OK) {
        CHECK(compare_exact(a, b) == 0);
        scene_destroy(b);
    }
    free(req);
    scene_destroy(a);
    free(plain);
    free(packed);
}

/* ---- quantized Edgebreaker: the same triangles within the quantization -------------- */

/* A triangle as its three positions, turned (winding kept) to start at its
 * lexicographically smallest vertex, for sorting. */
typedef struct tri9 {
    float p[9];
} tri9;

static int vless(const float *a, const float *b)
{
    for (int c = 0; c < 3; c++)
        if (a[c] != b[c]) return a[c] < b[c] ? -1 : 1;
    return 0;
}

static tri9 canon(vec3 a, vec3 b, vec3 c, float step)
{
    /* positions snapped to the quantization grid's cells for the ordering */
    float v[3][3] = {{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}}, s[3][3];
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) s[k][j] = roundf(v[k][j] / (4 * step));
    int first = 0;
    for (int k = 1; k < 3; k++)
        if (vless(s[k], s[first]) < 0) first = k;
    tri9 t;
    for (int k = 0; k < 3; k++) memcpy(t.p + 3 * k, v[(first + k) % 3], sizeof v[0]);
    return t;
}

static float sort_step;
static int tri_cmp(const void *x, const void *y)
{
    const tri9 *a = x, *b = y;
    for (int k = 0; k < 9; k++) {
        float sa = roundf(a->p[k] / (4 * sort_step)), sb = roundf(b->p[k] / (4 * sort_step));
        if (sa != sb) return sa < sb ? -1 : 1;
    }
    return 0;
}

static void test_quantized(void)
{
    const int qpos = 14;
    static uint8_t stream[1 << 16];
    int ids[4];
    size_t slen = draco_encode_mesh(pos, nrm, uv, col, NV, faces, NT, 0, qpos, 12, ids, stream, sizeof stream);
    REQUIRE(slen > 0);
    char *packed = document(stream, slen, ids, false, true, NULL);
    pk_scene *b;
    pk_status st = load(packed, module_config, &b);
    CHECKF(st == PK_OK, "%s", msg);
    free(packed);
    if (st != PK_OK) return;
    /* Draco quantizes positions on a grid of 2^q - 1 steps over the largest
     * extent of their box (here 2): each coordinate within half a step, and
     * a few float roundings of the quantizer's and the dequantizer's
     * arithmetic (coordinates at most 1 in magnitude: 4 FLT_EPSILON) */
    const float range = 2.0f, step = range / (float)((1 << qpos) - 1), tol = 0.5f * step + 4 * FLT_EPSILON;
    CHECK(b->ntris == NT);
    static tri9 want[NT], got[NT];
    for (int t = 0; t < NT; t++) {
        vec3 v[3];
        for (int k = 0; k < 3; k++) v[k] = v3(pos[3 * faces[3 * t + k]], pos[3 * faces[3 * t + k] + 1], pos[3 * faces[3 * t + k] + 2]);
        want[t] = canon(v[0], v[1], v[2], step);
    }
    for (size_t t = 0; t < b->ntris && t < NT; t++)
        got[t] = canon(b->positions[b->tris[t].v[0]], b->positions[b->tris[t].v[1]], b->positions[b->tris[t].v[2]], step);
    sort_step = step;
    qsort(want, NT, sizeof *want, tri_cmp);
    qsort(got, NT, sizeof *got, tri_cmp);
    float worst = 0;
    for (int t = 0; t < NT; t++)
        for (int k = 0; k < 9; k++) worst = fmaxf(worst, fabsf(want[t].p[k] - got[t].p[k]));
    CHECKF(worst <= tol, "a position %g from its original (half a step: %g)", (double)worst, (double)tol);
    printf("Edgebreaker, positions at %d bits: largest error %.3g (half a step %.3g); %zu stream bytes\n", qpos,
           (double)worst, (double)(0.5f * step), slen);
    scene_destroy(b);
}

/* ---- errors -------------------------------------------------------------------------- */

static uint32_t rng = 99;
static uint32_t rnd(void) { return rng = rng * 1664525u + 1013904223u, rng >> 8; }

static void test_errors(const uint8_t *stream, size_t slen, const int ids[4])
{
    static uint8_t bad[1 << 16];
    const char *ep = "t.gltf: /meshes/0/primitives/0/extensions/KHR_draco_mesh_compression: ";
    /* cut short, and its header spoilt */
    char *j = document(stream, slen / 2, ids, false, true, NULL);
    CHECK(load(j, module_config, NULL) == PK_ERR_PARSE);
    CHECKF(strncmp(msg, ep, strlen(ep)) == 0 && strstr(msg, "Draco stream"), "%s", msg);
    free(j);
    memcpy(bad, stream, slen);
    bad[0] ^= 0xff;
    j = document(bad, slen, ids, false, true, NULL);
    CHECK(load(j, module_config, NULL) == PK_ERR_PARSE);
    CHECKF(strncmp(msg, ep, strlen(ep)) == 0 && strstr(msg, "not a Draco stream"), "%s", msg);
    free(j);
    /* bytes changed past the header: an error or a mesh, never a crash */
    int errors = 0;
    for (int trial = 0; trial < 150; trial++) {
        memcpy(bad, stream, slen);
        int nflip = 1 + (int)(rnd() % 4);
        for (int f = 0; f < nflip; f++) bad[8 + rnd() % (slen - 8)] = (uint8_t)rnd();
        size_t n = trial % 3 == 0 ? 8 + rnd() % (slen - 8) : slen;
        j = document(bad, n, ids, false, true, NULL);
        pk_status st = load(j, module_config, NULL);
        CHECKF(st == PK_OK || (st == PK_ERR_PARSE && strncmp(msg, ep, strlen(ep)) == 0) || st == PK_ERR_LIMIT,
               "status %d: %s", (int)st, msg);
        errors += st != PK_OK;
        free(j);
    }
    printf("150 damaged streams: %d refused with one error, the others decoded\n", errors);
    /* an id the stream lacks; a name the primitive lacks */
    j = document(stream, slen, ids, false, true, "{\"POSITION\":77}");
    CHECK(load(j, module_config, NULL) == PK_ERR_PARSE);
    CHECKF(strncmp(msg, ep, strlen(ep)) == 0 && strstr(msg, "no attribute of id 77"), "%s", msg);
    free(j);
    char m[128];
    snprintf(m, sizeof m, "{\"POSITION\":%d,\"TEXCOORD_3\":%d}", ids[0], ids[2]);
    j = document(stream, slen, ids, false, true, m);
    CHECK(load(j, module_config, NULL) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "/attributes/TEXCOORD_3: the primitive has no attribute TEXCOORD_3"), "%s", msg);
    free(j);
    /* an attribute whose accessor's type disagrees with the stream's: NORMAL as TEXCOORD_0 */
    snprintf(m, sizeof m, "{\"POSITION\":%d,\"TEXCOORD_0\":%d}", ids[0], ids[1]);
    j = document(stream, slen, ids, false, true, m);
    CHECK(load(j, module_config, NULL) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "has 3 components, its accessor 2"), "%s", msg);
    free(j);
}
#endif

int main(void)
{
#if PK_HAVE_DRACO
    make_mesh();
    static uint8_t stream[1 << 16];
    int ids[4];
    size_t slen = draco_encode_mesh(pos, nrm, uv, col, NV, faces, NT, 1, 0, 0, ids, stream, sizeof stream);
    REQUIRE(slen > 0);
    test_no_module(stream, slen, ids);
    test_lossless(stream, slen, ids);
    test_quantized();
    test_errors(stream, slen, ids);
    return test_done("test_gltf_draco");
#else
    SKIP("this build has no Draco (Debian: libdraco-dev): KHR_draco_mesh_compression is not read");
#endif
}

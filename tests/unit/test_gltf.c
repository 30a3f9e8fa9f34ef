/*
 * test_gltf.c - the glTF 2.0 reader (io/scene_gltf.c, gltf_data.c,
 * gltf_material.c) on assets written here, buffers as base64 data: URIs:
 * every component type (plain and normalized), strides, sparse accessors,
 * index types, strips and fans, node transforms (matrix and T R S give the
 * same triangles), instanced meshes, cameras, KHR_lights_punctual in
 * glTF's photometric units, materials, GLB containers, the strict base64
 * decoder, and the messages hostile assets get (with their JSON pointers).
 */
#include "test.h"
#include "warnings.h"

#include "io/gltf.h"
#include "io/readers.h"
#include "scene/scene.h"

#include <stdint.h>

/* ---- assets built in memory ---------------------------------------------------- */

typedef struct bytes {
    uint8_t d[8192];
    size_t n;
} bytes;

static size_t put(bytes *b, const void *p, size_t n)
{
    REQUIRE(b->n + n <= sizeof b->d);
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

static char msg[1024];
static warning_log wlog;

/* Parses and commits text (JSON or GLB); *out the scene or NULL. */
static pk_status load_params(const char *data, size_t size, pk_scene **out, const char *const *params, size_t np)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wlog);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse_params(ctx, s, data, size, "t.gltf", PK_TEST_DATA, params, np);
    if (st == PK_OK) st = scene_commit(ctx, s);
    snprintf(msg, sizeof msg, "%s", pk_context_error(ctx));
    if (st == PK_OK) {
        char why[256];
        CHECKF(scene_check(s, why, sizeof why), "%s", why);
    }
    if (st != PK_OK || !out) scene_destroy(s);
    else *out = s;
    pk_context_destroy(ctx);
    return st;
}

static pk_status load(const char *json, pk_scene **out) { return load_params(json, strlen(json), out, NULL, 0); }

static bool vnear(vec3 a, vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

/* A document of one mesh (one primitive: attributes and extra primitive
 * keys) over one buffer, with the given accessors and views, placed by
 * one node (node_extra: its transform keys). */
static char *doc(const bytes *b, const char *views, const char *accessors, const char *prim, const char *node_extra,
                 const char *extra)
{
    char *uri = b64(b->d, b->n);
    size_t n = strlen(uri) + strlen(views) + strlen(accessors) + strlen(prim) + strlen(node_extra) + strlen(extra) + 1024;
    char *j = malloc(n);
    snprintf(j, n,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_mesh_quantization\"],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[%s],\"accessors\":[%s],"
             "\"meshes\":[{\"primitives\":[{%s}]}],"
             "\"nodes\":[{\"mesh\":0%s}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0%s}",
             b->n, uri, views, accessors, prim, node_extra, extra);
    free(uri);
    return j;
}

/* ---- base64 ------------------------------------------------------------------------- */

static void test_base64(void)
{
    uint8_t out[16];
    size_t n;
    CHECK(gltf_base64("Zm9v", 4, out, &n) && n == 3 && memcmp(out, "foo", 3) == 0);
    CHECK(gltf_base64("Zm8=", 4, out, &n) && n == 2 && memcmp(out, "fo", 2) == 0);
    CHECK(gltf_base64("Zg==", 4, out, &n) && n == 1 && out[0] == 'f');
    CHECK(gltf_base64("", 0, out, &n) && n == 0);
    CHECK(gltf_base64("+/+/", 4, out, &n) && n == 3 && out[0] == 0xfb && out[1] == 0xff && out[2] == 0xbf);
    static const char *const bad[] = {"Zg=", "Z===", "Zm9v=", "Zh==", "Zm9=", "Zm 9", "Zm9v\n", "Z=g=", "=Zg=", "Zm-v",
                                      "Zm_v", "Zg==Zm9v"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECKF(!gltf_base64(bad[i], strlen(bad[i]), out, &n), "'%s' accepted", bad[i]);
}

/* ---- accessors ----------------------------------------------------------------------- */

static const float tri_pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

/* The one triangle of a scene, vertex k. */
static vec3 vert(const pk_scene *s, size_t t, int k) { return s->positions[s->tris[t].v[k]]; }

static void check_unit_triangle(const pk_scene *s, float scale, const char *what)
{
    REQUIRE(s->ntris == 1);
    for (int k = 0; k < 3; k++) {
        vec3 want = v3(tri_pos[3 * k] * scale, tri_pos[3 * k + 1] * scale, tri_pos[3 * k + 2] * scale);
        CHECKF(vnear(vert(s, 0, k), want, 1e-6f), "%s: vertex %d (%g %g %g)", what, k, (double)vert(s, 0, k).x,
               (double)vert(s, 0, k).y, (double)vert(s, 0, k).z);
    }
}

static void test_component_types(void)
{
    /* the unit triangle in every component type; normalized ones reach 1 at
     * their maximum (BYTE 127, SHORT 32767: and -128 / -32768 clamp to -1) */
    struct {
        int ctype;
        bool normalized;
        float scale; /* what a stored 1 (or the maximum) reads as */
    } cases[] = {{5126, false, 1}, {5120, false, 1}, {5121, false, 1}, {5122, false, 1}, {5123, false, 1},
                 {5125, false, 1}, {5120, true, 1},  {5121, true, 1},  {5122, true, 1},  {5123, true, 1}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        bytes b = {0};
        uint8_t raw[64];
        size_t cs = cases[c].ctype == 5126 || cases[c].ctype == 5125 ? 4 : cases[c].ctype >= 5122 ? 2 : 1;
        for (int i = 0; i < 9; i++) {
            double v = tri_pos[i];
            if (cases[c].normalized)
                v *= cases[c].ctype == 5120 ? 127 : cases[c].ctype == 5121 ? 255 : cases[c].ctype == 5122 ? 32767 : 65535;
            if (cases[c].ctype == 5126) {
                float f = (float)v;
                memcpy(raw + 4 * i, &f, 4);
            } else {
                uint32_t u = (uint32_t)(int32_t)v;
                memcpy(raw + cs * (size_t)i, &u, cs); /* little-endian */
            }
        }
        /* each vertex padded to 4 bytes for the 1- and 2-byte types (VEC3 of bytes: stride 4) */
        size_t stride = cs == 4 ? 12 : cs == 2 ? 8 : 4;
        uint8_t strided[64] = {0};
        for (int v = 0; v < 3; v++) memcpy(strided + stride * (size_t)v, raw + 3 * cs * (size_t)v, 3 * cs);
        put(&b, strided, stride * 3);
        char views[128], acc[256];
        snprintf(views, sizeof views, "{\"buffer\":0,\"byteLength\":%zu,\"byteStride\":%zu}", stride * 3, stride);
        snprintf(acc, sizeof acc, "{\"bufferView\":0,\"componentType\":%d,\"normalized\":%s,\"count\":3,\"type\":\"VEC3\"}",
                 cases[c].ctype, cases[c].normalized ? "true" : "false");
        char *j = doc(&b, views, acc, "\"attributes\":{\"POSITION\":0}", "", "");
        pk_scene *s = NULL;
        pk_status st = load(j, &s);
        CHECKF(st == PK_OK, "type %d: %s", cases[c].ctype, msg);
        if (s) {
            char what[32];
            snprintf(what, sizeof what, "type %d%s", cases[c].ctype, cases[c].normalized ? " normalized" : "");
            check_unit_triangle(s, cases[c].scale, what);
            scene_destroy(s);
        }
        free(j);
    }
    /* the clamp of the most negative normalized values */
    bytes b = {0};
    int8_t sb[12] = {-128, -127, 0, 0, 127, 0, 0, 0, 0, 127, 0, 0};
    put(&b, sb, sizeof sb);
    char *j = doc(&b, "{\"buffer\":0,\"byteLength\":12,\"byteStride\":4}",
                  "{\"bufferView\":0,\"componentType\":5120,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"}",
                  "\"attributes\":{\"POSITION\":0}", "", "");
    pk_scene *s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        CHECK(vert(s, 0, 0).x == -1.0f && vert(s, 0, 0).y == -1.0f);
        scene_destroy(s);
    }
    free(j);
}

static void test_stride_and_sparse(void)
{
    /* positions interleaved with normals (stride 24), from an offset in the view */
    bytes b = {0};
    float inter[2 + 18];
    inter[0] = inter[1] = 99.0f; /* 8 bytes before the first vertex */
    for (int v = 0; v < 3; v++) {
        for (int k = 0; k < 3; k++) inter[2 + 6 * v + k] = tri_pos[3 * v + k];
        inter[2 + 6 * v + 3] = 0, inter[2 + 6 * v + 4] = 0, inter[2 + 6 * v + 5] = 1;
    }
    put(&b, inter, sizeof inter);
    char *j = doc(&b, "{\"buffer\":0,\"byteLength\":80,\"byteStride\":24}",
                  "{\"bufferView\":0,\"byteOffset\":8,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
                  "{\"bufferView\":0,\"byteOffset\":20,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}",
                  "\"attributes\":{\"POSITION\":0,\"NORMAL\":1}", "", "");
    pk_scene *s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        check_unit_triangle(s, 1, "interleaved");
        CHECK(s->nnormals == 3 && s->tris[0].n[0] >= 0 && vnear(s->normals[s->tris[0].n[0]], v3(0, 0, 1), 0));
        scene_destroy(s);
    }
    free(j);

    /* sparse: a base of zeros (no bufferView) with vertices 1 and 2 substituted,
     * indices as unsigned shorts */
    bytes c = {0};
    uint16_t idx[2] = {1, 2};
    float val[6] = {1, 0, 0, 0, 1, 0};
    put(&c, idx, sizeof idx);
    put(&c, val, sizeof val);
    j = doc(&c, "{\"buffer\":0,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":4,\"byteLength\":24}",
            "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":2,"
            "\"indices\":{\"bufferView\":0,\"componentType\":5123},\"values\":{\"bufferView\":1}}}",
            "\"attributes\":{\"POSITION\":0}", "", "");
    s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        check_unit_triangle(s, 1, "sparse on zeros");
        scene_destroy(s);
    }
    free(j);

    /* sparse over a buffer view: vertex 2 of a wrong triangle replaced (byte indices) */
    bytes d = {0};
    float base[9] = {0, 0, 0, 1, 0, 0, 5, 5, 5};
    uint8_t i8[1] = {2};
    float v2[3] = {0, 1, 0};
    put(&d, base, sizeof base);
    put(&d, i8, 1);
    put(&d, v2, sizeof v2);
    j = doc(&d, "{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":1},"
                "{\"buffer\":0,\"byteOffset\":40,\"byteLength\":12}",
            "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":1,"
            "\"indices\":{\"bufferView\":1,\"componentType\":5121},\"values\":{\"bufferView\":2}}}",
            "\"attributes\":{\"POSITION\":0}", "", "");
    s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        check_unit_triangle(s, 1, "sparse on a view");
        scene_destroy(s);
    }
    free(j);
}

/* ---- primitives --------------------------------------------------------------------- */

/* A strip and a fan of 5 vertices each (indices of each component type). */
static void test_modes_and_indices(void)
{
    /* the strip's vertices (0..4) and the fan's (5..9, in turn about 5) */
    const float pos[30] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0,
                           0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0};
    const int itypes[3] = {5121, 5123, 5125};
    for (int it = 0; it < 3; it++) {
        for (int mode = 4; mode <= 6; mode++) {
            bytes b = {0};
            put(&b, pos, sizeof pos);
            uint8_t ib[20] = {0};
            size_t is = itypes[it] == 5121 ? 1 : itypes[it] == 5123 ? 2 : 4;
            for (uint32_t k = 0; k < 5; k++) {
                uint32_t v = mode == 6 ? 5 + k : k;
                memcpy(ib + is * k, &v, is);
            }
            put(&b, ib, 5 * is);
            char views[160], acc[300], prim[96];
            snprintf(views, sizeof views,
                     "{\"buffer\":0,\"byteLength\":120},{\"buffer\":0,\"byteOffset\":120,\"byteLength\":%zu}", 5 * is);
            snprintf(acc, sizeof acc,
                     "{\"bufferView\":0,\"componentType\":5126,\"count\":10,\"type\":\"VEC3\"},"
                     "{\"bufferView\":1,\"componentType\":%d,\"count\":%d,\"type\":\"SCALAR\"}",
                     itypes[it], mode == 4 ? 3 : 5);
            snprintf(prim, sizeof prim, "\"attributes\":{\"POSITION\":0},\"indices\":1,\"mode\":%d", mode);
            char *j = doc(&b, views, acc, prim, "", "");
            pk_scene *s = NULL;
            CHECKF(load(j, &s) == PK_OK, "mode %d: %s", mode, msg);
            if (s) {
                if (mode == 4) {
                    CHECK(s->ntris == 1);
                } else {
                    REQUIRE(s->ntris == 3);
                    /* every triangle wound counter-clockwise seen from +z, as the first */
                    for (size_t t = 0; t < 3; t++) {
                        vec3 n = v3_cross(v3_sub(vert(s, t, 1), vert(s, t, 0)), v3_sub(vert(s, t, 2), vert(s, t, 0)));
                        CHECKF(n.z > 0.0f, "mode %d triangle %zu winds %g", mode, t, (double)n.z);
                    }
                    if (mode == 5) { /* strip: (0 1 2) (1 3 2) (2 3 4) */
                        CHECK(vnear(vert(s, 1, 0), v3(1, 0, 0), 0) && vnear(vert(s, 1, 1), v3(1, 1, 0), 0) &&
                              vnear(vert(s, 1, 2), v3(0, 1, 0), 0));
                    } else { /* fan: (6 7 5) (7 8 5) (8 9 5) */
                        CHECK(vnear(vert(s, 1, 0), v3(1, 1, 0), 0) && vnear(vert(s, 1, 1), v3(0, 1, 0), 0) &&
                              vnear(vert(s, 1, 2), v3(0, 0, 0), 0));
                    }
                }
                scene_destroy(s);
            }
            free(j);
        }
    }
    /* points and lines: skipped with a warning (the scene is then empty) */
    bytes b = {0};
    put(&b, tri_pos, sizeof tri_pos);
    char *j = doc(&b, "{\"buffer\":0,\"byteLength\":36}",
                  "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}",
                  "\"attributes\":{\"POSITION\":0},\"mode\":1", "", "");
    CHECK(load(j, NULL) == PK_ERR_EMPTY_SCENE);
    CHECK(warning_log_has(&wlog, "points and lines are not drawn"));
    free(j);
}

/* ---- nodes ------------------------------------------------------------------------- */

static void test_transforms(void)
{
    bytes b = {0};
    put(&b, tri_pos, sizeof tri_pos);
    const char *views = "{\"buffer\":0,\"byteLength\":36}";
    const char *acc = "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}";
    const char *prim = "\"attributes\":{\"POSITION\":0}";
    /* T R S: scale (2 3 4), half a turn about z, then translate (10 20 30);
     * the same written as a column-major matrix */
    char *trs = doc(&b, views, acc, prim,
                    ",\"translation\":[10,20,30],\"rotation\":[0,0,1,0],\"scale\":[2,3,4]", "");
    char *mat = doc(&b, views, acc, prim, ",\"matrix\":[-2,0,0,0, 0,-3,0,0, 0,0,4,0, 10,20,30,1]", "");
    pk_scene *a = NULL, *c = NULL;
    CHECKF(load(trs, &a) == PK_OK, "%s", msg);
    CHECKF(load(mat, &c) == PK_OK, "%s", msg);
    if (a && c) {
        REQUIRE(a->ntris == 1 && c->ntris == 1);
        for (int k = 0; k < 3; k++) CHECK(memcmp(&a->positions[a->tris[0].v[k]], &c->positions[c->tris[0].v[k]], sizeof(vec3)) == 0);
        CHECK(vnear(vert(a, 0, 1), v3(8, 20, 30), 0)); /* (1,0,0) -> (2,0,0) -> (-2,0,0) -> (8,20,30) */
        CHECK(vnear(vert(a, 0, 2), v3(10, 17, 30), 0));
    }
    scene_destroy(a);
    scene_destroy(c);
    free(trs);
    free(mat);

    /* a parent's transform applies after the child's: child translate x 1, parent scale 2 */
    char *uri = b64(b.d, b.n), j[2048];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
             "\"bufferViews\":[%s],\"accessors\":[%s],\"meshes\":[{\"primitives\":[{%s}]}],"
             "\"nodes\":[{\"scale\":[2,2,2],\"children\":[1,2]},{\"mesh\":0,\"translation\":[1,0,0]},"
             "{\"mesh\":0,\"translation\":[0,5,0]}],\"scenes\":[{\"nodes\":[0]}]}",
             uri, views, acc, prim);
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    CHECKF(scene_gltf_parse(ctx, s, j, strlen(j), "t.gltf", ".") == PK_OK, "%s", pk_context_error(ctx));
    /* a mesh placed by two nodes is one mesh and two instances */
    CHECK(s->nmeshes == 1 && s->ninstances == 2);
    CHECK(scene_commit(ctx, s) == PK_OK);
    REQUIRE(s->ntris == 2);
    CHECK(vnear(vert(s, 0, 0), v3(2, 0, 0), 0) && vnear(vert(s, 0, 1), v3(4, 0, 0), 0));
    CHECK(vnear(vert(s, 1, 0), v3(0, 10, 0), 0) && vnear(vert(s, 1, 2), v3(0, 12, 0), 0));
    scene_destroy(s);
    /* a mesh placed once is no object */
    char *one = doc(&b, views, acc, prim, "", "");
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    CHECK(scene_gltf_parse(ctx, s, one, strlen(one), "t.gltf", ".") == PK_OK);
    CHECK(s->nmeshes == 0 && s->ninstances == 0 && s->ntris == 1);
    scene_destroy(s);
    pk_context_destroy(ctx);
    free(one);
    free(uri);
}

/* ---- cameras and lights --------------------------------------------------------------- */

static void test_cameras(void)
{
    bytes b = {0};
    put(&b, tri_pos, sizeof tri_pos);
    const char *views = "{\"buffer\":0,\"byteLength\":36}";
    const char *acc = "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}";
    char *uri = b64(b.d, b.n), j[4096];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
             "\"bufferViews\":[%s],\"accessors\":[%s],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"aspectRatio\":2,\"znear\":0.1}},"
             "{\"type\":\"orthographic\",\"orthographic\":{\"xmag\":2,\"ymag\":1,\"znear\":0.1,\"zfar\":100}}],"
             "\"nodes\":[{\"mesh\":0},{\"camera\":1,\"translation\":[0,0,9]},{\"camera\":0,\"translation\":[0,0,5],"
             "\"rotation\":[0,0.70710678,0,0.70710678]}],\"scenes\":[{\"nodes\":[0,1,2]}]}",
             uri, views, acc);
    free(uri);
    /* the first camera in node order: /cameras/1, orthographic */
    pk_scene *s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        CHECK(s->has_camera && s->camera.projection == PK_PROJECTION_ORTHOGRAPHIC);
        CHECK_NEAR(s->camera.ortho_width, 4.0, 0);
        CHECK(s->render.has_width && s->render.opt.width == 512 && s->render.opt.height == 256);
        CHECK_NEAR(s->camera.look_from[2], 9.0, 0);
        CHECK_NEAR(s->camera.look_at[2], 8.0, 1e-6);
        scene_destroy(s);
    }
    /* camera=0 picks the perspective one: yfov in degrees, looking along -x
     * (the node turns -z a quarter about +y) */
    const char *p0[] = {"camera=0"};
    s = NULL;
    CHECKF(load_params(j, strlen(j), &s, p0, 1) == PK_OK, "%s", msg);
    if (s) {
        CHECK(s->camera.projection == PK_PROJECTION_PERSPECTIVE);
        CHECK_NEAR(s->camera.fov_deg, 0.5 * 180.0 / 3.14159265358979, 1e-4);
        CHECK_NEAR(s->camera.look_at[0] - s->camera.look_from[0], -1.0, 1e-6);
        CHECK_NEAR(s->camera.look_from[2], 5.0, 1e-6);
        CHECK_NEAR(s->camera.up[1], 1.0, 1e-6);
        CHECK(s->render.opt.width == 512 && s->render.opt.height == 256);
        scene_destroy(s);
    }
    const char *p5[] = {"camera=5"};
    CHECK(load_params(j, strlen(j), NULL, p5, 1) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strcmp(msg, "t.gltf: camera 5: the asset has 2 cameras") == 0, "%s", msg);
    const char *px[] = {"camera=x"};
    CHECK(load_params(j, strlen(j), NULL, px, 1) == PK_ERR_INVALID_ARGUMENT);
}

static void test_lights(void)
{
    bytes b = {0};
    put(&b, tri_pos, sizeof tri_pos);
    char *uri = b64(b.d, b.n), j[4096];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
             "{\"type\":\"point\",\"color\":[1,0.5,0.25],\"intensity\":683},"
             "{\"type\":\"spot\",\"intensity\":1366,\"spot\":{\"innerConeAngle\":0.25,\"outerConeAngle\":0.5}},"
             "{\"type\":\"directional\",\"intensity\":6.83}]}},"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"nodes\":[{\"mesh\":0},{\"translation\":[1,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
             "{\"translation\":[0,4,0],\"rotation\":[-0.70710678,0,0,0.70710678],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
             "{\"rotation\":[-0.70710678,0,0,0.70710678],\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}],"
             "\"scenes\":[{\"nodes\":[0,1,2,3]}]}",
             uri);
    free(uri);
    pk_scene *s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (s) {
        REQUIRE(s->nlights == 3);
        const point_light *p = &s->lights[0], *sp = &s->lights[1], *d = &s->lights[2];
        /* candela / 683 = W/sr */
        CHECK(vnear(p->position, v3(1, 2, 3), 0) && vnear(p->intensity, v3(1, 0.5f, 0.25f), 1e-6f) && !p->distant);
        CHECK(v3_len2(p->spot_dir) == 0.0f);
        /* the spot at (0,4,0) turned to shine down -y */
        CHECK(vnear(sp->position, v3(0, 4, 0), 1e-6f) && vnear(sp->spot_dir, v3(0, -1, 0), 1e-6f));
        CHECK_NEAR(sp->cos_inner, cos(0.25), 1e-6);
        CHECK_NEAR(sp->cos_outer, cos(0.5), 1e-6);
        CHECK(sp->spot_falloff == SPOT_FALLOFF_SQUARED); /* the specification's recommended falloff */
        CHECK(vnear(sp->intensity, v3s(2.0f), 1e-6f));
        /* directional: lux / 683 = W/m^2, position = the direction toward the light (+y) */
        CHECK(d->distant && vnear(d->position, v3(0, 1, 0), 1e-6f) && vnear(d->intensity, v3s(0.01f), 1e-7f));
        scene_destroy(s);
    }
}

/* ---- materials ------------------------------------------------------------------------ */

static void test_materials(void)
{
    bytes b = {0};
    float pu[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* uv */ 0, 0, 1, 0, 1, 1};
    put(&b, pu, sizeof pu);
    char *uri = b64(b.d, b.n), j[4096];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":60,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
             "\"images\":[{\"uri\":\"tex_holes.png\"},{\"uri\":\"tex_rgbw.png\"}],\"textures\":[{\"source\":0},{\"source\":1,\"sampler\":0}],"
             "\"samplers\":[{\"wrapS\":33071,\"wrapT\":10497}],"
             "\"materials\":["
             "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,1],\"metallicFactor\":0.25,\"roughnessFactor\":0.5},"
             "\"emissiveFactor\":[1,2,3],\"doubleSided\":true,"
             "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":2},"
             "\"KHR_materials_transmission\":{\"transmissionFactor\":0.75},\"KHR_materials_ior\":{\"ior\":1.33},"
             "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1,\"clearcoatRoughnessFactor\":0.5},"
             "\"KHR_materials_dispersion\":{}}},"
             "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},\"baseColorFactor\":[1,1,1,0.5]},"
             "\"emissiveFactor\":[1,0.5,1],\"emissiveTexture\":{\"index\":1},"
             "\"alphaMode\":\"MASK\",\"alphaCutoff\":0.25},"
             "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.3],"
             "\"baseColorTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.5,0.25],"
             "\"scale\":[2,3]}}},\"metallicRoughnessTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":"
             "{\"offset\":[0.5,0.25],\"scale\":[2,3]}}}},"
             "\"alphaMode\":\"BLEND\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0},"
             "{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1},"
             "{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":2}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             uri);
    free(uri);
    pk_scene *s = NULL;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    if (!s) return;
    REQUIRE(s->ntris == 3);
    const material *m0 = &s->materials[s->tris[0].material], *m1 = &s->materials[s->tris[1].material],
                   *m2 = &s->materials[s->tris[2].material];
    CHECK(m0->type == MAT_METALLIC_ROUGHNESS && vnear(m0->kd, v3(0.5f, 0.25f, 1), 0));
    CHECK(m0->metallic == 0.25f && m0->roughness == 0.5f && m0->transmission == 0.75f && m0->ni == 1.33f);
    CHECK(vnear(m0->ke, v3(2, 4, 6), 0) && m0->two_sided && m0->map_kd.kind == TEX_NONE);
    CHECK(m0->clearcoat == 1.0f && m0->clearcoat_roughness == 0.5f);
    CHECK(warning_log_has(&wlog, "KHR_materials_dispersion: drawn without dispersion"));
    /* MASK: a cut-out of alpha * 0.5 >= 0.25 (tex_holes: alpha 0 or 1) */
    CHECK(m1->map_kd.kind == TEX_IMAGE && m1->map_d.kind == TEX_IMAGE && m1->map_d.tex != m1->map_kd.tex);
    CHECK(m1->d == 1.0f && !m1->two_sided);
    /* an emission map: the factor times the texture, decoded from sRGB (the image m2's base colour uses) */
    CHECK(vnear(m1->ke, v3(1, 0.5f, 1), 0) && m1->map_ke.kind == TEX_IMAGE && m1->map_ke.tex == m2->map_kd.tex);
    /* BLEND: the constant alpha as stochastic transparency; one transform for the
     * material's textures: baked into the uvs, the references plain */
    CHECK(m2->blend && m2->blend_alpha == 0.3f && m2->d == 1.0f && m2->map_kd.kind == TEX_IMAGE && m2->map_mr.kind == TEX_IMAGE);
    CHECK(m2->map_kd.clamp == TEX_CLAMP_U); /* the sampler's wrapS clamps, its wrapT repeats */
    CHECK(m2->map_kd.s[0] == 1.0f && m2->map_kd.o[1] == 0.0f);
    CHECK(m2->map_mr.tex != m2->map_kd.tex); /* the same image, decoded as data */
    /* uv (1, 0) in glTF: scaled (2, 0), offset (2.5, 0.25), the scene's v = 1 - 0.25 */
    const uv2 t = s->uvs[s->tris[2].t[1]];
    CHECK_NEAR(t.u, 2.5, 1e-6);
    CHECK_NEAR(t.v, 0.75, 1e-6);
    /* untransformed uvs only flip v */
    const uv2 t0 = s->uvs[s->tris[0].t[2]];
    CHECK_NEAR(t0.u, 1.0, 0);
    CHECK_NEAR(t0.v, 0.0, 0);
    scene_destroy(s);
}

/* Mirrored repeat (an image doubled with its mirror image) and the second uv set. */
static void test_mirror_and_uv1(void)
{
    bytes b = {0};
    float pu[21] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* TEXCOORD_0 */ 0, 0, 0, 0, 0, 0, /* TEXCOORD_1 */ 0.25f, 0, 1, 0, 1, 1};
    put(&b, pu, sizeof pu);
    char *uri = b64(b.d, b.n), j[4096];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":84,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
             "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
             "\"images\":[{\"uri\":\"../tex_rgbw.png\"}],\"textures\":[{\"source\":0,\"sampler\":0}],"
             "\"samplers\":[{\"wrapS\":33648,\"wrapT\":33648}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"TEXCOORD_1\":2},"
             "\"material\":0}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             uri);
    free(uri);
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wlog);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    /* base_dir: tests/data/gltf, so that ../tex_rgbw.png is found */
    CHECKF(scene_gltf_parse(ctx, s, j, strlen(j), "t.gltf", PK_TEST_DATA "/gltf") == PK_OK, "%s", pk_context_error(ctx));
    CHECK(wlog.count == 0);
    REQUIRE(s->ntris == 1);
    /* both sets read, the texture reads the second: TEXCOORD_1's (0.25, 0) -> the scene's (0.25, 1) */
    REQUIRE(s->uvs1);
    CHECK_NEAR(s->uvs[s->tris[0].t[0]].u, 0.0, 0);
    CHECK_NEAR(s->uvs[s->tris[0].t[0]].v, 1.0, 0);
    CHECK_NEAR(s->uvs1[s->tris[0].v[0]].u, 0.25, 0);
    CHECK_NEAR(s->uvs1[s->tris[0].v[0]].v, 1.0, 0);
    const material *m = &s->materials[s->tris[0].material];
    REQUIRE(m->map_kd.kind == TEX_IMAGE && s->ntextures == 2 && m->map_kd.tex == 1 && m->map_kd.uvset == 1);
    const texture *src = &s->textures[0], *mir = &s->textures[1];
    REQUIRE(src->lv[0].w == 2 && mir->lv[0].w == 4 && mir->lv[0].h == 4 && src->nc == mir->nc && src->lv[0].px8);
    /* texel (x, y) of the doubled image is the source's mirrored texel */
    const int nc = src->nc;
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            int sx = x < 2 ? x : 3 - x, sy = y < 2 ? y : 3 - y;
            CHECK(memcmp(mir->lv[0].px8 + (y * 4 + x) * nc, src->lv[0].px8 + (sy * 2 + sx) * nc, (size_t)nc) == 0);
        }
    /* half the frequency; v shifted so that glTF's v = 0 (the top) stays the image's top */
    CHECK(m->map_kd.s[0] == 0.5f && m->map_kd.s[1] == 0.5f && m->map_kd.o[0] == 0.0f && m->map_kd.o[1] == 0.5f);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- GLB ------------------------------------------------------------------------------------ */

static size_t glb(uint8_t *out, const char *json, const bytes *bin, uint32_t lie_total, uint32_t lie_json)
{
    size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, at = 12;
    uint32_t w;
    memcpy(out, "glTF", 4);
    w = 2;
    memcpy(out + 4, &w, 4);
    w = (uint32_t)jp + (lie_json ? lie_json : 0);
    memcpy(out + at, &w, 4);
    w = 0x4E4F534A;
    memcpy(out + at + 4, &w, 4);
    memcpy(out + at + 8, json, jl);
    memset(out + at + 8 + jl, ' ', jp - jl);
    at += 8 + jp;
    if (bin) {
        w = (uint32_t)bin->n;
        memcpy(out + at, &w, 4);
        w = 0x004E4942;
        memcpy(out + at + 4, &w, 4);
        memcpy(out + at + 8, bin->d, bin->n);
        at += 8 + bin->n;
    }
    w = lie_total ? lie_total : (uint32_t)at;
    memcpy(out + 8, &w, 4);
    return at;
}

static void test_glb(void)
{
    bytes b = {0};
    put(&b, tri_pos, sizeof tri_pos);
    const char *json = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36}],"
                       "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                       "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                       "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                       "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";
    static uint8_t buf[8192];
    size_t n = glb(buf, json, &b, 0, 0);
    pk_scene *s = NULL;
    CHECKF(load_params((const char *)buf, n, &s, NULL, 0) == PK_OK, "%s", msg);
    if (s) {
        check_unit_triangle(s, 1, "glb");
        scene_destroy(s);
    }
    n = glb(buf, json, &b, 10000, 0);
    CHECK(load_params((const char *)buf, n, NULL, NULL, 0) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "t.gltf: GLB: the header says 10000 bytes, the file holds") == msg, "%s", msg);
    n = glb(buf, json, &b, 0, 4096);
    CHECK(load_params((const char *)buf, n, NULL, NULL, 0) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "JSON chunk's length") != NULL, "%s", msg);
    /* a BIN chunk shorter than the buffer says */
    bytes shortb = {0};
    put(&shortb, tri_pos, 24);
    n = glb(buf, json, &shortb, 0, 0);
    CHECK(load_params((const char *)buf, n, NULL, NULL, 0) == PK_ERR_PARSE);
    CHECKF(strcmp(msg, "t.gltf: /buffers/0: byteLength 36 exceeds its data (24 bytes)") == 0, "%s", msg);
    /* no BIN chunk at all */
    n = glb(buf, json, NULL, 0, 0);
    CHECK(load_params((const char *)buf, n, NULL, NULL, 0) == PK_ERR_PARSE);
    CHECK(load_params((const char *)buf, 7, NULL, NULL, 0) == PK_ERR_PARSE);
}

/* ---- hostile assets --------------------------------------------------------------------------- */

static void expect_error(const char *json, const char *want)
{
    pk_status st = load(json, NULL);
    CHECKF(st != PK_OK && strcmp(msg, want) == 0, "got '%s', want '%s'", msg, want);
}

static void test_errors(void)
{
    bytes b = {0};
    put(&b, tri_pos, sizeof tri_pos);
    const char *views = "{\"buffer\":0,\"byteLength\":36}";
    const char *prim = "\"attributes\":{\"POSITION\":0}";
    char *j;
    j = doc(&b, views, "{\"bufferView\":0,\"componentType\":5126,\"count\":100,\"type\":\"VEC3\"}", prim, "", "");
    expect_error(j, "t.gltf: /accessors/0: count 100 exceeds bufferView 0 (36 bytes)");
    free(j);
    /* an offset that wraps around: no overflow */
    j = doc(&b, views,
            "{\"bufferView\":0,\"byteOffset\":4294967296000,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}", prim,
            "", "");
    expect_error(j, "t.gltf: /accessors/0: count 1 exceeds bufferView 0 (36 bytes)");
    free(j);
    j = doc(&b, "{\"buffer\":0,\"byteOffset\":24,\"byteLength\":36}",
            "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}", prim, "", "");
    expect_error(j, "t.gltf: /bufferViews/0: byteOffset 24 + byteLength 36 exceeds buffer 0 (36 bytes)");
    free(j);
    j = doc(&b, "{\"buffer\":0,\"byteLength\":36,\"byteStride\":4}",
            "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}", prim, "", "");
    expect_error(j, "t.gltf: /accessors/0: bufferView 0's byteStride 4 is less than an element (12 bytes)");
    free(j);
    /* indices out of range */
    bytes c = {0};
    put(&c, tri_pos, sizeof tri_pos);
    uint16_t bad[3] = {0, 1, 7};
    put(&c, bad, sizeof bad);
    j = doc(&c, "{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}",
            "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
            "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}",
            "\"attributes\":{\"POSITION\":0},\"indices\":1", "", "");
    expect_error(j, "t.gltf: /meshes/0/primitives/0/indices: index 7 out of range (3 vertices)");
    free(j);
    /* a sparse index past the count */
    bytes d = {0};
    uint8_t si[1] = {3};
    float sv[3] = {0, 0, 0};
    put(&d, tri_pos, sizeof tri_pos);
    put(&d, si, 1);
    put(&d, sv, sizeof sv);
    j = doc(&d, "{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":1},"
                "{\"buffer\":0,\"byteOffset\":40,\"byteLength\":12}",
            "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":1,"
            "\"indices\":{\"bufferView\":1,\"componentType\":5121},\"values\":{\"bufferView\":2}}}",
            prim, "", "");
    expect_error(j, "t.gltf: /accessors/0/sparse/indices: index 3 out of range (count 3)");
    free(j);
    /* malformed data: URIs */
    static const char *const uris[][2] = {
        {"data:application/octet-stream;base64,AAA", "t.gltf: /buffers/0/uri: malformed base64 in the data: URI"},
        {"data:application/octet-stream;base64,AA*A", "t.gltf: /buffers/0/uri: malformed base64 in the data: URI"},
        {"data:application/octet-stream,AAAA", "t.gltf: /buffers/0/uri: only base64 data: URIs are read"},
        {"data:;base64", "t.gltf: /buffers/0/uri: malformed data: URI (no ',')"},
        {"http://example.com/x.bin", "t.gltf: /buffers/0/uri: 'http:' URIs are not read (only files and data: URIs)"},
        {"x%2.bin", "t.gltf: /buffers/0/uri: malformed percent escape in the URI"},
    };
    for (size_t i = 0; i < sizeof uris / sizeof uris[0]; i++) {
        char jj[1024];
        snprintf(jj, sizeof jj,
                 "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":3,\"uri\":\"%s\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":3}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],"
                 "\"scenes\":[{\"nodes\":[0]}]}",
                 uris[i][0]);
        expect_error(jj, uris[i][1]);
    }
    /* a missing file names the file */
    CHECK(load("{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":3,\"uri\":\"no%20such.bin\"}],"
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":3}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}]}",
               NULL) != PK_OK);
    CHECKF(strstr(msg, "t.gltf: /buffers/0/uri: ") == msg && strstr(msg, "no such.bin"), "%s", msg);
    /* node graphs: a cycle, two parents, depth */
    const char *head = "{\"asset\":{\"version\":\"2.0\"},";
    char jj[8192];
    snprintf(jj, sizeof jj, "%s\"nodes\":[{\"children\":[1]},{\"children\":[2]},{\"children\":[1]}],\"scenes\":[{\"nodes\":[0]}]}", head);
    expect_error(jj, "t.gltf: /nodes/2/children/0: node 1 is its own ancestor (a cycle)");
    snprintf(jj, sizeof jj, "%s\"nodes\":[{\"children\":[2]},{\"children\":[2]},{}],\"scenes\":[{\"nodes\":[0,1]}]}", head);
    expect_error(jj, "t.gltf: /nodes/1/children/0: node 2 is reached a second time (two parents)");
    snprintf(jj, sizeof jj, "%s\"nodes\":[{\"children\":[0]}],\"scenes\":[{\"nodes\":[0]}]}", head);
    expect_error(jj, "t.gltf: /nodes/0/children/0: node 0 is its own ancestor (a cycle)");
    size_t o = (size_t)snprintf(jj, sizeof jj, "%s\"nodes\":[", head);
    for (int i = 0; i < 300; i++) o += (size_t)snprintf(jj + o, sizeof jj - o, "%s{\"children\":[%d]}", i ? "," : "", i + 1);
    snprintf(jj + o, sizeof jj - o, ",{}],\"scenes\":[{\"nodes\":[0]}]}");
    expect_error(jj, "t.gltf: /nodes/256: nodes nested deeper than 256");
    /* transforms */
    snprintf(jj, sizeof jj, "%s\"nodes\":[{\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,1,0,0,0,1]}]}", head);
    expect_error(jj, "t.gltf: /nodes/0/matrix: not affine (its last row is not 0 0 0 1)");
    snprintf(jj, sizeof jj, "%s\"nodes\":[{\"translation\":[1e39,0,0]}]}", head);
    expect_error(jj, "t.gltf: /nodes/0/translation/0: must be a finite number");
    snprintf(jj, sizeof jj, "%s\"nodes\":[{\"rotation\":[0,0,0,0]}]}", head);
    expect_error(jj, "t.gltf: /nodes/0/rotation: not a unit quaternion");
    /* extensions and versions */
    snprintf(jj, sizeof jj, "%s\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]}", head);
    /* (this test names no Draco module: the build's is not found from here) */
    CHECK(load(jj, NULL) == PK_ERR_UNSUPPORTED);
    CHECKF(strstr(msg, "t.gltf: /extensionsRequired/0: Draco-compressed meshes (KHR_draco_mesh_compression) are not "
                       "read here (") == msg &&
               strstr(msg, "); export the model without Draco compression"),
           "%s", msg);
    snprintf(jj, sizeof jj, "%s\"extensionsRequired\":[\"EXT_unknown\"]}", head);
    expect_error(jj, "t.gltf: /extensionsRequired/0: extension 'EXT_unknown' is required and not supported");
    expect_error("{\"asset\":{\"version\":\"1.0\"}}", "t.gltf: /asset/version: '1.0' is not glTF 2.x");
    expect_error("{}", "t.gltf: /asset: required, and must be an object");
    expect_error("[1]", "t.gltf: the top level must be a JSON object");
    /* a byte-order mark is read past: the asset is valid, and empty */
    CHECK(load("\xEF\xBB\xBF{\"asset\":{\"version\":\"2.0\"}}", NULL) == PK_ERR_EMPTY_SCENE);
    expect_error("{\"asset\":", "t.gltf: JSON syntax error near byte 8");
    /* accessor kinds */
    j = doc(&b, views, "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}", prim, "", "");
    expect_error(j, "t.gltf: /accessors/0: POSITION must have 3 components");
    free(j);
    j = doc(&b, views, "{\"bufferView\":0,\"componentType\":5125,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"}", prim,
            "", "");
    expect_error(j, "t.gltf: /accessors/0: normalized applies to 8- and 16-bit integers only");
    free(j);
    j = doc(&b, views, "{\"bufferView\":0,\"componentType\":5124,\"count\":3,\"type\":\"VEC3\"}", prim, "", "");
    expect_error(j, "t.gltf: /accessors/0: componentType 5124 is not a glTF component type");
    free(j);
    j = doc(&b, views, "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}", prim, "", "");
    expect_error(j, "t.gltf: /accessors/0/bufferView: index 3 out of range (1 there)");
    free(j);
}

int main(void)
{
    test_base64();
    test_component_types();
    test_stride_and_sparse();
    test_modes_and_indices();
    test_transforms();
    test_cameras();
    test_lights();
    test_materials();
    test_mirror_and_uv1();
    test_glb();
    test_errors();
    return test_done("test_gltf");
}

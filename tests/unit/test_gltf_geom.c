/*
 * test_gltf_geom.c - glTF geometry at the file's pose (io/scene_gltf.c):
 * morph targets with the mesh's and the node's default weights, linear
 * blend skinning with the joints' node transforms and inverse bind
 * matrices (a two-joint bend against its closed form),
 * normalTexture.scale, COLOR_0 (stored, flattened with instances, and
 * multiplying the base colour at a hit) and alphaMode BLEND as stochastic
 * transparency (its coverage against the binomial spread, deterministic),
 * and vertex tangents: generated on a plane, a sphere and a cube with
 * mirrored uvs against their closed forms, and the same as given ones;
 * textures reading TEXCOORD_0 and TEXCOORD_1 (tests/data/gltf/uv_sets.gltf).
 * Assets are written here, buffers as base64 data: URIs.
 */
#include "test.h"
#include "warnings.h"

#include "io/gltf.h"
#include "io/readers.h"
#include "render/lights.h"
#include "render/surface.h"
#include "scene/scene.h"
#include "scene/scene_view.h"

#include <stdint.h>

typedef struct bytes {
    uint8_t d[65536];
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

static warning_log wlog;
static char msg[1024];
static const char *load_config; /* a context configuration for load (NULL: none) */

/* Parses and commits json; *out the scene (NULL on failure). */
static pk_status load(const char *json, pk_scene **out)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wlog);
    if (load_config) REQUIRE(pk_context_set_config(ctx, load_config) == PK_OK);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse(ctx, s, json, strlen(json), "t.gltf", PK_TEST_DATA "/gltf");
    if (st == PK_OK) st = scene_commit(ctx, s);
    snprintf(msg, sizeof msg, "%s", pk_context_error(ctx));
    if (st == PK_OK) {
        char why[256];
        CHECKF(scene_check(s, why, sizeof why), "%s", why);
    }
    if (st != PK_OK) {
        scene_destroy(s);
        s = NULL;
    }
    *out = s;
    pk_context_destroy(ctx);
    return st;
}

static bool vnear(vec3 a, vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

static vec3 vpos(const pk_scene *s, size_t t, int k) { return s->positions[s->tris[t].v[k]]; }
static vec3 vnrm(const pk_scene *s, size_t t, int k) { return s->normals[s->tris[t].n[k]]; }

/* ---- morph targets ---------------------------------------------------------------------- */

/* One triangle in z = 0 with normals +z and one target that moves it by
 * (0, 0, 2) and its normals by (1, 0, -1); mesh_extra and nodes: the
 * mesh's and the nodes' keys. */
static char *morph_doc(const char *mesh_extra, const char *nodes, const char *roots)
{
    bytes b = {0};
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float dp[9] = {0, 0, 2, 0, 0, 2, 0, 0, 2}, dn[9] = {1, 0, -1, 1, 0, -1, 1, 0, -1};
    put(&b, pos, sizeof pos);
    put(&b, nrm, sizeof nrm);
    put(&b, dp, sizeof dp);
    put(&b, dn, sizeof dn);
    char *uri = b64(b.d, b.n);
    char *j = malloc(8192);
    snprintf(j, 8192,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},"
             "{\"buffer\":0,\"byteOffset\":72,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":108,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},"
             "\"targets\":[{\"POSITION\":2,\"NORMAL\":3}]}]%s}],"
             "\"nodes\":[%s],\"scenes\":[{\"nodes\":[%s]}]}",
             b.n, uri, mesh_extra, nodes, roots);
    free(uri);
    return j;
}

static void test_morph(void)
{
    pk_scene *s;
    /* the mesh's weight 0.5: half the displacement, the normal halfway */
    char *j = morph_doc(",\"weights\":[0.5]", "{\"mesh\":0}", "0");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1);
    CHECK(wlog.count == 0);
    CHECK(vnear(vpos(s, 0, 0), v3(0, 0, 1), 1e-6f) && vnear(vpos(s, 0, 1), v3(1, 0, 1), 1e-6f) &&
          vnear(vpos(s, 0, 2), v3(0, 1, 1), 1e-6f));
    const float r = sqrtf(0.5f);
    for (int k = 0; k < 3; k++) CHECK(vnear(vnrm(s, 0, k), v3(r, 0, r), 1e-6f));
    scene_destroy(s);

    /* the node's weights override the mesh's */
    j = morph_doc(",\"weights\":[0.5]", "{\"mesh\":0,\"weights\":[1]}", "0");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1);
    CHECK(vnear(vpos(s, 0, 1), v3(1, 0, 2), 1e-6f));
    CHECK(vnear(vnrm(s, 0, 1), v3(1, 0, 0), 1e-6f));
    scene_destroy(s);

    /* no weights: the base shape; two nodes, one with its own weights: each drawn with its own */
    j = morph_doc("", "{\"mesh\":0,\"translation\":[5,0,0]},{\"mesh\":0,\"weights\":[0.25]}", "0,1");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 2);
    CHECK(vnear(vpos(s, 0, 1), v3(6, 0, 0), 1e-6f));
    CHECK(vnear(vpos(s, 1, 1), v3(1, 0, 0.5f), 1e-6f));
    CHECK(wlog.count == 0);
    scene_destroy(s);

    /* a weight that is not a number */
    j = morph_doc(",\"weights\":[\"a\"]", "{\"mesh\":0}", "0");
    CHECK(load(j, &s) == PK_ERR_PARSE && strstr(msg, "/meshes/0/weights/0: must be a finite number"));
    free(j);
}

/* One triangle with TEXCOORD_0 and COLOR_0 (VEC4 floats) and a target
 * that moves the uvs by (0.5, 0.25) and the colours by (-0.5, 0.25, 0)
 * (a VEC3: alpha stays), at weight 0.5. */
static void test_morph_attributes(void)
{
    bytes b = {0};
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, uv[6] = {0, 0, 1, 0, 0, 1};
    const float col[12] = {1, 1, 1, 0.5f, 1, 0, 0, 1, 0, 0, 1, 1};
    const float duv[6] = {0.5f, 0.25f, 0.5f, 0.25f, 0.5f, 0.25f};
    const float dcol[9] = {-0.5f, 0.25f, 0, -0.5f, 0.25f, 0, -0.5f, 0.25f, 0};
    put(&b, pos, sizeof pos);
    put(&b, uv, sizeof uv);
    put(&b, col, sizeof col);
    put(&b, duv, sizeof duv);
    put(&b, dcol, sizeof dcol);
    char *uri = b64(b.d, b.n);
    char *j = malloc(8192);
    snprintf(j, 8192,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
             "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":108,\"byteLength\":24},"
             "{\"buffer\":0,\"byteOffset\":132,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
             "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
             "{\"bufferView\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"COLOR_0\":2},"
             "\"targets\":[{\"TEXCOORD_0\":3,\"COLOR_0\":4}]}],\"weights\":[0.5]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             b.n, uri);
    free(uri);
    pk_scene *s;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1 && s->uvs && s->colors);
    CHECKF(wlog.count == 0, "%s", wlog.last);
    for (int k = 0; k < 3; k++) {
        const uv2 t = s->uvs[s->tris[0].t[k]];
        /* glTF's uv plus half the displacement; the scene's v is 1 - glTF's */
        CHECKF(fabsf(t.u - (uv[2 * k] + 0.25f)) < 1e-6f && fabsf(t.v - (1.0f - (uv[2 * k + 1] + 0.125f))) < 1e-6f,
               "vertex %d: uv (%g, %g)", k, (double)t.u, (double)t.v);
        const rgba c = s->colors[s->tris[0].v[k]];
        CHECKF(fabsf(c.r - (col[4 * k] - 0.25f)) < 1e-6f && fabsf(c.g - (col[4 * k + 1] + 0.125f)) < 1e-6f &&
                   c.b == col[4 * k + 2] && c.a == col[4 * k + 3],
               "vertex %d: colour (%g, %g, %g, %g)", k, (double)c.r, (double)c.g, (double)c.b, (double)c.a);
    }
    scene_destroy(s);
}

/* ---- skins --------------------------------------------------------------------------------- */

/* A two-joint bend: joint 1 (node 1) at the origin, joint 2 (node 2, its
 * child) one unit up, turned by angle_deg about +z; vertices at the
 * origin (joint 1), at (1, 1, 0) (half each) and at (0, 2, 0) (joint 2),
 * normals +x; the inverse bind matrices are those of the straight pose.
 * The skinned node's own translation (100, 0, 0) must not apply. */
/* two_sets: the middle vertex's two joints come from JOINTS_0/WEIGHTS_0
 * and JOINTS_1/WEIGHTS_1, one each. */
static char *skin_doc2(float angle_deg, bool with_ibm, const char *joints_extra, bool two_sets)
{
    bytes b = {0};
    const float pos[9] = {0, 0, 0, 1, 1, 0, 0, 2, 0}, nrm[9] = {1, 0, 0, 1, 0, 0, 1, 0, 0};
    const uint8_t jn[12] = {0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0};
    float wt[12] = {1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0};
    const uint8_t jn1[12] = {0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0};
    const float wt1[12] = {0, 0, 0, 0, 0.5f, 0, 0, 0, 0, 0, 0, 0};
    if (two_sets) wt[5] = 0.0f;
    const float ibm[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, /* identity */
                           1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1 /* translate (0, -1, 0) */};
    put(&b, pos, sizeof pos);
    put(&b, nrm, sizeof nrm);
    put(&b, jn, sizeof jn);
    put(&b, wt, sizeof wt);
    put(&b, ibm, sizeof ibm);
    put(&b, jn1, sizeof jn1);
    put(&b, wt1, sizeof wt1);
    char *uri = b64(b.d, b.n);
    const double h = (double)angle_deg * (3.14159265358979 / 180.0) / 2.0;
    char *j = malloc(8192);
    snprintf(j, 8192,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},"
             "{\"buffer\":0,\"byteOffset\":72,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":84,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":132,\"byteLength\":128},{\"buffer\":0,\"byteOffset\":260,\"byteLength\":12},"
             "{\"buffer\":0,\"byteOffset\":272,\"byteLength\":48}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":5121,\"count\":3,\"type\":\"VEC4\"},"
             "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
             "{\"bufferView\":4,\"componentType\":5126,\"count\":2,\"type\":\"MAT4\"},"
             "{\"bufferView\":5,\"componentType\":5121,\"count\":3,\"type\":\"VEC4\"},"
             "{\"bufferView\":6,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":2,"
             "\"WEIGHTS_0\":3%s}}]}],"
             "\"skins\":[{\"joints\":[1,2]%s%s}],"
             "\"nodes\":[{\"mesh\":0,\"skin\":0,\"translation\":[100,0,0]},{\"children\":[2]},"
             "{\"translation\":[0,1,0],\"rotation\":[0,0,%.17g,%.17g]}],"
             "\"scenes\":[{\"nodes\":[0,1]}]}",
             b.n, uri, two_sets ? ",\"JOINTS_1\":5,\"WEIGHTS_1\":6" : "", with_ibm ? ",\"inverseBindMatrices\":4" : "",
             joints_extra, sin(h), cos(h));
    free(uri);
    return j;
}

static char *skin_doc(float angle_deg, bool with_ibm, const char *joints_extra)
{
    return skin_doc2(angle_deg, with_ibm, joints_extra, false);
}

static void test_skin(void)
{
    pk_scene *s;
    /* bent by 90 degrees: (0, 2, 0) turns about (0, 1, 0) to (-1, 1, 0); the
     * vertex weighted half and half lies halfway between (1, 1, 0) and its
     * turned place (0, 2, 0); its normal turns by half as much */
    char *j = skin_doc(90.0f, true, "");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1);
    CHECKF(wlog.count == 0, "%s", wlog.last);
    CHECK(vnear(vpos(s, 0, 0), v3(0, 0, 0), 1e-5f));
    CHECK(vnear(vpos(s, 0, 1), v3(0.5f, 1.5f, 0), 1e-5f));
    CHECK(vnear(vpos(s, 0, 2), v3(-1, 1, 0), 1e-5f));
    const float r = sqrtf(0.5f);
    CHECK(vnear(vnrm(s, 0, 0), v3(1, 0, 0), 1e-5f));
    CHECK(vnear(vnrm(s, 0, 1), v3(r, r, 0), 1e-5f));
    CHECK(vnear(vnrm(s, 0, 2), v3(0, 1, 0), 1e-5f));
    scene_destroy(s);

    /* the middle vertex's joints split over JOINTS_0 and JOINTS_1: the same pose */
    j = skin_doc2(90.0f, true, "", true);
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1);
    CHECKF(wlog.count == 0, "%s", wlog.last);
    CHECK(vnear(vpos(s, 0, 1), v3(0.5f, 1.5f, 0), 1e-5f) && vnear(vpos(s, 0, 2), v3(-1, 1, 0), 1e-5f));
    CHECK(vnear(vnrm(s, 0, 1), v3(r, r, 0), 1e-5f));
    scene_destroy(s);

    /* the bind pose (no bend) gives the mesh as written, not moved by its node */
    j = skin_doc(0.0f, true, "");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1);
    CHECK(vnear(vpos(s, 0, 1), v3(1, 1, 0), 1e-6f) && vnear(vpos(s, 0, 2), v3(0, 2, 0), 1e-6f));
    scene_destroy(s);

    /* without inverse bind matrices (identity): joint 2's transform applies whole */
    j = skin_doc(0.0f, false, "");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 1);
    CHECK(vnear(vpos(s, 0, 2), v3(0, 3, 0), 1e-6f) && vnear(vpos(s, 0, 1), v3(1, 1.5f, 0), 1e-6f));
    scene_destroy(s);

    /* a joint number past the skin's joints */
    j = skin_doc(0.0f, true, "");
    char *at = strstr(j, "\"joints\":[1,2]");
    REQUIRE(at);
    memcpy(at, "\"joints\":[1,1]", 14);
    CHECK(load(j, &s) == PK_OK); /* the same joint twice is allowed */
    scene_destroy(s);
    free(j);
}

/* ---- normalTexture.scale ------------------------------------------------------------------ */

static void test_normal_scale(void)
{
    bytes b = {0};
    const float pu[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
    put(&b, pu, sizeof pu);
    char *uri = b64(b.d, b.n), j[4096];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":60,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
             "\"images\":[{\"uri\":\"../tex_rgbw.png\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"normalTexture\":{\"index\":0,\"scale\":0.25}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             uri);
    free(uri);
    pk_scene *s;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    REQUIRE(s);
    CHECKF(wlog.count == 0, "%s", wlog.last);
    const material *m = &s->materials[s->tris[0].material];
    CHECK(m->map_norm.kind == TEX_IMAGE && m->norm_scale == 0.25f);
    /* at texel centres: the map's x and y times 0.25 in the frame t = +x (u), b = -y (the image's
     * up: glTF's v runs down +y here), n = +z, then normalised */
    const scene_view v = scene_view_of(s);
    const float centres[3][2] = {{0.25f, 0.75f}, {0.75f, 0.75f}, {0.25f, 0.25f}};
    int checked = 0;
    for (int k = 0; k < 3; k++) {
        const float uc = centres[k][0], vc = centres[k][1];
        const tex_query q = {uc, vc, 0.0f, v3s(0.0f), v3s(0.0f), v.tex_nodes, uc, vc, 0.0f};
        const vec3 c = tex_eval_rgb(v.textures, &m->map_norm, q);
        const vec3 tl = v3(0.25f * (2.0f * c.x - 1.0f), 0.25f * (2.0f * c.y - 1.0f), 2.0f * c.z - 1.0f);
        if (!(tl.z > 0.0f)) continue; /* a normal facing away is not used */
        const vec3 want = v3_norm(v3(tl.x, -tl.y, tl.z));
        ray r = {{uc, 1.0f - vc, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
        hit h = {1.0f, 0, uc, 1.0f - vc};
        material tm;
        const surface sf = surface_texture(&v, &r, &h, 0.0f, surface_at(&v, &r, &h), &tm);
        CHECKF(vnear(sf.ns, want, 1e-5f), "texel %d: (%g %g %g), want (%g %g %g)", k, (double)sf.ns.x, (double)sf.ns.y,
               (double)sf.ns.z, (double)want.x, (double)want.y, (double)want.z);
        checked++;
    }
    CHECK(checked >= 1); /* (tex_rgbw: red and green texels point into the surface) */
    scene_destroy(s);
}


/* ---- COLOR_0 ------------------------------------------------------------------------------ */

/* A triangle with COLOR_0 (normalized unsigned bytes: red, green with
 * alpha 0.5, blue) placed by two nodes (one mesh, an instance each);
 * material: the primitive's keys (a material reference or nothing). */
static char *color_doc(const char *matref, const char *materials, const char *ctype_type)
{
    bytes b = {0};
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint8_t c8[12] = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 255};
    const float cf[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    put(&b, pos, sizeof pos);
    const bool f = strstr(ctype_type, "5126") != NULL;
    if (f) put(&b, cf, sizeof cf);
    else put(&b, c8, sizeof c8);
    char *uri = b64(b.d, b.n);
    char *j = malloc(8192);
    snprintf(j, 8192,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":%d}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"count\":3,%s}]%s,"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"COLOR_0\":1}%s}]}],"
             "\"nodes\":[{\"mesh\":0},{\"mesh\":0,\"translation\":[3,0,0]}],\"scenes\":[{\"nodes\":[0,1]}]}",
             b.n, uri, f ? 36 : 12, ctype_type, materials, matref);
    free(uri);
    return j;
}

static void test_color(void)
{
    pk_scene *s;
    char *j = color_doc(",\"material\":0", ",\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1]}}]",
                        "\"componentType\":5121,\"normalized\":true,\"type\":\"VEC4\"");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 2 && s->colors);
    CHECKF(wlog.count == 0, "%s", wlog.last);
    /* both instances carry the colours */
    for (size_t t = 0; t < 2; t++) {
        const rgba *c = s->colors;
        CHECK(c[s->tris[t].v[0]].r == 1.0f && c[s->tris[t].v[0]].g == 0.0f && c[s->tris[t].v[0]].a == 1.0f);
        CHECK(c[s->tris[t].v[1]].g == 1.0f && fabsf(c[s->tris[t].v[1]].a - 128.0f / 255.0f) < 1e-6f);
        CHECK(c[s->tris[t].v[2]].b == 1.0f && c[s->tris[t].v[2]].r == 0.0f);
    }
    const material *m = &s->materials[s->tris[0].material];
    CHECK(m->vertex_color && m->textured);
    /* at barycentric (1/2, 1/4, 1/4): the base colour 0.5 times the interpolated colour */
    const scene_view v = scene_view_of(s);
    ray r = {{3.25f, 0.25f, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY}; /* the second instance */
    hit h = {1.0f, 1, 0.25f, 0.25f};
    surface sf = surface_at(&v, &r, &h);
    material tm;
    sf = surface_texture(&v, &r, &h, 0.0f, sf, &tm);
    CHECK(vnear(sf.m->kd, v3(0.25f, 0.125f, 0.125f), 1e-6f));
    scene_destroy(s);

    /* VEC3 floats on a primitive without a material: the default material's copy takes them */
    j = color_doc("", "", "\"componentType\":5126,\"type\":\"VEC3\"");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->colors);
    CHECK(s->tris[0].material != 0 && s->materials[s->tris[0].material].vertex_color && !s->materials[0].vertex_color);
    CHECK(s->colors[s->tris[0].v[1]].g == 1.0f && s->colors[s->tris[0].v[1]].a == 1.0f);
    scene_destroy(s);

    /* unlit: the colours multiply the base colour, which is the emission, at
     * hits, in light samples and in the power that chooses among lights (the
     * colours' mean over the triangle, 1/3 each) */
    j = color_doc(",\"material\":0",
                  ",\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1]},"
                  "\"extensions\":{\"KHR_materials_unlit\":{}}}]",
                  "\"componentType\":5121,\"normalized\":true,\"type\":\"VEC4\"");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->ntris == 2 && s->nemissive == 2);
    {
        const scene_view uv = scene_view_of(s);
        surface us = surface_at(&uv, &r, &h);
        us = surface_texture(&uv, &r, &h, 0.0f, us, &tm);
        CHECKF(vnear(us.m->ke, v3(0.25f, 0.125f, 0.125f), 1e-6f), "ke %g %g %g", (double)us.m->ke.x,
               (double)us.m->ke.y, (double)us.m->ke.z);
        CHECK(vnear(us.m->kd, v3s(0.0f), 0.0f));
        env_light env;
        memset(&env, 0, sizeof env);
        light_set ls;
        pk_context *lc;
        REQUIRE(pk_context_create(NULL, &lc) == PK_OK);
        REQUIRE(light_set_build(lc, s, &env, &ls) == PK_OK);
        REQUIRE(ls.n == 2);
        const light *l = &ls.lights[ls.of_prim[1]];
        /* the light's radiance at barycentric (1/2, 1/4, 1/4) of the second instance */
        const vec3 q = v3_add(v3_scale(l->v[0], 0.5f), v3_add(v3_scale(l->v[1], 0.25f), v3_scale(l->v[2], 0.25f)));
        const vec3 le = light_le_at(&uv, l, q, l->le);
        CHECKF(vnear(le, v3(0.25f, 0.125f, 0.125f), 1e-6f), "le %g %g %g", (double)le.x, (double)le.y, (double)le.z);
        /* each triangle: luminance 0.5 / 3 over area 1/2, one side */
        CHECKF(fabs(ls.power - 2.0 * (0.5 / 3.0) * 0.5 * (double)PK_PI) < 1e-5, "power %g", ls.power);
        light_set_free(&lc->alloc, &ls);
        pk_context_destroy(lc);
    }
    scene_destroy(s);

    /* integers that are not normalized are refused */
    j = color_doc("", "", "\"componentType\":5121,\"type\":\"VEC4\"");
    CHECK(load(j, &s) == PK_ERR_PARSE && strstr(msg, "/accessors/1: COLOR_0 must be"));
    free(j);
}

/* ---- alphaMode BLEND ------------------------------------------------------------------- */

/* The share of n rays from (0, 0, 1) through a grid on the plane z = 0
 * that pass through the surface there, and whether the same rays choose
 * the same again. */
static double pass_share(const pk_scene *s, int n, bool *same)
{
    const scene_view v = scene_view_of(s);
    int pass = 0;
    *same = true;
    for (int i = 0; i < n; i++) {
        const float x = -0.2f + 0.4f * (float)(i % 200) / 200.0f, y = -0.2f + 0.4f * (float)(i / 200) / (float)(n / 200);
        ray r = {{0.0f, 0.0f, 1.0f}, 0.0f, {x, y, -1.0f}, INFINITY};
        /* the plane is triangle 0 (corners (-1,-1), (1,-1), (-1,1)) or 1 */
        const uint32_t prim = x + y <= 0.0f ? 0 : 1;
        hit h = {1.0f, prim, 0.0f, 0.0f};
        vec3 a, b, c;
        view_tri_verts(&v, prim, &a, &b, &c);
        /* barycentrics of (x, y, 0) */
        const vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a), d = v3_sub(v3(x, y, 0.0f), a);
        const float den = e1.x * e2.y - e1.y * e2.x;
        h.u = (d.x * e2.y - d.y * e2.x) / den;
        h.v = (e1.x * d.y - e1.y * d.x) / den;
        const bool hole = surface_is_hole(&v, &r, &h);
        pass += hole;
        if (surface_is_hole(&v, &r, &h) != hole) *same = false;
    }
    return (double)pass / n;
}

static char *blend_doc(float factor, const char *vertex_alpha)
{
    bytes b = {0};
    const float pos[12] = {-1, -1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0};
    const uint16_t idx[6] = {0, 1, 2, 2, 1, 3};
    float col[16];
    float va = (float)atof(vertex_alpha);
    for (int k = 0; k < 4; k++) col[4 * k] = col[4 * k + 1] = col[4 * k + 2] = 1.0f, col[4 * k + 3] = va;
    put(&b, pos, sizeof pos);
    put(&b, idx, sizeof idx);
    put(&b, col, sizeof col);
    char *uri = b64(b.d, b.n);
    char *j = malloc(8192);
    snprintf(j, 8192,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12},"
             "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":64}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"}],"
             "\"materials\":[{\"alphaMode\":\"BLEND\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,%g]}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0%s},\"indices\":1,\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             b.n, uri, (double)factor, va < 1.0f ? ",\"COLOR_0\":2" : "");
    free(uri);
    return j;
}

static void test_blend(void)
{
    const int n = 40000;
    const struct {
        float factor;
        const char *va;
        double want;
    } cases[] = {{0.5f, "1", 0.5}, {0.5f, "0.5", 0.75}, {1.0f, "1", 0.0}, {0.0f, "1", 1.0}, {0.8f, "1", 0.2}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        pk_scene *s;
        char *j = blend_doc(cases[k].factor, cases[k].va);
        CHECKF(load(j, &s) == PK_OK, "%s", msg);
        free(j);
        REQUIRE(s && s->ntris == 2);
        CHECKF(wlog.count == 0, "%s", wlog.last);
        const material *m = &s->materials[s->tris[0].material];
        CHECK(m->blend && m->cutout && s->has_cutout && m->d == 1.0f);
        bool same;
        const double share = pass_share(s, n, &same);
        /* binomial: 4 standard deviations of the share of n independent choices */
        const double p = cases[k].want, tol = 4.0 * sqrt(p * (1.0 - p) / n);
        CHECKF(fabs(share - p) <= tol, "factor %g, vertex alpha %s: %.4f pass, %.4f expected (+-%.4f)",
               (double)cases[k].factor, cases[k].va, share, p, tol);
        CHECK(same);
        scene_destroy(s);
    }
}

/* ---- tangents ----------------------------------------------------------------------------- */

/* A mesh (nv vertices: positions, normals, glTF uvs; optional tangents)
 * with a normal-mapped material, placed by one node (node: its extra keys). */
static char *mesh_doc(const float *pos, const float *nrm, const float *uv, const float *tan, size_t nv,
                      const uint32_t *idx, size_t ni, const char *node)
{
    static bytes b;
    b.n = 0;
    const size_t op = put(&b, pos, 12 * nv), on = put(&b, nrm, 12 * nv), ou = put(&b, uv, 8 * nv);
    const size_t oi = put(&b, idx, 4 * ni), ot = tan ? put(&b, tan, 16 * nv) : 0;
    char *uri = b64(b.d, b.n);
    size_t cap = strlen(uri) + 4096;
    char *j = malloc(cap);
    snprintf(j, cap,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},"
             "{\"bufferView\":3,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"},"
             "{\"bufferView\":4,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC4\"}],"
             "\"images\":[{\"uri\":\"../tex_rgbw.png\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"normalTexture\":{\"index\":0}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2%s},"
             "\"indices\":3,\"material\":0}]}],\"nodes\":[{\"mesh\":0%s}],\"scenes\":[{\"nodes\":[0]}]}",
             b.n, uri, op, 12 * nv, on, 12 * nv, ou, 8 * nv, oi, 4 * ni, tan ? ot : 0, tan ? 16 * nv : 4, nv, nv, nv,
             ni, tan ? nv : 1, tan ? ",\"TANGENT\":4" : "", node);
    free(uri);
    return j;
}

/* The scene's tangent of the vertex written at position i (the node
 * places the vertices in order, so the scene's position i). */
static vtangent tan_of(const pk_scene *s, size_t i) { return s->tangents[i]; }

static void test_tangents_plane(void)
{
    /* the unit square in z = 0, normals +z; uvs straight, then u mirrored */
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0}; /* glTF: v down, so the image's up is +y */
    const float uvm[8] = {1, 1, 0, 1, 0, 0, 1, 0};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (int mirrored = 0; mirrored < 2; mirrored++) {
        pk_scene *s;
        char *j = mesh_doc(pos, nrm, mirrored ? uvm : uv, NULL, 4, idx, 6, "");
        CHECKF(load(j, &s) == PK_OK, "%s", msg);
        free(j);
        REQUIRE(s && s->tangents && s->npositions == 4);
        CHECKF(wlog.count == 0, "%s", wlog.last);
        /* t along increasing u (+x, mirrored -x); the bitangent w (n x t) along the image's up (+y) */
        for (size_t i = 0; i < 4; i++) {
            const vtangent t = tan_of(s, i);
            CHECKF(vnear(t.t, v3(mirrored ? -1.0f : 1.0f, 0, 0), 1e-6f), "%g %g %g %g", (double)t.t.x, (double)t.t.y, (double)t.t.z, (double)t.w);
            CHECK(t.w == (mirrored ? -1.0f : 1.0f));
            CHECK(vnear(v3_scale(v3_cross(v3(0, 0, 1), t.t), t.w), v3(0, 1, 0), 1e-6f));
        }
        scene_destroy(s);

        /* the same tangents given in the file: the same frame */
        const float tg[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
        const float tgm[16] = {-1, 0, 0, -1, -1, 0, 0, -1, -1, 0, 0, -1, -1, 0, 0, -1};
        j = mesh_doc(pos, nrm, mirrored ? uvm : uv, mirrored ? tgm : tg, 4, idx, 6, "");
        pk_scene *s2;
        CHECKF(load(j, &s2) == PK_OK, "%s", msg);
        free(j);
        j = mesh_doc(pos, nrm, mirrored ? uvm : uv, NULL, 4, idx, 6, "");
        CHECKF(load(j, &s) == PK_OK, "%s", msg);
        free(j);
        REQUIRE(s && s2 && s->tangents && s2->tangents);
        for (size_t i = 0; i < 4; i++)
            CHECK(vnear(tan_of(s, i).t, tan_of(s2, i).t, 1e-6f) && tan_of(s, i).w == tan_of(s2, i).w);
        scene_destroy(s);
        scene_destroy(s2);
    }
    /* a mirroring node (x -> -x): the tangent follows, the handedness turns */
    pk_scene *s;
    char *j = mesh_doc(pos, nrm, uv, NULL, 4, idx, 6, ",\"scale\":[-1,1,1]");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->tangents);
    CHECK(vnear(tan_of(s, 0).t, v3(-1, 0, 0), 1e-6f) && tan_of(s, 0).w == -1.0f);
    scene_destroy(s);
}

static void test_tangents_sphere(void)
{
    /* a latitude-longitude sphere: u = phi / 2 pi around +y, glTF v = theta / pi from the top */
    enum { NU = 24, NV = 12 };
    static float pos[3 * (NU + 1) * (NV + 1)], nrm[3 * (NU + 1) * (NV + 1)], uv[2 * (NU + 1) * (NV + 1)];
    static uint32_t idx[6 * NU * NV];
    size_t ni = 0;
    for (int b = 0; b <= NV; b++)
        for (int a = 0; a <= NU; a++) {
            const int k = b * (NU + 1) + a;
            const double ph = 2.0 * 3.14159265358979 * a / NU, th = 3.14159265358979 * b / NV;
            /* p = (sin th cos ph, cos th, -sin th sin ph): u grows counter-clockwise seen from above */
            pos[3 * k] = (float)(sin(th) * cos(ph)), pos[3 * k + 1] = (float)cos(th), pos[3 * k + 2] = (float)(-sin(th) * sin(ph));
            memcpy(nrm + 3 * k, pos + 3 * k, 3 * sizeof(float));
            uv[2 * k] = (float)a / NU, uv[2 * k + 1] = (float)b / NV;
        }
    for (int b = 0; b < NV; b++)
        for (int a = 0; a < NU; a++) {
            const uint32_t k = (uint32_t)(b * (NU + 1) + a), r = NU + 1;
            /* counter-clockwise seen from outside */
            idx[ni++] = k, idx[ni++] = k + r, idx[ni++] = k + 1;
            idx[ni++] = k + 1, idx[ni++] = k + r, idx[ni++] = k + r + 1;
        }
    pk_scene *s;
    char *j = mesh_doc(pos, nrm, uv, NULL, (NU + 1) * (NV + 1), idx, ni, "");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->tangents);
    /* (the triangles at the poles have no area: dropped with a warning) */
    /* dp/dphi / |dp/dphi| = (-sin ph, 0, -cos ph); the bitangent toward the image's up, the north pole */
    double worst = 0.0;
    int wrong_hand = 0;
    for (int b = 1; b < NV; b++)
        for (int a = 1; a < NU; a++) {
            const int k = b * (NU + 1) + a;
            const double ph = 2.0 * 3.14159265358979 * a / NU, th = 3.14159265358979 * b / NV;
            const vec3 want = v3((float)-sin(ph), 0.0f, (float)-cos(ph));
            const vtangent t = tan_of(s, (size_t)k);
            worst = fmax(worst, (double)v3_len(v3_sub(t.t, want)));
            const vec3 bt = v3_scale(v3_cross(v3(nrm[3 * k], nrm[3 * k + 1], nrm[3 * k + 2]), t.t), t.w);
            /* d p / d theta points south: the image's up (v decreasing in glTF) is -d/dtheta */
            const vec3 south = v3((float)(cos(th) * cos(ph)), (float)-sin(th), (float)(-cos(th) * sin(ph)));
            wrong_hand += v3_dot(bt, south) > -0.99f;
        }
    /* the corners' weights are symmetric about each vertex of the grid: exact but for rounding */
    CHECKF(worst < 1e-5, "worst tangent error %g", worst);
    CHECK(wrong_hand == 0);
    scene_destroy(s);
}

static void test_tangents_cube(void)
{
    /* a cube's six faces, four vertices each; the uvs of the faces +x, -y and +z mirrored in u */
    static float pos[72], nrm[72], uv[48];
    static uint32_t idx[36];
    const float axes[6][3][3] = {
        /* normal, the face's u direction unmirrored, its image-up direction */
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}}, {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},
        {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},  {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}}};
    const bool mirror[6] = {true, false, false, true, true, false};
    for (int f = 0; f < 6; f++) {
        const vec3 n = v3(axes[f][0][0], axes[f][0][1], axes[f][0][2]);
        const vec3 U = v3(axes[f][1][0], axes[f][1][1], axes[f][1][2]), V = v3(axes[f][2][0], axes[f][2][1], axes[f][2][2]);
        const float cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
        for (int c = 0; c < 4; c++) {
            const int k = 4 * f + c;
            const vec3 p = v3_add(n, v3_add(v3_scale(U, 2.0f * cu[c] - 1.0f), v3_scale(V, 2.0f * cv[c] - 1.0f)));
            pos[3 * k] = p.x, pos[3 * k + 1] = p.y, pos[3 * k + 2] = p.z;
            nrm[3 * k] = n.x, nrm[3 * k + 1] = n.y, nrm[3 * k + 2] = n.z;
            uv[2 * k] = mirror[f] ? 1.0f - cu[c] : cu[c];
            uv[2 * k + 1] = 1.0f - cv[c];
        }
        /* counter-clockwise about n: U x V = n for every face */
        const uint32_t q = (uint32_t)(4 * f), o[6] = {0, 1, 2, 0, 2, 3};
        for (int e = 0; e < 6; e++) idx[6 * f + e] = q + o[e];
    }
    pk_scene *s;
    char *j = mesh_doc(pos, nrm, uv, NULL, 24, idx, 36, "");
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    free(j);
    REQUIRE(s && s->tangents);
    for (int f = 0; f < 6; f++) {
        const vec3 U = v3(axes[f][1][0], axes[f][1][1], axes[f][1][2]), V = v3(axes[f][2][0], axes[f][2][1], axes[f][2][2]);
        const vec3 n = v3(axes[f][0][0], axes[f][0][1], axes[f][0][2]);
        for (int c = 0; c < 4; c++) {
            const vtangent t = tan_of(s, (size_t)(4 * f + c));
            /* u increases along U, or against it where mirrored; the bitangent is always V (the image's up) */
            CHECKF(vnear(t.t, mirror[f] ? v3_neg(U) : U, 1e-6f), "face %d", f);
            CHECKF(t.w == (mirror[f] ? -1.0f : 1.0f), "face %d", f);
            CHECK(vnear(v3_scale(v3_cross(n, t.t), t.w), V, 1e-6f));
        }
    }
    scene_destroy(s);
}

/* Instances kept rather than flattened give the same vertex colours and
 * tangents at a hit (a mirroring instance's handedness turned). */
static void test_kept(void)
{
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    /* node 0 places the mesh and its child node 1 places it again, mirrored and turned */
    const char *nodes = ",\"children\":[1]},{\"mesh\":0,\"scale\":[-1,1,1],\"rotation\":[0,0,0.38268343,0.92387953]";
    char *j = mesh_doc(pos, nrm, uv, NULL, 4, idx, 6, nodes);
    pk_scene *flat, *kept;
    load_config = "scene.instances=flatten";
    CHECKF(load(j, &flat) == PK_OK, "%s", msg);
    load_config = "scene.instances=keep";
    CHECKF(load(j, &kept) == PK_OK, "%s", msg);
    load_config = NULL;
    free(j);
    REQUIRE(flat && kept && flat->ntris == 4 && kept->ntris == 0 && kept->nkept == 2 && flat->tangents && kept->mesh_tangents);
    const scene_view vf = scene_view_of(flat), vk = scene_view_of(kept);
    int bad = 0;
    for (uint32_t k = 0; k < 4; k++) {
        vec3 tf, tk;
        float wf, wk;
        REQUIRE(view_tri_tangent(&vf, k, 0.2f, 0.3f, &tf, &wf) && view_tri_tangent(&vk, k, 0.2f, 0.3f, &tk, &wk));
        bad += !vnear(v3_norm(tf), v3_norm(tk), 1e-6f) || wf != wk;
        if (k >= 2) CHECK(wf == -1.0f); /* the mirrored one */
    }
    CHECK(bad == 0);
    scene_destroy(flat);
    scene_destroy(kept);

    /* colours */
    j = color_doc(",\"material\":0", ",\"materials\":[{}]", "\"componentType\":5121,\"normalized\":true,\"type\":\"VEC4\"");
    load_config = "scene.instances=flatten";
    CHECKF(load(j, &flat) == PK_OK, "%s", msg);
    load_config = "scene.instances=keep";
    CHECKF(load(j, &kept) == PK_OK, "%s", msg);
    load_config = NULL;
    free(j);
    REQUIRE(flat && kept && kept->nkept == 2 && kept->mesh_colors);
    const scene_view cf = scene_view_of(flat), ck = scene_view_of(kept);
    for (uint32_t k = 0; k < 2; k++) {
        const rgba a = view_tri_color(&cf, k, 0.2f, 0.3f), b = view_tri_color(&ck, k, 0.2f, 0.3f);
        CHECK(a.r == b.r && a.g == b.g && a.b == b.b && a.a == b.a && fabsf(a.r - 0.5f) < 1e-6f);
    }
    scene_destroy(flat);
    scene_destroy(kept);
}

/* ---- texture-coordinate sets ------------------------------------------------------------ */

/* The file tests/data/gltf/NAME, read whole (NUL-terminated). */
static char *fixture(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/gltf/%s", PK_TEST_DATA, name);
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    REQUIRE(fseek(f, 0, SEEK_END) == 0);
    const long n = ftell(f);
    REQUIRE(n > 0 && fseek(f, 0, SEEK_SET) == 0);
    char *j = malloc((size_t)n + 1);
    REQUIRE(j && fread(j, 1, (size_t)n, f) == (size_t)n);
    j[n] = '\0';
    fclose(f);
    return j;
}

/* uv_sets.gltf (make_gltf.py): two quads over [-1, 1]^2 at z = 0, moved by
 * -1.1 and +1.1 in x (and the second again out of view), with TEXCOORD_0 = ((x + 1) / 2, (1 - y) / 2) and
 * TEXCOORD_1 a quarter turn of it, ((1 - y) / 2, (1 - x) / 2) (object x, y).
 * The first's base colour reads set 0 and its emission set 1; the second's
 * normal map reads set 1. At hits, each map is looked up at its own set's
 * coordinates (the scene's v = 1 - glTF's); the emission a light sample
 * sees is the one a hit sees; the second quad's generated tangents follow
 * set 1's u, which runs along -y; and keeping the meshes as instances
 * changes none of it. */
static void test_uv_sets(void)
{
    char *j = fixture("uv_sets.gltf");
    pk_scene *s, *kept;
    CHECKF(load(j, &s) == PK_OK, "%s", msg);
    CHECKF(wlog.count == 0, "%s", wlog.last);
    load_config = "scene.instances=keep";
    CHECKF(load(j, &kept) == PK_OK, "%s", msg);
    load_config = NULL;
    free(j);
    REQUIRE(s && kept && s->ntris == 6 && s->uvs1);
    /* (triangles: the first quad's 0, 1, the second's 2, 3, its copy's 4, 5) */
    const scene_view v = scene_view_of(s), vk = scene_view_of(kept);
    const material *m0 = &s->materials[s->tris[0].material];
    REQUIRE(m0->map_kd.kind == TEX_IMAGE && m0->map_kd.uvset == 0 && m0->map_ke.kind == TEX_IMAGE &&
            m0->map_ke.uvset == 1);
    tex_ref base = m0->map_kd, emit = m0->map_ke;
    emit.uvset = 0; /* looked up below at coordinates computed here */
    int checked = 0, differs = 0;
    for (uint32_t t = 0; t < 2; t++) {
        for (int k = 0; k < 5; k++) {
            const float bu = 0.1f + 0.17f * (float)k, bv = 0.07f + 0.11f * (float)k;
            if (bu + bv > 1.0f) continue;
            view_tri vt;
            view_tri_get(&v, t, &vt);
            const vec3 p = v3_add(v3_add(v3_scale(vt.p[0], 1.0f - bu - bv), v3_scale(vt.p[1], bu)), v3_scale(vt.p[2], bv));
            const float x = p.x + 1.1f, y = p.y; /* object space */
            const float u0 = (x + 1.0f) / 2.0f, v0 = 1.0f - (1.0f - y) / 2.0f;
            const float u1 = (1.0f - y) / 2.0f, v1 = 1.0f - (1.0f - x) / 2.0f;
            ray r = {{p.x, p.y, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
            hit h = {1.0f, t, bu, bv};
            material tm;
            const surface sf = surface_texture(&v, &r, &h, 0.0f, surface_at(&v, &r, &h), &tm);
            (void)sf;
            const tex_query q0 = {u0, v0, 0.0f, v3s(0.0f), v3s(0.0f), NULL, 0.0f, 0.0f, 0.0f};
            const tex_query q1 = {u1, v1, 0.0f, v3s(0.0f), v3s(0.0f), NULL, 0.0f, 0.0f, 0.0f};
            const vec3 kd = tex_eval_rgb(v.textures, &base, q0);
            const vec3 ke = v3_scale(tex_eval_rgb(v.textures, &emit, q1), 0.5f);
            CHECKF(vnear(tm.kd, kd, 2e-5f), "tri %u, (%g, %g): kd (%g %g %g), want (%g %g %g)", t, (double)bu, (double)bv,
                   (double)tm.kd.x, (double)tm.kd.y, (double)tm.kd.z, (double)kd.x, (double)kd.y, (double)kd.z);
            CHECKF(vnear(tm.ke, ke, 2e-5f), "tri %u, (%g, %g): ke (%g %g %g), want (%g %g %g)", t, (double)bu, (double)bv,
                   (double)tm.ke.x, (double)tm.ke.y, (double)tm.ke.z, (double)ke.x, (double)ke.y, (double)ke.z);
            /* set 0's coordinates would give another emission (so the check above can tell the sets apart) */
            differs += !vnear(v3_scale(tex_eval_rgb(v.textures, &emit, q0), 0.5f), ke, 0.05f);
            /* a light sample at p sees the same */
            const light l = light_of_triangle(t, vt.p[0], vt.p[1], vt.p[2], m0);
            const vec3 le = light_le_at(&v, &l, p, m0->ke);
            CHECKF(vnear(le, tm.ke, 2e-5f), "tri %u: light sample (%g %g %g), hit (%g %g %g)", t, (double)le.x,
                   (double)le.y, (double)le.z, (double)tm.ke.x, (double)tm.ke.y, (double)tm.ke.z);
            checked++;
        }
    }
    CHECK(checked >= 6 && differs >= 3);
    /* kept as instances (the second quad, placed twice): the same normal at the same hit as flattened */
    REQUIRE(kept->nkept == 2 && kept->mesh_uvs1 && kept->mesh_tangents);
    int bent = 0;
    for (uint32_t t = 0; t < 2; t++) {
        for (int k = 0; k < 4; k++) {
            const float bu = 0.15f + 0.2f * (float)k, bv = 0.1f + 0.05f * (float)k;
            hit h = {1.0f, 2 + t, bu, bv}, hk = {1.0f, (uint32_t)(kept->ntris + kept->nspheres) + t, bu, bv};
            view_tri vt;
            view_tri_get(&v, h.prim, &vt);
            const vec3 p = v3_add(v3_add(v3_scale(vt.p[0], 1.0f - bu - bv), v3_scale(vt.p[1], bu)), v3_scale(vt.p[2], bv));
            ray r = {{p.x, p.y, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
            material tm, tk;
            const surface a = surface_texture(&v, &r, &h, 0.0f, surface_at(&v, &r, &h), &tm);
            const surface b = surface_texture(&vk, &r, &hk, 0.0f, surface_at(&vk, &r, &hk), &tk);
            CHECKF(vnear(a.ns, b.ns, 1e-5f), "tri %u: ns (%g %g %g) flattened, (%g %g %g) kept", t, (double)a.ns.x,
                   (double)a.ns.y, (double)a.ns.z, (double)b.ns.x, (double)b.ns.y, (double)b.ns.z);
            bent += a.ns.z < 0.999f;
        }
    }
    CHECKF(bent >= 2, "bent %d", bent); /* (the map bends the normal at some: its red and green texels face away) */
    /* the second quad's tangents: set 1's u grows along -y */
    const material *m1 = &s->materials[s->tris[2].material];
    REQUIRE(m1->map_norm.kind == TEX_IMAGE && m1->map_norm.uvset == 1 && s->tangents);
    for (int k = 0; k < 3; k++) {
        const vtangent tg = s->tangents[s->tris[2].v[k]];
        CHECKF(vnear(tg.t, v3(0.0f, -1.0f, 0.0f), 1e-5f) && tg.w != 0.0f, "vertex %d: tangent (%g %g %g)", k,
               (double)tg.t.x, (double)tg.t.y, (double)tg.t.z);
    }
    scene_destroy(s);
    scene_destroy(kept);
}

int main(void)
{
    test_morph();
    test_morph_attributes();
    test_skin();
    test_normal_scale();
    test_color();
    test_blend();
    test_tangents_plane();
    test_tangents_sphere();
    test_tangents_cube();
    test_kept();
    test_uv_sets();
    return test_done("test_gltf_geom");
}

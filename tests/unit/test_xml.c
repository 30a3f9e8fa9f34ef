/*
 * test_xml.c - the Mitsuba XML reader on small scenes written here: each
 * transform, $ substitution, references, includes, each shape's triangles,
 * area and winding, the bsdf mapping, the emitters, the camera (against the
 * JSON camera it should equal, and the side of the image a +x object lands
 * on), and the messages of malformed input with their line numbers.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "scene/scene.h"
#include "scene/spectra.h"
#include "scene/texture.h"

#include <sys/stat.h>

#define NAME "scene.xml"
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static warning_log wl;

static bool warned(const char *part) { return warning_log_has(&wl, part); }

static pk_context *ctx;
static char tmpdir[256];

/* Parses xml (wrapped in <scene version="3.0.0"> when wrap) into a
 * committed scene; NULL on failure (the message is in ctx). */
static pk_scene *load(const char *xml, bool wrap)
{
    char buf[16384];
    if (wrap) snprintf(buf, sizeof buf, "<scene version=\"3.0.0\">\n%s\n</scene>\n", xml);
    else snprintf(buf, sizeof buf, "%s", xml);
    pk_context_clear_error(ctx);
    warning_log_clear(&wl);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_xml_memory(ctx, buf, strlen(buf), NAME, tmpdir, &s);
    if (st != PK_OK) return NULL;
    return s;
}

static pk_scene *load_ok(const char *xml)
{
    pk_scene *s = load(xml, true);
    CHECKF(s != NULL, "%s\n-> %s", xml, pk_context_error(ctx));
    return s;
}

/* Expects a failure whose message contains want. */
static void load_fails(const char *xml, bool wrap, const char *want)
{
    pk_scene *s = load(xml, wrap);
    CHECKF(s == NULL, "%s: loaded, expected an error with '%s'", xml, want);
    if (s) {
        pk_scene_destroy(s);
        return;
    }
    CHECKF(strstr(pk_context_error(ctx), want) != NULL, "got '%s', expected '%s'", pk_context_error(ctx), want);
}

static bool near3(vec3 a, vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

static double tri_area(const pk_scene *s, size_t k, vec3 *n)
{
    vec3 a, b, c;
    scene_tri_verts(s, k, &a, &b, &c);
    vec3 x = v3_cross(v3_sub(b, a), v3_sub(c, a));
    if (n) *n = v3_norm(x);
    return 0.5 * (double)v3_len(x);
}

static double total_area(const pk_scene *s)
{
    double a = 0.0;
    for (size_t k = 0; k < s->ntris; k++) a += tri_area(s, k, NULL);
    return a;
}

/* Every triangle's winding normal points away from c (outward), or toward
 * it when inward. */
static bool wound_outward(const pk_scene *s, vec3 c, bool inward)
{
    for (size_t k = 0; k < s->ntris; k++) {
        vec3 a, b, d, n;
        scene_tri_verts(s, k, &a, &b, &d);
        if (tri_area(s, k, &n) < 1e-9) continue;
        vec3 mid = v3_scale(v3_add(v3_add(a, b), d), 1.0f / 3.0f);
        float dot = v3_dot(n, v3_sub(mid, c));
        if (inward ? dot >= 0.0f : dot <= 0.0f) return false;
    }
    return true;
}

static void write_file(const char *rel, const void *data, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, rel);
    FILE *f = fopen(path, "wb");
    REQUIRE(f);
    REQUIRE(fwrite(data, 1, n, f) == n);
    fclose(f);
}

static void write_text(const char *rel, const char *text) { write_file(rel, text, strlen(text)); }

/* ---- transforms ---------------------------------------------------------------------- */

/* The rectangle's corner (1, 1, 0) after a transform. */
static vec3 corner_after(const char *transform)
{
    char xml[2048];
    snprintf(xml, sizeof xml, "<shape type=\"rectangle\"><transform name=\"to_world\">%s</transform></shape>", transform);
    pk_scene *s = load_ok(xml);
    vec3 r = v3s(NAN);
    if (s && s->npositions == 4) r = s->positions[2];
    pk_scene_destroy(s);
    return r;
}

static void test_transforms(void)
{
    CHECK(near3(corner_after("<translate x=\"1\" y=\"2\" z=\"3\"/>"), v3(2, 3, 3), 1e-6f));
    CHECK(near3(corner_after("<translate value=\"1, 2, 3\"/>"), v3(2, 3, 3), 1e-6f));
    CHECK(near3(corner_after("<scale value=\"2\"/>"), v3(2, 2, 0), 1e-6f));
    CHECK(near3(corner_after("<scale x=\"3\"/>"), v3(3, 1, 0), 1e-6f));
    CHECK(near3(corner_after("<scale value=\"1 2 3\"/>"), v3(1, 2, 0), 1e-6f));
    /* right-handed: 90 degrees about z takes (1, 1) to (-1, 1) */
    CHECK(near3(corner_after("<rotate z=\"1\" angle=\"90\"/>"), v3(-1, 1, 0), 1e-6f));
    CHECK(near3(corner_after("<rotate value=\"0 0 1\" angle=\"90\"/>"), v3(-1, 1, 0), 1e-6f));
    CHECK(near3(corner_after("<rotate x=\"1\" angle=\"90\"/>"), v3(1, 0, 1), 1e-6f));
    CHECK(near3(corner_after("<matrix value=\"1 0 0 5  0 1 0 0  0 0 1 0  0 0 0 1\"/>"), v3(6, 1, 0), 1e-6f));
    CHECK(near3(corner_after("<matrix value=\"0 -1 0  1 0 0  0 0 1\"/>"), v3(-1, 1, 0), 1e-6f));
    /* later elements apply after earlier ones: scale then translate vs the reverse */
    CHECK(near3(corner_after("<scale value=\"2\"/><translate x=\"1\"/>"), v3(3, 2, 0), 1e-6f));
    CHECK(near3(corner_after("<translate x=\"1\"/><scale value=\"2\"/>"), v3(4, 2, 0), 1e-6f));
    /* lookat: +z toward the target, +y toward up, x = up x z */
    CHECK(near3(corner_after("<lookat origin=\"0 0 0\" target=\"0 0 -5\" up=\"0 1 0\"/>"), v3(-1, 1, 0), 1e-6f));
    CHECK(near3(corner_after("<lookat origin=\"1, 2, 3\" target=\"1, 2, 4\" up=\"0, 1, 0\"/>"), v3(2, 3, 3), 1e-6f));
    /* camelCase (Mitsuba 0.x) name */
    pk_scene *s = load_ok("<shape type=\"rectangle\"><transform name=\"toWorld\"><translate z=\"7\"/></transform></shape>");
    CHECK(s && fabsf(s->positions[0].z - 7.0f) < 1e-6f);
    pk_scene_destroy(s);
    load_fails("<shape type=\"rectangle\"><transform name=\"to_world\">\n<matrix value=\"1 2 3\"/></transform></shape>",
               true, "scene.xml:3: matrix needs 16 (or 9) numbers, found 3");
    load_fails("<shape type=\"rectangle\"><transform name=\"to_world\">\n<rotate angle=\"5\"/></transform></shape>", true,
               "scene.xml:3: rotate: the axis must not be zero");
}

/* ---- $ parameters, ids, includes --------------------------------------------------- */

static void test_defaults_refs(void)
{
    pk_scene *s = load_ok("<default name=\"r\" value=\"0.25\"/>\n<default name=\"kind\" value=\"diffuse\"/>\n"
                          "<bsdf type=\"$kind\" id=\"m\"><rgb name=\"reflectance\" value=\"$r, 0.5, $r\"/></bsdf>\n"
                          "<shape type=\"rectangle\"><ref id=\"m\"/></shape>\n"
                          "<shape type=\"cube\"><ref id=\"m\"/></shape>\n");
    if (s) {
        CHECK(s->ntris == 14);
        uint32_t m = s->tris[0].material;
        CHECK(s->tris[13].material == m); /* one material for both references */
        CHECK(s->materials[m].type == MAT_DIFFUSE);
        CHECK(near3(s->materials[m].kd, v3(0.25f, 0.5f, 0.25f), 1e-6f));
        CHECK(strcmp(s->materials[m].name, "m") == 0);
    }
    pk_scene_destroy(s);
    /* the first definition holds (the command line's, when it gives one) */
    s = load_ok("<default name=\"r\" value=\"0.1\"/><default name=\"r\" value=\"0.9\"/>"
                "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"$r\"/></bsdf></shape>");
    CHECK(s && fabsf(s->materials[s->tris[0].material].kd.x - 0.1f) < 1e-6f);
    pk_scene_destroy(s);
    load_fails("<shape type=\"rectangle\">\n<bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"$nope\"/></bsdf></shape>",
               true, "scene.xml:3: value=\"...$nope...\": no <default name=\"nope\"> defines $nope");
    load_fails("<shape type=\"rectangle\">\n\n<ref id=\"missing\"/></shape>", true, "scene.xml:4: no bsdf has the id \"missing\"");
    load_fails("<bsdf type=\"twosided\" id=\"a\"><ref id=\"b\"/></bsdf>\n<bsdf type=\"twosided\" id=\"b\"><ref id=\"a\"/></bsdf>\n"
               "<shape type=\"rectangle\"><ref id=\"a\"/></shape>",
               true, "reference cycle");
    /* a nested twosided bsdf inside a shape */
    s = load_ok("<shape type=\"rectangle\"><bsdf type=\"twosided\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" "
                "value=\"0.1 0.2 0.3\"/></bsdf></bsdf></shape>");
    CHECK(s && near3(s->materials[s->tris[0].material].kd, v3(0.1f, 0.2f, 0.3f), 1e-6f));
    pk_scene_destroy(s);
}

static void test_include(void)
{
    write_text("inc_a.xml", "<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"red\"><rgb name=\"reflectance\" "
                            "value=\"0.8 0.1 0.1\"/></bsdf>\n<shape type=\"cube\"/>\n</scene>\n");
    char sub[512];
    snprintf(sub, sizeof sub, "%s/sub", tmpdir);
    mkdir(sub, 0700);
    /* relative to the including file: sub/inc_b.xml includes ../inc_a.xml */
    write_text("sub/inc_b.xml", "<scene version=\"3.0.0\"><include filename=\"../inc_a.xml\"/></scene>");
    pk_scene *s = load_ok("<include filename=\"sub/inc_b.xml\"/>\n<shape type=\"rectangle\"><ref id=\"red\"/></shape>");
    if (s) {
        CHECK(s->ntris == 14);
        CHECK(near3(s->materials[s->tris[12].material].kd, v3(0.8f, 0.1f, 0.1f), 1e-6f));
    }
    pk_scene_destroy(s);
    /* parameters from the caller come before the file's <default>s */
    write_text("params.xml", "<scene version=\"3.0.0\"><default name=\"r\" value=\"0.1\"/><shape type=\"$shape\">"
                             "<bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"$r\"/></bsdf></shape></scene>");
    char path[512];
    snprintf(path, sizeof path, "%s/params.xml", tmpdir);
    const char *params[] = {"r=0.7", "shape=cube", "r=0.2"};
    pk_context_clear_error(ctx);
    s = NULL;
    CHECKF(pk_scene_load_file_params(ctx, path, params, 3, &s) == PK_OK, "%s", pk_context_error(ctx));
    if (s) CHECK(s->ntris == 12 && fabsf(s->materials[s->tris[0].material].kd.x - 0.7f) < 1e-6f);
    pk_scene_destroy(s);
    const char *bad_params[] = {"no equals sign"};
    pk_context_clear_error(ctx);
    s = NULL;
    CHECK(pk_scene_load_file_params(ctx, path, bad_params, 1, &s) == PK_ERR_INVALID_ARGUMENT && !s);
    CHECK(strstr(pk_context_error(ctx), "parameter 'no equals sign': expected NAME=VALUE") != NULL);
    write_text("loop.xml", "<scene version=\"3.0.0\">\n\n<include filename=\"loop.xml\"/></scene>");
    load_fails("<include filename=\"loop.xml\"/>", true, "loop.xml:3: includes nested more than 8 deep");
    load_fails("\n<include filename=\"absent.xml\"/>", true, "scene.xml:3: ");
    write_text("broken.xml", "<scene version=\"3.0.0\">\n<shape type=\"cube\">\n</scene>");
    load_fails("<include filename=\"broken.xml\"/>", true, "broken.xml:3: malformed XML: mismatched tag");
}

/* ---- shapes ------------------------------------------------------------------------ */

static void test_shapes(void)
{
    pk_scene *s = load_ok("<shape type=\"rectangle\"/>");
    if (s) {
        vec3 n;
        CHECK(s->ntris == 2);
        CHECK_NEAR(total_area(s), 4.0, 1e-5);
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, 1), 1e-6f)); /* Mitsuba's emitting side: +z */
        tri_area(s, 1, &n);
        CHECK(near3(n, v3(0, 0, 1), 1e-6f));
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"rectangle\"><boolean name=\"flip_normals\" value=\"true\"/></shape>");
    if (s) {
        vec3 n;
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, -1), 1e-6f));
    }
    pk_scene_destroy(s);
    /* a mirroring transform keeps the side Mitsuba's normal (inverse transpose) gives */
    s = load_ok("<shape type=\"rectangle\"><transform name=\"to_world\"><scale x=\"-1\"/></transform></shape>");
    if (s) {
        vec3 n;
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, 1), 1e-6f));
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"rectangle\"><transform name=\"to_world\"><scale z=\"-1\"/></transform></shape>");
    if (s) {
        vec3 n;
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, -1), 1e-6f));
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"><transform name=\"to_world\"><scale value=\"2\"/><translate x=\"5\"/></transform></shape>");
    if (s) {
        CHECK(s->ntris == 12);
        CHECK_NEAR(total_area(s), 6.0 * 16.0, 1e-3);
        CHECK(wound_outward(s, v3(5, 0, 0), false));
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"><boolean name=\"flipNormals\" value=\"true\"/></shape>");
    CHECK(s && wound_outward(s, v3s(0), true));
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"><transform name=\"to_world\"><scale x=\"-2\"/></transform></shape>");
    CHECK(s && wound_outward(s, v3s(0), false));
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"disk\"><transform name=\"to_world\"><scale value=\"2\"/></transform></shape>");
    if (s) {
        CHECK(s->ntris == 64);
        CHECK_NEAR(total_area(s), 4.0 * 32.0 * sin(2.0 * M_PI / 64.0), 1e-4); /* the inscribed 64-gon */
        vec3 n;
        tri_area(s, 5, &n);
        CHECK(near3(n, v3(0, 0, 1), 1e-6f));
    }
    pk_scene_destroy(s);
    /* analytic sphere: center and radius under a similarity */
    s = load_ok("<shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"2\" z=\"3\"/><float name=\"radius\" value=\"0.5\"/>"
                "<transform name=\"to_world\"><scale value=\"2\"/><rotate y=\"1\" angle=\"90\"/></transform></shape>");
    if (s) {
        CHECK(s->nspheres == 1 && s->ntris == 0);
        CHECK(near3(s->spheres[0].center, v3(6, 4, -2), 1e-5f));
        CHECK_NEAR(s->spheres[0].radius, 1.0, 1e-6);
    }
    pk_scene_destroy(s);
    /* non-uniform scale: tessellated, outward; flipped: inward */
    s = load_ok("<shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"2\"/></transform></shape>");
    if (s) {
        CHECK(s->nspheres == 0 && s->ntris == 2 * 64 * 31);
        CHECK(wound_outward(s, v3s(0), false));
        CHECK(warned("tessellated"));
        /* an ellipsoid of semi-axes 2, 1, 1 has area 21.48; the mesh a little less */
        double a = total_area(s);
        CHECK(a > 21.2 && a < 21.49);
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"sphere\"><boolean name=\"flip_normals\" value=\"true\"/></shape>");
    CHECK(s && s->nspheres == 0 && wound_outward(s, v3s(0), true));
    pk_scene_destroy(s);
    /* unknown shapes are skipped with a warning naming the line */
    s = load_ok("<shape type=\"cube\"/>\n<shape type=\"hair\"/>");
    CHECK(s && s->ntris == 12);
    CHECK(warned("scene.xml:3: shape \"hair\" is not supported; skipped"));
    pk_scene_destroy(s);
}

static const char cube_obj[] = "mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n"
                               "usemtl whatever\nf 1//1 2//1 3//1 4//1\n";

static void test_obj_ply(void)
{
    write_text("quad.obj", cube_obj);
    pk_scene *s = load_ok("<shape type=\"obj\"><string name=\"filename\" value=\"quad.obj\"/>"
                          "<transform name=\"to_world\"><translate z=\"2\"/></transform>"
                          "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.2 0.3 0.4\"/></bsdf></shape>");
    if (s) {
        CHECK(s->ntris == 2);
        CHECK(near3(s->materials[s->tris[0].material].kd, v3(0.2f, 0.3f, 0.4f), 1e-6f));
        CHECK(fabsf(s->positions[s->tris[0].v[0]].z - 2.0f) < 1e-6f);
        CHECK(s->tris[0].n[0] >= 0);
        CHECK(!warned("not defined")); /* the XML's bsdf stands for the OBJ's materials */
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"obj\"><string name=\"filename\" value=\"quad.obj\"/>"
                "<boolean name=\"faceNormals\" value=\"true\"/><boolean name=\"flip_normals\" value=\"true\"/></shape>");
    if (s) {
        vec3 n;
        CHECK(s->tris[0].n[0] == -1);
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, -1), 1e-6f));
    }
    pk_scene_destroy(s);
    /* vertex normals against the winding: Mitsuba's side is the normals' */
    write_text("back.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 -1\nf 1//1 2//1 3//1\n");
    s = load_ok("<shape type=\"obj\"><string name=\"filename\" value=\"back.obj\"/><emitter type=\"area\"/></shape>");
    if (s) {
        vec3 n;
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, -1), 1e-6f));
    }
    pk_scene_destroy(s);
    load_fails("<shape type=\"obj\">\n<string name=\"filename\" value=\"nothere.obj\"/></shape>", true, "scene.xml:3: ");

    /* one quad and one triangle in the three PLY encodings */
    const char *ascii = "ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\n"
                        "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\n"
                        "property float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0 0 0 1 0 0\n2 0 0 0 0 1 1 0\n2 2 0 0 0 1 1 1\n0 2 0 0 0 1 0 1\n4 0 1 2 3\n3 0 2 3\n";
    write_text("a.ply", ascii);
    unsigned char bin[2][512];
    size_t nb[2];
    for (int be = 0; be < 2; be++) {
        const char *hdr = be ? "ply\nformat binary_big_endian 1.0\n" : "ply\nformat binary_little_endian 1.0\n";
        const char *rest = "element vertex 4\nproperty double x\nproperty float y\nproperty float z\n"
                           "element face 2\nproperty list uchar uint vertex_index\nproperty uchar flags\nend_header\n";
        size_t o = 0;
        memcpy(bin[be], hdr, strlen(hdr)), o += strlen(hdr);
        memcpy(bin[be] + o, rest, strlen(rest)), o += strlen(rest);
        const float xy[4][2] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
        for (int v = 0; v < 4; v++) {
            double x = xy[v][0];
            float y = xy[v][1], z = 0.0f;
            unsigned char tmp[16];
            memcpy(tmp, &x, 8);
            memcpy(tmp + 8, &y, 4);
            memcpy(tmp + 12, &z, 4);
            int sizes[3] = {8, 4, 4}, off = 0;
            for (int k = 0; k < 3; k++) { /* this machine is little endian */
                for (int i = 0; i < sizes[k]; i++) bin[be][o + off + i] = be ? tmp[off + sizes[k] - 1 - i] : tmp[off + i];
                off += sizes[k];
            }
            o += 16;
        }
        const uint32_t faces[2][5] = {{4, 0, 1, 2, 3}, {3, 0, 2, 3, 0}};
        for (int f = 0; f < 2; f++) {
            bin[be][o++] = (unsigned char)faces[f][0];
            for (uint32_t i = 0; i < faces[f][0]; i++) {
                uint32_t v = faces[f][1 + i];
                for (int k = 0; k < 4; k++) bin[be][o++] = (unsigned char)(v >> (be ? 24 - 8 * k : 8 * k));
            }
            bin[be][o++] = 7; /* flags */
        }
        nb[be] = o;
    }
    write_file("le.ply", bin[0], nb[0]);
    write_file("be.ply", bin[1], nb[1]);
    const char *files[3] = {"a.ply", "le.ply", "be.ply"};
    for (int i = 0; i < 3; i++) {
        char xml[512];
        snprintf(xml, sizeof xml, "<shape type=\"ply\"><string name=\"filename\" value=\"%s\"/></shape>", files[i]);
        s = load_ok(xml);
        if (!s) continue;
        CHECKF(s->ntris == 3, "%s: %zu triangles", files[i], s->ntris);
        CHECK_NEAR(total_area(s), 6.0, 1e-5);
        vec3 n;
        tri_area(s, 0, &n);
        CHECK(near3(n, v3(0, 0, 1), 1e-6f));
        CHECK(i == 0 ? s->nnormals == 4 : s->nnormals == 0);
        pk_scene_destroy(s);
    }
    /* the PLY reader itself: uvs, and refusals */
    ply_mesh m;
    CHECK(ply_parse(ctx, ascii, strlen(ascii), "a.ply", &m) == PK_OK);
    CHECK(m.uvs && m.uvs[4] == 1.0f && m.uvs[5] == 1.0f);
    ply_mesh_free(ctx, &m);
    const char *bad[] = {
        "ply\nformat ascii 1.0\nelement vertex 50\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n0 0 0\n3 0 1 2\n",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n",
        "plx\n",
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x01",
    };
    const char *why[] = {"cannot fit", "out of range", "no x, y and z", "no end_header", "not a PLY file", "cannot fit"};
    for (int i = 0; i < 6; i++) {
        pk_context_clear_error(ctx);
        CHECKF(ply_parse(ctx, bad[i], strlen(bad[i]), "b.ply", &m) != PK_OK, "bad ply %d accepted", i);
        CHECKF(strstr(pk_context_error(ctx), why[i]) != NULL, "bad ply %d: %s", i, pk_context_error(ctx));
        ply_mesh_free(ctx, &m);
    }
}

/* ---- bsdfs ------------------------------------------------------------------------- */

static material bsdf(const char *body)
{
    char xml[2048];
    snprintf(xml, sizeof xml, "<shape type=\"rectangle\">\n%s\n</shape>", body);
    pk_scene *s = load_ok(xml);
    material m;
    material_init(&m);
    if (s) {
        m = s->materials[s->tris[0].material];
        m.name = NULL;
    }
    pk_scene_destroy(s);
    return m;
}

static void test_bsdfs(void)
{
    material m = bsdf("");
    CHECK(m.type == MAT_DIFFUSE && near3(m.kd, v3s(0.5f), 0)); /* Mitsuba's default */
    m = bsdf("<bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"0.3\"/></bsdf>");
    CHECK(m.type == MAT_DIFFUSE && near3(m.kd, v3s(0.3f), 1e-6f));
    m = bsdf("<bsdf type=\"diffuse\"><srgb name=\"reflectance\" value=\"#ff8000\"/></bsdf>");
    CHECK(near3(m.kd, v3(1.0f, 0.2158605f, 0.0f), 1e-5f));
    /* wavelength:value pairs as Mitsuba 3 reduces them for a reflectance
     * (D65-weighted, zero outside 400..700 nm, so a little darker than 0.6) */
    m = bsdf("<bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:0.6, 700:0.6\"/></bsdf>");
    {
        const float nm[2] = {400.0f, 700.0f}, v[2] = {0.6f, 0.6f};
        CHECK(near3(m.kd, spectra_mitsuba3_rgb(nm, v, 2, false, true), 0));
        CHECK(m.kd.x > 0.5f && m.kd.x < 0.6f && m.kd.z > 0.5f && m.kd.z < 0.6f);
    }
    /* ... and as Mitsuba 0.6 does in a 0.x scene: no weighting, reflectance
     * and emitter alike; a single number is grey for both */
    {
        pk_scene *s06 = load("<scene version=\"0.5.0\"><shape type=\"rectangle\"><bsdf type=\"diffuse\">"
                             "<spectrum name=\"reflectance\" value=\"400:0.6, 700:0.6\"/></bsdf>"
                             "<emitter type=\"area\"><spectrum name=\"radiance\" value=\"400:0, 500:8, 600:15.6, 700:18.4\"/>"
                             "</emitter></shape><shape type=\"disk\"><emitter type=\"area\"><spectrum name=\"radiance\" "
                             "value=\"3\"/></emitter></shape></scene>", false);
        CHECKF(s06 != NULL, "%s", pk_context_error(ctx));
        if (s06) {
            const float nm[2] = {400.0f, 700.0f}, v[2] = {0.6f, 0.6f};
            const float lnm[4] = {400.0f, 500.0f, 600.0f, 700.0f}, lv[4] = {0.0f, 8.0f, 15.6f, 18.4f};
            const material *lit = &s06->materials[s06->tris[0].material];
            CHECK(near3(lit->kd, spectra_mitsuba06_rgb(nm, v, 2), 0));
            CHECK(near3(lit->ke, spectra_mitsuba06_rgb(lnm, lv, 4), 0));
            CHECK(near3(s06->materials[s06->tris[2].material].ke, v3s(3.0f), 0));
        }
        pk_scene_destroy(s06);
    }
    load_fails("<shape type=\"cube\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"500:0.5\"/></bsdf></shape>", true,
               "at least two wavelength:value pairs");
    m = bsdf("<bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:0, 580:0, 600:1, 800:1\"/></bsdf>");
    CHECK(m.kd.x > 0.5f && m.kd.x > 4.0f * m.kd.y && m.kd.z < 0.05f);
    /* a blackbody: 3000 K is reddish, 10000 K bluish; 5455 K (the equal-energy white point) about grey */
    pk_scene *bb = load_ok("<shape type=\"cube\"><emitter type=\"area\"><blackbody name=\"radiance\" temperature=\"3000K\"/>"
                           "</emitter></shape><shape type=\"rectangle\"><emitter type=\"area\"><blackbody name=\"radiance\" "
                           "temperature=\"10000\"/></emitter></shape><shape type=\"disk\"><emitter type=\"area\">"
                           "<blackbody name=\"radiance\" temperature=\"5455\"/></emitter></shape>");
    if (bb) {
        vec3 warm = bb->materials[bb->tris[0].material].ke, cold = bb->materials[bb->tris[12].material].ke;
        vec3 white = bb->materials[bb->tris[14].material].ke;
        CHECK(warm.x > 1.5f * warm.z && cold.z > 1.2f * cold.x);
        /* <blackbody> is Mitsuba 0.x's, reduced by its rule in every version */
        CHECK(near3(white, spectra_mitsuba06_blackbody(5455.0f), 0));
        /* Planck at 5455 K and 555 nm: 2hc^2 / l^5 / (exp(hc / (l k T)) - 1) = 1.97e4 W m^-2 sr^-1 nm^-1;
         * the equal-energy white it nearly is has sRGB green 0.95 */
        CHECKF(white.y > 0.95f * 1.77e4f && white.y < 0.95f * 2.17e4f, "%g", (double)white.y);
    }
    pk_scene_destroy(bb);
    m = bsdf("<bsdf type=\"roughdiffuse\"><rgb name=\"reflectance\" value=\"0.2\"/></bsdf>");
    CHECK(m.type == MAT_ROUGH_DIFFUSE && near3(m.kd, v3s(0.2f), 1e-6f) && m.alpha == 0.2f && wl.count == 0);
    m = bsdf("<bsdf type=\"roughdiffuse\"><float name=\"alpha\" value=\"0.7\"/>"
             "<boolean name=\"useFastApprox\" value=\"true\"/></bsdf>");
    CHECK(m.type == MAT_ROUGH_DIFFUSE && near3(m.kd, v3s(0.5f), 0) && fabsf(m.alpha - 0.7f) < 1e-7f && wl.count == 0);
    /* phong: Mitsuba's defaults (0.5, 0.2, 30), and kd + ks above 1 scaled down */
    m = bsdf("<bsdf type=\"phong\"/>");
    CHECK(m.type == MAT_PHONG && near3(m.kd, v3s(0.5f), 0) && near3(m.ks, v3s(0.2f), 0) && m.ns == 30.0f &&
          m.illum == 2 && wl.count == 0);
    m = bsdf("<bsdf type=\"phong\"><rgb name=\"diffuseReflectance\" value=\"0.9\"/>"
             "<rgb name=\"specularReflectance\" value=\"0.3\"/><float name=\"exponent\" value=\"5\"/></bsdf>");
    CHECK(m.type == MAT_PHONG && near3(m.kd, v3s(0.75f), 1e-6f) && near3(m.ks, v3s(0.25f), 1e-6f) && m.ns == 5.0f);
    m = bsdf("<bsdf type=\"conductor\"><string name=\"material\" value=\"Au\"/></bsdf>");
    CHECK(m.type == MAT_CONDUCTOR && !m.schlick && m.alpha == 0.0f);
    CHECK(m.eta.x < 0.2f && m.k.x > 3.9f && m.k.z < 1.7f); /* gold: red reflects most */
    m = bsdf("<bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"0.3\"/><string name=\"distribution\" "
             "value=\"beckmann\"/><rgb name=\"eta\" value=\"1.5 1 0.5\"/><rgb name=\"k\" value=\"9 6 4\"/></bsdf>");
    CHECK(m.type == MAT_CONDUCTOR && !m.schlick && fabsf(m.alpha - 0.3f) < 1e-6f && m.beckmann);
    CHECK(near3(m.eta, v3(1.5f / 1.000277f, 1.0f / 1.000277f, 0.5f / 1.000277f), 1e-5f));
    /* the distribution: beckmann by default (as in Mitsuba), ggx when named,
     * phong as beckmann (warned), for the conductor, dielectric and plastic */
    m = bsdf("<bsdf type=\"roughconductor\"/>");
    CHECK(m.beckmann && wl.count == 0);
    m = bsdf("<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/></bsdf>");
    CHECK(!m.beckmann);
    m = bsdf("<bsdf type=\"roughdielectric\"/>");
    CHECK(m.type == MAT_DIELECTRIC && m.beckmann);
    m = bsdf("<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/></bsdf>");
    CHECK(m.type == MAT_DIELECTRIC && !m.beckmann);
    m = bsdf("<bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"phong\"/></bsdf>");
    CHECK(m.type == MAT_PLASTIC && m.beckmann && warned("scene.xml:3: the phong distribution is rendered as Beckmann"));
    m = bsdf("<bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"as\"/></bsdf>");
    CHECK(m.beckmann && warned("microfacet distribution \"as\" is unknown; using beckmann"));
    m = bsdf("<bsdf type=\"roughconductor\"><string name=\"material\" value=\"none\"/><rgb name=\"specular_reflectance\" value=\"0.5\"/></bsdf>");
    CHECK(m.type == MAT_CONDUCTOR && m.schlick && near3(m.ks, v3s(1.0f), 1e-6f) && near3(m.tint, v3s(0.5f), 1e-6f) &&
          fabsf(m.alpha - 0.1f) < 1e-6f);
    /* a specular_reflectance multiplies the exact Fresnel term at every angle
     * (as Mitsuba does), not a Schlick F0; the Whitted mirror is F0 times it */
    m = bsdf("<bsdf type=\"conductor\"><rgb name=\"eta\" value=\"1 1 1\"/><rgb name=\"k\" value=\"2 2 2\"/>"
             "<float name=\"extEta\" value=\"1\"/><spectrum name=\"specularReflectance\" value=\"0.5\"/></bsdf>");
    CHECK(!m.schlick && near3(m.eta, v3s(1.0f), 1e-6f) && near3(m.k, v3s(2.0f), 1e-6f) &&
          near3(m.tint, v3s(0.5f), 1e-6f) && near3(m.ks, v3s(0.5f * 4.0f / 8.0f), 1e-3f));
    m = bsdf("<bsdf type=\"conductor\"><string name=\"material\" value=\"Xx\"/></bsdf>");
    CHECK(m.type == MAT_CONDUCTOR && warned("scene.xml:3: conductor material \"Xx\" is not in the table"));
    m = bsdf("<bsdf type=\"dielectric\"><float name=\"int_ior\" value=\"1.5\"/><float name=\"ext_ior\" value=\"1.2\"/></bsdf>");
    CHECK(m.type == MAT_DIELECTRIC && fabsf(m.ni - 1.25f) < 1e-6f && m.alpha == 0.0f);
    m = bsdf("<bsdf type=\"roughdielectric\"><string name=\"intIOR\" value=\"water\"/><string name=\"extIOR\" value=\"vacuum\"/>"
             "<float name=\"alpha\" value=\"0.2\"/><rgb name=\"specular_transmittance\" value=\"0.9 0.8 0.7\"/></bsdf>");
    CHECK(m.type == MAT_DIELECTRIC && fabsf(m.ni - 1.333f) < 1e-6f && fabsf(m.alpha - 0.2f) < 1e-6f);
    CHECK(near3(m.tf, v3(0.9f, 0.8f, 0.7f), 1e-6f));
    /* blendbsdf and mixturebsdf: mixes chosen per hit (the second with
     * probability weight); mixturebsdf by a chain of two-way mixes, weights
     * short of 1 leaving the rest to a black material */
    {
        pk_scene *bs = load_ok("<shape type=\"rectangle\"><bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.25\"/>"
                               "<bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/></bsdf></shape>");
        if (bs) {
            const material *mx = &bs->materials[bs->tris[0].material];
            CHECK(mx->type == MAT_MIX && mx->amount == 0.25f && wl.count == 0);
            CHECK(bs->materials[mx->mix_a].type == MAT_DIFFUSE && bs->materials[mx->mix_b].type == MAT_CONDUCTOR);
        }
        pk_scene_destroy(bs);
        bs = load_ok("<shape type=\"rectangle\"><bsdf type=\"mixturebsdf\"><string name=\"weights\" value=\"0.2, 0.3 0.25\"/>"
                     "<bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/><bsdf type=\"plastic\"/></bsdf></shape>");
        if (bs) {
            /* 0.2 diffuse, 0.3 conductor, 0.25 plastic, 0.25 black */
            const material *m0 = &bs->materials[bs->tris[0].material];
            CHECK(m0->type == MAT_MIX && fabsf(m0->amount - 0.8f) < 1e-6f && wl.count == 0);
            CHECK(bs->materials[m0->mix_a].type == MAT_DIFFUSE);
            const material *m1 = &bs->materials[m0->mix_b];
            CHECK(m1->type == MAT_MIX && fabsf(m1->amount - 0.5f / 0.8f) < 1e-6f &&
                  bs->materials[m1->mix_a].type == MAT_CONDUCTOR);
            const material *m2 = &bs->materials[m1->mix_b];
            CHECK(m2->type == MAT_MIX && fabsf(m2->amount - 0.5f) < 1e-6f && bs->materials[m2->mix_a].type == MAT_PLASTIC &&
                  bs->materials[m2->mix_b].type == MAT_DIFFUSE && near3(bs->materials[m2->mix_b].kd, v3s(0.0f), 0));
        }
        pk_scene_destroy(bs);
        m = bsdf("<bsdf type=\"mask\"><bsdf type=\"blendbsdf\"><bsdf type=\"plastic\"/><bsdf type=\"diffuse\"/></bsdf></bsdf>");
        CHECK(m.type == MAT_MIX && m.d == 1.0f && warned("bsdf \"mask\" over a mix of bsdfs is not supported"));
        m = bsdf("<bsdf type=\"blendbsdf\"><bsdf type=\"plastic\"/></bsdf>");
        CHECK(m.type == MAT_PLASTIC && warned("scene.xml:3: bsdf \"blendbsdf\" needs two nested bsdfs, not 1"));
        load_fails("<shape type=\"rectangle\"><bsdf type=\"mixturebsdf\"><string name=\"weights\" value=\"0.5\"/>"
                   "<bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf></shape>",
                   true, "needs as many weights (1) as nested bsdfs (2)");
    }
    m = bsdf("<bsdf type=\"thindielectric\"/>");
    CHECK(m.type == MAT_THIN_DIELECTRIC && fabsf(m.eta.x - 1.5046f / 1.000277f) < 1e-5f && wl.count == 0);
    /* the Whitted integrator's clear sheet: glass of index 1 */
    CHECK(m.ni == 1.0f && m.illum == 7);
    m = bsdf("<bsdf type=\"thindielectric\"><float name=\"intIOR\" value=\"1.33\"/><float name=\"extIOR\" value=\"1\"/>"
             "<rgb name=\"specularTransmittance\" value=\"0.5 0.6 0.7\"/></bsdf>");
    CHECK(m.type == MAT_THIN_DIELECTRIC && m.eta.x == 1.33f && near3(m.tf, v3(0.5f, 0.6f, 0.7f), 1e-6f));
    m = bsdf("<bsdf type=\"roughplastic\"><rgb name=\"diffuseReflectance\" value=\"0.1 0.2 0.3\"/>"
             "<float name=\"alpha\" value=\"0.05\"/><boolean name=\"nonlinear\" value=\"true\"/></bsdf>");
    CHECK(m.type == MAT_PLASTIC && near3(m.kd, v3(0.1f, 0.2f, 0.3f), 1e-6f) && fabsf(m.ni - 1.49f / 1.000277f) < 1e-5f);
    CHECK(fabsf(m.alpha - 0.05f) < 1e-6f && wl.count == 0);
    m = bsdf("<bsdf type=\"plastic\"/>");
    CHECK(m.type == MAT_PLASTIC && m.alpha == 0.0f && near3(m.kd, v3s(0.5f), 0));
    m = bsdf("<bsdf type=\"mask\"><float name=\"opacity\" value=\"0.25\"/><bsdf type=\"diffuse\"/></bsdf>");
    CHECK(m.type == MAT_DIFFUSE && fabsf(m.d - 0.25f) < 1e-6f);
    m = bsdf("<bsdf type=\"bumpmap\"><texture type=\"bitmap\"><string name=\"filename\" value=\"b.png\"/></texture>"
             "<bsdf type=\"plastic\"/></bsdf>");
    CHECK(m.type == MAT_PLASTIC && m.map_bump.kind == TEX_NONE && warned("texture not used ("));
    m = bsdf("<bsdf type=\"bumpmap\"><texture type=\"checkerboard\"/><bsdf type=\"plastic\"/></bsdf>");
    CHECK(m.type == MAT_PLASTIC && m.map_bump.kind == TEX_NONE &&
          warned("scene.xml:3: bsdf \"bumpmap\": only a bitmap height (scaled or not) bends the normal"));
    m = bsdf("<bsdf type=\"principled\"><rgb name=\"base_color\" value=\"0.9 0.6 0.2\"/><float name=\"metallic\" value=\"1\"/>"
             "<float name=\"roughness\" value=\"0.2\"/><float name=\"sheen\" value=\"0.3\"/></bsdf>");
    CHECK(m.type == MAT_PRINCIPLED && near3(m.kd, v3(0.9f, 0.6f, 0.2f), 1e-6f) && m.metallic == 1.0f &&
          fabsf(m.roughness - 0.2f) < 1e-6f && fabsf(m.alpha - 0.04f) < 1e-6f && fabsf(m.sheen - 0.3f) < 1e-6f);
    CHECK(!warned("principled is approximated"));
    /* the defaults: base colour 0.5, roughness 0.5, specular 0.5 (eta = 2 / (1 - sqrt(0.04)) - 1 = 1.5) */
    m = bsdf("<bsdf type=\"principled\"><rgb name=\"base_color\" value=\"0.1 0.2 0.3\"/></bsdf>");
    CHECK(m.type == MAT_PRINCIPLED && near3(m.kd, v3(0.1f, 0.2f, 0.3f), 1e-6f) && fabsf(m.alpha - 0.25f) < 1e-6f &&
          fabsf(m.ni - 1.5f) < 1e-5f && m.transmission == 0.0f && m.srate_spec == 1.0f);
    /* eta and specular together: eta wins, with a warning; anisotropic: Mitsuba's ax, ay (no warning) */
    m = bsdf("<bsdf type=\"principled\"><float name=\"eta\" value=\"1.33\"/><float name=\"specular\" value=\"0.2\"/>"
             "<float name=\"anisotropic\" value=\"0.5\"/><float name=\"roughness\" value=\"0.6\"/>"
             "<float name=\"spec_trans\" value=\"0.7\"/><float name=\"clearcoat_sampling_rate\" value=\"2\"/></bsdf>");
    CHECK(m.type == MAT_PRINCIPLED && fabsf(m.ni - 1.33f) < 1e-6f && warned("eta or specular, not both") &&
          !warned("anisotropic") && material_anisotropic(&m) && fabsf(m.transmission - 0.7f) < 1e-6f &&
          fabsf(m.ax - 0.36f / sqrtf(0.55f)) < 1e-5f && fabsf(m.ay - 0.36f * sqrtf(0.55f)) < 1e-5f &&
          m.srate_cc == 2.0f);
    m = bsdf("<bsdf type=\"principled\"><float name=\"metallic\" value=\"1.5\"/></bsdf>");
    CHECK(m.type == MAT_PRINCIPLED && m.metallic == 1.0f && warned("scene.xml:3: metallic must be in [0, 1], not 1.5"));
    /* principledthin: its own lobes (thin), diff_trans halved, its four rates */
    m = bsdf("<bsdf type=\"principledthin\"><rgb name=\"base_color\" value=\"0.1 0.2 0.3\"/>"
             "<float name=\"diff_trans\" value=\"0.6\"/><float name=\"spec_trans\" value=\"0.4\"/>"
             "<float name=\"eta\" value=\"1.33\"/><float name=\"specular_transmittance_sampling_rate\" value=\"3\"/></bsdf>");
    CHECK(m.type == MAT_PRINCIPLED && m.thin && near3(m.kd, v3(0.1f, 0.2f, 0.3f), 1e-6f) && fabsf(m.diff_trans - 0.3f) < 1e-6f &&
          fabsf(m.transmission - 0.4f) < 1e-6f && m.ni == 1.33f && m.srate_st == 3.0f && m.srate_dt == 1.0f &&
          !warned("principledthin"));
    m = bsdf("<bsdf type=\"principledthin\"><float name=\"diff_trans\" value=\"2.5\"/><float name=\"metallic\" value=\"1\"/></bsdf>");
    CHECK(m.type == MAT_PRINCIPLED && m.thin && m.diff_trans == 1.0f && warned("scene.xml:3: diff_trans must be in [0, 2], not 2.5") &&
          warned("metallic"));
    m = bsdf("<bsdf type=\"coating\"><float name=\"intIOR\" value=\"1.2\"/><bsdf type=\"diffuse\"><rgb name=\"reflectance\" "
             "value=\"0.3 0.4 0.5\"/></bsdf></bsdf>");
    CHECK(m.type == MAT_PLASTIC && near3(m.kd, v3(0.3f, 0.4f, 0.5f), 1e-6f) && fabsf(m.ni - 1.2f / 1.000277f) < 1e-5f);
    CHECK(m.alpha == 0.0f && wl.count == 0);
    m = bsdf("<bsdf type=\"roughcoating\"><float name=\"thickness\" value=\"2\"/><bsdf type=\"conductor\"/></bsdf>");
    CHECK(m.type == MAT_CONDUCTOR && warned("roughcoating\" over a non-diffuse bsdf"));
    m = bsdf("<bsdf type=\"hanrahan_krueger\"/>");
    CHECK(m.type == MAT_DIFFUSE && warned("scene.xml:3: bsdf \"hanrahan_krueger\" is not supported"));
    /* textures: a diffuse reflectance takes a bitmap (its value times kd = 1)
     * or a checkerboard; a missing file or another property gives a warning
     * and a constant colour */
    m = bsdf("<bsdf type=\"diffuse\">\n<texture name=\"reflectance\" type=\"bitmap\"><string name=\"filename\" value=\"t.jpg\"/>"
             "</texture></bsdf>");
    CHECK(near3(m.kd, v3s(0.5f), 0) && m.map_kd.kind == TEX_NONE && warned("scene.xml:4: texture not used (") &&
          warned("t.jpg: cannot open") && warned("using the constant 0.5 0.5 0.5 for reflectance"));
    {
        char path[512];
        snprintf(path, sizeof path, "%s/t.pfm", tmpdir);
        FILE *f = fopen(path, "wb");
        REQUIRE(f);
        const float px[6] = {0.25f, 0.5f, 1, 1, 1, 1};
        fprintf(f, "PF\n2 1\n-1.0\n");
        REQUIRE(fwrite(px, sizeof px, 1, f) == 1);
        fclose(f);
    }
    m = bsdf("<bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"bitmap\"><string name=\"filename\" value=\"t.pfm\"/>"
             "<float name=\"uscale\" value=\"4\"/></texture></bsdf>");
    CHECK(near3(m.kd, v3s(1.0f), 0) && m.map_kd.kind == TEX_IMAGE && m.map_kd.s[0] == 4.0f && m.map_kd.s[1] == 1.0f &&
          wl.count == 0);
    /* bump maps: Mitsuba 0.x's bump with a scaled bitmap, Mitsuba 3's bumpmap with its scale */
    m = bsdf("<bsdf type=\"bump\"><texture type=\"scale\"><float name=\"scale\" value=\"0.5\"/><texture type=\"scale\">"
             "<float name=\"scale\" value=\"4\"/><texture type=\"bitmap\"><string name=\"filename\" value=\"t.pfm\"/>"
             "<float name=\"uscale\" value=\"3\"/></texture></texture></texture><bsdf type=\"roughconductor\"/></bsdf>");
    CHECK(m.type == MAT_CONDUCTOR && m.beckmann && m.map_bump.kind == TEX_IMAGE && m.map_bump.bm == 2.0f &&
          m.map_bump.s[0] == 3.0f && wl.count == 0);
    m = bsdf("<bsdf type=\"bumpmap\"><float name=\"scale\" value=\"0.25\"/><texture type=\"bitmap\">"
             "<string name=\"filename\" value=\"t.pfm\"/></texture><bsdf type=\"diffuse\"/></bsdf>");
    CHECK(m.type == MAT_DIFFUSE && m.map_bump.kind == TEX_IMAGE && m.map_bump.bm == 0.25f && wl.count == 0);
    /* normal maps: the bitmap (raw, as normal maps are given) becomes the nested bsdf's map_norm */
    m = bsdf("<bsdf type=\"normalmap\"><texture name=\"normalmap\" type=\"bitmap\"><boolean name=\"raw\" value=\"true\"/>"
             "<string name=\"filename\" value=\"t.pfm\"/></texture><bsdf type=\"roughplastic\"/></bsdf>");
    CHECK(m.type == MAT_PLASTIC && m.map_norm.kind == TEX_IMAGE && m.map_bump.kind == TEX_NONE && wl.count == 0);
    m = bsdf("<bsdf type=\"normalmap\"><texture type=\"checkerboard\"/><bsdf type=\"diffuse\"/></bsdf>");
    CHECK(m.type == MAT_DIFFUSE && m.map_norm.kind == TEX_NONE &&
          warned("bsdf \"normalmap\": only a bitmap of normals is supported; using its nested bsdf alone"));
    m = bsdf("<bsdf type=\"roughplastic\"><texture name=\"diffuse_reflectance\" type=\"bitmap\"><string name=\"filename\" "
             "value=\"t.pfm\"/></texture></bsdf>");
    CHECK(m.type == MAT_PLASTIC && near3(m.kd, v3s(1.0f), 0) && m.map_kd.kind == TEX_IMAGE);
    m = bsdf("<bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"checkerboard\"><rgb name=\"color0\" value=\"0.8\"/>"
             "<rgb name=\"color1\" value=\"0.2 0.4 0.6\"/></texture></bsdf>");
    CHECK(near3(m.kd, v3s(1.0f), 0) && m.map_kd.kind == TEX_CHECKER && near3(m.map_kd.even, v3s(0.8f), 1e-6f) &&
          near3(m.map_kd.odd, v3(0.2f, 0.4f, 0.6f), 1e-6f) && m.map_kd.checker_scale == 2.0f);
    m = bsdf("<bsdf type=\"roughconductor\">\n<texture name=\"specular_reflectance\" type=\"checkerboard\"/></bsdf>");
    CHECK(m.map_kd.kind == TEX_NONE && warned("scene.xml:4: a texture for specular_reflectance is not supported; using the constant"));
    /* a texture on a rough bsdf's alpha is the roughness at each hit (alpha 1 times the texture's value), on
     * the conductor, dielectric and plastic; alpha_u and alpha_v win over it, as in Mitsuba */
    static const char *const rough[] = {"roughconductor", "roughdielectric", "roughplastic"};
    for (int i = 0; i < 3; i++) {
        char x[400];
        snprintf(x, sizeof x,
                 "<bsdf type=\"%s\"><texture name=\"alpha\" type=\"checkerboard\"><rgb name=\"color0\" "
                 "value=\"0.05\"/><rgb name=\"color1\" value=\"0.4\"/></texture></bsdf>",
                 rough[i]);
        m = bsdf(x);
        CHECKF(m.alpha == 1.0f && m.map_alpha.kind == TEX_CHECKER && fabsf(m.map_alpha.even.x - 0.05f) < 1e-7f &&
                   fabsf(m.map_alpha.odd.x - 0.4f) < 1e-7f && !m.map_alpha.squared && wl.count == 0,
               "%s: alpha %g, texture kind %d, %d warnings", rough[i], (double)m.alpha, (int)m.map_alpha.kind, wl.count);
    }
    m = bsdf("<bsdf type=\"roughconductor\"><texture name=\"alpha\" type=\"checkerboard\"/>"
             "<float name=\"alpha_u\" value=\"0.2\"/><float name=\"alpha_v\" value=\"0.3\"/></bsdf>");
    CHECK(m.map_alpha.kind == TEX_NONE && fabsf(m.alpha - 0.2f) < 1e-6f && fabsf(m.alpha_v - 0.3f) < 1e-6f);
    /* unknown properties: a warning naming the bsdf and the property */
    m = bsdf("<bsdf type=\"diffuse\"><float name=\"sheen\" value=\"1\"/></bsdf>");
    CHECK(warned("scene.xml:3: bsdf \"diffuse\": property \"sheen\" is not supported; ignored"));
}

/* ---- emitters ------------------------------------------------------------------------ */

static void test_emitters(void)
{
    pk_scene *s = load_ok("<bsdf type=\"diffuse\" id=\"w\"/>\n<shape type=\"rectangle\"><ref id=\"w\"/></shape>\n"
                          "<shape type=\"rectangle\"><ref id=\"w\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"1 2 3\"/>"
                          "</emitter></shape>");
    if (s) {
        const material *plain = &s->materials[s->tris[0].material], *lit = &s->materials[s->tris[2].material];
        CHECK(near3(plain->ke, v3s(0), 0) && near3(lit->ke, v3(1, 2, 3), 0));
        CHECK(!lit->two_sided && near3(lit->kd, v3s(0.5f), 0));
        CHECK(s->nemissive == 2);
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"/><emitter type=\"point\"><point name=\"position\" x=\"1\" y=\"2\" z=\"3\"/>"
                "<spectrum name=\"intensity\" value=\"5\"/></emitter>"
                "<emitter type=\"point\"><transform name=\"toWorld\"><translate x=\"-1\"/></transform></emitter>");
    if (s) {
        CHECK(s->nlights == 2);
        /* a uniform emitter spectrum in Mitsuba 3: 5 times the sRGB of XYZ (1, 1, 1) */
        CHECK(near3(s->lights[0].position, v3(1, 2, 3), 0) &&
              near3(s->lights[0].intensity, spectra_mitsuba3_uniform_emitter(5.0f), 0));
        CHECK(near3(s->lights[1].position, v3(-1, 0, 0), 0) && near3(s->lights[1].intensity, v3s(1), 0));
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"/><emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.5 0.25 1\"/></emitter>");
    CHECK(s && s->env.set && near3(s->env.radiance, v3(0.5f, 0.25f, 1.0f), 0));
    pk_scene_destroy(s);
    {
        /* a 2 x 1 PFM map */
        char path[512];
        snprintf(path, sizeof path, "%s/sky.pfm", tmpdir);
        FILE *f = fopen(path, "wb");
        REQUIRE(f);
        const float px[6] = {1, 1, 1, 2, 2, 2};
        fprintf(f, "PF\n2 1\n-1.0\n");
        REQUIRE(fwrite(px, sizeof px, 1, f) == 1);
        fclose(f);
    }
    load_fails("<shape type=\"cube\"/>\n<emitter type=\"envmap\"><string name=\"filename\" value=\"nowhere.exr\"/></emitter>",
               true, "scene.xml:3: envmap: ");
    s = load_ok("<shape type=\"cube\"/><emitter type=\"envmap\"><string name=\"filename\" value=\"sky.pfm\"/>"
                "<float name=\"scale\" value=\"2\"/><transform name=\"to_world\"><rotate y=\"1\" angle=\"90\"/></transform></emitter>");
    if (s) {
        char want[512];
        snprintf(want, sizeof want, "%s/sky.pfm", tmpdir);
        CHECK(s->env.set && s->env.map && strcmp(s->env.map, want) == 0);
        CHECK(s->env.map_scale == 2.0f && s->env.map_w == 2 && s->env.map_h == 1 && s->env.map_rgb[3] == 2.0f);
        /* a rotation of 90 degrees about y takes x to -z */
        CHECK(fabsf(s->env.to_world[0]) < 1e-6f && fabsf(s->env.to_world[6] + 1.0f) < 1e-6f);
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"/><emitter type=\"sunsky\"><float name=\"turbidity\" value=\"4\"/>"
                "<vector name=\"sunDirection\" x=\"0\" y=\"1\" z=\"1\"/><float name=\"skyScale\" value=\"6\"/>"
                "<float name=\"sunRadiusScale\" value=\"2\"/></emitter>");
    if (s) {
        const scene_environment *e = &s->env;
        CHECK(e->set && e->has_sun && e->has_sky && e->sky_turbidity == 4.0f && e->sky_scale == 6.0f);
        /* the Hosek-Wilkie sky with Mitsuba's default ground albedo */
        CHECK(e->sky_hosek && near3(e->sky_albedo, v3s(0.2f), 0));
        CHECK(near3(e->sun_dir, v3(0, 0.70710678f, 0.70710678f), 1e-6f));
        CHECK(fabsf(e->sun_angle - 2.0f * 0.5358f) < 1e-5f);
        /* the sun through the air: reddened, in Mitsuba's units (about 1e4) */
        CHECK(e->sun_radiance.x > e->sun_radiance.z && e->sun_radiance.y > 1e3f && e->sun_radiance.y < 1e4f);
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"/><emitter type=\"directional\"><vector name=\"direction\" x=\"0\" y=\"-1\" z=\"0\"/>"
                "<rgb name=\"irradiance\" value=\"2\"/></emitter>");
    if (s) {
        /* a distant light: the direction toward it, its irradiance */
        CHECK(!s->env.has_sun && s->nlights == 1 && s->lights[0].distant);
        CHECK(near3(s->lights[0].position, v3(0, 1, 0), 1e-6f) && near3(s->lights[0].intensity, v3(2, 2, 2), 0.0f));
    }
    pk_scene_destroy(s);
    s = load_ok("<shape type=\"cube\"/>\n<emitter type=\"spot\"/>\n<emitter type=\"collimated\"/>");
    /* Mitsuba's defaults: along +z, cutoff 20 degrees, beam width 3/4 of it, linear in the angle */
    CHECK(s && s->nlights == 1 && near3(s->lights[0].spot_dir, v3(0, 0, 1), 1e-6f) &&
          fabs(acos((double)s->lights[0].cos_outer) * 180.0 / M_PI - 20.0) < 1e-4 &&
          fabs(acos((double)s->lights[0].cos_inner) * 180.0 / M_PI - 15.0) < 1e-4 &&
          s->lights[0].spot_falloff == SPOT_FALLOFF_ANGLE && !warned("scene.xml:3") &&
          warned("scene.xml:4: emitter \"collimated\" is not supported; ignored"));
    pk_scene_destroy(s);
}

/* ---- sensor and settings ------------------------------------------------------------------ */

static pk_scene *load_json(const char *json)
{
    pk_scene *s = NULL;
    pk_context_clear_error(ctx);
    CHECKF(pk_scene_load_json_memory(ctx, json, strlen(json), "s.json", ".", &s) == PK_OK, "%s", pk_context_error(ctx));
    return s;
}

static void test_sensor(void)
{
    /* a lookat camera with its fov along y is the JSON camera of the same numbers */
    pk_scene *x = load_ok("<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/><string name=\"fov_axis\" value=\"y\"/>"
                          "<transform name=\"to_world\"><lookat origin=\"1 2 3\" target=\"1 2 -1\" up=\"0 1 0\"/></transform>"
                          "<film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/><integer name=\"height\" value=\"100\"/>"
                          "<rfilter type=\"tent\"/></film><sampler type=\"independent\"><integer name=\"sample_count\" value=\"16\"/>"
                          "</sampler></sensor><shape type=\"cube\"/>");
    pk_scene *j = load_json("{\"camera\": {\"look_from\": [1, 2, 3], \"look_at\": [1, 2, -1], \"up\": [0, 1, 0], \"fov\": 30},"
                            " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}");
    if (x && j) {
        pk_camera a, b;
        pk_scene_get_camera(x, &a);
        pk_scene_get_camera(j, &b);
        vec3 da = v3_norm(v3(a.look_at[0] - a.look_from[0], a.look_at[1] - a.look_from[1], a.look_at[2] - a.look_from[2]));
        vec3 db = v3_norm(v3(b.look_at[0] - b.look_from[0], b.look_at[1] - b.look_from[1], b.look_at[2] - b.look_from[2]));
        CHECK(near3(v3(a.look_from[0], a.look_from[1], a.look_from[2]), v3(b.look_from[0], b.look_from[1], b.look_from[2]), 1e-6f));
        CHECK(near3(da, db, 1e-6f));
        CHECK(near3(v3(a.up[0], a.up[1], a.up[2]), v3(0, 1, 0), 1e-6f));
        CHECK_NEAR(a.fov_deg, b.fov_deg, 1e-4);
        pk_render_options o;
        pk_scene_get_render_options(x, &o);
        CHECK(o.width == 200 && o.height == 100 && o.spp == 16);
    }
    pk_scene_destroy(x);
    pk_scene_destroy(j);
    /* fov along x (the default), diagonal, smaller, larger on a 200 x 100 film */
    const char *axes[] = {"x", "diagonal", "smaller", "larger"};
    const double tan_y[] = {tan(M_PI / 6) * 0.5, tan(M_PI / 6) * 100.0 / sqrt(50000.0), tan(M_PI / 6), tan(M_PI / 6) * 0.5};
    for (int i = 0; i < 4; i++) {
        char xml[1024];
        snprintf(xml, sizeof xml,
                 "<sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/><string name=\"fovAxis\" value=\"%s\"/>"
                 "<film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/><integer name=\"height\" value=\"100\"/></film>"
                 "</sensor><shape type=\"cube\"/>", axes[i]);
        pk_scene *s = load_ok(xml);
        if (!s) continue;
        CHECKF(fabs((double)s->camera.fov_deg - 2.0 * atan(tan_y[i]) * 180.0 / M_PI) < 1e-4, "fov_axis %s: %g", axes[i],
               (double)s->camera.fov_deg);
        pk_scene_destroy(s);
    }
    /* integrator depth: Mitsuba counts segments, Paprsek bounces */
    const char *depths[] = {"<integer name=\"max_depth\" value=\"3\"/>", "<integer name=\"maxDepth\" value=\"-1\"/>", "",
                            "<integer name=\"max_depth\" value=\"2000\"/>"};
    const int want[] = {2, PK_MAX_DEPTH, PK_MAX_DEPTH, PK_MAX_DEPTH};
    for (int i = 0; i < 4; i++) {
        char xml[512];
        snprintf(xml, sizeof xml, "<integrator type=\"path\">%s</integrator><shape type=\"cube\"/>", depths[i]);
        pk_scene *s = load_ok(xml);
        if (!s) continue;
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        CHECKF(o.max_depth == want[i], "%s: %d", depths[i], o.max_depth);
        pk_scene_destroy(s);
    }
    pk_scene *s = load_ok("<integrator type=\"bdpt\"/><shape type=\"cube\"/>");
    CHECK(s && warned("scene.xml:2: integrator \"bdpt\" is not supported; rendered with the path tracer"));
    pk_scene_destroy(s);
    load_fails("<sensor type=\"perspective\">\n<film type=\"hdrfilm\"><integer name=\"width\" value=\"100000\"/></film></sensor>",
               true, "scene.xml:3: film: width and height must be in 1..16384");
}

/* A camera looking down -z (Mitsuba's lookat) sees a red wall at x = -1 on
 * the left of the image and a green one at x = +1 on the right, as in the
 * Cornell box. */
static void test_handedness(void)
{
    const char *xml =
        "<sensor type=\"perspective\"><float name=\"fov\" value=\"90\"/><transform name=\"to_world\">"
        "<lookat origin=\"0 0 3\" target=\"0 0 0\" up=\"0 1 0\"/></transform>"
        "<film type=\"hdrfilm\"><integer name=\"width\" value=\"16\"/><integer name=\"height\" value=\"16\"/></film></sensor>"
        "<shape type=\"rectangle\"><transform name=\"to_world\"><translate x=\"-1\"/></transform>"
        "<bsdf type=\"diffuse\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"1 0 0\"/></emitter></shape>"
        "<shape type=\"rectangle\"><transform name=\"to_world\"><translate x=\"1\"/></transform>"
        "<bsdf type=\"diffuse\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"0 1 0\"/></emitter></shape>";
    pk_scene *s = load_ok(xml);
    if (!s) return;
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.spp = 1;
    o.threads = 1;
    pk_image *img = NULL;
    CHECKF(pk_render(ctx, s, &o, &img, NULL) == PK_OK, "%s", pk_context_error(ctx));
    if (img) {
        const float *px = pk_image_pixels_const(img);
        const float *left = px + 3 * (8 * 16 + 4), *right = px + 3 * (8 * 16 + 11);
        CHECKF(left[0] > 0.5f && left[1] == 0.0f, "left %g %g", (double)left[0], (double)left[1]);
        CHECKF(right[1] > 0.5f && right[0] == 0.0f, "right %g %g", (double)right[0], (double)right[1]);
    }
    pk_image_destroy(img);
    pk_scene_destroy(s);
}

/* ---- malformed input ----------------------------------------------------------------------- */

static void test_errors(void)
{
    load_fails("<scene version=\"3.0.0\">\n<shape type=\"cube\">\n</scene>", false, "scene.xml:3: malformed XML: mismatched tag");
    load_fails("<scene version=\"3.0.0\">\n<shape type=\"cube\"/>\n", false, "scene.xml:3: malformed XML: no element found");
    load_fails("", false, "malformed XML");
    load_fails("<scene>\n<shape type=\"cube\"", false, "scene.xml:2: malformed XML");
    load_fails("<?xml version=\"1.0\"?>\n<root/>", false, "scene.xml:2: the document element is <root>, expected <scene>");
    load_fails("<!DOCTYPE scene [<!ENTITY a \"aaaa\">]>\n<scene/>", false, "document type declarations");
    load_fails("<shape type=\"sphere\">\n<float name=\"radius\" value=\"abc\"/></shape>", true,
               "scene.xml:3: float: bad number in \"abc\"");
    load_fails("<shape type=\"sphere\">\n<float name=\"radius\" value=\"1e999\"/></shape>", true,
               "scene.xml:3: float: numbers must be finite");
    load_fails("<shape type=\"sphere\">\n<float name=\"radius\" value=\"-1\"/></shape>", true,
               "scene.xml:2: sphere: radius must be positive");
    load_fails("<shape type=\"sphere\">\n<point name=\"radius\" x=\"1\"/></shape>", true,
               "scene.xml:3: radius must be a <float>, found <point>");
    load_fails("<shape type=\"cube\"><bsdf type=\"diffuse\">\n<rgb name=\"reflectance\" value=\"1 2\"/></bsdf></shape>", true,
               "scene.xml:3: <rgb> needs 1 or 3 numbers");
    load_fails("<integrator type=\"path\">\n<integer name=\"max_depth\" value=\"2.5\"/></integrator>", true,
               "scene.xml:3: max_depth: \"2.5\" is not an integer");
    load_fails("<shape type=\"obj\"/>", true, "scene.xml:2: shape obj needs a filename");
    /* deep nesting is refused, not recursed */
    char deep[8192] = "<scene>";
    for (int i = 0; i < 100; i++) strcat(deep, "<a>");
    load_fails(deep, false, "nested more than 64 deep");
    /* unknown top-level elements: one warning each kind */
    pk_scene *s = load_ok("<shape type=\"cube\"/>\n<gizmo/>\n<gizmo/>");
    CHECK(s && wl.count == 1 && warned("scene.xml:3: <gizmo> is not supported; ignored"));
    pk_scene_destroy(s);
    /* a scene of nothing but a camera is empty */
    load_fails("<sensor type=\"perspective\"/>", true, "");
}

/* shapegroup and instance: the group's shapes become one mesh in the
 * group's space, each instance places it; the triangles come in file order,
 * an instance's where it stands in the file */
static bool tri_within(const pk_scene *s, size_t k, vec3 lo, vec3 hi)
{
    vec3 v[3];
    scene_tri_verts(s, k, &v[0], &v[1], &v[2]);
    for (int i = 0; i < 3; i++)
        if (v[i].x < lo.x || v[i].y < lo.y || v[i].z < lo.z || v[i].x > hi.x || v[i].y > hi.y || v[i].z > hi.z)
            return false;
    return true;
}

static void test_instances(void)
{
    pk_scene *s = load_ok("<shape type=\"rectangle\"/>\n"
                          "<shape type=\"shapegroup\" id=\"g\">\n"
                          "  <shape type=\"rectangle\">\n"
                          "    <transform name=\"to_world\"><scale value=\"2\"/></transform>\n"
                          "  </shape>\n"
                          "</shape>\n"
                          "<shape type=\"instance\"><ref id=\"g\"/>\n"
                          "  <transform name=\"to_world\"><translate x=\"10\"/></transform>\n"
                          "</shape>\n"
                          "<shape type=\"instance\"><ref id=\"g\"/>\n"
                          "  <transform name=\"to_world\"><rotate z=\"1\" angle=\"90\"/><translate y=\"-10\"/></transform>\n"
                          "</shape>\n"
                          "<shape type=\"cube\"/>\n");
    if (s) {
        CHECK(s->nmeshes == 1 && s->ninstances == 2 && s->nflattened == 2);
        REQUIRE(s->ntris == 2 + 2 + 2 + 12);
        CHECK(tri_within(s, 0, v3(-1, -1, 0), v3(1, 1, 0)) && tri_within(s, 1, v3(-1, -1, 0), v3(1, 1, 0)));
        /* the first instance: the group's 4x4 square moved to x = 10 */
        for (size_t k = 2; k < 4; k++) CHECK(tri_within(s, k, v3(8, -2, 0), v3(12, 2, 0)));
        vec3 a, b, c;
        scene_tri_verts(s, 2, &a, &b, &c);
        CHECK(a.x == 8.0f && a.y == -2.0f && a.z == 0.0f); /* (-1,-1) scaled by 2, then moved */
        /* the second: turned about z (exactly a square again), then moved to y = -10 */
        for (size_t k = 4; k < 6; k++) CHECK(tri_within(s, k, v3(-2.0001f, -12.0001f, 0), v3(2.0001f, -7.9999f, 0)));
        for (size_t k = 6; k < 18; k++) CHECK(tri_within(s, k, v3s(-1), v3s(1)));
        CHECK_NEAR(total_area(s), 4.0 + 16.0 + 16.0 + 24.0, 1e-3);
        vec3 n;
        tri_area(s, 4, &n);
        CHECK(near3(n, v3(0, 0, 1), 1e-6f));
    }
    pk_scene_destroy(s);

    /* a group's sphere is tessellated (instances place meshes); an area
     * emitter in a group makes every instance emit; a group never
     * instanced adds nothing */
    s = load_ok("<shape type=\"shapegroup\" id=\"ball\">\n"
                "  <shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>\n"
                "</shape>\n"
                "<shape type=\"shapegroup\" id=\"unused\"><shape type=\"cube\"/></shape>\n"
                "<shape type=\"instance\"><ref id=\"ball\"/></shape>\n"
                "<shape type=\"instance\"><ref id=\"ball\"/>\n"
                "  <transform name=\"to_world\"><translate x=\"5\"/></transform></shape>\n");
    if (s) {
        size_t per = 2 * 64 * (32 - 1);
        CHECK(s->nspheres == 0);
        CHECK(s->ntris == 2 * per);
        CHECK(s->nemissive == 2 * per);
        CHECK(tri_within(s, per, v3(4, -1, -1), v3(6, 1, 1)));
    }
    pk_scene_destroy(s);

    load_fails("<shape type=\"shapegroup\"><shape type=\"cube\"/></shape>", true, "scene.xml:2: a shapegroup needs an id");
    load_fails("<shape type=\"instance\"><ref id=\"nothing\"/></shape>", true,
               "scene.xml:2: instance: no shapegroup \"nothing\" before it");
    load_fails("<bsdf type=\"diffuse\" id=\"d\"/>\n<shape type=\"instance\"><ref id=\"d\"/></shape>", true,
               "scene.xml:3: instance: \"d\" is not a shapegroup");
    load_fails("<shape type=\"instance\"/>", true, "scene.xml:2: an instance needs a <ref");
    load_fails("<shape type=\"shapegroup\" id=\"a\"><shape type=\"shapegroup\" id=\"b\"/></shape>", true,
               "scene.xml:2: a shapegroup inside a shapegroup");
    load_fails("<shape type=\"shapegroup\" id=\"a\"><shape type=\"cube\"/></shape>\n"
               "<shape type=\"instance\"><ref id=\"a\"/>"
               "<transform name=\"to_world\"><scale x=\"0\"/></transform></shape>",
               true, "scene.xml:3: instance: to_world is singular");
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s", "/tmp/pk_test_xml_XXXXXX");
    REQUIRE(mkdtemp(tmpdir));
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wl);
    test_transforms();
    test_defaults_refs();
    test_include();
    test_shapes();
    test_obj_ply();
    test_bsdfs();
    test_emitters();
    test_sensor();
    test_handedness();
    test_errors();
    test_instances();
    pk_context_destroy(ctx);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    return test_done("test_xml");
}

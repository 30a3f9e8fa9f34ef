/*
 * test_obj.c - the OBJ and MTL readers: every face index form, negative
 * indices, fan order, messy text (CRLF, tabs, comments, continuation),
 * warnings (unknown statements, missing MTL, undefined usemtl), the exact
 * text of each error, the float parser's rounding, allocation failures, the
 * shared Cornell boxes, the bunny and Sponza (with a load-time print).
 */
#include "io/io_util.h"
#include "io/readers.h"
#include "scene/scene.h"
#include "test.h"
#include "warnings.h"

#include <float.h>
#include <stdint.h>

/* ---- helpers ------------------------------------------------------------ */

typedef warning_log warnings;

static pk_context *new_ctx(warnings *w)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    if (w) warning_log_attach(ctx, w);
    return ctx;
}

static pk_scene *new_scene(pk_context *ctx)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "test", &s) == PK_OK);
    return s;
}

/* Parses text from an exact-size heap copy (no NUL after it), so that a read
 * past the end shows under AddressSanitizer. */
static pk_status parse_text(pk_context *ctx, pk_scene *s, const char *text, size_t len, const char *name,
                            const xform *xf)
{
    char *buf = malloc(len ? len : 1);
    REQUIRE(buf);
    memcpy(buf, text, len);
    pk_status st = obj_parse(ctx, s, buf, len, name, PK_TEST_DATA, xf);
    free(buf);
    return st;
}

static pk_status parse_str(pk_context *ctx, pk_scene *s, const char *text, const char *name)
{
    return parse_text(ctx, s, text, strlen(text), name, NULL);
}

static pk_status parse_file(pk_context *ctx, pk_scene *s, const char *dir, const char *file, const xform *xf)
{
    char path[1024];
    if (snprintf(path, sizeof path, "%s/%s", dir, file) >= (int)sizeof path) return PK_ERR_INVALID_ARGUMENT;
    char *data;
    size_t size;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    st = obj_parse(ctx, s, data, size, file, dir, xf);
    mem_free(&ctx->alloc, data);
    return st;
}

static bool tri_is(const pk_scene *s, size_t k, uint32_t a, uint32_t b, uint32_t c)
{
    const triangle *t = &s->tris[k];
    return t->v[0] == a && t->v[1] == b && t->v[2] == c;
}

static bool nrm_is(const pk_scene *s, size_t k, int32_t a, int32_t b, int32_t c)
{
    const triangle *t = &s->tris[k];
    return t->n[0] == a && t->n[1] == b && t->n[2] == c;
}

static const material *mat_named(const pk_scene *s, const char *name)
{
    int64_t i = scene_find_material(s, name);
    return i < 0 ? NULL : &s->materials[i];
}

/* ---- index forms, negative indices, fan order -------------------------- */

static void test_index_forms(void)
{
    pk_context *ctx = new_ctx(NULL);
    pk_scene *s = new_scene(ctx);
    CHECKF(parse_file(ctx, s, PK_TEST_DATA, "obj_forms.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s->ntris == 7);
    CHECK(s->npositions == 4 && s->nnormals == 2);
    CHECK(tri_is(s, 0, 0, 1, 2) && nrm_is(s, 0, -1, -1, -1));
    CHECK(tri_is(s, 1, 0, 1, 2) && nrm_is(s, 1, -1, -1, -1));
    CHECK(tri_is(s, 2, 0, 1, 2) && nrm_is(s, 2, 0, 1, 0));
    CHECK(tri_is(s, 3, 0, 1, 3) && nrm_is(s, 3, 0, 1, 0));
    CHECK(tri_is(s, 4, 0, 1, 2) && nrm_is(s, 4, -1, -1, -1));   /* f -4 -3 -2 */
    CHECK(tri_is(s, 5, 0, 1, 3) && nrm_is(s, 5, 0, 1, 1));      /* negative v/vt/vn */
    CHECK(tri_is(s, 6, 0, 1, 2) && nrm_is(s, 6, -1, 1, 0));     /* mixed forms */
    for (size_t k = 0; k < s->ntris; k++) CHECK(s->tris[k].material == 0);
    /* vn 0 0 2 is stored unit length */
    CHECK_NEAR(s->normals[1].z, 1.0, 0.0);
    CHECK_NEAR(s->positions[3].x, 1.0, 0.0);
    CHECK_NEAR(s->positions[3].y, 1.0, 0.0);

    /* A second file in the same scene: its index 1 is the first position it added. */
    CHECK(parse_str(ctx, s, "v 5 5 5\nv 6 5 5\nv 5 6 5\nvn 1 0 0\nf 1//1 2//1 3//1\nf -1 -2 -3\n", "second.obj") ==
          PK_OK);
    REQUIRE(s->ntris == 9);
    CHECK(tri_is(s, 7, 4, 5, 6) && nrm_is(s, 7, 2, 2, 2));
    CHECK(tri_is(s, 8, 6, 5, 4));
    char why[256] = "";
    CHECKF(scene_check(s, why, sizeof why), "%s", why);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_fan_order(void)
{
    pk_context *ctx = new_ctx(NULL);
    pk_scene *s = new_scene(ctx);
    CHECK(parse_file(ctx, s, PK_TEST_DATA, "obj_pentagon.obj", NULL) == PK_OK);
    REQUIRE(s->ntris == 4);
    CHECK(tri_is(s, 0, 0, 1, 2));
    CHECK(tri_is(s, 1, 0, 2, 3));
    CHECK(tri_is(s, 2, 0, 3, 4));
    CHECK(tri_is(s, 3, 4, 3, 2));
    scene_destroy(s);

    /* The largest polygon allowed (past the inline corner buffer), twice. */
    size_t n = PK_MAX_POLYGON_VERTICES;
    size_t cap = n * 40 + 64;
    char *text = malloc(cap);
    REQUIRE(text);
    size_t len = 0;
    for (size_t i = 0; i < n; i++) {
        double a = 2.0 * 3.14159265358979 * (double)i / (double)n;
        len += (size_t)snprintf(text + len, cap - len, "v %.6f %.6f 0\n", cos(a), sin(a));
    }
    for (int rep = 0; rep < 2; rep++) {
        len += (size_t)snprintf(text + len, cap - len, "f");
        for (size_t i = 0; i < n; i++) len += (size_t)snprintf(text + len, cap - len, " %zu", rep ? n - i : i + 1);
        len += (size_t)snprintf(text + len, cap - len, "\n");
    }
    s = new_scene(ctx);
    CHECKF(parse_text(ctx, s, text, len, "big.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
    CHECK(s->ntris == 2 * (n - 2));
    if (s->ntris == 2 * (n - 2)) {
        CHECK(tri_is(s, n - 3, 0, (uint32_t)n - 2, (uint32_t)n - 1));
        CHECK(tri_is(s, n - 2, (uint32_t)n - 1, (uint32_t)n - 2, (uint32_t)n - 3));
        CHECK(tri_is(s, 2 * (n - 2) - 1, (uint32_t)n - 1, 1, 0));
    }
    scene_destroy(s);
    free(text);
    pk_context_destroy(ctx);
}

/* ---- messy text ---------------------------------------------------------- */

static void check_messy(pk_scene *s)
{
    REQUIRE(s->npositions == 4);
    CHECK_NEAR(s->positions[0].x, -1.5, 0.0);
    CHECK_NEAR(s->positions[0].y, 0.25, 0.0);
    CHECK_NEAR(s->positions[0].z, 20.0, 0.0);
    CHECK_NEAR(s->positions[1].x, 1.0, 0.0);
    CHECK_NEAR(s->positions[2].y, 1.0, 0.0);
    CHECK_NEAR(s->positions[3].x, 0.5, 0.0);
    CHECK(s->positions[3].y == 0.0f && signbit(s->positions[3].y));
    CHECK_NEAR(s->positions[3].z, 0.5, 0.0);
    REQUIRE(s->ntris == 3);
    CHECK(tri_is(s, 0, 0, 1, 2));
    CHECK(tri_is(s, 1, 0, 2, 3));
    CHECK(tri_is(s, 2, 1, 2, 3));
}

static void test_messy(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);
    pk_scene *s = new_scene(ctx);
    CHECKF(parse_file(ctx, s, PK_TEST_DATA, "obj_messy.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
    check_messy(s);
    CHECKF(w.count == 0, "%s", w.all);
    scene_destroy(s);

    /* The same text inline, CRLF guaranteed whatever git does to the fixture. */
    const char *text = "# messy\t\r\n\t\r\n  v\t-1.5  0.25\t2e1   \r\nv 1 0 0 0.5 0.25 0.125 # colour\r\n"
                       "v\t0 1 0 1.0\r\n   # c\r\nv +.5 -0. 5.E-1 1 0 0 1\r\no x\r\ng a b\r\ns off\r\ng\r\n"
                       "f 1 2 \\\r\n   3   \r\nf 1 3 4 # c\r\nf\t2\t3\t4\t";
    s = new_scene(ctx);
    CHECKF(parse_str(ctx, s, text, "messy.obj") == PK_OK, "%s", pk_context_error(ctx));
    check_messy(s);
    scene_destroy(s);

    /* The buffer ends inside "3999": only "3" may be read. */
    const char *cut = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3999";
    s = new_scene(ctx);
    CHECKF(parse_text(ctx, s, cut, strlen(cut) - 3, "cut.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
    CHECK(s->ntris == 1);
    scene_destroy(s);

    /* Empty input, only comments, a degenerate face: fine. */
    s = new_scene(ctx);
    CHECK(parse_text(ctx, s, "", 0, "empty.obj", NULL) == PK_OK);
    CHECK(parse_str(ctx, s, "# nothing\n\n   \n", "c.obj") == PK_OK);
    CHECK(parse_str(ctx, s, "v 0 0 0\nf 1 1 1\nf -1 -1 -1", "degen.obj") == PK_OK);
    CHECK(s->ntris == 2);
    CHECK(w.count == 0);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- warnings ------------------------------------------------------------ */

/* obj_parse_with_material: every face takes the given material, usemtl names
 * are neither looked up nor warned about, mtllib is not read; an empty
 * usemtl is still a warning. */
static void test_with_material(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);
    pk_scene *s = new_scene(ctx);
    uint32_t mat, other;
    REQUIRE(scene_add_material(ctx, s, "given", &mat) == PK_OK);
    REQUIRE(scene_add_material(ctx, s, "other", &other) == PK_OK);
    const char *t = "mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl undefined\nf 1 2 3\n"
                    "usemtl other\nf 1 2 3\nusemtl\nf 1 2 3\n";
    CHECKF(obj_parse_with_material(ctx, s, t, strlen(t), "fixed.obj", NULL, mat) == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(s->ntris == 3);
    for (size_t i = 0; i < 3; i++) CHECKF(s->tris[i].material == mat, "face %zu: %u", i, s->tris[i].material);
    CHECKF(w.count == 1 && strstr(w.all, "fixed.obj:9: usemtl without a name"), "%d warnings:\n%s", w.count, w.all);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_unknown_statements(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);
    pk_scene *s = new_scene(ctx);
    CHECK(parse_file(ctx, s, PK_TEST_DATA, "obj_unknown.obj", NULL) == PK_OK);
    CHECK(s->ntris == 1);
    CHECKF(w.count == 4, "%d warnings:\n%s", w.count, w.all);
    CHECKF(strstr(w.all, "obj_unknown.obj:4: unknown statement 'l' ignored (further ones not reported)\n"), "%s", w.all);
    CHECKF(strstr(w.all, "obj_unknown.obj:5: unknown statement 'p' ignored (further ones not reported)\n"), "%s", w.all);
    CHECKF(strstr(w.all, "obj_unknown.obj:7: unknown statement 'cstype' ignored"), "%s", w.all);
    CHECKF(strstr(w.all, "obj_unknown.obj:9: unknown statement 'vp' ignored"), "%s", w.all);
    scene_destroy(s);

    /* Many kinds of garbage: a bounded number of warnings, never an error. */
    char text[4096];
    size_t len = 0;
    for (int i = 0; i < 100; i++) len += (size_t)snprintf(text + len, sizeof text - len, "junk%d 1 2\n", i);
    memset(&w, 0, sizeof w);
    s = new_scene(ctx);
    CHECK(parse_text(ctx, s, text, len, "junk.obj", NULL) == PK_OK);
    CHECKF(w.count == IO_WARN_KINDS + 1, "%d", w.count);
    CHECKF(strstr(w.last, "no more are reported"), "%s", w.last);
    scene_destroy(s);

    /* Without a handler, warnings are dropped quietly. */
    pk_context_set_warning_handler(ctx, NULL, NULL);
    s = new_scene(ctx);
    CHECK(parse_str(ctx, s, "l 1 2\nusemtl none\nmtllib obj_nonexistent.mtl\n", "quiet.obj") == PK_OK);
    CHECK(pk_context_status(ctx) == PK_OK);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_missing_mtl(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);
    pk_scene *s = new_scene(ctx);
    CHECKF(parse_file(ctx, s, PK_TEST_DATA, "obj_missing_mtl.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
    CHECK(pk_context_status(ctx) == PK_OK);
    CHECK(strcmp(pk_context_error(ctx), "") == 0);
    REQUIRE(s->ntris == 1);
    CHECK(s->tris[0].material == 0);
    CHECKF(w.count == 2, "%s", w.all);
    CHECKF(strstr(w.all, "obj_missing_mtl.obj:1: cannot read material library 'obj_nonexistent.mtl' ("), "%s",
           w.all);
    CHECKF(strstr(w.all, "obj_missing_mtl.obj:5: material 'red' is not defined; its faces use the default material\n"),
           "%s", w.all);
    scene_destroy(s);

    /* base_dir NULL: mtllib is not read, and nothing is said about it. */
    memset(&w, 0, sizeof w);
    s = new_scene(ctx);
    const char *t = "mtllib obj_mat.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    CHECK(obj_parse(ctx, s, t, strlen(t), "nobase.obj", NULL, NULL) == PK_OK);
    CHECK(s->nmaterials == 1 && w.count == 0);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_materials(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);
    pk_scene *s = new_scene(ctx);
    CHECKF(parse_file(ctx, s, PK_TEST_DATA, "obj_mat.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
    CHECK(s->nmaterials == 4);
    const material *red = mat_named(s, "red"), *glass = mat_named(s, "glass"), *light = mat_named(s, "light");
    REQUIRE(red && glass && light);
    CHECK_NEAR(red->ka.x, 0.161, 1e-7);
    CHECK_NEAR(red->ka.z, 0.427, 1e-7);
    CHECK_NEAR(red->kd.x, 0.63, 1e-7);
    CHECK_NEAR(red->kd.y, 0.065, 1e-7);
    CHECK(red->ks.x == 0.5f && red->ks.y == 0.5f && red->ks.z == 0.5f);
    CHECK(red->ns == 10.0f && red->ni == 1.5f && red->illum == 2 && red->d == 1.0f);
    CHECK(glass->kd.x == 0.0f && glass->illum == 7);
    CHECK(glass->tf.x == 0.9f && glass->tf.y == 0.9f && glass->tf.z == 0.9f);
    CHECK(glass->d == 0.75f && glass->ni == 1.33f);
    CHECK(light->ke.x == 17.0f && light->ke.y == 12.0f && light->ke.z == 4.0f);
    CHECK(light->d == 0.75f);
    CHECK_NEAR(light->kd.x, 0.78, 1e-7); /* "KD": keywords ignore case */
    CHECK(light->ks.x == 0.0f && light->ns == 1.0f); /* MTL defaults */

    REQUIRE(s->ntris == 6);
    uint32_t want[6] = {0, (uint32_t)scene_find_material(s, "red"), (uint32_t)scene_find_material(s, "glass"),
                        (uint32_t)scene_find_material(s, "glass"), 0, (uint32_t)scene_find_material(s, "light")};
    for (int k = 0; k < 6; k++) CHECKF(s->tris[k].material == want[k], "triangle %d", k);

    /* missing textures: one warning each, naming the line and the file */
    CHECKF(w.count == 6, "%d warnings:\n%s", w.count, w.all);
    CHECKF(strstr(w.all, "obj_mat.mtl:9: texture 'red.png' not used (" PK_TEST_DATA "/red.png: cannot open: No such file "
                         "or directory); Kd is used alone\n"), "%s", w.all);
    CHECKF(strstr(w.all, "obj_mat.mtl:10: texture 'red_bump.png' not used ("), "%s", w.all);
    CHECKF(strstr(w.all, "obj_mat.mtl:11: texture 'red2.png' not used ("), "%s", w.all);
    CHECK(red->map_kd.kind == TEX_NONE && red->map_bump.kind == TEX_NONE && s->ntextures == 0);
    CHECKF(strstr(w.all, "obj_mat.mtl:19: 'Tf xyz' is not supported, statement ignored"), "%s", w.all);
    CHECKF(strstr(w.all, "obj_mat.mtl:20: 'Tf spectral' is not supported, statement ignored"), "%s", w.all);
    CHECKF(strstr(w.all, "obj_mat.obj:11: material 'nosuch' is not defined; its faces use the default material\n"),
           "%s", w.all);
    scene_destroy(s);

    /* mtl_parse on its own: one value is grey, Tr then d, illum out of range. */
    memset(&w, 0, sizeof w);
    s = new_scene(ctx);
    const char *m = "Kd 1 1 1\nnewmtl a b\nKd 0.25\nTr 0.9\nd 0.5\nillum 42\nnewmtl a b\nKe 1\n";
    CHECK(mtl_parse(ctx, s, m, strlen(m), "x.mtl") == PK_OK);
    const material *a = &s->materials[1];
    CHECK(strcmp(a->name, "a b") == 0);
    CHECK(a->kd.x == 0.25f && a->kd.y == 0.25f && a->kd.z == 0.25f && a->d == 0.5f && a->illum == 2);
    CHECK(scene_find_material(s, "a b") == 2); /* the later one wins */
    CHECKF(w.count == 2, "%s", w.all);
    CHECKF(strstr(w.all, "x.mtl:1: material statement before the first newmtl ignored"), "%s", w.all);
    CHECKF(strstr(w.all, "x.mtl:6: illumination model 42 is not one of 0..10; 2 is used"), "%s", w.all);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- oddities of real files (issue 4) ---------------------------------- */

static void test_oddities(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);

    /* A UTF-8 byte order mark before the first statement is skipped, in OBJ
     * and in MTL: the first vertex and the first material are not lost. */
    pk_scene *s = new_scene(ctx);
    CHECKF(parse_str(ctx, s, "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "bom.obj") == PK_OK, "%s",
           pk_context_error(ctx));
    CHECK(s->npositions == 3 && s->ntris == 1 && w.count == 0);
    const char *bm = "\xEF\xBB\xBFnewmtl first\nKd 0.5\n";
    CHECK(mtl_parse(ctx, s, bm, strlen(bm), "bom.mtl") == PK_OK);
    CHECK(scene_find_material(s, "first") == 1 && w.count == 0);
    scene_destroy(s);

    /* A backslash at the end of a comment does not continue it, whether the
     * comment fills the line or follows a statement. */
    s = new_scene(ctx);
    CHECKF(parse_str(ctx, s, "v 0 0 0 # C:\\models\\\nv 1 0 \\\n 0\n# D:\\\nv 0 1 0\nf 1 2 3\n", "c.obj") == PK_OK,
           "%s", pk_context_error(ctx));
    CHECKF(s->npositions == 3 && s->ntris == 1, "%zu positions, %zu triangles", s->npositions, s->ntris);
    CHECK(w.count == 0);
    scene_destroy(s);

    /* Values an MTL file may hold that make no sense are replaced, with a
     * warning, so that the file still renders. */
    memset(&w, 0, sizeof w);
    s = new_scene(ctx);
    const char *m = "newmtl odd\nKd -0.5 0.5 0.5\nKe -1\nNs -10\nNi 0\nNi -1.5\nKs -0 0 0\n";
    CHECKF(mtl_parse(ctx, s, m, strlen(m), "odd.mtl") == PK_OK, "%s", pk_context_error(ctx));
    const material *o = &s->materials[1];
    CHECK(o->kd.x == 0.0f && o->kd.y == 0.5f && o->ke.x == 0.0f && o->ns == 0.0f && o->ni == 1.0f);
    CHECKF(w.count == 5, "%d warnings:\n%s", w.count, w.all);
    CHECKF(strstr(w.all, "odd.mtl:2: Kd has a negative component; it is taken as 0\n"), "%s", w.all);
    CHECKF(strstr(w.all, "odd.mtl:3: Ke has a negative component; it is taken as 0\n"), "%s", w.all);
    CHECKF(strstr(w.all, "odd.mtl:4: Ns -10 is negative; 0 is used\n"), "%s", w.all);
    CHECKF(strstr(w.all, "odd.mtl:5: Ni 0 is not a positive index of refraction; 1 is used\n"), "%s", w.all);
    CHECKF(strstr(w.all, "odd.mtl:6: Ni -1.5 is not a positive index of refraction; 1 is used\n"), "%s", w.all);
    scene_destroy(s);

    /* Many materials (the name index grows several times), names given
     * twice: each name finds its newest material; usemtl over them all. */
    s = new_scene(ctx);
    size_t cap = 1 << 16, len = 0;
    char *text = malloc(cap);
    REQUIRE(text);
    for (int i = 0; i < 3000; i++) len += (size_t)snprintf(text + len, cap - len, "newmtl m%d\n", i % 2000);
    CHECK(mtl_parse(ctx, s, text, len, "many.mtl") == PK_OK);
    CHECK(s->nmaterials == 3001);
    for (int i = 0; i < 2000; i++) {
        char name[16];
        snprintf(name, sizeof name, "m%d", i);
        int64_t want = i < 1000 ? 2001 + i : 1 + i;
        CHECKF(scene_find_material(s, name) == want, "%s: %lld", name, (long long)scene_find_material(s, name));
    }
    CHECK(scene_find_material(s, "m2000") == -1 && scene_find_material(s, "default") == 0);
    char why[256];
    CHECKF(scene_check(s, why, sizeof why), "%s", why);
    free(text);
    scene_destroy(s);

    /* A JSON scene above PK_MAX_JSON_BYTES is refused before it is parsed
     * (its tree would take tens of times its size); the text is not read. */
    s = new_scene(ctx);
    CHECK(scene_json_parse(ctx, s, "{}", PK_MAX_JSON_BYTES + 1, "big.json", NULL) == PK_ERR_LIMIT);
    CHECKF(strcmp(pk_context_error(ctx), "big.json: a JSON scene may hold at most 67108864 bytes (meshes belong in "
                                         "OBJ files)") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- errors -------------------------------------------------------------- */

typedef struct err_case {
    const char *text;
    pk_status status;
    const char *message;
} err_case;

#define V3 "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

static const err_case obj_errors[] = {
    {"v 1 2\n", PK_ERR_PARSE, "e.obj:1: v needs 3 coordinates, found 2"},
    {"v\n", PK_ERR_PARSE, "e.obj:1: v needs 3 coordinates, found 0"},
    {"v 1.0abc 0 0\n", PK_ERR_PARSE, "e.obj:1: bad number '1.0abc'"},
    {"v 1,5 0 0\n", PK_ERR_PARSE, "e.obj:1: bad number '1,5'"},
    {"v 1e 0 0\n", PK_ERR_PARSE, "e.obj:1: bad number '1e'"},
    {"v - 0 0\n", PK_ERR_PARSE, "e.obj:1: bad number '-'"},
    {"v . 0 0\n", PK_ERR_PARSE, "e.obj:1: bad number '.'"},
    {"v 0x10 0 0\n", PK_ERR_PARSE, "e.obj:1: bad number '0x10'"},
    {"v 0 0 0#c\n", PK_ERR_PARSE, "e.obj:1: bad number '0#c'"},
    {"\n\nv nan 0 0\n", PK_ERR_PARSE, "e.obj:3: number 'nan' is not a finite float"},
    {"v 0 -inf 0\n", PK_ERR_PARSE, "e.obj:1: number '-inf' is not a finite float"},
    {"v 0 0 Infinity\n", PK_ERR_PARSE, "e.obj:1: number 'Infinity' is not a finite float"},
    {"v 1e99 0 0\n", PK_ERR_PARSE, "e.obj:1: number '1e99' is not a finite float"},
    {"v 3.5e38 0 0\n", PK_ERR_PARSE, "e.obj:1: number '3.5e38' is not a finite float"},
    {"v 0 0 -1e400\n", PK_ERR_PARSE, "e.obj:1: number '-1e400' is not a finite float"},
    {"v 1 2 3 4 5\n", PK_ERR_PARSE, "e.obj:1: v takes x y z, then w or r g b; found 5 numbers"},
    {"v 1 2 3 4 5 6 7 8\n", PK_ERR_PARSE, "e.obj:1: v takes x y z, then w or r g b; found more than 7 numbers"},
    {"vn 0 0\n", PK_ERR_PARSE, "e.obj:1: vn needs 3 coordinates, found 2"},
    {"vn 0 0 1 1\n", PK_ERR_PARSE, "e.obj:1: vn takes 3 coordinates, found more"},
    {"vn 0 nan 1\n", PK_ERR_PARSE, "e.obj:1: number 'nan' is not a finite float"},
    {"vt\n", PK_ERR_PARSE, "e.obj:1: vt needs 1 to 3 coordinates, found none"},
    {"vt 0 x\n", PK_ERR_PARSE, "e.obj:1: bad number 'x'"},
    {"vt 0 0 0 0\n", PK_ERR_PARSE, "e.obj:1: vt takes 1 to 3 coordinates, found more"},
    {V3 "f 0 1 2\n", PK_ERR_PARSE, "e.obj:4: face index 0 is not allowed (indices start at 1)"},
    {V3 "f 1 2 4\n", PK_ERR_PARSE, "e.obj:4: face index 4 out of range (1..3)"},
    {V3 "f 1 2 -4\n", PK_ERR_PARSE, "e.obj:4: face index -4 out of range (-3..-1)"},
    {V3 "f 1 2 99999999999999999999999\n", PK_ERR_PARSE,
     "e.obj:4: face index 99999999999999999999999 out of range (1..3)"},
    {V3 "f 1 2 -99999999999999999999999\n", PK_ERR_PARSE,
     "e.obj:4: face index -99999999999999999999999 out of range (-3..-1)"},
    {"f 1 2 3\n", PK_ERR_PARSE, "e.obj:1: face index 1 out of range (none defined yet)"},
    {"v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", PK_ERR_PARSE, "e.obj:3: face index 3 out of range (1..2)"},
    {V3 "f a b c\n", PK_ERR_PARSE, "e.obj:4: bad face vertex 'a'"},
    {V3 "f 1 2 3x\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '3x'"},
    {V3 "f 1 2 3.0\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '3.0'"},
    {V3 "f 1/ 2 3\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '1/'"},
    {V3 "f 1// 2 3\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '1//'"},
    {V3 "f 1/1/1/1 2 3\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '1/1/1/1'"},
    {V3 "f /1 2 3\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '/1'"},
    {V3 "f 1/x 2 3\n", PK_ERR_PARSE, "e.obj:4: bad face vertex '1/x'"},
    {V3 "f 1 2\n", PK_ERR_PARSE, "e.obj:4: face has 2 vertices, at least 3 are needed"},
    {V3 "f\n", PK_ERR_PARSE, "e.obj:4: face has 0 vertices, at least 3 are needed"},
    {V3 "f 1/1 2/1 3/1\n", PK_ERR_PARSE, "e.obj:4: texture coordinate index 1 out of range (none defined yet)"},
    {V3 "vt 0 0\nf 1/1 2/2 3/1\n", PK_ERR_PARSE, "e.obj:5: texture coordinate index 2 out of range (1..1)"},
    {V3 "vt 0 0\nf 1/1 2/0 3/1\n", PK_ERR_PARSE,
     "e.obj:5: texture coordinate index 0 is not allowed (indices start at 1)"},
    {V3 "vn 0 0 1\nf 1//1 2//-2 3//1\n", PK_ERR_PARSE, "e.obj:5: normal index -2 out of range (-1..-1)"},
    {V3 "f 1//1 2//1 3//1\n", PK_ERR_PARSE, "e.obj:4: normal index 1 out of range (none defined yet)"},
};

static const err_case mtl_errors[] = {
    {"newmtl a\nKd 1 2\n", PK_ERR_PARSE, "e.mtl:2: Kd needs 1 or 3 numbers, found 2"},
    {"newmtl a\nKs 1 2 3 4\n", PK_ERR_PARSE, "e.mtl:2: Ks needs 1 or 3 numbers, found more than 3"},
    {"newmtl a\nKe\n", PK_ERR_PARSE, "e.mtl:2: Ke needs 1 or 3 numbers, found 0"},
    {"newmtl a\r\nNs abc\r\n", PK_ERR_PARSE, "e.mtl:2: bad number 'abc'"},
    {"newmtl a\nNi\n", PK_ERR_PARSE, "e.mtl:2: Ni needs 1 number, found none"},
    {"newmtl a\nd 1 2\n", PK_ERR_PARSE, "e.mtl:2: d needs 1 number, found more"},
    {"newmtl a\nKd 1 nan 1\n", PK_ERR_PARSE, "e.mtl:2: number 'nan' is not a finite float"},
    {"newmtl a\nTr 1e50\n", PK_ERR_PARSE, "e.mtl:2: number '1e50' is not a finite float"},
    {"newmtl a\nillum two\n", PK_ERR_PARSE, "e.mtl:2: bad illumination model 'two'"},
    {"newmtl a\nillum\n", PK_ERR_PARSE, "e.mtl:2: illum needs a number"},
    {"newmtl a\nillum 2 3\n", PK_ERR_PARSE, "e.mtl:2: illum needs 1 number, found more"},
    {"newmtl\n", PK_ERR_PARSE, "e.mtl:1: newmtl needs a name"},
    {"newmtl # only a comment\n", PK_ERR_PARSE, "e.mtl:1: newmtl needs a name"},
};

static void test_errors(void)
{
    warnings w;
    pk_context *ctx = new_ctx(&w);
    for (size_t i = 0; i < sizeof obj_errors / sizeof obj_errors[0]; i++) {
        const err_case *c = &obj_errors[i];
        pk_scene *s = new_scene(ctx);
        pk_status st = parse_str(ctx, s, c->text, "e.obj");
        CHECKF(st == c->status, "case %zu: status %d", i, (int)st);
        CHECKF(pk_context_status(ctx) == c->status, "case %zu", i);
        CHECKF(strcmp(pk_context_error(ctx), c->message) == 0, "case %zu: got \"%s\" want \"%s\"", i,
               pk_context_error(ctx), c->message);
        pk_context_clear_error(ctx);
        scene_destroy(s);
    }
    for (size_t i = 0; i < sizeof mtl_errors / sizeof mtl_errors[0]; i++) {
        const err_case *c = &mtl_errors[i];
        pk_scene *s = new_scene(ctx);
        char *buf = malloc(strlen(c->text));
        REQUIRE(buf);
        memcpy(buf, c->text, strlen(c->text));
        pk_status st = mtl_parse(ctx, s, buf, strlen(c->text), "e.mtl");
        free(buf);
        CHECKF(st == c->status, "mtl case %zu: status %d", i, (int)st);
        CHECKF(strcmp(pk_context_error(ctx), c->message) == 0, "mtl case %zu: got \"%s\" want \"%s\"", i,
               pk_context_error(ctx), c->message);
        pk_context_clear_error(ctx);
        scene_destroy(s);
    }

    /* The example of the issue, on line 12 of box.obj. */
    pk_scene *s = new_scene(ctx);
    const char *box = "# box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\n"
                      "f 1 2 3 4\nf 5 6 7 9\n";
    CHECK(parse_str(ctx, s, box, "box.obj") == PK_ERR_PARSE);
    CHECKF(strcmp(pk_context_error(ctx), "box.obj:12: face index 9 out of range (1..8)") == 0, "%s",
           pk_context_error(ctx));
    pk_context_clear_error(ctx);
    scene_destroy(s);

    /* A polygon beyond the limit. */
    size_t n = PK_MAX_POLYGON_VERTICES + 1, cap = n * 8 + 64, len = 0;
    char *text = malloc(cap);
    REQUIRE(text);
    len += (size_t)snprintf(text, cap, V3 "f");
    for (size_t i = 0; i < n; i++) len += (size_t)snprintf(text + len, cap - len, " %zu", i % 3 + 1);
    s = new_scene(ctx);
    CHECK(parse_text(ctx, s, text, len, "e.obj", NULL) == PK_ERR_LIMIT);
    char want[128];
    snprintf(want, sizeof want, "e.obj:4: face has more than %d vertices", PK_MAX_POLYGON_VERTICES);
    CHECKF(strcmp(pk_context_error(ctx), want) == 0, "%s", pk_context_error(ctx));
    CHECK(s->ntris == 0);
    pk_context_clear_error(ctx);
    scene_destroy(s);
    free(text);

    /* An error inside an MTL names the MTL file and line. */
    s = new_scene(ctx);
    CHECK(parse_str(ctx, s, "mtllib obj_mat.mtl obj_bad.mtl\n", "two.obj") == PK_ERR_PARSE);
    CHECKF(strcmp(pk_context_error(ctx), "obj_bad.mtl:3: Kd needs 1 or 3 numbers, found 2") == 0, "%s",
           pk_context_error(ctx));
    CHECK(mat_named(s, "red") != NULL);
    pk_context_clear_error(ctx);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- transform ----------------------------------------------------------- */

static void test_xform(void)
{
    pk_context *ctx = new_ctx(NULL);
    /* scale x by 2, mirror z, then translate (1, 2, 3) */
    const xform m = {{2, 0, 0, 1, 0, 1, 0, 2, 0, 0, -1, 3, 0, 0, 0, 1}};
    pk_scene *s = new_scene(ctx);
    const char *t = "v 1 1 1\nv 0 0 0\nv 1 0 0\nvn 1 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n";
    CHECK(parse_text(ctx, s, t, strlen(t), "x.obj", &m) == PK_OK);
    REQUIRE(s->npositions == 3 && s->nnormals == 2);
    CHECK(s->positions[0].x == 3.0f && s->positions[0].y == 3.0f && s->positions[0].z == 2.0f);
    CHECK(s->positions[1].x == 1.0f && s->positions[1].y == 2.0f && s->positions[1].z == 3.0f);
    /* inverse transpose of diag(2, 1, -1) is diag(0.5, 1, -1): (1,1,0) -> (0.5,1,0)/|.| */
    CHECK_NEAR(s->normals[0].x, 0.5 / sqrt(1.25), 1e-6);
    CHECK_NEAR(s->normals[0].y, 1.0 / sqrt(1.25), 1e-6);
    CHECK_NEAR(s->normals[0].z, 0.0, 1e-7);
    CHECK_NEAR(s->normals[1].z, -1.0, 1e-7);
    scene_destroy(s);

    /* A rotation about z by 90 degrees keeps normals rotating with the surface. */
    const xform r = {{0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    s = new_scene(ctx);
    t = "vn 1 0 0\n";
    CHECK(parse_text(ctx, s, t, strlen(t), "r.obj", &r) == PK_OK);
    CHECK_NEAR(s->normals[0].x, 0.0, 1e-7);
    CHECK_NEAR(s->normals[0].y, 1.0, 1e-7);
    scene_destroy(s);

    const xform sing = {{1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    s = new_scene(ctx);
    CHECK(parse_text(ctx, s, t, strlen(t), "sing.obj", &sing) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strcmp(pk_context_error(ctx), "sing.obj: transform is singular") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    scene_destroy(s);

    const xform huge = {{1e30f, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    s = new_scene(ctx);
    t = "v 1e10 0 0\n";
    CHECK(parse_text(ctx, s, t, strlen(t), "huge.obj", &huge) == PK_ERR_PARSE);
    CHECKF(strcmp(pk_context_error(ctx), "huge.obj:1: transformed vertex is not finite") == 0, "%s",
           pk_context_error(ctx));
    pk_context_clear_error(ctx);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- float parser -------------------------------------------------------- */

static float parse1(const char *text)
{
    float f = -12345.0f;
    const char *e = text + strlen(text);
    const char *q = io_parse_float(text, e, &f);
    REQUIRE(q == e);
    return f;
}

static int64_t ulp_diff(float a, float b)
{
    int32_t ia, ib;
    memcpy(&ia, &a, 4);
    memcpy(&ib, &b, 4);
    if (ia < 0) ia = INT32_MIN - ia;
    if (ib < 0) ib = INT32_MIN - ib;
    int64_t d = (int64_t)ia - (int64_t)ib;
    return d < 0 ? -d : d;
}

static void test_float_parser(void)
{
    static const char *exact[] = {"0",          "-0",          "1",           "0.1",         "-2.5",
                                  "1e-45",      "1.4e-45",     "7e-46",       "1.17549435e-38",
                                  "3.4028235e38", "3.40282356e38", "123456789", "0.000001",   "1e10",
                                  "16777217",   "16777219",    ".5",          "5.",          "+7.25E+2",
                                  "0.30000001192092896", "123456789012345678901234567890",
                                  "0.0000000000000000000000000000000000000000000000001",
                                  "9999999999999999999999.9999e-3", "2.7182818284590452353602874713527"};
    for (size_t i = 0; i < sizeof exact / sizeof exact[0]; i++) {
        float want = strtof(exact[i], NULL);
        float got = parse1(exact[i]);
        CHECKF(got == want && signbit(got) == signbit(want), "%s: %.9g vs strtof %.9g", exact[i], (double)got,
               (double)want);
    }
    CHECK(isinf(parse1("3.40282357e38")) && isinf(parse1("1e39")));

    /* Random decimals against strtof: within 1 ulp always, exact nearly always. */
    uint64_t x = 0x9E3779B97F4A7C15ull;
    int inexact = 0, total = 200000;
    for (int i = 0; i < total; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        char buf[64];
        int digits = 1 + (int)(x % 12);
        uint64_t mant = (x >> 8) % 1000000000000ull;
        int exp = (int)((x >> 50) % 90) - 50;
        switch (i % 3) {
        case 0: snprintf(buf, sizeof buf, "%.*f", digits % 8, (double)(mant % 100000000) / 1000.0); break;
        case 1: snprintf(buf, sizeof buf, "%llue%d", (unsigned long long)(mant % 10000000000ull), exp); break;
        default: snprintf(buf, sizeof buf, "%.*e", digits, (double)mant * pow(10.0, exp)); break;
        }
        float want = strtof(buf, NULL);
        float got = parse1(buf);
        int64_t d = ulp_diff(got, want);
        if (d > 1) CHECKF(d <= 1, "%s: %.9g vs %.9g", buf, (double)got, (double)want);
        if (d) inexact++;
    }
    CHECKF(inexact * 10000 < total, "%d of %d not correctly rounded", inexact, total);
    printf("float parser: %d of %d random inputs differ from strtof by 1 ulp\n", inexact, total);

    int64_t v;
    const char *s = "123456789012345678901234";
    CHECK(io_parse_int(s, s + strlen(s), &v) == s + strlen(s) && v > 1000000000000000LL);
    s = "-42/";
    CHECK(io_parse_int(s, s + 4, &v) == s + 3 && v == -42);
    s = "+";
    CHECK(io_parse_int(s, s + 1, &v) == NULL);
}

/* ---- allocation failures ------------------------------------------------- */

typedef struct failing {
    long left;   /* allocations that still succeed; < 0 = unlimited */
    long live;
} failing;

static void *failing_realloc(void *user, void *ptr, size_t size)
{
    failing *f = user;
    if (size == 0) {
        if (ptr) f->live--;
        free(ptr);
        return NULL;
    }
    if (f->left == 0) return NULL;
    if (f->left > 0) f->left--;
    void *p = realloc(ptr, size);
    if (p && !ptr) f->live++;
    return p;
}

static void test_alloc_failures(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/obj_mat.obj", PK_TEST_DATA);
    bool done = false;
    for (long n = 0; n < 2000 && !done; n++) {
        failing f = {-1, 0};
        pk_allocator a = {failing_realloc, &f};
        pk_context *ctx;
        REQUIRE(pk_context_create(&a, &ctx) == PK_OK);
        pk_scene *s = new_scene(ctx);
        char *data;
        size_t size;
        REQUIRE(file_read_all(ctx, path, &data, &size) == PK_OK);
        f.left = n;
        pk_status st = obj_parse(ctx, s, data, size, "obj_mat.obj", PK_TEST_DATA, NULL);
        f.left = -1;
        CHECKF(st == PK_OK || st == PK_ERR_NOMEM, "n=%ld: %s", n, pk_context_error(ctx));
        if (st == PK_OK) {
            done = true;
            CHECK(s->ntris == 6);
        }
        mem_free(&ctx->alloc, data);
        scene_destroy(s);
        pk_context_destroy(ctx);
        CHECKF(f.live == 0, "n=%ld: %ld blocks leaked", n, f.live);
    }
    CHECK(done);
}

/* ---- shared scenes ------------------------------------------------------- */

static bool have(char *buf, size_t n, const char *rel)
{
    snprintf(buf, n, "%s/%s", PK_SHARED_DIR, rel);
    if (access(buf, R_OK) == 0) return true;
    printf("note: %s is not there; skipped\n", buf);
    return false;
}

static void test_cornell(void)
{
    static const struct {
        const char *file;
        size_t tris;
        float ke[3];
    } boxes[] = {
        {"CornellBox-Original.obj", 36, {17, 12, 4}},     {"CornellBox-Mirror.obj", 36, {17, 12, 4}},
        {"CornellBox-Sphere.obj", 2188, {10, 10, 10}},    {"CornellBox-Glossy.obj", 1112, {10, 10, 10}},
        {"CornellBox-Water.obj", 7088, {10, 10, 10}},     {"CornellBox-Empty-RG.obj", 12, {17, 12, 4}},
        {"CornellBox-Empty-CO.obj", 12, {10, 10, 10}},    {"CornellBox-Empty-White.obj", 12, {10, 10, 10}},
        {"CornellBox-Empty-Squashed.obj", 12, {10, 10, 10}},
    };
    char dir[1024];
    if (!have(dir, sizeof dir, "scenes/cornell")) return;
    for (size_t i = 0; i < sizeof boxes / sizeof boxes[0]; i++) {
        warnings w;
        pk_context *ctx = new_ctx(&w);
        pk_scene *s = new_scene(ctx);
        pk_status st = parse_file(ctx, s, dir, boxes[i].file, NULL);
        CHECKF(st == PK_OK, "%s: %s", boxes[i].file, pk_context_error(ctx));
        CHECKF(s->ntris == boxes[i].tris, "%s: %zu triangles", boxes[i].file, s->ntris);
        CHECKF(w.count == 0, "%s: %s", boxes[i].file, w.all);
        const material *light = mat_named(s, "light");
        CHECKF(light && light->ke.x == boxes[i].ke[0] && light->ke.y == boxes[i].ke[1] &&
                   light->ke.z == boxes[i].ke[2],
               "%s", boxes[i].file);
        /* every usemtl resolved: no face is left with the default material */
        size_t lit = 0;
        for (size_t k = 0; k < s->ntris; k++) {
            CHECKF(s->tris[k].material != 0, "%s: triangle %zu", boxes[i].file, k);
            if (s->tris[k].material == (uint32_t)scene_find_material(s, "light")) lit++;
        }
        CHECKF(lit >= 2, "%s: %zu light triangles", boxes[i].file, lit);
        char why[256] = "";
        CHECKF(scene_check(s, why, sizeof why), "%s: %s", boxes[i].file, why);
        scene_destroy(s);
        pk_context_destroy(ctx);
    }
    /* the Sphere box's glass sphere */
    {
        pk_context *ctx = new_ctx(NULL);
        pk_scene *s = new_scene(ctx);
        CHECK(parse_file(ctx, s, dir, "CornellBox-Sphere.obj", NULL) == PK_OK);
        const material *g = mat_named(s, "rightSphere");
        CHECK(g && g->illum == 7 && g->ni == 2.5f && g->tf.x == 0.1f);
        const material *l = mat_named(s, "light");
        CHECK(l && l->d == 1.0f);
        scene_destroy(s);
        pk_context_destroy(ctx);
    }
    /* water.obj names a water.mtl that does not exist */
    {
        warnings w;
        pk_context *ctx = new_ctx(&w);
        pk_scene *s = new_scene(ctx);
        CHECKF(parse_file(ctx, s, dir, "water.obj", NULL) == PK_OK, "%s", pk_context_error(ctx));
        CHECK(s->ntris == 4900);
        CHECKF(w.count == 2, "%s", w.all);
        CHECKF(strstr(w.all, "water.obj:1: cannot read material library 'water.mtl'"), "%s", w.all);
        CHECKF(strstr(w.all, "material 'water' is not defined"), "%s", w.all);
        for (size_t k = 0; k < s->ntris; k++) CHECK(s->tris[k].material == 0);
        scene_destroy(s);
        pk_context_destroy(ctx);
    }
}

static void test_big(const char *rel, size_t want_tris, size_t want_pos)
{
    char path[1024];
    if (!have(path, sizeof path, rel)) return;
    pk_context *ctx = new_ctx(NULL);
    char *dir = path_dirname(&ctx->alloc, path);
    REQUIRE(dir);
    double best = 1e30;
    for (int rep = 0; rep < 5; rep++) {
        pk_scene *s = new_scene(ctx);
        double t0 = time_now();
        char *data;
        size_t size;
        REQUIRE(file_read_all(ctx, path, &data, &size) == PK_OK);
        pk_status st = obj_parse(ctx, s, data, size, rel, dir, NULL);
        double t1 = time_now();
        mem_free(&ctx->alloc, data);
        CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
        CHECKF(s->ntris == want_tris, "%s: %zu triangles", rel, s->ntris);
        CHECKF(s->npositions == want_pos, "%s: %zu positions", rel, s->npositions);
        char why[256] = "";
        if (rep == 0) CHECKF(scene_check(s, why, sizeof why), "%s", why);
        if (t1 - t0 < best) best = t1 - t0;
        scene_destroy(s);
        if (test_failures) break;
    }
    printf("%s: read + parse %.1f ms (best of 5)\n", rel, best * 1e3);
    mem_free(&ctx->alloc, dir);
    pk_context_destroy(ctx);
}

int main(void)
{
    test_index_forms();
    test_fan_order();
    test_messy();
    test_unknown_statements();
    test_with_material();
    test_missing_mtl();
    test_materials();
    test_oddities();
    test_errors();
    test_xform();
    test_float_parser();
    test_alloc_failures();
    test_cornell();
    test_big("scenes/bench/stanford-bunny.obj", 69451, 35947);
    test_big("scenes/bench/dabrovic-sponza/sponza.obj", 66454, 39999);
    return test_done("test_obj");
}

/*
 * test_scene_build.c - io/scene_build.h, the readers' graphics state: the
 * transform stack (push, pop, concatenation order), the current material,
 * and meshes added through the current transform (positions, normals by the
 * inverse transpose, texture coordinates, winding); objects and instances,
 * flattened by scene_commit; and a Mitsuba XML scene with a shapegroup
 * loaded with every allocation failing in turn.
 */
#include "test.h"

#include "io/scene_build.h"
#include "io/readers.h"
#include "scene/scene.h"

static pk_context *new_ctx(void)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    return ctx;
}

static const vec3 quad_pos[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
static const vec3 quad_nrm[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
static const float quad_uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
static const uint32_t quad_tris[6] = {0, 1, 2, 0, 2, 3};

static void test_stack(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    REQUIRE(scene_create(ctx, "b", &s) == PK_OK);
    scene_builder b;
    sb_init(&b, ctx, s);
    CHECK(b.material == 0 && b.depth == 0);
    CHECK(!sb_pop(&b)); /* nothing pushed */
    xform t = xform_translate(v3(1, 0, 0)), sc = xform_scale(v3s(2.0f));
    sb_concat(&b, &t);
    REQUIRE(sb_push(&b));
    sb_concat(&b, &sc); /* applies first: translate(scale(p)) */
    CHECK_NEAR(xform_point(sb_transform(&b), v3(1, 1, 1)).x, 3.0, 0);
    REQUIRE(sb_pop(&b));
    CHECK_NEAR(xform_point(sb_transform(&b), v3(1, 1, 1)).x, 2.0, 0);
    int pushes = 0;
    while (sb_push(&b)) pushes++;
    CHECK(pushes == SB_MAX_DEPTH - 1);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void test_add_mesh(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    REQUIRE(scene_create(ctx, "b", &s) == PK_OK);
    uint32_t red;
    REQUIRE(scene_add_material(ctx, s, "red", &red) == PK_OK);
    scene_builder b;
    sb_init(&b, ctx, s);

    /* in object space, then placed twice: translated with the default
     * material, rotated -90 degrees about x (the quad now faces +y) with red */
    sb_mesh m = {quad_pos, quad_nrm, quad_uv, 4, quad_tris, 2, false};
    xform t = xform_translate(v3(0, 0, 5));
    sb_set_transform(&b, &t);
    REQUIRE(sb_add_mesh(&b, &m) == PK_OK);
    REQUIRE(sb_push(&b));
    xform r = xform_rotate(v3(1, 0, 0), -90.0f);
    sb_set_transform(&b, &r);
    sb_set_material(&b, red);
    m.flip = true;
    REQUIRE(sb_add_mesh(&b, &m) == PK_OK);
    REQUIRE(sb_pop(&b));

    REQUIRE(s->ntris == 4 && s->npositions == 8 && s->nnormals == 8 && s->nuvs == 8);
    CHECK(s->positions[2].x == 1.0f && s->positions[2].y == 1.0f && s->positions[2].z == 5.0f);
    CHECK(s->tris[0].material == 0 && s->tris[2].material == red);
    /* the second quad: (0,1,0) -> (0,0,-1) under -90 degrees about x */
    CHECK_NEAR(s->positions[7].x, 0.0, 1e-7);
    CHECK_NEAR(s->positions[7].y, 0.0, 1e-7);
    CHECK_NEAR(s->positions[7].z, -1.0, 1e-7);
    CHECK_NEAR(s->normals[4].y, 1.0, 1e-7); /* +z -> +y */
    /* indices point at the mesh's own vertices; flip swaps b and c */
    CHECK(s->tris[1].v[0] == 0 && s->tris[1].v[1] == 2 && s->tris[1].v[2] == 3);
    CHECK(s->tris[2].v[0] == 4 && s->tris[2].v[1] == 6 && s->tris[2].v[2] == 5);
    CHECK(s->tris[2].n[1] == 6 && s->tris[2].t[2] == 5);
    CHECK(s->uvs[6].u == 1.0f && s->uvs[6].v == 1.0f);

    /* without normals and uvs the triangles say -1 */
    sb_mesh bare = {quad_pos, NULL, NULL, 4, quad_tris, 2, false};
    REQUIRE(sb_add_mesh(&b, &bare) == PK_OK);
    CHECK(s->tris[4].n[0] == -1 && s->tris[4].t[2] == -1);
    CHECK(scene_commit(ctx, s) == PK_OK);

    /* a vertex that leaves the floats is an error that names the scene */
    xform huge = xform_scale(v3s(1e30f));
    const vec3 far[3] = {{1e10f, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    sb_mesh bad = {far, NULL, NULL, 3, quad_tris, 1, false};
    sb_set_transform(&b, &huge);
    CHECK(sb_add_mesh(&b, &bad) == PK_ERR_PARSE);
    CHECKF(strcmp(pk_context_error(ctx), "b: a transformed vertex is not finite") == 0, "%s", pk_context_error(ctx));
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* objects: defined once (in their own space), placed twice by the current
 * transform; scene_commit flattens them where they stand among the other
 * triangles, normals by the inverse transpose */
static void test_objects(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    REQUIRE(scene_create(ctx, "b", &s) == PK_OK);
    uint32_t red;
    REQUIRE(scene_add_material(ctx, s, "red", &red) == PK_OK);
    scene_builder b;
    sb_init(&b, ctx, s);
    const sb_mesh quad = {quad_pos, quad_nrm, quad_uv, 4, quad_tris, 2, false};
    REQUIRE(sb_add_mesh(&b, &quad) == PK_OK); /* triangles 0, 1: world */

    REQUIRE(sb_begin_object(&b));
    CHECK(!sb_begin_object(&b)); /* objects do not nest */
    xform up = xform_translate(v3(0, 0, 1));
    sb_set_transform(&b, &up);
    sb_set_material(&b, red);
    REQUIRE(sb_add_mesh(&b, &quad) == PK_OK);
    CHECK(sb_add_instance(&b, 0) == PK_ERR_INVALID_ARGUMENT); /* not inside an object */
    pk_context_clear_error(ctx);
    uint32_t mesh;
    REQUIRE(sb_end_object(&b, &mesh) == PK_OK);
    CHECK(mesh == 0 && s->nmeshes == 1);
    /* the object's geometry left the world */
    CHECK(s->ntris == 2 && s->npositions == 4 && s->nnormals == 4 && s->nuvs == 4);
    CHECK(s->mesh_positions[0].z == 1.0f && s->mesh_tris[0].material == red);

    xform x = xform_translate(v3(10, 0, 0));
    sb_set_transform(&b, &x);
    REQUIRE(sb_add_instance(&b, mesh) == PK_OK); /* triangles 2, 3 */
    sb_set_material(&b, 0);
    REQUIRE(sb_add_mesh(&b, &quad) == PK_OK);    /* triangles 4, 5 */
    xform sc = xform_scale(v3(2, 1, -1));
    sb_set_transform(&b, &sc);
    REQUIRE(sb_add_instance(&b, mesh) == PK_OK); /* triangles 6, 7 */
    xform flat = xform_scale(v3(1, 0, 1));
    sb_set_transform(&b, &flat);
    CHECK(sb_add_instance(&b, mesh) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    CHECK(s->ninstances == 2 && s->ntris == 4);

    REQUIRE(scene_commit(ctx, s) == PK_OK);
    REQUIRE(s->ntris == 8);
    CHECK(s->nflattened == 2);
    vec3 a, c1, c2;
    scene_tri_verts(s, 2, &a, &c1, &c2);
    CHECK(a.x == 10.0f && a.y == 0.0f && a.z == 1.0f && c2.x == 11.0f && c2.y == 1.0f);
    CHECK(s->tris[2].material == red && s->tris[3].material == red);
    CHECK(s->tris[4].material == 0 && s->tris[0].material == 0);
    scene_tri_verts(s, 4, &a, &c1, &c2);
    CHECK(a.x == 10.0f && a.z == 0.0f); /* the world quad between the instances (still moved by x) */
    scene_tri_verts(s, 6, &a, &c1, &c2);
    CHECK(a.x == 0.0f && a.z == -1.0f && c2.x == 2.0f);
    /* normals: +z through diag(2, 1, -1)'s inverse transpose is -z */
    CHECK(s->tris[6].n[0] >= 0);
    CHECK_NEAR(s->normals[s->tris[6].n[0]].z, -1.0, 1e-7);
    CHECK(s->uvs[s->tris[6].t[1]].u == 1.0f);
    /* committing again flattens nothing twice */
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    CHECK(s->ntris == 8);

    /* a mesh that refers to vertices outside it is refused */
    uint32_t m2;
    CHECK(scene_capture_mesh(ctx, s, 8, 0, 0, 0, &m2) == PK_ERR_INVALID_ARGUMENT);
    CHECK(s->ntris == 8 && s->nmeshes == 1);
    pk_context_clear_error(ctx);
    CHECK(sb_end_object(&b, &m2) == PK_ERR_INVALID_ARGUMENT); /* none begun */
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* ---- allocation failures through capture and flattening ---- */

typedef struct fail_alloc {
    long calls, fail_at; /* fail the call numbered fail_at (1-based); 0 = never */
    long live;           /* blocks currently allocated */
} fail_alloc;

/* Blocks carry a 16-byte header so that live blocks can be counted. */
static void *fail_hook(void *user, void *ptr, size_t size)
{
    fail_alloc *f = user;
    if (size == 0) {
        if (ptr) {
            f->live--;
            free((char *)ptr - 16);
        }
        return NULL;
    }
    f->calls++;
    if (f->fail_at && f->calls == f->fail_at) return NULL;
    char *q = realloc(ptr ? (char *)ptr - 16 : NULL, size + 16);
    if (!q) return NULL;
    if (!ptr) f->live++;
    return q + 16;
}

static const char *group_xml =
    "<scene version=\"3.0.0\">\n"
    "  <shape type=\"rectangle\"/>\n"
    "  <shape type=\"shapegroup\" id=\"g\">\n"
    "    <shape type=\"cube\"/>\n"
    "    <shape type=\"disk\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>\n"
    "  </shape>\n"
    "  <shape type=\"instance\"><ref id=\"g\"/></shape>\n"
    "  <shape type=\"rectangle\"/>\n"
    "  <shape type=\"instance\"><ref id=\"g\"/>\n"
    "    <transform name=\"to_world\"><translate x=\"3\"/></transform></shape>\n"
    "</scene>\n";

/* 0: loaded and committed; else the status of the failure */
static pk_status load_group(fail_alloc *f, size_t *ntris)
{
    pk_allocator a = {fail_hook, f};
    pk_context *ctx;
    if (pk_context_create(&a, &ctx) != PK_OK) return PK_ERR_NOMEM;
    pk_scene *s = NULL;
    pk_status st = scene_create(ctx, "g.xml", &s);
    if (st == PK_OK) st = scene_xml_parse(ctx, s, group_xml, strlen(group_xml), "g.xml", PK_TEST_DATA, NULL, 0);
    if (st == PK_OK) st = scene_commit(ctx, s);
    if (st == PK_OK) *ntris = s->ntris;
    if (st != PK_OK) CHECKF(pk_context_error(ctx)[0] != '\0', "status %d without a message", (int)st);
    scene_destroy(s);
    pk_context_destroy(ctx);
    return st;
}

static void test_alloc_failures(void)
{
    fail_alloc f = {0, 0, 0};
    size_t ntris = 0;
    REQUIRE(load_group(&f, &ntris) == PK_OK);
    CHECK(ntris == 2 + (12 + 64) + 2 + (12 + 64));
    CHECK(f.live == 0);
    long total = f.calls;
    for (long n = 1; n <= total; n++) {
        fail_alloc g = {0, n, 0};
        size_t k = 0;
        pk_status st = load_group(&g, &k);
        CHECKF(st == PK_ERR_NOMEM, "allocation %ld of %ld failed: status %d", n, total, (int)st);
        CHECKF(g.live == 0, "allocation %ld failed: %ld blocks leaked", n, g.live);
    }
}

int main(void)
{
    test_stack();
    test_add_mesh();
    test_objects();
    test_alloc_failures();
    return test_done("test_scene_build");
}

/*
 * test_texture.c - textures: bilinear lookups (repeat and clamp) and
 * trilinear ones against values worked out by hand, the mip chain (linear
 * means, sRGB re-encoding), mip level selection from a footprint, sRGB and
 * data decoding, checkerboards, uv interpolation on a triangle and on a
 * sphere, one load per file and mode, alpha cut-outs (a ray through a hole
 * hits what is behind; shadow rays pass) for every accelerator alike, a bad
 * texture falling back to the constant with one warning, and an end-to-end
 * render of a textured quad whose image mean is the texture's.
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"
#include "image/image_read.h"
#include "render/frame.h"
#include "render/surface.h"
#include "io/readers.h"
#include "scene/scene.h"
#include "scene/texture.h"

static pk_context *ctx;

typedef warning_log warns;

/* ---- lookups ------------------------------------------------------------------ */

static void test_bilinear(void)
{
    /* 2x2 grey, rows top first: 0 1 / 2 3 */
    const float px[4] = {0.0f, 1.0f, 2.0f, 3.0f};
    texture t;
    REQUIRE(texture_build(ctx, 2, 2, 1, NULL, px, false, &t) == PK_OK);
    CHECK(t.nlevels == 2 && t.lv[1].w == 1 && t.lv[1].h == 1);
    CHECK(t.lv[1].pxf[0] == 1.5f);
    float o[4];
    /* texel centres: (x + 0.5) / 2, 1 - (y + 0.5) / 2 */
    texture_bilinear(&t, 0, 0.25f, 0.75f, 0, o);
    CHECK_NEAR(o[0], 0.0, 1e-6);
    texture_bilinear(&t, 0, 0.75f, 0.25f, 0, o);
    CHECK_NEAR(o[0], 3.0, 1e-6);
    texture_bilinear(&t, 0, 0.5f, 0.5f, 0, o); /* between all four */
    CHECK_NEAR(o[0], 1.5, 1e-6);
    texture_bilinear(&t, 0, 0.375f, 0.75f, 0, o); /* a quarter from texel 0 toward texel 1 */
    CHECK_NEAR(o[0], 0.25, 1e-6);
    /* the left edge: repeat blends with the right column, clamp does not */
    texture_bilinear(&t, 0, 0.0f, 0.75f, 0, o);
    CHECK_NEAR(o[0], 0.5, 1e-6);
    texture_bilinear(&t, 0, 0.0f, 0.75f, TEX_CLAMP, o);
    CHECK_NEAR(o[0], 0.0, 1e-6);
    /* each axis by its own mode (glTF's wrapS and wrapT): u at the left edge,
     * v at the top edge, where repeat blends with the other side */
    texture_bilinear(&t, 0, 0.0f, 0.75f, TEX_CLAMP_U, o);
    CHECK_NEAR(o[0], 0.0, 1e-6);
    texture_bilinear(&t, 0, 0.0f, 0.75f, TEX_CLAMP_V, o);
    CHECK_NEAR(o[0], 0.5, 1e-6);
    texture_bilinear(&t, 0, 0.25f, 1.0f, 0, o); /* the top row blends with the bottom one */
    CHECK_NEAR(o[0], 1.0, 1e-6);
    texture_bilinear(&t, 0, 0.25f, 1.0f, TEX_CLAMP_U, o);
    CHECK_NEAR(o[0], 1.0, 1e-6);
    texture_bilinear(&t, 0, 0.25f, 1.0f, TEX_CLAMP_V, o);
    CHECK_NEAR(o[0], 0.0, 1e-6);
    texture_bilinear(&t, 0, -0.5f, 1.5f, TEX_CLAMP, o); /* beyond both edges: the corner texel */
    CHECK_NEAR(o[0], 0.0, 1e-6);
    texture_bilinear(&t, 0, -3.0f, 0.75f, 0, o); /* repeat: -3 is 0 */
    CHECK_NEAR(o[0], 0.5, 1e-6);
    texture_bilinear(&t, 0, 7.25f, 5.75f, 0, o);
    CHECK_NEAR(o[0], 0.0, 1e-5);
    texture_bilinear(&t, 0, NAN, INFINITY, 0, o); /* non-finite: read at 0 */
    CHECK(isfinite(o[0]));
    texture_free(&ctx->alloc, &t);
}

static void test_mipmaps(void)
{
    /* 4x4 grey 0..15 */
    float px[16];
    for (int i = 0; i < 16; i++) px[i] = (float)i;
    texture t;
    REQUIRE(texture_build(ctx, 4, 4, 1, NULL, px, false, &t) == PK_OK);
    REQUIRE(t.nlevels == 3);
    /* level 1: the means of 2x2 blocks */
    CHECK(t.lv[1].pxf[0] == 2.5f && t.lv[1].pxf[3] == 12.5f); /* (0+1+4+5)/4, (10+11+14+15)/4 */
    CHECK(t.lv[2].pxf[0] == 7.5f);
    CHECK(t.bytes == (16 + 4 + 1) * sizeof(float));
    /* level selection: a footprint of one level-0 texel is level 0, two texels level 1 */
    CHECK(texture_level(&t, 0.0f) == 0.0f);
    CHECK(texture_level(&t, 0.25f) == 0.0f);
    CHECK_NEAR(texture_level(&t, 0.5f), 1.0, 1e-6);
    CHECK_NEAR(texture_level(&t, 0.25f * sqrtf(2.0f)), 0.5, 1e-6);
    CHECK(texture_level(&t, 100.0f) == 2.0f);
    CHECK(texture_level(&t, NAN) == 0.0f);
    /* trilinear: halfway between the levels' bilinear values */
    float a[4], b[4], o[4];
    const float u = 0.3f, v = 0.6f;
    texture_bilinear(&t, 0, u, v, 0, a);
    texture_bilinear(&t, 1, u, v, 0, b);
    texture_lookup(&t, u, v, 0.25f * sqrtf(2.0f), 0, o);
    CHECK_NEAR(o[0], 0.5 * ((double)a[0] + (double)b[0]), 1e-5);
    texture_lookup(&t, u, v, 1e9f, 0, o); /* the coarsest level: the mean */
    CHECK_NEAR(o[0], 7.5, 1e-6);
    texture_free(&ctx->alloc, &t);

    /* odd sizes: 3x1 halves to 1x1 from the first two texels (the edge reused) */
    const float odd[3] = {1.0f, 3.0f, 100.0f};
    REQUIRE(texture_build(ctx, 3, 1, 1, NULL, odd, false, &t) == PK_OK);
    CHECK(t.nlevels == 2 && t.lv[1].w == 1 && t.lv[1].pxf[0] == 2.0f);
    texture_free(&ctx->alloc, &t);
}

static void test_srgb(void)
{
    /* 2x1 RGBA bytes: black and white, alpha 0 and 255 */
    const uint8_t px[8] = {0, 0, 0, 0, 255, 255, 255, 255};
    texture c, d;
    REQUIRE(texture_build(ctx, 2, 1, 4, px, NULL, true, &c) == PK_OK);
    REQUIRE(texture_build(ctx, 2, 1, 4, px, NULL, false, &d) == PK_OK);
    /* the 1x1 level: the linear mean 0.5, stored as sRGB 188 for colour,
     * 128 for data and for alpha (alpha is never sRGB) */
    CHECK(c.lv[1].px8[0] == 188 && c.lv[1].px8[3] == 128);
    CHECK(d.lv[1].px8[0] == 128 && d.lv[1].px8[3] == 128);
    const uint8_t mid[3] = {128, 64, 255};
    texture m, md;
    REQUIRE(texture_build(ctx, 1, 1, 3, mid, NULL, true, &m) == PK_OK);
    REQUIRE(texture_build(ctx, 1, 1, 3, mid, NULL, false, &md) == PK_OK);
    float o[4];
    texture_bilinear(&m, 0, 0.5f, 0.5f, 0, o);
    CHECK_NEAR(o[0], pow((128 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
    CHECK_NEAR(o[1], pow((64 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
    CHECK_NEAR(o[2], 1.0, 1e-7);
    texture_bilinear(&md, 0, 0.5f, 0.5f, 0, o);
    CHECK_NEAR(o[0], 128 / 255.0, 1e-6);
    /* the references: colour, scalar (mean of RGB), alpha (the alpha channel) */
    tex_ref r;
    tex_ref_init(&r);
    r.kind = TEX_IMAGE;
    r.tex = 0;
    texture arr[1] = {c};
    tex_query q = {0.25f, 0.5f, 0.0f, v3s(0.0f), v3s(0.0f), NULL, 0.25f, 0.5f, 0.0f}; /* the black, transparent texel */
    CHECK(tex_eval_alpha(arr, &r, q) == 0.0f);
    q.u = 0.75f;
    CHECK(tex_eval_alpha(arr, &r, q) == 1.0f);
    CHECK(tex_eval_scalar(arr, &r, q) == 1.0f);
    /* uv scale and offset: u' = 2 u + 0.25 */
    r.s[0] = 2.0f;
    r.o[0] = 0.25f;
    q.u = 0.25f; /* u' = 0.75: the white texel */
    CHECK(tex_eval_rgb(arr, &r, q).x == 1.0f);
    texture_free(&ctx->alloc, &c);
    texture_free(&ctx->alloc, &d);
    texture_free(&ctx->alloc, &m);
    texture_free(&ctx->alloc, &md);
}

static void test_checker(void)
{
    tex_ref r;
    tex_ref_init(&r);
    r.kind = TEX_CHECKER;
    r.even = v3(1, 0, 0);
    r.odd = v3(0, 0, 1);
    r.checker_scale = 4.0f;
    tex_query q = {0.1f, 0.1f, 0.0f, v3s(0.0f), v3s(0.0f), NULL, 0.1f, 0.1f, 0.0f}; /* cell (0, 0): even */
    CHECK(tex_eval_rgb(NULL, &r, q).x == 1.0f);
    q.u = 0.3f; /* cell (1, 0): odd */
    CHECK(tex_eval_rgb(NULL, &r, q).z == 1.0f);
    q.v = 0.3f; /* cell (1, 1): even */
    CHECK(tex_eval_rgb(NULL, &r, q).x == 1.0f);
    q.u = -0.1f; /* cell (-1, 1): even */
    CHECK(tex_eval_rgb(NULL, &r, q).x == 1.0f);
    q.v = 0.1f; /* cell (-1, 0): odd */
    CHECK(tex_eval_rgb(NULL, &r, q).z == 1.0f);
}

/* ---- scenes ------------------------------------------------------------------- */

static pk_scene *load(const char *obj_text, warns *w)
{
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.obj", &s) == PK_OK);
    warning_log_attach(ctx, w);
    pk_status st = obj_parse(ctx, s, obj_text, strlen(obj_text), "t.obj", PK_TEST_DATA, NULL);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    pk_context_set_warning_handler(ctx, NULL, NULL);
    return s;
}

static void test_uv(void)
{
    static warns w;
    warning_log_clear(&w);
    pk_scene *s = load("v 0 0 0\nv 2 0 0\nv 0 4 0\nvt 0.1 0.2\nvt 0.9 0.2\nvt 0.1 0.6\nf 1/1 2/2 3/3\nf 1 2 3\n", &w);
    REQUIRE(s->ntris == 2 && s->nuvs == 3);
    CHECK(s->tris[0].t[0] == 0 && s->tris[0].t[1] == 1 && s->tris[0].t[2] == 2);
    CHECK(s->tris[1].t[0] == -1 && s->tris[1].t[2] == -1);
    scene_view v = scene_view_of(s); /* what the renderer's kernels read */
    ray r = {{0.5f, 1.0f, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
    hit h = {1.0f, 0, 0.25f, 0.25f}; /* the point (0.5, 1, 0): b weight 0.25, c weight 0.25 */
    surface_uv q = surface_uv_at(&v, &r, &h);
    CHECK_NEAR(q.u, 0.5 * 0.1 + 0.25 * 0.9 + 0.25 * 0.1, 1e-6);
    CHECK_NEAR(q.v, 0.5 * 0.2 + 0.25 * 0.2 + 0.25 * 0.6, 1e-6);
    /* dp/du: 2 units of x per 0.8 of u; dp/dv: 4 of y per 0.4 of v */
    CHECK_NEAR(q.dpdu.x, 2.0 / 0.8, 1e-5);
    CHECK_NEAR(q.dpdv.y, 4.0 / 0.4, 1e-5);
    /* uv area 0.16 over the area 4: 0.2 uv per unit length */
    CHECK_NEAR(q.uv_per_len, 0.2, 1e-6);
    h.prim = 1; /* no vt: the barycentric coordinates */
    q = surface_uv_at(&v, &r, &h);
    CHECK(q.u == 0.25f && q.v == 0.25f);
    scene_destroy(s);

    /* a sphere: the top is v = 1, the equator 0.5; u runs around +y from -x */
    REQUIRE(scene_create(ctx, "sph", &s) == PK_OK);
    sphere sp = {{0, 0, 0}, 2.0f, 0};
    REQUIRE(scene_add_sphere(ctx, s, &sp) == PK_OK);
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    v = scene_view_of(s);
    ray down = {{0, 5, 0}, 0.0f, {0, -1, 0}, INFINITY};
    hit top = {3.0f, 0, 0, 0};
    CHECK_NEAR(surface_uv_at(&v, &down, &top).v, 1.0, 1e-6);
    ray side = {{5, 0, 0}, 0.0f, {-1, 0, 0}, INFINITY}; /* hits (2, 0, 0): phi 0 */
    hit eq = {3.0f, 0, 0, 0};
    q = surface_uv_at(&v, &side, &eq);
    CHECK_NEAR(q.v, 0.5, 1e-6);
    CHECK_NEAR(q.u, 0.5, 1e-6);
    ray back = {{0, 0, 5}, 0.0f, {0, 0, -1}, INFINITY}; /* hits (0, 0, 2): phi pi/2 */
    q = surface_uv_at(&v, &back, &eq);
    CHECK_NEAR(q.u, 0.75, 1e-6);
    CHECK_NEAR(q.dpdu.x, -4.0 * (double)PK_PI, 1e-4); /* around the axis, toward -x there */
    scene_destroy(s);
}

static void test_cache_and_fallback(void)
{
    static warns w;
    warning_log_clear(&w);
    const char *mtl = "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd tex_rgbw.png\nmap_d tex_rgbw.png\n"
                      "newmtl b\nmap_Kd -s 2 3 -o 0.5 0.25 -clamp on -blendu off -zz tex_rgbw.png\n"
                      "newmtl c\nKd 0.2 0.3 0.4\nmap_Kd missing.png\nmap_Ks tex_bad.png\n"
                      "newmtl d\nmap_Kd -s -clamp -bm inf tex_rgbw.png\nmap_Ks\n"
                      "newmtl e\nbump tex_normal.png\nnewmtl f\nbump -bm 0.5 tex_bump.png\n";
    pk_scene *s;
    REQUIRE(scene_create(ctx, "m", &s) == PK_OK);
    warning_log_attach(ctx, &w);
    CHECKF(mtl_parse_dir(ctx, s, mtl, strlen(mtl), "m.mtl", PK_TEST_DATA) == PK_OK, "%s", pk_context_error(ctx));
    pk_context_set_warning_handler(ctx, NULL, NULL);
    /* one load per file and mode: tex_rgbw.png as colour (a's, b's and d's map_Kd) and as data
     * (map_d), then tex_normal.png and tex_bump.png */
    CHECK(s->ntextures == 4);
    CHECK(s->textures[0].bytes == 2 * 2 * 3 + 3 && s->textures[1].bytes == 2 * 2 * 3 + 3);
    const material *a = &s->materials[scene_find_material(s, "a")];
    const material *b = &s->materials[scene_find_material(s, "b")];
    const material *c = &s->materials[scene_find_material(s, "c")];
    CHECK(a->map_kd.kind == TEX_IMAGE && b->map_kd.kind == TEX_IMAGE && a->map_kd.tex == b->map_kd.tex);
    CHECK(a->map_d.kind == TEX_IMAGE && a->map_d.tex != a->map_kd.tex);
    CHECK(b->map_kd.s[0] == 2.0f && b->map_kd.s[1] == 3.0f && b->map_kd.o[0] == 0.5f && b->map_kd.o[1] == 0.25f &&
          b->map_kd.clamp == TEX_CLAMP);
    CHECK(c->map_kd.kind == TEX_NONE && c->map_ks.kind == TEX_NONE && c->kd.x == 0.2f);
    const material *d = &s->materials[scene_find_material(s, "d")];
    /* malformed options are warned about and skipped; the texture is still used */
    CHECK(d->map_kd.kind == TEX_IMAGE && d->map_kd.s[0] == 1.0f && !d->map_kd.clamp && d->map_kd.bm == 1.0f);
    CHECKF(strstr(w.all, "m.mtl:12: texture option -s needs a number; ignored\n"), "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:12: texture option -clamp needs on or off; ignored\n"), "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:12: texture option -bm needs finite numbers; ignored\n"), "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:13: map_Ks without a file name ignored\n"), "%s", w.all);
    /* a bump map of bluish RGB is a normal map (as exporters write them); grey heights stay heights */
    const material *e = &s->materials[scene_find_material(s, "e")];
    const material *f = &s->materials[scene_find_material(s, "f")];
    CHECK(e->map_norm.kind == TEX_IMAGE && e->map_bump.kind == TEX_NONE);
    CHECK(f->map_bump.kind == TEX_IMAGE && f->map_norm.kind == TEX_NONE && f->map_bump.bm == 0.5f);
    CHECKF(strstr(w.all, "m.mtl:15: a bump map that holds normals (bluish RGB) is read as a normal map"), "%s", w.all);
    CHECKF(w.count == 9, "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:6: texture option '-blendu' is not supported, ignored"), "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:6: unknown texture option '-zz' skipped"), "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:9: texture 'missing.png' not used (" PK_TEST_DATA "/missing.png: cannot open"), "%s", w.all);
    CHECKF(strstr(w.all, "m.mtl:10: texture 'tex_bad.png' not used ("), "%s", w.all);
    CHECK(pk_context_status(ctx) == PK_OK);
    sphere sp = {{0, 0, 0}, 1.0f, 0};
    REQUIRE(scene_add_sphere(ctx, s, &sp) == PK_OK);
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    CHECK(a->textured && a->cutout && !c->textured && s->has_cutout);
    CHECK(s->ntextures == 4);
    scene_destroy(s);
}

/* A quad at z = 0 (x, y in -1..1) whose left half is a hole (map_d alpha 0),
 * and a quad behind it at z = -1. */
static void test_cutout(void)
{
    /* tex_holes.png is 32x32 with round holes centred at texels (7.5, 7.5) + 16k */
    static warns w;
    warning_log_clear(&w);
    char mtlpath[] = "/tmp/pk_cutout_XXXXXX";
    int fd = mkstemp(mtlpath);
    REQUIRE(fd >= 0);
    const char *mtl = "newmtl sheet\nmap_d " PK_TEST_DATA "/tex_holes.png\nnewmtl back\nKd 0.1 0.2 0.3\n";
    REQUIRE(write(fd, mtl, strlen(mtl)) == (ssize_t)strlen(mtl));
    close(fd);
    char obj[1024];
    snprintf(obj, sizeof obj,
             "mtllib %s\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "usemtl sheet\nf 1/1 2/2 3/3 4/4\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nusemtl back\nf 5 6 7 8\n",
             mtlpath);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.obj", &s) == PK_OK);
    warning_log_attach(ctx, &w);
    REQUIRE(obj_parse(ctx, s, obj, strlen(obj), "t.obj", "/", NULL) == PK_OK);
    pk_context_set_warning_handler(ctx, NULL, NULL);
    unlink(mtlpath);
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    CHECKF(w.count == 0, "%s", w.all);
    REQUIRE(s->has_cutout && s->ntextures == 1);
    /* the hole of texel (7.5, 7.5): uv (0.25, 1 - 0.25) -> x = -0.5, y = 0.5;
     * solid: texel (15, 3) -> uv (15.5 / 32, 1 - 3.5 / 32) -> x = -1 / 32, y = 25 / 32
     * (off the diagonal that the quad's two triangles share) */
    const ray through = {{-0.5f, 0.5f, 3.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
    const ray solid = {{-0.03125f, 0.78125f, 3.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
    const ray shadow_through = {{-0.5f, 0.5f, 3.0f}, 0.0f, {0.0f, 0.0f, -3.5f}, 1.0f}; /* ends at z = -0.5 */
    const ray shadow_solid = {{-0.03125f, 0.78125f, 3.0f}, 0.0f, {0.0f, 0.0f, -3.5f}, 1.0f};
    const pk_accel_kind kinds[] = {PK_ACCEL_NONE, PK_ACCEL_BVH, PK_ACCEL_MIDPOINT, PK_ACCEL_EMBREE};
    hit ref_through = {0}, ref_solid = {0};
    const scene_view v = scene_view_of(s);
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        if (!pk_accel_available(kinds[k])) {
            printf("accelerator %s not available, skipped\n", pk_accel_kind_name(kinds[k]));
            continue;
        }
        accel *a;
        REQUIRE(frame_build_accel(ctx, s, kinds[k], 1, &a) == PK_OK);
        ray r = through;
        hit h;
        REQUIRE(accel_intersect(a, &r, &h, NULL));
        CHECK(h.prim < 2 && surface_is_hole(&v, &r, &h)); /* the sheet, in a hole */
        CHECK(trace_past_holes(a, &v, &r, &h, NULL));
        /* Embree computes t, u, v its own way (with its AVX2 kernels a t of
         * 4 comes out an ulp or two away): the same triangle, t to 1e-6
         * relative; our accelerators give brute force's hit bit for bit */
        const bool own = kinds[k] != PK_ACCEL_EMBREE;
        CHECKF(h.prim >= 2 && (own ? h.t == 4.0f : fabsf(h.t - 4.0f) <= 4e-6f), "%s: prim %u t %a",
               pk_accel_kind_name(kinds[k]), h.prim, (double)h.t);
        if (k == 0) ref_through = h;
        if (own) CHECK(memcmp(&h, &ref_through, sizeof h) == 0); /* the same hit as brute force */
        else CHECK(h.prim == ref_through.prim);
        r = solid;
        REQUIRE(accel_intersect(a, &r, &h, NULL));
        CHECK(!surface_is_hole(&v, &r, &h));
        CHECK(trace_past_holes(a, &v, &r, &h, NULL));
        CHECKF(h.prim < 2 && (own ? h.t == 3.0f : fabsf(h.t - 3.0f) <= 3e-6f), "%s: prim %u t %a",
               pk_accel_kind_name(kinds[k]), h.prim, (double)h.t);
        if (k == 0) ref_solid = h;
        if (own) CHECK(memcmp(&h, &ref_solid, sizeof h) == 0);
        else CHECK(h.prim == ref_solid.prim);
        /* shadow rays: through the hole nothing blocks (the back quad is beyond the end) */
        CHECK(!occluded_past_holes(a, &v, &shadow_through, NULL));
        CHECK(occluded_past_holes(a, &v, &shadow_solid, NULL));
        CHECK(accel_occluded(a, &shadow_through, NULL)); /* without the holes it would be blocked */
        accel_destroy(a);
    }
    scene_destroy(s);
}

/* The textured quad filling the view, shown as it is (illum 0): the image
 * mean is the texture's linear mean, 0.5 per channel (red, green, blue,
 * white). The view is affine on the quad and the pixel grid a multiple of
 * the texture's, so the bilinear (repeating) texture is sampled uniformly
 * over whole periods: the mean is exact up to rounding. */
static void test_render_quad(void)
{
    pk_scene *s;
    REQUIRE(pk_scene_load_file(ctx, PK_TEST_DATA "/tex_quad.obj", &s) == PK_OK);
    pk_camera cam = {{0, 0, 0}, {0, 0, 0}, {0, 1, 0}, 40.0f, 0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    cam.look_from[2] = 1.0f / tanf(20.0f * PK_PI / 180.0f);
    REQUIRE(pk_scene_set_camera(ctx, s, &cam) == PK_OK);
    for (int integ = 0; integ < 1; integ++) {
        pk_render_options o;
        pk_render_options_init(&o);
        o.width = o.height = 64;
        o.spp = 1;
        o.integrator = PK_INTEGRATOR_WHITTED;
        o.threads = 2;
        pk_image *img = NULL;
        REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
        const float *p = pk_image_pixels_const(img);
        double sum[3] = {0, 0, 0};
        for (int i = 0; i < 64 * 64; i++)
            for (int c = 0; c < 3; c++) sum[c] += (double)p[3 * i + c];
        for (int c = 0; c < 3; c++) CHECK_NEAR(sum[c] / (64 * 64), 0.5, 1e-3);
        /* pixels next to texel centres (32 pixels a texel): the centres of
         * pixels 16 and 48 lie f = 1/64 of a texel past those of the red
         * (top-left) and white (bottom-right) texels, so bilinear weights
         * (1-f)^2, f(1-f), f(1-f), f^2 mix in their neighbours */
        const double f = 1.0 / 64.0;
        const float *tl = p + 3 * (16 * 64 + 16), *br = p + 3 * (48 * 64 + 48);
        CHECK_NEAR(tl[0], (1 - f) * (1 - f) + f * f, 1e-3); /* red + white */
        CHECK_NEAR(tl[1], f, 1e-3);                          /* green + white */
        CHECK_NEAR(br[1], 1 - f, 1e-3);                      /* white + green */
        CHECK_NEAR(br[2], 1 - f, 1e-3);                      /* white + blue */
        pk_image_destroy(img);
    }
    pk_scene_destroy(s);
}

/* JSON: textures and checkers in material parameters, a missing file warned about. */
static void test_json(void)
{
    char *text = NULL;
    size_t size = 0;
    REQUIRE(file_read_all(ctx, PK_TEST_DATA "/tex_json.json", &text, &size) == PK_OK);
    static warns w;
    warning_log_clear(&w);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "tex_json.json", &s) == PK_OK);
    warning_log_attach(ctx, &w);
    CHECKF(scene_json_parse(ctx, s, text, size, "tex_json.json", PK_TEST_DATA) == PK_OK, "%s", pk_context_error(ctx));
    pk_context_set_warning_handler(ctx, NULL, NULL);
    mem_free(&ctx->alloc, text);
    const material *floor = &s->materials[scene_find_material(s, "floor")];
    const material *ball = &s->materials[scene_find_material(s, "ball")];
    const material *metal = &s->materials[scene_find_material(s, "metal")];
    const material *oops = &s->materials[scene_find_material(s, "oops")];
    CHECK(floor->map_kd.kind == TEX_CHECKER && floor->map_kd.checker_scale == 300.0f && floor->kd.x == 1.0f);
    CHECK(floor->map_kd.odd.x == 0.1f);
    CHECK(ball->map_kd.kind == TEX_IMAGE && ball->map_kd.s[0] == 4.0f && ball->map_kd.s[1] == 2.0f);
    CHECK(ball->map_bump.kind == TEX_IMAGE && ball->map_bump.bm == 0.05f && ball->kd.x == 1.0f);
    CHECK(metal->map_alpha.kind == TEX_IMAGE && metal->map_alpha.squared && metal->alpha == 1.0f);
    CHECK(oops->map_kd.kind == TEX_NONE && oops->kd.x == 0.8f); /* the default kd */
    CHECK(oops->map_d.kind == TEX_CHECKER);
    CHECK(s->ntextures == 2); /* tex_checker.png (colour), tex_bump.png (data, twice) */
    CHECKF(w.count == 1 && strstr(w.all, "tex_json.json:10: materials.oops.kd.texture: texture 'nothere.png' not used ("),
           "%s", w.all);
    scene_destroy(s);

    /* clamp along one axis: "u" or "v" */
    {
        const char *j = "{\"materials\": {\"m\": {\"kd\": {\"texture\": \"tex_checker.png\", \"clamp\": \"v\"}},"
                        " \"n\": {\"kd\": {\"texture\": \"tex_checker.png\", \"clamp\": \"u\"}},"
                        " \"o\": {\"kd\": {\"texture\": \"tex_checker.png\", \"clamp\": true, \"uvset\": 1}}}}";
        REQUIRE(scene_create(ctx, "axes.json", &s) == PK_OK);
        CHECKF(scene_json_parse(ctx, s, j, strlen(j), "axes.json", PK_TEST_DATA) == PK_OK, "%s", pk_context_error(ctx));
        CHECK(s->materials[scene_find_material(s, "m")].map_kd.clamp == TEX_CLAMP_V);
        CHECK(s->materials[scene_find_material(s, "n")].map_kd.clamp == TEX_CLAMP_U);
        CHECK(s->materials[scene_find_material(s, "o")].map_kd.clamp == TEX_CLAMP);
        CHECK(s->materials[scene_find_material(s, "o")].map_kd.uvset == 1);
        CHECK(s->materials[scene_find_material(s, "n")].map_kd.uvset == 0);
        scene_destroy(s);
    }

    /* malformed texture objects are errors naming the value */
    static const struct {
        const char *json, *msg;
    } bad[] = {
        {"{\"materials\": {\"m\": {\"kd\": {\"scale\": 2}}}}", "materials.m.kd: a texture needs \"texture\""},
        {"{\"materials\": {\"m\": {\"kd\": {\"texture\": \"a.png\", \"checker\": {}}}}}", "a texture needs"},
        {"{\"materials\": {\"m\": {\"kd\": {\"texture\": 3}}}}", "materials.m.kd.texture: must be a file name"},
        {"{\"materials\": {\"m\": {\"kd\": {\"checker\": {\"scale\": 0}}}}}", "materials.m.kd.checker.scale: must be a positive"},
        {"{\"materials\": {\"m\": {\"type\": \"diffuse\", \"opacity\": 0.5}}}", "materials.m.opacity: must be a texture object"},
        {"{\"materials\": {\"m\": {\"kd\": {\"texture\": \"a.png\", \"clamp\": \"w\"}}}}",
         "materials.m.kd.clamp: must be true, false, \"u\" or \"v\""},
        {"{\"materials\": {\"m\": {\"kd\": {\"texture\": \"a.png\", \"uvset\": 2}}}}", "materials.m.kd.uvset: must be"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        REQUIRE(scene_create(ctx, "bad.json", &s) == PK_OK);
        CHECK(scene_json_parse(ctx, s, bad[i].json, strlen(bad[i].json), "bad.json", PK_TEST_DATA) == PK_ERR_PARSE);
        CHECKF(strstr(pk_context_error(ctx), bad[i].msg) != NULL, "%s", pk_context_error(ctx));
        pk_context_clear_error(ctx);
        scene_destroy(s);
    }
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_bilinear();
    test_mipmaps();
    test_srgb();
    test_checker();
    test_uv();
    test_cache_and_fallback();
    test_cutout();
    test_render_quad();
    test_json();
    pk_context_destroy(ctx);
    return test_done("test_texture");
}

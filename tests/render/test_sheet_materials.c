/*
 * test_sheet_materials.c - the thin dielectric, diffuse transmission, mix,
 * Oren-Nayar and Phong materials as each format names them
 * (tests/data/sheets): the pbrt-v4 box (thindielectric, diffusetransmission,
 * mix) and its JSON twin, the Mitsuba box (thindielectric, blendbsdf,
 * mixturebsdf, roughdiffuse, phong) and its JSON twin load without a warning,
 * into the material kinds they name, and give the same images: bit for bit
 * where the camera reaches the renderer through the same numbers (Mitsuba
 * and JSON), else block by block within Z standard errors measured from two
 * seeds of each (pbrt's camera, as in test_conformance).
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define SIZE 64
#define SPP 64
#define BLOCK 8
#define Z 5.0

static pk_context *ctx;
static warning_log warnings;

static pk_scene *load(const char *file)
{
    char path[512];
    snprintf(path, sizeof path, "%s/sheets/%s", PK_TEST_DATA, file);
    pk_scene *s = NULL;
    warning_log_clear(&warnings);
    pk_status st = pk_scene_load_file(ctx, path, &s);
    CHECKF(st == PK_OK, "%s: %s", file, pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    CHECKF(warnings.count == 0, "%s: %d warnings, the first: %s", file, warnings.count, warnings.msg[0]);
    return s;
}

static pk_image *render(const pk_scene *s, int seed)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = SIZE;
    o.spp = SPP;
    o.seed = seed;
    o.threads = 2;
    o.max_depth = 8;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    return img;
}

/* The kind of the material of the first triangle of the named part (the
 * OBJ and pbrt files list floor, ceiling, back, left, right, block, light,
 * two triangles each but the block's 8). */
static int kind_of(const pk_scene *s, int part)
{
    static const int first[] = {0, 2, 4, 6, 8, 10, 18};
    return s->materials[s->tris[first[part]].material].type;
}
enum { FLOOR, CEILING, BACK, LEFT, RIGHT, PART_BLOCK };

static bool same_bits(const pk_image *a, const pk_image *b)
{
    return memcmp(pk_image_pixels_const(a), pk_image_pixels_const(b), sizeof(float) * 3 * SIZE * SIZE) == 0;
}

/* Block means of a and b (each rendered with two seeds: a1/a2, b1/b2) agree
 * within Z standard errors of their difference, per channel. */
static int compare_blocks(const char *what, const pk_image *a1, const pk_image *a2, const pk_image *b1,
                          const pk_image *b2)
{
    const float *pa1 = pk_image_pixels_const(a1), *pa2 = pk_image_pixels_const(a2);
    const float *pb1 = pk_image_pixels_const(b1), *pb2 = pk_image_pixels_const(b2);
    int bad = 0;
    double worst = 0.0;
    for (int by = 0; by < SIZE; by += BLOCK)
        for (int bx = 0; bx < SIZE; bx += BLOCK)
            for (int c = 0; c < 3; c++) {
                double ma = 0, mb = 0, va = 0, vb = 0;
                for (int y = by; y < by + BLOCK; y++)
                    for (int x = bx; x < bx + BLOCK; x++) {
                        const int i = 3 * (y * SIZE + x) + c;
                        const double xa = pa1[i], ya = pa2[i], xb = pb1[i], yb = pb2[i];
                        ma += xa + ya, mb += xb + yb;
                        va += (xa - ya) * (xa - ya) / 2.0;
                        vb += (xb - yb) * (xb - yb) / 2.0;
                    }
                const double n = BLOCK * BLOCK;
                ma /= 2 * n, mb /= 2 * n;
                /* the mean of 2n pixels, each of variance v/n on average */
                const double se = sqrt(va / n / (2 * n) + vb / n / (2 * n)) + 1e-6 * (ma + mb);
                const double zz = fabs(ma - mb) / se;
                if (zz > worst) worst = zz;
                if (zz > Z && bad++ < 4)
                    CHECKF(0, "%s: block (%d, %d) channel %d: %.5f against %.5f (%.1f standard errors)", what, bx, by,
                           c, mb, ma, zz);
            }
    printf("  %s: worst block %.2f standard errors\n", what, worst);
    return bad;
}

static void same_geometry(const char *what, const pk_scene *a, const pk_scene *b)
{
    CHECKF(a->ntris == b->ntris, "%s: %zu triangles against %zu", what, b->ntris, a->ntris);
    if (a->ntris != b->ntris) return;
    int diff = 0;
    for (size_t t = 0; t < a->ntris; t++) {
        vec3 pa[3], pb[3];
        scene_tri_verts(a, (uint32_t)t, &pa[0], &pa[1], &pa[2]);
        scene_tri_verts(b, (uint32_t)t, &pb[0], &pb[1], &pb[2]);
        diff += memcmp(pa, pb, sizeof pa) != 0;
        const material *ma = &a->materials[a->tris[t].material], *mb = &b->materials[b->tris[t].material];
        diff += memcmp(&ma->ke, &mb->ke, sizeof ma->ke) != 0;
    }
    CHECKF(diff == 0, "%s: %d triangles differ in position or emission", what, diff);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    pk_scene *pbrt = load("box.pbrt"), *json = load("box.json"), *xml = load("box.xml"),
             *xjson = load("box_mitsuba.json");
    CHECK(kind_of(pbrt, FLOOR) == MAT_MIX && kind_of(pbrt, BACK) == MAT_DIFFUSE_TRANSMISSION &&
          kind_of(pbrt, PART_BLOCK) == MAT_THIN_DIELECTRIC);
    CHECK(kind_of(xml, FLOOR) == MAT_MIX && kind_of(xml, BACK) == MAT_MIX && kind_of(xml, LEFT) == MAT_ROUGH_DIFFUSE &&
          kind_of(xml, RIGHT) == MAT_PHONG && kind_of(xml, PART_BLOCK) == MAT_THIN_DIELECTRIC);
    for (int k = 0; k <= PART_BLOCK; k++) {
        CHECKF(kind_of(pbrt, k) == kind_of(json, k), "pbrt part %d: kind %d, JSON %d", k, kind_of(pbrt, k),
               kind_of(json, k));
        CHECKF(kind_of(xml, k) == kind_of(xjson, k), "Mitsuba part %d: kind %d, JSON %d", k, kind_of(xml, k),
               kind_of(xjson, k));
    }
    same_geometry("pbrt-v4 against JSON", json, pbrt);
    same_geometry("Mitsuba against JSON", xjson, xml);

    pk_image *x1 = render(xml, 1), *xj1 = render(xjson, 1);
    CHECKF(same_bits(x1, xj1), "Mitsuba XML: not its JSON twin's image bit for bit");
    pk_image *x1b = render(xml, 1);
    CHECKF(same_bits(x1, x1b), "Mitsuba XML: two renders with the same seed differ");
    pk_image *j1 = render(json, 1), *j2 = render(json, 2), *p1 = render(pbrt, 1), *p2 = render(pbrt, 2);
    const bool pbits = same_bits(j1, p1);
    printf("  pbrt-v4: %s\n", pbits ? "the same bits as its JSON twin" : "not the same bits (compared by blocks)");
    if (!pbits) CHECK(compare_blocks("pbrt-v4", j1, j2, p1, p2) == 0);
    pk_image *imgs[] = {x1, xj1, x1b, j1, j2, p1, p2};
    for (size_t i = 0; i < sizeof imgs / sizeof *imgs; i++) pk_image_destroy(imgs[i]);
    pk_scene *scenes[] = {pbrt, json, xml, xjson};
    for (size_t i = 0; i < 4; i++) pk_scene_destroy(scenes[i]);
    pk_context_destroy(ctx);
    return test_done("test_sheet_materials");
}

/*
 * test_conformance.c - one scene, five formats: the Cornell box of
 * tests/data/conformance (make_scenes.py) written as OBJ + MTL, JSON,
 * Mitsuba XML, pbrt-v4 and glTF 2.0 must give the same image.
 *
 * - The same scene graph: every format gives the same triangles (positions
 *   bit for bit, in the same order), the same emitters and the same camera
 *   (the OBJ file has none: it gets the others' through the API).
 * - The same image: where the materials map exactly (MTL's Lambert, JSON's,
 *   Mitsuba's and pbrt's diffuse: all a Lambert of the same albedo) the
 *   path-traced images are compared bit for bit. glTF's material is another
 *   model (metallic-roughness at metallic 0, roughness 1 has a dielectric
 *   specular layer a Lambert lacks), so the glTF file is compared with its
 *   JSON twin of the same model, box_mr.json; where a camera reaches the
 *   renderer through another formula (glTF's yfov in radians, pbrt's fov of
 *   the shorter axis) the images may differ in the last bits, and are then
 *   compared block by block within Z standard errors measured from two
 *   seeds of each.
 */
#include "test.h"

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

static pk_scene *load(const char *file)
{
    char path[512];
    snprintf(path, sizeof path, "%s/conformance/%s", PK_TEST_DATA, file);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_file(ctx, path, &s);
    CHECKF(st == PK_OK, "%s: %s", file, pk_context_error(ctx));
    REQUIRE(st == PK_OK);
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
    pk_scene *obj = load("box.obj"), *json = load("box.json"), *xml = load("box.xml"), *pbrt = load("box.pbrt"),
             *gltf = load("box.gltf");
    pk_camera cam;
    pk_scene_get_camera(json, &cam);
    REQUIRE(pk_scene_set_camera(ctx, obj, &cam) == PK_OK);

    same_geometry("JSON", obj, json);
    same_geometry("Mitsuba XML", obj, xml);
    same_geometry("pbrt-v4", obj, pbrt);
    same_geometry("glTF", obj, gltf);
    const struct {
        const char *name;
        const pk_scene *s;
    } cams[] = {{"Mitsuba XML", xml}, {"pbrt-v4", pbrt}, {"glTF", gltf}};
    for (size_t i = 0; i < 3; i++) {
        pk_camera c;
        pk_scene_get_camera(cams[i].s, &c);
        /* the same eye, view direction and field of view (look_at may lie
         * elsewhere on the line of sight) */
        double d = fabs((double)c.fov_deg - (double)cam.fov_deg), da[3], db[3], la = 0, lb = 0;
        for (int k = 0; k < 3; k++) {
            d += fabs((double)c.look_from[k] - (double)cam.look_from[k]);
            da[k] = (double)c.look_at[k] - (double)c.look_from[k], la += da[k] * da[k];
            db[k] = (double)cam.look_at[k] - (double)cam.look_from[k], lb += db[k] * db[k];
        }
        for (int k = 0; k < 3; k++) d += fabs(da[k] / sqrt(la) - db[k] / sqrt(lb));
        CHECKF(d < 1e-4, "%s: camera from (%g %g %g) to (%g %g %g), fov %g", cams[i].name, (double)c.look_from[0],
               (double)c.look_from[1], (double)c.look_from[2], (double)c.look_at[0], (double)c.look_at[1],
               (double)c.look_at[2], (double)c.fov_deg);
    }

    pk_image *o1 = render(obj, 1), *o2 = render(obj, 2);
    pk_image *j1 = render(json, 1), *x1 = render(xml, 1);
    CHECKF(same_bits(o1, j1), "JSON: not the OBJ's image bit for bit");
    CHECKF(same_bits(o1, x1), "Mitsuba XML: not the OBJ's image bit for bit");
    pk_image *p1 = render(pbrt, 1), *p2 = render(pbrt, 2);
    const bool pbits = same_bits(o1, p1);
    printf("  pbrt-v4: %s\n", pbits ? "the same bits" : "not the same bits (compared by blocks)");
    if (!pbits) CHECK(compare_blocks("pbrt-v4", o1, o2, p1, p2) == 0);
    pk_scene *mr = load("box_mr.json");
    same_geometry("glTF against its JSON twin", mr, gltf);
    pk_image *m1 = render(mr, 1), *m2 = render(mr, 2), *g1 = render(gltf, 1), *g2 = render(gltf, 2);
    const bool gbits = same_bits(m1, g1);
    printf("  glTF: %s\n", gbits ? "the same bits as its JSON twin" : "not the same bits (compared by blocks)");
    if (!gbits) CHECK(compare_blocks("glTF", m1, m2, g1, g2) == 0);
    /* and the two material models differ where they should: a little, at grazing angles */
    double so = 0.0, sm = 0.0;
    for (int i = 0; i < 3 * SIZE * SIZE; i++)
        so += (double)pk_image_pixels_const(o1)[i], sm += (double)pk_image_pixels_const(m1)[i];
    printf("  metallic-roughness (metallic 0, roughness 1) against Lambert: image mean %+.2f %%\n", 100.0 * (sm / so - 1.0));
    pk_scene_destroy(mr);
    pk_image *imgs[] = {o1, o2, j1, x1, p1, p2, g1, g2, m1, m2};
    for (size_t i = 0; i < sizeof imgs / sizeof *imgs; i++) pk_image_destroy(imgs[i]);
    pk_scene *scenes[] = {obj, json, xml, pbrt, gltf};
    for (size_t i = 0; i < 5; i++) pk_scene_destroy(scenes[i]);
    pk_context_destroy(ctx);
    return test_done("test_conformance");
}

/*
 * test_xml_scenes.c - the public Mitsuba scenes of ../shared/scenes (Bitterli's
 * Cornell box, "Veach, MIS" and classroom; the Mitsuba "Veach door") load
 * with the triangle counts their sources list and render small images without
 * NaN or negative values; the Cornell box has its red wall on the left, its
 * green wall on the right and its lamp at the top centre. Skipped when
 * ../shared is absent. First the principled scenes of tests/data/xml (which
 * need no ../shared): they load without warnings and render finite values;
 * the leaf of principledthin lit from behind glows green.
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"

static warning_log warnings;

/* Loads rel, renders it at w x h with spp samples; NULL image on failure. */
static pk_image *render(pk_context *ctx, const char *rel, int w, int h, int spp, pk_scene_info *info)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", PK_SHARED_DIR, rel);
    pk_scene *s = NULL;
    warning_log_clear(&warnings);
    if (pk_scene_load_file(ctx, path, &s) != PK_OK) {
        fprintf(stderr, "%s: %s\n", rel, pk_context_error(ctx));
        test_failures++;
        return NULL;
    }
    pk_scene_get_info(s, info);
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.width = w, o.height = h, o.spp = spp, o.threads = 0;
    if (o.max_depth > 8) o.max_depth = 8;
    pk_image *img = NULL;
    if (pk_render(ctx, s, &o, &img, NULL) != PK_OK) {
        fprintf(stderr, "%s: %s\n", rel, pk_context_error(ctx));
        test_failures++;
    }
    pk_scene_destroy(s);
    return img;
}

/* Every value finite and not negative; returns the mean. */
static double check_values(const pk_image *img, const char *what)
{
    const float *p = pk_image_pixels_const(img);
    size_t n = (size_t)pk_image_width(img) * (size_t)pk_image_height(img) * 3;
    double sum = 0.0;
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(p[i]) || p[i] < 0.0f) bad++;
        else sum += (double)p[i];
    }
    CHECKF(bad == 0, "%s: %zu values NaN, infinite or negative", what, bad);
    return sum / (double)n;
}

/* Mean colour of the pixels [x0, x1) x [y0, y1). */
static void region(const pk_image *img, int x0, int x1, int y0, int y1, double c[3])
{
    const float *p = pk_image_pixels_const(img);
    int w = pk_image_width(img);
    c[0] = c[1] = c[2] = 0.0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            for (int k = 0; k < 3; k++) c[k] += (double)p[3 * (y * w + x) + k];
    for (int k = 0; k < 3; k++) c[k] /= (double)((x1 - x0) * (y1 - y0));
}

/* tests/data/xml's principled and principledthin scenes */
static void test_principled_scenes(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    warnings.echo = true;
    static const char *const files[] = {"xml/principled_spheres.xml", "xml/principledthin_sheets.xml"};
    for (int i = 0; i < 2; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", PK_TEST_DATA, files[i]);
        pk_scene *s = NULL;
        warning_log_clear(&warnings);
        if (pk_scene_load_file(ctx, path, &s) != PK_OK) {
            fprintf(stderr, "%s: %s\n", files[i], pk_context_error(ctx));
            test_failures++;
            continue;
        }
        pk_scene_info info;
        pk_scene_get_info(s, &info);
        printf("%s: %d spheres, %d triangles, %d warnings\n", files[i], (int)info.spheres, (int)info.triangles,
               warnings.count);
        CHECK(warnings.count == 0);
        /* the anisotropic sphere is tessellated (its tangents follow Mitsuba's uv) */
        if (i == 0) CHECK(info.spheres == 4 && info.triangles > 1000);
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        o.width = 80, o.height = 50, o.spp = 32, o.threads = 0;
        pk_image *img = NULL;
        if (pk_render(ctx, s, &o, &img, NULL) != PK_OK) {
            fprintf(stderr, "%s: %s\n", files[i], pk_context_error(ctx));
            test_failures++;
        } else {
            CHECK(check_values(img, files[i]) > 0.01);
            if (i == 1) { /* the left sheet, seen from the side away from the lamp */
                double leaf[3];
                region(img, 8, 30, 14, 34, leaf);
                printf("principledthin leaf: %.3f %.3f %.3f\n", leaf[0], leaf[1], leaf[2]);
                CHECKF(leaf[1] > 1.5 * leaf[0] && leaf[1] > 1.5 * leaf[2], "leaf %g %g %g", leaf[0], leaf[1], leaf[2]);
            }
            pk_image_destroy(img);
        }
        pk_scene_destroy(s);
    }
    pk_context_destroy(ctx);
}

int main(void)
{
    test_principled_scenes();
    char buf[1024];
    shared_path(buf, sizeof buf, "scenes/bitterli/cornell-box/scene_v3.xml");
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    warnings.echo = true;
    pk_scene_info info;

    pk_image *img = render(ctx, "scenes/bitterli/cornell-box/scene_v3.xml", 64, 64, 16, &info);
    if (img) {
        /* 6 rectangles and 2 cubes: 6 * 2 + 2 * 12 triangles, the lamp's 2 emissive */
        CHECK(info.triangles == 36 && info.emissive_triangles == 2 && info.has_camera);
        CHECK(warnings.count == 0);
        check_values(img, "cornell-box");
        double left[3], right[3], lamp[3];
        region(img, 1, 8, 16, 48, left);
        region(img, 56, 63, 16, 48, right);
        region(img, 28, 36, 3, 7, lamp);
        CHECKF(left[0] > 3.0 * left[1] && left[0] > 3.0 * left[2], "left wall %g %g %g", left[0], left[1], left[2]);
        CHECKF(right[1] > 1.5 * right[0] && right[1] > 1.5 * right[2], "right wall %g %g %g", right[0], right[1], right[2]);
        /* the lamp seen directly: radiance 17 12 4 where the lamp covers the pixels */
        CHECKF(lamp[0] > 5.0 && lamp[0] > lamp[2], "lamp %g %g %g", lamp[0], lamp[1], lamp[2]);
        pk_image_destroy(img);
    }

    img = render(ctx, "scenes/bitterli/veach-mis/scene.xml", 64, 36, 4, &info);
    if (img) {
        /* 4 cubes and 2 rectangles; the 3 lamps are spheres */
        CHECK(info.triangles == 4 * 12 + 2 * 2 && info.spheres == 3 && warnings.count == 0);
        CHECK(check_values(img, "veach-mis") > 0.01);
        pk_image_destroy(img);
    }

    img = render(ctx, "scenes/bitterli/classroom/scene_v0.6.xml", 32, 18, 1, &info);
    if (img) {
        /* 103,832 triangles in the 79 meshes (SOURCES.md); lit by a sun and sky only */
        CHECK(info.triangles == 103832 && info.emissive_triangles == 0 && info.has_camera);
        check_values(img, "classroom");
        pk_image_destroy(img);
    }

    img = render(ctx, "scenes/mitsuba/veach-door/scene.xml", 32, 18, 1, &info);
    if (img) {
        /* 20,764 triangles in the 22 meshes (SOURCES.md), the lamp among them */
        CHECK(info.triangles == 20764 && info.emissive_triangles > 0 && info.has_camera);
        check_values(img, "veach-door");
        pk_image_destroy(img);
    }
    pk_context_destroy(ctx);
    return test_done("test_xml_scenes");
}

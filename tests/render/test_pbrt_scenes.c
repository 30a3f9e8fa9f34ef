/*
 * test_pbrt_scenes.c - the pbrt-v4 scenes of ../shared/scenes/pbrt-v4 against
 * what they must render: Bitterli's Cornell box in pbrt-v4 form renders the
 * image of the same scene in Mitsuba form (../shared/scenes/bitterli): the
 * mean difference of every channel, and of every 16 x 16 block, within its
 * confidence interval,
 * the red wall on the left (the image is not mirrored); the material test
 * ball loads with its meshes and renders finite values. Skipped when
 * ../shared is absent.
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"

#include <math.h>

static warning_log warnings;

static pk_image *render(pk_context *ctx, const char *rel, int w, int h, int spp, int seed, pk_scene_info *info)
{
    char path[1024];
    shared_path(path, sizeof path, rel);
    pk_scene *s = NULL;
    if (pk_scene_load_file(ctx, path, &s) != PK_OK) {
        fprintf(stderr, "%s: %s\n", rel, pk_context_error(ctx));
        test_failures++;
        return NULL;
    }
    if (info) pk_scene_get_info(s, info);
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.width = w, o.height = h, o.spp = spp, o.threads = 0, o.seed = seed;
    if (o.max_depth > 8) o.max_depth = 8;
    pk_image *img = NULL;
    if (pk_render(ctx, s, &o, &img, NULL) != PK_OK) {
        fprintf(stderr, "%s: %s\n", rel, pk_context_error(ctx));
        test_failures++;
    }
    pk_scene_destroy(s);
    return img;
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

int main(void)
{
    char buf[1024];
    shared_path(buf, sizeof buf, "scenes/pbrt-v4/cornell-box/scene-v4.pbrt");
    shared_path(buf, sizeof buf, "scenes/bitterli/cornell-box/scene_v3.xml");
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    warnings.echo = true;

    const int W = 64, H = 64, SPP = 64;
    pk_scene_info ia, ib;
    /* different seeds: the two estimates are independent */
    pk_image *a = render(ctx, "scenes/pbrt-v4/cornell-box/scene-v4.pbrt", W, H, SPP, 1, &ia);
    pk_image *b = render(ctx, "scenes/bitterli/cornell-box/scene_v3.xml", W, H, SPP, 2, &ib);
    if (a && b) {
        CHECKF(ia.triangles == ib.triangles, "%zu triangles against %zu", (size_t)ia.triangles, (size_t)ib.triangles);
        const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b);
        for (int c = 0; c < 3; c++) {
            /* the per-pixel differences are independent samples of a zero mean */
            double s = 0.0, s2 = 0.0, ma = 0.0;
            const int n = W * H;
            for (int i = 0; i < n; i++) {
                double d = (double)pa[3 * i + c] - (double)pb[3 * i + c];
                s += d, s2 += d * d, ma += (double)pa[3 * i + c];
            }
            double mean = s / n, var = (s2 - s * s / n) / (n - 1), se = sqrt(var / n);
            ma /= n;
            printf("channel %d: mean %.5f, difference %.6f +- %.6f (3.3 standard errors %.6f)\n", c, ma, mean, se,
                   3.3 * se);
            CHECKF(fabs(mean) <= 3.3 * se + 1e-4 * ma, "channel %d: mean difference %.6f beyond 3.3 x %.6f", c, mean, se);
            CHECK(ma > 0.02);
        }
        /* and every 16 x 16 block, within 4 standard errors (48 comparisons:
         * a false alarm once in about 300 runs), which a mirrored or shifted
         * image fails */
        for (int by = 0; by < H; by += 16)
            for (int bx = 0; bx < W; bx += 16)
                for (int c = 0; c < 3; c++) {
                    double s = 0.0, s2 = 0.0;
                    for (int y = by; y < by + 16; y++)
                        for (int x = bx; x < bx + 16; x++) {
                            int i = y * W + x;
                            double d = (double)pa[3 * i + c] - (double)pb[3 * i + c];
                            s += d, s2 += d * d;
                        }
                    const int n = 256;
                    double mean = s / n, se = sqrt((s2 - s * s / n) / (n - 1) / n);
                    CHECKF(fabs(mean) <= 4.0 * se + 1e-5, "block (%d, %d) channel %d: difference %.5f, standard error %.5f",
                           bx, by, c, mean, se);
                }
        /* not mirrored: the red wall on the left, the green one on the right */
        double l[3], r[3];
        region(a, 1, 6, 20, 44, l);
        region(a, W - 6, W - 1, 20, 44, r);
        CHECKF(l[0] > 2.0 * l[1] && r[1] > 1.5 * r[0], "left %.3f %.3f %.3f, right %.3f %.3f %.3f", l[0], l[1], l[2],
               r[0], r[1], r[2]);
    }
    pk_image_destroy(a);
    pk_image_destroy(b);

    /* the material test ball: its three PLY meshes and the floor */
    pk_scene_info it;
    pk_image *t = render(ctx, "scenes/pbrt-v4/material-testball/scene-v4.pbrt", 48, 27, 4, 0, &it);
    if (t) {
        CHECKF(it.triangles > 10000, "%zu triangles", (size_t)it.triangles);
        const float *p = pk_image_pixels_const(t);
        size_t bad = 0;
        for (size_t i = 0; i < 48 * 27 * 3; i++) bad += !isfinite(p[i]) || p[i] < 0.0f;
        CHECK(bad == 0);
    }
    pk_image_destroy(t);
    pk_context_destroy(ctx);
    return test_done("test_pbrt_scenes");
}

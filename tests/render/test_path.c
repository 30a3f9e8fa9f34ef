/*
 * test_path.c - the path tracer against closed forms, through the public API.
 *
 * Furnaces: inside a closed box whose faces all emit radiance E and reflect
 * diffusely with albedo r, the radiance is E / (1 - r) everywhere, in every
 * direction; the same holds for a sphere of that material inside a closed
 * sphere of it. Each pixel of a render is the mean of spp independent
 * samples of that radiance, so the image's pixels are draws of one
 * distribution: their mean must lie within z standard errors of E / (1 - r),
 * and every pixel within z_all standard deviations, with the standard
 * deviation measured on the image itself (no tolerance is set by hand).
 *
 * Determinism: the same pixels at 1 and 2 threads, for any tiling, and for
 * passes of fewer samples added into one film.
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"

#include <stdbool.h>
#include <stdint.h>

static pk_context *ctx;

/* z for the mean: two-sided p = 1e-4. z for all P pixels at once: two-sided
 * p = 1e-3 / P (Bonferroni), here P = 16 x 16 = 256: Phi^-1(1 - 0.001 / 512).
 * A pixel is a mean of FURNACE_SPP samples of a skewed (path length) sum,
 * near enough to normal at that count for these quantiles. */
#define Z_MEAN 3.89
#define Z_ALL_256 4.62
#define FURNACE_SIZE 16
#define FURNACE_SPP 256

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    REQUIRE(f);
    fputs(text, f);
    fclose(f);
}

/* A closed box [-1,1]^3 of one material (Kd r, Ke E) with every face wound to
 * face inward (one-sided emitters light the inside). */
static pk_scene *furnace_box(const char *dir, float r, float e)
{
    char path[512], text[4096], mtl[256];
    snprintf(mtl, sizeof mtl, "newmtl f\nKd %g %g %g\nKe %g %g %g\n", (double)r, (double)r, (double)r, (double)e,
             (double)e, (double)e);
    snprintf(path, sizeof path, "%s/furnace.mtl", dir);
    write_file(path, mtl);
    size_t n = (size_t)snprintf(text, sizeof text, "mtllib furnace.mtl\nusemtl f\n");
    for (int i = 0; i < 8; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "v %d %d %d\n", (i & 1) ? 1 : -1, (i & 2) ? 1 : -1,
                              (i & 4) ? 1 : -1);
    /* faces as corner quads; each is wound so that its normal points at the centre */
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int q = 0; q < 6; q++) {
        int v[4];
        for (int k = 0; k < 4; k++) v[k] = quads[q][k];
        /* normal of (v0, v1, v2) against the direction to the centre */
        float p[4][3];
        for (int k = 0; k < 4; k++) {
            p[k][0] = (v[k] & 1) ? 1.0f : -1.0f, p[k][1] = (v[k] & 2) ? 1.0f : -1.0f, p[k][2] = (v[k] & 4) ? 1.0f : -1.0f;
        }
        float e1[3], e2[3], nn[3];
        for (int k = 0; k < 3; k++) e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1], nn[1] = e1[2] * e2[0] - e1[0] * e2[2], nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        float d = -(nn[0] * p[0][0] + nn[1] * p[0][1] + nn[2] * p[0][2]); /* n . (centre - p0) */
        if (d < 0.0f) {
            int t = v[1];
            v[1] = v[3], v[3] = t;
        }
        n += (size_t)snprintf(text + n, sizeof text - n, "f %d %d %d %d\n", v[0] + 1, v[1] + 1, v[2] + 1, v[3] + 1);
    }
    snprintf(path, sizeof path, "%s/furnace.obj", dir);
    write_file(path, text);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
    pk_camera cam = {{0.1f, 0.2f, 0.3f}, {0.5f, -0.3f, -1.0f}, {0, 1, 0}, 70.0f, 0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    REQUIRE(pk_scene_set_camera(ctx, s, &cam) == PK_OK);
    return s;
}

static pk_scene *furnace_spheres(float r, float e)
{
    char text[1024];
    snprintf(text, sizeof text,
             "{\"materials\": {\"f\": {\"kd\": [%g, %g, %g], \"ke\": [%g, %g, %g], \"two_sided\": true}},"
             " \"camera\": {\"look_from\": [0, 1, 5], \"look_at\": [0, 0, -4], \"fov\": 50},"
             " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 10, \"material\": \"f\"},"
             "               {\"center\": [0, 0, -4], \"radius\": 2, \"material\": \"f\"}]}",
             (double)r, (double)r, (double)r, (double)e, (double)e, (double)e);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, text, strlen(text), "spheres.json", ".", &s) == PK_OK);
    return s;
}

static pk_image *render_path(const pk_scene *s, int size, int spp, int threads, int seed)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = o.height = size;
    o.spp = spp;
    o.max_depth = 64;
    o.threads = threads;
    o.seed = seed;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    return img;
}

static void check_furnace(const char *name, const pk_scene *s, float r, float e)
{
    const double want = (double)e / (1.0 - (double)r);
    pk_image *img = render_path(s, FURNACE_SIZE, FURNACE_SPP, 2, 1);
    const float *px = pk_image_pixels_const(img);
    const size_t P = FURNACE_SIZE * FURNACE_SIZE;
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < P; i++) { /* the luminance channel is as good as any: all are equal */
        double v = (double)px[3 * i + 1];
        sum += v, sum2 += v * v;
    }
    const double mean = sum / (double)P, var = (sum2 - sum * sum / (double)P) / (double)(P - 1);
    const double sd = sqrt(var > 0.0 ? var : 0.0), se = sd / sqrt((double)P);
    size_t outside = 0;
    for (size_t i = 0; i < P; i++)
        if (fabs((double)px[3 * i + 1] - want) > Z_ALL_256 * sd) outside++;
    printf("%s (albedo %.2f, E %.2f): mean %.5f, want %.5f, |diff| = %.2f standard errors (sd %.4f)\n", name,
           (double)r, (double)e, mean, want, fabs(mean - want) / se, sd);
    CHECKF(sd > 0.0, "%s: no noise at all: the estimator is not sampling", name);
    CHECKF(fabs(mean - want) <= Z_MEAN * se, "%s: mean %.5f, want %.5f (%.2f standard errors)", name, mean, want,
           fabs(mean - want) / se);
    CHECKF(outside == 0, "%s: %zu pixels beyond %.2f standard deviations", name, outside, Z_ALL_256);
    pk_image_destroy(img);
}

static bool same_image(const pk_image *a, const pk_image *b)
{
    return memcmp(pk_image_pixels_const(a), pk_image_pixels_const(b),
                  sizeof(float) * 3 * (size_t)pk_image_width(a) * (size_t)pk_image_height(a)) == 0;
}

static void check_determinism(void)
{
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    pk_image *a = render_path(s, 40, 3, 1, 7), *b = render_path(s, 40, 3, 2, 7), *c = render_path(s, 40, 3, 2, 8);
    CHECK(same_image(a, b));  /* threads */
    CHECK(!same_image(a, c)); /* another seed, other noise */
    /* a tiling: four regions in one film */
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = o.height = 40;
    o.spp = 3;
    o.max_depth = 64;
    o.threads = 2;
    o.seed = 7;
    pk_renderer *r = NULL;
    pk_film *f = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    REQUIRE(pk_film_create(ctx, 40, 40, &f) == PK_OK);
    const pk_region reg[4] = {{0, 0, 13, 40}, {13, 0, 27, 7}, {13, 7, 27, 33}, {0, 0, 0, 0}};
    CHECK(pk_renderer_render(r, reg, 3, f) == PK_OK);
    pk_image *t = NULL;
    REQUIRE(pk_film_resolve(ctx, f, &t) == PK_OK);
    CHECK(same_image(a, t));
    pk_image_destroy(t);
    pk_film_destroy(f);
    pk_renderer_destroy(r);
    /* progressive: passes 0, 1, 2 of 1 spp into one film are the samples
     * 0, 1, 2 of a 3-spp render, added in the same order: the same bits */
    o.spp = 1;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    REQUIRE(pk_film_create(ctx, 40, 40, &f) == PK_OK);
    for (uint32_t pass = 0; pass < 3; pass++) {
        pk_renderer_set_pass(r, pass);
        CHECK(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    }
    REQUIRE(pk_film_resolve(ctx, f, &t) == PK_OK);
    CHECK(same_image(a, t));
    pk_image_destroy(t);
    pk_film_destroy(f);
    pk_renderer_destroy(r);
    pk_image_destroy(a), pk_image_destroy(b), pk_image_destroy(c);
    pk_scene_destroy(s);
}


/* A floor under a light quad: wound to face the floor, no warning; wound to
 * face the sky, the warning that it faces away from the scene. */
static void check_facing_warning(const char *dir)
{
    const char *mtl = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n";
    char path[600];
    snprintf(path, sizeof path, "%s/lamp.mtl", dir);
    write_file(path, mtl);
    for (int up = 0; up < 2; up++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "mtllib lamp.mtl\nv -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n"
                 "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
                 "usemtl floor\nf 1 4 3 2\nusemtl lamp\n%s\n",
                 up ? "f 5 8 7 6" : "f 5 6 7 8");
        snprintf(path, sizeof path, "%s/lamp.obj", dir);
        write_file(path, text);
        pk_scene *s = NULL;
        REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
        warning_log w;
        warning_log_attach(ctx, &w);
        pk_image *img = render_path(s, 8, 1, 1, 0);
        pk_context_set_warning_handler(ctx, NULL, NULL);
        const int facing = warning_log_count(&w, "every area light faces away from the scene");
        CHECKF(facing == up, "lamp wound to face %s: %d warnings", up ? "up" : "down", facing);
        pk_image_destroy(img);
        pk_scene_destroy(s);
        remove(path);
    }
    snprintf(path, sizeof path, "%s/lamp.mtl", dir);
    remove(path);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    char dir[] = "/tmp/paprsek-furnace-XXXXXX";
    REQUIRE(mkdtemp(dir));
    const float albedo[] = {0.5f, 0.8f};
    for (int k = 0; k < 2; k++) {
        pk_scene *box = furnace_box(dir, albedo[k], 1.0f);
        check_furnace("box furnace", box, albedo[k], 1.0f);
        pk_scene_destroy(box);
        pk_scene *sph = furnace_spheres(albedo[k], 0.5f);
        check_furnace("sphere furnace", sph, albedo[k], 0.5f);
        pk_scene_destroy(sph);
    }
    check_facing_warning(dir);
    char path[600];
    snprintf(path, sizeof path, "%s/furnace.obj", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/furnace.mtl", dir);
    remove(path);
    rmdir(dir);
    check_determinism();
    pk_context_destroy(ctx);
    return test_done("test_path");
}

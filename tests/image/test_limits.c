/*
 * test_limits.c - the bounds of a render (issue 4): every option out of
 * range is refused with its exact message, the ray tree of a pathological
 * scene (glass inside a closed mirror, depth 64) stays within the ray budget,
 * a cancelled render returns its finished tiles, cameras at the ends of the
 * float range are handled, and an image write that fails leaves the
 * existing file and no temporary file.
 */
#include "test.h"

#include "paprsek.h"
#include "render/whitted.h"

#include <dirent.h>

static pk_context *ctx;

/* Renders with one option changed by set(); checks status and exact message. */
static void expect_refused(const pk_scene *s, void (*set)(pk_render_options *), pk_status want, const char *msg)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = 8;
    set(&o);
    pk_image *img = (pk_image *)&o; /* must be reset to NULL */
    pk_status st = pk_render(ctx, s, &o, &img, NULL);
    CHECKF(st == want, "status %d, wanted %d", (int)st, (int)want);
    CHECK(img == NULL);
    CHECKF(strcmp(pk_context_error(ctx), msg) == 0, "got \"%s\" want \"%s\"", pk_context_error(ctx), msg);
    pk_context_clear_error(ctx);
}

static void w0(pk_render_options *o) { o->width = 0; }
static void h_big(pk_render_options *o) { o->height = PK_MAX_IMAGE_SIDE + 1; }
static void pixels(pk_render_options *o) { o->width = o->height = PK_MAX_IMAGE_SIDE; }
static void spp_big(pk_render_options *o) { o->spp = PK_MAX_SPP + 1; }
static void spp0(pk_render_options *o) { o->spp = 0; }
static void ls_big(pk_render_options *o) { o->light_samples = PK_MAX_LIGHT_SAMPLES + 1; }
static void depth_big(pk_render_options *o) { o->max_depth = PK_MAX_DEPTH + 1; }
static void depth_neg(pk_render_options *o) { o->max_depth = -2; }
static void threads_big(pk_render_options *o) { o->threads = PK_MAX_THREADS + 1; }
static void accel_bad(pk_render_options *o) { o->accel = (pk_accel_kind)99; }

static void test_options(const pk_scene *s)
{
    expect_refused(s, w0, PK_ERR_LIMIT, "width 0 is out of range (1..16384)");
    expect_refused(s, h_big, PK_ERR_LIMIT, "height 16385 is out of range (1..16384)");
    expect_refused(s, pixels, PK_ERR_LIMIT, "image of 16384x16384 pixels is larger than 67108864 pixels");
    expect_refused(s, spp_big, PK_ERR_LIMIT, "samples per pixel 65537 is out of range (1..65536)");
    expect_refused(s, spp0, PK_ERR_LIMIT, "samples per pixel 0 is out of range (1..65536)");
    expect_refused(s, ls_big, PK_ERR_LIMIT, "light samples 4097 is out of range (0..4096)");
    expect_refused(s, depth_big, PK_ERR_LIMIT, "max depth 1025 is out of range (-1..1024)");
    expect_refused(s, depth_neg, PK_ERR_LIMIT, "max depth -2 is out of range (-1..1024)");
    expect_refused(s, threads_big, PK_ERR_LIMIT, "threads 1025 is out of range (0..1024)");
    expect_refused(s, accel_bad, PK_ERR_INVALID_ARGUMENT, "unknown accelerator 99");

    pk_image *img = NULL;
    CHECK(pk_image_create(ctx, 16385, 1, &img) == PK_ERR_LIMIT && img == NULL);
    CHECKF(strcmp(pk_context_error(ctx),
                  "image size 16385x1 is out of range (1..16384 per side, at most 67108864 pixels)") == 0,
           "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
}

/* A glass ball inside a closed mirror ball, seen from inside: no ray ever
 * escapes and every hit on the glass branches in two. */
static const char *hall_of_mirrors =
    "{ \"materials\": { \"mirror\": { \"kd\": [0, 0, 0], \"ks\": [1, 1, 1], \"illum\": 3 },\n"
    "                 \"glass\": { \"kd\": [0, 0, 0], \"ni\": 1.5, \"illum\": 7 } },\n"
    "  \"spheres\": [ { \"center\": [0, 0, 0], \"radius\": 3, \"material\": \"mirror\" },\n"
    "               { \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"glass\" } ],\n"
    "  \"lights\": [ { \"position\": [0, 2, 0], \"intensity\": 1 } ],\n"
    "  \"camera\": { \"look_from\": [0, 0.2, 2.5], \"look_at\": [0, 0, 0] } }\n";

static void test_ray_budget(void)
{
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, hall_of_mirrors, strlen(hall_of_mirrors), "hall.json", ".", &s) ==
            PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_WHITTED; /* its ray tree is what the budget bounds */
    o.width = o.height = 8;
    o.threads = 1;
    o.collect_stats = 1;
    pk_stats st8, st64;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, &st8) == PK_OK);
    pk_image_destroy(img);
    o.max_depth = PK_MAX_DEPTH;
    REQUIRE(pk_render(ctx, s, &o, &img, &st64) == PK_OK);
    pk_image_destroy(img);
    uint64_t sec8 = st8.rays_reflection + st8.rays_refraction, sec64 = st64.rays_reflection + st64.rays_refraction;
    /* depth 8: the whole tree is traced (at most 510 rays per camera ray) */
    CHECKF(sec8 > st8.rays_camera * 50 && sec8 <= st8.rays_camera * 510, "%llu secondary rays at depth 8",
           (unsigned long long)sec8);
    /* depth 64: the budget binds, instead of up to 2^64 rays per camera ray */
    CHECKF(sec64 <= st64.rays_camera * WHITTED_RAY_BUDGET && sec64 > st64.rays_camera * 2000,
           "%llu secondary rays for %llu camera rays at depth 64", (unsigned long long)sec64,
           (unsigned long long)st64.rays_camera);
    printf("hall of mirrors, 64 camera rays: %llu secondary rays at depth 8, %llu at depth 64 (budget %d each)\n",
           (unsigned long long)sec8, (unsigned long long)sec64, WHITTED_RAY_BUDGET);
    pk_scene_destroy(s);
}

static void test_cancel(const pk_scene *s)
{
    volatile int stop = 1;
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = 40;
    o.cancel = &stop;
    pk_image *img = NULL;
    CHECK(pk_render(ctx, s, &o, &img, NULL) == PK_ERR_CANCELLED);
    CHECKF(strcmp(pk_context_error(ctx), "render cancelled") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    REQUIRE(img != NULL); /* the finished tiles: none, so black */
    CHECK(pk_image_width(img) == 40 && pk_image_height(img) == 40);
    const float *p = pk_image_pixels_const(img);
    int lit = 0;
    for (int i = 0; i < 40 * 40 * 3; i++) lit += p[i] != 0.0f;
    CHECK(lit == 0);
    pk_image_destroy(img);
}

/* Cameras and scenes at the ends of the float range: a camera 1e30 away is
 * valid (its direction is normalised without overflow), one whose direction
 * overflows is refused by name, and so is a scene too large to frame. */
static void test_far(void)
{
    const char *huge = "v -3e38 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n";
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_obj_memory(ctx, huge, strlen(huge), "huge.obj", NULL, &s) == PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = 8;
    pk_image *img = NULL;
    CHECK(pk_render(ctx, s, &o, &img, NULL) == PK_ERR_LIMIT && img == NULL);
    CHECKF(strcmp(pk_context_error(ctx), "huge.obj: the scene is too large to frame automatically; give it a camera") ==
               0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    pk_camera far = {{0.0f, 1e30f, 1e30f}, {0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 40.0f, 0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    CHECKF(pk_scene_set_camera(ctx, s, &far) == PK_OK, "%s", pk_context_error(ctx));
    pk_camera apart = {{0.0f, 0.0f, 3e38f}, {0.0f, 0.0f, -3e38f}, {0.0f, 1.0f, 0.0f}, 40.0f, 0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    CHECK(pk_scene_set_camera(ctx, s, &apart) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strcmp(pk_context_error(ctx), "camera: look_from and look_at are too far apart") == 0, "%s",
           pk_context_error(ctx));
    pk_context_clear_error(ctx);
    pk_camera tiny = {{0.0f, 0.0f, 1e-30f}, {0.0f, 0.0f, 0.0f}, {0.0f, 1e-30f, 0.0f}, 40.0f, 0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    CHECKF(pk_scene_set_camera(ctx, s, &tiny) == PK_OK, "%s", pk_context_error(ctx));
    CHECK(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    pk_image_destroy(img);
    pk_scene_destroy(s);
}

static int count_tmp(const char *dir)
{
    int n = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strstr(e->d_name, ".tmp.")) n++;
    if (d) closedir(d);
    return n;
}

static void test_write(void)
{
    char dir[] = "/tmp/pk_limits_XXXXXX";
    REQUIRE(mkdtemp(dir));
    char path[256], bad[300];
    snprintf(path, sizeof path, "%s/a.png", dir);
    snprintf(bad, sizeof bad, "%s/missing/a.png", dir);
    pk_image *img = NULL;
    REQUIRE(pk_image_create(ctx, 4, 3, &img) == PK_OK);
    CHECK(pk_image_write(ctx, img, path) == PK_OK);
    CHECK(pk_image_write(ctx, img, bad) == PK_ERR_IO);
    char want[400];
    snprintf(want, sizeof want, "%s: cannot create a temporary file beside it: No such file or directory", bad);
    CHECKF(strcmp(pk_context_error(ctx), want) == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(pk_image_write(ctx, img, "x.bmp") == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strcmp(pk_context_error(ctx), "x.bmp: unknown image format (use .png, .pfm or .exr)") == 0, "%s",
           pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(count_tmp(dir) == 0);
    pk_image_destroy(img);
    remove(path);
    rmdir(dir);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    test_options(s);
    test_cancel(s);
    test_ray_budget();
    test_far();
    test_write();
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_limits");
}

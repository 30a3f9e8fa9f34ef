/*
 * test_camera.c - the thin-lens and orthographic cameras (render/camera.h)
 * against closed forms, and the camera fields of the API and the readers.
 *
 * - The lens sampler: the concentric map takes uniform points of the square
 *   to uniform points of the disk (chi-square over equal-area cells), for
 *   independent uniform input and for the path tracer's own lens samples
 *   (path_camera_place: the sampler's lens dimensions).
 * - The pinhole is the same code as before lenses existed: its rays equal,
 *   bit for bit, those of the formula it always had, whatever the lens
 *   sample says.
 * - Geometry: every ray of a film point passes through one point of the
 *   plane in focus and starts on the lens disk; orthographic rays are
 *   parallel, from the plane of the eye.
 * - The circle of confusion: an emitting sphere at distance z, the focus at
 *   zf, a lens of radius R: its image is a uniform disk of radius
 *   rc = R |z - zf| / (z zf) (image-plane units, the film at distance 1)
 *   convolved with the sphere's own disk (radius rs); the intensity-weighted
 *   second moment of the rendered image about the centre must be
 *   (rc^2 + rs^2) / 2, plus the 1/6 px^2 of the pixels' own square. The
 *   orthographic lens: rc = R |zf - z| / zf in scene units. In focus: as
 *   sharp as the pinhole.
 * - The orthographic image of a plane: an emitting rectangle whose edges
 *   fall at known fractions of pixels gives exactly those coverages, at
 *   any distance, and tilted about the vertical axis with the same
 *   projected outline gives the same image (no perspective).
 * - JSON and Mitsuba XML (thinlens, orthographic) fields, pk_camera_init
 *   defaults, pk_scene_set_camera's messages.
 */
#include "test.h"
#include "warnings.h"

#include "chi2.h"
#include "paprsek.h"

/* the path tracer's camera placement, with no tracing (never called here) */
#define PATH_TRACE(pt, t, r, h) ((void)(pt), (void)(t), (void)(r), (void)(h), false)
#define PATH_OCCLUDED(pt, t, r) ((void)(pt), (void)(t), (void)(r), false)
#include "render/path_kernel.h"

#include <stdint.h>
#include <unistd.h>

#define P_MIN 1e-4 /* chi-square p-value floor per check */

static pk_context *ctx;
static warning_log warnings;

/* ---- the lens sampler ------------------------------------------------------ */

/* Equal-area cells of the unit disk: RINGS rings (equal steps of r^2) of
 * SECTORS sectors. */
#define RINGS 8
#define SECTORS 16

static int disk_cell(float x, float y)
{
    const double r2 = (double)x * (double)x + (double)y * (double)y;
    int ring = (int)(r2 * RINGS);
    if (ring >= RINGS) ring = RINGS - 1;
    double a = atan2((double)y, (double)x);
    if (a < 0.0) a += 2.0 * M_PI;
    int sec = (int)(a / (2.0 * M_PI) * SECTORS);
    if (sec >= SECTORS) sec = SECTORS - 1;
    return ring * SECTORS + sec;
}

static double chi2_disk(const long *cells, long n)
{
    const double e = (double)n / (RINGS * SECTORS);
    double c = 0.0;
    for (int i = 0; i < RINGS * SECTORS; i++) c += ((double)cells[i] - e) * ((double)cells[i] - e) / e;
    return chi2_pvalue(c, RINGS * SECTORS - 1);
}

static void test_disk_map(void)
{
    /* independent uniform input */
    static long cells[RINGS * SECTORS];
    memset(cells, 0, sizeof cells);
    rng r = rng_seed(7, 11);
    const long n = 400000;
    int outside = 0;
    for (long i = 0; i < n; i++) {
        float x, y;
        sample_disk_concentric(rng_float(&r), rng_float(&r), &x, &y);
        if (!(x * x + y * y <= 1.0f + 1e-6f)) outside++;
        cells[disk_cell(x, y)]++;
    }
    double p = chi2_disk(cells, n);
    printf("disk map, uniform input: p = %.4g\n", p);
    CHECKF(outside == 0, "%d points outside the unit disk", outside);
    CHECKF(p > P_MIN, "concentric map: chi-square p = %g", p);
    /* corners and edges of the square: the disk's rim; the centre: its centre */
    float x, y;
    sample_disk_concentric(0.5f, 0.5f, &x, &y);
    CHECK(x == 0.0f && y == 0.0f);
    const float edge[4][2] = {{0.0f, 0.5f}, {0.5f, 0.0f}, {0.0f, 0.0f}, {0x1.fffffep-1f, 0x1.fffffep-1f}};
    for (int k = 0; k < 4; k++) {
        sample_disk_concentric(edge[k][0], edge[k][1], &x, &y);
        CHECK_NEAR(sqrt((double)x * (double)x + (double)y * (double)y), 1.0, 1e-5);
    }

    /* the path tracer's lens samples (the sampler's lens dimensions), over
     * pixels and sample indices */
    path_tracer pt;
    memset(&pt, 0, sizeof pt);
    pt.seed = 3;
    pt.lens = 1;
    memset(cells, 0, sizeof cells);
    long m = 0;
    int same_film = 0;
    for (int py = 0; py < 16; py++)
        for (int px = 0; px < 16; px++)
            for (uint32_t i = 0; i < 1024; i++, m++) {
                const camera_sample cs = path_camera_place(&pt, px, py, i);
                pt.lens = 0;
                const camera_sample c0 = path_camera_place(&pt, px, py, i);
                pt.lens = 1;
                if (cs.film_x == c0.film_x && cs.film_y == c0.film_y && c0.lens_u == 0.5f && c0.lens_v == 0.5f)
                    same_film++;
                sample_disk_concentric(cs.lens_u, cs.lens_v, &x, &y);
                cells[disk_cell(x, y)]++;
            }
    p = chi2_disk(cells, m);
    printf("disk map, the path tracer's lens samples: p = %.4g\n", p);
    CHECKF(p > P_MIN, "lens samples: chi-square p = %g", p);
    CHECKF(same_film == m, "the lens moved %ld film positions", m - same_film);
    /* the first 16 samples of one pixel: a (0,4,2)-net on the lens, so each
     * quarter of the square (a quarter of the disk) holds exactly 4 */
    int quarter[4] = {0, 0, 0, 0};
    for (uint32_t i = 0; i < 16; i++) {
        const camera_sample cs = path_camera_place(&pt, 5, 9, i);
        quarter[(cs.lens_u >= 0.5f) + 2 * (cs.lens_v >= 0.5f)]++;
    }
    CHECKF(quarter[0] == 4 && quarter[1] == 4 && quarter[2] == 4 && quarter[3] == 4, "lens quarters %d %d %d %d",
           quarter[0], quarter[1], quarter[2], quarter[3]);
}

/* ---- rays ------------------------------------------------------------------ */

/* The pinhole's ray as it was computed before lenses existed. */
static ray old_pinhole(const camera_frame *f, const camera_sample *cs)
{
    float sx = (2.0f * cs->film_x / (float)f->width - 1.0f) * f->half_w;
    float sy = (1.0f - 2.0f * cs->film_y / (float)f->height) * f->half_h;
    vec3 d = v3_norm(v3_add(v3_add(v3_scale(f->u, sx), v3_scale(f->v, sy)), v3_neg(f->w)));
    ray r = {f->origin, 0.0f, d, INFINITY};
    return r;
}

static pk_camera camera(float fx, float fy, float fz, float ax, float ay, float az, float fov)
{
    pk_camera c;
    pk_camera_init(&c);
    c.look_from[0] = fx, c.look_from[1] = fy, c.look_from[2] = fz;
    c.look_at[0] = ax, c.look_at[1] = ay, c.look_at[2] = az;
    c.fov_deg = fov;
    return c;
}

static void test_rays(void)
{
    rng r = rng_seed(21, 5);
    /* the pinhole: the old formula bit for bit, and the old frame */
    int differ = 0;
    for (int k = 0; k < 64; k++) {
        pk_camera c = camera(rng_float(&r) * 10 - 5, rng_float(&r) * 10 - 5, rng_float(&r) * 10 - 5,
                             rng_float(&r) * 10 - 5, rng_float(&r) * 10 - 5, rng_float(&r) * 10 - 5,
                             1.0f + 170.0f * rng_float(&r));
        c.focus_distance = (k & 1) ? 3.0f : 0.0f; /* no lens: the focus changes nothing */
        const camera_frame f = camera_setup(&c, 37 + k, 23 + 2 * k);
        CHECK(f.spread == 2.0f * f.half_h / (float)f.height && f.cone0 == 0.0f && !camera_has_lens(&f));
        for (int i = 0; i < 256; i++) {
            const camera_sample cs = {rng_float(&r) * (float)f.width, rng_float(&r) * (float)f.height,
                                      rng_float(&r), rng_float(&r), 1.0f};
            const ray a = camera_ray(&f, &cs), b = old_pinhole(&f, &cs);
            if (memcmp(&a.o, &b.o, sizeof a.o) || memcmp(&a.d, &b.d, sizeof a.d) || a.tmin != b.tmin ||
                a.tmax != b.tmax)
                differ++;
        }
    }
    CHECKF(differ == 0, "%d pinhole rays differ from the old formula", differ);

    /* the thin lens: every ray of a film point meets the plane in focus at
     * the pinhole ray's point there, and starts on the lens disk */
    pk_camera c = camera(1, 2, 3, -2, 0.5f, -1, 50.0f);
    c.lens_radius = 0.3f;
    c.focus_distance = 4.0f;
    camera_frame f = camera_setup(&c, 64, 48);
    CHECK(camera_has_lens(&f) && f.focus == 4.0f);
    double worst_focus = 0.0, worst_lens = 0.0;
    for (int i = 0; i < 1000; i++) {
        const camera_sample cs = {rng_float(&r) * 64, rng_float(&r) * 48, rng_float(&r), rng_float(&r), 1.0f};
        const ray a = camera_ray(&f, &cs), b = old_pinhole(&f, &cs);
        const vec3 off = v3_sub(a.o, f.origin);
        worst_lens = fmax(worst_lens, fabs((double)v3_dot(off, f.w)));
        CHECK(v3_len(off) <= 0.3f * (1.0f + 1e-5f));
        /* the pinhole ray reaches the plane in focus (distance 4 along -w) at
         * t = 4 / (d . -w); the lens ray likewise */
        const vec3 pb = v3_add(b.o, v3_scale(b.d, 4.0f / -v3_dot(b.d, f.w)));
        const vec3 pa = v3_add(a.o, v3_scale(a.d, -(4.0f + v3_dot(off, f.w)) / v3_dot(a.d, f.w)));
        worst_focus = fmax(worst_focus, (double)v3_len(v3_sub(pa, pb)));
        CHECK(fabsf(v3_len(a.d) - 1.0f) < 1e-6f);
    }
    CHECKF(worst_focus < 1e-5 * 4.0, "lens rays miss the point in focus by %g", worst_focus);
    CHECKF(worst_lens < 1e-6, "lens points off the lens plane by %g", worst_lens);
    /* focus_distance 0: the distance to look_at */
    c.focus_distance = 0.0f;
    f = camera_setup(&c, 64, 48);
    CHECK_NEAR(f.focus, sqrt(9.0 + 1.5 * 1.5 + 16.0), 1e-5);

    /* orthographic: parallel rays along -w from the plane of the eye, the
     * view ortho_width wide and as high as the aspect says */
    pk_camera o = camera(0, 0, 5, 0, 0, 0, 30.0f);
    o.projection = PK_PROJECTION_ORTHOGRAPHIC;
    o.ortho_width = 3.0f;
    f = camera_setup(&o, 60, 20);
    CHECK(f.ortho && f.half_w == 1.5f && f.half_h == 0.5f && f.spread == 0.0f && f.cone0 == 3.0f / 60.0f);
    const camera_sample corners[3] = {{0, 0, 0.5f, 0.5f, 1.0f}, {60, 20, 0.1f, 0.9f, 1.0f}, {30, 10, 0.5f, 0.5f, 1.0f}};
    const float want[3][2] = {{-1.5f, 0.5f}, {1.5f, -0.5f}, {0.0f, 0.0f}};
    for (int k = 0; k < 3; k++) {
        const ray a = camera_ray(&f, &corners[k]);
        CHECK(a.d.x == 0.0f && a.d.y == 0.0f && a.d.z == -1.0f && a.o.z == 5.0f);
        CHECK_NEAR(a.o.x, want[k][0], 1e-6);
        CHECK_NEAR(a.o.y, want[k][1], 1e-6);
    }
    /* ortho_width 0: the perspective view's width at look_at */
    o.ortho_width = 0.0f;
    f = camera_setup(&o, 60, 20);
    CHECK_NEAR(f.half_h, 5.0 * tan(15.0 * M_PI / 180.0), 1e-5);
    CHECK_NEAR(f.half_w, 3.0 * 5.0 * tan(15.0 * M_PI / 180.0), 1e-5);
}

/* ---- images ---------------------------------------------------------------- */

static pk_image *render(const pk_scene *s, int w, int h, int spp)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = w, o.height = h, o.spp = spp, o.max_depth = 0, o.threads = 2, o.seed = 1;
    pk_image *img = NULL;
    if (pk_render(ctx, s, &o, &img, NULL) != PK_OK) {
        fprintf(stderr, "render: %s\n", pk_context_error(ctx));
        exit(1);
    }
    return img;
}

/* A scene from JSON text (REQUIRE that it loads). */
static pk_scene *json_scene(const char *text, const char *dir)
{
    pk_scene *s = NULL;
    if (pk_scene_load_json_memory(ctx, text, strlen(text), "camera.json", dir, &s) != PK_OK) {
        fprintf(stderr, "%s\n", pk_context_error(ctx));
        exit(1);
    }
    return s;
}

/* The intensity-weighted second moment (px^2) of an image about its centre,
 * and the centroid's distance from the centre. */
static double second_moment(const pk_image *img, double *off)
{
    const int w = pk_image_width(img), h = pk_image_height(img);
    const float *p = pk_image_pixels_const(img);
    double s = 0.0, sx = 0.0, sy = 0.0, s2 = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const double v = p[3 * ((size_t)y * w + x) + 1], dx = x + 0.5 - 0.5 * w, dy = y + 0.5 - 0.5 * h;
            s += v, sx += v * dx, sy += v * dy, s2 += v * (dx * dx + dy * dy);
        }
    *off = s > 0.0 ? hypot(sx / s, sy / s) : (double)INFINITY;
    return s > 0.0 ? s2 / s : 0.0;
}

/* An emitting sphere of radius rho at distance z straight ahead, seen
 * through a lens of radius R focused at zf (perspective, tan(fov/2) = 1/4, or
 * orthographic ortho_width wide); returns the second moment of its image. */
static double coc_moment(bool ortho, float R, float zf, float z, float rho, int size, double *off)
{
    char text[1024];
    snprintf(text, sizeof text,
             "{\"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [0, 0, -1], \"fov\": %.9g,"
             "  \"lens_radius\": %g, \"focus_distance\": %g %s},"
             " \"materials\": {\"glow\": {\"kd\": [0, 0, 0], \"ke\": [1, 1, 1]}},"
             " \"spheres\": [{\"center\": [0, 0, %g], \"radius\": %g, \"material\": \"glow\"}],"
             " \"environment\": \"none\"}",
             2.0 * atan(0.25) * 180.0 / M_PI, (double)R, (double)zf,
             ortho ? ", \"projection\": \"orthographic\", \"ortho_width\": 0.5" : "", (double)-z, (double)rho);
    pk_scene *s = json_scene(text, ".");
    pk_image *img = render(s, size, size, 256);
    const double m = second_moment(img, off);
    pk_image_destroy(img);
    pk_scene_destroy(s);
    return m;
}

static void test_circle_of_confusion(void)
{
    const int size = 128;
    /* pixels per image-plane unit (perspective) and per scene unit (ortho 0.5 wide) */
    const double ppu = size / (2.0 * 0.25), ppo = size / 0.5;
    struct {
        bool ortho;
        float R, zf, z, rho;
    } cases[] = {
        {false, 0.25f, 2.0f, 4.0f, 0.1f},   /* behind the plane in focus */
        {false, 0.25f, 2.0f, 1.5f, 0.03f},  /* in front of it */
        {false, 0.2f, 3.0f, 9.0f, 0.2f},    /* farther, another lens */
        {true, 0.05f, 2.0f, 4.0f, 0.02f},   /* orthographic with a lens */
        {true, 0.06f, 2.0f, 1.0f, 0.015f},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const double R = cases[k].R, zf = cases[k].zf, z = cases[k].z, rho = cases[k].rho;
        double rc, rs;
        if (!cases[k].ortho) {
            rc = R * fabs(z - zf) / (z * zf) * ppu;
            rs = rho / sqrt(z * z - rho * rho) * ppu; /* the sphere's own disk */
        } else {
            rc = R * fabs(zf - z) / zf * ppo;
            rs = rho * ppo;
        }
        /* (the pixels integrate the image over their square: its second
         * moment grows by the square's, 1/6 px^2) */
        const double want = 0.5 * (rc * rc + rs * rs) + 1.0 / 6.0;
        double off;
        const double got = coc_moment(cases[k].ortho, cases[k].R, cases[k].zf, cases[k].z, cases[k].rho, size, &off);
        printf("circle of confusion %s R %g zf %g z %g: radius %.3f px, second moment %.4f, want %.4f (%.2f %%), "
               "centroid off by %.3f px\n",
               cases[k].ortho ? "ortho" : "persp", R, zf, z, rc, got, want, 100.0 * (got / want - 1.0), off);
        CHECKF(fabs(got / want - 1.0) < 0.015, "case %zu: second moment %g, want %g", k, got, want);
        CHECKF(off < 0.1, "case %zu: centroid %g px off the centre", k, off);
    }
    /* in focus: as sharp as the pinhole's image */
    double off;
    const double sharp = coc_moment(false, 0.25f, 4.0f, 4.0f, 0.1f, size, &off);
    const double pin = coc_moment(false, 0.0f, 4.0f, 4.0f, 0.1f, size, &off);
    printf("in focus: second moment %.4f, pinhole %.4f\n", sharp, pin);
    CHECKF(fabs(sharp - pin) < 0.01 * pin, "in focus: %g against the pinhole's %g", sharp, pin);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    REQUIRE(f);
    fputs(text, f);
    fclose(f);
}

/* An orthographic view 2 wide (128 x 64 pixels of 1/64) of an emitting
 * rectangle in z = zc (tilt: z grows with x by that slope), facing +z:
 * x in [-1 + 48.25/64, -1 + 80.25/64] (columns 49..79 full, 48 three
 * quarters, 80 a quarter), y in [0.5 - 39.5/64, 0.5 - 23.5/64] (rows
 * 24..38 full, 23 and 39 half). */
static pk_image *ortho_rect(const char *dir, float zc, float tilt, int spp)
{
    const double x0 = -1.0 + 48.25 / 64.0, x1 = -1.0 + 80.25 / 64.0, y0 = 0.5 - 39.5 / 64.0, y1 = 0.5 - 23.5 / 64.0;
    char text[1024], path[512];
    snprintf(path, sizeof path, "%s/glow.mtl", dir);
    write_file(path, "newmtl glow\nKd 0 0 0\nKe 1 1 1\n");
    snprintf(text, sizeof text,
             "mtllib glow.mtl\nusemtl glow\nv %.9g %.9g %.9g\nv %.9g %.9g %.9g\nv %.9g %.9g %.9g\nv %.9g %.9g %.9g\n"
             "f 1 2 3 4\n",
             x0, y0, (double)zc + (double)tilt * x0, x1, y0, (double)zc + (double)tilt * x1, x1, y1,
             (double)zc + (double)tilt * x1, x0, y1, (double)zc + (double)tilt * x0);
    snprintf(path, sizeof path, "%s/rect.obj", dir);
    write_file(path, text);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
    pk_camera c = camera(0, 0, 5, 0, 0, 0, 40.0f);
    c.projection = PK_PROJECTION_ORTHOGRAPHIC;
    c.ortho_width = 2.0f;
    REQUIRE(pk_scene_set_camera(ctx, s, &c) == PK_OK);
    REQUIRE(pk_scene_set_environment(ctx, s, NULL) == PK_OK);
    pk_image *img = render(s, 128, 64, spp);
    pk_scene_destroy(s);
    return img;
}

static void test_ortho_plane(void)
{
    char dir[] = "/tmp/pk_camera_XXXXXX";
    REQUIRE(mkdtemp(dir));
    const int spp = 64;
    pk_image *a = ortho_rect(dir, 0.0f, 0.0f, spp), *b = ortho_rect(dir, -3.0f, 0.0f, spp),
             *c = ortho_rect(dir, -1.0f, 1.5f, spp);
    const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b), *pc = pk_image_pixels_const(c);
    int wrong = 0, full = 0, moved = 0;
    double worst = 0.0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 128; x++) {
            const double cx = x < 48 || x > 80 ? 0.0 : x == 48 ? 0.75 : x == 80 ? 0.25 : 1.0;
            const double cy = y < 23 || y > 39 ? 0.0 : (y == 23 || y == 39) ? 0.5 : 1.0;
            const size_t i = 3 * ((size_t)y * 128 + x) + 1;
            const double e = fabs((double)pa[i] - cx * cy);
            worst = fmax(worst, e);
            if (e > 1.5 / spp) wrong++;
            if (pa[i] == 1.0f) full++;
            if (fabs((double)pb[i] - (double)pa[i]) > 1.5 / spp || fabs((double)pc[i] - (double)pa[i]) > 1.5 / spp)
                moved++;
        }
    printf("orthographic rectangle: %d full pixels (want 31 x 15 = 465), worst coverage error %.4f\n", full, worst);
    CHECKF(wrong == 0, "%d pixels off their coverage (worst %g)", wrong, worst);
    CHECKF(full == 31 * 15, "%d full pixels, want 465", full);
    CHECKF(moved == 0, "%d pixels change with the rectangle's distance or tilt", moved);
    pk_image_destroy(a);
    pk_image_destroy(b);
    pk_image_destroy(c);
    char path[600];
    snprintf(path, sizeof path, "%s/glow.mtl", dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/rect.obj", dir);
    unlink(path);
    rmdir(dir);
}

/* ---- the API and the readers ------------------------------------------------ */

static void test_api(void)
{
    pk_camera c;
    memset(&c, 0x7f, sizeof c);
    pk_camera_init(&c);
    CHECK(c.lens_radius == 0.0f && c.focus_distance == 0.0f && c.projection == PK_PROJECTION_PERSPECTIVE &&
          c.ortho_width == 0.0f && c.fov_deg == 45.0f);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    pk_camera good;
    pk_scene_get_camera(s, &good);
    CHECK(good.lens_radius == 0.0f && good.projection == PK_PROJECTION_PERSPECTIVE);
    struct {
        const char *what;
        float lens, focus, width;
        int proj;
    } bad[] = {
        {"lens_radius -0.5 must not be negative", -0.5f, 0.0f, 0.0f, 0},
        {"focus_distance -1 must not be negative", 0.1f, -1.0f, 0.0f, 0},
        {"ortho_width -2 must not be negative", 0.0f, 0.0f, -2.0f, 1},
        {"projection 7 is not", 0.0f, 0.0f, 1.0f, 7},
        {"camera values must be finite", NAN, 0.0f, 0.0f, 0},
        {"camera values must be finite", 0.0f, INFINITY, 0.0f, 0},
        {"camera values must be finite", 0.0f, 0.0f, NAN, 1},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        c = good;
        c.lens_radius = bad[k].lens, c.focus_distance = bad[k].focus, c.ortho_width = bad[k].width;
        c.projection = bad[k].proj;
        pk_context_clear_error(ctx);
        CHECK(pk_scene_set_camera(ctx, s, &c) == PK_ERR_INVALID_ARGUMENT);
        CHECKF(strstr(pk_context_error(ctx), bad[k].what), "%s: got '%s'", bad[k].what, pk_context_error(ctx));
    }
    pk_camera now;
    pk_scene_get_camera(s, &now);
    CHECK(memcmp(&now, &good, sizeof now) == 0); /* refused: unchanged */
    c = good;
    c.lens_radius = 0.01f, c.focus_distance = 0.5f, c.projection = PK_PROJECTION_ORTHOGRAPHIC, c.ortho_width = 0.7f;
    CHECK(pk_scene_set_camera(ctx, s, &c) == PK_OK);
    pk_scene_get_camera(s, &now);
    CHECK(memcmp(&now, &c, sizeof now) == 0);
    /* a focus distance or width of 0 stands for the distance to look_at,
     * which must then be finite */
    c = good;
    for (int k = 0; k < 3; k++) c.look_from[k] = -1.5e38f, c.look_at[k] = 1.5e38f; /* finite, 5.2e38 apart */
    c.lens_radius = 1.0f;
    pk_context_clear_error(ctx);
    CHECK(pk_scene_set_camera(ctx, s, &c) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strstr(pk_context_error(ctx), "too far apart"), "got '%s'", pk_context_error(ctx));
    c.focus_distance = 10.0f;
    CHECK(pk_scene_set_camera(ctx, s, &c) == PK_OK);
    c.lens_radius = 0.0f, c.projection = PK_PROJECTION_ORTHOGRAPHIC;
    CHECK(pk_scene_set_camera(ctx, s, &c) == PK_ERR_INVALID_ARGUMENT);
    c.ortho_width = 5.0f;
    CHECK(pk_scene_set_camera(ctx, s, &c) == PK_OK);
    pk_scene_destroy(s);
}

static void check_json_error(const char *camera_fields, const char *want)
{
    char text[1024];
    snprintf(text, sizeof text, "{\"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0]%s},\n"
                                " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}",
             camera_fields);
    pk_scene *s = NULL;
    pk_context_clear_error(ctx);
    CHECK(pk_scene_load_json_memory(ctx, text, strlen(text), "cam.json", ".", &s) == PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(ctx), want), "%s: got '%s'", want, pk_context_error(ctx));
    pk_scene_destroy(s);
}

static void test_json(void)
{
    pk_scene *s = json_scene("{\"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0], \"lens_radius\": 0.25,"
                             " \"focus_distance\": 3.5, \"projection\": \"orthographic\", \"ortho_width\": 6},"
                             " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}",
                             ".");
    pk_camera c;
    pk_scene_get_camera(s, &c);
    CHECK(c.lens_radius == 0.25f && c.focus_distance == 3.5f && c.projection == PK_PROJECTION_ORTHOGRAPHIC &&
          c.ortho_width == 6.0f);
    pk_scene_destroy(s);
    s = json_scene("{\"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0], \"projection\": \"perspective\"},"
                   " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}",
                   ".");
    pk_scene_get_camera(s, &c);
    CHECK(c.lens_radius == 0.0f && c.focus_distance == 0.0f && c.projection == PK_PROJECTION_PERSPECTIVE &&
          c.ortho_width == 0.0f);
    pk_scene_destroy(s);
    check_json_error(", \"lens_radius\": -1", "camera.lens_radius");
    check_json_error(", \"lens_radius\": -1", "must not be negative");
    check_json_error(",\n \"focus_distance\": -2", "cam.json:2:");
    check_json_error(", \"focus_distance\": -2", "camera.focus_distance");
    check_json_error(", \"ortho_width\": -2", "camera.ortho_width");
    check_json_error(", \"projection\": \"fisheye\"", "camera.projection");
    check_json_error(", \"projection\": 1", "must be \"perspective\" or \"orthographic\"");
    check_json_error(", \"lens_radius\": \"big\"", "camera.lens_radius");
    check_json_error(", \"lens_radius\": 0.1, \"lens_radius\": 0.2", "duplicate key");
    const char *far = "{\"camera\": {\"look_from\": [-1.5e38, -1.5e38, -1.5e38], \"look_at\": [1.5e38, 1.5e38, 1.5e38],"
                      " \"lens_radius\": 1}}";
    pk_scene *f = NULL;
    pk_context_clear_error(ctx);
    CHECK(pk_scene_load_json_memory(ctx, far, strlen(far), "far.json", ".", &f) == PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(ctx), "camera.look_at: is too far from look_from"), "got '%s'",
           pk_context_error(ctx));
    pk_scene_destroy(f);
}

static pk_scene *xml_scene(const char *sensor, pk_status want)
{
    char text[2048];
    snprintf(text, sizeof text,
             "<scene version=\"3.0.0\">\n%s\n"
             "<shape type=\"sphere\"><float name=\"radius\" value=\"1\"/></shape>\n</scene>\n",
             sensor);
    pk_scene *s = NULL;
    warning_log_attach(ctx, &warnings);
    pk_context_clear_error(ctx);
    const pk_status st = pk_scene_load_xml_memory(ctx, text, strlen(text), "cam.xml", NULL, &s);
    CHECKF(st == want, "%s: status %d (%s)", sensor, (int)st, st ? pk_context_error(ctx) : "");
    return s;
}

static void test_xml(void)
{
    pk_camera c;
    /* thinlens: its aperture and focus distance */
    pk_scene *s = xml_scene("<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.2\"/>"
                            "<float name=\"focus_distance\" value=\"7\"/><float name=\"fov\" value=\"30\"/>"
                            "<transform name=\"to_world\"><lookat origin=\"0,0,5\" target=\"0,0,0\" up=\"0,1,0\"/>"
                            "</transform></sensor>",
                            PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.lens_radius == 0.2f && c.focus_distance == 7.0f && c.projection == PK_PROJECTION_PERSPECTIVE);
    CHECKF(warnings.count == 0, "warnings: %s", warnings.all);
    pk_scene_destroy(s);
    /* Mitsuba 0.6 names; no focus distance: far_clip, as Mitsuba */
    s = xml_scene("<sensor type=\"thinlens\"><float name=\"apertureRadius\" value=\"0.5\"/>"
                  "<float name=\"farClip\" value=\"60\"/></sensor>",
                  PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.lens_radius == 0.5f && c.focus_distance == 60.0f);
    pk_scene_destroy(s);
    s = xml_scene("<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.5\"/></sensor>", PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.focus_distance == 1e4f);
    pk_scene_destroy(s);
    s = xml_scene("<sensor type=\"thinlens\"/>", PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(ctx), "cam.xml:2:") && strstr(pk_context_error(ctx), "needs aperture_radius"),
           "got '%s'", pk_context_error(ctx));
    pk_scene_destroy(s);
    s = xml_scene("<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"-1\"/></sensor>", PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(ctx), "aperture_radius"), "got '%s'", pk_context_error(ctx));
    pk_scene_destroy(s);
    s = xml_scene("<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"1\"/>"
                  "<float name=\"focus_distance\" value=\"0\"/></sensor>",
                  PK_ERR_PARSE);
    CHECKF(strstr(pk_context_error(ctx), "focus_distance"), "got '%s'", pk_context_error(ctx));
    pk_scene_destroy(s);
    /* perspective: no lens, whatever focus_distance says */
    s = xml_scene("<sensor type=\"perspective\"><float name=\"focus_distance\" value=\"3\"/></sensor>", PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.lens_radius == 0.0f && c.projection == PK_PROJECTION_PERSPECTIVE);
    pk_scene_destroy(s);
    /* orthographic: x in [-1, 1] of the sensor's frame, scaled by to_world */
    s = xml_scene("<sensor type=\"orthographic\"><transform name=\"to_world\"><scale value=\"2.5\"/>"
                  "<lookat origin=\"0,0,5\" target=\"0,0,0\" up=\"0,1,0\"/></transform></sensor>",
                  PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.projection == PK_PROJECTION_ORTHOGRAPHIC && fabsf(c.ortho_width - 5.0f) < 1e-5f && c.lens_radius == 0.0f);
    CHECK_NEAR(c.look_from[2], 5.0, 1e-5);
    CHECK(c.look_at[2] < c.look_from[2]);
    CHECKF(warnings.count == 0, "warnings: %s", warnings.all);
    pk_scene_destroy(s);
    s = xml_scene("<sensor type=\"orthographic\"/>", PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.projection == PK_PROJECTION_ORTHOGRAPHIC && c.ortho_width == 2.0f);
    pk_scene_destroy(s);
    s = xml_scene("<sensor type=\"orthographic\"><transform name=\"toWorld\"><scale x=\"2\" y=\"1\"/>"
                  "</transform></sensor>",
                  PK_OK);
    pk_scene_get_camera(s, &c);
    CHECK(c.ortho_width == 4.0f);
    CHECKF(warning_log_count(&warnings, "scales x and y differently") == 1, "warnings: %s", warnings.all);
    pk_scene_destroy(s);
    pk_context_set_warning_handler(ctx, NULL, NULL);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_disk_map();
    test_rays();
    test_api();
    test_json();
    test_xml();
    test_ortho_plane();
    test_circle_of_confusion();
    pk_context_destroy(ctx);
    return test_done("test_camera");
}

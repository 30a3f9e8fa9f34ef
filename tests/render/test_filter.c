/*
 * test_filter.c - the pixel filters (render/filter.h, pk_render_options.filter).
 *
 * - Sampling: each filter's offsets follow its normalised |f| (chi-square
 *   over bins whose expected counts come from integrating the filter's
 *   profile finely, independently of the sampling table), per axis with
 *   different radii along x and y.
 * - Weights: a sample's weight is sign(f) times the integral of |f| over
 *   that of f (per axis, multiplied), computed here by fine integration:
 *   exactly 1 for the box, triangle, gaussian and blackman-harris. The box
 *   of radius 0.5 places samples where they were before filters (the
 *   jitter itself, bit for bit).
 * - A step edge: the pinhole sees radiance 1 to the right of a vertical
 *   line at film position e and 0 left of it; a pixel centred at c then
 *   shows the fraction of the normalised filter beyond e - c: for the
 *   gaussian a closed form through erf, for the triangle a polynomial, for
 *   mitchell (negative lobes) a fine numerical integral. The tolerance is
 *   5 standard errors measured over renders with different seeds, plus the
 *   bound of the table's piecewise-constant shape (h^2 max|f'| / integral).
 * - Determinism: the same bytes at 1 and 2 threads and split into other
 *   regions (tiles), for the path tracer and Whitted.
 * - Where filters are named: JSON render.filter (and convert writing it
 *   back), pbrt-v4 PixelFilter (and its gaussian default), Mitsuba
 *   <rfilter> (and its gaussian default), with one message per bad input.
 */
#include "test.h"
#include "warnings.h"

#include "chi2.h"
#include "paprsek.h"

#define PATH_TRACE(pt, t, r, h) ((void)(pt), (void)(t), (void)(r), (void)(h), false)
#define PATH_OCCLUDED(pt, t, r) ((void)(pt), (void)(t), (void)(r), false)
#include "render/path_kernel.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define P_MIN 1e-4 /* chi-square p-value floor per check */

static pk_context *ctx;
static warning_log warnings;

/* The integral of filter f's profile (radius r) over [a, b], signed or of
 * |f|, by Simpson's rule on n intervals. */
static double integral(const pk_filter *f, double r, double a, double b, bool absolute, int n)
{
    const double h = (b - a) / n;
    double s = 0.0;
    for (int k = 0; k <= n; k++) {
        double v = filter_profile(f, r, a + h * k);
        if (absolute) v = fabs(v);
        s += v * (k == 0 || k == n ? 1.0 : (k & 1) ? 4.0 : 2.0);
    }
    return s * h / 3.0;
}

static pk_filter make(pk_filter_type t, float rx, float ry)
{
    pk_filter f;
    pk_filter_init(&f, t);
    if (rx > 0.0f) f.radius_x = rx;
    if (ry > 0.0f) f.radius_y = ry;
    return f;
}

/* ---- sampling and weights ----------------------------------------------------- */

#define BINS 32
#define DRAWS 400000

/* Chi-square of the offsets along each axis against |f| normalised, and
 * the weights against sign(f) W. */
static void check_filter(const char *what, const pk_filter *f)
{
    pixel_filter pf;
    CHECKF(filter_build(ctx, f, &pf) == PK_OK, "%s: %s", what, pk_context_error(ctx));
    const double rad[2] = {f->radius_x, f->radius_y};
    double expect[2][BINS], W[2];
    for (int a = 0; a < 2; a++) {
        const double r = rad[a], tot = integral(f, r, -r, r, true, 1 << 16);
        W[a] = tot / integral(f, r, -r, r, false, 1 << 16);
        for (int b = 0; b < BINS; b++)
            expect[a][b] = integral(f, r, -r + 2 * r * b / BINS, -r + 2 * r * (b + 1) / BINS, true, 1 << 10) / tot;
    }
    long count[2][BINS] = {{0}};
    rng g = rng_seed(0x9e3779b97f4a7c15ull ^ (uint64_t)f->type, 7);
    int bad_weight = 0, out_of_range = 0;
    double worst = 0.0;
    for (int i = 0; i < DRAWS; i++) {
        const float u = rng_float(&g), v = rng_float(&g);
        float ox, oy, w;
        filter_sample(&pf, u, v, &ox, &oy, &w);
        const double off[2] = {(double)ox - 0.5, (double)oy - 0.5};
        double want = 1.0;
        for (int a = 0; a < 2; a++) {
            const double t = (off[a] + rad[a]) / (2 * rad[a]);
            if (!(t >= 0.0 && t < 1.0)) {
                out_of_range++;
                continue;
            }
            count[a][(int)(t * BINS)]++;
            /* sign(f) W where f is clearly away from zero (the cell of a zero crossing has one sign) */
            const double fv = filter_profile(f, rad[a], off[a]);
            const double scale = filter_profile(f, rad[a], 0.0);
            if (fabs(fv) < 0.05 * scale) want = NAN;
            want *= fv < 0.0 ? -W[a] : W[a];
        }
        if (isnan(want)) continue;
        const double e = fabs((double)w - want) / fabs(want);
        if (e > worst) worst = e;
        if (e > 2e-3) bad_weight++;
    }
    CHECKF(out_of_range == 0, "%s: %d offsets outside the radius", what, out_of_range);
    CHECKF(bad_weight == 0, "%s: %d weights differ from sign(f) W (worst relative error %g)", what, bad_weight,
           worst);
    for (int a = 0; a < 2; a++) {
        double chi2 = 0.0;
        int dof = -1;
        for (int b = 0; b < BINS; b++) {
            const double e = expect[a][b] * DRAWS;
            if (e < 5.0) {
                CHECKF(count[a][b] <= (long)(e * 10.0 + 10.0), "%s: bin %d has %ld of %g", what, b, count[a][b], e);
                continue;
            }
            chi2 += (count[a][b] - e) * (count[a][b] - e) / e;
            dof++;
        }
        const double p = chi2_pvalue(chi2, dof);
        CHECKF(p > P_MIN, "%s axis %c: chi-square %g (%d dof), p = %g", what, "xy"[a], chi2, dof, p);
    }
    /* the weights' exact value for filters that are never negative */
    if (f->type != PK_FILTER_MITCHELL && f->type != PK_FILTER_LANCZOS) {
        float ox, oy, w;
        filter_sample(&pf, 0.3f, 0.8f, &ox, &oy, &w);
        CHECKF(w == 1.0f, "%s: weight %.9g, not 1", what, (double)w);
    }
}

static void test_sampling(void)
{
    check_filter("box 0.5", &(pk_filter){PK_FILTER_BOX, 0.5f, 0.5f, 0, 0, 0, 0});
    check_filter("box 1.5 x 0.7", &(pk_filter){PK_FILTER_BOX, 1.5f, 0.7f, 0, 0, 0, 0});
    check_filter("triangle", &(pk_filter){PK_FILTER_TRIANGLE, 2.0f, 1.0f, 0, 0, 0, 0});
    pk_filter g = make(PK_FILTER_GAUSSIAN, 0, 0);
    check_filter("gaussian", &g);
    g = make(PK_FILTER_GAUSSIAN, 2.0f, 1.0f);
    g.sigma = 0.7f;
    check_filter("gaussian 2 x 1 sigma 0.7", &g);
    pk_filter m = make(PK_FILTER_MITCHELL, 0, 0);
    check_filter("mitchell", &m);
    m.b = 0.0f, m.c = 0.5f, m.radius_y = 3.0f;
    check_filter("mitchell (catmull-rom) 2 x 3", &m);
    pk_filter bh = make(PK_FILTER_BLACKMAN_HARRIS, 0, 0);
    check_filter("blackman-harris", &bh);
    pk_filter l = make(PK_FILTER_LANCZOS, 0, 0);
    check_filter("lanczos", &l);
    l = make(PK_FILTER_LANCZOS, 3.0f, 3.0f);
    check_filter("lanczos 3 (Mitsuba's)", &l);

    /* the box of radius 0.5 is the jitter itself; its weights are 1 */
    pixel_filter pf;
    pk_filter box;
    pk_filter_init(&box, PK_FILTER_BOX);
    REQUIRE(filter_build(ctx, &box, &pf) == PK_OK);
    rng g2 = rng_seed(12345, 3);
    int moved = 0;
    for (int i = 0; i < 100000; i++) {
        const float u = rng_float(&g2), v = rng_float(&g2);
        float ox, oy, w;
        filter_sample(&pf, u, v, &ox, &oy, &w);
        moved += ox != u || oy != v || w != 1.0f;
    }
    CHECKF(moved == 0, "the box of radius 0.5 moved %d samples", moved);
    /* and a zeroed path tracer (no filter built) places samples the same way */
    path_tracer pt;
    memset(&pt, 0, sizeof pt);
    path_tracer pt2 = pt;
    pt2.filter = pf;
    int differ = 0;
    for (uint32_t i = 0; i < 1000; i++) {
        const camera_sample a = path_camera_place(&pt, 3, 7, i), b = path_camera_place(&pt2, 3, 7, i);
        differ += memcmp(&a, &b, sizeof a) != 0;
    }
    CHECKF(differ == 0, "%d camera samples differ between the built box and a zeroed filter", differ);

    /* a lanczos filter whose profile integrates to nothing positive is refused */
    pk_filter bad = make(PK_FILTER_LANCZOS, 1.5f, 1.5f);
    bad.tau = 0.02f;
    pixel_filter tmp;
    const pk_status st = filter_build(ctx, &bad, &tmp);
    if (st == PK_OK) {
        /* (then it integrates positively: the check must agree) */
        CHECK(integral(&bad, 1.5, -1.5, 1.5, false, 1 << 16) > 0.0);
    } else {
        CHECK(strstr(pk_context_error(ctx), "filter lanczos") != NULL);
        pk_context_clear_error(ctx);
    }
}

/* ---- a step edge ------------------------------------------------------------------- */

#define SW 16
#define SH 16
#define SEEDS 16
#define EDGE 8.3 /* film x of the edge, pixels */

static char dir[] = "/tmp/paprsek-filter-XXXXXX";

/* The camera at the origin looking down -z (fov 90: the plane z = -1 spans
 * x, y in [-1, 1] over the image); an emitter of radiance 1 in that plane
 * right of x0, which the film sees right of film x = EDGE. */
static pk_scene *edge_scene(const char *filter_json)
{
    const double x0 = 2.0 * EDGE / SW - 1.0;
    char obj[600], text[4096];
    snprintf(obj, sizeof obj, "%s/edge.obj", dir);
    FILE *f = fopen(obj, "w");
    REQUIRE(f);
    fprintf(f, "usemtl lamp\nv %.9g -100 -1\nv 100 -100 -1\nv 100 100 -1\nv %.9g 100 -1\nf 1 2 3 4\n", x0, x0);
    REQUIRE(fclose(f) == 0);
    snprintf(text, sizeof text,
             "{\"materials\": {\"lamp\": {\"type\": \"emitter\", \"radiance\": [1, 1, 1]}},"
             " \"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [0, 0, -1], \"fov\": 90},"
             " \"meshes\": [{\"obj\": \"edge.obj\"}], \"environment\": \"none\","
             " \"render\": {\"filter\": %s}}",
             filter_json);
    pk_scene *s = NULL;
    const pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "edge.json", dir, &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    remove(obj);
    return s;
}

static pk_image *render(const pk_scene *s, pk_integrator_kind ig, int spp, int seed, int threads)
{
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.integrator = ig;
    o.width = SW, o.height = SH;
    o.spp = spp;
    o.seed = seed;
    o.threads = threads;
    pk_image *img = NULL;
    const pk_status st = pk_render(ctx, s, &o, &img, NULL);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return img;
}

/* The filtered edge at column x (its centre x + 0.5) against expected(a),
 * a = EDGE - centre: the fraction of the filter beyond a. */
static void check_edge(const char *what, const char *json, const pk_filter *f, double (*expected)(const pk_filter *, double),
                       double table_bound)
{
    pk_scene *s = edge_scene(json);
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    CHECKF(memcmp(&o.filter, f, sizeof *f) == 0, "%s: the JSON filter is not the one meant", what);
    double sum[SW] = {0}, sum2[SW] = {0};
    for (int k = 0; k < SEEDS; k++) {
        pk_image *img = render(s, PK_INTEGRATOR_PATH, 64, k + 1, 2);
        const float *px = pk_image_pixels_const(img);
        for (int x = 0; x < SW; x++) {
            double m = 0.0;
            for (int y = 0; y < SH; y++) m += (double)px[3 * (y * SW + x)];
            m /= SH;
            sum[x] += m, sum2[x] += m * m;
        }
        pk_image_destroy(img);
    }
    double worst = 0.0, worst_tol = 0.0, worst_se = 0.0;
    for (int x = 0; x < SW; x++) {
        const double mean = sum[x] / SEEDS, var = (sum2[x] - SEEDS * mean * mean) / (SEEDS - 1);
        const double se = sqrt(var > 0.0 ? var / SEEDS : 0.0);
        const double want = expected(f, EDGE - (x + 0.5));
        const double tol = 5.0 * se + table_bound + 1e-6;
        CHECKF(fabs(mean - want) <= tol, "%s: column %d is %.6f, the filter gives %.6f (tolerance %.2g, se %.2g)",
               what, x, mean, want, tol, se);
        if (fabs(mean - want) / tol > (worst_tol > 0.0 ? worst / worst_tol : 0.0))
            worst = fabs(mean - want), worst_tol = tol, worst_se = se;
    }
    printf("edge, %s: %d columns; closest to its tolerance: off by %.2g (tolerance %.2g, standard error %.2g)\n",
           what, SW, worst, worst_tol, worst_se);
    pk_scene_destroy(s);
}

/* The truncated gaussian's mass beyond a, by erf. */
static double gauss_beyond(const pk_filter *f, double a)
{
    const double r = f->radius_x, s = f->sigma, k = exp(-r * r / (2 * s * s));
    if (a >= r) return 0.0;
    if (a <= -r) return 1.0;
    const double c = s * sqrt((double)PK_PI / 2.0);
    const double whole = c * 2.0 * erf(r / (s * sqrt(2.0))) - k * 2.0 * r;
    const double part = c * (erf(r / (s * sqrt(2.0))) - erf(a / (s * sqrt(2.0)))) - k * (r - a);
    return part / whole;
}

/* The triangle's mass beyond a. */
static double tent_beyond(const pk_filter *f, double a)
{
    const double r = f->radius_x;
    if (a >= r) return 0.0;
    if (a <= -r) return 1.0;
    return a >= 0.0 ? (r - a) * (r - a) / (2 * r * r) : 1.0 - (r + a) * (r + a) / (2 * r * r);
}

/* Any filter's signed mass beyond a, by fine integration. */
static double numeric_beyond(const pk_filter *f, double a)
{
    const double r = f->radius_x;
    if (a >= r) return 0.0;
    if (a <= -r) return 1.0;
    return integral(f, r, a, r, false, 1 << 16) / integral(f, r, -r, r, false, 1 << 16);
}

/* h^2 max|f'| / integral of f: how far the table's piecewise-constant
 * shape can move the mass beyond any point (h = the table's cell). */
static double table_bound(const pk_filter *f)
{
    const double r = f->radius_x, h = 2.0 * r / FILTER_CELLS;
    double d = 0.0;
    for (int k = 0; k < 100000; k++) {
        const double x = -r + 2.0 * r * k / 100000, e = 1e-5;
        const double s = fabs(filter_profile(f, r, x + e) - filter_profile(f, r, x - e)) / (2 * e);
        if (s > d) d = s;
    }
    return h * h * d / integral(f, r, -r, r, false, 1 << 16);
}

static void test_edge(void)
{
    pk_filter g = make(PK_FILTER_GAUSSIAN, 0, 0);
    check_edge("gaussian", "{\"type\": \"gaussian\"}", &g, gauss_beyond, table_bound(&g));
    pk_filter g2 = make(PK_FILTER_GAUSSIAN, 2.5f, 2.5f);
    g2.sigma = 0.8f;
    check_edge("gaussian 2.5 sigma 0.8", "{\"type\": \"gaussian\", \"radius\": 2.5, \"sigma\": 0.8}", &g2,
               gauss_beyond, table_bound(&g2));
    pk_filter t = make(PK_FILTER_TRIANGLE, 1.5f, 1.5f);
    check_edge("triangle 1.5", "{\"type\": \"triangle\", \"radius\": [1.5, 1.5]}", &t, tent_beyond, 0.0);
    pk_filter m = make(PK_FILTER_MITCHELL, 0, 0);
    check_edge("mitchell", "{\"type\": \"mitchell\"}", &m, numeric_beyond, table_bound(&m));
    pk_filter l = make(PK_FILTER_LANCZOS, 0, 0);
    check_edge("lanczos", "{\"type\": \"lanczos\"}", &l, numeric_beyond, table_bound(&l));
    pk_filter bh = make(PK_FILTER_BLACKMAN_HARRIS, 0, 0);
    check_edge("blackman-harris", "{\"type\": \"blackman-harris\"}", &bh, numeric_beyond, table_bound(&bh));
}

/* ---- determinism ----------------------------------------------------------------- */

static void test_determinism(void)
{
    pk_scene *s = NULL;
    const char *text = "{\"materials\": {\"w\": {\"kd\": [0.7, 0.6, 0.5]}, \"l\": {\"type\": \"emitter\", "
                       "\"radiance\": [4, 4, 4]}},"
                       " \"camera\": {\"look_from\": [0, 1, 4], \"look_at\": [0, 0.5, 0], \"fov\": 40},"
                       " \"spheres\": [{\"center\": [0, -100, 0], \"radius\": 100, \"material\": \"w\"},"
                       "   {\"center\": [0, 0.6, 0], \"radius\": 0.6, \"material\": \"w\"},"
                       "   {\"center\": [1, 2, 1], \"radius\": 0.3, \"material\": \"l\"}],"
                       " \"render\": {\"filter\": {\"type\": \"mitchell\"}}}";
    REQUIRE(pk_scene_load_json_memory(ctx, text, strlen(text), "det.json", ".", &s) == PK_OK);
    const pk_integrator_kind igs[2] = {PK_INTEGRATOR_PATH, PK_INTEGRATOR_WHITTED};
    for (int k = 0; k < 2; k++) {
        pk_image *a = render(s, igs[k], 9, 3, 1), *b = render(s, igs[k], 9, 3, 2);
        CHECKF(memcmp(pk_image_pixels_const(a), pk_image_pixels_const(b), sizeof(float) * 3 * SW * SH) == 0,
               "%s: 1 and 2 threads differ", pk_integrator_name(igs[k]));
        /* other tiles: the image in regions of odd shapes */
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        o.integrator = igs[k], o.width = SW, o.height = SH, o.spp = 9, o.seed = 3, o.threads = 2;
        pk_renderer *r = NULL;
        pk_film *film = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        REQUIRE(pk_film_create(ctx, SW, SH, &film) == PK_OK);
        const pk_region reg[3] = {{0, 0, 5, SH}, {5, 0, SW - 5, 7}, {5, 7, SW - 5, SH - 7}};
        REQUIRE(pk_renderer_render(r, reg, 3, film) == PK_OK);
        pk_image *c = NULL;
        REQUIRE(pk_film_resolve(ctx, film, &c) == PK_OK);
        CHECKF(memcmp(pk_image_pixels_const(a), pk_image_pixels_const(c), sizeof(float) * 3 * SW * SH) == 0,
               "%s: other tiles give other bytes", pk_integrator_name(igs[k]));
        /* and the filter matters: a box gives another image */
        pk_render_options ob = o;
        pk_filter_init(&ob.filter, PK_FILTER_BOX);
        pk_image *d = NULL;
        REQUIRE(pk_render(ctx, s, &ob, &d, NULL) == PK_OK);
        CHECK(memcmp(pk_image_pixels_const(a), pk_image_pixels_const(d), sizeof(float) * 3 * SW * SH) != 0);
        pk_image_destroy(a), pk_image_destroy(b), pk_image_destroy(c), pk_image_destroy(d);
        pk_film_destroy(film);
        pk_renderer_destroy(r);
    }
    pk_scene_destroy(s);
}

/* ---- where filters are named ----------------------------------------------------- */

static pk_filter scene_filter(const pk_scene *s)
{
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    return o.filter;
}

static pk_scene *load(const char *format, const char *text)
{
    pk_scene *s = NULL;
    warning_log_clear(&warnings);
    pk_context_clear_error(ctx);
    if (pk_scene_load_memory(ctx, format, text, strlen(text), NULL, ".", &s) != PK_OK) return NULL;
    return s;
}

#define SPHERE "\"spheres\": [{\"center\": [0, 0, -5], \"radius\": 1}],"
#define XML_SHAPE "<shape type=\"sphere\"/>"

static void test_readers(void)
{
    /* JSON: absent, the box of radius 0.5 */
    pk_scene *s = load("json", "{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}");
    REQUIRE(s);
    pk_filter f = scene_filter(s), box;
    pk_filter_init(&box, PK_FILTER_BOX);
    CHECK(memcmp(&f, &box, sizeof f) == 0);
    pk_scene_destroy(s);
    /* JSON: every field, and convert's round trip */
    s = load("json", "{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}],"
                     " \"render\": {\"filter\": {\"type\": \"mitchell\", \"radius\": [1.5, 2.5], \"b\": 0.25, "
                     "\"c\": 0.375}}}");
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_MITCHELL && f.radius_x == 1.5f && f.radius_y == 2.5f && f.b == 0.25f && f.c == 0.375f);
    char path[600];
    snprintf(path, sizeof path, "%s/round.json", dir);
    REQUIRE(pk_scene_write_json(ctx, s, path) == PK_OK);
    pk_scene *back = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &back) == PK_OK);
    const pk_filter fb = scene_filter(back);
    CHECK(memcmp(&f, &fb, sizeof f) == 0);
    remove(path);
    pk_scene_destroy(back);
    pk_scene_destroy(s);
    /* JSON: bad inputs, one message each with where */
    static const struct {
        const char *filter, *msg;
    } bad[] = {{"{\"type\": \"cubic\"}", "render.filter.type"},
               {"{\"type\": \"box\", \"radius\": 0}", "render.filter.radius"},
               {"{\"type\": \"box\", \"radius\": 17}", "render.filter.radius"},
               {"{\"type\": \"box\", \"sigma\": 1}", "render.filter.sigma"},
               {"{\"type\": \"gaussian\", \"sigma\": -1}", "render.filter.sigma"},
               {"{\"type\": \"lanczos\", \"tau\": 0}", "render.filter.tau"},
               {"3", "render.filter"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[512];
        snprintf(text, sizeof text, "{%s \"render\": {\"filter\": %s}}", SPHERE, bad[i].filter);
        s = load("json", text);
        CHECKF(!s && strstr(pk_context_error(ctx), bad[i].msg), "JSON filter %s: \"%s\"", bad[i].filter,
               pk_context_error(ctx));
        pk_scene_destroy(s);
    }
    s = load("json", "{" SPHERE " \"render\": {\"filter\": {\"type\": \"box\", \"size\": 1}}}");
    CHECKF(s && warnings.count == 1 && warning_log_has(&warnings, "size"), "JSON filter size: %s", warnings.all);
    pk_scene_destroy(s);

    /* pbrt-v4: the gaussian when none is named; PixelFilter's types and parameters */
    s = load("pbrt", "WorldBegin\nShape \"sphere\"\n");
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_GAUSSIAN && f.radius_x == 1.5f && f.radius_y == 1.5f && f.sigma == 0.5f);
    pk_scene_destroy(s);
    s = load("pbrt", "PixelFilter \"sinc\" \"float xradius\" 3 \"float yradius\" 2 \"float tau\" 2\nWorldBegin\nShape \"sphere\"\n");
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_LANCZOS && f.radius_x == 3.0f && f.radius_y == 2.0f && f.tau == 2.0f);
    CHECK(warnings.count == 0);
    pk_scene_destroy(s);
    s = load("pbrt", "PixelFilter \"box\"\nWorldBegin\nShape \"sphere\"\n");
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(memcmp(&f, &box, sizeof f) == 0);
    pk_scene_destroy(s);
    s = load("pbrt", "PixelFilter \"mitchell\" \"float B\" 0 \"float C\" 0.5 \"float sigma\" 1\nWorldBegin\nShape \"sphere\"\n");
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_MITCHELL && f.b == 0.0f && f.c == 0.5f && f.radius_x == 2.0f);
    CHECKF(warnings.count == 1 && warning_log_has(&warnings, "memory.pbrt:1") && warning_log_has(&warnings, "sigma"),
           "pbrt mitchell with sigma: %d warnings: %s", warnings.count, warnings.all);
    pk_scene_destroy(s);
    s = load("pbrt", "\nPixelFilter \"cubic\"\nWorldBegin\nShape \"sphere\"\n");
    REQUIRE(s);
    CHECK(scene_filter(s).type == PK_FILTER_GAUSSIAN);
    CHECKF(warnings.count == 1 && warning_log_has(&warnings, "memory.pbrt:2"), "pbrt unknown filter: %s",
           warnings.all);
    pk_scene_destroy(s);
    s = load("pbrt", "\n\nPixelFilter \"gaussian\" \"float xradius\" -1\nWorldBegin\nShape \"sphere\"\n");
    CHECKF(!s && strstr(pk_context_error(ctx), "memory.pbrt:3") && strstr(pk_context_error(ctx), "xradius"),
           "pbrt negative radius: \"%s\"", pk_context_error(ctx));
    pk_scene_destroy(s);

    /* Mitsuba: the gaussian of stddev 0.5 and radius 2 when none is named */
    const char *xml_head = "<scene version=\"3.0.0\"><sensor type=\"perspective\"><film type=\"hdrfilm\">";
    char text[1024];
    snprintf(text, sizeof text, "%s</film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_GAUSSIAN && f.radius_x == 2.0f && f.sigma == 0.5f);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter>"
                                "</film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_GAUSSIAN && f.radius_x == 1.0f && f.sigma == 0.25f);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"2\"/></rfilter>"
                                "</film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_LANCZOS && f.radius_x == 2.0f && f.tau == 2.0f);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"catmullrom\"/></film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_MITCHELL && f.b == 0.0f && f.c == 0.5f && f.radius_x == 2.0f);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"box\"/></film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(memcmp(&f, &box, sizeof f) == 0);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"tent\"/></film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    f = scene_filter(s);
    CHECK(f.type == PK_FILTER_TRIANGLE && f.radius_x == 1.0f);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"kaiser\"/></film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    REQUIRE(s);
    CHECK(scene_filter(s).type == PK_FILTER_GAUSSIAN);
    CHECKF(warnings.count == 1 && warning_log_has(&warnings, "kaiser"), "xml unknown filter: %s", warnings.all);
    pk_scene_destroy(s);
    snprintf(text, sizeof text, "%s<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"-1\"/></rfilter>"
                                "</film></sensor>" XML_SHAPE "</scene>", xml_head);
    s = load("xml", text);
    CHECKF(!s && strstr(pk_context_error(ctx), "stddev"), "xml bad stddev: \"%s\"", pk_context_error(ctx));
    pk_scene_destroy(s);

    /* the API refuses a bad filter in the options */
    pk_render_options o;
    pk_render_options_init(&o);
    CHECK(memcmp(&o.filter, &box, sizeof box) == 0);
    o.filter.radius_x = 0.0f;
    pk_context_clear_error(ctx);
    CHECK(pk_render_options_check(ctx, &o) != PK_OK && strstr(pk_context_error(ctx), "filter box"));
    pk_context_clear_error(ctx);
    pk_filter_type ty;
    CHECK(pk_filter_parse("blackman-harris", &ty) == PK_OK && ty == PK_FILTER_BLACKMAN_HARRIS);
    CHECK(pk_filter_parse("sinc", &ty) != PK_OK);
    CHECK(strcmp(pk_filter_name(PK_FILTER_LANCZOS), "lanczos") == 0);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    REQUIRE(mkdtemp(dir));
    test_sampling();
    test_readers();
    test_determinism();
    test_edge();
    rmdir(dir);
    pk_context_destroy(ctx);
    return test_done("test_filter");
}

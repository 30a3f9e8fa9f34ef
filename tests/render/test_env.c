/*
 * test_env.c - light from the surroundings (render/env.h) against its pdf
 * and against closed forms.
 *
 * Sampling: directions drawn from a lat-long map (turned by a rotation) fall
 * into cells of the sphere as often as the integral of env_pdf over each cell
 * says (chi-square), env_pdf integrates to 1, and radiance / pdf estimates
 * the integral of the radiance. The uniform case and the sun's cone likewise.
 *
 * Renders: a quad of albedo rho facing +z sees nothing but its surroundings,
 * so every pixel's expected radiance is rho / pi times the integral of
 * L(w) cos(w) over the upper hemisphere: for a constant L that is rho L, for
 * the sun's disc (angular radius a, angle t from the normal) it is
 * rho L sin^2(a) cos(t), and for a map the integral is computed here by
 * quadrature. The pixels are independent draws of one distribution: their
 * mean must lie within Z_MEAN standard errors, measured on the image. Both
 * integrators, and the path tracer's three light strategies.
 */
#include "test.h"
#include "warnings.h"

#include "chi2.h"
#include "paprsek.h"
#include "render/env.h"
#include "render/path.h"
#include "render/render.h"
#include "render/sampling.h"

#include <stdint.h>
#include <unistd.h>

/* two-sided p = 1e-4 per check */
#define Z_MEAN 3.89
#define P_MIN 1e-4
#define PK_PI_D 3.14159265358979323846

static pk_context *ctx;

/* ---- a test map ------------------------------------------------------------ */

#define MW 64
#define MH 32

/* A sky gradient, a dark lower half with a black band, and a bright patch. */
static void make_map(float *rgb)
{
    for (int j = 0; j < MH; j++)
        for (int i = 0; i < MW; i++) {
            float v = ((float)j + 0.5f) / MH, u = ((float)i + 0.5f) / MW;
            float *p = &rgb[3 * (j * MW + i)];
            if (v < 0.5f)
                p[0] = 0.2f + v, p[1] = 0.4f + v, p[2] = 1.0f;
            else
                p[0] = p[1] = p[2] = (j == MH - 3) ? 0.0f : 0.1f;
            if (fabsf(u - 0.3f) < 0.05f && fabsf(v - 0.25f) < 0.06f) p[0] = 40.0f, p[1] = 30.0f, p[2] = 20.0f;
        }
}

static void write_pfm(const char *path, const float *rgb)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f);
    fprintf(f, "PF\n%d %d\n-1.0\n", MW, MH);
    for (int j = MH - 1; j >= 0; j--) REQUIRE(fwrite(&rgb[3 * j * MW], sizeof(float), 3 * MW, f) == 3 * MW);
    fclose(f);
}

static env_light build_map_env(const float *rgb, float rot_deg)
{
    scene_environment d;
    scene_env_init(&d);
    d.set = true;
    scene_rotation_y(rot_deg, d.to_world);
    aabb b = {{-1, -1, -1}, {1, 1, 1}};
    env_light e;
    REQUIRE(env_build(ctx, &d, rgb, MW, MH, b, &e) == PK_OK);
    return e;
}

/* ---- cells of the sphere: NC_T bands in cos(theta) about +y, NC_P in phi ---- */

#define NC_T 12
#define NC_P 24
#define N_DRAWS 400000

static vec3 cell_dir(double ct, double phi)
{
    double st = sqrt(fmax(0.0, 1.0 - ct * ct));
    return v3((float)(st * cos(phi)), (float)ct, (float)(st * sin(phi)));
}

static int cell_of(vec3 d)
{
    int t = (int)((1.0 - (double)d.y) * 0.5 * NC_T);
    double phi = atan2((double)d.z, (double)d.x);
    if (phi < 0.0) phi += 2.0 * PK_PI_D;
    int p = (int)(phi / (2.0 * PK_PI_D) * NC_P);
    t = t < 0 ? 0 : t >= NC_T ? NC_T - 1 : t;
    p = p < 0 ? 0 : p >= NC_P ? NC_P - 1 : p;
    return t * NC_P + p;
}

/* Integral of the pdf (or the radiance's luminance) over cell c, the cell
 * being equal-area in (cos theta, phi): the midpoint rule on a q x q grid in
 * (theta, phi) with the Jacobian sin(theta), so that the pdf's 1 / sin(theta)
 * at the poles is no singularity for the rule. */
static double cell_integral(const env_light *e, int c, int q, bool radiance)
{
    const int t = c / NC_P, p = c % NC_P;
    const double th0 = acos(1.0 - 2.0 * t / NC_T), th1 = acos(1.0 - 2.0 * (t + 1) / NC_T);
    const double dth = (th1 - th0) / q, dphi = 2.0 * PK_PI_D / NC_P / q;
    double sum = 0.0;
    for (int a = 0; a < q; a++)
        for (int b = 0; b < q; b++) {
            const double th = th0 + (a + 0.5) * dth;
            vec3 d = cell_dir(cos(th), (p * q + b + 0.5) * dphi);
            sum += (radiance ? (double)v3_luminance(env_eval(e, d)) : (double)env_pdf(e, d)) * sin(th);
        }
    return sum * dth * dphi;
}

static void chi2_check(const char *what, const env_light *e, const double *expected_p, const int *count, int n)
{
    double chi2 = 0.0, pooled_e = 0.0, pooled_o = 0.0;
    int dof = -1, zero_hits = 0;
    for (int c = 0; c < NC_T * NC_P; c++) {
        double ex = expected_p[c] * n;
        if (ex < 5.0) { /* pool the sparse cells */
            pooled_e += ex, pooled_o += count[c];
            if (expected_p[c] == 0.0 && count[c] > 0) zero_hits++;
            continue;
        }
        chi2 += (count[c] - ex) * (count[c] - ex) / ex;
        dof++;
    }
    if (pooled_e >= 5.0) {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        dof++;
    }
    double pv = chi2_pvalue(chi2, dof);
    printf("%s: chi2 %.1f, %d dof, p = %.3g\n", what, chi2, dof, pv);
    CHECKF(pv > P_MIN, "%s: p = %g", what, pv);
    CHECKF(zero_hits == 0, "%s: %d samples in cells of zero pdf", what, zero_hits);
    (void)e;
}

static void test_map_sampling(float rot)
{
    static float rgb[3 * MW * MH];
    make_map(rgb);
    env_light e = build_map_env(rgb, rot);
    static double prob[NC_T * NC_P];
    static int count[NC_T * NC_P];
    double total_pdf = 0.0, total_l = 0.0;
    for (int c = 0; c < NC_T * NC_P; c++) {
        prob[c] = cell_integral(&e, c, 48, false);
        total_pdf += prob[c];
        total_l += cell_integral(&e, c, 48, true);
        count[c] = 0;
    }
    char what[96];
    snprintf(what, sizeof what, "map (rotation %g): integral of the pdf", (double)rot);
    printf("%s = %.5f\n", what, total_pdf);
    /* exactly 1 in theory; the midpoint rule misplaces mass at the pixel
     * edges, where the pdf jumps (about 1e-3 here, shrinking as the grid
     * is refined) */
    CHECKF(fabs(total_pdf - 1.0) < 2e-3, "%s = %g", what, total_pdf);
    rng r = rng_seed(42, (uint64_t)rot);
    double sum = 0.0, sum2 = 0.0;
    int mismatched = 0;
    for (int k = 0; k < N_DRAWS; k++) {
        vec3 d, le;
        float pdf;
        if (!env_sample(&e, rng_float(&r), rng_float(&r), &d, &le, &pdf)) continue;
        count[cell_of(d)]++;
        if (fabsf(pdf - env_pdf(&e, d)) > 1e-5f * pdf || !(fabsf(v3_len(d) - 1.0f) < 1e-5f)) mismatched++;
        double x = (double)v3_luminance(le) / (double)pdf;
        sum += x, sum2 += x * x;
    }
    CHECKF(mismatched == 0, "%d samples whose pdf or direction disagree with env_pdf", mismatched);
    snprintf(what, sizeof what, "map (rotation %g): directions", (double)rot);
    chi2_check(what, &e, prob, count, N_DRAWS);
    /* radiance / pdf estimates the integral of the radiance over the sphere */
    double mean = sum / N_DRAWS, se = sqrt((sum2 / N_DRAWS - mean * mean) / N_DRAWS);
    printf("map: integral of L: estimate %.4f +- %.4f, quadrature %.4f\n", mean, se, total_l);
    CHECKF(fabs(mean - total_l) < Z_MEAN * se + 1e-3 * total_l, "estimate %g, quadrature %g", mean, total_l);
    env_free(&ctx->alloc, &e);
}

static void test_uniform_and_sun(void)
{
    scene_environment d;
    scene_env_init(&d);
    d.set = true;
    d.radiance = v3(1.0f, 2.0f, 3.0f);
    d.has_sun = true;
    d.sun_dir = v3(0.3f, 0.8f, -0.2f);
    d.sun_radiance = v3s(1000.0f);
    d.sun_angle = 20.0f; /* wide, so that its cone spans cells */
    aabb b = {{-1, -1, -1}, {1, 1, 1}};
    env_light e;
    REQUIRE(env_build(ctx, &d, NULL, 0, 0, b, &e) == PK_OK);
    CHECK(e.active && e.uniform && e.sun);
    static double prob[NC_T * NC_P];
    static int count[NC_T * NC_P];
    for (int c = 0; c < NC_T * NC_P; c++) prob[c] = 1.0 / (NC_T * NC_P), count[c] = 0;
    rng r = rng_seed(7, 7);
    for (int k = 0; k < N_DRAWS; k++) {
        vec3 dir, le;
        float pdf;
        REQUIRE(env_sample(&e, rng_float(&r), rng_float(&r), &dir, &le, &pdf));
        CHECK(pdf == 1.0f / (4.0f * PK_PI) && le.z == 3.0f);
        count[cell_of(dir)]++;
    }
    chi2_check("uniform: directions", &e, prob, count, N_DRAWS);
    /* the sun: every direction in its cone, cos(theta) uniform in [cos a, 1] */
    const double cos_a = (double)e.sun_cos;
    CHECK(fabs(cos_a - cos(10.0 * PK_PI_D / 180.0)) < 1e-6);
    int outside = 0;
    int bins[10] = {0};
    for (int k = 0; k < N_DRAWS; k++) {
        vec3 dir = sun_sample(&e, rng_float(&r), rng_float(&r));
        double c = (double)v3_dot(dir, v3_norm(d.sun_dir));
        if (c < cos_a - 1e-6) outside++;
        int bi = (int)((1.0 - c) / (1.0 - cos_a) * 10.0);
        bins[bi < 0 ? 0 : bi > 9 ? 9 : bi]++;
    }
    CHECK(outside == 0);
    double chi2 = 0.0;
    for (int i = 0; i < 10; i++) chi2 += (bins[i] - N_DRAWS / 10.0) * (bins[i] - N_DRAWS / 10.0) / (N_DRAWS / 10.0);
    double pv = chi2_pvalue(chi2, 9);
    printf("sun: cos(theta) chi2 %.1f, p = %.3g\n", chi2, pv);
    CHECK(pv > P_MIN);
    CHECK(sun_covers(&e, v3_norm(d.sun_dir)) && !sun_covers(&e, v3(0, -1, 0)));
    env_free(&ctx->alloc, &e);
}

static void test_sky(void)
{
    vec3 sun = v3_norm(v3(0.0f, 0.5f, -1.0f)); /* 26.6 degrees above the horizon */
    vec3 zen = sky_preetham(v3(0, 1, 0), sun, 3.0f);
    vec3 near = sky_preetham(v3_norm(v3(0.0f, 0.6f, -1.0f)), sun, 3.0f);
    vec3 away = sky_preetham(v3_norm(v3(0.0f, 0.5f, 1.0f)), sun, 3.0f);
    CHECK(v3_finite(zen) && zen.z > zen.x); /* a clear sky is blue overhead */
    CHECK(v3_luminance(near) > v3_luminance(away)); /* and brightest around the sun */
    CHECK(v3_luminance(sky_preetham(v3(0, -1, 0), sun, 3.0f)) == 0.0f);
    for (float t = 2.0f; t <= 10.0f; t += 1.0f)
        for (int k = 0; k < 64; k++) {
            float a = 2.0f * PK_PI * (float)k / 64.0f;
            vec3 dir = v3_norm(v3(cosf(a), 0.05f + (float)(k % 8) * 0.1f, sinf(a)));
            vec3 c = sky_preetham(dir, sun, t);
            CHECK(v3_finite(c) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f);
        }
}

/* The Hosek-Wilkie sky: the cooked parameters are the table's control points
 * at the ends of the elevation curve (sun on the horizon, sun at the zenith),
 * linear in turbidity and albedo between table rows; the radiance is the
 * model's formula; a clear sky is blue overhead and brightest near the sun. */
#include "render/hosek_rgb.inc"

static void test_hosek(void)
{
    sky_hosek h;
    for (int c = 0; c < 3; c++) {
        /* sun at the zenith: the last control point; turbidity 1, albedo 0 */
        sky_hosek_init(&h, v3(0, 1, 0), 1.0f, v3s(0.0f));
        for (int i = 0; i < 9; i++) CHECK(fabs(h.cfg[c][i] - hosek_rgb[c][45 + i]) <= 1e-12 * fabs(hosek_rgb[c][45 + i]));
        CHECK(fabs(h.rad[c] - hosek_rgb_rad[c][5]) <= 1e-12 * hosek_rgb_rad[c][5]);
        /* sun on the horizon: the first; turbidity 10, albedo 1 */
        sky_hosek_init(&h, v3(1, 0, 0), 10.0f, v3s(1.0f));
        for (int i = 0; i < 9; i++)
            CHECK(fabs(h.cfg[c][i] - hosek_rgb[c][540 + 54 * 9 + i]) <= 1e-12 * fabs(hosek_rgb[c][540 + 54 * 9 + i]));
        CHECK(fabs(h.rad[c] - hosek_rgb_rad[c][60 + 6 * 9]) <= 1e-12 * hosek_rgb_rad[c][60 + 6 * 9]);
    }
    /* between rows: bilinear in turbidity and albedo */
    const vec3 sun = v3_norm(v3(0.0f, 0.5f, -1.0f));
    sky_hosek m, c00, c01, c10, c11;
    sky_hosek_init(&m, sun, 2.5f, v3(0.5f, 0.25f, 0.0f));
    sky_hosek_init(&c00, sun, 2.0f, v3s(0.0f));
    sky_hosek_init(&c01, sun, 3.0f, v3s(0.0f));
    sky_hosek_init(&c10, sun, 2.0f, v3s(1.0f));
    sky_hosek_init(&c11, sun, 3.0f, v3s(1.0f));
    const double al[3] = {0.5, 0.25, 0.0};
    for (int c = 0; c < 3; c++) {
        for (int i = 0; i < 9; i++) {
            double want = (1.0 - al[c]) * 0.5 * (c00.cfg[c][i] + c01.cfg[c][i]) + al[c] * 0.5 * (c10.cfg[c][i] + c11.cfg[c][i]);
            CHECK(fabs(m.cfg[c][i] - want) <= 1e-9 * fmax(1.0, fabs(want)));
        }
        double wr = (1.0 - al[c]) * 0.5 * (c00.rad[c] + c01.rad[c]) + al[c] * 0.5 * (c10.rad[c] + c11.rad[c]);
        CHECK(fabs(m.rad[c] - wr) <= 1e-9 * wr);
    }
    /* the formula where it is short: looking at a sun at the zenith (theta = gamma = 0),
     * (1 + A exp(B / 1.01)) (C + D + F + 2 G / (1 - H)^3 + I) times the radiance, over 106.856980 */
    sky_hosek_init(&h, v3(0, 1, 0), 3.0f, v3s(0.2f));
    vec3 z = sky_hosek_eval(&h, v3(0, 1, 0));
    const float zc[3] = {z.x, z.y, z.z};
    for (int c = 0; c < 3; c++) {
        const double *k = h.cfg[c];
        double want = (1.0 + k[0] * exp(k[1] / 1.01)) * (k[2] + k[3] + k[5] + 2.0 * k[6] / pow(1.0 - k[8], 3.0) + k[7]) *
                      h.rad[c] / 106.856980;
        CHECKF(fabs((double)zc[c] - want) <= 1e-5 * want, "hosek zenith[%d] %g, formula %g", c, (double)zc[c], want);
    }
    /* a clear sky: blue overhead, brightest around the sun, black below the horizon */
    sky_hosek_init(&h, sun, 3.0f, v3s(0.2f));
    vec3 zen = sky_hosek_eval(&h, v3(0, 1, 0));
    vec3 near = sky_hosek_eval(&h, v3_norm(v3(0.0f, 0.6f, -1.0f)));
    vec3 away = sky_hosek_eval(&h, v3_norm(v3(0.0f, 0.5f, 1.0f)));
    CHECK(v3_finite(zen) && zen.z > zen.x && v3_luminance(near) > v3_luminance(away));
    CHECK(v3_luminance(sky_hosek_eval(&h, v3(0, -1, 0))) == 0.0f);
    for (float t = 1.0f; t <= 10.0f; t += 0.5f)
        for (int k = 0; k < 64; k++) {
            float a = 2.0f * PK_PI * (float)k / 64.0f;
            vec3 dir = v3_norm(v3(cosf(a), 0.02f + (float)(k % 8) * 0.1f, sinf(a)));
            sky_hosek_init(&h, v3_norm(v3(0.3f, 0.05f + 0.1f * (float)(k % 9), -1.0f)), t, v3s((float)(k % 5) * 0.25f));
            vec3 c = sky_hosek_eval(&h, dir);
            CHECK(v3_finite(c) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f);
        }
}

/* ---- renders ---------------------------------------------------------------- */

#define RSIZE 16

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    REQUIRE(f);
    fputs(text, f);
    fclose(f);
}

/* A 4 x 4 quad in z = 0 facing +z, albedo rho, seen head-on so that it fills the image. */
static pk_scene *quad_scene(const char *dir, float rho)
{
    char path[512], mtl[128];
    snprintf(path, sizeof path, "%s/quad.mtl", dir);
    snprintf(mtl, sizeof mtl, "newmtl q\nKd %g %g %g\n", (double)rho, (double)rho, (double)rho);
    write_text(path, mtl);
    snprintf(path, sizeof path, "%s/quad.obj", dir);
    write_text(path, "mtllib quad.mtl\nusemtl q\nv -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nf 1 2 3 4\n");
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
    pk_camera cam = {{0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, 40.0f, 0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    REQUIRE(pk_scene_set_camera(ctx, s, &cam) == PK_OK);
    return s;
}

/* Mean and standard error of the pixels' luminance, path tracer (strategy)
 * or Whitted. */
static void render_mean(const pk_scene *s, pk_integrator_kind integ, int strategy, int spp, double *mean, double *se)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = integ;
    o.width = o.height = RSIZE;
    o.spp = spp;
    o.threads = 2;
    o.light_samples = 4;
    pk_renderer *r = NULL;
    pk_film *f = NULL;
    pk_image *img = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    if (integ == PK_INTEGRATOR_PATH) renderer_set_path_strategy(r, strategy);
    REQUIRE(pk_film_create(ctx, RSIZE, RSIZE, &f) == PK_OK);
    REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK);
    const float *px = pk_image_pixels_const(img);
    double sum = 0.0, sum2 = 0.0;
    const int n = RSIZE * RSIZE;
    for (int i = 0; i < n; i++) {
        double l = (double)v3_luminance(v3(px[3 * i], px[3 * i + 1], px[3 * i + 2]));
        sum += l, sum2 += l * l;
    }
    *mean = sum / n;
    *se = sqrt(fmax(sum2 / n - *mean * *mean, 0.0) / (n - 1));
    pk_image_destroy(img);
    pk_film_destroy(f);
    pk_renderer_destroy(r);
}

static void expect_mean(const char *what, const pk_scene *s, pk_integrator_kind integ, int strategy, int spp,
                        double expected)
{
    double mean, se;
    render_mean(s, integ, strategy, spp, &mean, &se);
    /* a zero-variance estimator (every sample the same) must be right to rounding */
    double z = se > 0.0 ? fabs(mean - expected) / se : (fabs(mean - expected) <= 1e-6 * expected ? 0.0 : (double)INFINITY);
    printf("%s: mean %.5f +- %.5f, expected %.5f (z = %.2f)\n", what, mean, se, expected, z);
    CHECKF(z < Z_MEAN, "%s: mean %g, expected %g, z = %g", what, mean, expected, z);
}

static void test_renders(const char *dir)
{
    const float rho = 0.8f;
    pk_scene *s = quad_scene(dir, rho);
    const char *names[3] = {"MIS", "light sampling", "BSDF sampling"};
    const int strategies[3] = {PATH_MIS, PATH_LIGHTS_ONLY, PATH_BSDF_ONLY};
    char what[128];

    /* a constant environment: rho L exactly */
    pk_environment env;
    pk_environment_init(&env);
    env.radiance[0] = env.radiance[1] = env.radiance[2] = 1.5f;
    REQUIRE(pk_scene_set_environment(ctx, s, &env) == PK_OK);
    for (int k = 0; k < 3; k++) {
        snprintf(what, sizeof what, "constant, path (%s)", names[k]);
        expect_mean(what, s, PK_INTEGRATOR_PATH, strategies[k], 16, (double)rho * 1.5);
    }
    expect_mean("constant, whitted", s, PK_INTEGRATOR_WHITTED, 0, 16, (double)rho * 1.5);

    /* a map, turned by 70 degrees: rho / pi * integral of L cos over z > 0 */
    static float rgb[3 * MW * MH];
    make_map(rgb);
    char map[512];
    snprintf(map, sizeof map, "%s/map.pfm", dir);
    write_pfm(map, rgb);
    env.radiance[0] = env.radiance[1] = env.radiance[2] = 0.0f;
    env.map = map;
    env.map_scale = 2.0f;
    env.rotation = 70.0f;
    REQUIRE(pk_scene_set_environment(ctx, s, &env) == PK_OK);
    env_light e = build_map_env(rgb, 70.0f);
    double irr = 0.0;
    const int q = 512;
    for (int a = 0; a < q; a++)     /* cos(theta) about +z, uniform */
        for (int b = 0; b < q; b++) { /* phi */
            double ct = (a + 0.5) / q, phi = 2.0 * PK_PI_D * (b + 0.5) / q, st = sqrt(1.0 - ct * ct);
            vec3 d = v3((float)(st * cos(phi)), (float)(st * sin(phi)), (float)ct);
            irr += (double)v3_luminance(env_eval(&e, d)) * ct;
        }
    irr *= 2.0 * PK_PI_D / ((double)q * q) * 2.0; /* d omega = d cos d phi; the scale 2 */
    env_free(&ctx->alloc, &e);
    const double expected = (double)rho / PK_PI_D * irr;
    for (int k = 0; k < 3; k++) {
        snprintf(what, sizeof what, "map, path (%s)", names[k]);
        expect_mean(what, s, PK_INTEGRATOR_PATH, strategies[k], k == 2 ? 64 : 16, expected);
    }
    expect_mean("map, whitted", s, PK_INTEGRATOR_WHITTED, 0, 16, expected);

    /* the sun alone, 30 degrees from the normal: rho L sin^2(a) cos(30) */
    char json[512];
    snprintf(json, sizeof json,
             "{\"meshes\": [{\"obj\": \"quad.obj\"}], \"camera\": {\"look_from\": [0, 0, 3], \"look_at\": [0, 0, 0], "
             "\"fov\": 40}, \"environment\": {\"sun\": {\"direction\": [0, 0.5, 0.8660254], \"radiance\": "
             "[5000, 5000, 5000], \"angle\": 2}}}");
    pk_scene *sun = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, json, strlen(json), "sun.json", dir, &sun) == PK_OK);
    const double sa = sin(1.0 * PK_PI_D / 180.0);
    const double want = (double)rho * 5000.0 * sa * sa * cos(30.0 * PK_PI_D / 180.0);
    for (int k = 0; k < 2; k++) { /* a small disc: BSDF sampling alone would need very many samples */
        snprintf(what, sizeof what, "sun, path (%s)", names[k]);
        expect_mean(what, sun, PK_INTEGRATOR_PATH, strategies[k], 16, want);
    }
    expect_mean("sun, whitted", sun, PK_INTEGRATOR_WHITTED, 0, 16, want);
    pk_scene_destroy(sun);

    /* the furnace of the issue: a diffuse sphere of albedo r under a constant
     * environment of radiance 1 has radiance r (it sees only the environment);
     * the camera is close enough that the sphere fills the image */
    const char *sphere_json =
        "{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": {\"type\": \"diffuse\", "
        "\"albedo\": [0.7, 0.7, 0.7]}}], \"camera\": {\"look_from\": [0, 0, 3], \"look_at\": [0, 0, 0], \"fov\": 20},"
        " \"environment\": [1, 1, 1]}";
    pk_scene *ball = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, sphere_json, strlen(sphere_json), "ball.json", dir, &ball) == PK_OK);
    for (int k = 0; k < 3; k++) {
        snprintf(what, sizeof what, "sphere furnace, path (%s)", names[k]);
        expect_mean(what, ball, PK_INTEGRATOR_PATH, strategies[k], 16, 0.7);
    }
    expect_mean("sphere furnace, whitted", ball, PK_INTEGRATOR_WHITTED, 0, 16, 0.7);
    pk_scene_destroy(ball);

    /* none: black, and no white default either */
    REQUIRE(pk_scene_set_environment(ctx, s, NULL) == PK_OK);
    double mean, se;
    render_mean(s, PK_INTEGRATOR_PATH, PATH_MIS, 1, &mean, &se);
    CHECK(mean == 0.0);
    pk_scene_destroy(s);
}

/* A scene without lights gets the white environment of radiance 1. */
static warning_log warnings;

static void test_default(const char *dir)
{
    pk_scene *s = quad_scene(dir, 0.5f);
    warning_log_attach(ctx, &warnings);
    expect_mean("default white environment, path", s, PK_INTEGRATOR_PATH, PATH_MIS, 8, 0.5);
    CHECK(warning_log_count(&warnings, "uniform white environment") == 1);
    pk_context_set_warning_handler(ctx, NULL, NULL);
    pk_scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    char dir[] = "/tmp/pk_test_env_XXXXXX";
    REQUIRE(mkdtemp(dir));
    test_map_sampling(0.0f);
    test_map_sampling(70.0f);
    test_uniform_and_sun();
    test_sky();
    test_hosek();
    test_renders(dir);
    test_default(dir);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
    pk_context_destroy(ctx);
    return test_done("test_env");
}

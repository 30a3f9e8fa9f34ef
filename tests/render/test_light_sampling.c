/*
 * test_light_sampling.c - triangle lights sampled by the solid angle they
 * subtend (render/spherical_triangle.h, render/lights.h), plain and warped
 * toward the receiver's cosine, against their pdf and against closed forms.
 *
 * - The map itself: its solid angle against a double-precision reference,
 *   sph_tri_invert undoing sph_tri_sample, the bilinear warp against its
 *   density (chi-square on the unit square).
 * - Sampling through light_sample_one_with: the points drawn fall into the
 *   cells of a barycentric grid on the triangle as often as the integral of
 *   light_pdf_at over each cell's solid angle says (chi-square), for near,
 *   far, grazing, sliver and almost hemispherical triangles; the pdf
 *   returned with a sample is light_pdf_at's for the same direction (the
 *   MIS weights of the path tracer use the latter); light_pdf_at integrates
 *   to 1 over the triangle's solid angle (Monte Carlo, with the variance
 *   measured), and the sampler covers the whole triangle. The cheap bound
 *   that light_tri_spherical tries first decides as the exact rule does.
 * - Closed forms: the irradiance of a uniform emissive triangle and quad
 *   (Lambert's polygon formula) against the light-sampling estimator and
 *   against MIS of light and cosine sampling, within Z_MEAN standard errors
 *   measured from the samples, in every mode; the variance of each mode is
 *   printed.
 * - Degenerate and extreme triangles (collinear, repeated vertices, the
 *   receiver on the plane, an edge or a vertex, slivers, 1e-20 and 1e30
 *   scales): sampling says no or gives a finite sample; pdfs are finite.
 */
#include "test.h"

/* The spherical map is tested down to small solid angles: this file's copy
 * of the sampling code turns to area sampling only below pbrt-v4's 3e-4 sr
 * (the library's threshold is higher for speed, src/render/spherical_triangle.h;
 * the renders of test_direct, test_mis and test_path run with it). */
#define SPH_TRI_MIN_SOLID_ANGLE 3e-4f

#include "chi2.h"
#include "math/tri.h"
#include "render/lights.h"
#include "render/sampling.h"

#include <stdint.h>

#define Z_MEAN 4.5    /* two-sided p ~ 7e-6 per check */
#define P_MIN 1e-4    /* chi-square p-value floor per check */
#define PI_D 3.14159265358979323846

/* ---- double-precision references ------------------------------------------ */

typedef struct d3 {
    double x, y, z;
} d3;

static d3 d3_of(vec3 v) { return (d3){v.x, v.y, v.z}; }
static d3 d3_sub(d3 a, d3 b) { return (d3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static d3 d3_add(d3 a, d3 b) { return (d3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static d3 d3_scale(d3 a, double s) { return (d3){a.x * s, a.y * s, a.z * s}; }
static double d3_dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 d3_cross(d3 a, d3 b) { return (d3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static double d3_len(d3 a) { return sqrt(d3_dot(a, a)); }
static d3 d3_norm(d3 a) { return d3_scale(a, 1.0 / d3_len(a)); }
static vec3 v3_of(d3 a) { return v3((float)a.x, (float)a.y, (float)a.z); }

/* Solid angle of triangle abc seen from p (Van Oosterom and Strackee). */
static double solid_angle_d(d3 p, d3 a, d3 b, d3 c)
{
    d3 A = d3_sub(a, p), B = d3_sub(b, p), C = d3_sub(c, p);
    double la = d3_len(A), lb = d3_len(B), lc = d3_len(C);
    double num = d3_dot(A, d3_cross(B, C));
    double den = la * lb * lc + d3_dot(A, B) * lc + d3_dot(A, C) * lb + d3_dot(B, C) * la;
    return 2.0 * atan2(fabs(num), den);
}

/* Irradiance at p (normal n) from a polygon of radiance 1 lying wholly
 * above p's horizon: Lambert's formula E = 1/2 |sum_i theta_i n.g_i|, g_i
 * the unit normal of the plane through p and edge i, theta_i the angle that
 * edge subtends. */
static double polygon_irradiance(d3 p, d3 n, const d3 *v, int nv)
{
    double sum = 0.0;
    for (int i = 0; i < nv; i++) {
        d3 r0 = d3_norm(d3_sub(v[i], p)), r1 = d3_norm(d3_sub(v[(i + 1) % nv], p));
        d3 g = d3_cross(r0, r1);
        double theta = atan2(d3_len(g), d3_dot(r0, r1));
        sum += theta * d3_dot(d3_norm(g), n);
    }
    return 0.5 * fabs(sum);
}

/* Barycentrics (b1, b2) of the point q of triangle abc's plane. */
static void barycentric_d(d3 a, d3 b, d3 c, d3 q, double *b1, double *b2)
{
    d3 e1 = d3_sub(b, a), e2 = d3_sub(c, a), N = d3_cross(e1, e2), r = d3_sub(q, a);
    double nn = d3_dot(N, N);
    *b1 = d3_dot(d3_cross(r, e2), N) / nn;
    *b2 = d3_dot(d3_cross(e1, r), N) / nn;
}

/* Where the ray p + t w (t > 0) meets triangle abc, or false. */
static bool ray_tri_d(d3 p, d3 w, d3 a, d3 b, d3 c, d3 *q)
{
    d3 e1 = d3_sub(b, a), e2 = d3_sub(c, a), N = d3_cross(e1, e2);
    double dn = d3_dot(w, N);
    if (dn == 0.0) return false;
    double t = d3_dot(d3_sub(a, p), N) / dn;
    if (!(t > 0.0)) return false;
    *q = d3_add(p, d3_scale(w, t));
    double b1, b2;
    barycentric_d(a, b, c, *q, &b1, &b2);
    return b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0;
}

/* ---- a scene of one or two emissive triangles -------------------------------- */

typedef struct lab {
    vec3 pos[6];
    triangle tris[2];
    material mat;
    scene_view v;
    light lights[2];
    float pmf[2], cdf[2];
    int32_t of_prim[2];
    light_set set;
    env_light env;
} lab;

/* Triangles (verts[3 i], verts[3 i + 1], verts[3 i + 2]), radiance 1,
 * chosen in proportion to area as light_set_build does. */
static void lab_init(lab *L, const vec3 *verts, int ntri, bool two_sided)
{
    memset(L, 0, sizeof *L);
    L->mat.ke = v3s(1.0f);
    L->mat.two_sided = two_sided;
    double total = 0.0;
    for (int i = 0; i < ntri; i++) {
        for (int k = 0; k < 3; k++) L->pos[3 * i + k] = verts[3 * i + k];
        L->tris[i] = (triangle){{3u * (uint32_t)i, 3u * (uint32_t)i + 1u, 3u * (uint32_t)i + 2u}, {-1, -1, -1}, {-1, -1, -1}, 0};
        vec3 a = verts[3 * i], b = verts[3 * i + 1], c = verts[3 * i + 2];
        L->lights[i] = light_of_triangle((uint32_t)i, a, b, c, &L->mat);
        L->of_prim[i] = i;
        total += (double)L->lights[i].area;
    }
    double acc = 0.0;
    for (int i = 0; i < ntri; i++) {
        L->pmf[i] = (float)((double)L->lights[i].area / total);
        acc += (double)L->lights[i].area / total;
        L->cdf[i] = (float)acc;
    }
    L->cdf[ntri - 1] = 1.0f;
    L->v.positions = L->pos, L->v.npositions = (size_t)(3 * ntri);
    L->v.tris = L->tris, L->v.ntris = (size_t)ntri;
    L->v.materials = &L->mat, L->v.nmaterials = 1;
    L->set = (light_set){.n = (size_t)ntri, .lights = L->lights, .cdf = L->cdf, .pmf = L->pmf, .of_prim = L->of_prim,
                         .env = -1, .sun = -1, .power = total};
}

static light_ctx ctx_at(vec3 p, vec3 n) { return (light_ctx){p, n, p, false}; }

static const char *mode_name(uint32_t mode)
{
    return mode == LIGHT_TRI_AREA ? "area" : mode == LIGHT_TRI_SOLID_ANGLE ? "solid angle" : "solid angle x cos";
}

/* The point a sample aims at (its shadow ray ends SHADOW_SHORTEN short). */
static vec3 sample_point(const light_sample *ls) { return v3_add(ls->shadow.o, ls->shadow.d); }

/* ---- the configurations --------------------------------------------------- */

typedef struct config {
    const char *name;
    vec3 p, n;      /* receiver and its normal */
    vec3 v[3];      /* the triangle, facing p */
} config;

static config configs[] = {
    {"near", {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, {{-0.6f, -0.4f, 1.0f}, {0.1f, 0.8f, 0.9f}, {0.7f, -0.5f, 1.2f}}},
    {"near, tilted receiver", {0.0f, 0.0f, 0.0f}, {0.8f, 0.0f, 0.6f}, {{-0.6f, -0.4f, 0.5f}, {0.1f, 0.8f, 0.4f}, {0.7f, -0.5f, 0.7f}}},
    {"far", {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, {{-0.6f, -0.4f, 36.0f}, {0.1f, 0.8f, 35.9f}, {0.7f, -0.5f, 36.2f}}},
    {"grazing", {0.0f, 0.02f, 0.0f}, {0.0f, -0.287348f, 0.957826f}, {{-1.0f, 0.0f, 0.5f}, {0.0f, 0.0f, 3.0f}, {1.0f, 0.0f, 0.5f}}},
    {"sliver", {0.1f, -0.2f, 0.0f}, {0.0f, 0.0f, 1.0f}, {{-2.0f, 0.0f, 1.0f}, {0.3f, 0.01f, 1.0f}, {2.0f, 0.0f, 1.0f}}},
    {"wide angle", {0.0f, 0.0f, 0.0f}, {0.0f, 0.6f, 0.8f}, {{-1.5f, 0.0f, 1.0f}, {0.0f, 0.05f, 1.0f}, {1.5f, 0.0f, 1.0f}}},
    {"almost a hemisphere", {0.3f, 0.2f, 0.0f}, {0.0f, 0.0f, 1.0f}, {{-20.0f, -20.0f, 1.0f}, {0.0f, 25.0f, 1.0f}, {20.0f, -20.0f, 1.0f}}},
};
#define NCONFIG (int)(sizeof configs / sizeof configs[0])

static double config_omega(const config *c)
{
    return solid_angle_d(d3_of(c->p), d3_of(c->v[0]), d3_of(c->v[1]), d3_of(c->v[2]));
}

/* ---- the map -------------------------------------------------------------- */

static void test_solid_angle(void)
{
    double worst = 0.0;
    for (int i = 0; i < NCONFIG; i++) {
        const config *c = &configs[i];
        sph_tri st;
        REQUIRE(sph_tri_setup(&st, c->p, c->v[0], c->v[1], c->v[2], 0.0f, 7.0f));
        double ref = config_omega(c), rel = fabs((double)st.area - ref) / ref;
        worst = fmax(worst, rel);
        CHECKF(rel < 1e-5, "%s: solid angle %.9g vs %.9g", c->name, (double)st.area, ref);
    }
    /* small ones, where alpha + beta + gamma - pi would have lost it all */
    for (int k = 1; k <= 6; k++) {
        float s = powf(10.0f, (float)-k);
        vec3 v0 = v3(-s, -s, 1.0f), v1 = v3(0.0f, s, 1.0f), v2 = v3(s, -0.5f * s, 1.0f);
        sph_tri st;
        REQUIRE(sph_tri_setup(&st, v3s(0.0f), v0, v1, v2, 0.0f, 7.0f));
        double ref = solid_angle_d((d3){0, 0, 0}, d3_of(v0), d3_of(v1), d3_of(v2)), rel = fabs((double)st.area - ref) / ref;
        worst = fmax(worst, rel);
        CHECKF(rel < 1e-4, "size 1e-%d: solid angle %.9g vs %.9g", k, (double)st.area, ref);
    }
    printf("solid angle: largest relative error %.2g\n", worst);
}

/* sph_tri_invert(sph_tri_sample(u)) = u, and the point sampled lies in the
 * triangle. */
static void test_invert(void)
{
    rng r = rng_seed(7, 1);
    for (int i = 0; i < NCONFIG; i++) {
        const config *c = &configs[i];
        sph_tri st;
        REQUIRE(sph_tri_setup(&st, c->p, c->v[0], c->v[1], c->v[2], 0.0f, 7.0f));
        double worst = 0.0, outside = 0.0;
        /* the edges of the square, then random points */
        const float edge[5] = {0.0f, 1e-7f, 0.5f, 0x1.fffffep-1f, 1.0f};
        for (int k = 0; k < 20025; k++) {
            float u0 = k < 25 ? edge[k % 5] : rng_float(&r), u1 = k < 25 ? edge[k / 5] : rng_float(&r);
            vec3 w = sph_tri_sample(&st, u0, u1);
            CHECK(v3_finite(w) && fabsf(v3_len(w) - 1.0f) < 1e-5f);
            float x0, x1;
            sph_tri_invert(&st, w, &x0, &x1);
            /* u0 is meaningless where the arc from b has length 0 (u1 = 0) */
            double e = fmax(fabs((double)x0 - (double)u0) * (double)u1, fabs((double)x1 - (double)u1));
            worst = fmax(worst, e);
            d3 q;
            bool in = ray_tri_d(d3_of(c->p), d3_of(w), d3_of(c->v[0]), d3_of(c->v[1]), d3_of(c->v[2]), &q);
            if (!in) {
                /* only by rounding: how far outside, as an angle */
                double b1, b2;
                d3 N = d3_cross(d3_sub(d3_of(c->v[1]), d3_of(c->v[0])), d3_sub(d3_of(c->v[2]), d3_of(c->v[0])));
                double t = d3_dot(d3_sub(d3_of(c->v[0]), d3_of(c->p)), N) / d3_dot(d3_of(w), N);
                q = d3_add(d3_of(c->p), d3_scale(d3_of(w), t));
                barycentric_d(d3_of(c->v[0]), d3_of(c->v[1]), d3_of(c->v[2]), q, &b1, &b2);
                outside = fmax(outside, fmax(fmax(-b1, -b2), b1 + b2 - 1.0));
            }
        }
        printf("%s: sample -> invert: largest |du| %.2g, farthest outside %.2g (barycentric)\n", c->name, worst, outside);
        CHECKF(worst < 2e-3, "%s: invert(sample(u)) differs from u by %g", c->name, worst);
        CHECKF(outside < 1e-4, "%s: samples %g outside the triangle", c->name, outside);
    }
}

/* The linear and bilinear warps against their densities. */
static void test_bilinear(void)
{
    /* sample_linear inverts the CDF */
    const float ab[][2] = {{1.0f, 1.0f}, {0.01f, 1.0f}, {1.0f, 0.01f}, {0.0f, 2.0f}, {3.0f, 0.0f}, {0.3f, 0.31f}};
    for (size_t i = 0; i < sizeof ab / sizeof ab[0]; i++) {
        double a = ab[i][0], b = ab[i][1];
        for (int k = 0; k <= 20; k++) {
            float u = k == 20 ? 0x1.fffffep-1f : (float)k / 20.0f;
            double x = (double)sample_linear(u, ab[i][0], ab[i][1]);
            double cdf = (a * x + 0.5 * (b - a) * x * x) / (0.5 * (a + b));
            CHECKF(x >= 0.0 && x < 1.0 && fabs(cdf - (double)u) < 1e-5, "sample_linear(%g, %g, %g) = %g, CDF %g", (double)u, a, b, x, cdf);
        }
    }
    /* bilinear: chi-square over a 10 x 10 grid against the exact cell integrals */
    const float ws[][4] = {{0.1f, 0.1f, 0.9f, 0.5f}, {1.0f, 0.01f, 0.01f, 1.0f}, {0.3f, 0.3f, 0.3f, 0.3f}};
    rng r = rng_seed(3, 5);
    for (size_t i = 0; i < sizeof ws / sizeof ws[0]; i++) {
        enum { G = 10, N = 400000 };
        static int count[G * G];
        memset(count, 0, sizeof count);
        for (int k = 0; k < N; k++) {
            float x, y;
            sample_bilinear(rng_float(&r), rng_float(&r), ws[i], &x, &y);
            REQUIRE(x >= 0.0f && x < 1.0f && y >= 0.0f && y < 1.0f);
            count[(int)(y * G) * G + (int)(x * G)]++;
        }
        double chi2 = 0.0, sum = 0.0;
        for (int j = 0; j < 4; j++) sum += (double)ws[i][j];
        for (int cy = 0; cy < G; cy++)
            for (int cx = 0; cx < G; cx++) {
                /* integral of the bilinear patch over the cell: its value at the centre times the area */
                double x = (cx + 0.5) / G, y = (cy + 0.5) / G;
                const double w0 = ws[i][0], w1 = ws[i][1], w2 = ws[i][2], w3 = ws[i][3];
                double f = (1 - x) * (1 - y) * w0 + x * (1 - y) * w1 + (1 - x) * y * w2 + x * y * w3;
                double e = N * 4.0 * f / sum / (G * G);
                chi2 += (count[cy * G + cx] - e) * (count[cy * G + cx] - e) / e;
                /* the pdf at the centre, as the code computes it */
                CHECK_NEAR(bilinear_pdf((float)x, (float)y, ws[i]), 4.0 * f / sum, 1e-5);
            }
        double pv = chi2_pvalue(chi2, G * G - 1);
        CHECKF(pv > P_MIN, "bilinear warp %zu: chi2 %.1f, p %.3g", i, chi2, pv);
    }
}

/* ---- sampling against the pdf ------------------------------------------------ */

#define GRID 12                /* cells per side of the barycentric grid */
#define NCELL (2 * GRID * GRID) /* lower and upper cells of each square; GRID^2 of them exist */
#define SUB 6                  /* quadrature: each cell cut into SUB^2 triangles */

/* Corners (barycentric b1, b2) of cell (i, j, upper) of an n-grid. */
static void cell_corners(int n, int i, int j, int upper, double bc[3][2])
{
    const double s = 1.0 / n;
    if (!upper) {
        bc[0][0] = i * s, bc[0][1] = j * s, bc[1][0] = (i + 1) * s, bc[1][1] = j * s, bc[2][0] = i * s, bc[2][1] = (j + 1) * s;
    } else {
        bc[0][0] = (i + 1) * s, bc[0][1] = j * s, bc[1][0] = (i + 1) * s, bc[1][1] = (j + 1) * s, bc[2][0] = i * s,
        bc[2][1] = (j + 1) * s;
    }
}

static int cell_of(double b1, double b2)
{
    double fx = b1 * GRID, fy = b2 * GRID;
    int i = (int)floor(fx), j = (int)floor(fy);
    i = i < 0 ? 0 : i >= GRID ? GRID - 1 : i;
    j = j < 0 ? 0 : j >= GRID ? GRID - 1 : j;
    if (i + j > GRID - 1) { /* on the far edge, by rounding */
        if (fx - i > fy - j) j = GRID - 1 - i; else i = GRID - 1 - j;
    }
    int upper = (fx - i) + (fy - j) > 1.0 && i + j <= GRID - 2;
    return 2 * (i * GRID + j) + upper;
}

/* Integral of light_pdf_at over the solid angle of cell (i, j, upper), by
 * the midpoint rule on SUB^2 sub-triangles, each weighted by its exact
 * solid angle. */
static double cell_probability(const lab *L, const config *c, uint32_t mode, int i, int j, int upper)
{
    double bc[3][2];
    cell_corners(GRID, i, j, upper, bc);
    d3 a = d3_of(c->v[0]), e1 = d3_sub(d3_of(c->v[1]), a), e2 = d3_sub(d3_of(c->v[2]), a);
    d3 cw[3];
    for (int k = 0; k < 3; k++) cw[k] = d3_add(a, d3_add(d3_scale(e1, bc[k][0]), d3_scale(e2, bc[k][1])));
    d3 f1 = d3_sub(cw[1], cw[0]), f2 = d3_sub(cw[2], cw[0]);
    double sum = 0.0;
    for (int si = 0; si < SUB; si++)
        for (int sj = 0; si + sj < SUB; sj++)
            for (int su = 0; su < 2; su++) {
                if (su && si + sj > SUB - 2) continue;
                double sc[3][2];
                cell_corners(SUB, si, sj, su, sc);
                d3 w[3], centre = {0, 0, 0};
                for (int k = 0; k < 3; k++) {
                    w[k] = d3_add(cw[0], d3_add(d3_scale(f1, sc[k][0]), d3_scale(f2, sc[k][1])));
                    centre = d3_add(centre, d3_scale(w[k], 1.0 / 3.0));
                }
                double pdf = light_pdf_at(&L->v, &L->lights[0], c->p, c->n, mode, v3_of(centre), L->lights[0].normal);
                sum += pdf * solid_angle_d(d3_of(c->p), w[0], w[1], w[2]);
            }
    return sum;
}

/* Chi-square of where light_sample_one_with's points fall against
 * cell_probability; returns the p-value. */
static double chi2_config(const config *c, uint32_t mode, int nsamples, uint64_t seed)
{
    lab L;
    lab_init(&L, c->v, 1, false);
    const light_ctx lc = ctx_at(c->p, c->n);
    static double expected[NCELL];
    static int count[NCELL];
    memset(count, 0, sizeof count);
    memset(expected, 0, sizeof expected);
    double total_p = 0.0;
    for (int i = 0; i < GRID; i++)
        for (int j = 0; i + j < GRID; j++)
            for (int up = 0; up < 2; up++) {
                if (up && i + j > GRID - 2) continue;
                const int k = 2 * (i * GRID + j) + up;
                expected[k] = cell_probability(&L, c, mode, i, j, up);
                total_p += expected[k];
            }
    rng r = rng_seed(seed, 11);
    int n = 0;
    d3 a = d3_of(c->v[0]), b = d3_of(c->v[1]), cc = d3_of(c->v[2]);
    for (int s = 0; s < nsamples; s++) {
        light_sample ls;
        float u1 = rng_float(&r), u2 = rng_float(&r);
        if (!light_sample_one_with(&L.set, &L.v, &L.env, 0, &lc, mode, u1, u2, &ls)) continue;
        double b1, b2;
        barycentric_d(a, b, cc, d3_of(sample_point(&ls)), &b1, &b2);
        count[cell_of(b1, b2)]++;
        n++;
    }
    CHECKF(n == nsamples, "%s, %s: %d of %d samples failed", c->name, mode_name(mode), nsamples - n, nsamples);
    /* cells expecting fewer than 5 are pooled */
    double chi2 = 0.0, pool_e = 0.0, pool_o = 0.0;
    int dof = -1;
    for (int k = 0; k < NCELL; k++) {
        if (!(expected[k] > 0.0)) {
            CHECKF(count[k] == 0, "cell %d: %d samples where none are expected", k, count[k]);
            continue;
        }
        double e = expected[k] / total_p * n;
        if (e < 5.0) {
            pool_e += e, pool_o += count[k];
            continue;
        }
        chi2 += (count[k] - e) * (count[k] - e) / e;
        dof++;
    }
    if (pool_e > 0.0) chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e, dof++;
    double pv = chi2_pvalue(chi2, dof);
    printf("%s (%.4g sr), %s: chi2 %.1f, dof %d, p %.3g; integral of the pdf by quadrature %.6f\n", c->name,
           config_omega(c), mode_name(mode), chi2, dof, pv, total_p);
    CHECKF(pv > P_MIN, "%s, %s: chi2 %.1f (dof %d), p %.3g", c->name, mode_name(mode), chi2, dof, pv);
    CHECKF(fabs(total_p - 1.0) < 2e-3, "%s, %s: the pdf integrates to %.6f by quadrature", c->name, mode_name(mode),
           total_p);
    return pv;
}

static void test_chi2(void)
{
    const uint32_t modes[] = {LIGHT_TRI_SOLID_ANGLE, LIGHT_TRI_SOLID_ANGLE_COS, LIGHT_TRI_AREA};
    for (int i = 0; i < NCONFIG; i++) {
        double om = config_omega(&configs[i]);
        REQUIRE(om > (double)SPH_TRI_MIN_SOLID_ANGLE && om < (double)SPH_TRI_MAX_SOLID_ANGLE); /* all exercise the map */
        for (int m = 0; m < 3; m++) chi2_config(&configs[i], modes[m], 300000, 100 + (uint64_t)(7 * i + m));
    }
}

/* The pdf returned with each sample is light_pdf_at's for its direction;
 * light_pdf_at integrates to 1 over the triangle (sampled by area:
 * E[pdf / pdf_area] = 1), and the sampler covers all of it (sampled by the
 * mode: E[pdf_area / pdf] = 1). */
static void test_pdf_consistency(void)
{
    const uint32_t modes[] = {LIGHT_TRI_SOLID_ANGLE, LIGHT_TRI_SOLID_ANGLE_COS};
    enum { N = 200000 };
    for (int i = 0; i < NCONFIG; i++) {
        const config *c = &configs[i];
        lab L;
        lab_init(&L, c->v, 1, false);
        const light *l = &L.lights[0];
        const light_ctx lc = ctx_at(c->p, c->n);
        for (int m = 0; m < 2; m++) {
            rng r = rng_seed(500 + (uint64_t)i, (uint64_t)m);
            double worst = 0.0, s1 = 0.0, s2 = 0.0, t1 = 0.0, t2 = 0.0;
            for (int k = 0; k < N; k++) {
                light_sample ls;
                REQUIRE(light_sample_one_with(&L.set, &L.v, &L.env, 0, &lc, modes[m], rng_float(&r), rng_float(&r), &ls));
                vec3 q = sample_point(&ls);
                float again = light_pdf_at(&L.v, l, c->p, c->n, modes[m], q, l->normal);
                worst = fmax(worst, fabs((double)again / (double)ls.pdf - 1.0));
                double x = (double)light_pdf_area(&L.v, l, c->p, q, l->normal) / (double)ls.pdf;
                s1 += x, s2 += x * x;
                /* by area */
                vec3 qa = sample_triangle(c->v[0], c->v[1], c->v[2], rng_float(&r), rng_float(&r));
                double y = (double)light_pdf_at(&L.v, l, c->p, c->n, modes[m], qa, l->normal) /
                           (double)light_pdf_area(&L.v, l, c->p, qa, l->normal);
                t1 += y, t2 += y * y;
            }
            double ms = s1 / N, se_s = sqrt(fmax(0.0, s2 / N - ms * ms) / N);
            double mt = t1 / N, se_t = sqrt(fmax(0.0, t2 / N - mt * mt) / N);
            printf("%s, %s: pdf of the sample vs light_pdf_at: largest relative difference %.2g; "
                   "integral of the pdf %.5f +- %.5f, coverage %.5f +- %.5f\n",
                   c->name, mode_name(modes[m]), worst, mt, se_t, ms, se_s);
            /* the plain mode is the same expression on both sides; the warp inverts the map */
            CHECKF(worst < (m == 0 ? 1e-6 : 2e-3), "%s, %s: light_pdf_at differs from the sample's pdf by %g", c->name,
                   mode_name(modes[m]), worst);
            CHECKF(fabs(mt - 1.0) < Z_MEAN * se_t + 1e-4, "%s, %s: the pdf integrates to %.5f +- %.5f", c->name,
                   mode_name(modes[m]), mt, se_t);
            CHECKF(fabs(ms - 1.0) < Z_MEAN * se_s + 1e-4, "%s, %s: E[pdf_area / pdf] = %.5f +- %.5f", c->name,
                   mode_name(modes[m]), ms, se_s);
        }
    }
    /* outside the solid-angle range both sides fall back to area sampling */
    const vec3 tiny[3] = {{-0.5f, -0.5f, 60.0f}, {0.0f, 0.5f, 60.0f}, {0.5f, -0.5f, 60.0f}};
    lab L;
    lab_init(&L, tiny, 1, false);
    const light_ctx lc = ctx_at(v3s(0.0f), v3(0.0f, 0.0f, 1.0f));
    REQUIRE(solid_angle_d((d3){0, 0, 0}, d3_of(tiny[0]), d3_of(tiny[1]), d3_of(tiny[2])) < (double)SPH_TRI_MIN_SOLID_ANGLE);
    rng r = rng_seed(9, 9);
    for (int k = 0; k < 1000; k++) {
        light_sample ls;
        REQUIRE(light_sample_one(&L.set, &L.v, &L.env, 0, &lc, rng_float(&r), rng_float(&r), &ls));
        float pa = light_pdf_area(&L.v, &L.lights[0], lc.p, sample_point(&ls), L.lights[0].normal);
        CHECK(ls.pdf == pa && light_pdf_li(&L.v, &L.lights[0], lc.p, lc.n, sample_point(&ls), L.lights[0].normal) == pa);
    }
}

/* ---- closed forms ------------------------------------------------------------- */

typedef struct acc {
    double s1, s2;
    long n;
} acc;
static void acc_add(acc *a, double x) { a->s1 += x, a->s2 += x * x, a->n++; }
static double acc_mean(const acc *a) { return a->s1 / (double)a->n; }
static double acc_var(const acc *a) { double m = acc_mean(a); return fmax(0.0, a->s2 / (double)a->n - m * m); }
static double acc_se(const acc *a) { return sqrt(acc_var(a) / (double)a->n); }

static double power_heuristic(double a, double b) { return a * a + b * b > 0.0 ? a * a / (a * a + b * b) : 0.0; }

/* Irradiance at (p, n) of the lights of L (radiance 1), whose polygon is
 * poly: light sampling alone, and MIS of light sampling and cosine
 * sampling, in each mode; every estimate within Z_MEAN standard errors of
 * Lambert's formula. */
static void irradiance_check(const char *name, lab *L, vec3 p, vec3 n, const d3 *poly, int npoly, int nsamples)
{
    const double ref = polygon_irradiance(d3_of(p), d3_of(n), poly, npoly);
    const uint32_t modes[] = {LIGHT_TRI_AREA, LIGHT_TRI_SOLID_ANGLE, LIGHT_TRI_SOLID_ANGLE_COS};
    const light_ctx lc = ctx_at(p, n);
    double var[3];
    for (int m = 0; m < 3; m++) {
        acc light_only = {0}, mis = {0};
        rng r = rng_seed(77 + (uint64_t)m, 3);
        for (int k = 0; k < nsamples; k++) {
            /* light sampling */
            double x = 0.0, xm = 0.0;
            light_sample ls;
            float u0 = rng_float(&r), u1 = rng_float(&r), u2 = rng_float(&r);
            if (light_sample_li_with(&L->set, &L->v, &L->env, &lc, modes[m], u0, u1, u2, &ls)) {
                double cosr = fmax(0.0, (double)v3_dot(n, ls.wi));
                x = (double)ls.le.x * cosr / (double)ls.pdf;
                xm = x * power_heuristic((double)ls.pdf, cosr / PI_D);
            }
            acc_add(&light_only, x);
            /* cosine sampling, the light's pdf from light_pdf_at (the MIS weight) */
            vec3 wb = sample_cosine(n, rng_float(&r), rng_float(&r));
            double pb = fmax(0.0, (double)v3_dot(n, wb)) / PI_D;
            for (size_t li = 0; li < L->set.n; li++) {
                vec3 a, b, c;
                view_tri_verts(&L->v, li, &a, &b, &c);
                d3 q;
                if (pb > 0.0 && ray_tri_d(d3_of(p), d3_of(wb), d3_of(a), d3_of(b), d3_of(c), &q)) {
                    const light *l = &L->lights[li];
                    double pl = (double)L->pmf[li] * (double)light_pdf_at(&L->v, l, p, n, modes[m], v3_of(q), l->normal);
                    xm += PI_D * power_heuristic(pb, pl); /* L cos / pb = pi */
                    break;
                }
            }
            acc_add(&mis, xm);
        }
        double z1 = (acc_mean(&light_only) - ref) / acc_se(&light_only), z2 = (acc_mean(&mis) - ref) / acc_se(&mis);
        var[m] = acc_var(&light_only);
        printf("%s, %s: E = %.6f (Lambert %.6f); light sampling %.6f (z %.2f, variance %.4g), MIS %.6f (z %.2f, "
               "variance %.4g)\n",
               name, mode_name(modes[m]), ref, ref, acc_mean(&light_only), z1, acc_var(&light_only), acc_mean(&mis), z2,
               acc_var(&mis));
        CHECKF(fabs(z1) < Z_MEAN, "%s, %s: light sampling %.6f vs %.6f (z %.2f)", name, mode_name(modes[m]),
               acc_mean(&light_only), ref, z1);
        CHECKF(fabs(z2) < Z_MEAN, "%s, %s: MIS %.6f vs %.6f (z %.2f)", name, mode_name(modes[m]), acc_mean(&mis), ref, z2);
    }
    printf("%s: variance of light sampling relative to area sampling: solid angle %.3f, x cos %.3f\n", name,
           var[1] / var[0], var[2] / var[0]);
}

static void test_irradiance(void)
{
    for (int i = 0; i < NCONFIG; i++) {
        const config *c = &configs[i];
        lab L;
        lab_init(&L, c->v, 1, false);
        d3 poly[3] = {d3_of(c->v[0]), d3_of(c->v[1]), d3_of(c->v[2])};
        /* Lambert's formula needs the whole polygon above the horizon */
        bool above = true;
        for (int k = 0; k < 3; k++) above = above && v3_dot(c->n, v3_sub(c->v[k], c->p)) > 0.0f;
        if (above) irradiance_check(c->name, &L, c->p, c->n, poly, 3, 200000);
    }
    /* a quad light of two triangles close to a wall's corner, and above a floor */
    const vec3 quad[4] = {{-0.5f, 1.0f, -0.5f}, {0.5f, 1.0f, -0.5f}, {0.5f, 1.0f, 0.5f}, {-0.5f, 1.0f, 0.5f}}; /* facing -y */
    const vec3 tris[6] = {quad[0], quad[1], quad[2], quad[0], quad[2], quad[3]};
    lab L;
    lab_init(&L, tris, 2, false);
    d3 poly[4] = {d3_of(quad[0]), d3_of(quad[1]), d3_of(quad[2]), d3_of(quad[3])};
    irradiance_check("quad over the floor", &L, v3(0.1f, 0.0f, 0.2f), v3(0.0f, 1.0f, 0.0f), poly, 4, 200000);
    irradiance_check("quad beside a wall", &L, v3(-0.6f, 0.9f, 0.0f), v3(1.0f, 0.0f, 0.0f), poly, 4, 200000);
}

/* ---- degenerate and extreme triangles ---------------------------------------- */

static void test_robust(void)
{
    rng r = rng_seed(31, 4);
    const float us[] = {0.0f, 0x1.fffffep-1f, 0.5f, 1e-7f};
    long sampled = 0, refused = 0;
    for (int k = 0; k < 60000; k++) {
        vec3 v[3], p;
        const int kind = k % 10;
        const float scale = powf(10.0f, (float)((int)(rng_u32(&r) % 9) * 6 - 24)); /* 1e-24 .. 1e24 */
        for (int j = 0; j < 3; j++)
            v[j] = v3_scale(v3(2.0f * rng_float(&r) - 1.0f, 2.0f * rng_float(&r) - 1.0f, 2.0f * rng_float(&r) - 1.0f), scale);
        p = v3_scale(v3(2.0f * rng_float(&r) - 1.0f, 2.0f * rng_float(&r) - 1.0f, 2.0f * rng_float(&r) - 1.0f), scale);
        switch (kind) {
        case 1: v[2] = v3_lerp(v[0], v[1], rng_float(&r)); break;                    /* collinear */
        case 2: v[1] = v[0]; break;                                                  /* repeated vertex */
        case 3: p = v[(int)(rng_u32(&r) % 3)]; break;                                /* at a vertex */
        case 4: p = v3_lerp(v[0], v[1], rng_float(&r)); break;                       /* on an edge */
        case 5: p = sample_triangle(v[0], v[1], v[2], rng_float(&r), rng_float(&r)); break; /* on the triangle */
        case 6: v[2] = v3_add(v3_lerp(v[0], v[1], 0.5f), v3_scale(v3(1e-6f, -2e-6f, 1e-6f), scale)); break; /* sliver */
        case 7: p = v3_add(v[0], v3_scale(v3_sub(v[1], v[0]), 1e-4f)); break;       /* next to a vertex */
        case 8: p = v3_add(sample_triangle(v[0], v[1], v[2], 0.3f, 0.6f), v3_scale(tri_normal(v[0], v[1], v[2]), 1e-5f * scale)); break;
        case 9: for (int j = 0; j < 3; j++) v[j] = v3_scale(v[j], 1e14f); break;     /* up to 1e38 */
        default: break;
        }
        lab L;
        lab_init(&L, v, 1, true);
        const light *l = &L.lights[0];
        const vec3 n = v3_norm_scaled(v3(rng_float(&r) - 0.5f, rng_float(&r) - 0.5f, rng_float(&r) - 0.5f));
        const light_ctx lc = ctx_at(p, n);
        for (uint32_t mode = 0; mode < 3; mode++) {
            float u1 = (k & 3) == 0 ? us[rng_u32(&r) % 4] : rng_float(&r), u2 = (k & 7) == 0 ? us[rng_u32(&r) % 4] : rng_float(&r);
            light_sample ls;
            if (light_sample_one_with(&L.set, &L.v, &L.env, 0, &lc, mode, u1, u2, &ls)) {
                sampled++;
                CHECKF(isfinite(ls.pdf) && ls.pdf > 0.0f && v3_finite(ls.wi) && v3_finite(ls.shadow.d),
                       "kind %d scale %g mode %u: pdf %g", kind, (double)scale, mode, (double)ls.pdf);
                float again = light_pdf_at(&L.v, l, p, n, mode, sample_point(&ls), l->normal);
                CHECKF(isfinite(again) && again >= 0.0f, "kind %d: light_pdf_at %g", kind, (double)again);
            } else {
                refused++;
            }
            vec3 q = sample_triangle(v[0], v[1], v[2], rng_float(&r), rng_float(&r));
            float pq = light_pdf_at(&L.v, l, p, n, mode, q, l->normal);
            CHECKF(isfinite(pq) && pq >= 0.0f, "kind %d scale %g mode %u: light_pdf_at %g", kind, (double)scale, mode,
                   (double)pq);
            sph_tri st;
            if (sph_tri_setup(&st, p, v[0], v[1], v[2], SPH_TRI_MIN_SOLID_ANGLE, SPH_TRI_MAX_SOLID_ANGLE)) {
                vec3 w = sph_tri_sample(&st, u1, u2);
                float x0, x1;
                sph_tri_invert(&st, w, &x0, &x1);
                CHECKF(v3_finite(w) && x0 >= 0.0f && x0 <= 1.0f && x1 >= 0.0f && x1 <= 1.0f, "kind %d: map gives NaN", kind);
            }
        }
    }
    printf("robustness: %ld samples, %ld refused, nothing non-finite\n", sampled, refused);
}

/* light_tri_spherical's cheap bound never turns away a triangle whose
 * solid angle is in range: the rule is the exact one. */
static void test_bound(void)
{
    rng r = rng_seed(17, 2);
    long spherical = 0, n = 200000;
    for (long k = 0; k < n; k++) {
        vec3 v[3];
        const float size = powf(10.0f, -3.0f * rng_float(&r)); /* 1e-3 .. 1, seen from about 1 */
        const vec3 c = v3(2.0f * rng_float(&r) - 1.0f, 2.0f * rng_float(&r) - 1.0f, 2.0f * rng_float(&r) - 1.0f);
        for (int j = 0; j < 3; j++)
            v[j] = v3_add(c, v3_scale(v3(rng_float(&r) - 0.5f, rng_float(&r) - 0.5f, rng_float(&r) - 0.5f), size));
        lab L;
        lab_init(&L, v, 1, true);
        sph_tri a, b;
        const bool exact = sph_tri_setup(&a, v3s(0.0f), v[0], v[1], v[2], SPH_TRI_MIN_SOLID_ANGLE, SPH_TRI_MAX_SOLID_ANGLE);
        const bool rule = light_tri_spherical(&L.lights[0], v3s(0.0f), &b);
        CHECKF(exact == rule, "size %g: exact %d, with the bound %d (solid angle %g)", (double)size, exact, rule,
               solid_angle_d((d3){0, 0, 0}, d3_of(v[0]), d3_of(v[1]), d3_of(v[2])));
        spherical += rule;
    }
    printf("bound: %ld of %ld random triangles sampled by solid angle, the same as without the bound\n", spherical, n);
}

int main(void)
{
    test_solid_angle();
    test_invert();
    test_bilinear();
    test_chi2();
    test_pdf_consistency();
    test_bound();
    test_irradiance();
    test_robust();
    return test_done("test_light_sampling");
}

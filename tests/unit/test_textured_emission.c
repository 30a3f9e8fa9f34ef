/*
 * test_textured_emission.c - emitters whose radiance is an image (map_ke):
 *
 * - each emitting triangle's power for light selection is ke times the
 *   map's mean over the triangle's own uv footprint: against a brute-force
 *   sum over the finest texels (each texel's share of the triangle counted
 *   by 16 x 16 points), within the bound the coarser level allows;
 * - the pdf a light sample reports (choice times solid angle) equals what
 *   the path tracer computes for the same point when a BSDF-sampled ray
 *   hits the emitter (light_pmf x light_pdf_li), with and without the tree;
 * - irradiance on a floor under a square emitter with a two-valued texture
 *   (one bright corner): light sampling alone, BSDF sampling alone and MIS
 *   against quadrature over the emitter in double precision, each block
 *   within a confidence interval from its measured variance.
 *
 * - every reader's textured emitter reaches the material's emission map,
 *   without a warning: OBJ/MTL map_Ke, a JSON emitter's radiance texture,
 *   pbrt-v4's diffuse area light with a filename, Mitsuba's area emitter
 *   with a bitmap radiance.
 *
 * PK_EMIT_BENCH=1 also times building the light set over 100k emitting
 * triangles on a 4096 x 4096 texture.
 */
#include "test.h"

#include "paprsek.h"
#include "render/lights.h"
#include "render/path.h"
#include "render/render.h"
#include "scene/scene.h"

#include "render/block_stats.h"
#include "warnings.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static pk_context *ctx;
static char dir[64];
static warning_log wl;

/* ---- files ---------------------------------------------------------------- */

static void write_pfm(const char *path, int w, int h, const float *grey)
{
    FILE *fp = fopen(path, "wb");
    REQUIRE(fp);
    fprintf(fp, "PF\n%d %d\n-1\n", w, h);
    for (int y = h - 1; y >= 0; y--) /* PFM stores the bottom row first */
        for (int x = 0; x < w; x++) {
            const float px[3] = {grey[y * w + x], grey[y * w + x], grey[y * w + x]};
            fwrite(px, sizeof px, 1, fp);
        }
    fclose(fp);
}

static void put_file(const char *name, const char *text)
{
    char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "w");
    REQUIRE(fp);
    fputs(text, fp);
    fclose(fp);
}

static pk_scene *load_json(const char *json)
{
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, json, strlen(json), "t.json", dir, &s);
    CHECKF(st == PK_OK, "load: %s", pk_context_error(ctx));
    if (st != PK_OK) return NULL;
    REQUIRE(pk_scene_commit(ctx, s) == PK_OK);
    return s;
}

/* ---- the texture as the renderer reads it --------------------------------- */

typedef struct img {
    int w, h;
    const float *px; /* row 0 at v = 1 */
} img;

static double texel(const img *t, long x, long y, bool clamp)
{
    if (clamp) {
        x = x < 0 ? 0 : x >= t->w ? t->w - 1 : x;
        y = y < 0 ? 0 : y >= t->h ? t->h - 1 : y;
    } else {
        x = ((x % t->w) + t->w) % t->w;
        y = ((y % t->h) + t->h) % t->h;
    }
    return (double)t->px[y * t->w + x];
}

/* Bilinear, repeat or clamp, texel (x, y) centred at ((x + 0.5) / w, 1 - (y + 0.5) / h). */
static double bilinear_at(const img *t, double u, double v, bool clamp)
{
    if (clamp) u = fmin(fmax(u, 0.0), 1.0), v = fmin(fmax(v, 0.0), 1.0);
    else u -= floor(u), v -= floor(v);
    const double x = u * t->w - 0.5, y = (1.0 - v) * t->h - 0.5;
    const double x0 = floor(x), y0 = floor(y), fx = x - x0, fy = y - y0;
    const long ix = (long)x0, iy = (long)y0;
    const double a = texel(t, ix, iy, clamp), b = texel(t, ix + 1, iy, clamp);
    const double c = texel(t, ix, iy + 1, clamp), d = texel(t, ix + 1, iy + 1, clamp);
    return (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
}

static double bilinear(const img *t, double u, double v) { return bilinear_at(t, u, v, false); }

/* ---- 1. integrated powers against a brute-force texel sum ------------------ */

static double rnd(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

static double edge(double ax, double ay, double bx, double by, double px, double py)
{
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

/* The mean over the triangle p (texel units of the finest level) of the
 * texture as lookups see it (bilinear), by sub x sub points a texel. */
static double brute_mean(const img *t, const double p[6], bool clamp, int sub, double *outside)
{
    double out = 0.0;
    const double xlo = fmin(p[0], fmin(p[2], p[4])), xhi = fmax(p[0], fmax(p[2], p[4]));
    const double ylo = fmin(p[1], fmin(p[3], p[5])), yhi = fmax(p[1], fmax(p[3], p[5]));
    const double sgn = edge(p[0], p[1], p[2], p[3], p[4], p[5]) > 0 ? 1.0 : -1.0;
    double sum = 0.0, cnt = 0.0;
    for (long iy = (long)floor(ylo); iy <= (long)floor(yhi); iy++)
        for (long ix = (long)floor(xlo); ix <= (long)floor(xhi); ix++) {
            int in = 0;
            for (int j = 0; j < sub; j++)
                for (int i = 0; i < sub; i++) {
                    const double x = (double)ix + (i + 0.5) / sub, y = (double)iy + (j + 0.5) / sub;
                    if (sgn * edge(p[0], p[1], p[2], p[3], x, y) >= 0 && sgn * edge(p[2], p[3], p[4], p[5], x, y) >= 0 &&
                        sgn * edge(p[4], p[5], p[0], p[1], x, y) >= 0)
                        in++, sum += bilinear_at(t, x / t->w, 1.0 - y / t->h, clamp);
                }
            cnt += in;
            if (ix < 0 || iy < 0 || ix >= t->w || iy >= t->h) out += in;
        }
    *outside = cnt > 0 ? out / cnt : 0.0;
    return cnt > 0 ? sum / cnt : (double)NAN;
}

#define NTRI 48

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void check_powers(void)
{
    /* a 64 x 64 grey texture: a ramp of stripes with bright spots, values in [0.05, 20] */
    enum { W = 64 };
    static float px[W * W];
    double vmin = INFINITY, vmax = 0.0;
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
            float v = 0.05f + (float)((x * 7 + y * 13) % 17) / 16.0f;
            if ((x / 8 + y / 8) % 5 == 0) v += 20.0f * (float)((x + y) % 3 == 0);
            px[y * W + x] = v;
            vmin = fmin(vmin, v), vmax = fmax(vmax, v);
        }
    char path[128];
    snprintf(path, sizeof path, "%s/tex.pfm", dir);
    write_pfm(path, W, W, px);
    const img tx = {W, W, px};
    /* NTRI triangles, each alone with its uvs: sizes from a third of a texel
     * to three repeats of the image; the second half through a material
     * with -s 2 1.5 -o 0.25 -0.5 -clamp on */
    char obj[1 << 16];
    size_t o = (size_t)snprintf(obj, sizeof obj, "mtllib t.mtl\n");
    double uvs[NTRI][6];
    unsigned seed = 7;
    for (int i = 0; i < NTRI; i++) {
        const double size = pow(10.0, -2.3 + 2.8 * rnd(&seed)); /* uv units: 0.005 .. 3 */
        const double cu = 2.0 * rnd(&seed) - 0.5, cv = 2.0 * rnd(&seed) - 0.5;
        for (int k = 0; k < 3; k++) {
            uvs[i][2 * k] = cu + size * (rnd(&seed) - 0.5);
            uvs[i][2 * k + 1] = cv + size * (rnd(&seed) - 0.5);
        }
        const double x = (double)(i % 8) * 3.0, z = (double)(i / 8) * 3.0;
        o += (size_t)snprintf(obj + o, sizeof obj - o,
                              "%sv %g 0 %g\nv %g 0 %g\nv %g 0 %g\nvt %.9g %.9g\nvt %.9g %.9g\nvt %.9g %.9g\n"
                              "f %d/%d %d/%d %d/%d\n",
                              i == 0 ? "usemtl a\n" : i == NTRI / 2 ? "usemtl b\n" : "", x, z, x + 1 + 0.1 * i, z,
                              x, z + 1.5, uvs[i][0], uvs[i][1], uvs[i][2], uvs[i][3], uvs[i][4], uvs[i][5], 3 * i + 1,
                              3 * i + 1, 3 * i + 2, 3 * i + 2, 3 * i + 3, 3 * i + 3);
    }
    /* a triangle of no uv area: the texel under its one uv */
    o += (size_t)snprintf(obj + o, sizeof obj - o,
                          "usemtl a\nv 0 0 -5\nv 1 0 -5\nv 0 0 -4\nvt 0.3 0.6\nf %d/%d %d/%d %d/%d\n", 3 * NTRI + 1,
                          3 * NTRI + 1, 3 * NTRI + 2, 3 * NTRI + 1, 3 * NTRI + 3, 3 * NTRI + 1);
    put_file("t.obj", obj);
    put_file("t.mtl", "newmtl a\nKd 0 0 0\nKe 1 1 1\nmap_Ke tex.pfm\n"
                      "newmtl b\nKd 0 0 0\nKe 1 1 1\nmap_Ke -s 2 1.5 1 -o 0.25 -0.5 0 -clamp on tex.pfm\n");
    pk_scene *s = load_json("{\"camera\": {\"look_from\": [0, 5, 0], \"look_at\": [0, 0, 0], \"up\": [0, 0, 1]},"
                            " \"meshes\": [{\"obj\": \"t.obj\"}]}");
    REQUIRE(s);
    REQUIRE(s->nemissive == NTRI + 1);
    env_light env;
    memset(&env, 0, sizeof env);
    light_set ls;
    REQUIRE(light_set_build(ctx, s, &env, &ls) == PK_OK);
    REQUIRE(ls.n == NTRI + 1);
    double worst = 0.0, worst_bound = 0.0, errs[NTRI];
    int bad = 0, nerr = 0;
    for (size_t k = 0; k < ls.n; k++) {
        const light *l = &ls.lights[k];
        const int i = (int)l->index;
        /* the mean the set used: power = mean * area * pi (one-sided, ke 1) */
        const double got = (double)ls.pmf[k] * ls.power / ((double)l->area * M_PI);
        if (i == NTRI) { /* the sliver: the texel under uv (0.3, 0.6) */
            const double want = texel(&tx, (long)floor(0.3 * W), (long)floor(0.4 * W), false);
            CHECKF(fabs(got - want) <= 1e-5 * want, "uv sliver: mean %.6g, the texel %.6g", got, want);
            continue;
        }
        const bool b = i >= NTRI / 2;
        const double su = b ? 2.0 : 1.0, sv = b ? 1.5 : 1.0, ou = b ? 0.25 : 0.0, ov = b ? -0.5 : 0.0;
        double p[6];
        for (int j = 0; j < 3; j++) {
            p[2 * j] = (su * uvs[i][2 * j] + ou) * W;
            p[2 * j + 1] = (1.0 - (sv * uvs[i][2 * j + 1] + ov)) * W;
        }
        const double bw0 = fmax(p[0], fmax(p[2], p[4])) - fmin(p[0], fmin(p[2], p[4]));
        const double bh0 = fmax(p[1], fmax(p[3], p[5])) - fmin(p[1], fmin(p[3], p[5]));
        /* points enough for a few thousand inside the smallest triangles */
        const int sub = (int)fmin(256.0, fmax(16.0, ceil(64.0 / fmin(bw0, bh0))));
        double outside;
        const double want = brute_mean(&tx, p, b, sub, &outside);
        /* the level the method reads (texture.h: the finest on which the
         * box spans at most TEX_TRI_CELLS texels); its texels are exact means
         * of the finest ones, and the bilinear filter moves light by less
         * than a finest texel, so only points near the edges count
         * differently: within sqrt(2) level texels plus one finest texel of
         * them, a band of area at most 2 d perimeter + pi d^2; the brute
         * force's own error is in the same kind of band of 1/sub texel */
        const double bw = bw0, bh = bh0;
        double side = 1.0;
        while (side < W && (bw / side > TEX_TRI_CELLS || bh / side > TEX_TRI_CELLS)) side *= 2.0;
        const double per = hypot(p[2] - p[0], p[3] - p[1]) + hypot(p[4] - p[2], p[5] - p[3]) + hypot(p[0] - p[4], p[1] - p[5]);
        const double area = 0.5 * fabs(edge(p[0], p[1], p[2], p[3], p[4], p[5]));
        const double d = (side > 1.0 ? M_SQRT2 * side : 0.0) + 1.0, db = M_SQRT2 / sub;
        double bound = (vmax - vmin) * (2.0 * d * per + M_PI * d * d + 2.0 * db * per + M_PI * db * db) / area;
        /* clamped outside the image, a coarse level's edge texels stand for
         * the finest's, which they need not equal */
        if (b && side > 1.0) bound += (vmax - vmin) * outside;
        if (side >= W) bound = vmax - vmin; /* the whole image's mean: only the range bounds it */
        bound += 1e-5 * want;                /* float rounding */
        const double err = fabs(got - want);
        if (getenv("PK_EMIT_VERBOSE"))
            printf("triangle %2d: box %8.3g x %8.3g texels, level side %3g: mean %.6g, brute force %.6g, error %.3g, bound %.3g\n",
                   i, bw, bh, side, got, want, err / want, bound / want);
        if (err / want > worst) worst = err / want, worst_bound = bound / want;
        errs[nerr++] = err / want;
        if (!(err <= bound)) {
            bad++;
            fprintf(stderr, "triangle %d (box %.3g x %.3g texels): mean %.6g, brute force %.6g, bound %.3g\n", i, bw,
                    bh, got, want, bound);
        }
    }
    qsort(errs, (size_t)nerr, sizeof *errs, cmp_double);
    printf("triangle means vs brute force: relative error median %.3g, largest %.3g (its bound %.3g)\n",
           errs[nerr / 2], worst, worst_bound);
    CHECKF(bad == 0, "%d triangle means outside their bounds", bad);
    light_set_free(&ctx->alloc, &ls);
    pk_scene_destroy(s);
}

/* ---- 2 and 3: a square emitter with a bright corner over a floor ----------- */

#define EW 8     /* the texture's side */
#define EN 8     /* the emitter's grid: EN x EN squares, two triangles each */
#define SIZE 32  /* image side */
#define BLOCK 8
#define VIEW 1.6 /* the orthographic view's width on the floor */
#define KD 0.5
static float etex[EW * EW];

static pk_scene *emitter_scene(void)
{
    for (int y = 0; y < EW; y++)
        for (int x = 0; x < EW; x++) etex[y * EW + x] = (x >= 5 && y >= 5) ? 40.0f : 0.05f;
    char path[128];
    snprintf(path, sizeof path, "%s/e.pfm", dir);
    write_pfm(path, EW, EW, etex);
    /* the emitter: [-0.5, 0.5]^2 at y = 1 facing down, u = x + 0.5, v = z + 0.5 */
    static char obj[1 << 16];
    size_t o = (size_t)snprintf(obj, sizeof obj, "mtllib e.mtl\nusemtl lamp\n");
    for (int j = 0; j <= EN; j++)
        for (int i = 0; i <= EN; i++) {
            const double x = -0.5 + (double)i / EN, z = -0.5 + (double)j / EN;
            o += (size_t)snprintf(obj + o, sizeof obj - o, "v %.9g 1 %.9g\nvt %.9g %.9g\n", x, z, x + 0.5, z + 0.5);
        }
    for (int j = 0; j < EN; j++)
        for (int i = 0; i < EN; i++) {
            const int a = j * (EN + 1) + i + 1, b = a + 1, c = a + EN + 1, d = c + 1;
            /* (x, z) -> (x + dx, z), (x, z + dz): normal -y */
            o += (size_t)snprintf(obj + o, sizeof obj - o, "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", a, a, b, b, c,
                                  c, b, b, d, d, c, c);
        }
    o += (size_t)snprintf(obj + o, sizeof obj - o,
                          "usemtl floor\nv -1 0 -1\nv -1 0 1\nv 1 0 -1\nv 1 0 1\nf %d %d %d\nf %d %d %d\n",
                          (EN + 1) * (EN + 1) + 1, (EN + 1) * (EN + 1) + 2, (EN + 1) * (EN + 1) + 3,
                          (EN + 1) * (EN + 1) + 2, (EN + 1) * (EN + 1) + 4, (EN + 1) * (EN + 1) + 3);
    put_file("e.obj", obj);
    char mtl[256];
    snprintf(mtl, sizeof mtl, "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nmap_Ke e.pfm\nnewmtl floor\nKd %g %g %g\n", KD, KD, KD);
    put_file("e.mtl", mtl);
    char json[512];
    snprintf(json, sizeof json,
             "{\"camera\": {\"look_from\": [0, 0.5, 0], \"look_at\": [0, 0, 0], \"up\": [0, 0, -1],"
             " \"projection\": \"orthographic\", \"ortho_width\": %g},"
             " \"meshes\": [{\"obj\": \"e.obj\"}]}",
             VIEW);
    return load_json(json);
}

/* Irradiance at floor point (x, 0, z) from the emitter: ke times the
 * bilinear texture over the square, cos cos / r^2 = 1 / r^4 at height 1,
 * by the midpoint rule on Q x Q cells. */
#define Q 192
static double irradiance(double x, double z)
{
    const img t = {EW, EW, etex};
    double sum = 0.0;
    for (int j = 0; j < Q; j++)
        for (int i = 0; i < Q; i++) {
            const double u = (i + 0.5) / Q, v = (j + 0.5) / Q;
            const double dx = u - 0.5 - x, dz = v - 0.5 - z, r2 = dx * dx + dz * dz + 1.0;
            sum += bilinear(&t, u, v) / (r2 * r2);
        }
    return sum / ((double)Q * Q);
}

/* Block means of the image the floor gives (kd / pi times irradiance), each
 * block's square by 4 x 4 Gauss-Legendre points. Pixel (px, py) sees the
 * floor at x = -VIEW/2 + (px + 0.5) VIEW / SIZE, z likewise from the top. */
static void quadrature(block_estimate *e)
{
    static const double g[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    memset(e, 0, sizeof *e);
    e->nb = SIZE / BLOCK;
    const double bs = VIEW * BLOCK / SIZE;
    for (int by = 0; by < e->nb; by++)
        for (int bx = 0; bx < e->nb; bx++) {
            const double cx = -VIEW / 2 + (bx + 0.5) * bs, cz = -VIEW / 2 + (by + 0.5) * bs;
            double m = 0.0;
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++) m += gw[i] * gw[j] / 4.0 * irradiance(cx + 0.5 * bs * g[i], cz + 0.5 * bs * g[j]);
            for (int c = 0; c < 3; c++) e->mean[by][bx][c] = KD / M_PI * m;
        }
}

static void render_strategy(const pk_scene *s, int strategy, int spp, int seed0, block_estimate *e)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = o.height = SIZE;
    o.spp = spp;
    o.max_depth = 2;
    o.threads = 2;
    pk_image *im[2];
    for (int k = 0; k < 2; k++) {
        o.seed = seed0 + 17 * k + strategy;
        pk_renderer *r = NULL;
        pk_film *f = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        renderer_set_path_strategy(r, strategy);
        REQUIRE(pk_film_create(ctx, SIZE, SIZE, &f) == PK_OK);
        REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
        REQUIRE(pk_film_resolve(ctx, f, &im[k]) == PK_OK);
        pk_film_destroy(f);
        pk_renderer_destroy(r);
    }
    block_estimate_from(im[0], im[1], BLOCK, e);
    pk_image_destroy(im[0]);
    pk_image_destroy(im[1]);
}

static double summed_var(const block_estimate *e)
{
    double v = 0.0;
    for (int by = 0; by < e->nb; by++)
        for (int bx = 0; bx < e->nb; bx++)
            for (int c = 0; c < 3; c++) v += e->var[by][bx][c];
    return v;
}

/* two-sided p = 1e-3 over 16 blocks x 3 channels x 3 strategies: Phi^-1(1 - 0.001 / 288) */
#define Z_CRIT 4.50

static void check_irradiance(pk_scene *s)
{
    static block_estimate want, mis, lights, bsdf;
    quadrature(&want);
    render_strategy(s, PATH_MIS, 64, 1000, &mis);
    render_strategy(s, PATH_LIGHTS_ONLY, 64, 2000, &lights);
    render_strategy(s, PATH_BSDF_ONLY, 256, 3000, &bsdf);
    block_compare("textured emitter", "MIS vs quadrature", &mis, &want, Z_CRIT);
    block_compare("textured emitter", "light sampling vs quadrature", &lights, &want, Z_CRIT);
    block_compare("textured emitter", "BSDF sampling vs quadrature", &bsdf, &want, Z_CRIT);
    printf("textured emitter: summed block variances: MIS %.3g, lights %.3g (64 spp), BSDF %.3g (256 spp)\n",
           summed_var(&mis), summed_var(&lights), summed_var(&bsdf));
}

/* For points on the floor and random numbers: the light a sample chose and
 * its pdf (choice x solid angle) against what a BSDF-sampled ray that hits
 * the same point computes (path_emission_weight: light_pmf x light_pdf_li). */
static void check_pdf_agreement(pk_scene *s)
{
    env_light env;
    memset(&env, 0, sizeof env);
    light_set ls;
    REQUIRE(light_set_build(ctx, s, &env, &ls) == PK_OK);
    REQUIRE(ls.n == 2 * EN * EN && ls.tree);
    const scene_view v = scene_view_of(s);
    /* the bright corner's triangles get the most: texels x, y >= 5 are u >= 5/8, v <= 3/8 */
    double bright = 0.0;
    for (size_t k = 0; k < ls.n; k++) {
        vec3 c = v3_scale(v3_add(ls.lights[k].v[0], v3_add(ls.lights[k].v[1], ls.lights[k].v[2])), 1.0f / 3.0f);
        if (c.x + 0.5f > 5.0f / 8 && c.z + 0.5f < 3.0f / 8) bright += (double)ls.pmf[k];
    }
    /* the corner's share of the emission as lookups see it (bilinear: some
     * of the corner's light spreads half a texel over its edges), by the
     * midpoint rule; the image's mean would give the corner 9/64 of the
     * choices, the texels as squares 360 / 362.75 */
    const img t = {EW, EW, etex};
    double in = 0.0, all = 0.0;
    for (int j = 0; j < 4 * Q; j++)
        for (int i = 0; i < 4 * Q; i++) {
            const double u = (i + 0.5) / (4 * Q), vv = (j + 0.5) / (4 * Q), e = bilinear(&t, u, vv);
            all += e, in += (u > 5.0 / 8 && vv < 3.0 / 8) ? e : 0.0;
        }
    printf("textured emitter: the bright corner's share of the light choices %.5f (of the emission %.5f)\n", bright,
           in / all);
    /* triangles at the finest level count the filter by a 2 x 2 point rule,
     * exact for triangles that tile whole texels (each point is the middle
     * of a piece on which the moved integral is linear): float rounding */
    CHECK_NEAR(bright, in / all, 1e-4);
    unsigned seed = 11;
    int n = 0, bad_pmf = 0, bad_pdf = 0;
    double worst = 0.0;
    for (int tree = 0; tree < 2; tree++) {
        ls.use_tree = tree;
        for (int i = 0; i < 4000; i++) {
            const vec3 p = v3((float)(1.6 * rnd(&seed) - 0.8), 0.0f, (float)(1.6 * rnd(&seed) - 0.8)), nrm = v3(0, 1, 0);
            light_ctx lc;
            memset(&lc, 0, sizeof lc);
            lc.p = p, lc.o = v3_add(p, v3(0, 1e-4f, 0)), lc.n = nrm;
            size_t li;
            float psel;
            if (!light_pick(&ls, &v, p, nrm, (float)rnd(&seed), &li, &psel)) continue;
            light_sample smp;
            if (!light_sample_one(&ls, &v, &env, li, &lc, (float)rnd(&seed), (float)rnd(&seed), &smp)) continue;
            const light *l = &ls.lights[li];
            const vec3 q = v3_add(smp.shadow.o, smp.shadow.d);
            n++;
            /* the hit finds the light through its triangle */
            const float pm = light_pmf(&ls, &v, p, nrm, (size_t)ls.of_prim[l->index]);
            bad_pmf += !(pm == psel);
            const float pl = pm * light_pdf_li(&v, l, p, nrm, q, l->normal);
            const double want = (double)psel * (double)smp.pdf, rel = fabs((double)pl - want) / want;
            worst = fmax(worst, rel);
            bad_pdf += !(rel <= 1e-4);
        }
    }
    printf("textured emitter: %d light samples: choice pmf equal in %d, largest relative pdf difference %.3g\n", n,
           n - bad_pmf, worst);
    CHECK(n > 4000);
    CHECKF(bad_pmf == 0, "%d samples whose choice pmf differs from the hit's", bad_pmf);
    CHECKF(bad_pdf == 0, "%d samples whose pdf differs from the hit's by more than 1e-4", bad_pdf);
    light_set_free(&ctx->alloc, &ls);
}

/* ---- the readers ------------------------------------------------------------ */

/* The scene (format, text) has emitting triangles, all of a material whose
 * emission map is the image e.pfm, and no warnings. */
static void check_reader(const char *format, const char *text)
{
    warning_log_clear(&wl);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_memory(ctx, format, text, strlen(text), NULL, dir, &s);
    CHECKF(st == PK_OK, "%s: %s", format, pk_context_error(ctx));
    if (st != PK_OK) return;
    REQUIRE(pk_scene_commit(ctx, s) == PK_OK);
    CHECKF(s->nemissive > 0, "%s: no emitting triangles", format);
    for (size_t i = 0; i < s->nemissive; i++) {
        const material *m = &s->materials[s->tris[s->emissive[i]].material];
        const bool ok = m->map_ke.kind == TEX_IMAGE && m->map_ke.tex >= 0 && strstr(s->textures[m->map_ke.tex].key, "e.pfm");
        CHECKF(ok, "%s: emitting triangle %zu has no emission map from e.pfm", format, i);
        if (!ok) break;
    }
    CHECKF(wl.count == 0, "%s: %d warnings, the last: %s", format, wl.count, wl.last);
    pk_scene_destroy(s);
}

static void check_readers(void)
{
    check_reader("obj", "mtllib e.mtl\nusemtl lamp\nv 0 1 0\nv 1 1 0\nv 0 1 1\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    check_reader("json", "{\"camera\": {\"look_from\": [0, 0, 3], \"look_at\": [0, 0, 0]},"
                         " \"materials\": [{\"name\": \"lamp\", \"type\": \"emitter\", \"radiance\": {\"texture\": \"e.pfm\"}}],"
                         " \"meshes\": [{\"obj\": \"e.obj\"}]}");
    check_reader("pbrt", "Camera \"perspective\"\nWorldBegin\nAttributeBegin\n"
                         "AreaLightSource \"diffuse\" \"string filename\" \"e.pfm\"\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"point2 uv\" [0 0 1 0 0 1]"
                         " \"integer indices\" [0 1 2]\nAttributeEnd\n");
    check_reader("xml", "<scene version=\"3.0.0\"><shape type=\"rectangle\"><emitter type=\"area\">"
                        "<texture type=\"bitmap\" name=\"radiance\"><string name=\"filename\" value=\"e.pfm\"/></texture>"
                        "</emitter></shape></scene>");
}

/* ---- the cost on a big case ------------------------------------------------ */

static void bench(void)
{
    enum { TW = 4096, G = 224 }; /* 2 x 224^2 = 100352 triangles */
    float *px = malloc(sizeof(float) * TW * TW);
    REQUIRE(px);
    for (int y = 0; y < TW; y++)
        for (int x = 0; x < TW; x++) px[y * TW + x] = (float)((x ^ y) & 255) / 255.0f;
    char path[128];
    snprintf(path, sizeof path, "%s/big.pfm", dir);
    write_pfm(path, TW, TW, px);
    free(px);
    snprintf(path, sizeof path, "%s/big.obj", dir);
    FILE *fp = fopen(path, "w");
    REQUIRE(fp);
    fprintf(fp, "mtllib big.mtl\nusemtl lamp\n");
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++) fprintf(fp, "v %d 1 %d\nvt %.9g %.9g\n", i, j, (double)i / G, (double)j / G);
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            const int a = j * (G + 1) + i + 1, b = a + 1, c = a + G + 1, d = c + 1;
            fprintf(fp, "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", a, a, b, b, c, c, b, b, d, d, c, c);
        }
    fclose(fp);
    put_file("big.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nmap_Ke big.pfm\n");
    pk_scene *s = load_json("{\"camera\": {\"look_from\": [0, 5, 0], \"look_at\": [0, 0, 0], \"up\": [0, 0, 1]},"
                            " \"meshes\": [{\"obj\": \"big.obj\"}]}");
    REQUIRE(s);
    env_light env;
    memset(&env, 0, sizeof env);
    light_set ls;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    REQUIRE(light_set_build(ctx, s, &env, &ls) == PK_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("bench: light set of %zu emitting triangles on a %d x %d texture: %.3f s\n", ls.n, TW, TW,
           (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    light_set_free(&ctx->alloc, &ls);
    /* the same without the map: what the rest of the set (the tree) costs */
    for (size_t i = 0; i < s->nmaterials; i++) s->materials[i].map_ke.kind = TEX_NONE;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    REQUIRE(light_set_build(ctx, s, &env, &ls) == PK_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("bench: the same without the emission map: %.3f s\n",
           (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    light_set_free(&ctx->alloc, &ls);
    pk_scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wl);
    wl.echo = true;
    snprintf(dir, sizeof dir, "/tmp/pk_emitXXXXXX");
    REQUIRE(mkdtemp(dir));
    check_powers();
    pk_scene *s = emitter_scene();
    REQUIRE(s);
    check_pdf_agreement(s);
    check_readers();
    check_irradiance(s);
    pk_scene_destroy(s);
    if (getenv("PK_EMIT_BENCH")) bench();
    pk_context_destroy(ctx);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return test_done("test_textured_emission");
}

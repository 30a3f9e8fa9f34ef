/*
 * test_light_tree.c - choosing lights through the light tree
 * (render/light_tree.h, light_pick and light_pmf in render/lights.h).
 *
 * - On a scene of many lights of every kind with a place (one- and
 *   two-sided triangles facing every way, spheres, point and spot lights)
 *   and some without (a constant environment, a distant light): at random
 *   receivers, with and without a normal, the probabilities light_pmf gives
 *   sum to one (or to what the lights without a place take, where no light
 *   of the tree can reach the receiver); the probability light_pick returns
 *   with a light is light_pmf's for it, bit for bit (MIS needs both to be
 *   the same function); and the lights picked fall as often as light_pmf
 *   says (chi-square).
 * - A lit floor under many small lamps rendered choosing lights by power
 *   and through the tree: the same mean within Z standard errors measured
 *   from two seeds each (both are unbiased), and the tree's variance lower
 *   (printed).
 */
#include "test.h"

#include "chi2.h"
#include "paprsek.h"
#include "render/env.h"
#include "render/lights.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define Z 5.0
#define P_MIN 1e-4

static pk_context *ctx;
static char tmpdir[64];

static double frand(uint64_t *st)
{
    *st = *st * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*st >> 11) * 0x1p-53;
}

/* An OBJ file of n small triangles at random places and orientations,
 * alternately of materials "one" and "two". */
static void write_lamps(const char *path, int n, uint64_t seed, double spread, double size)
{
    FILE *f = fopen(path, "w");
    REQUIRE(f != NULL);
    uint64_t st = seed;
    for (int i = 0; i < n; i++) {
        double c[3], a[3], b[3];
        for (int k = 0; k < 3; k++) c[k] = (frand(&st) - 0.5) * spread;
        for (int k = 0; k < 3; k++) a[k] = (frand(&st) - 0.5) * size, b[k] = (frand(&st) - 0.5) * size;
        fprintf(f, "v %.6f %.6f %.6f\nv %.6f %.6f %.6f\nv %.6f %.6f %.6f\n", c[0], c[1], c[2], c[0] + a[0],
                c[1] + a[1], c[2] + a[2], c[0] + b[0], c[1] + b[1], c[2] + b[2]);
        fprintf(f, "usemtl %s\nf %d %d %d\n", i % 2 ? "two" : "one", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    fclose(f);
}

/* Pearson's chi-square p-value of observed counts against expected ones,
 * cells expected below min_expect pooled into one. */
static double chi2_test_pooled(const double *obs, const double *expect, size_t n, double min_expect)
{
    double chi = 0.0, po = 0.0, pe = 0.0;
    int dof = -1;
    for (size_t i = 0; i < n; i++) {
        if (expect[i] < min_expect) {
            po += obs[i], pe += expect[i];
            continue;
        }
        chi += (obs[i] - expect[i]) * (obs[i] - expect[i]) / expect[i];
        dof++;
    }
    if (pe >= min_expect) chi += (po - pe) * (po - pe) / pe, dof++;
    else if (po > 0.0 && pe <= 0.0) return 0.0; /* drawn where it cannot be */
    return dof > 0 ? chi2_pvalue(chi, dof) : 1.0;
}

static pk_scene *load(const char *text)
{
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "lights.json", tmpdir, &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return s;
}

static void check_choices(void)
{
    char obj[128], text[8192];
    snprintf(obj, sizeof obj, "%s/lamps.obj", tmpdir);
    write_lamps(obj, 120, 7, 8.0, 0.6);
    int len = snprintf(text, sizeof text,
                       "{\"materials\": {\"one\": {\"type\": \"emitter\", \"radiance\": [3, 2, 1]},"
                       " \"two\": {\"type\": \"emitter\", \"radiance\": [1, 1, 4], \"two_sided\": true},"
                       " \"bulb\": {\"type\": \"emitter\", \"radiance\": [5, 5, 5]}},"
                       " \"meshes\": [{\"obj\": \"lamps.obj\"}], \"spheres\": [");
    uint64_t st = 99;
    for (int i = 0; i < 12; i++)
        len += snprintf(text + len, sizeof text - (size_t)len,
                        "%s{\"center\": [%.3f, %.3f, %.3f], \"radius\": %.3f, \"material\": \"bulb\"}", i ? "," : "",
                        (frand(&st) - 0.5) * 8, (frand(&st) - 0.5) * 8, (frand(&st) - 0.5) * 8, 0.05 + 0.2 * frand(&st));
    len += snprintf(text + len, sizeof text - (size_t)len, "], \"lights\": [");
    for (int i = 0; i < 10; i++) {
        const double px = (frand(&st) - 0.5) * 8, py = (frand(&st) - 0.5) * 8, pz = (frand(&st) - 0.5) * 8;
        if (i % 2)
            len += snprintf(text + len, sizeof text - (size_t)len,
                            "%s{\"type\": \"spot\", \"position\": [%.3f, %.3f, %.3f], \"direction\": [%.3f, %.3f, %.3f],"
                            " \"outer_angle\": %.1f, \"intensity\": %.2f}",
                            i ? "," : "", px, py, pz, frand(&st) - 0.5, frand(&st) - 0.5, frand(&st) - 0.5,
                            10 + 60 * frand(&st), 1 + 5 * frand(&st));
        else
            len += snprintf(text + len, sizeof text - (size_t)len,
                            "%s{\"position\": [%.3f, %.3f, %.3f], \"intensity\": %.2f}", i ? "," : "", px, py, pz,
                            1 + 5 * frand(&st));
    }
    snprintf(text + len, sizeof text - (size_t)len,
             ", {\"type\": \"distant\", \"direction\": [0.2, -1, 0.1], \"intensity\": 0.5}],"
             " \"environment\": [0.05, 0.06, 0.08]}");
    pk_scene *s = load(text);

    env_light env;
    REQUIRE(env_build(ctx, &s->env, s->env.map_rgb, s->env.map_w, s->env.map_h, s->bounds, &env) == PK_OK);
    light_set ls;
    REQUIRE(light_set_build(ctx, s, &env, &ls) == PK_OK);
    const scene_view v = scene_view_of(s);
    CHECKF(ls.tree != NULL && ls.ntree == 2 * (120 + 12 + 10) - 1, "tree of %zu nodes", ls.ntree);
    CHECKF(ls.ninf == 2, "%zu lights without a place", ls.ninf);
    ls.use_tree = 1;

    uint64_t rs = 12345;
    int receivers = 0, unreachable = 0;
    double worst_p = 1.0, min_sum = 1.0;
    for (int r = 0; r < 60; r++) {
        const vec3 p = v3((float)((frand(&rs) - 0.5) * 10), (float)((frand(&rs) - 0.5) * 10), (float)((frand(&rs) - 0.5) * 10));
        vec3 n = v3s(0.0f);
        if (r % 3) {
            n = v3((float)(frand(&rs) - 0.5), (float)(frand(&rs) - 0.5), (float)(frand(&rs) - 0.5));
            n = v3_norm(n);
        }
        double sum = 0.0, sum_inf = 0.0;
        double *pmf = malloc(ls.n * sizeof *pmf);
        REQUIRE(pmf != NULL);
        for (size_t i = 0; i < ls.n; i++) {
            pmf[i] = light_pmf(&ls, &v, p, n, i);
            CHECK(pmf[i] >= 0.0 && isfinite(pmf[i]));
            sum += pmf[i];
            if (!light_has_place(&ls, &v, i)) sum_inf += pmf[i];
        }
        /* a walk may also end where neither child can reach the receiver
         * (the children's bounds are tighter than their parent's): what is
         * missing from 1 is the chance of that, checked below */
        const bool reach = fabs(sum - sum_inf) > 0.0;
        unreachable += !reach;
        CHECKF(sum <= 1.0 + 2e-5 && sum > 0.0, "receiver %d: probabilities sum to %.8f", r, sum);
        if (sum < min_sum) min_sum = sum;
        /* picks: the pmf returned is light_pmf's; frequencies follow it */
        enum { N = 60000 };
        double *count = calloc(ls.n, sizeof *count);
        REQUIRE(count != NULL);
        int fails = 0, mismatch = 0;
        for (int k = 0; k < N; k++) {
            const float u = (float)frand(&rs);
            size_t li;
            float pr;
            if (!light_pick(&ls, &v, p, n, u, &li, &pr)) {
                fails++;
                continue;
            }
            count[li] += 1.0;
            if (pr != (float)pmf[li]) mismatch++;
        }
        CHECKF(mismatch == 0, "receiver %d: %d picks returned another probability than light_pmf", r, mismatch);
        const double q = fmax(1.0 - sum, 0.0);
        CHECKF(fabs((double)fails / N - q) < Z * sqrt(q * (1.0 - q) / N) + 1e-4,
               "receiver %d: %d of %d picks failed, expected %.4f", r, fails, N, 1.0 - sum);
        double *expect = malloc(ls.n * sizeof *expect);
        REQUIRE(expect != NULL);
        for (size_t i = 0; i < ls.n; i++) expect[i] = pmf[i] * N;
        const double pv = chi2_test_pooled(count, expect, ls.n, 5.0);
        if (pv < worst_p) worst_p = pv;
        CHECKF(pv > P_MIN, "receiver %d: chi-square p = %g", r, pv);
        free(expect);
        free(count);
        free(pmf);
        receivers++;
    }
    printf("  %d receivers (%d out of every tree light's reach), smallest chi-square p %.3g, smallest sum %.4f\n",
           receivers, unreachable, worst_p, min_sum);
    light_set_free(&ctx->alloc, &ls);
    env_free(&ctx->alloc, &env);
    pk_scene_destroy(s);
}

/* ---- renders: power against the tree ------------------------------------------ */

#define SIZE 32

static double lum(const float *p) { return 0.2126 * (double)p[0] + 0.7152 * (double)p[1] + 0.0722 * (double)p[2]; }

static pk_image *render(const pk_scene *s, int tree, int seed)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = SIZE;
    o.spp = 16;
    o.seed = seed;
    o.threads = 2;
    o.max_depth = 2;
    o.light_tree = tree;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    return img;
}

static void stats(const pk_image *a, const pk_image *b, double *mean, double *var)
{
    const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b);
    double m = 0.0, vv = 0.0;
    for (int i = 0; i < SIZE * SIZE; i++) {
        const double x = lum(pa + 3 * i), y = lum(pb + 3 * i);
        m += (x + y) / 2.0;
        vv += (x - y) * (x - y) / 2.0;
    }
    *mean = m / (SIZE * SIZE);
    *var = vv / (SIZE * SIZE);
}

static void check_renders(void)
{
    char obj[128], text[2048];
    snprintf(obj, sizeof obj, "%s/ceiling.obj", tmpdir);
    /* 200 small lamps facing down over a floor */
    FILE *f = fopen(obj, "w");
    REQUIRE(f != NULL);
    uint64_t st = 3;
    for (int i = 0; i < 200; i++) {
        const double x = (frand(&st) - 0.5) * 20, z = (frand(&st) - 0.5) * 20, y = 1.0 + 2.0 * frand(&st);
        fprintf(f, "v %.4f %.4f %.4f\nv %.4f %.4f %.4f\nv %.4f %.4f %.4f\nusemtl lamp\nf %d %d %d\n", x, y, z, x + 0.1,
                y, z, x, y, z + 0.1, 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    fclose(f);
    snprintf(text, sizeof text,
             "{\"materials\": {\"lamp\": {\"type\": \"emitter\", \"radiance\": [20, 20, 20]},"
             " \"floor\": {\"kd\": [0.5, 0.5, 0.5]}},"
             " \"camera\": {\"look_from\": [0, 8, 8], \"look_at\": [0, 0, 0], \"fov\": 60},"
             " \"meshes\": [{\"obj\": \"ceiling.obj\"}],"
             " \"spheres\": [{\"center\": [0, -1000, 0], \"radius\": 1000, \"material\": \"floor\"}],"
             " \"environment\": \"none\"}");
    pk_scene *s = load(text);
    pk_image *p0 = render(s, 0, 1), *p1 = render(s, 0, 2), *t0 = render(s, 1, 1), *t1 = render(s, 1, 2);
    double mp, vp, mt, vt;
    stats(p0, p1, &mp, &vp);
    stats(t0, t1, &mt, &vt);
    /* each mean is of 2 SIZE^2 pixel values of variance v (pixels independent) */
    const double se = sqrt(vp / (2.0 * SIZE * SIZE) + vt / (2.0 * SIZE * SIZE));
    CHECKF(fabs(mp - mt) < Z * se, "means differ: power %.6f, tree %.6f (se %.2g)", mp, mt, se);
    CHECKF(vt < vp, "the tree's variance %.4g is not below power's %.4g", vt, vp);
    printf("  200 lamps, 16 spp: mean power %.5f tree %.5f (se %.2g); pixel variance power %.4g tree %.4g (%.2fx)\n", mp,
           mt, se, vp, vt, vp / vt);
    pk_image_destroy(p0), pk_image_destroy(p1), pk_image_destroy(t0), pk_image_destroy(t1);
    pk_scene_destroy(s);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/pk_light_tree_XXXXXX");
    REQUIRE(mkdtemp(tmpdir) != NULL);
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_choices();
    check_renders();
    pk_context_destroy(ctx);
    char path[128];
    snprintf(path, sizeof path, "%s/lamps.obj", tmpdir), unlink(path);
    snprintf(path, sizeof path, "%s/ceiling.obj", tmpdir), unlink(path);
    rmdir(tmpdir);
    return test_done("test_light_tree");
}

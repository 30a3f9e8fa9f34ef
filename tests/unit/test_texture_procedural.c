/*
 * test_texture_procedural.c - pbrt-v4's procedural textures: Perlin noise
 * (zero at lattice points, its bound, its mean, continuity across cells,
 * period 256), fbm and turbulence as their octave sums, windy and marble
 * against their formulas over our noise, checkerboards on either side of
 * an edge in every mapping, the mappings' (s, t) against their formulas,
 * bilerp's corners and centre, dots inside and outside, scale, mix and
 * directionmix; the pbrt reader's default uvs (triangles, bilinear
 * patches, twisted patches as grids); and pbrt files using every texture
 * (and the user's guide scene) loading without a warning and rendering.
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"
#include "io/readers.h"
#include "scene/scene.h"
#include "scene/texture.h"

#include <stdlib.h>
#include <string.h>

static pk_context *ctx;

/* A reproducible uniform number in [0, 1). */
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double rnd(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

static tex_node node(tex_op op)
{
    tex_node d;
    memset(&d, 0, sizeof d);
    d.op = (uint8_t)op;
    d.a = d.b = d.c = -1;
    d.su = d.sv = 1.0f;
    d.k[0] = v3s(1.0f);
    /* texture space = world */
    d.xf[0] = d.xf[5] = d.xf[10] = 1.0f;
    return d;
}

static tex_node cnode(vec3 c)
{
    tex_node d = node(TN_CONST);
    d.k[0] = c;
    return d;
}

/* The value of the n nodes at (u, v), point p and normal nrm. */
static vec3 eval(const tex_node *nodes, int n, float u, float v, vec3 p, vec3 nrm)
{
    tex_ref r;
    tex_ref_init(&r);
    r.kind = TEX_EXPR, r.node = 0, r.nnodes = n;
    tex_query q = {u, v, 0.0f, p, nrm, nodes, u, v, 0.0f};
    return tex_expr_eval(NULL, &r, q);
}

static vec3 eval_p(const tex_node *nodes, int n, vec3 p) { return eval(nodes, n, 0.0f, 0.0f, p, v3(0, 0, 1)); }

/* ---- noise -------------------------------------------------------------------------- */

static void test_noise(void)
{
    /* zero at every lattice point (the gradients' dot products with 0) */
    for (int i = 0; i < 2000; i++) {
        const float x = (float)((int)(rnd() * 2000) - 1000), y = (float)((int)(rnd() * 2000) - 1000),
                    z = (float)((int)(rnd() * 2000) - 1000);
        CHECKF(tex_noise(x, y, z) == 0.0f, "noise(%g %g %g) = %g", (double)x, (double)y, (double)z,
               (double)tex_noise(x, y, z));
    }
    /* the bound: a blend (weights summing to 1) of terms |g . d| <= 2;
     * the mean: 0 (the gradients come in opposite pairs), within 5 standard
     * errors of the measured spread; period 256 in each axis */
    const int n = 200000;
    double sum = 0.0, sum2 = 0.0, mx = 0.0;
    bool bounded = true, periodic = true;
    for (int i = 0; i < n; i++) {
        /* multiples of 1/64: x - 256 and z + 512 are exact */
        const float x = floorf((float)(rnd() * 16384.0)) / 64.0f, y = (float)(rnd() * 256.0),
                    z = floorf((float)(rnd() * 16384.0)) / 64.0f;
        const double v = tex_noise(x, y, z);
        bounded = bounded && fabs(v) <= 2.0;
        if (fabs(v) > mx) mx = fabs(v);
        sum += v, sum2 += v * v;
        if (i < 1000) periodic = periodic && tex_noise(x - 256.0f, y, z + 512.0f) == tex_noise(x, y, z);
    }
    const double mean = sum / n, sd = sqrt(sum2 / n - mean * mean);
    CHECK(bounded);
    CHECK(periodic);
    CHECKF(mx > 0.5 && mx <= 1.1, "max |noise| %g", mx); /* improved noise reaches about 1 */
    CHECKF(fabs(mean) < 5.0 * sd / sqrt((double)n), "mean %g (sd %g)", mean, sd);
    CHECKF(sd > 0.1, "sd %g", sd);
    /* continuity: the gradient is bounded (fade' <= 1.875 times the spread
     * of terms, 4, plus |g| <= 2 per axis: under 9.5 * sqrt 3 along any unit
     * direction), including across cell faces */
    double lip = 0.0;
    for (int i = 0; i < 20000; i++) {
        vec3 p = v3((float)(rnd() * 64.0), (float)(rnd() * 64.0), (float)(rnd() * 64.0));
        if (i % 2) p.x = floorf(p.x) - 5e-4f; /* straddle a face */
        const float h = 1e-3f;
        vec3 d = v3_norm(v3((float)rnd() - 0.5f, (float)rnd() - 0.5f, (float)rnd() - 0.5f));
        if (i % 2) d = v3(1, 0, 0);
        const double dv =
            fabs((double)tex_noise(p.x + h * d.x, p.y + h * d.y, p.z + h * d.z) - (double)tex_noise(p.x, p.y, p.z));
        if (dv / (double)h > lip) lip = dv / (double)h;
    }
    CHECKF(lip < 9.5 * sqrt(3.0), "largest slope %g", lip);
    CHECK(tex_noise(NAN, 0.0f, 0.0f) == 0.0f && tex_noise(0.5f, INFINITY, 0.0f) == 0.0f);
}

static void test_fbm_family(void)
{
    for (int i = 0; i < 200; i++) {
        const vec3 p = v3((float)(rnd() * 20.0 - 10.0), (float)(rnd() * 20.0 - 10.0), (float)(rnd() * 20.0 - 10.0));
        const float omega = (float)(0.3 + 0.5 * rnd());
        const int oct = 1 + (int)(rnd() * 8);
        /* the octave sums, written out */
        double f = 0.0, t = 0.0;
        float o = 1.0f, lambda = 1.0f;
        for (int k = 0; k < oct; k++) {
            const double nz = (double)tex_noise(lambda * p.x, lambda * p.y, lambda * p.z);
            f += (double)o * nz, t += (double)o * fabs(nz);
            lambda *= 1.99f, o *= omega;
        }
        t += 0.2 * (double)o;
        CHECK_NEAR(tex_fbm(p, omega, oct), f, 1e-5);
        CHECK_NEAR(tex_turbulence(p, omega, oct), t, 1e-5);
        CHECK(tex_fbm(p, omega, 1) == tex_noise(p.x, p.y, p.z));

        tex_node d = node(TN_FBM);
        d.omega = omega, d.octaves = oct;
        CHECK_NEAR(eval_p(&d, 1, p).x, f, 1e-5);
        d.op = TN_WRINKLED;
        CHECK_NEAR(eval_p(&d, 1, p).y, t, 1e-5);
        /* windy: |fbm(p / 10, 1/2, 3)| fbm(p, 1/2, 6) */
        d.op = TN_WINDY;
        const double w = fabs((double)tex_fbm(v3_scale(p, 0.1f), 0.5f, 3)) * (double)tex_fbm(p, 0.5f, 6);
        CHECK_NEAR(eval_p(&d, 1, p).z, w, 1e-5);
        /* marble: the spline at 1/2 + sin(scale y + variation fbm(scale p)) / 2 */
        d.op = TN_MARBLE;
        d.scale = 1.7f, d.variation = 0.4f;
        const vec3 ps = v3_scale(p, d.scale);
        const vec3 m = tex_marble_colour(0.5f + 0.5f * sinf(ps.y + d.variation * tex_fbm(ps, omega, oct)));
        const vec3 got = eval_p(&d, 1, p);
        CHECK_NEAR(got.x, m.x, 1e-5);
        CHECK_NEAR(got.z, m.z, 1e-5);
    }
    /* the marble spline passes through its control points at segment ends
     * (1.5 times the colour): t = 0, 1/2 (grey 0.5) and 1 */
    CHECK_NEAR(tex_marble_colour(0.0f).x, 1.5 * 0.58, 1e-6);
    CHECK_NEAR(tex_marble_colour(0.0f).z, 1.5 * 0.6, 1e-6);
    CHECK_NEAR(tex_marble_colour(0.5f).y, 1.5 * 0.5, 1e-6);
    CHECK_NEAR(tex_marble_colour(1.0f).z, 1.5 * 0.6, 1e-6);
    /* between them, a cubic Bezier: at the middle of the segment from the
     * blue-grey (index 7) ... (t in [5/6, 1]): (c6 + 3 c7 + 3 c8 + c9)/8 does
     * not apply (9 points, 6 segments of c[i..i+3]); segment 5 at 1/2 is
     * (c5 + 3 c6 + 3 c7 + c8) / 8 */
    const double mid = (0.6 + 3 * 0.6 + 3 * 0.33 + 0.6) / 8.0 * 1.5;
    CHECK_NEAR(tex_marble_colour((5.0f + 0.5f) / 6.0f).z, mid, 1e-5);
}

/* ---- mappings and 2D textures ----------------------------------------------------- */

/* A bilerp node whose value is (s, t, 0): the mapping's coordinates. */
static tex_node st_probe(tex_mapping map)
{
    tex_node d = node(TN_BILERP);
    d.map = (uint8_t)map;
    d.k[0] = v3(0, 0, 0), d.k[1] = v3(0, 1, 0), d.k[2] = v3(1, 0, 0), d.k[3] = v3(1, 1, 0);
    return d;
}

static void test_mappings(void)
{
    const float pi = (float)PK_PI;
    /* uv: (su u + du, sv v + dv) */
    tex_node d = st_probe(TMAP_UV);
    d.su = 3.0f, d.sv = -2.0f, d.du = 0.25f, d.dv = 0.5f;
    vec3 st = eval(&d, 1, 0.1f, 0.2f, v3s(0.0f), v3(0, 0, 1));
    CHECK_NEAR(st.x, 0.55, 1e-6);
    CHECK_NEAR(st.y, 0.1, 1e-6);
    /* spherical: (theta / pi, phi / 2 pi) of the texture-space point, here
     * translated by (1, 0, 0) (xf = the inverse of the texture's transform) */
    d = st_probe(TMAP_SPHERICAL);
    d.xf[3] = -1.0f;
    const vec3 p = v3(1.0f + 0.3f, -0.4f, 0.5f);
    const double r = sqrt(0.09 + 0.16 + 0.25), th = acos(0.5 / r), ph = atan2(-0.4, 0.3) + 2.0 * (double)PK_PI;
    st = eval_p(&d, 1, p);
    CHECK_NEAR(st.x, th / (double)PK_PI, 1e-5);
    CHECK_NEAR(st.y, ph / (2.0 * (double)PK_PI), 1e-5);
    /* cylindrical: ((pi + atan2(y, x)) / 2 pi, z) */
    d = st_probe(TMAP_CYLINDRICAL);
    st = eval_p(&d, 1, v3(-0.2f, 0.7f, 0.35f));
    CHECK_NEAR(st.x, ((double)PK_PI + atan2(0.7, -0.2)) / (2.0 * (double)PK_PI), 1e-5);
    CHECK_NEAR(st.y, 0.35, 1e-6);
    /* planar: (du + p . v1, dv + p . v2) */
    d = st_probe(TMAP_PLANAR);
    d.v1 = v3(0.5f, 0, 0.5f), d.v2 = v3(0, 1, 0), d.du = 0.1f, d.dv = -0.2f;
    st = eval_p(&d, 1, v3(0.4f, 0.3f, 0.2f));
    CHECK_NEAR(st.x, 0.1 + 0.2 + 0.1, 1e-6);
    CHECK_NEAR(st.y, -0.2 + 0.3, 1e-6);
    (void)pi;

    /* bilerp: its corners and centre */
    tex_node b = node(TN_BILERP);
    b.k[0] = v3(1, 0, 0), b.k[1] = v3(0, 1, 0), b.k[2] = v3(0, 0, 1), b.k[3] = v3(1, 1, 1);
    const float cu[5] = {0, 0, 1, 1, 0.5f}, cv[5] = {0, 1, 0, 1, 0.5f};
    const vec3 want[5] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1), v3(1, 1, 1), v3(0.5f, 0.5f, 0.5f)};
    for (int i = 0; i < 5; i++) {
        const vec3 got = eval(&b, 1, cu[i], cv[i], v3s(0.0f), v3(0, 0, 1));
        CHECK_NEAR(got.x, want[i].x, 1e-6);
        CHECK_NEAR(got.y, want[i].y, 1e-6);
        CHECK_NEAR(got.z, want[i].z, 1e-6);
    }
}

/* tex1 on one side of an edge, tex2 on the other, for each mapping. */
static void test_checkerboard(void)
{
    tex_node n[3];
    n[0] = cnode(v3(1, 0, 0)), n[1] = cnode(v3(0, 0, 1)), n[2] = node(TN_CHECKER);
    n[2].a = 0, n[2].b = 1;
    const float e = 1e-3f;
    /* uv: s = 2 u + 0.25 crosses 1 at u = 0.375 */
    n[2].map = TMAP_UV, n[2].su = 2.0f, n[2].du = 0.25f;
    CHECK(eval(n, 3, 0.375f - e, 0.5f, v3s(0), v3(0, 0, 1)).x == 1.0f);
    CHECK(eval(n, 3, 0.375f + e, 0.5f, v3s(0), v3(0, 0, 1)).z == 1.0f);
    CHECK(eval(n, 3, 0.375f + e, -0.5f, v3s(0), v3(0, 0, 1)).x == 1.0f); /* both odd: even */
    /* planar: s = x + 0.5 crosses 1 at x = 0.5 */
    n[2] = node(TN_CHECKER), n[2].a = 0, n[2].b = 1, n[2].map = TMAP_PLANAR;
    n[2].v1 = v3(1, 0, 0), n[2].v2 = v3(0, 1, 0), n[2].du = 0.5f;
    CHECK(eval_p(n, 3, v3(0.5f - e, 0.2f, 7.0f)).x == 1.0f);
    CHECK(eval_p(n, 3, v3(0.5f + e, 0.2f, 7.0f)).z == 1.0f);
    /* cylindrical: t = z crosses 1 */
    n[2].map = TMAP_CYLINDRICAL;
    CHECK(eval_p(n, 3, v3(1.0f, 0.1f, 1.0f - e)).x == 1.0f);
    CHECK(eval_p(n, 3, v3(1.0f, 0.1f, 1.0f + e)).z == 1.0f);
    /* spherical: s = theta / pi reaches 1 only at the south pole; t never */
    n[2].map = TMAP_SPHERICAL;
    CHECK(eval_p(n, 3, v3(0.3f, -0.2f, -0.9f)).x == 1.0f);
    /* 3D: floor x + floor y + floor z; in texture space scaled by 4 (the
     * texture's transform a scale of 1/4) the edge at x = 1/4 */
    n[2].map = TMAP_3D;
    memset(n[2].xf, 0, sizeof n[2].xf);
    n[2].xf[0] = n[2].xf[5] = n[2].xf[10] = 4.0f;
    CHECK(eval_p(n, 3, v3(0.25f - e, 0.1f, 0.1f)).x == 1.0f);
    CHECK(eval_p(n, 3, v3(0.25f + e, 0.1f, 0.1f)).z == 1.0f);
    CHECK(eval_p(n, 3, v3(0.25f + e, 0.3f, 0.1f)).x == 1.0f);
    CHECK(eval_p(n, 3, v3(0.25f + e, 0.3f, -0.1f)).z == 1.0f);
    /* operands that are textures themselves: tex1 a bilerp */
    tex_node m[3];
    m[0] = st_probe(TMAP_UV), m[1] = cnode(v3s(0.5f)), m[2] = node(TN_CHECKER);
    m[2].a = 0, m[2].b = 1;
    const vec3 v = eval(m, 3, 0.25f, 0.75f, v3s(0), v3(0, 0, 1));
    CHECK_NEAR(v.x, 0.25, 1e-6);
    CHECK_NEAR(v.y, 0.75, 1e-6);
}

static void test_dots(void)
{
    tex_node n[3];
    n[0] = cnode(v3(1, 1, 1)), n[1] = cnode(v3(0, 0, 0)), n[2] = node(TN_DOTS);
    n[2].a = 0, n[2].b = 1;
    int with = 0, without = 0;
    for (int sc = -20; sc < 20; sc++)
        for (int tc = -20; tc < 20; tc++) {
            const bool dot = tex_noise((float)sc + 0.5f, (float)tc + 0.5f, 0.5f) > 0.0f;
            const float cs = (float)sc + 0.15f * tex_noise((float)sc + 1.5f, (float)tc + 2.8f, 0.5f);
            const float ct = (float)tc + 0.15f * tex_noise((float)sc + 4.5f, (float)tc + 9.8f, 0.5f);
            /* the dot's centre, and a point 0.355 from it toward the cell's
             * centre (outside the dot of radius 0.35, still in the cell) */
            const vec3 in = eval(n, 3, cs, ct, v3s(0), v3(0, 0, 1));
            const float ox = cs, oy = ct + (ct > (float)tc ? -0.355f : 0.355f);
            const vec3 out = eval(n, 3, ox, oy, v3s(0), v3(0, 0, 1));
            CHECK(in.x == (dot ? 1.0f : 0.0f));
            CHECK(out.x == 0.0f);
            with += dot, without += !dot;
        }
    /* about half the cells hold a dot */
    CHECKF(with > 400 && without > 400, "%d cells with dots, %d without", with, without);
}

static void test_combinators(void)
{
    tex_node n[4];
    n[0] = cnode(v3(0.2f, 0.4f, 0.6f)), n[1] = cnode(v3s(0.5f)), n[2] = cnode(v3s(0.25f));
    /* scale */
    n[3] = node(TN_SCALE), n[3].a = 0, n[3].b = 1;
    vec3 v = eval_p(n, 4, v3s(0));
    CHECK_NEAR(v.x, 0.1, 1e-7);
    CHECK_NEAR(v.z, 0.3, 1e-7);
    /* mix: (1 - amount) tex1 + amount tex2 */
    n[3] = node(TN_MIX), n[3].a = 0, n[3].b = 1, n[3].c = 2;
    v = eval_p(n, 4, v3s(0));
    CHECK_NEAR(v.x, 0.75 * 0.2 + 0.25 * 0.5, 1e-7);
    CHECK_NEAR(v.z, 0.75 * 0.6 + 0.25 * 0.5, 1e-7);
    /* directionmix: |n . dir| tex1 + (1 - |n . dir|) tex2, either side */
    n[3] = node(TN_DIRMIX), n[3].a = 0, n[3].b = 1, n[3].v1 = v3(0, 1, 0);
    const vec3 nn = v3_norm(v3(0.6f, -0.8f, 0.0f));
    v = eval(n, 4, 0, 0, v3s(0), nn);
    CHECK_NEAR(v.x, 0.8 * 0.2 + 0.2 * 0.5, 1e-6);
    v = eval(n, 4, 0, 0, v3s(0), v3_neg(nn));
    CHECK_NEAR(v.x, 0.8 * 0.2 + 0.2 * 0.5, 1e-6);
    /* sqrt (roughness remapping) */
    n[3] = node(TN_SQRT), n[3].a = 2;
    CHECK_NEAR(eval_p(n, 4, v3s(0)).y, 0.5, 1e-7);
    /* malformed expressions are refused by the scene */
    n[3] = node(TN_MIX), n[3].a = 3;
    CHECK(!tex_nodes_valid(n, 4, 0));
    n[3] = node(TN_IMAGE);
    n[3].tex = 0;
    CHECK(!tex_nodes_valid(n, 4, 0));
    CHECK(tex_nodes_valid(n, 4, 1));
}

/* ---- the pbrt reader ------------------------------------------------------------------ */

static warning_log warnings;

static pk_scene *load_text(const char *text)
{
    warning_log_clear(&warnings);
    pk_scene *s = NULL;
    REQUIRE(scene_create(ctx, "t.pbrt", &s) == PK_OK);
    pk_status st = scene_pbrt_parse(ctx, s, text, strlen(text), "t.pbrt", PK_TEST_DATA "/pbrt");
    if (st == PK_OK) st = scene_commit(ctx, s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    if (st != PK_OK) {
        scene_destroy(s);
        pk_context_clear_error(ctx);
        return NULL;
    }
    return s;
}

/* The uv of the corner of triangle t that lies at position p. */
static bool uv_at(const pk_scene *s, size_t t, vec3 p, float *u, float *v)
{
    for (int k = 0; k < 3; k++) {
        const triangle *tr = &s->tris[t];
        if (v3_len(v3_sub(s->positions[tr->v[k]], p)) < 1e-5f && tr->t[k] >= 0) {
            *u = s->uvs[tr->t[k]].u, *v = s->uvs[tr->t[k]].v;
            return true;
        }
    }
    return false;
}

static void test_default_uvs(void)
{
    /* a camera that does not mirror: world positions are the file's */
#define PLAIN "Scale -1 1 1\nCamera \"perspective\"\nWorldBegin\n"
    pk_scene *s = load_text(PLAIN "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 4\n"
                                  "Material \"diffuse\" \"texture reflectance\" \"c\"\n"
                                  "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0] \"integer indices\" [0 1 2]\n"
                                  "Shape \"bilinearmesh\" \"point3 P\" [0 0 5 1 0 5 0 1 5 1 1 5]\n");
    REQUIRE(s != NULL);
    CHECKF(warnings.count == 0, "%s", warnings.all);
    REQUIRE(s->ntris == 3);
    float u, v;
    /* the triangle: (0,0), (1,0), (1,1) at its corners */
    CHECK(uv_at(s, 0, v3(0, 0, 0), &u, &v) && u == 0.0f && v == 0.0f);
    CHECK(uv_at(s, 0, v3(1, 0, 0), &u, &v) && u == 1.0f && v == 0.0f);
    CHECK(uv_at(s, 0, v3(1, 1, 0), &u, &v) && u == 1.0f && v == 1.0f);
    /* the patch: (0,0), (1,0), (0,1), (1,1) at p00 p10 p01 p11 */
    const vec3 pc[4] = {v3(0, 0, 5), v3(1, 0, 5), v3(0, 1, 5), v3(1, 1, 5)};
    const float uc[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (int k = 0; k < 4; k++) {
        bool found = false;
        for (size_t t = 1; t < 3 && !found; t++)
            if (uv_at(s, t, pc[k], &u, &v)) found = u == uc[k][0] && v == uc[k][1];
        CHECKF(found, "patch corner %d", k);
    }
    scene_destroy(s);

    /* twisted uv (the user's guide floor): a grid on which uv are the
     * bilinear interpolation of the corners' */
    s = load_text(PLAIN "Texture \"c\" \"spectrum\" \"checkerboard\"\n"
                        "Material \"diffuse\" \"texture reflectance\" \"c\"\n"
                        "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 4 0 0 0 4 0 4 4 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\n");
    REQUIRE(s != NULL);
    CHECK(s->ntris == 2 * 64 * 64);
    bool ok = true;
    for (size_t t = 0; t < s->ntris; t++)
        for (int k = 0; k < 3; k++) {
            const vec3 q = s->positions[s->tris[t].v[k]];
            const float a = q.x / 4.0f, b = q.y / 4.0f;
            const uv2 w = s->uvs[s->tris[t].t[k]];
            ok = ok && fabsf(w.u - (a * (1 - b) + (1 - a) * b)) < 1e-5f && fabsf(w.v - b) < 1e-5f;
        }
    CHECK(ok);
    scene_destroy(s);

    /* untextured: the mesh is left as it was (no uv, shared vertices) */
    s = load_text(PLAIN "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"integer indices\" [0 1 2 0 2 3]\n");
    REQUIRE(s != NULL);
    CHECK(s->npositions == 4 && s->nuvs == 0);
    scene_destroy(s);
}

/* Texture directives: each kind becomes the map kind it should, and
 * parameters without a map slot say so. */
static void test_reader(void)
{
    pk_scene *s = load_text(PLAIN
                            "Texture \"k\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"rgb tex1\" [1 0 0]\n"
                            "Texture \"f\" \"float\" \"fbm\" Texture \"g\" \"float\" \"mix\" \"float tex1\" 1.4 "
                            "\"float tex2\" 1.6 \"texture amount\" \"f\"\n"
                            "Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"k\" \"texture amount\" \"f\"\n"
                            "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"texture reflectance\" \"k\"\n"
                            "MakeNamedMaterial \"b\" \"string type\" \"diffuse\" \"texture reflectance\" \"m\"\n"
                            "MakeNamedMaterial \"c\" \"string type\" \"dielectric\" \"texture roughness\" \"f\"\n"
                            "MakeNamedMaterial \"d\" \"string type\" \"dielectric\" \"texture eta\" \"g\"\n"
                            "MakeNamedMaterial \"e\" \"string type\" \"conductor\" \"texture eta\" \"k\" \"texture k\" \"f\"\n"
                            "Shape \"sphere\"\n");
    REQUIRE(s != NULL);
    const material *a = &s->materials[scene_find_material(s, "a")];
    const material *b = &s->materials[scene_find_material(s, "b")];
    const material *c = &s->materials[scene_find_material(s, "c")];
    const material *e = &s->materials[scene_find_material(s, "e")];
    CHECK(a->map_kd.kind == TEX_CHECKER && a->map_kd.s[0] == 2.0f); /* the scene's own checker, as before */
    CHECK(b->map_kd.kind == TEX_EXPR && b->map_kd.nnodes == 6); /* tex1 (2 consts, checker), tex2, fbm, mix */
    CHECK(c->map_alpha.kind == TEX_EXPR && c->alpha == 1.0f);
    CHECK(s->tex_nodes[c->map_alpha.node + c->map_alpha.nnodes - 1].op == TN_SQRT); /* remaproughness */
    /* a conductor's eta and k take their textures (the checker as the scene's own, the fbm as an expression) */
    CHECK(e->type == MAT_CONDUCTOR && e->map_eta.kind == TEX_CHECKER && e->map_k.kind == TEX_EXPR);
    CHECK(e->eta.x == 1.0f && e->k.x == 1.0f);
    CHECKF(warnings.count == 1 && strstr(warnings.all, "t.pbrt:10: a texture for 'eta' is not supported (the material "
                                                        "has no texture map for it); using its mean"),
           "%s", warnings.all);
    scene_destroy(s);
}

static void test_files(void)
{
    const char *files[2] = {PK_TEST_DATA "/pbrt/textures.pbrt", PK_TEST_DATA "/pbrt/guide.pbrt"};
    for (int f = 0; f < 2; f++) {
        warning_log_clear(&warnings);
        pk_scene *s;
        REQUIRE(pk_scene_load_file(ctx, files[f], &s) == PK_OK);
        CHECKF(warnings.count == 0, "%s: %s", files[f], warnings.all);
        pk_render_options o;
        pk_render_options_init(&o);
        o.width = 48, o.height = 48, o.spp = 2, o.threads = 2;
        pk_image *img = NULL;
        REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
        const float *p = pk_image_pixels_const(img);
        double sum = 0.0;
        bool finite = true;
        for (int i = 0; i < 3 * 48 * 48; i++) finite = finite && isfinite(p[i]), sum += (double)p[i];
        CHECK(finite);
        CHECKF(sum > 0.0, "%s renders black", files[f]);
        pk_image_destroy(img);
        pk_scene_destroy(s);
    }
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    test_noise();
    test_fbm_family();
    test_mappings();
    test_checkerboard();
    test_dots();
    test_combinators();
    test_default_uvs();
    test_reader();
    test_files();
    pk_context_destroy(ctx);
    return test_done("test_texture_procedural");
}

/*
 * test_math.c - vector math, the reference ray-triangle and ray-sphere tests,
 * Fresnel and refraction against closed-form values.
 */
#include "test.h"

#include "accel/geom.h"
#include "render/optics.h"
#include "render/sampling.h"

static bool tri_hit(vec3 o, vec3 d, vec3 a, vec3 b, vec3 c, float *t, float *u, float *v)
{
    ray r = {o, 0.0f, d, INFINITY};
    ray_pre p = ray_prepare(&r);
    return tri_intersect(&p, a, b, c, INFINITY, t, u, v);
}

static void test_vec(void)
{
    vec3 a = v3(1, 2, 3), b = v3(4, 5, 6);
    CHECK(v3_dot(a, b) == 32.0f);
    vec3 c = v3_cross(v3(1, 0, 0), v3(0, 1, 0));
    CHECK(c.x == 0.0f && c.y == 0.0f && c.z == 1.0f);
    CHECK_NEAR(v3_len(v3_norm(b)), 1.0, 1e-6);
    vec3 z = v3_norm(v3s(0.0f));
    CHECK(z.x == 0.0f && z.y == 0.0f && z.z == 0.0f);
    CHECK(v3_max_axis_abs(v3(-5, 1, 2)) == 0 && v3_max_axis_abs(v3(0, -3, 2)) == 1);
    vec3 r = v3_reflect(v3(1, -1, 0), v3(0, 1, 0));
    CHECK(r.x == 1.0f && r.y == 1.0f);
    aabb bx = aabb_grow(aabb_grow(aabb_empty(), v3(0, 0, 0)), v3(1, 2, 3));
    CHECK(aabb_area(bx) == 2.0f * (2 + 6 + 3));
    CHECK(aabb_area(aabb_empty()) == 0.0f);
    CHECK(aabb_contains(bx, aabb_grow(aabb_empty(), v3(0.5f, 1, 1))));
    CHECK(!v3_finite(v3(NAN, 0, 0)) && !v3_finite(v3(0, INFINITY, 0)));
}

static void test_triangle(void)
{
    vec3 a = v3(0, 0, 0), b = v3(1, 0, 0), c = v3(0, 1, 0);
    float t, u, v;
    /* interior */
    CHECK(tri_hit(v3(0.25f, 0.25f, 1), v3(0, 0, -1), a, b, c, &t, &u, &v));
    CHECK_NEAR(t, 1.0, 1e-6);
    CHECK_NEAR(u, 0.25, 1e-6);
    CHECK_NEAR(v, 0.25, 1e-6);
    /* from behind: still a hit (no culling) */
    CHECK(tri_hit(v3(0.25f, 0.25f, -2), v3(0, 0, 1), a, b, c, &t, &u, &v) && fabsf(t - 2.0f) < 1e-6f);
    /* misses: outside, pointing away, parallel in the plane, parallel above it */
    CHECK(!tri_hit(v3(0.75f, 0.75f, 1), v3(0, 0, -1), a, b, c, &t, &u, &v));
    CHECK(!tri_hit(v3(0.25f, 0.25f, 1), v3(0, 0, 1), a, b, c, &t, &u, &v));
    CHECK(!tri_hit(v3(-1, 0.25f, 0), v3(1, 0, 0), a, b, c, &t, &u, &v));
    CHECK(!tri_hit(v3(-1, 0.25f, 1), v3(1, 0, 0), a, b, c, &t, &u, &v));
    /* edges and vertices count as hits */
    CHECK(tri_hit(v3(0.5f, 0, 1), v3(0, 0, -1), a, b, c, &t, &u, &v));
    CHECK(tri_hit(v3(0, 0.5f, 1), v3(0, 0, -1), a, b, c, &t, &u, &v));
    CHECK(tri_hit(v3(0.5f, 0.5f, 1), v3(0, 0, -1), a, b, c, &t, &u, &v));
    CHECK(tri_hit(v3(0, 0, 1), v3(0, 0, -1), a, b, c, &t, &u, &v) && u == 0.0f && v == 0.0f);
    CHECK(tri_hit(v3(1, 0, 1), v3(0, 0, -1), a, b, c, &t, &u, &v) && u == 1.0f && v == 0.0f);
    /* watertight: rays through points of the shared diagonal of a quad (b-c)
     * split into (a,b,c) and (b,d2,c) hit at least one of the two */
    vec3 d2 = v3(1, 1, 0);
    rng q = rng_seed(7, 7);
    for (int i = 0; i < 2000; i++) {
        float s = rng_float(&q);
        vec3 target = v3_add(v3_scale(b, s), v3_scale(c, 1.0f - s));
        vec3 o = v3(rng_float(&q) * 4.0f - 2.0f, rng_float(&q) * 4.0f - 2.0f, 1.0f + rng_float(&q) * 3.0f);
        vec3 dir = v3_sub(target, o);
        float t1, t2;
        bool h1 = tri_hit(o, dir, a, b, c, &t1, &u, &v);
        bool h2 = tri_hit(o, dir, b, d2, c, &t2, &u, &v);
        CHECKF(h1 || h2, "ray %d through the shared edge missed both triangles", i);
    }
    /* ray starting past tmax or before tmin */
    ray r = {v3(0.25f, 0.25f, 1), 0.0f, v3(0, 0, -1), 0.5f};
    ray_pre p = ray_prepare(&r);
    CHECK(!tri_intersect(&p, a, b, c, r.tmax, &t, &u, &v));
    r.tmax = INFINITY;
    r.tmin = 1.5f;
    p = ray_prepare(&r);
    CHECK(!tri_intersect(&p, a, b, c, r.tmax, &t, &u, &v));
    /* degenerate triangle never hits */
    CHECK(!tri_hit(v3(0.5f, 0, 1), v3(0, 0, -1), a, b, v3(2, 0, 0), &t, &u, &v));
}

static void test_sphere(void)
{
    float t, u, v;
    ray r = {v3(0, 0, 5), 0.0f, v3(0, 0, -1), INFINITY};
    ray_pre p = ray_prepare(&r);
    CHECK(sphere_intersect(&p, v3(0, 0, 0), 1.0f, INFINITY, &t, &u, &v));
    CHECK_NEAR(t, 4.0, 1e-5);
    /* from inside: the far root */
    r.o = v3(0, 0, 0);
    p = ray_prepare(&r);
    CHECK(sphere_intersect(&p, v3(0, 0, 0), 1.0f, INFINITY, &t, &u, &v));
    CHECK_NEAR(t, 1.0, 1e-6);
    /* miss beside it, and behind the origin */
    r.o = v3(2, 0, 5);
    p = ray_prepare(&r);
    CHECK(!sphere_intersect(&p, v3(0, 0, 0), 1.0f, INFINITY, &t, &u, &v));
    r.o = v3(0, 0, -5);
    p = ray_prepare(&r);
    CHECK(!sphere_intersect(&p, v3(0, 0, 0), 1.0f, INFINITY, &t, &u, &v));
    /* unnormalised direction: t in its units */
    ray r2 = {v3(0, 0, 5), 0.0f, v3(0, 0, -2), INFINITY};
    p = ray_prepare(&r2);
    CHECK(sphere_intersect(&p, v3(0, 0, 0), 1.0f, INFINITY, &t, &u, &v));
    CHECK_NEAR(t, 2.0, 1e-5);
    /* far away, small sphere: no cancellation */
    ray r3 = {v3(0, 0, 1e4f), 0.0f, v3(0, 0, -1), INFINITY};
    p = ray_prepare(&r3);
    CHECK(sphere_intersect(&p, v3(0, 0, 0), 0.01f, INFINITY, &t, &u, &v));
    CHECK_NEAR(t, 1e4 - 0.01, 2e-3);
}

/* Fresnel in double from the textbook formulas. */
static double fresnel_ref(double ci, double n1, double n2)
{
    double si = sqrt(1 - ci * ci), st = n1 / n2 * si;
    if (st >= 1) return 1;
    double ct = sqrt(1 - st * st);
    double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    double rp = (n1 * ct - n2 * ci) / (n1 * ct + n2 * ci);
    return 0.5 * (rs * rs + rp * rp);
}

static void test_fresnel(void)
{
    /* normal incidence: ((n1-n2)/(n1+n2))^2 = 0.04 for glass */
    CHECK_NEAR(fresnel_dielectric(1.0f, 1.0f, 1.5f), 0.04, 1e-6);
    CHECK_NEAR(fresnel_dielectric(1.0f, 1.5f, 1.0f), 0.04, 1e-6);
    /* Brewster's angle: p-polarised reflectance vanishes, so F = Rs/2 */
    double tb = atan(1.5), ct = cos(tb), st = sin(tb) / 1.5, ctt = sqrt(1 - st * st);
    double rs = (ct - 1.5 * ctt) / (ct + 1.5 * ctt);
    CHECK_NEAR(fresnel_dielectric((float)ct, 1.0f, 1.5f), 0.5 * rs * rs, 1e-5);
    /* grazing incidence reflects everything */
    CHECK_NEAR(fresnel_dielectric(0.0f, 1.0f, 1.5f), 1.0, 1e-6);
    /* several angles, both directions */
    for (int deg = 0; deg < 90; deg += 10) {
        double ci = cos(deg * 3.14159265358979 / 180.0);
        CHECK_NEAR(fresnel_dielectric((float)ci, 1.0f, 1.33f), fresnel_ref(ci, 1.0, 1.33), 1e-5);
        CHECK_NEAR(fresnel_dielectric((float)ci, 2.5f, 1.0f), fresnel_ref(ci, 2.5, 1.0), 1e-5);
    }
    /* total internal reflection beyond the critical angle (glass to air: 41.8 degrees) */
    CHECK(fresnel_dielectric(cosf(45.0f * PK_PI / 180.0f), 1.5f, 1.0f) == 1.0f);
    CHECK(fresnel_dielectric(cosf(40.0f * PK_PI / 180.0f), 1.5f, 1.0f) < 1.0f);
}

static void test_refraction(void)
{
    /* Snell: n1 sin(i) = n2 sin(t) */
    for (int deg = 0; deg < 89; deg += 11) {
        float a = (float)deg * PK_PI / 180.0f;
        vec3 d = v3(sinf(a), -cosf(a), 0.0f), n = v3(0, 1, 0), t;
        REQUIRE(refract_dir(d, n, 1.0f / 1.5f, &t));
        CHECK_NEAR(v3_len(t), 1.0, 1e-5);
        CHECK(t.y < 0.0f);
        CHECK_NEAR(sinf(a), 1.5f * t.x, 1e-5);
    }
    /* normal incidence goes straight through */
    vec3 t;
    REQUIRE(refract_dir(v3(0, -1, 0), v3(0, 1, 0), 1.0f / 1.33f, &t));
    CHECK_NEAR(t.y, -1.0, 1e-6);
    /* total internal reflection from inside glass at 60 degrees */
    float a = 60.0f * PK_PI / 180.0f;
    CHECK(!refract_dir(v3(sinf(a), -cosf(a), 0), v3(0, 1, 0), 1.5f, &t));
    a = 30.0f * PK_PI / 180.0f;
    CHECK(refract_dir(v3(sinf(a), -cosf(a), 0), v3(0, 1, 0), 1.5f, &t));
}

static void test_sampling(void)
{
    rng r = rng_seed(1, 2), r2 = rng_seed(1, 2), r3 = rng_seed(2, 2);
    CHECK(rng_u32(&r) == rng_u32(&r2));
    CHECK(rng_u32(&r) != rng_u32(&r3));
    double mean = 0, cosmean = 0;
    for (int i = 0; i < 20000; i++) {
        float f = rng_float(&r);
        CHECK(f >= 0.0f && f < 1.0f);
        mean += (double)f;
        vec3 d = sample_cosine(v3(0, 0, 1), rng_float(&r), rng_float(&r));
        CHECK(d.z >= 0.0f);
        cosmean += (double)d.z;
    }
    CHECK_NEAR(mean / 20000.0, 0.5, 0.01);
    CHECK_NEAR(cosmean / 20000, 2.0 / 3.0, 0.01); /* E[cos] under a cosine density */
    /* uniform triangle samples stay inside */
    for (int i = 0; i < 1000; i++) {
        vec3 p = sample_triangle(v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), rng_float(&r), rng_float(&r));
        CHECK(p.x >= 0.0f && p.y >= 0.0f && p.x + p.y <= 1.0f + 1e-6f);
    }
}

int main(void)
{
    test_vec();
    test_triangle();
    test_sphere();
    test_fresnel();
    test_refraction();
    test_sampling();
    return test_done("test_math");
}

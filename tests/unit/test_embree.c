/*
 * test_embree.c - the Embree backend answers like the brute-force reference
 * (PK_ACCEL_NONE): same hit or miss, t to 1e-4 relative, same primitive
 * except at ties, for closest hits, any-hit queries and packets, on the
 * Cornell scenes and on a synthetic set with spheres and degenerate triangles.
 * Skips (77) when the build has no Embree or ../shared is absent.
 */
#include "test.h"

#include "accel/accel.h"

#include <stdint.h>

#if PK_HAVE_EMBREE

typedef struct rng {
    uint64_t s;
} rng;

static float rnd(rng *r)
{
    uint64_t x = (r->s += 0x9E3779B97F4A7C15ull);
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    x ^= x >> 31;
    return (float)(x >> 40) * (1.0f / 16777216.0f);
}

static vec3 rnd_dir(rng *r)
{
    for (;;) {
        vec3 d = v3(2.0f * rnd(r) - 1.0f, 2.0f * rnd(r) - 1.0f, 2.0f * rnd(r) - 1.0f);
        float l2 = v3_len2(d);
        if (l2 > 1e-4f && l2 <= 1.0f) return v3_scale(d, 1.0f / sqrtf(l2));
    }
}

/* Random rays from inside the (slightly grown) box; every fourth one has a
 * [tmin, tmax] window so that the interval is respected. */
static ray *make_rays(rng *r, vec3 lo, vec3 hi, size_t n)
{
    ray *rays = malloc(n * sizeof *rays);
    REQUIRE(rays);
    vec3 ext = v3_sub(hi, lo);
    float size = v3_max_comp(ext);
    lo = v3_sub(lo, v3_scale(ext, 0.1f));
    ext = v3_scale(ext, 1.2f);
    for (size_t i = 0; i < n; i++) {
        ray *q = &rays[i];
        q->o = v3_add(lo, v3_mul(ext, v3(rnd(r), rnd(r), rnd(r))));
        q->d = rnd_dir(r);
        q->tmin = 0.0f;
        q->tmax = INFINITY;
        if (i % 4 == 3) {
            q->tmin = rnd(r) * 0.5f * size;
            q->tmax = q->tmin + rnd(r) * size;
        }
    }
    return rays;
}

/* Hits this close to the origin have no relative precision: the rounding
 * of the origin (a few ulps) moves them (as in `paprsek bench compare`). */
static float origin_slack(const ray *r)
{
    float m = fmaxf(1.0f, fmaxf(fabsf(r->o.x), fmaxf(fabsf(r->o.y), fabsf(r->o.z))));
    return 1e-6f * m / v3_len(r->d);
}

static bool t_close(float a, float b, float tol)
{
    return fabsf(a - b) <= tol * fmaxf(fabsf(a), fabsf(b));
}

typedef struct tally {
    size_t rays, hits, mismatches, prim_ties, uv_bad;
} tally;

/* Compares closest hits h (Embree) with ref (brute force). */
static void compare_closest(const ray *rays, const hit *ref, const hit *h, size_t n, float tol, tally *t)
{
    for (size_t i = 0; i < n; i++) {
        t->rays++;
        bool hr = ref[i].prim != PK_NO_HIT, he = h[i].prim != PK_NO_HIT;
        if (hr) t->hits++;
        if (hr != he) {
            /* one says the ray starts on a surface, the other does not */
            if (fabsf(hr ? ref[i].t : h[i].t) > origin_slack(&rays[i])) t->mismatches++;
            continue;
        }
        if (!hr) {
            CHECK(isinf(h[i].t));
            continue;
        }
        if (!t_close(ref[i].t, h[i].t, tol) && fabsf(ref[i].t - h[i].t) > origin_slack(&rays[i])) {
            t->mismatches++;
            continue;
        }
        CHECKF(h[i].t >= rays[i].tmin && h[i].t <= rays[i].tmax, "t %g outside [%g, %g]",
               (double)h[i].t, (double)rays[i].tmin, (double)rays[i].tmax);
        if (ref[i].prim != h[i].prim) t->prim_ties++;
        else if (fabsf(ref[i].u - h[i].u) > 1e-3f || fabsf(ref[i].v - h[i].v) > 1e-3f) t->uv_bad++;
    }
}

/* Brute force and Embree over in, n random rays: closest, occluded, packets. */
static void check_input(pk_context *ctx, const accel_input *in, vec3 lo, vec3 hi, size_t n, float tol,
                        const char *what)
{
    accel *ref = NULL, *emb = NULL;
    REQUIRE(accel_create(ctx, PK_ACCEL_NONE, in, &ref) == PK_OK);
    pk_status st = accel_create(ctx, PK_ACCEL_EMBREE, in, &emb);
    CHECKF(st == PK_OK, "%s: %s", what, pk_context_error(ctx));
    if (st != PK_OK) {
        accel_destroy(ref);
        return;
    }
    CHECK(strcmp(emb->info.name, "embree") == 0);
    CHECK(emb->info.primitives == in->ntris + in->nspheres);
    CHECK(emb->info.build_ms >= 0.0);
    CHECK(emb->info.bytes > 0);

    rng r = {0x1234u + n};
    ray *rays = make_rays(&r, lo, hi, n);
    hit *h_ref = malloc(n * sizeof *h_ref), *h_emb = malloc(n * sizeof *h_emb);
    hit *h_closest = malloc(n * sizeof *h_closest);
    REQUIRE(h_ref && h_emb && h_closest);
    for (size_t i = 0; i < n; i++) {
        accel_intersect(ref, &rays[i], &h_ref[i], NULL);
        accel_intersect(emb, &rays[i], &h_emb[i], NULL);
    }
    tally t = {0};
    compare_closest(rays, h_ref, h_emb, n, tol, &t);
    memcpy(h_closest, h_emb, n * sizeof *h_emb);

    /* packets, with a count that leaves a partial last group */
    size_t np = n - 5;
    REQUIRE(emb->ops->intersect_packet);
    memset(h_emb, 0xAB, n * sizeof *h_emb);
    for (size_t base = 0; base < np; base += 100) {
        size_t m = np - base < 100 ? np - base : 100;
        emb->ops->intersect_packet(emb, rays + base, h_emb + base, m, false, NULL);
    }
    tally tp = {0};
    compare_closest(rays, h_ref, h_emb, np, tol, &tp);

    /* any hit: single rays, then packets (which report the t of the hit found) */
    size_t occ_bad = 0, occ_pk_bad = 0;
    accel_counters c = {7, 9};
    for (size_t i = 0; i < n; i++)
        if (accel_occluded(emb, &rays[i], &c) != (h_ref[i].prim != PK_NO_HIT)) occ_bad++;
    CHECK(c.tests == 7 && c.nodes == 9); /* Embree counts nothing */
    emb->ops->intersect_packet(emb, rays, h_emb, n, true, NULL);
    for (size_t i = 0; i < n; i++) {
        bool hr = h_ref[i].prim != PK_NO_HIT;
        bool he = h_emb[i].t < INFINITY;
        if (hr != he) {
            occ_pk_bad++;
            continue;
        }
        if (he) {
            CHECKF(h_emb[i].t >= rays[i].tmin && h_emb[i].t <= rays[i].tmax && h_emb[i].prim != PK_NO_HIT,
                   "%s: any-hit %zu: t %g prim %u", what, i, (double)h_emb[i].t, h_emb[i].prim);
            /* never nearer than the closest hit */
            CHECKF(h_emb[i].t >= h_closest[i].t * (1.0f - tol) - origin_slack(&rays[i]),
                   "%s: any-hit %zu: t %g, closest %g", what, i, (double)h_emb[i].t, (double)h_closest[i].t);
        }
    }

    /* Embree is not watertight: a ray through a shared edge may slip through. */
    size_t allowed = n / 2000 + 2;
    CHECKF(t.hits > n / 10, "%s: only %zu of %zu rays hit", what, t.hits, t.rays);
    CHECKF(t.mismatches <= allowed, "%s: closest: %zu of %zu rays disagree", what, t.mismatches, t.rays);
    CHECKF(tp.mismatches <= allowed, "%s: packets: %zu of %zu rays disagree", what, tp.mismatches, tp.rays);
    CHECKF(occ_bad <= allowed, "%s: occluded: %zu of %zu rays disagree", what, occ_bad, n);
    CHECKF(occ_pk_bad <= allowed, "%s: any-hit packets: %zu of %zu disagree", what, occ_pk_bad, n);
    CHECKF(t.uv_bad <= allowed, "%s: %zu hits with other u, v", what, t.uv_bad);
    printf("%s: %zu rays, %zu hits, %zu/%zu/%zu/%zu mismatches (closest/packets/occluded/any-hit packets), "
           "%zu ties, %.2f ms build\n",
           what, t.rays, t.hits, t.mismatches, tp.mismatches, occ_bad, occ_pk_bad, t.prim_ties,
           emb->info.build_ms);

    free(rays);
    free(h_ref);
    free(h_emb);
    free(h_closest);
    accel_destroy(emb);
    accel_destroy(ref);
}

static void check_scene(pk_context *ctx, const char *rel, size_t n)
{
    char path[1024];
    shared_path(path, sizeof path, rel);
    pk_scene *scene = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &scene) == PK_OK);
    pk_scene_info si;
    pk_scene_get_info(scene, &si);
    vec3 *verts = malloc(3 * si.triangles * sizeof *verts);
    REQUIRE(verts);
    for (size_t k = 0; k < si.triangles; k++) {
        float tv[9];
        REQUIRE(pk_scene_get_triangle(scene, k, tv) == PK_OK);
        for (int j = 0; j < 3; j++) verts[3 * k + j] = v3(tv[3 * j], tv[3 * j + 1], tv[3 * j + 2]);
    }
    accel_input in = {verts, si.triangles, NULL, 0, 2};
    vec3 lo = v3(si.bounds_min[0], si.bounds_min[1], si.bounds_min[2]);
    vec3 hi = v3(si.bounds_max[0], si.bounds_max[1], si.bounds_max[2]);
    check_input(ctx, &in, lo, hi, n, 1e-4f, rel);
    free(verts);
    pk_scene_destroy(scene);
}

/* Triangles (a degenerate one first, so numbering is tested) and spheres. */
static void check_synthetic(pk_context *ctx)
{
    enum { NT = 40, NS = 12 };
    vec3 verts[3 * NT];
    accel_sphere sph[NS];
    rng r = {99};
    verts[0] = v3(0, 0, 0);
    verts[1] = v3(1, 1, 1);
    verts[2] = v3(2, 2, 2); /* collinear: never hit, but keeps number 0 */
    for (int k = 1; k < NT; k++) {
        vec3 c = v3(4.0f * rnd(&r), 4.0f * rnd(&r), 4.0f * rnd(&r));
        for (int j = 0; j < 3; j++) verts[3 * k + j] = v3_add(c, v3_scale(rnd_dir(&r), 0.8f));
    }
    for (int k = 0; k < NS; k++) {
        sph[k].center = v3(4.0f * rnd(&r), 4.0f * rnd(&r), 4.0f * rnd(&r));
        sph[k].radius = 0.2f + 0.5f * rnd(&r);
    }
    accel_input in = {verts, NT, sph, NS, 1};
    check_input(ctx, &in, v3(0, 0, 0), v3(4, 4, 4), 20000, 1e-4f, "synthetic");

    /* Numbering, u, v and [tmin, tmax] on a small set: triangle 0 is
     * degenerate, triangle 1 lies in z = 0, sphere 2 sits above it. */
    vec3 tv[6] = {v3(0, 0, 0), v3(1, 1, 0), v3(2, 2, 0), v3(0, 0, 0), v3(2, 0, 0), v3(0, 2, 0)};
    accel_sphere ball = {v3(0.5f, 0.5f, 3.0f), 0.5f};
    accel_input small = {tv, 2, &ball, 1, 1};
    accel *emb = NULL;
    REQUIRE(accel_create(ctx, PK_ACCEL_EMBREE, &small, &emb) == PK_OK);
    ray q = {v3(0.5f, 0.25f, 1.0f), 0.0f, v3(0, 0, -1), INFINITY};
    hit h;
    REQUIRE(accel_intersect(emb, &q, &h, NULL));
    CHECK(h.prim == 1);
    CHECK_NEAR(h.t, 1.0f, 1e-6);
    CHECK_NEAR(h.u, 0.25f, 1e-6); /* p = (1-u-v) v0 + u v1 + v v2 */
    CHECK_NEAR(h.v, 0.125f, 1e-6);
    q.tmax = 0.99f;
    CHECK(!accel_intersect(emb, &q, &h, NULL));
    CHECK(h.prim == PK_NO_HIT && isinf(h.t));
    CHECK(!accel_occluded(emb, &q, NULL));
    q.tmax = INFINITY;
    q.tmin = 1.01f;
    CHECK(!accel_intersect(emb, &q, &h, NULL));
    /* the sphere is primitive ntris + 0 = 2; from its centre the ray leaves it */
    ray s = {ball.center, 0.0f, v3(0, 0, 1), INFINITY};
    REQUIRE(accel_intersect(emb, &s, &h, NULL));
    CHECK(h.prim == 2);
    CHECK_NEAR(h.t, 0.5f, 1e-5);
    CHECK_NEAR(h.v, 0.5f, 1e-3); /* the equator of the (u, v) parametrisation */
    s.o = v3(0.5f, 0.5f, 5.0f);
    s.d = v3(0, 0, -2); /* t in units of d */
    REQUIRE(accel_intersect(emb, &s, &h, NULL));
    CHECK(h.prim == 2);
    CHECK_NEAR(h.t, 0.75f, 1e-5);
    accel_destroy(emb);
}

static void check_quality(pk_context *ctx)
{
    const char *levels[] = {"embree.quality=low", "embree.quality=high", "embree.quality=medium"};
    for (int i = 0; i < 3; i++) {
        REQUIRE(pk_context_set_config(ctx, levels[i]) == PK_OK);
        check_scene(ctx, "scenes/cornell/CornellBox-Original.obj", 5000);
    }
    /* a bad value is refused by the config, naming the key, and changes nothing */
    CHECK(pk_context_set_config(ctx, "embree.quality=extreme") == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "embree.quality=extreme") != NULL);
    pk_context_clear_error(ctx);
    char cfg[512];
    pk_context_get_config(ctx, cfg, sizeof cfg);
    CHECK(strstr(cfg, "embree.quality=medium") != NULL);
    /* another Embree library than the one loaded: a clean error */
    REQUIRE(pk_context_set_config(ctx, "embree.library=/nowhere/libembree3.so.3") == PK_OK);
    vec3 v[3] = {v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)};
    accel_input in = {v, 1, NULL, 0, 1};
    accel *emb = NULL;
    CHECK(accel_create(ctx, PK_ACCEL_EMBREE, &in, &emb) == PK_ERR_UNSUPPORTED);
    CHECK(emb == NULL);
    CHECK(strstr(pk_context_error(ctx), "/nowhere/libembree3.so.3") != NULL);
    pk_context_clear_error(ctx);
    REQUIRE(pk_context_set_config(ctx, "embree.library=") == PK_OK);
}

#endif /* PK_HAVE_EMBREE */

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
#if !PK_HAVE_EMBREE
    {
        vec3 v[3] = {v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)};
        accel_input in = {v, 1, NULL, 0, 1};
        accel *emb = NULL;
        CHECK(!accel_embree_available(ctx));
        CHECK(accel_create(ctx, PK_ACCEL_EMBREE, &in, &emb) == PK_ERR_UNSUPPORTED);
        CHECK(strstr(pk_context_error(ctx), "no Embree") != NULL);
        pk_context_destroy(ctx);
        if (test_failures) return test_done("test_embree");
        SKIP("this build has no Embree");
    }
#else
    CHECK(accel_embree_available(ctx));
    check_synthetic(ctx);
    char path[1024];
    shared_path(path, sizeof path, "scenes/cornell/CornellBox-Sphere.obj");
    check_scene(ctx, "scenes/cornell/CornellBox-Sphere.obj", 20000);
    check_scene(ctx, "scenes/cornell/CornellBox-Original.obj", 20000);
    check_scene(ctx, "scenes/cornell/CornellBox-Glossy.obj", 20000);
    check_scene(ctx, "scenes/cornell/CornellBox-Water.obj", 10000);
    check_quality(ctx);
    pk_context_destroy(ctx);
    return test_done("test_embree");
#endif
}

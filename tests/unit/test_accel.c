/*
 * test_accel.c - the seed's midpoint BVH against brute force: invariants on
 * every build, and bit-identical closest hits and agreeing any-hit answers on
 * 100k random rays over each scene of ../shared/scenes/cornell; degenerate
 * inputs (no triangles, one, all at one point, huge and tiny coordinates).
 */
#include "test.h"

#include "render/frame.h"
#include "render/sampling.h"

#include <dirent.h>

#define NRAYS 100000

static pk_context *ctx;

static void make_rays(const pk_scene *s, ray *rays, size_t n, uint64_t seed)
{
    rng r = rng_seed(seed, 99);
    aabb b = s->bounds;
    vec3 ext = aabb_extent(b);
    float big = v3_max_comp(ext);
    for (size_t i = 0; i < n; i++) {
        vec3 o = v3(b.lo.x + ext.x * (rng_float(&r) * 1.4f - 0.2f), b.lo.y + ext.y * (rng_float(&r) * 1.4f - 0.2f),
                    b.lo.z + ext.z * (rng_float(&r) * 1.4f - 0.2f));
        vec3 d;
        if (i % 3 == 0 && s->ntris) { /* aim at a vertex of a random triangle: edges and corners */
            vec3 p[3];
            size_t k = rng_u32(&r) % s->ntris;
            scene_tri_verts(s, k, &p[0], &p[1], &p[2]);
            d = v3_sub(p[rng_u32(&r) % 3], o);
        } else {
            d = v3(rng_float(&r) * 2 - 1, rng_float(&r) * 2 - 1, rng_float(&r) * 2 - 1);
        }
        if (i % 17 == 0) d.x = 0.0f; /* axis-parallel components */
        if (i % 19 == 0) d.y = 0.0f;
        if (!(v3_len2(d) > 0.0f)) d = v3(0, 0, 1);
        rays[i] = (ray){o, 0.0f, d, INFINITY};
        if (i % 5 == 0) rays[i].tmax = big * rng_float(&r);
        if (i % 7 == 0) rays[i].tmin = big * 0.1f * rng_float(&r);
    }
}

static void compare(const char *name, const pk_scene *s, pk_accel_kind kind)
{
    accel *ref = NULL, *acc = NULL;
    REQUIRE(frame_build_accel(ctx, s, PK_ACCEL_NONE, 2, &ref) == PK_OK);
    REQUIRE(frame_build_accel(ctx, s, kind, 2, &acc) == PK_OK);
    char why[256] = "";
    if (kind == PK_ACCEL_MIDPOINT) CHECKF(midpoint_check(acc, why, sizeof why), "%s: %s", name, why);
    ray *rays = malloc(NRAYS * sizeof *rays);
    hit *h0 = malloc(NRAYS * sizeof *h0), *h1 = malloc(NRAYS * sizeof *h1), *o1 = malloc(NRAYS * sizeof *o1);
    REQUIRE(rays && h0 && h1 && o1);
    make_rays(s, rays, NRAYS, 1234);
    accel_trace_batch(ref, rays, h0, NRAYS, 2, 0, NULL);
    accel_trace_batch(acc, rays, h1, NRAYS, 2, 0, NULL);
    accel_trace_batch(acc, rays, o1, NRAYS, 2, PK_TRACE_ANY_HIT, NULL);
    size_t bad = 0, hits = 0, bad_any = 0;
    for (size_t i = 0; i < NRAYS; i++) {
        hits += h0[i].prim != PK_NO_HIT;
        if (memcmp(&h0[i], &h1[i], sizeof(hit)) != 0) {
            if (bad < 5)
                fprintf(stderr, "%s ray %zu: none t=%.9g prim=%u, %s t=%.9g prim=%u\n", name, i, (double)h0[i].t,
                        h0[i].prim, pk_accel_kind_name(kind), (double)h1[i].t, h1[i].prim);
            bad++;
        }
        bad_any += (o1[i].prim != PK_NO_HIT) != (h0[i].prim != PK_NO_HIT);
        /* the any-hit answer is a real hit: its t lies in the ray's interval */
        if (o1[i].prim != PK_NO_HIT) bad_any += !(o1[i].t >= rays[i].tmin && o1[i].t <= rays[i].tmax);
    }
    CHECKF(bad == 0, "%s: %zu of %d closest hits differ", name, bad, NRAYS);
    CHECKF(bad_any == 0, "%s: %zu any-hit answers disagree with closest hits", name, bad_any);
    CHECKF(hits > NRAYS / 10, "%s: only %zu rays hit: the test rays miss the scene", name, hits);
    printf("%s: %zu rays, %zu hits, %s identical to none\n", name, (size_t)NRAYS, hits, pk_accel_kind_name(kind));
    free(rays);
    free(h0);
    free(h1);
    free(o1);
    accel_destroy(ref);
    accel_destroy(acc);
}

static pk_scene *scene_from(const char *text)
{
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_obj_memory(ctx, text, strlen(text), "test.obj", NULL, &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    return s;
}

static void test_degenerate(void)
{
    /* one triangle */
    pk_scene *s = scene_from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    REQUIRE(s);
    compare("one triangle", s, PK_ACCEL_MIDPOINT);
    pk_scene_destroy(s);
    /* many triangles sharing one centroid (identical copies) plus a real one */
    char buf[8192];
    size_t n = (size_t)snprintf(buf, sizeof buf, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 6 5 5\nv 5 6 5\n");
    for (int i = 0; i < 40; i++) n += (size_t)snprintf(buf + n, sizeof buf - n, "f 1 2 3\n");
    snprintf(buf + n, sizeof buf - n, "f 4 5 6\n");
    s = scene_from(buf);
    REQUIRE(s);
    compare("coincident triangles", s, PK_ACCEL_MIDPOINT);
    pk_scene_destroy(s);
    /* huge and tiny coordinates (the edge-function products stay within float range) */
    s = scene_from("v -1e15 -1e15 0\nv 1e15 -1e15 0\nv 0 1e15 0\nv -1e15 -1e15 1e15\nv 1e15 -1e15 1e15\n"
                   "v 0 1e15 2e15\nf 1 2 3\nf 4 5 6\n");
    REQUIRE(s);
    compare("huge coordinates", s, PK_ACCEL_MIDPOINT);
    pk_scene_destroy(s);
    s = scene_from("v -1e-12 -1e-12 0\nv 1e-12 -1e-12 0\nv 0 1e-12 0\nv -1e-12 -1e-12 1e-12\nv 1e-12 -1e-12 1e-12\n"
                   "v 0 1e-12 2e-12\nf 1 2 3\nf 4 5 6\n");
    REQUIRE(s);
    compare("tiny coordinates", s, PK_ACCEL_MIDPOINT);
    pk_scene_destroy(s);
    /* all triangles at one point: nothing renderable, the loader refuses it */
    pk_scene *none = NULL;
    const char *pt = "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\nf 1 2 3\n";
    CHECK(pk_scene_load_obj_memory(ctx, pt, strlen(pt), "point.obj", NULL, &none) == PK_ERR_EMPTY_SCENE);
    CHECK(none == NULL);
    pk_context_clear_error(ctx);
    /* zero primitives: both accelerators build and always miss */
    accel_input in = {NULL, 0, NULL, 0, 1};
    accel *a = NULL;
    REQUIRE(accel_create(ctx, PK_ACCEL_MIDPOINT, &in, &a) == PK_OK);
    ray r = {v3(0, 0, 0), 0.0f, v3(0, 0, 1), INFINITY};
    hit h;
    CHECK(!accel_intersect(a, &r, &h, NULL) && h.prim == PK_NO_HIT && isinf(h.t));
    CHECK(!accel_occluded(a, &r, NULL));
    accel_destroy(a);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_degenerate();
    char dir[1024];
    shared_path(dir, sizeof dir, "scenes/cornell");
    DIR *d = opendir(dir);
    REQUIRE(d);
    struct dirent *e;
    int nscenes = 0;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l < 4 || strcmp(e->d_name + l - 4, ".obj") != 0) continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        pk_scene *s = NULL;
        if (pk_scene_load_file(ctx, path, &s) != PK_OK) {
            CHECKF(0, "%s: %s", path, pk_context_error(ctx));
            pk_context_clear_error(ctx);
            continue;
        }
        compare(e->d_name, s, PK_ACCEL_MIDPOINT);
        pk_scene_destroy(s);
        nscenes++;
    }
    closedir(d);
    CHECK(nscenes >= 10);
    pk_context_destroy(ctx);
    return test_done("test_accel");
}

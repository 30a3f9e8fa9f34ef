/*
 * test_bvh_gpu.c - the GPU layout and traversal of bvh_gpu.h, run on the
 * CPU: the functions the CUDA kernels call, compiled for the host. The
 * conversion's invariants (gpu_layout_check) and conservative boxes on
 * synthetic and shared scenes; the triangle test and ray set-up bit for bit
 * against geom.h's; closest hits bit for bit against brute force (the
 * "none" accelerator, geom.h's test on every triangle) and the CPU BVH;
 * any-hit answers; the checker catching broken layouts; and the public
 * door (--accel cuda without a driver is a clean error; with a device the
 * GPU's hits are compared here too).
 */
#include "accel/bvh_gpu.h"

#include "accel/accel.h"
#include "scene/scene.h"
#include "test.h"
#include "test_rng.h"

#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(sizeof(vec3) == 3 * sizeof(float), "vec3 arrays are float arrays");


static bool same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }
static bool same_hit(const pk_hit *a, const pk_hit *b)
{
    return same_bits(a->t, b->t) && a->prim == b->prim && same_bits(a->u, b->u) && same_bits(a->v, b->v);
}

/* ---- the pieces: quantisation, ray set-up, triangle test ------------------ */

static void test_quantise(void)
{
    rng g = {7};
    long bad = 0, refused = 0;
    for (int i = 0; i < 200000; i++) {
        float org = rng_range(&g, -1000.0f, 1000.0f) * (i % 3 == 0 ? 1e-30f : 1.0f);
        int e = (int)(rng_u32(&g) % 60) - 40;
        float s = ldexpf(1.0f, e);
        float lo = org + rng_f(&g) * 300.0f * s, hi = lo + rng_f(&g) * 300.0f * s;
        if (i % 17 == 0) hi = lo;
        uint8_t ql, qh;
        if (!gpu_quantise(org, (unsigned)(e + 127), lo, hi, &ql, &qh)) {
            /* refused only when the interval really does not fit in 255 steps */
            refused++;
            bad += !((double)hi - (double)org > 254.0 * (double)s);
            continue;
        }
        bad += !(gpu_plane(org, ql, s) <= lo && gpu_plane(org, qh, s) >= hi && ql <= qh);
    }
    CHECKF(bad == 0, "%ld intervals quantised wrongly or refused though they fit", bad);
    CHECK(refused > 0 && refused < 200000 / 2);
    uint8_t ql, qh;
    CHECK(!gpu_quantise(0.0f, 127, -1.0f, 1.0f, &ql, &qh)); /* below the frame */
    CHECK(!gpu_quantise(0.0f, 127, 0.0f, 256.0f, &ql, &qh)); /* beyond 255 steps */
    CHECK(gpu_quantise(0.0f, 127, 0.0f, 255.0f, &ql, &qh) && ql == 0 && qh == 255);
    CHECK(!gpu_quantise(0.0f, 127, NAN, 1.0f, &ql, &qh));
}

static vec3 rng_point(rng *g, float scale)
{
    return v3(rng_range(g, -scale, scale), rng_range(g, -scale, scale), rng_range(g, -scale, scale));
}

static void test_triangle_and_ray(void)
{
    rng g = {11};
    long bad_pre = 0, bad_tri = 0, hits = 0;
    for (int i = 0; i < 400000; i++) {
        const float scale = (i & 3) == 0 ? 1e4f : (i & 3) == 1 ? 1e-3f : 1.0f;
        vec3 a = rng_point(&g, scale), b = rng_point(&g, scale), c = rng_point(&g, scale);
        if (i % 11 == 0) c = v3_lerp(a, b, rng_f(&g)); /* degenerate */
        if (i % 13 == 0) b = a;
        ray r;
        r.o = rng_point(&g, 2.0f * scale);
        /* at a vertex, an edge or inside, or anywhere */
        uint32_t w = rng_u32(&g) % 4;
        vec3 target = w == 0 ? a : w == 1 ? v3_lerp(b, c, rng_f(&g)) : w == 2 ? v3_lerp(v3_lerp(a, b, 0.3f), c, 0.4f)
                                                                             : rng_point(&g, scale);
        r.d = v3_sub(target, r.o);
        if (i % 7 == 0) r.d.x = 0.0f;
        if (i % 9 == 0) r.d = v3(0.0f, 0.0f, -1.0f);
        if (!(v3_len2(r.d) > 0.0f)) r.d = v3(1, 0, 0);
        r.tmin = (i % 5 == 0) ? rng_f(&g) * 0.5f : 0.0f;
        r.tmax = (i % 6 == 0) ? rng_f(&g) * 1.5f : INFINITY;
        ray_pre p = ray_prepare(&r);
        gpu_ray q;
        gpu_ray_init(&q, (const pk_ray *)&r);
        bad_pre += !(q.kx == p.kx && q.ky == p.ky && q.kz == p.kz && same_bits(q.sx, p.sx) && same_bits(q.sy, p.sy) &&
                     same_bits(q.sz, p.sz) && same_bits(q.rd[0], p.inv_d.x) && same_bits(q.rd[1], p.inv_d.y) &&
                     same_bits(q.rd[2], p.inv_d.z));
        gpu_tri t = {{a.x, a.y, a.z}, 0, {b.x, b.y, b.z}, 0.0f, {c.x, c.y, c.z}, 0.0f};
        float t1 = 0, u1 = 0, v1 = 0, t2 = 0, u2 = 0, v2 = 0;
        bool h1 = tri_intersect(&p, a, b, c, r.tmax, &t1, &u1, &v1);
        bool h2 = gpu_tri_intersect(&q, &t, r.tmax, &t2, &u2, &v2);
        hits += h1;
        bad_tri += h1 != h2 || (h1 && !(same_bits(t1, t2) && same_bits(u1, u2) && same_bits(v1, v2)));
    }
    CHECKF(bad_pre == 0, "%ld ray set-ups differ from ray_prepare", bad_pre);
    CHECKF(bad_tri == 0, "%ld triangle tests differ from geom.h's", bad_tri);
    CHECKF(hits > 50000, "only %ld hits: the test exercises too little", hits);
}

/* ---- whole structures ------------------------------------------------------ */

typedef struct built {
    accel *cpu;   /* the CPU's wide BVH */
    accel *none;  /* brute force */
    gpu_layout g;
} built;

/* costs: the collapse's cost model (NULL: the CPU's tree) */
static bool build_tree(pk_context *ctx, const accel_input *in, const bvh_costs *costs, const char *name, built *b)
{
    memset(b, 0, sizeof *b);
    pk_status st = accel_bvh_create_costs(ctx, in, costs, &b->cpu);
    if (st == PK_OK) b->cpu->ntris = in->ntris, b->cpu->nspheres = in->nspheres; /* (as accel_create does) */
    CHECKF(st == PK_OK, "%s: bvh: %s", name, pk_context_error(ctx));
    if (st != PK_OK) return false;
    REQUIRE(accel_create(ctx, PK_ACCEL_NONE, in, &b->none) == PK_OK);
    st = gpu_layout_build(ctx, &ctx->alloc, b->cpu, &b->g);
    CHECKF(st == PK_OK, "%s: conversion: %s", name, pk_context_error(ctx));
    if (st != PK_OK) return false;
    char why[256] = "";
    CHECKF(gpu_layout_check(&b->g, (const float *)in->verts, why, sizeof why), "%s: gpu_layout_check: %s", name, why);
    CHECKF(gpu_layout_check_boxes(&b->g, b->cpu, why, sizeof why), "%s: gpu_layout_check_boxes: %s", name, why);
    return true;
}

static bool build_all(pk_context *ctx, const accel_input *in, const char *name, built *b)
{
    return build_tree(ctx, in, NULL, name, b);
}

static void free_all(pk_context *ctx, built *b)
{
    gpu_layout_free(&ctx->alloc, &b->g);
    accel_destroy(b->cpu);
    accel_destroy(b->none);
}

/* Random rays about box: origins in the box grown by 20%, random directions
 * (some with zero components, some along an axis), a third aimed at a
 * vertex, an edge or the inside of a triangle; some with tmin > 0 or a
 * finite tmax; a few that cannot hit anything (NaN, infinite origin). */
static ray *make_rays(rng *g, const accel_input *in, size_t n)
{
    aabb box = aabb_empty();
    for (size_t i = 0; i < 3 * in->ntris; i++)
        if (v3_finite(in->verts[i])) box = aabb_grow(box, in->verts[i]);
    if (!(box.lo.x <= box.hi.x)) box = (aabb){{-1, -1, -1}, {1, 1, 1}};
    vec3 ext = aabb_extent(box);
    ray *rays = malloc(n * sizeof *rays);
    REQUIRE(rays);
    for (size_t i = 0; i < n; i++) {
        ray r;
        r.o = v3(rng_range(g, box.lo.x - 0.2f * ext.x, box.hi.x + 0.2f * ext.x),
                 rng_range(g, box.lo.y - 0.2f * ext.y, box.hi.y + 0.2f * ext.y),
                 rng_range(g, box.lo.z - 0.2f * ext.z, box.hi.z + 0.2f * ext.z));
        r.tmin = 0.0f;
        r.tmax = INFINITY;
        uint32_t kind = rng_u32(g) % 12;
        if (kind < 4 && in->ntris) {
            const vec3 *p = in->verts + 3 * (rng_u32(g) % in->ntris);
            uint32_t w = rng_u32(g) % 3;
            vec3 target = w == 0 ? p[rng_u32(g) % 3] : w == 1 ? v3_lerp(p[0], p[1], rng_f(g))
                                                               : v3_lerp(v3_lerp(p[0], p[1], 0.5f), p[2], rng_f(g));
            r.d = v3_sub(target, r.o);
            if (!(v3_len2(r.d) > 0.0f) || !v3_finite(r.d)) r.d = rng_dir(g);
        } else {
            r.d = rng_dir(g);
            if (kind == 4) {
                uint32_t z = rng_u32(g) % 7;
                if (z & 1) r.d.x = 0.0f;
                if (z & 2) r.d.y = 0.0f;
                if (z & 4) r.d.z = 0.0f;
                if (!(v3_len2(r.d) > 0.0f)) r.d = v3(0.0f, -1.0f, 0.0f);
            } else if (kind == 5) {
                r.d = v3_scale(r.d, rng_range(g, 0.01f, 100.0f));
            }
        }
        if (kind == 6) r.tmax = rng_range(g, 0.0f, 2.0f);
        if (kind == 7) r.tmin = rng_range(g, 0.0f, 0.5f);
        if (kind == 8 && (rng_u32(g) & 15) == 0) {
            uint32_t z = rng_u32(g) % 3;
            if (z == 0) r.d.x = NAN;
            if (z == 1) r.o.y = INFINITY;
            if (z == 2) r.tmax = NAN;
        }
        if (kind == 9 && (rng_u32(g) & 7) == 0) r.d = v3(0x1p-130f, 1.0f, 0.0f); /* 1/d overflows */
        rays[i] = r;
    }
    return rays;
}

/* The box tests on every node of b against gpu_node_hits_v0 (whose boxes
 * contain the CPU's): GPU_TEST_FMA gives the same slots and the same entry
 * distances, GPU_TEST_WIDE at least the same slots with entry distances no
 * larger. Rays from make_rays and harder ones: tiny and
 * huge direction components (1/d overflowing or S = scale / d doing so),
 * origins far away, and cull distances of every size. */
static void check_box_tests(const built *b, const accel_input *in, rng *g, size_t nrays, const char *name)
{
    ray *rays = make_rays(g, in, nrays);
    long bad_fma = 0, bad_wide = 0, entered = 0, extra6 = 0;
    for (size_t i = 0; i < nrays; i++) {
        ray r = rays[i];
        const uint32_t kind = rng_u32(g) % 8;
        if (kind == 0) r.d.x *= 1e-30f; /* 1/d huge */
        if (kind == 1) r.d = v3_scale(r.d, 1e30f);
        if (kind == 2) r.o = v3_scale(r.o, 1e5f);
        if (kind == 3) r.d.y = 0x1p-149f;
        if (!gpu_ray_traceable((const pk_ray *)&r)) continue;
        gpu_ray q;
        gpu_ray_init(&q, (const pk_ray *)&r);
        const float tcull = kind == 4 ? INFINITY : rng_range(g, 0.0f, 3.0f) * (kind == 5 ? 1e6f : 1.0f);
        for (size_t j = 0; j < b->g.nnodes; j++) {
            const gpu_node *nd = &b->g.nodes[j];
            uint32_t w[24];
            gpu_node_load(nd, w);
            float t0[GPU_WIDTH], t3[GPU_WIDTH], t6[GPU_WIDTH];
            const unsigned m0 = gpu_node_hits_v0(nd, &q, tcull, t0);
            const unsigned m3 = gpu_node_hits_fma(w, &q, tcull, t3);
            const unsigned m6 = gpu_node_hits_wide(w, &q, tcull, t6);
            /* (gpu_trace_box uses it only for rays with every |1/d| < 2^64; here it is
             * tried on all, overflows included) */
            if (kind >= 4 && fabsf(q.rd[0]) < 0x1p64f && fabsf(q.rd[1]) < 0x1p64f && fabsf(q.rd[2]) < 0x1p64f) {
                /* rays it is used for */
                entered += __builtin_popcount(m0);
                extra6 += __builtin_popcount(m6 & ~m0);
            }
            bad_fma += m3 != m0, bad_wide += (m6 & m0) != m0;
            for (int s = 0; s < GPU_WIDTH; s++) {
                if (!(m0 >> s & 1u)) continue;
                bad_fma += !(t3[s] == t0[s]);
                bad_wide += !(t6[s] <= t0[s]);
            }
        }
    }
    free(rays);
    CHECKF(bad_fma == 0, "%s: GPU_TEST_FMA differs from gpu_node_hits_v0 %ld times", name, bad_fma);
    CHECKF(bad_wide == 0, "%s: GPU_TEST_WIDE misses a box or enters it later %ld times", name, bad_wide);
    printf("%s: box tests: %ld boxes entered by ordinary rays, %ld more (%.3f%%) by GPU_TEST_WIDE\n", name, entered,
           extra6, 100.0 * (double)extra6 / (double)(entered ? entered : 1));
}

/* Every ray: closest hit bit for bit against brute force (and against the
 * CPU BVH when cpu_too), any-hit agreeing on hit/miss with a real hit. */
static void check_rays(const built *b, const accel_input *in, const ray *rays, size_t n, bool brute, const char *name)
{
    long bad_brute = 0, bad_cpu = 0, bad_any = 0, bad_anyhit = 0, bad_v0 = 0, bad_loose = 0, nhits = 0, ties = 0;
    long loose_ties = 0, bad_ordered = 0, ordered_ties = 0;
    const long nn = (long)n;
    CHECKF(gpu_layout_ordered(&b->g), "%s: the ordered traversal cannot run (stack %u, %zu nodes)", name,
           b->g.ordered_need, b->g.nnodes);
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : bad_brute, bad_cpu, bad_any, bad_anyhit, bad_v0, \
                                                              bad_loose, nhits, ties, loose_ties, bad_ordered, \
                                                              ordered_ties)
    for (long i = 0; i < nn; i++) {
        const ray *r = &rays[i];
        pk_hit got, any;
        hit want, cpu;
        gpu_trace(b->g.nodes, b->g.tris, (const pk_ray *)r, false, &got, NULL);
        gpu_trace(b->g.nodes, b->g.tris, (const pk_ray *)r, true, &any, NULL);
        /* every kernel's traversal: the first one's answers, any hits
         * included where the box distances are the same (the same visiting
         * order); the loosened boxes give the same closest hit (but for ties) */
        pk_hit got0, any0, h;
        const bool f0 = gpu_trace_v0(b->g.nodes, b->g.tris, (const pk_ray *)r, false, &got0, NULL);
        const bool a0 = gpu_trace_v0(b->g.nodes, b->g.tris, (const pk_ray *)r, true, &any0, NULL);
        bad_v0 += !same_hit(&got, &got0) || !same_hit(&any, &any0) || f0 != (got.prim != PK_NO_HIT) ||
                  a0 != (any.prim != PK_NO_HIT);
        {
            bool f = gpu_trace_box(b->g.nodes, b->g.tris, (const pk_ray *)r, false, &h, NULL, GPU_TEST_FMA);
            bad_v0 += !same_hit(&h, &got0) || f != f0;
            f = gpu_trace_box(b->g.nodes, b->g.tris, (const pk_ray *)r, true, &h, NULL, GPU_TEST_FMA);
            bad_v0 += !same_hit(&h, &any0) || f != a0;
        }
        /* (the visiting order may differ: an exact tie in t may then go to
         * another triangle, as between brute force and the CPU BVH) */
        {
            bool fl = gpu_trace_box(b->g.nodes, b->g.tris, (const pk_ray *)r, false, &h, NULL, GPU_TEST_WIDE);
            if (fl != f0) bad_loose++;
            else if (!same_hit(&h, &got0)) {
                const vec3 *p = in->verts + 3 * (size_t)h.prim;
                ray_pre pre = ray_prepare(r);
                float t, u, v;
                const bool tie = same_bits(h.t, got0.t) && h.prim < in->ntris &&
                                 tri_intersect(&pre, p[0], p[1], p[2], r->tmax, &t, &u, &v) && same_bits(t, h.t);
                loose_ties += tie;
                bad_loose += !tie;
            }
            fl = gpu_trace_box(b->g.nodes, b->g.tris, (const pk_ray *)r, true, &h, NULL, GPU_TEST_WIDE);
            if (fl != a0) bad_loose++;
            else if (fl) { /* some real hit in [tmin, tmax] */
                const vec3 *p = in->verts + 3 * (size_t)h.prim;
                ray_pre pre = ray_prepare(r);
                float t, u, v;
                bad_loose += !(h.prim < in->ntris && tri_intersect(&pre, p[0], p[1], p[2], r->tmax, &t, &u, &v) &&
                               same_bits(t, h.t) && same_bits(u, h.u) && same_bits(v, h.v));
            }
        }
        /* the ordered traversal (octant slots, mask stack): the same closest
         * hit but for exact ties; any hits real */
        if (gpu_layout_ordered(&b->g))
            for (int box = 0; box < 2; box++) {
                const int bt = box ? GPU_TEST_WIDE : GPU_TEST_FMA;
                bool fo = gpu_trace_ordered(b->g.nodes, b->g.tris, (const pk_ray *)r, false, &h, NULL, bt);
                if (fo != f0) bad_ordered++;
                else if (!same_hit(&h, &got0)) {
                    const vec3 *p = in->verts + 3 * (size_t)h.prim;
                    ray_pre pre = ray_prepare(r);
                    float t, u, v;
                    const bool tie = same_bits(h.t, got0.t) && h.prim < in->ntris &&
                                     tri_intersect(&pre, p[0], p[1], p[2], r->tmax, &t, &u, &v) &&
                                     same_bits(t, h.t);
                    ordered_ties += tie;
                    bad_ordered += !tie;
                }
                fo = gpu_trace_ordered(b->g.nodes, b->g.tris, (const pk_ray *)r, true, &h, NULL, bt);
                if (fo != a0) bad_ordered++;
                else if (fo) {
                    const vec3 *p = in->verts + 3 * (size_t)h.prim;
                    ray_pre pre = ray_prepare(r);
                    float t, u, v;
                    bad_ordered += !(h.prim < in->ntris &&
                                     tri_intersect(&pre, p[0], p[1], p[2], r->tmax, &t, &u, &v) &&
                                     same_bits(t, h.t) && same_bits(u, h.u) && same_bits(v, h.v));
                }
            }
        accel_intersect(b->cpu, r, &cpu, NULL);
        bad_cpu += !same_hit(&got, (const pk_hit *)&cpu);
        if (brute) {
            accel_intersect(b->none, r, &want, NULL);
            /* An exact tie in t between different triangles (coplanar copies)
             * may go to a higher number than brute force's, as in the CPU BVH
             * (checked bit for bit above), whose cull slack is relative to t:
             * a box entered a few dozen ulps beyond a tied hit is skipped. The
             * other triangle must then be hit at exactly the same t. */
            bool tie = false;
            if (!same_hit(&got, (const pk_hit *)&want) && same_bits(got.t, want.t) && got.prim != PK_NO_HIT &&
                got.prim < in->ntris) {
                const vec3 *p = in->verts + 3 * (size_t)got.prim;
                ray_pre pre = ray_prepare(r);
                float t, u, v;
                tie = tri_intersect(&pre, p[0], p[1], p[2], r->tmax, &t, &u, &v) && same_bits(t, got.t);
                ties += tie;
            }
            bad_brute += !tie && !same_hit(&got, (const pk_hit *)&want);
            if (getenv("TEST_VERBOSE") && !tie && !same_hit(&got, (const pk_hit *)&want))
#pragma omp critical
                fprintf(stderr, "%s: ray %ld o %a %a %a d %a %a %a [%a %a]: got %a %u %a %a, brute %a %u %a %a\n", name,
                        i, (double)r->o.x, (double)r->o.y, (double)r->o.z, (double)r->d.x, (double)r->d.y,
                        (double)r->d.z, (double)r->tmin, (double)r->tmax, (double)got.t, got.prim, (double)got.u,
                        (double)got.v, (double)want.t, want.prim, (double)want.u, (double)want.v);
        }
        nhits += got.prim != PK_NO_HIT;
        bad_any += (any.prim != PK_NO_HIT) != (got.prim != PK_NO_HIT);
        if (any.prim != PK_NO_HIT) {
            /* the reported triangle is hit at the reported t, inside [tmin, tmax] */
            const vec3 *p = in->verts + 3 * (size_t)any.prim;
            ray_pre pre = ray_prepare(r);
            float t, u, v;
            bad_anyhit += !(any.prim < in->ntris && tri_intersect(&pre, p[0], p[1], p[2], r->tmax, &t, &u, &v) &&
                            same_bits(t, any.t) && any.t >= got.t);
        }
    }
    CHECKF(bad_brute == 0, "%s: %ld of %zu closest hits differ from brute force", name, bad_brute, n);
    CHECKF(bad_cpu == 0, "%s: %ld of %zu closest hits differ from the CPU BVH", name, bad_cpu, n);
    CHECKF(bad_v0 == 0, "%s: %ld of %zu hits differ between the exact box test and gpu_trace_v0", name, bad_v0, n);
    CHECKF(bad_loose == 0, "%s: %ld of %zu hits of the loosened box test (GPU_TEST_WIDE) are wrong", name, bad_loose,
           n);
    CHECKF(bad_ordered == 0, "%s: %ld of %zu hits of the ordered traversal are wrong", name, bad_ordered, n);
    if (ordered_ties)
        printf("%s: %ld exact ties went to another triangle with the ordered traversal\n", name, ordered_ties);
    CHECKF(bad_any == 0, "%s: %ld of %zu any-hit answers disagree with the closest hit", name, bad_any, n);
    CHECKF(bad_anyhit == 0, "%s: %ld of %zu any-hit answers are not real hits", name, bad_anyhit, n);
    if (ties) printf("%s: %ld exact ties went to another triangle than brute force's\n", name, ties);
    if (loose_ties)
        printf("%s: %ld exact ties went to another triangle with GPU_TEST_WIDE than with the CPU BVH\n", name,
               loose_ties);
    if (in->ntris > 1 && n > 0) CHECKF(nhits > 0, "%s: no ray hit anything", name);
}

static void check_input(pk_context *ctx, const accel_input *in, size_t nrays, size_t nbrute, uint64_t seed,
                        const char *name)
{
    built b;
    if (build_all(ctx, in, name, &b)) {
        rng g = {seed};
        check_box_tests(&b, in, &g, nrays / 40 + 10, name);
        ray *rays = make_rays(&g, in, nrays);
        check_rays(&b, in, rays, nbrute < nrays ? nbrute : nrays, true, name);
        if (nbrute < nrays) check_rays(&b, in, rays + nbrute, nrays - nbrute, false, name);
        free(rays);
        /* counting costs nothing in the answers */
        gpu_counters c = {0, 0};
        pk_hit h1, h2;
        ray r = {v3(0.1f, 0.2f, 5.0f), 0.0f, v3(0, 0, -1), INFINITY};
        gpu_trace(b.g.nodes, b.g.tris, (const pk_ray *)&r, false, &h1, &c);
        gpu_trace(b.g.nodes, b.g.tris, (const pk_ray *)&r, false, &h2, NULL);
        CHECK(same_hit(&h1, &h2) && c.nodes >= 1);
    }
    pk_context_clear_error(ctx);
    free_all(ctx, &b);
}

typedef struct mesh {
    vec3 *v;
    size_t ntris, cap;
} mesh;

static void mesh_tri(mesh *m, vec3 a, vec3 b, vec3 c)
{
    if (m->ntris == m->cap) {
        m->cap = m->cap ? 2 * m->cap : 64;
        m->v = realloc(m->v, m->cap * 3 * sizeof *m->v);
        REQUIRE(m->v);
    }
    m->v[3 * m->ntris] = a, m->v[3 * m->ntris + 1] = b, m->v[3 * m->ntris + 2] = c;
    m->ntris++;
}

static void run_mesh(pk_context *ctx, mesh *m, size_t nrays, size_t nbrute, uint64_t seed, const char *name)
{
    accel_input in = {m->v, m->ntris, NULL, 0, 2};
    check_input(ctx, &in, nrays, nbrute, seed, name);
    free(m->v);
    memset(m, 0, sizeof *m);
}

static void test_synthetic(pk_context *ctx)
{
    rng g = {2024};
    mesh m = {0};
    /* a soup of random triangles of all sizes */
    for (int i = 0; i < 3000; i++) {
        vec3 c = rng_point(&g, 10.0f);
        float s = rng_f(&g) < 0.1f ? 3.0f : 0.3f;
        mesh_tri(&m, v3_add(c, rng_point(&g, s)), v3_add(c, rng_point(&g, s)), v3_add(c, rng_point(&g, s)));
    }
    run_mesh(ctx, &m, 30000, 30000, 1, "soup");
    /* degenerate ones among them: zero area, repeated vertex, NaN and inf vertices */
    for (int i = 0; i < 600; i++) {
        vec3 a = rng_point(&g, 1.0f), b = rng_point(&g, 1.0f), c = rng_point(&g, 1.0f);
        switch (i % 6) {
        case 0: c = v3_lerp(a, b, 0.25f); break;
        case 1: b = a; break;
        case 2: c.y = NAN; break;
        case 3: a.x = INFINITY; break;
        default: break;
        }
        mesh_tri(&m, a, b, c);
    }
    run_mesh(ctx, &m, 20000, 20000, 2, "degenerate soup");
    /* identical triangles: ties go to the lower number */
    for (int i = 0; i < 40; i++) mesh_tri(&m, v3(-1, -1, 0), v3(1, -1, 0), v3(0, 1, 0));
    for (int i = 0; i < 40; i++) mesh_tri(&m, v3(-1, -1, 1), v3(1, -1, 1), v3(0, 1, 1));
    run_mesh(ctx, &m, 5000, 5000, 3, "stacked copies");
    /* a closed grid of quads in one plane (a zero extent on z), sharing edges */
    for (int i = 0; i < 40; i++)
        for (int j = 0; j < 40; j++) {
            vec3 p = v3((float)i, (float)j, 0.0f), q = v3((float)i + 1, (float)j, 0.0f);
            vec3 r = v3((float)i + 1, (float)j + 1, 0.0f), s = v3((float)i, (float)j + 1, 0.0f);
            mesh_tri(&m, p, q, r);
            mesh_tri(&m, p, r, s);
        }
    run_mesh(ctx, &m, 20000, 20000, 4, "flat grid");
    /* far from the origin and tiny: quantisation frames at extreme scales */
    for (int i = 0; i < 2000; i++) {
        vec3 c = v3_add(v3(1e6f, -2e6f, 3e5f), rng_point(&g, 100.0f));
        mesh_tri(&m, v3_add(c, rng_point(&g, 1.0f)), v3_add(c, rng_point(&g, 1.0f)), v3_add(c, rng_point(&g, 1.0f)));
    }
    run_mesh(ctx, &m, 10000, 10000, 5, "far away");
    for (int i = 0; i < 2000; i++) {
        /* (products of two coordinates must stay normal floats for the edge functions) */
        vec3 c = v3_scale(rng_point(&g, 1.0f), 1e-12f);
        mesh_tri(&m, v3_add(c, v3_scale(rng_point(&g, 1.0f), 1e-13f)), v3_add(c, v3_scale(rng_point(&g, 1.0f), 1e-13f)),
                 v3_add(c, v3_scale(rng_point(&g, 1.0f), 1e-13f)));
    }
    run_mesh(ctx, &m, 10000, 10000, 6, "tiny");
    /* one triangle; and none at all */
    mesh_tri(&m, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0));
    run_mesh(ctx, &m, 2000, 2000, 7, "one triangle");
    mesh_tri(&m, v3(0, 0, 0), v3(1, 0, 0), v3(2, 0, 0)); /* degenerate only */
    run_mesh(ctx, &m, 1000, 1000, 8, "nothing hittable");
    /* many small triangles: a deep tree */
    for (int i = 0; i < 60000; i++) {
        vec3 c = rng_point(&g, 50.0f);
        c.y *= 0.01f;
        mesh_tri(&m, v3_add(c, rng_point(&g, 0.2f)), v3_add(c, rng_point(&g, 0.2f)), v3_add(c, rng_point(&g, 0.2f)));
    }
    run_mesh(ctx, &m, 40000, 2000, 9, "60k slab");
}

/* ---- the checker catches broken layouts ------------------------------------ */

static void test_checker(pk_context *ctx)
{
    rng g = {99};
    mesh m = {0};
    for (int i = 0; i < 2000; i++) {
        vec3 c = rng_point(&g, 10.0f);
        mesh_tri(&m, v3_add(c, rng_point(&g, 0.5f)), v3_add(c, rng_point(&g, 0.5f)), v3_add(c, rng_point(&g, 0.5f)));
    }
    accel_input in = {m.v, m.ntris, NULL, 0, 1};
    built b;
    REQUIRE(build_all(ctx, &in, "checker", &b));
    REQUIRE(b.g.nnodes > 2);
    char why[256];
    const float *verts = (const float *)m.v;
    /* each damage is undone after it is checked */
    gpu_node *root = &b.g.nodes[0];
    int s = 0;
    while (root->child[s] == GPU_EMPTY) s++;
    /* a box shrunk on one side */
    uint8_t keep = root->q[1][s];
    root->q[1][s] = 0;
    CHECK(!gpu_layout_check(&b.g, verts, why, sizeof why) || !gpu_layout_check_boxes(&b.g, b.cpu, why, sizeof why));
    root->q[1][s] = keep;
    CHECK(gpu_layout_check(&b.g, verts, why, sizeof why));
    /* a vertex moved */
    float kv = b.g.tris[0].b[1];
    b.g.tris[0].b[1] = kv + 1.0f;
    CHECK(!gpu_layout_check(&b.g, verts, why, sizeof why) && strstr(why, "vertices differ"));
    b.g.tris[0].b[1] = kv;
    /* a triangle number out of range */
    uint32_t kp = b.g.tris[0].prim;
    b.g.tris[0].prim = (uint32_t)m.ntris;
    CHECK(!gpu_layout_check(&b.g, verts, why, sizeof why));
    b.g.tris[0].prim = kp;
    /* a node referenced twice (a slot of the root pointing at its sibling's node) */
    int inner = -1, other = -1;
    for (int k = 0; k < GPU_WIDTH; k++) {
        uint32_t ref = root->child[k];
        if (ref == GPU_EMPTY) continue;
        if (!(ref & GPU_LEAF) && inner < 0) inner = k;
        else if (other < 0) other = k;
    }
    if (inner >= 0 && other >= 0) {
        uint32_t kr = root->child[other];
        root->child[other] = root->child[inner];
        CHECK(!gpu_layout_check(&b.g, verts, why, sizeof why));
        root->child[other] = kr;
    }
    /* a leaf that lost its records */
    for (size_t i = 0; i < b.g.nnodes; i++) {
        gpu_node *nd = &b.g.nodes[i];
        int k = 0;
        while (k < GPU_WIDTH && (nd->child[k] == GPU_EMPTY || !(nd->child[k] & GPU_LEAF))) k++;
        if (k == GPU_WIDTH) continue;
        uint32_t kr = nd->child[k];
        nd->child[k] = GPU_EMPTY;
        CHECK(!gpu_layout_check(&b.g, verts, why, sizeof why));
        nd->child[k] = kr;
        break;
    }
    /* a wrong stack bound */
    b.g.stack_need++;
    CHECK(!gpu_layout_check(&b.g, verts, why, sizeof why));
    b.g.stack_need--;
    CHECKF(gpu_layout_check(&b.g, verts, why, sizeof why), "undamaged again: %s", why);
    free_all(ctx, &b);
    free(m.v);

    /* spheres are refused by the conversion and by the accelerator */
    accel_sphere sph = {v3(0, 0, 0), 1.0f};
    accel_input sin = {NULL, 0, &sph, 1, 1};
    accel *cpu = NULL;
    REQUIRE(accel_create(ctx, PK_ACCEL_BVH, &sin, &cpu) == PK_OK);
    gpu_layout gl;
    CHECK(gpu_layout_build(ctx, &ctx->alloc, cpu, &gl) == PK_ERR_UNSUPPORTED);
    pk_context_clear_error(ctx);
    accel_destroy(cpu);
}

/* ---- shared scenes ---------------------------------------------------------- */

/* Nodes visited, triangles tested and bytes read per ray (closest hit) on
 * rays from inside the scene's box: what the tree costs the GPU (printed). */
static void traffic(const built *b, const accel_input *in, const char *what, const char *name)
{
    rng g = {4242};
    const size_t n = 20000;
    ray *rays = make_rays(&g, in, n);
    gpu_counters c = {0, 0};
    for (size_t i = 0; i < n; i++) {
        pk_hit h;
        gpu_trace(b->g.nodes, b->g.tris, (const pk_ray *)&rays[i], false, &h, &c);
    }
    free(rays);
    printf("%-44s %s: %.1f nodes and leaves, %.1f triangles, %.0f bytes a ray\n", name, what, (double)c.nodes / n,
           (double)c.tests / n, ((double)c.nodes * sizeof(gpu_node) + (double)c.tests * sizeof(gpu_tri)) / n);
}

static void check_file(pk_context *ctx, const char *rel, size_t nrays, size_t nbrute)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", PK_SHARED_DIR, rel);
    if (access(path, R_OK) != 0) {
        printf("%s: not there (../shared is absent), skipped\n", rel);
        return;
    }
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_file(ctx, path, &s);
    CHECKF(st == PK_OK, "%s: %s", rel, pk_context_error(ctx));
    if (st != PK_OK) {
        pk_context_clear_error(ctx);
        return;
    }
    vec3 *verts = malloc((s->ntris * 3 + 1) * sizeof *verts);
    REQUIRE(verts);
    for (size_t k = 0; k < s->ntris; k++) scene_tri_verts(s, k, &verts[3 * k], &verts[3 * k + 1], &verts[3 * k + 2]);
    accel_input in = {verts, s->ntris, NULL, 0, 2};
    double t0 = omp_get_wtime();
    built b;
    if (build_all(ctx, &in, rel, &b)) {
        rng g = {0x9e3779b97f4a7c15ull ^ s->ntris};
        check_box_tests(&b, &in, &g, b.g.nnodes < 100 ? 20000 : (size_t)2e6 / b.g.nnodes, rel);
        ray *rays = make_rays(&g, &in, nrays);
        check_rays(&b, &in, rays, nbrute, true, rel);
        check_rays(&b, &in, rays + nbrute, nrays - nbrute, false, rel);
        free(rays);
        printf("%-44s %7zu tris %6zu nodes %7zu records (%.1f MiB) stack %3u  %.2f s\n", rel, s->ntris, b.g.nnodes,
               b.g.ntris, (double)(b.g.nnodes * sizeof(gpu_node) + b.g.ntris * sizeof(gpu_tri)) / 1048576.0,
               b.g.stack_need, omp_get_wtime() - t0);
        traffic(&b, &in, "the CPU's tree", rel);
    }
    free_all(ctx, &b);
    pk_context_clear_error(ctx);
    /* trees collapsed for the GPU with other node costs: the same checks */
    static const float node_costs[] = {2.0f, 4.0f, 8.0f};
    for (size_t c = 0; c < sizeof node_costs / sizeof *node_costs; c++) {
        const bvh_costs costs = {node_costs[c], 1, 16};
        char what[64];
        snprintf(what, sizeof what, "node cost %g", (double)costs.node);
        if (build_tree(ctx, &in, &costs, rel, &b)) {
            rng g = {77 + c};
            ray *rays = make_rays(&g, &in, nrays / 4);
            check_rays(&b, &in, rays, nbrute / 4, true, rel);
            check_rays(&b, &in, rays + nbrute / 4, nrays / 4 - nbrute / 4, false, rel);
            free(rays);
            printf("%-44s %s: %6zu nodes %7zu records (%.1f MiB) stack %3u\n", rel, what, b.g.nnodes, b.g.ntris,
                   (double)(b.g.nnodes * sizeof(gpu_node) + b.g.ntris * sizeof(gpu_tri)) / 1048576.0, b.g.stack_need);
            traffic(&b, &in, what, rel);
        }
        free_all(ctx, &b);
        pk_context_clear_error(ctx);
    }

    /* the public door: without a driver or device a clean error; with one,
     * the GPU's hits against the host's */
    pk_accel *pa = NULL;
    st = pk_accel_create(ctx, s, PK_ACCEL_CUDA, 2, &pa);
    if (!pk_accel_available(PK_ACCEL_CUDA)) {
        CHECK(st == PK_ERR_UNSUPPORTED && strstr(pk_context_error(ctx), "not available"));
    } else if (st != PK_OK) {
        const char *msg = pk_context_error(ctx);
        CHECKF(st == PK_ERR_UNSUPPORTED && (strstr(msg, "no CUDA driver") || strstr(msg, "no CUDA device")),
               "%s: --accel cuda: %s", rel, msg);
        printf("%s: --accel cuda: %s (the device comparison needs a GPU)\n", rel, msg);
    } else {
        rng g = {5};
        const size_t n = 100000;
        ray *rays = make_rays(&g, &in, n);
        pk_hit *dev = malloc(n * sizeof *dev), *host = malloc(n * sizeof *host);
        REQUIRE(dev && host);
        pk_accel *cpu = NULL;
        REQUIRE(pk_accel_create(ctx, s, PK_ACCEL_BVH, 2, &cpu) == PK_OK);
        /* the default kernels, then the reference ones (gpu_trace_v0) */
        for (int ver = 0; ver < 2; ver++) {
            accel *ref = NULL;
            if (ver > 0) {
                st = accel_cuda_create_reference(ctx, &in, &ref);
                CHECKF(st == PK_OK, "%s: reference kernels: %s", rel, pk_context_error(ctx));
                if (st != PK_OK) {
                    pk_context_clear_error(ctx);
                    continue;
                }
            }
            for (int any = 0; any < 2; any++) {
                unsigned flags = any ? PK_TRACE_ANY_HIT : 0u;
                if (ver > 0)
                    accel_trace_batch(ref, rays, (hit *)dev, n, 0, flags, NULL);
                else
                    pk_accel_trace(pa, (const pk_ray *)rays, dev, n, 0, flags, NULL);
                CHECKF(pk_context_status(ctx) == PK_OK, "%s: device trace: %s", rel, pk_context_error(ctx));
                pk_accel_trace(cpu, (const pk_ray *)rays, host, n, 0, flags, NULL);
                size_t bad = 0;
                for (size_t i = 0; i < n; i++)
                    bad += any ? (dev[i].prim != PK_NO_HIT) != (host[i].prim != PK_NO_HIT) : !same_hit(&dev[i], &host[i]);
                CHECKF(bad == 0, "%s: %s kernels: %zu of %zu device %s hits differ from the CPU's", rel,
                       ver ? "reference" : "default", bad, n, any ? "any" : "closest");
            }
            accel_destroy(ref);
        }
        pk_accel_device_info di;
        CHECK(pk_accel_get_device_info(pa, &di) == 1 && di.kernel_ms > 0.0 && di.structure_bytes > 0);
        CHECK(pk_accel_get_device_info(cpu, &di) == 0);
        printf("%s: the device (%s) agrees with the CPU on %zu rays\n", rel, di.device, n);
        pk_accel_destroy(cpu);
        free(rays), free(dev), free(host);
    }
    pk_context_clear_error(ctx);
    pk_accel_destroy(pa);
    free(verts);
    pk_scene_destroy(s);
}

/* ---- the ordered traversal's pieces ------------------------------------------ */

static void test_ordered_pieces(pk_context *ctx)
{
    /* bit j of the ordered mask is bit j ^ o of the node's */
    long bad = 0;
    for (unsigned o = 0; o < 8; o++)
        for (unsigned m = 0; m < 256; m++) {
            const unsigned pm = gpu_mask_order(m, o);
            for (unsigned j = 0; j < 8; j++) bad += (pm >> j & 1u) != (m >> (j ^ o) & 1u);
        }
    CHECKF(bad == 0, "gpu_mask_order: %ld bits misplaced", bad);
    uint32_t w[8] = {11, 22, 33, 44, 55, 66, 77, 88};
    for (unsigned i = 0; i < 8; i++) CHECK(gpu_sel8(w, i) == w[i]);
    /* eight boxes at the corners of a cube: each child lands in the slot of
     * its octant, so a ray of octant o meets the child of slot o first */
    mesh m = {0};
    for (int c = 0; c < 8; c++) {
        const vec3 o = v3((c & 1) ? 2.0f : -3.0f, (c & 2) ? 2.0f : -3.0f, (c & 4) ? 2.0f : -3.0f);
        for (int k = 0; k < 40; k++) { /* enough triangles that each corner is a subtree */
            const float f = 0.02f * (float)k;
            mesh_tri(&m, v3_add(o, v3(f, 0, 0)), v3_add(o, v3(f + 0.5f, 0.02f, 1)), v3_add(o, v3(f, 1, 0.3f)));
        }
    }
    accel_input in = {m.v, m.ntris, NULL, 0, 2};
    bvh_costs costs = {4.0f, 1, GPU_LEAF_MAX};
    built b;
    if (build_tree(ctx, &in, &costs, "corners", &b)) {
        const gpu_node *root = &b.g.nodes[0];
        int placed = 0, used = 0;
        for (int s = 0; s < GPU_WIDTH; s++) {
            if (root->child[s] == GPU_EMPTY) continue;
            used++;
            int ok = 1;
            for (int k = 0; k < 3; k++) {
                const float sc = gpu_scale(root->ex[k]);
                const float mid = 0.5f * (gpu_plane(root->org[k], root->q[2 * k][s], sc) +
                                          gpu_plane(root->org[k], root->q[2 * k + 1][s], sc));
                ok &= (s >> k & 1) ? mid > 0.0f : mid < 0.0f;
            }
            placed += ok;
        }
        CHECKF(used == 8 && placed == 8, "corners: %d of %d children in their octant's slot", placed, used);
        CHECKF(b.g.ordered_need >= 1 && b.g.ordered_need <= b.g.stack_need, "corners: ordered stack %u, sorted %u",
               b.g.ordered_need, b.g.stack_need);
    }
    free_all(ctx, &b);
    free(m.v);
}

/* ---- names and the public door ---------------------------------------------- */

static void test_public(pk_context *ctx)
{
    pk_accel_kind k = PK_ACCEL_DEFAULT;
    CHECK(pk_accel_kind_parse("cuda", &k) == PK_OK && k == PK_ACCEL_CUDA);
    CHECK(strcmp(pk_accel_kind_name(PK_ACCEL_CUDA), "cuda") == 0);
    CHECK(pk_accel_available(PK_ACCEL_CUDA) == PK_HAVE_CUDA_BUILD);
    /* a CPU accelerator has no device information */
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    pk_accel *pa = NULL;
    REQUIRE(pk_accel_create(ctx, s, PK_ACCEL_BVH, 1, &pa) == PK_OK);
    pk_accel_device_info di;
    memset(&di, 0x55, sizeof di);
    CHECK(pk_accel_get_device_info(pa, &di) == 0 && di.kernel_ms == 0.0 && di.device[0] == '\0');
    CHECK(pk_accel_get_device_info(NULL, &di) == 0 && pk_accel_get_device_info(pa, NULL) == 0);
    pk_accel_destroy(pa);
    /* the GPU renders with the path tracer, not the Whitted integrator */
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.accel = PK_ACCEL_CUDA;
    o.integrator = PK_INTEGRATOR_PATH;
    CHECK(pk_render_options_check(ctx, &o) == (PK_HAVE_CUDA_BUILD ? PK_OK : PK_ERR_UNSUPPORTED));
    pk_context_clear_error(ctx);
    o.integrator = PK_INTEGRATOR_WHITTED;
    CHECK(pk_render_options_check(ctx, &o) == PK_ERR_UNSUPPORTED);
    if (PK_HAVE_CUDA_BUILD) CHECK(strstr(pk_context_error(ctx), "path tracer only") != NULL);
    pk_context_clear_error(ctx);
    pk_scene_destroy(s);
}

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    double t0 = omp_get_wtime();
    test_quantise();
    test_triangle_and_ray();
    printf("pieces: %.2f s\n", omp_get_wtime() - t0);
    t0 = omp_get_wtime();
    test_synthetic(ctx);
    printf("synthetic cases: %.2f s\n", omp_get_wtime() - t0);
    test_checker(ctx);
    test_ordered_pieces(ctx);
    test_public(ctx);
    const char *cornell[] = {"CornellBox-Empty-CO.obj", "CornellBox-Glossy.obj", "CornellBox-Mirror.obj",
                             "CornellBox-Original.obj", "CornellBox-Sphere.obj", "CornellBox-Water.obj"};
    for (size_t i = 0; i < sizeof cornell / sizeof *cornell; i++) {
        char rel[256];
        snprintf(rel, sizeof rel, "scenes/cornell/%s", cornell[i]);
        check_file(ctx, rel, 30000, 30000);
    }
    check_file(ctx, "scenes/bench/stanford-bunny.obj", 100000, 1000);
    check_file(ctx, "scenes/bench/dabrovic-sponza/sponza.obj", 100000, 300);
    pk_context_destroy(ctx);
    return test_done("test_bvh_gpu");
}

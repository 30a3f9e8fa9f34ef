/*
 * test_gpu_warp.c - a warp cost model of the GPU traversals, run on the host.
 *
 * The GPU runs one ray per thread in warps of 32 that execute in lock step:
 * a loop iteration costs the warp as much as its slowest lane, and lanes
 * whose ray is done, or that wait for the others to finish a phase, idle.
 * The model runs the very traversal code the kernels run (bvh_gpu.h's
 * gpu_walk_step and gpu_owalk_step, a step at a time) on groups of 32
 * consecutive rays of a ray file, and counts per warp:
 *  - steps: iterations of the outer loop (down to a leaf, test it, pop),
 *    as many as the lane that needs most;
 *  - node iterations: per step, the most inner-node visits of any lane;
 *  - triangle iterations: per step, the most triangle tests of any lane;
 * and how many of those lane slots did useful work (SIMT efficiency). A
 * change's effect on divergence is then predicted before any device time
 * is spent: cost = a * node iterations + b * triangle iterations, with a
 * and b fitted to measured kernel times (bench/gpu_model.sh, docs/gpu.md).
 *
 * As a test (no arguments): the model's lane sums equal the traversal's
 * own counters ray by ray, a warp of 32 copies of one ray is fully
 * efficient, iterations are never fewer than the busiest lane's work, and
 * the two traversals agree on every closest hit. As a tool:
 *   test_gpu_warp SCENE RAYS [RAYS...]  (env PK_WARP_ANY=1: any hit)
 * prints the counts of the sorted (the default kernel's) and the ordered
 * traversal on the CPU's tree and the GPU's trees (leaves of at most 16 and
 * at most 4 triangles).
 */
#include "accel/accel.h"
#include "accel/bvh_gpu.h"
#include "scene/scene.h"
#include "test.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define WARP 32

typedef struct warp_counts {
    double rays;                /* traceable rays */
    double steps, node_it, tri_it; /* warp iterations (summed over warps) */
    double node_lane, tri_lane; /* lane work: inner-node visits, triangle tests */
    double warps;
} warp_counts;

enum { K_SORTED = 0, K_ORDERED = 1 };

/* One warp of up to 32 rays through kernel k; adds to *wc. */
static void model_warp(const gpu_layout *g, const pk_ray *rays, size_t n, int k, int box, bool any,
                       warp_counts *wc, pk_hit *hits)
{
    gpu_walk sw[WARP];
    gpu_owalk ow[WARP];
    static _Thread_local gpu_stack_entry sstack[WARP][GPU_STACK];
    static _Thread_local gpu_stack_entry ostack[WARP][GPU_OSTACK];
    bool active[WARP];
    int nactive = 0;
    for (size_t i = 0; i < n; i++) {
        active[i] = k == K_SORTED ? gpu_walk_init(&sw[i], &rays[i], box) : gpu_owalk_init(&ow[i], &rays[i], box);
        nactive += active[i];
    }
    wc->rays += nactive;
    wc->warps += 1;
    while (nactive > 0) {
        uint64_t max_node = 0, max_tri = 0;
        for (size_t i = 0; i < n; i++) {
            if (!active[i]) continue;
            gpu_counters c = {0, 0};
            const bool done = k == K_SORTED ? gpu_walk_step(&sw[i], sstack[i], g->nodes, g->tris, any, &c, box)
                                            : gpu_owalk_step(&ow[i], ostack[i], g->nodes, g->tris, any, &c);
            /* nodes counts the leaf too when one was reached (then tests > 0) */
            const uint64_t inner = c.nodes - (c.tests > 0 ? 1u : 0u);
            wc->node_lane += (double)inner;
            wc->tri_lane += (double)c.tests;
            if (inner > max_node) max_node = inner;
            if (c.tests > max_tri) max_tri = c.tests;
            if (done) active[i] = false, nactive--;
        }
        wc->steps += 1;
        wc->node_it += (double)max_node;
        wc->tri_it += (double)max_tri;
    }
    if (hits)
        for (size_t i = 0; i < n; i++) {
            if (k == K_SORTED) gpu_walk_hit(&sw[i], &hits[i]);
            else gpu_owalk_hit(&ow[i], &hits[i]);
            if (!gpu_ray_traceable(&rays[i])) hits[i].t = INFINITY, hits[i].prim = PK_NO_HIT, hits[i].u = hits[i].v = 0;
        }
}

static void model(const gpu_layout *g, const pk_ray *rays, size_t n, int k, int box, bool any, warp_counts *out,
                  pk_hit *hits)
{
    memset(out, 0, sizeof *out);
    const long nw = (long)((n + WARP - 1) / WARP);
    double r = 0, s = 0, ni = 0, ti = 0, nl = 0, tl = 0, w = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : r, s, ni, ti, nl, tl, w)
    for (long i = 0; i < nw; i++) {
        const size_t first = (size_t)i * WARP, cnt = n - first < WARP ? n - first : WARP;
        warp_counts c;
        memset(&c, 0, sizeof c);
        model_warp(g, rays + first, cnt, k, box, any, &c, hits ? hits + first : NULL);
        r += c.rays, s += c.steps, ni += c.node_it, ti += c.tri_it, nl += c.node_lane, tl += c.tri_lane, w += c.warps;
    }
    out->rays = r, out->steps = s, out->node_it = ni, out->tri_it = ti, out->node_lane = nl, out->tri_lane = tl;
    out->warps = w;
}

/* ---- building layouts ------------------------------------------------------- */

typedef struct tree {
    accel *cpu;
    gpu_layout g;
} tree;

static bool build(pk_context *ctx, const accel_input *in, const bvh_costs *costs, tree *t)
{
    memset(t, 0, sizeof *t);
    pk_status st = accel_bvh_create_costs(ctx, in, costs, &t->cpu);
    if (st == PK_OK) st = gpu_layout_build(ctx, &ctx->alloc, t->cpu, &t->g);
    CHECKF(st == PK_OK, "build: %s", pk_context_error(ctx));
    return st == PK_OK;
}

static void tree_free(pk_context *ctx, tree *t)
{
    gpu_layout_free(&ctx->alloc, &t->g);
    accel_destroy(t->cpu);
}

static vec3 *scene_verts(const pk_scene *s)
{
    vec3 *v = malloc((3 * s->ntris + 1) * sizeof *v);
    REQUIRE(v);
    for (size_t k = 0; k < s->ntris; k++) scene_tri_verts(s, k, &v[3 * k], &v[3 * k + 1], &v[3 * k + 2]);
    return v;
}

/* ---- the test ------------------------------------------------------------- */

static uint64_t rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
static float rng_unit(uint64_t *s) { return (float)(rng_next(s) >> 40) * 0x1p-24f; }

static void test_model(pk_context *ctx)
{
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    vec3 *verts = scene_verts(s);
    accel_input in = {verts, s->ntris, NULL, 0, 2};
    const bvh_costs costs = {4.0f, 1, 4};
    tree t;
    if (build(ctx, &in, &costs, &t)) {
        /* rays from inside the box: coherent (a pinhole grid) and incoherent */
        const size_t n = 32 * 512;
        pk_ray *rays = malloc(n * sizeof *rays);
        REQUIRE(rays);
        uint64_t seed = 7;
        for (size_t i = 0; i < n; i++) {
            pk_ray *r = &rays[i];
            r->org[0] = 0.0f, r->org[1] = 1.0f, r->org[2] = 3.0f;
            r->tmin = 0.0f, r->tmax = INFINITY;
            if (i < n / 2) {
                const float x = (float)(i % 128) / 64.0f - 1.0f, y = (float)(i / 128 % 64) / 32.0f - 1.0f;
                r->dir[0] = 0.4f * x, r->dir[1] = 0.4f * y, r->dir[2] = -1.0f;
            } else {
                r->org[0] = rng_unit(&seed) * 1.6f - 0.8f, r->org[1] = 0.1f + 1.7f * rng_unit(&seed);
                r->org[2] = rng_unit(&seed) * 1.6f - 0.8f;
                r->dir[0] = rng_unit(&seed) - 0.5f, r->dir[1] = rng_unit(&seed) - 0.5f,
                r->dir[2] = rng_unit(&seed) - 0.5f;
            }
        }
        pk_hit *h0 = malloc(n * sizeof *h0), *h1 = malloc(n * sizeof *h1);
        REQUIRE(h0 && h1);
        for (int any = 0; any < 2; any++)
            for (int k = 0; k < 2; k++) {
                warp_counts wc;
                model(&t.g, rays, n, k, GPU_TEST_WIDE, any, &wc, k ? h1 : h0);
                /* the lane sums are the traversal's own counters */
                double nodes = 0, tests = 0, leaves = 0;
                long bad = 0;
                for (size_t i = 0; i < n; i++) {
                    gpu_counters c = {0, 0};
                    pk_hit h;
                    if (k == K_SORTED)
                        gpu_trace_box(t.g.nodes, t.g.tris, &rays[i], any, &h, &c, GPU_TEST_WIDE);
                    else
                        gpu_trace_ordered(t.g.nodes, t.g.tris, &rays[i], any, &h, &c, GPU_TEST_WIDE);
                    nodes += (double)c.nodes, tests += (double)c.tests;
                    bad += memcmp(&h, k ? &h1[i] : &h0[i], sizeof h) != 0;
                    (void)leaves;
                }
                CHECKF(bad == 0, "kernel %d any %d: %ld hits of the model differ from the traversal's", k, any, bad);
                CHECKF(wc.tri_lane == tests, "kernel %d any %d: %.0f triangle tests in the model, %.0f counted", k, any,
                       wc.tri_lane, tests);
                CHECKF(wc.node_lane <= nodes && wc.node_lane >= nodes - wc.steps * WARP,
                       "kernel %d any %d: %.0f inner visits in the model, %.0f visits counted", k, any, wc.node_lane,
                       nodes);
                /* a warp iteration serves at most 32 lanes */
                CHECKF(wc.node_it * WARP >= wc.node_lane && wc.tri_it * WARP >= wc.tri_lane,
                       "kernel %d: more lane work than warp slots", k);
                CHECKF(wc.rays == (double)n && wc.warps == (double)(n / WARP), "kernel %d: %.0f rays %.0f warps", k,
                       wc.rays, wc.warps);
                printf("cornell box, %s, %s: per ray %.2f inner nodes %.2f triangles; per warp %.1f steps %.1f "
                       "node and %.1f triangle iterations; lanes busy %.0f%% / %.0f%%\n",
                       k ? "ordered" : "sorted", any ? "any hit" : "closest", wc.node_lane / wc.rays,
                       wc.tri_lane / wc.rays, wc.steps / wc.warps, wc.node_it / wc.warps, wc.tri_it / wc.warps,
                       100.0 * wc.node_lane / (WARP * wc.node_it), 100.0 * wc.tri_lane / (WARP * wc.tri_it));
            }
        /* the two traversals find the same closest hits (no exact ties here) */
        long differ = 0;
        warp_counts wc;
        model(&t.g, rays, n, K_SORTED, GPU_TEST_WIDE, false, &wc, h0);
        model(&t.g, rays, n, K_ORDERED, GPU_TEST_WIDE, false, &wc, h1);
        for (size_t i = 0; i < n; i++) differ += memcmp(&h0[i], &h1[i], sizeof *h0) != 0;
        CHECKF(differ == 0, "%ld closest hits differ between the sorted and the ordered traversal", differ);
        /* 32 copies of one ray: every lane busy in every iteration */
        pk_ray same[WARP];
        for (int i = 0; i < WARP; i++) same[i] = rays[n - 1];
        memset(&wc, 0, sizeof wc);
        for (int k = 0; k < 2; k++) {
            memset(&wc, 0, sizeof wc);
            model_warp(&t.g, same, WARP, k, GPU_TEST_WIDE, false, &wc, NULL);
            CHECKF(wc.node_lane == WARP * wc.node_it && wc.tri_lane == WARP * wc.tri_it && wc.node_it > 0,
                   "kernel %d: one ray 32 times is not fully efficient (%.0f of %.0f)", k, wc.node_lane,
                   WARP * wc.node_it);
        }
        /* one lane alone: its warp iterations are its own work */
        memset(&wc, 0, sizeof wc);
        model_warp(&t.g, same, 1, K_ORDERED, GPU_TEST_WIDE, false, &wc, NULL);
        CHECK(wc.node_it == wc.node_lane && wc.tri_it == wc.tri_lane);
        free(h0), free(h1), free(rays);
    }
    tree_free(ctx, &t);
    free(verts);
    pk_scene_destroy(s);
}

/* ---- the tool --------------------------------------------------------------- */

static int run_tool(pk_context *ctx, int argc, char **argv)
{
    pk_scene *s = NULL;
    if (pk_scene_load_file(ctx, argv[1], &s) != PK_OK) {
        fprintf(stderr, "%s\n", pk_context_error(ctx));
        return 1;
    }
    const bool any = getenv("PK_WARP_ANY") && atoi(getenv("PK_WARP_ANY"));
    vec3 *verts = scene_verts(s);
    accel_input in = {verts, s->ntris, NULL, 0, omp_get_max_threads()};
    static const struct {
        const char *name;
        bvh_costs costs;
        bool cpu;
    } trees[] = {{"cpu", {0, 0, 0}, true}, {"t4", {4.0f, 1, 16}, false}, {"t4l4", {4.0f, 1, 4}, false}};
    printf("tree kernel rays inner/ray tris/ray steps/warp nodeit/warp triit/warp node%% tri%% cost(a=1,b=1)/ray\n");
    for (int a = 2; a < argc; a++) {
        FILE *f = fopen(argv[a], "rb");
        if (!f) {
            fprintf(stderr, "%s: cannot open\n", argv[a]);
            return 1;
        }
        fseek(f, 0, SEEK_END);
        const long size = ftell(f);
        fseek(f, 0, SEEK_SET);
        const size_t n = (size_t)size / sizeof(pk_ray);
        pk_ray *rays = malloc(n * sizeof *rays + 1);
        REQUIRE(rays && fread(rays, sizeof *rays, n, f) == n);
        fclose(f);
        for (size_t ti = 0; ti < sizeof trees / sizeof *trees; ti++) {
            tree t;
            if (!build(ctx, &in, trees[ti].cpu ? NULL : &trees[ti].costs, &t)) return 1;
            for (int k = 0; k < 2; k++) {
                warp_counts wc;
                model(&t.g, rays, n, k, GPU_TEST_WIDE, any, &wc, NULL);
                printf("%s %s %s %.0f %.3f %.3f %.2f %.2f %.2f %.1f %.1f %.3f\n", argv[a], trees[ti].name,
                       k ? "ordered" : "sorted", wc.rays, wc.node_lane / wc.rays, wc.tri_lane / wc.rays,
                       wc.steps / wc.warps, wc.node_it / wc.warps, wc.tri_it / wc.warps,
                       100.0 * wc.node_lane / (WARP * wc.node_it), 100.0 * wc.tri_lane / (WARP * wc.tri_it),
                       (wc.node_it + wc.tri_it) / wc.warps / WARP);
                fflush(stdout);
            }
            tree_free(ctx, &t);
        }
        free(rays);
    }
    free(verts);
    pk_scene_destroy(s);
    return 0;
}

int main(int argc, char **argv)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    if (argc >= 3) {
        const int rc = run_tool(ctx, argc, argv);
        pk_context_destroy(ctx);
        return rc;
    }
    test_model(ctx);
    pk_context_destroy(ctx);
    return test_done("test_gpu_warp");
}

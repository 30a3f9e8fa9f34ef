/*
 * test_bvh.c - the wide SIMD BVH against brute force: invariants, closest
 * hits bit for bit, any-hit, packets, degenerate inputs and watertightness
 * on shared edges and vertices of closed meshes.
 */
#include "accel/bvh.h"
#include "scene/scene.h"
#include "test.h"
#include "test_rng.h"

#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>


/* ---- brute force: every primitive with geom.h's tests --------------------- */

typedef struct brute {
    const vec3 *verts;
    size_t ntris;
    const accel_sphere *spheres;
    size_t nspheres;
    uint8_t *skip;              /* degenerate */
    /* bounding spheres of the triangles, radius inflated, to skip most tests */
    float *cx, *cy, *cz, *r2;
    /* and of runs of CLUSTER consecutive triangles */
    float *kx, *ky, *kz, *kr2;
    uint32_t *perm;             /* triangles in Morton order, for the clusters */
    bool cull;
} brute;

static uint64_t *morton_keys;
static int cmp_morton(const void *a, const void *b)
{
    uint64_t x = morton_keys[*(const uint32_t *)a], y = morton_keys[*(const uint32_t *)b];
    return x < y ? -1 : x > y;
}
static uint64_t spread10(uint64_t x)
{
    uint64_t r = 0;
    for (int i = 0; i < 10; i++) r |= ((x >> i) & 1u) << (3 * i);
    return r;
}

enum { CLUSTER = 32 };

static void brute_init(brute *b, const accel_input *in, bool cull)
{
    memset(b, 0, sizeof *b);
    b->verts = in->verts;
    b->ntris = in->ntris;
    b->spheres = in->spheres;
    b->nspheres = in->nspheres;
    b->skip = calloc(in->ntris + 1, 1);
    b->cx = malloc((in->ntris + 8) * sizeof(float));
    b->cy = malloc((in->ntris + 8) * sizeof(float));
    b->cz = malloc((in->ntris + 8) * sizeof(float));
    b->r2 = malloc((in->ntris + 8) * sizeof(float));
    size_t nk = in->ntris / CLUSTER + 1;
    b->kx = malloc(nk * sizeof(float)), b->ky = malloc(nk * sizeof(float));
    b->kz = malloc(nk * sizeof(float)), b->kr2 = malloc(nk * sizeof(float));
    REQUIRE(b->skip && b->cx && b->cy && b->cz && b->r2 && b->kx && b->ky && b->kz && b->kr2);
    b->cull = cull;
    for (size_t i = 0; i < in->ntris; i++) {
        const vec3 *p = in->verts + 3 * i;
        b->skip[i] = bvh_tri_degenerate(p[0], p[1], p[2]) ? 1 : 0;
        vec3 c = v3_scale(v3_add(v3_add(p[0], p[1]), p[2]), 1.0f / 3.0f);
        float r = 0.0f;
        for (int k = 0; k < 3; k++) r = fmaxf(r, v3_len(v3_sub(p[k], c)));
        r = r * 1.01f + 1e-6f * (fabsf(c.x) + fabsf(c.y) + fabsf(c.z)) + 1e-12f;
        b->cx[i] = c.x, b->cy[i] = c.y, b->cz[i] = c.z, b->r2[i] = r * r;
    }
    /* clusters of triangles close in Morton order (a test-only helper, not a BVH) */
    b->perm = malloc((in->ntris + 1) * sizeof *b->perm);
    morton_keys = malloc((in->ntris + 1) * sizeof *morton_keys);
    REQUIRE(b->perm && morton_keys);
    aabb all = aabb_empty();
    for (size_t i = 0; i < in->ntris; i++)
        if (!b->skip[i]) all = aabb_grow(all, v3(b->cx[i], b->cy[i], b->cz[i]));
    vec3 ext = aabb_extent(all);
    for (size_t i = 0; i < in->ntris; i++) {
        /* one store per element: GCC 12.2 -O3 hoisted a "keys[i] = 0; ... continue;"
         * zeroing into a memset placed after this loop */
        uint64_t key = 0;
        if (!b->skip[i] && ext.x > 0 && ext.y > 0 && ext.z > 0 && v3_finite(ext)) {
            uint64_t q[3];
            float c[3] = {(b->cx[i] - all.lo.x) / ext.x, (b->cy[i] - all.lo.y) / ext.y, (b->cz[i] - all.lo.z) / ext.z};
            for (int k = 0; k < 3; k++) q[k] = (uint64_t)fminf(1023.0f, fmaxf(0.0f, c[k] * 1023.0f));
            key = spread10(q[0]) | spread10(q[1]) << 1 | spread10(q[2]) << 2;
        }
        b->perm[i] = (uint32_t)i;
        morton_keys[i] = key;
    }
    qsort(b->perm, in->ntris, sizeof *b->perm, cmp_morton);
    free(morton_keys);
    morton_keys = NULL;
    for (size_t k = 0; k * CLUSTER < in->ntris; k++) {
        size_t i0 = k * CLUSTER, i1 = i0 + CLUSTER < in->ntris ? i0 + CLUSTER : in->ntris;
        aabb box = aabb_empty();
        for (size_t j = i0; j < i1; j++) {
            uint32_t i = b->perm[j];
            if (!b->skip[i]) box = aabb_grow(box, v3(b->cx[i], b->cy[i], b->cz[i]));
        }
        vec3 c = box.lo.x <= box.hi.x ? aabb_center(box) : v3(0, 0, 0);
        float r = 0.0f;
        for (size_t j = i0; j < i1; j++) {
            uint32_t i = b->perm[j];
            if (!b->skip[i]) r = fmaxf(r, v3_len(v3_sub(v3(b->cx[i], b->cy[i], b->cz[i]), c)) + sqrtf(b->r2[i]));
        }
        r = r * 1.01f + 1e-6f * (fabsf(c.x) + fabsf(c.y) + fabsf(c.z)) + 1e-12f;
        b->kx[k] = c.x, b->ky[k] = c.y, b->kz[k] = c.z, b->kr2[k] = r * r;
    }
}

static void brute_free(brute *b)
{
    free(b->skip), free(b->cx), free(b->cy), free(b->cz), free(b->r2);
    free(b->kx), free(b->ky), free(b->kz), free(b->kr2), free(b->perm);
}

/* Does the ray's line pass within sqrt(r2dd / |d|^2) of (x, y, z)? */
static inline bool line_near(const ray *r, float x, float y, float z, float r2dd)
{
    float ox = x - r->o.x, oy = y - r->o.y, oz = z - r->o.z;
    float crx = oy * r->d.z - oz * r->d.y, cry = oz * r->d.x - ox * r->d.z, crz = ox * r->d.y - oy * r->d.x;
    return crx * crx + cry * cry + crz * crz <= r2dd;
}

typedef struct cand {
    float t;
    uint32_t k;
} cand;
static int cmp_cand(const void *a, const void *b)
{
    float x = ((const cand *)a)->t, y = ((const cand *)b)->t;
    return x < y ? -1 : x > y;
}

static bool brute_intersect(const brute *b, const ray *r, hit *h)
{
    ray_pre p = ray_prepare(r);
    h->t = r->tmax;
    h->prim = PK_NO_HIT;
    h->u = h->v = 0.0f;
    const float dd = v3_dot(r->d, r->d);
    /* clusters near the ray's line, front to back by the nearest distance
     * their bounding sphere allows; stop once that is beyond the closest hit */
    size_t nk = (b->ntris + CLUSTER - 1) / CLUSTER;
    cand *cs = malloc((nk + 1) * sizeof *cs);
    REQUIRE(cs);
    size_t nc = 0;
    for (size_t k = 0; k < nk; k++) {
        if (b->cull) {
            if (!line_near(r, b->kx[k], b->ky[k], b->kz[k], b->kr2[k] * dd)) continue;
            float tc = ((b->kx[k] - r->o.x) * r->d.x + (b->ky[k] - r->o.y) * r->d.y + (b->kz[k] - r->o.z) * r->d.z) / dd;
            float dr = sqrtf(b->kr2[k] / dd) * 1.001f;
            if (tc + dr < r->tmin) continue;
            cs[nc++] = (cand){tc - dr, (uint32_t)k};
        } else {
            cs[nc++] = (cand){-INFINITY, (uint32_t)k};
        }
    }
    if (b->cull) qsort(cs, nc, sizeof *cs, cmp_cand);
    for (size_t q = 0; q < nc; q++) {
        if (b->cull && cs[q].t > h->t) break;
        size_t k = cs[q].k;
        size_t i0 = k * CLUSTER, i1 = i0 + CLUSTER < b->ntris ? i0 + CLUSTER : b->ntris;
        for (size_t j = i0; j < i1; j++) {
            size_t i = b->perm[j];
            if (b->skip[i] || (b->cull && !line_near(r, b->cx[i], b->cy[i], b->cz[i], b->r2[i] * dd))) continue;
            const vec3 *v = b->verts + 3 * i;
            float t, u, w;
            if (tri_intersect(&p, v[0], v[1], v[2], h->t, &t, &u, &w) && hit_better(t, (uint32_t)i, h)) {
                h->t = t, h->prim = (uint32_t)i, h->u = u, h->v = w;
            }
        }
    }
    free(cs);
    for (size_t k = 0; k < b->nspheres; k++) {
        const accel_sphere *s = &b->spheres[k];
        if (!bvh_sphere_valid(s)) continue;
        float t, u, w;
        uint32_t id = (uint32_t)(b->ntris + k);
        if (sphere_intersect(&p, s->center, s->radius, h->t, &t, &u, &w) && hit_better(t, id, h)) {
            h->t = t, h->prim = id, h->u = u, h->v = w;
        }
    }
    if (h->prim == PK_NO_HIT) {
        hit_clear(h);
        return false;
    }
    return true;
}

static uint32_t fbits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

static bool same_hit(const hit *a, const hit *b)
{
    return a->prim == b->prim && fbits(a->t) == fbits(b->t) && fbits(a->u) == fbits(b->u) &&
           fbits(a->v) == fbits(b->v);
}

/* ---- checking an accelerator against brute force ---------------------------- */

static int report_budget = 12;

static void report(const char *what, const char *name, size_t i, const ray *r, const hit *got, const hit *want)
{
    if (report_budget-- <= 0) return;
    fprintf(stderr,
            "%s: %s ray %zu o=(%a %a %a) d=(%a %a %a) [%a %a]: got prim %u t %a, want prim %u t %a\n", name,
            what, i, (double)r->o.x, (double)r->o.y, (double)r->o.z, (double)r->d.x, (double)r->d.y,
            (double)r->d.z, (double)r->tmin, (double)r->tmax, got->prim, (double)got->t, want->prim,
            (double)want->t);
}

/* Closest hits, any-hit and packets of a against brute force on rays. */
static void check_rays(const accel *a, const brute *b, const ray *rays, size_t n, const char *name)
{
    hit *want = malloc(n * sizeof *want), *got = malloc(n * sizeof *got), *pk = malloc(n * sizeof *pk);
    hit *pany = malloc(n * sizeof *pany);
    REQUIRE(want && got && pk && pany);
    long bad_closest = 0, bad_any = 0, bad_count = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : bad_closest, bad_any, bad_count)
    for (long i = 0; i < (long)n; i++) {
        brute_intersect(b, &rays[i], &want[i]);
        bool hit1 = a->ops->intersect(a, &rays[i], &got[i], NULL);
        if (hit1 != (want[i].prim != PK_NO_HIT) || !same_hit(&got[i], &want[i])) bad_closest++;
        bool occ = a->ops->occluded(a, &rays[i], NULL, NULL);
        if (occ != hit1) bad_any++;
        accel_counters c = {0, 0};
        hit h2;
        bool hit2 = a->ops->intersect(a, &rays[i], &h2, &c);
        if (hit2 != hit1 || !same_hit(&h2, &got[i]) || c.nodes == 0) bad_count++;
    }
    for (size_t i = 0; i < n && bad_closest; i++)
        if (!same_hit(&got[i], &want[i])) report("closest", name, i, &rays[i], &got[i], &want[i]);
    CHECKF(bad_closest == 0, "%s: %ld of %zu closest hits differ from brute force", name, bad_closest, n);
    CHECKF(bad_any == 0, "%s: %ld of %zu occlusion answers differ from closest hit", name, bad_any, n);
    CHECKF(bad_count == 0, "%s: %ld of %zu counted traversals differ", name, bad_count, n);

    /* packets, in runs of various lengths */
    size_t runs[] = {1, 3, 8, 16, 37, 64, 256};
    for (size_t off = 0, k = 0; off < n; k++) {
        size_t m = runs[k % (sizeof runs / sizeof *runs)];
        if (m > n - off) m = n - off;
        a->ops->intersect_packet(a, rays + off, pk + off, m, false, NULL);
        a->ops->intersect_packet(a, rays + off, pany + off, m, true, NULL);
        off += m;
    }
    long bad_pk = 0, bad_pany = 0;
    for (size_t i = 0; i < n; i++) {
        if (!same_hit(&pk[i], &got[i])) {
            if (bad_pk == 0) report("packet", name, i, &rays[i], &pk[i], &got[i]);
            bad_pk++;
        }
        bool occ = pany[i].prim != PK_NO_HIT;
        if (occ != (got[i].prim != PK_NO_HIT) || (occ && !(pany[i].t >= rays[i].tmin && pany[i].t <= rays[i].tmax)))
            bad_pany++;
    }
    CHECKF(bad_pk == 0, "%s: %ld of %zu packet hits differ from single rays", name, bad_pk, n);
    CHECKF(bad_pany == 0, "%s: %ld of %zu packet occlusion answers differ", name, bad_pany, n);
    free(want), free(got), free(pk), free(pany);
}

/* Random rays around box: origins in the box grown by 20%, random directions,
 * some with zero components, some aimed at vertices, edges and interiors of
 * triangles, some with a finite tmax or a tmin > 0. */
static ray *make_rays(rng *g, aabb box, const accel_input *in, size_t n)
{
    ray *rays = malloc(n * sizeof *rays);
    REQUIRE(rays);
    vec3 ext = aabb_extent(box);
    aabb big = {v3_sub(box.lo, v3_scale(ext, 0.2f)), v3_add(box.hi, v3_scale(ext, 0.2f))};
    for (size_t i = 0; i < n; i++) {
        ray r;
        r.o = v3(rng_range(g, big.lo.x, big.hi.x), rng_range(g, big.lo.y, big.hi.y), rng_range(g, big.lo.z, big.hi.z));
        r.tmin = 0.0f;
        r.tmax = INFINITY;
        uint32_t kind = rng_u32(g) % 10;
        if (kind < 4 && in->ntris) {
            /* aim at a vertex, an edge point or an interior point */
            const vec3 *p = in->verts + 3 * (rng_u32(g) % in->ntris);
            vec3 target;
            uint32_t w = rng_u32(g) % 3;
            if (w == 0) target = p[rng_u32(g) % 3];
            else if (w == 1) target = v3_lerp(p[0], p[1], rng_f(g));
            else {
                float u = rng_f(g), v = rng_f(g);
                if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
                target = v3_add(p[0], v3_add(v3_scale(v3_sub(p[1], p[0]), u), v3_scale(v3_sub(p[2], p[0]), v)));
            }
            r.d = v3_sub(target, r.o);
            if (!(v3_len2(r.d) > 0.0f)) r.d = rng_dir(g);
        } else {
            r.d = rng_dir(g);
            if (kind == 4) {
                /* one or two zero components, or a pure axis direction */
                uint32_t z = rng_u32(g) % 7;
                if (z & 1) r.d.x = 0.0f;
                if (z & 2) r.d.y = 0.0f;
                if (z & 4) r.d.z = 0.0f;
                if (!(v3_len2(r.d) > 0.0f)) r.d = v3(0.0f, -1.0f, 0.0f);
                if (rng_u32(g) & 1) {
                    /* and start exactly on a vertex's plane */
                    if (in->ntris) {
                        const vec3 *p = in->verts + 3 * (rng_u32(g) % in->ntris);
                        r.o.x = p[0].x;
                    }
                }
            } else if (kind == 5) {
                r.d = v3_scale(r.d, rng_range(g, 0.01f, 100.0f)); /* not unit length */
            }
        }
        if (kind == 6) {
            r.tmax = rng_range(g, 0.0f, 2.0f);
        } else if (kind == 7) {
            r.tmin = rng_range(g, 0.0f, 0.5f);
        }
        rays[i] = r;
    }
    return rays;
}

/* Shadow rays: groups of 32 from one origin (inside the box grown by 20 %,
 * or on a triangle) toward vertices, edge points and interior points of
 * triangles, stopping short of the target or not, so that the packets of
 * rays sharing their origin meet the watertight test's edge cases. */
static ray *shadow_rays(rng *g, aabb box, const accel_input *in, size_t n)
{
    ray *rays = malloc(n * sizeof *rays);
    REQUIRE(rays);
    vec3 ext = aabb_extent(box);
    aabb big = {v3_sub(box.lo, v3_scale(ext, 0.2f)), v3_add(box.hi, v3_scale(ext, 0.2f))};
    vec3 o = box.lo;
    for (size_t i = 0; i < n; i++) {
        if (i % 32 == 0) {
            if (in->ntris && (rng_u32(g) & 1)) {
                const vec3 *p = in->verts + 3 * (rng_u32(g) % in->ntris);
                o = v3_lerp(v3_lerp(p[0], p[1], rng_f(g)), p[2], 0.5f * rng_f(g));
            } else {
                o = v3(rng_range(g, big.lo.x, big.hi.x), rng_range(g, big.lo.y, big.hi.y),
                       rng_range(g, big.lo.z, big.hi.z));
            }
        }
        vec3 target = v3(rng_range(g, big.lo.x, big.hi.x), rng_range(g, big.lo.y, big.hi.y),
                         rng_range(g, big.lo.z, big.hi.z));
        if (in->ntris) {
            const vec3 *p = in->verts + 3 * (rng_u32(g) % in->ntris);
            uint32_t w = rng_u32(g) % 3;
            target = w == 0 ? p[rng_u32(g) % 3] : w == 1 ? v3_lerp(p[0], p[1], rng_f(g))
                                                       : v3_lerp(v3_lerp(p[0], p[1], rng_f(g)), p[2], 0.5f);
        }
        ray r = {o, 0.0f, v3_sub(target, o), (rng_u32(g) & 1) ? 1.0f - 1e-3f : INFINITY};
        if (!(v3_len2(r.d) > 0.0f)) r.d = rng_dir(g);
        rays[i] = r;
    }
    return rays;
}

/* Camera rays of a w x w image in 4x4 tiles (coherent, for the packets). */
static ray *camera_rays(aabb box, int w, size_t *n_out)
{
    vec3 c = aabb_center(box), ext = aabb_extent(box);
    float size = fmaxf(ext.x, fmaxf(ext.y, ext.z));
    vec3 from = v3_add(c, v3(0.1f * size, 0.2f * size, 1.6f * size));
    vec3 wv = v3_norm(v3_sub(from, c));
    vec3 u = v3_norm(v3_cross(v3(0, 1, 0), wv));
    vec3 v = v3_cross(wv, u);
    ray *rays = malloc((size_t)w * (size_t)w * sizeof *rays);
    REQUIRE(rays);
    size_t k = 0;
    for (int ty = 0; ty < w; ty += 4)
        for (int tx = 0; tx < w; tx += 4)
            for (int y = ty; y < ty + 4; y++)
                for (int x = tx; x < tx + 4; x++) {
                    float px = ((float)x + 0.5f) / (float)w * 2.0f - 1.0f;
                    float py = 1.0f - ((float)y + 0.5f) / (float)w * 2.0f;
                    ray r;
                    r.o = from;
                    r.d = v3_norm(v3_sub(v3_add(v3_scale(u, px * 0.45f), v3_scale(v, py * 0.45f)), wv));
                    r.tmin = 0.0f;
                    r.tmax = INFINITY;
                    rays[k++] = r;
                }
    *n_out = k;
    return rays;
}

static accel *build(pk_context *ctx, const accel_input *in, const char *name)
{
    accel *a = NULL;
    pk_status st = accel_bvh_create(ctx, in, &a);
    CHECKF(st == PK_OK, "%s: build failed: %s", name, pk_context_error(ctx));
    REQUIRE(a);
    char why[256];
    CHECKF(bvh_check(a, why, sizeof why), "%s: bvh_check: %s", name, why);
    size_t valid = 0;
    for (size_t i = 0; i < in->ntris; i++)
        if (!bvh_tri_degenerate(in->verts[3 * i], in->verts[3 * i + 1], in->verts[3 * i + 2])) valid++;
    for (size_t i = 0; i < in->nspheres; i++) valid += bvh_sphere_valid(&in->spheres[i]);
    CHECKF(a->info.primitives == valid, "%s: %zu primitives in the tree, %zu valid", name, a->info.primitives, valid);
    CHECK(strcmp(a->info.name, "bvh") == 0);
    CHECK(a->info.nodes >= 1 && a->info.bytes > 0);
    /* the kernels this run tests: AVX-512 where the CPU has them, unless the
     * config says cpu.isa=avx2 (main passes PAPRSEK_CPU_ISA=avx2 on as that:
     * ctest runs this file both ways, test_bvh_avx2) */
    char cfg[512];
    pk_context_get_config(ctx, cfg, sizeof cfg);
    const bool forced = strstr(cfg, "cpu.isa=avx2") != NULL;
    CHECKF(a->isa && strcmp(a->isa, bvh_use_avx512(ctx) ? "avx512" : "avx2") == 0, "%s: kernels %s", name,
           a->isa ? a->isa : "(none)");
    CHECK(!forced || strcmp(a->isa, "avx2") == 0);
    return a;
}

/* Primitive references in all leaves (more than primitives after spatial splits). */
static size_t leaf_refs(const accel *a)
{
    const bvh *t = (const bvh *)a;
    size_t n = 0;
    for (size_t i = 0; i < t->nnodes; i++)
        for (int k = 0; k < BVH_WIDTH; k++) {
            uint32_t ref = t->nodes[i].child[k];
            if (ref == BVH_EMPTY || !bvh_is_leaf(ref) || (ref & BVH_SPHERE_LEAF)) continue;
            const bvh_tri_block *b = (const bvh_tri_block *)((const char *)t->tris + bvh_ref_offset(ref));
            for (uint32_t q = 0; q < bvh_leaf_blocks(ref); q++) n += bvh_tri_block_count(b + q);
        }
    return n;
}

static aabb input_bounds(const accel_input *in)
{
    aabb b = aabb_empty();
    for (size_t i = 0; i < 3 * in->ntris; i++)
        if (v3_finite(in->verts[i])) b = aabb_grow(b, in->verts[i]);
    for (size_t i = 0; i < in->nspheres; i++) {
        b = aabb_grow(b, v3_sub(in->spheres[i].center, v3s(in->spheres[i].radius)));
        b = aabb_grow(b, v3_add(in->spheres[i].center, v3s(in->spheres[i].radius)));
    }
    if (!(b.lo.x <= b.hi.x)) b = (aabb){{-1, -1, -1}, {1, 1, 1}};
    return b;
}

/* Builds over in and checks nrays random rays (and camera rays) against brute force. */
static void check_input(pk_context *ctx, const accel_input *in, size_t nrays, bool cull, uint64_t seed,
                        const char *name)
{
    double t0 = omp_get_wtime();
    accel *a = build(ctx, in, name);
    brute b;
    brute_init(&b, in, cull);
    rng g = {seed};
    aabb box = input_bounds(in);
    ray *rays = make_rays(&g, box, in, nrays);
    check_rays(a, &b, rays, nrays, name);
    free(rays);
    ray *shadow = shadow_rays(&g, box, in, nrays / 4 + 32);
    check_rays(a, &b, shadow, nrays / 4 + 32, name);
    free(shadow);
    size_t nc;
    ray *cam = camera_rays(box, 64, &nc);
    check_rays(a, &b, cam, nc, name);
    free(cam);
    brute_free(&b);
    accel_destroy(a);
    if (getenv("TEST_BVH_TIMES")) printf("%-40s %.2f s\n", name, omp_get_wtime() - t0);
}

/* ---- scenes from files ------------------------------------------------------- */

static void check_file(pk_context *ctx, const char *rel, size_t nrays)
{
    char path[1024];
    shared_path(path, sizeof path, rel);
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
    accel_sphere *sph = malloc((s->nspheres + 1) * sizeof *sph);
    REQUIRE(sph);
    for (size_t i = 0; i < s->nspheres; i++) sph[i] = (accel_sphere){s->spheres[i].center, s->spheres[i].radius};
    accel_input in = {verts, s->ntris, sph, s->nspheres, 2};
    double t0 = omp_get_wtime();
    check_input(ctx, &in, nrays, true, 0x9e3779b97f4a7c15ull ^ s->ntris, rel);
    printf("%-40s %7zu tris  %.2f s\n", rel, s->ntris, omp_get_wtime() - t0);

    /* the public path: pk_accel_create + pk_accel_trace, plain and coherent */
    pk_accel *pa = NULL;
    st = pk_accel_create(ctx, s, PK_ACCEL_BVH, 2, &pa);
    CHECKF(st == PK_OK, "%s: pk_accel_create: %s", rel, pk_context_error(ctx));
    if (pa) {
        pk_accel_info info;
        pk_accel_get_info(pa, &info);
        CHECK(strcmp(info.name, "bvh") == 0);
        const char *isa = pk_accel_isa(pa);
        CHECK(isa && strcmp(isa, bvh_use_avx512(ctx) ? "avx512" : "avx2") == 0);
        size_t nc;
        ray *cam = camera_rays(input_bounds(&in), 32, &nc);
        pk_hit *h1 = malloc(nc * sizeof *h1), *h2 = malloc(nc * sizeof *h2);
        REQUIRE(h1 && h2);
        pk_trace_counters cnt = {0, 0};
        pk_accel_trace(pa, (const pk_ray *)cam, h1, nc, 2, 0, &cnt);
        pk_accel_trace(pa, (const pk_ray *)cam, h2, nc, 2, PK_TRACE_COHERENT, NULL);
        size_t bad = 0;
        for (size_t i = 0; i < nc; i++) bad += !same_hit((const hit *)&h1[i], (const hit *)&h2[i]);
        CHECKF(bad == 0, "%s: %zu coherent hits differ", rel, bad);
        CHECK(cnt.nodes_visited > 0 && cnt.intersection_tests > 0);
        free(h1), free(h2), free(cam);
        pk_accel_destroy(pa);
    }
    /* an accelerator without a choice of kernels has no ISA to report */
    st = pk_accel_create(ctx, s, PK_ACCEL_NONE, 1, &pa);
    CHECK(st == PK_OK && pa && pk_accel_isa(pa) == NULL);
    pk_accel_destroy(pa);
    free(verts);
    free(sph);
    pk_scene_destroy(s);
}

/* ---- synthetic inputs ------------------------------------------------------------ */

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

/* Cube [-1,1]^3, each face an n x n grid of quads split in two; shuffled so
 * that neighbours end up far apart in the numbering. */
static void make_cube(mesh *m, int n, rng *g)
{
    for (int axis = 0; axis < 3; axis++)
        for (int side = -1; side <= 1; side += 2)
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    float p[4][3];
                    float u0 = -1.0f + 2.0f * (float)i / (float)n, u1 = -1.0f + 2.0f * (float)(i + 1) / (float)n;
                    float v0 = -1.0f + 2.0f * (float)j / (float)n, v1 = -1.0f + 2.0f * (float)(j + 1) / (float)n;
                    float uu[4] = {u0, u1, u1, u0}, vv[4] = {v0, v0, v1, v1};
                    for (int k = 0; k < 4; k++) {
                        p[k][axis] = (float)side;
                        p[k][(axis + 1) % 3] = uu[k];
                        p[k][(axis + 2) % 3] = vv[k];
                    }
                    vec3 q[4];
                    for (int k = 0; k < 4; k++) q[k] = v3(p[k][0], p[k][1], p[k][2]);
                    if ((i + j) & 1) {
                        mesh_tri(m, q[0], q[1], q[2]);
                        mesh_tri(m, q[0], q[2], q[3]);
                    } else {
                        mesh_tri(m, q[0], q[1], q[3]);
                        mesh_tri(m, q[1], q[2], q[3]);
                    }
                }
    for (size_t i = m->ntris; i > 1; i--) {
        size_t j = rng_u32(g) % i;
        for (int k = 0; k < 3; k++) {
            vec3 t = m->v[3 * (i - 1) + (size_t)k];
            m->v[3 * (i - 1) + (size_t)k] = m->v[3 * j + (size_t)k];
            m->v[3 * j + (size_t)k] = t;
        }
    }
}

/* Icosphere: an icosahedron subdivided levels times, vertices on the unit sphere
 * (shared vertices are bit-identical because each is computed once). */
static void make_icosphere(mesh *m, int levels)
{
    const float t = (1.0f + sqrtf(5.0f)) / 2.0f;
    vec3 *pts = malloc(12 * sizeof *pts);
    size_t npts = 12;
    vec3 base[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                     {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (int i = 0; i < 12; i++) pts[i] = v3_norm(base[i]);
    int faces0[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                         {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                         {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    size_t nf = 20;
    int (*f)[3] = malloc(nf * sizeof *f);
    memcpy(f, faces0, sizeof faces0);
    for (int l = 0; l < levels; l++) {
        int (*nfc)[3] = malloc(nf * 4 * sizeof *nfc);
        /* midpoint cache: a simple map from the edge (i, j) to a vertex */
        size_t cap = nf * 3;
        int64_t *keys = malloc(cap * 2 * sizeof *keys);
        int *vals = malloc(cap * 2 * sizeof *vals);
        for (size_t i = 0; i < cap * 2; i++) keys[i] = -1;
        pts = realloc(pts, (npts + nf * 3) * sizeof *pts);
        for (size_t k = 0; k < nf; k++) {
            int mid[3];
            for (int e = 0; e < 3; e++) {
                int a = f[k][e], b = f[k][(e + 1) % 3];
                int64_t key = a < b ? (int64_t)a * 1000000 + b : (int64_t)b * 1000000 + a;
                size_t hsh = (size_t)(key * 2654435761u) % (cap * 2);
                while (keys[hsh] != -1 && keys[hsh] != key) hsh = (hsh + 1) % (cap * 2);
                if (keys[hsh] == -1) {
                    keys[hsh] = key;
                    vals[hsh] = (int)npts;
                    pts[npts++] = v3_norm(v3_scale(v3_add(pts[a], pts[b]), 0.5f));
                }
                mid[e] = vals[hsh];
            }
            int a = f[k][0], b = f[k][1], c = f[k][2];
            int nn[4][3] = {{a, mid[0], mid[2]}, {b, mid[1], mid[0]}, {c, mid[2], mid[1]}, {mid[0], mid[1], mid[2]}};
            memcpy(nfc[4 * k], nn, sizeof nn);
        }
        free(keys), free(vals), free(f);
        f = nfc;
        nf *= 4;
    }
    for (size_t k = 0; k < nf; k++) mesh_tri(m, pts[f[k][0]], pts[f[k][1]], pts[f[k][2]]);
    free(pts), free(f);
}

/* Rays from inside points aimed exactly at every vertex and at points of
 * shared edges: the closed mesh must never be missed. */
static void check_watertight(pk_context *ctx, const mesh *m, const char *name, float oscale, rng *g)
{
    accel_input in = {m->v, m->ntris, NULL, 0, 2};
    accel *a = build(ctx, &in, name);
    brute b;
    brute_init(&b, &in, true);
    vec3 origins[5] = {{0, 0, 0}, {0.3f, -0.2f, 0.1f}, {-0.55f, 0.41f, -0.23f}, {0.7f, 0.7f, 0.7f},
                       {1.0f / 3.0f, 0.1f, -0.9f}};
    size_t nr = 5 * m->ntris * 4;
    ray *rays = malloc(nr * sizeof *rays);
    REQUIRE(rays);
    size_t k = 0;
    for (int o = 0; o < 5; o++)
        for (size_t i = 0; i < m->ntris; i++) {
            const vec3 *p = m->v + 3 * i;
            vec3 tg[4] = {p[0], v3_scale(v3_add(p[0], p[1]), 0.5f), v3_lerp(p[1], p[2], rng_f(g)),
                          v3_lerp(p[2], p[0], 0.25f)};
            for (int q = 0; q < 4; q++) {
                vec3 org = v3_scale(origins[o], oscale);
                ray r = {org, 0.0f, v3_sub(tg[q], org), INFINITY};
                rays[k++] = r;
            }
        }
    long misses = 0, bad = 0;
#pragma omp parallel for reduction(+ : misses, bad)
    for (long i = 0; i < (long)nr; i++) {
        hit h, w;
        if (!a->ops->intersect(a, &rays[i], &h, NULL)) misses++;
        if (!a->ops->occluded(a, &rays[i], NULL, NULL)) misses++;
        brute_intersect(&b, &rays[i], &w);
        if (!same_hit(&h, &w)) bad++;
    }
    CHECKF(misses == 0, "%s: %ld of %zu rays at shared edges and vertices escaped", name, misses, nr);
    CHECKF(bad == 0, "%s: %ld of %zu edge rays differ from brute force", name, bad, nr);
    /* the same rays as packets */
    hit *ph = malloc(nr * sizeof *ph);
    REQUIRE(ph);
    for (size_t off = 0; off < nr; off += 16)
        a->ops->intersect_packet(a, rays + off, ph + off, nr - off < 16 ? nr - off : 16, false, NULL);
    long pmiss = 0;
    for (size_t i = 0; i < nr; i++) pmiss += ph[i].prim == PK_NO_HIT;
    CHECKF(pmiss == 0, "%s: %ld packet rays escaped", name, pmiss);
    free(ph);
    free(rays);
    brute_free(&b);
    accel_destroy(a);
}

static void check_synthetic(pk_context *ctx)
{
    rng g = {12345};
    mesh m = {0};

    /* nothing at all: builds, always misses */
    {
        accel_input in = {NULL, 0, NULL, 0, 2};
        accel *a = build(ctx, &in, "empty");
        ray r = {{0, 0, 0}, 0.0f, {1, 0, 0}, INFINITY};
        hit h;
        CHECK(!a->ops->intersect(a, &r, &h, NULL) && h.prim == PK_NO_HIT && isinf(h.t));
        CHECK(!a->ops->occluded(a, &r, NULL, NULL));
        a->ops->intersect_packet(a, &r, &h, 1, false, NULL);
        CHECK(h.prim == PK_NO_HIT);
        CHECK(a->info.leaves == 0 && a->info.primitives == 0);
        accel_destroy(a);
    }
    /* one triangle */
    mesh_tri(&m, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0));
    {
        accel_input in = {m.v, 1, NULL, 0, 2};
        check_input(ctx, &in, 20000, false, 1, "one triangle");
    }
    /* only degenerate triangles: all at one point, collinear, NaN */
    m.ntris = 0;
    for (int i = 0; i < 50; i++) mesh_tri(&m, v3(1, 2, 3), v3(1, 2, 3), v3(1, 2, 3));
    mesh_tri(&m, v3(0, 0, 0), v3(1, 1, 1), v3(2, 2, 2));
    mesh_tri(&m, v3(0, 0, 0), v3(NAN, 1, 1), v3(2, 0, 2));
    mesh_tri(&m, v3(0, 0, 0), v3(INFINITY, 1, 1), v3(2, 0, 2));
    {
        accel_input in = {m.v, m.ntris, NULL, 0, 2};
        accel *a = build(ctx, &in, "degenerate only");
        CHECK(a->info.primitives == 0);
        accel_destroy(a);
    }
    /* 300 copies of one small triangle (one centroid: no SAH split exists)
     * plus the degenerate ones: ties go to the lowest prim */
    for (int i = 0; i < 300; i++) mesh_tri(&m, v3(0.9f, 2, 3), v3(1.1f, 2, 3), v3(1, 2.1f, 3.05f));
    {
        accel_input in = {m.v, m.ntris, NULL, 0, 2};
        check_input(ctx, &in, 20000, false, 2, "one point");
    }
    /* a random soup with triangles and spheres mixed */
    m.ntris = 0;
    for (int i = 0; i < 3000; i++) {
        vec3 c = v3(rng_range(&g, -5, 5), rng_range(&g, -5, 5), rng_range(&g, -5, 5));
        float s = rng_range(&g, 0.01f, 1.0f);
        mesh_tri(&m, c, v3_add(c, v3_scale(rng_dir(&g), s)), v3_add(c, v3_scale(rng_dir(&g), s)));
    }
    accel_sphere sph[200];
    for (int i = 0; i < 200; i++)
        sph[i] = (accel_sphere){v3(rng_range(&g, -5, 5), rng_range(&g, -5, 5), rng_range(&g, -5, 5)),
                                rng_range(&g, 0.01f, 0.6f)};
    {
        accel_input in = {m.v, m.ntris, sph, 200, 2};
        check_input(ctx, &in, 100000, true, 3, "soup + spheres");
        accel_input in2 = {NULL, 0, sph, 200, 1};
        check_input(ctx, &in2, 20000, false, 4, "spheres only");
    }
    /* rays with a non-finite origin or a NaN direction or interval hit
     * nothing, by every entry point (the render fuzz corpus holds the scene
     * where such a ray once reached an empty child slot and crashed) */
    {
        accel_input in = {m.v, 60, sph, 5, 2};
        accel *a = build(ctx, &in, "non-finite rays");
        const float bad[] = {NAN, INFINITY, -INFINITY};
        int hits = 0;
        for (int k = 0; k < 3; k++)
            for (int w = 0; w < 7; w++) {
                ray r = {v3(0.1f, 0.2f, 0.3f), 0.0f, v3(0.3f, -0.5f, 0.8f), INFINITY};
                float *f = w < 3 ? &r.o.x + w : w < 6 ? &r.d.x + (w - 3) : &r.tmax;
                if (w >= 3 && k > 0 && w < 6) continue; /* infinite directions are legitimate */
                if (w == 6 && k > 0) continue;          /* tmax = inf is the usual case */
                *f = bad[k];
                hit h;
                accel_counters c = {0, 0};
                hits += a->ops->intersect(a, &r, &h, NULL) + a->ops->intersect(a, &r, &h, &c);
                hits += a->ops->occluded(a, &r, NULL, NULL);
                a->ops->intersect_packet(a, &r, &h, 1, false, NULL);
                hits += h.prim != PK_NO_HIT;
            }
        CHECKF(hits == 0, "non-finite rays: %d hits", hits);
        accel_destroy(a);
    }
    /* long slivers crossing the scene in every direction: spatial splits cut
     * them into pieces held by several leaves */
    {
        mesh sl = {0};
        for (int i = 0; i < 2000; i++) {
            vec3 a = v3(rng_range(&g, -5, 5), rng_range(&g, -5, 5), rng_range(&g, -5, 5));
            vec3 b = v3_add(a, v3_scale(rng_dir(&g), rng_range(&g, 2.0f, 8.0f)));
            vec3 c = v3_add(v3_lerp(a, b, rng_f(&g)), v3_scale(rng_dir(&g), 0.05f));
            mesh_tri(&sl, a, b, c);
        }
        for (int i = 0; i < 2000; i++) {
            vec3 c = v3(rng_range(&g, -5, 5), rng_range(&g, -5, 5), rng_range(&g, -5, 5));
            mesh_tri(&sl, c, v3_add(c, v3(0.1f, 0, 0)), v3_add(c, v3(0, 0.1f, 0.05f)));
        }
        accel_input in = {sl.v, sl.ntris, NULL, 0, 2};
        accel *a = build(ctx, &in, "slivers");
        /* bvh.quality=fast (main passes PAPRSEK_BVH_QUALITY=fast on as
         * that) builds without spatial splits */
        char cfg[512];
        pk_context_get_config(ctx, cfg, sizeof cfg);
        if (!strstr(cfg, "bvh.quality=fast"))
            CHECKF(leaf_refs(a) > a->info.primitives, "slivers: no spatial split (%zu references, %zu primitives)",
                   leaf_refs(a), a->info.primitives);
        accel_destroy(a);
        check_input(ctx, &in, 50000, true, 7, "slivers");
        free(sl.v);
    }
    /* huge and tiny coordinates */
    {
        mesh big = {0}, tiny = {0};
        for (size_t i = 0; i < 3 * m.ntris; i += 3) {
            mesh_tri(&big, v3_scale(m.v[i], 1e30f), v3_scale(m.v[i + 1], 1e30f), v3_scale(m.v[i + 2], 1e30f));
            mesh_tri(&tiny, v3_scale(m.v[i], 1e-30f), v3_scale(m.v[i + 1], 1e-30f), v3_scale(m.v[i + 2], 1e-30f));
        }
        accel_input in = {big.v, big.ntris, NULL, 0, 2};
        check_input(ctx, &in, 8000, false, 5, "huge (1e30)");
        accel_input in2 = {tiny.v, tiny.ntris, NULL, 0, 2};
        check_input(ctx, &in2, 8000, false, 6, "tiny (1e-30)");
        free(big.v), free(tiny.v);
    }
    /* coordinates near 1e24 mixed with denormal ones: nodes whose box is
     * only denormals thick on one axis (1/extent overflows to inf) must not
     * bin a reference lying on the box's face at 0 * inf = NaN (found by
     * fuzzing; UndefinedBehaviorSanitizer fails the sanitize build there) */
    {
        const float thin[] = {0.0f, 0x1p-149f, 1.2e-45f, 1e-40f, 1.179435e-38f, -1e-45f};
        const int nthin = (int)(sizeof thin / sizeof thin[0]);
        mesh mix = {0};
        for (int i = 0; i < 1500; i++) {
            /* long slivers in an almost flat slab: overlapping children, so spatial splits are tried */
            vec3 a = v3(rng_range(&g, -5, 5), rng_range(&g, -5, 5), thin[rng_u32(&g) % (unsigned)nthin]);
            vec3 b = v3(a.x + rng_range(&g, -6, 6), a.y + rng_range(&g, -6, 6), thin[rng_u32(&g) % (unsigned)nthin]);
            vec3 c = v3(0.5f * (a.x + b.x) + rng_range(&g, -0.1f, 0.1f), 0.5f * (a.y + b.y) + rng_range(&g, -0.1f, 0.1f),
                        thin[rng_u32(&g) % (unsigned)nthin]);
            mesh_tri(&mix, a, b, c);
        }
        accel_input flat = {mix.v, mix.ntris, NULL, 0, 2};
        {
            /* Two families of rays, each against brute force: rays from z = +-1
             * through random points of the slab, and rays lying in the slab whose
             * z direction is denormal (1/d overflows: the slab test must not
             * take it as infinite). Rays that start inside the slab with a
             * normal z direction are left out: their hits lie denormals away,
             * below the resolution of the triangle test's arithmetic, which
             * then disagrees with exact geometry by design. */
            accel *a = build(ctx, &flat, "denormal-thin slab");
            brute br;
            brute_init(&br, &flat, false);
            enum { NR = 20000 };
            ray *rays = malloc(NR * sizeof *rays);
            REQUIRE(rays);
            for (int i = 0; i < NR; i++) {
                vec3 target = v3(rng_range(&g, -6, 6), rng_range(&g, -6, 6), thin[rng_u32(&g) % (unsigned)nthin]);
                if (i % 2 == 0) {
                    vec3 o = v3(rng_range(&g, -8, 8), rng_range(&g, -8, 8), (rng_u32(&g) & 1) ? 1.0f : -1.0f);
                    rays[i] = (ray){o, 0.0f, v3_sub(target, o), INFINITY};
                } else {
                    vec3 o = v3(rng_range(&g, -8, 8), rng_range(&g, -8, 8), thin[rng_u32(&g) % (unsigned)nthin]);
                    vec3 d = v3_sub(target, o);
                    d.z = (rng_u32(&g) & 1 ? 1.0f : -1.0f) * thin[1 + rng_u32(&g) % (unsigned)(nthin - 1)];
                    rays[i] = (ray){o, 0.0f, d, INFINITY};
                }
            }
            check_rays(a, &br, rays, NR, "denormal-thin slab");
            free(rays);
            brute_free(&br);
            accel_destroy(a);
        }
        for (int i = 0; i < 600; i++) {
            /* the same shapes scaled to 1e24 in x and y, some far off in z */
            vec3 a = v3(rng_range(&g, -1e24f, 1e24f), rng_range(&g, -1e24f, 1e24f), thin[rng_u32(&g) % (unsigned)nthin]);
            vec3 b = v3(a.x + rng_range(&g, -1e24f, 1e24f), a.y + 1e-40f, (i % 7 == 0) ? 1.2345e24f : thin[i % nthin]);
            vec3 c = v3(a.x + 1e-45f, a.y + rng_range(&g, -1e24f, 1e24f), thin[rng_u32(&g) % (unsigned)nthin]);
            mesh_tri(&mix, a, b, c);
        }
        accel_input both = {mix.v, mix.ntris, NULL, 0, 2};
        check_input(ctx, &both, 20000, false, 9, "1e24 mixed with denormals");
        free(mix.v);
    }
    /* axis-parallel rays through an axis-aligned grid of quads, some lying in the planes */
    {
        mesh cube = {0};
        make_cube(&cube, 8, &g);
        accel_input in = {cube.v, cube.ntris, NULL, 0, 2};
        accel *a = build(ctx, &in, "axis rays");
        brute b;
        brute_init(&b, &in, false);
        enum { N = 20000 };
        ray *rays = malloc(N * sizeof *rays);
        REQUIRE(rays);
        const float grid[] = {-1.0f, -0.75f, -0.5f, 0.0f, 0.25f, 1.0f, -1.5f, 1.5f};
        for (int i = 0; i < N; i++) {
            vec3 o;
            float *oc = &o.x;
            for (int k = 0; k < 3; k++)
                oc[k] = (rng_u32(&g) & 1) ? grid[rng_u32(&g) % 8] : rng_range(&g, -1.5f, 1.5f);
            vec3 d = v3(0, 0, 0);
            float *dc = &d.x;
            dc[rng_u32(&g) % 3] = (rng_u32(&g) & 1) ? 1.0f : -1.0f;
            if (i % 5 == 0) dc[rng_u32(&g) % 3] = -0.0f;
            rays[i] = (ray){o, 0.0f, d, INFINITY};
        }
        check_rays(a, &b, rays, N, "axis rays");
        free(rays);
        brute_free(&b);
        accel_destroy(a);
        free(cube.v);
    }
    free(m.v);

    /* watertightness */
    {
        mesh cube = {0};
        make_cube(&cube, 16, &g);
        check_watertight(ctx, &cube, "cube 16x16", 1.0f, &g);
        free(cube.v);
        mesh ico = {0};
        make_icosphere(&ico, 4);
        check_watertight(ctx, &ico, "icosphere", 0.75f, &g);
        free(ico.v);
    }
}

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    /* the test program (not the library) reads the old switches and passes
     * them on as config */
    const char *env = getenv("PAPRSEK_CPU_ISA");
    const char *q = getenv("PAPRSEK_BVH_QUALITY");
    if (env && strcmp(env, "avx2") == 0) REQUIRE(pk_context_set_config(ctx, "cpu.isa=avx2") == PK_OK);
    if (q && strcmp(q, "fast") == 0) REQUIRE(pk_context_set_config(ctx, "bvh.quality=fast") == PK_OK);
    printf("BVH kernels: %s%s\n", bvh_use_avx512(ctx) ? "avx512" : "avx2",
           bvh_use_avx512(ctx) || (env && strcmp(env, "avx2") == 0)
               ? ""
               : " (this CPU or build has no AVX-512 kernels: only the AVX2 ones are tested)");
    double t0 = omp_get_wtime();
    check_synthetic(ctx);
    printf("synthetic cases: %.2f s\n", omp_get_wtime() - t0);
    const char *cornell[] = {"CornellBox-Empty-CO.obj", "CornellBox-Empty-RG.obj", "CornellBox-Empty-Squashed.obj",
                             "CornellBox-Empty-White.obj", "CornellBox-Glossy.obj", "CornellBox-Mirror.obj",
                             "CornellBox-Original.obj", "CornellBox-Sphere.obj", "CornellBox-Water.obj",
                             "water.obj"};
    for (size_t i = 0; i < sizeof cornell / sizeof *cornell; i++) {
        char rel[256];
        snprintf(rel, sizeof rel, "scenes/cornell/%s", cornell[i]);
        check_file(ctx, rel, 100000);
    }
    check_file(ctx, "scenes/bench/stanford-bunny.obj", 100000);
    check_file(ctx, "scenes/bench/dabrovic-sponza/sponza.obj", 100000);
    pk_context_destroy(ctx);
    return test_done("test_bvh");
}

/*
 * bvh.h - the fast acceleration structure (--accel bvh), private to
 * bvh_build.c, bvh_traverse.c, bvh_packet.c and bvh_check.c.
 *
 * A binned-SAH binary BVH is built in parallel and collapsed into a
 * BVH_WIDTH-wide tree whose nodes keep their children's boxes as SoA float
 * arrays; leaves are SoA blocks of BVH_TRI_LANES triangles (raw vertices, so
 * the SIMD test can repeat geom.h's watertight test operation for operation)
 * or of spheres. See docs/bvh.md for the measurements behind the choices.
 */
#ifndef PK_BVH_H
#define PK_BVH_H

#include "accel.h"

#ifndef BVH_WIDTH
#define BVH_WIDTH 8          /* children per node: 8 (AVX) or 4 (SSE) */
#endif
#define BVH_TRI_LANES 4      /* triangles per SoA block (one SSE test) */
#define BVH_LEAF_MAX 4       /* primitives per leaf of the binary build */
#define BVH_SPHERE_LANES 4
#define BVH_MAX_DEPTH 96     /* wide levels; the builder stays below it */
#define BVH_STACK_SIZE (BVH_MAX_DEPTH * (BVH_WIDTH - 1) + 1)

/* Child references (uint32):
 *   bit 31 clear: an inner node, the index into bvh.nodes;
 *   bit 31 set:   a leaf: bit 30 = sphere leaf, bits 27..29 = blocks - 1,
 *                 bits 0..26 = first block in bvh.tris (or bvh.spheres);
 *   BVH_EMPTY:    an unused slot (its box is empty: lo = +inf, hi = -inf). */
#define BVH_LEAF 0x80000000u
#define BVH_SPHERE_LEAF 0x40000000u
#define BVH_EMPTY 0xFFFFFFFFu
#define BVH_BLOCK_BITS 27
#define BVH_BLOCK_MASK ((1u << BVH_BLOCK_BITS) - 1u)
#define BVH_MAX_LEAF_BLOCKS 8u

static inline bool bvh_is_leaf(uint32_t ref) { return (ref & BVH_LEAF) != 0; }
static inline uint32_t bvh_leaf_first(uint32_t ref) { return ref & BVH_BLOCK_MASK; }
static inline uint32_t bvh_leaf_blocks(uint32_t ref) { return ((ref >> BVH_BLOCK_BITS) & 7u) + 1u; }
static inline uint32_t bvh_leaf_ref(bool sphere, uint32_t first, uint32_t blocks)
{
    return BVH_LEAF | (sphere ? BVH_SPHERE_LEAF : 0u) | ((blocks - 1u) << BVH_BLOCK_BITS) | first;
}

/* Box planes in the order lo_x, hi_x, lo_y, hi_y, lo_z, hi_z, so that a
 * ray's near plane on an axis is b[2*axis + (d < 0)] and the far one the other. */
enum { BVH_LO_X, BVH_HI_X, BVH_LO_Y, BVH_HI_Y, BVH_LO_Z, BVH_HI_Z };

typedef struct bvh_node {
    float b[6][BVH_WIDTH];      /* children's boxes, world space, SoA */
    uint32_t child[BVH_WIDTH];  /* references as above */
} bvh_node;

/* Up to BVH_TRI_LANES triangles; unused lanes hold NaN vertices and
 * prim = PK_NO_HIT. Lanes are sorted by prim (ascending). */
typedef struct bvh_tri_block {
    float v[3][3][BVH_TRI_LANES];   /* [vertex a,b,c][axis x,y,z][lane], world space */
    uint32_t prim[BVH_TRI_LANES];
} bvh_tri_block;

typedef struct bvh_sphere_block {
    float c[3][BVH_SPHERE_LANES];   /* centre [axis][lane], world space */
    float r[BVH_SPHERE_LANES];      /* radius; unused lanes: NaN */
    uint32_t prim[BVH_SPHERE_LANES];
} bvh_sphere_block;

/* Invariants (bvh_check tests them):
 *  1. nodes[0] is the root and an inner node; every other node is the child
 *     of exactly one slot, and child indices are greater than the parent's
 *     (no cycles); the tree is at most BVH_MAX_DEPTH levels deep (so the
 *     traversal stack, BVH_STACK_SIZE entries, cannot overflow).
 *  2. A slot's box contains the boxes in its child node, and a leaf slot's
 *     box contains every vertex (sphere box) of its primitives; empty slots
 *     have empty boxes (lo = +inf, hi = -inf) and reference BVH_EMPTY.
 *  3. A leaf holds 1..BVH_LEAF_MAX primitives of one kind in
 *     1..BVH_MAX_LEAF_BLOCKS consecutive blocks; every block but the last is
 *     full; used lanes come first, sorted by prim, the rest are padding (NaN,
 *     PK_NO_HIT).
 *  4. Every primitive that can be hit is in exactly one leaf; no degenerate
 *     triangle (non-finite vertex or zero area) is in any; triangle ids are
 *     < ntris, sphere ids in [ntris, ntris + nspheres). info.primitives
 *     counts them.
 *  5. Every block is referenced by exactly one leaf. */
typedef struct bvh {
    accel base;
    bvh_node *nodes;            /* 64-byte aligned */
    size_t nnodes;
    bvh_tri_block *tris;        /* 64-byte aligned */
    size_t ntri_blocks;
    bvh_sphere_block *spheres;
    size_t nsphere_blocks;
    aabb bounds;                /* of everything that can be hit */
    int depth;                  /* levels of the wide tree (root = 1) */
} bvh;

/* Traversal entry points (bvh_traverse.c, bvh_packet.c). */
PK_HIDDEN bool bvh_intersect(const accel *a, const ray *r, hit *h, accel_counters *c);
PK_HIDDEN bool bvh_occluded(const accel *a, const ray *r, accel_counters *c);
/* Occlusion that also reports the hit it found (t, prim; cleared on a miss). */
PK_HIDDEN bool bvh_any_hit(const accel *a, const ray *r, hit *h, accel_counters *c);
PK_HIDDEN void bvh_intersect_packet(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                                    accel_counters *c);

/* Tests the invariants above; false with a reason in why (may be NULL). */
PK_HIDDEN bool bvh_check(const accel *a, char *why, size_t n);

/* Triangles that can never be hit (same rule as scene.h's tri_is_degenerate). */
static inline bool bvh_tri_degenerate(vec3 a, vec3 b, vec3 c)
{
    if (!v3_finite(a) || !v3_finite(b) || !v3_finite(c)) return true;
    vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    return !(v3_len2(n) > 0.0f) || !v3_finite(n);
}

/* Spheres the structure holds: finite centre, finite radius > 0. */
static inline bool bvh_sphere_valid(const accel_sphere *s)
{
    return v3_finite(s->center) && isfinite(s->radius) && s->radius > 0.0f &&
           v3_finite(v3_add(s->center, v3s(s->radius))) && v3_finite(v3_sub(s->center, v3s(s->radius)));
}

/* ---- per-ray kernels shared by the single-ray and packet traversals ---- */

#include <immintrin.h>

/* The box test visits a slot when tnear <= tfar + |tfar| * BVH_BOX_SLACK,
 * where tfar already includes the current closest t: the slack (16 ulps)
 * covers the rounding of the slab distances and of the triangle's t, so a
 * box that holds a hit at the current distance is never skipped (ties go to
 * the lower prim, so equal distances must still be visited). */
#define BVH_BOX_SLACK 0x1p-20f

typedef struct bvh_ray {
    ray_pre pre;            /* geom.h's shear constants, for the exact tests */
    float org[3];           /* origin, world space */
    float rd[3];            /* 1/d per axis: +-inf for zero components */
    int near[3], far[3];    /* box plane rows: 2*axis + (rd < 0), and the other */
    int kx, ky, kz;         /* shear axes (rows of bvh_tri_block.v[vertex]) */
    float ox, oy, oz;       /* origin components along kx, ky, kz */
    float tmin;
} bvh_ray;

static inline void bvh_ray_init(bvh_ray *br, const ray *r)
{
    br->pre = ray_prepare(r);
    const float o[3] = {r->o.x, r->o.y, r->o.z};
    const float rd[3] = {br->pre.inv_d.x, br->pre.inv_d.y, br->pre.inv_d.z};
    for (int k = 0; k < 3; k++) {
        br->org[k] = o[k];
        br->rd[k] = rd[k];
        int neg = signbit(rd[k]) ? 1 : 0;
        br->near[k] = 2 * k + neg;
        br->far[k] = 2 * k + 1 - neg;
    }
    br->kx = br->pre.kx;
    br->ky = br->pre.ky;
    br->kz = br->pre.kz;
    br->ox = o[br->kx];
    br->oy = o[br->ky];
    br->oz = o[br->kz];
    br->tmin = r->tmin;
}

/* Lanes of one triangle block that pass tri_intersect with limit tmax:
 * the same float operations in the same order as geom.h, four triangles at
 * a time (no FMA: the build has -ffp-contract=off and no fused intrinsics
 * are used here). Returns the lane mask; *t, *rcp, *V, *W hold the lanes. */
static inline int bvh_tri4(const bvh_tri_block *blk, const bvh_ray *r, float tmax, __m128 *t_out,
                           __m128 *rcp_out, __m128 *V_out, __m128 *W_out)
{
    const __m128 ox = _mm_set1_ps(r->ox), oy = _mm_set1_ps(r->oy), oz = _mm_set1_ps(r->oz);
    const __m128 sx = _mm_set1_ps(r->pre.sx), sy = _mm_set1_ps(r->pre.sy);
    const __m128 ax0 = _mm_sub_ps(_mm_load_ps(blk->v[0][r->kx]), ox);
    const __m128 ay0 = _mm_sub_ps(_mm_load_ps(blk->v[0][r->ky]), oy);
    const __m128 az0 = _mm_sub_ps(_mm_load_ps(blk->v[0][r->kz]), oz);
    const __m128 bx0 = _mm_sub_ps(_mm_load_ps(blk->v[1][r->kx]), ox);
    const __m128 by0 = _mm_sub_ps(_mm_load_ps(blk->v[1][r->ky]), oy);
    const __m128 bz0 = _mm_sub_ps(_mm_load_ps(blk->v[1][r->kz]), oz);
    const __m128 cx0 = _mm_sub_ps(_mm_load_ps(blk->v[2][r->kx]), ox);
    const __m128 cy0 = _mm_sub_ps(_mm_load_ps(blk->v[2][r->ky]), oy);
    const __m128 cz0 = _mm_sub_ps(_mm_load_ps(blk->v[2][r->kz]), oz);
    const __m128 ax = _mm_sub_ps(ax0, _mm_mul_ps(sx, az0)), ay = _mm_sub_ps(ay0, _mm_mul_ps(sy, az0));
    const __m128 bx = _mm_sub_ps(bx0, _mm_mul_ps(sx, bz0)), by = _mm_sub_ps(by0, _mm_mul_ps(sy, bz0));
    const __m128 cx = _mm_sub_ps(cx0, _mm_mul_ps(sx, cz0)), cy = _mm_sub_ps(cy0, _mm_mul_ps(sy, cz0));
    __m128 U = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
    __m128 V = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
    __m128 W = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
    const __m128 zero = _mm_setzero_ps();
    int zm = _mm_movemask_ps(_mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(U, zero), _mm_cmpeq_ps(V, zero)),
                                       _mm_cmpeq_ps(W, zero)));
    if (PK_UNLIKELY(zm)) {
        /* an edge function is exactly 0: recompute that lane in double */
        float fax[4], fay[4], fbx[4], fby[4], fcx[4], fcy[4], fu[4], fv[4], fw[4];
        _mm_storeu_ps(fax, ax), _mm_storeu_ps(fay, ay), _mm_storeu_ps(fbx, bx);
        _mm_storeu_ps(fby, by), _mm_storeu_ps(fcx, cx), _mm_storeu_ps(fcy, cy);
        _mm_storeu_ps(fu, U), _mm_storeu_ps(fv, V), _mm_storeu_ps(fw, W);
        for (int l = 0; l < 4; l++) {
            if (!(zm >> l & 1)) continue;
            fu[l] = (float)((double)fcx[l] * (double)fby[l] - (double)fcy[l] * (double)fbx[l]);
            fv[l] = (float)((double)fax[l] * (double)fcy[l] - (double)fay[l] * (double)fcx[l]);
            fw[l] = (float)((double)fbx[l] * (double)fay[l] - (double)fby[l] * (double)fax[l]);
        }
        U = _mm_loadu_ps(fu), V = _mm_loadu_ps(fv), W = _mm_loadu_ps(fw);
    }
    const __m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, zero), _mm_cmplt_ps(V, zero)), _mm_cmplt_ps(W, zero));
    const __m128 pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_cmpgt_ps(V, zero)), _mm_cmpgt_ps(W, zero));
    const __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
    int m = ~_mm_movemask_ps(_mm_or_ps(_mm_and_ps(neg, pos), _mm_cmpeq_ps(det, zero))) & 15;
    if (!m) return 0;
    const __m128 sz = _mm_set1_ps(r->pre.sz);
    const __m128 az = _mm_mul_ps(sz, az0), bz = _mm_mul_ps(sz, bz0), cz = _mm_mul_ps(sz, cz0);
    const __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, az), _mm_mul_ps(V, bz)), _mm_mul_ps(W, cz));
    const __m128 rcp = _mm_div_ps(_mm_set1_ps(1.0f), det);
    const __m128 t = _mm_mul_ps(T, rcp);
    m &= _mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(t, _mm_set1_ps(r->tmin)), _mm_cmple_ps(t, _mm_set1_ps(tmax))));
    *t_out = t;
    *rcp_out = rcp;
    *V_out = V;
    *W_out = W;
    return m;
}

/* Closest-hit update from one triangle block; true when *h changed. */
static inline bool bvh_tri4_closest(const bvh_tri_block *blk, const bvh_ray *r, hit *h)
{
    __m128 t, rcp, V, W;
    int m = bvh_tri4(blk, r, h->t, &t, &rcp, &V, &W);
    if (!m) return false;
    float ft[4];
    _mm_storeu_ps(ft, t);
    /* lanes are sorted by prim: the first lane with the smallest t wins */
    int best = __builtin_ctz((unsigned)m);
    for (int mm = m & (m - 1); mm; mm &= mm - 1) {
        int l = __builtin_ctz((unsigned)mm);
        if (ft[l] < ft[best]) best = l;
    }
    const uint32_t prim = blk->prim[best];
    if (!hit_better(ft[best], prim, h)) return false;
    float fr[4], fv[4], fw[4];
    _mm_storeu_ps(fr, rcp);
    _mm_storeu_ps(fv, V);
    _mm_storeu_ps(fw, W);
    h->t = ft[best];
    h->prim = prim;
    h->u = fv[best] * fr[best];
    h->v = fw[best] * fr[best];
    return true;
}

static inline bool bvh_sphere_block_closest(const bvh_sphere_block *blk, const bvh_ray *r, hit *h)
{
    bool any = false;
    for (int l = 0; l < BVH_SPHERE_LANES && blk->prim[l] != PK_NO_HIT; l++) {
        float t, u, v;
        vec3 c = v3(blk->c[0][l], blk->c[1][l], blk->c[2][l]);
        if (sphere_intersect(&r->pre, c, blk->r[l], h->t, &t, &u, &v) && hit_better(t, blk->prim[l], h)) {
            h->t = t;
            h->prim = blk->prim[l];
            h->u = u;
            h->v = v;
            any = true;
        }
    }
    return any;
}

/* Primitives in a leaf block (for the counters). */
static inline uint32_t bvh_tri_block_count(const bvh_tri_block *blk)
{
    uint32_t n = 0;
    for (int l = 0; l < BVH_TRI_LANES; l++) n += blk->prim[l] != PK_NO_HIT;
    return n;
}
static inline uint32_t bvh_sphere_block_count(const bvh_sphere_block *blk)
{
    uint32_t n = 0;
    for (int l = 0; l < BVH_SPHERE_LANES; l++) n += blk->prim[l] != PK_NO_HIT;
    return n;
}

#endif

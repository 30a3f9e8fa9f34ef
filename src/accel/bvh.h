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
#include "../math/tri.h"

#ifndef BVH_WIDTH
#define BVH_WIDTH 8          /* children per node: 8 (AVX) or 4 (SSE) */
#endif
#ifndef BVH_TRI_LANES
#define BVH_TRI_LANES 8      /* triangles per SoA block: 4 (SSE test) or 8 (AVX) */
#endif
#ifndef BVH_LEAF_MAX
#define BVH_LEAF_MAX 16      /* primitives per leaf (up to BVH_MAX_LEAF_BLOCKS blocks) */
#endif
#define BVH_SPHERE_LANES 4
#define BVH_MAX_DEPTH 96     /* wide levels; the builder stays below it */
#define BVH_STACK_SIZE (BVH_MAX_DEPTH * (BVH_WIDTH - 1) + 1)

/* Child references (uint32), byte offsets so that traversal needs one add:
 *   bit 0 clear: an inner node at byte offset ref from bvh.nodes;
 *   bit 0 set:   a leaf: bits 1..3 = blocks - 1, bit 4 = sphere leaf, and
 *                ref & ~31 = byte offset of its first block from bvh.tris
 *                (bvh.spheres); every node and block size is a multiple of 32;
 *   BVH_EMPTY:   an unused slot (its box is empty: lo = +inf, hi = -inf). */
#define BVH_LEAF 1u
#define BVH_SPHERE_LEAF 16u
#define BVH_EMPTY 0xFFFFFFFFu
#define BVH_MAX_LEAF_BLOCKS 8u

static inline bool bvh_is_leaf(uint32_t ref) { return (ref & BVH_LEAF) != 0; }
static inline size_t bvh_ref_offset(uint32_t ref) { return ref & ~(uint32_t)31; }
static inline uint32_t bvh_leaf_blocks(uint32_t ref) { return ((ref >> 1) & 7u) + 1u; }

/* Box planes in the order lo_x, hi_x, lo_y, hi_y, lo_z, hi_z, so that a
 * ray's near plane on an axis is b[2*axis + (d < 0)] and the far one the other. */
enum { BVH_LO_X, BVH_HI_X, BVH_LO_Y, BVH_HI_Y, BVH_LO_Z, BVH_HI_Z };

typedef struct bvh_node {
    float b[6][BVH_WIDTH];      /* children's boxes, world space, SoA */
    uint32_t child[BVH_WIDTH];  /* references as above */
#if BVH_WIDTH == 4
    uint32_t pad[4];            /* to a multiple of 32 bytes */
#endif
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
    uint32_t pad[4];                /* to a multiple of 32 bytes */
} bvh_sphere_block;

_Static_assert(sizeof(bvh_node) % 32 == 0 && sizeof(bvh_tri_block) % 32 == 0 &&
                   sizeof(bvh_sphere_block) % 32 == 0, "32-byte multiples: refs keep flags in the low bits");

static inline uint32_t bvh_node_ref(size_t index) { return (uint32_t)(index * sizeof(bvh_node)); }
static inline size_t bvh_node_index(uint32_t ref) { return ref / sizeof(bvh_node); }
static inline uint32_t bvh_leaf_ref(bool is_sphere, size_t first, uint32_t blocks)
{
    size_t off = first * (is_sphere ? sizeof(bvh_sphere_block) : sizeof(bvh_tri_block));
    return (uint32_t)off | (is_sphere ? BVH_SPHERE_LEAF : 0u) | ((blocks - 1u) << 1) | BVH_LEAF;
}
/* Index of the leaf's first block in bvh.tris or bvh.spheres. */
static inline size_t bvh_leaf_first(uint32_t ref)
{
    return bvh_ref_offset(ref) / ((ref & BVH_SPHERE_LEAF) ? sizeof(bvh_sphere_block) : sizeof(bvh_tri_block));
}

/* Invariants (bvh_check tests them):
 *  1. nodes[0] is the root and an inner node; every other node is the child
 *     of exactly one slot, and children come after their parent in memory
 *     (no cycles); the tree is at most BVH_MAX_DEPTH levels deep (so the
 *     traversal stack, BVH_STACK_SIZE entries, cannot overflow).
 *  2. A slot's box contains the boxes in its child node. A leaf slot's box
 *     overlaps the box of each of its primitives, and every corner of a
 *     primitive (vertex of a triangle, box corner of a sphere) lies in the
 *     box of at least one leaf holding it: spatial splits cut a primitive
 *     into pieces whose leaves' boxes together cover it. Empty slots have
 *     empty boxes (lo = +inf, hi = -inf) and reference BVH_EMPTY.
 *  3. A leaf holds 1..BVH_LEAF_MAX primitives of one kind in
 *     1..BVH_MAX_LEAF_BLOCKS consecutive blocks; every block but the last is
 *     full; used lanes come first, strictly increasing by prim, the rest are
 *     padding (NaN, PK_NO_HIT).
 *  4. Every primitive that can be hit is in at least one leaf (in several
 *     when spatial splits cut it); no degenerate triangle (non-finite vertex
 *     or zero area) is in any; triangle ids are < ntris, sphere ids in
 *     [ntris, ntris + nspheres). info.primitives counts them.
 *  5. Every block is referenced by exactly one leaf. */
typedef struct bvh {
    accel base;
    void *mem;                  /* the one block holding nodes, tris, spheres */
    size_t mem_bytes;           /* bytes of it in use */
    bvh_node *nodes;            /* 64-byte aligned */
    size_t nnodes;
    bvh_tri_block *tris;        /* 64-byte aligned */
    size_t ntri_blocks;
    bvh_sphere_block *spheres;
    size_t nsphere_blocks;
    aabb bounds;                /* of everything that can be hit */
    int depth;                  /* levels of the wide tree (root = 1) */
} bvh;

/* Traversal entry points (bvh_traverse.c, bvh_packet.c). Those files are
 * compiled twice: for the baseline (AVX2, x86-64-v3) and, where the compiler
 * can (PK_HAVE_AVX512_KERNELS), for AVX-512 (x86-64-v4) through
 * bvh_traverse_avx512.c and bvh_packet_avx512.c, which define BVH_AVX512
 * and so name their functions with BVH_FN's suffix. The same source and the
 * same float operations (no fused multiply-adds) give the same hits; only
 * the compiler's register allocation and instruction choice differ (32
 * vector registers and mask registers: fewer spills and moves). The
 * accelerator picks its set when it is built (bvh_use_avx512). */
#ifdef BVH_AVX512
#define BVH_FN(name) name##_avx512
#else
#define BVH_FN(name) name
#endif
PK_HIDDEN bool bvh_intersect(const accel *a, const ray *r, hit *h, accel_counters *c);
PK_HIDDEN bool bvh_occluded(const accel *a, const ray *r, hit *h, accel_counters *c);
PK_HIDDEN void bvh_intersect_packet(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                                    accel_counters *c);
#if PK_HAVE_AVX512_KERNELS
PK_HIDDEN bool bvh_intersect_avx512(const accel *a, const ray *r, hit *h, accel_counters *c);
PK_HIDDEN bool bvh_occluded_avx512(const accel *a, const ray *r, hit *h, accel_counters *c);
PK_HIDDEN void bvh_intersect_packet_avx512(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                                           accel_counters *c);
#endif
/* True when accelerators built now through ctx use the AVX-512 kernels:
 * they are built in, the CPU and the operating system support AVX-512 F,
 * CD, BW, DQ and VL, and ctx's config does not say cpu.isa=avx2 (which
 * forces the baseline, for comparisons; ctx NULL: the default). */
PK_HIDDEN bool bvh_use_avx512(const pk_context *ctx);

/* Tests the invariants above; false with a reason in why (may be NULL). */
PK_HIDDEN bool bvh_check(const accel *a, char *why, size_t n);

/* Triangles that can never be hit: scene.h's rule (non-finite vertex or zero
 * area), shared with the other accelerators. */
static inline bool bvh_tri_degenerate(vec3 a, vec3 b, vec3 c) { return tri_is_degenerate(a, b, c); }

/* Spheres the structure holds (prim_bounds' rule): finite centre, finite radius > 0. */
static inline bool bvh_sphere_valid(const accel_sphere *s)
{
    return v3_finite(s->center) && isfinite(s->radius) && s->radius > 0.0f;
}

/* ---- per-ray kernels shared by the single-ray and packet traversals ---- */

#include <immintrin.h>

/* The box test must never skip a box that holds the closest hit (ties go
 * to the lower prim, so boxes entered at exactly the current distance must
 * still be visited). Far distances are computed with 1/d scaled up by
 * 1 + BVH_BOX_SLACK and the current closest t is raised by the same
 * relative amount (16 ulps): that covers the rounding of the slab distances
 * (a few ulps, as in Ize's robust BVH traversal) and of the triangle's t. */
#define BVH_BOX_SLACK 0x1p-20f

static inline float bvh_cull_limit(float t) { return t + fabsf(t) * BVH_BOX_SLACK; }

/* SIMD vectors as wide as a triangle block. */
#if BVH_TRI_LANES == 8
typedef __m256 tvec;
#define TV_LOAD _mm256_load_ps
#define TV_LOADU _mm256_loadu_ps
#define TV_STOREU _mm256_storeu_ps
#define TV_SET1 _mm256_set1_ps
#define TV_ZERO _mm256_setzero_ps
#define TV_ADD _mm256_add_ps
#define TV_SUB _mm256_sub_ps
#define TV_MIN _mm256_min_ps
#define TV_MAX _mm256_max_ps
#define TV_MUL _mm256_mul_ps
#define TV_DIV _mm256_div_ps
#define TV_OR _mm256_or_ps
#define TV_AND _mm256_and_ps
#define TV_EQ(a, b) _mm256_cmp_ps(a, b, _CMP_EQ_OQ)
#define TV_LT(a, b) _mm256_cmp_ps(a, b, _CMP_LT_OQ)
#define TV_GT(a, b) _mm256_cmp_ps(a, b, _CMP_GT_OQ)
#define TV_LE(a, b) _mm256_cmp_ps(a, b, _CMP_LE_OQ)
#define TV_GE(a, b) _mm256_cmp_ps(a, b, _CMP_GE_OQ)
#define TV_MASK _mm256_movemask_ps
#elif BVH_TRI_LANES == 4
typedef __m128 tvec;
#define TV_LOAD _mm_load_ps
#define TV_LOADU _mm_loadu_ps
#define TV_STOREU _mm_storeu_ps
#define TV_SET1 _mm_set1_ps
#define TV_ZERO _mm_setzero_ps
#define TV_ADD _mm_add_ps
#define TV_SUB _mm_sub_ps
#define TV_MIN _mm_min_ps
#define TV_MAX _mm_max_ps
#define TV_MUL _mm_mul_ps
#define TV_DIV _mm_div_ps
#define TV_OR _mm_or_ps
#define TV_AND _mm_and_ps
#define TV_EQ _mm_cmpeq_ps
#define TV_LT _mm_cmplt_ps
#define TV_GT _mm_cmpgt_ps
#define TV_LE _mm_cmple_ps
#define TV_GE _mm_cmpge_ps
#define TV_MASK _mm_movemask_ps
#else
#error "BVH_TRI_LANES must be 4 or 8"
#endif
#define BVH_TRI_ALL ((1 << BVH_TRI_LANES) - 1)

/* What the triangle test needs of a ray: tri_intersect's constants. */
typedef struct bvh_tri_ray {
    float ox, oy, oz;          /* origin components along kx, ky, kz */
    float sx, sy, sz;          /* shear constants (ray_prepare's) */
    float tmin;
    uint32_t rowx, rowy, rowz; /* byte offsets of rows kx, ky, kz of a vertex in a block */
} bvh_tri_ray;

typedef struct bvh_ray {
    ray_pre pre;            /* geom.h's, for the sphere test and the box test's 1/d */
    bvh_tri_ray tri;
} bvh_ray;

/* Written component by component (no arrays of three floats: the compiler
 * would store them in pieces and reload them whole, which stalls store
 * forwarding at the start of every ray). */
static inline void bvh_ray_init(bvh_ray *br, const ray *r)
{
    br->pre = ray_prepare(r);
    bvh_tri_ray *t = &br->tri;
    const int kx = br->pre.kx, ky = br->pre.ky, kz = br->pre.kz;
    t->ox = v3_get(r->o, kx), t->oy = v3_get(r->o, ky), t->oz = v3_get(r->o, kz);
    t->sx = br->pre.sx, t->sy = br->pre.sy, t->sz = br->pre.sz;
    t->tmin = r->tmin;
    const uint32_t row = sizeof(float) * BVH_TRI_LANES;
    t->rowx = (uint32_t)kx * row, t->rowy = (uint32_t)ky * row, t->rowz = (uint32_t)kz * row;
}

/* Lanes in zm have an edge function that is exactly 0: recompute U, V, W
 * of those lanes in double, as tri_intersect does. */
static __attribute__((noinline, cold)) void bvh_tri_recompute(int zm, tvec ax, tvec ay, tvec bx, tvec by, tvec cx,
                                                            tvec cy, tvec *U, tvec *V, tvec *W)
{
    float fax[BVH_TRI_LANES], fay[BVH_TRI_LANES], fbx[BVH_TRI_LANES], fby[BVH_TRI_LANES];
    float fcx[BVH_TRI_LANES], fcy[BVH_TRI_LANES], fu[BVH_TRI_LANES], fv[BVH_TRI_LANES], fw[BVH_TRI_LANES];
    TV_STOREU(fax, ax), TV_STOREU(fay, ay), TV_STOREU(fbx, bx), TV_STOREU(fby, by);
    TV_STOREU(fcx, cx), TV_STOREU(fcy, cy), TV_STOREU(fu, *U), TV_STOREU(fv, *V), TV_STOREU(fw, *W);
    for (int l = 0; l < BVH_TRI_LANES; l++) {
        if (!(zm >> l & 1)) continue;
        fu[l] = (float)((double)fcx[l] * (double)fby[l] - (double)fcy[l] * (double)fbx[l]);
        fv[l] = (float)((double)fax[l] * (double)fcy[l] - (double)fay[l] * (double)fcx[l]);
        fw[l] = (float)((double)fbx[l] * (double)fay[l] - (double)fby[l] * (double)fax[l]);
    }
    *U = TV_LOADU(fu), *V = TV_LOADU(fv), *W = TV_LOADU(fw);
}

/* A vertex row of the block less the ray's origin component o; rel: the
 * block holds vertices already less the origin (bvh_tri_block_rel), so the
 * row is the difference. */
#define BVH_TRI_ROW(base, row, o, rel) \
    ((rel) ? TV_LOAD((const float *)((base) + (row))) : TV_SUB(TV_LOAD((const float *)((base) + (row))), (o)))

static inline __attribute__((always_inline)) int bvh_tri_test_x(const bvh_tri_block *blk, const bvh_tri_ray *r,
                                                                float tmax, tvec *t_out, tvec *rcp_out,
                                                                tvec *V_out, tvec *W_out, const bool rel)
{
    const char *va = (const char *)blk->v[0], *vb = (const char *)blk->v[1], *vc = (const char *)blk->v[2];
    const tvec ox = TV_SET1(r->ox), oy = TV_SET1(r->oy);
    const tvec sx = TV_SET1(r->sx), sy = TV_SET1(r->sy);
    tvec ax, ay, bx, by, cx, cy;
    {
        const tvec oz = TV_SET1(r->oz);
        const tvec az0 = BVH_TRI_ROW(va, r->rowz, oz, rel);
        ax = TV_SUB(BVH_TRI_ROW(va, r->rowx, ox, rel), TV_MUL(sx, az0));
        ay = TV_SUB(BVH_TRI_ROW(va, r->rowy, oy, rel), TV_MUL(sy, az0));
        const tvec bz0 = BVH_TRI_ROW(vb, r->rowz, oz, rel);
        bx = TV_SUB(BVH_TRI_ROW(vb, r->rowx, ox, rel), TV_MUL(sx, bz0));
        by = TV_SUB(BVH_TRI_ROW(vb, r->rowy, oy, rel), TV_MUL(sy, bz0));
        const tvec cz0 = BVH_TRI_ROW(vc, r->rowz, oz, rel);
        cx = TV_SUB(BVH_TRI_ROW(vc, r->rowx, ox, rel), TV_MUL(sx, cz0));
        cy = TV_SUB(BVH_TRI_ROW(vc, r->rowy, oy, rel), TV_MUL(sy, cz0));
    }
    tvec U = TV_SUB(TV_MUL(cx, by), TV_MUL(cy, bx));
    tvec V = TV_SUB(TV_MUL(ax, cy), TV_MUL(ay, cx));
    tvec W = TV_SUB(TV_MUL(bx, ay), TV_MUL(by, ax));
    const tvec zero = TV_ZERO();
    const int zm = TV_MASK(TV_OR(TV_OR(TV_EQ(U, zero), TV_EQ(V, zero)), TV_EQ(W, zero)));
    if (PK_UNLIKELY(zm)) {
        /* copies, so that only they have their address taken: U, V and W
         * can then stay in registers on the common path */
        tvec u = U, v = V, w = W;
        bvh_tri_recompute(zm, ax, ay, bx, by, cx, cy, &u, &v, &w);
        U = u, V = v, W = w;
    }
    /* reject mixed signs; a lane with a NaN edge function fails below
     * anyway (det and t are NaN), so min/max may drop NaNs here */
    const tvec neg = TV_LT(TV_MIN(TV_MIN(U, V), W), zero);
    const tvec pos = TV_GT(TV_MAX(TV_MAX(U, V), W), zero);
    const tvec det = TV_ADD(TV_ADD(U, V), W);
    int m = ~TV_MASK(TV_OR(TV_AND(neg, pos), TV_EQ(det, zero))) & BVH_TRI_ALL;
    if (!m) return 0;
    /* the z differences again (recomputed rather than kept: fewer live registers) */
    const tvec oz = TV_SET1(r->oz), sz = TV_SET1(r->sz);
    const tvec az = TV_MUL(sz, BVH_TRI_ROW(va, r->rowz, oz, rel));
    const tvec bz = TV_MUL(sz, BVH_TRI_ROW(vb, r->rowz, oz, rel));
    const tvec cz = TV_MUL(sz, BVH_TRI_ROW(vc, r->rowz, oz, rel));
    const tvec T = TV_ADD(TV_ADD(TV_MUL(U, az), TV_MUL(V, bz)), TV_MUL(W, cz));
    const tvec rcp = TV_DIV(TV_SET1(1.0f), det);
    const tvec t = TV_MUL(T, rcp);
    /* t in [tmin, tmax] and finite (an overflowed t is no hit) */
    m &= TV_MASK(TV_AND(TV_AND(TV_GE(t, TV_SET1(r->tmin)), TV_LE(t, TV_SET1(tmax))), TV_LT(t, TV_SET1(INFINITY))));
    *t_out = t;
    *rcp_out = rcp;
    *V_out = V;
    *W_out = W;
    return m;
}

/* Closest-hit update from one triangle block; true when *h changed. rel:
 * blk's vertices are relative to the ray's origin (bvh_tri_block_rel). */
static inline __attribute__((always_inline)) bool bvh_tri_closest_x(const bvh_tri_block *blk, const bvh_tri_ray *r,
                                                                    hit *h, const bool rel)
{
    tvec t, rcp, V, W;
    int m = bvh_tri_test_x(blk, r, h->t, &t, &rcp, &V, &W, rel);
    if (!m) return false;
    float ft[BVH_TRI_LANES];
    TV_STOREU(ft, t);
    /* lanes are sorted by prim: the first lane with the smallest t wins */
    int best = __builtin_ctz((unsigned)m);
    for (int mm = m & (m - 1); mm; mm &= mm - 1) {
        int l = __builtin_ctz((unsigned)mm);
        if (ft[l] < ft[best]) best = l;
    }
    const uint32_t prim = blk->prim[best];
    if (!hit_better(ft[best], prim, h)) return false;
    float fr[BVH_TRI_LANES], fv[BVH_TRI_LANES], fw[BVH_TRI_LANES];
    TV_STOREU(fr, rcp);
    TV_STOREU(fv, V);
    TV_STOREU(fw, W);
    h->t = ft[best];
    h->prim = prim;
    h->u = fv[best] * fr[best];
    h->v = fw[best] * fr[best];
    return true;
}

static inline bool bvh_tri_closest(const bvh_tri_block *blk, const bvh_tri_ray *r, hit *h)
{
    return bvh_tri_closest_x(blk, r, h, false);
}

/* Any-hit: true (with h->t, h->prim of one hit) when a lane hits. */
static inline __attribute__((always_inline)) bool bvh_tri_any_x(const bvh_tri_block *blk, const bvh_tri_ray *r,
                                                                hit *h, const bool rel)
{
    tvec t, rcp, V, W;
    int m = bvh_tri_test_x(blk, r, h->t, &t, &rcp, &V, &W, rel);
    if (!m) return false;
    float ft[BVH_TRI_LANES];
    TV_STOREU(ft, t);
    int l = __builtin_ctz((unsigned)m);
    h->t = ft[l];
    h->prim = blk->prim[l];
    return true;
}

static inline bool bvh_tri_any(const bvh_tri_block *blk, const bvh_tri_ray *r, hit *h)
{
    return bvh_tri_any_x(blk, r, h, false);
}

/* *out = blk with every vertex less the origin o (as the test subtracts it:
 * the same differences, so a test on out with rel = true gives the same
 * hits as on blk), for rays that share o. */
static inline void bvh_tri_block_rel(const bvh_tri_block *blk, float ox, float oy, float oz, bvh_tri_block *out)
{
    const tvec o[3] = {TV_SET1(ox), TV_SET1(oy), TV_SET1(oz)};
    for (int v = 0; v < 3; v++)
        for (int k = 0; k < 3; k++) TV_STOREU(out->v[v][k], TV_SUB(TV_LOAD(blk->v[v][k]), o[k]));
    memcpy(out->prim, blk->prim, sizeof out->prim);
}

static inline bool bvh_sphere_block_closest(const bvh_sphere_block *blk, const ray_pre *r, hit *h)
{
    bool any = false;
    for (int l = 0; l < BVH_SPHERE_LANES && blk->prim[l] != PK_NO_HIT; l++) {
        float t, u, v;
        vec3 c = v3(blk->c[0][l], blk->c[1][l], blk->c[2][l]);
        if (sphere_intersect(r, c, blk->r[l], h->t, &t, &u, &v) && hit_better(t, blk->prim[l], h)) {
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

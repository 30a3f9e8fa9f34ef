/*
 * bvh_traverse.c - single-ray traversal of the wide BVH: all children's
 * boxes tested at once (robust slab test), hit children visited near to far
 * (any-hit: the farthest first) from a fixed-size stack, leaves tested with
 * the SIMD watertight test that is bit-identical to geom.h's. Counting is
 * compiled in only where asked. Compiled twice, for AVX2 and AVX-512 (bvh.h).
 */
#include "bvh.h"

typedef struct stack_entry {
    uint32_t ref;
    float t;   /* entry distance of the child's box */
} stack_entry;

#if BVH_WIDTH == 8
typedef __m256 vfloat;
#define VF_LOAD _mm256_load_ps
#define VF_SET1 _mm256_set1_ps
#define VF_SUB _mm256_sub_ps
#define VF_MUL _mm256_mul_ps
#define VF_MIN _mm256_min_ps
#define VF_MAX _mm256_max_ps
#define VF_LE_MASK(a, b) _mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ))
#define VF_STORE _mm256_store_ps
#elif BVH_WIDTH == 4
typedef __m128 vfloat;
#define VF_LOAD _mm_load_ps
#define VF_SET1 _mm_set1_ps
#define VF_SUB _mm_sub_ps
#define VF_MUL _mm_mul_ps
#define VF_MIN _mm_min_ps
#define VF_MAX _mm_max_ps
#define VF_LE_MASK(a, b) _mm_movemask_ps(_mm_cmp_ps(a, b, _CMP_LE_OQ))
#define VF_STORE _mm_store_ps
#else
#error "BVH_WIDTH must be 4 or 8"
#endif

/* The ray as the node test wants it: broadcast origin and 1/d, the address
 * of node 0's box rows, and per axis the byte offset within a node of the
 * near plane's row (row 2k when 1/d >= 0, else 2k + 1); the far row is the
 * other one of the pair, at the offset with bit 5 flipped (rows are 32
 * bytes). Three offsets instead of six row pointers leave the node loop
 * fewer registers to spill. */
typedef struct node_ray {
    vfloat ox, oy, oz, rdx, rdy, rdz, rfx, rfy, rfz, tmin;
    const char *rows;
    size_t nx, ny, nz;
} node_ray;

#define ROW_BYTES (sizeof(float) * BVH_WIDTH)
_Static_assert(ROW_BYTES == 32 || ROW_BYTES == 16, "the far row's offset flips one bit");

static inline void node_ray_init(node_ray *nr, const ray *r, const ray_pre *pre, const bvh *t)
{
    const vec3 rd = pre->inv_d;
    nr->ox = VF_SET1(r->o.x), nr->oy = VF_SET1(r->o.y), nr->oz = VF_SET1(r->o.z);
    nr->rdx = VF_SET1(rd.x), nr->rdy = VF_SET1(rd.y), nr->rdz = VF_SET1(rd.z);
    nr->rfx = VF_SET1(rd.x * (1.0f + BVH_BOX_SLACK)), nr->rfy = VF_SET1(rd.y * (1.0f + BVH_BOX_SLACK));
    nr->rfz = VF_SET1(rd.z * (1.0f + BVH_BOX_SLACK));
    nr->tmin = VF_SET1(r->tmin);
    nr->rows = (const char *)t->nodes->b;
    nr->nx = (size_t)(0 + (signbit(rd.x) ? 1 : 0)) * ROW_BYTES;
    nr->ny = (size_t)(2 + (signbit(rd.y) ? 1 : 0)) * ROW_BYTES;
    nr->nz = (size_t)(4 + (signbit(rd.z) ? 1 : 0)) * ROW_BYTES;
}

/* Mask of the slots of the node at ref whose box the segment [tmin, tcull]
 * touches (tcull = bvh_cull_limit of the closest t); *tn gets the entry
 * distances. 0 * inf = NaN (a ray lying in a slab plane) is the first
 * operand of min/max, which then return the second: such a plane does not
 * limit the segment. */
static inline unsigned node_hits(uint32_t ref, const node_ray *r, float tcull, vfloat *tn)
{
    const char *p = r->rows + ref;
#define NODE_ROW(off) VF_LOAD((const float *)(p + (off)))
    const vfloat tnx = VF_MUL(VF_SUB(NODE_ROW(r->nx), r->ox), r->rdx);
    const vfloat tny = VF_MUL(VF_SUB(NODE_ROW(r->ny), r->oy), r->rdy);
    const vfloat tnz = VF_MUL(VF_SUB(NODE_ROW(r->nz), r->oz), r->rdz);
    const vfloat tfx = VF_MUL(VF_SUB(NODE_ROW(r->nx ^ ROW_BYTES), r->ox), r->rfx);
    const vfloat tfy = VF_MUL(VF_SUB(NODE_ROW(r->ny ^ ROW_BYTES), r->oy), r->rfy);
    const vfloat tfz = VF_MUL(VF_SUB(NODE_ROW(r->nz ^ ROW_BYTES), r->oz), r->rfz);
#undef NODE_ROW
    const vfloat near = VF_MAX(tnx, VF_MAX(tny, VF_MAX(tnz, r->tmin)));
    const vfloat far = VF_MIN(tfx, VF_MIN(tfy, VF_MIN(tfz, VF_SET1(tcull))));
    *tn = near;
    return (unsigned)VF_LE_MASK(near, far);
}

/* Tests leaf ref; closest: updates *best; any: true on the first hit. */
/* The leaf test is a call in the AVX2 kernels and inlined in the AVX-512
 * ones, where that measured 0-8 % faster (with 32 vector registers the node
 * loop's values need not be saved around a call). */
#ifdef BVH_AVX512
#define LEAF_INLINE __attribute__((always_inline)) inline
#else
#define LEAF_INLINE __attribute__((noinline))
#endif
static LEAF_INLINE bool leaf(const bvh *t, uint32_t ref, const bvh_ray *r, hit *best,
                                                       uint64_t *tests, const bool any, const bool count)
{
    const uint32_t nb = bvh_leaf_blocks(ref);
    const size_t off = bvh_ref_offset(ref);
    bool found = false;
    if (PK_LIKELY(!(ref & BVH_SPHERE_LEAF))) {
        const bvh_tri_block *tb = (const bvh_tri_block *)((const char *)t->tris + off);
        for (uint32_t b = 0; b < nb; b++) {
            const bvh_tri_block *blk = tb + b;
            if (count) *tests += bvh_tri_block_count(blk);
            if (any) {
                if (bvh_tri_any(blk, &r->tri, best)) return true;
            } else {
                found |= bvh_tri_closest(blk, &r->tri, best);
            }
        }
    } else {
        const bvh_sphere_block *sb = (const bvh_sphere_block *)((const char *)t->spheres + off);
        for (uint32_t b = 0; b < nb; b++) {
            const bvh_sphere_block *blk = sb + b;
            if (count) *tests += bvh_sphere_block_count(blk);
            if (bvh_sphere_block_closest(blk, &r->pre, best)) {
                if (any) return true;
                found = true;
            }
        }
    }
    return found;
}

static inline __attribute__((always_inline)) bool traverse(const bvh *t, const ray *rr, hit *out,
                                                           accel_counters *c, const bool any,
                                                           const bool count)
{
    if (!ray_traceable(rr)) { /* rejected at the root */
        if (count) c->nodes++;
        hit_clear(out);
        return false;
    }
    bvh_ray r;
    bvh_ray_init(&r, rr);
    node_ray nr;
    node_ray_init(&nr, rr, &r.pre, t);
    hit best = {rr->tmax, PK_NO_HIT, 0.0f, 0.0f};
    float tcull = bvh_cull_limit(best.t);
    const char *const children = (const char *)t->nodes->child;

    stack_entry stack[BVH_STACK_SIZE];
    stack_entry *sp = stack;
    uint32_t ref = 0;
    uint64_t nvisit = 0, tests = 0;
    for (;;) {
        while (!bvh_is_leaf(ref)) {
            const uint32_t *child = (const uint32_t *)(children + ref);
            if (count) nvisit++;
            vfloat tnv;
            unsigned mask = node_hits(ref, &nr, tcull, &tnv);
            if (!mask) goto pop;
            unsigned k0 = (unsigned)__builtin_ctz(mask);
            mask &= mask - 1;
            if (!mask) {
                ref = child[k0];
                continue;
            }
            _Alignas(32) float tn[BVH_WIDTH];
            VF_STORE(tn, tnv);
            if (any) {
                /* occlusion: any hit ends the search. The farthest child
                 * first: a ray that starts on a surface leaves the boxes
                 * around its origin without a hit, and whatever blocks it
                 * lies beyond; the others are pushed unsorted (sorting
                 * costs more than it saves) */
                unsigned kf = k0;
                float tf = tn[k0];
                do {
                    const unsigned k = (unsigned)__builtin_ctz(mask);
                    mask &= mask - 1;
                    const float tk = tn[k];
                    const bool farther = tk > tf;
                    /* push the nearer of the two, keep the farther (no branch) */
                    sp->ref = child[farther ? kf : k];
                    sp->t = -INFINITY;
                    sp++;
                    kf = farther ? k : kf;
                    tf = farther ? tk : tf;
                } while (mask);
                ref = child[kf];
                continue;
            }
            unsigned k1 = (unsigned)__builtin_ctz(mask);
            mask &= mask - 1;
            if (!mask) {
                const float t0 = tn[k0], t1 = tn[k1];
                const uint32_t c0 = child[k0], c1 = child[k1];
                const bool swap = t1 < t0;
                sp->ref = swap ? c0 : c1;
                sp->t = swap ? t0 : t1;
                sp++;
                ref = swap ? c1 : c0;
                continue;
            }
            /* three or more: push all, sort the run far to near, take the top */
            stack_entry *const base = sp;
            *sp++ = (stack_entry){child[k0], tn[k0]};
            *sp++ = (stack_entry){child[k1], tn[k1]};
            do {
                unsigned k = (unsigned)__builtin_ctz(mask);
                mask &= mask - 1;
                *sp++ = (stack_entry){child[k], tn[k]};
            } while (mask);
            for (stack_entry *i = base + 1; i < sp; i++) {
                stack_entry e = *i, *j = i;
                for (; j > base && j[-1].t < e.t; j--) *j = j[-1];
                *j = e;
            }
            ref = (--sp)->ref;
        }

        if (count) nvisit++;
        if (leaf(t, ref, &r, &best, &tests, any, count)) {
            if (any) goto done;
            tcull = bvh_cull_limit(best.t);
        }
    pop:
        for (;;) {
            if (sp == stack) goto done;
            --sp;
            if (sp->t <= tcull) {
                ref = sp->ref;
                break;
            }
        }
    }
done:
    if (count) {
        c->nodes += nvisit;
        c->tests += tests;
    }
    if (best.prim == PK_NO_HIT) {
        hit_clear(out);
        return false;
    }
    *out = best;
    return true;
}

static bool intersect_counted(const bvh *t, const ray *r, hit *h, accel_counters *c)
{
    return traverse(t, r, h, c, false, true);
}
static bool intersect_plain(const bvh *t, const ray *r, hit *h)
{
    return traverse(t, r, h, NULL, false, false);
}

bool BVH_FN(bvh_intersect)(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    const bvh *t = (const bvh *)a;
    return c ? intersect_counted(t, r, h, c) : intersect_plain(t, r, h);
}

bool BVH_FN(bvh_occluded)(const accel *a, const ray *r, hit *out, accel_counters *c)
{
    const bvh *t = (const bvh *)a;
    hit h;
    hit *hp = out ? out : &h;
    return c ? traverse(t, r, hp, c, true, true) : traverse(t, r, hp, NULL, true, false);
}

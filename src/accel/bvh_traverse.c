/*
 * bvh_traverse.c - single-ray traversal of the wide BVH: all children's
 * boxes tested at once (robust slab test), hit children visited near to far
 * from a fixed-size stack, leaves tested with the SIMD watertight test that
 * is bit-identical to geom.h's. Counting is compiled in only where asked.
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
#define VF_FMADD _mm256_fmadd_ps
#define VF_ABS(x) _mm256_andnot_ps(_mm256_set1_ps(-0.0f), x)
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
#define VF_FMADD _mm_fmadd_ps
#define VF_ABS(x) _mm_andnot_ps(_mm_set1_ps(-0.0f), x)
#define VF_LE_MASK(a, b) _mm_movemask_ps(_mm_cmp_ps(a, b, _CMP_LE_OQ))
#define VF_STORE _mm_store_ps
#else
#error "BVH_WIDTH must be 4 or 8"
#endif

/* Mask of the slots of n whose box the ray segment [tmin, tmax] touches;
 * *tn gets the entry distances. 0 * inf = NaN (a ray lying in a slab plane)
 * is the first operand of min/max, which then return the second: such a
 * plane does not limit the segment. */
static inline int node_hits(const bvh_node *n, const bvh_ray *r, vfloat ox, vfloat oy, vfloat oz,
                            vfloat rdx, vfloat rdy, vfloat rdz, vfloat tmin, float tmax, vfloat *tn)
{
    const vfloat tnx = VF_MUL(VF_SUB(VF_LOAD(n->b[r->near[0]]), ox), rdx);
    const vfloat tny = VF_MUL(VF_SUB(VF_LOAD(n->b[r->near[1]]), oy), rdy);
    const vfloat tnz = VF_MUL(VF_SUB(VF_LOAD(n->b[r->near[2]]), oz), rdz);
    const vfloat tfx = VF_MUL(VF_SUB(VF_LOAD(n->b[r->far[0]]), ox), rdx);
    const vfloat tfy = VF_MUL(VF_SUB(VF_LOAD(n->b[r->far[1]]), oy), rdy);
    const vfloat tfz = VF_MUL(VF_SUB(VF_LOAD(n->b[r->far[2]]), oz), rdz);
    const vfloat near = VF_MAX(tnx, VF_MAX(tny, VF_MAX(tnz, tmin)));
    vfloat far = VF_MIN(tfx, VF_MIN(tfy, VF_MIN(tfz, VF_SET1(tmax))));
    far = VF_FMADD(VF_ABS(far), VF_SET1(BVH_BOX_SLACK), far);
    *tn = near;
    return VF_LE_MASK(near, far);
}

static inline bool may_hit(float tn, float cur) { return tn <= cur + fabsf(cur) * BVH_BOX_SLACK; }

static inline __attribute__((always_inline)) bool traverse(const bvh *t, const ray *rr, hit *h,
                                                           accel_counters *c, const bool any,
                                                           const bool count)
{
    bvh_ray r;
    bvh_ray_init(&r, rr);
    const vfloat ox = VF_SET1(r.org[0]), oy = VF_SET1(r.org[1]), oz = VF_SET1(r.org[2]);
    const vfloat rdx = VF_SET1(r.rd[0]), rdy = VF_SET1(r.rd[1]), rdz = VF_SET1(r.rd[2]);
    const vfloat tmin = VF_SET1(rr->tmin);
    h->t = rr->tmax;
    h->prim = PK_NO_HIT;
    h->u = h->v = 0.0f;

    stack_entry stack[BVH_STACK_SIZE];
    int sp = 0;
    uint32_t ref = 0;
    uint64_t nodes = 0, tests = 0;
    for (;;) {
        while (!bvh_is_leaf(ref)) {
            const bvh_node *n = &t->nodes[ref];
            if (count) nodes++;
            vfloat tnv;
            unsigned mask = (unsigned)node_hits(n, &r, ox, oy, oz, rdx, rdy, rdz, tmin, h->t, &tnv);
            if (!mask) goto pop;
            unsigned k0 = (unsigned)__builtin_ctz(mask);
            mask &= mask - 1;
            if (!mask) {
                ref = n->child[k0];
                continue;
            }
            _Alignas(32) float tn[BVH_WIDTH];
            VF_STORE(tn, tnv);
            unsigned k1 = (unsigned)__builtin_ctz(mask);
            mask &= mask - 1;
            if (!mask) {
                if (tn[k0] <= tn[k1]) {
                    stack[sp++] = (stack_entry){n->child[k1], tn[k1]};
                    ref = n->child[k0];
                } else {
                    stack[sp++] = (stack_entry){n->child[k0], tn[k0]};
                    ref = n->child[k1];
                }
                continue;
            }
            /* three or more: push all, sort the run far to near, take the top */
            const int base = sp;
            stack[sp++] = (stack_entry){n->child[k0], tn[k0]};
            stack[sp++] = (stack_entry){n->child[k1], tn[k1]};
            do {
                unsigned k = (unsigned)__builtin_ctz(mask);
                mask &= mask - 1;
                stack[sp++] = (stack_entry){n->child[k], tn[k]};
            } while (mask);
            for (int i = base + 1; i < sp; i++) {
                stack_entry e = stack[i];
                int j = i;
                for (; j > base && stack[j - 1].t < e.t; j--) stack[j] = stack[j - 1];
                stack[j] = e;
            }
            ref = stack[--sp].ref;
        }

        /* leaf */
        if (count) nodes++;
        {
            const uint32_t first = bvh_leaf_first(ref), nb = bvh_leaf_blocks(ref);
            if (!(ref & BVH_SPHERE_LEAF)) {
                for (uint32_t b = 0; b < nb; b++) {
                    const bvh_tri_block *blk = &t->tris[first + b];
                    if (count) tests += bvh_tri_block_count(blk);
                    if (any) {
                        __m128 tt, rcp, V, W;
                        int m = bvh_tri4(blk, &r, h->t, &tt, &rcp, &V, &W);
                        if (m) {
                            float ft[4];
                            _mm_storeu_ps(ft, tt);
                            h->t = ft[__builtin_ctz((unsigned)m)];
                            h->prim = blk->prim[__builtin_ctz((unsigned)m)];
                            goto found;
                        }
                    } else {
                        bvh_tri4_closest(blk, &r, h);
                    }
                }
            } else {
                for (uint32_t b = 0; b < nb; b++) {
                    const bvh_sphere_block *blk = &t->spheres[first + b];
                    if (count) tests += bvh_sphere_block_count(blk);
                    if (bvh_sphere_block_closest(blk, &r, h) && any) goto found;
                }
            }
        }
    pop:
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (may_hit(stack[sp].t, h->t)) {
                ref = stack[sp].ref;
                break;
            }
        }
    }
found:
    if (count) {
        c->nodes += nodes;
        c->tests += tests;
    }
    return true;
done:
    if (count) {
        c->nodes += nodes;
        c->tests += tests;
    }
    if (h->prim == PK_NO_HIT) {
        hit_clear(h);
        return false;
    }
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

bool bvh_intersect(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    const bvh *t = (const bvh *)a;
    return c ? intersect_counted(t, r, h, c) : intersect_plain(t, r, h);
}

bool bvh_occluded(const accel *a, const ray *r, accel_counters *c)
{
    const bvh *t = (const bvh *)a;
    hit h;
    return c ? traverse(t, r, &h, c, true, true) : traverse(t, r, &h, NULL, true, false);
}

bool bvh_any_hit(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    const bvh *t = (const bvh *)a;
    return c ? traverse(t, r, h, c, true, true) : traverse(t, r, h, NULL, true, false);
}

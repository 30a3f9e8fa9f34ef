/*
 * bvh_packet.c - coherent rays (camera tiles, shadow rays toward one light)
 * traced through the wide BVH in packets of up to PACKET rays that share
 * their direction signs. A node is tested once for the whole packet with
 * interval arithmetic over the packet's origins and 1/d (a conservative
 * bound on every ray's own slab test); at a leaf each ray is tested against
 * the leaf's box and, if it touches it, against the primitives with the same
 * exact kernels as single rays, so the hits are bit-identical.
 */
#include "bvh.h"

#define PACKET 16      /* rays per packet: a multiple of 8, at most 32 */
#define PACKET_MIN 4   /* shorter runs of equal direction signs go as single rays */
#define GROUPS (PACKET / 8)

typedef struct pk_entry {
    uint32_t ref;
    float t;          /* lower bound of the packet's entry distances */
    uint32_t parent;  /* the node holding ref's box, and its slot */
    uint32_t slot;
} pk_entry;

typedef struct packet {
    const ray *rays;
    int n;
    uint32_t live;                 /* rays still traced (any-hit drops the occluded) */
    bool shared;                   /* every ray starts at the same point (shadow rays from one point) */
    int near[3], far[3];           /* box plane rows, shared by every ray */
    /* per ray, SoA: the box test's origin and 1/d, and tri_intersect's constants */
    _Alignas(32) float ox[PACKET], oy[PACKET], oz[PACKET];
    _Alignas(32) float rdx[PACKET], rdy[PACKET], rdz[PACKET];
    _Alignas(32) float rfx[PACKET], rfy[PACKET], rfz[PACKET];
    _Alignas(32) float tmin[PACKET], tcull[PACKET];
    _Alignas(32) float tox[PACKET], toy[PACKET], toz[PACKET], tsx[PACKET], tsy[PACKET], tsz[PACKET];
    _Alignas(32) uint32_t rowx[PACKET], rowy[PACKET], rowz[PACKET];
    /* the packet as one interval "ray": origins chosen per plane, 1/d bounds */
    __m256 on[3], of[3];           /* origin bound for near / far planes */
    __m256 rnlo[3], rnhi[3];       /* 1/d range (near planes) */
    __m256 rflo[3], rfhi[3];       /* 1/d * (1 + slack) range (far planes) */
    __m256 tmin_lo;
    hit best[PACKET];
} packet;

/* Lower bound of (p - o) * rd over o in the packet, rd in [lo, hi]: the
 * product is monotone in each factor, so a corner holds the extreme. */
static inline __m256 ilo(__m256 p, __m256 o, __m256 lo, __m256 hi)
{
    const __m256 d = _mm256_sub_ps(p, o);
    return _mm256_min_ps(_mm256_mul_ps(d, lo), _mm256_mul_ps(d, hi));
}
static inline __m256 ihi(__m256 p, __m256 o, __m256 lo, __m256 hi)
{
    const __m256 d = _mm256_sub_ps(p, o);
    return _mm256_max_ps(_mm256_mul_ps(d, lo), _mm256_mul_ps(d, hi));
}

/* Slots of node n that some ray of the packet may touch before tcull. */
static inline unsigned node_hits(const bvh_node *n, const packet *p, float tcull, __m256 *tn)
{
    const __m256 nx = ilo(_mm256_load_ps(n->b[p->near[0]]), p->on[0], p->rnlo[0], p->rnhi[0]);
    const __m256 ny = ilo(_mm256_load_ps(n->b[p->near[1]]), p->on[1], p->rnlo[1], p->rnhi[1]);
    const __m256 nz = ilo(_mm256_load_ps(n->b[p->near[2]]), p->on[2], p->rnlo[2], p->rnhi[2]);
    const __m256 fx = ihi(_mm256_load_ps(n->b[p->far[0]]), p->of[0], p->rflo[0], p->rfhi[0]);
    const __m256 fy = ihi(_mm256_load_ps(n->b[p->far[1]]), p->of[1], p->rflo[1], p->rfhi[1]);
    const __m256 fz = ihi(_mm256_load_ps(n->b[p->far[2]]), p->of[2], p->rflo[2], p->rfhi[2]);
    /* NaN (0 * inf) first: min/max then return the other operand */
    const __m256 near = _mm256_max_ps(nx, _mm256_max_ps(ny, _mm256_max_ps(nz, p->tmin_lo)));
    const __m256 far = _mm256_min_ps(fx, _mm256_min_ps(fy, _mm256_min_ps(fz, _mm256_set1_ps(tcull))));
    *tn = near;
    return (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ));
}

/* Rays of the packet (among live) whose own slab test passes slot s of n:
 * the single-ray test, one ray per lane. */
static inline uint32_t rays_hit_slot(const bvh_node *n, int s, const packet *p, uint32_t live)
{
    const __m256 px = _mm256_set1_ps(n->b[p->near[0]][s]), qx = _mm256_set1_ps(n->b[p->far[0]][s]);
    const __m256 py = _mm256_set1_ps(n->b[p->near[1]][s]), qy = _mm256_set1_ps(n->b[p->far[1]][s]);
    const __m256 pz = _mm256_set1_ps(n->b[p->near[2]][s]), qz = _mm256_set1_ps(n->b[p->far[2]][s]);
    uint32_t mask = 0;
    for (int g = 0; g < GROUPS; g++) {
        if (!((live >> (8 * g)) & 0xFFu)) continue;
        const int o = 8 * g;
        const __m256 ox = _mm256_load_ps(p->ox + o), oy = _mm256_load_ps(p->oy + o), oz = _mm256_load_ps(p->oz + o);
        const __m256 tnx = _mm256_mul_ps(_mm256_sub_ps(px, ox), _mm256_load_ps(p->rdx + o));
        const __m256 tny = _mm256_mul_ps(_mm256_sub_ps(py, oy), _mm256_load_ps(p->rdy + o));
        const __m256 tnz = _mm256_mul_ps(_mm256_sub_ps(pz, oz), _mm256_load_ps(p->rdz + o));
        const __m256 tfx = _mm256_mul_ps(_mm256_sub_ps(qx, ox), _mm256_load_ps(p->rfx + o));
        const __m256 tfy = _mm256_mul_ps(_mm256_sub_ps(qy, oy), _mm256_load_ps(p->rfy + o));
        const __m256 tfz = _mm256_mul_ps(_mm256_sub_ps(qz, oz), _mm256_load_ps(p->rfz + o));
        const __m256 near = _mm256_max_ps(tnx, _mm256_max_ps(tny, _mm256_max_ps(tnz, _mm256_load_ps(p->tmin + o))));
        const __m256 far = _mm256_min_ps(tfx, _mm256_min_ps(tfy, _mm256_min_ps(tfz, _mm256_load_ps(p->tcull + o))));
        mask |= (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ)) << o;
    }
    return mask & live;
}

/* No NaN reaches these (octant keeps such rays out of packets). */
static inline float hmin8(__m256 v)
{
    __m128 a = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    a = _mm_min_ps(a, _mm_shuffle_ps(a, a, 0x4E));
    a = _mm_min_ps(a, _mm_shuffle_ps(a, a, 0xB1));
    return _mm_cvtss_f32(a);
}
static inline float hmax8(__m256 v)
{
    __m128 a = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, 0x4E));
    a = _mm_max_ps(a, _mm_shuffle_ps(a, a, 0xB1));
    return _mm_cvtss_f32(a);
}

/* Lane-wise (k == 0 ? x : k == 1 ? y : z) for k in {0, 1, 2}. */
static inline __m256 sel3(__m256i k, __m256 x, __m256 y, __m256 z)
{
    const __m256 is0 = _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, _mm256_setzero_si256()));
    const __m256 is1 = _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, _mm256_set1_epi32(1)));
    return _mm256_blendv_ps(_mm256_blendv_ps(z, y, is1), x, is0);
}

/* Rays r[idx[0..7]] (32-byte records) as eight SoA columns:
 * o.x, o.y, o.z, tmin, d.x, d.y, d.z, tmax. */
static inline void load_transposed(const ray *r, const int *idx, __m256 c[8])
{
    __m256 w[8], t[8];
    for (int j = 0; j < 8; j++) w[j] = _mm256_loadu_ps((const float *)&r[idx[j]]);
    for (int j = 0; j < 8; j += 2) {
        t[j] = _mm256_unpacklo_ps(w[j], w[j + 1]);
        t[j + 1] = _mm256_unpackhi_ps(w[j], w[j + 1]);
    }
    for (int j = 0; j < 8; j += 4) {
        w[j] = _mm256_shuffle_ps(t[j], t[j + 2], 0x44);
        w[j + 1] = _mm256_shuffle_ps(t[j], t[j + 2], 0xEE);
        w[j + 2] = _mm256_shuffle_ps(t[j + 1], t[j + 3], 0x44);
        w[j + 3] = _mm256_shuffle_ps(t[j + 1], t[j + 3], 0xEE);
    }
    for (int j = 0; j < 4; j++) {
        c[j] = _mm256_permute2f128_ps(w[j], w[j + 4], 0x20);
        c[j + 4] = _mm256_permute2f128_ps(w[j], w[j + 4], 0x31);
    }
}

/* Sets up rays [0, n) of r, all with direction signs oct, as a packet:
 * eight rays at a time, each lane doing exactly ray_prepare's operations
 * (IEEE division and the same axis choice), so the triangle test sees the
 * same constants as for a single ray. Unused lanes repeat ray 0. */
static void packet_init(packet *p, const ray *r, int n, unsigned oct)
{
    p->rays = r;
    p->n = n;
    p->live = n == 32 ? 0xFFFFFFFFu : (1u << n) - 1u;
    for (int k = 0; k < 3; k++) {
        const int neg = (oct >> k) & 1;
        p->near[k] = 2 * k + neg;
        p->far[k] = 2 * k + 1 - neg;
    }
    const __m256 one = _mm256_set1_ps(1.0f), sign = _mm256_set1_ps(-0.0f);
    const __m256i i0 = _mm256_setzero_si256(), i1 = _mm256_set1_epi32(1), i2 = _mm256_set1_epi32(2);
    __m256 omin[3], omax[3], rmin[3], rmax[3], fmin[3], fmax[3], tmin;
    for (int g = 0; g < GROUPS; g++) {
        const int o = 8 * g;
        int idx[8];
        for (int j = 0; j < 8; j++) idx[j] = o + j < n ? o + j : 0;
        __m256 c[8];
        load_transposed(r, idx, c);
        const __m256 org[3] = {c[0], c[1], c[2]}, d[3] = {c[4], c[5], c[6]};
        __m256 rd[3], rf[3];
        for (int k = 0; k < 3; k++) {
            rd[k] = _mm256_div_ps(one, d[k]);
            rf[k] = _mm256_mul_ps(rd[k], _mm256_set1_ps(1.0f + BVH_BOX_SLACK));
        }
        _mm256_store_ps(p->ox + o, org[0]), _mm256_store_ps(p->oy + o, org[1]), _mm256_store_ps(p->oz + o, org[2]);
        _mm256_store_ps(p->rdx + o, rd[0]), _mm256_store_ps(p->rdy + o, rd[1]), _mm256_store_ps(p->rdz + o, rd[2]);
        _mm256_store_ps(p->rfx + o, rf[0]), _mm256_store_ps(p->rfy + o, rf[1]), _mm256_store_ps(p->rfz + o, rf[2]);
        _mm256_store_ps(p->tmin + o, c[3]);
        const __m256 tmax = c[7];
        _mm256_store_ps(p->tcull + o, _mm256_add_ps(tmax, _mm256_mul_ps(_mm256_andnot_ps(sign, tmax),
                                                                        _mm256_set1_ps(BVH_BOX_SLACK))));
        /* ray_prepare: kz = the largest |d| (ties as v3_max_axis_abs), kx, ky the
         * next two, swapped when d[kz] < 0 */
        const __m256 ax = _mm256_andnot_ps(sign, d[0]), ay = _mm256_andnot_ps(sign, d[1]), az = _mm256_andnot_ps(sign, d[2]);
        const __m256 gxy = _mm256_cmp_ps(ax, ay, _CMP_GT_OQ), gxz = _mm256_cmp_ps(ax, az, _CMP_GT_OQ);
        const __m256 gyz = _mm256_cmp_ps(ay, az, _CMP_GT_OQ);
        const __m256 kzf = _mm256_blendv_ps(_mm256_blendv_ps(_mm256_castsi256_ps(i2), _mm256_castsi256_ps(i1), gyz),
                                            _mm256_blendv_ps(_mm256_castsi256_ps(i2), _mm256_castsi256_ps(i0), gxz), gxy);
        const __m256i kz = _mm256_castps_si256(kzf);
        const __m256i kx0 = _mm256_blendv_epi8(_mm256_add_epi32(kz, i1), i0, _mm256_cmpeq_epi32(kz, i2));
        const __m256i ky0 = _mm256_blendv_epi8(_mm256_add_epi32(kx0, i1), i0, _mm256_cmpeq_epi32(kx0, i2));
        const __m256 dz = sel3(kz, d[0], d[1], d[2]);
        const __m256i swap = _mm256_castps_si256(_mm256_cmp_ps(dz, _mm256_setzero_ps(), _CMP_LT_OQ));
        const __m256i kx = _mm256_blendv_epi8(kx0, ky0, swap), ky = _mm256_blendv_epi8(ky0, kx0, swap);
        _mm256_store_ps(p->tsx + o, _mm256_div_ps(sel3(kx, d[0], d[1], d[2]), dz));
        _mm256_store_ps(p->tsy + o, _mm256_div_ps(sel3(ky, d[0], d[1], d[2]), dz));
        _mm256_store_ps(p->tsz + o, _mm256_div_ps(one, dz));
        _mm256_store_ps(p->tox + o, sel3(kx, org[0], org[1], org[2]));
        _mm256_store_ps(p->toy + o, sel3(ky, org[0], org[1], org[2]));
        _mm256_store_ps(p->toz + o, sel3(kz, org[0], org[1], org[2]));
        const int rowshift = BVH_TRI_LANES == 8 ? 5 : 4; /* row bytes: 4 * BVH_TRI_LANES */
        _mm256_store_si256((__m256i *)(p->rowx + o), _mm256_slli_epi32(kx, rowshift));
        _mm256_store_si256((__m256i *)(p->rowy + o), _mm256_slli_epi32(ky, rowshift));
        _mm256_store_si256((__m256i *)(p->rowz + o), _mm256_slli_epi32(kz, rowshift));
        for (int k = 0; k < 3; k++) {
            omin[k] = g ? _mm256_min_ps(omin[k], org[k]) : org[k];
            omax[k] = g ? _mm256_max_ps(omax[k], org[k]) : org[k];
            rmin[k] = g ? _mm256_min_ps(rmin[k], rd[k]) : rd[k];
            rmax[k] = g ? _mm256_max_ps(rmax[k], rd[k]) : rd[k];
            fmin[k] = g ? _mm256_min_ps(fmin[k], rf[k]) : rf[k];
            fmax[k] = g ? _mm256_max_ps(fmax[k], rf[k]) : rf[k];
        }
        tmin = g ? _mm256_min_ps(tmin, c[3]) : c[3];
    }
    _Static_assert(4 * BVH_TRI_LANES == (BVH_TRI_LANES == 8 ? 32 : 16), "row shift");
    for (int k = 0; k < 3; k++) {
        const bool pos = (p->near[k] & 1) == 0; /* near plane is lo: 1/d >= 0 */
        /* the least (plane - o) for near planes, the greatest for far ones,
         * taken with the sign of 1/d */
        p->on[k] = _mm256_set1_ps(pos ? hmax8(omax[k]) : hmin8(omin[k]));
        p->of[k] = _mm256_set1_ps(pos ? hmin8(omin[k]) : hmax8(omax[k]));
        p->rnlo[k] = _mm256_set1_ps(hmin8(rmin[k])), p->rnhi[k] = _mm256_set1_ps(hmax8(rmax[k]));
        p->rflo[k] = _mm256_set1_ps(hmin8(fmin[k])), p->rfhi[k] = _mm256_set1_ps(hmax8(fmax[k]));
    }
    p->tmin_lo = _mm256_set1_ps(hmin8(tmin));
    /* the origin bounds are one point: the same bits (not merely ==, which
     * would take -0 for 0) in every ray */
    p->shared = true;
    for (int i = 1; i < n && p->shared; i++)
        p->shared = memcmp(&r[i].o, &r[0].o, sizeof r[0].o) == 0;
    for (int i = 0; i < n; i++) p->best[i] = (hit){r[i].tmax, PK_NO_HIT, 0.0f, 0.0f};
}

/* The largest tcull of the live rays (-inf when none is live): eight lanes
 * at a time, the dead ones masked to -inf. */
static inline float packet_tcull(const packet *p)
{
    const __m256i bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256 ninf = _mm256_set1_ps(-INFINITY);
    __m256 m = ninf;
    for (int g = 0; g < GROUPS; g++) {
        const __m256i lm = _mm256_set1_epi32((int)((p->live >> (8 * g)) & 0xFFu));
        const __m256 on = _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(lm, bits), bits));
        m = _mm256_max_ps(m, _mm256_blendv_ps(ninf, _mm256_load_ps(p->tcull + 8 * g), on));
    }
    return hmax8(m);
}

/* The rays in mask of a packet whose rays share their origin against the
 * triangle leaf at off with nb blocks: each block is translated to the
 * origin once, and each ray's test skips its subtractions (the same
 * differences, the same hits). Each ray meets the blocks in order, as in
 * packet_leaf. */
static inline void packet_leaf_shared(const bvh *t, packet *p, size_t off, uint32_t nb, uint32_t mask, bool any,
                                      uint64_t *tests, const bool count)
{
    const bvh_tri_block *tb = (const bvh_tri_block *)((const char *)t->tris + off);
    _Alignas(64) bvh_tri_block rel;
    uint32_t found = 0;
    for (uint32_t b = 0; b < nb && mask; b++) {
        bvh_tri_block_rel(tb + b, p->ox[0], p->oy[0], p->oz[0], &rel);
        if (count) *tests += (uint64_t)bvh_tri_block_count(&rel) * (uint64_t)__builtin_popcount(mask);
        for (uint32_t m = mask; m; m &= m - 1) {
            const int i = __builtin_ctz(m);
            const bvh_tri_ray tr = {0.0f, 0.0f, 0.0f, p->tsx[i], p->tsy[i], p->tsz[i],
                                    p->tmin[i], p->rowx[i], p->rowy[i], p->rowz[i]};
            if (any) {
                if (bvh_tri_any_x(&rel, &tr, &p->best[i], true)) found |= 1u << i, mask &= ~(1u << i);
            } else if (bvh_tri_closest_x(&rel, &tr, &p->best[i], true)) {
                found |= 1u << i;
            }
        }
    }
    for (; found; found &= found - 1) {
        const int i = __builtin_ctz(found);
        if (any) p->live &= ~(1u << i);
        else p->tcull[i] = bvh_cull_limit(p->best[i].t);
    }
}

/* Tests the rays in mask against leaf ref. */
static inline void packet_leaf(const bvh *t, packet *p, uint32_t ref, uint32_t mask, bool any,
                               uint64_t *tests, const bool count)
{
    const uint32_t nb = bvh_leaf_blocks(ref);
    const size_t off = bvh_ref_offset(ref);
    if (p->shared && !(ref & BVH_SPHERE_LEAF)) {
        packet_leaf_shared(t, p, off, nb, mask, any, tests, count);
        return;
    }
    for (; mask; mask &= mask - 1) {
        const int i = __builtin_ctz(mask);
        hit *h = &p->best[i];
        bool found = false;
        if (!(ref & BVH_SPHERE_LEAF)) {
            const bvh_tri_ray tr = {p->tox[i], p->toy[i], p->toz[i], p->tsx[i], p->tsy[i], p->tsz[i],
                                    p->tmin[i], p->rowx[i], p->rowy[i], p->rowz[i]};
            const bvh_tri_block *tb = (const bvh_tri_block *)((const char *)t->tris + off);
            for (uint32_t b = 0; b < nb; b++) {
                if (count) *tests += bvh_tri_block_count(tb + b);
                if (any) {
                    if (bvh_tri_any(tb + b, &tr, h)) {
                        found = true;
                        break;
                    }
                } else {
                    found |= bvh_tri_closest(tb + b, &tr, h);
                }
            }
        } else {
            const ray_pre pre = ray_prepare(&p->rays[i]);
            const bvh_sphere_block *sb = (const bvh_sphere_block *)((const char *)t->spheres + off);
            for (uint32_t b = 0; b < nb; b++) {
                if (count) *tests += bvh_sphere_block_count(sb + b);
                if (bvh_sphere_block_closest(sb + b, &pre, h)) {
                    found = true;
                    if (any) break;
                }
            }
        }
        if (found) {
            if (any) p->live &= ~(1u << i);
            else p->tcull[i] = bvh_cull_limit(h->t);
        }
    }
}

static inline __attribute__((always_inline)) void packet_trace(const bvh *t, packet *p, bool any,
                                                               accel_counters *c, const bool count)
{
    pk_entry stack[BVH_STACK_SIZE];
    int sp = 0;
    uint32_t ref = 0, parent = 0, slot = 0; /* the root is an inner node */
    float tcull = packet_tcull(p);
    uint64_t nvisit = 0, tests = 0;
    const char *const nodes = (const char *)t->nodes;
    for (;;) {
        while (!bvh_is_leaf(ref)) {
            const bvh_node *n = (const bvh_node *)(nodes + ref);
            if (count) nvisit++;
            __m256 tnv;
            unsigned mask = node_hits(n, p, tcull, &tnv);
            if (!mask) goto pop;
            _Alignas(32) float tn[8];
            _mm256_store_ps(tn, tnv);
            const int base = sp;
            do {
                const unsigned k = (unsigned)__builtin_ctz(mask);
                mask &= mask - 1;
                stack[sp++] = (pk_entry){n->child[k], tn[k], ref, k};
            } while (mask);
            for (int i = base + 1; i < sp; i++) {
                pk_entry e = stack[i];
                int j = i;
                for (; j > base && stack[j - 1].t < e.t; j--) stack[j] = stack[j - 1];
                stack[j] = e;
            }
            --sp;
            ref = stack[sp].ref, parent = stack[sp].parent, slot = stack[sp].slot;
        }
        {
            /* only the rays whose own box test passes go on to the primitives */
            uint32_t rays = rays_hit_slot((const bvh_node *)(nodes + parent), (int)slot, p, p->live);
            if (rays) {
                if (count) nvisit++;
                packet_leaf(t, p, ref, rays, any, &tests, count);
                if (!p->live) goto done;
                tcull = packet_tcull(p);
            }
        }
    pop:
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (stack[sp].t <= tcull) {
                ref = stack[sp].ref, parent = stack[sp].parent, slot = stack[sp].slot;
                break;
            }
        }
    }
done:
    if (count) {
        c->nodes += nvisit;
        c->tests += tests;
    }
}

/* Direction signs; 8 for a ray that may not join a packet (a NaN or an
 * infinite origin would spoil the packet's bounds, and a direction component
 * whose reciprocal overflows needs ray_rcp's NaN, which the packet's interval
 * test does not take). */
static inline unsigned octant(const ray *r)
{
    if (!v3_finite(r->o) || isnan(r->d.x) || isnan(r->d.y) || isnan(r->d.z) || isnan(r->tmin) || isnan(r->tmax) ||
        ray_dir_tiny(r->d))
        return 8;
    return (signbit(r->d.x) ? 1u : 0u) | (signbit(r->d.y) ? 2u : 0u) | (signbit(r->d.z) ? 4u : 0u);
}

void BVH_FN(bvh_intersect_packet)(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                          accel_counters *c)
{
    const bvh *t = (const bvh *)a;
    packet p;
    for (size_t i = 0; i < n;) {
        /* a run of rays with the same direction signs, at most PACKET long */
        const unsigned oct = octant(&r[i]);
        int m = 1;
        while (oct < 8 && m < PACKET && i + (size_t)m < n && octant(&r[i + (size_t)m]) == oct) m++;
        if (m < PACKET_MIN) {
            for (int k = 0; k < m; k++) {
                if (any_hit) BVH_FN(bvh_occluded)(a, &r[i + (size_t)k], &h[i + (size_t)k], c);
                else BVH_FN(bvh_intersect)(a, &r[i + (size_t)k], &h[i + (size_t)k], c);
            }
            i += (size_t)m;
            continue;
        }
        packet_init(&p, r + i, m, oct);
        if (c) packet_trace(t, &p, any_hit, c, true);
        else packet_trace(t, &p, any_hit, NULL, false);
        for (int k = 0; k < m; k++) {
            if (p.best[k].prim == PK_NO_HIT) hit_clear(&h[i + (size_t)k]);
            else h[i + (size_t)k] = p.best[k];
        }
        i += (size_t)m;
    }
}

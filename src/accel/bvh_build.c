/*
 * bvh_build.c - builds the wide BVH: a binned-SAH binary tree (OpenMP tasks
 * over the top levels), collapsed into BVH_WIDTH-wide SoA nodes with SoA
 * triangle and sphere blocks in the leaves. Invariants: bvh.h; design and
 * measurements: docs/bvh.md.
 */
#include "bvh.h"

#include <immintrin.h>
#include <omp.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#define NBINS 32
#define TASK_MIN 2048      /* ranges below this are built by the task that holds them */
#define SAH_DEPTH_MAX 48   /* binary levels split by SAH; deeper ones split at the median */
#ifndef COST_NODE
#define COST_NODE 2.0f     /* SAH: cost of a node visit ... */
#endif
#define COST_BLOCK 1.0f    /* ... relative to a primitive block test */
#define BIN_LEAF_MAX 4     /* primitives per leaf of the binary tree */

/* A box in two SSE registers (lane 3 unused). */
typedef struct sbox {
    __m128 lo, hi;
} sbox;

static inline sbox sbox_empty(void)
{
    sbox b = {_mm_set1_ps(INFINITY), _mm_set1_ps(-INFINITY)};
    return b;
}
static inline sbox sbox_union(sbox a, sbox b)
{
    a.lo = _mm_min_ps(a.lo, b.lo);
    a.hi = _mm_max_ps(a.hi, b.hi);
    return a;
}
static inline sbox sbox_grow(sbox a, __m128 p)
{
    a.lo = _mm_min_ps(a.lo, p);
    a.hi = _mm_max_ps(a.hi, p);
    return a;
}
static inline float sbox_half_area(sbox b)
{
    const __m128 e = _mm_sub_ps(b.hi, b.lo);
    /* empty (or NaN) on some axis: no area */
    if ((_mm_movemask_ps(_mm_cmpge_ps(e, _mm_setzero_ps())) & 7) != 7) return 0.0f;
    const __m128 p = _mm_mul_ps(e, _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1))); /* xy, yz, zx */
    return _mm_cvtss_f32(_mm_add_ss(_mm_add_ss(p, _mm_shuffle_ps(p, p, 1)), _mm_movehl_ps(p, p)));
}
static inline aabb sbox_aabb(sbox b)
{
    float lo[4], hi[4];
    _mm_storeu_ps(lo, b.lo);
    _mm_storeu_ps(hi, b.hi);
    aabb r = {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
    return r;
}

/* Binary node: inner when count == 0 (children first, first + 1), else a
 * leaf over ids[first .. first + count). Either way its subtree holds
 * ids[begin .. begin + size). */
typedef struct bnode {
    sbox box;
    uint32_t first, count;
    uint32_t begin, size;
} bnode;

typedef struct builder {
    const sbox *pbox;       /* per primitive id */
    uint32_t *ids;          /* primitive ids, partitioned in place */
    bnode *nodes;
    uint32_t nnodes;        /* allocated so far (atomic) */
    uint32_t ntris;         /* ids >= ntris are spheres */
    bool spheres;           /* any sphere present */
} builder;

static inline __m128 centroid2(const sbox *b) { return _mm_add_ps(b->lo, b->hi); }

static uint32_t node_alloc2(builder *b)
{
    uint32_t k;
#pragma omp atomic capture
    {
        k = b->nnodes;
        b->nnodes += 2;
    }
    return k;
}

/* The binary tree's SAH counts primitives in groups of 4 (the collapse then
 * packs leaves into blocks of BVH_TRI_LANES). */
static inline float sah_blocks(uint32_t n) { return (float)((n + 3) / 4); }

typedef struct split {
    int axis;
    int bin;          /* left = bins < bin */
    float cost;       /* sum of half areas * blocks */
    sbox left, right;
} split;

typedef struct binner {
    float lo[4], scale[4];
    int nbins;        /* NBINS, fewer for small ranges */
} binner;

static inline int bin_of(const binner *bn, __m128 c2, int axis)
{
    float c[4];
    _mm_storeu_ps(c, c2);
    int k = (int)((c[axis] - bn->lo[axis]) * bn->scale[axis]);
    return k < 0 ? 0 : k >= bn->nbins ? bn->nbins - 1 : k;
}

/* Binned SAH over the doubled centroids in cb; false when every axis is flat. */
static bool find_split(const builder *b, uint32_t begin, uint32_t end, sbox cb, binner *bn, split *best)
{
    float lo[4], hi[4];
    _mm_storeu_ps(lo, cb.lo);
    _mm_storeu_ps(hi, cb.hi);
    const uint32_t n = end - begin;
    const int nb = n >= NBINS ? NBINS : n >= 8 ? (int)n : 8;
    bn->nbins = nb;
    bool any = false;
    for (int ax = 0; ax < 3; ax++) {
        float ext = hi[ax] - lo[ax];
        bn->lo[ax] = lo[ax];
        bn->scale[ax] = ext > 0.0f && isfinite(ext) ? (float)nb * 0.99999f / ext : 0.0f;
        if (bn->scale[ax] > 0.0f && isfinite(bn->scale[ax])) any = true;
        else bn->scale[ax] = 0.0f;
    }
    bn->lo[3] = 0.0f;
    bn->scale[3] = 0.0f;
    if (!any) return false;

    sbox bins[3][NBINS];
    uint32_t counts[3][NBINS];
    for (int ax = 0; ax < 3; ax++)
        for (int k = 0; k < nb; k++) {
            bins[ax][k] = sbox_empty();
            counts[ax][k] = 0;
        }
    const __m128 blo = _mm_loadu_ps(bn->lo), bsc = _mm_loadu_ps(bn->scale);
    for (uint32_t i = begin; i < end; i++) {
        const sbox *pb = &b->pbox[b->ids[i]];
        __m128 k4 = _mm_mul_ps(_mm_sub_ps(centroid2(pb), blo), bsc);
        __m128i ki = _mm_cvttps_epi32(k4);
        ki = _mm_max_epi32(_mm_setzero_si128(), _mm_min_epi32(ki, _mm_set1_epi32(nb - 1)));
        int k[4];
        _mm_storeu_si128((__m128i *)k, ki);
        for (int ax = 0; ax < 3; ax++) {
            counts[ax][k[ax]]++;
            bins[ax][k[ax]] = sbox_union(bins[ax][k[ax]], *pb);
        }
    }
    bool found = false;
    best->cost = INFINITY;
    for (int ax = 0; ax < 3; ax++) {
        if (bn->scale[ax] == 0.0f) continue;
        float rarea[NBINS];
        uint32_t rcount[NBINS];
        sbox acc = sbox_empty();
        uint32_t cnt = 0;
        for (int k = nb - 1; k > 0; k--) {
            acc = sbox_union(acc, bins[ax][k]);
            cnt += counts[ax][k];
            rarea[k] = sbox_half_area(acc);
            rcount[k] = cnt;
        }
        acc = sbox_empty();
        cnt = 0;
        for (int k = 1; k < nb; k++) {
            acc = sbox_union(acc, bins[ax][k - 1]);
            cnt += counts[ax][k - 1];
            if (cnt == 0 || rcount[k] == 0) continue;
            float cost = sbox_half_area(acc) * sah_blocks(cnt) + rarea[k] * sah_blocks(rcount[k]);
            if (cost < best->cost) {
                best->cost = cost;
                best->axis = ax;
                best->bin = k;
                found = true;
            }
        }
    }
    if (!found) return false;
    best->left = sbox_empty();
    best->right = sbox_empty();
    for (int k = 0; k < nb; k++) {
        if (k < best->bin) best->left = sbox_union(best->left, bins[best->axis][k]);
        else best->right = sbox_union(best->right, bins[best->axis][k]);
    }
    return true;
}

static void range_bounds(const builder *b, uint32_t begin, uint32_t end, sbox *box, sbox *cb)
{
    sbox bx = sbox_empty(), c = sbox_empty();
    for (uint32_t i = begin; i < end; i++) {
        const sbox *pb = &b->pbox[b->ids[i]];
        bx = sbox_union(bx, *pb);
        c = sbox_grow(c, centroid2(pb));
    }
    *box = bx;
    *cb = c;
}

/* Moves the triangles of [begin, end) before its spheres; returns the boundary. */
static uint32_t partition_kind(builder *b, uint32_t begin, uint32_t end)
{
    uint32_t i = begin, j = end;
    while (i < j) {
        if (b->ids[i] < b->ntris) {
            i++;
        } else {
            uint32_t t = b->ids[i];
            b->ids[i] = b->ids[--j];
            b->ids[j] = t;
        }
    }
    return i;
}

static void build_node(builder *b, uint32_t ni, uint32_t begin, uint32_t end, sbox cb, int depth);

static void build_children(builder *b, uint32_t ni, uint32_t begin, uint32_t mid, uint32_t end,
                           sbox lbox, sbox lcb, sbox rbox, sbox rcb, int depth)
{
    uint32_t k = node_alloc2(b);
    b->nodes[ni].first = k;
    b->nodes[ni].count = 0;
    b->nodes[k].box = lbox;
    b->nodes[k + 1].box = rbox;
    if (end - begin >= TASK_MIN) {
#pragma omp task default(none) firstprivate(b, k, begin, mid, lcb, depth)
        build_node(b, k, begin, mid, lcb, depth + 1);
        build_node(b, k + 1, mid, end, rcb, depth + 1);
    } else {
        build_node(b, k, begin, mid, lcb, depth + 1);
        build_node(b, k + 1, mid, end, rcb, depth + 1);
    }
}

/* nodes[ni].box is set by the caller; cb bounds the doubled centroids. */
static void build_node(builder *b, uint32_t ni, uint32_t begin, uint32_t end, sbox cb, int depth)
{
    uint32_t n = end - begin;
    b->nodes[ni].begin = begin;
    b->nodes[ni].size = n;
    split s;
    binner bn;
    bool ok = n > 1 && depth < SAH_DEPTH_MAX && find_split(b, begin, end, cb, &bn, &s);

    if (n <= BIN_LEAF_MAX) {
        float area = sbox_half_area(b->nodes[ni].box);
        bool leaf = !ok || COST_BLOCK * sah_blocks(n) * area <= COST_NODE * area + COST_BLOCK * s.cost;
        if (leaf) {
            uint32_t mid = b->spheres ? partition_kind(b, begin, end) : end;
            if (mid == begin || mid == end) {
                b->nodes[ni].first = begin;
                b->nodes[ni].count = n;
                return;
            }
            /* mixed triangles and spheres: one leaf of each */
            sbox lbox, lcb, rbox, rcb;
            range_bounds(b, begin, mid, &lbox, &lcb);
            range_bounds(b, mid, end, &rbox, &rcb);
            build_children(b, ni, begin, mid, end, lbox, lcb, rbox, rcb, depth);
            return;
        }
    }

    uint32_t mid;
    sbox lbox, lcb, rbox, rcb;
    if (ok) {
        const int ax = s.axis, sb = s.bin;
        uint32_t i = begin, j = end;
        lcb = sbox_empty();
        rcb = sbox_empty();
        for (;;) {
            while (i < j) {
                __m128 c = centroid2(&b->pbox[b->ids[i]]);
                if (bin_of(&bn, c, ax) >= sb) break;
                lcb = sbox_grow(lcb, c);
                i++;
            }
            while (i < j) {
                __m128 c = centroid2(&b->pbox[b->ids[j - 1]]);
                if (bin_of(&bn, c, ax) < sb) break;
                rcb = sbox_grow(rcb, c);
                j--;
            }
            if (i >= j) break;
            uint32_t t = b->ids[i];
            b->ids[i] = b->ids[j - 1];
            b->ids[j - 1] = t;
        }
        mid = i;
        lbox = s.left;
        rbox = s.right;
        PK_ASSERT(mid > begin && mid < end);
    } else {
        /* flat centroids or too deep: split in the middle of the range */
        mid = begin + n / 2;
        range_bounds(b, begin, mid, &lbox, &lcb);
        range_bounds(b, mid, end, &rbox, &rcb);
    }
    build_children(b, ni, begin, mid, end, lbox, lcb, rbox, rcb, depth);
}

/* ---- collapse into the wide tree ---------------------------------------- */

typedef struct collapser {
    const builder *b;
    const accel_input *in;
    bvh_node *nodes;
    size_t nnodes, cap_nodes;
    bvh_tri_block *tris;
    size_t ntri_blocks;
    bvh_sphere_block *spheres;
    size_t nsphere_blocks;
    size_t leaves;
    double sah;       /* sum of areas, normalised at the end */
    int depth;
} collapser;

static uint32_t make_leaf(collapser *c, const bnode *bn)
{
    uint32_t ids[BVH_LEAF_MAX];
    uint32_t n = bn->size;
    PK_ASSERT(n >= 1 && n <= BVH_LEAF_MAX);
    memcpy(ids, c->b->ids + bn->begin, n * sizeof *ids);
    for (uint32_t i = 1; i < n; i++) {
        uint32_t v = ids[i], j = i;
        for (; j > 0 && ids[j - 1] > v; j--) ids[j] = ids[j - 1];
        ids[j] = v;
    }
    c->leaves++;
    c->sah += (double)n * (double)sbox_half_area(bn->box);
    if (ids[0] >= c->b->ntris) {
        uint32_t first = (uint32_t)c->nsphere_blocks;
        uint32_t nb = (n + BVH_SPHERE_LANES - 1) / BVH_SPHERE_LANES;
        for (uint32_t k = 0; k < nb; k++) {
            bvh_sphere_block *blk = &c->spheres[c->nsphere_blocks++];
            for (int l = 0; l < BVH_SPHERE_LANES; l++) {
                uint32_t i = k * BVH_SPHERE_LANES + (uint32_t)l;
                if (i < n) {
                    const accel_sphere *sp = &c->in->spheres[ids[i] - c->b->ntris];
                    blk->c[0][l] = sp->center.x;
                    blk->c[1][l] = sp->center.y;
                    blk->c[2][l] = sp->center.z;
                    blk->r[l] = sp->radius;
                    blk->prim[l] = ids[i];
                } else {
                    blk->c[0][l] = blk->c[1][l] = blk->c[2][l] = blk->r[l] = NAN;
                    blk->prim[l] = PK_NO_HIT;
                }
            }
        }
        return bvh_leaf_ref(true, first, nb);
    }
    uint32_t first = (uint32_t)c->ntri_blocks;
    uint32_t nb = (n + BVH_TRI_LANES - 1) / BVH_TRI_LANES;
    for (uint32_t k = 0; k < nb; k++) {
        bvh_tri_block *blk = &c->tris[c->ntri_blocks++];
        for (int l = 0; l < BVH_TRI_LANES; l++) {
            uint32_t i = k * BVH_TRI_LANES + (uint32_t)l;
            if (i < n) {
                const vec3 *p = c->in->verts + 3 * (size_t)ids[i];
                for (int v = 0; v < 3; v++) {
                    blk->v[v][0][l] = p[v].x;
                    blk->v[v][1][l] = p[v].y;
                    blk->v[v][2][l] = p[v].z;
                }
                blk->prim[l] = ids[i];
            } else {
                for (int v = 0; v < 3; v++) blk->v[v][0][l] = blk->v[v][1][l] = blk->v[v][2][l] = NAN;
                blk->prim[l] = PK_NO_HIT;
            }
        }
    }
    return bvh_leaf_ref(false, first, nb);
}

static void set_slot_box(bvh_node *wn, int k, sbox box)
{
    aabb a = sbox_aabb(box);
    wn->b[BVH_LO_X][k] = a.lo.x;
    wn->b[BVH_HI_X][k] = a.hi.x;
    wn->b[BVH_LO_Y][k] = a.lo.y;
    wn->b[BVH_HI_Y][k] = a.hi.y;
    wn->b[BVH_LO_Z][k] = a.lo.z;
    wn->b[BVH_HI_Z][k] = a.hi.z;
}

static void init_node(bvh_node *wn)
{
    for (int k = 0; k < BVH_WIDTH; k++) {
        wn->b[BVH_LO_X][k] = wn->b[BVH_LO_Y][k] = wn->b[BVH_LO_Z][k] = INFINITY;
        wn->b[BVH_HI_X][k] = wn->b[BVH_HI_Y][k] = wn->b[BVH_HI_Z][k] = -INFINITY;
        wn->child[k] = BVH_EMPTY;
    }
}

/* The binary tree is collapsed into the wide one by dynamic programming
 * (Ylitie, Karras and Laine 2017): for every binary node n and every
 * i = 1..BVH_WIDTH, cost[i-1] is the least SAH cost of representing n's
 * subtree by at most i slots of a wide node, each either a leaf (the whole
 * subtree, up to BVH_LEAF_MAX primitives of one kind, COST_BLOCK per block)
 * or a wide node (COST_NODE plus the best distribution of its children over
 * BVH_WIDTH slots). Costs are areas times the per-visit cost; the root's is
 * the tree's SAH cost in those units. */
enum { DP_LEAF = 0, DP_NODE = 1, DP_FEWER = 0 };

typedef struct dp_entry {
    float cost[BVH_WIDTH];
    uint8_t how[BVH_WIDTH];  /* [0]: DP_LEAF or DP_NODE; [i>0]: DP_FEWER or k, slots given to the left child */
    uint8_t split;           /* as a wide node: slots given to the left child */
    uint32_t spheres;        /* spheres in the subtree */
} dp_entry;

static void dp_solve(const builder *b, uint32_t nnodes, const uint32_t *ids, dp_entry *dp)
{
    for (uint32_t ii = nnodes; ii-- > 0;) {
        const bnode *x = &b->nodes[ii];
        dp_entry *e = &dp[ii];
        const float area = sbox_half_area(x->box);
        if (x->count) {
            e->spheres = 0;
            for (uint32_t k = 0; k < x->count; k++) e->spheres += ids[x->first + k] >= b->ntris;
        } else {
            e->spheres = dp[x->first].spheres + dp[x->first + 1].spheres;
        }
        const bool mixed = e->spheres != 0 && e->spheres != x->size;
        const uint32_t lanes = e->spheres ? BVH_SPHERE_LANES : BVH_TRI_LANES;
        /* a flag, not an infinite cost: areas overflow to inf in huge scenes */
        const bool leaf_ok = x->size <= BVH_LEAF_MAX && !mixed;
        const float leaf = leaf_ok ? COST_BLOCK * (float)((x->size + lanes - 1) / lanes) * area : INFINITY;
        if (x->count) {
            for (int i = 0; i < BVH_WIDTH; i++) {
                e->cost[i] = leaf;
                e->how[i] = i == 0 ? DP_LEAF : DP_FEWER;
            }
            e->split = 0;
            continue;
        }
        const dp_entry *l = &dp[x->first], *r = &dp[x->first + 1];
        float dist[BVH_WIDTH + 1];
        uint8_t distk[BVH_WIDTH + 1];
        for (int j = 2; j <= BVH_WIDTH; j++) {
            dist[j] = INFINITY;
            distk[j] = 1;
            for (int k = 1; k < j; k++) {
                float v = l->cost[k - 1] + r->cost[j - k - 1];
                if (v < dist[j]) {
                    dist[j] = v;
                    distk[j] = (uint8_t)k;
                }
            }
        }
        const float node = COST_NODE * area + dist[BVH_WIDTH];
        e->split = distk[BVH_WIDTH];
        const bool as_leaf = leaf_ok && leaf <= node;
        e->cost[0] = as_leaf ? leaf : node;
        e->how[0] = as_leaf ? DP_LEAF : DP_NODE;
        for (int j = 2; j <= BVH_WIDTH; j++) {
            bool fewer = e->cost[j - 2] <= dist[j];
            e->cost[j - 1] = fewer ? e->cost[j - 2] : dist[j];
            e->how[j - 1] = fewer ? DP_FEWER : distk[j];
        }
    }
}

/* The binary nodes that fill at most j slots for node x. */
static void dp_gather(const builder *b, const dp_entry *dp, uint32_t x, int j, uint32_t *out, int *n)
{
    while (j > 1 && dp[x].how[j - 1] == DP_FEWER) j--;
    if (j == 1) {
        out[(*n)++] = x;
        return;
    }
    const int k = dp[x].how[j - 1];
    dp_gather(b, dp, b->nodes[x].first, k, out, n);
    dp_gather(b, dp, b->nodes[x].first + 1, j - k, out, n);
}

/* Makes the wide node for binary node bi (chosen as a node); returns its index. */
static uint32_t collapse(collapser *c, const dp_entry *dp, uint32_t bi, int depth)
{
    const bnode *bn = c->b->nodes;
    uint32_t wi = (uint32_t)c->nnodes++;
    PK_ASSERT(wi < c->cap_nodes);
    if (depth > c->depth) c->depth = depth;
    c->sah += (double)sbox_half_area(bn[bi].box);

    uint32_t kids[BVH_WIDTH];
    int nk = 0;
    const int k = dp[bi].split;
    dp_gather(c->b, dp, bn[bi].first, k, kids, &nk);
    dp_gather(c->b, dp, bn[bi].first + 1, BVH_WIDTH - k, kids, &nk);
    init_node(&c->nodes[wi]);
    for (int q = 0; q < nk; q++) {
        const bnode *x = &bn[kids[q]];
        uint32_t ref = dp[kids[q]].how[0] == DP_LEAF ? make_leaf(c, x)
                                                     : bvh_node_ref(collapse(c, dp, kids[q], depth + 1));
        bvh_node *wn = &c->nodes[wi]; /* index, not pointer, across recursion */
        wn->child[q] = ref;
        set_slot_box(wn, q, x->box);
    }
    return wi;
}

/* ---- the accelerator ---------------------------------------------------- */

static void bvh_destroy(accel *a)
{
    if (!a) return;
    bvh *t = (bvh *)a;
    const pk_allocator *al = a->alloc;
    mem_free(al, t->mem);
    mem_free(al, t);
}

static const accel_ops bvh_ops = {bvh_destroy, bvh_intersect, bvh_occluded, bvh_intersect_packet};

/* Nodes, triangle and sphere blocks in one block of memory; large ones start
 * on a 2 MiB boundary and ask for transparent huge pages, which saves TLB
 * misses on incoherent rays. */
#define HUGE_PAGE ((size_t)2 << 20)

static size_t round_up(size_t x, size_t a) { return (x + a - 1) & ~(a - 1); }

static bool place_arrays(const pk_allocator *al, bvh *t, const collapser *c)
{
    size_t bn = round_up(c->nnodes * sizeof(bvh_node), 64);
    size_t bt = round_up(c->ntri_blocks * sizeof(bvh_tri_block), 64);
    size_t bs = round_up(c->nsphere_blocks * sizeof(bvh_sphere_block), 64);
    size_t total = bn + bt + bs;
    bool huge = total >= HUGE_PAGE;
    size_t align = huge ? HUGE_PAGE : 64;
    unsigned char *raw = mem_alloc(al, total + align);
    if (!raw) return false;
    unsigned char *base = (unsigned char *)round_up((uintptr_t)raw, align);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (huge) madvise(base, total & ~(HUGE_PAGE - 1), MADV_HUGEPAGE);
#endif
    t->mem = raw;
    t->mem_bytes = total;
    t->nodes = (bvh_node *)base;
    t->tris = (bvh_tri_block *)(base + bn);
    t->spheres = c->nsphere_blocks ? (bvh_sphere_block *)(base + bn + bt) : NULL;
    memcpy(t->nodes, c->nodes, c->nnodes * sizeof(bvh_node));
    if (c->ntri_blocks) memcpy(t->tris, c->tris, c->ntri_blocks * sizeof(bvh_tri_block));
    if (c->nsphere_blocks) memcpy(t->spheres, c->spheres, c->nsphere_blocks * sizeof(bvh_sphere_block));
    t->nnodes = c->nnodes;
    t->ntri_blocks = c->ntri_blocks;
    t->nsphere_blocks = c->nsphere_blocks;
    return true;
}

pk_status accel_bvh_create(pk_context *ctx, const accel_input *in, accel **out)
{
    double t0 = time_now();
    const pk_allocator *al = &ctx->alloc;
    *out = NULL;
    size_t nprim_in = in->ntris + in->nspheres;
    if (nprim_in >= UINT32_MAX / 2) {
        return ctx_error(ctx, PK_ERR_LIMIT, "too many primitives for the BVH (%zu)", nprim_in);
    }
    pk_status st = PK_OK;
    bvh *t = mem_calloc(al, 1, sizeof *t);
    sbox *pbox = mem_alloc_aligned(al, (nprim_in ? nprim_in : 1) * sizeof(sbox), 64);
    uint32_t *ids = mem_alloc(al, (nprim_in ? nprim_in : 1) * sizeof(uint32_t));
    bnode *bnodes = NULL;
    dp_entry *dp = NULL;
    collapser c = {0};
    if (!t || !pbox || !ids) goto nomem;

    /* primitive boxes; degenerate triangles and invalid spheres stay out */
    uint32_t n = 0;
    sbox root = sbox_empty(), rootc = sbox_empty();
    for (size_t i = 0; i < in->ntris; i++) {
        const vec3 *p = in->verts + 3 * i;
        if (bvh_tri_degenerate(p[0], p[1], p[2])) continue;
        sbox b;
        b.lo = _mm_setr_ps(fminf(p[0].x, fminf(p[1].x, p[2].x)), fminf(p[0].y, fminf(p[1].y, p[2].y)),
                           fminf(p[0].z, fminf(p[1].z, p[2].z)), 0.0f);
        b.hi = _mm_setr_ps(fmaxf(p[0].x, fmaxf(p[1].x, p[2].x)), fmaxf(p[0].y, fmaxf(p[1].y, p[2].y)),
                           fmaxf(p[0].z, fmaxf(p[1].z, p[2].z)), 0.0f);
        pbox[i] = b;
        ids[n++] = (uint32_t)i;
        root = sbox_union(root, b);
        rootc = sbox_grow(rootc, centroid2(&b));
    }
    bool any_sphere = false;
    for (size_t i = 0; i < in->nspheres; i++) {
        const accel_sphere *s = &in->spheres[i];
        if (!bvh_sphere_valid(s)) continue;
        sbox b;
        b.lo = _mm_setr_ps(s->center.x - s->radius, s->center.y - s->radius, s->center.z - s->radius, 0.0f);
        b.hi = _mm_setr_ps(s->center.x + s->radius, s->center.y + s->radius, s->center.z + s->radius, 0.0f);
        pbox[in->ntris + i] = b;
        ids[n++] = (uint32_t)(in->ntris + i);
        root = sbox_union(root, b);
        rootc = sbox_grow(rootc, centroid2(&b));
        any_sphere = true;
    }

    builder b = {pbox, ids, NULL, 1, (uint32_t)in->ntris, any_sphere};
    size_t cap_b = 2 * (size_t)n + 1;
    bnodes = mem_alloc_aligned(al, cap_b * sizeof *bnodes, 64);
    if (!bnodes) goto nomem;
    b.nodes = bnodes;
    bnodes[0].box = root;
    bnodes[0].first = 0;
    bnodes[0].count = 0;
    bnodes[0].begin = 0;
    bnodes[0].size = 0;
    if (n > 0) {
        int threads = in->threads > 0 ? in->threads : 1;
        if (n < 2 * TASK_MIN) threads = 1;
#pragma omp parallel num_threads(threads) default(none) shared(b, n, rootc)
#pragma omp single
        build_node(&b, 0, 0, n, rootc, 1);
    }

    /* references are 32-bit byte offsets: the arrays must stay below 4 GiB */
    size_t inner = 1, tblocks = 0, sblocks = 0;
    {
        for (uint32_t i = 0; i < b.nnodes; i++) {
            const bnode *x = &bnodes[i];
            if (!x->count) inner++;
            else if (ids[x->first] < in->ntris) tblocks += (x->count + BVH_TRI_LANES - 1) / BVH_TRI_LANES;
            else sblocks += (x->count + BVH_SPHERE_LANES - 1) / BVH_SPHERE_LANES;
        }
        if (inner > (size_t)UINT32_MAX / sizeof(bvh_node) || tblocks > (size_t)UINT32_MAX / sizeof(bvh_tri_block) ||
            sblocks > (size_t)UINT32_MAX / sizeof(bvh_sphere_block)) {
            st = ctx_error(ctx, PK_ERR_LIMIT, "scene too large for the BVH (%u primitives)", n);
            goto fail;
        }
    }

    /* collapse: at most one wide node per binary inner node (+1 for a leaf root) */
    size_t binner_count = (b.nnodes - 1) / 2 + 1;
    c.b = &b;
    c.in = in;
    c.cap_nodes = binner_count + 1;
    c.nodes = mem_alloc_aligned(al, c.cap_nodes * sizeof(bvh_node), 64);
    c.tris = mem_alloc_aligned(al, (tblocks + 1) * sizeof(bvh_tri_block), 64);
    c.spheres = any_sphere ? mem_alloc_aligned(al, (sblocks + 1) * sizeof(bvh_sphere_block), 64) : NULL;
    if (!c.nodes || !c.tris || (any_sphere && !c.spheres)) goto nomem;
    if (n == 0) {
        init_node(&c.nodes[0]);
        c.nnodes = 1;
        c.depth = 1;
    } else {
        dp = mem_alloc(al, b.nnodes * sizeof *dp);
        if (!dp) goto nomem;
        dp_solve(&b, b.nnodes, ids, dp);
        if (dp[0].how[0] == DP_LEAF) {
            init_node(&c.nodes[0]);
            c.nnodes = 1;
            c.depth = 1;
            c.sah += (double)sbox_half_area(bnodes[0].box);
            c.nodes[0].child[0] = make_leaf(&c, &bnodes[0]);
            set_slot_box(&c.nodes[0], 0, bnodes[0].box);
        } else {
            collapse(&c, dp, 0, 1);
        }
    }

    bool ok = place_arrays(al, t, &c);
    if (!ok) goto nomem;
    t->bounds = n ? sbox_aabb(root) : aabb_empty();
    t->depth = c.depth;
    if (t->depth > BVH_MAX_DEPTH) {
        st = ctx_error(ctx, PK_ERR_LIMIT, "BVH deeper than %d levels", BVH_MAX_DEPTH);
        goto fail;
    }

    t->base.ops = &bvh_ops;
    t->base.alloc = al;
    t->base.ntris = in->ntris;
    t->base.nspheres = in->nspheres;
    pk_accel_info *info = &t->base.info;
    info->name = "bvh";
    info->nodes = t->nnodes;
    info->leaves = c.leaves;
    info->primitives = n;
    info->bytes = sizeof *t + t->mem_bytes;
    float ra = sbox_half_area(root);
    info->sah_cost = ra > 0.0f ? c.sah / (double)ra : 0.0;

    mem_free_aligned(al, c.nodes);
    mem_free_aligned(al, c.tris);
    mem_free_aligned(al, c.spheres);
    mem_free_aligned(al, bnodes);
    mem_free_aligned(al, pbox);
    mem_free(al, ids);
    mem_free(al, dp);
    info->build_ms = (time_now() - t0) * 1e3;
    *out = &t->base;
    return PK_OK;

nomem:
    st = ctx_nomem(ctx);
fail:
    mem_free(al, dp);
    mem_free_aligned(al, c.nodes);
    mem_free_aligned(al, c.tris);
    mem_free_aligned(al, c.spheres);
    mem_free_aligned(al, bnodes);
    mem_free_aligned(al, pbox);
    mem_free(al, ids);
    if (t) {
        t->base.alloc = al;
        bvh_destroy(&t->base);
    }
    return st;
}

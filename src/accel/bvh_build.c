/*
 * bvh_build.c - builds the wide BVH: a binned-SAH binary tree with spatial
 * splits (OpenMP tasks over the top levels), collapsed by dynamic
 * programming into BVH_WIDTH-wide SoA nodes with SoA triangle and sphere
 * blocks in the leaves. Invariants: bvh.h; design and measurements:
 * docs/bvh.md.
 */
#include "bvh.h"

#include <immintrin.h>
#include <omp.h>
#include <stdlib.h>
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
#ifndef SPATIAL_EXTRA
#define SPATIAL_EXTRA 0.25 /* spatial splits may add this many references per primitive */
#endif
#define SPATIAL_DEPTH_MAX 24
#define SPATIAL_ALPHA 1e-2f /* ... where children overlap by this fraction of the root's area */

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
 * leaf over references [first, first + count). */
typedef struct bnode {
    sbox box;
    uint32_t first, count;
} bnode;

/* References: a primitive id and the box of the part of it this reference
 * stands for (the whole primitive, or a piece cut by spatial splits). A
 * node's references are contiguous; [end, cap) after them is room that
 * spatial splits in its subtree may fill with duplicated references. */
typedef struct builder {
    sbox *rbox;             /* reference boxes */
    uint32_t *rid;          /* reference primitive ids */
    const accel_input *in;  /* for clipping triangles */
    bnode *nodes;
    uint32_t nnodes;        /* allocated so far (atomic) */
    uint32_t ntris;         /* ids >= ntris are spheres */
    bool spheres;           /* any sphere present */
    float min_overlap;      /* spatial splits are tried above this overlap (half area) */
} builder;

static inline __m128 centroid2(const sbox *b) { return _mm_add_ps(b->lo, b->hi); }

static inline void ref_swap(builder *b, uint32_t i, uint32_t j)
{
    sbox t = b->rbox[i];
    b->rbox[i] = b->rbox[j];
    b->rbox[j] = t;
    uint32_t u = b->rid[i];
    b->rid[i] = b->rid[j];
    b->rid[j] = u;
}

/* Moves references [from, from + n) to [to, to + n) (to >= from). */
static void ref_move(builder *b, uint32_t to, uint32_t from, uint32_t n)
{
    if (to == from || n == 0) return;
    memmove(b->rbox + to, b->rbox + from, n * sizeof *b->rbox);
    memmove(b->rid + to, b->rid + from, n * sizeof *b->rid);
}

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

/* The bin of a reference's doubled centroid on axis: find_split's vector
 * binning, on scalars (the same IEEE operations, so the same bin). */
/* Bin index 0..nbm1 of a position t measured in bins. Clamped in float
 * before the conversion, so that no NaN or out-of-range value is ever
 * converted to int (undefined behaviour): NaN and negatives go to bin 0. */
static inline int bin_clamp(float t, int nbm1)
{
    if (!(t > 0.0f)) return 0;
    if (t >= (float)nbm1) return nbm1;
    return (int)t;
}

static inline int part_bin(const sbox *r, int axis, float lo, float scale, int nbm1)
{
    const float *pl = (const float *)&r->lo, *ph = (const float *)&r->hi;
    return bin_clamp(((pl[axis] + ph[axis]) - lo) * scale, nbm1);
}

/* Binned SAH over the doubled centroids in cb; false when every axis is flat. */
/* Sweeps the nb bins of one axis for the cheapest plane between bins k-1 and
 * k: the left side takes the boxes and lcount of bins < k, the right side the
 * boxes and rcount of bins >= k (object splits pass one count for both,
 * spatial splits their entering and leaving counts). Returns the best k and
 * lowers *cost, or returns 0 when no plane is cheaper than *cost. */
#define SWEEP_MAX_BINS 32
static int sah_sweep(const sbox *bins, const uint32_t *lcount, const uint32_t *rcount, int nb, float *cost)
{
    float rarea[SWEEP_MAX_BINS];
    uint32_t rcnt[SWEEP_MAX_BINS];
    sbox acc = sbox_empty();
    uint32_t cnt = 0;
    for (int k = nb - 1; k > 0; k--) {
        acc = sbox_union(acc, bins[k]);
        cnt += rcount[k];
        rarea[k] = sbox_half_area(acc);
        rcnt[k] = cnt;
    }
    acc = sbox_empty();
    cnt = 0;
    int best = 0;
    for (int k = 1; k < nb; k++) {
        acc = sbox_union(acc, bins[k - 1]);
        cnt += lcount[k - 1];
        if (cnt == 0 || rcnt[k] == 0) continue;
        float c = sbox_half_area(acc) * sah_blocks(cnt) + rarea[k] * sah_blocks(rcnt[k]);
        if (c < *cost) {
            *cost = c;
            best = k;
        }
    }
    return best;
}

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
        const sbox *pb = &b->rbox[i];
        __m128 k4 = _mm_mul_ps(_mm_sub_ps(centroid2(pb), blo), bsc);
        /* clamped in float as bin_clamp does (maxps returns its second operand
         * for NaN, so NaN goes to 0), then truncated: always in 0..nb-1 */
        k4 = _mm_min_ps(_mm_max_ps(k4, _mm_setzero_ps()), _mm_set1_ps((float)(nb - 1)));
        __m128i ki = _mm_cvttps_epi32(k4);
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
        int k = sah_sweep(bins[ax], counts[ax], counts[ax], nb, &best->cost);
        if (k) {
            best->axis = ax;
            best->bin = k;
            found = true;
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

/* ---- spatial splits (Stich, Friedrich and Dietrich 2009) --------------- */

static inline float sbox_get(__m128 v, int axis)
{
    float f[4];
    _mm_storeu_ps(f, v);
    return f[axis];
}
static inline __m128 vset(__m128 v, int axis, float x)
{
    float f[4];
    _mm_storeu_ps(f, v);
    f[axis] = x;
    return _mm_loadu_ps(f);
}

/* Rounds a double box outward to floats. */
static inline float down_f(double x)
{
    float f = (float)x;
    return (double)f > x ? nextafterf(f, -INFINITY) : f;
}
static inline float up_f(double x)
{
    float f = (float)x;
    return (double)f < x ? nextafterf(f, INFINITY) : f;
}

/* The box of the part of reference i (box rb) between planes a <= b on axis:
 * a triangle is clipped exactly (in double, rounded outward), a sphere's box
 * is cut. Empty when nothing of it lies there. */
static sbox clip_ref(const builder *b, uint32_t id, sbox rb, int axis, float a, float bb)
{
    sbox slab = {vset(_mm_set1_ps(-INFINITY), axis, a), vset(_mm_set1_ps(INFINITY), axis, bb)};
    sbox out;
    if (id < b->ntris) {
        const vec3 *v = b->in->verts + 3 * (size_t)id;
        double p[3][3];
        for (int k = 0; k < 3; k++) p[k][0] = v[k].x, p[k][1] = v[k].y, p[k][2] = v[k].z;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        const double pa = a, pb = bb;
        for (int e = 0; e < 3; e++) {
            const double *P = p[e], *Q = p[(e + 1) % 3];
            if (P[axis] >= pa && P[axis] <= pb)
                for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], P[k]), hi[k] = fmax(hi[k], P[k]);
            const double planes[2] = {pa, pb};
            for (int q = 0; q < 2; q++) {
                const double c = planes[q];
                if ((P[axis] < c && Q[axis] > c) || (P[axis] > c && Q[axis] < c)) {
                    const double t = (c - P[axis]) / (Q[axis] - P[axis]);
                    for (int k = 0; k < 3; k++) {
                        double x = k == axis ? c : P[k] + t * (Q[k] - P[k]);
                        lo[k] = fmin(lo[k], x), hi[k] = fmax(hi[k], x);
                    }
                }
            }
        }
        if (!(lo[0] <= hi[0])) return sbox_empty();
        out.lo = _mm_setr_ps(down_f(lo[0]), down_f(lo[1]), down_f(lo[2]), 0.0f);
        out.hi = _mm_setr_ps(up_f(hi[0]), up_f(hi[1]), up_f(hi[2]), 0.0f);
    } else {
        out = rb;
    }
    /* within the reference's box and the slab */
    out.lo = _mm_max_ps(_mm_max_ps(out.lo, rb.lo), slab.lo);
    out.hi = _mm_min_ps(_mm_min_ps(out.hi, rb.hi), slab.hi);
    if ((_mm_movemask_ps(_mm_cmple_ps(out.lo, out.hi)) & 7) != 7) return sbox_empty();
    return out;
}

#define SPATIAL_BINS 16
_Static_assert(NBINS <= SWEEP_MAX_BINS && SPATIAL_BINS <= SWEEP_MAX_BINS, "sweep buffers");

typedef struct sp_split {
    int axis;
    float plane;
    float cost;
} sp_split;

/* Best spatial split of [begin, end) within node box nb: references are
 * binned by their boxes (cut, not clipped: cheap and conservative), each
 * counted where it enters and where it leaves. */
static bool find_spatial(const builder *b, uint32_t begin, uint32_t end, sbox nbox, sp_split *best)
{
    float lo[4], hi[4];
    _mm_storeu_ps(lo, nbox.lo);
    _mm_storeu_ps(hi, nbox.hi);
    best->cost = INFINITY;
    bool found = false;
    float w[3], inv[3];
    bool use[3];
    /* bin k of axis a is the slab [plo[a][k], phi[a][k]], as boxes open on the other axes */
    __m128 plo[3][SPATIAL_BINS], phi[3][SPATIAL_BINS];
    sbox bins[3][SPATIAL_BINS];
    uint32_t enter[3][SPATIAL_BINS], leave[3][SPATIAL_BINS];
    for (int ax = 0; ax < 3; ax++) {
        /* An axis is binned only when its bins have a width the arithmetic
         * can resolve: a finite reciprocal and distinct planes. A box only
         * denormals thick (ext 1e-38: SPATIAL_BINS / ext overflows to inf,
         * and a reference on the box's face then gives 0 * inf = NaN as its
         * bin) or too thin for its coordinates (lo + w == lo near 1e24) has no
         * useful spatial split on that axis. */
        const float ext = hi[ax] - lo[ax];
        w[ax] = ext / SPATIAL_BINS;
        inv[ax] = SPATIAL_BINS / ext;
        use[ax] = ext > 0.0f && isfinite(ext) && isfinite(inv[ax]) && lo[ax] + w[ax] > lo[ax] &&
                  lo[ax] + (float)(SPATIAL_BINS - 1) * w[ax] < hi[ax];
        if (!use[ax]) w[ax] = inv[ax] = 0.0f;
        for (int k = 0; k < SPATIAL_BINS; k++) {
            plo[ax][k] = vset(_mm_set1_ps(-INFINITY), ax, lo[ax] + (float)k * w[ax]);
            phi[ax][k] = vset(_mm_set1_ps(INFINITY), ax, lo[ax] + (float)(k + 1) * w[ax]);
            bins[ax][k] = sbox_empty();
            enter[ax][k] = leave[ax][k] = 0;
        }
    }
    for (uint32_t i = begin; i < end; i++) {
        const sbox *r = &b->rbox[i];
        float rl[4], rh[4];
        _mm_storeu_ps(rl, r->lo);
        _mm_storeu_ps(rh, r->hi);
        for (int ax = 0; ax < 3; ax++) {
            if (!use[ax]) continue;
            const int k0 = bin_clamp((rl[ax] - lo[ax]) * inv[ax], SPATIAL_BINS - 1);
            int k1 = bin_clamp((rh[ax] - lo[ax]) * inv[ax], SPATIAL_BINS - 1);
            if (k1 < k0) k1 = k0;
            enter[ax][k0]++;
            leave[ax][k1]++;
            if (k0 == k1) {
                bins[ax][k0] = sbox_union(bins[ax][k0], *r);
                continue;
            }
            for (int k = k0; k <= k1; k++) {
                sbox piece = {_mm_max_ps(r->lo, plo[ax][k]), _mm_min_ps(r->hi, phi[ax][k])};
                bins[ax][k] = sbox_union(bins[ax][k], piece);
            }
        }
    }
    for (int ax = 0; ax < 3; ax++) {
        if (!use[ax]) continue;
        int k = sah_sweep(bins[ax], enter[ax], leave[ax], SPATIAL_BINS, &best->cost);
        if (k) {
            best->axis = ax;
            best->plane = lo[ax] + (float)k * w[ax];
            found = true;
        }
    }
    return found;
}

static void range_bounds(const builder *b, uint32_t begin, uint32_t end, sbox *box, sbox *cb)
{
    sbox bx = sbox_empty(), c = sbox_empty();
    for (uint32_t i = begin; i < end; i++) {
        const sbox *pb = &b->rbox[i];
        bx = sbox_union(bx, *pb);
        c = sbox_grow(c, centroid2(pb));
    }
    *box = bx;
    *cb = c;
}

/* Splits [begin, end) at plane on axis into [begin, begin + nl) and
 * [rbegin, rbegin + nr), cutting the references that straddle the plane in
 * two; false (nothing changed) when that does not fit before cap. */
static bool do_spatial(builder *b, uint32_t begin, uint32_t end, uint32_t cap, int axis, float plane,
                       uint32_t *nl_out, uint32_t *rbegin_out, uint32_t *nr_out)
{
    /* three groups: left only | straddling | right only */
    uint32_t i = begin, m = begin, j = end;
    while (m < j) {
        const float lo = sbox_get(b->rbox[m].lo, axis), hi = sbox_get(b->rbox[m].hi, axis);
        if (hi <= plane) ref_swap(b, i++, m++);
        else if (lo >= plane) ref_swap(b, m, --j);
        else m++;
    }
    const uint32_t n0 = i - begin, ns = j - i, nr0 = end - j;
    const uint32_t n = end - begin, nl = n0 + ns, nr = nr0 + ns;
    if (ns == 0 || nl == 0 || nr == 0 || (size_t)nl + nr > (size_t)cap - begin) return false;
    /* the room left over goes to the children in proportion to their sizes */
    const uint32_t slack = cap - begin - nl - nr;
    const uint32_t rbegin = begin + nl + (uint32_t)((uint64_t)slack * nl / (nl + nr));
    ref_move(b, rbegin + ns, j, nr0);
    for (uint32_t k = 0; k < ns; k++) {
        const uint32_t at = i + k, id = b->rid[at];
        const sbox rb = b->rbox[at];
        sbox l = clip_ref(b, id, rb, axis, -INFINITY, plane);
        sbox r = clip_ref(b, id, rb, axis, plane, INFINITY);
        /* a piece lost to rounding keeps the cut box: still conservative */
        if (!(sbox_half_area(l) > 0.0f || (_mm_movemask_ps(_mm_cmple_ps(l.lo, l.hi)) & 7) == 7)) {
            l = rb;
            l.hi = vset(l.hi, axis, plane);
        }
        if (!(sbox_half_area(r) > 0.0f || (_mm_movemask_ps(_mm_cmple_ps(r.lo, r.hi)) & 7) == 7)) {
            r = rb;
            r.lo = vset(r.lo, axis, plane);
        }
        b->rbox[at] = l;
        b->rbox[rbegin + k] = r;
        b->rid[rbegin + k] = id;
    }
    (void)n;
    *nl_out = nl;
    *rbegin_out = rbegin;
    *nr_out = nr;
    return true;
}

/* Moves the triangles of [begin, end) before its spheres; returns the boundary. */
static uint32_t partition_kind(builder *b, uint32_t begin, uint32_t end)
{
    uint32_t i = begin, j = end;
    while (i < j) {
        if (b->rid[i] < b->ntris) i++;
        else ref_swap(b, i, --j);
    }
    return i;
}

static void build_node(builder *b, uint32_t ni, uint32_t begin, uint32_t end, uint32_t cap, sbox cb, int depth);

/* Children over [begin, begin + nl) and [rbegin, rbegin + nr); the room up to
 * cap is shared in proportion to their sizes (moving the right references). */
static void build_children(builder *b, uint32_t ni, uint32_t begin, uint32_t nl, uint32_t rbegin, uint32_t nr,
                           uint32_t cap, sbox lbox, sbox lcb, sbox rbox, sbox rcb, int depth)
{
    if (rbegin == begin + nl && cap > rbegin + nr) {
        const uint32_t slack = cap - begin - nl - nr;
        const uint32_t to = begin + nl + (uint32_t)((uint64_t)slack * nl / (nl + nr));
        ref_move(b, to, rbegin, nr);
        rbegin = to;
    }
    const uint32_t lcap = rbegin;
    uint32_t k = node_alloc2(b);
    b->nodes[ni].first = k;
    b->nodes[ni].count = 0;
    b->nodes[k].box = lbox;
    b->nodes[k + 1].box = rbox;
    if (nl + nr >= TASK_MIN) {
#pragma omp task default(none) firstprivate(b, k, begin, nl, lcap, lcb, depth)
        build_node(b, k, begin, begin + nl, lcap, lcb, depth + 1);
        build_node(b, k + 1, rbegin, rbegin + nr, cap, rcb, depth + 1);
    } else {
        build_node(b, k, begin, begin + nl, lcap, lcb, depth + 1);
        build_node(b, k + 1, rbegin, rbegin + nr, cap, rcb, depth + 1);
    }
}

/* nodes[ni].box is set by the caller; cb bounds the doubled centroids;
 * [end, cap) is free for duplicated references. */
static void build_node(builder *b, uint32_t ni, uint32_t begin, uint32_t end, uint32_t cap, sbox cb, int depth)
{
    const uint32_t n = end - begin;
    split s = {0, 0, INFINITY, sbox_empty(), sbox_empty()};
    binner bn = {{0.0f}, {0.0f}, 1};
    bool ok = n > 1 && depth < SAH_DEPTH_MAX && find_split(b, begin, end, cb, &bn, &s);
    const float area = sbox_half_area(b->nodes[ni].box);

    /* a spatial split when the object split's children overlap and there is room */
    sp_split sp = {0, 0.0f, INFINITY};
    bool spatial = false;
    if (ok && cap > end && n > BIN_LEAF_MAX && depth < SPATIAL_DEPTH_MAX) {
        sbox ov = {_mm_max_ps(s.left.lo, s.right.lo), _mm_min_ps(s.left.hi, s.right.hi)};
        if (sbox_half_area(ov) > b->min_overlap && find_spatial(b, begin, end, b->nodes[ni].box, &sp) &&
            sp.cost < s.cost)
            spatial = true;
    }

    if (n <= BIN_LEAF_MAX) {
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
            build_children(b, ni, begin, mid - begin, mid, end - mid, cap, lbox, lcb, rbox, rcb, depth);
            return;
        }
    }

    sbox lbox, lcb, rbox, rcb;
    if (spatial) {
        uint32_t nl, rbegin, nr;
        if (do_spatial(b, begin, end, cap, sp.axis, sp.plane, &nl, &rbegin, &nr)) {
            range_bounds(b, begin, begin + nl, &lbox, &lcb);
            range_bounds(b, rbegin, rbegin + nr, &rbox, &rcb);
            build_children(b, ni, begin, nl, rbegin, nr, cap, lbox, lcb, rbox, rcb, depth);
            return;
        }
        /* did not fit: the object split (the order of references does not matter to it) */
    }
    uint32_t mid;
    if (ok) {
        const int ax = s.axis, sb = s.bin;
        /* part_bin: the same bins as find_split's binning */
        const float blo = bn.lo[ax], bsc = bn.scale[ax];
        const int nbm1 = bn.nbins - 1;
        uint32_t i = begin, j = end;
        lcb = sbox_empty();
        rcb = sbox_empty();
        for (;;) {
            while (i < j) {
                if (part_bin(&b->rbox[i], ax, blo, bsc, nbm1) >= sb) break;
                lcb = sbox_grow(lcb, centroid2(&b->rbox[i]));
                i++;
            }
            while (i < j) {
                if (part_bin(&b->rbox[j - 1], ax, blo, bsc, nbm1) < sb) break;
                __m128 c = centroid2(&b->rbox[j - 1]);
                rcb = sbox_grow(rcb, c);
                j--;
            }
            if (i >= j) break;
            ref_swap(b, i, j - 1);
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
    build_children(b, ni, begin, mid - begin, mid, end - mid, cap, lbox, lcb, rbox, rcb, depth);
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
    float grow;       /* every slot's box grows by this much on each side (scene_grow) */
} collapser;

/* The primitives of binary subtree bi (at most BVH_LEAF_MAX references). */
static uint32_t gather_ids(const builder *b, uint32_t bi, uint32_t *ids, uint32_t n)
{
    const bnode *x = &b->nodes[bi];
    if (x->count) {
        for (uint32_t k = 0; k < x->count && n < BVH_LEAF_MAX; k++) ids[n++] = b->rid[x->first + k];
        return n;
    }
    n = gather_ids(b, x->first, ids, n);
    return gather_ids(b, x->first + 1, ids, n);
}

/* A leaf of the references in binary subtree bi: their primitives sorted,
 * pieces of one primitive (spatial splits) merged. */
static uint32_t make_leaf(collapser *c, uint32_t bi)
{
    const bnode *bn = &c->b->nodes[bi];
    uint32_t ids[BVH_LEAF_MAX];
    uint32_t n = gather_ids(c->b, bi, ids, 0);
    PK_ASSERT(n >= 1 && n <= BVH_LEAF_MAX);
    for (uint32_t i = 1; i < n; i++) {
        uint32_t v = ids[i], j = i;
        for (; j > 0 && ids[j - 1] > v; j--) ids[j] = ids[j - 1];
        ids[j] = v;
    }
    uint32_t u = 0;
    for (uint32_t i = 0; i < n; i++)
        if (u == 0 || ids[i] != ids[u - 1]) ids[u++] = ids[i];
    n = u;
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

/* How far every box of the tree reaches beyond its primitives, for a scene
 * whose bounding box has diagonal diag: 2^-18 diag (4 mm in a 1 km scene).
 * The triangle test's t is exact only up to rounding relative to the
 * vertices' distances from the ray's origin, not to t: a large triangle hit
 * near the origin can report a t below the entry distance of its own leaf's
 * box, and the search, which skips boxes entered beyond the closest t so
 * far, would then miss it where brute force finds it. The test's t is a
 * weighted mean of the vertices' distances along the ray, each within a few
 * ulps (2^-24 relative) of the vertices' distances from the origin, at most
 * the diagonal (bounded here by the sum of the extents) for an origin in the
 * scene; boxes this much larger contain
 * every hit point the test can report. (Rays from farther away hit at
 * distances comparable to their distance from the scene, which the relative
 * BVH_BOX_SLACK covers.) */
static float scene_grow(sbox root)
{
    const aabb a = sbox_aabb(root);
    /* the sum of the extents bounds the diagonal without squaring (no overflow for huge scenes) */
    const vec3 e = v3_sub(a.hi, a.lo);
    const float d = e.x + e.y + e.z;
    return d > 0.0f ? d * 0x1p-18f : 0.0f; /* an empty scene: 0 (NaN fails the test too) */
}

/* lo - g and hi + g, rounded outward (monotone in lo and hi, so that nested
 * boxes stay nested) */
static float grow_lo(float lo, float g) { return g > 0.0f ? nextafterf(lo - g, -INFINITY) : lo; }
static float grow_hi(float hi, float g) { return g > 0.0f ? nextafterf(hi + g, INFINITY) : hi; }

static void set_slot_box(bvh_node *wn, int k, sbox box, float g)
{
    aabb a = sbox_aabb(box);
    a.lo = v3(grow_lo(a.lo.x, g), grow_lo(a.lo.y, g), grow_lo(a.lo.z, g));
    a.hi = v3(grow_hi(a.hi.x, g), grow_hi(a.hi.y, g), grow_hi(a.hi.z, g));
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
 * subtree, up to costs->leaf_max primitives of one kind, COST_BLOCK per
 * block of costs->lanes) or a wide node (costs->node plus the best
 * distribution of its children over BVH_WIDTH slots). The CPU's costs:
 * COST_NODE, blocks of BVH_TRI_LANES, BVH_LEAF_MAX. Costs are areas times the per-visit cost; the root's is
 * the tree's SAH cost in those units. */
enum { DP_LEAF = 0, DP_NODE = 1, DP_FEWER = 0 };

typedef struct dp_entry {
    float cost[BVH_WIDTH];
    uint8_t how[BVH_WIDTH];  /* [0]: DP_LEAF or DP_NODE; [i>0]: DP_FEWER or k, slots given to the left child */
    uint8_t split;           /* as a wide node: slots given to the left child */
    uint32_t spheres;        /* sphere references in the subtree */
    uint32_t size;           /* references in the subtree */
} dp_entry;

static void dp_solve(const builder *b, const bvh_costs *costs, uint32_t nnodes, dp_entry *dp)
{
    for (uint32_t ii = nnodes; ii-- > 0;) {
        const bnode *x = &b->nodes[ii];
        dp_entry *e = &dp[ii];
        const float area = sbox_half_area(x->box);
        if (x->count) {
            e->spheres = 0;
            for (uint32_t k = 0; k < x->count; k++) e->spheres += b->rid[x->first + k] >= b->ntris;
            e->size = x->count;
        } else {
            e->spheres = dp[x->first].spheres + dp[x->first + 1].spheres;
            e->size = dp[x->first].size + dp[x->first + 1].size;
        }
        const uint32_t size = e->size;
        const bool mixed = e->spheres != 0 && e->spheres != size;
        const uint32_t lanes = e->spheres ? BVH_SPHERE_LANES : costs->lanes;
        /* a flag, not an infinite cost: areas overflow to inf in huge scenes */
        const bool leaf_ok = size <= costs->leaf_max && !mixed;
        const float leaf = leaf_ok ? COST_BLOCK * (float)((size + lanes - 1) / lanes) * area : INFINITY;
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
        const float node = costs->node * area + dist[BVH_WIDTH];
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
        uint32_t ref = dp[kids[q]].how[0] == DP_LEAF ? make_leaf(c, kids[q])
                                                     : bvh_node_ref(collapse(c, dp, kids[q], depth + 1));
        bvh_node *wn = &c->nodes[wi]; /* index, not pointer, across recursion */
        wn->child[q] = ref;
        set_slot_box(wn, q, x->box, c->grow);
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

static const accel_ops bvh_ops = {bvh_destroy, bvh_intersect, bvh_occluded, bvh_intersect_packet, NULL, NULL};
#if PK_HAVE_AVX512_KERNELS
static const accel_ops bvh_ops_avx512 = {bvh_destroy, bvh_intersect_avx512, bvh_occluded_avx512,
                                         bvh_intersect_packet_avx512, NULL, NULL};
#endif

bool bvh_use_avx512(const pk_context *ctx)
{
#if PK_HAVE_AVX512_KERNELS
    /* __builtin_cpu_supports also asks the OS (XCR0) whether it saves the
     * AVX-512 state */
    __builtin_cpu_init();
    if (!(__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
          __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
          __builtin_cpu_supports("avx512vl")))
        return false;
    return !(ctx && ctx->config.cpu_avx2);
#else
    (void)ctx;
    return false;
#endif
}

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
    return accel_bvh_create_costs(ctx, in, NULL, out);
}

pk_status accel_bvh_create_costs(pk_context *ctx, const accel_input *in, const bvh_costs *costs, accel **out)
{
    double t0 = time_now();
    /* the CPU's: a node visit costs COST_NODE block tests of BVH_TRI_LANES triangles */
    bvh_costs k = {COST_NODE, BVH_TRI_LANES, BVH_LEAF_MAX};
    if (costs) {
        k = *costs;
        if (!(k.node > 0.0f) || k.lanes < 1 || k.leaf_max < BIN_LEAF_MAX || k.leaf_max > BVH_LEAF_MAX)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                             "BVH costs: node cost %g, %u lanes, %u primitives a leaf (%d to %d)", (double)k.node,
                             k.lanes, k.leaf_max, BIN_LEAF_MAX, BVH_LEAF_MAX);
    }
    const pk_allocator *al = &ctx->alloc;
    *out = NULL;
    size_t nprim_in = in->ntris + in->nspheres;
    if (nprim_in >= UINT32_MAX / 2) {
        return ctx_error(ctx, PK_ERR_LIMIT, "too many primitives for the BVH (%zu)", nprim_in);
    }
    pk_status st = PK_OK;
    bvh *t = mem_calloc(al, 1, sizeof *t);
    /* room for the references that spatial splits add */
    const size_t cap_refs = nprim_in + (size_t)((double)nprim_in * SPATIAL_EXTRA) + 1;
    sbox *rbox = mem_alloc_aligned(al, cap_refs * sizeof(sbox), 64);
    uint32_t *rid = mem_alloc(al, cap_refs * sizeof(uint32_t));
    bnode *bnodes = NULL;
    dp_entry *dp = NULL;
    collapser c = {0};
    if (!t || !rbox || !rid) goto nomem;

    /* primitive boxes; degenerate triangles and invalid spheres stay out */
    uint32_t n = 0;
    sbox root = sbox_empty(), rootc = sbox_empty();
    for (size_t i = 0; i < in->ntris; i++) {
        const vec3 *p = in->verts + 3 * i;
        if (bvh_tri_degenerate(p[0], p[1], p[2])) continue;
        /* finite vertices (not degenerate): SSE min/max, not libm's fminf */
        const __m128 a = _mm_setr_ps(p[0].x, p[0].y, p[0].z, 0.0f), b1 = _mm_setr_ps(p[1].x, p[1].y, p[1].z, 0.0f),
                     c2 = _mm_setr_ps(p[2].x, p[2].y, p[2].z, 0.0f);
        sbox bx = {_mm_min_ps(a, _mm_min_ps(b1, c2)), _mm_max_ps(a, _mm_max_ps(b1, c2))};
        rbox[n] = bx;
        rid[n++] = (uint32_t)i;
        root = sbox_union(root, bx);
        rootc = sbox_grow(rootc, centroid2(&bx));
    }
    bool any_sphere = false;
    for (size_t i = 0; i < in->nspheres; i++) {
        const accel_sphere *sp = &in->spheres[i];
        if (!bvh_sphere_valid(sp)) continue;
        sbox bx;
        bx.lo = _mm_setr_ps(sp->center.x - sp->radius, sp->center.y - sp->radius, sp->center.z - sp->radius, 0.0f);
        bx.hi = _mm_setr_ps(sp->center.x + sp->radius, sp->center.y + sp->radius, sp->center.z + sp->radius, 0.0f);
        rbox[n] = bx;
        rid[n++] = (uint32_t)(in->ntris + i);
        root = sbox_union(root, bx);
        rootc = sbox_grow(rootc, centroid2(&bx));
        any_sphere = true;
    }
    /* bvh.quality=fast: no spatial splits (no room for duplicates) */
    const bool high = !ctx->config.bvh_fast;
    const uint32_t cap = n + (high ? (uint32_t)((double)n * SPATIAL_EXTRA) : 0);

    builder b = {rbox, rid, in, NULL, 1, (uint32_t)in->ntris, any_sphere, 0.0f};
    b.min_overlap = SPATIAL_ALPHA * sbox_half_area(root);
    size_t cap_b = 2 * (size_t)cap + 1;
    bnodes = mem_alloc_aligned(al, cap_b * sizeof *bnodes, 64);
    if (!bnodes) goto nomem;
    b.nodes = bnodes;
    bnodes[0].box = root;
    bnodes[0].first = 0;
    bnodes[0].count = 0;
    if (n > 0) {
        int threads = in->threads > 0 ? in->threads : 1;
        if (n < 2 * TASK_MIN) threads = 1;
#pragma omp parallel num_threads(threads) default(none) shared(b, n, cap, rootc)
#pragma omp single
        build_node(&b, 0, 0, n, cap, rootc, 1);
    }

    /* references are 32-bit byte offsets: the arrays must stay below 4 GiB */
    size_t inner = 1, tblocks = 0, sblocks = 0;
    {
        for (uint32_t i = 0; i < b.nnodes; i++) {
            const bnode *x = &bnodes[i];
            if (!x->count) inner++;
            else if (rid[x->first] < in->ntris) tblocks += (x->count + BVH_TRI_LANES - 1) / BVH_TRI_LANES;
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
    c.grow = scene_grow(root);
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
        dp_solve(&b, &k, b.nnodes, dp);
        if (dp[0].how[0] == DP_LEAF) {
            init_node(&c.nodes[0]);
            c.nnodes = 1;
            c.depth = 1;
            c.sah += (double)sbox_half_area(bnodes[0].box);
            c.nodes[0].child[0] = make_leaf(&c, 0);
            set_slot_box(&c.nodes[0], 0, bnodes[0].box, c.grow);
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
    t->base.isa = "avx2";
#if PK_HAVE_AVX512_KERNELS
    if (bvh_use_avx512(ctx)) t->base.ops = &bvh_ops_avx512, t->base.isa = "avx512";
#endif
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
    mem_free_aligned(al, rbox);
    mem_free(al, rid);
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
    mem_free_aligned(al, rbox);
    mem_free(al, rid);
    if (t) {
        t->base.alloc = al;
        bvh_destroy(&t->base);
    }
    return st;
}

/*
 * bvh_gpu.h - the BVH as the GPU traverses it, and the traversal itself,
 * written once: plain C over plain structs, PK_HD so that nvcc compiles the
 * same functions for the device (src/accel/cuda/trace.cu) that the CPU
 * tests call on the host (tests/unit/test_bvh_gpu.c). The few intrinsics
 * (16-byte __ldg loads, __byte_perm, __fmaf_rn) have host versions that
 * compute the same bits.
 *
 * Layout (docs/gpu.md says why): the 8-wide tree of bvh.h, node for node,
 * with each node's eight child boxes quantised to 8 bits per plane in a
 * frame of the node's own (origin = the low corner of the union of its
 * children, one power-of-two scale per axis), after Ylitie, Karras and
 * Laine 2017. A node is 96 bytes (three 32-byte memory sectors) where the
 * CPU's float node is 224: a ray that visits it reads eight boxes, the
 * child references and the frame at once. Leaves are runs of 48-byte
 * triangle records (the three vertices as they are in the scene, and the
 * triangle's number), so the test is geom.h's watertight test, operation
 * for operation, and gives the same t, u, v bit for bit (the device code is
 * compiled with -fmad=false, the CPU's with -ffp-contract=off).
 *
 * Decoded planes are org + q * 2^e computed in float; the converter picks q
 * (rounding down for low planes, up for high ones, and checking the float
 * result) so that every decoded box contains the CPU's float box: the slab
 * test over it, with the CPU's rounding slack, can only enter more boxes
 * than the CPU traversal does, never fewer, so no hit is lost; the closest
 * hit rule (smallest t, then smallest number) makes the answer independent
 * of the order in which leaves are visited (but for exact ties between
 * different triangles, see docs/gpu.md; the exact box tests visit in the
 * CPU's order).
 */
#ifndef PK_BVH_GPU_H
#define PK_BVH_GPU_H

#include "../paprsek_internal.h"
#include "tri_test.h"

#include <math.h>
#include <string.h>

#define GPU_WIDTH 8
/* Traversal stack entries; the converter refuses a tree that could need
 * more (gpu_layout.stack_need). */
#define GPU_STACK 128
#define GPU_EMPTY 0xFFFFFFFFu
/* Child reference: bit 31 clear: index of an inner node; set: a leaf of
 * ((ref >> 27) & 15) + 1 triangle records from index ref & GPU_LEAF_INDEX. */
#define GPU_LEAF 0x80000000u
#define GPU_LEAF_SHIFT 27
#define GPU_LEAF_MAX 16u
#define GPU_LEAF_INDEX 0x07FFFFFFu
/* Relative slack of the far slab distances and of the cull distance: the
 * CPU traversal's (bvh.h BVH_BOX_SLACK). */
#define GPU_BOX_SLACK 0x1p-20f

/* Plane rows in bvh.h's order: lo_x, hi_x, lo_y, hi_y, lo_z, hi_z. */
typedef struct gpu_node {
    float org[3];               /* low corner of the frame */
    uint8_t ex[3];              /* per axis: scale 2^(ex - 127), ex in 1..254 */
    uint8_t pad;
    uint8_t q[6][GPU_WIDTH];    /* quantised planes [row][child] */
    uint32_t child[GPU_WIDTH];  /* references as above; GPU_EMPTY for an unused slot */
} gpu_node;

typedef struct gpu_tri {
    float a[3];
    uint32_t prim;              /* the triangle's number in the scene */
    float b[3];
    float pad0;
    float c[3];
    float pad1;
} gpu_tri;

#ifndef __cplusplus
_Static_assert(sizeof(gpu_node) == 96 && sizeof(gpu_tri) == 48, "GPU node and triangle sizes");
#endif

static inline PK_HD uint32_t gpu_leaf_ref(uint32_t first, uint32_t count)
{
    return GPU_LEAF | ((count - 1u) << GPU_LEAF_SHIFT) | first;
}
static inline PK_HD uint32_t gpu_leaf_count(uint32_t ref) { return ((ref >> GPU_LEAF_SHIFT) & 15u) + 1u; }
static inline PK_HD uint32_t gpu_leaf_first(uint32_t ref) { return ref & GPU_LEAF_INDEX; }

/* 2^(biased - 127) for biased in 1..254 (a normal float, exact). */
static inline PK_HD float gpu_scale(unsigned biased)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float((unsigned)biased << 23);
#else
    uint32_t bits = (uint32_t)biased << 23;
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
#endif
}

/* A decoded plane: org + q * scale (q * scale is exact, the sum rounds). */
static inline PK_HD float gpu_plane(float org, unsigned q, float scale) { return org + (float)q * scale; }

/* The SSE min/max rules of the CPU traversal: a NaN first operand (0 * inf,
 * a ray lying in a slab plane) gives the second, i.e. no limit. */
static inline PK_HD float gpu_max(float a, float b) { return a > b ? a : b; }
static inline PK_HD float gpu_min(float a, float b) { return a < b ? a : b; }

static inline PK_HD float gpu_cull_limit(float t) { return t + fabsf(t) * GPU_BOX_SLACK; }

/* geom.h's ray_rcp. */
static inline PK_HD float gpu_rcp(float d)
{
    const float r = 1.0f / d;
    return d != 0.0f && isinf(r) ? NAN : r;
}

/* geom.h's ray_traceable. */
static inline PK_HD bool gpu_ray_traceable(const pk_ray *r)
{
    return isfinite(r->org[0]) && isfinite(r->org[1]) && isfinite(r->org[2]) && !isnan(r->dir[0]) &&
           !isnan(r->dir[1]) && !isnan(r->dir[2]) && !isnan(r->tmin) && !isnan(r->tmax);
}

/* What traversal needs of a ray: box and triangle constants. */
typedef struct gpu_ray {
    float o[3];
    float rd[3], rdf[3];     /* 1/d, and 1/d * (1 + slack) for far planes */
    int near[3], far[3];     /* plane rows per axis: 2 * axis + (1/d < 0), and the other */
    int kx, ky, kz;          /* shear axes (geom.h ray_prepare) */
    float ox, oy, oz;        /* origin components along kx, ky, kz (no indexing by a variable
                                in the triangle test: the ray stays in registers on the GPU) */
    float sx, sy, sz;
    float tmin;
} gpu_ray;

static inline PK_HD void gpu_ray_init(gpu_ray *g, const pk_ray *r)
{
    for (int k = 0; k < 3; k++) {
        g->o[k] = r->org[k];
        const float rd = gpu_rcp(r->dir[k]);
        g->rd[k] = rd;
        g->rdf[k] = rd * (1.0f + GPU_BOX_SLACK);
        const int neg = signbit(rd) ? 1 : 0;
        g->near[k] = 2 * k + neg;
        g->far[k] = 2 * k + 1 - neg;
    }
    g->tmin = r->tmin;
    /* kz: the largest |d| component (vec3.h v3_max_axis_abs), then ray_prepare's axes */
    const float x = fabsf(r->dir[0]), y = fabsf(r->dir[1]), z = fabsf(r->dir[2]);
    const int kz = (x > y) ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
    int kx = kz + 1 == 3 ? 0 : kz + 1;
    int ky = kx + 1 == 3 ? 0 : kx + 1;
    const float dz = r->dir[kz];
    if (dz < 0.0f) {
        const int tmp = kx;
        kx = ky;
        ky = tmp;
    }
    g->kx = kx, g->ky = ky, g->kz = kz;
    g->ox = r->org[kx], g->oy = r->org[ky], g->oz = r->org[kz];
    g->sx = r->dir[kx] / dz;
    g->sy = r->dir[ky] / dz;
    g->sz = 1.0f / dz;
}

/* geom.h's tri_intersect: the same test (tri_test.h) on the GPU's records. */
static inline PK_HD bool gpu_tri_intersect(const gpu_ray *r, const gpu_tri *tri, float tmax, float *t_out,
                                           float *u_out, float *v_out)
{
    const float ox = r->ox, oy = r->oy, oz = r->oz;
    return tri_test_watertight(tri->a[r->kx] - ox, tri->a[r->ky] - oy, tri->a[r->kz] - oz, tri->b[r->kx] - ox,
                               tri->b[r->ky] - oy, tri->b[r->kz] - oz, tri->c[r->kx] - ox, tri->c[r->ky] - oy,
                               tri->c[r->kz] - oz, r->sx, r->sy, r->sz, r->tmin, tmax, t_out, u_out, v_out);
}

/* Slots of node n whose decoded box the segment [tmin, tcull] touches, with
 * their entry distances in tn[]: the first version (v0), reading the node
 * byte by byte with the ray's plane rows as run-time indices. */
static inline PK_HD unsigned gpu_node_hits_v0(const gpu_node *n, const gpu_ray *r, float tcull, float tn[GPU_WIDTH])
{
    const float sx = gpu_scale(n->ex[0]), sy = gpu_scale(n->ex[1]), sz = gpu_scale(n->ex[2]);
    unsigned mask = 0;
    for (int k = 0; k < GPU_WIDTH; k++) {
        if (n->child[k] == GPU_EMPTY) continue;
        const float tnx = (gpu_plane(n->org[0], n->q[r->near[0]][k], sx) - r->o[0]) * r->rd[0];
        const float tny = (gpu_plane(n->org[1], n->q[r->near[1]][k], sy) - r->o[1]) * r->rd[1];
        const float tnz = (gpu_plane(n->org[2], n->q[r->near[2]][k], sz) - r->o[2]) * r->rd[2];
        const float tfx = (gpu_plane(n->org[0], n->q[r->far[0]][k], sx) - r->o[0]) * r->rdf[0];
        const float tfy = (gpu_plane(n->org[1], n->q[r->far[1]][k], sy) - r->o[1]) * r->rdf[1];
        const float tfz = (gpu_plane(n->org[2], n->q[r->far[2]][k], sz) - r->o[2]) * r->rdf[2];
        const float near = gpu_max(tnx, gpu_max(tny, gpu_max(tnz, r->tmin)));
        const float far = gpu_min(tfx, gpu_min(tfy, gpu_min(tfz, tcull)));
        tn[k] = near;
        if (near <= far) mask |= 1u << k;
    }
    return mask;
}

typedef struct gpu_stack_entry {
    uint32_t ref;
    float t;   /* entry distance of the child's box */
} gpu_stack_entry;

/* Traversal counters (the host path counts; the kernel passes NULL). */
typedef struct gpu_counters {
    uint64_t nodes, tests;
} gpu_counters;

/* The first traversal (kernel v0, kept to be timed against gpu_trace):
 * gpu_node_hits_v0, every hit child pushed with an insertion sort and the
 * nearest popped again, triangles read field by field. Same answers as
 * gpu_trace, bit for bit (the same arithmetic, the same visiting order). */
static inline PK_HD bool gpu_trace_v0(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *in, bool any,
                                   pk_hit *out, gpu_counters *count)
{
    out->t = INFINITY;
    out->prim = PK_NO_HIT;
    out->u = out->v = 0.0f;
    if (!gpu_ray_traceable(in)) return false;
    gpu_ray r;
    gpu_ray_init(&r, in);
    float best_t = in->tmax, best_u = 0.0f, best_v = 0.0f;
    uint32_t best_prim = PK_NO_HIT;
    float tcull = gpu_cull_limit(best_t);

    gpu_stack_entry stack[GPU_STACK];
    int sp = 0;
    uint32_t ref = 0;
    for (;;) {
        while (!(ref & GPU_LEAF)) {
            const gpu_node *n = &nodes[ref];
            if (count) count->nodes++;
            float tn[GPU_WIDTH];
            unsigned mask = gpu_node_hits_v0(n, &r, tcull, tn);
            if (!mask) goto pop;
            /* push every hit child, sort the run far to near, take the nearest */
            const int base = sp;
            for (int k = 0; k < GPU_WIDTH; k++) {
                if (!(mask >> k & 1u)) continue;
                gpu_stack_entry e = {n->child[k], tn[k]};
                int j = sp++;
                for (; j > base && stack[j - 1].t < e.t; j--) stack[j] = stack[j - 1];
                stack[j] = e;
            }
            ref = stack[--sp].ref;
        }
        {
            if (count) count->nodes++;
            const uint32_t first = gpu_leaf_first(ref), cnt = gpu_leaf_count(ref);
            for (uint32_t i = 0; i < cnt; i++) {
                const gpu_tri *tri = &tris[first + i];
                float t, u, v;
                if (count) count->tests++;
                if (!gpu_tri_intersect(&r, tri, best_t, &t, &u, &v)) continue;
                const uint32_t prim = tri->prim;
                if (t < best_t || (t == best_t && prim < best_prim)) {
                    best_t = t, best_prim = prim, best_u = u, best_v = v;
                    if (any) goto done;
                }
            }
            tcull = gpu_cull_limit(best_t);
        }
    pop:
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (stack[sp].t <= tcull) {
                ref = stack[sp].ref;
                break;
            }
        }
    }
done:
    if (best_prim == PK_NO_HIT) return false;
    out->t = best_t;
    out->prim = best_prim;
    out->u = best_u;
    out->v = best_v;
    return true;
}

/* ---- the traversal (the kernels of cuda/trace.cu; docs/gpu.md) --------------
 * The same arithmetic and the same visiting order as gpu_trace_v0, so the
 * same answers bit for bit, arranged for the GPU:
 *  - a node is read as six 16-byte loads into 24 registers (gpu_node_load)
 *    and its bytes are taken out with constant shifts: the ray's near and
 *    far rows per axis are chosen by a select on the ray's direction signs,
 *    never by indexing memory with a run-time row;
 *  - the eight slots are unrolled, so the entry distances stay in
 *    registers; the nearest hit child is kept in a register and goes next,
 *    only the others are pushed (still sorted far to near);
 *  - a triangle record is three 16-byte loads, its vertices permuted to the
 *    ray's axes by selects. */

#if defined(__CUDACC__)
#define GPU_UNROLL _Pragma("unroll")
#else
#define GPU_UNROLL
#endif

static inline PK_HD float gpu_bits_float(uint32_t u)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(u);
#else
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
#endif
}

/* The 96 bytes of a node as 24 words: 0-2 org, 3 the exponents (byte k:
 * axis k), 4 + 2 * row + (slot >= 4) the plane row's bytes of four slots
 * (byte slot & 3), 16 + slot the child references. */
static inline PK_HD void gpu_node_load(const gpu_node *n, uint32_t w[24])
{
#if defined(__CUDA_ARCH__)
    const uint4 *p = (const uint4 *)n;
    GPU_UNROLL
    for (int i = 0; i < 6; i++) {
        const uint4 v = __ldg(p + i);
        w[4 * i] = v.x, w[4 * i + 1] = v.y, w[4 * i + 2] = v.z, w[4 * i + 3] = v.w;
    }
#else
    memcpy(w, n, sizeof *n);
#endif
}

/* Byte b (0..3, a constant) of word w as a float, exactly: the bits of
 * 2^23 + byte, less 2^23 (one byte permute and one add on the GPU). */
static inline PK_HD float gpu_byte_float(uint32_t w, int b)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(__byte_perm(w, 0x4B000000u, 0x7540u | (unsigned)b)) - 8388608.0f;
#else
    return gpu_bits_float(0x4B000000u | ((w >> (8 * b)) & 255u)) - 8388608.0f;
#endif
}

/* Box tests on a node in registers (gpu_node_load). Each fills tn[] with
 * the entry distances and returns the mask of the slots whose box the
 * segment [tmin, tcull] touches; all enter every box the CPU's traversal
 * enters (docs/gpu.md). GPU_BOX_INLINE lets the PTX check
 * (tests/cuda/test_cuda_ptx.sh) keep them out of line, to see that their
 * fused multiply-adds are the only ones. */
#if defined(__CUDACC__) && defined(PK_GPU_BOX_NOINLINE)
#define GPU_BOX_INLINE __noinline__
#else
#define GPU_BOX_INLINE inline
#endif

/* a * b + c rounded once (the GPU's fma instruction; C's fmaf on the host,
 * also correctly rounded, so both compute the same bits). */
static inline PK_HD float gpu_fma(float a, float b, float c)
{
#if defined(__CUDA_ARCH__)
    return __fmaf_rn(a, b, c);
#else
    return fmaf(a, b, c);
#endif
}

/* The plane rows of the node for this ray: per axis the near and the far
 * row's two words (slots 0-3, 4-7), chosen by a select on the sign of 1/d. */
typedef struct gpu_rows {
    float org[3], sc[3];
    uint32_t nw[3][2], fw[3][2];
} gpu_rows;

static inline PK_HD void gpu_node_rows(const uint32_t w[24], const gpu_ray *r, gpu_rows *x)
{
    GPU_UNROLL
    for (int k = 0; k < 3; k++) {
        x->org[k] = gpu_bits_float(w[k]);
        x->sc[k] = gpu_scale((w[3] >> (8 * k)) & 255u);
        const bool neg = (r->near[k] & 1) != 0; /* near row 2k+1 (hi) when 1/d < 0 */
        const uint32_t lo0 = w[4 + 4 * k], lo1 = w[5 + 4 * k], hi0 = w[6 + 4 * k], hi1 = w[7 + 4 * k];
        x->nw[k][0] = neg ? hi0 : lo0, x->nw[k][1] = neg ? hi1 : lo1;
        x->fw[k][0] = neg ? lo0 : hi0, x->fw[k][1] = neg ? lo1 : hi1;
    }
}

/* GPU_TEST_FMA (kernel v3's; the path tracer's, and the default kernels'
 * for rays GPU_TEST_WIDE cannot take): gpu_node_hits_v0's distances bit for
 * bit with one operation less per plane:
 * org + q * scale with q * scale exact is one fma (one rounding of the
 * same exact value). The converter makes sure q * scale never overflows
 * where it matters (gpu_quantise checks both forms). */
static GPU_BOX_INLINE PK_HD unsigned gpu_node_hits_fma(const uint32_t w[24], const gpu_ray *r, float tcull,
                                                       float tn[GPU_WIDTH])
{
    gpu_rows x;
    gpu_node_rows(w, r, &x);
    unsigned mask = 0;
    GPU_UNROLL
    for (int s = 0; s < GPU_WIDTH; s++) {
        tn[s] = 0.0f;
        if (w[16 + s] == GPU_EMPTY) continue;
        const int h = s >> 2, b = s & 3;
        float near = r->tmin, far = tcull;
        GPU_UNROLL
        for (int k = 2; k >= 0; k--) {
            near = fmaxf((gpu_fma(gpu_byte_float(x.nw[k][h], b), x.sc[k], x.org[k]) - r->o[k]) * r->rd[k], near);
            far = fminf((gpu_fma(gpu_byte_float(x.fw[k][h], b), x.sc[k], x.org[k]) - r->o[k]) * r->rdf[k], far);
        }
        tn[s] = near;
        if (near <= far) mask |= 1u << s;
    }
    return mask;
}

/* The loosened box test, in two steps. Step one (kernel v4's, measured and
 * removed; GPU_TEST_WIDE below is built on it): one fma per plane,
 * t = fl(q * S + fl(A - E)) with S = scale / d and
 * A = (org - o) / d per node and axis, moved out by a bound E on the
 * rounding: near distances down, far ones up.
 *
 * Why it enters every box gpu_node_hits_v0 enters (so every box the CPU enters). With
 * u = 2^-24, P = org + q * scale (exact) and x = (P - o) * rd (exact):
 * gpu_node_hits_v0's distance fl(fl(fl(P) - o) * rd) is within
 * u * (|org rd| + 3.01 * 255 |S| + 2.01 |A|) of x (three roundings, |P| <=
 * |org| + 255 scale). Here S = scale * rd is exact (a power of
 * two times rd; a subnormal S errs by at most 2^-150, covered by the
 * 2^-100 below) and A = fl(fl(org - o) * rd) is within 2.0001 u |(org-o) rd|
 * of its exact value; fl(q * S + fl(A - E)) is then within
 * u * (2.0001 |(org-o) rd| + 2.0001 |A| + 255 |S| + 2.0001 E) of x - E.
 * So it is below gpu_node_hits_v0's distance when E >= u * (|org rd| + 1023 |S| + 6.03 |A|)
 * (+ a little for E's own rounding); E = 2^-20 * (|A| + 255 |S| + |org rd|)
 * + 2^-100 is twice that or more on every term. The far side is the same
 * with rdf and + E. Nothing there uses the signs of q, S or A, so it holds
 * for either row and either direction. Infinite or NaN values only loosen
 * the test: 1/d = +-inf (d = 0) or an overflowing S, A or |org rd| makes E
 * infinite, so every near distance of that axis is -inf or NaN and every
 * far one +inf or NaN, and a NaN plane is no limit (fmaxf, fminf); 1/d NaN
 * makes them all NaN, as in gpu_node_hits_v0. (So that an axis-parallel ray is not slowed
 * down by it, gpu_trace_box gives rays with a 1/d component of 2^64 or more
 * gpu_node_hits_fma instead.) The cost: boxes are looser by 2^-20 of the
 * distances involved, and of |org| / |d| (scenes far from the origin). The
 * entry distances differ from gpu_node_hits_v0's by as much, so children at nearly equal
 * distances may be visited in another order: the closest hit is the same
 * (smallest t, then smallest number), an any hit may be another. */
#define GPU_LOOSE_REL 0x1p-20f
#define GPU_LOOSE_ABS 0x1p-100f

/* Byte b (0..3, a constant) of word w as the float 2^23 + 256 * byte,
 * exactly: its bits with the byte in bits 8-15 (one byte permute). */
static inline PK_HD float gpu_byte_wide(uint32_t w, int b)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(__byte_perm(w, 0x4B000000u, 0x7504u | ((unsigned)b << 4)));
#else
    return gpu_bits_float(0x4B000000u | ((w >> (8 * b)) & 255u) << 8);
#endif
}

/* Step two, GPU_TEST_WIDE (kernel v6's, the default): step one without the
 * add that turns the byte into a
 * float: with m = 2^23 + 256 q (gpu_byte_wide, a byte permute),
 * t = fma(m, S', A'') where S' = S * 2^-8 and A'' = fl(fl(A - E) - 2^15 S)
 * (one fma: 2^23 * S' is exact), since m * S' = 2^15 S + q S. Against the
 * bound of step one this adds the rounding of A'' and of the
 * extra subtraction, u * (2 |A| + 2 E + 2^15 |S|): gpu_node_hits_v0's distance is then
 * above this one when E >= u * (|org rd| + 7.02 |A| + 33791 |S|) (+ E's own
 * rounding); E = 2^-20 * (|A| + |org rd|) + 2^-8 |S| + 2^-100 is 1.9 times
 * that or more on every term (2^-8 |S| is 1/256 of a quantisation step). A
 * subnormal S' errs by at most 2^-150, times m < 2^24: covered by 2^-100.
 * Infinite and NaN values loosen the test as in step one, and
 * gpu_trace_box gives it the same rays (every |1/d| < 2^64). */
static GPU_BOX_INLINE PK_HD unsigned gpu_node_hits_wide(const uint32_t w[24], const gpu_ray *r, float tcull,
                                                        float tn[GPU_WIDTH])
{
    gpu_rows x;
    gpu_node_rows(w, r, &x);
    float sn[3], an[3], sf[3], af[3];
    GPU_UNROLL
    for (int k = 0; k < 3; k++) {
        const float d = x.org[k] - r->o[k];
        const float a = d * r->rd[k], s = x.sc[k] * r->rd[k];
        const float a2 = d * r->rdf[k], s2 = x.sc[k] * r->rdf[k];
        const float g = fabsf(a) + fabsf(x.org[k] * r->rd[k]), g2 = fabsf(a2) + fabsf(x.org[k] * r->rdf[k]);
        const float e = gpu_fma(0x1p-8f, fabsf(s), gpu_fma(GPU_LOOSE_REL, g, GPU_LOOSE_ABS));
        const float e2 = gpu_fma(0x1p-8f, fabsf(s2), gpu_fma(GPU_LOOSE_REL, g2, GPU_LOOSE_ABS));
        sn[k] = s * 0x1p-8f, an[k] = gpu_fma(-0x1p23f, sn[k], a - e);
        sf[k] = s2 * 0x1p-8f, af[k] = gpu_fma(-0x1p23f, sf[k], a2 + e2);
    }
    unsigned mask = 0;
    GPU_UNROLL
    for (int s = 0; s < GPU_WIDTH; s++) {
        tn[s] = 0.0f;
        if (w[16 + s] == GPU_EMPTY) continue;
        const int h = s >> 2, b = s & 3;
        float near = r->tmin, far = tcull;
        GPU_UNROLL
        for (int k = 2; k >= 0; k--) {
            near = fmaxf(gpu_fma(gpu_byte_wide(x.nw[k][h], b), sn[k], an[k]), near);
            far = fminf(gpu_fma(gpu_byte_wide(x.fw[k][h], b), sf[k], af[k]), far);
        }
        tn[s] = near;
        if (near <= far) mask |= 1u << s;
    }
    return mask;
}

static inline PK_HD float gpu_sel3(const float v[3], int k) { return k == 0 ? v[0] : k == 1 ? v[1] : v[2]; }

/* gpu_tri_intersect on a record read with three 16-byte loads; *prim is
 * the record's triangle number. */
static inline PK_HD bool gpu_tri_intersect_rec(const gpu_ray *r, const gpu_tri *tri, float tmax, float *t_out,
                                               float *u_out, float *v_out, uint32_t *prim)
{
    float a[3], b[3], c[3];
#if defined(__CUDA_ARCH__)
    const float4 *p = (const float4 *)tri;
    const float4 x = __ldg(p), y = __ldg(p + 1), z = __ldg(p + 2);
    a[0] = x.x, a[1] = x.y, a[2] = x.z, *prim = __float_as_uint(x.w);
    b[0] = y.x, b[1] = y.y, b[2] = y.z;
    c[0] = z.x, c[1] = z.y, c[2] = z.z;
#else
    memcpy(a, tri->a, sizeof a), memcpy(b, tri->b, sizeof b), memcpy(c, tri->c, sizeof c);
    *prim = tri->prim;
#endif
    const float ox = r->ox, oy = r->oy, oz = r->oz;
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    return tri_test_watertight(gpu_sel3(a, kx) - ox, gpu_sel3(a, ky) - oy, gpu_sel3(a, kz) - oz, gpu_sel3(b, kx) - ox,
                               gpu_sel3(b, ky) - oy, gpu_sel3(b, kz) - oz, gpu_sel3(c, kx) - ox, gpu_sel3(c, ky) - oy,
                               gpu_sel3(c, kz) - oz, r->sx, r->sy, r->sz, r->tmin, tmax, t_out, u_out, v_out);
}

/* The traversal with box test box (a constant: GPU_TEST_FMA or
 * GPU_TEST_WIDE, named after the kernel versions that introduced them);
 * gpu_trace below is the one to call. */
enum { GPU_TEST_FMA = 3, GPU_TEST_WIDE = 6 };
/* One ray's traversal as a state that advances a step at a time: a step
 * goes down to a leaf, tests its triangles and pops the next node, so that
 * a kernel can give a lane whose ray is done a new ray between steps
 * (gpu_walk_*; gpu_trace_box runs the steps in a loop). The stack is the
 * caller's (GPU_STACK entries), sp and ref index into it. */
typedef struct gpu_walk {
    gpu_ray r;
    float best_t, best_u, best_v, tcull;
    uint32_t best_prim, ref;
    int sp;
    bool loose;             /* GPU_TEST_WIDE for this ray */
} gpu_walk;

/* Starts *w on *in; false when there is nothing to trace (no hit). */
static inline PK_HD bool gpu_walk_init(gpu_walk *w, const pk_ray *in, int box)
{
    w->best_t = in->tmax, w->best_u = w->best_v = 0.0f;
    w->best_prim = PK_NO_HIT;
    w->ref = 0, w->sp = 0;
    if (!gpu_ray_traceable(in)) return false;
    gpu_ray_init(&w->r, in);
    w->tcull = gpu_cull_limit(w->best_t);
    /* GPU_TEST_WIDE's per-ray terms; a ray with a huge or infinite 1/d
     * component (d = 0: axis-parallel) takes GPU_TEST_FMA instead, where
     * the bound would be infinite and the axis would limit nothing */
    w->loose = box == GPU_TEST_WIDE && fabsf(w->r.rd[0]) < 0x1p64f &&
               fabsf(w->r.rd[1]) < 0x1p64f && fabsf(w->r.rd[2]) < 0x1p64f;
    return true;
}

/* One step; true when the ray is done (gpu_walk_hit then has the answer). */
static inline PK_HD bool gpu_walk_step(gpu_walk *ws, gpu_stack_entry *stack, const gpu_node *nodes,
                                       const gpu_tri *tris, bool any, gpu_counters *count, int box)
{
    const gpu_ray *r = &ws->r;
    uint32_t ref = ws->ref;
    int sp = ws->sp;
    float tcull = ws->tcull;
    while (!(ref & GPU_LEAF)) {
        if (count) count->nodes++;
        uint32_t w[24];
        gpu_node_load(&nodes[ref], w);
        float tn[GPU_WIDTH];
        const unsigned mask = ws->loose ? gpu_node_hits_wide(w, r, tcull, tn) : gpu_node_hits_fma(w, r, tcull, tn);
        if (!mask) goto pop;
        /* The order of gpu_trace_v0, which pushes every hit child with an
         * insertion sort (a child goes above those nearer than it and above
         * equals from lower slots) and pops the top: here the top, the
         * nearest (the highest slot among equals), stays in cur. A child
         * replacing cur is at least as near as every pushed one, and a
         * pushed one as near as cur came from a lower slot, so the old cur
         * goes straight on top; any other child is inserted. */
        uint32_t cur = GPU_EMPTY;
        float ct = 0.0f;
        const int base = sp;
        GPU_UNROLL
        for (int k = 0; k < GPU_WIDTH; k++) {
            if (!(mask >> k & 1u)) continue;
            const uint32_t c = w[16 + k];
            const float t = tn[k];
            if (cur == GPU_EMPTY) {
                cur = c, ct = t;
            } else if (t <= ct) {
                stack[sp].ref = cur, stack[sp].t = ct;
                sp++;
                cur = c, ct = t;
            } else {
                int j = sp++;
                for (; j > base && stack[j - 1].t < t; j--) stack[j] = stack[j - 1];
                stack[j].ref = c, stack[j].t = t;
            }
        }
        ref = cur;
    }
    {
        if (count) count->nodes++;
        const uint32_t first = gpu_leaf_first(ref), cnt = gpu_leaf_count(ref);
        for (uint32_t i = 0; i < cnt; i++) {
            float t, u, v;
            uint32_t prim;
            if (count) count->tests++;
            if (!gpu_tri_intersect_rec(r, &tris[first + i], ws->best_t, &t, &u, &v, &prim)) continue;
            if (t < ws->best_t || (t == ws->best_t && prim < ws->best_prim)) {
                ws->best_t = t, ws->best_prim = prim, ws->best_u = u, ws->best_v = v;
                if (any) return true;
            }
        }
        tcull = gpu_cull_limit(ws->best_t);
    }
pop:
    for (;;) {
        if (sp == 0) return true;
        --sp;
        if (stack[sp].t <= tcull) {
            ref = stack[sp].ref;
            break;
        }
    }
    ws->ref = ref, ws->sp = sp, ws->tcull = tcull;
    return false;
}

/* The answer of a finished walk (a miss: t = +inf, PK_NO_HIT, u = v = 0). */
static inline PK_HD bool gpu_walk_hit(const gpu_walk *w, pk_hit *out)
{
    const bool found = w->best_prim != PK_NO_HIT;
    out->t = found ? w->best_t : INFINITY;
    out->prim = w->best_prim;
    out->u = found ? w->best_u : 0.0f;
    out->v = found ? w->best_v : 0.0f;
    return found;
}

static inline PK_HD bool gpu_trace_box(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *in, bool any,
                                       pk_hit *out, gpu_counters *count, int box)
{
    gpu_walk w;
    gpu_stack_entry stack[GPU_STACK];
    if (gpu_walk_init(&w, in, box))
        while (!gpu_walk_step(&w, stack, nodes, tris, any, count, box)) {
        }
    return gpu_walk_hit(&w, out);
}

/* ---- the ordered traversal (Ylitie, Karras and Laine 2017) -----------------
 * The converter places each node's children in slots by direction (slot bit
 * k set: the child lies on the positive side of the node's centre along
 * axis k; gpu_layout_build), so that visiting slots j ^ o for j = 0..7,
 * o = the ray's octant (bit k: d_k < 0), goes roughly near to far without
 * sorting. A node visit turns its hit mask into that order (three
 * conditional swaps), goes on with the first child and pushes one entry
 * when others remain: (node index << 8 | the remaining 8-bit mask, the
 * nearest entry distance of those children). A pop drops entries whose
 * distance lies beyond the closest hit found since, takes the next child of
 * the top entry and reads its reference (4 bytes of the parent). At most
 * one entry per ancestor: the stack needs gpu_layout.ordered_need entries
 * (the depth of the deepest inner node), GPU_OSTACK at most (half the
 * sorted traversal's bytes). A child popped from an entry that survives is
 * not culled on its own distance (an inner one is by its own box tests).
 * The closest hit is the same (smallest t, then smallest number; but for
 * the exact ties of docs/gpu.md, as with any other visiting order). */
#define GPU_OSTACK 64
#define GPU_ONODE_MAX (1u << 24) /* node indices that fit an entry */

static inline PK_HD unsigned gpu_octant(const gpu_ray *r)
{
    return (unsigned)(r->near[0] & 1) | (unsigned)(r->near[1] & 1) << 1 | (unsigned)(r->near[2] & 1) << 2;
}

/* Bit j of the result is bit j ^ o of m (m: 8 bits, o: 3 bits). */
static inline PK_HD unsigned gpu_mask_order(unsigned m, unsigned o)
{
    if (o & 1u) m = ((m & 0x55u) << 1) | ((m >> 1) & 0x55u);
    if (o & 2u) m = ((m & 0x33u) << 2) | ((m >> 2) & 0x33u);
    if (o & 4u) m = ((m & 0x0Fu) << 4) | ((m >> 4) & 0x0Fu);
    return m;
}

static inline PK_HD unsigned gpu_lowest_bit(unsigned m)
{
#if defined(__CUDA_ARCH__)
    return (unsigned)__ffs((int)m) - 1u;
#else
    return (unsigned)__builtin_ctz(m);
#endif
}

/* w[i] for a run-time i in 0..7, by selects (no indexed registers). */
static inline PK_HD uint32_t gpu_sel8(const uint32_t w[8], unsigned i)
{
    const uint32_t a = (i & 1u) ? w[1] : w[0], b = (i & 1u) ? w[3] : w[2];
    const uint32_t c = (i & 1u) ? w[5] : w[4], d = (i & 1u) ? w[7] : w[6];
    const uint32_t ab = (i & 2u) ? b : a, cd = (i & 2u) ? d : c;
    return (i & 4u) ? cd : ab;
}

/* One ray's ordered traversal as a state advancing a step at a time (as
 * gpu_walk): a step goes down to a leaf, tests it and takes the next
 * reference from the stack. ref: the next reference to visit, GPU_EMPTY
 * when the stack must be popped. */
typedef struct gpu_owalk {
    gpu_ray r;
    float best_t, best_u, best_v, tcull;
    uint32_t best_prim, ref;
    unsigned oct;
    int sp;
    bool loose;
} gpu_owalk;

static inline PK_HD bool gpu_owalk_init(gpu_owalk *w, const pk_ray *in, int box)
{
    w->best_t = in->tmax, w->best_u = w->best_v = 0.0f;
    w->best_prim = PK_NO_HIT;
    w->ref = 0, w->sp = 0, w->oct = 0;
    if (!gpu_ray_traceable(in)) return false;
    gpu_ray_init(&w->r, in);
    w->oct = gpu_octant(&w->r);
    w->tcull = gpu_cull_limit(w->best_t);
    w->loose = box == GPU_TEST_WIDE && fabsf(w->r.rd[0]) < 0x1p64f && fabsf(w->r.rd[1]) < 0x1p64f &&
               fabsf(w->r.rd[2]) < 0x1p64f;
    return true;
}

/* The next child of the top entry whose children may still be nearer
 * than tcull (entries all of whose children lie beyond it are dropped), or
 * GPU_EMPTY when none is left. */
static inline PK_HD uint32_t gpu_opop(gpu_stack_entry *stack, int *sp, const gpu_node *nodes, unsigned oct,
                                      float tcull)
{
    while (*sp > 0 && !(stack[*sp - 1].t <= tcull)) --*sp;
    if (*sp == 0) return GPU_EMPTY;
    const uint32_t e = stack[*sp - 1].ref;
    const uint32_t ni = e >> 8;
    unsigned pm = e & 255u;
    const unsigned j = gpu_lowest_bit(pm);
    pm &= pm - 1u;
    if (pm) stack[*sp - 1].ref = (ni << 8) | pm;
    else --*sp;
#if defined(__CUDA_ARCH__)
    return __ldg(&nodes[ni].child[j ^ oct]);
#else
    return nodes[ni].child[j ^ oct];
#endif
}

/* One step; true when the ray is done (gpu_owalk_hit then has the answer). */
static inline PK_HD bool gpu_owalk_step(gpu_owalk *ws, gpu_stack_entry *stack, const gpu_node *nodes,
                                        const gpu_tri *tris, bool any, gpu_counters *count)
{
    const gpu_ray *r = &ws->r;
    const unsigned oct = ws->oct;
    uint32_t ref = ws->ref;
    int sp = ws->sp;
    for (;;) {
        while (ref != GPU_EMPTY && !(ref & GPU_LEAF)) {
            if (count) count->nodes++;
            uint32_t w[24];
            gpu_node_load(&nodes[ref], w);
            float tn[GPU_WIDTH];
            const unsigned mask =
                ws->loose ? gpu_node_hits_wide(w, r, ws->tcull, tn) : gpu_node_hits_fma(w, r, ws->tcull, tn);
            unsigned pm = gpu_mask_order(mask, oct);
            if (!pm) {
                ref = GPU_EMPTY;
                break;
            }
            const unsigned j = gpu_lowest_bit(pm);
            pm &= pm - 1u;
            if (pm) {
                /* the nearest entry distance of the children left */
                const unsigned left = mask & ~(1u << (j ^ oct));
                float tl = INFINITY;
                GPU_UNROLL
                for (int k = 0; k < GPU_WIDTH; k++)
                    if (left >> k & 1u) tl = gpu_min(tl, tn[k]);
                stack[sp].ref = (ref << 8) | pm, stack[sp].t = tl;
                sp++;
            }
            ref = gpu_sel8(w + 16, j ^ oct);
        }
        if (ref != GPU_EMPTY) break; /* a leaf */
        ref = gpu_opop(stack, &sp, nodes, oct, ws->tcull);
        if (ref == GPU_EMPTY) return true;
    }
    if (count) count->nodes++;
    const uint32_t first = gpu_leaf_first(ref), cnt = gpu_leaf_count(ref);
    for (uint32_t i = 0; i < cnt; i++) {
        float t, u, v;
        uint32_t prim;
        if (count) count->tests++;
        if (!gpu_tri_intersect_rec(r, &tris[first + i], ws->best_t, &t, &u, &v, &prim)) continue;
        if (t < ws->best_t || (t == ws->best_t && prim < ws->best_prim)) {
            ws->best_t = t, ws->best_prim = prim, ws->best_u = u, ws->best_v = v;
            if (any) return true;
        }
    }
    ws->tcull = gpu_cull_limit(ws->best_t);
    ref = gpu_opop(stack, &sp, nodes, oct, ws->tcull);
    ws->ref = ref, ws->sp = sp;
    return ref == GPU_EMPTY;
}

static inline PK_HD bool gpu_owalk_hit(const gpu_owalk *w, pk_hit *out)
{
    const bool found = w->best_prim != PK_NO_HIT;
    out->t = found ? w->best_t : INFINITY;
    out->prim = w->best_prim;
    out->u = found ? w->best_u : 0.0f;
    out->v = found ? w->best_v : 0.0f;
    return found;
}

/* The ordered traversal with box test box (GPU_TEST_FMA or GPU_TEST_WIDE):
 * the same contract as gpu_trace. The layout's ordered_need must be at most
 * GPU_OSTACK and its node count below GPU_ONODE_MAX (gpu_layout_ordered). */
static inline PK_HD bool gpu_trace_ordered(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *in, bool any,
                                           pk_hit *out, gpu_counters *count, int box)
{
    gpu_owalk w;
    gpu_stack_entry stack[GPU_OSTACK];
    if (gpu_owalk_init(&w, in, box))
        while (!gpu_owalk_step(&w, stack, nodes, tris, any, count)) {
        }
    return gpu_owalk_hit(&w, out);
}

/* Closest hit (any = false) or any hit (any = true) of *in against the
 * layout: fills *out (a miss: t = +inf, prim = PK_NO_HIT, u = v = 0) and
 * returns whether something was hit. The same closest hit as every CPU
 * accelerator; for any hit, some hit in [tmin, tmax] with its t, u, v (the
 * first found, leaves visited near first). Callable from other device code
 * (one ray per thread; the stack is the thread's own). */
#ifndef GPU_TRACE_BOX
#define GPU_TRACE_BOX GPU_TEST_FMA
#endif
static inline PK_HD bool gpu_trace(const gpu_node *nodes, const gpu_tri *tris, const pk_ray *in, bool any,
                                   pk_hit *out, gpu_counters *count)
{
    return gpu_trace_box(nodes, tris, in, any, out, count, GPU_TRACE_BOX);
}

#ifndef __CUDACC__
/* ---- the host side: conversion and checks (bvh_gpu.c) -------------------- */

struct accel;

/* Invariants (gpu_layout_check tests them):
 *  1. nodes[0] is the root; every other node is the child of exactly one
 *     slot and comes after its parent (no cycles); references are in range.
 *  2. Each leaf holds 1..GPU_LEAF_MAX records; every record belongs to
 *     exactly one leaf; a record's prim is < ntris and its vertices are the
 *     scene's vertices of that triangle, bit for bit.
 *  3. Every triangle that can be hit (not degenerate) is in at least one
 *     leaf (in several when the builder's spatial splits cut it), no
 *     degenerate one in any; each of its vertices lies inside every decoded
 *     box on the path to at least one leaf holding it (all three inside one
 *     path when it is in a single leaf).
 *  4. Used slots have low planes <= high planes; unused slots are GPU_EMPTY.
 *  5. The traversal stack never needs more than GPU_STACK entries:
 *     stack_need (the largest sum, over a root-to-node path, of the hit
 *     children a node can push) <= GPU_STACK; ordered_need is the depth
 *     of the deepest inner node (the root's is 1).
 *  6. Slots follow the ray octants (gpu_trace_ordered): each node's slots
 *     are the CPU node's, permuted by gpu_layout_build's assignment of
 *     children to the octants around the node's centre. */
typedef struct gpu_layout {
    gpu_node *nodes;
    size_t nnodes;
    gpu_tri *tris;
    size_t ntris;          /* triangle records (references) */
    size_t scene_tris;     /* triangles of the scene (prim < scene_tris) */
    uint32_t stack_need;
    uint32_t ordered_need; /* gpu_trace_ordered's stack: the depth of the deepest inner node */
} gpu_layout;

/* Whether gpu_trace_ordered can run on g (its stack and entries suffice). */
static inline bool gpu_layout_ordered(const gpu_layout *g)
{
    return g->ordered_need <= GPU_OSTACK && g->nnodes < GPU_ONODE_MAX;
}

/* Converts the wide BVH b (accel_bvh_create's, triangles only) into *out.
 * Errors (NOMEM, LIMIT) are latched in ctx. */
PK_HIDDEN pk_status gpu_layout_build(pk_context *ctx, const pk_allocator *al, const struct accel *b,
                                     gpu_layout *out);
PK_HIDDEN void gpu_layout_free(const pk_allocator *al, gpu_layout *g);
/* Every decoded box of b's conversion contains the CPU box it came from
 * (g must be b's conversion): false with a reason otherwise. */
PK_HIDDEN bool gpu_layout_check_boxes(const gpu_layout *g, const struct accel *b, char *why, size_t n);
/* Invariants 1-5 against the scene's vertices (3 per triangle); false with
 * a reason in why (may be NULL). */
PK_HIDDEN bool gpu_layout_check(const gpu_layout *g, const float *verts, char *why, size_t n);
/* Quantises the interval [lo, hi] of a child within the frame (org, scale
 * 2^(ex-127)): *qlo, *qhi with gpu_plane(org, qlo) <= lo and
 * gpu_plane(org, qhi) >= hi, and the same of gpu_fma(q, scale, org); false
 * when it does not fit in 0..255. */
PK_HIDDEN bool gpu_quantise(float org, unsigned ex, float lo, float hi, uint8_t *qlo, uint8_t *qhi);
#endif

#endif

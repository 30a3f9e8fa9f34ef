/*
 * instances.c - the two-level structure for scenes that keep instances:
 * one accelerator of the chosen kind over the world's own triangles and
 * spheres, one over each mesh's object-space triangles (its bottom level),
 * and a binary tree over the instances' world boxes (the top level; binned
 * SAH, two instances per leaf). A ray meets an instance's mesh in the
 * mesh's space: origin and direction through the stored inverse transform,
 * the direction not renormalised, so that the t the mesh reports is the
 * world ray's parameter and hits in different instances compare directly;
 * the closest-hit rule (lower number wins a tie) then holds over the hit
 * numbers prim0 + k. With kind none there is no top level: every instance
 * is tested, which makes the brute-force reference for the others.
 */
#include "accel.h"
#include "bvh.h"

#include <stdio.h>
#include <string.h>

#define TL_LEAF_MAX 2
#define TL_BINS 16
#define TL_MAX_DEPTH 100     /* the builder splits at the median below this */
#define TL_STACK (TL_MAX_DEPTH + 2)

/* Top-level node: count 0: an inner node whose children are nodes index
 * and index + 1; else a leaf of count instances order[index ..]. */
typedef struct tl_node {
    float lo[3], hi[3];
    uint32_t index, count;
} tl_node;

typedef struct tl_inst {
    xform to_object;     /* the inverse of to_world (xform_invert: double, rounded once) */
    uint32_t mesh, prim0;
} tl_inst;

/* Invariants (accel_instances_check):
 *  1. inst[i] is input instance i with its inverse; meshes[m] is kind's
 *     accelerator over mesh m's triangles, NULL when it has none that can
 *     be hit; world is kind's over the world's primitives, NULL when none;
 *  2. brute (kind none): no top level; else nodes[0] is the root, each
 *     instance with a mesh that can be hit is in exactly one leaf (order),
 *     a node's box contains its children's boxes and a leaf's box the
 *     padded world box of each of its instances. */
typedef struct accel_inst {
    accel base;
    accel *world;
    accel **meshes;
    size_t nmeshes;
    aabb *mesh_box;      /* object-space bounds of what can be hit */
    tl_inst *inst;
    size_t ninst;
    tl_node *nodes;
    size_t nnodes;
    uint32_t *order;
    size_t norder;
    aabb *ibox;          /* the instances' padded world boxes (kind none: NULL) */
    bool brute;
} accel_inst;

static void inst_destroy(accel *a)
{
    accel_inst *A = (accel_inst *)a;
    const pk_allocator *al = a->alloc;
    accel_destroy(A->world);
    for (size_t m = 0; A->meshes && m < A->nmeshes; m++) accel_destroy(A->meshes[m]);
    mem_free(al, A->meshes);
    mem_free(al, A->mesh_box);
    mem_free(al, A->inst);
    mem_free(al, A->nodes);
    mem_free(al, A->order);
    mem_free(al, A->ibox);
    mem_free(al, A);
}

/* The ray r in instance in's space, up to tmax. */
static inline ray inst_ray(const tl_inst *in, const ray *r, float tmax)
{
    ray l;
    l.o = xform_point(&in->to_object, r->o);
    l.d = xform_vector(&in->to_object, r->d);
    l.tmin = r->tmin;
    l.tmax = tmax;
    return l;
}

/* Closest hit in instance i; updates *h when better. */
static inline bool inst_closest(const accel_inst *A, uint32_t i, const ray *r, hit *h, accel_counters *c)
{
    const tl_inst *in = &A->inst[i];
    const accel *m = A->meshes[in->mesh];
    if (!m) return false;
    ray l = inst_ray(in, r, h->t);
    hit lh;
    if (!accel_intersect(m, &l, &lh, c)) return false;
    const uint32_t prim = in->prim0 + lh.prim;
    if (!hit_better(lh.t, prim, h)) return false;
    h->t = lh.t;
    h->prim = prim;
    h->u = lh.u;
    h->v = lh.v;
    return true;
}

/* Entry distance of the ray into node n's box within [tmin, tfar], or false.
 * NaN slab distances (0 * inf, tiny directions) limit nothing. */
static inline bool tl_enter(const tl_node *n, vec3 o, vec3 inv, float tmin, float tfar, float *tn_out)
{
    const float t0x = (n->lo[0] - o.x) * inv.x, t1x = (n->hi[0] - o.x) * inv.x;
    const float t0y = (n->lo[1] - o.y) * inv.y, t1y = (n->hi[1] - o.y) * inv.y;
    const float t0z = (n->lo[2] - o.z) * inv.z, t1z = (n->hi[2] - o.z) * inv.z;
    const float tn = fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fmaxf(fminf(t0z, t1z), tmin));
    const float tf = fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
    *tn_out = tn;
    return tn <= bvh_cull_limit(tf) && tn <= tfar && !(n->lo[0] > n->hi[0]);
}

/* Visits the instances whose boxes the ray enters before limit(*t) (t
 * changes as hits are found), near child first; fn returns true to stop. */
#define TL_TRAVERSE(A, r, c, tvar, VISIT)                                                                   \
    do {                                                                                                    \
        const vec3 inv_ = v3(ray_rcp((r)->d.x), ray_rcp((r)->d.y), ray_rcp((r)->d.z));                      \
        uint32_t stack_[TL_STACK];                                                                          \
        int sp_ = 0;                                                                                        \
        float tn_;                                                                                          \
        if ((A)->nnodes && tl_enter(&(A)->nodes[0], (r)->o, inv_, (r)->tmin, bvh_cull_limit(tvar), &tn_))   \
            stack_[sp_++] = 0;                                                                              \
        while (sp_ > 0) {                                                                                   \
            const tl_node *n_ = &(A)->nodes[stack_[--sp_]];                                                 \
            if (c) (c)->nodes++;                                                                            \
            if (n_->count) {                                                                                \
                for (uint32_t k_ = 0; k_ < n_->count; k_++) {                                               \
                    const uint32_t inst_ = (A)->order[n_->index + k_];                                      \
                    VISIT                                                                                   \
                }                                                                                           \
                continue;                                                                                   \
            }                                                                                               \
            float t0_, t1_;                                                                                 \
            const float lim_ = bvh_cull_limit(tvar);                                                        \
            const bool h0_ = tl_enter(&(A)->nodes[n_->index], (r)->o, inv_, (r)->tmin, lim_, &t0_);         \
            const bool h1_ = tl_enter(&(A)->nodes[n_->index + 1], (r)->o, inv_, (r)->tmin, lim_, &t1_);     \
            if (h0_ && h1_) {                                                                               \
                const bool swap_ = t1_ < t0_;                                                               \
                stack_[sp_++] = n_->index + (swap_ ? 0u : 1u);                                              \
                stack_[sp_++] = n_->index + (swap_ ? 1u : 0u);                                              \
            } else if (h0_) {                                                                               \
                stack_[sp_++] = n_->index;                                                                  \
            } else if (h1_) {                                                                               \
                stack_[sp_++] = n_->index + 1;                                                              \
            }                                                                                               \
        }                                                                                                   \
    } while (0)

static bool inst_intersect(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    const accel_inst *A = (const accel_inst *)a;
    hit_clear(h);
    if (!ray_traceable(r)) return false;
    hit best;
    hit_clear(&best);
    best.t = r->tmax;
    if (A->world) {
        hit wh;
        if (accel_intersect(A->world, r, &wh, c)) best = wh;
    }
    if (A->brute) {
        for (uint32_t i = 0; i < A->ninst; i++) inst_closest(A, i, r, &best, c);
    } else {
        TL_TRAVERSE(A, r, c, best.t, { inst_closest(A, inst_, r, &best, c); });
    }
    if (best.prim == PK_NO_HIT) return false;
    *h = best;
    return true;
}

/* Any hit in instance i: fills *out and returns true. */
static inline bool inst_any(const accel_inst *A, uint32_t i, const ray *r, hit *out, accel_counters *c)
{
    const tl_inst *in = &A->inst[i];
    const accel *m = A->meshes[in->mesh];
    if (!m) return false;
    ray l = inst_ray(in, r, r->tmax);
    hit lh;
    if (!m->ops->occluded(m, &l, &lh, c)) return false;
    out->t = lh.t;
    out->prim = in->prim0 + lh.prim;
    out->u = lh.u;
    out->v = lh.v;
    return true;
}

static bool inst_occluded(const accel *a, const ray *r, hit *out, accel_counters *c)
{
    const accel_inst *A = (const accel_inst *)a;
    hit scratch;
    hit *h = out ? out : &scratch;
    hit_clear(h);
    if (!ray_traceable(r)) return false;
    if (A->world && A->world->ops->occluded(A->world, r, h, c)) return true;
    if (A->brute) {
        for (uint32_t i = 0; i < A->ninst; i++)
            if (inst_any(A, i, r, h, c)) return true;
    } else {
        const float tmax = r->tmax;
        bool found = false;
        TL_TRAVERSE(A, r, c, tmax, {
            if (inst_any(A, inst_, r, h, c)) {
                found = true;
                sp_ = 0;
                break;
            }
        });
        if (found) return true;
    }
    hit_clear(h);
    return false;
}

static const accel_ops inst_ops = {inst_destroy, inst_intersect, inst_occluded, NULL, NULL, NULL};

/* ---- the top level's build ---- */

typedef struct tl_build {
    aabb *box;           /* per instance, padded world boxes */
    vec3 *cent;          /* their centres */
} tl_build;

static void node_box(tl_node *n, aabb b)
{
    n->lo[0] = b.lo.x, n->lo[1] = b.lo.y, n->lo[2] = b.lo.z;
    n->hi[0] = b.hi.x, n->hi[1] = b.hi.y, n->hi[2] = b.hi.z;
}

/* Splits order[lo, hi) and returns the first index of the right part. */
static size_t tl_split(const tl_build *tb, uint32_t *order, size_t lo, size_t hi, int depth)
{
    const size_t n = hi - lo, mid = lo + n / 2;
    aabb cb = aabb_empty();
    for (size_t i = lo; i < hi; i++) cb = aabb_grow(cb, tb->cent[order[i]]);
    const vec3 ext = aabb_extent(cb);
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const float elo = v3_get(cb.lo, axis), w = v3_get(ext, axis);
    if (!(w > 0.0f) || depth >= TL_MAX_DEPTH / 2) return mid; /* one centre, or deep: halves, in index order */
    aabb bb[TL_BINS];
    size_t bn[TL_BINS] = {0};
    for (int k = 0; k < TL_BINS; k++) bb[k] = aabb_empty();
    const float scale = (float)TL_BINS / w;
    for (size_t i = lo; i < hi; i++) {
        int k = (int)((v3_get(tb->cent[order[i]], axis) - elo) * scale);
        k = k < 0 ? 0 : k >= TL_BINS ? TL_BINS - 1 : k;
        bb[k] = aabb_union(bb[k], tb->box[order[i]]);
        bn[k]++;
    }
    float right_area[TL_BINS];
    size_t right_n[TL_BINS];
    aabb acc = aabb_empty();
    size_t cnt = 0;
    for (int k = TL_BINS - 1; k > 0; k--) {
        acc = aabb_union(acc, bb[k]);
        cnt += bn[k];
        right_area[k] = aabb_area(acc);
        right_n[k] = cnt;
    }
    float best = INFINITY;
    int best_k = -1;
    acc = aabb_empty();
    cnt = 0;
    for (int k = 1; k < TL_BINS; k++) {
        acc = aabb_union(acc, bb[k - 1]);
        cnt += bn[k - 1];
        if (!cnt || !right_n[k]) continue;
        const float cost = aabb_area(acc) * (float)cnt + right_area[k] * (float)right_n[k];
        if (cost < best) best = cost, best_k = k;
    }
    if (best_k < 0) return mid;
    size_t i = lo, j = hi;
    while (i < j) {
        int k = (int)((v3_get(tb->cent[order[i]], axis) - elo) * scale);
        k = k < 0 ? 0 : k >= TL_BINS ? TL_BINS - 1 : k;
        if (k < best_k) {
            i++;
        } else {
            uint32_t t = order[i];
            order[i] = order[--j];
            order[j] = t;
        }
    }
    return i > lo && i < hi ? i : mid;
}

typedef struct tl_task {
    uint32_t node;
    size_t lo, hi;
    int depth;
} tl_task;

static pk_status tl_build_tree(pk_context *ctx, accel_inst *A, const tl_build *tb)
{
    const size_t n = A->norder;
    if (!n) return PK_OK;
    A->nodes = mem_realloc_array(&ctx->alloc, NULL, 2 * n, sizeof *A->nodes);
    tl_task *stack = mem_realloc_array(&ctx->alloc, NULL, 2 * n + 1, sizeof *stack);
    if (!A->nodes || !stack) {
        mem_free(&ctx->alloc, stack);
        return ctx_nomem(ctx);
    }
    A->nnodes = 1;
    size_t sp = 0;
    stack[sp++] = (tl_task){0, 0, n, 0};
    while (sp) {
        const tl_task t = stack[--sp];
        tl_node *nd = &A->nodes[t.node];
        aabb b = aabb_empty();
        for (size_t i = t.lo; i < t.hi; i++) b = aabb_union(b, tb->box[A->order[i]]);
        node_box(nd, b);
        if (t.hi - t.lo <= TL_LEAF_MAX) {
            nd->index = (uint32_t)t.lo;
            nd->count = (uint32_t)(t.hi - t.lo);
            continue;
        }
        const size_t m = tl_split(tb, A->order, t.lo, t.hi, t.depth);
        const uint32_t c0 = (uint32_t)A->nnodes;
        A->nnodes += 2;
        nd->index = c0;
        nd->count = 0;
        stack[sp++] = (tl_task){c0 + 1, m, t.hi, t.depth + 1};
        stack[sp++] = (tl_task){c0, t.lo, m, t.depth + 1};
    }
    mem_free(&ctx->alloc, stack);
    return PK_OK;
}

/* Object-space box of what can be hit of mesh m. */
static aabb mesh_bounds(const accel_mesh *m)
{
    aabb b = aabb_empty();
    for (size_t k = 0; k < m->ntris; k++) {
        const vec3 *p = m->verts + 3 * k;
        if (tri_is_degenerate(p[0], p[1], p[2])) continue;
        b = aabb_grow(aabb_grow(aabb_grow(b, p[0]), p[1]), p[2]);
    }
    return b;
}

/* World box of object box b placed by x, padded against the rounding of
 * rays taken into the instance's space (2^-12 of its size and position). */
static aabb placed_box(const xform *x, aabb b)
{
    aabb w = aabb_empty();
    for (int k = 0; k < 8; k++) {
        vec3 p = v3(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z);
        w = aabb_grow(w, xform_point(x, p));
    }
    const vec3 e = aabb_extent(w);
    const float mag = fmaxf(fmaxf(fmaxf(fabsf(w.lo.x), fabsf(w.hi.x)), fmaxf(fabsf(w.lo.y), fabsf(w.hi.y))),
                            fmaxf(fabsf(w.lo.z), fabsf(w.hi.z)));
    const float pad = (v3_max_comp(e) + mag) * 0x1p-12f;
    w.lo = v3_sub(w.lo, v3s(pad));
    w.hi = v3_add(w.hi, v3s(pad));
    return w;
}

static void add_info(pk_accel_info *to, const accel *a, size_t times)
{
    if (!a) return;
    to->nodes += a->info.nodes;
    to->leaves += a->info.leaves;
    to->bytes += a->info.bytes;
    to->primitives += a->info.primitives * times;
}

pk_status accel_instances_create(pk_context *ctx, pk_accel_kind kind, const accel_input *in0,
                                 const accel_instances *in, accel **out)
{
    *out = NULL;
    if (kind == PK_ACCEL_DEFAULT) kind = PK_ACCEL_BVH;
    if (kind != PK_ACCEL_NONE && kind != PK_ACCEL_MIDPOINT && kind != PK_ACCEL_BVH)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "instances: accelerator %d has no two-level form", (int)kind);
    if (in->ninstances >= UINT32_MAX)
        return ctx_error(ctx, PK_ERR_LIMIT, "instances: %zu instances are too many", in->ninstances);
    accel_inst *A = mem_calloc(&ctx->alloc, 1, sizeof *A);
    if (!A) return ctx_nomem(ctx);
    A->base.ops = &inst_ops;
    A->base.alloc = &ctx->alloc;
    A->brute = kind == PK_ACCEL_NONE;
    pk_status st = PK_OK;
    if (in0->ntris + in0->nspheres) st = accel_create(ctx, kind, in0, &A->world);
    A->nmeshes = in->nmeshes;
    A->meshes = mem_calloc(&ctx->alloc, in->nmeshes ? in->nmeshes : 1, sizeof *A->meshes);
    A->mesh_box = mem_calloc(&ctx->alloc, in->nmeshes ? in->nmeshes : 1, sizeof *A->mesh_box);
    A->inst = mem_realloc_array(&ctx->alloc, NULL, in->ninstances, sizeof *A->inst);
    A->order = mem_realloc_array(&ctx->alloc, NULL, in->ninstances, sizeof *A->order);
    tl_build tb = {mem_realloc_array(&ctx->alloc, NULL, in->ninstances, sizeof(aabb)),
                   mem_realloc_array(&ctx->alloc, NULL, in->ninstances, sizeof(vec3))};
    if (st == PK_OK && (!A->meshes || !A->mesh_box || !A->inst || !A->order || !tb.box || !tb.cent))
        st = ctx_nomem(ctx);
    for (size_t m = 0; m < in->nmeshes && st == PK_OK; m++) {
        A->mesh_box[m] = mesh_bounds(&in->meshes[m]);
        if (A->mesh_box[m].lo.x > A->mesh_box[m].hi.x) continue; /* nothing to hit */
        accel_input mi = {in->meshes[m].verts, in->meshes[m].ntris, NULL, 0, in0->threads};
        st = accel_create(ctx, kind, &mi, &A->meshes[m]);
    }
    for (size_t i = 0; i < in->ninstances && st == PK_OK; i++) {
        const accel_instance *ii = &in->instances[i];
        A->inst[i].mesh = ii->mesh;
        A->inst[i].prim0 = ii->prim0;
        if (ii->mesh >= in->nmeshes || !xform_invert(&ii->to_world, &A->inst[i].to_object) ||
            (uint64_t)ii->prim0 + in->meshes[ii->mesh].ntris >= PK_NO_HIT ||
            ii->prim0 < in0->ntris + in0->nspheres || (i && ii->prim0 < A->inst[i - 1].prim0)) {
            st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                           "instances: instance %zu: no such mesh, a singular transform or bad numbers", i);
            break;
        }
        A->ninst++;
        if (!A->meshes[ii->mesh]) continue;
        tb.box[i] = placed_box(&ii->to_world, A->mesh_box[ii->mesh]);
        if (!v3_finite(tb.box[i].lo) || !v3_finite(tb.box[i].hi)) {
            st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "instances: instance %zu is placed beyond float range", i);
            break;
        }
        tb.cent[i] = aabb_center(tb.box[i]);
        A->order[A->norder++] = (uint32_t)i;
    }
    if (st == PK_OK && !A->brute) st = tl_build_tree(ctx, A, &tb);
    if (A->brute) mem_free(&ctx->alloc, tb.box);
    else A->ibox = tb.box;
    mem_free(&ctx->alloc, tb.cent);
    if (st != PK_OK) {
        inst_destroy(&A->base);
        return st;
    }
    pk_accel_info *info = &A->base.info;
    const accel *named = A->world;
    for (size_t m = 0; !named && m < A->nmeshes; m++) named = A->meshes[m];
    info->name = named ? named->info.name : "instances";
    A->base.isa = named ? named->isa : NULL;
    add_info(info, A->world, 1);
    for (size_t m = 0; m < A->nmeshes; m++) add_info(info, A->meshes[m], 0);
    for (size_t i = 0; i < A->ninst; i++)
        if (A->meshes[A->inst[i].mesh]) info->primitives += A->meshes[A->inst[i].mesh]->info.primitives;
    info->nodes += A->nnodes;
    for (size_t k = 0; k < A->nnodes; k++) info->leaves += A->nodes[k].count != 0;
    info->bytes += sizeof *A + A->nmeshes * (sizeof *A->meshes + sizeof *A->mesh_box) +
                   A->ninst * (sizeof *A->inst + sizeof *A->order + (A->ibox ? sizeof *A->ibox : 0)) +
                   A->nnodes * sizeof *A->nodes;
    *out = &A->base;
    return PK_OK;
}

/* ---- the checker ---- */

static bool box_has(const tl_node *n, aabb b)
{
    return n->lo[0] <= b.lo.x && n->lo[1] <= b.lo.y && n->lo[2] <= b.lo.z && n->hi[0] >= b.hi.x &&
           n->hi[1] >= b.hi.y && n->hi[2] >= b.hi.z;
}

static aabb tl_box_of(const tl_node *n)
{
    aabb b = {v3(n->lo[0], n->lo[1], n->lo[2]), v3(n->hi[0], n->hi[1], n->hi[2])};
    return b;
}

bool accel_instances_check(const accel *a, char *why, size_t n)
{
#define IFAIL(...) do { if (why) snprintf(why, n, __VA_ARGS__); return false; } while (0)
    char dummy[8];
    if (!why) why = dummy, n = sizeof dummy;
    if (!a || a->ops != &inst_ops) IFAIL("not a two-level structure");
    const accel_inst *A = (const accel_inst *)a;
    char sub[200];
    for (size_t m = 0; m < A->nmeshes; m++) {
        const accel *b = A->meshes[m];
        if (!b || strcmp(b->info.name, "bvh") != 0) continue;
        if (!bvh_check(b, sub, sizeof sub)) IFAIL("mesh %zu: %s", m, sub);
    }
    if (A->world && strcmp(A->world->info.name, "bvh") == 0 && !bvh_check(A->world, sub, sizeof sub))
        IFAIL("world: %s", sub);
    if (A->brute) return true;
    size_t held = 0;
    for (size_t i = 0; i < A->ninst; i++) held += A->meshes[A->inst[i].mesh] != NULL;
    if (held != A->norder) IFAIL("%zu instances can be hit, %zu in the order", held, A->norder);
    if (!A->norder) {
        if (A->nnodes) IFAIL("nodes without instances");
        return true;
    }
    uint8_t *seen = mem_calloc(a->alloc, A->ninst ? A->ninst : 1, 1);
    uint8_t *reached = mem_calloc(a->alloc, A->nnodes, 1);
    uint32_t *stack = mem_calloc(a->alloc, A->nnodes + 1, sizeof *stack);
    bool ok = seen && reached && stack;
    size_t sp = 0, inleaves = 0;
    if (ok) stack[sp++] = 0;
    while (ok && sp) {
        const uint32_t k = stack[--sp];
        const tl_node *nd = &A->nodes[k];
        if (reached[k]++) {
            snprintf(why, n, "node %u reached twice", k);
            ok = false;
            break;
        }
        if (nd->count) {
            if (nd->count > TL_LEAF_MAX || (size_t)nd->index + nd->count > A->norder) {
                snprintf(why, n, "leaf %u out of range", k);
                ok = false;
                break;
            }
            for (uint32_t j = 0; j < nd->count && ok; j++) {
                const uint32_t i = A->order[nd->index + j];
                if (i >= A->ninst || seen[i]++) {
                    snprintf(why, n, "instance %u in two leaves", i);
                    ok = false;
                } else if (!box_has(nd, A->ibox[i])) {
                    snprintf(why, n, "leaf %u: box does not contain instance %u", k, i);
                    ok = false;
                }
                inleaves++;
            }
            continue;
        }
        if (nd->index <= k || nd->index + 1 >= A->nnodes) {
            snprintf(why, n, "node %u: children out of order", k);
            ok = false;
            break;
        }
        for (int c = 0; c < 2; c++)
            if (!box_has(nd, tl_box_of(&A->nodes[nd->index + c]))) {
                snprintf(why, n, "node %u: box does not contain child %d", k, c);
                ok = false;
            }
        stack[sp++] = nd->index;
        stack[sp++] = nd->index + 1;
    }
    if (ok && inleaves != A->norder) {
        snprintf(why, n, "%zu instances in leaves, %zu expected", inleaves, A->norder);
        ok = false;
    }
    mem_free(a->alloc, seen);
    mem_free(a->alloc, reached);
    mem_free(a->alloc, stack);
    return ok;
#undef IFAIL
}

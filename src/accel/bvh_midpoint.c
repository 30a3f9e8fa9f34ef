/*
 * bvh_midpoint.c - a simple BVH, kept for comparison: a binary tree split at the midpoint of the
 * centroid bounds on round-robin axes (x, y, z, x, ...), falling back to the
 * longest axis when every primitive lands on one side. Traversal visits the
 * nearer child first and skips nodes farther than the closest hit so far.
 *
 * Invariants (midpoint_check tests them):
 *  1. a node's box contains its children's boxes and its primitives' boxes;
 *  2. every primitive that can be hit is in exactly one leaf.
 */
#include "accel.h"

#include <stdio.h>
#include <string.h>

#define MID_LEAF_MAX 4
#define MID_MAX_DEPTH 512 /* deeper nodes become leaves; bounds the traversal stack */

typedef struct mid_node {
    aabb box;
    uint32_t first; /* leaf: first index into ids; inner: index of left child (right = left + 1) */
    uint32_t count; /* leaf: number of primitives (> 0); inner: 0 */
} mid_node;

typedef struct accel_mid {
    accel base;
    prim_set ps;
    uint32_t *ids;
    mid_node *nodes;
    uint32_t nnodes;
    uint32_t depth;  /* tree depth, sizes the traversal stack */
} accel_mid;

typedef struct build_state {
    pk_context *ctx;
    accel_mid *m;
    aabb *boxes;     /* per primitive id */
    vec3 *centroids; /* per primitive id */
    uint32_t cap;
} build_state;

static uint32_t new_nodes(build_state *b, uint32_t n)
{
    accel_mid *m = b->m;
    uint32_t first = m->nnodes;
    m->nnodes += n; /* capacity is 2*prims: a binary tree with leaves of >= 1 */
    return first;
}

/* Builds node idx over ids[first, first+count); iterative over a work stack so
 * pathological inputs cannot exhaust the C stack. */
typedef struct build_item {
    uint32_t node, first, count, depth;
} build_item;

static pk_status build(build_state *b, uint32_t nprims)
{
    accel_mid *m = b->m;
    uint32_t root = new_nodes(b, 1);
    build_item *stack = mem_realloc_array(m->base.alloc, NULL, (size_t)nprims + 64, sizeof *stack);
    if (!stack) return ctx_nomem(b->ctx);
    uint32_t sp = 0;
    stack[sp++] = (build_item){root, 0, nprims, 1};
    while (sp) {
        build_item it = stack[--sp];
        if (it.depth > m->depth) m->depth = it.depth;
        mid_node *node = &m->nodes[it.node];
        aabb box = aabb_empty(), cbox = aabb_empty();
        for (uint32_t i = it.first; i < it.first + it.count; i++) {
            box = aabb_union(box, b->boxes[m->ids[i]]);
            cbox = aabb_grow(cbox, b->centroids[m->ids[i]]);
        }
        node->box = box;
        node->first = it.first;
        node->count = it.count;
        if (it.count <= MID_LEAF_MAX || it.depth >= MID_MAX_DEPTH) continue;
        /* round-robin axis by depth, then the longest axis of the centroid bounds */
        int axes[2] = {(int)((it.depth - 1) % 3), 0};
        vec3 ext = aabb_extent(cbox);
        axes[1] = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
        uint32_t mid = 0;
        for (int a = 0; a < 2 && mid == 0; a++) {
            int axis = axes[a];
            float split = 0.5f * (v3_get(cbox.lo, axis) + v3_get(cbox.hi, axis));
            uint32_t i = it.first, j = it.first + it.count;
            while (i < j) {
                if (v3_get(b->centroids[m->ids[i]], axis) < split) {
                    i++;
                } else {
                    uint32_t tmp = m->ids[i];
                    m->ids[i] = m->ids[--j];
                    m->ids[j] = tmp;
                }
            }
            if (i != it.first && i != it.first + it.count) mid = i;
        }
        if (mid == 0) continue; /* all centroids coincide: keep a (larger) leaf */
        uint32_t left = new_nodes(b, 2);
        node = &m->nodes[it.node]; /* (nodes never move: capacity was reserved) */
        node->first = left;
        node->count = 0;
        stack[sp++] = (build_item){left + 1, mid, it.first + it.count - mid, it.depth + 1};
        stack[sp++] = (build_item){left, it.first, mid - it.first, it.depth + 1};
    }
    mem_free(m->base.alloc, stack);
    return PK_OK;
}

/* min/max that return b when a is NaN (0 * inf on a slab plane of a flat box):
 * the slab value goes first, the running interval second. Plain compares,
 * so they compile to minss/maxss instead of calls to fminf/fmaxf. */
static inline float min_nan(float a, float b) { return a < b ? a : b; }
static inline float max_nan(float a, float b) { return a > b ? a : b; }

/* Slab test; tfar is scaled up by 1 + 2*gamma(3) so that rounding never culls
 * a box the ray touches (robust traversal, Ize 2013). */
static inline bool box_hit(const aabb *b, const ray_pre *r, float tmax, float *tnear)
{
    float tx0 = (b->lo.x - r->o.x) * r->inv_d.x, tx1 = (b->hi.x - r->o.x) * r->inv_d.x;
    float ty0 = (b->lo.y - r->o.y) * r->inv_d.y, ty1 = (b->hi.y - r->o.y) * r->inv_d.y;
    float tz0 = (b->lo.z - r->o.z) * r->inv_d.z, tz1 = (b->hi.z - r->o.z) * r->inv_d.z;
    float t0 = r->tmin, t1 = tmax;
    t0 = max_nan(min_nan(tx0, tx1), t0);
    t1 = min_nan(max_nan(tx0, tx1), t1);
    t0 = max_nan(min_nan(ty0, ty1), t0);
    t1 = min_nan(max_nan(ty0, ty1), t1);
    t0 = max_nan(min_nan(tz0, tz1), t0);
    t1 = min_nan(max_nan(tz0, tz1), t1);
    t1 *= 1.0f + 2.0f * 3.0f * 0.5f * 1.1920929e-7f * 1.0001f;
    *tnear = t0;
    return t0 <= t1;
}

static inline bool mid_trace(const accel_mid *m, const ray *r, hit *h, bool any, accel_counters *c)
{
    ray_pre rp = ray_prepare(r);
    hit_clear(h);
    h->t = r->tmax;
    if (m->nnodes == 0) {
        h->t = INFINITY;
        return false;
    }
    uint32_t stack[MID_MAX_DEPTH + 2];
    uint32_t sp = 0;
    float tn;
    if (c) c->nodes++;
    if (box_hit(&m->nodes[0].box, &rp, h->t, &tn)) stack[sp++] = 0;
    while (sp) {
        const mid_node *n = &m->nodes[stack[--sp]];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                if (prim_test(&m->ps, m->ids[i], &rp, h) && any) {
                    if (c) c->tests += i - n->first + 1;
                    return true;
                }
            }
            if (c) c->tests += n->count;
            continue;
        }
        const mid_node *l = &m->nodes[n->first], *rr = l + 1;
        float tl, tr;
        if (c) c->nodes += 2;
        bool hl = box_hit(&l->box, &rp, h->t, &tl);
        bool hr = box_hit(&rr->box, &rp, h->t, &tr);
        if (hl && hr) {
            /* push the farther first so the nearer is visited first */
            if (tl <= tr) {
                stack[sp++] = n->first + 1;
                stack[sp++] = n->first;
            } else {
                stack[sp++] = n->first;
                stack[sp++] = n->first + 1;
            }
        } else if (hl) {
            stack[sp++] = n->first;
        } else if (hr) {
            stack[sp++] = n->first + 1;
        }
    }
    if (h->prim != PK_NO_HIT) return true;
    h->t = INFINITY;
    return false;
}

static bool mid_intersect(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    return c ? mid_trace((const accel_mid *)a, r, h, false, c) : mid_trace((const accel_mid *)a, r, h, false, NULL);
}

static bool mid_occluded(const accel *a, const ray *r, hit *out, accel_counters *c)
{
    hit h;
    hit *hp = out ? out : &h;
    return c ? mid_trace((const accel_mid *)a, r, hp, true, c) : mid_trace((const accel_mid *)a, r, hp, true, NULL);
}

static void mid_destroy(accel *a)
{
    accel_mid *m = (accel_mid *)a;
    const pk_allocator *al = a->alloc;
    prim_set_free(al, &m->ps);
    mem_free(al, m->ids);
    mem_free(al, m->nodes);
    mem_free(al, m);
}

static const accel_ops mid_ops = {mid_destroy, mid_intersect, mid_occluded, NULL, NULL, NULL};

pk_status accel_midpoint_create(pk_context *ctx, const accel_input *in, accel **out)
{
    *out = NULL;
    const pk_allocator *al = &ctx->alloc;
    accel_mid *m = mem_calloc(al, 1, sizeof *m);
    if (!m) return ctx_nomem(ctx);
    m->base.ops = &mid_ops;
    m->base.alloc = al;
    m->base.info.name = "midpoint";
    pk_status st = prim_set_init(ctx, al, in, &m->ps);
    build_state b = {ctx, m, NULL, NULL, 0};
    size_t total = in->ntris + in->nspheres;
    if (st != PK_OK) goto out_fail;
    if (total) {
        m->ids = mem_realloc_array(al, NULL, total, sizeof *m->ids);
        b.boxes = mem_realloc_array(al, NULL, total, sizeof *b.boxes);
        b.centroids = mem_realloc_array(al, NULL, total, sizeof *b.centroids);
        if (!m->ids || !b.boxes || !b.centroids) {
            st = ctx_nomem(ctx);
            goto out_fail;
        }
    }
    uint32_t n = 0;
    for (uint32_t id = 0; id < total; id++) {
        if (!prim_bounds(&m->ps, id, &b.boxes[id])) continue;
        b.centroids[id] = aabb_center(b.boxes[id]);
        m->ids[n++] = id;
    }
    if (n) {
        m->nodes = mem_realloc_array(al, NULL, 2 * (size_t)n, sizeof *m->nodes);
        if (!m->nodes) {
            st = ctx_nomem(ctx);
            goto out_fail;
        }
        st = build(&b, n);
        if (st != PK_OK) goto out_fail;
    }
    size_t leaves = 0;
    for (uint32_t i = 0; i < m->nnodes; i++) leaves += m->nodes[i].count != 0;
    m->base.info.nodes = m->nnodes;
    m->base.info.leaves = leaves;
    m->base.info.primitives = n;
    m->base.info.bytes = sizeof *m + (size_t)m->nnodes * sizeof *m->nodes + total * sizeof *m->ids +
                         in->ntris * 3 * sizeof(vec3) + in->nspheres * sizeof(accel_sphere);
    mem_free(al, b.boxes);
    mem_free(al, b.centroids);
    *out = &m->base;
    return PK_OK;
out_fail:
    mem_free(al, b.boxes);
    mem_free(al, b.centroids);
    mid_destroy(&m->base);
    return st;
}

bool midpoint_check(const accel *a, char *why, size_t n)
{
#define FAIL(...) do { snprintf(why, n, __VA_ARGS__); mem_free(a->alloc, seen); return false; } while (0)
    const accel_mid *m = (const accel_mid *)a;
    size_t total = (size_t)m->ps.ntris + m->ps.nspheres;
    uint8_t *seen = total ? mem_calloc(a->alloc, total, 1) : NULL;
    if (total && !seen) FAIL("out of memory");
    for (uint32_t i = 0; i < m->nnodes; i++) {
        const mid_node *nd = &m->nodes[i];
        if (nd->count == 0) {
            if (nd->first + 1 >= m->nnodes || nd->first <= i) FAIL("node %u: bad child index", i);
            for (int k = 0; k < 2; k++)
                if (!aabb_contains(nd->box, m->nodes[nd->first + k].box)) FAIL("node %u: child box outside", i);
            continue;
        }
        for (uint32_t j = nd->first; j < nd->first + nd->count; j++) {
            uint32_t id = m->ids[j];
            aabb b;
            if (id >= total || !prim_bounds(&m->ps, id, &b)) FAIL("node %u: bad primitive %u", i, id);
            if (!aabb_contains(nd->box, b)) FAIL("node %u: primitive %u outside the box", i, id);
            if (seen[id]++) FAIL("primitive %u in two leaves", id);
        }
    }
    for (size_t id = 0; id < total; id++) {
        aabb b;
        if (!seen[id] && prim_bounds(&m->ps, (uint32_t)id, &b)) FAIL("primitive %zu in no leaf", id);
    }
    mem_free(a->alloc, seen);
    return true;
#undef FAIL
}

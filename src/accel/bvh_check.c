/*
 * bvh_check.c - tests the invariants written beside struct bvh in bvh.h.
 * Used by the unit tests and debug builds; allocates its own bookkeeping.
 */
#include "bvh.h"

#include <stdio.h>
#include <string.h>

typedef struct checker {
    const bvh *t;
    uint8_t *node_seen, *tri_seen, *sphere_seen, *prim_seen;
    uint8_t *cover;   /* per primitive: which of its corners some leaf box holds */
    size_t prims;
    char *why;
    size_t n;
} checker;

static bool fail(checker *k, const char *fmt, ...) PK_PRINTF(2, 3);
static bool fail(checker *k, const char *fmt, ...)
{
    if (k->why && k->n) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(k->why, k->n, fmt, ap);
        va_end(ap);
    }
    return false;
}

static aabb slot_box(const bvh_node *n, int s)
{
    aabb b = {{n->b[BVH_LO_X][s], n->b[BVH_LO_Y][s], n->b[BVH_LO_Z][s]},
              {n->b[BVH_HI_X][s], n->b[BVH_HI_Y][s], n->b[BVH_HI_Z][s]}};
    return b;
}

static bool box_valid(aabb b)
{
    return b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z && v3_finite(b.lo) && v3_finite(b.hi);
}

static bool box_is_empty_marker(aabb b)
{
    return b.lo.x == INFINITY && b.lo.y == INFINITY && b.lo.z == INFINITY && b.hi.x == -INFINITY &&
           b.hi.y == -INFINITY && b.hi.z == -INFINITY;
}

static bool aabb_overlap(aabb b, vec3 lo, vec3 hi)
{
    return lo.x <= b.hi.x && lo.y <= b.hi.y && lo.z <= b.hi.z && hi.x >= b.lo.x && hi.y >= b.lo.y && hi.z >= b.lo.z;
}

static bool point_in(aabb b, vec3 p)
{
    return p.x >= b.lo.x && p.y >= b.lo.y && p.z >= b.lo.z && p.x <= b.hi.x && p.y <= b.hi.y && p.z <= b.hi.z;
}

static bool check_prim(checker *k, uint32_t prim, uint32_t ni, int s)
{
    const accel *a = &k->t->base;
    if (prim >= a->ntris + a->nspheres) return fail(k, "node %u slot %d: prim %u out of range", ni, s, prim);
    if (!k->prim_seen[prim]) k->prims++;
    k->prim_seen[prim] = 1;
    return true;
}

static bool check_leaf(checker *k, uint32_t ref, aabb box, uint32_t ni, int s)
{
    const bvh *t = k->t;
    const size_t first = bvh_leaf_first(ref);
    const uint32_t nb = bvh_leaf_blocks(ref);
    const bool sph = (ref & BVH_SPHERE_LEAF) != 0;
    const size_t nblocks = sph ? t->nsphere_blocks : t->ntri_blocks;
    const int lanes = sph ? BVH_SPHERE_LANES : BVH_TRI_LANES;
    if ((ref & 14u) != ((nb - 1u) << 1) || (ref & ~(uint32_t)31) % (sph ? sizeof(bvh_sphere_block) : sizeof(bvh_tri_block)))
        return fail(k, "node %u slot %d: malformed leaf reference %#x", ni, s, ref);
    if (nb > BVH_MAX_LEAF_BLOCKS || first + nb > nblocks)
        return fail(k, "node %u slot %d: leaf blocks %zu+%u out of range (invariant 3)", ni, s, first, nb);
    uint32_t count = 0;
    for (uint32_t b = 0; b < nb; b++) {
        uint8_t *seen = sph ? &k->sphere_seen[first + b] : &k->tri_seen[first + b];
        if (*seen) return fail(k, "block %zu referenced twice (invariant 5)", first + b);
        *seen = 1;
        const uint32_t *prim = sph ? t->spheres[first + b].prim : t->tris[first + b].prim;
        int used = 0;
        while (used < lanes && prim[used] != PK_NO_HIT) used++;
        for (int l = used; l < lanes; l++)
            if (prim[l] != PK_NO_HIT) return fail(k, "block %zu: a used lane after padding (invariant 3)", first + b);
        if (used == 0 || (b + 1 < nb && used != lanes))
            return fail(k, "block %zu: %d lanes used in a leaf of %u blocks (invariant 3)", first + b, used, nb);
        for (int l = 0; l < used; l++) {
            if (l > 0 && prim[l] <= prim[l - 1])
                return fail(k, "block %zu: lanes not sorted by prim (invariant 3)", first + b);
            if (!check_prim(k, prim[l], ni, s)) return false;
            if (sph) {
                const bvh_sphere_block *sb = &t->spheres[first + b];
                if (prim[l] < t->base.ntris) return fail(k, "sphere leaf holds triangle %u (invariant 3)", prim[l]);
                vec3 c = v3(sb->c[0][l], sb->c[1][l], sb->c[2][l]);
                accel_sphere sp = {c, sb->r[l]};
                if (!bvh_sphere_valid(&sp)) return fail(k, "sphere %u is invalid (invariant 4)", prim[l]);
                if (!aabb_overlap(box, v3_sub(c, v3s(sb->r[l])), v3_add(c, v3s(sb->r[l]))))
                    return fail(k, "sphere %u is outside its slot box (invariant 2)", prim[l]);
                k->cover[prim[l]] |= (uint8_t)(point_in(box, v3_sub(c, v3s(sb->r[l]))) |
                                               point_in(box, v3_add(c, v3s(sb->r[l]))) << 1 | 4);
            } else {
                const bvh_tri_block *tb = &t->tris[first + b];
                if (prim[l] >= t->base.ntris) return fail(k, "triangle leaf holds sphere %u (invariant 3)", prim[l]);
                vec3 v[3];
                for (int j = 0; j < 3; j++) v[j] = v3(tb->v[j][0][l], tb->v[j][1][l], tb->v[j][2][l]);
                if (bvh_tri_degenerate(v[0], v[1], v[2]))
                    return fail(k, "degenerate triangle %u is in a leaf (invariant 4)", prim[l]);
                aabb vb = aabb_grow(aabb_grow(aabb_grow(aabb_empty(), v[0]), v[1]), v[2]);
                if (!aabb_overlap(box, vb.lo, vb.hi))
                    return fail(k, "triangle %u is outside node %u slot %d (invariant 2)", prim[l], ni, s);
                for (int j = 0; j < 3; j++)
                    if (point_in(box, v[j])) k->cover[prim[l]] |= (uint8_t)(1u << j);
            }
        }
        count += (uint32_t)used;
    }
    if (count < 1 || count > BVH_LEAF_MAX)
        return fail(k, "node %u slot %d: leaf of %u primitives (invariant 3)", ni, s, count);
    return true;
}

static bool check_node(checker *k, uint32_t ni, int depth)
{
    const bvh *t = k->t;
    if (depth > BVH_MAX_DEPTH) return fail(k, "tree deeper than %d (invariant 1)", BVH_MAX_DEPTH);
    if (ni >= t->nnodes) return fail(k, "node %u out of range (invariant 1)", ni);
    if (k->node_seen[ni]) return fail(k, "node %u reached twice (invariant 1)", ni);
    k->node_seen[ni] = 1;
    const bvh_node *n = &t->nodes[ni];
    for (int s = 0; s < BVH_WIDTH; s++) {
        uint32_t ref = n->child[s];
        aabb box = slot_box(n, s);
        if (ref == BVH_EMPTY) {
            if (!box_is_empty_marker(box)) return fail(k, "node %u slot %d: empty slot with a box (invariant 2)", ni, s);
            continue;
        }
        if (!box_valid(box)) return fail(k, "node %u slot %d: invalid box (invariant 2)", ni, s);
        if (bvh_is_leaf(ref)) {
            if (!check_leaf(k, ref, box, ni, s)) return false;
            continue;
        }
        if (ref % sizeof(bvh_node)) return fail(k, "node %u slot %d: malformed node reference %#x", ni, s, ref);
        const size_t ci = bvh_node_index(ref);
        if (ci <= ni) return fail(k, "node %u slot %d: child %zu not after its parent (invariant 1)", ni, s, ci);
        if (ci >= t->nnodes) return fail(k, "node %u slot %d: child %zu out of range (invariant 1)", ni, s, ci);
        const bvh_node *cn = &t->nodes[ci];
        int used = 0;
        for (int q = 0; q < BVH_WIDTH; q++) {
            if (cn->child[q] == BVH_EMPTY) continue;
            used++;
            if (!aabb_contains(box, slot_box(cn, q)))
                return fail(k, "node %u slot %d does not contain node %u slot %d (invariant 2)", ni, s, ref, q);
        }
        if (used == 0) return fail(k, "node %zu has no children (invariant 1)", ci);
        if (!check_node(k, (uint32_t)ci, depth + 1)) return false;
    }
    return true;
}

bool bvh_check(const accel *a, char *why, size_t n)
{
    const bvh *t = (const bvh *)a;
    checker k = {t, NULL, NULL, NULL, NULL, NULL, 0, why, n};
    bool ok = false;
    if (why && n) why[0] = '\0';
    if (!t || !t->nodes || t->nnodes == 0) return fail(&k, "no root node (invariant 1)");
    const pk_allocator *al = a->alloc;
    k.node_seen = mem_calloc(al, t->nnodes, 1);
    k.tri_seen = mem_calloc(al, t->ntri_blocks + 1, 1);
    k.sphere_seen = mem_calloc(al, t->nsphere_blocks + 1, 1);
    k.prim_seen = mem_calloc(al, a->ntris + a->nspheres + 1, 1);
    k.cover = mem_calloc(al, a->ntris + a->nspheres + 1, 1);
    if (!k.node_seen || !k.tri_seen || !k.sphere_seen || !k.prim_seen || !k.cover) {
        fail(&k, "out of memory");
        goto out;
    }
    if (!check_node(&k, 0, 1)) goto out;
    for (size_t i = 0; i < t->nnodes; i++)
        if (!k.node_seen[i]) {
            fail(&k, "node %zu is unreachable (invariant 1)", i);
            goto out;
        }
    for (size_t i = 0; i < t->ntri_blocks; i++)
        if (!k.tri_seen[i]) {
            fail(&k, "triangle block %zu is in no leaf (invariant 5)", i);
            goto out;
        }
    for (size_t i = 0; i < t->nsphere_blocks; i++)
        if (!k.sphere_seen[i]) {
            fail(&k, "sphere block %zu is in no leaf (invariant 5)", i);
            goto out;
        }
    for (size_t i = 0; i < a->ntris + a->nspheres; i++)
        if (k.prim_seen[i] && (k.cover[i] & (i < a->ntris ? 7 : 3)) != (i < a->ntris ? 7 : 3)) {
            fail(&k, "primitive %zu: a corner lies in none of its leaves' boxes (invariant 2)", i);
            goto out;
        }
    if (k.prims != a->info.primitives) {
        fail(&k, "%zu primitives in leaves, info says %zu (invariant 4)", k.prims, a->info.primitives);
        goto out;
    }
    if (t->depth > BVH_MAX_DEPTH) {
        fail(&k, "depth %d (invariant 1)", t->depth);
        goto out;
    }
    ok = true;
out:
    mem_free(al, k.node_seen);
    mem_free(al, k.tri_seen);
    mem_free(al, k.sphere_seen);
    mem_free(al, k.prim_seen);
    mem_free(al, k.cover);
    return ok;
}

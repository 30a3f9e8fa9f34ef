/*
 * bvh_gpu.c - converts the CPU's wide BVH (bvh.h) into the GPU layout of
 * bvh_gpu.h, and checks the result: node i of the CPU tree becomes node i,
 * each child box is quantised conservatively in its node's frame, each
 * leaf's triangle lanes become a run of triangle records.
 */
#include "bvh_gpu.h"

#include "bvh.h"

#include <stdio.h>
#include <stdlib.h>

static void say(char *why, size_t n, const char *fmt, ...) PK_PRINTF(3, 4);
static void say(char *why, size_t n, const char *fmt, ...)
{
    if (!why || n == 0) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
}

bool gpu_quantise(float org, unsigned ex, float lo, float hi, uint8_t *qlo, uint8_t *qhi)
{
    if (ex < 1 || ex > 254 || !(lo <= hi) || !(lo >= org)) return false;
    const float s = gpu_scale(ex);
    double fl = floor(((double)lo - (double)org) / (double)s);
    double fh = ceil(((double)hi - (double)org) / (double)s);
    int l = fl < 0.0 ? 0 : fl > 255.0 ? 255 : (int)fl;
    int h = fh < 0.0 ? 0 : fh > 255.0 ? 255 : (int)fh;
    while (l > 0 && gpu_plane(org, (unsigned)l, s) > lo) l--;
    while (h < 255 && gpu_plane(org, (unsigned)h, s) < hi) h++;
    if (gpu_plane(org, (unsigned)l, s) > lo || gpu_plane(org, (unsigned)h, s) < hi) return false;
    /* the fma form (gpu_node_hits_fma) rounds the same exact value once: the
     * same planes unless q * scale overflows, which is then refused */
    if (gpu_fma((float)l, s, org) > lo || gpu_fma((float)h, s, org) < hi) return false;
    *qlo = (uint8_t)l;
    *qhi = (uint8_t)h;
    return true;
}

/* Frame of node src on axis k over its used slots; quantises them into dst.
 * false when no exponent fits (non-finite boxes). */
static bool quantise_axis(const bvh_node *src, gpu_node *dst, int k)
{
    float lo = INFINITY, hi = -INFINITY;
    for (int s = 0; s < BVH_WIDTH; s++) {
        if (src->child[s] == BVH_EMPTY) continue;
        lo = fminf(lo, src->b[2 * k][s]);
        hi = fmaxf(hi, src->b[2 * k + 1][s]);
    }
    if (lo > hi) { /* no used slot */
        dst->org[k] = 0.0f;
        dst->ex[k] = 127;
        return true;
    }
    if (!isfinite(lo) || !isfinite(hi)) return false;
    dst->org[k] = lo;
    /* smallest e with 255 * 2^e >= hi - lo, then larger ones until every slot fits */
    const double ext = (double)hi - (double)lo;
    int e = -126;
    if (ext > 0.0) {
        e = (int)ceil(log2(ext / 255.0));
        if (e < -126) e = -126;
    }
    for (; e <= 127; e++) {
        bool fits = true;
        for (int s = 0; s < GPU_WIDTH && fits; s++) {
            if (src->child[s] == BVH_EMPTY) {
                dst->q[2 * k][s] = 255, dst->q[2 * k + 1][s] = 0;
                continue;
            }
            fits = gpu_quantise(lo, (unsigned)(e + 127), src->b[2 * k][s], src->b[2 * k + 1][s], &dst->q[2 * k][s],
                                &dst->q[2 * k + 1][s]);
        }
        if (fits) {
            dst->ex[k] = (uint8_t)(e + 127);
            return true;
        }
    }
    return false;
}

/* The slot of each CPU slot (slot_of[s]) in the GPU node: children are
 * assigned to the octants about the centre of the node's box by their
 * centroids, greedily, the best-matching (child, octant) pair first (score:
 * the centroid's offset from the centre along the octant's diagonal, ties
 * to the lower child, then the lower octant); empty slots take the octants
 * left over, in order. Slot bit k set: the positive side along axis k. */
static void slot_order(const bvh_node *src, int slot_of[GPU_WIDTH])
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int s = 0; s < BVH_WIDTH; s++) {
        if (src->child[s] == BVH_EMPTY) continue;
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], src->b[2 * k][s]);
            hi[k] = fmaxf(hi[k], src->b[2 * k + 1][s]);
        }
    }
    double score[GPU_WIDTH][GPU_WIDTH]; /* [child slot][octant] */
    for (int s = 0; s < GPU_WIDTH; s++) {
        slot_of[s] = -1;
        for (int o = 0; o < GPU_WIDTH; o++) {
            double d = 0.0;
            if (src->child[s] != BVH_EMPTY)
                for (int k = 0; k < 3; k++) {
                    const double c = 0.5 * ((double)src->b[2 * k][s] + (double)src->b[2 * k + 1][s]) -
                                     0.5 * ((double)lo[k] + (double)hi[k]);
                    if (isfinite(c)) d += (o >> k & 1) ? c : -c;
                }
            score[s][o] = d;
        }
    }
    bool taken[GPU_WIDTH] = {false};
    for (int round = 0; round < GPU_WIDTH; round++) {
        int bs = -1, bo = -1;
        for (int s = 0; s < GPU_WIDTH; s++) {
            if (slot_of[s] >= 0 || src->child[s] == BVH_EMPTY) continue;
            for (int o = 0; o < GPU_WIDTH; o++)
                if (!taken[o] && (bs < 0 || score[s][o] > score[bs][bo])) bs = s, bo = o;
        }
        if (bs < 0) break;
        slot_of[bs] = bo, taken[bo] = true;
    }
    int o = 0;
    for (int s = 0; s < GPU_WIDTH; s++) {
        if (slot_of[s] >= 0) continue;
        while (taken[o]) o++;
        slot_of[s] = o, taken[o] = true;
    }
}

pk_status gpu_layout_build(pk_context *ctx, const pk_allocator *al, const accel *a, gpu_layout *out)
{
    _Static_assert(BVH_WIDTH == GPU_WIDTH, "the GPU node has the CPU node's width");
    _Static_assert(BVH_LEAF_MAX <= GPU_LEAF_MAX, "a CPU leaf fits a GPU leaf");
    const bvh *b = (const bvh *)a;
    memset(out, 0, sizeof *out);
    if (b->nsphere_blocks)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "the GPU traces triangles only: the scene has spheres");
    if (b->nnodes > GPU_LEAF_INDEX)
        return ctx_error(ctx, PK_ERR_LIMIT, "BVH too large for the GPU layout (%zu nodes)", b->nnodes);
    /* records: the used lanes of every block */
    size_t nrec = 0;
    for (size_t i = 0; i < b->ntri_blocks; i++) nrec += bvh_tri_block_count(&b->tris[i]);
    if (nrec > (size_t)GPU_LEAF_INDEX + 1)
        return ctx_error(ctx, PK_ERR_LIMIT, "BVH too large for the GPU layout (%zu triangle references)", nrec);
    out->nodes = mem_calloc(al, b->nnodes ? b->nnodes : 1, sizeof(gpu_node));
    out->tris = mem_calloc(al, nrec ? nrec : 1, sizeof(gpu_tri));
    /* acc: the entries the sorted traversal's stack holds on reaching node i;
     * depth: node i's depth (the root's is 1) */
    uint32_t *acc = mem_calloc(al, 2 * (b->nnodes ? b->nnodes : 1), sizeof(uint32_t));
    if (!out->nodes || !out->tris || !acc) {
        mem_free(al, acc);
        gpu_layout_free(al, out);
        return ctx_nomem(ctx);
    }
    out->nnodes = b->nnodes ? b->nnodes : 1;
    out->scene_tris = b->base.ntris;
    if (!b->nnodes) /* (the builder always makes a root; an empty one otherwise) */
        for (int s = 0; s < GPU_WIDTH; s++) out->nodes[0].child[s] = GPU_EMPTY, out->nodes[0].ex[s % 3] = 127;
    size_t r = 0;
    uint32_t need = 0, need_o = 1;
    uint32_t *depth = acc + (b->nnodes ? b->nnodes : 1);
    depth[0] = 1;
    for (size_t i = 0; i < b->nnodes; i++) {
        const bvh_node *src = &b->nodes[i];
        gpu_node tmp, *dst = &tmp;
        memset(&tmp, 0, sizeof tmp);
        for (int k = 0; k < 3; k++)
            if (!quantise_axis(src, dst, k)) {
                mem_free(al, acc);
                gpu_layout_free(al, out);
                return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "BVH node %zu has a box that cannot be quantised", i);
            }
        uint32_t used = 0;
        for (int s = 0; s < BVH_WIDTH; s++) used += src->child[s] != BVH_EMPTY;
        if (acc[i] + used > need) need = acc[i] + used;
        for (int s = 0; s < BVH_WIDTH; s++) {
            const uint32_t ref = src->child[s];
            if (ref == BVH_EMPTY) {
                dst->child[s] = GPU_EMPTY;
            } else if (!bvh_is_leaf(ref)) {
                const size_t ci = bvh_node_index(ref);
                dst->child[s] = (uint32_t)ci;
                if (ci < b->nnodes) acc[ci] = acc[i] + used - 1u;
            } else {
                const size_t first = bvh_leaf_first(ref);
                const uint32_t nb = bvh_leaf_blocks(ref);
                const size_t r0 = r;
                for (uint32_t bk = 0; bk < nb && first + bk < b->ntri_blocks; bk++) {
                    const bvh_tri_block *blk = &b->tris[first + bk];
                    for (int l = 0; l < BVH_TRI_LANES; l++) {
                        if (blk->prim[l] == PK_NO_HIT) continue;
                        gpu_tri *t = &out->tris[r++];
                        for (int ax = 0; ax < 3; ax++) {
                            t->a[ax] = blk->v[0][ax][l];
                            t->b[ax] = blk->v[1][ax][l];
                            t->c[ax] = blk->v[2][ax][l];
                        }
                        t->prim = blk->prim[l];
                    }
                }
                if (r == r0 || r - r0 > GPU_LEAF_MAX) {
                    mem_free(al, acc);
                    gpu_layout_free(al, out);
                    return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "BVH leaf with %zu triangles", r - r0);
                }
                dst->child[s] = gpu_leaf_ref((uint32_t)r0, (uint32_t)(r - r0));
            }
        }
        /* the slots in octant order (bvh_gpu.h, gpu_trace_ordered) */
        int slot_of[GPU_WIDTH];
        slot_order(src, slot_of);
        gpu_node *fin = &out->nodes[i];
        memcpy(fin->org, tmp.org, sizeof fin->org);
        memcpy(fin->ex, tmp.ex, sizeof fin->ex);
        fin->pad = 0;
        for (int s = 0; s < GPU_WIDTH; s++) {
            fin->child[slot_of[s]] = tmp.child[s];
            for (int row = 0; row < 6; row++) fin->q[row][slot_of[s]] = tmp.q[row][s];
        }
        for (int s = 0; s < GPU_WIDTH; s++)
            if (fin->child[s] != GPU_EMPTY && !(fin->child[s] & GPU_LEAF) && fin->child[s] < b->nnodes) {
                depth[fin->child[s]] = depth[i] + 1u;
                if (depth[i] + 1u > need_o) need_o = depth[i] + 1u;
            }
    }
    mem_free(al, acc);
    out->ntris = r;
    out->stack_need = need;
    out->ordered_need = need_o;
    if (need > GPU_STACK) {
        gpu_layout_free(al, out);
        return ctx_error(ctx, PK_ERR_LIMIT, "BVH too deep for the GPU traversal stack (%u entries needed, %d there)",
                         need, GPU_STACK);
    }
    return PK_OK;
}

void gpu_layout_free(const pk_allocator *al, gpu_layout *g)
{
    mem_free(al, g->nodes);
    mem_free(al, g->tris);
    memset(g, 0, sizeof *g);
}

bool gpu_layout_check_boxes(const gpu_layout *g, const accel *a, char *why, size_t n)
{
    const bvh *b = (const bvh *)a;
    if (g->nnodes != b->nnodes) {
        say(why, n, "%zu nodes for the CPU's %zu", g->nnodes, b->nnodes);
        return false;
    }
    for (size_t i = 0; i < g->nnodes; i++) {
        const gpu_node *gn = &g->nodes[i];
        const bvh_node *cn = &b->nodes[i];
        int slot_of[GPU_WIDTH];
        slot_order(cn, slot_of);
        for (int cs = 0; cs < GPU_WIDTH; cs++) {
            const int s = slot_of[cs]; /* the GPU's slot of the CPU's slot cs */
            const uint32_t cr = cn->child[cs], gr = gn->child[s];
            if ((cr == BVH_EMPTY) != (gr == GPU_EMPTY) ||
                (cr != BVH_EMPTY && bvh_is_leaf(cr) != ((gr & GPU_LEAF) != 0)) ||
                (cr != BVH_EMPTY && !bvh_is_leaf(cr) && bvh_node_index(cr) != gr)) {
                say(why, n, "node %zu slot %d: reference %#x does not match the CPU's %#x", i, s, gr, cr);
                return false;
            }
            if (cr == BVH_EMPTY) continue;
            for (int k = 0; k < 3; k++) {
                const float sc = gpu_scale(gn->ex[k]);
                const float lo = gpu_plane(gn->org[k], gn->q[2 * k][s], sc);
                const float hi = gpu_plane(gn->org[k], gn->q[2 * k + 1][s], sc);
                const float lo2 = gpu_fma((float)gn->q[2 * k][s], sc, gn->org[k]);
                const float hi2 = gpu_fma((float)gn->q[2 * k + 1][s], sc, gn->org[k]);
                if (!(lo <= cn->b[2 * k][cs] && hi >= cn->b[2 * k + 1][cs] && lo2 <= cn->b[2 * k][cs] &&
                      hi2 >= cn->b[2 * k + 1][cs])) {
                    say(why, n, "node %zu slot %d axis %d: decoded [%a, %a] does not contain [%a, %a]", i, s, k,
                        (double)lo, (double)hi, (double)cn->b[2 * k][cs], (double)cn->b[2 * k + 1][cs]);
                    return false;
                }
            }
        }
    }
    return true;
}

typedef struct pbox {
    float lo[3], hi[3];
} pbox;

static bool pbox_inside(const pbox *p, const float v[3])
{
    for (int k = 0; k < 3; k++)
        if (!(v[k] >= p->lo[k] && v[k] <= p->hi[k])) return false;
    return true;
}

bool gpu_layout_check(const gpu_layout *g, const float *verts, char *why, size_t n)
{
    bool ok = false;
    const size_t nn = g->nnodes, nt = g->scene_tris;
    if (nn == 0) {
        say(why, n, "no root node");
        return false;
    }
    uint32_t *parents = calloc(nn, sizeof *parents), *acc = calloc(2 * nn, sizeof *acc);
    uint32_t *owner = calloc(g->ntris ? g->ntris : 1, sizeof *owner);
    uint32_t *refs = calloc(nt ? nt : 1, sizeof *refs);
    unsigned char *cover = calloc(nt ? nt : 1, 1), *whole = calloc(nt ? nt : 1, 1);
    pbox *path = malloc(nn * sizeof *path);
    if (!parents || !acc || !owner || !refs || !cover || !whole || !path) {
        say(why, n, "out of memory");
        goto out;
    }
    for (int k = 0; k < 3; k++) path[0].lo[k] = -INFINITY, path[0].hi[k] = INFINITY;
    uint32_t need = 0, need_o = 1;
    uint32_t *depth = acc ? acc + nn : NULL;
    if (depth) depth[0] = 1;
    for (size_t i = 0; i < nn; i++) {
        const gpu_node *nd = &g->nodes[i];
        if (i > 0 && parents[i] != 1) {
            say(why, n, "node %zu has %u parents", i, parents[i]);
            goto out;
        }
        uint32_t used = 0;
        for (int s = 0; s < GPU_WIDTH; s++) used += nd->child[s] != GPU_EMPTY;
        if (acc[i] + used > need) need = acc[i] + used;
        for (int s = 0; s < GPU_WIDTH; s++) {
            const uint32_t ref = nd->child[s];
            if (ref == GPU_EMPTY) continue;
            pbox box = path[i];
            for (int k = 0; k < 3; k++) {
                if (nd->ex[k] < 1 || nd->ex[k] > 254) {
                    say(why, n, "node %zu: scale exponent %u out of range", i, nd->ex[k]);
                    goto out;
                }
                if (nd->q[2 * k][s] > nd->q[2 * k + 1][s]) {
                    say(why, n, "node %zu slot %d: empty box on axis %d", i, s, k);
                    goto out;
                }
                const float sc = gpu_scale(nd->ex[k]);
                box.lo[k] = fmaxf(box.lo[k], gpu_plane(nd->org[k], nd->q[2 * k][s], sc));
                box.hi[k] = fminf(box.hi[k], gpu_plane(nd->org[k], nd->q[2 * k + 1][s], sc));
            }
            if (!(ref & GPU_LEAF)) {
                if (ref <= i || ref >= nn) {
                    say(why, n, "node %zu slot %d: child node %u out of order or range", i, s, ref);
                    goto out;
                }
                parents[ref]++;
                acc[ref] = acc[i] + used - 1u;
                depth[ref] = depth[i] + 1u;
                if (depth[ref] > need_o) need_o = depth[ref];
                path[ref] = box;
                continue;
            }
            const uint32_t first = gpu_leaf_first(ref), cnt = gpu_leaf_count(ref);
            if ((size_t)first + cnt > g->ntris) {
                say(why, n, "node %zu slot %d: leaf records %u..%u beyond %zu", i, s, first, first + cnt, g->ntris);
                goto out;
            }
            for (uint32_t r = first; r < first + cnt; r++) {
                const gpu_tri *t = &g->tris[r];
                if (owner[r]++) {
                    say(why, n, "triangle record %u is in more than one leaf", r);
                    goto out;
                }
                if (t->prim >= nt) {
                    say(why, n, "triangle record %u: prim %u beyond %zu triangles", r, t->prim, nt);
                    goto out;
                }
                const float *v = verts + 9 * (size_t)t->prim;
                if (memcmp(t->a, v, 12) || memcmp(t->b, v + 3, 12) || memcmp(t->c, v + 6, 12)) {
                    say(why, n, "triangle record %u: vertices differ from triangle %u's", r, t->prim);
                    goto out;
                }
                unsigned in = (unsigned)pbox_inside(&box, t->a) | (unsigned)pbox_inside(&box, t->b) << 1 |
                              (unsigned)pbox_inside(&box, t->c) << 2;
                cover[t->prim] |= (unsigned char)in;
                whole[t->prim] |= in == 7u;
                refs[t->prim]++;
            }
        }
    }
    for (size_t r = 0; r < g->ntris; r++)
        if (owner[r] != 1) {
            say(why, n, "triangle record %zu is in no leaf", r);
            goto out;
        }
    for (size_t p = 0; p < nt; p++) {
        const float *v = verts + 9 * p;
        const bool degenerate = tri_is_degenerate(v3(v[0], v[1], v[2]), v3(v[3], v[4], v[5]), v3(v[6], v[7], v[8]));
        if (degenerate != (refs[p] == 0)) {
            say(why, n, "triangle %zu: %s, but in %u leaves", p, degenerate ? "degenerate" : "can be hit", refs[p]);
            goto out;
        }
        if (degenerate) continue;
        if (cover[p] != 7u || (refs[p] == 1 && !whole[p])) {
            say(why, n, "triangle %zu: a vertex outside the decoded boxes of the path to its leaf", p);
            goto out;
        }
    }
    if (need != g->stack_need || need > GPU_STACK) {
        say(why, n, "traversal stack needs %u entries (layout says %u, limit %d)", need, g->stack_need, GPU_STACK);
        goto out;
    }
    if (need_o != g->ordered_need) {
        say(why, n, "the ordered traversal's stack needs %u entries (layout says %u)", need_o, g->ordered_need);
        goto out;
    }
    ok = true;
out:
    free(parents);
    free(acc);
    free(owner);
    free(refs);
    free(cover);
    free(whole);
    free(path);
    return ok;
}

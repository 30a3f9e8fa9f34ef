/*
 * wavefront.c - the wavefront path tracer on the CPU (see wavefront.h): the
 * stages as OpenMP loops over the pool's queues, rays traced by the frame's
 * accelerator as path.c traces them.
 */
#include <omp.h>
#include <string.h>

/* the CPU's tracing, as in path.c (before wavefront.h, for its stages) */
#define PATH_TRACE(pt, t, r, h) ((pt)->f->a->ops->intersect((pt)->f->a, (r), (h), (t)->cp))
#define PATH_OCCLUDED(pt, t, r) ((pt)->f->a->ops->occluded((pt)->f->a, (r), NULL, (t)->cp))
#include "wavefront.h"

#define WF_POOL_DEFAULT (1 << 16) /* paths in flight */
#define WF_CHUNK_POOLS 8          /* samples run between two accumulations: this many pools */

struct wavefront {
    pk_context *ctx;
    const path_tracer *pt;
    int nt;           /* threads */
    path_thread *ts;  /* one per thread, on cache lines of their own */
    wf_pool p;
    size_t nchunk;    /* samples of p.out */
};

pk_status wavefront_create(pk_context *ctx, const path_tracer *pt, int pool, int threads, wavefront **out)
{
    *out = NULL;
    const pk_allocator *al = &ctx->alloc;
    wavefront *w = mem_calloc(al, 1, sizeof *w);
    if (!w) return ctx_nomem(ctx);
    w->ctx = ctx;
    w->pt = pt;
    w->nt = threads > 0 ? threads : omp_get_max_threads();
    wf_pool *p = &w->p;
    p->n = pool > 0 ? pool : WF_POOL_DEFAULT;
    const size_t n = (size_t)p->n;
    w->nchunk = n * WF_CHUNK_POOLS;
    w->ts = mem_alloc_aligned(al, (size_t)w->nt * sizeof *w->ts, 64);
    p->ps = mem_calloc(al, n, sizeof *p->ps);
    p->aov = mem_calloc(al, n, sizeof *p->aov);
    p->aov_open = mem_calloc(al, n, 1);
    p->stage = mem_calloc(al, n, 1);
    p->bg = mem_calloc(al, n, 1);
    p->item = mem_calloc(al, n, sizeof *p->item);
    p->rq_slot = mem_calloc(al, n, sizeof *p->rq_slot);
    p->rq_ray = mem_calloc(al, n, sizeof *p->rq_ray);
    p->rq_hit = mem_calloc(al, n, sizeof *p->rq_hit);
    p->rq_res = mem_calloc(al, n, 1);
    p->sq = mem_calloc(al, n, sizeof *p->sq);
    p->sq_ray = mem_calloc(al, n, sizeof *p->sq_ray);
    p->sq_c = mem_calloc(al, n, sizeof *p->sq_c);
    p->sq_indirect = mem_calloc(al, n, 1);
    p->sq_has = mem_calloc(al, n, 1);
    p->out = mem_calloc(al, w->nchunk, sizeof *p->out);
    if (!w->ts || !p->ps || !p->aov || !p->aov_open || !p->stage || !p->bg || !p->item || !p->rq_slot ||
        !p->rq_ray || !p->rq_hit || !p->rq_res || !p->sq || !p->sq_ray || !p->sq_c || !p->sq_indirect ||
        !p->sq_has || !p->out) {
        wavefront_destroy(w);
        return ctx_nomem(ctx);
    }
    memset(w->ts, 0, (size_t)w->nt * sizeof *w->ts);
    *out = w;
    return PK_OK;
}

void wavefront_destroy(wavefront *w)
{
    if (!w) return;
    const pk_allocator *al = &w->ctx->alloc;
    const wf_pool *p = &w->p;
    mem_free_aligned(al, w->ts);
    void *arrays[] = {p->ps,     p->aov,    p->aov_open, p->stage, p->bg,   p->item,        p->rq_slot,
                      p->rq_ray, p->rq_hit, p->rq_res,   p->sq,    p->sq_ray, p->sq_c,     p->sq_indirect,
                      p->sq_has, p->out};
    for (size_t i = 0; i < sizeof arrays / sizeof *arrays; i++) mem_free(al, arrays[i]);
    mem_free(al, w);
}

/* Runs the samples numbered c0..c1-1 through the pool into
 * p->out[0..c1-c0-1]: each round, the stages one after the other over the
 * ray queue, as OpenMP loops. The ray queue is filled in slot order by one
 * thread (the GPU fills it with atomics: the order of a queue changes no
 * sample). Every stage reads and writes only its entry's slot, so what
 * matters is the order of the stages for each entry: the CPU runs them in
 * three loops rather than five, for fewer barriers between threads. */
static void run_chunk(wavefront *w, const camera_frame *cf, const wf_pixels *pix, uint64_t first, uint64_t c0,
                      uint64_t c1, bool want_aov)
{
    const path_tracer *pt = w->pt;
    wf_pool *p = &w->p;
    uint64_t next = c0;
    int nrq = 0;
#pragma omp parallel num_threads(w->nt)
    {
        path_thread *t = &w->ts[omp_get_thread_num()];
        for (;;) {
            /* free slots take the next samples, in order; the ray queue
             * gets every slot with a ray to trace */
#pragma omp single
            {
                nrq = 0;
                for (int s = 0; s < p->n; s++) {
                    if (p->stage[s] == WF_FREE && next < c1) {
                        p->item[s] = next++;
                        p->stage[s] = WF_CAMERA;
                    }
                    if (p->stage[s] == WF_CAMERA || p->stage[s] == WF_BOUNCE) p->rq_slot[nrq++] = s;
                }
            }
            if (nrq == 0) break;
            /* generate and intersect; shade; shadow and accumulate */
#pragma omp for schedule(dynamic, 64)
            for (int q = 0; q < nrq; q++) {
                wf_stage_generate(pt, cf, p, pix, first, q, t);
                wf_stage_intersect(pt, p, q, t);
            }
#pragma omp for schedule(dynamic, 64)
            for (int q = 0; q < nrq; q++) wf_stage_shade(pt, p, pix, first, want_aov, q, t);
#pragma omp for schedule(dynamic, 64)
            for (int q = 0; q < nrq; q++) {
                if (p->sq_has[q]) wf_stage_shadow(pt, p, q, t);
                wf_stage_finish(p, c0, want_aov, q);
            }
        }
    }
}

pk_status wavefront_render(wavefront *w, const camera_frame *cf, const gpu_tile *tiles, size_t ntiles,
                           uint64_t first, int spp, float *acc, float *aov, wf_sample *samples, uint64_t rays[3])
{
    pk_context *ctx = w->ctx;
    const pk_allocator *al = &ctx->alloc;
    if (ntiles > SIZE_MAX / (GPU_TILE_PIXELS * 9 * sizeof(float)) || spp < 0)
        return ctx_error(ctx, PK_ERR_LIMIT, "wavefront: %zu tiles of %d samples are too many", ntiles, spp);
    const size_t slots = ntiles * GPU_TILE_PIXELS;
    uint32_t *slot = mem_calloc(al, slots ? slots : 1, sizeof *slot);
    int32_t *px = mem_calloc(al, slots ? slots : 1, sizeof *px), *py = mem_calloc(al, slots ? slots : 1, sizeof *py);
    if (!slot || !px || !py) {
        mem_free(al, slot), mem_free(al, px), mem_free(al, py);
        return ctx_nomem(ctx);
    }
    size_t npix = 0;
    for (size_t j = 0; j < ntiles; j++) {
        const gpu_tile *tl = &tiles[j];
        for (int i = 0; i < tl->w * tl->h; i++, npix++) {
            slot[npix] = (uint32_t)(j * GPU_TILE_PIXELS + (size_t)i);
            px[npix] = tl->x + i % tl->w;
            py[npix] = tl->y + i / tl->w;
        }
    }
    const wf_pixels pix = {slot, px, py, npix};
    memset(acc, 0, slots * 3 * sizeof(float));
    if (aov) memset(aov, 0, 3 * slots * 3 * sizeof(float));
    for (int i = 0; i < w->nt; i++) {
        w->ts[i].rays_camera = w->ts[i].rays_bounce = w->ts[i].rays_shadow = 0;
        w->ts[i].cp = NULL;
    }
    for (int s = 0; s < w->p.n; s++) w->p.stage[s] = WF_FREE;
    const uint64_t total = (uint64_t)npix * (uint64_t)spp;
    for (uint64_t c0 = 0; c0 < total; c0 += w->nchunk) {
        const uint64_t c1 = total - c0 < w->nchunk ? total : c0 + w->nchunk;
        run_chunk(w, cf, &pix, first, c0, c1, aov != NULL);
        /* the pixels' sums, each in the order of its samples, as the loop adds them */
        for (uint64_t k = c0; k < c1; k++) {
            const wf_sample *o = &w->p.out[k - c0];
            if (samples) samples[k] = *o;
            const size_t i = slot[k % npix];
            /* the pixel filter's weight, as the loop's (path_camera_place: 1 but in negative lobes) */
            const float wt =
                path_camera_place(w->pt, px[k % npix], py[k % npix], (uint32_t)(first + k / npix)).weight;
            if (aov) {
                float *a = &aov[3 * i], *nn = &aov[slots * 3 + 3 * i], *d = &aov[slots * 6 + 3 * i];
                a[0] += wt * o->aov.albedo.x, a[1] += wt * o->aov.albedo.y, a[2] += wt * o->aov.albedo.z;
                nn[0] += wt * o->aov.normal.x, nn[1] += wt * o->aov.normal.y, nn[2] += wt * o->aov.normal.z;
                d[0] += wt * o->aov.depth, d[1] += wt * o->aov.depth, d[2] += wt * o->aov.depth;
            }
            if (!o->kept) continue;
            acc[3 * i] += wt * o->L.x;
            acc[3 * i + 1] += wt * o->L.y;
            acc[3 * i + 2] += wt * o->L.z;
        }
    }
    if (rays)
        for (int i = 0; i < w->nt; i++) {
            rays[0] += w->ts[i].rays_camera;
            rays[1] += w->ts[i].rays_bounce;
            rays[2] += w->ts[i].rays_shadow;
        }
    mem_free(al, slot), mem_free(al, px), mem_free(al, py);
    return PK_OK;
}

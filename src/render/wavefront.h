/*
 * wavefront.h - the path tracer as a wavefront: a fixed pool of paths
 * advanced together, one stage at a time over queues, instead of one path
 * traced from start to end by one thread (path_kernel.h path_step). The
 * stages are
 *
 *   generate     free slots of the pool take the next pixel samples, in
 *                order, and their camera rays join the ray queue (with the
 *                next rays of the paths still going);
 *   intersect    the closest hit of every ray in the ray queue, past map_d
 *                holes;
 *   shade        path_kernel.h's phases at each hit: the start of a path
 *                (path_start) or the end of its last bounce (path_arrive),
 *                then the vertex (path_shade), which writes the shadow ray
 *                of its light sample into the shadow queue and leaves the
 *                path's next ray, if any;
 *   shadow       the occlusion test of each shadow ray, adding what it
 *                brings to its path unless blocked;
 *   accumulate   each finished path's radiance (path_result) into the
 *                sample it was started for; the pixels' sums are then
 *                added in the order of their samples.
 *
 * Every sample's radiance is the loop's, bit for bit: the same phases run
 * on the same state in the same order (emission, light sample, then what
 * the next ray finds), and a sample's random numbers depend only on its
 * pixel and index, never on the slot or the moment it runs. Pixels get
 * their sums in the order of their samples whatever the scheduling, so
 * images are the loop's too.
 *
 * The stage functions (wf_*) are PK_HD, for one queue entry each: the CPU
 * runs them in OpenMP loops (wavefront.c), a GPU would run them as one
 * kernel each. As path_kernel.h, they need PATH_TRACE and PATH_OCCLUDED
 * defined before this file is included; without them, only the host
 * interface is declared. The pool's per-path data are arrays of their own
 * (path states, AOVs, sample numbers, stages), the queues arrays of rays,
 * hits and contributions (structure of arrays).
 */
#ifndef PK_WAVEFRONT_H
#define PK_WAVEFRONT_H

#include "integrator.h"
#include "path.h"
#include "path_gpu.h" /* gpu_tile */

/* A pixel sample as the wavefront leaves it: its radiance L when kept (a
 * finite one, else a lost sample the renderer leaves out) and its AOVs. */
typedef struct wf_sample {
    vec3 L;
    aov_sample aov;
    bool kept;
} wf_sample;

typedef struct wavefront wavefront;

/* A wavefront over pt (which outlives it) with pool paths in flight (0: a
 * default) and threads threads (0: all). */
PK_HIDDEN pk_status wavefront_create(pk_context *ctx, const path_tracer *pt, int pool, int threads, wavefront **out);
PK_HIDDEN void wavefront_destroy(wavefront *w);

/* Renders samples first..first+spp-1 of every pixel of tiles[0..ntiles-1]
 * (as path_gpu_render): acc gets the sums of the kept samples
 * (ntiles * GPU_TILE_PIXELS * 3 floats, each tile's pixels in rows of its
 * width; the loop's sums, bit for bit). When not NULL, aov gets the sums of
 * the AOVs as the renderer's tiles take them: 3 arrays of ntiles *
 * GPU_TILE_PIXELS * 3 floats one after the other (albedo, normal, and the
 * depth in all three components); samples gets every sample, sample s of
 * the q-th pixel (tiles in order, each in rows) at samples[s * npix + q],
 * npix the number of pixels of all tiles. rays (not NULL) counts camera,
 * bounce and shadow rays into rays[0..2]. */
PK_HIDDEN pk_status wavefront_render(wavefront *w, const camera_frame *cf, const gpu_tile *tiles, size_t ntiles,
                                     uint64_t first, int spp, float *acc, float *aov, wf_sample *samples,
                                     uint64_t rays[3]);

/* A slot's stage: free, its camera ray or its next ray to trace, or its
 * path finished (to accumulate once its last shadow ray is done). */
enum { WF_FREE, WF_CAMERA, WF_BOUNCE, WF_DONE };
/* What intersect found: nothing, a surface, or nothing behind holes. */
enum { WF_MISS, WF_HIT, WF_HOLE_MISS };

#if defined(PATH_TRACE) && defined(PATH_OCCLUDED)
#include "path_kernel.h"

/* The pool and its queues (host or device arrays). Per slot: */
typedef struct wf_pool {
    int n;                 /* slots */
    path_state *ps;        /* the path */
    aov_sample *aov;       /* its AOVs (when wanted) */
    uint8_t *aov_open;     /* path_aov.open */
    uint8_t *stage;        /* WF_* */
    uint8_t *bg;           /* the camera ray saw the surroundings (wf_shade) */
    uint64_t *item;        /* the sample it runs: sample s of pixel q is s * npix + q */
    /* the ray queue, nrq entries: */
    int32_t *rq_slot;
    ray *rq_ray;
    hit *rq_hit;
    uint8_t *rq_res;       /* WF_MISS, WF_HIT, WF_HOLE_MISS */
    /* the shadow queue: entry q of the ray queue may leave one (sq_has[q]);
     * sq lists those q (on the GPU: the CPU runs them with their entries) */
    int32_t *sq;
    ray *sq_ray;
    vec3 *sq_c;
    uint8_t *sq_indirect;
    uint8_t *sq_has;
    /* the finished samples numbered c0.. (the current chunk) */
    wf_sample *out;
} wf_pool;

/* The pixels a render covers: pixel q (tiles in order, each in rows) lies
 * at (px[q], py[q]), its sums at slot[q] of the accumulation arrays. */
typedef struct wf_pixels {
    const uint32_t *slot;
    const int32_t *px, *py;
    size_t n;
} wf_pixels;


/* generate: the camera ray of sample index of pixel (px, py), placed as
 * the renderer places the loop's (path_camera_place, camera_ray). */
static inline PK_HD ray wf_generate(const path_tracer *pt, const camera_frame *cf, int px, int py, uint32_t index)
{
    const camera_sample cs = path_camera_place(pt, px, py, index);
    return camera_ray(cf, &cs);
}

/* intersect: the closest hit of *r in *h, past map_d holes (r->tmin then
 * lies past the last one, as path_step leaves it). WF_*. */
static inline PK_HD int wf_intersect(const path_tracer *pt, path_thread *t, ray *r, hit *h)
{
    if (!PATH_TRACE(pt, t, r, h)) return WF_MISS;
    if (pt->f->v.has_cutout && !path_past_holes(pt, t, r, h)) return WF_HOLE_MISS;
    return WF_HIT;
}

/* shade: the path in *ps after its ray r (intersect's result res, hit h):
 * for stage WF_CAMERA the camera ray of sample index of pixel (px, py),
 * which starts the path, else the path's last ray. Returns the slot's next
 * stage (WF_BOUNCE: ps->r to trace, or WF_DONE); *shadow tells whether *sr
 * holds a shadow ray to test; *bg is set when the camera ray saw the
 * surroundings, ps->L then the sample's radiance as it is. aov as for
 * path_step. */
static inline PK_HD int wf_shade(const path_tracer *pt, int stage, int px, int py, uint32_t index, int res,
                                 const ray *r, const hit *h, path_state *ps, path_aov *aov, path_shadow *sr,
                                 bool *shadow, bool *bg)
{
    *shadow = false;
    *bg = false;
    if (stage == WF_CAMERA) {
        vec3 c;
        if (!path_start(pt, px, py, index, r, res == WF_MISS ? NULL : h, ps, &c)) {
            ps->L = c;
            if (aov) aov->out->albedo = aov_normalised(c); /* the camera ray's miss: what it sees */
            *bg = true;
            return WF_DONE;
        }
    } else {
        ps->r = *r;
        ps->h = *h;
        if (!path_arrive(pt, ps, aov, res != WF_MISS)) return WF_DONE;
    }
    if (res == WF_HOLE_MISS) { /* through map_d holes, out: the ray came from vertex depth - 1 */
        path_miss(pt, ps, aov, v3_norm(ps->r.d), ps->depth >= 2);
        return WF_DONE;
    }
    const int next = path_shade(pt, ps, aov, sr);
    *shadow = (next & PATH_NEXT_SHADOW) != 0;
    return next & PATH_NEXT_BOUNCE ? WF_BOUNCE : WF_DONE;
}

/* shadow: the shadow ray sr of the path in *ps; what it brings is added
 * unless something blocks it. */
static inline PK_HD void wf_shadow(const path_tracer *pt, path_thread *t, const path_shadow *sr, path_state *ps)
{
    t->rays_shadow++;
    if (!path_occluded(pt, t, &sr->r)) path_add(pt, ps, sr->c, sr->indirect);
}

/* accumulate: the finished path's sample (bg: wf_shade's). */
static inline PK_HD void wf_finish(const path_state *ps, bool bg, wf_sample *out)
{
    if (bg) {
        out->L = ps->L;
        out->kept = true;
        return;
    }
    out->kept = path_result(ps, &out->L);
    if (!out->kept) out->L = v3s(0.0f);
}

/* ---- the stages for entry q of their queue (one GPU thread each) ---------------- */

/* generate: ray-queue entry q gets its ray, a new sample's camera ray
 * (samples numbered from first) or its path's next ray. */
static inline PK_HD void wf_stage_generate(const path_tracer *pt, const camera_frame *cf, const wf_pool *p,
                                           const wf_pixels *pix, uint64_t first, int q, path_thread *t)
{
    const int s = p->rq_slot[q];
    if (p->stage[s] == WF_CAMERA) {
        const size_t pq = (size_t)(p->item[s] % pix->n);
        const uint64_t index = first + p->item[s] / pix->n;
        p->rq_ray[q] = wf_generate(pt, cf, pix->px[pq], pix->py[pq], (uint32_t)index);
        t->rays_camera++;
    } else {
        p->rq_ray[q] = p->ps[s].r;
    }
}

static inline PK_HD void wf_stage_intersect(const path_tracer *pt, const wf_pool *p, int q, path_thread *t)
{
    p->rq_res[q] = (uint8_t)wf_intersect(pt, t, &p->rq_ray[q], &p->rq_hit[q]);
}

/* shade, for ray-queue entry q: the slot's next stage, its shadow ray. */
static inline PK_HD void wf_stage_shade(const path_tracer *pt, const wf_pool *p, const wf_pixels *pix,
                                        uint64_t first, bool want_aov, int q, path_thread *t)
{
    const int s = p->rq_slot[q];
    const int stage = p->stage[s];
    const size_t pq = (size_t)(p->item[s] % pix->n);
    const uint64_t index = first + p->item[s] / pix->n;
    if (stage == WF_CAMERA && want_aov) {
        p->aov[s] = (aov_sample){{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f};
        p->aov_open[s] = 1;
    }
    path_aov pa = {want_aov ? &p->aov[s] : NULL, want_aov && p->aov_open[s] != 0};
    path_shadow sr;
    bool shadow, bg;
    const int st = wf_shade(pt, stage, pix->px[pq], pix->py[pq], (uint32_t)index, p->rq_res[q], &p->rq_ray[q],
                            &p->rq_hit[q], &p->ps[s], want_aov ? &pa : NULL, &sr, &shadow, &bg);
    if (want_aov) p->aov_open[s] = pa.open;
    p->stage[s] = (uint8_t)st;
    p->bg[s] = bg;
    if (st == WF_BOUNCE) t->rays_bounce++;
    p->sq_has[q] = shadow;
    if (shadow) {
        p->sq_ray[q] = sr.r;
        p->sq_c[q] = sr.c;
        p->sq_indirect[q] = sr.indirect;
    }
}

/* shadow, for the shadow ray that ray-queue entry q left (sq_has[q]; the
 * GPU runs the entries listed in sq). */
static inline PK_HD void wf_stage_shadow(const path_tracer *pt, const wf_pool *p, int q, path_thread *t)
{
    const path_shadow sr = {p->sq_ray[q], p->sq_c[q], p->sq_indirect[q] != 0};
    wf_shadow(pt, t, &sr, &p->ps[p->rq_slot[q]]);
}

/* accumulate, for ray-queue entry q: a finished path into its sample
 * (p->out numbered from c0), its slot free again. */
static inline PK_HD void wf_stage_finish(const wf_pool *p, uint64_t c0, bool want_aov, int q)
{
    const int s = p->rq_slot[q];
    if (p->stage[s] != WF_DONE) return;
    wf_sample *o = &p->out[p->item[s] - c0];
    wf_finish(&p->ps[s], p->bg[s] != 0, o);
    o->aov = want_aov ? p->aov[s] : (aov_sample){{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f};
    p->stage[s] = WF_FREE;
}

#endif

#endif

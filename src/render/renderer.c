/*
 * renderer.c - render sessions: the frame is built once; each render splits
 * its regions into 16x16 tiles rendered in parallel (OpenMP, dynamic
 * scheduling), generates camera rays in coherent batches, has the
 * integrator (integrator.h: the path tracer or the Whitted integrator) shade
 * them, with the AOVs of what they see, and adds each finished tile to the
 * film. With the cuda accelerator the path tracer's kernel renders all
 * the tiles on the GPU instead (path_gpu.h) and the tiles go into the same
 * film. Every pixel sample seeds its own random numbers from (pixel,
 * sample), so a pixel's value does not depend on the threads, the tiles or
 * the regions.
 */
#include "render.h"

#include "camera.h"
#include "integrator.h"
#include "path.h"
#include "path_gpu.h"
#include "sampling.h"
#include "surface.h"

#include <omp.h>
#include <stdatomic.h>
#include <string.h>

#define TILE 16
#define BATCH (TILE * TILE)
#define PROGRESS_INTERVAL_S 0.25 /* at most 4 progress reports a second */

/* What the renderer itself counts in each thread: its camera rays and
 * their traversal work. On cache lines of its own (as the integrators'
 * thread states). */
typedef struct worker {
    _Alignas(64) uint64_t rays_camera;
    accel_counters counters;
    accel_counters *cp;     /* &counters when statistics are on, else NULL */
} worker;

struct pk_renderer {
    pk_context *ctx;
    pk_render_options opt;
    int nt;                 /* threads */
    frame fr;
    const integrator_ops *ig;
    void *self;             /* the integrator (ig->self_size bytes) */
    unsigned char *its;     /* nt thread states of ig->thread_size bytes */
    size_t nits;            /* how many of them are initialised */
    worker *ws;             /* nt entries */
    path_gpu *gpu;          /* the path tracer on the GPU (accel PK_ACCEL_CUDA), else NULL */
    pk_camera cam;
    uint32_t pass;          /* sample numbers start at pass * spp */
    pk_stats total;         /* since creation */
};

/* Warnings about scenes that the Whitted integrator will render black or
 * lit differently from what the file suggests. */
static void warn_lighting(pk_context *ctx, const pk_scene *s, const env_light *env, bool path)
{
    size_t emissive_spheres = 0;
    for (size_t i = 0; i < s->nspheres; i++) {
        vec3 ke = s->materials[s->spheres[i].material].ke;
        if (ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f) emissive_spheres++;
    }
    /* the path tracer has no ambient term */
    bool ambient = !path && (s->ambient.x > 0.0f || s->ambient.y > 0.0f || s->ambient.z > 0.0f);
    if (s->nemissive == 0 && s->nlights == 0 && emissive_spheres == 0 && !ambient && !env->active && !env->sun)
        ctx_warn(ctx, "%s: the scene has no light (no emissive triangle or sphere, no point light, a black "
                 "environment): the image will be black", s->name);
    if (emissive_spheres && !path)
        ctx_warn(ctx, "%s: %zu emissive sphere%s visible but light%s nothing: the Whitted integrator lights the scene "
                 "only from emissive triangles and point lights", s->name, emissive_spheres,
                 emissive_spheres == 1 ? " is" : "s are", emissive_spheres == 1 ? "s" : "");
}

/* The path tracer's area lights are one-sided. When a scene's only lights are
 * one-sided triangles and none of them sees the scene on its emitting side
 * while some see it behind them, they are almost surely wound the wrong way:
 * say so. Eight probe rays a side from up to 256 emitters. */
static void warn_facing(pk_context *ctx, const pk_scene *s, const accel *a)
{
    if (s->nemissive == 0 || s->nlights != 0) return;
    for (size_t i = 0; i < s->nspheres; i++) {
        vec3 ke = s->materials[s->spheres[i].material].ke;
        if (ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f) return;
    }
    const size_t step = s->nemissive > 256 ? s->nemissive / 256 : 1;
    size_t front = 0, back = 0;
    vec3 ext = aabb_extent(s->bounds);
    const float eps = 1e-5f * fmaxf(v3_max_comp(ext), 1e-6f), reach = v3_len(ext);
    for (size_t k = 0; k < s->nemissive; k += step) {
        const uint32_t t = s->emissive[k];
        if (s->materials[s->tris[t].material].two_sided) return;
        vec3 va, vb, vc;
        scene_tri_verts(s, t, &va, &vb, &vc);
        vec3 n = tri_normal(va, vb, vc), c = v3_scale(v3_add(v3_add(va, vb), vc), 1.0f / 3.0f);
        for (int side = 0; side < 2; side++) {
            vec3 ns = side ? v3_neg(n) : n;
            for (int j = 0; j < 8; j++) {
                vec3 d = sample_cosine(ns, ((float)j + 0.5f) / 8.0f, (float)((j * 5) % 8) / 8.0f);
                ray r = {v3_add(c, v3_scale(ns, eps + 4e-6f * v3_max_comp(v3(fabsf(c.x), fabsf(c.y), fabsf(c.z))))),
                         0.0f, d, INFINITY};
                hit h;
                /* a hit less than 1% of the scene's size in front of the light (along its
                 * normal) is the surface the light is
                 * mounted on (a ceiling a centimetre above), not the scene */
                if (accel_intersect(a, &r, &h, NULL) && h.t * v3_dot(d, ns) > 0.01f * reach) *(side ? &back : &front) += 1;
            }
        }
    }
    if (front == 0 && back > 0)
        ctx_warn(ctx, "%s: every area light faces away from the scene (a triangle emits on the side its "
                 "counter-clockwise winding faces): wound the wrong way? Reverse the faces, or give the "
                 "material \"two_sided\": true in a JSON scene", s->name);
}

/* n zeroed entries of size bytes (a multiple of 64) starting on a cache
 * line, so that no two threads' entries share one; free with
 * mem_free_aligned. */
static void *calloc_lines(const pk_allocator *al, size_t n, size_t size)
{
    if (n == 0 || size > SIZE_MAX / n) return NULL;
    void *p = mem_alloc_aligned(al, n * size, 64);
    if (p) memset(p, 0, n * size);
    return p;
}

static void *thread_state(const pk_renderer *r, int t) { return r->its + (size_t)t * r->ig->thread_size; }

pk_status renderer_create(pk_context *ctx, const pk_scene *s, const pk_render_options *opt, const pk_camera *cam,
                          pk_renderer **out)
{
    *out = NULL;
    if (opt->transparent && (opt->accel == PK_ACCEL_CUDA || opt->device == PK_DEVICE_CUDA))
        return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                         "device 'cuda': a transparent background is rendered on the CPU only (render without it "
                         "on the GPU, or on the CPU)");
    if (s->nkept && (opt->accel == PK_ACCEL_CUDA || opt->device == PK_DEVICE_CUDA))
        return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                         "device 'cuda': the GPU renders flattened triangles only (the scene keeps %zu instances; "
                         "render on the CPU, or flatten them with the config scene.instances=flatten)",
                         s->nkept);
    pk_renderer *r = mem_calloc(&ctx->alloc, 1, sizeof *r);
    if (!r) return ctx_nomem(ctx);
    r->ctx = ctx;
    r->opt = *opt;
    r->cam = *cam;
    r->nt = opt->threads > 0 ? opt->threads : omp_get_max_threads();
    pk_status st = frame_init(ctx, &r->fr, s, opt->accel, r->nt);
    if (st != PK_OK) {
        mem_free(&ctx->alloc, r);
        return st;
    }
    const bool media = scene_has_media(s);
    if (opt->integrator == PK_INTEGRATOR_VOLPATH || (opt->integrator == PK_INTEGRATOR_DEFAULT && media))
        r->ig = &integrator_volpath;
    else if (opt->integrator == PK_INTEGRATOR_WHITTED)
        r->ig = &integrator_whitted;
    else
        r->ig = &integrator_path;
    if (media && r->ig != &integrator_volpath)
        ctx_warn(ctx, "%s: the %s integrator ignores participating media (volpath renders them)", s->name,
                 r->ig->name);
    r->self = mem_calloc(&ctx->alloc, 1, r->ig->self_size);
    r->its = calloc_lines(&ctx->alloc, (size_t)r->nt, r->ig->thread_size);
    r->ws = calloc_lines(&ctx->alloc, (size_t)r->nt, sizeof *r->ws);
    if (!r->self || !r->its || !r->ws) {
        renderer_destroy(r);
        return ctx_nomem(ctx);
    }
    if ((st = r->ig->init(ctx, r->self, &r->fr, opt)) != PK_OK) {
        renderer_destroy(r); /* ig->free takes what a failed init left */
        return st;
    }
    const camera_frame cf = camera_setup(cam, opt->width, opt->height);
    r->ig->set_camera(r->self, &cf);
    for (int t = 0; t < r->nt; t++) {
        r->ws[t].cp = opt->collect_stats ? &r->ws[t].counters : NULL;
        if ((st = r->ig->thread_init(ctx, r->self, thread_state(r, t), opt->collect_stats != 0)) != PK_OK) {
            renderer_destroy(r);
            return st;
        }
        r->nits++;
    }
    const bool path = r->ig != &integrator_whitted;
    if (path && opt->accel == PK_ACCEL_CUDA && (st = path_gpu_create(ctx, r->self, &r->gpu)) != PK_OK) {
        renderer_destroy(r);
        return st;
    }
    r->total.build_us = r->fr.build_s * 1e6;
    r->total.threads = r->nt;
    r->total.accel_builds = 1;
    warn_lighting(ctx, s, &r->fr.env, path);
    if (path) warn_facing(ctx, s, r->fr.a);
    *out = r;
    return PK_OK;
}

void renderer_destroy(pk_renderer *r)
{
    if (!r) return;
    const pk_allocator *al = &r->ctx->alloc;
    for (size_t t = 0; t < r->nits; t++) r->ig->thread_free(al, thread_state(r, (int)t));
    mem_free_aligned(al, r->its);
    mem_free_aligned(al, r->ws);
    path_gpu_destroy(r->gpu);
    if (r->self) r->ig->free(al, r->self);
    mem_free(al, r->self);
    frame_free(al, &r->fr);
    mem_free(al, r);
}

pk_context *renderer_context(const pk_renderer *r) { return r->ctx; }
const pk_render_options *renderer_options(const pk_renderer *r) { return &r->opt; }
void renderer_set_camera(pk_renderer *r, const pk_camera *cam)
{
    r->cam = *cam;
    const camera_frame cf = camera_setup(cam, r->opt.width, r->opt.height);
    r->ig->set_camera(r->self, &cf);
}
const pk_camera *renderer_camera(const pk_renderer *r) { return &r->cam; }
void renderer_stats(const pk_renderer *r, pk_stats *stats) { *stats = r->total; }
void renderer_set_path_strategy(pk_renderer *r, int strategy)
{
    if (r->ig == &integrator_path || r->ig == &integrator_volpath) ((path_tracer *)r->self)->strategy = strategy;
}
void renderer_set_pass(pk_renderer *r, uint32_t pass) { r->pass = pass; }
uint32_t renderer_pass(const pk_renderer *r) { return r->pass; }
const frame *renderer_frame(const pk_renderer *r) { return &r->fr; }

typedef gpu_tile tile; /* x, y, w, h: at most TILE x TILE */
_Static_assert(TILE * TILE == GPU_TILE_PIXELS, "tiles of the GPU");

static bool regions_overlap(const pk_region *a, const pk_region *b)
{
    return a->x < b->x + b->width && b->x < a->x + a->width && a->y < b->y + b->height && b->y < a->y + a->height;
}

/* Checks the regions and counts their tiles. */
static pk_status check_regions(pk_context *ctx, const pk_region *reg, size_t n, int width, int height,
                               size_t *ntiles)
{
    size_t count = 0;
    for (size_t i = 0; i < n; i++) {
        const pk_region *g = &reg[i];
        if (g->width < 1 || g->height < 1 || g->x < 0 || g->y < 0 || g->x > width - g->width ||
            g->y > height - g->height)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                             "region %zu (%d,%d %dx%d) is empty or not inside the %dx%d image", i, g->x, g->y,
                             g->width, g->height, width, height);
        count += (size_t)((g->width + TILE - 1) / TILE) * (size_t)((g->height + TILE - 1) / TILE);
    }
    /* overlapping regions would add samples twice, from two threads at once */
    if (n <= 4096) {
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n; j++)
                if (regions_overlap(&reg[i], &reg[j]))
                    return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "regions %zu and %zu overlap", i, j);
    } else {
        uint8_t *seen = mem_calloc(&ctx->alloc, (size_t)width * (size_t)height, 1);
        if (!seen) return ctx_nomem(ctx);
        pk_status st = PK_OK;
        for (size_t i = 0; i < n && st == PK_OK; i++)
            for (int y = reg[i].y; y < reg[i].y + reg[i].height && st == PK_OK; y++)
                for (int x = reg[i].x; x < reg[i].x + reg[i].width; x++) {
                    uint8_t *p = &seen[(size_t)y * (size_t)width + (size_t)x];
                    if (*p) {
                        st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "region %zu overlaps an earlier region", i);
                        break;
                    }
                    *p = 1;
                }
        mem_free(&ctx->alloc, seen);
        if (st != PK_OK) return st;
    }
    *ntiles = count;
    return PK_OK;
}

/* The camera ray of sample smp (0..spp-1 of the current pass) of pixel
 * (px, py), placed on the film by the integrator; *w its weight in the
 * pixel (the pixel filter's). */
static inline ray sample_camera_ray(const pk_renderer *r, const camera_frame *cf, int px, int py, int smp, float *w)
{
    const int spp = r->opt.spp;
    const uint64_t index = (uint64_t)r->pass * (uint64_t)spp + (uint64_t)smp;
    const camera_sample cs = r->ig->camera_sample(r->self, px, py, index, smp, spp);
    *w = cs.weight;
    return camera_ray(cf, &cs);
}

/* Nodes visited + primitives tested by camera ray r alone (the heat map). */
static float camera_ray_heat(const pk_renderer *r, const ray *cr)
{
    accel_counters c = {0, 0};
    hit h;
    r->fr.a->ops->intersect(r->fr.a, cr, &h, &c);
    return (float)(c.nodes + c.tests);
}

/* Whether camera ray cr (closest hit *h, prim PK_NO_HIT for none) meets a
 * surface: past the holes of map_d cut-outs, as the integrators go. */
static bool camera_ray_covered(const pk_renderer *r, const ray *cr, const hit *h)
{
    if (h->prim == PK_NO_HIT) return false;
    if (!r->fr.v.has_cutout) return true;
    ray rr = *cr;
    hit hh = *h;
    return trace_past_holes(r->fr.a, &r->fr.v, &rr, &hh, NULL);
}

/* Renders the samples of tile tl into acc (3 floats a pixel) and, when the
 * film holds AOVs, their sums into aovs: camera rays traced as one batch,
 * then each sample shaded by the renderer's integrator. Returns false when
 * cancelled before the last sample. */
static bool render_tile(const pk_renderer *r, int tid, const camera_frame *cf, const tile *tl, float *acc,
                        float (*aovs)[BATCH * 3], unsigned aov_mask, volatile const int *cancel, atomic_int *stop)
{
    const int spp = r->opt.spp;
    const uint64_t first = (uint64_t)r->pass * (uint64_t)spp; /* the pass's first sample number */
    const int tw = tl->w, n = tl->w * tl->h;
    worker *wk = &r->ws[tid];
    void *ts = thread_state(r, tid);
    const bool want_aov = (aov_mask & (PK_AOV_ALBEDO | PK_AOV_NORMAL | PK_AOV_DEPTH)) != 0;
    ray rays[BATCH];
    hit hits[BATCH];
    float wts[BATCH];
    memset(acc, 0, sizeof(float) * 3 * (size_t)n);
    if (aov_mask) memset(aovs, 0, sizeof(float) * FILM_AOVS * BATCH * 3);
    for (int smp = 0; smp < spp; smp++) {
        /* also between samples: a tile at many samples may take long */
        if (smp > 0 && ((cancel && *cancel) || atomic_load_explicit(stop, memory_order_relaxed))) return false;
        for (int i = 0; i < n; i++)
            rays[i] = sample_camera_ray(r, cf, tl->x + i % tw, tl->y + i / tw, smp, &wts[i]);
        wk->rays_camera += (uint64_t)n;
        accel_intersect_many(r->fr.a, rays, hits, (size_t)n, false, wk->cp);
        for (int i = 0; i < n; i++) {
            vec3 c;
            aov_sample av;
            if (want_aov) av = (aov_sample){{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f};
            const int px = tl->x + i % tw, py = tl->y + i / tw;
            if (aov_mask & PK_AOV_HEATMAP) {
                const float heat = camera_ray_heat(r, &rays[i]);
                for (int k = 0; k < 3; k++) aovs[3][3 * i + k] += heat;
            }
            /* weighted by the pixel filter (1 but where a filter with negative lobes is negative) */
            const float w = wts[i];
            if (aov_mask & PK_AOV_ALPHA || r->opt.transparent) {
                const bool covered = camera_ray_covered(r, &rays[i], &hits[i]);
                if (aov_mask & PK_AOV_ALPHA)
                    for (int k = 0; k < 3; k++) aovs[4][3 * i + k] += covered ? w : 0.0f;
                if (!covered && r->opt.transparent) continue; /* the background: nothing, AOVs 0 */
            }
            const bool kept = r->ig->sample(r->self, ts, px, py, first + (uint64_t)smp, &rays[i],
                                            hits[i].prim == PK_NO_HIT ? NULL : &hits[i], &c, want_aov ? &av : NULL);
            if (want_aov) {
                const float *v[3] = {&av.albedo.x, &av.normal.x, NULL};
                for (int k = 0; k < 2; k++)
                    for (int j = 0; j < 3; j++) aovs[k][3 * i + j] += w * v[k][j];
                for (int j = 0; j < 3; j++) aovs[2][3 * i + j] += w * av.depth;
            }
            if (!kept) continue; /* a lost sample, not a poisoned pixel */
            acc[3 * i] += w * c.x;
            acc[3 * i + 1] += w * c.y;
            acc[3 * i + 2] += w * c.z;
        }
    }
    return true;
}

/* Adds a finished tile's AOV sums to the film. */
static void film_add_aovs(pk_film *film, const tile *tl, float (*aovs)[BATCH * 3])
{
    for (int k = 0; k < FILM_AOVS; k++)
        if (film->aovs & (1u << k)) film_add_aov_block(film, k, tl->x, tl->y, tl->w, tl->h, aovs[k]);
}

/* The AOVs of a tile the GPU rendered, from its camera rays traced again on
 * the CPU, one at a time: first-surface AOVs (aov_from_surface: Kd and the
 * shading normal of the first surface hit, zero for a miss), not the
 * path tracer's, which look through mirrors and glass to the first
 * non-specular vertex (path_kernel.h path_aov_vertex). Until these are
 * taken on the device, a GPU render's albedo and normal differ from a CPU
 * render's wherever specular surfaces, emitters or the environment are
 * seen; its depth is the same. */
static void render_tile_aovs_cpu(const pk_renderer *r, const camera_frame *cf, const tile *tl, pk_film *film)
{
    const scene_view *s = &r->fr.v;
    const int tw = tl->w, n = tl->w * tl->h;
    float v[FILM_AOVS][BATCH * 3];
    memset(v, 0, sizeof v);
    const float spread = cf->spread, cone0 = cf->cone0;
    for (int smp = 0; smp < r->opt.spp; smp++)
        for (int i = 0; i < n; i++) {
            float w;
            ray cr = sample_camera_ray(r, cf, tl->x + i % tw, tl->y + i / tw, smp, &w);
            accel_counters c = {0, 0};
            hit h;
            const bool got = r->fr.a->ops->intersect(r->fr.a, &cr, &h, (film->aovs & PK_AOV_HEATMAP) ? &c : NULL);
            float *a = &v[0][3 * i], *nn = &v[1][3 * i], *d = &v[2][3 * i], *hm = &v[3][3 * i], *al = &v[4][3 * i];
            const float heat = (float)(c.nodes + c.tests);
            hm[0] += heat, hm[1] += heat, hm[2] += heat;
            if (!got || (s->has_cutout && !trace_past_holes(r->fr.a, s, &cr, &h, NULL))) continue;
            al[0] += w, al[1] += w, al[2] += w;
            surface sf = surface_at(s, &cr, &h);
            material textured;
            if (sf.m->textured)
                sf = surface_texture(s, &cr, &h, cone0 + spread * h.t * v3_len(cr.d), sf, &textured);
            aov_sample av;
            aov_from_surface(&sf, &cr, &h, &av);
            a[0] += w * av.albedo.x, a[1] += w * av.albedo.y, a[2] += w * av.albedo.z;
            nn[0] += w * av.normal.x, nn[1] += w * av.normal.y, nn[2] += w * av.normal.z;
            d[0] += w * av.depth, d[1] += w * av.depth, d[2] += w * av.depth;
        }
    film_add_aovs(film, tl, v);
}

/* ---- on the GPU ------------------------------------------------------------------ */

typedef struct gpu_progress {
    const pk_renderer *r;
    uint64_t ntiles;
    double t1;
} gpu_progress;

/* Progress in tiles: the fraction of the samples done, of every tile. */
static bool gpu_progress_fn(void *user, uint64_t done, uint64_t total)
{
    const gpu_progress *p = user;
    const pk_render_options *opt = &p->r->opt;
    if (opt->cancel && *opt->cancel) return false;
    if (!opt->progress) return true;
    const uint64_t tiles = p->ntiles * done / total;
    return opt->progress(opt->progress_user, tiles < p->ntiles ? tiles : p->ntiles - 1, p->ntiles, time_now() - p->t1) == 0;
}

/* The tiles rendered by the GPU path tracer, then added to the film (and
 * their AOVs computed on the CPU). A cancelled render adds nothing: every
 * tile is then short of samples. */
static pk_status render_gpu(pk_renderer *r, const tile *tiles, size_t ntiles, const camera_frame *cf, pk_film *film,
                            double t1)
{
    const pk_render_options *opt = &r->opt;
    if (ntiles > SIZE_MAX / (GPU_TILE_PIXELS * 3 * sizeof(float))) return ctx_nomem(r->ctx);
    float *acc = mem_realloc_array(&r->ctx->alloc, NULL, ntiles * GPU_TILE_PIXELS * 3, sizeof(float));
    if (!acc) return ctx_nomem(r->ctx);
    gpu_progress gp = {r, (uint64_t)ntiles, t1};
    if (opt->progress && opt->progress(opt->progress_user, 0, (uint64_t)ntiles, 0.0) != 0) {
        mem_free(&r->ctx->alloc, acc);
        return PK_ERR_CANCELLED;
    }
    uint64_t rays[3] = {0, 0, 0};
    pk_status st = path_gpu_render(r->gpu, cf, tiles, ntiles, r->pass * (uint32_t)opt->spp, opt->spp, acc, rays,
                                   gpu_progress_fn, &gp);
    r->total.rays_camera += rays[0];
    r->total.rays_bounce += rays[1];
    r->total.rays_shadow += rays[2];
    if (st == PK_OK) {
        const long n = (long)ntiles;
#pragma omp parallel for schedule(dynamic, 1) num_threads(r->nt)
        for (long i = 0; i < n; i++) {
            const tile *tl = &tiles[i];
            film_add_block(film, tl->x, tl->y, tl->w, tl->h, &acc[(size_t)i * GPU_TILE_PIXELS * 3], (uint32_t)opt->spp);
            if (film->aovs) render_tile_aovs_cpu(r, cf, tl, film);
        }
    }
    mem_free(&r->ctx->alloc, acc);
    return st;
}

pk_status renderer_render(pk_renderer *r, const pk_region *regions, size_t nregions, pk_film *film)
{
    pk_context *ctx = r->ctx;
    const pk_render_options *opt = &r->opt;
    if (film->width != opt->width || film->height != opt->height)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "the film is %dx%d but the renderer makes %dx%d images",
                         film->width, film->height, opt->width, opt->height);
    const pk_region whole = {0, 0, opt->width, opt->height};
    if (!regions) {
        regions = &whole;
        nregions = 1;
    }
    size_t ntiles = 0;
    pk_status st = check_regions(ctx, regions, nregions, opt->width, opt->height, &ntiles);
    if (st != PK_OK) return st;
    if (ntiles > (size_t)INT32_MAX) return ctx_error(ctx, PK_ERR_LIMIT, "too many regions (%zu tiles)", ntiles);
    tile *tiles = mem_realloc_array(&ctx->alloc, NULL, ntiles ? ntiles : 1, sizeof *tiles);
    if (!tiles) return ctx_nomem(ctx);
    size_t k = 0;
    uint64_t pixels = 0;
    for (size_t i = 0; i < nregions; i++) {
        const pk_region *g = &regions[i];
        pixels += (uint64_t)g->width * (uint64_t)g->height;
        for (int y = g->y; y < g->y + g->height; y += TILE)
            for (int x = g->x; x < g->x + g->width; x += TILE) {
                int x1 = x + TILE < g->x + g->width ? x + TILE : g->x + g->width;
                int y1 = y + TILE < g->y + g->height ? y + TILE : g->y + g->height;
                tiles[k++] = (tile){x, y, x1 - x, y1 - y};
            }
    }

    for (int t = 0; t < r->nt; t++) {
        pk_stats drop;
        r->ig->take_counters(thread_state(r, t), &drop); /* zeroes them */
        r->ws[t].rays_camera = 0;
        r->ws[t].counters = (accel_counters){0, 0};
    }
    const camera_frame cf = camera_setup(&r->cam, opt->width, opt->height);
    if (r->gpu) {
        const double t0 = time_now();
        st = render_gpu(r, tiles, ntiles, &cf, film, t0);
        const double render_s = time_now() - t0;
        mem_free(&ctx->alloc, tiles);
        if (opt->progress && st == PK_OK) opt->progress(opt->progress_user, (uint64_t)ntiles, (uint64_t)ntiles, render_s);
        r->total.render_s += render_s;
        if (st == PK_OK) r->total.pixels += pixels;
        if (st == PK_ERR_CANCELLED) return ctx_error(ctx, PK_ERR_CANCELLED, "render cancelled");
        return st;
    }
    volatile const int *cancel = opt->cancel;
    atomic_int stop = 0;      /* set when the progress callback asks to stop */
    atomic_long done = 0;     /* finished tiles */
    int cancelled = 0;
    const int nt_total = (int)ntiles;
    const double t1 = time_now();
    double last_report = t1;
    if (opt->progress && opt->progress(opt->progress_user, 0, (uint64_t)ntiles, 0.0) != 0) stop = 1;
#pragma omp parallel num_threads(r->nt)
    {
        const int tid = omp_get_thread_num();
        float acc[BATCH * 3];
        float aovs[FILM_AOVS][BATCH * 3];
#pragma omp for schedule(dynamic, 1)
        for (int ti = 0; ti < nt_total; ti++) {
            if ((cancel && *cancel) || atomic_load_explicit(&stop, memory_order_relaxed)) {
#pragma omp atomic write
                cancelled = 1;
                continue;
            }
            const tile *tl = &tiles[ti];
            const bool finished = render_tile(r, tid, &cf, tl, acc, aovs, film->aovs, cancel, &stop);
            if (!finished) { /* an unfinished tile stays black */
#pragma omp atomic write
                cancelled = 1;
                continue;
            }
            film_add_block(film, tl->x, tl->y, tl->w, tl->h, acc, (uint32_t)opt->spp);
            if (film->aovs) film_add_aovs(film, tl, aovs);
            const long d = atomic_fetch_add_explicit(&done, 1, memory_order_relaxed) + 1;
            /* progress reports come from the calling thread only (OpenMP thread 0) */
            if (tid == 0 && opt->progress) {
                const double now = time_now();
                if (now - last_report >= PROGRESS_INTERVAL_S) {
                    last_report = now;
                    if (opt->progress(opt->progress_user, (uint64_t)d, (uint64_t)ntiles, now - t1) != 0)
                        atomic_store(&stop, 1);
                }
            }
        }
    }
    const double render_s = time_now() - t1;
    if (opt->progress) opt->progress(opt->progress_user, (uint64_t)atomic_load(&done), (uint64_t)ntiles, render_s);
    mem_free(&ctx->alloc, tiles);

    pk_stats *s = &r->total;
    for (int t = 0; t < r->nt; t++) {
        r->ig->take_counters(thread_state(r, t), s);
        s->rays_camera += r->ws[t].rays_camera;
        s->intersection_tests += r->ws[t].counters.tests;
        s->nodes_visited += r->ws[t].counters.nodes;
    }
    s->render_s += render_s;
    s->pixels += pixels;
    if (cancelled || atomic_load(&stop)) return ctx_error(ctx, PK_ERR_CANCELLED, "render cancelled");
    return PK_OK;
}

/*
 * render.c - the frame: builds the accelerator, splits the image into tiles
 * rendered in parallel (OpenMP, dynamic scheduling), generates camera rays
 * through pixel centres (stratified jitter for spp > 1) in coherent batches,
 * and gathers the statistics. Every pixel seeds its own random numbers, so the
 * image is the same for any thread count.
 */
#include "render.h"

#include "whitted.h"

#include <omp.h>
#include <string.h>

#define TILE 16
#define BATCH (TILE * TILE)

pk_status render_build_accel(pk_context *ctx, const pk_scene *s, pk_accel_kind kind, int threads, accel **out)
{
    *out = NULL;
    vec3 *verts = NULL;
    accel_sphere *sph = NULL;
    if (s->ntris) {
        verts = mem_realloc_array(&ctx->alloc, NULL, s->ntris, 3 * sizeof *verts); /* overflow-checked */
        if (!verts) return ctx_nomem(ctx);
        for (size_t k = 0; k < s->ntris; k++) scene_tri_verts(s, k, &verts[3 * k], &verts[3 * k + 1], &verts[3 * k + 2]);
    }
    if (s->nspheres) {
        sph = mem_realloc_array(&ctx->alloc, NULL, s->nspheres, sizeof *sph);
        if (!sph) {
            mem_free(&ctx->alloc, verts);
            return ctx_nomem(ctx);
        }
        for (size_t i = 0; i < s->nspheres; i++) {
            sph[i].center = s->spheres[i].center;
            sph[i].radius = s->spheres[i].radius;
        }
    }
    accel_input in = {verts, s->ntris, sph, s->nspheres, threads > 0 ? threads : omp_get_max_threads()};
    pk_status st = accel_create(ctx, kind, &in, out);
    mem_free(&ctx->alloc, verts);
    mem_free(&ctx->alloc, sph);
    return st;
}

void render_trace_rays(const accel *a, const ray *rays, hit *hits, size_t n, int threads, unsigned flags,
                       pk_trace_counters *counters)
{
    int nt = threads > 0 ? threads : omp_get_max_threads();
    const bool any = (flags & PK_TRACE_ANY_HIT) != 0, coherent = (flags & PK_TRACE_COHERENT) != 0;
    const size_t chunk = 256;
    const long nchunks = (long)((n + chunk - 1) / chunk);
    uint64_t tests = 0, nodes = 0;
#pragma omp parallel num_threads(nt) reduction(+ : tests, nodes)
    {
        accel_counters c = {0, 0};
        accel_counters *cp = counters ? &c : NULL;
#pragma omp for schedule(dynamic, 4)
        for (long ci = 0; ci < nchunks; ci++) {
            size_t lo = (size_t)ci * chunk, hi = lo + chunk < n ? lo + chunk : n;
            if (coherent) {
                accel_intersect_many(a, rays + lo, hits + lo, hi - lo, any, cp);
            } else if (any) {
                for (size_t i = lo; i < hi; i++) a->ops->occluded(a, &rays[i], &hits[i], cp);
            } else {
                for (size_t i = lo; i < hi; i++) a->ops->intersect(a, &rays[i], &hits[i], cp);
            }
        }
        tests += c.tests;
        nodes += c.nodes;
    }
    if (counters) {
        counters->intersection_tests += tests;
        counters->nodes_visited += nodes;
    }
}

typedef struct camera_frame {
    vec3 origin, u, v, w; /* w points backwards (from the target to the eye) */
    float half_w, half_h;
    int width, height;
} camera_frame;

static camera_frame camera_setup(const pk_camera *cam, int width, int height)
{
    camera_frame f;
    vec3 from = v3(cam->look_from[0], cam->look_from[1], cam->look_from[2]);
    vec3 at = v3(cam->look_at[0], cam->look_at[1], cam->look_at[2]);
    vec3 up = v3(cam->up[0], cam->up[1], cam->up[2]);
    f.origin = from;
    f.w = v3_norm_scaled(v3_sub(from, at));
    f.u = v3_norm(v3_cross(v3_norm_scaled(up), f.w));
    f.v = v3_cross(f.w, f.u);
    f.half_h = tanf(0.5f * cam->fov_deg * PK_PI / 180.0f);
    f.half_w = f.half_h * (float)width / (float)height;
    f.width = width;
    f.height = height;
    return f;
}

/* Ray through image position (x, y) in pixels, (0,0) the top-left corner. */
static inline ray camera_ray(const camera_frame *f, float x, float y)
{
    float sx = (2.0f * x / (float)f->width - 1.0f) * f->half_w;
    float sy = (1.0f - 2.0f * y / (float)f->height) * f->half_h;
    vec3 d = v3_norm(v3_add(v3_add(v3_scale(f->u, sx), v3_scale(f->v, sy)), v3_neg(f->w)));
    ray r = {f->origin, 0.0f, d, INFINITY};
    return r;
}

pk_status render_scene(pk_context *ctx, const pk_scene *s, const pk_camera *cam, const pk_render_options *opt,
                       pk_image **out, pk_stats *stats)
{
    *out = NULL;
    const pk_allocator *al = &ctx->alloc;
    int nt = opt->threads > 0 ? opt->threads : omp_get_max_threads();
    pk_image *img = NULL;
    accel *a = NULL;
    thread_state *ts = NULL;
    integrator in;
    memset(&in, 0, sizeof in);
    pk_status st = pk_image_create(ctx, opt->width, opt->height, &img);
    if (st != PK_OK) return st;

    double t0 = time_now();
    st = render_build_accel(ctx, s, opt->accel, nt, &a);
    if (st != PK_OK) goto out;
    double build_s = a->info.build_ms > 0.0 ? a->info.build_ms * 1e-3 : time_now() - t0;
    st = integrator_init(ctx, &in, s, a, opt);
    if (st != PK_OK) goto out;

    ts = mem_calloc(al, (size_t)nt, sizeof *ts);
    if (!ts) {
        st = ctx_nomem(ctx);
        goto out;
    }
    size_t nshadow = (size_t)opt->light_samples + s->nlights;
    if (nshadow == 0) nshadow = 1;
    for (int t = 0; t < nt; t++) {
        ts[t].cp = opt->collect_stats ? &ts[t].counters : NULL;
        ts[t].shadow_rays = mem_realloc_array(al, NULL, nshadow, sizeof(ray));
        ts[t].shadow_hits = mem_realloc_array(al, NULL, nshadow, sizeof(hit));
        ts[t].shadow_weight = mem_realloc_array(al, NULL, nshadow, sizeof(vec3));
        if (!ts[t].shadow_rays || !ts[t].shadow_hits || !ts[t].shadow_weight) {
            st = ctx_nomem(ctx);
            goto out;
        }
    }

    camera_frame cf = camera_setup(cam, opt->width, opt->height);
    const int tiles_x = (opt->width + TILE - 1) / TILE, tiles_y = (opt->height + TILE - 1) / TILE;
    const int ntiles = tiles_x * tiles_y;
    const int spp = opt->spp;
    const int sx = (int)ceilf(sqrtf((float)spp)), sy = (spp + sx - 1) / sx;
    volatile const int *cancel = opt->cancel;
    int cancelled = 0;
    double t1 = time_now();
#pragma omp parallel num_threads(nt)
    {
        thread_state *me = &ts[omp_get_thread_num()];
        ray rays[BATCH];
        hit hits[BATCH];
        float acc[BATCH * 3];
#pragma omp for schedule(dynamic, 1)
        for (int tile = 0; tile < ntiles; tile++) {
            if (cancel && *cancel) {
#pragma omp atomic write
                cancelled = 1;
                continue;
            }
            int x0 = (tile % tiles_x) * TILE, y0 = (tile / tiles_x) * TILE;
            int x1 = x0 + TILE < opt->width ? x0 + TILE : opt->width;
            int y1 = y0 + TILE < opt->height ? y0 + TILE : opt->height;
            int tw = x1 - x0, n = tw * (y1 - y0);
            memset(acc, 0, sizeof acc);
            bool stopped = false;
            for (int smp = 0; smp < spp; smp++) {
                /* also between passes: a tile at many samples may take long */
                if (smp > 0 && cancel && *cancel) {
                    stopped = true;
                    break;
                }
                for (int i = 0; i < n; i++) {
                    int px = x0 + i % tw, py = y0 + i / tw;
                    float jx = 0.5f, jy = 0.5f;
                    if (spp > 1) {
                        rng jr = rng_seed(((uint64_t)py << 32) | (uint32_t)px, (uint64_t)smp * 2 + 1);
                        jx = ((float)(smp % sx) + rng_float(&jr)) / (float)sx;
                        jy = ((float)(smp / sx) + rng_float(&jr)) / (float)sy;
                    }
                    rays[i] = camera_ray(&cf, (float)px + jx, (float)py + jy);
                }
                me->rays[RAY_CAMERA] += (uint64_t)n;
                accel_intersect_many(a, rays, hits, (size_t)n, false, me->cp);
                for (int i = 0; i < n; i++) {
                    if (hits[i].prim == PK_NO_HIT) continue;
                    int px = x0 + i % tw, py = y0 + i / tw;
                    me->rng = rng_seed(((uint64_t)py << 32) | (uint32_t)px, (uint64_t)smp * 2);
                    me->ray_budget = WHITTED_RAY_BUDGET;
                    vec3 c = whitted_shade(&in, me, &rays[i], &hits[i], 0);
                    acc[3 * i] += c.x;
                    acc[3 * i + 1] += c.y;
                    acc[3 * i + 2] += c.z;
                }
            }
            if (stopped) { /* an unfinished tile stays black */
#pragma omp atomic write
                cancelled = 1;
                continue;
            }
            float inv = 1.0f / (float)spp;
            for (int i = 0; i < n; i++) {
                int px = x0 + i % tw, py = y0 + i / tw;
                float *dst = img->pixels + 3 * ((size_t)py * (size_t)opt->width + (size_t)px);
                for (int ch = 0; ch < 3; ch++) {
                    float v = acc[3 * i + ch] * inv;
                    dst[ch] = isfinite(v) ? v : 0.0f;
                }
            }
        }
    }
    double render_s = time_now() - t1;

    if (stats) {
        memset(stats, 0, sizeof *stats);
        for (int t = 0; t < nt; t++) {
            stats->rays_camera += ts[t].rays[RAY_CAMERA];
            stats->rays_shadow += ts[t].rays[RAY_SHADOW];
            stats->rays_reflection += ts[t].rays[RAY_REFLECTION];
            stats->rays_refraction += ts[t].rays[RAY_REFRACTION];
            stats->intersection_tests += ts[t].counters.tests;
            stats->nodes_visited += ts[t].counters.nodes;
        }
        stats->build_us = build_s * 1e6;
        stats->render_s = render_s;
        stats->threads = nt;
    }
    if (cancelled) st = ctx_error(ctx, PK_ERR_CANCELLED, "render cancelled");
out:
    if (ts)
        for (int t = 0; t < nt; t++) {
            mem_free(al, ts[t].shadow_rays);
            mem_free(al, ts[t].shadow_hits);
            mem_free(al, ts[t].shadow_weight);
        }
    mem_free(al, ts);
    integrator_free(al, &in);
    accel_destroy(a);
    if (st == PK_OK || st == PK_ERR_CANCELLED)
        *out = img;
    else
        pk_image_destroy(img);
    return st;
}

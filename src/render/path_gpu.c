/*
 * path_gpu.c - the path tracer's structures copied to the GPU, and the
 * render loop around its kernel (see path_gpu.h). The device (driver,
 * memory, launches) is device/cuda.h's: this file opens one with the path
 * tracer's kernels (cuda/path.cu: "path" of the kernels' module) and
 * traces on the cuda accelerator's structure, whose device addresses the
 * accelerator gives (accel_cuda_bvh: one primary context per process).
 *
 * The copies are the CPU's structs byte for byte (nvcc lays C structs out
 * as the host compiler does; a kernel checks their sizes once), with every
 * pointer the device follows replaced by the address of a device copy of
 * its array. Host pointers the device never follows (names, the scene's
 * allocator) are cleared.
 */
#include "path_gpu.h"

#include "device/cuda.h"

#include <stddef.h>
#include <string.h>

#define WHO "device 'cuda'"

#define LAUNCH_TARGET_MS 50.0 /* a launch takes about this long: progress and cancelling stay prompt */

struct path_gpu {
    pk_context *ctx;
    cuda_device *dev;       /* the device with the path tracer's module */
    uint64_t *buf;          /* device buffers to free */
    size_t nbuf, cap_buf;
    uint64_t textures_buf;  /* device texture array (its levels are buffers too) */
    uint64_t d_pt;          /* the device's path_tracer */
    uint64_t d_tiles, d_acc, d_rays;
    size_t cap_tiles;
    size_t bytes;
    unsigned samples_per_launch;
};

/* A device copy of n elements of size bytes at src (0 for none). */
static pk_status upload(path_gpu *g, const void *src, size_t n, size_t size, uint64_t *out)
{
    *out = 0;
    if (!src || n == 0) return PK_OK;
    if (n > SIZE_MAX / size) return ctx_error(g->ctx, PK_ERR_LIMIT, "device 'cuda': buffer too large");
    if (g->nbuf == g->cap_buf) {
        const size_t cap = g->cap_buf ? 2 * g->cap_buf : 32;
        uint64_t *nb = mem_realloc_array(&g->ctx->alloc, g->buf, cap, sizeof *nb);
        if (!nb) return ctx_nomem(g->ctx);
        g->buf = nb;
        g->cap_buf = cap;
    }
    pk_status st = cuda_device_alloc(g->dev, src, n * size, NULL, out);
    if (st != PK_OK) return st;
    g->buf[g->nbuf++] = *out;
    g->bytes += n * size;
    return PK_OK;
}

static void *dev_ptr(uint64_t p) { return (void *)(uintptr_t)p; }

/* The scene's textures with their levels on the device. */
static pk_status upload_textures(path_gpu *g, const pk_scene *s, uint64_t *out)
{
    *out = 0;
    if (s->ntextures == 0) return PK_OK;
    texture *copy = mem_calloc(&g->ctx->alloc, s->ntextures, sizeof *copy);
    if (!copy) return ctx_nomem(g->ctx);
    pk_status st = PK_OK;
    for (size_t i = 0; i < s->ntextures && st == PK_OK; i++) {
        const texture *t = &s->textures[i];
        copy[i] = *t;
        copy[i].key = NULL;
        for (int k = 0; k < t->nlevels && st == PK_OK; k++) {
            const size_t n = (size_t)t->lv[k].w * (size_t)t->lv[k].h * (size_t)t->nc;
            uint64_t p8 = 0, pf = 0;
            st = upload(g, t->lv[k].px8, n, 1, &p8);
            if (st == PK_OK) st = upload(g, t->lv[k].pxf, n, sizeof(float), &pf);
            copy[i].lv[k].px8 = dev_ptr(p8);
            copy[i].lv[k].pxf = dev_ptr(pf);
        }
    }
    if (st == PK_OK) st = upload(g, copy, s->ntextures, sizeof *copy, out);
    mem_free(&g->ctx->alloc, copy);
    return st;
}

static pk_status check_layout(path_gpu *g)
{
    /* sizes of the shared structs as nvcc laid them out, against the host's */
    const uint64_t host[8] = {sizeof(scene_view), sizeof(material), sizeof(texture), sizeof(env_light),
                              sizeof(light_set), sizeof(path_tracer), sizeof(frame), sizeof(camera_frame)};
    uint64_t dev[8] = {0}, d = 0;
    pk_status st = cuda_device_alloc(g->dev, NULL, sizeof dev, NULL, &d);
    if (st != PK_OK) return st;
    void *params[] = {&d};
    st = cuda_device_run(g->dev, "pk_path_layout", 1, 32, params, NULL);
    if (st == PK_OK) st = cuda_device_copy(g->dev, dev, d, sizeof dev, false, NULL);
    cuda_device_free(g->dev, d);
    if (st != PK_OK) return st;
    for (int i = 0; i < 8; i++)
        if (dev[i] != host[i])
            return ctx_error(g->ctx, PK_ERR_UNSUPPORTED,
                             "device 'cuda': the kernels were built with structures laid out differently from "
                             "the library's (struct %d: %llu bytes on the device, %llu on the host): rebuild both",
                             i, (unsigned long long)dev[i], (unsigned long long)host[i]);
    return PK_OK;
}

pk_status path_gpu_create(pk_context *ctx, const path_tracer *pt, path_gpu **out)
{
    *out = NULL;
    const frame *f = pt->f;
    const pk_scene *s = f->s;
    if (!f->a || strcmp(f->a->info.name, "cuda") != 0)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "the GPU path tracer needs the cuda accelerator");
    if (s->nspheres)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "device 'cuda': the GPU renders triangles only (the scene has %zu "
                         "sphere%s)", s->nspheres, s->nspheres == 1 ? "" : "s");
    if (s->nkept)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "device 'cuda': the GPU renders flattened triangles only (the scene "
                         "keeps %zu instances)", s->nkept);
    if (scene_has_media(s))
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "device 'cuda': the GPU does not render participating media (the "
                         "scene has %zu medi%s); render it on the CPU", s->nmedia, s->nmedia == 1 ? "um" : "a");
#if !(defined(PK_HAVE_CUDA) && PK_HAVE_CUDA)
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, WHO " is not available in this build");
#endif
    path_gpu *g = mem_calloc(&ctx->alloc, 1, sizeof *g);
    if (!g) return ctx_nomem(ctx);
    g->ctx = ctx;
    g->samples_per_launch = 1;
    pk_status st = cuda_device_open(ctx, WHO, "path", &g->dev);
    if (st != PK_OK) {
        path_gpu_destroy(g);
        return st;
    }
    st = check_layout(g);

    /* the frame, without the host's scene and accelerator (the device follows neither) */
    frame df = *f;
    df.s = NULL;
    df.a = NULL;
    /* the scene: the frame's view of it, with its arrays on the device */
    scene_view *ds = &df.v;
    ds->spheres = NULL; /* refused above */
    uint64_t p;
#define UP(field, n)                                                          \
    if (st == PK_OK) st = upload(g, s->field, (n), sizeof *s->field, &p); \
    ds->field = dev_ptr(p);
    UP(positions, s->npositions)
    UP(normals, s->nnormals)
    UP(uvs, s->nuvs)
    UP(tris, s->ntris)
    UP(colors, s->colors ? s->npositions : 0)
    UP(tangents, s->tangents ? s->npositions : 0)
    UP(uvs1, s->uvs1 ? s->npositions : 0)
    UP(lights, s->nlights)
    UP(tex_nodes, s->ntex_nodes) /* procedural textures: plain data, evaluated by the same code */
#undef UP
    material *mats = mem_realloc_array(&ctx->alloc, NULL, s->nmaterials ? s->nmaterials : 1, sizeof *mats);
    if (!mats && st == PK_OK) st = ctx_nomem(ctx);
    if (st == PK_OK) {
        memcpy(mats, s->materials, s->nmaterials * sizeof *mats);
        for (size_t i = 0; i < s->nmaterials; i++) mats[i].name = NULL;
        st = upload(g, mats, s->nmaterials, sizeof *mats, &p);
        ds->materials = dev_ptr(p);
    }
    mem_free(&ctx->alloc, mats);
    if (st == PK_OK) st = upload_textures(g, s, &p);
    ds->textures = dev_ptr(p);

    /* the frame and its environment */
    memset(&df.lights, 0, sizeof df.lights);
    env_light *e = &df.env;
    const size_t npix = e->uniform ? 0 : (size_t)e->w * (size_t)e->h;
#define UPE(field, n)                                                        \
    if (st == PK_OK) st = upload(g, f->env.field, (n), sizeof *f->env.field, &p); \
    e->field = dev_ptr(p);
    UPE(rgb, 3 * npix)
    UPE(marginal, e->uniform ? 0 : (size_t)e->h)
    UPE(conditional, npix)
    UPE(weight, npix)
    const size_t ncell = e->portal ? (size_t)e->pw * (size_t)e->ph : 0;
    const size_t nsat = e->portal ? ((size_t)e->pw + 1) * ((size_t)e->ph + 1) : 0;
    UPE(portal_f, ncell)
    UPE(portal_sat, nsat)
#undef UPE
    uint64_t d_frame = 0;
    if (st == PK_OK) st = upload(g, &df, 1, sizeof df, &d_frame);

    /* the path tracer and its lights */
    path_tracer dp = *pt;
    dp.f = dev_ptr(d_frame);
    const light_set *ls = &pt->lights;
#define UPL(field, n)                                                          \
    if (st == PK_OK) st = upload(g, ls->field, (n), sizeof *ls->field, &p); \
    dp.lights.field = dev_ptr(p);
    UPL(lights, ls->n)
    UPL(cdf, ls->n)
    UPL(pmf, ls->n)
    UPL(of_prim, s->ntris + s->nspheres)
#undef UPL
    /* the GPU chooses lights by power: the tree stays on the host */
    dp.lights.use_tree = 0;
    dp.lights.tree = NULL, dp.lights.trail = NULL, dp.lights.inf = NULL, dp.lights.inf_cdf = NULL;
    uint64_t nodes, tris;
    accel_cuda_bvh(f->a, &nodes, &tris);
    dp.gpu_nodes = dev_ptr(nodes);
    dp.gpu_tris = dev_ptr(tris);
    if (st == PK_OK) st = upload(g, &dp, 1, sizeof dp, &g->d_pt);
    if (st != PK_OK) {
        path_gpu_destroy(g);
        return st;
    }
    *out = g;
    return PK_OK;
}

void path_gpu_destroy(path_gpu *g)
{
    if (!g) return;
    if (g->dev) {
        for (size_t i = 0; i < g->nbuf; i++) cuda_device_free(g->dev, g->buf[i]);
        cuda_device_free(g->dev, g->d_tiles);
        cuda_device_free(g->dev, g->d_acc);
        cuda_device_free(g->dev, g->d_rays);
        cuda_device_close(g->dev);
    }
    mem_free(&g->ctx->alloc, g->buf);
    mem_free(&g->ctx->alloc, g);
}

size_t path_gpu_bytes(const path_gpu *g)
{
    return g->bytes + g->cap_tiles * (sizeof(gpu_tile) + GPU_TILE_PIXELS * 3 * sizeof(float)) +
           (g->d_rays ? 3 * sizeof(uint64_t) : 0);
}

/* Tile list, accumulation and counter buffers for ntiles tiles. */
static pk_status ensure_tiles(path_gpu *g, size_t ntiles)
{
    if (!g->d_rays) {
        pk_status st = cuda_device_alloc(g->dev, NULL, 3 * sizeof(uint64_t), NULL, &g->d_rays);
        if (st != PK_OK) return st;
    }
    if (ntiles <= g->cap_tiles) return PK_OK;
    cuda_device_free(g->dev, g->d_tiles);
    cuda_device_free(g->dev, g->d_acc);
    g->d_tiles = g->d_acc = 0;
    g->cap_tiles = 0;
    pk_status st = cuda_device_alloc(g->dev, NULL, ntiles * sizeof(gpu_tile), NULL, &g->d_tiles);
    if (st == PK_OK) st = cuda_device_alloc(g->dev, NULL, ntiles * GPU_TILE_PIXELS * 3 * sizeof(float), NULL, &g->d_acc);
    if (st == PK_OK) g->cap_tiles = ntiles;
    return st;
}

pk_status path_gpu_render(path_gpu *g, const camera_frame *cf, const gpu_tile *tiles, size_t ntiles, uint32_t first,
                          int spp, float *acc, uint64_t rays[3], path_gpu_progress progress, void *user)
{
    if (ntiles == 0 || spp <= 0) return PK_OK;
    if (ntiles > UINT32_MAX / GPU_TILE_PIXELS)
        return ctx_error(g->ctx, PK_ERR_LIMIT, "device 'cuda': too many tiles (%zu)", ntiles);
    pk_status st = ensure_tiles(g, ntiles);
    if (st != PK_OK) return st;
    uint64_t zero[3] = {0, 0, 0};
    if ((st = cuda_device_copy(g->dev, (void *)(uintptr_t)tiles, g->d_tiles, ntiles * sizeof *tiles, true, NULL)) !=
            PK_OK ||
        (st = cuda_device_copy(g->dev, zero, g->d_rays, sizeof zero, true, NULL)) != PK_OK)
        return st;
    /* the camera's fields of the device's path tracer, from this render's
     * camera (set_camera may have changed it since the copy was made) */
    path_tracer pc;
    pc.spread = cf->spread;
    pc.cone0 = cf->cone0;
    pc.lens = camera_has_lens(cf);
    const size_t c0 = offsetof(path_tracer, spread), c1 = offsetof(path_tracer, lens) + sizeof pc.lens;
    if ((st = cuda_device_copy(g->dev, (char *)&pc + c0, g->d_pt + c0, c1 - c0, true, NULL)) != PK_OK) return st;
    unsigned nthreads = (unsigned)(ntiles * GPU_TILE_PIXELS);
    camera_frame cam = *cf;
    const char *kernel = camera_is_pinhole(cf) ? "pk_path_render" : "pk_path_render_camera";
    const uint64_t total = (uint64_t)spp;
    uint64_t done = 0;
    while (done < total) {
        unsigned n = g->samples_per_launch;
        if (n > total - done) n = (unsigned)(total - done);
        uint32_t from = first + (uint32_t)done;
        int accumulate = done > 0;
        void *params[] = {&g->d_pt, &cam, &g->d_tiles, &nthreads, &from, &n, &accumulate, &g->d_acc, &g->d_rays};
        double ms = 0.0;
        if ((st = cuda_device_run(g->dev, kernel, nthreads, 128, params, &ms)) != PK_OK) return st;
        done += n;
        /* the next launch sized to take about LAUNCH_TARGET_MS */
        if (ms > 0.0) {
            double want = (double)n * LAUNCH_TARGET_MS / ms;
            unsigned next = want < 1.0 ? 1u : want > 4096.0 ? 4096u : (unsigned)want;
            if (next > 2 * n) next = 2 * n; /* grow gently: paths vary */
            g->samples_per_launch = next;
        }
        if (progress && done < total && !progress(user, done, total)) {
            st = PK_ERR_CANCELLED; /* (the caller says so) */
            break;
        }
    }
    if (st == PK_OK)
        st = cuda_device_copy(g->dev, acc, g->d_acc, ntiles * GPU_TILE_PIXELS * 3 * sizeof(float), false, NULL);
    uint64_t r[3];
    if (cuda_device_copy(g->dev, r, g->d_rays, sizeof r, false, NULL) == PK_OK)
        for (int k = 0; k < 3; k++) rays[k] += r[k];
    return st;
}

/*
 * test_wavefront.c - the wavefront path tracer (render/wavefront.h) against
 * the loop (the path integrator the renderer calls, path.c): for every
 * pixel sample of several scenes, the same radiance, the same lost samples
 * and the same AOVs, compared with memcmp; the pixels' sums as the loop's
 * tiles add them, bit for bit. Each scene at pool sizes smaller than, equal
 * to and larger than its pixel count, at 1 and 2 threads.
 *
 * Scenes: the built-in Cornell box (also with the mitchell pixel filter,
 * whose negative lobes weight samples); tests/data's textured scene (texture
 * maps, map_d holes, bump and normal maps), its JSON scene (mirror and
 * glass spheres, point lights) and its room (a glossy and a mirror
 * material); CornellBox-Sphere and -Original of ../shared when present.
 *
 * With --bench SCENE WIDTH HEIGHT SPP THREADS POOL, times the loop and the
 * wavefront on SCENE instead, interleaved, five times each, and prints
 * each one's median samples per second (bench/wavefront.sh).
 */
#include "test.h"

#include "render/camera.h"
#include "render/frame.h"
#include "render/integrator.h"
#include "render/path.h"
#include "render/wavefront.h"

#include <omp.h>
#include <stdbool.h>
#include <stdint.h>
#include <time.h>

static pk_context *ctx;
static const pk_filter *case_filter; /* the pixel filter of the next setup_init (NULL: the default box) */

/* What the renderer would render: frame, path tracer, camera. */
typedef struct setup {
    frame f;
    path_tracer pt;
    camera_frame cf;
    int width, height;
} setup;

static void setup_init(setup *su, const pk_scene *s, int width, int height, float clamp, int regularize)
{
    memset(su, 0, sizeof *su);
    REQUIRE(frame_init(ctx, &su->f, s, PK_ACCEL_BVH, 2) == PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = width, o.height = height;
    o.seed = 7;
    o.clamp_indirect = clamp;
    o.regularize = regularize;
    if (case_filter) o.filter = *case_filter;
    REQUIRE(integrator_path.init(ctx, &su->pt, &su->f, &o) == PK_OK);
    pk_camera cam;
    pk_scene_get_camera(s, &cam);
    su->cf = camera_setup(&cam, width, height);
    integrator_path.set_camera(&su->pt, &su->cf);
    su->width = width, su->height = height;
}

static void setup_free(setup *su)
{
    integrator_path.free(&ctx->alloc, &su->pt);
    frame_free(&ctx->alloc, &su->f);
}

/* The tiles of the image, 16 x 16 pixels (partial at the right and bottom). */
static size_t make_tiles(int width, int height, gpu_tile *tiles)
{
    size_t n = 0;
    for (int y = 0; y < height; y += 16)
        for (int x = 0; x < width; x += 16)
            tiles[n++] = (gpu_tile){x, y, width - x < 16 ? width - x : 16, height - y < 16 ? height - y : 16};
    return n;
}

/* Sample index of pixel (px, py) by the loop, as the renderer takes it;
 * *w its pixel filter weight. */
static bool loop_sample(const setup *su, void *ts, int px, int py, uint64_t index, vec3 *L, aov_sample *aov, float *w)
{
    const camera_sample cs = integrator_path.camera_sample(&su->pt, px, py, index, 0, 1);
    *w = cs.weight;
    const ray r = camera_ray(&su->cf, &cs);
    hit h;
    const bool got = su->f.a->ops->intersect(su->f.a, &r, &h, NULL);
    *aov = (aov_sample){{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f};
    return integrator_path.sample(&su->pt, ts, px, py, index, &r, got ? &h : NULL, L, aov);
}

/* The loop's and the wavefront's samples of su's image, spp samples from
 * first, compared. */
static void compare(const char *name, const setup *su, uint64_t first, int spp)
{
    const int w = su->width, h = su->height;
    gpu_tile tiles[1024];
    REQUIRE(((w + 15) / 16) * ((h + 15) / 16) <= 1024);
    const size_t ntiles = make_tiles(w, h, tiles);
    const size_t npix = (size_t)w * (size_t)h, slots = ntiles * 256, nsamples = npix * (size_t)spp;

    /* the loop: samples in the wavefront's numbering, pixel sums as render_tile adds them */
    wf_sample *ref = calloc(nsamples, sizeof *ref);
    float *ref_acc = calloc(slots * 3, sizeof(float)), *ref_aov = calloc(slots * 9, sizeof(float));
    REQUIRE(ref && ref_acc && ref_aov);
    path_thread ts;
    REQUIRE(integrator_path.thread_init(ctx, &su->pt, &ts, false) == PK_OK);
    size_t lost = 0;
    for (int s = 0; s < spp; s++) {
        size_t q = 0;
        for (size_t j = 0; j < ntiles; j++)
            for (int i = 0; i < tiles[j].w * tiles[j].h; i++, q++) {
                const int px = tiles[j].x + i % tiles[j].w, py = tiles[j].y + i / tiles[j].w;
                wf_sample *o = &ref[(size_t)s * npix + q];
                float wt;
                o->kept = loop_sample(su, &ts, px, py, first + (uint64_t)s, &o->L, &o->aov, &wt);
                const size_t k = j * 256 + (size_t)i;
                float *a = &ref_aov[3 * k], *nn = &ref_aov[slots * 3 + 3 * k], *d = &ref_aov[slots * 6 + 3 * k];
                a[0] += wt * o->aov.albedo.x, a[1] += wt * o->aov.albedo.y, a[2] += wt * o->aov.albedo.z;
                nn[0] += wt * o->aov.normal.x, nn[1] += wt * o->aov.normal.y, nn[2] += wt * o->aov.normal.z;
                d[0] += wt * o->aov.depth, d[1] += wt * o->aov.depth, d[2] += wt * o->aov.depth;
                if (!o->kept) {
                    lost++;
                    o->L = v3s(0.0f);
                    continue;
                }
                ref_acc[3 * k] += wt * o->L.x, ref_acc[3 * k + 1] += wt * o->L.y, ref_acc[3 * k + 2] += wt * o->L.z;
            }
    }

    const int pools[] = {37, (int)npix, (int)nsamples + 101};
    wf_sample *got = malloc(nsamples * sizeof *got);
    float *acc = malloc(slots * 3 * sizeof(float)), *aov = malloc(slots * 9 * sizeof(float));
    REQUIRE(got && acc && aov);
    for (int pi = 0; pi < 3; pi++)
        for (int threads = 1; threads <= 2; threads++) {
            wavefront *wf;
            REQUIRE(wavefront_create(ctx, &su->pt, pools[pi], threads, &wf) == PK_OK);
            memset(got, 0xff, nsamples * sizeof *got);
            uint64_t rays[3] = {0, 0, 0};
            REQUIRE(wavefront_render(wf, &su->cf, tiles, ntiles, first, spp, acc, aov, got, rays) == PK_OK);
            size_t bad = 0, first_bad = 0;
            for (size_t k = 0; k < nsamples; k++) {
                const bool same = got[k].kept == ref[k].kept && memcmp(&got[k].L, &ref[k].L, sizeof(vec3)) == 0 &&
                                  memcmp(&got[k].aov, &ref[k].aov, sizeof(aov_sample)) == 0;
                if (!same && bad++ == 0) first_bad = k;
            }
            CHECKF(bad == 0, "%s, pool %d, %d thread(s): %zu of %zu samples differ, the first sample %zu of pixel "
                   "%zu: (%.9g %.9g %.9g) kept %d against the loop's (%.9g %.9g %.9g) kept %d",
                   name, pools[pi], threads, bad, nsamples, first_bad / npix, first_bad % npix,
                   (double)got[first_bad].L.x, (double)got[first_bad].L.y, (double)got[first_bad].L.z,
                   got[first_bad].kept, (double)ref[first_bad].L.x, (double)ref[first_bad].L.y,
                   (double)ref[first_bad].L.z, ref[first_bad].kept);
            CHECKF(memcmp(acc, ref_acc, slots * 3 * sizeof(float)) == 0, "%s, pool %d, %d thread(s): pixel sums",
                   name, pools[pi], threads);
            CHECKF(memcmp(aov, ref_aov, slots * 9 * sizeof(float)) == 0, "%s, pool %d, %d thread(s): AOV sums",
                   name, pools[pi], threads);
            CHECKF(rays[0] == nsamples, "%s: %llu camera rays for %zu samples", name, (unsigned long long)rays[0],
                   nsamples);
            CHECKF(rays[1] > 0 && rays[2] > 0, "%s: %llu bounce and %llu shadow rays", name,
                   (unsigned long long)rays[1], (unsigned long long)rays[2]);
            wavefront_destroy(wf);
        }
    printf("%s: %zu samples (%zu lost) the loop's at pools %d, %d, %d, 1 and 2 threads\n", name, nsamples, lost,
           pools[0], pools[1], pools[2]);
    free(ref), free(ref_acc), free(ref_aov), free(got), free(acc), free(aov);
}

static pk_scene *load(const char *path)
{
    pk_scene *s = NULL;
    const pk_status st = pk_scene_load_file(ctx, path, &s);
    CHECKF(st == PK_OK, "%s: %s", path, pk_context_error(ctx));
    return st == PK_OK ? s : NULL;
}

static void scene_case(const char *name, pk_scene *s, int w, int h, int spp, float clamp, int regularize)
{
    if (!s) return;
    setup su;
    setup_init(&su, s, w, h, clamp, regularize);
    compare(name, &su, 0, spp);
    compare(name, &su, (uint64_t)spp * 3, 2); /* a later pass: samples numbered from 3 spp on */
    setup_free(&su);
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The loop as the renderer runs it on the CPU (renderer.c render_tile):
 * tiles to threads, each tile's camera rays of a sample traced as one
 * batch, then each path to its end; the pixels' sums into acc. */
static void bench_loop(const setup *su, const gpu_tile *tiles, size_t ntiles, int spp, int threads, float *acc)
{
    path_thread *ts = mem_alloc_aligned(&ctx->alloc, (size_t)threads * sizeof *ts, 64);
    REQUIRE(ts);
    for (int i = 0; i < threads; i++) REQUIRE(integrator_path.thread_init(ctx, &su->pt, &ts[i], false) == PK_OK);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (long j = 0; j < (long)ntiles; j++) {
        void *t = &ts[omp_get_thread_num()];
        const gpu_tile *tl = &tiles[j];
        float *a = &acc[(size_t)j * 256 * 3];
        memset(a, 0, 256 * 3 * sizeof(float));
        ray rays[256];
        hit hits[256];
        const int n = tl->w * tl->h;
        for (int s = 0; s < spp; s++) {
            for (int i = 0; i < n; i++) {
                const camera_sample cs =
                    integrator_path.camera_sample(&su->pt, tl->x + i % tl->w, tl->y + i / tl->w, (uint64_t)s, s, spp);
                rays[i] = camera_ray(&su->cf, &cs);
            }
            accel_intersect_many(su->f.a, rays, hits, (size_t)n, false, NULL);
            for (int i = 0; i < n; i++) {
                vec3 L;
                if (integrator_path.sample(&su->pt, t, tl->x + i % tl->w, tl->y + i / tl->w, (uint64_t)s, &rays[i],
                                           hits[i].prim == PK_NO_HIT ? NULL : &hits[i], &L, NULL))
                    a[3 * i] += L.x, a[3 * i + 1] += L.y, a[3 * i + 2] += L.z;
            }
        }
    }
    mem_free_aligned(&ctx->alloc, ts);
}

static int bench(int argc, char **argv)
{
    if (argc != 8) {
        fprintf(stderr, "usage: test_wavefront --bench SCENE WIDTH HEIGHT SPP THREADS POOL\n");
        return 2;
    }
    const int w = atoi(argv[3]), h = atoi(argv[4]), spp = atoi(argv[5]), threads = atoi(argv[6]);
    const int pool = atoi(argv[7]);
    REQUIRE(w > 0 && h > 0 && spp > 0 && threads > 0 && pool >= 0);
    pk_scene *s = load(argv[2]);
    REQUIRE(s);
    setup su;
    setup_init(&su, s, w, h, 0.0f, 0);
    const size_t ntiles = (size_t)((w + 15) / 16) * (size_t)((h + 15) / 16);
    gpu_tile *tiles = malloc(ntiles * sizeof *tiles);
    float *acc = malloc(ntiles * 256 * 3 * sizeof(float)), *ref = malloc(ntiles * 256 * 3 * sizeof(float));
    REQUIRE(tiles && acc && ref);
    make_tiles(w, h, tiles);
    wavefront *wf;
    REQUIRE(wavefront_create(ctx, &su.pt, pool, threads, &wf) == PK_OK);
    double tl[5], tw[5];
    const double samples = (double)w * (double)h * (double)spp;
    for (int k = 0; k < 5; k++) {
        double t0 = now_s();
        bench_loop(&su, tiles, ntiles, spp, threads, ref);
        tl[k] = now_s() - t0;
        t0 = now_s();
        REQUIRE(wavefront_render(wf, &su.cf, tiles, ntiles, 0, spp, acc, NULL, NULL, NULL) == PK_OK);
        tw[k] = now_s() - t0;
        REQUIRE(memcmp(acc, ref, ntiles * 256 * 3 * sizeof(float)) == 0);
    }
    qsort(tl, 5, sizeof *tl, cmp_double);
    qsort(tw, 5, sizeof *tw, cmp_double);
    printf("%s %dx%d %d spp, %d thread(s), pool %d: loop %.3f M samples/s, wavefront %.3f M samples/s "
           "(%.3fx), images identical\n",
           argv[2], w, h, spp, threads, pool, samples / tl[2] * 1e-6, samples / tw[2] * 1e-6, tl[2] / tw[2]);
    wavefront_destroy(wf);
    free(tiles), free(acc), free(ref);
    setup_free(&su);
    pk_scene_destroy(s);
    return 0;
}

int main(int argc, char **argv)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    if (argc > 1 && strcmp(argv[1], "--bench") == 0) {
        const int rc = bench(argc, argv);
        pk_context_destroy(ctx);
        return rc;
    }
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    scene_case("built-in Cornell box", s, 40, 36, 3, 0.0f, 0);
    scene_case("built-in Cornell box, clamped and regularised", s, 24, 20, 2, 0.5f, 1);
    /* a pixel filter with negative lobes: weighted sums, the same placement */
    pk_filter mitchell;
    pk_filter_init(&mitchell, PK_FILTER_MITCHELL);
    case_filter = &mitchell;
    scene_case("built-in Cornell box, mitchell filter", s, 24, 20, 2, 0.0f, 0);
    case_filter = NULL;
    pk_scene_destroy(s);

    const char *data[] = {"tex_scene.obj", "json_example.json", "mpi_room.obj"};
    for (size_t i = 0; i < sizeof data / sizeof *data; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", PK_TEST_DATA, data[i]);
        s = load(path);
        scene_case(data[i], s, 40, 30, 3, 0.0f, 0);
        if (s) pk_scene_destroy(s);
    }

    const char *shared[] = {"scenes/cornell/CornellBox-Sphere.obj", "scenes/cornell/CornellBox-Original.obj"};
    for (size_t i = 0; i < sizeof shared / sizeof *shared; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", PK_SHARED_DIR, shared[i]);
        if (access(path, R_OK) != 0) {
            printf("%s is not there (../shared is absent): skipped\n", path);
            continue;
        }
        s = load(path);
        scene_case(shared[i], s, 32, 32, 3, 0.0f, 0);
        if (s) pk_scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return test_done("test_wavefront");
}

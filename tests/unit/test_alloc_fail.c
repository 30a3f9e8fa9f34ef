/*
 * test_alloc_fail.c - fault injection (as SQLite's test_malloc.c): an
 * allocator that fails the Nth allocation, swept over N through three runs:
 * an OBJ load and a small render, the built-in Cornell box, and a JSON scene
 * that reads meshes and a material library, rendered and written; and the
 * denoiser (weights loaded, network planned, an image denoised) when the
 * weights are there. Every failure must come back as PK_ERR_NOMEM (or the
 * load's own error) without a crash, and every block taken must be freed
 * (the live-block count returns to zero; ASan builds check the rest).
 */
#include "test.h"

#include "paprsek.h"

typedef struct fail_alloc {
    long calls, fail_at; /* fail the call numbered fail_at (1-based); 0 = never */
    long live;           /* blocks currently allocated */
    long failed;
} fail_alloc;

/* Blocks carry a 16-byte header with their size so that live blocks can be counted. */
static void *hook(void *user, void *ptr, size_t size)
{
    fail_alloc *f = user;
    if (size == 0) {
        if (ptr) {
            f->live--;
            free((char *)ptr - 16);
        }
        return NULL;
    }
    f->calls++;
    if (f->fail_at && f->calls == f->fail_at) {
        f->failed++;
        return NULL;
    }
    char *p = realloc(ptr ? (char *)ptr - 16 : NULL, size + 16);
    if (!p) return NULL;
    if (!ptr) f->live++;
    return p + 16;
}

static const char *obj_text =
    "mtllib none.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "vn 0 0 1\nvn 0 1 0\n"
    "usemtl missing\n"
    "f 1//1 2//1 3//1 4//1\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
    "f 1 1 1\n";

/* A JSON scene that reads two meshes (one with a material library) from
 * tests/data, with named and inline materials, spheres and a point light. */
static const char *json_text =
    "{ \"materials\": { \"white\": { \"kd\": [0.7, 0.7, 0.7] }, \"lamp\": { \"ke\": [4, 4, 4] } },\n"
    "  \"meshes\": [ { \"obj\": \"json_floor.obj\", \"transform\": { \"scale\": 4 } },\n"
    "              { \"obj\": \"obj_mat.obj\", \"transform\": { \"translate\": [0, 1, 0] } } ],\n"
    "  \"spheres\": [ { \"center\": [0, 0.5, 0], \"radius\": 0.5, \"material\": \"white\" },\n"
    "               { \"center\": [1, 0.5, 0], \"radius\": 0.3, \"material\": { \"illum\": 7, \"ni\": 1.5 } } ],\n"
    "  \"lights\": [ { \"position\": [0, 3, 2], \"intensity\": 5 } ],\n"
    "  \"camera\": { \"look_from\": [0, 1, 5], \"look_at\": [0, 0.5, 0] } }\n";

enum { RUN_OBJ, RUN_CORNELL, RUN_JSON, RUN_DENOISE };

/* The denoiser's small network on a 20x12 image with albedo and normal. */
static pk_status run_denoise(pk_context *ctx)
{
    pk_image *im[3] = {NULL, NULL, NULL}, *out = NULL;
    pk_status st = PK_OK;
    for (int k = 0; k < 3 && st == PK_OK; k++) {
        st = pk_image_create(ctx, 20, 12, &im[k]);
        if (st != PK_OK) break;
        float *p = pk_image_pixels(im[k]);
        for (int i = 0; i < 20 * 12 * 3; i++) p[i] = k == 2 ? (i % 3 == 2 ? 1.0f : 0.0f) : 0.1f * (float)(i % 7);
    }
    pk_denoise_options o;
    pk_denoise_options_init(&o);
    o.weights = PK_WEIGHTS_DIR;
    o.quality = PK_DENOISE_FAST;
    o.threads = 2;
    if (st == PK_OK) st = pk_denoise(ctx, &o, im[0], im[1], im[2], &out);
    if (st == PK_OK) CHECK(out != NULL);
    for (int k = 0; k < 3; k++) pk_image_destroy(im[k]);
    pk_image_destroy(out);
    return st;
}

/* One run with the Nth allocation failing; returns the status of the first failing step. */
static pk_status run(fail_alloc *f, int mode)
{
    const int use_cornell = mode == RUN_CORNELL;
    pk_allocator a = {hook, f};
    pk_context *ctx = NULL;
    pk_status st = pk_context_create(&a, &ctx);
    if (st != PK_OK) return st;
    pk_scene *s = NULL;
    pk_image *img = NULL;
    if (mode == RUN_DENOISE) {
        st = run_denoise(ctx);
        if (st != PK_OK) CHECKF(pk_context_error(ctx)[0] != '\0', "status %d without a message", (int)st);
        pk_context_destroy(ctx);
        return st;
    }
    if (mode == RUN_JSON)
        st = pk_scene_load_json_memory(ctx, json_text, strlen(json_text), "scene.json", PK_TEST_DATA, &s);
    else
        st = use_cornell ? pk_scene_create_cornell_box(ctx, &s)
                         : pk_scene_load_obj_memory(ctx, obj_text, strlen(obj_text), "cube.obj", NULL, &s);
    if (st == PK_OK) {
        pk_render_options o;
        pk_render_options_init(&o);
        o.width = o.height = 8;
        o.light_samples = 2;
        o.threads = 2;
        o.accel = mode == RUN_OBJ ? PK_ACCEL_MIDPOINT : PK_ACCEL_BVH;
        pk_stats stats;
        st = pk_render(ctx, s, &o, &img, &stats);
        if (st == PK_OK) CHECK(img != NULL);
        if (st != PK_OK) CHECK(img == NULL);
        if (st == PK_OK && mode == RUN_JSON) {
            /* the image write allocates too (the temporary name, a PNG row) */
            char path[] = "/tmp/pk_alloc_fail_XXXXXX.png";
            int fd = mkstemps(path, 4);
            REQUIRE(fd >= 0);
            close(fd);
            st = pk_image_write(ctx, img, path);
            remove(path);
        }
    }
    if (st != PK_OK) CHECKF(pk_context_error(ctx)[0] != '\0', "status %d without a message", (int)st);
    pk_image_destroy(img);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return st;
}

static void sweep(int mode)
{
    fail_alloc f = {0, 0, 0, 0};
    REQUIRE(run(&f, mode) == PK_OK);
    long total = f.calls;
    CHECK(f.live == 0);
    REQUIRE(total > 5);
    long nomem = 0;
    for (long n = 1; n <= total; n++) {
        fail_alloc g = {0, n, 0, 0};
        pk_status st = run(&g, mode);
        CHECKF(g.live == 0, "failing allocation %ld of %ld leaked %ld block(s)", n, total, g.live);
        if (g.failed) {
            CHECKF(st == PK_ERR_NOMEM, "failing allocation %ld of %ld gave status %d, not NOMEM", n, total, (int)st);
            nomem++;
        }
    }
    printf("%s: %ld allocations, each failed once: %ld reported out of memory, no leaks\n",
           mode == RUN_DENOISE ? "denoiser (weights, network, a 20x12 image)"
           : mode == RUN_CORNELL ? "cornell box + bvh render"
           : mode == RUN_JSON  ? "json scene (meshes, MTL) + bvh render + PNG write"
                               : "obj load + midpoint render",
           total, nomem);
}

int main(void)
{
    sweep(RUN_OBJ);
    sweep(RUN_CORNELL);
    sweep(RUN_JSON);
    char probe[512];
    snprintf(probe, sizeof probe, "%s/rt_hdr_alb_nrm_small.tza", PK_WEIGHTS_DIR);
    pk_context *ctx = NULL;
    pk_context_create(NULL, &ctx);
    if (access(probe, R_OK) != 0)
        printf("denoiser sweep skipped: no weights at %s (make weights)\n", PK_WEIGHTS_DIR);
    else if (pk_denoise_check(ctx, NULL) != PK_OK && strstr(pk_context_error(ctx), "oneDNN"))
        printf("denoiser sweep skipped: %s\n", pk_context_error(ctx));
    else
        sweep(RUN_DENOISE);
    pk_context_destroy(ctx);
    return test_done("test_alloc_fail");
}

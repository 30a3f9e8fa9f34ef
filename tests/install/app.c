/*
 * app.c - an application of the installed library, built by the install
 * tests against the shared and the static library (pkg-config and CMake).
 * It renders the built-in Cornell box at 32x32 through the public API and
 * checks that the image is not black. Prints nothing unless something fails
 * (the library itself must never print), exits non-zero on failure.
 *
 *   app                        the render only
 *   app embree                 also a render with the Embree accelerator
 *   app embree-missing TEXT    Embree is unavailable: pk_accel_available says
 *                              0, pk_accel_create fails with
 *                              PK_ERR_UNSUPPORTED and a message holding TEXT
 */
#include <paprsek.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Names the library uses inside (for its own hidden functions): an
 * application must be free to define them. With a library that exported
 * them, the static link would fail (multiple definitions) or the shared
 * library would call these instead of its own. */
double time_now(void) { return 42.0; }
int mem_alloc(int x) { return x + 1; }
int image_write(void) { return 7; }
int scene_create(void) { return 8; }
int ctx_error(void) { return 9; }

static int failures;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (!(cond)) {                                                               \
            fprintf(stderr, "app.c:%d: check failed: %s\n", __LINE__, #cond);        \
            failures++;                                                              \
        }                                                                            \
    } while (0)

/* Renders the scene at 32x32 with accel; 1 when some pixel is not black. */
static int render_lit(pk_context *ctx, const pk_scene *scene, pk_accel_kind accel)
{
    pk_render_options opt;
    pk_render_options_init(&opt);
    opt.width = 32;
    opt.height = 32;
    opt.light_samples = 4;
    opt.threads = 2;
    opt.accel = accel;
    pk_image *img = NULL;
    pk_status st = pk_render(ctx, scene, &opt, &img, NULL);
    if (st != PK_OK) {
        fprintf(stderr, "app: pk_render (%s): %s: %s\n", pk_accel_kind_name(accel),
                pk_status_string(st), pk_context_error(ctx));
        pk_image_destroy(img);
        return 0;
    }
    int lit = 0;
    if (img && pk_image_width(img) == 32 && pk_image_height(img) == 32) {
        const float *px = pk_image_pixels_const(img);
        for (int i = 0; i < 3 * 32 * 32; i++)
            if (px[i] > 0.0f) lit = 1;
    }
    pk_image_destroy(img);
    return lit;
}

int main(int argc, char **argv)
{
    const char *mode = argc > 1 ? argv[1] : "";

    CHECK(time_now() == 42.0 && mem_alloc(1) == 2 && image_write() == 7 && scene_create() == 8 &&
          ctx_error() == 9);
    CHECK(strcmp(pk_status_string(PK_OK), "") != 0);
    CHECK(pk_accel_available(PK_ACCEL_BVH) == 1);

    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) {
        fprintf(stderr, "app: pk_context_create failed\n");
        return 1;
    }
    /* the library reads no environment variable: a program passes on what
     * it reads as config (here the Embree library to load) */
    const char *lib = getenv("PAPRSEK_EMBREE_LIBRARY");
    if (lib && lib[0]) {
        char cfg[1100];
        snprintf(cfg, sizeof cfg, "embree.library=%s", lib);
        CHECK(strlen(lib) < 1000 && pk_context_set_config(ctx, cfg) == PK_OK);
    }
    pk_scene *scene = NULL;
    pk_status st = pk_scene_create_cornell_box(ctx, &scene);
    CHECK(st == PK_OK && scene != NULL);
    if (scene) {
        pk_scene_info info;
        pk_scene_get_info(scene, &info);
        CHECK(info.triangles > 0 && info.emissive_triangles > 0);
        CHECK(render_lit(ctx, scene, PK_ACCEL_DEFAULT));

        if (strcmp(mode, "embree") == 0) {
            CHECK(pk_accel_available(PK_ACCEL_EMBREE) == 1);
            CHECK(render_lit(ctx, scene, PK_ACCEL_EMBREE));
        } else if (strcmp(mode, "embree-missing") == 0) {
            const char *text = argc > 2 ? argv[2] : "";
            /* (pk_accel_available asks about the default library) */
            if (!(lib && lib[0])) CHECK(pk_accel_available(PK_ACCEL_EMBREE) == 0);
            pk_accel *acc = NULL;
            pk_context_clear_error(ctx);
            CHECK(pk_accel_create(ctx, scene, PK_ACCEL_EMBREE, 1, &acc) == PK_ERR_UNSUPPORTED);
            CHECK(acc == NULL);
            if (!strstr(pk_context_error(ctx), text)) {
                fprintf(stderr, "app: the message '%s' does not say '%s'\n", pk_context_error(ctx), text);
                failures++;
            }
            pk_accel_destroy(acc);
            pk_context_clear_error(ctx);
            /* the other accelerators are not affected */
            CHECK(render_lit(ctx, scene, PK_ACCEL_BVH));
        } else if (mode[0]) {
            fprintf(stderr, "app: unknown mode '%s'\n", mode);
            failures++;
        }
    }
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return failures ? 1 : 0;
}

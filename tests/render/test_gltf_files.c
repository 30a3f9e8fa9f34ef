/*
 * test_gltf_files.c - glTF 2.0 assets read from files through the public
 * door (pk_scene_load_file): the assets of tests/data/gltf (a GLB with an
 * embedded texture, an external buffer named by a percent-escaped URI,
 * instances with an orthographic camera) and their hostile siblings with
 * their messages; then the Khronos samples of ../shared/scenes/gltf load and
 * render small images without NaN, negative or all-black pixels (skipped
 * when ../shared is absent).
 */
#include "test.h"
#include "warnings.h"

#include "paprsek.h"

static warning_log warnings;

static pk_scene *load(pk_context *ctx, const char *path, const char *const *params, size_t np)
{
    pk_scene *s = NULL;
    warning_log_clear(&warnings);
    if (pk_scene_load_file_params(ctx, path, params, np, &s) != PK_OK) return NULL;
    return s;
}

/* Renders s at w x h, spp samples; the mean of the image (negative when a
 * pixel is NaN or negative). */
static double render_mean(pk_context *ctx, const pk_scene *s, int w, int h, int spp)
{
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.width = w, o.height = h, o.spp = spp, o.threads = 0;
    if (o.max_depth > 6) o.max_depth = 6;
    pk_image *img = NULL;
    if (pk_render(ctx, s, &o, &img, NULL) != PK_OK) {
        fprintf(stderr, "render: %s\n", pk_context_error(ctx));
        pk_image_destroy(img);
        return -1.0;
    }
    const float *px = pk_image_pixels_const(img);
    double sum = 0.0;
    for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++) {
        if (!(px[i] >= 0.0f) || !isfinite(px[i])) {
            pk_image_destroy(img);
            return -1.0;
        }
        sum += (double)px[i];
    }
    pk_image_destroy(img);
    return sum / ((double)w * h * 3);
}

static void test_own_assets(pk_context *ctx)
{
    char path[1024];
    pk_scene_info info;

    snprintf(path, sizeof path, "%s/gltf/cube.glb", PK_TEST_DATA);
    pk_scene *s = load(ctx, path, NULL, 0);
    CHECKF(s != NULL, "%s", pk_context_error(ctx));
    if (s) {
        pk_scene_get_info(s, &info);
        CHECK(info.triangles == 24 && info.point_lights == 2 && info.has_camera && info.textures == 1);
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        CHECK(o.width == 512 && o.height == 341); /* aspectRatio 1.5 */
        pk_camera cam;
        pk_scene_get_camera(s, &cam);
        CHECK_NEAR(cam.fov_deg, 0.7 * 180.0 / 3.14159265358979, 1e-4);
        CHECK_NEAR(cam.look_from[1], 1.2, 1e-6);
        CHECK(render_mean(ctx, s, 48, 32, 4) > 0.0);
        CHECK(warnings.count == 0);
        pk_scene_destroy(s);
    }

    snprintf(path, sizeof path, "%s/gltf/external.gltf", PK_TEST_DATA);
    s = load(ctx, path, NULL, 0);
    CHECKF(s != NULL, "%s", pk_context_error(ctx));
    if (s) {
        pk_scene_get_info(s, &info);
        /* the image and the MASK cut-out derived from its alpha */
        CHECK(info.triangles == 2 && info.textures == 2 && !info.has_camera);
        pk_scene_destroy(s);
    }

    snprintf(path, sizeof path, "%s/gltf/instanced.gltf", PK_TEST_DATA);
    s = load(ctx, path, NULL, 0);
    CHECKF(s != NULL, "%s", pk_context_error(ctx));
    if (s) {
        pk_scene_get_info(s, &info);
        CHECK(info.triangles == 3 * 12 + 2 + 3 && info.point_lights == 1 && info.has_camera);
        /* the three cubes: -1.5, 0 and 1.5 along x, the third half as tall */
        CHECK_NEAR(info.bounds_max[1], 1.0, 1e-6);
        CHECK_NEAR(info.bounds_min[0], -3.0, 1e-6);
        pk_camera cam;
        pk_scene_get_camera(s, &cam);
        CHECK(cam.projection == PK_PROJECTION_ORTHOGRAPHIC);
        CHECK_NEAR(cam.ortho_width, 8.0, 0);
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        CHECK(o.width == 512 && o.height == 384);
        CHECK(render_mean(ctx, s, 32, 24, 2) > 0.0);
        pk_scene_destroy(s);
    }
    const char *pick[] = {"camera=1"};
    CHECK(load(ctx, path, pick, 1) == NULL);
    CHECKF(strcmp(pk_context_error(ctx), "instanced.gltf: camera 1: the asset has 1 camera") == 0, "%s",
           pk_context_error(ctx));
    pk_context_clear_error(ctx);

    static const char *const bad[][2] = {
        {"bad_accessor.gltf", "bad_accessor.gltf: /accessors/0: count 100 exceeds bufferView 0 (36 bytes)"},
        {"bad_index.gltf", "bad_index.gltf: /meshes/0/primitives/0/indices: index 9 out of range (3 vertices)"},
        {"bad_uri.gltf", "bad_uri.gltf: /buffers/0/uri: malformed base64 in the data: URI"},
        {"bad_cycle.gltf", "bad_cycle.gltf: /nodes/1/children/0: node 0 is its own ancestor (a cycle)"},
        {"bad_length.glb", "bad_length.glb: GLB: the header says 1048576 bytes, the file holds 2956"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(path, sizeof path, "%s/gltf/%s", PK_TEST_DATA, bad[i][0]);
        s = load(ctx, path, NULL, 0);
        CHECK(s == NULL);
        CHECKF(strcmp(pk_context_error(ctx), bad[i][1]) == 0, "%s", pk_context_error(ctx));
        pk_context_clear_error(ctx);
        pk_scene_destroy(s);
    }
}

/* The Khronos samples: name, triangles (0: not checked). */
static void test_samples(pk_context *ctx)
{
    char dir[1024];
    shared_path(dir, sizeof dir, "scenes/gltf");
    static const struct {
        const char *name;
        size_t triangles;
    } samples[] = {{"Box", 12},
                   {"BoxTextured", 12},
                   {"OrientationTest", 0},
                   {"SimpleSparseAccessor", 0},
                   {"MetalRoughSpheresNoTextures", 0},
                   {"Cameras", 2},
                   {"TextureTransformTest", 0},
                   {"AlphaBlendModeTest", 0},
                   {"EmissiveStrengthTest", 0},
                   {"NormalTangentMirrorTest", 0},
                   {"TextureSettingsTest", 0}};
    for (size_t i = 0; i < sizeof samples / sizeof samples[0]; i++) {
        char path[1200];
        snprintf(path, sizeof path, "%s/%s/%s.gltf", dir, samples[i].name, samples[i].name);
        pk_scene *s = load(ctx, path, NULL, 0);
        CHECKF(s != NULL, "%s: %s", samples[i].name, pk_context_error(ctx));
        if (!s) {
            pk_context_clear_error(ctx);
            continue;
        }
        pk_scene_info info;
        pk_scene_get_info(s, &info);
        if (samples[i].triangles)
            CHECKF(info.triangles == samples[i].triangles, "%s: %zu triangles", samples[i].name, info.triangles);
        CHECKF(info.triangles > info.degenerate_triangles, "%s", samples[i].name);
        double mean = render_mean(ctx, s, 24, 24, 2);
        CHECKF(mean > 0.0, "%s: mean %g", samples[i].name, mean);
        pk_scene_destroy(s);
    }
    /* Cameras: the second camera by number */
    char path[1200];
    snprintf(path, sizeof path, "%s/Cameras/Cameras.gltf", dir);
    const char *pick[] = {"camera=1"};
    pk_scene *a = load(ctx, path, NULL, 0), *b = load(ctx, path, pick, 1);
    CHECKF(a && b, "%s", pk_context_error(ctx));
    if (a && b) {
        pk_camera ca, cb;
        pk_scene_get_camera(a, &ca);
        pk_scene_get_camera(b, &cb);
        CHECK(ca.projection == PK_PROJECTION_PERSPECTIVE && cb.projection == PK_PROJECTION_ORTHOGRAPHIC);
    }
    pk_scene_destroy(a);
    pk_scene_destroy(b);
}

int main(void)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &warnings);
    test_own_assets(ctx);
    test_samples(ctx);
    pk_context_destroy(ctx);
    return test_done("test_gltf_files");
}

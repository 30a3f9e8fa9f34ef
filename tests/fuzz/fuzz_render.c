/* fuzz_render.c - loads a fuzzed scene (JSON when it starts with '{', Mitsuba
 * XML when it starts with '<', OBJ otherwise, with mtllib and meshes read from tests/data) and renders it at
 * 8x8 with every code path of the integrator. */
#include "fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    size_t warned = 0;
    pk_context_set_warning_handler(ctx, fuzz_warning, &warned);
    pk_scene *s = NULL;
    const char *text = (const char *)data;
    pk_status st = size && text[0] == '{'   ? pk_scene_load_json_memory(ctx, text, size, "fuzz.json", PK_TEST_DATA, &s)
                   : size && text[0] == '<' ? pk_scene_load_xml_memory(ctx, text, size, "fuzz.xml", PK_TEST_DATA, &s)
                                            : pk_scene_load_obj_memory(ctx, text, size, "fuzz.obj", PK_TEST_DATA, &s);
    fuzz_check_error(ctx, st);
    if (st == PK_OK) {
        pk_render_options o;
        pk_scene_get_render_options(s, &o);
        o.width = o.height = 8;
        o.spp = 1;
        o.light_samples = 2;
        if (o.max_depth < 0 || o.max_depth > 4) o.max_depth = 4;
        o.threads = 1;
        if (o.accel == PK_ACCEL_EMBREE || o.accel == PK_ACCEL_CUDA) o.accel = PK_ACCEL_BVH;
        o.collect_stats = (int)(size & 1); /* both paths of the counters */
        pk_stats stats;
        pk_image *img = NULL;
        st = pk_render(ctx, s, &o, &img, &stats);
        fuzz_check_error(ctx, st);
        if (st == PK_OK && o.collect_stats && stats.rays_camera != 8 * 8) {
            fprintf(stderr, "fuzz: %llu camera rays for 8x8 pixels at 1 spp\n", (unsigned long long)stats.rays_camera);
            abort();
        }
        if (st == PK_OK) {
            const float *px = pk_image_pixels_const(img);
            for (int i = 0; i < 8 * 8 * 3; i++)
                if (!(px[i] >= 0.0f) || px[i] > 3.4e38f) {
                    fprintf(stderr, "fuzz: pixel value %g is negative or not finite\n", (double)px[i]);
                    abort();
                }
        }
        pk_image_destroy(img);
    }
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return 0;
}

/*
 * test_direct.c - the path tracer with one bounce (camera ray, then direct
 * light by next-event estimation and MIS) and the Whitted integrator without
 * recursion estimate the same image on a diffuse scene: every block mean must
 * agree within its confidence interval. Each integrator renders twice with
 * independent random numbers (another seed, another pass), and the pixel
 * differences measure each block mean's variance (block_stats.h).
 */
#include "test.h"

#include "paprsek.h"

#include "block_stats.h"

#define SIZE 48
#define BLOCK 16
/* two-sided p = 1e-3 over 9 blocks x 3 channels: Phi^-1(1 - 0.001 / 54) */
#define Z_CRIT 4.12

static pk_context *ctx;

static void render_twice(const pk_scene *s, pk_integrator_kind kind, block_estimate *e)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = kind;
    o.width = o.height = SIZE;
    o.threads = 2;
    if (kind == PK_INTEGRATOR_PATH) {
        o.max_depth = 1; /* emission seen by the camera, and direct light */
        o.spp = 64;
    } else {
        o.max_depth = 0; /* no mirror or glass recursion */
        o.spp = 16;      /* stratified over the pixel, as the path tracer's samples are */
        o.light_samples = 8;
    }
    pk_image *img[2];
    for (int k = 0; k < 2; k++) {
        o.seed = 11 + k;
        pk_renderer *r = NULL;
        pk_film *f = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        pk_renderer_set_pass(r, (uint32_t)k); /* the Whitted integrator's other random numbers */
        REQUIRE(pk_film_create(ctx, SIZE, SIZE, &f) == PK_OK);
        REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
        REQUIRE(pk_film_resolve(ctx, f, &img[k]) == PK_OK);
        pk_film_destroy(f);
        pk_renderer_destroy(r);
    }
    block_estimate_from(img[0], img[1], BLOCK, e);
    pk_image_destroy(img[0]);
    pk_image_destroy(img[1]);
}

static void check(const char *name, const pk_scene *s)
{
    static block_estimate p, w;
    render_twice(s, PK_INTEGRATOR_PATH, &p);
    render_twice(s, PK_INTEGRATOR_WHITTED, &w);
    double sum = 0.0;
    for (int by = 0; by < w.nb; by++)
        for (int bx = 0; bx < w.nb; bx++)
            for (int c = 0; c < 3; c++) sum += w.mean[by][bx][c];
    CHECKF(sum > 0.0, "%s: black", name);
    block_compare(name, "one-bounce path tracer vs Whitted", &p, &w, Z_CRIT);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    /* The lamp is two-sided: the Whitted integrator lights from both sides of
     * every emitter, the path tracer only from the front unless the material
     * says two_sided, so on the Cornell boxes (a lamp just under the ceiling)
     * the two differ by design where the ceiling sees the lamp's back. */
    const char *json =
        "{\"materials\": {\"white\": {\"kd\": [0.7, 0.7, 0.7]}, \"red\": {\"kd\": [0.6, 0.1, 0.1]},"
        " \"lamp\": {\"kd\": [0.3, 0.3, 0.3], \"ke\": [8, 7, 6], \"two_sided\": true}},"
        " \"camera\": {\"look_from\": [0, 1.5, 4], \"look_at\": [0, 0.5, 0], \"fov\": 45},"
        " \"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": {\"scale\": [4, 1, 4]}},"
        "   {\"obj\": \"json_lamp.obj\", \"transform\": {\"translate\": [0.4, 1.6, 0], \"scale\": [0.5, 1, 0.5]}}],"
        " \"spheres\": [{\"center\": [-0.4, 0.5, 0], \"radius\": 0.5, \"material\": \"red\"},"
        "   {\"center\": [0.7, 0.25, 0.6], \"radius\": 0.25, \"material\": \"white\"}]}";
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, json, strlen(json), "direct.json", PK_TEST_DATA, &s) == PK_OK);
    check("floor, spheres, two-sided lamp", s);
    pk_scene_destroy(s);
    /* Every kind of light at once, as the Whitted integrator samples them from
     * the one light set (by power, stratified) and the path tracer too: a
     * two-sided lamp, two point lights of different power, a constant
     * environment and the sun. */
    const char *mixed =
        "{\"materials\": {\"white\": {\"kd\": [0.7, 0.7, 0.7]}, \"red\": {\"kd\": [0.6, 0.1, 0.1]},"
        " \"lamp\": {\"kd\": [0.3, 0.3, 0.3], \"ke\": [4, 3.5, 3], \"two_sided\": true}},"
        " \"camera\": {\"look_from\": [0, 1.5, 4], \"look_at\": [0, 0.5, 0], \"fov\": 45},"
        " \"meshes\": [{\"obj\": \"json_floor.obj\", \"transform\": {\"scale\": [4, 1, 4]}},"
        "   {\"obj\": \"json_lamp.obj\", \"transform\": {\"translate\": [0.4, 1.6, 0], \"scale\": [0.5, 1, 0.5]}}],"
        " \"spheres\": [{\"center\": [-0.4, 0.5, 0], \"radius\": 0.5, \"material\": \"red\"},"
        "   {\"center\": [0.7, 0.25, 0.6], \"radius\": 0.25, \"material\": \"white\"}],"
        " \"lights\": [{\"position\": [-1.5, 2, 1], \"intensity\": 3},"
        "   {\"position\": [1.5, 1.2, 1.5], \"intensity\": 1, \"color\": [1, 0.6, 0.3]}],"
        " \"environment\": {\"radiance\": [0.2, 0.25, 0.3],"
        "   \"sun\": {\"direction\": [1, 2, 1], \"irradiance\": [1, 1, 1], \"angle\": 2}}}";
    REQUIRE(pk_scene_load_json_memory(ctx, mixed, strlen(mixed), "mixed.json", PK_TEST_DATA, &s) == PK_OK);
    check("lamp, point lights, environment and sun", s);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_direct");
}

/*
 * test_aov.c - the arbitrary outputs against what they must be.
 *
 * Inside an emitting sphere of radius 10 seen from its centre, every camera
 * ray travels 10, the normal faces back along the ray; the albedo is the
 * emitted colour normalised for the path tracer and the material's Kd for
 * Whitted (first-surface AOVs); the heatmap counts at least the one node and
 * the one sphere tested. The image itself does not change when AOVs are
 * asked for, and AOV films merge.
 *
 * The path tracer's albedo and normal are a denoiser's: those of the first
 * non-specular vertex, through mirrors and glass. Scenes of axis-aligned
 * quads (an OBJ file in a temporary folder, JSON materials) seen by a camera
 * at the origin looking down -z:
 *  - a mirror at z = -5 showing a diffuse wall at z = +5 (behind the
 *    camera): the albedo is Kd of the wall times the mirror's tint (exactly
 *    for an MTL mirror, illum 3 with Kd 0; within Schlick's angular term for
 *    a conductor by its normal reflectance); the normal is the wall's (0, 0,
 *    -1), not the mirror's (0, 0, 1); the depth is the distance to the
 *    mirror. Without the wall the mirror shows the constant environment:
 *    its colour normalised, times the tint, and a zero normal;
 *  - a smooth glass slab (index 3, R = 1/4 head-on) between a wall in front
 *    and one behind the camera: the albedo is the Fresnel mixture of the two
 *    walls' Kd, summed over the internal reflections, within a tolerance
 *    taken from the image's own spread;
 *  - the environment seen directly: its colour normalised, normal and depth
 *    zero; a rough metal: its tint (F0); rough glass: its transmittance;
 *    plastic: its Kd.
 */
#include "test.h"

#include "paprsek.h"

#include <stdbool.h>

static pk_context *ctx;

#define Z_MEAN 4.42 /* two-sided p = 1e-5 */
#define W 32
#define H 32
#define FOV 20.0

/* ---- scenes of quads ----------------------------------------------------------- */

/* A quad of material mtl in the plane z, |x|, |y| <= half, facing +z (up > 0)
 * or -z. */
static void quad(FILE *f, int *nv, const char *mtl, float z, float half, int up)
{
    fprintf(f, "usemtl %s\n", mtl);
    const float xs[4] = {-half, half, half, -half}, ys[4] = {-half, -half, half, half};
    for (int k = 0; k < 4; k++) fprintf(f, "v %g %g %g\n", (double)xs[k], (double)ys[k], (double)z);
    const int b = *nv + 1;
    if (up > 0)
        fprintf(f, "f %d %d %d %d\n", b, b + 1, b + 2, b + 3);
    else
        fprintf(f, "f %d %d %d %d\n", b + 3, b + 2, b + 1, b);
    *nv += 4;
}

typedef struct quad_spec {
    const char *mtl;
    float z, half;
    int up;
} quad_spec;

static char dir[] = "/tmp/paprsek-aov-XXXXXX";

/* A JSON scene: the quads (in an OBJ file), the materials (a JSON object's
 * inside), the environment (JSON), the camera at the origin looking down -z. */
static pk_scene *quad_scene(const quad_spec *q, int nq, const char *materials, const char *env)
{
    char obj[600], text[4096];
    snprintf(obj, sizeof obj, "%s/quads.obj", dir);
    FILE *f = fopen(obj, "w");
    REQUIRE(f);
    int nv = 0;
    for (int k = 0; k < nq; k++) quad(f, &nv, q[k].mtl, q[k].z, q[k].half, q[k].up);
    REQUIRE(fclose(f) == 0);
    snprintf(text, sizeof text,
             "{\"materials\": {%s},"
             " \"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [0, 0, -1], \"fov\": %g},"
             " \"meshes\": [{\"obj\": \"%s\"}], \"environment\": %s}",
             materials, FOV, obj, env);
    pk_scene *s = NULL;
    const pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "aov.json", dir, &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    remove(obj);
    return s;
}

/* The path tracer's albedo, normal and depth of s at spp samples per pixel
 * (the caller destroys them); the colour image must be the same as without
 * AOVs. */
static void render_aovs(const char *what, const pk_scene *s, int spp, pk_image **alb, pk_image **nor, pk_image **dep)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = W;
    o.height = H;
    o.spp = spp;
    o.threads = 2;
    pk_renderer *r = NULL;
    pk_film *f = NULL, *plain = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    REQUIRE(pk_film_create_aovs(ctx, W, H, PK_AOV_ALBEDO | PK_AOV_NORMAL | PK_AOV_DEPTH, &f) == PK_OK);
    REQUIRE(pk_film_create(ctx, W, H, &plain) == PK_OK);
    REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    REQUIRE(pk_renderer_render(r, NULL, 0, plain) == PK_OK);
    pk_image *img = NULL, *ref = NULL;
    REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK && pk_film_resolve(ctx, plain, &ref) == PK_OK);
    CHECKF(memcmp(pk_image_pixels_const(img), pk_image_pixels_const(ref), sizeof(float) * 3 * W * H) == 0,
           "%s: the colour image changes with the AOVs", what);
    REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_ALBEDO, alb) == PK_OK);
    REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_NORMAL, nor) == PK_OK);
    REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_DEPTH, dep) == PK_OK);
    pk_image_destroy(img), pk_image_destroy(ref);
    pk_film_destroy(f), pk_film_destroy(plain);
    pk_renderer_destroy(r);
}

/* Cosine between the camera's axis (-z) and the ray through the centre of
 * pixel i, and the smallest over the image (a corner's outer edge). */
static double pixel_cos(int i)
{
    const double t = tan(FOV * 0.5 * M_PI / 180.0);
    const double a = (2.0 * (i % W + 0.5) / W - 1.0) * t, b = (2.0 * (i / W + 0.5) / H - 1.0) * t;
    return 1.0 / sqrt(1.0 + a * a + b * b);
}
static double min_cos(void)
{
    const double t = tan(FOV * 0.5 * M_PI / 180.0);
    return 1.0 / sqrt(1.0 + 2.0 * t * t);
}

/* Counts the pixels whose value differs from v (per channel) by more than
 * tol, and prints the first. */
static int count_off(const char *what, const pk_image *img, const double v[3], double tol)
{
    const float *p = pk_image_pixels_const(img);
    int bad = 0;
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 3; c++)
            if (!(fabs((double)p[3 * i + c] - v[c]) <= tol)) {
                if (!bad)
                    fprintf(stderr, "%s: pixel %d channel %d: %.9g, expected %.9g (tol %g)\n", what, i, c,
                            (double)p[3 * i + c], v[c], tol);
                bad++;
            }
    return bad;
}

/* ---- mirrors ----------------------------------------------------------------- */

#define WALL_KD 0.7, 0.5, 0.2
static const double wall_kd[3] = {WALL_KD};

/* A mirror of material mirror (JSON) whose tint is tint to within tol,
 * showing the wall (wall: true) or, without it, the environment
 * [0.3, 0.6, 1.2]. */
static void check_mirror(const char *what, const char *mirror, const double tint[3], double tol, bool wall)
{
    char mats[512];
    snprintf(mats, sizeof mats, "\"mirror\": %s, \"wall\": {\"kd\": [%g, %g, %g], \"illum\": 1}", mirror,
             WALL_KD);
    const quad_spec q[2] = {{"mirror", -5.0f, 4.0f, 1}, {"wall", 5.0f, 10.0f, -1}};
    pk_scene *s = quad_scene(q, wall ? 2 : 1, mats, "[0.3, 0.6, 1.2]");
    pk_image *alb, *nor, *dep;
    render_aovs(what, s, 4, &alb, &nor, &dep);
    double a[3], n[3] = {0.0, 0.0, wall ? -1.0 : 0.0};
    const double env_n[3] = {0.25, 0.5, 1.0}; /* [0.3, 0.6, 1.2] / 1.2 */
    for (int c = 0; c < 3; c++) a[c] = tint[c] * (wall ? wall_kd[c] : env_n[c]);
    CHECKF(count_off(what, alb, a, tol + 1e-6) == 0, "%s: albedo is not the %s's times the tint", what,
           wall ? "wall" : "environment");
    CHECKF(count_off(what, nor, n, 1e-6) == 0, "%s: normal is not the %s", what, wall ? "wall's" : "zero");
    /* the depth: the distance to the mirror, 5 / cos */
    const float *d = pk_image_pixels_const(dep);
    int bad = 0;
    for (int i = 0; i < W * H; i++) bad += !(d[3 * i] >= 5.0f - 1e-4f && (double)d[3 * i] <= 5.0 / min_cos() + 1e-4);
    CHECKF(bad == 0, "%s: %d depths not the mirror's", what, bad);
    pk_image_destroy(alb), pk_image_destroy(nor), pk_image_destroy(dep);
    pk_scene_destroy(s);
}

static void check_mirrors(void)
{
    /* an MTL mirror (illum 3, Kd 0): weight Ks exactly */
    const double ks[3] = {0.9, 0.6, 0.3};
    const char *mtl = "{\"kd\": [0, 0, 0], \"ks\": [0.9, 0.6, 0.3], \"illum\": 3}";
    check_mirror("MTL mirror", mtl, ks, 1e-6, true);
    check_mirror("MTL mirror, sky", mtl, ks, 1e-6, false);
    /* a smooth conductor by its normal reflectance: Schlick's
     * F0 + (1 - F0) (1 - cos)^5, within the largest angular term */
    const double f0[3] = {0.95, 0.64, 0.54};
    const char *metal = "{\"type\": \"conductor\", \"specular\": [0.95, 0.64, 0.54]}";
    const double m5 = pow(1.0 - min_cos(), 5.0);
    check_mirror("smooth conductor", metal, f0, (1.0 - 0.54) * m5 + 1e-6, true);
    /* a perfect mirror: white */
    const double one[3] = {1.0, 1.0, 1.0};
    check_mirror("perfect conductor", "{\"type\": \"conductor\", \"specular\": [1, 1, 1]}", one, 1e-6, true);
}

/* ---- glass ----------------------------------------------------------------------- */

/* Unpolarised Fresnel reflectance of a dielectric of index eta (outside 1)
 * for an incident cosine ci. */
static double fresnel(double ci, double eta)
{
    const double st2 = (1.0 - ci * ci) / (eta * eta), ct = sqrt(1.0 - st2);
    const double rs = (ci - eta * ct) / (ci + eta * ct), rp = (eta * ci - ct) / (eta * ci + ct);
    return 0.5 * (rs * rs + rp * rp);
}

/* A slab of smooth glass (index 3, the faces at z = -2 and -2.5, normals
 * outward) in front of a wall "far" (z = -5) with a wall "back" behind the
 * camera (z = +5). A ray through the slab at cosine c meets R = F(c) at
 * every face (the faces are parallel, and Fresnel reflectance is the same
 * from either side); reflection and transmission both weigh 1 (clear
 * glass). Inside, going down, the path reaches the back wall with
 * probability x = R (1 - R) + R^2 x, x = R / (1 + R); from the camera
 * with p_back = R + (1 - R) x = 2R / (1 + R), and the far wall with
 * p_far = 1 - p_back. The expected albedo is the mixture of their Kd, the
 * expected normal (0, 0, p_far - p_back). */
static void check_glass(void)
{
    const double far[3] = {0.1, 0.2, 0.8}, back[3] = {0.9, 0.3, 0.1};
    char mats[512];
    snprintf(mats, sizeof mats,
             "\"glass\": {\"type\": \"dielectric\", \"ior\": 3},"
             " \"far\": {\"type\": \"diffuse\", \"albedo\": [%g, %g, %g]},"
             " \"back\": {\"type\": \"diffuse\", \"albedo\": [%g, %g, %g]}",
             far[0], far[1], far[2], back[0], back[1], back[2]);
    const quad_spec q[4] = {
        {"glass", -2.0f, 4.0f, 1}, {"glass", -2.5f, 4.0f, -1}, {"far", -5.0f, 10.0f, 1}, {"back", 5.0f, 20.0f, -1}};
    pk_scene *s = quad_scene(q, 4, mats, "[1, 1, 1]");
    const int spp = 64;
    pk_image *alb, *nor, *dep;
    render_aovs("glass slab", s, spp, &alb, &nor, &dep);
    const float *a = pk_image_pixels_const(alb), *n = pk_image_pixels_const(nor), *d = pk_image_pixels_const(dep);
    /* means over the image against the expected means, within Z_MEAN
     * standard errors taken from the spread of the pixels' own means */
    double sum[4] = {0}, sum2[4] = {0}, want[4] = {0};
    int bad_depth = 0;
    for (int i = 0; i < W * H; i++) {
        const double c = pixel_cos(i), R = fresnel(c, 3.0), pb = 2.0 * R / (1.0 + R);
        for (int k = 0; k < 4; k++) {
            const double v = k < 3 ? a[3 * i + k] : n[3 * i + 2];
            sum[k] += v, sum2[k] += v * v;
            want[k] += k < 3 ? pb * back[k] + (1.0 - pb) * far[k] : (1.0 - pb) - pb;
        }
        bad_depth += !(d[3 * i] >= 2.0f - 1e-4f && (double)d[3 * i] <= 2.0 / min_cos() + 1e-4);
        bad_depth += n[3 * i] != 0.0f || n[3 * i + 1] != 0.0f; /* only the z of the two walls */
    }
    const char *name[4] = {"albedo R", "albedo G", "albedo B", "normal z"};
    for (int k = 0; k < 4; k++) {
        const double m = sum[k] / (W * H), w = want[k] / (W * H);
        const double var = fmax(0.0, sum2[k] / (W * H) - m * m), se = sqrt(var / (W * H - 1));
        /* plus the jitter of the rays inside a pixel: R varies by less than 1e-4 over one */
        const double tol = Z_MEAN * se + 1e-4;
        CHECKF(fabs(m - w) <= tol, "glass slab: mean %s %.6f, expected %.6f (tol %.2g, se %.2g)", name[k], m, w, tol,
               se);
    }
    CHECKF(bad_depth == 0, "glass slab: %d depths or normals wrong", bad_depth);
    pk_image_destroy(alb), pk_image_destroy(nor), pk_image_destroy(dep);
    pk_scene_destroy(s);
}

/* ---- one surface filling the view ---------------------------------------------------- */

/* A quad of material mat (JSON) at z = -5 filling the view: its albedo is
 * want, its normal (0, 0, 1). */
static void check_surface(const char *what, const char *mat, const double want[3], double tol)
{
    char mats[512];
    snprintf(mats, sizeof mats, "\"m\": %s", mat);
    const quad_spec q[1] = {{"m", -5.0f, 4.0f, 1}};
    pk_scene *s = quad_scene(q, 1, mats, "[1, 1, 1]");
    pk_image *alb, *nor, *dep;
    render_aovs(what, s, 4, &alb, &nor, &dep);
    const double n[3] = {0.0, 0.0, 1.0};
    CHECKF(count_off(what, alb, want, tol) == 0, "%s: albedo", what);
    CHECKF(count_off(what, nor, n, 1e-6) == 0, "%s: normal", what);
    pk_image_destroy(alb), pk_image_destroy(nor), pk_image_destroy(dep);
    pk_scene_destroy(s);
}

static void check_surfaces(void)
{
    const double gold[3] = {1.0, 0.78, 0.34};
    check_surface("rough conductor (F0)",
                  "{\"type\": \"conductor\", \"specular\": [1, 0.78, 0.34], \"roughness\": 0.4}", gold, 1e-6);
    /* by its complex index: F0 = ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2) */
    const double eta[3] = {0.2, 0.92, 1.1}, k[3] = {3.9, 2.45, 2.14};
    double cu[3];
    for (int c = 0; c < 3; c++)
        cu[c] = ((eta[c] - 1) * (eta[c] - 1) + k[c] * k[c]) / ((eta[c] + 1) * (eta[c] + 1) + k[c] * k[c]);
    check_surface("rough copper (F0)", "{\"type\": \"conductor\", \"roughness\": 0.3}", cu, 1e-5);
    const double tf[3] = {0.5, 0.8, 1.0};
    check_surface("rough dielectric (transmittance)",
                  "{\"type\": \"dielectric\", \"roughness\": 0.3, \"transmittance\": [0.5, 0.8, 1]}", tf, 1e-6);
    const double kd[3] = {0.2, 0.4, 0.6};
    check_surface("plastic (Kd)", "{\"type\": \"plastic\", \"albedo\": [0.2, 0.4, 0.6]}", kd, 1e-6);
    check_surface("Phong (Kd)", "{\"kd\": [0.2, 0.4, 0.6], \"ks\": [0.3, 0.3, 0.3], \"ns\": 50}", kd, 1e-6);
}

/* The environment seen directly, past a quad out of view: its colour
 * normalised, normal and depth zero. */
static void check_sky(void)
{
    const quad_spec q[1] = {{"m", 5.0f, 1.0f, -1}};
    pk_scene *s = quad_scene(q, 1, "\"m\": {\"kd\": [0.5, 0.5, 0.5]}", "[2, 1, 0.5]");
    pk_image *alb, *nor, *dep;
    render_aovs("sky", s, 4, &alb, &nor, &dep);
    const double a[3] = {1.0, 0.5, 0.25}, zero[3] = {0.0, 0.0, 0.0};
    CHECK(count_off("sky albedo", alb, a, 1e-6) == 0);
    CHECK(count_off("sky normal", nor, zero, 0.0) == 0);
    CHECK(count_off("sky depth", dep, zero, 0.0) == 0);
    pk_image_destroy(alb), pk_image_destroy(nor), pk_image_destroy(dep);
    pk_scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    REQUIRE(mkdtemp(dir));
    check_mirrors();
    check_glass();
    check_surfaces();
    check_sky();
    REQUIRE(rmdir(dir) == 0);
    const char *json =
        "{\"materials\": {\"w\": {\"kd\": [0.25, 0.5, 0.75], \"ke\": [2, 1, 0.5], \"two_sided\": true}},"
        " \"camera\": {\"look_from\": [0, 0, 0], \"look_at\": [0, 0, -1], \"fov\": 60},"
        " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 10, \"material\": \"w\"}]}";
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_json_memory(ctx, json, strlen(json), "aov.json", ".", &s) == PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 17;
    o.height = 13;
    o.spp = 4;
    o.threads = 2;
    const unsigned all = PK_AOV_ALBEDO | PK_AOV_NORMAL | PK_AOV_DEPTH | PK_AOV_HEATMAP;
    for (int integ = 0; integ < 2; integ++) {
        o.integrator = integ ? PK_INTEGRATOR_WHITTED : PK_INTEGRATOR_PATH;
        pk_renderer *r = NULL;
        pk_film *f = NULL, *plain = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        REQUIRE(pk_film_create_aovs(ctx, 17, 13, all, &f) == PK_OK);
        REQUIRE(pk_film_create(ctx, 17, 13, &plain) == PK_OK);
        CHECK(pk_film_aovs(f) == all && pk_film_aovs(plain) == 0);
        CHECK(pk_renderer_render(r, NULL, 0, f) == PK_OK);
        CHECK(pk_renderer_render(r, NULL, 0, plain) == PK_OK);
        pk_image *img = NULL, *ref = NULL, *alb = NULL, *nor = NULL, *dep = NULL, *heat = NULL;
        REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK && pk_film_resolve(ctx, plain, &ref) == PK_OK);
        CHECK(memcmp(pk_image_pixels_const(img), pk_image_pixels_const(ref), sizeof(float) * 3 * 17 * 13) == 0);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_ALBEDO, &alb) == PK_OK);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_NORMAL, &nor) == PK_OK);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_DEPTH, &dep) == PK_OK);
        REQUIRE(pk_film_resolve_aov(ctx, f, PK_AOV_HEATMAP, &heat) == PK_OK);
        const float *a = pk_image_pixels_const(alb), *n = pk_image_pixels_const(nor), *d = pk_image_pixels_const(dep),
                    *h = pk_image_pixels_const(heat);
        int bad = 0;
        for (int i = 0; i < 17 * 13; i++) {
            /* the path tracer: the emitted colour normalised; Whitted: Kd */
            const float want[3] = {integ ? 0.25f : 1.0f, 0.5f, integ ? 0.75f : 0.25f};
            bad += fabsf(a[3 * i] - want[0]) > 1e-6f || fabsf(a[3 * i + 1] - want[1]) > 1e-6f ||
                   fabsf(a[3 * i + 2] - want[2]) > 1e-6f;
            bad += fabsf(d[3 * i] - 10.0f) > 1e-3f || d[3 * i + 1] != d[3 * i] || d[3 * i + 2] != d[3 * i];
            bad += !(h[3 * i] >= 2.0f); /* the root and the sphere at least */
            /* the mean of unit normals facing the camera: nearly unit, pointing back (+z side) */
            float len = sqrtf(n[3 * i] * n[3 * i] + n[3 * i + 1] * n[3 * i + 1] + n[3 * i + 2] * n[3 * i + 2]);
            bad += !(len > 0.99f && len < 1.0001f) || !(n[3 * i + 2] > 0.5f);
        }
        /* the centre pixel looks along -z: its normal is +z */
        const int c = 6 * 17 + 8;
        CHECKF(fabsf(n[3 * c + 2] - 1.0f) < 1e-3f, "centre normal z %g", (double)n[3 * c + 2]);
        CHECKF(bad == 0, "%s: %d AOV values wrong", integ ? "whitted" : "path", bad);
        /* a film without the AOV refuses it; AOV films merge */
        pk_image *none = NULL;
        CHECK(pk_film_resolve_aov(ctx, plain, PK_AOV_DEPTH, &none) == PK_ERR_INVALID_ARGUMENT && !none);
        pk_context_clear_error(ctx);
        pk_film *g = NULL;
        REQUIRE(pk_film_create_aovs(ctx, 17, 13, all, &g) == PK_OK);
        CHECK(pk_film_merge(ctx, g, f) == PK_OK && pk_film_merge(ctx, g, f) == PK_OK);
        pk_image *dep2 = NULL;
        REQUIRE(pk_film_resolve_aov(ctx, g, PK_AOV_DEPTH, &dep2) == PK_OK);
        CHECK(memcmp(pk_image_pixels_const(dep2), d, sizeof(float) * 3 * 17 * 13) == 0);
        pk_image_destroy(dep2);
        pk_film_destroy(g);
        pk_image_destroy(img), pk_image_destroy(ref), pk_image_destroy(alb), pk_image_destroy(nor);
        pk_image_destroy(dep), pk_image_destroy(heat);
        pk_film_destroy(f), pk_film_destroy(plain);
        pk_renderer_destroy(r);
    }
    CHECK(pk_aov_parse("depth") == PK_AOV_DEPTH && pk_aov_parse("colour") == 0);
    CHECK(strcmp(pk_aov_name(PK_AOV_HEATMAP), "heatmap") == 0);
    pk_film *x = NULL;
    CHECK(pk_film_create_aovs(ctx, 4, 4, 64u, &x) == PK_ERR_INVALID_ARGUMENT && !x);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_aov");
}

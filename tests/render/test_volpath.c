/*
 * test_volpath.c - the volumetric path tracer (render/volpath_kernel.h)
 * against closed forms, each tolerance Z standard errors of the estimate,
 * the standard error measured from the image itself (its pixels are
 * independent estimates, each the mean of SPP samples):
 *
 *  - absorption through a slab, homogeneous (chromatic, spectral MIS) and
 *    a grid whose density varies along the ray: exp(-optical depth), the
 *    camera's rays by delta tracking;
 *  - the same behind a glass boundary: (1-F)^2 e^-tau / (1 - F^2 e^-2tau);
 *  - shadow rays through a grid slab (ratio tracking) onto a diffuse floor:
 *    rho / pi E e^-tau;
 *  - an emissive, absorbing slab: le (1 - e^-tau);
 *  - single scattering in a slab lit by a distant light: its integral;
 *  - white furnaces: non-absorbing media (any g) inside an index-matched
 *    sphere and inside a glass sphere, and a constant grid, under a uniform
 *    environment, read the environment's radiance;
 *  - the same medium as homogeneous and as a constant grid: one image.
 *
 * Scenes are built in memory through the scene builders.
 */
#include "test.h"

#include "paprsek.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define Z 5.0
#define PI_D 3.14159265358979323846

static pk_context *ctx;

/* ---- building scenes ---------------------------------------------------------- */

static uint32_t add_mat(pk_scene *s, const char *name)
{
    uint32_t i;
    REQUIRE(scene_add_material(ctx, s, name, &i) == PK_OK);
    return i;
}

static void add_tri(pk_scene *s, vec3 a, vec3 b, vec3 c, uint32_t mat)
{
    const uint32_t v0 = (uint32_t)s->npositions;
    REQUIRE(scene_add_position(ctx, s, a) == PK_OK);
    REQUIRE(scene_add_position(ctx, s, b) == PK_OK);
    REQUIRE(scene_add_position(ctx, s, c) == PK_OK);
    triangle t = {{v0, v0 + 1, v0 + 2}, {-1, -1, -1}, {-1, -1, -1}, mat};
    REQUIRE(scene_add_triangle(ctx, s, &t) == PK_OK);
}

/* A quad a b c d, counter-clockwise seen from the side its normal points to. */
static void add_quad(pk_scene *s, vec3 a, vec3 b, vec3 c, vec3 d, uint32_t mat)
{
    add_tri(s, a, b, c, mat);
    add_tri(s, a, c, d, mat);
}

/* A box, its normals outward. */
static void add_box(pk_scene *s, vec3 lo, vec3 hi, uint32_t mat)
{
    const vec3 p[8] = {v3(lo.x, lo.y, lo.z), v3(hi.x, lo.y, lo.z), v3(hi.x, hi.y, lo.z), v3(lo.x, hi.y, lo.z),
                       v3(lo.x, lo.y, hi.z), v3(hi.x, lo.y, hi.z), v3(hi.x, hi.y, hi.z), v3(lo.x, hi.y, hi.z)};
    add_quad(s, p[0], p[3], p[2], p[1], mat); /* -z */
    add_quad(s, p[4], p[5], p[6], p[7], mat); /* +z */
    add_quad(s, p[0], p[1], p[5], p[4], mat); /* -y */
    add_quad(s, p[3], p[7], p[6], p[2], mat); /* +y */
    add_quad(s, p[0], p[4], p[7], p[3], mat); /* -x */
    add_quad(s, p[1], p[2], p[6], p[5], mat); /* +x */
}

static pk_scene *new_scene(const char *name)
{
    pk_scene *s = NULL;
    REQUIRE(scene_create(ctx, name, &s) == PK_OK);
    s->env.set = true; /* black surroundings unless a test says otherwise */
    return s;
}

static uint32_t add_homogeneous(pk_scene *s, vec3 sigma_t, vec3 albedo, float g, vec3 le)
{
    medium m;
    medium_init(&m);
    m.sigma_t = sigma_t, m.albedo = albedo, m.g = g, m.le = le;
    uint32_t i;
    REQUIRE(scene_add_medium(ctx, s, &m, &i) == PK_OK);
    return i;
}

/* A grid medium over box [lo, hi]: nz values along z (constant in x and y,
 * 2 voxels there), times sigma_t. */
static uint32_t add_zgrid(pk_scene *s, vec3 lo, vec3 hi, const float *vals, int nz, vec3 sigma_t, vec3 albedo,
                          float g)
{
    medium m;
    medium_init(&m);
    m.kind = MEDIUM_GRID;
    m.sigma_t = sigma_t, m.albedo = albedo, m.g = g;
    m.density = (medium_grid){2, 2, nz, 1, NULL};
    m.density.data = mem_realloc_array(&s->alloc, NULL, (size_t)4 * (size_t)nz, sizeof(float));
    REQUIRE(m.density.data);
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < 4; j++) m.density.data[k * 4 + j] = vals[k];
    const xform sc = xform_scale(v3_sub(hi, lo)), tr = xform_translate(lo);
    m.grid_to_world = xform_mul(&tr, &sc);
    uint32_t i;
    REQUIRE(scene_add_medium(ctx, s, &m, &i) == PK_OK);
    return i;
}

/* An interface material bounding medium med (inside), vacuum outside. */
static uint32_t interface_of(pk_scene *s, uint32_t med)
{
    const uint32_t m = add_mat(s, "boundary");
    material_interface(&s->materials[m]);
    s->materials[m].medium_in = (int32_t)med;
    s->materials[m].medium_out = MEDIUM_NONE;
    return m;
}

static uint32_t emitter(pk_scene *s, vec3 le)
{
    const uint32_t m = add_mat(s, "lamp");
    material_diffuse(&s->materials[m], v3s(0.0f));
    s->materials[m].ke = le;
    return m;
}

/* An orthographic camera at height h above the origin looking down -z,
 * the view w wide. */
static void ortho_down(pk_scene *s, float h, float w)
{
    pk_camera_init(&s->camera);
    s->camera.look_from[2] = h;
    s->camera.look_at[2] = h - 1.0f;
    s->camera.up[0] = 0.0f, s->camera.up[1] = 1.0f, s->camera.up[2] = 0.0f;
    s->camera.projection = PK_PROJECTION_ORTHOGRAPHIC;
    s->camera.ortho_width = w;
    s->has_camera = true;
}

/* ---- rendering and comparing -------------------------------------------------- */

typedef struct est {
    double mean[3], se[3];
} est;

static est render(pk_scene *s, int size, int spp, int max_depth, int strategy_unused)
{
    (void)strategy_unused;
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = size;
    o.spp = spp;
    o.threads = 2;
    o.max_depth = max_depth;
    pk_image *img = NULL;
    const pk_status st = pk_render(ctx, s, &o, &img, NULL);
    CHECKF(st == PK_OK, "%s: %s", s->name, pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    const float *px = pk_image_pixels_const(img);
    const size_t n = (size_t)size * (size_t)size;
    est e;
    for (int c = 0; c < 3; c++) {
        double m = 0.0, m2 = 0.0;
        for (size_t i = 0; i < n; i++) m += (double)px[3 * i + c], m2 += (double)px[3 * i + c] * (double)px[3 * i + c];
        m /= (double)n, m2 /= (double)n;
        e.mean[c] = m;
        e.se[c] = sqrt(fmax(m2 - m * m, 0.0) / (double)(n - 1));
    }
    pk_image_destroy(img);
    return e;
}

static void expect(const char *what, est e, const double want[3])
{
    for (int c = 0; c < 3; c++) {
        const double tol = Z * e.se[c] + 1e-4 * want[c] + 1e-6;
        CHECKF(fabs(e.mean[c] - want[c]) <= tol, "%s: channel %d: %.6f, want %.6f +- %.2g (se %.2g)", what, c, e.mean[c],
               want[c], tol, e.se[c]);
    }
    printf("  %s: (%.5f %.5f %.5f), want (%.5f %.5f %.5f), se (%.1e %.1e %.1e)\n", what, e.mean[0], e.mean[1],
           e.mean[2], want[0], want[1], want[2], e.se[0], e.se[1], e.se[2]);
}

/* ---- absorption --------------------------------------------------------------- */

/* Camera above a slab z in [0, d] of boundary material bmat, an emitter of
 * radiance 1 below it facing up. */
static void slab_scene(pk_scene *s, float d, uint32_t bmat)
{
    add_box(s, v3(-10.0f, -10.0f, 0.0f), v3(10.0f, 10.0f, d), bmat);
    const uint32_t lamp = emitter(s, v3s(1.0f));
    add_quad(s, v3(-20.0f, -20.0f, -1.0f), v3(20.0f, -20.0f, -1.0f), v3(20.0f, 20.0f, -1.0f), v3(-20.0f, 20.0f, -1.0f),
             lamp);
    ortho_down(s, 3.0f, 2.0f);
}

static void check_absorption(void)
{
    const vec3 sig = v3(0.4f, 1.1f, 2.3f);
    const float d = 0.8f;
    { /* homogeneous, chromatic: each channel's exp(-sigma d) through spectral MIS */
        pk_scene *s = new_scene("slab homogeneous");
        const uint32_t med = add_homogeneous(s, sig, v3s(0.0f), 0.0f, v3s(0.0f));
        slab_scene(s, d, interface_of(s, med));
        const double want[3] = {exp(-sig.x * d), exp(-sig.y * d), exp(-sig.z * d)};
        expect("absorbing slab, homogeneous chromatic", render(s, 32, 64, 16, 0), want);
        scene_destroy(s);
    }
    { /* a grid whose density rises along the ray (and a half-scattering albedo: scattered light is lost below) */
        pk_scene *s = new_scene("slab grid");
        const float vals[6] = {0.1f, 0.5f, 2.0f, 0.3f, 1.5f, 0.8f};
        const uint32_t med = add_zgrid(s, v3(-10.0f, -10.0f, 0.0f), v3(10.0f, 10.0f, d), vals, 6, sig, v3s(0.0f), 0.0f);
        slab_scene(s, d, interface_of(s, med));
        /* optical depth of the trilinear density along z: piecewise linear
         * between cell centres, held in the outer half cells */
        double integral = 0.0;
        const int steps = 600000;
        for (int i = 0; i < steps; i++) {
            const double z = (i + 0.5) / steps; /* unit cube */
            double x = z * 6 - 0.5;
            if (x < 0) x = 0;
            if (x > 5) x = 5;
            const int k = (int)x < 5 ? (int)x : 4;
            const double f = x - k;
            integral += ((double)vals[k] + f * (double)(vals[k + 1] - vals[k])) / steps;
        }
        const double want[3] = {exp(-(double)(sig.x * d) * integral), exp(-(double)(sig.y * d) * integral), exp(-(double)(sig.z * d) * integral)};
        expect("absorbing slab, grid along the ray (delta tracking)", render(s, 32, 64, 16, 0), want);
        scene_destroy(s);
    }
    { /* glass boundary: (1-F)^2 e^-tau / (1 - F^2 e^-2tau), black above */
        pk_scene *s = new_scene("slab glass");
        const uint32_t med = add_homogeneous(s, sig, v3s(0.0f), 0.0f, v3s(0.0f));
        const uint32_t glass = add_mat(s, "glass");
        material_dielectric(&s->materials[glass], 1.5f, 0.0f, v3s(1.0f));
        s->materials[glass].medium_in = (int32_t)med, s->materials[glass].medium_out = MEDIUM_NONE;
        slab_scene(s, d, glass);
        const double F = 0.04;
        double want[3];
        const float sg[3] = {sig.x, sig.y, sig.z};
        for (int c = 0; c < 3; c++) {
            const double T = exp(-sg[c] * d);
            want[c] = (1 - F) * (1 - F) * T / (1 - F * F * T * T);
        }
        expect("absorbing slab behind glass", render(s, 32, 128, 64, 0), want);
        scene_destroy(s);
    }
}

/* Shadow rays through a grid slab z in [1, 2] onto a diffuse floor at z = 0
 * lit straight down by a distant light; the camera sits under the slab. */
static void check_shadow_transmittance(void)
{
    pk_scene *s = new_scene("shadow grid");
    const float vals[5] = {0.2f, 1.7f, 0.4f, 0.9f, 0.05f};
    const vec3 sig = v3(0.5f, 1.0f, 1.5f);
    const uint32_t med = add_zgrid(s, v3(-50.0f, -50.0f, 1.0f), v3(50.0f, 50.0f, 2.0f), vals, 5, sig, v3s(0.0f), 0.0f);
    add_box(s, v3(-50.0f, -50.0f, 1.0f), v3(50.0f, 50.0f, 2.0f), interface_of(s, med));
    const uint32_t floor_m = add_mat(s, "floor");
    material_diffuse(&s->materials[floor_m], v3s(0.5f));
    add_quad(s, v3(-60.0f, -60.0f, 0.0f), v3(60.0f, -60.0f, 0.0f), v3(60.0f, 60.0f, 0.0f), v3(-60.0f, 60.0f, 0.0f),
             floor_m);
    REQUIRE(scene_light_distant(ctx, s, v3(0.0f, 0.0f, 1.0f), v3s(2.0f)) == PK_OK);
    ortho_down(s, 0.5f, 2.0f);
    double integral = 0.0;
    const int steps = 500000;
    for (int i = 0; i < steps; i++) {
        double x = (i + 0.5) / steps * 5 - 0.5;
        if (x < 0) x = 0;
        if (x > 4) x = 4;
        const int k = (int)x < 4 ? (int)x : 3;
        integral += ((double)vals[k] + (x - k) * (double)(vals[k + 1] - vals[k])) / steps;
    }
    const float sg[3] = {sig.x, sig.y, sig.z};
    double want[3];
    for (int c = 0; c < 3; c++) want[c] = 0.5 / PI_D * 2.0 * exp(-(double)sg[c] * integral);
    expect("floor under a grid slab (ratio tracking)", render(s, 32, 64, 1, 0), want);
    scene_destroy(s);
}

/* A global absorbing fog (the camera's medium, no boundaries) over a
 * diffuse floor lit by a point light: rho/pi I cos / r^2 e^-sigma r,
 * times e^-sigma for the camera ray's way down (the occlusion test and the
 * closed-form transmittance of shadow rays in homogeneous media). */
static void check_global_fog(void)
{
    pk_scene *s = new_scene("global fog");
    const float sa = 0.3f;
    s->camera_medium = (int32_t)add_homogeneous(s, v3s(sa), v3s(0.0f), 0.0f, v3s(0.0f));
    const uint32_t floor_m = add_mat(s, "floor");
    material_diffuse(&s->materials[floor_m], v3s(0.5f));
    add_quad(s, v3(-60.0f, -60.0f, 0.0f), v3(60.0f, -60.0f, 0.0f), v3(60.0f, 60.0f, 0.0f), v3(-60.0f, 60.0f, 0.0f),
             floor_m);
    REQUIRE(scene_light_point(ctx, s, v3(0.0f, 0.0f, 2.0f), v3s(5.0f)) == PK_OK);
    ortho_down(s, 1.0f, 0.5f);
    double sum = 0.0;
    const int n = 400;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const double x = -0.25 + (i + 0.5) * 0.5 / n, y = -0.25 + (j + 0.5) * 0.5 / n;
            const double r = sqrt(x * x + y * y + 4.0);
            sum += 0.5 / PI_D * 5.0 * (2.0 / r) / (r * r) * exp(-(double)sa * r) * exp(-(double)sa);
        }
    const double m = sum / ((double)n * n), want[3] = {m, m, m};
    expect("global fog over a lit floor", render(s, 32, 16, 1, 0), want);
    scene_destroy(s);
}

/* ---- emission ----------------------------------------------------------------- */

static void check_emission(void)
{
    pk_scene *s = new_scene("glowing slab");
    const float d = 0.7f;
    const vec3 sa = v3(1.3f, 0.4f, 2.5f), le = v3(1.0f, 0.5f, 0.25f);
    const uint32_t med = add_homogeneous(s, sa, v3s(0.0f), 0.0f, le);
    add_box(s, v3(-10.0f, -10.0f, 0.0f), v3(10.0f, 10.0f, d), interface_of(s, med));
    /* something to hit far below, black, so that the scene is not empty of lights' meaning */
    ortho_down(s, 3.0f, 2.0f);
    const double want[3] = {(double)le.x * (1.0 - exp(-(double)(sa.x * d))), (double)le.y * (1.0 - exp(-(double)(sa.y * d))),
                            (double)le.z * (1.0 - exp(-(double)(sa.z * d)))};
    expect("emissive absorbing slab, chromatic", render(s, 32, 64, 16, 0), want);
    scene_destroy(s);
}

/* ---- single scattering ---------------------------------------------------------- */

static double hg(double g, double c) /* c = dot(wo, wi) */
{
    const double den = 1 + g * g + 2 * g * c;
    return (1 - g * g) / (4 * PI_D * den * sqrt(den));
}

/* Single scattering in a slab under a distant light, per channel:
 * E sigma_s p (1 - e^(-sigma_t d k)) / (sigma_t k), k = 1 + 1 / cos. */
static void single_scattering(const char *what, vec3 sigt, vec3 albedo)
{
    const float d = 0.5f, g = 0.4f;
    pk_scene *s = new_scene(what);
    const uint32_t med = add_homogeneous(s, sigt, albedo, g, v3s(0.0f));
    add_box(s, v3(-100.0f, -100.0f, 0.0f), v3(100.0f, 100.0f, d), interface_of(s, med));
    const vec3 wl = v3_norm(v3(0.6f, 0.0f, 0.8f)); /* toward the light */
    REQUIRE(scene_light_distant(ctx, s, wl, v3s(3.0f)) == PK_OK);
    ortho_down(s, 3.0f, 2.0f);
    const double c = (double)wl.z, k = 1.0 + 1.0 / c;
    const float st[3] = {sigt.x, sigt.y, sigt.z}, al[3] = {albedo.x, albedo.y, albedo.z};
    double want[3];
    for (int i = 0; i < 3; i++)
        want[i] = 3.0 * hg(g, c) * (double)(al[i] * st[i]) * (1.0 - exp(-(double)(st[i] * d) * k)) / ((double)st[i] * k);
    expect(what, render(s, 32, 256, 1, 0), want);
    scene_destroy(s);
}

static void check_single_scattering(void)
{
    single_scattering("single scattering in a slab", v3s(0.6f), v3(0.9f, 0.6f, 0.3f));
    single_scattering("single scattering, chromatic extinction", v3(0.3f, 1.2f, 4.0f), v3(0.9f, 0.6f, 0.8f));
}

/* ---- white furnaces --------------------------------------------------------------- */

static pk_scene *furnace(const char *name, bool glass, bool grid, float g)
{
    pk_scene *s = new_scene(name);
    s->env.radiance = v3s(1.0f);
    uint32_t med;
    if (grid) {
        const float vals[3] = {1.5f, 1.5f, 1.5f};
        med = add_zgrid(s, v3s(-1.0f), v3s(1.0f), vals, 3, v3s(1.0f), v3s(1.0f), g);
    } else {
        med = add_homogeneous(s, v3s(1.5f), v3s(1.0f), g, v3s(0.0f));
    }
    uint32_t mat;
    if (glass) {
        mat = add_mat(s, "glass");
        material_dielectric(&s->materials[mat], 1.33f, 0.0f, v3s(1.0f));
        s->materials[mat].medium_in = (int32_t)med, s->materials[mat].medium_out = MEDIUM_NONE;
    } else {
        mat = interface_of(s, med);
    }
    if (grid) {
        add_box(s, v3s(-1.0f), v3s(1.0f), mat);
    } else {
        sphere sp = {v3s(0.0f), 1.0f, mat};
        REQUIRE(scene_add_sphere(ctx, s, &sp) == PK_OK);
    }
    pk_camera_init(&s->camera);
    s->camera.look_from[2] = 4.0f;
    s->camera.fov_deg = 35.0f;
    s->has_camera = true;
    return s;
}

static void check_furnaces(void)
{
    const double one[3] = {1.0, 1.0, 1.0};
    const float gs[3] = {0.0f, 0.7f, -0.4f};
    for (int i = 0; i < 3; i++) {
        char name[64];
        snprintf(name, sizeof name, "furnace, index-matched sphere, g %.1f", (double)gs[i]);
        pk_scene *s = furnace(name, false, false, gs[i]);
        expect(name, render(s, 24, 32, 64, 0), one);
        scene_destroy(s);
    }
    pk_scene *s = furnace("furnace, glass sphere, g 0.5", true, false, 0.5f);
    expect("furnace, glass sphere, g 0.5", render(s, 24, 32, 64, 0), one);
    scene_destroy(s);
    s = furnace("furnace, constant grid box, g 0.3", false, true, 0.3f);
    expect("furnace, constant grid box, g 0.3", render(s, 24, 32, 64, 0), one);
    scene_destroy(s);
}

/* ---- homogeneous and constant grid: one image ------------------------------------- */

static void check_grid_equals_homogeneous(void)
{
    est e[2];
    for (int k = 0; k < 2; k++) {
        pk_scene *s = new_scene(k ? "grid box" : "homogeneous box");
        const vec3 sig = v3(1.5f, 1.0f, 0.5f), al = v3(0.8f, 0.7f, 0.9f);
        uint32_t med;
        if (k) {
            const float vals[4] = {1.0f, 1.0f, 1.0f, 1.0f};
            med = add_zgrid(s, v3s(-1.0f), v3s(1.0f), vals, 4, sig, al, 0.2f);
        } else {
            med = add_homogeneous(s, sig, al, 0.2f, v3s(0.0f));
        }
        add_box(s, v3s(-1.0f), v3s(1.0f), interface_of(s, med));
        const uint32_t lamp = emitter(s, v3s(4.0f));
        add_quad(s, v3(-0.5f, -0.5f, 1.5f), v3(-0.5f, 0.5f, 1.5f), v3(0.5f, 0.5f, 1.5f), v3(0.5f, -0.5f, 1.5f), lamp);
        pk_camera_init(&s->camera);
        s->camera.look_from[0] = 3.0f, s->camera.look_from[2] = 3.0f;
        s->camera.look_at[2] = 0.0f;
        s->camera.fov_deg = 40.0f;
        s->has_camera = true;
        e[k] = render(s, 32, 64, 64, 0);
        scene_destroy(s);
    }
    for (int c = 0; c < 3; c++) {
        const double se = sqrt(e[0].se[c] * e[0].se[c] + e[1].se[c] * e[1].se[c]);
        CHECKF(fabs(e[0].mean[c] - e[1].mean[c]) <= Z * se + 1e-6, "homogeneous %.5f vs constant grid %.5f (se %.2g)",
               e[0].mean[c], e[1].mean[c], se);
    }
    printf("  homogeneous vs constant grid: (%.5f %.5f %.5f) vs (%.5f %.5f %.5f)\n", e[0].mean[0], e[0].mean[1],
           e[0].mean[2], e[1].mean[0], e[1].mean[1], e[1].mean[2]);
}

/* A grid with one absurd voxel among zeros (its majorant cells are 1e30
 * over nothing): the render ends, in bounded time, with finite pixels. */
static void check_hostile_grid(void)
{
    pk_scene *s = new_scene("hostile grid");
    const float vals[4] = {0.0f, 1e30f, 0.0f, 0.0f};
    const uint32_t med = add_zgrid(s, v3s(-1.0f), v3s(1.0f), vals, 4, v3s(1.0f), v3s(0.5f), 0.0f);
    add_box(s, v3s(-1.0f), v3s(1.0f), interface_of(s, med));
    s->env.radiance = v3s(1.0f);
    pk_camera_init(&s->camera);
    s->camera.look_from[0] = 0.3f, s->camera.look_from[2] = 4.0f;
    s->has_camera = true;
    const est e = render(s, 8, 1, 8, 0);
    CHECKF(isfinite(e.mean[0]) && e.mean[0] >= 0.0 && e.mean[0] <= 1.0 + 1e-6, "mean %g", e.mean[0]);
    printf("  hostile grid: mean %.4f, finite\n", e.mean[0]);
    scene_destroy(s);
}

/* ---- AOVs and the denoiser on a volumetric render ---------------------------------- */

/* A box of scattering medium lit from above, seen from the side. */
static pk_scene *lit_box(const char *name, vec3 albedo)
{
    pk_scene *s = new_scene(name);
    const uint32_t med = add_homogeneous(s, v3s(3.0f), albedo, 0.3f, v3s(0.0f));
    add_box(s, v3s(-1.0f), v3s(1.0f), interface_of(s, med));
    const uint32_t lamp = emitter(s, v3s(6.0f));
    add_quad(s, v3(-0.6f, -0.6f, 1.6f), v3(-0.6f, 0.6f, 1.6f), v3(0.6f, 0.6f, 1.6f), v3(0.6f, -0.6f, 1.6f), lamp);
    const uint32_t floor_m = add_mat(s, "floor");
    material_diffuse(&s->materials[floor_m], v3s(0.6f));
    add_quad(s, v3(-4.0f, -4.0f, -1.2f), v3(4.0f, -4.0f, -1.2f), v3(4.0f, 4.0f, -1.2f), v3(-4.0f, 4.0f, -1.2f),
             floor_m);
    pk_camera_init(&s->camera);
    s->camera.look_from[0] = 3.0f, s->camera.look_from[1] = -3.5f, s->camera.look_from[2] = 2.0f;
    s->camera.look_at[2] = 0.0f;
    s->camera.up[0] = 0.0f, s->camera.up[1] = 0.0f, s->camera.up[2] = 1.0f;
    s->camera.fov_deg = 40.0f;
    s->has_camera = true;
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    return s;
}

/* Renders s at size x size, spp samples from pass `pass`, colour and (aovs) AOVs. */
static pk_film *render_film(pk_scene *s, int size, int spp, unsigned aovs, uint32_t pass)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = size;
    o.spp = spp;
    o.threads = 2;
    o.max_depth = 32;
    pk_renderer *r = NULL;
    pk_film *film = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    REQUIRE(pk_film_create_aovs(ctx, size, size, aovs, &film) == PK_OK);
    pk_renderer_set_pass(r, pass);
    REQUIRE(pk_renderer_render(r, NULL, 0, film) == PK_OK);
    pk_renderer_destroy(r);
    return film;
}

static double rel_mse(const pk_image *a, const pk_image *ref, int n)
{
    const float *x = pk_image_pixels_const(a), *y = pk_image_pixels_const(ref);
    double e = 0.0;
    for (int i = 0; i < 3 * n; i++) {
        const double d = (double)x[i] - (double)y[i];
        e += d * d / ((double)y[i] * (double)y[i] + 1e-2);
    }
    return e / (3.0 * n);
}

static void check_aov_and_denoise(void)
{
    /* the albedo AOV where the camera ray's first collision is in the
     * medium: the medium's albedo (sigma_t is the same in every channel,
     * so every first collision is real and the throughput 1) */
    const vec3 al = v3(0.9f, 0.6f, 0.3f);
    pk_scene *s = new_scene("aov slab");
    const uint32_t med = add_homogeneous(s, v3s(4.0f), al, 0.0f, v3s(0.0f));
    add_box(s, v3(-10.0f, -10.0f, 0.0f), v3(10.0f, 10.0f, 2.0f), interface_of(s, med));
    ortho_down(s, 3.0f, 2.0f);
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    pk_film *film = render_film(s, 16, 16, PK_AOV_ALBEDO | PK_AOV_DEPTH, 0);
    pk_image *alb = NULL, *dep = NULL;
    REQUIRE(pk_film_resolve_aov(ctx, film, PK_AOV_ALBEDO, &alb) == PK_OK);
    REQUIRE(pk_film_resolve_aov(ctx, film, PK_AOV_DEPTH, &dep) == PK_OK);
    const float *a = pk_image_pixels_const(alb), *d = pk_image_pixels_const(dep);
    double dm = 0.0;
    int bad = 0;
    const double pass = exp(-8.0); /* camera rays through the slab without a collision see black */
    for (int i = 0; i < 16 * 16; i++) {
        const float w[3] = {al.x, al.y, al.z};
        for (int c = 0; c < 3; c++)
            if (fabs((double)a[3 * i + c] - (double)w[c]) > (double)w[c] * (pass * 16 + 1e-5)) bad++;
        dm += (double)d[3 * i];
    }
    dm /= 16 * 16;
    CHECKF(bad == 0, "%d albedo values are not the medium's albedo", bad);
    /* depth: 3 - 2 to the slab, then an exponential of mean 1/4 */
    CHECKF(fabs(dm - 1.25) < 5.0 * 0.25 / sqrt(16.0 * 16 * 16), "mean depth %.4f, want 1.25", dm);
    printf("  AOVs in a medium: albedo (%.4f %.4f %.4f), mean depth %.4f (want 1.25)\n", (double)a[0], (double)a[1],
           (double)a[2], dm);
    pk_image_destroy(alb);
    pk_image_destroy(dep);
    pk_film_destroy(film);
    scene_destroy(s);

    /* the denoiser on a noisy volumetric render: closer to the reference than its input */
    pk_denoise_options dopt;
    memset(&dopt, 0, sizeof dopt);
    dopt.weights = PK_WEIGHTS_DIR;
    if (pk_denoise_check(ctx, &dopt) != PK_OK) {
        printf("  denoiser on a volumetric render: skipped (%s)\n", pk_context_error(ctx));
        pk_context_clear_error(ctx);
        return;
    }
    const int size = 64;
    s = lit_box("denoise box", v3(0.95f, 0.8f, 0.6f));
    pk_film *ref_f = render_film(s, size, 512, 0, 1), *noisy_f = render_film(s, size, 4, PK_AOV_ALBEDO | PK_AOV_NORMAL, 0);
    pk_image *ref = NULL, *noisy = NULL, *nal = NULL, *nn = NULL, *clean = NULL;
    REQUIRE(pk_film_resolve(ctx, ref_f, &ref) == PK_OK);
    REQUIRE(pk_film_resolve(ctx, noisy_f, &noisy) == PK_OK);
    REQUIRE(pk_film_resolve_aov(ctx, noisy_f, PK_AOV_ALBEDO, &nal) == PK_OK);
    REQUIRE(pk_film_resolve_aov(ctx, noisy_f, PK_AOV_NORMAL, &nn) == PK_OK);
    REQUIRE(pk_denoise(ctx, &dopt, noisy, nal, nn, &clean) == PK_OK);
    const double e_noisy = rel_mse(noisy, ref, size * size), e_clean = rel_mse(clean, ref, size * size);
    CHECKF(e_clean < 0.5 * e_noisy, "denoised relMSE %.4f is not below half the noisy %.4f", e_clean, e_noisy);
    printf("  denoiser on a volumetric render (4 spp): relMSE %.4f -> %.4f against 512 spp\n", e_noisy, e_clean);
    pk_image_destroy(ref);
    pk_image_destroy(noisy);
    pk_image_destroy(nal);
    pk_image_destroy(nn);
    pk_image_destroy(clean);
    pk_film_destroy(ref_f);
    pk_film_destroy(noisy_f);
    scene_destroy(s);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_absorption();
    check_shadow_transmittance();
    check_global_fog();
    check_emission();
    check_single_scattering();
    check_furnaces();
    check_grid_equals_homogeneous();
    check_hostile_grid();
    check_aov_and_denoise();
    pk_context_destroy(ctx);
    return test_done("volpath");
}

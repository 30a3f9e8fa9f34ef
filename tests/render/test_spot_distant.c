/*
 * test_spot_distant.c - spot and distant lights (point_light.spot_dir,
 * .distant): the falloff curves of the three conventions against their
 * formulas, and renders of a diffuse floor lit by each light against the
 * closed-form radiance rho/pi * E (E the irradiance the light gives the
 * point), pixel by pixel, with both integrators. The light is a delta, so
 * the only randomness is where in its pixel each camera ray goes: the
 * expected pixel value is the closed form averaged over the pixel (a fine
 * grid in the test), and its standard deviation over the pixel, divided by
 * sqrt(spp), bounds the error (Z standard errors). The JSON and Mitsuba
 * readers' spot and directional lights are checked to arrive as such.
 */
#include "test.h"

#include "paprsek.h"
#include "render/lights.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PI_D 3.14159265358979323846
#define Z 5.0
#define SIZE 24
#define SPP 64
#define GRID 32 /* analytic sub-samples per pixel side */

static pk_context *ctx;

/* ---- the falloff curves ---------------------------------------------------- */

static void check_falloff(void)
{
    point_light l;
    memset(&l, 0, sizeof l);
    CHECK(spot_falloff(&l, v3(0.3f, -0.9f, 0.1f)) == 1.0f); /* no axis: every direction */
    l.spot_dir = v3(0.0f, 0.0f, 1.0f);
    const double inner = 20.0, outer = 30.0;
    l.cos_inner = (float)cos(inner * PI_D / 180.0), l.cos_outer = (float)cos(outer * PI_D / 180.0);
    for (int mode = 0; mode < 3; mode++) {
        l.spot_falloff = mode;
        for (double a = 0.0; a <= 40.0; a += 0.5) {
            const double c = cos(a * PI_D / 180.0), t = (c - cos(outer * PI_D / 180.0)) /
                                                         (cos(inner * PI_D / 180.0) - cos(outer * PI_D / 180.0));
            double want;
            if (a <= inner) want = 1.0;
            else if (a >= outer) want = 0.0;
            else if (mode == SPOT_FALLOFF_SMOOTHSTEP) want = t * t * (3.0 - 2.0 * t);
            else if (mode == SPOT_FALLOFF_SQUARED) want = t * t;
            else want = (outer - a) / (outer - inner);
            const vec3 w = v3((float)sin(a * PI_D / 180.0), 0.0f, (float)c);
            const double got = spot_falloff(&l, w);
            CHECKF(fabs(got - want) < 2e-4, "mode %d at %.1f degrees: %g, want %g", mode, a, got, want);
        }
    }
}

/* ---- renders of a lit floor ------------------------------------------------ */

/* The floor: a sphere of radius R about (0, -R, 0), seen from (0, H, 0)
 * straight down with up -z, fov FOV. */
#define R 1000.0
#define H 5.0
#define FOV 43.6
#define RHO 0.5

typedef struct lamp {
    int distant;
    double pos[3], dir[3]; /* dir: where light travels */
    double intensity;
    double cos_inner, cos_outer; /* spot when cos_outer > -1 */
    int falloff;
} lamp;

static double falloff_d(const lamp *lp, double c)
{
    if (!(lp->cos_outer > -1.0)) return 1.0;
    if (c >= lp->cos_inner) return 1.0;
    if (c <= lp->cos_outer) return 0.0;
    const double t = (c - lp->cos_outer) / (lp->cos_inner - lp->cos_outer);
    if (lp->falloff == SPOT_FALLOFF_SQUARED) return t * t;
    if (lp->falloff == SPOT_FALLOFF_ANGLE) return (acos(lp->cos_outer) - acos(c)) / (acos(lp->cos_outer) - acos(lp->cos_inner));
    return t * t * (3.0 - 2.0 * t);
}

/* The radiance seen through film point (fx, fy) (pixels). */
static double radiance_at(const lamp *lp, double fx, double fy)
{
    const double hh = tan(0.5 * FOV * PI_D / 180.0), hw = hh;
    const double sx = (2.0 * fx / SIZE - 1.0) * hw, sy = (1.0 - 2.0 * fy / SIZE) * hh;
    /* u = +x, v = -z, w = +y: d = u sx + v sy - w */
    double d[3] = {sx, -1.0, -sy};
    const double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; i++) d[i] /= dl;
    /* hit the sphere: o = (0, H, 0), c = (0, -R, 0) */
    const double oc[3] = {0.0, H + R, 0.0};
    const double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    const double cc = oc[1] * oc[1] - R * R, disc = b * b - cc;
    if (disc < 0.0) return 0.0;
    const double t = -b - sqrt(disc);
    const double p[3] = {t * d[0], H + t * d[1], t * d[2]};
    const double n[3] = {p[0] / R, (p[1] + R) / R, p[2] / R};
    double e;
    if (lp->distant) {
        const double c = -(n[0] * lp->dir[0] + n[1] * lp->dir[1] + n[2] * lp->dir[2]);
        e = c > 0.0 ? lp->intensity * c : 0.0;
    } else {
        double w[3] = {lp->pos[0] - p[0], lp->pos[1] - p[1], lp->pos[2] - p[2]};
        const double d2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], wl = sqrt(d2);
        for (int i = 0; i < 3; i++) w[i] /= wl;
        const double cr = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
        const double cs = -(w[0] * lp->dir[0] + w[1] * lp->dir[1] + w[2] * lp->dir[2]);
        e = cr > 0.0 ? lp->intensity * falloff_d(lp, cs) * cr / d2 : 0.0;
    }
    return RHO / PI_D * e;
}

static pk_scene *load(const char *text, const char *name)
{
    pk_scene *s = NULL;
    pk_status st = strstr(name, ".xml") ? pk_scene_load_xml_memory(ctx, text, strlen(text), name, ".", &s)
                                        : pk_scene_load_json_memory(ctx, text, strlen(text), name, ".", &s);
    CHECKF(st == PK_OK, "%s: %s", name, pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return s;
}

static void check_render(const lamp *lp, pk_scene *s, const char *what, pk_integrator_kind integ)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = o.height = SIZE;
    o.spp = SPP;
    o.threads = 2;
    o.integrator = integ;
    pk_image *img = NULL;
    REQUIRE(pk_render(ctx, s, &o, &img, NULL) == PK_OK);
    const float *px = pk_image_pixels_const(img);
    int bad = 0;
    double worst = 0.0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            double m = 0.0, m2 = 0.0;
            for (int j = 0; j < GRID; j++)
                for (int i = 0; i < GRID; i++) {
                    const double v = radiance_at(lp, x + (i + 0.5) / GRID, y + (j + 0.5) / GRID);
                    m += v, m2 += v * v;
                }
            m /= GRID * GRID, m2 /= GRID * GRID;
            const double sd = sqrt(fmax(m2 - m * m, 0.0));
            for (int c = 0; c < 3; c++) {
                const double got = px[3 * (y * SIZE + x) + c];
                const double tol = Z * sd / sqrt((double)SPP) + 2e-5 * m + 1e-7;
                const double err = fabs(got - m) / tol;
                if (err > worst) worst = err;
                if (err > 1.0 && bad++ < 5)
                    CHECKF(0, "%s (%s): pixel (%d, %d) channel %d: %.6g, want %.6g +- %.3g", what,
                           pk_integrator_name(integ), x, y, c, got, m, tol);
            }
        }
    CHECKF(bad == 0, "%s (%s): %d values off", what, pk_integrator_name(integ), bad);
    printf("  %s (%s): worst error %.2f of its tolerance\n", what, pk_integrator_name(integ), worst);
    pk_image_destroy(img);
}

static const char *json_head = "{\"materials\": {\"floor\": {\"kd\": [0.5, 0.5, 0.5]}},"
                               " \"camera\": {\"look_from\": [0, 5, 0], \"look_at\": [0, 0, 0], \"up\": [0, 0, -1],"
                               " \"fov\": 43.6},"
                               " \"render\": {\"max_depth\": 1},"
                               " \"spheres\": [{\"center\": [0, -1000, 0], \"radius\": 1000, \"material\": \"floor\"}],";

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_falloff();

    char text[4096];
    /* a distant light, slanted */
    {
        const double dir[3] = {0.3, -1.0, 0.2};
        const double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        lamp lp = {1, {0, 0, 0}, {dir[0] / dl, dir[1] / dl, dir[2] / dl}, 2.0, 1.0, -2.0, 0};
        snprintf(text, sizeof text, "%s \"lights\": [{\"type\": \"distant\", \"direction\": [0.3, -1, 0.2], \"intensity\": 2}]}",
                 json_head);
        pk_scene *s = load(text, "distant.json");
        check_render(&lp, s, "distant light", PK_INTEGRATOR_PATH);
        check_render(&lp, s, "distant light", PK_INTEGRATOR_WHITTED);
        pk_scene_destroy(s);
    }
    /* a spot light above the floor, tilted: its cone's edge crosses the image */
    {
        const double dir[3] = {0.2, -1.0, 0.0};
        const double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1]);
        lamp lp = {0, {0.0, 2.0, 0.3}, {dir[0] / dl, dir[1] / dl, 0.0}, 5.0, cos(20.0 * PI_D / 180.0),
                   cos(30.0 * PI_D / 180.0), SPOT_FALLOFF_SMOOTHSTEP};
        snprintf(text, sizeof text,
                 "%s \"lights\": [{\"type\": \"spot\", \"position\": [0, 2, 0.3], \"direction\": [0.2, -1, 0],"
                 " \"outer_angle\": 30, \"inner_angle\": 20, \"intensity\": 5}]}",
                 json_head);
        pk_scene *s = load(text, "spot.json");
        check_render(&lp, s, "spot light", PK_INTEGRATOR_PATH);
        check_render(&lp, s, "spot light", PK_INTEGRATOR_WHITTED);
        pk_scene_destroy(s);
    }
    /* Mitsuba's spot (linear in the angle, along +z of to_world) and directional */
    {
        const char *xml =
            "<scene version=\"3.0.0\">"
            " <sensor type=\"perspective\"><float name=\"fov\" value=\"43.6\"/><string name=\"fov_axis\" value=\"y\"/>"
            "  <transform name=\"to_world\"><lookat origin=\"0,5,0\" target=\"0,0,0\" up=\"0,0,-1\"/></transform>"
            "  <film type=\"hdrfilm\"><integer name=\"width\" value=\"24\"/><integer name=\"height\" value=\"24\"/></film>"
            " </sensor>"
            " <integrator type=\"path\"><integer name=\"max_depth\" value=\"2\"/></integrator>"
            " <shape type=\"sphere\"><point name=\"center\" x=\"0\" y=\"-1000\" z=\"0\"/><float name=\"radius\" value=\"1000\"/>"
            "  <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5\"/></bsdf></shape>"
            " <emitter type=\"spot\"><rgb name=\"intensity\" value=\"5\"/>"
            "  <float name=\"cutoff_angle\" value=\"30\"/><float name=\"beam_width\" value=\"20\"/>"
            "  <transform name=\"to_world\"><lookat origin=\"0,2,0.3\" target=\"0.2,1,0.3\" up=\"0,0,1\"/></transform>"
            " </emitter>"
            "</scene>";
        const double dl = sqrt(0.04 + 1.0);
        lamp lp = {0, {0.0, 2.0, 0.3}, {0.2 / dl, -1.0 / dl, 0.0}, 5.0, cos(20.0 * PI_D / 180.0),
                   cos(30.0 * PI_D / 180.0), SPOT_FALLOFF_ANGLE};
        pk_scene *s = load(xml, "spot.xml");
        check_render(&lp, s, "Mitsuba spot", PK_INTEGRATOR_PATH);
        pk_scene_destroy(s);
    }
    {
        const char *xml =
            "<scene version=\"3.0.0\">"
            " <sensor type=\"perspective\"><float name=\"fov\" value=\"43.6\"/><string name=\"fov_axis\" value=\"y\"/>"
            "  <transform name=\"to_world\"><lookat origin=\"0,5,0\" target=\"0,0,0\" up=\"0,0,-1\"/></transform>"
            "  <film type=\"hdrfilm\"><integer name=\"width\" value=\"24\"/><integer name=\"height\" value=\"24\"/></film>"
            " </sensor>"
            " <integrator type=\"path\"><integer name=\"max_depth\" value=\"2\"/></integrator>"
            " <shape type=\"sphere\"><point name=\"center\" x=\"0\" y=\"-1000\" z=\"0\"/><float name=\"radius\" value=\"1000\"/>"
            "  <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5\"/></bsdf></shape>"
            " <emitter type=\"directional\"><vector name=\"direction\" x=\"0.3\" y=\"-1\" z=\"0.2\"/>"
            "  <rgb name=\"irradiance\" value=\"2\"/></emitter>"
            "</scene>";
        const double dir[3] = {0.3, -1.0, 0.2};
        const double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        lamp lp = {1, {0, 0, 0}, {dir[0] / dl, dir[1] / dl, dir[2] / dl}, 2.0, 1.0, -2.0, 0};
        pk_scene *s = load(xml, "directional.xml");
        check_render(&lp, s, "Mitsuba directional", PK_INTEGRATOR_PATH);
        pk_scene_destroy(s);
    }
    /* bad lights are refused with a message */
    {
        static const char *const bad[] = {
            "\"lights\": [{\"type\": \"spot\", \"position\": [0, 2, 0], \"outer_angle\": 30}]}",
            "\"lights\": [{\"type\": \"spot\", \"position\": [0, 2, 0], \"direction\": [0, 0, 0]}]}",
            "\"lights\": [{\"type\": \"spot\", \"position\": [0, 2, 0], \"direction\": [0, -1, 0], \"inner_angle\": 40, \"outer_angle\": 30}]}",
            "\"lights\": [{\"type\": \"distant\", \"position\": [0, 2, 0], \"direction\": [0, -1, 0]}]}",
            "\"lights\": [{\"type\": \"laser\", \"position\": [0, 2, 0]}]}",
            "\"lights\": [{\"position\": [0, 2, 0], \"outer_angle\": 30}]}",
        };
        for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
            snprintf(text, sizeof text, "%s %s", json_head, bad[i]);
            pk_scene *s = NULL;
            pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "bad.json", ".", &s);
            CHECKF(st != PK_OK && s == NULL, "bad light %zu accepted", i);
            CHECKF(strstr(pk_context_error(ctx), "bad.json") != NULL, "message: %s", pk_context_error(ctx));
        }
    }
    pk_context_destroy(ctx);
    return test_done("test_spot_distant");
}

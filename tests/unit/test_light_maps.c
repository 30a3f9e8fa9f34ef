/*
 * test_light_maps.c - point lights shaped by images, as pbrt-v4's
 * goniometric and projection lights describe them: the reader's frames and
 * the renderer's lookup (point_light_map) return each texel for the
 * direction of its centre, nothing outside a projection's window, and
 * "power" sets the intensity from the map's mean.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "render/lights.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PLAIN "Scale -1 1 1\nCamera \"perspective\"\nWorldBegin\n"

static warning_log warnings;

static pk_scene *load(pk_context **ctx, const char *text)
{
    REQUIRE(pk_context_create(NULL, ctx) == PK_OK);
    warning_log_clear(&warnings);
    warning_log_attach(*ctx, &warnings);
    pk_scene *s = NULL;
    REQUIRE(scene_create(*ctx, "t.pbrt", &s) == PK_OK);
    pk_status st = scene_pbrt_parse(*ctx, s, text, strlen(text), "t.pbrt", "/tmp");
    if (st == PK_OK) st = scene_commit(*ctx, s);
    CHECKF(st == PK_OK, "load failed: %s", pk_context_error(*ctx));
    if (st != PK_OK) {
        scene_destroy(s);
        return NULL;
    }
    return s;
}

static void done(pk_context *ctx, pk_scene *s)
{
    if (s) scene_destroy(s);
    pk_context_destroy(ctx);
}

/* pbrt-v4's square -> sphere equal-area mapping (Clarberg), written from
 * its definition here, apart from the renderer's sphere -> square. */
static vec3 square_to_sphere(double u, double v)
{
    const double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0, ap = fabs(a), bp = fabs(b);
    const double sd = 1.0 - (ap + bp), r = 1.0 - fabs(sd);
    const double phi = (r == 0.0 ? 1.0 : (bp - ap) / r + 1.0) * M_PI / 4.0;
    const double z = copysign(1.0 - r * r, sd), q = r * sqrt(2.0 - r * r);
    return v3((float)(copysign(cos(phi), a) * q), (float)(copysign(sin(phi), b) * q), (float)z);
}

/* A PFM of w x h texels (row 0 on top, as images are read) of colour f(x, y). */
static void write_pfm(const char *path, int w, int h, vec3 (*f)(int, int))
{
    FILE *fp = fopen(path, "wb");
    REQUIRE(fp);
    fprintf(fp, "PF\n%d %d\n-1\n", w, h);
    for (int y = h - 1; y >= 0; y--) /* PFM stores the bottom row first */
        for (int x = 0; x < w; x++) {
            const vec3 c = f(x, y);
            const float px[3] = {c.x, c.y, c.z};
            fwrite(px, sizeof px, 1, fp);
        }
    fclose(fp);
}
static vec3 gonio_texel(int x, int y) { return v3s((float)(1 + x + 8 * y)); }
static vec3 proj_texel(int x, int y) { return v3((float)(x + 1), (float)(y + 1), 7.0f); }
static vec3 half_texel(int x, int y) { return (void)x, (void)y, v3s(0.5f); }

/* Goniometric and projection lights: every texel's centre direction, taken
 * to the world through the light's transform (a rotation of 90 degrees about
 * x for the goniometric light, whose square's +z is the light's +y), gives
 * that texel exactly; a projection's window (aspect 2, fov 60 across the
 * shorter side, its top row toward +y) gives nothing outside it or behind
 * the light; "power" sets the intensity to power / (4 pi mean). */
static void test_mapped_lights(void)
{
    char gp[] = "/tmp/pk_test_gonioXXXXXX", pp_[] = "/tmp/pk_test_projXXXXXX", hp[] = "/tmp/pk_test_halfXXXXXX";
    int fds[3] = {mkstemp(gp), mkstemp(pp_), mkstemp(hp)};
    REQUIRE(fds[0] >= 0 && fds[1] >= 0 && fds[2] >= 0);
    for (int i = 0; i < 3; i++) close(fds[i]);
    write_pfm(gp, 8, 8, gonio_texel);
    write_pfm(pp_, 4, 2, proj_texel);
    write_pfm(hp, 4, 4, half_texel);
    char text[1024];
    snprintf(text, sizeof text,
             PLAIN "AttributeBegin\nRotate 90 1 0 0\nLightSource \"goniometric\" \"string filename\" \"%s\"\n"
                   "AttributeEnd\nLightSource \"projection\" \"string filename\" \"%s\" \"float fov\" 60\n"
                   "LightSource \"goniometric\" \"string filename\" \"%s\" \"float power\" 10\nShape \"sphere\"\n",
             gp, pp_, hp);
    pk_context *ctx;
    pk_scene *s = load(&ctx, text);
    if (s) {
        REQUIRE(s->nlights == 3);
        const scene_view v = scene_view_of(s);
        const point_light *g = &s->lights[0], *pr = &s->lights[1], *h = &s->lights[2];
        CHECK(g->map_kind == LIGHT_MAP_GONIOMETRIC && pr->map_kind == LIGHT_MAP_PROJECTION);
        CHECK_NEAR(g->map_mean, 32.5, 1e-4);
        int wrong = 0;
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 8; x++) {
                const vec3 sq = square_to_sphere((x + 0.5) / 8.0, (y + 0.5) / 8.0);
                /* square frame (x, y, z) = light (x, z, y); the rotation takes light (x, y, z) to (x, -z, y) */
                const vec3 world = v3(sq.x, -sq.y, sq.z);
                const vec3 got = point_light_map(&v, g, world);
                if (got.x != (float)(1 + x + 8 * y) || got.y != got.x || got.z != got.x) wrong++;
            }
        CHECKF(wrong == 0, "goniometric: %d of 64 texels wrong", wrong);
        const double t = tan(M_PI / 6.0);
        wrong = 0;
        for (int y = 0; y < 2; y++)
            for (int x = 0; x < 4; x++) {
                const double px = (2.0 * (x + 0.5) / 4.0 - 1.0) * 2.0, py = (2.0 * (y + 0.5) / 2.0 - 1.0);
                const vec3 world = v3_norm(v3((float)(px * t), (float)(-py * t), 1.0f)); /* row 0 on top: +y */
                const vec3 got = point_light_map(&v, pr, world);
                if (!(got.x == (float)(x + 1) && got.y == (float)(y + 1) && got.z == 7.0f)) wrong++;
            }
        CHECKF(wrong == 0, "projection: %d of 8 texels wrong", wrong);
        CHECK(v3_max_comp(point_light_map(&v, pr, v3_norm(v3((float)(2.2 * t), 0.0f, 1.0f)))) == 0.0f);
        CHECK(v3_max_comp(point_light_map(&v, pr, v3(0.0f, 0.0f, -1.0f))) == 0.0f);
        /* the spot cone bounds the window: its corners lie just inside */
        CHECK(pr->spot_dir.z > 0.999f && fabs((double)pr->cos_outer - 1.0 / sqrt(1.0 + 5.0 * t * t)) < 2e-4);
        CHECK_NEAR(v3_luminance(h->intensity), 10.0 / (4.0 * M_PI * 0.5), 1e-3);
    }
    done(ctx, s);
    remove(gp), remove(pp_), remove(hp);
}


int main(void)
{
    test_mapped_lights();
    return test_done("test_light_maps");
}

/*
 * test_media_readers_pg.c - participating media in the pbrt-v4 reader
 * (io/scene_pbrt.c: MakeNamedMedium, MediumInterface, the camera's medium,
 * the interface material, the volpath integrator) and the glTF reader
 * (io/gltf_material.c: KHR_materials_volume): the media each file makes,
 * their grids and where they are placed, the media on the sides of each
 * surface, and the messages of bad input, each with file:line; and the
 * pbrt-v4 version of the fog scene against the JSON one.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "scene/scene.h"
#include "scene/spectra.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static warning_log warnings;

/* A camera that does not mirror (pbrt's camera x flipped), so that world
 * positions are the file's. */
#define PLAIN "Scale -1 1 1\nCamera \"perspective\"\nWorldBegin\n"
#define TRI "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"

static pk_scene *pbrt_at(pk_context **ctx, const char *text, bool commit)
{
    REQUIRE(pk_context_create(NULL, ctx) == PK_OK);
    warning_log_clear(&warnings);
    warning_log_attach(*ctx, &warnings);
    pk_scene *s = NULL;
    REQUIRE(scene_create(*ctx, "t.pbrt", &s) == PK_OK);
    pk_status st = scene_pbrt_parse(*ctx, s, text, strlen(text), "t.pbrt", PK_TEST_DATA "/media");
    if (st == PK_OK && commit) st = scene_commit(*ctx, s);
    if (st != PK_OK) {
        scene_destroy(s);
        return NULL;
    }
    return s;
}

static pk_scene *pbrt(pk_context **ctx, const char *text)
{
    pk_scene *s = pbrt_at(ctx, text, true);
    CHECKF(s != NULL, "load failed: %s", pk_context_error(*ctx));
    return s;
}

static void done(pk_context *ctx, pk_scene *s)
{
    if (s) scene_destroy(s);
    pk_context_destroy(ctx);
}

/* text must fail with a message that begins with prefix and holds part. */
static void pbrt_error(const char *text, const char *prefix, const char *part)
{
    pk_context *ctx;
    pk_scene *s = pbrt_at(&ctx, text, true);
    CHECKF(s == NULL, "loaded, expected \"%s\"", part);
    const char *m = pk_context_error(ctx);
    CHECKF(strncmp(m, prefix, strlen(prefix)) == 0 && strstr(m, part), "message \"%s\": expected %s...%s", m, prefix,
           part);
    done(ctx, s);
}

static bool near3(vec3 a, vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

static const medium *find(const pk_scene *s, const char *name)
{
    int64_t i = scene_find_medium(s, name);
    CHECKF(i >= 0, "no medium \"%s\"", name);
    return i >= 0 ? &s->media[i] : NULL;
}

static const material *tri_mat(const pk_scene *s, size_t k) { return &s->materials[s->tris[k].material]; }

/* The geometric normal of triangle k (its winding). */
static vec3 geo_normal(const pk_scene *s, size_t k)
{
    const triangle *t = &s->tris[k];
    vec3 a = s->positions[t->v[0]], b = s->positions[t->v[1]], c = s->positions[t->v[2]];
    return v3_norm(v3_cross(v3_sub(b, a), v3_sub(c, a)));
}

/* ---- pbrt-v4 ------------------------------------------------------------------------------- */

static void test_pbrt_homogeneous(void)
{
    pk_context *ctx;
    /* the camera sits in the outside medium of the MediumInterface before
     * Camera; sigma_t = (sigma_a + sigma_s) scale, albedo = sigma_s / that */
    pk_scene *s = pbrt(&ctx, "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                             "  \"rgb sigma_a\" [0.1 0.2 0.3] \"rgb sigma_s\" [0.3 0.2 0.1] \"float scale\" 2\n"
                             "  \"float g\" 0.4 \"rgb Le\" [1 2 3] \"float Lescale\" 0.5\n"
                             "MakeNamedMedium \"plain\" \"string type\" \"homogeneous\"\n"
                             "MakeNamedMedium \"skin\" \"string type\" \"homogeneous\" \"string preset\" \"Skin1\"\n"
                             "  \"float scale\" 10\n"
                             "MediumInterface \"\" \"fog\"\n"
                             "Scale -1 1 1\nCamera \"perspective\"\n"
                             "Integrator \"volpath\" \"integer maxdepth\" 7\n"
                             "WorldBegin\nLightSource \"point\"\n" TRI);
    if (s) {
        REQUIRE(s->nmedia == 3);
        const medium *f = find(s, "fog");
        CHECK(f->kind == MEDIUM_HOMOGENEOUS);
        CHECK(near3(f->sigma_t, v3(0.8f, 0.8f, 0.8f), 1e-6f));
        CHECK(near3(f->albedo, v3(0.75f, 0.5f, 0.25f), 1e-6f));
        CHECK(near3(f->le, v3(0.5f, 1.0f, 1.5f), 1e-6f));
        CHECK_NEAR(f->g, 0.4, 1e-7);
        /* pbrt's defaults: sigma_a = sigma_s = 1, no emission, isotropic */
        const medium *pl = find(s, "plain");
        CHECK(near3(pl->sigma_t, v3s(2.0f), 0) && near3(pl->albedo, v3s(0.5f), 0) && near3(pl->le, v3s(0.0f), 0) &&
              pl->g == 0.0f);
        /* Jensen et al. 2001's skin 1: sigma_s' (0.74, 0.88, 1.01), sigma_a (0.032, 0.17, 0.48) per mm */
        const medium *sk = find(s, "skin");
        CHECK(near3(sk->sigma_t, v3(7.72f, 10.5f, 14.9f), 1e-4f));
        CHECK(near3(sk->albedo, v3(0.74f / 0.772f, 0.88f / 1.05f, 1.01f / 1.49f), 1e-5f));
        CHECK(s->camera_medium == scene_find_medium(s, "fog"));
        CHECK(s->render.has_integrator && s->render.opt.integrator == PK_INTEGRATOR_VOLPATH);
        CHECK(s->render.opt.max_depth == 7);
        /* the MediumInterface stays current into the world, as in pbrt: the
         * shape bounds vacuum inside and fog outside */
        CHECK(tri_mat(s, 0)->medium_in == MEDIUM_NONE && tri_mat(s, 0)->medium_out == f - s->media);
        CHECK(scene_has_media(s));
    }
    done(ctx, s);
    /* Attribute "medium" gives defaults to the media of its block */
    s = pbrt(&ctx, PLAIN "LightSource \"point\"\n" TRI
                   "AttributeBegin\nAttribute \"medium\" \"float g\" 0.5 \"rgb sigma_s\" [2 2 2]\n"
                   "MakeNamedMedium \"a\" \"string type\" \"homogeneous\"\n"
                   "MakeNamedMedium \"b\" \"string type\" \"homogeneous\" \"float g\" -0.5\nAttributeEnd\n"
                   "MakeNamedMedium \"c\" \"string type\" \"homogeneous\"\n");
    if (s) {
        CHECK(find(s, "a")->g == 0.5f && near3(find(s, "a")->sigma_t, v3s(3.0f), 0));
        CHECK(find(s, "b")->g == -0.5f && find(s, "c")->g == 0.0f && near3(find(s, "c")->sigma_t, v3s(2.0f), 0));
    }
    done(ctx, s);
    /* a MediumInterface after Camera leaves the camera in vacuum */
    s = pbrt(&ctx, "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                   "Camera \"perspective\"\nMediumInterface \"fog\" \"fog\"\nWorldBegin\n"
                   "LightSource \"point\"\n" TRI);
    if (s) CHECK(s->camera_medium == MEDIUM_NONE);
    done(ctx, s);
}

static void test_pbrt_sides(void)
{
    pk_context *ctx;
    /* a triangle in z = 0 wound counter-clockwise seen from +z: pbrt's normal
     * (the outside) is +z */
    pk_scene *s = pbrt(&ctx, PLAIN
                       "MakeNamedMedium \"in\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [1 1 1]\n"
                       "MakeNamedMedium \"out\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [2 2 2]\n"
                       "LightSource \"point\"\n"
                       "AttributeBegin\n"
                       "  MediumInterface \"in\" \"out\"\n"
                       "  Material \"interface\"\n" TRI
                       "  Material \"dielectric\"\n" TRI
                       "  ReverseOrientation\n" TRI
                       "  MediumInterface \"in\"\n" TRI
                       "  MediumInterface \"in\" \"\"\n"
                       "  AreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\n" TRI
                       "AttributeEnd\n" TRI
                       "AttributeBegin\n"
                       "  MediumInterface \"in\" \"out\"\n"
                       "  Material \"diffuse\"\n"
                       "  Shape \"sphere\" \"float radius\" 2\n"
                       "  MediumInterface \"out\"\n"
                       "  Material \"interface\"\n"
                       "  Shape \"sphere\" \"float radius\" 3\n" /* no transition: left out */
                       "AttributeEnd\n");
    if (s) {
        const int32_t in = (int32_t)scene_find_medium(s, "in"), out = (int32_t)scene_find_medium(s, "out");
        REQUIRE(s->ntris == 6 && s->nspheres == 1);
        /* the interface: index-matched, inside and outside as named, and the
         * winding's normal points outside */
        CHECK(tri_mat(s, 0)->type == MAT_INTERFACE);
        CHECK(tri_mat(s, 0)->medium_in == in && tri_mat(s, 0)->medium_out == out);
        CHECK(near3(geo_normal(s, 0), v3(0, 0, 1), 1e-6f));
        CHECK(tri_mat(s, 1)->type == MAT_DIELECTRIC && tri_mat(s, 1)->medium_in == in &&
              tri_mat(s, 1)->medium_out == out);
        /* ReverseOrientation turns pbrt's normal, and with it the sides */
        CHECK(near3(geo_normal(s, 2), v3(0, 0, -1), 1e-6f) && tri_mat(s, 2)->medium_out == out);
        /* one name: no transition, the ray keeps its medium */
        CHECK(tri_mat(s, 3)->medium_in == MEDIUM_INHERIT && tri_mat(s, 3)->medium_out == MEDIUM_INHERIT);
        /* "" is vacuum; an area light keeps its emission and gets the media */
        CHECK(tri_mat(s, 4)->medium_in == in && tri_mat(s, 4)->medium_out == MEDIUM_NONE);
        CHECK(near3(tri_mat(s, 4)->ke, v3s(4.0f), 0));
        /* AttributeEnd restores the interface */
        CHECK(tri_mat(s, 5)->medium_in == MEDIUM_INHERIT && tri_mat(s, 5)->medium_out == MEDIUM_INHERIT);
        const material *sm = &s->materials[s->spheres[0].material];
        CHECK(sm->type == MAT_DIFFUSE && sm->medium_in == in && sm->medium_out == out && s->spheres[0].radius == 2.0f);
        /* the materials themselves are untouched: a copy carries the media */
        CHECK(s->materials[0].medium_in == MEDIUM_INHERIT);
    }
    done(ctx, s);
}

/* The world point of grid point q of medium m. */
static vec3 grid_point(const medium *m, vec3 q) { return xform_point(&m->grid_to_world, q); }

static void test_pbrt_grids(void)
{
    pk_context *ctx;
    /* uniformgrid: 2 x 2 x 1 voxels in the box (1,2,3)..(3,3,5), translated
     * by (10, 0, 0) */
    pk_scene *s = pbrt(&ctx, PLAIN
                       "AttributeBegin\nTranslate 10 0 0\n"
                       "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\"\n"
                       "  \"integer nx\" 2 \"integer ny\" 2 \"integer nz\" 1\n"
                       "  \"float density\" [0 1 2 3] \"point3 p0\" [1 2 3] \"point3 p1\" [3 3 5]\n"
                       "  \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [3 3 3] \"float scale\" 0.5\n"
                       "  \"rgb Le\" [1 0.5 0.25] \"float Lescale\" [1 2 3 4]\n"
                       "AttributeEnd\n"
                       "MakeNamedMedium \"tint\" \"string type\" \"rgbgrid\"\n"
                       "  \"integer nx\" 2\n"
                       "  \"rgb sigma_a\" [1 2 3  0 0 0] \"rgb sigma_s\" [1 2 1  4 0 2] \"float scale\" 3\n"
                       "  \"rgb Le\" [1 1 1  2 2 2] \"float Lescale\" 5\n"
                       "MakeNamedMedium \"half\" \"string type\" \"rgbgrid\" \"rgb sigma_s\" [0.5 0.5 0.5]\n"
                       "LightSource \"point\"\n" TRI);
    if (s) {
        const medium *m = find(s, "smoke");
        REQUIRE(m->kind == MEDIUM_GRID && m->density.data);
        CHECK(m->density.nx == 2 && m->density.ny == 2 && m->density.nz == 1 && m->density.channels == 1);
        for (int i = 0; i < 4; i++) CHECK(m->density.data[i] == (float)i);
        CHECK(near3(m->sigma_t, v3s(2.0f), 0) && near3(m->albedo, v3s(0.75f), 0));
        CHECK(near3(m->le, v3(1.0f, 0.5f, 0.25f), 0));
        REQUIRE(m->emission_grid.data && m->emission_grid.channels == 1);
        CHECK(m->emission_grid.data[3] == 4.0f);
        /* the box: the unit cube's corners go to p0 and p1, moved by the CTM */
        CHECK(near3(grid_point(m, v3s(0.0f)), v3(11, 2, 3), 1e-5f));
        CHECK(near3(grid_point(m, v3s(1.0f)), v3(13, 3, 5), 1e-5f));
        /* voxel (1, 0, 0)'s centre holds its value: cell-centred, as pbrt's SampledGrid */
        medium_point mp = medium_at(m, v3(12.5f, 2.25f, 4.0f));
        CHECK(near3(v3_add(mp.sigma_a, mp.sigma_s), v3s(2.0f), 1e-5f));
        CHECK(near3(mp.sigma_s, v3s(1.5f), 1e-5f));
        mp = medium_at(m, v3(11.5f, 2.75f, 4.0f)); /* voxel (0, 1, 0): density 2 */
        CHECK(near3(v3_add(mp.sigma_a, mp.sigma_s), v3s(4.0f), 1e-5f));
        CHECK(near3(mp.le, v3(3.0f, 1.5f, 0.75f), 1e-5f));
        /* outside the box: nothing */
        mp = medium_at(m, v3(1.0f, 2.5f, 4.0f));
        CHECK(near3(mp.sigma_s, v3s(0.0f), 0));

        /* rgbgrid: density = sigma_a + sigma_s per channel, under sigma_t = scale;
         * the albedo grid sigma_s / (sigma_a + sigma_s) */
        const medium *t = find(s, "tint");
        REQUIRE(t->kind == MEDIUM_GRID && t->density.channels == 3 && t->albedo_grid.data);
        const float dens[6] = {2, 4, 4, 4, 0, 2}, alb[6] = {0.5f, 0.5f, 0.25f, 1, 0, 1};
        for (int i = 0; i < 6; i++) {
            CHECK_NEAR(t->density.data[i], dens[i], 1e-6);
            CHECK_NEAR(t->albedo_grid.data[i], alb[i], 1e-6);
        }
        CHECK(near3(t->sigma_t, v3s(3.0f), 0) && near3(t->albedo, v3s(1.0f), 0) && near3(t->le, v3s(5.0f), 0));
        REQUIRE(t->emission_grid.data && t->emission_grid.channels == 3);
        CHECK(t->emission_grid.data[3] == 2.0f);
        /* at voxel 0's centre: sigma_a (1 2 3) x 3, sigma_s (1 2 1) x 3, Le 5 */
        medium_point tp = medium_at(t, v3(0.25f, 0.5f, 0.5f));
        CHECK(near3(tp.sigma_a, v3(3, 6, 9), 1e-5f) && near3(tp.sigma_s, v3(3, 6, 3), 1e-5f));
        CHECK(near3(tp.le, v3s(5.0f), 1e-6f));
        /* an absent grid is 1 everywhere */
        const medium *h = find(s, "half");
        REQUIRE(h->kind == MEDIUM_GRID && h->density.nx == 1);
        CHECK(near3(v3(h->density.data[0], h->density.data[1], h->density.data[2]), v3s(1.5f), 1e-6f));
        CHECK_NEAR(h->albedo_grid.data[0], 1.0 / 3.0, 1e-6);
        CHECK(near3(h->le, v3s(0.0f), 0));
    }
    done(ctx, s);

    /* pbrt's usual left-handed camera mirrors the world: the grid is mirrored
     * with the shapes (a vertex at the box's corner lands on its corner) */
    s = pbrt(&ctx, "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\"\n"
                   "Translate 0.5 0.25 0\n"
                   "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" \"float density\" [1]\n"
                   "  \"point3 p0\" [1 2 3] \"point3 p1\" [2 4 4]\n"
                   "Shape \"trianglemesh\" \"point3 P\" [1 2 3 2 4 4 2 2 3]\n");
    if (s) {
        const medium *m = find(s, "g");
        const vec3 c0 = grid_point(m, v3s(0.0f)), c1 = grid_point(m, v3s(1.0f));
        CHECK(near3(c0, s->positions[s->tris[0].v[0]], 1e-5f) || near3(c0, s->positions[s->tris[0].v[1]], 1e-5f) ||
              near3(c0, s->positions[s->tris[0].v[2]], 1e-5f));
        CHECK(near3(c1, s->positions[s->tris[0].v[0]], 1e-5f) || near3(c1, s->positions[s->tris[0].v[1]], 1e-5f) ||
              near3(c1, s->positions[s->tris[0].v[2]], 1e-5f));
        CHECK(fabsf(c0.x + 1.5f) < 1e-5f); /* mirrored across x = 0 */
        CHECK(xform_det3(&m->grid_to_world) < 0.0); /* the mirror is part of the placement */
    }
    done(ctx, s);
}

static double planck_nm(double kelvin, double nm)
{
    const double h = 6.62607015e-34, c = 2.99792458e8, kb = 1.380649e-23, l = nm * 1e-9;
    return 2 * h * c * c / (l * l * l * l * l) / (exp(h * c / (l * kb * kelvin)) - 1);
}

/* pbrt's blackbody at kelvin, 1 at its peak (Wien's displacement law), as
 * linear sRGB of what pbrt's sensor records (X, Y, Z: the CIE 1931
 * functions integrated at every nanometre, not normalised), colours
 * outside sRGB clipped at 0. */
static vec3 blackbody_closed_form(double kelvin)
{
    const double peak = planck_nm(kelvin, 2.8977721e6 / kelvin);
    double X = 0, Y = 0, Z = 0;
    for (int nm = 360; nm <= 830; nm++) {
        const double b = planck_nm(kelvin, nm) / peak;
        float xyz[3];
        spectra_cie1931((float)nm, xyz);
        X += b * (double)xyz[0], Y += b * (double)xyz[1], Z += b * (double)xyz[2];
    }
    return v3((float)fmax(0.0, 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z),
              (float)fmax(0.0, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z),
              (float)fmax(0.0, 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z));
}

static void test_pbrt_temperature(void)
{
    pk_context *ctx;
    pk_scene *s = pbrt(&ctx, PLAIN "LightSource \"point\"\n" TRI
                       "MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"integer nx\" 3\n"
                       "  \"float density\" [1 1 1] \"float temperature\" [50 3250 6500] \"float Lescale\" [1 1 0.5]\n"
                       "  \"float temperaturescale\" 2 \"float temperatureoffset\" 3000\n"
                       "MakeNamedMedium \"ember\" \"string type\" \"uniformgrid\" \"float density\" [1]\n"
                       "  \"float temperature\" [1500] \"float Lescale\" 3\n");
    if (s) {
        /* (T - 3000) x 2: none (below 100 K), 500 K, 7000 K x 0.5 */
        const medium *m = find(s, "fire");
        REQUIRE(m->emission_grid.data && m->emission_grid.channels == 3 && m->emission_grid.nx == 3);
        const float *e = m->emission_grid.data;
        CHECK(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
        const vec3 want1 = blackbody_closed_form(500.0), want2 = v3_scale(blackbody_closed_form(7000.0), 0.5f);
        CHECKF(near3(v3(e[3], e[4], e[5]), want1, 2e-3f * v3_max_comp(want1) + 1e-12f), "%g %g %g vs %g %g %g", (double)e[3],
               (double)e[4], (double)e[5], (double)want1.x, (double)want1.y, (double)want1.z);
        CHECKF(near3(v3(e[6], e[7], e[8]), want2, 2e-3f * v3_max_comp(want2)), "%g %g %g vs %g %g %g", (double)e[6], (double)e[7],
               (double)e[8], (double)want2.x, (double)want2.y, (double)want2.z);
        CHECK(near3(m->le, v3s(1.0f), 0));
        /* a 7000 K blackbody is bluish white and bright in pbrt's units (its
         * spectrum is 1 at its peak, near 414 nm) */
        CHECK(want2.z > want2.x && want2.y > 20.0f);
        const medium *em = find(s, "ember");
        const vec3 w3 = v3_scale(blackbody_closed_form(1500.0), 3.0f);
        CHECK(near3(v3(em->emission_grid.data[0], em->emission_grid.data[1], em->emission_grid.data[2]), w3,
                    2e-3f * v3_max_comp(w3)));
    }
    done(ctx, s);
}

/* pbrt-v4's cloud, baked: the grid's size follows the frequency and the
 * box, and the density follows pbrt's profile in height: full below y = 0
 * (the filling term 2 (1/2 - y) >= 1 there), noise in 0..1 above. */
static void test_pbrt_cloud(void)
{
    pk_context *ctx;
    pk_scene *s = pbrt(&ctx, PLAIN "LightSource \"point\"\n" TRI
                       "MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float frequency\" 1\n"
                       "  \"point3 p0\" [0 -0.5 0] \"point3 p1\" [1 1.5 0.5] \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [3 3 3]\n"
                       "MakeNamedMedium \"calm\" \"string type\" \"cloud\" \"float frequency\" 1 \"float wispiness\" 0\n"
                       "  \"point3 p0\" [0 -0.5 0] \"point3 p1\" [1 1.5 0.5]\n");
    if (s) {
        const medium *m = find(s, "c"), *calm = find(s, "calm");
        REQUIRE(m->kind == MEDIUM_GRID && m->density.channels == 1);
        CHECK(m->density.nx == 24 && m->density.ny == 48 && m->density.nz == 16);
        CHECK(near3(m->sigma_t, v3s(4.0f), 0) && near3(m->albedo, v3s(0.75f), 0));
        CHECK(near3(grid_point(m, v3s(0.0f)), v3(0, -0.5f, 0), 1e-6f) && near3(grid_point(m, v3s(1.0f)), v3(1, 1.5f, 0.5f), 1e-6f));
        int low = 0, high = 0, mid = 0, varied = 0, differs = 0;
        float first = -1.0f;
        const medium_grid *g = &m->density;
        for (int k = 0; k < g->nz; k++)
            for (int j = 0; j < g->ny; j++)
                for (int i = 0; i < g->nx; i++) {
                    const size_t v = ((size_t)k * (size_t)g->ny + (size_t)j) * (size_t)g->nx + (size_t)i;
                    const float d = g->data[v], y = -0.5f + 2.0f * ((float)j + 0.5f) / (float)g->ny;
                    if (y < 0.0f) low += d == 1.0f;
                    else {
                        high += y > 1.0f && d > 0.0f && d < 1.0f;
                        mid += d >= 0.0f && d <= 1.0f;
                        if (first < 0.0f) first = d;
                        varied += d != first;
                        differs += d != calm->density.data[v];
                    }
                }
        const int layer = g->nx * g->nz;
        CHECK(low == 12 * layer && mid == 36 * layer && high > 0);
        CHECKF(varied > layer && differs > layer, "varied %d, differs %d", varied, differs);
    }
    done(ctx, s);
}

static void test_pbrt_errors(void)
{
    const char *hom = "MakeNamedMedium \"m\" \"string type\" \"homogeneous\"\n";
    pbrt_error("WorldBegin\n\nMakeNamedMedium \"m\" \"string type\" \"fog\"\n", "t.pbrt:3: ",
               "unknown medium type \"fog\"");
    pbrt_error("WorldBegin\nMakeNamedMedium \"m\"\n", "t.pbrt:2: ", "needs 'string type'");
    char text[1024];
    snprintf(text, sizeof text, "%s%s", hom, hom);
    pbrt_error(text, "t.pbrt:2: ", "defined already");
    pbrt_error(PLAIN "MediumInterface \"nope\" \"\"\n\n" TRI, "t.pbrt:6: Shape: ", "no medium \"nope\"");
    pbrt_error("MediumInterface \"\" \"nope\"\nCamera \"perspective\"\nWorldBegin\n", "t.pbrt:2: ",
               "the camera's medium \"nope\"");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [1 -1 1]\n", "t.pbrt:1: ",
               "must be finite and >= 0");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" 1\n", "t.pbrt:1: ",
               "'float g' 1 must lie in");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float scale\" -2\n", "t.pbrt:1: ",
               "'float scale' -2 must lie in");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"string preset\" \"Mud\"\n", "t.pbrt:1: ",
               "preset \"Mud\" is not known");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 2\n"
               "  \"float density\" [1 2 3]\n",
               "t.pbrt:2: ", "'float density' has 3 values; nx x ny x nz = 2 x 1 x 1 needs 2");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [-1]\n", "t.pbrt:1: ",
               "value 0 is -1 (values must be finite and >= 0)");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n", "t.pbrt:1: ", "needs 'float density'");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 0 \"float density\" [1]\n",
               "t.pbrt:1: ", "'integer nx' 0 is outside");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 100000 \"integer ny\" 100000\n"
               "  \"float density\" [1]\n",
               "t.pbrt:1: ", "over the limit");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1]\n"
               "  \"point3 p0\" [0 0 0] \"point3 p1\" [1 0 1]\n",
               "t.pbrt:1: ", "has no volume");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1]\n"
               "  \"float temperature\" [1000 2000]\n",
               "t.pbrt:2: ", "'float temperature' has 2 values");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1]\n"
               "  \"float temperature\" [1000] \"rgb Le\" [1 1 1]\n",
               "t.pbrt:2: ", "give 'Le' or 'temperature', not both");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1 1]\n"
               "  \"rgb Le\" [1 1 1] \"float Lescale\" [1 2 3]\n",
               "t.pbrt:2: ", "'float Lescale' has 3 values");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"rgbgrid\"\n", "t.pbrt:1: ", "needs 'rgb sigma_a' and/or");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"rgbgrid\" \"rgb sigma_s\" [1 1 1]\n\"rgb Le\" [1 1 1]\n",
               "t.pbrt:2: ", "'rgb Le' needs 'rgb sigma_a'");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"rgbgrid\" \"integer nz\" 2 \"rgb sigma_a\" [1 1 1]\n",
               "t.pbrt:1: ", "'rgb sigma_a' has 3 values; nx x ny x nz = 1 x 1 x 2 needs 6 (3 a voxel)");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"cloud\" \"float wispiness\" -1\n", "t.pbrt:1: ",
               "'float wispiness' -1 must lie in");
    /* a grid file that cannot be read: the grid reader's message, after where */
    pbrt_error("\nMakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"no_such.nvdb\"\n",
               "t.pbrt:2: MakeNamedMedium \"m\": ", "no_such.nvdb");
    pbrt_error("MakeNamedMedium \"m\" \"string type\" \"nanovdb\"\n", "t.pbrt:1: ", "needs 'string filename'");
}


/* ---- glTF ---------------------------------------------------------------------------------- */

/* A tetrahedron (outward windings) as a data: URI: 4 positions then 12
 * indices (uint16). */
static char *tetra_uri(void)
{
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint16_t idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    uint8_t raw[72];
    memcpy(raw, pos, 48);
    memcpy(raw + 48, idx, 24);
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *o = malloc(256), *q = o;
    q += sprintf(q, "data:application/octet-stream;base64,");
    for (size_t i = 0; i < sizeof raw; i += 3) {
        uint32_t w = (uint32_t)raw[i] << 16 | (uint32_t)raw[i + 1] << 8 | raw[i + 2];
        for (int k = 3; k >= 0; k--) *q++ = al[w >> (6 * k) & 63];
    }
    *q = '\0';
    return o;
}

/* A glTF document of one tetrahedron per material (materials: the JSON
 * array's body). */
static char *gltf_doc(const char *materials, int nmat)
{
    char *uri = tetra_uri(), prims[1024] = "";
    for (int i = 0; i < nmat; i++)
        snprintf(prims + strlen(prims), sizeof prims - strlen(prims),
                 "%s{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":%d}", i ? "," : "", i);
    size_t n = strlen(uri) + strlen(materials) + strlen(prims) + 1024;
    char *j = malloc(n);
    snprintf(j, n,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"extensionsUsed\":[\"KHR_materials_volume\",\"KHR_materials_transmission\",\"KHR_materials_ior\"],"
             "\"buffers\":[{\"byteLength\":72,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":24}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,1]},{\"bufferView\":1,\"componentType\":5123,\"count\":12,\"type\":\"SCALAR\"}],"
             "\"materials\":[%s],\"meshes\":[{\"primitives\":[%s]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
             uri, materials, prims);
    free(uri);
    return j;
}

static pk_scene *gltf_at(pk_context **ctx, const char *materials, int nmat)
{
    REQUIRE(pk_context_create(NULL, ctx) == PK_OK);
    warning_log_clear(&warnings);
    warning_log_attach(*ctx, &warnings);
    pk_scene *s = NULL;
    REQUIRE(scene_create(*ctx, "t.gltf", &s) == PK_OK);
    char *j = gltf_doc(materials, nmat);
    pk_status st = scene_gltf_parse(*ctx, s, j, strlen(j), "t.gltf", ".");
    free(j);
    if (st == PK_OK) st = scene_commit(*ctx, s);
    if (st != PK_OK) {
        scene_destroy(s);
        return NULL;
    }
    return s;
}

#define VOL(t, d, c) "\"KHR_materials_volume\":{\"thicknessFactor\":" t d c "}"

static void test_gltf_volume(void)
{
    pk_context *ctx;
    pk_scene *s = gltf_at(
        &ctx,
        /* 0: clear glass with an absorbing inside */
        "{\"name\":\"glass\",\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0.2,"
        "\"baseColorFactor\":[1,0.9,0.8,1]},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
        "\"KHR_materials_ior\":{\"ior\":1.4}," VOL("1", ",\"attenuationDistance\":2", ",\"attenuationColor\":[0.5,0.25,1]") "}},"
        /* 1: half transmissive: the metallic-roughness BSDF whose transmission refracts, the inside absorbs */
        "{\"pbrMetallicRoughness\":{\"metallicFactor\":0},\"extensions\":{\"KHR_materials_transmission\":"
        "{\"transmissionFactor\":0.5}," VOL("0.5", ",\"attenuationDistance\":1", ",\"attenuationColor\":[0.5,0.5,0.5]") "}},"
        /* 2: thin-walled (thickness 0): no volume */
        "{\"pbrMetallicRoughness\":{\"metallicFactor\":0},\"extensions\":{\"KHR_materials_transmission\":"
        "{\"transmissionFactor\":1}," VOL("0", ",\"attenuationDistance\":1", "") "}},"
        /* 3: a volume that absorbs nothing (infinite distance): refracts, no medium */
        "{\"pbrMetallicRoughness\":{\"metallicFactor\":0},\"extensions\":{\"KHR_materials_transmission\":"
        "{\"transmissionFactor\":1}," VOL("1", "", ",\"attenuationColor\":[0.5,0.5,0.5]") "}},"
        /* 4: no transmission: the volume has nothing to say */
        "{\"extensions\":{" VOL("1", ",\"attenuationDistance\":1", "") "}}",
        5);
    CHECKF(s != NULL, "load failed: %s", pk_context_error(ctx));
    if (s) {
        REQUIRE(s->ntris == 20 && s->nmedia == 2);
        const material *m0 = tri_mat(s, 0);
        CHECK(m0->type == MAT_DIELECTRIC && fabsf(m0->ni - 1.4f) < 1e-6f && fabsf(m0->alpha - 0.04f) < 1e-6f);
        CHECK(near3(m0->tf, v3(1.0f, 0.9f, 0.8f), 1e-6f));
        REQUIRE(m0->medium_in >= 0);
        CHECK(m0->medium_out == MEDIUM_NONE);
        const medium *v = &s->media[m0->medium_in];
        /* sigma_a = -ln(colour) / distance: the colour is what is left after the distance */
        CHECK(v->kind == MEDIUM_HOMOGENEOUS && near3(v->sigma_t, v3(logf(2.0f) / 2, logf(4.0f) / 2, 0.0f), 1e-6f));
        CHECK(near3(v->albedo, v3s(0.0f), 0) && near3(v->le, v3s(0.0f), 0));
        CHECK(fabsf(expf(-v->sigma_t.y * 2.0f) - 0.25f) < 1e-6f);
        /* the medium is inside: every triangle's normal points away from the centroid */
        const vec3 c = v3s(0.25f);
        for (size_t k = 0; k < 4; k++) {
            const triangle *t = &s->tris[k];
            vec3 tc = v3_scale(v3_add(v3_add(s->positions[t->v[0]], s->positions[t->v[1]]), s->positions[t->v[2]]),
                               1.0f / 3.0f);
            CHECK(v3_dot(geo_normal(s, k), v3_sub(tc, c)) > 0.0f);
        }
        const material *m1 = tri_mat(s, 4);
        CHECK(m1->type == MAT_METALLIC_ROUGHNESS && m1->transmission == 0.5f);
        REQUIRE(m1->medium_in >= 0);
        CHECK(near3(s->media[m1->medium_in].sigma_t, v3s(logf(2.0f)), 1e-6f) && m1->medium_out == MEDIUM_NONE);
        CHECK(m1->volume && !warning_log_has(&warnings, "does not refract"));
        const material *m2 = tri_mat(s, 8);
        CHECK(m2->type == MAT_METALLIC_ROUGHNESS && m2->medium_in == MEDIUM_INHERIT && m2->medium_out == MEDIUM_INHERIT);
        CHECK(!m2->volume);
        const material *m3 = tri_mat(s, 12);
        CHECK(m3->type == MAT_DIELECTRIC && fabsf(m3->ni - 1.5f) < 1e-6f && m3->medium_in == MEDIUM_INHERIT);
        const material *m4 = tri_mat(s, 16);
        CHECK(m4->type == MAT_METALLIC_ROUGHNESS && m4->medium_in == MEDIUM_INHERIT);
    }
    done(ctx, s);
    /* hostile values */
    static const struct {
        const char *mat, *part;
    } bad[] = {
        {"{\"extensions\":{" VOL("1", ",\"attenuationDistance\":0", "") "}}",
         "t.gltf: /materials/0/extensions/KHR_materials_volume/attenuationDistance: 0 must be greater than 0"},
        {"{\"extensions\":{" VOL("1", ",\"attenuationDistance\":-1", "") "}}", "attenuationDistance"},
        {"{\"extensions\":{" VOL("1", "", ",\"attenuationColor\":[1,1.5,1]") "}}",
         "KHR_materials_volume/attenuationColor: 1.5 is outside [0, 1]"},
        {"{\"extensions\":{" VOL("1", "", ",\"attenuationColor\":[1,1]") "}}", "attenuationColor"},
        {"{\"extensions\":{" VOL("-1", "", "") "}}", "thicknessFactor"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        s = gltf_at(&ctx, bad[i].mat, 1);
        CHECKF(s == NULL && strstr(pk_context_error(ctx), bad[i].part), "case %zu: \"%s\"", i, pk_context_error(ctx));
        done(ctx, s);
    }
}


/* ---- the fog scene: pbrt-v4 against JSON ---------------------------------------------------- */

typedef pk_status (*parse_fn)(pk_context *, pk_scene *, const char *, size_t, const char *, const char *);

static pk_status parse_pbrt(pk_context *c, pk_scene *s, const char *d, size_t n, const char *name, const char *dir)
{
    return scene_pbrt_parse(c, s, d, n, name, dir);
}

/* tests/data/media/file, parsed and committed. */
static pk_scene *load_file(pk_context **ctx, const char *file, parse_fn parse)
{
    REQUIRE(pk_context_create(NULL, ctx) == PK_OK);
    warning_log_clear(&warnings);
    warning_log_attach(*ctx, &warnings);
    char path[512];
    snprintf(path, sizeof path, "%s/media/%s", PK_TEST_DATA, file);
    char *data = NULL;
    size_t size = 0;
    REQUIRE(file_read_all(*ctx, path, &data, &size) == PK_OK);
    pk_scene *s = NULL;
    REQUIRE(scene_create(*ctx, file, &s) == PK_OK);
    pk_status st = parse(*ctx, s, data, size, file, PK_TEST_DATA "/media");
    free(data);
    if (st == PK_OK) st = scene_commit(*ctx, s);
    CHECKF(st == PK_OK, "%s: %s", file, pk_context_error(*ctx));
    if (st != PK_OK) {
        scene_destroy(s);
        return NULL;
    }
    return s;
}

static bool close3(vec3 a, vec3 b) { return near3(a, b, 1e-5f * fmaxf(1.0f, fmaxf(v3_max_comp(a), v3_max_comp(b)))); }

/* The name of medium index i of s, "(vacuum)" or "(inherit)". */
static const char *med_name(const pk_scene *s, int32_t i)
{
    if (i == MEDIUM_NONE) return "(vacuum)";
    if (i == MEDIUM_INHERIT) return "(inherit)";
    return i >= 0 && (size_t)i < s->nmedia && s->media[i].name ? s->media[i].name : "(bad)";
}

/* Whether materials a (of scene sa) and b (of sb) describe the same surface. */
static bool same_material(const pk_scene *sa, const material *a, const pk_scene *sb, const material *b)
{
    if (a->type != b->type || !close3(a->ke, b->ke) || strcmp(med_name(sa, a->medium_in), med_name(sb, b->medium_in)) ||
        strcmp(med_name(sa, a->medium_out), med_name(sb, b->medium_out)))
        return false;
    if (a->type == MAT_DIFFUSE) return close3(a->kd, b->kd);
    if (a->type == MAT_DIELECTRIC) return fabsf(a->ni - b->ni) < 1e-6f && a->alpha == b->alpha && close3(a->tf, b->tf);
    return true;
}

/* The triangle of s with the corners of triangle t of r (in any rotation,
 * the same winding), or -1. */
static int64_t match_tri(const pk_scene *s, const pk_scene *r, const triangle *t)
{
    for (size_t k = 0; k < s->ntris; k++)
        for (int rot = 0; rot < 3; rot++) {
            bool same = true;
            for (int c = 0; c < 3 && same; c++)
                same = near3(s->positions[s->tris[k].v[(c + rot) % 3]], r->positions[t->v[c]], 1e-6f);
            if (same) return (int64_t)k;
        }
    return -1;
}

static void test_fog_scene(void)
{
    pk_context *cj, *cp;
    pk_scene *p = load_file(&cp, "fog.pbrt", parse_pbrt);
    if (p) { /* the scene on its own: the media of fog.json's numbers */
        REQUIRE(p->nmedia == 3);
        const medium *fog = find(p, "fog"), *milk = find(p, "milk"), *smoke = find(p, "smoke");
        CHECK(fog->sigma_t.x == 0.125f && close3(fog->sigma_t, v3s(0.125f)) && close3(fog->albedo, v3s(0.75f)) &&
              fabsf(fog->g - 0.3f) < 1e-7f);
        CHECK(close3(milk->sigma_t, v3(12, 14, 16)) && close3(milk->albedo, v3(0.999f, 0.998f, 0.995f)));
        CHECK(smoke->kind == MEDIUM_GRID && close3(smoke->sigma_t, v3s(2.0f)) && close3(smoke->albedo, v3s(0.9f)));
        CHECK(p->camera_medium == fog - p->media);
        CHECK(p->ntris == 2 * (3 + 1 + 1 + 1 + 6) && p->nspheres == 1);
        const material *sm = &p->materials[p->spheres[0].material];
        CHECK(sm->type == MAT_DIELECTRIC && sm->medium_in == milk - p->media && sm->medium_out == fog - p->media);
    }
    char path[512];
    snprintf(path, sizeof path, "%s/media/fog.json", PK_TEST_DATA);
    pk_scene *j = NULL;
    cj = NULL;
    if (access(path, R_OK) == 0) j = load_file(&cj, "fog.json", scene_json_parse);
    else fprintf(stderr, "note: %s is not there: fog.pbrt is not compared with it\n", path);
    if (j && p) {
        /* the same media */
        REQUIRE(j->nmedia == p->nmedia);
        for (size_t i = 0; i < j->nmedia; i++) {
            const medium *a = &j->media[i], *b = find(p, a->name);
            if (!b) continue;
            CHECKF(a->kind == b->kind && close3(a->sigma_t, b->sigma_t) && close3(a->albedo, b->albedo) &&
                       close3(a->le, b->le) && fabsf(a->g - b->g) < 1e-6f,
                   "medium %s differs", a->name);
            if (a->kind != MEDIUM_GRID || b->kind != MEDIUM_GRID) continue;
            const medium_grid *ga = &a->density, *gb = &b->density;
            REQUIRE(ga->nx == gb->nx && ga->ny == gb->ny && ga->nz == gb->nz && ga->channels == gb->channels);
            CHECK(memcmp(ga->data, gb->data, (size_t)ga->nx * ga->ny * ga->nz * ga->channels * sizeof(float)) == 0);
            CHECK(!a->albedo_grid.data && !b->albedo_grid.data && !a->emission_grid.data && !b->emission_grid.data);
            for (int c = 0; c < 8; c++) {
                const vec3 q = v3((float)(c & 1), (float)(c >> 1 & 1), (float)(c >> 2 & 1));
                CHECKF(close3(grid_point(a, q), grid_point(b, q)), "medium %s: grid corner %d placed elsewhere", a->name, c);
            }
        }
        CHECK(j->camera_medium >= 0 && strcmp(med_name(j, j->camera_medium), med_name(p, p->camera_medium)) == 0);
        /* the same surfaces, facing the same way, with the same materials and media */
        REQUIRE(j->ntris == p->ntris && j->nspheres == p->nspheres);
        for (size_t k = 0; k < j->ntris; k++) {
            int64_t m = match_tri(p, j, &j->tris[k]);
            CHECKF(m >= 0, "triangle %zu of fog.json is not in fog.pbrt (or faces the other way)", k);
            if (m < 0) continue;
            CHECKF(same_material(j, tri_mat(j, k), p, tri_mat(p, (size_t)m)), "triangle %zu: materials differ", k);
        }
        for (size_t k = 0; k < j->nspheres; k++) {
            const sphere *a = &j->spheres[k], *b = &p->spheres[k];
            CHECK(close3(a->center, b->center) && fabsf(a->radius - b->radius) < 1e-6f);
            CHECK(same_material(j, &j->materials[a->material], p, &p->materials[b->material]));
        }
        /* the same camera and settings */
        for (int c = 0; c < 3; c++) CHECK(fabsf(j->camera.look_from[c] - p->camera.look_from[c]) < 1e-5f);
        vec3 dj = v3_norm(v3_sub(v3(j->camera.look_at[0], j->camera.look_at[1], j->camera.look_at[2]),
                                 v3(j->camera.look_from[0], j->camera.look_from[1], j->camera.look_from[2])));
        vec3 dp = v3_norm(v3_sub(v3(p->camera.look_at[0], p->camera.look_at[1], p->camera.look_at[2]),
                                 v3(p->camera.look_from[0], p->camera.look_from[1], p->camera.look_from[2])));
        CHECK(near3(dj, dp, 1e-6f) && fabsf(j->camera.fov_deg - p->camera.fov_deg) < 1e-4f);
        CHECK(j->render.opt.integrator == PK_INTEGRATOR_VOLPATH && p->render.opt.integrator == PK_INTEGRATOR_VOLPATH);
        CHECK(j->render.opt.max_depth == p->render.opt.max_depth && j->render.opt.spp == p->render.opt.spp);
        CHECK(j->render.opt.width == p->render.opt.width && j->render.opt.height == p->render.opt.height);
    }
    if (cj) done(cj, j);
    done(cp, p);
}

int main(void)
{
    test_pbrt_homogeneous();
    test_pbrt_sides();
    test_pbrt_grids();
    test_pbrt_temperature();
    test_pbrt_cloud();
    test_pbrt_errors();
    test_gltf_volume();
    test_fog_scene();
    return test_done("test_media_readers_pg");
}

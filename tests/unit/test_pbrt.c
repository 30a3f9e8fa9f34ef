/*
 * test_pbrt.c - the pbrt-v4 reader (io/scene_pbrt.c, io/pbrt_tok.c): the
 * tokenizer (strings and escapes, numbers, brackets, comments, lines), and
 * each family of directives against what it must put in the scene:
 * transforms, the camera (pbrt's shorter-axis fov, the world mirrored for
 * pbrt's left-handed camera, lens and orthographic), film/sampler/
 * integrator settings, materials, lights, shapes (Loop subdivision against
 * positions worked out by hand), objects and instances, includes; and the
 * messages of bad input, each with file:line.
 */
#include "test.h"
#include "test_rng.h"
#include "warnings.h"

#include "io/pbrt_tok.h"
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

static pk_scene *load_at(pk_context **ctx, const char *text, const char *name, const char *dir, bool commit)
{
    REQUIRE(pk_context_create(NULL, ctx) == PK_OK);
    warning_log_clear(&warnings);
    warning_log_attach(*ctx, &warnings);
    pk_scene *s = NULL;
    REQUIRE(scene_create(*ctx, name, &s) == PK_OK);
    pk_status st = scene_pbrt_parse(*ctx, s, text, strlen(text), name, dir);
    if (st == PK_OK && commit) st = scene_commit(*ctx, s);
    if (st != PK_OK) {
        scene_destroy(s);
        return NULL;
    }
    return s;
}

/* Loads text (as t.pbrt in tests/data/pbrt) and commits; fails the test
 * when it does not load. */
static pk_scene *load(pk_context **ctx, const char *text)
{
    pk_scene *s = load_at(ctx, text, "t.pbrt", PK_TEST_DATA "/pbrt", true);
    CHECKF(s != NULL, "load failed: %s", pk_context_error(*ctx));
    return s;
}

static void done(pk_context *ctx, pk_scene *s)
{
    if (s) scene_destroy(s);
    pk_context_destroy(ctx);
}

/* text must fail with a message that begins with prefix and holds part. */
static void expect_error(const char *text, const char *prefix, const char *part)
{
    pk_context *ctx;
    pk_scene *s = load_at(&ctx, text, "t.pbrt", PK_TEST_DATA "/pbrt", true);
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

static bool has_position(const pk_scene *s, vec3 p, float tol)
{
    for (size_t i = 0; i < s->npositions; i++)
        if (near3(s->positions[i], p, tol)) return true;
    return false;
}

/* ---- tokenizer ---- */

static void test_tokenizer(void)
{
    const char *text = "Shape \"tri mesh\" # a comment \"not a string\"\n"
                       "[ 1 -2 3.5e2 .25 ]\n"
                       "\"esc\\\"aped\\n\" true\n"
                       "-0 9007199254740991 1e39";
    pbrt_tokenizer t;
    pbrt_tok_init(&t, text, strlen(text));
    pbrt_token k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_WORD && pbrt_tok_is(&k, "Shape") && k.line == 1);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_STRING && pbrt_tok_is(&k, "tri mesh") && k.line == 1);
    k = pbrt_tok_peek(&t);
    CHECK(k.kind == PBRT_TOK_LBRACK && k.line == 2);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_LBRACK);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && k.number == 1.0 && k.integer);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && k.number == -2.0 && k.integer);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && k.number == 350.0 && !k.integer);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && k.number == 0.25);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_RBRACK && k.line == 2);
    k = pbrt_tok_next(&t);
    char buf[32];
    CHECK(k.kind == PBRT_TOK_STRING && k.line == 3 && k.escapes);
    CHECK(pbrt_tok_string(&k, buf, sizeof buf) == 9 && strcmp(buf, "esc\"aped\n") == 0);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_WORD && pbrt_tok_is(&k, "true"));
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && k.number == 0.0 && k.line == 4);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && k.number == 9007199254740991.0 && k.integer); /* exact: 2^53 - 1 */
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_NUMBER && isinf(k.number)); /* beyond float: the reader refuses it */
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_END && k.line == 4);
    CHECK(pbrt_tok_next(&t).kind == PBRT_TOK_END);

    /* errors */
    const char *bad[] = {"\"open string\nnext", "\"open at end", "1.2.3", "Shape \x01"};
    const size_t line[] = {1, 1, 1, 1};
    const char *why[] = {"past the end of its line", "not closed", "bad number '1.2.3'", "unexpected byte 0x01"};
    for (int i = 0; i < 4; i++) {
        pbrt_tok_init(&t, bad[i], strlen(bad[i]));
        pbrt_token e;
        do e = pbrt_tok_next(&t);
        while (e.kind != PBRT_TOK_ERROR && e.kind != PBRT_TOK_END);
        CHECKF(e.kind == PBRT_TOK_ERROR && e.line == line[i] && strstr(t.why, why[i]), "bad input %d: %s", i, t.why);
    }
    /* a buffer without a NUL after it, and a byte order mark */
    const char bom[] = {'\xEF', '\xBB', '\xBF', 'W', 'o', 'r', 'l', 'd'};
    pbrt_tok_init(&t, bom, 5);
    k = pbrt_tok_next(&t);
    CHECK(k.kind == PBRT_TOK_WORD && k.len == 2 && memcmp(k.text, "Wo", 2) == 0);
}

/* ---- transforms ---- */

static void test_transforms(void)
{
    pk_context *ctx;
    /* one triangle (0,0,0) (1,0,0) (0,1,0) placed by each form */
    const char *tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    char text[4096];
    snprintf(text, sizeof text,
             PLAIN "LightSource \"point\" \"rgb I\" [1 1 1]\n"
                   "AttributeBegin\nTranslate 1 2 3\n%s" /* tris 0 */
                   "AttributeEnd\nAttributeBegin\nScale 2 2 2 Translate 1 0 0\n%s" /* 1: scale after translate */
                   "AttributeEnd\nTransformBegin\nRotate 90 0 0 1\n%sTransformEnd\n" /* 2 */
                   "AttributeBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\n%s" /* 3 */
                   "ConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1]\n%s" /* 4 */
                   "CoordinateSystem \"here\"\nIdentity\n%s" /* 5 */
                   "CoordSysTransform \"here\"\n%s" /* 6 */
                   "AttributeEnd\n%s", /* 7 */
             tri, tri, tri, tri, tri, tri, tri, tri);
    pk_scene *s = load(&ctx, text);
    if (s) {
        REQUIRE(s->ntris == 8);
        vec3 a, b, c;
        const vec3 want[8][2] = {{{1, 2, 3}, {2, 2, 3}},  {{2, 0, 0}, {4, 0, 0}}, {{0, 0, 0}, {0, 1, 0}},
                                 {{5, 6, 7}, {6, 6, 7}},  {{5, 6, 7}, {7, 6, 7}}, {{0, 0, 0}, {1, 0, 0}},
                                 {{5, 6, 7}, {7, 6, 7}},  {{0, 0, 0}, {1, 0, 0}}};
        for (int k = 0; k < 8; k++) {
            scene_tri_verts(s, (size_t)k, &a, &b, &c);
            CHECKF(near3(a, want[k][0], 1e-5f) && near3(b, want[k][1], 1e-5f), "triangle %d: (%g %g %g) (%g %g %g)", k,
                   (double)a.x, (double)a.y, (double)a.z, (double)b.x, (double)b.y, (double)b.z);
        }
    }
    done(ctx, s);
}

/* ---- camera and settings ---- */

static void test_camera(void)
{
    pk_context *ctx;
    /* pbrt's sensor: exposure time x ISO / 100 scales what the image records */
    pk_scene *s0 = load(&ctx, "Camera \"perspective\" \"float shutterclose\" 0.5\nFilm \"rgb\" \"float iso\" 400\n"
                              "WorldBegin\nLightSource \"point\" \"rgb I\" [1 2 3]\n"
                              "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\nShape \"sphere\"\n");
    if (s0) CHECK(near3(s0->lights[0].intensity, v3(2, 4, 6), 0) && near3(s0->materials[s0->spheres[0].material].ke, v3s(2), 0));
    done(ctx, s0);
    /* landscape: fov is the vertical angle; settings */
    pk_scene *s = load(&ctx, "LookAt 0 1 5  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
                             "Film \"rgb\" \"integer xresolution\" 400 \"integer yresolution\" 200 \"string filename\" \"x.exr\"\n"
                             "Sampler \"zsobol\" \"integer pixelsamples\" 24\n"
                             "Integrator \"volpath\" \"integer maxdepth\" 7 \"bool regularize\" true\n"
                             "WorldBegin\nShape \"sphere\"\n");
    if (s) {
        CHECK_NEAR(s->camera.fov_deg, 40.0, 1e-4);
        CHECK(near3(v3(s->camera.look_from[0], s->camera.look_from[1], s->camera.look_from[2]), v3(0, 1, 5), 1e-5f));
        CHECK(s->camera.look_at[2] < 5.0f && fabsf(s->camera.look_at[1] - 1.0f) < 1e-5f);
        CHECK(s->render.has_width && s->render.opt.width == 400 && s->render.opt.height == 200);
        CHECK(s->render.has_spp && s->render.opt.spp == 24);
        CHECK(s->render.has_max_depth && s->render.opt.max_depth == 7);
        CHECK(s->render.has_regularize && s->render.opt.regularize == 1);
        CHECK(s->camera.lens_radius == 0.0f && s->camera.projection == PK_PROJECTION_PERSPECTIVE);
        /* pbrt's LookAt camera sees world -x on the image's right: the world is mirrored across x = 0 */
        CHECK(s->nspheres == 1 && fabsf(s->spheres[0].center.x) < 1e-6f);
    }
    done(ctx, s);
    /* portrait: fov is the horizontal angle; the vertical one is wider */
    s = load(&ctx, "Camera \"perspective\" \"float fov\" 40 \"float lensradius\" 0.1 \"float focaldistance\" 3\n"
                   "Film \"rgb\" \"integer xresolution\" 200 \"integer yresolution\" 400\nWorldBegin\n"
                   "Shape \"sphere\" \"float radius\" 0.5\n");
    if (s) {
        double want = 2.0 * atan(tan(20.0 * M_PI / 180.0) * 2.0) * 180.0 / M_PI;
        CHECK_NEAR(s->camera.fov_deg, want, 1e-3);
        CHECK(s->camera.lens_radius == 0.1f && s->camera.focus_distance == 3.0f);
        CHECK(!s->render.has_spp && s->render.opt.max_depth == 5); /* pbrt's default depth */
    }
    done(ctx, s);
    /* a screen window twice the default height halves nothing but widens the view */
    s = load(&ctx, "Camera \"perspective\" \"float fov\" 30 \"float screenwindow\" [-2 2 -2 2]\n"
                   "Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 100\nWorldBegin\nShape \"sphere\"\n");
    if (s) CHECK_NEAR(s->camera.fov_deg, 2.0 * atan(2.0 * tan(15.0 * M_PI / 180.0)) * 180.0 / M_PI, 1e-3);
    done(ctx, s);
    s = load(&ctx, "Camera \"orthographic\"\nFilm \"rgb\" \"integer xresolution\" 300 \"integer yresolution\" 100\n"
                   "WorldBegin\nShape \"sphere\"\n");
    if (s) CHECK(s->camera.projection == PK_PROJECTION_ORTHOGRAPHIC && fabsf(s->camera.ortho_width - 6.0f) < 1e-5f);
    done(ctx, s);

    /* the default camera mirrors x; Scale -1 1 1 before it does not */
    const char *tri = "WorldBegin\nLightSource \"point\"\nShape \"trianglemesh\" \"point3 P\" [1 0 5 2 0 5 1 1 5]\n";
    char text[512];
    snprintf(text, sizeof text, "%s", tri);
    s = load(&ctx, text);
    if (s) CHECK(has_position(s, v3(-1, 0, 5), 1e-5f) && !has_position(s, v3(1, 0, 5), 1e-5f));
    if (s) CHECK(s->camera.look_at[2] > 0.0f); /* looking down +z */
    done(ctx, s);
    snprintf(text, sizeof text, "Scale -1 1 1 Camera \"perspective\"\n%s", tri);
    s = load(&ctx, text);
    if (s) CHECK(has_position(s, v3(1, 0, 5), 1e-5f));
    done(ctx, s);
}

/* ---- materials ---- */

static const material *tri_mat(const pk_scene *s, size_t k) { return &s->materials[s->tris[k].material]; }

static void test_materials(void)
{
    pk_context *ctx;
    const char *tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    char text[4096];
    snprintf(text, sizeof text,
             PLAIN "LightSource \"point\"\n"
                   "Material \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\n%s"
                   "MakeNamedMaterial \"au\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\" "
                   "\"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.25\n"
                   "NamedMaterial \"au\"\n%s"
                   "Material \"conductor\" \"float uroughness\" 0.04 \"float vroughness\" 0.04 \"bool remaproughness\" false\n%s"
                   "Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n%s"
                   "Material \"coateddiffuse\" \"rgb reflectance\" [0.5 0.4 0.3] \"float eta\" 1.4\n%s"
                   "MakeNamedMaterial \"grey\" \"string type\" \"diffuse\"\n"
                   "MakeNamedMaterial \"mixed\" \"string type\" \"mix\" \"string materials\" [\"au\" \"grey\"] "
                   "\"float amount\" 0.25\nNamedMaterial \"mixed\"\n%s"
                   "Material \"interface\"\n%s"
                   "Material \"hair\"\n%s",
             tri, tri, tri, tri, tri, tri, tri, tri);
    pk_scene *s = load(&ctx, text);
    if (s) {
        REQUIRE(s->ntris == 7); /* the interface's triangle is not there */
        CHECK(tri_mat(s, 0)->type == MAT_DIFFUSE && near3(tri_mat(s, 0)->kd, v3(0.1f, 0.2f, 0.3f), 0));
        vec3 eta, k;
        REQUIRE(spectra_named_metal("Au", &eta, &k));
        const material *au = tri_mat(s, 1);
        CHECK(au->type == MAT_CONDUCTOR && near3(au->eta, eta, 0) && near3(au->k, k, 0));
        CHECK_NEAR(au->alpha, 0.5, 1e-6); /* remapped: sqrt(0.25) */
        const material *cu = tri_mat(s, 2);
        REQUIRE(spectra_named_metal("Cu", &eta, &k));
        CHECK(cu->type == MAT_CONDUCTOR && near3(cu->eta, eta, 0) && fabsf(cu->alpha - 0.04f) < 1e-7f);
        CHECK(tri_mat(s, 3)->type == MAT_DIELECTRIC && fabsf(tri_mat(s, 3)->ni - 1.5185f) < 1e-4f);
        /* coateddiffuse: the layered material with pbrt-v4's defaults */
        const material *cd = tri_mat(s, 4);
        CHECK(cd->type == MAT_COATED && cd->coat_base == MATERIAL_BASE_DIFFUSE && fabsf(cd->ni - 1.4f) < 1e-6f &&
              near3(cd->kd, v3(0.5f, 0.4f, 0.3f), 0) && cd->alpha == 0.0f);
        CHECK(cd->layer.thickness == 0.01f && near3(cd->layer.albedo, v3s(0.0f), 0) && cd->layer.g == 0.0f &&
              cd->layer.maxdepth == 10 && cd->layer.nsamples == 1);
        /* the mix: "au" or "grey", the second with probability 0.25 */
        const material *mx = tri_mat(s, 5);
        CHECK(mx->type == MAT_MIX && mx->amount == 0.25f && mx->mix_a == (int)s->tris[1].material &&
              s->materials[mx->mix_b].type == MAT_DIFFUSE && near3(s->materials[mx->mix_b].kd, v3s(0.5f), 0));
        CHECK(tri_mat(s, 6)->type == MAT_DIFFUSE && warning_log_has(&warnings, "t.pbrt:22: material \"hair\""));
        CHECK(!warning_log_has(&warnings, "mix"));
    }
    done(ctx, s);
    /* textures: an image map and a checkerboard with pbrt's uv scale */
    s = load(&ctx, PLAIN "LightSource \"point\"\n"
                         "Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"../tex_checker.png\" "
                         "\"float uscale\" 2 \"float scale\" 0.5\n"
                         "Texture \"ch\" \"spectrum\" \"checkerboard\" \"float uscale\" 20 \"float vscale\" 10 "
                         "\"rgb tex1\" [1 0 0] \"rgb tex2\" [0 0 1]\n"
                         "Material \"diffuse\" \"texture reflectance\" \"img\"\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"point2 uv\" [0 0 1 0 0 1]\n"
                         "Material \"diffuse\" \"texture reflectance\" \"ch\"\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"point2 uv\" [0 0 1 0 0 1]\n");
    if (s) {
        REQUIRE(s->ntris == 2);
        const material *a = tri_mat(s, 0), *b = tri_mat(s, 1);
        CHECK(a->map_kd.kind == TEX_IMAGE && a->map_kd.s[0] == 2.0f && a->map_kd.s[1] == 1.0f && a->kd.x == 0.5f);
        CHECK(s->ntextures == 1);
        CHECK(b->map_kd.kind == TEX_CHECKER && b->map_kd.s[0] == 20.0f && b->map_kd.s[1] == 10.0f &&
              near3(b->map_kd.even, v3(1, 0, 0), 0) && near3(b->map_kd.odd, v3(0, 0, 1), 0));
    }
    done(ctx, s);
}

/* The closed form that Paprsek's plastic once used for coateddiffuse (its
 * albedo matched to the layer's), against a random walk through
 * the layer it describes (a smooth coat of index 1.5 over a Lambertian base
 * of albedo rho, nothing in between): of the light that enters, the part
 * that leaves again is rho (1 - Fi) / (1 - rho Fi) with Fi = 1 - (1 - Fe) /
 * eta^2 (Fe: the coat's diffuse reflectance from outside). The walk uses
 * the Fresnel equations from inside (with total internal reflection) and
 * knows nothing of Fe or Fi. */
static double fresnel_t(double c, double eta) /* light in a medium of index eta going out (relative 1/eta) */
{
    double s2 = eta * eta * (1.0 - c * c);
    if (s2 >= 1.0) return 1.0;
    double ct = sqrt(1.0 - s2), e = 1.0 / eta;
    double rs = (c - e * ct) / (c + e * ct), rp = (e * c - ct) / (e * c + ct);
    return 0.5 * (rs * rs + rp * rp);
}

static void test_layer_walk(void)
{
    const double eta = 1.5;
    double fe = 0.0;
    for (int i = 0; i < 20000; i++) {
        double mu = (i + 0.5) / 20000.0, ct = sqrt(1.0 - (1.0 - mu * mu) / (eta * eta));
        double rs = (mu - eta * ct) / (mu + eta * ct), rp = (eta * mu - ct) / (eta * mu + ct);
        fe += (rs * rs + rp * rp) * mu / 20000.0;
    }
    const double fi = 1.0 - (1.0 - fe) / (eta * eta);
    rng r = {12345};
    const double rhos[3] = {0.2, 0.5, 0.9};
    for (int k = 0; k < 3; k++) {
        const int n = 400000;
        int out = 0;
        for (int i = 0; i < n; i++) {
            for (int bounce = 0; bounce < 1000; bounce++) {
                if ((double)rng_f(&r) >= rhos[k]) break;          /* absorbed by the base */
                double mu = sqrt((double)rng_f(&r) + 1e-12); /* cosine-distributed, up */
                if ((double)rng_f(&r) >= fresnel_t(mu, eta)) {     /* through the coat */
                    out++;
                    break;
                }
            }
        }
        double p = (double)out / n, se = sqrt(p * (1.0 - p) / n);
        double want = rhos[k] * (1.0 - fi) / (1.0 - rhos[k] * fi);
        CHECKF(fabs(p - want) < 4.0 * se, "rho %g: the walk gives %.5f +- %.5f, the closed form %.5f", rhos[k], p, se,
               want);
    }
}

/* ---- lights ---- */

static void test_lights(void)
{
    pk_context *ctx;
    pk_scene *s = load(&ctx, PLAIN "LightSource \"point\" \"rgb I\" [1 2 3] \"point3 from\" [1 2 3] \"float scale\" 2\n"
                                   "Translate 0 10 0\n"
                                   "LightSource \"point\" \"blackbody I\" 6500 \"float power\" 100\n"
                                   "LightSource \"spot\" \"point3 from\" [0 0 0] \"point3 to\" [0 -2 0] "
                                   "\"float coneangle\" 30 \"float conedelta\" 10\n"
                                   "LightSource \"distant\" \"point3 from\" [0 0 0] \"point3 to\" [1 0 0] \"rgb L\" [3 3 3]\n"
                                   "LightSource \"infinite\" \"rgb L\" [0.5 0.25 1]\n"
                                   "Shape \"sphere\"\n");
    if (s) {
        REQUIRE(s->nlights == 4);
        CHECK(near3(s->lights[0].position, v3(1, 2, 3), 0) && near3(s->lights[0].intensity, v3(2, 4, 6), 0));
        /* power: luminance-1 spectrum times power / 4 pi */
        const point_light *l = &s->lights[1];
        CHECK(near3(l->position, v3(0, 10, 0), 0));
        CHECK_NEAR(v3_luminance(l->intensity), 100.0 / (4.0 * M_PI), 0.02);
        l = &s->lights[2];
        CHECK(near3(l->spot_dir, v3(0, -1, 0), 1e-6f));
        CHECK_NEAR(l->cos_outer, cos(30.0 * M_PI / 180.0), 1e-6);
        CHECK_NEAR(l->cos_inner, cos(20.0 * M_PI / 180.0), 1e-6);
        l = &s->lights[3];
        CHECK(l->distant && near3(l->position, v3(-1, 0, 0), 1e-6f) && near3(l->intensity, v3s(3), 0));
        CHECK(s->env.set && near3(s->env.radiance, v3(0.5f, 0.25f, 1.0f), 0));
    }
    done(ctx, s);
    /* emission spectra at luminance 1 without white balance: an equal-energy
     * spectrum is pinkish in sRGB (its white point is E, not D65), and a
     * spectrum at 600 nm alone is red */
    s = load(&ctx, PLAIN "LightSource \"point\" \"spectrum I\" [300 1 900 1]\n"
                         "LightSource \"point\" \"spectrum I\" [590 0 600 1 610 0]\nShape \"sphere\"\n");
    if (s) {
        vec3 e = s->lights[0].intensity, r = s->lights[1].intensity;
        CHECK_NEAR(v3_luminance(e), 1.0, 0.01);
        /* XYZ (1, 1, 1) in linear sRGB */
        CHECK(fabsf(e.x - 1.2048f) < 0.01f && fabsf(e.y - 0.9483f) < 0.01f && fabsf(e.z - 0.9088f) < 0.01f);
        CHECK(r.x > 3.0f * r.y && r.z < 0.05f * r.x);
    }
    done(ctx, s);
    /* area lights: emission on the shapes of the block, one- or two-sided, power over the area */
    s = load(&ctx, PLAIN "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 2 3] \"float scale\" 2\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nAttributeEnd\n"
                         "AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" 3000 \"bool twosided\" true "
                         "\"float power\" 10\nScale 2 2 2\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nAttributeEnd\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n");
    if (s) {
        REQUIRE(s->ntris == 3);
        CHECK(near3(tri_mat(s, 0)->ke, v3(2, 4, 6), 0) && !tri_mat(s, 0)->two_sided);
        CHECK(tri_mat(s, 1)->two_sided);
        /* 10 W over 2 sides of area 2, times pi: luminance 10 / (2 * 2 * pi) */
        CHECK_NEAR(v3_luminance(tri_mat(s, 1)->ke), 10.0 / (4.0 * M_PI), 0.005);
        CHECK(tri_mat(s, 1)->ke.x > tri_mat(s, 1)->ke.z); /* 3000 K is red */
        CHECK(v3_max_comp(tri_mat(s, 2)->ke) == 0.0f);
    }
    done(ctx, s);
}

/* An equal-area image (pbrt-v4's infinite lights) turned into the world's
 * lat-long map: a 32 x 32 image red where the light-space direction has
 * x > 0 (the right half of the square) and green where z > 0 (the inner
 * diamond |u| + |v| <= 1 of the square mapped to [-1, 1]^2), written as a
 * PFM. Then the same light rotated by 90 degrees about y. */
static void test_equal_area(void)
{
    const int n = 32;
    char path[] = "/tmp/pk_test_pbrt_envXXXXXX";
    int fd = mkstemp(path);
    REQUIRE(fd >= 0);
    FILE *f = fdopen(fd, "wb");
    REQUIRE(f);
    fprintf(f, "PF\n%d %d\n-1\n", n, n);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            float u = 2.0f * ((float)x + 0.5f) / (float)n - 1.0f, v = 2.0f * ((float)y + 0.5f) / (float)n - 1.0f;
            float px[3] = {u > 0.0f ? 1.0f : 0.0f, fabsf(u) + fabsf(v) <= 1.0f ? 1.0f : 0.0f, 0.25f};
            fwrite(px, sizeof px, 1, f);
        }
    fclose(f);
    for (int rot = 0; rot < 2; rot++) {
        char text[512];
        snprintf(text, sizeof text,
                 PLAIN "%sLightSource \"infinite\" \"string filename\" \"%s\" \"float scale\" 2\nShape \"sphere\"\n",
                 rot ? "Rotate 90 0 1 0\n" : "", path);
        pk_context *ctx;
        pk_scene *s = load(&ctx, text);
        if (s) {
            const scene_environment *e = &s->env;
            REQUIRE(e->map_rgb && e->map_w == 2 * e->map_h);
            size_t wrong = 0, tested = 0;
            for (int j = 0; j < e->map_h; j++)
                for (int i = 0; i < e->map_w; i++) {
                    float th = ((float)j + 0.5f) / (float)e->map_h * (float)M_PI;
                    float ph = ((float)i + 0.5f) / (float)e->map_w * 2.0f * (float)M_PI;
                    vec3 d = v3(sinf(th) * sinf(ph), cosf(th), -sinf(th) * cosf(ph));
                    /* into light space: the rotation's inverse */
                    vec3 l = rot ? v3(-d.z, d.y, d.x) : d;
                    const float *px = &e->map_rgb[3 * ((size_t)j * (size_t)e->map_w + (size_t)i)];
                    if (fabsf(l.x) > 0.15f) {
                        tested++;
                        wrong += (px[0] > 1.0f) != (l.x > 0.0f);
                    }
                    if (fabsf(l.z) > 0.15f) {
                        tested++;
                        wrong += (px[1] > 1.0f) != (l.z > 0.0f);
                    }
                    wrong += fabsf(px[2] - 0.5f) > 1e-6f;
                }
            CHECKF(wrong == 0 && tested > 1000, "rotation %d: %zu of %zu lookups wrong", rot, wrong, tested);
        }
        done(ctx, s);
    }
    /* "illuminance": pbrt-v4 scales the map so that the luminance above the
     * horizon times the cosine, summed with 2 pi / (pixels) per pixel, is the
     * value given. For a uniform image of c that sum is c pi / 2 (the pixels
     * of the upper half cover 2 pi steradians at 4 pi / pixels each, and the
     * cosine averages 1/2 over them), so every pixel becomes 2 E / pi. The
     * midpoint sum over the inner diamond at n = 32 is 4 / n^2 = 0.4 % short
     * of the integral: 1 % covers it. */
    f = fopen(path, "wb");
    REQUIRE(f);
    fprintf(f, "PF\n%d %d\n-1\n", n, n);
    for (int i = 0; i < 3 * n * n; i++) fwrite(&(float){0.25f}, sizeof(float), 1, f);
    fclose(f);
    {
        pk_context *ctx;
        char text[512];
        snprintf(text, sizeof text,
                 PLAIN "LightSource \"infinite\" \"string filename\" \"%s\" \"float illuminance\" 3\nShape \"sphere\"\n",
                 path);
        pk_scene *s = load(&ctx, text);
        if (s) {
            REQUIRE(s->env.map_rgb);
            const float *px = &s->env.map_rgb[3 * ((size_t)(s->env.map_h / 2) * (size_t)s->env.map_w + 5)];
            CHECKF(fabs((double)px[1] / (2.0 * 3.0 / M_PI) - 1.0) < 0.01, "illuminance 3: pixel %g, expected %g", (double)px[1],
                   2.0 * 3.0 / M_PI);
        }
        done(ctx, s);
        /* a uniform light of one nit gives pi lux on a level surface */
        s = load(&ctx, PLAIN "LightSource \"infinite\" \"rgb L\" [1 1 1] \"float illuminance\" 10\nShape \"sphere\"\n");
        if (s) CHECK_NEAR(v3_luminance(s->env.radiance), 10.0 / M_PI, 1e-4);
        done(ctx, s);
    }
    /* a lat-long (2:1) image is refused with a warning */
    f = fopen(path, "wb");
    REQUIRE(f);
    fprintf(f, "PF\n4 2\n-1\n");
    for (int i = 0; i < 24; i++) fwrite(&(float){1.0f}, sizeof(float), 1, f);
    fclose(f);
    pk_context *ctx;
    char text[512];
    snprintf(text, sizeof text, PLAIN "LightSource \"infinite\" \"string filename\" \"%s\"\nShape \"sphere\"\n", path);
    pk_scene *s = load(&ctx, text);
    if (s) CHECK(!s->env.map_rgb && warning_log_has(&warnings, "not the square equal-area image"));
    done(ctx, s);
    remove(path);
}

/* ---- shapes ---- */

/* Loop subdivision of a regular tetrahedron, one level, pushed to the limit:
 * the corners (valence 3) end at v/5 and the edge points (valence 6) at
 * 7 (a + b) / 48 (worked out from Loop's masks: one level moves a corner to
 * v/4 and an edge point to (a + b)/4, since the four corners sum to 0). */
static void test_loop(void)
{
    pk_context *ctx;
    pk_scene *s = load(&ctx, PLAIN "LightSource \"point\"\n"
                                   "Shape \"loopsubdiv\" \"integer levels\" 1 \"point3 P\" [1 1 1 -1 -1 1 -1 1 -1 1 -1 -1] "
                                   "\"integer indices\" [0 2 1 0 1 3 0 3 2 1 2 3]\n");
    const vec3 v[4] = {{1, 1, 1}, {-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}};
    if (s) {
        CHECK(s->ntris == 16 && s->npositions == 10 && s->nnormals == 10);
        for (int i = 0; i < 4; i++) CHECKF(has_position(s, v3_scale(v[i], 0.2f), 1e-6f), "corner %d", i);
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++)
                CHECKF(has_position(s, v3_scale(v3_add(v[i], v[j]), 7.0f / 48.0f), 1e-6f), "edge %d-%d", i, j);
        /* normals point outward at the corners */
        for (size_t i = 0; i < s->npositions; i++)
            CHECK(v3_dot(s->normals[i], s->positions[i]) > 0.0f);
    }
    done(ctx, s);
    /* one triangle: every vertex on the boundary. Corner a -> 13/20 a +
     * 7/40 (b + c); edge point ab -> 19/40 (a + b) + 1/20 c. */
    s = load(&ctx, PLAIN "LightSource \"point\"\n"
                         "Shape \"loopsubdiv\" \"integer levels\" 1 \"point3 P\" [0 0 0 4 0 0 0 4 0]\n");
    if (s) {
        vec3 a = v3(0, 0, 0), b = v3(4, 0, 0), c = v3(0, 4, 0);
        CHECK(s->ntris == 4 && s->npositions == 6);
        CHECK(has_position(s, v3_add(v3_scale(a, 0.65f), v3_scale(v3_add(b, c), 0.175f)), 1e-5f));
        CHECK(has_position(s, v3_add(v3_scale(b, 0.65f), v3_scale(v3_add(a, c), 0.175f)), 1e-5f));
        CHECK(has_position(s, v3_add(v3_scale(v3_add(a, b), 0.475f), v3_scale(c, 0.05f)), 1e-5f));
        CHECK(has_position(s, v3_add(v3_scale(v3_add(b, c), 0.475f), v3_scale(a, 0.05f)), 1e-5f));
    }
    done(ctx, s);
    /* levels multiply by 4 */
    s = load(&ctx, PLAIN "LightSource \"point\"\n"
                         "Shape \"loopsubdiv\" \"point3 P\" [1 1 1 -1 -1 1 -1 1 -1 1 -1 -1] "
                         "\"integer indices\" [0 1 2 0 3 1 0 2 3 1 3 2]\n");
    if (s) CHECK(s->ntris == 4 * 64 && s->npositions == 2 + 4 * 64 / 2); /* closed: V = F/2 + 2 */
    done(ctx, s);
}

static void test_shapes(void)
{
    pk_context *ctx;
    pk_scene *s = load(&ctx, PLAIN "LightSource \"point\"\n"
                                   /* 0: three vertices need no indices */
                                   "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                                   /* 1, 2: a bilinear patch is two triangles */
                                   "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"
                                   /* analytic: full sphere under a similarity */
                                   "AttributeBegin\nTranslate 0 0 -5 Scale 2 2 2 Rotate 30 1 1 0\n"
                                   "Shape \"sphere\" \"float radius\" 1.5\nAttributeEnd\n"
                                   /* alpha 0: not there */
                                   "Shape \"sphere\" \"float alpha\" 0\n"
                                   "Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n");
    if (s) {
        CHECK(s->ntris == 3 && s->nspheres == 1);
        CHECK(near3(s->spheres[0].center, v3(0, 0, -5), 1e-6f) && fabsf(s->spheres[0].radius - 3.0f) < 1e-5f);
        vec3 a, b, c;
        scene_tri_verts(s, 1, &a, &b, &c);
        vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
        CHECK(n.z > 0.0f); /* the patch faces +z: (p10 - p00) x (p01 - p00) */
        CHECK(warning_log_has(&warnings, "t.pbrt:12: shape \"curve\" is not supported"));
    }
    done(ctx, s);
    /* Attribute defaults hold within their block; the directive's own values win */
    s = load(&ctx, PLAIN "AttributeBegin\nAttribute \"light\" \"rgb I\" [2 2 2]\n"
                         "Attribute \"shape\" \"float radius\" 2 \"float wobble\" 1\n"
                         "LightSource \"point\"\nShape \"sphere\"\nShape \"sphere\" \"float radius\" 3\nAttributeEnd\n"
                         "Shape \"sphere\"\nLightSource \"point\"\n");
    if (s) {
        CHECK(s->nspheres == 3 && s->spheres[0].radius == 2.0f && s->spheres[1].radius == 3.0f &&
              s->spheres[2].radius == 1.0f);
        CHECK(s->nlights == 2 && s->lights[0].intensity.x == 2.0f && s->lights[1].intensity.x == 1.0f);
        CHECK(!warning_log_has(&warnings, "wobble"));
    }
    done(ctx, s);
    /* tessellated: partial sphere, stretched sphere, disk, cylinder: every
     * vertex on its surface, every triangle facing outward */
    s = load(&ctx, PLAIN "LightSource \"point\"\n"
                         "Shape \"sphere\" \"float radius\" 2 \"float zmin\" 0\n"
                         "Shape \"disk\" \"float radius\" 1 \"float innerradius\" 0.5 \"float height\" 3\n"
                         "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" -1 \"float zmax\" 1 \"float phimax\" 180\n");
    if (s) {
        size_t sphere_v = 0, disk_v = 0, cyl_v = 0;
        for (size_t i = 0; i < s->npositions; i++) {
            vec3 p = s->positions[i];
            float r = sqrtf(p.x * p.x + p.y * p.y);
            if (fabsf(v3_len(p) - 2.0f) < 1e-5f && p.z >= -1e-6f) sphere_v++;
            else if (fabsf(p.z - 3.0f) < 1e-6f && r >= 0.5f - 1e-6f && r <= 1.0f + 1e-6f) disk_v++;
            else if (fabsf(r - 0.5f) < 1e-6f && fabsf(p.z) <= 1.0f && p.y >= -1e-6f) cyl_v++;
        }
        CHECKF(sphere_v + disk_v + cyl_v == s->npositions, "%zu + %zu + %zu of %zu vertices on their surfaces", sphere_v,
               disk_v, cyl_v, s->npositions);
        CHECK(s->ndegenerate == 0);
        size_t inward = 0;
        for (size_t k = 0; k < s->ntris; k++) {
            vec3 a, b, c;
            scene_tri_verts(s, k, &a, &b, &c);
            vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
            vec3 m = v3_scale(v3_add(v3_add(a, b), c), 1.0f / 3.0f);
            vec3 out = fabsf(m.z - 3.0f) < 1e-5f ? v3(0, 0, 1) : fabsf(v3_len(m) - 2.0f) < 0.01f ? m : v3(m.x, m.y, 0);
            if (v3_dot(n, out) <= 0.0f) inward++;
        }
        CHECKF(inward == 0, "%zu triangles face inward", inward);
    }
    done(ctx, s);
    /* ReverseOrientation turns windings without normals; with normals the
     * normals' side is kept */
    s = load(&ctx, PLAIN "LightSource \"point\"\nReverseOrientation\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"normal N\" [0 0 1 0 0 1 0 0 1]\n");
    if (s) {
        vec3 a, b, c;
        scene_tri_verts(s, 0, &a, &b, &c);
        CHECK(v3_cross(v3_sub(b, a), v3_sub(c, a)).z < 0.0f);
        scene_tri_verts(s, 1, &a, &b, &c);
        CHECK(v3_cross(v3_sub(b, a), v3_sub(c, a)).z > 0.0f);
    }
    done(ctx, s);
    /* PLY: a quad in tests/data, read relative to the pbrt file */
    pk_context *c2;
    char *data = NULL;
    size_t size = 0;
    REQUIRE(pk_context_create(NULL, &c2) == PK_OK);
    REQUIRE(file_read_all(c2, PK_TEST_DATA "/pbrt/plymesh.pbrt", &data, &size) == PK_OK);
    pk_context_destroy(c2);
    s = load(&ctx, data);
    if (s) CHECK(s->ntris == 2 && has_position(s, v3(1, 1, -3), 0) && s->nnormals == 4 && s->nuvs == 4);
    done(ctx, s);
    free(data);
}

/* ---- objects, includes ---- */

static void test_objects(void)
{
    pk_context *ctx;
    pk_scene *s = load(&ctx, PLAIN "LightSource \"point\"\n"
                                   "ObjectBegin \"tri\"\nTranslate 0 0 1\n"
                                   "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nObjectEnd\n"
                                   "ObjectBegin \"empty\"\nObjectEnd\n"
                                   "Translate 10 0 0\nObjectInstance \"tri\"\n"
                                   "Translate 10 0 0\nObjectInstance \"tri\"\nObjectInstance \"empty\"\n");
    if (s) {
        CHECK(s->nmeshes == 1 && s->ninstances == 2 && s->ntris == 2);
        CHECK(has_position(s, v3(10, 0, 1), 1e-6f) && has_position(s, v3(21, 0, 1), 1e-6f));
    }
    done(ctx, s);
    /* the same under the mirrored default camera: instances land mirrored */
    s = load(&ctx, "WorldBegin\nLightSource \"point\"\n"
                   "ObjectBegin \"tri\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nObjectEnd\n"
                   "Translate 10 0 0\nObjectInstance \"tri\"\n");
    if (s) CHECK(has_position(s, v3(-10, 0, 0), 1e-5f) && has_position(s, v3(-11, 0, 0), 1e-5f));
    done(ctx, s);

    /* includes, relative to the including file */
    pk_context *c2;
    char *data = NULL;
    size_t size = 0;
    REQUIRE(pk_context_create(NULL, &c2) == PK_OK);
    REQUIRE(file_read_all(c2, PK_TEST_DATA "/pbrt/include_main.pbrt", &data, &size) == PK_OK);
    pk_context_destroy(c2);
    s = load_at(&ctx, data, "include_main.pbrt", PK_TEST_DATA "/pbrt", true);
    CHECKF(s != NULL, "%s", pk_context_error(ctx));
    if (s) CHECK(s->ntris == 2 && s->nlights == 1 && s->render.opt.width == 64 && s->materials[s->tris[0].material].kd.x == 0.5f);
    done(ctx, s);
    free(data);
}

/* ---- messages ---- */

static void test_errors(void)
{
    expect_error("WorldBegin\nInclude \"cycle_a.pbrt\"\n", PK_TEST_DATA "/pbrt/cycle_b.pbrt:2: Include \"cycle_a.pbrt\"",
                 "includes itself");
    expect_error("WorldBegin\n\nFrobnicate 1 2\n", "t.pbrt:3: ", "unknown directive 'Frobnicate'");
    expect_error(PLAIN "Shape \"trianglemesh\"\n  \"point3 P\" [0 0 0 1 0 0 0 1 0]\n  \"integer indices\" [0 1 3]\n",
                 "t.pbrt:6: ", "index 3 (number 2) is out of range (3 vertices)");
    expect_error(PLAIN "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1]\n", "t.pbrt:4: ",
                 "has 8 values, not a multiple of 3");
    expect_error(PLAIN "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 1]\n", "t.pbrt:4: ",
                 "without 'integer indices' must have exactly 3 vertices");
    expect_error(PLAIN "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2 0]\n",
                 "t.pbrt:4: ", "not a multiple of 3");
    expect_error("Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 1e39 1]\n", "t.pbrt:1: ", "number 15 is not finite");
    expect_error("Translate 1 2 nan\n", "t.pbrt:1: ", "Translate takes 3 numbers");
    expect_error("Scale 1 0 1\nCamera \"perspective\"\n", "t.pbrt:2: ", "the current transform is singular");
    expect_error("Transform [1 0 0 0 0 1 0 0 0 0 1 1 0 0 0 1]\n", "t.pbrt:1: ", "projective");
    expect_error("Shape \"sphere\"\n", "t.pbrt:1: ", "Shape before WorldBegin");
    expect_error("WorldBegin\nCamera \"perspective\"\n", "t.pbrt:2: ", "Camera after WorldBegin");
    expect_error("WorldBegin\nAttributeEnd\n", "t.pbrt:2: ", "AttributeEnd without a matching begin");
    expect_error("WorldBegin\nShape \"sphere\" \"float radius\" [1\n", "t.pbrt:2: ", "no closing ']'");
    expect_error("WorldBegin\nShape \"sphere\" \"float radius\" \"one\"\n", "t.pbrt:2: ", "takes numbers");
    expect_error("WorldBegin\nShape \"sphere\" \"radius\" 1\n", "t.pbrt:2: ", "expected a parameter \"type name\"");
    expect_error("WorldBegin\nShape \"sphere\" \"quaternion q\" 1\n", "t.pbrt:2: ", "unknown parameter type 'quaternion'");
    expect_error("WorldBegin\nShape \"teapot\"\n", "t.pbrt:2: ", "unknown shape \"teapot\"");
    expect_error("WorldBegin\nMaterial \"velvet\"\n", "t.pbrt:2: ", "unknown material type \"velvet\"");
    expect_error("WorldBegin\nNamedMaterial \"nope\"\n", "t.pbrt:2: ", "no material named \"nope\"");
    expect_error("WorldBegin\nObjectInstance \"nope\"\n", "t.pbrt:2: ", "no object named \"nope\"");
    expect_error("WorldBegin\nObjectBegin \"a\"\nObjectBegin \"b\"\n", "t.pbrt:3: ", "inside another object");
    expect_error("WorldBegin\nObjectBegin \"a\"\nShape \"sphere\"\n", "t.pbrt:2: ", "has no ObjectEnd");
    expect_error("WorldBegin\nShape \"sphere\" \"float radius\" 1 \"float radius\" 2\n", "t.pbrt:2: ", "given twice");
    expect_error("WorldBegin\n\"stray\"\n", "t.pbrt:2: ", "expected a directive");
    expect_error("WorldBegin\nInclude \"no_such.pbrt\"\n", "t.pbrt:2: Include: ", "no_such.pbrt");
    expect_error("WorldBegin\n\n\"unterminated\n", "t.pbrt:3: ", "past the end of its line");
    expect_error(PLAIN "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0 0 0 1 0 -1 0] "
                       "\"integer indices\" [0 1 2 0 1 3 0 1 4]\n",
                 "t.pbrt:4: ", "shared by more than two triangles");
    expect_error(PLAIN "Shape \"loopsubdiv\" \"integer levels\" 12 \"point3 P\" [0 0 0 1 0 0 0 1 0 0 0 1] "
                       "\"integer indices\" [0 1 2 0 3 1 0 2 3 1 3 2]\n",
                 "t.pbrt:4: ", "more than");
    expect_error("WorldBegin\n\nShape \"plymesh\" \"string filename\" \"no_such_mesh.ply\"\n", "t.pbrt:3: plymesh: ",
                 "no_such_mesh.ply");
    expect_error("LookAt 0 0 0  0 0 0  0 1 0\n", "t.pbrt:1: ", "the same point");
    expect_error("WorldBegin\nLightSource \"spot\" \"point3 from\" [0 0 0] \"point3 to\" [0 0 0]\n", "t.pbrt:2: ",
                 "no direction");
    /* a directive of 32 bytes or more that ends the (data, size) buffer: the
     * message quotes its bytes and nothing past the end (fuzzed: it read up
     * to 40 bytes from a token that is not NUL-terminated) */
    {
        const char text[] = "WorldBegin\nUnknownDirectiveNameOf32Bytes___PAST THE END";
        const size_t size = sizeof text - 1 - strlen("PAST THE END");
        pk_context *ctx;
        REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
        pk_scene *s = NULL;
        REQUIRE(scene_create(ctx, "t.pbrt", &s) == PK_OK);
        CHECK(scene_pbrt_parse(ctx, s, text, size, "t.pbrt", PK_TEST_DATA "/pbrt") == PK_ERR_PARSE);
        const char *m = pk_context_error(ctx);
        CHECKF(strcmp(m, "t.pbrt:2: unknown directive 'UnknownDirectiveNameOf32Bytes___'") == 0, "message \"%s\"", m);
        scene_destroy(s);
        pk_context_destroy(ctx);
    }
    expect_error("Frobnicate_the_scene_with_a_name_well_beyond_forty_bytes 1\n", "t.pbrt:1: ",
                 "unknown directive 'Frobnicate_the_scene_with_a_name_well_be'");
    /* a world without lights renders black, as in pbrt: no default environment */
    pk_context *ctx;
    pk_scene *s = load(&ctx, "WorldBegin\nShape \"sphere\"\n");
    if (s) CHECK(s->env.set && v3_max_comp(s->env.radiance) == 0.0f && !s->env.map);
    done(ctx, s);
    /* unused parameters are warned about with their line */
    s = load(&ctx, "WorldBegin\nLightSource \"point\"\nShape \"sphere\"\n  \"float wobble\" 3\n");
    if (s) CHECK(warning_log_has(&warnings, "t.pbrt:4: Shape \"sphere\": parameter 'float wobble' is not supported"));
    done(ctx, s);
}

int main(void)
{
    test_tokenizer();
    test_transforms();
    test_camera();
    test_materials();
    test_layer_walk();
    test_lights();
    test_equal_area();
    test_loop();
    test_shapes();
    test_objects();
    test_errors();
    return test_done("test_pbrt");
}

/*
 * test_json_materials.c - the physically based JSON material types
 * (docs/materials.md, docs/scene-format.md): each type with its defaults and
 * with explicit values, the MTL fields each sets for the Whitted integrator,
 * keys that do not belong to a type, and the exact text of each refusal.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "scene/scene.h"

#define NAME "scene.json"

static warning_log wl;

static pk_context *new_ctx(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wl);
    return ctx;
}

static pk_status parse(pk_context *ctx, const char *json, pk_scene **out)
{
    REQUIRE(scene_create(ctx, NAME, out) == PK_OK);
    return scene_json_parse(ctx, *out, json, strlen(json), NAME, PK_TEST_DATA);
}

static bool near3(vec3 a, float x, float y, float z, float tol)
{
    return fabsf(a.x - x) <= tol && fabsf(a.y - y) <= tol && fabsf(a.z - z) <= tol;
}

/* Parses {"materials": {"m": <body>}} and returns a copy of material m. */
static material one(const char *body)
{
    char json[1024];
    snprintf(json, sizeof json, "{\"materials\": {\"m\": %s}}", body);
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx, json, &s);
    CHECKF(st == PK_OK, "%s: %s", body, pk_context_error(ctx));
    material m;
    material_init(&m);
    int64_t i = scene_find_material(s, "m");
    CHECKF(i >= 0, "%s: no material m", body);
    if (i >= 0) m = s->materials[i];
    m.name = NULL;
    scene_destroy(s);
    pk_context_destroy(ctx);
    return m;
}

static void test_defaults(void)
{
    material m = one("{\"kd\": [0.2, 0.3, 0.4]}"); /* no type: the MTL fields */
    CHECK(m.type == MAT_MTL && near3(m.kd, 0.2f, 0.3f, 0.4f, 0) && m.illum == 2 && m.alpha == 0.0f);

    m = one("{\"type\": \"diffuse\"}");
    CHECK(m.type == MAT_DIFFUSE && near3(m.kd, 0.5f, 0.5f, 0.5f, 0) && near3(m.ks, 0, 0, 0, 0) && m.illum == 2);
    CHECK(near3(m.ke, 0, 0, 0, 0) && !m.two_sided);

    m = one("{\"type\": \"conductor\"}"); /* copper, smooth */
    CHECK(m.type == MAT_CONDUCTOR && !m.schlick && m.alpha == 0.0f);
    CHECK(near3(m.eta, 0.2f, 0.92f, 1.1f, 0) && near3(m.k, 3.9f, 2.45f, 2.14f, 0));
    /* Whitted: a mirror weighted by the normal-incidence reflectance */
    CHECK(m.illum == 3 && near3(m.kd, 0, 0, 0, 0));
    CHECKF(near3(m.ks, (0.64f + 15.21f) / (1.44f + 15.21f), (0.0064f + 6.0025f) / (3.6864f + 6.0025f),
                 (0.01f + 4.5796f) / (4.41f + 4.5796f), 1e-5f),
           "%g %g %g", (double)m.ks.x, (double)m.ks.y, (double)m.ks.z);

    m = one("{\"type\": \"dielectric\"}");
    CHECK(m.type == MAT_DIELECTRIC && m.ni == 1.5f && m.alpha == 0.0f && near3(m.tf, 1, 1, 1, 0));
    CHECK(m.illum == 7 && near3(m.ks, 0.04f, 0.04f, 0.04f, 1e-6f) && near3(m.kd, 0, 0, 0, 0));

    m = one("{\"type\": \"plastic\"}");
    CHECK(m.type == MAT_PLASTIC && m.ni == 1.5f && m.alpha == 0.0f && near3(m.kd, 0.5f, 0.5f, 0.5f, 0));
    CHECK(m.illum == 3 && near3(m.ks, 0.04f, 0.04f, 0.04f, 1e-6f));

    m = one("{\"type\": \"emitter\"}");
    CHECK(m.type == MAT_DIFFUSE && near3(m.ke, 1, 1, 1, 0) && near3(m.kd, 0, 0, 0, 0));

    /* glTF's defaults: base colour 1, metallic 1, roughness 1, ior 1.5 */
    m = one("{\"type\": \"metallic_roughness\"}");
    CHECK(m.type == MAT_METALLIC_ROUGHNESS && near3(m.kd, 1, 1, 1, 0) && m.metallic == 1.0f && m.roughness == 1.0f);
    CHECK(m.alpha == 1.0f && m.transmission == 0.0f && m.ni == 1.5f && m.map_mr.kind == TEX_NONE);
    CHECK(m.clearcoat == 0.0f && m.clearcoat_roughness == 0.0f);
    /* Whitted: no diffuse, a Phong lobe of the base colour as wide as alpha 1 */
    CHECK(near3(material_whitted_kd(&m), 0, 0, 0, 0) && near3(m.ks, 1, 1, 1, 0) && m.illum == 2 && m.ns == 0.0f);
}

static void test_explicit(void)
{
    material m = one("{\"type\": \"diffuse\", \"albedo\": [0.1, 0.2, 1], \"two_sided\": true}");
    CHECK(m.type == MAT_DIFFUSE && near3(m.kd, 0.1f, 0.2f, 1, 0) && m.two_sided);

    m = one("{\"type\": \"conductor\", \"eta\": [1.5, 1, 0.5], \"k\": [0, 1, 2], \"roughness\": 0.5}");
    CHECK(m.type == MAT_CONDUCTOR && !m.schlick && m.alpha == 0.25f);
    CHECK(near3(m.eta, 1.5f, 1, 0.5f, 0) && near3(m.k, 0, 1, 2, 0));
    CHECK(m.illum == 2 && fabsf(m.ns - 30.0f) < 1e-4f); /* alpha = sqrt(2 / (Ns + 2)) */
    CHECK(near3(m.ks, 0.04f, 0.2f, 4.25f / 6.25f, 1e-6f));

    m = one("{\"type\": \"conductor\", \"specular\": [1, 0.8, 0.3], \"alpha\": 0.3}");
    CHECK(m.type == MAT_CONDUCTOR && m.schlick && m.alpha == 0.3f && near3(m.ks, 1, 0.8f, 0.3f, 0));

    m = one("{\"type\": \"dielectric\", \"ior\": 1.33, \"roughness\": 0.2, \"transmittance\": [1, 0.5, 0]}");
    CHECK(m.type == MAT_DIELECTRIC && m.ni == 1.33f && fabsf(m.alpha - 0.04f) < 1e-7f);
    CHECK(near3(m.tf, 1, 0.5f, 0, 0));

    /* a smooth ior 1 dielectric is allowed: light passes straight through */
    m = one("{\"type\": \"dielectric\", \"ior\": 1}");
    CHECK(m.type == MAT_DIELECTRIC && m.ni == 1.0f);

    m = one("{\"type\": \"plastic\", \"albedo\": [0.9, 0, 0], \"ior\": 2, \"roughness\": 1}");
    CHECK(m.type == MAT_PLASTIC && m.ni == 2.0f && m.alpha == 1.0f && near3(m.kd, 0.9f, 0, 0, 0));
    CHECK(m.illum == 2 && m.ns == 0.0f && near3(m.ks, 1.0f / 9.0f, 1.0f / 9.0f, 1.0f / 9.0f, 1e-6f));

    m = one("{\"type\": \"emitter\", \"radiance\": [10, 5, 0], \"two_sided\": true}");
    CHECK(near3(m.ke, 10, 5, 0, 0) && m.two_sided && near3(m.kd, 0, 0, 0, 0));

    /* an emitter over a reflecting surface */
    m = one("{\"type\": \"emitter\", \"radiance\": [2, 3, 4], \"bsdf\": {\"type\": \"plastic\", \"albedo\": [0.7, 0.7, 0.7]}}");
    CHECK(m.type == MAT_PLASTIC && near3(m.ke, 2, 3, 4, 0) && near3(m.kd, 0.7f, 0.7f, 0.7f, 0) && !m.two_sided);
    m = one("{\"type\": \"emitter\", \"bsdf\": {\"type\": \"diffuse\"}, \"two_sided\": true}");
    CHECK(m.type == MAT_DIFFUSE && near3(m.ke, 1, 1, 1, 0) && near3(m.kd, 0.5f, 0.5f, 0.5f, 0) && m.two_sided);

    /* the two_sided wrapper: its material, reflecting and emitting on both sides */
    m = one("{\"type\": \"two_sided\", \"bsdf\": {\"type\": \"conductor\", \"specular\": [1, 0.5, 0.25]}}");
    CHECK(m.type == MAT_CONDUCTOR && m.schlick && near3(m.ks, 1, 0.5f, 0.25f, 0) && m.two_sided);
    m = one("{\"type\": \"two_sided\", \"bsdf\": {\"type\": \"emitter\", \"radiance\": [5, 5, 5]}}");
    CHECK(near3(m.ke, 5, 5, 5, 0) && m.two_sided);

    /* metallic-roughness with every parameter */
    m = one("{\"type\": \"metallic_roughness\", \"base_color\": [0.8, 0.4, 0.2], \"metallic\": 0.25,"
            " \"roughness\": 0.5, \"transmission\": 0.5, \"ior\": 1.33}");
    CHECK(m.type == MAT_METALLIC_ROUGHNESS && near3(m.kd, 0.8f, 0.4f, 0.2f, 0) && m.metallic == 0.25f);
    CHECK(m.roughness == 0.5f && m.alpha == 0.25f && m.transmission == 0.5f && m.ni == 1.33f);
    /* Whitted: kd (1 - metallic) (1 - transmission); F0 0.04 and the base colour mixed by metallic */
    CHECK(near3(material_whitted_kd(&m), 0.3f, 0.15f, 0.075f, 1e-6f));
    CHECK(near3(m.ks, 0.75f * 0.04f + 0.2f, 0.75f * 0.04f + 0.1f, 0.75f * 0.04f + 0.05f, 1e-6f));
    CHECK(m.illum == 2 && fabsf(m.ns - 30.0f) < 1e-4f);
    m = one("{\"type\": \"metallic_roughness\", \"clearcoat\": 0.75, \"clearcoat_roughness\": 0.25}");
    CHECK(m.type == MAT_METALLIC_ROUGHNESS && m.clearcoat == 0.75f && m.clearcoat_roughness == 0.25f);
    m = one("{\"type\": \"metallic_roughness\", \"metallic\": 0, \"roughness\": 0}"); /* smooth: a mirror lobe */
    CHECK(m.alpha == 0.0f && m.illum == 3 && near3(m.ks, 0.04f, 0.04f, 0.04f, 1e-7f));
    CHECK(near3(material_whitted_kd(&m), 1, 1, 1, 0));
    /* the maps: base colour sRGB, metallic-roughness data */
    {
        pk_context *ctx = new_ctx();
        pk_scene *s;
        pk_status st = parse(ctx,
                             "{\"materials\": {\"m\": {\"type\": \"metallic_roughness\", \"metallic\": 0.5,"
                             " \"base_color\": {\"texture\": \"tex_rgbw.png\"},"
                             " \"metallic_roughness_map\": {\"texture\": \"tex_rgbw.png\", \"scale\": 2}}}}",
                             &s);
        CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
        const material *t = &s->materials[scene_find_material(s, "m")];
        CHECK(t->type == MAT_METALLIC_ROUGHNESS && t->map_kd.kind == TEX_IMAGE && t->map_mr.kind == TEX_IMAGE);
        CHECK(near3(t->kd, 1, 1, 1, 0) && t->metallic == 0.5f && t->map_mr.s[0] == 2.0f);
        REQUIRE(s->ntextures == 2); /* the same file, once as colour and once as data */
        CHECK(s->textures[t->map_kd.tex].srgb && !s->textures[t->map_mr.tex].srgb);
        scene_destroy(s);
        pk_context_destroy(ctx);
    }

    /* the array form (with "name") and an inline sphere material */
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx,
                         "{\"materials\": [{\"name\": \"gold\", \"type\": \"conductor\", \"specular\": [1, 0.8, 0.3]}],"
                         " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1,"
                         "   \"material\": {\"type\": \"plastic\", \"roughness\": 0.1}},"
                         "  {\"center\": [3, 0, 0], \"radius\": 1, \"material\": \"gold\"}]}",
                         &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECK(wl.count == 0);
    REQUIRE(s->nspheres == 2);
    const material *a = &s->materials[s->spheres[0].material], *b = &s->materials[s->spheres[1].material];
    CHECK(a->type == MAT_PLASTIC && fabsf(a->alpha - 0.01f) < 1e-7f);
    CHECK(b->type == MAT_CONDUCTOR && b->schlick && strcmp(b->name, "gold") == 0);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

/* Keys that do not belong to a type are reported like other unknown keys. */
static void test_foreign_keys(void)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx,
                         "{\"materials\": {\n"
                         " \"gold\": {\"type\": \"conductor\", \"kd\": [1, 0, 0],\n"
                         "  \"albedo\": [1, 1, 1]},\n"
                         " \"glass\": {\"type\": \"dielectric\", \"alpha\": 0.5}}}",
                         &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECK(wl.count == 3);
    CHECKF(strcmp(wl.msg[0], "scene.json:2: materials.gold.kd: unknown key ignored") == 0, "%s", wl.msg[0]);
    CHECKF(strcmp(wl.msg[1], "scene.json:3: materials.gold.albedo: unknown key ignored") == 0, "%s", wl.msg[1]);
    CHECKF(strcmp(wl.msg[2], "scene.json:4: materials.glass.alpha: unknown key ignored") == 0, "%s", wl.msg[2]);
    const material *g = &s->materials[scene_find_material(s, "glass")];
    CHECK(g->type == MAT_DIELECTRIC && g->alpha == 0.0f);
    scene_destroy(s);
    pk_context_destroy(ctx);
}

static void expect_error(int line, const char *json, const char *message)
{
    pk_context *ctx = new_ctx();
    pk_scene *s;
    pk_status st = parse(ctx, json, &s);
    if (st != PK_ERR_PARSE || strcmp(pk_context_error(ctx), message) != 0) {
        fprintf(stderr, "%s:%d: expected \"%s\"\n    got %d \"%s\"\n", __FILE__, line, message, (int)st,
                pk_context_error(ctx));
        test_failures++;
    }
    scene_destroy(s);
    pk_context_destroy(ctx);
}

#define EXPECT_ERROR(json, message) expect_error(__LINE__, json, message)
#define MAT(body) "{\"materials\": {\"gold\": " body "}}"

static void test_errors(void)
{
    const char *types =
        "must be one of \"diffuse\", \"conductor\", \"dielectric\", \"plastic\", \"metallic_roughness\", "
        "\"emitter\", \"two_sided\", \"interface\", \"thin_dielectric\", \"diffuse_transmission\", \"mix\", "
        "\"rough_diffuse\", \"phong\", \"coated\", \"principled\"";
    char want[512];
    snprintf(want, sizeof want, "scene.json:1: materials.gold.type: %s", types);
    EXPECT_ERROR(MAT("{\"type\": \"metal\"}"), want);
    EXPECT_ERROR(MAT("{\"type\": \"mix\", \"materials\": [\"gold\", \"x\"]}"),
                 "scene.json:1: materials.gold.materials[0]: no material named \"gold\" before this one");
    EXPECT_ERROR(MAT("{\"type\": \"mix\"}"), "scene.json:1: materials.gold: a mix needs \"materials\": the names of two materials");
    EXPECT_ERROR(MAT("{\"type\": \"mix\", \"materials\": \"a\"}"), "scene.json:1: materials.gold.materials: must be a list of two material names");
    EXPECT_ERROR("{\"materials\": {\"a\": {\"type\": \"diffuse\"}, \"gold\": {\"type\": \"mix\", \"materials\": [\"a\", 3]}}}",
                 "scene.json:1: materials.gold.materials[1]: must be a material's name");
    EXPECT_ERROR("{\"materials\": {\"a\": {\"type\": \"diffuse\"}, \"gold\": {\"type\": \"mix\", \"materials\": [\"a\", \"a\"], "
                 "\"amount\": 1.5}}}",
                 "scene.json:1: materials.gold.amount: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"phong\", \"exponent\": -1}"), "scene.json:1: materials.gold.exponent: must not be negative");
    EXPECT_ERROR(MAT("{\"type\": \"coated\", \"g\": 1}"), "scene.json:1: materials.gold.g: must be in (-1, 1)");
    EXPECT_ERROR(MAT("{\"type\": \"coated\", \"albedo\": [1, 1, 1], \"specular\": [1, 1, 1]}"),
                 "scene.json:1: materials.gold.albedo: a coated conductor (\"eta\", \"k\" or \"specular\") has no "
                 "diffuse \"albedo\"");
    EXPECT_ERROR(MAT("{\"type\": \"coated\", \"maxdepth\": 0}"), "scene.json:1: materials.gold.maxdepth: must be an integer in 1..65536");
    EXPECT_ERROR(MAT("{\"type\": \"principled\", \"eta\": 1.4, \"specular\": 0.3}"),
                 "scene.json:1: materials.gold.specular: give \"eta\" or \"specular\", not both");
    EXPECT_ERROR(MAT("{\"type\": \"principled\", \"metallic\": 1.5}"), "scene.json:1: materials.gold.metallic: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"principled\", \"sheen\": {\"image\": \"x.png\"}}"),
                 "scene.json:1: materials.gold.sheen: must be a number in 0..1");
    EXPECT_ERROR(MAT("{\"type\": 3}"), want);
    snprintf(want, sizeof want, "scene.json:2: spheres[0].material.type: %s", types);
    EXPECT_ERROR("{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1,\n \"material\": {\"type\": \"Diffuse\"}}]}",
                 want);
    EXPECT_ERROR(MAT("{\"type\": \"diffuse\", \"type\": \"plastic\"}"), "scene.json:1: materials.gold.type: duplicate key");

    /* roughness and alpha */
    EXPECT_ERROR("{\"materials\": {\n\n \"gold\": {\"type\": \"conductor\", \"roughness\": 1.5}}}",
                 "scene.json:3: materials.gold.roughness: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"roughness\": -0.1}"),
                 "scene.json:1: materials.gold.roughness: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"plastic\", \"roughness\": \"high\"}"),
                 "scene.json:1: materials.gold.roughness: must be a number");
    EXPECT_ERROR(MAT("{\"type\": \"dielectric\", \"roughness\": 1e999}"),
                 "scene.json:1: materials.gold.roughness: must be a finite number");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"alpha\": 2}"), "scene.json:1: materials.gold.alpha: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"roughness\": 0.5, \"alpha\": 0.25}"),
                 "scene.json:1: materials.gold.alpha: give \"roughness\" or \"alpha\", not both");

    /* ior */
    EXPECT_ERROR(MAT("{\"type\": \"dielectric\", \"ior\": 0}"), "scene.json:1: materials.gold.ior: must be a positive number");
    EXPECT_ERROR(MAT("{\"type\": \"plastic\", \"ior\": -1.5}"), "scene.json:1: materials.gold.ior: must be a positive number");
    EXPECT_ERROR(MAT("{\"type\": \"dielectric\", \"ior\": 1, \"roughness\": 0.1}"),
                 "scene.json:1: materials.gold.ior: must not be 1 on a rough surface (roughness > 0)");
    EXPECT_ERROR(MAT("{\"type\": \"plastic\", \"ior\": 1e999}"),
                 "scene.json:1: materials.gold.ior: must be a finite number");

    /* reflectances */
    EXPECT_ERROR(MAT("{\"type\": \"diffuse\", \"albedo\": [0.5, 1.01, 0]}"),
                 "scene.json:1: materials.gold.albedo: components must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"plastic\", \"albedo\": [-0.1, 0, 0]}"),
                 "scene.json:1: materials.gold.albedo: components must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"diffuse\", \"albedo\": [0.5, 1e999, 0]}"),
                 "scene.json:1: materials.gold.albedo: numbers must be finite");
    EXPECT_ERROR(MAT("{\"type\": \"diffuse\", \"albedo\": 0.5}"),
                 "scene.json:1: materials.gold.albedo: must be an array of 3 numbers");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"specular\": [2, 1, 1]}"),
                 "scene.json:1: materials.gold.specular: components must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"dielectric\", \"transmittance\": [1, 1, 1.5]}"),
                 "scene.json:1: materials.gold.transmittance: components must be in 0..1");

    /* conductor indices */
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"eta\": [0, 1, 1]}"),
                 "scene.json:1: materials.gold.eta: components must be positive");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"k\": [1, -1, 1]}"),
                 "scene.json:1: materials.gold.k: components must not be negative");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"k\": [1, 1e999, 1]}"), "scene.json:1: materials.gold.k: numbers must be finite");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"eta\": [1, 1, 1], \"specular\": [1, 1, 1]}"),
                 "scene.json:1: materials.gold.eta: give \"eta\" and \"k\" or \"specular\", not both");
    EXPECT_ERROR(MAT("{\"type\": \"conductor\", \"specular\": [1, 1, 1], \"k\": [1, 1, 1]}"),
                 "scene.json:1: materials.gold.k: give \"eta\" and \"k\" or \"specular\", not both");

    /* emitter */
    EXPECT_ERROR(MAT("{\"type\": \"emitter\", \"radiance\": [1, -1, 1]}"),
                 "scene.json:1: materials.gold.radiance: colour components must not be negative");
    EXPECT_ERROR(MAT("{\"type\": \"emitter\", \"radiance\": [1, 1, 1e999]}"),
                 "scene.json:1: materials.gold.radiance: numbers must be finite");
    EXPECT_ERROR(MAT("{\"type\": \"emitter\", \"two_sided\": 1}"),
                 "scene.json:1: materials.gold.two_sided: must be true or false");
    EXPECT_ERROR(MAT("{\"type\": \"emitter\", \"bsdf\": [1]}"),
                 "scene.json:1: materials.gold.bsdf: must be a material object with a \"type\" (the emitting "
                 "surface's reflection)");
    EXPECT_ERROR(MAT("{\"type\": \"emitter\", \"bsdf\": {\"type\": \"emitter\"}}"),
                 "scene.json:1: materials.gold.bsdf.type: an emitter's bsdf cannot be another emitter");
    EXPECT_ERROR(MAT("{\"type\": \"emitter\", \"bsdf\": {\"type\": \"diffuse\", \"albedo\": [2, 0, 0]}}"),
                 "scene.json:1: materials.gold.bsdf.albedo: components must be in 0..1");

    /* two_sided */
    EXPECT_ERROR(MAT("{\"type\": \"two_sided\"}"),
                 "scene.json:1: materials.gold: a two_sided material needs a \"bsdf\": a material object with a "
                 "\"type\"");
    EXPECT_ERROR(MAT("{\"type\": \"two_sided\", \"bsdf\": {\"type\": \"dielectric\"}}"),
                 "scene.json:1: materials.gold.bsdf.type: is two-sided already");
    EXPECT_ERROR(MAT("{\"type\": \"two_sided\", \"bsdf\": {\"type\": \"diffuse\"}, \"two_sided\": false}"),
                 "scene.json:1: materials.gold.two_sided: a two_sided material is two-sided by its type");

    /* metallic-roughness */
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"metallic\": 2}"),
                 "scene.json:1: materials.gold.metallic: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"transmission\": -0.5}"),
                 "scene.json:1: materials.gold.transmission: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"roughness\": {\"texture\": \"tex_rgbw.png\"}}"),
                 "scene.json:1: materials.gold.roughness: must be a number in 0..1 (textures: \"metallic_roughness_map\")");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"clearcoat_roughness\": 1.5}"),
                 "scene.json:1: materials.gold.clearcoat_roughness: must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"clearcoat\": {\"texture\": \"tex_rgbw.png\"}}"),
                 "scene.json:1: materials.gold.clearcoat: must be a number in 0..1 (textures: \"metallic_roughness_map\")");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"metallic_roughness_map\": 1}"),
                 "scene.json:1: materials.gold.metallic_roughness_map: must be a texture object");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"base_color\": [2, 0, 0]}"),
                 "scene.json:1: materials.gold.base_color: components must be in 0..1");
    EXPECT_ERROR(MAT("{\"type\": \"metallic_roughness\", \"ior\": 0}"),
                 "scene.json:1: materials.gold.ior: must be a positive number");

    /* the array form still needs a name */
    EXPECT_ERROR("{\"materials\": [{\"type\": \"diffuse\"}]}", "scene.json:1: materials[0]: missing \"name\"");
    EXPECT_ERROR("{\"materials\": {\"gold\": [1]}}", "scene.json:1: materials.gold: must be an object");
}

/* The thin dielectric, diffuse transmission, mix, rough diffuse and Phong
 * types: defaults, values and the mix's references. */
static void test_sheets(void)
{
    material m = one("{\"type\": \"thin_dielectric\"}");
    CHECK(m.type == MAT_THIN_DIELECTRIC && near3(m.eta, 1.5f, 1.5f, 1.5f, 0) && near3(m.tf, 1, 1, 1, 0) && m.ni == 1.0f);
    m = one("{\"type\": \"thin_dielectric\", \"ior\": 1.33, \"transmittance\": [0.9, 0.8, 0.7]}");
    CHECK(m.eta.x == 1.33f && near3(m.tf, 0.9f, 0.8f, 0.7f, 0));
    m = one("{\"type\": \"diffuse_transmission\"}"); /* pbrt-v4's defaults */
    CHECK(m.type == MAT_DIFFUSE_TRANSMISSION && near3(m.kd, 0.25f, 0.25f, 0.25f, 0) && near3(m.tf, 0.25f, 0.25f, 0.25f, 0));
    m = one("{\"type\": \"diffuse_transmission\", \"albedo\": [0.5, 0.4, 0.3], \"transmittance\": [0.1, 0.2, 0.3]}");
    CHECK(near3(m.kd, 0.5f, 0.4f, 0.3f, 0) && near3(m.tf, 0.1f, 0.2f, 0.3f, 0));
    m = one("{\"type\": \"rough_diffuse\"}");
    CHECK(m.type == MAT_ROUGH_DIFFUSE && near3(m.kd, 0.5f, 0.5f, 0.5f, 0) && m.alpha == 0.2f);
    m = one("{\"type\": \"rough_diffuse\", \"alpha\": 0.6, \"albedo\": [0.2, 0.3, 0.4]}");
    CHECK(m.alpha == 0.6f && near3(m.kd, 0.2f, 0.3f, 0.4f, 0));
    m = one("{\"type\": \"phong\"}"); /* Mitsuba's defaults */
    CHECK(m.type == MAT_PHONG && near3(m.kd, 0.5f, 0.5f, 0.5f, 0) && near3(m.ks, 0.2f, 0.2f, 0.2f, 0) && m.ns == 30.0f);
    m = one("{\"type\": \"phong\", \"albedo\": [0.8, 0.8, 0.8], \"specular\": [0.4, 0.2, 0.2], \"exponent\": 7}");
    CHECK(near3(m.kd, 0.8f / 1.2f, 0.8f, 0.8f, 1e-6f) && near3(m.ks, 0.4f / 1.2f, 0.2f, 0.2f, 1e-6f) && m.ns == 7.0f);
    m = one("{\"type\": \"coated\"}"); /* pbrt-v4's coateddiffuse defaults */
    CHECK(m.type == MAT_COATED && m.coat_base == MATERIAL_BASE_DIFFUSE && near3(m.kd, 0.5f, 0.5f, 0.5f, 0) &&
          m.ni == 1.5f && m.alpha == 0.0f && m.layer.thickness == 0.01f && m.layer.maxdepth == 10 &&
          m.layer.nsamples == 1 && m.layer.g == 0.0f && near3(m.layer.albedo, 0, 0, 0, 0));
    m = one("{\"type\": \"coated\", \"eta\": [0.2, 0.9, 1.1], \"k\": [3.9, 2.4, 2.1], \"base_roughness\": 0.5, "
            "\"roughness\": 0.2, \"thickness\": 0.1, \"layer_albedo\": [0.5, 0.6, 0.7], \"g\": -0.3, "
            "\"maxdepth\": 20, \"nsamples\": 3}");
    CHECK(m.type == MAT_COATED && m.coat_base == MATERIAL_BASE_CONDUCTOR && !m.schlick && near3(m.eta, 0.2f, 0.9f, 1.1f, 0) &&
          m.base_alpha == 0.25f && fabsf(m.alpha - 0.04f) < 1e-7f && m.layer.thickness == 0.1f &&
          near3(m.layer.albedo, 0.5f, 0.6f, 0.7f, 0) && m.layer.g == -0.3f && m.layer.maxdepth == 20 &&
          m.layer.nsamples == 3);
    m = one("{\"type\": \"coated\", \"specular\": [0.9, 0.6, 0.4], \"base_alpha\": 0.1}");
    CHECK(m.type == MAT_COATED && m.coat_base == MATERIAL_BASE_CONDUCTOR && m.schlick && near3(m.ks, 0.9f, 0.6f, 0.4f, 0) &&
          m.base_alpha == 0.1f);
    /* Mitsuba's principled: its defaults (specular 0.5 is eta 1.5), every parameter, specular for eta */
    m = one("{\"type\": \"principled\"}");
    CHECK(m.type == MAT_PRINCIPLED && near3(m.kd, 0.5f, 0.5f, 0.5f, 0) && m.roughness == 0.5f && m.metallic == 0.0f &&
          fabsf(m.ni - 1.5f) < 1e-5f && m.anisotropic == 0.0f && m.srate_spec == 1.0f && !material_anisotropic(&m));
    m = one("{\"type\": \"principled\", \"base_color\": [0.9, 0.6, 0.2], \"roughness\": 0.3, \"metallic\": 0.7, "
            "\"spec_trans\": 0.2, \"anisotropic\": 0.5, \"spec_tint\": 0.1, \"sheen\": 0.4, \"sheen_tint\": 0.6, "
            "\"flatness\": 0.25, \"clearcoat\": 0.8, \"clearcoat_gloss\": 0.9, \"eta\": 1.33, "
            "\"clearcoat_sampling_rate\": 2}");
    CHECK(m.type == MAT_PRINCIPLED && near3(m.kd, 0.9f, 0.6f, 0.2f, 0) && m.roughness == 0.3f && m.metallic == 0.7f &&
          m.transmission == 0.2f && m.anisotropic == 0.5f && m.spec_tint == 0.1f && m.sheen == 0.4f &&
          m.sheen_tint == 0.6f && m.flatness == 0.25f && m.clearcoat == 0.8f && m.clearcoat_gloss == 0.9f &&
          m.ni == 1.33f && m.srate_cc == 2.0f && m.srate_diff == 1.0f && material_anisotropic(&m));
    /* calc_dist_params: ax = r^2 / sqrt(1 - 0.9 anisotropic), ay = r^2 sqrt(...) */
    CHECK(fabsf(m.ax - 0.09f / sqrtf(0.55f)) < 1e-6f && fabsf(m.ay - 0.09f * sqrtf(0.55f)) < 1e-6f && wl.count == 0);
    m = one("{\"type\": \"principled\", \"specular\": 0.3}");
    CHECK(fabsf(m.ni - (2.0f / (1.0f - sqrtf(0.024f)) - 1.0f)) < 1e-5f);
    /* a mix names materials before it; a mix of mixes */
    pk_context *ctx = new_ctx();
    pk_scene *s = NULL;
    pk_status st = parse(ctx,
                         "{\"materials\": {\"a\": {\"type\": \"diffuse\"}, \"b\": {\"type\": \"phong\"},"
                         " \"ab\": {\"type\": \"mix\", \"materials\": [\"a\", \"b\"], \"amount\": 0.25},"
                         " \"abb\": {\"type\": \"mix\", \"materials\": [\"ab\", \"b\"]}}}",
                         &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    if (st == PK_OK) {
        const material *ab = &s->materials[scene_find_material(s, "ab")], *abb = &s->materials[scene_find_material(s, "abb")];
        CHECK(ab->type == MAT_MIX && ab->amount == 0.25f && ab->mix_a == scene_find_material(s, "a") &&
              ab->mix_b == scene_find_material(s, "b"));
        CHECK(abb->type == MAT_MIX && abb->amount == 0.5f && abb->mix_a == scene_find_material(s, "ab"));
        CHECK(scene_mix_depth(s, (uint32_t)scene_find_material(s, "abb")) == 2 && wl.count == 0);
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
}

int main(void)
{
    test_sheets();
    test_defaults();
    test_explicit();
    test_foreign_keys();
    test_errors();
    return test_done("test_json_materials");
}

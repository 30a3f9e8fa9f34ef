/*
 * test_bump_aniso.c - pbrt-v4's material "displacement" as a bump map, and
 * the tangent frame of anisotropic roughness, at a hit on a pbrt quad
 * (surface_at, surface_texture, shading_at): a height that is a linear
 * function of u tilts the shading normal by the closed-form angle; a
 * constant displacement changes nothing; the shading frame's x axis follows
 * dp/du of the uv parameterisation (or, without uvs, pbrt's default uvs);
 * the readers give two roughnesses where their formats do (pbrt, Mitsuba,
 * JSON) and average them, with a warning, where they do not.
 */
#include "test.h"

#include "paprsek.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "warnings.h"

static pk_context *ctx;

/* A 2 x 2 quad in z = 0 (triangles (0,0) (2,0) (2,2) and (0,0) (2,2) (0,2),
 * normal +z) with uv (0,0) (1,0) (1,1) (0,1), or uvs turned by 90 degrees
 * (u along y) with turned, none without "point2 uv"; material is pbrt text
 * (with its textures). The pbrt reader mirrors the world (pbrt's camera
 * space is left-handed), so directions are checked against the world's
 * vertices. */
static pk_scene *quad(const char *mat, int uvs)
{
    char text[2048];
    const char *uv = uvs == 0   ? ""
                     : uvs == 1 ? "\"point2 uv\" [0 0  1 0  1 1  0 1]"
                                : "\"point2 uv\" [0 1  0 0  1 0  1 1]";
    snprintf(text, sizeof text,
             "LookAt 1 1 5  1 1 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n%s\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
             "  \"point3 P\" [0 0 0  2 0 0  2 2 0  0 2 0] %s\n",
             mat, uv);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_memory(ctx, "pbrt", text, strlen(text), "quad.pbrt", ".", &s);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK);
    return s;
}

/* The world direction in which u grows on the first triangle: from its
 * corner of uv (0, 0) to its corner of uv (1, 0) (with every uv layout of
 * quad() the two share an edge with v = 0). The reader mirrors and may
 * reorder corners, so they are found by their uvs. */
static vec3 u_dir(const pk_scene *s)
{
    const scene_view v = scene_view_of(s);
    view_tri t;
    view_tri_get(&v, 0, &t);
    REQUIRE(t.has_t);
    vec3 a = v3s(0.0f), b = v3s(0.0f);
    for (int k = 0; k < 3; k++) {
        if (t.t[k].u == 0.0f && t.t[k].v == 0.0f) a = t.p[k];
        if (t.t[k].u == 1.0f && t.t[k].v == 0.0f) b = t.p[k];
    }
    return v3_norm(v3_sub(b, a));
}

/* The shaded surface where a ray straight down meets the first triangle at
 * (1.4, 0.6) (barycentrics u 0.4, v 0.3), its texture maps applied. */
static surface shade(const pk_scene *s, material *tm)
{
    const scene_view v = scene_view_of(s);
    const ray r = {{1.4f, 0.6f, 5.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
    const hit h = {5.0f, 0, 0.4f, 0.3f};
    surface sf = surface_at(&v, &r, &h);
    if (sf.m->textured) sf = surface_texture(&v, &r, &h, 0.0f, sf, tm);
    return sf;
}

static void test_displacement(void)
{
    /* heights h u: the slope is h / 2 on the quad (u runs 0..1 over its
     * side of 2), so the normal tilts by atan(h / 2) against dp/du */
    static const float hs[] = {0.1f, 0.5f, 2.0f};
    for (int i = 0; i < 3; i++) {
        char mat[512];
        snprintf(mat, sizeof mat,
                 "Texture \"h\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 \"float v10\" %g \"float v11\" %g\n"
                 "Material \"diffuse\" \"texture displacement\" \"h\"",
                 (double)hs[i], (double)hs[i]);
        pk_scene *s = quad(mat, 1);
        material tm;
        const surface sf = shade(s, &tm);
        CHECK(sf.m->map_bump.kind == TEX_EXPR);
        const vec3 du = u_dir(s);
        const double want = atan(0.5 * (double)hs[i]), got = acos(fmin(1.0, (double)sf.ns.z));
        const float along = v3_dot(sf.ns, du), across = v3_len(v3_sub(sf.ns, v3_add(v3_scale(du, along), v3(0, 0, sf.ns.z))));
        /* the finite difference over du = 0.0005 (no footprint: pbrt's
         * fallback) of heights of size h, each rounded to a float epsilon:
         * a slope error of about 2 eps h / du in u, half that in x */
        const double tol = 2.0 * 1.2e-7 * (double)hs[i] / 0.0005 + 1e-6;
        CHECKF(fabs(got - want) <= tol && along < 0.0f && across < 1e-5f,
               "height %g u: normal (%g %g %g) tilted %.6f rad, closed form %.6f (tol %.2g)", (double)hs[i],
               (double)sf.ns.x, (double)sf.ns.y, (double)sf.ns.z, got, want, tol);
        pk_scene_destroy(s);
    }
    /* a constant displacement: a float, a constant texture, and a procedural
     * one of equal corners, which is bumped but has no slope */
    const char *consts[3] = {
        "Material \"diffuse\" \"float displacement\" 0.3",
        "Texture \"c\" \"float\" \"constant\" \"float value\" 0.3\nMaterial \"diffuse\" \"texture displacement\" \"c\"",
        "Texture \"c\" \"float\" \"bilerp\" \"float v00\" 0.3 \"float v01\" 0.3 \"float v10\" 0.3 \"float v11\" 0.3\n"
        "Material \"diffuse\" \"texture displacement\" \"c\"",
    };
    for (int i = 0; i < 3; i++) {
        pk_scene *s = quad(consts[i], 1);
        material tm;
        const surface sf = shade(s, &tm);
        CHECK(i == 2 ? sf.m->map_bump.kind == TEX_EXPR : !sf.m->textured);
        CHECKF(sf.ns.x == 0.0f && sf.ns.y == 0.0f && sf.ns.z == 1.0f, "constant displacement %d: normal %g %g %g", i,
               (double)sf.ns.x, (double)sf.ns.y, (double)sf.ns.z);
        pk_scene_destroy(s);
    }
}

static void test_tangent_frame(void)
{
    const char *aniso = "Material \"conductor\" \"float uroughness\" 0.01 \"float vroughness\" 0.2";
    /* u along x, u along y (turned uvs), and without uvs: pbrt's default
     * uvs (0,0) (1,0) (1,1) make dp/du the first edge, (2, 0, 0) */
    const int uvs[3] = {1, 2, 0};
    for (int i = 0; i < 3; i++) {
        pk_scene *s = quad(aniso, uvs[i]);
        const vec3 want = u_dir(s);
        material tm;
        const surface sf = shade(s, &tm);
        REQUIRE(sf.m->type == MAT_CONDUCTOR);
        CHECK(material_anisotropic(sf.m) && fabsf(sf.m->alpha - 0.1f) < 1e-6f &&
              fabsf(sf.m->alpha_v - sqrtf(0.2f)) < 1e-6f);
        const shading sh = shading_at(&sf);
        CHECK(sh.b.flags & PBSDF_ANISO);
        CHECKF(v3_len(v3_sub(sh.frame.s, want)) < 1e-6f && v3_len(v3_sub(sh.frame.n, v3(0.0f, 0.0f, 1.0f))) < 1e-6f,
               "uvs %d: frame s (%g %g %g) n (%g %g %g), want s (%g %g %g)", uvs[i], (double)sh.frame.s.x, (double)sh.frame.s.y, (double)sh.frame.s.z, (double)sh.frame.n.x, (double)sh.frame.n.y, (double)sh.frame.n.z, (double)want.x, (double)want.y, (double)want.z);
        pk_scene_destroy(s);
    }
    /* equal roughnesses: isotropic, the frame onb_from_normal's */
    pk_scene *s = quad("Material \"conductor\" \"float uroughness\" 0.1 \"float vroughness\" 0.1", 1);
    material tm;
    const surface sf = shade(s, &tm);
    CHECK(!material_anisotropic(sf.m) && !sf.m->textured);
    const shading sh = shading_at(&sf);
    const onb f = onb_from_normal(sf.ns);
    CHECK(!(sh.b.flags & PBSDF_ANISO) && memcmp(&sh.frame, &f, sizeof f) == 0);
    pk_scene_destroy(s);
}

/* The material of scene text in format fmt, with its warnings. */
static material first_material(const char *fmt, const char *text, warning_log *w)
{
    warning_log_clear(w);
    warning_log_attach(ctx, w);
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_memory(ctx, fmt, text, strlen(text), "m", ".", &s);
    pk_context_set_warning_handler(ctx, NULL, NULL);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(st == PK_OK && s->nmaterials >= 1);
    /* the scene's one conductor, dielectric, plastic or coated material (a default material may come first) */
    material m = s->materials[0];
    for (size_t i = 0; i < s->nmaterials; i++)
        if (s->materials[i].type == MAT_CONDUCTOR || s->materials[i].type == MAT_DIELECTRIC ||
            s->materials[i].type == MAT_PLASTIC || s->materials[i].type == MAT_COATED)
            m = s->materials[i];
    m.name = NULL;
    pk_scene_destroy(s);
    return m;
}

static void test_readers(void)
{
    static warning_log w;
    material m;
    /* Mitsuba: alpha_u along dp/du on roughconductor and roughdielectric */
    m = first_material("xml",
                       "<scene version=\"0.6.0\"><bsdf type=\"roughconductor\" id=\"a\"><float name=\"alpha_u\" "
                       "value=\"0.05\"/><float name=\"alpha_v\" value=\"0.3\"/></bsdf>"
                       "<shape type=\"sphere\"><ref id=\"a\"/></shape></scene>",
                       &w);
    CHECKF(m.type == MAT_CONDUCTOR && m.alpha == 0.05f && m.alpha_v == 0.3f && m.beckmann && w.count == 0,
           "roughconductor: alpha %g alpha_v %g, %d warnings: %s", (double)m.alpha, (double)m.alpha_v, w.count, w.all);
    m = first_material("xml",
                       "<scene version=\"0.6.0\"><bsdf type=\"roughdielectric\" id=\"a\"><string name=\"distribution\" "
                       "value=\"ggx\"/><float name=\"alpha_u\" value=\"0.2\"/><float name=\"alpha_v\" value=\"0.1\"/>"
                       "</bsdf><shape type=\"sphere\"><ref id=\"a\"/></shape></scene>",
                       &w);
    CHECK(m.type == MAT_DIELECTRIC && m.alpha == 0.2f && m.alpha_v == 0.1f && !m.beckmann && w.count == 0);
    /* roughplastic has no alpha_u/alpha_v in Mitsuba: their mean, warned */
    m = first_material("xml",
                       "<scene version=\"0.6.0\"><bsdf type=\"roughplastic\" id=\"a\"><float name=\"alpha_u\" "
                       "value=\"0.1\"/><float name=\"alpha_v\" value=\"0.3\"/></bsdf>"
                       "<shape type=\"sphere\"><ref id=\"a\"/></shape></scene>",
                       &w);
    CHECKF(m.type == MAT_PLASTIC && fabsf(m.alpha - 0.2f) < 1e-6f && m.alpha_v < 0.0f &&
               strstr(w.all, "anisotropic roughness is not supported here"),
           "roughplastic: alpha %g alpha_v %g: %s", (double)m.alpha, (double)m.alpha_v, w.all);
    /* JSON */
    m = first_material("json",
                       "{\"materials\": {\"m\": {\"type\": \"conductor\", \"alpha_u\": 0.05, \"alpha_v\": 0.3}},"
                       " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}]}",
                       &w);
    CHECK(m.type == MAT_CONDUCTOR && m.alpha == 0.05f && m.alpha_v == 0.3f && w.count == 0);
    m = first_material("json",
                       "{\"materials\": {\"m\": {\"type\": \"dielectric\", \"roughness\": 0.5, \"alpha_v\": 0.1}},"
                       " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}]}",
                       &w);
    CHECK(m.type == MAT_DIELECTRIC && m.alpha == 0.25f && m.alpha_v == 0.1f);
    /* pbrt: the coated materials keep the mean (and say so) */
    m = first_material("pbrt",
                       "WorldBegin\nMaterial \"coateddiffuse\" \"float uroughness\" 0.04 \"float vroughness\" 0.16\n"
                       "Shape \"sphere\"\n",
                       &w);
    CHECKF(m.type == MAT_COATED && fabsf(m.alpha - 0.3f) < 1e-6f && m.alpha_v < 0.0f &&
               strstr(w.all, "is rendered isotropic"),
           "coateddiffuse: alpha %g alpha_v %g: %s", (double)m.alpha, (double)m.alpha_v, w.all);
    m = first_material("pbrt",
                       "WorldBegin\nMaterial \"dielectric\" \"float uroughness\" 0.04 \"float vroughness\" 0.16 "
                       "\"bool remaproughness\" false\nShape \"sphere\"\n",
                       &w);
    CHECK(m.type == MAT_DIELECTRIC && m.alpha == 0.04f && m.alpha_v == 0.16f && w.count == 0);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    test_displacement();
    test_tangent_frame();
    test_readers();
    pk_context_destroy(ctx);
    if (test_failures) fprintf(stderr, "%d check(s) failed\n", test_failures);
    return test_failures ? 1 : 0;
}

/*
 * test_material.c - the material model's constructors (scene/material.h):
 * each kind's physically based parameters, its Whitted approximation
 * against values worked out by hand, and that a constructor leaves alone
 * what is not its kind's (name, maps, dissolve, emission, two-sidedness).
 */
#include "test.h"

#include "scene/material.h"

static bool near(float a, float b, float tol) { return fabsf(a - b) <= tol; }
static bool v3_near(vec3 a, vec3 b, float tol) { return near(a.x, b.x, tol) && near(a.y, b.y, tol) && near(a.z, b.z, tol); }

/* A material with everything a constructor must keep set to something. */
static material dressed(void)
{
    material m;
    material_init(&m);
    m.name = (char *)"kept";
    m.d = 0.25f;
    m.ke = v3(1.0f, 2.0f, 3.0f);
    m.two_sided = true;
    m.map_kd.kind = TEX_CHECKER;
    return m;
}

static void check_kept(const material *m, const char *what)
{
    CHECKF(m->name && strcmp(m->name, "kept") == 0 && m->d == 0.25f && m->two_sided && m->map_kd.kind == TEX_CHECKER &&
               m->ke.x == 1.0f && m->ke.y == 2.0f && m->ke.z == 3.0f,
           "%s changed what is not its kind's", what);
}

int main(void)
{
    material m;
    material_init(&m);
    CHECK(m.type == MAT_MTL && m.illum == 2 && m.d == 1.0f && m.ni == 1.0f && m.kd.x == 0.8f && !m.name);

    /* normal-incidence reflectances: (n-1)^2/(n+1)^2 and, with absorption,
     * ((n-1)^2 + k^2) / ((n+1)^2 + k^2) */
    CHECK(near(material_f0_dielectric(1.5f), 0.04f, 1e-7f));
    CHECK(material_f0_dielectric(1.0f) == 0.0f);
    vec3 f0 = material_f0_conductor(v3(1.0f, 2.0f, 0.5f), v3(0.0f, 1.0f, 2.0f));
    CHECK(v3_near(f0, v3(0.0f, 2.0f / 10.0f, 4.25f / 6.25f), 1e-6f));

    m = dressed();
    material_diffuse(&m, v3(0.1f, 0.2f, 0.3f));
    CHECK(m.type == MAT_DIFFUSE && m.kd.x == 0.1f && m.kd.z == 0.3f && m.illum == 2);
    check_kept(&m, "diffuse");

    /* a smooth metal is an ideal mirror weighted by its reflectance for
     * Whitted (illum 3); a rough one a Phong lobe of Ns = 2 / alpha^2 - 2 */
    m = dressed();
    material_conductor(&m, v3(1.0f, 2.0f, 0.5f), v3(0.0f, 1.0f, 2.0f), 0.0f);
    CHECK(m.type == MAT_CONDUCTOR && !m.schlick && m.eta.y == 2.0f && m.k.z == 2.0f && m.alpha == 0.0f);
    CHECK(v3_near(m.ks, f0, 0.0f) && m.kd.x == 0.0f && m.illum == 3);
    check_kept(&m, "conductor");
    m = dressed();
    material_conductor(&m, v3(1.0f, 2.0f, 0.5f), v3(0.0f, 1.0f, 2.0f), 0.5f);
    CHECK(m.illum == 2 && near(m.ns, 6.0f, 1e-5f) && m.alpha == 0.5f);

    m = dressed();
    material_conductor_f0(&m, v3(1.0f, 0.78f, 0.34f), 0.1f);
    CHECK(m.type == MAT_CONDUCTOR && m.schlick && m.ks.y == 0.78f && m.kd.x == 0.0f && m.illum == 2);
    CHECK(near(m.ns, 198.0f, 1e-2f));
    check_kept(&m, "conductor_f0");

    /* glass: illum 7 with Ks the normal reflectance, whatever the roughness */
    m = dressed();
    material_dielectric(&m, 1.5f, 0.2f, v3(0.9f, 1.0f, 0.8f));
    CHECK(m.type == MAT_DIELECTRIC && m.ni == 1.5f && m.alpha == 0.2f && m.tf.z == 0.8f);
    CHECK(m.illum == 7 && near(m.ks.x, 0.04f, 1e-7f) && m.kd.x == 0.0f);
    check_kept(&m, "dielectric");

    /* plastic: the base as Kd, the coat's reflectance as Ks */
    m = dressed();
    material_plastic(&m, v3(0.5f, 0.4f, 0.3f), 1.5f, 0.0f);
    CHECK(m.type == MAT_PLASTIC && m.kd.y == 0.4f && m.ni == 1.5f && near(m.ks.z, 0.04f, 1e-7f) && m.illum == 3);
    check_kept(&m, "plastic");
    m = dressed();
    material_plastic(&m, v3(0.5f, 0.4f, 0.3f), 1.5f, 1.0f);
    CHECK(m.illum == 2 && m.ns == 0.0f); /* alpha 1: the widest lobe, Ns 0 */
    return test_done("test_material");
}

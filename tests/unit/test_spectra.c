/*
 * test_spectra.c - scene/spectra.c: the colour matching functions near their
 * peaks, a flat spectrum as grey (the white point), a blackbody's colour
 * order and Wien's law, the named metal and index-of-refraction tables.
 */
#include "test.h"

#include "scene/spectra.h"

static void test_cie(void)
{
    float x, y, z;
    /* y peaks at 555 nm near 1; z peaks near 445 nm at about 1.78 */
    spectra_cie_xyz(555.0f, &x, &y, &z);
    CHECK_NEAR(y, 1.0, 0.02);
    spectra_cie_xyz(445.0f, &x, &y, &z);
    CHECK_NEAR(z, 1.78, 0.05);
    spectra_cie_xyz(830.0f, &x, &y, &z);
    CHECK(x < 1e-3f && y < 1e-3f && z < 1e-3f);
}

static void test_spectrum(void)
{
    /* a flat spectrum is grey of its value (the white point maps to white) */
    const float nm1[1] = {500.0f}, v1[1] = {0.25f};
    vec3 g = spectrum_to_rgb(nm1, v1, 1);
    CHECK_NEAR(g.x, 0.25, 1e-6);
    CHECK_NEAR(g.y, 0.25, 1e-6);
    CHECK_NEAR(g.z, 0.25, 1e-6);
    const float nm2[2] = {400.0f, 700.0f}, v2[2] = {0.5f, 0.5f};
    g = spectrum_to_rgb(nm2, v2, 2);
    CHECK_NEAR(g.x, 0.5, 1e-6);
    CHECK_NEAR(g.z, 0.5, 1e-6);
    /* energy only at long wavelengths is red; only at short ones blue */
    const float nm3[2] = {600.0f, 610.0f}, red[2] = {0.0f, 1.0f}, blue[2] = {1.0f, 0.0f};
    vec3 r = spectrum_to_rgb(nm3, red, 2);
    CHECK(r.x > r.y && r.x > r.z);
    const float nm4[2] = {450.0f, 460.0f};
    vec3 b = spectrum_to_rgb(nm4, blue, 2);
    CHECK(b.z > b.x && b.z > b.y);
    CHECK(b.x >= 0.0f && b.y >= 0.0f); /* negative channels clamped */
}

static void test_blackbody(void)
{
    vec3 cool = blackbody_rgb(2000.0f), hot = blackbody_rgb(10000.0f), mid = blackbody_rgb(5455.0f);
    CHECK(v3_finite(cool) && v3_finite(hot) && v3_finite(mid));
    CHECK(cool.x > cool.z);                         /* a candle is red */
    CHECK(hot.z > hot.x);                           /* a hot star is blue */
    /* spectra are divided by the equal-energy white, whose colour
     * temperature is about 5455 K: that blackbody is near grey */
    CHECK_NEAR(mid.x / mid.z, 1.0, 0.05);
    CHECK_NEAR(mid.y / mid.z, 1.0, 0.1);
    /* radiance grows with temperature (Stefan-Boltzmann, within the visible) */
    CHECK(v3_luminance(hot) > v3_luminance(mid) && v3_luminance(mid) > v3_luminance(cool));
    /* 5000 K: Planck's law at 555 nm is about 12.7 kW m^-2 sr^-1 nm^-1, which
     * a flat spectrum of that value would give as grey; the blackbody's green
     * is within a few tens of percent of it */
    vec3 b5 = blackbody_rgb(5000.0f);
    CHECK(b5.y > 8000.0f && b5.y < 18000.0f);
}

static void test_tables(void)
{
    vec3 eta, k;
    REQUIRE(spectra_named_metal("Au", &eta, &k));
    CHECK(eta.x == 0.143119f && eta.y == 0.374957f && eta.z == 1.44248f);
    CHECK(k.x == 3.98316f && k.y == 2.38572f && k.z == 1.60322f);
    REQUIRE(spectra_named_metal("Cu", &eta, &k));
    CHECK(eta.x == 0.200438f && k.z == 2.14219f);
    vec3 keep = v3s(7.0f);
    CHECK(!spectra_named_metal("Unobtainium", &keep, &keep));
    CHECK(keep.x == 7.0f);
    CHECK(!spectra_named_metal("none", &keep, &keep));
    float ior = 0.0f;
    REQUIRE(spectra_named_ior("bk7", &ior));
    CHECK(ior == 1.5046f);
    REQUIRE(spectra_named_ior("diamond", &ior));
    CHECK(ior == 2.419f);
    REQUIRE(spectra_named_ior("vacuum", &ior));
    CHECK(ior == 1.0f);
    CHECK(!spectra_named_ior("glass", &ior));
    CHECK(ior == 1.0f);
}

int main(void)
{
    test_cie();
    test_spectrum();
    test_blackbody();
    test_tables();
    return test_done("test_spectra");
}

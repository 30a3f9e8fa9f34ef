/*
 * spectra.c - colour matching functions, spectra and blackbodies to RGB, and
 * the named metal and index-of-refraction tables (spectra.h). Moved out of
 * the Mitsuba XML reader unchanged, so that every reader shares them.
 */
#include "spectra.h"

#include <math.h>
#include <string.h>

/* CIE 1931 colour matching functions, the multi-lobe Gaussian fit of Wyman,
 * Sloan and Shirley (2013). */
static float gauss_lobe(float x, float mu, float s1, float s2)
{
    float t = (x - mu) / (x < mu ? s1 : s2);
    return expf(-0.5f * t * t);
}

void spectra_cie_xyz(float nm, float *x, float *y, float *z)
{
    *x = 1.056f * gauss_lobe(nm, 599.8f, 37.9f, 31.0f) + 0.362f * gauss_lobe(nm, 442.0f, 16.0f, 26.7f) -
         0.065f * gauss_lobe(nm, 501.1f, 20.4f, 26.2f);
    *y = 0.821f * gauss_lobe(nm, 568.8f, 46.9f, 40.5f) + 0.286f * gauss_lobe(nm, 530.9f, 16.3f, 31.1f);
    *z = 1.217f * gauss_lobe(nm, 437.0f, 11.8f, 36.0f) + 0.681f * gauss_lobe(nm, 459.0f, 26.0f, 13.8f);
}

vec3 spectrum_to_rgb(const float *nm, const float *val, int n)
{
    double X = 0, Y = 0, Z = 0, X1 = 0, Y1 = 0, Z1 = 0;
    int j = 0;
    for (float l = 360.0f; l <= 830.0f; l += 1.0f) {
        while (j + 1 < n && nm[j + 1] < l) j++;
        float v;
        if (l <= nm[0]) v = val[0];
        else if (l >= nm[n - 1]) v = val[n - 1];
        else {
            float t = (l - nm[j]) / (nm[j + 1] - nm[j]);
            v = val[j] + t * (val[j + 1] - val[j]);
        }
        float x, y, z;
        spectra_cie_xyz(l, &x, &y, &z);
        X += (double)(x * v), Y += (double)(y * v), Z += (double)(z * v);
        X1 += (double)x, Y1 += (double)y, Z1 += (double)z;
    }
    const double m[9] = {3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108,
                         0.0415560, 0.0556434,  -0.2040259, 1.0572252};
    double c[3], w[3];
    for (int i = 0; i < 3; i++) {
        c[i] = m[3 * i] * X + m[3 * i + 1] * Y + m[3 * i + 2] * Z;
        w[i] = m[3 * i] * X1 + m[3 * i + 1] * Y1 + m[3 * i + 2] * Z1;
    }
    return v3((float)fmax(c[0] / w[0], 0.0), (float)fmax(c[1] / w[1], 0.0), (float)fmax(c[2] / w[2], 0.0));
}

vec3 blackbody_rgb(float kelvin)
{
    enum { N = 95 };
    float nm[N], val[N];
    for (int i = 0; i < N; i++) {
        double l = (360.0 + 5.0 * i) * 1e-9, h = 6.62607015e-34, c = 299792458.0, kb = 1.380649e-23;
        double b = 2.0 * h * c * c / (l * l * l * l * l) / expm1(h * c / (l * kb * (double)kelvin));
        nm[i] = (float)(360.0 + 5.0 * i);
        val[i] = (float)(b * 1e-9); /* per metre -> per nanometre */
    }
    return spectrum_to_rgb(nm, val, N);
}

typedef struct metal {
    const char *name;
    float eta[3], k[3];
} metal;

/* Complex indices of refraction of a few metals at the red, green and blue
 * primaries (docs/scene-format.md); the names of Mitsuba's material table. */
static const metal metals[] = {
    {"Cu", {0.200438f, 0.924033f, 1.10221f}, {3.91295f, 2.45285f, 2.14219f}},
    {"Au", {0.143119f, 0.374957f, 1.44248f}, {3.98316f, 2.38572f, 1.60322f}},
    {"Ag", {0.155265f, 0.116723f, 0.138342f}, {4.82835f, 3.12225f, 2.14696f}},
    {"Al", {1.65746f, 0.880369f, 0.521229f}, {9.22387f, 6.26952f, 4.837f}},
    {"Cr", {4.36968f, 2.9167f, 1.6547f}, {5.20643f, 4.23136f, 3.75495f}},
};

typedef struct ior_name {
    const char *name;
    float ior;
} ior_name;

/* Mitsuba's named indices of refraction. */
static const ior_name iors[] = {
    {"vacuum", 1.0f},         {"helium", 1.000036f},     {"hydrogen", 1.000132f},     {"air", 1.000277f},
    {"carbon dioxide", 1.00045f}, {"water", 1.3330f},    {"acetone", 1.36f},          {"ethanol", 1.361f},
    {"carbon tetrachloride", 1.461f}, {"glycerol", 1.4729f}, {"benzene", 1.501f},     {"silicone oil", 1.52045f},
    {"bromine", 1.661f},      {"water ice", 1.31f},      {"fused quartz", 1.458f},    {"pyrex", 1.470f},
    {"acrylic glass", 1.49f}, {"polypropylene", 1.49f},  {"bk7", 1.5046f},            {"sodium chloride", 1.544f},
    {"amber", 1.55f},         {"pet", 1.5750f},          {"diamond", 2.419f},
};

bool spectra_named_metal(const char *name, vec3 *eta, vec3 *k)
{
    for (size_t i = 0; i < sizeof metals / sizeof metals[0]; i++)
        if (strcmp(metals[i].name, name) == 0) {
            *eta = v3(metals[i].eta[0], metals[i].eta[1], metals[i].eta[2]);
            *k = v3(metals[i].k[0], metals[i].k[1], metals[i].k[2]);
            return true;
        }
    return false;
}

bool spectra_named_ior(const char *name, float *ior)
{
    for (size_t i = 0; i < sizeof iors / sizeof iors[0]; i++)
        if (strcmp(iors[i].name, name) == 0) {
            *ior = iors[i].ior;
            return true;
        }
    return false;
}

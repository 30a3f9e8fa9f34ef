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

/* Linear sRGB (IEC 61966-2-1's matrix, D65 white) of XYZ. */
static void srgb_from_xyz(double X, double Y, double Z, double rgb[3])
{
    static const double m[9] = {3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108,
                                0.0415560, 0.0556434,  -0.2040259, 1.0572252};
    for (int i = 0; i < 3; i++) rgb[i] = m[3 * i] * X + m[3 * i + 1] * Y + m[3 * i + 2] * Z;
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
    double c[3], w[3];
    srgb_from_xyz(X, Y, Z, c);
    srgb_from_xyz(X1, Y1, Z1, w);
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

/* ---- Mitsuba's reductions of spectra to RGB ----------------------------------------------- */

#include "cie1931.inc"

/* Rec. 709 / sRGB primaries from XYZ, with the coefficients both Mitsuba
 * 0.6 and Mitsuba 3 use. */
static vec3 xyz_to_linear_srgb(double X, double Y, double Z)
{
    return v3((float)(3.240479 * X - 1.537150 * Y - 0.498535 * Z),
              (float)(-0.969256 * X + 1.875991 * Y + 0.041556 * Z),
              (float)(0.055648 * X - 0.204043 * Y + 1.057311 * Z));
}

/* The tabulated matching functions at nm, linear between the nanometres,
 * zero outside 360..830 nm. */
static void cie_1nm(double nm, double xyz[3])
{
    xyz[0] = xyz[1] = xyz[2] = 0.0;
    if (!(nm >= 360.0 && nm <= 830.0)) return;
    double t = nm - 360.0;
    int i = (int)t;
    if (i > 469) i = 469;
    double f = t - i;
    for (int c = 0; c < 3; c++) xyz[c] = (1.0 - f) * (double)cie1931_xyz[i][c] + f * (double)cie1931_xyz[i + 1][c];
}

void spectra_cie1931(float nm, float xyz[3])
{
    double d[3];
    cie_1nm(nm, d);
    for (int c = 0; c < 3; c++) xyz[c] = (float)d[c];
}

/* The samples (nm, val) with Mitsuba 0.6's zero extension: a zero sample
 * one mean spacing beyond each end whose value is not zero. */
typedef struct zext {
    const float *nm, *val;
    int n;
    double lo, hi; /* the added ends (or the first/last wavelength) */
    bool add_lo, add_hi;
} zext;

/* Mitsuba 0.5 and 0.6 as released (up to its fix of 2020-01-31, commit
 * cfeb776, after 0.6.0) evaluate a tabulated spectrum (InterpolatedSpectrum::
 * eval) with the two ends of the lerp swapped: between samples (x0, f0) and
 * (x1, f1) at t = (l - x0) / (x1 - x0) it returns (1 - t) f1 + t f0, the
 * segment mirrored within its interval (a sample's own wavelength still gives
 * its value). Its RGB build reduces a spectrum through that evaluation, both
 * for the spectrum and for the matching functions, so an emitter given as
 * 400:0, 500:16, 600:31.2, 700:36.8 (zero-extended to 800 nm) is about 12 %
 * less red there than the straight interpolation gives. Trapezoid averages
 * (InterpolatedSpectrum::average, the y normalisation) are not affected, and
 * a mirrored segment keeps its own integral. */
static double mts06_lerp(double x0, double x1, double f0, double f1, double l)
{
    double t = (l - x0) / (x1 - x0);
    return (1.0 - t) * f1 + t * f0;
}

/* The k-th sample of the zero-extended spectrum, 0 <= k < zext_count. */
static int zext_count(const zext *z) { return z->n + z->add_lo + z->add_hi; }
static void zext_node(const zext *z, int k, double *x, double *f)
{
    if (z->add_lo) {
        if (k == 0) {
            *x = z->lo, *f = 0.0;
            return;
        }
        k--;
    }
    if (k == z->n) *x = z->hi, *f = 0.0;
    else *x = (double)z->nm[k], *f = (double)z->val[k];
}

/* The matching functions on [i, i + 1] nm (360 <= i < 830) at l, as
 * Mitsuba 0.5/0.6 evaluates them (mirrored). */
static void cie_06(int i, double l, double xyz[3])
{
    const int r = i - 360;
    for (int c = 0; c < 3; c++)
        xyz[c] = mts06_lerp(i, i + 1.0, (double)cie1931_xyz[r][c], (double)cie1931_xyz[r + 1][c], l);
}

/* The integral of y over 360..830 nm by trapezoids (CIE_Y_interp.average). */
static double cie_y_integral(void)
{
    double ysum = 0.0;
    for (int i = 0; i < 470; i++) ysum += 0.5 * ((double)cie1931_xyz[i][1] + (double)cie1931_xyz[i + 1][1]);
    return ysum;
}

vec3 spectra_mitsuba06_rgb(const float *nm, const float *val, int n)
{
    if (n < 2) return v3s(0.0f);
    zext z = {nm, val, n, (double)nm[0], (double)nm[n - 1], false, false};
    double spacing = ((double)nm[n - 1] - (double)nm[0]) / (n - 1);
    if (val[0] != 0.0f) z.lo = (double)nm[0] - spacing, z.add_lo = true;
    if (val[n - 1] != 0.0f) z.hi = (double)nm[n - 1] + spacing, z.add_hi = true;
    const int count = zext_count(&z);
    /* Pieces between consecutive breakpoints (every nanometre of the table
     * and every sample of the spectrum): on each, both factors are one
     * (mirrored) linear segment, so the product is quadratic and Simpson's
     * rule is exact. The jumps the mirroring leaves at the breakpoints are
     * never evaluated: each piece uses its own segments' formulas. */
    double acc[3] = {0, 0, 0}, x0, f0, x1, f1;
    int k = 0; /* the spectrum's segment [node k, node k + 1] */
    zext_node(&z, 0, &x0, &f0);
    zext_node(&z, 1, &x1, &f1);
    for (int i = 360; i < 830; i++) {
        double a = i;
        while (a < i + 1.0) {
            while (k + 2 < count && x1 <= a) {
                k++;
                x0 = x1, f0 = f1;
                zext_node(&z, k + 1, &x1, &f1);
            }
            double b = i + 1.0;
            if (x0 > a && x0 < b) b = x0; /* before the spectrum's first sample */
            else if (x1 > a && x1 < b) b = x1;
            const bool inside = a >= x0 && b <= x1;
            const double m = 0.5 * (a + b), l[3] = {a, m, b}, wgt[3] = {1.0, 4.0, 1.0};
            for (int q = 0; inside && q < 3; q++) {
                double s = mts06_lerp(x0, x1, f0, f1, l[q]), c[3];
                cie_06(i, l[q], c);
                for (int ch = 0; ch < 3; ch++) acc[ch] += (b - a) / 6.0 * wgt[q] * s * c[ch];
            }
            a = b;
        }
    }
    const double ysum = cie_y_integral();
    vec3 c = xyz_to_linear_srgb(acc[0] / ysum, acc[1] / ysum, acc[2] / ysum);
    return v3(fmaxf(c.x, 0.0f), fmaxf(c.y, 0.0f), fmaxf(c.z, 0.0f));
}

/* Planck's law in W m^-2 sr^-1 nm^-1, with the constants Mitsuba uses. */
static double planck_nm(double nm, double kelvin)
{
    const double c = 299792458.0, k = 1.3806488e-23, h = 6.62606957e-34;
    double l = nm * 1e-9;
    return 2.0 * h * c * c / (l * l * l * l * l) / (expm1(h * c / (l * k * kelvin)) * 1e9);
}

vec3 spectra_mitsuba06_blackbody(float kelvin)
{
    /* Planck's law against the tabulated functions (linear within each
     * nanometre): composite Simpson's rule on quarter nanometres, far
     * below float precision for this smooth integrand */
    double acc[3] = {0, 0, 0};
    const int sub = 4;
    for (int i = 360; i < 830; i++)
        for (int s = 0; s < sub; s++) {
            double a = i + (double)s / sub, b = a + 1.0 / sub, m = 0.5 * (a + b), ca[3], cm[3], cb[3];
            cie_06(i, a, ca), cie_06(i, m, cm), cie_06(i, b, cb); /* mirrored, as Mitsuba evaluates them */
            double pa = planck_nm(a, kelvin), pm = planck_nm(m, kelvin), pb = planck_nm(b, kelvin);
            for (int c = 0; c < 3; c++) acc[c] += (b - a) / 6.0 * (pa * ca[c] + 4.0 * pm * cm[c] + pb * cb[c]);
        }
    const double ysum = cie_y_integral();
    vec3 c = xyz_to_linear_srgb(acc[0] / ysum, acc[1] / ysum, acc[2] / ysum);
    return v3(fmaxf(c.x, 0.0f), fmaxf(c.y, 0.0f), fmaxf(c.z, 0.0f));
}

/* Mitsuba 3's tables: the matching functions and D65 every 5 nm over
 * 360..830 nm, linear between, zero outside. */
static void mts3_tables(double w, double xyz[3], double *d65)
{
    xyz[0] = xyz[1] = xyz[2] = *d65 = 0.0;
    if (!(w >= 360.0 && w <= 830.0)) return;
    double t = (w - 360.0) * (94.0 / 470.0);
    int i = (int)t;
    if (i > 93) i = 93;
    double f = t - i;
    for (int c = 0; c < 3; c++) xyz[c] = (1.0 - f) * (double)cie1931_xyz[5 * i][c] + f * (double)cie1931_xyz[5 * i + 5][c];
    /* D65 scaled as Mitsuba 3 scales it (to about 1 near 560 nm) */
    *d65 = ((1.0 - f) * (double)cie_d65[i] + f * (double)cie_d65[i + 1]) * (1.0 / 98.99741751876255);
}

/* Mitsuba 3's sum: 1000 equally spaced wavelengths from 360 to 830 nm
 * (both included), each weighted 470/1000 nm, over 106.7502594. */
static vec3 mts3_reduce(const float *nm, const float *val, int n, double kelvin, bool emitter, bool bounded)
{
    double X = 0, Y = 0, Z = 0;
    const int steps = 1000;
    for (int i = 0; i < steps; i++) {
        double w = 360.0 + (double)i / (steps - 1) * 470.0, v;
        if (kelvin > 0.0) v = planck_nm(w, kelvin);
        else {
            if (n < 2 || w < (double)nm[0] || w > (double)nm[n - 1]) continue;
            int a = 0, b = n - 1;
            while (b - a > 1) {
                int m = (a + b) / 2;
                if ((double)nm[m] <= w) a = m;
                else b = m;
            }
            double w0 = (double)nm[a], w1 = (double)nm[a + 1];
            v = ((w - w1) * (double)val[a] + (w0 - w) * (double)val[a + 1]) / (w0 - w1);
        }
        double c[3], d65;
        mts3_tables(w, c, &d65);
        double wt = v * (emitter ? 1.0 : d65);
        X += c[0] * wt, Y += c[1] * wt, Z += c[2] * wt;
    }
    double k = 470.0 / 106.7502593994140625 / steps;
    vec3 c = xyz_to_linear_srgb(X * k, Y * k, Z * k);
    c = v3(fmaxf(c.x, 0.0f), fmaxf(c.y, 0.0f), fmaxf(c.z, 0.0f));
    if (bounded) c = v3(fminf(c.x, 1.0f), fminf(c.y, 1.0f), fminf(c.z, 1.0f));
    return c;
}

vec3 spectra_mitsuba3_rgb(const float *nm, const float *val, int n, bool emitter, bool bounded)
{
    return mts3_reduce(nm, val, n, 0.0, emitter, bounded);
}

vec3 spectra_mitsuba3_blackbody(float kelvin) { return mts3_reduce(NULL, NULL, 0, kelvin, true, false); }

vec3 spectra_mitsuba3_uniform_emitter(float value)
{
    return v3_scale(xyz_to_linear_srgb(1.0, 1.0, 1.0), value);
}

/* ---- Mitsuba 0.6's sun ------------------------------------------------------------------- */

/* Preetham, Shirley and Smits (1999), after Iqbal's "An Introduction to
 * Solar Radiation" (1983): the extraterrestrial solar radiance (W m^-2
 * nm^-1 sr^-1) every 10 nm over 380..750 nm and the absorption coefficients
 * of ozone, mixed gases and water vapour (cm^-1), paired as Mitsuba 0.6 pairs
 * them (its ozone table runs 300..355 nm, then 445..790 nm). */
static const float sun_sol[38] = {
    16559.0f, 16233.7f, 21127.5f, 25888.2f, 25829.1f, 24232.3f, 26760.5f, 29658.3f, 30545.4f, 30057.5f,
    30663.7f, 28830.4f, 28712.1f, 27825.0f, 27100.6f, 27233.6f, 26361.3f, 25503.8f, 25060.2f, 25311.6f,
    25355.9f, 25134.2f, 24631.5f, 24173.2f, 23685.3f, 23212.1f, 22827.7f, 22339.8f, 21970.2f, 21526.7f,
    21097.9f, 20728.3f, 20240.4f, 19870.8f, 19427.2f, 19072.4f, 18628.9f, 18259.2f};
static const float sun_ko_nm[64] = {
    300, 305, 310, 315, 320, 325, 330, 335, 340, 345, 350, 355, 445, 450, 455, 460, 465, 470, 475, 480, 485, 490,
    495, 500, 505, 510, 515, 520, 525, 530, 535, 540, 545, 550, 555, 560, 565, 570, 575, 580, 585, 590, 595, 600,
    605, 610, 620, 630, 640, 650, 660, 670, 680, 690, 700, 710, 720, 730, 740, 750, 760, 770, 780, 790};
static const float sun_ko[64] = {
    10.0f,  4.8f,   2.7f,  1.35f,  .8f,   .380f, .160f, .075f, .04f,  .019f, .007f, .0f,   .003f,
    .003f,  .004f,  .006f, .008f,  .009f, .012f, .014f, .017f, .021f, .025f, .03f,  .035f, .04f,
    .045f,  .048f,  .057f, .063f,  .07f,  .075f, .08f,  .085f, .095f, .103f, .110f, .12f,  .122f,
    .12f,   .118f,  .115f, .12f,   .125f, .130f, .12f,  .105f, .09f,  .079f, .067f, .057f, .048f,
    .036f,  .028f,  .023f, .018f,  .014f, .011f, .010f, .009f, .007f, .004f, .0f,   .0f};
static const float sun_kg_nm[4] = {759, 760, 770, 771}, sun_kg[4] = {0, 3.0f, 0.210f, 0};
static const float sun_kwa_nm[13] = {689, 690, 700, 710, 720, 730, 740, 750, 760, 770, 780, 790, 800};
static const float sun_kwa[13] = {0,         0.160e-1f, 0.240e-1f, 0.125e-1f, 0.100e+1f, 0.870f,    0.610e-1f,
                                  0.100e-2f, 0.100e-4f, 0.100e-4f, 0.600e-3f, 0.175e-1f, 0.360e-1f};

/* The table at t as Mitsuba 0.5/0.6 evaluates it: a sample's own value at
 * its wavelength, the mirrored segment between samples (mts06_lerp), zero
 * outside. Only the ozone table's 355..445 nm gap is read off its samples
 * and midpoints, where the mirroring shows. */
static double table_at(const float *x, const float *y, int n, double t)
{
    if (t < (double)x[0] || t > (double)x[n - 1]) return 0.0;
    for (int i = 0; i + 1 < n; i++) {
        if (t == (double)x[i]) return (double)y[i];
        if (t < (double)x[i + 1]) return mts06_lerp(x[i], x[i + 1], y[i], y[i + 1], t);
    }
    return (double)y[n - 1];
}

void spectra_mitsuba06_sun_spectrum(float zenith, float turbidity, float nm[91], float val[91])
{
    const double th = (double)zenith, beta = 0.04608365822050 * (double)turbidity - 0.04586025928522;
    /* relative optical air mass (Kasten 1966) */
    const double m = 1.0 / (cos(th) + 0.15 * pow(93.885 - th * (180.0 / 3.14159265358979323846), -1.253));
    for (int i = 0; i < 91; i++) {
        const double l = 350.0 + 5.0 * i, um = l / 1000.0;
        const double tau_r = exp(-m * 0.008735 * pow(um, -4.08));         /* Rayleigh */
        const double tau_a = exp(-m * beta * pow(um, -1.3));              /* aerosols */
        const double tau_o = exp(-m * table_at(sun_ko_nm, sun_ko, 64, l) * 0.35); /* ozone, 0.35 cm */
        const double kg = table_at(sun_kg_nm, sun_kg, 4, l);
        const double tau_g = exp(-1.41 * kg * m / pow(1.0 + 118.93 * kg * m, 0.45)); /* mixed gases */
        const double kwa = table_at(sun_kwa_nm, sun_kwa, 13, l);
        const double tau_w = exp(-0.2385 * kwa * 2.0 * m / pow(1.0 + 20.07 * kwa * 2.0 * m, 0.45)); /* 2 cm of water */
        float sol_nm[38];
        for (int k = 0; k < 38; k++) sol_nm[k] = 380.0f + 10.0f * (float)k;
        nm[i] = (float)l;
        val[i] = (float)(table_at(sol_nm, sun_sol, 38, l) * tau_r * tau_a * tau_o * tau_g * tau_w);
    }
}

vec3 spectra_mitsuba06_sun(float zenith, float turbidity)
{
    float nm[91], val[91];
    spectra_mitsuba06_sun_spectrum(zenith, turbidity, nm, val);
    return spectra_mitsuba06_rgb(nm, val, 91);
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

/* ---- pbrt-v4's rules ------------------------------------------------------------------------- */

/* Linear sRGB of the emission spectrum e(nm) (called at every nanometre of
 * 360..830), scaled to luminance 1. */
static vec3 pbrt_emitter_unit(double (*e)(const void *, double), const void *user)
{
    double X = 0, Y = 0, Z = 0;
    for (int nm = 360; nm <= 830; nm++) {
        double b = e(user, (double)nm);
        float xyz[3];
        spectra_cie1931((float)nm, xyz);
        X += b * (double)xyz[0], Y += b * (double)xyz[1], Z += b * (double)xyz[2];
    }
    if (!(Y > 0.0) || !isfinite(Y)) return v3s(1.0f);
    X /= Y, Z /= Y, Y = 1.0;
    double c[3];
    srgb_from_xyz(X, Y, Z, c);
    return v3((float)fmax(c[0], 0.0), (float)fmax(c[1], 0.0), (float)fmax(c[2], 0.0));
}

/* Planck's law in W m^-2 sr^-1 m^-1 at nm nanometres (CODATA 2018). */
static double pbrt_planck(const void *user, double nm)
{
    const double h = 6.62607015e-34, c = 2.99792458e8, kb = 1.380649e-23, l = nm * 1e-9;
    return 2.0 * h * c * c / (l * l * l * l * l) / (exp(h * c / (l * kb * *(const double *)user)) - 1.0);
}

vec3 spectra_pbrt_blackbody(float kelvin)
{
    double k = (double)kelvin;
    return pbrt_emitter_unit(pbrt_planck, &k);
}

vec3 spectra_pbrt_blackbody_peak(double kelvin)
{
    const double peak = pbrt_planck(&kelvin, 2.8977721e-3 / kelvin * 1e9);
    double y = 0.0;
    for (int nm = 360; nm <= 830; nm++) {
        float xyz[3];
        spectra_cie1931((float)nm, xyz);
        y += pbrt_planck(&kelvin, (double)nm) / peak * (double)xyz[1];
    }
    return v3_scale(spectra_pbrt_blackbody((float)kelvin), (float)y);
}

typedef struct sampled {
    const float *nm, *val;
    size_t n;
} sampled;

/* pbrt's piecewise-linear spectrum: linear between the samples, 0 outside. */
static double sampled_at(const void *user, double nm)
{
    const sampled *s = user;
    if (nm < (double)s->nm[0] || nm > (double)s->nm[s->n - 1]) return 0.0;
    size_t i = 0;
    while (i + 1 < s->n && (double)s->nm[i + 1] < nm) i++;
    if (i + 1 == s->n) return (double)s->val[i];
    double t = (nm - (double)s->nm[i]) / ((double)s->nm[i + 1] - (double)s->nm[i]);
    return (double)s->val[i] + t * ((double)s->val[i + 1] - (double)s->val[i]);
}

vec3 spectra_pbrt_emitter(const float *nm, const float *val, size_t n)
{
    const sampled sp = {nm, val, n};
    return pbrt_emitter_unit(sampled_at, &sp);
}

/* pbrt-v4's metals and oxides that Mitsuba's table does not name: measured
 * complex indices from the refractiveindex.info database (public domain,
 * CC0 1.0): brass "other/alloys/Cu-Zn/Querry-Cu70Zn30" (M. R. Querry, 1987),
 * MgO and TiO2 in the samples pbrt-v4 tabulates. Reduced to RGB as the
 * metals above are (Bitterli's table, which these rules reproduce to 4e-5):
 * XYZ over 360..830 nm against the 1 nm CIE 1931 functions, the samples
 * linear between them and held beyond the last, divided by the integral of
 * y, then Mitsuba's sRGB matrix, negative channels set to 0. The samples are
 * in tests/unit/spectra_metals.inc, where test_spectra recomputes every row. */
static const metal pbrt_metals[] = {
    {"CuZn", {0.51977f, 0.488506f, 1.04201f}, {4.33059f, 2.5481f, 1.59189f}},
    {"MgO", {2.08965f, 1.65071f, 1.59488f}, {0.0f, 0.0f, 0.0f}},
    {"TiO2", {3.45663f, 2.80171f, 2.90516f}, {0.000102587f, 0.0f, 0.000635063f}},
};

/* pbrt-v4's named glasses: Schott's Sellmeier coefficients (n^2 = 1 + sum of
 * B_i l^2 / (l^2 - C_i), l in micrometres, C_i in square micrometres; the
 * Schott catalogue as the refractiveindex.info database lists it, CC0) and
 * the index at 550 nm they give, which is what a glass's name stands for
 * (test_spectra recomputes it). pbrt-v4's glass-F5, -F10 and -F11 are its
 * tables of N-SF5, N-SF10 and N-SF11; the SF names are accepted too. */
static const struct spectra_glass {
    const char *name, *schott;
    float eta550;
    double b[3], c[3];
} pbrt_glasses[] = {
    {"glass-BK7", "N-BK7", 1.51852f, {1.03961212, 0.231792344, 1.01046945}, {0.00600069867, 0.0200179144, 103.560653}},
    {"glass-BAF10", "N-BAF10", 1.67306f, {1.5851495, 0.143559385, 1.08521269}, {0.00926681282, 0.0424489805, 105.613573}},
    {"glass-FK51A", "N-FK51A", 1.48779f, {0.971247817, 0.216901417, 0.904651666}, {0.00472301995, 0.0153575612, 168.68133}},
    {"glass-LASF9", "N-LASF9", 1.85584f, {2.00029547, 0.298926886, 1.80691843}, {0.0121426017, 0.0538736236, 156.530829}},
    {"glass-F5", "N-SF5", 1.67711f, {1.52481889, 0.187085527, 1.42729015}, {0.011254756, 0.0588995392, 129.141675}},
    {"glass-SF5", "N-SF5", 1.67711f, {1.52481889, 0.187085527, 1.42729015}, {0.011254756, 0.0588995392, 129.141675}},
    {"glass-F10", "N-SF10", 1.73366f, {1.62153902, 0.256287842, 1.64447552}, {0.0122241457, 0.0595736775, 147.468793}},
    {"glass-SF10", "N-SF10", 1.73366f, {1.62153902, 0.256287842, 1.64447552}, {0.0122241457, 0.0595736775, 147.468793}},
    {"glass-F11", "N-SF11", 1.79115f, {1.73759695, 0.313747346, 1.89878101}, {0.013188707, 0.0623068142, 155.23629}},
    {"glass-SF11", "N-SF11", 1.79115f, {1.73759695, 0.313747346, 1.89878101}, {0.013188707, 0.0623068142, 155.23629}},
};

bool spectra_pbrt_glass(size_t i, const char **name, float *eta550, double b[3], double c[3])
{
    if (i >= sizeof pbrt_glasses / sizeof pbrt_glasses[0]) return false;
    *name = pbrt_glasses[i].name, *eta550 = pbrt_glasses[i].eta550;
    for (int j = 0; j < 3; j++) b[j] = pbrt_glasses[i].b[j], c[j] = pbrt_glasses[i].c[j];
    return true;
}

bool spectra_pbrt_metal(const char *sym, vec3 *eta, vec3 *k)
{
    if (spectra_named_metal(sym, eta, k)) return true;
    for (size_t i = 0; i < sizeof pbrt_metals / sizeof pbrt_metals[0]; i++)
        if (strcmp(pbrt_metals[i].name, sym) == 0) {
            *eta = v3(pbrt_metals[i].eta[0], pbrt_metals[i].eta[1], pbrt_metals[i].eta[2]);
            *k = v3(pbrt_metals[i].k[0], pbrt_metals[i].k[1], pbrt_metals[i].k[2]);
            return true;
        }
    return false;
}

/* ---- CIE illuminants ---------------------------------------------------------------------- */

#include "spectra_illum.inc"

/* CIE illuminant A (CIE 15:2004, eq. 2.1): Planck's law with c2 = 1.435e7
 * nm K at 2848 K, 100 at 560 nm; the same as a blackbody of 2856 K with
 * today's c2 = 1.4388e7 nm K. */
static double illum_a(const void *user, double nm)
{
    (void)user;
    const double c2 = 1.435e7, t = 2848.0;
    return 100.0 * pow(560.0 / nm, 5.0) * expm1(c2 / (t * 560.0)) / expm1(c2 / (t * nm));
}

typedef struct dseries {
    double m1, m2;
} dseries;

/* A D-series illuminant: S0 + M1 S1 + M2 S2, linear between the 5 nm rows
 * (300..830 nm), zero outside. */
static double illum_d(const void *user, double nm)
{
    const dseries *d = user;
    if (!(nm >= 300.0 && nm <= 830.0)) return 0.0;
    double t = (nm - 300.0) / 5.0;
    int i = (int)t;
    if (i > 105) i = 105;
    double f = t - i, s[3];
    for (int j = 0; j < 3; j++) s[j] = (1.0 - f) * (double)cie_daylight_s[j][i] + f * (double)cie_daylight_s[j][i + 1];
    return s[0] + d->m1 * s[1] + d->m2 * s[2];
}

void spectra_cie_daylight_m(double cct, bool round3, double *m1, double *m2)
{
    /* CIE 15:2004, eqs. 3.3 - 3.6: the chromaticity of daylight of the
     * correlated colour temperature, then the weights of S1 and S2 */
    const double t = cct;
    double x = t <= 7000.0 ? -4.6070e9 / (t * t * t) + 2.9678e6 / (t * t) + 0.09911e3 / t + 0.244063
                           : -2.0064e9 / (t * t * t) + 1.9018e6 / (t * t) + 0.24748e3 / t + 0.237040;
    double y = -3.0 * x * x + 2.870 * x - 0.275;
    double m = 0.0241 + 0.2562 * x - 0.7341 * y;
    *m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m;
    *m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
    if (round3) *m1 = round(*m1 * 1000.0) / 1000.0, *m2 = round(*m2 * 1000.0) / 1000.0;
}

double spectra_cie_daylight(double cct, bool round3, double nm)
{
    dseries d;
    spectra_cie_daylight_m(cct, round3, &d.m1, &d.m2);
    return illum_d(&d, nm);
}

typedef struct fseries {
    int i;
} fseries;

static double illum_f(const void *user, double nm)
{
    const int i = ((const fseries *)user)->i;
    if (!(nm >= 380.0 && nm <= 780.0)) return 0.0;
    double t = (nm - 380.0) / 5.0;
    int j = (int)t;
    if (j > 79) j = 79;
    double f = t - j;
    return (1.0 - f) * (double)cie_illum_f[i][j] + f * (double)cie_illum_f[i][j + 1];
}

double spectra_cie_illum_f(int i, double nm)
{
    const fseries f = {i - 1};
    return i >= 1 && i <= 12 ? illum_f(&f, nm) : 0.0;
}

/* The named illuminants as lights: luminance 1, linear sRGB (pbrt_emitter_unit). */
static bool pbrt_illuminant(const char *name, vec3 *out)
{
    if (strcmp(name, "stdillum-A") == 0) {
        *out = pbrt_emitter_unit(illum_a, NULL);
        return true;
    }
    /* D50 and D65 as CIE tabulates them (the correlated colour temperatures
     * 5000 and 6500 K times 1.4388 / 1.4380, M1 and M2 rounded to three
     * decimals); ACES's D60 as the Academy computes it (6000 K, not rounded) */
    double cct = 0.0;
    bool round3 = true;
    if (strcmp(name, "stdillum-D50") == 0) cct = 5000.0 * 1.4388 / 1.4380;
    else if (strcmp(name, "stdillum-D65") == 0) cct = 6500.0 * 1.4388 / 1.4380;
    else if (strcmp(name, "illum-acesD60") == 0) cct = 6000.0, round3 = false;
    if (cct > 0.0) {
        dseries d;
        spectra_cie_daylight_m(cct, round3, &d.m1, &d.m2);
        *out = pbrt_emitter_unit(illum_d, &d);
        return true;
    }
    if (strncmp(name, "stdillum-F", 10) == 0) {
        const char *n = name + 10;
        int i = 0;
        if (n[0] >= '1' && n[0] <= '9' && n[1] == '\0') i = n[0] - '0';
        else if (n[0] == '1' && n[1] >= '0' && n[1] <= '2' && n[2] == '\0') i = 10 + n[1] - '0';
        if (i) {
            const fseries f = {i - 1};
            *out = pbrt_emitter_unit(illum_f, &f);
            return true;
        }
    }
    return false;
}

int spectra_pbrt_named(const char *name, vec3 *out)
{
    if (strncmp(name, "metal-", 6) == 0) {
        const char *el = name + 6, *dash = strrchr(el, '-');
        bool is_k = false, ok = dash && dash != el;
        if (ok && strcmp(dash, "-k") == 0) is_k = true;
        else if (ok && strcmp(dash, "-eta") != 0) ok = false;
        char sym[16];
        const size_t n = ok ? (size_t)(dash - el) : 0;
        vec3 eta, k;
        if (ok && n < sizeof sym) {
            memcpy(sym, el, n);
            sym[n] = '\0';
            if (spectra_pbrt_metal(sym, &eta, &k)) {
                *out = is_k ? k : eta;
                return SPECTRA_PBRT_KNOWN;
            }
        }
    }
    for (size_t i = 0; i < sizeof pbrt_glasses / sizeof pbrt_glasses[0]; i++)
        if (strcmp(pbrt_glasses[i].name, name) == 0) {
            *out = v3s(pbrt_glasses[i].eta550);
            return SPECTRA_PBRT_KNOWN;
        }
    if (pbrt_illuminant(name, out)) return SPECTRA_PBRT_KNOWN;
    return SPECTRA_PBRT_UNKNOWN;
}

/*
 * spectra.h - what the scene readers know about light and matter beyond
 * RGB: the CIE 1931 colour matching functions, spectra (sampled at
 * wavelengths) and blackbody emitters reduced to linear sRGB, and the named
 * tables of scene formats (metals' complex indices of refraction, dielectric
 * indices of refraction). Pure functions of their arguments: no context, no
 * allocation, no messages (a reader reports what it could not use).
 */
#ifndef PK_SPECTRA_H
#define PK_SPECTRA_H

#include "../math/vec3.h"
#include "../paprsek_internal.h"

#include <stdbool.h>

/* The CIE 1931 2-degree colour matching functions at nm nanometres (the
 * multi-lobe Gaussian fit of Wyman, Sloan and Shirley, 2013). */
PK_HIDDEN void spectra_cie_xyz(float nm, float *x, float *y, float *z);

/* Linear sRGB of a spectrum given as n >= 1 samples (nm strictly ascending,
 * value), linear between them and constant beyond: XYZ by the colour
 * matching functions over 360..830 nm in 1 nm steps, then the sRGB matrix,
 * divided per channel by what a constant spectrum of 1 gives, so that a flat
 * reflectance r is grey r. Negative channels are clamped to 0. */
PK_HIDDEN vec3 spectrum_to_rgb(const float *nm, const float *val, int n);

/* Planck's spectral radiance of a blackbody at kelvin (> 0) in
 * W m^-2 sr^-1 nm^-1, sampled every 5 nm over 360..830 nm and reduced to
 * RGB as spectrum_to_rgb does (Mitsuba's <blackbody> units). */
PK_HIDDEN vec3 blackbody_rgb(float kelvin);

/* The CIE 1931 2-degree colour matching functions as tabulated by the CIE
 * (every nanometre, 360..830 nm), linear between the nanometres and zero
 * outside: xyz[0..2] = x, y, z at nm. */
PK_HIDDEN void spectra_cie1931(float nm, float xyz[3]);

/* Mitsuba 0.5/0.6's reduction of a sampled spectrum to linear sRGB in its
 * RGB mode (reflectances and emitters alike): the n >= 2 samples (nm
 * strictly ascending), zero beyond a zero sample added one mean spacing
 * past each end whose value is not zero; XYZ = the integrals over
 * 360..830 nm of the spectrum times the tabulated matching functions,
 * divided by the integral of y; then the Rec. 709 matrix; negative
 * channels clamped to 0. Between samples both the spectrum and the
 * matching functions are evaluated as released Mitsuba 0.5/0.6 evaluates
 * them, each linear segment mirrored within its interval (a swapped lerp,
 * fixed only in 2020): sparse spectra such as 100 nm emitters differ by
 * ~10 % from the straight interpolation, dense reflectances by < 1 %.
 * No white normalisation: a flat spectrum of 1 is XYZ (1, 1, 1), the
 * equal-energy white, pinkish in sRGB. Black for n < 2. */
PK_HIDDEN vec3 spectra_mitsuba06_rgb(const float *nm, const float *val, int n);

/* Mitsuba 0.5/0.6's <blackbody temperature=kelvin>: Planck's law in
 * W m^-2 sr^-1 nm^-1 reduced as spectra_mitsuba06_rgb reduces a spectrum. */
PK_HIDDEN vec3 spectra_mitsuba06_blackbody(float kelvin);

/* Mitsuba 3's reduction in its RGB variants: the spectrum (linear between
 * the n >= 2 samples, zero outside them) summed at 1000 equally spaced
 * wavelengths over 360..830 nm against the matching functions tabulated
 * every 5 nm, weighted by D65 (scaled to about 1 at 560 nm) unless emitter,
 * times 470 / 1000 / 106.7502594; then the Rec. 709 matrix; negative
 * channels clamped to 0, and channels above 1 clamped to 1 when bounded
 * (reflectances; emitters and unbounded properties such as a conductor's
 * eta and k are not). */
PK_HIDDEN vec3 spectra_mitsuba3_rgb(const float *nm, const float *val, int n, bool emitter, bool bounded);

/* A blackbody emitter at kelvin reduced as spectra_mitsuba3_rgb reduces an
 * emitter's spectrum (what Mitsuba 3's spectral variants show of it; its RGB
 * variants refuse blackbodies). */
PK_HIDDEN vec3 spectra_mitsuba3_blackbody(float kelvin);

/* Mitsuba 3's RGB of a uniform emitter spectrum of value: value times the
 * sRGB of XYZ (1, 1, 1). */
PK_HIDDEN vec3 spectra_mitsuba3_uniform_emitter(float value);

/* Mitsuba 0.6's sun: the extraterrestrial solar spectrum attenuated along
 * the air mass of the sun's zenith angle (radians) by Rayleigh and aerosol
 * scattering (turbidity), ozone, mixed gases and water vapour (Preetham et
 * al. 1999, after Iqbal 1983), sampled every 5 nm over 350..800 nm into
 * nm[91], val[91] (W m^-2 sr^-1 nm^-1); _sun reduces it to RGB as
 * spectra_mitsuba06_rgb does. */
PK_HIDDEN void spectra_mitsuba06_sun_spectrum(float zenith, float turbidity, float nm[91], float val[91]);
PK_HIDDEN vec3 spectra_mitsuba06_sun(float zenith, float turbidity);

/* ---- pbrt-v4's rules (its RGB film records what its spectral transport gives) ---- */

/* An emitter's sampled spectrum (n >= 1 samples, nm strictly ascending;
 * linear between them, zero outside) as pbrt-v4 normalises emitters: XYZ
 * over 360..830 nm every nanometre against the tabulated matching functions,
 * scaled to luminance Y = 1, then the sRGB matrix (no white balance: an
 * equal-energy spectrum is not grey), negative channels clamped to 0. */
PK_HIDDEN vec3 spectra_pbrt_emitter(const float *nm, const float *val, size_t n);
/* A blackbody at kelvin reduced as spectra_pbrt_emitter reduces a spectrum
 * (luminance 1). */
PK_HIDDEN vec3 spectra_pbrt_blackbody(float kelvin);
/* pbrt-v4's blackbody scaled to 1 at its peak (Wien's law), not to a
 * luminance: spectra_pbrt_blackbody times that spectrum's luminance (media's
 * "temperature" emission). */
PK_HIDDEN vec3 spectra_pbrt_blackbody_peak(double kelvin);
enum { SPECTRA_PBRT_UNKNOWN = 0, SPECTRA_PBRT_KNOWN = 1 };
/* A named spectrum of pbrt-v4 as RGB: "metal-XX-eta" / "metal-XX-k" (the
 * metals of spectra_pbrt_metal), "glass-XX" (the index at 550 nm of
 * spectra_pbrt_glass), and the illuminants stdillum-A (CIE's formula),
 * stdillum-D50, stdillum-D65, illum-acesD60 (CIE daylight of 5003, 6504
 * and 6000 K), stdillum-F1 ... F12 (CIE's tables) as lights: luminance 1,
 * reduced as spectra_pbrt_emitter reduces a spectrum (D65 is white to
 * 1e-3). SPECTRA_PBRT_UNKNOWN, nothing written, for another name. */
PK_HIDDEN int spectra_pbrt_named(const char *name, vec3 *out);

/* The complex index (eta, k) at the red, green and blue primaries of a
 * metal pbrt-v4 names ("Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"; also
 * "Cr"). False, nothing written, for another symbol. */
PK_HIDDEN bool spectra_pbrt_metal(const char *sym, vec3 *eta, vec3 *k);
/* The i-th named glass of pbrt-v4 (false past the last): its name, its
 * index at 550 nm and its Sellmeier coefficients (n^2 = 1 + sum of b_j l^2 /
 * (l^2 - c_j), l in micrometres), kept for spectral rendering. */
PK_HIDDEN bool spectra_pbrt_glass(size_t i, const char **name, float *eta550, double b[3], double c[3]);
/* CIE daylight (the D series) of correlated colour temperature cct
 * (4000..25000 K): M1 and M2 (rounded to three decimals, as CIE's tables,
 * when round3), and the relative spectral power at nm (300..830 nm, zero
 * outside). */
PK_HIDDEN void spectra_cie_daylight_m(double cct, bool round3, double *m1, double *m2);
PK_HIDDEN double spectra_cie_daylight(double cct, bool round3, double nm);
/* CIE illuminant Fi (1..12) at nm (380..780 nm, zero outside). */
PK_HIDDEN double spectra_cie_illum_f(int i, double nm);

/* The complex index of refraction (eta, k) of a named metal at the red,
 * green and blue primaries: "Cu", "Au", "Ag", "Al", "Cr" (the names of
 * Mitsuba's table). False, nothing written, for another name. */
PK_HIDDEN bool spectra_named_metal(const char *name, vec3 *eta, vec3 *k);

/* Mitsuba's named indices of refraction ("vacuum", "air", "water", "bk7",
 * "diamond", ...). False, nothing written, for another name. */
PK_HIDDEN bool spectra_named_ior(const char *name, float *ior);

#endif

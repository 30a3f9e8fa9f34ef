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

/* The complex index of refraction (eta, k) of a named metal at the red,
 * green and blue primaries: "Cu", "Au", "Ag", "Al", "Cr" (the names of
 * Mitsuba's table). False, nothing written, for another name. */
PK_HIDDEN bool spectra_named_metal(const char *name, vec3 *eta, vec3 *k);

/* Mitsuba's named indices of refraction ("vacuum", "air", "water", "bk7",
 * "diamond", ...). False, nothing written, for another name. */
PK_HIDDEN bool spectra_named_ior(const char *name, float *ior);

#endif

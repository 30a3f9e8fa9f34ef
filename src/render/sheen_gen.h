/*
 * sheen_gen.h - how sheen_table.inc is computed (host code only):
 * bench/sheen_table.c writes it with these functions, and
 * tests/unit/test_gltf_lobes.c recomputes entries and compares.
 *
 * E(mu, r) is integrated in double precision over the hemisphere of wi with
 * the midpoint rule in (t, phi), cos_i = t^2 (nodes dense toward grazing,
 * where the fibres reflect), of the lobe's formula written out here again
 * in double (sheen.h has the float one the renderer uses).
 */
#ifndef PK_SHEEN_GEN_H
#define PK_SHEEN_GEN_H

#include "sheen.h"

#include <math.h>

static inline double sheen_gen_r(int i) {
    return (double)PK_SH_R_MIN + (1.0 - (double)PK_SH_R_MIN) * (double)i / (PK_SH_R - 1);
}
static inline double sheen_gen_mu(int i) { return i == 0 ? (double)PK_EN_MU_MIN : (double)i / (PK_SH_MU - 1); }

static inline double sheen_gen_l(double x, double a) {
    const double t = (1.0 - a) * (1.0 - a);
    const double A = 21.5473 + (25.3245 - 21.5473) * t, B = 3.82987 + (3.32435 - 3.82987) * t;
    const double C = 0.19823 + (0.16801 - 0.19823) * t, D = -1.97760 + (-1.27393 + 1.97760) * t;
    const double E = -4.32054 + (-4.85967 + 4.32054) * t;
    return A / (1.0 + B * pow(x, C)) + D * x + E;
}
static inline double sheen_gen_lambda(double a, double c) {
    return c < 0.5 ? exp(sheen_gen_l(c, a)) : exp(2.0 * sheen_gen_l(0.5, a) - sheen_gen_l(1.0 - c, a));
}
/* D V cos_i for wo = (sin_o, 0, mu), wi = (sin_i cos phi, sin_i sin phi, cos_i). */
static inline double sheen_gen_f(double a, double mu, double ci, double phi) {
    const double so = sqrt(fmax(0.0, 1.0 - mu * mu)), si = sqrt(fmax(0.0, 1.0 - ci * ci));
    const double hx = so + si * cos(phi), hy = si * sin(phi), hz = mu + ci;
    const double l2 = hx * hx + hy * hy + hz * hz;
    if (!(l2 > 0.0)) return 0.0;
    const double s2 = 1.0 - hz * hz / l2;
    const double d = (2.0 + 1.0 / a) * pow(fmax(s2, 0.0), 0.5 / a) / (2.0 * M_PI);
    return d / ((1.0 + sheen_gen_lambda(a, mu) + sheen_gen_lambda(a, ci)) * 4.0 * mu);
}
/* E(mu, r) with n x n nodes (phi over [0, pi], doubled: the lobe is
 * symmetric about the plane of wo). */
static inline double sheen_gen_e(double r, double mu, int n) {
    const double a = r * r;
    double s = 0.0;
    for (int j = 0; j < n; j++) {
        const double phi = M_PI * ((double)j + 0.5) / n;
        for (int i = 0; i < n; i++) {
            const double t = ((double)i + 0.5) / n;
            s += sheen_gen_f(a, mu, t * t, phi) * 2.0 * t;
        }
    }
    return 2.0 * s * M_PI / ((double)n * (double)n);
}

#define SHEEN_GEN_N 512

#endif

/*
 * env.h - light from the surroundings: what a ray that leaves the scene
 * sees (the scene's environment description, scene.h). Two lights for the
 * integrators:
 *
 *  - the environment: a constant radiance, a lat-long map and an analytic
 *    daylight sky, summed into one radiance function of direction. A
 *    constant alone is sampled uniformly over the sphere; otherwise the sum
 *    is baked into a lat-long image and sampled in proportion to luminance
 *    times sin(theta) (a 2-D piecewise-constant distribution: rows by their
 *    sums, then a column within the row);
 *  - the sun: a disc of constant radiance, angular diameter sun_angle,
 *    sampled uniformly in its cone.
 *
 * Lat-long convention (as Mitsuba's envmap): in the map's frame, direction
 * (x, y, z) has u = atan2(x, -z) / (2 pi) (wrapped to [0, 1)) and
 * v = acos(y) / pi; row 0 of the image is v = 0 (straight up, +y). The
 * map's frame is rotated into the world by scene_environment.to_world.
 *
 * A portal (pbrt-v4's PortalImageInfiniteLight) restricts the environment
 * to the directions that pass through a rectangle: from a point o, the
 * environment (not the sun) gives light only toward directions whose line
 * from o crosses the rectangle, and zero elsewhere. Such directions are
 * parameterised in the portal's frame (x along p0 -> p3, y along p0 -> p1,
 * z their cross product, pointing away from the scene) by the angles
 * u = (atan2(x, z) + pi / 2) / pi, v = (atan2(y, z) + pi / 2) / pi: the
 * directions through the rectangle seen from o are then exactly a
 * rectangle [u0, u1] x [v0, v1] (the window) of the unit square. Sampling
 * draws (u, v) in the window from a piecewise-constant density (luminance
 * times the solid angle per unit (u, v), on a grid of the portal's
 * parameterisation, looked up in a summed-area table) and the solid-angle
 * pdf is that density over the window's integral, divided by
 * d(omega)/d(u, v) = pi^2 (1 - x^2)(1 - y^2) / z.
 */
#ifndef PK_ENV_H
#define PK_ENV_H

#include "../math/frame.h"
#include "../math/distrib.h"
#include "../scene/scene.h"

typedef struct env_light {
    bool active;          /* the environment part gives light */
    bool uniform;         /* constant only: uniform over the sphere */
    vec3 constant;        /* the constant (when uniform) */
    int w, h;             /* baked lat-long radiance, w * h RGB (when !uniform) */
    float *rgb;
    float *marginal;      /* h entries: CDF over rows, last = 1 */
    float *conditional;   /* w * h: per row, CDF over its columns, last = 1 */
    float *weight;        /* w * h: the pdf over (u, v) of each pixel (mean 1) */
    float to_world[9], to_map[9];
    bool sun;             /* the sun part gives light */
    vec3 sun_dir;         /* unit, toward the sun */
    vec3 sun_le;          /* radiance of the disc */
    float sun_cos;        /* cosine of the disc's angular radius */
    float sun_omc;        /* 1 - sun_cos, computed as 2 sin^2(radius / 2) (no cancellation) */
    onb sun_frame;
    /* emitted power estimates for choosing among all lights: pi R^2 times
     * the mean radiance (environment) or the irradiance (sun), R the radius
     * of the scene's bounding sphere */
    double power_env, power_sun;
    /* the portal (when portal): rows of portal_to_local are the frame's
     * axes in the world; p0 and p2 opposite corners; pw x ph cells of
     * density portal_f over (u, v) (integral 1 over the unit square) and
     * its summed-area table portal_sat, (pw + 1) x (ph + 1), row-major by v,
     * entry (i, j) the integral over [0, i / pw] x [0, j / ph] */
    bool portal;
    float portal_to_local[9];
    vec3 portal_p0, portal_p2;
    int pw, ph;
    float *portal_f;
    double *portal_sat;
    size_t bytes;         /* memory held */
} env_light;

/* Builds the environment of s; map_rgb (w x h linear RGB, row 0 on top,
 * borrowed) is the loaded env.map or NULL. An empty description gives an
 * inactive light. Negative and non-finite map values count as 0. */
PK_HIDDEN pk_status env_build(pk_context *ctx, const scene_environment *env, const float *map_rgb, int w, int h,
                              aabb bounds, env_light *out);
PK_HIDDEN void env_free(const pk_allocator *al, env_light *e);


/* ---- lookups (compiled for the GPU as well) ---------------------------------- */

static inline PK_HD vec3 env_mat3_mul(const float m[9], vec3 v)
{
    return v3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
              m[6] * v.x + m[7] * v.y + m[8] * v.z);
}

/* The world direction of lat-long coordinates (u, v). */
static inline PK_HD vec3 latlong_dir(const env_light *e, float u, float v)
{
    float theta = v * PK_PI, phi = 2.0f * PK_PI * u;
    float st = sinf(theta);
    return env_mat3_mul(e->to_world, v3(st * sinf(phi), cosf(theta), -st * cosf(phi)));
}

/* Lat-long coordinates of world direction d (unit). */
static inline PK_HD void latlong_uv(const env_light *e, vec3 d, float *u, float *v)
{
    vec3 m = env_mat3_mul(e->to_map, d);
    float uu = atan2f(m.x, -m.z) * (0.5f / PK_PI);
    if (uu < 0.0f) uu += 1.0f;
    *u = uu < 1.0f ? uu : 0.0f;
    *v = acosf(fminf(fmaxf(m.y, -1.0f), 1.0f)) * (1.0f / PK_PI);
}

/* Radiance of the environment part (no sun) toward unit direction d. */
static inline PK_HD vec3 env_eval(const env_light *e, vec3 d)
{
    if (!e->active) return v3s(0.0f);
    if (e->uniform) return e->constant;
    float u, v;
    latlong_uv(e, d, &u, &v);
    /* bilinear between pixel centres, wrapping in u and clamped in v */
    float x = u * (float)e->w - 0.5f, y = v * (float)e->h - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float tx = x - fx, ty = y - fy;
    int x0 = (int)fx, y0 = (int)fy;
    int x1 = x0 + 1, y1 = y0 + 1;
    if (x0 < 0) x0 += e->w;
    if (x1 >= e->w) x1 -= e->w;
    if (x0 < 0 || x0 >= e->w) x0 = 0;
    if (x1 < 0 || x1 >= e->w) x1 = 0;
    y0 = y0 < 0 ? 0 : y0 >= e->h ? e->h - 1 : y0;
    y1 = y1 < 0 ? 0 : y1 >= e->h ? e->h - 1 : y1;
    const float *p00 = &e->rgb[3 * ((size_t)y0 * (size_t)e->w + (size_t)x0)];
    const float *p10 = &e->rgb[3 * ((size_t)y0 * (size_t)e->w + (size_t)x1)];
    const float *p01 = &e->rgb[3 * ((size_t)y1 * (size_t)e->w + (size_t)x0)];
    const float *p11 = &e->rgb[3 * ((size_t)y1 * (size_t)e->w + (size_t)x1)];
    float c[3];
    for (int k = 0; k < 3; k++) {
        float top = p00[k] + (p10[k] - p00[k]) * tx, bot = p01[k] + (p11[k] - p01[k]) * tx;
        c[k] = top + (bot - top) * ty;
    }
    return v3(c[0], c[1], c[2]);
}

/* ---- the portal ---------------------------------------------------------- */

/* The portal's (u, v) of world direction d (unit) and d(omega)/d(u, v) there;
 * false for directions that do not point through the portal's plane. */
static inline PK_HD bool portal_uv(const env_light *e, vec3 d, float *u, float *v, float *jac)
{
    const vec3 w = env_mat3_mul(e->portal_to_local, d);
    if (!(w.z > 0.0f)) return false;
    if (jac) *jac = PK_PI * PK_PI * fmaxf(1.0f - w.x * w.x, 0.0f) * fmaxf(1.0f - w.y * w.y, 0.0f) / w.z;
    *u = fminf(fmaxf((atan2f(w.x, w.z) + 0.5f * PK_PI) * (1.0f / PK_PI), 0.0f), 1.0f);
    *v = fminf(fmaxf((atan2f(w.y, w.z) + 0.5f * PK_PI) * (1.0f / PK_PI), 0.0f), 1.0f);
    return true;
}

/* The world direction (unit) of the portal's (u, v), with d(omega)/d(u, v). */
static inline PK_HD vec3 portal_dir(const env_light *e, float u, float v, float *jac)
{
    const float x = tanf((u - 0.5f) * PK_PI), y = tanf((v - 0.5f) * PK_PI);
    const vec3 w = v3_norm(v3(x, y, 1.0f));
    *jac = PK_PI * PK_PI * fmaxf(1.0f - w.x * w.x, 0.0f) * fmaxf(1.0f - w.y * w.y, 0.0f) / w.z;
    const float *m = e->portal_to_local; /* local to world: the transpose */
    return v3_norm(v3(m[0] * w.x + m[3] * w.y + m[6] * w.z, m[1] * w.x + m[4] * w.y + m[7] * w.z,
                      m[2] * w.x + m[5] * w.y + m[8] * w.z));
}

/* The window: the (u, v) rectangle b = {u0, v0, u1, v1} of the directions
 * from o through the portal; false when o is not in front of it. */
static inline PK_HD bool portal_window(const env_light *e, vec3 o, float b[4])
{
    float ua, va, ub, vb;
    const vec3 da = v3_sub(e->portal_p0, o), db = v3_sub(e->portal_p2, o);
    if (!(v3_len2(da) > 0.0f) || !(v3_len2(db) > 0.0f)) return false;
    if (!portal_uv(e, v3_norm(da), &ua, &va, NULL) || !portal_uv(e, v3_norm(db), &ub, &vb, NULL)) return false;
    b[0] = fminf(ua, ub), b[1] = fminf(va, vb), b[2] = fmaxf(ua, ub), b[3] = fmaxf(va, vb);
    return b[2] > b[0] && b[3] > b[1];
}

/* The summed-area table at the continuous point (x, y) of the grid (x in
 * [0, pw], y in [0, ph]): bilinear between its entries, exact for the
 * integral of a piecewise-constant density. */
static inline PK_HD double portal_sat_at(const env_light *e, double x, double y)
{
    x = x < 0.0 ? 0.0 : x > (double)e->pw ? (double)e->pw : x;
    y = y < 0.0 ? 0.0 : y > (double)e->ph ? (double)e->ph : y;
    int i = (int)x, j = (int)y;
    if (i >= e->pw) i = e->pw - 1;
    if (j >= e->ph) j = e->ph - 1;
    const double fx = x - (double)i, fy = y - (double)j;
    const size_t W = (size_t)e->pw + 1;
    const double *s0 = &e->portal_sat[(size_t)j * W + (size_t)i], *s1 = s0 + W;
    const double a = s0[0] + (s0[1] - s0[0]) * fx, b = s1[0] + (s1[1] - s1[0]) * fx;
    return a + (b - a) * fy;
}

/* The integral of the density over [x0, x1] x [y0, y1] (grid units). */
static inline PK_HD double portal_integral(const env_light *e, double x0, double y0, double x1, double y1)
{
    return portal_sat_at(e, x1, y1) - portal_sat_at(e, x0, y1) - portal_sat_at(e, x1, y0) + portal_sat_at(e, x0, y0);
}

/* The portal's density cell of (u, v), clamped. */
static inline PK_HD size_t portal_cell(const env_light *e, float u, float v)
{
    int i = (int)(u * (float)e->pw), j = (int)(v * (float)e->ph);
    i = i < 0 ? 0 : i >= e->pw ? e->pw - 1 : i;
    j = j < 0 ? 0 : j >= e->ph ? e->ph - 1 : j;
    return (size_t)j * (size_t)e->pw + (size_t)i;
}

/* The pdf over (u, v) of the portal's sampling from o at (u, v) in the window b. */
static inline PK_HD float portal_pdf_uv(const env_light *e, const float b[4], float u, float v)
{
    const double total =
        portal_integral(e, (double)b[0] * e->pw, (double)b[1] * e->ph, (double)b[2] * e->pw, (double)b[3] * e->ph);
    if (!(total > 0.0)) return 0.0f;
    return (float)((double)e->portal_f[portal_cell(e, u, v)] / total);
}

/* The function portal_invert inverts (see there), at x. */
static inline PK_HD double portal_g(const env_light *e, int row, double xa, double xb, double a, double x)
{
    if (row < 0) return portal_integral(e, xa, a, xb, x);
    return (portal_sat_at(e, x, row + 1.0) - portal_sat_at(e, x, (double)row)) -
           (portal_sat_at(e, a, row + 1.0) - portal_sat_at(e, a, (double)row));
}

/* Inverts the piecewise-linear, non-decreasing g(t) = G(t) - G(a) on [a, b]
 * (knots at the integers) for target t: which is what a 1-D slice of the
 * summed-area table is. row < 0: G(x) = the window's integral up to
 * y = x in v (xa, xb its u range); row >= 0: G(x) = the integral along that
 * row of cells up to x. */
static inline PK_HD double portal_invert(const env_light *e, int row, double xa, double xb, double a, double b,
                                         double t)
{
    /* the last knot k in [a, b) with g(k) <= t, by bisection over the integers */
    int lo = (int)ceil(a), hi = (int)floor(b);
    double ka = a;
    if (lo <= hi && portal_g(e, row, xa, xb, a, (double)lo) <= t) {
        while (lo < hi) {
            const int mid = lo + (hi - lo + 1) / 2;
            if (portal_g(e, row, xa, xb, a, (double)mid) <= t)
                lo = mid;
            else
                hi = mid - 1;
        }
        ka = (double)lo;
    }
    double kb = floor(ka) + 1.0;
    if (kb > b) kb = b;
    if (!(kb > ka)) return ka;
    const double ga = portal_g(e, row, xa, xb, a, ka), gb = portal_g(e, row, xa, xb, a, kb);
    const double r = gb > ga ? (t - ga) / (gb - ga) : 0.5;
    return ka + (kb - ka) * (r < 0.0 ? 0.0 : r > 1.0 ? 1.0 : r);
}

/* A (u, v) in the window b from (u1, u2), by the density; false when the
 * window holds none of it. */
static inline PK_HD bool portal_sample_uv(const env_light *e, const float b[4], float u1, float u2, float *u,
                                          float *v)
{
    const double x0 = (double)b[0] * e->pw, x1 = (double)b[2] * e->pw;
    const double y0 = (double)b[1] * e->ph, y1 = (double)b[3] * e->ph;
    const double total = portal_integral(e, x0, y0, x1, y1);
    if (!(total > 0.0)) return false;
    const double y = portal_invert(e, -1, x0, x1, y0, y1, (double)u1 * total);
    int row = (int)y;
    if (row >= e->ph) row = e->ph - 1;
    const double rt = portal_sat_at(e, x1, row + 1.0) - portal_sat_at(e, x1, (double)row) -
                      (portal_sat_at(e, x0, row + 1.0) - portal_sat_at(e, x0, (double)row));
    if (!(rt > 0.0)) return false;
    const double x = portal_invert(e, row, 0.0, 0.0, x0, x1, (double)u2 * rt);
    *u = (float)(x / e->pw), *v = (float)(y / e->ph);
    return true;
}

/* The pixel of (u, v), clamped. */
static inline PK_HD size_t env_pixel_of(const env_light *e, float u, float v)
{
    int i = (int)(u * (float)e->w), j = (int)(v * (float)e->h);
    i = i < 0 ? 0 : i >= e->w ? e->w - 1 : i;
    j = j < 0 ? 0 : j >= e->h ? e->h - 1 : j;
    return (size_t)j * (size_t)e->w + (size_t)i;
}

/* Radiance of the environment part (no sun) that a ray from o toward unit
 * direction d receives: env_eval, or zero with a portal that d does not
 * pass through from o. */
static inline PK_HD vec3 env_eval_from(const env_light *e, vec3 o, vec3 d)
{
    if (!e->active) return v3s(0.0f);
    if (e->portal) {
        float b[4], u, v;
        if (!portal_window(e, o, b) || !portal_uv(e, d, &u, &v, NULL)) return v3s(0.0f);
        if (u < b[0] || u > b[2] || v < b[1] || v > b[3]) return v3s(0.0f);
    }
    return env_eval(e, d);
}

/* Solid-angle pdf with which env_sample gives d (no portal). */
static inline PK_HD float env_pdf(const env_light *e, vec3 d)
{
    if (!e->active) return 0.0f;
    if (e->uniform) return 1.0f / (4.0f * PK_PI);
    float u, v;
    latlong_uv(e, d, &u, &v);
    float st = sinf(v * PK_PI);
    if (!(st > 0.0f)) return 0.0f;
    return e->weight[env_pixel_of(e, u, v)] / (2.0f * PK_PI * PK_PI * st);
}

/* Solid-angle pdf with which env_sample_from gives d from o. */
static inline PK_HD float env_pdf_from(const env_light *e, vec3 o, vec3 d)
{
    if (!e->active) return 0.0f;
    if (!e->portal) return env_pdf(e, d);
    float b[4], u, v, jac;
    if (!portal_window(e, o, b) || !portal_uv(e, d, &u, &v, &jac)) return 0.0f;
    if (u < b[0] || u > b[2] || v < b[1] || v > b[3] || !(jac > 0.0f)) return 0.0f;
    const float p = portal_pdf_uv(e, b, u, v) / jac;
    return isfinite(p) ? p : 0.0f;
}

/* A direction (unit) toward the environment with its radiance and pdf;
 * false when the environment is black there. Without a portal. */
static inline PK_HD bool env_sample(const env_light *e, float u1, float u2, vec3 *d, vec3 *le, float *pdf)
{
    if (!e->active) return false;
    if (e->uniform) {
        float z = 1.0f - 2.0f * u1, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * PK_PI * u2;
        *d = v3(r * cosf(phi), r * sinf(phi), z);
        *le = e->constant;
        *pdf = 1.0f / (4.0f * PK_PI);
        return true;
    }
    float du, dv;
    const size_t j = cdf_pick(e->marginal, (size_t)e->h, u1);
    const float *row = &e->conditional[j * (size_t)e->w];
    const size_t i = cdf_pick(row, (size_t)e->w, u2);
    dv = cdf_remainder(e->marginal, j, u1);
    du = cdf_remainder(row, i, u2);
    float u = ((float)i + du) / (float)e->w, v = ((float)j + dv) / (float)e->h;
    float st = sinf(v * PK_PI);
    float wgt = e->weight[j * (size_t)e->w + i];
    if (!(st > 0.0f) || !(wgt > 0.0f)) return false;
    *d = v3_norm(latlong_dir(e, u, v));
    /* the pdf of the pixel the direction lands in, as env_pdf computes it
     * (the same pixel up to float rounding at its edges) */
    *pdf = env_pdf(e, *d);
    if (!(*pdf > 0.0f)) return false;
    *le = env_eval(e, *d);
    return true;
}

/* A direction (unit) from o toward the environment with its radiance and
 * pdf (through the portal when there is one); false when none. */
static inline PK_HD bool env_sample_from(const env_light *e, vec3 o, float u1, float u2, vec3 *d, vec3 *le,
                                         float *pdf)
{
    if (!e->active) return false;
    if (!e->portal) return env_sample(e, u1, u2, d, le, pdf);
    float b[4], u, v, jac;
    if (!portal_window(e, o, b) || !portal_sample_uv(e, b, u1, u2, &u, &v)) return false;
    *d = portal_dir(e, u, v, &jac);
    /* the pdf as env_pdf_from computes it, for MIS to agree */
    *pdf = env_pdf_from(e, o, *d);
    if (!(*pdf > 0.0f)) return false;
    *le = env_eval_from(e, o, *d);
    return true;
}

/* A direction in the sun's cone, uniform. */
static inline PK_HD vec3 sun_sample(const env_light *e, float u1, float u2)
{
    /* 1 - cos(theta) uniform in [0, omc]; sin from it without cancellation */
    float omc = u1 * e->sun_omc, cos_t = 1.0f - omc, sin_t = sqrtf(fmaxf(0.0f, omc * (2.0f - omc)));
    float phi = 2.0f * PK_PI * u2;
    return v3_norm(onb_to_world(e->sun_frame, v3(sin_t * cosf(phi), sin_t * sinf(phi), cos_t)));
}

/* The sun's radiance toward d (sun_le inside its disc, else 0) and pdf. */
static inline PK_HD bool sun_covers(const env_light *e, vec3 d) { return e->sun && v3_dot(d, e->sun_dir) >= e->sun_cos; }
static inline PK_HD float sun_pdf(const env_light *e) { return 1.0f / (2.0f * PK_PI * e->sun_omc); }

/* Everything a ray leaving the scene from o toward d sees: environment and sun. */
static inline PK_HD vec3 env_background(const env_light *e, vec3 o, vec3 d)
{
    vec3 c = env_eval_from(e, o, d);
    return sun_covers(e, d) ? v3_add(c, e->sun_le) : c;
}

/* The Preetham et al. (1999) clear-sky radiance toward d (unit, world)
 * for the sun direction sun (unit) and turbidity (2 .. 10), linear sRGB
 * in units where the zenith of a high sun is about 1; zero below the
 * horizon. */
PK_HIDDEN vec3 sky_preetham(vec3 d, vec3 sun, float turbidity);

/* The Hosek-Wilkie (2012) sky in RGB, as Mitsuba 0.6's sky emitter
 * evaluates it: the model's nine parameters and radiance scale per channel,
 * cooked for the sun (unit, +y up; a sun below the horizon is taken at it),
 * turbidity (1 .. 10) and ground albedo per channel (0 .. 1). */
typedef struct sky_hosek {
    double cfg[3][9], rad[3];
    vec3 sun;
} sky_hosek;
PK_HIDDEN void sky_hosek_init(sky_hosek *h, vec3 sun, float turbidity, vec3 albedo);
/* Its radiance toward d (unit, world), divided by 106.856980 (the sum of
 * the CIE y table) as Mitsuba does; zero below the horizon. */
PK_HIDDEN vec3 sky_hosek_eval(const sky_hosek *h, vec3 d);

#endif

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

/* The pixel of (u, v), clamped. */
static inline PK_HD size_t env_pixel_of(const env_light *e, float u, float v)
{
    int i = (int)(u * (float)e->w), j = (int)(v * (float)e->h);
    i = i < 0 ? 0 : i >= e->w ? e->w - 1 : i;
    j = j < 0 ? 0 : j >= e->h ? e->h - 1 : j;
    return (size_t)j * (size_t)e->w + (size_t)i;
}

/* Solid-angle pdf with which env_sample gives d. */
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

/* A direction (unit) toward the environment with its radiance and pdf;
 * false when the environment is black there. */
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

/* Everything a ray leaving the scene toward d sees: environment and sun. */
static inline PK_HD vec3 env_background(const env_light *e, vec3 d)
{
    vec3 c = e->active ? env_eval(e, d) : v3s(0.0f);
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

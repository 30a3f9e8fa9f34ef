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

/* Radiance of the environment part (no sun) toward unit direction d. */
PK_HIDDEN vec3 env_eval(const env_light *e, vec3 d);
/* Solid-angle pdf with which env_sample gives d. */
PK_HIDDEN float env_pdf(const env_light *e, vec3 d);
/* A direction (unit) toward the environment with its radiance and pdf;
 * false when the environment is black there. */
PK_HIDDEN bool env_sample(const env_light *e, float u1, float u2, vec3 *d, vec3 *le, float *pdf);

/* The sun's radiance toward d (sun_le inside its disc, else 0) and pdf. */
static inline bool sun_covers(const env_light *e, vec3 d) { return e->sun && v3_dot(d, e->sun_dir) >= e->sun_cos; }
static inline float sun_pdf(const env_light *e) { return 1.0f / (2.0f * PK_PI * e->sun_omc); }
PK_HIDDEN vec3 sun_sample(const env_light *e, float u1, float u2);

/* Everything a ray leaving the scene toward d sees: environment and sun. */
static inline vec3 env_background(const env_light *e, vec3 d)
{
    vec3 c = e->active ? env_eval(e, d) : v3s(0.0f);
    return sun_covers(e, d) ? v3_add(c, e->sun_le) : c;
}

/* The Preetham et al. (1999) clear-sky radiance toward d (unit, world)
 * for the sun direction sun (unit) and turbidity (2 .. 10), linear sRGB
 * in units where the zenith of a high sun is about 1; zero below the
 * horizon. */
PK_HIDDEN vec3 sky_preetham(vec3 d, vec3 sun, float turbidity);

#endif

/*
 * lights.h - the light table of a frame: the emissive triangles with their
 * areas, unit normals and a CDF over emitted power (luminance x area), built
 * once per renderer and shared by the integrators.
 */
#ifndef PK_LIGHTS_H
#define PK_LIGHTS_H

#include "../math/distrib.h"
#include "../scene/scene.h"
#include "env.h"

typedef struct light_table {
    size_t n;            /* the scene's emissive triangles (s->emissive) */
    float *cdf;          /* n entries, cumulative power, last = 1 */
    float *area;         /* area of each emissive triangle */
    vec3 *normal;        /* unit geometric normal of each emissive triangle */
    float power;         /* total emitted power (luminance * area) */
} light_table;

PK_HIDDEN pk_status lights_build(pk_context *ctx, const pk_scene *s, light_table *lt);
PK_HIDDEN void lights_free(const pk_allocator *al, light_table *lt);

/* The light whose CDF interval holds u in [0, 1) (lt->n > 0). */
static inline PK_HD size_t light_pick(const light_table *lt, float u) { return cdf_pick(lt->cdf, lt->n, u); }

/* ---- every light, for the path tracer ------------------------------------ */

enum { LIGHT_TRIANGLE, LIGHT_SPHERE, LIGHT_POINT, LIGHT_ENV, LIGHT_SUN };

typedef struct light {
    uint32_t kind;       /* LIGHT_* */
    uint32_t index;      /* triangle number, sphere number or point light number */
    float area;          /* triangles and spheres */
    vec3 normal;         /* triangles: unit winding normal */
} light;

/* Emissive triangles, emissive spheres, point lights, the environment and
 * the sun, chosen in proportion to their emitted power. */
typedef struct light_set {
    size_t n;
    light *lights;
    float *cdf;          /* n entries, last = 1 */
    float *pmf;          /* probability of choosing each light */
    int32_t *of_prim;    /* ntris + nspheres entries: the light a primitive is, or -1 */
    int32_t env, sun;    /* the environment's and the sun's light, or -1 */
    double power;
} light_set;

PK_HIDDEN pk_status light_set_build(pk_context *ctx, const pk_scene *s, const env_light *env, light_set *ls);
PK_HIDDEN void light_set_free(const pk_allocator *al, light_set *ls);

static inline PK_HD size_t light_set_pick(const light_set *ls, float u) { return cdf_pick(ls->cdf, ls->n, u); }

#endif

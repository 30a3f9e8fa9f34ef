/*
 * scene.c - building, validating and describing the in-memory scene.
 * Loaders append with scene_add_*; scene_commit checks the invariants of
 * scene.h and derives the degenerate flags, the emissive list and the bounds.
 */
#include "scene.h"

#include "../image/image_read.h"
#include "../options.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#define SCENE_MAX_PRIMS ((size_t)1 << 30) /* triangle numbers fit uint32 with room */
#define SCENE_MAX_MATERIALS ((size_t)1 << 24)

void scene_env_init(scene_environment *env)
{
    memset(env, 0, sizeof *env);
    env->map_scale = 1.0f;
    env->to_world[0] = env->to_world[4] = env->to_world[8] = 1.0f;
    env->sun_dir = (vec3){0.0f, 1.0f, 0.0f};
    env->sun_angle = 0.53f;
    env->sky_turbidity = 3.0f;
    env->sky_scale = 1.0f;
}

void scene_rotation_y(float deg, float m[9])
{
    float c = cosf(deg * (PK_PI / 180.0f)), s = sinf(deg * (PK_PI / 180.0f));
    const float r[9] = {c, 0.0f, s, 0.0f, 1.0f, 0.0f, -s, 0.0f, c};
    memcpy(m, r, sizeof r);
}

void scene_env_clear(const pk_allocator *a, scene_environment *env)
{
    mem_free(a, env->map);
    mem_free(a, env->map_rgb);
    scene_env_init(env);
}

pk_status scene_env_load(pk_context *ctx, scene_environment *env)
{
    if (!env->map || env->map_rgb) return PK_OK;
    return image_load_rgb(ctx, env->map, &env->map_w, &env->map_h, &env->map_rgb);
}

pk_status scene_create(pk_context *ctx, const char *name, pk_scene **out)
{
    *out = NULL;
    pk_scene *s = mem_calloc(&ctx->alloc, 1, sizeof *s);
    if (!s) return ctx_nomem(ctx);
    s->alloc = ctx->alloc;
    s->bounds = aabb_empty();
    s->kept_bounds = aabb_empty();
    s->camera_medium = MEDIUM_NONE;
    pk_render_options_init(&s->render.opt);
    scene_env_init(&s->env);
    s->name = mem_strdup(&s->alloc, name ? name : "scene");
    uint32_t idx;
    if (!s->name || scene_add_material(ctx, s, "default", &idx) != PK_OK) {
        scene_destroy(s);
        return ctx_nomem(ctx);
    }
    s->materials[0].kd = v3s(0.5f);
    *out = s;
    return PK_OK;
}

void scene_destroy(pk_scene *s)
{
    if (!s) return;
    const pk_allocator *a = &s->alloc;
    for (size_t i = 0; i < s->nmaterials; i++) mem_free(a, s->materials[i].name);
    mem_free(a, s->materials);
    mem_free(a, s->mat_index);
    mem_free(a, s->positions);
    mem_free(a, s->normals);
    mem_free(a, s->uvs);
    for (size_t i = 0; i < s->ntextures; i++) texture_free(a, &s->textures[i]);
    mem_free(a, s->textures);
    mem_free(a, s->tex_nodes);
    mem_free(a, s->tris);
    mem_free(a, s->spheres);
    mem_free(a, s->lights);
    mem_free(a, s->degenerate);
    mem_free(a, s->emissive);
    mem_free(a, s->mesh_positions);
    mem_free(a, s->mesh_normals);
    mem_free(a, s->mesh_uvs);
    mem_free(a, s->colors);
    mem_free(a, s->mesh_colors);
    mem_free(a, s->tangents);
    mem_free(a, s->mesh_tangents);
    mem_free(a, s->uvs1);
    mem_free(a, s->mesh_uvs1);
    mem_free(a, s->mesh_tris);
    mem_free(a, s->meshes);
    mem_free(a, s->instances);
    mem_free(a, s->kept);
    for (size_t i = 0; i < s->nmedia; i++) medium_free(a, &s->media[i]);
    mem_free(a, s->media);
    scene_env_clear(a, &s->env);
    mem_free(a, s->builder);
    mem_free(a, s->name);
    pk_allocator copy = *a;
    mem_free(&copy, s);
}

#define APPEND(ctx, s, arr, n, cap, item, limit, what)                                    \
    do {                                                                                  \
        if ((s)->n >= (limit))                                                            \
            return ctx_error(ctx, PK_ERR_LIMIT, "%s: more than %zu %s in one scene",      \
                             (s)->name, (size_t)(limit), what);                           \
        if (!mem_grow(&(s)->alloc, (void **)&(s)->arr, &(s)->cap, (s)->n + 1, sizeof *(s)->arr)) \
            return ctx_nomem(ctx);                                                        \
        (s)->arr[(s)->n++] = (item);                                                      \
        (s)->committed = false;                                                           \
        return PK_OK;                                                                     \
    } while (0)

pk_status scene_add_position(pk_context *ctx, pk_scene *s, vec3 p)
{
    if (s->colors) { /* every position has a colour: white until set */
        if (!mem_grow(&s->alloc, (void **)&s->colors, &s->cap_colors, s->npositions + 1, sizeof *s->colors))
            return ctx_nomem(ctx);
        s->colors[s->npositions] = (rgba){1.0f, 1.0f, 1.0f, 1.0f};
    }
    if (s->tangents) { /* every position has a tangent: none until set */
        if (!mem_grow(&s->alloc, (void **)&s->tangents, &s->cap_tangents, s->npositions + 1, sizeof *s->tangents))
            return ctx_nomem(ctx);
        s->tangents[s->npositions] = (vtangent){{0.0f, 0.0f, 0.0f}, 0.0f};
    }
    if (s->uvs1) { /* every position has a second uv: (0, 0) until set */
        if (!mem_grow(&s->alloc, (void **)&s->uvs1, &s->cap_uvs1, s->npositions + 1, sizeof *s->uvs1))
            return ctx_nomem(ctx);
        s->uvs1[s->npositions] = (uv2){0.0f, 0.0f};
    }
    APPEND(ctx, s, positions, npositions, cap_positions, p, SCENE_MAX_PRIMS, "vertices");
}

/* Grows *arr (of *cap) to n colours, white from from on. */
static bool colors_grow(const pk_allocator *a, rgba **arr, size_t *cap, size_t from, size_t n)
{
    if (!mem_grow(a, (void **)arr, cap, n ? n : 1, sizeof **arr)) return false;
    for (size_t i = from; i < n; i++) (*arr)[i] = (rgba){1.0f, 1.0f, 1.0f, 1.0f};
    return true;
}

pk_status scene_set_color(pk_context *ctx, pk_scene *s, size_t i, rgba c)
{
    if (i >= s->npositions) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a colour for no vertex", s->name);
    if (!s->colors && !colors_grow(&s->alloc, &s->colors, &s->cap_colors, 0, s->npositions)) return ctx_nomem(ctx);
    s->colors[i] = c;
    s->committed = false;
    return PK_OK;
}

/* Grows *arr (of *cap) to n tangents, none from from on. */
static bool tangents_grow(const pk_allocator *a, vtangent **arr, size_t *cap, size_t from, size_t n)
{
    if (!mem_grow(a, (void **)arr, cap, n ? n : 1, sizeof **arr)) return false;
    for (size_t i = from; i < n; i++) (*arr)[i] = (vtangent){{0.0f, 0.0f, 0.0f}, 0.0f};
    return true;
}

pk_status scene_set_tangent(pk_context *ctx, pk_scene *s, size_t i, vtangent t)
{
    if (i >= s->npositions) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a tangent for no vertex", s->name);
    if (!s->tangents && !tangents_grow(&s->alloc, &s->tangents, &s->cap_tangents, 0, s->npositions))
        return ctx_nomem(ctx);
    s->tangents[i] = t;
    s->committed = false;
    return PK_OK;
}

/* Grows *arr (of *cap) to n second-set uvs, (0, 0) from from on. */
static bool uvs1_grow(const pk_allocator *a, uv2 **arr, size_t *cap, size_t from, size_t n)
{
    if (!mem_grow(a, (void **)arr, cap, n ? n : 1, sizeof **arr)) return false;
    for (size_t i = from; i < n; i++) (*arr)[i] = (uv2){0.0f, 0.0f};
    return true;
}

pk_status scene_set_uv1(pk_context *ctx, pk_scene *s, size_t i, uv2 t)
{
    if (i >= s->npositions)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: texture coordinates for no vertex", s->name);
    if (!s->uvs1 && !uvs1_grow(&s->alloc, &s->uvs1, &s->cap_uvs1, 0, s->npositions)) return ctx_nomem(ctx);
    s->uvs1[i] = t;
    s->committed = false;
    return PK_OK;
}

pk_status scene_add_normal(pk_context *ctx, pk_scene *s, vec3 n)
{
    APPEND(ctx, s, normals, nnormals, cap_normals, n, SCENE_MAX_PRIMS, "normals");
}

pk_status scene_add_uv(pk_context *ctx, pk_scene *s, uv2 t)
{
    APPEND(ctx, s, uvs, nuvs, cap_uvs, t, SCENE_MAX_PRIMS, "texture coordinates");
}

pk_status scene_add_triangle(pk_context *ctx, pk_scene *s, const triangle *t)
{
    APPEND(ctx, s, tris, ntris, cap_tris, *t, SCENE_MAX_PRIMS, "triangles");
}

pk_status scene_add_sphere(pk_context *ctx, pk_scene *s, const sphere *sp)
{
    APPEND(ctx, s, spheres, nspheres, cap_spheres, *sp, SCENE_MAX_PRIMS, "spheres");
}

bool tex_nodes_valid(const tex_node *nodes, int n, size_t ntextures)
{
    if (n < 1 || n > TEX_MAX_NODES) return false;
    for (int i = 0; i < n; i++) {
        const tex_node *d = &nodes[i];
        if (d->op >= TN_COUNT || d->map >= TMAP_COUNT) return false;
        if (d->a >= i || d->b >= i || d->c >= i || d->a < -1 || d->b < -1 || d->c < -1) return false;
        if (d->op == TN_IMAGE && (d->tex < 0 || (size_t)d->tex >= ntextures)) return false;
        if ((d->op == TN_FBM || d->op == TN_WRINKLED || d->op == TN_MARBLE) && (d->octaves < 0 || d->octaves > 64))
            return false;
    }
    return true;
}

pk_status scene_add_tex_nodes(pk_context *ctx, pk_scene *s, const tex_node *nodes, int n, tex_ref *r)
{
    if (!tex_nodes_valid(nodes, n, s->ntextures))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "a malformed texture expression");
    if (s->ntex_nodes > (size_t)INT32_MAX - (size_t)n)
        return ctx_error(ctx, PK_ERR_LIMIT, "too many texture nodes");
    if (!mem_grow(&s->alloc, (void **)&s->tex_nodes, &s->cap_tex_nodes, s->ntex_nodes + (size_t)n, sizeof *s->tex_nodes))
        return ctx_nomem(ctx);
    memcpy(s->tex_nodes + s->ntex_nodes, nodes, (size_t)n * sizeof *nodes);
    tex_ref_init(r);
    r->kind = TEX_EXPR;
    r->node = (int32_t)s->ntex_nodes;
    r->nnodes = n;
    s->ntex_nodes += (size_t)n;
    return PK_OK;
}

static pk_status add_light(pk_context *ctx, pk_scene *s, const point_light *l)
{
    APPEND(ctx, s, lights, nlights, cap_lights, *l, SCENE_MAX_PRIMS, "point lights");
}

/* What every light must be; readers check their own values first (with
 * their own messages), so these catch only callers that did not. */
static pk_status light_check(pk_context *ctx, const char *kind, vec3 power)
{
    if (!v3_finite(power) || !(power.x >= 0.0f && power.y >= 0.0f && power.z >= 0.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s light: the intensity must be finite and not negative", kind);
    return PK_OK;
}

static bool unit(vec3 d) { return v3_finite(d) && fabsf(v3_len2(d) - 1.0f) < 1e-3f; }

pk_status scene_light_point(pk_context *ctx, pk_scene *s, vec3 position, vec3 intensity)
{
    pk_status st = light_check(ctx, "point", intensity);
    if (st) return st;
    if (!v3_finite(position)) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "point light: the position is not finite");
    point_light l;
    memset(&l, 0, sizeof l);
    l.position = position;
    l.intensity = intensity;
    return add_light(ctx, s, &l);
}

pk_status scene_light_spot(pk_context *ctx, pk_scene *s, vec3 position, vec3 axis, float cos_inner, float cos_outer,
                           int falloff, vec3 intensity)
{
    pk_status st = light_check(ctx, "spot", intensity);
    if (st) return st;
    if (!v3_finite(position)) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "spot light: the position is not finite");
    if (!unit(axis)) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "spot light: the axis is not a unit vector");
    if (!(cos_outer >= -1.0f && cos_outer <= cos_inner && cos_inner <= 1.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "spot light: the inner cone must lie inside the outer one");
    if (falloff != SPOT_FALLOFF_SMOOTHSTEP && falloff != SPOT_FALLOFF_ANGLE && falloff != SPOT_FALLOFF_SQUARED)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "spot light: unknown falloff %d", falloff);
    point_light l;
    memset(&l, 0, sizeof l);
    l.position = position;
    l.intensity = intensity;
    l.spot_dir = axis;
    l.cos_inner = cos_inner;
    l.cos_outer = cos_outer;
    l.spot_falloff = falloff;
    return add_light(ctx, s, &l);
}

/* The direction from the light of a projection map's screen point (x, y): in the map's frame (x t, y t, 1). */
static vec3 frame_to_world(const float m[9], vec3 d)
{
    /* m is world -> frame; its inverse by the cofactors */
    const double a = m[0], b = m[1], c = m[2], e = m[3], f = m[4], g = m[5], h = m[6], i = m[7], j = m[8];
    const double det = a * (f * j - g * i) - b * (e * j - g * h) + c * (e * i - f * h);
    const double inv[9] = {(f * j - g * i) / det, (c * i - b * j) / det, (b * g - c * f) / det,
                           (g * h - e * j) / det, (a * j - c * h) / det, (c * e - a * g) / det,
                           (e * i - f * h) / det, (b * h - a * i) / det, (a * f - b * e) / det};
    return v3((float)(inv[0] * (double)d.x + inv[1] * (double)d.y + inv[2] * (double)d.z),
              (float)(inv[3] * (double)d.x + inv[4] * (double)d.y + inv[5] * (double)d.z),
              (float)(inv[6] * (double)d.x + inv[7] * (double)d.y + inv[8] * (double)d.z));
}

pk_status scene_light_mapped(pk_context *ctx, pk_scene *s, vec3 position, vec3 intensity, int kind, int32_t map_tex,
                             const float to_light[9], float tan_half_fov, float sx, float sy, float power)
{
    pk_status st = light_check(ctx, "mapped point", intensity);
    if (st) return st;
    if (!v3_finite(position)) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "point light: the position is not finite");
    const bool proj = kind == LIGHT_MAP_PROJECTION || kind == LIGHT_MAP_PROJECTOR;
    if (kind != LIGHT_MAP_GONIOMETRIC && !proj)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "point light: unknown map kind %d", kind);
    if (map_tex < 0 || (size_t)map_tex >= s->ntextures)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "point light: no texture %d", (int)map_tex);
    double tm[9];
    for (int k = 0; k < 9; k++) tm[k] = (double)to_light[k];
    const double det = tm[0] * (tm[4] * tm[8] - tm[5] * tm[7]) - tm[1] * (tm[3] * tm[8] - tm[5] * tm[6]) +
                       tm[2] * (tm[3] * tm[7] - tm[4] * tm[6]);
    if (!(fabs(det) > 1e-20) || !isfinite(det))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "point light: the map's frame is singular");
    if (proj && !(tan_half_fov > 0.0f && isfinite(tan_half_fov) && sx > 0.0f && sy > 0.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "projection light: the field of view must be in (0, 180)");
    point_light l;
    memset(&l, 0, sizeof l);
    l.position = position;
    l.intensity = intensity;
    l.map_kind = kind;
    l.map_tex = map_tex;
    memcpy(l.to_light, to_light, sizeof l.to_light);
    const texture *t = &s->textures[map_tex];
    const tex_level *lv = &t->lv[0];
    double sum = 0.0, wsum = 0.0;
    for (int y = 0; y < lv->h; y++)
        for (int x = 0; x < lv->w; x++) {
            float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            tex_fetch(t, lv, x, y, c);
            const double g = t->nc >= 3 ? proj ? (double)v3_luminance(v3(c[0], c[1], c[2]))
                                                                         : ((double)c[0] + (double)c[1] + (double)c[2]) / 3.0
                                        : (double)c[0];
            double wt = 1.0; /* goniometric: texels of equal solid angle */
            /* solid angle per screen area: cos^3 / t^2 (which a projector's 1 / cos^3 cancels) */
            if (kind == LIGHT_MAP_PROJECTION) {
                const double px = (2.0 * (x + 0.5) / lv->w - 1.0) * (double)sx * (double)tan_half_fov;
                const double py = (2.0 * (y + 0.5) / lv->h - 1.0) * (double)sy * (double)tan_half_fov;
                wt = pow(1.0 + px * px + py * py, -1.5);
            }
            sum += fmax(g, 0.0) * wt, wsum += wt;
        }
    l.map_mean = wsum > 0.0 ? (float)(sum / wsum) : 0.0f;
    if (proj) {
        l.proj_tan = tan_half_fov, l.proj_sx = sx, l.proj_sy = sy;
        /* the cone around the frame's +z through the window's corners bounds it (a spot with one cone) */
        const vec3 axis = v3_norm_scaled(frame_to_world(to_light, v3(0.0f, 0.0f, 1.0f)));
        float cos_min = 1.0f;
        for (int k = 0; k < 4; k++) {
            const vec3 cw = v3_norm_scaled(frame_to_world(
                to_light, v3((k & 1 ? sx : -sx) * tan_half_fov, (k & 2 ? sy : -sy) * tan_half_fov, 1.0f)));
            cos_min = fminf(cos_min, v3_dot(cw, axis));
        }
        if (!v3_finite(axis) || !(cos_min > -1.0f))
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "projection light: the frame gives no direction");
        l.spot_dir = axis;
        l.cos_inner = l.cos_outer = fmaxf(cos_min - 1e-4f, -1.0f); /* a little wider: never cuts the map */
        /* the map's power over the cone's solid angle, as map_mean is used (lights.c) */
        const double cone = 2.0 * (double)PK_PI * (1.0 - (double)l.cos_outer);
        const double omega = 4.0 * (double)sx * (double)sy * (double)tan_half_fov * (double)tan_half_fov;
        l.map_mean = (float)((double)l.map_mean * omega * (wsum > 0.0 ? wsum / ((double)lv->w * lv->h) : 0.0) / cone);
    }
    if (power > 0.0f) {
        const double flux = (proj ? 2.0 * (double)PK_PI * (1.0 - (double)l.cos_outer)
                                                          : 4.0 * (double)PK_PI) *
                            (double)l.map_mean;
        if (flux > 0.0) l.intensity = v3_scale(l.intensity, (float)((double)power / flux));
    }
    return add_light(ctx, s, &l);
}

pk_status scene_light_distant(pk_context *ctx, pk_scene *s, vec3 to_light, vec3 irradiance)
{
    pk_status st = light_check(ctx, "distant", irradiance);
    if (st) return st;
    if (!unit(to_light)) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "distant light: the direction is not a unit vector");
    point_light l;
    memset(&l, 0, sizeof l);
    l.distant = true;
    l.position = to_light;
    l.intensity = irradiance;
    return add_light(ctx, s, &l);
}

void scene_env_none(pk_scene *s)
{
    scene_env_clear(&s->alloc, &s->env);
    s->env.set = true;
}

void scene_env_add_radiance(pk_scene *s, vec3 radiance)
{
    s->env.set = true;
    s->env.radiance = v3_add(s->env.radiance, radiance);
}

static bool unit_dir(vec3 d) { return v3_finite(d) && fabsf(v3_len2(d) - 1.0f) < 1e-3f; }
static bool nonneg(vec3 v) { return v3_finite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

void scene_env_frame(pk_scene *s, const float to_world[9])
{
    s->env.set = true;
    memcpy(s->env.to_world, to_world, sizeof s->env.to_world);
}

pk_status scene_env_map(pk_context *ctx, pk_scene *s, const char *path, float scale)
{
    scene_environment *env = &s->env;
    if (!path || !path[0] || !(scale >= 0.0f) || !isfinite(scale))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "environment map: a file and a finite scale, not negative");
    if (env->map || env->map_rgb) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "one environment map per scene");
    if (!(env->map = mem_strdup(&s->alloc, path))) return ctx_nomem(ctx);
    env->set = true;
    env->map_scale = scale;
    pk_status st = scene_env_load(ctx, env);
    if (st != PK_OK) {
        mem_free(&s->alloc, env->map);
        env->map = NULL;
    }
    return st;
}

pk_status scene_env_map_pixels(pk_context *ctx, pk_scene *s, const char *name, float *rgb, int w, int h, float scale)
{
    scene_environment *env = &s->env;
    pk_status st = PK_OK;
    if (!rgb || !name || w <= 0 || h <= 0 || !(scale >= 0.0f) || !isfinite(scale))
        st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "environment map: pixels, a size and a finite scale, not negative");
    else if (env->map || env->map_rgb)
        st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "one environment map per scene");
    else if (!(env->map = mem_strdup(&s->alloc, name)))
        st = ctx_nomem(ctx);
    if (st != PK_OK) {
        mem_free(&s->alloc, rgb);
        return st;
    }
    env->set = true;
    env->map_rgb = rgb;
    env->map_w = w, env->map_h = h;
    env->map_scale = scale;
    return PK_OK;
}

vec3 scene_sun_radiance(vec3 irradiance, float angle)
{
    float a = 0.5f * angle * (PK_PI / 180.0f), s = sinf(a);
    return v3_scale(irradiance, 1.0f / (PK_PI * s * s));
}

pk_status scene_env_sun(pk_context *ctx, pk_scene *s, vec3 to_sun, vec3 radiance, float angle)
{
    if (!unit_dir(to_sun) || !nonneg(radiance) || !(angle > 0.0f && angle <= 90.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "sun: a unit direction, a finite radiance not negative and a diameter in (0, 90] degrees");
    scene_environment *env = &s->env;
    env->set = env->has_sun = true;
    env->sun_dir = to_sun;
    env->sun_radiance = radiance;
    env->sun_angle = angle;
    return PK_OK;
}

pk_status scene_env_sky(pk_context *ctx, pk_scene *s, vec3 to_sun, float turbidity, float scale, bool hosek, vec3 albedo)
{
    if (!unit_dir(to_sun) || !(turbidity >= 1.0f && turbidity <= 10.0f) || !(scale >= 0.0f) || !isfinite(scale) ||
        !nonneg(albedo) || albedo.x > 1.0f || albedo.y > 1.0f || albedo.z > 1.0f)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "sky: a unit sun direction, turbidity in 1..10, a finite scale "
                                                       "not negative and an albedo in 0..1");
    scene_environment *env = &s->env;
    env->set = env->has_sky = true;
    env->sun_dir = to_sun;
    env->sky_turbidity = turbidity;
    env->sky_scale = scale;
    env->sky_hosek = hosek;
    if (hosek) env->sky_albedo = albedo;
    return PK_OK;
}

pk_status scene_render_int(pk_context *ctx, pk_scene *s, const char *name, int v)
{
    scene_render_settings *r = &s->render;
    static const struct {
        const char *name;
        size_t has;
    } marks[] = {{"width", offsetof(scene_render_settings, has_width)},
                 {"height", offsetof(scene_render_settings, has_height)},
                 {"spp", offsetof(scene_render_settings, has_spp)},
                 {"light_samples", offsetof(scene_render_settings, has_light_samples)},
                 {"max_depth", offsetof(scene_render_settings, has_max_depth)},
                 {"threads", offsetof(scene_render_settings, has_threads)},
                 {"seed", offsetof(scene_render_settings, has_seed)},
                 {"regularize", offsetof(scene_render_settings, has_regularize)},
                 {"light_tree", offsetof(scene_render_settings, has_light_tree)}};
    const pk_int_option *o = pk_int_option_find(name);
    for (size_t i = 0; o && i < sizeof marks / sizeof marks[0]; i++) {
        if (strcmp(marks[i].name, o->name) != 0) continue;
        if (v < o->min || v > o->max)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "render setting %s: %d is not in %d..%d", o->name, v, o->min,
                             o->max);
        *options_int_field(&r->opt, o) = v;
        *(bool *)(void *)((char *)r + marks[i].has) = true;
        return PK_OK;
    }
    return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "render setting \"%.40s\" is not known", name ? name : "");
}

void scene_render_accel(pk_scene *s, pk_accel_kind kind) { s->render.opt.accel = kind, s->render.has_accel = true; }
void scene_render_integrator(pk_scene *s, pk_integrator_kind kind)
{
    s->render.opt.integrator = kind, s->render.has_integrator = true;
}
void scene_render_fresnel(pk_scene *s, bool on) { s->render.opt.fresnel = on ? 1 : 0, s->render.has_fresnel = true; }
void scene_render_energy_compensation(pk_scene *s, bool on)
{
    s->render.opt.energy_compensation = on ? 1 : 0, s->render.has_energy_compensation = true;
}

pk_status scene_render_clamp(pk_context *ctx, pk_scene *s, float clamp_indirect)
{
    if (!(clamp_indirect >= 0.0f) || !isfinite(clamp_indirect))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "render setting clamp_indirect must be finite and not negative");
    s->render.opt.clamp_indirect = clamp_indirect, s->render.has_clamp_indirect = true;
    return PK_OK;
}

pk_status scene_render_filter(pk_context *ctx, pk_scene *s, const pk_filter *f)
{
    const pk_status st = options_check_filter(ctx, f);
    if (st != PK_OK) return st;
    s->render.opt.filter = *f, s->render.has_filter = true;
    return PK_OK;
}

void scene_scale_emission(pk_scene *s, float k)
{
    for (size_t i = 0; i < s->nmaterials; i++) s->materials[i].ke = v3_scale(s->materials[i].ke, k);
    for (size_t i = 0; i < s->nlights; i++) s->lights[i].intensity = v3_scale(s->lights[i].intensity, k);
    for (size_t i = 0; i < s->nmedia; i++) s->media[i].le = v3_scale(s->media[i].le, k);
    s->env.radiance = v3_scale(s->env.radiance, k);
    if (s->env.map || s->env.map_rgb) s->env.map_scale *= k;
    if (s->env.has_sun) s->env.sun_radiance = v3_scale(s->env.sun_radiance, k);
    if (s->env.has_sky) s->env.sky_scale *= k;
}

/* FNV-1a */
static size_t name_hash(const char *name)
{
    uint64_t h = 1469598103934665603u;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++) h = (h ^ *c) * 1099511628211u;
    return (size_t)(h ^ (h >> 32));
}

/* Points index at material i: replaces an older material of the same name. */
static void index_put(uint32_t *index, size_t slots, const material *mats, uint32_t i)
{
    size_t k = name_hash(mats[i].name) & (slots - 1);
    while (index[k] && strcmp(mats[index[k] - 1].name, mats[i].name) != 0) k = (k + 1) & (slots - 1);
    index[k] = i + 1;
}

/* Makes room in the index for one more material (rebuilt at twice the size
 * when it would be more than half full). */
static bool index_reserve(pk_scene *s)
{
    if (2 * (s->nmaterials + 1) < s->mat_slots) return true;
    size_t slots = s->mat_slots ? 2 * s->mat_slots : 64;
    uint32_t *index = mem_calloc(&s->alloc, slots, sizeof *index);
    if (!index) return false;
    for (size_t i = 0; i < s->nmaterials; i++) index_put(index, slots, s->materials, (uint32_t)i);
    mem_free(&s->alloc, s->mat_index);
    s->mat_index = index;
    s->mat_slots = slots;
    return true;
}

pk_status scene_add_material(pk_context *ctx, pk_scene *s, const char *name, uint32_t *index)
{
    if (s->nmaterials >= SCENE_MAX_MATERIALS)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: more than %zu materials in one scene", s->name,
                         (size_t)SCENE_MAX_MATERIALS);
    material m;
    material_init(&m);
    m.name = mem_strdup(&s->alloc, name);
    if (!m.name) return ctx_nomem(ctx);
    if (!mem_grow(&s->alloc, (void **)&s->materials, &s->cap_materials, s->nmaterials + 1, sizeof m) ||
        !index_reserve(s)) {
        mem_free(&s->alloc, m.name);
        return ctx_nomem(ctx);
    }
    *index = (uint32_t)s->nmaterials;
    s->materials[s->nmaterials++] = m;
    index_put(s->mat_index, s->mat_slots, s->materials, *index);
    return PK_OK;
}

pk_status scene_material_copy(pk_context *ctx, pk_scene *s, uint32_t mat, const char *name, uint32_t *index)
{
    if (mat >= s->nmaterials) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: no material %u", s->name, mat);
    uint32_t idx;
    pk_status st = scene_add_material(ctx, s, name, &idx);
    if (st != PK_OK) return st;
    material *c = &s->materials[idx];
    char *own = c->name;
    *c = s->materials[mat]; /* (the array may have moved: index again) */
    c->name = own;
    *index = idx;
    return PK_OK;
}

int scene_mix_depth(const pk_scene *s, uint32_t mat)
{
    if (mat >= s->nmaterials || s->materials[mat].type != MAT_MIX) return 0;
    const material *m = &s->materials[mat];
    if (m->mix_a < 0 || m->mix_b < 0 || (uint32_t)m->mix_a >= mat || (uint32_t)m->mix_b >= mat)
        return MATERIAL_MIX_DEPTH + 1; /* not a mix of earlier materials */
    const int a = scene_mix_depth(s, (uint32_t)m->mix_a);
    if (a >= MATERIAL_MIX_DEPTH) return a + 1;
    const int b = scene_mix_depth(s, (uint32_t)m->mix_b);
    return 1 + (a > b ? a : b);
}

pk_status scene_material_with_emission(pk_context *ctx, pk_scene *s, uint32_t mat, const char *name, vec3 ke,
                                       bool two_sided, uint32_t *index)
{
    if (!v3_finite(ke) || !(v3_min_comp(ke) >= 0.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: emission must be finite and not negative", name);
    pk_status st;
    uint32_t parts[2];
    const bool mix = mat < s->nmaterials && s->materials[mat].type == MAT_MIX;
    if (mix) { /* a mix emits through whichever material a hit meets: both emit */
        const int ab[2] = {s->materials[mat].mix_a, s->materials[mat].mix_b};
        for (int k = 0; k < 2; k++)
            if ((st = scene_material_with_emission(ctx, s, (uint32_t)ab[k], name, ke, two_sided, &parts[k])) != PK_OK)
                return st;
    }
    st = scene_material_copy(ctx, s, mat, name, index);
    if (st != PK_OK) return st;
    material *c = &s->materials[*index];
    if (mix) c->mix_a = (int)parts[0], c->mix_b = (int)parts[1];
    c->ke = ke;
    c->two_sided = two_sided;
    return PK_OK;
}

int64_t scene_find_material(const pk_scene *s, const char *name)
{
    if (!s->mat_slots) return -1;
    size_t k = name_hash(name) & (s->mat_slots - 1);
    for (; s->mat_index[k]; k = (k + 1) & (s->mat_slots - 1))
        if (strcmp(s->materials[s->mat_index[k] - 1].name, name) == 0) return (int64_t)s->mat_index[k] - 1;
    return -1;
}

/* ---- meshes and instances ---------------------------------------------- */

/* Appends n elements of size elem, from element first of src on, to *arr
 * (count *len, capacity *cap). src is offset only when there is something to
 * copy: a mesh without normals or uvs has src NULL, and NULL + 0 is undefined. */
static bool append_n(const pk_allocator *a, void **arr, size_t *len, size_t *cap, const void *src, size_t first,
                     size_t n, size_t elem)
{
    if (!n) return true;
    if (!mem_grow(a, arr, cap, *len + n, elem)) return false;
    memcpy((char *)*arr + *len * elem, (const char *)src + first * elem, n * elem);
    *len += n;
    return true;
}

pk_status scene_capture_mesh(pk_context *ctx, pk_scene *s, size_t pos0, size_t nrm0, size_t uv0, size_t tri0,
                             uint32_t *mesh)
{
    if (pos0 > s->npositions || nrm0 > s->nnormals || uv0 > s->nuvs || tri0 > s->ntris)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a mesh begins past the end of the scene", s->name);
    if (s->ninstances > s->nflattened && s->instances[s->ninstances - 1].at > tri0)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: an instance inside a mesh being defined", s->name);
    if (s->nmeshes >= SCENE_MAX_PRIMS)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: more than %zu meshes in one scene", s->name, (size_t)SCENE_MAX_PRIMS);
    scene_mesh m = {s->nmesh_positions, s->npositions - pos0, s->nmesh_normals, s->nnormals - nrm0,
                    s->nmesh_uvs,       s->nuvs - uv0,        s->nmesh_tris,    s->ntris - tri0};
    for (size_t k = tri0; k < s->ntris; k++) {
        const triangle *t = &s->tris[k];
        for (int j = 0; j < 3; j++)
            if (t->v[j] < pos0 || t->v[j] >= s->npositions || (t->n[j] >= 0 && (size_t)t->n[j] < nrm0) ||
                (t->t[j] >= 0 && (size_t)t->t[j] < uv0))
                return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a mesh's triangle uses a vertex from outside it",
                                 s->name);
    }
    const pk_allocator *a = &s->alloc;
    if (!mem_grow(a, (void **)&s->meshes, &s->cap_meshes, s->nmeshes + 1, sizeof *s->meshes) ||
        !append_n(a, (void **)&s->mesh_positions, &s->nmesh_positions, &s->cap_mesh_positions, s->positions, pos0,
                  m.npos, sizeof(vec3)) ||
        !append_n(a, (void **)&s->mesh_normals, &s->nmesh_normals, &s->cap_mesh_normals, s->normals, nrm0, m.nnrm,
                  sizeof(vec3)) ||
        !append_n(a, (void **)&s->mesh_uvs, &s->nmesh_uvs, &s->cap_mesh_uvs, s->uvs, uv0, m.nuv, sizeof(uv2)) ||
        !mem_grow(a, (void **)&s->mesh_tris, &s->cap_mesh_tris, s->nmesh_tris + m.ntris, sizeof(triangle))) {
        /* undo the partial appends: the mesh is not there */
        s->nmesh_positions = m.first_pos, s->nmesh_normals = m.first_nrm, s->nmesh_uvs = m.first_uv;
        return ctx_nomem(ctx);
    }
    if (s->colors || s->mesh_colors) { /* the mesh's colours beside its positions */
        const size_t had = s->mesh_colors ? m.first_pos : 0;
        if (!colors_grow(a, &s->mesh_colors, &s->cap_mesh_colors, had, s->nmesh_positions)) {
            s->nmesh_positions = m.first_pos, s->nmesh_normals = m.first_nrm, s->nmesh_uvs = m.first_uv;
            return ctx_nomem(ctx);
        }
        if (s->colors) memcpy(s->mesh_colors + m.first_pos, s->colors + pos0, m.npos * sizeof *s->colors);
    }
    if (s->tangents || s->mesh_tangents) { /* the mesh's tangents beside its positions */
        const size_t had = s->mesh_tangents ? m.first_pos : 0;
        if (!tangents_grow(a, &s->mesh_tangents, &s->cap_mesh_tangents, had, s->nmesh_positions)) {
            s->nmesh_positions = m.first_pos, s->nmesh_normals = m.first_nrm, s->nmesh_uvs = m.first_uv;
            return ctx_nomem(ctx);
        }
        if (s->tangents) memcpy(s->mesh_tangents + m.first_pos, s->tangents + pos0, m.npos * sizeof *s->tangents);
    }
    if (s->uvs1 || s->mesh_uvs1) { /* the mesh's second uvs beside its positions */
        const size_t had = s->mesh_uvs1 ? m.first_pos : 0;
        if (!uvs1_grow(a, &s->mesh_uvs1, &s->cap_mesh_uvs1, had, s->nmesh_positions)) {
            s->nmesh_positions = m.first_pos, s->nmesh_normals = m.first_nrm, s->nmesh_uvs = m.first_uv;
            return ctx_nomem(ctx);
        }
        if (s->uvs1) memcpy(s->mesh_uvs1 + m.first_pos, s->uvs1 + pos0, m.npos * sizeof *s->uvs1);
    }
    for (size_t k = tri0; k < s->ntris; k++) {
        triangle t = s->tris[k];
        for (int j = 0; j < 3; j++) {
            t.v[j] = (uint32_t)(t.v[j] - pos0);
            if (t.n[j] >= 0) t.n[j] = (int32_t)((size_t)t.n[j] - nrm0);
            if (t.t[j] >= 0) t.t[j] = (int32_t)((size_t)t.t[j] - uv0);
        }
        s->mesh_tris[s->nmesh_tris++] = t;
    }
    s->npositions = pos0, s->nnormals = nrm0, s->nuvs = uv0, s->ntris = tri0;
    *mesh = (uint32_t)s->nmeshes;
    s->meshes[s->nmeshes++] = m;
    s->committed = false;
    return PK_OK;
}

pk_status scene_add_instance(pk_context *ctx, pk_scene *s, uint32_t mesh, const xform *to_world, uint32_t mat)
{
    if (mesh >= s->nmeshes)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: instance of mesh %u, which does not exist", s->name, mesh);
    if (mat != SCENE_MESH_MATERIAL && mat >= s->nmaterials)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: instance material %u does not exist", s->name, mat);
    double det = xform_det3(to_world);
    if (!xform_finite(to_world) || !xform_is_affine(to_world) || !(det != 0.0) || !isfinite(det))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: an instance's transform is not finite, affine and invertible",
                         s->name);
    scene_instance in = {mesh, mat, *to_world, s->ntris};
    APPEND(ctx, s, instances, ninstances, cap_instances, in, PK_MAX_INSTANCES, "instances");
}

/* Appends instance in's vertices to the world arrays and its triangles to
 * out[*o ...]. */
static pk_status place_instance(pk_context *ctx, pk_scene *s, const scene_instance *in, triangle *out, size_t *o)
{
    const scene_mesh *m = &s->meshes[in->mesh];
    size_t pbase = s->npositions, nbase = s->nnormals, tbase = s->nuvs;
    pk_status st;
    float nm[9] = {0};
    if (m->nnrm && !xform_normal_matrix(&in->to_world, nm))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: an instance's transform is singular", s->name);
    for (size_t i = 0; i < m->npos; i++) {
        vec3 q = xform_point(&in->to_world, s->mesh_positions[m->first_pos + i]);
        if (!v3_finite(q)) return ctx_error(ctx, PK_ERR_PARSE, "%s: a transformed vertex is not finite", s->name);
        if ((st = scene_add_position(ctx, s, q))) return st;
    }
    if (s->mesh_colors) {
        if (!s->colors && !colors_grow(&s->alloc, &s->colors, &s->cap_colors, 0, s->npositions)) return ctx_nomem(ctx);
        memcpy(s->colors + pbase, s->mesh_colors + m->first_pos, m->npos * sizeof *s->colors);
    }
    if (s->mesh_tangents) { /* directions by to_world; a mirroring transform turns the handedness */
        if (!s->tangents && !tangents_grow(&s->alloc, &s->tangents, &s->cap_tangents, 0, s->npositions))
            return ctx_nomem(ctx);
        const float hand = xform_det3(&in->to_world) < 0.0 ? -1.0f : 1.0f;
        for (size_t i = 0; i < m->npos; i++) {
            const vtangent t = s->mesh_tangents[m->first_pos + i];
            vtangent tw = {v3_norm_scaled(xform_vector(&in->to_world, t.t)), t.w * hand};
            if (!v3_finite(tw.t) || t.w == 0.0f) tw = (vtangent){{0.0f, 0.0f, 0.0f}, 0.0f};
            s->tangents[pbase + i] = tw;
        }
    }
    if (s->mesh_uvs1) {
        if (!s->uvs1 && !uvs1_grow(&s->alloc, &s->uvs1, &s->cap_uvs1, 0, s->npositions)) return ctx_nomem(ctx);
        memcpy(s->uvs1 + pbase, s->mesh_uvs1 + m->first_pos, m->npos * sizeof *s->uvs1);
    }
    for (size_t i = 0; i < m->nnrm; i++) {
        vec3 n = v3_norm_scaled(xform_apply3(nm, s->mesh_normals[m->first_nrm + i]));
        if (!v3_finite(n)) n = v3s(0.0f);
        if ((st = scene_add_normal(ctx, s, n))) return st;
    }
    for (size_t i = 0; i < m->nuv; i++)
        if ((st = scene_add_uv(ctx, s, s->mesh_uvs[m->first_uv + i]))) return st;
    for (size_t k = 0; k < m->ntris; k++) {
        triangle t = s->mesh_tris[m->first_tri + k];
        for (int j = 0; j < 3; j++) {
            t.v[j] = (uint32_t)(t.v[j] + pbase);
            if (t.n[j] >= 0) t.n[j] = (int32_t)((size_t)t.n[j] + nbase);
            if (t.t[j] >= 0) t.t[j] = (int32_t)((size_t)t.t[j] + tbase);
        }
        if (in->material != SCENE_MESH_MATERIAL) t.material = in->material;
        out[(*o)++] = t;
    }
    return PK_OK;
}

static bool box_empty(aabb b) { return !(b.lo.x <= b.hi.x); }

static bool material_emits(const material *m) { return m->ke.x > 0.0f || m->ke.y > 0.0f || m->ke.z > 0.0f; }

/* Whether instance in would place an emitting triangle. */
static bool instance_emits(const pk_scene *s, const scene_instance *in)
{
    if (in->material != SCENE_MESH_MATERIAL) return material_emits(&s->materials[in->material]);
    const scene_mesh *m = &s->meshes[in->mesh];
    for (size_t k = 0; k < m->ntris; k++)
        if (material_emits(&s->materials[s->mesh_tris[m->first_tri + k].material])) return true;
    return false;
}

/* keep[i - first] for instances [first, n): which stay instances (scene.h's
 * rule, ctx's config scene.instances). */
static pk_status choose_kept(pk_context *ctx, const pk_scene *s, size_t first, size_t n, uint8_t *keep)
{
    const int mode = ctx->config.instances; /* 0 auto, 1 flatten, 2 keep */
    memset(keep, 0, n - first);
    if (mode == 1) return PK_OK;
    uint32_t *placed = NULL;
    if (mode == 0) {
        placed = mem_calloc(&s->alloc, s->nmeshes ? s->nmeshes : 1, sizeof *placed);
        if (!placed) return ctx_nomem(ctx);
        for (size_t i = 0; i < s->ninstances; i++)
            if (placed[s->instances[i].mesh] < 2) placed[s->instances[i].mesh]++;
    }
    size_t tris = 0, emitting = 0;
    for (size_t i = first; i < n; i++) {
        const scene_instance *in = &s->instances[i];
        if (placed && placed[in->mesh] < 2) continue;
        if (instance_emits(s, in)) {
            emitting++;
            continue;
        }
        keep[i - first] = 1;
        tris += s->meshes[in->mesh].ntris;
    }
    mem_free(&s->alloc, placed);
    if (mode == 0 && tris < SCENE_KEEP_MIN_TRIS) {
        memset(keep, 0, n - first);
        return PK_OK;
    }
    if (emitting)
        ctx_warn(ctx, "%s: %zu emitting instance%s flattened (lights are world triangles): their triangles take "
                      "memory as if written out", s->name, emitting, emitting == 1 ? "" : "s");
    return PK_OK;
}

/* The kept instances' hit numbers and world bounds: every vertex of a
 * triangle that is not degenerate in the mesh's space, placed as
 * flattening would place it, so that the bounds (and the ray offsets and
 * framing derived from them) are a flattened scene's. */
static pk_status number_kept(pk_context *ctx, pk_scene *s)
{
    s->nkept_tris = 0;
    s->kept_bounds = aabb_empty();
    if (!s->nkept) return PK_OK;
    uint64_t next = (uint64_t)s->ntris + s->nspheres;
    for (size_t i = 0; i < s->nkept; i++) {
        s->kept[i].prim0 = (uint32_t)next;
        next += s->meshes[s->kept[i].mesh].ntris;
        if (next >= PK_NO_HIT)
            return ctx_error(ctx, PK_ERR_LIMIT, "%s: the instances place %llu triangles; at most %u can be numbered",
                             s->name, (unsigned long long)next, (unsigned)PK_NO_HIT - 1u);
    }
    s->nkept_tris = (size_t)(next - s->ntris - s->nspheres);
    uint8_t *used = mem_calloc(&s->alloc, s->nmesh_positions ? s->nmesh_positions : 1, 1);
    if (!used) return ctx_nomem(ctx);
    for (size_t mi = 0; mi < s->nmeshes; mi++) {
        const scene_mesh *m = &s->meshes[mi];
        for (size_t k = 0; k < m->ntris; k++) {
            const triangle *t = &s->mesh_tris[m->first_tri + k];
            const vec3 *p = s->mesh_positions + m->first_pos;
            if (tri_is_degenerate(p[t->v[0]], p[t->v[1]], p[t->v[2]])) continue;
            for (int j = 0; j < 3; j++) used[m->first_pos + t->v[j]] = 1;
        }
    }
    aabb b = aabb_empty();
    for (size_t i = 0; i < s->nkept; i++) {
        const scene_mesh *m = &s->meshes[s->kept[i].mesh];
        for (size_t v = 0; v < m->npos; v++)
            if (used[m->first_pos + v]) b = aabb_grow(b, xform_point(&s->kept[i].to_world, s->mesh_positions[m->first_pos + v]));
    }
    mem_free(&s->alloc, used);
    s->kept_bounds = b;
    return PK_OK;
}

/* Instances [nflattened, ninstances) into the triangle list, each at its
 * place, or into the kept list. */
static pk_status flatten_instances(pk_context *ctx, pk_scene *s)
{
    size_t first = s->nflattened, n = s->ninstances;
    if (first == n) return number_kept(ctx, s);
    uint8_t *keep = mem_alloc(&s->alloc, n - first);
    if (!keep) return ctx_nomem(ctx);
    pk_status kst = choose_kept(ctx, s, first, n, keep);
    for (size_t i = first; i < n && kst == PK_OK; i++) {
        if (!keep[i - first]) continue;
        const scene_instance *in = &s->instances[i];
        scene_kept k;
        memset(&k, 0, sizeof k);
        k.to_world = in->to_world;
        k.mesh = in->mesh;
        k.material = in->material;
        if (s->meshes[in->mesh].nnrm && !xform_normal_matrix(&in->to_world, k.nrm))
            kst = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: an instance's transform is singular", s->name);
        else if (!mem_grow(&s->alloc, (void **)&s->kept, &s->cap_kept, s->nkept + 1, sizeof *s->kept))
            kst = ctx_nomem(ctx);
        else
            s->kept[s->nkept++] = k;
    }
    if (kst != PK_OK) {
        mem_free(&s->alloc, keep);
        return kst;
    }
    size_t extra = 0;
    for (size_t i = first; i < n; i++) {
        if (keep[i - first]) continue;
        extra += s->meshes[s->instances[i].mesh].ntris;
        if (extra > SCENE_MAX_PRIMS) break;
    }
    if (extra > SCENE_MAX_PRIMS || s->ntris + extra > SCENE_MAX_PRIMS) {
        mem_free(&s->alloc, keep);
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: more than %zu triangles in one scene", s->name,
                         (size_t)SCENE_MAX_PRIMS);
    }
    size_t total = s->ntris + extra;
    triangle *out = mem_realloc_array(&s->alloc, NULL, total ? total : 1, sizeof *out);
    if (!out) {
        mem_free(&s->alloc, keep);
        return ctx_nomem(ctx);
    }
    size_t o = 0, i = first;
    pk_status st = PK_OK;
    for (size_t k = 0; k <= s->ntris && st == PK_OK; k++) {
        for (; i < n && s->instances[i].at <= k && st == PK_OK; i++)
            if (!keep[i - first]) st = place_instance(ctx, s, &s->instances[i], out, &o);
        if (k < s->ntris) out[o++] = s->tris[k];
    }
    mem_free(&s->alloc, keep);
    if (st) {
        mem_free(&s->alloc, out);
        return st;
    }
    mem_free(&s->alloc, s->tris);
    s->tris = out;
    s->ntris = s->cap_tris = total;
    s->nflattened = n;
    return number_kept(ctx, s);
}

pk_status scene_commit(pk_context *ctx, pk_scene *s)
{
    char why[256];
    pk_status fst = flatten_instances(ctx, s);
    if (fst != PK_OK) return fst;
    if (!scene_check(s, why, sizeof why))
        return ctx_error(ctx, PK_ERR_PARSE, "%s: invalid scene: %s", s->name, why);
    pk_status est = scene_env_load(ctx, &s->env);
    if (est != PK_OK) return est;
    est = scene_media_prepare(ctx, s);
    if (est != PK_OK) return est;
    mem_free(&s->alloc, s->degenerate);
    mem_free(&s->alloc, s->emissive);
    s->degenerate = NULL;
    s->emissive = NULL;
    s->ndegenerate = s->nemissive = 0;
    s->bounds = aabb_empty();
    s->has_cutout = s->has_textured = s->has_interfaces = s->has_emission_maps = false;
    for (size_t i = 0; i < s->nmaterials; i++) {
        material *m = &s->materials[i];
        m->cutout = m->map_d.kind != TEX_NONE || m->blend;
        m->textured = material_anisotropic(m) || m->vertex_color;
        for (int k = 0; k < MATERIAL_NMAPS; k++) /* (map_d makes holes, not a textured surface) */
            m->textured |= material_map(m, k) != &m->map_d && material_map(m, k)->kind != TEX_NONE;
        s->has_cutout |= m->cutout;
        s->has_interfaces |= m->type == MAT_INTERFACE;
        s->has_textured |= m->textured;
        s->has_emission_maps |= m->map_ke.kind != TEX_NONE && v3_max_comp(m->ke) > 0.0f;
    }
    if (s->ntris) {
        s->degenerate = mem_calloc(&s->alloc, s->ntris, 1);
        if (!s->degenerate) return ctx_nomem(ctx);
    }
    size_t nemit = 0;
    for (size_t k = 0; k < s->ntris; k++) {
        vec3 a, b, c;
        scene_tri_verts(s, k, &a, &b, &c);
        if (tri_is_degenerate(a, b, c)) {
            s->degenerate[k] = 1;
            s->ndegenerate++;
            continue;
        }
        s->bounds = aabb_grow(aabb_grow(aabb_grow(s->bounds, a), b), c);
        if (material_emits(&s->materials[s->tris[k].material])) nemit++;
    }
    for (size_t i = 0; i < s->nspheres; i++) {
        const sphere *sp = &s->spheres[i];
        s->bounds = aabb_grow(s->bounds, v3_sub(sp->center, v3s(sp->radius)));
        s->bounds = aabb_grow(s->bounds, v3_add(sp->center, v3s(sp->radius)));
    }
    if (s->nkept_tris && !box_empty(s->kept_bounds))
        s->bounds = aabb_grow(aabb_grow(s->bounds, s->kept_bounds.lo), s->kept_bounds.hi);
    if (nemit) {
        s->emissive = mem_realloc_array(&s->alloc, NULL, nemit, sizeof *s->emissive);
        if (!s->emissive) return ctx_nomem(ctx);
        for (size_t k = 0; k < s->ntris; k++)
            if (!s->degenerate[k] && material_emits(&s->materials[s->tris[k].material]))
                s->emissive[s->nemissive++] = (uint32_t)k;
    }
    if (s->ndegenerate)
        ctx_warn(ctx, "%s: %zu degenerate triangle%s (zero area) dropped", s->name, s->ndegenerate,
                 s->ndegenerate == 1 ? "" : "s");
    if (s->ntris == s->ndegenerate && s->nspheres == 0 && box_empty(s->kept_bounds))
        return ctx_error(ctx, PK_ERR_EMPTY_SCENE, "%s: no renderable geometry (%zu triangles, %zu degenerate, no spheres)",
                         s->name, s->ntris, s->ndegenerate);
    if (!v3_finite(s->bounds.lo) || !v3_finite(s->bounds.hi))
        return ctx_error(ctx, PK_ERR_PARSE, "%s: scene bounds are not finite", s->name);
    s->committed = true;
    return PK_OK;
}

bool scene_check(const pk_scene *s, char *why, size_t n)
{
#define FAIL(...) do { if (why) snprintf(why, n, __VA_ARGS__); return false; } while (0)
    if (s->nmaterials == 0) FAIL("no default material");
    for (size_t i = 0; i < s->nmaterials; i++) {
        int64_t j = scene_find_material(s, s->materials[i].name);
        if (j < (int64_t)i || (size_t)j >= s->nmaterials || strcmp(s->materials[j].name, s->materials[i].name) != 0)
            FAIL("material %zu is not found by its name", i);
    }
    for (size_t i = 0; i < s->npositions; i++)
        if (!v3_finite(s->positions[i])) FAIL("position %zu is not finite", i);
    for (size_t i = 0; i < s->nnormals; i++)
        if (!v3_finite(s->normals[i])) FAIL("normal %zu is not finite", i);
    for (size_t i = 0; i < s->nuvs; i++)
        if (!isfinite(s->uvs[i].u) || !isfinite(s->uvs[i].v)) FAIL("uv %zu is not finite", i);
    for (size_t i = 0; s->uvs1 && i < s->npositions; i++)
        if (!isfinite(s->uvs1[i].u) || !isfinite(s->uvs1[i].v)) FAIL("the second uv of vertex %zu is not finite", i);
    size_t tex_bytes = 0;
    for (size_t i = 0; i < s->ntextures; i++) tex_bytes += s->textures[i].bytes;
    if (tex_bytes != s->texture_bytes) FAIL("texture bytes do not add up");
    for (size_t i = 0; i < s->nmaterials; i++) {
        const material *m = &s->materials[i];
        for (int j = 0; j < MATERIAL_NMAPS; j++) {
            const tex_ref *r = material_map_c(m, j);
            if (r->kind == TEX_IMAGE && (r->tex < 0 || (size_t)r->tex >= s->ntextures))
                FAIL("material %zu: texture index out of range", i);
            if (r->kind == TEX_EXPR &&
                (r->node < 0 || r->nnodes < 1 || (size_t)r->node > s->ntex_nodes ||
                 (size_t)r->nnodes > s->ntex_nodes - (size_t)r->node ||
                 !tex_nodes_valid(s->tex_nodes + r->node, r->nnodes, s->ntextures)))
                FAIL("material %zu: texture expression out of range", i);
        }
        if (m->type == MAT_MIX && scene_mix_depth(s, (uint32_t)i) > MATERIAL_MIX_DEPTH)
            FAIL("material %zu: a mix of materials that do not come before it, or nested more than %d deep", i,
                 MATERIAL_MIX_DEPTH);
    }
    for (size_t k = 0; k < s->ntris; k++) {
        const triangle *t = &s->tris[k];
        for (int j = 0; j < 3; j++) {
            if (t->v[j] >= s->npositions) FAIL("triangle %zu: vertex index out of range", k);
            if (t->n[j] < -1 || (t->n[j] >= 0 && (size_t)t->n[j] >= s->nnormals))
                FAIL("triangle %zu: normal index out of range", k);
            if (t->t[j] < -1 || (t->t[j] >= 0 && (size_t)t->t[j] >= s->nuvs))
                FAIL("triangle %zu: uv index out of range", k);
        }
        if (t->material >= s->nmaterials) FAIL("triangle %zu: material out of range", k);
    }
    for (size_t i = 0; i < s->nspheres; i++) {
        const sphere *sp = &s->spheres[i];
        if (!v3_finite(sp->center) || !(sp->radius > 0.0f) || !isfinite(sp->radius))
            FAIL("sphere %zu: bad center or radius", i);
        if (sp->material >= s->nmaterials) FAIL("sphere %zu: material out of range", i);
    }
    for (size_t i = 0; i < s->nlights; i++) {
        const point_light *l = &s->lights[i];
        if (!v3_finite(l->position) || !v3_finite(l->intensity) || !v3_finite(l->spot_dir) ||
            !isfinite(l->cos_inner) || !isfinite(l->cos_outer))
            FAIL("light %zu is not finite", i);
        if (l->distant && fabsf(v3_len(l->position) - 1.0f) > 1e-3f)
            FAIL("light %zu: a distant light's direction is not a unit vector", i);
        if (v3_len2(l->spot_dir) > 0.0f &&
            (fabsf(v3_len(l->spot_dir) - 1.0f) > 1e-3f || l->cos_outer > l->cos_inner || l->cos_outer < -1.0f ||
             l->cos_inner > 1.0f || l->spot_falloff < 0 || l->spot_falloff > SPOT_FALLOFF_SQUARED))
            FAIL("light %zu: a spot light needs a unit axis and -1 <= cos_outer <= cos_inner <= 1", i);
    }
    for (size_t i = 0; i < s->nmeshes; i++) {
        const scene_mesh *m = &s->meshes[i];
        if (m->first_pos + m->npos > s->nmesh_positions || m->first_nrm + m->nnrm > s->nmesh_normals ||
            m->first_uv + m->nuv > s->nmesh_uvs || m->first_tri + m->ntris > s->nmesh_tris)
            FAIL("mesh %zu: range out of bounds", i);
        for (size_t k = m->first_tri; k < m->first_tri + m->ntris; k++) {
            const triangle *t = &s->mesh_tris[k];
            for (int j = 0; j < 3; j++)
                if (t->v[j] >= m->npos || (t->n[j] >= 0 && (size_t)t->n[j] >= m->nnrm) ||
                    (t->t[j] >= 0 && (size_t)t->t[j] >= m->nuv) || t->n[j] < -1 || t->t[j] < -1)
                    FAIL("mesh %zu: triangle %zu: index out of range", i, k - m->first_tri);
            if (t->material >= s->nmaterials) FAIL("mesh %zu: triangle %zu: material out of range", i, k - m->first_tri);
        }
    }
    for (size_t i = 0; i < s->ninstances; i++)
        if (s->instances[i].mesh >= s->nmeshes ||
            (s->instances[i].material != SCENE_MESH_MATERIAL && s->instances[i].material >= s->nmaterials))
            FAIL("instance %zu: mesh or material out of range", i);
    if (s->committed && s->nflattened != s->ninstances) FAIL("instances not flattened");
    uint64_t next = (uint64_t)s->ntris + s->nspheres;
    for (size_t i = 0; i < s->nkept; i++) {
        const scene_kept *k = &s->kept[i];
        if (k->mesh >= s->nmeshes || (k->material != SCENE_MESH_MATERIAL && k->material >= s->nmaterials))
            FAIL("kept instance %zu: mesh or material out of range", i);
        if (s->committed && (k->prim0 != next || next + s->meshes[k->mesh].ntris >= PK_NO_HIT))
            FAIL("kept instance %zu: hit numbers out of order", i);
        next += s->meshes[k->mesh].ntris;
    }
    return true;
#undef FAIL
}

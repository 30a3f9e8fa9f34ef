/*
 * api_build.c - the public scene-building API (paprsek.h, "building
 * scenes"; docs/scene-api.md): pk_params over the parameter dictionary
 * (io/pdict.h), materials and lights through the creators the JSON reader
 * uses (io/create_material.h, io/create_light.h), meshes, objects and
 * instances through the builder (io/scene_build.h). Messages name the
 * scene and the thing where a reader names a file line.
 */
#include "io/create_light.h"
#include "io/create_material.h"
#include "io/pdict.h"
#include "io/scene_build.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define API_MAX_PRIMS ((size_t)1 << 30) /* vertices or triangles of one mesh (the scene's limit) */
#define PARAMS_MAX_FLOATS 4096           /* numbers in one parameter (a colour is 3) */

/* ---- pk_params ---------------------------------------------------------------- */

struct pk_params {
    pdict d; /* owning, no source: checked when a creator reads it */
};

pk_status pk_params_create(pk_context *ctx, pk_params **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_params *p = mem_calloc(&ctx->alloc, 1, sizeof *p);
    if (!p) return ctx_nomem(ctx);
    pd_init(&p->d, ctx, NULL, NULL, "parameters", true);
    *out = p;
    return PK_OK;
}

void pk_params_destroy(pk_params *p)
{
    if (!p) return;
    pk_allocator a = p->d.ctx->alloc;
    pd_free(&p->d);
    mem_free(&a, p);
}

void pk_params_clear(pk_params *p)
{
    if (p) pd_free(&p->d);
}

static pk_status set_entry(pk_params *p, const char *name, const pd_entry *e)
{
    if (!p) return PK_ERR_INVALID_ARGUMENT;
    if (!name || !name[0]) return ctx_error(p->d.ctx, PK_ERR_INVALID_ARGUMENT, "pk_params: a parameter needs a name");
    pd_entry c = *e;
    c.name = name;
    return pd_set(&p->d, &c);
}

pk_status pk_params_set_float(pk_params *p, const char *name, float value)
{
    const pd_entry e = {.kind = PD_NUMBER, .num = value};
    return set_entry(p, name, &e);
}

pk_status pk_params_set_floats(pk_params *p, const char *name, const float *values, size_t n)
{
    if (!p) return PK_ERR_INVALID_ARGUMENT;
    if (n && !values)
        return ctx_error(p->d.ctx, PK_ERR_INVALID_ARGUMENT, "pk_params: %s: no values", name ? name : "");
    if (n > PARAMS_MAX_FLOATS)
        return ctx_error(p->d.ctx, PK_ERR_LIMIT, "pk_params: %s: more than %d values", name ? name : "",
                         PARAMS_MAX_FLOATS);
    double v[PARAMS_MAX_FLOATS];
    for (size_t i = 0; i < n; i++) v[i] = values[i];
    const pd_entry e = {.kind = PD_NUMBERS, .nums = v, .n = n, .first_other = n};
    return set_entry(p, name, &e);
}

pk_status pk_params_set_rgb(pk_params *p, const char *name, float r, float g, float b)
{
    const float v[3] = {r, g, b};
    return pk_params_set_floats(p, name, v, 3);
}

pk_status pk_params_set_int(pk_params *p, const char *name, int value)
{
    const pd_entry e = {.kind = PD_NUMBER, .num = value};
    return set_entry(p, name, &e);
}

pk_status pk_params_set_bool(pk_params *p, const char *name, int value)
{
    const pd_entry e = {.kind = PD_BOOL, .b = value != 0};
    return set_entry(p, name, &e);
}

pk_status pk_params_set_string(pk_params *p, const char *name, const char *value)
{
    if (p && !value) return ctx_error(p->d.ctx, PK_ERR_INVALID_ARGUMENT, "pk_params: %s: no string", name ? name : "");
    const pd_entry e = {.kind = PD_STRING, .str = value};
    return set_entry(p, name, &e);
}

/* A dictionary for one creator: "type" (when given) and then the caller's
 * parameters, borrowed, unmarked. what names the thing in messages. */
static pk_status call_dict(pk_context *ctx, pdict *d, const char *what, const char *type, const pk_params *params)
{
    pd_init(d, ctx, NULL, NULL, what, false);
    pk_status st = PK_OK;
    if (type) {
        const pd_entry t = {.name = "type", .kind = PD_STRING, .str = type};
        st = pd_add(d, &t);
    }
    for (size_t i = 0; params && st == PK_OK && i < params->d.n; i++) {
        pd_entry e = params->d.e[i];
        e.used = false;
        st = pd_add(d, &e);
    }
    return st;
}

/* ---- scenes ------------------------------------------------------------------------ */

pk_status pk_scene_create(pk_context *ctx, const char *name, pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_scene *s = NULL;
    pk_status st = scene_create(ctx, name ? name : "scene", &s);
    if (st) return st;
    s->builder = mem_alloc(&s->alloc, sizeof *s->builder);
    if (!s->builder) {
        scene_destroy(s);
        return ctx_nomem(ctx);
    }
    sb_init(s->builder, ctx, s);
    *out = s;
    return PK_OK;
}

/* The checks every building call makes: arguments, a scene of
 * pk_scene_create's, not committed. The builder's context is the caller's. */
static pk_status building(pk_context *ctx, pk_scene *s)
{
    if (!ctx || !s) return PK_ERR_INVALID_ARGUMENT;
    if (!s->builder)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a scene read from a file takes no more geometry "
                                                       "(build scenes with pk_scene_create)", s->name);
    if (s->committed)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: the scene is committed and takes no more geometry, "
                                                       "materials or lights", s->name);
    s->builder->ctx = ctx;
    return PK_OK;
}

static pk_status check_material(pk_context *ctx, const pk_scene *s, const char *what, uint32_t m)
{
    if (m >= s->nmaterials)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: material %u is not in the scene (it has %zu)", s->name,
                         what, m, s->nmaterials);
    return PK_OK;
}

pk_status pk_scene_add_material(pk_context *ctx, pk_scene *s, const char *name, const char *type,
                                const pk_params *params, uint32_t *index)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    if (!name || !name[0]) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: a material needs a name", s->name);
    char what[160];
    snprintf(what, sizeof what, "%s: material \"%.64s\"", s->name, name);
    pdict d;
    material m;
    st = call_dict(ctx, &d, what, type, params);
    if (st == PK_OK) st = create_material(&d, &m);
    /* the creator leaves the media to its caller, and the API has none yet */
    static const char *const sides[2] = {"interior", "exterior"};
    for (int i = 0; i < 2 && st == PK_OK; i++) {
        const pd_entry *e = pd_get(&d, sides[i]);
        if (e) st = pd_fail(&d, e, -1, PK_ERR_UNSUPPORTED, "media are not taken through the API yet");
    }
    pd_free(&d);
    if (st) return st;
    uint32_t idx;
    if ((st = scene_add_material(ctx, s, name, &idx))) return st;
    material *dst = &s->materials[idx];
    char *owned = dst->name;
    *dst = m;
    dst->name = owned;
    if (index) *index = idx;
    return PK_OK;
}

/* *x from a row-major 3x4 or 4x4 matrix (NULL: the identity), checked as
 * the JSON reader checks "transform". */
static pk_status read_transform(pk_context *ctx, const pk_scene *s, const char *what, const float *t, int rows,
                                xform *x)
{
    *x = xform_identity();
    if (!t) return PK_OK;
    if (rows != 3 && rows != 4)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: transform_rows must be 3 or 4", s->name, what);
    for (int i = 0; i < 4 * rows; i++) {
        if (!isfinite(t[i]))
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: the transform is not finite", s->name, what);
        x->m[i] = t[i];
    }
    if (rows == 4 && !xform_is_affine(x))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: the transform's last row must be 0 0 0 1", s->name, what);
    double det = xform_det3(x);
    if (!(det != 0.0) || !isfinite(det))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: the transform is singular", s->name, what);
    return PK_OK;
}

/* The first non-finite number of v[0..n), or n. */
static size_t first_not_finite(const float *v, size_t n)
{
    size_t i = 0;
    while (i < n && isfinite(v[i])) i++;
    return i;
}

pk_status pk_scene_add_mesh(pk_context *ctx, pk_scene *s, const pk_mesh_desc *md)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    if (!md) return PK_ERR_INVALID_ARGUMENT;
    const char *w = "mesh";
    if (!md->positions || !md->npositions)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: no positions", s->name, w);
    if (!md->indices || !md->ntriangles)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: no triangles", s->name, w);
    if (md->npositions > API_MAX_PRIMS || md->ntriangles > API_MAX_PRIMS)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: %s: more than %zu vertices or triangles", s->name, w,
                         (size_t)API_MAX_PRIMS);
    if ((st = check_material(ctx, s, w, md->material))) return st;
    size_t k = first_not_finite(md->positions, 3 * md->npositions);
    if (k < 3 * md->npositions)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: position %zu is not finite", s->name, w, k / 3);
    if (md->normals && (k = first_not_finite(md->normals, 3 * md->npositions)) < 3 * md->npositions)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: normal %zu is not finite", s->name, w, k / 3);
    if (md->uvs && (k = first_not_finite(md->uvs, 2 * md->npositions)) < 2 * md->npositions)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: uv %zu is not finite", s->name, w, k / 2);
    for (size_t i = 0; i < 3 * md->ntriangles; i++)
        if (md->indices[i] >= md->npositions)
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: %s: triangle %zu: index %u is out of range (%zu positions)",
                             s->name, w, i / 3, md->indices[i], md->npositions);
    xform x;
    if ((st = read_transform(ctx, s, w, md->transform, md->transform_rows, &x))) return st;
    /* float xyz triples are vec3s (scene.h's layout) */
    const sb_mesh m = {.pos = (const vec3 *)md->positions,
                       .nrm = (const vec3 *)md->normals,
                       .uv = md->uvs,
                       .npos = md->npositions,
                       .tris = md->indices,
                       .ntris = md->ntriangles};
    scene_builder *b = s->builder;
    const size_t pos0 = s->npositions, nrm0 = s->nnormals, uv0 = s->nuvs, tri0 = s->ntris;
    sb_set_transform(b, &x);
    sb_set_material(b, md->material);
    st = sb_add_mesh(b, &m);
    const xform id = xform_identity();
    sb_set_transform(b, &id);
    if (st) { /* a failed call adds nothing */
        s->npositions = pos0, s->nnormals = nrm0, s->nuvs = uv0, s->ntris = tri0;
    }
    return st;
}

pk_status pk_scene_add_sphere(pk_context *ctx, pk_scene *s, const float center[3], float radius, uint32_t mat)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    if (!center) return PK_ERR_INVALID_ARGUMENT;
    if (first_not_finite(center, 3) < 3)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: sphere: center: numbers must be finite", s->name);
    if (!(radius > 0.0f) || !isfinite(radius))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: sphere: radius: must be a positive number", s->name);
    if ((st = check_material(ctx, s, "sphere", mat))) return st;
    const sphere sp = {.center = v3(center[0], center[1], center[2]), .radius = radius, .material = mat};
    return scene_add_sphere(ctx, s, &sp);
}

pk_status pk_scene_add_light(pk_context *ctx, pk_scene *s, const char *type, const pk_params *params)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    char what[160];
    snprintf(what, sizeof what, "%s: light %zu", s->name, s->nlights);
    pdict d;
    st = call_dict(ctx, &d, what, type, params);
    if (st == PK_OK) st = create_light(&d, s);
    pd_free(&d);
    return st;
}

pk_status pk_scene_begin_object(pk_context *ctx, pk_scene *s)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    if (!sb_begin_object(s->builder))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: an object is being defined already (objects do not nest)",
                         s->name);
    return PK_OK;
}

pk_status pk_scene_end_object(pk_context *ctx, pk_scene *s, uint32_t *object)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    if (!object) return PK_ERR_INVALID_ARGUMENT;
    if (s->builder->in_object && s->ntris == s->builder->obj_tri) {
        s->builder->in_object = false;
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: the object has no triangles", s->name);
    }
    return sb_end_object(s->builder, object);
}

pk_status pk_scene_add_instance(pk_context *ctx, pk_scene *s, uint32_t object, const float *transform, int rows)
{
    pk_status st = building(ctx, s);
    if (st) return st;
    if (object >= s->nmeshes)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: instance: object %u is not in the scene (it has %zu)",
                         s->name, object, s->nmeshes);
    xform x;
    if ((st = read_transform(ctx, s, "instance", transform, rows, &x))) return st;
    scene_builder *b = s->builder;
    sb_set_transform(b, &x);
    st = sb_add_instance(b, object);
    const xform id = xform_identity();
    sb_set_transform(b, &id);
    return st;
}

pk_status pk_scene_commit(pk_context *ctx, pk_scene *s)
{
    if (!ctx || !s) return PK_ERR_INVALID_ARGUMENT;
    if (s->committed) return PK_OK;
    if (s->builder && s->builder->in_object)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: an object is still being defined (pk_scene_end_object)",
                         s->name);
    return scene_commit(ctx, s);
}

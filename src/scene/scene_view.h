/*
 * scene_view.h - what rendering kernels read of a committed scene: its
 * arrays and their counts, flat (no name, allocator, index or reader
 * state), so that the same struct describes the scene on the CPU and, with
 * its arrays swapped for device copies, on the GPU. The frame builds one
 * per renderer; the authored pk_scene stays the readers' and the host
 * code's (light set, environment, warnings).
 */
#ifndef PK_SCENE_VIEW_H
#define PK_SCENE_VIEW_H

#include "scene.h"

typedef struct scene_view {
    const vec3 *positions, *normals;
    const uv2 *uvs;
    const triangle *tris;     /* ntris, in hit numbering; spheres follow as prims ntris.. */
    const rgba *colors;       /* vertex colours by position, NULL: none (pk_scene's) */
    const vtangent *tangents; /* vertex tangents by position, NULL: none */
    const uv2 *uvs1;          /* the second texture-coordinate set by position, NULL: none */
    const sphere *spheres;
    const material *materials;
    const point_light *lights;
    const texture *textures;
    const tex_node *tex_nodes;  /* procedural texture expressions' nodes */
    size_t npositions, nnormals, nuvs, ntris, nspheres, nmaterials, nlights, ntextures;
    bool has_cutout;          /* a material has map_d */
    bool has_textured;        /* a material has a map other than map_d */
    bool has_emission_maps;   /* an emitting material has map_ke (lights.h looks it up where it samples) */
    /* Kept instances (scene_kept): hit numbers from ntris + nspheres on
     * are their triangles, in object space in the mesh arrays. The GPU
     * renders scenes without them only (nkept 0). */
    const scene_kept *kept;
    size_t nkept;
    const scene_mesh *meshes;
    const vec3 *mesh_positions, *mesh_normals;
    const uv2 *mesh_uvs;
    const triangle *mesh_tris;
    const rgba *mesh_colors;  /* by mesh position, NULL: none */
    const vtangent *mesh_tangents; /* by mesh position, object space, NULL: none */
    const uv2 *mesh_uvs1;     /* by mesh position, NULL: none */
    /* Participating media (medium.h): the volumetric path tracer's (the GPU
     * renders scenes without them). */
    const medium *media;
    size_t nmedia;
    int32_t camera_medium;
    bool has_interfaces;      /* a material is MAT_INTERFACE (rays pass through some surfaces) */
} scene_view;

/* The view of committed scene s (its arrays, not copies). */
static inline scene_view scene_view_of(const pk_scene *s)
{
    scene_view v;
    v.positions = s->positions, v.normals = s->normals, v.uvs = s->uvs, v.tris = s->tris;
    v.spheres = s->spheres, v.materials = s->materials, v.lights = s->lights, v.textures = s->textures;
    v.tex_nodes = s->tex_nodes;
    v.npositions = s->npositions, v.nnormals = s->nnormals, v.nuvs = s->nuvs, v.ntris = s->ntris;
    v.nspheres = s->nspheres, v.nmaterials = s->nmaterials, v.nlights = s->nlights, v.ntextures = s->ntextures;
    v.has_cutout = s->has_cutout, v.has_textured = s->has_textured;
    v.has_emission_maps = s->has_emission_maps;
    v.kept = s->kept, v.nkept = s->nkept, v.meshes = s->meshes;
    v.mesh_positions = s->mesh_positions, v.mesh_normals = s->mesh_normals, v.mesh_uvs = s->mesh_uvs;
    v.mesh_tris = s->mesh_tris;
    v.colors = s->colors, v.mesh_colors = s->mesh_colors;
    v.tangents = s->tangents, v.mesh_tangents = s->mesh_tangents;
    v.uvs1 = s->uvs1, v.mesh_uvs1 = s->mesh_uvs1;
    v.media = s->media, v.nmedia = s->nmedia, v.camera_medium = s->camera_medium;
    v.has_interfaces = s->has_interfaces;
    return v;
}

/* A triangle as shading sees it, in world space: hit number prim (< ntris,
 * or a kept instance's from ntris + nspheres on). */
typedef struct view_tri {
    vec3 p[3];          /* vertices */
    vec3 n[3];          /* vertex normals when has_n (possibly zero: then unusable) */
    uv2 t[3];           /* texture coordinates when has_t */
    uv2 t1[3];          /* the second set's when has_t1 */
    bool has_n, has_t, has_t1;
    uint32_t material;
} view_tri;

/* The kept instance holding hit number prim (>= ntris + nspheres). */
static inline PK_HD size_t view_kept_of(const scene_view *s, uint32_t prim)
{
    size_t lo = 0, hi = s->nkept; /* the last one with prim0 <= prim */
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        if (s->kept[mid].prim0 <= prim) lo = mid;
        else hi = mid;
    }
    return lo;
}

/* The world triangle of hit number prim. A kept instance's is placed as
 * scene_commit would have flattened it (positions by to_world, normals by
 * its normal matrix, renormalised), so that a hit on it gives the numbers
 * the flattened triangle would. */
static inline PK_HD void view_tri_get(const scene_view *s, uint32_t prim, view_tri *out)
{
    if (prim < s->ntris) {
        const triangle *t = &s->tris[prim];
        out->has_n = t->n[0] >= 0 && t->n[1] >= 0 && t->n[2] >= 0;
        out->has_t = t->t[0] >= 0 && t->t[1] >= 0 && t->t[2] >= 0;
        for (int j = 0; j < 3; j++) {
            out->p[j] = s->positions[t->v[j]];
            if (out->has_n) out->n[j] = s->normals[t->n[j]];
            if (out->has_t) out->t[j] = s->uvs[t->t[j]];
        }
        out->has_t1 = s->uvs1 != NULL;
        for (int j = 0; out->has_t1 && j < 3; j++) out->t1[j] = s->uvs1[t->v[j]];
        out->material = t->material;
        return;
    }
    const scene_kept *k = &s->kept[view_kept_of(s, prim)];
    const scene_mesh *m = &s->meshes[k->mesh];
    const triangle *t = &s->mesh_tris[m->first_tri + (prim - k->prim0)];
    out->has_n = t->n[0] >= 0 && t->n[1] >= 0 && t->n[2] >= 0;
    out->has_t = t->t[0] >= 0 && t->t[1] >= 0 && t->t[2] >= 0;
    for (int j = 0; j < 3; j++) {
        out->p[j] = xform_point(&k->to_world, s->mesh_positions[m->first_pos + t->v[j]]);
        if (out->has_n) {
            vec3 n = v3_norm_scaled(xform_apply3(k->nrm, s->mesh_normals[m->first_nrm + (size_t)t->n[j]]));
            out->n[j] = v3_finite(n) ? n : v3s(0.0f);
        }
        if (out->has_t) out->t[j] = s->mesh_uvs[m->first_uv + (size_t)t->t[j]];
    }
    out->has_t1 = s->mesh_uvs1 != NULL;
    for (int j = 0; out->has_t1 && j < 3; j++) out->t1[j] = s->mesh_uvs1[m->first_pos + t->v[j]];
    out->material = k->material != SCENE_MESH_MATERIAL ? k->material : t->material;
}

/* The material of hit number prim (a triangle of either kind or a sphere). */
static inline PK_HD uint32_t view_prim_material(const scene_view *s, uint32_t prim)
{
    if (prim < s->ntris) return s->tris[prim].material;
    if (prim - s->ntris < s->nspheres) return s->spheres[prim - s->ntris].material;
    const scene_kept *k = &s->kept[view_kept_of(s, prim)];
    if (k->material != SCENE_MESH_MATERIAL) return k->material;
    const scene_mesh *m = &s->meshes[k->mesh];
    return s->mesh_tris[m->first_tri + (prim - k->prim0)].material;
}

/* The vertex colour at a hit on triangle prim (barycentric u, v of its
 * second and third vertices): white where the scene has none. */
static inline PK_HD rgba view_tri_color(const scene_view *s, uint32_t prim, float u, float v)
{
    rgba c[3], out = {1.0f, 1.0f, 1.0f, 1.0f};
    if (prim < s->ntris) {
        if (!s->colors) return out;
        for (int j = 0; j < 3; j++) c[j] = s->colors[s->tris[prim].v[j]];
    } else {
        if (!s->mesh_colors || prim - s->ntris < s->nspheres) return out;
        const scene_kept *k = &s->kept[view_kept_of(s, prim)];
        const scene_mesh *m = &s->meshes[k->mesh];
        const triangle *t = &s->mesh_tris[m->first_tri + (prim - k->prim0)];
        for (int j = 0; j < 3; j++) c[j] = s->mesh_colors[m->first_pos + t->v[j]];
    }
    const float w = 1.0f - u - v;
    out.r = c[0].r * w + c[1].r * u + c[2].r * v, out.g = c[0].g * w + c[1].g * u + c[2].g * v;
    out.b = c[0].b * w + c[1].b * u + c[2].b * v, out.a = c[0].a * w + c[1].a * u + c[2].a * v;
    return out;
}

/* The vertex tangent at a hit on triangle prim (barycentric u, v), world
 * space, not normalised, and its handedness *w: false where any of its
 * vertices has none. */
static inline PK_HD bool view_tri_tangent(const scene_view *s, uint32_t prim, float u, float v, vec3 *t, float *w)
{
    vtangent c[3];
    const scene_kept *k = NULL;
    if (prim < s->ntris) {
        if (!s->tangents) return false;
        for (int j = 0; j < 3; j++) c[j] = s->tangents[s->tris[prim].v[j]];
    } else {
        if (!s->mesh_tangents || prim - s->ntris < s->nspheres) return false;
        k = &s->kept[view_kept_of(s, prim)];
        const scene_mesh *m = &s->meshes[k->mesh];
        const triangle *tr = &s->mesh_tris[m->first_tri + (prim - k->prim0)];
        for (int j = 0; j < 3; j++) c[j] = s->mesh_tangents[m->first_pos + tr->v[j]];
    }
    if (c[0].w == 0.0f || c[1].w == 0.0f || c[2].w == 0.0f) return false;
    const float b = 1.0f - u - v;
    vec3 x = v3_add(v3_add(v3_scale(c[0].t, b), v3_scale(c[1].t, u)), v3_scale(c[2].t, v));
    float hand = c[0].w;
    if (k) { /* as flattening places it */
        x = xform_vector(&k->to_world, x);
        const float *m = k->to_world.m;
        const float det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                          m[2] * (m[4] * m[9] - m[5] * m[8]);
        if (det < 0.0f) hand = -hand;
    }
    *t = x;
    *w = hand;
    return true;
}

/* Geometry of triangle k. */
static inline PK_HD void view_tri_verts(const scene_view *s, size_t k, vec3 *a, vec3 *b, vec3 *c)
{
    const triangle *t = &s->tris[k];
    *a = s->positions[t->v[0]];
    *b = s->positions[t->v[1]];
    *c = s->positions[t->v[2]];
}

#endif

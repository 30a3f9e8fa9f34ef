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
    const sphere *spheres;
    const material *materials;
    const point_light *lights;
    const texture *textures;
    size_t npositions, nnormals, nuvs, ntris, nspheres, nmaterials, nlights, ntextures;
    bool has_cutout;          /* a material has map_d */
    bool has_textured;        /* a material has a map other than map_d */
} scene_view;

/* The view of committed scene s (its arrays, not copies). */
static inline scene_view scene_view_of(const pk_scene *s)
{
    scene_view v;
    v.positions = s->positions, v.normals = s->normals, v.uvs = s->uvs, v.tris = s->tris;
    v.spheres = s->spheres, v.materials = s->materials, v.lights = s->lights, v.textures = s->textures;
    v.npositions = s->npositions, v.nnormals = s->nnormals, v.nuvs = s->nuvs, v.ntris = s->ntris;
    v.nspheres = s->nspheres, v.nmaterials = s->nmaterials, v.nlights = s->nlights, v.ntextures = s->ntextures;
    v.has_cutout = s->has_cutout, v.has_textured = s->has_textured;
    return v;
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

/*
 * scene_build.h - the graphics state a scene reader keeps while it walks a
 * file, and the one way it adds meshes to the scene: a transform stack (the
 * current transform is the top), the current material, and mesh adding
 * (object-space vertices and triangles, placed by the current transform,
 * with the current material). Readers of formats with a graphics state
 * (pbrt-v4's AttributeBegin/End, glTF's node hierarchy) push and pop; the
 * Mitsuba XML reader sets each shape's to_world. Objects defined once and
 * placed many times (Mitsuba's shapegroup and instance, pbrt's ObjectBegin
 * and ObjectInstance, glTF's meshes used by several nodes) are meshes and
 * instances of the scene: shapes added between sb_begin_object and
 * sb_end_object become one mesh, which sb_add_instance places. Messages
 * follow the readers' rule: latched in the context, never printed.
 */
#ifndef PK_SCENE_BUILD_H
#define PK_SCENE_BUILD_H

#include "../math/xform.h"
#include "../paprsek_internal.h"
#include "../scene/scene.h"

#define SB_MAX_DEPTH 64 /* nested pushes */

/* Invariants: 0 <= depth < SB_MAX_DEPTH; stack[depth] is the current
 * transform (object to world); material < s->nmaterials; while in_object,
 * obj_* are the scene's counts when the object began. */
typedef struct scene_builder {
    pk_context *ctx;
    pk_scene *s;
    xform stack[SB_MAX_DEPTH];
    int depth;
    uint32_t material;
    bool in_object;
    size_t obj_pos, obj_nrm, obj_uv, obj_tri;
} scene_builder;

/* The identity transform and material 0 (the default) on a stack of one. */
PK_HIDDEN void sb_init(scene_builder *b, pk_context *ctx, pk_scene *s);

/* Saves the current transform (a copy stays current); false when the stack
 * is full (SB_MAX_DEPTH), which the reader reports where it is. */
PK_HIDDEN bool sb_push(scene_builder *b);
/* Restores the transform saved by the matching push; false when none is. */
PK_HIDDEN bool sb_pop(scene_builder *b);

static inline const xform *sb_transform(const scene_builder *b) { return &b->stack[b->depth]; }
/* Replaces the current transform. */
static inline void sb_set_transform(scene_builder *b, const xform *x) { b->stack[b->depth] = *x; }
/* current = current x: x applies first, in the current space (pbrt's
 * ConcatTransform, glTF's child nodes). */
static inline void sb_concat(scene_builder *b, const xform *x)
{
    b->stack[b->depth] = xform_mul(&b->stack[b->depth], x);
}
static inline void sb_set_material(scene_builder *b, uint32_t mat) { b->material = mat; }

/* A mesh in object space: npos vertices with optional normals (nrm) and
 * texture coordinates (uv, 2 floats a vertex), ntris triangles of three
 * vertex indices each (< npos, checked by the caller). */
typedef struct sb_mesh {
    const vec3 *pos;
    const vec3 *nrm;   /* NULL: none */
    const float *uv;   /* NULL: none */
    size_t npos;
    const uint32_t *tris;
    size_t ntris;
    bool flip;         /* reverse the winding (b and c swapped) */
} sb_mesh;

/* Appends the mesh to the scene's triangles, positions through the current
 * transform, normals through its inverse transpose (xform_normal_cofactors,
 * then normalised; a normal that does not survive is zero), non-finite
 * texture coordinates as (0, 0); every triangle gets the current material.
 * Errors: "scene: a transformed vertex is not finite" (PK_ERR_PARSE), the
 * scene's limits, out of memory. */
PK_HIDDEN pk_status sb_add_mesh(scene_builder *b, const sb_mesh *m);

/* Begins an object: what is added until sb_end_object (meshes, and OBJ
 * files read into the scene) is its geometry, in the space the current
 * transforms give it, which becomes the object's own space. False when an
 * object is already being defined (objects do not nest). */
PK_HIDDEN bool sb_begin_object(scene_builder *b);
/* Ends the object: its geometry leaves the world and becomes mesh *mesh
 * (scene_capture_mesh). */
PK_HIDDEN pk_status sb_end_object(scene_builder *b, uint32_t *mesh);
/* Places mesh by the current transform; its triangles keep their own
 * materials. Errors: an instance while an object is being defined, a
 * transform that is singular (PK_ERR_INVALID_ARGUMENT). */
PK_HIDDEN pk_status sb_add_instance(scene_builder *b, uint32_t mesh);

#endif

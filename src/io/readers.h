/*
 * readers.h - the scene file readers, one door each: OBJ (obj.c) and its MTL
 * libraries (mtl.c), the JSON scene (scene_json.c), Mitsuba XML
 * (scene_xml.c) and the PLY meshes it names (ply.c), glTF 2.0 (scene_gltf.c,
 * gltf_data.c, gltf_material.c), pbrt-v4 (scene_pbrt.c, pbrt_tok.c), and
 * the table of them (readers.c). Every reader parses a (data, size) buffer,
 * reads any further file through file_read_all, and reports a bad input as
 * "file:line: what is wrong" (glTF: "file: /json/pointer: what is wrong")
 * latched in the context; none prints, exits or commits the scene.
 */
#ifndef PK_READERS_H
#define PK_READERS_H

#include "../math/vec3.h"
#include "../math/xform.h"
#include "../paprsek_internal.h"
#include "../scene/scene.h"

/* Parses OBJ text into s, appending its triangles after those already there.
 * name: for messages; base_dir: where mtllib files are read from (NULL: not read).
 * xf: optional affine transform applied to positions (and its inverse
 * transpose to normals); NULL = identity. Does not commit. */
PK_HIDDEN pk_status obj_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                              const char *name, const char *base_dir, const xform *xf);
/* The same, with material mat (< s->nmaterials) on every face: usemtl names are
 * not looked up (nor warned about) and no material library is read. For
 * formats whose shape gives the mesh its material (Mitsuba's obj shape
 * with a bsdf). */
PK_HIDDEN pk_status obj_parse_with_material(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                                            const char *name, const xform *xf, uint32_t mat);
/* Parses MTL text, adding its materials to s. Texture maps are parsed but
 * not loaded. */
PK_HIDDEN pk_status mtl_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                              const char *name);
/* The same, loading the texture maps from files relative to tex_dir (NULL:
 * not loaded). A texture that cannot be used is a warning. */
PK_HIDDEN pk_status mtl_parse_dir(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                                  const char *name, const char *tex_dir);
/* Parses a JSON scene into s (meshes are loaded relative to base_dir). Does not commit. */
PK_HIDDEN pk_status scene_json_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                                     const char *name, const char *base_dir);
/* Parses a Mitsuba XML scene into s (files are read relative to base_dir;
 * docs/scene-format.md, "Mitsuba XML"). params (nparams strings
 * "name=value", may be NULL) set $name before the file's <default>s, which
 * then do not change them. Does not commit. */
PK_HIDDEN pk_status scene_xml_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                                    const char *name, const char *base_dir, const char *const *params,
                                    size_t nparams);

/* Parses a glTF 2.0 asset into s: JSON (.gltf) or binary (.glb, told by
 * its magic bytes); buffers and images are read relative to base_dir
 * (docs/scene-format.md, "glTF 2.0"). Messages name the JSON pointer of what
 * is wrong ("model.gltf: /accessors/3: ..."). Does not commit. */
PK_HIDDEN pk_status scene_gltf_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                                     const char *name, const char *base_dir);
/* The same with parameters "NAME=VALUE": camera=N renders /cameras/N (the
 * first camera in node order by default); others are warned about. */
PK_HIDDEN pk_status scene_gltf_parse_params(pk_context *ctx, pk_scene *s, const char *data, size_t size,
                                            const char *name, const char *base_dir, const char *const *params,
                                            size_t nparams);

/* Parses a pbrt-v4 scene into s (Include/Import and the files its shapes
 * and textures name are read relative to the including file; base_dir is
 * the folder of the first; docs/scene-format.md, "pbrt-v4"). Messages say
 * "file:line: what". Does not commit. */
PK_HIDDEN pk_status scene_pbrt_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                                     const char *base_dir);

/* ---- the formats (readers.c) ---- */

#define SCENE_READER_EXTS 2
/* One scene format: its name, the extensions that choose it (lower case,
 * with the dot), the folder relative files come from when a buffer is
 * given without one (NULL: none are read), and its parser (params:
 * "NAME=VALUE" strings, which formats without parameters ignore). */
typedef struct scene_reader {
    const char *name;
    const char *exts[SCENE_READER_EXTS];
    const char *default_dir;
    pk_status (*parse)(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                       const char *base_dir, const char *const *params, size_t nparams);
} scene_reader;
/* The format a file's extension chooses (ASCII case ignored); NULL for none. */
PK_HIDDEN const scene_reader *scene_reader_for_path(const char *path);
/* The format of that name or extension without the dot ("obj", "json",
 * "xml", "pbrt", "gltf", "glb"); NULL for none. */
PK_HIDDEN const scene_reader *scene_reader_named(const char *format);

/* ---- PLY meshes (Stanford polygon files): ascii, binary little and big
 * endian; vertex positions, optional normals and texture coordinates, and
 * faces as lists of vertex indices (fan-triangulated). Other elements and
 * properties are read past and ignored. Bounded by the size of the data:
 * no count is believed beyond what the bytes can hold. ---- */

typedef struct ply_mesh {
    vec3 *positions;      /* nvertices */
    vec3 *normals;        /* nvertices, or NULL when the file has none */
    float *uvs;           /* 2 * nvertices, or NULL when the file has none */
    /* 4 * nvertices each, or NULL: Paprsek's converter's vertex colours
     * (color_r, color_g, color_b, color_a) and tangents (tangent_x, _y, _z,
     * _w: scene.h's vtangent), all four properties or none */
    float *colors, *tangents;
    float *uvs1;          /* 2 * nvertices, or NULL: the second texture-coordinate set (u1, v1) */
    size_t nvertices;
    uint32_t *indices;    /* 3 * ntriangles, each < nvertices */
    size_t ntriangles;
    /* ntriangles: the face property "material" (an integer, as Paprsek's
     * converter writes it; UINT32_MAX where it is not a whole number >= 0
     * or a face has no such property), or NULL when no face has one */
    uint32_t *face_material;
} ply_mesh;

/* Parses a PLY file held in (data, size) into *out (zeroed first; free it
 * with ply_mesh_free, also after a failure). name is used in messages
 * ("name: what" or "name:line: what" in the header). */
PK_HIDDEN pk_status ply_parse(pk_context *ctx, const char *data, size_t size, const char *name, ply_mesh *out);
PK_HIDDEN void ply_mesh_free(pk_context *ctx, ply_mesh *m);
/* The PLY file rel that a scene file in folder dir names, read and parsed
 * into *out (ply_mesh_free it, also on failure); errors as
 * io_read_relative's (io_util.h): in scratch, to be latched again where the
 * name stood. */
PK_HIDDEN pk_status ply_read_relative(pk_context *ctx, pk_context *scratch, const char *dir, const char *rel,
                                      ply_mesh *out);

#endif

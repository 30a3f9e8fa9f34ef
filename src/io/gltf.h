/*
 * gltf.h - what the parts of the glTF 2.0 reader share (scene_gltf.c: the
 * document, nodes, meshes, cameras and lights; gltf_data.c: GLB chunks,
 * buffers, data: URIs and accessors; gltf_material.c: materials, images and
 * textures). Messages read "file: /json/pointer: what is wrong"
 * (docs/scene-format.md, "glTF 2.0").
 */
#ifndef PK_GLTF_H
#define PK_GLTF_H

#include "../paprsek_internal.h"
#include "../scene/scene.h"
#include "scene_build.h"

#include <cjson/cJSON.h>

#define GLTF_MAX_NODE_DEPTH 256   /* nested nodes walked */
#define GLTF_MAX_URI 4096         /* bytes of a decoded file URI */

/* A buffer's bytes: owned (a file or a data: URI) or borrowed (GLB BIN). */
typedef struct gltf_buffer {
    uint8_t *data;
    size_t size;    /* the buffer's byteLength (the data may hold a little more) */
    bool owned, loaded;
} gltf_buffer;

/* An accessor checked against its buffer view and buffer: element i,
 * component c lies at base + i * stride + c * csize (matrix columns
 * padded as the specification says are not read: no matrix accessor is). */
typedef struct gltf_accessor {
    const uint8_t *base;   /* NULL: no buffer view (zeros, then the sparse values) */
    size_t count, stride;
    int ctype;             /* 5120 .. 5126 */
    int ncomp;             /* 1..4 (SCALAR .. VEC4), 4/9/16 for matrices */
    bool normalized;
    bool matrix;           /* MAT2..MAT4 (never read as vertices) */
    /* sparse substitutes */
    size_t nsparse;
    const uint8_t *sp_idx, *sp_val;
    int sp_itype;
} gltf_accessor;

/* uv' = (m0 u + m1 v + m2, m3 u + m4 v + m5) in glTF's uv space (v down). */
typedef struct gltf_uv_xform {
    bool bake;
    float m[6];
} gltf_uv_xform;

typedef struct gltf {
    pk_context *ctx;
    pk_scene *s;
    const char *name;
    const char *base_dir;
    cJSON *root;
    const uint8_t *bin;    /* GLB BIN chunk (NULL: none) */
    size_t bin_size;
    gltf_buffer *buffers;
    size_t nbuffers;
    /* extensions declared (extensionsUsed) */
    bool ext_quantization, ext_texture_transform;
    /* glTF material i -> scene material (0 = not made yet, else index + 1) */
    uint32_t *materials;
    uint8_t *mat_uvset;    /* the TEXCOORD sets a material's textures read (bit k: TEXCOORD_k) */
    gltf_uv_xform *mat_uv; /* a KHR_texture_transform baked into the uvs */
    size_t nmaterials;
    /* image i decoded as colour (0) / data (1): texture index + 1, 0 = not yet */
    int32_t *images[2];
    size_t nimages;
    scene_builder b;
    /* what has been warned once */
    unsigned warned;
    int camera_pick;       /* /cameras/N asked for, -1: the first placed */
    const char *variant_name; /* KHR_materials_variants: the variant asked for (NULL: none) */
    int64_t variant;       /* its index in the asset's variants, -1: none */
    bool camera_done;
    /* the node being placed: its morph weights (NULL: the mesh's own) and,
     * for a skinned node, its joint matrices (joint's world transform times
     * its inverse bind matrix, nskin of them; NULL: not skinned) */
    const float *node_weights;
    size_t nnode_weights;
    xform *skin;
    size_t nskin;
    int64_t skin_index;
    int64_t *parent;       /* per node: its parent, -1 for a root */
    uint32_t vc_default;   /* the default material's copy for vertex colours (0: not made) */
    /* compressed data decoded (gltf_data.c, gltf_draco.c): buffer view i's
     * EXT_meshopt_compression bytes (NULL: not decoded), and accessor i as a
     * KHR_draco_mesh_compression primitive decoded it (acc_data[i] NULL: the
     * accessor as the document describes it) */
    uint8_t **view_dec;
    size_t nview_dec;
    gltf_accessor *acc_dec;
    uint8_t **acc_data;
    size_t nacc_dec;
} gltf;

/* warned bits */
enum {
    GW_POINTS = 1u << 0, GW_COLOR = 1u << 1, GW_UV1 = 1u << 2, GW_TANGENT = 1u << 3, GW_MR_TEX = 1u << 4,
    GW_BLEND = 1u << 6, GW_ROTATION = 1u << 7, GW_CLEARCOAT = 1u << 8,
    GW_EXT = 1u << 9, GW_MIRROR = 1u << 10, GW_NORMAL_SCALE = 1u << 11, GW_SKIN = 1u << 12,
    GW_ANIM = 1u << 14, GW_RANGE = 1u << 15, GW_UV_SETS = 1u << 16, GW_SINGULAR = 1u << 17, GW_MORPH = 1u << 18,
    GW_INSTANCE_MIRROR = 1u << 19, GW_DISPERSION = 1u << 20,
    GW_MESHOPT = 1u << 27, GW_DRACO = 1u << 28, GW_WEBP = 1u << 29, GW_BASISU = 1u << 30
};

/* "name: " + fmt, latched; returns st. */
PK_HIDDEN pk_status gltf_fail(gltf *g, pk_status st, const char *fmt, ...) PK_PRINTF(3, 4);
/* "name: " + fmt as a warning. */
PK_HIDDEN void gltf_warn(gltf *g, const char *fmt, ...) PK_PRINTF(2, 3);
/* The same, once per bit. */
PK_HIDDEN void gltf_warn_once(gltf *g, unsigned bit, const char *fmt, ...) PK_PRINTF(3, 4);

/* ---- JSON values (path: the JSON pointer of obj, for messages) ---- */

/* The array member key of the root (NULL when absent or not an array). */
PK_HIDDEN const cJSON *gltf_array(const gltf *g, const char *key);
PK_HIDDEN size_t gltf_count(const gltf *g, const char *key);
/* An index member: absent -> *out = -1 (an error when required); present:
 * an integer in [0, limit). */
PK_HIDDEN pk_status gltf_index(gltf *g, const cJSON *obj, const char *path, const char *key, size_t limit,
                               bool required, int64_t *out);
/* An integer member in [lo, hi], def when absent. */
PK_HIDDEN pk_status gltf_int(gltf *g, const cJSON *obj, const char *path, const char *key, int64_t lo, int64_t hi,
                             int64_t def, int64_t *out);
/* A finite number in [lo, hi], def when absent. */
PK_HIDDEN pk_status gltf_num(gltf *g, const cJSON *obj, const char *path, const char *key, double lo, double hi,
                             double def, float *out);
/* An array of exactly n finite numbers (out untouched when absent: *found false). */
PK_HIDDEN pk_status gltf_nums(gltf *g, const cJSON *obj, const char *path, const char *key, int n, float *out,
                              bool *found);
/* A string member (NULL when absent; an error when present and not a string). */
PK_HIDDEN pk_status gltf_string(gltf *g, const cJSON *obj, const char *path, const char *key, const char **out);
/* obj.extensions.name (NULL when absent). */
PK_HIDDEN const cJSON *gltf_ext(const cJSON *obj, const char *name);

/* ---- data (gltf_data.c) ---- */

/* Splits a GLB file into its JSON and BIN chunks (refusing lying lengths). */
PK_HIDDEN pk_status gltf_glb_split(gltf *g, const uint8_t *data, size_t size, const char **json, size_t *json_size);
/* Decodes a data: URI (";base64," required) into an owned block. path: for messages. */
PK_HIDDEN pk_status gltf_data_uri(gltf *g, const char *uri, const char *path, uint8_t **out, size_t *size);
/* Strict base64 (RFC 4648 alphabet, '=' padding only at the end, length a
 * multiple of 4): false on any other input. out holds at least
 * 3 * (n / 4) bytes. */
PK_HIDDEN bool gltf_base64(const char *in, size_t n, uint8_t *out, size_t *size);
/* Reads the file a relative URI names (percent-decoded, relative to the
 * glTF file) into an owned block. */
PK_HIDDEN pk_status gltf_read_uri_file(gltf *g, const char *uri, const char *path, char **out, size_t *size);
/* The bytes of buffer view i ([*data, *data + *size)), checked. */
PK_HIDDEN pk_status gltf_view(gltf *g, int64_t i, const uint8_t **data, size_t *size, size_t *stride);
/* Checks accessor i and describes it. */
PK_HIDDEN pk_status gltf_accessor_get(gltf *g, int64_t i, gltf_accessor *a);
/* Reads accessor i as floats, ncomp a vertex (normalized integers as the
 * specification maps them; others as their values). *out allocated. */
PK_HIDDEN pk_status gltf_read_floats(gltf *g, int64_t i, const gltf_accessor *a, float **out);
/* Reads a MAT4 accessor of floats as affine transforms (column-major in
 * the file; a last row other than 0 0 0 1 is refused). *out allocated. */
PK_HIDDEN pk_status gltf_read_mat4(gltf *g, int64_t i, const gltf_accessor *a, xform **out);
/* Reads a SCALAR accessor of unsigned integers. *out allocated. */
PK_HIDDEN pk_status gltf_read_uints(gltf *g, int64_t i, const gltf_accessor *a, uint32_t **out);
/* Frees the buffers and what was decoded from them (view_dec, acc_dec). */
PK_HIDDEN void gltf_buffers_free(gltf *g);

/* ---- KHR_draco_mesh_compression (gltf_draco.c) ---- */

/* Primitive p (path: its JSON pointer) has the extension: decodes its
 * Draco stream and substitutes the decoded data for the accessors its
 * attributes and indices name (gltf_accessor_get then describes those),
 * so that the primitive is read as an uncompressed one. Without the Draco
 * module, a primitive whose accessors have buffer views (the uncompressed
 * fallback) is read from those with one warning; one without is an error. */
PK_HIDDEN pk_status gltf_draco_primitive(gltf *g, const cJSON *p, const char *path);
/* Whether this build has the Draco module and it loads; when not, why (n
 * bytes) says why not. */
PK_HIDDEN bool gltf_have_draco(gltf *g, char *why, size_t n);

/* ---- materials (gltf_material.c) ---- */

/* The scene material for glTF material i (-1: the default), made on first
 * use; *uvsets: the TEXCOORD sets its textures read (bit k: TEXCOORD_k, k
 * < 2); g->mat_uv[i] says the uv transform to bake into the primitive's
 * uvs (both sets). */
PK_HIDDEN pk_status gltf_material(gltf *g, int64_t i, uint32_t *mat, int *uvsets);
PK_HIDDEN void gltf_materials_free(gltf *g);

#endif

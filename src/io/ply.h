/*
 * ply.h - PLY meshes (Stanford polygon files): ascii, binary little and big
 * endian; vertex positions, optional normals and texture coordinates, and
 * faces as lists of vertex indices (fan-triangulated). Other elements and
 * properties are read past and ignored. Bounded by the size of the data:
 * no count is believed beyond what the bytes can hold.
 */
#ifndef PK_PLY_H
#define PK_PLY_H

#include "../math/vec3.h"
#include "../paprsek_internal.h"

typedef struct ply_mesh {
    vec3 *positions;      /* nvertices */
    vec3 *normals;        /* nvertices, or NULL when the file has none */
    float *uvs;           /* 2 * nvertices, or NULL when the file has none */
    size_t nvertices;
    uint32_t *indices;    /* 3 * ntriangles, each < nvertices */
    size_t ntriangles;
} ply_mesh;

/* Parses a PLY file held in (data, size) into *out (zeroed first; free it
 * with ply_mesh_free, also after a failure). name is used in messages
 * ("name: what" or "name:line: what" in the header). */
PK_HIDDEN pk_status ply_parse(pk_context *ctx, const char *data, size_t size, const char *name, ply_mesh *out);
PK_HIDDEN void ply_mesh_free(pk_context *ctx, ply_mesh *m);

#endif

/*
 * gltf_draco_module.h - the C interface between the library and its Draco
 * module (paprsek_draco.so, built from gltf_draco.cpp where Debian's
 * libdraco-dev is found). The library never links Draco or the C++
 * runtime: gltf_draco.c loads the module with dlopen the first time a
 * KHR_draco_mesh_compression primitive is read, and hands it the
 * compressed bytes. The module sees nothing of the library but this header
 * (plain C): it allocates through host->alloc and reports through the
 * result; it prints nothing and throws nothing.
 *
 * The entry point's name carries the interface's version: a module of
 * another version of the library lacks it and is refused when loaded.
 */
#ifndef PK_GLTF_DRACO_MODULE_H
#define PK_GLTF_DRACO_MODULE_H

#include <stddef.h>
#include <stdint.h>

#define GLTF_DRACO_MODULE_FILE "paprsek_draco.so"
#define GLTF_DRACO_ENTRY "pk_draco_decode_v1"

/* What the library lends the module for one decode. */
typedef struct gltf_draco_host {
    void *user;
    void *(*alloc)(void *user, size_t size); /* NULL when out of memory */
    void (*free)(void *user, void *p);
    uint64_t max_points, max_faces;          /* larger meshes are refused (PK_ERR_LIMIT) */
} gltf_draco_host;

/* One attribute asked for: Draco's unique id, and the layout the glTF
 * accessor declares: ctype (5120 .. 5126, as glTF's componentType) and ncomp
 * components a point. The module sets data (npoints * ncomp components of
 * ctype, from host->alloc; the caller owns it): the attribute's values
 * converted as Draco converts them (integers to floats normalized when the
 * attribute is). */
typedef struct gltf_draco_attr {
    int id;
    int ctype;
    int ncomp;
    void *data;
} gltf_draco_attr;

/* One decode's outcome. status: 0 (PK_OK) with npoints, nfaces and indices
 * (3 * nfaces point indices, from host->alloc; the caller owns them and the
 * attributes' data); or a pk_status (PK_ERR_PARSE, PK_ERR_LIMIT,
 * PK_ERR_NOMEM) with message saying what is wrong and nothing allocated. */
typedef struct gltf_draco_result {
    int status;
    char message[300];
    size_t npoints, nfaces;
    uint32_t *indices;
} gltf_draco_result;

/* The module's one entry point (GLTF_DRACO_ENTRY): decodes the Draco mesh
 * in data[0..size-1] and the nattrs attributes of attrs. */
typedef void (*gltf_draco_decode_fn)(const gltf_draco_host *host, const uint8_t *data, size_t size,
                                     gltf_draco_attr *attrs, int nattrs, gltf_draco_result *out);

#endif

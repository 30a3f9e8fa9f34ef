/*
 * grid_openvdb_module.h - the C interface between the library and its
 * OpenVDB module (paprsek_openvdb.so, built from grid_openvdb.cpp where
 * Debian's libopenvdb-dev is found). The library never links OpenVDB, Boost
 * or the C++ runtime: grid_openvdb.c loads the module with dlopen the first
 * time a .vdb file is read, and hands it the file's bytes. The module sees
 * nothing of the library but this header (plain C, no library symbols): it
 * allocates the voxels through host->alloc and reports through the result.
 *
 * The entry point's name carries the interface's version: a module of
 * another version of the library lacks it and is refused when loaded.
 */
#ifndef PK_GRID_OPENVDB_MODULE_H
#define PK_GRID_OPENVDB_MODULE_H

#include <stddef.h>
#include <stdint.h>

#define GRID_OPENVDB_MODULE_FILE "paprsek_openvdb.so"
#define GRID_OPENVDB_ENTRY "pk_openvdb_read_v1"

/* What the library lends the module for one read. */
typedef struct grid_vdb_host {
    void *user;
    /* size bytes for the voxels (NULL when out of memory), and freeing them */
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *p);
    /* one line OpenVDB wrote to std::cerr while the file was read (n bytes) */
    void (*warn)(void *user, const char *line, size_t n);
    uint64_t max_voxels; /* MEDIUM_MAX_VOXELS */
} grid_vdb_host;

/* One read's outcome. status: 0 (PK_OK) with the grid in nx, ny, nz, data
 * (x fastest, from host->alloc; the caller owns it) and the box lo..hi; or a
 * pk_status (PK_ERR_PARSE, PK_ERR_UNSUPPORTED, PK_ERR_LIMIT, PK_ERR_NOMEM)
 * with message saying what is wrong (without the file's name) and nothing
 * allocated. */
typedef struct grid_vdb_result {
    int status;
    char message[400];
    int nx, ny, nz;
    float *data;
    float lo[3], hi[3];
} grid_vdb_result;

/* The module's one entry point (GRID_OPENVDB_ENTRY): reads the float grid
 * named grid (NULL: the first float grid) of the OpenVDB file whose bytes
 * are data[0..size-1]; prints nothing, throws nothing. */
typedef void (*grid_vdb_read_fn)(const grid_vdb_host *host, const char *data, size_t size, const char *grid,
                                 grid_vdb_result *out);

#endif

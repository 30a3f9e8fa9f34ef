/*
 * grid_io.h - voxel grid files for participating media (scene/medium.h):
 * Mitsuba's binary .vol format, NanoVDB files (float grids) and, through the
 * OpenVDB module (grid_openvdb.c) where it is installed, .vdb files. Each reader fills a medium_grid (x fastest,
 * 1 or 3 channels, values checked finite) and the box the grid spans in the
 * file's own coordinates (the reader of the scene then places that box),
 * allocating with al. Bad files are refused with one message
 * "path: what is wrong" latched in ctx (PK_ERR_IO, PK_ERR_PARSE,
 * PK_ERR_LIMIT beyond MEDIUM_MAX_VOXELS, PK_ERR_UNSUPPORTED for what the
 * build or reader does not handle); nothing is left allocated on failure.
 */
#ifndef PK_GRID_IO_H
#define PK_GRID_IO_H

#include "../paprsek_internal.h"
#include "../scene/medium.h"

/* Mitsuba 0.6 / 3 gridvolume ".vol": "VOL", version 3, encoding 1 (float32),
 * xres, yres, zres, channels (1 or 3), the bounding box (6 float32), then the
 * data, x fastest. */
PK_HIDDEN pk_status grid_read_vol(pk_context *ctx, const pk_allocator *al, const char *path, medium_grid *out,
                                  aabb *box);

/* A float grid of a NanoVDB file (.nvdb, format version 32), by name (NULL
 * or "": the first float grid), made dense over its root's active index box
 * with what a lookup returns (leaf values, tile values, the background).
 * Voxel values sit at integer index coordinates, so *box is that index box
 * widened by half a voxel on every side, mapped by the grid's index-to-world
 * map (scales and a shift only; others are refused). Uncompressed files only. */
PK_HIDDEN pk_status grid_read_nanovdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                                      medium_grid *out, aabb *box);

/* A float grid of an OpenVDB file (.vdb), by name (NULL or "": the first
 * float grid), made dense over its active bounding box, *box as for NanoVDB
 * (through the grid's linear transform), read by the OpenVDB module (ctx's
 * config openvdb.module, or the installed one). PK_ERR_UNSUPPORTED with a
 * message naming OpenVDB's package when the module is not there or does not
 * load. */
PK_HIDDEN pk_status grid_read_openvdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                                      medium_grid *out, aabb *box);

/* Whether .vdb files are read: the OpenVDB module ctx's config names (or
 * the installed one) loads. */
PK_HIDDEN bool grid_have_openvdb(const pk_context *ctx);

#endif

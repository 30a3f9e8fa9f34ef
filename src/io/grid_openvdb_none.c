/*
 * grid_openvdb_none.c - the .vdb reader of a build without OpenVDB
 * (Debian's libopenvdb-dev was not found when it was built): every .vdb
 * file is refused with a message saying so. grid_openvdb.cpp replaces this
 * file where OpenVDB is found.
 */
#include "grid_io.h"

pk_status grid_read_openvdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                            medium_grid *out, aabb *box)
{
    (void)al, (void)grid;
    *out = (medium_grid){0};
    *box = aabb_empty();
    return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                     "%s: this build reads no .vdb files (OpenVDB was not found when it was built)", path);
}

bool grid_have_openvdb(void) { return false; }

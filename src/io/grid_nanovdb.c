/*
 * grid_nanovdb.c - NanoVDB files (.nvdb). Not read yet: refused with a
 * message.
 */
#include "grid_io.h"

pk_status grid_read_nanovdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                            medium_grid *out, aabb *box)
{
    (void)al, (void)grid;
    *out = (medium_grid){0};
    *box = aabb_empty();
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: NanoVDB files are not read yet", path);
}

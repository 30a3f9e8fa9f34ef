/*
 * grid_openvdb.c - .vdb files through the OpenVDB module (paprsek_openvdb.so,
 * grid_openvdb.cpp; the interface is grid_openvdb_module.h). The library
 * links neither OpenVDB nor C++: the module is loaded (device/module.h: the
 * config's openvdb.module, or the one installed beside the library) the
 * first time a .vdb file is read, and never closed. Without it (OpenVDB was
 * not installed when the library was built, or is not installed now) a
 * .vdb file is refused with PK_ERR_UNSUPPORTED and one message naming the
 * package that brings it.
 */
#include "grid_io.h"
#include "grid_openvdb_module.h"

#include "device/module.h"

#include <stdio.h>
#include <string.h>

static dynlib vdb_module = DYNLIB_INIT;
static grid_vdb_read_fn vdb_read; /* set once under the loader's lock */

static bool init_vdb(void *h, const char *name, char *why, size_t n)
{
    void *sym = dynlib_symbol(h, GRID_OPENVDB_ENTRY);
    if (!sym) {
        snprintf(why, n, "%s has no %s (not the OpenVDB module of this version of the library)", name,
                 GRID_OPENVDB_ENTRY);
        return false;
    }
    memcpy(&vdb_read, &sym, sizeof sym);
    return true;
}

/* Loads the module ctx's config names (or the installed one); true when
 * vdb_read is ready, else false with the message for a .vdb file in why. */
static bool vdb_loaded(const pk_context *ctx, char *why, size_t n)
{
    char reason[600];
    bool missing = false;
    if (module_load(&vdb_module, ctx->config.openvdb_module, GRID_OPENVDB_MODULE_FILE, init_vdb, &missing, reason,
                    sizeof reason))
        return true;
    if (missing)
        snprintf(why, n, ".vdb files are read by the OpenVDB module, which is not here (%.400s): install OpenVDB "
                 "(Debian: libopenvdb-dev) and build the module (make build)", reason);
    else
        snprintf(why, n, "the OpenVDB module does not load: %.400s; is OpenVDB installed? (Debian: libopenvdb-dev)",
                 reason);
    return false;
}

bool grid_have_openvdb(const pk_context *ctx)
{
    char why[8];
    return vdb_loaded(ctx, why, sizeof why);
}

typedef struct host_state {
    pk_context *ctx;
    const pk_allocator *al;
    const char *path;
} host_state;

static void *host_alloc(void *user, size_t size) { return mem_alloc(((host_state *)user)->al, size); }
static void host_free(void *user, void *p) { mem_free(((host_state *)user)->al, p); }

static void host_warn(void *user, const char *line, size_t n)
{
    const host_state *h = user;
    ctx_warn(h->ctx, "%s: OpenVDB: %.*s", h->path, (int)(n > 300 ? 300 : n), line);
}

pk_status grid_read_openvdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                            medium_grid *out, aabb *box)
{
    *out = (medium_grid){0};
    *box = aabb_empty();
    char why[1100];
    if (!vdb_loaded(ctx, why, sizeof why)) return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: %s", path, why);
    char *data = NULL;
    size_t size = 0;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    host_state hs = {ctx, al, path};
    const grid_vdb_host host = {&hs, host_alloc, host_free, host_warn, MEDIUM_MAX_VOXELS};
    grid_vdb_result r;
    memset(&r, 0, sizeof r);
    vdb_read(&host, data, size, grid, &r);
    mem_free(&ctx->alloc, data);
    if (r.status == PK_ERR_NOMEM) return ctx_nomem(ctx);
    if (r.status != PK_OK) {
        r.message[sizeof r.message - 1] = '\0';
        return ctx_error(ctx, (pk_status)r.status, "%s: %s", path, r.message);
    }
    out->nx = r.nx, out->ny = r.ny, out->nz = r.nz;
    out->channels = 1;
    out->data = r.data;
    box->lo = v3(r.lo[0], r.lo[1], r.lo[2]);
    box->hi = v3(r.hi[0], r.hi[1], r.hi[2]);
    return PK_OK;
}

/* fuzz_grid.c - the grid file readers of participating media
 * (io/grid_io.h): Mitsuba's .vol and NanoVDB, both given the same bytes
 * through a context file reader that serves the input for any path; the
 * NanoVDB reader both for its first float grid and for a grid by name.
 * Oracle: a failure carries a message; a grid read has a size within the
 * voxel limit, 1 or 3 channels and finite values, and a finite box with
 * lo < hi on every axis. (OpenVDB's own reader is not fuzzed here.) */
#include "fuzz.h"

#include "io/grid_io.h"
#include "paprsek_internal.h"

#include <math.h>

typedef struct fuzz_input {
    const uint8_t *data;
    size_t size;
} fuzz_input;

static pk_status serve(void *user, const char *path, const void **data, size_t *size, char *why, size_t why_cap)
{
    (void)path, (void)why, (void)why_cap;
    const fuzz_input *in = user;
    *data = in->data;
    *size = in->size;
    return PK_OK;
}

static void check_grid(pk_context *ctx, pk_status st, medium_grid *g, const aabb *box)
{
    fuzz_check_error(ctx, st);
    if (st != PK_OK) {
        if (g->data) {
            fprintf(stderr, "fuzz: a refused grid kept its data\n");
            abort();
        }
        pk_context_clear_error(ctx);
        return;
    }
    if (g->nx <= 0 || g->ny <= 0 || g->nz <= 0 || (g->channels != 1 && g->channels != 3) || !g->data ||
        (size_t)g->nx * (size_t)g->ny * (size_t)g->nz > MEDIUM_MAX_VOXELS) {
        fprintf(stderr, "fuzz: bad grid %d x %d x %d x %d\n", g->nx, g->ny, g->nz, g->channels);
        abort();
    }
    const size_t n = (size_t)g->nx * (size_t)g->ny * (size_t)g->nz * (size_t)g->channels;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(g->data[i])) {
            fprintf(stderr, "fuzz: value %zu is not finite\n", i);
            abort();
        }
    if (!(isfinite(box->lo.x) && isfinite(box->lo.y) && isfinite(box->lo.z) && isfinite(box->hi.x) &&
          isfinite(box->hi.y) && isfinite(box->hi.z) && box->lo.x < box->hi.x && box->lo.y < box->hi.y &&
          box->lo.z < box->hi.z)) {
        fprintf(stderr, "fuzz: bad box\n");
        abort();
    }
    mem_free(&ctx->alloc, g->data);
    g->data = NULL;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    size_t warned = 0;
    pk_context_set_warning_handler(ctx, fuzz_warning, &warned);
    fuzz_input in = {data, size};
    pk_context_set_file_reader(ctx, serve, &in);
    medium_grid g;
    aabb box;
    pk_status st = grid_read_vol(ctx, &ctx->alloc, "fuzz.vol", &g, &box);
    check_grid(ctx, st, &g, &box);
    st = grid_read_nanovdb(ctx, &ctx->alloc, "fuzz.nvdb", NULL, &g, &box);
    check_grid(ctx, st, &g, &box);
    st = grid_read_nanovdb(ctx, &ctx->alloc, "fuzz.nvdb", "density", &g, &box);
    check_grid(ctx, st, &g, &box);
    pk_context_destroy(ctx);
    return 0;
}

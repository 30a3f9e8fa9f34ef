/*
 * grid_vol.c - Mitsuba's binary grid volume (.vol, the "gridvolume" of
 * Mitsuba 0.6 and Mitsuba 3). The layout, all little endian:
 *
 *   bytes 0..2   'V' 'O' 'L'
 *   byte  3      version, 3
 *   int32        encoding: 1 = float32 (the only one read here)
 *   int32 x 3    xres, yres, zres
 *   int32        channels: 1 or 3
 *   float32 x 6  the bounding box: xmin, ymin, zmin, xmax, ymax, zmax
 *   float32 ...  xres * yres * zres * channels values, channels innermost,
 *                then x, then y, then z
 *
 * which is medium_grid's own order, so the data is copied as it is after
 * its checks.
 */
#include "grid_io.h"

#include <math.h>
#include <string.h>

#define VOL_HEADER_BYTES 48

static uint32_t vol_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static int32_t vol_i32(const unsigned char *p)
{
    const uint32_t u = vol_u32(p);
    int32_t v;
    memcpy(&v, &u, sizeof v);
    return v;
}

static float vol_f32(const unsigned char *p)
{
    const uint32_t u = vol_u32(p);
    float v;
    memcpy(&v, &u, sizeof v);
    return v;
}

static pk_status vol_parse(pk_context *ctx, const pk_allocator *al, const char *path, const unsigned char *d,
                           size_t size, medium_grid *out, aabb *box)
{
    static const char magic[3] = {'V', 'O', 'L'};
    if (memcmp(d, magic, size < 3 ? size : 3) != 0)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not a Mitsuba grid volume (the file does not start with \"VOL\")", path);
    if (size < 4)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: truncated header (%zu of %d bytes)", path, size, VOL_HEADER_BYTES);
    if (d[3] != 3)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: grid volume version %d (only version 3 is read)", path,
                         (int)d[3]);
    if (size < VOL_HEADER_BYTES)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: truncated header (%zu of %d bytes)", path, size, VOL_HEADER_BYTES);
    const int32_t encoding = vol_i32(d + 4);
    if (encoding != 1)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                         "%s: grid volume encoding %ld (only 1, 32-bit floats, is read)", path, (long)encoding);
    const int32_t res[3] = {vol_i32(d + 8), vol_i32(d + 12), vol_i32(d + 16)};
    const int32_t channels = vol_i32(d + 20);
    if (res[0] <= 0 || res[1] <= 0 || res[2] <= 0)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: bad grid size %ld x %ld x %ld (each must be at least 1)", path,
                         (long)res[0], (long)res[1], (long)res[2]);
    if (channels != 1 && channels != 3)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: %ld channels (only 1 or 3 are read)", path, (long)channels);
    /* each factor is below 2^31, so the products of two fit in 64 bits;
     * the voxel count is compared before the third factor can overflow */
    const uint64_t nxy = (uint64_t)res[0] * (uint64_t)res[1];
    if (nxy > (uint64_t)MEDIUM_MAX_VOXELS || nxy * (uint64_t)res[2] > (uint64_t)MEDIUM_MAX_VOXELS)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: grid of %ld x %ld x %ld voxels is beyond the limit of %zu voxels",
                         path, (long)res[0], (long)res[1], (long)res[2], (size_t)MEDIUM_MAX_VOXELS);
    const size_t nvox = (size_t)(nxy * (uint64_t)res[2]);
    const size_t nval = nvox * (size_t)channels;
    const size_t need = VOL_HEADER_BYTES + nval * sizeof(float);
    if (size < need)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: truncated: %zu bytes, a %ld x %ld x %ld grid of %ld channel%s needs %zu",
                         path, size, (long)res[0], (long)res[1], (long)res[2], (long)channels, channels == 1 ? "" : "s",
                         need);
    float b[6];
    for (int i = 0; i < 6; i++) b[i] = vol_f32(d + 24 + 4 * i);
    for (int i = 0; i < 6; i++)
        if (!isfinite(b[i])) return ctx_error(ctx, PK_ERR_PARSE, "%s: the bounding box is not finite", path);
    for (int a = 0; a < 3; a++)
        if (!(b[a] < b[a + 3]))
            return ctx_error(ctx, PK_ERR_PARSE, "%s: empty or inverted bounding box (%c from %g to %g)", path, "xyz"[a],
                             (double)b[a], (double)b[a + 3]);
    const unsigned char *src = d + VOL_HEADER_BYTES;
    for (size_t i = 0; i < nval; i++) {
        const float v = vol_f32(src + 4 * i);
        if (!isfinite(v)) {
            const size_t vox = i / (size_t)channels;
            const size_t x = vox % (size_t)res[0], y = vox / (size_t)res[0] % (size_t)res[1],
                         z = vox / ((size_t)res[0] * (size_t)res[1]);
            return ctx_error(ctx, PK_ERR_PARSE, "%s: voxel (%zu, %zu, %zu) channel %zu is %s", path, x, y, z,
                             i % (size_t)channels, isnan(v) ? "NaN" : "infinite");
        }
    }
    float *data = mem_alloc(al, nval * sizeof(float));
    if (!data) return ctx_nomem(ctx);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    memcpy(data, src, nval * sizeof(float));
#else
    for (size_t i = 0; i < nval; i++) data[i] = vol_f32(src + 4 * i);
#endif
    if (size > need) ctx_warn(ctx, "%s: %zu bytes after the grid's data ignored", path, size - need);
    out->nx = res[0], out->ny = res[1], out->nz = res[2];
    out->channels = channels;
    out->data = data;
    box->lo = v3(b[0], b[1], b[2]);
    box->hi = v3(b[3], b[4], b[5]);
    return PK_OK;
}

pk_status grid_read_vol(pk_context *ctx, const pk_allocator *al, const char *path, medium_grid *out, aabb *box)
{
    *out = (medium_grid){0};
    *box = aabb_empty();
    char *data = NULL;
    size_t size = 0;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    st = vol_parse(ctx, al, path, (const unsigned char *)data, size, out, box);
    mem_free(&ctx->alloc, data);
    if (st != PK_OK) {
        *out = (medium_grid){0};
        *box = aabb_empty();
    }
    return st;
}

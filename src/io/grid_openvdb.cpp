/*
 * grid_openvdb.cpp - float grids of OpenVDB files (.vdb) through OpenVDB
 * (Debian's libopenvdb-dev), the library's only C++: it implements the C
 * interface of grid_io.h, catches every exception and prints nothing. The
 * build compiles it instead of grid_openvdb_none.c where OpenVDB is found.
 *
 * The file's bytes come through file_read_all (so that a context's file
 * reader serves them too) and are read as an OpenVDB stream. The grid asked
 * for (or the first float grid) is made dense over its active voxels'
 * bounding box with what a lookup in its tree returns (background where
 * nothing is stored); its box is that index box, half a voxel wider on
 * every side (OpenVDB's voxel centres lie on integer index coordinates),
 * mapped to world space by the grid's transform, which must be linear and
 * only scale (by positive factors) and translate.
 */
/* the library's C headers, read as C++: their zero-initialising compound
 * literals are fine in C and only draw C++'s field-initialiser warning */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
extern "C" {
#include "grid_io.h"
}
#pragma GCC diagnostic pop

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <istream>
#include <sstream>
#include <new>
#include <streambuf>
#include <string>

namespace {

/* A read-only stream buffer over bytes in memory (no copy). */
class MemoryBuf : public std::streambuf {
public:
    MemoryBuf(char *data, size_t size) { setg(data, data, data + size); }

protected:
    pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override
    {
        char *base = dir == std::ios_base::beg ? eback() : dir == std::ios_base::cur ? gptr() : egptr();
        if (off < eback() - base || off > egptr() - base) return pos_type(off_type(-1));
        setg(eback(), base + off, egptr());
        return pos_type(gptr() - eback());
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override
    {
        return seekoff(off_type(pos), std::ios_base::beg, which);
    }
};

/* OpenVDB (built without a logging library, as Debian's is) writes its
 * warnings to std::cerr: while a file is read they are caught and passed on
 * as the context's warnings instead. (std::cerr is the process's: output
 * another thread sends there meanwhile is caught too.) */
class CerrCapture {
public:
    CerrCapture(pk_context *ctx, const char *path) : ctx_(ctx), path_(path), old_(std::cerr.rdbuf(&text_)) {}
    ~CerrCapture()
    {
        std::cerr.rdbuf(old_);
        try {
            const std::string all = text_.str();
            size_t at = 0;
            while (at < all.size()) {
                size_t eol = all.find('\n', at);
                if (eol == std::string::npos) eol = all.size();
                if (eol > at)
                    ctx_warn(ctx_, "%s: OpenVDB: %.*s", path_, int(eol - at > 300 ? 300 : eol - at), all.c_str() + at);
                at = eol + 1;
            }
        } catch (...) { /* out of memory: the warnings are lost */
        }
    }
    CerrCapture(const CerrCapture &) = delete;
    CerrCapture &operator=(const CerrCapture &) = delete;

private:
    pk_context *ctx_;
    const char *path_;
    std::stringbuf text_;
    std::streambuf *old_;
};

struct Refusal {
    pk_status status;
    std::string what;
};

void check_transform(const openvdb::math::Transform &xf, double scale[3], double shift[3])
{
    if (!xf.isLinear()) throw Refusal{PK_ERR_UNSUPPORTED, "its transform is not linear (frustum or tapered)"};
    const openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
    /* OpenVDB's matrices act on row vectors: world = index * m */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (i != j && m(i, j) != 0.0)
                throw Refusal{PK_ERR_UNSUPPORTED, "its transform rotates or shears (only scales and translations are read)"};
    for (int a = 0; a < 3; a++) {
        scale[a] = m(a, a);
        shift[a] = m(3, a);
        if (!(std::isfinite(scale[a]) && scale[a] > 0.0 && std::isfinite(shift[a])))
            throw Refusal{PK_ERR_UNSUPPORTED, "its transform does not scale by positive finite factors"};
    }
}

pk_status read_float_grid(pk_context *ctx, const pk_allocator *al, const char *path, const openvdb::FloatGrid &grid,
                          medium_grid *out, aabb *box)
{
    const openvdb::CoordBBox bb = grid.evalActiveVoxelBoundingBox();
    if (bb.empty()) throw Refusal{PK_ERR_PARSE, "no active voxels"};
    const openvdb::Coord lo = bb.min(), hi = bb.max();
    int64_t dim[3];
    uint64_t nvox = 1;
    for (int a = 0; a < 3; a++) {
        dim[a] = int64_t(hi[a]) - int64_t(lo[a]) + 1;
        if (uint64_t(dim[a]) > MEDIUM_MAX_VOXELS || nvox * uint64_t(dim[a]) > MEDIUM_MAX_VOXELS)
            throw Refusal{PK_ERR_LIMIT, std::to_string(dim[0]) + " x " + std::to_string(dim[1]) + " x " +
                                            std::to_string(dim[2]) + " voxels is beyond the limit of " +
                                            std::to_string(size_t(MEDIUM_MAX_VOXELS)) + " voxels"};
        nvox *= uint64_t(dim[a]);
    }
    double scale[3], shift[3];
    check_transform(grid.transform(), scale, shift);
    float blo[3], bhi[3];
    for (int a = 0; a < 3; a++) {
        blo[a] = float(scale[a] * (double(lo[a]) - 0.5) + shift[a]);
        bhi[a] = float(scale[a] * (double(hi[a]) + 0.5) + shift[a]);
        if (!(std::isfinite(blo[a]) && std::isfinite(bhi[a]) && blo[a] < bhi[a]))
            throw Refusal{PK_ERR_PARSE, "its box in world space is empty or not finite"};
    }
    float *v = static_cast<float *>(mem_alloc(al, size_t(nvox) * sizeof(float)));
    if (!v) return ctx_nomem(ctx);
    openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
    size_t i = 0;
    for (int32_t z = lo[2]; z <= hi[2]; z++)
        for (int32_t y = lo[1]; y <= hi[1]; y++)
            for (int32_t x = lo[0]; x <= hi[0]; x++, i++) {
                const float f = acc.getValue(openvdb::Coord(x, y, z));
                if (!std::isfinite(f)) {
                    mem_free(al, v);
                    throw Refusal{PK_ERR_PARSE, "the value at voxel (" + std::to_string(x) + ", " + std::to_string(y) +
                                                    ", " + std::to_string(z) + ") is " +
                                                    (std::isnan(f) ? "NaN" : "infinite")};
                }
                v[i] = f;
            }
    out->nx = int(dim[0]), out->ny = int(dim[1]), out->nz = int(dim[2]);
    out->channels = 1;
    out->data = v;
    box->lo = v3(blo[0], blo[1], blo[2]);
    box->hi = v3(bhi[0], bhi[1], bhi[2]);
    return PK_OK;
}

pk_status read_vdb(pk_context *ctx, const pk_allocator *al, const char *path, char *data, size_t size, const char *want,
                   medium_grid *out, aabb *box)
{
    std::string gname;
    try {
        openvdb::initialize();
        MemoryBuf buf(data, size);
        std::istream is(&buf);
        /* a short read throws at once: OpenVDB would otherwise go on with the
         * sizes it failed to read (gigabytes of string for a truncated name) */
        is.exceptions(std::ios_base::badbit | std::ios_base::failbit | std::ios_base::eofbit);
        openvdb::GridPtrVecPtr grids;
        {
            CerrCapture capture(ctx, path);
            openvdb::io::Stream stream(is, false);
            grids = stream.getGrids();
        }
        if (is.fail() || !grids) return ctx_error(ctx, PK_ERR_PARSE, "%s: not a readable OpenVDB file (truncated?)", path);
        openvdb::GridBase::Ptr chosen;
        std::string names;
        for (const openvdb::GridBase::Ptr &g : *grids) {
            if (!g) continue;
            if (names.size() < 120) names += (names.empty() ? "'" : ", '") + g->getName() + "'";
            if (chosen) continue;
            if (want ? g->getName() == want : g->isType<openvdb::FloatGrid>()) chosen = g;
        }
        if (names.empty()) names = "no grids";
        else names = "the file has " + names;
        if (!chosen) {
            if (want) return ctx_error(ctx, PK_ERR_PARSE, "%s: no grid named '%s' (%s)", path, want, names.c_str());
            return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: no float grid (%s)", path, names.c_str());
        }
        gname = chosen->getName();
        openvdb::FloatGrid::Ptr fg = openvdb::gridPtrCast<openvdb::FloatGrid>(chosen);
        if (!fg)
            throw Refusal{PK_ERR_UNSUPPORTED, "values of type " + chosen->valueType() + " (only float grids are read)"};
        return read_float_grid(ctx, al, path, *fg, out, box);
    } catch (const Refusal &r) {
        return ctx_error(ctx, r.status, "%s: grid '%.64s': %s", path, gname.c_str(), r.what.c_str());
    } catch (const std::ios_base::failure &) {
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not a readable OpenVDB file (it ends too soon)", path);
    } catch (const std::bad_alloc &) {
        return ctx_nomem(ctx);
    } catch (const std::exception &e) {
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not a readable OpenVDB file (%.200s)", path, e.what());
    } catch (...) {
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not a readable OpenVDB file", path);
    }
}

} // namespace

pk_status grid_read_openvdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                            medium_grid *out, aabb *box)
{
    *out = medium_grid{};
    *box = aabb_empty();
    char *data = nullptr;
    size_t size = 0;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    st = read_vdb(ctx, al, path, data, size, grid && grid[0] ? grid : nullptr, out, box);
    mem_free(&ctx->alloc, data);
    if (st != PK_OK) {
        *out = medium_grid{};
        *box = aabb_empty();
    }
    return st;
}

bool grid_have_openvdb(void) { return true; }

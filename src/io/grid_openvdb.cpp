/*
 * grid_openvdb.cpp - the OpenVDB module (paprsek_openvdb.so): float grids of
 * OpenVDB files (.vdb) through OpenVDB (Debian's libopenvdb-dev). It is a
 * shared module of its own, the only C++ of the project, built where OpenVDB
 * is found and loaded by the library (grid_openvdb.c) the first time a .vdb
 * file is read, so that the library and its programs link neither OpenVDB,
 * Boost nor the C++ runtime. Its one entry point, of the C interface of
 * grid_openvdb_module.h, catches every exception and prints nothing.
 *
 * The file's bytes come from the library (so that a context's file reader
 * serves them too) and are read as an OpenVDB stream. The grid asked for (or
 * the first float grid) is made dense over its active voxels' bounding box
 * with what a lookup in its tree returns (background where nothing is
 * stored); its box is that index box, half a voxel wider on every side
 * (OpenVDB's voxel centres lie on integer index coordinates), mapped to
 * world space by the grid's transform, which must be linear and only scale
 * (by positive factors) and translate.
 */
#include "grid_openvdb_module.h"

#include "paprsek.h" /* pk_status's values alone */

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
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
 * to the library (host->warn), which makes them the context's warnings. (std::cerr is the process's: output
 * another thread sends there meanwhile is caught too.) */
class CerrCapture {
public:
    explicit CerrCapture(const grid_vdb_host *host) : host_(host), old_(std::cerr.rdbuf(&text_)) {}
    ~CerrCapture()
    {
        std::cerr.rdbuf(old_);
        try {
            const std::string all = text_.str();
            size_t at = 0;
            while (at < all.size()) {
                size_t eol = all.find('\n', at);
                if (eol == std::string::npos) eol = all.size();
                if (eol > at) host_->warn(host_->user, all.c_str() + at, eol - at);
                at = eol + 1;
            }
        } catch (...) { /* out of memory: the warnings are lost */
        }
    }
    CerrCapture(const CerrCapture &) = delete;
    CerrCapture &operator=(const CerrCapture &) = delete;

private:
    const grid_vdb_host *host_;
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

/* Fails the read: status and message (printf-style) in out. */
__attribute__((format(printf, 3, 4))) void fail(grid_vdb_result *out, int status, const char *fmt, ...)
{
    out->status = status;
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(out->message, sizeof out->message, fmt, ap);
    va_end(ap);
}

void read_float_grid(const grid_vdb_host *host, const openvdb::FloatGrid &grid, grid_vdb_result *out)
{
    const openvdb::CoordBBox bb = grid.evalActiveVoxelBoundingBox();
    if (bb.empty()) throw Refusal{PK_ERR_PARSE, "no active voxels"};
    const openvdb::Coord lo = bb.min(), hi = bb.max();
    int64_t dim[3];
    uint64_t nvox = 1;
    for (int a = 0; a < 3; a++) {
        dim[a] = int64_t(hi[a]) - int64_t(lo[a]) + 1;
        if (uint64_t(dim[a]) > host->max_voxels || nvox * uint64_t(dim[a]) > host->max_voxels)
            throw Refusal{PK_ERR_LIMIT, std::to_string(dim[0]) + " x " + std::to_string(dim[1]) + " x " +
                                            std::to_string(dim[2]) + " voxels is beyond the limit of " +
                                            std::to_string(host->max_voxels) + " voxels"};
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
    float *v = static_cast<float *>(host->alloc(host->user, size_t(nvox) * sizeof(float)));
    if (!v) throw std::bad_alloc();
    openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
    size_t i = 0;
    for (int32_t z = lo[2]; z <= hi[2]; z++)
        for (int32_t y = lo[1]; y <= hi[1]; y++)
            for (int32_t x = lo[0]; x <= hi[0]; x++, i++) {
                const float f = acc.getValue(openvdb::Coord(x, y, z));
                if (!std::isfinite(f)) {
                    host->free(host->user, v);
                    throw Refusal{PK_ERR_PARSE, "the value at voxel (" + std::to_string(x) + ", " + std::to_string(y) +
                                                    ", " + std::to_string(z) + ") is " +
                                                    (std::isnan(f) ? "NaN" : "infinite")};
                }
                v[i] = f;
            }
    out->nx = int(dim[0]), out->ny = int(dim[1]), out->nz = int(dim[2]);
    out->data = v;
    for (int a = 0; a < 3; a++) out->lo[a] = blo[a], out->hi[a] = bhi[a];
    out->status = PK_OK;
}

void read_vdb(const grid_vdb_host *host, const char *data, size_t size, const char *want, grid_vdb_result *out)
{
    std::string gname;
    try {
        openvdb::initialize();
        /* the stream only reads: the bytes are not written through */
        MemoryBuf buf(const_cast<char *>(data), size);
        std::istream is(&buf);
        /* a short read throws at once: OpenVDB would otherwise go on with the
         * sizes it failed to read (gigabytes of string for a truncated name) */
        is.exceptions(std::ios_base::badbit | std::ios_base::failbit | std::ios_base::eofbit);
        openvdb::GridPtrVecPtr grids;
        {
            CerrCapture capture(host);
            openvdb::io::Stream stream(is, false);
            grids = stream.getGrids();
        }
        if (is.fail() || !grids) return fail(out, PK_ERR_PARSE, "not a readable OpenVDB file (truncated?)");
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
            if (want) return fail(out, PK_ERR_PARSE, "no grid named '%.100s' (%s)", want, names.c_str());
            return fail(out, PK_ERR_UNSUPPORTED, "no float grid (%s)", names.c_str());
        }
        gname = chosen->getName();
        openvdb::FloatGrid::Ptr fg = openvdb::gridPtrCast<openvdb::FloatGrid>(chosen);
        if (!fg)
            throw Refusal{PK_ERR_UNSUPPORTED, "values of type " + chosen->valueType() + " (only float grids are read)"};
        read_float_grid(host, *fg, out);
    } catch (const Refusal &r) {
        fail(out, r.status, "grid '%.64s': %s", gname.c_str(), r.what.c_str());
    } catch (const std::ios_base::failure &) {
        fail(out, PK_ERR_PARSE, "not a readable OpenVDB file (it ends too soon)");
    } catch (const std::bad_alloc &) {
        fail(out, PK_ERR_NOMEM, "out of memory");
    } catch (const std::exception &e) {
        fail(out, PK_ERR_PARSE, "not a readable OpenVDB file (%.200s)", e.what());
    } catch (...) {
        fail(out, PK_ERR_PARSE, "not a readable OpenVDB file");
    }
}

} // namespace

extern "C" __attribute__((visibility("default"))) void pk_openvdb_read_v1(const grid_vdb_host *host, const char *data,
                                                                          size_t size, const char *grid,
                                                                          grid_vdb_result *out)
{
    *out = grid_vdb_result{};
    read_vdb(host, data, size, grid && grid[0] ? grid : nullptr, out);
    if (out->status != PK_OK && out->data) {
        host->free(host->user, out->data);
        out->data = nullptr;
    }
}

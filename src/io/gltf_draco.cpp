/*
 * gltf_draco.cpp - the Draco module (paprsek_draco.so): glTF's
 * KHR_draco_mesh_compression streams decoded by Draco's decoder (Debian's
 * libdraco-dev). A shared module of its own, built where Draco is found and
 * loaded by the library (gltf_draco.c) the first time a Draco-compressed
 * primitive is read, so that the library and its programs link neither
 * Draco nor the C++ runtime. Its one entry point, of the C interface of
 * gltf_draco_module.h, catches every exception and prints nothing.
 *
 * The stream must hold a triangle mesh. Its faces become point indices;
 * each attribute asked for (by Draco's unique id) is written per point in
 * the component type and count of the glTF accessor that stands for it,
 * converted by Draco (its dequantized values; integers to floats
 * normalized where the attribute says so). A value that does not fit the
 * accessor's type is refused, not clamped.
 */
#include "gltf_draco_module.h"

#include "paprsek.h" /* pk_status's values alone */

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <new>

namespace {

void fail(gltf_draco_result *out, int status, const char *fmt, ...)
{
    out->status = status;
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(out->message, sizeof out->message, fmt, ap);
    va_end(ap);
}

size_t comp_size(int ctype)
{
    switch (ctype) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

template <typename T>
bool convert(const draco::PointAttribute *a, size_t npoints, int ncomp, void *dst)
{
    T *o = static_cast<T *>(dst);
    for (size_t i = 0; i < npoints; i++) {
        const draco::AttributeValueIndex v = a->mapped_index(draco::PointIndex(static_cast<uint32_t>(i)));
        if (v.value() >= a->size()) return false;
        if (!a->ConvertValue<T>(v, static_cast<int8_t>(ncomp), o + i * static_cast<size_t>(ncomp))) return false;
    }
    return true;
}

bool convert_any(const draco::PointAttribute *a, size_t npoints, int ctype, int ncomp, void *dst)
{
    switch (ctype) {
    case 5120: return convert<int8_t>(a, npoints, ncomp, dst);
    case 5121: return convert<uint8_t>(a, npoints, ncomp, dst);
    case 5122: return convert<int16_t>(a, npoints, ncomp, dst);
    case 5123: return convert<uint16_t>(a, npoints, ncomp, dst);
    case 5125: return convert<uint32_t>(a, npoints, ncomp, dst);
    default: return convert<float>(a, npoints, ncomp, dst);
    }
}

void release(const gltf_draco_host *host, gltf_draco_attr *attrs, int nattrs, gltf_draco_result *out)
{
    for (int k = 0; k < nattrs; k++) {
        host->free(host->user, attrs[k].data);
        attrs[k].data = nullptr;
    }
    host->free(host->user, out->indices);
    out->indices = nullptr;
    out->npoints = out->nfaces = 0;
}

void decode(const gltf_draco_host *host, const uint8_t *data, size_t size, gltf_draco_attr *attrs, int nattrs,
            gltf_draco_result *out)
{
    draco::DecoderBuffer buf;
    buf.Init(reinterpret_cast<const char *>(data), size);
    auto type = draco::Decoder::GetEncodedGeometryType(&buf);
    if (!type.ok()) return fail(out, PK_ERR_PARSE, "not a Draco stream (%.200s)", type.status().error_msg());
    if (type.value() != draco::TRIANGULAR_MESH)
        return fail(out, PK_ERR_PARSE, "a Draco point cloud where a triangle mesh is expected");
    draco::Decoder dec;
    auto res = dec.DecodeMeshFromBuffer(&buf);
    if (!res.ok()) return fail(out, PK_ERR_PARSE, "corrupt Draco stream (%.200s)", res.status().error_msg());
    const draco::Mesh &m = *res.value();
    const size_t np = m.num_points(), nf = m.num_faces();
    if (np > host->max_points || nf > host->max_faces)
        return fail(out, PK_ERR_LIMIT, "a Draco mesh of %zu points and %zu faces is beyond the limits (%llu, %llu)", np,
                    nf, (unsigned long long)host->max_points, (unsigned long long)host->max_faces);
    if (!np || !nf) return fail(out, PK_ERR_PARSE, "an empty Draco mesh (%zu points, %zu faces)", np, nf);
    out->indices = static_cast<uint32_t *>(host->alloc(host->user, nf * 3 * sizeof(uint32_t)));
    if (!out->indices) return fail(out, PK_ERR_NOMEM, "out of memory");
    for (size_t f = 0; f < nf; f++) {
        const draco::Mesh::Face &face = m.face(draco::FaceIndex(static_cast<uint32_t>(f)));
        for (int c = 0; c < 3; c++) {
            uint32_t v = face[c].value();
            if (v >= np) {
                release(host, attrs, nattrs, out);
                return fail(out, PK_ERR_PARSE, "a Draco face names point %u of %zu", v, np);
            }
            out->indices[3 * f + static_cast<size_t>(c)] = v;
        }
    }
    out->npoints = np;
    out->nfaces = nf;
    for (int k = 0; k < nattrs; k++) {
        gltf_draco_attr *r = &attrs[k];
        const draco::PointAttribute *a = r->id >= 0 ? m.GetAttributeByUniqueId(static_cast<uint32_t>(r->id)) : nullptr;
        if (!a) {
            release(host, attrs, nattrs, out);
            return fail(out, PK_ERR_PARSE, "the Draco stream has no attribute of id %d", r->id);
        }
        if (a->num_components() != r->ncomp) {
            int have = a->num_components();
            release(host, attrs, nattrs, out);
            return fail(out, PK_ERR_PARSE, "Draco attribute %d has %d components, its accessor %d", r->id, have,
                        r->ncomp);
        }
        const size_t cs = comp_size(r->ctype);
        if (!cs || r->ncomp < 1 || r->ncomp > 4) {
            release(host, attrs, nattrs, out);
            return fail(out, PK_ERR_PARSE, "Draco attribute %d: component type %d, %d components", r->id, r->ctype,
                        r->ncomp);
        }
        r->data = host->alloc(host->user, np * static_cast<size_t>(r->ncomp) * cs);
        if (!r->data) {
            release(host, attrs, nattrs, out);
            return fail(out, PK_ERR_NOMEM, "out of memory");
        }
        if (!convert_any(a, np, r->ctype, r->ncomp, r->data)) {
            release(host, attrs, nattrs, out);
            return fail(out, PK_ERR_PARSE, "Draco attribute %d: a value does not fit its accessor's component type %d",
                        r->id, r->ctype);
        }
    }
    out->status = PK_OK;
}

} // namespace

extern "C" __attribute__((visibility("default"))) void pk_draco_decode_v1(const gltf_draco_host *host,
                                                                          const uint8_t *data, size_t size,
                                                                          gltf_draco_attr *attrs, int nattrs,
                                                                          gltf_draco_result *out)
{
    std::memset(out, 0, sizeof *out);
    for (int k = 0; k < nattrs; k++) attrs[k].data = nullptr;
    try {
        decode(host, data, size, attrs, nattrs, out);
    } catch (const std::bad_alloc &) {
        release(host, attrs, nattrs, out);
        fail(out, PK_ERR_NOMEM, "out of memory");
    } catch (const std::exception &e) {
        release(host, attrs, nattrs, out);
        fail(out, PK_ERR_PARSE, "Draco: %.200s", e.what());
    } catch (...) {
        release(host, attrs, nattrs, out);
        fail(out, PK_ERR_PARSE, "Draco failed");
    }
}

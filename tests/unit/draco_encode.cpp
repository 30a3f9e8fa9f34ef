/*
 * draco_encode.cpp - Draco's encoder for test_gltf_draco (a C test): a
 * triangle mesh of positions, normals, uvs and 8-bit colours encoded into a
 * KHR_draco_mesh_compression stream, so that the test makes its own files.
 */
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <cstdint>
#include <cstring>
#include <memory>

namespace {

int add(draco::Mesh &m, draco::GeometryAttribute::Type type, const void *values, size_t np, int ncomp,
        draco::DataType dt, bool normalized, size_t csize)
{
    draco::GeometryAttribute ga;
    ga.Init(type, nullptr, static_cast<uint8_t>(ncomp), dt, normalized, static_cast<int64_t>(csize * ncomp), 0);
    int id = m.AddAttribute(ga, true, static_cast<uint32_t>(np));
    draco::PointAttribute *a = m.attribute(id);
    for (size_t i = 0; i < np; i++)
        a->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)),
                             static_cast<const uint8_t *>(values) + i * csize * static_cast<size_t>(ncomp));
    return static_cast<int>(a->unique_id());
}

} // namespace

/* Encodes the mesh (nrm, uv, col may be NULL) into out (cap bytes): its
 * length, 0 on failure. ids[0..3]: the unique ids of POSITION, NORMAL,
 * TEXCOORD_0, COLOR_0 (-1 where absent). sequential: Draco's sequential
 * connectivity (faces and points kept in order) instead of Edgebreaker;
 * qpos, qother: quantization bits of positions and of the other float
 * attributes (0: none, the values kept exactly). */
extern "C" size_t draco_encode_mesh(const float *pos, const float *nrm, const float *uv, const uint8_t *col, size_t np,
                                    const uint32_t *faces, size_t nf, int sequential, int qpos, int qother,
                                    int ids[4], uint8_t *out, size_t cap)
{
    draco::Mesh m;
    m.set_num_points(static_cast<uint32_t>(np));
    for (size_t f = 0; f < nf; f++) {
        draco::Mesh::Face face;
        for (int c = 0; c < 3; c++) face[c] = draco::PointIndex(faces[3 * f + static_cast<size_t>(c)]);
        m.AddFace(face);
    }
    ids[0] = add(m, draco::GeometryAttribute::POSITION, pos, np, 3, draco::DT_FLOAT32, false, 4);
    ids[1] = nrm ? add(m, draco::GeometryAttribute::NORMAL, nrm, np, 3, draco::DT_FLOAT32, false, 4) : -1;
    ids[2] = uv ? add(m, draco::GeometryAttribute::TEX_COORD, uv, np, 2, draco::DT_FLOAT32, false, 4) : -1;
    ids[3] = col ? add(m, draco::GeometryAttribute::COLOR, col, np, 4, draco::DT_UINT8, true, 1) : -1;
    draco::Encoder enc;
    if (qpos > 0) enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, qpos);
    if (qother > 0) {
        enc.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, qother);
        enc.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, qother);
    }
    if (sequential) enc.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
    else enc.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer buf;
    if (!enc.EncodeMeshToBuffer(m, &buf).ok()) return 0;
    if (buf.size() > cap) return 0;
    std::memcpy(out, buf.data(), buf.size());
    return buf.size();
}

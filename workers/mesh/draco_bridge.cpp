// draco_bridge.cpp — the one C++ file: Draco decode/encode behind the
// extern "C" API of draco_bridge.h. Every entry point wraps its whole body in
// try/catch(...) so no exception ever crosses into C. It knows nothing about
// the mesh type or files; mesh_drc.c does that.
#include "mesh/draco_bridge.h"
extern "C" {
#include "util/errbuf.h"
}

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

namespace {

// Decodes into v/f (malloc'ed) or returns an error; may throw.
int decode(const unsigned char *buf, size_t len, int max_points, int max_faces,
           double **v, int *nv, int **f, int *nf, char *err, size_t errsz)
{
    draco::DecoderBuffer db;
    db.Init(reinterpret_cast<const char *>(buf), len);
    auto kind = draco::Decoder::GetEncodedGeometryType(&db);
    if (!kind.ok())
        return errbuf_set(err, errsz, DRACOB_EDECODE, "not a Draco buffer: %s",
                    kind.status().error_msg());
    if (kind.value() == draco::POINT_CLOUD)
        return errbuf_set(err, errsz, DRACOB_EKIND,
                    "the Draco buffer holds a point cloud; a triangle mesh is needed");
    if (kind.value() != draco::TRIANGULAR_MESH)
        return errbuf_set(err, errsz, DRACOB_EKIND, "the Draco buffer holds no triangle mesh");
    draco::Decoder dec;
    auto res = dec.DecodeMeshFromBuffer(&db);
    if (!res.ok())
        return errbuf_set(err, errsz, DRACOB_EDECODE, "Draco decoding failed: %s",
                    res.status().error_msg());
    std::unique_ptr<draco::Mesh> dm = std::move(res).value();
    if (!dm)
        return errbuf_set(err, errsz, DRACOB_EDECODE, "Draco decoding returned no mesh");
    const long long np = dm->num_points(), nfaces = dm->num_faces();
    if (np > max_points || nfaces > max_faces)
        return errbuf_set(err, errsz, DRACOB_ELIMIT,
                    "%lld points / %lld faces, over the limit of %d / %d",
                    np, nfaces, max_points, max_faces);
    const draco::PointAttribute *pos =
        dm->GetNamedAttribute(draco::GeometryAttribute::POSITION);
    if (!pos || pos->num_components() != 3)
        return errbuf_set(err, errsz, DRACOB_EDECODE, "no 3-component POSITION attribute");
    const int idx_id = dm->GetAttributeIdByMetadataEntry(DRACOB_INDEX_METADATA_NAME,
                                                         DRACOB_INDEX_METADATA_VALUE);
    const draco::PointAttribute *ia = idx_id >= 0 ? dm->attribute(idx_id) : nullptr;
    if (ia && ia->num_components() != 1)
        return errbuf_set(err, errsz, DRACOB_EDECODE, "vertex index attribute has %d components",
                    ia->num_components());

    // where[p] = the output row of decoded point p.
    std::vector<int> where(static_cast<size_t>(np));
    if (ia) {
        std::vector<char> seen(static_cast<size_t>(np), 0);
        for (long long p = 0; p < np; p++) {
            int32_t orig = -1;
            if (!ia->ConvertValue<int32_t>(ia->mapped_index(draco::PointIndex(p)), 1, &orig))
                return errbuf_set(err, errsz, DRACOB_EDECODE, "point %lld: unreadable vertex index", p);
            if (orig < 0 || orig >= np || seen[orig])
                return errbuf_set(err, errsz, DRACOB_EDECODE,
                            "point %lld: vertex index %d is not part of a permutation of 0..%lld",
                            p, orig, np - 1);
            seen[orig] = 1;
            where[p] = orig;
        }
    } else {
        for (long long p = 0; p < np; p++)
            where[p] = static_cast<int>(p);
    }

    double *ov = static_cast<double *>(malloc(sizeof(double) * (3 * np + 1)));
    int *of = static_cast<int *>(malloc(sizeof(int) * (3 * nfaces + 1)));
    if (!ov || !of) {
        free(ov);
        free(of);
        return errbuf_set(err, errsz, DRACOB_ENOMEM, "out of memory for %lld points", np);
    }
    for (long long p = 0; p < np; p++) {
        double q[3];
        if (!pos->ConvertValue<double>(pos->mapped_index(draco::PointIndex(p)), 3, q)) {
            free(ov);
            free(of);
            return errbuf_set(err, errsz, DRACOB_EDECODE, "point %lld: unreadable position", p);
        }
        memcpy(ov + 3 * (size_t)where[p], q, sizeof q);
    }
    for (long long t = 0; t < nfaces; t++) {
        const draco::Mesh::Face &face = dm->face(draco::FaceIndex(t));
        for (int k = 0; k < 3; k++) {
            const uint32_t p = face[k].value();
            if (p >= static_cast<uint64_t>(np)) {
                free(ov);
                free(of);
                return errbuf_set(err, errsz, DRACOB_EDECODE,
                            "face %lld: point index %u out of range [0, %lld)", t, p, np);
            }
            of[3 * t + k] = where[p];
        }
    }
    *v = ov;
    *f = of;
    *nv = static_cast<int>(np);
    *nf = static_cast<int>(nfaces);
    return DRACOB_OK;
}

// 1 when every coordinate is a float exactly (bit for bit, NaN payloads and
// -0 included), so float32 storage loses nothing.
bool all_float32(const double *v, int nv)
{
    for (long long i = 0; i < 3LL * nv; i++) {
        const double back = static_cast<double>(static_cast<float>(v[i]));
        if (memcmp(&back, &v[i], sizeof back) != 0)
            return false;
    }
    return true;
}

int encode(const double *v, int nv, const int *f, int nf, int bits,
           unsigned char **buf, size_t *len, char *err, size_t errsz)
{
    draco::Mesh dm;
    dm.set_num_points(static_cast<uint32_t>(nv));
    // Lossless (bits 0): Draco's sequential encoder stores an unquantized
    // float attribute as its raw values, so float32 positions stay float32
    // and anything else goes as float64. Quantized: the quantizer reads
    // float32 values, an error far below its step.
    const bool f64 = bits == DRACOB_LOSSLESS && !all_float32(v, nv);
    draco::GeometryAttribute ga;
    ga.Init(draco::GeometryAttribute::POSITION, nullptr, 3,
            f64 ? draco::DT_FLOAT64 : draco::DT_FLOAT32, false,
            (f64 ? sizeof(double) : sizeof(float)) * 3, 0);
    const int pos_id = dm.AddAttribute(ga, true, static_cast<uint32_t>(nv));
    draco::GeometryAttribute gi;
    gi.Init(draco::GeometryAttribute::GENERIC, nullptr, 1, draco::DT_INT32, false,
            sizeof(int32_t), 0);
    const int idx_id = dm.AddAttribute(gi, true, static_cast<uint32_t>(nv));
    if (pos_id < 0 || idx_id < 0)
        return errbuf_set(err, errsz, DRACOB_EENCODE, "cannot add Draco attributes");
    draco::PointAttribute *pa = dm.attribute(pos_id);
    draco::PointAttribute *ia = dm.attribute(idx_id);
    for (int i = 0; i < nv; i++) {
        const int32_t id = i;
        if (f64) {
            pa->SetAttributeValue(draco::AttributeValueIndex(i), &v[3 * i]);
        } else {
            const float q[3] = { static_cast<float>(v[3 * i]), static_cast<float>(v[3 * i + 1]),
                                 static_cast<float>(v[3 * i + 2]) };
            pa->SetAttributeValue(draco::AttributeValueIndex(i), q);
        }
        ia->SetAttributeValue(draco::AttributeValueIndex(i), &id);
    }
    std::unique_ptr<draco::AttributeMetadata> md(new draco::AttributeMetadata());
    md->AddEntryString(DRACOB_INDEX_METADATA_NAME, DRACOB_INDEX_METADATA_VALUE);
    dm.AddAttributeMetadata(idx_id, std::move(md));
    for (int t = 0; t < nf; t++) {
        draco::Mesh::Face face;
        for (int k = 0; k < 3; k++)
            face[k] = draco::PointIndex(static_cast<uint32_t>(f[3 * t + k]));
        dm.AddFace(face);
    }
    draco::Encoder enc;
    enc.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
    if (bits != DRACOB_LOSSLESS)
        enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
    draco::EncoderBuffer eb;
    const draco::Status st = enc.EncodeMeshToBuffer(dm, &eb);
    if (!st.ok())
        return errbuf_set(err, errsz, DRACOB_EENCODE, "Draco encoding failed: %s", st.error_msg());
    unsigned char *out = static_cast<unsigned char *>(malloc(eb.size() + 1));
    if (!out)
        return errbuf_set(err, errsz, DRACOB_ENOMEM, "out of memory for %zu bytes", eb.size());
    memcpy(out, eb.data(), eb.size());
    *buf = out;
    *len = eb.size();
    return DRACOB_OK;
}

} // namespace

extern "C" int dracob_decode(const unsigned char *buf, size_t len, int max_points,
                             int max_faces, double **v, int *nv, int **f, int *nf,
                             char *err, size_t errsz)
{
    if (!v || !nv || !f || !nf)
        return errbuf_set(err, errsz, DRACOB_EARG, "dracob_decode: NULL output");
    *v = nullptr;
    *f = nullptr;
    *nv = *nf = 0;
    if (!buf || len == 0)
        return errbuf_set(err, errsz, DRACOB_EDECODE, "empty Draco buffer");
    if (static_cast<unsigned long long>(len) > static_cast<unsigned long long>(DRACOB_MAX_BUFFER_BYTES))
        return errbuf_set(err, errsz, DRACOB_ELIMIT, "Draco buffer of %zu bytes, over the limit of %lld",
                    len, static_cast<long long>(DRACOB_MAX_BUFFER_BYTES));
    try {
        return decode(buf, len, max_points, max_faces, v, nv, f, nf, err, errsz);
    } catch (const std::bad_alloc &) {
        return errbuf_set(err, errsz, DRACOB_EDECODE,
                    "malformed Draco buffer (the decoder ran out of memory)");
    } catch (...) {
        return errbuf_set(err, errsz, DRACOB_EDECODE, "malformed Draco buffer (decoder exception)");
    }
}

extern "C" int dracob_encode(const double *v, int nv, const int *f, int nf,
                             int quantization_bits, unsigned char **buf, size_t *len,
                             char *err, size_t errsz)
{
    if (!buf || !len)
        return errbuf_set(err, errsz, DRACOB_EARG, "dracob_encode: NULL output");
    *buf = nullptr;
    *len = 0;
    if (nv < 0 || nf < 0 || (nv > 0 && !v) || (nf > 0 && !f))
        return errbuf_set(err, errsz, DRACOB_EARG, "dracob_encode: bad sizes or NULL arrays");
    if (quantization_bits < 0 || quantization_bits > 30)
        return errbuf_set(err, errsz, DRACOB_EARG, "quantization of %d bits; expected 0..30",
                    quantization_bits);
    for (long long i = 0; i < 3LL * nf; i++)
        if (f[i] < 0 || f[i] >= nv)
            return errbuf_set(err, errsz, DRACOB_EARG, "face %lld: vertex index %d out of range [0, %d)",
                        i / 3, f[i], nv);
    /* quantization maps positions onto a grid over their bounding box: a
     * NaN or infinity has no place on it (Draco throws) */
    for (long long i = 0; quantization_bits > 0 && i < 3LL * nv; i++)
        if (!std::isfinite(v[i]))
            return errbuf_set(err, errsz, DRACOB_EARG,
                        "vertex %lld: %c coordinate is %s (a %d-bit quantized encoding needs finite positions)",
                        i / 3, "xyz"[i % 3], std::isnan(v[i]) ? "NaN" : "infinite", quantization_bits);
    try {
        return encode(v, nv, f, nf, quantization_bits, buf, len, err, errsz);
    } catch (const std::bad_alloc &) {
        return errbuf_set(err, errsz, DRACOB_ENOMEM, "out of memory while encoding");
    } catch (...) {
        return errbuf_set(err, errsz, DRACOB_EENCODE, "Draco encoder exception");
    }
}

// Draco .drc reader and writer on Draco's own library (draco::Encoder / draco::Decoder), plus
// the encode/decode helpers the glTF reader and writer use for KHR_draco_mesh_compression.
// Settings mirror Debian's draco_encoder (speed = 10 - level for both encoder and decoder
// speed, quantization per attribute) so the output matches it byte for byte on the same mesh.
#include "io/draco.hpp"

#include "io/error.hpp"
#include "io/text_number.hpp"

#include <draco/attributes/attribute_quantization_transform.h>
#include <draco/compression/config/compression_shared.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/compression/point_cloud/point_cloud_decoder.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/encoder_buffer.h>
#include <draco/core/quantization_utils.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace meshstream::io {
namespace {

constexpr char kMagic[5] = {'D', 'R', 'A', 'C', 'O'};

// Adds a float32 × 3 per-vertex attribute with identity mapping and copies `values` into it.
int add_float3_attribute(draco::Mesh& mesh, draco::GeometryAttribute::Type type, const std::vector<float>& values) {
    draco::GeometryAttribute ga;
    ga.Init(type, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
    int id = mesh.AddAttribute(ga, true, static_cast<uint32_t>(values.size() / 3));
    mesh.attribute(id)->buffer()->Write(0, values.data(), values.size() * sizeof(float));
    return id;
}

// The dequantized value Draco's decoder yields for `value` on axis `axis` (quantization is
// monotonic, so this maps the input's max to the decoded max exactly).
float draco_roundtrip(float value, const draco::AttributeQuantizationTransform& q, int axis) {
    const int32_t max_q = (1 << q.quantization_bits()) - 1;
    draco::Quantizer quantizer;
    quantizer.Init(q.range(), max_q);
    draco::Dequantizer dequantizer;
    dequantizer.Init(q.range(), max_q);
    return dequantizer.DequantizeFloat(quantizer.QuantizeFloat(value - q.min_value(axis))) + q.min_value(axis);
}

// Writer: indexes the soup, encodes at finish().
class DracoWriter final : public Writer {
    static constexpr const char* kWhy = "Draco encodes the whole mesh in memory";

public:
    DracoWriter(ByteSink& sink, const WriteOptions& options)
        : sink_(sink), options_(options), indexer_(sink.name()) {
        check_draco_settings(sink.name(), options);
        budget_check_up_front(sink.name(), options, kWhy, draco_encode_estimate_bytes);
    }

    void write_chunk(const TriangleChunk& chunk) override {
        indexer_.add(chunk);
        budget_check(sink_.name(), options_, kWhy, indexer_.input_triangle_count(),
                     draco_encode_estimate_bytes(indexer_.vertex_count(), indexer_.triangle_count(), options_));
    }

    void finish_output() override {
        IndexedMesh mesh = indexer_.take();
        std::vector<float> normals;
        if (options_.normals) normals = mesh.smooth_normals();
        DracoEncoded encoded = encode_draco(mesh, options_.normals ? &normals : nullptr, options_, sink_.name());
        sink_.write(encoded.bytes.data(), encoded.bytes.size());
        note_ = draco_flattened_note(encoded, mesh.triangle_count(), options_);
    }
    std::vector<std::string> notes() const override {
        return note_.empty() ? std::vector<std::string>{} : std::vector<std::string>{sink_.name() + ": " + note_};
    }

private:
    std::string note_;
    ByteSink& sink_;
    WriteOptions options_;
    MeshIndexer indexer_;
};

// Reader: decodes the whole file at open, then hands out chunks.
class DracoReader final : public Reader {
public:
    DracoReader(ByteSource& source, const ReadOptions& options) : source_(source) {
        std::vector<std::byte> bytes;
        std::byte buf[1 << 16];
        while (size_t n = source.read(buf, sizeof buf)) {
            bytes.insert(bytes.end(), buf, buf + n);
            if (bytes.size() > options.memory_budget_bytes)
                throw Error(source.name(), "Draco decodes whole files in memory and this one is over the memory budget of " +
                                               binary_size(options.memory_budget_bytes) + "; raise --memory");
        }
        mesh_ = decode_draco(bytes, source.name());
        header_.triangle_count = mesh_.indices.size() / 3;
        header_.vertex_count = mesh_.positions.size() / 3;
        header_.variant = mesh_.edgebreaker ? "edgebreaker" : "sequential";
        header_.notes.emplace_back("draco", "bitstream " + std::to_string(mesh_.version_major) + "." +
                                                std::to_string(mesh_.version_minor) + ", " + header_.variant +
                                                " connectivity");
        header_.notes.emplace_back("draco_qp", mesh_.position_bits ? std::to_string(mesh_.position_bits) + " bits"
                                                                   : std::string("not quantized"));
        std::string attrs = "position";
        if (mesh_.normals) attrs += ", normal";
        if (mesh_.colors) attrs += ", color";
        if (mesh_.texcoords) attrs += ", texcoord";
        header_.notes.emplace_back("attributes", attrs);
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        const size_t count = mesh_.indices.size() / 3;
        while (next_ < count && !chunk.full()) {
            float* dst = chunk.push_slot();
            for (int k = 0; k < 3; ++k)
                std::memcpy(dst + 3 * k, &mesh_.positions[3 * size_t{mesh_.indices[3 * next_ + k]}], 3 * sizeof(float));
            ++next_;
        }
        return !chunk.empty();
    }

private:
    ByteSource& source_;
    DracoDecoded mesh_;
    size_t next_ = 0;
};

std::unique_ptr<Reader> open_draco_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<DracoReader>(source, options);
}

std::unique_ptr<Writer> open_draco_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<DracoWriter>(sink, options);
}

}  // namespace

const Format kDracoFormat = {
    "draco", "drc", "Draco compressed mesh (whole mesh in memory)", &probe_draco, &open_draco_reader, &open_draco_writer,
    Format::kAlwaysDraco,
};

bool probe_draco(std::span<const std::byte> head, std::optional<uint64_t>) {
    return head.size() >= 5 && std::memcmp(head.data(), kMagic, 5) == 0;
}

namespace {

// Peak RSS of Draco 1.5.5's entropy coding tables, measured (bench/web.sh's inputs, qp and qn
// 22-29): about 4 bytes per quantized value of positions (levels 0-8; 11 at levels 9 and 10,
// more than twice that at 30 bits) and of normals, for meshes past a few thousand vertices.
uint64_t draco_table_bytes(const WriteOptions& options) {
    const uint64_t per_value = options.draco_level < 9 ? 4 : options.draco_position_bits < 30 ? 12 : 24;
    return per_value * (uint64_t{1} << options.draco_position_bits) +
           (options.normals ? 4 * (uint64_t{1} << options.draco_normal_bits) : 0);
}

}  // namespace

uint64_t draco_encode_estimate_bytes(uint64_t vertex_count, uint64_t triangle_count, const WriteOptions& options) {
    // Peak RSS growth, measured on a 1 M-triangle soup of separate triangles (3 M vertices) and
    // closed 1 M and 2 M-triangle meshes (half as many vertices), Draco 1.5.5, level 7, fitted
    // and rounded up: the index tables and Draco's mesh copy and corner table per vertex and
    // per triangle; smooth normals add the area-weighted sums and Draco's normal attribute.
    return vertex_count * (96 + (options.normals ? 88 : 0)) + triangle_count * 76 + draco_table_bytes(options);
}

void check_draco_settings(const std::string& file, const WriteOptions& options) {
    if (options.draco_position_bits < 1 || options.draco_position_bits > 30)
        throw Error(file, "--draco-qp must be 1-30, got " + std::to_string(options.draco_position_bits));
    if (options.draco_normal_bits < 2 || options.draco_normal_bits > 30)
        throw Error(file, "--draco-qn must be 2-30, got " + std::to_string(options.draco_normal_bits));
    if (options.draco_level < 0 || options.draco_level > 10)
        throw Error(file, "--draco-cl must be 0-10, got " + std::to_string(options.draco_level));
    const uint64_t tables = draco_table_bytes(options);
    if (tables <= options.memory_budget_bytes) return;
    throw Error(file, "Draco's coding tables for --draco-qp " + std::to_string(options.draco_position_bits) +
                          (options.normals ? " and --draco-qn " + std::to_string(options.draco_normal_bits) : "") +
                          " at --draco-cl " + std::to_string(options.draco_level) + " take about " +
                          binary_size(tables) + " (they double with each bit), over the memory budget of " +
                          binary_size(options.memory_budget_bytes) +
                          ": give fewer bits (float positions hold 24) or --memory " +
                          std::to_string((tables >> 20) + 1) + "M or more");
}

DracoEncoded encode_draco(const IndexedMesh& mesh, const std::vector<float>* normals, const WriteOptions& options,
                          const std::string& file_name) {
    if (mesh.triangle_count() == 0)
        throw Error(file_name, "no triangles to write: Draco cannot encode an empty mesh");
    {
        // Draco quantizes positions with a float step of range / (2^bits − 1), the range being
        // the largest extent in float; it overflows for boxes wider than the largest float
        // (libdraco then crashed) and its inverse overflows for tiny boxes (every vertex then
        // decoded to one point far away). Refused, as Draco's own encoder cannot do them.
        const Bounds box = mesh.bounds();
        float range = 0;
        for (int a = 0; a < 3; ++a) range = std::max(range, box.max[a] - box.min[a]);
        const float max_q = float((uint32_t{1} << options.draco_position_bits) - 1);
        if (!std::isfinite(range))
            throw Error(file_name, "the mesh is wider along an axis than a float can hold (3.4e38): Draco cannot "
                                   "quantize it; write it without Draco (--no-draco for glTF, or another format)");
        if (range > 0 && !std::isfinite(max_q / range)) {
            std::string extent;
            append_number(extent, range);
            throw Error(file_name, "the mesh is too small for Draco's " + std::to_string(options.draco_position_bits) +
                                       "-bit quantization (largest extent " + extent +
                                       "): write it with fewer --draco-qp bits, or without Draco");
        }
    }
    draco::Mesh dm;
    dm.set_num_points(static_cast<uint32_t>(mesh.vertex_count()));
    int pos_att = add_float3_attribute(dm, draco::GeometryAttribute::POSITION, mesh.positions);
    int nrm_att = -1;
    if (normals) nrm_att = add_float3_attribute(dm, draco::GeometryAttribute::NORMAL, *normals);
    dm.SetNumFaces(mesh.triangle_count());
    for (size_t f = 0; f < mesh.triangle_count(); ++f) {
        draco::Mesh::Face face = {draco::PointIndex(mesh.indices[3 * f]), draco::PointIndex(mesh.indices[3 * f + 1]),
                                  draco::PointIndex(mesh.indices[3 * f + 2])};
        dm.SetFace(draco::FaceIndex(static_cast<uint32_t>(f)), face);
    }

    draco::Encoder encoder;
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, options.draco_position_bits);
    if (normals) encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, options.draco_normal_bits);
    const int speed = 10 - options.draco_level;
    encoder.SetSpeedOptions(speed, speed);
    encoder.SetTrackEncodedProperties(true);
    draco::EncoderBuffer buffer;
    draco::Status status = encoder.EncodeMeshToBuffer(dm, &buffer);
    if (!status.ok()) throw Error(file_name, "Draco encoding failed: " + status.error_msg_string());

    DracoEncoded out;
    out.bytes = std::move(*buffer.buffer());
    out.point_count = encoder.num_encoded_points();
    out.face_count = encoder.num_encoded_faces();
    out.position_id = static_cast<int>(dm.attribute(pos_att)->unique_id());
    if (nrm_att >= 0) out.normal_id = static_cast<int>(dm.attribute(nrm_att)->unique_id());
    // The decoded positions' bounds, computed with Draco's own quantizer on the input bounds.
    draco::AttributeQuantizationTransform q;
    if (!q.ComputeParameters(*dm.attribute(pos_att), options.draco_position_bits))
        throw Error(file_name, "Draco rejected the position quantization settings");
    Bounds in = mesh.bounds();
    for (int a = 0; a < 3; ++a) {
        out.decoded_bounds.min[a] = draco_roundtrip(in.min[a], q, a);
        out.decoded_bounds.max[a] = draco_roundtrip(in.max[a], q, a);
    }
    // Triangles the quantization flattens: a part thinner than the step (a 2 cm cable in a 1 km
    // box at 14 bits) decodes to zero-area triangles and renders as nothing, within the
    // documented error bound but worth saying.
    std::vector<float> decoded(mesh.positions.size());
    for (size_t i = 0; i < decoded.size(); ++i) decoded[i] = draco_roundtrip(mesh.positions[i], q, int(i % 3));
    auto zero_area = [](const std::vector<float>& p, const uint32_t* t) {
        double e1[3], e2[3];
        for (int a = 0; a < 3; ++a) {
            e1[a] = double(p[3 * size_t{t[1]} + a]) - p[3 * size_t{t[0]} + a];
            e2[a] = double(p[3 * size_t{t[2]} + a]) - p[3 * size_t{t[0]} + a];
        }
        return e1[1] * e2[2] - e1[2] * e2[1] == 0 && e1[2] * e2[0] - e1[0] * e2[2] == 0 &&
               e1[0] * e2[1] - e1[1] * e2[0] == 0;
    };
    for (size_t f = 0; f < mesh.triangle_count(); ++f)
        out.flattened += zero_area(decoded, &mesh.indices[3 * f]) && !zero_area(mesh.positions, &mesh.indices[3 * f]);
    return out;
}

std::string draco_flattened_note(const DracoEncoded& encoded, uint64_t triangles, const WriteOptions& options) {
    if (encoded.flattened == 0) return {};
    return std::to_string(encoded.flattened) + " of the " + std::to_string(triangles) +
           " triangles have zero area once decoded: thinner than Draco's " +
           std::to_string(options.draco_position_bits) +
           "-bit quantization step (the largest extent / (2^bits - 1)); raise --draco-qp, or write without Draco";
}

DracoDecoded decode_draco(std::span<const std::byte> bytes, const std::string& file_name, uint64_t base_offset,
                          int position_id) {
    DracoDecoded out;
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (!bytes.empty() && bytes.size() < 5 && std::memcmp(bytes.data(), kMagic, bytes.size()) == 0)
        throw Error(file_name, base_offset + bytes.size(), 0, "bitstream ends inside its 5-byte magic 'DRACO'");
    if (bytes.size() < 5 || std::memcmp(bytes.data(), kMagic, 5) != 0)
        throw Error(file_name, base_offset, 0, "not a Draco bitstream (expected magic 'DRACO', found " +
                                                   quote_token({reinterpret_cast<const char*>(bytes.data()),
                                                                std::min<size_t>(bytes.size(), 5)}) + ")");
    draco::DracoHeader header;
    {
        draco::DecoderBuffer header_buffer;
        header_buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
        draco::Status st = draco::PointCloudDecoder::DecodeHeader(&header_buffer, &header);
        if (!st.ok()) throw Error(file_name, base_offset, 0, "bad Draco header: " + st.error_msg_string());
    }
    out.version_major = header.version_major;
    out.version_minor = header.version_minor;
    out.edgebreaker = header.encoder_method == draco::MESH_EDGEBREAKER_ENCODING;
    if (header.encoder_type == draco::POINT_CLOUD)
        throw Error(file_name, base_offset + 7, 0,
                    "geometry type is a Draco point cloud (no faces); meshstream reads triangle meshes only");
    if (header.encoder_type != draco::TRIANGULAR_MESH)
        throw Error(file_name, base_offset + 7, 0,
                    "unknown Draco geometry type " + std::to_string(int(header.encoder_type)));

    draco::Decoder decoder;
    // Keep positions quantized so the quantization bits can be read back; dequantized below
    // with Draco's own inverse transform (bit-identical to a plain decode).
    decoder.SetSkipAttributeTransform(draco::GeometryAttribute::POSITION);
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok())
        throw Error(file_name, base_offset, 0, "Draco decoding failed: " + decoded.status().error_msg_string());
    std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();

    const draco::PointAttribute* pos = position_id >= 0 ? mesh->GetAttributeByUniqueId(static_cast<uint32_t>(position_id))
                                                        : mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION);
    if (!pos)
        throw Error(file_name, base_offset, 0,
                    position_id >= 0 ? "Draco data has no attribute with id " + std::to_string(position_id)
                                     : std::string("Draco mesh has no position attribute"));
    if (pos->num_components() < 3)
        throw Error(file_name, base_offset, 0,
                    "Draco positions have " + std::to_string(int(pos->num_components())) + " components, need 3");
    out.normals = mesh->GetNamedAttribute(draco::GeometryAttribute::NORMAL) != nullptr;
    out.colors = mesh->GetNamedAttribute(draco::GeometryAttribute::COLOR) != nullptr;
    out.texcoords = mesh->GetNamedAttribute(draco::GeometryAttribute::TEX_COORD) != nullptr;

    // Dequantize into `values` (one float3 per attribute value) when positions are quantized.
    std::unique_ptr<draco::PointAttribute> dequantized;
    const draco::PointAttribute* values = pos;
    if (pos->GetAttributeTransformData() &&
        pos->GetAttributeTransformData()->transform_type() == draco::ATTRIBUTE_QUANTIZATION_TRANSFORM) {
        draco::AttributeQuantizationTransform q;
        if (!q.InitFromAttribute(*pos)) throw Error(file_name, base_offset, 0, "bad Draco quantization data");
        out.position_bits = q.quantization_bits();
        dequantized = std::make_unique<draco::PointAttribute>();
        dequantized->Init(draco::GeometryAttribute::POSITION, pos->num_components(), draco::DT_FLOAT32, false, pos->size());
        if (!q.InverseTransformAttribute(*pos, dequantized.get()))
            throw Error(file_name, base_offset, 0, "Draco position dequantization failed");
        values = dequantized.get();
    }

    const uint32_t points = mesh->num_points();
    out.positions.resize(size_t{points} * 3);
    for (uint32_t p = 0; p < points; ++p) {
        draco::AttributeValueIndex avi = pos->mapped_index(draco::PointIndex(p));
        float v[4] = {0, 0, 0, 0};
        if (avi.value() >= values->size() || !values->ConvertValue<float>(avi, 3, v))
            throw Error(file_name, base_offset, 0, "Draco position of point " + std::to_string(p) + " is unreadable");
        std::memcpy(&out.positions[3 * size_t{p}], v, 3 * sizeof(float));
    }
    out.indices.resize(size_t{mesh->num_faces()} * 3);
    for (uint32_t f = 0; f < mesh->num_faces(); ++f) {
        const auto& face = mesh->face(draco::FaceIndex(f));
        for (int k = 0; k < 3; ++k) {
            uint32_t v = face[k].value();
            if (v >= points)
                throw Error(file_name, base_offset, 0, "Draco face " + std::to_string(f) + " references point " +
                                                           std::to_string(v) + " of " + std::to_string(points));
            out.indices[3 * size_t{f} + k] = v;
        }
    }
    return out;
}

}  // namespace meshstream::io

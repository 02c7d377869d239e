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
#include <draco/metadata/geometry_metadata.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace meshstream::io {
namespace {

constexpr char kMagic[5] = {'D', 'R', 'A', 'C', 'O'};

draco::DataType draco_type(ScalarType type) {
    switch (type) {
        case ScalarType::kInt8: return draco::DT_INT8;
        case ScalarType::kUInt8: return draco::DT_UINT8;
        case ScalarType::kInt16: return draco::DT_INT16;
        case ScalarType::kUInt16: return draco::DT_UINT16;
        case ScalarType::kInt32: return draco::DT_INT32;
        case ScalarType::kUInt32: return draco::DT_UINT32;
        case ScalarType::kFloat32:
        case ScalarType::kFloat64: return draco::DT_FLOAT32;  // Draco quantizes float32 only
    }
    return draco::DT_FLOAT32;
}

// A value converted to `T`, rounded and clamped to its range (integers) or as it is (float).
template <class T>
T to_component(double v) {
    if constexpr (std::is_floating_point_v<T>) {
        return static_cast<T>(v);
    } else {
        const double r = std::nearbyint(v);
        if (!(r >= double(std::numeric_limits<T>::min()))) return std::numeric_limits<T>::min();
        if (r >= double(std::numeric_limits<T>::max())) return std::numeric_limits<T>::max();
        return static_cast<T>(r);
    }
}

// Adds a per-vertex attribute (identity mapping) of `components` values of `type` per vertex,
// from `values` (components per vertex, each times `scale`). Returns its attribute id.
template <class V>
int add_attribute(draco::Mesh& mesh, draco::GeometryAttribute::Type kind, int components, draco::DataType type,
                  bool normalized, std::span<const V> values, double scale = 1.0) {
    const size_t bytes = draco::DataTypeLength(type);
    draco::GeometryAttribute ga;
    ga.Init(kind, nullptr, static_cast<uint8_t>(components), type, normalized, int64_t(bytes * components), 0);
    const uint32_t n = static_cast<uint32_t>(values.size() / size_t(components));
    const int id = mesh.AddAttribute(ga, true, n);
    std::vector<uint8_t> raw(size_t(components) * bytes);
    for (uint32_t v = 0; v < n; ++v) {
        for (int c = 0; c < components; ++c) {
            const double x = double(values[size_t{v} * components + c]) * scale;
            uint8_t* dst = &raw[size_t(c) * bytes];
            switch (type) {
                case draco::DT_INT8: {
                    int8_t y = to_component<int8_t>(x);
                    std::memcpy(dst, &y, 1);
                    break;
                }
                case draco::DT_UINT8: {
                    uint8_t y = to_component<uint8_t>(x);
                    std::memcpy(dst, &y, 1);
                    break;
                }
                case draco::DT_INT16: {
                    int16_t y = to_component<int16_t>(x);
                    std::memcpy(dst, &y, 2);
                    break;
                }
                case draco::DT_UINT16: {
                    uint16_t y = to_component<uint16_t>(x);
                    std::memcpy(dst, &y, 2);
                    break;
                }
                case draco::DT_INT32: {
                    int32_t y = to_component<int32_t>(x);
                    std::memcpy(dst, &y, 4);
                    break;
                }
                case draco::DT_UINT32: {
                    uint32_t y = to_component<uint32_t>(x);
                    std::memcpy(dst, &y, 4);
                    break;
                }
                default: {
                    float y = to_component<float>(x);
                    std::memcpy(dst, &y, 4);
                    break;
                }
            }
        }
        mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(v), raw.data());
    }
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
        : sink_(sink),
          options_(options),
          indexer_(sink.name(), "Draco", options.channels, options.strict),
          settings_(check_draco_settings(sink.name(), options)),
          budget_(sink.name(), options, kWhy) {
        budget_check_up_front(sink.name(), options, kWhy, draco_encode_estimate_bytes);
    }

    void write_chunk(const TriangleChunk& chunk) override {
        if (budget_.counting()) return budget_.count(chunk.size());
        indexer_.add(chunk);
        if (budget_.check(indexer_.input_triangle_count(),
                          draco_encode_estimate_bytes(indexer_.vertex_count(), indexer_.triangle_count(), options_)))
            indexer_ = MeshIndexer(sink_.name(), "Draco", options_.channels, options_.strict);  // frees the tables
    }

    void finish_output() override {
        if (budget_.counting()) budget_.fail();
        IndexedMesh mesh = indexer_.take();
        if (options_.strict)
            if (const int64_t t = first_repeated_vertex(mesh.indices); t >= 0)
                throw Error(sink_.name(), "triangle " + std::to_string(t) +
                                              " has two corners at one vertex, which "
                                              "Draco's encoder drops (" + mention(Setting::kStrict) + ")");
        std::vector<uint32_t> all(mesh.vertex_count());
        std::iota(all.begin(), all.end(), 0u);
        VertexValues values = mesh.values(all);
        all = std::vector<uint32_t>();
        Channels channels = mesh.channels;
        if (options_.normals && !channels.normal && mesh.triangle_count() > 0) {
            std::vector<float> normals = mesh.smooth_normals();
            values.normals = std::move(normals);
            channels.normal = true;
        }
        DracoEncoded encoded = encode_draco(mesh.positions, mesh.indices, values, channels, settings_, sink_.name());
        sink_.write(encoded.bytes.data(), encoded.bytes.size());
        notes_ = indexer_.notes();
        for (std::string& note : draco_notes(encoded, mesh.triangle_count(), settings_))
            notes_.push_back(std::move(note));
    }
    std::vector<std::string> format_notes() const override {
        std::vector<std::string> out;
        for (const std::string& note : notes_) out.push_back(sink_.name() + ": " + note);
        return out;
    }

private:
    std::vector<std::string> notes_;
    ByteSink& sink_;
    WriteOptions options_;
    MeshIndexer indexer_;
    DracoSettings settings_;
    WholeMeshBudget budget_;
};

const char* kind_name(DracoAttribute::Kind kind) {
    switch (kind) {
        case DracoAttribute::kNormal: return "normal";
        case DracoAttribute::kColor: return "color";
        case DracoAttribute::kTexCoord: return "texcoord";
        case DracoAttribute::kGeneric: return "generic";
        case DracoAttribute::kOther: return "other";
    }
    return "?";
}

// Reader: decodes the whole file at open, then hands out chunks.
class DracoReader final : public Reader {
public:
    DracoReader(ByteSource& source, const ReadOptions& options) {
        std::vector<std::byte> bytes;
        std::byte buf[1 << 16];
        while (size_t n = source.read(buf, sizeof buf)) {
            bytes.insert(bytes.end(), buf, buf + n);
            if (bytes.size() > options.memory_budget_bytes)
                throw Error(source.name(),
                            "Draco decodes whole files in memory and this one is over the memory budget of " +
                                binary_size(options.memory_budget_bytes) + "; raise " + mention(Setting::kMemory));
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
        // The channels: the first normal and colour attribute, up to kMaxUvSets texture
        // coordinate sets, every component of every generic attribute as a scalar.
        Channels& ch = header_.channels;
        ch.vertex_id = true;
        std::string attrs = "position", ignored;
        for (size_t a = 0; a < mesh_.attributes.size(); ++a) {
            const DracoAttribute& att = mesh_.attributes[a];
            std::string label = kind_name(att.kind);
            if (!att.name.empty()) label += " '" + att.name + "'";
            attrs += ", " + label;
            if (att.kind == DracoAttribute::kNormal && normal_ < 0 && att.components == 3) {
                normal_ = int(a);
                ch.normal = true;
            } else if (att.kind == DracoAttribute::kColor && color_ < 0 &&
                       (att.components == 3 || att.components == 4)) {
                color_ = int(a);
                ColorFormat f;
                f.type = att.type == ScalarType::kUInt8    ? ScalarType::kUInt8
                         : att.type == ScalarType::kUInt16 ? ScalarType::kUInt16
                                                           : ScalarType::kFloat32;
                f.alpha = att.components == 4;
                ch.color = f;
            } else if (att.kind == DracoAttribute::kTexCoord && ch.uv_sets < kMaxUvSets && att.components == 2) {
                uvs_.push_back(int(a));
                ch.uv_sets++;
            } else if (att.kind == DracoAttribute::kGeneric) {
                const std::string base = att.name.empty() ? "generic" + std::to_string(att.unique_id) : att.name;
                for (int c = 0; c < att.components; ++c) {
                    ch.vertex_scalars.push_back(
                        {att.components == 1 ? base : base + "_" + std::to_string(c), att.type});
                    scalars_.push_back({int(a), c});
                }
            } else {
                ignored += (ignored.empty() ? "" : ", ") + label;
            }
        }
        header_.notes.emplace_back("attributes", attrs);
        if (!ignored.empty()) header_.notes.emplace_back("not read", ignored);
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        const Channels& want = chunk.channels();
        const size_t count = mesh_.indices.size() / 3;
        // The chunk's scalar channels, by name, among this file's (-1: not here).
        std::vector<int> scalar_map;
        for (const ScalarChannel& s : want.vertex_scalars) {
            const auto& have = header_.channels.vertex_scalars;
            auto it = std::find_if(have.begin(), have.end(), [&](const ScalarChannel& h) { return h.name == s.name; });
            scalar_map.push_back(it == have.end() ? -1 : int(it - have.begin()));
        }
        while (next_ < count && !chunk.full()) {
            const size_t i = chunk.size();
            float* dst = chunk.push_slot();
            for (int k = 0; k < 3; ++k) {
                const uint32_t p = mesh_.indices[3 * next_ + k];
                std::memcpy(dst + 3 * k, &mesh_.positions[3 * size_t{p}], 3 * sizeof(float));
                if (want.vertex_id) chunk.id_at(i)[k] = p;
                if (want.normal && normal_ >= 0)
                    for (int c = 0; c < 3; ++c) chunk.normal_at(i)[3 * k + c] = float(value(normal_, p, c));
                if (want.color && color_ >= 0) {
                    const DracoAttribute& att = mesh_.attributes[color_];
                    for (int c = 0; c < att.components; ++c) chunk.color_at(i)[4 * k + c] = float(value(color_, p, c));
                }
                for (int s = 0; s < std::min<int>(want.uv_sets, int(uvs_.size())); ++s)
                    for (int c = 0; c < 2; ++c) chunk.uv_at(i, s)[2 * k + c] = float(value(uvs_[s], p, c));
                for (size_t c = 0; c < scalar_map.size(); ++c)
                    if (scalar_map[c] >= 0)
                        chunk.vertex_scalar_at(i, c)[k] =
                            value(scalars_[scalar_map[c]].first, p, scalars_[scalar_map[c]].second);
            }
            ++next_;
        }
        return !chunk.empty();
    }

private:
    double value(int attribute, uint32_t point, int component) const {
        const DracoAttribute& att = mesh_.attributes[attribute];
        return att.values[size_t{point} * att.components + component];
    }

    DracoDecoded mesh_;
    int normal_ = -1, color_ = -1;
    std::vector<int> uvs_;
    std::vector<std::pair<int, int>> scalars_;  // (attribute, component) per vertex scalar channel
    size_t next_ = 0;
};

std::unique_ptr<Reader> open_draco_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<DracoReader>(source, options);
}

std::unique_ptr<Writer> open_draco_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<DracoWriter>(sink, options);
}

Channels drc_keep_channels(const Channels& in, const WriteOptions& options) {
    return draco_keep_channels(in, options, false);
}

// Draco's connectivity coder puts the triangles in an order of its own.
std::string drc_reorders_triangles(const WriteOptions&) { return "Draco compression reorders triangles"; }

bool drc_takes_options(const std::type_info& type, const WriteOptions&) { return type == typeid(DracoSettings); }

}  // namespace

const Format kDracoFormat = {
    .name = "draco",
    .extensions = "drc",
    .description = "Draco compressed mesh (whole mesh in memory)",
    .probe = &probe_draco,
    .open_reader = &open_draco_reader,
    .open_writer = &open_draco_writer,
    .traits = Format::kWholeMesh,
    .keep_channels = &drc_keep_channels,
    .reorders_triangles = &drc_reorders_triangles,
    .takes_options = &drc_takes_options,
};

bool probe_draco(std::span<const std::byte> head, std::optional<uint64_t>) {
    return head.size() >= 5 && std::memcmp(head.data(), kMagic, 5) == 0;
}

Channels draco_keep_channels(const Channels& in, const WriteOptions&, bool gltf) {
    Channels out;
    out.normal = in.normal;
    out.color = in.color;
    out.uv_sets = in.uv_sets;
    if (!gltf) out.vertex_scalars = in.vertex_scalars;
    out.vertex_id = in.vertex_id;
    return out;
}

namespace {

// Peak RSS of Draco 1.5.5's entropy coding tables, measured (bench/web.sh's inputs, qp and qn
// 22-29): about 4 bytes per quantized value of positions (levels 0-8; 11 at levels 9 and 10,
// more than twice that at 30 bits) and of normals, for meshes past a few thousand vertices.
// Texture coordinates, float colours and generic attributes are quantized the same way.
uint64_t draco_table_bytes(const WriteOptions& options, const DracoSettings& settings) {
    const uint64_t per_value = settings.level < 9 ? 4 : settings.position_bits < 30 ? 12 : 24;
    const Channels& ch = options.channels;
    const bool float_colors = ch.color && ch.color->type == ScalarType::kFloat32;
    const bool float_scalars = std::any_of(
        ch.vertex_scalars.begin(), ch.vertex_scalars.end(),
        [](const ScalarChannel& s) { return s.type == ScalarType::kFloat32 || s.type == ScalarType::kFloat64; });
    return per_value * (uint64_t{1} << settings.position_bits) +
           (options.normals || ch.normal ? 4 * (uint64_t{1} << settings.normal_bits) : 0) +
           (ch.uv_sets > 0 ? 4 * (uint64_t{1} << settings.texcoord_bits) : 0) +
           (float_colors || float_scalars ? 4 * (uint64_t{1} << settings.color_bits) : 0);
}

}  // namespace

uint64_t draco_encode_estimate_bytes(uint64_t vertex_count, uint64_t triangle_count, const WriteOptions& options) {
    // Peak RSS growth, measured on a 1 M-triangle soup of separate triangles (3 M vertices) and
    // closed 1 M and 2 M-triangle meshes (half as many vertices), Draco 1.5.5, level 7, fitted
    // and rounded up: the index tables and Draco's mesh copy and corner table per vertex and
    // per triangle; smooth normals add the area-weighted sums and Draco's normal attribute.
    // Other attributes: the indexer's record, the unpacked values (up to twice the record, as
    // float or double) and Draco's copy of them, so about four records a vertex.
    const bool normals = options.normals || options.channels.normal;
    return vertex_count * (96 + (normals ? 88 : 0) + 4 * uint64_t(CornerLayout(options.channels).bytes())) +
           triangle_count * (76 + (options.channels.material ? 4 : 0)) +
           draco_table_bytes(options, options.format_options.get<DracoSettings>());
}

DracoSettings check_draco_settings(const std::string& file, const WriteOptions& options) {
    const DracoSettings s = options.format_options.get<DracoSettings>();
    auto check = [&](int value, int low, int high, Setting setting) {
        if (value < low || value > high)
            throw OptionError(setting, file + ": " + mention(setting) + " must be " + std::to_string(low) + "-" +
                                           std::to_string(high) + ", got " + std::to_string(value));
    };
    check(s.position_bits, 1, 30, Setting::kDracoPositionBits);
    check(s.normal_bits, 2, 30, Setting::kDracoNormalBits);
    check(s.texcoord_bits, 1, 30, Setting::kDracoTexcoordBits);
    check(s.color_bits, 1, 30, Setting::kDracoColorBits);
    check(s.level, 0, 10, Setting::kDracoLevel);
    const uint64_t tables = draco_table_bytes(options, s);
    if (tables <= options.memory_budget_bytes) return s;
    throw Error(
        file,
        "Draco's coding tables for " + mention(Setting::kDracoPositionBits) + " " + std::to_string(s.position_bits) +
            (options.normals || options.channels.normal
                 ? " and " + mention(Setting::kDracoNormalBits) + " " + std::to_string(s.normal_bits)
                 : "") +
            " at " + mention(Setting::kDracoLevel) + " " + std::to_string(s.level) + " take about " +
            binary_size(tables) +
            " (they double with each bit), over the memory budget of " + binary_size(options.memory_budget_bytes) +
            ": give fewer bits (float positions hold 24) or " + mention(Setting::kMemory) + " " +
            std::to_string((tables >> 20) + 1) +
            "M or more");
}

int64_t first_repeated_vertex(const std::vector<uint32_t>& indices) {
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        if (indices[t] == indices[t + 1] || indices[t + 1] == indices[t + 2] || indices[t] == indices[t + 2])
            return int64_t(t / 3);
    return -1;
}

DracoEncoded encode_draco(const std::vector<float>& input_positions, const std::vector<uint32_t>& indices,
                          const VertexValues& values, const Channels& channels, const DracoSettings& settings,
                          const std::string& file_name, bool flip_v, const DracoGrid* grid) {
    // On a grid, a position beyond it is moved onto its nearest side, as meshopt's quantizer
    // clamps (Draco's would wrap around).
    std::vector<float> clamped;  // a copy, once a position is moved
    if (grid != nullptr)
        for (size_t i = 0; i < input_positions.size(); ++i) {
            const float lo = grid->origin[i % 3], v = std::clamp(input_positions[i], lo, lo + grid->range);
            if (v != input_positions[i] && clamped.empty()) clamped = input_positions;
            if (!clamped.empty()) clamped[i] = v;
        }
    const std::vector<float>& positions = clamped.empty() ? input_positions : clamped;
    // Draco's encoder drops triangles with a repeated vertex: left out here, so they are counted.
    std::vector<uint32_t> kept;
    kept.reserve(indices.size());
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        if (indices[t] != indices[t + 1] && indices[t + 1] != indices[t + 2] && indices[t] != indices[t + 2])
            kept.insert(kept.end(), &indices[t], &indices[t] + 3);
    if (indices.empty()) throw Error(file_name, "no triangles to write: Draco cannot encode an empty mesh");
    if (kept.empty())
        throw Error(file_name, "every one of the " + std::to_string(indices.size() / 3) +
                                   " triangles has two corners at one vertex, which Draco's encoder drops: nothing to "
                                   "write (write it without Draco)");
    Bounds box;
    for (int a = 0; a < 3; ++a) box.min[a] = box.max[a] = positions[a];
    for (size_t i = 0; i < positions.size(); i += 3)
        for (int a = 0; a < 3; ++a) {
            box.min[a] = std::min(box.min[a], positions[i + a]);
            box.max[a] = std::max(box.max[a], positions[i + a]);
        }
    {
        // Draco quantizes positions with a float step of range / (2^bits − 1), the range being
        // the largest extent in float; it overflows for boxes wider than the largest float
        // (libdraco then crashed) and its inverse overflows for tiny boxes (every vertex then
        // decoded to one point far away). Refused, as Draco's own encoder cannot do them.
        float range = 0;
        for (int a = 0; a < 3; ++a) range = std::max(range, box.max[a] - box.min[a]);
        if (grid != nullptr) range = grid->range;
        const float max_q = float((uint32_t{1} << settings.position_bits) - 1);
        if (!std::isfinite(range))
            throw Error(file_name,
                        "the mesh is wider along an axis than a float can hold (3.4e38): Draco cannot "
                        "quantize it; write it without Draco (" + mention(Setting::kCompress) +
                            " none for glTF, or another format)");
        if (range > 0 && !std::isfinite(max_q / range)) {
            std::string extent;
            append_number(extent, range);
            throw Error(file_name, "the mesh is too small for Draco's " + std::to_string(settings.position_bits) +
                                       "-bit quantization (largest extent " + extent +
                                       "): write it with fewer " + mention(Setting::kDracoPositionBits) +
                                       " bits, or without Draco");
        }
    }
    const size_t n = positions.size() / 3;
    draco::Mesh dm;
    dm.set_num_points(static_cast<uint32_t>(n));
    const int pos_att = add_attribute(dm, draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32, false,
                                      std::span<const float>(positions));
    DracoEncoded out;
    std::vector<int> atts;  // attribute ids of what follows, to read back their unique ids
    int nrm_att = -1, col_att = -1;
    if (channels.normal)
        nrm_att = add_attribute(dm, draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32, false,
                                std::span<const float>(values.normals));
    if (channels.color) {
        const int comps = channels.color->alpha ? 4 : 3;
        const ScalarType t = channels.color->type;
        const double scale = t == ScalarType::kUInt8 ? 255.0 : t == ScalarType::kUInt16 ? 65535.0 : 1.0;
        std::vector<float> c(n * size_t(comps));  // RGBA to RGB or RGBA
        for (size_t v = 0; v < n; ++v)
            for (int k = 0; k < comps; ++k) c[v * comps + k] = values.colors[4 * v + k];
        col_att = add_attribute(dm, draco::GeometryAttribute::COLOR, comps, draco_type(t), t != ScalarType::kFloat32,
                                std::span<const float>(c), scale);
    }
    std::vector<int> uv_atts;
    for (int s = 0; s < channels.uv_sets; ++s) {
        std::vector<float> uv(values.uvs[s]);
        if (flip_v)
            for (size_t v = 0; v < n; ++v) uv[2 * v + 1] = 1.0f - uv[2 * v + 1];
        uv_atts.push_back(add_attribute(dm, draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32, false,
                                        std::span<const float>(uv)));
    }
    std::vector<int> generic_atts;
    for (size_t c = 0; c < channels.vertex_scalars.size(); ++c) {
        const int id =
            add_attribute(dm, draco::GeometryAttribute::GENERIC, 1, draco_type(channels.vertex_scalars[c].type), false,
                          std::span<const double>(values.scalars[c]));
        // Draco's tools name generic attributes by a "name" metadata entry.
        auto metadata = std::make_unique<draco::AttributeMetadata>();
        metadata->AddEntryString("name", channels.vertex_scalars[c].name);
        dm.AddAttributeMetadata(id, std::move(metadata));
        generic_atts.push_back(id);
    }
    dm.SetNumFaces(kept.size() / 3);
    for (size_t f = 0; f < kept.size() / 3; ++f) {
        draco::Mesh::Face face = {draco::PointIndex(kept[3 * f]), draco::PointIndex(kept[3 * f + 1]),
                                  draco::PointIndex(kept[3 * f + 2])};
        dm.SetFace(draco::FaceIndex(static_cast<uint32_t>(f)), face);
    }

    draco::Encoder encoder;
    if (grid != nullptr)
        encoder.SetAttributeExplicitQuantization(draco::GeometryAttribute::POSITION, settings.position_bits, 3,
                                                 grid->origin, grid->range);
    else
        encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, settings.position_bits);
    if (channels.normal) encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, settings.normal_bits);
    if (channels.uv_sets > 0)
        encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, settings.texcoord_bits);
    // Quantization applies to float attributes only: integer colours and scalars stay exact.
    if (channels.color) encoder.SetAttributeQuantization(draco::GeometryAttribute::COLOR, settings.color_bits);
    if (!channels.vertex_scalars.empty())
        encoder.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, settings.color_bits);
    const int speed = 10 - settings.level;
    encoder.SetSpeedOptions(speed, speed);
    encoder.SetTrackEncodedProperties(true);
    draco::EncoderBuffer buffer;
    draco::Status status = encoder.EncodeMeshToBuffer(dm, &buffer);
    if (!status.ok()) throw Error(file_name, "Draco encoding failed: " + status.error_msg_string());

    out.bytes = std::move(*buffer.buffer());
    out.point_count = encoder.num_encoded_points();
    out.face_count = encoder.num_encoded_faces();
    out.dropped = indices.size() / 3 - out.face_count;
    out.position_id = static_cast<int>(dm.attribute(pos_att)->unique_id());
    if (nrm_att >= 0) out.normal_id = static_cast<int>(dm.attribute(nrm_att)->unique_id());
    if (col_att >= 0) out.color_id = static_cast<int>(dm.attribute(col_att)->unique_id());
    for (int id : uv_atts) out.texcoord_ids.push_back(static_cast<int>(dm.attribute(id)->unique_id()));
    for (int id : generic_atts) out.generic_ids.push_back(static_cast<int>(dm.attribute(id)->unique_id()));
    // The decoded positions' bounds, computed with Draco's own quantizer on the input bounds.
    draco::AttributeQuantizationTransform q;
    if (grid != nullptr ? !q.SetParameters(settings.position_bits, grid->origin, 3, grid->range)
                        : !q.ComputeParameters(*dm.attribute(pos_att), settings.position_bits))
        throw Error(file_name, "Draco rejected the position quantization settings");
    for (int a = 0; a < 3; ++a) {
        out.decoded_bounds.min[a] = draco_roundtrip(box.min[a], q, a);
        out.decoded_bounds.max[a] = draco_roundtrip(box.max[a], q, a);
    }
    // Triangles the quantization flattens: a part thinner than the step (a 2 cm cable in a 1 km
    // box at 14 bits) decodes to zero-area triangles and renders as nothing, within the
    // documented error bound but worth saying.
    std::vector<float> decoded(positions.size());
    for (size_t i = 0; i < decoded.size(); ++i) decoded[i] = draco_roundtrip(positions[i], q, int(i % 3));
    auto zero_area = [](const std::vector<float>& p, const uint32_t* t) {
        double e1[3], e2[3];
        for (int a = 0; a < 3; ++a) {
            e1[a] = double(p[3 * size_t{t[1]} + a]) - p[3 * size_t{t[0]} + a];
            e2[a] = double(p[3 * size_t{t[2]} + a]) - p[3 * size_t{t[0]} + a];
        }
        return e1[1] * e2[2] - e1[2] * e2[1] == 0 && e1[2] * e2[0] - e1[0] * e2[2] == 0 &&
               e1[0] * e2[1] - e1[1] * e2[0] == 0;
    };
    for (size_t f = 0; f < kept.size() / 3; ++f)
        out.flattened += zero_area(decoded, &kept[3 * f]) && !zero_area(positions, &kept[3 * f]);
    out.on_grid = grid != nullptr;
    return out;
}

std::vector<std::string> draco_notes(const DracoEncoded& encoded, uint64_t triangles, const DracoSettings& settings) {
    std::vector<std::string> out;
    if (encoded.dropped)
        out.push_back(std::to_string(encoded.dropped) + " of the " + std::to_string(triangles) +
                      " triangles have two corners at one vertex (degenerate), which Draco's encoder drops: left out "
                      "(write without Draco to keep them; " + mention(Setting::kStrict) + " makes this an error)");
    if (encoded.flattened && encoded.on_grid)
        out.push_back(std::to_string(encoded.flattened) + " of the " + std::to_string(triangles) +
                      " triangles have zero area once decoded: thinner than the step of the " +
                      std::to_string(settings.position_bits) +
                      "-bit quantization grid they were written on (its extent / (2^bits - 1))");
    else if (encoded.flattened)
        out.push_back(std::to_string(encoded.flattened) + " of the " + std::to_string(triangles) +
                      " triangles have zero area once decoded: thinner than Draco's " +
                      std::to_string(settings.position_bits) +
                      "-bit quantization step (the largest extent / (2^bits - 1)); raise " +
                      mention(Setting::kDracoPositionBits) + ", or write without Draco");
    return out;
}

namespace {

ScalarType scalar_type_of(draco::DataType type) {
    switch (type) {
        case draco::DT_INT8: return ScalarType::kInt8;
        case draco::DT_UINT8: return ScalarType::kUInt8;
        case draco::DT_INT16: return ScalarType::kInt16;
        case draco::DT_UINT16: return ScalarType::kUInt16;
        case draco::DT_INT32: return ScalarType::kInt32;
        case draco::DT_UINT32: return ScalarType::kUInt32;
        case draco::DT_FLOAT64: return ScalarType::kFloat64;
        default: return ScalarType::kFloat32;
    }
}

// One stored component of type `type` at `p`, as a double.
double component_value(const uint8_t* p, draco::DataType type) {
    switch (type) {
        case draco::DT_INT8: return double(int8_t(p[0]));
        case draco::DT_UINT8: return double(p[0]);
        case draco::DT_INT16: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return v;
        }
        case draco::DT_UINT16: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return v;
        }
        case draco::DT_INT32: {
            int32_t v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case draco::DT_UINT32: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case draco::DT_FLOAT32: {
            float v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case draco::DT_FLOAT64: {
            double v;
            std::memcpy(&v, p, 8);
            return v;
        }
        default: return 0;
    }
}

}  // namespace

DracoDecoded decode_draco(std::span<const std::byte> bytes, const std::string& file_name, uint64_t base_offset,
                          int position_id) {
    DracoDecoded out;
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (!bytes.empty() && bytes.size() < 5 && std::memcmp(bytes.data(), kMagic, bytes.size()) == 0)
        throw Error(file_name, base_offset + bytes.size(), 0, "bitstream ends inside its 5-byte magic 'DRACO'");
    if (bytes.size() < 5 || std::memcmp(bytes.data(), kMagic, 5) != 0)
        throw Error(file_name, base_offset, 0,
                    "not a Draco bitstream (expected magic 'DRACO', found " +
                        quote_token({reinterpret_cast<const char*>(bytes.data()), std::min<size_t>(bytes.size(), 5)}) +
                        ")");
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

    const draco::PointAttribute* pos = position_id >= 0
                                           ? mesh->GetAttributeByUniqueId(static_cast<uint32_t>(position_id))
                                           : mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION);
    if (!pos)
        throw Error(file_name, base_offset, 0,
                    position_id >= 0 ? "Draco data has no attribute with id " + std::to_string(position_id)
                                     : std::string("Draco mesh has no position attribute"));
    if (pos->num_components() < 3)
        throw Error(file_name, base_offset, 0,
                    "Draco positions have " + std::to_string(int(pos->num_components())) + " components, need 3");

    // Dequantize into `values` (one float3 per attribute value) when positions are quantized.
    std::unique_ptr<draco::PointAttribute> dequantized;
    const draco::PointAttribute* values = pos;
    if (pos->GetAttributeTransformData() &&
        pos->GetAttributeTransformData()->transform_type() == draco::ATTRIBUTE_QUANTIZATION_TRANSFORM) {
        draco::AttributeQuantizationTransform q;
        if (!q.InitFromAttribute(*pos)) throw Error(file_name, base_offset, 0, "bad Draco quantization data");
        out.position_bits = q.quantization_bits();
        dequantized = std::make_unique<draco::PointAttribute>();
        dequantized->Init(draco::GeometryAttribute::POSITION, pos->num_components(), draco::DT_FLOAT32, false,
                          pos->size());
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

    // Every other attribute, per point. Integer colours are normalised (0..1) whether or not
    // the file flags them so: colours are fractions of their type's range by convention.
    for (int32_t a = 0; a < mesh->num_attributes(); ++a) {
        const draco::PointAttribute* att = mesh->attribute(a);
        if (att == pos) continue;
        DracoAttribute d;
        switch (att->attribute_type()) {
            case draco::GeometryAttribute::NORMAL: d.kind = DracoAttribute::kNormal; break;
            case draco::GeometryAttribute::COLOR: d.kind = DracoAttribute::kColor; break;
            case draco::GeometryAttribute::TEX_COORD: d.kind = DracoAttribute::kTexCoord; break;
            case draco::GeometryAttribute::GENERIC: d.kind = DracoAttribute::kGeneric; break;
            default: d.kind = DracoAttribute::kOther; break;
        }
        d.unique_id = static_cast<int>(att->unique_id());
        d.components = att->num_components();
        d.type = scalar_type_of(att->data_type());
        if (const draco::AttributeMetadata* md = mesh->GetAttributeMetadataByAttributeId(a))
            md->GetEntryString("name", &d.name);
        const size_t bytes_per = draco::DataTypeLength(att->data_type());
        if (d.components < 1 || bytes_per == 0 || d.kind == DracoAttribute::kOther) {
            out.attributes.push_back(std::move(d));
            continue;
        }
        const double scale = d.kind == DracoAttribute::kColor && d.type == ScalarType::kUInt8    ? 255.0
                             : d.kind == DracoAttribute::kColor && d.type == ScalarType::kUInt16 ? 65535.0
                                                                                                 : 1.0;
        d.values.resize(size_t{points} * d.components);
        std::vector<uint8_t> raw(bytes_per * d.components);
        for (uint32_t p = 0; p < points; ++p) {
            const draco::AttributeValueIndex avi = att->mapped_index(draco::PointIndex(p));
            if (avi.value() >= att->size())
                throw Error(file_name, base_offset, 0,
                            "Draco " + std::string(kind_name(d.kind)) + " attribute of point " + std::to_string(p) +
                                " is unreadable");
            att->GetValue(avi, raw.data());
            for (int c = 0; c < d.components; ++c)
                d.values[size_t{p} * d.components + c] = component_value(&raw[c * bytes_per], att->data_type()) / scale;
        }
        out.attributes.push_back(std::move(d));
    }

    out.indices.resize(size_t{mesh->num_faces()} * 3);
    for (uint32_t f = 0; f < mesh->num_faces(); ++f) {
        const auto& face = mesh->face(draco::FaceIndex(f));
        for (int k = 0; k < 3; ++k) {
            uint32_t v = face[k].value();
            if (v >= points)
                throw Error(file_name, base_offset, 0,
                            "Draco face " + std::to_string(f) + " references point " + std::to_string(v) + " of " +
                                std::to_string(points));
            out.indices[3 * size_t{f} + k] = v;
        }
    }
    return out;
}

}  // namespace meshstream::io

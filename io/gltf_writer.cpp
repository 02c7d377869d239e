// glTF 2.0 writer: the document is built as JSON here (nlohmann::ordered_json) and the binary
// payload in one buffer, written straight to the sink (GLB's BIN chunk, the .bin beside a
// .gltf) and never base64-encoded except for a .gltf written in place. Compression: Draco
// (KHR_draco_mesh_compression, io/draco.hpp), meshoptimizer (EXT_meshopt_compression with
// KHR_mesh_quantization, the way gltfpack -cc writes it) or none. See gltf.hpp for the contract.
#include "io/gltf.hpp"
#include "io/gltf_internal.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/mesh_index.hpp"
#include "io/text_number.hpp"
#if MESHSTREAM_WITH_DRACO
#include "io/draco.hpp"
#endif

#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>

#ifndef MESHSTREAM_VERSION
#define MESHSTREAM_VERSION "unknown"
#endif

namespace meshstream::io::gltf_detail {
namespace {

using Json = nlohmann::ordered_json;

constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125,
              kFloat = 5126;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
// Meshopt position quantization: 14 bits, gltfpack's default (-vp 14); normals 8-bit
// octahedral (-vn 8 with -cc's OCTAHEDRAL filter).
constexpr int kMeshoptPositionBits = 14;
constexpr int kMeshoptNormalBits = 8;

std::string base64(const unsigned char* data, size_t n) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((n + 2) / 3 * 4);
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = uint32_t{data[i]} << 16;
        if (i + 1 < n) v |= uint32_t{data[i + 1]} << 8;
        if (i + 2 < n) v |= data[i + 2];
        out.push_back(kAlphabet[(v >> 18) & 63]);
        out.push_back(kAlphabet[(v >> 12) & 63]);
        out.push_back(i + 1 < n ? kAlphabet[(v >> 6) & 63] : '=');
        out.push_back(i + 2 < n ? kAlphabet[v & 63] : '=');
    }
    return out;
}

// RFC 3986: everything but unreserved characters is percent-encoded in a relative URI.
std::string uri_encode(const std::string& name) {
    std::string out;
    for (unsigned char c : name) {
        if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~') {
            out.push_back(static_cast<char>(c));
        } else {
            char buf[4];
            std::snprintf(buf, sizeof buf, "%%%02X", c);
            out += buf;
        }
    }
    return out;
}

// "dir/scene.gltf(.gz)" -> "dir/scene".
std::string stem_of(std::string path) {
    if (path.size() > 3 && path.ends_with(".gz")) path.resize(path.size() - 3);
    size_t slash = path.find_last_of('/');
    size_t dot = path.find_last_of('.');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) path.resize(dot);
    return path;
}

// "dir/scene.gltf(.gz)" -> "dir/scene.bin".
std::string bin_path_for(const std::string& path) { return stem_of(path) + ".bin"; }

std::string base_name(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

// "image/png" or "image/jpeg" for a texture glTF can hold (its own MIME type, else its magic
// bytes); empty for anything else (glTF 2.0 core has PNG and JPEG only).
std::string image_mime_type(const Texture& texture) {
    if (texture.mime_type == "image/png" || texture.mime_type == "image/jpeg") return texture.mime_type;
    const auto& b = texture.bytes;
    if (b.size() >= 8 && b[0] == std::byte{0x89} && b[1] == std::byte{'P'} && b[2] == std::byte{'N'} &&
        b[3] == std::byte{'G'})
        return "image/png";
    if (b.size() >= 3 && b[0] == std::byte{0xFF} && b[1] == std::byte{0xD8} && b[2] == std::byte{0xFF})
        return "image/jpeg";
    return {};
}

// The materials the writer gives a texture image: those with image bytes of a type glTF holds.
bool writable_texture(const Material& m) {
    return m.texture && !m.texture->bytes.empty() && !image_mime_type(*m.texture).empty();
}

// The files a .gltf output at `path` writes beside itself: its .bin, then one image per
// material with a writable texture, "<stem>_<material>.png|jpg". None when written in place.
std::vector<std::string> side_files_of(const std::string& path, const WriteOptions& options) {
    if (is_stream(path)) return {};
    std::vector<std::string> out{bin_path_for(path)};
    if (!options.channels.material) return out;
    for (size_t m = 0; m < options.materials.size(); ++m)
        if (writable_texture(options.materials[m]))
            out.push_back(stem_of(path) + "_" + std::to_string(m) +
                          (image_mime_type(*options.materials[m].texture) == "image/png" ? ".png" : ".jpg"));
    return out;
}

// True when the glTF document at `gltf_path` names `file_name` as the URI of one of its buffers
// or images (URI-encoded, as this writer puts it, or plain). Unreadable or not glTF: false.
bool gltf_uses_file(const std::string& gltf_path, const std::string& file_name) {
    std::string text;
    try {
        const std::unique_ptr<ByteSource> source = ByteSource::open(gltf_path);
        char buf[1 << 16];
        constexpr size_t kMaxBytes = size_t{64} << 20;  // a glTF's JSON; more is not one
        for (size_t n; (n = source->read(buf, sizeof buf)) > 0;) {
            text.append(buf, n);
            if (text.size() > kMaxBytes) return false;
        }
    } catch (const Error&) {
        return false;
    }
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
    if (!doc.is_object()) return false;
    for (const char* list : {"buffers", "images"}) {
        if (!doc.contains(list) || !doc[list].is_array()) continue;
        for (const auto& item : doc[list]) {
            if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
            const std::string& uri = item["uri"].get_ref<const std::string&>();
            if (uri == uri_encode(file_name) || uri == file_name) return true;
        }
    }
    return false;
}

// The files beside a .gltf output are replaced when the .gltf is written. Unless the .gltf
// there already uses one (an earlier output, replaced as a set), it is someone else's
// (another glTF's, perhaps the input's): refused before any work instead of breaking that
// file silently.
void check_side_files(const std::string& gltf_path, const std::vector<std::string>& files) {
    struct stat st;
    const bool gltf_exists = ::stat(gltf_path.c_str(), &st) == 0;
    for (size_t i = 0; i < files.size(); ++i) {
        const std::string& file = files[i];
        if (::stat(file.c_str(), &st) != 0) continue;
        const std::string what = i == 0 ? "its buffer" : "its texture image";
        const std::string whose = i == 0 ? "another glTF's buffer?" : "another glTF's image?";
        if (!gltf_exists)
            throw Error(gltf_path, what + " would replace " + file + ", which exists but belongs to no earlier " +
                                       gltf_path + " (" + whose + "): move it, choose another name, or write .glb");
        if (!gltf_uses_file(gltf_path, base_name(file)))
            throw Error(gltf_path, what + " would replace " + file + ", which the existing " + gltf_path +
                                       " does not use as " + (i == 0 ? "its buffer" : "an image") + " (" + whose +
                                       "): move it, choose another name, or write .glb");
    }
}

// Smallest glTF index component type whose range holds indices 0..vertex_count-1 without the
// primitive-restart value (all ones), which glTF forbids in index data. meshopt's index codec
// takes 2- and 4-byte indices only.
int index_component_type(uint64_t vertex_count, size_t* size, bool meshopt) {
    if (vertex_count <= 0xFF && !meshopt) return *size = 1, kUnsignedByte;
    if (vertex_count <= 0xFFFF) return *size = 2, kUnsignedShort;
    return *size = 4, kUnsignedInt;
}

void pad4(std::vector<unsigned char>& bin) {
    while (bin.size() % 4) bin.push_back(0);
}

// Bytes one vertex takes in the output buffer with these channels (plain accessors).
uint64_t vertex_out_bytes(const Channels& ch, bool normals) {
    const uint64_t color = !ch.color                                ? 0
                           : ch.color->type == ScalarType::kFloat32 ? (ch.color->alpha ? 16 : 12)
                           : ch.color->type == ScalarType::kUInt16  ? 8
                                                                    : 4;
    return 12 + (ch.normal || normals ? 12 : 0) + color + 8 * uint64_t(ch.uv_sets);
}

// One vertex attribute of a primitive, as written: `count` elements `stride` bytes apart.
struct Stream {
    std::string semantic;  // "POSITION", "NORMAL", "COLOR_0", "TEXCOORD_0", ...
    int component_type = kFloat;
    const char* type = "VEC3";
    bool normalized = false;
    size_t element_bytes = 12;     // the accessor's element
    size_t stride = 12;            // a multiple of 4 (glTF's vertex attribute alignment)
    const char* filter = nullptr;  // meshopt filter, or null
    std::vector<unsigned char> data;
    Json min, max;  // POSITION's bounds
};

template <class T>
void put(std::vector<unsigned char>& data, size_t offset, T v) {
    std::memcpy(&data[offset], &v, sizeof v);
}

// The glTF document being written: its JSON lists and buffer 0.
struct Document {
    Json accessors = Json::array(), views = Json::array(), materials = Json::array(), textures = Json::array(),
         images = Json::array(), primitives = Json::array();
    std::vector<unsigned char> bin;  // buffer 0: the GLB's BIN chunk, the .bin
    uint64_t fallback_bytes = 0;     // EXT_meshopt_compression's fallback buffer (buffer 1)
    std::set<std::string> used, required;

    // Appends `n` bytes at a 4-byte boundary as a bufferView of buffer 0; returns its index.
    int add_view(const void* data, size_t n, size_t stride, int target) {
        pad4(bin);
        Json view = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", n}};
        if (stride) view["byteStride"] = stride;
        if (target) view["target"] = target;
        const auto* p = static_cast<const unsigned char*>(data);
        bin.insert(bin.end(), p, p + n);
        views.push_back(view);
        return int(views.size()) - 1;
    }
    // The same, compressed with meshoptimizer's codecs (mode "ATTRIBUTES" or "TRIANGLES"): the
    // compressed bytes go to buffer 0, the view itself to the fallback buffer, which holds no
    // data (the extension is required), as EXT_meshopt_compression lays it out.
    int add_meshopt_view(const std::vector<unsigned char>& data, size_t count, size_t stride, bool indices,
                         const char* filter) {
        std::vector<unsigned char> packed;
        if (indices) {
            meshopt_encodeIndexVersion(1);
            packed.resize(meshopt_encodeIndexBufferBound(count, count));
            if (stride == 2) {
                std::vector<uint16_t> idx(count);
                std::memcpy(idx.data(), data.data(), 2 * count);
                packed.resize(meshopt_encodeIndexBuffer(packed.data(), packed.size(), idx.data(), count));
            } else {
                std::vector<uint32_t> idx(count);
                std::memcpy(idx.data(), data.data(), 4 * count);
                packed.resize(meshopt_encodeIndexBuffer(packed.data(), packed.size(), idx.data(), count));
            }
        } else {
            packed.resize(meshopt_encodeVertexBufferBound(count, stride));
            packed.resize(meshopt_encodeVertexBuffer(packed.data(), packed.size(), data.data(), count, stride));
        }
        pad4(bin);
        Json ext = {{"buffer", 0},
                    {"byteOffset", bin.size()},
                    {"byteLength", packed.size()},
                    {"byteStride", stride},
                    {"mode", indices ? "TRIANGLES" : "ATTRIBUTES"},
                    {"count", count}};
        if (filter) ext["filter"] = filter;
        bin.insert(bin.end(), packed.begin(), packed.end());
        fallback_bytes = (fallback_bytes + 3) / 4 * 4;
        Json view = {{"buffer", 1}, {"byteOffset", fallback_bytes}, {"byteLength", data.size()}};
        if (!indices) view["byteStride"] = stride;
        view["target"] = indices ? kElementArrayBuffer : kArrayBuffer;
        view["extensions"] = {{kMeshoptExtension, ext}};
        fallback_bytes += data.size();
        views.push_back(view);
        return int(views.size()) - 1;
    }
    int add_accessor(Json accessor) {
        accessors.push_back(std::move(accessor));
        return int(accessors.size()) - 1;
    }
};

// A part's mesh data in the order written: positions, the channels' values, indices.
struct PartData {
    std::vector<float> positions;
    VertexValues values;
    std::vector<uint32_t> indices;
    size_t vertex_count() const { return positions.size() / 3; }
};

PartData part_data(const IndexedMesh& mesh, const MeshPart& part, const std::vector<float>* smooth) {
    PartData d;
    d.positions.resize(3 * part.vertex_count());
    for (size_t i = 0; i < part.vertex_count(); ++i)
        std::memcpy(&d.positions[3 * i], &mesh.positions[3 * size_t{part.vertices[i]}], 3 * sizeof(float));
    d.values = mesh.values(part.vertices);
    if (smooth) {
        d.values.normals.resize(3 * part.vertex_count());
        for (size_t i = 0; i < part.vertex_count(); ++i)
            std::memcpy(&d.values.normals[3 * i], &(*smooth)[3 * size_t{part.vertices[i]}], 3 * sizeof(float));
    }
    d.indices = part.indices;
    return d;
}

// Reorders a part for meshopt's codecs as gltfpack -cc does: triangles for the vertex cache
// in strip order (unless `keep_order`: a sorted stream keeps its order), then vertices in
// first-use order.
void optimize_for_meshopt(PartData& d, bool keep_order) {
    const size_t n = d.vertex_count();
    if (!keep_order) meshopt_optimizeVertexCacheStrip(d.indices.data(), d.indices.data(), d.indices.size(), n);
    std::vector<unsigned int> remap(n);
    const size_t unique = meshopt_optimizeVertexFetchRemap(remap.data(), d.indices.data(), d.indices.size(), n);
    meshopt_remapIndexBuffer(d.indices.data(), d.indices.data(), d.indices.size(), remap.data());
    auto reorder = [&](auto& values, size_t per) {
        if (values.empty()) return;
        auto out = values;
        out.resize(unique * per);
        for (size_t v = 0; v < n; ++v)
            if (remap[v] != ~0u) std::copy(&values[v * per], &values[v * per] + per, &out[size_t{remap[v]} * per]);
        values = std::move(out);
    };
    reorder(d.positions, 3);
    reorder(d.values.normals, 3);
    reorder(d.values.colors, 4);
    for (auto& uv : d.values.uvs) reorder(uv, 2);
    for (auto& s : d.values.scalars) reorder(s, 1);
}

// Position quantization of the meshopt encoding: q = round((p - offset) / scale · (2^bits - 1)),
// the node's transform (translation offset, uniform scale / (2^bits - 1)) undoing it.
struct Quantization {
    float offset[3] = {0, 0, 0};
    float scale = 1;  // the largest extent (1 when the mesh is a point)
    int bits = kMeshoptPositionBits;
    double step() const { return double(scale) / double((1 << bits) - 1); }
};

// The streams of a part: what each channel becomes in the chosen encoding.
std::vector<Stream> vertex_streams(const PartData& d, const Channels& ch, bool normals, bool meshopt,
                                   const Quantization& q) {
    const size_t n = d.vertex_count();
    std::vector<Stream> out;
    {
        Stream s;
        s.semantic = "POSITION";
        if (meshopt) {
            // Unsigned integers of q.bits (KHR_mesh_quantization), padded to 8 bytes as gltfpack does.
            s.component_type = kUnsignedShort;
            s.element_bytes = 6;
            s.stride = 8;
            s.data.assign(n * 8, 0);
            const float rscale = 1.0f / q.scale;
            uint16_t lo[3] = {0xFFFF, 0xFFFF, 0xFFFF}, hi[3] = {0, 0, 0};
            for (size_t v = 0; v < n; ++v)
                for (int a = 0; a < 3; ++a) {
                    const uint16_t x = static_cast<uint16_t>(
                        meshopt_quantizeUnorm((d.positions[3 * v + a] - q.offset[a]) * rscale, q.bits));
                    put(s.data, 8 * v + 2 * a, x);
                    lo[a] = std::min(lo[a], x);
                    hi[a] = std::max(hi[a], x);
                }
            s.min = {lo[0], lo[1], lo[2]};
            s.max = {hi[0], hi[1], hi[2]};
        } else {
            s.data.resize(n * 12);
            std::memcpy(s.data.data(), d.positions.data(), s.data.size());
            float lo[3], hi[3];
            for (int a = 0; a < 3; ++a) lo[a] = hi[a] = d.positions[a];
            for (size_t v = 0; v < n; ++v)
                for (int a = 0; a < 3; ++a) {
                    lo[a] = std::min(lo[a], d.positions[3 * v + a]);
                    hi[a] = std::max(hi[a], d.positions[3 * v + a]);
                }
            s.min = {lo[0], lo[1], lo[2]};
            s.max = {hi[0], hi[1], hi[2]};
        }
        out.push_back(std::move(s));
    }
    if (ch.normal || normals) {
        Stream s;
        s.semantic = "NORMAL";
        if (meshopt) {
            // Octahedral 8-bit (gltfpack -cc): meshopt's filter stores (u, v, 1) and the decoder
            // turns them back into a normalised (x, y, z) in the same bytes.
            s.component_type = kByte;
            s.normalized = true;
            s.element_bytes = 3;
            s.stride = 4;
            s.filter = "OCTAHEDRAL";
            std::vector<float> n4(4 * n);
            for (size_t v = 0; v < n; ++v) {
                std::copy(&d.values.normals[3 * v], &d.values.normals[3 * v] + 3, &n4[4 * v]);
                n4[4 * v + 3] = 0;
            }
            s.data.resize(4 * n);
            meshopt_encodeFilterOct(s.data.data(), n, 4, kMeshoptNormalBits, n4.data());
        } else {
            s.data.resize(12 * n);
            std::memcpy(s.data.data(), d.values.normals.data(), s.data.size());
        }
        out.push_back(std::move(s));
    }
    if (ch.color) {
        // The source's type (glTF holds float, normalized ubyte and ushort), padded to 4 bytes.
        Stream s;
        s.semantic = "COLOR_0";
        const int comps = ch.color->alpha ? 4 : 3;
        s.type = comps == 4 ? "VEC4" : "VEC3";
        const ScalarType t = ch.color->type;
        s.component_type = t == ScalarType::kUInt8 ? kUnsignedByte : t == ScalarType::kUInt16 ? kUnsignedShort : kFloat;
        s.normalized = s.component_type != kFloat;
        const size_t cbytes = t == ScalarType::kUInt8 ? 1 : t == ScalarType::kUInt16 ? 2 : 4;
        s.element_bytes = cbytes * comps;
        s.stride = (s.element_bytes + 3) / 4 * 4;
        s.data.assign(n * s.stride, 0);
        for (size_t v = 0; v < n; ++v)
            for (int c = 0; c < comps; ++c) {
                const float x = d.values.colors[4 * v + c];
                const size_t at = v * s.stride + c * cbytes;
                if (t == ScalarType::kUInt8)
                    put(s.data, at, color_to_unorm<uint8_t>(x, 255.0f));
                else if (t == ScalarType::kUInt16)
                    put(s.data, at, color_to_unorm<uint16_t>(x, 65535.0f));
                else
                    put(s.data, at, x);
            }
        out.push_back(std::move(s));
    }
    for (int set = 0; set < ch.uv_sets; ++set) {
        // glTF's v points down the image: v' = 1 - v of the chunk's.
        Stream s;
        s.semantic = "TEXCOORD_" + std::to_string(set);
        s.type = "VEC2";
        s.element_bytes = s.stride = 8;
        s.data.resize(8 * n);
        for (size_t v = 0; v < n; ++v) {
            put(s.data, 8 * v, d.values.uvs[set][2 * v]);
            put(s.data, 8 * v + 4, 1.0f - d.values.uvs[set][2 * v + 1]);
        }
        out.push_back(std::move(s));
    }
    return out;
}

class GltfWriter final : public Writer {
    static constexpr const char* kWhy = "glTF is written from the whole mesh in memory";
    // The indexer's tables, the per-primitive copies (indices, vertex lists and their unpacked
    // values), the output buffer; meshopt adds its optimizer's tables and the compressed copy.
    static uint64_t plain_need(uint64_t vertices, uint64_t triangles, const WriteOptions& options) {
        const uint64_t out = buffer_bytes(vertices, triangles, options);
        return indexed_mesh_bytes(vertices, triangles, options.channels) +
               4 * std::bit_ceil(std::max<uint64_t>(2 * vertices, 1024)) +
               vertices * (4 + 2 * uint64_t(CornerLayout(options.channels).bytes())) + triangles * 12 + out +
               (writer_compression(options) == GltfSettings::Compression::kMeshopt
                    ? out + vertices * 16 + triangles * 12
                    : 0);
    }
    static uint64_t buffer_bytes(uint64_t vertices, uint64_t triangles, const WriteOptions& options) {
        return vertices * vertex_out_bytes(options.channels, options.normals) + triangles * 12;
    }
    // A .gltf on stdout carries its buffer as a base64 data URI inside the JSON: the base64
    // text, the JSON document around it and the string written are copies of 4/3 of the
    // buffer each (measured on 1 M triangles: 5.2 buffers more peak RSS than to a file).
    static uint64_t plain_stdout_need(uint64_t vertices, uint64_t triangles, const WriteOptions& options) {
        return plain_need(vertices, triangles, options) + 6 * buffer_bytes(vertices, triangles, options);
    }
    static uint64_t draco_need(uint64_t vertices, uint64_t triangles, const WriteOptions& options) {
#if MESHSTREAM_WITH_DRACO
        return draco_encode_estimate_bytes(vertices, triangles, options);
#else
        return plain_need(vertices, triangles, options);
#endif
    }

public:
    GltfWriter(ByteSink& sink, const WriteOptions& options, bool binary)
        : sink_(sink),
          options_(options),
          binary_(binary),
          indexer_(sink.name(), "glTF", options.channels, options.strict),
          budget_(sink.name(), options, kWhy) {
        draco_ = writer_compression(options_) == GltfSettings::Compression::kDraco;
        meshopt_ = writer_compression(options_) == GltfSettings::Compression::kMeshopt;
        grid_ = options_.format_options.get<GltfSettings>().grid;
        if (grid_ && (draco_ || meshopt_)) {
            const int most = meshopt_ ? 16 : 30;
            if (grid_->bits < 1 || grid_->bits > most || !(grid_->extent > 0) || !std::isfinite(grid_->extent))
                throw Error(sink.name(), "the positions' quantization grid needs 1-" + std::to_string(most) +
                                             " bits with " + (meshopt_ ? "meshopt" : "Draco") +
                                             " and an extent above 0, got " + std::to_string(grid_->bits) +
                                             " bits");
        }
#if MESHSTREAM_WITH_DRACO
        if (draco_ && grid_) {
            // The grid's bits are Draco's position bits: its coding tables are counted with them.
            DracoSettings d = options_.format_options.get<DracoSettings>();
            d.position_bits = grid_->bits;
            options_.format_options.set(d);
        }
        if (draco_) draco_settings_ = check_draco_settings(sink.name(), options_);
#endif
        // Written in place (stdout, a pipe, a device), the .gltf has no directory entry of its
        // own that a .bin could sit beside: the buffer goes inside, as a data URI.
        inline_buffer_ = !binary_ && sink.in_place();
        budget_check_up_front(sink.name(), options_, kWhy,
                              draco_           ? draco_need
                              : inline_buffer_ ? plain_stdout_need
                                               : plain_need);
        if (!binary_ && !inline_buffer_) check_side_files(sink.name(), side_files_of(sink.name(), options_));
        // The count known and its tables within the budget (checked above): sized once.
        if (const std::optional<uint64_t> n = options_.triangle_count ? options_.triangle_count
                                                                      : options_.expected_triangle_count)
            indexer_.reserve(*n);
    }

    void write_chunk(const TriangleChunk& chunk) override {
        if (budget_.counting()) return budget_.count(chunk.size());
        indexer_.add(chunk);
        const uint64_t v = indexer_.vertex_count(), f = indexer_.triangle_count();
        uint64_t need;
        if (draco_) {
            need = draco_need(v, f, options_);
        } else {
            // The tables now, plus what finish() adds: the per-primitive copies, the output
            // buffer (and its compressed or base64 copies).
            const uint64_t out = buffer_bytes(v, f, options_);
            need = indexer_.memory_bytes() + v * (4 + 2 * uint64_t(CornerLayout(options_.channels).bytes())) + f * 12 +
                   out + (meshopt_ ? out + v * 16 + f * 12 : 0) + (inline_buffer_ ? 6 * out : 0);
        }
        if (budget_.check(indexer_.input_triangle_count(), need))
            indexer_ = MeshIndexer(sink_.name(), "glTF", options_.channels, options_.strict);  // frees the tables
    }

    void finish_output() override;
    void materials_updated(const std::vector<Material>& materials) override { options_.materials = materials; }
    std::vector<std::string> format_notes() const override {
        std::vector<std::string> out;
        for (const std::string& note : notes_) out.push_back(sink_.name() + ": " + note);
        return out;
    }

private:
    void add_materials(Document& doc, const std::vector<MeshPart>& parts, const std::vector<std::string>& image_files);
    Json plain_primitive(Document& doc, PartData& d, const Channels& ch, bool normals, const Quantization& q);
#if MESHSTREAM_WITH_DRACO
    Json draco_primitive(Document& doc, PartData& d, const Channels& ch, DracoEncoded* sums);
#endif
    std::string document_json(const Document& doc, const Json& nodes, const std::string& buffer_uri);

    std::vector<std::string> notes_;
    ByteSink& sink_;
    WriteOptions options_;
    bool binary_;
    bool draco_ = false, meshopt_ = false;
    std::optional<GltfSettings::Grid> grid_;  // the positions' common quantization grid (meshopt, Draco)
#if MESHSTREAM_WITH_DRACO
    DracoSettings draco_settings_;  // checked, when draco_
#endif
    bool inline_buffer_ = false;  // a .gltf on stdout: the buffer is a base64 data URI
    MeshIndexer indexer_;
    WholeMeshBudget budget_;
    std::map<uint32_t, int> material_json_;  // material table index -> glTF material
};

void GltfWriter::add_materials(Document& doc, const std::vector<MeshPart>& parts,
                               const std::vector<std::string>& image_files) {
    if (!options_.channels.material) return;
    size_t next_file = 0;
    std::map<uint32_t, size_t> file_of;  // material -> its image file (beside a .gltf)
    for (size_t m = 0; m < options_.materials.size(); ++m)
        if (writable_texture(options_.materials[m])) file_of[uint32_t(m)] = next_file++;
    uint64_t unreadable = 0, unsupported = 0;
    for (const MeshPart& part : parts) {
        if (part.material >= options_.materials.size()) continue;  // the default material
        const Material& m = options_.materials[part.material];
        // Materials carry what the formats share: a base colour and its texture; metallic 0
        // (glTF's default is 1, a metal), so a diffuse colour from OBJ or PLY looks as it did.
        Json pbr = Json::object();
        if (m.base_color != std::array<float, 4>{1, 1, 1, 1})
            pbr["baseColorFactor"] = {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]};
        if (m.texture && writable_texture(m)) {
            Json image;
            const std::string mime = image_mime_type(*m.texture);
            if (binary_) {
                image["bufferView"] = doc.add_view(m.texture->bytes.data(), m.texture->bytes.size(), 0, 0);
                image["mimeType"] = mime;
            } else if (inline_buffer_) {
                image["uri"] =
                    "data:" + mime + ";base64," +
                    base64(reinterpret_cast<const unsigned char*>(m.texture->bytes.data()), m.texture->bytes.size());
            } else {
                image["uri"] = uri_encode(base_name(image_files[1 + file_of.at(part.material)]));
            }
            if (!m.texture->uri.empty() && !m.texture->uri.starts_with("data:"))
                image["name"] = base_name(m.texture->uri);
            doc.images.push_back(image);
            doc.textures.push_back({{"source", doc.images.size() - 1}});
            pbr["baseColorTexture"] = {{"index", doc.textures.size() - 1}};
        } else if (m.texture) {
            ++(m.texture->bytes.empty() ? unreadable : unsupported);
        }
        pbr["metallicFactor"] = 0;
        Json material;
        if (!m.name.empty()) material["name"] = m.name;
        material["pbrMetallicRoughness"] = pbr;
        if (m.base_color[3] < 1.0f) material["alphaMode"] = "BLEND";
        doc.materials.push_back(material);
        material_json_[part.material] = int(doc.materials.size()) - 1;
    }
    if (unreadable)
        notes_.push_back(std::to_string(unreadable) +
                         " texture image(s) the input named could not be read: their "
                         "materials are written without them");
    if (unsupported)
        notes_.push_back(std::to_string(unsupported) +
                         " texture image(s) are neither PNG nor JPEG, which glTF holds: "
                         "their materials are written without them");
}

Json GltfWriter::plain_primitive(Document& doc, PartData& d, const Channels& ch, bool normals, const Quantization& q) {
    Json attributes = Json::object();
    for (Stream& s : vertex_streams(d, ch, normals, meshopt_, q)) {
        const size_t n = d.vertex_count();
        const int view = meshopt_ ? doc.add_meshopt_view(s.data, n, s.stride, false, s.filter)
                                  : doc.add_view(s.data.data(), s.data.size(),
                                                 s.stride != s.element_bytes ? s.stride : 0, kArrayBuffer);
        Json accessor = {{"bufferView", view}, {"componentType", s.component_type}, {"count", n}, {"type", s.type}};
        if (s.normalized) accessor["normalized"] = true;
        if (!s.min.is_null()) {
            accessor["min"] = s.min;
            accessor["max"] = s.max;
        }
        attributes[s.semantic] = doc.add_accessor(accessor);
    }
    size_t index_size = 0;
    const int component = index_component_type(d.vertex_count(), &index_size, meshopt_);
    std::vector<unsigned char> idx(d.indices.size() * index_size);
    for (size_t i = 0; i < d.indices.size(); ++i) {
        const uint32_t v = d.indices[i];
        const uint8_t le[4] = {uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)};
        std::memcpy(&idx[i * index_size], le, index_size);
    }
    const int view = meshopt_ ? doc.add_meshopt_view(idx, d.indices.size(), index_size, true, nullptr)
                              : doc.add_view(idx.data(), idx.size(), 0, kElementArrayBuffer);
    Json prim = {{"attributes", attributes}};
    prim["indices"] = doc.add_accessor(
        {{"bufferView", view}, {"componentType", component}, {"count", d.indices.size()}, {"type", "SCALAR"}});
    return prim;
}

#if MESHSTREAM_WITH_DRACO
Json GltfWriter::draco_primitive(Document& doc, PartData& d, const Channels& ch, DracoEncoded* sums) {
    std::optional<DracoGrid> grid;
    if (grid_) {
        grid.emplace();
        for (int a = 0; a < 3; ++a) grid->origin[a] = grid_->origin[a];
        grid->range = grid_->extent;
    }
    DracoEncoded enc = encode_draco(d.positions, d.indices, d.values, ch, draco_settings_, sink_.name(),
                                    /*flip_v=*/true, grid ? &*grid : nullptr);
    sums->dropped += enc.dropped;
    sums->flattened += enc.flattened;
    sums->on_grid = enc.on_grid;
    sums->face_count += enc.face_count;
    const int view = doc.add_view(enc.bytes.data(), enc.bytes.size(), 0, 0);
    size_t index_size = 0;
    Json attributes = Json::object(), ids = Json::object();
    auto accessor = [&](const char* semantic, int id, int component, const char* type, bool normalized) {
        Json a = {{"componentType", component}, {"count", enc.point_count}, {"type", type}};
        if (normalized) a["normalized"] = true;
        if (std::string(semantic) == "POSITION") {
            const Bounds& b = enc.decoded_bounds;
            a["min"] = {b.min[0], b.min[1], b.min[2]};
            a["max"] = {b.max[0], b.max[1], b.max[2]};
        }
        attributes[semantic] = doc.add_accessor(a);
        ids[semantic] = id;
    };
    accessor("POSITION", enc.position_id, kFloat, "VEC3", false);
    if (enc.normal_id >= 0) accessor("NORMAL", enc.normal_id, kFloat, "VEC3", false);
    if (enc.color_id >= 0) {
        const ScalarType t = ch.color->type;
        accessor("COLOR_0", enc.color_id,
                 t == ScalarType::kUInt8    ? kUnsignedByte
                 : t == ScalarType::kUInt16 ? kUnsignedShort
                                            : kFloat,
                 ch.color->alpha ? "VEC4" : "VEC3", t != ScalarType::kFloat32);
    }
    for (size_t s = 0; s < enc.texcoord_ids.size(); ++s)
        accessor(("TEXCOORD_" + std::to_string(s)).c_str(), enc.texcoord_ids[s], kFloat, "VEC2", false);
    Json prim = {{"attributes", attributes}};
    prim["indices"] = doc.add_accessor({{"componentType", index_component_type(enc.point_count, &index_size, false)},
                                        {"count", 3 * enc.face_count},
                                        {"type", "SCALAR"}});
    prim["extensions"] = {{kDracoExtension, {{"bufferView", view}, {"attributes", ids}}}};
    return prim;
}
#endif

void GltfWriter::finish_output() {
    if (budget_.counting()) budget_.fail();
    IndexedMesh mesh = indexer_.take();
    notes_ = indexer_.notes();
    const std::vector<std::string> image_files =
        !binary_ && !inline_buffer_ ? side_files_of(sink_.name(), options_) : std::vector<std::string>{};
    Document doc;
    Json nodes = Json::array();
    if (mesh.triangle_count() > 0) {
#if MESHSTREAM_WITH_DRACO
        if (draco_ && options_.strict)
            if (const int64_t t = first_repeated_vertex(mesh.indices); t >= 0)
                throw Error(sink_.name(), "triangle " + std::to_string(t) +
                                              " has two corners at one vertex, which "
                                              "Draco's encoder drops (" + mention(Setting::kStrict) + ")");
#endif
        // --normals adds smooth normals to a mesh that has none of its own.
        Channels ch = mesh.channels;
        ch.material = false;
        const bool smooth = options_.normals && !ch.normal;
        std::vector<float> smooth_normals;
        if (smooth) smooth_normals = mesh.smooth_normals();
        if (smooth) ch.normal = true;
        std::vector<MeshPart> parts = mesh.parts();
        add_materials(doc, parts, image_files);
        Quantization q;
        if (meshopt_ && grid_) {
            for (int a = 0; a < 3; ++a) q.offset[a] = grid_->origin[a];
            q.scale = grid_->extent;
            q.bits = grid_->bits;
        } else if (meshopt_) {
            const Bounds b = mesh.bounds();
            float extent = 0;
            for (int a = 0; a < 3; ++a) q.offset[a] = b.min[a], extent = std::max(extent, b.max[a] - b.min[a]);
            if (!std::isfinite(extent))
                throw Error(sink_.name(),
                            "the mesh is wider along an axis than a float can hold (3.4e38): it cannot be "
                            "quantized for meshopt; write it with " + mention(Setting::kCompress) + " none");
            q.scale = extent > 0 ? extent : 1.0f;
        }
#if MESHSTREAM_WITH_DRACO
        DracoEncoded sums;
#endif
        for (MeshPart& part : parts) {
            PartData d = part_data(mesh, part, smooth ? &smooth_normals : nullptr);
            part = MeshPart{part.material, {}, {}};  // its copy is in `d`
            Json prim;
#if MESHSTREAM_WITH_DRACO
            if (draco_) {
                prim = draco_primitive(doc, d, ch, &sums);
            } else
#endif
            {
                if (meshopt_) optimize_for_meshopt(d, options_.sorted_axis.has_value());
                prim = plain_primitive(doc, d, ch, smooth, q);
            }
            if (auto it = material_json_.find(part.material); it != material_json_.end()) prim["material"] = it->second;
            doc.primitives.push_back(prim);
        }
#if MESHSTREAM_WITH_DRACO
        if (draco_)
            for (std::string& note : draco_notes(sums, mesh.triangle_count(), draco_settings_))
                notes_.push_back(std::move(note));
#endif
        Json node = {{"mesh", 0}};
        if (meshopt_) {
            // The dequantization: p = offset + q · scale / (2^bits - 1) on every axis.
            node["translation"] = {q.offset[0], q.offset[1], q.offset[2]};
            const double s = q.step();
            node["scale"] = {s, s, s};
        }
        nodes.push_back(node);
        if (draco_) doc.used.insert(kDracoExtension), doc.required.insert(kDracoExtension);
        if (meshopt_) {
            doc.used.insert(kMeshoptExtension), doc.required.insert(kMeshoptExtension);
            doc.used.insert(kQuantizationExtension), doc.required.insert(kQuantizationExtension);
        }
    }
    mesh = IndexedMesh{};

    if (binary_) {
        std::string json = document_json(doc, nodes, {});
        while (json.size() % 4) json.push_back(' ');
        pad4(doc.bin);
        uint64_t total = 12 + 8 + json.size() + (doc.bin.empty() ? 0 : 8 + doc.bin.size());
        if (total > 0xFFFFFFFFull)
            throw Error(sink_.name(), "the GLB would be " + std::to_string(total) +
                                          " bytes, over GLB's 4 GiB limit; write .gltf (+ .bin) instead");
        std::string head;
        head.append(kGlbMagic, 4);
        put_u32(head, 2);
        put_u32(head, static_cast<uint32_t>(total));
        put_u32(head, static_cast<uint32_t>(json.size()));
        put_u32(head, kChunkJson);
        sink_.write(head);
        sink_.write(json);
        if (!doc.bin.empty()) {
            std::string chunk;
            put_u32(chunk, static_cast<uint32_t>(doc.bin.size()));
            put_u32(chunk, kChunkBin);
            sink_.write(chunk);
            sink_.write(doc.bin.data(), doc.bin.size());
        }
    } else if (doc.bin.empty()) {
        sink_.write(document_json(doc, nodes, {}));
    } else if (inline_buffer_) {
        std::string uri = "data:application/octet-stream;base64," + base64(doc.bin.data(), doc.bin.size());
        sink_.write(document_json(doc, nodes, uri));
    } else {
        const std::string bin_path = image_files[0];
        std::string json = document_json(doc, nodes, uri_encode(base_name(bin_path)));
        // The side files go through their own ByteSinks. Every file is written out in full
        // before any is renamed, so a full disk leaves none behind (nor an old .gltf beside a
        // new .bin); the caller renames the .gltf right after the .bin, which comes after the
        // images.
        std::vector<std::unique_ptr<ByteSink>> sides;
        for (size_t m = 0, k = 1; m < options_.materials.size() && options_.channels.material; ++m) {
            if (!writable_texture(options_.materials[m])) continue;
            const std::string& path = image_files[k++];
            if (std::find_if(doc.images.begin(), doc.images.end(), [&](const Json& im) {
                    return im.contains("uri") && im["uri"] == uri_encode(base_name(path));
                }) == doc.images.end())
                continue;  // a material no triangle uses
            sides.push_back(ByteSink::open(path));
            sides.back()->write(options_.materials[m].texture->bytes.data(),
                                options_.materials[m].texture->bytes.size());
        }
        sides.push_back(ByteSink::open(bin_path));
        sides.back()->write(doc.bin.data(), doc.bin.size());
        sink_.write(json);
        for (auto& side : sides) side->finish_writing();
        sink_.finish_writing();
        for (auto& side : sides) side->commit();
    }
}

std::string GltfWriter::document_json(const Document& doc, const Json& nodes, const std::string& buffer_uri) {
    Json out;
    out["asset"] = {{"version", "2.0"}, {"generator", std::string("meshstream ") + MESHSTREAM_VERSION}};
    if (!doc.used.empty()) out["extensionsUsed"] = Json(std::vector<std::string>(doc.used.begin(), doc.used.end()));
    if (!doc.required.empty())
        out["extensionsRequired"] = Json(std::vector<std::string>(doc.required.begin(), doc.required.end()));
    out["scene"] = 0;
    if (nodes.empty()) {
        out["scenes"] = Json::array({Json::object()});
    } else {
        out["scenes"] = Json::array({{{"nodes", {0}}}});
        out["nodes"] = nodes;
        out["meshes"] = Json::array({{{"primitives", doc.primitives}}});
    }
    if (!doc.materials.empty()) out["materials"] = doc.materials;
    if (!doc.textures.empty()) out["textures"] = doc.textures;
    if (!doc.images.empty()) out["images"] = doc.images;
    if (!doc.accessors.empty()) out["accessors"] = doc.accessors;
    if (!doc.views.empty()) out["bufferViews"] = doc.views;
    Json buffers = Json::array();
    if (!doc.bin.empty()) {
        Json buffer = {{"byteLength", doc.bin.size()}};  // a GLB's BIN chunk may pad past it
        if (!buffer_uri.empty()) buffer["uri"] = buffer_uri;
        buffers.push_back(buffer);
    }
    if (doc.fallback_bytes > 0)
        buffers.push_back(
            {{"byteLength", doc.fallback_bytes}, {"extensions", {{kMeshoptExtension, {{"fallback", true}}}}}});
    if (!buffers.empty()) out["buffers"] = buffers;
    return out.dump(binary_ ? -1 : 2) + (binary_ ? "" : "\n");
}

}  // namespace

std::unique_ptr<Writer> open_glb_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<GltfWriter>(sink, options, true);
}

std::vector<std::string> gltf_side_files(const std::string& path, const WriteOptions& options) {
    return side_files_of(path, options);
}

std::unique_ptr<Writer> open_gltf_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<GltfWriter>(sink, options, false);
}

GltfSettings::Compression writer_compression(const WriteOptions& options) {
    const GltfSettings::Compression c = options.format_options.get<GltfSettings>().compression;
#if !MESHSTREAM_WITH_DRACO
    if (c == GltfSettings::Compression::kDraco) return GltfSettings::Compression::kNone;
#endif
    return c;
}

Channels gltf_keep_channels(const Channels& in, const WriteOptions&) {
    // Every compression holds the same: normals, colour in its source's type (float, ubyte,
    // ushort; with or without alpha), up to four texture coordinate sets, materials.
    Channels out;
    out.normal = in.normal;
    out.color = in.color;
    out.uv_sets = std::min(in.uv_sets, kMaxUvSets);
    out.material = in.material;
    out.vertex_id = in.vertex_id;
    return out;
}

}  // namespace meshstream::io::gltf_detail

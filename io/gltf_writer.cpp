// glTF 2.0 writer on tinygltf (document model and JSON serialisation) and Draco
// (KHR_draco_mesh_compression). tinygltf serialises the document with an empty placeholder
// buffer, then the writer sets buffers[0] itself and frames the GLB container, so the
// (possibly large) binary payload is written straight to the sink and never base64-encoded or
// copied into tinygltf's model. See gltf.hpp for the contract.
#include "io/gltf.hpp"
#include "io/gltf_internal.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/mesh_index.hpp"
#if MESHSTREAM_WITH_DRACO
#include "io/draco.hpp"
#endif

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdio>
#include <memory>
#include <sstream>
#include <sys/stat.h>

#ifndef MESHSTREAM_VERSION
#define MESHSTREAM_VERSION "unknown"
#endif

namespace meshstream::io::gltf_detail {
namespace {

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

// "dir/scene.gltf(.gz)" -> "dir/scene.bin".
std::string bin_path_for(std::string path) {
    if (path.size() > 3 && path.ends_with(".gz")) path.resize(path.size() - 3);
    size_t slash = path.find_last_of('/');
    size_t dot = path.find_last_of('.');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) path.resize(dot);
    return path + ".bin";
}

std::string base_name(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

// True when the glTF document at `gltf_path` names `bin_name` as the URI of one of its buffers
// (URI-encoded, as this writer puts it, or plain). Unreadable or not a glTF document: false.
bool gltf_uses_buffer(const std::string& gltf_path, const std::string& bin_name) {
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
    if (!doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return false;
    for (const auto& buffer : doc["buffers"]) {
        if (!buffer.is_object() || !buffer.contains("uri") || !buffer["uri"].is_string()) continue;
        const std::string& uri = buffer["uri"].get_ref<const std::string&>();
        if (uri == uri_encode(bin_name) || uri == bin_name) return true;
    }
    return false;
}

// The .bin beside a .gltf output is replaced when the .gltf is written. Unless the .gltf there
// already uses it as its buffer (an earlier output, replaced as a pair), it is someone else's
// (another glTF's, perhaps the input's): refused before any work instead of breaking that
// file silently.
void check_side_file(const std::string& gltf_path) {
    const std::string bin = bin_path_for(gltf_path);
    struct stat st;
    if (::stat(bin.c_str(), &st) != 0) return;
    if (::stat(gltf_path.c_str(), &st) != 0)
        throw Error(gltf_path, "its buffer would replace " + bin +
                                   ", which exists but belongs to no earlier " + gltf_path +
                                   " (another glTF's buffer?): move it, choose another name, or write .glb");
    if (!gltf_uses_buffer(gltf_path, base_name(bin)))
        throw Error(gltf_path, "its buffer would replace " + bin + ", which the existing " + gltf_path +
                                   " does not use as its buffer (another glTF's buffer?): move it, choose another "
                                   "name, or write .glb");
}

// Smallest glTF index component type whose range holds indices 0..vertex_count-1 without the
// primitive-restart value (all ones), which glTF forbids in index data.
int index_component_type(uint64_t vertex_count, size_t* size) {
    if (vertex_count <= 0xFF) return *size = 1, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    if (vertex_count <= 0xFFFF) return *size = 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    return *size = 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}


class GltfWriter final : public Writer {
    static constexpr const char* kWhy = "glTF is written from the whole mesh in memory";
    // The indexer's tables (positions, 4-byte hash slots, a power of two at least twice the
    // vertices, indices) plus the output buffer, as in write().
    static uint64_t plain_need(uint64_t vertices, uint64_t triangles, const WriteOptions& options) {
        const bool normals = options.normals;
        return vertices * (12 + 12 + (normals ? 24 : 0)) + 4 * std::bit_ceil(std::max<uint64_t>(2 * vertices, 1024)) +
               triangles * (12 + 12);
    }
    // A .gltf on stdout carries its buffer as a base64 data URI inside the JSON: the base64
    // text, the JSON document around it and the string written are copies of 4/3 of the
    // buffer each (measured on 1 M triangles: 5.2 buffers more peak RSS than to a file).
    static uint64_t buffer_bytes(uint64_t vertices, uint64_t triangles, bool normals) {
        return vertices * (12 + (normals ? 12 : 0)) + triangles * 12;
    }
    static uint64_t plain_stdout_need(uint64_t vertices, uint64_t triangles, const WriteOptions& options) {
        return plain_need(vertices, triangles, options) + 6 * buffer_bytes(vertices, triangles, options.normals);
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
        : sink_(sink), options_(options), binary_(binary), indexer_(sink.name()) {
#if !MESHSTREAM_WITH_DRACO
        options_.draco = false;
#endif
#if MESHSTREAM_WITH_DRACO
        if (options_.draco) check_draco_settings(sink.name(), options_);
#endif
        // Written in place (stdout, a pipe, a device), the .gltf has no directory entry of its
        // own that a .bin could sit beside: the buffer goes inside, as a data URI.
        inline_buffer_ = !binary_ && sink.in_place();
        budget_check_up_front(sink.name(), options_, kWhy,
                              options_.draco ? draco_need : inline_buffer_ ? plain_stdout_need : plain_need);
        if (!binary_ && !inline_buffer_) check_side_file(sink.name());
    }

    void write_chunk(const TriangleChunk& chunk) override {
        indexer_.add(chunk);
        uint64_t v = indexer_.vertex_count(), f = indexer_.triangle_count();
        uint64_t need;
#if MESHSTREAM_WITH_DRACO
        if (options_.draco) need = draco_encode_estimate_bytes(v, f, options_);
        else
#endif
            // Index tables, plus the output buffer (positions, optional normals, indices), and
            // its base64 copies when it goes inline.
            need = indexer_.memory_bytes() + v * (12 + (options_.normals ? 24 : 0)) + f * 12 +
                   (inline_buffer_ ? 6 * buffer_bytes(v, f, options_.normals) : 0);
        budget_check(sink_.name(), options_, kWhy, indexer_.input_triangle_count(), need);
    }

    void finish_output() override;
    std::vector<std::string> notes() const override {
        return note_.empty() ? std::vector<std::string>{} : std::vector<std::string>{sink_.name() + ": " + note_};
    }

private:
    std::string note_;
    std::string document_json(tinygltf::Model& model, uint64_t buffer_bytes, const std::string& buffer_uri);

    ByteSink& sink_;
    WriteOptions options_;
    bool binary_;
    bool inline_buffer_ = false;  // a .gltf on stdout: the buffer is a base64 data URI
    MeshIndexer indexer_;
};

void append_bytes(std::vector<unsigned char>& bin, const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + n);
}

void pad4(std::vector<unsigned char>& bin) {
    while (bin.size() % 4) bin.push_back(0);
}

void GltfWriter::finish_output() {
    IndexedMesh mesh = indexer_.take();
    std::vector<float> normals;
    if (options_.normals && mesh.triangle_count() > 0) normals = mesh.smooth_normals();

    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = std::string("meshstream ") + MESHSTREAM_VERSION;
    model.defaultScene = 0;
    model.scenes.emplace_back();
    std::vector<unsigned char> bin;

    if (mesh.triangle_count() > 0) {
        tinygltf::Primitive prim;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Accessor indices, positions, normal_acc;
        indices.type = TINYGLTF_TYPE_SCALAR;
        positions.type = TINYGLTF_TYPE_VEC3;
        positions.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        normal_acc.type = TINYGLTF_TYPE_VEC3;
        normal_acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        size_t index_size = 0;
        Bounds bounds;
#if MESHSTREAM_WITH_DRACO
        if (options_.draco) {
            DracoEncoded enc = encode_draco(mesh, options_.normals ? &normals : nullptr, options_, sink_.name());
            note_ = draco_flattened_note(enc, mesh.triangle_count(), options_);
            append_bytes(bin, enc.bytes.data(), enc.bytes.size());
            tinygltf::BufferView view;
            view.buffer = 0;
            view.byteOffset = 0;
            view.byteLength = enc.bytes.size();
            model.bufferViews.push_back(view);
            indices.componentType = index_component_type(enc.point_count, &index_size);
            indices.count = 3 * enc.face_count;
            positions.count = enc.point_count;
            normal_acc.count = enc.point_count;
            bounds = enc.decoded_bounds;
            tinygltf::Value::Object attrs;
            attrs["POSITION"] = tinygltf::Value(enc.position_id);
            if (options_.normals) attrs["NORMAL"] = tinygltf::Value(enc.normal_id);
            tinygltf::Value::Object ext;
            ext["bufferView"] = tinygltf::Value(0);
            ext["attributes"] = tinygltf::Value(attrs);
            prim.extensions[kDracoExtension] = tinygltf::Value(ext);
            model.extensionsUsed.push_back(kDracoExtension);
            model.extensionsRequired.push_back(kDracoExtension);
        } else
#endif
        {
            // Layout: indices, then positions, then normals; each view 4-byte aligned.
            indices.componentType = index_component_type(mesh.vertex_count(), &index_size);
            indices.count = mesh.indices.size();
            positions.count = mesh.vertex_count();
            normal_acc.count = mesh.vertex_count();
            bounds = mesh.bounds();
            bin.reserve(mesh.indices.size() * index_size + 4 + mesh.positions.size() * 4 + normals.size() * 4);
            for (uint32_t i : mesh.indices) {
                uint8_t le[4] = {uint8_t(i), uint8_t(i >> 8), uint8_t(i >> 16), uint8_t(i >> 24)};
                append_bytes(bin, le, index_size);
            }
            tinygltf::BufferView iv;
            iv.buffer = 0;
            iv.byteOffset = 0;
            iv.byteLength = bin.size();
            iv.target = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
            model.bufferViews.push_back(iv);
            pad4(bin);
            tinygltf::BufferView pv;
            pv.buffer = 0;
            pv.byteOffset = bin.size();
            pv.byteLength = mesh.positions.size() * sizeof(float);
            pv.target = TINYGLTF_TARGET_ARRAY_BUFFER;
            append_bytes(bin, mesh.positions.data(), pv.byteLength);  // little-endian host (x86/ARM)
            model.bufferViews.push_back(pv);
            indices.bufferView = 0;
            positions.bufferView = 1;
            if (options_.normals) {
                tinygltf::BufferView nv = pv;
                nv.byteOffset = bin.size();
                append_bytes(bin, normals.data(), nv.byteLength);
                model.bufferViews.push_back(nv);
                normal_acc.bufferView = 2;
            }
        }
        positions.minValues = {bounds.min[0], bounds.min[1], bounds.min[2]};
        positions.maxValues = {bounds.max[0], bounds.max[1], bounds.max[2]};
        model.accessors.push_back(indices);
        model.accessors.push_back(positions);
        prim.indices = 0;
        prim.attributes["POSITION"] = 1;
        if (options_.normals) {
            model.accessors.push_back(normal_acc);
            prim.attributes["NORMAL"] = 2;
        }
        tinygltf::Mesh m;
        m.primitives.push_back(prim);
        model.meshes.push_back(m);
        tinygltf::Node node;
        node.mesh = 0;
        model.nodes.push_back(node);
        model.scenes[0].nodes.push_back(0);
        model.buffers.emplace_back();  // placeholder: set by document_json
    }
    mesh = IndexedMesh{};

    if (binary_) {
        std::string json = document_json(model, bin.size(), {});
        while (json.size() % 4) json.push_back(' ');
        pad4(bin);
        uint64_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size());
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
        if (!bin.empty()) {
            std::string chunk;
            put_u32(chunk, static_cast<uint32_t>(bin.size()));
            put_u32(chunk, kChunkBin);
            sink_.write(chunk);
            sink_.write(bin.data(), bin.size());
        }
    } else if (bin.empty()) {
        sink_.write(document_json(model, 0, {}));
    } else if (inline_buffer_) {
        std::string uri = "data:application/octet-stream;base64," + base64(bin.data(), bin.size());
        sink_.write(document_json(model, bin.size(), uri));
    } else {
        std::string bin_path = bin_path_for(sink_.name());
        std::string json = document_json(model, bin.size(), uri_encode(base_name(bin_path)));
        // The side file goes through its own ByteSink. Both files are written out in full
        // before either is renamed, so a full disk leaves neither behind (nor an old .gltf
        // beside a new .bin); the caller renames the .gltf right after the .bin.
        std::unique_ptr<ByteSink> side = ByteSink::open(bin_path);
        side->write(bin.data(), bin.size());
        sink_.write(json);
        side->finish_writing();
        sink_.finish_writing();
        side->commit();
    }
}

std::string GltfWriter::document_json(tinygltf::Model& model, uint64_t buffer_bytes, const std::string& buffer_uri) {
    std::ostringstream stream;
    tinygltf::TinyGLTF gltf;
    if (!gltf.WriteGltfSceneToStream(&model, stream, !binary_, false))
        throw Error(sink_.name(), "tinygltf could not serialise the document");
    nlohmann::ordered_json doc = nlohmann::ordered_json::parse(stream.str());
    // tinygltf writes a scene without nodes as null; glTF wants an object.
    if (doc.contains("scenes"))
        for (auto& scene : doc["scenes"])
            if (scene.is_null()) scene = nlohmann::ordered_json::object();
    if (buffer_bytes > 0) {
        nlohmann::ordered_json buffer;
        buffer["byteLength"] = buffer_bytes;
        if (!buffer_uri.empty()) buffer["uri"] = buffer_uri;
        doc["buffers"] = nlohmann::ordered_json::array({buffer});
    } else {
        doc.erase("buffers");
    }
    return doc.dump(binary_ ? -1 : 2) + (binary_ ? "" : "\n");
}


}  // namespace

std::unique_ptr<Writer> open_glb_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<GltfWriter>(sink, options, true);
}

std::vector<std::string> gltf_side_files(const std::string& path, const WriteOptions&) {
    // Written in place (stdout, a pipe, a device), the buffer goes inside, as a data URI.
    return is_stream(path) ? std::vector<std::string>{} : std::vector<std::string>{bin_path_for(path)};
}

std::unique_ptr<Writer> open_gltf_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<GltfWriter>(sink, options, false);
}

}  // namespace meshstream::io::gltf_detail

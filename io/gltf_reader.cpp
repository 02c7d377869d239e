// glTF 2.0 reader on tinygltf (JSON parsing and the document model) and Draco
// (KHR_draco_mesh_compression). tinygltf parses the whole document from memory; the reader
// walks the default scene, decodes each primitive once and hands out world-space triangles.
// See gltf.hpp for the contract.
#include "io/gltf.hpp"
#include "io/gltf_internal.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/text_number.hpp"
#if MESHSTREAM_WITH_DRACO
#include "io/draco.hpp"
#endif

#include <meshoptimizer.h>
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <string_view>

namespace meshstream::io::gltf_detail {
namespace {

// Image bytes by image index, kept as they are (never decoded): a texture is carried to the
// output, not looked at. Images in a bufferView are read later from their buffer, with bounds
// checks (tinygltf hands them over without any).
using ImageBytes = std::map<int, std::vector<std::byte>>;
bool keep_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                const unsigned char* bytes, int size, void* user) {
    if (image->bufferView >= 0 || size <= 0) return true;
    auto* p = reinterpret_cast<const std::byte*>(bytes);
    (*static_cast<ImageBytes*>(user))[index].assign(p, p + size);
    return true;
}

// Required extensions that do not change geometry, or that this reader implements.
bool extension_supported(const std::string& ext) {
#if MESHSTREAM_WITH_DRACO
    if (ext == kDracoExtension) return true;
#endif
    if (ext == kQuantizationExtension || ext == kMeshoptExtension) return true;
    return ext.starts_with("KHR_materials_") || ext.starts_with("KHR_texture_") || ext.starts_with("EXT_texture_") ||
           ext == "KHR_lights_punctual";
}

size_t component_size(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_INT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        default: return 0;
    }
}

int component_count(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        case TINYGLTF_TYPE_VEC4: return 4;
        default: return 0;
    }
}

// a + b for a message, where the two numbers come from a file and their sum may pass 2^64.
std::string sum_text(uint64_t a, uint64_t b) {
    uint64_t sum;
    return __builtin_add_overflow(a, b, &sum) ? std::to_string(a) + " + " + std::to_string(b) : std::to_string(sum);
}

// A bounds-checked window onto one accessor's elements.
struct AccessorView {
    const unsigned char* base = nullptr;  // null: no bufferView, all zeros (glTF 2.0 §3.6.2.4)
    size_t stride = 0, count = 0;
    int component_type = 0, components = 0;
    bool normalized = false;

    double get(size_t i, int c) const {
        if (!base) return 0.0;
        const unsigned char* p = base + i * stride + c * component_size(component_type);
        switch (component_type) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: {
                float f;
                std::memcpy(&f, p, 4);
                return f;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return get_u32(p);
            case TINYGLTF_COMPONENT_TYPE_INT: return static_cast<int32_t>(get_u32(p));
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                double v = uint16_t(p[0] | p[1] << 8);
                return normalized ? v / 65535.0 : v;
            }
            case TINYGLTF_COMPONENT_TYPE_SHORT: {
                double v = int16_t(uint16_t(p[0] | p[1] << 8));
                return normalized ? std::max(v / 32767.0, -1.0) : v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
            case TINYGLTF_COMPONENT_TYPE_BYTE: {
                double v = static_cast<int8_t>(p[0]);
                return normalized ? std::max(v / 127.0, -1.0) : v;
            }
            default: return 0.0;
        }
    }
};

// A primitive in its local space: positions and triangles (strips and fans already unrolled),
// and per vertex the channels the stream carries (each empty when this primitive lacks it).
struct PrimitiveGeometry {
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    std::vector<float> normals;           // 3 per vertex
    std::vector<float> colors;            // 4 per vertex, RGBA 0..1
    std::vector<std::vector<float>> uvs;  // per set: 2 per vertex, glTF's (v down)
};

struct Instance {
    double matrix[16];  // column-major world transform
    int mesh;
    const std::vector<double>* weights;  // morph target weights: the node's, else the mesh's
};

void mat_mul(const double* a, const double* b, double* out) {
    double r[16];
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    std::memcpy(out, r, sizeof r);
}

void local_matrix(const tinygltf::Node& node, double* m) {
    if (node.matrix.size() == 16) {
        for (int i = 0; i < 16; ++i) m[i] = node.matrix[i];
        return;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if (node.translation.size() == 3)
        for (int i = 0; i < 3; ++i) t[i] = node.translation[i];
    if (node.rotation.size() == 4)
        for (int i = 0; i < 4; ++i) q[i] = node.rotation[i];
    if (node.scale.size() == 3)
        for (int i = 0; i < 3; ++i) s[i] = node.scale[i];
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    // Rotation matrix of the unit quaternion (x, y, z, w), columns scaled: M = T · R · S.
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                         2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                         2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
    for (int c = 0; c < 3; ++c) {
        for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
        m[c * 4 + 3] = 0;
    }
    m[12] = t[0];
    m[13] = t[1];
    m[14] = t[2];
    m[15] = 1;
}

double det3(const double* m) {
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

// Required extensions listed in the raw JSON, for a clear refusal when tinygltf itself fails
// on data only the extension explains (EXT_meshopt_compression's fallback buffers).
std::vector<std::string> required_extensions_in(std::string_view json) {
    std::vector<std::string> out;
    auto doc = nlohmann::json::parse(json, nullptr, false);
    if (doc.is_discarded() || !doc.is_object() || !doc.contains("extensionsRequired")) return out;
    for (const auto& e : doc["extensionsRequired"])
        if (e.is_string()) out.push_back(e.get<std::string>());
    return out;
}

// The JSON of a glTF document: the file itself, or a GLB's first chunk (empty when cut short).
std::string_view json_text(const std::vector<unsigned char>& bytes, bool glb) {
    const char* text = reinterpret_cast<const char*>(bytes.data());
    if (!glb) return {text, bytes.size()};
    if (bytes.size() < 20) return {};
    return {text + 20, std::min<size_t>(get_u32(&bytes[12]), bytes.size() - 20)};
}

// Deepest nesting of JSON arrays and objects read. tinygltf (and nlohmann::json under it)
// recurse once per level when turning the parsed JSON into values, so a document of 15 000
// '[' overflowed the stack (SIGSEGV); a glTF document needs about 10 levels, extras a few more.
constexpr size_t kMaxJsonDepth = 512;

// Throws at the first array or object nested deeper than kMaxJsonDepth, before any JSON
// parser sees `json`, which starts at byte `offset` of the file, and at its end when it ends
// inside a string or an open array or object (a cut file: tinygltf said only "JSON string
// too short"). `container` names what ends there: "file" or "JSON chunk". Brackets inside
// strings (with their escapes) do not count; everything else is left to the parser.
void check_json_nesting(std::string_view json, uint64_t offset, const std::string& file, const char* container) {
    size_t depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < json.size(); ++i) {
        const char c = json[i];
        if (in_string) {
            if (c == '\\')
                ++i;  // the escaped character, which may be a quote
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                throw Error(file, offset + i, 0,
                            "JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                                " arrays and objects (a glTF document needs about 10)");
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    if (in_string || depth > 0)
        throw Error(file, offset + json.size(), 0,
                    std::string(container) + " ends inside the JSON document (" + (in_string ? "in a string, " : "") +
                        std::to_string(depth) + (depth == 1 ? " array or object" : " arrays or objects") +
                        " still open)");
}

// Whether some "uri" of the document names something other than a data: URI (a file).
bool names_files(std::string_view json) {
    for (size_t at = json.find("\"uri\""); at != std::string_view::npos; at = json.find("\"uri\"", at + 5)) {
        size_t v = at + 5;
        while (v < json.size() &&
               (json[v] == ' ' || json[v] == '\t' || json[v] == '\r' || json[v] == '\n' || json[v] == ':'))
            ++v;
        if (json.substr(v, 6) != "\"data:") return true;
    }
    return false;
}

// The bytes the document's buffers in other files declare (byteLength of each buffer whose URI
// is not a data: URI): tinygltf reads them whole, past the budget the document itself is held to.
// (Parsed only when some URI names a file: a document with embedded buffers, hundreds of MB of
// base64, is not parsed an extra time.)
uint64_t external_buffer_bytes(std::string_view json) {
    if (!names_files(json)) return 0;
    const auto doc = nlohmann::json::parse(json, nullptr, false);
    uint64_t total = 0;
    if (doc.is_discarded() || !doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return 0;
    for (const auto& b : doc["buffers"]) {
        if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string() || !b.contains("byteLength") ||
            !b["byteLength"].is_number_unsigned())
            continue;
        if (b["uri"].get<std::string>().rfind("data:", 0) == 0) continue;
        total += b["byteLength"].get<uint64_t>();
    }
    return total;
}

// tinygltf looks each buffer (and image) file up in the directory it is given and then in the
// current one ("." is always its second search path), so a .gltf whose sub/a.bin was missing
// quietly read ./a.bin. These file callbacks let through only paths in the document's own
// directory, as glTF's relative URIs mean, and remember the ones missing there for the error.
struct DocumentDir {
    std::string prefix;                // the directory as tinygltf joins it to a URI: "sub/", "./", "/"
    std::vector<std::string> missing;  // paths asked for in it that do not exist
    std::vector<std::string> read;     // paths read (MeshHeader::side_files)
};

bool document_file_exists(const std::string& path, void* user) {
    auto* dir = static_cast<DocumentDir*>(user);
    if (!path.starts_with(dir->prefix)) return false;
    struct stat st;
    if (::stat(path.c_str(), &st) == 0) return true;
    dir->missing.push_back(path);
    return false;
}

// URIs name files as they are: no "~" or "$VAR" expansion (older tinygltf ran wordexp on them).
std::string unexpanded_path(const std::string& path, void*) { return path; }

bool read_document_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    auto* dir = static_cast<DocumentDir*>(user);
    if (!path.starts_with(dir->prefix)) return false;
    dir->read.push_back(path);
    return tinygltf::ReadWholeFile(out, err, path, nullptr);
}

class GltfReader final : public Reader {
public:
    GltfReader(ByteSource& source, const ReadOptions& options)
        : name_(source.name()), budget_bytes_(options.memory_budget_bytes) {
        want_.normals = options.channels.normals;
        want_.colors = options.channels.colors;
        want_.uvs = options.channels.uvs;
        std::vector<unsigned char> bytes;
        unsigned char buf[1 << 16];
        while (size_t n = source.read(buf, sizeof buf)) {
            bytes.insert(bytes.end(), buf, buf + n);
            if (bytes.size() > options.memory_budget_bytes)
                throw Error(name_,
                            "glTF documents are read whole into memory and this one is over the memory budget of " +
                                binary_size(options.memory_budget_bytes) + "; raise " + mention(Setting::kMemory));
        }
        // A cut inside the magic ("g" of "glTF") is a GLB cut short too: no JSON starts so.
        const bool glb = !bytes.empty() && std::memcmp(bytes.data(), kGlbMagic, std::min<size_t>(bytes.size(), 4)) == 0;
        if (glb) {
            // tinygltf tolerates a GLB shorter than its header says when the cut falls in
            // padding; a file that disagrees with its own length is truncated or corrupt.
            if (bytes.size() < 12) throw Error(name_, bytes.size(), 0, "file ends inside the 12-byte GLB header");
            uint32_t stated = get_u32(&bytes[8]);
            if (stated != bytes.size())
                throw Error(name_, 8, 0,
                            "GLB header states " + std::to_string(stated) + " bytes, the file holds " +
                                std::to_string(bytes.size()));
        } else {
            size_t first = 0;
            while (first < bytes.size() && std::isspace(bytes[first])) ++first;
            if (first == bytes.size() || bytes[first] != '{')
                throw Error(name_, first, 0, "not glTF: expected the GLB magic 'glTF' or a JSON object");
        }
        if (!glb && bytes.size() > 0xFFFFFFFFull) throw Error(name_, "glTF JSON over 4 GiB is not supported");
        // Before any JSON parser runs: ours below (Draco indices, buffer sizes) and tinygltf's.
        check_json_nesting(json_text(bytes, glb), glb ? 20 : 0, name_, glb ? "JSON chunk" : "file");
        header_.variant = glb ? "binary (GLB)" : "JSON";

        if (glb) {
            // Where the BIN chunk's data starts in the file (buffer 0), for error positions;
            // taken before the JSON is rewritten below.
            const uint64_t json_end = bytes.size() >= 20 ? 20 + uint64_t{get_u32(&bytes[12])} : 0;
            if (json_end != 0 && json_end + 8 <= bytes.size() && get_u32(&bytes[json_end + 4]) == kChunkBin)
                bin_offset_ = json_end + 8;
        }
        rewrite_for_tinygltf(bytes, glb);
        if (const uint64_t external = external_buffer_bytes(json_text(bytes, glb));
            bytes.size() + external > options.memory_budget_bytes)
            throw Error(name_,
                        "glTF documents are read whole into memory with their buffers: this one and its buffer "
                        "files take " +
                            binary_size(bytes.size() + external) + ", over the memory budget of " +
                            binary_size(options.memory_budget_bytes) + "; raise " + mention(Setting::kMemory));

        tinygltf::TinyGLTF gltf;
        ImageBytes images;
        gltf.SetImageLoader(&keep_image, &images);
        std::string err, warn;
        const std::string base_dir = parent_dir(source.name());  // "." for stdin: the current directory
        DocumentDir files{base_dir.ends_with('/') ? base_dir : base_dir + "/", {}, {}};
        gltf.SetFsCallbacks({&document_file_exists, &unexpanded_path, &read_document_file, nullptr, &files});
        bool ok = glb ? gltf.LoadBinaryFromMemory(&model_, &err, &warn, bytes.data(),
                                                  static_cast<unsigned>(bytes.size()), base_dir)
                      : gltf.LoadASCIIFromString(&model_, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                                 static_cast<unsigned>(bytes.size()), base_dir);
        if (!ok) {
            for (const std::string& ext : required_extensions_in(json_text(bytes, glb)))
                if (!extension_supported(ext)) throw_unsupported_extension(ext);
            for (const std::string& path : files.missing)
                if (err.find("File not found : " + path.substr(files.prefix.size())) != std::string::npos)
                    throw Error(name_, "buffer file " + path + " does not exist (buffer files are read from the " +
                                           (name_ == "<stdin>" ? "current directory for a document on stdin)"
                                                               : "document's directory only)"));
            while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
            // tinygltf quotes the document: a bad data URI came back whole (1.1 MB for the
            // bunny's buffer), with whatever bytes the file held.
            throw Error(name_, "invalid glTF: " +
                                   (err.empty() ? std::string("tinygltf failed to parse it") : printable(err, 400)));
        }
        header_.side_files = files.read;
        bytes = std::vector<unsigned char>();  // the file is parsed: free it (`= {}` keeps the capacity)
        for (const std::string& ext : model_.extensionsRequired)
            if (!extension_supported(ext)) throw_unsupported_extension(ext);

        collect_instances();
        uint64_t triangles = 0;
        for (const Instance& inst : instances_)
            for (size_t p = 0; p < model_.meshes[inst.mesh].primitives.size(); ++p)
                triangles += primitive_triangle_count(inst.mesh, static_cast<int>(p));
        header_.triangle_count = triangles;
        describe_channels(images);
        header_.notes.emplace_back("instances", std::to_string(instances_.size()) + " mesh instance(s) of " +
                                                    std::to_string(model_.meshes.size()) + " mesh(es)");
        if (!model_.asset.generator.empty()) header_.notes.emplace_back("generator", model_.asset.generator);
        // Draco settings, from the first Draco primitive of the scene (decoded now, then cached).
        for (const Instance& inst : instances_) {
            const auto& prims = model_.meshes[inst.mesh].primitives;
            auto it =
                std::find_if(prims.begin(), prims.end(), [this](const tinygltf::Primitive& p) { return is_draco(p); });
            if (it == prims.end()) continue;
            geometry(inst.mesh, static_cast<int>(it - prims.begin()));
            header_.notes.emplace_back("draco", draco_settings_);
            break;
        }
        if (std::string meshopt = meshopt_summary(); !meshopt.empty()) header_.notes.emplace_back("meshopt", meshopt);
        std::string used;
        for (const std::string& e : model_.extensionsUsed) used += (used.empty() ? "" : ", ") + e;
        if (!used.empty()) header_.notes.emplace_back("extensions", used);
    }

    bool next(TriangleChunk& chunk) override;

private:
    void rewrite_for_tinygltf(std::vector<unsigned char>& bytes, bool glb);
    const std::vector<unsigned char>& meshopt_view(int index, const std::string& what) const;
    std::string meshopt_summary() const;
    [[noreturn]] void throw_unsupported_extension(const std::string& ext) const {
#if !MESHSTREAM_WITH_DRACO
        if (ext == kDracoExtension)
            throw Error(name_,
                        "requires extension KHR_draco_mesh_compression, but this meshstream was built without Draco");
#endif
        throw Error(name_, "requires extension " + ext + ", which meshstream does not support");
    }
    std::string where(int mesh, int prim) const {
        std::string s = "mesh " + std::to_string(mesh);
        if (!model_.meshes[mesh].name.empty()) s += " '" + model_.meshes[mesh].name + "'";
        return s + " primitive " + std::to_string(prim);
    }
    void collect_instances();
    void visit(int node, const double* parent, int depth);
    bool is_draco(const tinygltf::Primitive& p) const {
#if MESHSTREAM_WITH_DRACO
        return p.extensions.count(kDracoExtension) > 0;
#else
        (void)p;
        return false;
#endif
    }
    int mode_of(int mesh, int prim) const;
    uint64_t primitive_triangle_count(int mesh, int prim) const;
    AccessorView view(int accessor, const std::string& what) const;
    std::shared_ptr<const PrimitiveGeometry> geometry(int mesh, int prim);
    // Reads vertex attribute `semantic` of a plain primitive into `out` (`per` values a vertex:
    // the accessor's components, then 1 up to `per`, so a VEC3 colour is opaque), checking its
    // component count and element count; nothing when absent or not wanted.
    void read_attribute(const tinygltf::Primitive& p, const std::string& semantic, const std::string& at,
                        size_t vertices, int per, std::vector<float>& out) const;
    void describe_channels(const ImageBytes& images);
    // Whether the vertex attribute `semantic` is decoded: the kinds of channel the caller wants.
    bool wanted(const tinygltf::Primitive&, const std::string& semantic) const {
        if (semantic == "NORMAL") return want_.normals;
        if (semantic == "COLOR_0") return want_.colors;
        return want_.uvs;
    }
    std::optional<Texture> texture_of(const tinygltf::TextureInfo& info, const ImageBytes& images) const;
    void load_current();

    std::string name_;
    uint64_t budget_bytes_;  // --memory
    tinygltf::Model model_;
    std::vector<Instance> instances_;
    std::map<std::pair<int, int>, std::shared_ptr<const PrimitiveGeometry>> draco_cache_;
    std::map<std::pair<int, int>, int> draco_indices_;  // (mesh, primitive) -> hidden indices accessor
    std::string draco_settings_;                        // of the first Draco primitive decoded, for `info`
    std::optional<uint64_t> bin_offset_;                // file offset of a GLB's BIN chunk data (buffer 0)
    std::set<int> fallback_buffers_;                    // EXT_meshopt_compression fallback buffers, which hold no data
    // EXT_meshopt_compression bufferViews decoded so far, and their bytes (held to --memory).
    mutable std::map<int, std::vector<unsigned char>> meshopt_views_;
    mutable uint64_t meshopt_bytes_ = 0;
    // Streaming position: instance, primitive, triangle; world-space positions of the current one.
    size_t inst_ = 0, prim_ = 0, tri_ = 0;
    bool loaded_ = false;
    bool flip_ = false;
    std::shared_ptr<const PrimitiveGeometry> current_;
    std::vector<float> world_;
    std::vector<float> world_normals_;           // the current primitive's normals in world space
    std::vector<std::vector<float>> chunk_uvs_;  // its texture coordinates, transformed, v up
    uint32_t material_ = 0;                      // its index in header_.materials
    uint64_t id_base_ = 0, next_id_ = 0;         // vertex ids: its first, the next primitive's
    // Per glTF material: its base colour texture's KHR_texture_transform (uv' = m · (u, v, 1)),
    // applied to the texture coordinate set the texture reads.
    struct UvTransform {
        int set = 0;
        double m[6] = {1, 0, 0, 0, 1, 0};  // rows (a, b, c), (d, e, f)
    };
    std::vector<std::optional<UvTransform>> uv_transforms_;
    uint32_t default_material_ = 0;  // header_.materials index of glTF's default material
    struct {
        bool normals = true, colors = true, uvs = true;
    } want_;
};

// Rewrites what tinygltf 2.7 cannot parse as it is, before it does, and remembers what was taken:
// - KHR_draco_mesh_compression primitives have an index accessor without a bufferView (the
//   indices live in the Draco blob), which tinygltf rejects ("accessor[0] invalid bufferView"):
//   their "indices" are taken out and remembered in draco_indices_ (they only state the count);
// - EXT_meshopt_compression's fallback buffers have no data (no "uri", and not the GLB's BIN
//   chunk) when the extension is required, which tinygltf cannot load: they become one-byte
//   data URIs, remembered in fallback_buffers_, and their bufferViews are decoded from the
//   compressed data instead.
void GltfReader::rewrite_for_tinygltf(std::vector<unsigned char>& bytes, bool glb) {
    size_t json_begin = 0, json_size = bytes.size();
    if (glb) {
        if (bytes.size() < 20 || get_u32(&bytes[16]) != kChunkJson) return;  // tinygltf reports it
        json_begin = 20;
        json_size = get_u32(&bytes[12]);
        if (json_size > bytes.size() - 20) return;
    }
    std::string_view json(reinterpret_cast<const char*>(bytes.data()) + json_begin, json_size);
    if (json.find(kDracoExtension) == std::string_view::npos && json.find(kMeshoptExtension) == std::string_view::npos)
        return;
    auto doc = nlohmann::ordered_json::parse(json, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return;
    bool changed = false;
    if (doc.contains("meshes") && doc["meshes"].is_array()) {
        for (size_t m = 0; m < doc["meshes"].size(); ++m) {
            auto& mesh = doc["meshes"][m];
            if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
            for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
                auto& prim = mesh["primitives"][p];
                if (!prim.is_object() || !prim.contains("extensions") || !prim["extensions"].is_object() ||
                    !prim["extensions"].contains(kDracoExtension) || !prim.contains("indices") ||
                    !prim["indices"].is_number_integer())
                    continue;
                draco_indices_[{int(m), int(p)}] = prim["indices"].get<int>();
                prim.erase("indices");
                changed = true;
            }
        }
    }
    if (doc.contains("buffers") && doc["buffers"].is_array()) {
        for (size_t b = 0; b < doc["buffers"].size(); ++b) {
            auto& buffer = doc["buffers"][b];
            if (!buffer.is_object() || buffer.contains("uri") || (glb && b == 0) || !buffer.contains("extensions") ||
                !buffer["extensions"].is_object() || !buffer["extensions"].contains(kMeshoptExtension))
                continue;
            const auto& ext = buffer["extensions"][kMeshoptExtension];
            if (!ext.is_object() || !ext.contains("fallback") || ext["fallback"] != true) continue;
            // One zero byte: tinygltf refuses an empty data URI.
            buffer["uri"] = "data:application/octet-stream;base64,AA==";
            buffer["byteLength"] = 1;
            fallback_buffers_.insert(int(b));
            changed = true;
        }
    }
    if (!changed) return;
    std::string text = doc.dump();
    if (!glb) {
        bytes.assign(text.begin(), text.end());
        return;
    }
    while (text.size() % 4) text.push_back(' ');
    std::string head;
    head.append(kGlbMagic, 4);
    put_u32(head, 2);
    const size_t rest = bytes.size() - 20 - json_size;  // the BIN chunk and anything after
    put_u32(head, static_cast<uint32_t>(20 + text.size() + rest));
    put_u32(head, static_cast<uint32_t>(text.size()));
    put_u32(head, kChunkJson);
    std::vector<unsigned char> out;
    out.reserve(head.size() + text.size() + rest);
    out.insert(out.end(), head.begin(), head.end());
    out.insert(out.end(), text.begin(), text.end());
    out.insert(out.end(), bytes.begin() + 20 + json_size, bytes.end());
    bytes.swap(out);
}

namespace {

// An unsigned integer member of an extension object, `fallback` when absent; nullopt when
// present but not a non-negative integer.
std::optional<uint64_t> unsigned_member(const tinygltf::Value& object, const char* key,
                                        std::optional<uint64_t> fallback) {
    if (!object.Has(key)) return fallback;
    const tinygltf::Value& v = object.Get(key);
    if (v.IsInt() && v.Get<int>() >= 0) return uint64_t(v.Get<int>());
    if (v.IsNumber()) {
        const double d = v.GetNumberAsDouble();
        if (d >= 0 && d < 18446744073709551616.0 && d == std::floor(d)) return uint64_t(d);
    }
    return std::nullopt;
}

}  // namespace

// EXT_meshopt_compression: the bufferView's data, decoded once from its compressed copy with
// libmeshoptimizer's decoders and filters and cached. Every parameter the decoders assert on is
// checked first, so bad input is an io::Error (naming the bufferView and where its compressed
// bytes lie) and never reaches an assertion or a read out of bounds.
const std::vector<unsigned char>& GltfReader::meshopt_view(int index, const std::string& what) const {
    if (auto it = meshopt_views_.find(index); it != meshopt_views_.end()) return it->second;
    const tinygltf::BufferView& bv = model_.bufferViews[index];
    const tinygltf::Value& ext = bv.extensions.at(kMeshoptExtension);
    const std::string at = what + ": bufferView " + std::to_string(index) + " (EXT_meshopt_compression)";
    if (!ext.IsObject()) throw Error(name_, at + " is not a JSON object");
    const auto buffer = unsigned_member(ext, "buffer", std::nullopt);
    const auto offset = unsigned_member(ext, "byteOffset", 0),
               length = unsigned_member(ext, "byteLength", std::nullopt);
    const auto stride = unsigned_member(ext, "byteStride", std::nullopt),
               count = unsigned_member(ext, "count", std::nullopt);
    for (const auto& [value, key] :
         {std::pair{buffer, "buffer"}, std::pair{offset, "byteOffset"}, std::pair{length, "byteLength"},
          std::pair{stride, "byteStride"}, std::pair{count, "count"}})
        if (!value) throw Error(name_, at + " needs '" + key + "' as a non-negative integer");
    const std::string mode = ext.Get("mode").IsString() ? ext.Get("mode").Get<std::string>() : std::string();
    const std::string filter = !ext.Has("filter")             ? std::string("NONE")
                               : ext.Get("filter").IsString() ? ext.Get("filter").Get<std::string>()
                                                              : std::string("?");
    if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
        throw Error(name_, at + " has mode '" + printable(mode, 40) + "' (one of ATTRIBUTES, TRIANGLES, INDICES)");
    if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
        throw Error(name_, at + " has filter '" + printable(filter, 40) +
                               "' (one of NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL)");
    // The spec's limits, which are also libmeshoptimizer's preconditions (asserted there).
    if (mode == "ATTRIBUTES" && (*stride == 0 || *stride > 256 || *stride % 4 != 0))
        throw Error(name_, at + ": ATTRIBUTES with byteStride " + std::to_string(*stride) +
                               " (must be a multiple of 4, 4-256)");
    if (mode != "ATTRIBUTES" && *stride != 2 && *stride != 4)
        throw Error(name_, at + ": " + mode + " with byteStride " + std::to_string(*stride) + " (must be 2 or 4)");
    if (mode == "TRIANGLES" && *count % 3 != 0)
        throw Error(name_, at + ": TRIANGLES with count " + std::to_string(*count) + ", not a multiple of 3");
    if (filter != "NONE" && mode != "ATTRIBUTES")
        throw Error(name_, at + ": filter " + filter + " with mode " + mode + " (filters apply to ATTRIBUTES only)");
    if ((filter == "OCTAHEDRAL" && *stride != 4 && *stride != 8) || (filter == "QUATERNION" && *stride != 8))
        throw Error(name_, at + ": filter " + filter + " with byteStride " + std::to_string(*stride) + " (must be " +
                               (filter == "QUATERNION" ? "8)" : "4 or 8)"));
    if (mode == "ATTRIBUTES" && bv.byteStride != 0 && bv.byteStride != *stride)
        throw Error(name_, at + " has byteStride " + std::to_string(*stride) + ", its bufferView " +
                               std::to_string(bv.byteStride));
    uint64_t decoded_bytes = 0;
    if (__builtin_mul_overflow(*count, *stride, &decoded_bytes) || decoded_bytes != bv.byteLength)
        throw Error(name_, at + " decodes to count " + std::to_string(*count) + " x byteStride " +
                               std::to_string(*stride) + " bytes, but its bufferView's byteLength is " +
                               std::to_string(bv.byteLength));
    if (*buffer >= model_.buffers.size())
        throw Error(name_, at + " refers to buffer " + std::to_string(*buffer) + ", which does not exist");
    if (fallback_buffers_.count(int(*buffer)))
        throw Error(name_, at + " refers to buffer " + std::to_string(*buffer) + ", a fallback buffer without data");
    const std::vector<unsigned char>& data = model_.buffers[*buffer].data;
    if (*offset > data.size() || *length > data.size() - *offset)
        throw Error(name_, at + ": compressed bytes " + sum_text(*offset, 0) + " to " + sum_text(*offset, *length) +
                               " lie outside buffer " + std::to_string(*buffer) + " (" + std::to_string(data.size()) +
                               " bytes)");
    if (decoded_bytes > budget_bytes_ || meshopt_bytes_ + decoded_bytes > budget_bytes_)
        throw Error(name_, at + " decodes to " + binary_size(decoded_bytes) + ", which with the views decoded before " +
                               "passes the memory budget of " + binary_size(budget_bytes_) + "; raise " +
                               mention(Setting::kMemory));
    std::vector<unsigned char> out(decoded_bytes);
    const unsigned char* src = data.data() + *offset;
    int rc = 0;
    if (mode == "ATTRIBUTES")
        rc = meshopt_decodeVertexBuffer(out.data(), *count, *stride, src, *length);
    else if (mode == "TRIANGLES")
        rc = meshopt_decodeIndexBuffer(out.data(), *count, *stride, src, *length);
    else
        rc = meshopt_decodeIndexSequence(out.data(), *count, *stride, src, *length);
    if (rc != 0) {
        // Where the compressed bytes start: in the file for a GLB's own buffer, else in the buffer.
        const bool in_file = *buffer == 0 && bin_offset_ && model_.buffers[0].uri.empty();
        const std::string where = in_file ? std::string()
                                          : " (bytes " + std::to_string(*offset) + " to " + sum_text(*offset, *length) +
                                                " of buffer " + std::to_string(*buffer) + ")";
        throw Error(name_, in_file ? *bin_offset_ + *offset : 0, 0,
                    at + where + ": the compressed " + (mode == "ATTRIBUTES" ? "vertex" : "index") +
                        " data is corrupt or cut short (" + std::to_string(*length) + " bytes for " +
                        std::to_string(*count) + " " + (mode == "ATTRIBUTES" ? "elements" : "indices") + " of " +
                        std::to_string(*stride) + " bytes; libmeshoptimizer's " +
                        (mode == "ATTRIBUTES"  ? "meshopt_decodeVertexBuffer"
                         : mode == "TRIANGLES" ? "meshopt_decodeIndexBuffer"
                                               : "meshopt_decodeIndexSequence") +
                        " returned " + std::to_string(rc) + ")");
    }
    if (filter == "OCTAHEDRAL")
        meshopt_decodeFilterOct(out.data(), *count, *stride);
    else if (filter == "QUATERNION")
        meshopt_decodeFilterQuat(out.data(), *count, *stride);
    else if (filter == "EXPONENTIAL")
        meshopt_decodeFilterExp(out.data(), *count, *stride);
    meshopt_bytes_ += decoded_bytes;
    return meshopt_views_.emplace(index, std::move(out)).first->second;
}

// For `info`: how many bufferViews are compressed, by mode and filter, and their sizes.
std::string GltfReader::meshopt_summary() const {
    std::map<std::string, int> kinds;
    uint64_t compressed = 0, decoded = 0;
    for (const tinygltf::BufferView& bv : model_.bufferViews) {
        auto it = bv.extensions.find(kMeshoptExtension);
        if (it == bv.extensions.end() || !it->second.IsObject()) continue;
        const tinygltf::Value& ext = it->second;
        std::string kind = ext.Get("mode").IsString() ? ext.Get("mode").Get<std::string>() : "?";
        if (ext.Get("filter").IsString() && ext.Get("filter").Get<std::string>() != "NONE")
            kind += "+" + ext.Get("filter").Get<std::string>();
        ++kinds[kind];
        compressed += unsigned_member(ext, "byteLength", 0).value_or(0);
        decoded += bv.byteLength;
    }
    if (kinds.empty()) return {};
    std::string out;
    for (const auto& [kind, n] : kinds) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
    return out + " buffer view(s), " + binary_size(compressed) + " compressed, " + binary_size(decoded) + " decoded";
}

void GltfReader::collect_instances() {
    const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    if (model_.scenes.empty()) {
        // No scene: nothing says how meshes are placed; take each mesh once, untransformed.
        for (size_t m = 0; m < model_.meshes.size(); ++m) {
            Instance inst;
            std::memcpy(inst.matrix, identity, sizeof identity);
            inst.mesh = static_cast<int>(m);
            inst.weights = &model_.meshes[m].weights;
            instances_.push_back(inst);
        }
        return;
    }
    int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (scene >= static_cast<int>(model_.scenes.size()))
        throw Error(name_, "default scene " + std::to_string(scene) + " does not exist");
    for (int node : model_.scenes[scene].nodes) visit(node, identity, 0);
}

void GltfReader::visit(int node, const double* parent, int depth) {
    if (node < 0 || node >= static_cast<int>(model_.nodes.size()))
        throw Error(name_, "scene refers to node " + std::to_string(node) + ", which does not exist");
    if (depth > static_cast<int>(model_.nodes.size()))
        throw Error(name_, "node hierarchy has a cycle at node " + std::to_string(node));
    const tinygltf::Node& n = model_.nodes[node];
    double local[16], world[16];
    local_matrix(n, local);
    mat_mul(parent, local, world);
    if (n.mesh >= 0) {
        if (n.mesh >= static_cast<int>(model_.meshes.size()))
            throw Error(name_, "node " + std::to_string(node) + " refers to mesh " + std::to_string(n.mesh) +
                                   ", which does not exist");
        Instance inst;
        // glTF 2.0 §3.7.3.3: a skinned mesh ignores its node's transform (only joints move it).
        // Joint transforms are not applied: the mesh is read in its bind pose, as stored.
        static constexpr double kIdentity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        std::memcpy(inst.matrix, n.skin >= 0 ? kIdentity : world, sizeof world);
        inst.mesh = n.mesh;
        inst.weights = n.weights.empty() ? &model_.meshes[n.mesh].weights : &n.weights;
        instances_.push_back(inst);
    }
    for (int child : n.children) visit(child, world, depth + 1);
}

// The stream's channels, from the primitives the scene instances: a channel is present when
// any of them has it, and primitives without it give its default (normal (0, 0, 0), colour
// opaque white, texture coordinates (0, 0)). Colour keeps the accessors' type when they all
// agree (float, normalized ubyte or ushort), else travels as float; alpha when any is VEC4.
// Materials: the document's, with glTF's default material appended for primitives without one.
void GltfReader::describe_channels(const ImageBytes& images) {
    Channels& ch = header_.channels;
    ch.vertex_id = true;  // primitive and vertex: seams and split vertices stay apart
    bool with_material = false, without_material = false, first_color = true;
    for (const Instance& inst : instances_)
        for (size_t pi = 0; pi < model_.meshes[inst.mesh].primitives.size(); ++pi) {
            const tinygltf::Primitive& p = model_.meshes[inst.mesh].primitives[pi];
            ch.normal = ch.normal || p.attributes.count("NORMAL") > 0;
            if (auto it = p.attributes.find("COLOR_0"); it != p.attributes.end()) {
                if (it->second < 0 || it->second >= int(model_.accessors.size()))
                    throw Error(name_, where(inst.mesh, int(pi)) + " COLOR_0 refers to accessor " +
                                           std::to_string(it->second) + ", which does not exist");
                const tinygltf::Accessor& a = model_.accessors[it->second];
                const ScalarType t = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? ScalarType::kUInt8
                                     : a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? ScalarType::kUInt16
                                                                                                 : ScalarType::kFloat32;
                ColorFormat f = ch.color.value_or(ColorFormat{t, false});
                if (!first_color && f.type != t) f.type = ScalarType::kFloat32;
                f.alpha = f.alpha || a.type == TINYGLTF_TYPE_VEC4;
                ch.color = f;
                first_color = false;
            }
            for (int s = 0; s < kMaxUvSets && p.attributes.count("TEXCOORD_" + std::to_string(s)); ++s)
                ch.uv_sets = std::max(ch.uv_sets, s + 1);
            if (p.material >= int(model_.materials.size()))
                throw Error(name_, where(inst.mesh, int(pi)) + " refers to material " + std::to_string(p.material) +
                                       ", which does not exist");
            (p.material >= 0 ? with_material : without_material) = true;
        }
    if (!with_material) return;
    ch.material = true;
    uv_transforms_.resize(model_.materials.size());
    for (size_t i = 0; i < model_.materials.size(); ++i) {
        const tinygltf::Material& gm = model_.materials[i];
        Material m;
        m.name = gm.name.empty() ? "material" + std::to_string(i) : gm.name;
        const auto& pbr = gm.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() == 4)
            for (int c = 0; c < 4; ++c) m.base_color[c] = static_cast<float>(pbr.baseColorFactor[c]);
        m.texture = texture_of(pbr.baseColorTexture, images);
        if (pbr.baseColorTexture.index >= 0) {
            UvTransform t;
            t.set = pbr.baseColorTexture.texCoord;
            auto ext = pbr.baseColorTexture.extensions.find("KHR_texture_transform");
            if (ext != pbr.baseColorTexture.extensions.end() && ext->second.IsObject()) {
                const tinygltf::Value& x = ext->second;
                auto number = [](const tinygltf::Value& v, size_t k, double fallback) {
                    return v.IsArray() && v.ArrayLen() > k && v.Get(int(k)).IsNumber()
                               ? v.Get(int(k)).GetNumberAsDouble()
                               : fallback;
                };
                const double ox = number(x.Get("offset"), 0, 0), oy = number(x.Get("offset"), 1, 0);
                const double sx = number(x.Get("scale"), 0, 1), sy = number(x.Get("scale"), 1, 1);
                const double r = x.Get("rotation").IsNumber() ? x.Get("rotation").GetNumberAsDouble() : 0.0;
                if (x.Get("texCoord").IsInt()) t.set = x.Get("texCoord").Get<int>();
                // KHR_texture_transform: uv' = T · R · S · uv, R = [cos r, sin r; -sin r, cos r].
                const double c = std::cos(r), sn = std::sin(r);
                const double m6[6] = {c * sx, sn * sy, ox, -sn * sx, c * sy, oy};
                std::copy(m6, m6 + 6, t.m);
                uv_transforms_[i] = t;
            }
        }
        header_.materials.push_back(std::move(m));
    }
    default_material_ = uint32_t(header_.materials.size());
    if (without_material) header_.materials.push_back(Material{"default", {1, 1, 1, 1}, std::nullopt});
}

// The image a texture reference names, with its bytes: from its bufferView (bounds checked),
// a data: URI or a file beside the document (tinygltf read those). Null without a texture;
// without bytes when the image could not be read.
std::optional<Texture> GltfReader::texture_of(const tinygltf::TextureInfo& info, const ImageBytes& images) const {
    if (info.index < 0 || info.index >= int(model_.textures.size())) return std::nullopt;
    const int source = model_.textures[info.index].source;
    if (source < 0 || source >= int(model_.images.size())) return std::nullopt;
    const tinygltf::Image& image = model_.images[source];
    Texture t;
    t.uri = !image.uri.empty() ? image.uri : image.name;
    t.mime_type = image.mimeType;
    if (t.mime_type.empty()) {
        std::string lower = image.uri;
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (lower.ends_with(".png"))
            t.mime_type = "image/png";
        else if (lower.ends_with(".jpg") || lower.ends_with(".jpeg"))
            t.mime_type = "image/jpeg";
    }
    if (image.bufferView >= 0) {
        if (image.bufferView >= int(model_.bufferViews.size())) return t;
        const tinygltf::BufferView& bv = model_.bufferViews[image.bufferView];
        if (bv.buffer < 0 || bv.buffer >= int(model_.buffers.size()) || fallback_buffers_.count(bv.buffer)) return t;
        const auto& data = model_.buffers[bv.buffer].data;
        if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset) return t;
        const auto* p = reinterpret_cast<const std::byte*>(data.data() + bv.byteOffset);
        t.bytes.assign(p, p + bv.byteLength);
    } else if (auto it = images.find(source); it != images.end()) {
        t.bytes = it->second;
    }
    return t;
}

int GltfReader::mode_of(int mesh, int prim) const {
    int mode = model_.meshes[mesh].primitives[prim].mode;
    if (mode == -1) mode = TINYGLTF_MODE_TRIANGLES;  // the default when absent
    static const char* kNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    if (mode >= 0 && mode <= 3)
        throw Error(name_, where(mesh, prim) + " has mode " + kNames[mode] + " (" + std::to_string(mode) +
                               "); only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN are supported");
    if (mode > 6) throw Error(name_, where(mesh, prim) + " has unknown mode " + std::to_string(mode));
    if (is_draco(model_.meshes[mesh].primitives[prim]) && mode != TINYGLTF_MODE_TRIANGLES)
        throw Error(name_, where(mesh, prim) + ": KHR_draco_mesh_compression with mode " + std::to_string(mode) +
                               " is not supported (only TRIANGLES)");
    return mode;
}

uint64_t GltfReader::primitive_triangle_count(int mesh, int prim) const {
    const tinygltf::Primitive& p = model_.meshes[mesh].primitives[prim];
    int mode = mode_of(mesh, prim);
    auto pos = p.attributes.find("POSITION");
    if (pos == p.attributes.end()) throw Error(name_, where(mesh, prim) + " has no POSITION attribute");
    int acc = p.indices >= 0 ? p.indices : pos->second;
    if (auto hidden = draco_indices_.find({mesh, prim}); hidden != draco_indices_.end()) acc = hidden->second;
    if (acc < 0 || acc >= static_cast<int>(model_.accessors.size()))
        throw Error(name_, where(mesh, prim) + " refers to accessor " + std::to_string(acc) + ", which does not exist");
    uint64_t n = model_.accessors[acc].count;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3)
            throw Error(name_,
                        where(mesh, prim) + ": TRIANGLES with " + std::to_string(n) + " vertices, not a multiple of 3");
        return n / 3;
    }
    return n >= 3 ? n - 2 : 0;
}

AccessorView GltfReader::view(int accessor, const std::string& what) const {
    if (accessor < 0 || accessor >= static_cast<int>(model_.accessors.size()))
        throw Error(name_, what + " refers to accessor " + std::to_string(accessor) + ", which does not exist");
    const tinygltf::Accessor& a = model_.accessors[accessor];
    std::string where_acc = what + " (accessor " + std::to_string(accessor) + ")";
    if (a.sparse.isSparse) throw Error(name_, where_acc + " is sparse; sparse accessors are not supported");
    AccessorView v;
    v.count = a.count;
    v.component_type = a.componentType;
    v.components = component_count(a.type);
    v.normalized = a.normalized;
    size_t csize = component_size(a.componentType);
    if (csize == 0 || v.components == 0)
        throw Error(name_, where_acc + " has unsupported component type " + std::to_string(a.componentType) +
                               " / type " + std::to_string(a.type));
    if (a.bufferView < 0) {
        // All zeros: nothing is stored, so only the count bounds what is decoded (4 bytes a
        // component), and a 200-byte file could ask for 8 GB, or for 2^64 / 3 + 1 vertices,
        // whose float count wrapped to 2 and was written past. Held to --memory, as files are.
        if (a.count > budget_bytes_ / (4 * uint64_t(v.components)))
            throw Error(name_, where_acc + " has no bufferView (all zeros) and count " + std::to_string(a.count) +
                                   ", over the memory budget of " + binary_size(budget_bytes_) +
                                   " once decoded; raise " + mention(Setting::kMemory));
        return v;
    }
    if (a.bufferView >= static_cast<int>(model_.bufferViews.size()))
        throw Error(name_,
                    where_acc + " refers to bufferView " + std::to_string(a.bufferView) + ", which does not exist");
    const tinygltf::BufferView& bv = model_.bufferViews[a.bufferView];
    const bool meshopt = bv.extensions.count(kMeshoptExtension) > 0;
    if (!meshopt && (bv.buffer < 0 || bv.buffer >= static_cast<int>(model_.buffers.size())))
        throw Error(name_, where_acc + ": bufferView refers to a missing buffer");
    if (!meshopt && fallback_buffers_.count(bv.buffer))
        throw Error(name_, where_acc + ": bufferView " + std::to_string(a.bufferView) + " lies in buffer " +
                               std::to_string(bv.buffer) + ", an EXT_meshopt_compression fallback buffer without data");
    // A compressed view is decoded whole; its bytes then stand for the view (offset 0).
    const std::vector<unsigned char>& data =
        meshopt ? meshopt_view(a.bufferView, where_acc) : model_.buffers[bv.buffer].data;
    const size_t elem = csize * v.components;
    // glTF 2.0 §3.6.2.4: a stride spaces elements apart, it never overlaps them (the validator's
    // ACCESSOR_SMALL_BYTESTRIDE); byteStride 4 under VEC3 floats read each from the last one's y.
    if (bv.byteStride != 0 && bv.byteStride < elem)
        throw Error(name_, where_acc + ": bufferView " + std::to_string(a.bufferView) + " has byteStride " +
                               std::to_string(bv.byteStride) + ", less than the accessor's " + std::to_string(elem) +
                               "-byte elements");
    v.stride = bv.byteStride ? bv.byteStride : elem;
    // Offsets, lengths and the count are 64-bit numbers from the JSON, so no sum or product of
    // them may wrap: a byteOffset near 2^64 made the view start before its buffer.
    const uint64_t view_offset = meshopt ? 0 : bv.byteOffset, view_length = bv.byteLength;
    if (view_offset > data.size() || view_length > data.size() - view_offset)
        throw Error(name_, where_acc + ": bufferView " + std::to_string(a.bufferView) + " ends at byte " +
                               sum_text(view_offset, view_length) + ", past the end of buffer " +
                               std::to_string(bv.buffer) + " (" + std::to_string(data.size()) + " bytes)");
    uint64_t end = a.byteOffset, span = 0;  // the end of the last element, from the view's start
    const bool wraps =
        a.count > 0 && (__builtin_mul_overflow(uint64_t{a.count - 1}, uint64_t{v.stride}, &span) ||
                        __builtin_add_overflow(span, uint64_t{elem}, &span) || __builtin_add_overflow(end, span, &end));
    if (wraps || end > view_length)
        throw Error(name_, where_acc + " reaches byte " +
                               (wraps ? std::string("2^64 or more") : sum_text(view_offset, end)) +
                               " of a buffer view ending at " + std::to_string(view_offset + view_length));
    v.base = data.data() + view_offset + a.byteOffset;
    return v;
}

std::shared_ptr<const PrimitiveGeometry> GltfReader::geometry(int mesh, int prim) {
    const tinygltf::Primitive& p = model_.meshes[mesh].primitives[prim];
    const int mode = mode_of(mesh, prim);
    const std::string at = where(mesh, prim);
    auto geo = std::make_shared<PrimitiveGeometry>();
#if MESHSTREAM_WITH_DRACO
    if (is_draco(p)) {
        auto cached = draco_cache_.find({mesh, prim});
        if (cached != draco_cache_.end()) return cached->second;
        const tinygltf::Value& ext = p.extensions.at(kDracoExtension);
        const tinygltf::Value& bvv = ext.Get("bufferView");
        const tinygltf::Value& attrs = ext.Get("attributes");
        if (!bvv.IsInt() || !attrs.IsObject() || !attrs.Get("POSITION").IsInt())
            throw Error(name_, at + ": KHR_draco_mesh_compression needs an integer bufferView and attributes.POSITION");
        int bvi = bvv.Get<int>();
        if (bvi < 0 || bvi >= static_cast<int>(model_.bufferViews.size()))
            throw Error(name_, at + ": KHR_draco_mesh_compression refers to bufferView " + std::to_string(bvi) +
                                   ", which does not exist");
        const tinygltf::BufferView& bv = model_.bufferViews[bvi];
        if (bv.buffer < 0 || bv.buffer >= static_cast<int>(model_.buffers.size()) ||
            bv.byteOffset > model_.buffers[bv.buffer].data.size() ||
            bv.byteLength > model_.buffers[bv.buffer].data.size() - bv.byteOffset)  // no sum to wrap
            throw Error(name_, at + ": KHR_draco_mesh_compression bufferView " + std::to_string(bvi) +
                                   " lies outside its buffer");
        const auto* start = reinterpret_cast<const std::byte*>(model_.buffers[bv.buffer].data.data() + bv.byteOffset);
        DracoDecoded d;
        try {
            d = decode_draco({start, bv.byteLength}, name_, 0, attrs.Get("POSITION").Get<int>());
        } catch (const Error& e) {
            throw Error(name_, at + " (KHR_draco_mesh_compression): " + e.raw_message());
        }
        uint64_t stated = primitive_triangle_count(mesh, prim);
        if (d.indices.size() / 3 != stated)
            throw Error(name_, at + ": accessors state " + std::to_string(stated) +
                                   " triangles, the Draco data holds " + std::to_string(d.indices.size() / 3));
        if (draco_settings_.empty())
            draco_settings_ =
                "bitstream " + std::to_string(d.version_major) + "." + std::to_string(d.version_minor) + ", " +
                (d.edgebreaker ? "edgebreaker" : "sequential") + " connectivity, positions " +
                (d.position_bits ? std::to_string(d.position_bits) + " bits" : std::string("not quantized")) + " (" +
                at + ")";
        geo->positions = std::move(d.positions);
        geo->triangles = std::move(d.indices);
        // The other attributes the extension maps (semantic -> Draco unique id), per point.
        const size_t points = geo->positions.size() / 3;
        auto take = [&](const std::string& semantic, int min_components, int max_components, int per,
                        std::vector<float>& out) {
            const tinygltf::Value& id = attrs.Get(semantic);
            if (!id.IsInt() || !wanted(p, semantic)) return;
            auto it = std::find_if(d.attributes.begin(), d.attributes.end(),
                                   [&](const DracoAttribute& a) { return a.unique_id == id.Get<int>(); });
            if (it == d.attributes.end())
                throw Error(name_, at + ": KHR_draco_mesh_compression maps " + semantic + " to Draco attribute " +
                                       std::to_string(id.Get<int>()) + ", which the Draco data does not hold");
            if (it->components < min_components || it->components > max_components ||
                it->values.size() != points * it->components)
                throw Error(name_, at + ": the Draco attribute of " + semantic + " has " +
                                       std::to_string(it->components) + " components");
            out.assign(points * per, 1.0f);
            for (size_t v = 0; v < points; ++v)
                for (int c = 0; c < it->components; ++c) out[v * per + c] = float(it->values[v * it->components + c]);
        };
        take("NORMAL", 3, 3, 3, geo->normals);
        take("COLOR_0", 3, 4, 4, geo->colors);
        for (int s = 0; s < header_.channels.uv_sets; ++s) {
            geo->uvs.emplace_back();
            take("TEXCOORD_" + std::to_string(s), 2, 2, 2, geo->uvs.back());
        }
        draco_cache_[{mesh, prim}] = geo;
        return geo;
    }
#endif
    AccessorView pos = view(p.attributes.at("POSITION"), at + " POSITION");
    if (pos.components != 3) throw Error(name_, at + " POSITION is not VEC3");
    if (pos.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT) {
        bool quantized = std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(),
                                   kQuantizationExtension) != model_.extensionsUsed.end();
        bool integer = pos.component_type != TINYGLTF_COMPONENT_TYPE_INT &&
                       pos.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        if (!quantized || !integer)
            throw Error(name_, at + " POSITION has component type " + std::to_string(pos.component_type) +
                                   " (allowed: FLOAT, or 8/16-bit integers with KHR_mesh_quantization)");
    }
    geo->positions.resize(pos.count * 3);
    for (size_t i = 0; i < pos.count; ++i)
        for (int c = 0; c < 3; ++c) geo->positions[3 * i + c] = static_cast<float>(pos.get(i, c));

    read_attribute(p, "NORMAL", at, pos.count, 3, geo->normals);
    read_attribute(p, "COLOR_0", at, pos.count, 4, geo->colors);
    for (int s = 0; s < header_.channels.uv_sets; ++s) {
        geo->uvs.emplace_back();
        read_attribute(p, "TEXCOORD_" + std::to_string(s), at, pos.count, 2, geo->uvs.back());
    }

    std::vector<uint32_t> order;  // the vertex sequence the mode walks
    if (p.indices >= 0) {
        AccessorView idx = view(p.indices, at + " indices");
        if (idx.components != 1 || (idx.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                    idx.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                    idx.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
            throw Error(name_, at + " indices must be unsigned byte/short/int scalars");
        order.resize(idx.count);
        for (size_t i = 0; i < idx.count; ++i) {
            double v = idx.get(i, 0);
            if (v >= static_cast<double>(pos.count))
                throw Error(name_, at + " index " + std::to_string(i) + " is " + std::to_string(uint64_t(v)) +
                                       ", but POSITION has " + std::to_string(pos.count) + " vertices");
            order[i] = static_cast<uint32_t>(v);
        }
    } else {
        order.resize(pos.count);
        for (size_t i = 0; i < pos.count; ++i) order[i] = static_cast<uint32_t>(i);
    }
    const size_t n = order.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        geo->triangles = std::move(order);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // glTF 2.0 §3.7.2.1: triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}), keeping one winding.
        for (size_t i = 0; i + 2 < n; ++i) {
            uint32_t t[3] = {order[i], order[i + 1 + i % 2], order[i + 2 - i % 2]};
            geo->triangles.insert(geo->triangles.end(), t, t + 3);
        }
    } else {  // TRIANGLE_FAN: (v_{i+1}, v_{i+2}, v_0)
        for (size_t i = 0; i + 2 < n; ++i) {
            uint32_t t[3] = {order[i + 1], order[i + 2], order[0]};
            geo->triangles.insert(geo->triangles.end(), t, t + 3);
        }
    }
    return geo;
}

void GltfReader::read_attribute(const tinygltf::Primitive& p, const std::string& semantic, const std::string& at,
                                size_t vertices, int per, std::vector<float>& out) const {
    auto it = p.attributes.find(semantic);
    if (it == p.attributes.end() || !wanted(p, semantic)) return;
    const AccessorView a = view(it->second, at + " " + semantic);
    const int want_min = semantic == "COLOR_0" ? 3 : per;
    if (a.components < want_min || a.components > per)
        throw Error(name_, at + " " + semantic + " (accessor " + std::to_string(it->second) + ") has " +
                               std::to_string(a.components) + " components, not " +
                               (want_min == per ? std::to_string(per) : "3 or 4"));
    if (a.count != vertices)
        throw Error(name_, at + " " + semantic + " (accessor " + std::to_string(it->second) + ") has " +
                               std::to_string(a.count) + " elements, POSITION " + std::to_string(vertices));
    out.assign(vertices * per, 1.0f);  // a VEC3 colour's alpha stays 1
    for (size_t v = 0; v < vertices; ++v)
        for (int c = 0; c < a.components; ++c) out[v * per + c] = static_cast<float>(a.get(v, c));
}

void GltfReader::load_current() {
    const Instance& inst = instances_[inst_];
    current_ = geometry(inst.mesh, static_cast<int>(prim_));
    const double* m = inst.matrix;
    // A mirroring transform reverses the winding (glTF 2.0 §3.7.4); swap two corners back.
    flip_ = det3(m) < 0;
    const auto& src = current_->positions;
    // Morph targets at the default weights (glTF 2.0 §3.7.2.2): the pose a viewer shows.
    std::vector<double> morphed;
    const tinygltf::Primitive& p = model_.meshes[inst.mesh].primitives[prim_];
    for (size_t t = 0; t < p.targets.size() && t < inst.weights->size(); ++t) {
        const double w = (*inst.weights)[t];
        auto target = p.targets[t].find("POSITION");
        if (w == 0 || target == p.targets[t].end()) continue;
        const std::string at = where(inst.mesh, static_cast<int>(prim_)) + " morph target " + std::to_string(t);
        if (is_draco(p)) {  // Draco reorders the vertices the target's displacements refer to
            std::string weight;
            append_number(weight, w);
            throw Error(name_, at + " has weight " + weight +
                                   ": morph targets of KHR_draco_mesh_compression primitives are not supported");
        }
        const AccessorView d = view(target->second, at + " POSITION");
        if (d.components != 3 || d.count != src.size() / 3)
            throw Error(name_, at + " POSITION must be VEC3 with as many elements as POSITION (" +
                                   std::to_string(src.size() / 3) + ")");
        if (morphed.empty()) morphed.assign(src.begin(), src.end());
        for (size_t i = 0; i < d.count; ++i)
            for (int c = 0; c < 3; ++c) morphed[3 * i + c] += w * d.get(i, c);
    }
    world_.resize(src.size());
    for (size_t i = 0; i < src.size(); i += 3) {
        double x = src[i], y = src[i + 1], z = src[i + 2];
        if (!morphed.empty()) x = morphed[i], y = morphed[i + 1], z = morphed[i + 2];
        for (int r = 0; r < 3; ++r)
            world_[i + r] = static_cast<float>(m[r] * x + m[4 + r] * y + m[8 + r] * z + m[12 + r]);
    }
    // Normals go through the inverse transpose of the transform's 3 × 3 part: its cofactor
    // matrix, over the sign of its determinant (the length is normalised away).
    world_normals_.clear();
    if (!current_->normals.empty()) {
        const double sign = det3(m) < 0 ? -1.0 : 1.0;
        double cof[9];  // column-major, as m
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) {
                const int c1 = (c + 1) % 3, c2 = (c + 2) % 3, r1 = (r + 1) % 3, r2 = (r + 2) % 3;
                cof[c * 3 + r] = sign * (m[c1 * 4 + r1] * m[c2 * 4 + r2] - m[c1 * 4 + r2] * m[c2 * 4 + r1]);
            }
        const auto& n = current_->normals;
        // Without rotation or scale the file's values are kept bit for bit.
        const bool identity = m[0] == 1 && m[5] == 1 && m[10] == 1 && m[1] == 0 && m[2] == 0 && m[4] == 0 &&
                              m[6] == 0 && m[8] == 0 && m[9] == 0;
        world_normals_.assign(n.begin(), n.end());
        for (size_t i = 0; i < n.size() && !identity; i += 3) {
            double w[3], len = 0;
            for (int r = 0; r < 3; ++r) {
                w[r] = cof[r] * n[i] + cof[3 + r] * n[i + 1] + cof[6 + r] * n[i + 2];
                len += w[r] * w[r];
            }
            const double scale = len > 0 ? 1.0 / std::sqrt(len) : 0.0;
            for (int r = 0; r < 3; ++r) world_normals_[i + r] = static_cast<float>(w[r] * scale);
        }
    }
    // Texture coordinates: the material's KHR_texture_transform, then v flipped (glTF's v runs
    // down the image, the chunk's up).
    material_ = p.material >= 0 ? uint32_t(p.material) : default_material_;
    const UvTransform* transform =
        p.material >= 0 && size_t(p.material) < uv_transforms_.size() && uv_transforms_[p.material]
            ? &*uv_transforms_[p.material]
            : nullptr;
    chunk_uvs_.assign(current_->uvs.size(), {});
    for (size_t s = 0; s < current_->uvs.size(); ++s) {
        const auto& uv = current_->uvs[s];
        auto& out = chunk_uvs_[s];
        out.resize(uv.size());
        for (size_t i = 0; i < uv.size(); i += 2) {
            double u = uv[i], v = uv[i + 1];
            if (transform && transform->set == int(s)) {
                const double* t = transform->m;
                const double tu = t[0] * u + t[1] * v + t[2], tv = t[3] * u + t[4] * v + t[5];
                u = tu, v = tv;
            }
            out[i] = static_cast<float>(u);
            out[i + 1] = static_cast<float>(1.0 - v);
        }
    }
    id_base_ = next_id_;
    next_id_ += src.size() / 3;
    tri_ = 0;
    loaded_ = true;
}

bool GltfReader::next(TriangleChunk& chunk) {
    chunk.clear();
    while (!chunk.full() && inst_ < instances_.size()) {
        const tinygltf::Mesh& mesh = model_.meshes[instances_[inst_].mesh];
        if (prim_ >= mesh.primitives.size()) {
            ++inst_;
            prim_ = 0;
            loaded_ = false;
            continue;
        }
        if (!loaded_) load_current();
        const std::vector<uint32_t>& t = current_->triangles;
        const size_t count = t.size() / 3;
        const Channels& want = chunk.channels();
        const bool normals = want.normal && !world_normals_.empty();
        const bool colors = want.color && !current_->colors.empty();
        const int uv_sets = std::min(want.uv_sets, int(chunk_uvs_.size()));
        while (tri_ < count && !chunk.full()) {
            const size_t i = chunk.size();
            float* dst = chunk.push_slot();
            uint32_t v[3] = {t[3 * tri_], t[3 * tri_ + 1], t[3 * tri_ + 2]};
            if (flip_) std::swap(v[1], v[2]);
            for (int k = 0; k < 3; ++k) {
                const size_t x = v[k];
                std::memcpy(dst + 3 * k, &world_[3 * x], 3 * sizeof(float));
                if (normals) std::memcpy(chunk.normal_at(i) + 3 * k, &world_normals_[3 * x], 3 * sizeof(float));
                if (colors)
                    std::memcpy(chunk.color_at(i) + 4 * k, &current_->colors[4 * x], 4 * sizeof(float));
                else if (want.color)
                    std::fill_n(chunk.color_at(i) + 4 * k, 4, 1.0f);  // glTF: no colour is white
                for (int s = 0; s < uv_sets; ++s)
                    if (!chunk_uvs_[s].empty())
                        std::memcpy(chunk.uv_at(i, s) + 2 * k, &chunk_uvs_[s][2 * x], 2 * sizeof(float));
                if (want.vertex_id) chunk.id_at(i)[k] = id_base_ + x;
            }
            if (want.material) *chunk.material_at(i) = material_;
            ++tri_;
        }
        if (tri_ == count) {
            ++prim_;
            loaded_ = false;
        }
    }
    return !chunk.empty();
}

}  // namespace

std::unique_ptr<Reader> open_gltf_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<GltfReader>(source, options);
}

}  // namespace meshstream::io::gltf_detail

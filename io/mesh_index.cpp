// Soup -> indexed mesh for the whole-mesh writers: exact welding or vertex ids, see the header.
#include "io/mesh_index.hpp"

#include "io/error.hpp"
#include "io/hash.hpp"
#include "io/text_number.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace meshstream::io {
namespace {

constexpr uint32_t kEmpty = ~uint32_t{0};
constexpr uint64_t kMaxIndexCount = 0xFFFFFFFFull;  // glTF/Draco: 32-bit index counts and values

// Bits of a coordinate for welding; -0 and +0 weld (x + 0.0f turns -0 into +0).
inline uint32_t weld_bits(float x) {
    float y = x + 0.0f;
    uint32_t b;
    std::memcpy(&b, &y, 4);
    return b;
}

inline uint64_t hash_position(const float* p) {
    uint64_t a = weld_bits(p[0]), b = weld_bits(p[1]), c = weld_bits(p[2]);
    return mix64(a ^ mix64(b ^ mix64(c)));
}

inline bool same_position(const float* a, const float* b) {
    return weld_bits(a[0]) == weld_bits(b[0]) && weld_bits(a[1]) == weld_bits(b[1]) && weld_bits(a[2]) == weld_bits(b[2]);
}

}  // namespace

Bounds IndexedMesh::bounds() const {
    Bounds b;
    if (positions.empty()) return b;
    for (int a = 0; a < 3; ++a) b.min[a] = b.max[a] = positions[a];
    for (size_t i = 0; i < positions.size(); i += 3)
        for (int a = 0; a < 3; ++a) {
            b.min[a] = std::min(b.min[a], positions[i + a]);
            b.max[a] = std::max(b.max[a], positions[i + a]);
        }
    return b;
}

std::vector<float> IndexedMesh::smooth_normals() const {
    std::vector<float> n(positions.size(), 0.0f);
    for (size_t t = 0; t < indices.size(); t += 3) {
        const float* p0 = &positions[3 * size_t{indices[t]}];
        const float* p1 = &positions[3 * size_t{indices[t + 1]}];
        const float* p2 = &positions[3 * size_t{indices[t + 2]}];
        // The unnormalised cross product has length 2·area: the area weighting comes free.
        double e1[3], e2[3];
        for (int a = 0; a < 3; ++a) {
            e1[a] = double(p1[a]) - p0[a];
            e2[a] = double(p2[a]) - p0[a];
        }
        float c[3] = {float(e1[1] * e2[2] - e1[2] * e2[1]), float(e1[2] * e2[0] - e1[0] * e2[2]),
                      float(e1[0] * e2[1] - e1[1] * e2[0])};
        for (int k = 0; k < 3; ++k) {
            float* dst = &n[3 * size_t{indices[t + k]}];
            dst[0] += c[0];
            dst[1] += c[1];
            dst[2] += c[2];
        }
    }
    for (size_t i = 0; i < n.size(); i += 3) {
        double len = std::sqrt(double(n[i]) * n[i] + double(n[i + 1]) * n[i + 1] + double(n[i + 2]) * n[i + 2]);
        if (len > 0 && std::isfinite(len)) {
            for (int a = 0; a < 3; ++a) n[i + a] = static_cast<float>(n[i + a] / len);
        } else {
            n[i] = 0.0f;
            n[i + 1] = 0.0f;
            n[i + 2] = 1.0f;
        }
    }
    return n;
}

MeshIndexer::MeshIndexer(std::string file_name) : file_name_(std::move(file_name)) { slots_.assign(1024, kEmpty); }

uint64_t MeshIndexer::memory_bytes() const {
    // What is resident: the growing arrays up to their size (the pages of a vector's spare
    // capacity are not touched; counting capacity made the figure jump by a quarter at each
    // doubling and refused meshes that fit), the hash slots whole (they are initialized).
    return mesh_.positions.size() * sizeof(float) + ids_.size() * sizeof(uint64_t) +
           slots_.size() * sizeof(uint32_t) + mesh_.indices.size() * sizeof(uint32_t);
}

void MeshIndexer::grow() {
    std::vector<uint32_t> old(slots_.size() * 2, kEmpty);
    old.swap(slots_);
    size_t mask = slots_.size() - 1;
    for (uint32_t v : old) {
        if (v == kEmpty) continue;
        uint64_t h = id_mode_ == 1 ? mix64(ids_[v]) : hash_position(&mesh_.positions[3 * size_t{v}]);
        size_t s = h & mask;
        while (slots_[s] != kEmpty) s = (s + 1) & mask;
        slots_[s] = v;
    }
}

uint32_t MeshIndexer::vertex_for_position(const float* p) {
    size_t mask = slots_.size() - 1;
    size_t s = hash_position(p) & mask;
    while (slots_[s] != kEmpty) {
        if (same_position(&mesh_.positions[3 * size_t{slots_[s]}], p)) return slots_[s];
        s = (s + 1) & mask;
    }
    uint32_t v = static_cast<uint32_t>(mesh_.vertex_count());
    slots_[s] = v;
    mesh_.positions.insert(mesh_.positions.end(), p, p + 3);
    if (2 * (size_t{v} + 1) > slots_.size()) grow();
    return v;
}

uint32_t MeshIndexer::vertex_for_id(uint64_t id, const float* p) {
    size_t mask = slots_.size() - 1;
    size_t s = mix64(id) & mask;
    while (slots_[s] != kEmpty) {
        if (ids_[slots_[s]] == id) return slots_[s];
        s = (s + 1) & mask;
    }
    uint32_t v = static_cast<uint32_t>(mesh_.vertex_count());
    slots_[s] = v;
    ids_.push_back(id);
    mesh_.positions.insert(mesh_.positions.end(), p, p + 3);
    if (2 * (size_t{v} + 1) > slots_.size()) grow();
    return v;
}

void MeshIndexer::add(const TriangleChunk& chunk) {
    if (chunk.empty()) return;
    int mode = chunk.channels().vertex_id ? 1 : 0;
    if (id_mode_ == -1) id_mode_ = mode;
    if (mode != id_mode_)
        throw Error(file_name_, "the vertex-id channel " + std::string(mode ? "appeared" : "disappeared") +
                                    " after triangle " + std::to_string(input_triangles_) + " (producer bug)");
    auto xyz = chunk.xyz();
    auto ids = chunk.vertex_ids();
    for (size_t t = 0; t < chunk.size(); ++t, ++input_triangles_) {
        const float* p = &xyz[9 * t];
        for (int k = 0; k < 9; ++k)
            if (!std::isfinite(p[k]))
                throw Error(file_name_, "triangle " + std::to_string(input_triangles_) +
                                            " has a non-finite coordinate, which Draco and glTF cannot store");
        if (mesh_.indices.size() + 3 > kMaxIndexCount)
            throw Error(file_name_, "more than 2^32 - 1 indices (" + std::to_string(input_triangles_ + 1) +
                                        " triangles): glTF and Draco use 32-bit indices; split the mesh");
        uint32_t v[3];
        for (int k = 0; k < 3; ++k) v[k] = id_mode_ == 1 ? vertex_for_id(ids[3 * t + k], p + 3 * k) : vertex_for_position(p + 3 * k);
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            ++dropped_;
            continue;
        }
        mesh_.indices.insert(mesh_.indices.end(), v, v + 3);
    }
}

IndexedMesh MeshIndexer::take() {
    IndexedMesh out = std::move(mesh_);
    mesh_ = IndexedMesh{};
    ids_.clear();
    slots_.assign(1024, kEmpty);
    id_mode_ = -1;
    return out;
}

void budget_check_up_front(const std::string& file, const WriteOptions& options, const char* why,
                           uint64_t (*need)(uint64_t vertices, uint64_t triangles, const WriteOptions& options)) {
    const std::optional<uint64_t> n = options.triangle_count ? options.triangle_count : options.expected_triangle_count;
    if (!n) return;
    // A count from a broken header can be near 2^64, where the estimates wrap: past 2^40
    // triangles any estimate is beyond every machine, and the one of 2^40 is still a lower bound.
    const uint64_t counted = std::min(*n, uint64_t{1} << 40);
    const uint64_t least = need(counted / 2, counted, options);
    if (least <= options.memory_budget_bytes) return;
    const uint64_t mib = (least + (uint64_t{1} << 20) - 1) >> 20;
    throw Error(file, std::string(why) + ": the " + std::to_string(*n) + " triangles to be written need at least " +
                          binary_size(least) + ", over the memory budget of " +
                          binary_size(options.memory_budget_bytes) + "; give --memory " + std::to_string(mib) +
                          "M or more");
}

void budget_check(const std::string& file, const WriteOptions& options, const char* why, uint64_t triangles,
                  uint64_t need) {
    if (need <= options.memory_budget_bytes) return;
    const std::string budget = binary_size(options.memory_budget_bytes), estimate = binary_size(need);
    throw Error(file, std::string(why) + ": " + std::to_string(triangles) + " triangles so far need " +
                          (estimate == budget ? "a little more than the memory budget of " + budget
                                              : "about " + estimate + ", over the memory budget of " + budget) +
                          "; raise --memory");
}

}  // namespace meshstream::io

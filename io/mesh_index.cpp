// Soup -> indexed mesh for the whole-mesh writers: vertices keyed by position (or vertex id)
// and attribute record, see the header.
#include "io/mesh_index.hpp"

#include "io/error.hpp"
#include "io/hash.hpp"
#include "io/text_number.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

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
    return weld_bits(a[0]) == weld_bits(b[0]) && weld_bits(a[1]) == weld_bits(b[1]) &&
           weld_bits(a[2]) == weld_bits(b[2]);
}

// Non-finite values become 0; returns how many there were.
template <class T>
uint64_t zero_non_finite(T* v, size_t n) {
    uint64_t bad = 0;
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(v[i])) v[i] = 0, ++bad;
    return bad;
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
    // Vertices at one position (split by a seam, or by vertex ids) share their sums: group them
    // by sorting vertex numbers by position bits.
    const size_t n = vertex_count();
    std::vector<uint32_t> group(n);  // the first vertex (in position order) at each vertex's position
    {
        std::vector<uint32_t> order(n);
        std::iota(order.begin(), order.end(), 0u);
        auto key = [&](uint32_t v) {
            const float* p = &positions[3 * size_t{v}];
            return std::array<uint32_t, 3>{weld_bits(p[0]), weld_bits(p[1]), weld_bits(p[2])};
        };
        std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
        for (size_t i = 0; i < n; ++i)
            group[order[i]] = i > 0 && key(order[i]) == key(order[i - 1]) ? group[order[i - 1]] : order[i];
    }
    std::vector<double> sum(3 * n, 0.0);
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
        const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; ++k) {
            double* dst = &sum[3 * size_t{group[indices[t + k]]}];
            dst[0] += c[0];
            dst[1] += c[1];
            dst[2] += c[2];
        }
    }
    std::vector<float> out(3 * n);
    for (size_t v = 0; v < n; ++v) {
        const double* s = &sum[3 * size_t{group[v]}];
        const double len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        float* dst = &out[3 * v];
        if (len > 0 && std::isfinite(len)) {
            for (int a = 0; a < 3; ++a) dst[a] = static_cast<float>(s[a] / len);
        } else {
            dst[0] = 0.0f;
            dst[1] = 0.0f;
            dst[2] = 1.0f;
        }
    }
    return out;
}

std::vector<MeshPart> IndexedMesh::parts() const {
    const size_t triangles = triangle_count();
    // Triangles of each material, in mesh order (a counting sort).
    uint32_t material_count = 1;
    if (channels.material)
        for (uint32_t m : materials) material_count = std::max(material_count, m + 1);
    std::vector<uint64_t> start(size_t{material_count} + 1, 0);
    for (size_t t = 0; t < triangles; ++t) ++start[(channels.material ? materials[t] : 0) + 1];
    for (size_t m = 0; m < material_count; ++m) start[m + 1] += start[m];
    std::vector<MeshPart> parts;
    std::vector<uint32_t> local(vertex_count(), kEmpty);
    for (uint32_t m = 0; m < material_count; ++m) {
        if (start[m + 1] == start[m]) continue;
        MeshPart part;
        part.material = m;
        part.indices.reserve(3 * (start[m + 1] - start[m]));
        for (size_t t = 0; t < triangles; ++t) {
            if (channels.material && materials[t] != m) continue;
            for (int k = 0; k < 3; ++k) {
                const uint32_t v = indices[3 * t + k];
                if (local[v] == kEmpty) {
                    local[v] = static_cast<uint32_t>(part.vertices.size());
                    part.vertices.push_back(v);
                }
                part.indices.push_back(local[v]);
            }
        }
        for (uint32_t v : part.vertices) local[v] = kEmpty;
        parts.push_back(std::move(part));
        if (!channels.material) break;
    }
    return parts;
}

VertexValues IndexedMesh::values(std::span<const uint32_t> vertices) const {
    VertexValues out;
    const CornerLayout layout(channels);
    const size_t n = vertices.size();
    if (channels.normal) out.normals.resize(3 * n);
    if (channels.color) out.colors.resize(4 * n);
    out.uvs.assign(size_t(channels.uv_sets), std::vector<float>(2 * n));
    out.scalars.assign(channels.vertex_scalars.size(), std::vector<double>(n));
    std::vector<float> uv(2 * size_t(channels.uv_sets));
    std::vector<double> scalars(channels.vertex_scalars.size());
    for (size_t i = 0; i < n; ++i) {
        const std::byte* record = attributes.data() + size_t{vertices[i]} * layout.bytes();
        layout.unpack_values(record, channels.normal ? &out.normals[3 * i] : nullptr,
                             channels.color ? &out.colors[4 * i] : nullptr, uv.data(), scalars.data());
        for (int s = 0; s < channels.uv_sets; ++s) std::memcpy(&out.uvs[s][2 * i], &uv[2 * s], 2 * sizeof(float));
        for (size_t c = 0; c < scalars.size(); ++c) out.scalars[c][i] = scalars[c];
    }
    return out;
}

uint64_t indexed_mesh_bytes(uint64_t vertices, uint64_t triangles, const Channels& channels) {
    // Positions, records and ids per vertex; the hash table (8 bytes a vertex at load 1/2, and
    // rounded up to a power of two: about 12 on average); indices and materials per triangle.
    const uint64_t per_vertex = 12 + CornerLayout(channels).bytes() + (channels.vertex_id ? 8 : 0) + 12;
    return vertices * per_vertex + triangles * (12 + (channels.material ? 4 : 0));
}

Error non_finite_triangle_error(const std::string& file, const std::string& format, uint64_t triangle) {
    return Error(file, "triangle " + std::to_string(triangle) + " has a NaN or infinite coordinate, which " + format +
                           " cannot store (" + mention(Setting::kStrict) + ")");
}

Error index_count_error(const std::string& file, const std::string& format, uint64_t triangles) {
    return Error(file, "more than 2^32 - 1 indices (" + std::to_string(triangles) + " triangles): " + format +
                           " uses 32-bit indices; split the mesh");
}

MeshIndexer::MeshIndexer(std::string file_name, std::string format, const Channels& channels, bool strict)
    : file_name_(std::move(file_name)), format_(std::move(format)), strict_(strict), layout_(channels) {
    mesh_.channels = channels;
    mesh_.channels.vertex_id = false;
    mesh_.channels.face_scalars.clear();
    record_.resize(layout_.bytes());
    slots_.assign(1024, kEmpty);
}

void MeshIndexer::reserve(uint64_t triangles) {
    if (mesh_.vertex_count() > 0) return;
    triangles = std::min<uint64_t>(triangles, kMaxIndexCount / 3);
    // Two slots a vertex for triangles / 2 vertices, as the writers' budget estimates count them
    // (vertex_for grows the table once it is half full).
    size_t slots = slots_.size();
    while (slots < triangles) slots *= 2;
    if (slots > slots_.size()) slots_.assign(slots, kEmpty);
    const size_t vertices = size_t(triangles / 2 + 2);
    mesh_.positions.reserve(3 * vertices);
    mesh_.attributes.reserve(layout_.bytes() * vertices);
    mesh_.indices.reserve(3 * size_t(triangles));
}

uint64_t MeshIndexer::memory_bytes() const {
    // What is resident: the growing arrays up to their size (the pages of a vector's spare
    // capacity are not touched; counting capacity made the figure jump by a quarter at each
    // doubling and refused meshes that fit), the hash slots whole (they are initialized).
    return mesh_.positions.size() * sizeof(float) + mesh_.attributes.size() + ids_.size() * sizeof(uint64_t) +
           slots_.size() * sizeof(uint32_t) + mesh_.indices.size() * sizeof(uint32_t) +
           mesh_.materials.size() * sizeof(uint32_t);
}

uint64_t MeshIndexer::hash_of(uint32_t v) const {
    const uint64_t base = id_mode_ == 1 ? mix64(ids_[v]) : hash_position(&mesh_.positions[3 * size_t{v}]);
    return layout_.bytes() ? hash_bytes(&mesh_.attributes[size_t{v} * layout_.bytes()], layout_.bytes(), base) : base;
}

void MeshIndexer::grow() {
    std::vector<uint32_t> old(slots_.size() * 2, kEmpty);
    old.swap(slots_);
    size_t mask = slots_.size() - 1;
    for (uint32_t v : old) {
        if (v == kEmpty) continue;
        size_t s = hash_of(v) & mask;
        while (slots_[s] != kEmpty) s = (s + 1) & mask;
        slots_[s] = v;
    }
}

uint32_t MeshIndexer::vertex_for(const float* p, uint64_t id, const std::byte* record) {
    const size_t rb = layout_.bytes();
    uint64_t h = id_mode_ == 1 ? mix64(id) : hash_position(p);
    if (rb) h = hash_bytes(record, rb, h);
    const size_t mask = slots_.size() - 1;
    size_t s = h & mask;
    while (slots_[s] != kEmpty) {
        const uint32_t v = slots_[s];
        const bool same_key = id_mode_ == 1 ? ids_[v] == id : same_position(&mesh_.positions[3 * size_t{v}], p);
        if (same_key && (rb == 0 || std::memcmp(&mesh_.attributes[size_t{v} * rb], record, rb) == 0)) return v;
        s = (s + 1) & mask;
    }
    const uint32_t v = static_cast<uint32_t>(mesh_.vertex_count());
    slots_[s] = v;
    if (id_mode_ == 1) ids_.push_back(id);
    mesh_.positions.insert(mesh_.positions.end(), p, p + 3);
    mesh_.attributes.insert(mesh_.attributes.end(), record, record + rb);
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
    const Channels& ch = mesh_.channels;
    const Channels& has = chunk.channels();
    if ((ch.normal && !has.normal) || (ch.color && !has.color) || ch.uv_sets > has.uv_sets ||
        (!ch.vertex_scalars.empty() && ch.vertex_scalars != has.vertex_scalars) || (ch.material && !has.material))
        throw Error(file_name_, "a chunk lacks channels the writer was told of (producer bug): it has " +
                                    describe_missing(ch, has) + " missing");
    auto xyz = chunk.xyz();
    auto ids = chunk.vertex_ids();
    const int uv_sets = ch.uv_sets;
    const size_t scalar_count = ch.vertex_scalars.size();
    std::vector<double> scalars(scalar_count);
    for (size_t t = 0; t < chunk.size(); ++t, ++input_triangles_) {
        const float* p = &xyz[9 * t];
        bool finite = true;
        for (int k = 0; k < 9; ++k) finite = finite && std::isfinite(p[k]);
        if (!finite) {
            if (strict_) throw non_finite_triangle_error(file_name_, format_, input_triangles_);
            ++non_finite_;
            continue;
        }
        if (mesh_.indices.size() + 3 > kMaxIndexCount) throw index_count_error(file_name_, format_, input_triangles_ + 1);
        uint32_t v[3];
        for (int k = 0; k < 3; ++k) {
            if (layout_.bytes()) {
                // One corner's values, non-finite ones made 0 (glTF and Draco hold none).
                float normal[3] = {0, 0, 0}, rgba[4] = {0, 0, 0, 1}, uv[2 * kMaxUvSets] = {};
                if (ch.normal) std::memcpy(normal, chunk.normal_at(t) + 3 * k, sizeof normal);
                if (ch.color) std::memcpy(rgba, chunk.color_at(t) + 4 * k, sizeof rgba);
                for (int s = 0; s < uv_sets; ++s) std::memcpy(uv + 2 * s, chunk.uv_at(t, s) + 2 * k, 2 * sizeof(float));
                for (size_t c = 0; c < scalar_count; ++c) scalars[c] = chunk.vertex_scalar_at(t, c)[k];
                non_finite_attributes_ += zero_non_finite(normal, 3) + zero_non_finite(rgba, 4) +
                                          zero_non_finite(uv, 2 * size_t(uv_sets)) +
                                          zero_non_finite(scalars.data(), scalar_count);
                layout_.pack_values(normal, rgba, uv, scalars.data(), record_.data());
            }
            v[k] = vertex_for(p + 3 * k, id_mode_ == 1 ? ids[3 * t + k] : 0, record_.data());
        }
        mesh_.indices.insert(mesh_.indices.end(), v, v + 3);
        if (ch.material) mesh_.materials.push_back(*chunk.material_at(t));
    }
}

std::vector<std::string> MeshIndexer::notes() const {
    std::vector<std::string> out;
    if (non_finite_)
        out.push_back(std::to_string(non_finite_) + " of the " + std::to_string(input_triangles_) +
                      " triangles have a NaN or infinite coordinate, which " + format_ +
                      " cannot store: left out (" + mention(Setting::kStrict) + " makes this an error)");
    if (non_finite_attributes_)
        out.push_back(std::to_string(non_finite_attributes_) +
                      " attribute values (normal, colour, texture coordinate or scalar) were NaN or infinite: written "
                      "as 0");
    return out;
}

IndexedMesh MeshIndexer::take() {
    IndexedMesh out = std::move(mesh_);
    mesh_ = IndexedMesh{};
    mesh_.channels = out.channels;
    ids_.clear();
    slots_.assign(1024, kEmpty);
    id_mode_ = -1;
    return out;
}

namespace {

// The budget, and the share of the whole budget it is when it is not all of it.
std::string budget_text(uint64_t budget, uint32_t divisor) {
    return binary_size(budget) + (divisor > 1 ? " (1/" + std::to_string(divisor) + " of " + mention(Setting::kMemory) + ")" : std::string());
}

// The whole budget, in whole MiB, that gives a writer `bytes`.
std::string memory_option_mib(uint64_t bytes, uint32_t divisor) {
    const long double all = (long double)bytes * (long double)std::max<uint32_t>(divisor, 1);
    return std::to_string(uint64_t(std::ceil(all / (long double)(uint64_t{1} << 20))));
}

}  // namespace

void budget_check_up_front(const std::string& file, const WriteOptions& options, const char* why,
                           uint64_t (*need)(uint64_t vertices, uint64_t triangles, const WriteOptions& options)) {
    const std::optional<uint64_t> n = options.triangle_count ? options.triangle_count : options.expected_triangle_count;
    if (!n) return;
    // A count from a broken header can be near 2^64, where the estimates wrap: past 2^40
    // triangles any estimate is beyond every machine, and the one of 2^40 is still a lower bound.
    const uint64_t counted = std::min(*n, uint64_t{1} << 40);
    const uint64_t least = need(counted / 2, counted, options);
    if (least <= options.memory_budget_bytes) return;
    throw Error(file, std::string(why) + ": the " + std::to_string(*n) + " triangles to be written need at least " +
                          binary_size(least) + ", over the memory budget of " +
                          budget_text(options.memory_budget_bytes, options.memory_budget_divisor) + "; give " + mention(Setting::kMemory) + " " +
                          memory_option_mib(least, options.memory_budget_divisor) + "M or more");
}

WholeMeshBudget::WholeMeshBudget(std::string file, const WriteOptions& options, const char* why)
    : file_(std::move(file)),
      why_(why),
      budget_(options.memory_budget_bytes),
      divisor_(options.memory_budget_divisor),
      total_(options.triangle_count ? options.triangle_count : options.expected_triangle_count) {}

bool WholeMeshBudget::check(uint64_t triangles, uint64_t need) {
    if (need <= budget_ || counting_) return false;
    triangles_ = triangles;
    need_ = need;
    if (total_ && *total_ > triangles) refuse(*total_);
    counting_ = true;
    counted_ = triangles;
    return true;
}

void WholeMeshBudget::fail() const { refuse(counted_); }

void WholeMeshBudget::refuse(uint64_t total) const {
    // The bytes held grow with the triangles (and with the vertices, which follow them).
    const long double scaled =
        (long double)need_ * (long double)std::max(total, triangles_) / (long double)std::max<uint64_t>(triangles_, 1);
    const uint64_t all = scaled >= 1.8e19L ? UINT64_MAX : uint64_t(std::ceil(scaled));
    throw Error(file_, std::string(why_) + ": the " + std::to_string(total) + " triangles " +
                           (counting_ ? "given" : "to be written") + " need about " + binary_size(all) +
                           (total > triangles_
                                ? " (the first " + std::to_string(triangles_) + " took " + binary_size(need_) + ")"
                                : std::string()) +
                           ", over the memory budget of " + budget_text(budget_, divisor_) + "; give " + mention(Setting::kMemory) + " " +
                           memory_option_mib(all, divisor_) + "M or more");
}

}  // namespace meshstream::io
